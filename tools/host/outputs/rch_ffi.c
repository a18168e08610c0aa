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
#include "rc_version.h"
#include "rch_calib.h"
#include "rch_calib_effects.h"
#include "rch_data.h"
#include "rch_diag.h"
#include "rch_diagnose.h"
#include "rch_evaluate.h"
#include "rch_export.h"
#include "rch_file.h"
#include "rch_jw.h"
#include "rch_prior.h"
#include "rch_report.h"
#include "rch_robot.h"
#include "rch_save.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif
#define DEG (M_PI / 180.0)
#define PATH_LEN 1024

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
    char robot_path[PATH_LEN], truth_path[PATH_LEN], fix[PATH_LEN], effects[PATH_LEN], validate[PATH_LEN],
        plots[PATH_LEN], residuals[PATH_LEN];
};

/* A diagnosis (rch_diagnose_file) and the files it read. */
struct rch_ffi_diag {
    rch_diagnose_result r;
    char data_path[PATH_LEN], robot_path[PATH_LEN];
};

/* The options of a calibration after the data (internal: nothing crosses
 * the interface as a struct). */
typedef struct {
    const char *robot, *method;
    double test_fraction;
    unsigned long seed;
    unsigned max_iter;
    const char *fix, *effects;
    unsigned flags;
    const char *validate, *truth;
    unsigned long cases;
    size_t case_samples;
    const char *plots, *residuals;
} cal_opts;

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

/* ---- calibration ---- */

/* src into dst (PATH_LEN); the copy or NULL (src NULL). 1 in *long_ when
 * it does not fit. */
static const char *copy_opt(char *dst, const char *src, int *too_long)
{
    if (!src) {
        dst[0] = '\0';
        return NULL;
    }
    if ((size_t)snprintf(dst, PATH_LEN, "%s", src) >= PATH_LEN)
        *too_long = 1;
    return dst;
}

/* The checks `rcal calibrate` makes before the fit (cmd_calibrate.c): each
 * data file once, the validation file not a data file, --residuals for one
 * plain calibration, every joint reading within the robot's limits. */
static int precheck(const rch_calib_cfg *cfg, char *err, size_t err_len)
{
    for (size_t i = 0; i < cfg->n_data_paths; ++i)
        for (size_t j = 0; j < i; ++j)
            if (rch_same_file(cfg->data_paths[i], cfg->data_paths[j]) ||
                strcmp(cfg->data_paths[i], cfg->data_paths[j]) == 0) {
                if (err && err_len > 0)
                    snprintf(err, err_len, "data %s is the same file as data %s: refused (each file once; merging a "
                             "file with itself counts every sample twice)", cfg->data_paths[i], cfg->data_paths[j]);
                return RCH_FFI_ERR_ARG;
            }
    for (size_t i = 0; cfg->validate_path && i < cfg->n_data_paths; ++i)
        if (rch_same_file(cfg->validate_path, cfg->data_paths[i]) || strcmp(cfg->validate_path, cfg->data_paths[i]) == 0) {
            if (err && err_len > 0)
                snprintf(err, err_len, "validate %s is the same file as data %s: refused (validation data must be "
                         "samples the fit never saw)", cfg->validate_path, cfg->data_paths[i]);
            return RCH_FFI_ERR_ARG;
        }
    if (cfg->residuals_path && (cfg->cases > 1 || cfg->jumps))
        return fail(RCH_FFI_ERR_ARG, err, err_len, "%s",
                    "residuals is for one calibration without jumps (not with cases or jumps)");
    rch_robot *robot = malloc(sizeof *robot);
    if (!robot)
        return fail(RCH_FFI_ERR_NOMEM, err, err_len, "%s", "out of memory");
    rch_diag d;
    int rc = RCH_FFI_OK;
    if (rch_robot_load(robot, cfg->robot_path, &d) == 0) /* else rch_calib_run reports it */
        for (size_t i = 0; i <= cfg->n_data_paths && rc == RCH_FFI_OK; ++i) {
            const char *path = i < cfg->n_data_paths ? cfg->data_paths[i] : cfg->validate_path;
            rch_data data;
            if (!path)
                continue;
            if (rch_data_load_limited(&data, path, 0, &robot->model, &d) != 0)
                rc = fail_diag(RCH_FFI_ERR_INPUT, err, err_len, &d);
            else
                rch_data_free(&data);
        }
    free(robot);
    return rc;
}

