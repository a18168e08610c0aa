/* SPDX-License-Identifier: MIT */
/* sens_gen_check.c - the generator of sens_gen.h checked against facts it
 * does not compute itself (ctest sens_gen_check, label diagnose):
 *   - the tracker frame recovered by Kabsch from noise-free readings of a
 *     truth with the nominal DH equals the drawn one (and Kabsch recovers a
 *     known rotation of random points);
 *   - a temperature scale multiplies every distance between tracker points
 *     by 1 + k;
 *   - the 3 outlets' noise-free lengths equal the distances from the
 *     nominal flange (rct_flange) to the outlets; the written file's lengths
 *     are within 6 sigma + half a display step of them;
 *   - the gravity torque equals m g times the horizontal lever, summed, on
 *     an arm with every mass on the flange (one lever to check);
 *   - the gear error is the drawn three harmonics;
 *   - the written files parse: `rcal calibrate --positions F` and
 *     `rcal calibrate --data C` exit 0.
 * usage: sens_gen_check RCAL_BIN WORKDIR. Exit 0 when all hold. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sens_gen.h"

#define DEG (3.14159265358979323846 / 180.0)

static int fails;

static void check(int ok, const char *what, double v)
{
    printf("%s %s (%.3g)\n", ok ? "ok  " : "FAIL", what, v);
    fails += !ok;
}

static void kabsch_known(void)
{
    double a[20][3], b[20][3], R0[9], T0[3] = {1000.0, -2000.0, 300.0}, R[9], T[3];
    sg_truth t;
    sg_draw(&t, SG_NONE, 99u);
    memcpy(R0, t.trk_R, sizeof R0);
    rct_rng g = {5u};
    for (int i = 0; i < 20; ++i)
        for (int r = 0; r < 3; ++r)
            a[i][r] = 500.0 * rct_gauss(&g);
    for (int i = 0; i < 20; ++i)
        for (int r = 0; r < 3; ++r)
            b[i][r] = R0[r * 3] * a[i][0] + R0[r * 3 + 1] * a[i][1] + R0[r * 3 + 2] * a[i][2] + T0[r];
    sg_kabsch(R, T, (const double(*)[3])a, (const double(*)[3])b, 20, NULL);
    double e = 0.0;
    for (int k = 0; k < 9; ++k)
        e = fmax(e, fabs(R[k] - R0[k]));
    for (int r = 0; r < 3; ++r)
        e = fmax(e, fabs(T[r] - T0[r]) * 1e-3);
    check(e < 1e-9, "Kabsch recovers a known rigid motion of 20 random points", e);
}

static void tracker_frame(void)
{
    double a[SG_TRK_POSES][3], b[SG_TRK_POSES][3], R[9], T[3];
    for (uint64_t seed = 1; seed <= 5; ++seed) {
        sg_truth t;
        sg_draw(&t, SG_NONE, seed);
        sg_nominal_dh(t.dh); /* nominal robot: the base points known exactly */
        rct_rng g = {seed};
        for (int i = 0; i < SG_TRK_POSES; ++i) {
            double q[6];
            sg_random_pose(q, &g);
            sg_nominal_point(a[i], q, t.trk_target_mm[0]);
            sg_tracker_point(b[i], &t, q, 0);
        }
        sg_kabsch(R, T, (const double(*)[3])a, (const double(*)[3])b, SG_TRK_POSES, NULL);
        double er = 0.0, et = 0.0, dist = 0.0;
        for (int k = 0; k < 9; ++k)
            er = fmax(er, fabs(R[k] - t.trk_R[k]));
        for (int r = 0; r < 3; ++r) {
            et = fmax(et, fabs(T[r] - t.trk_T_mm[r]));
            dist += T[r] * T[r];
        }
        check(er < 1e-9 && et < 1e-6, "tracker frame recovered by Kabsch from noise-free nominal data", fmax(er, et));
        check(sqrt(dist) > 1400.0 && sqrt(dist) < 3100.0, "tracker 1.5-3 m from the base", sqrt(dist));
        double dmin = 1e9, dmax = 0.0;
        for (int k = 0; k < SG_TARGETS; ++k) {
            const double z[3] = {0, 0, 0}, d = rct_dist(t.trk_target_mm[k], z);
            dmin = fmin(dmin, d);
            dmax = fmax(dmax, d);
        }
        check(dmin >= 50.0 && dmax <= 175.0, "targets 50-175 mm from the flange", dmax);
    }
}

