/* SPDX-License-Identifier: MIT */
#include "rch_robot.h"

#include <strings.h>

#include "rch_urdf_robot.h"

#include <ctype.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rc_linalg.h"
#include "rch_cell_read.h"
#include "rch_data.h"
#include "rch_file.h"
#include "rch_json.h"
#include "rch_jw.h"
#include "rch_seen.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif
#define DEG (M_PI / 180.0)

/* ---- keys (issue 47: a misspelled key is refused, never skipped) ---- */

/* Edit distance of a and b (case-insensitive; each at most 63 bytes
 * counted, the rest ignored). */
static unsigned key_distance(const char *a, const char *b)
{
    unsigned row[64], la = (unsigned)(strlen(a) > 63 ? 63 : strlen(a)), lb = (unsigned)(strlen(b) > 63 ? 63 : strlen(b));
    for (unsigned j = 0; j <= lb; ++j)
        row[j] = j;
    for (unsigned i = 1; i <= la; ++i) {
        unsigned diag = row[0];
        row[0] = i;
        for (unsigned j = 1; j <= lb; ++j) {
            const unsigned up = row[j];
            const int same = tolower((unsigned char)a[i - 1]) == tolower((unsigned char)b[j - 1]);
            unsigned v = diag + (same ? 0u : 1u);
            if (up + 1 < v)
                v = up + 1;
            if (row[j - 1] + 1 < v)
                v = row[j - 1] + 1;
            row[j] = v;
            diag = up;
        }
    }
    return row[lb];
}

/* Every key of object o must be one of known (NULL-terminated): an unknown
 * one is refused at its key's line:col with the nearest known key when it
 * is near (at most half its length away), else the list. where names the
 * object ("the model file", "dh row 3"). 0, or -1 with d set. */
static int check_keys(const rch_json *o, const char *const *known, const char *where, const char *file, rch_diag *d)
{
    if (!o || o->type != RCH_JOBJ)
        return 0;
    for (size_t i = 0; i < o->n; ++i) {
        const char *k = o->keys[i];
        const char *best = NULL;
        unsigned best_d = ~0u;
        size_t m = 0;
        for (; known[m]; ++m) {
            if (strcmp(k, known[m]) == 0)
                break;
            const unsigned dist = key_distance(k, known[m]);
            if (dist < best_d) {
                best_d = dist;
                best = known[m];
            }
        }
        if (known[m])
            continue;
        const rch_json *v = o->items[i];
        const unsigned line = v->key_line ? v->key_line : v->line, col = v->key_line ? v->key_col : v->col;
        if (best && 2 * best_d <= (unsigned)strlen(best)) {
            rch_diag_set(d, file, line, col,
                         "unknown key \"%.60s\" in %s: did you mean %s? (a key rcal does not know is refused, "
                         "never skipped)", k, where, best);
        } else {
            char list[400] = "";
            for (size_t j = 0; known[j]; ++j) {
                const size_t at = strlen(list);
                snprintf(list + at, sizeof list - at, "%s%s", j ? ", " : "", known[j]);
            }
            rch_diag_set(d, file, line, col, "unknown key \"%.60s\" in %s (its keys: %s)", k, where, list);
        }
        return -1;
    }
    return 0;
}

static const char *const dh_keys[] = {"a_mm", "d_mm", "alpha_deg", "theta_deg", NULL};

static int want_num(double *v, const rch_json *j, const char *what, const char *file, rch_diag *d,
                    const rch_json *parent)
{
    if (!j) {
        rch_diag_set(d, file, parent->line, parent->col, "missing %s", what);
        return -1;
    }
    if (j->type != RCH_JNUM) {
        rch_diag_set(d, file, j->line, j->col, "%s must be a number", what);
        return -1;
    }
    *v = j->num;
    return 0;
}

/* The DH angles of a table (dh, already in rad) written in radians where
 * degrees are read (issue 47), checked before anything uses the model (so
 * that no data check blames the cable for it). A robot's twists and joint
 * offsets are multiples of 90 degrees (0, +-90, 180), a calibration moving
 * them by a fraction of a degree; in radians those are 0, +-1.5708 and
 * 3.1416. The rule, per column (alpha_deg, theta_deg) of the six rows: every
 * |value| at most RCH_ROBOT_RAD_BOUND (3.2) and at least one within
 * RCH_ROBOT_RAD_TOL (0.05) of pi/2 or pi. In degrees such a column would be
 * a robot whose twists (offsets) all lie within 3.2 deg of 0 while one is
 * 1.5-1.6 or 3.1-3.2 deg off it: no robot's, no calibration's. A table of
 * zeros (a planar test arm) is never refused. 0, or -1 with d set at the
 * value that shows it. */
#define RCH_ROBOT_RAD_BOUND 3.2
#define RCH_ROBOT_RAD_TOL 0.05
static int angles_in_degrees(double dh[RC_NJ][4], const rch_json *arr, const char *file, rch_diag *d)
{
    static const char *const keys[2] = {"alpha_deg", "theta_deg"};
    for (unsigned k = 2; k < 4; ++k) {
        int bounded = 1;
        unsigned sign_row = RC_NJ;
        for (unsigned i = 0; i < RC_NJ; ++i) {
            const double v = fabs(dh[i][k] / DEG);
            bounded &= v <= RCH_ROBOT_RAD_BOUND;
            if (sign_row == RC_NJ && (fabs(v - M_PI / 2) <= RCH_ROBOT_RAD_TOL || fabs(v - M_PI) <= RCH_ROBOT_RAD_TOL))
                sign_row = i;
        }
        if (!bounded || sign_row == RC_NJ)
            continue;
        const rch_json *at = rch_json_get(arr->items[sign_row], keys[k - 2]);
        rch_diag_set(d, file, at->line, at->col,
                     "dh[%u].%s = %g looks like radians: every %s of the table is within +-%g and this one is "
                     "%s in radians (a robot's %s are multiples of 90 degrees); rcal reads degrees (multiply by "
                     "180/pi)",
                     sign_row + 1, keys[k - 2], dh[sign_row][k] / DEG, keys[k - 2], RCH_ROBOT_RAD_BOUND,
                     fabs(fabs(dh[sign_row][k] / DEG) - M_PI / 2) <= RCH_ROBOT_RAD_TOL ? "pi/2" : "pi",
                     k == 2 ? "twists" : "joint offsets");
        return -1;
    }
    return 0;
}

