/* SPDX-License-Identifier: MIT */
/* rch_calib_plan.c - the runner of the calibration's plans (rch_calib_int.h,
 * rch_calib_plan_run): a table of stages run in order, each one's own wall
 * and CPU time booked in one timing record (rch_calib.h, rch_calib_timing),
 * the table started again when a stage asks (RCH_PLAN_AGAIN). The plans
 * themselves: rch_calib.c (the run: read, set-up, split and fit, the
 * systematic errors, the screen, the judge, the outputs) and
 * rch_calib_fit.c (one fit: start, MAP, jump check, attachment, prior
 * scale, jumps, metrics, uncertainty).
 *
 * Depends on: clock_gettime (POSIX). Memory: none. Errors: a stage's code.
 */
#include "rch_calib_int.h"

#include "rch_calib.h"

#include <time.h>

static const char *const stage_names[RCH_STAGE_N] = {
    "read", "setup", "split", "start", "map", "jump_check", "attachment", "prior_scale",
    "jumps", "metrics", "uncertainty", "systematic", "screen", "judge", "outputs",
};

const char *rch_calib_stage_name(unsigned id)
{
    return id < RCH_STAGE_N ? stage_names[id] : "?";
}

static double clock_ms(clockid_t id)
{
    struct timespec t;
    clock_gettime(id, &t);
    return (double)t.tv_sec * 1e3 + (double)t.tv_nsec / 1e6;
}

int rch_calib_plan_run(const rch_calib_stage *plan, size_t n, void *run, struct rch_calib_result *r,
                       struct rch_calib_timing *t, rch_diag *d)
{
    unsigned again = 0;
    for (size_t i = 0; i < n; ++i) {
        const unsigned id = plan[i].id < RCH_STAGE_N ? plan[i].id : RCH_STAGE_OUTPUTS;
        const double w0 = clock_ms(CLOCK_MONOTONIC), c0 = clock_ms(CLOCK_PROCESS_CPUTIME_ID);
        const double bw = t->total_wall_ms, bc = t->total_cpu_ms; /* what the stages inside it book */
        const int rc = plan[i].fn(run, r, d);
        const double ow = clock_ms(CLOCK_MONOTONIC) - w0 - (t->total_wall_ms - bw);
        const double oc = clock_ms(CLOCK_PROCESS_CPUTIME_ID) - c0 - (t->total_cpu_ms - bc);
        t->wall_ms[id] += ow;
        t->cpu_ms[id] += oc;
        t->runs[id]++;
        t->total_wall_ms += ow;
        t->total_cpu_ms += oc;
        if (rc == RCH_PLAN_AGAIN && again < RCH_PLAN_MAX_AGAIN) {
            again++;
            i = (size_t)-1; /* the table from its first stage (i wraps to 0) */
            continue;
        }
        if (rc != 0 && rc != RCH_PLAN_AGAIN)
            return rc;
    }
    return 0;
}
