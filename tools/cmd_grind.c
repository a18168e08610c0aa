/* cmd_grind.c - rcal grind: the grinding-path experiment (the paper's Table 8).
 *
 * A workpiece surface z = f(x, y) (built-in shapes, --surface SPEC), a raster
 * grinding path on it (lines along x, boustrophedon), the tool (flange) axis
 * along the inward surface normal. Nominal joint targets by inverse
 * kinematics on the nominal model (rc_comp_pose, each point seeded with the
 * previous one). Then the flange path the true robot (--truth) follows:
 *   - uncompensated:            FK_true(q_nom)
 *   - compensated, calibrated:  FK_true(comp(q_nom; calibrated model))
 *   - compensated, true model:  FK_true(comp(q_nom; true model))   (the floor)
 * and the deviation from the programmed path point at every point: mean,
 * SD, max, and five named points (the patch's corners and centre).
 *
 * Frames: cable lengths cannot see the base heading (a rotation about the
 * joint-1 axis) or the base height (a shift along it); a real cell takes
 * those from the workpiece frame. By default they are taken from the truth:
 * theta1 and d1 of the calibrated model get the rotation and shift that best
 * map its flange points onto the truth's over 2000 random poses (closed form);
 * --no-align compares raw frames.
 *
 * --plots DIR writes grind_path.svg (top view of the path, each segment
 * coloured by its deviation: uncompensated and compensated side by side, each
 * with its colour bar), grind_deviation.svg (deviation along the path, the
 * three cases, log scale) and grind_points.csv (every point).
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "rc_comp.h"
#include "rc_rand.h"
#include "rcal_cmds.h"
#include "rcal_opts.h"
#include "rch_plot.h"
#include "rch_robot.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif
#define DEG (M_PI / 180.0)

static void usage(FILE *f)
{
    fprintf(f,
            "usage: rcal grind --model MODEL.json --truth TRUTH.json [--surface SPEC] [--plots DIR]\n"
            "                  [--nominal ROBOT.json] [--position-only] [--max-dev-deg D] [--no-align] [--json]\n"
            "  --model    calibrated model used for compensation (rcal calibrate --out)\n"
            "  --truth    the simulated true robot (rcal simulate --truth-out, or any model file)\n"
            "  --nominal  nominal model the path is programmed with (default: the model's \"nominal\")\n"
            "  --surface  NAME[:key=value,...] (lengths mm, angles deg); NAME one of\n"
            "               plane              z = z0\n"
            "               tilted             z = z0 + tan(ax) (x - cx) + tan(ay) (y - cy)    ax=15 ay=0\n"
            "               cylinder           z = z0 + sqrt(r^2 - (y - cy)^2) - r, axis along x   r=150\n"
            "               saddle             z = z0 + k (x - cx)(y - cy) / (w/2 h/2)             k=20\n"
            "               sine               z = z0 + amp sin(2 pi (x - cx)/wl) cos(2 pi (y - cy)/wl)  amp=10 wl=100\n"
            "             common keys: cx=400 cy=0 z0=300 (patch centre), w=200 h=120 (patch size along\n"
            "             x and y), step=10 (raster line spacing), ds=5 (point spacing). Default: tilted\n"
            "  --plots    directory for grind_path.svg, grind_deviation.svg, grind_points.csv\n"
            "  --position-only  compensate the flange position only (default: full pose)\n"
            "  --max-dev-deg    largest joint correction (default 30: an offline experiment, not a\n"
            "                   controller; rcal compensate's default is 5.73 = 0.1 rad)\n"
            "  --no-align keep the calibrated model's base heading and height as identified\n"
            "  --json     one JSON object on stdout instead of the table\n");
}

/* ---- surfaces ---------------------------------------------------------- */

enum { SURF_PLANE, SURF_TILTED, SURF_CYLINDER, SURF_SADDLE, SURF_SINE };
static const char *const surf_names[] = {"plane", "tilted", "cylinder", "saddle", "sine"};

typedef struct {
    int kind;
    double cx, cy, z0, w, h, step, ds;
    double ax_deg, ay_deg, r, k, amp, wl;
} surface;