static int read_dh(double dh[RC_NJ][4], const rch_json *arr, const char *file, rch_diag *d,
                   const rch_json *parent)
{
    static const char *const keys[4] = {"a_mm", "d_mm", "alpha_deg", "theta_deg"};
    if (!arr || arr->type != RCH_JARR || arr->n != RC_NJ) {
        const rch_json *at = arr ? arr : parent;
        rch_diag_set(d, file, at->line, at->col, "\"dh\" must be an array of 6 joint rows");
        return -1;
    }
    for (unsigned i = 0; i < RC_NJ; ++i) {
        const rch_json *row = arr->items[i];
        if (row->type != RCH_JOBJ) {
            rch_diag_set(d, file, row->line, row->col, "dh row %u must be an object", i + 1);
            return -1;
        }
        char where[32];
        snprintf(where, sizeof where, "dh row %u", i + 1);
        if (check_keys(row, dh_keys, where, file, d) != 0)
            return -1;
        for (unsigned k = 0; k < 4; ++k) {
            char what[64];
            snprintf(what, sizeof what, "dh[%u].%s", i + 1, keys[k]);
            if (want_num(&dh[i][k], rch_json_get(row, keys[k]), what, file, d, row) != 0)
                return -1;
            /* a link longer than 5 m is no industrial robot's: the model file is wrong */
            const double lim = k < 2 ? RCH_ROBOT_MAX_LINK_MM : 720.0;
            if (fabs(dh[i][k]) > lim) {
                const rch_json *at = rch_json_get(row, keys[k]);
                rch_diag_set(d, file, at->line, at->col,
                             "%s = %g is implausible for a robot model (|value| at most %g): check the model file",
                             what, dh[i][k], lim);
                return -1;
            }
            if (k >= 2)
                dh[i][k] *= DEG;
        }
    }
    return angles_in_degrees(dh, arr, file, d);
}

static int read_effects(rc_model *m, const rch_json *arr, const char *file, rch_diag *d)
{
    if (arr->type != RCH_JARR) {
        rch_diag_set(d, file, arr->line, arr->col, "\"effects\" must be an array");
        return -1;
    }
    for (size_t i = 0; i < arr->n; ++i) {
        const rch_json *e = arr->items[i];
        const rch_json *kind = rch_json_get(e, "kind"), *joint = rch_json_get(e, "joint"),
                       *outlet = rch_json_get(e, "outlet"), *params = rch_json_get(e, "params"),
                       *ref = rch_json_get(e, "ref_dh");
        if (e->type != RCH_JOBJ || !kind || kind->type != RCH_JSTR) {
            rch_diag_set(d, file, e->line, e->col, "effect %zu needs a \"kind\" string", i + 1);
            return -1;
        }
        static const char *const effect_keys[] = {"kind", "joint", "outlet", "params", "ref_dh", NULL};
        char where[32];
        snprintf(where, sizeof where, "effect %zu", i + 1);
        if (check_keys(e, effect_keys, where, file, d) != 0)
            return -1;
        const int k = rc_effect_by_name(kind->str);
        const rc_effect_desc *ds = k > 0 ? rc_effect_describe((unsigned)k) : NULL;
        if (ds == NULL) {
            rch_diag_set(d, file, kind->line, kind->col, "unknown effect kind \"%s\"", kind->str);
            return -1;
        }
        unsigned j = 0;
        if (ds->arg == RC_EFF_ARG_OUTLET) {
            if (!outlet || outlet->type != RCH_JNUM || outlet->num < 1 || outlet->num >= RC_MAX_OUTLETS ||
                outlet->num != floor(outlet->num)) {
                rch_diag_set(d, file, outlet ? outlet->line : e->line, outlet ? outlet->col : e->col,
                             "effect outlet needs \"outlet\": 1..%d", RC_MAX_OUTLETS - 1);
                return -1;
            }
            j = (unsigned)outlet->num;
        } else if (joint) {
            if (joint->type != RCH_JNUM || joint->num < 1 || joint->num > 6 || joint->num != floor(joint->num)) {
                rch_diag_set(d, file, joint->line, joint->col, "effect joint must be 1..6");
                return -1;
            }
            j = (unsigned)joint->num - 1;
        }
        if (!params || params->type != RCH_JARR || params->n == 0 || params->n > RC_MAX_PARAMS) {
            rch_diag_set(d, file, e->line, e->col, "effect %zu needs a non-empty \"params\" array", i + 1);
            return -1;
        }
        rc_status st = rc_model_add_effect(m, (rc_effect_kind)k, j, (unsigned)params->n);
        if (st != RC_OK) {
            rch_diag_set(d, file, e->line, e->col, "effect %zu (%s): %s", i + 1, kind->str, rc_strerror(st));
            return -1;
        }
        rc_effect *ef = &m->effects[m->n_effects - 1];
        if (ef->count != params->n) {
            rch_diag_set(d, file, params->line, params->col, "effect %s takes %u parameters, not %zu", kind->str,
                         (unsigned)ef->count, params->n);
            return -1;
        }
        for (size_t p = 0; p < params->n; ++p) {
            if (want_num(&m->x[ef->first + p], params->items[p], "effect parameter", file, d, params) != 0)
                return -1;
            const double lim = ds->limit;
            if (fabs(m->x[ef->first + p]) > lim) {
                rch_diag_set(d, file, params->items[p]->line, params->items[p]->col,
                             "effect %s: parameter %zu = %g is implausible (|value| at most %g %s): check the model "
                             "file",
                             kind->str, p + 1, m->x[ef->first + p], lim, ds->unit_text);
                return -1;
            }
        }
        if (ef->kind == RC_EFF_LENGTH_PERIODIC && !(fabs(m->x[ef->first + 2]) >= 1.0)) {
            rch_diag_set(d, file, params->line, params->col,
                         "effect length_periodic: the period (third parameter) must be at least 1 mm");
            return -1;
        }
        if (ref) {
            if (ref->type != RCH_JARR || ref->n != 4) {
                rch_diag_set(d, file, ref->line, ref->col, "\"ref_dh\" must be 4 rows [a, d, alpha, theta]");
                return -1;
            }
            for (unsigned r = 0; r < 4; ++r) {
                const rch_json *row = ref->items[r];
                if (row->type != RCH_JARR || row->n != 4) {
                    rch_diag_set(d, file, row->line, row->col, "ref_dh row must have 4 numbers");
                    return -1;
                }
                for (unsigned c = 0; c < 4; ++c) {
                    if (want_num(&ef->ref_dh[r][c], row->items[c], "ref_dh value", file, d, row) != 0)
                        return -1;
                    if (c >= 2)
                        ef->ref_dh[r][c] *= DEG;
                }
            }
        }
    }
    return 0;
}

