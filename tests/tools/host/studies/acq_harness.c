/* SPDX-License-Identifier: MIT */
/* acq_harness.c - the acquisition tests' harness (see acq_harness.h). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "rch_acqfile.h"
#include "rch_acquire.h"
#include "rch_data.h"
#include "rch_poses.h"
#include "rch_robot.h"
#include "acq_harness.h"

const double plan_deg[NP][RC_NJ] = {
    {0, 0, 0, 0, 30, 0}, {40, 20, -30, 10, 45, 0}, {-60, 30, 10, -20, 60, 30}, {90, -20, 20, 40, -50, 10}};
char dir_[256];
double nominal_mm[NP];


static void pdev_load(tio *t, int k);
static rc_status t_open(void *ctx, rcd_port **port, const char *path, const rcd_serial_config *cfg)
{
    tio *t = ctx;
    int k = t->opened++ == 0 ? 0 : 1;
    t->port.ops = &rcd_mock_ops;
    t->port.ctx = &t->m[k];
    if (k == 1)
        t->m[1].clock_ms = t->m[0].clock_ms;
    *port = &t->port;
    if (t->pd)
        pdev_load(t, k);
    return rcd_port_open(&t->port, path, cfg);
}
static void t_close(void *ctx)
{
    tio *t = ctx;
    rcd_port_close(&t->port);
}
static void t_sleep(void *ctx, rcd_port *port, unsigned long ms)
{
    (void)ctx;
    ((rcd_mock_ctx *)port->ctx)->clock_ms += (uint32_t)ms;
}
static long long t_wall(void *ctx)
{
    (void)ctx;
    return 1700000000000ll;
}
static int t_confirm(void *ctx, size_t pose)
{
    (void)ctx;
    (void)pose;
    return 0;
}

/* ASCII stream of `count` frames per value. Returns the length. The mock
 * delivers one frame per read (max_chunk), as a display that streams: a
 * flush at a new pose drops nothing that was not yet "sent". */
size_t g_frame;
size_t script(uint8_t *s, size_t cap, const double *v, size_t nv, unsigned count)
{
    size_t len = 0;
    for (size_t i = 0; i < nv; ++i)
        for (unsigned k = 0; k < count; ++k) {
            size_t n;
            assert_int_equal(rcd_encode_ascii(s + len, &n, cap - len, v[i], RCD_STYLE_ZERO_PAD, RCD_UNIT_NONE, 2),
                             RC_OK);
            len += n;
            g_frame = n;
        }
    return len;
}

void tio_init(tio *t)
{
    memset(t, 0, sizeof *t);
    for (int k = 0; k < 2; ++k) {
        rcd_port p;
        rcd_mock_init(&p, &t->m[k]);
        t->m[k].rx = t->rx[k];
    }
}

void path_in(char *buf, size_t cap, const char *name)
{
    snprintf(buf, cap, "%s/%s", dir_, name);
}

void write_text(const char *name, const char *text)
{
    char p[512];
    FILE *f;
    path_in(p, sizeof p, name);
    f = fopen(p, "w");
    assert_non_null(f);
    fputs(text, f);
    fclose(f);
}

long long fsize(const char *name)
{
    char p[512];
    struct stat sb;
    path_in(p, sizeof p, name);
    return stat(p, &sb) == 0 ? (long long)sb.st_size : -1;
}

char g_plan[512], g_out[512], g_err[8192];

void config(rch_acq_config *c, const char *out_name)
{
    rch_acq_config_default(c);
    c->port_path = "mock";
    c->poses_path = g_plan;
    path_in(g_out, sizeof g_out, out_name);
    remove(g_out);
    c->out_path = g_out;
    c->robot_path = ROBOT;
    c->settle_ms = 100;
    c->read_timeout_ms = 50;
    c->retries = 3;
    c->reconnect_s = 1;
    c->quiet = 1;
}

int run(rch_acq_result *r, const rch_acq_config *c, tio *t)
{
    t->m[0].max_chunk = t->m[1].max_chunk = g_frame;
    rch_acq_io io = {t_open, t_close, t_sleep, t_wall, t_confirm, NULL, t};
    FILE *e;
    memset(g_err, 0, sizeof g_err);
    e = fmemopen(g_err, sizeof g_err, "w");
    int rc;
    assert_non_null(e);
    rc = rch_acquire_run(r, c, &io, NULL, e);
    fclose(e);
    print_message("%s", g_err);
    return rc;
}

