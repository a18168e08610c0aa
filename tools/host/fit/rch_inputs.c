/* SPDX-License-Identifier: MIT */
/* rch_inputs.c - a calibration's inputs read, merged and checked in the
 * order of rch_inputs.h. */
#include "rch_inputs.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "rc_version.h"
#include "rch_file.h"
#include "rch_groups.h"
#include "rch_positions.h"
#include "rch_sensors.h"
#include "rch_sha256.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif
#define DEG (M_PI / 180.0)

/* One cable file read once: parsed (joints within limits, the lengths'
 * scale checked as rch_data_load_limited does) and its digest (sha, 65)
 * taken from the same bytes. 0, or -1 with d set. */
static int load_one(rch_data *out, const char *path, const char *text, size_t text_len, const rc_model *limits,
                    char *sha, rch_diag *d)
{
    char *buf = NULL;
    size_t len = 0;
    memset(out, 0, sizeof *out);
    if (text) { /* rows in memory (rch_calib_cfg.data_text): parsed as a file's, named path */
        if (!(buf = malloc(text_len + 1))) {
            rch_diag_set(d, path, 0, 0, "out of memory");
            return -1;
        }
        memcpy(buf, text, text_len);
        buf[len = text_len] = '\0';
    } else if (rch_read_file(&buf, &len, path, RCH_DATA_MAX_BYTES, d) != 0)
        return -1;
    rch_sha256 c;
    rch_sha256_init(&c);
    rch_sha256_update(&c, buf, len);
    rch_sha256_final(&c, sha);
    const rch_sensor_desc *sd = rch_sensor_for_file(buf, len); /* another sensor's file, by its header */
    int rc = sd ? rch_sensor_parse(out, sd, buf, len, path, limits, d)
                : rch_data_parse_limited(out, buf, len, path, 0, limits, d);
    free(buf);
    if (rc == 0 && !sd && limits && rch_data_check_scale(out, path, limits, d) != 0) {
        rch_data_free(out);
        rc = -1;
    }
    return rc;
}

/* Load every data file and merge them in the order given: samples, x, y, z
 * (kept only when every file has them), source lines; t becomes the
 * acquisition order over all files; the group column is kept only when
 * every file has one (numbers offset per file). counts (files): samples
 * of each. */
