/* SPDX-License-Identifier: MIT */
/* rch_comp.c - a robot program's joint targets through the compensation
 * (rch_comp.h): CSV and RAPID line handling, file safety. */
#include "rch_comp.h"

#include "rc_rand.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/types.h>
#include <time.h>

#include "rch_file.h"
#include "rch_ik.h"
#include "rch_opt.h"
#include "rch_rapid.h"
#include "rch_robot.h"
#include "rch_stdio.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif
#define DEG (M_PI / 180.0)
#define MAX_FIELDS 64
/* longest input line (a RAPID target line is a few hundred bytes): a longer
 * one, or a stream without line ends (/dev/zero), is refused, not buffered */
#define MAX_LINE 65536

/* a stream compensating another TCP than the job's (a robtarget's tool) */
typedef struct {
    double tcp[3]; /* mm, flange frame */
    rc_model det, nom, fit;
    rc_comp_stream s;
} tcp_stream;
#define MAX_TCPS 16

typedef struct {
    rc_comp_stream *stream;
    const rc_model *cal, *fit; /* the stream's calibrated model, the full fit (may be NULL) at its point */
    rc_comp_stream *stream0;   /* the job's: its TCP */
    const rc_model *cal0, *fit0;
    tcp_stream *tcps[MAX_TCPS];
    size_t ntcps;
    const rch_comp_gate *gate;
    rch_comp_result *res;
    FILE *out, *warn;
    const char *in_name;
    int format; /* 0 auto, 1 csv, 2 rapid */
    int have_header;
    int qcol[RC_NJ]; /* header column of each joint */
    unsigned nfields_header;
} comp_ctx;

static double now_ns(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec * 1e9 + (double)t.tv_nsec;
}

/* Split a line at commas. start[k]/len[k]: field k (trimmed); returns the
 * number of fields, or -1 when more than MAX_FIELDS. */
static int split_csv(const char *line, size_t n, size_t start[MAX_FIELDS], size_t len[MAX_FIELDS])
{
    int k = 0;
    size_t i = 0;
    for (;;) {
        if (k >= MAX_FIELDS)
            return -1;
        size_t b = i;
        while (b < n && (line[b] == ' ' || line[b] == '\t'))
            ++b;
        size_t e = b;
        while (e < n && line[e] != ',')
            ++e;
        size_t end = e;
        while (end > b && (line[end - 1] == ' ' || line[end - 1] == '\t' || line[end - 1] == '\r'))
            --end;
        start[k] = b;
        len[k] = end - b;
        ++k;
        if (e >= n)
            break;
        i = e + 1;
    }
    return k;
}

/* Parse a number occupying exactly text[0..len) (the strict reader of
 * rch_opt.h: no blanks, no hex, finite). */
static int parse_num(double *v, const char *text, size_t len)
{
    char buf[64];
    if (len == 0 || len >= sizeof buf)
        return -1;
    memcpy(buf, text, len);
    buf[len] = '\0';
    return rch_parse_double(buf, v);
}

double rch_comp_u95_written(double u95_mm, int status, double miss_mm)
{
    if (status == 3)
        return NAN;
    if (status == 2)
        return u95_mm + (miss_mm > 0.0 ? miss_mm : 0.0);
    return u95_mm;
}

/* One line of --uncertainty-out (when asked for and the model has a posterior). */
static void u95_line(const comp_ctx *c, unsigned line, double u95_mm)
{
    if (c->gate && c->gate->u95_out && c->gate->unc && c->gate->unc->present)
        fprintf(c->gate->u95_out, "%u,%.6f\n", line, u95_mm);
}

/* Compensate one target (degrees in, degrees out). 0 ok, 1 not converged
 * (output still written), -1 range error (d set). cols: (6) columns of the
 * fields for diagnostics. */
