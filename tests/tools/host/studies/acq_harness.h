/* SPDX-License-Identifier: MIT */
/* acq_harness.h - the acquisition tests' harness (test_acquire.c,
 * test_acquire_device.c): rch_acquire_run in-process with a test io over
 * mock ports and a simulated clock, a four-pose plan with its nominal
 * lengths, and a display that shows what the cable at the robot's pose
 * reads (issue 23: reconnects, jumps, a filtering display). */
#ifndef ACQ_HARNESS_H
#define ACQ_HARNESS_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "rch_acquire.h"
#include "rch_robot.h"

#define ROBOT RCAL_SOURCE_DIR "/data/irb120.json"
#define NP 4
#define PD_FRAMES 2400
#define NROWS (2 * NP) /* rows of a plan with every pose twice (two outlets, two points of a plate) */

extern const double plan_deg[NP][RC_NJ];
extern char dir_[256];
extern double nominal_mm[NP]; /* the nominal model's length at each plan pose */
extern size_t g_frame;        /* the bytes of one frame script() wrote last */
extern char g_plan[512], g_out[512], g_err[8192]; /* the plan, the output, what the run printed */

/* ---- a test io: mock ports, simulated clock ------------------------------ */
struct pdev;
typedef struct tio {
    rcd_port port;
    rcd_mock_ctx m[2]; /* the display, and what appears after a reconnect */
    int opened;        /* opens so far */
    uint8_t rx[2][8192];
    struct pdev *pd; /* non-NULL: a display that shows the pose the robot is at (below) */
} tio;

/* ---- issue 23: devices that deceive ---------------------------------------
 * A display that shows what the cable at the robot's pose reads: the test io's
 * joint source learns the pose the run asked for (also when it goes back to
 * the last recorded one) and the device's script becomes that pose's value,
 * as the device in use shows it (val[0] before a hang-up, val[1] after the
 * reconnect), through a first-order filter of time constant tau_ms when set,
 * read every 50 ms at the display's 0.01 mm. */
typedef struct pdev {
    double val[2][NROWS]; /* what device k shows at plan row p (mm) */
    int hang_at;         /* device 0 hangs up when the robot reaches this pose (-1: never) */
    double tau_ms;       /* the display's filter; 0: none */
    int pose;            /* where the robot is */
    double shown[2];     /* the display's value when the robot arrived (filter state) */
    int jump_at;         /* the device jumps by jump_mm when the robot first reaches this pose (0: never) */
    double jump_mm;
    int jumped;
    int freeze_at;       /* the display freezes when the robot reaches this plan row (-1: never): from then on
                            it shows what it showed (HOLD pressed, firmware hung) */
    int frozen;
    double frozen_mm;
    double frames[2][PD_FRAMES];
    uint8_t rx[2][PD_FRAMES * 16];
    size_t flen;
} pdev;

/* ASCII stream of `count` frames per value (sets g_frame); its length. */
size_t script(uint8_t *s, size_t cap, const double *v, size_t nv, unsigned count);
void tio_init(tio *t);
void path_in(char *buf, size_t cap, const char *name); /* name inside the tests' directory */
void write_text(const char *name, const char *text);
long long fsize(const char *name); /* -1: absent */
void config(rch_acq_config *c, const char *out_name); /* the run's defaults, out_name removed */
int run(rch_acq_result *r, const rch_acq_config *c, tio *t); /* over t's scripts */
/* The directory RCAL_BINARY_DIR/tests/tools/host/studies/sub (one per test program: they
 * may run at once), the plan in it and its nominal lengths; 0. */
int acq_setup(const char *sub);
int run_pd(rch_acq_result *r, const rch_acq_config *c, tio *t, pdev *d); /* with the display d */
void pdev_init(pdev *d, double off0, double off1); /* device k shows nominal + off_k (row p: pose p % NP) */
/* The nominal model's length at q_deg from the encoder at enc_mm to the
 * flange, or to point_mm (flange frame; NULL: the flange centre). */
double nominal_at(const double q_deg[RC_NJ], const double enc_mm[3], const double *point_mm);
/* The plan's NP poses twice, labelled 0 and 1 in column col: label-major
 * (every pose of label 0, then of label 1: rcal poses --outlet) or pose-major
 * (each pose on label 0, then 1: rcal poses --cable-point), into name; row r
 * is pose row_pose(r, pose_major) labelled row_label(r, pose_major). */
void write_labelled_plan(const char *name, const char *col, int pose_major);
int row_pose(int r, int pose_major);
int row_label(int r, int pose_major);
double recorded(const char *path, int pose); /* the recorded L of pose (NAN: not there) */
char *slurp(const char *path, size_t *n); /* the file, in one of two static buffers */

#endif
