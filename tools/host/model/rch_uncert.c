/* SPDX-License-Identifier: MIT */
/* rch_uncert.c - the covariance of a calibration (see rch_uncert.h):
 * the Jacobian at the solution, its scaled normal matrix and eigen-
 * decomposition, the classical, cluster-robust and MAP posterior
 * covariances, each parameter's standard error and class (lib/rc_ident's
 * one definition, made weak by a large standard error), and the parameters
 * compensation holds nominal (the determined part of the model). The
 * figures at a pose drawn from the covariance (pos95, rot95, the map, u95)
 * are in rch_uncert_u95.c.
 * Depends on: lib/rc_ident, rc_fk; rch_jac, rch_prior, rch_stats; LAPACKE
 * (dposv, dsyev). Memory: u->cov on the heap (rch_uncert_free); scratch
 * freed before return. Errors: -1 with the message in err[errlen]. */
#include "rch_uncert.h"
#include "rch_jac.h"
#include "rch_prior.h"
#include "rch_robot.h"
#include "rch_stats.h"

#include <lapacke.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rc_ident.h"

void rch_uncert_free(rch_uncert *u)
{
    free(u->cov);
    u->cov = NULL;
}

/* Groups usable as clusters: at least 5 groups with >= 2 samples each. */
#define CL(i) (cl ? cl[i] : s[i].group)

static unsigned count_groups(const rc_sample *s, const uint16_t *cl, size_t n, unsigned *gmax)
{
    unsigned mx = 0;
    for (size_t i = 0; i < n; ++i)
        if (CL(i) > mx)
            mx = CL(i);
    unsigned *cnt = calloc((size_t)mx + 1, sizeof *cnt);
    if (!cnt)
        return 0;
    for (size_t i = 0; i < n; ++i)
        cnt[CL(i)]++;
    unsigned g = 0, small = 0;
    for (unsigned k = 0; k <= mx; ++k) {
        g += cnt[k] > 0;
        small += cnt[k] == 1;
    }
    free(cnt);
    *gmax = mx;
    return (g >= 5 && small * 2 < g) ? g : 0;
}

typedef struct {
    unsigned nf;
    unsigned idx[RC_MAX_PARAMS];
    double D[RC_MAX_PARAMS];
    double ev[RC_MAX_PARAMS];
    double *V;  /* (nf x nf) eigenvectors in columns, ascending eigenvalues */
    uint8_t dir_class[RC_MAX_PARAMS];   /* (nf) rc_ident_class of direction d (ascending order) */
    uint8_t param_class[RC_MAX_PARAMS]; /* (nf) rc_ident_class of free parameter a */
    double *Cz; /* (nf x nf) covariance in scaled coordinates */
} scaled;

/* Classes of directions and parameters from the one definition (rc_ident),
 * on the eigen-decomposition in ascending order. */
static int ident(scaled *z, size_t n_rows)
{
    unsigned nf = z->nf;
    double evd[RC_MAX_PARAMS], *Vd = malloc((size_t)nf * nf * sizeof *Vd);
    rc_ident id;
    if (!Vd)
        return -1;
    for (unsigned d = 0; d < nf; ++d) {
        evd[d] = z->ev[nf - 1 - d];
        for (unsigned a = 0; a < nf; ++a)
            Vd[a * nf + d] = z->V[a * nf + (nf - 1 - d)];
    }
    rc_status st = rc_ident_classify_eig(&id, evd, Vd, nf, n_rows);
    free(Vd);
    if (st != RC_OK)
        return -1;
    for (unsigned d = 0; d < nf; ++d)
        z->dir_class[d] = id.dir_class[nf - 1 - d];
    memcpy(z->param_class, id.param_class, nf);
    return 0;
}

/* The posterior covariance in scaled coordinates of a MAP fit (prior sd
 * psd of the free parameters, scaled: psd_k D_k; 0 = none) with the
 * residual sd noise:
 *   H = A / noise^2 + P,  P = diag(1 / psd^2)
 *   classical:      Cz = H^-1
 *   cluster-robust: Cz = H^-1 (c M / noise^4 + P) H^-1, M = sum_g u_g u_g^T
 * (the data's part of the information replaced by the clustered scores'
 * outer product, the prior's kept). Every direction is determined (by the
 * data or by the prior), so nothing is left out. */
