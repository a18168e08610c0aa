/* SPDX-License-Identifier: MIT */
/* rch_inputs.h - every input of a calibration, read and checked once: the
 * robot file, the cable-length files (merged), the laser-tracker positions
 * files, with the set-up groups, the outlets, the provenance and, when asked,
 * the joints dequantized. `rcal calibrate` (rch_calib_run) reads its inputs
 * through rch_inputs_load and nothing else; a study that takes the inputs
 * calibrate takes calls it with the same rch_calib_cfg.
 *
 * In this order, as rch_calib_run has always done it:
 *   1. the robot file (rch_robot_load);
 *   2. every cable file (rch_data_load_limited against the robot's joint limits, rch_data_check_units) merged in the
 *      order given: x, y, z kept only when every file has them; t becomes
 *      the acquisition order over all files; the group column kept only
 *      when every file has one (numbers offset per file);
 *   3. the set-up groups: the file's group column, else consecutive samples
 *      sharing the wrist joints at the joints' display step, never across
 *      two files (rch_groups_by_wrist);
 *   4. the provenance: each file, its samples and sha256, the date, the tool;
 *   5. the outlets (rch_data_outlets): an RC_EFF_OUTLET effect added to
 *      robot.model for each outlet after the first;
 *   6. the positions files (rch_pos_load), appended: three samples a row,
 *      one set-up group a file, the tracker frame and targets added to
 *      robot.model (the start frame cfg->tracker_start when given), their
 *      provenance after the cable files'; the cable files' x, y, z dropped;
 *   7. joint angles recovered from x, y, z (rch_dequant), inconsistent rows
 *      dropped: forced by cfg->dequantize, off with cfg->no_dequantize, and
 *      by default when the file shows rounding (the joints on a display step
 *      of 0.01 deg or coarser, x, y, z the nominal FK of finer angles, at most
 *      5 % of rows refused; the decision and its reason in dequant.why).
 *   8. the validation file (cfg->validate_path), within the robot's limits,
 *      kept as read in validate: only a fitted model reads its rows.
 * Each file is opened once (its digest taken from the bytes parsed); no
 * later stage and no command opens an input again.
 * Not here: the pipeline's own checks (--residuals with --cases, the cost
 * estimate), the effects a fit adds to the model (attachment, axis tilts,
 * --effects).
 *
 * Depends on: rch_calib_cfg, rch_data, rch_robot, rch_positions,
 * rch_dequant, rch_groups, rch_sha256. Memory: data and file_of on the heap
 * (rch_inputs_free). Errors: 0, or -1 with d set (file:line:col as the
 * readers give it); on failure *out holds nothing to free.
 */
#ifndef RCH_INPUTS_H
#define RCH_INPUTS_H

#include <stddef.h>
#include <stdint.h>

#include "rch_calib_cfg.h"
#include "rch_data.h"
#include "rch_dequant.h"
#include "rch_diag.h"
#include "rch_robot.h"

typedef struct rch_inputs {
    rch_data data;          /* merged samples: the cable files in the order given, then the positions rows
                               (three samples each); with dequantize the refused rows dropped */
    unsigned *file_of;      /* (data.n) input file of each sample: 0..n_files-1 the cable files, n_files +
                               k the positions file k */
    size_t n_files;         /* cable files (rch_calib_cfg_n_files; 0: positions only) */
    size_t counts[RCH_CALIB_MAX_FILES]; /* (n_files) samples read from each cable file */
    size_t n_read;          /* samples read (cable files, then positions), before dequantize dropped any */
    rch_robot robot;        /* the robot file; robot.model with the further outlets and, with positions, the
                               tracker frame and targets effects added */
    unsigned n_outlets;     /* encoder places in the data (column outlet; 1 without it) */
    uint8_t outlet_label[RC_MAX_OUTLETS]; /* (n_outlets) the file's label of outlet k (k = 0: e) */
    unsigned n_groups;      /* set-up groups (the positions files one each) */
    int groups_from_file;   /* the cable files' group column gave them */
    size_t n_pos_rows;      /* position rows read (three samples each) */
    size_t n_pos_poses;
    unsigned n_targets;
    int pos_has_sigma;
    double pos_sigma_mm;    /* the files' median sigma_mm (rows are weighed equally) */
    rch_provenance prov;    /* data files, samples, sha256, date, tool (paths point at cfg's strings) */
    int have_dequant;       /* the joints were dequantized (forced or automatic) */
    rch_dequant_result dequant;
    unsigned dequant_refused_lines[16]; /* first refused rows (file lines) */
    double (*read_q)[RC_NJ]; /* with cfg->keep_poses: every data file's rows' joints as parsed (rad, one a row,
                                before any is dequantized or dropped), the files in provenance order; else NULL */
    size_t read_n[RCH_PROV_MAX_FILES]; /* (prov.n_files) rows of each in read_q (0: a sensor file, no pose read) */
    rch_data validate;      /* cfg->validate_path's rows as read (labels as in the file), else empty */
} rch_inputs;

/* Read every input cfg names (robot_path, data_path / data_paths,
 * positions_paths; dequantize, have_tracker_start; cases, residuals_path
 * and jumps only to refuse them with positions). 0, or -1 with d set. */
int rch_inputs_load(rch_inputs *out, const rch_calib_cfg *cfg, rch_diag *d);
/* The inputs raw (read by rch_inputs_load with no_dequantize and keep_poses
 * from the files cfg names) as rch_inputs_load would read them for cfg:
 * copied, then dequantized as cfg says (step 7), read_q kept only with
 * cfg->keep_poses. No file is opened. rch_inputs_load does this when
 * cfg->inputs is set. 0, or -1 with d set (*out holds nothing to free). */
int rch_inputs_copy(rch_inputs *out, const rch_inputs *raw, const rch_calib_cfg *cfg, rch_diag *d);
/* Free data and file_of; in may be zeroed or freed already. */
void rch_inputs_free(rch_inputs *in);

#endif
