/* SPDX-License-Identifier: MIT */
/* fuzz_rapid.c - the RAPID reader (rch_rapid_scan) and, on each robtarget it
 * finds, the nominal IK with its confdata (rch_ik_solve) on the IRB120.
 * Invariants: a refusal has a message; targets lie inside the text, in
 * order, without overlap, their numbers inside them; a readable target has
 * 6 or 11 finite numbers; the text with every number rewritten ("%.4f", as
 * rcal compensate writes) scans to the same targets; an IK solution is
 * inside the joint limits, has the confdata asked for and reaches the pose. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fuzz_check.h"
#include "rch_ik.h"
#include "rch_rapid.h"

#define DEG (3.14159265358979323846 / 180.0)

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static void check_ik(const rch_rapid_target *t)
{
    static rc_model m;
    static int init;
    if (!init) {
        const double dh[RC_NJ][4] = {{0, 290, -90 * DEG, 0}, {270, 0, 0, -90 * DEG}, {70, 0, -90 * DEG, 0},
                                     {0, 302, 90 * DEG, 0},  {0, 0, -90 * DEG, 0},   {0, 72, 0, 0}};
        const double enc[3] = {0, 0, 0};
        const double lim[RC_NJ] = {165, 110, 110, 160, 120, 400};
        rc_model_init(&m, dh, enc);
        for (unsigned j = 0; j < RC_NJ; ++j) {
            m.q_min_rad[j] = -lim[j] * DEG;
            m.q_max_rad[j] = lim[j] * DEG;
        }
        init = 1;
    }
    int cf[4];
    for (int k = 0; k < 4; ++k) {
        const double v = t->val[7 + k];
        if (!(fabs(v) <= 1000) || v != floor(v))
            return;
        cf[k] = (int)v;
    }
    double q[RC_NJ], p[3], qt[4];
    int c2[4];
    char why[256];
    if (rch_ik_solve(q, &m, &t->val[0], &t->val[3], cf, NULL, why, sizeof why) != 0) {
        FZ_CHECK(why[0] != '\0');
        return;
    }
    for (unsigned j = 0; j < RC_NJ; ++j)
        FZ_CHECK(q[j] >= m.q_min_rad[j] - 1e-9 && q[j] <= m.q_max_rad[j] + 1e-9);
    rch_ik_fk(p, qt, c2, &m, q, NULL);
    FZ_CHECK(c2[3] == cf[3]);
    const double e = fabs(p[0] - t->val[0]) + fabs(p[1] - t->val[1]) + fabs(p[2] - t->val[2]);
    FZ_CHECK(e < 1e-5 * (1.0 + fabs(t->val[0]) + fabs(t->val[1]) + fabs(t->val[2])) * 1e-3 + 1e-6);
    const double n = sqrt(t->val[3] * t->val[3] + t->val[4] * t->val[4] + t->val[5] * t->val[5] + t->val[6] * t->val[6]);
    const double dot = (qt[0] * t->val[3] + qt[1] * t->val[4] + qt[2] * t->val[5] + qt[3] * t->val[6]) / n;
    FZ_CHECK(fabs(dot) > 1.0 - 1e-9);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    rch_rapid_targets ts;
    rch_diag d;
    memset(&ts, 0, sizeof ts);
    memset(&d, 0, sizeof d);
    const char *text = (const char *)data; /* exactly size bytes, no NUL after them */
    if (rch_rapid_scan(&ts, text, size, "fuzz.mod", &d) != 0) {
        FZ_CHECK(d.msg[0] != '\0');
        FZ_CHECK(ts.n == 0 || ts.t != NULL);
        rch_rapid_free(&ts);
        return 0;
    }
    size_t prev_end = 0, n_nums = 0;
    for (size_t i = 0; i < ts.n; ++i) {
        const rch_rapid_target *t = &ts.t[i];
        FZ_CHECK(t->off < t->end && t->end <= size && t->off >= prev_end);
        FZ_CHECK(text[t->off] == '[' && text[t->end - 1] == ']');
        FZ_CHECK(t->line >= 1 && t->col >= 1);
        prev_end = t->end;
        if (t->error[0]) {
            FZ_CHECK(t->n == 0);
            continue;
        }
        FZ_CHECK(t->n == (t->kind == RCH_RAPID_JOINTTARGET ? 6u : 11u));
        size_t at = t->off;
        for (unsigned k = 0; k < t->n; ++k) {
            FZ_CHECK(t->num_off[k] >= at && t->num_off[k] + t->num_len[k] <= t->end && t->num_len[k] > 0);
            FZ_CHECK(isfinite(t->val[k]));
            at = t->num_off[k] + t->num_len[k];
        }
        n_nums += t->n;
        if (t->kind == RCH_RAPID_ROBTARGET)
            check_ik(t);
    }
    /* rewrite every number and scan again: the same targets */
    char *out = malloc(size + 48 * n_nums + 1);
    FZ_CHECK(out != NULL);
    size_t o = 0, at = 0;
    for (size_t i = 0; i < ts.n; ++i)
        for (unsigned k = 0; k < ts.t[i].n; ++k) {
            memcpy(out + o, text + at, ts.t[i].num_off[k] - at);
            o += ts.t[i].num_off[k] - at;
            const double v = ts.t[i].val[k];
            o += (size_t)snprintf(out + o, 48, "%.4f", fabs(v) < 1e30 ? v : 0.0);
            at = ts.t[i].num_off[k] + ts.t[i].num_len[k];
        }
    memcpy(out + o, text + at, size - at);
    o += size - at;
    rch_rapid_targets t2;
    memset(&t2, 0, sizeof t2);
    FZ_CHECK(rch_rapid_scan(&t2, out, o, "fuzz.mod", &d) == 0);
    FZ_CHECK(t2.n == ts.n);
    for (size_t i = 0; i < ts.n; ++i) {
        FZ_CHECK(t2.t[i].kind == ts.t[i].kind && t2.t[i].context == ts.t[i].context);
        FZ_CHECK((t2.t[i].error[0] != '\0') == (ts.t[i].error[0] != '\0'));
    }
    rch_rapid_free(&t2);
    free(out);
    rch_rapid_free(&ts);
    return 0;
}
