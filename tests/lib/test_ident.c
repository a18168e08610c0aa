/* SPDX-License-Identifier: MIT */
/* rc_ident: the one definition of what the data can identify. Problems with a
 * known rank deficiency (two columns that differ only by a unit), a known weak
 * direction (two columns 1e-4 apart), a zero column, and a full-rank problem
 * whose D-optimality figure is checked against a Cholesky determinant. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <string.h>

#include "rc_ident.h"
#include "rc_linalg.h"
#include "rc_rand.h"

enum { M = 200, NP = 5 };

/* AtA (n x n) = J^T J of J (m x n) */
static void normal_of(double *AtA, const double *J, unsigned m, unsigned n)
{
    for (unsigned i = 0; i < n; ++i)
        for (unsigned k = 0; k < n; ++k) {
            double s = 0.0;
            for (unsigned r = 0; r < m; ++r)
                s += J[r * n + i] * J[r * n + k];
            AtA[i * n + k] = s;
        }
}

/* Columns: 0 random; 1 random; 2 = 1000 * column 0 (same direction in other
 * units: one null direction mixing 0 and 2); 3 = column 1 + 1e-4 * noise (one
 * weak direction mixing 1 and 3); 4 random (identifiable on its own). */
static void deficient(double *J, rc_rng *g)
{
    for (unsigned r = 0; r < M; ++r) {
        double *row = &J[r * NP];
        row[0] = rc_rng_normal(g);
        row[1] = rc_rng_normal(g);
        row[2] = 1000.0 * row[0];
        row[3] = row[1] + 1e-4 * rc_rng_normal(g);
        row[4] = rc_rng_normal(g);
    }
}

static void test_known_null_and_weak(void **state)
{
    (void)state;
    static double J[M * NP];
    double AtA[NP * NP], V[NP * NP], work[NP * NP + NP];
    rc_rng g;
    rc_rng_seed(&g, 7);
    deficient(J, &g);
    normal_of(AtA, J, M, NP);
    assert_true(rc_ident_work_size(NP) <= sizeof work / sizeof work[0]);
    rc_ident id;
    assert_int_equal(rc_ident_normal(&id, V, work, AtA, NP, M), RC_OK);
    assert_int_equal(id.n, NP);
    assert_int_equal(id.rank, NP - 1);
    assert_int_equal(id.n_null, 1);
    assert_int_equal(id.n_weak, 1);
    /* descending, first is 1 */
    assert_true(fabs(id.sv_rel[0] - 1.0) < 1e-15);
    for (unsigned k = 1; k < NP; ++k)
        assert_true(id.sv_rel[k] <= id.sv_rel[k - 1]);
    /* the weak one: columns 1 and 3 after scaling differ by about 1e-4 */
    assert_int_equal(id.dir_class[NP - 2], RC_IDENT_WEAK);
    assert_true(id.sv_rel[NP - 2] > 1e-5 && id.sv_rel[NP - 2] < 1e-3);
    assert_int_equal(id.dir_class[NP - 1], RC_IDENT_NONE);
    assert_true(id.sv_rel[NP - 1] < RC_IDENT_NULL_REL);
    /* the null direction is (e0 - e2)/sqrt(2) in scaled coordinates */
    const double *vn = &V[NP - 1];
    assert_true(fabs(fabs(vn[0 * NP]) - sqrt(0.5)) < 1e-6);
    assert_true(fabs(fabs(vn[2 * NP]) - sqrt(0.5)) < 1e-6);
    assert_true(vn[0 * NP] * vn[2 * NP] < 0.0);
    assert_true(fabs(vn[1 * NP]) < 1e-6 && fabs(vn[3 * NP]) < 1e-6 && fabs(vn[4 * NP]) < 1e-6);
    /* the weak direction is (e1 - e3)/sqrt(2) */
    const double *vw = &V[NP - 2];
    assert_true(fabs(fabs(vw[1 * NP]) - sqrt(0.5)) < 1e-3);
    assert_true(vw[1 * NP] * vw[3 * NP] < 0.0);
    /* per parameter */
    assert_int_equal(id.param_class[0], RC_IDENT_NONE);
    assert_int_equal(id.param_class[2], RC_IDENT_NONE);
    assert_int_equal(id.param_class[1], RC_IDENT_WEAK);
    assert_int_equal(id.param_class[3], RC_IDENT_WEAK);
    assert_int_equal(id.param_class[4], RC_IDENT_IDENTIFIABLE);
    assert_string_equal(rc_ident_class_str((rc_ident_class)id.param_class[0]), "not identifiable");
    assert_string_equal(rc_ident_class_str((rc_ident_class)id.param_class[1]), "weak");
    assert_string_equal(rc_ident_class_str((rc_ident_class)id.param_class[4]), "identifiable");
    assert_true(id.cond > 1e3 && id.cond < 1e6);
    assert_true(id.observability > 0.0);
}

/* A full-rank problem: log_det is log det of the scaled normal matrix (from a
 * Cholesky factor), O1 the geometric mean of the singular values / sqrt(m),
 * and the result does not depend on the units of a column. */
