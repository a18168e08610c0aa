/* SPDX-License-Identifier: MIT */
/* rch_diagnose_int.h - what the files of `rcal diagnose` share (not a public
 * header): the run's state handed from phase to phase, the explanatory
 * variables, and the functions one file defines for the others.
 *   rch_diagnose.c         the workflow: inputs, floor, folds, geometry, jumps, verdict
 *   rch_diagnose_tests.c   the structure tests of residuals
 *   rch_diagnose_search.c  the candidate effects and the search among them
 *   rch_diagnose_score.c   the score test of one candidate
 *   rch_diagnose_out.c     text, JSON, next step, model file, residual table
 *   rch_diagnose_plot.c    the plots */
#ifndef RCH_DIAGNOSE_INT_H
#define RCH_DIAGNOSE_INT_H

#include <math.h>
#include <stdio.h>

#include "rch_diagnose.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif
#define DEG (M_PI / 180.0)

/* Explanatory variables per sample, from the geometric model: the gravity
 * levers of joints 2 and 3, the cable length, the cable direction, the
 * acquisition order. */
enum { V_LEV2 = 0, V_LEV3, V_LEN, V_UX, V_UY, V_UZ, V_T, V_N };

typedef struct ctx {
    const rc_sample *s; /* (n) */
    size_t n;
    unsigned k;                            /* folds */
    unsigned *fold;                        /* (n) fold of each sample */
    rc_sample *train[RCH_DIAGNOSE_MAX_FOLDS]; /* (n_train[f]) */
    size_t n_train[RCH_DIAGNOSE_MAX_FOLDS];
    rc_solve_work *w;
    unsigned max_iter;
    int verbose;
    unsigned *pose;                        /* (n) the pose of each sample (0..n_poses-1, by first appearance) */
    size_t n_poses;
    int have_fixed;                        /* fixed0 holds the base model's parameters no sample sees */
    uint8_t fixed0[RC_MAX_PARAMS];         /* (RC_MAX_PARAMS) 1: held (an unseen encoder, target); 0 beyond */
} ctx;

/* The state of one diagnosis run, handed from phase to phase. The phases run
 * in order (setup, steps, 1 geometry, 2 floor, 3 folds, 4 cross-validated
 * geometry, 5 candidate search, 6 after, 7 report); each reads what the ones
 * before it left here and in the result. Everything on the heap is freed by
 * run_free. */
typedef struct run_state {
    rch_diagnose_cfg cfg;     /* with the defaults filled in */
    rch_diagnose_result *out; /* the caller's result, filled phase by phase */
    ctx c;                    /* samples (out->s), folds, training sets, solver scratch */
    rc_model base;            /* the model entering the current search step (geometry + chosen effects) */
    rc_model *base_folds;     /* (k) that model fitted on each fold's training samples */
    rc_model *cand_full;      /* (N_ALL_CANDS) each candidate fitted on all samples */
    rc_model *cand_folds;     /* (N_ALL_CANDS x k) each candidate fitted per fold */
    double *cand_res;         /* (N_ALL_CANDS x n) held-out residuals per candidate */
    double *r0;               /* (n) held-out residuals of the current model */
    double *tmp;              /* (n x 6) scratch */
    double (*var)[V_N];       /* (n) explanatory variables of the structure tests */
    unsigned *order;          /* (n) shuffled pose order */
    uint8_t *cls;             /* (n) each sample's sensor (index into out->sensors) */
    unsigned base_rank;       /* identifiable directions of base (0: not yet computed this step) */
} run_state;

/* The number of candidate effects (rch_diagnose_search.c's table). */
#define RCH_DG_N_CANDS 19u

/* rch_diagnose.c: the fits of the workflow. */
int rch_dg_fit(rc_model *m, rc_solve_result *res, ctx *c, const uint8_t *fixed, const rc_sample *s, size_t n);
int rch_dg_cv_run(rc_model *models, double *res, ctx *c);
unsigned rch_dg_rank_at(const rc_model *m, unsigned np, const rc_sample *s, size_t n, rc_solve_work *w, int dump);

/* The paired held-out gain of b over a (squared errors, per sample; a, b:
 * (n) residuals), its standard error and z, the poses as the units (the
 * samples of one pose are not independent). */
void rch_dg_paired_gain(double *gain_mm2, double *se_mm2, const double *a, const double *b, const ctx *c);

/* rch_diagnose_tests.c */
unsigned rch_dg_groups_usable(unsigned n_groups, size_t n);
unsigned rch_dg_structure_tests(rch_diagnose_test *out, const double *r, const rc_sample *s, size_t n,
                                const double (*var)[V_N], unsigned n_groups, double alpha);

/* The class of sample s's sensor: its kind (rc_sensor_kind), the tracker's
 * three coordinates one class (RC_SENSOR_TRACKER_X). A diagnosis keeps each
 * class apart: its rows, its figures (a class per cable outlet there), its
 * structure tests. */
unsigned rch_dg_sensor_class(const rc_sample *s);

/* The structure tests of each sensor in the data (rch_dg_structure_tests on
 * each class's rows apart (rch_dg_sensor_class: the cable's, the tracker's,
 * each other sensor's), with an ANOVA over the outlets, the coordinates and
 * the targets or the sensor's labels; Bonferroni over all of them).
 * One outlet's lengths alone: rch_dg_structure_tests itself. */
unsigned rch_dg_sensor_tests(rch_diagnose_test *out, const double *r, const rc_sample *s, size_t n,
                             const double (*var)[V_N], unsigned n_groups, double alpha);

/* rch_diagnose_score.c: the cluster-robust score test of the candidate
 * parameters nb..n_params-1 of m0 (the current model with the candidate
 * added at zero; m1: it fitted, whose residuals give the score's
 * covariance, or NULL) over c's samples, poses as clusters. q_ident: the
 * directions the candidate adds; k_fitted: the current model's fitted
 * directions. 0 with F, its numerator dof and p; -1 when it cannot be
 * formed (nothing identifiable, too few poses, a LAPACK failure). */
int rch_dg_score_test(double *f_stat, unsigned *dof, double *p_value, const rc_model *m0, const rc_model *m1,
                      unsigned nb, unsigned q_ident, unsigned k_fitted, const ctx *c);

/* rch_diagnose_search.c */
int rch_dg_has_effect(const rc_model *m, rc_effect_kind kind, unsigned joint0);
void rch_dg_phase_search(run_state *S);

#endif
