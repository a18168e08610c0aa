/* fw_example.c - the rcal core embedded as controller firmware would do it:
 * models in const tables (flash), the stream state in .bss, one call per
 * control cycle, no heap and no stdio. Compiled for the host (CMake target
 * fw_example, run by ctest) and for a Cortex-M7 (cross_build.sh). */
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
    return rc_comp_stream_init(&s_stream, &fw_model_cal, &fw_model_nom, &cfg);
}

rc_status fw_comp_cycle(double q_cmd_rad[RC_NJ], const double q_target_rad[RC_NJ])
{
    return rc_comp_stream_step(&s_stream, q_cmd_rad, NULL, q_target_rad);
}

unsigned long fw_comp_flagged(void) { return s_stream.n_fail; }

#ifdef FW_EXAMPLE_MAIN
/* A stand-in for the control loop: a slow joint-space sweep, 2000 cycles.
 * Returns the number of flagged cycles (0 expected). */
int main(void)
{
    static const double centre[RC_NJ] = {0.2, 0.3, -0.3, 0.4, 0.9, 0.5};
    double q[RC_NJ], cmd[RC_NJ];
    if (fw_comp_init() != RC_OK)
        return 100;
    for (unsigned k = 0; k < 2000u; ++k) {
        /* triangle wave, no libm call needed for the demo trajectory */
        const double t = (double)(k % 1000u) / 500.0;
        const double s = t < 1.0 ? t : 2.0 - t;
        for (unsigned i = 0; i < RC_NJ; ++i)
            q[i] = centre[i] + 0.3 * (s - 0.5) * (i % 2u ? -1.0 : 1.0);
        (void)fw_comp_cycle(cmd, q);
    }
    return (int)fw_comp_flagged();
}
#endif
