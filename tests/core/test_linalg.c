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

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_eig_matches_definition_and_jacobi),
        cmocka_unit_test(test_eig_nonfinite),
        cmocka_unit_test(test_cholesky),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
