/* SPDX-License-Identifier: MIT */
/* rch_sensor_touch.c - points touched on flat plates as calibration data
 * (docs/touches.md; the sensor's prediction: lib/rc_sensor_plane.c).
 *
 * A touch file: q1..q6 (degrees) and plane (the plate or plate placement,
 * 0..RC_MAX_TARGETS-1) per row, optional pose, sigma_mm and height_mm: the
 * probe's point lay on that plate's surface (height_mm above it along its
 * normal: the top of a gauge block of that height standing on the plate)
 * when the joints were read. Planes alone see no length (every length of
 * the robot, the probe and the plates scaled alike fits as well): a gauge
 * block's height is the length that fixes the robot's size. The probe
 * tip (RC_EFF_TOUCH_TIP) and every plate (RC_EFF_PLANE_NORMALS, _OFFSETS)
 * are fitted with the robot; their start is closed form at the model's
 * geometry (touch_start): with the tip held, each plate is the plane through
 * its points (centroid, the scatter's smallest eigenvector); with the
 * plates' normals held, the tip and the offsets are linear least squares;
 * the two alternate, each lowering the same sum of squares.
 */
#include "rch_sensors.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "rc_linalg.h"
#include "rc_sensor.h"
#include "rch_positions.h"

#define TOUCH_START_ROUNDS 200
#define TOUCH_MIN_SPREAD_MM 1.0 /* a plate's touches must spread this far in two directions (RMS) */

extern const rch_sensor_desc rch_sensor_touch;

static int touch_add_effects(rc_model *m, unsigned n_planes)
{
    if (rch_pos_effect_at(m, RC_EFF_TOUCH_TIP, NULL) < 0 && rc_model_add_effect(m, RC_EFF_TOUCH_TIP, 0, 0) != RC_OK)
        return -1;
    if (rch_pos_effect_at(m, RC_EFF_PLANE_NORMALS, NULL) < 0 &&
        (rc_model_add_effect(m, RC_EFF_PLANE_NORMALS, 0, 2u * n_planes) != RC_OK ||
         rc_model_add_effect(m, RC_EFF_PLANE_OFFSETS, 0, n_planes) != RC_OK))
        return -1;
    return 0;
}

/* The flange of m at q: o (3), R (3 x 3); rc_fk's point less a tool offset. */
static void flange(double o[3], double R[9], const rc_model *m, const double q[RC_NJ])
{
    const int ti = rch_pos_effect_at(m, RC_EFF_TOOL_OFFSET, NULL);
    rc_fk(o, R, m, q);
    if (ti >= 0)
        for (int r = 0; r < 3; ++r)
            o[r] -= R[3 * r] * m->x[ti] + R[3 * r + 1] * m->x[ti + 1] + R[3 * r + 2] * m->x[ti + 2];
}

/* The probe's point p (3) of sample s at the tip t (3) on m. */
static void touch_point(double p[3], const rc_model *m, const rc_sample *s, const double t[3])
{
    double o[3], R[9];
    flange(o, R, m, s->q_rad);
    for (int r = 0; r < 3; ++r)
        p[r] = o[r] + R[3 * r] * t[0] + R[3 * r + 1] * t[1] + R[3 * r + 2] * t[2];
}

/* The point of sample s on its plate's face: the probe's at the tip t less
 * its height along the plate's normal n (have_n: n known, else not moved). */
static void face_point(double p[3], const rc_model *m, const rc_sample *s, const double t[3], const double n[3],
                       int have_n)
{
    touch_point(p, m, s, t);
    for (int r = 0; have_n && r < 3; ++r)
        p[r] -= s->value * n[r];
}

/* Each plate k < np through its points at the tip t: n (np x 3), dist (np);
 * have_n: n holds the last round's normals (the heights taken off along
 * them), else only touches at height 0 when a plate has 3. 0, or -1 with
 * *bad the plate whose points do not span a plane. */
