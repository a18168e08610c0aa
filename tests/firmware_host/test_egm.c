/* SPDX-License-Identifier: MIT */
/* test_egm.c - rcal-rt's EGM codec and reference guard (firmware_host/rt_egm.h,
 * issue 49). The wire bytes are written and read here by hand (protobuf's
 * varints and tags, ABB's field numbers), not by protobuf-c: an EgmRobot in
 * both encodings of a repeated double (packed and one tag per value) decodes
 * to its fields; every malformed one is refused with a reason naming the
 * field; an EgmSensor carries seqno, tm, MSGTYPE_CORRECTION and the six
 * joints. The guard: no change of the reference beyond the path's own plus
 * the stated limit, a failed compensation keeps the last correction, the
 * joint limits hold, and an unlimited reference is the compensation's own
 * numbers bit for bit. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "rt_egm.h"

/* ---- a hand-written protobuf writer ---- */
typedef struct wbuf {
    uint8_t b[2048];
    size_t n;
} wbuf;

static void w_varint(wbuf *w, uint64_t v)
{
    do {
        uint8_t c = (uint8_t)(v & 0x7fu);
        v >>= 7;
        w->b[w->n++] = (uint8_t)(c | (v ? 0x80u : 0u));
    } while (v);
}

static void w_tag(wbuf *w, unsigned field, unsigned wire) { w_varint(w, ((uint64_t)field << 3) | wire); }

static void w_double(wbuf *w, double d)
{
    uint64_t u;
    memcpy(&u, &d, 8);
    for (int i = 0; i < 8; ++i)
        w->b[w->n++] = (uint8_t)(u >> (8 * i));
}

static void w_sub(wbuf *w, unsigned field, const wbuf *sub)
{
    w_tag(w, field, 2);
    w_varint(w, sub->n);
    memcpy(w->b + w->n, sub->b, sub->n);
    w->n += sub->n;
}

/* EgmJoints { repeated double joints = 1 } of n values, packed or not */
static void joints(wbuf *out, const double *q, int n, int packed)
{
    memset(out, 0, sizeof *out);
    if (packed) {
        wbuf p;
        memset(&p, 0, sizeof p);
        for (int i = 0; i < n; ++i)
            w_double(&p, q[i]);
        w_sub(out, 1, &p);
    } else {
        for (int i = 0; i < n; ++i) {
            w_tag(out, 1, 1);
            w_double(out, q[i]);
        }
    }
}

typedef struct robot_spec {
    int header, seqno, mtype, fb, fb_n, planned, packed;
    double fb_q[RT_EGM_NJ], pl_q[RT_EGM_NJ];
} robot_spec;

/* EgmRobot: header(1){seqno 1, tm 2, mtype 3}, feedBack(2){joints(1)}, planned(3){joints(1)},
 * motorState(4){state 1}, mciState(5){state 1}, mciConvergenceMet(6), rapidExecState(8){state 1},
 * utilizationRate(10) */
static void robot(wbuf *w, const robot_spec *s)
{
    memset(w, 0, sizeof *w);
    if (s->header) {
        wbuf h;
        memset(&h, 0, sizeof h);
        if (s->seqno) {
            w_tag(&h, 1, 0);
            w_varint(&h, 4000000000u);
        }
        w_tag(&h, 2, 0);
        w_varint(&h, 123456u);
        w_tag(&h, 3, 0);
        w_varint(&h, (uint64_t)s->mtype);
        w_sub(w, 1, &h);
    }
    if (s->fb) {
        wbuf j, f;
        joints(&j, s->fb_q, s->fb_n, s->packed);
        memset(&f, 0, sizeof f);
        w_sub(&f, 1, &j);
        w_sub(w, 2, &f);
    }
    if (s->planned) {
        wbuf j, p;
        joints(&j, s->pl_q, RT_EGM_NJ, s->packed);
        memset(&p, 0, sizeof p);
        w_sub(&p, 1, &j);
        w_sub(w, 3, &p);
    }
    static const unsigned st_field[3] = {4, 5, 8};
    static const unsigned st_val[3] = {1, 3, 2};
    for (int k = 0; k < 3; ++k) {
        wbuf m;
        memset(&m, 0, sizeof m);
        w_tag(&m, 1, 0);
        w_varint(&m, st_val[k]);
        w_sub(w, st_field[k], &m);
    }
    w_tag(w, 6, 0);
    w_varint(w, 1);
    w_tag(w, 10, 1);
    w_double(w, 42.5);
}

static robot_spec good(void)
{
    robot_spec s = {1, 1, 2, 1, RT_EGM_NJ, 1, 0, {1.5, -20.25, 30, 0, 45.125, -170}, {1.75, -20, 30.5, 0.25, 45, -169}};
    return s;
}

static rt_egm_arena arena;

