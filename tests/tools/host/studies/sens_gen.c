/* SPDX-License-Identifier: MIT */
/* sens_gen.c - the independent generator of sens_gen.h (issue 31): truths,
 * poses, tracker and 3-outlet cable files. Sizes (per draw):
 *   DH errors: a, d 0.25 mm x Student-t(3), clipped at 1.5 mm; alpha, theta
 *     0.025 deg x t(3), clipped at 0.15 deg (a heavy tail: the code's prior
 *     is Gaussian);
 *   tracker: 1.5-3 m from the base, any rotation; 3 targets on a plate
 *     50-150 mm along the flange axis, 30-70 mm off it, 120 deg apart (+-15);
 *     noise 0.01-0.03 mm per coordinate; joints read at 0.001 deg;
 *   cable: outlets 120 deg apart (+-20) around the base, 0.5-1.2 m from it,
 *     z -100..400 mm; the cable at the flange centre (half the draws) or
 *     N(0, 3 mm) off it; noise 0.005-0.02 mm, display step 0.01 mm; joints
 *     read at 0.01 deg;
 *   SG_GRAVITY: upper arm 2.5-3.5 kg at 0.3-0.7 of link 2, forearm
 *     1.5-2.5 kg at 0.3-0.7 from the elbow to the wrist centre, tool
 *     0.5-3 kg 60-120 mm along the flange axis (+-10 mm across);
 *     compliance 1-3e-5 rad/(N m) on joints 2 and 3 (about 0.01-0.06 deg);
 *   SG_GEAR: first harmonic 0.006-0.015 deg, second 0.4-0.8 of it, third
 *     0.1-0.25 of it, joint 1, 2 or 3;
 *   SG_TEMP: k 20-60 ppm, either sign;
 *   SG_OUTLET: common offset 0.1-0.3 mm, one outlet 0.1-0.3 mm more (either
 *     sign each), each outlet's scale -60..60 ppm.
 * Depends on: sens_gen.h, rct_indep.h, libc, libm. Memory: none kept.
 * Errors: a file that cannot be written (-1). */
#include "sens_gen.h"

#include <math.h>
#include <string.h>

#define SG_PI 3.14159265358979323846
#define SG_DEG (SG_PI / 180.0)
#define SG_G 9.81 /* m/s^2 */

const char *const sg_effect_name[SG_N_EFFECTS] = {"none", "gravity", "gear", "temperature", "outlet"};

/* data/irb120.json, copied */
static const double nom_dh_deg[6][4] = {{0, 290, -90, 0}, {270, 0, 0, -90}, {70, 0, -90, 0},
                                        {0, 302, 90, 0},  {0, 0, -90, 0},   {0, 72, 0, 0}};
const double sg_qmin_deg[6] = {-165, -110, -110, -160, -120, -400};
const double sg_qmax_deg[6] = {165, 110, 70, 160, 120, 400};

void sg_nominal_dh(double dh[6][4])
{
    for (int i = 0; i < 6; ++i) {
        dh[i][0] = nom_dh_deg[i][0];
        dh[i][1] = nom_dh_deg[i][1];
        dh[i][2] = nom_dh_deg[i][2] * SG_DEG;
        dh[i][3] = nom_dh_deg[i][3] * SG_DEG;
    }
}

static double uni(rct_rng *g, double lo, double hi)
{
    return lo + (hi - lo) * rct_u01(g);
}

static double sgn(rct_rng *g)
{
    return rct_u01(g) < 0.5 ? -1.0 : 1.0;
}

/* Student-t with 3 degrees of freedom, clipped at +-clip. */
static double student3(rct_rng *g, double clip)
{
    const double a = rct_gauss(g), b = rct_gauss(g), c = rct_gauss(g);
    const double x = rct_gauss(g) / sqrt((a * a + b * b + c * c) / 3.0);
    return x > clip ? clip : x < -clip ? -clip : x;
}

/* R (3 x 3, row-major) = exp([w]x), w = angle * unit axis. */
static void rodrigues(double R[9], const double axis[3], double angle)
{
    const double n = sqrt(axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]);
    const double x = axis[0] / n, y = axis[1] / n, z = axis[2] / n, c = cos(angle), s = sin(angle), v = 1.0 - c;
    const double M[9] = {c + x * x * v,     x * y * v - z * s, x * z * v + y * s, y * x * v + z * s, c + y * y * v,
                         y * z * v - x * s, z * x * v - y * s, z * y * v + x * s, c + z * z * v};
    memcpy(R, M, sizeof M);
}

