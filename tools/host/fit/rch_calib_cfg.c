/* SPDX-License-Identifier: MIT */
/* rch_calib_cfg.c - the defaults and the file list of a calibration request
 * (see rch_calib_cfg.h). */
#include "rch_calib_cfg.h"

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
