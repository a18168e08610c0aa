/* cmd_acquire.c - rcal acquire: record cable lengths from the encoder display.
 *
 * For each pose of a plan: show it (and announce it to the robot side),
 * wait for the arm to settle, read the display until N consecutive readings
 * agree within a tolerance, and append "pose, q1..q6, L, spread, count, time"
 * to the output, flushed and fsync'ed at once. Re-running the same command
 * resumes at the first pose missing from the output.
 *
 * Never a silent wrong value: ASCII frames pass the display's format lock
 * (rcd_display.h), STX/Modbus frames their checksum, every reading the
 * physical range, and a sample is the mean of N consecutive readings whose
 * max - min <= --stable-mm. Anything else is retried, reported, or stops the
 * run with a message that says how to resume.
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "rcal_cmds.h"
#include "rcal_opts.h"
#include "rcd_display.h"
#include "rch_data.h"

#define ACQ_HEADER "pose,q1,q2,q3,q4,q5,q6,L,spread_mm,n_readings,t_unix_ms"
#define ACQ_MAX_N 64

/* ---- joint-angle source hook ---------------------------------------------
 * Where the recorded q1..q6 come from. Today: the plan itself (the robot
 * program visits the planned poses; the controller repeats them to its
 * display step). To record the angles a controller actually reports (for
 * example a RAPID socket or EGM stream sending "q1 .. q6" lines), implement
 * read() to fill q_deg for the current pose - it may block until the
 * controller says the motion is finished - and select it with --joints.
 * Return 0 on success, -1 with a message on stderr to stop the run. */
typedef struct acq_joint_source {
    const char *name;
    int (*read)(void *ctx, double q_deg[RC_NJ], const double plan_deg[RC_NJ], size_t pose);
    void *ctx;
} acq_joint_source;

static int joints_from_plan(void *ctx, double q_deg[RC_NJ], const double plan_deg[RC_NJ], size_t pose)
{
    (void)ctx;
    (void)pose;
    memcpy(q_deg, plan_deg, sizeof(double) * RC_NJ);
    return 0;
}

static const acq_joint_source joint_sources[] = {
    {"plan", joints_from_plan, NULL},
};

/* ---- options ---------------------------------------------------------- */

typedef struct acq_opts {
    const char *port, *poses, *out, *announce, *backend, *joints;
    rcd_serial_config ser;
    rcd_proto_config proto;
    unsigned long n, settle_ms, read_timeout_ms, retries, pose_timeout_s, reconnect_s, poll_interval_ms;
    double tol_mm, min_mm, max_mm;
    int confirm, quiet;
} acq_opts;

static void usage(FILE *f)
{
    fprintf(f,
            "usage: rcal acquire --port PATH --protocol ascii|ascii-poll|stx|modbus --poses POSES.csv --out DATA.csv\n"
            "                    [--backend serialport|posix] [--baud B] [--data-bits 5-8] [--parity none|odd|even|mark|space]\n"
            "                    [--stop-bits 1|2] [--flow none|xonxoff|rtscts|dtrdsr] [--poll-cmd TEXT]\n"
            "                    [--mb-addr A] [--mb-reg R] [--mb-format int32|float] [--mb-order abcd|cdab|badc|dcba]\n"
            "                    [--mb-decimals D] [--samples-per-pose N] [--stable-mm TOL] [--settle-ms T]\n"
            "                    [--read-timeout-ms T] [--retries R] [--pose-timeout-s S] [--reconnect-s S]\n"
            "                    [--min-mm A] [--max-mm B] [--poll-interval-ms T] [--announce FILE] [--confirm]\n"
            "                    [--joints plan] [--quiet]\n"
            "  For each pose of POSES.csv (q1..q6 in degrees): show it, write 'INDEX q1..q6' to --announce FILE\n"
            "  (for a robot-side program; the simulated display follows it), wait --settle-ms (default 2000) or,\n"
            "  with --confirm, for Enter; then read until --samples-per-pose N (default 5) consecutive readings\n"
            "  lie within --stable-mm TOL (default 0.05) of each other and record their mean as L (mm).\n"
            "  Each sample is appended to DATA.csv and fsync'ed at once; rerunning the same command resumes at\n"
            "  the first missing pose. Columns: " ACQ_HEADER " (t_unix_ms: wall clock).\n"
            "  Backend: serialport (default; real adapters, 9600 8N1 unless told) or posix (ptys of rcal_simdisplay).\n"
            "  Retry policy: a reading waits --read-timeout-ms (2000); after --retries R (5) failures in a row\n"
            "  (timeouts, corrupt frames, device errors) the port is closed and reopened; a disconnect is retried\n"
            "  for --reconnect-s (10) seconds; a pose that does not settle within --pose-timeout-s (60) stops\n"
            "  the run. Polled protocols ask at most every --poll-interval-ms (100): set it to the display's\n"
            "  update period or more, so that N readings are N fresh measurements, not one repeated.\n"
            "  Readings outside [--min-mm 1, --max-mm 20000] are rejected. Exit 0 done, 1 stopped\n"
            "  (rerun to resume), 2 usage.\n");
}