static int compensate(comp_ctx *c, double out_deg[RC_NJ], const double in_deg[RC_NJ], unsigned line,
                      const unsigned cols[RC_NJ], rch_diag *d)
{
    rc_real q[RC_NJ], qc[RC_NJ];
    const rc_model *m = c->cal;
    for (unsigned i = 0; i < RC_NJ; ++i) {
        q[i] = (rc_real)(in_deg[i] * DEG);
        if ((double)q[i] < m->q_min_rad[i] || (double)q[i] > m->q_max_rad[i]) {
            rch_diag_set(d, c->in_name, line, cols[i], "q%u = %g deg is outside the joint limits [%g, %g] deg", i + 1,
                         in_deg[i], m->q_min_rad[i] / DEG, m->q_max_rad[i] / DEG);
            return -1;
        }
    }
    double u95_at = NAN; /* the posterior's radius at the target, when the model has one */
    if (c->gate) {
        double qd[RC_NJ], pf[3], pd[3];
        for (unsigned i = 0; i < RC_NJ; ++i)
            qd[i] = (double)q[i];
        if (c->fit) {
            rc_fk(pf, NULL, c->fit, qd);
            rc_fk(pd, NULL, m, qd);
            double e = sqrt((pf[0] - pd[0]) * (pf[0] - pd[0]) + (pf[1] - pd[1]) * (pf[1] - pd[1]) +
                            (pf[2] - pd[2]) * (pf[2] - pd[2]));
            if (e > c->res->max_held_mm)
                c->res->max_held_mm = e;
        }
        if (c->gate->unc && c->gate->unc->present) {
            double u95 = c->gate->unc->has_prior ? rch_model_unc_radius95_mm(c->gate->unc, m, qd)
                                                 : rch_model_unc_pos95_mm(c->gate->unc, m, qd);
            u95_at = u95;
            /* A posterior (MAP) model: compensation never makes the expected
             * error larger than the uncompensated target's (the posterior is
             * never wider than the prior the nominal model stands for), so
             * there is no limit unless the user sets one. A model without
             * (least squares): 1 mm, its covariance leaves out what it held. */
            double lim = c->gate->max_unc_mm > 0 ? c->gate->max_unc_mm : c->gate->unc->has_prior ? INFINITY : 1.0;
            if (!(u95 <= lim)) {
                for (unsigned i = 0; i < RC_NJ; ++i)
                    out_deg[i] = in_deg[i];
                u95_line(c, line, rch_comp_u95_written(u95, 3, 0.0));
                c->res->n_uncertain++;
                if (c->warn)
                    fprintf(c->warn,
                            "%s:%u: warning: target left uncompensated: the model's 95 %% position uncertainty here "
                            "is %.4f mm, above %.4f mm (the data did not determine the model at this pose)\n",
                            c->in_name, line, u95, lim);
                return 1;
            }
            if (u95 > c->res->max_pos95_mm)
                c->res->max_pos95_mm = u95;
        }
    }
    rc_comp_result res;
    const double t0 = now_ns();
    rc_status st = rc_comp_stream_step(c->stream, qc, &res, q);
    rch_comp_result *r = c->res;
    r->t_ns += now_ns() - t0;
    r->n++;
    r->iters += res.iterations;
    for (unsigned i = 0; i < RC_NJ; ++i)
        out_deg[i] = (double)qc[i] / DEG;
    if ((double)res.corr_max_rad / DEG > r->max_corr_deg)
        r->max_corr_deg = (double)res.corr_max_rad / DEG;
    if (st == RC_OK) {
        if (res.exit == RC_COMP_POSITION_ONLY)
            r->n_pos_only++;
        u95_line(c, line, rch_comp_u95_written(u95_at, res.exit == RC_COMP_POSITION_ONLY, 0.0));
        return 0;
    }
    u95_line(c, line, rch_comp_u95_written(u95_at, 2, (double)res.pos_err_mm));
    r->n_fail++;
    if ((double)res.pos_err_mm > r->max_fail_err_mm)
        r->max_fail_err_mm = (double)res.pos_err_mm;
    char joints[64] = "";
    if (res.exit == RC_COMP_JOINT_LIMIT || res.exit == RC_COMP_MAX_DEV) {
        const unsigned mask = res.exit == RC_COMP_JOINT_LIMIT ? res.limit_mask : res.bound_mask;
        size_t k = (size_t)snprintf(joints, sizeof joints, " (joint%s", (mask & (mask - 1u)) ? "s" : "");
        for (unsigned i = 0; i < RC_NJ && k < sizeof joints; ++i)
            if (mask & (1u << i))
                k += (size_t)snprintf(joints + k, sizeof joints - k, " %u", i + 1);
        if (k < sizeof joints)
            snprintf(joints + k, sizeof joints - k, ")");
    }
    if (res.exit == RC_COMP_JOINT_LIMIT)
        r->n_joint_limit++;
    if (c->warn != NULL)
        fprintf(c->warn,
                "%s:%u: warning: target not compensated: %s%s; wrote the target plus the last good correction, "
                "%.4f mm from the nominal position\n",
                c->in_name, line, st == RC_ERR_NOCONV ? rc_comp_exit_str(res.exit) : rc_strerror(st), joints,
                (double)res.pos_err_mm);
    return 1;
}

static int is_comment_or_blank(const char *s, size_t n)
{
    size_t i = 0;
    while (i < n && (s[i] == ' ' || s[i] == '\t' || s[i] == '\r'))
        ++i;
    return i == n || s[i] == '#';
}

static int starts_with_ci(const char *s, size_t n, const char *w)
{
    size_t k = strlen(w);
    while (n > 0 && (*s == ' ' || *s == '\t')) {
        ++s;
        --n;
    }
    return n >= k && strncasecmp(s, w, k) == 0;
}

static const char *find_ci(const char *s, size_t n, const char *w)
{
    size_t k = strlen(w);
    for (size_t i = 0; i + k <= n; ++i)
        if (strncasecmp(s + i, w, k) == 0)
            return s + i;
    return NULL;
}

/* One CSV line (not blank, not a comment). 0 ok, 1 not converged, -1 error. */
static int do_csv(comp_ctx *c, const char *line, size_t n, unsigned lineno, rch_diag *d)
{
    size_t st[MAX_FIELDS], ln[MAX_FIELDS];
    const int nf = split_csv(line, n, st, ln);
    if (nf < 0) {
        rch_diag_set(d, c->in_name, lineno, 1, "more than %d fields", MAX_FIELDS);
        return -1;
    }
    if (!c->have_header) {
        if (nf != RC_NJ) {
            rch_diag_set(d, c->in_name, lineno, (unsigned)(nf > RC_NJ ? st[RC_NJ] + 1 : n + 1),
                         "expected 6 joint angles q1..q6 in degrees, found %d field%s", nf, nf == 1 ? "" : "s");
            return -1;
        }
    } else if ((unsigned)nf != c->nfields_header) {
        rch_diag_set(d, c->in_name, lineno, (unsigned)((unsigned)nf > c->nfields_header ? st[c->nfields_header] + 1 : n + 1),
                     "expected %u fields as in the header, found %d", c->nfields_header, nf);
        return -1;
    }
    double qd[RC_NJ], qo[RC_NJ];
    unsigned cols[RC_NJ];
    for (unsigned i = 0; i < RC_NJ; ++i) {
        const int k = c->have_header ? c->qcol[i] : (int)i;
        cols[i] = (unsigned)st[k] + 1;
        if (parse_num(&qd[i], line + st[k], ln[k]) != 0) {
            rch_diag_set(d, c->in_name, lineno, cols[i], "q%u: '%.*s' is not a finite number", i + 1,
                         (int)(ln[k] > 40 ? 40 : ln[k]), line + st[k]);
            return -1;
        }
    }
    const int r = compensate(c, qo, qd, lineno, cols, d);
    if (r < 0)
        return r;
    for (int k = 0; k < nf; ++k) {
        int j = -1;
        for (int i = 0; i < RC_NJ; ++i)
            if ((c->have_header ? c->qcol[i] : i) == k)
                j = i;
        if (k > 0)
            fputc(',', c->out);
        if (j >= 0)
            fprintf(c->out, "%.6f", qo[j]);
        else
            fwrite(line + st[k], 1, ln[k], c->out);
    }
    fputc('\n', c->out);
    return r;
}

