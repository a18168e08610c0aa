/* SPDX-License-Identifier: MIT */
/* test_fixture.c - the C fixture of the core-only tests (rct_irb120.h) is
 * data/irb120.json, number for number: the IRB120 exists once as data; and
 * that model reproduces the real file's reported positions. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

#include <cmocka.h>

#include "rc_model.h"
#include "rch_data.h"
#include "rch_robot.h"
#include "rct_irb120.h"

static void test_fixture_is_the_model_file(void **state)
{
    (void)state;
    rch_robot r;
    rch_diag d;
    assert_int_equal(rch_robot_load(&r, RCAL_SOURCE_DIR "/data/irb120.json", &d), 0);
    double dh[6][4];
    rct_irb120_dh(dh);
    unsigned n = 0;
    for (int i = 0; i < 6; ++i) {
        for (int k = 0; k < 4; ++k, ++n)
            assert_true(fabs(r.model.x[4 * i + k] - dh[i][k]) <= 1e-12 * (1.0 + fabs(dh[i][k])));
        assert_true(fabs(r.model.q_min_rad[i] - rct_irb120_lim_deg[i][0] * 3.14159265358979323846 / 180.0) < 1e-12);
        assert_true(fabs(r.model.q_max_rad[i] - rct_irb120_lim_deg[i][1] * 3.14159265358979323846 / 180.0) < 1e-12);
    }
    print_message("rct_irb120.h = data/irb120.json: %u DH numbers and 12 joint limits\n", n);
}

/* The nominal model (data/irb120.json) against the real file's x, y, z (the
 * controller's nominal FK before the joints were rounded to 0.1 deg). */
static void test_fk_real_file(void **state)
{
    (void)state;
    FILE *f = fopen(RCAL_SHARED_DATA, "r");
    if (!f) {
        print_message("SKIP: %s is absent; FK check against the real file not run\n", RCAL_SHARED_DATA);
        skip();
    }
    fclose(f);
    rch_data d;
    rch_diag dg;
    assert_int_equal(rch_data_load(&d, RCAL_SHARED_DATA, 0, &dg), 0);
    assert_non_null(d.xyz);
    rch_robot r;
    assert_int_equal(rch_robot_load(&r, RCAL_SOURCE_DIR "/data/irb120.json", &dg), 0);
    const rc_model m = r.model;
    size_t within_1mm = 0, far = 0;
    for (size_t i = 0; i < d.n; ++i) {
        double p[3];
        rc_fk(p, NULL, &m, d.s[i].q_rad);
        const double dist = sqrt(pow(p[0] - d.xyz[i][0], 2) + pow(p[1] - d.xyz[i][1], 2) + pow(p[2] - d.xyz[i][2], 2));
        if (dist < 1.0)
            ++within_1mm;
        else if (dist > 50.0)
            ++far;
    }
    /* all rows but the faulty ones agree within the 0.1 deg angle rounding */
    assert_int_equal(d.n, 1042);
    assert_true(within_1mm >= 1039);
    assert_int_equal(far, 1); /* line 952: z = 504.5 in the file, FK says 405.35 */
    rch_data_free(&d);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_fixture_is_the_model_file), cmocka_unit_test(test_fk_real_file)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
