/* SPDX-License-Identifier: MIT */
/* rch_acqfile.h - the acquisition file: append-only, locked, resumable.
 *
 * Format (CSV, written here and nowhere else; read back by rch_data_parse,
 * the one reader of measurement files):
 *   pose,q1,q2,q3,q4,q5,q6,L,spread_mm,n_readings,t_unix_ms
 * one line per sample: plan index, joint angles (deg, %.4f), the sample's
 * mean length and spread (mm, %.4f), the readings it averages and the wall
 * clock (ms). Each line is written with one write(2) and fsync'ed at once.
 * A file of several encoder places (issue 20) has a last column, outlet (the
 * place's label, 0..255: RCH_ACQ_HEADER_OUTLET): the same plan run again from
 * another place appends to the same file, and a pose counts as done only for
 * the place it was measured from. A file's header decides: an outlet is
 * given exactly when the file has the column. The same for a cable hooked in
 * turn on the points of a tool plate: a last column target (after outlet)
 * names the point, each run records one.
 *
 * rch_acqfile_open() takes an exclusive lock on the file (fcntl F_SETLK,
 * held until rch_acqfile_close): a second acquisition on the same file is
 * refused with the holder's pid. It then reads what is already there,
 * bounded (regular files only, at most RCH_ACQ_MAX_BYTES, lines at most
 * RCH_ACQ_MAX_LINE bytes): an unfinished last line (an interrupted write, or
 * the NUL bytes a power cut leaves) is appended to "<path>.dropped" and cut
 * off; any other damage is refused with line and column, nothing changed.
 * Samples already recorded are never deleted or rewritten.
 *
 * Data path: serial byte -> reading (drivers) -> sample (lib/rc_stable) ->
 * this file -> rch_data -> fit.
 * Host side (prefix rch_): POSIX (open, fcntl, fsync), heap for the scan.
 */
#ifndef RCH_ACQFILE_H
#define RCH_ACQFILE_H

#include <stddef.h>

#include "rc_model.h"
#include "rc_stable.h"
#include "rch_diag.h"

#define RCH_ACQ_HEADER "pose,q1,q2,q3,q4,q5,q6,L,spread_mm,n_readings,t_unix_ms"
#define RCH_ACQ_HEADER_OUTLET RCH_ACQ_HEADER ",outlet"
#define RCH_ACQ_HEADER_TARGET RCH_ACQ_HEADER ",target"
#define RCH_ACQ_HEADER_OUTLET_TARGET RCH_ACQ_HEADER ",outlet,target"
/* A run driven by a controller (rcal acquire --controller, docs/controller-link.md) records the controller's
 * joints in q1..q6 (%.6f deg) and the plan's beside them in these last columns; the plan check on resuming
 * compares those. rch_data ignores them (unknown columns). */
#define RCH_ACQ_PLAN_COLS ",q1_plan,q2_plan,q3_plan,q4_plan,q5_plan,q6_plan"
#define RCH_ACQ_MAX_LINE 4096u                  /* longest line accepted when resuming */
#define RCH_ACQ_MAX_BYTES (256u * 1024u * 1024u) /* largest file resumed (about 2.5 M samples) */

typedef struct rch_acqfile {
    int fd;              /* -1 when closed */
    char path[1024];
    int outlet_p1;       /* 0 no outlet column, k + 1 the outlet label k recorded (rch_acqfile_open_outlet) */
    int target_p1;       /* 0 no target column, p + 1 the cable point p of a tool plate recorded (rch_acqfile_open_at) */
    int plan_cols;       /* 1: q1_plan..q6_plan columns (rch_acqfile_open_plan) */
} rch_acqfile;

/* What the file held when it was opened. */
typedef struct rch_acqfile_state {
    size_t n_done;          /* distinct plan poses already recorded */
    int has_last;           /* the file holds at least one sample */
    size_t last_pose;       /* plan index of the last sample in the file */
    double last_len_mm;     /* its length */
    size_t dropped_bytes;   /* unfinished tail moved to <path>.dropped */
} rch_acqfile_state;

/* Open or create path for appending, locked, and scan it against the plan.
 * plan_deg: (n_poses x 6) plan joint angles in degrees (4 decimals, as the
 * plan file has them); done: (n_poses) output, 1 for each pose recorded.
 * A sample whose angles differ from the plan's by more than 1e-3 deg, or
 * whose pose is not in the plan, is refused ("the file belongs to another
 * plan"). 0, or -1 with d set (and the file closed, unlocked, unchanged). */
int rch_acqfile_open(rch_acqfile *a, rch_acqfile_state *st, unsigned char *done, const char *path,
                     const double (*plan_deg)[RC_NJ], size_t n_poses, rch_diag *d);

/* rch_acqfile_open for the encoder place outlet_p1 - 1 (0: a file of one
 * place, no outlet column): poses count as done only when measured from it. */
int rch_acqfile_open_outlet(rch_acqfile *a, rch_acqfile_state *st, unsigned char *done, const char *path,
                            const double (*plan_deg)[RC_NJ], size_t n_poses, int outlet_p1, rch_diag *d);

/* rch_acqfile_open_outlet with the cable point target_p1 - 1 of a tool plate
 * (0: no target column): the file has a target column exactly when a point
 * is given, and poses count as done only for this outlet and point. */
int rch_acqfile_open_at(rch_acqfile *a, rch_acqfile_state *st, unsigned char *done, const char *path,
                        const double (*plan_deg)[RC_NJ], size_t n_poses, int outlet_p1, int target_p1, rch_diag *d);

/* rch_acqfile_open_at with plan_cols 1: the file has the last columns q1_plan..q6_plan (RCH_ACQ_PLAN_COLS),
 * q1..q6 are a controller's joints; a file with them is resumed only this way and one without them never. */
int rch_acqfile_open_plan(rch_acqfile *a, rch_acqfile_state *st, unsigned char *done, const char *path,
                          const double (*plan_deg)[RC_NJ], size_t n_poses, int outlet_p1, int target_p1, int plan_cols,
                          rch_diag *d);

/* Append one sample line and fsync. 0, or -1 with d set. */
int rch_acqfile_append(rch_acqfile *a, size_t pose, const double q_deg[RC_NJ], const rc_stable_result *r,
                       long long t_unix_ms, rch_diag *d);

/* rch_acqfile_append with the plan's joints beside (a file opened with plan_cols; plan_deg may be NULL
 * otherwise). */
int rch_acqfile_append_plan(rch_acqfile *a, size_t pose, const double q_deg[RC_NJ], const double plan_deg[RC_NJ],
                            const rc_stable_result *r, long long t_unix_ms, rch_diag *d);

/* Close and unlock (safe on a closed file). 0, or -1 with d set (may be NULL). */
int rch_acqfile_close(rch_acqfile *a, rch_diag *d);

#endif