static double surf_z(const surface *s, double x, double y)
{
    const double dx = x - s->cx, dy = y - s->cy;
    switch (s->kind) {
    case SURF_TILTED: return s->z0 + tan(s->ax_deg * DEG) * dx + tan(s->ay_deg * DEG) * dy;
    case SURF_CYLINDER: return s->z0 + sqrt(fmax(0.0, s->r * s->r - dy * dy)) - s->r;
    case SURF_SADDLE: return s->z0 + s->k * dx * dy / (0.25 * s->w * s->h);
    case SURF_SINE: return s->z0 + s->amp * sin(2.0 * M_PI * dx / s->wl) * cos(2.0 * M_PI * dy / s->wl);
    default: return s->z0;
    }
}

/* Upward unit normal by central differences. */
static void surf_normal(double n[3], const surface *s, double x, double y)
{
    const double h = 1e-3;
    const double fx = (surf_z(s, x + h, y) - surf_z(s, x - h, y)) / (2 * h);
    const double fy = (surf_z(s, x, y + h) - surf_z(s, x, y - h)) / (2 * h);
    const double l = sqrt(fx * fx + fy * fy + 1.0);
    n[0] = -fx / l;
    n[1] = -fy / l;
    n[2] = 1.0 / l;
}

static int surf_parse(surface *s, const char *spec)
{
    memset(s, 0, sizeof *s);
    s->kind = SURF_TILTED;
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
    if (!spec)
        return 0;
    char buf[512];
    if (strlen(spec) >= sizeof buf)
        return -1;
    strcpy(buf, spec);
    char *colon = strchr(buf, ':');
    if (colon)
        *colon = '\0';
    int found = -1;
    for (int i = 0; i < (int)(sizeof surf_names / sizeof surf_names[0]); ++i)
        if (strcmp(buf, surf_names[i]) == 0)
            found = i;
    if (found < 0) {
        fprintf(stderr, "rcal grind: unknown surface '%s' (plane, tilted, cylinder, saddle, sine)\n", buf);
        return -1;
    }
    s->kind = found;
    if (!colon)
        return 0;
    for (char *kv = strtok(colon + 1, ","); kv; kv = strtok(NULL, ",")) {
        char *eq = strchr(kv, '=');
        char *end;
        if (!eq) {
            fprintf(stderr, "rcal grind: surface option '%s' is not key=value\n", kv);
            return -1;
        }
        *eq = '\0';
        errno = 0;
        const double v = strtod(eq + 1, &end);
        if (eq[1] == '\0' || *end != '\0' || errno != 0 || !isfinite(v)) {
            fprintf(stderr, "rcal grind: surface option %s: '%s' is not a number\n", kv, eq + 1);
            return -1;
        }
        static const char *const keys[] = {"cx", "cy", "z0", "w", "h", "step", "ds", "ax", "ay", "r", "k", "amp", "wl"};
        double *dst[] = {&s->cx, &s->cy, &s->z0, &s->w, &s->h, &s->step, &s->ds, &s->ax_deg, &s->ay_deg,
                         &s->r, &s->k, &s->amp, &s->wl};
        int hit = 0;
        for (size_t i = 0; i < sizeof keys / sizeof keys[0]; ++i)
            if (strcmp(kv, keys[i]) == 0) {
                *dst[i] = v;
                hit = 1;
            }
        if (!hit) {
            fprintf(stderr, "rcal grind: unknown surface key '%s'\n", kv);
            return -1;
        }
    }
    if (!(s->w > 0 && s->h >= 0 && s->step > 0 && s->ds > 0 && s->wl > 0 && s->r > 0.5 * s->h &&
          s->w / s->ds <= 5000 && s->h / s->step <= 1000 && fabs(s->ax_deg) < 80 && fabs(s->ay_deg) < 80)) {
        fprintf(stderr, "rcal grind: surface sizes must be positive, r > h/2, slopes < 80 deg, "
                        "at most 5000 points per line and 1000 lines\n");
        return -1;
    }
    return 0;
}

/* ---- path -------------------------------------------------------------- */

