/* SPDX-License-Identifier: MIT */
/* rch_diagnose_in.c - the inputs of `rcal diagnose`: every file `rcal
 * calibrate` takes (cable lengths from one or several outlets, tracker
 * positions, both), merged into one sample set and one start model with
 * the sensors' frames and the effects already known; then the workflow
 * (rch_diagnose_run). See rch_diagnose.h. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "rch_diagnose_int.h"
#include "rch_calib_effects.h"
#include "rch_data.h"
#include "rch_dequant.h"
#include "rch_groups.h"
#include "rch_positions.h"
#include "rch_robot.h"

/* The cable files merged in order (as rcal calibrate merges them): samples,
 * lines, file index, x, y, z when every file has them; t the acquisition
 * order over all files; the group column kept when every file has one
 * (offset per file), else set-ups by wrist within each file (*groups_given
 * then 1). One file: as read. 0, or -1 with d set. */
static int load_cable(rch_data *out, unsigned **file_of, int *groups_given, const rch_diagnose_in *in,
                      const rc_model *limits, rch_diag *d)
{
    memset(out, 0, sizeof *out);
    *file_of = NULL;
    if (in->n_data == 0)
        return 0;
    if (in->n_data > RCH_DIAGNOSE_MAX_FILES) {
        rch_diag_set(d, "", 0, 0, "at most %d data files", RCH_DIAGNOSE_MAX_FILES);
        return -1;
    }
    rch_data part[RCH_DIAGNOSE_MAX_FILES];
    size_t total = 0;
    int all_xyz = 1, all_group = 1;
    for (size_t f = 0; f < in->n_data; ++f) {
        if (rch_data_load_limited(&part[f], in->data_paths[f], 0, limits, d) != 0) {
            for (size_t g = 0; g < f; ++g)
                rch_data_free(&part[g]);
            return -1;
        }
        total += part[f].n;
        all_xyz &= part[f].xyz != NULL;
        all_group &= part[f].has_group;
    }
    if (in->n_data == 1) {
        *out = part[0];
        *file_of = calloc(out->n ? out->n : 1, sizeof **file_of);
        *groups_given = out->has_group;
        return *file_of ? 0 : -1;
    }
    out->s = malloc(total * sizeof *out->s);
    out->line = malloc(total * sizeof *out->line);
    out->xyz = all_xyz ? malloc(total * sizeof *out->xyz) : NULL;
    *file_of = malloc(total * sizeof **file_of);
    int ok = out->s && out->line && *file_of && (!all_xyz || out->xyz);
    double *q = calloc(total * 3 + 1, sizeof *q), step = 0.0;
    for (size_t f = 0, k = 0; ok && q && f < in->n_data; ++f)
        for (size_t i = 0; i < part[f].n; ++i, ++k)
            for (unsigned j = 0; j < 3; ++j)
                q[k * 3 + j] = part[f].s[i].q_rad[3 + j] / DEG;
    if (q)
        step = rch_dequant_detect_step(q, total * 3);
    free(q);
    unsigned goff = 0;
    for (size_t f = 0, k = 0; f < in->n_data; ++f) {
        unsigned gmax = 0;
        if (ok && !all_group)
            gmax = rch_groups_by_wrist(part[f].s, part[f].n, step, NULL) - 1u;
        for (size_t i = 0; ok && i < part[f].n; ++i, ++k) {
            out->s[k] = part[f].s[i];
            out->s[k].t = total > 1 ? (double)k / (double)(total - 1) : 0.0;
            if (all_group)
                gmax = out->s[k].group > gmax ? out->s[k].group : gmax;
            out->s[k].group = (uint16_t)(goff + out->s[k].group);
            out->line[k] = part[f].line[i];
            (*file_of)[k] = (unsigned)f;
            if (all_xyz)
                memcpy(out->xyz[k], part[f].xyz[i], sizeof out->xyz[k]);
        }
        goff += gmax + 1;
        rch_data_free(&part[f]);
    }
    out->n = total;
    out->has_group = 1;
    *groups_given = 1;
    if (!ok) {
        rch_data_free(out);
        free(*file_of);
        *file_of = NULL;
        rch_diag_set(d, "", 0, 0, "out of memory");
        return -1;
    }
    return 0;
}

