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

struct rch_calib_result;

/* rch_calib_fit.c: identification and the figures once the split is made:
 * the BC model, the fit (maximum a posteriori with the prior, the cable
 * attachment decided, the jump check; or --jumps), the before/after
 * metrics, then rch_calib_finish. train (r->n_train), test (r->n_test).
 * 0, -1 with d set, -2 on a bad --fix name. */
int rch_calib_fit_and_report(struct rch_calib_result *r, rc_solve_work *w, const rc_sample *train,
                             const rc_sample *test, rch_diag *d);

/* rch_calib_figures.c: after the fit: truth, identifiability, uncertainty
 * (and its plot), validation. fixed (r->model.n_params): the parameters
 * held; fit: the model fitted to train (r->model, or with the jumps'
 * offsets); setup (r->n_train, or NULL): the covariance's clusters. 0, or
 * -1 with d set. */
int rch_calib_finish(struct rch_calib_result *r, const uint8_t *fixed, const rc_sample *train, const rc_model *fit,
                     const uint16_t *setup, rch_diag *d);

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
