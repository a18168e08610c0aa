/* SPDX-License-Identifier: MIT */
#include "rch_data.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "rc_rand.h"
#include "rch_file.h"
#include "rch_opt.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

enum { C_Q1 = 0, C_L = 6, C_X = 7, C_Y = 8, C_Z = 9, C_T = 10, C_G = 11, C_P = 12, C_O = 13, C_TG = 14, C_SG = 15,
       C_N = 16 };
static const char *const col_names[C_N] = {"q1", "q2", "q3",    "q4",   "q5",     "q6",     "L",      "x",
                                           "y",  "z",  "t",     "group", "pose", "outlet", "target", "sigma_mm"};

typedef struct {
    const char *p; /* field start */
    size_t len;
    unsigned col;  /* 1-based column of the first character */
} field;

/* Split one line (without its terminator) into fields; returns the count. */
static size_t split_line(field *f, size_t max, const char *line, size_t len)
{
    size_t n = 0, start = 0;
    for (size_t i = 0; i <= len; ++i) {
        if (i == len || line[i] == ',') {
            if (n < max) {
                size_t a = start, b = i;
                while (a < b && (line[a] == ' ' || line[a] == '\t'))
                    ++a;
                while (b > a && (line[b - 1] == ' ' || line[b - 1] == '\t' || line[b - 1] == '\r'))
                    --b;
                f[n].p = line + a;
                f[n].len = b - a;
                f[n].col = (unsigned)(a + 1);
            }
            ++n;
            start = i + 1;
        }
    }
    return n;
}

/* The one strict number reader (rch_parse_double: decimal only, no blanks,
 * no hex, no overflow). NaN and infinity words come back as such, so that
 * the caller names them ("not finite") rather than "not a number". */
static int parse_number(double *v, const field *f)
{
    char buf[64];
    if (f->len == 0 || f->len >= sizeof buf)
        return -1;
    memcpy(buf, f->p, f->len);
    buf[f->len] = '\0';
    if (rch_parse_double(buf, v) == 0)
        return 0;
    {
        const char *w = buf + (buf[0] == '+' || buf[0] == '-');
        if (strcasecmp(w, "nan") == 0) {
            *v = NAN;
            return 0;
        }
        if (strcasecmp(w, "inf") == 0 || strcasecmp(w, "infinity") == 0) {
            *v = buf[0] == '-' ? -INFINITY : INFINITY;
            return 0;
        }
    }
    return -1;
}

/* 1 when nothing but NUL bytes and blanks follows text[from..len). */
static int is_last_line(const char *text, size_t from, size_t len)
{
    for (size_t i = from; i < len; ++i)
        if (text[i] != '\0' && !isspace((unsigned char)text[i]))
            return 0;
    return 1;
}

/* What a header without the needed columns looks like, when it is a
 * known other convention ("" otherwise). */
static const char *header_hint(const char *line, size_t len)
{
    if (memchr(line, '\t', len))
        return "; the header is separated by tabs: rcal reads comma-separated values";
    if (memchr(line, ';', len))
        return "; the header is separated by semicolons: rcal reads comma-separated values with '.' decimals";
    return "";
}

static const char *number_hint(const field *f)
{
    if (f->len > 0 && (f->p[0] == '"' || f->p[0] == '\''))
        return " (quoted: write numbers without quotes)";
    size_t i = f->len > 0 && (f->p[0] == '+' || f->p[0] == '-') ? 1u : 0u;
    if (f->len > i + 1 && f->p[i] == '0' && (f->p[i + 1] == 'x' || f->p[i + 1] == 'X'))
        return " (hexadecimal numbers are not accepted: write decimals)";
    if (memchr(f->p, ';', f->len) || memchr(f->p, '\t', f->len))
        return " (separators must be commas)";
    if (f->len > 1 && (f->p[f->len - 1] == 'e' || f->p[f->len - 1] == 'E' ||
                       ((f->p[f->len - 1] == '+' || f->p[f->len - 1] == '-') &&
                        (f->p[f->len - 2] == 'e' || f->p[f->len - 2] == 'E'))))
        return " (an exponent without its digits)";
    return "";
}

/* The parser's state while it walks the text. */
typedef struct parse_ctx {
    const char *name;
    unsigned flags;
    rch_diag *d;
    int col_of[C_N]; /* field index of each known column, -1 absent */
    size_t cap;      /* allocated rows */
    unsigned line_no;
    const rc_model *lim; /* joint limits of the robot, or NULL */
    size_t n_header;     /* fields of the header line */
    int implicit;        /* RCH_DATA_TARGETS without a header: the columns are q1..q6 by position */
    const char *nm[C_N]; /* the columns' names: col_names, a sensor file's label (and value) its own */
} parse_ctx;

/* 1 when field f (quotes removed) is a column name the reader knows. */
static int names_a_column(const field *f)
{
    const char *p = f->p;
    size_t n = f->len;
    if (n >= 2 && p[0] == '"' && p[n - 1] == '"') {
        ++p;
        n -= 2;
    }
    for (int k = 0; k < C_N; ++k)
        if (n == strlen(col_names[k]) && strncasecmp(p, col_names[k], n) == 0)
            return 1;
    return 0;
}

