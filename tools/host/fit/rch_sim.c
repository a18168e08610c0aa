/* SPDX-License-Identifier: MIT */
#include "rch_sim.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "rch_data.h"
#include "rch_file.h"
#include "rch_save.h"
#include "rch_stats.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif
#define DEG (M_PI / 180.0)

void rch_sim_defaults(rch_sim_config *c)
{
    if (c->err_len_mm == 0.0) c->err_len_mm = 0.3;
    if (c->err_ang_deg == 0.0) c->err_ang_deg = 0.05;
    if (c->noise_mm == 0.0) c->noise_mm = 0.01;
    if (c->resolution_mm == 0.0) c->resolution_mm = 0.004;
    if (c->q_step_deg == 0.0) c->q_step_deg = 0.1;
    if (c->len_min_mm == 0.0) c->len_min_mm = 250.0;
    if (c->len_max_mm == 0.0) c->len_max_mm = 800.0;
    if (c->group_span_deg == 0.0) c->group_span_deg = 25.0;
}

void rch_sim_truth(rc_model *truth, const rc_model *nominal, const double enc_mm[3],
                   const rch_sim_config *c, rc_rng *g)
{
    *truth = *nominal;
    for (unsigned i = 0; i < RC_NJ; ++i) {
        const double sl = c->err_len_mm > 0.0 ? c->err_len_mm : 0.0, sa = c->err_ang_deg > 0.0 ? c->err_ang_deg : 0.0;
        truth->x[RC_P_A(i)] += sl * rc_rng_normal(g);
        truth->x[RC_P_D(i)] += sl * rc_rng_normal(g);
        truth->x[RC_P_ALPHA(i)] += sa * DEG * rc_rng_normal(g);
        truth->x[RC_P_THETA(i)] += sa * DEG * rc_rng_normal(g);
    }
    for (unsigned k = 0; k < 3; ++k)
        truth->x[RC_P_ENC + k] = enc_mm[k];
}

static double quant(double v, double step) { return step > 0.0 ? step * floor(v / step + 0.5) : v; }

static void range_of(double *lo, double *hi, const rc_model *m, const rch_sim_config *c, unsigned j)
{
    if (c->q_lo_deg[j] == 0.0 && c->q_hi_deg[j] == 0.0) {
        *lo = m->q_min_rad[j];
        *hi = m->q_max_rad[j];
    } else {
        *lo = c->q_lo_deg[j] * DEG;
        *hi = c->q_hi_deg[j] * DEG;
    }
}

/* q uniform in [lo, hi] per joint, joint 1 first: one rc_rng_u01 per joint */
static void uniform_pose(double q[RC_NJ], const double lo[RC_NJ], const double hi[RC_NJ], rc_rng *g)
{
    for (unsigned j = 0; j < RC_NJ; ++j)
        q[j] = lo[j] + (hi[j] - lo[j]) * rc_rng_u01(g);
}

void rch_sim_pose(double q_rad[RC_NJ], const rc_model *m, double margin_rad, rc_rng *g)
{
    double lo[RC_NJ], hi[RC_NJ];
    for (unsigned j = 0; j < RC_NJ; ++j) {
        lo[j] = m->q_min_rad[j] + margin_rad;
        hi[j] = m->q_max_rad[j] - margin_rad;
    }
    uniform_pose(q_rad, lo, hi, g);
}

void rch_sim_poses(rc_sample *out, size_t n, const rc_model *m, double margin_rad, rc_rng *g)
{
    for (size_t i = 0; i < n; ++i) {
        memset(&out[i], 0, sizeof out[i]);
        rch_sim_pose(out[i].q_rad, m, margin_rad, g);
    }
}

