/* SPDX-License-Identifier: MIT */
/* rch_calib.c - the calibration pipeline (see rch_calib.h): the inputs read
 * (rch_inputs_load), the cost checked, the effects a fit carries added, the
 * split into training and held-out rows (or the paper's cases), one fit
 * each (rch_calib_fit.c), the residual CSV.
 *
 * Depends on: rch_inputs, rch_calib_effects, rch_calib_fit (rch_calib_int.h),
 * rch_cost, rch_resid, rch_positions, rch_data. Memory: the inputs and the
 * scratch freed before returning. Errors: see rch_calib_run.
 */
#include "rch_calib.h"
#include "rch_file.h"
#include "rch_calib_int.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "rch_calib_effects.h"
#include "rch_cost.h"
#include "rch_data.h"
#include "rch_inputs.h"
#include "rch_resid.h"
#include "rch_sensors.h"

/* The run's state (the plan of rch_calib_run): the request, the inputs read
 * once, the solver's workspace, the rows held out (--residuals) and the
 * timing record every stage books into. The result keeps the answers. */
typedef struct calib_run {
    const rch_calib_cfg *cfg;
    rch_inputs *in;
    rc_solve_work *w;
    uint8_t *held;
    rch_calib_timing timing;
} calib_run;

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
static int run_once(calib_run *run, rch_calib_result *r, const rc_sample *s, size_t m, unsigned long long seed,
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
    rc = rch_calib_fit_run(r, run->w, train, test, r->cfg.validate_path ? &run->in->validate : NULL, &run->timing, d);
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
static int run_cases(calib_run *run, rch_calib_result *r, const rch_data *data, rch_diag *d)
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
        int one = run_once(run, into, sub, m, r->cfg.seed * 1000003ull + k + 7, NULL, d);
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
static int save_residuals(const rch_calib_result *r, const rch_inputs *in, const uint8_t *held, rch_diag *d)
{
    const rch_data *data = &in->data;
    const char *inputs[RCH_CALIB_MAX_FILES + 3] = {r->cfg.robot_path, r->cfg.truth_path, r->cfg.validate_path};
    const size_t nf = rch_calib_cfg_n_files(&r->cfg);
    for (size_t f = 0; f < nf; ++f)
        inputs[3 + f] = rch_calib_cfg_file(&r->cfg, f);
    rch_resid_table t;
    rch_resid_init(&t, inputs + 3, nf);
    int rc = 0;
    for (size_t i = 0; i < data->n && rc == 0; ++i)
        rc = rch_resid_add_model(&t, &r->model, &data->s[i], &data->line[i], &in->file_of[i], 1,
                                 held[i] ? RCH_RESID_TEST : RCH_RESID_TRAIN, 0);
    if (rc == 0 && r->have_validate) /* the validation rows as read (rch_inputs) */
        rc = rch_resid_add_model(&t, &r->model, in->validate.s, in->validate.line, NULL, in->validate.n,
                                 RCH_RESID_VALIDATE, 0);
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

/* The inputs' figures into the result: what the report and the model file
 * name, and the robot model the fit extends. */
static void take_inputs(rch_calib_result *r, const rch_inputs *in)
{
    r->robot = in->robot;
    r->n_data = in->n_read;
    r->n_outlets = in->n_outlets;
    memcpy(r->outlet_label, in->outlet_label, sizeof r->outlet_label);
    r->n_groups = in->n_groups;
    r->groups_from_file = in->groups_from_file;
    r->prov = in->prov;
    r->n_lengths = rch_pos_count_lengths(in->data.s, in->data.n);
    for (size_t i = 0; i < in->data.n && !r->other_sensor; ++i) {
        const rch_sensor_desc *sd = rch_sensor_of_kind(in->data.s[i].sensor);
        if (sd) {
            r->other_sensor = sd->kind;
            if (sd->caveat)
                sd->caveat(r->sensor_note, sizeof r->sensor_note, in->data.s, in->data.n);
        }
    }
    r->n_pos_rows = in->n_pos_rows;
    r->n_pos_poses = in->n_pos_poses;
    r->n_targets = in->n_targets;
    r->pos_has_sigma = in->pos_has_sigma;
    r->pos_sigma_mm = in->pos_sigma_mm;
    r->have_dequant = in->have_dequant;
    r->dequant = in->dequant;
    memcpy(r->dequant_refused_lines, in->dequant_refused_lines, sizeof r->dequant_refused_lines);
}

/* The effects the fit adds to r->robot.model: the cable attachment vector
 * and the axis tilts by default (with the prior), then --effects. n_len:
 * the cable-length samples. 0, -1 (no room) or -2 (a bad --effects entry),
 * d set. */
static int fit_effects(rch_calib_result *r, const rch_calib_cfg *cfg, size_t n_len, rch_diag *d)
{
    if (cfg->n_cable_points > 0) { /* the cable on a tool plate's points (the reader added them): no attachment */
        if (cfg->cable_point_sd_mm > 0.0)
            r->robot.prior.points_mm = cfg->cable_point_sd_mm;
        n_len = 0;
    }
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
                return -1;
            }
        }
    if (want_tool && !has_tool && (n_len > 0 || cfg->tool_offset) &&
        rc_model_add_effect(&r->robot.model, RC_EFF_TOOL_OFFSET, 0, 0) != RC_OK) {
        rch_diag_set(d, "", 0, 0, "cannot add the tool offset (RC_MAX_PARAMS or RC_MAX_EFFECTS)");
        return -1;
    }
    /* the systematic length errors the default run decided to fit (rch_calib_sys.c) */
    if (r->sys.offset_fitted &&
        rc_model_add_effect(&r->robot.model, r->n_outlets > 1 ? RC_EFF_OUTLET_OFFSET : RC_EFF_LENGTH_OFFSET, 0, 0) !=
            RC_OK) {
        rch_diag_set(d, "", 0, 0, "cannot add the length offset (RC_MAX_PARAMS or RC_MAX_EFFECTS)");
        return -1;
    }
    if (r->sys.drift_fitted && rc_model_add_effect(&r->robot.model, RC_EFF_TIME_DRIFT, 0, 1) != RC_OK) {
        rch_diag_set(d, "", 0, 0, "cannot add the drift (RC_MAX_PARAMS or RC_MAX_EFFECTS)");
        return -1;
    }
    if (cfg->effects && rch_calib_effects(&r->robot.model, cfg->effects, d) != 0)
        return -2;
    return 0;
}

