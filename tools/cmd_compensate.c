/* cmd_compensate.c - rcal compensate: correct a robot program's joint targets
 * with a calibrated model, streaming (one line in, one line out, flushed).
 *
 * Input forms, detected from the first line that is not blank or a comment:
 *  - CSV without a header: six numbers per line, q1..q6 in degrees;
 *    output: the six corrected angles.
 *  - CSV with a header (first field not a number): the columns q1..q6 (or
 *    j1..j6), any case, are corrected; every other column (a target name, a
 *    speed, ...) is copied unchanged, so a whole program's target list goes
 *    through. The header line is copied.
 *  - ABB RAPID (a line starting with MODULE or %%%, or holding "jointtarget"):
 *    every "jointtarget NAME := [[q1,...,q6], [external axes]]" has its six
 *    robot axes corrected; every other line is copied unchanged.
 * Blank lines and lines starting with '#' are copied. A malformed line or a
 * target outside the joint limits stops the run with file:line:col. A target
 * that does not converge is written as the target plus the last good
 * correction (rc_comp_stream) and reported on stderr; the exit status is then
 * 1. */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <time.h>

#include "rc_comp.h"
#include "rcal_cmds.h"
#include "rcal_opts.h"
#include "rch_diag.h"
#include "rch_robot.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif
#define DEG (M_PI / 180.0)
#define MAX_FIELDS 64

static void usage(FILE *f)
{
    fprintf(f,
            "usage: rcal compensate --model MODEL.json [--in FILE|-] [--out FILE|-] [--nominal ROBOT.json]\n"
            "                       [--position-only] [--max-dev-deg D] [--format auto|csv|rapid] [--summary]\n"
            "Corrects joint targets computed with the nominal model so that the calibrated\n"
            "robot reaches the nominal flange pose: q' with FK_cal(q') = FK_nom(q).\n"
            "  --model          calibrated model (rcal-model/1, from rcal calibrate --out)\n"
            "  --nominal        nominal model the targets were made with (default: the\n"
            "                   model file's \"nominal\" table)\n"
            "  --in, --out      files, '-' for stdin/stdout (default); output is flushed per line\n"
            "  --position-only  match the flange position only (default: position and orientation)\n"
            "  --max-dev-deg    largest correction per joint (default 5.73 = 0.1 rad)\n"
            "  --format         input form (default auto): csv lines of q1..q6 in degrees, with\n"
            "                   or without a header (other columns are copied), or ABB RAPID\n"
            "                   jointtarget declarations\n"
            "  --summary        targets, iterations, largest correction and time on stderr\n");
}

typedef struct {
    rc_comp_stream stream;
    const char *in_name;
    FILE *out;
    int format; /* 0 auto, 1 csv, 2 rapid */
    int have_header;
    int qcol[RC_NJ]; /* header column of each joint */
    unsigned nfields_header;
    unsigned long n, n_fail, n_pos_only, iters;
    double max_corr_deg;
    double t_ns;
} comp_ctx;

static double now_ns(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec * 1e9 + (double)t.tv_nsec;
}

/* Split a line at commas. start[k]/len[k]: field k (trimmed); returns the
 * number of fields, or -1 when more than MAX_FIELDS. */
static int split_csv(const char *line, size_t n, size_t start[MAX_FIELDS], size_t len[MAX_FIELDS])
{
    int k = 0;
    size_t i = 0;
    for (;;) {
        if (k >= MAX_FIELDS)
            return -1;
        size_t b = i;
        while (b < n && (line[b] == ' ' || line[b] == '\t'))
            ++b;
        size_t e = b;
        while (e < n && line[e] != ',')
            ++e;
        size_t end = e;
        while (end > b && (line[end - 1] == ' ' || line[end - 1] == '\t' || line[end - 1] == '\r'))
            --end;
        start[k] = b;
        len[k] = end - b;
        ++k;
        if (e >= n)
            break;
        i = e + 1;
    }
    return k;
}

