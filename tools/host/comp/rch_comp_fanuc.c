/* SPDX-License-Identifier: MIT */
/* rch_comp_fanuc.c - a Fanuc LS program through the compensation (see
 * rch_comp.h, docs/comp-fanuc.md): read whole (rch_fanuc_scan), each joint
 * position corrected in the controller's joints (rch_ctrl), each Cartesian
 * position through the nominal IK (rch_ikg) on the branch its CONFIG
 * letters name and the turns its turn numbers name, in its user and tool
 * frames (the frames file), corrected at its tool's TCP, and the nominal
 * pose of the corrected joints written back (turn numbers recomputed, the
 * letters kept); only the numbers' bytes change. All or nothing: a position
 * that cannot be corrected is named and nothing is written.
 * Depends on: rch_fanuc, rch_ikg, rch_ctrl, rch_file, one target
 * (rch_comp.c), the point model (rch_comp_model.c). Memory: the program,
 * its edits, the IK and the streams for other TCPs on the heap.
 * Errors: -1 with d set. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "rch_comp_int.h"
#include "rch_fanuc.h"
#include "rch_file.h"
#include "rch_ikg.h"

typedef struct {
    double R[9], p[3];
} pose;

static void pose_id(pose *a)
{
    static const double I[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    memcpy(a->R, I, sizeof I);
    a->p[0] = a->p[1] = a->p[2] = 0.0;
}

/* c = a b */
static void pose_mul(pose *c, const pose *a, const pose *b)
{
    pose r;
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j)
            r.R[3 * i + j] = a->R[3 * i] * b->R[j] + a->R[3 * i + 1] * b->R[3 + j] + a->R[3 * i + 2] * b->R[6 + j];
        r.p[i] = a->R[3 * i] * b->p[0] + a->R[3 * i + 1] * b->p[1] + a->R[3 * i + 2] * b->p[2] + a->p[i];
    }
    *c = r;
}

static void pose_inv(pose *b, const pose *a)
{
    pose r;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            r.R[3 * i + j] = a->R[3 * j + i];
    for (int i = 0; i < 3; ++i)
        r.p[i] = -(r.R[3 * i] * a->p[0] + r.R[3 * i + 1] * a->p[1] + r.R[3 * i + 2] * a->p[2]);
    *b = r;
}

static void pose_xyzwpr(pose *a, const double v[6])
{
    rch_fanuc_wpr_to_rot(a->R, &v[3]);
    memcpy(a->p, v, 3 * sizeof *v);
}

/* W, P, R of R nearest the written ones (each by whole turns; at P = +-90
 * deg, where only W -+ R is defined, R kept as written). */
static void wpr_near(double out[3], const double R[9], const double orig[3])
{
    rch_fanuc_rot_to_wpr(out, R);
    if (fabs(fabs(out[1]) - 90.0) < 1e-7) {
        const double s = atan2(out[1] > 0 ? R[1] : -R[1], R[4]) / DEG; /* w - r (p = 90) or w + r (p = -90) */
        out[2] = orig[2];
        out[0] = out[1] > 0 ? s + orig[2] : s - orig[2];
    }
    for (int k = 0; k < 3; ++k)
        out[k] += 360.0 * floor((orig[k] - out[k]) / 360.0 + 0.5);
}

/* The run's Fanuc state: the nominal IK, the frames, the controller map. */
typedef struct {
    rch_ikg *ik;
    rch_fanuc_frames fr;
    int have_frames;
    const char *frames_name;
    const rch_ctrl *ctrl;
    rch_ctrl id;
    pose B, F; /* the controller's base (DH frame 0 in its world) and flange (in the last DH frame) */
} fstate;

/* The CONFIG letters and turns of model joints q (rad): letters 'N'/'F'
 * (the controller's J5 negative: flip), 'U'/'D' and 'T'/'B' (the elbow, the
 * wrist centre against axis 1, each on the zero position's side or not:
 * rch_ikg_branch), turns of J1, J4, J6 (J in (-180, 180] + 360 t). */
