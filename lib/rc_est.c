/* SPDX-License-Identifier: MIT */
/* rc_est.c - EKF, PF, SCA, QIBAS and SSLM identification; see rc_est.h. */
#include "rc_est.h"

#include <math.h>
#include <string.h>

#include "rc_ident.h"
#include "rc_linalg.h"
#include "rc_rand.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

RC_STATIC_ASSERT(RC_EST_MAX_POP * RC_MAX_PARAMS < 4 * 1024 * 1024, est_pop_size);

const char *rc_est_method_name(rc_est_method method)
{
#define RC_EST_NAME_(id, name) name,
    static const char *const names[] = {RC_EST_METHODS(RC_EST_NAME_)};
#undef RC_EST_NAME_
    return (unsigned)method < sizeof names / sizeof names[0] ? names[method] : "unknown";
}

/* ---- identifiable subset ---------------------------------------------- */

rc_status rc_est_subset(uint8_t *fixed_out, unsigned *n_kept, rc_est_work *w, const rc_model *m,
                        const uint8_t *fixed_in, double tol, const rc_sample *samples, size_t n)
{
    unsigned nf = 0, kept = 0;
    double cost;
    RC_ASSERT(fixed_out != NULL && n_kept != NULL && w != NULL && m != NULL);
    *n_kept = 0;
    if (samples == NULL || n == 0 || m->n_params > RC_MAX_PARAMS)
        return RC_ERR_ARG;
    if (!(tol > 0.0)) /* rc_ident's null bound on a relative singular value, squared (see below) */
        tol = RC_IDENT_NULL_REL * RC_IDENT_NULL_REL;
    for (unsigned k = 0; k < m->n_params; ++k) {
        fixed_out[k] = 1;
        if (fixed_in == NULL || fixed_in[k] == 0)
            w->idx[nf++] = (uint16_t)k;
    }
    if (nf == 0)
        return RC_ERR_RANK;
    rc_status st = rc_normal_eq(w->P, w->g, &cost, w->jrow, m, w->idx, nf, samples, n);
    if (st != RC_OK)
        return st;
    /* correlation matrix C = D^-1 A D^-1; zero columns stay zero. D is
     * rc_ident's column scale: a column at most RC_IDENT_ZERO_COL of the
     * largest in norm (e.g. alpha6, theta6: rounding-level values) counts as
     * zero, never identifiable. The pivot cut below is rc_ident's null
     * bound: a column whose residual diagonal (its squared distance, as a
     * unit column, from the span of those kept) is below tol =
     * RC_IDENT_NULL_REL^2 would add a direction of relative singular value
     * below RC_IDENT_NULL_REL (s_min <= sqrt(residual), s_max >= 1), which
     * rc_ident calls not identifiable: a dropped parameter is always a
     * null one. The converse is looser: the residual is not divided by
     * s_max^2 (>= 1), so a pair down to about half the bound in s_rel is
     * still kept (tests/lib/test_solve.c, test_solve_cut_is_rc_ident). */
    rc_ident_scale(w->D, w->P, nf, (size_t)nf + 1);
    for (unsigned i = 0; i < nf; ++i)
        for (unsigned k = 0; k < nf; ++k) {
            const double d = w->D[i] * w->D[k];
            w->P[(size_t)i * nf + k] = d > 0.0 ? w->P[(size_t)i * nf + k] / d : 0.0;
        }
    /* greedy pivoted Cholesky: pick the largest residual diagonal, eliminate.
     * v[i] = residual diagonal of i; T holds the columns of the factor. */
    uint8_t *used = w->mask;
    for (unsigned i = 0; i < nf; ++i) {
        w->v[i] = w->P[(size_t)i * nf + i];
        used[i] = 0;
    }
    for (unsigned step = 0; step < nf; ++step) {
        unsigned piv = nf;
        double best = tol;
        for (unsigned i = 0; i < nf; ++i)
            if (!used[i] && w->v[i] > best) {
                best = w->v[i];
                piv = i;
            }
        if (piv == nf)
            break;
        used[piv] = 1;
        const double lpp = sqrt(w->v[piv]);
        /* column `step` of L: L[i] = (C[i][piv] - sum_k L_k[i] L_k[piv]) / lpp */
        for (unsigned i = 0; i < nf; ++i) {
            double s = w->P[(size_t)i * nf + piv];
            for (unsigned k = 0; k < step; ++k)
                s -= w->T[(size_t)k * nf + i] * w->T[(size_t)k * nf + piv];
            w->T[(size_t)step * nf + i] = used[i] && i != piv ? 0.0 : s / lpp;
        }
        for (unsigned i = 0; i < nf; ++i)
            if (!used[i]) {
                const double l = w->T[(size_t)step * nf + i];
                w->v[i] -= l * l;
            }
        fixed_out[w->idx[piv]] = 0;
        ++kept;
    }
    *n_kept = kept;
    return kept > 0 ? RC_OK : RC_ERR_RANK;
}

