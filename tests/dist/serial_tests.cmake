# Included by ctest after the file of gtest_discover_tests() that defines the vsd_dist_tests tests: the
# multi-process ones run alone (they spawn processes, use ports and may make network namespaces).
set_tests_properties("DistProcesses.AReaderThatDiesAndARejoinerFollowAWriterProcess"
                     "DistProcesses.NetworkNamespacesWithLossDelayAndReordering"
                     "DistProcesses.TenPercentPacketLossLosesNothingAndReordersNothing"
                     "DistProcesses.ThreeProcessesEditingOneListEndWithTheSameList" PROPERTIES RUN_SERIAL TRUE)
