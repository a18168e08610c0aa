/* SPDX-License-Identifier: MIT */
/* cmd_compensate.c - rcal compensate: correct a robot program's joint targets
 * with a calibrated model. Options here; the work is rch_comp_run
 * (tools/host/comp/rch_comp.h: CSV and RAPID forms, safe output files). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rcal_cmds.h"
#include "rch_comp.h"
#include "rch_jw.h"
#include "rch_opt.h"

static const char summary[] =
    "correct joint targets computed with the nominal model so that the calibrated robot reaches the nominal "
    "flange pose: q' with FK_cal(q') = FK_nom(q)";
static const char details[] =
    "Input: csv lines of q1..q6 in degrees, with or without a header (other columns are copied), or an ABB RAPID "
    "module: every jointtarget and robtarget literal (declarations, inline in instructions, assignments) is "
    "corrected, every other byte copied; a robtarget through the nominal IK with its confdata, written as the "
    "nominal pose of the corrected joints (tool0, or the --tool TCP; base frame). A RAPID target that cannot be "
    "corrected is named with line, column and reason and nothing is written. A Universal Robots URScript program "
    "goes through the same way: the joint lists and p[...] poses of movej/movel/movep/movec, get_inverse_kin and "
    "assignments, a pose through the nominal IK nearest the previous target's joints (or qnear) at set_tcp's TCP "
    "(docs/comp-urscript.md). A target that does not converge is written as the "
    "closest point found within the bounds (the target plus the last good correction when it follows the previous "
    "target on a path), with a warning naming the cause and its position error; the exit status is then 1.";

/* Why the orientation is or is not corrected (issue 47). */
static void print_orientation(const rch_comp_result *r)
{
    if (r->mode_forced) {
        fprintf(stderr, "rcal compensate: orientation %s (forced by %s)\n",
                r->position_only_used ? "not corrected" : "corrected",
                r->position_only_used ? "--position-only" : "--full-pose");
    } else if (r->orient.known) {
        fprintf(stderr,
                "rcal compensate: orientation %s: position only, the calibrated model leaves the tool's axis (the "
                "flange z axis) %.4f deg off the nominal one (RMS over the joint limits); corrected, its predicted "
                "error is %.4f deg: correcting is expected to leave the axis %s (--position-only / --full-pose "
                "force either)\n",
                r->position_only_used ? "not corrected" : "corrected", r->orient.uncorr_deg, r->orient.unc_deg,
                r->position_only_used ? (r->orient.tie ? "closer, but within 10 %: a tie, decided for the joints "
                                                         "that move least"
                                                       : "no closer than not correcting")
                                      : "closer than not correcting");
    } else {
        fprintf(stderr, "rcal compensate: orientation %s (the model carries no uncertainty to weigh it by)\n",
                r->position_only_used ? "not corrected" : "corrected");
    }
}

/* Which parameters the corrections came from (issue 10). */
static void print_sources(const rch_comp_result *r, const char *model)
{
    fprintf(stderr, "rcal compensate: corrections from %u of 24 DH parameters of %s%s; held at nominal: %s\n",
            24u - r->n_held, model,
            r->version1 ? " (a version-1 model: the held ones from the nominal model's identifiability)" : "",
            r->n_held ? r->held : "none");
    char u95[64] = "n/a (the model carries no uncertainty)";
    if (!isnan(r->max_pos95_mm))
        snprintf(u95, sizeof u95, "%.4f mm", r->max_pos95_mm);
    fprintf(stderr,
            "rcal compensate: the held parameters' fitted values would have moved the flange by up to %.4f mm at "
            "these targets; mode %s (orientation %s by the data); largest 95 %% position uncertainty at a "
            "compensated target %s; %lu targets left uncompensated for their uncertainty\n",
            r->max_held_mm, r->position_only_used ? "position only" : "position and orientation",
            r->orientation_determined ? "determined" : "not determined", u95, r->n_uncertain);
    print_orientation(r);
}

/* Targets, iterations, largest correction and time (--summary). */
static void print_summary(const rch_comp_result *rp)
{
    const rch_comp_result r = *rp;
    char fails[160] = "";
    if (r.n_fail > 0)
        snprintf(fails, sizeof fails, " (%lu at a joint limit; largest position error written %.4f mm)",
                 r.n_joint_limit, r.max_fail_err_mm);
    fprintf(stderr,
            "rcal compensate: %lu target%s, %lu not converged%s, %lu with the orientation best effort (position "
            "matched), %.2f iterations/target, largest correction %.4f deg, %.2f us/target\n",
            r.n, r.n == 1 ? "" : "s", r.n_fail, fails, r.n_pos_only, r.n ? (double)r.iters / (double)r.n : 0.0,
            r.max_corr_deg, r.n ? r.t_ns / (double)r.n / 1e3 : 0.0);
}