int acq_setup(const char *sub)
{
    rch_robot rb;
    rch_diag dg;
    char text[1024];
    size_t n = 0;
    snprintf(dir_, sizeof dir_, "%s/tests/tools/host/studies/%s", RCAL_BINARY_DIR, sub);
    (void)mkdir(dir_, 0755);
    assert_int_equal(rch_robot_load(&rb, ROBOT, &dg), 0);
    rb.model.x[RC_P_ENC] = 250.0;
    rb.model.x[RC_P_ENC + 1] = -460.0;
    rb.model.x[RC_P_ENC + 2] = 10.0;
    n += (size_t)snprintf(text + n, sizeof text - n, "pose,q1,q2,q3,q4,q5,q6\n");
    for (int i = 0; i < NP; ++i) {
        rc_sample s;
        memset(&s, 0, sizeof s);
        memset(&s, 0, sizeof s);
        n += (size_t)snprintf(text + n, sizeof text - n, "%d", i);
        for (int j = 0; j < RC_NJ; ++j) {
            s.q_rad[j] = plan_deg[i][j] * 3.14159265358979323846 / 180.0;
            n += (size_t)snprintf(text + n, sizeof text - n, ",%.4f", plan_deg[i][j]);
        }
        n += (size_t)snprintf(text + n, sizeof text - n, "\n");
        assert_int_equal(rc_meas(&nominal_mm[i], NULL, &rb.model, &s), RC_OK);
    }
    write_text("plan.csv", text);
    path_in(g_plan, sizeof g_plan, "plan.csv");
    return 0;
}

/* a display that follows the robot (true lengths 1 mm off the nominal
 * ones, as a real robot is; misses of 2 mm, under --jump-mm): every pose
 * recorded */


/* the value device k shows now (the frame last delivered) */
static double pdev_now(const tio *t, int k)
{
    const pdev *d = t->pd;
    size_t f = d->flen ? t->m[k].rx_pos / d->flen : 0;
    if (t->m[k].rx_len == 0)
        return d->shown[k];
    return d->frames[k][f > 0 ? f - 1 : 0];
}

static void pdev_load(tio *t, int k)
{
    pdev *d = t->pd;
    const double target = d->frozen ? d->frozen_mm : d->val[k][d->pose] + (d->jumped ? d->jump_mm : 0.0);
    size_t len = 0;
    t->m[k].rx = d->rx[k];
    t->m[k].ms_per_read = 50;
    t->m[k].closed_at_end = 0;
    if (k == 0 && d->pose == d->hang_at) {
        t->m[0].rx_len = 0;
        t->m[0].rx_pos = 0;
        t->m[0].closed_at_end = 1;
        return;
    }
    for (int f = 0; f < PD_FRAMES; ++f) {
        /* settle_ms (100) after the move, then one frame per 50 ms */
        const double tt = 100.0 + 50.0 * f;
        double y = d->tau_ms > 0.0 && !d->frozen ? target + (d->shown[k] - target) * exp(-tt / d->tau_ms) : target;
        size_t n;
        y = round(y * 100.0) / 100.0;
        d->frames[k][f] = y;
        assert_int_equal(rcd_encode_ascii(d->rx[k] + len, &n, sizeof d->rx[k] - len, y, RCD_STYLE_ZERO_PAD,
                                          RCD_UNIT_NONE, 2), RC_OK);
        assert_true(d->flen == 0 || n == d->flen);
        d->flen = n;
        len += n;
    }
    t->m[k].rx_len = len;
    t->m[k].rx_pos = 0;
    t->m[k].max_chunk = d->flen;
}

static int t_joints(void *ctx, double q_deg[RC_NJ], const double plan[RC_NJ], size_t pose)
{
    tio *t = ctx;
    int k = t->opened > 1 ? 1 : 0;
    (void)q_deg;
    (void)plan;
    t->pd->shown[k] = pdev_now(t, k);
    t->pd->pose = (int)pose;
    if ((int)pose == t->pd->freeze_at && !t->pd->frozen) {
        t->pd->frozen = 1;
        t->pd->frozen_mm = t->pd->shown[k];
    }
    if (t->pd->jump_at && (int)pose == t->pd->jump_at)
        t->pd->jumped = 1;
    pdev_load(t, k);
    return 0;
}

