# Compile options for vsd's own targets. Everything here is PRIVATE so that
# consumers never inherit our warnings, -Werror or sanitizer flags.
# The warnings of vsd's own code (and -Werror with VSD_WERROR); vsd_target_options() adds them. Also for
# the native SOML++ modules the tests and benchmarks generate, so that generated code stays warning-clean
# where a user's build warns.
function(vsd_target_warnings target)
  if(CMAKE_CXX_COMPILER_ID MATCHES "GNU|Clang")
    target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic)
    # GCC 12 and 13 report -Wrestrict false positives inside libstdc++'s operator+ on strings at -O2/-O3
    # (GCC bug 105329); they are not about our code.
    if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU" AND CMAKE_CXX_COMPILER_VERSION VERSION_GREATER_EQUAL 12
       AND CMAKE_CXX_COMPILER_VERSION VERSION_LESS 14)
      target_compile_options(${target} PRIVATE -Wno-restrict)
    endif()
    if(VSD_WERROR)
      target_compile_options(${target} PRIVATE -Werror)
    endif()
  endif()
endfunction()

function(vsd_target_options target)
  target_compile_features(${target} PUBLIC cxx_std_20)
  vsd_target_warnings(${target})
  if(CMAKE_CXX_COMPILER_ID MATCHES "GNU|Clang")
    if(VSD_SANITIZE OR VSD_BUILD_FUZZERS)
      target_compile_options(${target} PRIVATE -fsanitize=address,undefined -fno-omit-frame-pointer
                                               -fno-sanitize-recover=all)
      target_link_options(${target} PRIVATE -fsanitize=address,undefined)
      # A sanitized test binary as a PIE carries about a million relative relocations (ASan's global
      # metadata), and the loader spends ~0.4 s on them at every start; ctest starts one process per
      # test. Linked as a fixed-address executable, there is nothing to relocate.
      get_target_property(type ${target} TYPE)
      if(type STREQUAL "EXECUTABLE" AND NOT BUILD_SHARED_LIBS)
        target_link_options(${target} PRIVATE -no-pie)
      endif()
    endif()
  endif()
endfunction()

# Coverage for libFuzzer in vsd's module libraries (vsd_add_module calls this; C sources too, where the C
# compiler is clang), the code the fuzzers link. The fuzzers themselves compile and link with
# -fsanitize=fuzzer. The same tree builds and runs the test suite under the sanitizers (.ci/run): one
# sanitized build. Tests, tools and examples get no coverage: no fuzzer links them (and clang 14's
# coverage tables fail to assemble for the work cell's cell.cpp: "cannot represent a difference across
# sections").
function(vsd_fuzz_coverage target)
  if(VSD_BUILD_FUZZERS)
    target_compile_options(${target} PRIVATE $<$<COMPILE_LANG_AND_ID:CXX,Clang>:-fsanitize=fuzzer-no-link>
                                             $<$<COMPILE_LANG_AND_ID:C,Clang>:-fsanitize=fuzzer-no-link>)
  endif()
endfunction()