static int parse_enum(const char *v, const char *const *names, unsigned n, unsigned *out)
{
    for (unsigned i = 0; i < n; ++i)
        if (strcmp(v, names[i]) == 0) {
            *out = i;
            return 0;
        }
    return -1;
}

static int parse_opts(acq_opts *o, int argc, char **argv)
{
    static const char *const parities[] = {"none", "odd", "even", "mark", "space"};
    static const char *const flows[] = {"none", "xonxoff", "rtscts", "dtrdsr"};
    const char *protocol = NULL, *parity = NULL, *flow = NULL, *poll_cmd = NULL, *mb_format = NULL,
               *mb_order = NULL;
    unsigned long baud = 0, bits = 0, stop = 0, mb_addr = 1, mb_reg = 0, mb_dec = 0;
    memset(o, 0, sizeof *o);
    o->backend = "serialport";
    o->joints = "plan";
    o->n = 5;
    o->tol_mm = 0.05;
    o->settle_ms = 2000;
    o->read_timeout_ms = 2000;
    o->retries = 5;
    o->pose_timeout_s = 60;
    o->reconnect_s = 10;
    o->poll_interval_ms = 100;
    o->min_mm = 1.0;
    o->max_mm = 20000.0;
    for (int i = 1; i < argc; ++i) {
        if (rcal_opt_str(argc, argv, &i, "--port", &o->port) || rcal_opt_str(argc, argv, &i, "--poses", &o->poses) ||
            rcal_opt_str(argc, argv, &i, "--out", &o->out) || rcal_opt_str(argc, argv, &i, "--protocol", &protocol) ||
            rcal_opt_str(argc, argv, &i, "--backend", &o->backend) ||
            rcal_opt_str(argc, argv, &i, "--announce", &o->announce) ||
            rcal_opt_str(argc, argv, &i, "--joints", &o->joints) || rcal_opt_str(argc, argv, &i, "--parity", &parity) ||
            rcal_opt_str(argc, argv, &i, "--flow", &flow) || rcal_opt_str(argc, argv, &i, "--poll-cmd", &poll_cmd) ||
            rcal_opt_str(argc, argv, &i, "--mb-format", &mb_format) ||
            rcal_opt_str(argc, argv, &i, "--mb-order", &mb_order) || rcal_opt_uint(argc, argv, &i, "--baud", &baud) ||
            rcal_opt_uint(argc, argv, &i, "--data-bits", &bits) || rcal_opt_uint(argc, argv, &i, "--stop-bits", &stop) ||
            rcal_opt_uint(argc, argv, &i, "--mb-addr", &mb_addr) || rcal_opt_uint(argc, argv, &i, "--mb-reg", &mb_reg) ||
            rcal_opt_uint(argc, argv, &i, "--mb-decimals", &mb_dec) ||
            rcal_opt_uint(argc, argv, &i, "--samples-per-pose", &o->n) ||
            rcal_opt_double(argc, argv, &i, "--stable-mm", &o->tol_mm) ||
            rcal_opt_uint(argc, argv, &i, "--settle-ms", &o->settle_ms) ||
            rcal_opt_uint(argc, argv, &i, "--read-timeout-ms", &o->read_timeout_ms) ||
            rcal_opt_uint(argc, argv, &i, "--retries", &o->retries) ||
            rcal_opt_uint(argc, argv, &i, "--pose-timeout-s", &o->pose_timeout_s) ||
            rcal_opt_uint(argc, argv, &i, "--reconnect-s", &o->reconnect_s) ||
            rcal_opt_uint(argc, argv, &i, "--poll-interval-ms", &o->poll_interval_ms) ||
            rcal_opt_double(argc, argv, &i, "--min-mm", &o->min_mm) ||
            rcal_opt_double(argc, argv, &i, "--max-mm", &o->max_mm))
            continue;
        if (strcmp(argv[i], "--confirm") == 0) {
            o->confirm = 1;
            continue;
        }
        if (strcmp(argv[i], "--quiet") == 0) {
            o->quiet = 1;
            continue;
        }
        if (strcmp(argv[i], "--help") == 0 || strcmp(argv[i], "-h") == 0) {
            usage(stdout);
            exit(0);
        }
        return rcal_opt_unknown("acquire", argv[i]);
    }
    if (!o->port)
        return rcal_opt_missing("acquire", "--port");
    if (!protocol)
        return rcal_opt_missing("acquire", "--protocol");
    if (!o->poses)
        return rcal_opt_missing("acquire", "--poses");
    if (!o->out)
        return rcal_opt_missing("acquire", "--out");
    if (rcd_protocol_from_name(&o->proto.protocol, protocol) != RC_OK) {
        fprintf(stderr, "rcal acquire: --protocol must be ascii, ascii-poll, stx or modbus, not '%s'\n", protocol);
        return 2;
    }
    if (strcmp(o->backend, "serialport") != 0 && strcmp(o->backend, "posix") != 0) {
        fprintf(stderr, "rcal acquire: --backend must be serialport or posix\n");
        return 2;
    }
    o->ser.baud = (unsigned)baud;
    o->ser.data_bits = (unsigned)bits;
    o->ser.stop_bits = (unsigned)stop;
    if (parity) {
        unsigned k;
        if (parse_enum(parity, parities, 5, &k) != 0) {
            fprintf(stderr, "rcal acquire: unknown --parity '%s'\n", parity);
            return 2;
        }
        o->ser.parity = (rcd_parity)k;
    }
    if (flow) {
        unsigned k;
        if (parse_enum(flow, flows, 4, &k) != 0) {
            fprintf(stderr, "rcal acquire: unknown --flow '%s'\n", flow);
            return 2;
        }
        o->ser.flow = (rcd_flow)k;
    }
    {
        rcd_serial_config chk;
        if (rcd_serial_config_resolve(&chk, &o->ser) != RC_OK) {
            fprintf(stderr, "rcal acquire: invalid line settings (data bits 5-8, stop bits 1-2)\n");
            return 2;
        }
    }
    if (poll_cmd) {
        size_t k = 0;
        for (const char *p = poll_cmd; *p && k + 1 < sizeof o->proto.poll_cmd; ++p) {
            if (p[0] == '\\' && (p[1] == 'r' || p[1] == 'n')) {
                o->proto.poll_cmd[k++] = p[1] == 'r' ? '\r' : '\n';
                ++p;
            } else {
                o->proto.poll_cmd[k++] = *p;
            }
        }
    }
    if (mb_addr < 1 || mb_addr > 247 || mb_reg > 65535 || mb_dec > 9) {
        fprintf(stderr, "rcal acquire: --mb-addr 1..247, --mb-reg 0..65535, --mb-decimals 0..9\n");
        return 2;
    }
    o->proto.mb_addr = (uint8_t)mb_addr;
    o->proto.mb_reg = (uint16_t)mb_reg;
    o->proto.mb_decimals = (uint8_t)mb_dec;
    if (mb_format && strcmp(mb_format, "float") == 0)
        o->proto.mb_format = RCD_MB_FLOAT32;
    else if (mb_format && strcmp(mb_format, "int32") != 0) {
        fprintf(stderr, "rcal acquire: --mb-format must be int32 or float\n");
        return 2;
    }
    if (mb_order && rcd_word_order_from_name(&o->proto.mb_order, mb_order) != RC_OK) {
        fprintf(stderr, "rcal acquire: --mb-order must be abcd, cdab, badc or dcba\n");
        return 2;
    }
    if (o->n < 1 || o->n > ACQ_MAX_N) {
        fprintf(stderr, "rcal acquire: --samples-per-pose must be 1..%d\n", ACQ_MAX_N);
        return 2;
    }
    if (!(o->tol_mm >= 0) || !(o->min_mm < o->max_mm) || o->read_timeout_ms < 1 || o->retries < 1) {
        fprintf(stderr, "rcal acquire: need --stable-mm >= 0, --min-mm < --max-mm, --read-timeout-ms and --retries >= 1\n");
        return 2;
    }
    return 0;
}

