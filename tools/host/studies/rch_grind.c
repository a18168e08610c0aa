/* SPDX-License-Identifier: MIT */
/* rch_grind.c - the grinding-path experiment; see rch_grind.h. */
#include "rch_grind.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "rc_comp.h"
#include "rc_rand.h"
#include "rch_jw.h"
#include "rch_opt.h"
#include "rch_plot.h"
#include "rch_svg.h"
#include "rch_robot.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif
#define DEG (M_PI / 180.0)

/* ---- surfaces ---------------------------------------------------------- */

static const char *const surf_names[] = {"plane", "tilted", "cylinder", "saddle", "sine"};

const char *rch_surface_name(rch_surface_kind kind)
{
    return (unsigned)kind < sizeof surf_names / sizeof surf_names[0] ? surf_names[kind] : "?";
}

void rch_surface_defaults(rch_surface *s)
{
    memset(s, 0, sizeof *s);
    s->kind = RCH_SURF_TILTED;
    s->cx = 400;
    s->cy = 0;
    s->z0 = 300;
    s->w = 200;
    s->h = 120;
    s->step = 10;
    s->ds = 5;
    s->ax_deg = 15;
    s->r = 150;
    s->k = 20;
    s->amp = 10;
    s->wl = 100;
}

double rch_surface_z(const rch_surface *s, double x, double y)
{
    const double dx = x - s->cx, dy = y - s->cy;
    switch (s->kind) {
    case RCH_SURF_TILTED: return s->z0 + tan(s->ax_deg * DEG) * dx + tan(s->ay_deg * DEG) * dy;
    case RCH_SURF_CYLINDER: return s->z0 + sqrt(fmax(0.0, s->r * s->r - dy * dy)) - s->r;
    case RCH_SURF_SADDLE: return s->z0 + s->k * dx * dy / (0.25 * s->w * s->h);
    case RCH_SURF_SINE: return s->z0 + s->amp * sin(2.0 * M_PI * dx / s->wl) * cos(2.0 * M_PI * dy / s->wl);
    default: return s->z0;
    }
}

/* Upward unit normal by central differences. */
static void surf_normal(double n[3], const rch_surface *s, double x, double y)
{
    const double h = 1e-3;
    const double fx = (rch_surface_z(s, x + h, y) - rch_surface_z(s, x - h, y)) / (2 * h);
    const double fy = (rch_surface_z(s, x, y + h) - rch_surface_z(s, x, y - h)) / (2 * h);
    const double l = sqrt(fx * fx + fy * fy + 1.0);
    n[0] = -fx / l;
    n[1] = -fy / l;
    n[2] = 1.0 / l;
}

/* One "key=value" of a surface spec into s; 0 or -1 with d set. */
static int surf_key(rch_surface *s, char *kv, rch_diag *d)
{
    static const char *const keys[] = {"cx", "cy", "z0", "w", "h", "step", "ds", "ax", "ay", "r", "k", "amp", "wl"};
    double *dst[] = {&s->cx, &s->cy, &s->z0, &s->w, &s->h, &s->step, &s->ds, &s->ax_deg, &s->ay_deg,
                     &s->r, &s->k, &s->amp, &s->wl};
    char *eq = strchr(kv, '=');
    double v;
    if (!eq) {
        rch_diag_set(d, "", 0, 0, "surface option '%s' is not key=value", kv);
        return -1;
    }
    *eq = '\0';
    if (rch_parse_double(eq + 1, &v) != 0) { /* strict: decimal, finite, nothing around it */
        rch_diag_set(d, "", 0, 0, "surface option %s: '%s' is not a number", kv, eq + 1);
        return -1;
    }
    for (size_t i = 0; i < sizeof keys / sizeof keys[0]; ++i)
        if (strcmp(kv, keys[i]) == 0) {
            *dst[i] = v;
            return 0;
        }
    rch_diag_set(d, "", 0, 0, "unknown surface key '%s'", kv);
    return -1;
}

int rch_surface_parse(rch_surface *s, const char *spec, rch_diag *d)
{
    char buf[512];
    int found = -1;
    rch_surface_defaults(s);
    if (!spec)
        return 0;
    if (strlen(spec) >= sizeof buf) {
        rch_diag_set(d, "", 0, 0, "surface spec longer than %zu characters", sizeof buf - 1);
        return -1;
    }
    memcpy(buf, spec, strlen(spec) + 1);
    char *colon = strchr(buf, ':');
    if (colon)
        *colon = '\0';
    for (int i = 0; i < (int)(sizeof surf_names / sizeof surf_names[0]); ++i)
        if (strcmp(buf, surf_names[i]) == 0)
            found = i;
    if (found < 0) {
        rch_diag_set(d, "", 0, 0, "unknown surface '%s' (plane, tilted, cylinder, saddle, sine)", buf);
        return -1;
    }
    s->kind = (rch_surface_kind)found;
    for (char *kv = colon ? colon + 1 : NULL, *next; kv; kv = next) {
        next = strchr(kv, ',');
        if (next)
            *next++ = '\0';
        if (*kv != '\0' && surf_key(s, kv, d) != 0)
            return -1;
    }
    if (!(s->w > 0 && s->h >= 0 && s->step > 0 && s->ds > 0 && s->wl > 0 && s->r > 0.5 * s->h &&
          s->w / s->ds <= 5000 && s->h / s->step <= 1000 && fabs(s->ax_deg) < 80 && fabs(s->ay_deg) < 80)) {
        rch_diag_set(d, "", 0, 0, "surface sizes must be positive, r > h/2, slopes < 80 deg, "
                                  "at most 5000 points per line and 1000 lines");
        return -1;
    }
    const double n_pts = (floor(s->w / s->ds + 1e-9) + 1.0) * (floor(s->h / s->step + 1e-9) + 1.0);
    if (n_pts > RCH_GRIND_MAX_POINTS) {
        rch_diag_set(d, "", 0, 0, "%.0f path points, above the limit of %d (about %d MB); raise ds or step",
                     n_pts, RCH_GRIND_MAX_POINTS, (int)(RCH_GRIND_MAX_POINTS * sizeof(rch_grind_point) >> 20));
        return -1;
    }
    return 0;
}

