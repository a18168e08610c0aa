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

/* A NUL byte in the first line is refused where it stands (binary data, a device, UTF-16) before the rest
 * is read; one later (a power cut's) is left to the format's reader. */
static void test_read_file_nul(void **state)
{
    (void)state;
    char p[300];
    static const char body[] = "q1,L\0x,3\n";
    path_in(p, sizeof p, "nul.csv");
    FILE *f = fopen(p, "wb");
    assert_non_null(f);
    assert_int_equal(fwrite(body, 1, sizeof body - 1, f), sizeof body - 1);
    assert_int_equal(fclose(f), 0);
    char *t = NULL;
    size_t n = 7;
    rch_diag d;
    assert_int_equal(rch_read_file(&t, &n, p, 100, &d), -1);
    assert_null(t);
    assert_int_equal(n, 0);
    assert_int_equal(d.line, 1);
    assert_int_equal(d.col, 5);
    assert_non_null(strstr(d.msg, "NUL byte"));
    static const char later[] = "q1,L\n12,3\n\0\0";
    f = fopen(p, "wb");
    assert_non_null(f);
    assert_int_equal(fwrite(later, 1, sizeof later - 1, f), sizeof later - 1);
    assert_int_equal(fclose(f), 0);
    assert_int_equal(rch_read_file(&t, &n, p, 100, &d), 0);
    assert_int_equal(n, sizeof later - 1);
    free(t);
}

/* Child: a page and its CSV as one bundle, the CSV larger than the file-size
 * limit: 0 when the bundle was committed, 1 when refused. */
static int child_bundle(const char *page, const char *csv, long limit)
{
    signal(SIGXFSZ, SIG_IGN);
    struct rlimit r = {(rlim_t)limit, (rlim_t)limit};
    if (setrlimit(RLIMIT_FSIZE, &r) != 0)
        return 3;
    rch_out o[2];
    rch_diag d;
    if (rch_out_open(&o[0], page, "--out", NULL, 0, &d) != 0)
        return 2;
    if (rch_out_open(&o[1], csv, "--out (plot data)", NULL, 0, &d) != 0) {
        rch_out_abort(&o[0]);
        return 2;
    }
    fputs("<html>new page</html>\n", o[0].f);
    for (int i = 0; i < 20; ++i)
        fputs("a,b,c,d,e,f,g,h\n", o[1].f);
    return rch_out_commit_all(o, 2, &d) == 0 ? 0 : 1;
}

/* Issue 23: a report and its CSVs are written whole or not at all (the
 * page is not renamed into place before every CSV was written). */
static void test_bundle_whole_or_nothing(void **state)
{
    (void)state;
    char page[300], csv[300];
    path_in(page, sizeof page, "x.html");
    path_in(csv, sizeof csv, "x_params.csv");
    put(page, "old page");
    for (long limit = 100; limit <= 1000; limit += 900) {
        pid_t pid = fork();
        assert_true(pid >= 0);
        if (pid == 0)
            _exit(child_bundle(page, csv, limit));
        int st = 0;
        waitpid(pid, &st, 0);
        assert_true(WIFEXITED(st));
        if (limit == 100) { /* the CSV does not fit: nothing of the bundle is in place */
            assert_int_equal(WEXITSTATUS(st), 1);
            assert_string_equal(get(page), "old page");
            assert_null(get(csv));
            assert_int_equal(count_entries(), 1); /* no temporary left */
        } else {
            assert_int_equal(WEXITSTATUS(st), 0);
            assert_string_equal(get(page), "<html>new page</html>\n");
            assert_non_null(get(csv));
            assert_int_equal(count_entries(), 2);
        }
    }
}

/* Issue 23: one command's outputs never name each other: by inode when the
 * file exists, by normalised path when it does not; links resolved. */