/* ---- helpers ------------------------------------------------------------ */

static long long wall_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_REALTIME, &ts);
    return (long long)ts.tv_sec * 1000 + ts.tv_nsec / 1000000;
}

static long long mono_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (long long)ts.tv_sec * 1000 + ts.tv_nsec / 1000000;
}

static void sleep_ms(unsigned long ms)
{
    struct timespec ts;
    ts.tv_sec = (time_t)(ms / 1000);
    ts.tv_nsec = (long)(ms % 1000) * 1000000L;
    while (nanosleep(&ts, &ts) != 0 && errno == EINTR)
        ;
}

/* Scan an existing output: check its header, drop an unfinished last line
 * (a crash mid-write), mark the poses already recorded and check that their
 * joint angles are the plan's. Returns 0, or -1 with a message. */
/* Saves the bytes [from, end of file) of f to "<path>.dropped" (appended),
 * so that even the fragment of an interrupted write is never destroyed. */
static int save_tail(FILE *f, const char *path, long from)
{
    char dpath[4096], buf[4096];
    size_t n;
    FILE *d;
    snprintf(dpath, sizeof dpath, "%s.dropped", path);
    if (fseek(f, from, SEEK_SET) != 0 || !(d = fopen(dpath, "a"))) {
        fprintf(stderr, "rcal acquire: %s: cannot save the unfinished last line to %s: %s\n", path, dpath,
                strerror(errno));
        return -1;
    }
    while ((n = fread(buf, 1, sizeof buf, f)) > 0)
        if (fwrite(buf, 1, n, d) != n)
            break;
    if (ferror(f) || fclose(d) != 0) {
        fprintf(stderr, "rcal acquire: %s: cannot save the unfinished last line to %s\n", path, dpath);
        return -1;
    }
    fprintf(stderr, "rcal acquire: the dropped fragment is kept in %s\n", dpath);
    return 0;
}

