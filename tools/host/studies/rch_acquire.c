/* SPDX-License-Identifier: MIT */
/* rch_acquire.c - the acquisition state machine (see rch_acquire.h). */
#include "rch_acquire.h"

#include <errno.h>
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "rch_acqfile.h"
#include "rch_data.h"
#include "rch_file.h"
#include "rch_robot.h"

#define DEG_PER_RAD (180.0 / 3.14159265358979323846)

void rch_acq_config_default(rch_acq_config *c)
{
    memset(c, 0, sizeof *c);
    c->backend = "serialport";
    c->encoder_mm[0] = 250.0;
    c->encoder_mm[1] = -460.0;
    c->encoder_mm[2] = 10.0;
    rc_stable_config_default(&c->stable);
    c->settle_ms = 2000;
    c->read_timeout_ms = 2000;
    c->retries = 5;
    c->reconnect_s = 10;
    c->poll_interval_ms = 100;
    c->follow_tol_mm = 10.0;
    c->jump_mm = 3.0;
    c->controller_tol_deg = 0.05;
    c->controller_wait_s = 60;
    c->link_timeout_s = 5;
    c->move_timeout_s = 60;
}

int rch_acq_follows(double *miss_mm, double len_mm, double pred_mm, double ref_len_mm, double ref_pred_mm,
                    double tol_mm)
{
    *miss_mm = fabs((len_mm - ref_len_mm) - (pred_mm - ref_pred_mm));
    return *miss_mm <= tol_mm ? 0 : -1;
}

/* ---- the real io: POSIX or libserialport backend, nanosleep, wall clock -- */

typedef struct sys_io {
    const char *backend;
    rcd_port port;
    rcd_posix_ctx px;
    rcd_serialport_ctx sp;
    int open;
} sys_io;

static rc_status sys_open(void *ctx, rcd_port **port, const char *path, const rcd_serial_config *cfg)
{
    sys_io *s = ctx;
    rc_status st;
    if (strcmp(s->backend, "posix") == 0)
        rcd_posix_init(&s->port, &s->px);
    else
        rcd_serialport_init(&s->port, &s->sp);
    st = rcd_port_open(&s->port, path, cfg);
    s->open = st == RC_OK;
    *port = &s->port;
    return st;
}

static void sys_close(void *ctx)
{
    sys_io *s = ctx;
    if (s->open)
        rcd_port_close(&s->port);
    s->open = 0;
}

static void sys_sleep(void *ctx, rcd_port *port, unsigned long ms)
{
    struct timespec ts;
    (void)ctx;
    (void)port;
    ts.tv_sec = (time_t)(ms / 1000);
    ts.tv_nsec = (long)(ms % 1000) * 1000000L;
    while (nanosleep(&ts, &ts) != 0 && errno == EINTR)
        ;
}

static long long sys_wall(void *ctx)
{
    struct timespec ts;
    (void)ctx;
    clock_gettime(CLOCK_REALTIME, &ts);
    return (long long)ts.tv_sec * 1000 + ts.tv_nsec / 1000000;
}

static int sys_confirm(void *ctx, size_t pose)
{
    int ch;
    (void)ctx;
    (void)pose;
    printf("  move the robot there, then press Enter ");
    fflush(stdout);
    while ((ch = getchar()) != '\n' && ch != EOF)
        ;
    return ch == EOF ? -1 : 0;
}

/* ---- one run ------------------------------------------------------------- */

typedef struct acq {
    const rch_acq_config *c;
    const rch_acq_io *io;
    FILE *out, *err;
    rch_acq_result *res;
    rcd_port *port;
    rcd_display d;
    size_t n;                 /* plan poses */
    double (*plan_deg)[RC_NJ]; /* (n x 6) */
    double *pred_mm;          /* (n) nominal length, NaN when unknown */
    unsigned char *done;      /* (n) */
    unsigned char *other;     /* (n) 1: a row of another outlet of the plan (its outlet column): not this run's */
    size_t n_mine;            /* rows this run measures */
    int outlet_p1;            /* this run's outlet + 1 (--outlet, or the plan's only outlet), 0: one place */
    int target_p1;            /* this run's cable point + 1 (--target, or the plan's only one), 0: one point */
    uint8_t pred_outlet;      /* the outlet of the follow check's model this run's lengths are predicted from */
    rch_acqfile file;
    int has_ref;              /* a recorded sample to check the next against */
    size_t ref_pose;
    double ref_len_mm;
    rc_stable st;             /* the stability rule, one for the run (its learnt tau is the display's) */
    const char *verify_why;   /* non-NULL: go back to ref_pose before the next sample counts */
    int reconnected;          /* set by reconnect(): the pose's readings so far are void */
    size_t jump_cleared;      /* pose + 1 whose suspected jump the check at ref_pose cleared; 0 none */
    int not_following;        /* the follow check refused a pose `retries` times: the run stops */
    int holding;              /* 1: the reference is a held sample, not yet written (run_poses) */
    int linked;               /* --controller: the link drives the run */
    rch_link link;
    rch_acqtime tm;           /* --controller: rcal's own time per pose (rch_acqtime.h) */
    rch_ctrl ctrl;            /* the robot file's controller conventions: a joint source's values (the
                                 controller's) are mapped to the model's before they are recorded */
} acq;

/* A mark of rcal's time per pose (linked runs only). */
static void tm_mark(acq *a, rch_acqtime_ev ev)
{
    if (a->linked)
        rch_acqtime_mark(&a->tm, ev, rch_acqtime_clock_ms(), rch_acqtime_cpu_ms());
}

#define SAY(a, ...) ((a)->out ? (void)fprintf((a)->out, __VA_ARGS__) : (void)0)
#define WARN(a, ...) ((a)->err ? (void)fprintf((a)->err, "rcal acquire: " __VA_ARGS__) : (void)0)
#define NOTE(a, ...) (!(a)->c->quiet ? WARN(a, __VA_ARGS__) : (void)0)
/* a pose's progress line: kept with --confirm (the user is asked at the pose) */
#define PROGRESS(a, ...) (!(a)->c->quiet || (a)->c->confirm ? SAY(a, __VA_ARGS__) : (void)0)