/* RCH_DATA_TARGETS: is the first line a header? By its names only: a line
 * none of whose fields names a column is the first target (and its fields
 * are then read as numbers, each refused with its column if it is not). */
static int is_header_line(const field *fields, size_t nf)
{
    for (size_t i = 0; i < nf; ++i)
        if (names_a_column(&fields[i]))
            return 1;
    return 0;
}

/* The header line: find the known columns. 0 or -1 with d set. */
static int parse_header(parse_ctx *pc, field *fields, size_t nf, const char *line, size_t ll)
{
    const unsigned flags = pc->flags;
    for (size_t i = 0; i < nf; ++i) {
        if (fields[i].len >= 2 && fields[i].p[0] == '"' && fields[i].p[fields[i].len - 1] == '"') {
            fields[i].p++; /* "q1": a quoted header name is the name */
            fields[i].len -= 2;
        }
        for (int k = 0; k < C_N; ++k) {
            if (fields[i].len == strlen(pc->nm[k]) && strncasecmp(fields[i].p, pc->nm[k], fields[i].len) == 0) {
                if (pc->col_of[k] >= 0) {
                    rch_diag_set(pc->d, pc->name, pc->line_no, fields[i].col, "column '%s' appears twice in the header",
                                 pc->nm[k]);
                    return -1;
                }
                pc->col_of[k] = (int)i;
            }
        }
    }
    for (int k = 0; k <= C_P; ++k) {
        if (k > C_L && k != C_P)
            continue;
        if (pc->col_of[k] < 0 && !(k == C_L && (flags & RCH_DATA_NO_LEN)) && !(k == C_P && !(flags & RCH_DATA_POSE))) {
            rch_diag_set(pc->d, pc->name, pc->line_no, 1, "header has no '%s' column (need %sq1..q6 in degrees%s)%s",
                         col_names[k], (flags & RCH_DATA_POSE) ? "pose, " : "",
                         (flags & RCH_DATA_NO_LEN) ? "" : " and L in mm", header_hint(line, ll));
            return -1;
        }
    }
    if (flags & RCH_DATA_POSITIONS)
        for (int k = C_X; k <= C_Z; ++k)
            if (pc->col_of[k] < 0) {
                rch_diag_set(pc->d, pc->name, pc->line_no, 1,
                             "header has no '%s' column (a positions file needs q1..q6 in degrees and x, y, z in mm "
                             "in the tracker's frame)%s",
                             col_names[k], header_hint(line, ll));
                return -1;
            }
    if ((flags & RCH_DATA_SENSOR) && pc->col_of[C_TG] < 0) {
        rch_diag_set(pc->d, pc->name, pc->line_no, 1, "header has no '%s' column%s", pc->nm[C_TG],
                     header_hint(line, ll));
        return -1;
    }
    if ((flags & RCH_DATA_SENSOR) && pc->nm[C_L] == col_names[C_L])
        pc->col_of[C_L] = -1; /* a sensor without a measured value: an L column is not its */
    if (flags & RCH_DATA_SENSOR)
        pc->col_of[C_X] = pc->col_of[C_Y] = pc->col_of[C_Z] = pc->col_of[C_O] = -1;
    if ((pc->col_of[C_X] >= 0) != (pc->col_of[C_Y] >= 0) || (pc->col_of[C_X] >= 0) != (pc->col_of[C_Z] >= 0))
        pc->col_of[C_X] = pc->col_of[C_Y] = pc->col_of[C_Z] = -1; /* use x,y,z only as a triple */
    if (!(flags & (RCH_DATA_POSITIONS | RCH_DATA_SENSOR)))
        pc->col_of[C_SG] = -1; /* a positions or sensor file's column only (a cable file's target: the tool point the
                                  cable is on, RC_EFF_CABLE_POINTS) */
    return 0;
}

/* Room for one more row. 0 or -1 with d set. */
static int grow(rch_data *out, parse_ctx *pc)
{
    size_t nc;
    if (out->n < pc->cap)
        return 0;
    if (out->n >= RCH_DATA_MAX_ROWS) {
        rch_diag_set(pc->d, pc->name, pc->line_no, 1,
                     "more than %lu data rows: refused (a calibration needs about 560 bytes of memory per row; "
                     "use a subset)",
                     (unsigned long)RCH_DATA_MAX_ROWS);
        return -1;
    }
    nc = pc->cap ? 2 * pc->cap : 256;
    if (nc > RCH_DATA_MAX_ROWS)
        nc = RCH_DATA_MAX_ROWS;
    rc_sample *s = realloc(out->s, nc * sizeof *s);
    if (s)
        out->s = s;
    unsigned *ln = s ? realloc(out->line, nc * sizeof *ln) : NULL;
    if (ln)
        out->line = ln;
    if (s && ln && pc->col_of[C_SG] >= 0) {
        double *sg = realloc(out->sigma_mm, nc * sizeof *sg);
        if (sg)
            out->sigma_mm = sg;
        s = sg ? s : NULL;
    }
    if (s && ln && pc->col_of[C_P] >= 0 && (pc->flags & (RCH_DATA_POSE | RCH_DATA_POSITIONS | RCH_DATA_SENSOR))) {
        unsigned long *pz = realloc(out->pose, nc * sizeof *pz);
        if (pz)
            out->pose = pz;
        s = pz ? s : NULL;
    }
    if (s && ln && pc->col_of[C_X] >= 0) {
        double(*xyz)[3] = realloc(out->xyz, nc * sizeof *xyz);
        if (xyz)
            out->xyz = xyz;
        s = xyz ? s : NULL;
    }
    if (!s || !ln) {
        rch_diag_set(pc->d, pc->name, pc->line_no, 0, "out of memory");
        return -1;
    }
    pc->cap = nc;
    return 0;
}