/* The leading columns of a sample line of an acquisition file,
 * "pose,q1,..,q6,L" (further columns are not read): the pose a decimal index,
 * the others finite numbers, read with strtoul/strtod and their end and
 * ERANGE checks (the file comes from outside: an out-of-range number is
 * refused, where sscanf's behaviour would be undefined). 0, or -1 when the
 * line does not start with such a sample. */
static int parse_sample(const char *line, unsigned long *pose, double q[RC_NJ], double *L)
{
    double v[RC_NJ + 1];
    const char *p = line;
    char *end;
    if (*p < '0' || *p > '9')
        return -1;
    errno = 0;
    *pose = strtoul(p, &end, 10);
    if (errno != 0 || *end != ',')
        return -1;
    p = end + 1;
    for (int k = 0; k <= RC_NJ; ++k) {
        errno = 0;
        v[k] = strtod(p, &end);
        if (end == p || errno != 0 || !isfinite(v[k]))
            return -1;
        p = end;
        if (k < RC_NJ) {
            if (*p != ',')
                return -1;
            ++p;
        } else if (*p != ',' && *p != '\n' && *p != '\r' && *p != '\0') {
            return -1;
        }
    }
    memcpy(q, v, RC_NJ * sizeof v[0]);
    *L = v[RC_NJ];
    return 0;
}

/* Reads an existing acquisition file before resuming. Lines are read with
 * getline(), so a NUL byte (returned length != strlen) and lines of any
 * length are seen for what they are. Only the last line of the file may lack
 * its '\n' (an interrupted write): it is copied to "<out>.dropped" and cut
 * off. Any damage before the end is refused with its line and column and the
 * file is left untouched: acquired samples are never deleted. */