/* "encoder_mm": [x, y, z] when present (has_encoder set). 0 or -1 (d set). */
static int read_encoder(rch_robot *out, double enc[3], const rch_json *root, const char *name, rch_diag *d)
{
    const rch_json *e = rch_json_get(root, "encoder_mm");
    if (!e)
        return 0;
    if (e->type != RCH_JARR || e->n != 3) {
        rch_diag_set(d, name, e->line, e->col, "\"encoder_mm\" must be [x, y, z]");
        return -1;
    }
    for (unsigned k = 0; k < 3; ++k) {
        if (want_num(&enc[k], e->items[k], "encoder_mm value", name, d, e) != 0)
            return -1;
        if (fabs(enc[k]) > 1e5) {
            rch_diag_set(d, name, e->items[k]->line, e->items[k]->col, "encoder_mm value is absurd");
            return -1;
        }
    }
    out->has_encoder = 1;
    return 0;
}

/* "joint_limits_deg" into m (default +-180 deg). 0 or -1 (d set). */
static int read_limits(rc_model *m, const rch_json *root, const char *name, rch_diag *d)
{
    const rch_json *lim = rch_json_get(root, "joint_limits_deg");
    for (unsigned i = 0; i < RC_NJ; ++i) {
        m->q_min_rad[i] = -M_PI;
        m->q_max_rad[i] = M_PI;
    }
    if (!lim)
        return 0;
    if (lim->type != RCH_JARR || lim->n != RC_NJ) {
        rch_diag_set(d, name, lim->line, lim->col, "\"joint_limits_deg\" must be 6 [min, max] pairs");
        return -1;
    }
    for (unsigned i = 0; i < RC_NJ; ++i) {
        const rch_json *pr = lim->items[i];
        double lo, hi;
        if (pr->type != RCH_JARR || pr->n != 2 || want_num(&lo, pr->items[0], "joint limit", name, d, pr) != 0 ||
            want_num(&hi, pr->items[1], "joint limit", name, d, pr) != 0 || !(lo < hi) || fabs(lo) > 720 ||
            fabs(hi) > 720) {
            rch_diag_set(d, name, pr->line, pr->col, "joint %u limits must be [min, max] degrees, min < max", i + 1);
            return -1;
        }
        m->q_min_rad[i] = lo * DEG;
        m->q_max_rad[i] = hi * DEG;
    }
    return 0;
}

/* "nominal": {"dh": [...]} of a calibrated model (has_nominal set). */
static int read_nominal(rch_robot *out, const rch_json *root, const char *name, rch_diag *d)
{
    const rch_json *nom = rch_json_get(root, "nominal");
    double ndh[RC_NJ][4];
    if (!nom)
        return 0;
    if (nom->type != RCH_JOBJ) {
        rch_diag_set(d, name, nom->line, nom->col, "\"nominal\" must be an object with \"dh\"");
        return -1;
    }
    static const char *const nominal_keys[] = {"dh", NULL};
    if (check_keys(nom, nominal_keys, "\"nominal\"", name, d) != 0 ||
        read_dh(ndh, rch_json_get(nom, "dh"), name, d, nom) != 0)
        return -1;
    for (unsigned i = 0; i < RC_NJ; ++i)
        for (unsigned k = 0; k < 4; ++k)
            out->nominal.x[4 * i + k] = ndh[i][k];
    out->has_nominal = 1;
    return 0;
}

/* One "parameters" entry k: class and standard error (file units: mm, deg). */
static int read_unc_param(rch_robot *out, unsigned k, const rch_json *p, const char *name, rch_diag *d)
{
    const rch_json *cl = rch_json_get(p, "class"), *se = rch_json_get(p, "std_error");
    if (p->type != RCH_JOBJ || !cl || cl->type != RCH_JSTR) {
        rch_diag_set(d, name, p->line, p->col, "uncertainty parameter %u: needs \"class\"", k + 1);
        return -1;
    }
    static const char *const param_keys[] = {"name",     "unit", "value",    "std_error", "class",         "compensation",
                                             "prior_sd", "seen", "seen_why", "data_vs_prior", NULL};
    char where[48];
    snprintf(where, sizeof where, "uncertainty parameter %u", k + 1);
    if (check_keys(p, param_keys, where, name, d) != 0)
        return -1;
    unsigned c = 0;
    while (c < 4 && strcmp(cl->str, rch_param_class_name((rch_param_class)c)) != 0)
        ++c;
    if (c == 4) {
        rch_diag_set(d, name, cl->line, cl->col, "unknown class \"%s\" (identifiable, weak, not identifiable, fixed)",
                     cl->str);
        return -1;
    }
    out->unc.cls[k] = (uint8_t)c;
    const rch_json *cp = rch_json_get(p, "compensation");
    if (cp && (cp->type != RCH_JSTR || (strcmp(cp->str, "nominal") != 0 && strcmp(cp->str, "fitted") != 0 &&
                                        strcmp(cp->str, "not used") != 0))) {
        rch_diag_set(d, name, cp->line, cp->col,
                     "uncertainty parameter %u: \"compensation\" must be exactly \"fitted\", \"nominal\" or "
                     "\"not used\"", k + 1);
        return -1;
    }
    /* version-2 files before this member: weak and not identifiable held nominal */
    out->unc.comp_nominal[k] = cp && cp->type == RCH_JSTR ? strcmp(cp->str, "nominal") == 0 : (c == 2 || c == 3);
    out->unc.se[k] = NAN;
    if (se && se->type == RCH_JNUM) {
        if (!(se->num >= 0.0) || !isfinite(se->num)) {
            rch_diag_set(d, name, se->line, se->col, "std_error must be a finite number >= 0");
            return -1;
        }
        out->unc.se[k] = se->num * (rc_param_unit(&out->model, k) == 1 ? DEG : 1.0);
    }
    return 0;
}

