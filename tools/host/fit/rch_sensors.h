/* SPDX-License-Identifier: MIT */
/* rch_sensors.h - the sensors a data file may come from besides the cable
 * and the laser tracker, as one table the calibration reads.
 *
 * A sensor is a source of rows (issue 50): its kind in lib's RC_SENSORS with
 * the hook that predicts a row, its effects in RC_EFFECTS (side
 * RC_SIDE_SENSOR), and here one descriptor: the column that names its file
 * and labels its rows (rc_sample.target), its value column if it reads one,
 * how its effects are added and started. `rcal calibrate --data FILE` takes
 * a file of such a sensor by its header (rch_inputs.c); everything after
 * the read (the split, the fit, the identifiability, the posterior, the
 * judge, the figures) sees samples of a kind with a unit, not the sensor.
 * Adding a sensor: its row in RC_SENSORS and effects in lib/rc_model.h, its
 * hook (lib/), its descriptor (a file of its own here) and one line in the
 * table of rch_sensors.c (DESIGN.md, "... a sensor").
 * Host side (prefix rch_sensor_). Memory: rch_sensor_parse allocates as
 * rch_data does (rch_data_free).
 */
#ifndef RCH_SENSORS_H
#define RCH_SENSORS_H

#include <stddef.h>

#include "rc_model.h"
#include "rch_data.h"
#include "rch_diag.h"

typedef struct rch_sensor_desc {
    unsigned kind;      /* its rc_sensor_kind (lib's RC_SENSORS) */
    const char *name;   /* "touch": messages and the report */
    const char *label;  /* the column that names its file and labels its rows ("plane": rc_sample.target) */
    const char *labels; /* what a label numbers, plural ("planes") */
    const char *value;  /* its measured value's column (optional in a file: 0 without it), NULL: none */
    const char *doc;    /* its docs page ("docs/touches.md") */
    /* Add its effects to m for labels 0 .. n_labels - 1 (none when present). 0, or -1 (capacity). */
    int (*add_effects)(rc_model *m, unsigned n_labels);
    /* Closed-form start of its effects at m's geometry from its samples among s (n): what the fit
     * starts from. 0, or -1 with d set (the rows cannot place them). */
    int (*start)(rc_model *m, const rc_sample *s, size_t n, rch_diag *d);
    /* What the data s (n, every sensor's) leave unseen that the report must say (one sentence into note,
     * note_len), or "" (NULL: nothing to say). */
    void (*caveat)(char *note, size_t note_len, const rc_sample *s, size_t n);
    const char *words;  /* its data in words, for the report ("plate touches") */
    const char *gauge;  /* why theta1 and d1 are held with its data alone ("the plates' places absorb ...") */
    const char *advice; /* the next step when its poses leave the geometry to the prior */
    int tip_effect;     /* its point on the flange: an rc_effect_kind of three parameters x, y, z ("the <name> tip" in
                           the identifiability's reasons, as the cable attachment's tool_offset), -1: none */
} rch_sensor_desc;

/* The sensor whose file text (len) is, by its header's label column; NULL:
 * none (a cable file, or another). */
const rch_sensor_desc *rch_sensor_for_file(const char *text, size_t len);
/* The descriptor of sensor kind kind, NULL when it has none. */
const rch_sensor_desc *rch_sensor_of_kind(unsigned kind);

/* Parse text (len) as a file of sd named name (joints within limits' when
 * not NULL): rch_data_parse_sensor, then each sample's kind set and, with a
 * sigma_mm column, its weight the median sigma over its own (rc_sample.weight,
 * as a tracker file's). 0, or -1 with d set. */
int rch_sensor_parse(rch_data *out, const rch_sensor_desc *sd, const char *text, size_t len, const char *name,
                     const rc_model *limits, rch_diag *d);

/* Every sensor with samples in s (n): its effects added to m for the labels
 * its samples use. 0, or -1 with d set (capacity). */
int rch_sensors_add_effects(rc_model *m, const rc_sample *s, size_t n, rch_diag *d);
/* Every sensor with samples in s (n): its start (sd->start). 0, or -1 with d set. */
int rch_sensors_start(rc_model *m, const rc_sample *s, size_t n, rch_diag *d);

/* Samples of s (n) of a sensor in the table (not lengths, not the tracker's). */
size_t rch_sensors_count(const rc_sample *s, size_t n);

#endif /* RCH_SENSORS_H */