/* Header line: find q1..q6 (or j1..j6). 0 or -1. */
static int do_header(comp_ctx *c, const char *line, size_t n, unsigned lineno, rch_diag *d)
{
    size_t st[MAX_FIELDS], ln[MAX_FIELDS];
    const int nf = split_csv(line, n, st, ln);
    if (nf < 0) {
        rch_diag_set(d, c->in_name, lineno, 1, "more than %d header fields", MAX_FIELDS);
        return -1;
    }
    for (int i = 0; i < RC_NJ; ++i) {
        c->qcol[i] = -1;
        for (int k = 0; k < nf; ++k) {
            char qn[3] = {'q', (char)('1' + i), '\0'}, jn[3] = {'j', (char)('1' + i), '\0'};
            if (ln[k] == 2 && (strncasecmp(line + st[k], qn, 2) == 0 || strncasecmp(line + st[k], jn, 2) == 0)) {
                if (c->qcol[i] >= 0) {
                    rch_diag_set(d, c->in_name, lineno, (unsigned)st[k] + 1, "column q%d appears twice", i + 1);
                    return -1;
                }
                c->qcol[i] = k;
            }
        }
        if (c->qcol[i] < 0) {
            /* a first line of numbers (or nan, inf) is a target, not a header */
            char *end = NULL;
            (void)strtod(line + st[0], &end);
            const int numeric = nf > 0 && end != line + st[0] && (size_t)(end - line) == st[0] + ln[0];
            rch_diag_set(d, c->in_name, lineno, 1, "header has no q%d column (need q1..q6, degrees)%s", i + 1,
                         numeric ? ": this first line holds numbers, a target; put a header line "
                                   "q1,q2,q3,q4,q5,q6 above the targets"
                                 : "");
            return -1;
        }
    }
    c->have_header = 1;
    c->nfields_header = (unsigned)nf;
    fwrite(line, 1, n, c->out);
    fputc('\n', c->out);
    return 0;
}

/* One replacement of the rewritten module: text[off..off+len) -> rep. */
typedef struct {
    size_t off, len;
    char rep[40];
} edit;

static int add_edit(edit **e, size_t *n, size_t *cap, size_t off, size_t len, const char *fmt, double v)
{
    if (*n == *cap) {
        const size_t nc = *cap ? 2 * *cap : 64;
        edit *ne = realloc(*e, nc * sizeof *ne);
        if (!ne)
            return -1;
        *e = ne;
        *cap = nc;
    }
    edit *x = &(*e)[(*n)++];
    x->off = off;
    x->len = len;
    snprintf(x->rep, sizeof x->rep, fmt, v);
    return 0;
}

/* A target rcal cannot correct: named with its line, column and reason. */
static void rapid_refuse(comp_ctx *c, unsigned long *n_bad, rch_diag *d, const rch_rapid_target *t, unsigned base,
                         const char *why)
{
    char what[96];
    snprintf(what, sizeof what, "%s%s%s", rch_rapid_kind_name(t->kind), t->name[0] ? " " : "", t->name);
    if (*n_bad == 0)
        rch_diag_set(d, c->in_name, base + t->line, t->col, "%s (%s): %s", what, rch_rapid_context_name(t->context),
                     why);
    if (c->warn)
        fprintf(c->warn, "%s:%u:%u: error: %s (%s) cannot be corrected: %s\n", c->in_name, base + t->line, t->col,
                what, rch_rapid_context_name(t->context), why);
    ++*n_bad;
}

/* A rigid pose: trans (mm), rotation (3 x 3, row-major). */
typedef struct {
    double p[3], R[9];
} pose;

static void pose_mul(pose *o, const pose *a, const pose *b)
{
    pose r;
    for (int i = 0; i < 3; ++i) {
        r.p[i] = a->p[i];
        for (int j = 0; j < 3; ++j) {
            r.p[i] += a->R[3 * i + j] * b->p[j];
            r.R[3 * i + j] = 0;
            for (int k = 0; k < 3; ++k)
                r.R[3 * i + j] += a->R[3 * i + k] * b->R[3 * k + j];
        }
    }
    *o = r;
}

static void pose_inv(pose *o, const pose *a)
{
    pose r;
    for (int i = 0; i < 3; ++i) {
        r.p[i] = 0;
        for (int j = 0; j < 3; ++j) {
            r.R[3 * i + j] = a->R[3 * j + i];
            r.p[i] -= a->R[3 * j + i] * a->p[j];
        }
    }
    *o = r;
}

/* v (7): trans, ABB quaternion (its norm within 1e-3 of 1, normalised). 0 or -1. */
static int pose_from(pose *o, const double v[7])
{
    const double n = sqrt(v[3] * v[3] + v[4] * v[4] + v[5] * v[5] + v[6] * v[6]);
    if (!(fabs(n - 1.0) <= 1e-3))
        return -1;
    const double q[4] = {v[3] / n, v[4] / n, v[5] / n, v[6] / n};
    memcpy(o->p, v, 3 * sizeof o->p[0]);
    rch_ik_quat_to_rot(o->R, q);
    return 0;
}

static int rot_is_identity(const double v[7])
{
    return v[3] == 1.0 && v[4] == 0.0 && v[5] == 0.0 && v[6] == 0.0;
}

/* How robtarget t is read: the pose of its TCP (F, in tool0's frame) in its
 * work object (W, in the base frame). */
typedef struct {
    pose W, F;
    int simple;       /* W is the base and F has tool0's orientation: the TCP path of rch_ik */
    double tcp[3];    /* F's origin in the flange frame (mm): the point compensated */
    int has_tcp;      /* not the flange */
} rt_frames;

/* The tool and work object the instruction that uses robtarget t names, as
 * the module declares them (or --tool for a tool it does not): 0, or -1
 * with why set. tool: --tool (3) or NULL. */
