/* SPDX-License-Identifier: MIT */
/* cmd_acquire.c - rcal acquire: record cable lengths from the encoder display.
 *
 * Parses the options and runs rch_acquire_run (tools/host/studies/rch_acquire.h: the
 * state machine, the follow check; lib/rc_stable.h: the stability rule;
 * tools/host/files/rch_acqfile.h: the locked, append-only, resumable file).
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "rcal_cmds.h"
#include "rch_paths.h" /* RCAL_DEFAULT_ROBOT */
#include "rch_acqfile.h"
#include "rch_acquire.h"
#include "rch_calib_cfg.h"
#include "rch_jw.h"
#include "rch_opt.h"

static const char summary[] = "record cable lengths from the encoder display, pose by pose";
static const char details[] =
    "For each pose of POSES.csv (q1..q6 in degrees): show it, write 'INDEX q1..q6' to --announce FILE (for a\n"
    "robot-side program; the simulated display follows it), wait --settle-ms or, with --confirm, for Enter; then\n"
    "read until --samples-per-pose N consecutive readings lie within --stable-mm TOL of each other and record\n"
    "their mean as L (mm). Each sample is appended to DATA.csv and fsync'ed at once, under an exclusive lock;\n"
    "rerunning the same command resumes at the first missing pose. Columns: " RCH_ACQ_HEADER "\n"
    "(t_unix_ms: wall clock).\n"
    "Follow check: from the last recorded pose to this one the length must change by what the nominal --robot\n"
    "model (cable outlet: the file's encoder_mm, else --encoder) predicts, within --follow-tol-mm; a frozen\n"
    "display or another device fails it: the pose is measured again up to --retries times, then the run stops\n"
    "and nothing is recorded. It holds at every place and point: --outlet N other than 0 predicts from\n"
    "--encoder (that place's position) or a MODEL with outlet N, --target P to --cable-point P; where no\n"
    "prediction can be made the run stops before recording, naming the option (--no-follow-check: unchecked).\n"
    "The first sample of a place and point is written once the next pose's sample follows it.\n"
    "Plan poses must be inside the robot's joint limits.\n"
    "Jump check: a change more than --jump-mm (3) from the model's, and every reconnect and resume, send the run\n"
    "back to the last recorded pose (announced; with --confirm you are asked to return there) to read it again:\n"
    "within --verify-tol-mm (default --stable-mm) the run goes on; off (a slipped cable, a counter reset) it\n"
    "stops with nothing recorded after that pose, or with --on-jump record reports the jump and goes on.\n"
    "Trend: a window whose slope says the display still creeps (a filter of time constant --display-tau-ms, or\n"
    "the one learnt from the readings) is not a sample.\n"
    "Backend: serialport (real adapters, 9600 8N1 unless told) or posix (ptys of rcal_simdisplay).\n"
    "Retry policy: a reading waits --read-timeout-ms; after --retries failures in a row the port is closed and\n"
    "reopened; a disconnect is retried for --reconnect-s seconds; a pose that does not settle within\n"
    "--pose-timeout-s stops the run. Polled protocols ask at most every --poll-interval-ms: set it to the\n"
    "display's update period or more, so that N readings are N fresh measurements. Exit 0 done, 1 stopped\n"
    "(rerun to resume), 2 usage.\n"
    "Controller link: with --controller tcp:[HOST:]PORT rcal listens (127.0.0.1 unless HOST is given) and the\n"
    "robot program connects and speaks rcal-link/1 (docs/controller-link.md): rcal sends NEXT J / BACK J, the\n"
    "controller answers AT J with its joints; a report off the plan by more than --controller-tol-deg, out of\n"
    "order, duplicated or garbled, and a second controller, are named faults and nothing is recorded from them;\n"
    "a lost link is waited for --controller-wait-s and resumes at the pose in force. The file then records the\n"
    "controller's joints (6 decimals) and the plan's in q1_plan..q6_plan.";

static int pick(const char *v, const char *choices)
{
    int k = 0;
    size_t n = strlen(v);
    for (const char *p = choices; *p; ++k) {
        const char *e = strchr(p, '|');
        size_t len = e ? (size_t)(e - p) : strlen(p);
        if (len == n && strncmp(p, v, n) == 0)
            return k;
        p += len + (e ? 1 : 0);
    }
    return 0; /* rch_opt checked the choice */
}

