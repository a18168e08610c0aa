/* SPDX-License-Identifier: MIT */
/* rch_poses.h - planning a pose set (`rcal poses`).
 *
 * Two criteria, one candidate set: `candidates` random poses uniformly
 * inside the joint limits (less margin_deg, at 0.01 deg steps) whose
 * nominal cable length from the outlet(s) lies in [len_min_mm, len_max_mm].
 *
 * RCH_POSES_POSITION (the default; issue 20): the 3-D accuracy of the
 * calibrated robot. K outlets at given approximate places (outlet 0 is the
 * model's encoder when none are given); every pose is measured from every
 * outlet (K rows per pose), or with `split` each pose from one outlet (N / K
 * poses each, slot t of the design belonging to outlet t mod K). The
 * model is the one `rcal calibrate` fits: the nominal DH, Hayati's tilt of
 * every nominally parallel axis, one outlet effect per place, theta1 and d1
 * held (the gauge). The information of a design is
 *   M = P + sum over its rows g g^T / noise^2,
 * g = d l / d x (rc_meas), P the physical prior's diag(1 / sd^2)
 * (rch_prior_fill: directions the prior fixes need no poses); the outlets,
 * which have no prior, are given 100 mm about their approximate places so
 * that M is invertible before the first pose (the data then place them to
 * a few hundredths of a mm). The criterion is I-optimality, the classical
 * "average prediction variance": minimise
 *   phi = mean over W workspace poses w of trace(Jp_w M^-1 Jp_w^T),
 * the expected squared 3-D error of the point (flange or tool) over the
 * workspace (W = 300 poses uniform in the joint limits; Jp = d p / d x,
 * rch_uncert_point_sens). A candidate of rows X lowers it by
 * trace((I + X^T C X)^-1 X^T C Q C X), C = M^-1, Q = mean Jp^T Jp:
 * greedy additions, then exchange passes (a pose swapped for the candidate
 * that lowers phi most while it falls). The plan is reported by its
 * predicted 3-D accuracy: the 95 % radius of the position error
 * (rch_uncert_radius95 of Jp C Jp^T) at n_eval other workspace poses, median
 * and 95th percentile, beside N random candidates of the same design.
 *
 * RCH_POSES_LENGTH (the earlier plan, one outlet): D-optimal on the lengths:
 * maximise log det(X^T X) over the directions rc_ident calls identifiable
 * (columns scaled by their RMS), greedy + Fedorov exchange, reported by the
 * observability index O1 (rch_ident) beside N random poses.
 *
 * The plan's rows are then ordered for joint travel (rch_poses_order).
 *
 * The cable and the cell (issue 48): with a cell (the robot file's "links"
 * and "cell", rch_cell.h) a candidate whose straight cable, from any outlet
 * it is measured from to any point it is hooked on, comes within
 * clearance_mm of a link, a box or the floor, or whose flange or a link is
 * below the floor, is dropped before the design (rch_poses_safe.c); the
 * result counts them by reason. Cost of the position criterion: about candidates x K x
 * P^2 x N x (passes + 1) products (P ~ 26 + 3 K); 50 poses from 3 outlets
 * of 2000 candidates about 2 s on one core.
 * Host side (prefix rch_): heap; progress lines on a caller-given stream.
 */
#ifndef RCH_POSES_H
#define RCH_POSES_H

#include <stddef.h>
#include <stdio.h>

#include "rc_model.h"
#include "rch_cell.h"
#include "rch_diag.h"
#include "rch_prior.h"

#define RCH_POSES_MAX_COUNT 1000u        /* poses per plan */
#define RCH_POSES_MAX_CANDIDATES 200000u /* candidate poses */

typedef struct rch_poses_config {
    size_t count;              /* N, 1..RCH_POSES_MAX_COUNT */
    size_t candidates;         /* 0: max(2000, 40 N); else N..RCH_POSES_MAX_CANDIDATES */
    unsigned long passes;      /* exchange passes (4 in rcal poses) */
    double max_minutes;        /* refuse a plan estimated longer (rch_poses_estimate); 0: 60 */
    unsigned long long seed;
    double len_min_mm, len_max_mm; /* cable length range, min < max */
    double margin_deg;             /* kept from every joint limit, >= 0 */
    /* the position criterion (zero-initialised: the default) */
    int criterion;                 /* rch_poses_criterion */
    unsigned n_outlets;            /* K places of the encoder, 0: the model's encoder alone */
    double outlet_mm[RC_MAX_OUTLETS][3]; /* (K x 3) their approximate places, base frame */
    int split;                     /* 1: each pose measured from one outlet; 0: from every outlet */
    double noise_mm;               /* length noise the prediction is for; 0: RCH_POSES_NOISE_MM */
    unsigned n_points;             /* P points of a tool plate the cable is hooked on in turn (every pose
                                      measured on each; RC_EFF_CABLE_POINTS), 0: the flange point alone */
    double points_mm[RC_MAX_TARGETS][3]; /* (P x 3) their drawing, flange frame */
    int has_tool;                  /* 1: plan for the tool point tool_mm (flange frame), else the flange */
    double tool_mm[3];
    const rch_prior_cfg *prior;    /* NULL: rch_prior_defaults */
    size_t n_work;                 /* workspace poses of the criterion, 0: 300 */
    size_t n_eval;                 /* workspace poses of the reported accuracy, 0: 1000 */
    int keep_order;                /* 1: the rows in the selection's order (no rch_poses_order) */
    const rch_cell *cell;          /* the arm's links and the cell (NULL or empty: every candidate safe) */
    double clearance_mm;           /* the cable's least distance from a link, a box, the floor */
} rch_poses_config;

