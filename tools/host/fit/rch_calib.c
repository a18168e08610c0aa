/* SPDX-License-Identifier: MIT */
/* rch_calib.c - the calibration pipeline and the nominal-FK check (see rch_calib.h). */
#include "rch_calib.h"
#include "rch_cost.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <lapacke.h>

#include "rc_version.h"
#include "rch_data.h"
#include "rch_dequant.h"
#include "rch_groups.h"
#include "rch_opt.h"
#include "rch_plot.h"
#include "rch_prior.h"
#include "rch_comp.h"
#include "rc_rand.h"
#include "rch_resid.h"
#include "rch_sha256.h"
#include "rch_jw.h"
#include "rch_save.h"
#include "rch_sim.h"
#include "rch_stats.h"
#include "rch_text.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif
#define DEG (M_PI / 180.0)

/* The first guess of outlet k's position (k = 0: e) from its samples. */
static int guess_outlet(double e[3], const rc_model *m, unsigned k, const rc_sample *s, size_t n, rch_diag *d)
{
    rc_sample *sub = malloc((n ? n : 1) * sizeof *sub);
    size_t ns = 0;
    if (!sub) {
        rch_diag_set(d, "", 0, 0, "out of memory");
        return -1;
    }
    for (size_t i = 0; i < n; ++i)
        if (s[i].outlet == k && s[i].sensor == RC_SENSOR_LENGTH) /* a tracker's samples have no outlet */
            sub[ns++] = s[i];
    rc_status st = rc_encoder_guess(e, m, sub, ns);
    free(sub);
    char which[48] = "";
    if (k > 0)
        snprintf(which, sizeof which, " of outlet %u", k);
    if (st == RC_ERR_RANGE) {
        rch_diag_set(d, "", 0, 0,
                     "cannot place the encoder%s: the lengths fit no sphere around the nominal flange positions "
                     "(misfit above 15 %% of the lengths): the length column is not the cable, or the robot "
                     "is over 100 mm from its nominal model; give the outlet in the robot file (\"encoder_mm\")",
                     which);
        return -1;
    }
    if (st != RC_OK) {
        rch_diag_set(d, "", 0, 0, "cannot place the encoder%s: %s (the poses must spread in all three directions)",
                     which, rc_strerror(st));
        return -1;
    }
    return 0;
}

int rch_calib_bc(rc_model *start, rc_solve_work *w, const rc_model *nominal, int has_encoder, const rc_sample *s,
                 size_t n, rch_diag *d)
{
    *start = *nominal;
    const size_t n_len = rch_pos_count_lengths(s, n);
    if (n_len < n && rch_pos_effect_at(start, RC_EFF_TRACKER_ROTATION, NULL) >= 0 &&
        rch_pos_start(start, s, n, rch_pos_frame_given(start)) != 0) { /* closed form, then with e below */
        rch_diag_set(d, "", 0, 0, "cannot place the tracker: the positions do not spread in three directions");
        return -1;
    }
    if (!has_encoder && (n_len > 0 || n == 0)) { /* no lengths at all: e is held (rch_pos_fix_unseen) */
        double e[3];
        if (guess_outlet(e, start, 0, s, n, d) != 0)
            return -1;
        memcpy(&start->x[RC_P_ENC], e, sizeof e);
    }
    for (unsigned i = 0; i < start->n_effects; ++i) {
        const rc_effect *ef = &start->effects[i];
        if (ef->kind != RC_EFF_OUTLET)
            continue;
        double e[3];
        if (guess_outlet(e, start, ef->joint, s, n, d) != 0)
            return -1;
        memcpy(&start->x[ef->first], e, sizeof e);
    }
    uint8_t fixed[RC_MAX_PARAMS];
    memset(fixed, 1, sizeof fixed);
    fixed[RC_P_ENC] = fixed[RC_P_ENC + 1] = fixed[RC_P_ENC + 2] = 0;
    for (unsigned i = 0; i < start->n_effects; ++i) {
        const rc_effect_desc *ds = rc_effect_describe(start->effects[i].kind);
        if (start->effects[i].kind == RC_EFF_OUTLET || (ds && ds->side == RC_SIDE_SENSOR))
            memset(&fixed[start->effects[i].first], 0, start->effects[i].count);
    }
    rch_pos_fix_unseen(fixed, start, s, n);
    rc_solve_config cfg;
    memset(&cfg, 0, sizeof cfg);
    cfg.method = RC_METHOD_LM;
    cfg.max_iter = RCH_CALIB_BC_MAX_ITER;
    cfg.fixed = fixed;
    rc_solve_result res;
    rc_status st = rc_solve(start, &res, w, &cfg, s, n);
    if (st != RC_OK) {
        rch_diag_set(d, "", 0, 0, "fitting the encoder position failed: %s", rc_strerror(st));
        return -1;
    }
    return 0;
}

void rch_calib_cfg_init(rch_calib_cfg *cfg)
{
    memset(cfg, 0, sizeof *cfg);
    cfg->method = RC_METHOD_LM;
    cfg->test_fraction = 0.1;
    cfg->seed = 1;
    cfg->cases = 1;
}

int rch_calib_start(rc_model *start, rc_solve_work *w, const rch_robot *robot, const rc_sample *train, size_t n,
                    rch_diag *d)
{
    return rch_calib_bc(start, w, &robot->model, robot->has_encoder, train, n, d);
}

int rch_method_parse(rc_method *out, const char *name)
{
    return rc_method_from_name(out, name) == RC_OK ? 0 : -1;
}

/* The effects --effects may name, from the one table (rc_effect_desc.user),
 * for messages: "length_offset, ..., joint_periodic:J". */
static void effect_list(char *buf, size_t len)
{
    size_t pos = 0;
    buf[0] = '\0';
    for (unsigned k = 1; k <= RC_EFF_LAST && pos < len; ++k) {
        const rc_effect_desc *ds = rc_effect_describe(k);
        if (!ds || !ds->user)
            continue;
        pos += (size_t)snprintf(buf + pos, len - pos, "%s%s%s", pos ? ", " : "", ds->name,
                                ds->arg == RC_EFF_ARG_JOINT ? ":J" : ds->arg == RC_EFF_ARG_PERIOD ? ":P" : "");
    }
}

int rch_calib_effects(rc_model *m, const char *list, rch_diag *d)
{
    char buf[512], names[512];
    if (strlen(list) >= sizeof buf) {
        rch_diag_set(d, "", 0, 0, "--effects: list longer than %zu characters", sizeof buf - 1);
        return -1;
    }
    memcpy(buf, list, strlen(list) + 1);
    for (char *tok = buf, *next; tok && *tok; tok = next) {
        next = strchr(tok, ',');
        if (next)
            *next++ = '\0';
        char *colon = strchr(tok, ':');
        if (colon)
            *colon++ = '\0';
        const int kind = rc_effect_by_name(tok);
        const rc_effect_desc *ds = kind > 0 ? rc_effect_describe((unsigned)kind) : NULL;
        if (!ds || !ds->user) {
            effect_list(names, sizeof names);
            rch_diag_set(d, "", 0, 0, "--effects: unknown effect '%s' (%s)", tok, names);
            return -1;
        }
        if (ds->arg == RC_EFF_ARG_PERIOD) { /* the period's start value, mm */
            double per = 0.0;
            if (!colon || rch_parse_double(colon, &per) != 0 || !(per >= 1.0 && per <= 1000.0)) {
                rch_diag_set(d, "", 0, 0, "--effects: %s needs its period in mm (1..1000), e.g. %s:137", tok, tok);
                return -1;
            }
            rc_status st = rc_model_add_effect(m, (rc_effect_kind)kind, 0, 0);
            if (st != RC_OK) {
                rch_diag_set(d, "", 0, 0, "--effects: cannot add %s: %s", tok, rc_strerror(st));
                return -1;
            }
            m->x[m->effects[m->n_effects - 1].first + 2] = per;
            continue;
        }
        unsigned long j = 0;
        const int needs_joint = ds->arg == RC_EFF_ARG_JOINT;
        if (needs_joint && (!colon || rch_parse_ulong(colon, &j) != 0 || j < 1 || j > 6)) {
            rch_diag_set(d, "", 0, 0, "--effects: %s needs the joint, e.g. %s:2", tok, tok);
            return -1;
        }
        rc_status st = rc_model_add_effect(m, (rc_effect_kind)kind, needs_joint ? (unsigned)j - 1u : 0u, 0);
        if (st != RC_OK) {
            rch_diag_set(d, "", 0, 0, "--effects: cannot add %s%s%s: %s", tok, colon ? ":" : "", colon ? colon : "",
                         rc_strerror(st));
            return -1;
        }
    }
    return 0;
}

void rch_model_strip_nuisance(rc_model *out, const rc_model *m)
{
    rch_model_rebuild(out, m, 1, 0, NULL);
}

int rch_calib_fix(uint8_t *fixed, const rc_model *m, const char *list, rch_diag *d)
{
    const char *p = list;
    while (p && *p) {
        const char *end = strchr(p, ',');
        const size_t len = end ? (size_t)(end - p) : strlen(p);
        unsigned k;
        char name[64];
        for (k = 0; k < m->n_params; ++k) {
            rc_param_name(name, sizeof name, m, k);
            if (len > 0 && strlen(name) == len && strncmp(name, p, len) == 0)
                break;
        }
        if (len > 0 && k == m->n_params) {
            rch_diag_set(d, "", 0, 0, "--fix: unknown parameter '%.*s'", (int)(len < 64 ? len : 64), p);
            return -1;
        }
        if (len > 0)
            fixed[k] = 1;
        p = end ? end + 1 : NULL;
    }
    return 0;
}

static double now_ms(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec * 1e3 + (double)t.tv_nsec / 1e6;
}

/* Flange positions of the BC and the identified model against a simulated
 * truth over random poses, base heading and height aligned (cable lengths
 * cannot see them). */
static int truth_flange(rch_calib_result *r, rch_diag *d)
{
    rch_robot truth;
    if (rch_robot_load(&truth, r->cfg.truth_path, d) != 0)
        return -1;
    rc_sample *ws = malloc(RCH_CALIB_TRUTH_POSES * sizeof *ws);
    if (!ws) {
        rch_diag_set(d, "", 0, 0, "out of memory");
        return -1;
    }
    rc_rng g;
    rc_rng_seed(&g, RCH_CALIB_TRUTH_SEED);
    rch_sim_poses(ws, RCH_CALIB_TRUTH_POSES, &truth.model, 0.0, &g);
    rch_sim_flange_diff(&r->truth_before_rms_mm, &r->truth_before_max_mm, &r->before, &truth.model, ws,
                        RCH_CALIB_TRUTH_POSES, 1);
    rch_sim_flange_diff(&r->truth_after_rms_mm, &r->truth_after_max_mm, &r->model, &truth.model, ws,
                        RCH_CALIB_TRUTH_POSES, 1);
    free(ws);
    r->have_truth = 1;
    return 0;
}

/* Predicted 95 % flange-position uncertainty against the horizontal reach
 * of the flange, at the training poses and at random poses in the joint
 * limits: uncertainty_position.svg and its data, uncertainty_position.csv,
 * in plots_dir (rch_plot_save: never over an input, atomic). 0, or -1
 * with d set. */
static int uncertainty_plot(rch_calib_result *r, const rch_uncert *u, const rc_sample *train, rch_diag *d)
{
    const size_t nw = 1000, nt = r->n_train;
    double *x = malloc((nt + nw) * sizeof *x), *y = malloc((nt + nw) * sizeof *y);
    rch_plot *p = rch_plot_new("Predicted 95 % flange-position uncertainty of the calibrated model",
                               "horizontal reach of the flange from the base axis (mm)",
                               "predicted 95 % position uncertainty (mm)");
    const char *inputs[2 * RCH_CALIB_MAX_FILES + 4];
    size_t n_in = 0;
    int rc = -1;
    if (!x || !y || !p) {
        rch_diag_set(d, "", 0, 0, "out of memory");
        goto done;
    }
    if (rch_plot_mkdir(r->cfg.plots_dir) != 0) {
        rch_diag_set(d, "", 0, 0, "cannot create %s: %s", r->cfg.plots_dir, strerror(errno));
        goto done;
    }
    rc_rng g;
    rc_rng_seed(&g, RCH_CALIB_TRUTH_SEED);
    for (size_t i = 0; i < nt + nw; ++i) {
        double q[RC_NJ], pos[3];
        for (unsigned j = 0; j < RC_NJ; ++j)
            q[j] = i < nt ? train[i].q_rad[j]
                          : r->model.q_min_rad[j] + (r->model.q_max_rad[j] - r->model.q_min_rad[j]) * rc_rng_u01(&g);
        rc_fk(pos, NULL, &r->model, q);
        x[i] = sqrt(pos[0] * pos[0] + pos[1] * pos[1]);
        y[i] = rch_uncert_pos95_mm(u, &r->model, q);
    }
    rch_plot_subtitle(p, "from the parameter covariance of the fit, at the data's poses and at random poses");
    rch_plot_scatter(p, "random poses in the joint limits", x + nt, y + nt, nw);
    rch_plot_scatter(p, "the data's poses (training set)", x, y, nt);
    rch_plot_logy(p, 1);
    const int several = r->cfg.data_paths && r->cfg.n_data_paths;
    for (size_t k = 0; k < (several ? r->cfg.n_data_paths : 1u) && n_in < RCH_CALIB_MAX_FILES; ++k)
        inputs[n_in++] = several ? r->cfg.data_paths[k] : r->cfg.data_path;
    for (size_t k = 0; k < r->cfg.n_positions_paths && k < RCH_CALIB_MAX_FILES; ++k)
        inputs[n_in++] = r->cfg.positions_paths[k];
    inputs[n_in++] = r->cfg.validate_path;
    inputs[n_in++] = r->cfg.robot_path;
    inputs[n_in++] = r->cfg.truth_path;
    const rch_plot_dir pd = {r->cfg.plots_dir, inputs, n_in, NULL};
    rc = rch_plot_save(p, &pd, "uncertainty_position.svg", d);
    if (rc == 0)
        snprintf(r->plot_paths, sizeof r->plot_paths, "%s/uncertainty_position.svg\n%s/uncertainty_position.csv\n",
                 r->cfg.plots_dir, r->cfg.plots_dir);
    p = NULL; /* freed by rch_plot_save */
done:
    free(x);
    free(y);
    rch_plot_free(p);
    return rc;
}

