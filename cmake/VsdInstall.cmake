# Install rules and CMake package files for vsd (included by the top level when VSD_INSTALL is ON).
#
# Produces
#   <prefix>/lib/libvsd_<module>.a, <prefix>/include/vsd/...
#   <prefix>/lib/cmake/vsd/vsdConfig.cmake, vsdConfigVersion.cmake       -> find_package(vsd CONFIG)
#   <prefix>/lib/cmake/vsd/vsd-<module>-targets*.cmake                   one export set per module
#   <build>/vsdConfig.cmake, vsd-<module>-targets.cmake                   -> -Dvsd_DIR=<build> also works
# and the imported targets vsd::<module> (vsd::core, vsd::io, ...) and vsd::vsd (all of them).
#
# Components: every module is a component of the package, with its own export set, so that
#   find_package(vsd CONFIG REQUIRED COMPONENTS core)    finds Eigen and Threads and nothing else,
#   find_package(vsd CONFIG REQUIRED COMPONENTS scene)   also urdfdom and assimp (and vsd::core),
#   find_package(vsd CONFIG REQUIRED)                     every installed module and vsd::vsd.
# A module registers itself through vsd_add_module() (cmake/VsdModule.cmake): the vsd modules it links and
# the packages behind its imported link targets (static libraries: even PRIVATE ones reach a consumer's
# link line, as $<LINK_ONLY:...>, so a consumer must find them). Only imported targets are linked, never a
# library path, so the exported files name no path of the machine that built vsd.

include_guard(GLOBAL)
include(CMakePackageConfigHelpers)

set(VSD_INSTALL_CMAKEDIR "${CMAKE_INSTALL_LIBDIR}/cmake/vsd"
    CACHE STRING "Install directory (relative to the prefix) of vsd's CMake package files")
mark_as_advanced(VSD_INSTALL_CMAKEDIR)

# install(TARGETS) of one target into export set @p set, and that set's targets file (install and build tree).
function(_vsd_install_export tgt set)
  install(TARGETS ${tgt}
    EXPORT ${set}
    ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT vsd_development
    LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT vsd_runtime
            NAMELINK_COMPONENT vsd_development
    RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR} COMPONENT vsd_runtime
    INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
  install(EXPORT ${set}
    NAMESPACE vsd::
    FILE ${set}.cmake
    DESTINATION ${VSD_INSTALL_CMAKEDIR}
    COMPONENT vsd_development)
  export(EXPORT ${set} NAMESPACE vsd:: FILE "${PROJECT_BINARY_DIR}/${set}.cmake")
endfunction()

# A CMake list as the arguments of set(): each element quoted.
function(_vsd_quoted_list out)
  set(s "")
  foreach(e IN LISTS ARGN)
    string(APPEND s " \"${e}\"")
  endforeach()
  set(${out} "${s}" PARENT_SCOPE)
endfunction()

# --- targets and what each component needs ----------------------------------------------------------
get_property(_vsd_modules GLOBAL PROPERTY VSD_MODULES)
set(VSD_CONFIG_COMPONENTS "")
foreach(_vsd_m IN LISTS _vsd_modules)
  _vsd_install_export(vsd_${_vsd_m} vsd-${_vsd_m}-targets)
  get_property(_vsd_needs GLOBAL PROPERTY VSD_MODULE_${_vsd_m}_MODULES)
  get_property(_vsd_packages GLOBAL PROPERTY VSD_MODULE_${_vsd_m}_PACKAGES)
  get_property(_vsd_pkg_config GLOBAL PROPERTY VSD_MODULE_${_vsd_m}_PKG_CONFIG)
  _vsd_quoted_list(_vsd_q_needs ${_vsd_needs})
  _vsd_quoted_list(_vsd_q_packages ${_vsd_packages})
  _vsd_quoted_list(_vsd_q_pkg_config ${_vsd_pkg_config})
  string(APPEND VSD_CONFIG_COMPONENTS
    "set(_vsd_${_vsd_m}_modules${_vsd_q_needs})\n"
    "set(_vsd_${_vsd_m}_packages${_vsd_q_packages})\n"
    "set(_vsd_${_vsd_m}_pkg_config${_vsd_q_pkg_config})\n")
endforeach()
_vsd_install_export(vsd_vsd vsd-vsd-targets)   # the umbrella: the component `vsd`
_vsd_quoted_list(VSD_CONFIG_MODULES ${_vsd_modules})
message(STATUS "vsd: installing the modules${VSD_CONFIG_MODULES} and vsd::vsd")

# --- headers -------------------------------------------------------------------------------------------
install(DIRECTORY "${PROJECT_SOURCE_DIR}/include/"
  DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}
  COMPONENT vsd_development
  FILES_MATCHING PATTERN "*.hpp" PATTERN "*.h" PATTERN "*.inl" PATTERN "*.ipp")

# --- vsdConfig.cmake / vsdConfigVersion.cmake --------------------------------------------------------
# One config file serves both trees: it only includes the targets files from its own directory.
configure_package_config_file(
  "${CMAKE_CURRENT_LIST_DIR}/vsdConfig.cmake.in"
  "${PROJECT_BINARY_DIR}/vsdConfig.cmake"
  INSTALL_DESTINATION ${VSD_INSTALL_CMAKEDIR})

write_basic_package_version_file(
  "${PROJECT_BINARY_DIR}/vsdConfigVersion.cmake"
  VERSION ${PROJECT_VERSION}
  COMPATIBILITY SameMajorVersion)

# vsd_add_soml_module() next to the config file in the build tree too (the config includes it from there).
configure_file("${CMAKE_CURRENT_LIST_DIR}/VsdSomlModule.cmake" "${PROJECT_BINARY_DIR}/VsdSomlModule.cmake" COPYONLY)

install(FILES
  "${PROJECT_BINARY_DIR}/vsdConfig.cmake"
  "${PROJECT_BINARY_DIR}/vsdConfigVersion.cmake"
  "${CMAKE_CURRENT_LIST_DIR}/VsdSomlModule.cmake"
  DESTINATION ${VSD_INSTALL_CMAKEDIR}
  COMPONENT vsd_development)

if(EXISTS "${PROJECT_SOURCE_DIR}/LICENSE")
  install(FILES "${PROJECT_SOURCE_DIR}/LICENSE"
    DESTINATION ${CMAKE_INSTALL_DATADIR}/doc/vsd
    COMPONENT vsd_development)
endif()

unset(_vsd_modules)
unset(_vsd_m)
unset(_vsd_needs)
unset(_vsd_packages)
unset(_vsd_pkg_config)
unset(_vsd_q_needs)
unset(_vsd_q_packages)
unset(_vsd_q_pkg_config)
