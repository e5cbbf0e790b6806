# SPDX-License-Identifier: MIT
# Install rules of the runtime: libraries, public headers, the CMake package `aggrelod`
# (components runtime and collision) and the pkg-config files aggrelod-runtime.pc and
# aggrelod-runtime-collision.pc. Included from runtime/CMakeLists.txt, in the full build and in
# a runtime-only one (AGGRELOD_RUNTIME_ONLY). Install components: `runtime` and `collision`
# (cmake --install BUILD --component runtime).
include(CMakePackageConfigHelpers)

set(AGGRELOD_INSTALL_CMAKEDIR "${CMAKE_INSTALL_LIBDIR}/cmake/aggrelod" CACHE STRING
  "Where the aggrelod CMake package files are installed, relative to the prefix")
set(AGGRELOD_INSTALL_PKGCONFIGDIR "${CMAKE_INSTALL_LIBDIR}/pkgconfig" CACHE STRING
  "Where aggrelod-runtime.pc and aggrelod-runtime-collision.pc are installed, relative to the prefix")
set(_aggrelod_runtime_dir ${CMAKE_CURRENT_LIST_DIR}/..)

# --- aggrelod::runtime (standard library only) ----------------------------------------------
install(TARGETS aggrelod_runtime EXPORT aggrelod_runtime_targets
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT runtime
  LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT runtime
  RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR} COMPONENT runtime)
# Every public header (aggrelod_runtime.h, aggrelod/*.h) but the collision one.
install(DIRECTORY ${_aggrelod_runtime_dir}/include/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR} COMPONENT runtime
  FILES_MATCHING PATTERN "*.h" PATTERN "collision.h" EXCLUDE)
install(EXPORT aggrelod_runtime_targets NAMESPACE aggrelod:: FILE aggrelod-runtime-targets.cmake
  DESTINATION ${AGGRELOD_INSTALL_CMAKEDIR} COMPONENT runtime)
install(FILES ${_aggrelod_runtime_dir}/LICENSE DESTINATION ${CMAKE_INSTALL_DATADIR}/doc/aggrelod-runtime
  COMPONENT runtime)

# --- aggrelod::runtime_collision (Embree 3) --------------------------------------------------
if(TARGET aggrelod_runtime_collision)
  install(TARGETS aggrelod_runtime_collision EXPORT aggrelod_collision_targets
    ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT collision
    LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT collision
    RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR} COMPONENT collision)
  install(FILES ${_aggrelod_runtime_dir}/include/aggrelod/collision.h
    DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/aggrelod COMPONENT collision)
  install(EXPORT aggrelod_collision_targets NAMESPACE aggrelod:: FILE aggrelod-collision-targets.cmake
    DESTINATION ${AGGRELOD_INSTALL_CMAKEDIR} COMPONENT collision)
endif()

# --- CMake package: find_package(aggrelod CONFIG COMPONENTS runtime collision) ---------------
configure_package_config_file(${CMAKE_CURRENT_LIST_DIR}/aggrelod-config.cmake.in
  ${CMAKE_CURRENT_BINARY_DIR}/aggrelod-config.cmake
  INSTALL_DESTINATION ${AGGRELOD_INSTALL_CMAKEDIR})
# 0.x: a new minor version may change the API, so only the same major.minor matches.
write_basic_package_version_file(${CMAKE_CURRENT_BINARY_DIR}/aggrelod-config-version.cmake
  VERSION ${PROJECT_VERSION} COMPATIBILITY SameMinorVersion)
install(FILES ${CMAKE_CURRENT_BINARY_DIR}/aggrelod-config.cmake ${CMAKE_CURRENT_BINARY_DIR}/aggrelod-config-version.cmake
  DESTINATION ${AGGRELOD_INSTALL_CMAKEDIR} COMPONENT runtime)

