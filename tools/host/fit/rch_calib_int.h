/* SPDX-License-Identifier: MIT */
/* rch_calib_int.h - internal to the calibration pipeline (rch_calib*.c):
 * the functions one of its files owns and another calls. Not for use
 * outside tools/host/fit/rch_calib*.c.
 *
 * Depends on: the core types (rc_model, rc_solve); the result is named by
 * its struct tag, so this header does not include rch_calib.h (each user
 * does). Memory and errors: as each function says.
 */
#ifndef RCH_CALIB_INT_H
#define RCH_CALIB_INT_H

#include <stddef.h>
#include <stdint.h>

#include "rc_solve.h"
#include "rch_diag.h"
#include "rch_jumps.h"

struct rch_calib_result;
struct rch_calib_timing;
struct rch_data;

/* rch_calib_plan.c: the plan's runner. A plan is a table of stages, each a
 * function of (run state, result): the run state (the steering: what the
 * next stage is to do, scratch, the inputs) apart from the result (the
 * answers). rch_calib_plan_run runs the stages in order, books each one's
 * own wall and CPU time into t (a stage that runs a plan itself is booked
 * without the inner stages' time), stops at the first that fails (its
 * code returned) and starts the table again when a stage returns
 * RCH_PLAN_AGAIN (at most RCH_PLAN_MAX_AGAIN times: the fit redone with what
 * a stage found, e.g. length jumps to fit as nuisance). 0, or the code. */
#define RCH_PLAN_AGAIN 1
#define RCH_PLAN_MAX_AGAIN 2
typedef int (*rch_calib_stage_fn)(void *run, struct rch_calib_result *r, rch_diag *d);
typedef struct rch_calib_stage {
    unsigned id;           /* rch_calib_stage_id: its line in the timing record */
    rch_calib_stage_fn fn;
} rch_calib_stage;
int rch_calib_plan_run(const rch_calib_stage *plan, size_t n, void *run, struct rch_calib_result *r,
                       struct rch_calib_timing *t, rch_diag *d);

/* The state of one fit's plan (rch_calib_fit.c): what rch_calib_fit_run
 * is given, then the steering its stages pass on. Not an answer: the
 * answers are the result's. */
typedef struct rch_calib_fit_state {
    /* given */
    rc_solve_work *w;
    const rc_sample *train, *test;  /* (r->n_train, r->n_test) */
    const struct rch_data *validate; /* the --validate rows as read (rch_inputs), or NULL */
    /* set by the stages */
    rc_solve_config cfg;            /* the solver's request (the prior's sd, its noise) */
    uint8_t fixed[RC_MAX_PARAMS];   /* the parameters held (gauge, --fix, unseen) */
    const rc_sample *eval_set;      /* the held-out rows (the training ones when none is held out) */
    size_t n_eval;
    rc_status st;                   /* the identification's solver status */
    double chi2_1;                  /* the MAP objective of the attachment model */
    int jumps;                      /* the jumps are fitted as nuisance (--jumps, or the check found them) */
    int checked;                    /* the jump check's first noise pass was made */
    unsigned passes0;               /* its noise passes */
    int have_jump_at, keep_jump_at; /* the change points of this training set are known (searched once) */
    int attach_m0;                  /* refit at the change points found (the no-attachment model, the refit under
                                       the prior's estimated scale) */
    rc_model check_model;           /* the jump check's fit at its change points (geometry + offsets) */
    int have_check_model;           /* check_model is set: the first nuisance fit starts from it */
    unsigned map_passes0;           /* noise passes made before a resumed map_fit (added to noise_passes) */
    int map_one_pass;               /* map_fit stops after its first noise pass (the jump check's early look) */
    int map_warm;                   /* map_fit's first pass from the fit at hand (r->model, r->jumps.model) at its
                                       noise r->noise_mm, not from the start model at its RMS */
    double noise_fit_mm;            /* the noise map_fit's last pass was fitted at (r->noise_mm: the next's) */
    unsigned n_jump_at;
    double jump_rms_before_mm;      /* training RMS of the geometry alone (the search's) */
    size_t jump_at[RCH_JUMPS_MAX];  /* (n_jump_at) first training sample (in t order) after each jump */
    /* what the uncertainty stage reads: the rows, the parameters held, the model fitted, the clusters */
    const rc_sample *fin_train;
    uint8_t fin_fixed[RC_MAX_PARAMS];
    const rc_model *fin_fit;
    rc_sample *fin_sorted;          /* (heap) the training rows in time order, each in its segment (--jumps) */
    uint16_t *fin_setup;            /* (heap) their set-up groups, or NULL */
} rch_calib_fit_state;

/* rch_calib_fit.c: identification and the figures once the split is made,
 * as a plan (the BC model; the MAP fit with its noise loop; the jump check;
 * the attachment; the prior's scale; --jumps' nuisance fit; the metrics;
 * rch_calib_finish), its stages' time booked into t. train (r->n_train),
 * test (r->n_test), validate (or NULL): the --validate rows. 0, -1 with d
 * set, -2 on a bad --fix name. */
int rch_calib_fit_run(struct rch_calib_result *r, rc_solve_work *w, const rc_sample *train, const rc_sample *test,
                      const struct rch_data *validate, struct rch_calib_timing *t, rch_diag *d);

/* rch_calib_figures.c: after the fit: truth, identifiability, uncertainty
 * (and its plot), validation (on validate_rows, the --validate rows as read;
 * NULL: none). fixed (r->model.n_params): the parameters
 * held; fit: the model fitted to train (r->model, or with the jumps'
 * offsets); setup (r->n_train, or NULL): the covariance's clusters. 0, or
 * -1 with d set. */
int rch_calib_finish(struct rch_calib_result *r, const uint8_t *fixed, const rc_sample *train, const rc_model *fit,
                     const uint16_t *setup, const struct rch_data *validate_rows, rch_diag *d);

/* rch_calib_print.c: "2 of the 3 steps the change-point search found are
 * far above the residual (...)" into buf (len), for the report and the
 * model file's refusal. */
void rch_calib_jump_counts(char *buf, size_t len, const struct rch_calib_result *r);
/* rch_calib_print.c: the data file a report names (the first positions file
 * without one). */
const char *rch_calib_data_name(const struct rch_calib_result *r);

/* rch_calib_screen.c: the rows of s (n; their lines and files) the fitted
 * r->model cannot reconcile with the rest, marked in drop (n) and named in
 * r->screen. Returns how many rows are out (0: none), or -1 with d set when
 * too many are (the file refused) or memory runs out. */
int rch_calib_screen(struct rch_calib_result *r, uint8_t *drop, const rc_sample *s, size_t n, const unsigned *line,
                     const unsigned *file_of, rch_diag *d);

/* rch_calib_sys.c: the score statistics of a length offset (each outlet's)
 * and a linear drift at the fit at hand (r->model, or r->jumps.model), over
 * the rows s (n), the parameters fixed held; into out's scores, penalties,
 * sizes and testable flags. 0, or -1 with err set. */
struct rch_calib_sys;
int rch_calib_sys_score(struct rch_calib_sys *out, const struct rch_calib_result *r, const uint8_t *fixed,
                        const rc_sample *s, size_t n, char *err, size_t errlen);

/* rch_calib_judge.c: r->judge from the fit at hand over its rows s (n):
 * the sensor's floor, the noise against it, the model against the
 * nominal one, and (when either fails) the causes tried. */
void rch_calib_judge_run(struct rch_calib_result *r, rc_solve_work *w, const rc_sample *s, size_t n);

#endif
