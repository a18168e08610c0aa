/* SPDX-License-Identifier: MIT */
/* test_evaluate.c - a model evaluated on data it never saw, and the ISO 9283
 * distance figures from repeated poses, against values computed here from
 * the independent generator (tests/common/rct_indep.h); the length jumps a
 * model was calibrated with, read back from its file and said by rcal
 * evaluate (not applied to new data). */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmocka.h>

#include "rch_evaluate.h"
#include "rch_robot.h"
#include "rct_indep.h"

static void test_iso9283_and_refit(void **state)
{
    (void)state;
    rch_robot nom;
    rch_diag d;
    assert_int_equal(rch_robot_load(&nom, RCAL_SOURCE_DIR "/data/irb120.json", &d), 0);
    rct_rng g = {99};
    double dh[6][4], e[3] = {260.0, -470.0, 15.0};
    for (int i = 0; i < 6; ++i)
        for (int k = 0; k < 4; ++k)
            dh[i][k] = nom.model.x[4 * i + k];
    /* 40 poses, each read 5 times with noise; true lengths from our FK */
    enum { P = 40, R = 5 };
    rc_sample s[P * R];
    memset(s, 0, sizeof s);
    double ad_max = 0, rd_max = 0, ad_sum = 0, rd_sum = 0;
    for (int p = 0; p < P; ++p) {
        double q[6], pos[3];
        for (int j = 0; j < 6; ++j)
            q[j] = nom.model.q_min_rad[j] * 0.7 + (nom.model.q_max_rad[j] - nom.model.q_min_rad[j]) * 0.7 * rct_u01(&g);
        rct_flange(pos, dh, q);
        double truth = rct_dist(pos, e), bias = 0.02 * rct_gauss(&g), mean = 0, ss = 0;
        for (int r = 0; r < R; ++r) {
            rc_sample *x = &s[p * R + r];
            memcpy(x->q_rad, q, sizeof q);
            x->value = truth + bias + 0.01 * rct_gauss(&g);
            x->t = 0;
            x->group = 0;
            x->outlet = 0;
            mean += x->value;
        }
        mean /= R;
        for (int r = 0; r < R; ++r)
            ss += (s[p * R + r].value - mean) * (s[p * R + r].value - mean);
        double ad = fabs(mean - truth), rd = 3.0 * sqrt(ss / (R - 1));
        ad_max = fmax(ad_max, ad);
        rd_max = fmax(rd_max, rd);
        ad_sum += ad;
        rd_sum += rd;
    }
    rc_model m = nom.model;
    memcpy(&m.x[RC_P_ENC], e, sizeof e);
    rch_evaluate_result r;
    char err[200];
    assert_int_equal(rch_evaluate(&r, &m, s, P * R, NULL, NULL, err, sizeof err), 0);
    assert_int_equal(r.n_poses, P);
    assert_int_equal(r.n_repeated, P);
    assert_true(fabs(r.ad_max_mm - ad_max) < 1e-9 && fabs(r.rd_max_mm - rd_max) < 1e-9);
    assert_true(fabs(r.ad_mean_mm - ad_sum / P) < 1e-9 && fabs(r.rd_mean_mm - rd_sum / P) < 1e-9);
    assert_int_equal(r.encoder_refitted, 0);
    /* a model whose outlet is 5 mm off: refitting the outlet alone recovers it */
    rc_model off = m;
    off.x[RC_P_ENC] += 5.0;
    rch_evaluate_result r2;
    assert_int_equal(rch_evaluate(&r2, &off, s, P * R, NULL, NULL, err, sizeof err), 0);
    assert_true(r2.m.rmse_mm > 1.0);
    rc_solve_work *w = malloc(sizeof *w);
    rch_evaluate_config cfg = {1, 0};
    assert_int_equal(rch_evaluate(&r2, &off, s, P * R, &cfg, w, err, sizeof err), 0);
    free(w);
    assert_int_equal(r2.encoder_refitted, 1);
    assert_true(fabs(r2.encoder_shift_mm - 5.0) < 0.1);
    assert_true(r2.m.rmse_mm < 0.05);
    print_message("ISO 9283 on 40 poses x 5 readings: AD mean %.4f max %.4f mm, RD mean %.4f max %.4f mm; "
                  "outlet 5 mm off: RMSE %.3f mm after refitting it alone (moved %.3f mm)\n",
                  r.ad_mean_mm, r.ad_max_mm, r.rd_mean_mm, r.rd_max_mm, r2.m.rmse_mm, r2.encoder_shift_mm);
}

#define RCAL RCAL_BINARY_DIR "/tools/rcal"

static char *run_out(const char *cmd)
{
    FILE *p = popen(cmd, "r");
    assert_non_null(p);
    char *b = calloc(1, 1 << 16);
    assert_non_null(b);
    const size_t n = fread(b, 1, (1 << 16) - 1, p);
    b[n] = '\0';
    const int st = pclose(p);
    if (!(WIFEXITED(st) && WEXITSTATUS(st) == 0))
        fail_msg("%s: exit %d\n%s", cmd, st, b);
    return b;
}

