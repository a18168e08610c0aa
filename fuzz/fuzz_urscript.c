/* SPDX-License-Identifier: MIT */
/* fuzz_urscript.c - the URScript reader (rch_urs_scan) and, on the first
 * poses it finds, the general IK (rch_ikg_all) on a UR5e.
 * Invariants: a refusal has a message; targets lie inside the text, in
 * order, without overlap, their numbers inside them and in order; a
 * readable target has 6 finite numbers, a pose starts with "p[", a list
 * with "["; get_inverse_kin's qnear is a later qnear target; the text with
 * every number rewritten ("%.9f", as rcal compensate writes) scans to the
 * same targets; every IK solution meets its pose. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fuzz_check.h"
#include "rc_sensor.h"
#include "rch_ikg.h"
#include "rch_urscript.h"

#define DEG (3.14159265358979323846 / 180.0)

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static void check_ik(const rch_urs_target *t)
{
    static rch_ikg ik;
    static int init;
    if (!init) {
        rc_model m;
        const double dh[RC_NJ][4] = {{0, 162.5, 90 * DEG, 0}, {-425, 0, 0, 0},   {-392.2, 0, 0, 0},
                                     {0, 133.3, 90 * DEG, 0}, {0, 99.7, -90 * DEG, 0}, {0, 99.6, 0, 0}};
        const double enc[3] = {0, 0, 0};
        rc_model_init(&m, dh, enc);
        for (unsigned j = 0; j < RC_NJ; ++j) {
            m.q_min_rad[j] = -360 * DEG;
            m.q_max_rad[j] = 360 * DEG;
        }
        FZ_CHECK(rch_ikg_init(&ik, &m, NULL) == RCH_IKG_OK);
        init = 1;
    }
    if (!(fabs(t->val[0]) < 10 && fabs(t->val[1]) < 10 && fabs(t->val[2]) < 10 && fabs(t->val[3]) < 100 &&
          fabs(t->val[4]) < 100 && fabs(t->val[5]) < 100))
        return;
    double p[3], R[9], sol[RCH_IKG_MAX_SOL][RC_NJ];
    for (int k = 0; k < 3; ++k)
        p[k] = t->val[k] * 1000.0;
    rc_rotvec_matrix(R, &t->val[3]);
    const int n = rch_ikg_all(sol, NULL, &ik, p, R);
    FZ_CHECK(n >= 0 && n <= RCH_IKG_MAX_SOL);
    for (int s = 0; s < n; ++s) {
        double p2[3], R2[9];
        rch_ikg_fk(p2, R2, &ik, sol[s]);
        FZ_CHECK(fabs(p2[0] - p[0]) + fabs(p2[1] - p[1]) + fabs(p2[2] - p[2]) < 1e-5);
        double e = 0;
        for (int k = 0; k < 9; ++k)
            e += fabs(R2[k] - R[k]);
        FZ_CHECK(e < 1e-6);
    }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    rch_urs_targets ts;
    rch_diag d;
    memset(&ts, 0, sizeof ts);
    memset(&d, 0, sizeof d);
    const char *text = (const char *)data; /* exactly size bytes, no NUL after them */
    if (rch_urs_scan(&ts, text, size, "fuzz.script", 1, &d) != 0) {
        FZ_CHECK(d.msg[0] != '\0');
        rch_urs_free(&ts);
        return 0;
    }
    size_t prev_end = 0, n_nums = 0;
    unsigned n_ik = 0;
    for (size_t i = 0; i < ts.n; ++i) {
        const rch_urs_target *t = &ts.t[i];
        FZ_CHECK(t->off < t->end && t->end <= size && t->off >= prev_end);
        FZ_CHECK(t->line >= 1 && t->col >= 1);
        FZ_CHECK(t->kind == RCH_URS_POSE ? text[t->off] == 'p' && text[t->off + 1] == '[' : text[t->off] == '[');
        prev_end = t->end;
        if (t->error[0]) {
            FZ_CHECK(t->n == 0);
            continue;
        }
        FZ_CHECK(t->n == 6u && text[t->end - 1] == ']');
        if (t->role == RCH_URS_IK && t->qnear >= 0)
            FZ_CHECK((size_t)t->qnear > i && (size_t)t->qnear < ts.n && ts.t[t->qnear].role == RCH_URS_QNEAR);
        size_t at = t->off;
        for (unsigned k = 0; k < t->n; ++k) {
            FZ_CHECK(t->num_off[k] >= at && t->num_off[k] + t->num_len[k] <= t->end && t->num_len[k] > 0);
            FZ_CHECK(isfinite(t->val[k]));
            at = t->num_off[k] + t->num_len[k];
        }
        n_nums += t->n;
        if (t->kind == RCH_URS_POSE && n_ik < 4) {
            ++n_ik;
            check_ik(t);
        }
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
            o += (size_t)snprintf(out + o, 48, "%.9f", fabs(v) < 1e30 ? v : 0.0);
            at = ts.t[i].num_off[k] + ts.t[i].num_len[k];
        }
    memcpy(out + o, text + at, size - at);
    o += size - at;
    rch_urs_targets t2;
    memset(&t2, 0, sizeof t2);
    FZ_CHECK(rch_urs_scan(&t2, out, o, "fuzz.script", 1, &d) == 0);
    FZ_CHECK(t2.n == ts.n);
    for (size_t i = 0; i < ts.n; ++i) {
        FZ_CHECK(t2.t[i].kind == ts.t[i].kind && t2.t[i].role == ts.t[i].role);
        FZ_CHECK((t2.t[i].error[0] != '\0') == (ts.t[i].error[0] != '\0'));
    }
    rch_urs_free(&t2);
    free(out);
    rch_urs_free(&ts);
    return 0;
}