static void test_outputs_distinct(void **state)
{
    (void)state;
    char a[300], a2[300], b[300], l[300], sub[300];
    path_in(a, sizeof a, "new.json");
    path_in(a2, sizeof a2, "sub/../new.json");
    path_in(b, sizeof b, "other.json");
    path_in(l, sizeof l, "link.json");
    path_in(sub, sizeof sub, "sub");
    assert_int_equal(mkdir(sub, 0700), 0);
    assert_int_equal(symlink("new.json", l), 0); /* dangling until new.json exists */
    assert_int_equal(rch_path_same(a, a2), 1);
    assert_int_equal(rch_path_same(a, l), 1);
    assert_int_equal(rch_path_same(a, b), 0);
    const char *const outs[3] = {a, b, a2}, *const whats[3] = {"--out", "--residuals", "--report"};
    rch_diag d;
    assert_int_equal(rch_outs_distinct(outs, whats, 2, &d), 0);
    assert_int_equal(rch_outs_distinct(outs, whats, 3, &d), -1);
    assert_non_null(strstr(d.msg, "--report"));
    assert_non_null(strstr(d.msg, "same file as --out"));
    /* the same rule inside rch_out_open, for every output of the command */
    rch_out_one_command();
    rch_out o1, o2;
    assert_int_equal(rch_out_open(&o1, a, "--out", NULL, 0, &d), 0);
    assert_int_equal(rch_out_open(&o2, l, "--residuals", NULL, 0, &d), -1);
    assert_non_null(strstr(d.msg, "same file as --out"));
    fputs("model", o1.f);
    assert_int_equal(rch_out_commit(&o1, &d), 0);
    assert_int_equal(rch_out_open(&o2, a2, "--report", NULL, 0, &d), -1); /* now by inode */
    assert_int_equal(rch_out_open(&o2, b, "--residuals", NULL, 0, &d), 0);
    rch_out_abort(&o2);
    rch_out_one_command(); /* a new command: nothing remembered */
    assert_int_equal(rch_out_open(&o2, a, "--out", NULL, 0, &d), 0);
    rch_out_abort(&o2);
    assert_string_equal(get(a), "model");
}

/* Issue 23: through a link the target is replaced (the link stays), the
 * mode is kept, a read-only file is refused. */
static void test_link_mode_readonly(void **state)
{
    (void)state;
    char t[300], l[300], ro[300];
    path_in(t, sizeof t, "target.csv");
    path_in(l, sizeof l, "link.csv");
    path_in(ro, sizeof ro, "ro.csv");
    put(t, "old");
    assert_int_equal(chmod(t, 0640), 0);
    assert_int_equal(symlink("target.csv", l), 0);
    rch_out o;
    rch_diag d;
    assert_int_equal(rch_out_open(&o, l, "--out", NULL, 0, &d), 0);
    fputs("new", o.f);
    assert_int_equal(rch_out_commit(&o, &d), 0);
    struct stat st;
    assert_int_equal(lstat(l, &st), 0);
    assert_true(S_ISLNK(st.st_mode));
    assert_string_equal(get(t), "new");
    assert_int_equal(stat(t, &st), 0);
    assert_int_equal(st.st_mode & 07777, 0640);
    put(ro, "keep");
    assert_int_equal(chmod(ro, 0444), 0);
    assert_int_equal(rch_out_open(&o, ro, "--out", NULL, 0, &d), -1);
    assert_non_null(strstr(d.msg, "read-only (mode 0444)"));
    assert_string_equal(get(ro), "keep");
    assert_int_equal(count_entries(), 3);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(test_refuses_inputs_by_inode, setup, teardown),
        cmocka_unit_test_setup_teardown(test_atomic_replace_and_abort, setup, teardown),
        cmocka_unit_test_setup_teardown(test_fault_after_every_byte, setup, teardown),
        cmocka_unit_test_setup_teardown(test_read_file_limit, setup, teardown),
        cmocka_unit_test_setup_teardown(test_bundle_whole_or_nothing, setup, teardown),
        cmocka_unit_test_setup_teardown(test_outputs_distinct, setup, teardown),
        cmocka_unit_test_setup_teardown(test_read_file_nul, setup, teardown),
        cmocka_unit_test_setup_teardown(test_link_mode_readonly, setup, teardown),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
