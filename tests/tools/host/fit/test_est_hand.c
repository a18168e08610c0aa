/* SPDX-License-Identifier: MIT */
/* test_est_hand.c - EKF, PF and SCA (rc_est) against implementations
 * written here from their descriptions in rc_est.h, on a small problem:
 * three free parameters (a2 mm, theta2 rad, encoder z mm) of a simulated
 * IRB120, 40 lengths with 0.02 mm noise, the start off the truth inside the
 * methods' box. The hand versions draw from the same generator (rc_rng,
 * seeded as rc_est_solve seeds it) in the order the descriptions imply, so
 * the library's returned model must agree to 1e-9. Each one kills a
 * departure: the EKF's adaptive measurement noise removed (R fixed), SCA's
 * cosine branch dropped, PF's resampling removed (docs/methods.md). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "rc_est.h"
#include "rc_rand.h"
#include "rc_solve.h"
#include "rch_robot.h"

#define PI 3.14159265358979323846
enum { NS = 40, NP = 3 };

static rc_model g_start;
static rc_sample g_s[NS];
static const unsigned g_idx[NP] = {RC_P_A(1), RC_P_THETA(1), RC_P_ENC + 2};
static uint8_t g_fixed[RC_MAX_PARAMS];
static double g_bound[NP]; /* rc_est's default box: 2 mm, 0.2 deg, encoder 5 mm */
static rc_est_work W;

static int setup(void **state)
{
    rch_robot robot;
    rch_diag d;
    rc_rng g;
    const double enc[3] = {250.0, -460.0, 10.0};
    (void)state;
    if (rch_robot_load(&robot, RCAL_SOURCE_DIR "/data/irb120.json", &d) != 0)
        return -1;
    rc_model truth = robot.model;
    memcpy(&truth.x[RC_P_ENC], enc, sizeof enc);
    g_start = truth;
    g_start.x[RC_P_A(1)] -= 1.2;
    g_start.x[RC_P_THETA(1)] += 0.12 * PI / 180.0;
    g_start.x[RC_P_ENC + 2] -= 3.0;
    rc_rng_seed(&g, 21);
    for (unsigned i = 0; i < NS; ++i) {
        memset(&g_s[i], 0, sizeof g_s[i]);
        for (unsigned j = 0; j < RC_NJ; ++j)
            g_s[i].q_rad[j] = (rc_rng_u01(&g) - 0.5) * (j == 1 || j == 2 ? 1.6 : 3.0);
        if (rc_meas(&g_s[i].value, NULL, &truth, &g_s[i]) != RC_OK)
            return -1;
        g_s[i].value += 0.02 * rc_rng_normal(&g);
    }
    memset(g_fixed, 1, sizeof g_fixed);
    for (unsigned i = 0; i < NP; ++i)
        g_fixed[g_idx[i]] = 0;
    g_bound[0] = 2.0;
    g_bound[1] = 0.2 * PI / 180.0;
    g_bound[2] = 5.0;
    return 0;
}

static void seed_as_rc_est(rc_rng *g, uint64_t seed, rc_est_method mt)
{
    rc_rng_seed(g, seed ^ ((uint64_t)mt + 1u) * 0x9E3779B97F4A7C15ull);
}

/* the model at normalised u (x = x0 + bound u) and its cost */
static void at_u(rc_model *m, const double u[NP])
{
    *m = g_start;
    for (unsigned j = 0; j < NP; ++j)
        m->x[g_idx[j]] = g_start.x[g_idx[j]] + g_bound[j] * u[j];
}

static double cost_u(const double u[NP])
{
    rc_model m;
    double c;
    at_u(&m, u);
    if (rc_cost(&c, &m, g_s, NS) != RC_OK || !isfinite(c))
        return HUGE_VAL;
    return c;
}

static double clamp1(double v) { return v < -1.0 ? -1.0 : (v > 1.0 ? 1.0 : v); }

static double reflect1(double v)
{
    if (v > 1.0)
        v = 2.0 - v;
    if (v < -1.0)
        v = -2.0 - v;
    return clamp1(v);
}

static rc_model run_lib(rc_est_method mt, unsigned pop, unsigned iters, uint64_t seed)
{
    rc_est_config cfg;
    rc_est_result res;
    rc_model m = g_start;
    memset(&cfg, 0, sizeof cfg);
    cfg.method = mt;
    cfg.pop = pop;
    cfg.max_iter = iters;
    cfg.seed = seed;
    cfg.fixed = g_fixed;
    cfg.keep_all = 1;
    assert_int_equal(rc_est_solve(&m, &res, &W, &cfg, g_s, NS), RC_OK);
    return m;
}

static void same_model(const rc_model *lib, const rc_model *hand, const char *what)
{
    for (unsigned j = 0; j < NP; ++j) {
        const double a = lib->x[g_idx[j]], b = hand->x[g_idx[j]];
        if (fabs(a - b) > 1e-9 * (1.0 + fabs(b)))
            fail_msg("%s parameter %u: library %.15g, hand %.15g", what, j, a, b);
    }
}

