/* SPDX-License-Identifier: MIT */
/* rch_comp_run.c - rch_comp_run and rch_comp_lines (see rch_comp.h): the
 * models loaded and made into the point models and the stream, the input
 * and the outputs opened (never replacing an input; --uncertainty-out), and
 * the lines read, bounded, checked and sent by their form (detected from the
 * first line or forced) to the CSV path (rch_comp_csv.c) or the RAPID path
 * (rch_comp_rapid.c); a failed write stops the stream.
 * Depends on: rch_robot, rch_file (rch_out), rch_stdio, the models
 * (rch_comp_model.c). Memory: the line buffer on the heap; the models in
 * static storage (one run at a time). Errors: -1 with d set; nothing is
 * left in place of the output when a run fails. */
#include "rch_comp.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "rch_comp_int.h"
#include "rch_data.h"
#include "rch_file.h"
#include "rch_stdio.h"
#include "rch_urscript_comp.h"

/* longest input line (a RAPID target line is a few hundred bytes): a longer
 * one, or a stream without line ends (/dev/zero), is refused, not buffered */
#define MAX_LINE 65536

static int is_comment_or_blank(const char *s, size_t n)
{
    size_t i = 0;
    while (i < n && (s[i] == ' ' || s[i] == '\t' || s[i] == '\r'))
        ++i;
    return i == n || s[i] == '#';
}

static int starts_with_ci(const char *s, size_t n, const char *w)
{
    size_t k = strlen(w);
    while (n > 0 && (*s == ' ' || *s == '\t')) {
        ++s;
        --n;
    }
    return n >= k && strncasecmp(s, w, k) == 0;
}

/* The line's last character that is not blank (before a URScript comment
 * '#') is a colon: URScript's "def main():", never KRL's "DEF main( )". */
static int ends_with_colon(const char *s, size_t n)
{
    const char *hash = memchr(s, '#', n);
    if (hash)
        n = (size_t)(hash - s);
    while (n > 0 && (s[n - 1] == ' ' || s[n - 1] == '\t' || s[n - 1] == '\r'))
        --n;
    return n > 0 && s[n - 1] == ':';
}

static const char *find_ci(const char *s, size_t n, const char *w)
{
    size_t k = strlen(w);
    for (size_t i = 0; i + k <= n; ++i)
        if (strncasecmp(s + i, w, k) == 0)
            return s + i;
    return NULL;
}

/* One line of at most MAX_LINE bytes into *line (grown as needed, its end
 * kept): its length, -1 at the end of the input, -2 when longer. A line ends
 * at LF, CRLF or a lone CR (each counted as a line for file:line:col). */
static long read_line(char **line, size_t *cap, FILE *in)
{
    size_t n = 0;
    int ch = EOF;
    while (n <= MAX_LINE && (ch = getc(in)) != EOF) {
        if (n + 3 > *cap) {
            const size_t nc = *cap ? 2 * *cap : 256;
            char *nl = realloc(*line, nc);
            if (!nl)
                return -2;
            *line = nl;
            *cap = nc;
        }
        (*line)[n++] = (char)ch;
        if (ch == '\n')
            break;
        if (ch == '\r') {
            const int next = getc(in);
            if (next == '\n')
                (*line)[n++] = '\n';
            else if (next != EOF)
                ungetc(next, in);
            break;
        }
    }
    if (n == 0 && ch == EOF)
        return -1;
    if (n > MAX_LINE)
        return -2;
    (*line)[n] = '\0';
    return (long)n;
}

/* A write of the output failed (full disk, closed pipe or descriptor): 1
 * with d set, the stream stops there; no line is ever lost silently. */
static int out_failed(const rch_cpi_ctx *c, unsigned lineno, rch_diag *d)
{
    if (!ferror(c->out))
        return 0;
    rch_diag_set(d, c->out == stdout ? "<stdout>" : "", 0, 0,
                 "write failed at input line %u (%s): stopped there, the output is incomplete", lineno,
                 strerror(rch_stdio_errno(c->out)));
    return 1;
}

/* The form of the input from its first line that is not blank or a comment
 * (line, a BOM of bom bytes, then tn bytes of text): RAPID, or CSV (then
 * held back for the radians check) whose first line is a header when its
 * first field is not a number (read and copied here). 0, 1 (the header
 * consumed) or -1 (d set). */
