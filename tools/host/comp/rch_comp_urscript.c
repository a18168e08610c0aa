/* SPDX-License-Identifier: MIT */
/* rch_comp_urscript.c - a URScript program through the compensation (see
 * rch_urscript_comp.h): read whole (rch_urs_scan), each joint list
 * corrected, each pose through the nominal IK on the branch nearest the
 * robot's joints, corrected at its TCP (a stream per TCP, made when first
 * needed) and written back; only the numbers' bytes change. All or nothing.
 * Depends on: rch_urscript (the reader), rch_ikg (the nominal IK), rch_ctrl
 * (the controller's joints and frames), one target (rch_comp.c), the point
 * model (rch_comp_model.c), rc_rotvec_* (lib). Memory: the program, its edits
 * and the streams for other TCPs on the heap. Errors: -1 with d set. */
#include "rch_urscript_comp.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "rc_sensor.h"
#include "rch_ikg.h"
#include "rch_urscript.h"

/* two solutions nearer than this are the same (rad, each joint) */
#define SAME_RAD 1e-6

typedef struct { /* a rigid pose: p (mm), R row-major */
    double p[3], R[9];
} pose;

typedef struct {
    rch_cpi_ctx *c;
    const rch_ctrl *ctrl;
    rch_ikg ik;              /* the nominal model's, at the DH flange */
    pose tcp;                /* the TCP in the controller's flange frame */
    int has_tcp;
    pose B, F;               /* the controller's base and flange frames (rch_ctrl) */
    int have_cur;
    double cur[RC_NJ];       /* where the original program's robot stands (model rad) */
    double cur_c[RC_NJ];     /* where the compensated program's robot stands */
    rch_cpi_edits ed;
    unsigned long n_bad;
    unsigned base;
    unsigned err_line, err_col; /* where a refusal points when not at the literal (a joint's value) */
    rch_diag *d;
} urs;

static void mul(pose *o, const pose *a, const pose *b)
{
    pose r;
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j)
            r.R[3 * i + j] = a->R[3 * i] * b->R[j] + a->R[3 * i + 1] * b->R[3 + j] + a->R[3 * i + 2] * b->R[6 + j];
        r.p[i] = a->p[i] + a->R[3 * i] * b->p[0] + a->R[3 * i + 1] * b->p[1] + a->R[3 * i + 2] * b->p[2];
    }
    *o = r;
}

static void inv(pose *o, const pose *a)
{
    pose r;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            r.R[3 * i + j] = a->R[3 * j + i];
    for (int i = 0; i < 3; ++i)
        r.p[i] = -(r.R[3 * i] * a->p[0] + r.R[3 * i + 1] * a->p[1] + r.R[3 * i + 2] * a->p[2]);
    *o = r;
}

static void ident(pose *o)
{
    memset(o, 0, sizeof *o);
    o->R[0] = o->R[4] = o->R[8] = 1.0;
}

/* p[x,y,z,rx,ry,rz] (m, rad) -> pose (mm) */
static void from_urs(pose *o, const double v[6])
{
    for (int k = 0; k < 3; ++k)
        o->p[k] = v[k] * 1000.0;
    rc_rotvec_matrix(o->R, &v[3]);
}

/* pose -> p[...] (m, rad), the rotation vector the equivalent nearest
 * old (3): w or w (1 - 2 pi / |w|) (the same rotation the other way). */
static void to_urs(double v[6], const pose *a, const double old[3])
{
    double w[3];
    rc_rotvec_from_matrix(w, a->R);
    const double n = sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
    if (n > 1e-9) {
        const double f = 1.0 - 2.0 * M_PI / n;
        double d0 = 0, d1 = 0;
        for (int k = 0; k < 3; ++k) {
            d0 += (w[k] - old[k]) * (w[k] - old[k]);
            d1 += (f * w[k] - old[k]) * (f * w[k] - old[k]);
        }
        if (d1 < d0)
            for (int k = 0; k < 3; ++k)
                w[k] *= f;
    }
    for (int k = 0; k < 3; ++k) {
        v[k] = a->p[k] / 1000.0;
        v[3 + k] = w[k];
    }
}

