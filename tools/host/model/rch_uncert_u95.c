/* SPDX-License-Identifier: MIT */
/* rch_uncert_u95.c - what a covariance predicts at a pose (see
 * rch_uncert.h): the flange's and the tool point's sensitivity to the
 * parameters (closed-form DH columns, central differences for the effects),
 * the 95 % position and orientation semi-axes (pos95, rot95) of a
 * calibration and of a model file's rch_model_unc, the map over the data's
 * poses and the workspace, and the 95 % radius u95 (rch_uncert_radius95,
 * rch_model_unc_radius95_mm). The covariance itself: rch_uncert.c.
 * Depends on: lib/rc_kin (rc_kin_fk_dh_jac), rc_fk, rc_linalg
 * (rcu_sym3_eig_max), rc_rand; rch_stats; LAPACKE (dsyev). Memory: scratch
 * on the heap (NaN or -1 when it cannot be had), nothing kept. Errors: NaN
 * figures, or -1 from rch_uncert_map_compute. */
#include "rch_uncert.h"
#include "rch_prior.h"
#include "rch_stats.h"

#include <lapacke.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "rc_kin.h"
#include "rc_linalg.h"
#include "rc_rand.h"

/* chi-square quantile with 3 degrees of freedom at 0.95 */
#define CHI2_3_95 7.814727903251178

/* Sensitivity of the flange position (Jp, may be NULL) and of its
 * small-rotation vector (Jr, may be NULL) to the parameters k < n with
 * use[k] set; the others' columns are zero. The DH columns in closed form
 * from one chain (rc_kin_fk_dh_jac on kin, the model compiled by
 * sens_compile); the encoder's and those of effects that move neither the
 * flange nor the point it carries (length, outlet and sensor side) are zero;
 * the tool offset's and the axis tilts' in closed form from the same chain
 * (with kin); the other effects' by central differences of rc_fk (the
 * joint-side effects). kin
 * NULL (a model rc_kin cannot hold): central differences for all. */
