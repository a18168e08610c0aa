/* SPDX-License-Identifier: MIT */
/* rch_ffi.c - the flat C API for foreign-function use (see rch_ffi.h). */
#include "rch_ffi.h"

#include "rch_comp.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "rc_comp.h"
#include "rc_model.h"
#include "rc_solve.h"
#include "rch_calib.h"
#include "rch_diag.h"
#include "rch_robot.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif
#define DEG (M_PI / 180.0)
#define PATH_LEN 1024

struct rch_ffi_model {
    rch_robot robot; /* robot.model is the model, robot.nominal its nominal table */
};

/* A calibration: the host pipeline's result (rch_calib_run), with copies of
 * the paths its cfg points at (the caller's strings need not outlive the
 * call). */
struct rch_ffi_calib {
    rch_calib_result r;
    char data_path[PATH_LEN], robot_path[PATH_LEN], truth_path[PATH_LEN], fix[PATH_LEN];
};

int rch_ffi_abi(void)
{
    return RCH_FFI_ABI;
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

/* Message into err (may be NULL) and the status back. */
static int fail(int status, char *err, size_t err_len, const char *fmt, const char *arg)
{
    if (err && err_len > 0)
        snprintf(err, err_len, fmt, arg);
    return status;
}

static int fail_diag(int status, char *err, size_t err_len, const rch_diag *d)
{
    char msg[1024];
    return fail(status, err, err_len, "%s", rch_diag_str(d, msg, sizeof msg));
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

/* Parameter k of m in display units (mm, deg, own unit). */
static void param_out(const rc_model *m, unsigned k, double x, char *name, size_t len, double *value, int *unit)
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
    param_out(&m->robot.model, k, src->x[k], name, len, value, unit);
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
    static rc_model det; /* only for nominal == 2 */
    const rc_model *model = nominal == 1 ? &m->robot.nominal : &m->robot.model;
    if (nominal == 2) {
        rch_model_unc unc;
        int v1;
        char held[8];
        det = m->robot.model;
        if (m->robot.has_nominal || m->robot.unc.present)
            rch_comp_determined(&det, &unc, &v1, held, sizeof held, &m->robot, &m->robot.nominal);
        model = &det;
    }
    for (size_t i = 0; i < n; ++i) {
        rc_sample s;
        to_sample(&s, &q_deg[RC_NJ * i]);
        rc_fk(&pos_mm[3 * i], rot ? &rot[9 * i] : NULL, model, s.q_rad);
    }
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

/* ---- calibration ---- */

static void copy_opt(char *dst, const char *src)
{
    snprintf(dst, PATH_LEN, "%s", src ? src : "");
}

int rch_ffi_calibrate_file(rch_ffi_calib **out, const char *data_path, const char *robot_path, const char *method,
                           double test_fraction, unsigned long seed, unsigned max_iter, const char *fix,
                           int tool_offset, const char *truth_path, char *err, size_t err_len)
{
    if (!out || !data_path || !robot_path)
        return fail(RCH_FFI_ERR_ARG, err, err_len, "%s", "calibrate: NULL argument (data and robot are required)");
    *out = NULL;
    rch_calib_cfg cfg;
    rch_calib_cfg_init(&cfg);
    if (rch_method_parse(&cfg.method, method ? method : "lm") != 0)
        return fail(RCH_FFI_ERR_ARG, err, err_len, "unknown method '%s' (lm, ltlm, lm-paper, ltlm-paper)", method);
    if (!(test_fraction >= 0.0 && test_fraction < 1.0))
        return fail(RCH_FFI_ERR_ARG, err, err_len, "%s", "test_fraction must be in [0, 1)");
    rch_ffi_calib *c = malloc(sizeof *c);
    if (!c)
        return fail(RCH_FFI_ERR_NOMEM, err, err_len, "%s", "out of memory");
    copy_opt(c->data_path, data_path);
    copy_opt(c->robot_path, robot_path);
    copy_opt(c->truth_path, truth_path);
    copy_opt(c->fix, fix);
    cfg.data_path = c->data_path;
    cfg.robot_path = c->robot_path;
    cfg.truth_path = truth_path ? c->truth_path : NULL;
    cfg.fix = fix ? c->fix : NULL;
    cfg.test_fraction = test_fraction;
    cfg.seed = seed;
    cfg.max_iter = max_iter;
    cfg.tool_offset = tool_offset != 0;
    rch_diag d;
    memset(&d, 0, sizeof d);
    const int rc = rch_calib_run(&c->r, &cfg, &d);
    if (rc != 0) {
        free(c);
        const int input = d.file[0] != '\0';
        return fail_diag(rc == -2 ? RCH_FFI_ERR_ARG : input ? RCH_FFI_ERR_INPUT : RCH_FFI_ERR_SOLVER, err, err_len,
                         &d);
    }
    *out = c;
    return RCH_FFI_OK;
}

int rch_ffi_calibrate_arrays(rch_ffi_calib **out, const double *q_deg, const double *len_mm, size_t n,
                             const char *robot_path, const char *method, double test_fraction, unsigned long seed,
                             unsigned max_iter, const char *fix, int tool_offset, const char *truth_path, char *err,
                             size_t err_len)
{
    if (!out || !q_deg || !len_mm || n == 0)
        return fail(RCH_FFI_ERR_ARG, err, err_len, "%s", "calibrate: no samples");
    *out = NULL;
    const char *dir = getenv("TMPDIR");
    char tmp[PATH_LEN];
    snprintf(tmp, sizeof tmp, "%s/rcal-ffi-XXXXXX", dir && dir[0] ? dir : "/tmp");
    const int fd = mkstemp(tmp);
    FILE *f = fd >= 0 ? fdopen(fd, "w") : NULL;
    if (!f) {
        if (fd >= 0) {
            close(fd);
            unlink(tmp);
        }
        return fail(RCH_FFI_ERR_IO, err, err_len, "cannot create a temporary file %s", tmp);
    }
    int bad = fprintf(f, "q1,q2,q3,q4,q5,q6,L\n") < 0;
    for (size_t i = 0; i < n && !bad; ++i) {
        const double *q = &q_deg[RC_NJ * i];
        bad = fprintf(f, "%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g\n", q[0], q[1], q[2], q[3], q[4], q[5],
                      len_mm[i]) < 0;
    }
    bad |= fclose(f) != 0;
    int rc = bad ? fail(RCH_FFI_ERR_IO, err, err_len, "writing the temporary file %s failed", tmp)
                 : rch_ffi_calibrate_file(out, tmp, robot_path, method, test_fraction, seed, max_iter, fix,
                                          tool_offset, truth_path, err, err_len);
    unlink(tmp);
    if (rc == RCH_FFI_OK)
        copy_opt((*out)->data_path, "<arrays>"); /* the model file's "data" */
    return rc;
}

void rch_ffi_calib_free(rch_ffi_calib *c)
{
    free(c);
}

int rch_ffi_calib_metrics(const rch_ffi_calib *c, int which, double *out)
{
    if (!c || !out || which < RCH_FFI_BEFORE || which > RCH_FFI_TRAIN_AFTER)
        return RCH_FFI_ERR_ARG;
    const rc_metrics *all[4] = {&c->r.before_m, &c->r.after_m, &c->r.train_before, &c->r.train_after};
    const rc_metrics *m = all[which];
    out[0] = (double)m->n;
    out[1] = m->rmse_mm;
    out[2] = m->mean_abs_mm;
    out[3] = m->sd_mm;
    out[4] = m->mean_mm;
    out[5] = m->max_mm;
    return RCH_FFI_OK;
}

int rch_ffi_calib_info(const rch_ffi_calib *c, size_t *n_train, size_t *n_test, int *converged, unsigned *iterations,
                       unsigned *cost_evals, char *exit_buf, size_t exit_len)
{
    if (!c)
        return RCH_FFI_ERR_ARG;
    if (n_train)
        *n_train = c->r.n_train;
    if (n_test)
        *n_test = c->r.n_test;
    if (converged)
        *converged = c->r.after_ok;
    if (iterations)
        *iterations = c->r.solve.iterations;
    if (cost_evals)
        *cost_evals = c->r.solve.cost_evals;
    if (exit_buf && exit_len > 0)
        snprintf(exit_buf, exit_len, "%s", rc_exit_str(c->r.solve.exit));
    return RCH_FFI_OK;
}

unsigned rch_ffi_calib_n_params(const rch_ffi_calib *c)
{
    return c ? c->r.model.n_params : 0u;
}

int rch_ffi_calib_param(const rch_ffi_calib *c, unsigned k, char *name, size_t len, double *value, double *delta,
                        int *unit)
{
    if (!c || k >= c->r.model.n_params)
        return RCH_FFI_ERR_ARG;
    const rch_calib_result *r = &c->r;
    const double nominal = k < RC_N_DH ? r->robot.model.x[k] : (k < RC_N_BASE ? r->before.x[k] : 0.0);
    double v = 0.0, dv = 0.0;
    param_out(&r->model, k, r->finite ? r->model.x[k] : 0.0, name, len, &v, unit);
    param_out(&r->model, k, r->finite ? r->model.x[k] - nominal : 0.0, NULL, 0, &dv, NULL);
    if (value)
        *value = v;
    if (delta)
        *delta = dv;
    return RCH_FFI_OK;
}

int rch_ffi_calib_model(rch_ffi_model **out, const rch_ffi_calib *c, char *err, size_t err_len)
{
    if (!out || !c)
        return fail(RCH_FFI_ERR_ARG, err, err_len, "%s", "calib_model: NULL argument");
    *out = NULL;
    rch_ffi_model *m = malloc(sizeof *m);
    if (!m)
        return fail(RCH_FFI_ERR_NOMEM, err, err_len, "%s", "out of memory");
    m->robot = c->r.robot;
    m->robot.model = c->r.model;
    m->robot.has_nominal = 1;
    *out = m;
    return RCH_FFI_OK;
}

int rch_ffi_calib_write(const rch_ffi_calib *c, const char *path, char *err, size_t err_len)
{
    if (!c || !path)
        return fail(RCH_FFI_ERR_ARG, err, err_len, "%s", "calib_write: NULL argument");
    if (!c->r.finite)
        return fail(RCH_FFI_ERR_NUMERIC, err, err_len, "not writing %s: the model is not finite", path);
    rch_diag d;
    memset(&d, 0, sizeof d);
    if (rch_calib_save_model(&c->r, path, &d) != 0)
        return fail_diag(RCH_FFI_ERR_IO, err, err_len, &d);
    return RCH_FFI_OK;
}

int rch_ffi_calib_truth(const rch_ffi_calib *c, double *out)
{
    if (!c || !out || !c->r.have_truth)
        return RCH_FFI_ERR_ARG;
    out[0] = c->r.truth_before_rms_mm;
    out[1] = c->r.truth_before_max_mm;
    out[2] = c->r.truth_after_rms_mm;
    out[3] = c->r.truth_after_max_mm;
    return RCH_FFI_OK;
}

int rch_ffi_calib_json(const rch_ffi_calib *c, char *buf, size_t len, size_t *needed)
{
    if (!c)
        return RCH_FFI_ERR_ARG;
    char *text = NULL;
    size_t n = 0;
    FILE *f = open_memstream(&text, &n);
    if (!f)
        return RCH_FFI_ERR_NOMEM;
    char name[] = "calibrate"; /* the library call stands for the command */
    char *av[] = {name};
    const int bad = rch_calib_json(f, &c->r, 1, av) != 0;
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

/* ---- compensation ---- */

int rch_ffi_compensate(const rch_ffi_model *cal, const rch_ffi_model *nominal, double *out_deg, int *status,
                       const double *q_deg, size_t n, int position_only, double max_dev_deg, char *err,
                       size_t err_len)
{
    if (!cal || !out_deg || (!q_deg && n > 0))
        return fail(RCH_FFI_ERR_ARG, err, err_len, "%s", "compensate: NULL argument");
    if (!(max_dev_deg >= 0.0))
        return fail(RCH_FFI_ERR_ARG, err, err_len, "%s", "compensate: max_dev_deg must be >= 0");
    /* the same model and mode as rcal compensate (rch_comp_run) */
    static rc_model det;
    static rch_model_unc unc;
    int version1 = 0;
    char held[256];
    det = cal->robot.model;
    memset(&unc, 0, sizeof unc);
    const int calibrated = cal->robot.has_nominal || cal->robot.unc.present;
    if (calibrated)
        rch_comp_determined(&det, &unc, &version1, held, sizeof held, &cal->robot, &cal->robot.nominal);
    const rc_model *m = &det;
    const rc_model *nom = nominal ? &nominal->robot.model : &cal->robot.nominal;
    const int orient = unc.present && !version1 && unc.orientation_determined;
    const int pos_only = position_only == 1 || (position_only == 0 && calibrated && !orient);
    rc_comp_config cfg;
    memset(&cfg, 0, sizeof cfg);
    cfg.max_dev_rad = max_dev_deg * DEG;
    cfg.flags = pos_only ? RC_COMP_FLAG_POSITION_ONLY : 0u;
    rc_comp_stream s;
    rc_comp_stream_init(&s, m, nom, &cfg);
    for (size_t i = 0; i < n; ++i) {
        const double *in = &q_deg[RC_NJ * i];
        double q[RC_NJ], qc[RC_NJ];
        for (unsigned j = 0; j < RC_NJ; ++j) {
            q[j] = in[j] * DEG;
            if (!(q[j] >= m->q_min_rad[j] && q[j] <= m->q_max_rad[j])) {
                if (err && err_len > 0)
                    snprintf(err, err_len, "target %zu: q%u = %g deg is outside the joint limits [%g, %g] deg", i,
                             j + 1, in[j], m->q_min_rad[j] / DEG, m->q_max_rad[j] / DEG);
                return RCH_FFI_ERR_RANGE;
            }
        }
        if (unc.present && !version1 && !(rch_model_unc_pos95_mm(&unc, m, q) <= 1.0)) {
            for (unsigned j = 0; j < RC_NJ; ++j)
                out_deg[RC_NJ * i + j] = in[j]; /* left uncompensated: uncertainty above 1 mm */
            if (status)
                status[i] = 3;
            continue;
        }
        rc_comp_result res;
        const rc_status st = rc_comp_stream_step(&s, qc, &res, q);
        for (unsigned j = 0; j < RC_NJ; ++j)
            out_deg[RC_NJ * i + j] = qc[j] / DEG;
        if (status)
            status[i] = st != RC_OK ? 2 : res.exit == RC_COMP_POSITION_ONLY ? 1 : 0;
    }
    return RCH_FFI_OK;
}
