/* SPDX-License-Identifier: MIT */
/* fuzz_csv.c - measurement CSV files (rch_data_parse, flags 0). */
#include "fuzz_data_common.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    fuzz_data(data, size, 0);
    return 0;
}
