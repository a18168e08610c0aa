/* SPDX-License-Identifier: MIT */
/* fuzz_data_common.h - one fuzz body for the CSV reader (rch_data_parse),
 * used with flags 0 (measurement files), RCH_DATA_NO_LEN (pose plans) and
 * RCH_DATA_POSE | RCH_DATA_ALLOW_EMPTY (acquisition files, as rch_acqfile reads them) and
 * RCH_DATA_POSITIONS | RCH_DATA_NO_LEN (tracker positions, as rch_pos_load reads them) and
 * RCH_DATA_TARGETS | RCH_DATA_NO_LEN (joint target lists, as rcal-rt --in reads them). */
#ifndef FUZZ_DATA_COMMON_H
#define FUZZ_DATA_COMMON_H

#include <math.h>
#include <stdint.h>
#include <string.h>

#include "fuzz_check.h"
#include "rch_data.h"

static void fuzz_data(const uint8_t *data, size_t size, unsigned flags)
{
    rch_data d;
    rch_diag diag;
    const double q_max = 720.0 * 3.14159265358979323846 / 180.0 * (1.0 + 1e-12);
    memset(&diag, 0, sizeof diag);
    /* The parser gets exactly size bytes (no NUL after them): ASan catches any
     * read past the end. */
    int rc = rch_data_parse(&d, (const char *)data, size, "fuzz.csv", flags, &diag);
    if (rc != 0) {
        /* refused: a message, nothing left allocated */
        FZ_CHECK(diag.msg[0] != '\0');
        FZ_CHECK(d.s == NULL && d.xyz == NULL && d.line == NULL && d.pose == NULL && d.sigma_mm == NULL && d.n == 0);
        return;
    }
    if (d.n == 0) { /* only with RCH_DATA_ALLOW_EMPTY (an acquisition file holding its header) */
        FZ_CHECK(flags & RCH_DATA_ALLOW_EMPTY);
        rch_data_free(&d);
        return;
    }
    FZ_CHECK(d.s != NULL && d.line != NULL);
    if (flags & RCH_DATA_POSITIONS)
        FZ_CHECK(d.xyz != NULL); /* required; pose and sigma_mm when present */
    else
        FZ_CHECK(((flags & RCH_DATA_POSE) != 0) == (d.pose != NULL) && d.sigma_mm == NULL);
    for (size_t i = 0; i < d.n; ++i) {
        const rc_sample *s = &d.s[i];
        for (int j = 0; j < RC_NJ; ++j)
            FZ_CHECK(isfinite(s->q_rad[j]) && fabs(s->q_rad[j]) <= q_max);
        if (flags & RCH_DATA_NO_LEN)
            FZ_CHECK(s->value == 0.0 || (s->value > 0.0 && s->value <= 20000.0));
        else
            FZ_CHECK(s->value > 0.0 && s->value <= 20000.0);
        /* documented: t scaled to [0, 1] */
        FZ_CHECK(isfinite(s->t) && s->t >= 0.0 && s->t <= 1.0);
        /* a header takes line 1, except in a target list without one (RCH_DATA_TARGETS) */
        FZ_CHECK(d.line[i] >= ((flags & RCH_DATA_TARGETS) ? 1u : 2u));
        if (i > 0)
            FZ_CHECK(d.line[i] > d.line[i - 1]);
        if (d.pose)
            FZ_CHECK(d.pose[i] <= 1000000000ul);
        FZ_CHECK(s->target < RC_MAX_TARGETS && s->sensor == RC_SENSOR_LENGTH);
        if (d.sigma_mm)
            FZ_CHECK(d.sigma_mm[i] > 0.0 && d.sigma_mm[i] <= 100.0);
        if (d.xyz)
            for (int k = 0; k < 3; ++k)
                FZ_CHECK(isfinite(d.xyz[i][k]));
    }
    if (flags & RCH_DATA_TARGETS) { /* the radians check on what was read: a verdict with its reason */
        double mx[RC_NJ] = {0};
        char why[320];
        why[0] = '\0';
        for (size_t i = 0; i < d.n; ++i)
            for (int j = 0; j < RC_NJ; ++j)
                mx[j] = fmax(mx[j], fabs(d.s[i].q_rad[j]) * (180.0 / 3.14159265358979323846));
        const int rad = rch_data_q_look_rad(why, sizeof why, mx, d.n);
        FZ_CHECK(rad == 0 || (rad == 1 && why[0] != '\0'));
    }
    rch_data_free(&d);
    FZ_CHECK(d.s == NULL && d.n == 0);
}

#endif
