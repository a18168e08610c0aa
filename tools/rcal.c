/* rcal - command-line tool: acquisition, calibration, comparison, diagnosis,
 * compensation. Dispatches to tools/cmd_<name>.c. */
#include <stdio.h>
#include <string.h>

#include "rcal_cmds.h"

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
    fprintf(f, "usage: rcal COMMAND [options]   (rcal COMMAND --help for options)\n\ncommands:\n");
    for (size_t i = 0; i < sizeof commands / sizeof commands[0]; ++i)
        fprintf(f, "  %-11s %s\n", commands[i].name, commands[i].help);
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        usage(stderr);
        return 2;
    }
    if (strcmp(argv[1], "--help") == 0 || strcmp(argv[1], "-h") == 0 || strcmp(argv[1], "help") == 0) {
        usage(stdout);
        return 0;
    }
    for (size_t i = 0; i < sizeof commands / sizeof commands[0]; ++i)
        if (strcmp(argv[1], commands[i].name) == 0)
            return commands[i].fn(argc - 1, argv + 1);
    fprintf(stderr, "rcal: unknown command '%s'\n", argv[1]);
    usage(stderr);
    return 2;
}