static void refuse(urs *u, const rch_urs_target *t, const char *why)
{
    rch_cpi_ctx *c = u->c;
    const unsigned line = u->err_line ? u->err_line : t->line, col = u->err_line ? u->err_col : t->col;
    u->err_line = u->err_col = 0;
    char what[96];
    snprintf(what, sizeof what, "%s%s%s", rch_urs_kind_name(t->kind), t->name[0] ? " " : "", t->name);
    const char *where = t->instr[0] ? t->instr : rch_urs_role_name(t->role);
    if (u->n_bad == 0)
        rch_diag_set(u->d, c->in_name, line, col, "%s (%s): %s", what, where, why);
    if (c->warn)
        fprintf(c->warn, "%s:%u:%u: error: %s (%s) cannot be corrected: %s\n", c->in_name, line, col,
                what, where, why);
    ++u->n_bad;
}

/* The nominal solution of the DH flange pose T nearest seed (model rad),
 * each axis in its turn nearest the seed inside the limits: 0 with q, or
 * -1 (why). gap: how much farther the second nearest solution is. */
static int nearest_ik(double q[RC_NJ], double *gap, const urs *u, const pose *T, const double seed[RC_NJ], char *why,
                      size_t why_len)
{
    double all[RCH_IKG_MAX_SOL][RC_NJ];
    const int n = rch_ikg_all(all, NULL, &u->ik, T->p, T->R);
    double best = HUGE_VAL, second = HUGE_VAL;
    int found = 0;
    for (int k = 0; k < n; ++k) {
        double x[RC_NJ], s2 = 0;
        int ok = 1;
        for (int i = 0; i < RC_NJ && ok; ++i) {
            x[i] = all[k][i] + 2.0 * M_PI * floor((seed[i] - all[k][i]) / (2.0 * M_PI) + 0.5);
            if (x[i] > u->ik.q_max_rad[i] + 1e-12 && x[i] - 2.0 * M_PI >= u->ik.q_min_rad[i] - 1e-12)
                x[i] -= 2.0 * M_PI;
            if (x[i] < u->ik.q_min_rad[i] - 1e-12 && x[i] + 2.0 * M_PI <= u->ik.q_max_rad[i] + 1e-12)
                x[i] += 2.0 * M_PI;
            ok = x[i] >= u->ik.q_min_rad[i] - 1e-12 && x[i] <= u->ik.q_max_rad[i] + 1e-12;
            s2 += (x[i] - seed[i]) * (x[i] - seed[i]);
        }
        if (!ok)
            continue;
        const double dd = sqrt(s2);
        if (dd < best) {
            second = best;
            best = dd;
            memcpy(q, x, sizeof x);
            found = 1;
        } else if (dd < second)
            second = dd;
    }
    if (!found) {
        snprintf(why, why_len, "%s", n == 0 ? "out of reach of the nominal robot" : "no solution inside the joint limits");
        return -1;
    }
    *gap = second - best;
    return 0;
}

/* The DH flange pose of the controller's TCP pose P read with the TCP:
 * B^-1 P TCP^-1 F^-1. */
static void dh_flange(pose *T, const urs *u, const pose *P)
{
    pose a, ti, fi, bi;
    inv(&ti, &u->tcp);
    inv(&fi, &u->F);
    inv(&bi, &u->B);
    mul(&a, P, &ti);
    mul(&a, &a, &fi);
    mul(T, &bi, &a);
}

/* ... and back: B T(q) F TCP at model joints q. */
static void ctrl_pose(pose *P, const urs *u, const double q[RC_NJ])
{
    pose T;
    rch_ikg_fk(T.p, T.R, &u->ik, q);
    mul(P, &u->B, &T);
    mul(P, P, &u->F);
    mul(P, P, &u->tcp);
}