static int decide_form(rch_cpi_ctx *c, const char *line, size_t bom, size_t tn, unsigned lineno, rch_diag *d)
{
    const char *text = line + bom;
    if (starts_with_ci(text, tn, "&ACCESS") || starts_with_ci(text, tn, "&REL") || starts_with_ci(text, tn, "&PARAM") ||
        starts_with_ci(text, tn, "&COMMENT") || (starts_with_ci(text, tn, "DEF") && !ends_with_colon(text, tn)) ||
        starts_with_ci(text, tn, "GLOBAL DEF") || starts_with_ci(text, tn, "DECL ")) {
        c->format = RCH_COMP_KRL;
        return 0;
    }
    if (starts_with_ci(text, tn, "/PROG")) {
        c->format = RCH_COMP_FANUC;
        return 0;
    }
    if (starts_with_ci(text, tn, "MODULE") || starts_with_ci(text, tn, "%%%") || starts_with_ci(text, tn, "!") ||
        find_ci(text, tn, "jointtarget") || find_ci(text, tn, "robtarget")) {
        c->format = 2;
        return 0;
    }
    if (rch_cpi_urscript_detect(text, tn)) {
        c->format = RCH_COMP_FORMAT_URSCRIPT;
        return 0;
    }
    size_t st[RCH_CPI_MAX_FIELDS], ln[RCH_CPI_MAX_FIELDS];
    double v;
    c->format = 1;
    if (!(c->gate && c->gate->assume_degrees) && rch_cpi_csv_hold(c, d) != 0)
        return -1;
    if (!(rch_cpi_split_csv(text, tn, st, ln) > 0 && rch_cpi_parse_num(&v, text + st[0], ln[0]) != 0))
        return 0;
    fwrite(line, 1, bom, c->out);
    return rch_cpi_csv_header(c, text, tn, lineno, d) < 0 || out_failed(c, lineno, d) ? -1 : 1;
}

/* The end of a CSV input held back (rch_cpi_csv_hold) because it looked like
 * radians so far: refused when it still does (rch_data_q_look_rad; nothing
 * written), else what was held written out. rc as the lines left it; returns
 * the run's. */
static int held_end(rch_cpi_ctx *c, int rc, unsigned lineno, rch_diag *d)
{
    if (!c->held)
        return rc;
    char why[320];
    if (rc >= 0 && rch_data_q_look_rad(why, sizeof why, c->max_abs_deg, c->n_targets)) {
        rch_diag_set(d, c->in_name, 0, 0, "%s; nothing written (if they are degrees: --assume-degrees)", why);
        rc = -1;
    }
    if (rc < 0) {
        rch_cpi_csv_drop(c);
        return rc;
    }
    rch_cpi_csv_release(c);
    return out_failed(c, lineno, d) ? -1 : rc;
}

int rch_comp_lines(FILE *out, rch_comp_result *res, FILE *in, const char *in_name, rc_comp_stream *s,
                   const rc_model *cal, rch_comp_format format, FILE *warn, rch_diag *d)
{
    return rch_comp_lines_gated(out, res, in, in_name, s, cal, NULL, format, warn, d);
}

