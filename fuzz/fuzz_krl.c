/* SPDX-License-Identifier: MIT */
/* fuzz_krl.c - the KRL reader (rch_krl_scan) and, on each Cartesian target
 * it finds, KUKA's inverse kinematics with its Status and Turn
 * (rch_krl_ik) on a KR 6-like arm with KUKA's joint map.
 * Invariants: a refusal has a message; targets lie inside the text, in
 * order, their numbers inside them; a readable target has its six main
 * components, finite; the text with every number rewritten ("%.4f", as
 * rcal compensate writes) scans to the same targets; an IK solution is
 * inside the joint limits, has the Status and Turn asked for and reaches the
 * pose. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fuzz_check.h"
#include "rch_krl.h"

#define DEG (3.14159265358979323846 / 180.0)

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static void check_ik(const rch_krl_target *t)
{
    static rc_model m;
    static rch_ctrl ctl;
    static rch_ikg ik;
    static int init;
    if (!init) {
        const double dh[RC_NJ][4] = {{25, 400, -90 * DEG, 0}, {455, 0, 0, -90 * DEG}, {35, 0, -90 * DEG, 0},
                                     {0, 420, 90 * DEG, 0},   {0, 0, -90 * DEG, 0},   {0, 80, 0, 0}};
        const double enc[3] = {0, 0, 0};
        const double lo[RC_NJ] = {-170, -120, -110, -180, -120, -350}, hi[RC_NJ] = {170, 60, 150, 180, 120, 350};
        const double sign[RC_NJ] = {-1, 1, 1, -1, 1, -1}, zero[RC_NJ] = {0, -90, 90, 0, 0, 0};
        const double rpy[3] = {0, -90 * DEG, 180 * DEG};
        rc_model_init(&m, dh, enc);
        rch_ctrl_identity(&ctl);
        for (unsigned j = 0; j < RC_NJ; ++j) {
            m.q_min_rad[j] = lo[j] * DEG;
            m.q_max_rad[j] = hi[j] * DEG;
            ctl.sign[j] = sign[j];
            ctl.zero_rad[j] = zero[j] * DEG;
        }
        ctl.identity_joints = 0;
        ctl.has_flange = 1;
        rch_ctrl_rpy_to_rot(ctl.flange_R, rpy);
        FZ_CHECK(rch_ikg_init(&ik, &m, NULL) == RCH_IKG_OK);
        init = 1;
    }
    double p[3], R[9], a[RC_NJ], p2[3], R2[9];
    rch_krl_frame_to_pose(p, R, (const rch_krl_frame *)(const void *)t->val);
    const int s = (int)t->val[RCH_KRL_S], tu = (int)t->val[RCH_KRL_T];
    char why[256];
    if (rch_krl_ik(a, &ik, &m, &ctl, p, R, s, tu, why, sizeof why) != 0) {
        FZ_CHECK(why[0] != '\0');
        return;
    }
    FZ_CHECK(rch_krl_status(&m, &ctl, a) == s && rch_krl_turn(a) == tu);
    rch_krl_fk(p2, R2, &m, &ctl, a);
    double e = 0.0;
    for (int k = 0; k < 3; ++k)
        e += fabs(p2[k] - p[k]);
    FZ_CHECK(e < 1e-5);
    for (int k = 0; k < 9; ++k)
        FZ_CHECK(fabs(R2[k] - R[k]) < 1e-7);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    rch_krl_targets ts;
    rch_diag d;
    memset(&ts, 0, sizeof ts);
    memset(&d, 0, sizeof d);
    const char *text = (const char *)data; /* exactly size bytes */
    if (rch_krl_scan(&ts, text, size, "fuzz.src", &d) != 0) {
        FZ_CHECK(d.msg[0] != '\0');
        rch_krl_free(&ts);
        return 0;
    }
    size_t prev = 0, n_nums = 0;
    unsigned n_ik = 0; /* the IK (every branch) is the slow part: the first few targets of an input */
    for (size_t i = 0; i < ts.n; ++i) {
        const rch_krl_target *t = &ts.t[i];
        FZ_CHECK(t->off < t->end && t->end <= size && t->off >= prev);
        FZ_CHECK(t->line >= 1 && t->col >= 1);
        prev = t->off;
        if (t->error[0])
            continue;
        FZ_CHECK(text[t->off] == '{' && text[t->end - 1] == '}');
        FZ_CHECK((t->mask & 0x3Fu) == 0x3Fu);
        for (unsigned k = 0; k < RCH_KRL_NSLOT; ++k) {
            if (!((t->mask >> k) & 1u))
                continue;
            FZ_CHECK(t->num_off[k] > t->off && t->num_off[k] + t->num_len[k] < t->end && t->num_len[k] > 0);
            FZ_CHECK(isfinite(t->val[k]));
            ++n_nums;
        }
        if (t->type >= RCH_KRL_POS && n_ik++ < 3)
            check_ik(t);
    }
    /* every number rewritten: the same targets */
    char *out = malloc(size + 48 * n_nums + 1);
    FZ_CHECK(out != NULL);
    size_t o = 0, at = 0;
    for (size_t i = 0; i < ts.n; ++i) {
        const rch_krl_target *t = &ts.t[i];
        if (t->error[0])
            continue;
        for (unsigned k = 0; k < RCH_KRL_NSLOT; ++k) { /* in the text's order */
            size_t best = (size_t)-1;
            unsigned bk = 0;
            for (unsigned j = 0; j < RCH_KRL_NSLOT; ++j)
                if ((t->mask >> j) & 1u && t->num_off[j] >= at && t->num_off[j] < best) {
                    best = t->num_off[j];
                    bk = j;
                }
            if (best == (size_t)-1)
                break;
            memcpy(out + o, text + at, best - at);
            o += best - at;
            const double v = t->val[bk];
            o += (size_t)snprintf(out + o, 48, bk == RCH_KRL_S || bk == RCH_KRL_T ? "%.0f" : "%.4f", v);
            at = best + t->num_len[bk];
        }
    }
    memcpy(out + o, text + at, size - at);
    o += size - at;
    rch_krl_targets t2;
    memset(&t2, 0, sizeof t2);
    FZ_CHECK(rch_krl_scan(&t2, out, o, "fuzz.src", &d) == 0);
    FZ_CHECK(t2.n == ts.n);
    for (size_t i = 0; i < ts.n; ++i) {
        FZ_CHECK(t2.t[i].type == ts.t[i].type && t2.t[i].context == ts.t[i].context);
        FZ_CHECK((t2.t[i].error[0] != '\0') == (ts.t[i].error[0] != '\0'));
    }
    rch_krl_free(&t2);
    free(out);
    rch_krl_free(&ts);
    return 0;
}
