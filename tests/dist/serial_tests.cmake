# Included by ctest after gtest_discover_tests() has defined the vsd_dist_tests tests: the multi-process
# ones run alone (they spawn processes, use ports and may make network namespaces).
foreach(_t "DistProcesses.AReaderThatDiesAndARejoinerFollowAWriterProcess"
           "DistProcesses.NetworkNamespacesWithLossDelayAndReordering")
  if(TEST "${_t}")
    set_tests_properties("${_t}" PROPERTIES RUN_SERIAL TRUE)
  endif()
endforeach()
