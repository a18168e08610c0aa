/* SPDX-License-Identifier: MIT */
/* fuzz_touch.c - a file of another sensor through the sensor table
 * (rch_sensors.h): recognised by its header, parsed (rch_sensor_parse), its
 * effects added and started in closed form on the IRB120's nominal model
 * (the touch sensor: plates fitted to the touched points, the probe by least
 * squares). Invariants: a file not the sensor's is left alone; refused with a
 * message and nothing allocated, or every sample of the sensor's kind with a
 * label below RC_MAX_TARGETS and a finite value; the start either refuses with
 * a message or leaves every parameter finite. */
#include <math.h>
#include <stdint.h>
#include <string.h>

#include "fuzz_check.h"
#include "rch_sensors.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static const double dh[RC_NJ][4] = {{0, 290, -1.5707963267948966, 0}, {270, 0, 0, -1.5707963267948966},
                                        {70, 0, -1.5707963267948966, 0},  {0, 302, 1.5707963267948966, 0},
                                        {0, 0, -1.5707963267948966, 0},   {0, 72, 0, 0}};
    static const double enc[3] = {0.0, 0.0, 0.0};
    rc_model m;
    rch_data d;
    rch_diag dg;
    if (rc_model_init(&m, dh, enc) != RC_OK)
        return 0;
    const rch_sensor_desc *sd = rch_sensor_for_file((const char *)data, size);
    if (!sd)
        return 0;
    memset(&dg, 0, sizeof dg);
    if (rch_sensor_parse(&d, sd, (const char *)data, size, "fuzz.csv", size % 2 ? &m : NULL, &dg) != 0) {
        FZ_CHECK(dg.msg[0] != '\0');
        FZ_CHECK(d.s == NULL && d.n == 0 && d.line == NULL);
        return 0;
    }
    for (size_t i = 0; i < d.n; ++i)
        FZ_CHECK(d.s[i].sensor == sd->kind && d.s[i].target < RC_MAX_TARGETS && isfinite(d.s[i].value) &&
                 d.s[i].weight >= 0.0);
    memset(&dg, 0, sizeof dg);
    if (rch_sensors_add_effects(&m, d.s, d.n, &dg) == 0) {
        if (rch_sensors_start(&m, d.s, d.n, &dg) != 0)
            FZ_CHECK(dg.msg[0] != '\0');
        else
            for (unsigned k = 0; k < m.n_params; ++k)
                FZ_CHECK(isfinite(m.x[k]));
    }
    rch_data_free(&d);
    return 0;
}