/* ---- path -------------------------------------------------------------- */

void rch_grind_defaults(rch_grind_config *cfg)
{
    memset(cfg, 0, sizeof *cfg);
    rch_surface_defaults(&cfg->surface);
    cfg->align = 1;
    cfg->max_dev_rad = 30.0 * DEG;
}

/* Tool frame: z along the inward normal, x along +x projected onto the
 * tangent plane, y = z cross x. R columns are the axes. */
static void tool_frame(double R[9], const double n[3])
{
    const double z[3] = {-n[0], -n[1], -n[2]};
    double x[3] = {1.0 - z[0] * z[0], -z[0] * z[1], -z[0] * z[2]};
    const double l = sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]);
    for (int i = 0; i < 3; ++i)
        x[i] /= l;
    const double y[3] = {z[1] * x[2] - z[2] * x[1], z[2] * x[0] - z[0] * x[2], z[0] * x[1] - z[1] * x[0]};
    for (int r = 0; r < 3; ++r) {
        R[3 * r + 0] = x[r];
        R[3 * r + 1] = y[r];
        R[3 * r + 2] = z[r];
    }
}

/* The raster path on the surface (boustrophedon lines along x). 0 or -1 (memory). */
static int make_path(rch_grind_result *res, const rch_surface *s)
{
    const size_t nx = (size_t)floor(s->w / s->ds + 1e-9) + 1;
    const size_t ny = (size_t)floor(s->h / s->step + 1e-9) + 1;
    rch_grind_point *p = calloc(nx * ny, sizeof *p);
    if (!p)
        return -1;
    size_t k = 0;
    for (size_t j = 0; j < ny; ++j) {
        const double y = s->cy - 0.5 * s->h + (double)j * s->step;
        for (size_t i = 0; i < nx; ++i) {
            const size_t ii = (j % 2 == 0) ? i : nx - 1 - i;
            const double x = s->cx - 0.5 * s->w + (double)ii * s->ds;
            double n[3];
            p[k].p_mm[0] = x;
            p[k].p_mm[1] = y;
            p[k].p_mm[2] = rch_surface_z(s, x, y);
            surf_normal(n, s, x, y);
            tool_frame(p[k].R, n);
            ++k;
        }
    }
    res->pts = p;
    res->n = k;
    res->nx = nx;
    res->ny = ny;
    return 0;
}

/* Nominal IK of the whole path; the first point from a few seeds. */
static int path_ik(rch_grind_point *pts, size_t n, const rc_model *nom, rch_diag *d)
{
    rc_comp_config cfg;
    memset(&cfg, 0, sizeof cfg);
    cfg.max_iter = 200;
    cfg.tol_mm = 1e-7;
    cfg.tol_rad = 1e-10;
    const double q1 = atan2(pts[0].p_mm[1], pts[0].p_mm[0]);
    static const double q2s[] = {0.3, 0.0, 0.6, -0.3}, q3s[] = {0.3, 0.0, 0.8}, q5s[] = {1.2, 0.8, 1.6};
    int ok = 0;
    for (size_t a = 0; a < 4 && !ok; ++a)
        for (size_t b = 0; b < 3 && !ok; ++b)
            for (size_t c = 0; c < 3 && !ok; ++c) {
                const double seed[RC_NJ] = {q1, q2s[a], q3s[b], 0.0, q5s[c], q1};
                rc_comp_result res;
                if (rc_comp_pose(pts[0].q_nom_rad, &res, nom, pts[0].p_mm, pts[0].R, seed, &cfg) == RC_OK &&
                    res.exit == RC_COMP_CONVERGED && pts[0].q_nom_rad[4] > 0.2)
                    ok = 1;
            }
    if (!ok) {
        rch_diag_set(d, "", 0, 0, "the nominal robot cannot reach the path start (%.1f, %.1f, %.1f) mm with the "
                                  "tool along the surface normal; move the patch (cx, cy, z0)",
                     pts[0].p_mm[0], pts[0].p_mm[1], pts[0].p_mm[2]);
        return -1;
    }
    cfg.max_dev_rad = 0.5; /* successive points are close: no configuration jumps */
    for (size_t k = 1; k < n; ++k) {
        rc_comp_result res;
        if (rc_comp_pose(pts[k].q_nom_rad, &res, nom, pts[k].p_mm, pts[k].R, pts[k - 1].q_nom_rad, &cfg) != RC_OK ||
            res.exit != RC_COMP_CONVERGED) {
            rch_diag_set(d, "", 0, 0, "the nominal robot cannot follow the path at point %zu (%.1f, %.1f, %.1f) mm "
                                      "(%s); make the patch smaller or move it",
                         k, pts[k].p_mm[0], pts[k].p_mm[1], pts[k].p_mm[2], rc_comp_exit_str(res.exit));
            return -1;
        }
    }
    return 0;
}

