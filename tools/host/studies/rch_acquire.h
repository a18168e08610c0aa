/* SPDX-License-Identifier: MIT */
/* rch_acquire.h - recording cable lengths pose by pose (`rcal acquire`).
 *
 * For each pose of a plan not yet in the output: announce it (for the robot
 * side), wait for the arm to settle, read the display (drivers/rcd_display)
 * and feed every reading to the stability rule (lib/rc_stable) until it
 * gives a sample, check that the sample follows the move, and append it to
 * the acquisition file (rch_acqfile: locked, append-only, fsync'ed).
 *
 * Never a silent wrong value:
 *  - ASCII frames pass the display's format lock, STX/Modbus frames their
 *    checksum, every reading the physical range [min_mm, max_mm];
 *  - a sample must follow the move: from the last recorded pose to this one
 *    the length must change by what the nominal model predicts, within
 *    follow_tol_mm (default 10 mm; see rch_acq_config). A display that did
 *    not change (HOLD pressed, firmware hung) or another device on the port
 *    fails it: the pose is measured again after --settle-ms, up to `retries`
 *    times, then the run stops loudly; the sample is never recorded. The
 *    check holds at every place of the encoder (--outlet N predicts from
 *    --encoder, that place's position) and on every point of a tool plate
 *    (--target P predicts to --cable-point P); where no prediction can be
 *    made the run stops before recording anything, saying what is missing
 *    and which option supplies it (--no-follow-check is the only way to
 *    run unchecked). The first sample of a place and point in a file has
 *    nothing to be compared with: it is held, not written, until the next
 *    pose's sample follows it (both are then written, in order), so a
 *    display frozen from the start is never recorded either: refused at the
 *    next pose, the held sample is dropped too. A run that stops for any
 *    other reason (a device reading otherwise after a reconnect, a timeout)
 *    writes it unchecked, as before, so that a rerun re-reads it; so does a
 *    run with a single pose, with a warning. The
 *    same check is what a display that reappears after a reconnect must pass
 *    (its format lock is kept, so its protocol settings must match as well);
 *  - the device must still read what it read (issue 23): after a reconnect,
 *    when a run resumes a file, and when a sample changes by more than
 *    jump_mm from what the nominal model predicts (a length jump suspected),
 *    the run first goes back to the last recorded pose (announced like any
 *    pose; with --confirm the operator is asked to return there) and reads it
 *    again. Within verify_tol_mm of the recorded length: the device is the
 *    same, the run goes on (a suspected jump was the nominal model's error;
 *    the pose is measured again and recorded). Off: a slipped cable, a
 *    counter reset, a display re-zeroed or another device; by default the
 *    run stops with nothing recorded after that pose (on_jump_record: the
 *    jump is reported, counted in jumps[], and the run goes on from the
 *    re-read length: calibrate's jump check sees it in the file's order);
 *  - the stability rule refuses a display still creeping (lib/rc_stable:
 *    the trend test, its time constant learnt and kept for the whole run);
 *  - every plan pose must lie inside the robot's joint limits;
 *  - no output path may name an input (--out, --announce, --poses,
 *    --robot, by device and inode).
 * Anything else is retried, reported, or stops the run with a message that
 * says how to resume (rerun the same command).
 *
 * Data path: serial byte -> reading (rcd_proto, rcd_display) -> sample
 * (rc_stable) -> acquisition file (rch_acqfile) -> rch_data -> fit.
 * Host side (prefix rch_): stdio for progress, heap for the plan.
 */
#ifndef RCH_ACQUIRE_H
#define RCH_ACQUIRE_H

#include <stddef.h>
#include <stdio.h>

#include "rc_model.h"
#include "rc_stable.h"
#include "rcd_display.h"
#include "rch_acqtime.h"
#include "rch_link.h"

/* How the acquisition reaches the world. Pass NULL to rch_acquire_run for
 * the real one (backend "serialport" or "posix", nanosleep, wall clock,
 * Enter on stdin); tests pass a mock port and a simulated clock. */
