/* SPDX-License-Identifier: MIT */
/* rch_report_warn.c - the warnings of the report: the fit (convergence,
 * held-out set, rank, a worse model), the parameters (prior only, partly
 * determined, far from nominal; extrapolation), the diagnosis (what the
 * model misses, another data set) and the inputs (changed or unread data,
 * no provenance, the calibration's own warnings). At most
 * RCH_REPORT_MAX_WARN, each into rep's warn[] (640 bytes, truncated).
 * Depends on: rch_json (through the model). Memory: none. Errors: none.
 * See rch_report_int.h. */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "rch_seen.h"

#include "rch_report_int.h"

static void warnf(rep *r, const char *fmt, ...) RCH_PRINTF(2, 3);
static void warnf(rep *r, const char *fmt, ...)
{
    va_list ap;
    if (r->n_warn >= RCH_REPORT_MAX_WARN)
        return;
    va_start(ap, fmt);
    vsnprintf(r->warn[r->n_warn++], sizeof r->warn[0], fmt, ap);
    va_end(ap);
}

void rch_rep_warn_fit(rep *r)
{
    const double before = jnum(r->cal, "before.rmse_mm"), after = jnum(r->cal, "after.rmse_mm");
    const char *exit_why = jstr(r->cal, "exit");
    if (jbool(r->cal, "converged") == 0)
        warnf(r, "The solver did not converge (exit: %s): the after figures and the parameters are not meaningful.",
              exit_why ? exit_why : "not in this run");
    if (jbool(r->cal, "held_out") == 0)
        warnf(r, "No held-out samples: the before/after figures are on the training data and flatter the model.");
    if (isfinite(before) && isfinite(after) && after > before)
        warnf(r, "The calibrated model is worse than the nominal one on the held-out samples (RMSE %.4f mm against "
                 "%.4f mm).", after, before);
    const double rank = jnum(r->cal, "identifiability.rank"), np = jnum(r->cal, "identifiability.params"),
                 weak = jnum(r->cal, "identifiability.weak");
    const int prior = jbool(rch_rep_jpath(r->cal, "estimation"), "prior") == 1;
    if (isfinite(rank) && isfinite(np) && rank < np)
        warnf(r, "%.0f of %.0f parameter directions are not seen by these data; %s (see the identifiability table).",
              np - rank, np,
              prior ? "the physical prior holds them near nominal and their uncertainty is counted at the prior's "
                      "width"
                    : "the solver left them at their starting values");
    if (isfinite(weak) && weak > 0)
        warnf(r, "%.0f direction(s) are only weakly seen by the data: %s.", weak,
              prior ? "the prior shares in their values" : "their values carry little information");
    const double tb = jnum(r->cal, "truth_flange.before_rms_mm"), ta = jnum(r->cal, "truth_flange.after_rms_mm");
    if (isfinite(tb) && isfinite(ta) && ta > tb)
        warnf(r, "Against the simulated truth the calibrated flange positions are worse than the nominal ones "
                 "(RMS %.4f mm against %.4f mm).", ta, tb);
}

void rch_rep_warn_params(rep *r, const prow *p, size_t n)
{
    char weak[512] = "", notid[512] = "", far[512] = "";
    int posterior = 0;
    for (size_t k = 0; k < n; ++k) {
        const int sc = rch_seen_parse(p[k].cls); /* the one vocabulary, or an older file's words */
        const int po = strcmp(p[k].cls, "prior only") == 0 || sc == RCH_SEEN_PRIOR,
                  pa = strcmp(p[k].cls, "partly") == 0 || (sc == RCH_SEEN_PARTLY && p[k].prior_sd > 0.0);
        posterior |= po || pa || strcmp(p[k].cls, "determined") == 0 || (sc == RCH_SEEN_DATA && p[k].prior_sd > 0.0);
        char *dst = strcmp(p[k].cls, "weak") == 0 || pa || sc == RCH_SEEN_PARTLY ? weak
                    : strcmp(p[k].cls, "not identifiable") == 0 || po || sc == RCH_SEEN_UNSEEN ? notid
                                                                      : NULL;
        if (dst && strlen(dst) + strlen(p[k].name) + 3 < sizeof weak)
            snprintf(dst + strlen(dst), sizeof weak - strlen(dst), "%s%s", dst[0] ? ", " : "", p[k].name);
        if (p[k].prior_sd > 0.0 && fabs(p[k].delta) > 3.0 * p[k].prior_sd && strlen(far) + strlen(p[k].name) + 3 < sizeof far)
            snprintf(far + strlen(far), sizeof far - strlen(far), "%s%s", far[0] ? ", " : "", p[k].name);
    }
    if (notid[0])
        warnf(r, posterior ? "Determined by the prior only (the data did not narrow them; they stay within their "
                             "prior, and compensation uses them as they are): %s."
                           : "Not identifiable (their values mean nothing alone; compensation keeps them nominal): %s.",
              notid);
    if (weak[0])
        warnf(r, posterior ? "Partly determined by the data (the prior shares in their values): %s."
                           : "Weakly identified (large standard error): %s.",
              weak);
    if (far[0])
        warnf(r, "More than 3 prior standard deviations from nominal (a real deviation, or an effect these "
                 "parameters stand in for: run rcal diagnose): %s.", far);
    if (jbool(r->unc, "orientation_determined") == 0)
        warnf(r, "The data do not determine the flange orientation: compensate position only.");
    const double in = jnum(r->unc, "position95_mm.data_max"), ws = jnum(r->unc, "position95_mm.workspace_max");
    if (isfinite(in) && isfinite(ws) && ws > 3.0 * in)
        warnf(r, "The model extrapolates: predicted 95 %% position uncertainty up to %.3g mm over the whole workspace "
                 "against %.3g mm inside the data; trust it only near the measured poses.", ws, in);
}

