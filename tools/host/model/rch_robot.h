/* SPDX-License-Identifier: MIT */
/* rch_robot.h - robot-model and calibrated-model files (JSON).
 *
 * Formats "rcal-model/1" and "rcal-model/2" (docs/model-format.md; lengths
 * in mm, angles in degrees); version 2 adds "uncertainty", "provenance":
 * {
 *   "format": "rcal-model/1",
 *   "name": "ABB IRB120",
 *   "dh": [ {"a_mm": 0, "d_mm": 290, "alpha_deg": -90, "theta_deg": 0}, ... 6 rows ],
 *   "joint_limits_deg": [[-165, 165], ... 6 pairs],          (optional, default +-180)
 *   "encoder_mm": [x, y, z],                                  (optional in a robot file)
 *   "effects": [ {"kind": "joint_periodic", "joint": 3,       (optional model extensions;
 *                 "params": [...], "ref_dh": [[a, d, alpha, theta] x 4]} ],  joint 1-based,
 *                                                              params in SI: mm, rad, rad/m)
 *   "prior": {"length_mm": 0.5, "twist_deg": 0.1, "offset_deg": 1.0, "attachment_mm": 100},
 *                                 (optional: tolerances before the data, rch_prior.h)
 *   "nominal": { "dh": [...] },   (calibrated model: the nominal table it corrects)
 *   "calibration": { ... }        (calibrated model: informational, not read back)
 * }
 * theta_deg is the joint offset: theta_i = q_i + theta_deg_i.
 */
#ifndef RCH_ROBOT_H
#define RCH_ROBOT_H

#include <stdio.h>

#include "rc_model.h"
#include "rch_cell.h"
#include "rch_ctrl.h"
#include "rch_diag.h"
#include "rch_jw.h"
#include "rch_data.h"
#include "rch_prior.h"
#include "rch_uncert.h"

/* Link lengths (a, d) beyond this are refused as a wrong model file. */
#define RCH_ROBOT_MAX_LINK_MM 5000.0

typedef struct rch_robot {
    char name[128];
    rc_model model;     /* the model in the file (calibrated or nominal) */
    rc_model nominal;   /* "nominal" member if present, else == model without effects */
    int has_encoder;    /* encoder_mm was given */
    int has_nominal;    /* the file is a calibrated model with a nominal table */
    rch_model_unc unc;  /* rcal-model/2 "uncertainty" (unc.present == 0 for version 1) */
    rch_prior_cfg prior; /* "prior" member: tolerances by parameter type (defaults where absent) */
    /* from the informational "calibration" member (absent: 0, ""): */
    unsigned n_cal_jumps;   /* "length_jumps": steps of the cable length fitted as nuisance of that acquisition,
                               never applied to new data */
    double cal_jump_max_mm; /* the largest |size_mm| of them */
    char cal_data[512];     /* "data": the file the model was calibrated on */
    unsigned n_outlet_labels; /* "outlet_labels": the data files' label of outlet k (k = 0: encoder_mm, k the
                                 outlet effect numbered k); 0: absent (the labels are the numbers) */
    uint8_t outlet_label[RC_MAX_OUTLETS];
    rch_cell cell;          /* "links" (the arm's capsules) and "cell" (floor, boxes): rch_cell.h; empty when
                               absent */
    rch_ctrl ctrl;          /* "controller": the controller's joint signs, zeros, J2/J3 coupling and flange frame
                               (rch_ctrl.h); the identity when absent */
} rch_robot;

/* Where a calibration came from (rcal-model/2 "provenance"). */
#define RCH_PROV_MAX_FILES 16
typedef struct rch_provenance {
    unsigned n_files;
    const char *file[RCH_PROV_MAX_FILES];   /* as given */
    size_t samples[RCH_PROV_MAX_FILES];
    char sha256[RCH_PROV_MAX_FILES][65];
    char date[32];                          /* UTC, ISO 8601 */
    const char *tool;                       /* "rcal 0.1.0" */
} rch_provenance;