static uint32_t now_ms(const acq *a)
{
    return rcd_port_now_ms(a->port);
}

/* Close and reopen until it works or reconnect_s passes. */
static rc_status reconnect(acq *a)
{
    const uint32_t t0 = now_ms(a);
    const unsigned long limit_ms = a->c->reconnect_s * 1000ul;
    rc_status st;
    a->io->close(a->io->ctx);
    do {
        st = a->io->open(a->io->ctx, &a->port, a->c->port_path, &a->c->ser);
        if (st == RC_OK) {
            a->d.port = a->port;
            rcd_display_reset(&a->d); /* the format lock is kept: the device must show the same format */
            WARN(a, "%s reopened\n", a->c->port_path);
            a->reconnected = 1;
            if (a->has_ref)
                a->verify_why = "after the reconnect";
            return RC_OK;
        }
        a->io->sleep_ms(a->io->ctx, a->port, 250);
    } while ((unsigned long)(uint32_t)(now_ms(a) - t0) < limit_ms);
    WARN(a, "cannot reopen %s within %lu s: %s: %s\n", a->c->port_path, a->c->reconnect_s, rc_strerror(st),
         rcd_port_last_error(a->port));
    return st;
}

/* A failure or hang-up: count it, maybe reopen. RC_OK to go on. */
static rc_status handle_failure(acq *a, rc_status st, const rcd_reading *r, size_t pose, unsigned long *fails,
                                unsigned long *reopens, rc_stable *s)
{
    const rch_acq_config *c = a->c;
    if (st == RC_ERR_CLOSED || st == RC_ERR_IO) {
        WARN(a, "pose %zu: display disconnected (%s: %s); reconnecting\n", pose, rc_strerror(st),
             rcd_port_last_error(a->port));
    } else {
        ++*fails;
        if (st == RC_ERR_TIMEOUT) {
            a->res->timeouts++;
            WARN(a, "pose %zu: no reading within %lu ms (%lu/%lu)%s\n", pose, c->read_timeout_ms, *fails,
                 c->retries, rcd_display_why_silent(&a->d));
        } else if (st == RC_ERR_DEVICE) {
            a->res->device++;
            WARN(a, "pose %zu: the display answered Modbus exception %u (%lu/%lu)\n", pose, (unsigned)r->exception,
                 *fails, c->retries);
        } else if (st == RC_ERR_FORMAT || st == RC_ERR_CHECKSUM) {
            if (r->reject == RCD_REJECT_MB_SLAVE)
                WARN(a, "pose %zu: a reply from Modbus slave %u ignored (--mb-addr is %u)\n", pose,
                     (unsigned)r->mb_addr, (unsigned)(c->proto.mb_addr ? c->proto.mb_addr : 1u));
            else if (r->reject == RCD_REJECT_MB_FUNCTION)
                WARN(a, "pose %zu: a reply with Modbus function 0x%02X ignored (0x03 was asked)\n", pose,
                     (unsigned)r->mb_fn);
            else
                NOTE(a, "pose %zu: %s frame dropped\n", pose,
                     st == RC_ERR_CHECKSUM ? "corrupted (checksum)" : "malformed");
            if (*fails < c->retries * 10)
                return RC_OK; /* corruption: cheap to retry, the next frame is near */
        } else {
            WARN(a, "pose %zu: %s\n", pose, rc_strerror(st));
            return st;
        }
        if (*fails < c->retries)
            return RC_OK;
        WARN(a, "pose %zu: %lu failures in a row; reopening the port\n", pose, *fails);
    }
    a->res->reconnects++;
    *fails = 0;
    rc_stable_clear_window(s);
    if (++*reopens > c->retries) {
        WARN(a, "pose %zu: %lu reconnects did not help\n", pose, c->retries);
        return st;
    }
    return reconnect(a);
}

/* Read until the stability rule gives a sample. */
static rc_status measure(rc_stable_result *out, acq *a, size_t pose)
{
    const rch_acq_config *c = a->c;
    rc_stable *const s = &a->st;
    unsigned long fails = 0, reopens = 0;
    uint32_t last_poll = 0;
    int polled_once = 0;
    rc_status st;
    rc_stable_restart(s);
    a->reconnected = 0;
    for (;;) {
        rcd_reading r;
        memset(&r, 0, sizeof r);
        if (a->d.cfg.protocol != RCD_PROTO_ASCII && c->poll_interval_ms) {
            uint32_t since = now_ms(a) - last_poll;
            if (polled_once && since < c->poll_interval_ms)
                a->io->sleep_ms(a->io->ctx, a->port, c->poll_interval_ms - since);
            last_poll = now_ms(a);
            polled_once = 1;
        }
        st = rcd_display_read(&a->d, &r, (unsigned)c->read_timeout_ms);
        if (st == RC_OK) {
            fails = 0;
            st = rc_stable_push(s, out, r.len_mm, now_ms(a));
            if (st == RC_OK)
                tm_mark(a, RCH_ACQTIME_SAMPLE);
            if (st == RC_OK || st == RC_ERR_TIMEOUT)
                break;
            if (st == RC_ERR_RANGE)
                NOTE(a, "pose %zu: reading %.4f mm outside [%g, %g] mm rejected\n", pose, r.len_mm,
                     c->stable.min_mm, c->stable.max_mm);
            continue;
        }
        st = handle_failure(a, st, &r, pose, &fails, &reopens, s);
        if (st != RC_OK)
            return st;
        if (a->reconnected && a->verify_why) {
            st = RC_ERR_INCOMPLETE; /* the device must first read the last recorded pose as it did */
            break;
        }
        if (s->started && c->stable.timeout_ms && (uint32_t)(now_ms(a) - s->t_start_ms) > c->stable.timeout_ms) {
            st = RC_ERR_TIMEOUT;
            break;
        }
    }
    a->res->range += s->range_rejects;
    a->res->unstable += s->restarts;
    a->res->trend_rejects += s->trend_rejects;
    if (st == RC_ERR_TIMEOUT)
        WARN(a, "pose %zu: no %u consecutive readings within %g mm and without a trend in %lu s (robot still "
                "moving or vibrating, or a display filter of time constant %.1f s still settling? %lu windows had a "
                "trend; raise --stable-mm or --pose-timeout-s)\n", pose, c->stable.n, c->stable.tol_mm,
             (unsigned long)(c->stable.timeout_ms / 1000u), rc_stable_tau_ms(s) / 1000.0, s->trend_rejects);
    return st;
}