void rch_grind_align_base(double *phi_rad, double *dz_mm, const rc_model *cal, const rc_model *truth)
{
    rc_rng g;
    rc_rng_seed(&g, 12345);
    double sxx = 0, sxy = 0, sz = 0;
    const int n = 2000;
    for (int k = 0; k < n; ++k) {
        double q[RC_NJ], pc[3], pt[3];
        for (int i = 0; i < RC_NJ; ++i)
            q[i] = truth->q_min_rad[i] + (truth->q_max_rad[i] - truth->q_min_rad[i]) * rc_rng_u01(&g);
        rc_fk(pc, NULL, cal, q);
        rc_fk(pt, NULL, truth, q);
        sxx += pc[0] * pt[0] + pc[1] * pt[1];
        sxy += pc[0] * pt[1] - pc[1] * pt[0];
        sz += pt[2] - pc[2];
    }
    *phi_rad = atan2(sxy, sxx);
    *dz_mm = sz / n;
}

static double dist3(const double a[3], const double b[3])
{
    return sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
}

/* Signed deviation of pt from p's programmed point along the outward
 * surface normal (the tool z axis, column 3 of R, points inward). */
static double dev_normal(const double pt[3], const rch_grind_point *p)
{
    return -((pt[0] - p->p_mm[0]) * p->R[2] + (pt[1] - p->p_mm[1]) * p->R[5] + (pt[2] - p->p_mm[2]) * p->R[8]);
}

/* Compensate every path point with model m (a stream, as a controller
 * would) and measure the true flange's deviation: into dev_mm[c] and
 * flag[c] of every point, or (c < 0) into *only. Returns the points whose
 * orientation was matched as best effort only. */
static size_t comp_pass(rch_grind_result *res, const rch_grind_config *gc, int c, const rc_model *m,
                        const rc_model *truth, const rc_model *nom, rch_stats *only)
{
    rc_comp_config cfg;
    rc_comp_stream st;
    size_t n_best_effort = 0;
    memset(&cfg, 0, sizeof cfg);
    cfg.flags = gc->position_only ? RC_COMP_FLAG_POSITION_ONLY : 0u;
    cfg.max_dev_rad = gc->max_dev_rad;
    cfg.max_iter = 50;
    rc_comp_stream_init(&st, m, nom, &cfg);
    for (size_t k = 0; k < res->n; ++k) {
        rch_grind_point *p = &res->pts[k];
        double qc[RC_NJ], pt[3];
        rc_comp_result cr;
        const rc_status stc = rc_comp_stream_step(&st, qc, &cr, p->q_nom_rad);
        if (stc == RC_OK && cr.exit == RC_COMP_POSITION_ONLY)
            ++n_best_effort;
        rc_fk(pt, NULL, truth, qc);
        if (c < 0) {
            if (only != NULL)
                rch_stats_add(only, dist3(pt, p->p_mm));
            continue;
        }
        p->flag[c] = stc != RC_OK;
        p->dev_mm[c] = dist3(pt, p->p_mm);
        p->dev_n_mm[c] = dev_normal(pt, p);
    }
    return n_best_effort;
}

/* Deviation of the true flange at every point, for the three cases; with
 * alignment also the nominal model aligned the same way (what the alignment
 * alone is worth). */
static void deviations(rch_grind_result *res, const rch_grind_config *gc, const rc_model *cal,
                       const rc_model *truth, const rc_model *nom)
{
    for (size_t k = 0; k < res->n; ++k) {
        double pt[3];
        rc_fk(pt, NULL, truth, res->pts[k].q_nom_rad);
        res->pts[k].dev_mm[RCH_GRIND_UNCOMP] = dist3(pt, res->pts[k].p_mm);
        res->pts[k].dev_n_mm[RCH_GRIND_UNCOMP] = dev_normal(pt, &res->pts[k]);
    }
    res->n_orient_best_effort = comp_pass(res, gc, RCH_GRIND_COMP_CAL, cal, truth, nom, NULL);
    (void)comp_pass(res, gc, RCH_GRIND_COMP_TRUE, truth, truth, nom, NULL);
    memset(&res->align_only_mm, 0, sizeof res->align_only_mm);
    if (gc->align) {
        rc_model nom_aligned = *nom;
        double phi, dz;
        rch_grind_align_base(&phi, &dz, &nom_aligned, truth);
        nom_aligned.x[RC_P_THETA(0)] += phi;
        nom_aligned.x[RC_P_D(0)] += dz;
        (void)comp_pass(res, gc, -1, &nom_aligned, truth, nom, &res->align_only_mm);
    }
}

/* 1 when the geometry of m is its nominal table (nothing was calibrated). */
static int is_nominal(const rc_model *m, const rc_model *nom)
{
    for (unsigned k = 0; k < RC_N_DH; ++k)
        if (m->x[k] != nom->x[k])
            return 0;
    return 1;
}

/* Path indices nearest to the patch's corners and centre. */
static void named_points(rch_grind_result *res, const rch_surface *s)
{
    const double tx[5] = {s->cx - 0.5 * s->w, s->cx + 0.5 * s->w, s->cx, s->cx - 0.5 * s->w, s->cx + 0.5 * s->w};
    const double ty[5] = {s->cy - 0.5 * s->h, s->cy - 0.5 * s->h, s->cy, s->cy + 0.5 * s->h, s->cy + 0.5 * s->h};
    for (int m = 0; m < 5; ++m) {
        double best = HUGE_VAL;
        res->named[m] = 0;
        for (size_t k = 0; k < res->n; ++k) {
            const double *p = res->pts[k].p_mm;
            const double e = (p[0] - tx[m]) * (p[0] - tx[m]) + (p[1] - ty[m]) * (p[1] - ty[m]);
            if (e < best) {
                best = e;
                res->named[m] = k;
            }
        }
    }
}

