/* SPDX-License-Identifier: MIT */
/* rch_calib_judge.c - a model judged against what its sensor can produce
 * before it is written (issue 47): a fit with 29-517 mm of "noise" (q5 in
 * another controller's sign convention, q4 and q6 swapped, a plate's points
 * told in another order) explains nothing, and a model written from it moved
 * a real program by 1.9 degrees.
 *
 * What the sensor can produce, per length: sqrt(sd^2 + step^2 / 12 + j^2),
 * sd the encoder's repeatability with the robot's (stated, --sensor-sd-mm,
 * or RCH_JUDGE_SENSOR_SD_MM), step the display's (the largest decimal step
 * every length sits on, or --display-step-mm), j the joints' display step
 * (likewise from the joints' digits, or --joint-step-deg; none once the
 * joints were dequantized) through the length's joint derivatives, RMS over
 * the rows. A tracker's rows: its stated sigma_mm (else the same sd) and
 * the joints' step through the position. The fit's noise beyond
 * RCH_JUDGE_FACTOR x that floor, or a model that predicts its own training
 * rows worse than the nominal model does, is not written unless forced
 * (rch_calib_save_model). Then the causes rcal can test are tried: each
 * joint column negated, each pair swapped, the plate's points in every other
 * order; the one whose nominal fit (the encoder alone, rch_calib_start)
 * explains the data far better than the file as read is named with its fix.
 *
 * Depends on: the core (rc_meas), rch_start, rch_calib. Memory: scratch
 * freed before return. Errors: none (a cause not testable is left out). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rch_calib.h"
#include "rch_calib_int.h"
#include "rch_start.h"

#define DEG (3.14159265358979323846 / 180.0)

/* The largest decimal step (10 ... 1e-6) that every value of v (n) sits on
 * within 1e-6 of the step; 0 when none does (or n = 0). */
static double decimal_step(const double *v, size_t n, double unit)
{
    if (n == 0)
        return 0.0;
    for (int e = 1; e >= -6; --e) { /* 10 ... 1e-6 */
        const double step = pow(10.0, e);
        size_t k = 0;
        for (; k < n; ++k) {
            const double x = v[k] / unit / step;
            if (fabs(x - nearbyint(x)) > 1e-3)
                break;
        }
        if (k == n)
            return step;
    }
    return 0.0;
}

/* The joints' step's RMS effect on the rows s (n) of m (one value per
 * sensor: lengths [0], tracker coordinates [1]), by central differences. */
static void joint_effect(double out[2], const rc_model *m, const rc_sample *s, size_t n, double step_rad)
{
    double sum[2] = {0.0, 0.0};
    size_t cnt[2] = {0, 0};
    const double h = 1e-6;
    for (size_t i = 0; i < n && step_rad > 0.0; ++i) {
        const int tr = s[i].sensor != RC_SENSOR_LENGTH;
        double v = 0.0;
        int ok = 1;
        for (unsigned j = 0; j < RC_NJ && ok; ++j) {
            rc_sample a = s[i], b = s[i];
            a.q_rad[j] += h;
            b.q_rad[j] -= h;
            double la = 0.0, lb = 0.0;
            ok = rc_meas(&la, NULL, m, &a) == RC_OK && rc_meas(&lb, NULL, m, &b) == RC_OK;
            if (ok) {
                const double g = (la - lb) / (2.0 * h);
                v += g * g * step_rad * step_rad / 12.0;
            }
        }
        if (ok && isfinite(v)) {
            sum[tr] += v;
            cnt[tr]++;
        }
    }
    out[0] = cnt[0] ? sqrt(sum[0] / (double)cnt[0]) : 0.0;
    out[1] = cnt[1] ? sqrt(sum[1] / (double)cnt[1]) : 0.0;
}

/* RMS of the nominal robot's residuals over s (n) once only the encoder
 * (and the tracker's frame) is fitted: how well the file as given can be
 * explained at all. INFINITY when it cannot be fitted. */
static double nominal_rms(const rch_robot *robot, rc_solve_work *w, const rc_sample *s, size_t n)
{
    rc_model m;
    rch_diag d;
    memset(&d, 0, sizeof d);
    if (rch_calib_start(&m, w, robot, s, n, &d) != 0)
        return INFINITY;
    rc_metrics e;
    if (rc_eval(&e, &m, s, n) != RC_OK || !isfinite(e.rmse_mm))
        return INFINITY;
    return e.rmse_mm;
}

