/* SPDX-License-Identifier: MIT */
/* rch_file.c - outputs that never destroy an input or a finished file
 * (see rch_file.h). */
#if !defined(_XOPEN_SOURCE)
#define _XOPEN_SOURCE 700 /* realpath, fchown */
#endif
#include "rch_file.h"

#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "rch_stdio.h"

#define RCH_TMP_MAX 64    /* temporaries alive at once */
#define RCH_CLAIM_MAX 256 /* outputs remembered for one command */
#define RCH_KEY_MAX 4096

/* ---- temporaries removed on a signal ---------------------------------- */

static char g_tmp[RCH_TMP_MAX][1024];
static volatile sig_atomic_t g_tmp_used[RCH_TMP_MAX];
static int g_handlers;
static const int g_signals[] = {SIGINT, SIGTERM, SIGHUP, SIGQUIT, SIGPIPE};
#define N_SIGNALS (sizeof g_signals / sizeof g_signals[0])

/* Async-signal-safe: unlink and raise only. SA_RESETHAND restored the default
 * action and SA_NODEFER lets the raise take effect at once. */
static void on_signal(int sig)
{
    const int saved = errno;
    for (size_t i = 0; i < RCH_TMP_MAX; ++i)
        if (g_tmp_used[i])
            (void)unlink(g_tmp[i]);
    errno = saved;
    (void)raise(sig);
}

static void install_handlers(void)
{
    if (g_handlers)
        return;
    g_handlers = 1;
    for (size_t k = 0; k < N_SIGNALS; ++k) {
        struct sigaction old, sa;
        if (sigaction(g_signals[k], NULL, &old) != 0 || old.sa_handler == SIG_IGN)
            continue; /* ignored by the caller (nohup, a shell's trap ''): stays ignored */
        if (old.sa_handler != SIG_DFL)
            continue; /* the program has its own */
        memset(&sa, 0, sizeof sa);
        sa.sa_handler = on_signal;
        sigemptyset(&sa.sa_mask);
        sa.sa_flags = SA_RESETHAND | SA_NODEFER;
        (void)sigaction(g_signals[k], &sa, NULL);
    }
}

/* The signals of the handler blocked (1) or restored (0) around a change of
 * the table and the file it names, so no signal sees half of it. */
static void block_signals(int on, sigset_t *saved)
{
    if (on) {
        sigset_t set;
        sigemptyset(&set);
        for (size_t k = 0; k < N_SIGNALS; ++k)
            sigaddset(&set, g_signals[k]);
        (void)sigprocmask(SIG_BLOCK, &set, saved);
    } else {
        (void)sigprocmask(SIG_SETMASK, saved, NULL);
    }
}

/* With signals blocked. */
static int tmp_add(const char *path)
{
    if (strlen(path) >= sizeof g_tmp[0])
        return -1;
    for (size_t i = 0; i < RCH_TMP_MAX; ++i)
        if (!g_tmp_used[i]) {
            memcpy(g_tmp[i], path, strlen(path) + 1);
            g_tmp_used[i] = 1;
            install_handlers();
            return 0;
        }
    return -1;
}

static void tmp_drop(const char *path)
{
    for (size_t i = 0; i < RCH_TMP_MAX; ++i)
        if (g_tmp_used[i] && strcmp(g_tmp[i], path) == 0) {
            g_tmp_used[i] = 0;
            return;
        }
}

int rch_tmp_register(const char *path)
{
    sigset_t saved;
    block_signals(1, &saved);
    const int rc = tmp_add(path);
    block_signals(0, &saved);
    return rc;
}

void rch_tmp_forget(const char *path)
{
    sigset_t saved;
    block_signals(1, &saved);
    tmp_drop(path);
    block_signals(0, &saved);
}

/* ---- paths: the same file, by inode or by normalised name -------------- */

/* The target of a chain of symbolic links ending at path (a dangling link
 * gives the file it would create). 0, or -1 (loop, too long). */
static int resolve_links(char *out, size_t cap, const char *path)
{
    char cur[RCH_KEY_MAX], link[RCH_KEY_MAX];
    const size_t pl = strlen(path);
    if (pl >= sizeof cur)
        return -1;
    memcpy(cur, path, pl + 1);
    for (int hop = 0; hop < 40; ++hop) {
        struct stat st;
        if (lstat(cur, &st) != 0 || !S_ISLNK(st.st_mode)) {
            const size_t cl = strlen(cur);
            if (cl >= cap)
                return -1;
            memcpy(out, cur, cl + 1);
            return 0;
        }
        const ssize_t n = readlink(cur, link, sizeof link - 1);
        if (n < 0 || (size_t)n >= sizeof link - 1)
            return -1;
        link[n] = '\0';
        if (link[0] == '/') {
            memcpy(cur, link, (size_t)n + 1); /* n < sizeof link - 1 <= sizeof cur - 1 */
        } else { /* relative to the link's directory */
            char *slash = strrchr(cur, '/');
            const size_t dl = slash ? (size_t)(slash - cur + 1) : 0;
            if (dl + (size_t)n >= sizeof cur)
                return -1;
            memmove(cur + dl, link, (size_t)n + 1);
        }
    }
    return -1;
}

