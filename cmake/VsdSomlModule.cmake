# vsd_add_soml_module(TARGET SCRIPT... [TOOL path]): a native library of SOML++ scripts (docs/soml.md,
# "Native compilation"). `vsd-soml compile SCRIPT... -o DIR` generates DIR/soml_native.cpp at build time
# (again whenever a script or the tool changes); TARGET is the shared library (a MODULE: loaded with
# Program::load_native, never linked) built from it. The generated code includes only
# vsd/soml/native_abi.hpp.
#
# The tool: TOOL if given, else the vsd-soml of this build (target vsd_soml_tool), else the one found on
# PATH or next to an installed vsd (find_program). The script must be the same text the program loads:
# a library of another version is refused at load time (image hash).
function(vsd_add_soml_module target)
  cmake_parse_arguments(PARSE_ARGV 1 arg "" "TOOL" "")
  set(scripts "")
  foreach(s IN LISTS arg_UNPARSED_ARGUMENTS)
    get_filename_component(abs "${s}" ABSOLUTE)
    list(APPEND scripts "${abs}")
  endforeach()
  if(NOT scripts)
    message(FATAL_ERROR "vsd_add_soml_module(${target}): no script")
  endif()
  if(arg_TOOL)
    set(tool "${arg_TOOL}")
    set(tool_dep "${arg_TOOL}")
  elseif(TARGET vsd_soml_tool)
    set(tool "$<TARGET_FILE:vsd_soml_tool>")
    set(tool_dep vsd_soml_tool)
  else()
    # Installed: <prefix>/lib/cmake/vsd/ -> <prefix>/bin; a build tree: <build>/tools.
    find_program(VSD_SOML_TOOL vsd-soml
      HINTS "${CMAKE_CURRENT_FUNCTION_LIST_DIR}/../../../bin" "${CMAKE_CURRENT_FUNCTION_LIST_DIR}/tools" REQUIRED)
    set(tool "${VSD_SOML_TOOL}")
    set(tool_dep "${VSD_SOML_TOOL}")
  endif()
  set(dir "${CMAKE_CURRENT_BINARY_DIR}/${target}_soml")
  file(MAKE_DIRECTORY "${dir}")
  add_custom_command(OUTPUT "${dir}/soml_native.cpp"
    COMMAND "${tool}" compile ${scripts} -o "${dir}"
    DEPENDS ${scripts} ${tool_dep}
    COMMENT "vsd-soml compile ${target}"
    VERBATIM)
  add_library(${target} MODULE "${dir}/soml_native.cpp")
  # Only the include directories of vsd::soml (the generated code includes native_abi.hpp, links nothing).
  if(TARGET vsd_soml)
    target_include_directories(${target} PRIVATE $<TARGET_PROPERTY:vsd_soml,INTERFACE_INCLUDE_DIRECTORIES>)
  elseif(TARGET vsd::soml)
    target_include_directories(${target} PRIVATE $<TARGET_PROPERTY:vsd::soml,INTERFACE_INCLUDE_DIRECTORIES>)
  endif()
  target_compile_features(${target} PRIVATE cxx_std_20)
  set_target_properties(${target} PROPERTIES PREFIX "" CXX_VISIBILITY_PRESET hidden)
endfunction()
