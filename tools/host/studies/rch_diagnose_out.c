/* SPDX-License-Identifier: MIT */
/* rch_diagnose_out.c - what `rcal diagnose` reports: the text report, the
 * JSON object, the next step, the model file with the effects found and the
 * residual table. See rch_diagnose.h. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "rch_diagnose_int.h"
#include "rch_calib.h"
#include "rch_jw.h"
#include "rch_plot.h"
#include "rch_text.h"

/* ---------------------------------------------------------------- output */

static void print_tests(FILE *f, const rch_diagnose_test *t, unsigned n)
{
    fprintf(f, "  %-36s %5s %6s %10s %9s %7s\n", "variable", "dof1", "dof2", "F", "p", "R^2");
    char pb[16];
    for (unsigned k = 0; k < n; ++k)
        fprintf(f, "  %-36s %5u %6u %10.2f %9s %6.1f%% %s\n", t[k].name, t[k].dof1, t[k].dof2, t[k].f_stat,
                rch_plot_fmt_p(pb, sizeof pb, t[k].p_value), 100.0 * t[k].r2, t[k].significant ? "STRUCTURE" : "");
}

/* Whether the next step fits length jumps (--jumps): the diagnosis found
 * them (calibrate's, or its own), was told (--jumps), or named per set-up
 * offsets (group_offset), which calibrate fits as the jumps at the set-up
 * changes its search tells from the noise (it has no per-set-up offset of
 * its own). */
static int next_jumps(const rch_diagnose_result *r)
{
    if (r->jumps_asked || r->jumps.n_jumps > 0 || strcmp(r->effect, "length_jump") == 0)
        return 1;
    for (unsigned s = 0; s < r->n_steps; ++s)
        if (r->steps[s].chosen >= 0 && r->steps[s].cand[r->steps[s].chosen].kind == RC_EFF_GROUP_OFFSET)
            return 1;
    return 0;
}

static void chosen_effects(char *list, size_t len, const rch_diagnose_result *r);

/* What the next step adds to the diagnosis's own inputs: effects to the
 * known ones, --jumps. 0: the chain ends here (the next step is the
 * calibration of what this diagnosis was given). */
static unsigned next_adds(const rch_diagnose_result *r)
{
    char list[512];
    chosen_effects(list, sizeof list, r);
    return (strcmp(list, r->known_effects) != 0) + (next_jumps(r) && !r->jumps_asked);
}

/* The first screen: the verdict with the size of what was found, the held-out
 * error of each sensor before and after (3-D for the tracker), what to run
 * next. */
