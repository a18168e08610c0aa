/* SPDX-License-Identifier: MIT */
/* rch_grind.h - the grinding-path experiment (the paper's Table 8): the
 * algorithm behind `rcal grind`.
 *
 * A workpiece surface z = f(x, y) (rch_surface: built-in shapes), a raster
 * grinding path on it (lines along x, boustrophedon), the tool (flange) axis
 * along the inward surface normal. Nominal joint targets by inverse
 * kinematics on the nominal model (rc_comp_pose, each point seeded with the
 * previous one). Then the flange path the true robot follows:
 *   - uncompensated:            FK_true(q_nom)
 *   - compensated, calibrated:  FK_true(comp(q_nom; calibrated model))
 *   - compensated, true model:  FK_true(comp(q_nom; true model))   (the floor)
 * and the deviation from the programmed path point at every point: mean,
 * SD, max, rms, and five named points (the patch's corners and centre).
 *
 * Frames: cable lengths cannot see the base heading (a rotation about the
 * joint-1 axis) or the base height (a shift along it); a real cell takes
 * those from the workpiece frame. With cfg.align they are taken from the
 * truth (rch_grind_align_base): theta1 and d1 of the calibrated model get
 * the rotation and shift that best map its flange points onto the truth's
 * over 2000 random poses (closed form). Because that alignment uses the
 * truth, the result also says what it alone is worth (the nominal model
 * aligned the same way, compensated) and whether the "calibrated" model is
 * the nominal one (issue 12: a nominal model must not be credited with what
 * the alignment removes).
 *
 * Depends on: rc_comp, rc_model, rc_rand (core); rch_stats, rch_plot, rch_jw,
 * rch_robot (host, model files of the Table 8 form).
 * Memory: rch_grind_run allocates the path inside the result;
 * rch_grind_free releases it (also after a failed run). Errors: 0, or -1
 * with d set (unreachable path, out of memory).
 */
#ifndef RCH_GRIND_H
#define RCH_GRIND_H

#include <stddef.h>
#include <stdio.h>

#include "rc_model.h"
#include "rch_diag.h"
#include "rch_stats.h"
#include "rch_plot.h"

/* ---- surfaces ---- */

typedef enum rch_surface_kind {
    RCH_SURF_PLANE = 0,    /* z = z0 */
    RCH_SURF_TILTED = 1,   /* z = z0 + tan(ax) (x - cx) + tan(ay) (y - cy) */
    RCH_SURF_CYLINDER = 2, /* z = z0 + sqrt(r^2 - (y - cy)^2) - r, axis along x */
    RCH_SURF_SADDLE = 3,   /* z = z0 + k (x - cx)(y - cy) / (w/2 h/2) */
    RCH_SURF_SINE = 4      /* z = z0 + amp sin(2 pi (x - cx)/wl) cos(2 pi (y - cy)/wl) */
} rch_surface_kind;

typedef struct rch_surface {
    rch_surface_kind kind;
    double cx, cy, z0;      /* patch centre (mm) */
    double w, h;            /* patch size along x and y (mm) */
    double step, ds;        /* raster line spacing, point spacing (mm) */
    double ax_deg, ay_deg;  /* tilted: slopes */
    double r;               /* cylinder radius (mm) */
    double k;               /* saddle height (mm) */
    double amp, wl;         /* sine amplitude and wavelength (mm) */
} rch_surface;

/* The most path points a surface may give (memory about 36 MB, a few seconds). */
#define RCH_GRIND_MAX_POINTS 200000

/* tilted, centre (400, 0, 300), 200 x 120, step 10, ds 5, ax 15, r 150, k 20, amp 10, wl 100. */
void rch_surface_defaults(rch_surface *s);
/* "NAME[:key=value,...]" (keys cx cy z0 w h step ds ax ay r k amp wl) over
 * the defaults; NULL: the defaults. Sizes must be positive, r > h/2, slopes
 * below 80 deg, at most 5000 points per line, 1000 lines and
 * RCH_GRIND_MAX_POINTS in all. 0 or -1 with d. */
int rch_surface_parse(rch_surface *s, const char *spec, rch_diag *d);
const char *rch_surface_name(rch_surface_kind kind);
double rch_surface_z(const rch_surface *s, double x_mm, double y_mm);

/* ---- the experiment ---- */

enum {
    RCH_GRIND_UNCOMP = 0,    /* FK_true(q_nom) */
    RCH_GRIND_COMP_CAL = 1,  /* compensated with the calibrated model */
    RCH_GRIND_COMP_TRUE = 2, /* compensated with the true model (floor) */
    RCH_GRIND_CASES = 3
};

typedef struct rch_grind_config {
    rch_surface surface;
    int position_only;  /* 1: compensate the flange position only */
    int align;          /* 1: base heading and height of the calibrated model from the truth */
    double max_dev_rad; /* largest joint correction, > 0 */
} rch_grind_config;

/* Default surface, full pose, align on, 30 deg. */
void rch_grind_defaults(rch_grind_config *cfg);

typedef struct rch_grind_point {
    double p_mm[3];                     /* programmed flange point */
    double R[9];                        /* programmed flange orientation, row-major, columns = tool axes */
    double q_nom_rad[RC_NJ];            /* nominal joint target */
    double dev_mm[RCH_GRIND_CASES];     /* deviation of the true flange from p_mm */
    double dev_n_mm[RCH_GRIND_CASES];   /* its signed part along the outward surface normal (+: above the surface,
                                           the tool short of the programmed depth; -: into the workpiece) */
    int flag[RCH_GRIND_CASES];          /* compensation failed (0 ok) */
} rch_grind_point;

