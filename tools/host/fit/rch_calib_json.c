/* SPDX-License-Identifier: MIT */
/* rch_calib_json.c - the report of `rcal calibrate --json` as one JSON
 * object, "rcal-calibrate/1" (rch_calib_json; docs/json-formats.md).
 *
 * Depends on: rch_calib.h, rch_jw, rch_robot (the uncertainty and provenance
 * members), rch_positions. Memory: none on the heap. Errors: -1 on a write
 * error.
 */
#include "rch_calib.h"
#include "rch_calib_int.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "rch_jw.h"
#include "rch_sensors.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif
#define DEG (M_PI / 180.0)

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

/* What parameter k's "delta" is taken from: the nominal DH, the start's
 * encoder, a tool plate's point as told (--cable-point: the start's, by
 * name), else 0. */
static double param_nominal(const rch_calib_result *r, unsigned k)
{
    const rc_model *m = &r->model;
    if (k < RC_N_DH)
        return r->robot.model.x[k];
    if (k < RC_N_BASE)
        return r->before.x[k];
    char name[64], other[64];
    for (unsigned e = 0; e < m->n_effects; ++e)
        if (m->effects[e].kind == RC_EFF_CABLE_POINTS && k >= m->effects[e].first &&
            k < m->effects[e].first + m->effects[e].count) {
            rc_param_name(name, sizeof name, m, k);
            for (unsigned j = RC_N_BASE; j < r->before.n_params; ++j)
                if (strcmp(rc_param_name(other, sizeof other, &r->before, j), name) == 0)
                    return r->before.x[j];
        }
    return 0.0;
}