static void fk_sensitivity(double Jp[3][RC_MAX_PARAMS], double Jr[3][RC_MAX_PARAMS], const uint8_t *use, unsigned n,
                           const rc_model *m, const rc_kin *kin, const double q_rad[RC_NJ])
{
    rc_model t; /* m with one parameter moved: copied when a difference needs it */
    int have_t = 0;
    double jp[3 * RC_N_DH], jr[3 * RC_N_DH], rot[9], pos[3];
    rc_kin_data kd;
    if (kin != NULL)
        rc_kin_fk_dh_jac(pos, rot, Jp ? jp : NULL, Jr ? jr : NULL, &kd, kin, q_rad);
    for (unsigned k = 0; k < n; ++k) {
        for (int i = 0; i < 3; ++i) {
            if (Jp)
                Jp[i][k] = 0.0;
            if (Jr)
                Jr[i][k] = 0.0;
        }
        if (!use[k] || k >= m->n_params || (kin != NULL && k >= RC_N_DH && k < RC_N_BASE))
            continue; /* (k past m: a covariance's nuisance, e.g. the jumps' offsets, which m drops) */
        if (kin != NULL && k < RC_N_DH) {
            for (int i = 0; i < 3; ++i) {
                if (Jp)
                    Jp[i][k] = jp[i * RC_N_DH + (int)k];
                if (Jr)
                    Jr[i][k] = jr[i * RC_N_DH + (int)k];
            }
            continue;
        }
        const rc_effect *e = k >= RC_N_BASE ? rc_param_effect(m, k) : NULL;
        const rc_effect_desc *ds = e != NULL ? rc_effect_describe(e->kind) : NULL;
        if (ds != NULL && (ds->side == RC_SIDE_LENGTH || ds->side == RC_SIDE_OUTLET || ds->side == RC_SIDE_SENSOR))
            continue; /* moves nothing the flange carries: a zero column */
        if (kin != NULL && e != NULL && e->kind == RC_EFF_TOOL_OFFSET) {
            for (int i = 0; Jp && i < 3; ++i) /* p = flange + R6 t: d p / d t_j = R6's column j, no rotation */
                Jp[i][k] = rot[i * 3 + (int)(k - e->first)];
            continue;
        }
        if (kin != NULL && e != NULL && e->kind == RC_EFF_AXIS_TILT && e->joint < RC_NJ) {
            /* Ry(beta) after Rx(alpha) turns frame j+1 about its own y axis, which it leaves in place:
             * d p / d beta = y_{j+1} x (p - o_{j+1}), d w / d beta = y_{j+1} */
            const double *R = kd.R[e->joint + 1], *o = kd.o[e->joint + 1];
            const double y[3] = {R[1], R[4], R[7]}, r[3] = {pos[0] - o[0], pos[1] - o[1], pos[2] - o[2]};
            const double v[3] = {y[1] * r[2] - y[2] * r[1], y[2] * r[0] - y[0] * r[2], y[0] * r[1] - y[1] * r[0]};
            for (int i = 0; i < 3; ++i) {
                if (Jp)
                    Jp[i][k] = v[i];
                if (Jr)
                    Jr[i][k] = y[i];
            }
            continue;
        }
        const double h = rc_param_unit(m, k) == 1 ? 1e-7 : 1e-5;
        double pp[3], pm[3], Rp[9], Rm[9];
        if (!have_t) {
            t = *m;
            have_t = 1;
        }
        t.x[k] = m->x[k] + h;
        rc_fk(pp, Rp, &t, q_rad);
        t.x[k] = m->x[k] - h;
        rc_fk(pm, Rm, &t, q_rad);
        t.x[k] = m->x[k];
        for (int i = 0; Jp && i < 3; ++i)
            Jp[i][k] = (pp[i] - pm[i]) / (2.0 * h);
        if (Jr) { /* small rotation Rp Rm^T ~ I + [w]x, w = 2 h dw/dx */
            double D[9];
            for (int i = 0; i < 3; ++i)
                for (int j = 0; j < 3; ++j)
                    D[i * 3 + j] = Rp[i * 3] * Rm[j * 3] + Rp[i * 3 + 1] * Rm[j * 3 + 1] + Rp[i * 3 + 2] * Rm[j * 3 + 2];
            Jr[0][k] = 0.5 * (D[7] - D[5]) / (2.0 * h);
            Jr[1][k] = 0.5 * (D[2] - D[6]) / (2.0 * h);
            Jr[2][k] = 0.5 * (D[3] - D[1]) / (2.0 * h);
        }
    }
}

/* The kinematics of m compiled for fk_sensitivity into kin: kin, or NULL
 * when rc_kin cannot hold m (central differences then). */
static const rc_kin *sens_compile(rc_kin *kin, const rc_model *m)
{
    return rc_kin_compile(kin, m) == RC_OK ? kin : NULL;
}

/* The part of a covariance an ellipsoid reads: the parameters k < n with
 * use[k] set whose FK sensitivity can be nonzero (not the encoder's), idx
 * (nn) in order, and their covariance c (nn x nn, contiguous, the caller's
 * buffer of n * n doubles). After factor_cov (factored set): idx in pivot
 * order and c holds the factor F (nn x r, row a in c + a * nn, entries
 * k < min(a + 1, r)) with Cov = F F^T up to what the pivoting dropped. */
typedef struct {
    unsigned nn, r, factored;
    unsigned idx[RC_MAX_PARAMS];
    double *c;
} cov_pack;

static void pack_cov(cov_pack *p, double *buf, const double *cov, size_t ld, const uint8_t *use, unsigned n)
{
    p->nn = 0;
    p->r = 0;
    p->factored = 0;
    p->c = buf;
    for (unsigned k = 0; k < n; ++k)
        if (use[k] && !(k >= RC_N_DH && k < RC_N_BASE))
            p->idx[p->nn++] = k;
    for (unsigned a = 0; a < p->nn; ++a)
        for (unsigned b = 0; b < p->nn; ++b)
            buf[(size_t)a * p->nn + b] = cov[(size_t)p->idx[a] * ld + p->idx[b]];
}