/* The cluster-robust covariance is estimated from G groups' scores: G - 1
 * degrees of freedom. Its 95 % regions in three dimensions (the position
 * figures: u95_mm, the compensation gate, the map, the report's verdict)
 * are Hotelling's T^2, not chi2: the data's part of the covariance is
 * scaled by their ratio (rch_t2_ratio95_3d(G - 1): 1.56 at 15 groups,
 * 1.13 at 48, 1.01 at 300), so that every 3-D figure drawn from it keeps
 * its 95 %. One-dimensional intervals (a parameter's +-1.96 se) are then
 * wider than Student's t would make them (at 15 groups 1.25 against 1.09
 * times the CR1 width). Truth study, two outlets, fixed-wrist set-ups of 20
 * poses (seed 5): coverage 0.851 before, 0.924 after. */
static double cluster_factor(unsigned G)
{
    const double f = rch_t2_ratio95_3d((double)G - 1.0);
    return isfinite(f) ? f : 1.0;
}

static int covariance_map(scaled *z, rch_uncert *u, const double *A, const double *J, const double *r,
                          const rc_sample *s, const uint16_t *cl, size_t n, int want_cluster, const double *psd,
                          double noise)
{
    const unsigned nf = z->nf;
    const double s2 = noise * noise;
    double *H = calloc((size_t)nf * nf, sizeof *H), *Hi = calloc((size_t)nf * nf, sizeof *Hi);
    double *M = calloc((size_t)nf * nf, sizeof *M);
    int rc = -1;
    if (!H || !Hi || !M)
        goto done;
    for (unsigned a = 0; a < nf; ++a) {
        for (unsigned b = 0; b < nf; ++b)
            H[a * nf + b] = A[a * nf + b] / s2;
        if (psd[a] > 0.0)
            H[a * nf + a] += 1.0 / (psd[a] * psd[a]);
        else /* no prior: a ridge far below any information the data carry keeps H definite */
            H[a * nf + a] += 1e-12 * (H[a * nf + a] > 0.0 ? H[a * nf + a] : 1.0);
        Hi[a * nf + a] = 1.0;
    }
    if (LAPACKE_dposv(LAPACK_ROW_MAJOR, 'U', (lapack_int)nf, (lapack_int)nf, H, (lapack_int)nf, Hi,
                      (lapack_int)nf) != 0)
        goto done;
    double ssr = 0.0, peff = 0.0;
    for (size_t i = 0; i < n; ++i)
        ssr += r[i] * r[i];
    for (unsigned a = 0; a < nf; ++a)
        for (unsigned b = 0; b < nf; ++b)
            peff += Hi[a * nf + b] * A[b * nf + a] / s2;
    u->rank = 0;
    u->n_weak = 0;
    for (unsigned d = 0; d < nf; ++d) {
        u->rank += z->dir_class[d] != RC_IDENT_NONE;
        u->n_weak += z->dir_class[d] == RC_IDENT_WEAK;
    }
    u->sigma_mm = noise;
    u->p_eff = peff;
    (void)ssr;
    unsigned gmax = 0, G = want_cluster ? count_groups(s, cl, n, &gmax) : 0;
    if (G) {
        double *ug = calloc(((size_t)gmax + 1) * nf, sizeof *ug), *T = calloc((size_t)nf * nf, sizeof *T);
        if (!ug || !T) {
            free(ug);
            free(T);
            goto done;
        }
        for (size_t i = 0; i < n; ++i) {
            double *ui = ug + (size_t)CL(i) * nf;
            for (unsigned k = 0; k < nf; ++k)
                ui[k] += J[i * nf + k] * r[i];
        }
        for (unsigned g = 0; g <= gmax; ++g) {
            const double *ua = ug + (size_t)g * nf;
            for (unsigned a = 0; a < nf; ++a)
                for (unsigned b = 0; b < nf; ++b)
                    M[a * nf + b] += ua[a] * ua[b];
        }
        const double dof = (double)n - peff;
        /* CR1 (G / (G - 1) (n - 1) / (n - p)), then the few-groups factor
         * (cluster_factor) */
        const double c = ((double)G / (G - 1.0)) * (((double)n - 1.0) / (dof > 1.0 ? dof : 1.0)) * cluster_factor(G);
        for (unsigned a = 0; a < nf; ++a) {
            for (unsigned b = 0; b < nf; ++b)
                M[a * nf + b] *= c / (s2 * s2);
            if (psd[a] > 0.0)
                M[a * nf + a] += 1.0 / (psd[a] * psd[a]);
        }
        for (unsigned a = 0; a < nf; ++a)
            for (unsigned k = 0; k < nf; ++k) {
                const double h = Hi[a * nf + k];
                for (unsigned b = 0; b < nf; ++b)
                    T[a * nf + b] += h * M[k * nf + b];
            }
        for (unsigned a = 0; a < nf; ++a)
            for (unsigned b = 0; b < nf; ++b) {
                double v = 0.0;
                for (unsigned k = 0; k < nf; ++k)
                    v += T[a * nf + k] * Hi[k * nf + b];
                z->Cz[a * nf + b] = v;
            }
        for (unsigned a = 0; a < nf; ++a)
            for (unsigned b = a + 1; b < nf; ++b) {
                const double v = 0.5 * (z->Cz[a * nf + b] + z->Cz[b * nf + a]);
                z->Cz[a * nf + b] = z->Cz[b * nf + a] = v;
            }
        free(ug);
        free(T);
        u->kind = RCH_COV_CLUSTER;
        u->n_groups = G;
    } else {
        memcpy(z->Cz, Hi, (size_t)nf * nf * sizeof *Hi);
        u->kind = RCH_COV_CLASSICAL;
        u->n_groups = 0;
    }
    rc = 0;
done:
    free(H);
    free(Hi);
    free(M);
    return rc;
}

