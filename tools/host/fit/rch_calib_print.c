/* SPDX-License-Identifier: MIT */
/* rch_calib_print.c - the text report of `rcal calibrate` (rch_calib_print):
 * the paper's Table 7 form, the effects, the outlets, the predicted
 * uncertainty, identifiability, the tracker positions, the summary and the
 * next step; and the words the model file's refusal shares
 * (rch_calib_int.h).
 *
 * Depends on: rch_calib.h, rch_prior, rch_uncert, rch_positions, rch_text.
 * Memory: none on the heap. Errors: none (write errors are the stream's).
 */
#include "rch_calib.h"
#include "rch_calib_int.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "rch_prior.h"
#include "rch_seen.h"
#include "rch_text.h"
#include "rch_sensors.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif
#define DEG (M_PI / 180.0)

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
    const rch_sensor_desc *sd = rch_sensor_of_kind(r->other_sensor);
    if (r->n_lengths == 0)
        fprintf(f, "  encoder e: no cable lengths (%s only), held\n\n",
                r->n_pos_rows ? "tracker positions" : sd ? sd->words : "other sensors");
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
        if (q->automatic)
            fprintf(f, "  (%s)\n", q->why);
    } else if (r->dequant.automatic && r->dequant.q_step_deg >= 0.01 && r->dequant.fk_rms_before_mm > 0.02) {
        fprintf(f, "%s\n", r->dequant.why); /* rounded joints whose x, y, z say more, left: why */
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
/* The fit against what its sensor can produce (rch_calib_judge.c), one line. */
static void print_judge(FILE *f, const rch_calib_result *r)
{
    const rch_calib_judge *j = &r->judge;
    if (!j->done)
        return;
    char floor[400];
    rch_calib_judge_floor_text(floor, sizeof floor, r);
    fprintf(f, "  the fit against its sensor: noise %.4g mm, %.2g x what the sensor can produce (%s)%s\n",
            j->noise_mm, j->ratio, floor, j->beyond ? ": FAR BEYOND IT" : "");
}

void rch_calib_judge_floor_text(char *buf, size_t len, const rch_calib_result *r)
{
    const rch_calib_judge *j = &r->judge;
    const size_t n_len = r->n_data > r->n_pos_rows * 3 ? 1 : 0;
    size_t pos = 0;
    if (n_len)
        pos += (size_t)snprintf(buf + pos, len - pos,
                                "%.3g mm: repeatability %.3g mm%s, display step %.3g mm, joints' step %.3g deg "
                                "(%.3g mm on a length)",
                                j->floor_mm, j->sensor_sd_mm, j->sensor_sd_stated ? " stated" : " (default; --sensor-sd-mm)",
                                j->display_step_mm, j->joint_step_deg, j->joint_part_mm);
    if (r->n_pos_rows && pos < len)
        snprintf(buf + pos, len - pos, "%stracker %.3g mm", pos ? "; " : "", j->pos_floor_mm);
}

void rch_calib_judge_text(char *buf, size_t len, const rch_calib_result *r)
{
    const rch_calib_judge *j = &r->judge;
    char floor[400];
    rch_calib_judge_floor_text(floor, sizeof floor, r);
    size_t pos = 0;
    if (j->beyond)
        pos += (size_t)snprintf(buf + pos, len - pos,
                                "the fit's noise %.4g mm is %.0f x what the sensor can produce (%s): the model "
                                "explains nothing the sensor measured",
                                j->noise_mm, j->ratio, floor);
    if (j->worse_than_nominal && pos < len)
        pos += (size_t)snprintf(buf + pos, len - pos, "%sit predicts its own data worse than the nominal robot "
                                                      "(%.4f against %.4f mm RMS)",
                                pos ? "; " : "", r->train_after.rmse_mm, r->train_before.rmse_mm);
    if (pos >= len)
        return;
    if (j->cause_found)
        snprintf(buf + pos, len - pos, "; likely: %s", j->cause);
    else
        snprintf(buf + pos, len - pos,
                 "; tried: %s%s: none explains it. Look for wrong units or columns, another robot's or session's "
                 "data, a sensor far noisier than stated (%s)",
                 r->n_data > r->n_pos_rows * 3 ? "a length offset and a drift (weighed by default), length jumps and "
                                                  "rows far off (the screen), "
                                               : "rows far off (the screen), ",
                 j->tried[0] ? j->tried : "relabelled joint columns",
                 r->n_data > r->n_pos_rows * 3 ? "--sensor-sd-mm" : "the positions file's sigma_mm column");
}

/* The value of the first parameter of the effect kind in m (and its count), or NAN. */
static double effect_value(const rc_model *m, rc_effect_kind kind, unsigned k)
{
    for (unsigned e = 0; e < m->n_effects; ++e)
        if (m->effects[e].kind == kind && k < m->effects[e].count)
            return m->x[m->effects[e].first + k];
    return NAN;
}

/* The systematic length errors weighed by default (rch_calib_sys.c), a line each. */
static void print_sys(FILE *f, const rch_calib_result *r)
{
    const rch_calib_sys *y = &r->sys;
    if (!y->tested)
        return;
    const rc_model *m = &r->model;
    if (y->offset_fitted) {
        fprintf(f, "  length offset (a display's zero set off the outlet): fitted,");
        if (y->n_offsets > 1)
            for (unsigned k = 0; k < y->n_offsets; ++k)
                fprintf(f, " outlet %u %+.4f mm%s", (unsigned)r->outlet_label[k],
                        effect_value(m, RC_EFF_OUTLET_OFFSET, k), k + 1 < y->n_offsets ? "," : "");
        else
            fprintf(f, " %+.4f mm", effect_value(m, RC_EFF_LENGTH_OFFSET, 0));
        fprintf(f, " (its evidence %.1f beats its Occam penalty %.1f; --no-length-offset: not weighed)\n",
                y->offset_score, y->offset_occam);
    } else if (y->offset_testable) {
        fprintf(f, "  length offset (a display's zero): not needed (its evidence %.1f against its Occam penalty "
                   "%.1f%s)\n", y->offset_score, y->offset_occam,
                fabs(y->offset_score - y->offset_occam) <= RCH_SYS_TIE ? ": a tie, decided for the simpler model" : "");
    }
    if (y->drift_fitted)
        fprintf(f, "  drift of the lengths over the run: fitted as nuisance, %+.4f mm from the first row to the last "
                   "(its evidence %.1f beats its Occam penalty %.1f; not used at a new pose; --no-drift: not "
                   "weighed)\n", effect_value(m, RC_EFF_TIME_DRIFT, 0), y->drift_score, y->drift_occam);
    else if (y->drift_testable)
        fprintf(f, "  drift of the lengths over the run: not needed (its evidence %.1f against its Occam penalty "
                   "%.1f%s)\n", y->drift_score, y->drift_occam,
                fabs(y->drift_score - y->drift_occam) <= RCH_SYS_TIE ? ": a tie, decided for the simpler model" : "");
    if (y->refit_kept_out)
        fprintf(f, "  (a refit with %s gained %.1f against its penalty %.1f: not kept)\n",
                y->refit_kept_out == 1 ? "the offset" : "the drift",
                y->refit_gain, y->refit_occam);
}

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
    const double a = r->seen_median_mm;
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

/* The diagnosis of this run's inputs with what the run already fitted
 * (its files, --jumps, --dequantize-joints, --effects: the diagnosis then
 * offers only what the model lacks and ends at none when nothing is left),
 * quoted for the shell, into buf. */
static void diagnose_hint(char *buf, size_t len, const rch_calib_result *r)
{
    const rch_calib_cfg *c = &r->cfg;
    const char *argv[12 + 4 * RCH_CALIB_MAX_FILES];
    int n = 0;
    argv[n++] = "rcal";
    argv[n++] = "diagnose";
    for (size_t k = 0; k < rch_calib_cfg_n_files(c) && k < RCH_CALIB_MAX_FILES; ++k) {
        argv[n++] = "--data";
        argv[n++] = rch_calib_cfg_file(c, k);
    }
    for (size_t k = 0; k < c->n_positions_paths && k < RCH_CALIB_MAX_FILES; ++k) {
        argv[n++] = "--positions";
        argv[n++] = c->positions_paths[k];
    }
    argv[n++] = "--robot";
    argv[n++] = c->robot_path ? c->robot_path : "ROBOT.json";
    if (c->jumps)
        argv[n++] = "--jumps";
    if (r->have_dequant) /* forced or automatic: diagnose is told (its own default keeps the joints) */
        argv[n++] = "--dequantize-joints";
    if (c->effects && c->effects[0]) {
        argv[n++] = "--effects";
        argv[n++] = c->effects;
    }
    rch_shell_join(buf, len, n, argv);
}

/* Cable lengths only to one attachment point (no tracker, no cable points). */
static int one_point_cable(const rch_calib_result *r)
{
    return r->n_pos_rows == 0 && r->other_sensor == 0 && rch_pos_effect_at(&r->model, RC_EFF_CABLE_POINTS, NULL) < 0;
}

/* Tracker positions and no cable lengths. */
static int tracker_only(const rch_calib_result *r)
{
    return r->n_pos_rows && r->n_data == 3 * r->n_pos_rows;
}

/* What the headline's point is, in words. */
static const char *seen_point_words(const rch_calib_result *r)
{
    switch (r->seen_at) {
    case RCH_CALIB_SEEN_TARGETS: return "at the tracker's targets";
    case RCH_CALIB_SEEN_ATTACHMENT: return "at the cable attachment point";
    default: return "at the flange centre";
    }
}

/* The headline: the 95 % accuracy at the point the data see, then the
 * flange centre's apart when the point is off it. */
static void print_headline(FILE *f, const rch_calib_result *r, const char *lead)
{
    const rch_uncert_map *mp = &r->unc.map;
    fprintf(f, "%s%s: +-%.4f mm (median over the data's poses; max %.4f)", lead, seen_point_words(r),
            r->seen_median_mm, r->seen_max_mm);
    if (r->seen_at != RCH_CALIB_SEEN_TARGETS)
        fprintf(f, ", whole workspace +-%.4f mm (median over %d random poses; max %.4f)", mp->work_median_mm,
                RCH_CALIB_TRUTH_POSES, mp->work_max_mm);
    fputc('\n', f);
    if (!r->flange_apart)
        return;
    fprintf(f, "  the flange centre behind %s: +-%.4f mm (median; max %.4f)%s\n",
            r->seen_at == RCH_CALIB_SEEN_TARGETS ? "them" : "it", r->flange_median_mm, r->flange_max_mm,
            !r->flange_prior_only ? ""
            : r->seen_at == RCH_CALIB_SEEN_TARGETS
                ? ": prior only (the data see the point above, not the flange centre behind it: compensate at "
                  "that point, rcal compensate --tool X,Y,Z, or measure at the flange centre)"
                : ": prior only (the data see the point above, not the flange centre behind it: compensate at "
                  "that point, rcal compensate --tool X,Y,Z; or measure where the cable is hooked and say so, "
                  "--cable-point X,Y,Z --cable-point-sd MM (hooked to 0.1 mm: about 0.1 mm at the flange), or hook "
                  "it at the flange centre)");
}

/* The prior's scale estimated from the data: each DH type's factor with its
 * uncertainty, or why the stated sd was kept. */
static void print_prior_scale(FILE *f, const rch_calib_result *r)
{
    static const char *const name[RCH_PS_TYPES] = {"lengths", "twists", "joint zeros"};
    const double stated[RCH_PS_TYPES] = {r->robot.prior.length_mm, r->robot.prior.twist_deg,
                                         r->robot.prior.offset_deg};
    static const char *const unit[RCH_PS_TYPES] = {"mm", "deg", "deg"};
    const rch_prior_scale *ps = &r->prior_scale;
    fprintf(f, "  the prior's scale from this robot's data (type-II maximum likelihood; the uncertainty never below "
               "the stated sd, at most %g x):", RCH_PRIOR_SCALE_MAX);
    for (int t = 0; t < RCH_PS_TYPES; ++t) {
        if (ps->fallback[t]) {
            fprintf(f, "%s %s %.3g %s kept (the data determine %.1f of %u: too few to say their spread)",
                    t ? ";" : "", name[t], stated[t], unit[t], ps->gamma[t], ps->n[t]);
            continue;
        }
        fprintf(f, "%s %s %.3g -> %.3g %s (x %.2f +- %.0f %%, from %.1f of %u determined%s", t ? ";" : "", name[t],
                stated[t], stated[t] * ps->factor[t], unit[t], ps->factor[t], 100.0 * ps->rel_se[t], ps->gamma[t],
                ps->n[t], ps->factor_ml[t] < 1.0 ? "; their spread is within the stated sd" : "");
        if (ps->factor_fit[t] < ps->factor[t])
            fprintf(f, ": the estimate draws the ones the data barely see toward the drawing with %.3g %s, x %.2f",
                    stated[t] * ps->factor_fit[t], unit[t], ps->factor_fit[t]);
        fputc(')', f);
    }
    fputc('\n', f);
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
                   "%.3g deg, cable attachment %.3g mm%s); noise %.4f +- %.4f mm estimated from the residuals "
                   "(%u fit%s, %.1f effective parameters; +- from its chi-square degrees of freedom)\n",
                r->robot.prior.length_mm, r->robot.prior.twist_deg, r->robot.prior.offset_deg,
                r->robot.prior.attachment_mm, r->robot.prior.from_file ? ", from the robot file" : ", defaults",
                r->noise_mm, rch_sd_se(r->noise_mm, (double)r->n_train - r->p_eff), r->noise_passes,
                r->noise_passes == 1 ? "" : "s", r->p_eff);
    if (u->has_prior && r->prior_scaled)
        print_prior_scale(f, r);
    const rch_sensor_desc *sd = rch_sensor_of_kind(r->other_sensor);
    if (u->has_prior && r->n_pos_rows)
        fprintf(f, "  theta1 and d1 held (gauge): the tracker's frame absorbs the robot's heading and height, as "
                   "an outlet does for lengths; a cell sets its base frame anyway\n");
    else if (u->has_prior && r->n_lengths == 0 && sd)
        fprintf(f, "  theta1 and d1 held (gauge): %s; a cell sets its base frame anyway\n", sd->gauge);
    else if (u->has_prior)
        fprintf(f, "  theta1 and d1 held (gauge): lengths from outlets whose places are estimated cannot see the "
                   "robot's heading and height against them; a cell sets its base frame anyway\n");
    if (r->n_lengths > 0)
        print_outlets(f, m);
    if (r->sensor_note[0])
        fprintf(f, "  %s: %s\n", sd ? sd->words : "data", r->sensor_note);
    if (r->attach_auto)
        fprintf(f, "  cable attachment: %s (an attachment vector improves the fit by %s%.1f against its Occam "
                   "penalty %.1f)\n",
                r->attach_centred ? "at the flange centre" : "estimated in the flange frame (the flange centre "
                                                             "relative to it is known only from the prior of a6, d6)",
                r->attach_bound ? "at least " : "",
                fmax(r->attach_dchi2, 0.0), /* below 0 only by the scaled prior taken without a refit: with
                                               more freedom the optimum does not fit worse */
                r->attach_occam);
    print_sys(f, r);
    print_judge(f, r);
    fprintf(f, "  parameter        value   1 std.error  what the data see (%s)\n",
            u->has_prior ? "posterior sd against the prior's; why" : "why");
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
        const rch_seen cl = rch_seen_of_unc(u, k);
        const char *why = rch_seen_why(cl, (rch_param_class)u->cls[k]);
        char pc[200] = "";
        int dev3 = 0;
        if (u->has_prior && u->prior_sd[k] > 0.0 && u->cls[k] != RCH_PARAM_FIXED) {
            dev3 = fabs(m->x[k] - r->prior_mean[k]) / u->prior_sd[k] > 3.0;
            outside += dev3;
            const double ratio = u->se[k] / u->prior_sd[k];
            /* above 100 %: the cluster-robust covariance scales the posterior by the set-up groups' scatter */
            snprintf(pc, sizeof pc, " (sd %.0f %% of prior%s)", 100.0 * ratio,
                     ratio > 1.005 && u->kind == RCH_COV_CLUSTER ? ", widened by the set-up groups' scatter" : "");
        }
        fprintf(f, "  %-10s %12.5f %s %-3s %s%s%s%s%s\n", nm, m->x[k] * sc, se, unit == 0 ? "mm" : unit == 1 ? "deg" : "",
                rch_seen_words(cl), pc, why[0] ? "; " : "", why,
                dev3 ? "  OUTSIDE the prior's plausible range (> 3 sd from nominal)" : "");
        if (k < RC_N_DH && u->comp_nominal[k]) {
            size_t len = strlen(list);
            snprintf(list + len, sizeof list - len, "%s%s", held ? " " : "", nm);
            ++held;
        }
    }
    hint_paths hp;
    hint_paths_of(&hp, r);
    char dh[2400];
    diagnose_hint(dh, sizeof dh, r);
    if (outside)
        fprintf(f, "  next: %u parameter(s) OUTSIDE the prior's range are a real deviation (check the drawing) or "
                   "stand in for an effect the model lacks: %s\n",
                outside, dh);
    print_headline(f, r, "predicted 3-D accuracy after compensation (95 %, longest semi-axis of the position "
                         "ellipsoid) ");
    if (accuracy_needs_poses(r) && tracker_only(r))
        fprintf(f, "  next: the positions are fitted to %.3f mm but the targets only to %.3f mm: the poses leave "
                   "most of the geometry to the prior; measure poses that move every joint, with the targets "
                   "spread on the tool\n",
                r->after_m.rmse_mm, r->seen_median_mm);
    else if (accuracy_needs_poses(r) && r->n_lengths == 0 && rch_sensor_of_kind(r->other_sensor))
        fprintf(f, "  next: the %s are fitted to %.3f mm but the 3-D accuracy only to %.3f mm: the poses leave most of "
                   "the geometry to the prior; %s\n",
                rch_sensor_of_kind(r->other_sensor)->words, r->after_m.rmse_mm, r->seen_median_mm,
                rch_sensor_of_kind(r->other_sensor)->advice);
    else if (accuracy_needs_poses(r))
        fprintf(f, "  next: the lengths are predicted to %.3f mm but the 3-D accuracy only to %.3f mm: the poses leave "
                   "most of the geometry to the prior; plan poses that move every joint, from more than one outlet: "
                   "rcal poses --robot %s --count 60 --outlet X,Y,Z --outlet X2,Y2,Z2 --out plan.csv\n",
                r->after_m.rmse_mm, r->seen_median_mm, hp.robot);
    fprintf(f,
            "predicted flange-orientation uncertainty (95 %%) inside the data: +-%.4f deg with every parameter, "
            "+-%.4f deg with those compensation uses: orientation %s\n",
            u->map.rot_data_median_deg, u->map.rot_det_median_deg,
            u->orientation_determined ? "determined by the data (compensation matches position and orientation)"
            : one_point_cable(r) ? "not seen by the data (one cable attachment point: the lengths measure a point, "
                                   "not the turn about it; compensation defaults to position-only)"
                                 : "NOT determined by the data (compensation defaults to position-only)");
    fprintf(f,
            "compensation uses %u of 24 DH parameters as fitted; held at nominal (tied to a direction the data do not "
            "see or see only weakly, that moves the robot): %s\n\n",
            RC_N_DH - held, held ? list : "none");
}