static void fanuc_config(char cfg[3], int turn[3], const fstate *fs, const double q[RC_NJ])
{
    double j[RC_NJ];
    rch_ctrl_from_model(j, fs->ctrl, q);
    const int br = rch_ikg_branch(fs->ik, q);
    cfg[0] = sin(j[4]) < 0 ? 'F' : 'N';
    cfg[1] = (br & 2) ? 'D' : 'U';
    cfg[2] = (br & 4) ? 'B' : 'T';
    static const int ax[3] = {0, 3, 5};
    for (int k = 0; k < 3; ++k)
        turn[k] = (int)ceil((j[ax[k]] / DEG - 180.0) / 360.0 - 1e-12);
}

/* The frames of position q: UF (in the world) and UT (in the faceplate).
 * 0, or -1 with why set. */
static int frames_of(pose *uf, pose *ut, const fstate *fs, const rch_fanuc_pos *q, int need_uf, char *why,
                     size_t why_len)
{
    pose_id(uf);
    pose_id(ut);
    if (need_uf && q->uf != 0) {
        if (!fs->have_frames || !fs->fr.has_uf[q->uf]) {
            snprintf(why, why_len, "UF %d: user frame %d is not given (%s%s): it lives in the controller, not in "
                     "the LS file; give it as \"uframe,%d,x,y,z,w,p,r\"", q->uf, q->uf,
                     fs->have_frames ? "not in --fanuc-frames " : "no --fanuc-frames file",
                     fs->have_frames ? fs->frames_name : "", q->uf);
            return -1;
        }
        pose_xyzwpr(uf, fs->fr.uf[q->uf]);
    }
    if (q->ut != 0) {
        if (!fs->have_frames || !fs->fr.has_ut[q->ut]) {
            snprintf(why, why_len, "UT %d: tool frame %d is not given (%s%s): it lives in the controller, not in "
                     "the LS file; give it as \"utool,%d,x,y,z,w,p,r\"", q->ut, q->ut,
                     fs->have_frames ? "not in --fanuc-frames " : "no --fanuc-frames file",
                     fs->have_frames ? fs->frames_name : "", q->ut);
            return -1;
        }
        pose_xyzwpr(ut, fs->fr.ut[q->ut]);
    }
    return 0;
}

/* One position: out (9) the numbers to write. 0 ok, 1 flagged, 2 left as
 * it was, -1 refused (why set). */