static void draw_tracker(sg_truth *t, rct_rng *g)
{
    double axis[3] = {rct_gauss(g), rct_gauss(g), rct_gauss(g)}, c[3];
    rodrigues(t->trk_R, axis, uni(g, 0.2, SG_PI));
    const double dist = uni(g, 1500.0, 3000.0), az = uni(g, 0.0, 2.0 * SG_PI);
    c[0] = dist * cos(az);
    c[1] = dist * sin(az);
    c[2] = uni(g, -200.0, 500.0);
    for (int r = 0; r < 3; ++r) /* p_t = R (p - c) = R p + T */
        t->trk_T_mm[r] = -(t->trk_R[r * 3] * c[0] + t->trk_R[r * 3 + 1] * c[1] + t->trk_R[r * 3 + 2] * c[2]);
    const double h = uni(g, 50.0, 150.0), a0 = uni(g, 0.0, 2.0 * SG_PI);
    for (int k = 0; k < SG_TARGETS; ++k) {
        const double a = a0 + k * 2.0 * SG_PI / 3.0 + (k ? uni(g, -15.0, 15.0) * SG_DEG : 0.0), r = uni(g, 30.0, 70.0);
        t->trk_target_mm[k][0] = r * cos(a);
        t->trk_target_mm[k][1] = r * sin(a);
        t->trk_target_mm[k][2] = h + uni(g, -5.0, 5.0);
    }
    t->trk_noise_mm = uni(g, 0.01, 0.03);
}

static void draw_cable(sg_truth *t, rct_rng *g)
{
    const double a0 = uni(g, 0.0, 2.0 * SG_PI);
    for (int k = 0; k < SG_OUTLETS; ++k) {
        const double a = a0 + k * 2.0 * SG_PI / 3.0 + uni(g, -20.0, 20.0) * SG_DEG;
        const double z = uni(g, -100.0, 400.0), d = uni(g, 500.0, 1200.0);
        const double rho = sqrt(d * d - z * z);
        t->outlet_mm[k][0] = rho * cos(a);
        t->outlet_mm[k][1] = rho * sin(a);
        t->outlet_mm[k][2] = z;
    }
    const int off = rct_u01(g) < 0.5;
    for (int r = 0; r < 3; ++r)
        t->attach_mm[r] = off ? 3.0 * rct_gauss(g) : 0.0;
    t->cab_noise_mm = uni(g, 0.005, 0.02);
}

static void draw_effect(sg_truth *t, sg_effect e, rct_rng *g)
{
    if (e == SG_GRAVITY) {
        t->mass_kg[0] = uni(g, 2.5, 3.5);
        t->mass_kg[1] = uni(g, 1.5, 2.5);
        t->mass_kg[2] = uni(g, 0.5, 3.0);
        t->arm_frac = uni(g, 0.3, 0.7);
        t->fore_frac = uni(g, 0.3, 0.7);
        t->tool_com_mm[0] = uni(g, -10.0, 10.0);
        t->tool_com_mm[1] = uni(g, -10.0, 10.0);
        t->tool_com_mm[2] = uni(g, 60.0, 120.0);
        t->compl_rad_per_nm[0] = uni(g, 1e-5, 3e-5);
        t->compl_rad_per_nm[1] = uni(g, 1e-5, 3e-5);
    } else if (e == SG_GEAR) {
        t->gear_joint = 1u + (unsigned)(3.0 * rct_u01(g));
        t->gear_amp_rad[0] = uni(g, 0.006, 0.015) * SG_DEG;
        t->gear_amp_rad[1] = uni(g, 0.4, 0.8) * t->gear_amp_rad[0];
        t->gear_amp_rad[2] = uni(g, 0.1, 0.25) * t->gear_amp_rad[0];
        for (int h = 0; h < 3; ++h)
            t->gear_phase_rad[h] = uni(g, 0.0, 2.0 * SG_PI);
    } else if (e == SG_TEMP) {
        t->trk_scale = sgn(g) * uni(g, 20e-6, 60e-6);
    } else if (e == SG_OUTLET) {
        const double common = sgn(g) * uni(g, 0.1, 0.3);
        t->odd_outlet = (unsigned)(SG_OUTLETS * rct_u01(g));
        for (unsigned k = 0; k < SG_OUTLETS; ++k) {
            t->cab_offset_mm[k] = common + (k == t->odd_outlet ? sgn(g) * uni(g, 0.1, 0.3) : 0.0);
            t->cab_scale[k] = uni(g, -60e-6, 60e-6);
        }
    }
}