# --- pkg-config ------------------------------------------------------------------------------
# The libraries are static: Libs carries what they need from the C++ compiler's own runtime
# (for GCC: -lstdc++ -lm), so that a C program links with `pkg-config --libs` alone. That list
# is what CMake itself adds when a C program links C++ code: the C++ compiler's implicit
# libraries that the C compiler does not link.
set(_aggrelod_cxx_libs "")
foreach(_lib IN LISTS CMAKE_CXX_IMPLICIT_LINK_LIBRARIES)
  if(NOT _lib IN_LIST CMAKE_C_IMPLICIT_LINK_LIBRARIES)
    if(_lib MATCHES "^-" OR IS_ABSOLUTE "${_lib}")
      list(APPEND _aggrelod_cxx_libs "${_lib}")
    else()
      list(APPEND _aggrelod_cxx_libs "-l${_lib}")
    endif()
  endif()
endforeach()
list(REMOVE_DUPLICATES _aggrelod_cxx_libs)
list(JOIN _aggrelod_cxx_libs " " _aggrelod_cxx_libs)
if(_aggrelod_cxx_libs)
  set(_aggrelod_cxx_libs " ${_aggrelod_cxx_libs}")
endif()
# Relocatable: the prefix is found from the .pc file's own place (pkg-config's ${pcfiledir}),
# so `cmake --install BUILD --prefix DIR` gives working files for any DIR.
if(IS_ABSOLUTE "${AGGRELOD_INSTALL_PKGCONFIGDIR}")
  set(AGGRELOD_PC_PREFIX "${CMAKE_INSTALL_PREFIX}")
  set(AGGRELOD_PC_PKGCONFIGDIR "${AGGRELOD_INSTALL_PKGCONFIGDIR}")
else()
  file(RELATIVE_PATH _up "/_/${AGGRELOD_INSTALL_PKGCONFIGDIR}" "/_")
  string(REGEX REPLACE "/$" "" _up "${_up}")
  set(AGGRELOD_PC_PREFIX "\${pcfiledir}/${_up}")
  set(AGGRELOD_PC_PKGCONFIGDIR "${AGGRELOD_INSTALL_PKGCONFIGDIR}")
endif()
foreach(_dir INCLUDEDIR LIBDIR)
  if(IS_ABSOLUTE "${CMAKE_INSTALL_${_dir}}")
    set(AGGRELOD_PC_${_dir} "${CMAKE_INSTALL_${_dir}}")
  else()
    set(AGGRELOD_PC_${_dir} "\${prefix}/${CMAKE_INSTALL_${_dir}}")
  endif()
endforeach()
set(AGGRELOD_PC_CXX_LIBS "${_aggrelod_cxx_libs}")
configure_file(${CMAKE_CURRENT_LIST_DIR}/aggrelod-runtime.pc.in ${CMAKE_CURRENT_BINARY_DIR}/aggrelod-runtime.pc @ONLY)
install(FILES ${CMAKE_CURRENT_BINARY_DIR}/aggrelod-runtime.pc DESTINATION ${AGGRELOD_PC_PKGCONFIGDIR}
  COMPONENT runtime)

if(TARGET aggrelod_runtime_collision)
  # Embree 3 ships no .pc file: link its library by the path its CMake package gives.
  get_target_property(_embree_library embree LOCATION)
  if(NOT _embree_library)
    message(FATAL_ERROR "aggrelod: cannot tell where the Embree library is (target embree has no LOCATION)")
  endif()
  get_filename_component(_embree_dir "${_embree_library}" DIRECTORY)
  get_filename_component(_embree_name "${_embree_library}" NAME_WE)
  string(REGEX REPLACE "^lib" "" _embree_name "${_embree_name}")
  set(AGGRELOD_PC_EMBREE_LIBS "-L${_embree_dir} -l${_embree_name}")
  configure_file(${CMAKE_CURRENT_LIST_DIR}/aggrelod-runtime-collision.pc.in
    ${CMAKE_CURRENT_BINARY_DIR}/aggrelod-runtime-collision.pc @ONLY)
  install(FILES ${CMAKE_CURRENT_BINARY_DIR}/aggrelod-runtime-collision.pc DESTINATION ${AGGRELOD_PC_PKGCONFIGDIR}
    COMPONENT collision)
endif()