/* Covariance (cluster-robust by set-up group when the groups allow it),
 * standard errors, classes, predicted uncertainty over the data and the
 * workspace, and the determined model. Leaves have_unc 0 when it cannot be
 * computed (too few samples for the free parameters). -1 (d set) only when
 * the plot asked for (plots_dir) cannot be written. */
static int uncertainty(rch_calib_result *r, const uint8_t *fixed, const rc_sample *train, const rc_model *fit,
                       const uint16_t *setup, rch_diag *d)
{
    rch_uncert u;
    char err[256];
    int rc = 0;
    if (rch_uncert_compute_map(&u, fit, fixed, train, setup, r->n_train, 1, r->prior_on ? r->prior_sd : NULL,
                               r->noise_mm, err, sizeof err) != 0)
        return 0;
    rch_model_unc_from(&r->unc, &u);
    if (rch_uncert_map_compute(&r->unc.map, &u, &r->model, train, r->n_train, RCH_CALIB_TRUTH_POSES,
                               RCH_CALIB_TRUTH_SEED) == 0) {
        r->unc.orientation_determined = r->unc.map.rot_det_median_deg < RCH_ORIENT_DETERMINED_DEG;
        r->have_unc = 1;
    }
    if (r->cfg.plots_dir)
        rc = uncertainty_plot(r, &u, train, d);
    rch_uncert_free(&u);
    rch_model_unc_determined(&r->determined, &r->model, &r->robot.nominal, &r->unc);
    return rc;
}

static size_t n_files(const rch_calib_cfg *cfg)
{
    return cfg->data_paths && cfg->n_data_paths ? cfg->n_data_paths : cfg->data_path ? 1 : 0; /* 0: positions only */
}

static const char *file_at(const rch_calib_cfg *cfg, size_t i)
{
    return cfg->data_paths && cfg->n_data_paths ? cfg->data_paths[i] : cfg->data_path;
}

/* Load every data file and merge them in the order given: samples, x, y, z
 * (kept only when every file has them), source lines; t becomes the
 * acquisition order over all files; the group column is kept only when
 * every file has one (numbers offset per file). counts (files): samples
 * of each. */
static int load_all(rch_data *out, size_t *counts, const rch_calib_cfg *cfg, rch_diag *d)
{
    const size_t nf = n_files(cfg);
    memset(out, 0, sizeof *out);
    if (nf > RCH_CALIB_MAX_FILES) {
        rch_diag_set(d, "", 0, 0, "at most %d data files", RCH_CALIB_MAX_FILES);
        return -1;
    }
    if (nf == 0)
        return 0; /* tracker positions only (append_positions) */
    if (nf == 1) {
        int rc = rch_data_load(out, file_at(cfg, 0), 0, d);
        counts[0] = out->n;
        if (rc == 0 && rch_data_check_units(out, file_at(cfg, 0), d) != 0) {
            rch_data_free(out);
            return -1;
        }
        return rc;
    }
    rch_data part[RCH_CALIB_MAX_FILES];
    size_t total = 0, k = 0;
    int all_xyz = 1, all_group = 1;
    for (size_t f = 0; f < nf; ++f) {
        if (rch_data_load(&part[f], file_at(cfg, f), 0, d) != 0 ||
            rch_data_check_units(&part[f], file_at(cfg, f), d) != 0) {
            if (part[f].s)
                rch_data_free(&part[f]);
            for (size_t g = 0; g < f; ++g)
                rch_data_free(&part[g]);
            return -1;
        }
        counts[f] = part[f].n;
        total += part[f].n;
        all_xyz &= part[f].xyz != NULL;
        all_group &= part[f].has_group;
    }
    out->s = malloc(total * sizeof *out->s);
    out->line = malloc(total * sizeof *out->line);
    out->xyz = all_xyz ? malloc(total * sizeof *out->xyz) : NULL;
    int ok = out->s && out->line && (!all_xyz || out->xyz);
    unsigned goff = 0;
    for (size_t f = 0; f < nf; ++f) {
        unsigned gmax = 0;
        for (size_t i = 0; ok && i < part[f].n; ++i, ++k) {
            out->s[k] = part[f].s[i];
            out->s[k].t = total > 1 ? (double)k / (double)(total - 1) : 0.0;
            gmax = out->s[k].group > gmax ? out->s[k].group : gmax;
            out->s[k].group = (uint16_t)(all_group ? goff + out->s[k].group : f);
            out->line[k] = part[f].line[i];
            if (all_xyz)
                memcpy(out->xyz[k], part[f].xyz[i], sizeof out->xyz[k]);
        }
        goff += gmax + 1;
        rch_data_free(&part[f]);
    }
    out->n = total;
    out->has_group = all_group;
    out->has_t = 1;
    if (!ok) {
        rch_data_free(out);
        rch_diag_set(d, "", 0, 0, "out of memory");
        return -1;
    }
    return 0;
}

/* The tracker positions files (cfg.positions_paths) appended to data: three
 * samples a row (rch_positions.h), one set-up group a file, the tracker
 * frame and targets added to the model. 0, or -1 with d set. */
static int append_positions(rch_calib_result *r, rch_data *data, rch_diag *d)
{
    const rch_calib_cfg *cfg = &r->cfg;
    if (cfg->cases > 1 || cfg->residuals_path || cfg->dequantize || cfg->jumps) {
        rch_diag_set(d, "", 0, 0,
                     "--positions is not yet combined with --cases, --residuals, --dequantize-joints or --jumps");
        return -1;
    }
    rch_pos p;
    if (rch_pos_load(&p, cfg->positions_paths, cfg->n_positions_paths, 0.0, &r->robot.model, d) != 0)
        return -1;
    rc_sample *s = realloc(data->s, (data->n + p.n) * sizeof *s);
    if (s)
        data->s = s;
    unsigned *ln = s ? realloc(data->line, (data->n + p.n) * sizeof *ln) : NULL;
    if (ln)
        data->line = ln;
    if (!ln || rch_pos_add_effects(&r->robot.model, p.n_targets) != 0 ||
        (cfg->have_tracker_start && rch_pos_set_frame(&r->robot.model, cfg->tracker_start) != 0)) {
        rch_diag_set(d, "", 0, 0, ln ? "no room for the tracker frame and %u targets (RC_MAX_EFFECTS, RC_MAX_PARAMS)"
                                     : "out of memory", p.n_targets);
        rch_pos_free(&p);
        return -1;
    }
    for (size_t i = 0; i < p.n; ++i) {
        data->s[data->n + i] = p.s[i];
        data->s[data->n + i].group = (uint16_t)(r->n_groups + p.file[i]);
        data->line[data->n + i] = p.line[i];
    }
    data->n += p.n;
    free(data->xyz); /* the length files' x, y, z (only --dequantize-joints reads them) */
    data->xyz = NULL;
    r->n_groups += (unsigned)cfg->n_positions_paths;
    r->n_data = data->n;
    r->n_pos_rows = p.rows;
    r->n_pos_poses = p.poses;
    r->n_targets = p.n_targets;
    r->pos_has_sigma = p.has_sigma;
    r->pos_sigma_mm = p.sigma_mm;
    rch_provenance *pv = &r->prov;
    for (size_t f = 0; f < cfg->n_positions_paths && pv->n_files < RCH_PROV_MAX_FILES; ++f) {
        size_t c = 0;
        for (size_t i = 0; i < p.n; ++i)
            c += p.file[i] == f;
        pv->file[pv->n_files] = cfg->positions_paths[f];
        pv->samples[pv->n_files] = c;
        if (rch_sha256_file(pv->sha256[pv->n_files], cfg->positions_paths[f]) != 0)
            snprintf(pv->sha256[pv->n_files], sizeof pv->sha256[0], "unreadable");
        pv->n_files++;
    }
    rch_pos_free(&p);
    return 0;
}

/* The model on data the fit never saw (no refit). */
static int validate(rch_calib_result *r, rc_solve_work *w, rch_diag *d)
{
    rch_data v;
    char err[256];
    if (rch_data_load(&v, r->cfg.validate_path, 0, d) != 0)
        return -1;
    int rc = rch_evaluate(&r->validate, &r->model, v.s, v.n, NULL, w, err, sizeof err);
    rch_data_free(&v);
    if (rc != 0) {
        rch_diag_set(d, r->cfg.validate_path, 0, 0, "%s", err);
        return -1;
    }
    r->have_validate = 1;
    return 0;
}

/* Provenance: the data files, their samples and digests, the date, the tool. */
static void provenance(rch_calib_result *r, const size_t *counts)
{
    rch_provenance *p = &r->prov;
    p->n_files = (unsigned)n_files(&r->cfg);
    for (unsigned f = 0; f < p->n_files; ++f) {
        p->file[f] = file_at(&r->cfg, f);
        p->samples[f] = counts[f];
        if (rch_sha256_file(p->sha256[f], p->file[f]) != 0)
            snprintf(p->sha256[f], sizeof p->sha256[f], "unreadable");
    }
    time_t now = time(NULL);
    struct tm tmv;
    if (gmtime_r(&now, &tmv))
        strftime(p->date, sizeof p->date, "%Y-%m-%dT%H:%M:%SZ", &tmv);
    p->tool = "rcal " RC_VERSION_STRING;
}

/* Set-up groups: the file's group column, else consecutive samples sharing
 * the wrist joints at the joints' display step, never across two files. */
static void groups(rch_calib_result *r, rch_data *data, const size_t *counts)
{
    r->groups_from_file = data->has_group;
    if (data->has_group) {
        unsigned mx = 0;
        for (size_t i = 0; i < data->n; ++i)
            mx = data->s[i].group > mx ? data->s[i].group : mx;
        r->n_groups = mx + 1;
        return;
    }
    double *q = calloc(data->n * 3 + 1, sizeof *q), step = 0.0;
    if (q) {
        for (size_t i = 0; i < data->n; ++i)
            for (unsigned j = 0; j < 3; ++j)
                q[i * 3 + j] = data->s[i].q_rad[3 + j] / DEG;
        step = rch_dequant_detect_step(q, data->n * 3);
        free(q);
    }
    r->n_groups = 0;
    for (size_t f = 0, at = 0; f < n_files(&r->cfg); at += counts[f], ++f) {
        unsigned g = rch_groups_by_wrist(data->s + at, counts[f], step, NULL);
        for (size_t i = at; i < at + counts[f]; ++i)
            data->s[i].group = (uint16_t)(data->s[i].group + r->n_groups);
        r->n_groups += g;
    }
}

/* After the fit: truth, identifiability, uncertainty, validation. fit:
 * the model fitted to train (r->model, or with the jumps' offsets). */
static int finish(rch_calib_result *r, const uint8_t *fixed, const rc_sample *train, const rc_model *fit,
                  const uint16_t *setup, rch_diag *d)
{
    if (r->cfg.truth_path && r->finite && truth_flange(r, d) != 0)
        return -1;
    r->have_ident = r->finite && rch_ident_compute(&r->ident, fit, train, r->n_train) == 0;
    if (r->finite && uncertainty(r, fixed, train, fit, setup, d) != 0)
        return -1;
    if (r->cfg.validate_path && r->after_ok) {
        rc_solve_work *w = malloc(sizeof *w);
        int rc = w ? validate(r, w, d) : -1;
        free(w);
        if (rc != 0)
            return -1;
    }
    return 0;
}

/* Effective number of parameters of a MAP fit at m: trace(H^-1 A), A = J^T J
 * of the data and H = A + W with W the prior rows' weights (rc_solve.h). The
 * noise estimate SSR / (n - p_eff) counts as fitted only what the data (not
 * the prior) determined. Without a prior: the number of free parameters. */
static double effective_params(const rc_model *m, const rc_solve_config *cfg, const rc_sample *s, size_t n)
{
    uint16_t idx[RC_MAX_PARAMS];
    unsigned nf = 0;
    for (unsigned k = 0; k < m->n_params; ++k)
        if (!cfg->fixed || !cfg->fixed[k])
            idx[nf++] = (uint16_t)k;
    const size_t nn = nf ? (size_t)nf * nf : 1u;
    double *A = malloc(nn * sizeof *A), *H = malloc(nn * sizeof *H);
    double g[RC_MAX_PARAMS], jrow[RC_MAX_PARAMS], cost, pe = (double)nf;
    if (A && H && rc_normal_eq(A, g, &cost, jrow, m, idx, nf, s, n) == RC_OK) {
        memcpy(H, A, (size_t)nf * nf * sizeof *H);
        rc_prior_normal_eq(H, g, &cost, m, idx, nf, cfg); /* H = A + W, the solver's prior rows */
        for (unsigned i = 0; i < nf; ++i) {
            const double sd = cfg->prior_sd ? cfg->prior_sd[idx[i]] : 0.0;
            if (!(sd > 0.0 && isfinite(sd)))
                H[(size_t)i * nf + i] += 1e-12 * (H[(size_t)i * nf + i] + 1e-300); /* a free direction */
        }
        /* H X = A, trace X */
        if (LAPACKE_dposv(LAPACK_ROW_MAJOR, 'U', (lapack_int)nf, (lapack_int)nf, H, (lapack_int)nf, A,
                          (lapack_int)nf) == 0) {
            pe = 0.0;
            for (unsigned i = 0; i < nf; ++i)
                pe += A[(size_t)i * nf + i];
        }
    }
    free(A);
    free(H);
    return pe;
}

