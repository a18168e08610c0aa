/* cmd_poses.c - rcal poses: plan an identifiable pose set.
 *
 * Method (D-optimal design, greedy start + Fedorov exchange):
 *  1. draw --candidates random poses uniformly inside the joint limits (less
 *     --margin-deg) whose nominal cable length lies in [--len-min-mm,
 *     --len-max-mm], the range the encoder reaches;
 *  2. one row per candidate of the identification Jacobian d l / d x (rc_meas,
 *     nominal model with the encoder position), each column scaled by its
 *     RMS over the candidates so that mm and rad compare;
 *  3. keep the identifiable parameter subset: pivoted Gram-Schmidt on the
 *     scaled columns drops those that are combinations of others (alpha6; the
 *     base heading/height vs the encoder; d2 vs d3) - r columns remain;
 *  4. maximise log det(J_S^T J_S) over N poses: greedy additions (each adds the
 *     candidate with the largest x^T A^-1 x), then exchange passes that swap a
 *     chosen pose for a candidate while the determinant grows.
 * The plan is reported with the observability index O1 = (prod s_i)^(1/r) /
 * sqrt(N) of rch_ident (the same figure `rcal calibrate` prints) beside that
 * of N random poses from the same candidates. Collisions of the cable with
 * the arm are not modelled: review the plan before running it on a robot.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rc_rand.h"
#include "rcal_cmds.h"
#include "rcal_opts.h"
#include "rch_ident.h"
#include "rch_robot.h"

#define PI_ 3.14159265358979323846

static void usage(FILE *f)
{
    fprintf(f,
            "usage: rcal poses --count N --out POSES.csv [--robot MODEL.json] [--seed S] [--encoder X,Y,Z]\n"
            "                  [--len-min-mm A] [--len-max-mm B] [--candidates M] [--margin-deg D] [--passes P]\n"
            "  Plans N poses inside the joint limits of MODEL (default %s) less --margin-deg (5) whose\n"
            "  cable length (encoder at the file's encoder_mm, else --encoder, default 250,-460,10 mm) is within\n"
            "  [--len-min-mm 250, --len-max-mm 800], chosen among M random candidates (default max(2000, 40 N))\n"
            "  to maximise det(J^T J) of the identifiable parameters (greedy + exchange, --passes 4).\n"
            "  Writes pose,q1..q6 (degrees, 0.01 deg steps); prints the observability index O1 beside that of\n"
            "  a random plan of the same size.\n",
            RCAL_DEFAULT_ROBOT);
}

/* Cholesky of the r x r matrix A (row-major) into L; log det or -inf. */
static double chol(double *L, const double *A, unsigned r)
{
    double ld = 0;
    for (unsigned i = 0; i < r; ++i)
        for (unsigned j = 0; j <= i; ++j) {
            double s = A[i * r + j];
            for (unsigned k = 0; k < j; ++k)
                s -= L[i * r + k] * L[j * r + k];
            if (i == j) {
                if (!(s > 0))
                    return -INFINITY;
                L[i * r + i] = sqrt(s);
                ld += 2.0 * log(L[i * r + i]);
            } else {
                L[i * r + j] = s / L[j * r + j];
            }
        }
    return ld;
}

/* x^T A^-1 x with A = L L^T: |L^-1 x|^2. tmp: (r). */
static double quad(const double *L, const double *x, double *tmp, unsigned r)
{
    double q = 0;
    for (unsigned i = 0; i < r; ++i) {
        double s = x[i];
        for (unsigned k = 0; k < i; ++k)
            s -= L[i * r + k] * tmp[k];
        tmp[i] = s / L[i * r + i];
        q += tmp[i] * tmp[i];
    }
    return q;
}

static void add_outer(double *A, const double *x, double w, unsigned r)
{
    for (unsigned i = 0; i < r; ++i)
        for (unsigned j = 0; j < r; ++j)
            A[i * r + j] += w * x[i] * x[j];
}