/* Does a known set name the encoder outlet (ex, ey, ez)? */
static int names_encoder(const char *params)
{
    static const char *const e[3] = {"ex", "ey", "ez"};
    for (const char *p = params; *p;) {
        const size_t len = strcspn(p, " ");
        for (int k = 0; k < 3; ++k)
            if (len == 2 && strncmp(p, e[k], 2) == 0)
                return 1;
        p += len;
        p += *p == ' ';
    }
    return 0;
}

/* no_lengths: a tracker-only run (the encoder held: the sets that trade
 * against it say nothing of these data). */
static void print_ident(FILE *f, const rch_ident *id, int prior, int no_lengths)
{
    fprintf(f,
            "identifiability (%u parameters, at the solution): rank %u: %u direction(s) the data do not see, %u "
            "seen only weakly;\n  condition number %.3g over the identifiable part, observability index O1 %.4g\n",
            id->n_params, id->rank, id->n_params - id->rank, id->n_weak, id->cond, id->observability);
    for (unsigned k = 0; k < id->n_dirs; ++k) {
        fprintf(f, "  - %s (relative singular value %.1e): %s\n", id->dirs[k].weak ? "seen only weakly" : "NOT seen by the data",
                id->dirs[k].sv_rel, id->dirs[k].combo);
        if (id->dirs[k].why[0] && !(no_lengths && strstr(id->dirs[k].why, "encoder")))
            fprintf(f, "      %s\n", id->dirs[k].why);
    }
    unsigned shown = 0;
    for (unsigned k = 0; k < id->n_combos; ++k)
        shown += !(no_lengths && names_encoder(id->combos[k].params));
    if (shown)
        fprintf(f, "  what these directions hold (known sets of parameters whose columns are dependent):\n");
    for (unsigned k = 0; k < id->n_combos; ++k)
        if (!(no_lengths && names_encoder(id->combos[k].params)))
            fprintf(f, "    %s %s (%.1e): %s\n", id->combos[k].params, id->combos[k].weak ? "seen only weakly" : "NOT seen by the data",
                id->combos[k].sv_rel, id->combos[k].why);
    fprintf(f, prior ? "  With the prior, what the data do not see stays where the drawing puts it (the prior's mean), "
                       "with the prior's uncertainty (\"prior only\" above).\n\n"
                     : "  The solver leaves directions the data do not see where they started (nominal).\n\n");
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
    if (r->pos_has_sigma)
        fprintf(f, "tracker positions: %zu rows (%zu poses, %u target(s)), %zu cable lengths; each position row "
                   "weighed by its sigma_mm against the files' median %.4g mm (the noise figures are a median row's)\n",
                r->n_pos_rows, r->n_pos_poses, r->n_targets, r->n_data - 3 * r->n_pos_rows, r->pos_sigma_mm);
    else
        fprintf(f, "tracker positions: %zu rows (%zu poses, %u target(s)), %zu cable lengths; every row weighs the "
                   "same (no sigma_mm column)\n",
                r->n_pos_rows, r->n_pos_poses, r->n_targets, r->n_data - 3 * r->n_pos_rows);
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
void rch_calib_jump_counts(char *buf, size_t len, const rch_calib_result *r)
{
    const unsigned found = r->jumps_found, steps = r->jump_check_steps;
    if (found == steps)
        snprintf(buf, len, "the change-point search found %u step%s far above the residual (8 x its robust sd "
                 "%.4f mm; largest %.3f mm)", found, found == 1 ? "" : "s", r->jump_check_scale_mm, r->jump_check_max_mm);
    else
        snprintf(buf, len, "%u of the %u steps the change-point search found %s far above the residual (8 x its "
                 "robust sd %.4f mm; largest %.3f mm)", found, steps, found == 1 ? "is" : "are", r->jump_check_scale_mm,
                 r->jump_check_max_mm);
}

const char *rch_calib_data_name(const rch_calib_result *r)
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
    if (r->judge.done && (r->judge.beyond || r->judge.worse_than_nominal)) {
        char why[2048];
        rch_calib_judge_text(why, sizeof why, r);
        fprintf(f, "  NOT A MODEL TO USE: %s; %s\n", why,
                r->cfg.force ? "written anyway (--force)" : "rcal calibrate --out refuses to write it (--force writes it)");
    }
    if (r->after_ok)
        fprintf(f, "  %s RMSE %.4f mm before -> %.4f mm after calibration (%zu samples%s)\n",
                r->n_test ? "held-out" : "training", r->before_m.rmse_mm, r->after_m.rmse_mm,
                r->n_test ? r->n_test : r->n_train, r->n_test ? " the fit never saw" : ", none held out");
    else
        fprintf(f, "  %s RMSE %.4f mm before; after: the solver diverged, no figures\n",
                r->n_test ? "held-out" : "training", r->before_m.rmse_mm);
    if (r->have_unc)
        print_headline(f, r, "  predicted 3-D accuracy after compensation (95 %) ");
    else
        fputs("  predicted 3-D accuracy: none in this run (no uncertainty: too few samples or a model that is not "
              "finite)\n",
              f);
    const unsigned outside = r->have_unc ? outside_prior(r) : 0;
    if (r->jumps_found && !r->cfg.jumps && !r->jumps_auto)
        fprintf(f, "  next: rcal calibrate --data %s --robot %s --jumps (the lengths jump and this fit does not model "
                   "them)\n",
                hp.data, hp.robot);
    else if (outside) {
        char dh[2400];
        diagnose_hint(dh, sizeof dh, r);
        fprintf(f, "  next: %s (%u parameter%s outside the prior's range)\n", dh, outside, outside == 1 ? "" : "s");
    }
    else if (accuracy_needs_poses(r) && tracker_only(r))
        fprintf(f, "  next: measure poses that move every joint, with the targets spread on the tool (the 3-D "
                   "accuracy at the targets is %.0f x the position RMSE: the poses leave most of the geometry to "
                   "the prior)\n",
                r->seen_median_mm / r->after_m.rmse_mm);
    else if (accuracy_needs_poses(r) && r->n_lengths == 0 && rch_sensor_of_kind(r->other_sensor))
        fprintf(f, "  next: %s (the 3-D accuracy is %.0f x the RMSE of the %s: the poses leave most of the geometry "
                   "to the prior)\n",
                rch_sensor_of_kind(r->other_sensor)->advice, r->seen_median_mm / r->after_m.rmse_mm,
                rch_sensor_of_kind(r->other_sensor)->words);
    else if (accuracy_needs_poses(r))
        fprintf(f, "  next: rcal poses --robot %s --count 60 --outlet X,Y,Z --outlet X2,Y2,Z2 --out plan.csv (the "
                   "3-D accuracy is %.0f x the length RMSE: the poses leave most of the geometry to the prior)\n",
                hp.robot, r->seen_median_mm / r->after_m.rmse_mm);
}