static int cmp_t(const void *a, const void *b)
{
    double x = ((const rc_sample *)a)->t, y = ((const rc_sample *)b)->t;
    return (x > y) - (x < y);
}

/* The jump fit of one pass: the first search finds the change points
 * (rch_jumps_find), every later fit of the same training set refits at them
 * (rch_jumps_refit): the noise passes, the attachment comparison and the
 * final fit move the change points' sizes, not where they are. */
static int jumps_fit(rch_calib_result *r, rc_solve_work *w, const uint8_t *fixed, const rch_jumps_config *jc,
                     const rc_sample *sorted, char *err, size_t errlen)
{
    if (r->have_jump_at) {
        const int rc = rch_jumps_refit(&r->jumps, &r->before, fixed, sorted, r->n_train, r->jump_at, r->n_jump_at,
                                       jc, w, err, errlen);
        r->jumps.rms_before_mm = r->jump_rms_before_mm; /* the geometry alone, from the search */
        return rc;
    }
    if (rch_jumps_find(&r->jumps, &r->before, fixed, sorted, r->n_train, jc, w, err, errlen) != 0)
        return -1;
    r->jump_rms_before_mm = r->jumps.rms_before_mm;
    r->n_jump_at = r->jumps.n_jumps;
    memcpy(r->jump_at, r->jumps.at, r->jumps.n_jumps * sizeof r->jump_at[0]);
    r->have_jump_at = 1;
    return 0;
}

/* Length jumps (nuisance): detected on the training samples in acquisition
 * order and fitted with the geometry; r->model becomes the geometry alone
 * (what predicts a new pose). Held-out samples are labelled with their
 * segment to evaluate; those between a jump and the training samples around
 * it cannot be placed (their segment is a guess) and are counted apart. */
static int fit_jumps(rch_calib_result *r, rc_solve_work *w, const uint8_t *fixed, const rc_solve_config *scfg,
                     const rc_sample *train, const rc_sample *eval_set, size_t n_eval, rch_diag *d)
{
    rc_sample *tr = malloc(r->n_train * sizeof *tr), *ev = malloc(n_eval * sizeof *ev);
    uint16_t *setup = NULL;
    char err[256];
    int rc = -1;
    if (!tr || !ev) {
        rch_diag_set(d, "", 0, 0, "out of memory");
        goto done;
    }
    memcpy(tr, train, r->n_train * sizeof *tr);
    memcpy(ev, eval_set, n_eval * sizeof *ev);
    qsort(tr, r->n_train, sizeof *tr, cmp_t);
    setup = malloc((r->n_train ? r->n_train : 1) * sizeof *setup);
    if (!setup) {
        rch_diag_set(d, "", 0, 0, "out of memory");
        goto done;
    }
    for (size_t i = 0; i < r->n_train; ++i)
        setup[i] = tr[i].group; /* set-up groups: the clusters of the covariance */
    rch_jumps_config jc;
    memset(&jc, 0, sizeof jc);
    jc.solve = scfg;
    if (jumps_fit(r, w, fixed, &jc, tr, err, sizeof err) != 0) {
        if (r->n_test)
            rch_diag_set(d, "", 0, 0, "length jumps: %s: the training samples, %zu of the %zu rows after %zu held "
                         "out (--test-fraction 0 fits them all; or record more poses)", err, r->n_train,
                         r->n_train + r->n_test, r->n_test);
        else
            rch_diag_set(d, "", 0, 0, "length jumps: %s", err);
        goto done;
    }
    r->have_jumps = 1;
    r->model = r->jumps.geometry;
    rch_stats sa;
    memset(&sa, 0, sizeof sa);
    r->n_ambiguous = 0;
    for (size_t i = 0; i < n_eval; ++i) {
        ev[i].group = (uint16_t)rch_jumps_segment(&r->jumps, ev[i].t);
        int amb = 0;
        for (unsigned k = 0; k < r->jumps.n_jumps; ++k) {
            size_t a = r->jumps.at[k]; /* first training sample after the jump; a - 1 the last before */
            amb |= a > 0 && ev[i].t > tr[a - 1].t && ev[i].t < tr[a].t;
        }
        double l;
        if (!amb && rc_meas(&l, NULL, &r->jumps.model, &ev[i]) == RC_OK)
            rch_stats_add(&sa, l - ev[i].len_mm);
        r->n_ambiguous += (size_t)amb;
    }
    rch_stats_metrics(&r->after_unambiguous, &sa);
    r->after_ok = rc_eval(&r->after_m, &r->jumps.model, ev, n_eval) == RC_OK;
    for (size_t i = 0; i < r->n_train; ++i)
        tr[i].group = (uint16_t)rch_jumps_segment(&r->jumps, tr[i].t);
    rc_eval(&r->train_before, &r->before, tr, r->n_train);
    if (!r->after_ok || rc_eval(&r->train_after, &r->jumps.model, tr, r->n_train) != RC_OK)
        memset(&r->train_after, 0, sizeof r->train_after);
    uint8_t fxj[RC_MAX_PARAMS];
    memcpy(fxj, fixed, sizeof fxj);
    if (r->jumps.n_jumps) /* the first segment's offset is the reference */
        fxj[r->jumps.model.effects[r->jumps.model.n_effects - 1].first] = 1;
    rc = finish(r, fxj, tr, &r->jumps.model, setup, d);
done:
    free(tr);
    free(ev);
    free(setup);
    return rc;
}

/* One maximum a posteriori fit from r->before (cfg: the prior set up, its
 * noise estimated here): the residuals' sd the prior is weighed against
 * comes from the data: start from the start model's RMS (a weak prior),
 * then SSR / (n - p_eff) of each fit, until it settles (2 %). Every pass
 * starts from the start model, so a pass never inherits the previous one's
 * excursions. With --jumps each pass is a jump search. r->model (and
 * r->jumps), r->noise_mm, r->p_eff, r->noise_passes are set; *chi2 is the
 * MAP objective in units of the noise variance (SSR / noise^2 + prior). */
static rc_status map_fit(rch_calib_result *r, rc_solve_work *w, rc_solve_config *pcfg, const uint8_t *fixed,
                         const rc_sample *train, double *chi2)
{
    rc_solve_config cfg = *pcfg;
    rc_status st = RC_OK;
    double ssr = 0.0, chi2_loop = INFINITY;
    {
        /* The residuals' sd the prior is weighed against, from the data: start
         * from the start model's RMS (a weak prior), then SSR / (n - p_eff) of
         * each fit, until it settles (2 %). Every pass starts from the start
         * model, so a pass never inherits the previous one's excursions. */
        rc_metrics m0;
        double noise = rc_eval(&m0, &r->before, train, r->n_train) == RC_OK && m0.rmse_mm > 0.0 ? m0.rmse_mm : 1.0;
        rc_sample *sorted = NULL;
        if (r->cfg.jumps && (sorted = malloc(r->n_train * sizeof *sorted)) != NULL) {
            memcpy(sorted, train, r->n_train * sizeof *sorted);
            qsort(sorted, r->n_train, sizeof *sorted, cmp_t);
        }
        for (unsigned pass = 0; pass < 6; ++pass) {
            cfg.prior_noise_mm = noise;
            const rc_model *fitm = &r->model;
            const rc_sample *fs = train;
            const uint8_t *fx = fixed;
            uint8_t fxj[RC_MAX_PARAMS];
            r->model = r->before;
            if (r->cfg.jumps && sorted) {
                rch_jumps_config jc;
                char err[256];
                memset(&jc, 0, sizeof jc);
                jc.solve = &cfg;
                if (pass <= 1 && !r->attach_m0)
                    r->have_jump_at = 0; /* the change points depend on the prior's weight: searched again
                                            until the noise is near its final value (pass 1), refitted after */
                if (jumps_fit(r, w, fixed, &jc, sorted, err, sizeof err) != 0)
                    break; /* fit_jumps reports it */
                fitm = &r->jumps.model;
                fs = sorted;
                memset(fxj, 0, sizeof fxj);
                memcpy(fxj, fixed, r->before.n_params);
                if (r->jumps.n_jumps)
                    fxj[r->jumps.model.effects[r->jumps.model.n_effects - 1].first] = 1;
                fx = fxj;
                for (size_t i = 0; i < r->n_train; ++i)
                    sorted[i].group = (uint16_t)rch_jumps_segment(&r->jumps, sorted[i].t);
            } else {
                st = rc_solve(&r->model, &r->solve, w, &cfg, train, r->n_train);
                if (st != RC_OK)
                    break;
            }
            rc_solve_config pc = cfg;
            pc.fixed = fx;
            if (rc_cost(&ssr, fitm, fs, r->n_train) != RC_OK)
                break;
            chi2_loop = (ssr + rc_prior_cost(fitm, &pc)) / (noise * noise);
            r->p_eff = effective_params(fitm, &pc, fs, r->n_train);
            r->noise_passes = pass + 1;
            const double dof = (double)r->n_train - r->p_eff;
            const double next = dof > 1.0 ? sqrt(ssr / dof) : noise;
            const int settled = fabs(next - noise) <= 0.02 * noise;
            noise = next > 1e-6 ? next : 1e-6;
            if (settled)
                break;
        }
        free(sorted);
        r->noise_mm = cfg.prior_noise_mm = noise;
        r->model = r->before;
        if (st == RC_OK && !r->cfg.jumps)
            st = rc_solve(&r->model, &r->solve, w, &cfg, train, r->n_train);
    }
    *chi2 = r->cfg.jumps ? chi2_loop : INFINITY;
    if (st == RC_OK && !r->cfg.jumps) {
        const rc_model *fitm = &r->model;
        double c = 0.0;
        rc_solve_config pc = cfg;
        uint8_t fxj[RC_MAX_PARAMS];
        memcpy(fxj, fixed, sizeof fxj);
        pc.fixed = fxj;
        if (rc_cost(&c, fitm, train, r->n_train) == RC_OK) /* the SSR does not depend on the order */
            *chi2 = (c + rc_prior_cost(fitm, &pc)) / (cfg.prior_noise_mm * cfg.prior_noise_mm);
    }
    *pcfg = cfg;
    return st;
}

/* The cable attachment, decided by the data. Lengths cannot tell the flange
 * centre from a point on the flange axis (d6 against the attachment's z,
 * a6 and theta6 against its x, y): with an attachment vector the flange
 * centre is only as well known as the prior of a6, d6. So the vector is
 * kept only when the data need it: its fit (chi2_1) must beat the fit with
 * the cable at the flange centre (chi2_0) by more than its Occam penalty,
 * 2 sum ln(prior sd / posterior sd) over its three components (the Laplace
 * evidence of the two models). Otherwise the model without it is used.
 * r->attach_* record the decision. */
static rc_status choose_attachment(rch_calib_result *r, rc_solve_work *w, rc_solve_config *cfg, uint8_t *fixed,
                                   const rc_sample *train, double chi2_1)
{
    const rc_model m1 = r->model, before1 = r->before;
    const rch_jumps j1 = r->jumps;
    const rc_solve_result s1 = r->solve;
    const double noise1 = r->noise_mm, peff1 = r->p_eff;
    const unsigned passes1 = r->noise_passes;
    double mean1[RC_MAX_PARAMS], sd1[RC_MAX_PARAMS];
    memcpy(mean1, r->prior_mean, sizeof mean1);
    memcpy(sd1, r->prior_sd, sizeof sd1);
    /* the attachment's posterior sd */
    int first = -1;
    for (unsigned e = 0; e < m1.n_effects; ++e)
        if (m1.effects[e].kind == RC_EFF_TOOL_OFFSET)
            first = m1.effects[e].first;
    if (first < 0)
        return RC_OK;
    rch_uncert u;
    char err[128];
    const rc_model *fm = r->cfg.jumps ? &j1.model : &m1;
    uint8_t fx[RC_MAX_PARAMS];
    memcpy(fx, fixed, sizeof fx);
    if (r->cfg.jumps && j1.n_jumps)
        fx[j1.model.effects[j1.model.n_effects - 1].first] = 1;
    double occam = 0.0;
    if (rch_uncert_compute_map(&u, fm, fx, train, NULL, r->n_train, 0, r->prior_sd, noise1, err, sizeof err) != 0)
        return RC_OK; /* keep the attachment */
    for (int k = 0; k < 3; ++k)
        if (u.se[first + k] > 0.0 && r->prior_sd[first + k] > 0.0)
            occam += log(r->prior_sd[first + k] / u.se[first + k]);
    rch_uncert_free(&u);
    /* the model with the cable at the flange centre */
    rc_model m0;
    rch_comp_point_model(&m0, &before1, NULL);
    r->before = m0;
    memset(r->prior_mean, 0, sizeof r->prior_mean);
    memset(r->prior_sd, 0, sizeof r->prior_sd);
    rch_prior_fill(r->prior_mean, r->prior_sd, &r->before, &r->robot.nominal, &r->robot.prior);
    double chi2_0 = INFINITY;
    rc_solve_config c0 = *cfg;
    c0.prior_mean = r->prior_mean;
    c0.prior_sd = r->prior_sd;
    r->attach_m0 = 1; /* at the attachment model's change points */
    rc_status st = map_fit(r, w, &c0, fixed, train, &chi2_0);
    r->attach_m0 = 0;
    /* both objectives in units of the attachment model's noise */
    const double chi2_0n = st == RC_OK ? chi2_0 * (r->noise_mm * r->noise_mm) / (noise1 * noise1) : INFINITY;
    r->attach_dchi2 = chi2_0n - chi2_1;
    r->attach_occam = 2.0 * occam;
    if (st == RC_OK && r->attach_dchi2 <= r->attach_occam) {
        r->attach_centred = 1;
        r->robot.model = m0; /* the model file carries no attachment */
        *cfg = c0;
        return RC_OK;
    }
    /* keep the attachment model */
    r->attach_centred = 0;
    r->model = m1;
    r->before = before1;
    r->jumps = j1;
    r->solve = s1;
    r->noise_mm = noise1;
    r->p_eff = peff1;
    r->noise_passes = passes1;
    memcpy(r->prior_mean, mean1, sizeof mean1);
    memcpy(r->prior_sd, sd1, sizeof sd1);
    cfg->prior_noise_mm = noise1;
    return RC_OK;
}