static void print_summary(FILE *f, const rch_diagnose_result *r)
{
    fprintf(f, "\nVerdict: %s", r->effect);
    if (r->joint)
        fprintf(f, " (joint %u)", r->joint);
    if (r->n_known)
        fprintf(f, "  (beside the %u effect(s) already in the model)", r->n_known);
    fprintf(f, "\n");
    for (unsigned k = 0; k < r->n_params; ++k)
        fprintf(f, "  %-34s %12.5f +- %.5f %s\n", r->params[k].name, r->params[k].value, r->params[k].se,
                r->params[k].unit);
    if (r->jumps.n_jumps > 0) { /* the nuisance the next step fits with --jumps, on the first screen */
        unsigned big = 0;
        for (unsigned k = 1; k < r->jumps.n_jumps; ++k)
            big = fabs(r->jumps.size_mm[k]) > fabs(r->jumps.size_mm[big]) ? k : big;
        char where[32] = "";
        if (r->jump_line[big])
            snprintf(where, sizeof where, " at line %u", r->jump_line[big]);
        fprintf(f, "  %-34s %u, largest %+.4f mm%s%s\n", "length jumps (nuisance)", r->jumps.n_jumps,
                r->jumps.size_mm[big], where, r->jumps_implausible ? " (more than a display event: below)" : "");
    }
    fprintf(f, "  %-34s %8s %10s %10s %10s\n", "held-out error by sensor (RMS, mm)", "rows", "before", "after",
            "floor");
    for (unsigned k = 0; k < r->n_sensors; ++k) {
        char name[64];
        snprintf(name, sizeof name, "%s%s", r->sensors[k].name, strcmp(r->sensors[k].kind, "tracker") == 0 ? " (3-D)" : "");
        fprintf(f, "  %-34s %8zu %10.4f %10.4f %10.4f\n", name, r->sensors[k].rows, r->sensors[k].before_mm,
                r->sensors[k].after_mm, r->sensors[k].floor_mm);
    }
    if (r->in.n_data + r->in.n_positions > 0) {
        char next[1400], why[400] = "";
        const unsigned addable = next_adds(r);
        if (addable == 0 && strcmp(r->remaining, "none") == 0)
            snprintf(why, sizeof why, "  (the end: %s)",
                     r->n_chosen ? "what was found is already in this command (nuisance fitted with the geometry, "
                                   "never used at a new pose); the held-out residual left is noise"
                                 : "nothing more to add, the held-out residual is noise");
        else if (addable == 0)
            snprintf(why, sizeof why, "  (the end of what the candidates explain: %s)", r->remaining_why);
        int groups = 0;
        for (unsigned s = 0; s < r->n_steps; ++s)
            groups |= r->steps[s].chosen >= 0 && r->steps[s].cand[r->steps[s].chosen].kind == RC_EFF_GROUP_OFFSET;
        if (groups)
            fprintf(f, "  group_offset: calibrate has no per-set-up offset; the next step fits the set-up changes its "
                       "jump search tells from the noise as length jumps (--jumps)\n");
        if (r->jumps_implausible)
            fprintf(f, "  warning: %u length jump(s) larger than %.3g mm, more than a display event (below)\n",
                    r->jumps_implausible, r->jump_max_mm);
        if (rch_diagnose_next(next, sizeof next, r, NULL, r->in.robot_given ? r->in.robot_path : NULL) == 0)
            fprintf(f, "  next: %s%s\n", next, why);
    }
}

