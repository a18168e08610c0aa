/* SPDX-License-Identifier: MIT */
/* rch_comp_krl.c - a KUKA KRL file (.src or .dat) through the compensation
 * (see rch_krl.h, rch_comp.h): read whole (rch_krl_scan); each axis target
 * (AXIS, E6AXIS) corrected in the controller's joint convention (the robot
 * file's "controller", rch_ctrl.h); each Cartesian target (POS, E6POS)
 * read in its $TOOL and $BASE, through the nominal IK on the branch its
 * Status and Turn name, corrected at its TCP, and written back as the
 * nominal pose of the corrected joints in the same frames with Status and
 * Turn recomputed. Only the numbers' bytes change. All or nothing: a target
 * that cannot be corrected is named and nothing is written.
 * Depends on: rch_krl, rch_ikg, one target (rch_comp.c), the TCP streams
 * (rch_cpi_use_tcp, rch_comp_rapid.c). Memory: the file, its edits and the
 * IK on the heap. Errors: -1 with d set. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "rch_comp_int.h"
#include "rch_krl.h"

/* (p, R) = (p1, R1) (p2, R2) */
static void compose(double p[3], double R[9], const double p1[3], const double R1[9], const double p2[3],
                    const double R2[9])
{
    double pp[3], RR[9];
    for (int i = 0; i < 3; ++i) {
        pp[i] = p1[i];
        for (int j = 0; j < 3; ++j) {
            pp[i] += R1[3 * i + j] * p2[j];
            RR[3 * i + j] = R1[3 * i] * R2[j] + R1[3 * i + 1] * R2[3 + j] + R1[3 * i + 2] * R2[6 + j];
        }
    }
    memcpy(p, pp, sizeof pp);
    memcpy(R, RR, sizeof RR);
}

static void invert(double pi[3], double Ri[9], const double p[3], const double R[9])
{
    for (int i = 0; i < 3; ++i) {
        pi[i] = 0.0;
        for (int j = 0; j < 3; ++j) {
            Ri[3 * i + j] = R[3 * j + i];
            pi[i] -= R[3 * j + i] * p[j];
        }
    }
}

static void refuse(rch_cpi_ctx *c, unsigned long *n_bad, rch_diag *d, const rch_krl_target *t, unsigned base,
                   const char *why)
{
    char what[128];
    if (t->type == 0) /* a statement refused as a whole */
        snprintf(what, sizeof what, "statement");
    else
        snprintf(what, sizeof what, "%s%s%s (%s)", rch_krl_type_name(t->type), t->name[0] ? " " : "", t->name,
                 rch_krl_context_name(t->context));
    if (*n_bad == 0)
        rch_diag_set(d, c->in_name, base + t->line, t->col, "%s: %s", what, why);
    if (c->warn)
        fprintf(c->warn, "%s:%u:%u: error: %s cannot be corrected: %s\n", c->in_name, base + t->line, t->col, what,
                why);
    ++*n_bad;
}

typedef struct {
    const rc_model *nom;
    const rch_ctrl *ctl;
    rch_ikg *ik;
} krl_kin;

/* One target's six joints: controller degrees in a_in, corrected into
 * a_out. 0, 1 flagged, 2 left as it was, -1 (why set). */
static int krl_joints(rch_cpi_ctx *c, const krl_kin *k, double a_out[RC_NJ], const double a_in[RC_NJ],
                      unsigned line, const unsigned cols[RC_NJ], char *why, size_t why_len)
{
    double a[RC_NJ], q[RC_NJ], qd[RC_NJ], qo[RC_NJ];
    for (int i = 0; i < RC_NJ; ++i)
        a[i] = a_in[i] * DEG;
    rch_ctrl_to_model(q, k->ctl, a);
    for (int i = 0; i < RC_NJ; ++i) {
        qd[i] = q[i] / DEG;
        if (!(q[i] >= c->cal->q_min_rad[i] && q[i] <= c->cal->q_max_rad[i])) {
            /* the limits as the controller reads them */
            double lo[RC_NJ], hi[RC_NJ], ql[RC_NJ], qh[RC_NJ];
            for (int j = 0; j < RC_NJ; ++j) {
                ql[j] = c->cal->q_min_rad[j];
                qh[j] = c->cal->q_max_rad[j];
            }
            rch_ctrl_from_model(lo, k->ctl, ql);
            rch_ctrl_from_model(hi, k->ctl, qh);
            snprintf(why, why_len, "A%d = %g deg is outside the joint limits [%g, %g] deg", i + 1, a_in[i],
                     fmin(lo[i], hi[i]) / DEG, fmax(lo[i], hi[i]) / DEG);
            return -1;
        }
    }
    const int r = rch_cpi_compensate_at(c, qo, qd, line, cols, why, why_len);
    if (r < 0)
        strncat(why, " (the model's joint)", why_len - strlen(why) - 1);
    if (r < 0 || r == 2)
        return r;
    for (int i = 0; i < RC_NJ; ++i)
        q[i] = qo[i] * DEG;
    rch_ctrl_from_model(a, k->ctl, q);
    for (int i = 0; i < RC_NJ; ++i)
        a_out[i] = a[i] / DEG;
    return r;
}