int rch_sim_samples(rc_sample *out, double (*true_q_rad)[RC_NJ], size_t n, const rc_model *truth,
                    const rch_sim_config *c, rc_rng *g)
{
    double centre[RC_NJ] = {0}, last_q[RC_NJ] = {0};
    unsigned group = 0;
    for (size_t i = 0; i < n; ++i) {
        if (c->repeats > 1 && i % c->repeats != 0) {
            /* the same pose read again: the same joints, fresh length noise */
            rc_sample s = out[i - 1];
            double l;
            memcpy(s.q_rad, last_q, sizeof last_q);
            if (rc_meas(&l, NULL, truth, &s) != RC_OK)
                return -1;
            double noise = c->noise_mm > 0.0 ? c->noise_mm * rc_rng_normal(g) : 0.0;
            s.value = quant(l + noise, c->resolution_mm);
            memcpy(s.q_rad, out[i - 1].q_rad, sizeof s.q_rad);
            s.t = n > 1 ? (double)i / (double)(n - 1) : 0.0;
            if (true_q_rad)
                memcpy(true_q_rad[i], last_q, sizeof last_q);
            out[i] = s;
            continue;
        }
        const int new_group = c->group_size > 0 && i % c->group_size == 0;
        if (new_group && i > 0)
            ++group;
        rc_sample s;
        double q[RC_NJ];
        int found = 0;
        for (unsigned tries = 0; tries < 100000 && !found; ++tries) {
            if (c->group_size == 0 || new_group) {
                double lo[RC_NJ], hi[RC_NJ];
                for (unsigned j = 0; j < RC_NJ; ++j)
                    range_of(&lo[j], &hi[j], truth, c, j);
                uniform_pose(q, lo, hi, g);
                memcpy(centre, q, sizeof q);
            } else {
                for (unsigned j = 0; j < RC_NJ; ++j) {
                    double lo, hi;
                    range_of(&lo, &hi, truth, c, j);
                    q[j] = centre[j];
                    if (j < 3) {
                        q[j] += c->group_span_deg * DEG * (2.0 * rc_rng_u01(g) - 1.0);
                        if (q[j] < lo) q[j] = lo;
                        if (q[j] > hi) q[j] = hi;
                    }
                }
            }
            memset(&s, 0, sizeof s);
            memcpy(s.q_rad, q, sizeof q);
            s.t = n > 1 ? (double)i / (double)(n - 1) : 0.0;
            s.group = (uint16_t)(group > 65535 ? 65535 : group);
            double l;
            if (rc_meas(&l, NULL, truth, &s) != RC_OK)
                continue;
            double p[3];
            rc_fk(p, NULL, truth, q);
            if (l >= c->len_min_mm && l <= c->len_max_mm && p[2] > 50.0) {
                found = 1;
                double noise = c->noise_mm > 0.0 ? c->noise_mm * rc_rng_normal(g) : 0.0;
                s.value = quant(l + noise, c->resolution_mm);
            }
        }
        if (!found)
            return -1;
        if (true_q_rad)
            memcpy(true_q_rad[i], q, sizeof q);
        memcpy(last_q, q, sizeof q);
        for (unsigned j = 0; j < RC_NJ; ++j)
            s.q_rad[j] = quant(q[j] / DEG, c->q_step_deg) * DEG;
        out[i] = s;
    }
    return 0;
}

void rch_sim_flange_diff(double *rms_mm, double *max_mm, const rc_model *a, const rc_model *b,
                         const rc_sample *poses, size_t n, int align)
{
    double sxy = 0.0, sxx = 0.0, dz = 0.0, phi = 0.0;
    rch_stats st;
    memset(&st, 0, sizeof st);
    if (align) {
        for (size_t i = 0; i < n; ++i) {
            double pa[3], pb[3];
            rc_fk(pa, NULL, a, poses[i].q_rad);
            rc_fk(pb, NULL, b, poses[i].q_rad);
            sxy += pa[0] * pb[1] - pa[1] * pb[0];
            sxx += pa[0] * pb[0] + pa[1] * pb[1];
            dz += (pb[2] - pa[2]) / (double)n;
        }
        phi = atan2(sxy, sxx);
    }
    const double c = cos(phi), s = sin(phi);
    for (size_t i = 0; i < n; ++i) {
        double pa[3], pb[3];
        rc_fk(pa, NULL, a, poses[i].q_rad);
        rc_fk(pb, NULL, b, poses[i].q_rad);
        const double x = c * pa[0] - s * pa[1], y = s * pa[0] + c * pa[1], z = pa[2] + dz;
        rch_stats_add(&st, sqrt((x - pb[0]) * (x - pb[0]) + (y - pb[1]) * (y - pb[1]) + (z - pb[2]) * (z - pb[2])));
    }
    *rms_mm = rch_stats_rms(&st);
    *max_mm = st.max_abs;
}

