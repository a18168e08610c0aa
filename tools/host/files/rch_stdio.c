/* SPDX-License-Identifier: MIT */
/* rch_stdio.c - standard descriptors opened and standard output checked
 * (see rch_stdio.h). */
#if defined(__linux__) && !defined(_GNU_SOURCE)
#define _GNU_SOURCE /* fopencookie (glibc) */
#endif
#include "rch_stdio.h"

#include <errno.h>
#include <fcntl.h>
#include <string.h>
#include <sys/types.h>
#include <unistd.h>

static const char *g_prog = "rcal";
static int g_was_closed[3]; /* descriptor found closed at the start */
static int g_out_errno;     /* reason of the first failed write on standard output (glibc stream) */
static FILE *g_orig_stdout; /* the C library's stream, while ours is installed */

/* Descriptor fd closed? Then /dev/null on it, in the direction that keeps
 * every use failing as on the closed descriptor. */
static void open_null(int fd)
{
    if (fcntl(fd, F_GETFD) != -1 || errno != EBADF)
        return;
    g_was_closed[fd] = 1;
    const int got = open("/dev/null", fd == 0 ? O_WRONLY : O_RDONLY);
    if (got == fd)
        return;
    /* The lowest free descriptor is fd (0, 1, 2 are handled in order), so
     * this is /dev/null missing: no safe way to go on. */
    _exit(125);
}

#if defined(__GLIBC__)
static ssize_t out_write(void *cookie, const char *buf, size_t n)
{
    (void)cookie;
    size_t done = 0;
    while (done < n) {
        const ssize_t k = write(STDOUT_FILENO, buf + done, n - done);
        if (k < 0 && errno == EINTR)
            continue;
        if (k <= 0) {
            if (!g_out_errno)
                g_out_errno = k < 0 ? errno : EIO;
            return (ssize_t)done; /* fewer than n: the stream sets its error flag */
        }
        done += (size_t)k;
    }
    return (ssize_t)n;
}

/* Standard output through a stream that keeps the reason of its first
 * failure; buffered as the C library would (lines on a terminal). */
static void install_stdout(void)
{
    static const cookie_io_functions_t io = {NULL, out_write, NULL, NULL};
    FILE *f = fopencookie(NULL, "w", io);
    if (!f)
        return; /* keep the C library's stream: the reason is then errno's */
    if (setvbuf(f, NULL, isatty(STDOUT_FILENO) ? _IOLBF : _IOFBF, BUFSIZ) != 0) {
        fclose(f);
        return;
    }
    g_orig_stdout = stdout;
    stdout = f;
}
#else
static void install_stdout(void)
{
}
#endif

void rch_stdio_begin(const char *prog)
{
    if (prog)
        g_prog = prog;
    for (int fd = 0; fd < 3; ++fd)
        open_null(fd);
    install_stdout();
}

int rch_stdio_errno(FILE *f)
{
    if (f == stdout && g_orig_stdout && g_out_errno)
        return g_out_errno;
    return errno;
}

int rch_stdio_end(int status)
{
    int err = 0, bad = ferror(stdout) != 0;
    if (bad)
        err = rch_stdio_errno(stdout);
    errno = 0;
    if (fflush(stdout) != 0 && !bad) {
        bad = 1;
        err = rch_stdio_errno(stdout);
    }
    if (g_orig_stdout) { /* ours: close it, then the descriptor */
        if (fclose(stdout) != 0 && !bad) {
            bad = 1;
            err = rch_stdio_errno(stdout);
        }
        stdout = g_orig_stdout;
        g_orig_stdout = NULL;
        errno = 0;
        if (close(STDOUT_FILENO) != 0 && !bad && errno != EBADF) {
            bad = 1;
            err = errno;
        }
    } else {
        errno = 0;
        if (fclose(stdout) != 0 && !bad) {
            bad = 1;
            err = errno;
        }
    }
    if (bad) {
        if (err == EBADF && g_was_closed[1])
            fprintf(stderr, "%s: write error on standard output: it is closed (%s); nothing written there\n",
                    g_prog, strerror(err));
        else if (err)
            fprintf(stderr, "%s: write error on standard output: %s; the output is incomplete\n", g_prog,
                    strerror(err));
        else
            fprintf(stderr, "%s: write error on standard output: %s; the output is incomplete\n", g_prog,
                    strerror(EIO)); /* the stream failed with no errno left: an I/O error, never no reason */
        if (status == 0)
            status = 1;
    }
    if ((ferror(stderr) || fflush(stderr) != 0) && status == 0)
        status = 1; /* a message was lost: it cannot be reported where it failed */
    return status;
}
