# Configures, builds and checks one CMake project in a separate build tree. Run as a ctest test:
#
#   cmake -DACTION=install  -DSOURCE_DIR=<vsd>      -DBINARY_DIR=<dir> -DVSD_PREFIX=<prefix> [common] -P RunCMakeProject.cmake
#   cmake -DACTION=consumer -DSOURCE_DIR=<consumer> -DBINARY_DIR=<dir> [-DVSD_PREFIX=<prefix>]
#         [-DVSD_SOURCE_DIR=<vsd>] [common] -P RunCMakeProject.cmake
#
#   cmake -DACTION=configure -DSOURCE_DIR=<consumer> -DBINARY_DIR=<dir> [-DVSD_DIR=<dir>]
#         [-DEXPECT_ERROR=<regex>] [common] -P RunCMakeProject.cmake
#
# common: -DGENERATOR= -DMAKE_PROGRAM= -DCXX_COMPILER= -DCTEST_COMMAND= -DEIGEN3_DIR= -DVSD_WERROR=
#         -DEXTRA_ARGS=<-D...>|<-D...>  further configure arguments, separated by '|'
#
# install  : fresh Release build of vsd (no tests/examples/benchmarks/tools; the modules EXTRA_ARGS leaves
#            on), then `cmake --install` into VSD_PREFIX (wiped first, so nothing stale can hide a missing
#            install rule).
# consumer : Release build of a consumer project, then its own ctest (which runs the consumer binary).
#            With VSD_PREFIX the project must find vsd there via find_package; with VSD_SOURCE_DIR it
#            gets the vsd source tree.
# configure: configure (and generate) a consumer project only, against the package in VSD_DIR (a build
#            tree's); with EXPECT_ERROR the configure must fail with output matching it.
# Build trees are kept between runs, so re-runs are incremental.
cmake_minimum_required(VERSION 3.21)

foreach(var ACTION SOURCE_DIR BINARY_DIR GENERATOR CTEST_COMMAND)
  if(NOT DEFINED ${var} OR "${${var}}" STREQUAL "")
    message(FATAL_ERROR "RunCMakeProject.cmake: ${var} is required")
  endif()
endforeach()

set(config Release)
set(jobs 2)

function(run_step what)
  message(STATUS "---- ${what}")
  execute_process(COMMAND ${ARGN} COMMAND_ECHO STDOUT RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "${what} failed (${rc})")
  endif()
endfunction()

# A tree configured by another generator cannot be reused: start it afresh.
if(EXISTS "${BINARY_DIR}/CMakeCache.txt")
  file(STRINGS "${BINARY_DIR}/CMakeCache.txt" cached_gen REGEX "^CMAKE_GENERATOR:INTERNAL=")
  if(NOT cached_gen STREQUAL "CMAKE_GENERATOR:INTERNAL=${GENERATOR}")
    message(STATUS "Removing ${BINARY_DIR} (configured with another generator)")
    file(REMOVE_RECURSE "${BINARY_DIR}")
  endif()
endif()

set(configure_args -S "${SOURCE_DIR}" -B "${BINARY_DIR}" -G "${GENERATOR}"
                   "-DCMAKE_BUILD_TYPE=${config}" -DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF)
if(MAKE_PROGRAM)
  list(APPEND configure_args "-DCMAKE_MAKE_PROGRAM=${MAKE_PROGRAM}")
endif()
if(CXX_COMPILER)
  list(APPEND configure_args "-DCMAKE_CXX_COMPILER=${CXX_COMPILER}")
endif()
if(EIGEN3_DIR)
  list(APPEND configure_args "-DEigen3_DIR=${EIGEN3_DIR}")
endif()
if(EXTRA_ARGS)
  string(REPLACE "|" ";" extra "${EXTRA_ARGS}")
  list(APPEND configure_args ${extra})
endif()