int rch_diagnose_print(FILE *f, const rch_diagnose_result *r)
{
    fprintf(f, "rcal diagnose: %zu residual rows (%zu poses), %u set-up groups, %u-fold cross-validation (random "
               "within groups, every pose whole)\n",
            r->n, r->n_poses, r->n_groups, r->folds);
    print_summary(f, r);
    if (r->n_flicker)
        fprintf(f, "  %u sample(s) kept in their group although a wrist reading moved by one display step\n",
                r->n_flicker);
    fprintf(f, "\nNoise floor: %.4f mm rms  (joint display step %.3g deg through the Jacobian: %.4f mm; "
               "length step %.3g mm%s: %.4f mm)\n",
            r->noise_floor_mm, r->q_step_deg, r->floor_joints_mm, r->len_step_mm,
            r->len_noise_mm > 0.0 ? " + noise" : "", r->floor_len_mm);
    fprintf(f, "Geometric model (%u parameters, rank %u of %u free): training RMSE %.4f mm, held-out RMSE %.4f mm "
               "= %.2f x floor\n",
            r->geo.n_params, r->geo_rank, r->geo_free, r->train_rmse_geo_mm, r->rmse_before_mm,
            r->rmse_before_mm / r->noise_floor_mm);
    fprintf(f, "\nStructure of the held-out residuals (geometry only; F tests, Bonferroni over %u tests):\n",
            r->n_tests);
    print_tests(f, r->before, r->n_tests);
    for (unsigned s = 0; s < r->n_steps; ++s) {
        const rch_diagnose_step *st = &r->steps[s];
        fprintf(f, "\nStep %u: candidates fitted jointly with the geometry (model held-out RMSE %.4f mm)\n", s + 1,
                st->rmse_base_mm);
        fprintf(f, "  %-22s %6s %6s %10s %11s %7s %9s %8s %9s  %s\n", "effect", "params", "ident", "held-out",
                "gain mm^2", "z", "p", "score F", "p score", "");
        for (unsigned k = 0; k < st->n_cand; ++k) {
            const rch_diagnose_cand *ca = &st->cand[k];
            char pb[16], ps[16], fs[16];
            snprintf(fs, sizeof fs, "%.2f", ca->score_f);
            if (ca->tested)
                fprintf(f, "  %-22s %6u %6u %10.4f %11.5f %7.2f %9s %8s %9s  %s%s%s\n", ca->name, ca->n_params,
                        ca->n_ident, ca->rmse_cv_mm, ca->gain_mm2, ca->z, rch_plot_fmt_p(pb, sizeof pb, ca->p_value),
                        ca->scored ? fs : "-", ca->scored ? rch_plot_fmt_p(ps, sizeof ps, ca->score_p) : "-",
                        (int)k == st->chosen ? "<- CHOSEN" : ca->significant ? "significant" : "",
                        ca->note[0] ? "  " : "", ca->note);
            else
                fprintf(f, "  %-22s %6u %6u %10s %11s %7s %9s %8s %9s  %s\n", ca->name, ca->n_params, ca->n_ident, "-",
                        "-", "-", "-", "-", "-", ca->note);
        }
        fprintf(f, "  -> %s\n", st->chosen >= 0 ? st->why : st->why[0] ? st->why : "stop");
    }
    fprintf(f, "\nVerdict: %s", r->effect);
    if (r->joint)
        fprintf(f, " (joint %u)", r->joint);
    fprintf(f, "\n");
    if (r->dequant_corrected)
        fprintf(f, "Joints recovered from x, y, z: %zu rows corrected, %zu refused as inconsistent.\n",
                r->dequant_corrected, r->dequant_refused);
    if (r->jumps.n_jumps > 0) {
        fprintf(f,
                "Length jumps in acquisition order (the lengths shift at a row and stay shifted: a display "
                "re-zeroed or counts lost; removed as a nuisance before the search below):\n");
        for (unsigned k = 0; k < r->jumps.n_jumps; ++k)
        {
            char where[48] = "";
            if (r->jump_line[k])
                snprintf(where, sizeof where, "line %u, ", r->jump_line[k]);
            fprintf(f, "  at %ssample %zu (1-based, in file order; t %.4f): %+.4f +- %.4f mm%s\n", where,
                    r->jumps.at[k] + 1, r->jumps.at_t[k], r->jumps.size_mm[k], r->jumps.se_mm[k],
                    fabs(r->jumps.size_mm[k]) > r->jump_max_mm ? "  IMPLAUSIBLE as a display event" : "");
        }
        fprintf(f, "  geometry held-out RMSE %.4f mm with the jumps in the data, %.4f mm with them removed\n",
                r->rmse_before_mm, r->rmse_jumps_mm);
        if (r->jumps_by_calibrate)
            fprintf(f, "  (found as rcal calibrate finds them on the same inputs: its search at its fit with the prior, "
                       "and its rule)\n");
        if (r->jumps_implausible)
            fprintf(f,
                    "  %u of them larger than %.3g mm (--jump-max-mm): more than a display re-zeroed or counts lost; "
                    "look for a cable re-hooked, rows from another set-up, or an effect the model lacks\n",
                    r->jumps_implausible, r->jump_max_mm);
        if (r->jumps_at_setup_change)
            fprintf(f,
                    "  %u of them fall where the set-up changes: there a jump is confounded with anything that depends "
                    "on the set-up; revisiting set-ups in shuffled order would separate them\n",
                    r->jumps_at_setup_change);
    } else if (r->jumps_confounded) {
        fprintf(f,
                "Steps in acquisition order (%u) were found only where the set-up changes: confounded with set-up "
                "dependent effects (left to the candidates below); revisiting set-ups in shuffled order would "
                "separate them.\n",
                r->jumps_confounded);
    }
    if (r->n_chosen > 0) {
        fprintf(f, "Effects added, in order:");
        for (unsigned s = 0; s < r->n_steps; ++s)
            if (r->steps[s].chosen >= 0)
                fprintf(f, " %s", r->steps[s].cand[r->steps[s].chosen].name);
        fprintf(f, "\n(fitted on all samples, +- fold-jackknife standard error: see the verdict above)\n");
        fprintf(f, "  contribution to the measurements: %.4f mm rms\n", r->effect_rms_mm);
    }
    fprintf(f, "\nHeld-out RMSE: before %.4f mm (%.2f x floor) -> after %.4f mm (%.2f x floor); floor %.4f mm\n",
            r->rmse_before_mm, r->rmse_before_mm / r->noise_floor_mm, r->rmse_after_mm,
            r->rmse_after_mm / r->noise_floor_mm, r->noise_floor_mm);
    fprintf(f, "Remaining: %s%s%s\n", r->remaining, r->remaining_why[0] ? ": " : "", r->remaining_why);
    if (r->n_chosen > 0) {
        fprintf(f, "\nStructure of the held-out residuals after:\n");
        print_tests(f, r->after, r->n_tests);
    }
    fprintf(f, "\nWhat these data cannot identify:\n");
    for (unsigned k = 0; k < r->n_notes; ++k)
        fprintf(f, "  - %s\n", r->notes[k]);
    fprintf(f, "\nTime: %.0f ms\n", r->time_ms);
    return ferror(f) ? -1 : 0;
}

