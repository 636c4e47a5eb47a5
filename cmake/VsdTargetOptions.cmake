# Compile options for vsd's own targets. Everything here is PRIVATE so that
# consumers never inherit our warnings, -Werror or sanitizer flags.
function(vsd_target_options target)
  target_compile_features(${target} PUBLIC cxx_std_20)
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
    if(VSD_BUILD_FUZZERS)
      # Coverage for libFuzzer in every vsd target; the fuzzers themselves link the fuzzer runtime.
      target_compile_options(${target} PRIVATE -fsanitize=fuzzer-no-link,address,undefined -fno-omit-frame-pointer
                                               -fno-sanitize-recover=all)
      target_link_options(${target} PRIVATE -fsanitize=address,undefined)
    elseif(VSD_SANITIZE)
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