static void tracker_scale(void)
{
    sg_truth t, u;
    sg_draw(&t, SG_TEMP, 3u);
    u = t;
    u.trk_scale = 0.0;
    rct_rng g = {7u};
    double q1[6], q2[6], p1[3], p2[3], r1[3], r2[3];
    sg_random_pose(q1, &g);
    sg_random_pose(q2, &g);
    sg_tracker_point(p1, &t, q1, 1);
    sg_tracker_point(p2, &t, q2, 2);
    sg_tracker_point(r1, &u, q1, 1);
    sg_tracker_point(r2, &u, q2, 2);
    const double ratio = rct_dist(p1, p2) / rct_dist(r1, r2) - 1.0;
    check(fabs(ratio - t.trk_scale) < 1e-12 && fabs(t.trk_scale) >= 20e-6 && fabs(t.trk_scale) <= 60e-6,
          "tracker distances scaled by 1 + k, k 20-60 ppm", ratio);
}

/* Reads the cable file: rows' L and outlet, q in degrees. Returns rows. */
static int read_cable(const char *path, double (*q)[6], double *L, unsigned *o, int max)
{
    FILE *f = fopen(path, "r");
    char line[512];
    int n = 0;
    if (!f)
        return -1;
    if (!fgets(line, sizeof line, f)) {
        fclose(f);
        return -1;
    }
    while (n < max && fgets(line, sizeof line, f)) {
        double *v = q[n];
        if (sscanf(line, "%lf,%lf,%lf,%lf,%lf,%lf,%lf,%u", &v[0], &v[1], &v[2], &v[3], &v[4], &v[5], &L[n], &o[n]) == 8)
            ++n;
    }
    fclose(f);
    return n;
}

static void cable(const char *dir)
{
    static double q[SG_OUTLETS * SG_CAB_POSES][6], L[SG_OUTLETS * SG_CAB_POSES];
    static unsigned o[SG_OUTLETS * SG_CAB_POSES];
    char path[1024];
    sg_truth t;
    sg_draw(&t, SG_NONE, 4u);
    sg_nominal_dh(t.dh);
    snprintf(path, sizeof path, "%s/check_cable.csv", dir);
    rct_rng g = {11u};
    if (sg_write_cable(path, &t, &g) != 0) {
        check(0, "cable file written", 0);
        return;
    }
    const int n = read_cable(path, q, L, o, SG_OUTLETS * SG_CAB_POSES);
    check(n == SG_OUTLETS * SG_CAB_POSES, "cable file: 100 poses x 3 outlets", n);
    unsigned per[SG_OUTLETS] = {0, 0, 0};
    double worst = 0.0, dnoisefree = 0.0, dmin = 1e9, dmax = 0.0;
    const double zero[3] = {0, 0, 0};
    for (int k = 0; k < SG_OUTLETS; ++k) {
        dmin = fmin(dmin, rct_dist(t.outlet_mm[k], zero));
        dmax = fmax(dmax, rct_dist(t.outlet_mm[k], zero));
    }
    for (int i = 0; i < n; ++i) {
        double qr[6], p[3], R[9], dh[6][4];
        for (int j = 0; j < 6; ++j)
            qr[j] = q[i][j] * DEG;
        sg_nominal_dh(dh);
        rct_pose(p, R, dh, qr);
        for (int r = 0; r < 3; ++r)
            p[r] += R[r * 3] * t.attach_mm[0] + R[r * 3 + 1] * t.attach_mm[1] + R[r * 3 + 2] * t.attach_mm[2];
        if (o[i] < SG_OUTLETS) {
            per[o[i]]++;
            /* the file's joints are rounded to 0.01 deg: up to ~0.3 mm at the flange; compare the exact
             * length at the rounded reading with the generator's at the same reading */
            dnoisefree = fmax(dnoisefree, fabs(sg_cable_length(&t, qr, o[i]) - rct_dist(p, t.outlet_mm[o[i]])));
        }
        worst = fmax(worst, fabs(L[i] - rct_dist(p, t.outlet_mm[o[i] % SG_OUTLETS])));
    }
    check(per[0] == SG_CAB_POSES && per[1] == SG_CAB_POSES && per[2] == SG_CAB_POSES, "100 rows per outlet",
          per[0]);
    check(dmin >= 499.0 && dmax <= 1201.0, "outlets 0.5-1.2 m from the base", dmax);
    check(dnoisefree < 1e-9, "3 outlets' lengths equal the distances (noise-free, nominal robot)", dnoisefree);
    /* the file's L against the distance at the rounded joints: noise, display step and the joint rounding
     * (0.005 deg on 6 joints at up to ~0.9 m: < 0.5 mm) */
    check(worst < 0.5, "file lengths within noise + rounding of the distances", worst);
}