/* Pivoted Cholesky of the packed covariance (for an ellipsoid at many
 * poses: 3 nn r - 3 r^2 / 2 products a pose instead of 3 nn^2), on the
 * correlation scale so that millimetres and radians weigh alike: a pivot
 * stops the factor when what is left of every parameter's variance, once the
 * ones before are known, is below FACTOR_TOL of its variance (a relative
 * change of at most 1e-12 in any ellipsoid). Parameters with no variance
 * (held) have no column. */
#define FACTOR_TOL 1e-12
static void factor_cov(cov_pack *p)
{
    const unsigned nn = p->nn;
    double *A = p->c, sc[RC_MAX_PARAMS];
    for (unsigned a = 0; a < nn; ++a) {
        const double d = A[(size_t)a * nn + a];
        sc[a] = d > 0.0 ? sqrt(d) : 0.0;
    }
    for (unsigned a = 0; a < nn; ++a)
        for (unsigned b = 0; b < nn; ++b)
            A[(size_t)a * nn + b] = sc[a] > 0.0 && sc[b] > 0.0 ? A[(size_t)a * nn + b] / (sc[a] * sc[b]) : 0.0;
    unsigned c = 0;
    for (; c < nn; ++c) {
        unsigned q = c;
        for (unsigned a = c + 1; a < nn; ++a)
            if (A[(size_t)a * nn + a] > A[(size_t)q * nn + q])
                q = a;
        if (!(A[(size_t)q * nn + q] > FACTOR_TOL))
            break;
        if (q != c) { /* symmetric swap of rows and columns c, q */
            for (unsigned b = 0; b < nn; ++b) {
                const double t = A[(size_t)c * nn + b];
                A[(size_t)c * nn + b] = A[(size_t)q * nn + b];
                A[(size_t)q * nn + b] = t;
            }
            for (unsigned a = 0; a < nn; ++a) {
                const double t = A[(size_t)a * nn + c];
                A[(size_t)a * nn + c] = A[(size_t)a * nn + q];
                A[(size_t)a * nn + q] = t;
            }
            const unsigned ti = p->idx[c];
            p->idx[c] = p->idx[q];
            p->idx[q] = ti;
            const double ts = sc[c];
            sc[c] = sc[q];
            sc[q] = ts;
        }
        const double l = sqrt(A[(size_t)c * nn + c]);
        A[(size_t)c * nn + c] = l;
        for (unsigned a = c + 1; a < nn; ++a)
            A[(size_t)a * nn + c] /= l;
        for (unsigned a = c + 1; a < nn; ++a) /* the whole trailing block: a later swap reads both halves */
            for (unsigned b = c + 1; b < nn; ++b)
                A[(size_t)a * nn + b] -= A[(size_t)a * nn + c] * A[(size_t)b * nn + c];
    }
    p->r = c;
    p->factored = 1;
    for (unsigned a = 0; a < nn; ++a) /* back to the covariance's units */
        for (unsigned k = 0; k < c && k <= a; ++k)
            A[(size_t)a * nn + k] *= sc[a];
}

/* t0 += x * a0, t1 += x * a1, t2 += x * a2 over n entries (vectorises). */
static void axpy3(double *restrict t0, double *restrict t1, double *restrict t2, const double *restrict x, double a0,
                  double a1, double a2, unsigned n)
{
    for (unsigned i = 0; i < n; ++i) {
        t0[i] += x[i] * a0;
        t1[i] += x[i] * a1;
        t2[i] += x[i] * a2;
    }
}

/* Longest semi-axis of the 95 % ellipsoid of J Cov J^T, J (3 x n, the
 * columns p->idx read), Cov packed in p: T = Cov J^T, then J T (upper
 * triangle); or, p factored, U = J F and U U^T; then its largest
 * eigenvalue in closed form. */