/* Is DH parameter i's variance v beyond what any calibration determines (a
 * standard error above 1 m or 1 rad, RCH_UNDETERMINED_*)? Not a number
 * counts as beyond. */
static double undetermined_lim(unsigned i)
{
    return (i % 4 == 0 || i % 4 == 1) ? RCH_UNDETERMINED_MM2 : RCH_UNDETERMINED_RAD2;
}

int rch_robot_unc_undetermined(const rch_model_unc *u, unsigned k)
{
    return k < RC_N_DH && !(u->cov_dh[k * RC_N_DH + k] <= undetermined_lim(k));
}

/* A covariance read from outside is checked as data (issue 23): symmetric,
 * of physical size (a standard error below 1 m or 1 rad: beyond, no
 * calibration determined anything and every uncertainty figure would be
 * meaningless) and positive semi-definite (its smallest eigenvalue not below
 * -1e-9 of its largest); otherwise it would turn the safety checks of
 * compensation into noise (a -1 diagonal printed "0.0000 mm"). The rows and
 * columns of undetermined parameters (und[i], issue 33) are out of the
 * check: read_uncertainty has set them aside. */
static int check_cov(const double *c, const uint8_t *und, const rch_json *arr, const char *name, rch_diag *d)
{
    const unsigned n = RC_N_DH;
    for (unsigned i = 0; i < n; ++i) {
        if (und[i])
            continue;
        const double v = c[i * n + i], lim = undetermined_lim(i);
        if (!(v >= 0.0) || v > lim) {
            const rch_json *it = arr->items[i * n + i];
            rch_diag_set(d, name, it->line, it->col,
                         "covariance_dh[%u][%u] = %g is not a variance of a calibrated parameter (0 to %g %s^2)", i, i,
                         v, lim, lim > 1.0 ? "mm" : "rad");
            return -1;
        }
        for (unsigned j = 0; j < i; ++j) {
            if (und[j])
                continue;
            const double a = c[i * n + j], b = c[j * n + i];
            if (fabs(a - b) > 1e-9 * sqrt(c[i * n + i] * c[j * n + j]) + 1e-300) {
                const rch_json *it = arr->items[i * n + j];
                rch_diag_set(d, name, it->line, it->col, "covariance_dh is not symmetric at [%u][%u] (%g against %g)",
                             i, j, a, b);
                return -1;
            }
        }
    }
    double A[RC_N_DH * RC_N_DH], V[RC_N_DH * RC_N_DH], ev[RC_N_DH];
    for (unsigned i = 0; i < n; ++i)
        for (unsigned j = 0; j < n; ++j)
            A[i * n + j] = und[i] || und[j] ? 0.0 : c[i * n + j];
    if (rcu_eig_sym(ev, V, A, n, 0) != RC_OK) {
        rch_diag_set(d, name, arr->line, arr->col, "covariance_dh: its eigenvalues cannot be computed");
        return -1;
    }
    double mx = 0.0, mn = 0.0;
    for (unsigned i = 0; i < n; ++i) {
        mx = ev[i] > mx ? ev[i] : mx;
        mn = ev[i] < mn ? ev[i] : mn;
    }
    if (mn < -1e-9 * mx - 1e-300) {
        rch_diag_set(d, name, arr->line, arr->col,
                     "covariance_dh is not positive semi-definite (eigenvalue %g against a largest of %g): not the "
                     "covariance of any calibration", mn, mx);
        return -1;
    }
    return 0;
}

/* The DH parameters the data left undetermined (issue 33): those named in
 * "undetermined" (written since) and, in files written before, those whose
 * variance is beyond RCH_UNDETERMINED_* while compensation holds them
 * nominal (a no-prior fit's weak direction). Each must be held nominal by
 * compensation: a file that says it uses an undetermined value is refused.
 * und: (24) set to 1 for each. */
static int read_undetermined(uint8_t und[RC_N_DH], const rch_robot *out, const rch_json *u, const rch_json *cov,
                             const char *name, rch_diag *d)
{
    const rch_json *ul = rch_json_get(u, "undetermined");
    memset(und, 0, RC_N_DH);
    if (ul && ul->type != RCH_JARR) {
        rch_diag_set(d, name, ul->line, ul->col, "\"undetermined\" must be an array of DH parameter names");
        return -1;
    }
    for (size_t i = 0; ul && i < ul->n; ++i) {
        const rch_json *s = ul->items[i];
        unsigned k = 0;
        char nm[64];
        while (k < RC_N_DH &&
               !(s->type == RCH_JSTR && strcmp(s->str, rc_param_name(nm, sizeof nm, &out->model, k)) == 0))
            ++k;
        if (k == RC_N_DH) {
            rch_diag_set(d, name, s->line, s->col,
                         "\"undetermined\": item %zu is not a DH parameter name (a1 .. theta6)", i + 1);
            return -1;
        }
        und[k] = 1;
    }
    for (unsigned k = 0; k < RC_N_DH; ++k) {
        const rch_json *it = cov->items[k * RC_N_DH + k];
        if (!und[k] && it->type == RCH_JNUM && it->num > undetermined_lim(k) && out->unc.comp_nominal[k] &&
            out->unc.cls[k] != RCH_PARAM_FIXED)
            und[k] = 1;
        char nm[64];
        if (und[k] && !out->unc.comp_nominal[k]) {
            rch_diag_set(d, name, it->line, it->col,
                         "%s is undetermined by the data but its \"compensation\" is \"fitted\": compensation cannot "
                         "use a value the data did not determine (make it \"nominal\")",
                         rc_param_name(nm, sizeof nm, &out->model, k));
            return -1;
        }
    }
    return 0;
}