typedef enum { RCH_POSES_POSITION = 0, RCH_POSES_LENGTH = 1 } rch_poses_criterion;
#define RCH_POSES_NOISE_MM 0.02
#define RCH_POSES_OUTLET_SD_MM 100.0 /* the planner's prior on the outlets' approximate places */

/* Predicted 3-D accuracy of a design: the 95 % radius of the point's
 * position error over workspace poses. */
typedef struct rch_poses_accuracy {
    double median_mm, p95_mm;      /* over the n_eval workspace poses */
    double phi_mm2;                /* the criterion: mean trace of the position covariance over them */
} rch_poses_accuracy;

/* The plan's joint travel before and after rch_poses_order (issue 48). */
typedef struct rch_poses_travel {
    double before_deg, after_deg;     /* the sum over sessions of max_j |dq_j| per move, from home (deg) */
    unsigned outlets_reordered;       /* outlets whose tour beat the input order (the others kept it) */
    double before_min_deg[RC_NJ], before_max_deg[RC_NJ]; /* each joint's span over the rows */
    double after_min_deg[RC_NJ], after_max_deg[RC_NJ];
} rch_poses_travel;

typedef struct rch_poses_result {
    rc_sample *poses;          /* (n) the plan, q at 0.01 deg steps; rch_poses_free */
    size_t n;
    size_t n_candidates;
    unsigned n_ident;          /* identifiable directions (rc_ident rank of the candidates) */
    unsigned n_params;
    double o1_plan, o1_random; /* observability O1 (rch_ident) of the plan and of N random candidates */
    unsigned rank_plan, rank_random;
    /* the position criterion */
    unsigned n_outlets;        /* K */
    size_t n_distinct;         /* distinct poses (n = K n_distinct, or n_distinct with split) */
    rch_poses_accuracy plan, random; /* predicted 3-D accuracy of the plan and of random poses */
    size_t rows_per_outlet[RC_MAX_OUTLETS];
    size_t rows_advised;       /* fewest rows advised: calibrate's parameters (the free ones + the cable
                                  attachment it tries) + RCH_POSES_ROWS_SPARE */
    /* with a tool plate (c->n_points > 0, the position criterion): what each further point gains, the
     * plan's poses measured on points 0..j only (by_points[j - 1]), predicted at the same point */
    rch_poses_travel travel;   /* the joint travel before and after ordering (rch_poses_order) */
    unsigned n_points;
    struct {
        size_t rows;
        int ok;                   /* 0: the prediction failed (why: not kept) */
        rch_poses_accuracy acc;
    } by_points[RC_MAX_TARGETS];
    /* candidates dropped for the cable and the cell (rch_cell_reason; [0] unused), of n_checked checked
     * (a pose, or with split a pose from one outlet, inside the length range) */
    size_t dropped[RCH_CELL_N_REASONS];
    size_t n_checked;
} rch_poses_result;

/* Is pose q measured from outlet k (0..K-1 of c's outlets; the model's
 * encoder when c has none) on every point the cable is hooked on (plate
 * points, else the tool point, else the flange) safe for c's cell? 1, or 0
 * with res->dropped[reason] counted; res->n_checked counted either way. */
int rch_poses_safe(rch_poses_result *res, const rc_model *m, const rch_poses_config *c, const rc_sample *q,
                   unsigned k);
/* "12 cable near a link, 3 flange or link below the floor" (nothing: "none"). */
void rch_poses_dropped_str(char *buf, size_t size, const rch_poses_result *res);
/* `rcal calibrate` estimates the noise from its residuals (SSR / (n - p_eff)):
 * with about as many rows as parameters the estimate collapses, the prior
 * loses its weight and the fit follows the noise (measured, plan_study.py
 * --table: 30 rows for 32 parameters, 3-D error 0.33-0.69 mm against a
 * predicted 0.05-0.07 mm; 60 rows and more as predicted). */
#define RCH_POSES_ROWS_SPARE 10u