static void json_params(rch_jw *w, const rch_calib_result *r)
{
    const rc_model *m = &r->model;
    rch_jw_arr(w, "params");
    for (unsigned k = 0; k < m->n_params; ++k) {
        char name[64];
        const int unit = rc_param_unit(m, k);
        const double scale = unit == 1 ? 1.0 / DEG : 1.0;
        const double nominal = param_nominal(r, k);
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
    /* the headline: the accuracy at the point the data see (new members) */
    rch_jw_obj(w, "seen_point");
    rch_jw_str(w, "at", r->seen_at == RCH_CALIB_SEEN_TARGETS      ? "targets"
                        : r->seen_at == RCH_CALIB_SEEN_ATTACHMENT ? "attachment"
                                                                  : "flange");
    rch_jw_numf(w, "position95_median_mm", r->seen_median_mm, "%.6g");
    rch_jw_numf(w, "position95_max_mm", r->seen_max_mm, "%.6g");
    if (r->flange_apart) {
        rch_jw_numf(w, "flange_position95_median_mm", r->flange_median_mm, "%.6g");
        rch_jw_numf(w, "flange_position95_max_mm", r->flange_max_mm, "%.6g");
        rch_jw_str(w, "flange", r->flange_prior_only ? "prior_only" : "partly");
    }
    rch_jw_end(w);
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

/* "estimation"."judge": the model against what its sensor can produce (rch_calib_judge.c) */
static void json_judge(rch_jw *w, const rch_calib_result *r)
{
    if (r->judge.done) {
        const rch_calib_judge *j = &r->judge;
        rch_jw_obj(w, "judge");
        rch_jw_numf(w, "noise_mm", j->noise_mm, "%.6g");
        rch_jw_numf(w, "floor_mm", j->floor_mm, "%.6g");
        rch_jw_numf(w, "sensor_sd_mm", j->sensor_sd_mm, "%.6g");
        rch_jw_bool(w, "sensor_sd_stated", j->sensor_sd_stated);
        rch_jw_numf(w, "display_step_mm", j->display_step_mm, "%.6g");
        rch_jw_numf(w, "joint_step_deg", j->joint_step_deg, "%.6g");
        rch_jw_numf(w, "joint_part_mm", j->joint_part_mm, "%.6g");
        if (r->n_pos_rows)
            rch_jw_numf(w, "tracker_floor_mm", j->pos_floor_mm, "%.6g");
        rch_jw_numf(w, "ratio", j->ratio, "%.6g");
        rch_jw_numf(w, "factor", RCH_JUDGE_FACTOR, "%.6g");
        rch_jw_bool(w, "beyond", j->beyond);
        rch_jw_bool(w, "worse_than_nominal", j->worse_than_nominal);
        rch_jw_bool(w, "usable", !j->beyond && !j->worse_than_nominal);
        if (j->beyond || j->worse_than_nominal) {
            char why[2048];
            rch_calib_judge_text(why, sizeof why, r);
            rch_jw_str(w, "why", why);
        }
        rch_jw_end(w);
    }
}

/* "estimation": the prior and its scale, the noise, outlets, attachment, systematic effects, the judge */
static void json_estimation(rch_jw *w, const rch_calib_result *r)
{
    rch_jw_obj(w, "estimation");
    rch_jw_bool(w, "prior", r->prior_on);
    if (r->prior_on) {
        rch_jw_num(w, "prior_length_mm", r->robot.prior.length_mm);
        rch_jw_num(w, "prior_twist_deg", r->robot.prior.twist_deg);
        rch_jw_num(w, "prior_offset_deg", r->robot.prior.offset_deg);
        rch_jw_num(w, "prior_attachment_mm", r->robot.prior.attachment_mm);
        if (r->prior_scaled) { /* the factors on the stated sd the data gave (rch_prior_scale) */
            static const char *const key[RCH_PS_TYPES] = {"lengths", "twists", "joint_zeros"};
            rch_jw_obj(w, "prior_scale");
            for (int t = 0; t < RCH_PS_TYPES; ++t) {
                rch_jw_obj(w, key[t]);
                rch_jw_numf(w, "factor", r->prior_scale.factor[t], "%.6g");
                rch_jw_numf(w, "factor_fit", r->prior_scale.factor_fit[t], "%.6g");
                rch_jw_numf(w, "factor_ml", r->prior_scale.factor_ml[t], "%.6g");
                rch_jw_numf(w, "rel_se", r->prior_scale.rel_se[t], "%.6g");
                rch_jw_numf(w, "determined", r->prior_scale.gamma[t], "%.6g");
                rch_jw_uint(w, "parameters", r->prior_scale.n[t]);
                rch_jw_bool(w, "fallback", r->prior_scale.fallback[t]);
                rch_jw_end(w);
            }
            rch_jw_end(w);
        }
        rch_jw_numf(w, "noise_mm", r->noise_mm, "%.6g");
        rch_jw_numf(w, "noise_se_mm", rch_sd_se(r->noise_mm, (double)r->n_train - r->p_eff), "%.4g");
        rch_jw_numf(w, "effective_params", r->p_eff, "%.4g");
    }
    rch_jw_uint(w, "outlets", r->n_outlets ? r->n_outlets : 1u);
    if (r->attach_auto) {
        rch_jw_str(w, "attachment", r->attach_centred ? "flange centre" : "estimated");
        rch_jw_numf(w, "attachment_dchi2", r->attach_dchi2, "%.6g");
        rch_jw_numf(w, "attachment_occam", r->attach_occam, "%.6g");
        rch_jw_bool(w, "attachment_dchi2_is_bound", r->attach_bound);
    }
    if (r->sys.tested) {
        rch_jw_obj(w, "systematic");
        rch_jw_bool(w, "length_offset_fitted", r->sys.offset_fitted);
        rch_jw_numf(w, "length_offset_score", r->sys.offset_score, "%.6g");
        rch_jw_numf(w, "length_offset_occam", r->sys.offset_occam, "%.6g");
        rch_jw_bool(w, "drift_fitted", r->sys.drift_fitted);
        rch_jw_numf(w, "drift_score", r->sys.drift_score, "%.6g");
        rch_jw_numf(w, "drift_occam", r->sys.drift_occam, "%.6g");
        rch_jw_bool(w, "refit_kept_out", r->sys.refit_kept_out);
        rch_jw_end(w);
    }
    json_judge(w, r);
    rch_jw_bool(w, "jumps_found_by_default", r->jumps_auto);
    rch_jw_end(w);
}

/* "screened": the rows left out as irreconcilable (rch_calib_screen.c) */
static void json_screened(rch_jw *w, const rch_calib_result *r)
{
    if (r->screen.out) { /* rows left out as irreconcilable (rch_calib_screen.c) */
        rch_jw_obj(w, "screened");
        rch_jw_uint(w, "rows", r->screen.rows);
        rch_jw_uint(w, "left_out", r->screen.out);
        rch_jw_numf(w, "k", RCH_SCREEN_K, "%g");
        rch_jw_numf(w, "scale_length_mm", r->screen.scale_mm[0], "%.6g");
        rch_jw_numf(w, "scale_position_mm", r->screen.scale_mm[1], "%.6g");
        rch_jw_arr(w, "rows_left_out");
        for (unsigned k = 0; k < r->screen.n_named; ++k) {
            const rch_screen_row *q = &r->screen.row[k];
            rch_jw_obj(w, NULL);
            rch_jw_str(w, "file", q->file < r->prov.n_files ? r->prov.file[q->file] : "");
            rch_jw_uint(w, "line", q->line);
            const rch_sensor_desc *sd = rch_sensor_of_kind(q->sensor);
            rch_jw_str(w, "sensor", sd ? sd->name : q->tracker ? "tracker" : "cable");
            rch_jw_numf(w, "residual_mm", q->residual_mm, "%.6g");
            rch_jw_str(w, "likely", rch_screen_kind(q));
            if (q->label_fits)
                rch_jw_uint(w, "fits_outlet", q->label_fits - 1u);
            else
                rch_jw_null(w, "fits_outlet");
            rch_jw_end(w);
        }
        rch_jw_end(w);
        rch_jw_end(w);
    }
}

/* The optional sections: truth, identifiability, uncertainty, jumps, dequantization, protocol, validation. */
static void json_extras(rch_jw *w, const rch_calib_result *r)
{
    if (r->cfg.truth_path) {
        rch_jw_obj(w, "truth_flange");
        rch_jw_numf(w, "before_rms_mm", r->truth_before_rms_mm, "%.6f");
        rch_jw_numf(w, "before_max_mm", r->truth_before_max_mm, "%.6f");
        rch_jw_numf(w, "after_rms_mm", r->truth_after_rms_mm, "%.6f");
        rch_jw_numf(w, "after_max_mm", r->truth_after_max_mm, "%.6f");
        rch_jw_end(w);
    }
    if (r->have_ident)
        json_ident(w, &r->ident);
    if (r->have_unc)
        json_uncertainty(w, r);
    if (r->have_jumps) {
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
        rch_jw_uint(w, "held_out_ambiguous", r->n_ambiguous);
        json_metrics(w, "after_unambiguous", &r->after_unambiguous);
    }
    if (r->have_dequant) {
        rch_jw_obj(w, "dequantized");
        rch_jw_uint(w, "corrected", r->dequant.n_corrected);
        rch_jw_uint(w, "refused", r->dequant.n_refused);
        rch_jw_numf(w, "dq_rms_deg", r->dequant.dq_rms_deg, "%.6f");
        rch_jw_bool(w, "automatic", r->dequant.automatic);
        rch_jw_end(w);
    }
    if (r->cases_done > 1) {
        rch_jw_obj(w, "protocol");
        rch_jw_uint(w, "cases", r->cases_done);
        rch_jw_numf(w, "before_rmse_mean_mm", r->case_before.mean, "%.6f");
        rch_jw_numf(w, "before_rmse_sd_mm", rch_stats_sd(&r->case_before), "%.6f");
        rch_jw_numf(w, "after_rmse_mean_mm", r->case_after.mean, "%.6f");
        rch_jw_numf(w, "after_rmse_sd_mm", rch_stats_sd(&r->case_after), "%.6f");
        rch_jw_uint(w, "held_out_ambiguous", r->case_ambiguous);
        rch_jw_numf(w, "after_unambiguous_rmse_mean_mm", r->case_unamb.n ? r->case_unamb.mean : NAN, "%.6f");
        rch_jw_numf(w, "after_unambiguous_rmse_sd_mm", r->case_unamb.n ? rch_stats_sd(&r->case_unamb) : NAN, "%.6f");
        rch_jw_end(w);
    }
    if (r->have_validate) {
        rch_jw_obj(w, "validation");
        rch_jw_str(w, "data", r->cfg.validate_path);
        json_metrics(w, "residual", &r->validate.m);
        rch_jw_uint(w, "repeated_poses", r->validate.n_repeated);
        rch_jw_numf(w, "iso9283_ad_mean_mm", r->validate.ad_mean_mm, "%.6f");
        rch_jw_numf(w, "iso9283_ad_max_mm", r->validate.ad_max_mm, "%.6f");
        rch_jw_numf(w, "iso9283_rd_mean_mm", r->validate.rd_mean_mm, "%.6f");
        rch_jw_numf(w, "iso9283_rd_max_mm", r->validate.rd_max_mm, "%.6f");
        rch_jw_end(w);
    }
}

void rch_calib_timing_json(rch_jw *w, const rch_calib_timing *t)
{
    rch_jw_obj(w, "timing");
    rch_jw_numf(w, "wall_ms", t->total_wall_ms, "%.3f");
    rch_jw_numf(w, "cpu_ms", t->total_cpu_ms, "%.3f");
    rch_jw_arr(w, "stages");
    for (unsigned k = 0; k < RCH_STAGE_N; ++k) {
        if (!t->runs[k])
            continue;
        rch_jw_obj(w, NULL);
        rch_jw_str(w, "stage", rch_calib_stage_name(k));
        rch_jw_uint(w, "runs", t->runs[k]);
        rch_jw_numf(w, "wall_ms", t->wall_ms[k], "%.3f");
        rch_jw_numf(w, "cpu_ms", t->cpu_ms[k], "%.3f");
        rch_jw_end(w);
    }
    rch_jw_end(w);
    rch_jw_end(w);
}

int rch_calib_json(FILE *f, const rch_calib_result *r, int argc, char **argv)
{
    rch_jw w;
    rch_jw_begin(&w, f, 0, "rcal-calibrate/1", argc, argv);
    rch_jw_str(&w, "method", rc_method_name(r->cfg.method));
    rch_jw_str(&w, "data", rch_calib_data_name(r));
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
    if (r->cfg.timing)
        rch_calib_timing_json(&w, &r->timing);
    json_params(&w, r);
    json_estimation(&w, r);
    if (r->n_pos_rows)
        json_positions(&w, r);
    json_screened(&w, r);
    json_extras(&w, r);
    rch_robot_write_provenance(&w, &r->prov);
    rch_jw_end(&w);
    return rch_jw_finish(&w);
}