/* What the informational "calibration" member says of the fit: the file
 * and the length jumps fitted as nuisance ("length_jumps": [{"line", "t",
 * "size_mm", "se_mm"}], written since the jumps are said by rcal evaluate).
 * Older files have neither: 0. */
static int read_calibration(rch_robot *out, const rch_json *c, const char *name, rch_diag *d)
{
    if (!c || c->type != RCH_JOBJ)
        return 0;
    const rch_json *data = rch_json_get(c, "data"), *jumps = rch_json_get(c, "length_jumps");
    if (data && data->type == RCH_JSTR)
        snprintf(out->cal_data, sizeof out->cal_data, "%s", data->str);
    if (!jumps)
        return 0;
    if (jumps->type != RCH_JARR) {
        rch_diag_set(d, name, jumps->line, jumps->col, "\"calibration\": \"length_jumps\" must be an array of "
                     "{\"size_mm\": number, ...}");
        return -1;
    }
    for (size_t k = 0; k < jumps->n; ++k) {
        const rch_json *sz = rch_json_get(jumps->items[k], "size_mm");
        if (!sz || sz->type != RCH_JNUM || !isfinite(sz->num)) {
            rch_diag_set(d, name, jumps->items[k]->line, jumps->items[k]->col,
                         "\"calibration\": length jump %zu needs \"size_mm\", a finite number", k + 1);
            return -1;
        }
        if (fabs(sz->num) > out->cal_jump_max_mm)
            out->cal_jump_max_mm = fabs(sz->num);
    }
    out->n_cal_jumps = (unsigned)jumps->n;
    return 0;
}

/* "outlet_labels": one distinct label 0..255 per outlet (encoder_mm first,
 * then the outlet effects by number). Absent: 0 labels. 0 or -1 (d set). */
static int read_outlet_labels(rch_robot *out, const rch_json *a, const char *name, rch_diag *d)
{
    out->n_outlet_labels = 0;
    if (!a)
        return 0;
    unsigned outlets = 1;
    for (unsigned e = 0; e < out->model.n_effects; ++e)
        outlets += out->model.effects[e].kind == RC_EFF_OUTLET;
    if (a->type != RCH_JARR || a->n != outlets) {
        rch_diag_set(d, name, a->line, a->col, "\"outlet_labels\" must be an array of %u labels (the encoder's, then "
                                              "one per outlet effect)", outlets);
        return -1;
    }
    for (size_t k = 0; k < a->n; ++k) {
        const rch_json *v = a->items[k];
        if (v->type != RCH_JNUM || !(v->num >= 0 && v->num <= 255) || v->num != floor(v->num)) {
            rch_diag_set(d, name, v->line, v->col, "an outlet label is an integer 0..255");
            return -1;
        }
        for (size_t j = 0; j < k; ++j)
            if (out->outlet_label[j] == (uint8_t)v->num) {
                rch_diag_set(d, name, v->line, v->col, "outlet label %g twice", v->num);
                return -1;
            }
        out->outlet_label[k] = (uint8_t)v->num;
    }
    out->n_outlet_labels = (unsigned)a->n;
    return 0;
}

int rch_robot_outlets_of(const rch_robot *robot, rc_sample *s, size_t n, const unsigned *lines, const char *name,
                         rch_diag *d)
{
    return robot->n_outlet_labels == 0
               ? 0
               : rch_data_outlets_as(robot->outlet_label, robot->n_outlet_labels, s, n, lines, name, d);
}

/* "uncertainty" of an rcal-model/2 file. */
static int read_uncertainty(rch_robot *out, const rch_json *u, const char *name, rch_diag *d)
{
    const rch_json *ps = rch_json_get(u, "parameters"), *cov = rch_json_get(u, "covariance_dh"),
                   *od = rch_json_get(u, "orientation_determined"), *sg = rch_json_get(u, "sigma_mm");
    if (u->type != RCH_JOBJ || !ps || ps->type != RCH_JARR || ps->n != out->model.n_params) {
        rch_diag_set(d, name, u->line, u->col, "\"uncertainty\" needs \"parameters\", one per model parameter (%u)",
                     out->model.n_params);
        return -1;
    }
    static const char *const unc_keys[] = {"covariance",   "groups",        "sigma_mm",
                                           "rank",         "posterior",     "parameters",
                                           "undetermined", "covariance_dh", "determined",
                                           "orientation_determined", "position95_mm", "orientation95_deg", NULL};
    static const char *const det_keys[] = {"dh", NULL};
    if (check_keys(u, unc_keys, "\"uncertainty\"", name, d) != 0 ||
        check_keys(rch_json_get(u, "determined"), det_keys, "\"uncertainty\".\"determined\"", name, d) != 0)
        return -1;
    for (unsigned k = 0; k < ps->n; ++k)
        if (read_unc_param(out, k, ps->items[k], name, d) != 0)
            return -1;
    if (!cov || cov->type != RCH_JARR || cov->n != RC_N_DH * RC_N_DH) {
        rch_diag_set(d, name, u->line, u->col, "\"uncertainty\" needs \"covariance_dh\": %d numbers (24 x 24, mm and rad)",
                     RC_N_DH * RC_N_DH);
        return -1;
    }
    uint8_t und[RC_N_DH];
    if (read_undetermined(und, out, u, cov, name, d) != 0)
        return -1;
    for (unsigned k = 0; k < cov->n; ++k) {
        const unsigned i = k / RC_N_DH, j = k % RC_N_DH;
        if (und[i] || und[j]) { /* null (or a number beyond belief): no information */
            if (cov->items[k]->type != RCH_JNULL && cov->items[k]->type != RCH_JNUM) {
                rch_diag_set(d, name, cov->items[k]->line, cov->items[k]->col,
                             "covariance_dh: a number, or null in the row and column of an undetermined parameter");
                return -1;
            }
            out->unc.cov_dh[k] = i == j ? INFINITY : 0.0;
            continue;
        }
        if (cov->items[k]->type != RCH_JNUM || !isfinite(cov->items[k]->num)) {
            rch_diag_set(d, name, cov->items[k]->line, cov->items[k]->col,
                         "covariance_dh: not a finite number (null only in the row and column of a parameter listed "
                         "in \"undetermined\")");
            return -1;
        }
        out->unc.cov_dh[k] = cov->items[k]->num;
    }
    if (check_cov(out->unc.cov_dh, und, cov, name, d) != 0)
        return -1;
    for (unsigned k = 0; k < RC_N_DH; ++k)
        if (und[k])
            out->unc.se[k] = NAN;
    out->unc.orientation_determined = od && od->type == RCH_JBOOL && od->num != 0.0;
    out->unc.sigma_mm = sg && sg->type == RCH_JNUM ? sg->num : NAN;
    const rch_json *po = rch_json_get(u, "posterior");
    if (po && po->type != RCH_JBOOL) {
        rch_diag_set(d, name, po->line, po->col, "\"posterior\" must be true or false");
        return -1;
    }
    out->unc.has_prior = po && po->num != 0.0;
    out->unc.n = out->model.n_params;
    out->unc.present = 1;
    return 0;
}