/* "\r" and "\n" in --poll-cmd become CR and LF. 0, or -1 (nothing cut,
 * the caller refuses) when the command does not fit in cap - 1 bytes. */
static int unescape(char *dst, size_t cap, const char *src)
{
    size_t k = 0;
    for (const char *p = src; *p; ++p) {
        if (k + 1 >= cap)
            return -1;
        if (p[0] == '\\' && (p[1] == 'r' || p[1] == 'n')) {
            dst[k++] = p[1] == 'r' ? '\r' : '\n';
            ++p;
        } else {
            dst[k++] = *p;
        }
    }
    dst[k] = '\0';
    return 0;
}

/* rcal's own time per pose over the link (rch_acqtime.h): the "timing" object of the controller's. */
static void json_timing(rch_jw *w, const rch_acqtime_stats *t, const rch_acq_config *c)
{
    rch_jw_obj(w, "timing");
    rch_jw_uint(w, "poses", t->n);
    rch_jw_uint(w, "settle_ms", c->settle_ms);
    rch_jw_numf(w, "own_ms_median", t->own_ms_median, "%.3f");
    rch_jw_numf(w, "own_ms_p95", t->own_ms_p95, "%.3f");
    rch_jw_numf(w, "own_ms_max", t->own_ms_max, "%.3f");
    rch_jw_numf(w, "display_ms_median", t->display_ms_median, "%.3f");
    rch_jw_numf(w, "display_ms_max", t->display_ms_max, "%.3f");
    rch_jw_numf(w, "move_ms_median", t->move_ms_median, "%.3f");
    rch_jw_numf(w, "move_ms_max", t->move_ms_max, "%.3f");
    rch_jw_numf(w, "cpu_ms_median", t->cpu_ms_median, "%.3f");
    rch_jw_numf(w, "cpu_ms_max", t->cpu_ms_max, "%.3f");
    rch_jw_end(w);
}

/* The run summary as one JSON object on stdout (rcal-acquire/1), also when
 * the run stopped (exit says how it ended). */
static int report_json(const rch_acq_result *r, const rch_acq_config *c, const char *proto, int rc, int argc,
                       char **argv)
{
    const char *const files[] = {"out", c->out_path, "poses_file", c->poses_path, "port", c->port_path,
                                 "protocol", proto, NULL};
    rch_jw w;
    rch_jw_begin(&w, stdout, 0, "rcal-acquire/1", argc, argv);
    rch_jw_strs(&w, files);
    rch_jw_int(&w, "exit", rc);
    rch_jw_bool(&w, "complete", rc == 0 && r->n_new + r->n_before == r->n_poses);
    rch_jw_bool(&w, "stopped", r->stopped);
    if (r->stopped)
        rch_jw_uint(&w, "stopped_at_pose", r->stopped_at);
    else
        rch_jw_null(&w, "stopped_at_pose");
    rch_jw_uint(&w, "poses_in_plan", r->n_poses);
    rch_jw_uint(&w, "samples_before", r->n_before);
    rch_jw_uint(&w, "samples_written", r->n_new);
    rch_jw_uint(&w, "dropped_bytes", r->dropped_bytes);
    rch_jw_obj(&w, "stability");
    rch_jw_uint(&w, "samples_per_pose", c->stable.n);
    rch_jw_num(&w, "stable_mm", c->stable.tol_mm);
    rch_jw_num(&w, "min_mm", c->stable.min_mm);
    rch_jw_num(&w, "max_mm", c->stable.max_mm);
    rch_jw_uint(&w, "unstable_restarts", r->unstable);
    rch_jw_uint(&w, "trend_rejects", r->trend_rejects);
    rch_jw_num(&w, "display_tau_ms", r->tau_ms);
    rch_jw_end(&w);
    rch_jw_obj(&w, "rejected");
    rch_jw_uint(&w, "timeouts", r->timeouts);
    rch_jw_uint(&w, "bad_frames", r->bad_frames);
    rch_jw_uint(&w, "format_rejects", r->shape_rejects);
    rch_jw_uint(&w, "device_errors", r->device);
    rch_jw_uint(&w, "out_of_range", r->range);
    rch_jw_uint(&w, "follow_refusals", r->follow_refusals);
    rch_jw_end(&w);
    rch_jw_uint(&w, "readings", r->readings);
    rch_jw_uint(&w, "reconnects", r->reconnects);
    rch_jw_bool(&w, "follow_check", !c->no_follow_check);
    rch_jw_num(&w, "worst_follow_mm", r->n_new ? r->worst_follow_mm : NAN);
    rch_jw_uint(&w, "rechecks", r->verifies);
    if (c->controller) {
        rch_jw_obj(&w, "controller");
        rch_jw_str(&w, "link", c->controller);
        rch_jw_uint(&w, "port", r->link_port);
        rch_jw_uint(&w, "connections", r->link_connects);
        rch_jw_obj(&w, "faults");
        for (int k = 0; k < RCH_LINK_NFAULTS; ++k)
            rch_jw_uint(&w, rch_link_fault_name(k), r->link_faults[k]);
        rch_jw_end(&w);
        json_timing(&w, &r->timing, c);
        rch_jw_end(&w);
    }
    rch_jw_uint(&w, "recheck_failures", r->verify_fails);
    rch_jw_arr(&w, "jumps");
    for (size_t k = 0; k < r->n_jumps && k < sizeof r->jumps / sizeof r->jumps[0]; ++k) {
        rch_jw_obj(&w, NULL);
        rch_jw_uint(&w, "before_pose", r->jumps[k].pose);
        rch_jw_num(&w, "jump_mm", r->jumps[k].jump_mm);
        rch_jw_end(&w);
    }
    rch_jw_end(&w);
    rch_jw_end(&w);
    return rch_jw_finish(&w);
}

