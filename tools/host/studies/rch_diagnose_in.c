/* SPDX-License-Identifier: MIT */
/* rch_diagnose_in.c - the inputs of `rcal diagnose`: every file `rcal
 * calibrate` takes (cable lengths from one or several outlets, tracker
 * positions, both), read by calibrate's one reader (rch_inputs_load), made
 * into one start model with the sensors' frames and the effects already
 * known; then the workflow (rch_diagnose_run). See rch_diagnose.h.
 * Each file is opened once: the inputs read (raw) are kept in the result for
 * every later stage (rch_calib_cfg.inputs).
 * Depends on: rch_inputs, rch_calib_effects. Memory: the result's line and
 * file arrays and the inputs read (rch_diagnose_free). Errors: -1 with d set. */
#include <stdlib.h>
#include <string.h>

#include "rch_calib.h"
#include "rch_calib_effects.h"
#include "rch_diagnose_int.h"
#include "rch_inputs.h"

/* The start model: the nominal geometry (the robot file's own effects left
 * out, as always), the outlets, the cable points and the tracker frame and
 * targets that the reader added to the robot's model (with their values), then the effects
 * already known. 0, or -1 with d set. */
static int start_model(rc_model *m, const rch_inputs *in, const char *effects, rch_diag *d)
{
    *m = in->robot.nominal;
    m->n_effects = 0;
    m->n_params = RC_N_BASE;
    const rc_model *src = &in->robot.model;
    for (unsigned e = 0; e < src->n_effects; ++e) {
        const rc_effect *ef = &src->effects[e];
        const rc_effect_desc *ds = rc_effect_describe(ef->kind);
        if (!ds || (ds->side != RC_SIDE_OUTLET && ds->side != RC_SIDE_SENSOR && ef->kind != RC_EFF_CABLE_POINTS))
            continue;
        if (rc_model_add_effect(m, (rc_effect_kind)ef->kind, ef->joint, ef->count) != RC_OK) {
            rch_diag_set(d, "", 0, 0, "no room for the %s effect (RC_MAX_EFFECTS %d, RC_MAX_PARAMS %d)",
                         rc_effect_name((rc_effect_kind)ef->kind), RC_MAX_EFFECTS, RC_MAX_PARAMS);
            return -1;
        }
        memcpy(&m->x[m->effects[m->n_effects - 1].first], &src->x[ef->first], ef->count * sizeof m->x[0]);
    }
    return effects ? rch_calib_effects(m, effects, d) : 0;
}

/* Whether the file has length jumps, as rcal calibrate decides it on the
 * same inputs (cc: the files, the robot, the effects known, --jumps; its
 * default test fraction and seed: the run the next step makes): its one
 * jump search (rch_jumps) at its MAP fit with the physical prior, its rule
 * (a step 8 x the residual, or every change point with --jumps). The
 * change points and the segments' offsets into c (jumps_given). A search
 * without the prior could trade a step near either end of the file for a
 * common length offset, which the geometry nearly absorbs: that gave jumps
 * of hundreds of millimetres. 0, or -1 when calibrate fails (c unchanged:
 * the diagnosis searches on its own). */
static int calibrate_jumps(rch_diagnose_cfg *c, const rch_calib_cfg *cc_in, const char *effects, int jumps)
{
    rch_calib_cfg cc = *cc_in;
    cc.effects = effects;
    cc.jumps = jumps;
    rch_calib_result *cr = malloc(sizeof *cr);
    rch_diag d;
    if (!cr)
        return -1;
    if (rch_calib_run(cr, &cc, &d) != 0 || !cr->after_ok) {
        free(cr);
        return -1;
    }
    c->jumps_given = 1;
    c->n_given_jumps = 0;
    memset(c->given_offset_mm, 0, sizeof c->given_offset_mm);
    if (cr->have_jumps && cr->jumps.n_jumps > 0) {
        const rch_jumps *j = &cr->jumps;
        const rc_effect *e = &j->model.effects[j->model.n_effects - 1];
        c->n_given_jumps = j->n_jumps;
        for (unsigned k = 0; k < j->n_jumps; ++k) {
            c->given_jump_t[k] = j->at_t[k];
            c->given_jump_mm[k] = j->size_mm[k];
            c->given_jump_se_mm[k] = j->se_mm[k];
        }
        for (unsigned k = 0; k <= j->n_jumps && k < e->count; ++k)
            c->given_offset_mm[k] = j->model.x[e->first + k];
    }
    free(cr);
    return 0;
}

