/* SPDX-License-Identifier: MIT */
/* simdisplay.c - a simulated cable-encoder display on a pseudo-terminal.
 *
 * Opens a pty, puts its slave side in raw mode, prints the slave's path as
 * the FIRST LINE of stdout (and points --link at it), then speaks one display
 * protocol like a real device until killed, --exit-after-frames or
 * --max-seconds:
 *   ascii       streams "+0509.190\r\n" lines at --rate-hz (default 20)
 *   ascii-poll  answers each poll command (default "R\r") with one line
 *   stx         answers each poll command with STX payload ETX BCC
 *   modbus      answers fn 0x03 requests for --mb-reg (2 registers); other
 *               registers get exception 2 (illegal data address)
 *
 * Value source (mm):
 *   --value MM                constant
 *   --script FILE             one value per line, the next one for each frame
 *                             (the last one is held)
 *   --truth MODEL.json --poses POSES.csv [--follow FILE]
 *                             the true cable length of a simulated robot
 *                             (rc_meas of the truth model) at the pose the
 *                             acquisition is at. How the display learns the
 *                             pose: `rcal acquire --announce FILE` writes the
 *                             index of the pose it asks the robot to visit to
 *                             FILE (atomically, "INDEX q1 .. q6"), standing for
 *                             the robot program; the display re-reads FILE
 *                             before each frame. After a change the shown
 *                             length moves from the old to the new value over
 *                             --settle-ms with a decaying 0.5 mm vibration, as
 *                             the arm travels and settles.
 *   --outlet X,Y,Z (repeatable)  the true places of the encoder's outlets
 *                             0, 1, ... (mm, base frame) for a plan with an
 *                             outlet column (rcal poses --outlet ...): each
 *                             pose's length is from the place of its row's
 *                             outlet (rcal acquire --outlet N runs the rows
 *                             of one place at a time). Without it, the truth
 *                             model's own (encoder_mm for outlet 0, its
 *                             outlet effects for the others); a plan row of
 *                             an outlet neither gives is refused at start.
 *                             One --outlet on a plan without an outlet
 *                             column puts the display at that place (the
 *                             run of rcal acquire --outlet N --encoder X,Y,Z
 *                             on the same plan from a second place).
 *   --cable-point X,Y,Z (repeatable)  the true points of a tool plate the
 *                             cable is hooked on (mm, flange frame; point
 *                             0, 1, ... in order) for a plan with a target
 *                             column (rcal poses --cable-point): each row's
 *                             length is to the point of its target (rcal
 *                             acquire --target P runs one point's rows at
 *                             a time). A plan with a target column needs
 *                             them (or a truth model with a plate); one on a
 *                             plan without the column hooks the cable there.
 * Realism and faults:
 *   --rate-hz R         measuring rate: a new value every 1/R s (streamed, or
 *                       shown to polls: polls in between get the same value)
 *   --noise-mm S        Gaussian noise on each new value (default 0)
 *   --decimals D        digits after the point (ascii/stx, default 3)
 *   --style zero|unit   "+0509.190" or "+ 509.190, MM" (ascii, default zero)
 *   --unit mm|cm|m|in   unit shown in the unit style (default mm)
 *   --baud B            pace output at B baud, 10 bits per byte (0: no pacing)
 *   --drop P, --corrupt P    per-byte probability of dropping / replacing it
 *   --garbage P         per-frame probability of 1..12 random bytes before it
 *   --silence-every N --silence-ms T   after every N frames, say nothing for T ms
 *   --disconnect-after N  after N frames send half a frame and close the pty;
 *                       with --reconnect-ms R open a new pty R ms later (its
 *                       path printed as a new stdout line, --link re-pointed),
 *                       else exit
 *   --disconnect-at-pose P  the same when the robot reaches pose P (1 or
 *                       more): a hang-up tied to the run, not to the clock
 *   --freeze-after N    after N frames the shown value never changes again
 *                       (HOLD pressed, firmware hung): `rcal acquire` must
 *                       refuse it (follow check)
 *   --foreign-offset-mm X  the device found after a reconnect is another
 *                       one (or the cable slipped while unplugged): it shows
 *                       the true length + X mm
 *   --filter-tau-ms T   the display filters what it shows (first order, time
 *                       constant T): it creeps towards a new length
 *   --jump-at-pose P --jump-mm J  when the robot reaches pose P (1 or more)
 *                       the display jumps by J mm and stays off (a slipped
 *                       cable, a counter that lost counts)
 *   --seed S            random faults and noise are reproducible
 *
 * On SIGTERM, SIGINT or SIGHUP it stops and removes --link (when the link
 * still points at its pty), so `kill PID` leaves nothing behind.
 */
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <math.h>
#include <poll.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <termios.h>
#include <time.h>
#include <unistd.h>

#include "rc_rand.h"
#include "rcd_proto.h"
#include "rch_data.h"
#include "rch_opt.h"
#include "rch_robot.h"
#include "rch_stdio.h"

/* set by SIGTERM, SIGINT, SIGHUP: the serving loop ends */
static volatile sig_atomic_t stop_requested;

static void on_stop(int sig)
{
    (void)sig;
    stop_requested = 1;
}