static void gravity(void)
{
    sg_truth t;
    sg_draw(&t, SG_GRAVITY, 8u);
    sg_nominal_dh(t.dh);
    t.mass_kg[0] = t.mass_kg[1] = 0.0; /* all the weight at the tool */
    memset(t.tool_com_mm, 0, sizeof t.tool_com_mm);
    t.mass_kg[2] = 2.0;
    const double q[6] = {0.3, 0.2, -0.4, 0.1, 0.7, 0.0};
    double tau[2], o1[3], o2[3], p[3], dh[6][4];
    sg_gravity_torque(tau, &t, q);
    sg_nominal_dh(dh);
    rct_frame(o1, NULL, dh, q, 1);
    rct_frame(o2, NULL, dh, q, 2);
    rct_flange(p, dh, q);
    /* the arm's plane holds the heading (cos q1, sin q1): the horizontal lever along it */
    const double hx = cos(q[0]), hy = sin(q[0]);
    const double l2 = ((p[0] - o1[0]) * hx + (p[1] - o1[1]) * hy) * 1e-3;
    const double l3 = ((p[0] - o2[0]) * hx + (p[1] - o2[1]) * hy) * 1e-3;
    /* a weight's torque about a horizontal axis across the heading is m g times its lever along the heading;
     * the lever across (the wrist's swing out of the arm's plane) does not count */
    const double e = fmax(fabs(tau[0] - 2.0 * 9.81 * l2), fabs(tau[1] - 2.0 * 9.81 * l3));
    check(e < 1e-9, "gravity torque = m g x horizontal lever (joints 2 and 3)", e);
    sg_truth u;
    sg_draw(&u, SG_GRAVITY, 8u);
    double qe[6], t2[2];
    sg_joints_true(qe, &u, q);
    sg_gravity_torque(t2, &u, q);
    const double defl = fmax(fabs(qe[1] - q[1]), fabs(qe[2] - q[2])) / DEG;
    check(fabs(qe[1] - q[1] - u.compl_rad_per_nm[0] * t2[0]) < 1e-15 && defl > 0.001 && defl < 0.2,
          "deflection = torque x compliance, 0.001-0.2 deg", defl);
}

static void gear(void)
{
    sg_truth t;
    sg_draw(&t, SG_GEAR, 2u);
    const double q[6] = {0.5, -0.3, 0.4, 1.0, -0.8, 2.0};
    double qe[6];
    sg_joints_true(qe, &t, q);
    const unsigned j = t.gear_joint - 1u;
    double want = 0.0;
    for (int h = 1; h <= 3; ++h)
        want += t.gear_amp_rad[h - 1] * sin(h * q[j] + t.gear_phase_rad[h - 1]);
    double other = 0.0;
    for (unsigned k = 0; k < 6; ++k)
        other += k == j ? 0.0 : fabs(qe[k] - q[k]);
    check(fabs(qe[j] - q[j] - want) < 1e-15 && other == 0.0 && t.gear_amp_rad[2] < t.gear_amp_rad[1] &&
              t.gear_amp_rad[1] < t.gear_amp_rad[0],
          "gear error: three harmonics of one joint, decreasing", qe[j] - q[j]);
}

