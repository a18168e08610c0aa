/* SPDX-License-Identifier: MIT */
/* rt_rsi_model.h - the RSI partner's model (rt_rsi_loop.c): set up as rcal
 * compensate sets it up (rch_comp_run), with the controller's joint
 * convention (the robot file's "controller" member, rch_ctrl.h), and the
 * model file watched off the answer path (a thread of normal priority that
 * stat()s and reads the file; the loop takes what it posted with a
 * non-blocking try, docs/rsi.md "Faults"). Prefix rt_rsi_model_ and
 * rt_rsi_watch_. */
#ifndef RT_RSI_MODEL_H
#define RT_RSI_MODEL_H

#include <pthread.h>
#include <stddef.h>
#include <sys/stat.h>

#include "rc_comp.h"
#include "rch_ctrl.h"

typedef struct rt_rsi_model {
    rc_model det, nom_pt;  /* the determined model and the nominal, both at the flange */
    rc_comp_config cfg;
    int position_only;
    rch_ctrl ctrl;         /* the controller's joints (the nominal file's member with --nominal, else the
                              model file's; the identity when absent) */
    int map;               /* ctrl is not the identity: setpoints mapped to the model's joints and back */
} rt_rsi_model;

/* What to load: the paths and the orientation options of rcal compensate. */
typedef struct rt_rsi_model_src {
    const char *model, *nominal;
    int position_only, full_pose;
} rt_rsi_model_src;

/* Load src into m. 0 with note (what is compensated, one line) or -1 with
 * err ("file:line:col: what"). Not thread-safe (static storage): one caller
 * at a time (the start, then the watcher thread only). */
int rt_rsi_model_load(rt_rsi_model *m, char *note, size_t note_len, char *err, size_t err_len,
                      const rt_rsi_model_src *src);

/* Controller joints (degrees) to the model's (radians) and the model's
 * (radians) back to the controller's (degrees). */
void rt_rsi_model_to_model(double q_rad[6], const rt_rsi_model *m, const double ctrl_deg[6]);
void rt_rsi_model_to_ctrl(double ctrl_deg[6], const rt_rsi_model *m, const double q_rad[6]);

enum { RT_RSI_WATCH_NONE = 0, RT_RSI_WATCH_MODEL, RT_RSI_WATCH_REFUSED, RT_RSI_WATCH_REMOVED };

typedef struct rt_rsi_watch {
    pthread_t th;
    pthread_mutex_t mu;
    int started;
    rt_rsi_model_src src;
    double every_s;        /* the file looked at this often */
    struct stat st;        /* the file as last seen (thread only) */
    int have_st;
    /* under mu */
    int stop;
    int posted;            /* RT_RSI_WATCH_*: what waits for the loop */
    unsigned long changes; /* replacements seen */
    rt_rsi_model next;
    char msg[640];
} rt_rsi_watch;

/* Start watching src->model (st0: the file as loaded). 0, or -1 (no thread:
 * said on stderr; the model then stays). */
int rt_rsi_watch_start(rt_rsi_watch *w, const rt_rsi_model_src *src, const struct stat *st0, double every_s);
/* Never blocks: RT_RSI_WATCH_NONE when nothing was posted or the thread
 * holds the lock; RT_RSI_WATCH_MODEL with the new model in out; _REFUSED or
 * _REMOVED with msg. */
int rt_rsi_watch_take(rt_rsi_watch *w, rt_rsi_model *out, char *msg, size_t msg_len);
void rt_rsi_watch_stop(rt_rsi_watch *w);

#endif
