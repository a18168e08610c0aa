/* SPDX-License-Identifier: MIT */
/* urdf_fk_dump.c - rcal's forward kinematics of a robot (a URDF or a model
 * file, rch_robot_load) as the controller's flange pose B T_dh(q) F
 * (rch_ctrl_fk), for tests/tools/host/outputs/urdf_fk.py to compare with a URDF's:
 *   urdf_fk_dump ROBOT FK.csv [SEED MODEL_OUT.json]
 * 200 random joint vectors inside the limits, lines "q1..q6 (rad), x, y, z
 * (mm)". With SEED: the model's DH table perturbed as a calibration would
 * move it (a, d by up to 2 mm, alpha, theta by up to 0.3 deg), written to
 * MODEL_OUT.json (the nominal table and the controller member with it) and
 * its FK dumped instead. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "rch_robot.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

static unsigned long long lcg = 99;
static double urand(double lo, double hi)
{
    lcg = lcg * 6364136223846793005ULL + 1442695040888963407ULL;
    return lo + (hi - lo) * (double)(lcg >> 11) / 9007199254740992.0;
}

int main(int argc, char **argv)
{
    if (argc != 3 && argc != 5) {
        fprintf(stderr, "usage: urdf_fk_dump ROBOT FK.csv [SEED MODEL_OUT.json]\n");
        return 2;
    }
    static rch_robot r;
    rch_diag d;
    char msg[800];
    if (rch_robot_load(&r, argv[1], &d) != 0) {
        fprintf(stderr, "urdf_fk_dump: %s\n", rch_diag_str(&d, msg, sizeof msg));
        return 1;
    }
    if (argc == 5) {
        lcg = strtoull(argv[3], NULL, 10);
        for (int i = 0; i < RC_NJ; ++i) {
            r.model.x[RC_P_A(i)] += urand(-2, 2);
            r.model.x[RC_P_D(i)] += urand(-2, 2);
            r.model.x[RC_P_ALPHA(i)] += urand(-0.3, 0.3) * M_PI / 180;
            r.model.x[RC_P_THETA(i)] += urand(-0.3, 0.3) * M_PI / 180;
        }
        FILE *m = fopen(argv[4], "w");
        rch_robot_info info = {0};
        info.ctrl = &r.ctrl;
        if (!m || rch_robot_write(m, r.name, &r.model, &r.nominal, &info) != 0 || fclose(m) != 0)
            return 1;
        /* read back: the FK is of the file as rcal reads it */
        if (rch_robot_load(&r, argv[4], &d) != 0) {
            fprintf(stderr, "urdf_fk_dump: %s\n", rch_diag_str(&d, msg, sizeof msg));
            return 1;
        }
    }
    FILE *f = fopen(argv[2], "w");
    if (!f)
        return 1;
    for (int n = 0; n < 200; ++n) {
        double q[RC_NJ], p[3];
        for (int i = 0; i < RC_NJ; ++i)
            q[i] = urand(fmax(r.model.q_min_rad[i], -M_PI), fmin(r.model.q_max_rad[i], M_PI));
        rch_ctrl_fk(p, NULL, &r.ctrl, &r.model, q);
        for (int i = 0; i < RC_NJ; ++i)
            fprintf(f, "%.17g,", q[i]);
        fprintf(f, "%.17g,%.17g,%.17g\n", p[0], p[1], p[2]);
    }
    return fclose(f) == 0 ? 0 : 1;
}
