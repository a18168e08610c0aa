/* SPDX-License-Identifier: MIT */
/* rcal_rt.c - rcal-rt: the compensation in a host real-time loop, its
 * benchmark, and the generator of the firmware's compiled-in model tables.
 *
 *   rcal-rt [--model MODEL.json] [--rate-hz 1000] [--seconds 10] [--in TARGETS.csv] [--fifo] [--cpu N]
 *   rcal-rt --bench [--targets N] [--repeat R] [--model MODEL.json]
 *   rcal-rt --emit-c MODEL.json [--position-only] > fw_model_data.h
 *   rcal-rt [--model MODEL.json] --egm-port PORT --in FILE|FIFO [--egm-bind ADDR] [--egm-controller ADDR] ...
 *   rcal-rt [--model MODEL.json] --egm-bench [--seconds S] [--rate-hz 250] [--fifo]
 * (the EGM sensor of issue 49: rt_egm.h, docs/egm.md; built when protobuf-c is)
 *
 * Exit status: 0, 1 when a cycle failed (the compensation did not converge)
 * or missed its deadline (the counts on stderr), or an input was refused,
 * 2 for a usage error.
 *
 * Loop: wakes at absolute times t_k = t_0 + k * period (clock_nanosleep with
 * TIMER_ABSTIME on CLOCK_MONOTONIC), compensates the k-th target of the
 * stream, and records: the compute latency (the rc_comp_stream_step call),
 * the wake-up lateness (actual wake minus t_k) and the completion time
 * (done minus t_k). A deadline miss is a cycle whose result is ready after
 * t_k + period (the next cycle's start); cycles so late that their slot has
 * passed are counted as missed too and not run twice.
 * Without --model the compiled-in firmware tables (fw_model_data.h) are used.
 */
#include <errno.h>
#include <math.h>
#include <sched.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <time.h>

#include "fw_model_data.h"
#include "rc_comp.h"
#include "rch_diag.h"
#include "rch_comp.h"
#include "rch_data.h"
#include "rch_emit.h"
#include "rch_file.h"
#include "rch_opt.h"
#include "rch_robot.h"
#include "rch_stdio.h"
#include "rt_sched.h"
#ifdef RCAL_HAVE_EXPAT
#include "rt_rsi_loop.h"
#endif
#ifdef RCAL_HAVE_EGM
#include "rt_egm.h"
#endif

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif
#define DEG (M_PI / 180.0)
/* --bench --targets limit: 56 bytes per target (its q and its latency) */
#define RT_MAX_TARGETS 10000000UL
/* --bench: targets times repeats (about 2 minutes at 1 us per target) */
#define RT_MAX_BENCH_WORK 100000000.0
/* the loop: cycles (24 bytes of timings each: 240 MB) */
#define RT_MAX_CYCLES 10000000.0

static void usage(FILE *f)
{
    fprintf(f,
            "usage: rcal-rt [--model MODEL.json] [--nominal ROBOT.json] [--rate-hz HZ] [--seconds S]\n"
            "               [--in TARGETS.csv] [--position-only] [--fifo] [--cpu N] [--json]\n"
            "       rcal-rt --bench [--targets N] [--repeat R] [--cold] [--model MODEL.json] [--position-only]\n"
            "       rcal-rt --emit-c MODEL.json [--position-only]\n"
            "       rcal-rt [--model M.json] --egm-port PORT --in FILE|FIFO|- [--egm-bind ADDR] [--egm-controller ADDR]\n"
            "               [--egm-step-deg D] [--egm-follow-deg D] [--egm-timeout-s S] [--egm-wait-s S] [--json]\n"
            "       rcal-rt [--model M.json] --egm-bench [--seconds S] [--rate-hz 250] [--fifo] [--json]\n"
            "  loop:    compensates one target per period (default 1000 Hz for 10 s) with\n"
            "           clock_nanosleep(TIMER_ABSTIME) and reports compute latency, wake-up\n"
            "           lateness and completion time (median, p99, p99.99, max) and deadline misses\n"
            "  --in     targets (q1..q6 degrees per line; a header line, optional, names its columns),\n"
            "           cycled; default: a smooth synthetic joint-space path through the workspace.\n"
            "           Read as every rcal CSV: a field that is not a finite decimal number is refused\n"
            "           with file:line:col, targets that look like radians are refused\n"
            "  --fifo   run as SCHED_FIFO priority 80 with memory locked (needs the privilege)\n"
            "  --bench  compensates N targets back to back (default 200000), R times (default 5),\n"
            "           reports latency per target and targets/s for each run and their medians;\n"
            "           --cold solves every target from scratch (no warm start from the last correction)\n"
            "  --emit-c writes the C tables of a model for fw_example.c (fw_model_data.h)\n"
            "  --egm-port  an ABB EGM sensor in joint mode on UDP (default address 127.0.0.1): each EgmRobot of the\n"
            "           controller answered with an EgmSensor whose planned joints are the next --in target\n"
            "           compensated (degrees); faults counted, the reference never jumps (docs/egm.md)\n"
            "  --egm-bench  rcal-rt's EGM loop and a trivial C responder answering a C controller at --rate-hz\n"
            "           (250) for --seconds (10): latency, missed cycles, CPU per cycle\n"
            "Without --model, the compiled-in firmware model tables are used.\n");
#ifdef RCAL_HAVE_EXPAT
    rt_rsi_usage(f);
#endif
}