/* ---- shared helpers --------------------------------------------------- */

typedef struct est_ctx {
    rc_est_work *w;
    const rc_est_config *cfg;
    const rc_model *start;
    const rc_sample *s;
    size_t n;
    unsigned nf;
    rc_est_result *res;
    double best_cost;   /* objective of w->ubest (normalised methods) */
    rc_solve_config pc; /* the prior (rc_prior_cost, rc_prior_normal_eq); no prior: all zero */
    int prior;
    const double *sin_q, *cos_q; /* (n x 6) the readings' sines and cosines in w->T's unused tail, or NULL */
} est_ctx;

/* The objective every method minimises: the squared residuals, plus the
 * prior's rows when there is a prior (the MAP objective, as rc_solve's). */
static rc_status objective(double *f, const est_ctx *c, const rc_model *m)
{
    const rc_status st = rc_cost_tab(f, m, c->s, c->sin_q, c->cos_q, c->n);
    if (st == RC_OK && c->prior)
        *f += rc_prior_cost(m, &c->pc);
    return st;
}

static double rms_of(double cost, size_t n) { return sqrt(cost / (double)n); }

static double clamp1(double v) { return v < -1.0 ? -1.0 : (v > 1.0 ? 1.0 : v); }

/* Reflect into [-1, 1] (one reflection, then clamp). */
static double reflect1(double v)
{
    if (v > 1.0)
        v = 2.0 - v;
    if (v < -1.0)
        v = -2.0 - v;
    return clamp1(v);
}

/* out = start with the moved parameters at normalised u. */
static void model_at(rc_model *out, const est_ctx *c, const double *u)
{
    *out = *c->start;
    for (unsigned j = 0; j < c->nf; ++j)
        out->x[c->w->idx[j]] = c->w->x0[j] + c->w->bound[j] * u[j];
}

/* Cost at normalised u; a failed evaluation counts as +inf. */
static double cost_u(est_ctx *c, const double *u)
{
    double cost;
    model_at(&c->w->trial, c, u);
    ++c->res->cost_evals;
    if (objective(&cost, c, &c->w->trial) != RC_OK || !isfinite(cost))
        return HUGE_VAL;
    return cost;
}

/* Keep u as the best point when its cost is lower. */
static void offer(est_ctx *c, const double *u, double cost)
{
    if (cost < c->best_cost) {
        c->best_cost = cost;
        memcpy(c->w->ubest, u, c->nf * sizeof u[0]);
    }
}

/* The training RMS a curve shows at m whose objective is f: the data's
 * residuals only (with a prior the objective also holds the prior's rows). */
static double curve_rms(const est_ctx *c, const rc_model *m, double f)
{
    double ssr;
    if (c->prior && rc_cost(&ssr, m, c->s, c->n) == RC_OK)
        return rms_of(ssr, c->n);
    return rms_of(f, c->n);
}

static void report(est_ctx *c, unsigned it)
{
    c->res->iterations = it;
    if (c->cfg->on_iter) {
        model_at(&c->w->best, c, c->w->ubest);
        c->cfg->on_iter(c->cfg->cb_ctx, it, curve_rms(c, &c->w->best, c->best_cost), &c->w->best);
    }
}

/* ---- M4 SCA ------------------------------------------------------------ */