if(ACTION STREQUAL "install")
  if(NOT VSD_PREFIX)
    message(FATAL_ERROR "RunCMakeProject.cmake: ACTION=install needs VSD_PREFIX")
  endif()
  list(APPEND configure_args -DVSD_BUILD_TESTS=OFF -DVSD_BUILD_EXAMPLES=OFF -DVSD_BUILD_BENCHMARKS=OFF
                             -DVSD_BUILD_TOOLS=OFF -DVSD_INSTALL=ON "-DCMAKE_INSTALL_PREFIX=${VSD_PREFIX}")
  if(DEFINED VSD_WERROR AND NOT VSD_WERROR STREQUAL "")
    list(APPEND configure_args "-DVSD_WERROR=${VSD_WERROR}")
  endif()
  run_step("configure vsd" "${CMAKE_COMMAND}" ${configure_args})
  run_step("build vsd" "${CMAKE_COMMAND}" --build "${BINARY_DIR}" --config ${config} --parallel ${jobs})
  file(REMOVE_RECURSE "${VSD_PREFIX}")
  run_step("install vsd" "${CMAKE_COMMAND}" --install "${BINARY_DIR}" --config ${config}
           --prefix "${VSD_PREFIX}")
  file(GLOB_RECURSE config_files "${VSD_PREFIX}/*/vsdConfig.cmake")
  if(NOT config_files)
    message(FATAL_ERROR "no vsdConfig.cmake below ${VSD_PREFIX} after install")
  endif()
  if(NOT EXISTS "${VSD_PREFIX}/include/vsd/vsd.hpp")
    message(FATAL_ERROR "${VSD_PREFIX}/include/vsd/vsd.hpp was not installed")
  endif()
  message(STATUS "vsd installed to ${VSD_PREFIX}: ${config_files}")
elseif(ACTION STREQUAL "consumer")
  if(VSD_PREFIX)
    list(APPEND configure_args "-DCMAKE_PREFIX_PATH=${VSD_PREFIX}" "-DVSD_EXPECTED_PREFIX=${VSD_PREFIX}")
  endif()
  if(VSD_SOURCE_DIR)
    list(APPEND configure_args "-DVSD_SOURCE_DIR=${VSD_SOURCE_DIR}")
    if(DEFINED VSD_WERROR AND NOT VSD_WERROR STREQUAL "")
      list(APPEND configure_args "-DVSD_WERROR=${VSD_WERROR}")
    endif()
  endif()
  run_step("configure consumer" "${CMAKE_COMMAND}" ${configure_args})
  run_step("build consumer" "${CMAKE_COMMAND}" --build "${BINARY_DIR}" --config ${config} --parallel ${jobs})
  run_step("run consumer" "${CTEST_COMMAND}" --test-dir "${BINARY_DIR}" -C ${config}
           --output-on-failure --no-tests=error)
elseif(ACTION STREQUAL "configure")
  if(VSD_DIR)
    list(APPEND configure_args "-Dvsd_DIR=${VSD_DIR}")
  endif()
  if(NOT EXPECT_ERROR)
    run_step("configure consumer" "${CMAKE_COMMAND}" ${configure_args})
  else()
    message(STATUS "---- configure consumer (must fail)")
    execute_process(COMMAND "${CMAKE_COMMAND}" ${configure_args} RESULT_VARIABLE rc OUTPUT_VARIABLE out
                    ERROR_VARIABLE err)
    if(rc EQUAL 0)
      message(FATAL_ERROR "the configure succeeded; it should have failed with: ${EXPECT_ERROR}")
    endif()
    if(NOT "${out}${err}" MATCHES "${EXPECT_ERROR}")
      message(FATAL_ERROR "the configure failed, but without '${EXPECT_ERROR}':\n${out}${err}")
    endif()
    message(STATUS "failed as expected: ${EXPECT_ERROR}")
  endif()
else()
  message(FATAL_ERROR "RunCMakeProject.cmake: unknown ACTION '${ACTION}'")
endif()
