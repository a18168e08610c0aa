/* SPDX-License-Identifier: MIT */
/* rch_diagnose_plot.c - the residual plots of `rcal diagnose` (SVG via rch_plot). */
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "rch_diagnose.h"
#include "rch_plot.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

/* Where the plots go: the directory (written through rch_plot_save, with
 * the data of each plot as CSV beside it), the list of written files. */
typedef struct plot_out {
    rch_plot_dir pd;
    char *paths;
    size_t len;
} plot_out;

static int save(rch_plot *p, const plot_out *o, const char *file, rch_diag *d)
{
    if (rch_plot_save(p, &o->pd, file, d) != 0)
        return -1;
    const size_t used = strlen(o->paths), n = strlen(file) - 4; /* without .svg */
    if (used < o->len)
        snprintf(o->paths + used, o->len - used, "  %s/%s (data: %.*s.csv)\n", o->pd.dir, file, (int)n, file);
    return 0;
}

/* The x label of a plot over the set-up groups: where their numbers come
 * from (the same numbers in every plot and in the per-sample CSVs). */
#define GROUP_LABEL "set-up group (number as in the data's group column, else 0.. in file order)"

/* Explanatory variable of structure test k for sample i (x of the plot). */
static double test_x(const rch_diagnose_result *r, unsigned k, size_t i, const char **label)
{
    const rc_sample *s = &r->s[i];
    const char *name = r->before[k].name;
    if (name[0] == 'q' && name[1] >= '1' && name[1] <= '6') {
        *label = "joint angle (deg)";
        return s->q_rad[name[1] - '1'] * 180.0 / M_PI;
    }
    if (strncmp(name, "gravity lever j", 15) == 0) {
        double ref[4][4];
        for (unsigned a = 0; a < 4; ++a)
            for (unsigned b = 0; b < 4; ++b)
                ref[a][b] = r->geo.x[4 * a + b];
        *label = "gravity lever (m)";
        return rc_gravity_lever_m((const double(*)[4])ref, name[15] == '2' ? 1u : 2u, s->q_rad);
    }
    if (strcmp(name, "cable length") == 0) {
        *label = "cable length (mm)";
        return s->value;
    }
    if (strcmp(name, "cable direction") == 0) {
        double p[3], u[3], nu = 0.0;
        rc_fk(p, NULL, &r->geo, s->q_rad);
        for (int c = 0; c < 3; ++c) {
            u[c] = p[c] - r->geo.x[RC_P_ENC + c];
            nu += u[c] * u[c];
        }
        *label = "cable direction, z component";
        return u[2] / sqrt(nu);
    }
    if (strncmp(name, "groups", 6) == 0) {
        *label = "set-up group (number)";
        return s->group;
    }
    *label = "acquisition order (0..1)";
    return s->t;
}

/* 1. Held-out residuals in acquisition order, before and after, within the
 * noise floor. x: (n) scratch. */
static int plot_order(const rch_diagnose_result *r, const plot_out *o, double *x, rch_diag *d)
{
    const size_t n = r->n;
    char title[256];
    for (size_t i = 0; i < n; ++i)
        x[i] = (double)i;
    rch_plot *p = rch_plot_new("Held-out length residual of each sample, in acquisition order",
                               "sample (acquisition order, from 0)", "model - measured cable length (mm)");
    snprintf(title, sizeof title, "RMS: geometry only %.3f mm, %s %.3f mm; noise floor %.3f mm (verdict: %s)",
             r->rmse_before_mm, r->n_chosen ? "with the chosen effects" : "nothing added,", r->rmse_after_mm,
             r->noise_floor_mm, r->effect);
    rch_plot_subtitle(p, title);
    rch_plot_scatter(p, "geometry only", x, r->res_before_mm, n);
    if (r->n_chosen)
        rch_plot_scatter(p, "with the chosen effects", x, r->res_after_mm, n);
    const double ends[2] = {0.0, n ? (double)(n - 1) : 0.0}, fh[2] = {r->noise_floor_mm, r->noise_floor_mm},
                 fl[2] = {-r->noise_floor_mm, -r->noise_floor_mm};
    rch_plot_line(p, "+ noise floor", ends, fh, 2); /* level lines: their two ends */
    rch_plot_line(p, "- noise floor", ends, fl, 2);
    /* the nuisance found: each length jump a vertical line between the last
     * sample before it and the first after (acquisition order) */
    if (r->jumps.n_jumps > 0 && n > 0) {
        double lo = r->res_before_mm[0], hi = r->res_before_mm[0];
        for (size_t i = 1; i < n; ++i) {
            lo = r->res_before_mm[i] < lo ? r->res_before_mm[i] : lo;
            hi = r->res_before_mm[i] > hi ? r->res_before_mm[i] : hi;
        }
        for (unsigned k = 0; k < r->jumps.n_jumps; ++k) {
            char lab[96];
            const double xv[2] = {(double)r->jumps.at[k] - 0.5, (double)r->jumps.at[k] - 0.5}, yv[2] = {lo, hi};
            snprintf(lab, sizeof lab, "length jump %u: %+.3f mm", k + 1, r->jumps.size_mm[k]);
            rch_plot_line(p, lab, xv, yv, 2);
        }
    }
    rch_plot_size(p, 1000, 500);
    return save(p, o, "residuals_order.svg", d);
}