/* "prior": {"length_mm", "twist_deg", "offset_deg", "attachment_mm"}, each
 * optional, positive and physical; defaults for the rest (rch_prior.h). */
static int read_prior(rch_prior_cfg *p, const rch_json *pr, const char *name, rch_diag *d)
{
    rch_prior_defaults(p);
    const struct {
        const char *key;
        double *dst;
        double max;
    } keys[] = {{"length_mm", &p->length_mm, 100.0},
                {"twist_deg", &p->twist_deg, 10.0},
                {"offset_deg", &p->offset_deg, 30.0},
                {"attachment_mm", &p->attachment_mm, 2000.0}};
    if (!pr)
        return 0;
    if (pr->type != RCH_JOBJ) {
        rch_diag_set(d, name, pr->line, pr->col, "\"prior\" must be an object of standard deviations");
        return -1;
    }
    for (size_t i = 0; i < pr->n; ++i) {
        size_t k = 0;
        while (k < sizeof keys / sizeof keys[0] && strcmp(pr->keys[i], keys[k].key) != 0)
            ++k;
        if (k == sizeof keys / sizeof keys[0]) {
            rch_diag_set(d, name, pr->items[i]->line, pr->items[i]->col,
                         "unknown prior \"%s\" (length_mm, twist_deg, offset_deg, attachment_mm)", pr->keys[i]);
            return -1;
        }
        double v;
        if (want_num(&v, pr->items[i], keys[k].key, name, d, pr) != 0)
            return -1;
        if (!(v > 0.0 && v <= keys[k].max)) {
            rch_diag_set(d, name, pr->items[i]->line, pr->items[i]->col,
                         "prior %s = %g must be a standard deviation in (0, %g]", keys[k].key, v, keys[k].max);
            return -1;
        }
        *keys[k].dst = v;
    }
    p->from_file = 1;
    return 0;
}

int rch_robot_parse(rch_robot *out, const char *text, size_t len, const char *name, rch_diag *d)
{
    double dh[RC_NJ][4], enc[3] = {0, 0, 0};
    memset(out, 0, sizeof *out);
    rch_json *root = rch_json_parse(text, len, name, d);
    if (!root)
        return -1;
    int rc = -1;
    if (root->type != RCH_JOBJ) {
        rch_diag_set(d, name, root->line, root->col, "a model file must be a JSON object");
        goto done;
    }
    /* every member is one rcal knows ("calibration", "fit" and "provenance"
     * are informational: their contents are not checked) */
    static const char *const top_keys[] = {"format",  "name",        "dh",          "joint_limits_deg", "encoder_mm",
                                           "effects", "prior",       "nominal",     "calibration",      "uncertainty",
                                           "fit",     "provenance",  "outlet_labels", "$schema",        "links",
                                           "cell",    "controller", "source", NULL};
    if (check_keys(root, top_keys, "the model file", name, d) != 0)
        goto done;
    const rch_json *fmt = rch_json_get(root, "format");
    if (fmt && (fmt->type != RCH_JSTR ||
                (strcmp(fmt->str, "rcal-model/1") != 0 && strcmp(fmt->str, "rcal-model/2") != 0))) {
        rch_diag_set(d, name, fmt->line, fmt->col,
                     "unsupported format (expected \"rcal-model/1\" or \"rcal-model/2\")");
        goto done;
    }
    const rch_json *nm = rch_json_get(root, "name");
    snprintf(out->name, sizeof out->name, "%s", nm && nm->type == RCH_JSTR ? nm->str : "robot");
    if (read_dh(dh, rch_json_get(root, "dh"), name, d, root) != 0 || read_encoder(out, enc, root, name, d) != 0)
        goto done;
    if (rc_model_init(&out->model, (const double(*)[4])dh, enc) != RC_OK) {
        rch_diag_set(d, name, root->line, root->col, "invalid DH table");
        goto done;
    }
    if (read_limits(&out->model, root, name, d) != 0)
        goto done;
    out->nominal = out->model;
    if (read_nominal(out, root, name, d) != 0)
        goto done;
    const rch_json *eff = rch_json_get(root, "effects");
    if (eff && read_effects(&out->model, eff, name, d) != 0)
        goto done;
    const rch_json *unc = rch_json_get(root, "uncertainty");
    if (unc && read_uncertainty(out, unc, name, d) != 0)
        goto done;
    if (read_prior(&out->prior, rch_json_get(root, "prior"), name, d) != 0)
        goto done;
    if (read_calibration(out, rch_json_get(root, "calibration"), name, d) != 0)
        goto done;
    if (read_outlet_labels(out, rch_json_get(root, "outlet_labels"), name, d) != 0)
        goto done;
    if (rch_cell_read(&out->cell, rch_json_get(root, "links"), rch_json_get(root, "cell"), name, d) != 0)
        goto done;
    if (rch_ctrl_read(&out->ctrl, rch_json_get(root, "controller"), name, d) != 0)
        goto done;
    rc = 0;
done:
    rch_json_free(root);
    return rc;
}