/* Joint j's reading v (degrees, as written) beyond the robot's limits by
 * more than the file's rounding. */
static int out_of_limits(const rc_model *m, int j, double v)
{
    const double lo = m->q_min_rad[j] * (180.0 / M_PI) - RCH_DATA_LIMIT_TOL_DEG,
                 hi = m->q_max_rad[j] * (180.0 / M_PI) + RCH_DATA_LIMIT_TOL_DEG;
    return v < lo || v > hi;
}

/* Range of one field's value v of column k: 0, or -1 with d set. */
static int check_value(const parse_ctx *pc, int k, double v, const field *f)
{
    const char *nm = pc->nm[k];
    const unsigned ln = pc->line_no, col = f->col;
    if (!isfinite(v))
        rch_diag_set(pc->d, pc->name, ln, col, "field '%s': %s is not finite (no sensor reads it: fix or remove the row)",
                     nm, isnan(v) ? "NaN" : "infinity");
    else if (k < C_L && fabs(v) > 720.0)
        rch_diag_set(pc->d, pc->name, ln, col, "field '%s': %g degrees is outside -720..720", nm, v);
    else if (k == C_L && (pc->flags & RCH_DATA_SENSOR) && fabs(v) > 1e4)
        rch_diag_set(pc->d, pc->name, ln, col, "field '%s': %g mm is not a reading of this sensor (|value| <= 10000 mm)",
                     nm, v);
    else if (k == C_L && !(pc->flags & RCH_DATA_SENSOR) && !(v >= RCH_DATA_MIN_LEN_MM && v <= 20000.0))
        rch_diag_set(pc->d, pc->name, ln, col,
                     "field 'L': %g mm is not a cable length a draw-wire encoder reads (%g <= L <= 20000 mm): %s",
                     v, RCH_DATA_MIN_LEN_MM,
                     v > 0.0 && v < 1.0 && v >= 0.01 ? "metres? rcal reads millimetres (multiply by 1000)"
                                                     : "check the column's unit and the display, or remove the row");
    else if (k < C_L && pc->lim && out_of_limits(pc->lim, k - C_Q1, v))
        rch_diag_set(pc->d, pc->name, ln, col,
                     "field '%s': %.10g deg is outside joint %d's limits [%g, %g] deg of the robot model (%g deg "
                     "allowed for rounding): no reading of this robot; check --robot and the column order",
                     nm, v, k - C_Q1 + 1, pc->lim->q_min_rad[k - C_Q1] * (180.0 / M_PI),
                     pc->lim->q_max_rad[k - C_Q1] * (180.0 / M_PI), RCH_DATA_LIMIT_TOL_DEG);
    else if ((k == C_X || k == C_Y || k == C_Z) && fabs(v) > 1e5)
        rch_diag_set(pc->d, pc->name, ln, col, "field '%s': %g mm is absurd", nm, v);
    else if (k == C_T && fabs(v) > 1e300) /* t_max - t_min must stay finite when scaling */
        rch_diag_set(pc->d, pc->name, ln, col, "field 't': %g is absurd", v);
    else if (k == C_P && (v < 0.0 || v > 1e9 || v != floor(v)))
        rch_diag_set(pc->d, pc->name, ln, col, "field 'pose': %g is not an integer in 0..1000000000", v);
    else if (k == C_G && (v < 0.0 || v > 65535.0 || v != floor(v)))
        rch_diag_set(pc->d, pc->name, ln, col, "field 'group': %g is not an integer in 0..65535", v);
    else if (k == C_TG && (v < 0.0 || v >= RC_MAX_TARGETS || v != floor(v)))
        rch_diag_set(pc->d, pc->name, ln, col, "field '%s': %g is not a %s number (an integer 0..%d)", nm, v, nm,
                     RC_MAX_TARGETS - 1);
    else if (k == C_SG && !(v > 0.0 && v <= 100.0))
        rch_diag_set(pc->d, pc->name, ln, col, "field 'sigma_mm': %g is not a sensor's standard deviation (0 < sigma "
                     "<= 100 mm)", v);
    else if (k == C_O && (v < 0.0 || v > 255.0 || v != floor(v)))
        rch_diag_set(pc->d, pc->name, ln, col,
                     "field 'outlet': %g is not an outlet number (an integer 0..255 naming where the encoder stood)",
                     v);
    else
        return 0;
    return -1;
}

