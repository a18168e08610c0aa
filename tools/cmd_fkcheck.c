/* cmd_fkcheck.c - rcal fkcheck: does our forward kinematics reproduce the
 * controller's nominal x, y, z columns? Reports every row that does not. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rcal_cmds.h"
#include "rch_data.h"
#include "rch_robot.h"
#include "rcal_opts.h"

int rcal_cmd_fkcheck(int argc, char **argv)
{
    const char *data_path = NULL, *robot_path = RCAL_DEFAULT_ROBOT;
    double tol_mm = 0.5;
    int json = 0;
    for (int i = 1; i < argc; ++i) {
        if (rcal_opt_str(argc, argv, &i, "--data", &data_path) || rcal_opt_str(argc, argv, &i, "--robot", &robot_path))
            continue;
        if (rcal_opt_double(argc, argv, &i, "--tol-mm", &tol_mm))
            continue;
        if (strcmp(argv[i], "--json") == 0) {
            json = 1;
            continue;
        }
        if (strcmp(argv[i], "--help") == 0) {
            printf("usage: rcal fkcheck --data FILE [--robot MODEL.json] [--tol-mm T] [--json]\n"
                   "Compares the nominal FK at each row's joint angles with its x, y, z columns.\n"
                   "Rows further than T mm (default 0.5) are listed.\n");
            return 0;
        }
        return rcal_opt_unknown("fkcheck", argv[i]);
    }
    if (!data_path)
        return rcal_opt_missing("fkcheck", "--data");
    rch_robot robot;
    rch_data data;
    rch_diag d;
    char msg[1024];
    if (rch_robot_load(&robot, robot_path, &d) != 0 || rch_data_load(&data, data_path, 0, &d) != 0) {
        fprintf(stderr, "rcal fkcheck: %s\n", rch_diag_str(&d, msg, sizeof msg));
        return 1;
    }
    if (!data.xyz) {
        fprintf(stderr, "rcal fkcheck: %s has no x, y, z columns\n", data_path);
        rch_data_free(&data);
        return 1;
    }
    size_t bad = 0, rounding = 0;
    const double rounding_deg = 0.1; /* the 0.1 deg display step: the minimum-norm dq overestimates the
                                        * smallest max-norm change, so one full step is allowed */
    double sum2 = 0.0, maxd = 0.0, maxd_good = 0.0;
    if (!json)
        printf("FK check of %s against %s (tolerance %.3f mm)\n", data_path, robot.name, tol_mm);
    for (size_t i = 0; i < data.n; ++i) {
        double p[3];
        rc_fk(p, NULL, &robot.nominal, data.s[i].q_rad);
        const double dx = p[0] - data.xyz[i][0], dy = p[1] - data.xyz[i][1], dz = p[2] - data.xyz[i][2];
        const double dist = sqrt(dx * dx + dy * dy + dz * dz);
        sum2 += dist * dist;
        if (dist > maxd)
            maxd = dist;
        /* The file's angles are rounded to 0.1 deg: a row is consistent when a
         * joint change within that rounding explains the difference. Minimum-norm
         * dq = J^T (J J^T)^-1 dp over the position rows of the joint Jacobian. */
        double jac[36], pp[3], dq_max_deg = 0.0;
        rc_fk_jac(pp, NULL, jac, &robot.nominal, data.s[i].q_rad);
        {
            double M[9], r[3] = {-dx, -dy, -dz};
            for (int a = 0; a < 3; ++a)
                for (int b = 0; b < 3; ++b) {
                    double s = 0.0;
                    for (int k = 0; k < 6; ++k)
                        s += jac[6 * a + k] * jac[6 * b + k];
                    M[3 * a + b] = s;
                }
            const double det = M[0] * (M[4] * M[8] - M[5] * M[7]) - M[1] * (M[3] * M[8] - M[5] * M[6]) +
                               M[2] * (M[3] * M[7] - M[4] * M[6]);
            double y[3] = {0, 0, 0};
            if (fabs(det) > 1e-12) { /* Cramer's rule on the 3x3 system M y = r */
                for (int c = 0; c < 3; ++c) {
                    double T[9];
                    memcpy(T, M, sizeof T);
                    for (int a = 0; a < 3; ++a)
                        T[3 * a + c] = r[a];
                    y[c] = (T[0] * (T[4] * T[8] - T[5] * T[7]) - T[1] * (T[3] * T[8] - T[5] * T[6]) +
                            T[2] * (T[3] * T[7] - T[4] * T[6])) / det;
                }
            }
            for (int k = 0; k < 6; ++k) {
                const double dqk = (jac[k] * y[0] + jac[6 + k] * y[1] + jac[12 + k] * y[2]) * (180.0 / 3.14159265358979323846);
                if (fabs(dqk) > dq_max_deg)
                    dq_max_deg = fabs(dqk);
            }
        }
        if (dist > tol_mm && dq_max_deg <= rounding_deg) {
            ++rounding;
            if (dist > maxd_good)
                maxd_good = dist;
        } else if (dist > tol_mm) {
            ++bad;
            if (!json)
                printf("  FAULT line %u: |FK - xyz| = %.3f mm, needs a joint change of %.3f deg (FK %.2f %.2f %.2f, "
                       "file %.2f %.2f %.2f)\n",
                       data.line[i], dist, dq_max_deg, p[0], p[1], p[2], data.xyz[i][0], data.xyz[i][1],
                       data.xyz[i][2]);
        } else if (dist > maxd_good) {
            maxd_good = dist;
        }
    }
    if (json)
        printf("{\"rows\": %zu, \"faults\": %zu, \"explained_by_rounding\": %zu, \"rms_mm\": %.6f, "
               "\"max_mm\": %.6f, \"max_consistent_mm\": %.6f}\n",
               data.n, bad, rounding, sqrt(sum2 / (double)data.n), maxd, maxd_good);
    else
        printf("rows %zu: %zu within %.2f mm, %zu further but explained by the 0.1 deg angle rounding "
               "(|dq| <= %.2f deg), %zu FAULTS.\nlargest consistent difference %.3f mm; RMS of all %.4f mm\n",
               data.n, data.n - bad - rounding, tol_mm, rounding, rounding_deg, bad, maxd_good,
               sqrt(sum2 / (double)data.n));
    rch_data_free(&data);
    return 0;
}