int rch_robot_load(rch_robot *out, const char *path, rch_diag *d)
{
    char *text;
    size_t len;
    const size_t pl = strlen(path);
    if (pl > 5 && strcasecmp(path + pl - 5, ".urdf") == 0) { /* a URDF: rch_urdf_robot.h */
        if (rch_read_file(&text, &len, path, (size_t)16 << 20, d) != 0)
            return -1;
        const int rc = rch_urdf_robot_parse(out, text, len, path, d);
        free(text);
        return rc;
    }
    /* the one file reader: a directory, a read error (with its reason) or a file over 64 KiB is refused */
    if (rch_read_file(&text, &len, path, (size_t)1 << 16, d) != 0)
        return -1;
    const int rc = rch_robot_parse(out, text, len, path, d);
    free(text);
    return rc;
}

static void write_dh(rch_jw *w, const char *key, const rc_model *m)
{
    rch_jw_arr(w, key);
    for (unsigned i = 0; i < RC_NJ; ++i) {
        rch_jw_obj(w, NULL);
        rch_jw_numf(w, "a_mm", m->x[RC_P_A(i)], "%.9g");
        rch_jw_numf(w, "d_mm", m->x[RC_P_D(i)], "%.9g");
        rch_jw_numf(w, "alpha_deg", m->x[RC_P_ALPHA(i)] / DEG, "%.9g");
        rch_jw_numf(w, "theta_deg", m->x[RC_P_THETA(i)] / DEG, "%.9g");
        rch_jw_end(w);
    }
    rch_jw_end(w);
}

static void write_numsf(rch_jw *w, const char *key, const double *v, size_t n, const char *fmt)
{
    rch_jw_arr(w, key);
    for (size_t i = 0; i < n; ++i)
        rch_jw_numf(w, NULL, v[i], fmt);
    rch_jw_end(w);
}

void rch_robot_write_unc_map(rch_jw *w, const rch_uncert_map *mp)
{
    rch_jw_obj(w, "position95_mm");
    rch_jw_numf(w, "data_median", mp->data_median_mm, "%.6g");
    rch_jw_numf(w, "data_max", mp->data_max_mm, "%.6g");
    rch_jw_numf(w, "workspace_median", mp->work_median_mm, "%.6g");
    rch_jw_numf(w, "workspace_max", mp->work_max_mm, "%.6g");
    rch_jw_end(w);
    rch_jw_obj(w, "orientation95_deg");
    rch_jw_numf(w, "data_median", mp->rot_data_median_deg, "%.6g");
    rch_jw_numf(w, "data_max", mp->rot_data_max_deg, "%.6g");
    rch_jw_numf(w, "determined_median", mp->rot_det_median_deg, "%.6g");
    rch_jw_numf(w, "determined_max", mp->rot_det_max_deg, "%.6g");
    rch_jw_end(w);
}

void rch_robot_write_unc_params(rch_jw *w, const rc_model *m, const rch_model_unc *u, const char *value_fmt)
{
    rch_jw_arr(w, "parameters");
    for (unsigned k = 0; k < m->n_params; ++k) {
        char nm[64];
        const int unit = rc_param_unit(m, k);
        const double sc = unit == 1 ? 1.0 / DEG : 1.0;
        rch_jw_obj(w, NULL);
        rch_jw_str(w, "name", rc_param_name(nm, sizeof nm, m, k));
        rch_jw_str(w, "unit", unit == 0 ? "mm" : unit == 1 ? "deg" : "SI");
        rch_jw_numf(w, "value", m->x[k] * sc, value_fmt);
        /* NaN -> null; so is an undetermined parameter's */
        rch_jw_numf(w, "std_error", rch_robot_unc_undetermined(u, k) ? NAN : u->se[k] * sc, "%.6g");
        rch_jw_str(w, "class", rch_param_class_name((rch_param_class)u->cls[k]));
        rch_jw_str(w, "compensation", k < RC_N_DH ? (u->comp_nominal[k] ? "nominal" : "fitted") : "not used");
        if (u->has_prior && u->prior_sd[k] > 0.0) {
            rch_jw_numf(w, "prior_sd", u->prior_sd[k] * sc, "%.6g");
            rch_jw_str(w, "data_vs_prior", rch_prior_class_name((rch_prior_class)u->prior_cls[k]));
        }
        /* the one class every report prints (rch_seen.h); "class" and
         * "data_vs_prior" above are the two facts it is made of */
        const rch_seen seen = rch_seen_of_unc(u, k);
        rch_jw_str(w, "seen", rch_seen_key(seen));
        rch_jw_str(w, "seen_why", rch_seen_why(seen, (rch_param_class)u->cls[k]));
        rch_jw_end(w);
    }
    rch_jw_end(w);
}