/* A row of as many fields as the header: a decimal comma ("12,5") or a
 * lost field shifts every later column, so neither is read. Empty fields
 * after the header's last (a trailing comma) are no shift. 0 or -1 with d set. */
static int check_field_count(const parse_ctx *pc, const field *fields, size_t nf, size_t ll)
{
    const size_t nh = pc->n_header;
    size_t last = nf;
    while (last > nh && fields[last - 1].len == 0)
        --last;
    if (pc->implicit && (last > nh || nf < nh)) {
        rch_diag_set(pc->d, pc->name, pc->line_no, last > nh ? fields[nh].col : (unsigned)ll + 1,
                     "the row has %zu field%s: a file without a header line holds the six joint angles q1..q6 "
                     "(degrees) per row; a decimal comma ('12,5' for 12.5) or a missing or extra field shifts them "
                     "(name the columns in a header line to add others)",
                     last > nh ? last : nf, (last > nh ? last : nf) == 1 ? "" : "s");
        return -1;
    }
    if (last > nh) {
        rch_diag_set(pc->d, pc->name, pc->line_no, fields[nh].col,
                     "the row has %zu fields, the header %zu: a decimal comma ('12,5' for 12.5; rcal reads '.' "
                     "decimals) or a field too many shifts the columns; fix or remove the row",
                     last, nh);
        return -1;
    }
    if (nf < nh) {
        int k_lost = -1; /* the first column read that the row lacks */
        for (int k = 0; k < C_N; ++k)
            if (pc->col_of[k] >= (int)nf && (k_lost < 0 || pc->col_of[k] < pc->col_of[k_lost]))
                k_lost = k;
        rch_diag_set(pc->d, pc->name, pc->line_no, (unsigned)ll + 1,
                     "%s%s%sthe row has %zu fields, the header %zu: a field is missing and the columns after it are "
                     "shifted (an empty field is still written: 1,,3); fix or remove the row",
                     k_lost >= 0 ? "missing field '" : "", k_lost >= 0 ? pc->nm[k_lost] : "",
                     k_lost >= 0 ? "': " : "", nf, nh);
        return -1;
    }
    return 0;
}

/* One data row into out->[n]. 0 or -1 with d set. */
static int parse_row(rch_data *out, parse_ctx *pc, const field *fields, size_t nf, size_t ll)
{
    double v[C_N] = {0};
    rc_sample *s;
    if (check_field_count(pc, fields, nf, ll) != 0 || grow(out, pc) != 0)
        return -1;
    for (int k = 0; k < C_N; ++k) {
        if (pc->col_of[k] < 0 || (k == C_P && !(pc->flags & (RCH_DATA_POSE | RCH_DATA_POSITIONS | RCH_DATA_SENSOR))))
            continue;
        const size_t c = (size_t)pc->col_of[k];
        if (c >= nf) {
            rch_diag_set(pc->d, pc->name, pc->line_no, (unsigned)ll + 1,
                         "missing field '%s' (column %zu; the line has %zu fields)", pc->nm[k], c + 1, nf);
            return -1;
        }
        if (parse_number(&v[k], &fields[c]) != 0) {
            rch_diag_set(pc->d, pc->name, pc->line_no, fields[c].col, "field '%s': '%.*s' is not a number%s%s",
                         pc->nm[k], (int)(fields[c].len > 40 ? 40 : fields[c].len), fields[c].p,
                         number_hint(&fields[c]),
                         pc->implicit && out->n == 0 && fields[c].len > 0 && isalpha((unsigned char)fields[c].p[0])
                             ? " (a first line is a header only when it names its columns: q1,q2,q3,q4,q5,q6)"
                             : "");
            return -1;
        }
        if (check_value(pc, k, v[k], &fields[c]) != 0)
            return -1;
    }
    s = &out->s[out->n];
    memset(s, 0, sizeof *s);
    for (int j = 0; j < RC_NJ; ++j)
        s->q_rad[j] = v[C_Q1 + j] * (M_PI / 180.0);
    s->value = v[C_L];
    s->t = v[C_T];
    s->group = (uint16_t)v[C_G];
    s->outlet = (uint8_t)v[C_O]; /* the file's label: rch_data_outlets numbers them 0.. */
    s->target = (uint8_t)v[C_TG];
    if (out->sigma_mm)
        out->sigma_mm[out->n] = v[C_SG];
    if (out->xyz) {
        out->xyz[out->n][0] = v[C_X];
        out->xyz[out->n][1] = v[C_Y];
        out->xyz[out->n][2] = v[C_Z];
    }
    if (out->pose)
        out->pose[out->n] = (unsigned long)v[C_P];
    out->line[out->n] = pc->line_no;
    ++out->n;
    return 0;
}

