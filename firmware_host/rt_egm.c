/* SPDX-License-Identifier: MIT */
/* rt_egm.c - the EGM codec (EgmRobot in, EgmSensor out) on protobuf-c's
 * generated code (egm.pb-c.h, from egm.proto at build time) and the
 * reference guard. See rt_egm.h. No I/O, no heap: the decoder unpacks into
 * a caller-owned arena, the encoder packs messages built on the stack. */
#include "rt_egm.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "egm.pb-c.h"

/* ---- the arena allocator ---- */

static void *arena_alloc(void *ctx, size_t n)
{
    rt_egm_arena *a = ctx;
    const size_t align = 16;
    size_t at = (a->used + align - 1) / align * align;
    if (at > sizeof a->buf || n > sizeof a->buf - at)
        return NULL; /* protobuf-c then fails the unpack: a malformed datagram */
    a->used = at + n;
    return a->buf + at;
}

static void arena_free(void *ctx, void *p)
{
    (void)ctx;
    (void)p; /* released all at once by the next decode */
}

/* six finite joints from a list, else -1 with why */
static int six(double q[RT_EGM_NJ], const Abb__Egm__EgmJoints *j, const char *what, char *why, size_t why_len)
{
    if (j->n_joints != RT_EGM_NJ) {
        snprintf(why, why_len, "%s.joints has %zu values, not %d", what, j->n_joints, RT_EGM_NJ);
        return -1;
    }
    for (int i = 0; i < RT_EGM_NJ; ++i) {
        if (!isfinite(j->joints[i]) || fabs(j->joints[i]) > 1e6) {
            snprintf(why, why_len, "%s.joints[%d] is not a finite angle in degrees", what, i);
            return -1;
        }
        q[i] = j->joints[i];
    }
    return 0;
}

int rt_egm_decode(rt_egm_robot *out, char *why, size_t why_len, rt_egm_arena *arena, const uint8_t *buf,
                  size_t len)
{
    memset(out, 0, sizeof *out);
    out->motor = out->mci = out->rapid = out->conv_met = -1;
    if (len > RT_EGM_MAX_DGRAM) {
        snprintf(why, why_len, "datagram of %zu bytes, over the %d an EgmRobot can take", len, RT_EGM_MAX_DGRAM);
        return -1;
    }
    arena->used = 0;
    ProtobufCAllocator al = {arena_alloc, arena_free, arena};
    Abb__Egm__EgmRobot *r = abb__egm__egm_robot__unpack(&al, len, buf);
    if (!r) {
        snprintf(why, why_len, "not an EgmRobot message (%zu bytes that do not decode as one)", len);
        return -1;
    }
    int rc = -1;
    if (!r->header || !r->header->has_seqno)
        snprintf(why, why_len, "EgmRobot without header.seqno");
    else if (r->header->has_mtype && r->header->mtype != ABB__EGM__EGM_HEADER__MESSAGE_TYPE__MSGTYPE_DATA)
        snprintf(why, why_len, "EgmRobot with header.mtype %d, not MSGTYPE_DATA (2)", (int)r->header->mtype);
    else if (!r->feedback || !r->feedback->joints)
        snprintf(why, why_len, "EgmRobot without feedBack.joints");
    else if (six(out->fb_deg, r->feedback->joints, "feedBack", why, why_len) == 0 &&
             (!r->planned || !r->planned->joints ||
              six(out->planned_deg, r->planned->joints, "planned", why, why_len) == 0)) {
        out->seqno = r->header->seqno;
        out->has_tm = r->header->has_tm;
        out->tm_ms = r->header->has_tm ? r->header->tm : 0u;
        out->has_planned = r->planned && r->planned->joints;
        if (r->motorstate)
            out->motor = (int)r->motorstate->state;
        if (r->mcistate)
            out->mci = (int)r->mcistate->state;
        if (r->rapidexecstate)
            out->rapid = (int)r->rapidexecstate->state;
        if (r->has_mciconvergencemet)
            out->conv_met = r->mciconvergencemet ? 1 : 0;
        rc = 0;
    }
    abb__egm__egm_robot__free_unpacked(r, &al); /* the arena's: a no-op, kept for the generated code's contract */
    return rc;
}

size_t rt_egm_encode(uint8_t *buf, size_t cap, uint32_t seqno, uint32_t tm_ms, const double q_deg[RT_EGM_NJ])
{
    Abb__Egm__EgmHeader h = ABB__EGM__EGM_HEADER__INIT;
    Abb__Egm__EgmJoints j = ABB__EGM__EGM_JOINTS__INIT;
    Abb__Egm__EgmPlanned p = ABB__EGM__EGM_PLANNED__INIT;
    Abb__Egm__EgmSensor s = ABB__EGM__EGM_SENSOR__INIT;
    double q[RT_EGM_NJ];
    memcpy(q, q_deg, sizeof q);
    h.has_seqno = 1;
    h.seqno = seqno;
    h.has_tm = 1;
    h.tm = tm_ms;
    h.has_mtype = 1;
    h.mtype = ABB__EGM__EGM_HEADER__MESSAGE_TYPE__MSGTYPE_CORRECTION;
    j.n_joints = RT_EGM_NJ;
    j.joints = q;
    p.joints = &j;
    s.header = &h;
    s.planned = &p;
    const size_t n = abb__egm__egm_sensor__get_packed_size(&s);
    if (n > cap)
        return 0;
    return abb__egm__egm_sensor__pack(&s, buf);
}

/* ---- the guard ---- */

void rt_egm_guard_init(rt_egm_guard *g, double step_deg, const double q_min_deg[RT_EGM_NJ],
                       const double q_max_deg[RT_EGM_NJ])
{
    memset(g, 0, sizeof *g);
    g->step_deg = step_deg;
    memcpy(g->q_min_deg, q_min_deg, sizeof g->q_min_deg);
    memcpy(g->q_max_deg, q_max_deg, sizeof g->q_max_deg);
}

int rt_egm_guard_step(rt_egm_guard *g, double sent_deg[RT_EGM_NJ], const double target_deg[RT_EGM_NJ],
                      const double comp_deg[RT_EGM_NJ])
{
    double c[RT_EGM_NJ];
    int limited = 0;
    for (int i = 0; i < RT_EGM_NJ; ++i) {
        c[i] = comp_deg ? comp_deg[i] - target_deg[i] : (g->have ? g->corr_deg[i] : 0.0);
        if (g->have) {
            const double d = c[i] - g->corr_deg[i];
            if (d > g->step_deg) {
                c[i] = g->corr_deg[i] + g->step_deg;
                limited = 1;
            } else if (d < -g->step_deg) {
                c[i] = g->corr_deg[i] - g->step_deg;
                limited = 1;
            }
        }
    }
    for (int i = 0; i < RT_EGM_NJ; ++i) {
        /* the compensation's own numbers when nothing was limited (bit for bit what rcal compensate writes) */
        sent_deg[i] = comp_deg && !limited ? comp_deg[i] : target_deg[i] + c[i];
        sent_deg[i] = fmin(fmax(sent_deg[i], g->q_min_deg[i]), g->q_max_deg[i]);
        g->corr_deg[i] = c[i];
        g->sent_deg[i] = sent_deg[i];
    }
    g->have = 1;
    g->n_clamped += (unsigned long)limited;
    return limited;
}