/* Absolute path with ".", ".." and repeated slashes removed, by text. */
static int lexical(char *out, size_t cap, const char *path)
{
    char buf[RCH_KEY_MAX];
    size_t n = 0;
    if (path[0] != '/') {
        if (!getcwd(buf, sizeof buf))
            return -1;
        n = strlen(buf);
    }
    const size_t pl = strlen(path);
    if (n + 1 + pl >= sizeof buf)
        return -1;
    buf[n++] = '/';
    memcpy(buf + n, path, pl + 1);
    size_t k = 0; /* out: "/a/b" */
    for (char *p = buf; *p;) {
        while (*p == '/')
            ++p;
        char *e = p;
        while (*e && *e != '/')
            ++e;
        const size_t len = (size_t)(e - p);
        if (len == 0 || (len == 1 && p[0] == '.')) {
        } else if (len == 2 && p[0] == '.' && p[1] == '.') {
            while (k > 0 && out[k - 1] != '/')
                --k;
            if (k > 0)
                --k;
        } else {
            if (k + 1 + len >= cap)
                return -1;
            out[k++] = '/';
            memcpy(out + k, p, len);
            k += len;
        }
        p = e;
    }
    if (k == 0)
        out[k++] = '/';
    out[k] = '\0';
    return 0;
}

/* The key of an output path: its directory resolved (realpath) and its last
 * component through its links; lexical where the directory is missing. */
static int path_key(char *key, size_t cap, const char *path)
{
    char target[RCH_KEY_MAX], norm[RCH_KEY_MAX], dir[PATH_MAX];
    if (resolve_links(target, sizeof target, path) != 0 || lexical(norm, sizeof norm, target) != 0)
        return -1;
    char *slash = strrchr(norm, '/');
    const char *base = slash + 1;
    *slash = '\0';
    if (realpath(norm[0] ? norm : "/", dir) != NULL) {
        const int w = snprintf(key, cap, "%s/%s", strcmp(dir, "/") == 0 ? "" : dir, base);
        return w >= 0 && (size_t)w < cap ? 0 : -1;
    }
    *slash = '/';
    const size_t nl = strlen(norm);
    if (nl >= cap)
        return -1;
    memcpy(key, norm, nl + 1);
    return 0;
}

int rch_same_file(const char *a, const char *b)
{
    struct stat sa, sb;
    if (!a || !b || stat(a, &sa) != 0 || stat(b, &sb) != 0)
        return 0;
    return sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino;
}

int rch_path_same(const char *a, const char *b)
{
    struct stat sa, sb;
    char ka[RCH_KEY_MAX], kb[RCH_KEY_MAX];
    if (!a || !b)
        return 0;
    const int ea = stat(a, &sa) == 0, eb = stat(b, &sb) == 0;
    if (ea && eb)
        return sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino;
    if (ea != eb)
        return 0;
    if (path_key(ka, sizeof ka, a) != 0 || path_key(kb, sizeof kb, b) != 0)
        return strcmp(a, b) == 0;
    return strcmp(ka, kb) == 0;
}

/* ---- the outputs of one command ---------------------------------------- */

typedef struct {
    char key[RCH_KEY_MAX];
    char path[1024], what[96];
    int has_id;
    dev_t dev;
    ino_t ino;
} claim;

static claim *g_claims; /* RCH_CLAIM_MAX, allocated by rch_out_one_command */
static size_t g_n_claims;

void rch_out_one_command(void)
{
    if (!g_claims)
        g_claims = calloc(RCH_CLAIM_MAX, sizeof *g_claims);
    g_n_claims = 0;
}

static const claim *claimed(const char *path)
{
    char key[RCH_KEY_MAX];
    struct stat st;
    const int have_key = path_key(key, sizeof key, path) == 0, exists = stat(path, &st) == 0;
    for (size_t i = 0; g_claims && i < g_n_claims; ++i) {
        const claim *c = &g_claims[i];
        if ((have_key && strcmp(c->key, key) == 0) ||
            (exists && c->has_id && c->dev == st.st_dev && c->ino == st.st_ino))
            return c;
    }
    return NULL;
}

