/* SPDX-License-Identifier: MIT */
/* sens_gen.h - independent test data for `rcal diagnose` on every sensor
 * (issue 31): a random true IRB120 seen by a laser tracker (positions
 * files, docs/positions.md) and by a cable encoder at three outlets (data
 * files with an `outlet` column), with one hidden physical effect in a form
 * the code under test does not use.
 *
 * Written apart from the code under test: the kinematics and random
 * numbers are tests/common/rct_indep.h's, the nominal IRB120 is a copy of
 * data/irb120.json's DH table as constants; nothing of lib/ or tools/host/
 * is called to make data. The noise levels, the effect and its location are
 * never written into a file.
 *
 * Forms (sens_gen.c says the sizes):
 *   true DH = nominal + Student-t (3 dof) errors, clipped;
 *   SG_GRAVITY  point masses on the upper arm, forearm and tool; gravity
 *               torque about joints 2 and 3 from their positions (r x F);
 *               deflection = torque x compliance on both joints;
 *   SG_GEAR     one joint (1, 2 or 3) with a transmission error of a first,
 *               second and small third harmonic of its angle, random phases;
 *   SG_TEMP     the tracker's positions scaled about its origin by 1 + k;
 *   SG_OUTLET   each outlet's cable length offset (a common part, one
 *               outlet offset again) and its own length scale;
 *   SG_NONE     nothing hidden (the control).
 *
 * Depends on: rct_indep.h, libc, libm. Memory: fixed-size structs, the
 * caller's. Errors: the writers return 0, or -1 when a file cannot be
 * written. */
#ifndef SENS_GEN_H
#define SENS_GEN_H

#include <stdio.h>

#include "rct_indep.h"

#define SG_TARGETS 3     /* tracker targets on the tool plate */
#define SG_TRK_POSES 36  /* tracker poses (x SG_TARGETS rows) */
#define SG_OUTLETS 3     /* cable encoder places */
#define SG_CAB_POSES 100 /* cable poses, each measured from every outlet */

typedef enum { SG_NONE, SG_GRAVITY, SG_GEAR, SG_TEMP, SG_OUTLET, SG_N_EFFECTS } sg_effect;

extern const char *const sg_effect_name[SG_N_EFFECTS];

/* The nominal IRB120 (data/irb120.json): dh[i] = {a_mm, d_mm, alpha_rad,
 * theta_off_rad}; joint limits in rad. */
void sg_nominal_dh(double dh[6][4]);
extern const double sg_qmin_deg[6], sg_qmax_deg[6];

typedef struct {
    sg_effect effect;
    double dh[6][4]; /* true DH, as rct_frame takes it */
    /* tracker: p_tracker = (1 + trk_scale) (R p_base + T) */
    double trk_R[9];                 /* rotation, row-major */
    double trk_T_mm[3];              /* the base origin in the tracker's frame */
    double trk_target_mm[SG_TARGETS][3]; /* targets in the flange frame */
    double trk_noise_mm;             /* per coordinate */
    double trk_scale;                /* SG_TEMP: k (20-60 ppm), else 0 */
    /* cable: L_k = (1 + cab_scale[k]) |p_attach - outlet_k| + cab_offset_mm[k] */
    double outlet_mm[SG_OUTLETS][3];   /* base frame */
    double attach_mm[3];               /* cable attachment in the flange frame */
    double cab_noise_mm;
    double cab_offset_mm[SG_OUTLETS];  /* SG_OUTLET, else 0 */
    double cab_scale[SG_OUTLETS];      /* SG_OUTLET, else 0 */
    unsigned odd_outlet;               /* SG_OUTLET: the outlet offset again */
    /* SG_GRAVITY: masses (kg) of the upper arm, forearm, tool; where they sit */
    double mass_kg[3];
    double arm_frac;                   /* upper-arm mass on link 2 (0..1 from joint 2) */
    double fore_frac;                  /* forearm mass from frame 3 towards the wrist centre */
    double tool_com_mm[3];             /* tool mass in the flange frame */
    double compl_rad_per_nm[2];        /* joints 2 and 3 */
    /* SG_GEAR */
    unsigned gear_joint;               /* 1..3 */
    double gear_amp_rad[3], gear_phase_rad[3];
} sg_truth;

/* Draws a truth with effect e from seed. */
void sg_draw(sg_truth *t, sg_effect e, uint64_t seed);

/* Multiplies the hidden effect's size by k (compliances, gear amplitudes,
 * tracker scale, cable offsets and scales). */
void sg_scale_effect(sg_truth *t, double k);

/* The joint angles the arm really takes at readings q (rad): the hidden
 * joint-side effect (gravity deflection, gear error) added. qe (6). */
void sg_joints_true(double qe[6], const sg_truth *t, const double q[6]);

/* Where a point tool (flange frame, mm) of the TRUE robot is at readings
 * q (base frame, mm), the hidden joint-side effect included. p (3). */
void sg_true_point(double p[3], const sg_truth *t, const double q[6], const double tool_mm[3]);

/* Where the NOMINAL robot puts the same point. p (3). */
void sg_nominal_point(double p[3], const double q[6], const double tool_mm[3]);

/* A random pose within 0.9 of the limits (joint 6 within +-180 deg), away
 * from the wrist singularity (|sin q5| > 0.15), flange above z = 50 mm.
 * q (6, rad). */
void sg_random_pose(double q[6], rct_rng *g);

/* Gravity torques (N m) about joints 2 and 3 of the true arm at q. tau (2). */
void sg_gravity_torque(double tau[2], const sg_truth *t, const double q[6]);

/* The tracker file: SG_TRK_POSES poses x SG_TARGETS rows, columns
 * q1..q6 (deg, 0.001), x, y, z (mm, 0.0001), target, pose; noise drawn
 * from g. Returns 0 or -1. */
int sg_write_positions(const char *path, const sg_truth *t, rct_rng *g);

/* The cable file: SG_CAB_POSES poses, each measured from every outlet
 * (outlet 0's rows first), columns q1..q6 (deg, 0.01), L (mm, 0.01),
 * outlet; noise drawn from g. Returns 0 or -1. */
int sg_write_cable(const char *path, const sg_truth *t, rct_rng *g);

/* n random targets (sg_random_pose), q1..q6 in degrees (0.000001), header
 * line; also into q (n x 6, rad) when not NULL. Returns 0 or -1. */
int sg_write_targets(const char *path, double (*q)[6], unsigned n, rct_rng *g);

/* The exact cable length of the truth at readings q from outlet k, before
 * noise and display step (mm). */
double sg_cable_length(const sg_truth *t, const double q[6], unsigned k);

/* The exact tracker reading of target k at readings q (mm), before noise. */
void sg_tracker_point(double p[3], const sg_truth *t, const double q[6], unsigned k);

/* The rigid motion (R, T) minimising sum |R a_i + T - b_i|^2 over the rows
 * with use[i] != 0 (use NULL: all), Horn's quaternion form of Kabsch (a
 * Jacobi eigen-solve of the 4 x 4 matrix). a, b (n x 3); R (3 x 3,
 * row-major), T (3). A tool of the harness, not of the data. */
void sg_kabsch(double R[9], double T[3], const double (*a)[3], const double (*b)[3], unsigned n,
               const unsigned char *use);

#endif