typedef struct {
    double p[3];      /* programmed flange point */
    double R[9];      /* programmed flange orientation */
    double q_nom[RC_NJ];
    double dev[3];    /* deviation: uncompensated, compensated (calibrated), compensated (truth) */
    int flag[3];      /* compensation status per case (0 ok) */
} path_pt;

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

static size_t make_path(path_pt **out, const surface *s, size_t *nx_out, size_t *ny_out)
{
    const size_t nx = (size_t)floor(s->w / s->ds + 1e-9) + 1;
    const size_t ny = (size_t)floor(s->h / s->step + 1e-9) + 1;
    path_pt *p = calloc(nx * ny, sizeof *p);
    if (!p)
        return 0;
    size_t k = 0;
    for (size_t j = 0; j < ny; ++j) {
        const double y = s->cy - 0.5 * s->h + (double)j * s->step;
        for (size_t i = 0; i < nx; ++i) {
            const size_t ii = (j % 2 == 0) ? i : nx - 1 - i;
            const double x = s->cx - 0.5 * s->w + (double)ii * s->ds;
            double n[3];
            p[k].p[0] = x;
            p[k].p[1] = y;
            p[k].p[2] = surf_z(s, x, y);
            surf_normal(n, s, x, y);
            tool_frame(p[k].R, n);
            ++k;
        }
    }
    *out = p;
    *nx_out = nx;
    *ny_out = ny;
    return k;
}

/* Nominal IK of the whole path; the first point from a few seeds. */
static int path_ik(path_pt *pts, size_t n, const rc_model *nom)
{
    rc_comp_config cfg;
    memset(&cfg, 0, sizeof cfg);
    cfg.max_iter = 200;
    cfg.tol_mm = 1e-7;
    cfg.tol_rad = 1e-10;
    const double q1 = atan2(pts[0].p[1], pts[0].p[0]);
    static const double q2s[] = {0.3, 0.0, 0.6, -0.3}, q3s[] = {0.3, 0.0, 0.8}, q5s[] = {1.2, 0.8, 1.6};
    int ok = 0;
    for (size_t a = 0; a < 4 && !ok; ++a)
        for (size_t b = 0; b < 3 && !ok; ++b)
            for (size_t c = 0; c < 3 && !ok; ++c) {
                const double seed[RC_NJ] = {q1, q2s[a], q3s[b], 0.0, q5s[c], q1};
                rc_comp_result res;
                if (rc_comp_pose(pts[0].q_nom, &res, nom, pts[0].p, pts[0].R, seed, &cfg) == RC_OK &&
                    res.exit == RC_COMP_CONVERGED && pts[0].q_nom[4] > 0.2)
                    ok = 1;
            }
    if (!ok) {
        fprintf(stderr, "rcal grind: the nominal robot cannot reach the path start (%.1f, %.1f, %.1f) mm with the "
                        "tool along the surface normal; move the patch (cx, cy, z0)\n",
                pts[0].p[0], pts[0].p[1], pts[0].p[2]);
        return -1;
    }
    cfg.max_dev_rad = 0.5; /* successive points are close: no configuration jumps */
    for (size_t k = 1; k < n; ++k) {
        rc_comp_result res;
        if (rc_comp_pose(pts[k].q_nom, &res, nom, pts[k].p, pts[k].R, pts[k - 1].q_nom, &cfg) != RC_OK ||
            res.exit != RC_COMP_CONVERGED) {
            fprintf(stderr, "rcal grind: the nominal robot cannot follow the path at point %zu (%.1f, %.1f, %.1f) mm "
                            "(%s); make the patch smaller or move it\n",
                    k, pts[k].p[0], pts[k].p[1], pts[k].p[2], rc_comp_exit_str(res.exit));
            return -1;
        }
    }
    return 0;
}

/* ---- frame alignment --------------------------------------------------- */

/* Rotation about the base z axis and shift along it that best map cal's
 * flange points onto truth's (2000 random poses in the joint limits). */
static void align_base(double *phi_rad, double *dz_mm, const rc_model *cal, const rc_model *truth)
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

/* ---- statistics -------------------------------------------------------- */

typedef struct {
    double mean, sd, max, rms;
    size_t n_flag;
} dev_stats;