int run_pd(rch_acq_result *r, const rch_acq_config *c, tio *t, pdev *d)
{
    rch_acq_io io = {t_open, t_close, t_sleep, t_wall, t_confirm, t_joints, t};
    FILE *e;
    int rc;
    t->pd = d;
    memset(g_err, 0, sizeof g_err);
    e = fmemopen(g_err, sizeof g_err, "w");
    assert_non_null(e);
    rc = rch_acquire_run(r, c, &io, NULL, e);
    fclose(e);
    print_message("%s", g_err);
    return rc;
}

void pdev_init(pdev *d, double off0, double off1)
{
    memset(d, 0, sizeof *d);
    d->hang_at = -1;
    d->freeze_at = -1;
    for (int p = 0; p < NROWS; ++p) {
        d->val[0][p] = nominal_mm[p % NP] + off0;
        d->val[1][p] = nominal_mm[p % NP] + off1;
    }
    d->shown[0] = d->shown[1] = nominal_mm[0];
}

/* the recorded L of pose p in the file (NAN: not there) */
double recorded(const char *path, int pose)
{
    char line[512];
    double L = NAN;
    FILE *f = fopen(path, "r");
    assert_non_null(f);
    while (fgets(line, sizeof line, f)) {
        int p;
        double q[6], len;
        if (sscanf(line, "%d,%lf,%lf,%lf,%lf,%lf,%lf,%lf", &p, &q[0], &q[1], &q[2], &q[3], &q[4], &q[5], &len) == 8 &&
            p == pose)
            L = len;
    }
    fclose(f);
    return L;
}

char *slurp(const char *path, size_t *n)
{
    static char buf[2][8192];
    static int which;
    FILE *f = fopen(path, "rb");
    char *b = buf[which ^= 1];
    assert_non_null(f);
    *n = fread(b, 1, sizeof buf[0], f);
    fclose(f);
    return b;
}

double nominal_at(const double q_deg[RC_NJ], const double enc_mm[3], const double *point_mm)
{
    static rch_robot rb;
    rch_diag dg;
    rc_sample s;
    double len = NAN;
    assert_int_equal(rch_robot_load(&rb, ROBOT, &dg), 0);
    memcpy(&rb.model.x[RC_P_ENC], enc_mm, 3 * sizeof(double));
    if (point_mm) {
        assert_int_equal(rc_model_add_effect(&rb.model, RC_EFF_CABLE_POINTS, 0, 3), RC_OK);
        memcpy(&rb.model.x[rb.model.effects[rb.model.n_effects - 1].first], point_mm, 3 * sizeof(double));
    }
    memset(&s, 0, sizeof s);
    for (int j = 0; j < RC_NJ; ++j)
        s.q_rad[j] = q_deg[j] * 3.14159265358979323846 / 180.0;
    assert_int_equal(rc_meas(&len, NULL, &rb.model, &s), RC_OK);
    return len;
}

int row_pose(int r, int pose_major)
{
    return pose_major ? r / 2 : r % NP;
}

int row_label(int r, int pose_major)
{
    return pose_major ? r % 2 : r / NP;
}

void write_labelled_plan(const char *name, const char *col, int pose_major)
{
    char text[2048];
    size_t n = 0;
    n += (size_t)snprintf(text + n, sizeof text - n, "pose,q1,q2,q3,q4,q5,q6,%s\n", col);
    for (int r = 0; r < NROWS; ++r) {
        const int i = row_pose(r, pose_major), k = row_label(r, pose_major);
        n += (size_t)snprintf(text + n, sizeof text - n, "%d", r);
        for (int j = 0; j < RC_NJ; ++j)
            n += (size_t)snprintf(text + n, sizeof text - n, ",%.4f", plan_deg[i][j]);
        n += (size_t)snprintf(text + n, sizeof text - n, ",%d\n", k);
    }
    write_text(name, text);
}
