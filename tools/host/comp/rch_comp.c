/* SPDX-License-Identifier: MIT */
/* rch_comp.c - one target through the compensation (see rch_comp.h): the
 * joint limits, the gate (the posterior's 95 % radius at the target against
 * --max-uncertainty-mm: above it the target is left as it was), the stream
 * step, its counts and warnings, and the --uncertainty-out line. What the
 * CSV path (rch_comp_csv.c) and the RAPID path (rch_comp_rapid.c) share;
 * the run is rch_comp_run.c, the models rch_comp_model.c; internals in
 * rch_comp_int.h.
 * Depends on: rc_comp (lib), rch_uncert. Memory: none. Errors: -1 with d
 * set (a joint outside its limits); a target not converged is counted and
 * warned about. */
#include "rch_comp.h"

#include <math.h>
#include <string.h>
#include <time.h>

#include "rch_comp_int.h"

static double now_ns(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec * 1e9 + (double)t.tv_nsec;
}

double rch_comp_u95_written(double u95_mm, int status, double miss_mm)
{
    if (status == 3)
        return NAN;
    if (status == 2)
        return u95_mm + (miss_mm > 0.0 ? miss_mm : 0.0);
    return u95_mm;
}

/* One line of --uncertainty-out (when asked for): "nan" where the u95 is
 * unknown (a model without an uncertainty, a target left uncompensated). */
static void u95_line(const rch_cpi_ctx *c, unsigned line, double u95_mm)
{
    if (c->gate && c->gate->u95_out) {
        if (isnan(u95_mm))
            fprintf(c->gate->u95_out, "%u,nan\n", line);
        else
            fprintf(c->gate->u95_out, "%u,%.6f\n", line, u95_mm);
    }
}

/* Compensate one target (degrees in, degrees out). 0 ok, 1 not converged
 * (output still written), -1 range error (d set). cols: (6) columns of the
 * fields for diagnostics. */