static int announce(const char *path, size_t pose, const double q_deg[RC_NJ])
{
    char tmp[1100];
    FILE *f;
    if ((size_t)snprintf(tmp, sizeof tmp, "%s.tmp", path) >= sizeof tmp || rch_tmp_register(tmp) != 0)
        return -1;
    f = fopen(tmp, "w"); /* removed on SIGINT / SIGTERM while registered */
    if (!f) {
        rch_tmp_forget(tmp);
        return -1;
    }
    fprintf(f, "%zu", pose);
    for (int j = 0; j < RC_NJ; ++j)
        fprintf(f, " %.4f", q_deg[j]);
    fprintf(f, "\n");
    int rc = fclose(f) != 0 ? -1 : rename(tmp, path);
    if (rc != 0)
        unlink(tmp);
    rch_tmp_forget(tmp);
    return rc;
}

/* Measure pose i until its sample follows the move (or give up). */
static rc_status measure_checked(rc_stable_result *r, acq *a, size_t i)
{
    const rch_acq_config *c = a->c;
    for (unsigned long attempt = 0;; ++attempt) {
        double miss = 0.0;
        rc_status st;
        rcd_port_flush(a->port); /* nothing from while the arm was moving */
        rcd_display_reset(&a->d);
        st = measure(r, a, i);
        if (st != RC_OK)
            return st;
        /* every row of this run has a prediction (predict_lengths); a NaN would refuse, never skip */
        if (c->no_follow_check || !a->has_ref ||
            rch_acq_follows(&miss, r->mean_mm, a->pred_mm[i], a->ref_len_mm, a->pred_mm[a->ref_pose],
                            c->follow_tol_mm) == 0) {
            if (a->has_ref && !c->no_follow_check && miss > c->jump_mm && a->jump_cleared != i + 1) {
                WARN(a, "pose %zu: L = %.4f mm changed by %+.2f mm from pose %zu where the nominal model predicts "
                        "%+.2f mm (off by %.2f mm, more than --jump-mm %g): a length jump? (a slipped cable, a "
                        "counter reset) Going back to pose %zu to read it again; nothing recorded yet\n",
                     i, r->mean_mm, r->mean_mm - a->ref_len_mm, a->ref_pose,
                     a->pred_mm[i] - a->pred_mm[a->ref_pose], miss, c->jump_mm, a->ref_pose);
                a->verify_why = "for a suspected length jump";
                a->jump_cleared = i + 1; /* once cleared at ref_pose, this pose's change is the model's error */
                return RC_ERR_INCOMPLETE;
            }
            if (a->has_ref && miss > a->res->worst_follow_mm)
                a->res->worst_follow_mm = miss;
            return RC_OK;
        }
        a->res->follow_refusals++;
        WARN(a, "pose %zu: REFUSED L = %.4f mm: from pose %zu (L = %.4f mm) the nominal model predicts a change of "
                "%+.2f mm, the display shows %+.2f mm (off by %.2f mm, tolerance %g mm): %s (%lu/%lu)\n",
             i, r->mean_mm, a->ref_pose, a->ref_len_mm, a->pred_mm[i] - a->pred_mm[a->ref_pose],
             r->mean_mm - a->ref_len_mm, miss, c->follow_tol_mm,
             fabs(r->mean_mm - a->ref_len_mm) <= c->stable.tol_mm
                 ? "the display did not change: frozen (HOLD pressed, firmware hung) or the robot did not move"
                 : "a frozen display (HOLD pressed, firmware hung), another device on the port, a slipped "
                   "cable, or the robot is not at the pose",
             attempt + 1, c->retries);
        if (attempt + 1 >= c->retries) {
            WARN(a, "pose %zu: the display does not follow the robot; nothing recorded. Check the display (HOLD?), "
                    "the port (--port %s), the robot's position and --robot/--encoder, then rerun to resume "
                    "(--follow-tol-mm sets the tolerance)\n", i, c->port_path);
            a->not_following = 1;
            return RC_ERR_RANGE;
        }
        a->io->sleep_ms(a->io->ctx, a->port, c->settle_ms);
    }
}

/* Plan, robot, limits and nominal lengths. 0, or 1 with a message. */
/* This run's label of a plan column (the uint8_t rc_sample field at off:
 * outlet or target, labels below max): the one given (*p1 = label + 1), else
 * the plan's only one; the plan's other rows marked in a->other. 0, or -1
 * with the reason said (many: what the labels are, which: how to name one). */
static int run_label(acq *a, int *p1, const rch_data *plan, size_t off, unsigned max, const char *many,
                     const char *which, const char *one)
{
    unsigned char seen[256] = {0};
    unsigned n_lab = 0;
    for (size_t i = 0; i < plan->n; ++i) {
        const unsigned lab = *((const uint8_t *)&plan->s[i] + off);
        n_lab += lab < max && !seen[lab]++;
    }
    if (!*p1 && n_lab == 1)
        *p1 = *((const uint8_t *)&plan->s[0] + off) + 1;
    if (!*p1) {
        WARN(a, "%s plans %u %s: say which one this run %s; nothing was recorded\n", a->c->poses_path, n_lab, many,
             which);
        return -1;
    }
    if (*p1 > (int)max || !seen[*p1 - 1]) {
        WARN(a, "%s has no rows for %s %d; nothing was recorded\n", a->c->poses_path, one, *p1 - 1);
        return -1;
    }
    for (size_t i = 0; i < plan->n; ++i)
        a->other[i] |= *((const uint8_t *)&plan->s[i] + off) != (unsigned)(*p1 - 1);
    return 0;
}

