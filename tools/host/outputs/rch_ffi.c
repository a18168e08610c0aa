/* SPDX-License-Identifier: MIT */
/* rch_ffi.c - the flat C API for foreign-function use (see rch_ffi.h): the
 * ABI, version and statuses; model handles, forward kinematics and cable
 * lengths; the helpers the other rch_ffi_*.c share (rch_ffi_int.h lists
 * the files). Depends on: rch_robot, the core (rc_model). Memory: a model
 * handle on the heap, the caller's until rch_ffi_model_free. Errors: a
 * status, the message into err. */
#include "rch_ffi.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rc_version.h"
#include "rch_comp.h"
#include "rch_ffi_int.h"
#include "rch_uncert.h"

int rch_ffi_abi(void)
{
    return RCH_FFI_ABI;
}

const char *rch_ffi_version(void)
{
    return rc_version();
}

const char *rch_ffi_strerror(int status)
{
    switch (status) {
    case RCH_FFI_OK: return "ok";
    case RCH_FFI_ERR_ARG: return "invalid argument";
    case RCH_FFI_ERR_INPUT: return "bad input file";
    case RCH_FFI_ERR_RANGE: return "value out of range";
    case RCH_FFI_ERR_NUMERIC: return "numeric failure";
    case RCH_FFI_ERR_SOLVER: return "calibration failed";
    case RCH_FFI_ERR_NOMEM: return "out of memory";
    case RCH_FFI_ERR_IO: return "output failed";
    default: return "unknown status";
    }
}


/* ---- models ---- */

int rch_ffi_model_load(rch_ffi_model **out, const char *path, char *err, size_t err_len)
{
    if (!out || !path)
        return fail(RCH_FFI_ERR_ARG, err, err_len, "%s", "model_load: NULL argument");
    *out = NULL;
    rch_ffi_model *m = malloc(sizeof *m);
    if (!m)
        return fail(RCH_FFI_ERR_NOMEM, err, err_len, "%s", "out of memory");
    rch_diag d;
    if (rch_robot_load(&m->robot, path, &d) != 0) {
        free(m);
        return fail_diag(RCH_FFI_ERR_INPUT, err, err_len, &d);
    }
    *out = m;
    return RCH_FFI_OK;
}

void rch_ffi_model_free(rch_ffi_model *m)
{
    free(m);
}

int rch_ffi_model_name(const rch_ffi_model *m, char *buf, size_t len)
{
    if (!m || !buf || len == 0)
        return RCH_FFI_ERR_ARG;
    snprintf(buf, len, "%s", m->robot.name);
    return RCH_FFI_OK;
}

int rch_ffi_model_has_nominal(const rch_ffi_model *m)
{
    return m ? m->robot.has_nominal : 0;
}

int rch_ffi_model_limits(const rch_ffi_model *m, double *q_min_deg, double *q_max_deg)
{
    if (!m || !q_min_deg || !q_max_deg)
        return RCH_FFI_ERR_ARG;
    for (unsigned j = 0; j < RC_NJ; ++j) {
        q_min_deg[j] = m->robot.model.q_min_rad[j] / DEG;
        q_max_deg[j] = m->robot.model.q_max_rad[j] / DEG;
    }
    return RCH_FFI_OK;
}

unsigned rch_ffi_model_n_params(const rch_ffi_model *m)
{
    return m ? m->robot.model.n_params : 0u;
}

void rch_ffip_param_out(const rc_model *m, unsigned k, double x, char *name, size_t len, double *value,
                        int *unit)
{
    const int u = rc_param_unit(m, k);
    if (name && len > 0)
        rc_param_name(name, len, m, k);
    if (value)
        *value = u == 1 ? x / DEG : x;
    if (unit)
        *unit = u;
}

int rch_ffi_model_param(const rch_ffi_model *m, unsigned k, int nominal, char *name, size_t len, double *value,
                        int *unit)
{
    if (!m || k >= m->robot.model.n_params || (nominal && k >= RC_N_BASE))
        return RCH_FFI_ERR_ARG;
    const rc_model *src = nominal && k < RC_N_DH ? &m->robot.nominal : &m->robot.model;
    rch_ffip_param_out(&m->robot.model, k, src->x[k], name, len, value, unit);
    return RCH_FFI_OK;
}

