/* SPDX-License-Identifier: MIT */
/* rch_poses_order.c - a plan ordered for travel (rch_poses_order, see
 * rch_poses.h; issue 48 item 5), called once after the selection.
 *
 * The travel metric: a move costs the largest joint excursion,
 * max_j |dq_j| (deg): a joint move (MoveAbsJ, movej) drives every joint at
 * once, synchronised, so its time is set by the joint that travels most
 * (at comparable joint speeds); a sum over joints would charge a move in
 * which all joints turn together six times what it takes. A plan's travel
 * is the sum of its moves over its sessions (the rows of one outlet and one
 * plate point are one `rcal acquire` run), each from home (q = 0, inside
 * the limits less the margin) to its first row, then row to row.
 *
 * The tour, per outlet (its poses; the same pose on each plate point is one
 * stop, its rows kept together): nearest neighbour from home, then 2-opt on
 * the open path (the start fixed at home, the end free) until no reversal
 * shortens it or RCH_POSES_ORDER_MAX_PASSES passes; a joint whose range
 * spans more than 360 deg counts the shorter way round. Then the branches:
 * such a joint may take q + 360 k within the limits less the margin (the
 * same robot pose: the FK and the cable length are unchanged); along the
 * tour the combination of branches minimising the travel is chosen by
 * dynamic programming (at most RCH_POSES_ORDER_MAX_STATES combinations a
 * pose; beyond that each joint takes the branch nearest the previous pose).
 * An outlet's new order is kept only when it travels less than the input.
 * Cost: O(U^2) per 2-opt pass for U poses (1000 poses: a few ms a pass).
 * Memory: heap, freed before return. Errors: -1 with d set (out of memory). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "rch_poses_int.h"

#define RCH_POSES_ORDER_MAX_PASSES 100
#define RCH_POSES_ORDER_MAX_STATES 64
#define MAX_BRANCHES 5 /* q + 360 k, k = -2..2 */

/* home: q = 0 clamped into the limits less the margin (radians). */
static void home_q(double home[RC_NJ], const rc_model *m, double margin_rad)
{
    for (int j = 0; j < RC_NJ; ++j) {
        const double lo = m->q_min_rad[j] + margin_rad, hi = m->q_max_rad[j] - margin_rad;
        home[j] = lo > 0.0 ? lo : hi < 0.0 ? hi : 0.0;
    }
}

static double move_deg(const double *a, const double *b)
{
    double mx = 0.0;
    for (int j = 0; j < RC_NJ; ++j) {
        const double d = fabs(a[j] - b[j]);
        mx = d > mx ? d : mx;
    }
    return mx * 180.0 / PI_;
}

/* The travel of rows over the sessions (outlet, target) from home (deg). */
static double travel_from(const rc_sample *rows, size_t n, const double home[RC_NJ])
{
    unsigned char done[256][256 / 8];
    double sum = 0.0;
    memset(done, 0, sizeof done);
    for (size_t i = 0; i < n; ++i) {
        const unsigned o = rows[i].outlet, t = rows[i].target;
        if (done[o][t / 8] & (1u << (t % 8)))
            continue;
        done[o][t / 8] |= (unsigned char)(1u << (t % 8));
        const double *prev = home;
        for (size_t k = i; k < n; ++k)
            if (rows[k].outlet == o && rows[k].target == t) {
                sum += move_deg(prev, rows[k].q_rad);
                prev = rows[k].q_rad;
            }
    }
    return sum;
}

double rch_poses_travel_deg(const rc_sample *rows, size_t n, const rc_model *m, double margin_deg)
{
    double home[RC_NJ];
    home_q(home, m, margin_deg * PI_ / 180.0);
    return travel_from(rows, n, home);
}

/* The tour's work: the stops (poses) of one outlet. */
typedef struct order_work {
    size_t U;
    double (*q)[RC_NJ]; /* (U) each stop's joints as planned */
    int wrap[RC_NJ];    /* the joint's range spans more than 360 deg */
    double home[RC_NJ];
} order_work;

/* The tour's distance: the move with the wrapping joints the shorter way round (a lower bound of the move
 * with the best branches). */