static int fit_planes(double (*n)[3], double *dist, unsigned *bad, const rc_model *m, const rc_sample *s, size_t ns,
                      unsigned np, const double t[3], int have_n)
{
    for (unsigned k = 0; k < np; ++k) {
        double c[3] = {0, 0, 0}, S[9] = {0}, V[9], ev[3], p[3];
        size_t cnt = 0, on = 0; /* touches of plate k, those on its face (height 0) */
        for (size_t i = 0; i < ns; ++i)
            on += s[i].sensor == RC_SENSOR_PLANE && s[i].target == k && s[i].value == 0.0;
        const int face = !have_n && on >= 3; /* the first round: the face's touches alone */
        for (size_t i = 0; i < ns; ++i)
            if (s[i].sensor == RC_SENSOR_PLANE && s[i].target == k && (!face || s[i].value == 0.0)) {
                face_point(p, m, &s[i], t, n[k], have_n);
                for (int r = 0; r < 3; ++r)
                    c[r] += p[r];
                ++cnt;
            }
        if (cnt < 3) {
            *bad = k;
            return -1;
        }
        for (int r = 0; r < 3; ++r)
            c[r] /= (double)cnt;
        for (size_t i = 0; i < ns; ++i)
            if (s[i].sensor == RC_SENSOR_PLANE && s[i].target == k && (!face || s[i].value == 0.0)) {
                face_point(p, m, &s[i], t, n[k], have_n);
                for (int r = 0; r < 3; ++r)
                    for (int q = 0; q < 3; ++q)
                        S[3 * r + q] += (p[r] - c[r]) * (p[q] - c[q]);
            }
        if (rcu_eig_sym(ev, V, S, 3, 0) != RC_OK || ev[1] < TOUCH_MIN_SPREAD_MM * TOUCH_MIN_SPREAD_MM * (double)cnt) {
            *bad = k;
            return -1;
        }
        double side = 0.0; /* the flange's side of the plate: where the probe comes from */
        for (size_t i = 0; i < ns; ++i)
            if (s[i].sensor == RC_SENSOR_PLANE && s[i].target == k) {
                double o[3], R[9];
                flange(o, R, m, s[i].q_rad);
                for (int r = 0; r < 3; ++r)
                    side += V[3 * r + 2] * (o[r] - c[r]);
            }
        for (int r = 0; r < 3; ++r)
            n[k][r] = side < 0.0 ? -V[3 * r + 2] : V[3 * r + 2]; /* the smallest eigenvalue's vector, out of the face */
        dist[k] = n[k][0] * c[0] + n[k][1] * c[1] + n[k][2] * c[2];
    }
    return 0;
}

/* With the normals n (np x 3) held: the tip t (3) and offsets dist (np)
 * minimising sum (n_k . (o + R t) - d_k - value)^2, a small ridge keeping
 * t where the orientations do not see it. 0, or -1 (singular). */
static int fit_tip(double t[3], double *dist, const rc_model *m, const rc_sample *s, size_t ns, unsigned np,
                   const double (*n)[3])
{
    double A[(3 + RC_MAX_TARGETS) * (3 + RC_MAX_TARGETS)] = {0}, b[3 + RC_MAX_TARGETS] = {0};
    const unsigned nu = 3 + np;
    for (size_t i = 0; i < ns; ++i) {
        if (s[i].sensor != RC_SENSOR_PLANE || s[i].target >= np)
            continue;
        const unsigned k = s[i].target;
        double o[3], R[9], row[3 + RC_MAX_TARGETS] = {0};
        flange(o, R, m, s[i].q_rad);
        for (int j = 0; j < 3; ++j)
            row[j] = n[k][0] * R[j] + n[k][1] * R[3 + j] + n[k][2] * R[6 + j];
        row[3 + k] = -1.0;
        const double rhs = s[i].value - (n[k][0] * o[0] + n[k][1] * o[1] + n[k][2] * o[2]);
        for (unsigned a = 0; a < nu; ++a) {
            b[a] += row[a] * rhs;
            for (unsigned c = 0; c < nu; ++c)
                A[a * nu + c] += row[a] * row[c];
        }
    }
    double tr = 0.0;
    for (unsigned a = 0; a < nu; ++a)
        tr += A[a * nu + a];
    for (unsigned j = 0; j < 3; ++j) { /* ridge towards the current t */
        A[j * nu + j] += 1e-9 * tr;
        b[j] += 1e-9 * tr * t[j];
    }
    if (rcu_chol_solve(A, b, nu) != RC_OK)
        return -1;
    for (unsigned j = 0; j < 3; ++j)
        t[j] = b[j];
    for (unsigned k = 0; k < np; ++k)
        dist[k] = b[3 + k];
    return 0;
}