void rch_rep_warn_diag(rep *r)
{
    const char *effect = jstr(r->diag, "effect"), *why = jstr(r->diag, "remaining_why");
    if (!r->diag)
        return;
    if (effect && strcmp(effect, "unexplained") == 0)
        warnf(r, "The diagnosis finds error the model does not explain: %s.", why ? why : "not in this run");
    else if (effect && strcmp(effect, "none") != 0) {
        char seq[256] = "";
        const rch_json *q = jarr(r->diag, "sequence");
        for (size_t k = 0; q && k < q->n; ++k)
            if (q->items[k]->type == RCH_JSTR && strlen(seq) + strlen(q->items[k]->str) + 3 < sizeof seq)
                snprintf(seq + strlen(seq), sizeof seq - strlen(seq), "%s%s", k ? ", " : "", q->items[k]->str);
        const double b = jnum(r->diag, "rmse_before_mm"), a = jnum(r->diag, "rmse_after_mm");
        char fig[128] = "";
        if (isfinite(a) && isfinite(b))
            snprintf(fig, sizeof fig, " (held-out RMSE %.4g mm with the geometry alone, %.4g mm with %s)", b, a,
                     q && q->n > 1 ? "them" : "it");
        const rch_json *cj = jarr(r->cal, "length_jumps");
        if (strcmp(effect, "length_jump") == 0 && cj && cj->n)
            ; /* the calibration fitted them: nothing the model misses */
        else
            warnf(r, "The diagnosis finds what the geometric model misses: %s%s. The calibration above does not "
                     "model it: %s.",
                  seq[0] ? seq : effect, fig,
                  strcmp(effect, "length_jump") == 0 ? "calibrate again with --jumps"
                                                     : "calibrate again with --effects naming it (the diagnosis' "
                                                       "Next line gives the command)");
    }
    const double nd = jnum(r->diag, "n"), nc = jnum(r->cal, "n_train") + jnum(r->cal, "n_test");
    const double dropped = jnum(r->cal, "dequantized.refused");
    if (isfinite(nd) && isfinite(nc) && nd != nc && !(isfinite(dropped) && nd == nc + dropped))
        warnf(r, "The diagnosis ran on %.0f samples, the calibration on %.0f: are they from the same data?", nd, nc);
    const double flick = jnum(r->diag, "wrist_flicker_samples");
    if (isfinite(flick) && flick > 0)
        warnf(r, "%.0f sample(s) have a wrist reading that moved by one display step within their set-up.", flick);
}

void rch_rep_warn_inputs(rep *r, const dfile *df, size_t n_df)
{
    const char *md = jstr(r->model, "calibration.data"), *cd = jstr(r->cal, "data");
    if (md && cd && strcmp(md, cd) != 0)
        warnf(r, "The model file was calibrated on %s, this calibration on %s: the model may be from another run.",
              md, cd);
    for (size_t i = 0; i < n_df; ++i) {
        if (df[i].sha_rec && df[i].sha_now[0] && strcmp(df[i].sha_rec, df[i].sha_now) != 0)
            warnf(r, "The data file %s changed since the calibration (its SHA-256 differs from the one recorded).",
                  df[i].file);
        if (!df[i].sha_now[0])
            warnf(r, "The data file %s was not read (%s): its content cannot be checked.", df[i].file, df[i].why);
    }
    if (!r->prov && !jstr(r->cal, "tool"))
        warnf(r, "No provenance in this run (tool version, command line, data hash, date): the result cannot be "
                 "traced to its data and its program.");
    const rch_json *w = jarr(r->cal, "warnings");
    for (size_t i = 0; w && i < w->n; ++i)
        if (w->items[i]->type == RCH_JSTR)
            warnf(r, "%s", w->items[i]->str);
}
