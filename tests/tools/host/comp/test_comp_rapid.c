/* SPDX-License-Identifier: MIT */
/* test_comp_rapid.c - whole RAPID programs (issue 21): the nominal IK
 * against forward kinematics (every configuration of random poses), the
 * committed module with every target form compensated and each target's
 * before/after checked against the stream's result for the same joints,
 * every byte outside the corrected numbers kept, and a module of targets
 * that cannot be corrected refused with each one's line, column and reason. */
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
#include "rch_ik.h"
#include "rch_rapid.h"
#include "rch_robot.h"

#define DEG (3.14159265358979323846 / 180.0)
#define RCAL RCAL_BINARY_DIR "/tools/rcal"
#define MODULE_IN RCAL_SOURCE_DIR "/tests/tools/host/comp/data/every_form.mod"
#define MODULE_BAD RCAL_SOURCE_DIR "/tests/tools/host/comp/data/bad_targets.mod"

static char dir[64], model_path[128];
static rch_robot nominal, robot;

static char *slurp(const char *path, size_t *len)
{
    FILE *f = fopen(path, "rb");
    assert_non_null(f);
    char *b = malloc(1 << 20);
    assert_non_null(b);
    *len = fread(b, 1, (1 << 20) - 1, f);
    b[*len] = '\0';
    fclose(f);
    return b;
}

static int run(const char *cmd)
{
    const int st = system(cmd);
    assert_true(st != -1);
    return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

static int setup(void **state)
{
    (void)state;
    strcpy(dir, "/tmp/rcal_comp_rapid_XXXXXX");
    assert_non_null(mkdtemp(dir));
    snprintf(model_path, sizeof model_path, "%s/model.json", dir);
    rch_diag d;
    assert_int_equal(rch_robot_load(&nominal, RCAL_SOURCE_DIR "/data/irb120.json", &d), 0);
    rc_model cal = nominal.model; /* "calibrated": nominal + known errors */
    rc_rng g;
    rc_rng_seed(&g, 21);
    for (int k = 0; k < RC_N_DH; ++k)
        cal.x[k] += (k % 4 < 2 ? 0.5 : 0.1 * DEG) * rc_rng_normal(&g);
    cal.x[RC_P_ALPHA(5)] = nominal.model.x[RC_P_ALPHA(5)];
    FILE *f = fopen(model_path, "w");
    assert_non_null(f);
    assert_int_equal(rch_robot_write(f, "test calibrated", &cal, &nominal.model, NULL), 0);
    fclose(f);
    assert_int_equal(rch_robot_load(&robot, model_path, &d), 0);
    return 0;
}

static int teardown(void **state)
{
    (void)state;
    char cmd[128];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    return system(cmd) == 0 ? 0 : -1;
}

static double rot_gap(const double a[4], const double b[4])
{
    const double na = sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2] + a[3] * a[3]);
    const double nb = sqrt(b[0] * b[0] + b[1] * b[1] + b[2] * b[2] + b[3] * b[3]);
    return 1.0 - fabs(a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3]) / (na * nb);
}

/* FK(IK(pose)) = pose for every closed-form solution of random poses; the
 * confdata of each solution selects it back. */
static void ik_round_trip(const rc_model *m, const char *name);

static void test_ik_round_trip(void **state)
{
    (void)state;
    ik_round_trip(&nominal.model, "irb120");
    static rch_robot kr6;
    rch_diag d;
    assert_int_equal(rch_robot_load(&kr6, RCAL_SOURCE_DIR "/data/kr6.json", &d), 0);
    ik_round_trip(&kr6.model, "kr6 (a1 = 25 mm)");
}

static void ik_round_trip(const rc_model *m, const char *name)
{
    char why[256];
    assert_int_equal(rch_ik_supported(m, why, sizeof why), 0);
    /* tool0 at the zero position, as the IRB120's controller reads it */
    const double q0[RC_NJ] = {0, 0, 0, 0, 0, 0};
    double p[3], qt[4];
    int cf[4];
    rch_ik_fk(p, qt, cf, m, q0, NULL);
    if (strcmp(name, "irb120") == 0)
        assert_true(fabs(p[0] - 374) < 1e-9 && fabs(p[1]) < 1e-9 && fabs(p[2] - 630) < 1e-9);
    if (strcmp(name, "irb120") == 0)
        assert_true(fabs(qt[0] - sqrt(0.5)) < 1e-12 && fabs(qt[1]) < 1e-12 && fabs(qt[2] - sqrt(0.5)) < 1e-12 &&
                fabs(qt[3]) < 1e-12);
    rc_rng g;
    rc_rng_seed(&g, 2101);
    double worst_mm = 0, worst_rot = 0, worst_q = 0;
    int seen[8] = {0}, n_sol = 0;
    const double tool[3] = {30, -20, 120};
    for (int t = 0; t < 500; ++t) {
        double q[RC_NJ];
        for (unsigned j = 0; j < RC_NJ; ++j)
            q[j] = m->q_min_rad[j] + (m->q_max_rad[j] - m->q_min_rad[j]) * rc_rng_u01(&g);
        const double *tl = t % 2 ? tool : NULL;
        rch_ik_fk(p, qt, cf, m, q, tl);
        double all[8][RC_NJ];
        const int n = rch_ik_all(all, m, p, qt, tl);
        /* eight with no shoulder offset; with a1 != 0 the arm turned over
         * may not reach (four) */
        assert_true(n == 8 || (n >= 2 && m->x[RC_P_A(0)] != 0.0));
        int cfx_mask = 0;
        for (int k = 0; k < n; ++k) {
            double p2[3], q2[4];
            int c2[4];
            rch_ik_fk(p2, q2, c2, m, all[k], tl);
            const double e = sqrt((p2[0] - p[0]) * (p2[0] - p[0]) + (p2[1] - p[1]) * (p2[1] - p[1]) +
                                  (p2[2] - p[2]) * (p2[2] - p[2]));
            worst_mm = fmax(worst_mm, e);
            worst_rot = fmax(worst_rot, rot_gap(q2, qt));
            cfx_mask |= 1 << c2[3];
            seen[c2[3]]++;
            ++n_sol;
        }
        int bits = 0;
        for (int b = 0; b < 8; ++b)
            bits += (cfx_mask >> b) & 1;
        assert_int_equal(bits, n); /* each solution its own cfx */
        double qs[RC_NJ];
        assert_int_equal(rch_ik_solve(qs, m, p, qt, cf, tl, why, sizeof why), 0);
        for (unsigned j = 0; j < RC_NJ; ++j)
            worst_q = fmax(worst_q, fabs(qs[j] - q[j]));
    }
    printf("IK round trip, %s: %d solutions of 500 poses (%d..%d per cfx), worst |FK(IK) - pose| %.3g mm, "
           "1 - |q.q'| %.3g, joints recovered from confdata to %.3g rad\n",
           name, n_sol, seen[0], seen[7], worst_mm, worst_rot, worst_q);
    assert_true(worst_mm < 1e-9);
    assert_true(worst_rot < 1e-12);
    assert_true(worst_q < 1e-9);
}