/* longest delay an option may ask for: one day */
#define SIM_MAX_MS 86400000UL

typedef enum { SRC_CONST, SRC_SCRIPT, SRC_ROBOT } src_kind;

typedef struct sim {
    rcd_proto_config pc;
    unsigned decimals;
    rcd_ascii_style style;
    rcd_unit unit;
    double rate_hz, noise_mm, p_drop, p_corrupt, p_garbage;
    unsigned long baud, silence_every, silence_ms, disconnect_after, exit_after, settle_ms;
    long reconnect_ms;
    double max_seconds;
    const char *link, *follow;
    src_kind src;
    double const_mm;
    double *script;
    size_t n_script, script_pos;
    double *pose_len; /* (n_poses) true lengths */
    size_t n_poses;
    long cur_pose;
    double from_mm;
    long long change_ms;
    int master, keeper;
    char path[128];
    rc_rng rng;
    unsigned long frames;
    double line_free_s;
    long long silent_until_ms;
    unsigned long last_silence_frame;
    int disconnected;
    double shown_mm, next_refresh_s;
    int have_shown;
    unsigned long freeze_after; /* 0: never */
    double foreign_offset_mm;   /* added after a reconnect */
    double filter_tau_ms;       /* first-order filter of the shown value (0: none) */
    double filt_mm, filt_t_s;   /* its state */
    int have_filt;
    unsigned long disconnect_at_pose; /* hang up (as --disconnect-after) when the robot reaches this pose (0: never) */
    unsigned long jump_at_pose; /* the display jumps by jump_mm when the robot reaches this pose (0: never) */
    double jump_mm;
    int jumped;
    int foreign;                /* the reconnected device is another one */
} sim;

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

static long long now_ms(void)
{
    return (long long)(now_s() * 1000.0);
}

static void sleep_s(double s)
{
    struct timespec ts;
    if (s <= 0)
        return;
    ts.tv_sec = (time_t)s;
    ts.tv_nsec = (long)((s - (double)ts.tv_sec) * 1e9);
    nanosleep(&ts, NULL);
}

static int open_pty(sim *s)
{
    struct termios tio;
    const char *name;
    s->master = posix_openpt(O_RDWR | O_NOCTTY);
    if (s->master < 0 || grantpt(s->master) != 0 || unlockpt(s->master) != 0 ||
        !(name = ptsname(s->master))) {
        fprintf(stderr, "simdisplay: cannot open a pseudo-terminal: %s\n", strerror(errno));
        return -1;
    }
    snprintf(s->path, sizeof s->path, "%s", name);
    /* Keep a slave fd open: the master then never sees EIO while no client
     * is connected, and the raw mode set here stays until a client changes it. */
    s->keeper = open(s->path, O_RDWR | O_NOCTTY | O_NONBLOCK);
    if (s->keeper < 0 || tcgetattr(s->keeper, &tio) != 0) {
        fprintf(stderr, "simdisplay: cannot open %s: %s\n", s->path, strerror(errno));
        return -1;
    }
    cfmakeraw(&tio);
    tcsetattr(s->keeper, TCSANOW, &tio);
    fcntl(s->master, F_SETFL, fcntl(s->master, F_GETFL) | O_NONBLOCK);
    if (s->link) {
        char tmp[600];
        if ((size_t)snprintf(tmp, sizeof tmp, "%s.tmp%ld", s->link, (long)getpid()) >= sizeof tmp) {
            fprintf(stderr, "simdisplay: --link %s: longer than %zu bytes: refused, not cut\n", s->link,
                    sizeof tmp - 32);
            return -1;
        }
        unlink(tmp);
        if (symlink(s->path, tmp) != 0 || rename(tmp, s->link) != 0) {
            fprintf(stderr, "simdisplay: cannot link %s: %s\n", s->link, strerror(errno));
            return -1;
        }
    }
    printf("%s\n", s->path);
    fflush(stdout);
    return 0;
}

static void close_pty(sim *s)
{
    if (s->master >= 0)
        close(s->master);
    if (s->keeper >= 0)
        close(s->keeper);
    s->master = s->keeper = -1;
}

/* Paced write; drops what the pty cannot take (nobody reading). */
static void send_bytes(sim *s, const uint8_t *b, size_t n)
{
    size_t off = 0;
    if (s->baud) {
        double t = now_s();
        if (s->line_free_s > t)
            sleep_s(s->line_free_s - t);
        t = now_s();
        s->line_free_s = (s->line_free_s > t ? s->line_free_s : t) + (double)n * 10.0 / (double)s->baud;
    }
    while (off < n) {
        ssize_t w = write(s->master, b + off, n - off);
        if (w > 0) {
            off += (size_t)w;
            continue;
        }
        if (w < 0 && errno == EINTR)
            continue;
        break; /* EAGAIN: buffer full, the frame is lost like on a real line */
    }
}

/* The pose index at the start of the --follow file ("INDEX q1 .. q6"), or
 * -1 when there is none yet or it is not a whole non-negative number (a file
 * being replaced, or garbage: the display keeps its pose). */