int rch_sim_make(rch_sim_set *out, const rch_sim_job *job, rch_diag *d)
{
    memset(out, 0, sizeof *out);
    out->sim = job->sim;
    out->seed = job->seed;
    rch_sim_defaults(&out->sim);
    if (rch_robot_load(&out->robot, job->truth_path ? job->truth_path : job->robot_path, d) != 0)
        return -1;
    rc_rng g;
    rc_rng_seed(&g, job->seed);
    if (job->truth_path) {
        out->truth = out->robot.model;
        if (!out->robot.has_encoder)
            memcpy(&out->truth.x[RC_P_ENC], job->enc_mm, sizeof job->enc_mm);
    } else {
        rch_sim_truth(&out->truth, &out->robot.model, job->enc_mm, &out->sim, &g);
    }
    out->s = malloc((job->n ? job->n : 1) * sizeof *out->s);
    if (!out->s) {
        rch_diag_set(d, "", 0, 0, "out of memory for %zu samples", job->n);
        return -1;
    }
    if (rch_sim_samples(out->s, NULL, job->n, &out->truth, &out->sim, &g) != 0) {
        rch_diag_set(d, "", 0, 0, "no pose puts the cable within %.0f..%.0f mm; check --encoder",
                     out->sim.len_min_mm, out->sim.len_max_mm);
        rch_sim_set_free(out);
        return -1;
    }
    out->n = job->n;
    return 0;
}

void rch_sim_set_free(rch_sim_set *set)
{
    free(set->s);
    set->s = NULL;
    set->n = 0;
}

static void sim_info(rch_jw *w, const void *ctx)
{
    const rch_sim_set *set = ctx;
    rch_jw_bool(w, "simulated", 1);
    rch_jw_uint(w, "seed", set->seed);
    rch_jw_numf(w, "noise_mm", set->sim.noise_mm, "%g");
    rch_jw_numf(w, "resolution_mm", set->sim.resolution_mm, "%g");
    rch_jw_numf(w, "q_step_deg", set->sim.q_step_deg, "%g");
}

int rch_sim_write_truth(FILE *f, const rch_sim_set *set)
{
    const rch_robot_info info = {sim_info, set, NULL, NULL, NULL, NULL, 0, NULL};
    return rch_robot_write(f, "simulated truth", &set->truth, &set->robot.nominal, &info);
}

static int write_csv_fn(FILE *f, const void *ctx)
{
    const rch_sim_set *set = ctx;
    return rch_data_write(f, set->s, set->n, &set->robot.nominal);
}

static int write_truth_fn(FILE *f, const void *ctx)
{
    return rch_sim_write_truth(f, ctx);
}

/* 1 when a and b name one file in one directory (the directories compared
 * by device and inode): two spellings of a file that does not exist yet. */
static int same_place(const char *a, const char *b)
{
    const char *sa = strrchr(a, '/'), *sb = strrchr(b, '/');
    const char *ba = sa ? sa + 1 : a, *bb = sb ? sb + 1 : b;
    char da[4096], db[4096];
    struct stat xa, xb;
    if (strcmp(ba, bb) != 0)
        return 0;
    snprintf(da, sizeof da, "%.*s", sa ? (sa == a ? 1 : (int)(sa - a)) : 1, sa ? a : ".");
    snprintf(db, sizeof db, "%.*s", sb ? (sb == b ? 1 : (int)(sb - b)) : 1, sb ? b : ".");
    return stat(da, &xa) == 0 && stat(db, &xb) == 0 && xa.st_dev == xb.st_dev && xa.st_ino == xb.st_ino;
}

int rch_sim_save(const rch_sim_set *set, const rch_sim_job *job, const char *out_path, const char *truth_out,
                 rch_diag *d)
{
    const char *inputs[3] = {job->robot_path, job->truth_path, out_path};
    if (truth_out) {
        if (strcmp(truth_out, out_path) == 0 || rch_same_file(truth_out, out_path) || same_place(truth_out, out_path)) {
            rch_diag_set(d, "", 0, 0, "--truth-out %s is also --out: refused, nothing written", truth_out);
            return -1;
        }
        /* --truth-out naming an input is refused before --out is written */
        for (int k = 0; k < 2; ++k)
            if (inputs[k] && rch_same_file(truth_out, inputs[k])) {
                rch_diag_set(d, truth_out, 0, 0,
                             "--truth-out names the same file as the input %s: refused, nothing written (choose "
                             "another output)",
                             inputs[k]);
                return -1;
            }
    }
    if (rch_save(out_path, "--out", inputs, 2, write_csv_fn, set, d) != 0)
        return -1;
    return truth_out ? rch_save(truth_out, "--truth-out", inputs, 3, write_truth_fn, set, d) : 0;
}
