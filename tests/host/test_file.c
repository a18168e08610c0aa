/* SPDX-License-Identifier: MIT */
/* test_file.c - outputs never destroy an input or a finished file:
 * refusal by device and inode whatever the spelling, atomic replacement, and
 * a fault injected after every byte of the new file (RLIMIT_FSIZE in a child
 * process): the old file survives intact and the new one is complete or
 * absent, with no temporary left behind. */
#include <dirent.h>
#include <setjmp.h>
#include <signal.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmocka.h>

#include "rch_file.h"

static char dir[256];

static void path_in(char *buf, size_t len, const char *name)
{
    snprintf(buf, len, "%s/%s", dir, name);
}

static void put(const char *path, const char *text)
{
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fputs(text, f);
    fclose(f);
}

static char *get(const char *path)
{
    static char buf[8192];
    FILE *f = fopen(path, "r");
    if (!f)
        return NULL;
    size_t n = fread(buf, 1, sizeof buf - 1, f);
    buf[n] = '\0';
    fclose(f);
    return buf;
}

static int count_entries(void)
{
    DIR *d = opendir(dir);
    int n = 0;
    for (struct dirent *e; (e = readdir(d));)
        n += e->d_name[0] != '.';
    closedir(d);
    return n;
}

static int setup(void **state)
{
    (void)state;
    snprintf(dir, sizeof dir, "/tmp/rch_file_XXXXXX");
    return mkdtemp(dir) ? 0 : -1;
}

static int teardown(void **state)
{
    (void)state;
    char cmd[300];
    snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
    return system(cmd) == 0 ? 0 : -1;
}

static void test_refuses_inputs_by_inode(void **state)
{
    (void)state;
    char in[300], alias[300], hard[300], other[300];
    path_in(in, sizeof in, "data.csv");
    put(in, "q1,L\n1,2\n");
    snprintf(alias, sizeof alias, "%s/./../%s/data.csv", dir, strrchr(dir, '/') + 1);
    path_in(hard, sizeof hard, "hard.csv");
    assert_int_equal(link(in, hard), 0);
    path_in(other, sizeof other, "link.csv");
    assert_int_equal(symlink(in, other), 0);
    const char *inputs[] = {NULL, in};
    const char *outs[] = {in, alias, hard, other};
    for (size_t k = 0; k < 4; ++k) {
        rch_out o;
        rch_diag d;
        memset(&d, 0, sizeof d);
        assert_int_equal(rch_out_open(&o, outs[k], "--out", inputs, 2, &d), -1);
        assert_non_null(strstr(d.msg, "--out names the same file as the input"));
    }
    assert_string_equal(get(in), "q1,L\n1,2\n");
    assert_int_equal(count_entries(), 3); /* no temporary left */
    assert_int_equal(rch_same_file(in, hard), 1);
    assert_int_equal(rch_same_file(in, "/nonexistent/x"), 0);
}

static void test_atomic_replace_and_abort(void **state)
{
    (void)state;
    char out[300];
    path_in(out, sizeof out, "model.json");
    put(out, "old");
    rch_out o;
    rch_diag d;
    assert_int_equal(rch_out_open(&o, out, "--out", NULL, 0, &d), 0);
    fputs("new", o.f);
    assert_string_equal(get(out), "old"); /* nothing visible before commit */
    rch_out_abort(&o);
    assert_string_equal(get(out), "old");
    assert_int_equal(rch_out_open(&o, out, "--out", NULL, 0, &d), 0);
    fputs("new content", o.f);
    assert_int_equal(rch_out_commit(&o, &d), 0);
    assert_string_equal(get(out), "new content");
    struct stat st;
    assert_int_equal(stat(out, &st), 0);
    assert_true((st.st_mode & 0044) != 0 || (umask(022) & 0044)); /* not left 0600 */
    char devnull[] = "/dev/null";
    assert_int_equal(rch_out_open(&o, devnull, "--out", NULL, 0, &d), -1); /* not a regular file */
}

/* Child: replace `out` with `text` under a file-size limit of `limit` bytes. */
static int child_write(const char *out, const char *text, long limit)
{
    signal(SIGXFSZ, SIG_IGN);
    struct rlimit r = {(rlim_t)limit, (rlim_t)limit};
    if (setrlimit(RLIMIT_FSIZE, &r) != 0)
        return 3;
    rch_out o;
    rch_diag d;
    if (rch_out_open(&o, out, "--out", NULL, 0, &d) != 0)
        return 1;
    setvbuf(o.f, NULL, _IONBF, 0); /* fail at the exact byte */
    if (fputs(text, o.f) == EOF) {
        rch_out_abort(&o);
        return 1;
    }
    return rch_out_commit(&o, &d) == 0 ? 0 : 1;
}

static void test_fault_after_every_byte(void **state)
{
    (void)state;
    char out[300], expect_old[600];
    path_in(out, sizeof out, "prog.csv");
    const char *old_text = "q1,q2,q3,q4,q5,q6\n1,2,3,4,5,6\n";
    const char *new_text = "q1,q2,q3,q4,q5,q6\n10,20,30,40,50,60\n11,21,31,41,51,61\n";
    size_t n = strlen(new_text);
    unsigned failed = 0, done = 0;
    for (size_t limit = 0; limit <= n + 1; ++limit) {
        put(out, old_text);
        snprintf(expect_old, sizeof expect_old, "%s", old_text);
        pid_t pid = fork();
        assert_true(pid >= 0);
        if (pid == 0)
            _exit(child_write(out, new_text, (long)limit));
        int st = 0;
        waitpid(pid, &st, 0);
        assert_true(WIFEXITED(st));
        const char *now = get(out);
        assert_non_null(now);
        if (WEXITSTATUS(st) == 0) {
            assert_string_equal(now, new_text); /* complete */
            ++done;
        } else {
            assert_int_equal(WEXITSTATUS(st), 1);
            assert_string_equal(now, expect_old); /* old file intact */
            ++failed;
        }
        assert_int_equal(count_entries(), 1); /* no temporary left behind */
    }
    /* Every limit below the size failed, the others succeeded. */
    assert_int_equal(failed, n);
    assert_int_equal(done, 2);
    print_message("fault after every byte: %u failed writes left the old file intact, %u complete\n", failed, done);
}

static void test_read_file_limit(void **state)
{
    (void)state;
    char p[300];
    path_in(p, sizeof p, "big.txt");
    put(p, "0123456789");
    char *t;
    size_t n;
    rch_diag d;
    assert_int_equal(rch_read_file(&t, &n, p, 10, &d), 0);
    assert_int_equal(n, 10);
    free(t);
    assert_int_equal(rch_read_file(&t, &n, p, 9, &d), -1);
    assert_non_null(strstr(d.msg, "limit of 9 bytes"));
    assert_int_equal(rch_read_file(&t, &n, "/nonexistent/x", 9, &d), -1);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(test_refuses_inputs_by_inode, setup, teardown),
        cmocka_unit_test_setup_teardown(test_atomic_replace_and_abort, setup, teardown),
        cmocka_unit_test_setup_teardown(test_fault_after_every_byte, setup, teardown),
        cmocka_unit_test_setup_teardown(test_read_file_limit, setup, teardown),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