static long read_follow(const sim *s)
{
    FILE *f;
    char buf[64], *end;
    long idx;
    if (!s->follow || !(f = fopen(s->follow, "r")))
        return -1;
    if (!fgets(buf, sizeof buf, f)) {
        fclose(f);
        return -1;
    }
    fclose(f);
    end = buf + strcspn(buf, " \t\r\n"); /* "INDEX q1 .. q6": the index */
    *end = '\0';
    if (rch_parse_long(buf, &idx) != 0 || idx < 0)
        return -1;
    return idx;
}

static double true_value(sim *s)
{
    switch (s->src) {
    case SRC_CONST:
        return s->const_mm;
    case SRC_SCRIPT: {
        size_t i = s->script_pos < s->n_script ? s->script_pos : s->n_script - 1;
        s->script_pos++;
        return s->script[i];
    }
    case SRC_ROBOT:
    default: {
        long long t = now_ms();
        double target, frac;
        target = s->pose_len[s->cur_pose];
        if (!s->settle_ms || t - s->change_ms >= (long long)s->settle_ms)
            return target;
        frac = (double)(t - s->change_ms) / (double)s->settle_ms;
        return s->from_mm + (target - s->from_mm) * frac +
               0.5 * (1.0 - frac) * sin(6.283185307179586 * (double)(t - s->change_ms) / 40.0);
    }
    }
}

/* The robot side: notice a new pose index in the --follow file (called on
 * every turn of the main loop, at most 20 ms apart). */
static void follow_pose(sim *s)
{
    long idx;
    long long t;
    double frac, shown;
    if (s->src != SRC_ROBOT)
        return;
    idx = read_follow(s);
    if (idx < 0 || (size_t)idx >= s->n_poses || idx == s->cur_pose)
        return;
    t = now_ms();
    shown = s->pose_len[s->cur_pose]; /* start of the move: from what is shown now */
    if (s->settle_ms && t - s->change_ms < (long long)s->settle_ms) {
        frac = (double)(t - s->change_ms) / (double)s->settle_ms;
        shown = s->from_mm + (shown - s->from_mm) * frac;
    }
    s->from_mm = shown;
    s->cur_pose = idx;
    if (s->jump_at_pose && (unsigned long)idx == s->jump_at_pose)
        s->jumped = 1; /* the counter lost counts on the way: every later value is off */
    if (s->disconnect_at_pose && (unsigned long)idx == s->disconnect_at_pose) {
        s->disconnect_after = s->frames ? s->frames : 1; /* the next frame is cut in half */
        s->disconnect_at_pose = 0;
    }
    s->change_ms = t;
}

/* The value the display shows: refreshed at --rate-hz (its measuring rate);
 * a poll between two refreshes gets the same value again, like a real one. */
static double shown_value(sim *s)
{
    double t = now_s();
    if (s->freeze_after && s->frames >= s->freeze_after && s->have_shown)
        return s->shown_mm; /* frozen: HOLD pressed or firmware hung */
    if (s->pc.protocol != RCD_PROTO_ASCII && s->rate_hz > 0 && s->have_shown && t < s->next_refresh_s)
        return s->shown_mm;
    s->shown_mm = true_value(s) + (s->foreign ? s->foreign_offset_mm : 0.0) + (s->jumped ? s->jump_mm : 0.0);
    if (s->filter_tau_ms > 0) { /* y += (x - y) (1 - exp(-dt / tau)) */
        if (s->have_filt)
            s->filt_mm = s->shown_mm + (s->filt_mm - s->shown_mm) * exp(-(t - s->filt_t_s) * 1000.0 / s->filter_tau_ms);
        else
            s->filt_mm = s->shown_mm;
        s->have_filt = 1;
        s->filt_t_s = t;
        s->shown_mm = s->filt_mm;
    }
    if (s->noise_mm > 0)
        s->shown_mm += s->noise_mm * rc_rng_normal(&s->rng);
    s->have_shown = 1;
    s->next_refresh_s = t + (s->rate_hz > 0 ? 1.0 / s->rate_hz : 0.0);
    return s->shown_mm;
}

/* Build, damage and send one frame (or half of one, then disconnect). */
static void emit(sim *s)
{
    uint8_t f[RCD_MAX_FRAME], out[RCD_MAX_FRAME * 2 + 16];
    size_t n = 0, k = 0;
    rc_status st;
    double v = shown_value(s);
    switch (s->pc.protocol) {
    case RCD_PROTO_ASCII:
    case RCD_PROTO_ASCII_POLL:
        st = rcd_encode_ascii(f, &n, sizeof f, v, s->style, s->unit, s->decimals);
        break;
    case RCD_PROTO_STX:
        st = rcd_encode_stx(f, &n, sizeof f, v, s->decimals);
        break;
    default:
        st = rcd_encode_modbus(f, &n, sizeof f, v, &s->pc);
        break;
    }
    if (st != RC_OK) {
        fprintf(stderr, "simdisplay: cannot encode %.4f mm: %s\n", v, rc_strerror(st));
        return;
    }
    s->frames++;
    if (s->disconnect_after && s->frames == s->disconnect_after + 1) {
        send_bytes(s, f, n / 2);
        sleep_s(0.05);
        close_pty(s);
        s->disconnected = 1;
        return;
    }
    if (s->p_garbage > 0 && rc_rng_u01(&s->rng) < s->p_garbage) {
        unsigned g = 1 + rc_rng_below(&s->rng, 12);
        while (g--)
            out[k++] = (uint8_t)rc_rng_below(&s->rng, 256);
    }
    for (size_t i = 0; i < n; ++i) {
        if (s->p_drop > 0 && rc_rng_u01(&s->rng) < s->p_drop)
            continue;
        if (s->p_corrupt > 0 && rc_rng_u01(&s->rng) < s->p_corrupt)
            out[k++] = (uint8_t)(f[i] ^ (1u + rc_rng_below(&s->rng, 255)));
        else
            out[k++] = f[i];
    }
    send_bytes(s, out, k);
}

