/* SPDX-License-Identifier: MIT */
/* rch_comp_rapid.c - a RAPID module through the compensation (see
 * rch_comp.h): read whole (rch_rapid_scan), each joint target corrected,
 * each robtarget through the nominal IK with its confdata in its frames
 * (rch_comp_frames.c), corrected at its tool's TCP (a stream per TCP, made
 * when first needed) and written back; only the numbers' bytes change. All
 * or nothing: a target that cannot be corrected is named and nothing is
 * written.
 * Depends on: rch_rapid, rch_ik, one target (rch_comp.c), the point model
 * (rch_comp_model.c). Memory: the module, its edits and the streams for
 * other TCPs on the heap (the streams kept in the context for the module).
 * Errors: -1 with d set. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "rch_comp_int.h"
#include "rch_data.h"
#include "rch_ik.h"

/* A target rcal cannot correct: named with its line, column and reason. */
static void rapid_refuse(rch_cpi_ctx *c, unsigned long *n_bad, rch_diag *d, const rch_rapid_target *t, unsigned base,
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

/* Compensate at tcp (3, flange frame): the job's stream when it is the
 * job's point, else one made for it (kept for the module). 0, or -1 with
 * why set. */
int rch_cpi_use_tcp(rch_cpi_ctx *c, const double tcp[3], int has_tcp, char *why, size_t why_len)
{
    const double *jt = c->gate ? c->gate->tool_mm : NULL;
    c->stream = c->stream0;
    c->cal = c->cal0;
    c->fit = c->fit0;
    if ((!has_tcp && !jt) || (has_tcp && jt && tcp[0] == jt[0] && tcp[1] == jt[1] && tcp[2] == jt[2]) ||
        (!jt && tcp[0] == 0.0 && tcp[1] == 0.0 && tcp[2] == 0.0))
        return 0;
    for (size_t k = 0; k < c->ntcps; ++k)
        if (c->tcps[k]->tcp[0] == tcp[0] && c->tcps[k]->tcp[1] == tcp[1] && c->tcps[k]->tcp[2] == tcp[2]) {
            c->stream = &c->tcps[k]->s;
            c->cal = &c->tcps[k]->det;
            c->fit = c->gate && c->gate->fit_any ? &c->tcps[k]->fit : NULL;
            return 0;
        }
    const rch_comp_gate *g = c->gate;
    if (!g || !g->det_any || !g->cfg || !g->nominal || c->ntcps == RCH_CPI_MAX_TCPS) {
        snprintf(why, why_len, "its tool's TCP [%g,%g,%g] (flange frame) is not the point this compensation was set "
                 "up for%s", tcp[0], tcp[1], tcp[2],
                 c->ntcps == RCH_CPI_MAX_TCPS ? " (more than 16 TCPs in one program)" : "");
        return -1;
    }
    rch_cpi_tcp_stream *ts = calloc(1, sizeof *ts);
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

/* One robtarget: the nominal IK with its confdata gives the joints (of its
 * tool's TCP in its work object), the compensation corrects them at that
 * TCP, the nominal pose of the corrected joints in the same frames (its
 * confdata recomputed) is written. 0 ok, 1 flagged, 2 left as it was,
 * -1 refused (why set). */
static int rapid_robtarget(rch_cpi_ctx *c, double out[RCH_RAPID_NUMS], const rch_rapid_target *t, unsigned base,
                           char *why, size_t why_len)
{
    const rc_model *nom = c->gate ? c->gate->nominal : NULL;
    if (nom == NULL) {
        snprintf(why, why_len, "no nominal model to invert");
        return -1;
    }
    if (t->extax_used) {
        /* the pose is the TCP's in the work object; with a track the base
         * moves with eax, and the nominal IK of a fixed base (what the
         * correction inverts) is no longer the controller's */
        char v[48];
        if (isfinite(t->extax_val))
            snprintf(v, sizeof v, " = %g", t->extax_val);
        else
            snprintf(v, sizeof v, " is not a literal number");
        snprintf(why, why_len,
                 "external axis eax_%c%s (line %u, column %u): a robtarget with an external axis in use (a track "
                 "moving the base, a positioner) cannot be corrected: the model has no track, its corrections "
                 "assume the base fixed; only 9E9 (unused) is accepted",
                 'a' + (int)t->extax_used - 1, v, base + t->extax_line, t->extax_col);
        return -1;
    }
    rch_cpi_frames fr;
    if (rch_cpi_robtarget_frames(&fr, t, c->gate->tool_mm, base, why, why_len) != 0)
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
        rch_cpi_tool0_pose(px, qx, &fr, t);
        ik = rch_ik_solve(q, nom, px, qx, cf, NULL, why, why_len);
    }
    if (ik != 0 || rch_cpi_use_tcp(c, fr.tcp, fr.has_tcp, why, why_len) != 0)
        return -1;
    unsigned cols[RC_NJ];
    for (unsigned i = 0; i < RC_NJ; ++i) {
        qd[i] = q[i] / DEG;
        cols[i] = t->col;
    }
    const int r = rch_cpi_compensate_at(c, qo, qd, base + t->line, cols, why, why_len);
    if (r < 0 || r == 2)
        return r; /* 2: left uncompensated, copied as it was */
    c->res->n_robtargets++;
    double qr[RC_NJ], pos[3], quat[4];
    int cfo[4];
    for (unsigned i = 0; i < RC_NJ; ++i)
        qr[i] = qo[i] * DEG;
    if (fr.simple)
        rch_ik_fk(pos, quat, cfo, nom, qr, tcp);
    else { /* T' = W^-1 X' F */
        rch_ik_fk(pos, quat, cfo, nom, qr, NULL);
        rch_cpi_target_pose(pos, quat, &fr);
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

/* The module's jointtargets together in radians where RAPID means degrees
 * (issue 47, rch_data_q_look_rad): refused at the first one. 0, or -1 with
 * d set. */
static int rapid_radians(const rch_cpi_ctx *c, const rch_rapid_targets *ts, unsigned base, rch_diag *d)
{
    double max_abs_deg[RC_NJ] = {0};
    size_t n_joint = 0;
    const rch_rapid_target *first = NULL;
    for (size_t i = 0; i < ts->n; ++i)
        if (ts->t[i].kind == RCH_RAPID_JOINTTARGET && !ts->t[i].error[0]) {
            first = first ? first : &ts->t[i];
            ++n_joint;
            for (unsigned k = 0; k < RC_NJ; ++k)
                max_abs_deg[k] = fmax(max_abs_deg[k], fabs(ts->t[i].val[k]));
        }
    char why[320];
    if (!first || (c->gate && c->gate->assume_degrees) || !rch_data_q_look_rad(why, sizeof why, max_abs_deg, n_joint))
        return 0;
    rch_diag_set(d, c->in_name, base + first->line, first->col,
                 "jointtarget: %s (RAPID robax is in degrees); nothing written (if they are degrees: "
                 "--assume-degrees)", why);
    return -1;
}

/* A whole RAPID module text[0..len), its first line being line base + 1:
 * every joint target and robtarget corrected, every other byte copied. All
 * or nothing: a target that cannot be corrected is named (line, column,
 * reason) and nothing is written. 0, 1 (some flagged), -1. */
static int do_rapid_text(rch_cpi_ctx *c, const char *text, size_t len, unsigned base, rch_diag *d)
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
    if (rapid_radians(c, &ts, base, d) != 0) {
        rch_rapid_free(&ts);
        return -1;
    }
    rch_cpi_edits ed = {NULL, 0, 0};
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
            r = rch_cpi_compensate(c, out, t->val, base + t->line, cols, &dd);
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
            if (rch_cpi_edit_add(&ed, t->num_off[k], t->num_len[k], fmt, out[k]) != 0) {
                rch_diag_set(d, c->in_name, 0, 0, "out of memory");
                rch_cpi_edits_free(&ed);
                rch_rapid_free(&ts);
                return -1;
            }
        }
    }
    if (n_bad > 0) {
        rch_cpi_refused(c, d, n_bad, "target");
        rc = -1;
    } else
        rch_cpi_edits_write(c, text, len, &ed);
    rch_cpi_edits_free(&ed);
    rch_rapid_free(&ts);
    return rc;
}

/* The rest of a RAPID input: the line already read (raw, got bytes) and
 * everything after it, at most RCH_RAPID_MAX_BYTES. */
int rch_cpi_rapid(rch_cpi_ctx *c, const char *line, size_t got, FILE *in, unsigned lineno, rch_diag *d)
{
    return rch_cpi_whole(c, line, got, in, lineno, RCH_RAPID_MAX_BYTES, "a RAPID module", do_rapid_text, d);
}