/* The model's outlet number (0: encoder_mm, k: its RC_EFF_OUTLET k) for the
 * data label `label` (through the file's "outlet_labels" when it has them),
 * -1 when the model has no such place. */
static int model_outlet_of(const rch_robot *robot, int label)
{
    const rc_model *m = &robot->model;
    int k = -1;
    if (robot->n_outlet_labels) {
        for (unsigned j = 0; j < robot->n_outlet_labels && k < 0; ++j)
            if (robot->outlet_label[j] == label)
                k = (int)j;
    } else {
        k = label == 0 ? 0 : -1;
        for (unsigned e = 0; e < m->n_effects && k < 0; ++e)
            if (m->effects[e].kind == RC_EFF_OUTLET && m->effects[e].joint == label)
                k = label;
    }
    return k;
}

/* The follow check's model for this run: the place it measures from (outlet
 * 0: the robot file's encoder, else --encoder; outlet N > 0: --encoder when
 * given, else the model's outlet N) and the point the cable is on (the
 * plate's --cable-point, or the model's own plate). 0, or -1 with what is
 * missing and the option that supplies it said: no prediction, no run. */
static int predict_setup(acq *a, rch_robot *robot, const rch_data *plan)
{
    const rch_acq_config *c = a->c;
    rc_model *m = &robot->model;
    const int place = a->outlet_p1 > 0 ? a->outlet_p1 - 1 : 0, k = model_outlet_of(robot, place);
    unsigned model_points = 0;
    for (unsigned e = 0; e < m->n_effects; ++e)
        if (m->effects[e].kind == RC_EFF_CABLE_POINTS)
            model_points = m->effects[e].count / 3u;
    a->pred_outlet = 0;
    if ((place > 0 && c->encoder_given) || (k == 0 && !robot->has_encoder)) {
        memcpy(&m->x[RC_P_ENC], c->encoder_mm, sizeof c->encoder_mm); /* --encoder, or its default at outlet 0 */
    } else if (k == 0) { /* the robot file's own place first (documented) */
        if (c->encoder_given && (m->x[RC_P_ENC] != c->encoder_mm[0] || m->x[RC_P_ENC + 1] != c->encoder_mm[1] ||
                                 m->x[RC_P_ENC + 2] != c->encoder_mm[2]))
            NOTE(a, "--encoder %g,%g,%g not used: %s gives the encoder's place (%g, %g, %g) mm, which the follow "
                    "check predicts from\n", c->encoder_mm[0], c->encoder_mm[1], c->encoder_mm[2], c->robot_path,
                 m->x[RC_P_ENC], m->x[RC_P_ENC + 1], m->x[RC_P_ENC + 2]);
    } else if (k > 0) {
        a->pred_outlet = (uint8_t)k; /* a calibrated model that knows this place */
    } else if (c->encoder_given) {
        memcpy(&m->x[RC_P_ENC], c->encoder_mm, sizeof c->encoder_mm);
    } else if (!c->no_follow_check) {
        WARN(a, "--outlet %d: the follow check needs the place this run measures from to predict the lengths, and "
                "%s has no outlet %d: give its position with --encoder X,Y,Z (mm, base frame; rcal poses prints it "
                "with the plan); nothing was recorded\n", place, c->robot_path, place);
        return -1;
    }
    if (c->n_points > 0) { /* the follow check predicts the length to the point the cable is on */
        if (model_points || rc_model_add_effect(m, RC_EFF_CABLE_POINTS, 0, 3u * c->n_points) != RC_OK) {
            WARN(a, "cannot add %u cable points to %s%s; nothing was recorded\n", c->n_points, c->robot_path,
                 model_points ? " (it has a plate of its own: leave out --cable-point)" : "");
            return -1;
        }
        memcpy(&m->x[m->effects[m->n_effects - 1].first], c->points_mm, 3u * c->n_points * sizeof(double));
        model_points = c->n_points;
    } else if (plan->has_target && !model_points && !c->no_follow_check) {
        WARN(a, "%s puts the cable on points of a tool plate (column target): the follow check predicts the length "
                "to the point the cable is on and needs the plate's points: give --cable-point X,Y,Z once per point "
                "(flange frame, mm, in target order, as rcal poses was given them); nothing was recorded\n",
             c->poses_path);
        return -1;
    }
    if (model_points)
        for (size_t i = 0; i < plan->n; ++i)
            if (!a->other[i] && plan->s[i].target >= model_points) {
                WARN(a, "%s:%u: the cable on point %u, but %s gives %u; nothing was recorded\n", c->poses_path,
                     plan->line[i], (unsigned)plan->s[i].target, c->n_points ? "--cable-point" : c->robot_path,
                     model_points);
                return -1;
            }
    return 0;
}

/* The nominal length of each of this run's plan rows (a->pred_mm; NaN for
 * the rows of other places and points). 0, or -1: a row the model gives no
 * length at (the point at the outlet) stops the run unless the check is off. */
static int predict_lengths(acq *a, const rc_model *m, const rch_data *plan)
{
    for (size_t i = 0; i < plan->n; ++i) {
        rc_sample s = plan->s[i];
        a->pred_mm[i] = NAN;
        if (a->other[i])
            continue;
        s.value = 0.0;
        s.outlet = a->pred_outlet;
        if (rc_meas(&a->pred_mm[i], NULL, m, &s) != RC_OK || !isfinite(a->pred_mm[i])) {
            a->pred_mm[i] = NAN;
            if (!a->c->no_follow_check) {
                WARN(a, "%s:%u: pose %zu: the nominal model gives no cable length there (the cable's point at the "
                        "outlet %g, %g, %g mm?): the follow check cannot predict it; check --encoder and --robot "
                        "(--no-follow-check runs unchecked); nothing was recorded\n", a->c->poses_path, plan->line[i],
                     i, m->x[RC_P_ENC], m->x[RC_P_ENC + 1], m->x[RC_P_ENC + 2]);
                return -1;
            }
        }
    }
    return 0;
}

