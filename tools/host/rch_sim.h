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

#include "rc_model.h"
#include "rc_rand.h"

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
} rch_sim_config;

/* Fill zero fields with the defaults above. */
void rch_sim_defaults(rch_sim_config *c);

/* truth = nominal + random DH errors (sigmas from c), encoder at enc_mm.
 * Effects of nominal are copied unchanged. */
void rch_sim_truth(rc_model *truth, const rc_model *nominal, const double enc_mm[3],
                   const rch_sim_config *c, rc_rng *g);

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

#endif