/* --dequantize-joints on the cable rows: set-ups from the wrist angles as
 * recorded (on the display grid) first, then the joints recovered; the rows
 * it refuses are dropped. 0, or -1 with d set. */
static int dequantize(rch_data *data, unsigned *file_of, rch_diagnose_cfg *c, rch_dequant_result *dq,
                      const rch_robot *robot, const char *name, rch_diag *d)
{
    if (!c->groups_given) {
        double *q = calloc(data->n * 3 + 1, sizeof *q);
        double step = 0.0;
        for (size_t i = 0; q && i < data->n; ++i)
            for (unsigned j = 0; j < 3; ++j)
                q[i * 3 + j] = data->s[i].q_rad[3 + j] / DEG;
        if (q)
            step = rch_dequant_detect_step(q, data->n * 3);
        free(q);
        rch_groups_by_wrist(data->s, data->n, step, NULL);
        c->groups_given = 1;
    }
    uint8_t *bad = data->xyz ? calloc(data->n + 1, 1) : NULL;
    if (!bad) {
        rch_diag_set(d, name, 0, 0, "--dequantize-joints needs the x, y, z columns");
        return -1;
    }
    rch_dequant(dq, bad, data->s, data->n, (const double(*)[3])data->xyz, &robot->nominal, 0.0);
    size_t k = 0;
    for (size_t i = 0; i < data->n; ++i)
        if (!bad[i]) {
            data->line[k] = data->line[i];
            file_of[k] = file_of[i];
            data->s[k++] = data->s[i];
        }
    data->n = k;
    free(bad);
    if (c->q_step_deg == 0.0)
        c->q_step_deg = -1.0; /* the joints are no longer on the display grid */
    return 0;
}

/* The positions files appended to the cable rows (three samples a row, one
 * set-up group a file after the cable's), the tracker frame and targets
 * added to the model. 0, or -1 with d set. */
static int append_positions(rch_data *data, unsigned **file_of, rc_model *m, rch_diagnose_cfg *c,
                            const rch_diagnose_in *in, rch_diag *d)
{
    rch_pos p;
    if (rch_pos_load(&p, in->positions_paths, in->n_positions, 0.0, m, d) != 0)
        return -1;
    if (!c->groups_given && data->n) { /* the cable's set-ups by wrist before the tracker's are numbered */
        double *q = calloc(data->n * 3 + 1, sizeof *q), step = 0.0;
        for (size_t i = 0; q && i < data->n; ++i)
            for (unsigned j = 0; j < 3; ++j)
                q[i * 3 + j] = data->s[i].q_rad[3 + j] / DEG;
        if (q)
            step = rch_dequant_detect_step(q, data->n * 3);
        free(q);
        rch_groups_by_wrist(data->s, data->n, step, NULL);
    }
    c->groups_given = 1;
    unsigned g0 = 0;
    for (size_t i = 0; i < data->n; ++i)
        g0 = data->s[i].group + 1u > g0 ? data->s[i].group + 1u : g0;
    const size_t n = data->n + p.n;
    rc_sample *s = realloc(data->s, n * sizeof *s);
    if (s)
        data->s = s;
    unsigned *ln = s ? realloc(data->line, n * sizeof *ln) : NULL;
    if (ln)
        data->line = ln;
    unsigned *fo = ln ? realloc(*file_of, n * sizeof *fo) : NULL;
    if (fo)
        *file_of = fo;
    if (!fo || rch_pos_add_effects(m, p.n_targets) != 0) {
        rch_diag_set(d, "", 0, 0,
                     fo ? "no room for the tracker frame and %u targets (RC_MAX_EFFECTS %d, RC_MAX_PARAMS %d)"
                        : "out of memory",
                     p.n_targets, RC_MAX_EFFECTS, RC_MAX_PARAMS);
        rch_pos_free(&p);
        return -1;
    }
    for (size_t i = 0; i < p.n; ++i) {
        data->s[data->n + i] = p.s[i];
        data->s[data->n + i].group = (uint16_t)(g0 + p.file[i]);
        data->line[data->n + i] = p.line[i];
        fo[data->n + i] = (unsigned)in->n_data + p.file[i];
    }
    data->n = n;
    free(data->xyz);
    data->xyz = NULL;
    rch_pos_free(&p);
    return 0;
}

