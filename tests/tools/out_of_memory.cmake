# `vsd-io check` of a 4.2 GB file in a process that may not have that much memory: "out of memory" and exit
# status 1, not std::terminate (SIGABRT). The file is sparse (no disk space) and goes again at the end.
# Run with -DTOOL=<vsd-io> -DWORK=<scratch dir>.
set(file "${WORK}/big.vsds")
file(MAKE_DIRECTORY "${WORK}")
execute_process(COMMAND truncate -s 4200000000 "${file}" RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "cannot make a sparse file of 4.2 GB with truncate")
endif()
# A 1 GiB address space: the tool runs, its 4.2 GB buffer cannot be had.
execute_process(COMMAND sh -c "ulimit -v 1048576 && exec \"$0\" check \"$1\"" "${TOOL}" "${file}"
  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
file(REMOVE "${file}")
if(NOT rc STREQUAL "1" OR NOT err MATCHES "vsd-io: out of memory")
  message(FATAL_ERROR "expected exit status 1 and 'vsd-io: out of memory', got ${rc}:\n${out}${err}")
endif()
message(STATUS "exit status 1: ${err}")
