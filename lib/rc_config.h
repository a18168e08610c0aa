/* SPDX-License-Identifier: MIT */
/* rc_config.h - compile-time limits and contract checks of the rcal core.
 *
 * The core (lib/) is C99 with no heap, no stdio and no global state. Every
 * buffer is caller-owned and sized by the limits below (from the generated
 * rc_version.h). Contract violations (a NULL where the API forbids it)
 * go to RC_ASSERT, which a firmware build may redirect; runtime failures are
 * returned as rc_status codes (rc_status.h).
 */
#ifndef RC_CONFIG_H
#define RC_CONFIG_H

/* Joints of the serial arm and DH parameters per joint (a, d, alpha, theta). */
#define RC_NJ 6
#define RC_DH_PER_JOINT 4
#define RC_N_DH (RC_NJ * RC_DH_PER_JOINT) /* 24 */
#define RC_N_ENC 3                        /* encoder outlet e (x, y, z) */
#define RC_N_BASE (RC_N_DH + RC_N_ENC)    /* 27: geometry + encoder */

/* Version and compile-time limits, generated at configure time and installed
 * with the headers (cmake/rcal_version_header.cmake): RC_MAX_PARAMS, the
 * maximum number of model parameters (27 base plus model extensions,
 * rc_model.h effects), and RC_MAX_EFFECTS, the maximum number of model
 * extensions. Set them with -DRCAL_MAX_PARAMS=n -DRCAL_MAX_EFFECTS=n when
 * configuring; a -D of another value to the compiler is refused. */
#include "rc_version.h"
#if RC_MAX_PARAMS < RC_N_BASE
#error "RC_MAX_PARAMS must be at least 27 (24 DH parameters + encoder position)"
#endif
#if RC_MAX_PARAMS > 1024
#error "RC_MAX_PARAMS above 1024 makes the solver workspace unreasonably large"
#endif

#if RC_MAX_EFFECTS < 1 || RC_MAX_EFFECTS > 64
#error "RC_MAX_EFFECTS must be within 1..64"
#endif

/* ---- Scalar type of the kinematics and compensation path (rc_kin, rc_comp).
 * rc_real is double by default; -DRC_REAL_FLOAT
 * makes it float for a single-precision FPU (Cortex-M4F), where a double
 * costs a soft-float library call. The solvers and estimators (rc_model's
 * parameter vector, rc_solve, rc_est) stay double: they run on the host.
 * RC_REAL_C(1.5) writes a literal of the type (1.5 or 1.5f), RC_REAL_EPS its
 * machine epsilon; tolerances of the compensation are derived from it
 * (rc_comp.h). */
#ifdef RC_REAL_FLOAT
typedef float rc_real;
#define RC_REAL_IS_FLOAT 1
#define RC_REAL_C(x) x##f
#define RC_REAL_EPS 1.1920929e-07f /* FLT_EPSILON */
#define RC_REAL_NAME "float"
#else
typedef double rc_real;
#define RC_REAL_IS_FLOAT 0
#define RC_REAL_C(x) x
#define RC_REAL_EPS 2.220446049250313e-16 /* DBL_EPSILON */
#define RC_REAL_NAME "double"
#endif
/* ---- end of the scalar type block */

/* Contract checks. Default: the C library's assert (compiled out by NDEBUG).
 * Firmware may define RC_ASSERT to its own fault handler. */
#ifndef RC_ASSERT
#include <assert.h>
#define RC_ASSERT(cond) assert(cond)
#endif

#define RC_STATIC_ASSERT(cond, name) typedef char rc_static_assert_##name[(cond) ? 1 : -1]

#endif /* RC_CONFIG_H */