static void write_uncertainty(rch_jw *w, const rc_model *m, const rch_model_unc *u, const rc_model *det)
{
    rch_jw_obj(w, "uncertainty");
    rch_jw_str(w, "covariance", u->kind == RCH_COV_CLUSTER ? "cluster-robust" : "classical");
    rch_jw_uint(w, "groups", u->n_groups);
    rch_jw_numf(w, "sigma_mm", u->sigma_mm, "%.6g");
    rch_jw_uint(w, "rank", u->rank);
    rch_jw_bool(w, "posterior", u->has_prior); /* the covariance of a MAP fit: prior-only directions included */
    rch_robot_write_unc_params(w, m, u, "%.12g");
    /* the parameters the data left undetermined (issue 33): named, their
     * rows and columns of covariance_dh null */
    uint8_t und[RC_N_DH];
    unsigned n_und = 0;
    for (unsigned k = 0; k < RC_N_DH; ++k)
        n_und += und[k] = (uint8_t)rch_robot_unc_undetermined(u, k);
    if (n_und) {
        rch_jw_arr(w, "undetermined");
        for (unsigned k = 0; k < RC_N_DH; ++k) {
            char nm[64];
            if (und[k])
                rch_jw_str(w, NULL, rc_param_name(nm, sizeof nm, m, k));
        }
        rch_jw_end(w);
    }
    rch_jw_arr(w, "covariance_dh");
    for (unsigned k = 0; k < RC_N_DH * RC_N_DH; ++k)
        rch_jw_numf(w, NULL, und[k / RC_N_DH] || und[k % RC_N_DH] ? NAN : u->cov_dh[k], "%.9g");
    rch_jw_end(w);
    if (det) {
        rch_jw_obj(w, "determined");
        write_dh(w, "dh", det);
        rch_jw_end(w);
    }
    rch_jw_bool(w, "orientation_determined", u->orientation_determined);
    rch_robot_write_unc_map(w, &u->map);
    rch_jw_end(w);
}

void rch_robot_write_provenance(rch_jw *w, const rch_provenance *p)
{
    rch_jw_obj(w, "provenance");
    rch_jw_arr(w, "data");
    for (unsigned i = 0; i < p->n_files; ++i) {
        rch_jw_obj(w, NULL);
        rch_jw_str(w, "file", p->file[i]);
        rch_jw_uint(w, "samples", p->samples[i]);
        rch_jw_str(w, "sha256", p->sha256[i]);
        rch_jw_end(w);
    }
    rch_jw_end(w);
    rch_jw_str(w, "date", p->date);
    rch_jw_str(w, "tool", p->tool);
    rch_jw_end(w);
}

int rch_robot_write(FILE *f, const char *name, const rc_model *m, const rc_model *nominal,
                    const rch_robot_info *info)
{
    rch_jw w;
    rch_jw_init(&w, f, 1);
    rch_jw_obj(&w, NULL);
    rch_jw_str(&w, "format", info && info->unc ? "rcal-model/2" : "rcal-model/1");
    rch_jw_str(&w, "name", name ? name : "robot");
    write_dh(&w, "dh", m);
    rch_jw_arr(&w, "joint_limits_deg");
    for (unsigned i = 0; i < RC_NJ; ++i) {
        const double lim[2] = {m->q_min_rad[i] / DEG, m->q_max_rad[i] / DEG};
        write_numsf(&w, NULL, lim, 2, "%.9g");
    }
    rch_jw_end(&w);
    write_numsf(&w, "encoder_mm", &m->x[RC_P_ENC], 3, "%.9g");
    if (info && info->outlet_label && info->n_outlets > 0) {
        int plain = 1; /* labels 0, 1, ... are the numbers: nothing to say */
        for (unsigned k = 0; k < info->n_outlets; ++k)
            plain &= info->outlet_label[k] == k;
        if (!plain) {
            rch_jw_arr(&w, "outlet_labels");
            for (unsigned k = 0; k < info->n_outlets; ++k)
                rch_jw_uint(&w, NULL, info->outlet_label[k]);
            rch_jw_end(&w);
        }
    }
    if (m->n_effects) {
        rch_jw_arr(&w, "effects");
        for (unsigned i = 0; i < m->n_effects; ++i) {
            const rc_effect *e = &m->effects[i];
            rch_jw_obj(&w, NULL);
            rch_jw_str(&w, "kind", rc_effect_name((rc_effect_kind)e->kind));
            const rc_effect_desc *ds = rc_effect_describe(e->kind);
            if (ds && ds->arg == RC_EFF_ARG_OUTLET)
                rch_jw_uint(&w, "outlet", e->joint);
            else
                rch_jw_uint(&w, "joint", e->joint + 1u);
            write_numsf(&w, "params", &m->x[e->first], e->count, "%.12g");
            rch_jw_arr(&w, "ref_dh");
            for (unsigned r = 0; r < 4; ++r) {
                const double row[4] = {e->ref_dh[r][0], e->ref_dh[r][1], e->ref_dh[r][2] / DEG,
                                       e->ref_dh[r][3] / DEG};
                write_numsf(&w, NULL, row, 4, "%.9g");
            }
            rch_jw_end(&w);
            rch_jw_end(&w);
        }
        rch_jw_end(&w);
    }
    if (nominal) {
        rch_jw_obj(&w, "nominal");
        write_dh(&w, "dh", nominal);
        rch_jw_end(&w);
    }
    if (info && info->ctrl)
        rch_ctrl_write(&w, info->ctrl);
    if (info && info->write) {
        rch_jw_obj(&w, "calibration");
        info->write(&w, info->ctx);
        rch_jw_end(&w);
    }
    if (info && info->unc)
        write_uncertainty(&w, m, info->unc, info->determined);
    if (info && info->prov)
        rch_robot_write_provenance(&w, info->prov);
    rch_jw_end(&w);
    return rch_jw_finish(&w) == 0 && !ferror(f) ? 0 : -1;
}

int rch_load_model_and_data(struct rch_robot *robot, const char *model_path, rch_data *data, const char *data_path,
                            rch_diag *d)
{
    if (rch_robot_load(robot, model_path, d) != 0 || rch_data_load_limited(data, data_path, 0, &robot->model, d) != 0)
        return -1;
    if (rch_robot_outlets_of(robot, data->s, data->n, data->line, data_path, d) != 0) {
        rch_data_free(data);
        return -1;
    }
    return 0;
}