/* A Cartesian target: out (slots 0..7) its corrected X..C, S, T. */
static int krl_cart(rch_cpi_ctx *c, const krl_kin *k, double out[RCH_KRL_NSLOT], const rch_krl_target *t,
                    unsigned base, char *why, size_t why_len)
{
    rch_krl_frame X;
    memcpy(X.v, t->val, sizeof X.v);
    double px[3], Rx[9], pt[3], Rt[9], pb[3], Rb[9], pti[3], Rti[9], pf[3], Rf[9];
    rch_krl_frame_to_pose(px, Rx, &X);
    rch_krl_frame_to_pose(pt, Rt, &t->tool);
    rch_krl_frame_to_pose(pb, Rb, &t->base);
    invert(pti, Rti, pt, Rt);
    compose(pf, Rf, pb, Rb, px, Rx); /* the flange: $BASE X $TOOL^-1 */
    compose(pf, Rf, pf, Rf, pti, Rti);
    double a[RC_NJ], ao[RC_NJ];
    if (rch_krl_ik(a, k->ik, k->nom, k->ctl, pf, Rf, (int)t->val[RCH_KRL_S], (int)t->val[RCH_KRL_T], why,
                   why_len) != 0)
        return -1;
    /* the TCP in the last DH frame: F applied to the tool's origin */
    double tcp[3];
    for (int i = 0; i < 3; ++i)
        tcp[i] = k->ctl->flange_mm[i] + k->ctl->flange_R[3 * i] * pt[0] + k->ctl->flange_R[3 * i + 1] * pt[1] +
                 k->ctl->flange_R[3 * i + 2] * pt[2];
    const int has_tcp = tcp[0] != 0.0 || tcp[1] != 0.0 || tcp[2] != 0.0;
    if (rch_cpi_use_tcp(c, tcp, has_tcp, why, why_len) != 0)
        return -1;
    unsigned cols[RC_NJ];
    for (int i = 0; i < RC_NJ; ++i)
        cols[i] = t->col;
    const int r = krl_joints(c, k, ao, a, base + t->line, cols, why, why_len); /* the job's stream set back */
    if (r < 0 || r == 2)
        return r;
    c->res->n_robtargets++;
    /* X' = $BASE^-1 flange' $TOOL */
    double pbi[3], Rbi[9];
    rch_krl_fk(pf, Rf, k->nom, k->ctl, ao);
    invert(pbi, Rbi, pb, Rb);
    compose(pf, Rf, pbi, Rbi, pf, Rf);
    compose(pf, Rf, pf, Rf, pt, Rt);
    rch_krl_frame Xo;
    rch_krl_pose_to_frame(&Xo, pf, Rf);
    memcpy(out, Xo.v, sizeof Xo.v);
    out[RCH_KRL_S] = rch_krl_status(k->nom, k->ctl, ao);
    out[RCH_KRL_T] = rch_krl_turn(ao);
    return r;
}

static int do_krl_text(rch_cpi_ctx *c, const char *text, size_t len, unsigned base, rch_diag *d)
{
    rch_krl_targets ts;
    memset(&ts, 0, sizeof ts);
    if (rch_krl_scan(&ts, text, len, c->in_name, d) != 0)
        return -1;
    if (ts.n == 0) {
        rch_diag_set(d, c->in_name, 0, 0, "no AXIS, E6AXIS, POS or E6POS target in this KRL file (declarations, "
                     "assignments, motions): nothing to correct; nothing written");
        rch_krl_free(&ts);
        return -1;
    }
    static rch_ctrl ident;
    rch_ctrl_identity(&ident);
    krl_kin k = {c->gate ? c->gate->nominal : NULL, c->gate && c->gate->ctrl ? c->gate->ctrl : &ident, NULL};
    rch_cpi_edits ed = {NULL, 0, 0};
    unsigned long n_bad = 0;
    int rc = 0, oom = 0;
    for (size_t i = 0; i < ts.n && !oom; ++i) {
        const rch_krl_target *t = &ts.t[i];
        if (t->error[0]) {
            refuse(c, &n_bad, d, t, base, t->error);
            continue;
        }
        char why[512] = "";
        double out[RCH_KRL_NSLOT];
        int r;
        const int cart = t->type >= RCH_KRL_POS;
        if (cart) {
            if (!k.nom) {
                refuse(c, &n_bad, d, t, base, "no nominal model to invert");
                continue;
            }
            if (!k.ik) {
                k.ik = malloc(sizeof *k.ik);
                if (!k.ik || rch_ikg_init(k.ik, k.nom, NULL) != RCH_IKG_OK) {
                    refuse(c, &n_bad, d, t, base, "the nominal model cannot be inverted");
                    continue;
                }
            }
            r = krl_cart(c, &k, out, t, base, why, sizeof why);
        } else
            r = krl_joints(c, &k, out, t->val, base + t->line, t->num_col, why, sizeof why);
        if (r < 0) {
            refuse(c, &n_bad, d, t, base, why);
            continue;
        }
        if (r == 2) {
            rc = 1;
            continue;
        }
        if (r > 0)
            rc = 1;
        for (int s = 0; s < (cart ? 8 : 6); ++s) {
            if (!((t->mask >> s) & 1u))
                continue; /* an auxiliary point's S and T, left out, stay out */
            const char *fmt = !cart ? "%.6f" : s < 3 ? "%.4f" : s < 6 ? "%.6f" : "%.0f";
            if (rch_cpi_edit_add(&ed, t->num_off[s], t->num_len[s], fmt, out[s]) != 0)
                oom = 1;
        }
    }
    if (oom) {
        rch_diag_set(d, c->in_name, 0, 0, "out of memory");
        rc = -1;
    } else if (n_bad > 0) {
        rch_cpi_refused(c, d, n_bad, "target");
        rc = -1;
    } else /* sorted by offset there: components may be written in any order */
        rch_cpi_edits_write(c, text, len, &ed);
    free(k.ik);
    rch_cpi_edits_free(&ed);
    rch_krl_free(&ts);
    return rc;
}

int rch_cpi_krl(rch_cpi_ctx *c, const char *line, size_t got, FILE *in, unsigned lineno, rch_diag *d)
{
    return rch_cpi_whole(c, line, got, in, lineno, RCH_KRL_MAX_BYTES, "a KRL file", do_krl_text, d);
}
