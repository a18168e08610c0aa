/* SPDX-License-Identifier: MIT */
/* rt_rsi_model.c - the RSI partner's model and its watcher (rt_rsi_model.h). */
#include "rt_rsi_model.h"

#include <errno.h>
#include <math.h>
#include <sched.h>
#include <signal.h>
#include <stdio.h>
#include <string.h>
#include <time.h>

#include "rch_comp.h"
#include "rch_diag.h"
#include "rch_robot.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif
#define DEG (M_PI / 180.0)

int rt_rsi_model_load(rt_rsi_model *m, char *note, size_t note_len, char *err, size_t err_len,
                      const rt_rsi_model_src *src)
{
    static rch_robot robot, nominal;
    static rch_model_unc unc;
    rch_diag d;
    char msg[1024];
    memset(&d, 0, sizeof d);
    rch_comp_job job;
    memset(&job, 0, sizeof job);
    job.model_path = src->model;
    job.nominal_path = src->nominal;
    if (rch_robot_load(&robot, src->model, &d) != 0 ||
        (src->nominal && (rch_robot_load(&nominal, src->nominal, &d) != 0 ||
                          rch_comp_same_model(&d, &job, &robot, &nominal) != 0))) {
        snprintf(err, err_len, "%s", rch_diag_str(&d, msg, sizeof msg));
        return -1;
    }
    const rc_model *nom = src->nominal ? &nominal.model : &robot.nominal;
    int version1 = 0;
    char held[256] = "";
    memset(m, 0, sizeof *m);
    m->det = robot.model;
    memset(&unc, 0, sizeof unc);
    if (robot.has_nominal || robot.unc.present)
        rch_comp_determined(&m->det, &unc, &version1, held, sizeof held, &robot, &robot.nominal);
    const int orient_det = unc.present && !version1 && unc.orientation_determined;
    rch_comp_point_model(&m->det, &m->det, NULL);
    rch_comp_point_model(&m->nom_pt, nom, NULL);
    rch_comp_orient or;
    memset(&or, 0, sizeof or);
    if (!src->position_only && !src->full_pose)
        rch_comp_orient_decide(&or, unc.present && !version1 ? &unc : NULL, &m->det, &m->nom_pt, &m->cfg);
    m->position_only = rch_comp_position_only(&or, src->position_only, src->full_pose,
                                              robot.has_nominal || robot.unc.present, orient_det);
    m->cfg.flags = m->position_only ? RC_COMP_FLAG_POSITION_ONLY : 0u;
    /* the controller's joints as rcal compensate reads them: the nominal file's member, else the model's */
    m->ctrl = src->nominal ? nominal.ctrl : robot.ctrl;
    m->map = m->ctrl.present && !m->ctrl.identity_joints;
    snprintf(note, note_len, "compensating with %s (%s); held nominal: %s; the controller's joints: %s%s",
             src->model, m->position_only ? "position only" : "position and orientation", held[0] ? held : "none",
             m->map ? "mapped to the model's (\"controller\" member)" : "the model's",
             !robot.has_nominal && !src->nominal ? "; warning: no \"nominal\" table, only its effects are corrected"
                                                 : "");
    return 0;
}

void rt_rsi_model_to_model(double q_rad[6], const rt_rsi_model *m, const double ctrl_deg[6])
{
    for (int i = 0; i < 6; ++i)
        q_rad[i] = ctrl_deg[i] * DEG;
    if (m->map)
        rch_ctrl_to_model(q_rad, &m->ctrl, q_rad);
}

void rt_rsi_model_to_ctrl(double ctrl_deg[6], const rt_rsi_model *m, const double q_rad[6])
{
    double c[6];
    memcpy(c, q_rad, sizeof c);
    if (m->map)
        rch_ctrl_from_model(c, &m->ctrl, c);
    for (int i = 0; i < 6; ++i)
        ctrl_deg[i] = c[i] / DEG;
}

/* ---- the watcher ---- */

static int same_file(const struct stat *a, const struct stat *b)
{
    return a->st_ino == b->st_ino && a->st_dev == b->st_dev && a->st_size == b->st_size &&
           a->st_mtim.tv_sec == b->st_mtim.tv_sec && a->st_mtim.tv_nsec == b->st_mtim.tv_nsec;
}

