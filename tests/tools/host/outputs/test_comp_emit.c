/* SPDX-License-Identifier: MIT */
/* test_comp_emit.c - the firmware table generator (rch_emit_c): a model name
 * made to break out of the C comment and string it lands in ("*" "/", a
 * newline, a backslash, "??/", quotes, a non-ASCII byte) is escaped: the
 * generated header compiles warning-free in double and in float, declares
 * nothing but its tables, and carries the name byte for byte; its tables are
 * what rc_kin_compile gives (the effects' tables included). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "rch_emit.h"
#include "rct_irb120.h"

#define DEG (3.14159265358979323846 / 180.0)

static const char evil_name[] = "evil */ int injected = 1; /* \\\n#error broken ?\?/\n\"q\" \xc3\xa9 end\\";

static void make_model(rc_model *m)
{
    double dh[RC_NJ][4];
    rct_irb120_dh(dh);
    static const double enc[3] = {600, -300, 50};
    assert_int_equal(rc_model_init(m, (const double(*)[4])dh, enc), RC_OK);
}

static int run(const char *cmd)
{
    int st = system(cmd);
    return (st != -1 && WIFEXITED(st)) ? WEXITSTATUS(st) : -1;
}

static void test_escaped_header_compiles(void **state)
{
    (void)state;
    char dir[] = "/tmp/rcal_emit_XXXXXX";
    assert_non_null(mkdtemp(dir));
    rc_model cal, nom;
    make_model(&nom);
    cal = nom;
    cal.x[RC_P_A(1)] += 0.25;
    assert_int_equal(rc_model_add_effect(&cal, RC_EFF_TOOL_OFFSET, 0, 0), RC_OK);
    assert_int_equal(rc_model_add_effect(&cal, RC_EFF_JOINT_PERIODIC, 3, 0), RC_OK);
    assert_int_equal(rc_model_add_effect(&cal, RC_EFF_JOINT_COMPLIANCE, 1, 0), RC_OK);
    for (unsigned k = RC_N_BASE; k < cal.n_params; ++k)
        cal.x[k] = 1e-3 * (double)(k - RC_N_BASE + 1);

    char hdr[128], tu[128], cmd[1024];
    snprintf(hdr, sizeof hdr, "%s/fw_model_data.h", dir);
    snprintf(tu, sizeof tu, "%s/use.c", dir);
    FILE *f = fopen(hdr, "w");
    assert_non_null(f);
    const rch_emit_src src = {evil_name, "rcal-rt --emit-c /tmp/x*/y.json", 0u};
    rch_diag d;
    assert_int_equal(rch_emit_c(f, &src, &cal, &nom, &d), 0);
    fclose(f);

    /* the translation unit: the name byte for byte, the tables as compiled,
     * and `injected` free for its own use (a definition from the header
     * would conflict) */
    rc_kin kc;
    assert_int_equal(rc_kin_compile(&kc, &cal), RC_OK);
    f = fopen(tu, "w");
    assert_non_null(f);
    fprintf(f, "#include \"fw_model_data.h\"\n#include <string.h>\nstatic const char injected[] = {");
    for (size_t i = 0; i < sizeof evil_name; ++i)
        fprintf(f, "%d,", (int)(signed char)evil_name[i]);
    fprintf(f, "};\nint main(void)\n{\n    int ok = sizeof fw_model_name == sizeof injected &&\n"
               "             memcmp(fw_model_name, injected, sizeof injected) == 0;\n");
    fprintf(f, "    ok = ok && fw_kin_cal.link[1].a_mm == RC_REAL_C(%.17e) && fw_kin_cal.n_jeff == %u && "
               "fw_kin_cal.n_ref == %u && fw_kin_cal.has_tool == 1;\n",
            (double)kc.link[1].a_mm, kc.n_jeff, kc.n_ref);
    fprintf(f, "    ok = ok && fw_kin_cal.jeff[0].c[2] == RC_REAL_C(%.17e) && fw_kin_cal.ref[0].link[2].sin_alpha == "
               "RC_REAL_C(%.17e);\n",
            (double)kc.jeff[0].c[2], (double)kc.ref[0].link[2].sin_alpha);
    fprintf(f, "    ok = ok && fw_kin_nom.link[1].a_mm == RC_REAL_C(270.0) && FW_MODEL_COMP_FLAGS == 0u;\n"
               "    return ok ? 0 : 1;\n}\n");
    fclose(f);
    static const char *const defs[2] = {"", "-DRC_REAL_FLOAT"};
    for (int k = 0; k < 2; ++k) {
        snprintf(cmd, sizeof cmd,
                 "'%s' -std=c99 -Wall -Wextra -Werror -pedantic -Wconversion -Wdouble-promotion %s -I'%s' "
                 "-I'%s/lib' -I'%s/include' '%s' '%s/lib/rc_version.c' -o '%s/use' -lm && '%s/use'",
                 RCAL_CC, defs[k], dir, RCAL_SOURCE_DIR, RCAL_BINARY_DIR, tu, RCAL_SOURCE_DIR, dir, dir);
        if (run(cmd) != 0)
            fail_msg("generated header failed (%s): %s", defs[k], cmd);
    }
    /* no raw comment end or line splice anywhere in the comment lines */
    f = fopen(hdr, "r");
    assert_non_null(f);
    char line[4096];
    unsigned n = 0;
    while (fgets(line, sizeof line, f) != NULL) {
        if (strncmp(line, "/*", 2) == 0 || strncmp(line, " *", 2) == 0) {
            const char *end = strstr(line, "*/");
            assert_true(end == NULL || end[2] == '\n'); /* only the comment's own end, at a line end */
            assert_null(strchr(line, '\\') != NULL && strstr(line, "\\x") == NULL ? line : NULL);
        }
        ++n;
    }
    fclose(f);
    assert_true(n > 20);
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    assert_int_equal(run(cmd), 0);
}

/* A model the firmware tables cannot hold is refused with a message. */
static void test_refuses_uncompilable(void **state)
{
    (void)state;
    rc_model cal, nom;
    make_model(&nom);
    cal = nom;
    cal.x[RC_P_D(2)] = NAN;
    const rch_emit_src src = {"x", "test", 0u};
    rch_diag d;
    FILE *f = tmpfile();
    assert_non_null(f);
    assert_int_equal(rch_emit_c(f, &src, &cal, &nom, &d), -1);
    assert_non_null(strstr(d.msg, "cannot be compiled"));
    fclose(f);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_escaped_header_compiles),
        cmocka_unit_test(test_refuses_uncompilable),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
