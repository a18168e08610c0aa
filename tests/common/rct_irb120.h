/* SPDX-License-Identifier: MIT */
/* rct_irb120.h - the one IRB120 fixture of the C tests that link the core
 * alone (no model-file reader): the nominal DH table and joint limits of
 * data/irb120.json, in the file's units (mm, degrees). Host tests load
 * data/irb120.json itself; host_fixture checks that the two agree, so they
 * cannot drift apart. */
#ifndef RCT_IRB120_H
#define RCT_IRB120_H

/* (6 x 4) a_mm, d_mm, alpha_deg, theta_offset_deg */
static const double rct_irb120_dh_deg[6][4] = {
    {0, 290, -90, 0}, {270, 0, 0, -90}, {70, 0, -90, 0}, {0, 302, 90, 0}, {0, 0, -90, 0}, {0, 72, 0, 0},
};
/* (6 x 2) joint limits, degrees */
static const double rct_irb120_lim_deg[6][2] = {{-165, 165}, {-110, 110}, {-110, 70},
                                                {-160, 160}, {-120, 120}, {-400, 400}};

/* The table with angles in radians, into dh (6 x 4). */
static inline void rct_irb120_dh(double dh[6][4])
{
    for (int i = 0; i < 6; ++i)
        for (int k = 0; k < 4; ++k)
            dh[i][k] = rct_irb120_dh_deg[i][k] * (k < 2 ? 1.0 : 3.14159265358979323846 / 180.0);
}

#endif /* RCT_IRB120_H */
