/* SPDX-License-Identifier: MIT */
/* rch_comp_int.h - what the compensation's files share: the state of one
 * program going through (the job's stream and the streams made for other
 * TCPs), the frames a robtarget is read in, and the steps each file does:
 * one target through the stream and its gate (rch_comp.c), a CSV line or
 * header (rch_comp_csv.c), a RAPID module (rch_comp_rapid.c) with its
 * robtargets' frames (rch_comp_frames.c); the run and the lines
 * (rch_comp_run.c) call them; the point and determined models are
 * rch_comp_model.c. Internal to the compensation (prefix rch_cpi_), not part
 * of the host library's API (rch_comp.h is).
 * Depends on: rch_comp.h, rch_rapid.h. Memory: the streams for other TCPs
 * on the heap (freed by rch_comp_lines_gated). Errors: -1 with d (or why)
 * set. */
#ifndef RCH_COMP_INT_H
#define RCH_COMP_INT_H

#include <stddef.h>
#include <stdio.h>

#include "rch_comp.h"
#include "rch_rapid.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif
#define DEG (M_PI / 180.0)
#define RCH_CPI_MAX_FIELDS 64

/* a stream compensating another TCP than the job's (a robtarget's tool) */
typedef struct {
    double tcp[3]; /* mm, flange frame */
    rc_model det, nom, fit;
    rc_comp_stream s;
} rch_cpi_tcp_stream;
#define RCH_CPI_MAX_TCPS 16

typedef struct {
    rc_comp_stream *stream;
    const rc_model *cal, *fit; /* the stream's calibrated model, the full fit (may be NULL) at its point */
    rc_comp_stream *stream0;   /* the job's: its TCP */
    const rc_model *cal0, *fit0;
    rch_cpi_tcp_stream *tcps[RCH_CPI_MAX_TCPS];
    size_t ntcps;
    const rch_comp_gate *gate;
    rch_comp_result *res;
    FILE *out, *warn;
    const char *in_name;
    int format; /* rch_comp_format: 0 auto, 1 csv, 2 rapid, 3 urscript, 4 krl, 5 fanuc */
    const char *eol; /* the line end of the line being read ("\n", "\r\n" or "\r"): a CSV line keeps it */
    double max_abs_deg[RC_NJ]; /* the largest |q| of each joint of the targets read (degrees as read) */
    unsigned long n_targets;   /* joint targets read (the radians check, rch_data_q_look_rad) */
    FILE *held;                /* the CSV output held back while the targets still look like radians (the
                                  real output in held_out) */
    FILE *held_out;
    char *held_buf;
    size_t held_len;
    int have_header;
    int qcol[RC_NJ]; /* header column of each joint */
    unsigned nfields_header;
} rch_cpi_ctx;

/* A rigid pose: trans (mm), rotation (3 x 3, row-major). */
typedef struct {
    double p[3], R[9];
} rch_cpi_pose;

/* How robtarget t is read: the pose of its TCP (F, in tool0's frame) in its
 * work object (W, in the base frame). */
typedef struct {
    rch_cpi_pose W, F;
    int simple;       /* W is the base and F has tool0's orientation: the TCP path of rch_ik */
    double tcp[3];    /* F's origin in the flange frame (mm): the point compensated */
    int has_tcp;      /* not the flange */
} rch_cpi_frames;

/* rch_comp.c: one target */
/* Compensate one target (degrees in, degrees out), gated by the posterior's
 * u95 at the target. 0 ok, 1 not converged or left uncompensated (output
 * still written), -1 range error (d set). cols: (6) columns of the fields
 * for diagnostics. */
int rch_cpi_compensate(rch_cpi_ctx *c, double out_deg[RC_NJ], const double in_deg[RC_NJ], unsigned line,
                       const unsigned cols[RC_NJ], rch_diag *d);
/* One target of a program read whole, on the stream rch_cpi_use_tcp chose:
 * rch_cpi_compensate, then the job's own stream set back. 0 or 1 as
 * rch_cpi_compensate, 2 left uncompensated for its uncertainty (copied as it
 * was), -1 with why set. */
int rch_cpi_compensate_at(rch_cpi_ctx *c, double out_deg[RC_NJ], const double in_deg[RC_NJ], unsigned line,
                          const unsigned cols[RC_NJ], char *why, size_t why_len);

/* rch_comp_csv.c: CSV lines */
/* Split a line at commas. start[k]/len[k]: field k (trimmed); returns the
 * number of fields, or -1 when more than RCH_CPI_MAX_FIELDS. */
int rch_cpi_split_csv(const char *line, size_t n, size_t start[RCH_CPI_MAX_FIELDS], size_t len[RCH_CPI_MAX_FIELDS]);
/* A number occupying exactly text[0..len) (rch_parse_double). 0 or -1. */
int rch_cpi_parse_num(double *v, const char *text, size_t len);
/* The CSV output held back (c->held) from the start of a CSV input until
 * a joint value beyond pi shows the targets are degrees: what was held is
 * written to the real output (release), or dropped when the input ends
 * looking like radians (drop). rch_comp_csv.c. hold: 0 or -1 (d set). */