static void json_num(rch_jw *w, const char *key, double v)
{
    rch_jw_numf(w, key, v, "%.6g");
}

static void json_joint(rch_jw *w, unsigned joint)
{
    if (joint)
        rch_jw_uint(w, "joint", joint);
    else
        rch_jw_null(w, "joint");
}

static void json_tests(rch_jw *w, const char *key, const rch_diagnose_test *t, unsigned n)
{
    rch_jw_arr(w, key);
    for (unsigned k = 0; k < n; ++k) {
        rch_jw_obj(w, NULL);
        rch_jw_str(w, "variable", t[k].name);
        rch_jw_uint(w, "dof1", t[k].dof1);
        rch_jw_uint(w, "dof2", t[k].dof2);
        json_num(w, "f", t[k].f_stat);
        json_num(w, "p", t[k].p_value);
        json_num(w, "r2", t[k].r2);
        rch_jw_bool(w, "significant", t[k].significant);
        rch_jw_end(w);
    }
    rch_jw_end(w);
}

static void json_cands(rch_jw *w, const rch_diagnose_result *r)
{
    rch_jw_arr(w, "candidates");
    for (unsigned s = 0; s < r->n_steps; ++s)
        for (unsigned k = 0; k < r->steps[s].n_cand; ++k) {
            const rch_diagnose_cand *ca = &r->steps[s].cand[k];
            rch_jw_obj(w, NULL);
            rch_jw_uint(w, "step", s + 1);
            rch_jw_str(w, "effect", rc_effect_name(ca->kind));
            json_joint(w, ca->joint);
            rch_jw_uint(w, "params", ca->n_params);
            rch_jw_uint(w, "identifiable", ca->n_ident);
            rch_jw_bool(w, "tested", ca->tested);
            if (ca->tested) {
                json_num(w, "rmse_cv_mm", ca->rmse_cv_mm);
                json_num(w, "gain_mm2", ca->gain_mm2);
                json_num(w, "gain_se_mm2", ca->gain_se_mm2);
                json_num(w, "z", ca->z);
                json_num(w, "p", ca->p_value);
                if (ca->scored) {
                    json_num(w, "score_f", ca->score_f);
                    rch_jw_uint(w, "score_dof", ca->score_dof);
                    json_num(w, "score_p", ca->score_p);
                }
                rch_jw_str(w, "test", ca->scored ? "score" : "held-out");
            }
            rch_jw_bool(w, "significant", ca->significant);
            rch_jw_bool(w, "chosen", (int)k == r->steps[s].chosen);
            rch_jw_str(w, "note", ca->note);
            rch_jw_end(w);
        }
    rch_jw_end(w);
}