static int robtarget_frames(rt_frames *fr, const rch_rapid_target *t, const double *tool, unsigned base, char *why,
                            size_t why_len)
{
    double fv[7] = {0, 0, 0, 1, 0, 0, 0}, wv[7] = {0, 0, 0, 1, 0, 0, 0};
    if (t->use_error[0]) {
        snprintf(why, why_len, "%s", t->use_error);
        return -1;
    }
    pose_from(&fr->W, wv);
    fr->simple = 1;
    if (t->wobj[0] && strcasecmp(t->wobj, "wobj0") != 0) {
        if (!t->wobj_declared) {
            snprintf(why, why_len, "used in work object %s (line %u), which this module does not declare with a "
                     "literal wobjdata: rcal needs its uframe and oframe (declare it in this module)", t->wobj,
                     base + t->use_line);
            return -1;
        }
        if (t->wobj_robhold) {
            snprintf(why, why_len, "used in work object %s (line %u), which the robot holds (robhold TRUE: a "
                     "stationary tool): rcal corrects robtargets of a tool the robot holds", t->wobj,
                     base + t->use_line);
            return -1;
        }
        if (!t->wobj_ufprog) {
            snprintf(why, why_len, "used in work object %s (line %u), whose user frame moves (ufprog FALSE, ufmec "
                     "\"%.40s\"): rcal corrects robtargets in a fixed frame", t->wobj, base + t->use_line,
                     t->wobj_ufmec);
            return -1;
        }
        pose U, O;
        if (pose_from(&U, t->wobj_uframe) != 0 || pose_from(&O, t->wobj_oframe) != 0) {
            snprintf(why, why_len, "used in work object %s (line %u), whose uframe or oframe rot is not a unit "
                     "quaternion", t->wobj, base + t->use_line);
            return -1;
        }
        pose_mul(&fr->W, &U, &O);
        fr->simple = 0;
    }
    if (t->tool_declared) {
        if (!t->tool_robhold) {
            snprintf(why, why_len, "used with tool %s (line %u), a stationary tool (robhold FALSE): its robtargets "
                     "are not TCP poses", t->tool, base + t->use_line);
            return -1;
        }
        memcpy(fv, t->tool_frame, sizeof fv);
        if (!rot_is_identity(fv))
            fr->simple = 0;
    } else if (t->tool[0] && strcasecmp(t->tool, "tool0") != 0) {
        if (!tool) {
            snprintf(why, why_len, "used with tool %s (line %u), which this module does not declare with a literal "
                     "tooldata: a robtarget is the pose of that tool's TCP; give --tool X,Y,Z (its TCP in the "
                     "flange frame, tool0's orientation) or declare %s in this module", t->tool, base + t->use_line,
                     t->tool);
            return -1;
        }
        /* tool0 is the flange turned 180 deg about z (RCH_IK_TOOL0_RZ_DEG) */
        fv[0] = -tool[0];
        fv[1] = -tool[1];
        fv[2] = tool[2];
    } else if (!t->tool[0] && tool) { /* no instruction of the module uses it: --tool */
        fv[0] = -tool[0];
        fv[1] = -tool[1];
        fv[2] = tool[2];
    }
    if (pose_from(&fr->F, fv) != 0) {
        snprintf(why, why_len, "used with tool %s (line %u), whose tframe rot is not a unit quaternion", t->tool,
                 base + t->use_line);
        return -1;
    }
    fr->tcp[0] = -fv[0];
    fr->tcp[1] = -fv[1];
    fr->tcp[2] = fv[2];
    fr->has_tcp = fv[0] != 0.0 || fv[1] != 0.0 || fv[2] != 0.0 || (tool && !t->tool[0]);
    return 0;
}

/* Compensate at tcp (3, flange frame): the job's stream when it is the
 * job's point, else one made for it (kept for the module). 0, or -1 with
 * why set. */
static int use_tcp(comp_ctx *c, const double tcp[3], int has_tcp, char *why, size_t why_len)
{
    const double *jt = c->gate ? c->gate->tool_mm : NULL;
    c->stream = c->stream0;
    c->cal = c->cal0;
    c->fit = c->fit0;
    if ((!has_tcp && !jt) || (has_tcp && jt && tcp[0] == jt[0] && tcp[1] == jt[1] && tcp[2] == jt[2]) ||
        (!jt && tcp[0] == 0.0 && tcp[1] == 0.0 && tcp[2] == 0.0))
        return 0;
    for (size_t k = 0; k < c->ntcps; ++k)
        if (memcmp(c->tcps[k]->tcp, tcp, sizeof c->tcps[k]->tcp) == 0) {
            c->stream = &c->tcps[k]->s;
            c->cal = &c->tcps[k]->det;
            c->fit = &c->tcps[k]->fit;
            return 0;
        }
    const rch_comp_gate *g = c->gate;
    if (!g || !g->det_any || !g->cfg || !g->nominal || c->ntcps == MAX_TCPS) {
        snprintf(why, why_len, "its tool's TCP [%g,%g,%g] (flange frame) is not the point this compensation was set "
                 "up for%s", tcp[0], tcp[1], tcp[2], c->ntcps == MAX_TCPS ? " (more than 16 TCPs in one module)" : "");
        return -1;
    }
    tcp_stream *ts = calloc(1, sizeof *ts);
    if (!ts) {
        snprintf(why, why_len, "out of memory");
        return -1;
    }
    memcpy(ts->tcp, tcp, sizeof ts->tcp);
    rch_comp_point_model(&ts->det, g->det_any, tcp);
    rch_comp_point_model(&ts->nom, g->nominal, tcp);
    rch_comp_point_model(&ts->fit, g->fit_any ? g->fit_any : g->det_any, tcp);
    const rc_status st = rc_comp_stream_init(&ts->s, &ts->det, &ts->nom, g->cfg);
    if (st != RC_OK) {
        snprintf(why, why_len, "the model cannot be used for compensation at its tool's TCP: %s", rc_strerror(st));
        free(ts);
        return -1;
    }
    c->tcps[c->ntcps++] = ts;
    c->stream = &ts->s;
    c->cal = &ts->det;
    c->fit = g->fit_any ? &ts->fit : NULL;
    return 0;
}