static void run_sca(est_ctx *c, rc_rng *g)
{
    rc_est_work *w = c->w;
    const unsigned N = c->cfg->pop ? c->cfg->pop : 30u;
    const unsigned T = c->cfg->max_iter ? c->cfg->max_iter : 500u;
    const unsigned nf = c->nf;
    const double a = 2.0;
    for (unsigned i = 0; i < N; ++i) {
        double *X = &w->pop[(size_t)i * nf];
        for (unsigned j = 0; j < nf; ++j)
            X[j] = i == 0 ? 0.0 : 2.0 * rc_rng_u01(g) - 1.0;
        w->fit[i] = cost_u(c, X);
        offer(c, X, w->fit[i]);
    }
    for (unsigned t = 0; t < T; ++t) {
        const double r1 = a - (double)t * a / (double)T;
        for (unsigned i = 0; i < N; ++i) {
            double *X = &w->pop[(size_t)i * nf];
            for (unsigned j = 0; j < nf; ++j) {
                const double r2 = 2.0 * M_PI * rc_rng_u01(g);
                const double r3 = 2.0 * rc_rng_u01(g);
                const double r4 = rc_rng_u01(g);
                const double dist = fabs(r3 * w->ubest[j] - X[j]);
                X[j] += r4 < 0.5 ? r1 * sin(r2) * dist : r1 * cos(r2) * dist;
                X[j] = clamp1(X[j]);
            }
        }
        /* evaluate after the whole population moved (Mirjalili's order) */
        for (unsigned i = 0; i < N; ++i) {
            const double *X = &w->pop[(size_t)i * nf];
            w->fit[i] = cost_u(c, X);
            offer(c, X, w->fit[i]);
        }
        report(c, t + 1);
    }
}

/* ---- M5 QIBAS ---------------------------------------------------------- */

static void run_qibas(est_ctx *c, rc_rng *g)
{
    rc_est_work *w = c->w;
    const unsigned T = c->cfg->max_iter ? c->cfg->max_iter : 2000u;
    const unsigned nf = c->nf;
    const double d0 = c->cfg->qibas_d0 > 0.0 ? c->cfg->qibas_d0 : 0.2;
    const double dmin = 1e-6;
    const double eta = pow(dmin / d0, 1.0 / (double)T);
    double *x = w->u, *b = w->v, *xt = w->dx;
    double f, d = d0;
    memset(x, 0, nf * sizeof x[0]);
    f = cost_u(c, x);
    offer(c, x, f);
    for (unsigned t = 0; t < T; ++t) {
        double nb = 0.0, fl, fr, fq, tq, bestf, bestt = 0.0;
        const double step = 2.0 * d;
        do {
            nb = 0.0;
            for (unsigned j = 0; j < nf; ++j) {
                b[j] = rc_rng_normal(g);
                nb += b[j] * b[j];
            }
        } while (!(nb > 1e-300));
        nb = sqrt(nb);
        for (unsigned j = 0; j < nf; ++j)
            b[j] /= nb;
        for (unsigned j = 0; j < nf; ++j)
            xt[j] = clamp1(x[j] - d * b[j]);
        fl = cost_u(c, xt);
        for (unsigned j = 0; j < nf; ++j)
            xt[j] = clamp1(x[j] + d * b[j]);
        fr = cost_u(c, xt);
        const double curv = fl - 2.0 * f + fr;
        if (curv > 0.0 && isfinite(curv)) {
            tq = d * (fl - fr) / (2.0 * curv);
            if (tq > step)
                tq = step;
            if (tq < -step)
                tq = -step;
        } else {
            tq = fr < fl ? step : -step; /* BAS: toward the better antenna */
        }
        for (unsigned j = 0; j < nf; ++j)
            xt[j] = clamp1(x[j] + tq * b[j]);
        fq = cost_u(c, xt);
        bestf = f;
        if (fl < bestf) {
            bestf = fl;
            bestt = -d;
        }
        if (fr < bestf) {
            bestf = fr;
            bestt = d;
        }
        if (fq < bestf) {
            bestf = fq;
            bestt = tq;
        }
        if (bestt != 0.0) {
            for (unsigned j = 0; j < nf; ++j)
                x[j] = clamp1(x[j] + bestt * b[j]);
            f = bestf;
            offer(c, x, f);
        }
        d = d * eta > dmin ? d * eta : dmin;
        report(c, t + 1);
    }
}

/* ---- M3 PF ------------------------------------------------------------- */

/* Effective sample size of weights exp(phi * lam_i), normalised into wgt. */
static double pf_weights(double *wgt, const double *lam, unsigned N, double phi)
{
    double sum = 0.0, sq = 0.0;
    for (unsigned i = 0; i < N; ++i) {
        wgt[i] = isfinite(lam[i]) ? exp(phi * lam[i]) : 0.0;
        sum += wgt[i];
    }
    if (!(sum > 0.0))
        return 0.0;
    for (unsigned i = 0; i < N; ++i) {
        wgt[i] /= sum;
        sq += wgt[i] * wgt[i];
    }
    return 1.0 / sq;
}