int rch_grind_run(rch_grind_result *res, const rch_grind_config *cfg, const rc_model *cal_in, const rc_model *truth,
                  const rc_model *nom, rch_diag *d)
{
    rc_model cal = *cal_in;
    memset(res, 0, sizeof *res);
    res->model_is_nominal = is_nominal(cal_in, nom);
    if (cfg->align) {
        rch_grind_align_base(&res->heading_rad, &res->height_mm, &cal, truth);
        cal.x[RC_P_THETA(0)] += res->heading_rad;
        cal.x[RC_P_D(0)] += res->height_mm;
    }
    if (make_path(res, &cfg->surface) != 0) {
        rch_diag_set(d, "", 0, 0, "out of memory");
        return -1;
    }
    if (path_ik(res->pts, res->n, nom, d) != 0)
        return -1;
    deviations(res, cfg, &cal, truth, nom);
    for (int c = 0; c < RCH_GRIND_CASES; ++c) {
        memset(&res->cases[c].dev_mm, 0, sizeof res->cases[c].dev_mm);
        for (size_t k = 0; k < res->n; ++k) {
            rch_stats_add(&res->cases[c].dev_mm, res->pts[k].dev_mm[c]);
            res->cases[c].n_flag += res->pts[k].flag[c] != 0;
        }
    }
    named_points(res, &cfg->surface);
    return 0;
}

void rch_grind_free(rch_grind_result *res)
{
    free(res->pts);
    res->pts = NULL;
    res->n = 0;
}

/* ---- reports ----------------------------------------------------------- */

static const char *const point_names[5] = {"P1", "P2", "P3", "P4", "P5"};
static const char *const point_where[5] = {"corner x-, y- (path start)", "corner x+, y-", "centre", "corner x-, y+",
                                           "corner x+, y+"};
static const char *const case_names[RCH_GRIND_CASES] = {"uncompensated", "compensated (calibrated model)",
                                                        "compensated (true model, floor)"};

const char *rch_grind_point_name(int m) { return m >= 0 && m < 5 ? point_names[m] : "?"; }

static void spec_line(char *buf, size_t len, const rch_surface *s)
{
    snprintf(buf, len, "%s, centre (%.0f, %.0f, %.0f) mm, %.0f x %.0f mm, line step %.1f mm, point step %.1f mm",
             rch_surface_name(s->kind), s->cx, s->cy, s->z0, s->w, s->h, s->step, s->ds);
}

static void report_table(FILE *f, const rch_grind_result *res)
{
    fprintf(f, "\ndeviation of the true flange path from the programmed path (mm)\n");
    fprintf(f, "  %-34s %9s %9s %9s", "", "mean", "SD", "max");
    for (int m = 0; m < 5; ++m)
        fprintf(f, " %8s", point_names[m]);
    fprintf(f, "\n");
    for (int c = 0; c < RCH_GRIND_CASES; ++c) {
        const rch_stats *s = &res->cases[c].dev_mm;
        fprintf(f, "  %-34s %9.4f %9.4f %9.4f", case_names[c], s->mean, rch_stats_sd(s), s->max_abs);
        for (int m = 0; m < 5; ++m)
            fprintf(f, " %8.4f", res->pts[res->named[m]].dev_mm[c]);
        fprintf(f, "\n");
    }
    fprintf(f, "  named points:");
    for (int m = 0; m < 5; ++m) {
        const double *p = res->pts[res->named[m]].p_mm;
        fprintf(f, " %s = %s (%.0f, %.0f, %.1f)%s", point_names[m], point_where[m], p[0], p[1], p[2],
                m < 4 ? ";" : "\n");
    }
}

void rch_grind_report(FILE *f, const rch_grind_result *res, const rch_grind_config *cfg, const char *model_name,
                      const char *truth_name)
{
    char spec[160];
    const double unc = res->cases[RCH_GRIND_UNCOMP].dev_mm.mean, cal = res->cases[RCH_GRIND_COMP_CAL].dev_mm.mean;
    spec_line(spec, sizeof spec, &cfg->surface);
    fprintf(f, "rcal grind: %s\n  %zu path points on %zu raster lines; compensation: %s\n", spec, res->n, res->ny,
            cfg->position_only ? "flange position" : "flange pose (position first)");
    fprintf(f, "  calibrated model %s, true robot %s\n", model_name, truth_name);
    if (cfg->align)
        fprintf(f, "  base heading and height of the calibrated model taken from the truth: %+.4f deg about z, "
                   "%+.4f mm along z\n",
                res->heading_rad / DEG, res->height_mm);
    report_table(f, res);
    if (unc > 0)
        fprintf(f, "  compensation with the calibrated model removes %.1f%% of the mean deviation\n",
                100.0 * (1.0 - cal / unc));
    if (unc > 0 && res->align_only_mm.n > 0)
        fprintf(f, "  of which the base alignment taken from the truth alone (the nominal model aligned the same "
                   "way) removes %.1f%%\n",
                100.0 * (1.0 - res->align_only_mm.mean / unc));
    if (res->model_is_nominal)
        fprintf(f, "  warning: the model's geometry is its nominal table: it is not calibrated, and whatever the\n"
                   "  compensation removes comes from the base alignment taken from the truth (--no-align: none)\n");
    if (res->cases[RCH_GRIND_COMP_CAL].n_flag || res->cases[RCH_GRIND_COMP_TRUE].n_flag)
        fprintf(f, "  warning: %zu / %zu points not compensated (flagged)\n", res->cases[RCH_GRIND_COMP_CAL].n_flag,
                res->cases[RCH_GRIND_COMP_TRUE].n_flag);
    if (res->n_orient_best_effort)
        fprintf(f, "  note: %zu points with the orientation best effort (position matched): the calibrated model's "
                   "orientation differs beyond the correction bound; --position-only avoids the wrist motion\n",
                res->n_orient_best_effort);
}