typedef struct {
    double rt_mm, rt_rot, land_mm, land_rot;
} worst;

/* One robtarget of the module: b (after) is FK_nom of the stream's output qc
 * for the IK joints of a (before), and the controller's IK of b puts the
 * real robot (det) on a's pose. */
static void check_robtarget(worst *w, const rch_rapid_target *a, const rch_rapid_target *b, const rc_real qc[RC_NJ],
                            const rc_model *det, int exit_kind)
{
    char why[256];
    double qcd[RC_NJ], p[3], qt[4];
    int cf[4];
    for (unsigned j = 0; j < RC_NJ; ++j)
        qcd[j] = (double)qc[j];
    rch_ik_fk(p, qt, cf, &robot.nominal, qcd, NULL);
    for (int j = 0; j < 3; ++j)
        w->rt_mm = fmax(w->rt_mm, fabs(b->val[j] - p[j]));
    w->rt_rot = fmax(w->rt_rot, rot_gap(&b->val[3], qt));
    for (int j = 0; j < 4; ++j)
        assert_int_equal((int)b->val[7 + j], cf[j]);
    /* what the controller then does: its nominal IK of the written
     * target, on the real (calibrated) robot, lands on the intended pose */
    int cfo[4] = {(int)b->val[7], (int)b->val[8], (int)b->val[9], (int)b->val[10]};
    double qr[RC_NJ], pr[3], Rr[9], Rz[9], Ra[9];
    assert_int_equal(rch_ik_solve(qr, &robot.nominal, &b->val[0], &b->val[3], cfo, NULL, why, sizeof why), 0);
    rc_fk(pr, Rr, det, qr);
    rch_ik_quat_to_rot(Ra, &a->val[3]);
    const double Rz180[9] = {-1, 0, 0, 0, -1, 0, 0, 0, 1};
    memcpy(Rz, Rz180, sizeof Rz);
    double Rt[9];
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            Rt[3 * i + j] = Rr[3 * i] * Rz[j] + Rr[3 * i + 1] * Rz[3 + j] + Rr[3 * i + 2] * Rz[6 + j];
    double tr = 0;
    for (int i = 0; i < 9; ++i)
        tr += Rt[i] * Ra[i];
    const double ang = acos(fmin(1.0, fmax(-1.0, (tr - 1.0) / 2.0)));
    const double e = sqrt((pr[0] - a->val[0]) * (pr[0] - a->val[0]) + (pr[1] - a->val[1]) * (pr[1] - a->val[1]) +
                          (pr[2] - a->val[2]) * (pr[2] - a->val[2]));
    w->land_mm = fmax(w->land_mm, e);
    if (exit_kind != RC_COMP_POSITION_ONLY)
        w->land_rot = fmax(w->land_rot, ang);
    printf("line %3u %-11s %-9s before [%g,%g,%g] [%g,%g,%g,%g] [%g,%g,%g,%g] after [%.4f,%.4f,%.4f] "
           "[%.7f,%.7f,%.7f,%.7f] [%g,%g,%g,%g]; the real robot at the controller's IK of it: %.5f mm, %.2g rad "
           "from the intended pose\n",
           a->line, "robtarget", a->name[0] ? a->name : "(inline)", a->val[0], a->val[1], a->val[2], a->val[3],
           a->val[4], a->val[5], a->val[6], a->val[7], a->val[8], a->val[9], a->val[10], b->val[0], b->val[1],
           b->val[2], b->val[3], b->val[4], b->val[5], b->val[6], b->val[7], b->val[8], b->val[9], b->val[10], e,
           ang);
}

/* The module with every target form: each output target is the stream's
 * correction of the same joints (a robtarget: the nominal pose of the
 * corrected IK joints), and the bytes between the numbers are unchanged. */
