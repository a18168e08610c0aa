/* SPDX-License-Identifier: MIT */
/* rch_ffi_calib.c - the calibration of the flat C API (see rch_ffi.h): the
 * checks `rcal calibrate` makes, rch_calib_run from data files or from
 * arrays (through a temporary CSV, removed after), the result's metrics,
 * parameters, standard errors and figures by name, its model and JSON; and
 * the evaluation of a model on new data (rch_evaluate). Depends on:
 * rch_calib, rch_data, rch_evaluate, rch_file (temporaries). Memory: a
 * calibration handle on the heap, the caller's until rch_ffi_calib_free;
 * the solver's workspace freed before return. Errors: a status, the message
 * into err. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "rc_solve.h"
#include "rch_data.h"
#include "rch_evaluate.h"
#include "rch_ffi_int.h"
#include "rch_calib_effects.h"
#include "rch_file.h"
#include "rch_prior.h"

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
    const char *const *positions; /* (n_positions) tracker positions files, or NULL */
    size_t n_positions;
    const char *data_text; /* the one data "file"'s rows in memory (the arrays), or NULL */
    size_t data_text_len;
    const double *cable_points_mm; /* (n_cable_points x 3) a tool plate's nominal points, flange frame, or NULL */
    size_t n_cable_points;
    double cable_point_sd_mm; /* their tolerance (0: the default) */
} cal_opts;

/* ---- calibration ---- */

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
    for (size_t i = 0; i < cfg->n_positions_paths; ++i)
        for (size_t j = 0; j < cfg->n_data_paths + i; ++j) {
            const char *o = j < cfg->n_data_paths ? cfg->data_paths[j] : cfg->positions_paths[j - cfg->n_data_paths];
            if (rch_same_file(cfg->positions_paths[i], o) || strcmp(cfg->positions_paths[i], o) == 0)
                return fail(RCH_FFI_ERR_ARG, err, err_len, "positions %s is given twice or is another input: refused",
                            cfg->positions_paths[i]);
        }
    if (cfg->residuals_path && (cfg->cases > 1 || cfg->jumps))
        return fail(RCH_FFI_ERR_ARG, err, err_len, "%s",
                    "residuals is for one calibration without jumps (not with cases or jumps)");
    return RCH_FFI_OK; /* the joints within the robot's limits, the data's and the validation's: rch_inputs_load,
                          which reads each file once */
}