static dev_stats stats_of(const path_pt *p, size_t n, int c)
{
    dev_stats s = {0, 0, 0, 0, 0};
    for (size_t k = 0; k < n; ++k) {
        s.mean += p[k].dev[c];
        s.rms += p[k].dev[c] * p[k].dev[c];
        if (p[k].dev[c] > s.max)
            s.max = p[k].dev[c];
        if (p[k].flag[c])
            s.n_flag++;
    }
    s.mean /= (double)n;
    for (size_t k = 0; k < n; ++k)
        s.sd += (p[k].dev[c] - s.mean) * (p[k].dev[c] - s.mean);
    s.sd = n > 1 ? sqrt(s.sd / (double)(n - 1)) : 0.0;
    s.rms = sqrt(s.rms / (double)n);
    return s;
}

/* ---- SVG: path coloured by deviation ----------------------------------- */

/* A perceptually ordered colour map (viridis, 5 stops), t in [0, 1]. */
static void colour(char out[8], double t)
{
    static const double stops[5][3] = {
        {68, 1, 84}, {59, 82, 139}, {33, 145, 140}, {94, 201, 98}, {253, 231, 37}};
    t = t < 0 ? 0 : (t > 1 ? 1 : t);
    const double u = t * 4.0;
    int i = (int)floor(u);
    if (i > 3)
        i = 3;
    const double f = u - i;
    int rgb[3];
    for (int c = 0; c < 3; ++c)
        rgb[c] = (int)lround(stops[i][c] + f * (stops[i + 1][c] - stops[i][c]));
    snprintf(out, 8, "#%02x%02x%02x", rgb[0], rgb[1], rgb[2]);
}