static double now_ns(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec * 1e9 + (double)t.tv_nsec;
}

static int cmp_double(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Nearest-rank percentile of sorted v (n > 0), p in [0, 100]. */
static double pct(const double *v, size_t n, double p)
{
    size_t k = (size_t)ceil(p / 100.0 * (double)n);
    if (k < 1)
        k = 1;
    if (k > n)
        k = n;
    return v[k - 1];
}

typedef struct {
    double med, p99, p9999, max, mean;
} stats;

static stats stats_of(double *v, size_t n)
{
    stats s = {0, 0, 0, 0, 0};
    if (n == 0)
        return s;
    qsort(v, n, sizeof v[0], cmp_double);
    double sum = 0.0;
    for (size_t i = 0; i < n; ++i)
        sum += v[i];
    s.med = pct(v, n, 50.0);
    s.p99 = pct(v, n, 99.0);
    s.p9999 = pct(v, n, 99.99);
    s.max = v[n - 1];
    s.mean = sum / (double)n;
    return s;
}

/* Targets: a file's rows (degrees -> rad) or the synthetic path. */
typedef struct {
    double (*q)[RC_NJ];
    size_t n;
} targets;

/* Smooth path through the workspace, away from the singularities: each
 * joint a sine of its own frequency. k at rate_hz. */
static void synth_target(double q[RC_NJ], size_t k, double rate_hz)
{
    static const double c[RC_NJ] = {0.0, 0.35, -0.35, 0.0, 0.9, 0.0};
    static const double a[RC_NJ] = {1.2, 0.35, 0.35, 1.0, 0.5, 1.5};
    static const double f[RC_NJ] = {0.05, 0.07, 0.11, 0.13, 0.17, 0.19};
    const double t = (double)k / rate_hz;
    for (int i = 0; i < RC_NJ; ++i)
        q[i] = c[i] + a[i] * sin(2.0 * M_PI * f[i] * t + i);
}

static void get_target(double q[RC_NJ], const targets *t, size_t k, double rate_hz)
{
    if (t->n > 0)
        memcpy(q, t->q[k % t->n], sizeof t->q[0]);
    else
        synth_target(q, k, rate_hz);
}

static void print_stats(const char *label, const stats *s, int json)
{
    if (json)
        printf("\"%s\": {\"median_us\": %.3f, \"p99_us\": %.3f, \"p99_99_us\": %.3f, \"max_us\": %.3f, "
               "\"mean_us\": %.3f}",
               label, s->med, s->p99, s->p9999, s->max, s->mean);
    else
        printf("  %-22s median %8.3f  p99 %8.3f  p99.99 %8.3f  max %9.3f  mean %8.3f  (us)\n", label, s->med,
               s->p99, s->p9999, s->max, s->mean);
}

static int run_bench(const rc_kin *cal, const rc_kin *nom, const rc_comp_config *cfg, const targets *t,
                     size_t n, unsigned repeat, int cold, int json)
{
    if (n == 0 || repeat == 0) {
        fprintf(stderr, "rcal-rt: empty benchmark\n");
        return 1;
    }
    double *lat = malloc(n * sizeof *lat);
    double *meds = malloc(repeat * sizeof *meds), *p4s = malloc(repeat * sizeof *p4s),
           *tps = malloc(repeat * sizeof *tps);
    double (*tq)[RC_NJ] = malloc(n * sizeof *tq);
    if (!lat || !meds || !p4s || !tps || !tq) {
        fprintf(stderr, "rcal-rt: out of memory\n");
        free(lat);
        free(meds);
        free(p4s);
        free(tps);
        free(tq);
        return 1;
    }
    unsigned long fails = 0, iters = 0;
    if (!json)
        printf("rcal-rt bench: %zu targets per run, %u runs, one core, %s\n", n, repeat,
               cold ? "cold: every target solved from its own q (no warm start)"
                    : "stream: seeded with the last correction, targets 1 ms apart");
    for (size_t k = 0; k < n; ++k)
        get_target(tq[k], t, k, 1000.0);
    static rc_comp_stream s;
    for (unsigned r = 0; r < repeat; ++r) {
        double qc[RC_NJ], sink = 0.0;
        /* throughput: back to back, no per-call timing */
        rc_comp_stream_init_kin(&s, cal, nom, cfg);
        const double t0 = now_ns();
        for (size_t k = 0; k < n; ++k) {
            if (cold)
                s.have_dq = 0;
            if (rc_comp_stream_step(&s, qc, NULL, tq[k]) != RC_OK)
                ++fails;
            sink += qc[0];
        }
        const double total_s = (now_ns() - t0) / 1e9;
        /* latency: each call timed */
        rc_comp_stream_init_kin(&s, cal, nom, cfg);
        for (size_t k = 0; k < n; ++k) {
            rc_comp_result res;
            if (cold)
                s.have_dq = 0;
            const double a = now_ns();
            rc_comp_stream_step(&s, qc, &res, tq[k]);
            lat[k] = (now_ns() - a) / 1e3;
            iters += res.iterations;
            sink += qc[1];
        }
        stats st = stats_of(lat, n);
        meds[r] = st.med;
        p4s[r] = st.p9999;
        tps[r] = (double)n / total_s;
        if (!json)
            printf("  run %u: median %.3f us, p99 %.3f us, p99.99 %.3f us, max %.3f us; %.0f targets/s%s\n", r + 1,
                   st.med, st.p99, st.p9999, st.max, tps[r], isfinite(sink) ? "" : " (non-finite output!)");
    }
    free(tq);
    qsort(meds, repeat, sizeof *meds, cmp_double);
    qsort(p4s, repeat, sizeof *p4s, cmp_double);
    qsort(tps, repeat, sizeof *tps, cmp_double);
    const double mi = (double)iters / ((double)n * repeat);
    if (json)
        printf("{\"targets\": %zu, \"runs\": %u, \"median_us\": %.3f, \"p99_99_us\": %.3f, \"targets_per_s\": %.0f, "
               "\"iterations_per_target\": %.3f, \"not_converged\": %lu}\n",
               n, repeat, pct(meds, repeat, 50), pct(p4s, repeat, 50), pct(tps, repeat, 50), mi, fails);
    else
        printf("median over runs: latency median %.3f us, p99.99 %.3f us, %.0f targets/s; %.3f iterations/target, "
               "%lu not converged\n",
               pct(meds, repeat, 50), pct(p4s, repeat, 50), pct(tps, repeat, 50), mi, fails);
    free(lat);
    free(meds);
    free(p4s);
    free(tps);
    if (fails)
        fprintf(stderr, "rcal-rt: %lu of %zu compensations failed: they did not converge (the stream's fallback "
                        "was used); exit status 1\n", fails, n * (size_t)repeat);
    return fails ? 1 : 0;
}

static int run_loop(const rc_kin *cal, const rc_kin *nom, const rc_comp_config *cfg, const targets *t,
                    double rate_hz, double seconds, int json)
{
    const size_t n = (size_t)(rate_hz * seconds + 0.5);
    const long period_ns = (long)(1e9 / rate_hz + 0.5);
    if (n == 0) {
        fprintf(stderr, "rcal-rt: empty run (--rate-hz times --seconds is less than one cycle)\n");
        return 1;
    }
    double *lat = malloc(n * sizeof *lat), *wake = malloc(n * sizeof *wake), *done = malloc(n * sizeof *done);
    if (!lat || !wake || !done) {
        fprintf(stderr, "rcal-rt: out of memory\n");
        free(lat);
        free(wake);
        free(done);
        return 1;
    }
    static rc_comp_stream s;
    rc_comp_stream_init_kin(&s, cal, nom, cfg);
    /* warm up caches and the stream's correction */
    double q[RC_NJ], qc[RC_NJ];
    get_target(q, t, 0, rate_hz);
    rc_comp_stream_step(&s, qc, NULL, q);

    struct timespec next;
    clock_gettime(CLOCK_MONOTONIC, &next);
    next.tv_nsec += 2 * period_ns;
    size_t ran = 0, misses = 0, skipped = 0;
    unsigned long fails = 0;
    for (size_t k = 0; k < n; ++k) {
        while (next.tv_nsec >= 1000000000L) {
            next.tv_nsec -= 1000000000L;
            next.tv_sec++;
        }
        while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &next, NULL) == EINTR) {
        }
        const double tk = (double)next.tv_sec * 1e9 + (double)next.tv_nsec;
        const double w = now_ns();
        get_target(q, t, k, rate_hz);
        const double a = now_ns();
        if (rc_comp_stream_step(&s, qc, NULL, q) != RC_OK)
            ++fails;
        const double b = now_ns();
        lat[ran] = (b - a) / 1e3;
        wake[ran] = (w - tk) / 1e3;
        done[ran] = (b - tk) / 1e3;
        if (b - tk > (double)period_ns)
            ++misses;
        ++ran;
        next.tv_nsec += period_ns;
        /* a cycle whose slot already passed is not run late: count and skip it */
        for (;;) {
            const double tn = (double)next.tv_sec * 1e9 + (double)next.tv_nsec;
            if (now_ns() <= tn + (double)period_ns || k + 1 >= n)
                break;
            next.tv_nsec += period_ns;
            while (next.tv_nsec >= 1000000000L) {
                next.tv_nsec -= 1000000000L;
                next.tv_sec++;
            }
            ++skipped;
            ++misses;
            ++k;
        }
    }
    stats sl = stats_of(lat, ran), sw = stats_of(wake, ran), sd = stats_of(done, ran);
    if (json) {
        printf("{\"rate_hz\": %.1f, \"cycles\": %zu, \"deadline_misses\": %zu, \"skipped\": %zu, \"not_converged\": %lu, ",
               rate_hz, n, misses, skipped, fails);
        print_stats("compute", &sl, 1);
        printf(", ");
        print_stats("wake_lateness", &sw, 1);
        printf(", ");
        print_stats("completion", &sd, 1);
        printf("}\n");
    } else {
        printf("rcal-rt: %.0f Hz (period %.1f us), %zu cycles, %.1f s\n", rate_hz, (double)period_ns / 1e3, n,
               seconds);
        print_stats("compensation", &sl, 0);
        print_stats("wake-up lateness", &sw, 0);
        print_stats("completion (t - t_k)", &sd, 0);
        printf("  deadline misses: %zu (of which %zu cycles skipped), not converged: %lu\n", misses, skipped, fails);
    }
    free(lat);
    free(wake);
    free(done);
    if (fails)
        fprintf(stderr, "rcal-rt: %lu of %zu cycles failed: the compensation did not converge (the stream's "
                        "fallback was used); exit status 1\n", fails, ran);
    if (misses)
        fprintf(stderr, "rcal-rt: %zu of %zu cycles missed their deadline; exit status 1\n", misses, n);
    return misses || fails ? 1 : 0;
}