static void test_every_form(void **state)
{
    (void)state;
    char out[128], cmd[640];
    snprintf(out, sizeof out, "%s/every_form_comp.mod", dir);
    snprintf(cmd, sizeof cmd, "'%s' compensate --model '%s' --full-pose --in '%s' --out '%s'", RCAL, model_path,
             MODULE_IN, out);
    assert_int_equal(run(cmd), 0);
    size_t n_in, n_out;
    char *in = slurp(MODULE_IN, &n_in), *ou = slurp(out, &n_out);
    rch_rapid_targets ti, to;
    memset(&ti, 0, sizeof ti);
    memset(&to, 0, sizeof to);
    rch_diag d;
    assert_int_equal(rch_rapid_scan(&ti, in, n_in, "in", &d), 0);
    assert_int_equal(rch_rapid_scan(&to, ou, n_out, "out", &d), 0);
    /* the forms: 6 jointtarget declarations (two on a line, one over four
     * lines with a comment inside, an array of two), 5 robtarget ones (one
     * over four lines, an array of two), 2 inline MoveAbsJ, a jointtarget
     * assignment, 3 inline robtargets (MoveL, MoveC's two), a robtarget
     * assignment; the comment, the string and the num table are no target */
    assert_int_equal(ti.n, 18);
    assert_int_equal(to.n, 18);
    unsigned n_kind[3] = {0}, n_ctx[4] = {0};
    for (size_t k = 0; k < ti.n; ++k) {
        n_kind[ti.t[k].kind]++;
        n_ctx[ti.t[k].context]++;
        assert_string_equal(ti.t[k].error, "");
    }
    assert_int_equal(n_kind[RCH_RAPID_JOINTTARGET], 9);
    assert_int_equal(n_kind[RCH_RAPID_ROBTARGET], 9);
    assert_int_equal(n_ctx[RCH_RAPID_DECLARATION], 11);
    assert_int_equal(n_ctx[RCH_RAPID_ASSIGNMENT], 2);
    assert_int_equal(n_ctx[RCH_RAPID_INLINE], 5);
    /* every byte outside the numbers: the texts without their numbers agree */
    size_t ai = 0, ao = 0;
    for (size_t k = 0; k < ti.n; ++k)
        for (unsigned j = 0; j < ti.t[k].n; ++j) {
            const size_t li = ti.t[k].num_off[j] - ai, lo = to.t[k].num_off[j] - ao;
            assert_int_equal(li, lo);
            assert_memory_equal(in + ai, ou + ao, li);
            ai = ti.t[k].num_off[j] + ti.t[k].num_len[j];
            ao = to.t[k].num_off[j] + to.t[k].num_len[j];
        }
    assert_int_equal(n_in - ai, n_out - ao);
    assert_memory_equal(in + ai, ou + ao, n_in - ai);

    /* the stream rcal compensate runs (full pose, flange), fed the same joints in the same order */
    rc_model det, nom_pt;
    rch_model_unc unc;
    int v1;
    char held[256];
    rch_comp_determined(&det, &unc, &v1, held, sizeof held, &robot, &robot.nominal);
    rch_comp_point_model(&det, &det, NULL);
    rch_comp_point_model(&nom_pt, &robot.nominal, NULL);
    rc_comp_config cfg;
    memset(&cfg, 0, sizeof cfg);
    static rc_comp_stream s;
    assert_int_equal(rc_comp_stream_init(&s, &det, &nom_pt, &cfg), RC_OK);
    double worst_jt = 0;
    worst w = {0, 0, 0, 0};
    for (size_t k = 0; k < ti.n; ++k) {
        const rch_rapid_target *a = &ti.t[k], *b = &to.t[k];
        assert_int_equal(a->kind, b->kind);
        rc_real q[RC_NJ], qc[RC_NJ];
        double qd[RC_NJ];
        char why[256];
        if (a->kind == RCH_RAPID_JOINTTARGET) {
            for (unsigned j = 0; j < RC_NJ; ++j)
                q[j] = (rc_real)(a->val[j] * DEG);
        } else {
            int cf[4] = {(int)a->val[7], (int)a->val[8], (int)a->val[9], (int)a->val[10]};
            assert_int_equal(rch_ik_solve(qd, &robot.nominal, &a->val[0], &a->val[3], cf, NULL, why, sizeof why), 0);
            for (unsigned j = 0; j < RC_NJ; ++j)
                q[j] = (rc_real)qd[j];
        }
        rc_comp_result res;
        assert_int_equal(rc_comp_stream_step(&s, qc, &res, q), RC_OK);
        if (a->kind == RCH_RAPID_JOINTTARGET) {
            for (unsigned j = 0; j < RC_NJ; ++j)
                worst_jt = fmax(worst_jt, fabs(b->val[j] - (double)qc[j] / DEG));
            printf("line %3u %-11s %-9s before [%g,%g,%g,%g,%g,%g] after [%.4f,%.4f,%.4f,%.4f,%.4f,%.4f]\n",
                   a->line, rch_rapid_kind_name(a->kind), a->name[0] ? a->name : "(inline)", a->val[0], a->val[1],
                   a->val[2], a->val[3], a->val[4], a->val[5], b->val[0], b->val[1], b->val[2], b->val[3], b->val[4],
                   b->val[5]);
            continue;
        }
        check_robtarget(&w, a, b, qc, &det, res.exit);
    }
    printf("every form: jointtargets within %.2g deg of the stream, robtargets within %.2g mm and 1-|q.q'| %.2g of "
           "FK_nom(stream(IK_nom)); the real robot lands within %.4f mm and %.2g rad\n",
           worst_jt, w.rt_mm, w.rt_rot, w.land_mm, w.land_rot);
    assert_true(worst_jt <= 0.5e-4 + 1e-9);   /* %.4f */
    assert_true(w.rt_mm <= 0.5e-4 + 1e-9); /* %.4f */
    assert_true(w.rt_rot < 1e-12);
    assert_true(w.land_mm < 2e-3);
    assert_true(w.land_rot < 1e-5);
    rch_rapid_free(&ti);
    rch_rapid_free(&to);
    free(in);
    free(ou);
}

