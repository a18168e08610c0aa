#include "rch_calib.h"

#include <string.h>

int rch_calib_start(rc_model *start, rc_solve_work *w, const rch_robot *robot, const rc_sample *train,
                    size_t n, rch_diag *d)
{
    *start = robot->model;
    if (!robot->has_encoder) {
        double e[3];
        rc_status st = rc_encoder_guess(e, start, train, n);
        if (st != RC_OK) {
            rch_diag_set(d, "", 0, 0,
                         "cannot place the encoder: %s (the poses must spread in all three directions)",
                         rc_strerror(st));
            return -1;
        }
        memcpy(&start->x[RC_P_ENC], e, sizeof e);
    }
    uint8_t fixed[RC_MAX_PARAMS];
    memset(fixed, 1, sizeof fixed);
    fixed[RC_P_ENC] = fixed[RC_P_ENC + 1] = fixed[RC_P_ENC + 2] = 0;
    rc_solve_config cfg;
    memset(&cfg, 0, sizeof cfg);
    cfg.fixed = fixed;
    rc_solve_result res;
    rc_status st = rc_solve(start, &res, w, &cfg, train, n);
    if (st != RC_OK) {
        rch_diag_set(d, "", 0, 0, "fitting the encoder position failed: %s", rc_strerror(st));
        return -1;
    }
    return 0;
}

int rch_method_parse(rc_method *out, const char *name)
{
    static const rc_method all[] = {RC_METHOD_LM, RC_METHOD_LTLM, RC_METHOD_LM_PAPER, RC_METHOD_LTLM_PAPER};
    for (size_t i = 0; i < sizeof all / sizeof all[0]; ++i)
        if (strcmp(name, rc_method_name(all[i])) == 0) {
            *out = all[i];
            return 0;
        }
    return -1;
}