static void decodes_both_encodings(void **state)
{
    (void)state;
    for (int packed = 0; packed < 2; ++packed) {
        robot_spec s = good();
        s.packed = packed;
        wbuf w;
        robot(&w, &s);
        rt_egm_robot r;
        char why[256] = "";
        assert_int_equal(rt_egm_decode(&r, why, sizeof why, &arena, w.b, w.n), 0);
        assert_int_equal(r.seqno, 4000000000u);
        assert_int_equal(r.tm_ms, 123456u);
        assert_true(r.has_planned);
        for (int i = 0; i < RT_EGM_NJ; ++i) {
            assert_true(r.fb_deg[i] == s.fb_q[i]);
            assert_true(r.planned_deg[i] == s.pl_q[i]);
        }
        assert_int_equal(r.motor, RT_EGM_MOTORS_ON);
        assert_int_equal(r.mci, RT_EGM_MCI_RUNNING);
        assert_int_equal(r.rapid, RT_EGM_RAPID_RUNNING);
        assert_int_equal(r.conv_met, 1);
    }
}

static void refuses_malformed(void **state)
{
    (void)state;
    struct {
        robot_spec s;
        const char *why;
    } cases[8];
    int n = 0;
    cases[n].s = good(), cases[n].s.header = 0, cases[n++].why = "header.seqno";
    cases[n].s = good(), cases[n].s.seqno = 0, cases[n++].why = "header.seqno";
    cases[n].s = good(), cases[n].s.mtype = 3, cases[n++].why = "MSGTYPE_DATA";
    cases[n].s = good(), cases[n].s.fb = 0, cases[n++].why = "feedBack.joints";
    cases[n].s = good(), cases[n].s.fb_n = 5, cases[n++].why = "feedBack.joints has 5 values";
    cases[n].s = good(), cases[n].s.fb_q[2] = NAN, cases[n++].why = "feedBack.joints[2]";
    cases[n].s = good(), cases[n].s.pl_q[5] = INFINITY, cases[n++].why = "planned.joints[5]";
    for (int k = 0; k < n; ++k) {
        wbuf w;
        robot(&w, &cases[k].s);
        rt_egm_robot r;
        char why[256] = "";
        assert_int_equal(rt_egm_decode(&r, why, sizeof why, &arena, w.b, w.n), -1);
        if (!strstr(why, cases[k].why))
            fail_msg("case %d: '%s' does not name %s", k, why, cases[k].why);
    }
    /* truncated anywhere inside the last field, and garbage */
    robot_spec s = good();
    wbuf w;
    robot(&w, &s);
    rt_egm_robot r;
    char why[256];
    for (size_t cut = 1; cut < 9; ++cut)
        assert_int_equal(rt_egm_decode(&r, why, sizeof why, &arena, w.b, w.n - cut), -1);
    static const uint8_t junk[] = {0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0x01};
    assert_int_equal(rt_egm_decode(&r, why, sizeof why, &arena, junk, sizeof junk), -1);
    assert_int_equal(rt_egm_decode(&r, why, sizeof why, &arena, junk, 0), -1);
    static uint8_t big[RT_EGM_MAX_DGRAM + 1];
    assert_int_equal(rt_egm_decode(&r, why, sizeof why, &arena, big, sizeof big), -1);
    assert_non_null(strstr(why, "over the"));
}

/* ---- a hand-written reader of the EgmSensor ---- */
static uint64_t r_varint(const uint8_t *b, size_t n, size_t *at)
{
    uint64_t v = 0;
    for (unsigned sh = 0; *at < n && sh < 64; sh += 7) {
        const uint8_t c = b[(*at)++];
        v |= (uint64_t)(c & 0x7fu) << sh;
        if (!(c & 0x80u))
            break;
    }
    return v;
}

static void encodes_sensor(void **state)
{
    (void)state;
    const double q[RT_EGM_NJ] = {10.028370123456789, 20.175698, -29.892841, 40.021266, 49.9374, -179.99997};
    uint8_t out[256];
    const size_t n = rt_egm_encode(out, sizeof out, 77u, 4321u, q);
    assert_true(n > 0);
    assert_int_equal(rt_egm_encode(out, 10, 77u, 4321u, q), 0); /* too small: nothing */
    size_t at = 0;
    unsigned seqno = 0, tm = 0, mtype = 0, nj = 0, got_header = 0, got_planned = 0;
    double j[RT_EGM_NJ] = {0};
    while (at < n) {
        const uint64_t tag = r_varint(out, n, &at);
        assert_int_equal(tag & 7u, 2u);
        const size_t len = (size_t)r_varint(out, n, &at), end = at + len;
        assert_true(end <= n);
        if ((tag >> 3) == 1) { /* header */
            got_header = 1;
            while (at < end) {
                const uint64_t t = r_varint(out, n, &at);
                const unsigned v = (unsigned)r_varint(out, n, &at);
                if ((t >> 3) == 1)
                    seqno = v;
                else if ((t >> 3) == 2)
                    tm = v;
                else if ((t >> 3) == 3)
                    mtype = v;
            }
        } else if ((tag >> 3) == 2) { /* planned { joints(1) { joints(1) } } */
            got_planned = 1;
            assert_int_equal(r_varint(out, n, &at), (1u << 3) | 2u);
            const size_t jend = at + (size_t)r_varint(out, n, &at);
            while (at < jend) {
                const uint64_t t = r_varint(out, n, &at);
                if (t == ((1u << 3) | 2u)) { /* packed */
                    const size_t pend = at + (size_t)r_varint(out, n, &at);
                    for (; at + 8 <= pend && nj < RT_EGM_NJ; at += 8, ++nj)
                        memcpy(&j[nj], out + at, 8);
                } else {
                    assert_int_equal(t, (1u << 3) | 1u);
                    memcpy(&j[nj++], out + at, 8);
                    at += 8;
                }
            }
        }
        at = end;
    }
    assert_true(got_header && got_planned);
    assert_int_equal(seqno, 77u);
    assert_int_equal(tm, 4321u);
    assert_int_equal(mtype, RT_EGM_MSG_CORRECTION);
    assert_int_equal(nj, RT_EGM_NJ);
    for (int i = 0; i < RT_EGM_NJ; ++i)
        assert_true(j[i] == q[i]); /* bit for bit */
}