static int is_silent(sim *s)
{
    long long t = now_ms();
    if (t < s->silent_until_ms)
        return 1;
    if (s->silence_every && s->frames && s->frames % s->silence_every == 0 &&
        s->last_silence_frame != s->frames) {
        s->last_silence_frame = s->frames;
        s->silent_until_ms = t + (long long)s->silence_ms;
        return 1;
    }
    return 0;
}

static int load_script(sim *s, const char *path)
{
    FILE *f = fopen(path, "r");
    char line[256];
    size_t cap = 0;
    unsigned lineno = 0;
    if (!f) {
        fprintf(stderr, "simdisplay: %s: %s\n", path, strerror(errno));
        return -1;
    }
    while (fgets(line, sizeof line, f)) {
        char *p = line, *end;
        double v;
        ++lineno;
        while (*p == ' ' || *p == '\t')
            ++p;
        if (*p == '#' || *p == '\n' || *p == '\r' || *p == '\0')
            continue; /* comment or blank line */
        end = p + strlen(p);
        while (end > p && (end[-1] == ' ' || end[-1] == '\t' || end[-1] == '\r' || end[-1] == '\n'))
            *--end = '\0';
        if (rch_parse_double(p, &v) != 0) {
            fprintf(stderr, "simdisplay: %s:%u: not a number (one value in mm per line, # for comments)\n", path,
                    lineno);
            fclose(f);
            return -1;
        }
        if (s->n_script == cap) {
            double *ns;
            cap = cap ? 2 * cap : 64;
            ns = realloc(s->script, cap * sizeof *s->script);
            if (!ns) {
                fprintf(stderr, "simdisplay: out of memory\n");
                fclose(f);
                return -1;
            }
            s->script = ns;
        }
        s->script[s->n_script++] = v;
    }
    fclose(f);
    if (!s->n_script) {
        fprintf(stderr, "simdisplay: %s holds no value\n", path);
        return -1;
    }
    return 0;
}

/* The true length of plan row smp (its outlet column as read) on the truth
 * model m, from places[outlet] when --outlet gave n_places places (else m's
 * own outlets). 0, or -1 with the message printed (line: the row's). */
static int row_length(double *len_mm, const rc_model *m, rc_sample smp, const double (*places)[3], size_t n_places,
                      const char *poses_path, unsigned line)
{
    rc_model mk;
    const rc_model *use = m;
    if (n_places) {
        if (smp.outlet >= n_places) {
            fprintf(stderr,
                    "simdisplay: %s:%u: a pose from outlet %u, but --outlet gave %zu place%s (outlets 0 .. %zu): give "
                    "one --outlet X,Y,Z per outlet of the plan\n",
                    poses_path, line, (unsigned)smp.outlet, n_places, n_places == 1 ? "" : "s", n_places - 1);
            return -1;
        }
        mk = *m;
        memcpy(&mk.x[RC_P_ENC], places[smp.outlet], 3 * sizeof mk.x[0]);
        smp.outlet = 0;
        use = &mk;
    }
    const rc_status st = rc_meas(len_mm, NULL, use, &smp);
    if (st == RC_OK)
        return 0;
    if (smp.outlet != 0)
        fprintf(stderr,
                "simdisplay: %s:%u: a pose from outlet %u, a place the truth model does not have: give the true "
                "places of the plan's outlets with --outlet X,Y,Z (once per outlet 0, 1, ..., in order)\n",
                poses_path, line, (unsigned)smp.outlet);
    else
        fprintf(stderr, "simdisplay: %s:%u: no length at this pose (the flange at the encoder outlet)\n", poses_path,
                line);
    return -1;
}

/* The plate's true points on the truth model m (--cable-point, n of them):
 * every target of the plan d must be one of them. 0, or -1 with the message
 * printed (the first row beyond them, file:line). */