/* Covariance in scaled coordinates: classical or cluster-robust. */
static int covariance(scaled *z, rch_uncert *u, const double *J, const double *r, const rc_sample *s,
                      const uint16_t *cl, size_t n, int want_cluster)
{
    unsigned nf = z->nf;
    /* pseudo-inverse A+ = sum over kept directions v v^T / ev */
    double *Ap = calloc((size_t)nf * nf, sizeof *Ap);
    double *M = calloc((size_t)nf * nf, sizeof *M);
    if (!Ap || !M) {
        free(Ap);
        free(M);
        return -1;
    }
    u->rank = u->n_weak = 0;
    for (unsigned d = 0; d < nf; ++d) {
        if (z->dir_class[d] == RC_IDENT_NONE)
            continue;
        u->rank++;
        u->n_weak += z->dir_class[d] == RC_IDENT_WEAK;
        for (unsigned a = 0; a < nf; ++a)
            for (unsigned b = 0; b < nf; ++b)
                Ap[a * nf + b] += z->V[a * nf + d] * z->V[b * nf + d] / z->ev[d];
    }
    double ssr = 0.0;
    for (size_t i = 0; i < n; ++i)
        ssr += r[i] * r[i];
    double dof = (double)n - (double)u->rank;
    u->sigma_mm = dof > 0 ? sqrt(ssr / dof) : NAN;
    unsigned gmax = 0, G = want_cluster ? count_groups(s, cl, n, &gmax) : 0;
    if (G) {
        double *ug = calloc(((size_t)gmax + 1) * nf, sizeof *ug);
        if (!ug) {
            free(Ap);
            free(M);
            return -1;
        }
        for (size_t i = 0; i < n; ++i) {
            if (CL(i) > gmax)
                continue; /* cannot happen: gmax is the largest group */
            double *ui = ug + (size_t)CL(i) * nf;
            for (unsigned k = 0; k < nf; ++k)
                ui[k] += J[i * nf + k] * r[i];
        }
        for (unsigned g = 0; g <= gmax; ++g) {
            const double *ua = ug + (size_t)g * nf; /* score of cluster g, (nf) */
            for (unsigned a = 0; a < nf; ++a)
                for (unsigned b = 0; b < nf; ++b)
                    M[a * nf + b] += ua[a] * ua[b];
        }
        free(ug);
        const double c = ((double)G / (G - 1.0)) * (((double)n - 1.0) / (dof > 0 ? dof : 1.0)) * cluster_factor(G);
        /* Cz = c Ap M Ap */
        double *T = calloc((size_t)nf * nf, sizeof *T);
        if (!T) {
            free(Ap);
            free(M);
            return -1;
        }
        for (unsigned a = 0; a < nf; ++a)
            for (unsigned k = 0; k < nf; ++k)
                for (unsigned b = 0; b < nf; ++b)
                    T[a * nf + b] += Ap[a * nf + k] * M[k * nf + b];
        for (unsigned a = 0; a < nf; ++a)
            for (unsigned b = 0; b < nf; ++b) {
                double v = 0.0;
                for (unsigned k = 0; k < nf; ++k)
                    v += T[a * nf + k] * Ap[k * nf + b];
                z->Cz[a * nf + b] = c * v;
            }
        /* Ap M Ap rounds differently in its two triangles (5e-9 relative on
         * the demo's weak wrist directions); an ellipsoid J Cz J^T cancels
         * those large terms down to 1e-5 of them, so the two triangles gave
         * map figures 2e-4 apart. Cz is symmetric: its mean with its transpose. */
        for (unsigned a = 0; a < nf; ++a)
            for (unsigned b = a + 1; b < nf; ++b) {
                const double v = 0.5 * (z->Cz[a * nf + b] + z->Cz[b * nf + a]);
                z->Cz[a * nf + b] = z->Cz[b * nf + a] = v;
            }
        free(T);
        u->kind = RCH_COV_CLUSTER;
        u->n_groups = G;
    } else {
        double s2 = u->sigma_mm * u->sigma_mm;
        for (size_t k = 0; k < (size_t)nf * nf; ++k)
            z->Cz[k] = s2 * Ap[k];
        u->kind = RCH_COV_CLASSICAL;
        u->n_groups = 0;
    }
    free(Ap);
    free(M);
    return 0;
}

