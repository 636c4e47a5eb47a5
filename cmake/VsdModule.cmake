# vsd_add_module(): one library module of vsd (vsd::<name>), declared once.
#
#   vsd_add_module(<name>
#     SOURCES <file>...                  the module's sources (relative to the calling directory)
#     [MODULES <module>...]              vsd modules it needs (core, io, scene, ...), linked PUBLIC
#     [PUBLIC <target>...]               further public link dependencies (imported targets)
#     [PRIVATE <target>...]              private link dependencies (imported targets)
#     [FIND_DEPENDENCIES <"args">...]    packages behind PUBLIC/PRIVATE: find_package(<args> QUIET) here, and
#                                        again in a consumer's find_package(vsd COMPONENTS <name>)
#     [PKG_CONFIG <prefix> <module>]     a pkg-config package instead (imported target PkgConfig::<prefix>)
#     [REQUIRE_TARGETS <target>...]      targets the dependencies must provide (default: those of PRIVATE/PUBLIC
#                                        that contain "::")
#     [HINT <text>])                     how to install what is missing (for the "skipping" message)
#
# The option VSD_WITH_<NAME> (declared in the top CMakeLists.txt) switches the module on. When it is off, a
# vsd module it needs was not built, or a dependency is missing, the module is skipped with a message
# (the build goes on) and vsd_<name> is not a target: callers test `if(TARGET vsd_<name>)`.
# Otherwise it defines the static library vsd_<name>, its alias vsd::<name>, the EXPORT_NAME <name> and
# vsd's compile options, and registers the module for installation: its own export set (the component
# <name> of the installed package, see VsdInstall.cmake) with the packages a consumer must find for it.
#
# Every module is also linked into the umbrella target vsd::vsd (vsd_add_umbrella(), at the end of src/).
include_guard(GLOBAL)

function(vsd_add_module name)
  cmake_parse_arguments(PARSE_ARGV 1 arg "" "HINT"
    "SOURCES;MODULES;PUBLIC;PRIVATE;FIND_DEPENDENCIES;PKG_CONFIG;REQUIRE_TARGETS")
  string(TOUPPER "${name}" upper)
  set(target vsd_${name})
  if(NOT name STREQUAL "core" AND DEFINED VSD_WITH_${upper} AND NOT VSD_WITH_${upper})
    return()
  endif()

  # vsd modules first: a module whose prerequisite was skipped is skipped too.
  set(missing "")
  foreach(m IN LISTS arg_MODULES)
    if(NOT TARGET vsd_${m})
      list(APPEND missing "vsd::${m}")
    endif()
  endforeach()
  if(missing)
    list(JOIN missing " and " missing)
    message(STATUS "vsd: skipping vsd::${name} (needs ${missing})")
    return()
  endif()

  # Third-party packages: found here, quietly; each must yield the targets the module links.
  foreach(dep IN LISTS arg_FIND_DEPENDENCIES)
    separate_arguments(dep_args UNIX_COMMAND "${dep}")
    find_package(${dep_args} QUIET)
  endforeach()
  set(pkg_config_target "")
  if(arg_PKG_CONFIG)
    list(GET arg_PKG_CONFIG 0 prefix)
    list(SUBLIST arg_PKG_CONFIG 1 -1 pkg_modules)
    find_package(PkgConfig QUIET)
    if(PkgConfig_FOUND)
      pkg_check_modules(${prefix} QUIET IMPORTED_TARGET GLOBAL ${pkg_modules})
    endif()
    set(pkg_config_target PkgConfig::${prefix})
  endif()
  set(required ${arg_REQUIRE_TARGETS})
  if(NOT arg_REQUIRE_TARGETS)
    foreach(t IN LISTS arg_PUBLIC arg_PRIVATE)
      if(t MATCHES "::")
        list(APPEND required ${t})
      endif()
    endforeach()
  endif()
  foreach(t IN LISTS required pkg_config_target)
    if(NOT TARGET ${t})
      list(APPEND missing ${t})
    endif()
  endforeach()
  if(missing)
    list(JOIN missing ", " missing)
    set(hint "")
    if(arg_HINT)
      set(hint ": ${arg_HINT}")
    endif()
    message(STATUS "vsd: skipping vsd::${name} (${missing} not found${hint})")
    return()
  endif()

  add_library(${target} STATIC ${arg_SOURCES})
  add_library(vsd::${name} ALIAS ${target})
  set_target_properties(${target} PROPERTIES EXPORT_NAME ${name} OUTPUT_NAME ${target})
  set(module_targets "")
  foreach(m IN LISTS arg_MODULES)
    list(APPEND module_targets vsd_${m})
  endforeach()
  target_link_libraries(${target} PUBLIC ${module_targets} ${arg_PUBLIC} PRIVATE ${arg_PRIVATE} ${pkg_config_target})
  if(name STREQUAL "core")
    target_include_directories(${target} PUBLIC
      $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}/include>
      $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
  endif()
  vsd_target_options(${target})
  vsd_fuzz_coverage(${target})

  # For the package (VsdInstall.cmake): the module in dependency order, what it needs.
  set_property(GLOBAL APPEND PROPERTY VSD_MODULES ${name})
  set_property(GLOBAL PROPERTY VSD_MODULE_${name}_MODULES "${arg_MODULES}")
  set_property(GLOBAL PROPERTY VSD_MODULE_${name}_PACKAGES "${arg_FIND_DEPENDENCIES}")
  set_property(GLOBAL PROPERTY VSD_MODULE_${name}_PKG_CONFIG "${arg_PKG_CONFIG}")
endfunction()

# vsd_add_umbrella(): vsd::vsd, an INTERFACE library linking every module that was built (exported as the
# component `vsd` of the package, which asks for all of them).
function(vsd_add_umbrella)
  get_property(modules GLOBAL PROPERTY VSD_MODULES)
  add_library(vsd_vsd INTERFACE)
  add_library(vsd::vsd ALIAS vsd_vsd)
  set_target_properties(vsd_vsd PROPERTIES EXPORT_NAME vsd)
  foreach(m IN LISTS modules)
    target_link_libraries(vsd_vsd INTERFACE vsd_${m})
  endforeach()
endfunction()