/* The model compensation uses (rch_comp_determined): det; returns 1 when
 * the model file says the orientation was not determined (position only). */
static int determined(rc_model *det, const rch_robot *robot)
{
    *det = robot->model;
    if (!robot->has_nominal && !robot->unc.present)
        return 0; /* a plain robot file: nothing was calibrated */
    static rch_model_unc unc;
    int v1 = 0;
    char held[256];
    unsigned n = rch_comp_determined(det, &unc, &v1, held, sizeof held, robot, &robot->nominal);
    /* the flange, never the cable attachment point the calibration measured */
    rch_comp_point_model(det, det, NULL);
    fprintf(stderr, "rcal-rt: compensating with %u of 24 DH parameters as fitted; held nominal: %s\n", 24u - n,
            n ? held : "none");
    return v1 || !unc.orientation_determined;
}

/* --emit-c: the firmware's compiled tables (rch_emit_c) on stdout. */
static int emit_c(const char *path, const char *nominal_path, int position_only)
{
    static rch_robot robot, nominal;
    rch_diag d;
    char msg[1024], cmd[2200];
    if (rch_robot_load(&robot, path, &d) != 0 || (nominal_path && rch_robot_load(&nominal, nominal_path, &d) != 0)) {
        fprintf(stderr, "rcal-rt: %s\n", rch_diag_str(&d, msg, sizeof msg));
        return 1;
    }
    if ((size_t)snprintf(cmd, sizeof cmd, "rcal-rt --emit-c %s%s%s%s", path, nominal_path ? " --nominal " : "",
                         nominal_path ? nominal_path : "", position_only ? " --position-only" : "") >= sizeof cmd) {
        fprintf(stderr, "rcal-rt: --emit-c: the model paths are too long for the header's provenance line (%zu "
                        "bytes): refused, not cut\n", sizeof cmd);
        return 2;
    }
    /* the firmware compensates with what the data determined, as rcal compensate does (issue 10) */
    static rc_model det;
    int pos_only = determined(&det, &robot) || position_only;
    const rch_emit_src src = {robot.name, cmd, pos_only ? (unsigned)RC_COMP_FLAG_POSITION_ONLY : 0u};
    memset(&d, 0, sizeof d);
    const int bad = rch_emit_c(stdout, &src, &det, nominal_path ? &nominal.model : &robot.nominal, &d) != 0;
    if (bad && !ferror(stdout)) {
        fprintf(stderr, "rcal-rt: %s: %s\n", path, rch_diag_str(&d, msg, sizeof msg));
        return 1;
    }
    if (bad || fflush(stdout) != 0) { /* d.msg is not the reason: the stream's is */
        fprintf(stderr, "rcal-rt: --emit-c %s: writing the C tables to standard output failed: %s\n", path,
                strerror(rch_stdio_errno(stdout)));
        return 1;
    }
    return 0;
}