/* Classes, standard errors and the parameter-space covariance. */
/* Does a step along direction d (scaled coordinates) move the flange
 * (position, or orientation at a 100 mm lever) at the poses s? Relative to
 * the largest such effect of any direction: below 1e-6 it does not (d2 - d3
 * of parallel joints moves nothing the robot does). rel_out (nf). */
/* Physical size of a parameter step: mm as they are, angles at a 500 mm
 * lever (the IRB120's reach), other units (effects) not counted. */
static double phys_weight(const rc_model *m, unsigned k)
{
    int unit = rc_param_unit(m, k);
    return unit == 0 ? 1.0 : unit == 1 ? 500.0 : 0.0;
}

/* FK effect (flange position, and orientation at a 100 mm lever) at up to
 * RCH_FKREL_POSES of the poses s of the parameter step h * u (u: n_params,
 * unscaled), divided by h, into g (RCH_FKREL_ROWS). Returns the poses used. */
#define RCH_FKREL_POSES 40
#define RCH_FKREL_ROWS (RCH_FKREL_POSES * 12)
static size_t fk_effect(double *g, const double *u, const rc_model *m, const rc_sample *s, size_t n)
{
    const double h = 1e-5;
    size_t step = n > RCH_FKREL_POSES ? n / RCH_FKREL_POSES : 1, row = 0, used = 0;
    memset(g, 0, RCH_FKREL_ROWS * sizeof *g);
    for (size_t i = 0; i < n && row + 12 <= RCH_FKREL_ROWS; i += step, ++used) {
        rc_model a = *m, b = *m;
        for (unsigned k = 0; k < m->n_params; ++k) {
            a.x[k] += h * u[k];
            b.x[k] -= h * u[k];
        }
        double pa[3], pb[3], Ra[9], Rb[9];
        rc_fk(pa, Ra, &a, s[i].q_rad);
        rc_fk(pb, Rb, &b, s[i].q_rad);
        for (int c = 0; c < 3; ++c)
            g[row++] = (pa[c] - pb[c]) / (2.0 * h);
        for (int c = 0; c < 9; ++c)
            g[row++] = 100.0 * (Ra[c] - Rb[c]) / (2.0 * h);
    }
    return used;
}