/* The default run looks for length jumps as diagnose does: a model fitted
 * across a jump it does not know is wrong, so rch_calib_save_model refuses it
 * and names --jumps. r->jumps_found, r->jump_check_max_mm. */
static void jump_check(rch_calib_result *r, rc_solve_work *w, const uint8_t *fixed, const rc_solve_config *cfg,
                       const rc_sample *train)
{
    rc_sample *tr = malloc(r->n_train * sizeof *tr);
    rch_jumps *j = malloc(sizeof *j);
    rc_model keep_model = r->model;
    if (tr && j) {
        memcpy(tr, train, r->n_train * sizeof *tr);
        qsort(tr, r->n_train, sizeof *tr, cmp_t);
        rch_jumps_config jc;
        char err[128];
        memset(&jc, 0, sizeof jc);
        jc.solve = cfg;
        if (rch_jumps_find(j, &r->before, fixed, tr, r->n_train, &jc, w, err, sizeof err) == 0) {
            r->n_jump_at = j->n_jumps; /* every change point found: the nuisance fit starts from them */
            r->jump_check_steps = j->n_jumps;
            r->jump_rms_before_mm = j->rms_before_mm;
            memcpy(r->jump_at, j->at, j->n_jumps * sizeof r->jump_at[0]);
            /* A step can also describe an effect the geometry lacks (a joint
             * compliance leaves steps of a few times the residual, inside
             * set-ups too): a jump counts as a sensor event when it is far
             * above what is left, 8 x the RMS residual with the jumps (measured:
             * the real IRB120 file's two largest are 10.6 and 14.5 x, a third
             * 3.7 x; the step a missing joint compliance leaves, 4.4 x in
             * tests/diagnose/test_diag_roundtrip.c). */
            for (unsigned k = 0; k < j->n_jumps; ++k) {
                if (!(fabs(j->size_mm[k]) > 8.0 * j->rms_after_mm))
                    continue;
                r->jumps_found++;
                if (fabs(j->size_mm[k]) > r->jump_check_max_mm)
                    r->jump_check_max_mm = fabs(j->size_mm[k]);
            }
        }
    }
    r->model = keep_model;
    free(tr);
    free(j);
}

/* Identification and the figures, once the split is made. */
static int fit_and_report(rch_calib_result *r, rc_solve_work *w, const rc_sample *train, const rc_sample *test,
                          rch_diag *d)
{
    if (!r->keep_jump_at)
        r->have_jump_at = 0; /* a new training set: its change points are searched */
    if (rch_calib_start(&r->before, w, &r->robot, train, r->n_train, d) != 0)
        return -1;
    r->model = r->before;
    uint8_t fixed[RC_MAX_PARAMS];
    memset(fixed, 0, sizeof fixed);
    if (r->cfg.fix && rch_calib_fix(fixed, &r->model, r->cfg.fix, d) != 0)
        return -2;
    rch_pos_fix_unseen(fixed, &r->model, train, r->n_train); /* what only an absent sensor sees */
    rc_solve_config cfg;
    memset(&cfg, 0, sizeof cfg);
    cfg.method = r->cfg.method;
    cfg.fixed = fixed;
    cfg.max_iter = r->cfg.max_iter;
    cfg.seed = r->cfg.seed;
    r->prior_on = !r->cfg.no_prior && (cfg.method == RC_METHOD_LM || cfg.method == RC_METHOD_LTLM);
    if (r->prior_on) {
        memset(r->prior_mean, 0, sizeof r->prior_mean);
        memset(r->prior_sd, 0, sizeof r->prior_sd);
        rch_prior_fill(r->prior_mean, r->prior_sd, &r->before, &r->robot.nominal, &r->robot.prior);
        rch_prior_gauge(fixed);
        cfg.prior_mean = r->prior_mean;
        cfg.prior_sd = r->prior_sd;
    }
    const double t0 = now_ms();
    rc_status st = RC_OK;
    if (r->prior_on) {
        double chi2_1 = 0.0;
        st = map_fit(r, w, &cfg, fixed, train, &chi2_1);
        if (st == RC_OK && r->attach_auto)
            st = choose_attachment(r, w, &cfg, fixed, train, chi2_1);
    } else {
        st = rc_solve(&r->model, &r->solve, w, &cfg, train, r->n_train);
    }
    r->time_ms = now_ms() - t0;
    if (st != RC_OK) {
        rch_diag_set(d, "", 0, 0, "solver failed: %s", rc_strerror(st));
        return -1;
    }
    r->finite = 1;
    for (unsigned k = 0; k < r->model.n_params; ++k)
        r->finite &= isfinite(r->model.x[k]) != 0;
    const rc_sample *eval_set = r->n_test ? test : train;
    const size_t n_eval = r->n_test ? r->n_test : r->n_train;
    rc_eval(&r->before_m, &r->before, eval_set, n_eval);
    if (r->cfg.jumps) {
        return fit_jumps(r, w, fixed, &cfg, train, eval_set, n_eval, d);
    }
    if (r->prior_on && !r->cfg.no_jump_check && r->n_train >= 40 && !r->n_pos_rows) { /* jumps: a cable's */
        jump_check(r, w, fixed, &cfg, train);
        if (r->jumps_found && !r->cfg.residuals_path) {
            /* fit them as nuisance, as --jumps does: the default run never
             * hands on a geometry fitted across jumps */
            r->cfg.jumps = 1;
            r->jumps_auto = 1;
            r->have_jump_at = 1; /* at the change points the check found */
            r->keep_jump_at = 1;
            const int rc = fit_and_report(r, w, train, test, d);
            r->keep_jump_at = 0;
            return rc;
        }
    }
    r->after_ok = r->finite && rc_eval(&r->after_m, &r->model, eval_set, n_eval) == RC_OK;
    int train_ok = r->after_ok;
    if (eval_set == train) { /* nothing held out: the training figures are those */
        r->train_before = r->before_m;
        r->train_after = r->after_m;
    } else {
        rc_eval(&r->train_before, &r->before, train, r->n_train);
        train_ok = train_ok && rc_eval(&r->train_after, &r->model, train, r->n_train) == RC_OK;
    }
    if (!train_ok)
        memset(&r->train_after, 0, sizeof r->train_after);
    return finish(r, fixed, train, &r->model, NULL, d);
}

/* Joint angles from the file's x, y, z; inconsistent rows dropped (and from
 * file_of (n) when given). */
static int dequantize(rch_calib_result *r, rch_data *data, unsigned *file_of, rch_diag *d)
{
    if (!data->xyz) {
        rch_diag_set(d, r->cfg.data_path, 0, 0, "--dequantize-joints needs the x, y, z columns");
        return -1;
    }
    uint8_t *bad = calloc(data->n + 1, 1);
    if (!bad) {
        rch_diag_set(d, "", 0, 0, "out of memory");
        return -1;
    }
    rch_dequant(&r->dequant, bad, data->s, data->n, (const double(*)[3])data->xyz, &r->robot.nominal, 0.0);
    size_t k = 0;
    unsigned nr = 0;
    for (size_t i = 0; i < data->n; ++i) {
        if (bad[i]) {
            if (nr < 16)
                r->dequant_refused_lines[nr++] = data->line[i];
            continue;
        }
        data->s[k] = data->s[i];
        data->line[k] = data->line[i];
        if (file_of)
            file_of[k] = file_of[i];
        memcpy(data->xyz[k], data->xyz[i], sizeof data->xyz[k]);
        ++k;
    }
    data->n = k;
    free(bad);
    r->have_dequant = 1;
    return 0;
}

/* The split: random rows, or whole set-up groups drawn at random until the
 * held-out share is reached. idx (n): held-out indices first. */
static size_t split(size_t *idx, const rc_sample *s, size_t n, double fraction, int by_group, unsigned long long seed)
{
    size_t want = (size_t)floor(fraction * (double)n + 0.5);
    rch_split(idx, n, seed);
    if (rch_pos_count_tracker(s, n) > 0 && want == 0) { /* all rows train: in file order (a row's x, y, z together) */
        for (size_t i = 0; i < n; ++i)
            idx[i] = i;
        return 0;
    }
    if (rch_pos_count_tracker(s, n) > 0 && want > 0)
        return rch_pos_split(idx, s, n, want); /* a tracker pose whole on one side (not by set-up group) */
    if (!by_group || want == 0)
        return want;
    size_t *tmp = n ? malloc(n * sizeof *tmp) : NULL, k = 0;
    if (!tmp)
        return want;
    /* take the groups of the shuffled rows in the order they come */
    uint8_t *taken = calloc(65536, 1);
    if (!taken) {
        free(tmp);
        return want;
    }
    for (size_t i = 0; i < n && k < want; ++i) {
        unsigned g = s[idx[i]].group;
        if (taken[g])
            continue;
        taken[g] = 1;
        for (size_t j = 0; j < n; ++j)
            if (s[j].group == g)
                tmp[k++] = j;
    }
    size_t nt = k;
    for (size_t j = 0; j < n; ++j)
        if (!taken[s[j].group])
            tmp[k++] = j;
    memcpy(idx, tmp, n * sizeof *idx);
    free(tmp);
    free(taken);
    return nt;
}

/* The 3-D errors of the tracker positions, before and after, held out (or
 * training when none is) and training. */
static void position_figures(rch_calib_result *r, const rc_sample *train, const rc_sample *test)
{
    const rc_sample *ev = r->n_test ? test : train;
    const size_t ne = r->n_test ? r->n_test : r->n_train;
    r->have_pos = r->after_ok && rch_pos_errors(&r->pos_before, &r->before, ev, ne) == 0 &&
                  rch_pos_errors(&r->pos_after, &r->model, ev, ne) == 0 &&
                  rch_pos_errors(&r->pos_train_after, &r->model, train, r->n_train) == 0;
}

/* One calibration on the rows sub (m) of data; held (m, or NULL) set to 1
 * for the held-out rows. */
static int run_once(rch_calib_result *r, rc_solve_work *w, const rc_sample *s, size_t m, unsigned long long seed,
                    uint8_t *held, rch_diag *d)
{
    size_t *idx = malloc((m ? m : 1) * sizeof *idx);
    rc_sample *train = NULL, *test = NULL;
    int rc = -1;
    if (!idx) {
        rch_diag_set(d, "", 0, 0, "out of memory");
        return -1;
    }
    r->n_test = split(idx, s, m, r->cfg.test_fraction, r->cfg.holdout_groups, seed);
    r->n_train = m - r->n_test;
    for (size_t i = 0; held && i < r->n_test; ++i)
        held[idx[i]] = 1;
    if (r->n_train < RC_N_BASE) {
        rch_diag_set(d, "", 0, 0, "%zu training samples; at least %d are needed for 27 parameters", r->n_train,
                     RC_N_BASE);
        goto done;
    }
    test = rch_data_pick(s, idx, r->n_test);
    train = rch_data_pick(s, idx + r->n_test, r->n_train);
    if (!test || !train) {
        rch_diag_set(d, "", 0, 0, "out of memory");
        goto done;
    }
    rc = fit_and_report(r, w, train, test, d);
    if (rc == 0 && r->n_pos_rows)
        position_figures(r, train, test);
done:
    free(idx);
    free(train);
    free(test);
    return rc;
}

/* Measured on the reference machine (docs/methods.md, "Cost estimates";
 * `rcal calibrate` on robotcali.csv, 1,041 rows, and on 10,000 simulated
 * rows): seconds per case = fixed + per_row * rows (* iterations for the
 * paper's methods, which run to their cap). */
double rch_calib_estimate_s(const rch_calib_cfg *cfg, size_t n_rows, double *bound_s)
{
    const double m = (double)(cfg->cases > 1 && cfg->case_samples && cfg->case_samples < n_rows ? cfg->case_samples
                                                                                                : n_rows);
    const double cases = cfg->cases > 1 ? (double)cfg->cases : 1.0;
    const int paper = cfg->method == RC_METHOD_LM_PAPER || cfg->method == RC_METHOD_LM_PAPER_DEG ||
                      cfg->method == RC_METHOD_LTLM_PAPER || cfg->method == RC_METHOD_LTLM_PAPER_DEG;
    const int chaotic = cfg->method == RC_METHOD_LTLM || cfg->method == RC_METHOD_LTLM_PAPER ||
                        cfg->method == RC_METHOD_LTLM_PAPER_DEG;
    double one, bound;
    if (paper) {
        const double it = cfg->max_iter ? (double)cfg->max_iter : 50.0;
        /* per training row and iteration: 2.7-7.8 us (ltlm-paper) and 0.6-1.9 us (lm-paper) measured as the
         * shared machine's load changed; the geometric middles */
        one = 0.1 + (chaotic ? 4.5e-6 : 0.9e-6) * m * (1.0 - cfg->test_fraction) * it;
        bound = one;
    } else {
        const double it = cfg->max_iter ? (double)cfg->max_iter : 100.0;
        one = chaotic ? 0.2 + 174e-6 * m : 0.06 + 53e-6 * m;
        bound = one + (chaotic ? 4.5e-6 : 0.9e-6) * m * it; /* every iteration to the cap */
    }
    if (cfg->jumps || !cfg->no_jump_check) {
        /* the jump search refits with the robust solver around candidate change points: 0.2x (simulated,
         * no jump) to 5x (robotcali.csv) the fit itself; 1.5x is the geometric middle. A paper method's run
         * refits with the robust solver once: small beside its iterations */
        const double jc = paper ? 0.05 : 1.5 * one;
        one += jc;
        bound += jc;
    }
    if (bound_s)
        *bound_s = cases * bound;
    return cases * one;
}