/* The causes: every relabelling, the best one's RMS against the file's. */
static void try_causes(rch_calib_judge *j, const rch_calib_result *r, rc_solve_work *w, const rc_sample *s, size_t n)
{
    rc_sample *c = malloc((n ? n : 1) * sizeof *c);
    if (!c)
        return;
    const double base = nominal_rms(&r->robot, w, s, n);
    double best = base;
    char what[200] = "", fix[200] = "";
    /* every relabelling's RMS and name, to say the ones that explain the data as well as the best (one
     * outlet cannot tell the robot from its mirror image: q1 negated reads as well as q4 negated) */
    double cand_e[32];
    char cand_name[32][24];
    unsigned n_cand = 0;
    size_t pos = 0;
    pos += (size_t)snprintf(j->tried + pos, sizeof j->tried - pos,
                            "each joint column negated (another controller's sign convention), each pair of joint "
                            "columns swapped");
    /* one joint negated */
    for (unsigned a = 0; a < RC_NJ; ++a) {
        memcpy(c, s, n * sizeof *c);
        for (size_t i = 0; i < n; ++i)
            c[i].q_rad[a] = -c[i].q_rad[a];
        const double e = nominal_rms(&r->robot, w, c, n);
        if (n_cand < 32) {
            cand_e[n_cand] = e;
            snprintf(cand_name[n_cand++], sizeof cand_name[0], "q%u negated", a + 1);
        }
        if (e < best) {
            best = e;
            snprintf(what, sizeof what, "q%u is read in another sign convention", a + 1);
            snprintf(fix, sizeof fix, "negate the q%u column (or export it in this robot's convention)", a + 1);
        }
    }
    /* two joints swapped */
    for (unsigned a = 0; a < RC_NJ; ++a)
        for (unsigned b = a + 1; b < RC_NJ; ++b) {
            memcpy(c, s, n * sizeof *c);
            for (size_t i = 0; i < n; ++i) {
                const double t = c[i].q_rad[a];
                c[i].q_rad[a] = c[i].q_rad[b];
                c[i].q_rad[b] = t;
            }
            const double e = nominal_rms(&r->robot, w, c, n);
            if (n_cand < 32) {
                cand_e[n_cand] = e;
                snprintf(cand_name[n_cand++], sizeof cand_name[0], "q%u and q%u swapped", a + 1, b + 1);
            }
            if (e < best) {
                best = e;
                snprintf(what, sizeof what, "the columns q%u and q%u are swapped", a + 1, b + 1);
                snprintf(fix, sizeof fix, "swap the headers q%u and q%u", a + 1, b + 1);
            }
        }
    /* the plate's points in another order (up to 4 points: every permutation) */
    const unsigned np = r->cfg.n_cable_points;
    if (np >= 2 && np <= 4) {
        pos += (size_t)snprintf(j->tried + pos, sizeof j->tried - pos, ", the plate's points in every other order");
        unsigned perm[4] = {0, 1, 2, 3};
        /* Heap's algorithm, iterative */
        unsigned cidx[4] = {0, 0, 0, 0};
        for (unsigned i = 1; i < np;) {
            if (cidx[i] < i) {
                const unsigned k = i % 2 ? cidx[i] : 0, t = perm[k];
                perm[k] = perm[i];
                perm[i] = t;
                memcpy(c, s, n * sizeof *c);
                for (size_t q = 0; q < n; ++q)
                    if (c[q].sensor == RC_SENSOR_LENGTH && c[q].target < np)
                        c[q].target = (uint8_t)perm[c[q].target];
                const double e = nominal_rms(&r->robot, w, c, n);
                if (e < best) {
                    best = e;
                    char order[32] = "";
                    size_t o = 0;
                    for (unsigned t2 = 0; t2 < np; ++t2)
                        o += (size_t)snprintf(order + o, sizeof order - o, "%s%u", t2 ? "," : "", perm[t2]);
                    snprintf(what, sizeof what, "the plate's points are told in another order than the target "
                                                "column's");
                    snprintf(fix, sizeof fix, "the target column's points 0..%u are the --cable-point values "
                                              "%s in that order: give --cable-point in the data's order",
                             np - 1, order);
                }
                cidx[i]++;
                i = 1;
            } else {
                cidx[i] = 0;
                ++i;
            }
        }
    }
    if (r->n_pos_rows)
        snprintf(j->tried + pos, sizeof j->tried - pos,
                 "; not testable: positions shuffled against their poses (check the tracker's export)");
    /* far better: under half the file's RMS, and near what a robot off its drawing leaves (a few mm) */
    if (what[0] && best < 0.5 * base && best < 0.25 * base + 5.0) {
        j->cause_found = 1;
        char alt[120] = "";
        size_t ap = 0;
        for (unsigned k = 0; k < n_cand; ++k)
            if (cand_e[k] < 1.1 * best && cand_e[k] != best && ap < sizeof alt)
                ap += (size_t)snprintf(alt + ap, sizeof alt - ap, "%s%s", ap ? ", " : "", cand_name[k]);
        snprintf(j->cause, sizeof j->cause, "%s: the nominal robot then explains the data to %.3g mm RMS where "
                                            "the file as read leaves %.3g mm; %s%s%s%s",
                 what, best, base, fix, alt[0] ? " (as well explained by a mirror image of it: " : "", alt,
                 alt[0] ? "; check which one the controller exported)" : "");
    }
    free(c);
}