/* The start model: the nominal geometry (the robot file's own effects
 * left out, as before), an RC_EFF_OUTLET per further outlet, then the
 * effects already known. 0, or -1 with d set. */
static int start_model(rc_model *m, rch_diagnose_result *out, rch_data *data, const rch_robot *robot, rch_diag *d)
{
    *m = robot->nominal;
    m->n_effects = 0;
    m->n_params = RC_N_BASE;
    const int no = rch_data_outlets(out->outlet_label, data->s, data->n, d);
    if (no < 0)
        return -1;
    for (unsigned k = 1; k < (unsigned)no; ++k)
        if (rc_model_add_effect(m, RC_EFF_OUTLET, k, 0) != RC_OK) {
            rch_diag_set(d, "", 0, 0, "cannot add outlet %u (RC_MAX_EFFECTS %d, RC_MAX_PARAMS %d)", k,
                         RC_MAX_EFFECTS, RC_MAX_PARAMS);
            return -1;
        }
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
    rch_robot robot;
    rch_data data;
    unsigned *file_of = NULL;
    rch_diagnose_cfg c = *cfg;
    rc_model m;
    if (rch_robot_load(&robot, in->robot_path, d) != 0)
        return -1;
    if (load_cable(&data, &file_of, &c.groups_given, in, &robot.model, d) != 0)
        return -1;
    c.have_encoder = robot.has_encoder;
    c.keep_effects = 1;
    rch_dequant_result dq;
    memset(&dq, 0, sizeof dq);
    int rc = -1;
    if (cfg->dequantize && data.n &&
        dequantize(&data, file_of, &c, &dq, &robot, in->n_data ? in->data_paths[0] : "", d) != 0)
        goto done;
    if (start_model(&m, out, &data, &robot, d) != 0)
        goto done;
    if (in->n_positions && append_positions(&data, &file_of, &m, &c, in, d) != 0)
        goto done;
    if (in->effects && rch_calib_effects(&m, in->effects, d) != 0)
        goto done;
    if (data.n > 100000)
        fprintf(stderr, "rcal diagnose: %zu samples, %u folds: this takes minutes\n", data.n, c.folds ? c.folds : 5u);
    uint8_t labels[RC_MAX_OUTLETS];
    memcpy(labels, out->outlet_label, sizeof labels);
    rc = rch_diagnose_run(out, data.s, data.n, &m, &c, d);
    memcpy(out->outlet_label, labels, sizeof labels);
    out->in = *in;
    out->dequant_corrected = dq.n_corrected;
    out->dequant_refused = dq.n_refused;
    for (unsigned k = 0; k < out->n_sensors; ++k) /* the outlets by the files' labels */
        if (!out->sensors[k].tracker) {
            out->sensors[k].label = out->outlet_label[out->sensors[k].label];
            if (strcmp(out->sensors[k].name, "cable") != 0)
                snprintf(out->sensors[k].name, sizeof out->sensors[k].name, "cable outlet %u", out->sensors[k].label);
        }
    out->line = malloc((data.n ? data.n : 1) * sizeof *out->line);
    out->file = malloc((data.n ? data.n : 1) * sizeof *out->file);
    if (out->line && out->file) {
        memcpy(out->line, data.line, data.n * sizeof *out->line);
        memcpy(out->file, file_of, data.n * sizeof *out->file);
    }
    for (unsigned k = 0; rc == 0 && k < out->jumps.n_jumps; ++k)
        for (size_t i = 0; i < data.n; ++i)
            if (data.s[i].t == out->jumps.at_t[k]) {
                out->jump_line[k] = data.line[i];
                break;
            }
done:
    free(file_of);
    rch_data_free(&data);
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
