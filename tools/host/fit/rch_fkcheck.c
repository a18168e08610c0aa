/* SPDX-License-Identifier: MIT */
/* rch_fkcheck.c - the nominal FK against the file's x, y, z, rounding told
 * from faults (see rch_fkcheck.h). */
#include "rch_fkcheck.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rch_data.h"
#include "rch_robot.h"
#include "rch_stats.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif
#define DEG (M_PI / 180.0)

/* Largest joint change (deg) of the minimum-norm dq = J^T (J J^T)^-1 dp that
 * moves the flange by dp, over the position rows of the joint Jacobian. */
static double explaining_dq_deg(const double jac[36], const double dp[3])
{
    double M[9], y[3] = {0, 0, 0}, dq_max = 0.0;
    for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) {
            double s = 0.0;
            for (int k = 0; k < 6; ++k)
                s += jac[6 * a + k] * jac[6 * b + k];
            M[3 * a + b] = s;
        }
    const double det = M[0] * (M[4] * M[8] - M[5] * M[7]) - M[1] * (M[3] * M[8] - M[5] * M[6]) +
                       M[2] * (M[3] * M[7] - M[4] * M[6]);
    if (fabs(det) > 1e-12) { /* Cramer's rule on the 3x3 system M y = dp */
        for (int c = 0; c < 3; ++c) {
            double T[9];
            memcpy(T, M, sizeof T);
            for (int a = 0; a < 3; ++a)
                T[3 * a + c] = dp[a];
            y[c] = (T[0] * (T[4] * T[8] - T[5] * T[7]) - T[1] * (T[3] * T[8] - T[5] * T[6]) +
                    T[2] * (T[3] * T[7] - T[4] * T[6])) / det;
        }
    }
    for (int k = 0; k < 6; ++k) {
        const double dqk = (jac[k] * y[0] + jac[6 + k] * y[1] + jac[12 + k] * y[2]) * (180.0 / M_PI);
        if (fabs(dqk) > dq_max)
            dq_max = fabs(dqk);
    }
    return dq_max;
}

static int fk_rows(rch_fkcheck_result *r, const rch_data *data, const rc_model *nominal, double tol_mm)
{
    rch_stats all;
    memset(&all, 0, sizeof all);
    for (size_t i = 0; i < data->n; ++i) {
        double p[3], pp[3], jac[36];
        rc_fk(p, NULL, nominal, data->s[i].q_rad);
        const double dp[3] = {data->xyz[i][0] - p[0], data->xyz[i][1] - p[1], data->xyz[i][2] - p[2]};
        const double dist = sqrt(dp[0] * dp[0] + dp[1] * dp[1] + dp[2] * dp[2]);
        rch_stats_add(&all, dist);
        /* the file's angles are rounded to 0.1 deg: a row is consistent when
         * a joint change within that rounding explains the difference */
        rc_fk_jac(pp, NULL, jac, nominal, data->s[i].q_rad);
        const double dq_deg = explaining_dq_deg(jac, dp);
        if (dist > tol_mm && dq_deg <= RCH_FK_ROUNDING_DEG) {
            ++r->rounding;
            if (dist > r->max_consistent_mm)
                r->max_consistent_mm = dist;
        } else if (dist > tol_mm) {
            rch_fk_fault *f = &r->fault[r->faults++];
            f->line = data->line[i];
            f->dist_mm = dist;
            f->dq_deg = dq_deg;
            memcpy(f->fk_mm, p, sizeof p);
            memcpy(f->file_mm, data->xyz[i], sizeof f->file_mm);
        } else if (dist > r->max_consistent_mm) {
            r->max_consistent_mm = dist;
        }
    }
    r->rows = data->n;
    r->rms_mm = rch_stats_rms(&all);
    r->max_mm = all.max_abs;
    return 0;
}

int rch_fkcheck_run(rch_fkcheck_result *r, const char *data_path, const char *robot_path, double tol_mm,
                    rch_diag *d)
{
    memset(r, 0, sizeof *r);
    rch_robot robot;
    rch_data data;
    if (rch_robot_load(&robot, robot_path, d) != 0 || rch_data_load(&data, data_path, 0, d) != 0)
        return -1;
    snprintf(r->robot_name, sizeof r->robot_name, "%s", robot.name);
    int rc = -1;
    if (!data.xyz)
        rch_diag_set(d, data_path, 0, 0, "no x, y, z columns");
    else if (!(r->fault = malloc((data.n ? data.n : 1) * sizeof *r->fault)))
        rch_diag_set(d, "", 0, 0, "out of memory");
    else
        rc = fk_rows(r, &data, &robot.nominal, tol_mm);
    rch_data_free(&data);
    return rc;
}

void rch_fkcheck_free(rch_fkcheck_result *r)
{
    free(r->fault);
    r->fault = NULL;
}
