/* SPDX-License-Identifier: MIT */
/* test_comp_cli.c - rcal compensate round trips: a target list with a header
 * and extra columns, plain lines on stdin, a RAPID module, and bad lines
 * reported with file:line:col; outputs that would destroy an input refused
 * (issue 12); the warning of a target that could not be compensated names a
 * joint limit and gives the error of what was written (issue 12); the host
 * library's rch_comp_lines in-process. Runs the built rcal binary. */
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

#include "rc_rand.h"
#include "rch_comp.h"
#include "rch_robot.h"

#define DEG (3.14159265358979323846 / 180.0)
#define RCAL RCAL_BINARY_DIR "/tools/rcal"
#define RCAL_RT RCAL_BINARY_DIR "/firmware_host/rcal-rt"

static char dir[64];
static char model_path[128];
static rch_robot robot;

static void write_file(const char *path, const char *text)
{
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fputs(text, f);
    fclose(f);
}

static char *read_file(const char *path)
{
    FILE *f = fopen(path, "r");
    assert_non_null(f);
    static char buf[1 << 16];
    size_t n = fread(buf, 1, sizeof buf - 1, f);
    buf[n] = '\0';
    fclose(f);
    return buf;
}

static char *read_file_copy(const char *path)
{
    const char *t = read_file(path);
    char *c = malloc(strlen(t) + 1);
    assert_non_null(c);
    strcpy(c, t);
    return c;
}