/* Parse a number occupying exactly text[0..len). */
static int parse_num(double *v, const char *text, size_t len)
{
    char buf[64];
    char *end;
    if (len == 0 || len >= sizeof buf)
        return -1;
    memcpy(buf, text, len);
    buf[len] = '\0';
    errno = 0;
    *v = strtod(buf, &end);
    if (*end != '\0' || errno != 0 || !isfinite(*v))
        return -1;
    return 0;
}

/* Compensate one target (degrees in, degrees out). 0 ok, 1 not converged
 * (output still written), -1 range error (d set). cols: (6) columns of the
 * fields for diagnostics. */
static int compensate(comp_ctx *c, double out_deg[RC_NJ], const double in_deg[RC_NJ], unsigned line,
                      const unsigned cols[RC_NJ], rch_diag *d)
{
    double q[RC_NJ], qc[RC_NJ];
    const rc_kin *m = &c->stream.own[0];
    for (unsigned i = 0; i < RC_NJ; ++i) {
        q[i] = in_deg[i] * DEG;
        if (q[i] < m->q_min_rad[i] || q[i] > m->q_max_rad[i]) {
            rch_diag_set(d, c->in_name, line, cols[i], "q%u = %g deg is outside the joint limits [%g, %g] deg", i + 1,
                         in_deg[i], m->q_min_rad[i] / DEG, m->q_max_rad[i] / DEG);
            return -1;
        }
    }
    rc_comp_result res;
    const double t0 = now_ns();
    rc_status st = rc_comp_stream_step(&c->stream, qc, &res, q);
    c->t_ns += now_ns() - t0;
    c->n++;
    c->iters += res.iterations;
    for (unsigned i = 0; i < RC_NJ; ++i)
        out_deg[i] = qc[i] / DEG;
    if (res.corr_max_rad / DEG > c->max_corr_deg)
        c->max_corr_deg = res.corr_max_rad / DEG;
    if (st == RC_OK) {
        if (res.exit == RC_COMP_POSITION_ONLY)
            c->n_pos_only++;
        return 0;
    }
    c->n_fail++;
    fprintf(stderr, "%s:%u: warning: target not compensated (%s: %s, position error %.4f mm); wrote the target plus "
                    "the last good correction\n",
            c->in_name, line, rc_strerror(st), rc_comp_exit_str(res.exit), res.pos_err_mm);
    return 1;
}

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

static const char *find_ci(const char *s, size_t n, const char *w)
{
    size_t k = strlen(w);
    for (size_t i = 0; i + k <= n; ++i)
        if (strncasecmp(s + i, w, k) == 0)
            return s + i;
    return NULL;
}

/* One CSV line (not blank, not a comment). 0 ok, 1 not converged, -1 error. */
static int do_csv(comp_ctx *c, const char *line, size_t n, unsigned lineno, rch_diag *d)
{
    size_t st[MAX_FIELDS], ln[MAX_FIELDS];
    const int nf = split_csv(line, n, st, ln);
    if (nf < 0) {
        rch_diag_set(d, c->in_name, lineno, 1, "more than %d fields", MAX_FIELDS);
        return -1;
    }
    if (!c->have_header) {
        if (nf != RC_NJ) {
            rch_diag_set(d, c->in_name, lineno, (unsigned)(nf > RC_NJ ? st[RC_NJ] + 1 : n + 1),
                         "expected 6 joint angles q1..q6 in degrees, found %d field%s", nf, nf == 1 ? "" : "s");
            return -1;
        }
    } else if ((unsigned)nf != c->nfields_header) {
        rch_diag_set(d, c->in_name, lineno, (unsigned)((unsigned)nf > c->nfields_header ? st[c->nfields_header] + 1 : n + 1),
                     "expected %u fields as in the header, found %d", c->nfields_header, nf);
        return -1;
    }
    double qd[RC_NJ], qo[RC_NJ];
    unsigned cols[RC_NJ];
    for (unsigned i = 0; i < RC_NJ; ++i) {
        const int k = c->have_header ? c->qcol[i] : (int)i;
        cols[i] = (unsigned)st[k] + 1;
        if (parse_num(&qd[i], line + st[k], ln[k]) != 0) {
            rch_diag_set(d, c->in_name, lineno, cols[i], "q%u: '%.*s' is not a finite number", i + 1,
                         (int)(ln[k] > 40 ? 40 : ln[k]), line + st[k]);
            return -1;
        }
    }
    const int r = compensate(c, qo, qd, lineno, cols, d);
    if (r < 0)
        return r;
    for (int k = 0; k < nf; ++k) {
        int j = -1;
        for (int i = 0; i < RC_NJ; ++i)
            if ((c->have_header ? c->qcol[i] : i) == k)
                j = i;
        if (k > 0)
            fputc(',', c->out);
        if (j >= 0)
            fprintf(c->out, "%.6f", qo[j]);
        else
            fwrite(line + st[k], 1, ln[k], c->out);
    }
    fputc('\n', c->out);
    return r;
}

