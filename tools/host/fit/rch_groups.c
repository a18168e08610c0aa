/* SPDX-License-Identifier: MIT */
/* rch_groups.c - set-up groups from the wrist joints (see rch_groups.h). */
#include "rch_groups.h"

#include <math.h>

#define DEG (3.14159265358979323846 / 180.0)

unsigned rch_groups_by_wrist(rc_sample *s, size_t n, double q_step_deg, unsigned *flicker)
{
    const double tol = (q_step_deg > 0.0 ? 1.5 * q_step_deg : 1e-9) * DEG;
    unsigned g = 0, fl = 0;
    for (size_t i = 0; i < n; ++i) {
        if (i > 0) {
            int same = 1, exact = 1;
            for (unsigned j = 3; j < RC_NJ; ++j) {
                const double dq = fabs(s[i].q_rad[j] - s[i - 1].q_rad[j]);
                same = same && dq <= tol;
                exact = exact && dq == 0.0;
            }
            if (!same)
                ++g;
            else if (!exact)
                ++fl;
        }
        s[i].group = (uint16_t)(g > 65535 ? 65535 : g);
    }
    if (flicker)
        *flicker = fl;
    return n ? g + 1 : 0;
}
