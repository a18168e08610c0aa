/* SPDX-License-Identifier: MIT */
/* rch_sim.h - simulated robot and cable encoder with known truth.
 *
 * A true robot is the nominal model plus DH errors (chosen or random), an
 * encoder outlet position and, optionally, model effects (rc_model effects).
 * Poses are drawn inside the joint limits (and the simulation ranges below)
 * until the cable length lies within the encoder's range; in grouped mode
 * the wrist joints (q4..q6) stay fixed for group_size consecutive poses, as
 * in a real acquisition where the operator moves the arm joints only.
 * The measured length is the true model's length at the TRUE joint angles,
 * plus Gaussian noise, quantized to the encoder resolution; the recorded
 * joint angles are the true ones quantized to the display step (0.1 deg).
 */
#ifndef RCH_SIM_H
#define RCH_SIM_H

#include <stddef.h>
#include <stdio.h>

#include "rc_model.h"
#include "rc_rand.h"
#include "rch_diag.h"
#include "rch_robot.h"

typedef struct rch_sim_config {
    double err_len_mm;      /* sigma of random a, d errors (mm); default 0.3 */
    double err_ang_deg;     /* sigma of random alpha, theta errors (deg); default 0.05 */
    double noise_mm;        /* sigma of the length noise; default 0.01 (negative: none) */
    double resolution_mm;   /* length quantization; default 0.004 (negative: none) */
    double q_step_deg;      /* joint reading quantization; default 0.1 (negative: none) */
    double len_min_mm;      /* encoder range; default 250 */
    double len_max_mm;      /* default 800 */
    double q_lo_deg[RC_NJ]; /* sampling range; both 0 for a joint: its joint limits */
    double q_hi_deg[RC_NJ];
    unsigned group_size;    /* 0: every pose independent; else wrist fixed per group */
    double group_span_deg;  /* spread of q1..q3 around a group's centre; default 25 */
    unsigned repeats;       /* 0 or 1: every sample a new pose; R: each pose read R times in a row (fresh noise) */
} rch_sim_config;

/* Fill zero fields with the defaults above. */
void rch_sim_defaults(rch_sim_config *c);

/* truth = nominal + random DH errors (sigmas from c), encoder at enc_mm.
 * Effects of nominal are copied unchanged. */
void rch_sim_truth(rc_model *truth, const rc_model *nominal, const double enc_mm[3],
                   const rch_sim_config *c, rc_rng *g);

/* One random pose: q_rad (6) uniform within the joint limits of m shrunk by
 * margin_rad on each side (0: the limits themselves); joint 1 first, one
 * rc_rng_u01 draw per joint. The one definition of "random poses in the
 * limits". */
void rch_sim_pose(double q_rad[RC_NJ], const rc_model *m, double margin_rad, rc_rng *g);

/* n samples (q only: len, t and group zero) at rch_sim_pose poses. */
void rch_sim_poses(rc_sample *out, size_t n, const rc_model *m, double margin_rad, rc_rng *g);

/* n simulated samples from truth (q recorded as displayed, L measured).
 * true_q_rad: (n x 6) the unquantized angles, or NULL. Returns 0, or -1 when
 * no pose within the encoder range was found in 100000 draws. */
int rch_sim_samples(rc_sample *out, double (*true_q_rad)[RC_NJ], size_t n, const rc_model *truth,
                    const rch_sim_config *c, rc_rng *g);

/* Flange-position agreement of two models over poses (n): RMS and max of
 * |p_a(q) - p_b(q)| in mm. With align != 0, first removes what cable lengths
 * cannot see: a rotation about the base z axis and a shift along it (the
 * base heading and height), fitted in closed form. */
void rch_sim_flange_diff(double *rms_mm, double *max_mm, const rc_model *a, const rc_model *b,
                         const rc_sample *poses, size_t n, int align);

/* ------------------------------------------------ a simulated data set */

/* What `rcal simulate` asks for. */
typedef struct rch_sim_job {
    const char *robot_path; /* nominal robot model (required) */
    const char *truth_path; /* a given true model, or NULL: nominal + random DH errors */
    double enc_mm[3];       /* encoder outlet when the truth has none */
    size_t n;               /* samples, >= 1 */
    unsigned long seed;
    rch_sim_config sim;     /* zero fields: defaults (rch_sim_defaults) */
} rch_sim_job;

typedef struct rch_sim_set {
    rch_robot robot;        /* the file read (the nominal, or the given truth) */
    rc_model truth;         /* the true model the lengths come from */
    rch_sim_config sim;     /* with the defaults filled in */
    unsigned long seed;
    rc_sample *s;           /* (n) on the heap: rch_sim_set_free */
    size_t n;
} rch_sim_set;

/* The truth (job->truth_path, its encoder or enc_mm; else nominal + random
 * errors) and n samples from it, seeded by job->seed. 0, or -1 with d set. */
int rch_sim_make(rch_sim_set *out, const rch_sim_job *job, rch_diag *d);
void rch_sim_set_free(rch_sim_set *set);

/* The true model as a model file with a "calibration" member saying it is
 * simulated (seed, noise, resolution, joint step). 0 or -1 (write error). */
int rch_sim_write_truth(FILE *f, const rch_sim_set *set);

/* The samples as CSV into out_path (rch_data_write) and, when truth_out is not
 * NULL, the truth into truth_out; each whole or not at all (rch_save), never
 * over job's inputs (the truth never over the CSV either). 0, or -1 with d. */
int rch_sim_save(const rch_sim_set *set, const rch_sim_job *job, const char *out_path, const char *truth_out,
                 rch_diag *d);

#endif
