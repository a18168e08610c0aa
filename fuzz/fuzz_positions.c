/* SPDX-License-Identifier: MIT */
/* fuzz_positions.c - laser-tracker positions files (rch_data_parse with
 * RCH_DATA_POSITIONS | RCH_DATA_NO_LEN, as rch_pos_load reads them). */
#include "fuzz_data_common.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    fuzz_data(data, size, RCH_DATA_POSITIONS | RCH_DATA_NO_LEN);
    return 0;
}