/* src into dst (n bytes), cut when longer */
static void copy_str(char *dst, size_t n, const char *src)
{
    size_t k = strlen(src);
    if (k >= n)
        k = n - 1;
    memcpy(dst, src, k);
    dst[k] = '\0';
}

static void post(rt_rsi_watch *w, int what, const rt_rsi_model *m, const char *msg)
{
    pthread_mutex_lock(&w->mu);
    w->posted = what;
    w->changes++;
    if (m)
        w->next = *m;
    copy_str(w->msg, sizeof w->msg, msg);
    pthread_mutex_unlock(&w->mu);
}

static void *watch_main(void *arg)
{
    rt_rsi_watch *w = arg;
    static rt_rsi_model m; /* one watcher at a time */
    for (;;) {
        struct timespec ts = {(time_t)w->every_s, (long)(fmod(w->every_s, 1.0) * 1e9)};
        while (nanosleep(&ts, &ts) != 0 && errno == EINTR) {
        }
        pthread_mutex_lock(&w->mu);
        const int stop = w->stop;
        pthread_mutex_unlock(&w->mu);
        if (stop)
            break;
        struct stat st;
        if (stat(w->src.model, &st) != 0) {
            if (w->have_st)
                post(w, RT_RSI_WATCH_REMOVED, NULL, strerror(errno));
            w->have_st = 0;
            continue;
        }
        if (w->have_st && same_file(&st, &w->st))
            continue;
        w->st = st;
        w->have_st = 1;
        char note[1024], err[1024];
        if (rt_rsi_model_load(&m, note, sizeof note, err, sizeof err, &w->src) != 0)
            post(w, RT_RSI_WATCH_REFUSED, NULL, err);
        else
            post(w, RT_RSI_WATCH_MODEL, &m, note);
    }
    return NULL;
}

int rt_rsi_watch_start(rt_rsi_watch *w, const rt_rsi_model_src *src, const struct stat *st0, double every_s)
{
    memset(w, 0, sizeof *w);
    w->src = *src;
    w->every_s = every_s;
    if (st0) {
        w->st = *st0;
        w->have_st = 1;
    }
    if (pthread_mutex_init(&w->mu, NULL) != 0)
        return -1;
    /* a normal thread whatever the loop's scheduling (the file system may stall it; the loop never waits
     * for it), with a small stack (mlockall locks it) */
    pthread_attr_t a;
    pthread_attr_init(&a);
    struct sched_param sp;
    memset(&sp, 0, sizeof sp);
    pthread_attr_setinheritsched(&a, PTHREAD_EXPLICIT_SCHED);
    pthread_attr_setschedpolicy(&a, SCHED_OTHER);
    pthread_attr_setschedparam(&a, &sp);
    pthread_attr_setstacksize(&a, (size_t)256 << 10);
    /* SIGINT and SIGTERM for the loop's thread (they end its blocking read) */
    sigset_t block, old;
    sigemptyset(&block);
    sigaddset(&block, SIGINT);
    sigaddset(&block, SIGTERM);
    pthread_sigmask(SIG_BLOCK, &block, &old);
    const int rc = pthread_create(&w->th, &a, watch_main, w);
    pthread_sigmask(SIG_SETMASK, &old, NULL);
    pthread_attr_destroy(&a);
    if (rc != 0) {
        fprintf(stderr, "rcal-rt: rsi: note: the model file is not watched (no thread: %s)\n", strerror(rc));
        pthread_mutex_destroy(&w->mu);
        return -1;
    }
    w->started = 1;
    return 0;
}

int rt_rsi_watch_take(rt_rsi_watch *w, rt_rsi_model *out, char *msg, size_t msg_len)
{
    if (!w->started || pthread_mutex_trylock(&w->mu) != 0)
        return RT_RSI_WATCH_NONE;
    const int what = w->posted;
    if (what == RT_RSI_WATCH_MODEL)
        *out = w->next;
    if (what != RT_RSI_WATCH_NONE)
        copy_str(msg, msg_len, w->msg);
    w->posted = RT_RSI_WATCH_NONE;
    pthread_mutex_unlock(&w->mu);
    return what;
}

void rt_rsi_watch_stop(rt_rsi_watch *w)
{
    if (!w->started)
        return;
    pthread_mutex_lock(&w->mu);
    w->stop = 1;
    pthread_mutex_unlock(&w->mu);
    pthread_join(w->th, NULL);
    pthread_mutex_destroy(&w->mu);
    w->started = 0;
}