static int run(const char *rcal, const char *args)
{
    char cmd[4096];
    snprintf(cmd, sizeof cmd, "'%s' %s >/dev/null 2>&1", rcal, args);
    return system(cmd);
}

/* Issue 33: the outlets are the file's labels everywhere. The 3-outlet file
 * relabelled 0, 1, 2 -> 7, 3, 5 (first appearance no longer the numeric
 * order): the model calibrated on it, evaluated on the same file, meets the
 * same outlets (held-out-like RMSE at the noise, not hundreds of mm); a
 * label the model has no outlet for is refused. */
static void labels(const char *rcal, const char *dir, const char *cpath)
{
    char lpath[1024], bpath[1024], mpath[1024], opath[1024], args[4000], line[512];
    static const int map[3] = {7, 3, 5};
    snprintf(lpath, sizeof lpath, "%s/check_cab_labels.csv", dir);
    snprintf(bpath, sizeof bpath, "%s/check_cab_badlabel.csv", dir);
    snprintf(mpath, sizeof mpath, "%s/check_cab_labels.json", dir);
    snprintf(opath, sizeof opath, "%s/check_cab_labels.out", dir);
    FILE *in = fopen(cpath, "r"), *out = fopen(lpath, "w"), *bad = fopen(bpath, "w");
    int hdr = 1, outlet_col = -1, row = 0;
    while (in && out && bad && fgets(line, sizeof line, in)) {
        char *f[16];
        int nf = 0;
        line[strcspn(line, "\r\n")] = '\0';
        for (char *p = strtok(line, ","); p && nf < 16; p = strtok(NULL, ","))
            f[nf++] = p;
        for (int k = 0; hdr && k < nf; ++k)
            if (strcmp(f[k], "outlet") == 0)
                outlet_col = k;
        for (int k = 0; k < nf; ++k) {
            char v[64];
            snprintf(v, sizeof v, "%s", f[k]);
            if (!hdr && k == outlet_col) {
                const int o = atoi(f[k]);
                snprintf(v, sizeof v, "%d", o >= 0 && o < 3 ? map[o] : o);
            }
            fprintf(out, "%s%s", k ? "," : "", v);
            fprintf(bad, "%s%s", k ? "," : "", !hdr && k == outlet_col && row == 5 ? "9" : v);
        }
        fputc('\n', out);
        fputc('\n', bad);
        row += !hdr;
        hdr = 0;
    }
    if (in)
        fclose(in);
    if (out)
        fclose(out);
    if (bad)
        fclose(bad);
    check(outlet_col >= 0, "the cable file has an outlet column", outlet_col);
    snprintf(args, sizeof args, "calibrate --data '%s' --out '%s'", lpath, mpath);
    check(run(rcal, args) == 0, "calibrate on outlets labelled 7, 3, 5 writes its model", 0);
    snprintf(args, sizeof args, "evaluate --model '%s' --data '%s' --json > '%s'", mpath, lpath, opath);
    char cmd[4200];
    snprintf(cmd, sizeof cmd, "'%s' %s 2>/dev/null", rcal, args);
    const int rc = system(cmd);
    double rmse = -1.0;
    FILE *j = fopen(opath, "r");
    char buf[8192] = "";
    if (j) {
        const size_t k = fread(buf, 1, sizeof buf - 1, j);
        buf[k] = '\0';
        fclose(j);
    }
    const char *p = strstr(buf, "\"rmse_mm\":");
    if (p)
        rmse = atof(p + strlen("\"rmse_mm\":"));
    check(rc == 0 && rmse >= 0.0 && rmse < 0.1, "evaluate meets the outlets by their labels (RMSE mm)", rmse);
    snprintf(args, sizeof args, "evaluate --model '%s' --data '%s'", mpath, bpath);
    check(run(rcal, args) != 0, "a label the model has no outlet for (9) is refused", 0);
}