/* The TCP's point in the DH flange frame (the point compensated). */
static void tcp_dh(double out[3], const urs *u)
{
    for (int i = 0; i < 3; ++i)
        out[i] = u->F.p[i] + u->F.R[3 * i] * u->tcp.p[0] + u->F.R[3 * i + 1] * u->tcp.p[1] + u->F.R[3 * i + 2] * u->tcp.p[2];
}

/* One corrected joint vector: q (model rad) in, qo out. 0, 1 flagged, 2 left
 * as it was (uncertain), -1 (why). */
static int correct(urs *u, double qo[RC_NJ], const double q[RC_NJ], const rch_urs_target *t, char *why, size_t wl)
{
    rch_cpi_ctx *c = u->c;
    double tp[3];
    tcp_dh(tp, u);
    const int has = u->has_tcp || (c->gate && c->gate->tool_mm);
    if (rch_cpi_use_tcp(c, tp, has, why, wl) != 0)
        return -1;
    double qd[RC_NJ], od[RC_NJ];
    unsigned cols[RC_NJ];
    for (int i = 0; i < RC_NJ; ++i) {
        qd[i] = q[i] / DEG;
        cols[i] = t->num_col[i];
    }
    const int r = rch_cpi_compensate_at(c, od, qd, t->line, cols, why, wl);
    if (r < 0) {
        for (int i = 0; i < RC_NJ && t->kind == RCH_URS_JOINTS; ++i)
            if (!(q[i] >= c->cal->q_min_rad[i] && q[i] <= c->cal->q_max_rad[i])) { /* named at that number */
                u->err_line = t->num_line[i];
                u->err_col = t->num_col[i];
                break;
            }
        return -1;
    }
    for (int i = 0; i < RC_NJ; ++i)
        qo[i] = od[i] * DEG;
    return r;
}

/* A joint list: its values are the controller's (rad). */
static int do_joints(urs *u, double out[6], const rch_urs_target *t, char *why, size_t wl)
{
    double q[RC_NJ], qo[RC_NJ];
    rch_ctrl_to_model(q, u->ctrl, t->val);
    const int r = correct(u, qo, q, t, why, wl);
    if (r < 0)
        return r;
    memcpy(u->cur, q, sizeof q);
    memcpy(u->cur_c, r == 2 ? q : qo, sizeof q);
    u->have_cur = 1;
    rch_ctrl_from_model(out, u->ctrl, qo);
    return r;
}

/* A pose: the controller's IK nearest where the robot stands, corrected,
 * the nominal pose of the corrected joints; checked as the controller will
 * read it. */
