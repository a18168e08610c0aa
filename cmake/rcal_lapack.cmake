# SPDX-License-Identifier: MIT
# rcal_lapack.cmake - the one BLAS/LAPACK every rcal binary computes with.
#
# Debian's liblapack.so.3 / libblas.so.3 (and liblapack.a / libblas.a) are
# update-alternatives links: installing a package that brings ATLAS or
# OpenBLAS switches them, and the same source then built (or merely ran) an
# rcal whose outputs differed in 11 of 44 golden runs. So rcal links the
# reference implementations' archives by their own place, which no
# alternative moves: <libdir>/lapack/liblapack.a and <libdir>/blas/libblas.a
# (liblapack-dev, libblas-dev; <libdir> is the compiler's multiarch library
# directory, so any architecture), after LAPACKE's liblapacke.a
# (liblapacke-dev). They go into every binary that computes: the rcal
# program, the test programs, librcal_ffi.so (Python) and a shared
# librcalhost.so (hidden there: -Wl,--exclude-libs), so neither the
# alternatives, LD_LIBRARY_PATH, LD_PRELOAD nor a library another module of
# the process loaded first (numpy's) can change a result. The Fortran
# run-time is linked shared (libgfortran.a is not position-independent),
# static in a static program.
#
# RCAL_PIN_REFERENCE_LAPACK=OFF links the system's shared LAPACKE instead
# (whatever BLAS/LAPACK the loader finds at run time; rcal --version names
# it). ON (the default) fails at configure time when the archives are
# missing.
#
# Sets:
#   RCAL_LAPACK_PINNED       ON/OFF
#   RCAL_LAPACK_ARCHIVES     liblapacke.a, the reference liblapack.a and libblas.a (pinned)
#   RCAL_LAPACK_SHARED_TAIL  what follows them in a dynamic link (the shared libgfortran, libm)
#   RCAL_LAPACK_BUILT        one line for rcal --version: what the build linked
#   RCAL_LAPACK_VERSION      the pinned LAPACK's ILAVER ("3.11.0"; "" unpinned or cross-compiling)
#   LAPACKE_LIB, LAPACKE_INCLUDE
# and rcal_lapack_target(), which defines rcal::lapacke (the same name
# rcalConfig.cmake defines on a consumer's side). A target with the property RCAL_STATIC_LINK (the rcal
# program linked -static, cmake/rcal_static.cmake) gets the static Fortran
# run-time instead.

option(RCAL_PIN_REFERENCE_LAPACK "Link the reference LAPACK and BLAS archives (not the system's alternative)" ON)
find_library(LAPACKE_LIB lapacke REQUIRED)
find_path(LAPACKE_INCLUDE lapacke.h PATHS /usr/include /usr/include/lapacke REQUIRED)

# rcal_lapack_reference_dirs(<out> <sub>): <d>/<sub> for each library
# directory of the compiler (/usr/lib/x86_64-linux-gnu/lapack, ...).
function(rcal_lapack_reference_dirs out sub)
  set(dirs "")
  foreach(d ${CMAKE_C_IMPLICIT_LINK_DIRECTORIES})
    list(APPEND dirs ${d}/${sub})
  endforeach()
  if(CMAKE_LIBRARY_ARCHITECTURE)
    list(APPEND dirs /usr/lib/${CMAKE_LIBRARY_ARCHITECTURE}/${sub})
  endif()
  set(${out} ${dirs} PARENT_SCOPE)
endfunction()