static int calibrate(rch_ffi_calib **out, const char *const *data_paths, size_t n_data, const cal_opts *o,
                     char *err, size_t err_len)
{
    if (!out || (n_data > 0 && !data_paths) || (o->n_positions > 0 && !o->positions) ||
        n_data + o->n_positions == 0 || !o->robot)
        return fail(RCH_FFI_ERR_ARG, err, err_len, "%s",
                    "calibrate: NULL argument (data or positions, and robot, are required)");
    *out = NULL;
    if (n_data > RCH_CALIB_MAX_FILES || o->n_positions > RCH_CALIB_MAX_FILES)
        return fail(RCH_FFI_ERR_ARG, err, err_len, "%s", "calibrate: at most 16 data and 16 positions files");
    rch_calib_cfg cfg;
    rch_calib_cfg_init(&cfg);
    if (rch_method_parse(&cfg.method, o->method ? o->method : "lm") != 0) {
        char msg[256];
        snprintf(msg, sizeof msg, "unknown method '%s' (%s)", o->method, RC_METHOD_LIST);
        return fail(RCH_FFI_ERR_ARG, err, err_len, "%s", msg);
    }
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
        c->data_v[i] = rch_ffip_copy_opt(c->data[i], data_paths[i], &too_long);
    }
    for (size_t i = 0; i < o->n_positions; ++i) {
        if (!o->positions[i]) {
            free(c);
            return fail(RCH_FFI_ERR_ARG, err, err_len, "%s", "calibrate: a NULL positions path");
        }
        c->pos_v[i] = rch_ffip_copy_opt(c->pos[i], o->positions[i], &too_long);
    }
    cfg.data_path = n_data ? c->data_v[0] : NULL;
    cfg.data_paths = n_data ? c->data_v : NULL;
    cfg.n_data_paths = n_data;
    cfg.data_text = o->data_text;
    cfg.data_text_len = o->data_text_len;
    cfg.positions_paths = o->n_positions ? c->pos_v : NULL;
    cfg.n_positions_paths = o->n_positions;
    cfg.no_screen = (o->flags & RCH_FFI_CAL_NO_SCREEN) != 0;
    cfg.no_dequantize = (o->flags & RCH_FFI_CAL_NO_DEQUANTIZE) != 0;
    cfg.prior_stated = (o->flags & RCH_FFI_CAL_PRIOR_STATED) != 0;
    cfg.no_length_offset = (o->flags & RCH_FFI_CAL_NO_LENGTH_OFFSET) != 0;
    cfg.no_drift = (o->flags & RCH_FFI_CAL_NO_DRIFT) != 0;
    cfg.force = (o->flags & RCH_FFI_CAL_FORCE) != 0;
    cfg.robot_path = rch_ffip_copy_opt(c->robot_path, o->robot, &too_long);
    cfg.truth_path = rch_ffip_copy_opt(c->truth_path, o->truth, &too_long);
    cfg.fix = rch_ffip_copy_opt(c->fix, o->fix, &too_long);
    cfg.effects = rch_ffip_copy_opt(c->effects, o->effects, &too_long);
    cfg.validate_path = rch_ffip_copy_opt(c->validate, o->validate, &too_long);
    cfg.plots_dir = rch_ffip_copy_opt(c->plots, o->plots, &too_long);
    cfg.residuals_path = rch_ffip_copy_opt(c->residuals, o->residuals, &too_long);
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
    if (o->n_cable_points > RC_MAX_TARGETS || (o->n_cable_points > 0 && !o->cable_points_mm) ||
        !(o->cable_point_sd_mm == 0.0 || (o->cable_point_sd_mm >= 1e-6 && o->cable_point_sd_mm <= 100.0))) {
        free(c);
        if (err && err_len > 0)
            snprintf(err, err_len, "calibrate: at most %d cable points (mm, flange frame) and their sd in [1e-06, "
                     "100] mm (0: the default)", RC_MAX_TARGETS);
        return RCH_FFI_ERR_ARG;
    }
    for (size_t k = 0; k < o->n_cable_points; ++k)
        for (unsigned a = 0; a < 3; ++a) {
            const double x = o->cable_points_mm[3 * k + a];
            if (!isfinite(x) || fabs(x) > 2000.0) {
                free(c);
                if (err && err_len > 0)
                    snprintf(err, err_len, "calibrate: cable point %zu: need X, Y, Z in mm in the flange frame, "
                             "each within 2000", k);
                return RCH_FFI_ERR_ARG;
            }
            cfg.cable_points_mm[k][a] = x;
        }
    cfg.n_cable_points = (unsigned)o->n_cable_points;
    cfg.cable_point_sd_mm = o->cable_point_sd_mm;
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
                        truth_path, cases, case_samples, plots_dir, residuals_path, NULL, 0, NULL, 0, NULL, 0, 0.0};
    return calibrate(out, data_paths, n_data, &o, err, err_len);
}

int rch_ffi_calibrate_inputs(rch_ffi_calib **out, const char *const *data_paths, size_t n_data,
                             const char *const *positions_paths, size_t n_positions, const double *cable_points_mm,
                             size_t n_cable_points, double cable_point_sd_mm, const char *robot_path,
                             const char *method, double test_fraction, unsigned long seed, unsigned max_iter,
                             const char *fix, const char *effects, unsigned flags, const char *validate_path,
                             const char *truth_path, unsigned long cases, size_t case_samples, const char *plots_dir,
                             const char *residuals_path, char *err, size_t err_len)
{
    const cal_opts o = {robot_path, method, test_fraction, seed, max_iter, fix, effects, flags, validate_path,
                        truth_path, cases, case_samples, plots_dir, residuals_path, positions_paths, n_positions, NULL, 0, cable_points_mm,
                        n_cable_points, cable_point_sd_mm};
    return calibrate(out, data_paths, n_data, &o, err, err_len);
}

/* The name the arrays' rows go by inside (rch_calib_cfg.data_text). */
#define RCH_FFI_ARRAYS_NAME "rcal-ffi-arrays"

/* A message about the arrays' rows (named RCH_FFI_ARRAYS_NAME) names the arrays: "TMP:L:C: m"
 * becomes "arrays, sample L-2 (0-based): m" (the header is line 1), any other
 * mention of TMP "<arrays>". */
static void name_arrays(char *err, size_t err_len, const char *tmp)
{
    if (!err || err_len == 0)
        return;
    const size_t tl = strlen(tmp);
    char out[2048], *hit = strstr(err, tmp);
    if (!hit)
        return;
    char *end = NULL;
    const unsigned long line = hit[tl] == ':' ? strtoul(hit + tl + 1, &end, 10) : 0;
    if (line >= 2 && end && *end == ':') {
        const char *rest = end + 1;
        while (*rest >= '0' && *rest <= '9')
            ++rest;
        if (*rest == ':')
            ++rest;
        while (*rest == ' ')
            ++rest;
        snprintf(out, sizeof out, "%.*sarrays, sample %lu (0-based): %s", (int)(hit - err), err, line - 2, rest);
    } else
        snprintf(out, sizeof out, "%.*s<arrays>%s", (int)(hit - err), err, hit + tl);
    snprintf(err, err_len, "%s", out);
}