/* Parameters compensation must keep nominal. Within the span S of the weak
 * and not-identifiable directions (eigenvectors of a near-degenerate
 * eigenvalue are arbitrary mixtures of it, so single directions do not
 * tell), the FK effects of unit steps along an orthonormal basis of S give
 * G; the eigenvectors of G^T G split S into combinations that move the
 * flange and ones that do not. A combination that moves the flange by more
 * than 1e-3 mm (RMS over the poses) per mm of its physical size (mm, and
 * rad at a 500 mm lever) is undetermined for the robot, and every parameter
 * with a squared share >= RC_IDENT_SHARE (scaled coordinates) in those
 * combinations stays nominal. Combinations that move nothing the
 * robot does (d2 - d3 of the parallel joints 2 and 3) hold nothing.
 * Parameters weak by their standard error alone stay nominal too. */
static int comp_nominal(rch_uncert *u, const scaled *z, const rc_model *m, const rc_sample *s, size_t n)
{
    unsigned nf = z->nf, nn = 0, np = m->n_params, dir[RC_MAX_PARAMS];
    double *g = calloc((size_t)RCH_FKREL_ROWS * nf, sizeof *g), *U = calloc((size_t)nf * np, sizeof *U);
    double *M = calloc((size_t)nf * nf, sizeof *M), ev[RC_MAX_PARAMS];
    size_t used = 1;
    if (!g || !U || !M) {
        free(g);
        free(U);
        free(M);
        return -1;
    }
    for (unsigned d = 0; d < nf; ++d) {
        if (z->dir_class[d] == RC_IDENT_IDENTIFIABLE)
            continue;
        double *ud = U + (size_t)nn * np; /* a unit step in scaled coordinates, unscaled */
        for (unsigned a = 0; a < nf; ++a)
            ud[z->idx[a]] = z->V[a * nf + d] / z->D[a];
        used = fk_effect(g + (size_t)nn * RCH_FKREL_ROWS, ud, m, s, n);
        dir[nn++] = d;
    }
    for (unsigned a = 0; a < nn; ++a)
        for (unsigned b = 0; b < nn; ++b)
            for (unsigned r = 0; r < RCH_FKREL_ROWS; ++r)
                M[a * nn + b] += g[(size_t)a * RCH_FKREL_ROWS + r] * g[(size_t)b * RCH_FKREL_ROWS + r];
    if (nn > 0 && LAPACKE_dsyev(LAPACK_ROW_MAJOR, 'V', 'U', (lapack_int)nn, M, (lapack_int)nn, ev) != 0)
        nn = 0;
    double share[RC_MAX_PARAMS] = {0};
    for (unsigned e = 0; e < nn; ++e) {
        double c[RC_MAX_PARAMS], cn = 0.0; /* the combination, unscaled, and its physical size */
        for (unsigned k = 0; k < np; ++k) {
            c[k] = 0.0;
            for (unsigned j = 0; j < nn; ++j)
                c[k] += M[j * nn + e] * U[(size_t)j * np + k];
            cn += pow(c[k] * phys_weight(m, k), 2);
        }
        double moves = sqrt(fmax(ev[e], 0.0) / (double)used) / fmax(sqrt(cn), 1e-300);
        if (!(moves >= 1e-3))
            continue; /* moves nothing the robot does */
        for (unsigned a = 0; a < nf; ++a) {
            double w = 0.0; /* component of parameter a in the combination, scaled coordinates */
            for (unsigned j = 0; j < nn; ++j)
                w += z->V[a * nf + dir[j]] * M[j * nn + e];
            share[a] += w * w; /* the combinations are orthonormal: shares add */
        }
    }
    for (unsigned a = 0; a < nf; ++a)
        if (share[a] >= RC_IDENT_SHARE)
            u->comp_nominal[z->idx[a]] = 1;
    for (unsigned a = 0; a < nf; ++a)
        if (u->cls[z->idx[a]] == RCH_PARAM_WEAK)
            u->comp_nominal[z->idx[a]] = 1;
    /* a DH parameter the model file will call undetermined (a standard error
     * above 1 m or 1 rad, rch_robot_unc_undetermined) is held too, whatever
     * its null directions move: a share below RC_IDENT_SHARE of a weak
     * direction seen at 1e-3 of the strongest can still give it 60 deg
     * (alpha5 of compare's BC model on the real file); written "fitted",
     * every reader refused it */
    for (unsigned a = 0; a < nf; ++a) {
        const unsigned k = z->idx[a];
        const double lim = (k % 4 < 2) ? RCH_UNDETERMINED_MM2 : RCH_UNDETERMINED_RAD2;
        if (k < RC_N_DH && !(u->cov[(size_t)k * np + k] <= lim))
            u->comp_nominal[k] = 1;
    }
    free(g);
    free(U);
    free(M);
    return 0;
}

