/* SPDX-License-Identifier: MIT */
/* rch_paths.c - run-time location of the data files (rch_paths.h). */
#include "rch_paths.h"

#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* Set by tools/CMakeLists.txt. */
#ifndef RCH_BIN_TO_DATA
#define RCH_BIN_TO_DATA "../share/rcal"
#endif

#ifndef PATH_MAX
#define PATH_MAX 4096
#endif

/* dir + "/" + file into buf; 0 when it fits, -1 when not. */
static int join(char *buf, size_t len, const char *dir, const char *file)
{
    int n = snprintf(buf, len, "%s/%s", dir, file);
    if (n < 0 || (size_t)n >= len) {
        if (len > 0)
            buf[0] = '\0';
        return -1;
    }
    return 0;
}

/* Directory of the running program into dir (PATH_MAX); 0 or -1. */
static int exe_dir(char dir[PATH_MAX])
{
    ssize_t n = readlink("/proc/self/exe", dir, PATH_MAX - 1);
    if (n <= 0)
        return -1;
    dir[n] = '\0';
    char *slash = strrchr(dir, '/');
    if (slash == NULL)
        return -1;
    *slash = '\0';
    return 0;
}

/* Is the directory `dir` inside (or equal to) `root`? */
static int is_under(const char *dir, const char *root)
{
    size_t n = strlen(root);
    return n > 0 && strncmp(dir, root, n) == 0 && (dir[n] == '\0' || dir[n] == '/');
}

int rch_data_path(char *buf, size_t len, const char *file)
{
    char dir[PATH_MAX], cand[PATH_MAX];
    const char *env = getenv("RCAL_DATA_DIR");
    if (env != NULL && env[0] != '\0' && join(cand, sizeof cand, env, file) == 0 && access(cand, R_OK) == 0)
        return join(buf, len, env, file);

    int have_exe = exe_dir(dir) == 0;
#if defined(RCH_BUILD_DIR) && defined(RCH_SOURCE_DATA_DIR)
    int in_build_tree = have_exe && is_under(dir, RCH_BUILD_DIR);
#else
    (void)is_under;
#endif
    char installed[PATH_MAX] = "";
    if (have_exe) {
        char data[PATH_MAX];
        /* dir is canonical (the kernel's path of the program): each leading
         * "../" of RCH_BIN_TO_DATA removes its last component. */
        const char *rel = RCH_BIN_TO_DATA;
        char *slash;
        while (strncmp(rel, "../", 3) == 0 && (slash = strrchr(dir, '/')) != NULL && slash != dir) {
            *slash = '\0';
            rel += 3;
        }
        if (join(data, sizeof data, dir, rel) == 0 && join(installed, sizeof installed, data, file) == 0 &&
            access(installed, R_OK) == 0)
            return join(buf, len, data, file);
    }
#if defined(RCH_BUILD_DIR) && defined(RCH_SOURCE_DATA_DIR)
    if (in_build_tree && join(cand, sizeof cand, RCH_SOURCE_DATA_DIR, file) == 0 && access(cand, R_OK) == 0)
        return join(buf, len, RCH_SOURCE_DATA_DIR, file);
#endif
    /* Not found: the installed place, or the bare name, for the message. */
    if (installed[0] != '\0' && strlen(installed) < len)
        memcpy(buf, installed, strlen(installed) + 1);
    else if (strlen(file) < len)
        memcpy(buf, file, strlen(file) + 1);
    else if (len > 0)
        buf[0] = '\0';
    return -1;
}

const char *rch_default_robot(void)
{
    static char path[PATH_MAX];
    if (path[0] == '\0')
        (void)rch_data_path(path, sizeof path, "irb120.json");
    return path;
}
