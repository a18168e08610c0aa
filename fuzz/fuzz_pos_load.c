/* SPDX-License-Identifier: MIT */
/* fuzz_pos_load.c - the positions layer over the CSV reader (rch_pos_parse:
 * what rch_pos_load does to each file): the row checks (reused pose
 * numbers, targets, duplicate rows) and, with the IRB120's nominal model,
 * the scale, the mirrored frame and the controller's positions (the Kabsch
 * fits). Invariants: refused with a message and nothing allocated, or three
 * samples a kept row, every pose number below the poses' count. */
#include <math.h>
#include <stdint.h>
#include <string.h>

#include "fuzz_check.h"
#include "rc_sensor.h"
#include "rch_positions.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static const double dh[RC_NJ][4] = {{0, 290, -1.5707963267948966, 0}, {270, 0, 0, -1.5707963267948966},
                                        {70, 0, -1.5707963267948966, 0},  {0, 302, 1.5707963267948966, 0},
                                        {0, 0, -1.5707963267948966, 0},   {0, 72, 0, 0}};
    static const double enc[3] = {250.0, -460.0, 10.0};
    rc_model m;
    rch_pos p;
    rch_diag d;
    int rc;
    if (rc_model_init(&m, dh, enc) != RC_OK)
        return 0;
    memset(&d, 0, sizeof d);
    /* with and without the model; duplicate rows warn on stderr */
    rc = rch_pos_parse(&p, (const char *)data, size, "fuzz.csv", size % 2 ? &m : NULL, &d);
    if (rc != 0) {
        FZ_CHECK(d.msg[0] != '\0');
        FZ_CHECK(p.s == NULL && p.n == 0 && p.line == NULL && p.file == NULL);
        return 0;
    }
    FZ_CHECK(p.n == 3 * p.rows && p.rows >= 1 && p.poses >= 1 && p.n_targets >= 1 && p.n_targets <= RC_MAX_TARGETS);
    for (size_t i = 0; i < p.n; ++i) {
        FZ_CHECK(p.s[i].sensor == RC_SENSOR_TRACKER_X + i % 3 && isfinite(p.s[i].value));
        FZ_CHECK(p.s[i].t >= 0.0 && p.s[i].t < (double)p.poses && p.s[i].target < p.n_targets);
        FZ_CHECK(p.line[i] >= 2 && p.file[i] == 0);
    }
    rch_pos_free(&p);
    return 0;
}