int rch_cpi_csv_hold(rch_cpi_ctx *c, rch_diag *d);
void rch_cpi_csv_release(rch_cpi_ctx *c);
void rch_cpi_csv_drop(rch_cpi_ctx *c);
/* One CSV line (not blank, not a comment). 0 ok, 1 not converged, -1 error. */
int rch_cpi_csv_line(rch_cpi_ctx *c, const char *line, size_t n, unsigned lineno, rch_diag *d);
/* A header line: q1..q6 (or j1..j6) found, the line copied. 0 or -1. */
int rch_cpi_csv_header(rch_cpi_ctx *c, const char *line, size_t n, unsigned lineno, rch_diag *d);

/* Programs read whole (rch_comp_whole.c). One replacement of the text:
 * text[off..off+len) -> rep; the edits of one program. */
typedef struct rch_cpi_edit {
    size_t off, len;
    char rep[40];
} rch_cpi_edit;
typedef struct rch_cpi_edits {
    rch_cpi_edit *ed; /* (n) malloc'd */
    size_t n, cap;
} rch_cpi_edits;
/* What a format does with the whole text (line0: the line before its first). */
typedef int (*rch_cpi_text_fn)(rch_cpi_ctx *c, const char *text, size_t len, unsigned line0, rch_diag *d);
/* The line already read (got bytes) and the rest of in, at most max_bytes
 * (what: "a RAPID module", ...), handed to fn. fn's return, or -1 (d set). */
int rch_cpi_whole(rch_cpi_ctx *c, const char *line, size_t got, FILE *in, unsigned lineno, size_t max_bytes,
                  const char *what, rch_cpi_text_fn fn, rch_diag *d);
/* One more edit: v printed with fmt. 0, or -1 (out of memory). */
int rch_cpi_edit_add(rch_cpi_edits *e, size_t off, size_t len, const char *fmt, double v);
void rch_cpi_edits_free(rch_cpi_edits *e);
/* text to c->out with the edits applied (sorted here by offset); every other byte as it was. */
void rch_cpi_edits_write(rch_cpi_ctx *c, const char *text, size_t len, rch_cpi_edits *e);
/* n_bad targets (noun: "target", "position") refused, nothing written: said
 * once in d (with c->warn each was named above; else d holds the first). */
void rch_cpi_refused(rch_cpi_ctx *c, rch_diag *d, unsigned long n_bad, const char *noun);

/* rch_comp_rapid.c: a RAPID module */
/* The rest of a RAPID input: the line already read (raw, got bytes) and
 * everything after it, at most RCH_RAPID_MAX_BYTES, corrected all or
 * nothing. 0, 1 (some flagged), -1 (d set). */
int rch_cpi_rapid(rch_cpi_ctx *c, const char *line, size_t got, FILE *in, unsigned lineno, rch_diag *d);

/* rch_comp_fanuc.c: a Fanuc LS program, read whole as a RAPID module is. */
int rch_cpi_fanuc(rch_cpi_ctx *c, const char *line, size_t got, FILE *in, unsigned lineno, rch_diag *d);

/* Compensate at tcp (3, flange frame; has_tcp 0: the flange): the job's
 * stream when it is the job's point, else one made for it (kept for the
 * program). rch_comp_rapid.c. 0, or -1 with why set. */
int rch_cpi_use_tcp(rch_cpi_ctx *c, const double tcp[3], int has_tcp, char *why, size_t why_len);

/* rch_comp_krl.c: a KUKA KRL file (.src or .dat), read whole as a RAPID
 * module is (the line already read and the rest of in), corrected all or
 * nothing. 0, 1 (some flagged), -1 (d set). */
int rch_cpi_krl(rch_cpi_ctx *c, const char *line, size_t got, FILE *in, unsigned lineno, rch_diag *d);

/* rch_comp_frames.c: a robtarget's frames */
/* The tool and work object the instruction that uses robtarget t names, as
 * the module declares them (or --tool for a tool it does not): 0, or -1
 * with why set. tool: --tool (3) or NULL. base: the module's first line - 1. */
int rch_cpi_robtarget_frames(rch_cpi_frames *fr, const rch_rapid_target *t, const double *tool, unsigned base,
                             char *why, size_t why_len);
/* The flange (tool0) pose of robtarget t read with fr: pos, quat (4). */
void rch_cpi_tool0_pose(double pos[3], double quat[4], const rch_cpi_frames *fr, const rch_rapid_target *t);
/* The robtarget read with fr whose flange (tool0) pose is pos, quat (4),
 * in place: T = W^-1 X F. */
void rch_cpi_target_pose(double pos[3], double quat[4], const rch_cpi_frames *fr);

#endif