/* --controller: the link's connections and its faults by name. */
static void report_link(const rch_acq_result *r, const rch_acq_config *c, FILE *f)
{
    if (!c->controller)
        return;
    fprintf(f, "rcal acquire: controller link %s: %lu connection%s; faults:", c->controller, r->link_connects,
            r->link_connects == 1 ? "" : "s");
    for (int k = 0; k < RCH_LINK_NFAULTS; ++k)
        fprintf(f, " %s %lu", rch_link_fault_name(k), r->link_faults[k]);
    fprintf(f, "\n");
    if (r->timing.n)
        fprintf(f, "rcal acquire: rcal's own time per pose (AT to the next command, less --settle-ms %lu and the "
                   "display's stability window, median %.1f ms): median %.2f ms, 95 %% %.2f ms, max %.2f ms over %zu "
                   "poses; CPU %.2f ms median, %.2f ms max\n",
                c->settle_ms, r->timing.display_ms_median, r->timing.own_ms_median, r->timing.own_ms_p95,
                r->timing.own_ms_max, r->timing.n, r->timing.cpu_ms_median, r->timing.cpu_ms_max);
}

/* The one-line summary of a complete run. */
static void report_text(const rch_acq_result *r, const rch_acq_config *c)
{
    printf("rcal acquire: %zu poses recorded (%zu new) in %s; %lu readings, %lu timeouts, %lu bad frames, "
           "%lu format rejects, %lu device errors, %lu out of range, %lu unstable restarts, %lu reconnects, "
           "%lu follow refusals (worst miss %.2f mm), %lu trend rejects (display tau %.1f s), %lu rechecks\n",
           r->n_before + r->n_new, r->n_new, c->out_path, r->readings, r->timeouts, r->bad_frames, r->shape_rejects,
           r->device, r->range, r->unstable, r->reconnects, r->follow_refusals, r->worst_follow_mm, r->trend_rejects,
           r->tau_ms / 1000.0, r->verifies);
    report_link(r, c, stdout);
    for (size_t k = 0; k < r->n_jumps && k < sizeof r->jumps / sizeof r->jumps[0]; ++k)
        printf("rcal acquire: JUMP of %+.3f mm before pose %zu recorded past (--on-jump record): fit with calibrate "
               "--jumps\n", r->jumps[k].jump_mm, r->jumps[k].pose);
}

/* The options of rcal acquire: the run's configuration and the values
 * turned into it. */
typedef struct acquire_args {
    rch_acq_config c;
    const char *proto, *parity, *flow, *mbf, *mbo, *poll, *joints, *on_jump;
    rch_opt_strs cable_points;
    unsigned long baud, bits, stop, mb_addr, mb_reg, mb_dec, n, pose_s, outlet, tau_ms, target;
    int json, no_learn;
} acquire_args;

/* The parsed options into a->c (outlet_given: --outlet was given, and so
 * on). -1, or 2 (reported). */