/* The calibration again from the start on in's rows (the same inputs, split
 * seed and effects, the screen's and the systematic decision's findings
 * kept). 0, or as run_once. */
static int refit_all(calib_run *run, rch_calib_result *r, rch_diag *d)
{
    const rch_inputs *in = run->in;
    const rch_calib_cfg cfg = *run->cfg; /* as asked */
    /* the refit's plot replaces the fit's (the same command's) */
    for (const char *q = r->plot_paths, *e; *q && (e = strchr(q, '\n')) != NULL; q = e + 1) {
        char one[1200];
        if ((size_t)(e - q) < sizeof one) {
            memcpy(one, q, (size_t)(e - q));
            one[e - q] = '\0';
            rch_out_unclaim(one);
        }
    }
    const rch_calib_screen_result keep = r->screen;
    const rch_calib_sys sys = r->sys;
    double(*read_q)[RC_NJ] = r->read_q; /* the poses as read (cfg.keep_poses): the run's, kept */
    size_t read_n[RCH_PROV_MAX_FILES];
    memcpy(read_n, r->read_n, sizeof read_n);
    memset(r, 0, sizeof *r);
    r->cfg = cfg;
    r->sys = sys;
    r->read_q = read_q;
    memcpy(r->read_n, read_n, sizeof read_n);
    take_inputs(r, in);
    int rc = fit_effects(r, &cfg, rch_pos_count_lengths(in->data.s, in->data.n), d);
    if (rc == 0)
        rc = run_once(run, r, in->data.s, in->data.n, cfg.seed, NULL, d);
    r->screen = keep;
    return rc;
}