static int scan_existing(const char *path, unsigned char *done, size_t n_poses,
                         double (*plan_deg)[RC_NJ], size_t *n_done)
{
    FILE *f = fopen(path, "r+");
    char *line = NULL;
    size_t cap = 0;
    ssize_t got;
    long good_end = 0;
    unsigned lineno = 0;
    int rc = 0, partial = 0;
    *n_done = 0;
    if (!f) {
        if (errno == ENOENT)
            return 0;
        fprintf(stderr, "rcal acquire: %s: %s\n", path, strerror(errno));
        return -1;
    }
    while ((got = getline(&line, &cap, f)) > 0) {
        size_t len = (size_t)got, clen = strlen(line);
        unsigned long pose;
        double q[RC_NJ], L;
        ++lineno;
        if (clen != len) {
            fprintf(stderr, "rcal acquire: %s:%u:%zu: NUL byte: the file is damaged; repair it or choose another "
                            "--out (nothing was changed)\n", path, lineno, clen + 1);
            rc = -1;
            break;
        }
        if (line[len - 1] != '\n') {
            /* getline returns a line without '\n' only at the end of the file */
            fprintf(stderr, "rcal acquire: %s:%u: unfinished last line (interrupted write) dropped\n", path, lineno);
            partial = 1;
            break;
        }
        if (lineno == 1) {
            if (strncmp(line, ACQ_HEADER, strlen(ACQ_HEADER)) != 0) {
                fprintf(stderr, "rcal acquire: %s exists but is not an acquisition file (header '%s' expected); "
                                "choose another --out\n", path, ACQ_HEADER);
                rc = -1;
                break;
            }
        } else if (len > 1) {
            if (parse_sample(line, &pose, q, &L) != 0 || pose >= n_poses) {
                fprintf(stderr, "rcal acquire: %s:%u: not a sample of this plan (%zu poses); choose another --out\n",
                        path, lineno, n_poses);
                rc = -1;
                break;
            }
            for (int j = 0; j < RC_NJ && rc == 0; ++j)
                if (fabs(q[j] - plan_deg[pose][j]) > 1e-3) {
                    fprintf(stderr, "rcal acquire: %s:%u: pose %lu has q%d = %.4f but the plan says %.4f: "
                                    "the file belongs to another plan\n", path, lineno, pose, j + 1, q[j], plan_deg[pose][j]);
                    rc = -1;
                }
            if (rc != 0)
                break;
            if (!done[pose])
                ++*n_done;
            done[pose] = 1;
        }
        good_end = ftell(f);
    }
    free(line);
    if (rc == 0 && ferror(f)) {
        fprintf(stderr, "rcal acquire: %s: read error: %s\n", path, strerror(errno));
        rc = -1;
    }
    if (rc == 0 && partial) {
        if (save_tail(f, path, good_end) != 0) {
            rc = -1;
        } else if (ftruncate(fileno(f), good_end) != 0) {
            fprintf(stderr, "rcal acquire: %s: cannot truncate: %s\n", path, strerror(errno));
            rc = -1;
        }
    }
    fclose(f);
    return rc;
}

static int announce(const char *path, size_t pose, const double q_deg[RC_NJ])
{
    char tmp[4096];
    FILE *f;
    snprintf(tmp, sizeof tmp, "%s.tmp", path);
    f = fopen(tmp, "w");
    if (!f)
        return -1;
    fprintf(f, "%zu", pose);
    for (int j = 0; j < RC_NJ; ++j)
        fprintf(f, " %.4f", q_deg[j]);
    fprintf(f, "\n");
    if (fclose(f) != 0)
        return -1;
    return rename(tmp, path);
}

typedef struct acq_port {
    rcd_port port;
    rcd_posix_ctx px;
    rcd_serialport_ctx sp;
    int open;
} acq_port;

static rc_status port_open(acq_port *p, const acq_opts *o)
{
    if (strcmp(o->backend, "posix") == 0)
        rcd_posix_init(&p->port, &p->px);
    else
        rcd_serialport_init(&p->port, &p->sp);
    rc_status st = rcd_port_open(&p->port, o->port, &o->ser);
    p->open = st == RC_OK;
    return st;
}

static void port_close(acq_port *p)
{
    if (p->open)
        rcd_port_close(&p->port);
    p->open = 0;
}

