# Script mode, run after a test executable is built (see VsdGTestSuites.cmake):
#   cmake -D EXE=<test executable> -D OUT=<ctest file to write> -D PROPERTIES=<properties file> -P this
# Lists the executable's suites and writes one add_test() per suite.
execute_process(COMMAND "${EXE}" --gtest_list_tests
  OUTPUT_VARIABLE listing ERROR_VARIABLE errors RESULT_VARIABLE rc TIMEOUT 120)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "${EXE} --gtest_list_tests failed (${rc}):\n${listing}${errors}")
endif()
string(REPLACE "\n" ";" lines "${listing}")
set(content "include(\"${PROPERTIES}\")\n")
set(count 0)
foreach(line IN LISTS lines)
  # A suite line starts in column 0 and its name ends with a dot: "SimState." or
  # "Formats/Files.  # TypeParam = ..."; tests are indented; gtest_main's banner has no dot.
  if(line MATCHES "^([A-Za-z_][A-Za-z0-9_/]*)\\.( .*)?$")
    set(suite "${CMAKE_MATCH_1}")
    string(APPEND content
      "add_test(\"${suite}.*\" \"${EXE}\" \"--gtest_filter=${suite}.*\")\n"
      "set_tests_properties(\"${suite}.*\" PROPERTIES \${_vsd_suite_properties})\n")
    math(EXPR count "${count} + 1")
  endif()
endforeach()
if(count EQUAL 0)
  message(FATAL_ERROR "${EXE} lists no test suites")
endif()
file(WRITE "${OUT}" "${content}")