int rch_ffi_calibrate_arrays(rch_ffi_calib **out, const double *q_deg, const double *len_mm, const double *xyz_mm,
                             const int *group, const int *outlet, const int *target, size_t n,
                             const double *cable_points_mm, size_t n_cable_points, double cable_point_sd_mm,
                             const char *robot_path,
                             const char *method, double test_fraction, unsigned long seed, unsigned max_iter,
                             const char *fix, const char *effects, unsigned flags, const char *validate_path,
                             const char *truth_path, unsigned long cases, size_t case_samples, const char *plots_dir,
                             const char *residuals_path, char *err, size_t err_len)
{
    if (!out || !q_deg || !len_mm || n == 0)
        return fail(RCH_FFI_ERR_ARG, err, err_len, "%s", "calibrate: no samples");
    *out = NULL;
    for (size_t i = 0; i < n; ++i)
        if ((group && (group[i] < 0 || group[i] > 65535)) || (outlet && (outlet[i] < 0 || outlet[i] > 255)) ||
            (target && (target[i] < 0 || target[i] >= RC_MAX_TARGETS))) {
            if (err && err_len > 0)
                snprintf(err, err_len, "calibrate: sample %zu: group labels must be in 0..65535, outlet labels in "
                         "0..255, target (cable point) labels in 0..%d", i, RC_MAX_TARGETS - 1);
            return RCH_FFI_ERR_ARG;
        }
    /* the rows in memory, as a file's (the one CSV parser checks them): no temporary file */
    const char *tmp = RCH_FFI_ARRAYS_NAME;
    char *text = NULL;
    size_t text_len = 0;
    FILE *f = open_memstream(&text, &text_len);
    if (!f)
        return fail(RCH_FFI_ERR_NOMEM, err, err_len, "%s", "out of memory");
    int bad = fprintf(f, "q1,q2,q3,q4,q5,q6,L%s%s%s%s\n", xyz_mm ? ",x,y,z" : "", group ? ",group" : "",
                      outlet ? ",outlet" : "", target ? ",target" : "") < 0;
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
        if (target)
            bad |= fprintf(f, ",%d", target[i]) < 0;
        bad |= fputc('\n', f) == EOF;
    }
    bad |= fclose(f) != 0;
    const char *paths[1] = {tmp};
    const cal_opts o = {robot_path, method, test_fraction, seed, max_iter, fix, effects, flags, validate_path,
                        truth_path, cases, case_samples, plots_dir, residuals_path, NULL, 0, text, text_len,
                        cable_points_mm, n_cable_points, cable_point_sd_mm};
    int rc = bad ? fail(RCH_FFI_ERR_NOMEM, err, err_len, "%s", "out of memory (the arrays' rows)")
                 : calibrate(out, paths, 1, &o, err, err_len);
    free(text);
    if (rc != RCH_FFI_OK)
        name_arrays(err, err_len, tmp);
    if (rc == RCH_FFI_OK) {
        int unused = 0;
        rch_ffip_copy_opt((*out)->data[0], "<arrays>", &unused); /* the model file's "data" */
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
    rch_ffip_param_out(&r->model, k, r->finite ? r->model.x[k] : 0.0, name, len, &v, unit);
    rch_ffip_param_out(&r->model, k, r->finite ? r->model.x[k] - nominal : 0.0, NULL, 0, &dv, NULL);
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
        {"length_offset_fitted", r->sys.tested, r->sys.offset_fitted},
        {"drift_fitted", r->sys.tested, r->sys.drift_fitted},
        {"judge_ratio", r->judge.done, r->judge.ratio},
        {"judge_floor_mm", r->judge.done, r->judge.floor_mm},
        {"judge_usable", r->judge.done, !r->judge.beyond && !r->judge.worse_than_nominal},
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

/* The library call stands for the command in the JSON's "command". */
static char g_cal_name[] = "calibrate";

int rch_ffip_cal_json(FILE *f, const void *ctx)
{
    char *av[] = {g_cal_name};
    return rch_calib_json(f, ctx, 1, av);
}

int rch_ffi_calib_json(const rch_ffi_calib *c, char *buf, size_t len, size_t *needed)
{
    if (!c)
        return RCH_FFI_ERR_ARG;
    return rch_ffip_text_out(rch_ffip_cal_json, &c->r, buf, len, needed);
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
    if (rch_robot_outlets_of(&m->robot, data.s, data.n, data.line, data_path, &d) != 0) {
        rch_data_free(&data);
        return fail_diag(RCH_FFI_ERR_INPUT, err, err_len, &d);
    }
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
