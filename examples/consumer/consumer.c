/* SPDX-License-Identifier: MIT */
/* consumer.c - the smallest program built against an installed rcal: it loads
 * the nominal ABB IRB120 through the host library (rch_robot_load), places a
 * cable-encoder outlet, and prints the cable length the core predicts
 * (rc_meas) for one pose.
 *
 *   consumer [MODEL.json]   (default: irb120.json found by rch_data_path)
 *
 * Exit status 0 on success, 1 when the model cannot be loaded or evaluated.
 */
#include <stdio.h>

#include "rc_config.h"
#include "rc_model.h"
#include "rch_paths.h"
#include "rch_robot.h"

int main(int argc, char **argv)
{
    static rch_robot robot; /* large: keep it off the stack */
    rch_diag diag = {0};
    char path[4096], msg[1024];
    if (argc > 1)
        snprintf(path, sizeof path, "%s", argv[1]);
    else if (rch_data_path(path, sizeof path, "irb120.json") != 0) {
        fprintf(stderr, "consumer: irb120.json not found (looked for %s); set RCAL_DATA_DIR\n", path);
        return 1;
    }
    if (rch_robot_load(&robot, path, &diag) != 0) {
        fprintf(stderr, "consumer: %s\n", rch_diag_str(&diag, msg, sizeof msg));
        return 1;
    }

    /* Encoder outlet on the floor in front of the robot (base frame, mm). */
    robot.model.x[RC_P_ENC + 0] = 600.0;
    robot.model.x[RC_P_ENC + 1] = -150.0;
    robot.model.x[RC_P_ENC + 2] = 0.0;
    rc_sample s = {.q_rad = {0.1, -0.3, 0.2, 0.5, -0.4, 0.7}}; /* joint readings, rad */
    double len_mm = 0.0;
    rc_status st = rc_meas(&len_mm, NULL, &robot.model, &s);
    if (st != RC_OK) {
        fprintf(stderr, "consumer: rc_meas: %s\n", rc_strerror(st));
        return 1;
    }
    printf("rcal %s (core %s, RC_MAX_PARAMS %d): %s: cable length %.6f mm\n", RC_VERSION_STRING, rc_version(),
           RC_MAX_PARAMS, robot.name, len_mm);
    return 0;
}
