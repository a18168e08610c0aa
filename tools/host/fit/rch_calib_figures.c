/* SPDX-License-Identifier: MIT */
/* rch_calib_figures.c - what the pipeline reports once a model is fitted:
 * flange errors against a simulated truth, identifiability, the parameter
 * covariance and the predicted 3-D uncertainty (with its plot), the model on
 * the validation file (rch_calib_int.h, rch_calib_finish).
 *
 * Depends on: rch_sim, rch_ident, rch_uncert, rch_plot, rch_evaluate,
 * rch_data, rch_robot. Memory: scratch freed before returning. Errors: 0, or
 * -1 with d set.
 */
#include "rch_calib_int.h"

#include "rch_calib.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rc_rand.h"
#include "rch_data.h"
#include "rch_plot.h"
#include "rch_positions.h"
#include "rch_sim.h"
#include "rch_stats.h"

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

/* The headline's point (rch_calib_result.seen_at): every tracker target
 * (its covariance with the rest counted), else the cable attachment when
 * the model has one off the flange centre (the map's own point), else the
 * flange; and the flange centre's figure apart when the point is off it. */
static void seen_point(rch_calib_result *r, const rch_uncert *u, const rc_sample *train)
{
    const rc_model *m = &r->model;
    const size_t n = r->n_train;
    double *v = malloc((n + 1) * sizeof *v);
    unsigned nt = 0;
    const int kf = rch_pos_effect_at(m, RC_EFF_TRACKER_TARGETS, &nt);
    const int tf = rch_pos_effect_at(m, RC_EFF_TOOL_OFFSET, NULL);
    const double zero[3] = {0.0, 0.0, 0.0};
    r->seen_at = RCH_CALIB_SEEN_FLANGE;
    r->seen_median_mm = r->unc.map.data_median_mm;
    r->seen_max_mm = r->unc.map.data_max_mm;
    r->flange_apart = 0;
    if (!v)
        return;
    if (kf >= 0 && nt >= 3 && r->n_pos_rows) {
        size_t c = 0;
        for (unsigned j = 0; j < nt / 3; ++j)
            c += rch_uncert_point95(v + c, u, m, train, n - c, &m->x[kf + 3 * (int)j], kf + 3 * (int)j, (int)j);
        if (c) {
            r->seen_at = RCH_CALIB_SEEN_TARGETS;
            rch_median_max(&r->seen_median_mm, &r->seen_max_mm, v, c);
            r->flange_apart = 1;
            r->flange_median_mm = r->unc.map.data_median_mm;
            r->flange_max_mm = r->unc.map.data_max_mm;
        }
    } else if (tf >= 0 && sqrt(m->x[tf] * m->x[tf] + m->x[tf + 1] * m->x[tf + 1] + m->x[tf + 2] * m->x[tf + 2]) > 1.0) {
        const size_t c = rch_uncert_point95(v, u, m, train, n, zero, -1, -1);
        if (c) {
            r->seen_at = RCH_CALIB_SEEN_ATTACHMENT;
            r->flange_apart = 1;
            rch_median_max(&r->flange_median_mm, &r->flange_max_mm, v, c);
        }
    }
    r->flange_prior_only = r->flange_apart && r->flange_median_mm > 2.0 * r->seen_median_mm;
    free(v);
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
    double psd[RC_MAX_PARAMS]; /* the prior as the 95 % figures read it: an estimated scale's predictive width */
    memcpy(psd, r->prior_sd, sizeof psd);
    if (r->prior_scaled)
        rch_prior_scale_apply_predictive(psd, psd, fit->n_params, &r->prior_scale);
    if (rch_uncert_compute_map(&u, fit, fixed, train, setup, r->n_train, 1, r->prior_on ? psd : NULL,
                               r->noise_mm, err, sizeof err) != 0)
        return 0;
    rch_model_unc_from(&r->unc, &u);
    if (rch_uncert_map_compute(&r->unc.map, &u, &r->model, train, r->n_train, RCH_CALIB_TRUTH_POSES,
                               RCH_CALIB_TRUTH_SEED) == 0) {
        r->unc.orientation_determined = r->unc.map.rot_det_median_deg < RCH_ORIENT_DETERMINED_DEG;
        r->have_unc = 1;
        seen_point(r, &u, train);
    }
    if (r->cfg.plots_dir)
        rc = uncertainty_plot(r, &u, train, d);
    rch_uncert_free(&u);
    rch_model_unc_determined(&r->determined, &r->model, &r->robot.nominal, &r->unc);
    return rc;
}

/* The model on data the fit never saw (no refit): v, the validation file's
 * rows as read (rch_inputs), their outlet labels mapped to the fit's. */
static int validate(rch_calib_result *r, rc_solve_work *w, const rch_data *v, rch_diag *d)
{
    char err[256];
    rc_sample *s = malloc((v->n ? v->n : 1) * sizeof *s);
    if (!s) {
        rch_diag_set(d, "", 0, 0, "out of memory");
        return -1;
    }
    memcpy(s, v->s, v->n * sizeof *s);
    if (rch_data_outlets_as(r->outlet_label, r->n_outlets, s, v->n, v->line, r->cfg.validate_path, d) != 0) {
        free(s); /* the validation file's labels are the calibration data's */
        return -1;
    }
    int rc = rch_evaluate(&r->validate, &r->model, s, v->n, NULL, w, err, sizeof err);
    free(s);
    if (rc != 0) {
        rch_diag_set(d, r->cfg.validate_path, 0, 0, "%s", err);
        return -1;
    }
    r->have_validate = 1;
    return 0;
}

/* After the fit: truth, identifiability, uncertainty, validation. fit:
 * the model fitted to train (r->model, or with the jumps' offsets). */
int rch_calib_finish(rch_calib_result *r, const uint8_t *fixed, const rc_sample *train, const rc_model *fit,
                     const uint16_t *setup, const rch_data *validate_rows, rch_diag *d)
{
    if (r->cfg.truth_path && r->finite && truth_flange(r, d) != 0)
        return -1;
    r->have_ident = r->finite && rch_ident_compute(&r->ident, fit, train, r->n_train) == 0;
    if (r->finite && uncertainty(r, fixed, train, fit, setup, d) != 0)
        return -1;
    if (r->cfg.validate_path && r->after_ok && validate_rows) {
        rc_solve_work *w = malloc(sizeof *w);
        int rc = w ? validate(r, w, validate_rows, d) : -1;
        free(w);
        if (rc != 0)
            return -1;
    }
    return 0;
}
