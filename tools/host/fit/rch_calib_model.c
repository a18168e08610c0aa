/* SPDX-License-Identifier: MIT */
/* rch_calib_model.c - the calibrated model file (rcal-model/2) with its
 * "calibration" member (rch_calib_write_model), and its safe save, refused
 * for a geometry fitted across length jumps (rch_calib_save_model).
 *
 * Depends on: rch_calib.h, rch_robot (rch_robot_write), rch_save, rch_jw.
 * Memory: none on the heap. Errors: -1 (d set by rch_calib_save_model).
 */
#include "rch_calib.h"
#include "rch_calib_int.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "rch_jw.h"
#include "rch_save.h"

static void calib_info(rch_jw *w, const void *ctx)
{
    const rch_calib_result *r = ctx;
    rch_jw_str(w, "method", rc_method_name(r->cfg.method));
    rch_jw_str(w, "data", rch_calib_data_name(r));
    rch_jw_uint(w, "n_train", r->n_train);
    rch_jw_uint(w, "n_test", r->n_test);
    rch_jw_uint(w, "seed", r->cfg.seed);
    rch_jw_numf(w, "rmse_before_mm", r->before_m.rmse_mm, "%.6f");
    rch_jw_numf(w, "rmse_after_mm", r->after_m.rmse_mm, "%.6f");
    if (r->have_jumps && r->jumps.n_jumps) { /* read back: rcal evaluate says they are not applied */
        rch_jw_arr(w, "length_jumps");
        for (unsigned k = 0; k < r->jumps.n_jumps; ++k) {
            rch_jw_obj(w, NULL);
            rch_jw_uint(w, "line", r->jump_lines[k]);
            rch_jw_numf(w, "t", r->jumps.at_t[k], "%.6f");
            rch_jw_numf(w, "size_mm", r->jumps.size_mm[k], "%.6f");
            rch_jw_numf(w, "se_mm", r->jumps.se_mm[k], "%.6f");
            rch_jw_end(w);
        }
        rch_jw_end(w);
    }
}

int rch_calib_write_model(FILE *f, const rch_calib_result *r)
{
    if (!r->finite)
        return -1;
    const rch_robot_info info = {calib_info, r, r->have_unc ? &r->unc : NULL, r->have_unc ? &r->determined : NULL,
                                 &r->prov, r->outlet_label, r->n_outlets, &r->robot.ctrl};
    return rch_robot_write(f, r->robot.name, &r->model, &r->robot.nominal, &info);
}

static int write_model_fn(FILE *f, const void *ctx)
{
    return rch_calib_write_model(f, ctx);
}

/* rch_save's writer of a text in memory. */
typedef struct {
    const char *text;
    size_t len;
} mem_text;
static int write_text_fn(FILE *f, const void *ctx)
{
    const mem_text *t = ctx;
    return fwrite(t->text, 1, t->len, f) == t->len ? 0 : -1;
}

int rch_calib_save_model(const rch_calib_result *r, const char *path, rch_diag *d)
{
    return rch_calib_save_model_text(r, path, NULL, NULL, d);
}

int rch_calib_save_model_text(const rch_calib_result *r, const char *path, char **text, size_t *len, rch_diag *d)
{
    if (text)
        *text = NULL;
    if (r->jumps_found && !r->cfg.jumps && !r->jumps_auto) {
        char counts[200];
        rch_calib_jump_counts(counts, sizeof counts, r);
        rch_diag_set(d, path, 0, 0,
                     "not written: the lengths jump in acquisition order (%s), which this fit does not model, so "
                     "its geometry is wrong; run again with --jumps, which fits the %u step%s found (or "
                     "--no-jump-check to write it anyway)",
                     counts, r->jump_check_steps, r->jump_check_steps == 1 ? "" : "s");
        return -1;
    }
    const rch_calib_judge *j = &r->judge;
    if (j->done && (j->beyond || j->worse_than_nominal) && !r->cfg.force) {
        char why[2048];
        rch_calib_judge_text(why, sizeof why, r);
        rch_diag_set(d, path, 0, 0, "not written: %s (--force writes it anyway)", why);
        return -1;
    }
    /* every command reads a model file through rch_robot_load, which refuses an effect outside its
     * plausible range (rc_effect_desc.limit): a fit that ends there is said here, not written for the
     * next command to refuse */
    const rc_model *fm = &r->model;
    for (unsigned e = 0; e < fm->n_effects; ++e) {
        const rc_effect_desc *ds = rc_effect_describe(fm->effects[e].kind);
        for (unsigned k = 0; ds && k < fm->effects[e].count; ++k) {
            const double v = fm->x[fm->effects[e].first + k];
            if (!(fabs(v) <= ds->limit)) {
                rch_diag_set(d, path, 0, 0,
                             "not written: effect %s parameter %u = %g is outside its plausible range (|value| at "
                             "most %g %s), which every rcal command refuses to load: the fit traded it against "
                             "something the data do not see, or the effect is not this one",
                             ds->name, k + 1, v, ds->limit, ds->unit_text);
                return -1;
            }
        }
    }
    const char *inputs[2 * RCH_CALIB_MAX_FILES + 4] = {r->cfg.robot_path, r->cfg.truth_path, r->cfg.validate_path};
    size_t n = 3;
    for (size_t f = 0; f < rch_calib_cfg_n_files(&r->cfg); ++f)
        inputs[n++] = rch_calib_cfg_file(&r->cfg, f);
    for (size_t f = 0; f < r->cfg.n_positions_paths && f < RCH_CALIB_MAX_FILES; ++f)
        inputs[n++] = r->cfg.positions_paths[f];
    if (!text)
        return rch_save(path, "--out", inputs, n, write_model_fn, r, d);
    /* the text made once in memory, written from there: the reader in this process takes the same bytes */
    char *buf = NULL;
    size_t blen = 0;
    FILE *m = open_memstream(&buf, &blen);
    const int wr = m ? rch_calib_write_model(m, r) : -1;
    if (!m || fclose(m) != 0 || wr != 0) {
        free(buf);
        rch_diag_set(d, path, 0, 0, "--out: the model could not be made in memory (out of memory, or not finite)");
        return -1;
    }
    const mem_text t = {buf, blen};
    if (rch_save(path, "--out", inputs, n, write_text_fn, &t, d) != 0) {
        free(buf);
        return -1;
    }
    *text = buf;
    *len = blen;
    return 0;
}