/* The flange (tool0) pose of robtarget t read with fr: pos, quat (4). */
static void tool0_pose(double pos[3], double quat[4], const rt_frames *fr, const rch_rapid_target *t)
{
    pose T, Fi, X;
    pose_from(&T, t->val); /* its norm is checked by rch_ik_solve */
    pose_mul(&X, &fr->W, &T);
    pose_inv(&Fi, &fr->F);
    pose_mul(&X, &X, &Fi);
    memcpy(pos, X.p, sizeof X.p);
    rch_ik_rot_to_quat(quat, X.R);
}

/* One robtarget: the nominal IK with its confdata gives the joints (of its
 * tool's TCP in its work object), the compensation corrects them at that
 * TCP, the nominal pose of the corrected joints in the same frames (its
 * confdata recomputed) is written. 0 ok, 1 flagged, 2 left as it was,
 * -1 refused (why set). */
static int rapid_robtarget(comp_ctx *c, double out[RCH_RAPID_NUMS], const rch_rapid_target *t, unsigned base,
                           char *why, size_t why_len)
{
    const rc_model *nom = c->gate ? c->gate->nominal : NULL;
    if (nom == NULL) {
        snprintf(why, why_len, "no nominal model to invert");
        return -1;
    }
    rt_frames fr;
    if (robtarget_frames(&fr, t, c->gate->tool_mm, base, why, why_len) != 0)
        return -1;
    int cf[4];
    for (int k = 0; k < 4; ++k) {
        const double v = t->val[7 + k];
        if (!(v == floor(v)) || fabs(v) > 1000) {
            snprintf(why, why_len, "confdata value %g is not an integer", v);
            return -1;
        }
        cf[k] = (int)v;
    }
    const double qn = sqrt(t->val[3] * t->val[3] + t->val[4] * t->val[4] + t->val[5] * t->val[5] + t->val[6] * t->val[6]);
    if (!fr.simple && !(fabs(qn - 1.0) <= 1e-3)) {
        snprintf(why, why_len, "its rot is not a unit quaternion (norm %g)", qn);
        return -1;
    }
    const double *tcp = fr.has_tcp ? fr.tcp : NULL;
    double q[RC_NJ], qd[RC_NJ], qo[RC_NJ], px[3], qx[4];
    int ik;
    if (fr.simple)
        ik = rch_ik_solve(q, nom, &t->val[0], &t->val[3], cf, tcp, why, why_len);
    else {
        tool0_pose(px, qx, &fr, t);
        ik = rch_ik_solve(q, nom, px, qx, cf, NULL, why, why_len);
    }
    if (ik != 0 || use_tcp(c, fr.tcp, fr.has_tcp, why, why_len) != 0)
        return -1;
    unsigned cols[RC_NJ];
    for (unsigned i = 0; i < RC_NJ; ++i) {
        qd[i] = q[i] / DEG;
        cols[i] = t->col;
    }
    rch_diag dd;
    const unsigned long before_unc = c->res->n_uncertain;
    const int r = compensate(c, qo, qd, base + t->line, cols, &dd);
    c->stream = c->stream0;
    c->cal = c->cal0;
    c->fit = c->fit0;
    if (r < 0) {
        snprintf(why, why_len, "%.300s", dd.msg);
        return -1;
    }
    if (c->res->n_uncertain != before_unc)
        return 2; /* left uncompensated: copied as it was */
    c->res->n_robtargets++;
    double qr[RC_NJ], pos[3], quat[4];
    int cfo[4];
    for (unsigned i = 0; i < RC_NJ; ++i)
        qr[i] = qo[i] * DEG;
    if (fr.simple)
        rch_ik_fk(pos, quat, cfo, nom, qr, tcp);
    else { /* T' = W^-1 X' F */
        rch_ik_fk(pos, quat, cfo, nom, qr, NULL);
        double v[7] = {pos[0], pos[1], pos[2], quat[0], quat[1], quat[2], quat[3]};
        pose X, Wi, T;
        pose_from(&X, v);
        pose_inv(&Wi, &fr.W);
        pose_mul(&T, &Wi, &X);
        pose_mul(&T, &T, &fr.F);
        memcpy(pos, T.p, sizeof T.p);
        rch_ik_rot_to_quat(quat, T.R);
    }
    /* the quaternion's sign as written */
    const double dot = quat[0] * t->val[3] + quat[1] * t->val[4] + quat[2] * t->val[5] + quat[3] * t->val[6];
    for (int k = 0; k < 3; ++k)
        out[k] = pos[k];
    for (int k = 0; k < 4; ++k)
        out[3 + k] = dot < 0 ? -quat[k] : quat[k];
    for (int k = 0; k < 4; ++k)
        out[7 + k] = cfo[k];
    return r;
}

/* A whole RAPID module text[0..len), its first line being line base + 1:
 * every joint target and robtarget corrected, every other byte copied. All
 * or nothing: a target that cannot be corrected is named (line, column,
 * reason) and nothing is written. 0, 1 (some flagged), -1. */