/* The paper's protocol: `cases` random subsets of case_samples rows, each
 * split and calibrated; the held-out RMSE before and after over the cases. */
static int run_cases(rch_calib_result *r, rc_solve_work *w, const rch_data *data, rch_diag *d)
{
    rch_calib_result *c = malloc(sizeof *c);
    size_t *idx = malloc((data->n ? data->n : 1) * sizeof *idx);
    size_t m = r->cfg.case_samples && r->cfg.case_samples < data->n ? r->cfg.case_samples : data->n;
    rc_sample *sub = NULL;
    int rc = -1;
    rch_progress pg;
    rch_progress_start(&pg, stderr, "rcal calibrate: cases", (double)r->cfg.cases,
                       rch_calib_estimate_s(&r->cfg, data->n, NULL));
    if (!c || !idx) {
        rch_diag_set(d, "", 0, 0, "out of memory");
        goto done;
    }
    for (unsigned long k = 0; k < r->cfg.cases; ++k) {
        rch_split(idx, data->n, r->cfg.seed * 1000003ull + k);
        free(sub);
        sub = rch_data_pick(data->s, idx, m);
        if (!sub) {
            rch_diag_set(d, "", 0, 0, "out of memory");
            goto done;
        }
        rch_calib_result *into = k == 0 ? r : c;
        if (k > 0) {
            memcpy(c, r, sizeof *c);
            c->cfg.truth_path = NULL;
            c->cfg.validate_path = NULL;
            c->cfg.plots_dir = NULL;
        }
        int one = run_once(into, w, sub, m, r->cfg.seed * 1000003ull + k + 7, NULL, d);
        if (one != 0) {
            rc = one;
            goto done;
        }
        rch_stats_add(&r->case_before, into->before_m.rmse_mm);
        rch_stats_add(&r->case_after, into->after_ok ? into->after_m.rmse_mm : NAN);
        if (into->have_jumps) {
            rch_stats_add(&r->case_unamb, into->after_unambiguous.rmse_mm);
            r->case_ambiguous += into->n_ambiguous;
        }
        r->cases_done++;
        fprintf(stderr, "rcal calibrate: case %lu of %lu: held-out RMSE %.4f -> %.4f mm\n", k + 1, r->cfg.cases,
                into->before_m.rmse_mm, into->after_m.rmse_mm);
        rch_progress_step(&pg, (double)(k + 1));
    }
    rc = 0;
done:
    free(c);
    free(idx);
    free(sub);
    return rc;
}

/* The per-sample residual CSV (cfg.residuals_path) of a single run: every
 * row with the identified model, set train or test by held (n); file_of (n)
 * the input file of each row. */
static int save_residuals(const rch_calib_result *r, const rch_data *data, const unsigned *file_of,
                          const uint8_t *held, rch_diag *d)
{
    const char *inputs[RCH_CALIB_MAX_FILES + 3] = {r->cfg.robot_path, r->cfg.truth_path, r->cfg.validate_path};
    const size_t nf = n_files(&r->cfg);
    for (size_t f = 0; f < nf; ++f)
        inputs[3 + f] = file_at(&r->cfg, f);
    rch_resid_table t;
    rch_resid_init(&t, inputs + 3, nf);
    int rc = 0;
    for (size_t i = 0; i < data->n && rc == 0; ++i)
        rc = rch_resid_add_model(&t, &r->model, &data->s[i], &data->line[i], &file_of[i], 1,
                                 held[i] ? RCH_RESID_TEST : RCH_RESID_TRAIN, 0);
    rch_data v;
    if (rc == 0 && r->have_validate) {
        rc = rch_data_load(&v, r->cfg.validate_path, 0, d);
        if (rc == 0) {
            rc = rch_resid_add_model(&t, &r->model, v.s, v.line, NULL, v.n, RCH_RESID_VALIDATE, 0);
            rch_data_free(&v);
        }
    }
    if (rc != 0 && !d->msg[0])
        rch_diag_set(d, "", 0, 0, "out of memory");
    if (rc == 0)
        rc = rch_resid_save(r->cfg.residuals_path, inputs, 3 + nf, &t, d);
    rch_resid_free(&t);
    return rc;
}

/* The cost, before the work: refused above --max-minutes (0, or -1 with d
 * set), said on stderr above 10 s. */
static int check_cost(const rch_calib_cfg *cfg, size_t n, rch_diag *d)
{
    double bound_s;
    const double est_s = rch_calib_estimate_s(cfg, n, &bound_s);
    const double limit_s = 60.0 * (cfg->max_minutes > 0.0 ? cfg->max_minutes : 60.0);
    char b1[32], b2[32], b3[32];
    if (est_s > limit_s) {
        char it[48];
        if (cfg->max_iter)
            snprintf(it, sizeof it, "--max-iter %u", cfg->max_iter);
        else
            snprintf(it, sizeof it, "the default iteration cap");
        rch_diag_set(d, "", 0, 0,
                     "this run would take about %s (%lu case(s) of %zu rows, %s, %s; the measured cost per row "
                     "on the reference machine, docs/methods.md), above the limit of %s: lower --cases, "
                     "--samples or --max-iter, or raise --max-minutes",
                     rch_cost_human(b1, sizeof b1, est_s), cfg->cases > 1 ? cfg->cases : 1ul,
                     cfg->cases > 1 && cfg->case_samples && cfg->case_samples < n ? cfg->case_samples : n,
                     rc_method_name(cfg->method), it, rch_cost_human(b3, sizeof b3, limit_s));
        return -1;
    }
    if (est_s > 10.0)
        fprintf(stderr, "rcal calibrate: %zu samples, %s: about %s (at most %s)\n", n,
                rc_method_name(cfg->method), rch_cost_human(b1, sizeof b1, est_s),
                rch_cost_human(b2, sizeof b2, bound_s));
    return 0;
}

int rch_calib_run(rch_calib_result *r, const rch_calib_cfg *cfg, rch_diag *d)
{
    memset(r, 0, sizeof *r);
    memset(d, 0, sizeof *d);
    r->cfg = *cfg;
    if (cfg->residuals_path && (cfg->cases > 1 || cfg->jumps)) {
        rch_diag_set(d, "", 0, 0, "--residuals is for one calibration without --jumps (not with --cases or --jumps)");
        return -2;
    }
    rch_data data;
    size_t counts[RCH_CALIB_MAX_FILES] = {0};
    if (rch_robot_load(&r->robot, cfg->robot_path, d) != 0 || load_all(&data, counts, cfg, d) != 0)
        return -1;
    r->n_data = data.n;
    if (check_cost(cfg, data.n, d) != 0) {
        rch_data_free(&data);
        return -2;
    }
    groups(r, &data, counts);
    provenance(r, counts);
    {
        const int no = rch_data_outlets(r->outlet_label, data.s, data.n, d);
        if (no < 0) {
            rch_data_free(&data);
            return -1;
        }
        r->n_outlets = (unsigned)no;
        for (unsigned k = 1; k < r->n_outlets; ++k)
            if (rc_model_add_effect(&r->robot.model, RC_EFF_OUTLET, k, 0) != RC_OK) {
                rch_diag_set(d, "", 0, 0, "cannot add outlet %u (RC_MAX_PARAMS or RC_MAX_EFFECTS)", k);
                rch_data_free(&data);
                return -1;
            }
    }
    if (cfg->n_positions_paths && append_positions(r, &data, d) != 0) {
        rch_data_free(&data);
        return -1;
    }
    const size_t n_len = rch_pos_count_lengths(data.s, data.n);
    int rc = -1;
    rc_solve_work *w = malloc(sizeof *w);
    unsigned *file_of = cfg->residuals_path ? malloc((data.n ? data.n : 1) * sizeof *file_of) : NULL;
    uint8_t *held = cfg->residuals_path ? calloc(data.n ? data.n : 1, 1) : NULL;
    if (cfg->residuals_path && (!file_of || !held)) {
        rch_diag_set(d, "", 0, 0, "out of memory");
        goto done;
    }
    for (size_t f = 0, i = 0; file_of && f < RCH_CALIB_MAX_FILES; ++f)
        for (size_t k = 0; k < counts[f] && i < data.n; ++k)
            file_of[i++] = (unsigned)f;
    int has_tool = 0;
    for (unsigned e = 0; e < r->robot.model.n_effects; ++e)
        has_tool |= r->robot.model.effects[e].kind == RC_EFF_TOOL_OFFSET;
    /* the cable attachment point in the flange frame is estimated by default
     * (with its prior): the flange centre is where compensation aims */
    const int want_tool = cfg->tool_offset || (!cfg->no_prior && (cfg->method == RC_METHOD_LM ||
                                                                   cfg->method == RC_METHOD_LTLM));
    r->attach_auto = want_tool && !has_tool && !cfg->tool_offset && n_len > 0;
    /* Hayati's beta where a joint axis is nominally parallel to the previous
     * one (alpha = 0 or 180 deg, rows 2..5): standard DH can tilt that axis
     * only with a d of metres, which the prior forbids, so the tilt gets its
     * own parameter (with the twists' prior) */
    if (want_tool && !cfg->tool_offset)
        for (unsigned i = 1; i + 1 < RC_NJ; ++i) {
            int have = 0;
            for (unsigned e = 0; e < r->robot.model.n_effects; ++e)
                have |= r->robot.model.effects[e].kind == RC_EFF_AXIS_TILT && r->robot.model.effects[e].joint == i;
            if (!have && fabs(sin(r->robot.nominal.x[RC_P_ALPHA(i)])) < 1e-6 &&
                rc_model_add_effect(&r->robot.model, RC_EFF_AXIS_TILT, i, 0) != RC_OK) {
                rch_diag_set(d, "", 0, 0, "cannot add the axis tilt of row %u (RC_MAX_PARAMS or RC_MAX_EFFECTS)", i + 1);
                goto done;
            }
        }
    if (want_tool && !has_tool && (n_len > 0 || cfg->tool_offset) &&
        rc_model_add_effect(&r->robot.model, RC_EFF_TOOL_OFFSET, 0, 0) != RC_OK) {
        rch_diag_set(d, "", 0, 0, "cannot add the tool offset (RC_MAX_PARAMS or RC_MAX_EFFECTS)");
        goto done;
    }
    if (!w) {
        rch_diag_set(d, "", 0, 0, "out of memory");
        goto done;
    }
    if (cfg->effects && rch_calib_effects(&r->robot.model, cfg->effects, d) != 0) {
        rc = -2;
        goto done;
    }
    if (cfg->dequantize && dequantize(r, &data, file_of, d) != 0)
        goto done;
    if (cfg->cases > 1)
        rc = run_cases(r, w, &data, d);
    else
        rc = run_once(r, w, data.s, data.n, cfg->seed, held, d);
    if (rc == 0 && cfg->residuals_path && r->finite && save_residuals(r, &data, file_of, held, d) != 0)
        rc = -1;
    if (rc == 0 && r->have_jumps && r->prov.n_files == 1)
        for (unsigned k = 0; k < r->jumps.n_jumps; ++k)
            for (size_t i = 0; i < data.n; ++i)
                if (data.s[i].t == r->jumps.at_t[k]) {
                    r->jump_lines[k] = data.line[i];
                    break;
                }
done:
    free(w);
    free(file_of);
    free(held);
    rch_data_free(&data);
    return rc;
}

static void print_metrics_row(FILE *f, const char *label, const rc_metrics *m)
{
    fprintf(f, "  %-38s %8.4f %8.4f %8.4f %8.4f\n", label, m->rmse_mm, m->mean_abs_mm, m->sd_mm, m->max_mm);
}

static void print_model(FILE *f, const rch_calib_result *r)
{
    const rc_model *m = &r->model, *nom = &r->robot.model, *bc = &r->before;
    fprintf(f, "identified model (the paper's Table 7 form; deltas against nominal):\n");
    fprintf(f, "  joint     a (mm)     d (mm)   alpha (deg)  theta (deg) |   da (mm)    dd (mm)  dalpha(deg)  "
               "dtheta(deg)\n");
    for (unsigned j = 0; j < RC_NJ; ++j) {
        const double *x = &m->x[4 * j], *x0 = &nom->x[4 * j];
        fprintf(f, "  %5u %10.4f %10.4f %12.5f %12.5f | %9.4f %10.4f %12.5f %12.5f\n", j + 1, x[0], x[1],
                x[2] / DEG, x[3] / DEG, x[0] - x0[0], x[1] - x0[1], (x[2] - x0[2]) / DEG, (x[3] - x0[3]) / DEG);
    }
    if (r->n_pos_rows && r->n_data == 3 * r->n_pos_rows)
        fprintf(f, "  encoder e: no cable lengths (tracker positions only), held\n\n");
    else
        fprintf(f, "  encoder e = (%.4f, %.4f, %.4f) mm  (before calibration: %.4f, %.4f, %.4f)\n\n", m->x[RC_P_ENC],
                m->x[RC_P_ENC + 1], m->x[RC_P_ENC + 2], bc->x[RC_P_ENC], bc->x[RC_P_ENC + 1], bc->x[RC_P_ENC + 2]);
}

