/* SPDX-License-Identifier: MIT */
/* rch_poses_rapid.c - a plan as an ABB RAPID module
 * (rch_poses_write_rapid, see rch_poses.h): one jointtarget per row, one
 * PROC per outlet, main asking the outlet when there are several.
 * Depends on: stdio only. Memory: none. Errors: -1 when a write failed. */
#include "rch_poses.h"

#define PI_ 3.14159265358979323846

int rch_poses_write_rapid(FILE *f, const rc_sample *rows, const unsigned char *outlet_label, size_t n,
                          double settle_s, const char *comment)
{
    unsigned char seen[256] = {0};
    unsigned n_out = 0;
    for (size_t i = 0; i < n; ++i) {
        const unsigned o = outlet_label ? outlet_label[i] : 0u;
        if (!seen[o]) { /* a flag, not a count: 256 poses of one outlet must not wrap it */
            seen[o] = 1;
            ++n_out;
        }
    }
    fprintf(f, "MODULE rcal_plan\n");
    if (comment)
        fprintf(f, "    ! %s\n", comment);
    fprintf(f, "    ! %zu poses; at each: MoveAbsJ (fine), a message on the pendant, WaitTime %.3g s while rcal "
               "acquire reads the cable length\n", n, settle_s);
    for (size_t i = 0; i < n; ++i) {
        fprintf(f, "    CONST jointtarget rcal_p%zu:=[[", i);
        for (int j = 0; j < RC_NJ; ++j)
            fprintf(f, "%s%.4f", j ? "," : "", rows[i].q_rad[j] * 180.0 / PI_);
        fprintf(f, "],[9E9,9E9,9E9,9E9,9E9,9E9]];\n");
    }
    fprintf(f, "    CONST num rcal_settle_s:=%.3g;\n\n", settle_s);
    for (unsigned o = 0; o < 256; ++o) {
        if (!seen[o])
            continue;
        fprintf(f, "    PROC rcal_outlet%u()\n", o);
        for (size_t i = 0; i < n; ++i) {
            if ((outlet_label ? outlet_label[i] : 0u) != o)
                continue;
            fprintf(f, "        MoveAbsJ rcal_p%zu\\NoEOffs, v100, fine, tool0;\n", i);
            fprintf(f, "        TPWrite \"rcal pose %zu outlet %u\";\n", i, o);
            fprintf(f, "        WaitTime rcal_settle_s;\n");
        }
        fprintf(f, "    ENDPROC\n\n");
    }
    fprintf(f, "    PROC main()\n");
    if (n_out <= 1) {
        for (unsigned o = 0; o < 256; ++o)
            if (seen[o])
                fprintf(f, "        rcal_outlet%u;\n", o);
    } else {
        fprintf(f, "        VAR num k;\n");
        fprintf(f, "        TPReadNum k, \"rcal: the encoder stands at which outlet?\";\n");
        fprintf(f, "        TEST k\n");
        for (unsigned o = 0; o < 256; ++o)
            if (seen[o])
                fprintf(f, "        CASE %u:\n            rcal_outlet%u;\n", o, o);
        fprintf(f, "        DEFAULT:\n            TPWrite \"rcal: no such outlet in this plan\";\n");
        fprintf(f, "        ENDTEST\n");
    }
    fprintf(f, "    ENDPROC\nENDMODULE\n");
    return ferror(f) ? -1 : 0;
}