static int load_inputs(acq *a)
{
    const rch_acq_config *c = a->c;
    rch_data plan;
    rch_robot *robot;
    rch_diag dg;
    char buf[900];
    int rc = 1;
    if (rch_data_load(&plan, c->poses_path, RCH_DATA_NO_LEN, &dg) != 0) {
        WARN(a, "%s\n", rch_diag_str(&dg, buf, sizeof buf));
        return 1;
    }
    robot = calloc(1, sizeof *robot);
    if (!robot || rch_robot_load(robot, c->robot_path, &dg) != 0) {
        WARN(a, "%s\n", robot ? rch_diag_str(&dg, buf, sizeof buf) : "out of memory");
        goto out;
    }
    a->ctrl = robot->ctrl;
    a->n = plan.n;
    a->plan_deg = calloc(plan.n, sizeof *a->plan_deg);
    a->pred_mm = calloc(plan.n, sizeof *a->pred_mm);
    a->done = calloc(plan.n, 1);
    a->other = calloc(plan.n ? plan.n : 1, 1);
    if (!a->plan_deg || !a->pred_mm || !a->done || !a->other) {
        WARN(a, "out of memory\n");
        goto out;
    }
    /* a plan for several places (rcal poses --outlet ...) or on several points of a tool plate (rcal poses
     * --cable-point): this run records the rows of its outlet and its point (--outlet N, --target P, or the
     * plan's only one) */
    a->outlet_p1 = c->outlet_p1;
    a->target_p1 = c->target_p1;
    if (plan.n && plan.has_outlet &&
        run_label(a, &a->outlet_p1, &plan, offsetof(rc_sample, outlet), 256, "places of the encoder (column outlet)",
                  "measures from with --outlet N", "outlet") != 0)
        goto out;
    if (plan.n && plan.has_target &&
        run_label(a, &a->target_p1, &plan, offsetof(rc_sample, target), RC_MAX_TARGETS,
                  "cable points of the tool (column target)", "has the cable on with --target P", "point") != 0)
        goto out;
    if (!plan.has_target && a->target_p1) {
        WARN(a, "--target %d: %s has no target column (plan the points with rcal poses --cable-point); nothing was "
                "recorded\n", a->target_p1 - 1, c->poses_path);
        goto out;
    }
    a->n_mine = 0;
    for (size_t i = 0; i < plan.n; ++i)
        a->n_mine += !a->other[i];
    if (predict_setup(a, robot, &plan) != 0)
        goto out;
    for (size_t i = 0; i < plan.n; ++i) {
        for (int j = 0; j < RC_NJ; ++j) {
            const double q = plan.s[i].q_rad[j];
            if (!(q >= robot->model.q_min_rad[j] - 1e-9 && q <= robot->model.q_max_rad[j] + 1e-9)) {
                WARN(a, "%s:%u: pose %zu: q%d = %.4f deg is outside the joint limits [%.2f, %.2f] deg of %s; "
                        "nothing was recorded\n", c->poses_path, plan.line[i], i, j + 1, q * DEG_PER_RAD,
                     robot->model.q_min_rad[j] * DEG_PER_RAD, robot->model.q_max_rad[j] * DEG_PER_RAD,
                     c->robot_path);
                goto out;
            }
            /* back to the file's degrees, at its 4 decimals */
            a->plan_deg[i][j] = round(q * DEG_PER_RAD * 1e4) / 1e4;
        }
        char why[200]; /* issue 48: a row whose cable would cross the arm or the cell is not run */
        if (c->cell_check && !a->other[i] && rch_cell_row_refused(why, sizeof why, &robot->cell, &robot->model, &plan.s[i],
                                                 a->pred_outlet)) {
            WARN(a, "%s:%u: pose %zu refused, %s (the links and cell of %s); not moved there, nothing was "
                    "recorded: re-plan with rcal poses\n", c->poses_path, plan.line[i], i, why, c->robot_path);
            goto out;
        }
    }
    if (predict_lengths(a, &robot->model, &plan) != 0)
        goto out;
    rc = 0;
out:
    free(robot);
    rch_data_free(&plan);
    return rc;
}

/* Refuse an output that names an input (device and inode). */
static int check_paths(acq *a)
{
    const rch_acq_config *c = a->c;
    const char *const outs[2] = {c->out_path, c->announce_path};
    const char *const outs_name[2] = {"--out", "--announce"};
    const char *const ins[4] = {c->poses_path, c->robot_path, c->announce_path, c->out_path};
    const char *const ins_name[4] = {"--poses", "--robot", "--announce", "--out"};
    for (int o = 0; o < 2; ++o)
        for (int k = 0; k < 4; ++k) {
            if (!outs[o] || !ins[k] || (o == 0 && k == 3) || (o == 1 && k == 2))
                continue; /* an output against itself */
            if (strcmp(outs[o], ins[k]) == 0 || rch_same_file(outs[o], ins[k])) {
                WARN(a, "%s %s is also %s %s: refused (it would be destroyed); choose another file\n", outs_name[o],
                     outs[o], ins_name[k], ins[k]);
                return 1;
            }
        }
    return 0;
}

/* Joints in degrees between the controller's convention and the model's (the robot file's "controller"
 * member, rch_ctrl.h): to_model 1 reads the controller's numbers, 0 writes the model's as the controller's. */
static void ctrl_deg(double out_deg[RC_NJ], const rch_ctrl *c, const double in_deg[RC_NJ], int to_model)
{
    double in[RC_NJ], out[RC_NJ];
    for (unsigned j = 0; j < RC_NJ; ++j)
        in[j] = in_deg[j] / DEG_PER_RAD;
    if (to_model)
        rch_ctrl_to_model(out, c, in);
    else
        rch_ctrl_from_model(out, c, in);
    for (unsigned j = 0; j < RC_NJ; ++j)
        out_deg[j] = out[j] * DEG_PER_RAD;
}