int rch_comp_lines_gated(FILE *out, rch_comp_result *res, FILE *in, const char *in_name, rc_comp_stream *s,
                         const rc_model *cal, const rch_comp_gate *gate, rch_comp_format format, FILE *warn,
                         rch_diag *d)
{
    rch_cpi_ctx c = {.stream = s, .cal = cal, .fit = gate ? gate->fit : NULL, .stream0 = s, .cal0 = cal,
                  .fit0 = gate ? gate->fit : NULL, .gate = gate, .res = res, .out = out, .warn = warn,
                  .in_name = in_name, .format = (int)format};
    char *line = NULL;
    size_t cap = 0;
    long got;
    unsigned lineno = 0;
    int rc = 0, decided = c.format != 0;
    if (c.format == 1 && !(gate && gate->assume_degrees) && rch_cpi_csv_hold(&c, d) != 0)
        return -1; /* --format csv: held from the start as a detected CSV is */
    while ((got = read_line(&line, &cap, in)) != -1) {
        size_t n = (size_t)got;
        ++lineno;
        if (got == -2) {
            rch_diag_set(d, c.in_name, lineno, 1, "line longer than %d bytes (no line end?): refused", MAX_LINE);
            rc = -1;
            break;
        }
        while (n > 0 && (line[n - 1] == '\n' || line[n - 1] == '\r'))
            --n;
        c.eol = (size_t)got == n ? "\n" : (size_t)got - n == 2 ? "\r\n" : line[n] == '\r' ? "\r" : "\n";
        /* a UTF-8 byte-order mark: not part of the first line's text; kept in the output */
        const size_t bom = lineno == 1 && n >= 3 && memcmp(line, "\xEF\xBB\xBF", 3) == 0 ? 3u : 0u;
        const char *text = line + bom;
        const size_t tn = n - bom;
        if (memchr(line, '\0', n) != NULL) {
            rch_diag_set(d, c.in_name, lineno, (unsigned)((const char *)memchr(line, '\0', n) - line) + 1,
                         "NUL byte in text input");
            rc = -1;
            break;
        }
        if (c.format != 2 && c.format != 3 && is_comment_or_blank(text, tn)) {
            fwrite(line, 1, n, c.out);
            fputs(c.eol, c.out);
            if (out_failed(&c, lineno, d)) {
                rc = -1;
                break;
            }
            continue;
        }
        int r;
        if (!decided) {
            decided = 1;
            if ((r = decide_form(&c, line, bom, tn, lineno, d)) < 0) {
                rc = -1;
                break;
            }
            if (r > 0)
                continue; /* a CSV header, copied */
        }
        if (c.format == RCH_COMP_FANUC) { /* a Fanuc LS program likewise (rch_comp_fanuc.c) */
            rc = rch_cpi_fanuc(&c, line, (size_t)got, in, lineno, d);
            if (rc >= 0 && out_failed(&c, lineno, d))
                rc = -1;
            break;
        }
        if (c.format == 2 || c.format == RCH_COMP_FORMAT_URSCRIPT || c.format == RCH_COMP_KRL) {
            /* read whole, its bytes as they are: all or nothing */
            rc = c.format == 2                          ? rch_cpi_rapid(&c, line, (size_t)got, in, lineno, d)
                 : c.format == RCH_COMP_FORMAT_URSCRIPT ? rch_cpi_urscript(&c, line, (size_t)got, in, lineno, d)
                                                        : rch_cpi_krl(&c, line, (size_t)got, in, lineno, d);

            if (rc >= 0 && out_failed(&c, lineno, d))
                rc = -1;
            break;
        }
        fwrite(line, 1, bom, c.out);
        r = rch_cpi_csv_line(&c, text, tn, lineno, d);
        if (r < 0) {
            rc = -1;
            break;
        }
        if (r > 0)
            rc = 1;
        if (out_failed(&c, lineno, d)) {
            rc = -1;
            break;
        }
    }
    free(line);
    for (size_t k = 0; k < c.ntcps; ++k)
        free(c.tcps[k]);
    rc = held_end(&c, rc, lineno, d);
    res->format = (rch_comp_format)c.format;
    if (rc >= 0 && ferror(in)) {
        rch_diag_set(d, c.in_name, 0, 0, "read error: %s", strerror(errno));
        rc = -1;
    }
    return rc;
}

int rch_comp_same_model(rch_diag *d, const rch_comp_job *job, const rch_robot *model, const rch_robot *nominal)
{
    const char *how = NULL;
    if (rch_path_same(job->model_path, job->nominal_path))
        how = "the same file";
    else if (model->model.n_params == nominal->model.n_params && model->model.n_effects == nominal->model.n_effects) {
        int equal = 1;
        for (unsigned k = 0; k < model->model.n_params && equal; ++k) /* the encoder's place moves no joint */
            equal = (k >= RC_P_ENC && k < RC_P_ENC + 3) || model->model.x[k] == nominal->model.x[k];
        if (equal)
            how = "the same numbers: every DH parameter and effect equal";
    }
    if (!how)
        return 0;
    rch_diag_set(d, job->nominal_path, 0, 0,
                 "--nominal %s is the calibrated model --model %s itself (%s): compensation would correct nothing; "
                 "give the nominal robot file the program was made with (e.g. data/irb120.json), or leave "
                 "--nominal out to use the model file's own \"nominal\" table",
                 job->nominal_path, job->model_path, how);
    return -1;
}