static int calibrate(rch_ffi_calib **out, const char *const *data_paths, size_t n_data, const cal_opts *o,
                     char *err, size_t err_len)
{
    if (!out || !data_paths || n_data == 0 || !o->robot)
        return fail(RCH_FFI_ERR_ARG, err, err_len, "%s", "calibrate: NULL argument (data and robot are required)");
    *out = NULL;
    if (n_data > RCH_CALIB_MAX_FILES)
        return fail(RCH_FFI_ERR_ARG, err, err_len, "%s", "calibrate: at most 16 data files");
    rch_calib_cfg cfg;
    rch_calib_cfg_init(&cfg);
    if (rch_method_parse(&cfg.method, o->method ? o->method : "lm") != 0)
        return fail(RCH_FFI_ERR_ARG, err, err_len,
                    "unknown method '%s' (lm, ltlm, lm-paper, ltlm-paper, lm-paper-deg, ltlm-paper-deg)", o->method);
    if (!(o->test_fraction >= 0.0 && o->test_fraction < 1.0))
        return fail(RCH_FFI_ERR_ARG, err, err_len, "%s", "test_fraction must be in [0, 1)");
    if (o->cases > 1000 || o->max_iter > 100000)
        return fail(RCH_FFI_ERR_ARG, err, err_len, "%s", "cases must be at most 1000, max_iter at most 100000");
    rch_ffi_calib *c = malloc(sizeof *c);
    if (!c)
        return fail(RCH_FFI_ERR_NOMEM, err, err_len, "%s", "out of memory");
    int too_long = 0;
    for (size_t i = 0; i < n_data; ++i) {
        if (!data_paths[i]) {
            free(c);
            return fail(RCH_FFI_ERR_ARG, err, err_len, "%s", "calibrate: a NULL data path");
        }
        c->data_v[i] = copy_opt(c->data[i], data_paths[i], &too_long);
    }
    cfg.data_path = c->data_v[0];
    cfg.data_paths = c->data_v;
    cfg.n_data_paths = n_data;
    cfg.robot_path = copy_opt(c->robot_path, o->robot, &too_long);
    cfg.truth_path = copy_opt(c->truth_path, o->truth, &too_long);
    cfg.fix = copy_opt(c->fix, o->fix, &too_long);
    cfg.effects = copy_opt(c->effects, o->effects, &too_long);
    cfg.validate_path = copy_opt(c->validate, o->validate, &too_long);
    cfg.plots_dir = copy_opt(c->plots, o->plots, &too_long);
    cfg.residuals_path = copy_opt(c->residuals, o->residuals, &too_long);
    if (too_long) {
        free(c);
        return fail(RCH_FFI_ERR_ARG, err, err_len, "calibrate: a path or list longer than %s bytes", "1023");
    }
    cfg.test_fraction = o->test_fraction;
    cfg.seed = o->seed;
    cfg.max_iter = o->max_iter;
    cfg.tool_offset = (o->flags & RCH_FFI_CAL_TOOL_OFFSET) != 0;
    cfg.jumps = (o->flags & RCH_FFI_CAL_JUMPS) != 0;
    cfg.dequantize = (o->flags & RCH_FFI_CAL_DEQUANTIZE) != 0;
    cfg.no_prior = (o->flags & RCH_FFI_CAL_NO_PRIOR) != 0;
    cfg.holdout_groups = (o->flags & RCH_FFI_CAL_HOLDOUT_GROUPS) != 0;
    cfg.no_jump_check = (o->flags & RCH_FFI_CAL_NO_JUMP_CHECK) != 0;
    cfg.cases = o->cases > 1 ? o->cases : 1;
    cfg.case_samples = o->case_samples;
    int rc = precheck(&cfg, err, err_len);
    if (rc != RCH_FFI_OK) {
        free(c);
        return rc;
    }
    rch_diag d;
    memset(&d, 0, sizeof d);
    rc = rch_calib_run(&c->r, &cfg, &d);
    if (rc != 0) {
        free(c);
        const int input = d.file[0] != '\0';
        return fail_diag(rc == -2 ? RCH_FFI_ERR_ARG : input ? RCH_FFI_ERR_INPUT : RCH_FFI_ERR_SOLVER, err, err_len,
                         &d);
    }
    *out = c;
    return RCH_FFI_OK;
}

int rch_ffi_calibrate(rch_ffi_calib **out, const char *const *data_paths, size_t n_data, const char *robot_path,
                      const char *method, double test_fraction, unsigned long seed, unsigned max_iter,
                      const char *fix, const char *effects, unsigned flags, const char *validate_path,
                      const char *truth_path, unsigned long cases, size_t case_samples, const char *plots_dir,
                      const char *residuals_path, char *err, size_t err_len)
{
    const cal_opts o = {robot_path, method, test_fraction, seed, max_iter, fix, effects, flags, validate_path,
                        truth_path, cases, case_samples, plots_dir, residuals_path};
    return calibrate(out, data_paths, n_data, &o, err, err_len);
}