void sg_draw(sg_truth *t, sg_effect e, uint64_t seed)
{
    rct_rng g = {seed * 0x2545f4914f6cdd1dull + 12345u};
    memset(t, 0, sizeof *t);
    t->effect = e;
    sg_nominal_dh(t->dh);
    for (int i = 0; i < 6; ++i) {
        t->dh[i][0] += 0.25 * student3(&g, 6.0);
        t->dh[i][1] += 0.25 * student3(&g, 6.0);
        t->dh[i][2] += 0.025 * SG_DEG * student3(&g, 6.0);
        t->dh[i][3] += 0.025 * SG_DEG * student3(&g, 6.0);
    }
    draw_tracker(t, &g);
    draw_cable(t, &g);
    draw_effect(t, e, &g);
}

void sg_scale_effect(sg_truth *t, double k)
{
    t->compl_rad_per_nm[0] *= k;
    t->compl_rad_per_nm[1] *= k;
    for (int h = 0; h < 3; ++h)
        t->gear_amp_rad[h] *= k;
    t->trk_scale *= k;
    for (int o = 0; o < SG_OUTLETS; ++o) {
        t->cab_offset_mm[o] *= k;
        t->cab_scale[o] *= k;
    }
}

/* Torque (N m) about the axis through o along z of a weight m at r (mm). */
static double weight_torque(const double o[3], const double z[3], const double r[3], double m_kg)
{
    const double d[3] = {(r[0] - o[0]) * 1e-3, (r[1] - o[1]) * 1e-3, (r[2] - o[2]) * 1e-3};
    const double F[3] = {0.0, 0.0, -m_kg * SG_G};
    const double c[3] = {d[1] * F[2] - d[2] * F[1], d[2] * F[0] - d[0] * F[2], d[0] * F[1] - d[1] * F[0]};
    return z[0] * c[0] + z[1] * c[1] + z[2] * c[2];
}

void sg_gravity_torque(double tau[2], const sg_truth *t, const double q[6])
{
    double dh[6][4], o1[3], R1[9], o2[3], R2[9], o4[3], o6[3], R6[9], arm[3], fore[3], tool[3];
    memcpy(dh, t->dh, sizeof dh);
    rct_frame(o1, R1, dh, q, 1);
    rct_frame(o2, R2, dh, q, 2);
    rct_frame(o4, NULL, dh, q, 4);
    rct_frame(o6, R6, dh, q, 6);
    const double z1[3] = {R1[2], R1[5], R1[8]}, z2[3] = {R2[2], R2[5], R2[8]};
    for (int r = 0; r < 3; ++r) {
        arm[r] = o1[r] + t->arm_frac * (o2[r] - o1[r]);
        fore[r] = o2[r] + t->fore_frac * (o4[r] - o2[r]);
        tool[r] = o6[r] + R6[r * 3] * t->tool_com_mm[0] + R6[r * 3 + 1] * t->tool_com_mm[1] +
                  R6[r * 3 + 2] * t->tool_com_mm[2];
    }
    tau[0] = weight_torque(o1, z1, arm, t->mass_kg[0]) + weight_torque(o1, z1, fore, t->mass_kg[1]) +
             weight_torque(o1, z1, tool, t->mass_kg[2]);
    tau[1] = weight_torque(o2, z2, fore, t->mass_kg[1]) + weight_torque(o2, z2, tool, t->mass_kg[2]);
}

void sg_joints_true(double qe[6], const sg_truth *t, const double q[6])
{
    memcpy(qe, q, 6 * sizeof *qe);
    if (t->effect == SG_GRAVITY) {
        double tau[2];
        sg_gravity_torque(tau, t, q);
        qe[1] += t->compl_rad_per_nm[0] * tau[0];
        qe[2] += t->compl_rad_per_nm[1] * tau[1];
    } else if (t->effect == SG_GEAR) {
        const unsigned j = t->gear_joint - 1u;
        for (int h = 0; h < 3; ++h)
            qe[j] += t->gear_amp_rad[h] * sin((h + 1) * q[j] + t->gear_phase_rad[h]);
    }
}

static void point_of(double p[3], double dh[6][4], const double q[6], const double tool_mm[3])
{
    double R[9];
    rct_pose(p, R, dh, q);
    for (int r = 0; r < 3; ++r)
        p[r] += R[r * 3] * tool_mm[0] + R[r * 3 + 1] * tool_mm[1] + R[r * 3 + 2] * tool_mm[2];
}

void sg_true_point(double p[3], const sg_truth *t, const double q[6], const double tool_mm[3])
{
    double dh[6][4], qe[6];
    memcpy(dh, t->dh, sizeof dh);
    sg_joints_true(qe, t, q);
    point_of(p, dh, qe, tool_mm);
}