/* Acquisition order scaled to [0, 1]: the t column if present, else the row order. */
static void scale_t(rch_data *out)
{
    double tmin = 0.0, tmax = 0.0;
    for (size_t i = 0; i < out->n; ++i) {
        if (!out->has_t)
            out->s[i].t = (double)i;
        if (i == 0 || out->s[i].t < tmin)
            tmin = out->s[i].t;
        if (i == 0 || out->s[i].t > tmax)
            tmax = out->s[i].t;
    }
    for (size_t i = 0; i < out->n; ++i)
        out->s[i].t = tmax > tmin ? (out->s[i].t - tmin) / (tmax - tmin) : 0.0;
}

/* A NUL byte in line: its message (what a power cut leaves, when last). */
static int nul_check(const parse_ctx *pc, const char *line, size_t ll, const char *text, size_t next, size_t len)
{
    const char *z = memchr(line, '\0', ll);
    if (!z)
        return 0;
    if (is_last_line(text, next, len))
        rch_diag_set(pc->d, pc->name, pc->line_no, (unsigned)(z - line) + 1,
                     "the last line holds NUL bytes, what a power cut during a write leaves: rerun `rcal acquire` "
                     "with the same --out to move it to %s.dropped, or delete that line", pc->name);
    else
        rch_diag_set(pc->d, pc->name, pc->line_no, (unsigned)(z - line) + 1, "NUL byte in text");
    return -1;
}

static int parse(rch_data *out, const char *text, size_t len, const char *name, unsigned flags,
                 const rc_model *lim, const char *label, const char *value, rch_diag *d)
{
    field fields[256];
    size_t pos = 0;
    int have_header = 0;
    parse_ctx pc;
    memset(out, 0, sizeof *out);
    memset(&pc, 0, sizeof pc);
    pc.name = name;
    pc.flags = flags;
    pc.d = d;
    pc.lim = lim;
    for (int k = 0; k < C_N; ++k) {
        pc.col_of[k] = -1;
        pc.nm[k] = col_names[k];
    }
    if (flags & RCH_DATA_SENSOR) {
        pc.nm[C_TG] = label;
        if (value)
            pc.nm[C_L] = value; /* optional: 0 where the file has none */
        flags |= RCH_DATA_NO_LEN;
        pc.flags = flags;
    }
    if (len >= 3 && memcmp(text, "\xEF\xBB\xBF", 3) == 0)
        pos = 3; /* UTF-8 byte-order mark (spreadsheet export) */
    while (pos < len) {
        size_t e = pos, blank = 0;
        /* a line ends at '\n', or at a '\r' not followed by '\n' (CR-only files) */
        while (e < len && text[e] != '\n' && !(text[e] == '\r' && (e + 1 == len || text[e + 1] != '\n')))
            ++e;
        const char *line = text + pos;
        size_t ll = e - pos;
        pos = e + 1;
        ++pc.line_no;
        if (ll > 0 && line[ll - 1] == '\r')
            --ll;
        while (blank < ll && isspace((unsigned char)line[blank]))
            ++blank;
        if (blank == ll || line[blank] == '#')
            continue;
        if (nul_check(&pc, line, ll, text, pos, len) != 0)
            goto fail;
        const size_t nf = split_line(fields, 256, line, ll);
        if (nf > 256) {
            rch_diag_set(d, name, pc.line_no, 1, "too many columns (%zu, at most 256)", nf);
            goto fail;
        }
        if (!have_header && (flags & RCH_DATA_TARGETS) && !is_header_line(fields, nf)) {
            for (int k = 0; k < RC_NJ; ++k) /* no header: q1..q6 by position, this line the first row */
                pc.col_of[C_Q1 + k] = k;
            pc.n_header = RC_NJ;
            pc.implicit = 1;
            have_header = 1;
        }
        if (!have_header) {
            if (parse_header(&pc, fields, nf, line, ll) != 0)
                goto fail;
            pc.n_header = nf;
            have_header = 1;
        } else if (parse_row(out, &pc, fields, nf, ll) != 0) {
            goto fail;
        }
    }
    if (!have_header) {
        rch_diag_set(d, name, 0, 0, (flags & RCH_DATA_TARGETS) ? "empty file: no targets" : "empty file: no header line");
        goto fail;
    }
    if (out->n == 0 && !(flags & RCH_DATA_ALLOW_EMPTY)) {
        rch_diag_set(d, name, pc.line_no, 0, "no data rows after the header");
        goto fail;
    }
    out->has_t = pc.col_of[C_T] >= 0;
    out->has_group = pc.col_of[C_G] >= 0;
    out->has_outlet = pc.col_of[C_O] >= 0;
    out->has_target = pc.col_of[C_TG] >= 0;
    scale_t(out);
    return 0;
fail:
    rch_data_free(out);
    return -1;
}

int rch_data_parse(rch_data *out, const char *text, size_t len, const char *name, unsigned flags,
                   rch_diag *d)
{
    return parse(out, text, len, name, flags, NULL, NULL, NULL, d);
}