int rch_ffi_calibrate_arrays(rch_ffi_calib **out, const double *q_deg, const double *len_mm, const double *xyz_mm,
                             const int *group, const int *outlet, size_t n, const char *robot_path,
                             const char *method, double test_fraction, unsigned long seed, unsigned max_iter,
                             const char *fix, const char *effects, unsigned flags, const char *validate_path,
                             const char *truth_path, unsigned long cases, size_t case_samples, const char *plots_dir,
                             const char *residuals_path, char *err, size_t err_len)
{
    if (!out || !q_deg || !len_mm || n == 0)
        return fail(RCH_FFI_ERR_ARG, err, err_len, "%s", "calibrate: no samples");
    *out = NULL;
    for (size_t i = 0; i < n; ++i)
        if ((group && group[i] < 0) || (outlet && outlet[i] < 0))
            return fail(RCH_FFI_ERR_ARG, err, err_len, "%s", "calibrate: group and outlet labels must be >= 0");
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
    rch_tmp_register(tmp);
    int bad = fprintf(f, "q1,q2,q3,q4,q5,q6,L%s%s%s\n", xyz_mm ? ",x,y,z" : "", group ? ",group" : "",
                      outlet ? ",outlet" : "") < 0;
    for (size_t i = 0; i < n && !bad; ++i) {
        const double *q = &q_deg[RC_NJ * i];
        bad = fprintf(f, "%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g", q[0], q[1], q[2], q[3], q[4], q[5],
                      len_mm[i]) < 0;
        if (xyz_mm)
            bad |= fprintf(f, ",%.17g,%.17g,%.17g", xyz_mm[3 * i], xyz_mm[3 * i + 1], xyz_mm[3 * i + 2]) < 0;
        if (group)
            bad |= fprintf(f, ",%d", group[i]) < 0;
        if (outlet)
            bad |= fprintf(f, ",%d", outlet[i]) < 0;
        bad |= fputc('\n', f) == EOF;
    }
    bad |= fclose(f) != 0;
    const char *paths[1] = {tmp};
    const cal_opts o = {robot_path, method, test_fraction, seed, max_iter, fix, effects, flags, validate_path,
                        truth_path, cases, case_samples, plots_dir, residuals_path};
    int rc = bad ? fail(RCH_FFI_ERR_IO, err, err_len, "writing the temporary file %s failed", tmp)
                 : calibrate(out, paths, 1, &o, err, err_len);
    unlink(tmp);
    rch_tmp_forget(tmp);
    if (rc == RCH_FFI_OK) {
        int unused = 0;
        copy_opt((*out)->data[0], "<arrays>", &unused); /* the model file's "data" */
    }
    return rc;
}

void rch_ffi_calib_free(rch_ffi_calib *c)
{
    free(c);
}

