/* SPDX-License-Identifier: MIT */
/* rch_ffi_diag.c - the diagnosis of the flat C API (see rch_ffi.h):
 * rch_diagnose_file and rch_diagnose_inputs with the options of `rcal diagnose`, its verdict,
 * chosen effects, parameters, figures by name, Next command, residuals,
 * JSON and model file. Depends on: rch_diagnose. Memory: a diagnosis
 * handle on the heap, the caller's until rch_ffi_diag_free. Errors: a
 * status, the message into err. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rch_ffi_int.h"

/* The library call stands for the command in the JSON's "command". */
static char g_diag_name[] = "diagnose";

int rch_ffip_diag_json(FILE *f, const void *ctx)
{
    char *av[] = {g_diag_name};
    return rch_diagnose_json(f, ctx, 1, av);
}

/* ---- diagnosis ---- */

/* The options of a diagnosis into cfg: 0, or a status with err set. */
static int diag_cfg(rch_diagnose_cfg *cfg, unsigned long seed, unsigned folds, unsigned steps, unsigned flags,
                    double q_step_deg, double len_step_mm, double len_noise_mm, double alpha, unsigned max_iter,
                    char *err, size_t err_len)
{
    if ((folds && (folds < 2 || folds > RCH_DIAGNOSE_MAX_FOLDS)) || steps > RCH_DIAGNOSE_MAX_STEPS ||
        !(q_step_deg >= -1 && q_step_deg <= 10) || !(len_step_mm >= -1 && len_step_mm <= 10) ||
        !(len_noise_mm >= 0 && len_noise_mm <= 100) || !(alpha >= 0 && alpha <= 0.5) || max_iter > 100000)
        return fail(RCH_FFI_ERR_ARG, err, err_len, "%s",
                    "diagnose: folds 2..20, steps 1..4, q_step_deg and len_step_mm -1..10, len_noise_mm 0..100, "
                    "alpha 0..0.5, max_iter at most 100000");
    memset(cfg, 0, sizeof *cfg);
    cfg->folds = folds ? folds : 5;
    cfg->max_steps = steps ? steps : 3;
    cfg->seed = seed;
    cfg->q_step_deg = q_step_deg;
    cfg->len_step_mm = len_step_mm;
    cfg->len_noise_mm = len_noise_mm;
    cfg->alpha = alpha;
    cfg->max_iter = max_iter;
    cfg->no_jumps = (flags & RCH_FFI_DIAG_NO_JUMPS) != 0;
    cfg->dequantize = (flags & RCH_FFI_DIAG_DEQUANTIZE) != 0;
    cfg->jumps = (flags & RCH_FFI_DIAG_JUMPS) != 0;
    return RCH_FFI_OK;
}