/* Number options: the whole value must be a number (the strict readers of
 * rch_opt.h: no blanks, no hex, finite, no wrap), else a message naming the
 * option and the value and -1 (main then exits 2, a usage error). Ranges are
 * checked by main. */
static int opt_double(const char *name, const char *v, double *out)
{
    if (rch_parse_double(v, out) != 0) {
        fprintf(stderr, "rcal-rt: option %s: '%s' is not a finite decimal number\n", name, v);
        return -1;
    }
    return 0;
}

static int opt_ulong(const char *name, const char *v, unsigned long *out)
{
    if (rch_parse_ulong(v, out) != 0) {
        fprintf(stderr, "rcal-rt: option %s: '%s' is not a non-negative integer that fits\n", name, v);
        return -1;
    }
    return 0;
}

/* The command line of rcal-rt. */
typedef struct rt_opts {
    const char *model_path, *nominal_path, *in_path, *emit;
    double rate_hz, seconds;
    unsigned long n_bench, repeat, cpu;
    int bench, cold, fifo, json, position_only, pin;
    /* EGM (issue 49) */
    unsigned long egm_port;
    const char *egm_bind, *egm_controller;
    double egm_step_deg, egm_follow_deg, egm_timeout_s, egm_wait_s;
    int egm, egm_bench, rate_given;
    const rch_ctrl *ctrl; /* --model's controller joints (NULL: the identity, or no --model) */
} rt_opts;