/* The demo file with every length from data row 300 on 5 mm longer: the
 * default calibration fits the jump, the model file keeps it, and rcal
 * evaluate says it is not applied, naming the calibration file as such. */
static void test_jumps_said(void **state)
{
    (void)state;
    char dir[] = "/tmp/rcal_eval_XXXXXX", jump[64], model[64], cmd[512];
    assert_non_null(mkdtemp(dir));
    snprintf(jump, sizeof jump, "%s/jump.csv", dir);
    snprintf(model, sizeof model, "%s/m.json", dir);
    FILE *in = fopen(RCAL_SOURCE_DIR "/data/sim_irb120.csv", "r"), *out = fopen(jump, "w");
    assert_true(in && out);
    char line[512];
    for (int k = 0; fgets(line, sizeof line, in); ++k) {
        char *last = strrchr(line, ',');
        if (k > 300 && last)
            snprintf(last, sizeof line - (size_t)(last - line), ",%.4f\n", atof(last + 1) + 5.0);
        fputs(line, out);
    }
    fclose(in);
    fclose(out);
    snprintf(cmd, sizeof cmd, "'%s' calibrate --data '%s' --out '%s'", RCAL, jump, model);
    free(run_out(cmd));
    rch_robot m;
    rch_diag d;
    assert_int_equal(rch_robot_load(&m, model, &d), 0);
    assert_int_equal(m.n_cal_jumps, 1);
    assert_true(fabs(m.cal_jump_max_mm - 5.0) < 0.05);
    assert_string_equal(m.cal_data, jump);
    static const char note[] = "  note: the model was calibrated with 1 length jump fitted as nuisance of that "
                               "acquisition (largest 4.99";
    snprintf(cmd, sizeof cmd, "'%s' evaluate --model '%s' --data '%s'", RCAL, model, jump);
    char *text = run_out(cmd);
    if (!strstr(text, note) || !strstr(text, "not applied to new data: this is the calibration file, so the RMSE "
                                              "above includes its jumps"))
        fail_msg("%s", text);
    free(text);
    snprintf(cmd, sizeof cmd, "'%s' evaluate --model '%s' --data '%s'", RCAL, model,
             RCAL_SOURCE_DIR "/data/sim_irb120.csv");
    text = run_out(cmd);
    if (!strstr(text, note) || !strstr(text, "on another file the RMSE holds that file's own jumps"))
        fail_msg("%s", text);
    free(text);
    snprintf(cmd, sizeof cmd, "'%s' evaluate --model '%s' --data '%s' --json", RCAL, model, jump);
    text = run_out(cmd);
    const char *cj = strstr(text, "\"calibration_jumps\"");
    if (!cj || !strstr(cj, "\"n\": 1") || !strstr(cj, "\"applied\": false") ||
        !strstr(cj, "\"data_is_calibration_file\": true") || !strstr(cj, "\"max_mm\": 4.99"))
        fail_msg("%s", text);
    free(text);
    /* a model without jumps says nothing of them */
    snprintf(cmd, sizeof cmd, "'%s' evaluate --model '%s' --data '%s'", RCAL, RCAL_SOURCE_DIR "/data/irb120.json",
             jump);
    text = run_out(cmd);
    assert_null(strstr(text, "note:"));
    free(text);
    /* the member read back is checked */
    static const char bad[] = "{\"format\": \"rcal-model/1\", \"name\": \"x\", \"dh\": [{\"a_mm\": 0, \"d_mm\": 290, "
        "\"alpha_deg\": -90, \"theta_deg\": 0}, {\"a_mm\": 270, \"d_mm\": 0, \"alpha_deg\": 0, \"theta_deg\": -90}, "
        "{\"a_mm\": 70, \"d_mm\": 0, \"alpha_deg\": -90, \"theta_deg\": 0}, {\"a_mm\": 0, \"d_mm\": 302, "
        "\"alpha_deg\": 90, \"theta_deg\": 0}, {\"a_mm\": 0, \"d_mm\": 0, \"alpha_deg\": -90, \"theta_deg\": 0}, "
        "{\"a_mm\": 0, \"d_mm\": 72, \"alpha_deg\": 0, \"theta_deg\": 0}],\n\"calibration\": {\"length_jumps\": "
        "[{\"size_mm\": \"5\"}]}}";
    assert_int_equal(rch_robot_parse(&m, bad, strlen(bad), "bad.json", &d), -1);
    char msg[1024];
    rch_diag_str(&d, msg, sizeof msg);
    if (!strstr(msg, "bad.json:2:34: \"calibration\": length jump 1 needs \"size_mm\", a finite number"))
        fail_msg("%s", msg);
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    assert_int_equal(system(cmd), 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_iso9283_and_refit), cmocka_unit_test(test_jumps_said)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
