/* SPDX-License-Identifier: MIT */
/* rc_model.c - kinematics and the cable-length measurement model. */
#include "rc_model.h"

#include "rc_sensor.h"

#include <math.h>
#include <string.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

RC_STATIC_ASSERT(RC_MAX_PARAMS <= 65535, params_fit_uint16);

/* Frames of the chain: o[k] origin and R[k] rotation of frame k (frame 0 is
 * the base, frame k the one after joint k's transform). */
typedef struct {
    double o[RC_NJ + 1][3];
    double R[RC_NJ + 1][9];
} chain;

#define RC_CHAIN_T double
#define RC_CHAIN_LINK chain_link
#include "rc_chain.inc" /* the one link transform (also rc_kin.c's) */

static const double chain_eye[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};

/* The chain from the DH lengths (dh[i][0] a, dh[i][1] d) and the cosines and
 * sines of the joint angles (ct, st) and of the alphas (ca, sa), (nj) each;
 * row i's axis tilt (Hayati's beta) from cm1[i] = cos b - 1, ts[i] = sin b
 * (NULL: none). */
static void chain_trig(chain *c, const double dh[][4], const double ct[], const double st[], const double ca[],
                       const double sa[], unsigned nj, const double *cm1, const double *ts)
{
    memcpy(c->R[0], chain_eye, sizeof chain_eye);
    c->o[0][0] = c->o[0][1] = c->o[0][2] = 0.0;
    for (unsigned i = 0; i < nj; ++i)
        chain_link(c->R[i + 1], c->o[i + 1], c->R[i], c->o[i], dh[i][0], dh[i][1], ct[i], st[i], ca[i], sa[i],
                   cm1 ? cm1[i] : 0.0, ts ? ts[i] : 0.0, 1);
}

/* chain_trig for the six joints of a model in the solver's passes: the
 * tilts from the prepared model pr (or none); with full = 0 the last
 * rotation R6 is left out (a length without Jacobian or tool offset needs o6
 * only). */
static void chain_axes(chain *c, const rc_model *m, const double ct[RC_NJ], const double st[RC_NJ],
                       const double ca[RC_NJ], const double sa[RC_NJ], int full, const rc_meas_prep *pr)
{
    memcpy(c->R[0], chain_eye, sizeof chain_eye);
    c->o[0][0] = c->o[0][1] = c->o[0][2] = 0.0;
    for (unsigned i = 0; i < RC_NJ; ++i) {
        const int tilt = pr != NULL && pr->tilt_at[i] >= 0;
        chain_link(c->R[i + 1], c->o[i + 1], c->R[i], c->o[i], m->x[RC_P_A(i)], m->x[RC_P_D(i)], ct[i], st[i],
                   ca[i], sa[i], tilt ? pr->tilt_cm1[i] : 0.0, tilt ? pr->tilt_s[i] : 0.0, full || i + 1 < RC_NJ);
    }
}

static void chain_compute(chain *c, const double dh[][4], const double theta_rad[], unsigned nj)
{
    double ct[RC_NJ], st[RC_NJ], ca[RC_NJ], sa[RC_NJ];
    for (unsigned i = 0; i < nj; ++i) {
        ct[i] = cos(theta_rad[i]);
        st[i] = sin(theta_rad[i]);
        ca[i] = cos(dh[i][2]);
        sa[i] = sin(dh[i][2]);
    }
    chain_trig(c, dh, ct, st, ca, sa, nj, NULL, NULL);
}

/* The axis tilts of m: cm1, ts (6) cos(beta) - 1 and sin(beta), at (6) the
 * index of each row's beta in x or -1. Returns 1 when any row is tilted. */
static int model_tilts(double cm1[RC_NJ], double ts[RC_NJ], int16_t at[RC_NJ], const rc_model *m)
{
    int any = 0;
    for (unsigned i = 0; i < RC_NJ; ++i) {
        cm1[i] = ts[i] = 0.0;
        at[i] = -1;
    }
    for (unsigned e = 0; e < m->n_effects; ++e) {
        const rc_effect *ef = &m->effects[e];
        if (ef->kind != RC_EFF_AXIS_TILT || ef->joint >= RC_NJ || at[ef->joint] >= 0)
            continue;
        const double b = m->x[ef->first], h = sin(0.5 * b);
        cm1[ef->joint] = -2.0 * h * h; /* cos b - 1 without cancellation */
        ts[ef->joint] = sin(b);
        at[ef->joint] = (int16_t)ef->first;
        any = 1;
    }
    return any;
}

static void cross3(double out[3], const double a[3], const double b[3])
{
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}

