/* SPDX-License-Identifier: MIT */
/* rcal - command-line tool: acquisition, calibration, comparison, diagnosis,
 * compensation. Dispatches to tools/cmd_<name>.c. */
#include <stdio.h>
#if defined(__GLIBC__)
#include <malloc.h>
#endif
#include <string.h>

#include "rc_config.h"
#include "rcal_cmds.h"
#include "rch_file.h"
#include "rch_lapack.h"
#include "rch_paths.h"
#include "rch_stdio.h"

typedef struct {
    const char *name;
    int (*fn)(int argc, char **argv);
    const char *help;
} rcal_command;

static const rcal_command commands[] = {
    {"calibrate", rcal_cmd_calibrate, "identify DH errors and the encoder position from cable lengths"},
    {"simulate", rcal_cmd_simulate, "generate a data set from a simulated robot with known errors"},
    {"fkcheck", rcal_cmd_fkcheck, "compare forward kinematics with a file's x, y, z columns"},
    {"compare", rcal_cmd_compare, "run the paper's seven identification methods on identical splits"},
    {"chaos", rcal_cmd_chaos, "uniformity study of the logistic-tent chaotic map"},
    {"acquire", rcal_cmd_acquire, "record cable lengths from the encoder display over a serial port"},
    {"poses", rcal_cmd_poses, "plan an identifiable pose set inside the joint limits"},
    {"compensate", rcal_cmd_compensate, "correct joint targets with a calibrated model"},
    {"grind", rcal_cmd_grind, "grinding-path experiment: deviation with and without compensation"},
    {"diagnose", rcal_cmd_diagnose, "find the physical effect the model misses"},
    {"evaluate", rcal_cmd_evaluate, "a calibrated model on new data, no refit; ISO 9283 distance figures"},
    {"bench", rcal_cmd_bench, "benchmarks: calibration time, compensation latency, parser speed"},
    {"export", rcal_cmd_export, "export a model as a URDF or a DH table in CSV"},
    {"report", rcal_cmd_report, "an HTML report of a calibration run (self-contained, plots inline)"},
};

static void usage(FILE *f)
{
    fprintf(f, "usage: rcal COMMAND [options]   (rcal COMMAND --help for options)\n"
               "       rcal --version | -V\n\ncommands:\n");
    for (size_t i = 0; i < sizeof commands / sizeof commands[0]; ++i)
        fprintf(f, "  %-11s %s\n", commands[i].name, commands[i].help);
}

/* Version of the program and of the core it runs with, the compile-time
 * limits, the robot model it would load by default and the BLAS/LAPACK it
 * computes with. */
static int version(void)
{
    char robot[4096];
    int found = rch_data_path(robot, sizeof robot, "irb120.json") == 0;
    printf("rcal %s\n", RC_VERSION_STRING);
    printf("core library %s\n", rc_version());
    printf("limits: RC_MAX_PARAMS %d, RC_MAX_EFFECTS %d\n", RC_MAX_PARAMS, RC_MAX_EFFECTS);
    printf("robot model: %s%s\n", robot, found ? "" : " (not found; set RCAL_DATA_DIR)");
    rch_lapack_info la;
    char line[3 * RCH_LAPACK_PATH];
    rch_lapack_get(&la);
    printf("BLAS/LAPACK: %s\n", rch_lapack_line(line, sizeof line, &la));
    return 0;
}

static int run(int argc, char **argv)
{
#if defined(__GLIBC__)
    /* A calibration allocates and frees a few matrices of 100-250 KB (the
     * Jacobian, its copies for the SVD and the covariance). Above glibc's
     * default 128 KB each one is a fresh mmap, faulted in page by page and
     * unmapped at free; kept on the heap, the next one reuses those pages:
     * 370 -> 290 page faults and 0.5 ms of the real data's 12 ms
     * (perf stat -e page-faults; scripts/bench_ceres.sh). */
    mallopt(M_MMAP_THRESHOLD, 64 << 20);
    mallopt(M_TRIM_THRESHOLD, 128 << 20);
#endif
    if (argc < 2) {
        usage(stderr);
        return 2;
    }
    if (strcmp(argv[1], "--help") == 0 || strcmp(argv[1], "-h") == 0 || strcmp(argv[1], "help") == 0) {
        usage(stdout);
        return 0;
    }
    if (strcmp(argv[1], "--version") == 0 || strcmp(argv[1], "-V") == 0)
        return version();
    for (size_t i = 0; i < sizeof commands / sizeof commands[0]; ++i)
        if (strcmp(argv[1], commands[i].name) == 0)
            return commands[i].fn(argc - 1, argv + 1);
    fprintf(stderr, "rcal: unknown command '%s'\n", argv[1]);
    usage(stderr);
    return 2;
}

/* Closed standard descriptors are opened on /dev/null before anything else
 * (no file ever takes them); every write to standard output and standard
 * error is checked at the end (tools/host/files/rch_stdio.h). */
int main(int argc, char **argv)
{
    rch_stdio_begin("rcal");
    rch_out_one_command(); /* its outputs never name each other (tools/host/files/rch_file.h) */
    return rch_stdio_end(run(argc, argv));
}
