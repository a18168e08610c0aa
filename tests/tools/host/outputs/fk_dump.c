/* SPDX-License-Identifier: MIT */
/* fk_dump.c - rcal's forward kinematics at random joint vectors, for the
 * independent URDF reader (urdf_fk.py).
 *
 *   fk_dump MODEL.json N SEED  ->  N lines "q1,...,q6,x,y,z" (rad, mm, %.17g)
 *
 * q uniform inside the model's joint limits (rc_rng); x, y, z from rc_fk (the
 * tool point when the model has a tool offset). Exit 1 on a bad model. */
#include <stdio.h>
#include <stdlib.h>

#include "rc_model.h"
#include "rc_rand.h"
#include "rch_robot.h"
#include "rch_comp.h"

int main(int argc, char **argv)
{
    if (argc != 4) {
        fprintf(stderr, "usage: fk_dump MODEL.json N SEED\n");
        return 2;
    }
    static rch_robot r;
    rch_diag d;
    char msg[1024];
    if (rch_robot_load(&r, argv[1], &d) != 0) {
        fprintf(stderr, "fk_dump: %s\n", rch_diag_str(&d, msg, sizeof msg));
        return 1;
    }
    static rc_model pm; /* the flange: the URDF carries the robot, not the cable attachment */
    rch_comp_point_model(&pm, &r.model, NULL);
    const long n = strtol(argv[2], NULL, 10);
    rc_rng g;
    rc_rng_seed(&g, (uint64_t)strtoull(argv[3], NULL, 10));
    for (long k = 0; k < n; ++k) {
        double q[RC_NJ], p[3];
        for (unsigned i = 0; i < RC_NJ; ++i)
            q[i] = r.model.q_min_rad[i] + (r.model.q_max_rad[i] - r.model.q_min_rad[i]) * rc_rng_u01(&g);
        rc_fk(p, NULL, &pm, q);
        for (unsigned i = 0; i < RC_NJ; ++i)
            printf("%.17g,", q[i]);
        printf("%.17g,%.17g,%.17g\n", p[0], p[1], p[2]);
    }
    return fflush(stdout) == 0 ? 0 : 1;
}