static int touch_start(rc_model *m, const rc_sample *s, size_t ns, rch_diag *d)
{
    unsigned np = 0, bad = 0;
    const int tf = rch_pos_effect_at(m, RC_EFF_TOUCH_TIP, NULL), nf = rch_pos_effect_at(m, RC_EFF_PLANE_NORMALS, NULL),
              df = rch_pos_effect_at(m, RC_EFF_PLANE_OFFSETS, &np);
    if (tf < 0 || nf < 0 || df < 0)
        return 0;
    double t[3], n[RC_MAX_TARGETS][3], dist[RC_MAX_TARGETS];
    memcpy(t, &m->x[tf], sizeof t);
    for (unsigned r = 0; r < TOUCH_START_ROUNDS; ++r) {
        const double t0[3] = {t[0], t[1], t[2]};
        if (fit_planes(n, dist, &bad, m, s, ns, np, t, r > 0) != 0) {
            rch_diag_set(d, "", 0, 0,
                         "cannot place plane %u: its touches do not spread over a plate (at least 3, %.0f mm apart "
                         "in two directions; docs/touches.md)",
                         bad, TOUCH_MIN_SPREAD_MM);
            return -1;
        }
        if (fit_tip(t, dist, m, s, ns, np, (const double(*)[3])n) != 0)
            break; /* the plates as fitted; the fit goes on from them */
        if (fabs(t[0] - t0[0]) + fabs(t[1] - t0[1]) + fabs(t[2] - t0[2]) < 1e-7)
            break;
    }
    memcpy(&m->x[tf], t, sizeof t);
    for (unsigned k = 0; k < np; ++k) {
        rc_plane_angles(&m->x[nf + 2 * k], &m->x[nf + 2 * k + 1], n[k]);
        m->x[df + k] = dist[k];
    }
    return 0;
}

/* No cable length and no gauge height: nothing in the data is a length. */
static void touch_caveat(char *note, size_t note_len, const rc_sample *s, size_t n)
{
    note[0] = '\0';
    for (size_t i = 0; i < n; ++i)
        if (s[i].sensor == RC_SENSOR_LENGTH || (s[i].sensor == RC_SENSOR_PLANE && s[i].value != 0.0))
            return;
    snprintf(note, note_len,
             "no length in the data (no gauge block's height_mm, no cable length): planes see only directions, "
             "every length of the robot, the probe and the plates scaled alike fits as well, so the robot's size "
             "is the prior's; touch the top of a gauge block of known height standing on a plate "
             "(docs/touches.md)");
}

const rch_sensor_desc rch_sensor_touch = {
    RC_SENSOR_PLANE, "touch", "plane", "planes", "height_mm", "docs/touches.md", touch_add_effects, touch_start,
    touch_caveat, "plate touches",
    "the plates' places absorb the robot's heading and height, as an outlet does for lengths",
    "touch plates facing three directions, at poses that move every joint and turn the probe (docs/touches.md)",
    RC_EFF_TOUCH_TIP,
};