int rch_ffi_diagnose(rch_ffi_diag **out, const char *data_path, const char *robot_path, unsigned long seed,
                     unsigned folds, unsigned steps, unsigned flags, double q_step_deg, double len_step_mm,
                     double len_noise_mm, double alpha, unsigned max_iter, char *err, size_t err_len)
{
    if (!out || !data_path || !robot_path)
        return fail(RCH_FFI_ERR_ARG, err, err_len, "%s", "diagnose: NULL argument (data and robot are required)");
    *out = NULL;
    rch_diagnose_cfg cfg;
    const int st = diag_cfg(&cfg, seed, folds, steps, flags, q_step_deg, len_step_mm, len_noise_mm, alpha, max_iter,
                            err, err_len);
    if (st != RCH_FFI_OK)
        return st;
    rch_ffi_diag *g = calloc(1, sizeof *g);
    if (!g)
        return fail(RCH_FFI_ERR_NOMEM, err, err_len, "%s", "out of memory");
    int too_long = 0;
    rch_ffip_copy_opt(g->data_path, data_path, &too_long);
    rch_ffip_copy_opt(g->robot_path, robot_path, &too_long);
    if (too_long) {
        free(g);
        return fail(RCH_FFI_ERR_ARG, err, err_len, "diagnose: a path longer than %s bytes", "1023");
    }
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

/* The "\n"-separated paths of list into g->files from slot at (v: their
 * pointers); the count, or -1 when one is too long or there are too many. */
static int split_paths(const char **v, rch_ffi_diag *g, size_t at, const char *list)
{
    int k = 0;
    for (const char *p = list; p && *p;) {
        const char *e = strchr(p, '\n');
        const size_t len = e ? (size_t)(e - p) : strlen(p);
        if (len > 0) {
            if (k >= RCH_DIAGNOSE_MAX_FILES || len >= PATH_LEN)
                return -1;
            memcpy(g->files[at + (size_t)k], p, len);
            g->files[at + (size_t)k][len] = '\0';
            v[k] = g->files[at + (size_t)k];
            ++k;
        }
        p = e ? e + 1 : p + len;
    }
    return k;
}

int rch_ffi_diagnose_inputs(rch_ffi_diag **out, const char *data_paths, const char *positions_paths,
                            const char *robot_path, const char *effects, unsigned long seed, unsigned folds,
                            unsigned steps, unsigned flags, double q_step_deg, double len_step_mm,
                            double len_noise_mm, double alpha, unsigned max_iter, char *err, size_t err_len)
{
    if (!out || !robot_path)
        return fail(RCH_FFI_ERR_ARG, err, err_len, "%s", "diagnose: NULL argument (the robot is required)");
    *out = NULL;
    rch_diagnose_cfg cfg;
    const int st = diag_cfg(&cfg, seed, folds, steps, flags, q_step_deg, len_step_mm, len_noise_mm, alpha, max_iter,
                            err, err_len);
    if (st != RCH_FFI_OK)
        return st;
    rch_ffi_diag *g = calloc(1, sizeof *g);
    if (!g)
        return fail(RCH_FFI_ERR_NOMEM, err, err_len, "%s", "out of memory");
    int too_long = 0;
    rch_ffip_copy_opt(g->robot_path, robot_path, &too_long);
    rch_ffip_copy_opt(g->effects, effects ? effects : "", &too_long);
    const int nd = split_paths(g->data_v, g, 0, data_paths);
    const int np = split_paths(g->pos_v, g, RCH_DIAGNOSE_MAX_FILES, positions_paths);
    if (too_long || nd < 0 || np < 0) {
        free(g);
        return fail(RCH_FFI_ERR_ARG, err, err_len, "diagnose: at most 16 files of each kind, each path shorter than %s "
                                                   "bytes", "1024");
    }
    if (nd + np == 0) {
        free(g);
        return fail(RCH_FFI_ERR_ARG, err, err_len, "%s", "diagnose: no data: give data or positions files");
    }
    if (nd > 0)
        snprintf(g->data_path, sizeof g->data_path, "%s", g->data_v[0]);
    rch_diagnose_in in;
    memset(&in, 0, sizeof in);
    in.data_paths = g->data_v;
    in.n_data = (size_t)nd;
    in.positions_paths = g->pos_v;
    in.n_positions = (size_t)np;
    in.robot_path = g->robot_path;
    in.effects = g->effects[0] ? g->effects : NULL;
    rch_diag d;
    memset(&d, 0, sizeof d);
    if (rch_diagnose_inputs(&g->r, &in, &cfg, &d) != 0) {
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
        {"jumps_implausible", r->jumps_implausible},
        {"jump_max_mm", r->jump_max_mm},
        {"jumps_by_calibrate", r->jumps_by_calibrate},
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

int rch_ffi_diag_nuisance(const rch_ffi_diag *g, char *buf, size_t len)
{
    if (!g || !buf || len == 0)
        return RCH_FFI_ERR_ARG;
    return rch_diagnose_nuisance(buf, len, &g->r) == 0 ? RCH_FFI_OK : RCH_FFI_ERR_ARG;
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
    return rch_ffip_text_out(rch_ffip_diag_json, &g->r, buf, len, needed);
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
