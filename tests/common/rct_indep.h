/* SPDX-License-Identifier: MIT */
/* rct_indep.h - an independent data generator for tests: its own random
 * numbers (splitmix64 + Box-Muller) and its own forward kinematics
 * (standard DH with 4 x 4 homogeneous matrices), written apart from the
 * code under test (lib/rc_model.c, tools/host/fit/rch_sim.c). Tests draw the
 * truth, the poses and the noise here and never pass the noise level, the
 * effect or its location to the code under test. */
#ifndef RCT_INDEP_H
#define RCT_INDEP_H

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

typedef struct {
    uint64_t s;
} rct_rng;

static inline double rct_u01(rct_rng *g)
{
    uint64_t z = (g->s += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    z ^= z >> 31;
    return ((double)(z >> 11) + 0.5) / 9007199254740992.0;
}

static inline double rct_gauss(rct_rng *g)
{
    double u = rct_u01(g), v = rct_u01(g);
    return sqrt(-2.0 * log(u)) * cos(6.283185307179586 * v);
}

/* Frame k (after k joints, 0..6) of a standard-DH arm: dh[i] = {a_mm,
 * d_mm, alpha_rad, theta_off_rad}, joint angle q[i] added to theta. Origin
 * p (3), rotation R (3 x 3, row-major; may be NULL). */
static inline void rct_frame(double p[3], double R[9], double dh[6][4], const double q[6], int k)
{
    double T[4][4] = {{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}, {0, 0, 0, 1}};
    for (int i = 0; i < k; ++i) {
        double th = q[i] + dh[i][3], ct = cos(th), st = sin(th), ca = cos(dh[i][2]), sa = sin(dh[i][2]);
        double A[4][4] = {{ct, -st * ca, st * sa, dh[i][0] * ct},
                          {st, ct * ca, -ct * sa, dh[i][0] * st},
                          {0, sa, ca, dh[i][1]},
                          {0, 0, 0, 1}};
        double X[4][4];
        for (int r = 0; r < 4; ++r)
            for (int c = 0; c < 4; ++c)
                X[r][c] = T[r][0] * A[0][c] + T[r][1] * A[1][c] + T[r][2] * A[2][c] + T[r][3] * A[3][c];
        memcpy(T, X, sizeof T);
    }
    for (int r = 0; r < 3; ++r) {
        p[r] = T[r][3];
        for (int c = 0; R && c < 3; ++c)
            R[r * 3 + c] = T[r][c];
    }
}

/* Flange position. */
static inline void rct_flange(double p[3], double dh[6][4], const double q[6])
{
    rct_frame(p, NULL, dh, q, 6);
}

/* Flange pose: position p (3) and rotation R (3 x 3, row-major). */
static inline void rct_pose(double p[3], double R[9], double dh[6][4], const double q[6])
{
    rct_frame(p, R, dh, q, 6);
}

/* Gravity moment arm about joint 2 (m): the wrist centre's (frame 4)
 * horizontal offset from joint 2's axis (frame 1), along the arm's heading. */
static inline double rct_lever2_m(double dh[6][4], const double q[6])
{
    double j2[3], w[3];
    rct_frame(j2, NULL, dh, q, 1);
    rct_frame(w, NULL, dh, q, 4);
    const double hx = cos(q[0] + dh[0][3]), hy = sin(q[0] + dh[0][3]);
    return ((w[0] - j2[0]) * hx + (w[1] - j2[1]) * hy) / 1000.0;
}

static inline double rct_dist(const double p[3], const double e[3])
{
    return sqrt((p[0] - e[0]) * (p[0] - e[0]) + (p[1] - e[1]) * (p[1] - e[1]) + (p[2] - e[2]) * (p[2] - e[2]));
}

/* The robot dh (rad for the angles) as a truth model file (rcal-model/1,
 * the IRB120's limits, the encoder at (250, -460, 10)) for
 * rch_calib_cfg.truth_path, into path. 0, or -1 when it cannot be written. */
static inline int rct_write_truth(const char *path, const char *name, double dh[6][4])
{
    const double deg = 3.14159265358979323846 / 180.0;
    FILE *f = fopen(path, "w");
    if (!f)
        return -1;
    fprintf(f, "{\"format\": \"rcal-model/1\", \"name\": \"%s\", \"dh\": [", name);
    for (int i = 0; i < 6; ++i)
        fprintf(f, "%s{\"a_mm\": %.12g, \"d_mm\": %.12g, \"alpha_deg\": %.12g, \"theta_deg\": %.12g}", i ? ", " : "",
                dh[i][0], dh[i][1], dh[i][2] / deg, dh[i][3] / deg);
    fprintf(f, "], \"joint_limits_deg\": [[-165, 165], [-110, 110], [-110, 70], [-160, 160], [-120, 120], "
               "[-400, 400]], \"encoder_mm\": [250, -460, 10]}\n");
    return fclose(f) == 0 ? 0 : -1;
}

#endif