static void classify(rch_uncert *u, const scaled *z, const rc_model *m)
{
    unsigned nf = z->nf, np = u->n_params;
    for (unsigned d = 0; d < nf; ++d) {
        for (unsigned a = 0; a < nf; ++a) {
            double w = z->V[a * nf + d] * z->V[a * nf + d];
            unsigned k = z->idx[a];
            if (z->dir_class[d] == RC_IDENT_NONE)
                u->null_share[k] += w;
            else if (z->dir_class[d] == RC_IDENT_WEAK)
                u->weak_share[k] += w;
        }
    }
    for (unsigned k = 0; k < np; ++k)
        u->cls[k] = RCH_PARAM_FIXED;
    for (unsigned a = 0; a < nf; ++a) {
        unsigned k = z->idx[a];
        double se = sqrt(fmax(z->Cz[a * nf + a], 0.0)) / z->D[a];
        double tol = rc_param_unit(m, k) == 1 ? RCH_UNCERT_WEAK_RAD : RCH_UNCERT_WEAK_MM;
        if (u->has_prior) {
            /* the posterior: every parameter has a standard error; the class
             * says whether the data or the prior set it */
            u->se[k] = se;
            u->prior_cls[k] = (uint8_t)rch_prior_classify(se, u->prior_sd[k]);
            u->cls[k] = z->param_class[a] == RC_IDENT_NONE
                            ? RCH_PARAM_NOT_IDENTIFIABLE
                            : (z->param_class[a] == RC_IDENT_WEAK ? RCH_PARAM_WEAK : RCH_PARAM_IDENTIFIABLE);
        } else if (z->param_class[a] == RC_IDENT_NONE) {
            u->cls[k] = RCH_PARAM_NOT_IDENTIFIABLE;
            u->se[k] = NAN;
        } else {
            int weak = z->param_class[a] == RC_IDENT_WEAK || (rc_param_unit(m, k) != 2 && se > tol);
            u->cls[k] = weak ? RCH_PARAM_WEAK : RCH_PARAM_IDENTIFIABLE;
            u->se[k] = se;
        }
        for (unsigned b = 0; b < nf; ++b) {
            unsigned l = z->idx[b];
            u->cov[(size_t)k * np + l] = z->Cz[a * nf + b] / (z->D[a] * z->D[b]);
        }
    }
}

int rch_uncert_compute(rch_uncert *u, const rc_model *m, const uint8_t *fixed, const rc_sample *s, size_t n,
                       int want_cluster, char *err, size_t errlen)
{
    return rch_uncert_compute_cl(u, m, fixed, s, NULL, n, want_cluster, err, errlen);
}

int rch_uncert_compute_cl(rch_uncert *u, const rc_model *m, const uint8_t *fixed, const rc_sample *s,
                          const uint16_t *cl, size_t n, int want_cluster, char *err, size_t errlen)
{
    return rch_uncert_compute_map(u, m, fixed, s, cl, n, want_cluster, NULL, 0.0, err, errlen);
}