static double ellipsoid95(double J[3][RC_MAX_PARAMS], const cov_pack *p)
{
    const unsigned nn = p->nn;
    double jc[3][RC_MAX_PARAMS], T[3][RC_MAX_PARAMS], C[9] = {0};
    for (int i = 0; i < 3; ++i)
        for (unsigned a = 0; a < nn; ++a) {
            jc[i][a] = J[i][p->idx[a]];
            T[i][a] = 0.0;
        }
    /* C = U T^T (upper triangle) over len columns: factored, T = J F and U =
     * T; else T = Cov J^T (Cov symmetric: row b of Cov times J[i][b] added
     * to T[i]) and U = J */
    unsigned len = nn;
    double(*U)[RC_MAX_PARAMS] = jc;
    if (p->factored) { /* row a of F: min(a + 1, r) entries */
        for (unsigned a = 0; a < nn; ++a)
            axpy3(T[0], T[1], T[2], p->c + (size_t)a * nn, jc[0][a], jc[1][a], jc[2][a], a < p->r ? a + 1 : p->r);
        len = p->r;
        U = T;
    } else {
        for (unsigned b = 0; b < nn; ++b)
            axpy3(T[0], T[1], T[2], p->c + (size_t)b * nn, jc[0][b], jc[1][b], jc[2][b], nn);
    }
    for (int i = 0; i < 3; ++i)
        for (int j = i; j < 3; ++j) {
            double v = 0.0;
            for (unsigned a = 0; a < len; ++a)
                v += U[i][a] * T[j][a];
            C[i * 3 + j] = v;
        }
    return sqrt(CHI2_3_95 * fmax(rcu_sym3_eig_max(C), 0.0));
}

/* 95 % position semi-axis at q from a covariance cov (n x n, leading
 * dimension ld) over the parameters k < n with use[k] set. */
static double pos95_cov(const double *cov, size_t ld, const uint8_t *use, unsigned n, const rc_model *m,
                        const rc_kin *kin, const double q_rad[RC_NJ])
{
    double Jp[3][RC_MAX_PARAMS];
    cov_pack p;
    double *buf = malloc((size_t)n * n * sizeof *buf + 1);
    if (!buf)
        return NAN;
    pack_cov(&p, buf, cov, ld, use, n);
    fk_sensitivity(Jp, NULL, use, n, m, kin, q_rad);
    const double r = ellipsoid95(Jp, &p);
    free(buf);
    return r;
}

/* Parameters of the position uncertainty: identifiable and weak ones. */
static void use_pos(uint8_t *use, const rch_uncert *u)
{
    for (unsigned k = 0; k < u->n_params; ++k)
        use[k] = u->cls[k] == RCH_PARAM_IDENTIFIABLE || u->cls[k] == RCH_PARAM_WEAK ||
                 (u->has_prior && u->cls[k] != RCH_PARAM_FIXED);
}

/* Parameters of the orientation uncertainty: all but fixed and
 * not-identifiable ones, and with determined_only not those compensation
 * keeps nominal. */
static void use_rot(uint8_t *use, const rch_uncert *u, int determined_only)
{
    for (unsigned k = 0; k < u->n_params; ++k)
        use[k] = !(u->cls[k] == RCH_PARAM_FIXED || (u->cls[k] == RCH_PARAM_NOT_IDENTIFIABLE && !u->has_prior) ||
                   (determined_only && u->comp_nominal[k]));
}

double rch_uncert_pos95_mm(const rch_uncert *u, const rc_model *m, const double q_rad[RC_NJ])
{
    uint8_t use[RC_MAX_PARAMS];
    rc_kin kin;
    use_pos(use, u);
    return pos95_cov(u->cov, u->n_params, use, u->n_params, m, sens_compile(&kin, m), q_rad);
}

void rch_model_unc_from(rch_model_unc *out, const rch_uncert *u)
{
    memset(out, 0, sizeof *out);
    out->present = 1;
    out->n = u->n_params;
    out->kind = u->kind;
    out->n_groups = u->n_groups;
    out->rank = u->rank;
    out->sigma_mm = u->sigma_mm;
    memcpy(out->cls, u->cls, u->n_params);
    memcpy(out->comp_nominal, u->comp_nominal, u->n_params);
    memcpy(out->se, u->se, u->n_params * sizeof *u->se);
    out->has_prior = u->has_prior;
    memcpy(out->prior_cls, u->prior_cls, u->n_params);
    memcpy(out->prior_sd, u->prior_sd, u->n_params * sizeof *u->prior_sd);
    for (unsigned k = 0; k < RC_N_DH && k < u->n_params; ++k)
        for (unsigned l = 0; l < RC_N_DH && l < u->n_params; ++l)
            out->cov_dh[k * RC_N_DH + l] = u->cov[(size_t)k * u->n_params + l];
}

