/* SPDX-License-Identifier: MIT */
/* rch_pos_read.c - reading laser-tracker positions files (rch_pos_load of
 * rch_positions.h) and their plausibility checks, before any fit.
 *
 * Each file, after the CSV reader (rch_data, RCH_DATA_POSITIONS: the field
 * count of every row, each value, the joint limits):
 *  - units as read: joints all within +-7 look like radians, coordinates
 *    all within +-5 like metres;
 *  - rows: a row identical in every field to an earlier one (pasted twice)
 *    is warned on stderr and dropped, not taken as a repeat (a repeat has
 *    fresh noise); a pose number whose rows differ in their joints by more
 *    than RCH_POS_SAME_Q_DEG (the column reused by a second session), one
 *    pose and target measured at places more than RCH_POS_REPEAT_MM apart
 *    (several targets and no target column; a wrong target number), two
 *    targets whose distance changes from pose to pose by more than that;
 *  - with the robot's model: the spread of the points against the spread
 *    the nominal kinematics give at the same joints (a unit: cm, inches, m,
 *    µm), the best fit of the nominal points by a reflection against the
 *    best by a rotation (a mirrored frame), and a rigid fit of the nominal
 *    points that leaves no more than the file's rounding (the controller's
 *    computed positions given as measurements).
 * Depends on rch_data (files), rch_positions (rch_pos_start: the Kabsch
 * fit, rch_pos_errors), rc_model. Memory: rch_pos_load allocates
 * (rch_pos_free); the checks use temporary heap. Errors: -1 with d set
 * (file:line:col; a finding over the whole file: file: only); warnings on
 * stderr as "file:line: warning: ...".
 */
#include "rch_positions.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rc_sensor.h"
#include "rch_data.h"
#include "rch_dequant.h"
#include "rch_file.h"
#include "rch_sha256.h"

#define RAD2DEG (180.0 / 3.14159265358979323846)

