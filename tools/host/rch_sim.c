#include "rch_sim.h"

#include <math.h>
#include <string.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif
#define DEG (M_PI / 180.0)

void rch_sim_defaults(rch_sim_config *c)
{
    if (c->err_len_mm == 0.0) c->err_len_mm = 0.3;
    if (c->err_ang_deg == 0.0) c->err_ang_deg = 0.05;
    if (c->noise_mm == 0.0) c->noise_mm = 0.01;
    if (c->resolution_mm == 0.0) c->resolution_mm = 0.004;
    if (c->q_step_deg == 0.0) c->q_step_deg = 0.1;
    if (c->len_min_mm == 0.0) c->len_min_mm = 250.0;
    if (c->len_max_mm == 0.0) c->len_max_mm = 800.0;
    if (c->group_span_deg == 0.0) c->group_span_deg = 25.0;
}

void rch_sim_truth(rc_model *truth, const rc_model *nominal, const double enc_mm[3],
                   const rch_sim_config *c, rc_rng *g)
{
    *truth = *nominal;
    for (unsigned i = 0; i < RC_NJ; ++i) {
        truth->x[RC_P_A(i)] += c->err_len_mm * rc_rng_normal(g);
        truth->x[RC_P_D(i)] += c->err_len_mm * rc_rng_normal(g);
        truth->x[RC_P_ALPHA(i)] += c->err_ang_deg * DEG * rc_rng_normal(g);
        truth->x[RC_P_THETA(i)] += c->err_ang_deg * DEG * rc_rng_normal(g);
    }
    for (unsigned k = 0; k < 3; ++k)
        truth->x[RC_P_ENC + k] = enc_mm[k];
}

static double quant(double v, double step) { return step > 0.0 ? step * floor(v / step + 0.5) : v; }

static void range_of(double *lo, double *hi, const rc_model *m, const rch_sim_config *c, unsigned j)
{
    if (c->q_lo_deg[j] == 0.0 && c->q_hi_deg[j] == 0.0) {
        *lo = m->q_min_rad[j];
        *hi = m->q_max_rad[j];
    } else {
        *lo = c->q_lo_deg[j] * DEG;
        *hi = c->q_hi_deg[j] * DEG;
    }
}

int rch_sim_samples(rc_sample *out, double (*true_q_rad)[RC_NJ], size_t n, const rc_model *truth,
                    const rch_sim_config *c, rc_rng *g)
{
    double centre[RC_NJ] = {0};
    unsigned group = 0;
    for (size_t i = 0; i < n; ++i) {
        const int new_group = c->group_size > 0 && i % c->group_size == 0;
        if (new_group && i > 0)
            ++group;
        rc_sample s;
        double q[RC_NJ];
        int found = 0;
        for (unsigned tries = 0; tries < 100000 && !found; ++tries) {
            if (c->group_size == 0 || new_group) {
                for (unsigned j = 0; j < RC_NJ; ++j) {
                    double lo, hi;
                    range_of(&lo, &hi, truth, c, j);
                    centre[j] = q[j] = lo + (hi - lo) * rc_rng_u01(g);
                }
            } else {
                for (unsigned j = 0; j < RC_NJ; ++j) {
                    double lo, hi;
                    range_of(&lo, &hi, truth, c, j);
                    q[j] = centre[j];
                    if (j < 3) {
                        q[j] += c->group_span_deg * DEG * (2.0 * rc_rng_u01(g) - 1.0);
                        if (q[j] < lo) q[j] = lo;
                        if (q[j] > hi) q[j] = hi;
                    }
                }
            }
            memset(&s, 0, sizeof s);
            memcpy(s.q_rad, q, sizeof q);
            s.t = n > 1 ? (double)i / (double)(n - 1) : 0.0;
            s.group = (uint16_t)(group > 65535 ? 65535 : group);
            double l;
            if (rc_meas(&l, NULL, truth, &s) != RC_OK)
                continue;
            double p[3];
            rc_fk(p, NULL, truth, q);
            if (l >= c->len_min_mm && l <= c->len_max_mm && p[2] > 50.0) {
                found = 1;
                double noise = c->noise_mm > 0.0 ? c->noise_mm * rc_rng_normal(g) : 0.0;
                s.len_mm = quant(l + noise, c->resolution_mm);
            }
        }
        if (!found)
            return -1;
        if (true_q_rad)
            memcpy(true_q_rad[i], q, sizeof q);
        for (unsigned j = 0; j < RC_NJ; ++j)
            s.q_rad[j] = quant(q[j] / DEG, c->q_step_deg) * DEG;
        out[i] = s;
    }
    return 0;
}

void rch_sim_flange_diff(double *rms_mm, double *max_mm, const rc_model *a, const rc_model *b,
                         const rc_sample *poses, size_t n, int align)
{
    double sxy = 0.0, sxx = 0.0, dz = 0.0, phi = 0.0, sum2 = 0.0, mx = 0.0;
    if (align) {
        for (size_t i = 0; i < n; ++i) {
            double pa[3], pb[3];
            rc_fk(pa, NULL, a, poses[i].q_rad);
            rc_fk(pb, NULL, b, poses[i].q_rad);
            sxy += pa[0] * pb[1] - pa[1] * pb[0];
            sxx += pa[0] * pb[0] + pa[1] * pb[1];
            dz += (pb[2] - pa[2]) / (double)n;
        }
        phi = atan2(sxy, sxx);
    }
    const double c = cos(phi), s = sin(phi);
    for (size_t i = 0; i < n; ++i) {
        double pa[3], pb[3];
        rc_fk(pa, NULL, a, poses[i].q_rad);
        rc_fk(pb, NULL, b, poses[i].q_rad);
        const double x = c * pa[0] - s * pa[1], y = s * pa[0] + c * pa[1], z = pa[2] + dz;
        const double d = sqrt((x - pb[0]) * (x - pb[0]) + (y - pb[1]) * (y - pb[1]) + (z - pb[2]) * (z - pb[2]));
        sum2 += d * d;
        if (d > mx)
            mx = d;
    }
    *rms_mm = n ? sqrt(sum2 / (double)n) : 0.0;
    *max_mm = mx;
}