double rch_model_unc_pos95_mm(const rch_model_unc *u, const rc_model *m, const double q_rad[RC_NJ])
{
    uint8_t use[RC_N_DH];
    for (unsigned k = 0; k < RC_N_DH; ++k)
        use[k] = u->cls[k] != RCH_PARAM_FIXED && !u->comp_nominal[k] && isfinite(u->se[k]);
    rc_kin kin;
    return pos95_cov(u->cov_dh, RC_N_DH, use, RC_N_DH, m, sens_compile(&kin, m), q_rad);
}

double rch_model_unc_tool95_mm(const rch_model_unc *u, const rc_model *det, const rc_model *fit,
                               const double q_rad[RC_NJ], const double tool_mm[3])
{
    uint8_t use[RC_N_DH];
    for (unsigned k = 0; k < RC_N_DH; ++k)
        use[k] = u->cls[k] != RCH_PARAM_FIXED && isfinite(u->se[k]);
    double Jp[3][RC_MAX_PARAMS], Jr[3][RC_MAX_PARAMS], p[3], R[9], t[3], shift[3] = {0, 0, 0};
    rc_kin kin;
    fk_sensitivity(Jp, Jr, use, RC_N_DH, det, sens_compile(&kin, det), q_rad);
    rc_fk(p, R, det, q_rad);
    for (int i = 0; i < 3; ++i)
        t[i] = R[i * 3] * tool_mm[0] + R[i * 3 + 1] * tool_mm[1] + R[i * 3 + 2] * tool_mm[2];
    for (unsigned k = 0; k < RC_N_DH; ++k) { /* d(p + R t) = dp + w x (R t) */
        double w0 = Jr[0][k], w1 = Jr[1][k], w2 = Jr[2][k];
        Jp[0][k] += w1 * t[2] - w2 * t[1];
        Jp[1][k] += w2 * t[0] - w0 * t[2];
        Jp[2][k] += w0 * t[1] - w1 * t[0];
        if (u->comp_nominal[k] && use[k])
            for (int i = 0; i < 3; ++i)
                shift[i] += Jp[i][k] * (fit->x[k] - det->x[k]);
    }
    double buf[RC_N_DH * RC_N_DH];
    cov_pack cp;
    pack_cov(&cp, buf, u->cov_dh, RC_N_DH, use, RC_N_DH);
    return sqrt(shift[0] * shift[0] + shift[1] * shift[1] + shift[2] * shift[2]) + ellipsoid95(Jp, &cp);
}

double rch_model_unc_rot_trace(const rch_model_unc *u, const rc_model *m, const double q_rad[RC_NJ],
                               int determined_only, const double *axis)
{
    if (!u || !u->present)
        return NAN;
    uint8_t use[RC_N_DH];
    unsigned n_used = 0;
    for (unsigned k = 0; k < RC_N_DH; ++k) {
        use[k] = k < u->n && u->cls[k] != RCH_PARAM_FIXED && !u->comp_nominal[k] && isfinite(u->se[k]) &&
                 !(determined_only && u->has_prior && u->prior_cls[k] == RCH_PRIOR_CLASS_PRIOR_ONLY);
        n_used += use[k];
    }
    if (n_used == 0)
        return 0.0;
    double Jr[3][RC_MAX_PARAMS], tr = 0.0;
    rc_kin kin;
    fk_sensitivity(NULL, Jr, use, RC_N_DH, m, sens_compile(&kin, m), q_rad);
    for (unsigned a = 0; axis && a < RC_N_DH; ++a) { /* (I - axis axis^T) Jr: the tilt of the axis */
        const double c = axis[0] * Jr[0][a] + axis[1] * Jr[1][a] + axis[2] * Jr[2][a];
        for (int i = 0; i < 3; ++i)
            Jr[i][a] -= c * axis[i];
    }
    for (int i = 0; i < 3; ++i)
        for (unsigned a = 0; a < RC_N_DH; ++a) {
            if (!use[a] || Jr[i][a] == 0.0)
                continue;
            for (unsigned b = 0; b < RC_N_DH; ++b)
                if (use[b])
                    tr += Jr[i][a] * u->cov_dh[a * RC_N_DH + b] * Jr[i][b];
        }
    return tr > 0.0 ? tr : 0.0;
}

