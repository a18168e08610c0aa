/* SPDX-License-Identifier: MIT */
/* test_lapack.c - the program computes with the reference LAPACK and BLAS
 * the build pinned (cmake/rcal_lapack.cmake), whatever the loader would
 * find: ctest runs it twice, as is (pkg_lapack_pinned) and with a fake
 * liblapack.so.3/libblas.so.3 first on LD_LIBRARY_PATH
 * (pkg_lapack_pinned_other_on_path: fake_lapack.c, ILAVER 0.0.0, every
 * eigenvalue 42), which is what installing ATLAS or OpenBLAS does to a
 * program that takes them from the loader. RCAL_LAPACK_VERSION: ILAVER of
 * the pinned archive, found at configure time. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include <cmocka.h>
#include <lapacke.h>

#include "rch_lapack.h"

#ifndef RCAL_LAPACK_VERSION
#define RCAL_LAPACK_VERSION "(not pinned)"
#endif

static void test_the_pinned_lapack_runs(void **state)
{
    (void)state;
    rch_lapack_info info;
    rch_lapack_get(&info);
    char v[32], line[3 * RCH_LAPACK_PATH];
    snprintf(v, sizeof v, "%d.%d.%d", info.version[0], info.version[1], info.version[2]);
    rch_lapack_line(line, sizeof line, &info);
    print_message("BLAS/LAPACK: %s\n", line);
    assert_string_equal(v, RCAL_LAPACK_VERSION);
    assert_int_equal(info.pinned, 1);
    if (!info.linked_in)
        fail_msg("LAPACK %s and BLAS %s are not the archives linked in", info.lapack_file, info.blas_file);
    char want[64];
    snprintf(want, sizeof want, "reference LAPACK %s and BLAS, linked in (pinned: ", RCAL_LAPACK_VERSION);
    assert_non_null(strstr(line, want));
}

/* LAPACKE's calls reach the pinned LAPACK: the eigenvalues of [2 1; 1 2]
 * are 1 and 3 (the fake says 42). */
static void test_lapacke_calls_the_pinned_lapack(void **state)
{
    (void)state;
    double a[4] = {2.0, 1.0, 1.0, 2.0}, w[2] = {0.0, 0.0};
    assert_int_equal(LAPACKE_dsyev(LAPACK_ROW_MAJOR, 'N', 'U', 2, a, 2, w), 0);
    if (!(fabs(w[0] - 1.0) < 1e-14 && fabs(w[1] - 3.0) < 1e-14))
        fail_msg("eigenvalues %.17g %.17g, want 1 and 3", w[0], w[1]);
}

/* The line of a build that is not pinned names the files the loader chose. */
static void test_line_names_the_loaded_files(void **state)
{
    (void)state;
    rch_lapack_info info;
    memset(&info, 0, sizeof info);
    info.version[0] = 3;
    info.version[1] = 10;
    info.version[2] = 3;
    snprintf(info.lapack_file, sizeof info.lapack_file, "/usr/lib/x86_64-linux-gnu/atlas/liblapack.so.3.10.3");
    snprintf(info.blas_file, sizeof info.blas_file, "/usr/lib/x86_64-linux-gnu/atlas/libblas.so.3.10.3");
    info.built = "the system's LAPACKE";
    char line[3 * RCH_LAPACK_PATH];
    rch_lapack_line(line, sizeof line, &info);
    assert_string_equal(line, "LAPACK 3.10.3 from /usr/lib/x86_64-linux-gnu/atlas/liblapack.so.3.10.3, BLAS from "
                              "/usr/lib/x86_64-linux-gnu/atlas/libblas.so.3.10.3 (not pinned, the build linked: "
                              "the system's LAPACKE)");
    char small[8];
    assert_ptr_equal(rch_lapack_line(small, sizeof small, &info), small);
    assert_string_equal(small, "LAPACK ");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_the_pinned_lapack_runs),
        cmocka_unit_test(test_lapacke_calls_the_pinned_lapack),
        cmocka_unit_test(test_line_names_the_loaded_files),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
