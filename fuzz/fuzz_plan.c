/* SPDX-License-Identifier: MIT */
/* fuzz_plan.c - pose plans (rch_data_parse with RCH_DATA_NO_LEN: no L column
 * needed), the reader `rcal acquire` uses for its plan. */
#include "fuzz_data_common.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    fuzz_data(data, size, RCH_DATA_NO_LEN);
    return 0;
}