int rch_diagnose_json(FILE *f, const rch_diagnose_result *r, int argc, char **argv)
{
    rch_jw w;
    rch_jw_begin(&w, f, 0, "rcal-diagnose/1", argc, argv);
    rch_jw_str(&w, "effect", r->effect);
    json_joint(&w, r->joint);
    json_num(&w, "rmse_before_mm", r->rmse_before_mm);
    json_num(&w, "rmse_after_mm", r->rmse_after_mm);
    json_num(&w, "noise_floor_mm", r->noise_floor_mm);
    json_num(&w, "noise_floor_joints_mm", r->floor_joints_mm);
    json_num(&w, "noise_floor_length_mm", r->floor_len_mm);
    json_num(&w, "q_step_deg", r->q_step_deg);
    json_num(&w, "len_step_mm", r->len_step_mm);
    json_num(&w, "train_rmse_geometry_mm", r->train_rmse_geo_mm);
    rch_jw_uint(&w, "n", r->n);
    rch_jw_uint(&w, "groups", r->n_groups);
    rch_jw_uint(&w, "wrist_flicker_samples", r->n_flicker);
    rch_jw_uint(&w, "folds", r->folds);
    rch_jw_str(&w, "remaining", r->remaining);
    rch_jw_str(&w, "remaining_why", r->remaining_why);
    json_num(&w, "noise_est_mm", r->noise_est_mm);
    rch_jw_uint(&w, "poses", r->n_poses);
    rch_jw_uint(&w, "known_effects", r->n_known);
    rch_jw_arr(&w, "sensors"); /* per sensor: held-out RMS before and after (3-D for the tracker) */
    for (unsigned k = 0; k < r->n_sensors; ++k) {
        const rch_diagnose_sensor *z = &r->sensors[k];
        rch_jw_obj(&w, NULL);
        rch_jw_str(&w, "name", z->name);
        rch_jw_str(&w, "kind", z->kind);
        if (z->tracker)
            rch_jw_null(&w, "outlet");
        else
            rch_jw_uint(&w, "outlet", z->label);
        rch_jw_uint(&w, "rows", z->rows);
        json_num(&w, "before_mm", z->before_mm);
        json_num(&w, "after_mm", z->after_mm);
        json_num(&w, "floor_mm", z->floor_mm);
        rch_jw_end(&w);
    }
    rch_jw_end(&w);
    {
        char next[1400];
        if (r->in.n_data + r->in.n_positions > 0 &&
            rch_diagnose_next(next, sizeof next, r, NULL, r->in.robot_given ? r->in.robot_path : NULL) == 0)
            rch_jw_str(&w, "next", next);
        else
            rch_jw_null(&w, "next");
    }
    {
        char nu[256];
        rch_jw_arr(&w, "nuisance"); /* named and fitted by the next step, never used at a new pose */
        if (rch_diagnose_nuisance(nu, sizeof nu, r) == 0)
            for (char *p = nu, *q; *p; p = q) {
                q = strchr(p, ',');
                if (q)
                    *q++ = '\0';
                else
                    q = p + strlen(p);
                rch_jw_str(&w, NULL, p);
            }
        rch_jw_end(&w);
    }
    rch_jw_arr(&w, "length_jumps");
    for (unsigned k = 0; k < r->jumps.n_jumps; ++k) {
        rch_jw_obj(&w, NULL);
        rch_jw_uint(&w, "sample", r->jumps.at[k]);
        if (r->jump_line[k])
            rch_jw_uint(&w, "line", r->jump_line[k]);
        else
            rch_jw_null(&w, "line");
        json_num(&w, "t", r->jumps.at_t[k]);
        json_num(&w, "size_mm", r->jumps.size_mm[k]);
        json_num(&w, "se_mm", r->jumps.se_mm[k]);
        rch_jw_end(&w);
    }
    rch_jw_end(&w);
    json_num(&w, "rmse_jumps_removed_mm", r->jumps.n_jumps ? r->rmse_jumps_mm : NAN);
    rch_jw_str(&w, "jumps_found_by", r->jumps_by_calibrate ? "calibrate" : "diagnose");
    json_num(&w, "jump_max_mm", r->jump_max_mm);
    rch_jw_uint(&w, "jumps_implausible", r->jumps_implausible);
    rch_jw_arr(&w, "sequence");
    for (unsigned s = 0; s < r->n_steps; ++s)
        if (r->steps[s].chosen >= 0)
            rch_jw_str(&w, NULL, r->steps[s].cand[r->steps[s].chosen].name);
    rch_jw_end(&w);
    json_cands(&w, r);
    rch_jw_arr(&w, "params");
    for (unsigned k = 0; k < r->n_params; ++k) {
        rch_jw_obj(&w, NULL);
        rch_jw_str(&w, "name", r->params[k].name);
        json_num(&w, "value", r->params[k].value);
        json_num(&w, "se", r->params[k].se);
        rch_jw_str(&w, "unit", r->params[k].unit);
        rch_jw_end(&w);
    }
    rch_jw_end(&w);
    json_num(&w, "effect_rms_mm", r->effect_rms_mm);
    json_tests(&w, "structure_before", r->before, r->n_tests);
    json_tests(&w, "structure_after", r->after, r->n_tests);
    rch_jw_arr(&w, "not_identifiable");
    for (unsigned k = 0; k < r->n_notes; ++k)
        rch_jw_str(&w, NULL, r->notes[k]);
    rch_jw_end(&w);
    json_num(&w, "time_ms", r->time_ms);
    rch_jw_end(&w);
    return rch_jw_finish(&w);
}