void rch_out_unclaim(const char *path)
{
    const claim *c = claimed(path);
    if (!c)
        return;
    const size_t i = (size_t)(c - g_claims);
    memmove(&g_claims[i], &g_claims[i + 1], (g_n_claims - i - 1) * sizeof *g_claims);
    g_n_claims--;
}

static void claim_add(const char *path, const char *what)
{
    struct stat st;
    if (!g_claims || g_n_claims == RCH_CLAIM_MAX)
        return;
    claim *c = &g_claims[g_n_claims];
    if (path_key(c->key, sizeof c->key, path) != 0)
        snprintf(c->key, sizeof c->key, "%s", path);
    snprintf(c->path, sizeof c->path, "%s", path);
    snprintf(c->what, sizeof c->what, "%s", what);
    c->has_id = stat(path, &st) == 0;
    c->dev = c->has_id ? st.st_dev : 0;
    c->ino = c->has_id ? st.st_ino : 0;
    g_n_claims++;
}

/* After a rename the file at path is a new inode. */
static void claim_placed(const char *path)
{
    struct stat st;
    char key[RCH_KEY_MAX];
    if (!g_claims || path_key(key, sizeof key, path) != 0 || stat(path, &st) != 0)
        return;
    for (size_t i = 0; i < g_n_claims; ++i)
        if (strcmp(g_claims[i].key, key) == 0) {
            g_claims[i].has_id = 1;
            g_claims[i].dev = st.st_dev;
            g_claims[i].ino = st.st_ino;
        }
}

int rch_outs_distinct(const char *const *paths, const char *const *whats, size_t n, rch_diag *d)
{
    for (size_t i = 0; i < n; ++i)
        for (size_t j = 0; j < i; ++j)
            if (paths[i] && paths[j] && strcmp(paths[i], "-") != 0 && strcmp(paths[j], "-") != 0 &&
                rch_path_same(paths[i], paths[j])) {
                rch_diag_set(d, "", 0, 0,
                             "%s %s names the same file as %s %s: refused, nothing written (give each output its own "
                             "name)",
                             whats[i], paths[i], whats[j], paths[j]);
                return -1;
            }
    return 0;
}

/* ---- one output --------------------------------------------------------- */

int rch_out_open(rch_out *o, const char *path, const char *what, const char *const *inputs, size_t n_inputs,
                 rch_diag *d)
{
    char final[RCH_KEY_MAX];
    memset(o, 0, sizeof *o);
    if (!path || !*path) {
        rch_diag_set(d, "", 0, 0, "%s: empty output path", what);
        return -1;
    }
    if (strcmp(path, "-") == 0) {
        o->f = stdout;
        snprintf(o->path, sizeof o->path, "-");
        return 0;
    }
    for (size_t i = 0; i < n_inputs; ++i)
        if (inputs[i] && strcmp(inputs[i], "-") != 0 && (rch_same_file(path, inputs[i]) || rch_path_same(path, inputs[i]))) {
            rch_diag_set(d, path, 0, 0,
                         "%s names the same file as the input %s: refused, nothing written (choose another output)",
                         what, inputs[i]);
            return -1;
        }
    const claim *c = claimed(path);
    if (c) {
        rch_diag_set(d, path, 0, 0,
                     "%s names the same file as %s %s of this command: refused, nothing written (give each output "
                     "its own name)",
                     what, c->what, c->path);
        return -1;
    }
    /* through a symbolic link: the link's target is replaced, the link stays */
    if (resolve_links(final, sizeof final, path) != 0) {
        rch_diag_set(d, path, 0, 0, "%s: a loop of symbolic links or a path too long: refused", what);
        return -1;
    }
    struct stat st;
    const int exists = stat(final, &st) == 0;
    if (exists && !S_ISREG(st.st_mode)) {
        rch_diag_set(d, path, 0, 0, "%s is not a regular file: refused", what);
        return -1;
    }
    if (exists && (access(final, W_OK) != 0 || (st.st_mode & (S_IWUSR | S_IWGRP | S_IWOTH)) == 0)) {
        rch_diag_set(d, path, 0, 0,
                     "%s: the file is read-only (mode %04o): refused, nothing written (make it writable, e.g. "
                     "chmod u+w, or choose another output)",
                     what, (unsigned)(st.st_mode & 07777));
        return -1;
    }
    const size_t fl = strlen(final);
    if (fl + 16 >= sizeof o->tmp) {
        rch_diag_set(d, "", 0, 0, "%s: path too long (%zu bytes)", what, fl);
        return -1;
    }
    memcpy(o->path, final, fl + 1);
    memcpy(o->tmp, final, fl);
    memcpy(o->tmp + fl, ".tmpXXXXXX", sizeof ".tmpXXXXXX");
    sigset_t saved;
    block_signals(1, &saved);
    int fd = mkstemp(o->tmp), full = 0;
    const int err = errno;
    if (fd >= 0 && tmp_add(o->tmp) != 0) {
        close(fd);
        unlink(o->tmp);
        fd = -1;
        full = 1;
    }
    block_signals(0, &saved);
    if (fd < 0) {
        rch_diag_set(d, path, 0, 0, "%s: cannot create a temporary file beside it: %s", what,
                     full ? "more than 64 outputs open at once" : strerror(err));
        o->tmp[0] = '\0';
        return -1;
    }
    if (exists) { /* the file keeps its mode (and owner, where permitted) */
        (void)fchmod(fd, st.st_mode & 07777);
        if (fchown(fd, st.st_uid, st.st_gid) != 0)
            (void)fchmod(fd, st.st_mode & 0777); /* no set-id bits for another owner */
    } else { /* mkstemp makes 0600; a new file gets the usual umask-based mode */
        mode_t mask = umask(0);
        umask(mask);
        (void)fchmod(fd, (mode_t)(0666 & ~mask));
    }
    o->f = fdopen(fd, "w");
    if (!o->f) {
        rch_diag_set(d, path, 0, 0, "%s: %s", what, strerror(errno));
        close(fd);
        rch_out_abort(o);
        return -1;
    }
    claim_add(o->path, what);
    return 0;
}