static int do_pose(urs *u, double out[6], const rch_urs_target *t, const rch_urs_targets *ts, char *why, size_t wl)
{
    double seed[RC_NJ], seed_c[RC_NJ];
    if (t->role == RCH_URS_IK && t->qnear >= 0) {
        rch_ctrl_to_model(seed, u->ctrl, ts->t[t->qnear].val);
        memcpy(seed_c, seed, sizeof seed);
    } else if (u->have_cur) {
        memcpy(seed, u->cur, sizeof seed);
        memcpy(seed_c, u->cur_c, sizeof seed);
    } else {
        snprintf(why, wl, "no joint target or qnear before it: the branch the controller takes (the solution nearest "
                 "where the robot stands) cannot be told; put a movej([...]) before it or use "
                 "get_inverse_kin(p[...], qnear=[...])");
        return -1;
    }
    pose P, T;
    from_urs(&P, t->val);
    dh_flange(&T, u, &P);
    double q[RC_NJ], qo[RC_NJ], gap;
    char w2[200];
    if (nearest_ik(q, &gap, u, &T, seed, w2, sizeof w2) != 0) {
        snprintf(why, wl, "the nominal inverse kinematics: %s", w2);
        return -1;
    }
    const int r = correct(u, qo, q, t, why, wl);
    if (r < 0)
        return r;
    memcpy(u->cur, q, sizeof q);
    u->have_cur = 1;
    if (r == 2) { /* left as it was */
        memcpy(u->cur_c, q, sizeof q);
        memcpy(out, t->val, 6 * sizeof *out);
        return r;
    }
    pose Pc, Tc;
    ctrl_pose(&Pc, u, qo);
    to_urs(out, &Pc, &t->val[3]);
    /* the controller's reading of what is written (after its rounding) */
    double written[6], qc[RC_NJ];
    for (int k = 0; k < 6; ++k) {
        char b[40];
        snprintf(b, sizeof b, k < 3 ? "%.8f" : "%.9f", out[k]);
        written[k] = strtod(b, NULL);
    }
    from_urs(&Pc, written);
    dh_flange(&Tc, u, &Pc);
    if (nearest_ik(qc, &gap, u, &Tc, seed_c, w2, sizeof w2) != 0) {
        snprintf(why, wl, "the corrected pose: the nominal inverse kinematics: %s", w2);
        return -1;
    }
    double dmax = 0;
    for (int i = 0; i < RC_NJ; ++i)
        dmax = fmax(dmax, fabs(qc[i] - qo[i]));
    if (dmax > 1e-5) {
        snprintf(why, wl, "the controller would take another solution of the corrected pose (%.4f rad from the "
                 "corrected joints): a pose next to a singularity or halfway between two solutions", dmax);
        return -1;
    }
    memcpy(u->cur_c, qc, sizeof qc);
    return r;
}

static int do_text(rch_cpi_ctx *c, const char *text, size_t len, unsigned base, rch_diag *d)
{
    rch_urs_targets ts;
    memset(&ts, 0, sizeof ts);
    if (rch_urs_scan(&ts, text, len, c->in_name, base + 1, d) != 0) {
        rch_urs_free(&ts);
        return -1;
    }
    urs *up = calloc(1, sizeof *up); /* the IK's tables are large */
    if (!up) {
        rch_diag_set(d, c->in_name, 0, 0, "out of memory");
        rch_urs_free(&ts);
        return -1;
    }
    up->c = c;
    up->base = 0; /* the reader counts the file's lines */
    (void)base;
    up->d = d;
    rch_ctrl idc;
    rch_ctrl_identity(&idc);
    up->ctrl = c->gate && c->gate->ctrl ? c->gate->ctrl : &idc;
    ident(&up->tcp);
    ident(&up->B);
    ident(&up->F);
    if (up->ctrl->has_base) {
        memcpy(up->B.R, up->ctrl->base_R, sizeof up->B.R);
        memcpy(up->B.p, up->ctrl->base_mm, sizeof up->B.p);
    }
    if (up->ctrl->has_flange) {
        memcpy(up->F.R, up->ctrl->flange_R, sizeof up->F.R);
        memcpy(up->F.p, up->ctrl->flange_mm, sizeof up->F.p);
    }
    if (c->gate && c->gate->tool_mm) /* --tool: a point in the DH flange frame, before any set_tcp */
        for (int i = 0; i < 3; ++i) /* F^-1 tool */
            up->tcp.p[i] = up->F.R[i] * (c->gate->tool_mm[0] - up->F.p[0]) + up->F.R[3 + i] * (c->gate->tool_mm[1] - up->F.p[1]) +
                         up->F.R[6 + i] * (c->gate->tool_mm[2] - up->F.p[2]);
    const rc_model *nom = c->gate ? c->gate->nominal : NULL;
    size_t n_targets = 0;
    for (size_t i = 0; i < ts.n; ++i)
        n_targets += ts.t[i].role != RCH_URS_TCP && ts.t[i].role != RCH_URS_QNEAR;
    int rc = 0;
    if (n_targets == 0) {
        rch_diag_set(d, c->in_name, 0, 0, "no joint list or pose target in this program (movej, movel, movep, movec, "
                     "get_inverse_kin, assignments): nothing to correct; nothing written");
        rch_urs_free(&ts);
        free(up);
        return -1;
    }
    if (!nom || rch_ikg_init(&up->ik, nom, NULL) != RCH_IKG_OK) {
        rch_diag_set(d, c->in_name, 0, 0, "no nominal model to invert the pose targets with; nothing written");
        rch_urs_free(&ts);
        free(up);
        return -1;
    }
    for (size_t i = 0; i < ts.n; ++i) {
        const rch_urs_target *t = &ts.t[i];
        char why[512];
        double out[6];
        if (t->error[0]) {
            refuse(up, t, t->error);
            continue;
        }
        if (t->role == RCH_URS_QNEAR)
            continue; /* a seed, kept */
        if (t->role == RCH_URS_TCP) {
            from_urs(&up->tcp, t->val);
            up->has_tcp = t->val[0] != 0 || t->val[1] != 0 || t->val[2] != 0;
            continue;
        }
        const int r = t->kind == RCH_URS_JOINTS ? do_joints(up, out, t, why, sizeof why)
                                                : do_pose(up, out, t, &ts, why, sizeof why);
        if (r < 0) {
            refuse(up, t, why);
            continue;
        }
        if (r > 0)
            rc = 1;
        if (r == 2)
            continue;
        if (t->kind == RCH_URS_POSE)
            c->res->n_robtargets++;
        for (unsigned k = 0; k < RCH_URS_NUMS; ++k)
            if (rch_cpi_edit_add(&up->ed, t->num_off[k], t->num_len[k], t->kind == RCH_URS_POSE && k < 3 ? "%.8f" : "%.9f",
                                 out[k] == 0.0 ? 0.0 : out[k]) != 0) { /* never "-0.000" */
                rch_diag_set(d, c->in_name, 0, 0, "out of memory");
                rch_cpi_edits_free(&up->ed);
                rch_urs_free(&ts);
                free(up);
                return -1;
            }
    }
    if (up->n_bad > 0) {
        rch_cpi_refused(c, d, up->n_bad, "target");
        rc = -1;
    } else
        rch_cpi_edits_write(c, text, len, &up->ed);
    rch_cpi_edits_free(&up->ed);
    rch_urs_free(&ts);
    free(up);
    return rc;
}