/* Whether the model already carries an effect of kind. */
static int has_effect(const rc_model *m, rc_effect_kind kind)
{
    for (unsigned e = 0; e < m->n_effects; ++e)
        if (m->effects[e].kind == kind)
            return 1;
    return 0;
}

/* The systematic length errors (rch_calib_sys.c): a length offset and a
 * drift weighed at the fit at hand by their score against their Occam
 * penalty; the winners fitted by a refit, kept when its profile likelihood
 * gain n ln(noise0^2 / noise1^2) still beats the penalty (else the fit at
 * hand is restored and the refit said). 0, or -1 with d set. */
static int stage_systematic(void *vrun, rch_calib_result *r, rch_diag *d)
{
    calib_run *run = vrun;
    const rch_inputs *in = run->in;
    const rch_calib_cfg *cfg = run->cfg;
    if (!r->after_ok || !r->prior_on || cfg->cases > 1 || cfg->residuals_path ||
        (cfg->no_length_offset && cfg->no_drift) || rch_pos_count_lengths(in->data.s, in->data.n) < 40)
        return 0;
    const rc_model *m = &r->model;
    int off_ok = !cfg->no_length_offset && !has_effect(m, RC_EFF_LENGTH_OFFSET) &&
                 !has_effect(m, RC_EFF_OUTLET_OFFSET) && !has_effect(m, RC_EFF_GROUP_OFFSET);
    int dr_ok = !cfg->no_drift && !has_effect(m, RC_EFF_TIME_DRIFT);
    /* one at a time, the stronger first, the other scored again at the fit with it: an offset's score
     * leaks into a drift's at the fit with neither (and back) */
    for (int round = 0; round < 2 && (off_ok || dr_ok); ++round) {
        char err[160];
        rch_calib_sys y = r->sys;
        if (rch_calib_sys_score(&y, r, r->fixed, in->data.s, in->data.n, err, sizeof err) != 0)
            return 0; /* not testable at this fit: nothing said, nothing more changed */
        rch_calib_sys *z = &r->sys;
        z->tested = 1;
        z->n_offsets = y.n_offsets;
        if (off_ok) {
            z->offset_testable = y.offset_testable;
            z->offset_score = y.offset_score;
            z->offset_occam = y.offset_occam;
            z->offset_size_mm = y.offset_size_mm;
        }
        if (dr_ok) {
            z->drift_testable = y.drift_testable;
            z->drift_score = y.drift_score;
            z->drift_occam = y.drift_occam;
            z->drift_size_mm = y.drift_size_mm;
        }
        /* a margin: a score within RCH_SYS_TIE of its penalty is a tie, decided for the simpler model (a
         * decision must not flip with the last digits another BLAS or CPU gives) */
        const double m_off = off_ok && z->offset_testable ? z->offset_score - z->offset_occam : -INFINITY,
                     m_dr = dr_ok && z->drift_testable ? z->drift_score - z->drift_occam : -INFINITY;
        if (!(m_off > RCH_SYS_TIE) && !(m_dr > RCH_SYS_TIE))
            break;
        const int take_off = m_off >= m_dr;
        rch_calib_result *old = malloc(sizeof *old);
        if (!old) {
            rch_diag_set(d, "", 0, 0, "out of memory");
            return -1;
        }
        memcpy(old, r, sizeof *old);
        if (take_off) {
            r->sys.offset_fitted = 1;
            off_ok = 0;
        } else {
            r->sys.drift_fitted = 1;
            dr_ok = 0;
        }
        const int rc = refit_all(run, r, d);
        const double occam = take_off ? old->sys.offset_occam : old->sys.drift_occam;
        const double gain = rc == 0 && r->after_ok && r->noise_mm > 0.0
                                ? (double)r->n_train * log(old->noise_mm * old->noise_mm / (r->noise_mm * r->noise_mm))
                                : -INFINITY;
        if (!(gain > occam)) {
            memcpy(r, old, sizeof *r);
            r->sys.refit_kept_out = take_off ? 1 : 2;
        }
        r->sys.refit_gain = gain;
        r->sys.refit_occam = occam;
        free(old);
        if (r->sys.refit_kept_out)
            break;
    }
    return 0;
}

