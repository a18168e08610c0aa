/* SPDX-License-Identifier: MIT */
/* rch_calib_cfg.c - the defaults and the file list of a calibration request
 * (see rch_calib_cfg.h). */
#include "rch_calib_cfg.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void rch_calib_cfg_init(rch_calib_cfg *cfg)
{
    memset(cfg, 0, sizeof *cfg);
    cfg->method = RC_METHOD_LM;
    cfg->test_fraction = 0.1;
    cfg->seed = 1;
    cfg->cases = 1;
}

size_t rch_calib_cfg_n_files(const rch_calib_cfg *cfg)
{
    return cfg->data_paths && cfg->n_data_paths ? cfg->n_data_paths : cfg->data_path ? 1 : 0; /* 0: positions only */
}

const char *rch_calib_cfg_file(const rch_calib_cfg *cfg, size_t i)
{
    return cfg->data_paths && cfg->n_data_paths ? cfg->data_paths[i] : cfg->data_path;
}

int rch_calib_cfg_cable_points(rch_calib_cfg *cfg, const char *const *v, size_t n, char *err, size_t errlen)
{
    return rch_cable_points_parse(cfg->cable_points_mm, &cfg->n_cable_points, v, n, err, errlen);
}

int rch_cable_points_parse(double (*pts)[3], unsigned *n_out, const char *const *v, size_t n, char *err, size_t errlen)
{
    if (n > RC_MAX_TARGETS) {
        snprintf(err, errlen, "--cable-point given %zu times: at most %d points", n, RC_MAX_TARGETS);
        return -1;
    }
    for (size_t k = 0; k < n; ++k) { /* "X,Y,Z" in mm, the flange frame */
        const char *p = v[k];
        for (unsigned c = 0; c < 3; ++c) {
            char *end = NULL;
            const double x = strtod(p, &end);
            if (end == p || !isfinite(x) || fabs(x) > 2000.0 || (c < 2 ? *end != ',' : *end != '\0')) {
                snprintf(err, errlen, "--cable-point '%s' (point %zu): need X,Y,Z in mm in the flange frame, each "
                                      "within 2000", v[k], k);
                return -1;
            }
            pts[k][c] = x;
            p = end + 1;
        }
    }
    *n_out = (unsigned)n;
    return 0;
}