static double dot3(const double a[3], const double b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

rc_status rc_model_init(rc_model *m, const double dh[RC_NJ][4], const double enc_mm[3])
{
    RC_ASSERT(m != NULL && dh != NULL && enc_mm != NULL);
    memset(m, 0, sizeof *m);
    for (unsigned i = 0; i < RC_NJ; ++i) {
        for (unsigned k = 0; k < 4; ++k) {
            if (!isfinite(dh[i][k]))
                return RC_ERR_RANGE;
            m->x[4 * i + k] = dh[i][k];
        }
        m->q_min_rad[i] = -M_PI;
        m->q_max_rad[i] = M_PI;
    }
    for (unsigned k = 0; k < 3; ++k) {
        if (!isfinite(enc_mm[k]))
            return RC_ERR_RANGE;
        m->x[RC_P_ENC + k] = enc_mm[k];
    }
    m->n_params = RC_N_BASE;
    return RC_OK;
}

/* The table of effects, indexed by kind (rc_model.h, rc_effect_desc). */
#define RC_EFF_DESC_(id, ...) {RC_EFF_##id, __VA_ARGS__},
static const rc_effect_desc effect_table[] = {RC_EFFECTS(RC_EFF_DESC_)};
#undef RC_EFF_DESC_
RC_STATIC_ASSERT(sizeof effect_table / sizeof effect_table[0] == RC_EFF_LAST + 1, effect_table_covers_every_kind);

const rc_effect_desc *rc_effect_describe(unsigned kind)
{
    if (kind == RC_EFF_NONE || kind > RC_EFF_LAST)
        return NULL;
    RC_ASSERT(effect_table[kind].kind == kind);
    return &effect_table[kind];
}

int rc_effect_by_name(const char *name)
{
    if (name == NULL)
        return -1;
    for (unsigned k = 1; k <= RC_EFF_LAST; ++k)
        if (strcmp(effect_table[k].name, name) == 0)
            return (int)k;
    return -1;
}

rc_status rc_model_add_effect(rc_model *m, rc_effect_kind kind, unsigned joint, unsigned count)
{
    RC_ASSERT(m != NULL);
    const rc_effect_desc *ds = rc_effect_describe((unsigned)kind);
    if (ds == NULL)
        return RC_ERR_ARG;
    unsigned n = ds->count;
    if (ds->arg == RC_EFF_ARG_COUNT)
        n = count;
    if (ds->arg != RC_EFF_ARG_JOINT && ds->arg != RC_EFF_ARG_OUTLET)
        joint = 0;
    if (kind == RC_EFF_TIME_DRIFT) { /* polynomial in t without constant, degree 1..4; 0: 3 */
        n = count == 0 ? 3u : count;
        if (n > 4)
            return RC_ERR_ARG;
    }
    if ((kind == RC_EFF_OUTLET_OFFSET || kind == RC_EFF_OUTLET_SCALE) && n == 0) {
        n = 1; /* one per outlet: e and every RC_EFF_OUTLET */
        for (unsigned i = 0; i < m->n_effects; ++i)
            if (m->effects[i].kind == RC_EFF_OUTLET && m->effects[i].joint + 1u > n)
                n = m->effects[i].joint + 1u;
    }
    if (kind == RC_EFF_JOINT_COMPLIANCE && joint != 1 && joint != 2)
        return RC_ERR_ARG; /* gravity lever defined for joints 2 and 3 */
    if (ds->arg == RC_EFF_ARG_OUTLET) {
        if (joint < 1 || joint >= RC_MAX_OUTLETS)
            return RC_ERR_ARG;
        for (unsigned i = 0; i < m->n_effects; ++i)
            if (m->effects[i].kind == RC_EFF_OUTLET && m->effects[i].joint == joint)
                return RC_ERR_ARG; /* one effect per outlet */
    } else if (joint >= RC_NJ) {
        return RC_ERR_ARG;
    }
    if (ds->count == 0 && ds->suffixes[0] != '\0') { /* a group of named parameters per item (target, point) */
        unsigned per = 1;
        for (const char *c = ds->suffixes; *c; ++c)
            per += *c == '|';
        if (n % per != 0 || n > per * RC_MAX_TARGETS)
            return RC_ERR_ARG; /* three per target, per point */
    }
    if (ds->side == RC_SIDE_SENSOR || kind == RC_EFF_CABLE_POINTS)
        for (unsigned i = 0; i < m->n_effects; ++i)
            if (m->effects[i].kind == (uint8_t)kind)
                return RC_ERR_ARG; /* one tracker frame, one set of targets, one plate */
    if (n == 0)
        return RC_ERR_ARG;
    if (m->n_effects >= RC_MAX_EFFECTS || (unsigned)m->n_params + n > RC_MAX_PARAMS)
        return RC_ERR_CAPACITY;
    rc_effect *e = &m->effects[m->n_effects++];
    memset(e, 0, sizeof *e);
    e->kind = (uint8_t)kind;
    e->joint = (uint8_t)joint;
    e->first = m->n_params;
    e->count = (uint16_t)n;
    for (unsigned i = 0; i < 4; ++i)
        for (unsigned k = 0; k < 4; ++k)
            e->ref_dh[i][k] = m->x[4 * i + k];
    for (unsigned k = 0; k < n; ++k)
        m->x[m->n_params + k] = 0.0;
    m->n_params = (uint16_t)(m->n_params + n);
    return RC_OK;
}

void rc_model_wrap_angles(rc_model *m)
{
    RC_ASSERT(m != NULL);
    for (unsigned i = 0; i < RC_NJ; ++i) {
        for (unsigned k = RC_P_ALPHA(i); k <= RC_P_THETA(i); ++k) {
            double a = m->x[k];
            /* fmod by the double nearest 2 pi is exact but shifts the angle
             * by 2.4e-16 rad per turn: beyond 1e6 rad (4e-11 rad) wrapping
             * would change the model, so such angles stay as they are. */
            if (!isfinite(a) || fabs(a) > 1e6)
                continue;
            a = fmod(a, 2.0 * M_PI); /* (-2 pi, 2 pi) */
            if (a > M_PI)
                a -= 2.0 * M_PI;
            else if (a <= -M_PI)
                a += 2.0 * M_PI;
            m->x[k] = a;
        }
    }
}

const char *rc_effect_name(rc_effect_kind kind)
{
    const rc_effect_desc *ds = rc_effect_describe((unsigned)kind);
    return ds ? ds->name : "none";
}

/* Small bounded formatter: copies s into buf at *pos. */
static void put_str(char *buf, size_t len, size_t *pos, const char *s)
{
    while (*s != '\0' && *pos + 1 < len)
        buf[(*pos)++] = *s++;
    buf[*pos < len ? *pos : len - 1] = '\0';
}

static void put_uint(char *buf, size_t len, size_t *pos, unsigned v)
{
    char tmp[12];
    int n = 0;
    do {
        tmp[n++] = (char)('0' + v % 10u);
        v /= 10u;
    } while (v != 0 && n < 11);
    while (n > 0 && *pos + 1 < len)
        buf[(*pos)++] = tmp[--n];
    buf[*pos < len ? *pos : len - 1] = '\0';
}

const char *rc_param_name(char *buf, size_t buf_len, const rc_model *m, unsigned k)
{
    static const char *const dh_names[4] = {"a", "d", "alpha", "theta"};
    static const char *const enc_names[3] = {"ex", "ey", "ez"};
    size_t pos = 0;
    RC_ASSERT(buf != NULL && buf_len > 0 && m != NULL);
    buf[0] = '\0';
    if (k < RC_N_DH) {
        put_str(buf, buf_len, &pos, dh_names[k % 4]);
        put_uint(buf, buf_len, &pos, k / 4 + 1);
        return buf;
    }
    if (k < RC_N_BASE) {
        put_str(buf, buf_len, &pos, enc_names[k - RC_N_DH]);
        return buf;
    }
    for (unsigned i = 0; i < m->n_effects; ++i) {
        const rc_effect *e = &m->effects[i];
        if (k < e->first || k >= (unsigned)e->first + e->count)
            continue;
        unsigned j = k - e->first;
        const rc_effect_desc *ds = rc_effect_describe(e->kind);
        if (ds == NULL)
            break;
        put_str(buf, buf_len, &pos, ds->name);
        if (ds->arg == RC_EFF_ARG_JOINT) {
            put_str(buf, buf_len, &pos, ".j");
            put_uint(buf, buf_len, &pos, e->joint + 1u);
        } else if (ds->arg == RC_EFF_ARG_OUTLET) {
            put_str(buf, buf_len, &pos, ".");
            put_uint(buf, buf_len, &pos, e->joint);
        }
        if (ds->suffixes[0] != '\0') { /* the j-th of "a|b|c" */
            unsigned ns = 1;
            for (const char *c = ds->suffixes; *c != '\0'; ++c)
                ns += *c == '|';
            if (e->count > ns) { /* repeated: name.<prefix><repeat>.<suffix> */
                put_str(buf, buf_len, &pos, ".");
                put_str(buf, buf_len, &pos, ds->index_prefix);
                put_uint(buf, buf_len, &pos, j / ns + ds->index_base);
                j %= ns;
            }
            const char *sfx = ds->suffixes;
            for (unsigned t = 0; t < j && *sfx != '\0'; ++sfx)
                t += *sfx == '|';
            put_str(buf, buf_len, &pos, ".");
            while (*sfx != '\0' && *sfx != '|' && pos + 1 < buf_len)
                buf[pos++] = *sfx++;
            buf[pos] = '\0';
        } else if (e->count > 1 || ds->index_prefix[0] != '\0') {
            put_str(buf, buf_len, &pos, ".");
            put_str(buf, buf_len, &pos, ds->index_prefix);
            put_uint(buf, buf_len, &pos, j + ds->index_base);
        }
        return buf;
    }
    put_str(buf, buf_len, &pos, "p");
    put_uint(buf, buf_len, &pos, k);
    return buf;
}

const rc_effect *rc_param_effect(const rc_model *m, unsigned k)
{
    RC_ASSERT(m != NULL);
    for (unsigned i = 0; i < m->n_effects; ++i) {
        const rc_effect *e = &m->effects[i];
        if (k >= e->first && k < (unsigned)e->first + e->count)
            return e;
    }
    return NULL;
}

int rc_param_unit(const rc_model *m, unsigned k)
{
    if (k < RC_N_DH)
        return (k % 4 == 0 || k % 4 == 1) ? 0 : 1;
    if (k < RC_N_BASE)
        return 0;
    const rc_effect *e = rc_param_effect(m, k);
    if (e == NULL)
        return 2;
    const rc_effect_desc *ds = rc_effect_describe(e->kind);
    return ds ? ds->unit : 2;
}

double rc_gravity_lever_m(const double ref_dh[4][4], unsigned joint, const double q_rad[RC_NJ])
{
    chain c;
    double th[4], v[3], w[3];
    static const double down[3] = {0.0, 0.0, -1.0};
    RC_ASSERT(joint < 4);
    for (unsigned i = 0; i < 4; ++i)
        th[i] = q_rad[i] + ref_dh[i][3];
    chain_compute(&c, ref_dh, th, 4);
    const double z[3] = {c.R[joint][2], c.R[joint][5], c.R[joint][8]};
    for (int r = 0; r < 3; ++r)
        v[r] = c.o[4][r] - c.o[joint][r];
    cross3(w, v, down);
    return dot3(z, w) * 1e-3;
}

void rc_model_theta(double theta_rad[RC_NJ], const rc_model *m, const double q_rad[RC_NJ])
{
    for (unsigned i = 0; i < RC_NJ; ++i)
        theta_rad[i] = q_rad[i] + m->x[RC_P_THETA(i)];
    for (unsigned i = 0; i < m->n_effects; ++i) {
        const rc_effect *e = &m->effects[i];
        const double *p = &m->x[e->first];
        const double q = e->joint < RC_NJ ? q_rad[e->joint] : 0.0; /* outlets and targets: no joint */
        if (e->kind == RC_EFF_JOINT_COMPLIANCE)
            theta_rad[e->joint] += p[0] * rc_gravity_lever_m(e->ref_dh, e->joint, q_rad);
        else if (e->kind == RC_EFF_JOINT_PERIODIC)
            theta_rad[e->joint] += p[0] * sin(q) + p[1] * cos(q) + p[2] * sin(2.0 * q) + p[3] * cos(2.0 * q);
    }
}

/* dtheta/dq (6 x 6, row = theta index, column = q index) including effects. */
static void theta_dq(double D[36], const rc_model *m, const double q_rad[RC_NJ])
{
    memset(D, 0, 36 * sizeof D[0]);
    for (unsigned i = 0; i < RC_NJ; ++i)
        D[7 * i] = 1.0;
    for (unsigned i = 0; i < m->n_effects; ++i) {
        const rc_effect *e = &m->effects[i];
        const double *p = &m->x[e->first];
        const unsigned j = e->joint;
        const double q = j < RC_NJ ? q_rad[j] : 0.0;
        if (e->kind == RC_EFF_JOINT_PERIODIC) {
            D[7 * j] += p[0] * cos(q) - p[1] * sin(q) + 2.0 * p[2] * cos(2.0 * q) - 2.0 * p[3] * sin(2.0 * q);
        } else if (e->kind == RC_EFF_JOINT_COMPLIANCE && p[0] != 0.0) {
            /* The lever depends on q2..q4 smoothly; a central difference is
             * exact enough for Newton steps (it scales the Jacobian only). */
            double qq[RC_NJ];
            const double h = 1e-6;
            memcpy(qq, q_rad, sizeof qq);
            for (unsigned k = 0; k < 4; ++k) {
                const double q0 = qq[k];
                qq[k] = q0 + h;
                const double fp = rc_gravity_lever_m(e->ref_dh, j, qq);
                qq[k] = q0 - h;
                const double fm = rc_gravity_lever_m(e->ref_dh, j, qq);
                qq[k] = q0;
                D[6 * j + k] += p[0] * (fp - fm) / (2.0 * h);
            }
        }
    }
}

/* Index of the tool-offset parameters in x, or -1. */
static int tool_index(const rc_model *m)
{
    for (unsigned i = 0; i < m->n_effects; ++i)
        if (m->effects[i].kind == RC_EFF_TOOL_OFFSET)
            return (int)m->effects[i].first;
    return -1;
}

/* Index of the cable points' parameters in x, or -1; *count: their points. */
static int points_index(const rc_model *m, unsigned *count)
{
    *count = 0;
    for (unsigned i = 0; i < m->n_effects; ++i)
        if (m->effects[i].kind == RC_EFF_CABLE_POINTS) {
            *count = m->effects[i].count / 3u;
            return (int)m->effects[i].first;
        }
    return -1;
}

/* The index in x of the point sample s measures (its cable point with
 * RC_EFF_CABLE_POINTS: pi its first parameter, np the points; else tool). */
static int sample_point(const rc_sample *s, int tool, int pi, unsigned np)
{
    if (pi >= 0 && s->sensor == RC_SENSOR_LENGTH && s->target < np)
        return pi + 3 * (int)s->target;
    return tool;
}

/* The measured point tool (3) of chain c: the flange origin, plus R6 t with
 * a tool offset at x[ti] (ti < 0: none). */
static void chain_tool(double tool[3], const chain *c, const rc_model *m, int ti)
{
    for (unsigned r = 0; r < 3; ++r) {
        tool[r] = c->o[RC_NJ][r];
        if (ti >= 0) {
            const double *t = &m->x[ti];
            const double *R = c->R[RC_NJ];
            tool[r] += R[3 * r] * t[0] + R[3 * r + 1] * t[1] + R[3 * r + 2] * t[2];
        }
    }
}

/* Chain of the model at q; tool (3) receives the measured point. */
static void model_chain(chain *c, double tool[3], const rc_model *m, const double q_rad[RC_NJ])
{
    double th[RC_NJ], cm1[RC_NJ], ts[RC_NJ];
    int16_t at[RC_NJ];
    rc_model_theta(th, m, q_rad);
    if (model_tilts(cm1, ts, at, m)) {
        double ct[RC_NJ], st[RC_NJ], ca[RC_NJ], sa[RC_NJ];
        for (unsigned i = 0; i < RC_NJ; ++i) {
            ct[i] = cos(th[i]);
            st[i] = sin(th[i]);
            ca[i] = cos(m->x[RC_P_ALPHA(i)]);
            sa[i] = sin(m->x[RC_P_ALPHA(i)]);
        }
        chain_trig(c, (const double(*)[4])m->x, ct, st, ca, sa, RC_NJ, cm1, ts);
    } else {
        chain_compute(c, (const double(*)[4])m->x, th, RC_NJ);
    }
    chain_tool(tool, c, m, tool_index(m));
}

void rc_fk(double pos_mm[3], double rot[9], const rc_model *m, const double q_rad[RC_NJ])
{
    chain c;
    double tool[3];
    RC_ASSERT(pos_mm != NULL && m != NULL && q_rad != NULL);
    model_chain(&c, tool, m, q_rad);
    memcpy(pos_mm, tool, 3 * sizeof pos_mm[0]);
    if (rot != NULL)
        memcpy(rot, c.R[RC_NJ], 9 * sizeof rot[0]);
}

void rc_fk_jac(double pos_mm[3], double rot[9], double jac[36], const rc_model *m,
               const double q_rad[RC_NJ])
{
    chain c;
    double Jt[36], D[36], p[3];
    RC_ASSERT(pos_mm != NULL && jac != NULL && m != NULL && q_rad != NULL);
    model_chain(&c, p, m, q_rad);
    for (unsigned i = 0; i < RC_NJ; ++i) {
        const double z[3] = {c.R[i][2], c.R[i][5], c.R[i][8]};
        double v[3], w[3];
        for (int r = 0; r < 3; ++r)
            v[r] = p[r] - c.o[i][r];
        cross3(w, z, v);
        for (unsigned r = 0; r < 3; ++r) {
            Jt[6 * r + i] = w[r];
            Jt[6 * (r + 3) + i] = z[r];
        }
    }
    theta_dq(D, m, q_rad);
    for (int r = 0; r < 6; ++r)
        for (int k = 0; k < 6; ++k) {
            double s = 0.0;
            for (int i = 0; i < 6; ++i)
                s += Jt[6 * r + i] * D[6 * i + k];
            jac[6 * r + k] = s;
        }
    memcpy(pos_mm, p, 3 * sizeof pos_mm[0]);
    if (rot != NULL)
        memcpy(rot, c.R[RC_NJ], 9 * sizeof rot[0]);
}

void rc_qtrig_fill(double *sin_q, double *cos_q, const rc_sample *samples, size_t n)
{
    RC_ASSERT(sin_q != NULL && cos_q != NULL && (samples != NULL || n == 0));
    for (size_t k = 0; k < n; ++k)
        for (unsigned i = 0; i < RC_NJ; ++i) {
            const double q = samples[k].q_rad[i]; /* one load: sin and cos fuse to sincos */
            sin_q[RC_NJ * k + i] = sin(q);
            cos_q[RC_NJ * k + i] = cos(q);
        }
}

void rc_meas_prepare(rc_meas_prep *p, const rc_model *m)
{
    RC_ASSERT(p != NULL && m != NULL);
    memset(p, 0, sizeof *p);
    for (unsigned i = 0; i < RC_NJ; ++i) {
        const double th = m->x[RC_P_THETA(i)], al = m->x[RC_P_ALPHA(i)];
        p->cos_off[i] = cos(th);
        p->sin_off[i] = sin(th);
        p->cos_alpha[i] = cos(al);
        p->sin_alpha[i] = sin(al);
    }
    p->tool = (int16_t)tool_index(m);
    unsigned np;
    p->points = (int16_t)points_index(m, &np);
    p->n_points = (uint8_t)np;
    p->has_tilt = (uint8_t)model_tilts(p->tilt_cm1, p->tilt_s, p->tilt_at, m);
    for (unsigned i = 0; i < m->n_effects; ++i) {
        const rc_effect *e = &m->effects[i];
        if (e->kind == RC_EFF_JOINT_COMPLIANCE || e->kind == RC_EFF_JOINT_PERIODIC) {
            p->joint_effect[e->joint] = 1;
            p->has_joint_effect = 1;
        }
    }
}

static rc_status meas_chain(double *len_mm, double *jac, const rc_model *m, const rc_sample *s, const chain *c,
                            const double p[3]);

rc_status rc_meas(double *len_mm, double *jac, const rc_model *m, const rc_sample *s)
{
    chain c;
    double p[3];
    unsigned np;
    RC_ASSERT(len_mm != NULL && m != NULL && s != NULL);
    model_chain(&c, p, m, s->q_rad);
    const int pi = points_index(m, &np), tool = tool_index(m), at = sample_point(s, tool, pi, np);
    if (at != tool)
        chain_tool(p, &c, m, at);
    return meas_chain(len_mm, jac, m, s, &c, p);
}

/* Chain of the model at sample s by angle addition; p (3) the measured point.
 * full = 0: R[6] is not needed (rc_meas_prepared without jac). */
static void chain_prepared(chain *c, double p[3], const rc_model *m, const rc_meas_prep *pr, const rc_sample *s,
                           const double *sin_q, const double *cos_q, int full)
{
    double own_s[RC_NJ], own_c[RC_NJ], ct[RC_NJ], st[RC_NJ];
    if (sin_q == NULL || cos_q == NULL) {
        rc_qtrig_fill(own_s, own_c, s, 1);
        sin_q = own_s;
        cos_q = own_c;
    }
    for (unsigned i = 0; i < RC_NJ; ++i) { /* angle addition: q_i + theta_off_i */
        ct[i] = cos_q[i] * pr->cos_off[i] - sin_q[i] * pr->sin_off[i];
        st[i] = sin_q[i] * pr->cos_off[i] + cos_q[i] * pr->sin_off[i];
    }
    if (pr->has_joint_effect) {
        double th[RC_NJ];
        rc_model_theta(th, m, s->q_rad);
        for (unsigned i = 0; i < RC_NJ; ++i)
            if (pr->joint_effect[i]) {
                ct[i] = cos(th[i]);
                st[i] = sin(th[i]);
            }
    }
    const int at = sample_point(s, pr->tool, pr->points, pr->n_points);
    chain_axes(c, m, ct, st, pr->cos_alpha, pr->sin_alpha, full || at >= 0 || pr->has_tilt || s->sensor != 0,
               pr->has_tilt ? pr : NULL);
    chain_tool(p, c, m, at);
}

void rc_point_prepared(double pos_mm[3], const rc_model *m, const rc_meas_prep *p, const rc_sample *s,
                       const double *sin_q, const double *cos_q)
{
    chain c;
    RC_ASSERT(pos_mm != NULL && m != NULL && p != NULL && s != NULL);
    chain_prepared(&c, pos_mm, m, p, s, sin_q, cos_q, 0);
}

rc_status rc_meas_prepared(double *len_mm, double *jac, const rc_model *m, const rc_meas_prep *pr,
                           const rc_sample *s, const double *sin_q, const double *cos_q)
{
    chain c;
    double p[3];
    RC_ASSERT(len_mm != NULL && m != NULL && pr != NULL && s != NULL);
    chain_prepared(&c, p, m, pr, s, sin_q, cos_q, jac != NULL);
    return meas_chain(len_mm, jac, m, s, &c, p);
}

/* The chain's part of a measurement's Jacobian row: g (3) = d value / d p at
 * the point p (3) moved rigidly with the flange, into jac's DH rows, axis
 * tilts and joint-side effects; dl_dtheta (6) receives d value / d theta_i.
 * The one chain rule of every sensor (lengths, tracker positions). */
static void point_jac(double *jac, double dl_dtheta[RC_NJ], const rc_model *m, const rc_sample *s, const chain *c,
                      const double p[3], const double g[3])
{
    double cm1[RC_NJ], ts[RC_NJ];
    int16_t tat[RC_NJ];
    const int tilted = model_tilts(cm1, ts, tat, m);
    for (unsigned i = 0; i < RC_NJ; ++i) {
        const double z[3] = {c->R[i][2], c->R[i][5], c->R[i][8]};
        double x1[3] = {c->R[i + 1][0], c->R[i + 1][3], c->R[i + 1][6]};
        double v[3], w[3];
        if (tilted && tat[i] >= 0) { /* a and alpha act along x before the tilt: x = cos b x' + sin b z' */
            const double z1[3] = {c->R[i + 1][2], c->R[i + 1][5], c->R[i + 1][8]};
            for (int r = 0; r < 3; ++r)
                x1[r] = x1[r] + cm1[i] * x1[r] + ts[i] * z1[r];
        }
        for (int r = 0; r < 3; ++r)
            v[r] = p[r] - c->o[i][r];
        cross3(w, z, v);
        dl_dtheta[i] = dot3(g, w);
        for (int r = 0; r < 3; ++r)
            v[r] = p[r] - c->o[i + 1][r];
        cross3(w, x1, v);
        jac[RC_P_A(i)] = dot3(g, x1);
        jac[RC_P_D(i)] = dot3(g, z);
        jac[RC_P_ALPHA(i)] = dot3(g, w);
        jac[RC_P_THETA(i)] = dl_dtheta[i];
    }
    for (unsigned i = 0; i < m->n_effects; ++i) {
        const rc_effect *ef = &m->effects[i];
        double *J = &jac[ef->first];
        const double q = ef->joint < RC_NJ ? s->q_rad[ef->joint] : 0.0;
        switch ((rc_effect_kind)ef->kind) {
        case RC_EFF_AXIS_TILT: { /* a turn about y of frame j+1 at its origin */
            const unsigned j = ef->joint < RC_NJ ? ef->joint : 0u;
            const double y1[3] = {c->R[j + 1][1], c->R[j + 1][4], c->R[j + 1][7]};
            double v[3], w[3];
            for (int r = 0; r < 3; ++r)
                v[r] = p[r] - c->o[j + 1][r];
            cross3(w, y1, v);
            J[0] = tat[j] == (int16_t)ef->first ? dot3(g, w) : 0.0;
            break;
        }
        case RC_EFF_JOINT_COMPLIANCE:
            J[0] = dl_dtheta[ef->joint] * rc_gravity_lever_m(ef->ref_dh, ef->joint, s->q_rad);
            break;
        case RC_EFF_JOINT_PERIODIC: {
            const double gj = dl_dtheta[ef->joint];
            J[0] = gj * sin(q);
            J[1] = gj * cos(q);
            J[2] = gj * sin(2.0 * q);
            J[3] = gj * cos(2.0 * q);
            break;
        }
        default: break;
        }
    }
}

/* A sample of a sensor with a hook (RC_SENSORS, rc_sensor.h): its value
 * and Jacobian row, the chain's part along the hook's gradient. */
static rc_status sensor_chain(double *value, double *jac, const rc_model *m, const rc_sample *s, const chain *c)
{
    double pt[3], g[3], dl_dtheta[RC_NJ];
    const rc_status st = rc_sensor_hook(s->sensor)(value, pt, g, jac, m, s, c->o[RC_NJ], c->R[RC_NJ]);
    if (st == RC_OK && jac != NULL)
        point_jac(jac, dl_dtheta, m, s, c, pt, g);
    return st;
}

/* A length's effects: what each kind's function reads (the sample, the
 * chain, the chord) and what it adds to (the length's scale and additive
 * terms, the gradient gd (3) of the chord-dependent terms with respect to
 * the chord). Each kind has one function, called twice per length: with
 * g == NULL it adds its value and, when J is not NULL, writes its columns
 * that do not depend on dl/dp; with g (dl/dp, 3) it writes the columns that
 * do (an outlet's, a tool point's). */
typedef struct len_terms {
    const rc_model *m;
    const rc_sample *s;
    const chain *c;
    double u[3];          /* the chord's direction */
    double dist, h2;      /* the chord (mm) and its horizontal span squared (mm^2) */
    int outlet_first;     /* the sample's outlet effect's first parameter, -1: e */
    const double *g;      /* NULL: the value pass; else dl/dp (3): the gradient pass */
    double scale, add, gd[3];
} len_terms;

typedef void (*eff_fn)(len_terms *t, double *J, const rc_effect *ef, const double *x);

/* Kinds with no part in a length's value (joint, geometry side: the chain's, point_jac). */
static void eff_none(len_terms *t, double *J, const rc_effect *ef, const double *x)
{
    (void)t, (void)J, (void)ef, (void)x;
}
#define eff_NONE eff_none

/* Another sensor's (the tracker's frame and targets): no part in a length. */
static void eff_sensor(len_terms *t, double *J, const rc_effect *ef, const double *x)
{
    (void)x;
    if (t->g == NULL && J != NULL)
        for (unsigned k = 0; k < ef->count; ++k)
            J[k] = 0.0;
}

static void eff_LENGTH_OFFSET(len_terms *t, double *J, const rc_effect *ef, const double *x)
{
    (void)ef;
    if (t->g != NULL)
        return;
    t->add += x[0];
    if (J != NULL)
        J[0] = 1.0;
}

static void eff_LENGTH_SCALE(len_terms *t, double *J, const rc_effect *ef, const double *x)
{
    (void)ef;
    if (t->g != NULL)
        return;
    t->scale += x[0];
    if (J != NULL)
        J[0] = t->dist;
}

static void eff_OUTLET_OFFSET(len_terms *t, double *J, const rc_effect *ef, const double *x)
{
    if (t->g != NULL)
        return;
    if (t->s->outlet < ef->count)
        t->add += x[t->s->outlet];
    if (J != NULL)
        for (unsigned k = 0; k < ef->count; ++k)
            J[k] = k == t->s->outlet ? 1.0 : 0.0;
}

static void eff_OUTLET_SCALE(len_terms *t, double *J, const rc_effect *ef, const double *x)
{
    if (t->g != NULL)
        return;
    if (t->s->outlet < ef->count)
        t->scale += x[t->s->outlet];
    if (J != NULL)
        for (unsigned k = 0; k < ef->count; ++k)
            J[k] = k == t->s->outlet ? t->dist : 0.0;
}

static void eff_TIME_DRIFT(len_terms *t, double *J, const rc_effect *ef, const double *x)
{
    if (t->g != NULL)
        return;
    double tp = t->s->t;
    for (unsigned k = 0; k < ef->count; ++k) {
        t->add += x[k] * tp;
        if (J != NULL)
            J[k] = tp;
        tp *= t->s->t;
    }
}

static void eff_GROUP_OFFSET(len_terms *t, double *J, const rc_effect *ef, const double *x)
{
    if (t->g != NULL)
        return;
    if (t->s->group < ef->count)
        t->add += x[t->s->group];
    if (J != NULL)
        for (unsigned k = 0; k < ef->count; ++k)
            J[k] = (k == t->s->group) ? 1.0 : 0.0;
}

/* c h^2 L, h and L in m (1e-9 from mm^3) */
static void eff_CABLE_SAG(len_terms *t, double *J, const rc_effect *ef, const double *x)
{
    (void)ef;
    if (t->g != NULL)
        return;
    const double k = x[0] * 1e-9, dist = t->dist, h2 = t->h2;
    t->add += k * h2 * dist;
    t->gd[0] += k * (2.0 * dist * t->u[0] * dist + h2 * t->u[0]);
    t->gd[1] += k * (2.0 * dist * t->u[1] * dist + h2 * t->u[1]);
    t->gd[2] += k * h2 * t->u[2];
    if (J != NULL)
        J[0] = 1e-9 * h2 * dist;
}

static void eff_LENGTH_NONLIN(len_terms *t, double *J, const rc_effect *ef, const double *x)
{
    (void)ef;
    if (t->g != NULL)
        return;
    const double v = t->dist * 1e-3 - RC_LENGTH_NONLIN_CENTRE_M;
    const double dv = (2.0 * x[0] * v + 3.0 * x[1] * v * v) * 1e-3; /* mm per mm of chord */
    t->add += x[0] * v * v + x[1] * v * v * v;
    for (int r = 0; r < 3; ++r)
        t->gd[r] += dv * t->u[r];
    if (J != NULL) {
        J[0] = v * v;
        J[1] = v * v * v;
    }
}

static void eff_LENGTH_PERIODIC(len_terms *t, double *J, const rc_effect *ef, const double *x)
{
    (void)ef;
    if (t->g != NULL)
        return;
    if (J != NULL)
        J[0] = J[1] = J[2] = 0.0;
    if (!(fabs(x[2]) > 1e-9))
        return;
    const double w = 2.0 * M_PI / x[2], ph = w * t->dist, sp = sin(ph), cp = cos(ph);
    const double dv = (x[0] * cp - x[1] * sp) * w; /* mm per mm of chord */
    t->add += x[0] * sp + x[1] * cp;
    for (int r = 0; r < 3; ++r)
        t->gd[r] += dv * t->u[r];
    if (J != NULL) {
        J[0] = sp;
        J[1] = cp;
        J[2] = (x[0] * cp - x[1] * sp) * (-ph / x[2]); /* d ph / dP = -dist 2 pi / P^2 */
    }
}

/* Where the length is measured from: -dl/dp for the sample's own outlet. */
static void eff_OUTLET(len_terms *t, double *J, const rc_effect *ef, const double *x)
{
    (void)x;
    if (t->g == NULL || J == NULL)
        return;
    for (unsigned k = 0; k < 3; ++k)
        J[k] = (int)ef->first == t->outlet_first ? -t->g[k] : 0.0;
}

/* The measured point in the flange frame: dp/dt = R6 for the point the sample measures. */
static void eff_point(len_terms *t, double *J, const rc_effect *ef, const double *x)
{
    unsigned np;
    (void)x;
    if (t->g == NULL || J == NULL)
        return;
    const double *R = t->c->R[RC_NJ], *g = t->g;
    const int pi = points_index(t->m, &np), at = sample_point(t->s, tool_index(t->m), pi, np);
    for (unsigned k = 0; k < ef->count; ++k)
        J[k] = (int)(ef->first + k - k % 3u) == at ? g[0] * R[k % 3u] + g[1] * R[3 + k % 3u] + g[2] * R[6 + k % 3u]
                                                   : 0.0;
}
#define eff_TOOL_OFFSET eff_point
#define eff_CABLE_POINTS eff_point

/* An effect's function by its side: a length-, point- or outlet-side kind has
 * its own (eff_<KIND>); a joint- or geometry-side kind has no part in a
 * length's own terms (the chain's, point_jac); a sensor-side kind's columns
 * of a length are zero (rc_sensor.h). */
#define EFF_BY_SIDE_RC_SIDE_LENGTH(id) eff_##id
#define EFF_BY_SIDE_RC_SIDE_POINT(id) eff_##id
#define EFF_BY_SIDE_RC_SIDE_OUTLET(id) eff_##id
#define EFF_BY_SIDE_RC_SIDE_JOINT(id) eff_none
#define EFF_BY_SIDE_RC_SIDE_GEOMETRY(id) eff_none
#define EFF_BY_SIDE_RC_SIDE_SENSOR(id) eff_sensor
#define RC_EFF_FN_(id, name, count, side, ...) EFF_BY_SIDE_##side(id),
static const eff_fn eff_fns[] = {RC_EFFECTS(RC_EFF_FN_)};
#undef RC_EFF_FN_

/* Every effect's function of t's pass (t->g NULL: values; else the
 * gradient's columns) with jac (n_params) or NULL. */
static void length_effects(len_terms *t, double *jac)
{
    for (unsigned i = 0; i < t->m->n_effects; ++i) {
        const rc_effect *ef = &t->m->effects[i];
        if (ef->kind < sizeof eff_fns / sizeof eff_fns[0])
            eff_fns[ef->kind](t, jac != NULL ? &jac[ef->first] : NULL, ef, &t->m->x[ef->first]);
    }
}

/* Length (and its Jacobian) of sample s from the model's chain c at s and
 * the measured point p; other sensors through sensor_chain. */
static rc_status meas_chain(double *len_mm, double *jac, const rc_model *m, const rc_sample *s, const chain *c,
                            const double p[3])
{
    double u[3], dl_dtheta[RC_NJ];
    if (s->sensor != RC_SENSOR_LENGTH)
        return sensor_chain(len_mm, jac, m, s, c);
    const double *e = &m->x[RC_P_ENC];
    int outlet_first = -1; /* the outlet effect's first parameter, -1: e */
    if (s->outlet != 0) {
        for (unsigned i = 0; i < m->n_effects && outlet_first < 0; ++i)
            if (m->effects[i].kind == RC_EFF_OUTLET && m->effects[i].joint == s->outlet)
                outlet_first = m->effects[i].first;
        if (outlet_first < 0)
            return RC_ERR_ARG; /* a sample from an outlet the model does not have */
        e = &m->x[outlet_first];
    }
    for (int r = 0; r < 3; ++r)
        u[r] = p[r] - e[r];
    const double dist = sqrt(dot3(u, u));
    if (!(dist > 1e-9) || !isfinite(dist))
        return RC_ERR_NUMERIC;
    for (int r = 0; r < 3; ++r)
        u[r] /= dist;

    /* Length-side effects: l = (1 + scale) * dist + additive terms; those
     * that depend on the chord d = p - e (sag, nonlinearity, periodic) add their
     * gradient with respect to d to gd (3), so that dl/dd = scale u + gd. */
    len_terms t;
    t.m = m;
    t.s = s;
    t.c = c;
    for (int r = 0; r < 3; ++r)
        t.u[r] = u[r];
    t.dist = dist;
    t.h2 = u[0] * u[0] * dist * dist + u[1] * u[1] * dist * dist; /* horizontal span^2, mm^2 */
    t.outlet_first = outlet_first;
    t.g = NULL;
    t.scale = 1.0;
    t.add = 0.0;
    t.gd[0] = t.gd[1] = t.gd[2] = 0.0;
    length_effects(&t, jac);
    *len_mm = t.scale * dist + t.add;
    if (jac == NULL)
        return RC_OK;

    double g[3]; /* dl/dp (3): the chord direction, scaled, plus the chord-dependent effects */
    for (int r = 0; r < 3; ++r)
        g[r] = t.scale * u[r] + t.gd[r];
    point_jac(jac, dl_dtheta, m, s, c, p, g);
    for (int r = 0; r < 3; ++r)
        jac[RC_P_ENC + r] = outlet_first < 0 ? -g[r] : 0.0;
    t.g = g;
    length_effects(&t, jac);
    return RC_OK;
}