/* The rows the fit cannot reconcile with the rest (rch_calib_screen): none,
 * or the calibration again without them, from the start (the same inputs,
 * effects and split seed), the screen's findings kept. Every row is screened
 * again under the refitted model, until the rows left out no longer change
 * (at most RCH_SCREEN_ROUNDS fits): a row that only the first, contaminated
 * fit put far off comes back. Not with length jumps fitted (their offsets
 * are the fit's, not the model's) or a model that did not fit. 0, or -1 with
 * d set (refused: too many). */
#define RCH_SCREEN_ROUNDS 4
static int stage_screen(void *vrun, rch_calib_result *r, rch_diag *d)
{
    calib_run *run = vrun;
    rch_inputs *in = run->in;
    if (run->cfg->cases > 1 || run->cfg->no_screen || run->cfg->residuals_path || !r->after_ok)
        return 0;
    rch_data *data = &in->data;
    const size_t n = data->n;
    uint8_t *drop = malloc(n ? n : 1), *prev = calloc(n ? n : 1, 1);
    rc_sample *s0 = malloc((n ? n : 1) * sizeof *s0);
    unsigned *l0 = malloc((n ? n : 1) * sizeof *l0), *f0 = malloc((n ? n : 1) * sizeof *f0);
    int rc = 0;
    if (!drop || !prev || !s0 || !l0 || !f0) {
        rch_diag_set(d, "", 0, 0, "out of memory");
        rc = -1;
        goto done;
    }
    memcpy(s0, data->s, n * sizeof *s0); /* every row, for each round's screen */
    memcpy(l0, data->line, n * sizeof *l0);
    memcpy(f0, in->file_of, n * sizeof *f0);
    for (unsigned round = 0; round < RCH_SCREEN_ROUNDS; ++round) {
        const int out = rch_calib_screen(r, drop, s0, n, l0, f0, d);
        if (out < 0) {
            rc = -1;
            break;
        }
        if (memcmp(drop, prev, n) == 0) /* the same rows as the fit at hand left out: done */
            break;
        memcpy(prev, drop, n);
        size_t k = 0;
        for (size_t i = 0; i < n; ++i)
            if (!drop[i]) {
                data->s[k] = s0[i];
                data->line[k] = l0[i];
                in->file_of[k++] = f0[i];
            }
        data->n = k;
        rc = refit_all(run, r, d);
        if (rc != 0 || !r->after_ok)
            break;
    }
done:
    free(drop);
    free(prev);
    free(s0);
    free(l0);
    free(f0);
    return rc;
}

/* read: every input, once (rch_inputs_load). */
static int stage_read(void *vrun, rch_calib_result *r, rch_diag *d)
{
    calib_run *run = vrun;
    if (rch_inputs_load(run->in, run->cfg, d) != 0) {
        free(run->in);
        run->in = NULL; /* nothing to free */
        return -1;
    }
    take_inputs(r, run->in);
    r->read_q = run->in->read_q; /* the result's own from here (rch_calib_result_free) */
    memcpy(r->read_n, run->in->read_n, sizeof r->read_n);
    run->in->read_q = NULL;
    return 0;
}

/* setup: the cost checked (the cable files' rows), the workspace, the
 * effects the fit carries. */