void rch_model_unc_determined(rc_model *out, const rc_model *fit, const rc_model *nominal, const rch_model_unc *u)
{
    *out = *fit;
    for (unsigned k = 0; k < RC_N_DH && k < u->n; ++k)
        if (u->comp_nominal[k])
            out->x[k] = nominal->x[k];
}

/* What the map evaluates at every pose: the covariance packed for the
 * position (pos), the orientation with every parameter (rot) and with those
 * compensation uses (det), and the parameters any of them reads (all). */
typedef struct {
    cov_pack pos, rot, det;
    uint8_t all[RC_MAX_PARAMS];
    double *buf; /* 3 x (n_params x n_params) behind the packs */
} map_ctx;

static int map_ctx_init(map_ctx *c, const rch_uncert *u)
{
    const unsigned np = u->n_params;
    uint8_t up[RC_MAX_PARAMS] = {0}, ur[RC_MAX_PARAMS] = {0}, ud[RC_MAX_PARAMS] = {0};
    c->buf = malloc(3 * (size_t)np * np * sizeof *c->buf + 1);
    if (!c->buf)
        return -1;
    use_pos(up, u);
    use_rot(ur, u, 0);
    use_rot(ud, u, 1);
    for (unsigned k = 0; k < np; ++k)
        c->all[k] = up[k] || ur[k];
    pack_cov(&c->pos, c->buf, u->cov, np, up, np);
    pack_cov(&c->rot, c->buf + (size_t)np * np, u->cov, np, ur, np);
    pack_cov(&c->det, c->buf + 2 * (size_t)np * np, u->cov, np, ud, np);
    factor_cov(&c->pos);
    factor_cov(&c->rot);
    factor_cov(&c->det);
    return 0;
}

/* The three figures of the map at one pose from one sensitivity: the 95 %
 * position semi-axis, the orientation one with every parameter and with
 * those compensation uses (rot and rot_det NULL: position only). */
static void map_pose(double *pos, double *rot, double *rot_det, const rch_uncert *u, const map_ctx *c,
                     const rc_model *m, const rc_kin *kin, const double q_rad[RC_NJ])
{
    double Jp[3][RC_MAX_PARAMS], Jr[3][RC_MAX_PARAMS];
    fk_sensitivity(Jp, rot ? Jr : NULL, c->all, u->n_params, m, kin, q_rad);
    *pos = ellipsoid95(Jp, &c->pos);
    if (rot == NULL)
        return;
    *rot = ellipsoid95(Jr, &c->rot) * 57.29577951308232;
    *rot_det = ellipsoid95(Jr, &c->det) * 57.29577951308232;
}