static int run(const char *cmd)
{
    int st = system(cmd);
    assert_true(st != -1);
    return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

static double fk_gap_on(const rch_robot *r, const double q_deg[6], const double qc_deg[6]);

static double fk_gap(const double q_deg[6], const double qc_deg[6])
{
    return fk_gap_on(&robot, q_deg, qc_deg);
}

static double fk_gap_on(const rch_robot *r, const double q_deg[6], const double qc_deg[6])
{
    double q[6], qc[6], pn[3], pc[3];
    for (int i = 0; i < 6; ++i) {
        q[i] = q_deg[i] * DEG;
        qc[i] = qc_deg[i] * DEG;
    }
    /* compensation acts on the determined part of the model (issue 10) */
    rc_model det;
    rch_model_unc unc;
    int v1;
    char held[256];
    rch_comp_determined(&det, &unc, &v1, held, sizeof held, r, &r->nominal);
    rc_fk(pn, NULL, &r->nominal, q);
    rc_fk(pc, NULL, &det, qc);
    return sqrt((pn[0] - pc[0]) * (pn[0] - pc[0]) + (pn[1] - pc[1]) * (pn[1] - pc[1]) +
                (pn[2] - pc[2]) * (pn[2] - pc[2]));
}

static int setup(void **state)
{
    (void)state;
    strcpy(dir, "/tmp/rcal_comp_cli_XXXXXX");
    assert_non_null(mkdtemp(dir));
    snprintf(model_path, sizeof model_path, "%s/model.json", dir);
    rch_robot nom;
    rch_diag d;
    assert_int_equal(rch_robot_load(&nom, RCAL_SOURCE_DIR "/data/irb120.json", &d), 0);
    /* "calibrated" model: nominal + known errors */
    rc_model cal = nom.model;
    rc_rng g;
    rc_rng_seed(&g, 8);
    for (int k = 0; k < RC_N_DH; ++k)
        cal.x[k] += (k % 4 < 2 ? 0.5 : 0.1 * DEG) * rc_rng_normal(&g);
    cal.x[RC_P_ALPHA(5)] = nom.model.x[RC_P_ALPHA(5)];
    FILE *f = fopen(model_path, "w");
    assert_non_null(f);
    assert_int_equal(rch_robot_write(f, "test calibrated", &cal, &nom.model, NULL), 0);
    fclose(f);
    assert_int_equal(rch_robot_load(&robot, model_path, &d), 0);
    assert_true(robot.has_nominal);
    return 0;
}

static int teardown(void **state)
{
    (void)state;
    char cmd[160];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    return system(cmd) == 0 ? 0 : -1;
}

static void test_target_list_with_header(void **state)
{
    (void)state;
    char in[128], out[128], cmd[512];
    snprintf(in, sizeof in, "%s/prog.csv", dir);
    snprintf(out, sizeof out, "%s/prog_comp.csv", dir);
    const double tq[3][6] = {{10, 20, -30, 40, 50, 60}, {-35, 5, 10, -20, 70, 100}, {60, -10, -40, 90, -45, -30}};
    write_file(in, "name,q1,q2,q3,q4,q5,q6,speed\n"
                   "p10,10,20,-30,40,50,60,v100\n"
                   "# a comment\n"
                   "\n"
                   "p20, -35, 5, 10, -20, 70, 100 ,v200\n"
                   "p30,60,-10,-40,90,-45,-30,v50\n");
    snprintf(cmd, sizeof cmd, "'%s' compensate --model '%s' --in '%s' --out '%s'", RCAL, model_path, in, out);
    assert_int_equal(run(cmd), 0);
    char *txt = read_file(out);
    char *save = NULL, *line = strtok_r(txt, "\n", &save);
    assert_string_equal(line, "name,q1,q2,q3,q4,q5,q6,speed");
    const char *names[3] = {"p10", "p20", "p30"}, *speeds[3] = {"v100", "v200", "v50"};
    int k = 0;
    while ((line = strtok_r(NULL, "\n", &save)) != NULL) {
        if (line[0] == '#')
            continue;
        char name[16], speed[16];
        double q[6];
        assert_int_equal(sscanf(line, "%15[^,],%lf,%lf,%lf,%lf,%lf,%lf,%15s", name, &q[0], &q[1], &q[2], &q[3],
                                &q[4], &q[5], speed),
                         8);
        assert_true(k < 3);
        assert_string_equal(name, names[k]);
        assert_string_equal(speed, speeds[k]);
        assert_true(fk_gap(tq[k], q) < 1e-3);
        double corr = 0.0;
        for (int i = 0; i < 6; ++i)
            corr = fmax(corr, fabs(q[i] - tq[k][i]));
        assert_true(corr > 1e-3); /* it did correct */
        ++k;
    }
    assert_int_equal(k, 3);
}

static void test_stdin_plain(void **state)
{
    (void)state;
    char out[128], cmd[512];
    snprintf(out, sizeof out, "%s/plain.csv", dir);
    snprintf(cmd, sizeof cmd, "printf '10,20,-30,40,50,60\\n0,0,0,0,30,0\\n' | '%s' compensate --model '%s' > '%s'",
             RCAL, model_path, out);
    assert_int_equal(run(cmd), 0);
    double q[2][6];
    const double tq[2][6] = {{10, 20, -30, 40, 50, 60}, {0, 0, 0, 0, 30, 0}};
    FILE *f = fopen(out, "r");
    assert_non_null(f);
    for (int k = 0; k < 2; ++k)
        assert_int_equal(fscanf(f, "%lf,%lf,%lf,%lf,%lf,%lf", &q[k][0], &q[k][1], &q[k][2], &q[k][3], &q[k][4],
                                &q[k][5]),
                         6);
    fclose(f);
    for (int k = 0; k < 2; ++k)
        assert_true(fk_gap(tq[k], q[k]) < 1e-3);
}

static void test_rapid_module(void **state)
{
    (void)state;
    char in[128], out[128], cmd[512];
    snprintf(in, sizeof in, "%s/m.mod", dir);
    snprintf(out, sizeof out, "%s/m_comp.mod", dir);
    write_file(in, "MODULE Grind\n"
                   "  CONST jointtarget jt10:=[[10,20,-30,40,50,60],[9E9,9E9,9E9,9E9,9E9,9E9]];\n"
                   "  PROC main()\n    MoveAbsJ jt10, v100, fine, tool0;\n  ENDPROC\nENDMODULE\n");
    snprintf(cmd, sizeof cmd, "'%s' compensate --model '%s' --in '%s' --out '%s'", RCAL, model_path, in, out);
    assert_int_equal(run(cmd), 0);
    const char *txt = read_file(out);
    assert_non_null(strstr(txt, "MODULE Grind\n"));
    assert_non_null(strstr(txt, "    MoveAbsJ jt10, v100, fine, tool0;\n"));
    const char *jt = strstr(txt, "jt10:=[[");
    assert_non_null(jt);
    double q[6];
    assert_int_equal(sscanf(jt, "jt10:=[[%lf,%lf,%lf,%lf,%lf,%lf]", &q[0], &q[1], &q[2], &q[3], &q[4], &q[5]), 6);
    assert_non_null(strstr(jt, "],[9E9,9E9,9E9,9E9,9E9,9E9]];"));
    const double tq[6] = {10, 20, -30, 40, 50, 60};
    assert_true(fk_gap(tq, q) < 0.01); /* RAPID keeps 4 decimals */
}

static void test_bad_lines(void **state)
{
    (void)state;
    char in[128], err[128], cmd[512];
    snprintf(in, sizeof in, "%s/bad.csv", dir);
    snprintf(err, sizeof err, "%s/err.txt", dir);
    static const struct {
        const char *text;
        const char *where;
    } cases[] = {
        {"10,20,-30,40,50,60\n1,2,x,4,5,6\n", ":2:5:"},        /* not a number */
        {"10,20,-30,40,50,60\n1,2,3,4,5\n", ":2:10:"},          /* missing field */
        {"10,20,-30,40,50,60,7\n", ":1:20:"},                    /* extra field */
        {"10,20,100,40,50,60\n", ":1:7:"},                       /* q3 beyond its limit (70 deg) */
        {"q1,q2,q3,q4,q5\n", ":1:1:"},                           /* header without q6 */
        {"10,20,-30,40,50,nan\n", ":1:17:"},                     /* NaN */
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; ++k) {
        write_file(in, cases[k].text);
        snprintf(cmd, sizeof cmd, "'%s' compensate --model '%s' --in '%s' > /dev/null 2> '%s'", RCAL, model_path, in,
                 err);
        assert_int_equal(run(cmd), 1);
        char want[192];
        snprintf(want, sizeof want, "%s%s", in, cases[k].where);
        const char *msg = read_file(err);
        if (strstr(msg, want) == NULL)
            fail_msg("case %zu: expected '%s' in: %s", k, want, msg);
    }
    /* usage errors */
    snprintf(cmd, sizeof cmd, "'%s' compensate --in x > /dev/null 2>&1", RCAL);
    assert_int_equal(run(cmd), 2);
}

/* An output that names an input is refused before anything is written:
 * --out = --in (a RAPID program), --out = --model, also through another
 * spelling of the path; and an input error halfway leaves an existing output
 * as it was (issue 12). */
static void test_output_never_destroys(void **state)
{
    (void)state;
    char prog[128], out[128], err[128], cmd[1024];
    snprintf(prog, sizeof prog, "%s/prog.mod", dir);
    snprintf(out, sizeof out, "%s/out.csv", dir);
    snprintf(err, sizeof err, "%s/err.txt", dir);
    write_file(prog, "MODULE M\n  CONST jointtarget j1:=[[10,20,-30,40,50,60],[9E9,9E9,9E9,9E9,9E9,9E9]];\nENDMODULE\n");
    char *prog_before = read_file_copy(prog), *model_before = read_file_copy(model_path);
    snprintf(cmd, sizeof cmd, "'%s' compensate --model '%s' --in '%s' --out '%s' 2> '%s'", RCAL, model_path, prog, prog,
             err);
    assert_int_equal(run(cmd), 1);
    assert_string_equal(read_file(prog), prog_before);
    assert_non_null(strstr(read_file(err), "same file as the input"));
    snprintf(cmd, sizeof cmd, "cd '%s' && '%s' compensate --model model.json --in prog.mod --out ./model.json 2> '%s'",
             dir, RCAL, err);
    assert_int_equal(run(cmd), 1);
    assert_string_equal(read_file(model_path), model_before);
    assert_non_null(strstr(read_file(err), "same file as the input"));
    /* a bad line at the end: the existing output keeps its content */
    write_file(out, "precious\n");
    write_file(prog, "10,20,-30,40,50,60\n1,2,x,4,5,6\n");
    snprintf(cmd, sizeof cmd, "'%s' compensate --model '%s' --in '%s' --out '%s' 2> '%s'", RCAL, model_path, prog, out,
             err);
    assert_int_equal(run(cmd), 1);
    assert_string_equal(read_file(out), "precious\n");
    /* 0 is not silently the default */
    snprintf(cmd, sizeof cmd, "'%s' compensate --model '%s' --max-dev-deg 0 < /dev/null 2> '%s'", RCAL, model_path, err);
    assert_int_equal(run(cmd), 2);
    assert_non_null(strstr(read_file(err), "--max-dev-deg"));
    free(prog_before);
    free(model_before);
}

/* A target that needs joint 1 beyond its limit: the warning says a joint
 * limit is in the way (not "iteration limit") and its position error is the
 * error of what was written (issue 12: "0.19 mm" for a target written
 * 21.8 mm off). */
static void test_failure_reported_truthfully(void **state)
{
    (void)state;
    char mp[128], in[128], out[128], err[128], cmd[1024];
    snprintf(mp, sizeof mp, "%s/limit_model.json", dir);
    snprintf(in, sizeof in, "%s/limit.csv", dir);
    snprintf(out, sizeof out, "%s/limit_out.csv", dir);
    snprintf(err, sizeof err, "%s/limit_err.txt", dir);
    rc_model cal = robot.nominal;
    cal.x[RC_P_THETA(0)] -= 0.05;
    FILE *f = fopen(mp, "w");
    assert_non_null(f);
    assert_int_equal(rch_robot_write(f, "joint 1 off", &cal, &robot.nominal, NULL), 0);
    fclose(f);
    rch_robot lim;
    rch_diag d;
    assert_int_equal(rch_robot_load(&lim, mp, &d), 0);
    const double tq[6] = {165, 20, -10, 10, 40, 5};
    write_file(in, "165,20,-10,10,40,5\n");
    snprintf(cmd, sizeof cmd, "'%s' compensate --model '%s' --position-only --in '%s' --out '%s' 2> '%s'", RCAL, mp, in,
             out, err);
    assert_int_equal(run(cmd), 1);
    const char *msg = read_file(err);
    assert_non_null(strstr(msg, "joint limit"));
    assert_null(strstr(msg, "iteration limit"));
    const char *at = strstr(msg, "the closest point found within the bounds, ");
    assert_non_null(at);
    double said = -1.0;
    assert_int_equal(sscanf(at, "the closest point found within the bounds, %lf mm", &said), 1);
    double qo[6];
    f = fopen(out, "r");
    assert_non_null(f);
    assert_int_equal(fscanf(f, "%lf,%lf,%lf,%lf,%lf,%lf", &qo[0], &qo[1], &qo[2], &qo[3], &qo[4], &qo[5]), 6);
    fclose(f);
    const double gap = fk_gap_on(&lim, tq, qo);
    assert_true(gap > 1.0);
    if (fabs(gap - said) > 1e-3)
        fail_msg("warning says %.4f mm, the written target is %.4f mm off", said, gap);
}

/* u95_mm of a target whose compensation did not converge is what the robot
 * then misses by: the posterior's radius plus the distance the warning names
 * (not the radius alone, as if it had been compensated). The demo model
 * (a posterior) with --max-dev-deg 0.001: every target stops short. */
static void test_u95_of_unconverged(void **state)
{
    (void)state;
    char mp[160], in[160], out[160], u_ok[160], u_bad[160], err[160], cmd[1200];
    snprintf(mp, sizeof mp, "%s/demo_model.json", dir);
    snprintf(in, sizeof in, "%s/u95_targets.csv", dir);
    snprintf(out, sizeof out, "%s/u95_out.csv", dir);
    snprintf(u_ok, sizeof u_ok, "%s/u95_ok.csv", dir);
    snprintf(u_bad, sizeof u_bad, "%s/u95_bad.csv", dir);
    snprintf(err, sizeof err, "%s/u95_err.txt", dir);
    snprintf(cmd, sizeof cmd, "'%s' calibrate --data '%s/data/sim_irb120.csv' --out '%s' > /dev/null", RCAL,
             RCAL_SOURCE_DIR, mp);
    assert_int_equal(run(cmd), 0);
    write_file(in, "10,20,30,40,50,50\n-30,40,10,20,-50,90\n");
    snprintf(cmd, sizeof cmd, "'%s' compensate --model '%s' --in '%s' --out '%s' --uncertainty-out '%s'", RCAL, mp, in,
             out, u_ok);
    assert_int_equal(run(cmd), 0);
    snprintf(cmd, sizeof cmd,
             "'%s' compensate --model '%s' --in '%s' --out '%s' --uncertainty-out '%s' --max-dev-deg 0.001 2> '%s'",
             RCAL, mp, in, out, u_bad, err);
    assert_int_equal(run(cmd), 1);
    double ok[2], bad[2], miss[2];
    unsigned ln;
    FILE *f = fopen(u_ok, "r"), *g = fopen(u_bad, "r");
    assert_non_null(f);
    assert_non_null(g);
    assert_int_equal(fscanf(f, "line,u95_mm %u,%lf %u,%lf", &ln, &ok[0], &ln, &ok[1]), 4);
    assert_int_equal(fscanf(g, "line,u95_mm %u,%lf %u,%lf", &ln, &bad[0], &ln, &bad[1]), 4);
    fclose(f);
    fclose(g);
    const char *msg = read_file(err), *at = msg;
    for (int k = 0; k < 2; ++k) {
        at = strstr(at, "within the bounds, ");
        assert_non_null(at);
        assert_int_equal(sscanf(at, "within the bounds, %lf mm", &miss[k]), 1);
        at += 19;
        assert_true(ok[k] > 0.0 && ok[k] < 0.05 && miss[k] > 0.1);
        if (fabs(bad[k] - (ok[k] + miss[k])) > 1e-4)
            fail_msg("target %d: u95 %.6f mm, expected %.6f + %.4f", k + 1, bad[k], ok[k], miss[k]);
    }
}

/* The host library in-process: rch_comp_lines on a CSV with a header. */
static void test_lines_in_process(void **state)
{
    (void)state;
    static rc_comp_stream s;
    assert_int_equal(rc_comp_stream_init(&s, &robot.model, &robot.nominal, NULL), RC_OK);
    FILE *in = tmpfile(), *out = tmpfile();
    assert_non_null(in);
    assert_non_null(out);
    fputs("id,j1,j2,j3,j4,j5,j6\na,10,20,-30,40,50,60\n# note\nb,0,0,0,0,30,0\n", in);
    rewind(in);
    rch_comp_result r;
    rch_diag d;
    memset(&r, 0, sizeof r);
    assert_int_equal(rch_comp_lines(out, &r, in, "mem", &s, &robot.model, RCH_COMP_AUTO, NULL, &d), 0);
    assert_int_equal(r.format, RCH_COMP_CSV);
    assert_int_equal(r.n, 2);
    assert_int_equal(r.n_fail, 0);
    assert_true(r.max_corr_deg > 1e-3 && r.max_corr_deg < 5.73);
    rewind(out);
    char line[256];
    assert_non_null(fgets(line, sizeof line, out));
    assert_string_equal(line, "id,j1,j2,j3,j4,j5,j6\n");
    double q[6];
    char id[8];
    assert_non_null(fgets(line, sizeof line, out));
    assert_int_equal(sscanf(line, "%7[^,],%lf,%lf,%lf,%lf,%lf,%lf", id, &q[0], &q[1], &q[2], &q[3], &q[4], &q[5]), 7);
    const double tq[6] = {10, 20, -30, 40, 50, 60};
    assert_string_equal(id, "a");
    /* this stream was made with the full model: check against it */
    double qr[6], qcr[6], pn[3], pc[3];
    for (int i = 0; i < 6; ++i) {
        qr[i] = tq[i] * DEG;
        qcr[i] = q[i] * DEG;
    }
    rc_fk(pn, NULL, &robot.nominal, qr);
    rc_fk(pc, NULL, &robot.model, qcr);
    assert_true(sqrt((pn[0] - pc[0]) * (pn[0] - pc[0]) + (pn[1] - pc[1]) * (pn[1] - pc[1]) +
                     (pn[2] - pc[2]) * (pn[2] - pc[2])) < 1e-3);
    fclose(in);
    fclose(out);
    /* an error names file:line:col */
    in = tmpfile();
    out = tmpfile();
    fputs("1,2,3,4,5,6\n1,2,3,4,5\n", in);
    rewind(in);
    assert_int_equal(rch_comp_lines(out, &r, in, "mem", &s, &robot.model, RCH_COMP_CSV, NULL, &d), -1);
    assert_int_equal(d.line, 2);
    fclose(in);
    fclose(out);
}

/* rcal-rt refuses malformed or out-of-range number options with a message
 * naming the option (exit 2), before it loads or runs anything. */
static void test_rt_bad_numbers(void **state)
{
    static const char *const bad[] = {
        "--rate-hz 1000x", "--rate-hz x",  "--seconds 1e999",    "--seconds nan",
        "--repeat -1",     "--repeat 2.5", "--targets 99999999999999999999999", "--targets 20000000",
        "--cpu abc",       "--cpu -1",     "--cpu 100000",       "--rate-hz 1 --seconds 0.1",
    };
    char cmd[512], err[128];
    (void)state;
    if (access(RCAL_RT, X_OK) != 0) {
        print_message("SKIP: %s not built\n", RCAL_RT);
        skip();
    }
    snprintf(err, sizeof err, "%s/rt.err", dir);
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; ++k) {
        snprintf(cmd, sizeof cmd, "'%s' %s > /dev/null 2> '%s'", RCAL_RT, bad[k], err);
        if (run(cmd) != 2)
            fail_msg("rcal-rt %s: expected exit 2", bad[k]);
        char opt[32];
        snprintf(opt, sizeof opt, "%.*s", (int)strcspn(bad[k], " "), bad[k]);
        if (!strstr(read_file(err), opt))
            fail_msg("rcal-rt %s: the message does not name %s: %s", bad[k], opt, read_file(err));
    }
}