static int stage_setup(void *vrun, rch_calib_result *r, rch_diag *d)
{
    calib_run *run = vrun;
    const rch_calib_cfg *cfg = run->cfg;
    const rch_data *data = &run->in->data;
    size_t n_cable = 0;
    for (size_t f = 0; f < run->in->n_files; ++f)
        n_cable += run->in->counts[f];
    if (check_cost(cfg, n_cable, d) != 0)
        return -2;
    run->w = malloc(sizeof *run->w);
    run->held = cfg->residuals_path ? calloc(data->n ? data->n : 1, 1) : NULL;
    if (!run->w || (cfg->residuals_path && !run->held)) {
        rch_diag_set(d, "", 0, 0, "out of memory");
        return -1;
    }
    return fit_effects(r, cfg, rch_pos_count_lengths(data->s, data->n), d);
}

/* split: the split and one fit (its own plan), or the paper's cases. */
static int stage_split(void *vrun, rch_calib_result *r, rch_diag *d)
{
    calib_run *run = vrun;
    const rch_data *data = &run->in->data;
    if (run->cfg->cases > 1)
        return run_cases(run, r, data, d);
    return run_once(run, r, data->s, data->n, run->cfg->seed, run->held, d);
}

/* judge: the fit against what its sensor can produce. */
static int stage_judge(void *vrun, rch_calib_result *r, rch_diag *d)
{
    calib_run *run = vrun;
    (void)d;
    if (run->cfg->cases <= 1)
        rch_calib_judge_run(r, run->w, run->in->data.s, run->in->data.n);
    return 0;
}

/* outputs: the residual CSV; the file lines of the jumps (one file). */
static int stage_outputs(void *vrun, rch_calib_result *r, rch_diag *d)
{
    calib_run *run = vrun;
    const rch_data *data = &run->in->data;
    if (run->cfg->residuals_path && r->finite && save_residuals(r, run->in, run->held, d) != 0)
        return -1;
    if (r->have_jumps && r->prov.n_files == 1)
        for (unsigned k = 0; k < r->jumps.n_jumps; ++k)
            for (size_t i = 0; i < data->n; ++i)
                if (data->s[i].t == r->jumps.at_t[k]) {
                    r->jump_lines[k] = data->line[i];
                    break;
                }
    return 0;
}

/* The run's plan, in order (the fit's own: rch_calib_fit.c). To add a
 * stage: a function of (run, result) here, its id in rch_calib_stage_id
 * (rch_calib.h) and its name in rch_calib_plan.c. */
static const rch_calib_stage run_plan[] = {
    {RCH_STAGE_READ, stage_read},           {RCH_STAGE_SETUP, stage_setup},
    {RCH_STAGE_SPLIT, stage_split},         {RCH_STAGE_SYSTEMATIC, stage_systematic},
    {RCH_STAGE_SCREEN, stage_screen},       {RCH_STAGE_JUDGE, stage_judge},
    {RCH_STAGE_OUTPUTS, stage_outputs},
};

int rch_calib_run(rch_calib_result *r, const rch_calib_cfg *cfg, rch_diag *d)
{
    memset(r, 0, sizeof *r);
    memset(d, 0, sizeof *d);
    r->cfg = *cfg;
    if (cfg->residuals_path && (cfg->cases > 1 || cfg->jumps)) {
        rch_diag_set(d, "", 0, 0, "--residuals is for one calibration without --jumps (not with --cases or --jumps)");
        return -2;
    }
    calib_run *run = calloc(1, sizeof *run);
    if (run)
        run->in = malloc(sizeof *run->in);
    if (!run || !run->in) {
        free(run);
        rch_diag_set(d, "", 0, 0, "out of memory");
        return -1;
    }
    run->cfg = cfg;
    const int rc = rch_calib_plan_run(run_plan, sizeof run_plan / sizeof run_plan[0], run, r, &run->timing, d);
    r->timing = run->timing; /* (a refit's restore of the result kept its own) */
    free(run->w);
    free(run->held);
    if (run->in) {
        rch_inputs_free(run->in);
        free(run->in);
    }
    free(run);
    return rc;
}

void rch_calib_result_free(rch_calib_result *r)
{
    free(r->read_q);
    r->read_q = NULL;
}