int rch_uncert_map_compute(rch_uncert_map *out, const rch_uncert *u, const rc_model *m, const rc_sample *s, size_t n,
                           size_t n_random, uint64_t seed)
{
    memset(out, 0, sizeof *out);
    const size_t nv = n > n_random ? n : n_random;
    map_ctx c;
    double *v = malloc(3 * nv * sizeof *v + 1);
    if (!v || map_ctx_init(&c, u) != 0) {
        free(v);
        return -1;
    }
    double *vr = v + nv, *vd = vr + nv;
    rc_kin kin;
    const rc_kin *k = sens_compile(&kin, m);
    for (size_t i = 0; i < n; ++i)
        map_pose(&v[i], &vr[i], &vd[i], u, &c, m, k, s[i].q_rad);
    rch_median_max(&out->data_median_mm, &out->data_max_mm, v, n);
    rch_median_max(&out->rot_data_median_deg, &out->rot_data_max_deg, vr, n);
    rch_median_max(&out->rot_det_median_deg, &out->rot_det_max_deg, vd, n);
    out->n_data = n;
    rc_rng g;
    rc_rng_seed(&g, seed);
    for (size_t i = 0; i < n_random; ++i) {
        double q[RC_NJ];
        for (int j = 0; j < RC_NJ; ++j)
            q[j] = m->q_min_rad[j] + (m->q_max_rad[j] - m->q_min_rad[j]) * rc_rng_u01(&g);
        map_pose(&v[i], NULL, NULL, u, &c, m, k, q);
    }
    rch_median_max(&out->work_median_mm, &out->work_max_mm, v, n_random);
    out->n_work = n_random;
    free(c.buf);
    free(v);
    return 0;
}

/* One orientation figure at q (det: with the parameters compensation uses). */
static double rot95_one(const rch_uncert *u, const rc_model *m, const double q_rad[RC_NJ], int det)
{
    double pos, rot, rdet;
    rc_kin kin;
    map_ctx c;
    if (map_ctx_init(&c, u) != 0)
        return NAN;
    map_pose(&pos, &rot, &rdet, u, &c, m, sens_compile(&kin, m), q_rad);
    free(c.buf);
    return det ? rdet : rot;
}

double rch_uncert_rot95_deg(const rch_uncert *u, const rc_model *m, const double q_rad[RC_NJ])
{
    return rot95_one(u, m, q_rad, 0);
}

double rch_uncert_rot95_det_deg(const rch_uncert *u, const rc_model *m, const double q_rad[RC_NJ])
{
    return rot95_one(u, m, q_rad, 1);
}

/* The 95 % quantile of |e| for e ~ N(0, C), C (3 x 3) with eigenvalues ev:
 * |e|^2 = sum ev_i z_i^2 taken as c chi2_nu with the same mean and variance
 * (Welch-Satterthwaite: c = sum ev^2 / sum ev, nu = (sum ev)^2 / sum ev^2),
 * its quantile by Wilson-Hilferty. Within 3 % of the exact radius from one
 * dominant axis (nu = 1) to a sphere (nu = 3). */
static double radius95(const double ev[3])
{
    double s1 = 0.0, s2 = 0.0;
    for (int i = 0; i < 3; ++i) {
        const double e = ev[i] > 0.0 ? ev[i] : 0.0;
        s1 += e;
        s2 += e * e;
    }
    if (!(s1 > 0.0))
        return 0.0;
    const double c = s2 / s1, nu = s1 * s1 / s2, z = 1.6448536269514722;
    const double h = 2.0 / (9.0 * nu), t = 1.0 - h + z * sqrt(h);
    return sqrt(c * nu * t * t * t);
}

double rch_model_unc_radius95_mm(const rch_model_unc *u, const rc_model *m, const double q_rad[RC_NJ])
{
    uint8_t use[RC_N_DH];
    double Jp[3][RC_MAX_PARAMS], C[9] = {0}, V[9], ev[3];
    for (unsigned k = 0; k < RC_N_DH; ++k)
        use[k] = u->cls[k] != RCH_PARAM_FIXED && !u->comp_nominal[k] && isfinite(u->se[k]);
    rc_kin kin;
    fk_sensitivity(Jp, NULL, use, RC_N_DH, m, sens_compile(&kin, m), q_rad);
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
            double v = 0.0;
            for (unsigned a = 0; a < RC_N_DH; ++a) {
                if (!use[a] || Jp[i][a] == 0.0)
                    continue;
                double t = 0.0;
                for (unsigned b = 0; b < RC_N_DH; ++b)
                    if (use[b])
                        t += u->cov_dh[a * RC_N_DH + b] * Jp[j][b];
                v += Jp[i][a] * t;
            }
            C[i * 3 + j] = v;
        }
    for (int i = 0; i < 3; ++i)
        for (int j = i + 1; j < 3; ++j)
            C[i * 3 + j] = C[j * 3 + i] = 0.5 * (C[i * 3 + j] + C[j * 3 + i]);
    memcpy(V, C, sizeof V);
    if (LAPACKE_dsyev(LAPACK_ROW_MAJOR, 'N', 'U', 3, V, 3, ev) != 0)
        return NAN;
    return radius95(ev);
}