/* The effects of the next step as `rcal calibrate --effects` names them,
 * into list: the known ones as given (the chain repeats them as the user
 * wrote them: a period refitted without the prior may wander), then each
 * effect the search chose that calibrate fits, nuisance (time_drift)
 * included: it is fitted with the geometry and left out at a new pose. Per
 * set-up offsets (group_offset) go by --jumps (next_jumps); tool_offset is
 * calibrate's attachment, decided by the data. */
static void chosen_effects(char *list, size_t len, const rch_diagnose_result *r)
{
    size_t pos = (size_t)snprintf(list, len, "%s", r->known_effects);
    for (unsigned s = 0; s < r->n_steps && pos < len; ++s) {
        const int c = r->steps[s].chosen;
        if (c < 0)
            continue;
        const rch_diagnose_cand *ca = &r->steps[s].cand[c];
        const rc_effect_desc *ds = rc_effect_describe(ca->kind);
        if (!ds || !ds->user || ca->kind == RC_EFF_TOOL_OFFSET)
            continue;
        if (ds->arg == RC_EFF_ARG_JOINT) {
            pos += (size_t)snprintf(list + pos, len - pos, "%s%s:%u", pos ? "," : "", ds->name, ca->joint);
        } else if (ds->arg == RC_EFF_ARG_PERIOD) {
            double per = 0.0;
            for (unsigned e = 0; e < r->final.n_effects; ++e)
                if (r->final.effects[e].kind == (uint8_t)ca->kind)
                    per = fabs(r->final.x[r->final.effects[e].first + 2]);
            pos += (size_t)snprintf(list + pos, len - pos, "%s%s:%.6g", pos ? "," : "", ds->name, per);
        } else {
            pos += (size_t)snprintf(list + pos, len - pos, "%s%s", pos ? "," : "", ds->name);
        }
    }
}

int rch_diagnose_nuisance(char *buf, size_t len, const rch_diagnose_result *r)
{
    size_t pos = 0;
    buf[0] = '\0';
    if (len == 0)
        return -1;
    if (r->jumps.n_jumps > 0)
        pos += (size_t)snprintf(buf + pos, len - pos, "length_jump");
    for (unsigned s = 0; s < r->n_steps && pos < len; ++s) {
        const int c = r->steps[s].chosen;
        const rc_effect_desc *ds = c >= 0 ? rc_effect_describe(r->steps[s].cand[c].kind) : NULL;
        if (ds && ds->nuisance)
            pos += (size_t)snprintf(buf + pos, len - pos, "%s%s", pos ? "," : "", ds->name);
    }
    return pos < len ? 0 : -1;
}

int rch_diagnose_next(char *buf, size_t len, const rch_diagnose_result *r, const char *data_path,
                      const char *robot_path)
{
    char list[512];
    chosen_effects(list, sizeof list, r);
    const char *argv[16 + 4 * RCH_DIAGNOSE_MAX_FILES + 2 * RC_MAX_TARGETS];
    int n = 0;
    argv[n++] = "rcal";
    argv[n++] = "calibrate";
    if (r->in.n_data + r->in.n_positions == 0) {
        argv[n++] = "--data";
        argv[n++] = data_path;
    }
    for (size_t k = 0; k < r->in.n_data && k < RCH_DIAGNOSE_MAX_FILES; ++k) {
        argv[n++] = "--data";
        argv[n++] = r->in.data_paths[k];
    }
    for (size_t k = 0; k < r->in.n_positions && k < RCH_DIAGNOSE_MAX_FILES; ++k) {
        argv[n++] = "--positions";
        argv[n++] = r->in.positions_paths[k];
    }
    if (robot_path) {
        argv[n++] = "--robot";
        argv[n++] = robot_path;
    }
    for (size_t k = 0; k < r->in.n_cable_points && k < RC_MAX_TARGETS; ++k) {
        argv[n++] = "--cable-point";
        argv[n++] = r->in.cable_points[k];
    }
    if (next_jumps(r))
        argv[n++] = "--jumps";
    if (r->dequant_corrected)
        argv[n++] = "--dequantize-joints";
    if (list[0]) {
        argv[n++] = "--effects";
        argv[n++] = list;
    }
    argv[n++] = "--out";
    argv[n++] = "model.json";
    rch_shell_join(buf, len, n, argv);
    return strstr(buf, " ... (cut)") ? -1 : 0;
}

