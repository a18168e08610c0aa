/* SPDX-License-Identifier: MIT */
/* fuzz_egm.c - rcal-rt's EGM decoder (rt_egm_decode: an EgmRobot datagram
 * from the network, issue 49) on any bytes. Invariants: a datagram is
 * either refused with a reason or gives six finite feedback joints (and six
 * finite planned ones when present) within +-1e6 deg; the decoder's arena
 * is never overrun (ASan); the reference guard fed with the decoded joints
 * keeps its bound (the change beyond the path's own at most its limit) and
 * the joint limits. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "rt_egm.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static rt_egm_arena arena;

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    rt_egm_robot r;
    char why[256];
    why[0] = '\0';
    if (rt_egm_decode(&r, why, sizeof why, &arena, data, size) != 0) {
        if (why[0] == '\0')
            abort(); /* a refusal always says why */
        return 0;
    }
    for (int i = 0; i < RT_EGM_NJ; ++i)
        if (!isfinite(r.fb_deg[i]) || fabs(r.fb_deg[i]) > 1e6 ||
            (r.has_planned && (!isfinite(r.planned_deg[i]) || fabs(r.planned_deg[i]) > 1e6)))
            abort();
    static const double lo[RT_EGM_NJ] = {-165, -110, -110, -160, -120, -400};
    static const double hi[RT_EGM_NJ] = {165, 110, 70, 160, 120, 400};
    rt_egm_guard g;
    rt_egm_guard_init(&g, 0.01, lo, hi);
    double t0[RT_EGM_NJ], t1[RT_EGM_NJ], s0[RT_EGM_NJ], s1[RT_EGM_NJ];
    for (int i = 0; i < RT_EGM_NJ; ++i) {
        t0[i] = fmin(fmax(r.fb_deg[i], lo[i]), hi[i]);
        t1[i] = fmin(fmax(r.has_planned ? r.planned_deg[i] : r.fb_deg[i], lo[i]), hi[i]);
    }
    rt_egm_guard_step(&g, s0, t0, t0);
    rt_egm_guard_step(&g, s1, t1, r.has_planned ? r.fb_deg : NULL); /* any "compensation", or a failed one */
    for (int i = 0; i < RT_EGM_NJ; ++i)
        if (!(fabs(s1[i] - s0[i]) <= fabs(t1[i] - t0[i]) + 0.01 + 1e-9 * (1.0 + fabs(t1[i]))) || s1[i] < lo[i] ||
            s1[i] > hi[i])
            abort();
    return 0;
}
