/* SPDX-License-Identifier: MIT */
/* rc_sensor.c - the laser tracker's position as a measured quantity (rc_sensor.h). */
#include "rc_sensor.h"

#include <math.h>
#include <string.h>

static void skew(double S[9], const double v[3])
{
    S[0] = 0.0;
    S[1] = -v[2];
    S[2] = v[1];
    S[3] = v[2];
    S[4] = 0.0;
    S[5] = -v[0];
    S[6] = -v[1];
    S[7] = v[0];
    S[8] = 0.0;
}

/* I + a W + b W^2, W = [w]x: the form of both exp and J_l. */
static void so3_series(double R[9], const double w[3], double a, double b)
{
    double W[9];
    skew(W, w);
    for (int r = 0; r < 3; ++r)
        for (int k = 0; k < 3; ++k) {
            double w2 = 0.0;
            for (int i = 0; i < 3; ++i)
                w2 += W[3 * r + i] * W[3 * i + k];
            R[3 * r + k] = (r == k ? 1.0 : 0.0) + a * W[3 * r + k] + b * w2;
        }
}

void rc_rotvec_matrix(double R[9], const double w[3])
{
    const double th2 = w[0] * w[0] + w[1] * w[1] + w[2] * w[2], th = sqrt(th2);
    double a, b;
    if (th < 1e-6) { /* series: sin t / t and (1 - cos t) / t^2 */
        a = 1.0 - th2 / 6.0;
        b = 0.5 - th2 / 24.0;
    } else {
        a = sin(th) / th;
        b = (1.0 - cos(th)) / th2;
    }
    so3_series(R, w, a, b);
}

void rc_rotvec_jl(double J[9], const double w[3])
{
    const double th2 = w[0] * w[0] + w[1] * w[1] + w[2] * w[2], th = sqrt(th2);
    double a, b;
    if (th < 1e-4) { /* (1 - cos t) / t^2 and (t - sin t) / t^3 */
        a = 0.5 - th2 / 24.0;
        b = 1.0 / 6.0 - th2 / 120.0;
    } else {
        a = (1.0 - cos(th)) / th2;
        b = (th - sin(th)) / (th2 * th);
    }
    so3_series(J, w, a, b);
}

void rc_rotvec_from_matrix(double w[3], const double R[9])
{
    const double c = fmax(-1.0, fmin(1.0, 0.5 * (R[0] + R[4] + R[8] - 1.0)));
    const double th = acos(c);
    const double v[3] = {R[7] - R[5], R[2] - R[6], R[3] - R[1]}; /* 2 sin(th) axis */
    if (th < 1e-6) {
        for (int k = 0; k < 3; ++k)
            w[k] = 0.5 * v[k];
        return;
    }
    if (th < 3.14159265358979323846 - 1e-4) {
        const double f = th / (2.0 * sin(th));
        for (int k = 0; k < 3; ++k)
            w[k] = f * v[k];
        return;
    }
    /* near pi: the axis from the diagonal of (R + I) / 2 = a a^T */
    double a[3];
    int big = 0;
    for (int k = 1; k < 3; ++k)
        if (R[4 * k] > R[4 * big])
            big = k;
    a[big] = sqrt(fmax(0.0, 0.5 * (R[4 * big] + 1.0)));
    for (int k = 0; k < 3; ++k)
        if (k != big)
            a[k] = 0.25 * (R[3 * big + k] + R[3 * k + big]) / a[big];
    const double s = v[0] * a[0] + v[1] * a[1] + v[2] * a[2] < 0.0 ? -1.0 : 1.0;
    for (int k = 0; k < 3; ++k)
        w[k] = s * th * a[k];
}