static void svg_panel(FILE *f, const path_pt *p, size_t n, int c, const surface *s, double ox, double oy,
                      double pw, double ph, const char *title, const char *const names[5], const size_t idx[5])
{
    double vmax = 0.0;
    for (size_t k = 0; k < n; ++k)
        vmax = fmax(vmax, p[k].dev[c]);
    if (!(vmax > 0.0))
        vmax = 1e-9;
    const double sc = fmin(pw / s->w, ph / fmax(s->h, 1e-9));
    const double cx = ox + 0.5 * pw, cy = oy + 0.5 * ph;
#define PX(x) (cx + ((x) - s->cx) * sc)
#define PY(y) (cy - ((y) - s->cy) * sc)
    fprintf(f, "<text x=\"%.1f\" y=\"%.1f\" font-size=\"15\" text-anchor=\"middle\">%s</text>\n", ox + 0.5 * pw,
            oy - 28, title);
    fprintf(f, "<rect x=\"%.1f\" y=\"%.1f\" width=\"%.1f\" height=\"%.1f\" fill=\"#f4f4f4\" stroke=\"#999\"/>\n",
            PX(s->cx - 0.5 * s->w) - 6, PY(s->cy + 0.5 * s->h) - 6, s->w * sc + 12, s->h * sc + 12);
    for (size_t k = 0; k + 1 < n; ++k) {
        char col[8];
        colour(col, 0.5 * (p[k].dev[c] + p[k + 1].dev[c]) / vmax);
        fprintf(f, "<line x1=\"%.2f\" y1=\"%.2f\" x2=\"%.2f\" y2=\"%.2f\" stroke=\"%s\" stroke-width=\"4\" "
                   "stroke-linecap=\"round\"/>\n",
                PX(p[k].p[0]), PY(p[k].p[1]), PX(p[k + 1].p[0]), PY(p[k + 1].p[1]), col);
    }
    for (int m = 0; m < 5; ++m) {
        const path_pt *q = &p[idx[m]];
        fprintf(f, "<circle cx=\"%.2f\" cy=\"%.2f\" r=\"5\" fill=\"none\" stroke=\"#d62728\" stroke-width=\"2\"/>\n",
                PX(q->p[0]), PY(q->p[1]));
        const int right = q->p[0] > s->cx + 1e-9, below = q->p[1] < s->cy - 1e-9;
        fprintf(f, "<text x=\"%.2f\" y=\"%.2f\" font-size=\"12\" fill=\"#d62728\" text-anchor=\"%s\" "
                   "font-weight=\"bold\">%s %.3f</text>\n",
                PX(q->p[0]) + (right ? -9 : 9), PY(q->p[1]) + (below ? 20 : -9), right ? "end" : "start", names[m],
                q->dev[c]);
    }
    /* colour bar */
    const double bx = ox + pw + 30, by = oy, bh = ph;
    for (int i = 0; i < 50; ++i) {
        char col[8];
        colour(col, (i + 0.5) / 50.0);
        fprintf(f, "<rect x=\"%.1f\" y=\"%.2f\" width=\"14\" height=\"%.2f\" fill=\"%s\"/>\n", bx,
                by + bh - (i + 1) * bh / 50.0, bh / 50.0 + 0.3, col);
    }
    fprintf(f, "<rect x=\"%.1f\" y=\"%.1f\" width=\"14\" height=\"%.1f\" fill=\"none\" stroke=\"#333\"/>\n", bx, by, bh);
    for (int i = 0; i <= 4; ++i)
        fprintf(f, "<text x=\"%.1f\" y=\"%.1f\" font-size=\"11\">%.3g</text>\n", bx + 18, by + bh - i * bh / 4.0 + 4,
                vmax * i / 4.0);
    fprintf(f, "<text x=\"%.1f\" y=\"%.1f\" font-size=\"11\">mm</text>\n", bx, by - 10);
    /* axes: x and y ticks at the patch edges */
    fprintf(f, "<text x=\"%.1f\" y=\"%.1f\" font-size=\"11\" text-anchor=\"middle\">x = %.0f</text>\n",
            PX(s->cx - 0.5 * s->w), PY(s->cy - 0.5 * s->h) + 42, s->cx - 0.5 * s->w);
    fprintf(f, "<text x=\"%.1f\" y=\"%.1f\" font-size=\"11\" text-anchor=\"middle\">x = %.0f mm</text>\n",
            PX(s->cx + 0.5 * s->w), PY(s->cy - 0.5 * s->h) + 42, s->cx + 0.5 * s->w);
    fprintf(f, "<text x=\"%.1f\" y=\"%.1f\" font-size=\"11\" text-anchor=\"end\">y = %.0f</text>\n",
            PX(s->cx - 0.5 * s->w) - 10, PY(s->cy - 0.5 * s->h) + 4, s->cy - 0.5 * s->h);
    fprintf(f, "<text x=\"%.1f\" y=\"%.1f\" font-size=\"11\" text-anchor=\"end\">y = %.0f</text>\n",
            PX(s->cx - 0.5 * s->w) - 10, PY(s->cy + 0.5 * s->h) + 4, s->cy + 0.5 * s->h);
#undef PX
#undef PY
}

static int write_path_svg(const char *path, const path_pt *p, size_t n, const surface *s, const char *const names[5],
                          const size_t idx[5], const char *subtitle)
{
    FILE *f = fopen(path, "w");
    if (!f)
        return -1;
    const double pw = 420, ph = fmax(120.0, fmin(420.0, 420.0 * s->h / s->w)), W = 2 * pw + 360, H = ph + 150;
    fprintf(f, "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
               "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%.0f\" height=\"%.0f\" viewBox=\"0 0 %.0f %.0f\" "
               "font-family=\"sans-serif\">\n<rect width=\"100%%\" height=\"100%%\" fill=\"white\"/>\n",
            W, H, W, H);
    fprintf(f, "<text x=\"%.1f\" y=\"22\" font-size=\"16\" text-anchor=\"middle\">Grinding path, top view: deviation of "
               "the true flange path from the programmed one</text>\n",
            W / 2);
    fprintf(f, "<text x=\"%.1f\" y=\"40\" font-size=\"12\" text-anchor=\"middle\" fill=\"#555\">%s</text>\n", W / 2,
            subtitle);
    svg_panel(f, p, n, 0, s, 90, 95, pw, ph, "uncompensated", names, idx);
    svg_panel(f, p, n, 1, s, 90 + pw + 180, 95, pw, ph, "compensated (calibrated model)", names, idx);
    fprintf(f, "</svg>\n");
    return fclose(f) == 0 ? 0 : -1;
}

