/* SPDX-License-Identifier: MIT */
/* Dense linear algebra of the core: QL eigen-solver against Jacobi and
 * against the definition, Cholesky solve. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <string.h>

#include "rc_linalg.h"
#include "rc_rand.h"

enum { N = 30 };

static void random_sym(double *A, unsigned n, rc_rng *g, unsigned rank)
{
    /* A = B B^T with B (n x rank): positive semi-definite with n - rank zeros */
    double B[N * N];
    for (unsigned i = 0; i < n * rank; ++i)
        B[i] = rc_rng_normal(g);
    for (unsigned i = 0; i < n; ++i)
        for (unsigned j = 0; j < n; ++j) {
            double s = 0.0;
            for (unsigned k = 0; k < rank; ++k)
                s += B[i * rank + k] * B[j * rank + k];
            A[i * n + j] = s;
        }
}

static void test_eig_matches_definition_and_jacobi(void **state)
{
    (void)state;
    rc_rng g;
    rc_rng_seed(&g, 42);
    for (unsigned n = 1; n <= N; n += 7) {
        for (unsigned rank = 1; rank <= n; rank += 5) {
            double A[N * N], A0[N * N], A1[N * N], V[N * N], V1[N * N], ev[N], ev1[N];
            random_sym(A0, n, &g, rank);
            memcpy(A, A0, sizeof(double) * n * n);
            memcpy(A1, A0, sizeof(double) * n * n);
            assert_int_equal(rcu_eig_sym(ev, V, A, n, 0), RC_OK);
            assert_int_equal(rcu_eig_sym_jacobi(ev1, V1, A1, n, 0), RC_OK);
            const double scale = fabs(ev[0]) + 1.0;
            for (unsigned k = 0; k < n; ++k) {
                assert_true(fabs(ev[k] - ev1[k]) < 1e-10 * scale);
                if (k > 0)
                    assert_true(ev[k] <= ev[k - 1]);
                if (k >= rank)
                    assert_true(fabs(ev[k]) < 1e-10 * scale); /* the null space is found */
                /* A v = lambda v, |v| = 1 */
                double nrm = 0.0;
                for (unsigned i = 0; i < n; ++i) {
                    double s = 0.0;
                    for (unsigned j = 0; j < n; ++j)
                        s += A0[i * n + j] * V[j * n + k];
                    assert_true(fabs(s - ev[k] * V[i * n + k]) < 1e-9 * scale);
                    nrm += V[i * n + k] * V[i * n + k];
                }
                assert_true(fabs(nrm - 1.0) < 1e-12);
            }
        }
    }
}

static void test_eig_nonfinite(void **state)
{
    (void)state;
    double A[4] = {1, NAN, NAN, 1}, V[4], ev[2];
    assert_int_equal(rcu_eig_sym(ev, V, A, 2, 0), RC_ERR_NUMERIC);
}

static void test_cholesky(void **state)
{
    (void)state;
    double A[9] = {4, 2, 0, 2, 5, 1, 0, 1, 3}, x[3] = {1, 2, 3}, b[3];
    const double A0[9] = {4, 2, 0, 2, 5, 1, 0, 1, 3};
    for (int i = 0; i < 3; ++i)
        b[i] = A0[3 * i] * x[0] + A0[3 * i + 1] * x[1] + A0[3 * i + 2] * x[2];
    assert_int_equal(rcu_chol_solve(A, b, 3), RC_OK);
    for (int i = 0; i < 3; ++i)
        assert_true(fabs(b[i] - x[i]) < 1e-12);
    double S[4] = {1, 2, 2, 1}, c[2] = {1, 1}; /* indefinite */
    assert_int_equal(rcu_chol_solve(S, c, 2), RC_ERR_NUMERIC);
}

/* rcu_sym3_eig_max: the closed form against the QL solver on random
 * symmetric 3 x 3 matrices (definite, semi-definite, indefinite, with
 * repeated eigenvalues), diagonal ones, and NaN. */
static void test_sym3_eig_max(void **state)
{
    (void)state;
    rc_rng g;
    rc_rng_seed(&g, 9);
    for (int trial = 0; trial < 2000; ++trial) {
        double A[9], A1[9], V[9], ev[3];
        const unsigned kind = (unsigned)trial % 4;
        if (kind == 0) {
            random_sym(A, 3, &g, 1 + (unsigned)trial % 3); /* B B^T, rank 1..3 */
        } else {
            for (int i = 0; i < 3; ++i)
                for (int j = i; j < 3; ++j)
                    A[3 * i + j] = A[3 * j + i] = kind == 3 && i != j ? 0.0 : rc_rng_normal(&g);
        }
        if (kind == 2) { /* a repeated eigenvalue: Q diag(a, a, b) Q^T from an eigenbasis */
            memcpy(A1, A, sizeof A1);
            assert_int_equal(rcu_eig_sym(ev, V, A1, 3, 0), RC_OK);
            const double lam[3] = {1.5, 1.5, -0.5};
            for (int i = 0; i < 3; ++i)
                for (int j = 0; j < 3; ++j) {
                    double sum = 0.0;
                    for (int k = 0; k < 3; ++k)
                        sum += V[3 * i + k] * lam[k] * V[3 * j + k];
                    A[3 * i + j] = sum;
                }
        }
        memcpy(A1, A, sizeof A1);
        assert_int_equal(rcu_eig_sym(ev, V, A1, 3, 0), RC_OK);
        const double scale = fabs(ev[0]) > fabs(ev[2]) ? fabs(ev[0]) : fabs(ev[2]);
        /* a double largest eigenvalue costs half the digits (acos near -1) */
        const double tol = kind == 2 ? 1e-7 : 1e-12;
        if (!(fabs(rcu_sym3_eig_max(A) - ev[0]) <= tol * (scale + 1e-300)))
            print_error("trial %d kind %u: %.17g vs %.17g\n", trial, kind, rcu_sym3_eig_max(A), ev[0]);
        assert_true(fabs(rcu_sym3_eig_max(A) - ev[0]) <= tol * (scale + 1e-300));
    }
    const double Z[9] = {0};
    assert_true(rcu_sym3_eig_max(Z) == 0.0);
    const double Q[9] = {1, NAN, 0, NAN, 1, 0, 0, 0, 1};
    assert_true(isnan(rcu_sym3_eig_max(Q)));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_eig_matches_definition_and_jacobi),
        cmocka_unit_test(test_eig_nonfinite),
        cmocka_unit_test(test_cholesky),
        cmocka_unit_test(test_sym3_eig_max),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