static void run_pf(est_ctx *c, rc_rng *g)
{
    rc_est_work *w = c->w;
    const unsigned N = c->cfg->pop ? c->cfg->pop : 100u;
    const unsigned T = c->cfg->max_iter ? c->cfg->max_iter : 100u;
    const unsigned nf = c->nf;
    const double h = pow(4.0 / ((double)(nf + 2) * (double)N), 1.0 / (double)(nf + 4));
    const double shrink = sqrt(1.0 - h * h); /* Liu-West: the kernel keeps the variance */
    double *lam = w->fit2, *mean = w->v, *sd = w->dx;
    for (unsigned i = 0; i < N; ++i) {
        double *X = &w->pop[(size_t)i * nf];
        for (unsigned j = 0; j < nf; ++j)
            X[j] = i == 0 ? 0.0 : clamp1(rc_rng_normal(g) / 3.0);
        w->fit[i] = cost_u(c, X);
        offer(c, X, w->fit[i]);
    }
    for (unsigned t = 0; t < T; ++t) {
        double cmin = HUGE_VAL, phi, ess;
        for (unsigned i = 0; i < N; ++i)
            if (w->fit[i] < cmin)
                cmin = w->fit[i];
        if (!isfinite(cmin))
            break;
        const double R = cmin / (double)c->n > 1e-30 ? cmin / (double)c->n : 1e-30;
        for (unsigned i = 0; i < N; ++i)
            lam[i] = -(w->fit[i] - cmin) / (2.0 * R);
        /* largest phi <= 1 with ESS >= N/2 (bisection on log phi) */
        phi = 1.0;
        ess = pf_weights(w->wgt, lam, N, phi);
        if (ess < 0.5 * (double)N) {
            double lo = 0.0, hi = 1.0;
            for (int k = 0; k < 50; ++k) {
                const double mid = 0.5 * (lo + hi);
                if (pf_weights(w->wgt, lam, N, mid) >= 0.5 * (double)N)
                    lo = mid;
                else
                    hi = mid;
            }
            phi = lo;
            ess = pf_weights(w->wgt, lam, N, phi);
        }
        (void)ess;
        /* weighted mean and sd; the mean is a candidate estimate */
        for (unsigned j = 0; j < nf; ++j) {
            double mu = 0.0, var = 0.0;
            for (unsigned i = 0; i < N; ++i)
                mu += w->wgt[i] * w->pop[(size_t)i * nf + j];
            for (unsigned i = 0; i < N; ++i) {
                const double dv = w->pop[(size_t)i * nf + j] - mu;
                var += w->wgt[i] * dv * dv;
            }
            mean[j] = mu;
            sd[j] = sqrt(var) > 1e-7 ? sqrt(var) : 1e-7;
        }
        offer(c, mean, cost_u(c, mean));
        /* systematic resampling into pop2 */
        {
            const double u0 = rc_rng_u01(g) / (double)N;
            double cum = w->wgt[0];
            unsigned i = 0;
            for (unsigned k = 0; k < N; ++k) {
                const double uk = u0 + (double)k / (double)N;
                while (uk > cum && i + 1 < N)
                    cum += w->wgt[++i];
                memcpy(&w->pop2[(size_t)k * nf], &w->pop[(size_t)i * nf], nf * sizeof(double));
            }
        }
        /* jitter (regularisation) and evaluate */
        for (unsigned k = 0; k < N; ++k) {
            double *X = &w->pop[(size_t)k * nf];
            const double *Y = &w->pop2[(size_t)k * nf];
            for (unsigned j = 0; j < nf; ++j)
                X[j] = reflect1(shrink * Y[j] + (1.0 - shrink) * mean[j] +
                                h * sd[j] * rc_rng_normal(g));
            w->fit[k] = cost_u(c, X);
            offer(c, X, w->fit[k]);
        }
        report(c, t + 1);
    }
}

/* ---- M2 EKF ------------------------------------------------------------ */

/* One scalar measurement of the filters (run_ekf, run_iekf): with h = w->g
 * (nf) the measurement row, S = h^T P h + R, gain K = P h / S, the state
 * x_idx += K innov and P by the Joseph form P = (I - K h^T) P (I - K h^T)^T +
 * R K K^T (as M = P - K (Ph)^T; P' = M - (M h) K^T + R K K^T, symmetrised).
 * *S and *hph get S and h^T P h before the update. RC_ERR_NUMERIC when S is
 * not positive. Scratch: w->dx (Ph), w->v (K), w->D (M h), w->T (M). */