/* Show pose i to the robot side, wait for it. 0, or 1 with a message. */
static int go_to(acq *a, size_t i, double q_deg[RC_NJ], int recheck)
{
    const rch_acq_config *c = a->c;
    PROGRESS(a, "%s %zu/%zu: q =", recheck ? "back to pose" : "pose", i + 1, a->n);
    for (int j = 0; j < RC_NJ; ++j)
        PROGRESS(a, " %.4f", a->plan_deg[i][j]);
    PROGRESS(a, recheck ? " deg (the last recorded pose: its length is read again)\n" : " deg\n");
    if (a->out)
        fflush(a->out);
    if (c->announce_path && announce(c->announce_path, i, a->plan_deg[i]) != 0) {
        WARN(a, "cannot write --announce %s: %s\n", c->announce_path, strerror(errno));
        return 1;
    }
    if (a->linked) { /* the controller goes there and says where it stands */
        double xyz[3];
        int has_xyz;
        rc_status st;
        double plan_ctrl[RC_NJ]; /* the plan as the controller states joints: what its report is checked against */
        if (a->ctrl.identity_joints)
            memcpy(plan_ctrl, a->plan_deg[i], sizeof plan_ctrl);
        else
            ctrl_deg(plan_ctrl, &a->ctrl, a->plan_deg[i], 0);
        tm_mark(a, RCH_ACQTIME_CMD);
        st = rch_link_pose(&a->link, recheck ? "BACK" : "NEXT", i, plan_ctrl, q_deg, xyz, &has_xyz);
        if (st != RC_OK) {
            WARN(a, "pose %zu: the controller link failed (%s); stopped, nothing recorded from it (rerun to resume)\n",
                 i, rc_strerror(st));
            return 1;
        }
        if (!a->ctrl.identity_joints) /* the controller's joints, as it means them, recorded as the model's */
            ctrl_deg(q_deg, &a->ctrl, q_deg, 1);
        tm_mark(a, RCH_ACQTIME_AT);
        rch_link_wait(&a->link, c->settle_ms + c->stable.timeout_ms + 5000ul);
        a->io->sleep_ms(a->io->ctx, a->port, c->settle_ms);
        tm_mark(a, RCH_ACQTIME_SETTLED);
        return 0;
    }
    if (c->confirm && a->io->confirm(a->io->ctx, i) != 0) {
        WARN(a, "end of input; stopped (rerun to resume)\n");
        return 1;
    }
    a->io->sleep_ms(a->io->ctx, a->port, c->settle_ms);
    memcpy(q_deg, a->plan_deg[i], sizeof(double) * RC_NJ); /* default joint source: the plan */
    if (a->io->joints && a->io->joints(a->io->ctx, q_deg, a->plan_deg[i], i) != 0) {
        WARN(a, "pose %zu: the joint-angle source failed; stopped (rerun to resume)\n", i);
        return 1;
    }
    if (a->io->joints && !a->ctrl.identity_joints) /* the controller's numbers, as it means them */
        ctrl_deg(q_deg, &a->ctrl, q_deg, 1);
    return 0;
}

/* The device must read the last recorded pose as it did before pose i's
 * sample counts (after a reconnect, on resuming, for a suspected jump).
 * RC_OK go on (a->ref_len_mm may have moved: on_jump_record), else stop. */
static rc_status recheck(acq *a, size_t i)
{
    const rch_acq_config *c = a->c;
    const double tol = c->verify_tol_mm > 0.0 ? c->verify_tol_mm : c->stable.tol_mm;
    const size_t r = a->ref_pose;
    for (unsigned long attempt = 0; attempt <= c->retries; ++attempt) {
        const char *why = a->verify_why;
        rc_stable_result v;
        double q_deg[RC_NJ], off;
        rc_status st;
        a->res->verifies++;
        if (go_to(a, r, q_deg, 1) != 0)
            return RC_ERR_IO;
        rcd_port_flush(a->port);
        rcd_display_reset(&a->d);
        st = measure(&v, a, r);
        if (st == RC_ERR_INCOMPLETE)
            continue; /* reconnected while re-reading: once more */
        if (st != RC_OK)
            return st;
        off = v.mean_mm - a->ref_len_mm;
        if (fabs(off) <= tol) {
            NOTE(a, "pose %zu re-read %s: L = %.4f mm, recorded %.4f mm (%+.3f mm, within %g mm): the device "
                    "reads as before; going on at pose %zu\n", r, why, v.mean_mm, a->ref_len_mm, off, tol, i);
            a->verify_why = NULL;
            return RC_OK;
        }
        a->res->verify_fails++;
        WARN(a, "pose %zu re-read %s: L = %.4f mm where %.4f mm was recorded: the device now reads %+.3f mm off "
                "(more than %g mm): a slipped or re-hooked cable, an encoder counter that reset, a display "
                "re-zeroed, or another device on the port. The %zu samples up to pose %zu are kept in %s; %s\n",
             r, why, v.mean_mm, a->ref_len_mm, off, tol, a->res->n_before + a->res->n_new + (size_t)a->holding, r,
             c->out_path,
             c->on_jump_record ? "--on-jump record: this jump is recorded past; the run goes on from the length "
                                 "read now (fit with calibrate --jumps, or calibrate's jump check will stop)"
                               : "nothing more is recorded. Check the cable hook and the display, then rerun the "
                                 "same command to resume (it re-reads this pose first); if the offset is real and "
                                 "should stay, rerun with --on-jump record (and fit with calibrate --jumps) or "
                                 "start a new file");
        if (!c->on_jump_record)
            return RC_ERR_RANGE;
        if (a->res->n_jumps < sizeof a->res->jumps / sizeof a->res->jumps[0]) {
            a->res->jumps[a->res->n_jumps].pose = i;
            a->res->jumps[a->res->n_jumps].jump_mm = off;
        }
        a->res->n_jumps++;
        a->ref_len_mm = v.mean_mm; /* the new offset: what follows is checked against it */
        a->verify_why = NULL;
        return RC_OK;
    }
    WARN(a, "pose %zu: the device kept disconnecting while pose %zu was re-read\n", i, r);
    return RC_ERR_IO;
}