/* Targets that cannot be corrected: each named, nothing written, exit 1. */
static void test_refused(void **state)
{
    (void)state;
    char out[128], err[128], cmd[640];
    snprintf(out, sizeof out, "%s/bad_comp.mod", dir);
    snprintf(err, sizeof err, "%s/bad.err", dir);
    snprintf(cmd, sizeof cmd, "'%s' compensate --model '%s' --in '%s' --out '%s' 2> '%s'", RCAL, model_path,
             MODULE_BAD, out, err);
    assert_int_equal(run(cmd), 1);
    assert_int_equal(access(out, F_OK), -1); /* nothing written */
    size_t n;
    char *msg = slurp(err, &n);
    static const char *const want[] = {
        "bad_targets.mod:3:25: error: robtarget pFar (declaration) cannot be corrected: out of reach",
        "bad_targets.mod:4:28: error: jointtarget jName (declaration) cannot be corrected: axis 3 (line 4, column 36): "
        "'q3' is not a literal number",
        "bad_targets.mod:5:29: error: jointtarget jShort (declaration) cannot be corrected: a jointtarget is "
        "[[6 robot axes],[6 external axes]]; this aggregate is [[5],[6]]",
        "bad_targets.mod:6:26: error: robtarget pConf (declaration) cannot be corrected: the solution with cfx = 0 "
        "has axis 1 outside the quadrant cf1 = 2 (axis 1 at 10.0000 deg: cf1 = 0); solutions exist with "
        "[cf1,cf4,cf6,cfx] = [0,0,0,0], [0,-2,-2,1], [0,0,-4,0], [0,-2,2,1] (write one of them as the robtarget's "
        "confdata)", /* axis 6 spans +-400 deg: 60 deg is also -300 (cf6 = -4), -120 also 240 (cf6 = 2) */
        "bad_targets.mod:7:29: error: jointtarget jLimit (declaration) cannot be corrected: q3 = 100 deg is outside",
        "bad_targets.mod:8:26: error: robtarget pWobj (declaration) cannot be corrected: used in work object wobjTable "
        "(line 11)",
        "bad_targets.mod:12:11: error: robtarget (inline) cannot be corrected: used with tool tPen (line 12)",
        "bad_targets.mod:10:15: error: jointtarget jUnknown (assignment) cannot be corrected: 'jUnknown' has the form "
        "of a jointtarget but is not declared in this module",
        "bad_targets.mod:14:26: error: robtarget pSing (declaration) cannot be corrected: singular: the wrist centre "
        "is on axis 1 (shoulder singularity)",
        "rcal compensate: " RCAL_SOURCE_DIR "/tests/tools/host/comp/data/bad_targets.mod: 9 targets cannot be corrected (each "
        "named above with its line, column and reason); nothing written",
    };
    for (size_t k = 0; k < sizeof want / sizeof want[0]; ++k)
        if (!strstr(msg, want[k]))
            fail_msg("expected '%s' in:\n%s", want[k], msg);
    free(msg);
}

/* A confdata with no solution (the user's report: cf6 = 0 where axis 6 is
 * at -8 deg): the one error is printed once and names the confdata that
 * exist; the module with the first of them is then corrected. */
static void test_refused_names_confdata(void **state)
{
    (void)state;
    char in[128], out[128], err[128], cmd[768];
    snprintf(in, sizeof in, "%s/conf.mod", dir);
    snprintf(out, sizeof out, "%s/conf_comp.mod", dir);
    snprintf(err, sizeof err, "%s/conf.err", dir);
    static const char mod[] = "MODULE m\n  PROC main()\n    MoveL [[350,-50,450],[0,0,1,0],[%s],"
                              "[9E9,9E9,9E9,9E9,9E9,9E9]], v100, fine, tool0;\n  ENDPROC\nENDMODULE\n";
    FILE *f = fopen(in, "w");
    assert_non_null(f);
    fprintf(f, mod, "-1,0,0,0");
    fclose(f);
    snprintf(cmd, sizeof cmd, "'%s' compensate --model '%s' --in '%s' --out '%s' 2> '%s'", RCAL, model_path, in, out,
             err);
    assert_int_equal(run(cmd), 1);
    assert_int_equal(access(out, F_OK), -1);
    size_t n;
    char *msg = slurp(err, &n);
    const char *want = "conf.mod:3:11: error: robtarget (inline) cannot be corrected: the solution with cfx = 0 has "
                       "axis 6 outside the quadrant cf6 = 0 (axis 6 at -8.1301 deg: cf6 = -1); solutions exist with "
                       "[cf1,cf4,cf6,cfx] = [-1,0,-1,0], [-1,0,-5,0], [-1,0,3,0] (write";
    const char *at = strstr(msg, want);
    if (!at)
        fail_msg("expected '%s' in:\n%s", want, msg);
    if (strstr(at + strlen(want), "outside the quadrant"))
        fail_msg("the reason is printed more than once:\n%s", msg);
    if (!strstr(msg, "conf.mod: 1 target cannot be corrected (each named above with its line, column and reason); "
                     "nothing written"))
        fail_msg("no closing line in:\n%s", msg);
    free(msg);
    f = fopen(in, "w");
    assert_non_null(f);
    fprintf(f, mod, "-1,0,-1,0");
    fclose(f);
    assert_int_equal(run(cmd), 0);
    assert_int_equal(access(out, F_OK), 0);
    /* the whole turns of axis 6 it names are accepted too */
    static const char *const turned[] = {"-1,0,-5,0", "-1,0,3,0"}, *const kept[] = {",-5,0],[9E9", ",3,0],[9E9"};
    for (size_t k = 0; k < 2; ++k) {
        assert_int_equal(remove(out), 0);
        f = fopen(in, "w");
        assert_non_null(f);
        fprintf(f, mod, turned[k]);
        fclose(f);
        assert_int_equal(run(cmd), 0);
        char *w = slurp(out, &n);
        /* axis 4 is near 0 here: the corrected joints' cf4 may differ,
         * the turn of axis 6 may not */
        if (!strstr(w, kept[k]))
            fail_msg("confdata [%s]: axis 6's turn not kept in:\n%s", turned[k], w);
        free(w);
    }
}

