/* SPDX-License-Identifier: MIT */
/* fuzz_robot.c - robot-model and calibrated-model files (rch_robot_parse).
 * An accepted file must give a usable model: finite parameters, consistent
 * effect table, and forward kinematics / cable length that stay finite. */
#include <math.h>
#include <stdint.h>
#include <string.h>

#include "fuzz_check.h"
#include "rch_robot.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static void check_model(const rc_model *m)
{
    unsigned used = RC_N_BASE;
    FZ_CHECK(m->n_params >= RC_N_BASE && m->n_params <= RC_MAX_PARAMS);
    FZ_CHECK(m->n_effects <= RC_MAX_EFFECTS);
    for (unsigned k = 0; k < m->n_params; ++k)
        FZ_CHECK(isfinite(m->x[k]));
    for (unsigned e = 0; e < m->n_effects; ++e) {
        const rc_effect *ef = &m->effects[e];
        FZ_CHECK(ef->kind >= RC_EFF_LENGTH_OFFSET && ef->kind <= RC_EFF_LAST);
        FZ_CHECK(ef->first == used);
        FZ_CHECK(ef->joint < RC_NJ);
        used += ef->count;
    }
    FZ_CHECK(used == m->n_params);
    for (int j = 0; j < RC_NJ; ++j)
        FZ_CHECK(isfinite(m->q_min_rad[j]) && isfinite(m->q_max_rad[j]) &&
                 m->q_min_rad[j] <= m->q_max_rad[j]);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static rch_robot r; /* large (models with effects); static keeps the stack small */
    rch_diag diag;
    memset(&diag, 0, sizeof diag);
    if (rch_robot_parse(&r, (const char *)data, size, "fuzz.json", &diag) != 0) {
        FZ_CHECK(diag.msg[0] != '\0');
        return 0;
    }
    FZ_CHECK(memchr(r.name, '\0', sizeof r.name) != NULL);
    check_model(&r.model);
    check_model(&r.nominal);
    /* Exercise the model: zero pose and the joint-limit corners. */
    rc_sample s;
    memset(&s, 0, sizeof s);
    s.value = 500.0;
    double p[3], rot[9], jac[RC_MAX_PARAMS];
    for (int corner = 0; corner < 3; ++corner) {
        for (int j = 0; j < RC_NJ; ++j)
            s.q_rad[j] = corner == 0 ? 0.0 : corner == 1 ? r.model.q_min_rad[j] : r.model.q_max_rad[j];
        rc_fk(p, rot, &r.model, s.q_rad);
        double len = 0.0;
        /* a model that was accepted must not predict a non-finite length */
        if (rc_meas(&len, jac, &r.model, &s) == RC_OK)
            FZ_CHECK(isfinite(len));
    }
    return 0;
}