/* A RAPID robtarget is corrected (issue 21; it was copied with a warning,
 * issue 13); --accept-robtargets is still accepted, with a note. */
static void test_robtargets_corrected(void **state)
{
    (void)state;
    char in[128], out[128], err[128], cmd[640];
    snprintf(in, sizeof in, "%s/mixed.mod", dir);
    snprintf(out, sizeof out, "%s/mixed_comp.mod", dir);
    snprintf(err, sizeof err, "%s/mixed.err", dir);
    write_file(in, "MODULE m\n"
                   "  CONST jointtarget j1 := [[10,20,30,40,50,60],[9E9,9E9,9E9,9E9,9E9,9E9]];\n"
                   "  CONST robtarget p1 := [[438.426,100.804,511.163],[0.174033,0.432048,0.808673,0.359297],"
                   "[0,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];\n"
                   "ENDMODULE\n");
    snprintf(cmd, sizeof cmd, "'%s' compensate --model '%s' --in '%s' --out '%s' 2> '%s'", RCAL, model_path, in, out,
             err);
    assert_int_equal(run(cmd), 0);
    const char *txt = read_file(out);
    assert_non_null(strstr(txt, "CONST robtarget p1 := [["));
    assert_null(strstr(txt, "[[438.426,100.804,511.163]")); /* the robtarget was corrected */
    assert_null(strstr(txt, "[[10,20,30,40,50,60]"));       /* the jointtarget was corrected */
    snprintf(cmd, sizeof cmd, "'%s' compensate --model '%s' --in '%s' --out '%s' --accept-robtargets 2> '%s'", RCAL,
             model_path, in, out, err);
    assert_int_equal(run(cmd), 0);
    assert_non_null(strstr(read_file(err), "--accept-robtargets is deprecated"));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_target_list_with_header),
        cmocka_unit_test(test_rt_bad_numbers),
        cmocka_unit_test(test_stdin_plain),
        cmocka_unit_test(test_rapid_module),
        cmocka_unit_test(test_bad_lines),
        cmocka_unit_test(test_output_never_destroys),
        cmocka_unit_test(test_failure_reported_truthfully),
        cmocka_unit_test(test_lines_in_process),
        cmocka_unit_test(test_robtargets_corrected),
        cmocka_unit_test(test_u95_of_unconverged),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
