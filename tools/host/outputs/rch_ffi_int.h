/* SPDX-License-Identifier: MIT */
/* rch_ffi_int.h - what the files of the flat C API share (internal: not
 * installed, not part of rch_ffi.h).
 *
 * What: the handles' layouts (rch_ffi_model, rch_ffi_calib, rch_ffi_diag),
 * the status-and-message helpers and the few functions one file offers the
 * others. The API is split by concept:
 *   rch_ffi.c          ABI, version, statuses; model handles, FK, cable
 *                      lengths; the shared helpers below
 *   rch_ffi_calib.c    calibration (files or arrays) and its figures; evaluation
 *   rch_ffi_diag.c     the diagnosis and its figures
 *   rch_ffi_comp.c     compensation of joint targets
 *   rch_ffi_report.c   export and the HTML report
 * Internal names: rch_ffip_, declared RCH_FFI_HIDDEN so that librcal_ffi.so
 * exports rch_ffi_* alone (python/CMakeLists.txt compiles the rch_ffi*.c
 * into it).
 *
 * Depends on: rch_calib, rch_diagnose, rch_robot, rch_diag.
 * Memory: none here (the handles are allocated by their files).
 * Errors: fail() and fail_diag() write the message and return the status. */
#ifndef RCH_FFI_INT_H
#define RCH_FFI_INT_H

#include <stddef.h>
#include <stdio.h>

#include "rc_model.h"
#include "rch_calib.h"
#include "rch_diag.h"
#include "rch_diagnose.h"
#include "rch_ffi.h"
#include "rch_robot.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif
#define DEG (M_PI / 180.0)
#define PATH_LEN 1024

/* Not exported from the shared library (the helpers the rch_ffi*.c share). */
#if defined(__GNUC__)
#define RCH_FFI_HIDDEN __attribute__((visibility("hidden")))
#else
#define RCH_FFI_HIDDEN
#endif

struct rch_ffi_model {
    rch_robot robot; /* robot.model is the model, robot.nominal its nominal table */
};

/* A calibration: the host pipeline's result (rch_calib_run), with copies of
 * the strings its cfg points at (the caller's strings need not outlive the
 * call). */
struct rch_ffi_calib {
    rch_calib_result r;
    char data[RCH_CALIB_MAX_FILES][PATH_LEN];
    const char *data_v[RCH_CALIB_MAX_FILES];
    char pos[RCH_CALIB_MAX_FILES][PATH_LEN]; /* tracker positions files */
    const char *pos_v[RCH_CALIB_MAX_FILES];
    char robot_path[PATH_LEN], truth_path[PATH_LEN], fix[PATH_LEN], effects[PATH_LEN], validate[PATH_LEN],
        plots[PATH_LEN], residuals[PATH_LEN];
};

/* A diagnosis (rch_diagnose_file) and the files it read. */
struct rch_ffi_diag {
    rch_diagnose_result r;
    char data_path[PATH_LEN], robot_path[PATH_LEN];
    char files[2 * RCH_DIAGNOSE_MAX_FILES][PATH_LEN]; /* rch_ffi_diagnose_inputs: the data, then the positions files */
    const char *data_v[RCH_DIAGNOSE_MAX_FILES], *pos_v[RCH_DIAGNOSE_MAX_FILES];
    char effects[1024];
};

/* Message into err (may be NULL) and the status back. */
static inline int fail(int status, char *err, size_t err_len, const char *fmt, const char *arg)
{
    if (err && err_len > 0)
        snprintf(err, err_len, fmt, arg);
    return status;
}

static inline int fail_diag(int status, char *err, size_t err_len, const rch_diag *d)
{
    char msg[1024];
    return fail(status, err, err_len, "%s", rch_diag_str(d, msg, sizeof msg));
}

/* Parameter k of m in display units (mm, deg, own unit) (rch_ffi.c). */
RCH_FFI_HIDDEN void rch_ffip_param_out(const rc_model *m, unsigned k, double x, char *name, size_t len,
                                       double *value, int *unit);
/* src into dst (PATH_LEN); the copy or NULL (src NULL). 1 in *too_long
 * when it does not fit (rch_ffi.c). */
RCH_FFI_HIDDEN const char *rch_ffip_copy_opt(char *dst, const char *src, int *too_long);
/* The text a writer puts on a stream, NUL-terminated into buf (len); *needed
 * the bytes it takes. ctx: what write reports (rch_ffi.c). */
typedef int (*rch_ffip_json_fn)(FILE *f, const void *ctx);
RCH_FFI_HIDDEN int rch_ffip_text_out(rch_ffip_json_fn write, const void *ctx, char *buf, size_t len,
                                     size_t *needed);
/* The JSON of `rcal calibrate --json` / `rcal diagnose --json` of a result
 * (ctx: rch_calib_result / rch_diagnose_result), the library call standing
 * for the command in its "command" (rch_ffi_calib.c, rch_ffi_diag.c). */
RCH_FFI_HIDDEN int rch_ffip_cal_json(FILE *f, const void *ctx);
RCH_FFI_HIDDEN int rch_ffip_diag_json(FILE *f, const void *ctx);

#endif