static int fanuc_pos(rch_cpi_ctx *c, const fstate *fs, double out[RCH_FANUC_NUMS], const rch_fanuc_pos *q,
                     unsigned base, char *why, size_t why_len)
{
    pose uf, ut;
    if (frames_of(&uf, &ut, fs, q, !q->joint, why, why_len) != 0)
        return -1;
    /* the point compensated: the TCP in the last DH frame, F UT */
    pose fut;
    pose_mul(&fut, &fs->F, &ut);
    double qm[RC_NJ], qd[RC_NJ], qo[RC_NJ];
    if (q->joint) {
        double j[RC_NJ];
        for (int k = 0; k < RC_NJ; ++k)
            j[k] = q->val[k] * DEG;
        rch_ctrl_to_model(qm, fs->ctrl, j);
    } else {
        /* T_dh = B^-1 UF P UT^-1 F^-1 */
        pose P, t, bi, fi;
        pose_xyzwpr(&P, q->val);
        pose_inv(&bi, &fs->B);
        pose_inv(&fi, &fut);
        pose_mul(&t, &bi, &uf);
        pose_mul(&t, &t, &P);
        pose_mul(&t, &t, &fi);
        double all[RCH_IKG_MAX_SOL][RC_NJ];
        const int ns = rch_ikg_all(all, NULL, fs->ik, t.p, t.R);
        if (ns == 0) {
            snprintf(why, why_len, "out of the nominal robot's reach (no inverse kinematics solution)");
            return -1;
        }
        int found = -1;
        for (int s = 0; s < ns && found < 0; ++s) {
            char cf[3];
            int tn[3];
            fanuc_config(cf, tn, fs, all[s]);
            if (memcmp(cf, q->cfg, 3) == 0)
                found = s;
        }
        if (found < 0) {
            snprintf(why, why_len, "no solution of the nominal robot with CONFIG '%c %c %c' (at or across a "
                     "singularity)", q->cfg[0], q->cfg[1], q->cfg[2]);
            return -1;
        }
        double j[RC_NJ];
        rch_ctrl_from_model(j, fs->ctrl, all[found]);
        static const int ax[3] = {0, 3, 5};
        for (int k = 0; k < 3; ++k) {
            double a = fmod(j[ax[k]] / DEG, 360.0);
            a = a > 180.0 ? a - 360.0 : a <= -180.0 ? a + 360.0 : a;
            j[ax[k]] = (a + 360.0 * q->val[6 + k]) * DEG;
        }
        rch_ctrl_to_model(qm, fs->ctrl, j);
        for (int k = 0; k < RC_NJ; ++k)
            if (qm[k] < fs->ik->q_min_rad[k] - 1e-9 || qm[k] > fs->ik->q_max_rad[k] + 1e-9) {
                snprintf(why, why_len, "with its CONFIG's turn numbers the nominal robot's axis %d is at %.4f deg, "
                         "outside its limits [%g, %g] deg", k + 1, qm[k] / DEG, fs->ik->q_min_rad[k] / DEG,
                         fs->ik->q_max_rad[k] / DEG);
                return -1;
            }
    }
    if (rch_cpi_use_tcp(c, fut.p, fut.p[0] != 0.0 || fut.p[1] != 0.0 || fut.p[2] != 0.0, why, why_len) != 0)
        return -1;
    unsigned cols[RC_NJ];
    for (int k = 0; k < RC_NJ; ++k) {
        qd[k] = qm[k] / DEG;
        cols[k] = q->num_col[q->joint ? k : 0];
    }
    const int r = rch_cpi_compensate_at(c, qo, qd, base + q->line, cols, why, why_len);
    if (r < 0 || r == 2)
        return r;
    double qr[RC_NJ];
    for (int k = 0; k < RC_NJ; ++k)
        qr[k] = qo[k] * DEG;
    if (q->joint) {
        double j[RC_NJ];
        rch_ctrl_from_model(j, fs->ctrl, qr);
        for (int k = 0; k < RC_NJ; ++k)
            out[k] = j[k] / DEG;
        return r;
    }
    c->res->n_robtargets++;
    char cf[3];
    int tn[3];
    fanuc_config(cf, tn, fs, qr);
    if (memcmp(cf, q->cfg, 3) != 0) {
        snprintf(why, why_len, "the corrected joints' configuration '%c %c %c' is not the position's '%c %c %c' "
                 "(the correction crosses a singularity)", cf[0], cf[1], cf[2], q->cfg[0], q->cfg[1], q->cfg[2]);
        return -1;
    }
    /* P' = UF^-1 B T_dh(q') F UT */
    pose t, ufi;
    rch_ikg_fk(t.p, t.R, fs->ik, qr);
    pose_inv(&ufi, &uf);
    pose_mul(&t, &fs->B, &t);
    pose_mul(&t, &t, &fut);
    pose_mul(&t, &ufi, &t);
    for (int k = 0; k < 3; ++k)
        out[k] = t.p[k];
    wpr_near(&out[3], t.R, &q->val[3]);
    for (int k = 0; k < 3; ++k)
        out[6 + k] = tn[k];
    return r;
}

static void refuse(rch_cpi_ctx *c, unsigned long *n_bad, rch_diag *d, const rch_fanuc_pos *q, unsigned base,
                   const char *why)
{
    if (*n_bad == 0)
        rch_diag_set(d, c->in_name, base + q->line, q->col, "P[%u] (%s position%s): %s", q->idx,
                     q->joint ? "joint" : "Cartesian", q->n_uses ? "" : ", used by no motion", why);
    if (c->warn)
        fprintf(c->warn, "%s:%u:%u: error: P[%u] cannot be corrected: %s\n", c->in_name, base + q->line, q->col, q->idx,
                why);
    ++*n_bad;
}

