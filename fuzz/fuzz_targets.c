/* SPDX-License-Identifier: MIT */
/* fuzz_targets.c - joint target lists (rch_data_parse with RCH_DATA_TARGETS |
 * RCH_DATA_NO_LEN: the header optional and recognised by its names), the
 * reader rcal-rt --in uses (issue 47), and the radians check its targets go
 * through (rch_data_q_look_rad). */
#include "fuzz_data_common.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    fuzz_data(data, size, RCH_DATA_TARGETS | RCH_DATA_NO_LEN);
    return 0;
}