/* The options into o: -1 when they were read, else the exit status (0 after
 * --help, 2 for a bad option, with its message). */
static int parse_args(rt_opts *o, int argc, char **argv)
{
    memset(o, 0, sizeof *o);
    o->rate_hz = 1000.0;
    o->seconds = 10.0;
    o->n_bench = 200000;
    o->repeat = 5;
    o->egm_step_deg = 0.01;
    o->egm_follow_deg = 1.0;
    o->egm_timeout_s = 1.0;
    o->egm_wait_s = 60.0;
    for (int i = 1; i < argc; ++i) {
        const char *a = argv[i];
        const int has = i + 1 < argc;
        if (strcmp(a, "--model") == 0 && has)
            o->model_path = argv[++i];
        else if (strcmp(a, "--nominal") == 0 && has)
            o->nominal_path = argv[++i];
        else if (strcmp(a, "--in") == 0 && has)
            o->in_path = argv[++i];
        else if (strcmp(a, "--emit-c") == 0 && has)
            o->emit = argv[++i];
        else if (strcmp(a, "--rate-hz") == 0 && has) {
            if (opt_double(a, argv[++i], &o->rate_hz) != 0)
                return 2;
            o->rate_given = 1;
        } else if (strcmp(a, "--seconds") == 0 && has) {
            if (opt_double(a, argv[++i], &o->seconds) != 0)
                return 2;
        } else if (strcmp(a, "--targets") == 0 && has) {
            if (opt_ulong(a, argv[++i], &o->n_bench) != 0)
                return 2;
        } else if (strcmp(a, "--repeat") == 0 && has) {
            if (opt_ulong(a, argv[++i], &o->repeat) != 0)
                return 2;
        } else if (strcmp(a, "--cpu") == 0 && has) {
            if (opt_ulong(a, argv[++i], &o->cpu) != 0)
                return 2;
            o->pin = 1;
        } else if (strcmp(a, "--egm-port") == 0 && has) {
            if (opt_ulong(a, argv[++i], &o->egm_port) != 0)
                return 2;
            o->egm = 1;
        } else if (strcmp(a, "--egm-bind") == 0 && has)
            o->egm_bind = argv[++i];
        else if (strcmp(a, "--egm-controller") == 0 && has)
            o->egm_controller = argv[++i];
        else if ((strcmp(a, "--egm-step-deg") == 0 || strcmp(a, "--egm-follow-deg") == 0 ||
                  strcmp(a, "--egm-timeout-s") == 0 || strcmp(a, "--egm-wait-s") == 0) && has) {
            double *v = a[6] == 's' ? &o->egm_step_deg : a[6] == 'f' ? &o->egm_follow_deg
                        : a[6] == 't' ? &o->egm_timeout_s : &o->egm_wait_s;
            if (opt_double(a, argv[++i], v) != 0)
                return 2;
        } else if (strcmp(a, "--egm-bench") == 0)
            o->egm_bench = 1;
        else if (strcmp(a, "--bench") == 0)
            o->bench = 1;
        else if (strcmp(a, "--cold") == 0)
            o->cold = 1;
        else if (strcmp(a, "--fifo") == 0)
            o->fifo = 1;
        else if (strcmp(a, "--json") == 0)
            o->json = 1;
        else if (strcmp(a, "--position-only") == 0)
            o->position_only = 1;
        else if (strcmp(a, "--help") == 0) {
            usage(stdout);
            return 0;
        } else {
            int takes_value = 0;
            static const char *const valued[] = {"--model",   "--nominal", "--in",     "--emit-c",
                                                 "--rate-hz", "--seconds", "--targets", "--repeat", "--cpu",
                                                 "--egm-port", "--egm-bind", "--egm-controller", "--egm-step-deg",
                                                 "--egm-follow-deg", "--egm-timeout-s", "--egm-wait-s"};
            for (size_t k = 0; k < sizeof valued / sizeof valued[0]; ++k)
                takes_value |= strcmp(a, valued[k]) == 0;
            if (takes_value)
                fprintf(stderr, "rcal-rt: option %s needs a value\n", a);
            else
                fprintf(stderr, "rcal-rt: unknown option '%s'\n", a);
            usage(stderr);
            return 2;
        }
    }
    return -1;
}