/* Dequantized joints, length jumps, the protocol over cases. */
static void print_effects(FILE *f, const rch_calib_result *r)
{
    if (r->have_dequant) {
        const rch_dequant_result *q = &r->dequant;
        fprintf(f,
                "joints dequantized from x, y, z: %zu rows corrected (RMS %.4f deg, largest %.4f deg; |FK - xyz| "
                "%.4f -> %.6f mm), %zu refused as inconsistent",
                q->n_corrected, q->dq_rms_deg, q->dq_max_deg, q->fk_rms_before_mm, q->fk_rms_after_mm, q->n_refused);
        for (size_t i = 0; i < q->n_refused && i < 16; ++i)
            fprintf(f, "%s%u", i ? ", " : " (lines ", r->dequant_refused_lines[i]);
        fprintf(f, "%s\n", q->n_refused ? ")" : "");
    }
    if (r->have_jumps) {
        const rch_jumps *j = &r->jumps;
        fprintf(f, "length jumps in acquisition order (nuisance, not used at a new pose): %u found; training RMS "
                   "%.4f mm without them, %.4f mm with them\n",
                j->n_jumps, j->rms_before_mm, j->rms_after_mm);
        for (unsigned k = 0; k < j->n_jumps; ++k) {
            char where[48] = "";
            if (r->jump_lines[k])
                snprintf(where, sizeof where, " at line %u", r->jump_lines[k]);
            fprintf(f, "  jump %u%s (t %.4f): %+.4f +- %.4f mm\n", k + 1, where, j->at_t[k], j->size_mm[k],
                    j->se_mm[k]);
        }
        if (r->n_ambiguous)
            fprintf(f,
                    "  %zu held-out samples lie between a jump and the training samples around it (their segment "
                    "cannot be known): RMSE without them %.4f mm\n",
                    r->n_ambiguous, r->after_unambiguous.rmse_mm);
    }
    if (r->cases_done > 1)
        fprintf(f,
                "protocol: %lu cases of %zu random rows, %.0f %% held out%s: held-out RMSE before %.4f +- %.4f mm, "
                "after %.4f +- %.4f mm (mean +- sd over the cases; the figures below are case 1's)\n",
                r->cases_done, r->n_train + r->n_test, 100.0 * r->cfg.test_fraction,
                r->cfg.holdout_groups ? " (whole set-up groups)" : "", r->case_before.mean,
                rch_stats_sd(&r->case_before), r->case_after.mean, rch_stats_sd(&r->case_after));
    if (r->cases_done > 1 && r->case_unamb.n)
        fprintf(f,
                "  without the %zu held-out samples (of all cases) that lie between a jump and the training samples "
                "around it: after %.4f +- %.4f mm\n",
                r->case_ambiguous, r->case_unamb.mean, rch_stats_sd(&r->case_unamb));
    if (r->have_dequant || r->have_jumps || r->cases_done > 1)
        fprintf(f, "\n");
}

/* What the outlets add: the rigid motion their places fix (rch_prior_outlet_span). */
static void print_outlets(FILE *f, const rc_model *m)
{
    double pos[RC_MAX_OUTLETS][3], off = 0.0;
    unsigned n = 1;
    memcpy(pos[0], &m->x[RC_P_ENC], sizeof pos[0]);
    for (unsigned e = 0; e < m->n_effects && n < RC_MAX_OUTLETS; ++e)
        if (m->effects[e].kind == RC_EFF_OUTLET)
            memcpy(pos[n++], &m->x[m->effects[e].first], sizeof pos[0]);
    const int span = rch_prior_outlet_span(&off, (const double(*)[3])pos, n);
    fprintf(f, "  outlets: %u place%s", n, n == 1 ? "" : "s");
    if (n > 2)
        fprintf(f, " (largest distance from the line through the two farthest apart: %.0f mm)", off);
    fprintf(f, "; %s\n", rch_prior_outlet_span_text(span));
}

/* Parameters more than 3 prior sd from the prior's mean (the "OUTSIDE"
 * rows of the uncertainty table). */
static unsigned outside_prior(const rch_calib_result *r)
{
    const rch_model_unc *u = &r->unc;
    unsigned n = 0;
    for (unsigned k = 0; u->has_prior && k < r->model.n_params; ++k)
        if (u->prior_sd[k] > 0.0 && u->cls[k] != RCH_PARAM_FIXED)
            n += fabs(r->model.x[k] - r->prior_mean[k]) / u->prior_sd[k] > 3.0;
    return n;
}

/* The 3-D accuracy is far worse than the lengths: the poses leave the
 * geometry to the prior. */
static int accuracy_needs_poses(const rch_calib_result *r)
{
    const double a = r->unc.map.data_median_mm;
    return r->have_unc && r->after_ok && a > 10.0 * r->after_m.rmse_mm && a > 0.1;
}

/* The data file and the robot file as a next-step command names them,
 * quoted for the shell (rch_shell_join). */
typedef struct {
    char data[1100], robot[1100];
} hint_paths;

static void hint_paths_of(hint_paths *h, const rch_calib_result *r)
{
    const char *d = r->cfg.data_path ? r->cfg.data_path : "FILE";
    const char *b = r->cfg.robot_path ? r->cfg.robot_path : "ROBOT.json";
    rch_shell_join(h->data, sizeof h->data, 1, &d);
    rch_shell_join(h->robot, sizeof h->robot, 1, &b);
}

static void print_uncertainty(FILE *f, const rch_calib_result *r)
{
    const rch_model_unc *u = &r->unc;
    const rc_model *m = &r->model;
    if (u->kind == RCH_COV_CLUSTER)
        fprintf(f, "uncertainty (cluster-robust covariance over %u set-up groups%s; residual sigma %.4f mm):\n",
                u->n_groups, r->groups_from_file ? " of the file" : " found from the wrist joints", u->sigma_mm);
    else
        fprintf(f, "uncertainty (classical covariance: the samples carry no usable set-up groups; residual sigma "
                   "%.4f mm):\n",
                u->sigma_mm);
    if (u->has_prior)
        fprintf(f, "  maximum a posteriori with the physical prior (sd: lengths %.3g mm, twists %.3g deg, joint zeros "
                   "%.3g deg, cable attachment %.3g mm%s); noise %.4f mm estimated from the residuals "
                   "(%u fits, %.1f effective parameters)\n",
                r->robot.prior.length_mm, r->robot.prior.twist_deg, r->robot.prior.offset_deg,
                r->robot.prior.attachment_mm, r->robot.prior.from_file ? ", from the robot file" : ", defaults",
                r->noise_mm, r->noise_passes, r->p_eff);
    if (u->has_prior && r->n_pos_rows)
        fprintf(f, "  theta1 and d1 held (gauge): the tracker's frame absorbs the robot's heading and height, as "
                   "an outlet does for lengths; a cell sets its base frame anyway\n");
    else if (u->has_prior)
        fprintf(f, "  theta1 and d1 held (gauge): lengths from outlets whose places are estimated cannot see the "
                   "robot's heading and height against them; a cell sets its base frame anyway\n");
    print_outlets(f, m);
    if (r->attach_auto)
        fprintf(f, "  cable attachment: %s (an attachment vector improves the fit by %.1f against its Occam "
                   "penalty %.1f)\n",
                r->attach_centred ? "at the flange centre" : "estimated in the flange frame (the flange centre "
                                                             "relative to it is known only from the prior of a6, d6)",
                r->attach_dchi2, r->attach_occam);
    fprintf(f, "  parameter        value   1 std.error  class%s\n", u->has_prior ? "              data vs prior" : "");
    unsigned held = 0, outside = 0;
    char list[512] = "";
    for (unsigned k = 0; k < m->n_params; ++k) {
        char nm[64], se[32];
        const int unit = rc_param_unit(m, k);
        const double sc = unit == 1 ? 1.0 / DEG : 1.0;
        if (isfinite(u->se[k]))
            snprintf(se, sizeof se, "%11.5f", u->se[k] * sc);
        else
            snprintf(se, sizeof se, "%11s", "-");
        rc_param_name(nm, sizeof nm, m, k);
        char pc[96] = "";
        if (u->has_prior && u->prior_sd[k] > 0.0 && u->cls[k] != RCH_PARAM_FIXED) {
            const double dev = fabs(m->x[k] - r->prior_mean[k]) / u->prior_sd[k];
            outside += dev > 3.0;
            snprintf(pc, sizeof pc, "  %-10s (se %.0f %% of prior)%s",
                     rch_prior_class_name((rch_prior_class)u->prior_cls[k]), 100.0 * u->se[k] / u->prior_sd[k],
                     dev > 3.0 ? "  OUTSIDE the prior's plausible range (> 3 sd from nominal)" : "");
        }
        fprintf(f, "  %-10s %12.5f %s %-3s %-16s%s\n", nm, m->x[k] * sc, se,
                unit == 0 ? "mm" : unit == 1 ? "deg" : "", rch_param_class_name((rch_param_class)u->cls[k]), pc);
        if (k < RC_N_DH && u->comp_nominal[k]) {
            size_t len = strlen(list);
            snprintf(list + len, sizeof list - len, "%s%s", held ? " " : "", nm);
            ++held;
        }
    }
    hint_paths hp;
    hint_paths_of(&hp, r);
    if (outside)
        fprintf(f, "  next: %u parameter(s) OUTSIDE the prior's range are a real deviation (check the drawing) or "
                   "stand in for an effect the model lacks: rcal diagnose --data %s --robot %s%s\n",
                outside, hp.data, hp.robot, r->cfg.dequantize ? " --dequantize-joints" : "");
    fprintf(f,
            "predicted 3-D accuracy after compensation (95 %%, longest semi-axis of the flange-position "
            "ellipsoid): over the sampled region +-%.4f mm (median over the data's poses; max %.4f), whole "
            "workspace +-%.4f mm (median over %d random poses; max %.4f)\n",
            u->map.data_median_mm, u->map.data_max_mm, u->map.work_median_mm, RCH_CALIB_TRUTH_POSES,
            u->map.work_max_mm);
    if (accuracy_needs_poses(r))
        fprintf(f, "  next: the lengths are predicted to %.3f mm but the 3-D accuracy only to %.3f mm: the poses leave "
                   "most of the geometry to the prior; plan poses that move every joint, from more than one outlet: "
                   "rcal poses --robot %s --count 60 --outlet X,Y,Z --outlet X2,Y2,Z2 --out plan.csv\n",
                r->after_m.rmse_mm, u->map.data_median_mm, hp.robot);
    fprintf(f,
            "predicted flange-orientation uncertainty (95 %%) inside the data: +-%.4f deg with every parameter, "
            "+-%.4f deg with those compensation uses: orientation %s\n",
            u->map.rot_data_median_deg, u->map.rot_det_median_deg,
            u->orientation_determined ? "determined (compensation matches position and orientation)"
                                      : "NOT determined (compensation defaults to position-only)");
    fprintf(f,
            "compensation uses %u of 24 DH parameters as fitted; held at nominal (tied to a weak or not-identifiable "
            "combination that moves the robot): %s\n\n",
            RC_N_DH - held, held ? list : "none");
}

static void print_ident(FILE *f, const rch_ident *id, int prior)
{
    fprintf(f,
            "identifiability (%u parameters, at the solution): rank %u, %u not identifiable, %u weakly "
            "identifiable;\n  condition number %.3g over the identifiable part, observability index O1 %.4g\n",
            id->n_params, id->rank, id->n_params - id->rank, id->n_weak, id->cond, id->observability);
    for (unsigned k = 0; k < id->n_dirs; ++k) {
        fprintf(f, "  - %s (relative singular value %.1e): %s\n", id->dirs[k].weak ? "weak" : "NOT identifiable",
                id->dirs[k].sv_rel, id->dirs[k].combo);
        if (id->dirs[k].why[0])
            fprintf(f, "      %s\n", id->dirs[k].why);
    }
    if (id->n_combos)
        fprintf(f, "  what these directions hold (known sets of parameters whose columns are dependent):\n");
    for (unsigned k = 0; k < id->n_combos; ++k)
        fprintf(f, "    %s %s (%.1e): %s\n", id->combos[k].params, id->combos[k].weak ? "weak" : "NOT identifiable",
                id->combos[k].sv_rel, id->combos[k].why);
    fprintf(f, prior ? "  With the prior, what the data cannot identify stays where the drawing puts it (the prior's mean), "
                       "with the prior's uncertainty (the parameters' classes above).\n\n"
                     : "  The solver leaves directions it cannot identify where they started (nominal).\n\n");
}

static void print_pos_err(FILE *f, const char *label, const rch_pos_err *e)
{
    fprintf(f, "  %-36s %8.4f %8.4f %8.4f", label, e->rms_mm, e->mean_mm, e->max_mm);
    if (e->repeated)
        fprintf(f, "   AP %.4f  RP %.4f (%zu repeated)", e->ap_max_mm, e->rp_max_mm, e->repeated);
    fprintf(f, "\n");
}

/* The tracker positions in 3-D: |p_model - p_measured| (rch_positions.h). */
static void print_positions(FILE *f, const rch_calib_result *r)
{
    if (!r->n_pos_rows)
        return;
    fprintf(f, "tracker positions: %zu rows (%zu poses, %u target(s)), %zu cable lengths; every row weighs the "
               "same%s\n",
            r->n_pos_rows, r->n_pos_poses, r->n_targets, r->n_data - 3 * r->n_pos_rows,
            r->pos_has_sigma ? " (the files' sigma_mm is reported, not used as a weight)" : "");
    fprintf(f, "  (the table above counts every row: a length or one coordinate of a position)\n");
    if (!r->have_pos) {
        fprintf(f, "  3-D errors: none (the fit did not converge)\n\n");
        return;
    }
    fprintf(f, "3-D position error, %s (%zu positions, mm)   RMS     mean      MAX   ISO 9283 (worst pose)\n",
            r->n_test ? "held-out" : "training", r->pos_after.points);
    print_pos_err(f, "before (nominal DH, fitted tracker)", &r->pos_before);
    print_pos_err(f, "after", &r->pos_after);
    fprintf(f, "training 3-D RMS after: %.4f mm over %zu positions\n", r->pos_train_after.rms_mm,
            r->pos_train_after.points);
    unsigned nt = 0;
    const int tf = rch_pos_effect_at(&r->model, RC_EFF_TRACKER_POSITION, NULL),
              rf = rch_pos_effect_at(&r->model, RC_EFF_TRACKER_ROTATION, NULL),
              kf = rch_pos_effect_at(&r->model, RC_EFF_TRACKER_TARGETS, &nt);
    if (tf >= 0 && rf >= 0) {
        const double *w = &r->model.x[rf];
        fprintf(f, "tracker frame (base in the tracker's): T %.3f %.3f %.3f mm, rotation vector %.4f %.4f %.4f deg "
                   "(it absorbs the base: theta1 and d1 stay held, the gauge)\n",
                r->model.x[tf], r->model.x[tf + 1], r->model.x[tf + 2], w[0] / DEG, w[1] / DEG, w[2] / DEG);
    }
    for (unsigned j = 0; kf >= 0 && j < nt / 3; ++j)
        fprintf(f, "  target %u in the flange frame: %.4f %.4f %.4f mm\n", j, r->model.x[kf + 3 * (int)j],
                r->model.x[kf + 3 * (int)j + 1], r->model.x[kf + 3 * (int)j + 2]);
    fprintf(f, "\n");
}

