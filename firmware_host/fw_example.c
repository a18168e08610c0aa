/* SPDX-License-Identifier: MIT */
/* fw_example.c - the rcal core embedded as controller firmware would do it:
 * compiled models in const tables (flash, fw_model_data.h), the stream state
 * with its scratch in .bss, one call per control cycle, no heap and no
 * stdio. Compiled for the host (CMake target fw_example, run by ctest) and
 * by cross_build.sh for a Cortex-M7 (double) and a Cortex-M4F (float). */
#include "fw_example.h"

#include <string.h>

#include "fw_model_data.h"

static rc_comp_stream s_stream; /* the only mutable state */

#ifdef FW_PORT_H
/* Contract violation in the core: a firmware would log and go to a safe
 * state; here it parks the CPU. */
void fw_fault(const char *file, int line)
{
    (void)file;
    (void)line;
    for (;;) {
    }
}
#endif

rc_status fw_comp_init(void)
{
    rc_comp_config cfg;
    memset(&cfg, 0, sizeof cfg); /* all-zero: defaults */
    cfg.flags = FW_MODEL_COMP_FLAGS;
    return rc_comp_stream_init_kin(&s_stream, &fw_kin_cal, &fw_kin_nom, &cfg);
}

rc_status fw_comp_cycle(rc_real q_cmd_rad[RC_NJ], const rc_real q_target_rad[RC_NJ])
{
    return rc_comp_stream_step(&s_stream, q_cmd_rad, NULL, q_target_rad);
}

uint32_t fw_comp_flagged(void) { return s_stream.n_fail; }

#ifdef FW_EXAMPLE_MAIN
/* A stand-in for the control loop: a slow joint-space sweep, 2000 cycles.
 * Returns the number of flagged cycles (0 expected). */
int main(void)
{
    static const rc_real centre[RC_NJ] = {RC_REAL_C(0.2), RC_REAL_C(0.3), RC_REAL_C(-0.3),
                                          RC_REAL_C(0.4), RC_REAL_C(0.9), RC_REAL_C(0.5)};
    rc_real q[RC_NJ], cmd[RC_NJ];
    if (fw_comp_init() != RC_OK)
        return 100;
    for (unsigned k = 0; k < 2000u; ++k) {
        /* triangle wave, no libm call needed for the demo trajectory */
        const rc_real t = (rc_real)(k % 1000u) / RC_REAL_C(500.0);
        const rc_real s = t < RC_REAL_C(1.0) ? t : RC_REAL_C(2.0) - t;
        for (unsigned i = 0; i < RC_NJ; ++i)
            q[i] = centre[i] + RC_REAL_C(0.3) * (s - RC_REAL_C(0.5)) * (i % 2u ? RC_REAL_C(-1.0) : RC_REAL_C(1.0));
        (void)fw_comp_cycle(cmd, q);
    }
    return (int)fw_comp_flagged();
}
#endif