static double tour_dist(const order_work *w, const double *a, const double *b)
{
    double mx = 0.0;
    for (int j = 0; j < RC_NJ; ++j) {
        double d = fabs(a[j] - b[j]);
        if (w->wrap[j]) {
            d = fmod(d, 2.0 * PI_);
            d = d > PI_ ? 2.0 * PI_ - d : d;
        }
        mx = d > mx ? d : mx;
    }
    return mx;
}

static const double *stop_q(const order_work *w, const size_t *tour, size_t i)
{
    return w->q[tour[i]];
}

/* Nearest neighbour from home, then 2-opt on the open path (home fixed, end free). */
static void make_tour(size_t *tour, const order_work *w, unsigned char *used)
{
    const double *cur = w->home;
    memset(used, 0, w->U);
    for (size_t i = 0; i < w->U; ++i) {
        size_t best = 0;
        double bd = INFINITY;
        for (size_t u = 0; u < w->U; ++u)
            if (!used[u]) {
                const double d = tour_dist(w, cur, w->q[u]);
                if (d < bd) {
                    bd = d;
                    best = u;
                }
            }
        used[best] = 1;
        tour[i] = best;
        cur = w->q[best];
    }
    for (int pass = 0; pass < RCH_POSES_ORDER_MAX_PASSES; ++pass) {
        int improved = 0;
        for (size_t i = 0; i + 1 < w->U; ++i) {
            const double *a = i ? stop_q(w, tour, i - 1) : w->home;
            for (size_t k = i + 1; k < w->U; ++k) {
                /* reverse tour[i..k]: edges (a, t_i) and (t_k, t_k+1) become (a, t_k) and (t_i, t_k+1) */
                const double *ti = stop_q(w, tour, i), *tk = stop_q(w, tour, k);
                double before = tour_dist(w, a, ti), after = tour_dist(w, a, tk);
                if (k + 1 < w->U) {
                    const double *tn = stop_q(w, tour, k + 1);
                    before += tour_dist(w, tk, tn);
                    after += tour_dist(w, ti, tn);
                }
                if (after < before - 1e-12) {
                    for (size_t l = i, r = k; l < r; ++l, --r) {
                        const size_t t = tour[l];
                        tour[l] = tour[r];
                        tour[r] = t;
                    }
                    improved = 1;
                }
            }
        }
        if (!improved)
            break;
    }
}

/* A joint's branches at q: q + 360 k inside [lo, hi], q itself first. */
static unsigned branches(double *out, double q, int wrap, double lo, double hi)
{
    unsigned n = 0;
    out[n++] = q;
    for (int k = -2; wrap && k <= 2; ++k) {
        const double v = q + 2.0 * PI_ * k;
        if (k != 0 && v >= lo - 1e-9 && v <= hi + 1e-9)
            out[n++] = v;
    }
    return n;
}

/* The branch combination s of stop q (nb, br: each joint's branches) into out. */
static void state_q(double *out, const unsigned *nb, double br[RC_NJ][MAX_BRANCHES], unsigned s)
{
    for (int j = 0; j < RC_NJ; ++j) {
        out[j] = br[j][s % nb[j]];
        s /= nb[j];
    }
}

static unsigned stop_branches(unsigned *nb, double br[RC_NJ][MAX_BRANCHES], const order_work *w, const double *q,
                              const rc_model *m, double margin_rad)
{
    unsigned ns = 1;
    for (int j = 0; j < RC_NJ; ++j) {
        nb[j] = branches(br[j], q[j], w->wrap[j], m->q_min_rad[j] + margin_rad, m->q_max_rad[j] - margin_rad);
        ns *= nb[j];
    }
    return ns;
}

/* The branches along the tour: out (U x 6) the joints chosen for each stop in tour order. Dynamic programming
 * over the combinations (or, beyond RCH_POSES_ORDER_MAX_STATES of them, the branch nearest the previous stop). 0
 * or -1 (memory). */
