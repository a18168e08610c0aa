/* SPDX-License-Identifier: MIT */
/* rt_egm.h - rcal-rt as an ABB EGM sensor in joint mode (issue 49): the
 * codec of the two messages it speaks (EgmRobot in, EgmSensor out; the
 * schema firmware_host/egm.proto with ABB's field numbers, compiled by
 * protoc-c), the guard that keeps the reference from jumping, and the UDP
 * loop (rt_egm_run.c) with its bench (rt_egm_bench.c). docs/egm.md.
 *
 * The codec and the guard are pure (no I/O, no heap: protobuf-c unpacks
 * into a caller-owned arena) so that the decoder is fuzzed on its own
 * (fuzz/fuzz_egm.c). Prefix rt_egm_. Units: joints in degrees on the wire
 * and in these structs (EGM's unit), radians only at the compensation. */
#ifndef RT_EGM_H
#define RT_EGM_H

#include <stddef.h>
#include <stdint.h>

#include "rc_comp.h"

struct rch_ctrl; /* rch_ctrl.h */

#define RT_EGM_NJ 6
/* largest datagram read; a longer one is malformed (EGM's are ~400 bytes) */
#define RT_EGM_MAX_DGRAM 1400
/* the decoder's arena: protobuf-c's allocations for one datagram of at most
 * RT_EGM_MAX_DGRAM bytes (each repeated double at most 8 bytes per wire byte,
 * each sub-message under 100 bytes) */
#define RT_EGM_ARENA_BYTES 65536

/* EgmHeader.MessageType, EgmMCIState, EgmRapidCtrlExecState, EgmMotorState values (egm.proto) */
enum { RT_EGM_MSG_DATA = 2, RT_EGM_MSG_CORRECTION = 3 };
enum { RT_EGM_MOTORS_ON = 1, RT_EGM_MOTORS_OFF = 2 };
enum { RT_EGM_MCI_ERROR = 1, RT_EGM_MCI_STOPPED = 2, RT_EGM_MCI_RUNNING = 3 };
enum { RT_EGM_RAPID_STOPPED = 1, RT_EGM_RAPID_RUNNING = 2 };

/* What rcal-rt reads of an EgmRobot (-1: the field was absent). */
typedef struct rt_egm_robot {
    uint32_t seqno;                  /* header.seqno (required here) */
    uint32_t tm_ms;                  /* header.tm, 0 when absent */
    int has_tm;
    double fb_deg[RT_EGM_NJ];        /* feedBack.joints (required here: six finite values) */
    int has_planned;                 /* planned.joints present (then six finite values) */
    double planned_deg[RT_EGM_NJ];
    int motor, mci, rapid, conv_met; /* motorState, mciState, rapidExecState, mciConvergenceMet; -1 absent */
} rt_egm_robot;

/* The arena protobuf-c unpacks into (no heap). */
typedef struct rt_egm_arena {
    size_t used;
    unsigned char buf[RT_EGM_ARENA_BYTES];
} rt_egm_arena;

/* Decode one datagram (len bytes) as an EgmRobot. 0, or -1 with why (a
 * sentence naming the field): not a protobuf EgmRobot, longer than
 * RT_EGM_MAX_DGRAM, no header or seqno, mtype other than MSGTYPE_DATA, no
 * feedback joints, a joints list (feedback or planned) that is not six
 * finite numbers. */
int rt_egm_decode(rt_egm_robot *out, char *why, size_t why_len, rt_egm_arena *arena, const uint8_t *buf,
                  size_t len);

/* Encode an EgmSensor: header (seqno, tm_ms, MSGTYPE_CORRECTION) and
 * planned.joints = q_deg (six). Writes at most cap bytes to buf; returns the
 * length, or 0 when cap is too small. */
size_t rt_egm_encode(uint8_t *buf, size_t cap, uint32_t seqno, uint32_t tm_ms, const double q_deg[RT_EGM_NJ]);

/* The reference guard. The reference sent is the target plus a correction
 * c_k; c_k is the compensation's (compensated - target) when it converged,
 * the last one when it did not, and its change per cycle is limited to
 * step_deg per joint, so |sent_k - sent_k-1| <= |target_k - target_k-1| +
 * step_deg for every joint, whatever happens. The first correction is taken
 * as it is (there is no earlier reference). The reference is then kept
 * within the joint limits (a clip never makes a change larger). */
