/* SPDX-License-Identifier: MIT */
/* rch_link.h - the controller link `rcal-link/1` (docs/controller-link.md).
 *
 * rcal listens on a TCP port (127.0.0.1 by default), one robot controller
 * connects; per pose rcal sends NEXT J / BACK J / AGAIN J and waits for the
 * controller's `AT J OUTLET POINT Q1..Q6 [X Y Z]` (joints in deg at the
 * controller's precision). Heartbeats, the timeouts, reconnects and the named
 * faults (rch_link_fault) are handled inside rch_link_pose: it returns only
 * with an accepted report or a reason to stop. POSIX sockets, non-blocking,
 * poll(2) with bounded waits, no threads. Built into rcal_acquire (with
 * rch_acquire.c), not into the installed host library.
 */
#ifndef RCH_LINK_H
#define RCH_LINK_H

#include <stddef.h>
#include <stdio.h>

#include "rc_model.h"
#include "rc_status.h"

#define RCH_LINK_VERSION "rcal-link/1"
#define RCH_LINK_MAX_LINE 255u

/* The faults of docs/controller-link.md, named on the wire and in the summary. */
typedef enum rch_link_fault {
    RCH_LINK_OFFSET,    /* AT J with a joint beyond the tolerance from the plan */
    RCH_LINK_DUPLICATE, /* AT K for a pose already recorded or being read */
    RCH_LINK_ORDER,     /* AT K for another pose than asked, not yet recorded */
    RCH_LINK_PLACE,     /* AT J with another outlet or plate point than this run's */
    RCH_LINK_UNKNOWN,   /* not a message, or wrong fields */
    RCH_LINK_VERSION_F, /* HELLO of another version, or a message before HELLO */
    RCH_LINK_BUSY,      /* a second controller */
    RCH_LINK_STALLED,   /* no AT within the move timeout */
    RCH_LINK_LOST,      /* connection closed or silent past the link timeout */
    RCH_LINK_NFAULTS
} rch_link_fault;

/* "OFFSET", "DUPLICATE", ... */
const char *rch_link_fault_name(int fault);

typedef struct rch_link_config {
    const char *spec;              /* "tcp:[HOST:]PORT" */
    double tol_deg;                /* > 0: largest |q - q_plan| accepted per joint */
    unsigned long wait_ms;         /* a controller connects within this (first time, after a loss) */
    unsigned long link_timeout_ms; /* nothing received this long: the link is lost */
    unsigned long move_timeout_ms; /* AT J after the command */
    unsigned long hb_ms;           /* heartbeat after this long without sending */
    unsigned long retries;         /* OFFSET / STALLED in a row before stopping, >= 1 */
    size_t n_poses;                /* in the plan (WELCOME) */
    int outlet, point;             /* this run's labels, -1 none */
} rch_link_config;

typedef struct rch_link {
    rch_link_config c;
    char host[64];
    unsigned port;                 /* the port listened on (0 in spec: the one the system chose) */
    int lfd, cfd;                  /* listening and controller sockets, -1 none */
    int hello;                     /* the controller said HELLO */
    char buf[2 * RCH_LINK_MAX_LINE + 2];
    size_t len;
    int skipping;                  /* discarding the rest of a line too long */
    long long last_rx_ms, last_tx_ms;
    const unsigned char *done;     /* (n_poses) 1 recorded, for DUPLICATE; may be NULL */
    long reading;                  /* the pose whose AT was last accepted, -1 none */
    char cmd[32];                  /* the command in force ("NEXT 3") */
    unsigned long faults[RCH_LINK_NFAULTS];
    unsigned long connects;        /* controllers accepted */
    FILE *err;                     /* faults and losses named here (may be NULL) */
} rch_link;

/* Parse "tcp:[HOST:]PORT" (HOST numeric IPv4, default 127.0.0.1; PORT 0..65535). 0, or -1. */
int rch_link_parse(char host[64], unsigned *port, const char *spec);

/* Listen. RC_OK, or an error said on err. */
rc_status rch_link_open(rch_link *l, const rch_link_config *c, FILE *err);

/* Send `CMD J` (cmd "NEXT", "BACK" or "AGAIN") and wait for the controller's accepted `AT J`: its joints
 * (deg) in q_deg, its TCP (mm) in xyz_mm when *has_xyz. Accepts, reconnects, heartbeats and answers faults
 * meanwhile. RC_OK; RC_ERR_TIMEOUT no controller within wait_ms or `retries` stalls; RC_ERR_RANGE `retries`
 * offsets in a row; RC_ERR_IO a socket error. */
rc_status rch_link_pose(rch_link *l, const char *cmd, size_t pose, const double plan_deg[RC_NJ], double q_deg[RC_NJ],
                        double xyz_mm[3], int *has_xyz);

/* `WAIT MS` (stand still, rcal is reading). */
void rch_link_wait(rch_link *l, unsigned long ms);

/* `STOP REASON` to a connected controller. */
void rch_link_stop(rch_link *l, const char *reason);

void rch_link_close(rch_link *l);

#endif