/* A tool the module declares: its tooldata is used (no --tool needed), the
 * robtarget is that TCP's pose, and the real robot's TCP lands on it; a
 * --tool with the same TCP gives the same module. */
static void test_declared_tool(void **state)
{
    (void)state;
    char in[128], out[128], out2[128], cmd[768];
    snprintf(in, sizeof in, "%s/pen.mod", dir);
    snprintf(out, sizeof out, "%s/pen_comp.mod", dir);
    snprintf(out2, sizeof out2, "%s/pen_comp2.mod", dir);
    FILE *f = fopen(in, "w");
    assert_non_null(f);
    fputs("MODULE m\n  PERS tooldata tPen:=[TRUE,[[10,-5,150],[1,0,0,0]],[0.5,[0,0,50],[1,0,0,0],0,0,0]];\n"
          "  PROC main()\n    MoveL [[438.426,100.804,511.163],[0.174033,0.432048,0.808673,0.359297],[0,0,0,0],"
          "[9E9,9E9,9E9,9E9,9E9,9E9]], v100, fine, tPen;\n  ENDPROC\nENDMODULE\n",
          f);
    fclose(f);
    snprintf(cmd, sizeof cmd, "'%s' compensate --model '%s' --full-pose --in '%s' --out '%s'", RCAL, model_path, in,
             out);
    assert_int_equal(run(cmd), 0);
    snprintf(cmd, sizeof cmd, "'%s' compensate --model '%s' --full-pose --tool=-10,5,150 --in '%s' --out '%s'", RCAL,
             model_path, in, out2);
    assert_int_equal(run(cmd), 0);
    size_t n, n2;
    char *t2 = slurp(out2, &n2);
    char *txt = slurp(out, &n);
    rch_rapid_targets to;
    memset(&to, 0, sizeof to);
    rch_diag d;
    assert_int_equal(rch_rapid_scan(&to, txt, n, "out", &d), 0);
    assert_int_equal(to.n, 1);
    const rch_rapid_target *b = &to.t[0];
    const double tool[3] = {-10, 5, 150}, want[3] = {438.426, 100.804, 511.163};
    int cf[4] = {(int)b->val[7], (int)b->val[8], (int)b->val[9], (int)b->val[10]};
    double q[RC_NJ], p[3];
    char why[256];
    assert_int_equal(rch_ik_solve(q, &robot.nominal, &b->val[0], &b->val[3], cf, tool, why, sizeof why), 0);
    rc_model det, det_tcp;
    rch_model_unc unc;
    int v1;
    char held[256];
    rch_comp_determined(&det, &unc, &v1, held, sizeof held, &robot, &robot.nominal);
    rch_comp_point_model(&det_tcp, &det, tool);
    rc_fk(p, NULL, &det_tcp, q);
    const double e = sqrt((p[0] - want[0]) * (p[0] - want[0]) + (p[1] - want[1]) * (p[1] - want[1]) +
                          (p[2] - want[2]) * (p[2] - want[2]));
    printf("declared tool: the real TCP at the controller's IK of the written robtarget is %.5f mm from the "
           "intended point (written trans [%.4f,%.4f,%.4f])\n", e, b->val[0], b->val[1], b->val[2]);
    assert_true(e < 2e-3);
    assert_true(fabs(b->val[0] - want[0]) > 0.01); /* it was corrected */
    assert_int_equal(n, n2);
    assert_memory_equal(txt, t2, n);
    rch_rapid_free(&to);
    free(txt);
    free(t2);
}

/* Issue 33: the test's own rigid-body kinematics (quaternions w first). */
static void q_mul(double o[4], const double a[4], const double b[4])
{
    const double r[4] = {a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3],
                         a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
                         a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1],
                         a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0]};
    memcpy(o, r, sizeof r);
}

static void q_rot(double o[3], const double q[4], const double v[3])
{
    const double p[4] = {0, v[0], v[1], v[2]}, c[4] = {q[0], -q[1], -q[2], -q[3]};
    double t[4];
    q_mul(t, q, p);
    q_mul(t, t, c);
    memcpy(o, t + 1, 3 * sizeof o[0]);
}

static void q_unit(double q[4])
{
    const double n = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    for (int i = 0; i < 4; ++i)
        q[i] /= n;
}

/* (op, oq) = (ap, aq) (bp, bq) */
static void f_mul(double op[3], double oq[4], const double ap[3], const double aq[4], const double bp[3],
                  const double bq[4])
{
    double r[3], q[4];
    q_rot(r, aq, bp);
    q_mul(q, aq, bq);
    for (int i = 0; i < 3; ++i)
        op[i] = ap[i] + r[i];
    memcpy(oq, q, sizeof q);
}

static void f_inv(double op[3], double oq[4], const double ap[3], const double aq[4])
{
    const double c[4] = {aq[0], -aq[1], -aq[2], -aq[3]};
    double r[3];
    q_rot(r, c, ap);
    for (int i = 0; i < 3; ++i)
        op[i] = -r[i];
    memcpy(oq, c, sizeof c);
}