static rc_status kalman_update(double *S_out, double *hph_out, rc_est_work *w, rc_model *x, unsigned nf, double R,
                               double innov)
{
    const double *h = w->g;
    double *Ph = w->dx, *K = w->v, *Mh = w->D, hph = 0.0;
    for (unsigned i = 0; i < nf; ++i) {
        double acc = 0.0;
        for (unsigned k = 0; k < nf; ++k)
            acc += w->P[(size_t)i * nf + k] * h[k];
        Ph[i] = acc;
        hph += h[i] * acc;
    }
    const double S = hph + R;
    *S_out = S;
    *hph_out = hph;
    if (!(S > 0.0) || !isfinite(S))
        return RC_ERR_NUMERIC;
    for (unsigned i = 0; i < nf; ++i) {
        K[i] = Ph[i] / S;
        x->x[w->idx[i]] += K[i] * innov;
    }
    for (unsigned i = 0; i < nf; ++i)
        for (unsigned k = 0; k < nf; ++k)
            w->T[(size_t)i * nf + k] = w->P[(size_t)i * nf + k] - K[i] * Ph[k];
    for (unsigned i = 0; i < nf; ++i) {
        double acc = 0.0;
        for (unsigned k = 0; k < nf; ++k)
            acc += w->T[(size_t)i * nf + k] * h[k];
        Mh[i] = acc;
    }
    for (unsigned i = 0; i < nf; ++i)
        for (unsigned k = i; k < nf; ++k) {
            const double a = w->T[(size_t)i * nf + k] - Mh[i] * K[k] + R * K[i] * K[k];
            const double b = w->T[(size_t)k * nf + i] - Mh[k] * K[i] + R * K[k] * K[i];
            w->P[(size_t)i * nf + k] = w->P[(size_t)k * nf + i] = 0.5 * (a + b);
        }
    return RC_OK;
}

static rc_status run_ekf(est_ctx *c, rc_model *m)
{
    rc_est_work *w = c->w;
    const rc_est_config *cfg = c->cfg;
    const unsigned T = cfg->max_iter ? cfg->max_iter : 10u;
    const unsigned nf = c->nf;
    const double res_mm = cfg->resolution_mm > 0.0 ? cfg->resolution_mm : 0.004;
    const double sig = cfg->noise_mm > 0.0 ? cfg->noise_mm : res_mm / sqrt(12.0);
    const double alpha = cfg->ekf_alpha > 0.0 ? (cfg->ekf_alpha < 1.0 ? cfg->ekf_alpha : 1.0) : 0.3;
    const double q = cfg->ekf_q > 0.0 ? cfg->ekf_q : 1e-9;
    const double tol = cfg->tol_cost > 0.0 ? cfg->tol_cost : 1e-10;
    double *h = w->g;
    double prev = c->best_cost;
    /* R starts at the caller's noise, else at the start's mean squared
     * residual (what the residual-based rule would converge to at x0) */
    double R = cfg->noise_mm > 0.0 ? sig * sig : c->best_cost / (double)c->n;
    if (!(R >= sig * sig))
        R = sig * sig;
    rc_model *x = &w->trial; /* the filter state lives in a model */
    *x = *m;
    for (unsigned pass = 0; pass < T; ++pass) {
        memset(w->P, 0, (size_t)nf * nf * sizeof(double));
        for (unsigned j = 0; j < nf; ++j)
            w->P[(size_t)j * nf + j] = w->bound[j] * w->bound[j];
        for (size_t s = 0; s < c->n; ++s) {
            double l, hph = 0.0;
            if (rc_meas(&l, w->jrow, x, &c->s[s]) != RC_OK)
                continue; /* degenerate sample: no information */
            const double innov = c->s[s].value - l;
            for (unsigned j = 0; j < nf; ++j) {
                h[j] = w->jrow[w->idx[j]];
                w->P[(size_t)j * nf + j] += q * w->bound[j] * w->bound[j];
            }
            double S;
            if (kalman_update(&S, &hph, w, x, nf, R, innov) != RC_OK)
                return RC_ERR_NUMERIC;
            /* Residual-based adaptive measurement noise: the post-update
             * residual eps = innov R / S and h^T P+ h = hph R / S (both exact
             * for the linearised measurement) give
             * R <- alpha R + (1 - alpha) (eps^2 + h^T P+ h). */
            {
                const double eps = innov * R / S;
                R = alpha * R + (1.0 - alpha) * (eps * eps + hph * R / S);
                if (!(R > 1e-300) || !isfinite(R))
                    R = sig * sig;
            }
        }
        double cost;
        ++c->res->cost_evals;
        rc_status st = rc_cost(&cost, x, c->s, c->n);
        if (st == RC_OK) {
            c->best_cost = cost; /* the filter's estimate after this pass */
            w->best = *x;
        }
        c->res->iterations = pass + 1;
        if (cfg->on_iter)
            cfg->on_iter(cfg->cb_ctx, pass + 1, rms_of(c->best_cost, c->n),
                         c->best_cost < HUGE_VAL ? &w->best : m);
        if (st != RC_OK)
            break;
        if (prev - cost >= 0.0 && prev - cost < tol * prev)
            break;
        prev = cost;
    }
    return RC_OK;
}