/* The options' ranges: 0, or 2 with the message. */
static int check_args(const rt_opts *o)
{
    if (!(o->rate_hz >= 1.0 && o->rate_hz <= 100000.0)) {
        fprintf(stderr, "rcal-rt: --rate-hz %g is out of range (1 to 100000)\n", o->rate_hz);
        return 2;
    }
    if (!(o->seconds > 0.0 && o->seconds <= 3600.0)) {
        fprintf(stderr, "rcal-rt: --seconds %g is out of range (more than 0, at most 3600)\n", o->seconds);
        return 2;
    }
    if (o->n_bench == 0 || o->n_bench > RT_MAX_TARGETS) {
        fprintf(stderr, "rcal-rt: --targets %lu is out of range (1 to %lu)\n", o->n_bench,
                (unsigned long)RT_MAX_TARGETS);
        return 2;
    }
    if (o->repeat == 0 || o->repeat > 1000) {
        fprintf(stderr, "rcal-rt: --repeat %lu is out of range (1 to 1000)\n", o->repeat);
        return 2;
    }
    if (o->bench && (double)o->n_bench * (double)o->repeat > RT_MAX_BENCH_WORK) {
        fprintf(stderr, "rcal-rt: --targets times --repeat is %.0f, over the limit of %.0f compensations\n",
                (double)o->n_bench * (double)o->repeat, RT_MAX_BENCH_WORK);
        return 2;
    }
    if (!o->bench && o->rate_hz * o->seconds > RT_MAX_CYCLES) {
        fprintf(stderr, "rcal-rt: --rate-hz times --seconds is %.0f cycles, over the limit of %.0f (24 bytes of "
                        "timings each)\n", o->rate_hz * o->seconds, RT_MAX_CYCLES);
        return 2;
    }
    if (!o->bench && o->rate_hz * o->seconds < 0.5) {
        fprintf(stderr, "rcal-rt: --rate-hz times --seconds must be at least one cycle\n");
        return 2;
    }
    if (o->egm && (o->egm_port == 0 || o->egm_port > 65535)) {
        fprintf(stderr, "rcal-rt: --egm-port %lu is out of range (1 to 65535)\n", o->egm_port);
        return 2;
    }
    if (o->egm && !o->in_path) {
        fprintf(stderr, "rcal-rt: --egm-port needs --in FILE|FIFO|- (the path's joint targets, one per cycle)\n");
        return 2;
    }
    if (!(o->egm_step_deg > 0.0 && o->egm_step_deg <= 10.0) || !(o->egm_follow_deg > 0.0) ||
        !(o->egm_timeout_s > 0.0 && o->egm_timeout_s <= 3600.0) || !(o->egm_wait_s > 0.0 && o->egm_wait_s <= 86400.0)) {
        fprintf(stderr, "rcal-rt: --egm-step-deg (0 to 10], --egm-follow-deg (> 0), --egm-timeout-s (0 to 3600], "
                        "--egm-wait-s (0 to 86400]: a value is out of range\n");
        return 2;
    }
    if (o->pin && o->cpu >= (unsigned long)CPU_SETSIZE) {
        fprintf(stderr, "rcal-rt: --cpu must be 0..%d\n", CPU_SETSIZE - 1);
        return 2;
    }
    return 0;
}