int rch_comp_run(rch_comp_result *res, const rch_comp_job *job, FILE *warn, rch_diag *d)
{
    static rch_robot robot, nominal_robot;
    memset(res, 0, sizeof *res);
    if (job->model_path == NULL) {
        rch_diag_set(d, "", 0, 0, "no calibrated model given");
        return -1;
    }
    if (!(job->max_dev_deg >= 0.0) || !isfinite(job->max_dev_deg)) {
        rch_diag_set(d, "", 0, 0, "the largest correction must be a finite positive angle (0: default)");
        return -1;
    }
    if (rch_robot_load(&robot, job->model_path, d) != 0 ||
        (job->nominal_path && rch_robot_load(&nominal_robot, job->nominal_path, d) != 0))
        return -1;
    if (job->nominal_path && rch_comp_same_model(d, job, &robot, &nominal_robot) != 0)
        return -1;
    const rc_model *nom = job->nominal_path ? &nominal_robot.model : &robot.nominal;
    const rc_model *nom_raw = nom; /* what the program was made with: the robtargets' IK */
    res->no_nominal = !job->nominal_path && !robot.has_nominal;
    static rc_model det;
    static rch_model_unc unc;
    det = robot.model;
    memset(&unc, 0, sizeof unc);
    if (robot.has_nominal || robot.unc.present)
        res->n_held = rch_comp_determined(&det, &unc, &res->version1, res->held, sizeof res->held, &robot,
                                          &robot.nominal);
    res->orientation_determined = unc.present && !res->version1 && unc.orientation_determined;
    res->mode_forced = job->position_only || job->full_pose;
    res->u95_unknown = !(unc.present && !res->version1);
    if (res->u95_unknown)
        res->max_pos95_mm = NAN;
    /* the point compensation moves: the flange (or the given TCP) of both
     * models, never the cable attachment the calibration measured */
    static rc_model nom_pt, det_any;
    det_any = det;
    rch_comp_point_model(&det, &det, job->tool_mm);
    rch_comp_point_model(&nom_pt, nom, job->tool_mm);
    nom = &nom_pt;
    rc_comp_config cfg;
    memset(&cfg, 0, sizeof cfg);
    cfg.max_dev_rad = (rc_real)(job->max_dev_deg * DEG);
    if (!res->mode_forced)
        rch_comp_orient_decide(&res->orient, unc.present && !res->version1 ? &unc : NULL, &det, nom, &cfg);
    res->position_only_used = rch_comp_position_only(&res->orient, job->position_only, job->full_pose,
                                                     robot.has_nominal || robot.unc.present,
                                                     res->orientation_determined);
    cfg.flags = res->position_only_used ? RC_COMP_FLAG_POSITION_ONLY : 0u;
    static rc_comp_stream s;
    rc_status st = rc_comp_stream_init(&s, &det, nom, &cfg);
    if (st != RC_OK) {
        rch_diag_set(d, job->model_path, 0, 0, "the model cannot be used for compensation: %s", rc_strerror(st));
        return -1;
    }

    const int from_stdin = job->in_path == NULL || strcmp(job->in_path, "-") == 0;
    const char *in_name = from_stdin ? "<stdin>" : job->in_path;
    FILE *in = stdin;
    if (!from_stdin && (in = fopen(job->in_path, "r")) == NULL) {
        rch_diag_set(d, job->in_path, 0, 0, "%s", strerror(errno));
        return -1;
    }
    const char *const inputs[3] = {from_stdin ? NULL : job->in_path, job->model_path, job->nominal_path};
    rch_out o;
    if (rch_out_open(&o, job->out_path ? job->out_path : "-", "--out", inputs, 3, d) != 0) {
        if (in != stdin)
            fclose(in);
        return -1;
    }
    if (o.f == stdout)
        setvbuf(stdout, NULL, _IOLBF, 0);
    static rc_model fit_pt;
    rch_comp_point_model(&fit_pt, &robot.model, job->tool_mm);
    rch_out uo;
    int have_uo = 0;
    if (job->uncertainty_path) {
        const char *const uin[4] = {from_stdin ? NULL : job->in_path, job->model_path, job->nominal_path, job->out_path};
        if (rch_out_open(&uo, job->uncertainty_path, "--uncertainty-out", uin, 4, d) != 0) {
            if (in != stdin)
                fclose(in);
            if (o.f != stdout)
                rch_out_abort(&o);
            return -1;
        }
        have_uo = 1;
        fprintf(uo.f, "line,u95_mm\n");
    }
    const rch_comp_gate gate = {&fit_pt, unc.present && !res->version1 ? &unc : NULL, job->max_unc_mm,
                                job->accept_robtargets, have_uo ? uo.f : NULL, nom_raw, job->tool_mm,
                                &det_any, &robot.model, &cfg, job->u95_policy, job->assume_degrees,
                                job->nominal_path ? &nominal_robot.ctrl : &robot.ctrl, job->fanuc_frames_path};
    int rc = rch_comp_lines_gated(o.f, res, in, in_name, &s, &det, &gate, job->format, warn, d);
    if (in != stdin)
        fclose(in);
    if (rc < 0 && !d->file[0] && o.f != stdout && ferror(o.f)) /* a write error: the file it was writing */
        snprintf(d->file, sizeof d->file, "%.255s", o.path);
    if (rc < 0) {
        if (o.f != stdout)
            rch_out_abort(&o);
        else
            fflush(stdout);
        if (have_uo)
            rch_out_abort(&uo);
        return -1;
    }
    if (rch_out_commit(&o, d) != 0) {
        if (have_uo)
            rch_out_abort(&uo);
        return -1;
    }
    if (have_uo && rch_out_commit(&uo, d) != 0)
        return -1;
    return rc;
}