/* "2 of the 3 steps the change-point search found are far above the
 * residual (...)", or, when every one is, "the change-point search found 2
 * steps far above the residual (...)". */
static void jump_counts(char *buf, size_t len, const rch_calib_result *r)
{
    const unsigned found = r->jumps_found, steps = r->jump_check_steps;
    if (found == steps)
        snprintf(buf, len, "the change-point search found %u step%s far above the residual (8 x its RMS; largest "
                 "%.3f mm)", found, found == 1 ? "" : "s", r->jump_check_max_mm);
    else
        snprintf(buf, len, "%u of the %u steps the change-point search found %s far above the residual (8 x its "
                 "RMS; largest %.3f mm)", found, steps, found == 1 ? "is" : "are", r->jump_check_max_mm);
}

static const char *data_name(const rch_calib_result *r)
{
    return r->cfg.data_path ? r->cfg.data_path : r->cfg.n_positions_paths ? r->cfg.positions_paths[0] : "";
}

/* The last lines on the screen: the held-out RMSE before -> after, the
 * predicted 3-D accuracy after compensation, and the first next step the
 * report above names (the jumps it does not model, parameters outside the
 * prior, poses that leave the geometry to the prior). */
static void print_summary(FILE *f, const rch_calib_result *r)
{
    hint_paths hp;
    hint_paths_of(&hp, r);
    fputs("\nsummary:\n", f);
    if (r->after_ok)
        fprintf(f, "  %s RMSE %.4f mm before -> %.4f mm after calibration (%zu samples%s)\n",
                r->n_test ? "held-out" : "training", r->before_m.rmse_mm, r->after_m.rmse_mm,
                r->n_test ? r->n_test : r->n_train, r->n_test ? " the fit never saw" : ", none held out");
    else
        fprintf(f, "  %s RMSE %.4f mm before; after: the solver diverged, no figures\n",
                r->n_test ? "held-out" : "training", r->before_m.rmse_mm);
    if (r->have_unc)
        fprintf(f, "  predicted 3-D accuracy after compensation (95 %%): +-%.4f mm over the data's poses (median; "
                   "max %.4f), +-%.4f mm over the whole workspace (median; max %.4f)\n",
                r->unc.map.data_median_mm, r->unc.map.data_max_mm, r->unc.map.work_median_mm, r->unc.map.work_max_mm);
    else
        fputs("  predicted 3-D accuracy: none in this run (no uncertainty: too few samples or a model that is not "
              "finite)\n",
              f);
    const unsigned outside = r->have_unc ? outside_prior(r) : 0;
    if (r->jumps_found && !r->cfg.jumps)
        fprintf(f, "  next: rcal calibrate --data %s --robot %s --jumps (the lengths jump and this fit does not model "
                   "them)\n",
                hp.data, hp.robot);
    else if (outside)
        fprintf(f, "  next: rcal diagnose --data %s --robot %s%s (%u parameter%s outside the prior's range)\n",
                hp.data, hp.robot, r->cfg.dequantize ? " --dequantize-joints" : "", outside, outside == 1 ? "" : "s");
    else if (accuracy_needs_poses(r))
        fprintf(f, "  next: rcal poses --robot %s --count 60 --outlet X,Y,Z --outlet X2,Y2,Z2 --out plan.csv (the "
                   "3-D accuracy is %.0f x the length RMSE: the poses leave most of the geometry to the prior)\n",
                hp.robot, r->unc.map.data_median_mm / r->after_m.rmse_mm);
}

void rch_calib_print(FILE *f, const rch_calib_result *r)
{
    const char *method = rc_method_name(r->cfg.method);
    if (r->prov.n_files > 1)
        fprintf(f, "rcal calibrate: %u files merged (%zu samples), robot \"%s\", method %s\n", r->prov.n_files,
                r->n_data, r->robot.name, method);
    else
        fprintf(f, "rcal calibrate: %s (%zu samples), robot \"%s\", method %s\n", data_name(r), r->n_data,
                r->robot.name, method);
    fprintf(f, "split: %zu train / %zu held out (test fraction %.2f, seed %lu)\n\n", r->n_train, r->n_test,
            r->cfg.test_fraction, r->cfg.seed);
    /* the check counts the steps far above the residual; the fit then takes
     * every step the search found, the smaller ones too: both numbers said */
    const unsigned steps = r->jump_check_steps, fitted = r->have_jumps ? r->jumps.n_jumps : steps;
    char counts[200], all[64];
    jump_counts(counts, sizeof counts, r);
    snprintf(all, sizeof all, steps == 1 ? "it is" : r->jumps_found == steps ? "they are" : "all %u are", steps);
    hint_paths hp;
    hint_paths_of(&hp, r);
    if (r->jumps_found && !r->cfg.jumps)
        fprintf(f, "WARNING: the lengths jump in acquisition order: %s, and this fit does not model them: its "
                   "geometry is wrong and --out is refused.\n  next: rcal calibrate --data %s --robot %s --jumps (it "
                   "fits the %u step%s found; and --dequantize-joints when the file's joints are rounded; rcal "
                   "diagnose tells)\n\n",
                counts, hp.data, hp.robot, steps, steps == 1 ? "" : "s");
    if (r->jumps_auto) {
        char also[64] = "";
        if (fitted != steps)
            snprintf(also, sizeof also, " (%u after the fit with them)", fitted);
        fprintf(f, "note: the lengths jump in acquisition order: %s, so %s fitted as nuisance%s, as --jumps does "
                   "(--no-jump-check: not looked for)%s\n\n",
                counts, all, also,
                r->cfg.dequantize ? "" : "; if the file's joint angles are rounded, add --dequantize-joints "
                                         "(rcal fkcheck tells)");
    }
    fprintf(f, "%s error (%zu samples, mm)          RMSE  mean|e|       SD      MAX\n",
            r->n_test ? "held-out" : "training", r->n_test ? r->n_test : r->n_train);
    print_metrics_row(f, "before (nominal DH, fitted encoder)", &r->before_m);
    if (r->after_ok)
        print_metrics_row(f, "after", &r->after_m);
    else
        fprintf(f, "  after: the solver diverged (non-finite model or cable length): no figures\n");
    fprintf(f, "  (mean|e| is what the paper's Eq. 20 calls SD; SD here is the true standard deviation)\n");
    fprintf(f, "training RMSE: before %.4f mm, after %.4f mm\n\n", r->train_before.rmse_mm, r->train_after.rmse_mm);
    print_positions(f, r);
    if (r->have_truth)
        fprintf(f,
                "flange position against the truth (%d random poses, base heading/height aligned):\n"
                "  before RMS %.4f mm, max %.4f mm;  after RMS %.4f mm, max %.4f mm\n\n",
                RCH_CALIB_TRUTH_POSES, r->truth_before_rms_mm, r->truth_before_max_mm, r->truth_after_rms_mm,
                r->truth_after_max_mm);
    print_effects(f, r);
    print_model(f, r);
    if (r->have_unc)
        print_uncertainty(f, r);
    if (r->have_ident)
        print_ident(f, &r->ident, r->prior_on);
    if (r->have_validate) {
        const rch_evaluate_result *v = &r->validate;
        fprintf(f,
                "validation on %s (%zu samples the fit never saw, no refit): RMSE %.4f mm, mean|e| %.4f, SD %.4f, "
                "MAX %.4f mm\n",
                r->cfg.validate_path, v->m.n, v->m.rmse_mm, v->m.mean_abs_mm, v->m.sd_mm, v->m.max_mm);
        if (v->n_repeated)
            fprintf(f, "  ISO 9283 over %zu repeated poses: AD mean %.4f / max %.4f mm, RD mean %.4f / max %.4f mm\n",
                    v->n_repeated, v->ad_mean_mm, v->ad_max_mm, v->rd_mean_mm, v->rd_max_mm);
        fprintf(f, "\n");
    }
    if (r->plot_paths[0])
        fprintf(f, "plots:\n%s\n", r->plot_paths);
    if (r->have_jumps && r->solve.iterations == 0)
        fprintf(f, "solver: %s with %u length jump(s) (a change-point search, each candidate a fit), %.2f ms\n",
                method, r->jumps.n_jumps, r->time_ms);
    else
        fprintf(f, "solver: %s, %u iterations, %u passes over the data, exit: %s, %.2f ms\n", method,
                r->solve.iterations, r->solve.cost_evals, rc_exit_str(r->solve.exit), r->time_ms);
    print_summary(f, r);
}

static void json_metrics(rch_jw *w, const char *name, const rc_metrics *m)
{
    rch_jw_obj(w, name);
    rch_jw_uint(w, "n", m->n);
    rch_jw_numf(w, "rmse_mm", m->rmse_mm, "%.6f");
    rch_jw_numf(w, "mean_abs_mm", m->mean_abs_mm, "%.6f");
    rch_jw_numf(w, "sd_mm", m->sd_mm, "%.6f");
    rch_jw_numf(w, "mean_mm", m->mean_mm, "%.6f");
    rch_jw_numf(w, "max_mm", m->max_mm, "%.6f");
    rch_jw_num(w, "rmse_full_mm", m->rmse_mm); /* rmse_mm to the last bit (%.17g): checks of --residuals */
    rch_jw_end(w);
}

static void json_params(rch_jw *w, const rch_calib_result *r)
{
    const rc_model *m = &r->model;
    rch_jw_arr(w, "params");
    for (unsigned k = 0; k < m->n_params; ++k) {
        char name[64];
        const int unit = rc_param_unit(m, k);
        const double scale = unit == 1 ? 1.0 / DEG : 1.0;
        const double nominal = k < RC_N_DH ? r->robot.model.x[k] : (k < RC_N_BASE ? r->before.x[k] : 0.0);
        rch_jw_obj(w, NULL);
        rch_jw_str(w, "name", rc_param_name(name, sizeof name, m, k));
        rch_jw_str(w, "unit", unit == 0 ? "mm" : unit == 1 ? "deg" : "-");
        rch_jw_numf(w, "value", r->finite ? m->x[k] * scale : 0.0, "%.9g");
        rch_jw_numf(w, "delta", r->finite ? (m->x[k] - nominal) * scale : 0.0, "%.9g");
        rch_jw_end(w);
    }
    rch_jw_end(w);
    rch_jw_arr(w, "encoder_mm");
    for (unsigned k = 0; k < 3; ++k)
        rch_jw_numf(w, NULL, m->x[RC_P_ENC + k], "%.6f");
    rch_jw_end(w);
}

static void json_ident(rch_jw *w, const rch_ident *id)
{
    rch_jw_obj(w, "identifiability");
    rch_jw_uint(w, "params", id->n_params);
    rch_jw_uint(w, "rank", id->rank);
    rch_jw_uint(w, "weak", id->n_weak);
    rch_jw_numf(w, "cond", id->cond, "%.6g");
    rch_jw_numf(w, "observability", id->observability, "%.6g");
    rch_jw_arr(w, "directions");
    for (unsigned k = 0; k < id->n_dirs; ++k) {
        rch_jw_obj(w, NULL);
        rch_jw_numf(w, "sv_rel", id->dirs[k].sv_rel, "%.3g");
        rch_jw_str(w, "identifiable", id->dirs[k].weak ? "weakly" : "no");
        rch_jw_str(w, "combo", id->dirs[k].combo);
        rch_jw_end(w);
    }
    rch_jw_end(w);
    rch_jw_arr(w, "dependent_sets");
    for (unsigned k = 0; k < id->n_combos; ++k) {
        rch_jw_obj(w, NULL);
        rch_jw_str(w, "params", id->combos[k].params);
        rch_jw_str(w, "identifiable", id->combos[k].weak ? "weakly" : "no");
        rch_jw_numf(w, "sv_rel", id->combos[k].sv_rel, "%.3g");
        rch_jw_str(w, "why", id->combos[k].why);
        rch_jw_end(w);
    }
    rch_jw_end(w);
    rch_jw_end(w);
}

static void json_uncertainty(rch_jw *w, const rch_calib_result *r)
{
    const rch_model_unc *u = &r->unc;
    rch_jw_obj(w, "uncertainty");
    rch_jw_str(w, "covariance", u->kind == RCH_COV_CLUSTER ? "cluster-robust" : "classical");
    rch_jw_uint(w, "groups", u->n_groups);
    rch_jw_str(w, "groups_from", r->groups_from_file ? "file" : "wrist joints");
    rch_jw_numf(w, "sigma_mm", u->sigma_mm, "%.6g");
    rch_jw_uint(w, "rank", u->rank);
    rch_jw_bool(w, "posterior", u->has_prior);
    rch_robot_write_unc_params(w, &r->model, u, "%.9g");
    rch_robot_write_unc_map(w, &u->map);
    rch_jw_bool(w, "orientation_determined", u->orientation_determined);
    rch_jw_end(w);
}

/* With --positions: the "positions" member (docs/json-formats.md). */
static void json_positions(rch_jw *w, const rch_calib_result *r)
{
    rch_jw_obj(w, "positions");
    rch_jw_uint(w, "rows", r->n_pos_rows);
    rch_jw_uint(w, "poses", r->n_pos_poses);
    rch_jw_uint(w, "targets", r->n_targets);
    rch_jw_num(w, "sigma_mm", r->pos_has_sigma ? r->pos_sigma_mm : NAN);
    if (r->have_pos) {
        rch_pos_err_json(w, "position_error_mm", &r->pos_after);
        rch_pos_err_json(w, "before_mm", &r->pos_before);
        rch_pos_err_json(w, "train_after_mm", &r->pos_train_after);
    }
    rch_jw_end(w);
}

