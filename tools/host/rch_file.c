/* SPDX-License-Identifier: MIT */
/* rch_file.c - outputs that never destroy an input or a finished file
 * (see rch_file.h). */
#include "rch_file.h"

#include <errno.h>
#include <fcntl.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

int rch_same_file(const char *a, const char *b)
{
    struct stat sa, sb;
    if (!a || !b || stat(a, &sa) != 0 || stat(b, &sb) != 0)
        return 0;
    return sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino;
}

int rch_out_open(rch_out *o, const char *path, const char *what, const char *const *inputs, size_t n_inputs,
                 rch_diag *d)
{
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
        if (inputs[i] && rch_same_file(path, inputs[i])) {
            rch_diag_set(d, path, 0, 0,
                         "%s names the same file as the input %s: refused, nothing written (choose another output)",
                         what, inputs[i]);
            return -1;
        }
    struct stat st;
    if (stat(path, &st) == 0 && !S_ISREG(st.st_mode)) {
        rch_diag_set(d, path, 0, 0, "%s is not a regular file: refused", what);
        return -1;
    }
    if (strlen(path) + 16 >= sizeof o->tmp) {
        rch_diag_set(d, "", 0, 0, "%s: path too long (%zu bytes)", what, strlen(path));
        return -1;
    }
    snprintf(o->path, sizeof o->path, "%s", path);
    snprintf(o->tmp, sizeof o->tmp, "%s.tmpXXXXXX", path);
    int fd = mkstemp(o->tmp);
    if (fd < 0) {
        rch_diag_set(d, path, 0, 0, "%s: cannot create a temporary file beside it: %s", what, strerror(errno));
        o->tmp[0] = '\0';
        return -1;
    }
    /* mkstemp makes 0600; a result file gets the usual umask-based mode. */
    mode_t mask = umask(0);
    umask(mask);
    (void)fchmod(fd, (mode_t)(0666 & ~mask));
    o->f = fdopen(fd, "w");
    if (!o->f) {
        rch_diag_set(d, path, 0, 0, "%s: %s", what, strerror(errno));
        close(fd);
        unlink(o->tmp);
        o->tmp[0] = '\0';
        return -1;
    }
    return 0;
}

int rch_out_commit(rch_out *o, rch_diag *d)
{
    if (!o->f)
        return -1;
    if (o->f == stdout) {
        o->f = NULL;
        if (fflush(stdout) != 0) {
            rch_diag_set(d, "", 0, 0, "standard output: %s", strerror(errno));
            return -1;
        }
        return 0;
    }
    int bad = ferror(o->f) != 0;
    bad |= fflush(o->f) != 0;
    bad |= fsync(fileno(o->f)) != 0;
    int err = errno;
    bad |= fclose(o->f) != 0;
    o->f = NULL;
    if (bad) {
        rch_diag_set(d, o->path, 0, 0, "write failed (%s): the previous file is unchanged", strerror(err));
        unlink(o->tmp);
        o->tmp[0] = '\0';
        return -1;
    }
    if (rename(o->tmp, o->path) != 0) {
        rch_diag_set(d, o->path, 0, 0, "cannot rename the finished output into place: %s", strerror(errno));
        unlink(o->tmp);
        o->tmp[0] = '\0';
        return -1;
    }
    o->tmp[0] = '\0';
    return 0;
}

void rch_out_abort(rch_out *o)
{
    if (o->f && o->f != stdout)
        fclose(o->f);
    o->f = NULL;
    if (o->tmp[0])
        unlink(o->tmp);
    o->tmp[0] = '\0';
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
    size_t cap = max_bytes < 4096 ? max_bytes : 4096, n = 0;
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