static void test_full_rank_figures(void **state)
{
    (void)state;
    static double J[M * NP];
    double AtA[NP * NP], S[NP * NP], b[NP] = {0}, V[NP * NP], work[NP * NP + NP];
    rc_rng g;
    rc_rng_seed(&g, 11);
    for (unsigned i = 0; i < M * NP; ++i)
        J[i] = rc_rng_normal(&g);
    normal_of(AtA, J, M, NP);
    rc_ident id;
    assert_int_equal(rc_ident_normal(&id, V, work, AtA, NP, M), RC_OK);
    assert_int_equal(id.rank, NP);
    assert_int_equal(id.n_weak, 0);
    for (unsigned i = 0; i < NP; ++i)
        assert_int_equal(id.param_class[i], RC_IDENT_IDENTIFIABLE);
    for (unsigned i = 0; i < NP; ++i)
        for (unsigned k = 0; k < NP; ++k)
            S[i * NP + k] = AtA[i * NP + k] / sqrt(AtA[i * NP + i] * AtA[k * NP + k]);
    assert_int_equal(rcu_chol_solve(S, b, NP), RC_OK);
    double ld = 0.0;
    for (unsigned i = 0; i < NP; ++i)
        ld += 2.0 * log(S[i * NP + i]);
    assert_true(fabs(id.log_det - ld) < 1e-10);
    assert_true(fabs(id.observability - exp(ld / (2.0 * NP)) / sqrt((double)M)) < 1e-12);
    /* column 3 in other units: nothing changes */
    rc_ident id2;
    for (unsigned r = 0; r < M; ++r)
        J[r * NP + 3] *= 1e4;
    normal_of(AtA, J, M, NP);
    assert_int_equal(rc_ident_normal(&id2, V, work, AtA, NP, M), RC_OK);
    assert_true(fabs(id2.log_det - id.log_det) < 1e-9);
    for (unsigned k = 0; k < NP; ++k)
        assert_true(fabs(id2.sv_rel[k] - id.sv_rel[k]) < 1e-12);
}

/* A column at rounding level (as alpha6) counts as exactly zero: null, and
 * the others are untouched. */
static void test_zero_column(void **state)
{
    (void)state;
    static double J[M * NP];
    double AtA[NP * NP], V[NP * NP], work[NP * NP + NP];
    rc_rng g;
    rc_rng_seed(&g, 3);
    for (unsigned r = 0; r < M; ++r)
        for (unsigned i = 0; i < NP; ++i)
            J[r * NP + i] = i == 2 ? 1e-14 * rc_rng_normal(&g) : rc_rng_normal(&g);
    normal_of(AtA, J, M, NP);
    rc_ident id;
    assert_int_equal(rc_ident_normal(&id, V, work, AtA, NP, M), RC_OK);
    assert_int_equal(id.rank, NP - 1);
    assert_int_equal(id.n_null, 1);
    assert_true(id.sv_rel[NP - 1] == 0.0);
    assert_true(fabs(fabs(V[2 * NP + NP - 1]) - 1.0) < 1e-12);
    assert_int_equal(id.param_class[2], RC_IDENT_NONE);
    for (unsigned i = 0; i < NP; ++i)
        if (i != 2)
            assert_int_equal(id.param_class[i], RC_IDENT_IDENTIFIABLE);
}

/* rc_ident_classify applies the documented thresholds to given values. */
static void test_classify_thresholds(void **state)
{
    (void)state;
    enum { N = 4 };
    const double sv[N] = {2.0, 2.0 * 1.0001e-3, 2.0 * 0.9999e-3, 2.0 * 0.9999e-6};
    double V[N * N] = {0};
    for (unsigned i = 0; i < N; ++i)
        V[i * N + i] = 1.0;
    rc_ident id;
    assert_int_equal(rc_ident_classify(&id, sv, V, N, 100), RC_OK);
    assert_int_equal(id.dir_class[0], RC_IDENT_IDENTIFIABLE);
    assert_int_equal(id.dir_class[1], RC_IDENT_IDENTIFIABLE);
    assert_int_equal(id.dir_class[2], RC_IDENT_WEAK);
    assert_int_equal(id.dir_class[3], RC_IDENT_NONE);
    assert_int_equal(id.rank, 3);
    assert_int_equal(id.n_weak, 1);
    assert_int_equal(id.param_class[2], RC_IDENT_WEAK);
    assert_int_equal(id.param_class[3], RC_IDENT_NONE);
    assert_true(fabs(id.cond - 1.0 / 0.9999e-3) < 1e-6);
    /* from eigenvalues (the squares): the same classes and figures */
    double ev[N];
    for (unsigned k = 0; k < N; ++k)
        ev[k] = sv[k] * sv[k];
    ev[N - 1] = -1e-30; /* rounding below zero: a null direction, not an error */
    rc_ident ie;
    assert_int_equal(rc_ident_classify_eig(&ie, ev, V, N, 100), RC_OK);
    for (unsigned k = 0; k < N; ++k)
        assert_int_equal(ie.dir_class[k], id.dir_class[k]);
    assert_int_equal(ie.rank, id.rank);
    assert_true(fabs(ie.log_det - id.log_det) < 1e-12 && fabs(ie.cond - id.cond) < 1e-6);
    ev[1] = INFINITY;
    assert_int_equal(rc_ident_classify_eig(&ie, ev, V, N, 100), RC_ERR_NUMERIC);
    /* errors */
    const double bad[N] = {1.0, NAN, 0.5, 0.1};
    assert_int_equal(rc_ident_classify(&id, bad, V, N, 100), RC_ERR_NUMERIC);
    assert_int_equal(rc_ident_classify(&id, sv, V, 0, 100), RC_ERR_ARG);
    double w[1];
    assert_int_equal(rc_ident_normal(&id, V, w, V, RC_MAX_PARAMS + 1, 10), RC_ERR_ARG);
    /* all zero: nothing identifiable, no division by zero */
    const double z[N] = {0};
    assert_int_equal(rc_ident_classify(&id, z, V, N, 100), RC_OK);
    assert_int_equal(id.rank, 0);
    assert_int_equal(id.n_null, N);
    assert_true(id.observability == 0.0 && id.cond == 0.0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_known_null_and_weak),
        cmocka_unit_test(test_full_rank_figures),
        cmocka_unit_test(test_zero_column),
        cmocka_unit_test(test_classify_thresholds),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