/* The targets the warnings name ("IN:LINE: warning: TEXT" lines of
 * rch_comp_run), each with its line, what happened and the message. */
static void json_targets(rch_jw *w, const char *warnings)
{
    rch_jw_arr(w, "targets_not_corrected");
    for (const char *p = warnings; p && *p;) {
        const char *eol = strchr(p, '\n'), *tag = strstr(p, ": warning: ");
        const size_t len = eol ? (size_t)(eol - p) : strlen(p);
        if (tag && tag < p + len) {
            const char *num = tag;
            while (num > p && num[-1] >= '0' && num[-1] <= '9')
                --num;
            const char *text = tag + 11;
            char msg[512];
            snprintf(msg, sizeof msg, "%.*s", (int)(p + len - text), text);
            if (num < tag && num > p && num[-1] == ':') {
                rch_jw_obj(w, NULL);
                rch_jw_uint(w, "line", strtoull(num, NULL, 10));
                rch_jw_str(w, "exit", strstr(msg, "left uncompensated") ? "left_uncertain"
                                      : strstr(msg, "not compensated")    ? "not_converged"
                                                                          : "warning");
                rch_jw_str(w, "message", msg);
                rch_jw_end(w);
            }
        }
        p += len + (eol ? 1 : 0);
    }
    rch_jw_end(w);
}

/* The --summary figures as one JSON object on stdout (rcal-compensate/1). */
static int summary_json(const rch_comp_result *r, const rch_comp_job *job, int rc, const char *warnings, int argc,
                        char **argv)
{
    const char *const files[] = {"model", job->model_path, "nominal", job->nominal_path, "in", job->in_path,
                                 "out", job->out_path, "input_format",
                                 r->format == RCH_COMP_RAPID ? "rapid" : r->format == RCH_COMP_FANUC ? "fanuc"
                                 : r->format == RCH_COMP_URSCRIPT ? "urscript"
                                 : r->format == RCH_COMP_KRL ? "krl" : "csv",
                                 NULL};
    rch_jw w;
    rch_jw_begin(&w, stdout, 0, "rcal-compensate/1", argc, argv);
    rch_jw_strs(&w, files);
    rch_jw_int(&w, "exit", rc == 0 ? 0 : 1);
    rch_jw_uint(&w, "targets", r->n + r->n_uncertain);
    rch_jw_uint(&w, "corrected", r->n - r->n_fail);
    rch_jw_uint(&w, "not_converged", r->n_fail);
    rch_jw_uint(&w, "not_converged_joint_limit", r->n_joint_limit);
    rch_jw_uint(&w, "orientation_best_effort", r->n_pos_only);
    rch_jw_uint(&w, "left_uncertain", r->n_uncertain);
    rch_jw_uint(&w, "robtargets", r->n_robtargets);
    rch_jw_uint(&w, "left_robtargets", 0); /* kept for readers of rcal-compensate/1: robtargets are corrected */
    rch_jw_num(&w, "largest_correction_deg", r->max_corr_deg);
    rch_jw_num(&w, "largest_fail_error_mm", r->n_fail ? r->max_fail_err_mm : NAN);
    rch_jw_num(&w, "iterations_per_target", r->n ? (double)r->iters / (double)r->n : NAN);
    rch_jw_num(&w, "time_us_per_target", r->n ? r->t_ns / (double)r->n / 1e3 : NAN);
    rch_jw_str(&w, "mode", r->position_only_used ? "position" : "pose");
    rch_jw_bool(&w, "orientation_determined", r->orientation_determined);
    rch_jw_num(&w, "max_uncertainty_mm", job->max_unc_mm);
    rch_jw_num(&w, "largest_pos95_mm", r->max_pos95_mm); /* null: unknown (no uncertainty in the model) */
    rch_jw_obj(&w, "orientation");
    rch_jw_bool(&w, "corrected", !r->position_only_used);
    rch_jw_str(&w, "chosen_by", r->mode_forced ? "option" : r->orient.known ? "uncertainty" : "model_file");
    rch_jw_num(&w, "uncorrected_rms_deg", r->orient.known ? r->orient.uncorr_deg : NAN);
    rch_jw_num(&w, "correction_error_rms_deg", r->orient.known ? r->orient.unc_deg : NAN);
    rch_jw_end(&w);
    json_targets(&w, warnings);
    rch_jw_obj(&w, "params");
    rch_jw_uint(&w, "dh_used", 24u - r->n_held);
    rch_jw_arr(&w, "dh_held"); /* names, held at nominal */
    for (const char *p = r->held; *p;) {
        char nm[32];
        size_t k = 0;
        while (p[k] && p[k] != ' ')
            ++k;
        snprintf(nm, sizeof nm, "%.*s", (int)k, p);
        rch_jw_str(&w, NULL, nm);
        p += k + (p[k] == ' ');
    }
    rch_jw_end(&w);
    rch_jw_bool(&w, "held_from_nominal_identifiability", r->version1);
    rch_jw_num(&w, "held_max_flange_mm", r->max_held_mm);
    rch_jw_bool(&w, "model_has_nominal", !r->no_nominal);
    rch_jw_end(&w);
    rch_jw_end(&w);
    return rch_jw_finish(&w);
}