typedef struct rch_acq_io {
    /* open path with cfg; *port stays valid until close */
    rc_status (*open)(void *ctx, rcd_port **port, const char *path, const rcd_serial_config *cfg);
    void (*close)(void *ctx);
    void (*sleep_ms)(void *ctx, rcd_port *port, unsigned long ms);
    long long (*wall_ms)(void *ctx);   /* recorded in t_unix_ms */
    int (*confirm)(void *ctx, size_t pose); /* --confirm: 0 go on, -1 stop */
    /* The joint-angle source: the q1..q6 (deg) recorded for pose `pose`.
     * NULL: the plan's own angles (the robot program visits the planned
     * poses). A controller stream (RAPID socket, EGM) plugs in here; it may
     * block until the motion is finished. 0, or -1 to stop the run. Its
     * q_deg are the controller's numbers: mapped to the model's by the
     * robot file's "controller" member (rch_ctrl.h; identity when absent). */
    int (*joints)(void *ctx, double q_deg[RC_NJ], const double plan_deg[RC_NJ], size_t pose);
    void *ctx;
} rch_acq_io;

typedef struct rch_acq_config {
    const char *port_path;      /* device */
    const char *backend;        /* "serialport" or "posix" (real io only) */
    const char *poses_path;     /* plan: pose,q1..q6 (deg) */
    const char *out_path;       /* acquisition file */
    const char *announce_path;  /* "INDEX q1..q6" for the robot side; NULL: none */
    const char *robot_path;     /* nominal model: joint limits and the follow check */
    double encoder_mm[3];       /* cable outlet when the robot file has none; with outlet_p1 > 1 the place
                                   this run measures from (when encoder_given) */
    int encoder_given;          /* 1: encoder_mm was given (--encoder). An outlet other than 0 needs it, or a
                                   robot model with that outlet (RC_EFF_OUTLET), for the follow check */
    rcd_serial_config ser;
    rcd_proto_config proto;
    rc_stable_config stable;    /* n, tol_mm, [min_mm, max_mm], timeout_ms (pose timeout) */
    unsigned long settle_ms;        /* wait after announcing a pose */
    unsigned long read_timeout_ms;  /* one reading, >= 1 */
    unsigned long retries;          /* failures in a row before reopening; reopens and follow-check
                                       refusals per pose before stopping; >= 1 */
    unsigned long reconnect_s;      /* keep trying to reopen this long */
    unsigned long poll_interval_ms; /* polled protocols ask at most this often */
    /* follow check: |dL_measured - dL_nominal| <= follow_tol_mm between the
     * last recorded pose and this one. 10 mm by default: with the nominal
     * IRB120 model (outlet 250,-460,10) the worst miss over the 1,041 moves
     * of the real data set (robotcali.csv) is 6.3 mm, mean 0.85 mm, and
     * 3.0 mm on simulated robots (`rcal simulate`, seeds 1-5): the nominal
     * kinematics are off by a few mm, which is what calibration corrects.
     * A frozen display misses by the whole predicted change, so it is caught
     * at the first move that changes the length by more than 10 mm (54 % of
     * the real data's small consecutive moves; most moves of a D-optimal
     * plan). Raise it when the outlet position is only roughly known. */
    double follow_tol_mm;       /* > 0 */
    /* jump check: a miss above jump_mm (< follow_tol_mm) sends the run back
     * to the last recorded pose (see above). 3 mm by default: the nominal
     * IRB120 model misses by more than 3 mm on 18 (1.7 %) of the real data's
     * 1,041 moves (99th percentile 3.56 mm, worst 6.27 mm), so a 5 mm jump
     * is caught unless the model's own miss cancels 2 mm of it, at the cost
     * of one extra move for about 1 pose in 58. The check at the pose, not
     * the threshold, decides: a false alarm costs a move, never a sample. */
    double jump_mm;             /* > 0; >= follow_tol_mm: off */
    double verify_tol_mm;       /* re-read at the last recorded pose agrees within this; 0: stable.tol_mm */
    int on_jump_record;         /* 0: stop at a confirmed jump (default); 1: report it and go on */
    int no_follow_check;        /* 1: skip it (a plan of tiny moves) */
    int outlet_p1;              /* 0: one encoder place; k + 1: this run measures from outlet k (the file's
                                   outlet column). k > 0: the follow check predicts from encoder_mm when
                                   encoder_given, else from the robot model's outlet of label k (its
                                   "outlet_labels", else its outlet effect k); neither: the run stops before
                                   recording, naming --encoder */
    int target_p1;              /* 0: the cable on one point; p + 1: on point p of a tool plate (the plan's and
                                   the file's target column, rcal poses --cable-point) */
    unsigned n_points;          /* the plate's points for the follow check's prediction (--cable-point), 0: the
                                   flange point. A plan with a target column needs them (or a robot model with
                                   RC_EFF_CABLE_POINTS): else the run stops before recording, naming
                                   --cable-point */
    double points_mm[RC_MAX_TARGETS][3]; /* (n_points x 3) their drawing, flange frame */
    int confirm, quiet; /* quiet: no per-pose progress lines (kept with confirm), no notes */
    /* The controller link (docs/controller-link.md): "tcp:[HOST:]PORT" or NULL. Given, the controller's
     * reports drive the run (NEXT/BACK J instead of --announce/--confirm alone; settle_ms counts from its
     * report), the file records its joints with the plan's beside (q1_plan..q6_plan) and --confirm is
     * refused. */
    const char *controller;
    double controller_tol_deg;          /* a report farther from the plan than this per joint: OFFSET (0.05) */
    unsigned long controller_wait_s;    /* a controller connects within this (60) */
    unsigned long link_timeout_s;       /* silence that loses the link (5) */
    unsigned long move_timeout_s;       /* a report after NEXT/BACK (60) */
    int cell_check;     /* 1 (rcal acquire's default; 0 here): a plan row whose straight cable would cross a link,
                           a box or the floor of the robot file, or put the arm below the floor, stops the run
                           before the first move (rch_cell_row_refused) */
} rch_acq_config;