/* ---- SCA (Mirjalili 2016), rc_est.h's description ---- */
static void test_sca_hand(void **state)
{
    enum { N = 6, T = 12 };
    double X[N][NP], ub[NP] = {0, 0, 0}, best = cost_u(ub);
    unsigned cos_used = 0;
    rc_rng g;
    (void)state;
    seed_as_rc_est(&g, 7, RC_EST_SCA);
    for (unsigned i = 0; i < N; ++i) {
        for (unsigned j = 0; j < NP; ++j)
            X[i][j] = i == 0 ? 0.0 : 2.0 * rc_rng_u01(&g) - 1.0;
        const double c = cost_u(X[i]);
        if (c < best) {
            best = c;
            memcpy(ub, X[i], sizeof ub);
        }
    }
    for (unsigned t = 0; t < T; ++t) {
        const double r1 = 2.0 - (double)t * 2.0 / (double)T;
        for (unsigned i = 0; i < N; ++i)
            for (unsigned j = 0; j < NP; ++j) {
                const double r2 = 2.0 * PI * rc_rng_u01(&g), r3 = 2.0 * rc_rng_u01(&g), r4 = rc_rng_u01(&g);
                const double dist = fabs(r3 * ub[j] - X[i][j]);
                if (r4 < 0.5) {
                    X[i][j] += r1 * sin(r2) * dist;
                } else {
                    X[i][j] += r1 * cos(r2) * dist;
                    ++cos_used;
                }
                X[i][j] = clamp1(X[i][j]);
            }
        for (unsigned i = 0; i < N; ++i) { /* evaluated after the whole population moved */
            const double c = cost_u(X[i]);
            if (c < best) {
                best = c;
                memcpy(ub, X[i], sizeof ub);
            }
        }
    }
    rc_model hand, lib = run_lib(RC_EST_SCA, N, T, 7);
    at_u(&hand, ub);
    assert_true(cos_used > 0);
    assert_true(best < cost_u((const double[NP]){0, 0, 0}));
    same_model(&lib, &hand, "SCA");
}

/* ---- PF: regularised particle filter, rc_est.h's description ---- */
static double pf_weights(double *wgt, const double *lam, unsigned n, double phi)
{
    double sum = 0.0, sq = 0.0;
    for (unsigned i = 0; i < n; ++i) {
        wgt[i] = isfinite(lam[i]) ? exp(phi * lam[i]) : 0.0;
        sum += wgt[i];
    }
    if (!(sum > 0.0))
        return 0.0;
    for (unsigned i = 0; i < n; ++i) {
        wgt[i] /= sum;
        sq += wgt[i] * wgt[i];
    }
    return 1.0 / sq;
}

static void test_pf_hand(void **state)
{
    enum { N = 10, T = 8 };
    double P[N][NP], P2[N][NP], fit[N], lam[N], wgt[N], mean[NP], sd[NP], ub[NP] = {0, 0, 0};
    double best = cost_u(ub);
    const double h = pow(4.0 / ((double)(NP + 2) * (double)N), 1.0 / (double)(NP + 4));
    const double shrink = sqrt(1.0 - h * h);
    unsigned dup = 0;
    rc_rng g;
    (void)state;
    seed_as_rc_est(&g, 9, RC_EST_PF);
#define OFFER(u, c)                                                                                                    \
    do {                                                                                                               \
        const double c_ = (c);                                                                                         \
        if (c_ < best) {                                                                                               \
            best = c_;                                                                                                 \
            memcpy(ub, (u), sizeof ub);                                                                                \
        }                                                                                                              \
    } while (0)
    for (unsigned i = 0; i < N; ++i) {
        for (unsigned j = 0; j < NP; ++j)
            P[i][j] = i == 0 ? 0.0 : clamp1(rc_rng_normal(&g) / 3.0);
        fit[i] = cost_u(P[i]);
        OFFER(P[i], fit[i]);
    }
    for (unsigned t = 0; t < T; ++t) {
        double cmin = HUGE_VAL;
        for (unsigned i = 0; i < N; ++i)
            cmin = fit[i] < cmin ? fit[i] : cmin;
        const double R = cmin / (double)NS > 1e-30 ? cmin / (double)NS : 1e-30;
        for (unsigned i = 0; i < N; ++i)
            lam[i] = -(fit[i] - cmin) / (2.0 * R);
        if (pf_weights(wgt, lam, N, 1.0) < 0.5 * (double)N) { /* tempered: ESS >= N/2 */
            double lo = 0.0, hi = 1.0;
            for (int k = 0; k < 50; ++k) {
                const double mid = 0.5 * (lo + hi);
                if (pf_weights(wgt, lam, N, mid) >= 0.5 * (double)N)
                    lo = mid;
                else
                    hi = mid;
            }
            (void)pf_weights(wgt, lam, N, lo);
        }
        for (unsigned j = 0; j < NP; ++j) {
            double mu = 0.0, var = 0.0;
            for (unsigned i = 0; i < N; ++i)
                mu += wgt[i] * P[i][j];
            for (unsigned i = 0; i < N; ++i)
                var += wgt[i] * (P[i][j] - mu) * (P[i][j] - mu);
            mean[j] = mu;
            sd[j] = sqrt(var) > 1e-7 ? sqrt(var) : 1e-7;
        }
        OFFER(mean, cost_u(mean));
        { /* systematic resampling */
            const double u0 = rc_rng_u01(&g) / (double)N;
            double cum = wgt[0];
            unsigned i = 0;
            for (unsigned k = 0; k < N; ++k) {
                const double uk = u0 + (double)k / (double)N;
                while (uk > cum && i + 1 < N)
                    cum += wgt[++i];
                memcpy(P2[k], P[i], sizeof P2[k]);
                dup += k > 0 && memcmp(P2[k], P2[k - 1], sizeof P2[k]) == 0;
            }
        }
        for (unsigned k = 0; k < N; ++k) { /* Liu-West kernel jitter */
            for (unsigned j = 0; j < NP; ++j)
                P[k][j] = reflect1(shrink * P2[k][j] + (1.0 - shrink) * mean[j] + h * sd[j] * rc_rng_normal(&g));
            fit[k] = cost_u(P[k]);
            OFFER(P[k], fit[k]);
        }
    }
#undef OFFER
    rc_model hand, lib = run_lib(RC_EST_PF, N, T, 9);
    at_u(&hand, ub);
    assert_true(dup > 0); /* resampling duplicated particles: the problem exercises it */
    same_model(&lib, &hand, "PF");
}