static int load_all(rch_data *out, size_t *counts, char (*sha)[65], const rch_calib_cfg *cfg, const rc_model *limits,
                    rch_diag *d)
{
    const size_t nf = rch_calib_cfg_n_files(cfg);
    memset(out, 0, sizeof *out);
    if (nf > RCH_CALIB_MAX_FILES) {
        rch_diag_set(d, "", 0, 0, "at most %d data files", RCH_CALIB_MAX_FILES);
        return -1;
    }
    if (nf == 0)
        return 0; /* tracker positions only (append_positions) */
    if (nf == 1) {
        int rc = load_one(out, rch_calib_cfg_file(cfg, 0), cfg->data_text, cfg->data_text_len, limits, sha[0], d);
        counts[0] = out->n;
        if (rc == 0 && rch_data_check_units(out, rch_calib_cfg_file(cfg, 0), d) != 0) {
            rch_data_free(out);
            return -1;
        }
        return rc;
    }
    rch_data part[RCH_CALIB_MAX_FILES];
    size_t total = 0, k = 0;
    int all_xyz = 1, all_group = 1;
    for (size_t f = 0; f < nf; ++f) {
        if (load_one(&part[f], rch_calib_cfg_file(cfg, f), NULL, 0, limits, sha[f], d) != 0 ||
            rch_data_check_units(&part[f], rch_calib_cfg_file(cfg, f), d) != 0) {
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

/* Set-up groups: the file's group column, else consecutive samples sharing
 * the wrist joints at the joints' display step, never across two files. */
static void groups(rch_inputs *in, const rch_calib_cfg *cfg)
{
    rch_data *data = &in->data;
    const size_t *counts = in->counts;
    in->groups_from_file = data->has_group;
    if (data->has_group) {
        unsigned mx = 0;
        for (size_t i = 0; i < data->n; ++i)
            mx = data->s[i].group > mx ? data->s[i].group : mx;
        in->n_groups = mx + 1;
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
    in->n_groups = 0;
    for (size_t f = 0, at = 0; f < rch_calib_cfg_n_files(cfg); at += counts[f], ++f) {
        unsigned g = rch_groups_by_wrist(data->s + at, counts[f], step, NULL);
        for (size_t i = at; i < at + counts[f]; ++i)
            data->s[i].group = (uint16_t)(data->s[i].group + in->n_groups);
        in->n_groups += g;
    }
}

/* Provenance: the data files, their samples and digests, the date, the tool. */
static void provenance(rch_inputs *in, const rch_calib_cfg *cfg)
{
    rch_provenance *p = &in->prov;
    const size_t *counts = in->counts;
    p->n_files = (unsigned)rch_calib_cfg_n_files(cfg);
    for (unsigned f = 0; f < p->n_files; ++f) {
        p->file[f] = rch_calib_cfg_file(cfg, f);
        p->samples[f] = counts[f]; /* (its digest: load_one, from the bytes read) */
    }
    time_t now = time(NULL);
    struct tm tmv;
    if (gmtime_r(&now, &tmv))
        strftime(p->date, sizeof p->date, "%Y-%m-%dT%H:%M:%SZ", &tmv);
    p->tool = "rcal " RC_VERSION_STRING;
}

/* With cfg->keep_poses: the joints of n rows (stride: samples a row) of
 * provenance file f appended to in->read_q. 0, or -1 with d set. */
static int keep_poses(rch_inputs *in, unsigned f, const rc_sample *s, size_t n, size_t stride, rch_diag *d)
{
    size_t have = 0;
    for (unsigned g = 0; g < f; ++g)
        have += in->read_n[g];
    double(*q)[RC_NJ] = realloc(in->read_q, (have + n + 1) * sizeof *q);
    if (!q) {
        rch_diag_set(d, "", 0, 0, "out of memory");
        return -1;
    }
    in->read_q = q;
    for (size_t i = 0; i < n; ++i)
        memcpy(q[have + i], s[i * stride].q_rad, sizeof *q);
    in->read_n[f] = n;
    return 0;
}

/* The tracker positions files (cfg.positions_paths) appended to data: three
 * samples a row (rch_positions.h), one set-up group a file, the tracker
 * frame and targets added to the model. 0, or -1 with d set. */
static int append_positions(rch_inputs *in, const rch_calib_cfg *cfg, rch_diag *d)
{
    rch_data *data = &in->data;
    if (cfg->cases > 1 || cfg->residuals_path || cfg->dequantize || cfg->jumps) {
        rch_diag_set(d, "", 0, 0,
                     "--positions is not yet combined with --cases, --residuals, --dequantize-joints or --jumps");
        return -1;
    }
    rch_pos p;
    if (rch_pos_load(&p, cfg->positions_paths, cfg->n_positions_paths, 0.0, &in->robot.model, d) != 0)
        return -1;
    if (rch_pos_targets_whole(&p, cfg->positions_paths, d) != 0) {
        rch_pos_free(&p);
        return -1;
    }
    rc_sample *s = realloc(data->s, (data->n + p.n) * sizeof *s);
    if (s)
        data->s = s;
    unsigned *ln = s ? realloc(data->line, (data->n + p.n) * sizeof *ln) : NULL;
    if (ln)
        data->line = ln;
    unsigned *fo = ln ? realloc(in->file_of, (data->n + p.n ? data->n + p.n : 1) * sizeof *fo) : NULL;
    if (fo)
        in->file_of = fo;
    if (!fo || rch_pos_add_effects(&in->robot.model, p.n_targets) != 0 ||
        (cfg->have_tracker_start && rch_pos_set_frame(&in->robot.model, cfg->tracker_start) != 0)) {
        rch_diag_set(d, "", 0, 0, fo ? "no room for the tracker frame and %u targets (RC_MAX_EFFECTS, RC_MAX_PARAMS)"
                                     : "out of memory", p.n_targets);
        rch_pos_free(&p);
        return -1;
    }
    for (size_t i = 0; i < p.n; ++i) {
        data->s[data->n + i] = p.s[i];
        data->s[data->n + i].group = (uint16_t)(in->n_groups + p.file[i]);
        data->line[data->n + i] = p.line[i];
        in->file_of[data->n + i] = (unsigned)(in->n_files + p.file[i]);
    }
    data->n += p.n;
    free(data->xyz); /* the length files' x, y, z (only --dequantize-joints reads them) */
    data->xyz = NULL;
    /* a sensor file's own pose and sigma columns (read into its samples when parsed) are not the appended
     * rows': every array left holds data->n entries (rch_inputs_copy copies n of each) */
    free(data->pose);
    data->pose = NULL;
    free(data->sigma_mm);
    data->sigma_mm = NULL;
    in->n_groups += (unsigned)cfg->n_positions_paths;
    in->n_pos_rows = p.rows;
    in->n_pos_poses = p.poses;
    in->n_targets = p.n_targets;
    in->pos_has_sigma = p.has_sigma;
    in->pos_sigma_mm = p.sigma_mm;
    rch_provenance *pv = &in->prov;
    for (size_t f = 0; f < cfg->n_positions_paths && pv->n_files < RCH_PROV_MAX_FILES; ++f) {
        size_t c = 0;
        for (size_t i = 0; i < p.n; ++i)
            c += p.file[i] == f;
        pv->file[pv->n_files] = cfg->positions_paths[f];
        pv->samples[pv->n_files] = c;
        if (f < RCH_POS_MAX_FILES) /* the digest of the bytes rch_pos_load read */
            memcpy(pv->sha256[pv->n_files], p.sha256[f], sizeof pv->sha256[0]);
        else
            snprintf(pv->sha256[pv->n_files], sizeof pv->sha256[0], "unknown");
        if (cfg->keep_poses) { /* the file's rows: three samples each, in file order */
            size_t first = 0;
            while (first < p.n && p.file[first] != f)
                ++first;
            if (keep_poses(in, pv->n_files, p.s + first, c / 3, 3, d) != 0) {
                rch_pos_free(&p);
                return -1;
            }
        }
        pv->n_files++;
    }
    rch_pos_free(&p);
    return 0;
}

/* The automatic rule: the joints sit on a display step of 0.01 deg or
 * coarser, x, y, z miss the nominal FK of the rounded joints by more than
 * 0.02 mm RMS (they were computed from finer angles), at most 5 % of the rows
 * need more than the rounding (rch_dequant refuses them) and the corrected
 * joints reproduce x, y, z at least 4 times closer. 1: apply; 0: keep the
 * joints as read; the reason in res->why either way. */
static int auto_rule(rch_dequant_result *res, const rch_data *data)
{
    const rch_dequant_result *q = res;
    if (q->q_step_deg < 0.01) {
        snprintf(res->why, sizeof res->why, "joints kept as read: they sit on no display step of 0.01 deg or coarser");
        return 0;
    }
    if (q->n_refused * 20 > data->n) {
        snprintf(res->why, sizeof res->why,
                 "joints kept as read: %zu of %zu rows' x, y, z are not the nominal FK of angles within the "
                 "rounding (not the controller's own FK)", q->n_refused, data->n);
        return 0;
    }
    if (!(q->fk_rms_before_mm > 0.02) || !(q->fk_rms_after_mm * 4.0 < q->fk_rms_before_mm)) {
        snprintf(res->why, sizeof res->why,
                 "joints kept as read: x, y, z agree with the rounded joints already (|FK - xyz| %.4f mm RMS)",
                 q->fk_rms_before_mm);
        return 0;
    }
    snprintf(res->why, sizeof res->why,
             "automatic: the joints sit on a %g deg step and x, y, z are the nominal FK of finer angles"
             "; --no-dequantize-joints keeps them as read", q->q_step_deg);
    return 1;
}

/* Joint angles from the file's x, y, z; inconsistent rows dropped (and from
 * file_of). cfg->dequantize forces it (refused without x, y, z); otherwise
 * auto_rule decides, and a file without x, y, z keeps its joints. */
static int dequantize(rch_inputs *in, const rch_calib_cfg *cfg, rch_diag *d)
{
    rch_data *data = &in->data;
    unsigned *file_of = in->file_of;
    if (!data->xyz) {
        if (!cfg->dequantize)
            return 0;
        rch_diag_set(d, cfg->data_path, 0, 0, "--dequantize-joints needs the x, y, z columns");
        return -1;
    }
    uint8_t *bad = calloc(data->n + 1, 1);
    rc_sample *keep = cfg->dequantize ? NULL : malloc((data->n ? data->n : 1) * sizeof *keep);
    double *qd = cfg->dequantize ? NULL : malloc((data->n ? data->n : 1) * RC_NJ * sizeof *qd);
    if (!bad || (!cfg->dequantize && (!keep || !qd))) {
        free(bad);
        free(keep);
        free(qd);
        rch_diag_set(d, "", 0, 0, "out of memory");
        return -1;
    }
    double step = 0.0;
    if (!cfg->dequantize) {
        memcpy(keep, data->s, data->n * sizeof *keep);
        for (size_t i = 0; i < data->n; ++i)
            for (unsigned j = 0; j < RC_NJ; ++j)
                qd[i * RC_NJ + j] = data->s[i].q_rad[j] / DEG;
        step = rch_dequant_detect_step(qd, data->n * RC_NJ);
    }
    rch_dequant(&in->dequant, bad, data->s, data->n, (const double(*)[3])data->xyz, &in->robot.nominal, 0.0);
    in->dequant.q_step_deg = step;
    in->dequant.automatic = !cfg->dequantize;
    if (!cfg->dequantize && !auto_rule(&in->dequant, data)) {
        memcpy(data->s, keep, data->n * sizeof *keep); /* the joints as read */
        free(bad);
        free(keep);
        free(qd);
        return 0;
    }
    free(keep);
    free(qd);
    size_t k = 0;
    unsigned nr = 0;
    for (size_t i = 0; i < data->n; ++i) {
        if (bad[i]) {
            if (nr < 16)
                in->dequant_refused_lines[nr++] = data->line[i];
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
    in->have_dequant = 1;
    return 0;
}

/* The outlets numbered 0, 1, ... (rch_data_outlets); an outlet effect for
 * each after the first. */
static int outlets(rch_inputs *in, rch_diag *d)
{
    const int no = rch_data_outlets(in->outlet_label, in->data.s, in->data.n, d);
    if (no < 0)
        return -1;
    in->n_outlets = (unsigned)no;
    for (unsigned k = 1; k < in->n_outlets; ++k)
        if (rc_model_add_effect(&in->robot.model, RC_EFF_OUTLET, k, 0) != RC_OK) {
            rch_diag_set(d, "", 0, 0, "cannot add outlet %u (RC_MAX_PARAMS or RC_MAX_EFFECTS)", k);
            return -1;
        }
    return 0;
}

/* The cable's points (the data's target column on length rows) against
 * --cable-point: a point named must be given, and given points must be
 * used; the points (RC_EFF_CABLE_POINTS at their drawing) into the robot's
 * model. 0, or -1 with d naming the file and line. */
static int cable_points(rch_inputs *in, const rch_calib_cfg *cfg, rch_diag *d)
{
    const rch_data *data = &in->data;
    unsigned used = 0;
    for (size_t i = 0; i < data->n; ++i) {
        const rc_sample *s = &data->s[i];
        if (s->sensor != RC_SENSOR_LENGTH)
            continue;
        const unsigned fi = in->file_of ? in->file_of[i] : 0;
        const char *file = fi < in->n_files && cfg->data_paths ? cfg->data_paths[fi] : cfg->data_path ? cfg->data_path : "";
        if (s->target > 0 && cfg->n_cable_points == 0) {
            rch_diag_set(d, file, data->line ? data->line[i] : 0, 0,
                         "the cable is on point %u of the tool (the target column), but the points' places are not "
                         "given: --cable-point X,Y,Z for each (nominal, flange frame, mm, in target order)",
                         (unsigned)s->target);
            return -1;
        }
        if (cfg->n_cable_points > 0 && s->target >= cfg->n_cable_points) {
            rch_diag_set(d, file, data->line ? data->line[i] : 0, 0,
                         "the cable is on point %u of the tool, but --cable-point gives %u (points 0..%u)",
                         (unsigned)s->target, cfg->n_cable_points, cfg->n_cable_points - 1);
            return -1;
        }
        used |= 1u << (s->target < 31 ? s->target : 31);
    }
    if (cfg->n_cable_points > 0 && used != (1u << cfg->n_cable_points) - 1u) {
        rch_diag_set(d, "", 0, 0,
                     "--cable-point gives %u points but the cable files do not use every one of them (their target "
                     "column: 0..%u, each at least once)",
                     cfg->n_cable_points, cfg->n_cable_points - 1);
        return -1;
    }
    if (cfg->n_cable_points == 0)
        return 0;
    rc_model *m = &in->robot.model;
    if (rc_model_add_effect(m, RC_EFF_CABLE_POINTS, 0, 3u * cfg->n_cable_points) != RC_OK) {
        rch_diag_set(d, "", 0, 0, "cannot add %u cable points (RC_MAX_PARAMS or RC_MAX_EFFECTS)", cfg->n_cable_points);
        return -1;
    }
    const unsigned f = m->effects[m->n_effects - 1].first;
    for (unsigned k = 0; k < cfg->n_cable_points; ++k)
        for (unsigned c = 0; c < 3; ++c)
            m->x[f + 3 * k + c] = cfg->cable_points_mm[k][c];
    return 0;
}

/* a copy of n elements of size each of src into *dst (NULL stays NULL). 0, or -1 out of memory. */
static int dup_array(void *dst, const void *src, size_t n, size_t size)
{
    void **out = dst;
    *out = NULL;
    if (!src)
        return 0;
    if (!(*out = malloc((n ? n : 1) * size)))
        return -1;
    memcpy(*out, src, n * size);
    return 0;
}

static int dup_data(rch_data *out, const rch_data *src)
{
    *out = *src;
    out->s = NULL;
    out->xyz = NULL;
    out->line = NULL;
    out->pose = NULL;
    out->sigma_mm = NULL;
    return dup_array(&out->s, src->s, src->n, sizeof *src->s) | dup_array(&out->xyz, src->xyz, src->n, sizeof *src->xyz) |
           dup_array(&out->line, src->line, src->n, sizeof *src->line) |
           dup_array(&out->pose, src->pose, src->n, sizeof *src->pose) |
           dup_array(&out->sigma_mm, src->sigma_mm, src->n, sizeof *src->sigma_mm);
}

int rch_inputs_copy(rch_inputs *out, const rch_inputs *raw, const rch_calib_cfg *cfg, rch_diag *d)
{
    if (cfg->n_positions_paths && (cfg->cases > 1 || cfg->residuals_path || cfg->dequantize || cfg->jumps)) {
        memset(out, 0, sizeof *out); /* append_positions' refusal */
        rch_diag_set(d, "", 0, 0,
                     "--positions is not yet combined with --cases, --residuals, --dequantize-joints or --jumps");
        return -1;
    }
    *out = *raw;
    out->file_of = NULL;
    out->read_q = NULL;
    memset(&out->data, 0, sizeof out->data);
    memset(&out->validate, 0, sizeof out->validate);
    size_t n_q = 0;
    for (unsigned f = 0; f < RCH_PROV_MAX_FILES; ++f)
        n_q += raw->read_n[f];
    if (!cfg->keep_poses)
        memset(out->read_n, 0, sizeof out->read_n);
    if ((dup_data(&out->data, &raw->data) | dup_data(&out->validate, &raw->validate) |
         dup_array(&out->file_of, raw->file_of, raw->data.n, sizeof *raw->file_of) |
         (cfg->keep_poses ? dup_array(&out->read_q, raw->read_q, n_q, sizeof *raw->read_q) : 0)) != 0) {
        rch_diag_set(d, "", 0, 0, "out of memory");
        rch_inputs_free(out);
        return -1;
    }
    if (!cfg->no_dequantize && dequantize(out, cfg, d) != 0) {
        rch_inputs_free(out);
        return -1;
    }
    return 0;
}

int rch_inputs_load(rch_inputs *out, const rch_calib_cfg *cfg, rch_diag *d)
{
    if (cfg->inputs)
        return rch_inputs_copy(out, cfg->inputs, cfg, d);
    memset(out, 0, sizeof *out);
    out->n_files = rch_calib_cfg_n_files(cfg);
    if (rch_robot_load(&out->robot, cfg->robot_path, d) != 0)
        return -1;
    if (load_all(&out->data, out->counts, out->prov.sha256, cfg, &out->robot.model, d) != 0) {
        memset(&out->data, 0, sizeof out->data); /* (joints within the robot's limits) the readers keep nothing */
        return -1;
    }
    /* the cable files' rows as parsed (a sensor file's none: its rows are no pose of the report's figures) */
    for (size_t f = 0, i = 0; cfg->keep_poses && f < out->n_files && f < RCH_PROV_MAX_FILES; i += out->counts[f++]) {
        const size_t n = out->counts[f];
        /* NOLINTNEXTLINE(clang-analyzer-core.UndefinedBinaryOperatorResult): load_all filled s[0, data.n) */
        const int cable = n > 0 && i < out->data.n && out->data.s[i].sensor == RC_SENSOR_LENGTH;
        if (keep_poses(out, (unsigned)f, out->data.s + i, cable ? n : 0, 1, d) != 0) {
            rch_inputs_free(out);
            return -1;
        }
    }
    /* the validation file, read here once (within the robot's limits); only a fitted model reads its rows */
    if (cfg->validate_path && rch_data_load_limited(&out->validate, cfg->validate_path, 0, &out->robot.model, d) != 0) {
        memset(&out->validate, 0, sizeof out->validate);
        rch_data_free(&out->data);
        return -1;
    }
    groups(out, cfg);
    provenance(out, cfg);
    out->file_of = malloc((out->data.n ? out->data.n : 1) * sizeof *out->file_of);
    if (!out->file_of) {
        rch_diag_set(d, "", 0, 0, "out of memory");
        goto fail;
    }
    for (size_t f = 0, i = 0; f < out->n_files; ++f)
        for (size_t k = 0; k < out->counts[f] && i < out->data.n; ++k)
            out->file_of[i++] = (unsigned)f;
    if (outlets(out, d) != 0 || cable_points(out, cfg, d) != 0 ||
        rch_sensors_add_effects(&out->robot.model, out->data.s, out->data.n, d) != 0 ||
        (cfg->n_positions_paths && append_positions(out, cfg, d) != 0))
        goto fail;
    out->n_read = out->data.n;
    if (!cfg->no_dequantize && dequantize(out, cfg, d) != 0)
        goto fail;
    return 0;
fail:
    rch_inputs_free(out);
    return -1;
}

void rch_inputs_free(rch_inputs *in)
{
    rch_data_free(&in->data);
    rch_data_free(&in->validate);
    free(in->file_of);
    in->file_of = NULL;
    free(in->read_q);
    in->read_q = NULL;
}