int rch_cpi_compensate(rch_cpi_ctx *c, double out_deg[RC_NJ], const double in_deg[RC_NJ], unsigned line,
                       const unsigned cols[RC_NJ], rch_diag *d)
{
    rc_real q[RC_NJ], qc[RC_NJ];
    const rc_model *m = c->cal;
    for (unsigned i = 0; i < RC_NJ; ++i) {
        q[i] = (rc_real)(in_deg[i] * DEG);
        if ((double)q[i] < m->q_min_rad[i] || (double)q[i] > m->q_max_rad[i]) {
            rch_diag_set(d, c->in_name, line, cols[i], "q%u = %g deg is outside the joint limits [%g, %g] deg", i + 1,
                         in_deg[i], m->q_min_rad[i] / DEG, m->q_max_rad[i] / DEG);
            return -1;
        }
    }
    double u95_at = NAN; /* the posterior's radius at the target, when the model has one */
    if (c->gate) {
        double qd[RC_NJ], pf[3], pd[3];
        for (unsigned i = 0; i < RC_NJ; ++i)
            qd[i] = (double)q[i];
        if (c->fit) {
            rc_fk(pf, NULL, c->fit, qd);
            rc_fk(pd, NULL, m, qd);
            double e = sqrt((pf[0] - pd[0]) * (pf[0] - pd[0]) + (pf[1] - pd[1]) * (pf[1] - pd[1]) +
                            (pf[2] - pd[2]) * (pf[2] - pd[2]));
            if (e > c->res->max_held_mm)
                c->res->max_held_mm = e;
        }
        const rch_model_unc *unc = c->gate->unc && c->gate->unc->present ? c->gate->unc : NULL;
        /* no covariance: the u95 is unknown (NaN, "n/a"), never 0 */
        const double u95 = !unc ? NAN : unc->has_prior ? rch_model_unc_radius95_mm(unc, m, qd)
                                                        : rch_model_unc_pos95_mm(unc, m, qd);
        u95_at = u95;
        /* A posterior (MAP) model: compensation never makes the expected
         * error larger than the uncompensated target's (the posterior is
         * never wider than the prior the nominal model stands for), so
         * there is no limit unless the user sets one. A model without
         * (least squares): 1 mm, its covariance leaves out what it held. A
         * model without an uncertainty: no limit unless one is set, and
         * then no target can be shown to be within it (the policy acts on
         * every target). */
        const double lim = c->gate->max_unc_mm > 0 ? c->gate->max_unc_mm
                           : !unc || unc->has_prior ? INFINITY
                                                    : 1.0;
        /* beyond the limit: a known u95 above it (or not a number), an
         * unknown one against a limit the user set */
        const int beyond = unc ? !(u95 <= lim) : isfinite(lim);
        char u95s[64];
        if (isnan(u95))
            snprintf(u95s, sizeof u95s, "unknown (the model carries no uncertainty)");
        else
            snprintf(u95s, sizeof u95s, "%.4f mm", u95);
        if (beyond && c->gate->u95_policy == RCH_COMP_U95_REFUSE) {
            rch_diag_set(d, c->in_name, line, 0,
                         "the model's 95 %% position uncertainty at the compensated point is %s here, above %.4f mm "
                         "(--u95-policy refuse: nothing written)",
                         u95s, lim);
            return -1;
        }
        if (beyond && c->gate->u95_policy == RCH_COMP_U95_WARN) {
            c->res->n_uncertain++;
            if (c->warn)
                fprintf(c->warn,
                        "%s:%u: warning: compensated, but the model's 95 %% position uncertainty at the "
                        "compensated point is %s here, above %.4f mm\n",
                        c->in_name, line, u95s, lim);
        } else if (beyond) {
            for (unsigned i = 0; i < RC_NJ; ++i)
                out_deg[i] = in_deg[i];
            u95_line(c, line, rch_comp_u95_written(u95, 3, 0.0));
            c->res->n_uncertain++;
            if (c->warn)
                fprintf(c->warn,
                        "%s:%u: warning: target left uncompensated: the model's 95 %% position uncertainty here "
                        "is %s, above %.4f mm (%s)\n",
                        c->in_name, line, u95s, lim,
                        unc ? "the data did not determine the model at this pose"
                            : "--max-uncertainty-mm cannot be met by a model without one");
            return 1;
        }
        if (u95 > c->res->max_pos95_mm)
            c->res->max_pos95_mm = u95;
    }
    rc_comp_result res;
    const double t0 = now_ns();
    rc_status st = rc_comp_stream_step(c->stream, qc, &res, q);
    rch_comp_result *r = c->res;
    r->t_ns += now_ns() - t0;
    r->n++;
    r->iters += res.iterations;
    for (unsigned i = 0; i < RC_NJ; ++i)
        out_deg[i] = (double)qc[i] / DEG;
    if ((double)res.corr_max_rad / DEG > r->max_corr_deg)
        r->max_corr_deg = (double)res.corr_max_rad / DEG;
    if (st == RC_OK) {
        if (res.exit == RC_COMP_POSITION_ONLY)
            r->n_pos_only++;
        u95_line(c, line, rch_comp_u95_written(u95_at, res.exit == RC_COMP_POSITION_ONLY, 0.0));
        return 0;
    }
    u95_line(c, line, rch_comp_u95_written(u95_at, 2, (double)res.pos_err_mm));
    r->n_fail++;
    if ((double)res.pos_err_mm > r->max_fail_err_mm)
        r->max_fail_err_mm = (double)res.pos_err_mm;
    char joints[64] = "";
    if (res.exit == RC_COMP_JOINT_LIMIT || res.exit == RC_COMP_MAX_DEV) {
        const unsigned mask = res.exit == RC_COMP_JOINT_LIMIT ? res.limit_mask : res.bound_mask;
        size_t k = (size_t)snprintf(joints, sizeof joints, " (joint%s", (mask & (mask - 1u)) ? "s" : "");
        for (unsigned i = 0; i < RC_NJ && k < sizeof joints; ++i)
            if (mask & (1u << i))
                k += (size_t)snprintf(joints + k, sizeof joints - k, " %u", i + 1);
        if (k < sizeof joints)
            snprintf(joints + k, sizeof joints - k, ")");
    }
    if (res.exit == RC_COMP_JOINT_LIMIT)
        r->n_joint_limit++;
    if (c->warn != NULL)
        fprintf(c->warn,
                "%s:%u: warning: target not compensated: %s%s; wrote %s, %.4f mm from the nominal position\n",
                c->in_name, line, st == RC_ERR_NOCONV ? rc_comp_exit_str(res.exit) : rc_strerror(st), joints,
                st != RC_ERR_NOCONV ? "the target"
                : res.held_last     ? "the target plus the last good correction (on a path)"
                                    : "the closest point found within the bounds",
                (double)res.pos_err_mm);
    return 1;
}

int rch_cpi_compensate_at(rch_cpi_ctx *c, double out_deg[RC_NJ], const double in_deg[RC_NJ], unsigned line,
                          const unsigned cols[RC_NJ], char *why, size_t why_len)
{
    rch_diag dd;
    memset(&dd, 0, sizeof dd);
    const unsigned long before = c->res->n_uncertain;
    const int r = rch_cpi_compensate(c, out_deg, in_deg, line, cols, &dd);
    c->stream = c->stream0;
    c->cal = c->cal0;
    c->fit = c->fit0;
    if (r < 0) {
        snprintf(why, why_len, "%.300s", dd.msg);
        return -1;
    }
    return c->res->n_uncertain != before ? 2 : r;
}
