# Installs the component vsd_python of the build tree BUILD_DIR into PREFIX and imports the package from
# the prefix's site-packages with PYTHON (ctest vsd_python_install).
file(REMOVE_RECURSE "${PREFIX}")
execute_process(COMMAND "${CMAKE_COMMAND}" --install "${BUILD_DIR}" --component vsd_python --prefix "${PREFIX}"
                RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "installing the component vsd_python failed (${rc})")
endif()
file(GLOB_RECURSE inits "${PREFIX}/*__init__.py")
list(FILTER inits INCLUDE REGEX "/site-packages/vsd/__init__\\.py$")
if(NOT inits)
  message(FATAL_ERROR "the package vsd was not installed below ${PREFIX}/.../site-packages")
endif()
list(GET inits 0 init)
get_filename_component(site "${init}" DIRECTORY)
get_filename_component(site "${site}" DIRECTORY)
execute_process(COMMAND "${CMAKE_COMMAND}" -E env "PYTHONPATH=${site}" PYTHONDONTWRITEBYTECODE=1
                        "${PYTHON}" -c "import vsd; assert vsd.__file__.startswith('${site}'), vsd.__file__; vsd.Environment().main_state.create('Node')"
                RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "import vsd from ${site} failed")
endif()
message(STATUS "vsd installed and imported from ${site}")
