/* SPDX-License-Identifier: MIT */
/* rch_urdf_robot.c - a URDF to a DH model and the calibrated overlay
 * (rch_urdf_robot.h). */
#include "rch_urdf_robot.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

typedef struct {
    double R[9], t[3]; /* mm */
} xf;

static const xf XF_I = {{1, 0, 0, 0, 1, 0, 0, 0, 1}, {0, 0, 0}};

static xf xf_mul(const xf *a, const xf *b)
{
    xf c;
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j)
            c.R[3 * i + j] = a->R[3 * i] * b->R[j] + a->R[3 * i + 1] * b->R[3 + j] + a->R[3 * i + 2] * b->R[6 + j];
        c.t[i] = a->t[i] + a->R[3 * i] * b->t[0] + a->R[3 * i + 1] * b->t[1] + a->R[3 * i + 2] * b->t[2];
    }
    return c;
}

static xf xf_inv(const xf *a)
{
    xf c;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            c.R[3 * i + j] = a->R[3 * j + i];
    for (int i = 0; i < 3; ++i)
        c.t[i] = -(c.R[3 * i] * a->t[0] + c.R[3 * i + 1] * a->t[1] + c.R[3 * i + 2] * a->t[2]);
    return c;
}

static xf origin_of(const rch_urdf_joint *j)
{
    xf o;
    rch_ctrl_rpy_to_rot(o.R, j->rpy);
    for (int k = 0; k < 3; ++k)
        o.t[k] = 1000.0 * j->xyz[k];
    return o;
}

/* DH row T = Rz(th) Tz(d) Tx(a) Rx(al) */
static xf dh_xf(double a, double d, double al, double th)
{
    const double c = cos(th), s = sin(th), ca = cos(al), sa = sin(al);
    const xf T = {{c, -s * ca, s * sa, s, c * ca, -c * sa, 0, sa, ca}, {a * c, a * s, d}};
    return T;
}

/* DH frame k (0..6) of m at q = 0 (theta = the offsets) */
static xf dh_frame(const rc_model *m, unsigned k)
{
    xf T = XF_I;
    for (unsigned i = 0; i < k; ++i) {
        const xf E = dh_xf(m->x[RC_P_A(i)], m->x[RC_P_D(i)], m->x[RC_P_ALPHA(i)], m->x[RC_P_THETA(i)]);
        T = xf_mul(&T, &E);
    }
    return T;
}