static const double qmin[RT_EGM_NJ] = {-165, -110, -110, -160, -120, -400};
static const double qmax[RT_EGM_NJ] = {165, 110, 70, 160, 120, 400};

static void guard_bounds(void **state)
{
    (void)state;
    rt_egm_guard g;
    rt_egm_guard_init(&g, 0.01, qmin, qmax);
    double t[RT_EGM_NJ] = {10, 20, 30, 40, 50, 60}, c[RT_EGM_NJ], sent[RT_EGM_NJ], prev[RT_EGM_NJ];
    for (int i = 0; i < RT_EGM_NJ; ++i)
        c[i] = t[i] + 0.3; /* a first correction of 0.3 deg: taken as it is */
    assert_int_equal(rt_egm_guard_step(&g, sent, t, c), 0);
    for (int i = 0; i < RT_EGM_NJ; ++i)
        assert_true(sent[i] == c[i]);
    /* a path moving 0.05 deg per cycle; the compensation jumps (a new model) by 0.2 deg: the change of the
     * reference beyond the path's own stays within 0.01 deg, and after 20 cycles it is the compensation's */
    int limited = 0;
    for (int k = 1; k <= 40; ++k) {
        memcpy(prev, sent, sizeof prev);
        double tp[RT_EGM_NJ];
        memcpy(tp, t, sizeof tp);
        for (int i = 0; i < RT_EGM_NJ; ++i) {
            t[i] += 0.05;
            c[i] = t[i] + (k >= 3 ? 0.1 : 0.3);
        }
        limited += rt_egm_guard_step(&g, sent, t, c);
        for (int i = 0; i < RT_EGM_NJ; ++i)
            assert_true(fabs(sent[i] - prev[i]) <= fabs(t[i] - tp[i]) + 0.01 + 1e-12);
    }
    assert_int_equal(limited, 20);
    assert_int_equal(g.n_clamped, 20ul);
    for (int i = 0; i < RT_EGM_NJ; ++i)
        assert_true(sent[i] == c[i]); /* the ramp over: the compensation's own numbers */
}

static void guard_failure_and_limits(void **state)
{
    (void)state;
    rt_egm_guard g;
    rt_egm_guard_init(&g, 0.01, qmin, qmax);
    double t[RT_EGM_NJ] = {0, 0, 69.95, 0, 0, 0}, c[RT_EGM_NJ], sent[RT_EGM_NJ];
    for (int i = 0; i < RT_EGM_NJ; ++i)
        c[i] = t[i] + 0.04;
    rt_egm_guard_step(&g, sent, t, c);
    assert_true(sent[2] == c[2]);
    /* the compensation fails (NULL): the last correction is kept on the new target */
    t[0] = 1.0;
    t[2] = 69.97;
    assert_int_equal(rt_egm_guard_step(&g, sent, t, NULL), 0);
    assert_true(fabs(sent[0] - 1.04) < 1e-12);
    assert_true(fabs(g.corr_deg[2] - 0.04) < 1e-12);
    /* ...and the reference stays within q3's limit of 70 deg, even where target plus correction is not */
    assert_true(sent[2] == 70.0);
    /* a failure at the very first target: the target itself */
    rt_egm_guard_init(&g, 0.01, qmin, qmax);
    rt_egm_guard_step(&g, sent, t, NULL);
    for (int i = 0; i < RT_EGM_NJ; ++i)
        assert_true(sent[i] == t[i]);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(decodes_both_encodings), cmocka_unit_test(refuses_malformed),
        cmocka_unit_test(encodes_sensor),         cmocka_unit_test(guard_bounds),
        cmocka_unit_test(guard_failure_and_limits),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