/* the fixture's tool tGrip (tframe) and work object wTable (uframe oframe) */
typedef struct {
    double Fp[3], Fq[4], Wp[3], Wq[4];
} frames;

static void fixture_frames(frames *f, int with_wobj)
{
    const double Fp[3] = {12, -8, 160}, Up[3] = {350, -120, 80}, Op[3] = {20, 10, 5};
    double Fq[4] = {0.965926, 0, 0.258819, 0}, Uq[4] = {0.92388, 0, 0, 0.382683}, Oq[4] = {0.996195, 0.087156, 0, 0};
    q_unit(Fq);
    q_unit(Uq);
    q_unit(Oq);
    memcpy(f->Fp, Fp, sizeof Fp);
    memcpy(f->Fq, Fq, sizeof Fq);
    f_mul(f->Wp, f->Wq, Up, Uq, Op, Oq);
    if (!with_wobj) {
        const double z[3] = {0, 0, 0}, one[4] = {1, 0, 0, 0};
        memcpy(f->Wp, z, sizeof z);
        memcpy(f->Wq, one, sizeof one);
    }
}

/* What the controller does with the written robtarget b (tool F, work
 * object W): its flange pose W b F^-1, the nominal IK with b's confdata; the
 * real robot (det) there puts its TCP at FK_det tool0 F. Returns the
 * distance (mm) of that TCP from W a (a: the robtarget as taught), *ang its
 * orientation's angle (rad). */
static double landing(double *ang, const rch_rapid_target *a, const rch_rapid_target *b, const frames *f,
                      const rc_model *det)
{
    double Tq[4] = {b->val[3], b->val[4], b->val[5], b->val[6]}, Xp[3], Xq[4], Fip[3], Fiq[4];
    q_unit(Tq);
    f_mul(Xp, Xq, f->Wp, f->Wq, b->val, Tq);
    f_inv(Fip, Fiq, f->Fp, f->Fq);
    f_mul(Xp, Xq, Xp, Xq, Fip, Fiq);
    const int cf[4] = {(int)b->val[7], (int)b->val[8], (int)b->val[9], (int)b->val[10]};
    double q[RC_NJ], pr[3], Rr[9];
    char why[256];
    if (rch_ik_solve(q, &robot.nominal, Xp, Xq, cf, NULL, why, sizeof why) != 0)
        fail_msg("line %u: the controller's IK of the written robtarget: %s", b->line, why);
    rc_fk(pr, Rr, det, q);
    /* the real TCP: flange, turned 180 deg about z (tool0), then F */
    double tcp[3], Fr[3] = {-f->Fp[0], -f->Fp[1], f->Fp[2]}; /* F's origin in the flange frame */
    for (int i = 0; i < 3; ++i)
        tcp[i] = pr[i] + Rr[3 * i] * Fr[0] + Rr[3 * i + 1] * Fr[1] + Rr[3 * i + 2] * Fr[2];
    double Aq[4] = {a->val[3], a->val[4], a->val[5], a->val[6]}, Ip[3], Iq[4];
    q_unit(Aq);
    f_mul(Ip, Iq, f->Wp, f->Wq, a->val, Aq); /* intended TCP pose in the base frame */
    /* the real tool frame's axes against the intended ones */
    double ang_max = 0;
    for (int k = 0; k < 3; ++k) {
        double e[3] = {0, 0, 0}, ai[3], at[3], a0[3];
        e[k] = 1;
        q_rot(ai, Iq, e);  /* intended axis k */
        q_rot(a0, f->Fq, e); /* the tool's axis k in tool0 */
        const double t0[3] = {-a0[0], -a0[1], a0[2]}; /* in the flange frame */
        for (int i = 0; i < 3; ++i)
            at[i] = Rr[3 * i] * t0[0] + Rr[3 * i + 1] * t0[1] + Rr[3 * i + 2] * t0[2];
        const double dot = ai[0] * at[0] + ai[1] * at[1] + ai[2] * at[2];
        ang_max = fmax(ang_max, acos(fmin(1.0, fmax(-1.0, dot))));
    }
    *ang = ang_max;
    return sqrt((tcp[0] - Ip[0]) * (tcp[0] - Ip[0]) + (tcp[1] - Ip[1]) * (tcp[1] - Ip[1]) +
                (tcp[2] - Ip[2]) * (tcp[2] - Ip[2]));
}

/* Every byte of in outside its targets' numbers is in out. */
static void same_outside_numbers(const char *in, size_t n_in, const rch_rapid_targets *ti, const char *ou,
                                 size_t n_out, const rch_rapid_targets *to)
{
    size_t ai = 0, ao = 0;
    assert_int_equal(ti->n, to->n);
    for (size_t k = 0; k < ti->n; ++k)
        for (unsigned j = 0; j < ti->t[k].n; ++j) {
            const size_t li = ti->t[k].num_off[j] - ai, lo = to->t[k].num_off[j] - ao;
            assert_int_equal(li, lo);
            assert_memory_equal(in + ai, ou + ao, li);
            ai = ti->t[k].num_off[j] + ti->t[k].num_len[j];
            ao = to->t[k].num_off[j] + to->t[k].num_len[j];
        }
    assert_int_equal(n_in - ai, n_out - ao);
    assert_memory_equal(in + ai, ou + ao, n_in - ai);
}