static int to_config(acquire_args *a, int outlet_given, int target_given, int encoder_given)
{
    a->c.encoder_given = encoder_given;
    a->c.outlet_p1 = outlet_given ? (int)a->outlet + 1 : 0;
    a->c.target_p1 = target_given ? (int)a->target + 1 : 0;
    if (a->cable_points.n) { /* the calibrate option's one parser */
        char perr[160];
        if (rch_cable_points_parse(a->c.points_mm, &a->c.n_points, a->cable_points.v, a->cable_points.n, perr,
                                   sizeof perr) != 0) {
            fprintf(stderr, "rcal acquire: %s\n", perr);
            return 2;
        }
    }
    if (!(a->c.stable.min_mm < a->c.stable.max_mm)) {
        fprintf(stderr, "rcal acquire: need --min-mm < --max-mm\n");
        return 2;
    }
    a->c.proto.protocol = (rcd_protocol)pick(a->proto, "ascii|ascii-poll|stx|modbus");
    a->c.ser.baud = (unsigned)a->baud;
    a->c.ser.data_bits = (unsigned)a->bits;
    a->c.ser.stop_bits = (unsigned)a->stop;
    a->c.ser.parity = (rcd_parity)pick(a->parity, "none|odd|even|mark|space");
    a->c.ser.flow = (rcd_flow)pick(a->flow, "none|xonxoff|rtscts|dtrdsr");
    if (a->poll && unescape(a->c.proto.poll_cmd, sizeof a->c.proto.poll_cmd, a->poll) != 0) {
        fprintf(stderr, "rcal acquire: --poll-cmd '%s' is longer than the %zu bytes a poll command may have (\\r and "
                        "\\n count one each): refused, not cut\n",
                a->poll, sizeof a->c.proto.poll_cmd - 1);
        return 2;
    }
    a->c.proto.mb_addr = (uint8_t)a->mb_addr;
    a->c.proto.mb_reg = (uint16_t)a->mb_reg;
    a->c.proto.mb_decimals = (uint8_t)a->mb_dec;
    a->c.proto.mb_format = (rcd_mb_format)pick(a->mbf, "int32|float");
    a->c.proto.mb_order = (rcd_word_order)pick(a->mbo, "abcd|cdab|badc|dcba");
    a->c.stable.n = (unsigned)a->n;
    a->c.stable.timeout_ms = (uint32_t)(a->pose_s * 1000ul);
    a->c.stable.tau_ms = (uint32_t)a->tau_ms;
    a->c.stable.learn_tau = !a->no_learn;
    a->c.on_jump_record = strcmp(a->on_jump, "record") == 0;
    return -1;
}

/* The options into a: -1 when the command should run, else its exit status
 * (0 for --help, 2 for an error, reported). */