/* One pose in degrees as a sample (radians as the CSV reader converts). */
static void to_sample(rc_sample *s, const double q_deg[RC_NJ])
{
    memset(s, 0, sizeof *s);
    for (unsigned j = 0; j < RC_NJ; ++j)
        s->q_rad[j] = q_deg[j] * (M_PI / 180.0);
}

int rch_ffi_fk(const rch_ffi_model *m, int nominal, double *pos_mm, double *rot, const double *q_deg, size_t n,
               char *err, size_t err_len)
{
    if (!m || !pos_mm || (!q_deg && n > 0))
        return fail(RCH_FFI_ERR_ARG, err, err_len, "%s", "fk: NULL argument");
    rc_model *det = NULL; /* only for nominal == 2: on the heap (no static state, too large for a stack) */
    const rc_model *model = nominal == 1 ? &m->robot.nominal : &m->robot.model;
    if (nominal == 2) {
        rch_model_unc *unc = malloc(sizeof *unc);
        det = malloc(sizeof *det);
        if (!det || !unc) {
            free(det);
            free(unc);
            return fail(RCH_FFI_ERR_NOMEM, err, err_len, "%s", "out of memory");
        }
        int v1;
        char held[8];
        *det = m->robot.model;
        if (m->robot.has_nominal || m->robot.unc.present)
            rch_comp_determined(det, unc, &v1, held, sizeof held, &m->robot, &m->robot.nominal);
        free(unc);
        model = det;
    }
    for (size_t i = 0; i < n; ++i) {
        rc_sample s;
        to_sample(&s, &q_deg[RC_NJ * i]);
        rc_fk(&pos_mm[3 * i], rot ? &rot[9 * i] : NULL, model, s.q_rad);
    }
    free(det);
    return RCH_FFI_OK;
}

int rch_ffi_cable_length(const rch_ffi_model *m, double *len_mm, const double *q_deg, size_t n, char *err,
                         size_t err_len)
{
    if (!m || !len_mm || (!q_deg && n > 0))
        return fail(RCH_FFI_ERR_ARG, err, err_len, "%s", "cable_length: NULL argument");
    for (size_t i = 0; i < n; ++i) {
        rc_sample s;
        to_sample(&s, &q_deg[RC_NJ * i]);
        const rc_status st = rc_meas(&len_mm[i], NULL, &m->robot.model, &s);
        if (st != RC_OK) {
            if (err && err_len > 0)
                snprintf(err, err_len, "pose %zu: %s (the flange point is at the encoder outlet)", i,
                         rc_strerror(st));
            return RCH_FFI_ERR_NUMERIC;
        }
    }
    return RCH_FFI_OK;
}

/* ---- shared by the calibration and the diagnosis ---- */

const char *rch_ffip_copy_opt(char *dst, const char *src, int *too_long)
{
    if (!src) {
        dst[0] = '\0';
        return NULL;
    }
    if ((size_t)snprintf(dst, PATH_LEN, "%s", src) >= PATH_LEN)
        *too_long = 1;
    return dst;
}

int rch_ffip_text_out(rch_ffip_json_fn write, const void *ctx, char *buf, size_t len, size_t *needed)
{
    char *text = NULL;
    size_t n = 0;
    FILE *f = open_memstream(&text, &n);
    if (!f)
        return RCH_FFI_ERR_NOMEM;
    const int bad = write(f, ctx) != 0;
    if ((fclose(f) != 0) | bad) {
        free(text);
        return RCH_FFI_ERR_IO;
    }
    if (needed)
        *needed = n + 1;
    const int fits = buf && len > n;
    if (fits)
        memcpy(buf, text, n + 1);
    free(text);
    return fits ? RCH_FFI_OK : RCH_FFI_ERR_ARG;
}