static void remove_tmp(rch_out *o)
{
    if (!o->tmp[0])
        return;
    sigset_t saved;
    block_signals(1, &saved);
    unlink(o->tmp);
    tmp_drop(o->tmp);
    block_signals(0, &saved);
    o->tmp[0] = '\0';
}

/* Flush, sync and close; the temporary stays for out_place. 0 or -1 (d set,
 * temporary removed). */
static int out_finish(rch_out *o, rch_diag *d)
{
    int bad = ferror(o->f) != 0, err = bad ? errno : 0;
    if (fflush(o->f) != 0 && !bad) {
        bad = 1;
        err = errno;
    }
    if (fsync(fileno(o->f)) != 0 && !bad) {
        bad = 1;
        err = errno;
    }
    if (fclose(o->f) != 0 && !bad) {
        bad = 1;
        err = errno;
    }
    o->f = NULL;
    if (bad) {
        rch_diag_set(d, o->path, 0, 0, "write failed (%s): the previous file is unchanged",
                     err ? strerror(err) : "I/O error");
        remove_tmp(o);
        return -1;
    }
    return 0;
}

static int out_place(rch_out *o, rch_diag *d)
{
    sigset_t saved;
    block_signals(1, &saved);
    const int rc = rename(o->tmp, o->path);
    const int err = errno;
    if (rc != 0)
        unlink(o->tmp);
    tmp_drop(o->tmp);
    block_signals(0, &saved);
    o->tmp[0] = '\0';
    if (rc != 0) {
        rch_diag_set(d, o->path, 0, 0, "cannot rename the finished output into place: %s", strerror(err));
        return -1;
    }
    claim_placed(o->path);
    return 0;
}

static int stdout_done(rch_out *o, rch_diag *d)
{
    o->f = NULL;
    if (fflush(stdout) != 0 || ferror(stdout)) {
        rch_diag_set(d, "", 0, 0, "standard output: write failed (%s): the output is incomplete",
                     strerror(rch_stdio_errno(stdout)));
        return -1;
    }
    return 0;
}

int rch_out_commit(rch_out *o, rch_diag *d)
{
    if (!o->f)
        return -1;
    if (o->f == stdout)
        return stdout_done(o, d);
    if (out_finish(o, d) != 0)
        return -1;
    return out_place(o, d);
}

int rch_out_commit_all(rch_out *o, size_t n, rch_diag *d)
{
    int rc = 0;
    for (size_t k = 0; k < n && rc == 0; ++k) {
        if (!o[k].f)
            rc = -1;
        else if (o[k].f == stdout)
            rc = stdout_done(&o[k], d);
        else
            rc = out_finish(&o[k], d);
    }
    if (rc != 0) { /* nothing renamed: every temporary goes */
        for (size_t k = 0; k < n; ++k)
            rch_out_abort(&o[k]);
        return -1;
    }
    for (size_t k = 0; k < n; ++k)
        if (o[k].tmp[0] && rc == 0)
            rc = out_place(&o[k], d);
        else
            rch_out_abort(&o[k]);
    return rc;
}