int rch_data_parse_limited(rch_data *out, const char *text, size_t len, const char *name, unsigned flags,
                           const rc_model *limits, rch_diag *d)
{
    return parse(out, text, len, name, flags, limits, NULL, NULL, d);
}

int rch_data_parse_sensor(rch_data *out, const char *text, size_t len, const char *name, const char *label,
                          const char *value, const rc_model *limits, rch_diag *d)
{
    return parse(out, text, len, name, RCH_DATA_SENSOR, limits, label, value, d);
}

int rch_data_header_has(const char *text, size_t len, const char *column)
{
    field fields[256];
    size_t pos = len >= 3 && memcmp(text, "\xEF\xBB\xBF", 3) == 0 ? 3u : 0u;
    while (pos < len) { /* the first line that is neither blank nor a comment */
        size_t e = pos, blank = 0;
        while (e < len && text[e] != '\n' && text[e] != '\r')
            ++e;
        const char *line = text + pos;
        const size_t ll = e - pos;
        pos = e + 1;
        while (blank < ll && isspace((unsigned char)line[blank]))
            ++blank;
        if (blank == ll || line[blank] == '#')
            continue;
        const size_t nf = split_line(fields, 256, line, ll);
        for (size_t i = 0; i < nf && i < 256; ++i) {
            const char *p = fields[i].p;
            size_t n = fields[i].len;
            if (n >= 2 && p[0] == '"' && p[n - 1] == '"') {
                ++p;
                n -= 2;
            }
            if (n == strlen(column) && strncasecmp(p, column, n) == 0)
                return 1;
        }
        return 0;
    }
    return 0;
}

/* ---- scale of lengths and positions against the robot (issue 33) ---- */