/* The plan ordered for travel (issue 48; rch_poses_order.c): per outlet
 * (the rows `rcal acquire --outlet N` runs; the same pose on each plate
 * point stays one stop, its rows together) a tour from home (q = 0 within
 * the limits less margin_deg) that shortens the joint travel, nearest
 * neighbour then 2-opt; a joint with a range over 360 deg (less the margins)
 * takes the branch q + 360 k (the same robot pose) that minimises the travel
 * along the tour, within the limits less margin_deg. Travel: the sum over
 * the sessions (outlet, target) of max over joints of |dq| per move, from
 * home. Rows keep their columns' meaning (outlet, target, the pose); an
 * outlet's order changes only when its travel falls. tr: the figures. 0, or
 * -1 with d set (out of memory; rows unchanged). */
int rch_poses_order(rc_sample *rows, size_t n, const rc_model *m, double margin_deg, rch_poses_travel *tr,
                    rch_diag *d);
/* The joint travel of rows as rch_poses_order measures it (deg). */
double rch_poses_travel_deg(const rc_sample *rows, size_t n, const rc_model *m, double margin_deg);
/* tr for rows kept in their order (after = before). */
void rch_poses_travel_of(rch_poses_travel *tr, const rc_sample *rows, size_t n, const rc_model *m,
                         double margin_deg);

/* Plan poses for model m (with its encoder position set). progress: a
 * stream for progress lines when the plan takes more than a few seconds
 * (NULL: silent). 0, or -1 with d set (limits, empty joint range, length
 * range the candidates cannot reach, out of memory). */
int rch_poses_plan(rch_poses_result *res, const rc_model *m, const rch_poses_config *c, FILE *progress,
                   rch_diag *d);
void rch_poses_free(rch_poses_result *res);

/* The predicted 3-D accuracy of given rows (n; q_rad and outlet 0..K-1 read)
 * for the outlets and options of c (criterion ignored). 0, or -1 with d. */
int rch_poses_predict(rch_poses_accuracy *acc, const rc_model *m, const rch_poses_config *c, const rc_sample *rows,
                      size_t n, rch_diag *d);

/* Which k of the n candidate places (cand_mm, n x 3) give the best predicted
 * 3-D accuracy (median 95 % radius over the workspace) for a plan of
 * c->count poses (a greedy plan per combination, c's other options): every
 * combination when there are at most RCH_POSES_MAX_COMBOS, else greedily
 * (the best place, then the one that improves it most, ...). */
#define RCH_POSES_MAX_CANDIDATE_PLACES 16u
#define RCH_POSES_MAX_COMBOS 64u
typedef struct rch_poses_combo {
    unsigned k;                   /* places in it (fewer than the choice's k on the greedy path's way) */
    unsigned idx[RC_MAX_OUTLETS]; /* (k) candidate indices */
    rch_poses_accuracy acc;
    int span;                     /* rch_prior_outlet_span */
} rch_poses_combo;
typedef struct rch_poses_choice {
    unsigned k, n_cand;
    int exhaustive;
    size_t n_combos;
    rch_poses_combo combos[RCH_POSES_MAX_COMBOS + RCH_POSES_MAX_CANDIDATE_PLACES * RC_MAX_OUTLETS];
    size_t best;                  /* index into combos */
} rch_poses_choice;
int rch_poses_choose_outlets(rch_poses_choice *out, const rc_model *m, const rch_poses_config *c,
                             const double (*cand_mm)[3], unsigned n, unsigned k, rch_diag *d);

/* The plan as an ABB RAPID module: one CONST jointtarget per row (robax in
 * degrees, extax 9E9), one PROC per outlet moving through its rows (MoveAbsJ
 * ... fine, tool0), writing "rcal pose I outlet K" on the pendant (TPWrite)
 * and waiting settle_s (WaitTime) while `rcal acquire` reads, and main (it
 * asks the outlet when there are several). outlet_label: (n) the rows'
 * outlet column, NULL: all 0. 0, or -1 (a write failed). */
int rch_poses_write_rapid(FILE *f, const rc_sample *rows, const unsigned char *outlet_label, size_t n,
                          double settle_s, const char *comment);

/* What a plan costs before it starts, from the exact work count and the
 * cost of a unit measured on the reference machine (docs/driver.md): the
 * position criterion about 0.8 ns x poses x candidates x nf^2 per phase (the
 * greedy design, then each exchange pass), nf the parameters it designs for;
 * the length criterion 20 us per candidate (its Jacobian row) plus 0.3 ns x
 * poses x candidates x r^2 per phase, r the identifiable rank. first_s: the
 * greedy design and one pass; all_s: every --passes pass (exchange stops
 * early when no swap helps, so all_s is the most it takes). Measured against
 * real runs in tests/system/sim/plan_study.py's neighbourhood: within a factor of 2. */
void rch_poses_estimate(double *first_s, double *all_s, size_t n, size_t n_cand, unsigned nf, unsigned long passes,
                        int length_criterion);

#endif