void rch_calib_judge_run(rch_calib_result *r, rc_solve_work *w, const rc_sample *s, size_t n)
{
    rch_calib_judge *j = &r->judge;
    memset(j, 0, sizeof *j);
    if (!r->after_ok || n == 0)
        return;
    const rch_calib_cfg *cfg = &r->cfg;
    double *v = malloc((n * RC_NJ + 1) * sizeof *v);
    if (!v)
        return;
    size_t nl = 0, nq = 0;
    for (size_t i = 0; i < n; ++i) {
        if (s[i].sensor == RC_SENSOR_LENGTH)
            v[nl++] = s[i].value;
    }
    j->display_step_mm = cfg->display_step_mm > 0.0 ? cfg->display_step_mm : decimal_step(v, nl, 1.0);
    for (size_t i = 0; i < n; ++i)
        for (unsigned k = 0; k < RC_NJ; ++k)
            v[nq++] = s[i].q_rad[k];
    const int dequantized = r->have_dequant && r->dequant.n_corrected > 0;
    j->joint_step_deg = cfg->joint_step_given ? cfg->joint_step_deg : dequantized ? 0.0 : decimal_step(v, nq, DEG);
    free(v);
    j->sensor_sd_stated = cfg->sensor_sd_mm > 0.0;
    j->sensor_sd_mm = j->sensor_sd_stated ? cfg->sensor_sd_mm : RCH_JUDGE_SENSOR_SD_MM;
    double jp[2];
    const rc_model *fm = r->have_jumps ? &r->jumps.model : &r->model;
    joint_effect(jp, fm, s, n, j->joint_step_deg * DEG);
    j->joint_part_mm = jp[0];
    j->floor_mm = sqrt(j->sensor_sd_mm * j->sensor_sd_mm + j->display_step_mm * j->display_step_mm / 12.0 +
                       jp[0] * jp[0]);
    const double pos_sd = r->pos_has_sigma && r->pos_sigma_mm > 0.0 ? r->pos_sigma_mm : j->sensor_sd_mm;
    j->pos_floor_mm = sqrt(pos_sd * pos_sd + jp[1] * jp[1]);
    const size_t n_len = rch_pos_count_lengths(s, n);
    /* the noise is one number over both sensors: judged against the larger floor of those present */
    const double fl = n_len == n ? j->floor_mm : n_len == 0 ? j->pos_floor_mm : fmax(j->floor_mm, j->pos_floor_mm);
    j->noise_mm = r->noise_mm > 0.0 ? r->noise_mm : r->train_after.rmse_mm;
    j->ratio = fl > 0.0 ? j->noise_mm / fl : INFINITY;
    j->beyond = !(j->ratio <= RCH_JUDGE_FACTOR);
    j->worse_than_nominal = r->train_after.n > 0 && r->train_before.n > 0 &&
                            r->train_after.rmse_mm > r->train_before.rmse_mm;
    j->done = 1;
    if (j->beyond || j->worse_than_nominal)
        try_causes(j, r, w, s, n);
}