static int cmp_double(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Median absolute deviation of v (n), sorted in place. */
static double mad(double *v, size_t n)
{
    qsort(v, n, sizeof v[0], cmp_double);
    const double med = v[n / 2];
    for (size_t i = 0; i < n; ++i)
        v[i] = fabs(v[i] - med);
    qsort(v, n, sizeof v[0], cmp_double);
    return v[n / 2];
}

/* The unit a spread ratio (file / robot) points to, or NULL for mm: more
 * than 3x away from 1 and within 2x of another unit's ratio, the nearest
 * (in log scale: cm and inches are 2.54 apart). */
static const char *unit_of_ratio(double ratio, const char **fix)
{
    static const struct {
        double ratio;
        const char *unit, *fix;
    } u[] = {{0.1, "cm", "multiply by 10"},         {1.0 / 25.4, "inches", "multiply by 25.4"},
             {0.001, "metres", "multiply by 1000"}, {10.0, "tenths of a millimetre", "divide by 10"},
             {100.0, "hundredths of a millimetre", "divide by 100"}, {1000.0, "micrometres", "divide by 1000"}};
    if (!(ratio > 0.0) || (ratio > 1.0 / 3.0 && ratio < 3.0))
        return NULL;
    const char *best = NULL;
    double best_d = log(2.0);
    for (size_t k = 0; k < sizeof u / sizeof u[0]; ++k) {
        const double dist = fabs(log(ratio / u[k].ratio));
        if (dist < best_d) {
            best_d = dist;
            best = u[k].unit;
            *fix = u[k].fix;
        }
    }
    return best;
}

int rch_data_check_scale(const rch_data *data, const char *name, const rc_model *m, rch_diag *d)
{
    const size_t n = data->n;
    if (!m || n < RCH_DATA_SCALE_MIN_ROWS)
        return 0;
    double *a = malloc(2 * n * sizeof *a);
    if (!a)
        return 0; /* a check, not a reader: no memory, no check */
    double *b = a + n;
    const double *e = &m->x[RC_N_DH];
    size_t k = 0;
    const unsigned first = data->s[0].outlet; /* the model's e: the lengths of one outlet */
    for (size_t i = 0; i < n; ++i) {
        if (data->s[i].outlet != first)
            continue;
        double p[3];
        rc_fk(p, NULL, m, data->s[i].q_rad);
        a[k] = data->s[i].value;
        b[k++] = sqrt((p[0] - e[0]) * (p[0] - e[0]) + (p[1] - e[1]) * (p[1] - e[1]) + (p[2] - e[2]) * (p[2] - e[2]));
    }
    int rc = 0;
    const char *fix = NULL, *unit = NULL;
    double sl = 0.0, sr = 0.0;
    if (k >= RCH_DATA_SCALE_MIN_ROWS && data->s[0].value > 0.0) {
        sl = mad(a, k);
        sr = mad(b, k);
        if (sr >= RCH_DATA_SCALE_MIN_SPREAD_MM)
            unit = unit_of_ratio(sl / sr, &fix);
    }
    if (unit) {
        rch_diag_set(d, name, 0, 0,
                     "the cable lengths look like %s: their spread (median absolute deviation) is %.4g against %.4g "
                     "mm of the nominal flange-to-encoder distance at the same joints; rcal reads millimetres (%s)",
                     unit, sl, sr, fix);
        rc = -1;
    }
    if (rc == 0 && data->xyz) {
        double c[2][3] = {{0}};
        for (size_t i = 0; i < n; ++i) {
            double p[3];
            rc_fk(p, NULL, m, data->s[i].q_rad);
            for (int j = 0; j < 3; ++j) {
                c[0][j] += data->xyz[i][j] / (double)n;
                c[1][j] += p[j] / (double)n;
            }
        }
        for (size_t i = 0; i < n; ++i) {
            double p[3], f2 = 0.0, r2 = 0.0;
            rc_fk(p, NULL, m, data->s[i].q_rad);
            for (int j = 0; j < 3; ++j) {
                f2 += (data->xyz[i][j] - c[0][j]) * (data->xyz[i][j] - c[0][j]);
                r2 += (p[j] - c[1][j]) * (p[j] - c[1][j]);
            }
            a[i] = sqrt(f2);
            b[i] = sqrt(r2);
        }
        qsort(a, n, sizeof a[0], cmp_double);
        qsort(b, n, sizeof b[0], cmp_double);
        sl = a[n / 2];
        sr = b[n / 2];
        if (sr >= RCH_DATA_SCALE_MIN_SPREAD_MM && (unit = unit_of_ratio(sl / sr, &fix)) != NULL) {
            rch_diag_set(d, name, 0, 0,
                         "the x, y, z columns look like %s: their median distance from their centre is %.4g against "
                         "%.4g mm of the nominal flange at the same joints; rcal reads millimetres (%s)",
                         unit, sl, sr, fix);
            rc = -1;
        }
    }
    free(a);
    return rc;
}

int rch_data_load_limited(rch_data *out, const char *path, unsigned flags, const rc_model *limits, rch_diag *d)
{
    char *buf = NULL;
    size_t len = 0;
    memset(out, 0, sizeof *out);
    if (rch_read_file(&buf, &len, path, RCH_DATA_MAX_BYTES, d) != 0)
        return -1;
    int rc = parse(out, buf, len, path, flags, limits, NULL, NULL, d);
    free(buf);
    if (rc == 0 && limits && !(flags & (RCH_DATA_NO_LEN | RCH_DATA_POSITIONS)) &&
        rch_data_check_scale(out, path, limits, d) != 0) {
        rch_data_free(out);
        rc = -1;
    }
    return rc;
}

int rch_data_load(rch_data *out, const char *path, unsigned flags, rch_diag *d)
{
    return rch_data_load_limited(out, path, flags, NULL, d);
}

void rch_data_free(rch_data *data)
{
    free(data->s);
    free(data->xyz);
    free(data->line);
    free(data->pose);
    free(data->sigma_mm);
    memset(data, 0, sizeof *data);
}

rc_sample *rch_data_pick(const rc_sample *s, const size_t *idx, size_t k)
{
    rc_sample *o = malloc((k ? k : 1) * sizeof *o);
    if (!o)
        return NULL;
    for (size_t i = 0; i < k; ++i)
        o[i] = s[idx[i]];
    return o;
}

int rch_data_write(FILE *f, const rc_sample *s, size_t n, const rc_model *nominal)
{
    if (fprintf(f, "%sq1,q2,q3,q4,q5,q6,L\n", nominal ? "x,y,z," : "") < 0)
        return -1;
    for (size_t i = 0; i < n; ++i) {
        if (nominal) {
            double p[3];
            rc_fk(p, NULL, nominal, s[i].q_rad);
            fprintf(f, "%.4f,%.4f,%.4f,", p[0], p[1], p[2]);
        }
        for (int j = 0; j < RC_NJ; ++j)
            fprintf(f, "%.4f,", s[i].q_rad[j] * (180.0 / M_PI));
        if (fprintf(f, "%.4f\n", s[i].value) < 0)
            return -1;
    }
    return fflush(f) == 0 ? 0 : -1;
}

static int write_plan(FILE *f, const rc_sample *s, size_t n, int with_outlet, int with_target)
{
    if (fprintf(f, "pose,q1,q2,q3,q4,q5,q6%s%s\n", with_outlet ? ",outlet" : "", with_target ? ",target" : "") < 0)
        return -1;
    for (size_t t = 0; t < n; ++t) {
        fprintf(f, "%zu", t);
        for (int j = 0; j < RC_NJ; ++j)
            fprintf(f, ",%.4f", s[t].q_rad[j] * 180.0 / M_PI);
        if (with_outlet)
            fprintf(f, ",%u", (unsigned)s[t].outlet);
        if (with_target)
            fprintf(f, ",%u", (unsigned)s[t].target);
        if (fprintf(f, "\n") < 0)
            return -1;
    }
    return fflush(f) == 0 && !ferror(f) ? 0 : -1;
}

int rch_data_write_plan(FILE *f, const rc_sample *s, size_t n)
{
    return write_plan(f, s, n, 0, 0);
}

int rch_data_write_plan_outlets(FILE *f, const rc_sample *s, size_t n)
{
    return write_plan(f, s, n, 1, 0);
}

int rch_data_write_plan_cols(FILE *f, const rc_sample *s, size_t n, int with_outlet, int with_target)
{
    return write_plan(f, s, n, with_outlet, with_target);
}

void rch_split(size_t *idx, size_t n, unsigned long long seed)
{
    rc_rng g;
    rc_rng_seed(&g, seed);
    for (size_t i = 0; i < n; ++i)
        idx[i] = i;
    for (size_t i = n; i > 1; --i) { /* Fisher-Yates */
        size_t j = (size_t)rc_rng_below(&g, (uint32_t)i);
        size_t t = idx[i - 1];
        idx[i - 1] = idx[j];
        idx[j] = t;
    }
}

int rch_data_check_units(const rch_data *data, const char *name, rch_diag *d)
{
    double qmax = 0.0, lmax = 0.0;
    size_t n_len = 0; /* lengths among the rows (another sensor's file has none: RCH_DATA_SENSOR) */
    if (data->n < 5)
        return 0;
    for (size_t i = 0; i < data->n; ++i) {
        for (unsigned j = 0; j < RC_NJ; ++j)
            qmax = fmax(qmax, fabs(data->s[i].q_rad[j]));
        if (data->s[i].sensor == RC_SENSOR_LENGTH) {
            lmax = fmax(lmax, data->s[i].value);
            ++n_len;
        }
    }
    /* the loader converted degrees to radians: a file written in radians
     * leaves every joint within 7 "degrees" (400 deg is 6.98 rad) */
    if (qmax > 0.0 && qmax < 7.0 * 3.14159265358979323846 / 180.0) {
        rch_diag_set(d, name, 0, 0,
                     "every joint angle is within +-7: the q columns look like radians, rcal reads degrees "
                     "(multiply by 180/pi)");
        return -1;
    }
    if (n_len > 0 && lmax < 20.0) {
        rch_diag_set(d, name, 0, 0,
                     "every cable length is below 20: the L column looks like metres, rcal reads millimetres "
                     "(multiply by 1000)");
        return -1;
    }
    return 0;
}

int rch_data_q_look_rad(char *why, size_t why_len, const double max_abs_deg[RC_NJ], size_t n)
{
    double mx = 0.0;
    unsigned moving = 0;
    for (unsigned j = 0; j < RC_NJ; ++j) {
        if (!(max_abs_deg[j] <= RCH_DATA_RAD_BOUND))
            return 0; /* a value beyond pi (or not a number): degrees */
        mx = fmax(mx, max_abs_deg[j]);
        moving += max_abs_deg[j] >= RCH_DATA_RAD_MOVE;
    }
    if (n == 0 || moving < RCH_DATA_RAD_JOINTS)
        return 0;
    snprintf(why, why_len,
             "the joint targets look like radians: every joint of the %zu target%s lies within +-%.4f (the largest "
             "|q| is %.4g) and %u joints move by %g or more; rcal reads degrees (multiply by 180/pi)",
             n, n == 1 ? "" : "s", RCH_DATA_RAD_BOUND, mx, moving, RCH_DATA_RAD_MOVE);
    return 1;
}

int rch_data_outlets(uint8_t label[RC_MAX_OUTLETS], rc_sample *s, size_t n, rch_diag *d)
{
    unsigned k = 0;
    int of[256];
    for (unsigned i = 0; i < 256; ++i)
        of[i] = -1;
    for (size_t i = 0; i < n; ++i) {
        const unsigned v = s[i].outlet;
        if (of[v] < 0) {
            if (k >= RC_MAX_OUTLETS) {
                rch_diag_set(d, "", 0, 0, "more than %d outlets in the data (column 'outlet')", RC_MAX_OUTLETS);
                return -1;
            }
            label[k] = (uint8_t)v;
            of[v] = (int)k++;
        }
        s[i].outlet = (uint8_t)of[v];
    }
    return (int)k;
}

int rch_data_outlets_as(const uint8_t *label, unsigned n_labels, rc_sample *s, size_t n, const unsigned *lines,
                        const char *name, rch_diag *d)
{
    for (size_t i = 0; i < n; ++i) {
        if (s[i].sensor != RC_SENSOR_LENGTH)
            continue;
        unsigned k = 0;
        while (k < n_labels && label[k] != s[i].outlet)
            ++k;
        if (k == n_labels) {
            char list[4 * RC_MAX_OUTLETS + 1] = "";
            for (unsigned j = 0, pos = 0; j < n_labels && pos < sizeof list; ++j)
                pos += (unsigned)snprintf(list + pos, sizeof list - pos, "%s%u", j ? "," : "", label[j]);
            rch_diag_set(d, name, lines ? lines[i] : 0, 0,
                         "outlet %u is not an outlet of the model (its outlets, as the calibration's data labelled "
                         "them: %s)",
                         s[i].outlet, list);
            return -1;
        }
        s[i].outlet = (uint8_t)k;
    }
    return 0;
}