static int add_points(rc_model *m, const rch_data *d, const double (*points)[3], size_t n, const char *truth_path,
                      const char *poses_path)
{
    unsigned have = 0;
    for (unsigned k = 0; k < m->n_effects; ++k)
        if (m->effects[k].kind == RC_EFF_CABLE_POINTS)
            have = m->effects[k].count / 3u;
    if (n) {
        if (have || rc_model_add_effect(m, RC_EFF_CABLE_POINTS, 0, (unsigned)(3 * n)) != RC_OK) {
            fprintf(stderr, "simdisplay: %s: cannot add %zu cable points%s\n", truth_path, n,
                    have ? " (it has a plate of its own: leave out --cable-point)" : "");
            return -1;
        }
        memcpy(&m->x[m->effects[m->n_effects - 1].first], points, 3 * n * sizeof m->x[0]);
        have = (unsigned)n;
    }
    for (size_t i = 0; i < d->n && d->has_target; ++i)
        if (d->s[i].target >= have) {
            fprintf(stderr,
                    "simdisplay: %s:%u: a pose with the cable on point %u of a tool plate, but %s%u point%s: give the "
                    "plate's true points with --cable-point X,Y,Z (flange frame, mm; once per point 0, 1, ..., in "
                    "order)\n", poses_path, d->line ? d->line[i] : (unsigned)i + 2, (unsigned)d->s[i].target,
                    n ? "--cable-point gave " : "the truth model has ", have, have == 1 ? "" : "s");
            return -1;
        }
    return 0;
}

static int load_robot(sim *s, const char *truth_path, const char *poses_path, const double (*places)[3],
                      size_t n_places, const double (*points)[3], size_t n_points)
{
    rch_robot *r = calloc(1, sizeof *r);
    rch_data d;
    rch_diag dg;
    char buf[900];
    if (!r)
        return -1;
    if (rch_robot_load(r, truth_path, &dg) != 0) {
        fprintf(stderr, "simdisplay: %s\n", rch_diag_str(&dg, buf, sizeof buf));
        free(r);
        return -1;
    }
    if (!r->has_encoder)
        fprintf(stderr, "simdisplay: warning: %s has no encoder_mm; using its default\n", truth_path);
    if (rch_data_load(&d, poses_path, RCH_DATA_NO_LEN, &dg) != 0) {
        fprintf(stderr, "simdisplay: %s\n", rch_diag_str(&dg, buf, sizeof buf));
        free(r);
        return -1;
    }
    if (add_points(&r->model, &d, points, n_points, truth_path, poses_path) != 0) {
        rch_data_free(&d);
        free(r);
        return -1;
    }
    s->n_poses = d.n;
    s->pose_len = calloc(d.n ? d.n : 1, sizeof *s->pose_len);
    if (!s->pose_len) {
        fprintf(stderr, "simdisplay: out of memory\n");
        rch_data_free(&d);
        free(r);
        return -1;
    }
    for (size_t i = 0; i < d.n; ++i) {
        rc_sample smp = d.s[i];
        double l;
        smp.t = d.n > 1 ? (double)i / (double)(d.n - 1) : 0.0;
        if (row_length(&l, &r->model, smp, places, n_places, poses_path, d.line ? d.line[i] : (unsigned)i + 2) != 0) {
            rch_data_free(&d);
            free(r);
            return -1;
        }
        s->pose_len[i] = l;
    }
    rch_data_free(&d);
    free(r);
    return s->n_poses ? 0 : -1;
}

/* Options of the simulated display, parsed with the shared table-driven
 * parser (rch_opt: strict numbers, --opt=value, -h, generated usage). */
typedef struct sim_args {
    const char *protocol, *script, *truth, *poses, *style, *unit, *mb_format, *mb_order, *poll_cmd;
    rch_opt_strs outlets;                 /* --outlet X,Y,Z, as given */
    double places[RCH_OPT_MAX_STRS][3];  /* (n_places x 3) mm, parsed */
    size_t n_places;
    rch_opt_strs cable_points;            /* --cable-point X,Y,Z, as given */
    double points[RC_MAX_TARGETS][3];    /* (n_points x 3) mm, flange frame, parsed */
    size_t n_points;
    unsigned long decimals, mb_addr, mb_reg, mb_decimals, reply_delay_ms, seed;
    long reconnect_ms;
} sim_args;

/* The values of a repeatable X,Y,Z option (mm, each within lim) into out
 * (at most max). 0, or -1 with the message printed. */
static int parse_triples(double (*out)[3], const rch_opt_strs *v, size_t max, const char *opt, double lim)
{
    if (v->n > max) {
        fprintf(stderr, "simdisplay: %zu %s: at most %zu\n", v->n, opt, max);
        return -1;
    }
    for (size_t i = 0; i < v->n; ++i) {
        double *p = out[i];
        if (rch_parse_triple(v->v[i], p) != 0 || fabs(p[0]) > lim || fabs(p[1]) > lim || fabs(p[2]) > lim) {
            fprintf(stderr, "simdisplay: %s '%s': expected X,Y,Z in mm (three finite numbers within %g)\n", opt,
                    v->v[i], lim);
            return -1;
        }
    }
    return 0;
}