int rch_grind_json(FILE *f, const rch_grind_result *res, const rch_grind_config *cfg, int argc, char **argv)
{
    static const char *const keys[3] = {"uncompensated", "compensated_calibrated", "compensated_true"};
    rch_jw w;
    rch_jw_begin(&w, f, 1, "rcal-grind/1", argc, argv);
    rch_jw_str(&w, "surface", rch_surface_name(cfg->surface.kind));
    rch_jw_uint(&w, "points", res->n);
    rch_jw_uint(&w, "lines", res->ny);
    rch_jw_str(&w, "mode", cfg->position_only ? "position" : "pose");
    rch_jw_obj(&w, "align");
    rch_jw_bool(&w, "on", cfg->align);
    rch_jw_numf(&w, "heading_deg", res->heading_rad / DEG, "%.6f");
    rch_jw_numf(&w, "height_mm", res->height_mm, "%.6f");
    /* the nominal model with the same alignment: what the alignment alone is worth */
    rch_jw_numf(&w, "alignment_only_mean_mm", res->align_only_mm.n > 0 ? res->align_only_mm.mean : NAN, "%.6f");
    rch_jw_end(&w);
    rch_jw_bool(&w, "model_is_nominal", res->model_is_nominal);
    rch_jw_obj(&w, "cases");
    for (int c = 0; c < RCH_GRIND_CASES; ++c) {
        const rch_stats *s = &res->cases[c].dev_mm;
        rch_jw_obj(&w, keys[c]);
        rch_jw_numf(&w, "mean_mm", s->mean, "%.6f");
        rch_jw_numf(&w, "sd_mm", rch_stats_sd(s), "%.6f");
        rch_jw_numf(&w, "max_mm", s->max_abs, "%.6f"); /* deviations are >= 0 */
        rch_jw_numf(&w, "rms_mm", rch_stats_rms(s), "%.6f");
        rch_jw_uint(&w, "not_converged", res->cases[c].n_flag);
        rch_jw_arr(&w, "named");
        for (int m = 0; m < 5; ++m)
            rch_jw_numf(&w, NULL, res->pts[res->named[m]].dev_mm[c], "%.6f");
        rch_jw_end(&w);
        rch_jw_end(&w);
    }
    rch_jw_end(&w);
    rch_jw_end(&w);
    return rch_jw_finish(&w);
}

/* ---- plots ------------------------------------------------------------- */

/* Top-view placement of one panel: patch point (x, y) mm to pixels. */
typedef struct panel_map {
    const rch_surface *s;
    double sc, cx, cy; /* pixels per mm, panel centre */
} panel_map;

static double px(const panel_map *m, double x) { return m->cx + (x - m->s->cx) * m->sc; }
static double py(const panel_map *m, double y) { return m->cy - (y - m->s->cy) * m->sc; }

/* The colour bar of one panel at (bx, by), bh high: 0 to vmax mm, its tick
 * labels right of it and its unit label right of those, all inside the
 * panel's slot (SVG_BAR_W pixels). */
#define SVG_BAR_W 110.0
static void svg_colour_bar(FILE *f, double bx, double by, double bh, double vmax)
{
    static const rch_svg_paint frame = {.stroke = "#333"};
    static const rch_svg_font tick = {.size_px = 11},
                              unit = {.size_px = 11, .anchor = RCH_SVG_MIDDLE, .rotate_deg = -90.0};
    rch_svg_group(f, "colourbar", NULL, NULL);
    for (int i = 0; i < 50; ++i) {
        char col[8];
        rch_svg_viridis(col, (i + 0.5) / 50.0);
        const rch_svg_paint cell = {.fill = col};
        rch_svg_rect(f, bx, by + bh - (i + 1) * bh / 50.0, 14.0, bh / 50.0 + 0.3, &cell, NULL);
    }
    rch_svg_rect(f, bx, by, 14.0, bh, &frame, NULL);
    for (int i = 0; i <= 4; ++i)
        rch_svg_textf(f, bx + 18, by + bh - i * bh / 4.0 + 4, &tick, "%.3g", vmax * i / 4.0);
    rch_svg_text(f, bx + 84, by + bh / 2, &unit, "deviation (mm)");
    rch_svg_group_end(f);
}

/* Axis labels at the patch edges. */
static void svg_panel_axes(FILE *f, const panel_map *m)
{
    static const rch_svg_font xf = {.size_px = 11, .anchor = RCH_SVG_MIDDLE}, yf = {.size_px = 11, .anchor = RCH_SVG_END};
    const rch_surface *s = m->s;
    const double x0 = s->cx - 0.5 * s->w, x1 = s->cx + 0.5 * s->w, y0 = s->cy - 0.5 * s->h, y1 = s->cy + 0.5 * s->h;
    rch_svg_textf(f, px(m, x0), py(m, y0) + 42, &xf, "x = %.0f", x0);
    rch_svg_textf(f, px(m, x1), py(m, y0) + 42, &xf, "x = %.0f mm", x1);
    rch_svg_textf(f, px(m, x0) - 10, py(m, y0) + 4, &yf, "y = %.0f", y0);
    rch_svg_textf(f, px(m, x0) - 10, py(m, y1) + 4, &yf, "y = %.0f", y1);
}