/* Header line: find q1..q6 (or j1..j6). 0 or -1. */
static int do_header(comp_ctx *c, const char *line, size_t n, unsigned lineno, rch_diag *d)
{
    size_t st[MAX_FIELDS], ln[MAX_FIELDS];
    const int nf = split_csv(line, n, st, ln);
    if (nf < 0) {
        rch_diag_set(d, c->in_name, lineno, 1, "more than %d header fields", MAX_FIELDS);
        return -1;
    }
    for (int i = 0; i < RC_NJ; ++i) {
        c->qcol[i] = -1;
        for (int k = 0; k < nf; ++k) {
            char qn[3] = {'q', (char)('1' + i), '\0'}, jn[3] = {'j', (char)('1' + i), '\0'};
            if (ln[k] == 2 && (strncasecmp(line + st[k], qn, 2) == 0 || strncasecmp(line + st[k], jn, 2) == 0)) {
                if (c->qcol[i] >= 0) {
                    rch_diag_set(d, c->in_name, lineno, (unsigned)st[k] + 1, "column q%d appears twice", i + 1);
                    return -1;
                }
                c->qcol[i] = k;
            }
        }
        if (c->qcol[i] < 0) {
            rch_diag_set(d, c->in_name, lineno, 1, "header has no q%d column (need q1..q6, degrees)", i + 1);
            return -1;
        }
    }
    c->have_header = 1;
    c->nfields_header = (unsigned)nf;
    fwrite(line, 1, n, c->out);
    fputc('\n', c->out);
    return 0;
}