/* 2. Mean held-out residual per set-up group (when there are 2..n/2 groups). */
static int plot_groups(const rch_diagnose_result *r, const plot_out *o, rch_diag *d)
{
    const size_t n = r->n;
    if (!(r->n_groups >= 2 && r->n_groups <= n / 2))
        return 0;
    const unsigned G = r->n_groups;
    double *gb = calloc(G, sizeof *gb), *ga = calloc(G, sizeof *ga), *gx = calloc(G, sizeof *gx);
    size_t *cnt = calloc(G, sizeof *cnt);
    int rc = -1;
    if (!gb || !ga || !gx || !cnt) {
        rch_diag_set(d, "", 0, 0, "out of memory");
        goto done;
    }
    for (size_t i = 0; i < n; ++i) {
        gb[r->s[i].group] += r->res_before_mm[i];
        ga[r->s[i].group] += r->res_after_mm[i];
        cnt[r->s[i].group]++;
    }
    /* the groups as numbered in the samples (the file's group column, or
     * 0.. in file order when grouped by the wrist), as in residuals_structure;
     * groups with no sample (gaps in a given numbering) are left out */
    unsigned m = 0;
    for (unsigned g = 0; g < G; ++g)
        if (cnt[g]) {
            gx[m] = g;
            gb[m] = gb[g] / (double)cnt[g];
            ga[m] = ga[g] / (double)cnt[g];
            ++m;
        }
    rch_plot *p = rch_plot_new("Mean held-out length residual of each set-up group", GROUP_LABEL,
                               "mean of model - measured cable length (mm)");
    rch_plot_scatter(p, "geometry only", gx, gb, m);
    if (r->n_chosen)
        rch_plot_scatter(p, "with the chosen effects", gx, ga, m);
    rc = save(p, o, "group_means.svg", d);
done:
    free(gb);
    free(ga);
    free(gx);
    free(cnt);
    return rc;
}

/* 3. Held-out RMSE of each candidate of the first step. */
static int plot_candidates(const rch_diagnose_result *r, const plot_out *o, rch_diag *d)
{
    if (r->n_steps == 0)
        return 0;
    const rch_diagnose_step *st = &r->steps[0];
    const char *labels[RCH_DIAGNOSE_MAX_CAND];
    unsigned cat[RCH_DIAGNOSE_MAX_CAND];
    static const char *const cat_names[2] = {"not chosen", "chosen (significant held-out gain)"};
    double v[RCH_DIAGNOSE_MAX_CAND], cx[RCH_DIAGNOSE_MAX_CAND + 2], cy[RCH_DIAGNOSE_MAX_CAND + 2],
        fy[RCH_DIAGNOSE_MAX_CAND + 2];
    size_t m = 0;
    for (unsigned k = 0; k < st->n_cand; ++k)
        if (st->cand[k].tested) {
            labels[m] = st->cand[k].name;
            cat[m] = (int)k == st->chosen ? 1u : 0u;
            v[m++] = st->cand[k].rmse_cv_mm;
        }
    for (size_t k = 0; k < m + 2; ++k) {
        cx[k] = (double)k - 1.0;
        cy[k] = st->rmse_base_mm;
        fy[k] = r->noise_floor_mm;
    }
    rch_plot *p = rch_plot_new("Held-out RMS length error with each candidate effect added to the geometry",
                               "candidate effect", "held-out RMS length error (mm)");
    rch_plot_subtitle(p, "step 1 of the search; candidates that could not be tested are left out");
    rch_plot_bars(p, labels, v, NULL, m);
    rch_plot_bar_categories(p, cat, cat_names, 2);
    rch_plot_line(p, "geometry only", cx, cy, m + 2);
    rch_plot_line(p, "noise floor", cx, fy, m + 2);
    rch_plot_size(p, 1100, 500);
    return save(p, o, "candidates.svg", d);
}

/* 4. Residuals against the variable of the strongest structure test. x: (n). */
static int plot_structure(const rch_diagnose_result *r, const plot_out *o, double *x, rch_diag *d)
{
    unsigned best = 0;
    char title[256];
    for (unsigned k = 1; k < r->n_tests; ++k)
        if (r->before[k].p_value < r->before[best].p_value)
            best = k;
    const char *label = "";
    for (size_t i = 0; i < r->n; ++i)
        x[i] = test_x(r, best, i, &label);
    char pbuf[32];
    if (strncmp(r->before[best].name, "groups", 6) == 0)
        label = GROUP_LABEL;
    snprintf(title, sizeof title, "Held-out length residual against %s", r->before[best].name);
    rch_plot *p = rch_plot_new(title, label, "model - measured cable length (mm)");
    snprintf(title, sizeof title, "the strongest structure of the residuals (geometry only): F test p %s%s",
             r->before[best].p_value < 1e-300 ? "" : "= ", rch_plot_fmt_p(pbuf, sizeof pbuf, r->before[best].p_value));
    rch_plot_subtitle(p, title);
    rch_plot_scatter(p, "geometry only", x, r->res_before_mm, r->n);
    if (r->n_chosen)
        rch_plot_scatter(p, "with the chosen effects", x, r->res_after_mm, r->n);
    return save(p, o, "residuals_structure.svg", d);
}

int rch_diagnose_plots(const rch_diagnose_result *r, const char *dir, const char *const *inputs, size_t n_inputs,
                       char *paths, size_t paths_len, rch_diag *d)
{
    const size_t n = r->n;
    double *x = malloc((n ? n : 1) * sizeof *x);
    const plot_out o = {{dir, inputs, n_inputs, NULL}, paths, paths_len};
    int rc = -1;
    if (paths_len)
        paths[0] = '\0';
    if (!x)
        rch_diag_set(d, "", 0, 0, "out of memory");
    else if (rch_plot_mkdir(dir) != 0)
        rch_diag_set(d, dir, 0, 0, "cannot create the directory: %s", strerror(errno));
    else if (plot_order(r, &o, x, d) == 0 && plot_groups(r, &o, d) == 0 && plot_candidates(r, &o, d) == 0 &&
             plot_structure(r, &o, x, d) == 0)
        rc = 0;
    free(x);
    return rc;
}