/* The model files compiled into kc and kn (*pos_only raised when the
 * model's orientation is not determined). 0, or -1 with the message in err. */
static int kin_from_files(rc_kin *kc, rc_kin *kn, int *pos_only, rch_ctrl *ctrl, const char *model_path,
                          const char *nominal_path, char *err, size_t err_len)
{
    static rch_robot robot, nominal;
    rch_diag d;
    char msg[1024];
    rch_comp_job job; /* the paths, for the check that --nominal is not the model itself */
    memset(&job, 0, sizeof job);
    job.model_path = model_path;
    job.nominal_path = nominal_path;
    if (rch_robot_load(&robot, model_path, &d) != 0 ||
        (nominal_path && (rch_robot_load(&nominal, nominal_path, &d) != 0 ||
                          rch_comp_same_model(&d, &job, &robot, &nominal) != 0))) {
        snprintf(err, err_len, "%s", rch_diag_str(&d, msg, sizeof msg));
        return -1;
    }
    /* the controller's joints as rcal compensate reads them: the nominal file's member, else the model's */
    if (ctrl)
        *ctrl = nominal_path ? nominal.ctrl : robot.ctrl;
    static rc_model det;
    if (determined(&det, &robot))
        *pos_only = 1;
    rc_status st = rc_kin_compile(kc, &det);
    if (st == RC_OK)
        st = rc_kin_compile(kn, nominal_path ? &nominal.model : &robot.nominal);
    if (st != RC_OK) {
        snprintf(err, err_len, "%s: the model cannot be compiled: %s", model_path, rc_strerror(st));
        return -1;
    }
    return 0;
}

/* The kinematics to compensate with: the compiled-in firmware tables, or
 * --model's determined model and its nominal (static storage). cfg's flags
 * set (o->position_only raised when the model's orientation is not
 * determined). 0, or 1 with the message. */
static int load_kin(const rc_kin **cal, const rc_kin **nom, rc_comp_config *cfg, rt_opts *o)
{
    static rc_kin kin_cal, kin_nom;
    unsigned flags = FW_MODEL_COMP_FLAGS;
    *cal = &fw_kin_cal;
    *nom = &fw_kin_nom;
    if (o->model_path) {
        char err[1200];
        static rch_ctrl ctrl;
        if (kin_from_files(&kin_cal, &kin_nom, &o->position_only, &ctrl, o->model_path, o->nominal_path, err,
                           sizeof err)) {
            fprintf(stderr, "rcal-rt: %s\n", err);
            return 1;
        }
        o->ctrl = ctrl.present && !ctrl.identity_joints ? &ctrl : NULL;
        *cal = &kin_cal;
        *nom = &kin_nom;
        flags = 0;
    }
    if (o->position_only)
        flags |= RC_COMP_FLAG_POSITION_ONLY;
    memset(cfg, 0, sizeof *cfg);
    cfg->flags = flags;
    return 0;
}