static int choose_branches(double (*out)[RC_NJ], const order_work *w, const size_t *tour, const rc_model *m,
                           double margin_rad)
{
    const unsigned S = RCH_POSES_ORDER_MAX_STATES;
    double *cost = malloc(2 * S * sizeof *cost);
    unsigned char *back = malloc((w->U ? w->U : 1) * S);
    unsigned *state = malloc((w->U ? w->U : 1) * sizeof *state);
    int greedy = 0;
    if (!cost || !back || !state) {
        free(cost);
        free(back);
        free(state);
        return -1;
    }
    unsigned nb[RC_NJ], pnb[RC_NJ], ns = 1, pns = 1;
    double br[RC_NJ][MAX_BRANCHES], pbr[RC_NJ][MAX_BRANCHES];
    for (int j = 0; j < RC_NJ; ++j) { /* the home as the one state before the first stop */
        pnb[j] = 1;
        pbr[j][0] = w->home[j];
    }
    double *pc = cost, *cc = cost + S;
    pc[0] = 0.0;
    for (size_t i = 0; i < w->U && !greedy; ++i) {
        ns = stop_branches(nb, br, w, w->q[tour[i]], m, margin_rad);
        if (ns > S) {
            greedy = 1;
            break;
        }
        for (unsigned s = 0; s < ns; ++s) {
            double qs[RC_NJ], qp[RC_NJ];
            state_q(qs, nb, br, s);
            cc[s] = INFINITY;
            for (unsigned p = 0; p < pns; ++p) {
                state_q(qp, pnb, pbr, p);
                const double c = pc[p] + move_deg(qp, qs);
                if (c < cc[s]) {
                    cc[s] = c;
                    back[i * S + s] = (unsigned char)p;
                }
            }
        }
        double *t = pc;
        pc = cc;
        cc = t;
        pns = ns;
        memcpy(pnb, nb, sizeof nb);
        memcpy(pbr, br, sizeof br);
    }
    if (!greedy && w->U) {
        unsigned s = 0;
        for (unsigned k = 1; k < pns; ++k)
            if (pc[k] < pc[s])
                s = k;
        for (size_t i = w->U; i-- > 0;) {
            state[i] = s;
            s = back[i * S + s];
        }
        for (size_t i = 0; i < w->U; ++i) {
            stop_branches(nb, br, w, w->q[tour[i]], m, margin_rad);
            state_q(out[i], nb, br, state[i]);
        }
    } else if (greedy) {
        const double *prev = w->home;
        for (size_t i = 0; i < w->U; ++i) {
            stop_branches(nb, br, w, w->q[tour[i]], m, margin_rad);
            for (int j = 0; j < RC_NJ; ++j) {
                unsigned b = 0;
                for (unsigned k = 1; k < nb[j]; ++k)
                    if (fabs(br[j][k] - prev[j]) < fabs(br[j][b] - prev[j]))
                        b = k;
                out[i][j] = br[j][b];
            }
            prev = out[i];
        }
    }
    free(cost);
    free(back);
    free(state);
    return 0;
}

/* One outlet's rows (idx, n of them, in file order) reordered into dst; *moved 1 when the order changed. */

/* Whether two poses' joints are the same values (a pose on each plate point repeats them exactly). */
static int same_q(const double *a, const double *b)
{
    for (unsigned j = 0; j < RC_NJ; ++j)
        if (a[j] != b[j]) /* NOLINT(clang-diagnostic-float-equal): the same row copied, not a computed value */
            return 0;
    return 1;
}