/* 0 run, 1 help printed, 2 usage error. */
static int parse_options(sim *s, sim_args *g, int argc, char **argv)
{
    unsigned long long seen = 0;
    const rch_opt opts[] = {
        {"--protocol", RCH_OPT_CHOICE, &g->protocol, 0, 0, NULL, "protocol spoken", 0, "ascii|ascii-poll|stx|modbus"},
        {"--value", RCH_OPT_DOUBLE, &s->const_mm, -1e9, 1e9, "MM", "constant value", 0, NULL},
        {"--script", RCH_OPT_STR, &g->script, 0, 0, "FILE", "one value per line, the next per frame", 0, NULL},
        {"--truth", RCH_OPT_STR, &g->truth, 0, 0, "MODEL.json", "true robot (with --poses)", 0, NULL},
        {"--poses", RCH_OPT_STR, &g->poses, 0, 0, "POSES.csv", "the plan the acquisition follows", 0, NULL},
        {"--follow", RCH_OPT_STR, &s->follow, 0, 0, "FILE", "the pose announced by rcal acquire", 0, NULL},
        {"--outlet", RCH_OPT_STRS, &g->outlets, 0, 0, "X,Y,Z",
         "true place of outlet 0, 1, ... (repeatable; default: the truth model's)", 0, NULL},
        {"--cable-point", RCH_OPT_STRS, &g->cable_points, 0, 0, "X,Y,Z",
         "true point 0, 1, ... of the tool plate the cable is on (flange frame; repeatable; for a plan's target "
         "column)", 0, NULL},
        {"--noise-mm", RCH_OPT_DOUBLE, &s->noise_mm, 0, 1e9, "S", "Gaussian noise per value", 0, NULL},
        {"--decimals", RCH_OPT_UINT, &g->decimals, 0, 6, "D", "digits after the point", 0, NULL},
        {"--style", RCH_OPT_CHOICE, &g->style, 0, 0, NULL, "+0509.190 or + 509.190, MM", 0, "zero|unit"},
        {"--unit", RCH_OPT_CHOICE, &g->unit, 0, 0, NULL, "unit in the unit style", 0, "mm|cm|m|in"},
        {"--rate-hz", RCH_OPT_DOUBLE, &s->rate_hz, 0, 1e6, "R", "measuring rate", 0, NULL},
        {"--baud", RCH_OPT_UINT, &s->baud, 0, 100000000, "B", "pace output (0: no pacing)", 0, NULL},
        {"--poll-cmd", RCH_OPT_STR, &g->poll_cmd, 0, 0, "TEXT", "poll command (\\r, \\n allowed)", 0, NULL},
        {"--mb-addr", RCH_OPT_UINT, &g->mb_addr, 0, 247, "A", "Modbus slave address (0: 1)", 0, NULL},
        {"--mb-reg", RCH_OPT_UINT, &g->mb_reg, 0, 65535, "R", "first holding register", 0, NULL},
        {"--mb-format", RCH_OPT_CHOICE, &g->mb_format, 0, 0, NULL, NULL, 0, "int32|float"},
        {"--mb-order", RCH_OPT_CHOICE, &g->mb_order, 0, 0, NULL, NULL, 0, "abcd|cdab|badc|dcba"},
        {"--mb-decimals", RCH_OPT_UINT, &g->mb_decimals, 0, 9, "D", NULL, 0, NULL},
        {"--drop", RCH_OPT_DOUBLE, &s->p_drop, 0, 1, "P", "per-byte drop probability", 0, NULL},
        {"--corrupt", RCH_OPT_DOUBLE, &s->p_corrupt, 0, 1, "P", "per-byte corruption probability", 0, NULL},
        {"--garbage", RCH_OPT_DOUBLE, &s->p_garbage, 0, 1, "P", "per-frame garbage probability", 0, NULL},
        {"--silence-every", RCH_OPT_UINT, &s->silence_every, 0, 4294967295.0, "N", "frames between silences", 0, NULL},
        {"--silence-ms", RCH_OPT_UINT, &s->silence_ms, 0, SIM_MAX_MS, "T", NULL, 0, NULL},
        {"--disconnect-after", RCH_OPT_UINT, &s->disconnect_after, 0, 4294967294.0, "N", "frames, then hang up", 0, NULL},
        {"--reconnect-ms", RCH_OPT_INT, &g->reconnect_ms, -1, SIM_MAX_MS, "R", "reopen after R ms (-1: exit)", 0, NULL},
        {"--foreign-offset-mm", RCH_OPT_DOUBLE, &s->foreign_offset_mm, -1e5, 1e5, "X", "another device after a reconnect", 0, NULL},
        {"--filter-tau-ms", RCH_OPT_DOUBLE, &s->filter_tau_ms, 0, 1e6, "T", "first-order display filter", 0, NULL},
        {"--disconnect-at-pose", RCH_OPT_UINT, &s->disconnect_at_pose, 0, 4294967294.0, "P",
         "hang up when the robot reaches P", 0, NULL},
        {"--jump-at-pose", RCH_OPT_UINT, &s->jump_at_pose, 0, 4294967294.0, "P", "jump when the robot reaches P", 0, NULL},
        {"--jump-mm", RCH_OPT_DOUBLE, &s->jump_mm, -1e5, 1e5, "J", "the jump (with --jump-at-pose)", 0, NULL},
        {"--freeze-after", RCH_OPT_UINT, &s->freeze_after, 0, 4294967294.0, "N", "frames, then the value freezes", 0, NULL},
        {"--settle-ms", RCH_OPT_UINT, &s->settle_ms, 0, SIM_MAX_MS, "T", "move transient", 0, NULL},
        {"--reply-delay-ms", RCH_OPT_UINT, &g->reply_delay_ms, 0, SIM_MAX_MS, "T", NULL, 0, NULL},
        {"--link", RCH_OPT_STR, &s->link, 0, 0, "PATH", "symlink to the current pty", 0, NULL},
        {"--seed", RCH_OPT_UINT, &g->seed, 0, 4294967295.0, "S", "random faults and noise", 0, NULL},
        {"--exit-after-frames", RCH_OPT_UINT, &s->exit_after, 0, 4294967295.0, "N", NULL, 0, NULL},
        {"--max-seconds", RCH_OPT_DOUBLE, &s->max_seconds, 0, 1e9, "T", NULL, 0, NULL},
    };
    const rch_cmdspec spec = {"simdisplay", "a simulated cable-encoder display on a pseudo-terminal",
                              "Needs --value, --script, or --truth with --poses. Prints the pty path as the first line "
                              "of stdout.\nSee the comment of tools/simdisplay/simdisplay.c.",
                              opts, sizeof opts / sizeof opts[0]};
    rch_opt_status st = rch_opt_parse(&spec, argc, argv, &seen, stdout, stderr);
    if (st != RCH_OPT_OK)
        return st == RCH_OPT_HELP ? 1 : 2;
    rcd_protocol_from_name(&s->pc.protocol, g->protocol);
    rcd_unit_from_name(&s->unit, g->unit);
    rcd_word_order_from_name(&s->pc.mb_order, g->mb_order);
    s->style = strcmp(g->style, "unit") == 0 ? RCD_STYLE_SPACE_UNIT : RCD_STYLE_ZERO_PAD;
    s->pc.mb_format = strcmp(g->mb_format, "float") == 0 ? RCD_MB_FLOAT32 : RCD_MB_INT32;
    s->decimals = (unsigned)g->decimals;
    s->pc.mb_addr = (uint8_t)g->mb_addr;
    s->pc.mb_reg = (uint16_t)g->mb_reg;
    s->pc.mb_decimals = (uint8_t)g->mb_decimals;
    s->reconnect_ms = g->reconnect_ms;
    if (g->poll_cmd) { /* C escapes \r and \n are understood; never cut */
        size_t k = 0;
        for (const char *p = g->poll_cmd; *p; ++p) {
            if (k + 1 >= sizeof s->pc.poll_cmd) {
                fprintf(stderr, "simdisplay: --poll-cmd is longer than %zu bytes: refused, not cut\n",
                        sizeof s->pc.poll_cmd - 1);
                return 2;
            }
            if (p[0] == '\\' && (p[1] == 'r' || p[1] == 'n')) {
                s->pc.poll_cmd[k++] = p[1] == 'r' ? '\r' : '\n';
                ++p;
            } else {
                s->pc.poll_cmd[k++] = *p;
            }
        }
    }
    if (parse_triples(g->places, &g->outlets, RCH_OPT_MAX_STRS, "--outlet", 1e5) != 0)
        return 2;
    g->n_places = g->outlets.n;
    if (g->n_places && !g->truth) {
        fprintf(stderr, "simdisplay: --outlet goes with --truth and --poses\n");
        return 2;
    }
    if (parse_triples(g->points, &g->cable_points, RC_MAX_TARGETS, "--cable-point", 1e4) != 0)
        return 2;
    g->n_points = g->cable_points.n;
    if (g->n_points && !g->truth) {
        fprintf(stderr, "simdisplay: --cable-point goes with --truth and --poses\n");
        return 2;
    }
    if ((g->truth != NULL) != (g->poses != NULL)) {
        fprintf(stderr, "simdisplay: --truth and --poses go together\n");
        return 2;
    }
    if (!g->script && !g->truth && !rch_opt_given(&spec, seen, "--value")) {
        fprintf(stderr, "simdisplay: give --value MM, --script FILE, or --truth MODEL.json --poses POSES.csv\n");
        return 2;
    }
    return 0;
}