int rch_calib_json(FILE *f, const rch_calib_result *r, int argc, char **argv)
{
    rch_jw w;
    rch_jw_begin(&w, f, 0, "rcal-calibrate/1", argc, argv);
    rch_jw_str(&w, "method", rc_method_name(r->cfg.method));
    rch_jw_str(&w, "data", data_name(r));
    rch_jw_uint(&w, "n_train", r->n_train);
    rch_jw_uint(&w, "n_test", r->n_test);
    rch_jw_uint(&w, "seed", r->cfg.seed);
    json_metrics(&w, "before", &r->before_m);
    json_metrics(&w, "after", &r->after_m);
    json_metrics(&w, "train_before", &r->train_before);
    json_metrics(&w, "train_after", &r->train_after);
    rch_jw_bool(&w, "held_out", r->n_test > 0);
    rch_jw_bool(&w, "converged", r->after_ok);
    rch_jw_str(&w, "exit", rc_exit_str(r->solve.exit));
    rch_jw_uint(&w, "iterations", r->solve.iterations);
    rch_jw_uint(&w, "cost_evals", r->solve.cost_evals);
    rch_jw_numf(&w, "time_ms", r->time_ms, "%.3f");
    json_params(&w, r);
    rch_jw_obj(&w, "estimation");
    rch_jw_bool(&w, "prior", r->prior_on);
    if (r->prior_on) {
        rch_jw_num(&w, "prior_length_mm", r->robot.prior.length_mm);
        rch_jw_num(&w, "prior_twist_deg", r->robot.prior.twist_deg);
        rch_jw_num(&w, "prior_offset_deg", r->robot.prior.offset_deg);
        rch_jw_num(&w, "prior_attachment_mm", r->robot.prior.attachment_mm);
        rch_jw_numf(&w, "noise_mm", r->noise_mm, "%.6g");
        rch_jw_numf(&w, "effective_params", r->p_eff, "%.4g");
    }
    rch_jw_uint(&w, "outlets", r->n_outlets ? r->n_outlets : 1u);
    if (r->attach_auto) {
        rch_jw_str(&w, "attachment", r->attach_centred ? "flange centre" : "estimated");
        rch_jw_numf(&w, "attachment_dchi2", r->attach_dchi2, "%.6g");
        rch_jw_numf(&w, "attachment_occam", r->attach_occam, "%.6g");
    }
    rch_jw_bool(&w, "jumps_found_by_default", r->jumps_auto);
    rch_jw_end(&w);
    if (r->n_pos_rows)
        json_positions(&w, r);
    if (r->cfg.truth_path) {
        rch_jw_obj(&w, "truth_flange");
        rch_jw_numf(&w, "before_rms_mm", r->truth_before_rms_mm, "%.6f");
        rch_jw_numf(&w, "before_max_mm", r->truth_before_max_mm, "%.6f");
        rch_jw_numf(&w, "after_rms_mm", r->truth_after_rms_mm, "%.6f");
        rch_jw_numf(&w, "after_max_mm", r->truth_after_max_mm, "%.6f");
        rch_jw_end(&w);
    }
    if (r->have_ident)
        json_ident(&w, &r->ident);
    if (r->have_unc)
        json_uncertainty(&w, r);
    if (r->have_jumps) {
        rch_jw_arr(&w, "length_jumps");
        for (unsigned k = 0; k < r->jumps.n_jumps; ++k) {
            rch_jw_obj(&w, NULL);
            rch_jw_uint(&w, "line", r->jump_lines[k]);
            rch_jw_numf(&w, "t", r->jumps.at_t[k], "%.6f");
            rch_jw_numf(&w, "size_mm", r->jumps.size_mm[k], "%.6f");
            rch_jw_numf(&w, "se_mm", r->jumps.se_mm[k], "%.6f");
            rch_jw_end(&w);
        }
        rch_jw_end(&w);
        rch_jw_uint(&w, "held_out_ambiguous", r->n_ambiguous);
        json_metrics(&w, "after_unambiguous", &r->after_unambiguous);
    }
    if (r->have_dequant) {
        rch_jw_obj(&w, "dequantized");
        rch_jw_uint(&w, "corrected", r->dequant.n_corrected);
        rch_jw_uint(&w, "refused", r->dequant.n_refused);
        rch_jw_numf(&w, "dq_rms_deg", r->dequant.dq_rms_deg, "%.6f");
        rch_jw_end(&w);
    }
    if (r->cases_done > 1) {
        rch_jw_obj(&w, "protocol");
        rch_jw_uint(&w, "cases", r->cases_done);
        rch_jw_numf(&w, "before_rmse_mean_mm", r->case_before.mean, "%.6f");
        rch_jw_numf(&w, "before_rmse_sd_mm", rch_stats_sd(&r->case_before), "%.6f");
        rch_jw_numf(&w, "after_rmse_mean_mm", r->case_after.mean, "%.6f");
        rch_jw_numf(&w, "after_rmse_sd_mm", rch_stats_sd(&r->case_after), "%.6f");
        rch_jw_uint(&w, "held_out_ambiguous", r->case_ambiguous);
        rch_jw_numf(&w, "after_unambiguous_rmse_mean_mm", r->case_unamb.n ? r->case_unamb.mean : NAN, "%.6f");
        rch_jw_numf(&w, "after_unambiguous_rmse_sd_mm", r->case_unamb.n ? rch_stats_sd(&r->case_unamb) : NAN, "%.6f");
        rch_jw_end(&w);
    }
    if (r->have_validate) {
        rch_jw_obj(&w, "validation");
        rch_jw_str(&w, "data", r->cfg.validate_path);
        json_metrics(&w, "residual", &r->validate.m);
        rch_jw_uint(&w, "repeated_poses", r->validate.n_repeated);
        rch_jw_numf(&w, "iso9283_ad_mean_mm", r->validate.ad_mean_mm, "%.6f");
        rch_jw_numf(&w, "iso9283_ad_max_mm", r->validate.ad_max_mm, "%.6f");
        rch_jw_numf(&w, "iso9283_rd_mean_mm", r->validate.rd_mean_mm, "%.6f");
        rch_jw_numf(&w, "iso9283_rd_max_mm", r->validate.rd_max_mm, "%.6f");
        rch_jw_end(&w);
    }
    rch_robot_write_provenance(&w, &r->prov);
    rch_jw_end(&w);
    return rch_jw_finish(&w);
}

static void calib_info(rch_jw *w, const void *ctx)
{
    const rch_calib_result *r = ctx;
    rch_jw_str(w, "method", rc_method_name(r->cfg.method));
    rch_jw_str(w, "data", data_name(r));
    rch_jw_uint(w, "n_train", r->n_train);
    rch_jw_uint(w, "n_test", r->n_test);
    rch_jw_uint(w, "seed", r->cfg.seed);
    rch_jw_numf(w, "rmse_before_mm", r->before_m.rmse_mm, "%.6f");
    rch_jw_numf(w, "rmse_after_mm", r->after_m.rmse_mm, "%.6f");
    if (r->have_jumps && r->jumps.n_jumps) { /* read back: rcal evaluate says they are not applied */
        rch_jw_arr(w, "length_jumps");
        for (unsigned k = 0; k < r->jumps.n_jumps; ++k) {
            rch_jw_obj(w, NULL);
            rch_jw_uint(w, "line", r->jump_lines[k]);
            rch_jw_numf(w, "t", r->jumps.at_t[k], "%.6f");
            rch_jw_numf(w, "size_mm", r->jumps.size_mm[k], "%.6f");
            rch_jw_numf(w, "se_mm", r->jumps.se_mm[k], "%.6f");
            rch_jw_end(w);
        }
        rch_jw_end(w);
    }
}

int rch_calib_write_model(FILE *f, const rch_calib_result *r)
{
    if (!r->finite)
        return -1;
    const rch_robot_info info = {calib_info, r, r->have_unc ? &r->unc : NULL, r->have_unc ? &r->determined : NULL,
                                 &r->prov};
    return rch_robot_write(f, r->robot.name, &r->model, &r->robot.nominal, &info);
}

static int write_model_fn(FILE *f, const void *ctx)
{
    return rch_calib_write_model(f, ctx);
}

int rch_calib_save_model(const rch_calib_result *r, const char *path, rch_diag *d)
{
    if (r->jumps_found && !r->cfg.jumps) {
        char counts[200];
        jump_counts(counts, sizeof counts, r);
        rch_diag_set(d, path, 0, 0,
                     "not written: the lengths jump in acquisition order (%s), which this fit does not model, so "
                     "its geometry is wrong; run again with --jumps, which fits the %u step%s found (or "
                     "--no-jump-check to write it anyway)",
                     counts, r->jump_check_steps, r->jump_check_steps == 1 ? "" : "s");
        return -1;
    }
    const char *inputs[2 * RCH_CALIB_MAX_FILES + 4] = {r->cfg.robot_path, r->cfg.truth_path, r->cfg.validate_path};
    size_t n = 3;
    for (size_t f = 0; f < n_files(&r->cfg); ++f)
        inputs[n++] = file_at(&r->cfg, f);
    for (size_t f = 0; f < r->cfg.n_positions_paths && f < RCH_CALIB_MAX_FILES; ++f)
        inputs[n++] = r->cfg.positions_paths[f];
    return rch_save(path, "--out", inputs, n, write_model_fn, r, d);
}

/* ------------------------------------------------------------ fkcheck */

/* Largest joint change (deg) of the minimum-norm dq = J^T (J J^T)^-1 dp that
 * moves the flange by dp, over the position rows of the joint Jacobian. */
static double explaining_dq_deg(const double jac[36], const double dp[3])
{
    double M[9], y[3] = {0, 0, 0}, dq_max = 0.0;
    for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) {
            double s = 0.0;
            for (int k = 0; k < 6; ++k)
                s += jac[6 * a + k] * jac[6 * b + k];
            M[3 * a + b] = s;
        }
    const double det = M[0] * (M[4] * M[8] - M[5] * M[7]) - M[1] * (M[3] * M[8] - M[5] * M[6]) +
                       M[2] * (M[3] * M[7] - M[4] * M[6]);
    if (fabs(det) > 1e-12) { /* Cramer's rule on the 3x3 system M y = dp */
        for (int c = 0; c < 3; ++c) {
            double T[9];
            memcpy(T, M, sizeof T);
            for (int a = 0; a < 3; ++a)
                T[3 * a + c] = dp[a];
            y[c] = (T[0] * (T[4] * T[8] - T[5] * T[7]) - T[1] * (T[3] * T[8] - T[5] * T[6]) +
                    T[2] * (T[3] * T[7] - T[4] * T[6])) / det;
        }
    }
    for (int k = 0; k < 6; ++k) {
        const double dqk = (jac[k] * y[0] + jac[6 + k] * y[1] + jac[12 + k] * y[2]) * (180.0 / M_PI);
        if (fabs(dqk) > dq_max)
            dq_max = fabs(dqk);
    }
    return dq_max;
}

static int fk_rows(rch_fkcheck_result *r, const rch_data *data, const rc_model *nominal, double tol_mm)
{
    rch_stats all;
    memset(&all, 0, sizeof all);
    for (size_t i = 0; i < data->n; ++i) {
        double p[3], pp[3], jac[36];
        rc_fk(p, NULL, nominal, data->s[i].q_rad);
        const double dp[3] = {data->xyz[i][0] - p[0], data->xyz[i][1] - p[1], data->xyz[i][2] - p[2]};
        const double dist = sqrt(dp[0] * dp[0] + dp[1] * dp[1] + dp[2] * dp[2]);
        rch_stats_add(&all, dist);
        /* the file's angles are rounded to 0.1 deg: a row is consistent when
         * a joint change within that rounding explains the difference */
        rc_fk_jac(pp, NULL, jac, nominal, data->s[i].q_rad);
        const double dq_deg = explaining_dq_deg(jac, dp);
        if (dist > tol_mm && dq_deg <= RCH_FK_ROUNDING_DEG) {
            ++r->rounding;
            if (dist > r->max_consistent_mm)
                r->max_consistent_mm = dist;
        } else if (dist > tol_mm) {
            rch_fk_fault *f = &r->fault[r->faults++];
            f->line = data->line[i];
            f->dist_mm = dist;
            f->dq_deg = dq_deg;
            memcpy(f->fk_mm, p, sizeof p);
            memcpy(f->file_mm, data->xyz[i], sizeof f->file_mm);
        } else if (dist > r->max_consistent_mm) {
            r->max_consistent_mm = dist;
        }
    }
    r->rows = data->n;
    r->rms_mm = rch_stats_rms(&all);
    r->max_mm = all.max_abs;
    return 0;
}

int rch_fkcheck_run(rch_fkcheck_result *r, const char *data_path, const char *robot_path, double tol_mm,
                    rch_diag *d)
{
    memset(r, 0, sizeof *r);
    rch_robot robot;
    rch_data data;
    if (rch_robot_load(&robot, robot_path, d) != 0 || rch_data_load(&data, data_path, 0, d) != 0)
        return -1;
    snprintf(r->robot_name, sizeof r->robot_name, "%s", robot.name);
    int rc = -1;
    if (!data.xyz)
        rch_diag_set(d, data_path, 0, 0, "no x, y, z columns");
    else if (!(r->fault = malloc((data.n ? data.n : 1) * sizeof *r->fault)))
        rch_diag_set(d, "", 0, 0, "out of memory");
    else
        rc = fk_rows(r, &data, &robot.nominal, tol_mm);
    rch_data_free(&data);
    return rc;
}

void rch_fkcheck_free(rch_fkcheck_result *r)
{
    free(r->fault);
    r->fault = NULL;
}
