/* SPDX-License-Identifier: MIT */
/* rcal_cmds.h - the subcommands of the rcal command-line tool.
 *
 * Each subcommand lives in its own file tools/cmd_<name>.c and gets argv
 * starting at its own name (argv[0] == "calibrate"). Return value is the
 * process exit status: 0 success, 1 failure of the work, 2 usage error.
 */
#ifndef RCAL_CMDS_H
#define RCAL_CMDS_H

int rcal_cmd_calibrate(int argc, char **argv);  /* issue 2 */
int rcal_cmd_simulate(int argc, char **argv);   /* issue 2 */
int rcal_cmd_fkcheck(int argc, char **argv);    /* issue 2 */
int rcal_cmd_bench(int argc, char **argv);      /* benchmarks (all issues) */
int rcal_cmd_compare(int argc, char **argv);    /* issue 3 */
int rcal_cmd_chaos(int argc, char **argv);      /* issue 3 */
int rcal_cmd_acquire(int argc, char **argv);    /* issue 4 */
int rcal_cmd_poses(int argc, char **argv);      /* issue 4 */
int rcal_cmd_poses_touch(int argc, char **argv); /* issue 50: rcal poses --plate (cmd_poses_touch.c) */
int rcal_cmd_compensate(int argc, char **argv); /* issue 5 */
int rcal_cmd_grind(int argc, char **argv);      /* issue 5 */
int rcal_cmd_diagnose(int argc, char **argv);   /* issue 6 */
int rcal_cmd_evaluate(int argc, char **argv);   /* issue 10 */
int rcal_cmd_export(int argc, char **argv);     /* issue 13 */
int rcal_cmd_report(int argc, char **argv);     /* issue 13 */

#include <stdio.h>

/* --report FILE.html: rch_report_inline (tools/host/outputs/rch_report.h). */

/* The shared rule for a command's outputs, before any work: outs[n] (NULL
 * skipped) never name each other (nor, with html, the files of its report)
 * nor any of inputs[n_inputs]. 0, or 1 with the message on stderr
 * ("rcal CMD: ..."). */
int rcal_outputs_check(const char *cmd, const char *const *outs, const char *const *whats, size_t n,
                       const char *html, const char *const *inputs, size_t n_inputs);

#endif