/* Compensate path (extra options opts) to out; its targets before and after. */
static void comp_module(char **in, size_t *n_in, rch_rapid_targets *ti, char **ou, size_t *n_out,
                        rch_rapid_targets *to, const char *path, const char *out, const char *opts)
{
    char cmd[1024];
    snprintf(cmd, sizeof cmd, "'%s' compensate --model '%s' --full-pose %s --in '%s' --out '%s'", RCAL, model_path,
             opts, path, out);
    assert_int_equal(run(cmd), 0);
    *in = slurp(path, n_in);
    *ou = slurp(out, n_out);
    memset(ti, 0, sizeof *ti);
    memset(to, 0, sizeof *to);
    rch_diag d;
    assert_int_equal(rch_rapid_scan(ti, *in, *n_in, "in", &d), 0);
    assert_int_equal(rch_rapid_scan(to, *ou, *n_out, "out", &d), 0);
    same_outside_numbers(*in, *n_in, ti, *ou, *n_out, to);
}

/* Issue 33: robtargets used by every motion instruction form (MoveL/J/C,
 * the DO/AO/GO/Sync variants, TriggL/J/C, SearchL/C, ArcL/C, optional
 * arguments between, Offs/RelTool, an assignment, a user PROC besides a
 * MoveL, CalcJointT, a compact IF) with a declared tool whose frame is
 * turned and a declared work object: each corrected for that tool and work
 * object, the real TCP landing on the taught pose; the same module read as
 * tool0/wobj0 (what rcal did before) misses by a measured amount. */
static void test_tools_wobjs(void **state)
{
    (void)state;
    rc_model det;
    rch_model_unc unc;
    int v1;
    char held[256], out[128], old_in[128], old_out[128], cmd[1024];
    rch_comp_determined(&det, &unc, &v1, held, sizeof held, &robot, &robot.nominal);
    const char *path = RCAL_SOURCE_DIR "/tests/tools/host/comp/data/tools_wobjs.mod";
    snprintf(out, sizeof out, "%s/tools_wobjs_comp.mod", dir);
    char *in, *ou;
    size_t n_in, n_out;
    rch_rapid_targets ti, to;
    comp_module(&in, &n_in, &ti, &ou, &n_out, &to, path, out, "");
    assert_int_equal(ti.n, 30);
    /* the same module with the tool-only uses (pTool1, pTool2) read as tool0 (what rcal did for an
     * instruction it did not read; the work object ones are out of reach read so) */
    snprintf(old_in, sizeof old_in, "%s/tools_wobjs_as_tool0.mod", dir);
    snprintf(old_out, sizeof old_out, "%s/tools_wobjs_as_tool0_comp.mod", dir);
    snprintf(cmd, sizeof cmd, "sed -e 's/fine, tGrip;/fine, tool0;/' '%s' > '%s'", path, old_in);
    assert_int_equal(run(cmd), 0);
    char *oin, *oou;
    size_t n_oin, n_oou;
    rch_rapid_targets oti, oto;
    comp_module(&oin, &n_oin, &oti, &oou, &n_oou, &oto, old_in, old_out, "");
    assert_int_equal(oti.n, 30);
    double worst_mm = 0, worst_rad = 0, old_min = INFINITY, old_max = 0;
    for (size_t k = 0; k < ti.n; ++k) {
        const rch_rapid_target *a = &ti.t[k], *b = &to.t[k];
        assert_int_equal(a->kind, RCH_RAPID_ROBTARGET);
        assert_string_equal(a->tool, "tGrip");
        frames f;
        fixture_frames(&f, strncmp(a->name, "pTool", 5) != 0);
        double ang, ang_old;
        const int tool_only = strncmp(a->name, "pTool", 5) == 0;
        const double e = landing(&ang, a, b, &f, &det), e_old = tool_only ? landing(&ang_old, a, &oto.t[k], &f, &det) : NAN;
        printf("%-8s %-9s (line %3u) the real TCP lands %.5f mm, %.2g rad from the taught pose (read as "
               "tool0/wobj0: %.4f mm)\n", a->name, a->use_instr, a->use_line, e, ang, e_old);
        worst_mm = fmax(worst_mm, e);
        worst_rad = fmax(worst_rad, ang);
        if (tool_only) {
            old_min = fmin(old_min, e_old);
            old_max = fmax(old_max, e_old);
        }
    }
    printf("tools and work objects: %zu robtargets land within %.5f mm and %.2g rad; read as tool0/wobj0 the "
           "tool-only ones missed by %.4f..%.4f mm\n", ti.n, worst_mm, worst_rad, old_min, old_max);
    assert_true(worst_mm < 2e-3);
    assert_true(worst_rad < 1e-5);
    assert_true(old_min > 0.02);
    rch_rapid_free(&ti);
    rch_rapid_free(&to);
    rch_rapid_free(&oti);
    rch_rapid_free(&oto);
    free(in);
    free(ou);
    free(oin);
    free(oou);
}

/* A run that must fail: exit 1, no output, each expected line in stderr. */
static void expect_refused(const char *fixture, const char *const *want, size_t n_want)
{
    char out[128], err[128], cmd[1024];
    snprintf(out, sizeof out, "%s/refused_comp.mod", dir);
    snprintf(err, sizeof err, "%s/refused.err", dir);
    snprintf(cmd, sizeof cmd, "'%s' compensate --model '%s' --in '%s/tests/tools/host/comp/data/%s' --out '%s' 2> '%s'", RCAL,
             model_path, RCAL_SOURCE_DIR, fixture, out, err);
    assert_int_equal(run(cmd), 1);
    assert_int_equal(access(out, F_OK), -1); /* nothing written */
    size_t n;
    char *msg = slurp(err, &n);
    for (size_t k = 0; k < n_want; ++k)
        if (!strstr(msg, want[k]))
            fail_msg("expected '%s' in:\n%s", want[k], msg);
    free(msg);
}