static int parse(acquire_args *a, int argc, char **argv)
{
    rch_cmdspec spec;
    unsigned long long seen = 0;
    memset(a, 0, sizeof *a);
    a->parity = "none";
    a->flow = "none";
    a->mbf = "int32";
    a->mbo = "abcd";
    a->joints = "plan";
    a->on_jump = "stop";
    a->baud = 9600;
    a->bits = 8;
    a->stop = 1;
    a->mb_addr = 1;
    a->n = 5;
    a->pose_s = 60;
    rch_acq_config_default(&a->c);
    a->c.robot_path = RCAL_DEFAULT_ROBOT;
    int no_cell_check = 0;
    const rch_opt opts[] = {
        {"--port", RCH_OPT_STR, &a->c.port_path, 0, 0, "PATH", "serial device", RCH_OPT_REQUIRED, NULL},
        {"--protocol", RCH_OPT_CHOICE, &a->proto, 0, 0, NULL, "display protocol", RCH_OPT_REQUIRED, "ascii|ascii-poll|stx|modbus"},
        {"--poses", RCH_OPT_STR, &a->c.poses_path, 0, 0, "POSES.csv", "pose plan (rcal poses)", RCH_OPT_REQUIRED, NULL},
        {"--out", RCH_OPT_STR, &a->c.out_path, 0, 0, "DATA.csv", "acquisition file (appended)", RCH_OPT_REQUIRED, NULL},
        {"--outlet", RCH_OPT_UINT, &a->outlet, 0, 255, "N",
         "the encoder place this run measures from (a label 0..255, written as the file's outlet column): "
         "the same plan run again from another place appends to the same file; a plan with an outlet "
         "column (rcal poses --outlet ...) has its rows of outlet N recorded; N other than 0 needs --encoder, "
         "this place's position, for the follow check (or a MODEL with outlet N)", 0, NULL},
        {"--robot", RCH_OPT_STR, &a->c.robot_path, 0, 0, "MODEL.json", "nominal model: limits, follow check", 0, NULL},
        {"--cable-point", RCH_OPT_STRS, &a->cable_points, 0, 0, "X,Y,Z",
         "with --target: the plate's points (nominal, flange frame, mm; once each, in target order) the follow check "
         "predicts the lengths to; a plan with a target column needs them", 0, NULL},
        {"--target", RCH_OPT_UINT, &a->target, 0, RC_MAX_TARGETS - 1, "P",
         "the point of the tool plate the cable is on in this run (the plan's target column, rcal poses "
         "--cable-point): its rows are recorded, the file's target column says P; run again on each point", 0, NULL},
        {"--encoder", RCH_OPT_TRIPLE, a->c.encoder_mm, -1e5, 1e5, "X,Y,Z",
         "cable outlet (mm) if MODEL has none; with --outlet N > 0 that place's position", 0, NULL},
        {"--backend", RCH_OPT_CHOICE, &a->c.backend, 0, 0, NULL, "port backend", 0, "serialport|posix"},
        {"--baud", RCH_OPT_UINT, &a->baud, 50, 4000000, NULL, "bits per second", 0, NULL},
        {"--data-bits", RCH_OPT_UINT, &a->bits, 5, 8, NULL, NULL, 0, NULL},
        {"--parity", RCH_OPT_CHOICE, &a->parity, 0, 0, NULL, NULL, 0, "none|odd|even|mark|space"},
        {"--stop-bits", RCH_OPT_UINT, &a->stop, 1, 2, NULL, NULL, 0, NULL},
        {"--flow", RCH_OPT_CHOICE, &a->flow, 0, 0, NULL, "flow control", 0, "none|xonxoff|rtscts|dtrdsr"},
        {"--poll-cmd", RCH_OPT_STR, &a->poll, 0, 0, "TEXT", "poll command (\\r, \\n allowed; default R\\r)", 0, NULL},
        {"--mb-addr", RCH_OPT_UINT, &a->mb_addr, 1, 247, NULL, "Modbus slave address", 0, NULL},
        {"--mb-reg", RCH_OPT_UINT, &a->mb_reg, 0, 65535, NULL, "first holding register", 0, NULL},
        {"--mb-format", RCH_OPT_CHOICE, &a->mbf, 0, 0, NULL, NULL, 0, "int32|float"},
        {"--mb-order", RCH_OPT_CHOICE, &a->mbo, 0, 0, NULL, "word order", 0, "abcd|cdab|badc|dcba"},
        {"--mb-decimals", RCH_OPT_UINT, &a->mb_dec, 0, 9, NULL, "int32 scale 10^-D mm", 0, NULL},
        {"--samples-per-pose", RCH_OPT_UINT, &a->n, 1, RC_STABLE_MAX_N, "N", "consecutive readings per sample", 0, NULL},
        {"--stable-mm", RCH_OPT_DOUBLE, &a->c.stable.tol_mm, 0, 1000, "TOL", "max - min of the N readings", 0, NULL},
        {"--min-mm", RCH_OPT_DOUBLE, &a->c.stable.min_mm, 0, 1e6, NULL, "smallest plausible reading", 0, NULL},
        {"--max-mm", RCH_OPT_DOUBLE, &a->c.stable.max_mm, 0, 1e6, NULL, "largest plausible reading", 0, NULL},
        {"--settle-ms", RCH_OPT_UINT, &a->c.settle_ms, 0, 86400000, NULL, "wait after each move", 0, NULL},
        {"--read-timeout-ms", RCH_OPT_UINT, &a->c.read_timeout_ms, 1, 3600000, NULL, NULL, 0, NULL},
        {"--retries", RCH_OPT_UINT, &a->c.retries, 1, 1000, "R", NULL, 0, NULL},
        {"--pose-timeout-s", RCH_OPT_UINT, &a->pose_s, 1, 86400, NULL, NULL, 0, NULL},
        {"--reconnect-s", RCH_OPT_UINT, &a->c.reconnect_s, 0, 3600, NULL, NULL, 0, NULL},
        {"--poll-interval-ms", RCH_OPT_UINT, &a->c.poll_interval_ms, 0, 60000, NULL, NULL, 0, NULL},
        {"--follow-tol-mm", RCH_OPT_DOUBLE, &a->c.follow_tol_mm, 0.001, 1e4, NULL, "follow check tolerance", 0, NULL},
        {"--jump-mm", RCH_OPT_DOUBLE, &a->c.jump_mm, 0.001, 1e4, "MM",
         "a change this far from the model's sends the run back to the last recorded pose", 0, NULL},
        {"--verify-tol-mm", RCH_OPT_DOUBLE, &a->c.verify_tol_mm, 0, 1000, "MM",
         "the last recorded pose read again must agree within this (default --stable-mm)", 0, NULL},
        {"--on-jump", RCH_OPT_CHOICE, &a->on_jump, 0, 0, NULL,
         "a confirmed jump stops the run, or is reported and recorded past", 0, "stop|record"},
        {"--display-tau-ms", RCH_OPT_UINT, &a->tau_ms, 0, 600000, "MS",
         "the display's filter time constant, when known (the trend test)", 0, NULL},
        {"--no-learn-tau", RCH_OPT_FLAG, &a->no_learn, 0, 0, NULL,
         "do not learn the display's time constant from the readings", 0, NULL},
        {"--no-follow-check", RCH_OPT_FLAG, &a->c.no_follow_check, 0, 0, NULL, "skip the follow check", 0, NULL},
        {"--no-cell-check", RCH_OPT_FLAG, &no_cell_check, 0, 0, NULL,
         "run plan rows whose cable would cross a link, a box or the floor of --robot (default: refused)", 0, NULL},
        {"--announce", RCH_OPT_STR, &a->c.announce_path, 0, 0, "FILE", "pose for the robot side", 0, NULL},
        {"--confirm", RCH_OPT_FLAG, &a->c.confirm, 0, 0, NULL, "wait for Enter at each pose", 0, NULL},
        {"--joints", RCH_OPT_CHOICE, &a->joints, 0, 0, NULL, "source of q1..q6", 0, "plan"},
        {"--controller", RCH_OPT_STR, &a->c.controller, 0, 0, "tcp:[HOST:]PORT",
         "listen for the robot controller (docs/controller-link.md; HOST 127.0.0.1 unless given): its reports drive "
         "the run and its joints are recorded, the plan's beside them", 0, NULL},
        {"--controller-tol-deg", RCH_OPT_DOUBLE, &a->c.controller_tol_deg, 1e-6, 10, "DEG",
         "a report farther from the plan than this per joint is the fault OFFSET (0.05)", 0, NULL},
        {"--controller-wait-s", RCH_OPT_UINT, &a->c.controller_wait_s, 1, 86400, "S",
         "a controller connects within this, first and after a loss (60)", 0, NULL},
        {"--link-timeout-s", RCH_OPT_UINT, &a->c.link_timeout_s, 1, 3600, "S", "silence that loses the link (5)", 0,
         NULL},
        {"--move-timeout-s", RCH_OPT_UINT, &a->c.move_timeout_s, 1, 86400, "S",
         "the controller reports the pose within this of NEXT/BACK, else STALLED (60)", 0, NULL},
        {"--quiet", RCH_OPT_FLAG, &a->c.quiet, 0, 0, NULL,
         "no per-pose lines (kept with --confirm) and fewer notes; the closing summary and every warning stay", 0, NULL},
        {"--json", RCH_OPT_FLAG, &a->json, 0, 0, NULL,
         "the run summary as one JSON object on stdout (progress then goes to stderr)", 0, NULL},
    };
    const int st = rch_opt_cmd(&spec, "acquire", summary, details, opts, RCH_OPT_COUNT(opts), argc, argv, &seen);
    if (st >= 0)
        return st;
    a->c.cell_check = !no_cell_check;
    return to_config(a, rch_opt_given(&spec, seen, "--outlet"), rch_opt_given(&spec, seen, "--target"),
                     rch_opt_given(&spec, seen, "--encoder"));
}

int rcal_cmd_acquire(int argc, char **argv)
{
    acquire_args a;
    rch_acq_result r;
    memset(&r, 0, sizeof r);
    const int st = parse(&a, argc, argv);
    if (st >= 0)
        return st;
    const rch_acq_config *c = &a.c;
    const int rc = rch_acquire_run(&r, c, NULL, a.json ? stderr : stdout, stderr);
    if (a.json)
        return report_json(&r, c, a.proto, rc, argc, argv) != 0 && rc == 0 ? 1 : rc;
    if (rc == 0 && r.n_new + r.n_before == r.n_poses && r.n_new)
        report_text(&r, c);
    else
        report_link(&r, c, stderr);
    return rc;
}