/* Defaults as `rcal acquire` documents them (paths NULL, ASCII, posix off). */
void rch_acq_config_default(rch_acq_config *c);

typedef struct rch_acq_result {
    size_t n_poses;          /* in the plan */
    size_t n_before;         /* already in the file */
    size_t n_new;            /* recorded by this run */
    size_t dropped_bytes;    /* unfinished last line moved to <out>.dropped */
    int stopped;             /* 1: stopped at pose stopped_at (rerun to resume) */
    size_t stopped_at;
    unsigned long readings, timeouts, bad_frames, shape_rejects, device, range, unstable, reconnects;
    unsigned long follow_refusals; /* samples refused by the follow check */
    double worst_follow_mm;  /* largest |dL_measured - dL_nominal| among recorded samples */
    unsigned long trend_rejects; /* full windows refused by the stability rule's trend test */
    double tau_ms;           /* the display time constant the run ended with (set or learnt) */
    unsigned long verifies;  /* returns to the last recorded pose */
    unsigned long verify_fails; /* of which the device read differently */
    size_t n_jumps;          /* confirmed jumps recorded past (on_jump_record) */
    struct { size_t pose; double jump_mm; } jumps[16]; /* the first 16 */
    unsigned long link_faults[RCH_LINK_NFAULTS]; /* --controller: the faults named, per rch_link_fault */
    unsigned long link_connects;                  /* controllers accepted (1 + reconnects) */
    unsigned link_port;                           /* the port listened on */
    rch_acqtime_stats timing;                     /* --controller: rcal's own time per pose (rch_acqtime.h) */
} rch_acq_result;

/* Run the acquisition. Progress on out, problems on err (either may be
 * NULL: silent). 0 all poses recorded, 1 stopped or refused (res->stopped
 * tells whether a rerun resumes), 2 invalid configuration. */
int rch_acquire_run(rch_acq_result *res, const rch_acq_config *c, const rch_acq_io *io, FILE *out, FILE *err);

/* The follow check alone: 0 when a sample of len_mm at a pose predicted at
 * pred_mm follows the reference (ref_len_mm recorded at a pose predicted at
 * ref_pred_mm) within tol_mm; *miss_mm gets |dL_measured - dL_nominal|. */
int rch_acq_follows(double *miss_mm, double len_mm, double pred_mm, double ref_len_mm, double ref_pred_mm,
                    double tol_mm);

#endif