/* ---- the command ------------------------------------------------------- */

int rcal_cmd_grind(int argc, char **argv)
{
    const char *model_path = NULL, *truth_path = NULL, *nominal_path = NULL, *spec = NULL, *plots = NULL;
    int json = 0, position_only = 0, align = 1;
    double max_dev_deg = 30.0;
    for (int i = 1; i < argc; ++i) {
        if (rcal_opt_double(argc, argv, &i, "--max-dev-deg", &max_dev_deg))
            continue;
        if (rcal_opt_str(argc, argv, &i, "--model", &model_path) ||
            rcal_opt_str(argc, argv, &i, "--truth", &truth_path) ||
            rcal_opt_str(argc, argv, &i, "--nominal", &nominal_path) ||
            rcal_opt_str(argc, argv, &i, "--surface", &spec) || rcal_opt_str(argc, argv, &i, "--plots", &plots))
            continue;
        if (strcmp(argv[i], "--json") == 0)
            json = 1;
        else if (strcmp(argv[i], "--position-only") == 0)
            position_only = 1;
        else if (strcmp(argv[i], "--no-align") == 0)
            align = 0;
        else if (strcmp(argv[i], "--help") == 0) {
            usage(stdout);
            return 0;
        } else
            return rcal_opt_unknown("grind", argv[i]);
    }
    if (!model_path)
        return rcal_opt_missing("grind", "--model");
    if (!truth_path)
        return rcal_opt_missing("grind", "--truth");
    surface s;
    if (surf_parse(&s, spec) != 0)
        return 2;
    if (!(max_dev_deg > 0.0 && max_dev_deg <= 180.0)) {
        fprintf(stderr, "rcal grind: --max-dev-deg must be within (0, 180]\n");
        return 2;
    }

    static rch_robot mrob, trob, nrob;
    rch_diag d;
    char msg[1024];
    if (rch_robot_load(&mrob, model_path, &d) != 0 || rch_robot_load(&trob, truth_path, &d) != 0 ||
        (nominal_path && rch_robot_load(&nrob, nominal_path, &d) != 0)) {
        fprintf(stderr, "rcal grind: %s\n", rch_diag_str(&d, msg, sizeof msg));
        return 1;
    }
    const rc_model *nom = nominal_path ? &nrob.model : &mrob.nominal;
    const rc_model *truth = &trob.model;
    rc_model cal = mrob.model;
    double phi = 0.0, dz = 0.0;
    if (align) {
        align_base(&phi, &dz, &cal, truth);
        cal.x[RC_P_THETA(0)] += phi;
        cal.x[RC_P_D(0)] += dz;
    }

    path_pt *pts = NULL;
    size_t nx = 0, ny = 0;
    const size_t n = make_path(&pts, &s, &nx, &ny);
    if (n == 0) {
        fprintf(stderr, "rcal grind: out of memory\n");
        return 1;
    }
    if (path_ik(pts, n, nom) != 0) {
        free(pts);
        return 1;
    }
    rc_comp_config cfg;
    memset(&cfg, 0, sizeof cfg);
    cfg.flags = position_only ? RC_COMP_FLAG_POSITION_ONLY : 0u;
    cfg.max_dev_rad = max_dev_deg * DEG;
    cfg.max_iter = 50;
    rc_comp_stream st_cal, st_true;
    rc_comp_stream_init(&st_cal, &cal, nom, &cfg);
    rc_comp_stream_init(&st_true, truth, nom, &cfg);
    size_t n_orient_best_effort = 0;
    for (size_t k = 0; k < n; ++k) {
        double qc[RC_NJ], pt[3];
        rc_comp_result res;
        rc_fk(pt, NULL, truth, pts[k].q_nom);
        pts[k].dev[0] = sqrt((pt[0] - pts[k].p[0]) * (pt[0] - pts[k].p[0]) +
                             (pt[1] - pts[k].p[1]) * (pt[1] - pts[k].p[1]) + (pt[2] - pts[k].p[2]) * (pt[2] - pts[k].p[2]));
        for (int c = 1; c <= 2; ++c) {
            rc_status stc = rc_comp_stream_step(c == 1 ? &st_cal : &st_true, qc, &res, pts[k].q_nom);
            pts[k].flag[c] = stc != RC_OK;
            if (stc == RC_OK && res.exit == RC_COMP_POSITION_ONLY && c == 1)
                ++n_orient_best_effort;
            rc_fk(pt, NULL, truth, qc);
            pts[k].dev[c] = sqrt((pt[0] - pts[k].p[0]) * (pt[0] - pts[k].p[0]) +
                                 (pt[1] - pts[k].p[1]) * (pt[1] - pts[k].p[1]) +
                                 (pt[2] - pts[k].p[2]) * (pt[2] - pts[k].p[2]));
        }
    }
    /* five named points: the patch corners and the centre */
    static const char *const names[5] = {"P1", "P2", "P3", "P4", "P5"};
    static const char *const where[5] = {"corner x-, y- (path start)", "corner x+, y-", "centre",
                                         "corner x-, y+", "corner x+, y+"};
    size_t idx[5];
    {
        const double tx[5] = {s.cx - 0.5 * s.w, s.cx + 0.5 * s.w, s.cx, s.cx - 0.5 * s.w, s.cx + 0.5 * s.w};
        const double ty[5] = {s.cy - 0.5 * s.h, s.cy - 0.5 * s.h, s.cy, s.cy + 0.5 * s.h, s.cy + 0.5 * s.h};
        for (int m = 0; m < 5; ++m) {
            double best = HUGE_VAL;
            for (size_t k = 0; k < n; ++k) {
                const double e = (pts[k].p[0] - tx[m]) * (pts[k].p[0] - tx[m]) + (pts[k].p[1] - ty[m]) * (pts[k].p[1] - ty[m]);
                if (e < best) {
                    best = e;
                    idx[m] = k;
                }
            }
        }
    }
    const dev_stats su = stats_of(pts, n, 0), sc = stats_of(pts, n, 1), stt = stats_of(pts, n, 2);
    static const char *const case_names[3] = {"uncompensated", "compensated (calibrated model)",
                                              "compensated (true model, floor)"};
    const dev_stats *ss[3] = {&su, &sc, &stt};
    char spec_buf[160];
    snprintf(spec_buf, sizeof spec_buf, "%s, centre (%.0f, %.0f, %.0f) mm, %.0f x %.0f mm, line step %.1f mm, "
                                        "point step %.1f mm",
             surf_names[s.kind], s.cx, s.cy, s.z0, s.w, s.h, s.step, s.ds);
    if (json) {
        printf("{\"surface\": \"%s\", \"points\": %zu, \"lines\": %zu, \"mode\": \"%s\", \"align\": {\"on\": %s, "
               "\"heading_deg\": %.6f, \"height_mm\": %.6f}, \"cases\": {",
               surf_names[s.kind], n, ny, position_only ? "position" : "pose", align ? "true" : "false", phi / DEG, dz);
        static const char *const keys[3] = {"uncompensated", "compensated_calibrated", "compensated_true"};
        for (int c = 0; c < 3; ++c) {
            printf("%s\"%s\": {\"mean_mm\": %.6f, \"sd_mm\": %.6f, \"max_mm\": %.6f, \"rms_mm\": %.6f, "
                   "\"not_converged\": %zu, \"named\": [",
                   c ? ", " : "", keys[c], ss[c]->mean, ss[c]->sd, ss[c]->max, ss[c]->rms, ss[c]->n_flag);
            for (int m = 0; m < 5; ++m)
                printf("%s%.6f", m ? ", " : "", pts[idx[m]].dev[c]);
            printf("]}");
        }
        printf("}}\n");
    } else {
        printf("rcal grind: %s\n  %zu path points on %zu raster lines; compensation: %s\n", spec_buf, n, ny,
               position_only ? "flange position" : "flange pose (position first)");
        printf("  calibrated model %s, true robot %s\n", model_path, truth_path);
        if (align)
            printf("  base heading and height of the calibrated model taken from the truth: %+.4f deg about z, "
                   "%+.4f mm along z\n",
                   phi / DEG, dz);
        printf("\ndeviation of the true flange path from the programmed path (mm)\n");
        printf("  %-34s %9s %9s %9s", "", "mean", "SD", "max");
        for (int m = 0; m < 5; ++m)
            printf(" %8s", names[m]);
        printf("\n");
        for (int c = 0; c < 3; ++c) {
            printf("  %-34s %9.4f %9.4f %9.4f", case_names[c], ss[c]->mean, ss[c]->sd, ss[c]->max);
            for (int m = 0; m < 5; ++m)
                printf(" %8.4f", pts[idx[m]].dev[c]);
            printf("\n");
        }
        printf("  named points:");
        for (int m = 0; m < 5; ++m)
            printf(" %s = %s (%.0f, %.0f, %.1f)%s", names[m], where[m], pts[idx[m]].p[0], pts[idx[m]].p[1],
                   pts[idx[m]].p[2], m < 4 ? ";" : "\n");
        if (su.mean > 0)
            printf("  compensation with the calibrated model removes %.1f%% of the mean deviation\n",
                   100.0 * (1.0 - sc.mean / su.mean));
        if (sc.n_flag || stt.n_flag)
            printf("  warning: %zu / %zu points not compensated (flagged)\n", sc.n_flag, stt.n_flag);
        if (n_orient_best_effort)
            printf("  note: %zu points with the orientation best effort (position matched): the calibrated model's "
                   "orientation differs beyond the correction bound; --position-only avoids the wrist motion\n",
                   n_orient_best_effort);
    }
    int rc = 0;
    if (plots) {
        char path[1024];
        mkdir(plots, 0777);
        snprintf(path, sizeof path, "%s/grind_path.svg", plots);
        if (write_path_svg(path, pts, n, &s, names, idx, spec_buf) != 0) {
            fprintf(stderr, "rcal grind: cannot write %s: %s\n", path, strerror(errno));
            rc = 1;
        }
        double *x = malloc(n * sizeof *x), *y = malloc(n * sizeof *y);
        if (x && y) {
            rch_plot *pl = rch_plot_new("Deviation along the grinding path", "path point", "deviation (mm)");
            rch_plot_logy(pl, 1);
            for (int c = 0; c < 3; ++c) {
                for (size_t k = 0; k < n; ++k) {
                    x[k] = (double)k;
                    y[k] = fmax(pts[k].dev[c], 1e-7);
                }
                rch_plot_line(pl, case_names[c], x, y, n);
            }
            snprintf(path, sizeof path, "%s/grind_deviation.svg", plots);
            if (rch_plot_write_svg(pl, path) != 0) {
                fprintf(stderr, "rcal grind: cannot write %s\n", path);
                rc = 1;
            }
            rch_plot_free(pl);
        }
        free(x);
        free(y);
        snprintf(path, sizeof path, "%s/grind_points.csv", plots);
        FILE *f = fopen(path, "w");
        if (f) {
            fprintf(f, "k,x,y,z,q1,q2,q3,q4,q5,q6,dev_uncomp_mm,dev_comp_cal_mm,dev_comp_true_mm\n");
            for (size_t k = 0; k < n; ++k) {
                fprintf(f, "%zu,%.4f,%.4f,%.4f", k, pts[k].p[0], pts[k].p[1], pts[k].p[2]);
                for (int i = 0; i < RC_NJ; ++i)
                    fprintf(f, ",%.6f", pts[k].q_nom[i] / DEG);
                fprintf(f, ",%.6f,%.6f,%.6f\n", pts[k].dev[0], pts[k].dev[1], pts[k].dev[2]);
            }
            if (fclose(f) != 0)
                rc = 1;
        } else {
            fprintf(stderr, "rcal grind: cannot write %s: %s\n", path, strerror(errno));
            rc = 1;
        }
        if (!json && rc == 0)
            printf("  plots: %s/grind_path.svg, %s/grind_deviation.svg; points: %s/grind_points.csv\n", plots, plots,
                   plots);
    }
    free(pts);
    return rc;
}
