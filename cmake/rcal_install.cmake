# SPDX-License-Identifier: MIT
# rcal_install.cmake - what `cmake --install` adds beside the targets: the
# exported targets (rcal::core, rcal::host), rcalConfig.cmake and its version
# file for find_package(rcal CONFIG), rcal.pc for pkg-config, the data files
# under share/rcal and the licence. Included by the top CMakeLists.txt after
# the targets exist.
include(CMakePackageConfigHelpers)

set(RCAL_INSTALL_CMAKEDIR ${CMAKE_INSTALL_LIBDIR}/cmake/rcal)
set(RCAL_INSTALL_DATADIR ${CMAKE_INSTALL_DATADIR}/rcal)

install(EXPORT rcalTargets NAMESPACE rcal:: DESTINATION ${RCAL_INSTALL_CMAKEDIR} FILE rcalTargets.cmake)

# A static rcal::host carries LAPACKE as a link-only dependency; the config
# file finds it on the consumer's machine (no build-machine path installed):
# the reference LAPACK and BLAS archives by their own place when this build
# pinned them (cmake/rcal_lapack.cmake), so that a consumer computes as rcal
# does. A shared librcalhost.so has them inside.
if(TARGET rcal_host AND NOT BUILD_SHARED_LIBS)
  set(RCAL_CONFIG_NEEDS_LAPACKE 1)
else()
  set(RCAL_CONFIG_NEEDS_LAPACKE 0)
endif()
if(RCAL_LAPACK_PINNED)
  set(RCAL_CONFIG_LAPACK_PINNED 1)
else()
  set(RCAL_CONFIG_LAPACK_PINNED 0)
endif()
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/rcalConfig.cmake.in
  ${PROJECT_BINARY_DIR}/rcalConfig.cmake
  INSTALL_DESTINATION ${RCAL_INSTALL_CMAKEDIR}
  PATH_VARS RCAL_INSTALL_DATADIR CMAKE_INSTALL_INCLUDEDIR)
# Before 1.0 a minor version may break the API: only the same MAJOR.MINOR
# satisfies a request (as the SONAME says).
if(PROJECT_VERSION_MAJOR EQUAL 0)
  set(_rcal_compat SameMinorVersion)
else()
  set(_rcal_compat SameMajorVersion)
endif()
write_basic_package_version_file(${PROJECT_BINARY_DIR}/rcalConfigVersion.cmake
  VERSION ${PROJECT_VERSION} COMPATIBILITY ${_rcal_compat})
install(FILES ${PROJECT_BINARY_DIR}/rcalConfig.cmake ${PROJECT_BINARY_DIR}/rcalConfigVersion.cmake
  DESTINATION ${RCAL_INSTALL_CMAKEDIR})

# pkg-config: relocatable (prefix from the .pc file's own place).
file(RELATIVE_PATH RCAL_PC_TO_PREFIX /x/${CMAKE_INSTALL_LIBDIR}/pkgconfig /x)
string(REGEX REPLACE "/$" "" RCAL_PC_TO_PREFIX "${RCAL_PC_TO_PREFIX}")
if(TARGET rcal_host AND RCAL_LAPACK_PINNED)
  # the reference archives by their place in the system (Debian's
  # liblapack-dev, libblas-dev), never -llapack (an alternative)
  set(RCAL_PC_LIBS "-lrcalhost -lrcalcore")
  # -lexpat: the host library's URDF reader (rch_urdf.c)
  string(REPLACE ";" " " RCAL_PC_LIBS_PRIVATE "${RCAL_LAPACK_ARCHIVES};-l:libgfortran.so.5;-lexpat;-lm")
elseif(TARGET rcal_host)
  set(RCAL_PC_LIBS "-lrcalhost -lrcalcore")
  set(RCAL_PC_LIBS_PRIVATE "-llapacke -lexpat -lm")
else()
  set(RCAL_PC_LIBS "-lrcalcore")
  set(RCAL_PC_LIBS_PRIVATE "-lm")
endif()
configure_file(${PROJECT_SOURCE_DIR}/cmake/rcal.pc.in ${PROJECT_BINARY_DIR}/rcal.pc @ONLY)
install(FILES ${PROJECT_BINARY_DIR}/rcal.pc DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)

# Data the tools read at run time (the nominal IRB120, the demo data set):
# found by rch_data_path() relative to the installed program.
install(DIRECTORY ${PROJECT_SOURCE_DIR}/data/ DESTINATION ${RCAL_INSTALL_DATADIR})
install(FILES ${PROJECT_SOURCE_DIR}/LICENSE DESTINATION ${CMAKE_INSTALL_DATADIR}/doc/rcal)