int rch_uncert_compute_map(rch_uncert *u, const rc_model *m, const uint8_t *fixed, const rc_sample *s,
                           const uint16_t *cl, size_t n, int want_cluster, const double *prior_sd, double noise_mm,
                           char *err, size_t errlen)
{
    memset(u, 0, sizeof *u);
    if (prior_sd && noise_mm > 0.0) {
        u->has_prior = 1;
        for (unsigned k = 0; k < m->n_params; ++k)
            u->prior_sd[k] = prior_sd[k] > 0.0 && isfinite(prior_sd[k]) ? prior_sd[k] : 0.0;
    }
    u->n_params = m->n_params;
    u->n_samples = n;
    scaled z;
    memset(&z, 0, sizeof z);
    for (unsigned k = 0; k < m->n_params; ++k)
        if (!fixed || !fixed[k])
            z.idx[z.nf++] = k;
    u->nf = z.nf;
    if (z.nf == 0 || n <= z.nf) {
        snprintf(err, errlen, "uncertainty needs more samples (%zu) than free parameters (%u)", n, z.nf);
        return -1;
    }
    size_t np = m->n_params, nf = z.nf;
    rch_jac jac;
    double *J = NULL, *r = NULL, *A = calloc(nf * nf, sizeof *A);
    double *V = calloc(nf * nf, sizeof *V), *Cz = calloc(nf * nf, sizeof *Cz);
    z.V = V;
    z.Cz = Cz;
    u->cov = calloc(np * np, sizeof *u->cov);
    int rc = -1;
    memset(&jac, 0, sizeof jac);
    if (!A || !V || !Cz || !u->cov) {
        snprintf(err, errlen, "out of memory");
        goto done;
    }
    {
        uint16_t cols[RC_MAX_PARAMS];
        for (unsigned k = 0; k < z.nf; ++k)
            cols[k] = (uint16_t)z.idx[k];
        if (rch_jac_eval(&jac, m, cols, z.nf, s, n, err, errlen) != 0) /* the Jacobian at the solution */
            goto done;
        rch_jac_scale_columns(&jac, z.D);
        J = jac.J;
        r = jac.r;
    }
    for (size_t i = 0; i < n; ++i)
        for (size_t a = 0; a < nf; ++a)
            for (size_t b = a; b < nf; ++b)
                A[a * nf + b] += J[i * nf + a] * J[i * nf + b];
    for (size_t a = 0; a < nf; ++a)
        for (size_t b = 0; b < a; ++b)
            A[a * nf + b] = A[b * nf + a];
    memcpy(z.V, A, nf * nf * sizeof *A);
    if (LAPACKE_dsyev(LAPACK_ROW_MAJOR, 'V', 'U', (lapack_int)nf, z.V, (lapack_int)nf, z.ev) != 0) {
        snprintf(err, errlen, "eigen-decomposition of the normal matrix failed");
        goto done;
    }
    if (ident(&z, n) != 0) {
        snprintf(err, errlen, "the identifiability analysis failed (non-finite normal matrix)");
        goto done;
    }
    if (u->has_prior) {
        double psd[RC_MAX_PARAMS];
        for (unsigned a = 0; a < z.nf; ++a)
            psd[a] = u->prior_sd[z.idx[a]] * z.D[a];
        if (covariance_map(&z, u, A, J, r, s, cl, n, want_cluster, psd, noise_mm) != 0) {
            snprintf(err, errlen, "the posterior covariance failed (out of memory or not positive definite)");
            goto done;
        }
    } else if (covariance(&z, u, J, r, s, cl, n, want_cluster) != 0) {
        snprintf(err, errlen, "out of memory");
        goto done;
    }
    classify(u, &z, m);
    /* with a prior compensation uses the whole estimate: the posterior
     * already weighs what the data did not determine toward nominal */
    if (!u->has_prior && comp_nominal(u, &z, m, s, n) != 0) {
        snprintf(err, errlen, "out of memory");
        goto done;
    }
    rc = 0;
done:
    rch_jac_free(&jac);
    free(A);
    free(V);
    free(Cz);
    if (rc != 0)
        rch_uncert_free(u);
    return rc;
}

void rch_uncert_determined(rc_model *out, const rc_model *fit, const rc_model *nominal, const rch_uncert *u)
{
    *out = *fit;
    for (unsigned k = 0; k < u->n_params && k < RC_N_DH; ++k)
        if (u->comp_nominal[k])
            out->x[k] = nominal->x[k];
}