/* Issue 33: uses rcal cannot read, each refused with line, column, reason. */
static void test_refused_uses(void **state)
{
    (void)state;
    static const char *const want[] = {
        "refuse_uses.mod:6:26: error: robtarget pProc (declaration) cannot be corrected: passed to Draw (line 14), "
        "which is not a motion instruction rcal reads (a user PROC or another instruction): the tool and work object "
        "it is used with cannot be told",
        "refuse_uses.mod:7:26: error: robtarget pLate (declaration) cannot be corrected: passed to a late-bound "
        "procedure call (line 15)",
        "refuse_uses.mod:8:25: error: robtarget pTwo (declaration) cannot be corrected: used with tGrip (MoveL, line "
        "16) and with tool0 (MoveL, line 17)",
        "refuse_uses.mod:9:26: error: robtarget pConv (declaration) cannot be corrected: used in work object wConv "
        "(line 18), whose user frame moves (ufprog FALSE, ufmec \"CNV1\")",
        "refuse_uses.mod:10:28: error: robtarget pNoWobj (declaration) cannot be corrected: used in work object wElse "
        "(line 19), which this module does not declare with a literal wobjdata",
        "refuse_uses.mod:11:30: error: robtarget pToolExpr (declaration) cannot be corrected: the Tool argument of "
        "MoveL (line 20) is not a tool's name",
        "refuse_uses.mod:12:26: error: robtarget pSpot (declaration) cannot be corrected: passed to SpotL (line 21)",
        "refuse_uses.mod: 7 targets cannot be corrected",
    };
    expect_refused("refuse_uses.mod", want, sizeof want / sizeof want[0]);
}

/* Issue 47: a robtarget whose external axes are in use (a value other than
 * 9E9: a robot on a track) is refused at that value with the reason; 9E9 in
 * any spelling (9E+09, 9.0E9) is unused and corrected. */
static void test_refused_extax(void **state)
{
    (void)state;
    static const char *const want[] = {
        "refuse_extax.mod:3:27: error: robtarget pTrack (declaration) cannot be corrected: external axis eax_a = 1200 "
        "(line 3, column 108): a robtarget with an external axis in use (a track moving the base, a positioner) "
        "cannot be corrected: the model has no track, its corrections assume the base fixed; only 9E9 (unused) is "
        "accepted",
        "refuse_extax.mod:4:28: error: robtarget pSecond (declaration) cannot be corrected: external axis eax_c = "
        "-35.5 (line 4, column 117)",
        "refuse_extax.mod:5:26: error: robtarget pName (declaration) cannot be corrected: external axis eax_b is not "
        "a literal number (line 5, column 108)",
        "refuse_extax.mod: 3 targets cannot be corrected",
    };
    expect_refused("refuse_extax.mod", want, sizeof want / sizeof want[0]);
    char err[128];
    snprintf(err, sizeof err, "%s/refused.err", dir); /* expect_refused's */
    size_t n;
    char *msg = slurp(err, &n);
    assert_null(strstr(msg, "pUnused")); /* 9E+09, 9.0E9: unused, corrected */
    free(msg);
}

/* Issue 33: a robtarget of an ALIAS type is corrected (the real robot lands
 * on it); one inside a RECORD is refused, naming the record and field. */
static void test_record_alias(void **state)
{
    (void)state;
    static const char *const want[] = {
        "record_alias.mod:9:22: error: robtarget st1 (declaration) cannot be corrected: a robtarget inside the RECORD "
        "station (field approach)",
    };
    expect_refused("record_alias.mod", want, 1);
    rc_model det;
    rch_model_unc unc;
    int v1;
    char held[256], out[128];
    rch_comp_determined(&det, &unc, &v1, held, sizeof held, &robot, &robot.nominal);
    snprintf(out, sizeof out, "%s/alias_comp.mod", dir);
    char *in, *ou;
    size_t n_in, n_out;
    rch_rapid_targets ti, to;
    comp_module(&in, &n_in, &ti, &ou, &n_out, &to, RCAL_SOURCE_DIR "/tests/tools/host/comp/data/alias.mod", out, "");
    assert_int_equal(ti.n, 1);
    frames f;
    memset(&f, 0, sizeof f);
    f.Fq[0] = f.Wq[0] = 1;
    double ang;
    const double e = landing(&ang, &ti.t[0], &to.t[0], &f, &det);
    printf("ALIAS robtarget: the real flange lands %.5f mm, %.2g rad from the taught pose\n", e, ang);
    assert_true(e < 2e-3 && ang < 1e-5);
    assert_true(fabs(to.t[0].val[0] - ti.t[0].val[0]) > 1e-3); /* corrected */
    rch_rapid_free(&ti);
    rch_rapid_free(&to);
    free(in);
    free(ou);
}

/* Issue 33: a module without any target is an error (exit 1, nothing written). */
static void test_no_target(void **state)
{
    (void)state;
    static const char *const want[] = {"no_target.mod: no jointtarget or robtarget in this module (declarations, "
                                       "assignments, instruction arguments): nothing to correct; nothing written"};
    expect_refused("no_target.mod", want, 1);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_ik_round_trip),
        cmocka_unit_test(test_every_form),
        cmocka_unit_test(test_refused),
        cmocka_unit_test(test_refused_names_confdata),
        cmocka_unit_test(test_declared_tool),
        cmocka_unit_test(test_tools_wobjs),
        cmocka_unit_test(test_refused_uses),
        cmocka_unit_test(test_refused_extax),
        cmocka_unit_test(test_record_alias),
        cmocka_unit_test(test_no_target),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