/* RAPID: rewrite the robax of a jointtarget declaration; other lines copied. */
static int do_rapid(comp_ctx *c, const char *line, size_t n, unsigned lineno, rch_diag *d)
{
    const char *jt = find_ci(line, n, "jointtarget");
    const char *as = jt ? find_ci(jt, n - (size_t)(jt - line), ":=") : NULL;
    if (as == NULL) { /* not a declaration with a value: copy */
        fwrite(line, 1, n, c->out);
        fputc('\n', c->out);
        return 0;
    }
    const char *p = as + 2, *end = line + n;
    while (p < end && (*p == ' ' || *p == '\t'))
        ++p;
    if (end - p < 2 || p[0] != '[' || p[1] != '[') {
        rch_diag_set(d, c->in_name, lineno, (unsigned)(p - line) + 1, "expected [[q1,...,q6],[...]] after :=");
        return -1;
    }
    const char *body = p + 2;
    const char *close = memchr(body, ']', (size_t)(end - body));
    if (close == NULL) {
        rch_diag_set(d, c->in_name, lineno, (unsigned)(body - line) + 1, "missing ']' after the robot axes");
        return -1;
    }
    size_t st[MAX_FIELDS], ln[MAX_FIELDS];
    const int nf = split_csv(body, (size_t)(close - body), st, ln);
    if (nf != RC_NJ) {
        rch_diag_set(d, c->in_name, lineno, (unsigned)(body - line) + 1, "expected 6 robot axes, found %d", nf);
        return -1;
    }
    double qd[RC_NJ], qo[RC_NJ];
    unsigned cols[RC_NJ];
    for (int i = 0; i < RC_NJ; ++i) {
        cols[i] = (unsigned)(body - line) + (unsigned)st[i] + 1;
        if (parse_num(&qd[i], body + st[i], ln[i]) != 0) {
            rch_diag_set(d, c->in_name, lineno, cols[i], "axis %d: '%.*s' is not a finite number", i + 1,
                         (int)(ln[i] > 40 ? 40 : ln[i]), body + st[i]);
            return -1;
        }
    }
    const int r = compensate(c, qo, qd, lineno, cols, d);
    if (r < 0)
        return r;
    fwrite(line, 1, (size_t)(body - line), c->out);
    fprintf(c->out, "%.4f,%.4f,%.4f,%.4f,%.4f,%.4f", qo[0], qo[1], qo[2], qo[3], qo[4], qo[5]);
    fwrite(close, 1, (size_t)(end - close), c->out);
    fputc('\n', c->out);
    return r;
}