static int do_rapid_text(comp_ctx *c, const char *text, size_t len, unsigned base, rch_diag *d)
{
    rch_rapid_targets ts;
    memset(&ts, 0, sizeof ts);
    if (rch_rapid_scan(&ts, text, len, c->in_name, d) != 0) {
        d->line += d->line ? base : 0;
        return -1;
    }
    if (ts.n == 0) { /* a module with nothing to correct is most likely not the one meant */
        rch_diag_set(d, c->in_name, 0, 0, "no jointtarget or robtarget in this module (declarations, assignments, "
                     "instruction arguments): nothing to correct; nothing written");
        rch_rapid_free(&ts);
        return -1;
    }
    edit *ed = NULL;
    size_t ne = 0, cap = 0;
    unsigned long n_bad = 0;
    int rc = 0;
    for (size_t i = 0; i < ts.n; ++i) {
        const rch_rapid_target *t = &ts.t[i];
        if (t->error[0]) {
            rapid_refuse(c, &n_bad, d, t, base, t->error);
            continue;
        }
        char why[512];
        double out[RCH_RAPID_NUMS];
        int r;
        if (t->kind == RCH_RAPID_JOINTTARGET) {
            unsigned cols[RC_NJ];
            for (unsigned k = 0; k < RC_NJ; ++k)
                cols[k] = t->num_col[k];
            rch_diag dd;
            r = compensate(c, out, t->val, base + t->line, cols, &dd);
            if (r < 0) {
                rapid_refuse(c, &n_bad, d, t, base, dd.msg);
                continue;
            }
        } else {
            r = rapid_robtarget(c, out, t, base, why, sizeof why);
            if (r < 0) {
                rapid_refuse(c, &n_bad, d, t, base, why);
                continue;
            }
            if (r == 2) {
                rc = 1;
                continue;
            }
        }
        if (r > 0)
            rc = 1;
        for (unsigned k = 0; k < t->n; ++k) {
            const char *fmt = t->kind == RCH_RAPID_JOINTTARGET ? "%.4f" : k < 3 ? "%.4f" : k < 7 ? "%.7f" : "%.0f";
            if (add_edit(&ed, &ne, &cap, t->num_off[k], t->num_len[k], fmt, out[k]) != 0) {
                rch_diag_set(d, c->in_name, 0, 0, "out of memory");
                free(ed);
                rch_rapid_free(&ts);
                return -1;
            }
        }
    }
    if (n_bad > 0 && c->warn) {
        /* each target is named above; the error says how many, once */
        rch_diag_set(d, c->in_name, 0, 0, "%lu target%s cannot be corrected (each named above with its line, column "
                     "and reason); nothing written", n_bad, n_bad == 1 ? "" : "s");
        rc = -1;
    } else if (n_bad > 0) {
        if (n_bad > 1) {
            char more[80];
            snprintf(more, sizeof more, " (and %lu more targets; nothing written)", n_bad - 1);
            strncat(d->msg, more, sizeof d->msg - strlen(d->msg) - 1);
        } else
            strncat(d->msg, " (nothing written)", sizeof d->msg - strlen(d->msg) - 1);
        rc = -1;
    } else {
        size_t at = 0;
        for (size_t k = 0; k < ne; ++k) {
            fwrite(text + at, 1, ed[k].off - at, c->out);
            fputs(ed[k].rep, c->out);
            at = ed[k].off + ed[k].len;
        }
        fwrite(text + at, 1, len - at, c->out);
        if (len > 0 && text[len - 1] != '\n')
            fputc('\n', c->out);
    }
    free(ed);
    rch_rapid_free(&ts);
    return rc;
}

/* The rest of a RAPID input: the line already read (raw, got bytes) and
 * everything after it, at most RCH_RAPID_MAX_BYTES. */
static int do_rapid(comp_ctx *c, const char *line, size_t got, FILE *in, unsigned lineno, rch_diag *d)
{
    size_t cap = got + 65536, n = got;
    char *buf = malloc(cap);
    if (!buf) {
        rch_diag_set(d, c->in_name, lineno, 1, "out of memory");
        return -1;
    }
    memcpy(buf, line, got);
    for (;;) {
        if (n == cap) {
            if (cap > RCH_RAPID_MAX_BYTES) {
                free(buf);
                rch_diag_set(d, c->in_name, 0, 0, "a RAPID module of more than %u bytes is refused",
                             RCH_RAPID_MAX_BYTES);
                return -1;
            }
            char *nb = realloc(buf, 2 * cap);
            if (!nb) {
                free(buf);
                rch_diag_set(d, c->in_name, lineno, 1, "out of memory");
                return -1;
            }
            buf = nb;
            cap *= 2;
        }
        const size_t k = fread(buf + n, 1, cap - n, in);
        n += k;
        if (k == 0)
            break;
    }
    const int rc = do_rapid_text(c, buf, n, lineno - 1, d);
    free(buf);
    return rc;
}

/* One line of at most MAX_LINE bytes into *line (grown as needed, '\n'
 * kept): its length, -1 at the end of the input, -2 when longer. */
static long read_line(char **line, size_t *cap, FILE *in)
{
    size_t n = 0;
    int ch = EOF;
    while (n <= MAX_LINE && (ch = getc(in)) != EOF) {
        if (n + 2 > *cap) {
            const size_t nc = *cap ? 2 * *cap : 256;
            char *nl = realloc(*line, nc);
            if (!nl)
                return -2;
            *line = nl;
            *cap = nc;
        }
        (*line)[n++] = (char)ch;
        if (ch == '\n')
            break;
    }
    if (n == 0 && ch == EOF)
        return -1;
    if (n > MAX_LINE)
        return -2;
    (*line)[n] = '\0';
    return (long)n;
}

/* A write of the output failed (full disk, closed pipe or descriptor): 1
 * with d set, the stream stops there; no line is ever lost silently. */
static int out_failed(const comp_ctx *c, unsigned lineno, rch_diag *d)
{
    if (!ferror(c->out))
        return 0;
    rch_diag_set(d, c->out == stdout ? "<stdout>" : "", 0, 0,
                 "write failed at input line %u (%s): stopped there, the output is incomplete", lineno,
                 strerror(rch_stdio_errno(c->out)));
    return 1;
}

int rch_comp_lines(FILE *out, rch_comp_result *res, FILE *in, const char *in_name, rc_comp_stream *s,
                   const rc_model *cal, rch_comp_format format, FILE *warn, rch_diag *d)
{
    return rch_comp_lines_gated(out, res, in, in_name, s, cal, NULL, format, warn, d);
}