# rcal_compiler_file(<out> <name>): the compiler's own file <name>
# (libgfortran.a, ...), or "".
function(rcal_compiler_file out name)
  execute_process(COMMAND ${CMAKE_C_COMPILER} -print-file-name=${name}
    OUTPUT_VARIABLE p OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
  if(p AND IS_ABSOLUTE "${p}" AND EXISTS "${p}")
    set(${out} ${p} PARENT_SCOPE)
  else()
    set(${out} "" PARENT_SCOPE)
  endif()
endfunction()

set(RCAL_LAPACK_PINNED OFF)
set(RCAL_LAPACK_ARCHIVES "")
set(RCAL_LAPACK_SHARED_TAIL m)
set(RCAL_LAPACK_VERSION "")
if(RCAL_PIN_REFERENCE_LAPACK)
  rcal_lapack_reference_dirs(_lapack_dirs lapack)
  rcal_lapack_reference_dirs(_blas_dirs blas)
  find_library(RCAL_REF_LAPACKE_A NAMES liblapacke.a)
  find_library(RCAL_REF_LAPACK_A NAMES liblapack.a PATHS ${_lapack_dirs} NO_DEFAULT_PATH)
  find_library(RCAL_REF_BLAS_A NAMES libblas.a PATHS ${_blas_dirs} NO_DEFAULT_PATH)
  rcal_compiler_file(_gfortran_so libgfortran.so)
  if(NOT _gfortran_so)
    find_library(_gfortran_so NAMES gfortran libgfortran.so.5)
  endif()
  set(_missing "")
  foreach(v RCAL_REF_LAPACKE_A RCAL_REF_LAPACK_A RCAL_REF_BLAS_A _gfortran_so)
    if(NOT ${v})
      list(APPEND _missing ${v})
    endif()
  endforeach()
  if(_missing)
    message(FATAL_ERROR "rcal links the reference LAPACK and BLAS archives by their own place "
      "(<libdir>/lapack/liblapack.a, <libdir>/blas/libblas.a, liblapacke.a, the Fortran run-time), "
      "so that no alternative (ATLAS, OpenBLAS) changes its results; not found: ${_missing} "
      "(searched ${_lapack_dirs} ${_blas_dirs}). Debian: scripts/install-deps.sh (liblapacke-dev "
      "liblapack-dev libblas-dev gfortran), or configure with -DRCAL_PIN_REFERENCE_LAPACK=OFF to link the "
      "system's LAPACKE (results then follow the system's BLAS/LAPACK; rcal --version names it).")
  endif()
  # one name per file (merged /usr: /lib/<arch>/lapack is /usr/lib/<arch>/lapack)
  foreach(v RCAL_REF_LAPACKE_A RCAL_REF_LAPACK_A RCAL_REF_BLAS_A)
    get_filename_component(${v} ${${v}} REALPATH)
  endforeach()
  set(RCAL_LAPACK_PINNED ON)
  set(RCAL_LAPACK_ARCHIVES ${RCAL_REF_LAPACKE_A} ${RCAL_REF_LAPACK_A} ${RCAL_REF_BLAS_A})
  set(RCAL_LAPACK_SHARED_TAIL ${_gfortran_so} m)
  set(RCAL_LAPACK_BUILT "${RCAL_REF_LAPACK_A}, ${RCAL_REF_BLAS_A}")
  # The pinned LAPACK's version (ILAVER), for the test that the program runs
  # with it (tests/system/pkg: pkg_lapack_pinned).
  if(NOT CMAKE_CROSSCOMPILING)
    set(_src ${CMAKE_BINARY_DIR}/rcal_lapack_version.c)
    file(WRITE ${_src} "/* written by cmake/rcal_lapack.cmake */
#include <stdio.h>
void ilaver_(int *major, int *minor, int *patch);
int main(void)
{
    int a = 0, b = 0, c = 0;
    ilaver_(&a, &b, &c);
    printf(\"%d.%d.%d\", a, b, c);
    return 0;
}
")
    try_run(_run_rc _compile_ok ${CMAKE_BINARY_DIR}/rcal_lapack_version SOURCES ${_src}
      LINK_LIBRARIES ${RCAL_REF_LAPACK_A} ${RCAL_REF_BLAS_A} ${RCAL_LAPACK_SHARED_TAIL}
      RUN_OUTPUT_VARIABLE _ver COMPILE_OUTPUT_VARIABLE _log)
    if(NOT _compile_ok OR NOT _run_rc EQUAL 0 OR NOT _ver MATCHES "^[0-9]+\\.[0-9]+\\.[0-9]+$")
      message(FATAL_ERROR "the reference LAPACK ${RCAL_REF_LAPACK_A} with ${RCAL_REF_BLAS_A} does not link "
        "into a program (or its ILAVER does not run): ${_log}")
    endif()
    set(RCAL_LAPACK_VERSION ${_ver})
  endif()
  message(STATUS "BLAS/LAPACK: reference LAPACK ${RCAL_LAPACK_VERSION} (${RCAL_REF_LAPACK_A}) and BLAS "
    "(${RCAL_REF_BLAS_A}), linked in (pinned)")
else()
  set(RCAL_LAPACK_BUILT "the system's LAPACKE ${LAPACKE_LIB} and the BLAS/LAPACK the loader finds at run time")
  message(STATUS "BLAS/LAPACK: NOT pinned (RCAL_PIN_REFERENCE_LAPACK=OFF): ${LAPACKE_LIB} and whatever "
    "liblapack.so.3/libblas.so.3 the loader finds")
endif()

# rcal_lapack_target(): rcal::lapacke, the archives (pinned) or the shared
# LAPACKE; called once RCAL_PROGRAM_STATIC is known. A static
# program (RCAL_STATIC_LINK) gets the archives cmake/rcal_static.cmake
# found to link -static (RCAL_STATIC_LAPACK_DEPS: LAPACK, BLAS, the static
# Fortran run-time).
function(rcal_lapack_target)
  if(TARGET rcal::lapacke)
    return()
  endif()
  add_library(rcal::lapacke INTERFACE IMPORTED GLOBAL)
  set_target_properties(rcal::lapacke PROPERTIES INTERFACE_INCLUDE_DIRECTORIES ${LAPACKE_INCLUDE})
  if(RCAL_LAPACK_PINNED)
    set(_dyn ${RCAL_LAPACK_ARCHIVES} ${RCAL_LAPACK_SHARED_TAIL})
  else()
    set(_dyn ${LAPACKE_LIB})
  endif()
  if(RCAL_PROGRAM_STATIC)
    set(_st "$<BOOL:$<TARGET_PROPERTY:RCAL_STATIC_LINK>>")
    set(_libs "")
    foreach(a ${_dyn})
      list(APPEND _libs "$<$<NOT:${_st}>:${a}>")
    endforeach()
    foreach(a ${RCAL_A_lapacke} ${RCAL_STATIC_LAPACK_DEPS})
      list(APPEND _libs "$<${_st}:${a}>")
    endforeach()
    set_target_properties(rcal::lapacke PROPERTIES INTERFACE_LINK_LIBRARIES "${_libs}")
  else()
    set_target_properties(rcal::lapacke PROPERTIES INTERFACE_LINK_LIBRARIES "${_dyn}")
  endif()
endfunction()