/* M2 with a prior: the iterated EKF (Bell & Cathey 1993). Each pass filters
 * the samples from the prior (mean: the prior's for parameters that have one,
 * the start's for the others; covariance diag(sd^2), (10 box)^2 for the
 * others) with every measurement linearised at the previous pass's estimate
 * x_lin: predicted l(x_lin) + h (x - x_lin). R is the prior's noise^2, fixed
 * (the weight the prior is given against the data), no process noise. A pass
 * is one Gauss-Newton step on the MAP objective, so the fixed point is the
 * MAP estimate; the pass that lowers the objective least ends it, the best
 * pass is returned. */
static rc_status run_iekf(est_ctx *c, rc_model *m)
{
    rc_est_work *w = c->w;
    const rc_est_config *cfg = c->cfg;
    const unsigned T = cfg->max_iter ? cfg->max_iter : 10u;
    const unsigned nf = c->nf;
    const double tol = cfg->tol_cost > 0.0 ? cfg->tol_cost : 1e-10;
    const double R = cfg->prior_noise_mm * cfg->prior_noise_mm;
    double *h = w->g;
    double *xl = w->pop; /* (nf) the linearisation point, x_lin - start */
    double prev = c->best_cost;
    rc_model *x = &w->trial; /* the filter state */
    rc_model *lin = &w->best;
    *lin = *m;
    for (unsigned pass = 0; pass < T; ++pass) {
        *x = *m;
        memset(w->P, 0, (size_t)nf * nf * sizeof(double));
        for (unsigned j = 0; j < nf; ++j) {
            const unsigned k = w->idx[j];
            const double sd = cfg->prior_sd[k];
            const int has = sd > 0.0 && isfinite(sd);
            x->x[k] = has ? cfg->prior_mean[k] : m->x[k];
            w->P[(size_t)j * nf + j] = has ? sd * sd : 100.0 * w->bound[j] * w->bound[j];
            xl[j] = lin->x[k];
        }
        for (size_t s = 0; s < c->n; ++s) {
            double l, hph = 0.0, pred;
            if (rc_meas(&l, w->jrow, lin, &c->s[s]) != RC_OK)
                continue; /* degenerate sample: no information */
            pred = l;
            for (unsigned j = 0; j < nf; ++j) {
                h[j] = w->jrow[w->idx[j]];
                pred += h[j] * (x->x[w->idx[j]] - xl[j]);
            }
            const double innov = c->s[s].value - pred;
            double S;
            if (kalman_update(&S, &hph, w, x, nf, R, innov) != RC_OK)
                return RC_ERR_NUMERIC;
        }
        double cost;
        ++c->res->cost_evals;
        const rc_status st = objective(&cost, c, x);
        c->res->iterations = pass + 1;
        if (st != RC_OK || !(cost < prev)) { /* no better than the last pass: it is the estimate */
            if (cfg->on_iter)
                cfg->on_iter(cfg->cb_ctx, pass + 1, curve_rms(c, lin, c->best_cost), lin);
            break;
        }
        c->best_cost = cost;
        *lin = *x; /* the next pass linearises here; w->best is the estimate */
        if (cfg->on_iter)
            cfg->on_iter(cfg->cb_ctx, pass + 1, curve_rms(c, lin, c->best_cost), lin);
        if (prev - cost < tol * prev)
            break;
        prev = cost;
    }
    return RC_OK;
}

/* ---- M6 SSLM ----------------------------------------------------------- */

/* Variable step-size LM (our reading of the paper's ref. 19; rc_est.h):
 * the damping mu stays fixed, the step size eta along the LM direction
 * varies: first tried min(1, 2 eta_prev), halved until the cost falls. */