int rch_cpi_urscript(rch_cpi_ctx *c, const char *line, size_t got, FILE *in, unsigned lineno, rch_diag *d)
{
    return rch_cpi_whole(c, line, got, in, lineno, RCH_URS_MAX_BYTES, "a URScript program", do_text, d);
}

static int word_at(const char *s, size_t n, const char *w)
{
    const size_t k = strlen(w);
    return n >= k && strncasecmp(s, w, k) == 0 && (n == k || s[k] == ' ' || s[k] == '\t' || s[k] == '(');
}

int rch_cpi_urscript_detect(const char *text, size_t n)
{
    while (n > 0 && (*text == ' ' || *text == '\t')) {
        ++text;
        --n;
    }
    static const char *const starts[] = {"def", "sec", "global", "local", "thread", NULL};
    for (const char *const *w = starts; *w; ++w)
        if (word_at(text, n, *w))
            return 1;
    static const char *const calls[] = {"movej", "movel", "movep", "movec", "set_tcp", "get_inverse_kin", NULL};
    for (size_t i = 0; i < n; ++i)
        for (const char *const *w = calls; *w; ++w) {
            const size_t k = strlen(*w);
            size_t j = i + k;
            const int after_word = i > 0 && (text[i - 1] == '_' || ((text[i - 1] | 32) >= 'a' && (text[i - 1] | 32) <= 'z') ||
                                             (text[i - 1] >= '0' && text[i - 1] <= '9'));
            if (i + k <= n && !after_word && strncmp(text + i, *w, k) == 0) {
                while (j < n && (text[j] == ' ' || text[j] == '\t'))
                    ++j;
                if (j < n && text[j] == '(')
                    return 1;
            }
        }
    return 0;
}