/* Options that exclude each other; 1 when they fit. */
static int args_fit(int position_only, int full_pose, int json, const char *out)
{
    if (position_only && full_pose) {
        fprintf(stderr, "rcal compensate: --position-only and --full-pose exclude each other\n");
        return 0;
    }
    if (json && strcmp(out, "-") == 0) {
        fprintf(stderr, "rcal compensate: --json needs --out FILE (the targets would share stdout)\n");
        return 0;
    }
    return 1;
}

/* rch_comp_run, its warnings on stderr; with --json they are also read back
 * into *warn_text (for the JSON; the caller frees it). */
static int run_job(rch_comp_result *r, const rch_comp_job *job, int json, char **warn_text)
{
    rch_diag d;
    char msg[1024];
    size_t warn_len = 0;
    FILE *warn = json ? open_memstream(warn_text, &warn_len) : NULL;
    const int rc = rch_comp_run(r, job, warn ? warn : stderr, &d);
    if (warn && fclose(warn) == 0 && *warn_text)
        fputs(*warn_text, stderr);
    if (r->no_nominal)
        fprintf(stderr, "rcal compensate: warning: %s has no \"nominal\" table; only its effects are corrected\n",
                job->model_path);
    if (rc < 0)
        fprintf(stderr, "rcal compensate: %s\n", rch_diag_str(&d, msg, sizeof msg));
    return rc;
}