static rc_status run_sslm(est_ctx *c, rc_model *m)
{
    rc_est_work *w = c->w;
    const rc_est_config *cfg = c->cfg;
    const unsigned T = cfg->max_iter ? cfg->max_iter : 100u;
    const unsigned nf = c->nf;
    const double tol = cfg->tol_cost > 0.0 ? cfg->tol_cost : 1e-10;
    const double mu = cfg->sslm_mu > 0.0 ? cfg->sslm_mu : 1e-2;
    double eta = 1.0, cost;
    rc_model *x = &w->best;
    *x = *m;
    for (unsigned it = 0; it < T; ++it) {
        rc_status st = rc_normal_eq(w->P, w->g, &cost, w->jrow, x, w->idx, nf, c->s, c->n);
        ++c->res->cost_evals;
        if (st != RC_OK)
            return st;
        if (c->prior)
            rc_prior_normal_eq(w->P, w->g, &cost, x, w->idx, nf, &c->pc);
        if (it == 0) /* the scaling of the start, kept (scaled variables u = D x) */
            for (unsigned i = 0; i < nf; ++i) {
                const double a = w->P[(size_t)i * nf + i];
                w->D[i] = a > 0.0 ? sqrt(a) : 1.0;
            }
        for (unsigned i = 0; i < nf; ++i) {
            w->dx[i] = -w->g[i] / w->D[i];
            for (unsigned k = 0; k < nf; ++k)
                w->T[(size_t)i * nf + k] = w->P[(size_t)i * nf + k] / (w->D[i] * w->D[k]);
            w->T[(size_t)i * nf + i] += mu;
        }
        if (rcu_chol_solve(w->T, w->dx, nf) != RC_OK)
            return RC_ERR_NUMERIC;
        int accepted = 0;
        double newcost = cost, a = 2.0 * eta < 1.0 ? 2.0 * eta : 1.0;
        for (unsigned h = 0; h <= 40; ++h, a *= 0.5) {
            double ct;
            w->trial = *x;
            for (unsigned i = 0; i < nf; ++i)
                w->trial.x[w->idx[i]] += a * w->dx[i] / w->D[i];
            ++c->res->cost_evals;
            if (objective(&ct, c, &w->trial) == RC_OK && ct < cost) {
                accepted = 1;
                newcost = ct;
                break;
            }
        }
        if (!accepted)
            break; /* no step size lowers the cost: converged */
        *x = w->trial;
        eta = a;
        c->best_cost = newcost;
        c->res->iterations = it + 1;
        if (cfg->on_iter)
            cfg->on_iter(cfg->cb_ctx, it + 1, curve_rms(c, x, c->best_cost), x);
        if (cost - newcost < tol * cost)
            break;
    }
    return RC_OK;
}

/* ---- dispatcher -------------------------------------------------------- */

static double bound_of(const rc_model *m, unsigned k, const rc_est_config *cfg)
{
    const double blen = cfg->bound_len_mm > 0.0 ? cfg->bound_len_mm : 2.0;
    const double bang = cfg->bound_ang_rad > 0.0 ? cfg->bound_ang_rad : 0.2 * M_PI / 180.0;
    const double benc = cfg->bound_enc_mm > 0.0 ? cfg->bound_enc_mm : 5.0;
    const double both = cfg->bound_other > 0.0 ? cfg->bound_other : 1e-3;
    if (k >= RC_P_ENC && k < RC_N_BASE)
        return benc;
    switch (rc_param_unit(m, k)) {
    case 0: return blen;
    case 1: return bang;
    default: return both;
    }
}