/* Modbus: answer every complete request in rq (fn 03 for --mb-reg, else exception 2). */
static void serve_modbus(sim *s, uint8_t *rq, size_t *rq_len, unsigned long reply_delay_ms)
{
    for (;;) {
        uint16_t reg = 0, cnt = 0;
        size_t c = 0;
        rc_status st = rcd_parse_modbus_request(&reg, &cnt, &c, s->pc.mb_addr ? s->pc.mb_addr : 1, rq, *rq_len);
        memmove(rq, rq + c, *rq_len - c);
        *rq_len -= c;
        if (st == RC_ERR_INCOMPLETE)
            break;
        if (st != RC_OK)
            continue;
        sleep_s((double)reply_delay_ms / 1000.0);
        if (reg != s->pc.mb_reg || cnt != 2) {
            uint8_t e[8];
            size_t n;
            rcd_encode_modbus_exception(e, &n, sizeof e, s->pc.mb_addr ? s->pc.mb_addr : 1, 2);
            send_bytes(s, e, n);
        } else {
            emit(s);
        }
        if (s->disconnected)
            break;
    }
}

/* ASCII polled and STX: one frame per poll command found in rq. */
static void serve_polled(sim *s, uint8_t *rq, size_t *rq_len, unsigned long reply_delay_ms)
{
    const char *cmd = s->pc.poll_cmd[0] ? s->pc.poll_cmd : "R\r";
    size_t cl = strlen(cmd);
    for (;;) {
        size_t p = 0;
        while (p + cl <= *rq_len && memcmp(rq + p, cmd, cl) != 0)
            ++p;
        if (p + cl > *rq_len) {
            if (*rq_len >= cl) { /* keep a possible partial command */
                memmove(rq, rq + *rq_len - (cl - 1), cl - 1);
                *rq_len = cl - 1;
            }
            break;
        }
        memmove(rq, rq + p + cl, *rq_len - p - cl);
        *rq_len -= p + cl;
        sleep_s((double)reply_delay_ms / 1000.0);
        emit(s);
        if (s->disconnected)
            break;
    }
}