#ifdef RCAL_HAVE_EGM
/* --egm-port: the model file read again when it is replaced (rt_egm_reload_fn) */
static int egm_reload(void *ctx, rc_kin *cal, rc_kin *nom, unsigned *flags, char *err, size_t err_len)
{
    const rt_opts *o = ctx;
    int pos_only = o->position_only;
    if (kin_from_files(cal, nom, &pos_only, NULL, o->model_path, o->nominal_path, err, err_len) != 0)
        return -1;
    *flags = pos_only ? (unsigned)RC_COMP_FLAG_POSITION_ONLY : 0u;
    return 0;
}

static int run_egm(rt_opts *o, const rc_kin *cal, const rc_kin *nom, const rc_comp_config *cfg)
{
    if (o->egm_bench)
        return rt_egm_bench(cal, nom, cfg, o->rate_given ? o->rate_hz : 250.0, o->seconds, o->fifo, o->json);
    rt_egm_opts e;
    rt_egm_opts_default(&e);
    e.port = (unsigned)o->egm_port;
    if (o->egm_bind)
        e.bind_addr = o->egm_bind;
    e.controller = o->egm_controller;
    e.in_path = o->in_path;
    e.model_path = o->model_path;
    e.reload = o->model_path ? egm_reload : NULL;
    e.reload_ctx = o;
    e.period_ms = o->rate_given ? 1e3 / o->rate_hz : 4.0;
    e.step_deg = o->egm_step_deg;
    e.follow_deg = o->egm_follow_deg;
    e.timeout_s = o->egm_timeout_s;
    e.wait_s = o->egm_wait_s;
    e.json = o->json;
    e.ctrl = o->ctrl; /* kept as read at the start when the model file is replaced */
    if (o->ctrl)
        fprintf(stderr, "rcal-rt: egm: the controller's joints mapped to the model's and back (%s's \"controller\" "
                        "member)\n", o->nominal_path ? o->nominal_path : o->model_path);
    return rt_egm_run(&e, cal, nom, cfg);
}
#endif

static int run(int argc, char **argv)
{
    rt_opts o;
    for (int i = 1; i < argc; ++i) /* --rsi-*: the KUKA RSI partner (rt_rsi_loop.c, docs/rsi.md) */
        if (strncmp(argv[i], "--rsi-", 6) == 0) {
#ifdef RCAL_HAVE_EXPAT
            return rt_rsi_main(argc, argv);
#else
            fprintf(stderr, "rcal-rt: %s: this rcal-rt was built without expat (libexpat1-dev): no RSI\n", argv[i]);
            return 2;
#endif
        }
    int rc = parse_args(&o, argc, argv);
    if (rc >= 0)
        return rc;
    if (o.emit)
        return emit_c(o.emit, o.nominal_path, o.position_only);
    if ((rc = check_args(&o)) != 0)
        return rc;
    const rc_kin *cal, *nom;
    rc_comp_config cfg;
    if (load_kin(&cal, &nom, &cfg, &o) != 0)
        return 1;
    if (o.egm || o.egm_bench) {
#ifdef RCAL_HAVE_EGM
        (void)rt_sched_realtime(o.pin, o.cpu, o.fifo);
        return run_egm(&o, cal, nom, &cfg);
#else
        fprintf(stderr, "rcal-rt: --egm-port and --egm-bench are not in this build (configured with RCAL_EGM off, "
                        "or protobuf-c was not found: Debian protobuf-c-compiler libprotobuf-c-dev)\n");
        return 2;
#endif
    }
    targets t = {NULL, 0};
    rch_diag d;
    memset(&d, 0, sizeof d);
    if (o.in_path && rch_comp_read_targets(&t.q, &t.n, o.in_path, cal, &d) != 0) {
        char msg[1024];
        fprintf(stderr, "rcal-rt: %s\n", rch_diag_str(&d, msg, sizeof msg));
        return 1;
    }
    (void)rt_sched_realtime(o.pin, o.cpu, o.fifo);
    rc = o.bench ? run_bench(cal, nom, &cfg, &t, o.n_bench, (unsigned)o.repeat, o.cold, o.json)
                 : run_loop(cal, nom, &cfg, &t, o.rate_hz, o.seconds, o.json);
    free(t.q);
    return rc;
}

/* Closed standard descriptors opened on /dev/null first; standard output and
 * standard error checked at the end (tools/host/files/rch_stdio.h). */
int main(int argc, char **argv)
{
    rch_stdio_begin("rcal-rt");
    return rch_stdio_end(run(argc, argv));
}