void sg_nominal_point(double p[3], const double q[6], const double tool_mm[3])
{
    double dh[6][4];
    sg_nominal_dh(dh);
    point_of(p, dh, q, tool_mm);
}

void sg_random_pose(double q[6], rct_rng *g)
{
    const double zero[3] = {0, 0, 0};
    for (;;) {
        for (int j = 0; j < 6; ++j) {
            const double lo = j == 5 ? -180.0 : 0.9 * sg_qmin_deg[j], hi = j == 5 ? 180.0 : 0.9 * sg_qmax_deg[j];
            q[j] = uni(g, lo, hi) * SG_DEG;
        }
        double p[3];
        sg_nominal_point(p, q, zero);
        if (fabs(sin(q[4])) > 0.15 && p[2] > 50.0)
            return;
    }
}

double sg_cable_length(const sg_truth *t, const double q[6], unsigned k)
{
    double p[3];
    sg_true_point(p, t, q, t->attach_mm);
    return (1.0 + t->cab_scale[k]) * rct_dist(p, t->outlet_mm[k]) + t->cab_offset_mm[k];
}

void sg_tracker_point(double p[3], const sg_truth *t, const double q[6], unsigned k)
{
    double b[3];
    sg_true_point(b, t, q, t->trk_target_mm[k]);
    for (int r = 0; r < 3; ++r)
        p[r] = (1.0 + t->trk_scale) *
               (t->trk_R[r * 3] * b[0] + t->trk_R[r * 3 + 1] * b[1] + t->trk_R[r * 3 + 2] * b[2] + t->trk_T_mm[r]);
}

static double quant(double x, double step)
{
    return step * floor(x / step + 0.5);
}

int sg_write_positions(const char *path, const sg_truth *t, rct_rng *g)
{
    FILE *f = fopen(path, "w");
    if (!f)
        return -1;
    fprintf(f, "q1,q2,q3,q4,q5,q6,x,y,z,target,pose\n");
    for (unsigned i = 0; i < SG_TRK_POSES; ++i) {
        double q[6];
        sg_random_pose(q, g);
        for (unsigned k = 0; k < SG_TARGETS; ++k) {
            double p[3];
            sg_tracker_point(p, t, q, k);
            for (int j = 0; j < 6; ++j)
                fprintf(f, "%.3f,", quant(q[j] / SG_DEG, 0.001));
            for (int r = 0; r < 3; ++r)
                fprintf(f, "%.4f,", p[r] + t->trk_noise_mm * rct_gauss(g));
            fprintf(f, "%u,%u\n", k, i);
        }
    }
    return fclose(f) == 0 ? 0 : -1;
}

int sg_write_cable(const char *path, const sg_truth *t, rct_rng *g)
{
    double q[SG_CAB_POSES][6];
    FILE *f = fopen(path, "w");
    if (!f)
        return -1;
    for (unsigned i = 0; i < SG_CAB_POSES; ++i) {
        int ok = 0;
        while (!ok) { /* every outlet's cable between 150 and 1700 mm */
            sg_random_pose(q[i], g);
            ok = 1;
            for (unsigned k = 0; k < SG_OUTLETS; ++k) {
                const double l = sg_cable_length(t, q[i], k);
                ok = ok && l > 150.0 && l < 1700.0;
            }
        }
    }
    fprintf(f, "q1,q2,q3,q4,q5,q6,L,outlet\n");
    for (unsigned k = 0; k < SG_OUTLETS; ++k)
        for (unsigned i = 0; i < SG_CAB_POSES; ++i) {
            const double l = sg_cable_length(t, q[i], k) + t->cab_noise_mm * rct_gauss(g);
            for (int j = 0; j < 6; ++j)
                fprintf(f, "%.2f,", quant(q[i][j] / SG_DEG, 0.01));
            fprintf(f, "%.2f,%u\n", quant(l, 0.01), k);
        }
    return fclose(f) == 0 ? 0 : -1;
}

int sg_write_targets(const char *path, double (*q)[6], unsigned n, rct_rng *g)
{
    FILE *f = fopen(path, "w");
    if (!f)
        return -1;
    fprintf(f, "q1,q2,q3,q4,q5,q6\n");
    for (unsigned i = 0; i < n; ++i) {
        double qi[6];
        sg_random_pose(qi, g);
        for (int j = 0; j < 6; ++j) { /* as written: the targets the program compares with */
            qi[j] = quant(qi[j] / SG_DEG, 1e-6) * SG_DEG;
            fprintf(f, "%.6f%s", qi[j] / SG_DEG, j < 5 ? "," : "\n");
        }
        if (q)
            memcpy(q[i], qi, sizeof qi);
    }
    return fclose(f) == 0 ? 0 : -1;
}