static int setup(fstate *fs, rch_cpi_ctx *c, rch_diag *d)
{
    memset(fs, 0, sizeof *fs);
    const rch_comp_gate *g = c->gate;
    if (!g || !g->nominal) {
        rch_diag_set(d, c->in_name, 0, 0, "a Fanuc program needs the nominal model it was made with");
        return -1;
    }
    rch_ctrl_identity(&fs->id);
    fs->ctrl = g->ctrl ? g->ctrl : &fs->id;
    pose_id(&fs->B);
    pose_id(&fs->F);
    if (fs->ctrl->has_base) {
        memcpy(fs->B.R, fs->ctrl->base_R, sizeof fs->B.R);
        memcpy(fs->B.p, fs->ctrl->base_mm, sizeof fs->B.p);
    }
    if (fs->ctrl->has_flange) {
        memcpy(fs->F.R, fs->ctrl->flange_R, sizeof fs->F.R);
        memcpy(fs->F.p, fs->ctrl->flange_mm, sizeof fs->F.p);
    }
    if (g->fanuc_frames_path) {
        char *text = NULL;
        size_t len = 0;
        if (rch_read_file(&text, &len, g->fanuc_frames_path, 1u << 20, d) != 0)
            return -1;
        const int r = rch_fanuc_frames_parse(&fs->fr, text, len, g->fanuc_frames_path, d);
        free(text);
        if (r != 0)
            return -1;
        fs->have_frames = 1;
        fs->frames_name = g->fanuc_frames_path;
    }
    fs->ik = malloc(sizeof *fs->ik);
    if (!fs->ik || rch_ikg_init(fs->ik, g->nominal, NULL) != RCH_IKG_OK) {
        free(fs->ik);
        fs->ik = NULL;
        rch_diag_set(d, c->in_name, 0, 0, "the nominal model cannot be inverted (rch_ikg_init)");
        return -1;
    }
    return 0;
}

static int do_fanuc_text(rch_cpi_ctx *c, const char *text, size_t len, unsigned base, rch_diag *d)
{
    rch_fanuc_prog prog;
    if (rch_fanuc_scan(&prog, text, len, c->in_name, d) != 0) {
        d->line += d->line ? base : 0;
        return -1;
    }
    if (prog.n == 0) {
        rch_diag_set(d, c->in_name, 0, 0, "no position in /POS: nothing to correct; nothing written");
        rch_fanuc_free(&prog);
        return -1;
    }
    fstate fs;
    if (setup(&fs, c, d) != 0) {
        rch_fanuc_free(&prog);
        return -1;
    }
    rch_cpi_edits ed = {NULL, 0, 0};
    unsigned long n_bad = 0;
    int rc = 0;
    for (size_t i = 0; i < prog.n; ++i) {
        const rch_fanuc_pos *q = &prog.p[i];
        char why[512];
        double out[RCH_FANUC_NUMS];
        const int r = fanuc_pos(c, &fs, out, q, base, why, sizeof why);
        if (r < 0) {
            refuse(c, &n_bad, d, q, base, why);
            continue;
        }
        if (r == 2) {
            rc = 1;
            continue;
        }
        if (r > 0)
            rc = 1;
        for (unsigned k = 0; k < q->n; ++k) {
            const char *fmt = k >= 6 ? "%.0f" : (!q->joint && k < 3) ? "%.4f" : "%.6f";
            if (rch_cpi_edit_add(&ed, q->num_off[k], q->num_len[k], fmt, out[k] == 0.0 ? 0.0 : out[k]) != 0) {
                rch_diag_set(d, c->in_name, 0, 0, "out of memory");
                rch_cpi_edits_free(&ed);
                free(fs.ik);
                rch_fanuc_free(&prog);
                return -1;
            }
        }
    }
    if (n_bad > 0) {
        rch_cpi_refused(c, d, n_bad, "position");
        rc = -1;
    } else /* in the text's order there (a record's CONFIG turns come before its X) */
        rch_cpi_edits_write(c, text, len, &ed);
    rch_cpi_edits_free(&ed);
    free(fs.ik);
    rch_fanuc_free(&prog);
    return rc;
}

int rch_cpi_fanuc(rch_cpi_ctx *c, const char *line, size_t got, FILE *in, unsigned lineno, rch_diag *d)
{
    return rch_cpi_whole(c, line, got, in, lineno, RCH_FANUC_MAX_BYTES, "a Fanuc LS program", do_fanuc_text, d);
}