/* One panel: the path of case c coloured by its deviation, the named points, a colour bar. */
static void svg_panel(FILE *f, const rch_grind_result *res, int c, const rch_surface *s, double ox, double oy,
                      double pw, double ph, const char *title)
{
    static const rch_svg_paint patch = {.fill = "#f4f4f4", .stroke = "#999"},
                               ring = {.stroke = "#d62728", .stroke_px = 2};
    static const rch_svg_font tf = {.size_px = 15, .anchor = RCH_SVG_MIDDLE},
                              sf = {.size_px = 12, .anchor = RCH_SVG_MIDDLE, .fill = "#555"};
    const rch_grind_point *p = res->pts;
    double vmax = 0.0;
    for (size_t k = 0; k < res->n; ++k)
        vmax = fmax(vmax, p[k].dev_mm[c]);
    if (!(vmax > 0.0))
        vmax = 1e-9;
    const panel_map m = {s, fmin(pw / s->w, ph / fmax(s->h, 1e-9)), ox + 0.5 * pw, oy + 0.5 * ph};
    rch_svg_text(f, ox + 0.5 * pw, oy - 40, &tf, title);
    rch_svg_textf(f, ox + 0.5 * pw, oy - 24, &sf, "own colour scale: 0 to %.3g mm", vmax);
    rch_svg_rect(f, px(&m, s->cx - 0.5 * s->w) - 6, py(&m, s->cy + 0.5 * s->h) - 6, s->w * m.sc + 12,
                 s->h * m.sc + 12, &patch, NULL);
    rch_svg_group(f, "series", "segments", NULL); /* n points: n - 1 segments */
    for (size_t k = 0; k + 1 < res->n; ++k) {
        char col[8];
        rch_svg_viridis(col, 0.5 * (p[k].dev_mm[c] + p[k + 1].dev_mm[c]) / vmax);
        const rch_svg_paint seg = {.stroke = col, .stroke_px = 4, .round_cap = 1};
        rch_svg_line(f, px(&m, p[k].p_mm[0]), py(&m, p[k].p_mm[1]), px(&m, p[k + 1].p_mm[0]), py(&m, p[k + 1].p_mm[1]),
                     &seg);
    }
    rch_svg_group_end(f);
    for (int i = 0; i < 5; ++i) {
        const rch_grind_point *q = &p[res->named[i]];
        const double qx = px(&m, q->p_mm[0]), qy = py(&m, q->p_mm[1]);
        const int right = q->p_mm[0] > s->cx + 1e-9, below = q->p_mm[1] < s->cy - 1e-9;
        const rch_svg_font lf = {.size_px = 12, .fill = "#d62728", .bold = 1, .anchor = right ? RCH_SVG_END : RCH_SVG_START};
        rch_svg_circle(f, qx, qy, 5.0, &ring);
        rch_svg_textf(f, qx + (right ? -9 : 9), qy + (below ? 20 : -9), &lf, "%s %.3g", point_names[i], q->dev_mm[c]);
    }
    svg_colour_bar(f, ox + pw + 30, oy, ph, vmax);
    svg_panel_axes(f, &m);
}

static void write_path_svg(FILE *f, const rch_grind_result *res, const rch_surface *s)
{
    char subtitle[160];
    spec_line(subtitle, sizeof subtitle, s);
    const double pw = 420, ph = fmax(120.0, fmin(420.0, 420.0 * s->h / s->w)), gap = 100,
                 W = 90 + 2 * (pw + 30 + SVG_BAR_W) + gap, H = ph + 165;
    static const char title[] = "Grinding path seen from above: distance of the true flange position from the "
                                "programmed one (mm)";
    const rch_svg_doc doc = {.width_px = W, .height_px = H, .title = title, .font_family = "sans-serif"};
    static const rch_svg_font tf = {.size_px = 16, .anchor = RCH_SVG_MIDDLE},
                              sf = {.size_px = 12, .anchor = RCH_SVG_MIDDLE, .fill = "#555"};
    rch_svg_begin(f, &doc);
    rch_svg_text(f, W / 2, 22, &tf, title);
    rch_svg_text(f, W / 2, 40, &sf, subtitle);
    svg_panel(f, res, RCH_GRIND_UNCOMP, s, 90, 110, pw, ph, "uncompensated");
    svg_panel(f, res, RCH_GRIND_COMP_CAL, s, 90 + pw + 30 + SVG_BAR_W + gap, 110, pw, ph,
              "compensated (calibrated model)");
    rch_svg_end(f);
}

static rch_plot *plot_deviation(const rch_grind_result *res)
{
    const size_t n = res->n;
    double *x = malloc((n ? n : 1) * sizeof *x), *y = malloc((n ? n : 1) * sizeof *y);
    rch_plot *pl = NULL;
    if (x && y) {
        pl = rch_plot_new("Distance of the true flange position from the programmed one along the grinding path",
                          "path point (number, in path order)", "deviation (mm)");
        rch_plot_subtitle(pl, "deviations below 1e-7 mm (the compensation's numerical floor) are drawn at 1e-7 mm");
        rch_plot_size(pl, 900, 500);
        rch_plot_logy(pl, 1);
        for (int c = 0; c < RCH_GRIND_CASES; ++c) {
            for (size_t k = 0; k < n; ++k) {
                x[k] = (double)k;
                y[k] = fmax(res->pts[k].dev_mm[c], 1e-7);
            }
            rch_plot_line(pl, case_names[c], x, y, n);
        }
    }
    free(x);
    free(y);
    return pl;
}

