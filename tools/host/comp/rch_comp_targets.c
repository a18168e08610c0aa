/* SPDX-License-Identifier: MIT */
/* rch_comp_targets.c - rcal-rt's joint-target file (--in, see rch_comp.h):
 * read once through the project's one CSV reader (rch_data,
 * RCH_DATA_TARGETS), the radians rule applied, the rows copied out.
 * Depends on: rch_file (rch_read_file), rch_data. Memory: *q_rad malloc'd
 * (the caller frees). Errors: -1 with d set (file:line:col). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "rch_comp.h"
#include "rch_data.h"
#include "rch_file.h"

/* largest file (about 1.5 million targets of 40 bytes) */
#define RCH_TARGETS_MAX_BYTES ((size_t)64 << 20)

int rch_comp_read_targets(double (**q_rad)[RC_NJ], size_t *n, const char *path, const rc_kin *m, rch_diag *d)
{
    static const double deg = 3.14159265358979323846 / 180.0;
    rc_model lim; /* the limits of the model compensating (the reader's check) */
    char *text = NULL;
    size_t len = 0;
    rch_data data;
    *q_rad = NULL;
    *n = 0;
    memset(&lim, 0, sizeof lim);
    for (int i = 0; i < RC_NJ; ++i) {
        lim.q_min_rad[i] = (double)m->q_min_rad[i];
        lim.q_max_rad[i] = (double)m->q_max_rad[i];
    }
    if (rch_read_file(&text, &len, path, RCH_TARGETS_MAX_BYTES, d) != 0)
        return -1;
    const int rc = rch_data_parse_limited(&data, text, len, path, RCH_DATA_TARGETS | RCH_DATA_NO_LEN, &lim, d);
    free(text);
    if (rc != 0)
        return -1;
    double max_abs_deg[RC_NJ] = {0};
    for (size_t k = 0; k < data.n; ++k)
        for (int i = 0; i < RC_NJ; ++i)
            max_abs_deg[i] = fmax(max_abs_deg[i], fabs(data.s[k].q_rad[i] / deg));
    char why[256];
    if (rch_data_q_look_rad(why, sizeof why, max_abs_deg, data.n)) {
        rch_diag_set(d, path, 0, 0, "%s", why);
        rch_data_free(&data);
        return -1;
    }
    *q_rad = malloc((data.n ? data.n : 1) * sizeof (*q_rad)[0]);
    if (!*q_rad) {
        rch_diag_set(d, path, 0, 0, "out of memory for %zu targets", data.n);
        rch_data_free(&data);
        return -1;
    }
    for (size_t k = 0; k < data.n; ++k)
        memcpy((*q_rad)[k], data.s[k].q_rad, sizeof (*q_rad)[0]);
    *n = data.n;
    rch_data_free(&data);
    return 0;
}
