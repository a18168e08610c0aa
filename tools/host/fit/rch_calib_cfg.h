/* SPDX-License-Identifier: MIT */
/* rch_calib_cfg.h - what `rcal calibrate` is asked to do: the input files and
 * the options of one calibration (rch_calib_cfg), read by the inputs
 * (rch_inputs_load) and by the pipeline (rch_calib_run).
 *
 * Depends on: the core (rc_method). Memory: the configuration points at the
 * caller's strings and owns nothing. Errors: none (plain data).
 */
#ifndef RCH_CALIB_CFG_H
#define RCH_CALIB_CFG_H

#include <stddef.h>

#include "rc_solve.h"

#define RCH_CALIB_MAX_FILES 16
struct rch_inputs; /* rch_inputs.h */
typedef struct rch_calib_cfg {
    const char *data_path;  /* measurements CSV (required; the first of data_paths when several) */
    const char *const *data_paths; /* (n_data_paths) several files merged, NULL: data_path alone */
    size_t n_data_paths;
    const char *validate_path; /* data the fit never sees: evaluated with no refit, or NULL */
    const char *plots_dir;  /* predicted-uncertainty plot and its CSV, or NULL */
    const char *robot_path; /* nominal robot model (required) */
    const char *truth_path; /* simulated truth model, or NULL */
    const char *fix;        /* parameters held at nominal ("a1,theta6"), or NULL */
    rc_method method;
    double test_fraction;   /* share held out, [0, 1) */
    unsigned long seed;     /* split and LTLM seed */
    unsigned max_iter;      /* 0: the method's default */
    int tool_offset;        /* 1: also identify the cable attachment in the flange frame */
    const char *effects;    /* effects fitted with the geometry (rch_calib_effects), or NULL */
    int jumps;              /* 1: fit length jumps at change points in acquisition order (nuisance, rch_jumps) */
    int dequantize;         /* 1: recover rounded joint angles from the file's x, y, z (rch_dequant), refused
                               without them; 0: automatic, when the joints sit on a display step and x, y, z
                               are the nominal FK of finer angles (rch_inputs) */
    int no_dequantize;      /* 1: the joints as read, never dequantized */
    int holdout_groups;     /* 1: hold out whole set-up groups instead of random rows */
    unsigned long cases;    /* > 1: repeat on `cases` random subsets (the paper's protocol) */
    size_t case_samples;    /* rows per case (0: every row) */
    const char *residuals_path; /* per-sample residual CSV (rch_resid.h) of a single run, or NULL */
    int no_jump_check;      /* 1: the default run does not look for length jumps (rch_calib_save_model
                               refuses a model fitted across jumps it found) */
    int prior_stated;       /* 1: the prior's sd as stated, not scaled from the data (rch_prior_scale) */
    int no_prior;           /* 1: least squares without the physical prior (rch_prior.h), no cable
                               attachment vector unless asked, no gauge: the earlier behaviour */
    const char *const *positions_paths; /* (n_positions_paths) laser-tracker positions files
                                           (rch_positions.h), merged after the data; data_path may
                                           then be NULL */
    size_t n_positions_paths;
    int have_tracker_start; /* tracker_start is the tracker frame's start (else closed form) */
    double tracker_start[6]; /* T (mm) and the rotation vector (rad) of the base in the tracker's frame */
    int no_screen;          /* 1: every row fitted, none screened out (rch_calib_screen.c) */
    int keep_poses;         /* 1: the result keeps each data file's poses as read (rch_calib_result.read_q, for
                               --report's figures; freed by rch_calib_result_free) */
    int timing;             /* 1: the JSON carries the plan's timing record ("timing": each stage's time) */
    const char *data_text;  /* the one data file's rows in memory (CSV, data_text_len bytes; the Python
                               library's arrays): data_path only names them, nothing is read from disk */
    size_t data_text_len;
    double max_minutes;     /* refuse a run estimated longer (rch_calib_estimate_s); 0: 60 */
    unsigned n_cable_points; /* points of a tool plate the cable is hooked on in turn (the data's target
                                column names them; RC_EFF_CABLE_POINTS), 0: none */
    double cable_points_mm[RC_MAX_TARGETS][3]; /* (n_cable_points x 3) their nominal coordinates, flange frame */
    double cable_point_sd_mm; /* their tolerance (prior sd of each coordinate); 0: RCH_PRIOR_POINTS_MM */
    int no_length_offset;   /* 1: a length offset (display zero) is never weighed by default (rch_calib_sys.c) */
    int no_drift;           /* 1: a drift over the run is never weighed by default */
    int force;              /* 1: write a model the judge refuses (its noise far beyond the sensor's) */
    double sensor_sd_mm;    /* the length sensor's repeatability (with the robot's); 0: RCH_JUDGE_SENSOR_SD_MM */
    double display_step_mm; /* the lengths' display step; 0: from the data's digits */
    double joint_step_deg;  /* the joints' display step; < 0: from the data's digits; 0 given: none */
    int joint_step_given;
    const struct rch_inputs *inputs; /* the inputs read already (rch_inputs_load with no_dequantize and keep_poses,
                                        of the files this cfg names): copied, dequantized as this cfg says, never
                                        read again (rch_inputs_copy); NULL: read them */
} rch_calib_cfg;

/* The defaults of `rcal calibrate`: everything zero or NULL but method LM,
 * test fraction 0.1, seed 1, one case. */
void rch_calib_cfg_init(rch_calib_cfg *cfg);

/* The cable-length files of cfg: data_paths when given, else data_path
 * alone; 0 with tracker positions only. */
size_t rch_calib_cfg_n_files(const rch_calib_cfg *cfg);
/* The --cable-point values v (n, "X,Y,Z" mm each, flange frame) into
 * cfg->cable_points_mm, n_cable_points. 0, or -1 with err naming the value. */
int rch_calib_cfg_cable_points(rch_calib_cfg *cfg, const char *const *v, size_t n, char *err, size_t errlen);
/* The same into pts (RC_MAX_TARGETS x 3) and *n_out: the one parser of --cable-point. */
int rch_cable_points_parse(double (*pts)[3], unsigned *n_out, const char *const *v, size_t n, char *err, size_t errlen);
/* Cable-length file i (< rch_calib_cfg_n_files). */
const char *rch_calib_cfg_file(const rch_calib_cfg *cfg, size_t i);

#endif