static void write_points_csv(FILE *f, const rch_grind_result *res)
{
    fprintf(f, "k,x,y,z,q1,q2,q3,q4,q5,q6,dev_uncomp_mm,dev_comp_cal_mm,dev_comp_true_mm\n");
    for (size_t k = 0; k < res->n; ++k) {
        const rch_grind_point *p = &res->pts[k];
        fprintf(f, "%zu,%.4f,%.4f,%.4f", k, p->p_mm[0], p->p_mm[1], p->p_mm[2]);
        for (int i = 0; i < RC_NJ; ++i)
            fprintf(f, ",%.6f", p->q_nom_rad[i] / DEG);
        fprintf(f, ",%.6f,%.6f,%.6f\n", p->dev_mm[0], p->dev_mm[1], p->dev_mm[2]);
    }
}

/* The data of grind_path.svg: one row per drawn point of each panel. */
static int save_path_csv(const rch_grind_result *res, const rch_plot_dir *pd, rch_diag *d)
{
    static const char *const head[] = {"panel", "path point (number)", "x (mm)", "y (mm)", "deviation (mm)"};
    static const int cases[2] = {RCH_GRIND_UNCOMP, RCH_GRIND_COMP_CAL};
    const size_t n = res->n;
    const char **text = malloc((2 * n + 1) * sizeof *text);
    double *num = malloc((2 * n + 1) * 4 * sizeof *num);
    int rc;
    if (!text || !num) {
        rc = rch_plot_save_csv(NULL, pd, "grind_path.svg", d);
    } else {
        for (size_t j = 0; j < 2; ++j)
            for (size_t k = 0; k < n; ++k) {
                const size_t r = j * n + k;
                text[r] = case_names[cases[j]];
                num[4 * r] = (double)k;
                num[4 * r + 1] = res->pts[k].p_mm[0];
                num[4 * r + 2] = res->pts[k].p_mm[1];
                num[4 * r + 3] = res->pts[k].dev_mm[cases[j]];
            }
        const rch_plot_table t = {head, 1, 4, 2 * n, text, num};
        rc = rch_plot_save_csv(&t, pd, "grind_path.svg", d);
    }
    free(text);
    free(num);
    return rc;
}

int rch_grind_plots(const rch_grind_result *res, const rch_grind_config *cfg, const rch_plot_dir *pd, rch_diag *d)
{
    rch_out o;
    if (rch_plot_mkdir(pd->dir) != 0) {
        rch_diag_set(d, "", 0, 0, "cannot create %s: %s", pd->dir, strerror(errno));
        return -1;
    }
    if (rch_plot_open(&o, pd, "grind_path.svg", d) != 0)
        return -1;
    write_path_svg(o.f, res, &cfg->surface);
    if (rch_plot_close(&o, pd, 0, d) != 0 || save_path_csv(res, pd, d) != 0 || rch_plot_save(plot_deviation(res), pd, "grind_deviation.svg", d) != 0 ||
        rch_plot_open(&o, pd, "grind_points.csv", d) != 0)
        return -1;
    write_points_csv(o.f, res);
    return rch_plot_close(&o, pd, 0, d);
}

/* ---- Table 8: several models on one path --------------------------------- */

static void table_row(rch_grind_row *r, const char *name, const rch_grind_result *res, int c)
{
    double sum = 0.0, ss = 0.0;
    memset(r, 0, sizeof *r);
    snprintf(r->name, sizeof r->name, "%s", name);
    for (int m = 0; m < 5; ++m) {
        r->p_mm[m] = res->pts[res->named[m]].dev_n_mm[c];
        sum += r->p_mm[m];
    }
    r->mean_mm = sum / 5.0;
    for (int m = 0; m < 5; ++m)
        ss += (r->p_mm[m] - r->mean_mm) * (r->p_mm[m] - r->mean_mm);
    r->sd_mm = sqrt(ss / 4.0); /* n - 1, as the paper's Table 8 */
    for (size_t k = 0; k < res->n; ++k) {
        rch_stats_add(&r->path_mm, res->pts[k].dev_mm[c]);
        rch_stats_add(&r->path_n_mm, res->pts[k].dev_n_mm[c]);
        r->n_flag += res->pts[k].flag[c] != 0;
    }
}

int rch_grind_table8(rch_grind_table *t, const rch_grind_config *cfg, const rc_model *const *models,
                     const char *const *names, size_t n_models, const rc_model *truth, const rc_model *nom,
                     rch_diag *d)
{
    memset(t, 0, sizeof *t);
    if (n_models < 1 || n_models > RCH_GRIND_MAX_MODELS) {
        rch_diag_set(d, "", 0, 0, "1..%d models, not %zu", RCH_GRIND_MAX_MODELS, n_models);
        return -1;
    }
    for (size_t k = 0; k < n_models; ++k) {
        rch_grind_result res;
        if (rch_grind_run(&res, cfg, models[k], truth, nom, d) != 0) {
            rch_grind_free(&res);
            return -1;
        }
        if (k == 0) {
            table_row(&t->row[0], "BC", &res, RCH_GRIND_UNCOMP);
            t->n_points = res.n;
            for (int m = 0; m < 5; ++m)
                memcpy(t->named_p_mm[m], res.pts[res.named[m]].p_mm, sizeof t->named_p_mm[m]);
        }
        table_row(&t->row[k + 1], names[k], &res, RCH_GRIND_COMP_CAL);
        t->heading_rad[k] = res.heading_rad;
        t->height_mm[k] = res.height_mm;
        if (k + 1 == n_models)
            table_row(&t->row[k + 2], "true model", &res, RCH_GRIND_COMP_TRUE);
        rch_grind_free(&res);
    }
    t->n_rows = n_models + 2;
    return 0;
}

