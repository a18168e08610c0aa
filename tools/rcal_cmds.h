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
int rcal_cmd_compensate(int argc, char **argv); /* issue 5 */
int rcal_cmd_grind(int argc, char **argv);      /* issue 5 */
int rcal_cmd_diagnose(int argc, char **argv);   /* issue 6 */
int rcal_cmd_evaluate(int argc, char **argv);   /* issue 10 */
int rcal_cmd_export(int argc, char **argv);     /* issue 13 */
int rcal_cmd_report(int argc, char **argv);     /* issue 13 */

#include <stdio.h>

/* --report FILE.html of calibrate and diagnose (tools/cmd_report.c): the
 * page of `rcal report` from this run. cal (required) and diag (may be NULL)
 * are the run's results; their JSON, as --json of this command line
 * (argc, argv) prints it, is kept beside the page as FILE.calibration.json
 * and FILE.diagnosis.json (never over an input), and rch_report_write reads
 * them in this process. model: the model file written by the run, or NULL.
 * inputs (n_inputs): the run's input files, which no output of the report
 * may replace. quiet: no message on stderr. 0, or 1 with the message on
 * stderr. */
struct rch_calib_result;
struct rch_diagnose_result;
int rcal_report_inline(const char *html, const struct rch_calib_result *cal, const struct rch_diagnose_result *diag,
                       int argc, char **argv, const char *model, const char *const *inputs, size_t n_inputs,
                       int quiet);

/* Every file --report HTML writes besides the page (its JSON, the plot data),
 * for the check that a command's outputs never name each other before the
 * work: names[k] (k < RCAL_REPORT_BUNDLE), what[k] the option that makes it.
 * Returns the count. */
#define RCAL_REPORT_BUNDLE 6
#define RCAL_REPORT_NAME 1100
size_t rcal_report_bundle(char names[RCAL_REPORT_BUNDLE][RCAL_REPORT_NAME], const char *html);

/* The shared rule for a command's outputs, before any work: outs[n] (NULL
 * skipped) never name each other (nor, with html, the files of its report)
 * nor any of inputs[n_inputs]. 0, or 1 with the message on stderr
 * ("rcal CMD: ..."). */
int rcal_outputs_check(const char *cmd, const char *const *outs, const char *const *whats, size_t n,
                       const char *html, const char *const *inputs, size_t n_inputs);

#endif