rc_status rc_est_solve(rc_model *m, rc_est_result *res, rc_est_work *w, const rc_est_config *cfg,
                       const rc_sample *samples, size_t n)
{
    static const rc_est_config defaults;
    rc_est_result local;
    est_ctx c;
    rc_rng g;
    rc_status st;
    RC_ASSERT(m != NULL && w != NULL);
    if (cfg == NULL)
        cfg = &defaults;
    if (res == NULL)
        res = &local;
    memset(res, 0, sizeof *res);
    if (samples == NULL || n == 0 || m->n_params > RC_MAX_PARAMS || m->n_params < RC_N_BASE)
        return RC_ERR_ARG;
    if (cfg->pop > RC_EST_MAX_POP || (cfg->pop > 0 && cfg->pop < 4))
        return RC_ERR_ARG;
    if ((unsigned)cfg->method > (unsigned)RC_EST_SSLM)
        return RC_ERR_ARG;

    unsigned nf = 0;
    for (unsigned k = 0; k < m->n_params; ++k)
        if (cfg->fixed == NULL || cfg->fixed[k] == 0)
            ++nf;
    res->n_free = nf;
    if (nf == 0)
        return RC_ERR_RANK;
    memset(&c.pc, 0, sizeof c.pc);
    c.prior = cfg->prior_mean != NULL && cfg->prior_sd != NULL && cfg->prior_noise_mm > 0.0;
    if (c.prior) {
        c.pc.prior_mean = cfg->prior_mean;
        c.pc.prior_sd = cfg->prior_sd;
        c.pc.prior_noise_mm = cfg->prior_noise_mm;
        c.pc.fixed = cfg->fixed;
    }
    if (!cfg->keep_all && !c.prior) { /* with a prior every direction is determined: all move */
        uint8_t sub[RC_MAX_PARAMS];
        unsigned kept;
        st = rc_est_subset(sub, &kept, w, m, cfg->fixed, cfg->subset_tol, samples, n);
        if (st != RC_OK)
            return st;
        nf = 0;
        for (unsigned k = 0; k < m->n_params; ++k)
            if (!sub[k])
                w->idx[nf++] = (uint16_t)k;
    } else {
        nf = 0;
        for (unsigned k = 0; k < m->n_params; ++k)
            if (cfg->fixed == NULL || cfg->fixed[k] == 0)
                w->idx[nf++] = (uint16_t)k;
    }
    res->n_moved = nf;
    for (unsigned j = 0; j < nf; ++j) {
        w->x0[j] = m->x[w->idx[j]];
        w->bound[j] = bound_of(m, w->idx[j], cfg);
        if (c.prior && cfg->prior_sd[w->idx[j]] > 0.0 && isfinite(cfg->prior_sd[w->idx[j]]))
            w->bound[j] = 3.0 * cfg->prior_sd[w->idx[j]]; /* the box: the prior's 3 sd */
        w->ubest[j] = 0.0;
    }

    c.w = w;
    c.cfg = cfg;
    c.start = m;
    c.s = samples;
    c.n = n;
    c.nf = nf;
    c.res = res;
    c.sin_q = c.cos_q = NULL;
    if ((size_t)nf * nf + 2u * RC_NJ * n <= (size_t)RC_MAX_PARAMS * RC_MAX_PARAMS) {
        /* every method evaluates the objective on the same readings: their trigonometry once, in the tail of
         * w->T past the nf x nf the methods use */
        double *sq = &w->T[(size_t)nf * nf], *cq = sq + (size_t)RC_NJ * n;
        rc_qtrig_fill(sq, cq, samples, n);
        c.sin_q = sq;
        c.cos_q = cq;
    }
    ++res->cost_evals;
    st = objective(&c.best_cost, &c, m);
    if (st != RC_OK)
        return st;
    {
        double data_cost;
        st = rc_cost(&data_cost, m, samples, n);
        if (st != RC_OK)
            return st;
        res->rms_start_mm = rms_of(data_cost, n);
    }
    rc_rng_seed(&g, cfg->seed ^ ((uint64_t)cfg->method + 1u) * 0x9E3779B97F4A7C15ull);

    switch (cfg->method) {
    case RC_EST_EKF:
        w->best = *m;
        st = c.prior ? run_iekf(&c, m) : run_ekf(&c, m);
        if (st == RC_OK)
            *m = w->best;
        break;
    case RC_EST_SSLM:
        st = run_sslm(&c, m);
        if (st == RC_OK)
            *m = w->best;
        break;
    case RC_EST_PF:
    case RC_EST_SCA:
    case RC_EST_QIBAS:
        if (cfg->method == RC_EST_PF)
            run_pf(&c, &g);
        else if (cfg->method == RC_EST_SCA)
            run_sca(&c, &g);
        else
            run_qibas(&c, &g);
        model_at(&w->best, &c, w->ubest);
        *m = w->best;
        st = RC_OK;
        break;
    default: /* not a method (RC_EST_COUNT_ and beyond) */
        st = RC_ERR_ARG;
        break;
    }
    if (st != RC_OK)
        return st;
    double cost;
    ++res->cost_evals;
    st = rc_cost(&cost, m, samples, n);
    if (st != RC_OK)
        return st;
    res->rms_final_mm = rms_of(cost, n);
    return RC_OK;
}