typedef struct rch_grind_case {
    rch_stats dev_mm;  /* over the path */
    size_t n_flag;    /* points not compensated */
} rch_grind_case;

typedef struct rch_grind_result {
    rch_grind_point *pts;  /* (n) in path order */
    size_t n, nx, ny;      /* points, points per line, lines */
    double heading_rad, height_mm; /* base alignment applied (0 without align) */
    rch_grind_case cases[RCH_GRIND_CASES];
    size_t named[5];       /* path indices of P1..P5 (corners x-y-, x+y-, centre, x-y+, x+y+) */
    size_t n_orient_best_effort; /* calibrated compensation matched the position only */
    rch_stats align_only_mm; /* with align: deviation when compensating with the nominal model aligned to the
                               truth the same way (what the alignment alone is worth); empty without align */
    int model_is_nominal;   /* the calibrated model's geometry equals the nominal table */
} rch_grind_result;

/* cal: calibrated model, truth: the true robot, nom: the nominal model the
 * path is programmed with. 0, or -1 with d set. */
int rch_grind_run(rch_grind_result *res, const rch_grind_config *cfg, const rc_model *cal, const rc_model *truth,
                  const rc_model *nom, rch_diag *d);
void rch_grind_free(rch_grind_result *res);

/* Rotation about the base z axis and shift along it that best map cal's
 * flange points onto truth's (2000 random poses in truth's joint limits). */
void rch_grind_align_base(double *phi_rad, double *dz_mm, const rc_model *cal, const rc_model *truth);

/* "P1".."P5" and where they are. */
const char *rch_grind_point_name(int m);

void rch_grind_report(FILE *f, const rch_grind_result *res, const rch_grind_config *cfg, const char *model_name,
                      const char *truth_name);
/* One JSON object through rch_jw. 0, or -1 on a write error. */
int rch_grind_json(FILE *f, const rch_grind_result *res, const rch_grind_config *cfg, int argc, char **argv);

/* grind_path.svg (top view, segments coloured by deviation, uncompensated
 * and compensated side by side), grind_deviation.svg (deviation along the
 * path, log scale) and grind_points.csv (every point) into pd->dir (created
 * when missing; never over one of pd->inputs). 0, or -1 with d set. */
int rch_grind_plots(const rch_grind_result *res, const rch_grind_config *cfg, const rch_plot_dir *pd, rch_diag *d);

/* ---- the paper's Table 8 form: several models on one path ---- */

/* The paper (Table 8) lists five path points per model with signed
 * deviations, and their Mean and SD (n - 1). It does not say which five
 * points nor along which direction the sign is taken; we take P1..P5 above
 * (the patch's four corners and centre: spread over the patch, fixed before
 * any result) and the deviation of the true flange along the outward
 * surface normal at the point (dev_n_mm), the direction that sets the
 * removal depth in grinding. */
#define RCH_GRIND_MAX_MODELS 16

typedef struct rch_grind_row {
    char name[64];
    double p_mm[5];        /* signed normal deviation at P1..P5 */
    double mean_mm, sd_mm; /* over the five; SD with n - 1 */
    rch_stats path_mm;     /* |deviation| (3-D) over the whole path */
    rch_stats path_n_mm;   /* signed normal deviation over the whole path */
    size_t n_flag;         /* points not compensated */
} rch_grind_row;

typedef struct rch_grind_table {
    size_t n_rows;         /* BC, the models, the true-model floor */
    size_t n_points;
    double heading_rad[RCH_GRIND_MAX_MODELS], height_mm[RCH_GRIND_MAX_MODELS]; /* alignment applied per model */
    rch_grind_row row[RCH_GRIND_MAX_MODELS + 2];
    double named_p_mm[5][3];
} rch_grind_table;

/* Row 0 "BC": the uncompensated path (FK_true(q_nom), before compensation);
 * then one row per model (names[k], compensated with models[k], n_models
 * 1..RCH_GRIND_MAX_MODELS); last "true model": compensated with the truth
 * (the floor). 0, or -1 with d set. */
int rch_grind_table8(rch_grind_table *t, const rch_grind_config *cfg, const rc_model *const *models,
                     const char *const *names, size_t n_models, const rc_model *truth, const rc_model *nom,
                     rch_diag *d);
/* The same on model files (rch_robot_load): paths (n) labelled names, the
 * true robot truth_path, the nominal the path is programmed with
 * nominal_path (NULL: the first model's "nominal"). 0, or -1 with d set. */
int rch_grind_table8_files(rch_grind_table *t, const rch_grind_config *cfg, const char *const *paths,
                           const char *const *names, size_t n, const char *truth_path, const char *nominal_path,
                           rch_diag *d);
void rch_grind_table8_report(FILE *f, const rch_grind_table *t, const rch_grind_config *cfg, const char *truth_name);
/* One JSON object through rch_jw ("rcal-grind-table8/1"; argc, argv: the
 * command line for its header). 0, or -1 on a write error. */
int rch_grind_table8_json(FILE *f, const rch_grind_table *t, const rch_grind_config *cfg, int argc, char **argv);

#endif
