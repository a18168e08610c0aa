/* SPDX-License-Identifier: MIT */
/* rch_sensors.c - the table of sensors read from data files (rch_sensors.h). */
#include "rch_sensors.h"

#include <stdlib.h>
#include <string.h>

#include "rch_stats.h"

/* The table: one line per sensor (its descriptor is defined in its own file). */
extern const rch_sensor_desc rch_sensor_touch; /* rch_sensor_touch.c: points touched on plates */
static const rch_sensor_desc *const sensors[] = {
    &rch_sensor_touch,
    NULL /* the end */
};

const rch_sensor_desc *rch_sensor_for_file(const char *text, size_t len)
{
    for (size_t i = 0; sensors[i] != NULL; ++i)
        if (rch_data_header_has(text, len, sensors[i]->label))
            return sensors[i];
    return NULL;
}

const rch_sensor_desc *rch_sensor_of_kind(unsigned kind)
{
    for (size_t i = 0; sensors[i] != NULL; ++i)
        if (sensors[i]->kind == kind)
            return sensors[i];
    return NULL;
}

int rch_sensor_parse(rch_data *out, const rch_sensor_desc *sd, const char *text, size_t len, const char *name,
                     const rc_model *limits, rch_diag *d)
{
    if (rch_data_parse_sensor(out, text, len, name, sd->label, sd->value, limits, d) != 0)
        return -1;
    for (size_t i = 0; i < out->n; ++i)
        out->s[i].sensor = (uint8_t)sd->kind;
    if (out->sigma_mm && out->n > 0) {
        double *v = malloc(out->n * sizeof *v);
        if (!v) {
            rch_data_free(out);
            rch_diag_set(d, name, 0, 0, "out of memory");
            return -1;
        }
        double med, mx;
        memcpy(v, out->sigma_mm, out->n * sizeof *v);
        rch_median_max(&med, &mx, v, out->n);
        free(v);
        for (size_t i = 0; i < out->n; ++i)
            out->s[i].weight = med / out->sigma_mm[i];
    }
    return 0;
}

/* The labels kind's samples among s (n) use: the largest + 1, 0 without samples. */
static unsigned labels_used(const rc_sample *s, size_t n, unsigned kind)
{
    unsigned k = 0;
    for (size_t i = 0; i < n; ++i)
        if (s[i].sensor == kind && s[i].target + 1u > k)
            k = s[i].target + 1u;
    return k;
}

int rch_sensors_add_effects(rc_model *m, const rc_sample *s, size_t n, rch_diag *d)
{
    for (size_t i = 0; sensors[i] != NULL; ++i) {
        const unsigned k = labels_used(s, n, sensors[i]->kind);
        if (k > 0 && sensors[i]->add_effects(m, k) != 0) {
            rch_diag_set(d, "", 0, 0, "no room in the model for the %s sensor's effects of %u %s (RC_MAX_EFFECTS, "
                         "RC_MAX_PARAMS)", sensors[i]->name, k, sensors[i]->labels);
            return -1;
        }
    }
    return 0;
}

int rch_sensors_start(rc_model *m, const rc_sample *s, size_t n, rch_diag *d)
{
    for (size_t i = 0; sensors[i] != NULL; ++i)
        if (labels_used(s, n, sensors[i]->kind) > 0 && sensors[i]->start(m, s, n, d) != 0)
            return -1;
    return 0;
}

size_t rch_sensors_count(const rc_sample *s, size_t n)
{
    size_t c = 0;
    for (size_t i = 0; i < n; ++i)
        c += rch_sensor_of_kind(s[i].sensor) != NULL;
    return c;
}