/* Append pose i's sample, taken at wall-clock t_ms, to the file. 0, or 1
 * with the message. */
static int append(acq *a, size_t i, const double q_deg[RC_NJ], const rc_stable_result *r, long long t_ms)
{
    rch_diag dg;
    char buf[900];
    if (rch_acqfile_append_plan(&a->file, i, q_deg, a->plan_deg[i], r, t_ms, &dg) != 0) {
        WARN(a, "%s\n", rch_diag_str(&dg, buf, sizeof buf));
        return 1;
    }
    a->res->n_new++;
    a->done[i] = 1; /* a controller's later report of it is a DUPLICATE */
    return 0;
}

/* The run stops with pose `held`'s sample held (the first of this place and
 * point, not yet followed by a move). Refused by the follow check at the
 * next pose: the display may have been frozen all along, it is dropped.
 * Stopped for anything else (a reconnect to a device that reads otherwise,
 * a timeout, the robot side): it is written as the first sample always was,
 * unchecked, so that a rerun re-reads it before going on. 0, or 1. */
static int stop_held(acq *a, size_t held, const double q_deg[RC_NJ], const rc_stable_result *r, long long t_ms)
{
    if (a->not_following) {
        WARN(a, "pose %zu's sample (L = %.4f mm), the first from this %s, is not recorded either: no move after it "
                "followed, so it cannot be told from a frozen display\n", held, r->mean_mm,
             a->target_p1 ? "place and point" : "place");
        return 0;
    }
    WARN(a, "pose %zu's sample (L = %.4f mm), the first from this %s, is recorded unchecked (the run stopped before a "
            "move could confirm it); a rerun reads it again first\n", held, r->mean_mm,
         a->target_p1 ? "place and point" : "place");
    return append(a, held, q_deg, r, t_ms);
}

static int run_poses(acq *a)
{
    const rch_acq_config *c = a->c;
    /* the first sample of this place and point in the file: nothing to compare it with, so it is held until the
     * next pose's sample follows it (a display frozen from the start is never recorded) */
    int held = 0;
    size_t held_pose = 0;
    double held_q[RC_NJ];
    long long held_t = 0;
    rc_stable_result held_r;
    memset(&held_r, 0, sizeof held_r);
    for (size_t i = 0; i < a->n; ++i) {
        rc_stable_result r;
        double q_deg[RC_NJ];
        rc_status st = RC_ERR_INCOMPLETE;
        if (a->done[i] || a->other[i])
            continue;
        for (unsigned long round = 0; st == RC_ERR_INCOMPLETE; ++round) {
            if (a->verify_why && a->has_ref && (st = recheck(a, i)) != RC_OK)
                break;
            if (round > 2 * c->retries + 2) {
                WARN(a, "pose %zu: the device keeps disconnecting or jumping\n", i);
                st = RC_ERR_IO;
                break;
            }
            if (go_to(a, i, q_deg, 0) != 0) {
                if (held)
                    (void)stop_held(a, held_pose, held_q, &held_r, held_t);
                return 1;
            }
            st = measure_checked(&r, a, i);
        }
        if (st != RC_OK) {
            a->res->stopped = 1;
            a->res->stopped_at = i;
            if (held) {
                if (stop_held(a, held_pose, held_q, &held_r, held_t) != 0)
                    return 1;
                if (a->not_following)
                    a->res->stopped_at = held_pose;
            }
            WARN(a, "stopped at pose %zu; %zu of %zu poses recorded in %s; rerun the same command to resume\n",
                 a->res->stopped_at, a->res->n_before + a->res->n_new, a->n_mine, c->out_path);
            return 1;
        }
        if (!a->has_ref && !c->no_follow_check) { /* held, not written */
            held = 1;
            held_pose = i;
            held_r = r;
            held_t = a->io->wall_ms(a->io->ctx); /* when it was taken, not when it is written */
            memcpy(held_q, q_deg, sizeof held_q);
            a->holding = 1;
            PROGRESS(a, "  L = %.4f mm (spread %.4f mm over %u readings; recorded once the next pose follows it)\n",
                     r.mean_mm, r.spread_mm, r.count);
        } else {
            if (held && append(a, held_pose, held_q, &held_r, held_t) != 0)
                return 1;
            held = a->holding = 0;
            if (append(a, i, q_deg, &r, a->io->wall_ms(a->io->ctx)) != 0)
                return 1;
            PROGRESS(a, "  L = %.4f mm (spread %.4f mm over %u readings)\n", r.mean_mm, r.spread_mm, r.count);
        }
        tm_mark(a, RCH_ACQTIME_KEPT);
        a->has_ref = 1;
        a->ref_pose = i;
        a->ref_len_mm = r.mean_mm;
        if (a->out)
            fflush(a->out);
    }
    if (held) { /* the run's only pose: nothing could follow it */
        WARN(a, "pose %zu: recorded WITHOUT the follow check: it is the only pose this run measures (a frozen "
                "display could not be told from a good one; check its length)\n", held_pose);
        if (append(a, held_pose, held_q, &held_r, held_t) != 0)
            return 1;
    }
    return 0;
}