/* Eigenvector of the largest eigenvalue of the symmetric 4 x 4 A (Jacobi
 * rotations). v (4). */
static void eig4_max(double v[4], double A[4][4])
{
    double V[4][4] = {{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}, {0, 0, 0, 1}};
    for (int sweep = 0; sweep < 60; ++sweep) {
        double off = 0.0;
        for (int p = 0; p < 4; ++p)
            for (int r = p + 1; r < 4; ++r)
                off += A[p][r] * A[p][r];
        if (off < 1e-30)
            break;
        for (int p = 0; p < 4; ++p)
            for (int r = p + 1; r < 4; ++r) {
                if (fabs(A[p][r]) < 1e-300)
                    continue;
                const double th = 0.5 * (A[r][r] - A[p][p]) / A[p][r];
                const double tt = (th >= 0 ? 1.0 : -1.0) / (fabs(th) + sqrt(th * th + 1.0));
                const double c = 1.0 / sqrt(tt * tt + 1.0), s = tt * c;
                for (int k = 0; k < 4; ++k) { /* A <- A J */
                    const double akp = A[k][p], akr = A[k][r];
                    A[k][p] = c * akp - s * akr;
                    A[k][r] = s * akp + c * akr;
                }
                for (int k = 0; k < 4; ++k) { /* A <- J^T A */
                    const double apk = A[p][k], ark = A[r][k];
                    A[p][k] = c * apk - s * ark;
                    A[r][k] = s * apk + c * ark;
                }
                for (int k = 0; k < 4; ++k) {
                    const double vkp = V[k][p], vkr = V[k][r];
                    V[k][p] = c * vkp - s * vkr;
                    V[k][r] = s * vkp + c * vkr;
                }
            }
    }
    int best = 0;
    for (int k = 1; k < 4; ++k)
        if (A[k][k] > A[best][best])
            best = k;
    for (int k = 0; k < 4; ++k)
        v[k] = V[k][best];
}

void sg_kabsch(double R[9], double T[3], const double (*a)[3], const double (*b)[3], unsigned n,
               const unsigned char *use)
{
    double ca[3] = {0, 0, 0}, cb[3] = {0, 0, 0}, S[3][3] = {{0}}, m = 0.0;
    for (unsigned i = 0; i < n; ++i)
        if (!use || use[i]) {
            for (int r = 0; r < 3; ++r) {
                ca[r] += a[i][r];
                cb[r] += b[i][r];
            }
            m += 1.0;
        }
    for (int r = 0; r < 3; ++r) {
        ca[r] /= m > 0 ? m : 1.0;
        cb[r] /= m > 0 ? m : 1.0;
    }
    for (unsigned i = 0; i < n; ++i)
        if (!use || use[i])
            for (int r = 0; r < 3; ++r)
                for (int c = 0; c < 3; ++c)
                    S[r][c] += (a[i][r] - ca[r]) * (b[i][c] - cb[c]);
    double N[4][4] = {
        {S[0][0] + S[1][1] + S[2][2], S[1][2] - S[2][1], S[2][0] - S[0][2], S[0][1] - S[1][0]},
        {S[1][2] - S[2][1], S[0][0] - S[1][1] - S[2][2], S[0][1] + S[1][0], S[2][0] + S[0][2]},
        {S[2][0] - S[0][2], S[0][1] + S[1][0], -S[0][0] + S[1][1] - S[2][2], S[1][2] + S[2][1]},
        {S[0][1] - S[1][0], S[2][0] + S[0][2], S[1][2] + S[2][1], -S[0][0] - S[1][1] + S[2][2]}};
    double v[4];
    eig4_max(v, N);
    const double w = v[0], x = v[1], y = v[2], z = v[3];
    const double M[9] = {1 - 2 * (y * y + z * z), 2 * (x * y - w * z),     2 * (x * z + w * y),
                         2 * (x * y + w * z),     1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
                         2 * (x * z - w * y),     2 * (y * z + w * x),     1 - 2 * (x * x + y * y)};
    memcpy(R, M, sizeof M);
    for (int r = 0; r < 3; ++r)
        T[r] = cb[r] - (R[r * 3] * ca[0] + R[r * 3 + 1] * ca[1] + R[r * 3 + 2] * ca[2]);
}