static int order_outlet(rc_sample *dst, const rc_sample *rows, const size_t *idx, size_t n, order_work *w,
                        const rc_model *m, double margin_rad, int *moved)
{
    size_t *start = malloc((n + 1) * sizeof *start), *tour = malloc((n ? n : 1) * sizeof *tour);
    unsigned char *used = malloc(n ? n : 1);
    double(*bq)[RC_NJ] = malloc((n ? n : 1) * sizeof *bq);
    w->q = malloc((n ? n : 1) * sizeof *w->q);
    int rc = -1;
    if (!start || !tour || !used || !bq || !w->q)
        goto out;
    w->U = 0; /* the stops: runs of rows with the same joints (the pose on each plate point) */
    for (size_t i = 0; i < n; ++i)
        if (i == 0 || !same_q(rows[idx[i]].q_rad, rows[idx[i - 1]].q_rad)) {
            start[w->U] = i;
            memcpy(w->q[w->U++], rows[idx[i]].q_rad, sizeof w->q[0]);
        }
    start[w->U] = n;
    make_tour(tour, w, used);
    if (choose_branches(bq, w, tour, m, margin_rad) != 0)
        goto out;
    size_t o = 0;
    for (size_t u = 0; u < w->U; ++u)
        for (size_t r = start[tour[u]]; r < start[tour[u] + 1]; ++r) {
            dst[o] = rows[idx[r]];
            memcpy(dst[o++].q_rad, bq[u], sizeof bq[u]);
        }
    /* keep the input order unless the tour travels less */
    rc_sample *orig = malloc((n ? n : 1) * sizeof *orig);
    if (!orig)
        goto out;
    for (size_t i = 0; i < n; ++i)
        orig[i] = rows[idx[i]];
    *moved = travel_from(dst, n, w->home) < travel_from(orig, n, w->home);
    if (!*moved)
        memcpy(dst, orig, n * sizeof *orig);
    free(orig);
    rc = 0;
out:
    free(start);
    free(tour);
    free(used);
    free(bq);
    free(w->q);
    w->q = NULL;
    return rc;
}

/* Each joint's smallest and largest value over the rows (deg). */
static void span(double *lo, double *hi, const rc_sample *rows, size_t n)
{
    for (int j = 0; j < RC_NJ; ++j) {
        lo[j] = n ? INFINITY : 0.0;
        hi[j] = n ? -INFINITY : 0.0;
        for (size_t i = 0; i < n; ++i) {
            const double a = rows[i].q_rad[j] * 180.0 / PI_;
            lo[j] = a < lo[j] ? a : lo[j];
            hi[j] = a > hi[j] ? a : hi[j];
        }
    }
}

void rch_poses_travel_of(rch_poses_travel *tr, const rc_sample *rows, size_t n, const rc_model *m,
                         double margin_deg)
{
    memset(tr, 0, sizeof *tr);
    tr->before_deg = tr->after_deg = rch_poses_travel_deg(rows, n, m, margin_deg);
    span(tr->before_min_deg, tr->before_max_deg, rows, n);
    span(tr->after_min_deg, tr->after_max_deg, rows, n);
}

int rch_poses_order(rc_sample *rows, size_t n, const rc_model *m, double margin_deg, rch_poses_travel *tr,
                    rch_diag *d)
{
    order_work w;
    const double margin_rad = margin_deg * PI_ / 180.0;
    memset(&w, 0, sizeof w);
    memset(tr, 0, sizeof *tr);
    home_q(w.home, m, margin_rad);
    for (int j = 0; j < RC_NJ; ++j)
        w.wrap[j] = m->q_max_rad[j] - m->q_min_rad[j] - 2.0 * margin_rad > 2.0 * PI_;
    tr->before_deg = travel_from(rows, n, w.home);
    span(tr->before_min_deg, tr->before_max_deg, rows, n);
    rc_sample *out = malloc((n ? n : 1) * sizeof *out);
    size_t *idx = malloc((n ? n : 1) * sizeof *idx);
    if (!out || !idx) {
        free(out);
        free(idx);
        rch_diag_set(d, "", 0, 0, "ordering %zu plan rows for travel: out of memory", n);
        return -1;
    }
    unsigned char seen[256] = {0};
    size_t o = 0;
    for (size_t i = 0; i < n; ++i) { /* each outlet's rows in turn, in the order the outlets first appear */
        const unsigned k = rows[i].outlet;
        if (seen[k])
            continue;
        seen[k] = 1;
        size_t c = 0;
        for (size_t l = i; l < n; ++l)
            if (rows[l].outlet == k)
                idx[c++] = l;
        int moved = 0;
        if (order_outlet(out + o, rows, idx, c, &w, m, margin_rad, &moved) != 0) {
            free(out);
            free(idx);
            rch_diag_set(d, "", 0, 0, "ordering %zu plan rows for travel: out of memory", n);
            return -1;
        }
        tr->outlets_reordered += (unsigned)moved;
        o += c;
    }
    memcpy(rows, out, n * sizeof *out);
    free(out);
    free(idx);
    tr->after_deg = travel_from(rows, n, w.home);
    span(tr->after_min_deg, tr->after_max_deg, rows, n);
    return 0;
}
