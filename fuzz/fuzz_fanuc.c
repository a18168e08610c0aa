/* SPDX-License-Identifier: MIT */
/* fuzz_fanuc.c - the Fanuc LS reader (rch_fanuc_scan), the frames file
 * reader (rch_fanuc_frames_parse) and W, P, R on what they read.
 * Invariants: a refusal has a message and leaves nothing to free;
 * positions lie inside the text, their numbers in order, without overlap,
 * finite, 6 (joint) or 9 (Cartesian: CONFIG's turns first in the text, then
 * X..R); the text with every number rewritten ("%.4f", as a rewrite could)
 * scans to the same positions and uses; W, P, R -> rotation -> W, P, R ->
 * rotation is the same rotation. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fuzz_check.h"
#include "rch_fanuc.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

typedef struct {
    size_t off, len;
    double v;
} num;

static int cmp_off(const void *a, const void *b)
{
    const size_t x = ((const num *)a)->off, y = ((const num *)b)->off;
    return x < y ? -1 : x > y;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    const char *text = (const char *)data;
    rch_diag d;
    memset(&d, 0, sizeof d);
    rch_fanuc_frames fr;
    if (rch_fanuc_frames_parse(&fr, text, size, "fuzz.csv", &d) != 0)
        FZ_CHECK(d.msg[0] != '\0');
    else
        for (int k = 0; k <= RCH_FANUC_MAX_FRAMES; ++k)
            for (int j = 0; j < 6; ++j)
                FZ_CHECK(isfinite(fr.uf[k][j]) && isfinite(fr.ut[k][j]));
    memset(&d, 0, sizeof d);
    rch_fanuc_prog p;
    if (rch_fanuc_scan(&p, text, size, "fuzz.ls", &d) != 0) {
        FZ_CHECK(d.msg[0] != '\0');
        FZ_CHECK(p.p == NULL && p.n == 0);
        return 0;
    }
    size_t n_nums = 0;
    for (size_t i = 0; i < p.n; ++i) {
        const rch_fanuc_pos *q = &p.p[i];
        FZ_CHECK(q->n == (q->joint ? 6u : 9u));
        FZ_CHECK(q->line >= 1 && q->col >= 1);
        for (unsigned k = 0; k < q->n; ++k) {
            FZ_CHECK(q->num_len[k] > 0 && q->num_off[k] + q->num_len[k] <= size);
            FZ_CHECK(isfinite(q->val[k]));
            if (k > 0 && k != 6)
                FZ_CHECK(q->num_off[k] >= q->num_off[k - 1] + q->num_len[k - 1]);
        }
        if (!q->joint) {
            FZ_CHECK(q->num_off[8] + q->num_len[8] <= q->num_off[0]); /* CONFIG before X */
            double R[9], w[3], R2[9];
            rch_fanuc_wpr_to_rot(R, &q->val[3]);
            rch_fanuc_rot_to_wpr(w, R);
            rch_fanuc_wpr_to_rot(R2, w);
            if (fabs(q->val[3]) < 1e6 && fabs(q->val[4]) < 1e6 && fabs(q->val[5]) < 1e6)
                for (int k = 0; k < 9; ++k)
                    FZ_CHECK(fabs(R[k] - R2[k]) < 1e-6);
        }
        n_nums += q->n;
    }
    /* rewrite every number in the text's order; scan again */
    num *nums = malloc((n_nums + 1) * sizeof *nums);
    FZ_CHECK(nums != NULL);
    size_t m = 0;
    for (size_t i = 0; i < p.n; ++i)
        for (unsigned k = 0; k < p.p[i].n; ++k) {
            nums[m].off = p.p[i].num_off[k];
            nums[m].len = p.p[i].num_len[k];
            nums[m++].v = p.p[i].val[k];
        }
    qsort(nums, m, sizeof *nums, cmp_off);
    char *out = malloc(size + 48 * n_nums + 1);
    FZ_CHECK(out != NULL);
    size_t o = 0, at = 0;
    for (size_t j = 0; j < m; ++j) {
        FZ_CHECK(nums[j].off >= at);
        memcpy(out + o, text + at, nums[j].off - at);
        o += nums[j].off - at;
        o += (size_t)snprintf(out + o, 48, "%.4f", fabs(nums[j].v) < 1e30 ? nums[j].v : 0.0);
        at = nums[j].off + nums[j].len;
    }
    memcpy(out + o, text + at, size - at);
    o += size - at;
    rch_fanuc_prog p2;
    memset(&d, 0, sizeof d);
    FZ_CHECK(rch_fanuc_scan(&p2, out, o, "fuzz.ls", &d) == 0);
    FZ_CHECK(p2.n == p.n && p2.n_motion == p.n_motion);
    for (size_t i = 0; i < p.n; ++i) {
        FZ_CHECK(p2.p[i].idx == p.p[i].idx && p2.p[i].joint == p.p[i].joint && p2.p[i].n_uses == p.p[i].n_uses);
        FZ_CHECK(memcmp(p2.p[i].cfg, p.p[i].cfg, 3) == 0);
    }
    rch_fanuc_free(&p2);
    free(out);
    free(nums);
    rch_fanuc_free(&p);
    return 0;
}
