# Runs `vsd-soml run SCRIPT <args>` (args from a header line "// args: ...") in SCRIPT's directory and
# compares stdout followed by stderr with SCRIPT's .out file. The exit code must be 0, or the N of a
# header line "// expect-exit: N" (run-time error goldens). The header is the leading `//` comment.
# Used by the ctest entries vsd_soml_<name>.
file(STRINGS "${SCRIPT}" lines)
set(args "")
set(expected_rc 0)
foreach(line IN LISTS lines)
  if(NOT line MATCHES "^//")
    break()
  endif()
  if(line MATCHES "^// args: (.*)$")
    separate_arguments(args UNIX_COMMAND "${CMAKE_MATCH_1}")
  elseif(line MATCHES "^// expect-exit: ([0-9]+)$")
    set(expected_rc "${CMAKE_MATCH_1}")
  endif()
endforeach()
# The script's own name, run from its directory: diagnostics and call stacks name "NAME.soml", not a
# path that depends on the checkout.
# NATIVE (optional): a native library of the script (vsd-soml compile), passed as `--native NATIVE`.
if(NATIVE)
  list(APPEND args --native "${NATIVE}")
endif()
get_filename_component(dir "${SCRIPT}" DIRECTORY)
get_filename_component(name "${SCRIPT}" NAME)
execute_process(COMMAND "${TOOL}" run "${name}" ${args} WORKING_DIRECTORY "${dir}" OUTPUT_VARIABLE out
  ERROR_VARIABLE err RESULT_VARIABLE rc)
string(REGEX REPLACE "\\.soml$" ".out" expected_file "${SCRIPT}")
file(READ "${expected_file}" expected)
if(NOT rc STREQUAL expected_rc)
  message(FATAL_ERROR "vsd-soml run exited with ${rc}, expected ${expected_rc}:\n${out}${err}")
endif()
if(NOT "${out}${err}" STREQUAL expected)
  message(FATAL_ERROR "output differs from ${expected_file}:\n--- got ---\n${out}${err}--- expected ---\n${expected}")
endif()