/* ---- EKF with the residual-based adaptive R, rc_est.h's description ---- */
static void test_ekf_hand(void **state)
{
    enum { T = 3 };
    const double q = 1e-9, alpha = 0.3, sig = 0.004 / sqrt(12.0);
    double x[NP], P[NP][NP], c0, R, R_first_pass_end = 0.0;
    rc_model m = g_start;
    (void)state;
    assert_int_equal(rc_cost(&c0, &g_start, g_s, NS), RC_OK);
    R = c0 / (double)NS; /* the start's mean squared residual */
    if (!(R >= sig * sig))
        R = sig * sig;
    for (unsigned j = 0; j < NP; ++j)
        x[j] = g_start.x[g_idx[j]];
    for (unsigned pass = 0; pass < T; ++pass) {
        memset(P, 0, sizeof P);
        for (unsigned j = 0; j < NP; ++j)
            P[j][j] = g_bound[j] * g_bound[j];
        for (unsigned s = 0; s < NS; ++s) {
            double l, jrow[RC_MAX_PARAMS], hv[NP], Ph[NP], K[NP], hph = 0.0;
            for (unsigned j = 0; j < NP; ++j)
                m.x[g_idx[j]] = x[j];
            assert_int_equal(rc_meas(&l, jrow, &m, &g_s[s]), RC_OK);
            const double innov = g_s[s].value - l;
            for (unsigned j = 0; j < NP; ++j) {
                hv[j] = jrow[g_idx[j]];
                P[j][j] += q * g_bound[j] * g_bound[j];
            }
            for (unsigned i = 0; i < NP; ++i) {
                Ph[i] = 0.0;
                for (unsigned k = 0; k < NP; ++k)
                    Ph[i] += P[i][k] * hv[k];
                hph += hv[i] * Ph[i];
            }
            const double S = hph + R;
            for (unsigned i = 0; i < NP; ++i) {
                K[i] = Ph[i] / S;
                x[i] += K[i] * innov;
            }
            /* Joseph form (I - K h^T) P (I - K h^T)^T + R K K^T */
            double M[NP][NP], Mh[NP], Pn[NP][NP];
            for (unsigned i = 0; i < NP; ++i)
                for (unsigned k = 0; k < NP; ++k)
                    M[i][k] = P[i][k] - K[i] * Ph[k];
            for (unsigned i = 0; i < NP; ++i) {
                Mh[i] = 0.0;
                for (unsigned k = 0; k < NP; ++k)
                    Mh[i] += M[i][k] * hv[k];
            }
            for (unsigned i = 0; i < NP; ++i)
                for (unsigned k = 0; k < NP; ++k)
                    Pn[i][k] = M[i][k] - Mh[i] * K[k] + R * K[i] * K[k];
            for (unsigned i = 0; i < NP; ++i)
                for (unsigned k = 0; k < NP; ++k)
                    P[i][k] = 0.5 * (Pn[i][k] + Pn[k][i]);
            /* adaptive R from the post-update residual (Akhlaghi et al. 2017) */
            const double eps = innov * R / S;
            R = alpha * R + (1.0 - alpha) * (eps * eps + hph * R / S);
        }
        if (pass == 0)
            R_first_pass_end = R;
    }
    for (unsigned j = 0; j < NP; ++j)
        m.x[g_idx[j]] = x[j];
    rc_model lib = run_lib(RC_EST_EKF, 0, T, 3);
    /* the adaptation moved R far from its start: the problem exercises it */
    assert_true(fabs(R_first_pass_end - c0 / (double)NS) > 0.2 * (c0 / (double)NS));
    same_model(&lib, &m, "EKF");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_sca_hand),
        cmocka_unit_test(test_pf_hand),
        cmocka_unit_test(test_ekf_hand),
    };
    return cmocka_run_group_tests(tests, setup, NULL);
}
