/* SPDX-License-Identifier: MIT */
/* test_fixture.c - the C fixture of the core-only tests (rct_irb120.h) is
 * data/irb120.json, number for number: the IRB120 exists once as data. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

#include <cmocka.h>

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

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_fixture_is_the_model_file)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
