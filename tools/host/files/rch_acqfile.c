/* SPDX-License-Identifier: MIT */
/* rch_acqfile.c - the acquisition file (see rch_acqfile.h). */
#include "rch_acqfile.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "rch_data.h"

#define DEG_PER_RAD (180.0 / 3.14159265358979323846)

static int write_all(int fd, const char *p, size_t n)
{
    while (n > 0) {
        ssize_t w = write(fd, p, n);
        if (w < 0 && errno == EINTR)
            continue;
        if (w <= 0) {
            if (w == 0)
                errno = EIO; /* no progress and no reason: never a stale errno in the message */
            return -1;
        }
        p += w;
        n -= (size_t)w;
    }
    return 0;
}

/* Appends text[from..len) to "<path>.dropped": even the fragment of an
 * interrupted write is never destroyed. */
static int save_tail(const char *path, const char *text, size_t from, size_t len, rch_diag *d)
{
    char dpath[1100];
    int fd, rc;
    snprintf(dpath, sizeof dpath, "%s.dropped", path);
    fd = open(dpath, O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
    if (fd < 0) {
        rch_diag_set(d, path, 0, 0, "cannot save the unfinished last line to %s: %s", dpath, strerror(errno));
        return -1;
    }
    rc = write_all(fd, text + from, len - from);
    if (rc == 0)
        rc = fsync(fd);
    int err = rc != 0 ? errno : 0;
    if (close(fd) != 0 && rc == 0) {
        rc = -1;
        err = errno;
    }
    if (rc != 0) {
        rch_diag_set(d, path, 0, 0, "cannot save the unfinished last line to %s: %s", dpath,
                     strerror(err ? err : EIO));
        return -1;
    }
    return 0;
}

/* Exclusive lock on the whole file; -1 with d naming the holder. */
static int lock_file(int fd, const char *path, rch_diag *d)
{
    struct flock fl;
    memset(&fl, 0, sizeof fl);
    fl.l_type = F_WRLCK;
    fl.l_whence = SEEK_SET;
    if (fcntl(fd, F_SETLK, &fl) == 0)
        return 0;
    if (errno == EACCES || errno == EAGAIN) {
        memset(&fl, 0, sizeof fl);
        fl.l_type = F_WRLCK;
        fl.l_whence = SEEK_SET;
        if (fcntl(fd, F_GETLK, &fl) == 0 && fl.l_type != F_UNLCK)
            rch_diag_set(d, path, 0, 0,
                         "another acquisition (pid %ld) is writing this file; wait for it to end or choose "
                         "another --out", (long)fl.l_pid);
        else
            rch_diag_set(d, path, 0, 0, "another acquisition is writing this file; choose another --out");
        return -1;
    }
    rch_diag_set(d, path, 0, 0, "cannot lock: %s", strerror(errno));
    return -1;
}

/* Where the complete, trustworthy part of text ends: after the last line
 * ending in '\n', less a last line holding NUL bytes (power cut).
 * -1 with d set when a line is longer than RCH_ACQ_MAX_LINE. */
static long good_prefix(const char *text, size_t len, const char *path, rch_diag *d)
{
    size_t start = 0, good = 0, prev_good = 0;
    unsigned line = 0;
    for (size_t i = 0; i < len; ++i) {
        if (text[i] != '\n')
            continue;
        ++line;
        if (i - start > RCH_ACQ_MAX_LINE) {
            rch_diag_set(d, path, line, 1, "line longer than %u bytes: not an acquisition file; choose another "
                         "--out (nothing was changed)", RCH_ACQ_MAX_LINE);
            return -1;
        }
        prev_good = good;
        good = i + 1;
        start = i + 1;
    }
    if (len - start > RCH_ACQ_MAX_LINE) {
        rch_diag_set(d, path, line + 1, 1, "unfinished last line longer than %u bytes: not an acquisition file; "
                     "choose another --out (nothing was changed)", RCH_ACQ_MAX_LINE);
        return -1;
    }
    if (good > 0) { /* the last complete line holds NUL bytes (power cut) */
        size_t a = prev_good, nul = 0;
        for (size_t i = a; i + 1 < good; ++i)
            nul += text[i] == '\0';
        if (nul > 0)
            good = prev_good;
    }
    return (long)good;
}

/* The plan's joints of a file with the columns q1_plan..q6_plan (the last six of each line, written by
 * rch_acqfile_append_plan): *q_deg gets those of the data line `line` (1-based) of text. 0, or -1. */
static int plan_cols_of(double q_deg[RC_NJ], const char *text, size_t len, unsigned line)
{
    size_t i = 0, end;
    for (unsigned l = 1; l < line && i < len; ++i)
        l += text[i] == '\n';
    for (end = i; end < len && text[end] != '\n'; ++end)
        ;
    size_t p = end;
    for (int j = RC_NJ - 1; j >= 0; --j) { /* back over six fields */
        size_t e = p;
        while (p > i && text[p - 1] != ',')
            --p;
        if (p == i)
            return -1;
        char buf[64];
        size_t n = e - p < sizeof buf - 1 ? e - p : sizeof buf - 1;
        memcpy(buf, text + p, n);
        buf[n] = '\0';
        char *stop;
        q_deg[j] = strtod(buf, &stop);
        if (stop == buf || (*stop != '\0' && *stop != '\r'))
            return -1;
        --p; /* the comma */
    }
    return 0;
}

static int check_plan(const rch_data *f, unsigned char *done, rch_acqfile_state *st,
                      const double (*plan_deg)[RC_NJ], size_t n_poses, const char *path, int outlet_p1, int target_p1,
                      const char *text, size_t len, rch_diag *d)
{
    size_t last = f->n;
    for (size_t i = 0; i < f->n; ++i) {
        const unsigned long pose = f->pose[i];
        if (pose >= n_poses) {
            rch_diag_set(d, path, f->line[i], 1, "pose %lu is not in the plan (%zu poses): the file belongs to "
                         "another plan; choose another --out", pose, n_poses);
            return -1;
        }
        double qp[RC_NJ];
        if (text && plan_cols_of(qp, text, len, f->line[i]) != 0) {
            rch_diag_set(d, path, f->line[i], 1, "the plan's joints q1_plan..q6_plan are missing or not numbers; "
                         "choose another --out");
            return -1;
        }
        for (int j = 0; j < RC_NJ; ++j) {
            /* a controller's joints (plan columns) differ from the plan by its tolerance: the plan columns decide */
            const double q = text ? qp[j] : f->s[i].q_rad[j] * DEG_PER_RAD;
            if (fabs(q - plan_deg[pose][j]) > 1e-3) {
                rch_diag_set(d, path, f->line[i], 1, "pose %lu has q%d = %.4f but the plan says %.4f: the file "
                             "belongs to another plan; choose another --out", pose, j + 1, q, plan_deg[pose][j]);
                return -1;
            }
        }
        if (outlet_p1 && f->s[i].outlet != (unsigned)(outlet_p1 - 1))
            continue; /* measured from another place: not done from this one */
        if (target_p1 && f->s[i].target != (unsigned)(target_p1 - 1))
            continue; /* the cable on another point */
        if (!done[pose])
            st->n_done++;
        done[pose] = 1;
        last = i;
    }
    if (last < f->n) { /* the last sample from this place */
        st->has_last = 1;
        st->last_pose = (size_t)f->pose[last];
        st->last_len_mm = f->s[last].value;
    }
    return 0;
}

/* Read the file (bounded), drop an unfinished tail, check the rest. */
static int has_header(const char *text, size_t len, const char *h)
{
    const size_t n = strlen(h);
    return len > n && strncmp(text, h, n) == 0 && (text[n] == '\n' || (text[n] == '\r' && len > n + 1 && text[n + 1] == '\n'));
}

static int scan(rch_acqfile_state *st, unsigned char *done, int fd, const char *path,
                const double (*plan_deg)[RC_NJ], size_t n_poses, int outlet_p1, int target_p1, int plan_cols,
                rch_diag *d)
{
    struct stat sb;
    char *text;
    size_t len = 0;
    long good;
    int rc = -1;
    if (fstat(fd, &sb) != 0) {
        rch_diag_set(d, path, 0, 0, "cannot stat: %s", strerror(errno));
        return -1;
    }
    if (!S_ISREG(sb.st_mode)) {
        rch_diag_set(d, path, 0, 0, "is not a regular file (a device or pipe cannot hold an acquisition); "
                     "choose another --out");
        return -1;
    }
    if ((unsigned long long)sb.st_size > RCH_ACQ_MAX_BYTES) {
        rch_diag_set(d, path, 0, 0, "holds %lld bytes, more than the %u an acquisition file may have; choose "
                     "another --out", (long long)sb.st_size, RCH_ACQ_MAX_BYTES);
        return -1;
    }
    text = malloc((size_t)sb.st_size + 1);
    if (!text) {
        rch_diag_set(d, path, 0, 0, "out of memory");
        return -1;
    }
    while (len < (size_t)sb.st_size) {
        ssize_t r = pread(fd, text + len, (size_t)sb.st_size - len, (off_t)len);
        if (r < 0 && errno == EINTR)
            continue;
        if (r <= 0)
            break;
        len += (size_t)r;
    }
    good = good_prefix(text, len, path, d);
    if (good < 0)
        goto out;
    static const char *const headers[8] = {
        RCH_ACQ_HEADER, RCH_ACQ_HEADER_OUTLET, RCH_ACQ_HEADER_TARGET, RCH_ACQ_HEADER_OUTLET_TARGET,
        RCH_ACQ_HEADER RCH_ACQ_PLAN_COLS, RCH_ACQ_HEADER_OUTLET RCH_ACQ_PLAN_COLS,
        RCH_ACQ_HEADER_TARGET RCH_ACQ_PLAN_COLS, RCH_ACQ_HEADER_OUTLET_TARGET RCH_ACQ_PLAN_COLS};
    int kind = -1; /* the file's header: bit 0 outlet, bit 1 target, bit 2 the plan's joints beside */
    for (int k = 0; good > 0 && k < 8 && kind < 0; ++k)
        if (has_header(text, (size_t)good, headers[k]))
            kind = k;
    const int want = (outlet_p1 ? 1 : 0) | (target_p1 ? 2 : 0) | (plan_cols ? 4 : 0);
    if (good > 0 && kind >= 0 && (kind & 4) != (want & 4)) {
        rch_diag_set(d, path, 1, 1, (kind & 4) ? "records a controller's joints with the plan's beside them "
                                                 "(q1_plan..q6_plan): resume it with --controller (nothing was "
                                                 "changed)"
                                               : "records the plan's joints (no q1_plan..q6_plan): a run with "
                                                 "--controller needs a file of its own (nothing was changed)");
        goto out;
    }
    if (good > 0 && kind < 0) {
        rch_diag_set(d, path, 1, 1, "exists but is not an acquisition file (header '%s' expected); choose "
                     "another --out (nothing was changed)", headers[want]);
        goto out;
    }
    const int plain = kind >= 0 && !(kind & 1), with_outlet = kind >= 0 && (kind & 1);
    if (kind >= 0 && (kind & 2) != (want & 2)) {
        rch_diag_set(d, path, 1, 1, (kind & 2) ? "records the cable on several points of a tool plate (column "
                                                 "target): say which one this run has with --target N (nothing was "
                                                 "changed)"
                                               : "holds samples of the cable on one point (no target column): a run "
                                                 "with --target needs a file of its own (nothing was changed)");
        goto out;
    }
    if (plain && outlet_p1) {
        rch_diag_set(d, path, 1, 1, "holds samples of one encoder place (no outlet column): a run with --outlet "
                     "needs a file of its own, or leave --outlet out (nothing was changed)");
        goto out;
    }
    if (with_outlet && !outlet_p1) {
        rch_diag_set(d, path, 1, 1, "records several encoder places (column outlet): say which one this run "
                     "measures from with --outlet N (nothing was changed)");
        goto out;
    }
    if (good > 0) {
        rch_data f;
        if (rch_data_parse(&f, text, (size_t)good, path, RCH_DATA_POSE | RCH_DATA_ALLOW_EMPTY, d) != 0)
            goto out;
        rc = check_plan(&f, done, st, plan_deg, n_poses, path, outlet_p1, target_p1, plan_cols ? text : NULL,
                        (size_t)good, d);
        rch_data_free(&f);
        if (rc != 0)
            goto out;
        rc = -1;
    }
    if ((size_t)good < len) {
        if (save_tail(path, text, (size_t)good, len, d) != 0)
            goto out;
        if (ftruncate(fd, (off_t)good) != 0) {
            rch_diag_set(d, path, 0, 0, "cannot truncate: %s", strerror(errno));
            goto out;
        }
        st->dropped_bytes = len - (size_t)good;
    }
    char header[128];
    snprintf(header, sizeof header, "%s\n", headers[want]);
    if (good == 0 && write_all(fd, header, strlen(header)) != 0) {
        rch_diag_set(d, path, 0, 0, "cannot write the header: %s", strerror(errno));
        goto out;
    }
    if (fsync(fd) != 0) {
        rch_diag_set(d, path, 0, 0, "fsync: %s", strerror(errno));
        goto out;
    }
    rc = 0;
out:
    free(text);
    return rc;
}

int rch_acqfile_open(rch_acqfile *a, rch_acqfile_state *st, unsigned char *done, const char *path,
                     const double (*plan_deg)[RC_NJ], size_t n_poses, rch_diag *d)
{
    return rch_acqfile_open_outlet(a, st, done, path, plan_deg, n_poses, 0, d);
}

int rch_acqfile_open_outlet(rch_acqfile *a, rch_acqfile_state *st, unsigned char *done, const char *path,
                            const double (*plan_deg)[RC_NJ], size_t n_poses, int outlet_p1, rch_diag *d)
{
    return rch_acqfile_open_at(a, st, done, path, plan_deg, n_poses, outlet_p1, 0, d);
}

int rch_acqfile_open_at(rch_acqfile *a, rch_acqfile_state *st, unsigned char *done, const char *path,
                        const double (*plan_deg)[RC_NJ], size_t n_poses, int outlet_p1, int target_p1, rch_diag *d)
{
    return rch_acqfile_open_plan(a, st, done, path, plan_deg, n_poses, outlet_p1, target_p1, 0, d);
}

int rch_acqfile_open_plan(rch_acqfile *a, rch_acqfile_state *st, unsigned char *done, const char *path,
                          const double (*plan_deg)[RC_NJ], size_t n_poses, int outlet_p1, int target_p1, int plan_cols,
                          rch_diag *d)
{
    a->plan_cols = plan_cols != 0;
    memset(st, 0, sizeof *st);
    memset(done, 0, n_poses);
    a->fd = -1;
    a->outlet_p1 = outlet_p1 > 0 && outlet_p1 <= 256 ? outlet_p1 : 0;
    a->target_p1 = target_p1 > 0 && target_p1 <= RC_MAX_TARGETS ? target_p1 : 0;
    if (strlen(path) >= sizeof a->path) {
        rch_diag_set(d, path, 0, 0, "path too long");
        return -1;
    }
    memcpy(a->path, path, strlen(path) + 1);
    a->fd = open(path, O_RDWR | O_CREAT | O_APPEND | O_CLOEXEC | O_NOCTTY | O_NONBLOCK, 0644);
    if (a->fd < 0) {
        rch_diag_set(d, path, 0, 0, "cannot open for appending: %s", strerror(errno));
        return -1;
    }
    if (lock_file(a->fd, path, d) != 0 || scan(st, done, a->fd, path, plan_deg, n_poses, a->outlet_p1, a->target_p1, a->plan_cols,
                                                d) != 0) {
        close(a->fd);
        a->fd = -1;
        return -1;
    }
    return 0;
}

int rch_acqfile_append(rch_acqfile *a, size_t pose, const double q_deg[RC_NJ], const rc_stable_result *r,
                       long long t_unix_ms, rch_diag *d)
{
    return rch_acqfile_append_plan(a, pose, q_deg, NULL, r, t_unix_ms, d);
}

int rch_acqfile_append_plan(rch_acqfile *a, size_t pose, const double q_deg[RC_NJ], const double plan_deg[RC_NJ],
                            const rc_stable_result *r, long long t_unix_ms, rch_diag *d)
{
    char line[640];
    int n = snprintf(line, sizeof line, "%zu", pose);
    if (a->plan_cols && !plan_deg) {
        rch_diag_set(d, a->path, 0, 0, "the plan's joints are missing for pose %zu", pose);
        return -1;
    }
    for (int j = 0; j < RC_NJ; ++j) /* a controller's joints at its full precision (1e-6 deg); the plan's at 4 */
        n += snprintf(line + n, sizeof line - (size_t)n, a->plan_cols ? ",%.6f" : ",%.4f", q_deg[j]);
    n += snprintf(line + n, sizeof line - (size_t)n, ",%.4f,%.4f,%u,%lld", r->mean_mm, r->spread_mm, r->count,
                  t_unix_ms);
    if (a->outlet_p1)
        n += snprintf(line + n, sizeof line - (size_t)n, ",%d", a->outlet_p1 - 1);
    if (a->target_p1)
        n += snprintf(line + n, sizeof line - (size_t)n, ",%d", a->target_p1 - 1);
    for (int j = 0; a->plan_cols && j < RC_NJ; ++j)
        n += snprintf(line + n, sizeof line - (size_t)n, ",%.4f", plan_deg[j]);
    n += snprintf(line + n, sizeof line - (size_t)n, "\n");
    if (n <= 0 || (size_t)n >= sizeof line) {
        rch_diag_set(d, a->path, 0, 0, "sample line too long");
        return -1;
    }
    if (write_all(a->fd, line, (size_t)n) != 0 || fsync(a->fd) != 0) {
        rch_diag_set(d, a->path, 0, 0, "writing failed: %s", strerror(errno));
        return -1;
    }
    return 0;
}

int rch_acqfile_close(rch_acqfile *a, rch_diag *d)
{
    int rc = 0;
    if (a->fd >= 0 && close(a->fd) != 0) {
        rch_diag_set(d, a->path, 0, 0, "close: %s", strerror(errno));
        rc = -1;
    }
    a->fd = -1;
    return rc;
}
