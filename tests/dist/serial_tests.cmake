# Included by ctest after the file of vsd_gtest_suites() that defines the vsd_dist_tests suites: the
# multi-process tests run alone (they spawn processes, use ports and may make network namespaces).
set_tests_properties("DistProcesses.*" PROPERTIES RUN_SERIAL TRUE)