int rch_diagnose_save_model(const rch_diagnose_result *r, const char *data_path, const char *robot_path,
                            const char *path, const char *const *inputs, size_t n_inputs, rch_diag *d)
{
    (void)inputs;
    (void)n_inputs; /* rch_calib_save_model refuses the data and the robot file itself */
    char list[512];
    chosen_effects(list, sizeof list, r);
    static rch_calib_result cr;
    rch_calib_cfg cfg;
    rch_calib_cfg_init(&cfg);
    cfg.data_path = data_path;
    if (r->in.n_data + r->in.n_positions > 0) { /* every input the diagnosis read */
        cfg.data_path = r->in.n_data ? r->in.data_paths[0] : NULL;
        cfg.data_paths = r->in.n_data > 1 ? r->in.data_paths : NULL;
        cfg.n_data_paths = r->in.n_data > 1 ? r->in.n_data : 0;
        cfg.positions_paths = r->in.positions_paths;
        cfg.n_positions_paths = r->in.n_positions;
    }
    cfg.robot_path = robot_path;
    if (rch_calib_cfg_cable_points(&cfg, r->in.cable_points, r->in.n_cable_points, list, sizeof list) != 0) {
        rch_diag_set(d, "", 0, 0, "%s", list); /* checked when read: not reached */
        return -1;
    }
    chosen_effects(list, sizeof list, r);
    cfg.test_fraction = 0.0;
    cfg.effects = list[0] ? list : NULL;
    cfg.jumps = next_jumps(r);
    cfg.dequantize = r->dequant_corrected > 0;
    cfg.inputs = r->raw; /* the files as the diagnosis read them, not read again */
    const int rc = rch_calib_run(&cr, &cfg, d);
    if (rc != 0)
        return -1;
    if (!cr.after_ok) {
        rch_diag_set(d, path, 0, 0, "the model with the diagnosed effects (%s) did not fit: not written",
                     list[0] ? list : "none");
        return -1;
    }
    return rch_calib_save_model(&cr, path, d);
}

int rch_diagnose_resid(rch_resid_table *t, const rch_diagnose_result *r, const unsigned *line)
{
    char chain[48] = "";
    size_t len = 0;
    for (unsigned k = 0; k < r->n_steps; ++k) {
        const int c = r->steps[k].chosen;
        if (c >= 0 && len < sizeof chain)
            len += (size_t)snprintf(chain + len, sizeof chain - len, "%s%s", len ? "+" : "", r->steps[k].cand[c].name);
    }
    (void)rch_resid_add_step(t, "geometry_cv");
    if (r->n_chosen > 0) {
        char name[64];
        snprintf(name, sizeof name, "%s_cv", chain);
        (void)rch_resid_add_step(t, name);
    }
    for (size_t i = 0; i < r->n; ++i) {
        rch_resid_row row;
        memset(&row, 0, sizeof row);
        row.line = line[i];
        row.set = RCH_RESID_TRAIN;
        row.s = r->s[i];
        if (rc_meas(&row.predicted_mm, NULL, &r->final, &r->s[i]) != RC_OK)
            row.predicted_mm = NAN;
        for (unsigned c = 0; c < RCH_RESID_MAX_STEPS; ++c)
            row.after_mm[c] = NAN;
        row.after_mm[0] = r->res_before_mm ? -r->res_before_mm[i] : NAN; /* they are model - measured */
        if (r->n_chosen > 0)
            row.after_mm[1] = r->res_after_mm ? -r->res_after_mm[i] : NAN;
        if (rch_resid_add(t, &row) != 0)
            return -1;
    }
    return 0;
}