typedef struct rt_egm_guard {
    double step_deg;                 /* the stated limit of the correction's change per cycle */
    double q_min_deg[RT_EGM_NJ], q_max_deg[RT_EGM_NJ]; /* the joint limits every reference is kept within */
    int have;
    double corr_deg[RT_EGM_NJ];      /* the correction of the last reference */
    double sent_deg[RT_EGM_NJ];      /* the last reference */
    unsigned long n_clamped;         /* references whose correction was limited */
} rt_egm_guard;

void rt_egm_guard_init(rt_egm_guard *g, double step_deg, const double q_min_deg[RT_EGM_NJ],
                       const double q_max_deg[RT_EGM_NJ]);
/* The next reference into sent_deg for target_deg: comp_deg its compensation,
 * or NULL when the compensation failed (the last correction is kept).
 * Returns 1 when the correction was limited, else 0. */
int rt_egm_guard_step(rt_egm_guard *g, double sent_deg[RT_EGM_NJ], const double target_deg[RT_EGM_NJ],
                      const double comp_deg[RT_EGM_NJ]);

/* ---- the loop (rt_egm_run.c) ---- */

/* A source of joint targets (radians): 1 a target, 0 none yet (a stream that
 * stalls), -1 the end (or a fatal input error, said on stderr). A row the
 * reader refuses is -2 with the message on stderr (counted, skipped). */
typedef int (*rt_egm_next_fn)(void *ctx, double q_rad[RT_EGM_NJ]);
/* The model file read again into cal and nom (not the tables in use) with
 * its compensation flags; 0, or -1 with the reason in err. */
typedef int (*rt_egm_reload_fn)(void *ctx, rc_kin *cal, rc_kin *nom, unsigned *flags, char *err, size_t err_len);

typedef struct rt_egm_opts {
    const char *bind_addr;           /* default "127.0.0.1" */
    unsigned port;                   /* --egm-port */
    const char *controller;          /* --egm-controller ADDR: the only address answered (default: the first
                                        valid sender, address and port, locked) */
    const char *in_path;             /* --in FILE|FIFO, "-" standard input; NULL: next/next_ctx */
    rt_egm_next_fn next;             /* the target source when in_path is NULL (the bench) */
    void *next_ctx;
    const char *model_path;          /* watched for a replacement (NULL: none) */
    rt_egm_reload_fn reload;
    void *reload_ctx;
    double period_ms;                /* the controller's cycle (EGM: 4 ms); a datagram later than 1.5 periods is late */
    double step_deg;                 /* the guard's limit, default 0.01 deg per cycle */
    double follow_deg;               /* the robot's planned/feedback joints this far from every recent reference:
                                        not following (default 1 deg) */
    double timeout_s;                /* the controller silent this long after its first datagram: the end */
    double wait_s;                   /* no first datagram within this: the end (exit 1) */
    int json;                        /* the summary also as one JSON line on stdout */
    int quiet;                       /* no per-fault log lines (the bench) */
    const char *label;               /* the summary's name ("rcal-rt egm") */
    const struct rch_ctrl *ctrl;     /* the controller's joint convention (the model file's "controller"
                                        member, rch_ctrl.h): --in targets and the robot's joints are the
                                        controller's, compensated in the model's and answered in the
                                        controller's; NULL: the identity */
} rt_egm_opts;

void rt_egm_opts_default(rt_egm_opts *o);

/* Serve EGM on o's port until the controller falls silent (o->timeout_s),
 * SIGINT/SIGTERM, or no first datagram in o->wait_s. cal, nom, cfg: the
 * compensation (the model's tables; replaced by o->reload when the model
 * file changes). Exit status: 0 when the input ended and every row was
 * sent compensated with a robot that followed; 1 otherwise (the counts in
 * the summary on stderr); 2 a setup error (socket, address). */
int rt_egm_run(const rt_egm_opts *o, const rc_kin *cal, const rc_kin *nom, const rc_comp_config *cfg);

/* rcal-rt --egm-bench: rcal-rt's EGM loop and a trivial C responder, side by
 * side, answering a C controller at rate_hz for seconds (docs/egm.md). */
int rt_egm_bench(const rc_kin *cal, const rc_kin *nom, const rc_comp_config *cfg, double rate_hz, double seconds,
                 int fifo, int json);

#endif /* RT_EGM_H */