int rch_out_errno(rch_out *o)
{
    const int before = errno;
    if (!o->f)
        return before ? before : EIO;
    if (o->f == stdout)
        return rch_stdio_errno(stdout);
    errno = 0;
    if (fflush(o->f) != 0 && errno != 0)
        return errno;
    return before ? before : EIO;
}

void rch_out_abort(rch_out *o)
{
    if (o->f && o->f != stdout)
        fclose(o->f);
    o->f = NULL;
    remove_tmp(o);
}

static const char *file_kind(mode_t m)
{
    return S_ISFIFO(m) ? "a FIFO" : S_ISCHR(m) ? "a character device" : S_ISBLK(m) ? "a block device"
           : S_ISDIR(m) ? "a directory" : S_ISSOCK(m) ? "a socket" : "something else";
}

FILE *rch_open_regular(const char *path, size_t max_bytes, char *why, size_t why_len)
{
    /* O_NONBLOCK: opening a FIFO with no writer must not wait */
    const int fd = open(path, O_RDONLY | O_NONBLOCK | O_NOCTTY);
    struct stat st;
    if (fd < 0) {
        snprintf(why, why_len, "%s", strerror(errno));
        return NULL;
    }
    if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
        snprintf(why, why_len, "%s, not a regular file", file_kind(st.st_mode));
        close(fd);
        return NULL;
    }
    if ((unsigned long long)st.st_size > (unsigned long long)max_bytes) {
        snprintf(why, why_len, "larger than the limit of %zu MiB", max_bytes >> 20);
        close(fd);
        return NULL;
    }
    const int fl = fcntl(fd, F_GETFL);
    FILE *f = fl < 0 || fcntl(fd, F_SETFL, fl & ~O_NONBLOCK) != 0 ? NULL : fdopen(fd, "rb");
    if (!f) {
        snprintf(why, why_len, "%s", strerror(errno));
        close(fd);
    }
    return f;
}

int rch_read_file(char **text, size_t *len, const char *path, size_t max_bytes, rch_diag *d)
{
    *text = NULL;
    *len = 0;
    FILE *f = fopen(path, "rb");
    if (!f) {
        rch_diag_set(d, path, 0, 0, "cannot open: %s", strerror(errno));
        return -1;
    }
    struct stat st;
    if (fstat(fileno(f), &st) == 0 && S_ISDIR(st.st_mode)) {
        rch_diag_set(d, path, 0, 0, "is a directory, not a file: name the file in it");
        fclose(f);
        return -1;
    }
    size_t cap = max_bytes < 4096 ? max_bytes : 4096, n = 0;
    int seen_nl = 0;
    char *buf = malloc(cap + 1);
    int oom = buf == NULL;
    while (!oom) {
        if (n == cap) {
            if (cap >= max_bytes) {
                int c = fgetc(f);
                if (c == EOF && !ferror(f))
                    break; /* exactly max_bytes */
                rch_diag_set(d, path, 0, 0, "larger than the limit of %zu bytes: refused", max_bytes);
                free(buf);
                fclose(f);
                return -1;
            }
            size_t ncap = cap * 2 > max_bytes ? max_bytes : cap * 2;
            char *nb = realloc(buf, ncap + 1);
            if (!nb) {
                oom = 1;
                break;
            }
            buf = nb;
            cap = ncap;
        }
        size_t got = fread(buf + n, 1, cap - n, f);
        if (!seen_nl && got) { /* a NUL in the first line: binary data, a device or UTF-16, refused at once (a
                                   NUL later, as a power cut leaves, is the format reader's to name) */
            const char *nl = memchr(buf + n, '\n', got);
            const char *nul = memchr(buf + n, '\0', nl ? (size_t)(nl - (buf + n)) : got);
            if (nul) {
                rch_diag_set(d, path, 1, (unsigned)(nul - buf) + 1u, "a NUL byte in the first line: not a text file "
                             "(binary data, a device, or text in UTF-16: save it as UTF-8 or ASCII): refused");
                free(buf);
                fclose(f);
                return -1;
            }
            seen_nl = nl != NULL;
        }
        n += got;
        if (got == 0)
            break;
    }
    if (oom) {
        free(buf);
        buf = NULL;
    }
    if (!buf) {
        rch_diag_set(d, path, 0, 0, "out of memory");
        fclose(f);
        return -1;
    }
    if (ferror(f)) {
        rch_diag_set(d, path, 0, 0, "read error: %s", strerror(errno));
        free(buf);
        fclose(f);
        return -1;
    }
    fclose(f);
    buf[n] = '\0';
    *text = buf;
    *len = n;
    return 0;
}
