# SPDX-License-Identifier: MIT
# A fully static rcal program (issue 15, speed): the dynamic loader spends
# about 1.5 ms per run resolving LAPACKE -> LAPACK -> BLAS/ATLAS ->
# gfortran -> quadmath and libserialport, as long as a whole calibration of
# the demo data. When the system has the static archives (Debian's -dev
# packages ship them) the program is linked with -static; when a trial link
# fails (no archive, another BLAS layout) it stays dynamic and configure says
# so. The libraries (rcal::core, rcal::host) are unchanged; only the program.
#
# rcal_static_probe(<out>): sets <out> to the list of archives (after
# LAPACKE: LAPACK, a BLAS and its run-time; the reference ones when
# cmake/rcal_lapack.cmake pins them) that link a static program
# calling the LAPACKE and libserialport functions rcal uses, or to "" when
# none of the known layouts links.

function(rcal_static_probe out)
  set(${out} "" PARENT_SCOPE)
  foreach(n lapacke lapack blas atlas openblas serialport)
    find_library(RCAL_A_${n} NAMES lib${n}.a)
  endforeach()
  foreach(n gfortran quadmath)
    execute_process(COMMAND ${CMAKE_C_COMPILER} -print-file-name=lib${n}.a
      OUTPUT_VARIABLE p OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
    if(p AND IS_ABSOLUTE "${p}" AND EXISTS "${p}")
      set(RCAL_A_${n} ${p})
    else()
      set(RCAL_A_${n} "")
    endif()
  endforeach()
  # Pinned (cmake/rcal_lapack.cmake): the reference archives by their own
  # place, never the alternatives' liblapack.a/libblas.a.
  if(RCAL_LAPACK_PINNED)
    set(RCAL_A_lapacke ${RCAL_REF_LAPACKE_A})
    set(RCAL_A_lapack ${RCAL_REF_LAPACK_A})
    set(RCAL_A_blas ${RCAL_REF_BLAS_A})
    set(RCAL_A_atlas "")
    set(RCAL_A_openblas "")
  endif()
  if(NOT RCAL_A_lapacke OR NOT RCAL_A_lapack OR NOT RCAL_A_gfortran)
    return()
  endif()
  set(src ${CMAKE_BINARY_DIR}/rcal_static_probe.c)
  file(WRITE ${src} "/* written by cmake/rcal_static.cmake */
#include <math.h>
int LAPACKE_dsyev(int, char, char, int, double *, int, double *);
int LAPACKE_dgesvd(int, char, char, int, int, double *, int, double *, double *, int, double *, int, double *);
int LAPACKE_dgeqrf(int, int, int, double *, int, double *);
int LAPACKE_dorgqr(int, int, int, int, double *, int, const double *);
int sp_get_port_by_name(const char *, void **);
int main(int argc, char **argv)
{
    double a[4] = {2.0, 1.0, 1.0, 2.0}, w[2], s[2], u[4], vt[4], sb[2], tau[2];
    (void)argv;
    if (argc > 5) {
        void *p = 0;
        return sp_get_port_by_name(\"x\", &p);
    }
    int r = LAPACKE_dsyev(102, 'V', 'U', 2, a, 2, w);
    r |= LAPACKE_dgesvd(102, 'A', 'A', 2, 2, a, 2, s, u, 2, vt, 2, sb);
    r |= LAPACKE_dgeqrf(102, 2, 2, a, 2, tau);
    r |= LAPACKE_dorgqr(102, 2, 2, 2, a, 2, tau);
    return r != 0 || !(sqrt(w[1]) > 0.0);
}
")
  set(tail ${RCAL_A_gfortran})
  if(RCAL_A_quadmath)
    list(APPEND tail ${RCAL_A_quadmath})
  endif()
  set(cands "")
  if(RCAL_A_blas)
    list(APPEND cands "${RCAL_A_blas}")
    if(RCAL_A_atlas)
      list(APPEND cands "${RCAL_A_blas}|${RCAL_A_atlas}")
    endif()
  endif()
  if(RCAL_A_openblas)
    list(APPEND cands "${RCAL_A_openblas}|-lpthread")
  endif()
  set(sp "")
  if(RCAL_A_serialport)
    set(sp ${RCAL_A_serialport})
  endif()
  foreach(c ${cands})
    string(REPLACE "|" ";" blas "${c}")
    set(libs ${RCAL_A_lapacke} ${RCAL_A_lapack} ${blas} ${tail} ${sp} m)
    try_compile(RCAL_STATIC_PROBE_OK ${CMAKE_BINARY_DIR}/rcal_static_probe SOURCES ${src}
      LINK_OPTIONS -static LINK_LIBRARIES ${libs})
    if(RCAL_STATIC_PROBE_OK)
      set(${out} ${RCAL_A_lapack} ${blas} ${tail} PARENT_SCOPE)
      return()
    endif()
  endforeach()
endfunction()