/* The tracker's scale named on a tracker file alone (a temperature drift
 * it cannot see: it trades with the robot's size): calibrate writes a
 * model with the scale at its prior (the start fit once took up the robot's
 * size error in it, 405 ppm, a model rcal compensate refused), and that
 * model compensates. */
static void scale_model(const char *rcal, const char *dir)
{
    char path[1024], mpath[1024], tpath[1024], opath[1024], args[4000];
    sg_truth t;
    sg_draw(&t, SG_TEMP, 1u);
    rct_rng g = {7919ull * 1u + 17u};
    static double q[50][6];
    snprintf(path, sizeof path, "%s/check_pos_temp.csv", dir);
    snprintf(mpath, sizeof mpath, "%s/check_pos_temp.json", dir);
    snprintf(tpath, sizeof tpath, "%s/check_pos_targets.csv", dir);
    snprintf(opath, sizeof opath, "%s/check_pos_comp.csv", dir);
    if (sg_write_positions(path, &t, &g) != 0 || sg_write_targets(tpath, q, 50, &g) != 0) {
        check(0, "files written", 0);
        return;
    }
    remove(mpath);
    remove(opath);
    snprintf(args, sizeof args, "calibrate --positions '%s' --test-fraction 0.03 --effects tracker_scale --out '%s'",
             path, mpath);
    check(run(rcal, args) == 0, "calibrate --positions F --effects tracker_scale writes its model", 0);
    FILE *j = fopen(mpath, "r");
    static char buf[200000];
    size_t k = j ? fread(buf, 1, sizeof buf - 1, j) : 0;
    buf[k] = '\0';
    if (j)
        fclose(j);
    double sc = 1.0;
    const char *at = strstr(buf, "\"tracker_scale\"");
    if (at && (at = strstr(at, "\"params\"")) && (at = strchr(at, '[')))
        sc = atof(at + 1);
    check(fabs(sc) <= 1e-4, "a scale a tracker alone cannot see stays within its prior sd of 0", sc);
    snprintf(args, sizeof args, "compensate --model '%s' --in '%s' --out '%s'", mpath, tpath, opath);
    check(run(rcal, args) == 0, "rcal compensate takes the model calibrate wrote", 0);
}

static void parse(const char *rcal, const char *dir)
{
    char path[1024], cpath[1024], args[3000];
    sg_truth t;
    sg_draw(&t, SG_GRAVITY, 6u);
    rct_rng g = {13u};
    snprintf(path, sizeof path, "%s/check_pos.csv", dir);
    snprintf(cpath, sizeof cpath, "%s/check_cab.csv", dir);
    if (sg_write_positions(path, &t, &g) != 0 || sg_write_cable(cpath, &t, &g) != 0) {
        check(0, "files written", 0);
        return;
    }
    snprintf(args, sizeof args, "calibrate --positions '%s'", path);
    int rc = run(rcal, args);
    check(rc == 0, "rcal calibrate --positions F exits 0", rc);
    snprintf(args, sizeof args, "calibrate --data '%s'", cpath);
    rc = run(rcal, args);
    check(rc == 0, "rcal calibrate --data C (3 outlets) exits 0", rc);
    labels(rcal, dir, cpath);
    scale_model(rcal, dir);
}

int main(int argc, char **argv)
{
    if (argc < 3) {
        fprintf(stderr, "usage: sens_gen_check RCAL_BIN WORKDIR\n");
        return 2;
    }
    kabsch_known();
    tracker_frame();
    tracker_scale();
    cable(argv[2]);
    gravity();
    gear();
    parse(argv[1], argv[2]);
    printf("%s (%d failed)\n", fails ? "FAIL" : "ok", fails);
    return fails != 0;
}