static int cmp_double(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* The same joint readings (value by value: -0 equals 0). */
static int same_q(const double *a, const double *b)
{
    for (unsigned j = 0; j < RC_NJ; ++j)
        if (a[j] != b[j])
            return 0;
    return 1;
}

static double dist3(const double *a, const double *b)
{
    return sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
}

/* Units, as rch_data_check_units for lengths: joints all within +-7 (as
 * read) look like radians, coordinates all within +-5 like metres. */
static int check_units(const rch_data *dt, const char *path, rch_diag *d)
{
    double qmax = 0.0, pmax = 0.0;
    if (dt->n < 5)
        return 0;
    for (size_t i = 0; i < dt->n; ++i) {
        for (unsigned j = 0; j < RC_NJ; ++j)
            qmax = fmax(qmax, fabs(dt->s[i].q_rad[j]));
        for (unsigned c = 0; c < 3; ++c)
            pmax = fmax(pmax, fabs(dt->xyz[i][c]));
    }
    if (qmax > 0.0 && qmax < 7.0 / RAD2DEG) {
        rch_diag_set(d, path, 0, 0, "every joint angle is within +-7: the q columns look like radians, rcal reads "
                                    "degrees (multiply by 180/pi, or scripts/positions_convert.py --joints-unit rad)");
        return -1;
    }
    if (pmax < 5.0) {
        rch_diag_set(d, path, 0, 0, "every coordinate is within +-5: x, y, z look like metres, rcal reads "
                                    "millimetres (multiply by 1000, or scripts/positions_convert.py --positions-unit m)");
        return -1;
    }
    return 0;
}

/* ---- rows: duplicates, reused pose numbers, targets */

/* Every field of row i as read: joints, x, y, z, target, pose, sigma. */
static int same_row(const rch_data *dt, size_t a, size_t b)
{
    return same_q(dt->s[a].q_rad, dt->s[b].q_rad) && dt->xyz[a][0] == dt->xyz[b][0] && dt->xyz[a][1] == dt->xyz[b][1] && dt->xyz[a][2] == dt->xyz[b][2] &&
           dt->s[a].target == dt->s[b].target && (!dt->pose || dt->pose[a] == dt->pose[b]) &&
           (!dt->sigma_mm || dt->sigma_mm[a] == dt->sigma_mm[b]) && (!dt->has_t || dt->s[a].t == dt->s[b].t);
}

typedef struct {
    uint64_t h; /* hash of the row's fields, or the pose key */
    unsigned target;
    size_t i;
} row_ref;

static int cmp_ref(const void *a, const void *b)
{
    const row_ref *x = a, *y = b;
    if (x->h != y->h)
        return x->h < y->h ? -1 : 1;
    if (x->target != y->target)
        return x->target < y->target ? -1 : 1;
    return (x->i > y->i) - (x->i < y->i);
}

static uint64_t fnv(uint64_t h, double v)
{
    unsigned char b[sizeof v];
    v += 0.0; /* -0 hashes as 0 */
    memcpy(b, &v, sizeof v);
    for (size_t k = 0; k < sizeof v; ++k)
        h = (h ^ b[k]) * 0x100000001b3ull;
    return h;
}

/* Rows identical in every field to an earlier row: drop[i] = 1, one
 * warning line each on stderr (the first 10, then a count). ref: (n) scratch. */
static size_t mark_duplicates(uint8_t *drop, row_ref *ref, const rch_data *dt, const char *path)
{
    size_t dropped = 0, *of = malloc(dt->n * sizeof *of);
    if (!of)
        return 0;
    for (size_t i = 0; i < dt->n; ++i) {
        uint64_t h = 0xcbf29ce484222325ull;
        for (unsigned j = 0; j < RC_NJ; ++j)
            h = fnv(h, dt->s[i].q_rad[j]);
        for (unsigned c = 0; c < 3; ++c)
            h = fnv(h, dt->xyz[i][c]);
        ref[i].h = fnv(h, (double)dt->s[i].target);
        ref[i].target = 0;
        ref[i].i = i;
        of[i] = i;
    }
    qsort(ref, dt->n, sizeof *ref, cmp_ref);
    for (size_t a = 0; a < dt->n;) {
        size_t b = a + 1;
        while (b < dt->n && ref[b].h == ref[a].h)
            ++b;
        for (size_t u = a + 1; u < b; ++u) /* equal hashes: the fields compared */
            for (size_t v = a; v < u; ++v)
                if (of[ref[v].i] == ref[v].i && same_row(dt, ref[u].i, ref[v].i)) {
                    of[ref[u].i] = ref[v].i;
                    break;
                }
        a = b;
    }
    for (size_t i = 0; i < dt->n; ++i)
        if (of[i] != i) {
            drop[i] = 1;
            if (dropped++ < 10)
                fprintf(stderr,
                        "%s:%u: warning: the same row as line %u, every field identical (pasted twice?): dropped, "
                        "not taken as a repeat (a repeat has fresh noise)\n",
                        path, dt->line[i], dt->line[of[i]]);
        }
    if (dropped > 10)
        fprintf(stderr, "%s: warning: %zu rows identical to an earlier one dropped in all (10 shown)\n", path, dropped);
    free(of);
    return dropped;
}

/* Each kept row's pose: the pose column, else consecutive rows with the
 * same joint readings; key (n), numbered from 0. Returns the poses' count
 * (the largest key + 1). */
static double pose_keys(double *key, const rch_data *dt, const uint8_t *drop)
{
    double top = 0.0;
    size_t prev = (size_t)-1;
    for (size_t i = 0; i < dt->n; ++i) {
        if (drop[i])
            continue;
        if (dt->pose)
            key[i] = (double)dt->pose[i];
        else if (prev != (size_t)-1 && same_q(dt->s[i].q_rad, dt->s[prev].q_rad))
            key[i] = top - 1.0; /* the same joint readings as the row before: the same pose */
        else
            key[i] = top;
        top = fmax(top, key[i] + 1.0);
        prev = i;
    }
    return top;
}

/* Largest joint difference (deg) of rows a and b; *j its joint. */
static double q_diff_deg(const rch_data *dt, size_t a, size_t b, unsigned *j)
{
    double mx = 0.0;
    *j = 0;
    for (unsigned k = 0; k < RC_NJ; ++k)
        if (fabs(dt->s[a].q_rad[k] - dt->s[b].q_rad[k]) * RAD2DEG > mx) {
            mx = fabs(dt->s[a].q_rad[k] - dt->s[b].q_rad[k]) * RAD2DEG;
            *j = k;
        }
    return mx;
}

/* One pose's rows ref[a..b) (sorted by target, then line): the pose's
 * joints, each target's repeats, the distances between targets against
 * the first pose that had them (dref, lref: RC_MAX_TARGETS^2). 0 or -1. */
static int check_pose(const row_ref *ref, size_t a, size_t b, const rch_data *dt, const char *path, double *dref,
                      unsigned *lref, rch_diag *d)
{
    size_t first[RC_MAX_TARGETS];
    for (unsigned t = 0; t < RC_MAX_TARGETS; ++t)
        first[t] = (size_t)-1;
    for (size_t u = a; u < b; ++u) {
        const size_t i = ref[u].i, i0 = ref[a].i;
        unsigned j;
        const double dq = q_diff_deg(dt, i, i0, &j);
        if (dq > RCH_POS_SAME_Q_DEG) {
            const size_t lo = dt->line[i] < dt->line[i0] ? i : i0, hi = lo == i ? i0 : i;
            rch_diag_set(d, path, dt->line[hi], 1,
                         "pose %lu: line %u has other joints than line %u (q%u differs by %.4g deg): the pose column "
                         "is reused (a second session appended to the file?); give the poses of each session their own "
                         "numbers",
                         dt->pose ? dt->pose[i] : 0ul, dt->line[hi], dt->line[lo], j + 1, dq);
            return -1;
        }
        const unsigned t = ref[u].target;
        if (first[t] == (size_t)-1) {
            first[t] = i;
            continue;
        }
        const double dx = dist3(dt->xyz[i], dt->xyz[first[t]]);
        if (dx > RCH_POS_REPEAT_MM) {
            if (!dt->has_target)
                rch_diag_set(d, path, dt->line[i], 1,
                             "lines %u and %u are the same pose (the same joints%s) but their positions are %.4g mm "
                             "apart (a repeat is within %g mm): several targets per pose? add a target column "
                             "(0, 1, ... naming each row's target)",
                             dt->line[first[t]], dt->line[i], dt->pose ? " and pose number" : "", dx,
                             RCH_POS_REPEAT_MM);
            else
                rch_diag_set(d, path, dt->line[i], 1,
                             "lines %u and %u: target %u of the same pose measured %.4g mm apart (a repeat is within "
                             "%g mm): a wrong target number, or the robot moved between them",
                             dt->line[first[t]], dt->line[i], t, dx, RCH_POS_REPEAT_MM);
            return -1;
        }
    }
    for (unsigned t = 0; t < RC_MAX_TARGETS; ++t) /* the targets sit fixed on the tool */
        for (unsigned v = t + 1; v < RC_MAX_TARGETS && first[t] != (size_t)-1; ++v) {
            if (first[v] == (size_t)-1)
                continue;
            const double dd = dist3(dt->xyz[first[t]], dt->xyz[first[v]]);
            const unsigned k = t * RC_MAX_TARGETS + v;
            if (!lref[k]) {
                dref[k] = dd;
                lref[k] = dt->line[first[v]];
            } else if (fabs(dd - dref[k]) > RCH_POS_REPEAT_MM) {
                rch_diag_set(d, path, dt->line[first[v]], 1,
                             "targets %u and %u are %.4g mm apart here (lines %u, %u) but %.4g mm at line %u: the "
                             "targets are fixed on the tool, so a row names the wrong target (or the tool moved)",
                             t, v, dd, dt->line[first[t]], dt->line[first[v]], dref[k], lref[k]);
                return -1;
            }
        }
    return 0;
}

/* Reused pose numbers and the targets, over the kept rows. 0 or -1. */
static int check_poses(const rch_data *dt, const double *key, const uint8_t *drop, row_ref *ref, const char *path,
                       rch_diag *d)
{
    size_t k = 0;
    for (size_t i = 0; i < dt->n; ++i)
        if (!drop[i]) {
            ref[k].h = (uint64_t)key[i];
            ref[k].target = dt->s[i].target;
            ref[k++].i = i;
        }
    qsort(ref, k, sizeof *ref, cmp_ref);
    double *dref = calloc(RC_MAX_TARGETS * RC_MAX_TARGETS, sizeof *dref);
    unsigned *lref = calloc(RC_MAX_TARGETS * RC_MAX_TARGETS, sizeof *lref);
    int rc = dref && lref ? 0 : -1;
    if (rc)
        rch_diag_set(d, path, 0, 0, "out of memory");
    for (size_t a = 0; a < k && rc == 0;) {
        size_t b = a + 1;
        while (b < k && ref[b].h == ref[a].h)
            ++b;
        rc = check_pose(ref, a, b, dt, path, dref, lref, d);
        a = b;
    }
    free(dref);
    free(lref);
    return rc;
}

/* ---- the robot's nominal kinematics against the points */

/* The finest decimal step the file's x, y, z are written with (10^-k,
 * k <= 9; 0 for more digits). */
static double file_step(const rch_data *dt, const uint8_t *drop)
{
    int kmax = 0;
    for (size_t i = 0; i < dt->n; ++i)
        for (unsigned c = 0; c < 3 && !drop[i]; ++c)
            while (kmax <= 9) {
                const double s = dt->xyz[i][c] * pow(10.0, kmax);
                if (fabs(s - nearbyint(s)) <= 1e-9 + 1e-15 * fabs(s))
                    break;
                ++kmax;
            }
    return kmax > 9 ? 0.0 : pow(10.0, -kmax);
}

/* RMS distance of the points p (k x 3) to their centroid. */
static double spread(const double (*p)[3], size_t k)
{
    double c[3] = {0, 0, 0}, ss = 0.0;
    for (size_t i = 0; i < k; ++i)
        for (int r = 0; r < 3; ++r)
            c[r] += p[i][r] / (double)k;
    for (size_t i = 0; i < k; ++i)
        ss += dist3(p[i], c) * dist3(p[i], c);
    return sqrt(ss / (double)k);
}

/* The spread of the measured points y against the nominal flange's o
 * (k x 3 each). 0 or -1 with d set. */
static int check_scale(const double (*o)[3], const double (*y)[3], size_t k, const char *path, rch_diag *d)
{
    static const struct {
        double ratio;
        const char *unit, *fix;
    } units[] = {{0.1, "centimetres", "multiply by 10"},       {1.0 / 25.4, "inches", "multiply by 25.4"},
                 {0.01, "decimetres", "multiply by 100"},      {0.001, "metres", "multiply by 1000"},
                 {1000.0, "micrometres", "divide by 1000"}};
    const double sn = spread(o, k), sm = spread(y, k), r = sm / sn;
    if (!(sn >= RCH_POS_MIN_SPREAD_MM) || (r >= RCH_POS_SCALE_MIN && r <= RCH_POS_SCALE_MAX))
        return 0;
    int best = -1;
    for (int u = 0; u < (int)(sizeof units / sizeof units[0]); ++u)
        if (fabs(log(r / units[u].ratio)) < log(1.6) &&
            (best < 0 || fabs(log(r / units[u].ratio)) < fabs(log(r / units[best].ratio))))
            best = u;
    if (best >= 0)
        rch_diag_set(d, path, 0, 0,
                     "x, y, z spread %.4g times as far as the robot's nominal kinematics at the same joints (RMS "
                     "%.4g mm about their centre against %.4g mm): they look like %s, rcal reads millimetres (%s)",
                     r, sm, sn, units[best].unit, units[best].fix);
    else
        rch_diag_set(d, path, 0, 0,
                     "x, y, z spread %.4g times as far as the robot's nominal kinematics at the same joints (RMS "
                     "%.4g mm about their centre against %.4g mm; a tracker sees the same, up to the targets' "
                     "offsets): not millimetres, or another robot; check the unit and --robot",
                     r, sm, sn);
    return -1;
}

/* What the improper matrix A (3 x 3, tracker from robot) looks like: a
 * swap or a negation of the file's columns when A is near a signed
 * permutation (a tracker frame aligned with the robot's), into buf. */
static void describe_mirror(char *buf, size_t len, const double A[9])
{
    static const char ax[3] = {'x', 'y', 'z'};
    int perm[3], sign[3], ok = 1;
    for (int r = 0; r < 3; ++r) {
        perm[r] = 0;
        for (int c = 1; c < 3; ++c)
            if (fabs(A[3 * r + c]) > fabs(A[3 * r + perm[r]]))
                perm[r] = c;
        sign[r] = A[3 * r + perm[r]] < 0 ? -1 : 1;
        ok &= fabs(A[3 * r + perm[r]]) > 0.99; /* within 8 deg: a tracker aligned with the base */
    }
    ok &= perm[0] != perm[1] && perm[1] != perm[2] && perm[0] != perm[2];
    if (!ok) {
        snprintf(buf, len, "the tracker is turned against the robot, so which two axes cannot be told");
        return;
    }
    int fixed = 0, neg = 0;
    for (int r = 0; r < 3; ++r) {
        fixed += perm[r] == r;
        neg += sign[r] < 0;
    }
    char map[32];
    snprintf(map, sizeof map, "%s%c, %s%c, %s%c", sign[0] < 0 ? "-" : "", ax[perm[0]], sign[1] < 0 ? "-" : "",
             ax[perm[1]], sign[2] < 0 ? "-" : "", ax[perm[2]]);
    if (fixed == 1 && neg == 0) {
        int a = -1, b = -1;
        for (int r = 0; r < 3; ++r)
            if (perm[r] != r)
            {
                if (a < 0)
                    a = r;
                else
                    b = r;
            }
        snprintf(buf, len, "it looks like %c and %c swapped (the file's x, y, z are %s of the robot's base frame)",
                 ax[a < 0 ? 0 : a], ax[b < 0 ? 1 : b], map); /* one fixed axis: the other two swap (a, b >= 0) */
    } else if (fixed == 3 && neg == 1) {
        int a = sign[0] < 0 ? 0 : sign[1] < 0 ? 1 : 2;
        snprintf(buf, len, "it looks like %c negated (the file's x, y, z are %s of the robot's base frame)", ax[a],
                 map);
    } else {
        snprintf(buf, len, "the file's x, y, z are %s of the robot's base frame", map);
    }
}

/* The largest target + 1 of the tracker samples s (n). */
static unsigned targets_of(const rc_sample *s, size_t n)
{
    unsigned nt = 1;
    for (size_t i = 0; i < n; ++i)
        if (s[i].target + 1u > nt)
            nt = s[i].target + 1u;
    return nt;
}

/* The best rigid fit (rch_pos_start) of m's nominal points to s (n), the
 * 3-D RMS left into *rms and the fitted model into fit. 0, or -1 (no fit). */
static int rigid_fit(double *rms, rc_model *fit, const rc_model *m, const rc_sample *s, size_t n)
{
    rch_pos_err e;
    *fit = *m;
    if (rch_pos_add_effects(fit, targets_of(s, n)) != 0 || rch_pos_start(fit, s, n, 0) != 0 ||
        rch_pos_errors(&e, fit, s, n) != 0 || e.points == 0)
        return -1;
    *rms = e.rms_mm;
    return 0;
}

/* The joints' display step (deg; 0: not on one of 0.01 deg or coarser) of
 * the tracker samples s (n), and the 3-D RMS by which that rounding alone
 * moves the points of fit (its targets) at those joints: each joint's
 * rounding error uniform in +-step/2 (variance step^2 / 12), through the
 * point's joint Jacobian (central differences). */
static double rounding_effect(double *step_deg, const rc_model *fit, const rc_sample *s, size_t n)
{
    *step_deg = 0.0;
    const size_t k = n / 3;
    double *v = malloc((k * RC_NJ + 1) * sizeof *v);
    if (!v || k == 0) {
        free(v);
        return 0.0;
    }
    for (size_t i = 0; i < k; ++i)
        for (unsigned j = 0; j < RC_NJ; ++j)
            v[i * RC_NJ + j] = s[3 * i].q_rad[j] * RAD2DEG;
    *step_deg = rch_dequant_detect_step(v, k * RC_NJ);
    free(v);
    if (*step_deg < 0.01)
        return 0.0;
    unsigned nt = 0;
    const int kf = rch_pos_effect_at(fit, RC_EFF_TRACKER_TARGETS, &nt);
    const double h = 1e-6, var = (*step_deg / RAD2DEG) * (*step_deg / RAD2DEG) / 12.0;
    double sum = 0.0;
    for (size_t i = 0; i < k; ++i) {
        const rc_sample *si = &s[3 * i];
        const double zero[3] = {0.0, 0.0, 0.0};
        const double *t = kf >= 0 && 3u * si->target + 2u < nt ? &fit->x[kf + 3 * (int)si->target] : zero;
        for (unsigned j = 0; j < RC_NJ; ++j) {
            double qa[RC_NJ], qb[RC_NJ], pa[3], pb[3], Ra[9], Rb[9];
            memcpy(qa, si->q_rad, sizeof qa);
            memcpy(qb, si->q_rad, sizeof qb);
            qa[j] += h;
            qb[j] -= h;
            rc_fk(pa, Ra, fit, qa);
            rc_fk(pb, Rb, fit, qb);
            for (int c = 0; c < 3; ++c) {
                const double da = pa[c] + Ra[3 * c] * t[0] + Ra[3 * c + 1] * t[1] + Ra[3 * c + 2] * t[2],
                             db = pb[c] + Rb[3 * c] * t[0] + Rb[3 * c + 1] * t[1] + Rb[3 * c + 2] * t[2];
                sum += (da - db) / (2.0 * h) * (da - db) / (2.0 * h) * var;
            }
        }
    }
    return sqrt(sum / (double)k);
}

/* Handedness (the best reflection against the best rotation) and the
 * controller's computed positions (a rigid fit to the rounding), for the
 * file's tracker samples s (n). 0 or -1 with d set. */
static int check_frame(const rc_model *m, const rc_sample *s, size_t n, double step, const char *path,
                       rch_diag *d)
{
    rc_model *fit = malloc(2 * sizeof *fit);
    rc_sample *sm = malloc(n * sizeof *sm);
    double rp = 0.0, rm = 0.0;
    int rc = 0;
    if (!fit || !sm)
        goto done;
    memcpy(sm, s, n * sizeof *sm);
    for (size_t i = 0; i < n; ++i) /* z negated: a rotation of these is a reflection of the file's */
        if (sm[i].sensor == RC_SENSOR_TRACKER_Z)
            sm[i].value = -sm[i].value;
    if (rigid_fit(&rp, &fit[0], m, s, n) != 0 || rigid_fit(&rm, &fit[1], m, sm, n) != 0)
        goto done;
    if (rp > RCH_POS_MIRROR_MIN_MM && rm < RCH_POS_MIRROR_RATIO * rp) {
        double R[9], A[9];
        char what[160];
        rc_rotvec_matrix(R, &fit[1].x[rch_pos_effect_at(&fit[1], RC_EFF_TRACKER_ROTATION, NULL)]);
        for (int k = 0; k < 9; ++k)
            A[k] = (k >= 6 ? -1.0 : 1.0) * R[k];
        describe_mirror(what, sizeof what, A);
        rch_diag_set(d, path, 0, 0,
                     "the x, y, z frame is mirrored (left-handed): the robot's nominal points fit them to %.4g mm RMS "
                     "with a reflection, to %.4g mm with a rotation; %s. A tracker's frame is right-handed: swap two "
                     "of the x, y, z columns back, or negate one",
                     rm, rp, what);
        rc = -1;
    } else if (n / 3 >= RCH_POS_MIN_ROWS_RIGID + targets_of(s, n) && rp <= 0.75 * step + 1e-6) {
        rch_diag_set(d, path, 0, 0,
                     "these are the controller's computed positions, not measurements: the robot's nominal "
                     "kinematics at the joints give x, y, z to %.3g mm RMS after a rigid motion (the file's rounding "
                     "%g mm; a real robot and tracker differ by 0.05 mm or more); give the tracker's measured x, y, z",
                     rp, step);
        rc = -1;
    } else if (n / 3 >= RCH_POS_MIN_ROWS_RIGID + targets_of(s, n)) {
        /* rounded joints: the controller's x, y, z are the nominal kinematics of the unrounded angles, so
         * they miss those of the rounded ones by the rounding's effect alone (issue 47: 0.1 deg joints left
         * about 0.5 mm, far above the x, y, z rounding, and passed as measurements) */
        double qstep = 0.0;
        const double eff = rounding_effect(&qstep, &fit[0], s, n), lim = sqrt(eff * eff + 0.25 * step * step);
        /* the rigid fit's RMS with its degrees of freedom restored (the frame's 6, 3 per target): what the
         * rounding left is then about lim; joints exactly on round values (a plan of whole degrees)
         * leave the robot's own errors, whatever their size, so the window is two-sided */
        const double k3 = (double)(n - n % 3), dof = k3 - 6.0 - 3.0 * targets_of(s, n);
        const double rpc = dof > 0.0 ? rp * sqrt(k3 / dof) : rp;
        if (eff > 0.0 && qstep >= RCH_POS_ROUNDING_MIN_DEG && rpc >= lim / RCH_POS_ROUNDING_RATIO &&
            rpc <= RCH_POS_ROUNDING_RATIO * lim) {
            rch_diag_set(d, path, 0, 0,
                         "these are the controller's computed positions, not measurements: the robot's nominal "
                         "kinematics at the joints give x, y, z to %.3g mm RMS after a rigid motion, what the joints' "
                         "rounding to %g deg alone leaves (%.3g mm expected; a real robot and tracker differ by more); "
                         "give the tracker's measured x, y, z",
                         rp, qstep, eff);
            rc = -1;
        }
    }
done:
    free(fit);
    free(sm);
    return rc;
}

/* The nominal kinematics m against the file's tracker samples s (n, three
 * per row): the scale, then the frame. 0 or -1 with d set. */
static int check_model(const rc_model *m, const rc_sample *s, size_t n, double step, const char *path,
                       rch_diag *d)
{
    const size_t k = n / 3;
    if (k < 5)
        return 0;
    rc_model flange = *m; /* the flange: the cable attachment left out, as rch_pos_start */
    for (unsigned i = 0; i < flange.n_effects; ++i)
        if (flange.effects[i].kind == RC_EFF_TOOL_OFFSET)
            memset(&flange.x[flange.effects[i].first], 0, 3 * sizeof flange.x[0]);
    double (*o)[3] = malloc(k * sizeof *o), (*y)[3] = malloc(k * sizeof *y);
    int rc = 0;
    if (o && y) {
        for (size_t i = 0; i < k; ++i) {
            rc_fk(o[i], NULL, &flange, s[3 * i].q_rad);
            for (int c = 0; c < 3; ++c)
                y[i][c] = s[3 * i + c].value;
        }
        rc = check_scale((const double(*)[3])o, (const double(*)[3])y, k, path, d);
    }
    free(o);
    free(y);
    return rc != 0 ? rc : check_frame(m, s, n, step, path, d);
}

/* ---- the loader */

/* Append file f's kept rows (three samples each) to out; pose numbers
 * base + key. 0 or -1 (out of memory). */
static int append_file(rch_pos *out, const rch_data *dt, const uint8_t *drop, const double *key, unsigned f,
                       double base, double *sig, size_t *nsig)
{
    rc_sample *s = realloc(out->s, (out->n + 3 * dt->n + 1) * sizeof *s);
    if (s)
        out->s = s;
    unsigned *ln = s ? realloc(out->line, (out->n + 3 * dt->n + 1) * sizeof *ln) : NULL;
    if (ln)
        out->line = ln;
    unsigned *fl = ln ? realloc(out->file, (out->n + 3 * dt->n + 1) * sizeof *fl) : NULL;
    if (fl)
        out->file = fl;
    if (!fl)
        return -1;
    for (size_t i = 0; i < dt->n; ++i) {
        if (drop[i])
            continue;
        for (unsigned c = 0; c < 3; ++c) {
            rc_sample *o = &out->s[out->n];
            *o = dt->s[i];
            o->sensor = (uint8_t)(RC_SENSOR_TRACKER_X + c);
            o->value = dt->xyz[i][c];
            o->t = base + key[i];
            o->outlet = 0;
            o->group = 0;
            o->weight = dt->sigma_mm ? dt->sigma_mm[i] : 0.0; /* the row's stated sd, made a weight in finish */
            out->line[out->n] = dt->line[i];
            out->file[out->n] = f;
            out->n++;
        }
        if (dt->s[i].target + 1u > out->n_targets)
            out->n_targets = dt->s[i].target + 1u;
        if (dt->sigma_mm)
            sig[(*nsig)++] = dt->sigma_mm[i];
        out->rows++;
    }
    return 0;
}

/* One file read into dt: check, append; dt freed. 0 or -1 with d set. */
static int add_one(rch_pos *out, rch_data *dtp, const char *path, unsigned f, double *next, const rc_model *limits,
                   double **sig, size_t *nsig, rch_diag *d)
{
    const rch_data dt = *dtp;
    int rc = check_units(&dt, path, d);
    uint8_t *drop = calloc(dt.n + 1, 1);
    double *key = malloc((dt.n + 1) * sizeof *key), *ns = realloc(*sig, (*nsig + dt.n + 1) * sizeof *ns);
    row_ref *ref = malloc((dt.n + 1) * sizeof *ref);
    if (ns)
        *sig = ns;
    if (rc == 0 && (!drop || !key || !ns || !ref)) {
        rch_diag_set(d, path, 0, 0, "out of memory");
        rc = -1;
    }
    if (rc == 0) {
        out->dropped += mark_duplicates(drop, ref, &dt, path);
        const double poses = pose_keys(key, &dt, drop);
        const size_t from = out->n;
        rc = check_poses(&dt, key, drop, ref, path, d);
        if (rc == 0 && append_file(out, &dt, drop, key, f, *next, *sig, nsig) != 0) {
            rch_diag_set(d, path, 0, 0, "out of memory");
            rc = -1;
        }
        if (rc == 0 && limits)
            rc = check_model(limits, out->s + from, out->n - from, file_step(&dt, drop), path, d);
        *next += poses;
    }
    free(drop);
    free(key);
    free(ref);
    rch_data_free(dtp);
    return rc;
}

/* The median of the sigma_mm column: sig (nsig), freed. */
static void finish(rch_pos *out, double next, double pose0, double *sig, size_t nsig)
{
    out->poses = (size_t)(next - pose0);
    if (nsig) {
        qsort(sig, nsig, sizeof *sig, cmp_double);
        out->has_sigma = 1;
        out->sigma_mm = sig[nsig / 2];
    }
    for (size_t i = 0; i < out->n; ++i) /* a stated sd weighs its row against the files' median: sd_ref / sd_i */
        out->s[i].weight = out->s[i].weight > 0.0 && out->has_sigma ? out->sigma_mm / out->s[i].weight : 0.0;
    free(sig);
}

/* One positions file read once: parsed (joints within limits) and its
 * digest (out->sha256[f]) taken from the same bytes. 0, or -1 with d set. */
static int read_hashed(rch_data *dt, rch_pos *out, const char *path, size_t f, const rc_model *limits, rch_diag *d)
{
    char *buf = NULL;
    size_t len = 0;
    memset(dt, 0, sizeof *dt);
    if (rch_read_file(&buf, &len, path, RCH_DATA_MAX_BYTES, d) != 0)
        return -1;
    if (f < RCH_POS_MAX_FILES) {
        rch_sha256 c;
        rch_sha256_init(&c);
        rch_sha256_update(&c, buf, len);
        rch_sha256_final(&c, out->sha256[f]);
    }
    const int rc = rch_data_parse_limited(dt, buf, len, path, RCH_DATA_POSITIONS | RCH_DATA_NO_LEN, limits, d);
    free(buf);
    return rc;
}

int rch_pos_load(rch_pos *out, const char *const *paths, size_t k, double pose0, const rc_model *limits,
                 rch_diag *d)
{
    memset(out, 0, sizeof *out);
    double next = pose0, *sig = NULL;
    size_t nsig = 0;
    for (size_t f = 0; f < k; ++f) {
        rch_data dt;
        if (read_hashed(&dt, out, paths[f], f, limits, d) != 0 ||
            add_one(out, &dt, paths[f], (unsigned)f, &next, limits, &sig, &nsig, d) != 0) {
            rch_pos_free(out);
            free(sig);
            return -1;
        }
    }
    finish(out, next, pose0, sig, nsig);
    return 0;
}

int rch_pos_targets_whole(const rch_pos *p, const char *const *paths, rch_diag *d)
{
    unsigned char seen[RC_MAX_TARGETS] = {0};
    size_t first[RC_MAX_TARGETS] = {0};
    for (size_t i = 0; i < p->n; ++i)
        if (p->s[i].target < RC_MAX_TARGETS && !seen[p->s[i].target]) {
            seen[p->s[i].target] = 1;
            first[p->s[i].target] = i;
        }
    for (unsigned k = 0; k < p->n_targets && k < RC_MAX_TARGETS; ++k) {
        if (seen[k])
            continue;
        unsigned above = k + 1;
        while (above < p->n_targets && !seen[above])
            ++above; /* the first label past the gap (there is one: n_targets is the largest + 1) */
        const size_t i = first[above];
        rch_diag_set(d, paths[p->file[i]], p->line[i], 1,
                     "target %u, but no row has target %u: the targets are numbered 0, 1, ... without a gap (a "
                     "target with no rows would be fitted from nothing, kept at the flange centre, and judge every "
                     "later file there); renumber the target column or measure target %u",
                     above, k, k);
        return -1;
    }
    return 0;
}

int rch_pos_parse(rch_pos *out, const char *text, size_t len, const char *name, const rc_model *model, rch_diag *d)
{
    rch_data dt;
    double next = 0.0, *sig = NULL;
    size_t nsig = 0;
    memset(out, 0, sizeof *out);
    if (rch_data_parse(&dt, text, len, name, RCH_DATA_POSITIONS | RCH_DATA_NO_LEN, d) != 0)
        return -1;
    if (add_one(out, &dt, name, 0, &next, model, &sig, &nsig, d) != 0) {
        rch_pos_free(out);
        free(sig);
        return -1;
    }
    finish(out, next, 0.0, sig, nsig);
    return 0;
}