int rcal_cmd_compensate(int argc, char **argv)
{
    const char *model = NULL, *nominal = NULL, *in = "-", *out = "-", *format = "auto";
    double max_dev_deg = 0.1 * 57.295779513082323; /* 0.1 rad, shown as the default */
    int position_only = 0, full_pose = 0, want_summary = 0, accept_rt = 0, json = 0, assume_deg = 0;
    double max_unc_mm = 0.0, tool[3] = {0.0, 0.0, 0.0};
    const char *unc_out = NULL, *u95_policy = "skip", *fanuc_frames = NULL;
    rch_cmdspec spec;
    const rch_opt opts[] = {
        {"--model", RCH_OPT_STR, &model, 0, 0, "MODEL.json", "calibrated model (rcal-model/2 or /1, from rcal calibrate --out)",
         RCH_OPT_REQUIRED, NULL},
        {"--nominal", RCH_OPT_STR, &nominal, 0, 0, "ROBOT.json",
         "nominal model the targets were made with (default: the model file's \"nominal\" table)", 0, NULL},
        {"--in", RCH_OPT_STR, &in, 0, 0, "FILE|-", "targets (default standard input)", 0, NULL},
        {"--out", RCH_OPT_STR, &out, 0, 0, "FILE|-",
         "result (default standard output, flushed per line; a RAPID module at the end, whole); a file is replaced only when complete, and never "
         "when it is the input or a model",
         0, NULL},
        {"--tool", RCH_OPT_TRIPLE, tool, -2000.0, 2000.0, "X,Y,Z",
         "the TCP to place, mm in the flange frame (default: the flange centre; never the cable attachment the "
         "calibration measured); RAPID robtargets are then poses of this TCP with tool0's orientation (an ABB "
         "tooldata trans [x,y,z] is -x,-y,z here)",
         0, NULL},
        {"--uncertainty-out", RCH_OPT_STR, &unc_out, 0, 0, "FILE.csv",
         "per target (its input line) the predicted 95 % position uncertainty u95_mm of the compensated point, "
         "from the calibration's posterior covariance (prior-only directions included)",
         0, NULL},
        {"--position-only", RCH_OPT_FLAG, &position_only, 0, 0, NULL,
         "match the position of the flange (or the --tool TCP) only, whatever the model's orientation", 0, NULL},
        {"--full-pose", RCH_OPT_FLAG, &full_pose, 0, 0, NULL,
         "match position and orientation (default: the orientation is corrected when the calibrated flange "
         "orientation differs from nominal by more than the correction's predicted error, sqrt 2 x its RMS; "
         "--summary says which and why)",
         0, NULL},
        {"--max-uncertainty-mm", RCH_OPT_DOUBLE, &max_unc_mm, 0.0, 1000.0, "MM",
         "leave a target uncompensated (with a warning) where the model's 95 % position uncertainty is larger "
         "(0: no limit for a model with a posterior, whose compensation never widens the error; 1 mm for one "
         "without)", 0, NULL},
        {"--u95-policy", RCH_OPT_CHOICE, &u95_policy, 0, 0, NULL,
         "what a target beyond --max-uncertainty-mm (u95 at the compensated point: the flange or the --tool TCP) "
         "does: skip (left uncompensated, a warning), warn (compensated, a warning naming its line and u95) or "
         "refuse (exit 1, nothing written)",
         0, "skip|warn|refuse"},
        {"--max-dev-deg", RCH_OPT_DOUBLE, &max_dev_deg, 0.001, 90.0, "D", "largest correction per joint", 0, NULL},
        {"--accept-robtargets", RCH_OPT_FLAG, &accept_rt, 0, 0, NULL,
         "deprecated, no effect: RAPID robtargets are corrected (through the nominal inverse kinematics)", 0, NULL},
        {"--format", RCH_OPT_CHOICE, &format, 0, 0, NULL, "input form", 0, "auto|csv|rapid|urscript|fanuc|krl"},
        {"--fanuc-frames", RCH_OPT_STR, &fanuc_frames, 0, 0, "FRAMES.csv",
         "a Fanuc program's user and tool frames, as the pendant shows them (lines uframe,n,x,y,z,w,p,r and "
         "utool,n,x,y,z,w,p,r; mm, deg): a position in a UF or UT not given is refused (docs/comp-fanuc.md)",
         0, NULL},
        {"--assume-degrees", RCH_OPT_FLAG, &assume_deg, 0, 0, NULL,
         "the joint targets are degrees even where they all look like radians (every joint within +-pi and two "
         "joints moving by 0.2 or more: refused without this option)",
         0, NULL},
        {"--summary", RCH_OPT_FLAG, &want_summary, 0, 0, NULL, "targets, iterations, largest correction and time on stderr",
         0, NULL},
        {"--json", RCH_OPT_FLAG, &json, 0, 0, NULL,
         "the summary as one JSON object on stdout (needs --out FILE: the targets do not share stdout)", 0, NULL},
    };
    unsigned long long seen = 0;
    const int ps = rch_opt_cmd(&spec, "compensate", summary, details, opts, RCH_OPT_COUNT(opts), argc, argv, &seen);
    if (ps >= 0)
        return ps;
    if (!args_fit(position_only, full_pose, json, out))
        return 2;
    if (accept_rt)
        fprintf(stderr, "rcal compensate: note: --accept-robtargets is deprecated and has no effect: robtargets are "
                        "corrected now\n");

    const rch_comp_job job = {
        .model_path = model,
        .nominal_path = nominal,
        .in_path = in,
        .out_path = out,
        .format = strcmp(format, "csv") == 0     ? RCH_COMP_CSV
                  : strcmp(format, "rapid") == 0 ? RCH_COMP_RAPID
                  : strcmp(format, "urscript") == 0 ? RCH_COMP_URSCRIPT
                  : strcmp(format, "fanuc") == 0 ? RCH_COMP_FANUC
                  : strcmp(format, "krl") == 0 ? RCH_COMP_KRL
                                                 : RCH_COMP_AUTO,
        .position_only = position_only,
        .full_pose = full_pose,
        .max_unc_mm = max_unc_mm,
        .u95_policy = strcmp(u95_policy, "warn") == 0     ? RCH_COMP_U95_WARN
                      : strcmp(u95_policy, "refuse") == 0 ? RCH_COMP_U95_REFUSE
                                                          : RCH_COMP_U95_SKIP,
        .accept_robtargets = accept_rt,
        .max_dev_deg = rch_opt_given(&spec, seen, "--max-dev-deg") ? max_dev_deg : 0.0, /* 0: the core's 0.1 rad */
        .tool_mm = rch_opt_given(&spec, seen, "--tool") ? tool : NULL,
        .uncertainty_path = unc_out,
        .assume_degrees = assume_deg,
        .fanuc_frames_path = fanuc_frames,
    };
    rch_comp_result r;
    memset(&r, 0, sizeof r);
    char *warn_text = NULL;
    const int rc = run_job(&r, &job, json, &warn_text);
    if (rc < 0) {
        free(warn_text);
        return 1;
    }
    if (want_summary) {
        print_sources(&r, model);
        print_summary(&r);
    }
    const int bad_json = json && summary_json(&r, &job, rc, warn_text, argc, argv) != 0;
    free(warn_text);
    return rc == 0 && !bad_json ? 0 : 1;
}