int rch_ffi_calib_metrics(const rch_ffi_calib *c, int which, double *out)
{
    if (!c || !out || which < RCH_FFI_BEFORE || which > RCH_FFI_VALIDATE)
        return RCH_FFI_ERR_ARG;
    if ((which == RCH_FFI_AFTER_UNAMBIGUOUS && !c->r.have_jumps) || (which == RCH_FFI_VALIDATE && !c->r.have_validate))
        return RCH_FFI_ERR_ARG;
    const rc_metrics *all[6] = {&c->r.before_m,          &c->r.after_m,           &c->r.train_before,
                                &c->r.train_after,       &c->r.after_unambiguous, &c->r.validate.m};
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

int rch_ffi_calib_param_unc(const rch_ffi_calib *c, unsigned k, double *std_error, double *prior_sd, char *cls,
                            size_t cls_len, char *prior_cls, size_t prior_cls_len, int *held)
{
    if (!c || !c->r.have_unc || !c->r.unc.present || k >= c->r.unc.n || k >= c->r.model.n_params)
        return RCH_FFI_ERR_ARG;
    const rch_model_unc *u = &c->r.unc;
    const double sc = rc_param_unit(&c->r.model, k) == 1 ? 1.0 / DEG : 1.0;
    if (std_error)
        *std_error = u->se[k] * sc; /* NaN stays NaN */
    const int has_prior = u->has_prior && u->prior_sd[k] > 0.0;
    if (prior_sd)
        *prior_sd = has_prior ? u->prior_sd[k] * sc : 0.0;
    if (cls && cls_len > 0)
        snprintf(cls, cls_len, "%s", rch_param_class_name((rch_param_class)u->cls[k]));
    if (prior_cls && prior_cls_len > 0)
        snprintf(prior_cls, prior_cls_len, "%s", has_prior ? rch_prior_class_name((rch_prior_class)u->prior_cls[k]) : "");
    if (held)
        *held = k < RC_N_DH && u->comp_nominal[k];
    return RCH_FFI_OK;
}

/* One named figure of a calibration: 0 with *v, or -1 (unknown, absent). */
static int calib_figure(const rch_calib_result *r, const char *name, double *v)
{
    const rch_uncert_map *mp = &r->unc.map;
    const int unc = r->have_unc && r->unc.present, val = r->have_validate, cases = r->cases_done > 1;
    const rch_evaluate_result *e = &r->validate;
    const struct {
        const char *name;
        int present;
        double value;
    } t[] = {
        {"n_data", 1, (double)r->n_data},
        {"time_ms", 1, r->time_ms},
        {"prior", 1, r->prior_on},
        {"noise_mm", 1, r->noise_mm},
        {"effective_params", 1, r->p_eff},
        {"outlets", 1, r->n_outlets},
        {"groups", 1, r->n_groups},
        {"attachment_centred", 1, r->attach_centred},
        {"jumps_found_by_default", 1, r->jumps_found},
        {"jump_check_max_mm", 1, r->jump_check_max_mm},
        {"jumps_fitted", 1, r->have_jumps ? r->jumps.n_jumps : 0},
        {"n_ambiguous", 1, (double)r->n_ambiguous},
        {"dequant_corrected", r->have_dequant, (double)r->dequant.n_corrected},
        {"dequant_refused", r->have_dequant, (double)r->dequant.n_refused},
        {"dequant_rms_deg", r->have_dequant, r->dequant.dq_rms_deg},
        {"dequant_max_deg", r->have_dequant, r->dequant.dq_max_deg},
        {"position95_data_median_mm", unc, mp->data_median_mm},
        {"position95_data_max_mm", unc, mp->data_max_mm},
        {"position95_workspace_median_mm", unc, mp->work_median_mm},
        {"position95_workspace_max_mm", unc, mp->work_max_mm},
        {"orientation95_data_median_deg", unc, mp->rot_data_median_deg},
        {"orientation95_data_max_deg", unc, mp->rot_data_max_deg},
        {"orientation_determined", unc, r->unc.orientation_determined},
        {"sigma_mm", unc, r->unc.sigma_mm},
        {"rank", unc, r->unc.rank},
        {"validate_encoder_refitted", val, e->encoder_refitted},
        {"validate_poses", val, (double)e->n_poses},
        {"validate_repeated_poses", val, (double)e->n_repeated},
        {"validate_ad_mean_mm", val, e->ad_mean_mm},
        {"validate_ad_max_mm", val, e->ad_max_mm},
        {"validate_rd_mean_mm", val, e->rd_mean_mm},
        {"validate_rd_max_mm", val, e->rd_max_mm},
        {"cases_done", 1, (double)r->cases_done},
        {"cases_before_rmse_mean_mm", cases, r->case_before.mean},
        {"cases_after_rmse_mean_mm", cases, r->case_after.mean},
    };
    for (size_t i = 0; i < sizeof t / sizeof t[0]; ++i)
        if (strcmp(t[i].name, name) == 0) {
            if (!t[i].present)
                return -1;
            *v = t[i].value;
            return 0;
        }
    return -1;
}

int rch_ffi_calib_get(const rch_ffi_calib *c, const char *name, double *value)
{
    if (!c || !name || !value)
        return RCH_FFI_ERR_ARG;
    return calib_figure(&c->r, name, value) == 0 ? RCH_FFI_OK : RCH_FFI_ERR_ARG;
}

int rch_ffi_calib_jumps(const rch_ffi_calib *c, unsigned *n, unsigned *line, double *size_mm, double *se_mm,
                        unsigned cap)
{
    if (!c || !n)
        return RCH_FFI_ERR_ARG;
    const rch_jumps *j = &c->r.jumps;
    *n = c->r.have_jumps ? j->n_jumps : 0u;
    for (unsigned k = 0; k < *n && k < cap; ++k) {
        if (line)
            line[k] = c->r.jump_lines[k];
        if (size_mm)
            size_mm[k] = j->size_mm[k];
        if (se_mm)
            se_mm[k] = j->se_mm[k];
    }
    return RCH_FFI_OK;
}

int rch_ffi_calib_outlets(const rch_ffi_calib *c, unsigned *n, int *label, unsigned cap)
{
    if (!c || !n)
        return RCH_FFI_ERR_ARG;
    *n = c->r.n_outlets;
    for (unsigned k = 0; label && k < *n && k < cap && k < RC_MAX_OUTLETS; ++k)
        label[k] = c->r.outlet_label[k];
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

/* The text a writer puts on a stream, NUL-terminated into buf (len); *needed
 * the bytes it takes. ctx: what write reports. */
typedef int (*json_fn)(FILE *f, const void *ctx);
static int text_out(json_fn write, const void *ctx, char *buf, size_t len, size_t *needed)
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

/* The library call stands for the command in the JSON's "command". */
static char g_cal_name[] = "calibrate", g_diag_name[] = "diagnose";

static int cal_json(FILE *f, const void *ctx)
{
    char *av[] = {g_cal_name};
    return rch_calib_json(f, ctx, 1, av);
}

static int diag_json(FILE *f, const void *ctx)
{
    char *av[] = {g_diag_name};
    return rch_diagnose_json(f, ctx, 1, av);
}

int rch_ffi_calib_json(const rch_ffi_calib *c, char *buf, size_t len, size_t *needed)
{
    if (!c)
        return RCH_FFI_ERR_ARG;
    return text_out(cal_json, &c->r, buf, len, needed);
}

/* ---- diagnosis ---- */

int rch_ffi_diagnose(rch_ffi_diag **out, const char *data_path, const char *robot_path, unsigned long seed,
                     unsigned folds, unsigned steps, unsigned flags, double q_step_deg, double len_step_mm,
                     double len_noise_mm, double alpha, unsigned max_iter, char *err, size_t err_len)
{
    if (!out || !data_path || !robot_path)
        return fail(RCH_FFI_ERR_ARG, err, err_len, "%s", "diagnose: NULL argument (data and robot are required)");
    *out = NULL;
    if ((folds && (folds < 2 || folds > RCH_DIAGNOSE_MAX_FOLDS)) || steps > RCH_DIAGNOSE_MAX_STEPS ||
        !(q_step_deg >= -1 && q_step_deg <= 10) || !(len_step_mm >= -1 && len_step_mm <= 10) ||
        !(len_noise_mm >= 0 && len_noise_mm <= 100) || !(alpha >= 0 && alpha <= 0.5) || max_iter > 100000)
        return fail(RCH_FFI_ERR_ARG, err, err_len, "%s",
                    "diagnose: folds 2..20, steps 1..4, q_step_deg and len_step_mm -1..10, len_noise_mm 0..100, "
                    "alpha 0..0.5, max_iter at most 100000");
    rch_ffi_diag *g = malloc(sizeof *g);
    if (!g)
        return fail(RCH_FFI_ERR_NOMEM, err, err_len, "%s", "out of memory");
    int too_long = 0;
    copy_opt(g->data_path, data_path, &too_long);
    copy_opt(g->robot_path, robot_path, &too_long);
    if (too_long) {
        free(g);
        return fail(RCH_FFI_ERR_ARG, err, err_len, "diagnose: a path longer than %s bytes", "1023");
    }
    rch_diagnose_cfg cfg;
    memset(&cfg, 0, sizeof cfg);
    cfg.folds = folds ? folds : 5;
    cfg.max_steps = steps ? steps : 3;
    cfg.seed = seed;
    cfg.q_step_deg = q_step_deg;
    cfg.len_step_mm = len_step_mm;
    cfg.len_noise_mm = len_noise_mm;
    cfg.alpha = alpha;
    cfg.max_iter = max_iter;
    cfg.no_jumps = (flags & RCH_FFI_DIAG_NO_JUMPS) != 0;
    cfg.dequantize = (flags & RCH_FFI_DIAG_DEQUANTIZE) != 0;
    rch_diag d;
    memset(&d, 0, sizeof d);
    if (rch_diagnose_file(&g->r, g->data_path, g->robot_path, &cfg, &d) != 0) {
        rch_diagnose_free(&g->r);
        free(g);
        return fail_diag(d.file[0] ? RCH_FFI_ERR_INPUT : RCH_FFI_ERR_SOLVER, err, err_len, &d);
    }
    *out = g;
    return RCH_FFI_OK;
}

void rch_ffi_diag_free(rch_ffi_diag *g)
{
    if (!g)
        return;
    rch_diagnose_free(&g->r);
    free(g);
}

int rch_ffi_diag_verdict(const rch_ffi_diag *g, char *effect, size_t len, unsigned *joint, char *remaining,
                         size_t remaining_len, char *why, size_t why_len)
{
    if (!g)
        return RCH_FFI_ERR_ARG;
    if (effect && len > 0)
        snprintf(effect, len, "%s", g->r.effect);
    if (joint)
        *joint = g->r.joint;
    if (remaining && remaining_len > 0)
        snprintf(remaining, remaining_len, "%s", g->r.remaining);
    if (why && why_len > 0)
        snprintf(why, why_len, "%s", g->r.remaining_why);
    return RCH_FFI_OK;
}

int rch_ffi_diag_chosen(const rch_ffi_diag *g, unsigned k, char *name, size_t len, double *rmse_cv_mm,
                        double *gain_mm2, double *p_value)
{
    if (!g)
        return RCH_FFI_ERR_ARG;
    unsigned seen = 0;
    for (unsigned s = 0; s < g->r.n_steps; ++s) {
        const rch_diagnose_step *st = &g->r.steps[s];
        if (st->chosen < 0 || (unsigned)st->chosen >= st->n_cand)
            continue;
        if (seen++ != k)
            continue;
        const rch_diagnose_cand *cd = &st->cand[st->chosen];
        if (name && len > 0)
            snprintf(name, len, "%s", cd->name);
        if (rmse_cv_mm)
            *rmse_cv_mm = cd->rmse_cv_mm;
        if (gain_mm2)
            *gain_mm2 = cd->gain_mm2;
        if (p_value)
            *p_value = cd->p_value;
        return RCH_FFI_OK;
    }
    return RCH_FFI_ERR_ARG;
}

int rch_ffi_diag_param(const rch_ffi_diag *g, unsigned k, char *name, size_t len, double *value, double *se,
                       char *unit, size_t unit_len)
{
    if (!g || k >= g->r.n_params || k >= RCH_DIAGNOSE_MAX_PARAMS)
        return RCH_FFI_ERR_ARG;
    const rch_diagnose_param *p = &g->r.params[k];
    if (name && len > 0)
        snprintf(name, len, "%s", p->name);
    if (value)
        *value = p->value;
    if (se)
        *se = p->se;
    if (unit && unit_len > 0)
        snprintf(unit, unit_len, "%s", p->unit);
    return RCH_FFI_OK;
}

int rch_ffi_diag_get(const rch_ffi_diag *g, const char *name, double *value)
{
    if (!g || !name || !value)
        return RCH_FFI_ERR_ARG;
    const rch_diagnose_result *r = &g->r;
    unsigned chosen = 0;
    for (unsigned s = 0; s < r->n_steps; ++s)
        chosen += r->steps[s].chosen >= 0;
    const struct {
        const char *name;
        double value;
    } t[] = {
        {"n", (double)r->n},
        {"n_groups", r->n_groups},
        {"folds", r->folds},
        {"n_chosen", chosen},
        {"n_params", r->n_params},
        {"noise_floor_mm", r->noise_floor_mm},
        {"floor_joints_mm", r->floor_joints_mm},
        {"floor_len_mm", r->floor_len_mm},
        {"train_rmse_geo_mm", r->train_rmse_geo_mm},
        {"rmse_before_mm", r->rmse_before_mm},
        {"rmse_after_mm", r->rmse_after_mm},
        {"noise_est_mm", r->noise_est_mm},
        {"n_jumps", r->jumps.n_jumps},
        {"rmse_jumps_mm", r->rmse_jumps_mm},
        {"dequant_corrected", (double)r->dequant_corrected},
        {"dequant_refused", (double)r->dequant_refused},
        {"effect_rms_mm", r->effect_rms_mm},
        {"q_step_deg", r->q_step_deg},
        {"len_step_mm", r->len_step_mm},
        {"time_ms", r->time_ms},
    };
    for (size_t i = 0; i < sizeof t / sizeof t[0]; ++i)
        if (strcmp(t[i].name, name) == 0) {
            *value = t[i].value;
            return RCH_FFI_OK;
        }
    return RCH_FFI_ERR_ARG;
}

int rch_ffi_diag_next(const rch_ffi_diag *g, int name_robot, char *buf, size_t len)
{
    if (!g || !buf || len == 0)
        return RCH_FFI_ERR_ARG;
    return rch_diagnose_next(buf, len, &g->r, g->data_path, name_robot ? g->robot_path : NULL) == 0
               ? RCH_FFI_OK
               : RCH_FFI_ERR_ARG;
}

int rch_ffi_diag_residuals(const rch_ffi_diag *g, double *before_mm, double *after_mm, double *floor_mm)
{
    if (!g)
        return RCH_FFI_ERR_ARG;
    const size_t n = g->r.n;
    if (before_mm && n)
        memcpy(before_mm, g->r.res_before_mm, n * sizeof *before_mm);
    if (after_mm && n)
        memcpy(after_mm, g->r.res_after_mm, n * sizeof *after_mm);
    if (floor_mm && n)
        memcpy(floor_mm, g->r.floor_mm, n * sizeof *floor_mm);
    return RCH_FFI_OK;
}

int rch_ffi_diag_json(const rch_ffi_diag *g, char *buf, size_t len, size_t *needed)
{
    if (!g)
        return RCH_FFI_ERR_ARG;
    return text_out(diag_json, &g->r, buf, len, needed);
}

int rch_ffi_diag_write(const rch_ffi_diag *g, const char *path, char *err, size_t err_len)
{
    if (!g || !path)
        return fail(RCH_FFI_ERR_ARG, err, err_len, "%s", "diag_write: NULL argument");
    const char *inputs[2] = {g->data_path, g->robot_path};
    rch_diag d;
    memset(&d, 0, sizeof d);
    if (rch_diagnose_save_model(&g->r, g->data_path, g->robot_path, path, inputs, 2, &d) != 0)
        return fail_diag(RCH_FFI_ERR_IO, err, err_len, &d);
    return RCH_FFI_OK;
}

/* ---- evaluation ---- */

int rch_ffi_evaluate(double *out, const rch_ffi_model *m, const char *data_path, int refit_encoder,
                     double same_pose_deg, char *err, size_t err_len)
{
    if (!out || !m || !data_path)
        return fail(RCH_FFI_ERR_ARG, err, err_len, "%s", "evaluate: NULL argument");
    if (!(same_pose_deg == 0.0 || (same_pose_deg >= 1e-9 && same_pose_deg <= 1.0)))
        return fail(RCH_FFI_ERR_ARG, err, err_len, "%s", "evaluate: same_pose_deg must be in [1e-9, 1] (0: 1e-6)");
    rch_data data;
    rch_diag d;
    if (rch_data_load_limited(&data, data_path, 0, &m->robot.model, &d) != 0)
        return fail_diag(RCH_FFI_ERR_INPUT, err, err_len, &d);
    const rch_evaluate_config cfg = {refit_encoder != 0, same_pose_deg > 0 ? same_pose_deg : 1e-6};
    rch_evaluate_result r;
    rc_solve_work *w = malloc(sizeof *w);
    char msg[512] = "out of memory";
    const int rc = w ? rch_evaluate(&r, &m->robot.model, data.s, data.n, &cfg, w, msg, sizeof msg) : -1;
    free(w);
    rch_data_free(&data);
    if (rc != 0)
        return fail(w ? RCH_FFI_ERR_SOLVER : RCH_FFI_ERR_NOMEM, err, err_len, "%s", msg);
    const double v[17] = {(double)r.m.n, r.m.rmse_mm, r.m.mean_abs_mm, r.m.sd_mm, r.m.mean_mm, r.m.max_mm,
                          r.encoder_refitted, r.encoder_mm[0], r.encoder_mm[1], r.encoder_mm[2],
                          r.encoder_refitted ? r.encoder_shift_mm : 0.0, (double)r.n_poses, (double)r.n_repeated,
                          r.ad_mean_mm, r.ad_max_mm, r.rd_mean_mm, r.rd_max_mm};
    memcpy(out, v, sizeof v);
    return RCH_FFI_OK;
}

/* ---- compensation ---- */

/* The compensation set-up of rch_comp_run (rch_comp.c): the determined
 * model, the mode, the point both models move. Heap: too large for a
 * thread's stack, and no static state. */
typedef struct {
    rc_model det, nom_pt;
    rch_model_unc unc;
    rc_comp_stream s;
} comp_setup;

int rch_ffi_compensate(const rch_ffi_model *cal, const rch_ffi_model *nominal, double *out_deg, int *status,
                       double *u95_mm, const double *q_deg, size_t n, int position_only, double max_dev_deg,
                       double max_unc_mm, const double *tool_mm, char *err, size_t err_len)
{
    if (!cal || !out_deg || (!q_deg && n > 0))
        return fail(RCH_FFI_ERR_ARG, err, err_len, "%s", "compensate: NULL argument");
    if (!(max_dev_deg >= 0.0) || !isfinite(max_dev_deg) || !(max_unc_mm >= 0.0) || position_only < 0 ||
        position_only > 2)
        return fail(RCH_FFI_ERR_ARG, err, err_len, "%s",
                    "compensate: max_dev_deg and max_unc_mm must be >= 0, position_only 0, 1 or 2");
    for (unsigned k = 0; tool_mm && k < 3; ++k)
        if (!isfinite(tool_mm[k]) || fabs(tool_mm[k]) > 2000.0)
            return fail(RCH_FFI_ERR_ARG, err, err_len, "%s", "compensate: tool_mm must be 3 finite numbers within "
                                                              "+-2000 mm");
    comp_setup *cs = malloc(sizeof *cs);
    if (!cs)
        return fail(RCH_FFI_ERR_NOMEM, err, err_len, "%s", "out of memory");
    const rch_robot *robot = &cal->robot;
    int version1 = 0;
    char held[256];
    cs->det = robot->model;
    memset(&cs->unc, 0, sizeof cs->unc);
    const int calibrated = robot->has_nominal || robot->unc.present;
    if (calibrated)
        rch_comp_determined(&cs->det, &cs->unc, &version1, held, sizeof held, robot, &robot->nominal);
    const int orient = cs->unc.present && !version1 && cs->unc.orientation_determined;
    const int pos_only = position_only == 1 || (position_only == 0 && !orient && calibrated);
    rch_comp_point_model(&cs->det, &cs->det, tool_mm);
    rch_comp_point_model(&cs->nom_pt, nominal ? &nominal->robot.model : &robot->nominal, tool_mm);
    rc_comp_config cfg;
    memset(&cfg, 0, sizeof cfg);
    cfg.max_dev_rad = (rc_real)(max_dev_deg * DEG);
    cfg.flags = pos_only ? RC_COMP_FLAG_POSITION_ONLY : 0u;
    const rc_status st0 = rc_comp_stream_init(&cs->s, &cs->det, &cs->nom_pt, &cfg);
    if (st0 != RC_OK) {
        free(cs);
        return fail(RCH_FFI_ERR_NUMERIC, err, err_len, "the model cannot be used for compensation: %s",
                    rc_strerror(st0));
    }
    const rch_model_unc *gate = cs->unc.present && !version1 ? &cs->unc : NULL;
    const double lim = max_unc_mm > 0 ? max_unc_mm : gate && gate->has_prior ? INFINITY : 1.0;
    const rc_model *m = &cs->det;
    int rc = RCH_FFI_OK;
    for (size_t i = 0; i < n && rc == RCH_FFI_OK; ++i) {
        const double *in = &q_deg[RC_NJ * i];
        rc_real q[RC_NJ], qc[RC_NJ];
        double qd[RC_NJ];
        for (unsigned j = 0; j < RC_NJ && rc == RCH_FFI_OK; ++j) {
            q[j] = (rc_real)(in[j] * DEG);
            qd[j] = (double)q[j];
            if (!(qd[j] >= m->q_min_rad[j] && qd[j] <= m->q_max_rad[j])) {
                if (err && err_len > 0)
                    snprintf(err, err_len, "target %zu: q%u = %g deg is outside the joint limits [%g, %g] deg", i,
                             j + 1, in[j], m->q_min_rad[j] / DEG, m->q_max_rad[j] / DEG);
                rc = RCH_FFI_ERR_RANGE;
            }
        }
        if (rc != RCH_FFI_OK)
            break;
        const double u95 = !gate ? NAN
                           : gate->has_prior ? rch_model_unc_radius95_mm(gate, m, qd)
                                             : rch_model_unc_pos95_mm(gate, m, qd);
        if (gate && !(u95 <= lim)) {
            for (unsigned j = 0; j < RC_NJ; ++j)
                out_deg[RC_NJ * i + j] = in[j]; /* left uncompensated: uncertainty above the limit */
            if (status)
                status[i] = 3;
            if (u95_mm)
                u95_mm[i] = rch_comp_u95_written(u95, 3, 0.0);
            continue;
        }
        rc_comp_result res;
        const rc_status st = rc_comp_stream_step(&cs->s, qc, &res, q);
        for (unsigned j = 0; j < RC_NJ; ++j)
            out_deg[RC_NJ * i + j] = (double)qc[j] / DEG;
        const int how = st != RC_OK ? 2 : res.exit == RC_COMP_POSITION_ONLY ? 1 : 0;
        if (status)
            status[i] = how;
        if (u95_mm)
            u95_mm[i] = rch_comp_u95_written(u95, how, (double)res.pos_err_mm);
    }
    free(cs);
    return rc;
}

/* ---- export and report ---- */

int rch_ffi_export(const char *model_path, const char *out_path, int format, const char *nominal_urdf,
                   int drop_joint_effects, unsigned *written, unsigned *effects_left, char *err, size_t err_len)
{
    if (!model_path || !out_path || (format != RCH_EXPORT_URDF && format != RCH_EXPORT_DH_CSV))
        return fail(RCH_FFI_ERR_ARG, err, err_len, "%s", "export: model, output and format 0 (URDF) or 1 (DH CSV)");
    if (nominal_urdf && format != RCH_EXPORT_URDF)
        return fail(RCH_FFI_ERR_ARG, err, err_len, "%s", "export: nominal_urdf applies to the URDF format only");
    const char *inputs[2] = {model_path, nominal_urdf};
    rch_out out;
    rch_diag d;
    memset(&d, 0, sizeof d);
    if (rch_out_open(&out, out_path, "--out", inputs, 2, &d) != 0)
        return fail_diag(RCH_FFI_ERR_IO, err, err_len, &d);
    rch_export_result res;
    memset(&res, 0, sizeof res);
    if (rch_export_file(&res, out.f, (rch_export_format)format, model_path, nominal_urdf, drop_joint_effects != 0,
                        &d) != 0) {
        rch_out_abort(&out);
        return fail_diag(d.file[0] ? RCH_FFI_ERR_INPUT : RCH_FFI_ERR_ARG, err, err_len, &d);
    }
    if (rch_out_commit(&out, &d) != 0)
        return fail_diag(RCH_FFI_ERR_IO, err, err_len, &d);
    if (written)
        *written = format == RCH_EXPORT_URDF ? res.n_joints : res.n_rows;
    if (effects_left)
        *effects_left = res.n_effects_left;
    return RCH_FFI_OK;
}

/* page without .html/.htm, then suffix, into buf (PATH_LEN + 32). */
static void beside(char *buf, size_t len, const char *page, const char *suffix)
{
    size_t n = strlen(page);
    if (n >= 5 && strcmp(page + n - 5, ".html") == 0)
        n -= 5;
    else if (n >= 4 && strcmp(page + n - 4, ".htm") == 0)
        n -= 4;
    snprintf(buf, len, "%.*s%s", (int)n, page, suffix);
}

static void add_path(char *paths, size_t len, const char *p)
{
    const size_t k = strlen(paths);
    if (k < len)
        snprintf(paths + k, len - k, "%s\n", p);
}

int rch_ffi_report(const rch_ffi_calib *c, const rch_ffi_diag *g, const char *html_path, const char *model_path,
                   double tolerance_mm, char *paths, size_t paths_len, char *err, size_t err_len)
{
    if (!c || !html_path || strcmp(html_path, "-") == 0 || strlen(html_path) >= PATH_LEN)
        return fail(RCH_FFI_ERR_ARG, err, err_len, "%s",
                    "report: a calibration and a page name (under 1024 bytes; the plot data go beside it)");
    char cal_path[PATH_LEN + 32], diag_path[PATH_LEN + 32];
    beside(cal_path, sizeof cal_path, html_path, ".calibration.json");
    beside(diag_path, sizeof diag_path, html_path, ".diagnosis.json");
    const rch_calib_cfg *cfg = &c->r.cfg;
    const char *ins[RCH_CALIB_MAX_FILES + 6];
    size_t n_ins = 0;
    ins[n_ins++] = model_path;
    ins[n_ins++] = cfg->robot_path;
    ins[n_ins++] = cfg->truth_path;
    ins[n_ins++] = cfg->validate_path;
    for (size_t i = 0; i < cfg->n_data_paths && cfg->data_paths; ++i)
        ins[n_ins++] = cfg->data_paths[i];
    if (g)
        ins[n_ins++] = g->data_path;
    rch_diag d;
    memset(&d, 0, sizeof d);
    const char *const outs[3] = {html_path, cal_path, g ? diag_path : NULL};
    static const char *const what[3] = {"report", "report (its calibration JSON)", "report (its diagnosis JSON)"};
    if (rch_outs_distinct(outs, what, 3, &d) != 0)
        return fail_diag(RCH_FFI_ERR_IO, err, err_len, &d);
    if (rch_save(cal_path, what[1], ins, n_ins, cal_json, &c->r, &d) != 0 ||
        (g && rch_save(diag_path, what[2], ins, n_ins, diag_json, &g->r, &d) != 0))
        return fail_diag(RCH_FFI_ERR_IO, err, err_len, &d);
    rch_report_cfg rc = {.cal_path = cal_path, .diag_path = g ? diag_path : NULL, .model_path = model_path,
                         .out_path = html_path, .tolerance_mm = tolerance_mm > 0.0 ? tolerance_mm : 0.0};
    rch_report_result res;
    memset(&res, 0, sizeof res);
    if (rch_report_write(&res, &rc, &d) != 0)
        return fail_diag(RCH_FFI_ERR_IO, err, err_len, &d);
    if (paths && paths_len > 0) {
        paths[0] = '\0';
        add_path(paths, paths_len, html_path);
        for (unsigned k = 0; k < res.n_csv && k < RCH_REPORT_MAX_CSV; ++k)
            add_path(paths, paths_len, res.csv[k]);
        add_path(paths, paths_len, cal_path);
        if (g)
            add_path(paths, paths_len, diag_path);
    }
    return RCH_FFI_OK;
}