int rch_diagnose_inputs(rch_diagnose_result *out, const rch_diagnose_in *in, const rch_diagnose_cfg *cfg,
                        rch_diag *d)
{
    memset(out, 0, sizeof *out);
    if (in->n_data + in->n_positions == 0) {
        rch_diag_set(d, "", 0, 0, "no data: give --data or --positions");
        return -1;
    }
    if (in->n_data > RCH_CALIB_MAX_FILES || in->n_positions > RCH_CALIB_MAX_FILES) {
        rch_diag_set(d, "", 0, 0, "at most %d data files and %d positions files", RCH_CALIB_MAX_FILES,
                     RCH_CALIB_MAX_FILES);
        return -1;
    }
    rch_calib_cfg cc; /* the inputs as calibrate reads them */
    rch_calib_cfg_init(&cc);
    cc.data_path = in->n_data ? in->data_paths[0] : NULL;
    cc.data_paths = in->n_data > 1 ? in->data_paths : NULL;
    cc.n_data_paths = in->n_data > 1 ? in->n_data : 0;
    cc.positions_paths = in->positions_paths;
    cc.n_positions_paths = in->n_positions;
    cc.robot_path = in->robot_path;
    char perr[160];
    if (rch_calib_cfg_cable_points(&cc, in->cable_points, in->n_cable_points, perr, sizeof perr) != 0) {
        rch_diag_set(d, "", 0, 0, "%s", perr);
        return -1;
    }
    /* every file read once, the joints as read and the poses kept (raw): the diagnosis, the jumps' calibration,
     * the next step's model and --report's calibration each take their copy of it (rch_calib_cfg.inputs) */
    rch_inputs *raw = calloc(1, sizeof *raw), *data = calloc(1, sizeof *data);
    if (!raw || !data) {
        free(raw);
        free(data);
        rch_diag_set(d, "", 0, 0, "out of memory");
        return -1;
    }
    cc.no_dequantize = 1;
    cc.keep_poses = 1;
    if (rch_inputs_load(raw, &cc, d) != 0) {
        free(raw);
        free(data);
        return -1;
    }
    cc.inputs = raw;
    cc.keep_poses = 0;
    cc.dequantize = cfg->dequantize;
    cc.no_dequantize = !cfg->dequantize; /* diagnose dequantizes only when told (calibrate's hint tells it) */
    if (rch_inputs_load(data, &cc, d) != 0) {
        rch_inputs_free(raw);
        free(raw);
        free(data);
        return -1;
    }
    rch_diagnose_cfg c = *cfg;
    /* One cable file as read (no group column, not dequantized): the set-ups by wrist are the workflow's
     * own (rch_groups_by_wrist at the detected joint step, the readings that flicker by one step counted);
     * otherwise the reader's: never across two files, the tracker's a file each. */
    c.groups_given = data->groups_from_file || in->n_data > 1 || in->n_positions > 0 || cfg->dequantize;
    c.have_encoder = data->robot.has_encoder;
    c.keep_effects = 1;
    if (cfg->dequantize && c.q_step_deg == 0.0)
        c.q_step_deg = -1.0; /* the joints are no longer on the display grid */
    /* the jumps: calibrate's, where it looks for them (one outlet, no tracker; several outlets with --jumps) */
    if (!cfg->no_jumps && !cfg->jumps_given && in->n_positions == 0 && (data->n_outlets <= 1 || cfg->jumps)) {
        rch_calib_cfg cj = cc;
        cj.no_dequantize = 0; /* as the next step runs it: calibrate dequantizes by itself where it can */
        (void)calibrate_jumps(&c, &cj, in->effects, cfg->jumps);
    }
    rc_model m;
    int rc = start_model(&m, data, in->effects, d);
    const size_t n = data->data.n;
    if (rc == 0 && n > 100000)
        fprintf(stderr, "rcal diagnose: %zu samples, %u folds: this takes minutes\n", n, c.folds ? c.folds : 5u);
    if (rc == 0)
        rc = rch_diagnose_run(out, data->data.s, n, &m, &c, d);
    memcpy(out->outlet_label, data->outlet_label, sizeof out->outlet_label);
    out->in = *in;
    snprintf(out->known_effects, sizeof out->known_effects, "%s", in->effects ? in->effects : "");
    out->dequant_corrected = data->dequant.n_corrected;
    out->dequant_refused = data->dequant.n_refused;
    for (unsigned k = 0; k < out->n_sensors; ++k) /* the outlets by the files' labels */
        if (!out->sensors[k].tracker) {
            out->sensors[k].label = out->outlet_label[out->sensors[k].label];
            if (strcmp(out->sensors[k].name, "cable") != 0)
                snprintf(out->sensors[k].name, sizeof out->sensors[k].name, "cable outlet %u", out->sensors[k].label);
        }
    out->line = malloc((n ? n : 1) * sizeof *out->line);
    out->file = malloc((n ? n : 1) * sizeof *out->file);
    if (out->line && out->file) {
        memcpy(out->line, data->data.line, n * sizeof *out->line);
        memcpy(out->file, data->file_of, n * sizeof *out->file);
    }
    for (unsigned k = 0; rc == 0 && k < out->jumps.n_jumps; ++k)
        for (size_t i = 0; i < n; ++i)
            if (data->data.s[i].t == out->jumps.at_t[k]) {
                out->jump_line[k] = data->data.line[i];
                break;
            }
    out->raw = raw;
    out->n_read = data->n_read;
    rch_inputs_free(data);
    free(data);
    return rc;
}

int rch_diagnose_file(rch_diagnose_result *out, const char *data_path, const char *robot_path,
                      const rch_diagnose_cfg *cfg, rch_diag *d)
{
    const char *paths[1] = {data_path};
    rch_diagnose_in in;
    memset(&in, 0, sizeof in);
    in.data_paths = paths;
    in.n_data = 1;
    in.robot_path = robot_path;
    const int rc = rch_diagnose_inputs(out, &in, cfg, d);
    memset(&out->in, 0, sizeof out->in); /* paths was ours */
    return rc;
}