int rch_comp_lines_gated(FILE *out, rch_comp_result *res, FILE *in, const char *in_name, rc_comp_stream *s,
                         const rc_model *cal, const rch_comp_gate *gate, rch_comp_format format, FILE *warn,
                         rch_diag *d)
{
    comp_ctx c = {.stream = s, .cal = cal, .fit = gate ? gate->fit : NULL, .stream0 = s, .cal0 = cal,
                  .fit0 = gate ? gate->fit : NULL, .gate = gate, .res = res, .out = out, .warn = warn,
                  .in_name = in_name, .format = (int)format};
    char *line = NULL;
    size_t cap = 0;
    long got;
    unsigned lineno = 0;
    int rc = 0, decided = c.format != 0;
    while ((got = read_line(&line, &cap, in)) != -1) {
        size_t n = (size_t)got;
        ++lineno;
        if (got == -2) {
            rch_diag_set(d, c.in_name, lineno, 1, "line longer than %d bytes (no line end?): refused", MAX_LINE);
            rc = -1;
            break;
        }
        while (n > 0 && (line[n - 1] == '\n' || line[n - 1] == '\r'))
            --n;
        if (memchr(line, '\0', n) != NULL) {
            rch_diag_set(d, c.in_name, lineno, (unsigned)((const char *)memchr(line, '\0', n) - line) + 1,
                         "NUL byte in text input");
            rc = -1;
            break;
        }
        if (c.format != 2 && is_comment_or_blank(line, n)) {
            fwrite(line, 1, n, c.out);
            fputc('\n', c.out);
            if (out_failed(&c, lineno, d)) {
                rc = -1;
                break;
            }
            continue;
        }
        int r;
        if (!decided) {
            decided = 1;
            if (starts_with_ci(line, n, "MODULE") || starts_with_ci(line, n, "%%%") || starts_with_ci(line, n, "!") ||
                find_ci(line, n, "jointtarget") ||
                find_ci(line, n, "robtarget")) {
                c.format = 2;
            } else {
                size_t st[MAX_FIELDS], ln[MAX_FIELDS];
                double v;
                c.format = 1;
                if (split_csv(line, n, st, ln) > 0 && parse_num(&v, line + st[0], ln[0]) != 0) {
                    if (do_header(&c, line, n, lineno, d) < 0 || out_failed(&c, lineno, d)) {
                        rc = -1;
                        break;
                    }
                    continue;
                }
            }
        }
        if (c.format == 2) { /* a module is read whole: all or nothing */
            rc = do_rapid(&c, line, (size_t)got, in, lineno, d);
            if (rc >= 0 && out_failed(&c, lineno, d))
                rc = -1;
            break;
        }
        r = do_csv(&c, line, n, lineno, d);
        if (r < 0) {
            rc = -1;
            break;
        }
        if (r > 0)
            rc = 1;
        if (out_failed(&c, lineno, d)) {
            rc = -1;
            break;
        }
    }
    free(line);
    for (size_t k = 0; k < c.ntcps; ++k)
        free(c.tcps[k]);
    res->format = (rch_comp_format)c.format;
    if (rc >= 0 && ferror(in)) {
        rch_diag_set(d, c.in_name, 0, 0, "read error: %s", strerror(errno));
        rc = -1;
    }
    return rc;
}

int rch_comp_run(rch_comp_result *res, const rch_comp_job *job, FILE *warn, rch_diag *d)
{
    static rch_robot robot, nominal_robot;
    memset(res, 0, sizeof *res);
    if (job->model_path == NULL) {
        rch_diag_set(d, "", 0, 0, "no calibrated model given");
        return -1;
    }
    if (!(job->max_dev_deg >= 0.0) || !isfinite(job->max_dev_deg)) {
        rch_diag_set(d, "", 0, 0, "the largest correction must be a finite positive angle (0: default)");
        return -1;
    }
    if (rch_robot_load(&robot, job->model_path, d) != 0 ||
        (job->nominal_path && rch_robot_load(&nominal_robot, job->nominal_path, d) != 0))
        return -1;
    const rc_model *nom = job->nominal_path ? &nominal_robot.model : &robot.nominal;
    const rc_model *nom_raw = nom; /* what the program was made with: the robtargets' IK */
    res->no_nominal = !job->nominal_path && !robot.has_nominal;
    static rc_model det;
    static rch_model_unc unc;
    det = robot.model;
    memset(&unc, 0, sizeof unc);
    if (robot.has_nominal || robot.unc.present)
        res->n_held = rch_comp_determined(&det, &unc, &res->version1, res->held, sizeof res->held, &robot,
                                          &robot.nominal);
    res->orientation_determined = unc.present && !res->version1 && unc.orientation_determined;
    res->position_only_used = job->position_only || (!job->full_pose && !res->orientation_determined &&
                                                     (robot.has_nominal || robot.unc.present));
    /* the point compensation moves: the flange (or the given TCP) of both
     * models, never the cable attachment the calibration measured */
    static rc_model nom_pt, det_any;
    det_any = det;
    rch_comp_point_model(&det, &det, job->tool_mm);
    rch_comp_point_model(&nom_pt, nom, job->tool_mm);
    nom = &nom_pt;
    rc_comp_config cfg;
    memset(&cfg, 0, sizeof cfg);
    cfg.max_dev_rad = (rc_real)(job->max_dev_deg * DEG);
    cfg.flags = res->position_only_used ? RC_COMP_FLAG_POSITION_ONLY : 0u;
    static rc_comp_stream s;
    rc_status st = rc_comp_stream_init(&s, &det, nom, &cfg);
    if (st != RC_OK) {
        rch_diag_set(d, job->model_path, 0, 0, "the model cannot be used for compensation: %s", rc_strerror(st));
        return -1;
    }

    const int from_stdin = job->in_path == NULL || strcmp(job->in_path, "-") == 0;
    const char *in_name = from_stdin ? "<stdin>" : job->in_path;
    FILE *in = stdin;
    if (!from_stdin && (in = fopen(job->in_path, "r")) == NULL) {
        rch_diag_set(d, job->in_path, 0, 0, "%s", strerror(errno));
        return -1;
    }
    const char *const inputs[3] = {from_stdin ? NULL : job->in_path, job->model_path, job->nominal_path};
    rch_out o;
    if (rch_out_open(&o, job->out_path ? job->out_path : "-", "--out", inputs, 3, d) != 0) {
        if (in != stdin)
            fclose(in);
        return -1;
    }
    if (o.f == stdout)
        setvbuf(stdout, NULL, _IOLBF, 0);
    static rc_model fit_pt;
    rch_comp_point_model(&fit_pt, &robot.model, job->tool_mm);
    rch_out uo;
    int have_uo = 0;
    if (job->uncertainty_path) {
        const char *const uin[4] = {from_stdin ? NULL : job->in_path, job->model_path, job->nominal_path, job->out_path};
        if (rch_out_open(&uo, job->uncertainty_path, "--uncertainty-out", uin, 4, d) != 0) {
            if (in != stdin)
                fclose(in);
            if (o.f != stdout)
                rch_out_abort(&o);
            return -1;
        }
        have_uo = 1;
        fprintf(uo.f, "line,u95_mm\n");
    }
    const rch_comp_gate gate = {&fit_pt, unc.present && !res->version1 ? &unc : NULL, job->max_unc_mm,
                                job->accept_robtargets, have_uo ? uo.f : NULL, nom_raw, job->tool_mm,
                                &det_any, &robot.model, &cfg};
    int rc = rch_comp_lines_gated(o.f, res, in, in_name, &s, &det, &gate, job->format, warn, d);
    if (in != stdin)
        fclose(in);
    if (rc < 0) {
        if (o.f != stdout)
            rch_out_abort(&o);
        else
            fflush(stdout);
        if (have_uo)
            rch_out_abort(&uo);
        return -1;
    }
    if (rch_out_commit(&o, d) != 0) {
        if (have_uo)
            rch_out_abort(&uo);
        return -1;
    }
    if (have_uo && rch_out_commit(&uo, d) != 0)
        return -1;
    return rc;
}