int rch_acquire_run(rch_acq_result *res, const rch_acq_config *c, const rch_acq_io *io, FILE *out, FILE *err)
{
    static const rch_acq_io sys_ops = {sys_open, sys_close, sys_sleep, sys_wall, sys_confirm, NULL, NULL};
    sys_io sys;
    rch_acq_io real;
    acq a;
    rch_acqfile_state fst;
    rch_diag dg;
    char buf[900];
    rc_stable chk;
    rc_status st;
    int rc = 1, file_open = 0, port_open = 0;

    memset(res, 0, sizeof *res);
    memset(&a, 0, sizeof a);
    a.c = c;
    a.out = out;
    a.err = err;
    a.res = res;
    a.file.fd = -1;
    if (!c->port_path || !c->poses_path || !c->out_path || !c->robot_path || c->read_timeout_ms < 1 ||
        c->read_timeout_ms > 3600000ul || c->retries < 1 || rc_stable_init(&chk, &c->stable) != RC_OK ||
        !(c->follow_tol_mm > 0.0) || !(c->jump_mm > 0.0) || !(c->verify_tol_mm >= 0.0) ||
        rc_stable_init(&a.st, &c->stable) != RC_OK || rcd_display_init(&a.d, &(rcd_port){&rcd_mock_ops, NULL}, &c->proto) != RC_OK) {
        WARN(&a, "invalid settings\n");
        return 2;
    }
    if (!io) {
        memset(&sys, 0, sizeof sys);
        sys.backend = c->backend ? c->backend : "serialport";
        real = sys_ops;
        real.ctx = &sys;
        io = &real;
    }
    a.io = io;
    if (check_paths(&a) != 0 || load_inputs(&a) != 0)
        goto out;
    res->n_poses = a.n_mine;
    if (c->controller && c->confirm) {
        WARN(&a, "--controller and --confirm: the controller says when the robot is there; choose one\n");
        goto out;
    }
    if (rch_acqfile_open_plan(&a.file, &fst, a.done, c->out_path, (const double(*)[RC_NJ])a.plan_deg, a.n,
                              a.outlet_p1, a.target_p1, c->controller != NULL, &dg) != 0) {
        WARN(&a, "%s\n", rch_diag_str(&dg, buf, sizeof buf));
        goto out;
    }
    file_open = 1;
    for (size_t i = 0; i < a.n; ++i)
        if (a.done[i] && a.other[i]) {
            WARN(&a, "%s: pose %zu was recorded from outlet %d%s, but the plan %s gives it to another outlet or "
                     "point: the file belongs to another plan (nothing was changed)\n",
                 c->out_path, i, a.outlet_p1 - 1, a.target_p1 ? " on this point" : "", c->poses_path);
            goto out;
        }
    res->n_before = fst.n_done;
    res->dropped_bytes = fst.dropped_bytes;
    if (fst.dropped_bytes)
        WARN(&a, "%s: unfinished last line (%zu bytes, an interrupted write) dropped; it is kept in %s.dropped\n",
             c->out_path, fst.dropped_bytes, c->out_path);
    a.has_ref = fst.has_last;
    a.ref_pose = fst.last_pose;
    a.ref_len_mm = fst.last_len_mm;
    if (a.has_ref)
        a.verify_why = "on resuming"; /* the device may have been re-hooked or reset since */
    if (fst.n_done == a.n_mine) {
        SAY(&a, "rcal acquire: %s already holds all %zu poses; nothing to do\n", c->out_path, a.n_mine);
        rc = 0;
        goto out;
    }
    if (fst.n_done)
        SAY(&a, "rcal acquire: resuming: %zu of %zu poses already in %s\n", fst.n_done, a.n_mine, c->out_path);
    st = io->open(io->ctx, &a.port, c->port_path, &c->ser);
    if (st != RC_OK) {
        WARN(&a, "cannot open %s (%s backend): %s: %s\n", c->port_path, c->backend ? c->backend : "given",
             rc_strerror(st), rcd_port_last_error(a.port));
        if (c->backend && strcmp(c->backend, "serialport") == 0 && strncmp(c->port_path, "/dev/pts/", 9) == 0)
            WARN(&a, "libserialport refuses pseudo-terminals: use --backend posix\n");
        goto out;
    }
    port_open = 1;
    rcd_display_init(&a.d, a.port, &c->proto);
    if (c->controller) {
        rch_link_config lc;
        memset(&lc, 0, sizeof lc);
        lc.spec = c->controller;
        lc.tol_deg = c->controller_tol_deg;
        lc.wait_ms = c->controller_wait_s * 1000ul;
        lc.link_timeout_ms = c->link_timeout_s * 1000ul;
        lc.move_timeout_ms = c->move_timeout_s * 1000ul;
        lc.hb_ms = 1000;
        lc.retries = c->retries;
        lc.n_poses = a.n;
        lc.outlet = a.outlet_p1 - 1;
        lc.point = a.target_p1 - 1;
        if (rch_acqtime_init(&a.tm, a.n_mine, (double)c->settle_ms) != 0) {
            WARN(&a, "out of memory\n");
            goto out;
        }
        if (rch_link_open(&a.link, &lc, err) != RC_OK)
            goto out;
        a.link.done = a.done;
        a.linked = 1;
        res->link_port = a.link.port;
        if (out)
            fflush(out);
        if (err)
            fflush(err);
    }
    rc = run_poses(&a);
    if (a.linked) {
        tm_mark(&a, RCH_ACQTIME_CMD); /* STOP: the last pose's own time ends here */
        rch_link_stop(&a.link, rc == 0 ? "done" : "stopped");
        if (rch_acqtime_stats_of(&res->timing, &a.tm) != 0)
            WARN(&a, "out of memory: no timing\n");
        memcpy(res->link_faults, a.link.faults, sizeof res->link_faults);
        res->link_connects = a.link.connects;
        rch_link_close(&a.link);
        a.linked = 0;
    }
    res->tau_ms = rc_stable_tau_ms(&a.st);
    res->readings = a.d.stats.readings;
    res->bad_frames = a.d.stats.bad_frames;
    res->shape_rejects = a.d.stats.shape_rejects;
out:
    if (file_open && rch_acqfile_close(&a.file, &dg) != 0) {
        WARN(&a, "%s\n", rch_diag_str(&dg, buf, sizeof buf));
        rc = 1;
    }
    if (port_open)
        io->close(io->ctx);
    free(a.plan_deg);
    free(a.pred_mm);
    free(a.done);
    free(a.other);
    rch_acqtime_free(&a.tm);
    return rc;
}