static double observability(const rc_model *m, const rc_sample *c, const size_t *idx, size_t n, unsigned *rank)
{
    rc_sample *s = malloc(n * sizeof *s);
    rch_ident *id = calloc(1, sizeof *id);
    double o = -1;
    if (s && id) {
        for (size_t i = 0; i < n; ++i)
            s[i] = c[idx[i]];
        if (rch_ident_compute(id, m, s, n) == 0) {
            o = id->observability;
            *rank = id->rank;
        }
    }
    free(s);
    free(id);
    return o;
}

int rcal_cmd_poses(int argc, char **argv)
{
    const char *robot_path = RCAL_DEFAULT_ROBOT, *out_path = NULL;
    unsigned long n = 0, seed = 1, n_cand = 0, passes = 4;
    double len_min = 250, len_max = 800, margin_deg = 5, enc[3] = {250.0, -460.0, 10.0};
    rch_robot *robot = NULL;
    rch_diag dg;
    char dbuf[900];
    rc_sample *cand = NULL;
    double *G = NULL, *X = NULL, *A = NULL, *L = NULL, *tmp = NULL, *scale = NULL;
    size_t *design = NULL, *rnd = NULL;
    unsigned char *in_design = NULL;
    unsigned *cols = NULL, r = 0, P;
    rc_rng g;
    int rc = 1;
    FILE *out = NULL;

    for (int i = 1; i < argc; ++i) {
        if (rcal_opt_str(argc, argv, &i, "--robot", &robot_path) || rcal_opt_str(argc, argv, &i, "--out", &out_path) ||
            rcal_opt_triple(argc, argv, &i, "--encoder", enc) || rcal_opt_uint(argc, argv, &i, "--count", &n) ||
            rcal_opt_uint(argc, argv, &i, "--seed", &seed) || rcal_opt_uint(argc, argv, &i, "--candidates", &n_cand) ||
            rcal_opt_uint(argc, argv, &i, "--passes", &passes) ||
            rcal_opt_double(argc, argv, &i, "--len-min-mm", &len_min) ||
            rcal_opt_double(argc, argv, &i, "--len-max-mm", &len_max) ||
            rcal_opt_double(argc, argv, &i, "--margin-deg", &margin_deg))
            continue;
        if (strcmp(argv[i], "--help") == 0 || strcmp(argv[i], "-h") == 0) {
            usage(stdout);
            return 0;
        }
        return rcal_opt_unknown("poses", argv[i]);
    }
    if (!out_path)
        return rcal_opt_missing("poses", "--out");
    if (n < 1 || n > 100000) {
        fprintf(stderr, "rcal poses: --count must be 1..100000\n");
        return 2;
    }
    if (!(len_min < len_max) || margin_deg < 0) {
        fprintf(stderr, "rcal poses: need --len-min-mm < --len-max-mm and --margin-deg >= 0\n");
        return 2;
    }
    if (!n_cand)
        n_cand = n * 40 > 2000 ? n * 40 : 2000;
    if (n_cand < n) {
        fprintf(stderr, "rcal poses: --candidates must be at least --count\n");
        return 2;
    }
    robot = calloc(1, sizeof *robot);
    if (!robot || rch_robot_load(robot, robot_path, &dg) != 0) {
        fprintf(stderr, "rcal poses: %s\n", robot ? rch_diag_str(&dg, dbuf, sizeof dbuf) : "out of memory");
        goto done;
    }
    if (!robot->has_encoder)
        memcpy(&robot->model.x[RC_P_ENC], enc, sizeof enc);
    P = robot->model.n_params;
    cand = malloc(n_cand * sizeof *cand);
    G = malloc(n_cand * P * sizeof *G);
    scale = calloc(P, sizeof *scale);
    cols = malloc(P * sizeof *cols);
    design = malloc(n * sizeof *design);
    rnd = malloc(n * sizeof *rnd);
    in_design = calloc(n_cand, 1);
    if (!cand || !G || !scale || !cols || !design || !rnd || !in_design) {
        fprintf(stderr, "rcal poses: out of memory\n");
        goto done;
    }
    /* 1-2: candidates and their Jacobian rows */
    rc_rng_seed(&g, seed);
    {
        size_t got = 0, tries = 0;
        const double mg = margin_deg * PI_ / 180.0;
        while (got < n_cand) {
            rc_sample s;
            double len;
            if (++tries > 1000 * (size_t)n_cand) {
                fprintf(stderr, "rcal poses: only %zu of %lu candidate poses have a cable length within [%g, %g] mm; "
                                "check --encoder and the length range\n", got, n_cand, len_min, len_max);
                goto done;
            }
            memset(&s, 0, sizeof s);
            for (int j = 0; j < RC_NJ; ++j) {
                double lo = robot->model.q_min_rad[j] + mg, hi = robot->model.q_max_rad[j] - mg;
                double q = lo + (hi - lo) * rc_rng_u01(&g);
                s.q_rad[j] = round(q * 180.0 / PI_ * 100.0) / 100.0 * PI_ / 180.0; /* 0.01 deg */
            }
            if (rc_meas(&len, G + got * P, &robot->model, &s) != RC_OK || !(len >= len_min && len <= len_max))
                continue;
            cand[got++] = s;
        }
    }
    for (unsigned j = 0; j < P; ++j) {
        double ss = 0;
        for (size_t i = 0; i < n_cand; ++i)
            ss += G[i * P + j] * G[i * P + j];
        scale[j] = ss > 0 ? 1.0 / sqrt(ss / (double)n_cand) : 0.0;
    }
    /* 3: identifiable columns by pivoted Gram-Schmidt over the candidates */
    {
        double *Q = malloc(n_cand * P * sizeof *Q), first = 0;
        unsigned char *used = calloc(P, 1);
        if (!Q || !used) {
            free(Q);
            free(used);
            goto done;
        }
        for (size_t i = 0; i < n_cand; ++i)
            for (unsigned j = 0; j < P; ++j)
                Q[i * P + j] = G[i * P + j] * scale[j];
        for (;;) {
            unsigned best = P;
            double bn = 0;
            for (unsigned j = 0; j < P; ++j) {
                double s2 = 0;
                if (used[j])
                    continue;
                for (size_t i = 0; i < n_cand; ++i)
                    s2 += Q[i * P + j] * Q[i * P + j];
                if (s2 > bn) {
                    bn = s2;
                    best = j;
                }
            }
            if (best == P)
                break;
            if (r == 0)
                first = sqrt(bn);
            if (sqrt(bn) < 1e-6 * first)
                break;
            used[best] = 1;
            cols[r++] = best;
            for (unsigned j = 0; j < P; ++j) { /* remove the chosen direction */
                double dot = 0, nb = sqrt(bn);
                if (used[j])
                    continue;
                for (size_t i = 0; i < n_cand; ++i)
                    dot += Q[i * P + j] * Q[i * P + best] / nb;
                for (size_t i = 0; i < n_cand; ++i)
                    Q[i * P + j] -= dot * Q[i * P + best] / nb;
            }
        }
        free(Q);
        free(used);
    }
    X = malloc(n_cand * r * sizeof *X);
    A = calloc((size_t)r * r, sizeof *A);
    L = calloc((size_t)r * r, sizeof *L);
    tmp = malloc((r ? r : 1) * sizeof *tmp);
    if (!X || !A || !L || !tmp)
        goto done;
    for (size_t i = 0; i < n_cand; ++i)
        for (unsigned k = 0; k < r; ++k)
            X[i * r + k] = G[i * P + cols[k]] * scale[cols[k]];
    /* 4a: greedy D-optimal start (a tiny ridge keeps A invertible early on) */
    {
        const double ridge = 1e-6;
        for (unsigned k = 0; k < r; ++k)
            A[k * r + k] = ridge;
        for (size_t t = 0; t < n; ++t) {
            size_t best = 0;
            double bq = -1;
            chol(L, A, r);
            for (size_t i = 0; i < n_cand; ++i) {
                double q;
                if (in_design[i])
                    continue;
                q = quad(L, X + i * r, tmp, r);
                if (q > bq) {
                    bq = q;
                    best = i;
                }
            }
            design[t] = best;
            in_design[best] = 1;
            add_outer(A, X + best * r, 1.0, r);
        }
        /* 4b: exchange passes */
        for (unsigned long pass = 0; pass < passes; ++pass) {
            unsigned swaps = 0;
            for (size_t t = 0; t < n; ++t) {
                double ld_now = chol(L, A, r), ld_minus, q_out;
                size_t best = n_cand;
                double bq = -1;
                q_out = quad(L, X + design[t] * r, tmp, r);
                (void)q_out;
                add_outer(A, X + design[t] * r, -1.0, r);
                ld_minus = chol(L, A, r);
                if (!isfinite(ld_minus)) {
                    add_outer(A, X + design[t] * r, 1.0, r);
                    continue;
                }
                for (size_t i = 0; i < n_cand; ++i) {
                    double q;
                    if (in_design[i])
                        continue;
                    q = quad(L, X + i * r, tmp, r);
                    if (q > bq) {
                        bq = q;
                        best = i;
                    }
                }
                /* det(A- + x x^T) = det(A-) (1 + x^T A-^-1 x) */
                if (best < n_cand && ld_minus + log1p(bq) > ld_now + 1e-9) {
                    in_design[design[t]] = 0;
                    design[t] = best;
                    in_design[best] = 1;
                    ++swaps;
                }
                add_outer(A, X + design[t] * r, 1.0, r);
            }
            if (!swaps)
                break;
        }
    }
    /* report: O1 of the plan and of a random plan of the same size */
    {
        unsigned rank_opt = 0, rank_rnd = 0;
        double o_opt, o_rnd;
        rc_rng g2;
        rc_rng_seed(&g2, seed ^ 0x9E3779B97F4A7C15ull);
        memset(in_design, 0, n_cand);
        for (size_t t = 0; t < n; ++t) { /* n distinct random candidates */
            size_t i;
            do
                i = rc_rng_below(&g2, (uint32_t)n_cand);
            while (in_design[i]);
            in_design[i] = 1;
            rnd[t] = i;
        }
        o_opt = observability(&robot->model, cand, design, n, &rank_opt);
        o_rnd = observability(&robot->model, cand, rnd, n, &rank_rnd);
        printf("rcal poses: %lu poses from %lu candidates, %u identifiable parameters of %u\n", n, n_cand, r, P);
        printf("  observability O1 (rch_ident): planned %.5g (rank %u), random %.5g (rank %u), ratio %.2f\n", o_opt,
               rank_opt, o_rnd, rank_rnd, o_rnd > 0 ? o_opt / o_rnd : 0.0);
    }
    out = fopen(out_path, "w");
    if (!out) {
        fprintf(stderr, "rcal poses: cannot write %s\n", out_path);
        goto done;
    }
    fprintf(out, "pose,q1,q2,q3,q4,q5,q6\n");
    for (size_t t = 0; t < n; ++t) {
        fprintf(out, "%zu", t);
        for (int j = 0; j < RC_NJ; ++j)
            fprintf(out, ",%.4f", cand[design[t]].q_rad[j] * 180.0 / PI_);
        fprintf(out, "\n");
    }
    if (fclose(out) != 0) {
        fprintf(stderr, "rcal poses: writing %s failed\n", out_path);
        goto done;
    }
    printf("  written to %s\n", out_path);
    rc = 0;
done:
    free(robot);
    free(cand);
    free(G);
    free(X);
    free(A);
    free(L);
    free(tmp);
    free(scale);
    free(cols);
    free(design);
    free(rnd);
    free(in_design);
    return rc;
}