void rch_calib_print_screened(FILE *f, const rch_calib_result *r, const char *prefix)
{
    const rch_calib_screen_result *z = &r->screen;
    for (unsigned k = 0; k < z->n_named; ++k) {
        const rch_screen_row *w = &z->row[k];
        const char *file = w->file < r->prov.n_files ? r->prov.file[w->file] : "?";
        char why[64] = "";
        if (w->label_fits)
            snprintf(why, sizeof why, " (its length fits outlet %u)", w->label_fits - 1u);
        const rch_sensor_desc *sd = rch_sensor_of_kind(w->sensor);
        fprintf(f, "%s%s:%u: left out: %s %.4g mm off (%.0f x its sensor's robust scale %.3g mm): likely %s%s\n", prefix,
                file, w->line, sd ? sd->name : w->tracker ? "position" : "length", w->residual_mm,
                w->scale_mm > 0.0 ? w->residual_mm / w->scale_mm : 0.0, w->scale_mm, rch_screen_kind(w), why);
    }
    if (z->out > z->n_named)
        fprintf(f, "%s... and %zu more rows left out\n", prefix, z->out - z->n_named);
}

void rch_calib_print(FILE *f, const rch_calib_result *r)
{
    const char *method = rc_method_name(r->cfg.method);
    if (r->prov.n_files > 1)
        fprintf(f, "rcal calibrate: %u files merged (%zu samples), robot \"%s\", method %s\n", r->prov.n_files,
                r->n_data, r->robot.name, method);
    else
        fprintf(f, "rcal calibrate: %s (%zu samples), robot \"%s\", method %s\n", rch_calib_data_name(r), r->n_data,
                r->robot.name, method);
    fprintf(f, "split: %zu train / %zu held out (test fraction %.2f, seed %lu)\n\n", r->n_train, r->n_test,
            r->cfg.test_fraction, r->cfg.seed);
    if (r->screen.out) {
        fprintf(f, "ROWS LEFT OUT: %zu of %zu rows cannot be reconciled with the rest (beyond %.0f x their sensor's "
                   "robust scale, 1.4826 x the median absolute deviation of its residuals, and %.2g mm): the fit ran "
                   "again without them (--no-screen keeps them)\n",
                r->screen.out, r->screen.rows, RCH_SCREEN_K, RCH_SCREEN_FLOOR_MM);
        rch_calib_print_screened(f, r, "  ");
        fputc('\n', f);
    }
    /* the check counts the steps far above the residual; the fit then takes
     * every step the search found, the smaller ones too: both numbers said */
    const unsigned steps = r->jump_check_steps, fitted = r->have_jumps ? r->jumps.n_jumps : steps;
    char counts[200], all[64];
    rch_calib_jump_counts(counts, sizeof counts, r);
    snprintf(all, sizeof all, steps == 1 ? "it is" : r->jumps_found == steps ? "they are" : "all %u are", steps);
    hint_paths hp;
    hint_paths_of(&hp, r);
    if (r->jumps_found && !r->cfg.jumps && !r->jumps_auto)
        fprintf(f, "WARNING: the lengths jump in acquisition order: %s, and this fit does not model them: its "
                   "geometry is wrong and --out is refused.\n  next: rcal calibrate --data %s --robot %s --jumps (it "
                   "fits the %u step%s found; rcal diagnose tells)\n\n",
                counts, hp.data, hp.robot, steps, steps == 1 ? "" : "s");
    if (r->jumps_auto) {
        char also[64] = "";
        if (fitted != steps)
            snprintf(also, sizeof also, " (%u after the fit with them)", fitted);
        fprintf(f, "note: the lengths jump in acquisition order: %s, so %s fitted as nuisance%s, as --jumps does "
                   "(--no-jump-check: not looked for)\n\n",
                counts, all, also);
    }
    if (tracker_only(r)) /* no cable: the rows are the positions' coordinates */
        fprintf(f, "%s error (%zu coordinates, mm)      RMSE  mean|e|       SD      MAX\n",
                r->n_test ? "held-out" : "training", r->n_test ? r->n_test : r->n_train);
    else
        fprintf(f, "%s error (%zu samples, mm)          RMSE  mean|e|       SD      MAX\n",
                r->n_test ? "held-out" : "training", r->n_test ? r->n_test : r->n_train);
    print_metrics_row(f, tracker_only(r) ? "before (nominal DH, fitted tracker)"
                                         : "before (nominal DH, fitted encoder)", &r->before_m);
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
        print_ident(f, &r->ident, r->prior_on, tracker_only(r));
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

void rch_calib_timing_print(FILE *f, const rch_calib_timing *t, const char *prefix)
{
    fprintf(f, "%stiming (each stage's own time; ms):      wall       cpu  runs\n", prefix);
    for (unsigned k = 0; k < RCH_STAGE_N; ++k)
        if (t->runs[k])
            fprintf(f, "%s  %-34s %9.2f %9.2f %5u\n", prefix, rch_calib_stage_name(k), t->wall_ms[k], t->cpu_ms[k],
                    t->runs[k]);
    fprintf(f, "%s  %-34s %9.2f %9.2f\n", prefix, "total", t->total_wall_ms, t->total_cpu_ms);
}