/* Close and reopen until it works or reconnect_s passes. */
static rc_status reconnect(acq_port *p, rcd_display *d, const acq_opts *o)
{
    long long until = mono_ms() + (long long)o->reconnect_s * 1000;
    rc_status st;
    port_close(p);
    do {
        st = port_open(p, o);
        if (st == RC_OK) {
            d->port = &p->port;
            rcd_display_reset(d);
            fprintf(stderr, "rcal acquire: %s reopened\n", o->port);
            return RC_OK;
        }
        sleep_ms(250);
    } while (mono_ms() < until);
    fprintf(stderr, "rcal acquire: cannot reopen %s within %lu s: %s: %s\n", o->port, o->reconnect_s,
            rc_strerror(st), rcd_port_last_error(&p->port));
    return st;
}

typedef struct acq_counts {
    unsigned long timeouts, corrupt, device, range, unstable, reconnects;
} acq_counts;

/* Read until n consecutive readings agree within tol. Returns RC_OK with the
 * mean and spread, or the error that stopped it. */
static rc_status measure_pose(double *mean_mm, double *spread_mm, acq_port *p, rcd_display *d,
                              const acq_opts *o, size_t pose, acq_counts *cnt)
{
    double win[ACQ_MAX_N];
    size_t nw = 0;
    unsigned long fails = 0, reconnects = 0;
    long long deadline = mono_ms() + (long long)o->pose_timeout_s * 1000, last_poll = 0;
    while (mono_ms() < deadline) {
        rcd_reading r = {0};
        rc_status st;
        if (d->cfg.protocol != RCD_PROTO_ASCII && o->poll_interval_ms) {
            long long wait = last_poll + (long long)o->poll_interval_ms - mono_ms();
            if (last_poll && wait > 0)
                sleep_ms((unsigned long)wait);
            last_poll = mono_ms();
        }
        st = rcd_display_read(d, &r, (unsigned)o->read_timeout_ms);
        if (st == RC_OK) {
            double lo, hi;
            size_t k;
            if (!(r.len_mm >= o->min_mm && r.len_mm <= o->max_mm)) {
                cnt->range++;
                if (!o->quiet)
                    fprintf(stderr, "rcal acquire: pose %zu: reading %.4f mm outside [%g, %g] mm rejected\n", pose,
                            r.len_mm, o->min_mm, o->max_mm);
                nw = 0;
                continue;
            }
            fails = 0;
            /* keep the longest tail of the window that agrees with r */
            win[nw++] = r.len_mm;
            for (k = nw - 1; k > 0; --k) {
                lo = hi = r.len_mm;
                for (size_t m = k - 1; m < nw; ++m) {
                    lo = win[m] < lo ? win[m] : lo;
                    hi = win[m] > hi ? win[m] : hi;
                }
                if (hi - lo > o->tol_mm)
                    break;
            }
            if (k > 0) { /* win[k-1] disagrees: drop win[0..k-1] */
                cnt->unstable++;
                memmove(win, win + k, (nw - k) * sizeof *win);
                nw -= k;
            }
            if (nw > o->n) {
                memmove(win, win + 1, (nw - 1) * sizeof *win);
                --nw;
            }
            if (nw == o->n) {
                double sum = 0;
                lo = hi = win[0];
                for (size_t m = 0; m < nw; ++m) {
                    sum += win[m];
                    lo = win[m] < lo ? win[m] : lo;
                    hi = win[m] > hi ? win[m] : hi;
                }
                *mean_mm = sum / (double)nw;
                *spread_mm = hi - lo;
                return RC_OK;
            }
            continue;
        }
        if (st == RC_ERR_CLOSED || st == RC_ERR_IO) {
            fprintf(stderr, "rcal acquire: pose %zu: display disconnected (%s: %s); reconnecting\n", pose,
                    rc_strerror(st), rcd_port_last_error(&p->port));
            cnt->reconnects++;
            nw = 0;
            if (++reconnects > o->retries) {
                fprintf(stderr, "rcal acquire: pose %zu: %lu reconnects did not help\n", pose, o->retries);
                return st;
            }
            st = reconnect(p, d, o);
            if (st != RC_OK)
                return st;
            continue;
        }
        ++fails;
        if (st == RC_ERR_TIMEOUT) {
            cnt->timeouts++;
            fprintf(stderr, "rcal acquire: pose %zu: no reading within %lu ms (%lu/%lu)\n", pose, o->read_timeout_ms,
                    fails, o->retries);
        } else if (st == RC_ERR_DEVICE) {
            cnt->device++;
            fprintf(stderr, "rcal acquire: pose %zu: the display answered Modbus exception %u (%lu/%lu)\n", pose,
                    (unsigned)r.exception, fails, o->retries);
        } else if (st == RC_ERR_FORMAT || st == RC_ERR_CHECKSUM) {
            cnt->corrupt++;
            if (!o->quiet)
                fprintf(stderr, "rcal acquire: pose %zu: %s frame dropped\n", pose,
                        st == RC_ERR_CHECKSUM ? "corrupted (checksum)" : "malformed");
            if (fails < o->retries * 10)
                continue; /* corruption: cheap to retry, the next frame is near */
        } else {
            fprintf(stderr, "rcal acquire: pose %zu: %s\n", pose, rc_strerror(st));
            return st;
        }
        if (fails >= o->retries) {
            fprintf(stderr, "rcal acquire: pose %zu: %lu failures in a row; reopening the port\n", pose, fails);
            cnt->reconnects++;
            fails = 0;
            nw = 0;
            if (++reconnects > o->retries) {
                fprintf(stderr, "rcal acquire: pose %zu: %lu reconnects did not help\n", pose, o->retries);
                return st;
            }
            st = reconnect(p, d, o);
            if (st != RC_OK)
                return st;
        }
    }
    fprintf(stderr, "rcal acquire: pose %zu: no %lu consecutive readings within %g mm in %lu s "
                    "(robot still moving or vibrating? raise --stable-mm or --pose-timeout-s)\n",
            pose, o->n, o->tol_mm, o->pose_timeout_s);
    return RC_ERR_TIMEOUT;
}