int rch_grind_table8_files(rch_grind_table *t, const rch_grind_config *cfg, const char *const *paths,
                           const char *const *names, size_t n, const char *truth_path, const char *nominal_path,
                           rch_diag *d)
{
    const rc_model *models[RCH_GRIND_MAX_MODELS];
    int rc = -1;
    if (n < 1 || n > RCH_GRIND_MAX_MODELS) {
        rch_diag_set(d, "", 0, 0, "1..%d models, not %zu", RCH_GRIND_MAX_MODELS, n);
        return -1;
    }
    rch_robot *rob = malloc((n + 2) * sizeof *rob); /* the models, the truth, the nominal */
    if (!rob) {
        rch_diag_set(d, "", 0, 0, "out of memory");
        return -1;
    }
    for (size_t k = 0; k < n; ++k) {
        if (rch_robot_load(&rob[k], paths[k], d) != 0)
            goto done;
        models[k] = &rob[k].model;
    }
    if (rch_robot_load(&rob[n], truth_path, d) != 0 ||
        (nominal_path && rch_robot_load(&rob[n + 1], nominal_path, d) != 0))
        goto done;
    rc = rch_grind_table8(t, cfg, models, names, n, &rob[n].model, nominal_path ? &rob[n + 1].model : &rob[0].nominal,
                          d);
done:
    free(rob);
    return rc;
}

void rch_grind_table8_report(FILE *f, const rch_grind_table *t, const rch_grind_config *cfg, const char *truth_name)
{
    char spec[160];
    spec_line(spec, sizeof spec, &cfg->surface);
    fprintf(f, "rcal grind, the paper's Table 8 form: %s\n  %zu path points; true robot %s; compensation: %s%s\n", spec,
            t->n_points, truth_name, cfg->position_only ? "flange position" : "flange pose (position first)",
            cfg->align ? "; base heading and height of each model taken from the truth" : "");
    fprintf(f, "\nsigned deviation along the outward surface normal at five path points (mm; + above the surface)\n");
    fprintf(f, "  %-16s %8s %8s %8s %8s %8s %8s %8s | %10s %9s %9s %9s\n", "model", "P1", "P2", "P3", "P4", "P5",
            "Mean", "SD", "path mean", "path SD", "path max", "normal SD");
    for (size_t r = 0; r < t->n_rows; ++r) {
        const rch_grind_row *w = &t->row[r];
        fprintf(f, "  %-16s", w->name);
        for (int m = 0; m < 5; ++m)
            fprintf(f, " %8.3f", w->p_mm[m]);
        fprintf(f, " %8.3f %8.3f | %10.4f %9.4f %9.4f %9.4f%s\n", w->mean_mm, w->sd_mm, w->path_mm.mean,
                rch_stats_sd(&w->path_mm), w->path_mm.max_abs, rch_stats_sd(&w->path_n_mm),
                w->n_flag ? "  (points not compensated)" : "");
    }
    fprintf(f, "  Mean, SD: over the five points (SD with n - 1, as the paper); path: |3-D deviation| over all %zu "
               "points;\n  normal SD: SD of the signed normal deviation over the path. BC: before compensation.\n",
            t->n_points);
    fprintf(f, "  points:");
    for (int m = 0; m < 5; ++m)
        fprintf(f, " %s = %s (%.0f, %.0f, %.1f)%s", point_names[m], point_where[m], t->named_p_mm[m][0],
                t->named_p_mm[m][1], t->named_p_mm[m][2], m < 4 ? ";" : "\n");
}

int rch_grind_table8_json(FILE *f, const rch_grind_table *t, const rch_grind_config *cfg, int argc, char **argv)
{
    rch_jw w;
    rch_jw_begin(&w, f, 1, "rcal-grind-table8/1", argc, argv);
    rch_jw_str(&w, "surface", rch_surface_name(cfg->surface.kind));
    rch_jw_uint(&w, "points", t->n_points);
    rch_jw_bool(&w, "align", cfg->align);
    rch_jw_arr(&w, "rows");
    for (size_t r = 0; r < t->n_rows; ++r) {
        const rch_grind_row *x = &t->row[r];
        rch_jw_obj(&w, NULL);
        rch_jw_str(&w, "model", x->name);
        rch_jw_arr(&w, "points_normal_mm");
        for (int m = 0; m < 5; ++m)
            rch_jw_numf(&w, NULL, x->p_mm[m], "%.6f");
        rch_jw_end(&w);
        rch_jw_numf(&w, "mean_mm", x->mean_mm, "%.6f");
        rch_jw_numf(&w, "sd_mm", x->sd_mm, "%.6f");
        rch_jw_numf(&w, "path_mean_mm", x->path_mm.mean, "%.6f");
        rch_jw_numf(&w, "path_sd_mm", rch_stats_sd(&x->path_mm), "%.6f");
        rch_jw_numf(&w, "path_max_mm", x->path_mm.max_abs, "%.6f");
        rch_jw_numf(&w, "path_normal_sd_mm", rch_stats_sd(&x->path_n_mm), "%.6f");
        rch_jw_uint(&w, "not_compensated", x->n_flag);
        rch_jw_end(&w);
    }
    rch_jw_end(&w);
    rch_jw_end(&w);
    return rch_jw_finish(&w);
}