void rch_model_rebuild(rc_model *out, const rc_model *m, int drop_nuisance, int drop_point, const double *tool_mm)
{
    double dh[RC_NJ][4];
    for (unsigned i = 0; i < RC_NJ; ++i)
        for (unsigned k = 0; k < 4; ++k)
            dh[i][k] = m->x[4 * i + k];
    rc_model r;
    rc_model_init(&r, (const double(*)[4])dh, &m->x[RC_P_ENC]);
    memcpy(r.q_min_rad, m->q_min_rad, sizeof r.q_min_rad);
    memcpy(r.q_max_rad, m->q_max_rad, sizeof r.q_max_rad);
    if (tool_mm && rc_model_add_effect(&r, RC_EFF_TOOL_OFFSET, 0, 0) == RC_OK)
        memcpy(&r.x[r.effects[0].first], tool_mm, 3 * sizeof r.x[0]);
    for (unsigned e = 0; e < m->n_effects; ++e) {
        const rc_effect *ef = &m->effects[e];
        const rc_effect_desc *ds = rc_effect_describe(ef->kind);
        if ((drop_point && ef->kind == RC_EFF_TOOL_OFFSET) || (drop_nuisance && ds && ds->nuisance))
            continue;
        if (rc_model_add_effect(&r, (rc_effect_kind)ef->kind, ef->joint, ef->count) != RC_OK)
            continue;
        rc_effect *ne = &r.effects[r.n_effects - 1];
        memcpy(ne->ref_dh, ef->ref_dh, sizeof ne->ref_dh);
        memcpy(&r.x[ne->first], &m->x[ef->first], ef->count * sizeof r.x[0]);
    }
    *out = r;
}

void rch_comp_point_model(rc_model *out, const rc_model *m, const double *tool_mm)
{
    rch_model_rebuild(out, m, 0, 1, tool_mm);
}

unsigned rch_comp_determined(rc_model *det, rch_model_unc *unc, int *version1, char *held, size_t held_len,
                             const rch_robot *robot, const rc_model *nominal)
{
    *version1 = 0;
    if (robot->unc.present) {
        *unc = robot->unc;
    } else {
        /* version 1: what the nominal model's geometry lets cable lengths see */
        enum { N = 400 };
        static rc_sample s[N];
        rc_model m = *nominal;
        memcpy(&m.x[RC_P_ENC], &robot->model.x[RC_P_ENC], 3 * sizeof m.x[0]);
        memcpy(m.q_min_rad, robot->model.q_min_rad, sizeof m.q_min_rad);
        memcpy(m.q_max_rad, robot->model.q_max_rad, sizeof m.q_max_rad);
        rc_rng g;
        rc_rng_seed(&g, 20261129u);
        size_t k = 0;
        for (size_t i = 0; i < N; ++i) {
            for (unsigned j = 0; j < RC_NJ; ++j)
                s[k].q_rad[j] = m.q_min_rad[j] + (m.q_max_rad[j] - m.q_min_rad[j]) * rc_rng_u01(&g);
            if (rc_meas(&s[k].len_mm, NULL, &m, &s[k]) == RC_OK)
                ++k;
        }
        rch_uncert u;
        char err[128];
        memset(unc, 0, sizeof *unc);
        if (rch_uncert_compute(&u, &m, NULL, s, k, 0, err, sizeof err) == 0) {
            rch_model_unc_from(unc, &u);
            rch_uncert_free(&u);
        }
        memset(unc->cov_dh, 0, sizeof unc->cov_dh);
        /* compensation uses the whole estimate: nothing is held because it
         * shares a weak combination (a fit's weak directions stay where its
         * solver or prior left them) */
        memset(unc->comp_nominal, 0, sizeof unc->comp_nominal);
        *version1 = 1;
    }
    rch_model_unc_determined(det, &robot->model, nominal, unc);
    unsigned n = 0;
    size_t len = 0;
    if (held_len)
        held[0] = '\0';
    for (unsigned k = 0; k < RC_N_DH && k < unc->n; ++k)
        if (unc->comp_nominal[k]) {
            char nm[32];
            rc_param_name(nm, sizeof nm, &robot->model, k);
            if (len < held_len)
                len += (size_t)snprintf(held + len, held_len - len, "%s%s", n ? " " : "", nm);
            ++n;
        }
    return n;
}