static double dot3(const double a[3], const double b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
static void cross3(double c[3], const double a[3], const double b[3])
{
    c[0] = a[1] * b[2] - a[2] * b[1];
    c[1] = a[2] * b[0] - a[0] * b[2];
    c[2] = a[0] * b[1] - a[1] * b[0];
}
static double unit3(double v[3])
{
    const double n = sqrt(dot3(v, v));
    if (n > 0)
        for (int k = 0; k < 3; ++k)
            v[k] /= n;
    return n;
}

/* The joint whose child is link, or -1. */
static long joint_to(const rch_urdf_doc *doc, const char *link)
{
    for (size_t k = 0; k < doc->n_joints; ++k)
        if (strcmp(doc->joint[k].child, link) == 0)
            return (long)k;
    return -1;
}

/* The world (root) frame of link at q = 0 (mm). */
static xf world_of(const rch_urdf_doc *doc, const char *link)
{
    xf T = XF_I;
    const char *l = link;
    for (size_t step = 0; step <= doc->n_joints; ++step) {
        const long j = joint_to(doc, l);
        if (j < 0)
            break;
        const xf O = origin_of(&doc->joint[j]);
        T = xf_mul(&O, &T);
        l = doc->joint[j].parent;
    }
    return T;
}

/* The flange link: joint 6's child, then down single fixed children; *first
 * the first fixed joint on the way (-1: none). */
static const char *flange_link(const rch_urdf_doc *doc, size_t j6, long *first)
{
    const char *l = doc->joint[j6].child;
    *first = -1;
    for (size_t step = 0; step < doc->n_joints; ++step) {
        long only = -1;
        unsigned n = 0;
        for (size_t k = 0; k < doc->n_joints; ++k)
            if (strcmp(doc->joint[k].parent, l) == 0) {
                ++n;
                if (strcmp(doc->joint[k].type, "fixed") == 0)
                    only = (long)k;
            }
        if (n != 1 || only < 0)
            break;
        if (*first < 0)
            *first = only;
        l = doc->joint[only].child;
    }
    return l;
}

typedef struct {
    size_t chain[RC_NJ];
    xf J[RC_NJ];  /* joint frames (before their rotation) in the root at q = 0 */
    double z[RC_NJ][3];
    xf flange;    /* the flange link in the root */
    long first_fixed;
    const char *flange_name;
} urdf_chain;

static int read_chain(urdf_chain *c, const rch_urdf_doc *doc, const char *file, rch_diag *d)
{
    if (rch_urdf_chain(c->chain, doc, file, d) != 0)
        return -1;
    for (unsigned i = 0; i < RC_NJ; ++i) {
        const rch_urdf_joint *j = &doc->joint[c->chain[i]];
        const xf W = world_of(doc, j->parent), O = origin_of(j);
        c->J[i] = xf_mul(&W, &O);
        double a[3] = {j->axis[0], j->axis[1], j->axis[2]};
        if (!(unit3(a) > 1e-9)) {
            rch_diag_set(d, file, j->line, j->col, "joint \"%s\": its axis has no direction", j->name);
            return -1;
        }
        for (int r = 0; r < 3; ++r)
            c->z[i][r] = c->J[i].R[3 * r] * a[0] + c->J[i].R[3 * r + 1] * a[1] + c->J[i].R[3 * r + 2] * a[2];
    }
    c->flange_name = flange_link(doc, c->chain[RC_NJ - 1], &c->first_fixed);
    c->flange = world_of(doc, c->flange_name);
    return 0;
}

/* The DH table (6 x 4: a, d, alpha, theta), B and F of a chain. */
static void chain_dh(double dh[RC_NJ][4], xf *B, xf *F, const urdf_chain *c)
{
    double o[3], x[3], z[3];
    /* frame 0: on axis 1 at the foot of the root origin, x the root's x made perpendicular */
    memcpy(z, c->z[0], sizeof z);
    const double s = -dot3(c->J[0].t, z);
    for (int k = 0; k < 3; ++k)
        o[k] = c->J[0].t[k] + s * z[k];
    double ex[3] = {1, 0, 0};
    const double pz = dot3(ex, z);
    for (int k = 0; k < 3; ++k)
        x[k] = ex[k] - pz * z[k];
    if (unit3(x) < 1e-6) {
        const double ey[3] = {0, 1, 0}, py = dot3(ey, z);
        for (int k = 0; k < 3; ++k)
            x[k] = ey[k] - py * z[k];
        unit3(x);
    }
    double y[3];
    cross3(y, z, x);
    for (int r = 0; r < 3; ++r) {
        B->R[3 * r] = x[r];
        B->R[3 * r + 1] = y[r];
        B->R[3 * r + 2] = z[r];
        B->t[r] = o[r];
    }
    for (unsigned i = 0; i < RC_NJ; ++i) {
        double o2[3], x2[3], z2[3];
        if (i + 1 < RC_NJ) {
            memcpy(z2, c->z[i + 1], sizeof z2);
            const double *p2 = c->J[i + 1].t;
            double cr[3];
            cross3(cr, z, z2);
            if (sqrt(dot3(cr, cr)) > 1e-9) { /* the common normal */
                double w0[3];
                for (int k = 0; k < 3; ++k)
                    w0[k] = o[k] - p2[k];
                const double b = dot3(z, z2), dd = dot3(z, w0), e = dot3(z2, w0), den = 1.0 - b * b;
                const double t2 = (e - b * dd) / den;
                for (int k = 0; k < 3; ++k)
                    o2[k] = p2[k] + t2 * z2[k];
                memcpy(x2, cr, sizeof x2);
                unit3(x2);
            } else { /* parallel: the perpendicular from o */
                double w0[3];
                for (int k = 0; k < 3; ++k)
                    w0[k] = o[k] - p2[k];
                const double t2 = dot3(w0, z2);
                for (int k = 0; k < 3; ++k) {
                    o2[k] = p2[k] + t2 * z2[k];
                    x2[k] = o2[k] - o[k];
                }
                if (unit3(x2) < 1e-9)
                    memcpy(x2, x, sizeof x2);
            }
        } else { /* frame 6: on axis 6 at the foot of the flange origin, x the flange's x made perpendicular */
            memcpy(z2, z, sizeof z2);
            const double t2 = dot3(c->flange.t, z) - dot3(o, z);
            double fx[3] = {c->flange.R[0], c->flange.R[3], c->flange.R[6]};
            for (int k = 0; k < 3; ++k) {
                o2[k] = o[k] + t2 * z[k];
                x2[k] = fx[k] - dot3(fx, z) * z[k];
            }
            if (unit3(x2) < 1e-6) {
                const double fy[3] = {c->flange.R[1], c->flange.R[4], c->flange.R[7]};
                for (int k = 0; k < 3; ++k)
                    x2[k] = fy[k] - dot3(fy, z) * z[k];
                unit3(x2);
            }
        }
        double xx[3], zz[3], v[3];
        cross3(xx, x, x2);
        cross3(zz, z, z2);
        for (int k = 0; k < 3; ++k)
            v[k] = o2[k] - o[k];
        dh[i][0] = dot3(v, x2);
        dh[i][1] = dot3(v, z);
        dh[i][2] = atan2(dot3(zz, x2), dot3(z, z2));
        dh[i][3] = atan2(dot3(xx, z), dot3(x, x2));
        memcpy(o, o2, sizeof o);
        memcpy(x, x2, sizeof x);
        memcpy(z, z2, sizeof z);
    }
    /* F = (B T_dh(0))^-1 flange, with T_dh from the table just made */
    xf T = *B;
    for (unsigned i = 0; i < RC_NJ; ++i) {
        const xf E = dh_xf(dh[i][0], dh[i][1], dh[i][2], dh[i][3]);
        T = xf_mul(&T, &E);
    }
    const xf Ti = xf_inv(&T);
    *F = xf_mul(&Ti, &c->flange);
}

static int is_identity(const xf *T)
{
    for (int k = 0; k < 9; ++k)
        if (fabs(T->R[k] - XF_I.R[k]) > 1e-12)
            return 0;
    return fabs(T->t[0]) + fabs(T->t[1]) + fabs(T->t[2]) <= 1e-9;
}

static void ctrl_set(double R[9], double t[3], double rpy_deg[3], const xf *T)
{
    double rpy[3];
    memcpy(R, T->R, sizeof T->R);
    memcpy(t, T->t, sizeof T->t);
    rch_ctrl_rot_to_rpy(rpy, T->R);
    for (int k = 0; k < 3; ++k)
        rpy_deg[k] = rpy[k] * 180.0 / M_PI;
    /* R read back from rpy_deg when the model file is reloaded: the same rotation to rounding */
}

int rch_urdf_robot_parse(rch_robot *out, const char *text, size_t len, const char *file, rch_diag *d)
{
    memset(out, 0, sizeof *out);
    rch_urdf_doc doc;
    if (rch_urdf_doc_parse(&doc, text, len, file, d) != 0)
        return -1;
    urdf_chain c;
    int rc = -1;
    if (read_chain(&c, &doc, file, d) != 0)
        goto done;
    double dh[RC_NJ][4];
    xf B, F;
    chain_dh(dh, &B, &F, &c);
    const double enc[3] = {0, 0, 0};
    if (rc_model_init(&out->model, (const double(*)[4])dh, enc) != RC_OK) {
        rch_diag_set(d, file, 0, 0, "the URDF's chain gives a DH table that is not finite");
        goto done;
    }
    for (unsigned i = 0; i < RC_NJ; ++i) {
        const rch_urdf_joint *j = &doc.joint[c.chain[i]];
        if (strcmp(j->type, "revolute") == 0 && j->has_limit) {
            if (!(j->lower <= j->upper) || !isfinite(j->lower) || !isfinite(j->upper)) {
                rch_diag_set(d, file, j->line, j->col, "joint \"%s\": its limits [%g, %g] are not a range", j->name,
                             j->lower, j->upper);
                goto done;
            }
            out->model.q_min_rad[i] = j->lower;
            out->model.q_max_rad[i] = j->upper;
        }
    }
    for (unsigned i = 0; i < RC_NJ; ++i) /* a link's length beyond the robot file's limit: a wrong file */
        if (fabs(dh[i][0]) > RCH_ROBOT_MAX_LINK_MM || fabs(dh[i][1]) > RCH_ROBOT_MAX_LINK_MM) {
            rch_diag_set(d, file, 0, 0, "the URDF's DH row %u has a = %g mm, d = %g mm: beyond %g mm (a wrong unit?)",
                         i + 1, dh[i][0], dh[i][1], RCH_ROBOT_MAX_LINK_MM);
            goto done;
        }
    out->nominal = out->model;
    snprintf(out->name, sizeof out->name, "%s", doc.robot[0] ? doc.robot : "robot");
    rch_ctrl_identity(&out->ctrl);
    rch_prior_defaults(&out->prior);
    if (!is_identity(&B)) {
        out->ctrl.present = out->ctrl.has_base = 1;
        ctrl_set(out->ctrl.base_R, out->ctrl.base_mm, out->ctrl.base_rpy_deg, &B);
    }
    if (!is_identity(&F)) {
        out->ctrl.present = out->ctrl.has_flange = 1;
        ctrl_set(out->ctrl.flange_R, out->ctrl.flange_mm, out->ctrl.flange_rpy_deg, &F);
    }
    rc = 0;
done:
    rch_urdf_doc_free(&doc);
    return rc;
}

/* an origin start tag for T into buf (metres, radians, %.17g) */
static void origin_tag(char *buf, size_t n, const xf *T, int empty)
{
    double rpy[3];
    rch_ctrl_rot_to_rpy(rpy, T->R);
    snprintf(buf, n, "<origin xyz=\"%.17g %.17g %.17g\" rpy=\"%.17g %.17g %.17g\"%s>", T->t[0] / 1000.0,
             T->t[1] / 1000.0, T->t[2] / 1000.0, rpy[0], rpy[1], rpy[2], empty ? "/" : "");
}

typedef struct {
    size_t at, len; /* bytes replaced (len 0: inserted at) */
    char text[320];
} edit;

static int edit_cmp(const void *a, const void *b)
{
    const edit *x = a, *y = b;
    return (x->at > y->at) - (x->at < y->at);
}

static void set_edit(edit *e, const rch_urdf_joint *j, const char *text, const xf *T)
{
    if (j->has_origin) {
        const int empty = j->origin_len >= 2 && text[j->origin_at + j->origin_len - 2] == '/';
        e->at = j->origin_at;
        e->len = j->origin_len;
        origin_tag(e->text, sizeof e->text, T, empty);
    } else {
        char tag[300];
        origin_tag(tag, sizeof tag, T, 1);
        e->at = j->tag_end;
        e->len = 0;
        snprintf(e->text, sizeof e->text, "\n    %s", tag);
    }
}

int rch_urdf_overlay_write(FILE *f, int *flange_moved, const char *text, size_t len, const char *file,
                           const rc_model *nominal, const rc_model *cal, rch_diag *d)
{
    rch_urdf_doc doc;
    *flange_moved = 0;
    if (rch_urdf_doc_parse(&doc, text, len, file, d) != 0)
        return -1;
    urdf_chain c;
    int rc = -1;
    if (read_chain(&c, &doc, file, d) != 0)
        goto done;
    double dh[RC_NJ][4];
    xf B, F;
    chain_dh(dh, &B, &F, &c);
    static const char *const col[4] = {"a", "d", "alpha", "theta"};
    for (unsigned i = 0; i < RC_NJ; ++i)
        for (unsigned k = 0; k < 4; ++k) {
            double e = nominal->x[4 * i + k] - dh[i][k];
            if (k >= 2)
                e = remainder(e, 2.0 * M_PI);
            if (!(fabs(e) <= 1e-6)) {
                rch_diag_set(d, file, 0, 0, "the nominal URDF is not the model's nominal robot: %s%u is %.9g from "
                             "the URDF, %.9g in the model's nominal table", col[k], i + 1, dh[i][k],
                             nominal->x[4 * i + k]);
                rc = -2;
                goto done;
            }
        }
    /* N_i: joint i's frame in the nominal DH frame i-1; J'_i = B DHcal_{i-1} N_i */
    xf Jn[RC_NJ];
    for (unsigned i = 0; i < RC_NJ; ++i) {
        const xf Dn = dh_frame(nominal, i), Dc = dh_frame(cal, i);
        const xf BDn = xf_mul(&B, &Dn), BDc = xf_mul(&B, &Dc), BDni = xf_inv(&BDn);
        const xf N = xf_mul(&BDni, &c.J[i]);
        Jn[i] = xf_mul(&BDc, &N);
    }
    edit e[RC_NJ + 1];
    unsigned ne = 0;
    for (unsigned i = 0; i < RC_NJ; ++i) {
        const rch_urdf_joint *j = &doc.joint[c.chain[i]];
        xf P; /* the parent link's new frame */
        if (i == 0) {
            P = world_of(&doc, j->parent);
        } else { /* J'_{i-1} and the fixed joints between, as they were */
            const xf Ji = xf_inv(&c.J[i - 1]), W = world_of(&doc, j->parent);
            const xf Fix = xf_mul(&Ji, &W);
            P = xf_mul(&Jn[i - 1], &Fix);
        }
        const xf Pi = xf_inv(&P);
        const xf O = xf_mul(&Pi, &Jn[i]);
        set_edit(&e[ne++], j, text, &O);
    }
    /* the flange: B DHcal_6 F, through the first fixed joint after joint 6 */
    const xf D6 = dh_frame(cal, RC_NJ), BD6 = xf_mul(&B, &D6), Fl = xf_mul(&BD6, &F);
    if (c.first_fixed >= 0) {
        const rch_urdf_joint *j = &doc.joint[c.first_fixed];
        const xf Wc = world_of(&doc, j->child), Wci = xf_inv(&Wc);
        const xf Rest = xf_mul(&Wci, &c.flange), Resti = xf_inv(&Rest), J6i = xf_inv(&Jn[RC_NJ - 1]);
        const xf A = xf_mul(&J6i, &Fl);
        const xf O = xf_mul(&A, &Resti);
        set_edit(&e[ne++], j, text, &O);
    } else {
        *flange_moved = 1;
    }
    qsort(e, ne, sizeof e[0], edit_cmp);
    size_t at = 0;
    for (unsigned k = 0; k < ne; ++k) {
        fwrite(text + at, 1, e[k].at - at, f);
        fputs(e[k].text, f);
        at = e[k].at + e[k].len;
    }
    fwrite(text + at, 1, len - at, f);
    rc = 0;
done:
    rch_urdf_doc_free(&doc);
    return rc;
}