int rcal_cmd_compensate(int argc, char **argv)
{
    const char *model_path = NULL, *nominal_path = NULL, *in_path = "-", *out_path = "-", *format = "auto";
    double max_dev_deg = 0.0;
    int position_only = 0, summary = 0;
    for (int i = 1; i < argc; ++i) {
        if (rcal_opt_str(argc, argv, &i, "--model", &model_path) ||
            rcal_opt_str(argc, argv, &i, "--nominal", &nominal_path) ||
            rcal_opt_str(argc, argv, &i, "--in", &in_path) || rcal_opt_str(argc, argv, &i, "--out", &out_path) ||
            rcal_opt_str(argc, argv, &i, "--format", &format) ||
            rcal_opt_double(argc, argv, &i, "--max-dev-deg", &max_dev_deg))
            continue;
        if (strcmp(argv[i], "--position-only") == 0) {
            position_only = 1;
            continue;
        }
        if (strcmp(argv[i], "--summary") == 0) {
            summary = 1;
            continue;
        }
        if (strcmp(argv[i], "--help") == 0) {
            usage(stdout);
            return 0;
        }
        return rcal_opt_unknown("compensate", argv[i]);
    }
    if (!model_path)
        return rcal_opt_missing("compensate", "--model");
    comp_ctx c;
    memset(&c, 0, sizeof c);
    if (strcmp(format, "auto") == 0)
        c.format = 0;
    else if (strcmp(format, "csv") == 0)
        c.format = 1;
    else if (strcmp(format, "rapid") == 0)
        c.format = 2;
    else {
        fprintf(stderr, "rcal compensate: --format must be auto, csv or rapid\n");
        return 2;
    }
    if (max_dev_deg < 0.0) {
        fprintf(stderr, "rcal compensate: --max-dev-deg must be positive\n");
        return 2;
    }

    static rch_robot robot, nominal_robot;
    rch_diag d;
    char msg[1024];
    if (rch_robot_load(&robot, model_path, &d) != 0 ||
        (nominal_path && rch_robot_load(&nominal_robot, nominal_path, &d) != 0)) {
        fprintf(stderr, "rcal compensate: %s\n", rch_diag_str(&d, msg, sizeof msg));
        return 1;
    }
    const rc_model *nom = nominal_path ? &nominal_robot.model : &robot.nominal;
    if (!nominal_path && !robot.has_nominal)
        fprintf(stderr, "rcal compensate: warning: %s has no \"nominal\" table; only its effects are corrected\n",
                model_path);
    rc_comp_config cfg;
    memset(&cfg, 0, sizeof cfg);
    cfg.max_dev_rad = max_dev_deg * DEG;
    cfg.flags = position_only ? RC_COMP_FLAG_POSITION_ONLY : 0u;
    rc_comp_stream_init(&c.stream, &robot.model, nom, &cfg);

    FILE *in = stdin;
    c.in_name = "<stdin>";
    if (strcmp(in_path, "-") != 0) {
        in = fopen(in_path, "r");
        if (!in) {
            fprintf(stderr, "rcal compensate: %s: %s\n", in_path, strerror(errno));
            return 1;
        }
        c.in_name = in_path;
    }
    c.out = stdout;
    if (strcmp(out_path, "-") != 0) {
        c.out = fopen(out_path, "w");
        if (!c.out) {
            fprintf(stderr, "rcal compensate: %s: %s\n", out_path, strerror(errno));
            if (in != stdin)
                fclose(in);
            return 1;
        }
    }
    setvbuf(c.out, NULL, _IOLBF, 0);

    char *line = NULL;
    size_t cap = 0;
    ssize_t got;
    unsigned lineno = 0;
    int rc = 0, decided = c.format != 0;
    while ((got = getline(&line, &cap, in)) >= 0) {
        size_t n = (size_t)got;
        ++lineno;
        while (n > 0 && (line[n - 1] == '\n' || line[n - 1] == '\r'))
            --n;
        if (memchr(line, '\0', n) != NULL) {
            rch_diag_set(&d, c.in_name, lineno, (unsigned)((const char *)memchr(line, '\0', n) - line) + 1,
                         "NUL byte in text input");
            rc = -1;
            break;
        }
        if (c.format != 2 && is_comment_or_blank(line, n)) {
            fwrite(line, 1, n, c.out);
            fputc('\n', c.out);
            continue;
        }
        int r;
        if (!decided) {
            decided = 1;
            if (starts_with_ci(line, n, "MODULE") || starts_with_ci(line, n, "%%%") || find_ci(line, n, "jointtarget")) {
                c.format = 2;
            } else {
                size_t st[MAX_FIELDS], ln[MAX_FIELDS];
                double v;
                c.format = 1;
                if (split_csv(line, n, st, ln) > 0 && parse_num(&v, line + st[0], ln[0]) != 0) {
                    r = do_header(&c, line, n, lineno, &d);
                    if (r < 0) {
                        rc = -1;
                        break;
                    }
                    continue;
                }
            }
        }
        r = c.format == 2 ? do_rapid(&c, line, n, lineno, &d) : do_csv(&c, line, n, lineno, &d);
        if (r < 0) {
            rc = -1;
            break;
        }
        if (r > 0)
            rc = 1;
    }
    free(line);
    if (rc >= 0 && ferror(in)) {
        fprintf(stderr, "rcal compensate: reading %s: %s\n", c.in_name, strerror(errno));
        rc = -2;
    }
    if (in != stdin)
        fclose(in);
    int werr = fflush(c.out) != 0 || ferror(c.out);
    if (c.out != stdout)
        werr |= fclose(c.out) != 0;
    if (rc == -1)
        fprintf(stderr, "rcal compensate: %s\n", rch_diag_str(&d, msg, sizeof msg));
    if (werr) {
        fprintf(stderr, "rcal compensate: writing %s failed\n", out_path);
        return 1;
    }
    if (summary)
        fprintf(stderr,
                "rcal compensate: %lu targets, %lu not converged, %lu with the orientation best effort (position "
                "matched), %.2f iterations/target, largest correction %.4f deg, %.2f us/target\n",
                c.n, c.n_fail, c.n_pos_only, c.n ? (double)c.iters / (double)c.n : 0.0, c.max_corr_deg,
                c.n ? c.t_ns / (double)c.n / 1e3 : 0.0);
    return rc == 0 ? 0 : 1;
}