double rch_uncert_radius95(const double C[9])
{
    double V[9], ev[3];
    for (int i = 0; i < 9; ++i)
        if (!isfinite(C[i]))
            return NAN;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            V[i * 3 + j] = 0.5 * (C[i * 3 + j] + C[j * 3 + i]);
    if (LAPACKE_dsyev(LAPACK_ROW_MAJOR, 'N', 'U', 3, V, 3, ev) != 0)
        return NAN;
    return radius95(ev);
}

size_t rch_uncert_point95(double *v, const rch_uncert *u, const rc_model *m, const rc_sample *s, size_t n,
                          const double t_mm[3], int t_first, int target)
{
    const unsigned np = u->n_params;
    uint8_t use[RC_MAX_PARAMS], use_fk[RC_MAX_PARAMS];
    rc_model f = *m; /* the flange: m with its tool offset at zero (its columns filled below) */
    use_pos(use, u);
    memcpy(use_fk, use, sizeof use_fk);
    for (unsigned e = 0; e < f.n_effects; ++e)
        if (f.effects[e].kind == RC_EFF_TOOL_OFFSET)
            for (unsigned c = 0; c < f.effects[e].count; ++c) {
                f.x[f.effects[e].first + c] = 0.0;
                use_fk[f.effects[e].first + c] = 0;
                if ((int)(f.effects[e].first + c) < t_first || (int)(f.effects[e].first + c) > t_first + 2)
                    use[f.effects[e].first + c] = 0;
            }
    if (t_first >= 0)
        for (int c = 0; c < 3; ++c)
            use_fk[t_first + c] = 0;
    double *buf = malloc((size_t)np * np * sizeof *buf + 1);
    if (!buf)
        return 0;
    cov_pack p;
    pack_cov(&p, buf, u->cov, np, use, np);
    factor_cov(&p);
    rc_kin kin;
    const rc_kin *k = sens_compile(&kin, &f);
    size_t out = 0;
    for (size_t i = 0; i < n; ++i) {
        if (target >= 0 && (s[i].sensor == RC_SENSOR_LENGTH || s[i].target != (unsigned)target))
            continue;
        double Jp[3][RC_MAX_PARAMS], Jr[3][RC_MAX_PARAMS], pf[3], R[9], t[3];
        fk_sensitivity(Jp, Jr, use_fk, np, &f, k, s[i].q_rad);
        rc_fk(pf, R, &f, s[i].q_rad);
        for (int a = 0; a < 3; ++a)
            t[a] = R[a * 3] * t_mm[0] + R[a * 3 + 1] * t_mm[1] + R[a * 3 + 2] * t_mm[2];
        for (unsigned c = 0; c < np; ++c) { /* d(p + R t) = dp + w x (R t) */
            const double w0 = Jr[0][c], w1 = Jr[1][c], w2 = Jr[2][c];
            Jp[0][c] += w1 * t[2] - w2 * t[1];
            Jp[1][c] += w2 * t[0] - w0 * t[2];
            Jp[2][c] += w0 * t[1] - w1 * t[0];
        }
        for (int c = 0; t_first >= 0 && c < 3; ++c)
            for (int a = 0; a < 3; ++a)
                Jp[a][t_first + c] = R[a * 3 + c];
        v[out++] = ellipsoid95(Jp, &p);
    }
    free(buf);
    return out;
}

void rch_uncert_point_sens(double Jp[3][RC_MAX_PARAMS], const rc_model *m, const double q_rad[RC_NJ])
{
    uint8_t use[RC_MAX_PARAMS];
    rc_kin kin;
    memset(use, 1, sizeof use);
    fk_sensitivity(Jp, NULL, use, m->n_params, m, sens_compile(&kin, m), q_rad);
}