/* The display's life: frames, requests, silences, disconnects. 0 or 1. */
static int serve(sim *s, unsigned long reply_delay_ms)
{
    uint8_t rq[512];
    size_t rq_len = 0;
    const double t_start = now_s();
    double next_frame = t_start;
    for (;;) {
        struct pollfd pfd;
        int timeout_ms = 20;
        double t = now_s();
        if (stop_requested || t - t_start > s->max_seconds || (s->exit_after && s->frames >= s->exit_after))
            return 0;
        if (s->disconnected) {
            if (s->reconnect_ms < 0)
                return 0;
            sleep_s((double)s->reconnect_ms / 1000.0);
            s->disconnected = 0;
            s->disconnect_after = 0;
            s->foreign = s->foreign_offset_mm != 0.0;
            rq_len = 0;
            if (open_pty(s) != 0)
                return 1;
            continue;
        }
        if (s->pc.protocol == RCD_PROTO_ASCII)
            timeout_ms = t < next_frame ? (int)((next_frame - t) * 1000.0) : 0;
        pfd.fd = s->master;
        pfd.events = POLLIN;
        pfd.revents = 0;
        if (poll(&pfd, 1, timeout_ms) > 0 && (pfd.revents & POLLIN)) {
            ssize_t r = read(s->master, rq + rq_len, sizeof rq - rq_len);
            if (r > 0)
                rq_len += (size_t)r;
        }
        follow_pose(s);
        if (is_silent(s)) {
            rq_len = 0; /* a silent display ignores requests */
            continue;
        }
        if (s->pc.protocol == RCD_PROTO_ASCII) {
            if (now_s() >= next_frame) {
                emit(s);
                next_frame += s->rate_hz > 0 ? 1.0 / s->rate_hz : 0.0;
                if (next_frame < now_s() - 1.0)
                    next_frame = now_s(); /* do not burst after a stall */
            }
        } else if (s->pc.protocol == RCD_PROTO_MODBUS) {
            serve_modbus(s, rq, &rq_len, reply_delay_ms);
        } else {
            serve_polled(s, rq, &rq_len, reply_delay_ms);
        }
        if (rq_len == sizeof rq)
            rq_len = 0;
    }
}

static int run(int argc, char **argv)
{
    sim s;
    static sim_args g = {"ascii", NULL, NULL, NULL, "zero", "mm", "int32", "abcd", NULL, {{0}, 0}, {{0}}, 0,
                         {{0}, 0}, {{0}}, 0, 3, 0, 0, 0, 0, 1, -1};
    int rc;
    memset(&s, 0, sizeof s);
    s.rate_hz = 20;
    s.max_seconds = 600;
    s.master = s.keeper = -1;
    rc = parse_options(&s, &g, argc, argv);
    if (rc != 0)
        return rc == 1 ? 0 : 2;
    rc_rng_seed(&s.rng, g.seed);
    if (g.script) {
        s.src = SRC_SCRIPT;
        rc = load_script(&s, g.script) != 0;
    } else if (g.truth) {
        s.src = SRC_ROBOT;
        rc = load_robot(&s, g.truth, g.poses, (const double(*)[3])g.places, g.n_places,
                        (const double(*)[3])g.points, g.n_points) != 0;
    } else {
        s.src = SRC_CONST;
    }
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_stop;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGTERM, &sa, NULL);
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGHUP, &sa, NULL);
    if (rc == 0)
        rc = open_pty(&s) != 0 ? 1 : serve(&s, g.reply_delay_ms);
    if (s.link && s.path[0]) { /* the link goes with the pty, unless another display took it over */
        char to[sizeof s.path];
        const ssize_t n = readlink(s.link, to, sizeof to - 1);
        if (n > 0 && (size_t)n < sizeof to) {
            to[n] = '\0';
            if (strcmp(to, s.path) == 0)
                unlink(s.link);
        }
    }
    close_pty(&s);
    free(s.script);
    free(s.pose_len);
    return rc;
}

/* Closed standard descriptors opened on /dev/null first; standard output and
 * standard error checked at the end (tools/host/files/rch_stdio.h). */
int main(int argc, char **argv)
{
    rch_stdio_begin("simdisplay");
    return rch_stdio_end(run(argc, argv));
}
