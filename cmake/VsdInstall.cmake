# Install rules and CMake package files for vsd (included by the top level when VSD_INSTALL is ON).
#
# Produces
#   <prefix>/lib/libvsd_core.a, <prefix>/include/vsd/...
#   <prefix>/lib/cmake/vsd/{vsdConfig,vsdConfigVersion,vsdTargets*}.cmake   -> find_package(vsd CONFIG)
#   <build>/{vsdConfig,vsdConfigVersion,vsdTargets}.cmake                     -> -Dvsd_DIR=<build> also works
# and the imported targets vsd::<EXPORT_NAME>, e.g. vsd::core.
#
# Adding a library module to the package
# ---------------------------------------
# This file is included *after* add_subdirectory(src), so a module's CMakeLists.txt cannot call a
# function defined here. Modules therefore register themselves through a GLOBAL property, which is
# order-independent and crosses directory scopes:
#
#     set_property(GLOBAL APPEND PROPERTY VSD_INSTALL_TARGETS vsd_foo)      # next to add_library(vsd_foo)
#     set_target_properties(vsd_foo PROPERTIES EXPORT_NAME foo)             # -> vsd::foo for consumers
#
# and, if the module links a package's imported target beyond Eigen3/Threads, a find_dependency() line
# for vsdConfig.cmake. Note that vsd's libraries are STATIC, so even PRIVATE link dependencies end up in
# the exported interface (as $<LINK_ONLY:...>) and need this line:
#
#     set_property(GLOBAL APPEND PROPERTY VSD_INSTALL_DEPENDENCIES "Boost 1.74")  # args of find_dependency
#
# vsd_core is always installed. Every registered target goes into the single export set `vsdTargets`.
# For code that runs after this file (rare), vsd_install_target(<tgt>) does the same registration and
# installs the target immediately.

include_guard(GLOBAL)
include(CMakePackageConfigHelpers)

set(VSD_INSTALL_CMAKEDIR "${CMAKE_INSTALL_LIBDIR}/cmake/vsd"
    CACHE STRING "Install directory (relative to the prefix) of vsd's CMake package files")
mark_as_advanced(VSD_INSTALL_CMAKEDIR)

# install(TARGETS) for one target into the vsdTargets export set.
function(_vsd_install_one tgt)
  if(NOT TARGET ${tgt})
    message(FATAL_ERROR "vsd install: '${tgt}' was registered for installation but is not a target")
  endif()
  install(TARGETS ${tgt}
    EXPORT vsdTargets
    ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT vsd_development
    LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT vsd_runtime
            NAMELINK_COMPONENT vsd_development
    RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR} COMPONENT vsd_runtime
    INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
endfunction()

# Late registration, for targets created after this file was included.
function(vsd_install_target tgt)
  get_property(registered GLOBAL PROPERTY VSD_INSTALL_TARGETS)
  if(tgt STREQUAL "vsd_core" OR tgt IN_LIST registered)
    return()  # already installed
  endif()
  set_property(GLOBAL APPEND PROPERTY VSD_INSTALL_TARGETS ${tgt})
  _vsd_install_one(${tgt})
endfunction()

# --- targets -------------------------------------------------------------------------------------------
get_property(_vsd_install_targets GLOBAL PROPERTY VSD_INSTALL_TARGETS)
list(PREPEND _vsd_install_targets vsd_core)
list(REMOVE_DUPLICATES _vsd_install_targets)
foreach(_vsd_tgt IN LISTS _vsd_install_targets)
  _vsd_install_one(${_vsd_tgt})
endforeach()
message(STATUS "vsd: installing targets ${_vsd_install_targets}")

# --- headers -------------------------------------------------------------------------------------------
install(DIRECTORY "${PROJECT_SOURCE_DIR}/include/"
  DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}
  COMPONENT vsd_development
  FILES_MATCHING PATTERN "*.hpp" PATTERN "*.h" PATTERN "*.inl" PATTERN "*.ipp")

# --- export set: install tree and build tree ----------------------------------------------------------
install(EXPORT vsdTargets
  NAMESPACE vsd::
  FILE vsdTargets.cmake
  DESTINATION ${VSD_INSTALL_CMAKEDIR}
  COMPONENT vsd_development)

export(EXPORT vsdTargets
  NAMESPACE vsd::
  FILE "${PROJECT_BINARY_DIR}/vsdTargets.cmake")

# --- vsdConfig.cmake / vsdConfigVersion.cmake --------------------------------------------------------
# Extra find_dependency() lines registered by modules (see the top of this file).
get_property(_vsd_extra_deps GLOBAL PROPERTY VSD_INSTALL_DEPENDENCIES)
list(REMOVE_DUPLICATES _vsd_extra_deps)
set(VSD_CONFIG_EXTRA_DEPENDENCIES "")
foreach(_vsd_dep IN LISTS _vsd_extra_deps)
  string(APPEND VSD_CONFIG_EXTRA_DEPENDENCIES "find_dependency(${_vsd_dep})\n")
endforeach()

# One config file serves both trees: it only includes vsdTargets.cmake from its own directory.
configure_package_config_file(
  "${CMAKE_CURRENT_LIST_DIR}/vsdConfig.cmake.in"
  "${PROJECT_BINARY_DIR}/vsdConfig.cmake"
  INSTALL_DESTINATION ${VSD_INSTALL_CMAKEDIR})

write_basic_package_version_file(
  "${PROJECT_BINARY_DIR}/vsdConfigVersion.cmake"
  VERSION ${PROJECT_VERSION}
  COMPATIBILITY SameMajorVersion)

install(FILES
  "${PROJECT_BINARY_DIR}/vsdConfig.cmake"
  "${PROJECT_BINARY_DIR}/vsdConfigVersion.cmake"
  DESTINATION ${VSD_INSTALL_CMAKEDIR}
  COMPONENT vsd_development)

if(EXISTS "${PROJECT_SOURCE_DIR}/LICENSE")
  install(FILES "${PROJECT_SOURCE_DIR}/LICENSE"
    DESTINATION ${CMAKE_INSTALL_DATADIR}/doc/vsd
    COMPONENT vsd_development)
endif()

unset(_vsd_install_targets)
unset(_vsd_extra_deps)
unset(_vsd_tgt)
unset(_vsd_dep)
