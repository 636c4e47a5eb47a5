# vsd_gtest_suites(<target> LABEL <label> [PROPERTIES <ctest properties>...])
#
# Registers one ctest test per GoogleTest *suite* of <target>, named "<Suite>.*" and run as
# `<target> --gtest_filter=<Suite>.*`. gtest_discover_tests() registers one per test, and ctest then
# starts a process per test: ~850 starts, which cost more than the tests themselves in the sanitizer
# tree (an ASan binary needs about half a second to start). Suites keep ctest's parallelism and its
# -R/-L selection, and a failure still names the failing test in the output.
#
# Like gtest_discover_tests(), the suites are listed after each build (`--gtest_list_tests`), so a new
# suite needs no CMake change. PROPERTIES (e.g. ENVIRONMENT, TIMEOUT, RUN_SERIAL) apply to every suite;
# a single suite's properties can be set in a file added to the directory's TEST_INCLUDE_FILES after
# this call (see tests/dist/serial_tests.cmake).
set(_vsd_gtest_suites_script "${CMAKE_CURRENT_LIST_DIR}/VsdGTestSuitesWrite.cmake")

function(vsd_gtest_suites target)
  cmake_parse_arguments(PARSE_ARGV 1 arg "" "LABEL" "PROPERTIES")
  set(dir "${CMAKE_CURRENT_BINARY_DIR}/${target}_suites")
  set(list_file "${dir}/suites.cmake")
  # The properties are written at configure time, quoted by CMake itself, and read by the list file.
  set(props "")
  foreach(p IN LISTS arg_PROPERTIES)
    string(REPLACE "\\" "\\\\" p "${p}")
    string(REPLACE "\"" "\\\"" p "${p}")
    string(APPEND props " \"${p}\"")
  endforeach()
  file(WRITE "${dir}/properties.cmake" "set(_vsd_suite_properties LABELS \"${arg_LABEL}\"${props})\n")
  add_custom_command(TARGET ${target} POST_BUILD
    COMMAND "${CMAKE_COMMAND}" -D "EXE=$<TARGET_FILE:${target}>" -D "OUT=${list_file}"
            -D "PROPERTIES=${dir}/properties.cmake" -P "${_vsd_gtest_suites_script}"
    BYPRODUCTS "${list_file}"
    VERBATIM)
  # ctest reads this when it starts: the suites once the target is built, a failing placeholder before.
  file(WRITE "${dir}/include.cmake"
    "if(EXISTS \"${list_file}\")\n"
    "  include(\"${list_file}\")\n"
    "else()\n"
    "  add_test(${target}_NOT_BUILT ${target}_NOT_BUILT)\n"
    "endif()\n")
  set_property(DIRECTORY APPEND PROPERTY TEST_INCLUDE_FILES "${dir}/include.cmake")
endfunction()