/* A model file; a path ending in ".urdf" (any case) is a URDF read by
 * rch_urdf_robot_load (rch_urdf_in.h): a six-joint serial chain turned into
 * the DH table. */
int rch_robot_load(rch_robot *out, const char *path, rch_diag *d);
int rch_robot_parse(rch_robot *out, const char *text, size_t len, const char *name, rch_diag *d);

/* The "calibration" member of a model file: write() adds its members through
 * the JSON writer (so every string is escaped); ctx is passed through. */
typedef struct rch_robot_info {
    void (*write)(rch_jw *w, const void *ctx);
    const void *ctx;
    /* rcal-model/2 (all may be NULL; with unc the file is version 2): */
    const rch_model_unc *unc;      /* uncertainty, classes, determined model */
    const rc_model *determined;    /* the model compensation uses */
    const rch_provenance *prov;
    const uint8_t *outlet_label;   /* (n_outlets) the data's label of outlet k, written as "outlet_labels" when
                                      they are not simply 0, 1, ... (NULL: none) */
    unsigned n_outlets;
    const rch_ctrl *ctrl;          /* the nominal file's "controller" member, written back when present (NULL:
                                      none) */
} rch_robot_info;

/* Write a model file through rch_jw (every string escaped, non-finite numbers
 * null). nominal may be NULL; info may be NULL (no "calibration" member).
 * Returns 0, or -1 on a write error. */
int rch_robot_write(FILE *f, const char *name, const rc_model *m, const rc_model *nominal,
                    const rch_robot_info *info);

/* Pieces of the uncertainty and provenance members, shared by the model
 * file and `rcal calibrate --json`: the "parameters" array (value, standard
 * error, class, compensation use; values printed with value_fmt), the
 * "position95_mm" and "orientation95_deg" objects, the "provenance" object. */
void rch_robot_write_unc_params(rch_jw *w, const rc_model *m, const rch_model_unc *u, const char *value_fmt);

/* Undetermined DH parameters (issue 33): a standard error above 1 m or
 * 1 rad is no calibration's result but a direction the data did not see (a
 * no-prior fit's weak one). The model file lists them by name in
 * "uncertainty": {"undetermined": ["alpha5", ...]}, their "std_error" and
 * their rows and columns of "covariance_dh" null; read back, such a
 * parameter has se NaN and in cov_dh an infinite variance and zero
 * covariances, so every figure that uses a standard error leaves it out as
 * it does a not-identifiable one (compensation holds it nominal: a file
 * that says otherwise is refused). 1: DH parameter k of u is undetermined
 * (cov_dh[k][k] beyond the limit or not a number). */
#define RCH_UNDETERMINED_MM2 1e6
#define RCH_UNDETERMINED_RAD2 1.0
int rch_robot_unc_undetermined(const rch_model_unc *u, unsigned k);
void rch_robot_write_unc_map(rch_jw *w, const rch_uncert_map *mp);
void rch_robot_write_provenance(rch_jw *w, const rch_provenance *p);

/* A command's two inputs: the robot (or calibrated) model file and a data
 * file, its joints inside the model's limits. 0, or -1 with d set (nothing
 * left allocated). */
/* The data's outlet labels (rc_sample.outlet as read) replaced by the
 * model's outlet numbers through robot's "outlet_labels" (when the file has
 * them; else the labels are the numbers, as before). A label the model has
 * no outlet for is refused with the file's line. lines (n) may be NULL. 0,
 * or -1 with d set. */
int rch_robot_outlets_of(const struct rch_robot *robot, rc_sample *s, size_t n, const unsigned *lines,
                         const char *name, rch_diag *d);

int rch_load_model_and_data(rch_robot *robot, const char *model_path, rch_data *data, const char *data_path,
                            rch_diag *d);

#endif