rc_status rc_sensor_tracker(double *value, double pt[3], double g[3], double *jac, const rc_model *m,
                            const rc_sample *s, const double o6[3], const double R6[9])
{
    int tf = -1, rf = -1, kf = -1, sf = -1; /* first parameters of translation, rotation, target, scale */
    RC_ASSERT(value != NULL && pt != NULL && g != NULL && m != NULL && s != NULL && o6 != NULL && R6 != NULL);
    if (s->sensor < RC_SENSOR_TRACKER_X || s->sensor > RC_SENSOR_TRACKER_Z)
        return RC_ERR_ARG;
    const int c = (int)s->sensor - RC_SENSOR_TRACKER_X;
    for (unsigned i = 0; i < m->n_effects; ++i) {
        const rc_effect *e = &m->effects[i];
        if (e->kind == RC_EFF_TRACKER_POSITION && tf < 0)
            tf = e->first;
        else if (e->kind == RC_EFF_TRACKER_ROTATION && rf < 0)
            rf = e->first;
        else if (e->kind == RC_EFF_TRACKER_TARGETS && kf < 0 && 3u * s->target + 3u <= e->count)
            kf = e->first + 3 * s->target;
        else if (e->kind == RC_EFF_TRACKER_SCALE && sf < 0)
            sf = e->first;
    }
    const double k = 1.0 + (sf >= 0 ? m->x[sf] : 0.0); /* the tracker's scale about its origin */
    if (kf < 0)
        return RC_ERR_ARG; /* a target the model does not have */
    const double *t = &m->x[kf];
    for (int r = 0; r < 3; ++r)
        pt[r] = o6[r] + R6[3 * r] * t[0] + R6[3 * r + 1] * t[1] + R6[3 * r + 2] * t[2];
    double R[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    if (rf >= 0)
        rc_rotvec_matrix(R, &m->x[rf]);
    double v = 0.0;
    for (int i = 0; i < 3; ++i) {
        g[i] = R[3 * c + i];
        v += g[i] * pt[i];
    }
    const double unscaled = v + (tf >= 0 ? m->x[tf + c] : 0.0);
    *value = k * unscaled;
    for (int i = 0; i < 3; ++i)
        g[i] *= k;
    if (!isfinite(*value))
        return RC_ERR_NUMERIC;
    if (jac == NULL)
        return RC_OK;
    memset(jac, 0, m->n_params * sizeof jac[0]);
    if (sf >= 0)
        jac[sf] = unscaled;
    if (tf >= 0)
        jac[tf + c] = k;
    if (rf >= 0) { /* -e_c^T [R pt]x J_l */
        double Rp[3], S[9], J[9];
        for (int r = 0; r < 3; ++r)
            Rp[r] = R[3 * r] * pt[0] + R[3 * r + 1] * pt[1] + R[3 * r + 2] * pt[2];
        skew(S, Rp);
        rc_rotvec_jl(J, &m->x[rf]);
        for (int j = 0; j < 3; ++j) {
            double sum = 0.0;
            for (int i = 0; i < 3; ++i)
                sum += S[3 * c + i] * J[3 * i + j];
            jac[rf + j] = -k * sum;
        }
    }
    for (int j = 0; j < 3; ++j) /* g^T R6 (g scaled) */
        jac[kf + j] = g[0] * R6[j] + g[1] * R6[3 + j] + g[2] * R6[6 + j];
    return RC_OK;
}

rc_status rc_sensor_none(double *value, double pt[3], double g[3], double *jac, const rc_model *m,
                         const rc_sample *s, const double o6[3], const double R6[9])
{
    (void)value, (void)pt, (void)g, (void)jac, (void)m, (void)s, (void)o6, (void)R6;
    return RC_ERR_ARG;
}

/* The list RC_SENSORS as tables, indexed by kind. */
#define RC_SENSOR_UNIT_(id, name, unit, hook) unit,
static const char *const sensor_units[] = {RC_SENSORS(RC_SENSOR_UNIT_)};
#undef RC_SENSOR_UNIT_
#define RC_SENSOR_NAME_(id, name, unit, hook) name,
static const char *const sensor_names[] = {RC_SENSORS(RC_SENSOR_NAME_)};
#undef RC_SENSOR_NAME_
#define RC_SENSOR_HOOK_(id, name, unit, hook) hook,
static const rc_sensor_hook_fn sensor_hooks[] = {RC_SENSORS(RC_SENSOR_HOOK_)};
#undef RC_SENSOR_HOOK_

const char *rc_sensor_unit(unsigned sensor) { return sensor < RC_SENSOR_COUNT_ ? sensor_units[sensor] : "?"; }

const char *rc_sensor_name(unsigned sensor) { return sensor < RC_SENSOR_COUNT_ ? sensor_names[sensor] : "unknown"; }

rc_sensor_hook_fn rc_sensor_hook(unsigned sensor)
{
    return sensor < RC_SENSOR_COUNT_ ? sensor_hooks[sensor] : rc_sensor_none;
}