int rcal_cmd_acquire(int argc, char **argv)
{
    acq_opts o;
    rch_data plan;
    rch_diag dg;
    char dbuf[900];
    double (*plan_deg)[RC_NJ] = NULL;
    unsigned char *done = NULL;
    size_t n_done = 0, n_new = 0;
    const acq_joint_source *js = NULL;
    acq_port p;
    rcd_display d;
    acq_counts cnt;
    FILE *out = NULL;
    rc_status st;
    int rc = 1;

    rc = parse_opts(&o, argc, argv);
    if (rc != 0)
        return rc;
    rc = 1;
    for (size_t i = 0; i < sizeof joint_sources / sizeof joint_sources[0]; ++i)
        if (strcmp(o.joints, joint_sources[i].name) == 0)
            js = &joint_sources[i];
    if (!js) {
        fprintf(stderr, "rcal acquire: --joints: only 'plan' is built in (see the hook in cmd_acquire.c)\n");
        return 2;
    }
    if (rch_data_load(&plan, o.poses, RCH_DATA_NO_LEN, &dg) != 0) {
        fprintf(stderr, "rcal acquire: %s\n", rch_diag_str(&dg, dbuf, sizeof dbuf));
        return 1;
    }
    memset(&cnt, 0, sizeof cnt);
    memset(&p, 0, sizeof p);
    plan_deg = calloc(plan.n ? plan.n : 1, sizeof *plan_deg);
    done = calloc(plan.n ? plan.n : 1, 1);
    if (!plan_deg || !done)
        goto out;
    for (size_t i = 0; i < plan.n; ++i)
        for (int j = 0; j < RC_NJ; ++j) /* back to the file's degrees, at its 4 decimals */
            plan_deg[i][j] = round(plan.s[i].q_rad[j] * (180.0 / 3.14159265358979323846) * 1e4) / 1e4;
    if (scan_existing(o.out, done, plan.n, plan_deg, &n_done) != 0)
        goto out;
    if (n_done == plan.n) {
        printf("rcal acquire: %s already holds all %zu poses; nothing to do\n", o.out, plan.n);
        rc = 0;
        goto out;
    }
    out = fopen(o.out, "a");
    if (!out) {
        fprintf(stderr, "rcal acquire: cannot open %s for appending: %s\n", o.out, strerror(errno));
        goto out;
    }
    if (ftell(out) == 0) {
        fprintf(out, "%s\n", ACQ_HEADER);
        if (fflush(out) != 0 || fsync(fileno(out)) != 0) {
            fprintf(stderr, "rcal acquire: %s: %s\n", o.out, strerror(errno));
            goto out;
        }
    }
    if (n_done)
        printf("rcal acquire: resuming: %zu of %zu poses already in %s\n", n_done, plan.n, o.out);
    st = port_open(&p, &o);
    if (st != RC_OK) {
        fprintf(stderr, "rcal acquire: cannot open %s (%s backend): %s: %s\n", o.port, o.backend, rc_strerror(st),
                rcd_port_last_error(&p.port));
        if (strcmp(o.backend, "serialport") == 0 && strncmp(o.port, "/dev/pts/", 9) == 0)
            fprintf(stderr, "rcal acquire: libserialport refuses pseudo-terminals: use --backend posix\n");
        goto out;
    }
    if (rcd_display_init(&d, &p.port, &o.proto) != RC_OK) {
        fprintf(stderr, "rcal acquire: invalid protocol settings\n");
        goto out;
    }
    for (size_t i = 0; i < plan.n; ++i) {
        double q_deg[RC_NJ], mean = 0, spread = 0;
        if (done[i])
            continue;
        printf("pose %zu/%zu: q =", i + 1, plan.n);
        for (int j = 0; j < RC_NJ; ++j)
            printf(" %.4f", plan_deg[i][j]);
        printf(" deg\n");
        fflush(stdout);
        if (o.announce && announce(o.announce, i, plan_deg[i]) != 0) {
            fprintf(stderr, "rcal acquire: cannot write --announce %s: %s\n", o.announce, strerror(errno));
            goto out;
        }
        if (o.confirm) {
            int ch;
            printf("  move the robot there, then press Enter ");
            fflush(stdout);
            while ((ch = getchar()) != '\n' && ch != EOF)
                ;
            if (ch == EOF) {
                fprintf(stderr, "rcal acquire: end of input; stopped (rerun to resume)\n");
                goto out;
            }
        }
        sleep_ms(o.settle_ms);
        if (js->read(js->ctx, q_deg, plan_deg[i], i) != 0)
            goto out;
        rcd_port_flush(&p.port); /* nothing from while the arm was moving */
        rcd_display_reset(&d);
        st = measure_pose(&mean, &spread, &p, &d, &o, i, &cnt);
        if (st != RC_OK) {
            fprintf(stderr, "rcal acquire: stopped at pose %zu; %zu of %zu poses recorded in %s; "
                            "rerun the same command to resume\n", i, n_done + n_new, plan.n, o.out);
            goto out;
        }
        fprintf(out, "%zu", i);
        for (int j = 0; j < RC_NJ; ++j)
            fprintf(out, ",%.4f", q_deg[j]);
        fprintf(out, ",%.4f,%.4f,%lu,%lld\n", mean, spread, o.n, wall_ms());
        if (fflush(out) != 0 || fsync(fileno(out)) != 0) {
            fprintf(stderr, "rcal acquire: writing %s failed: %s\n", o.out, strerror(errno));
            goto out;
        }
        ++n_new;
        printf("  L = %.4f mm (spread %.4f mm over %lu readings)\n", mean, spread, o.n);
        fflush(stdout);
    }
    printf("rcal acquire: %zu poses recorded (%zu new) in %s; %lu readings, %lu timeouts, %lu bad frames, "
           "%lu format rejects, %lu device errors, %lu out of range, %lu unstable restarts, %lu reconnects\n",
           n_done + n_new, n_new, o.out, d.stats.readings, cnt.timeouts, d.stats.bad_frames, d.stats.shape_rejects,
           cnt.device, cnt.range, cnt.unstable, cnt.reconnects);
    rc = 0;
out:
    if (out && fclose(out) != 0) {
        fprintf(stderr, "rcal acquire: closing %s failed: %s\n", o.out, strerror(errno));
        rc = 1;
    }
    port_close(&p);
    free(plan_deg);
    free(done);
    rch_data_free(&plan);
    return rc;
}
