/* SPDX-License-Identifier: MIT */
/* fuzz_acq.c - acquisition files (rch_data_parse with RCH_DATA_POSE |
 * RCH_DATA_ALLOW_EMPTY), the reader `rcal acquire` resumes with
 * (tools/host/files/rch_acqfile.c). */
#include "fuzz_data_common.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    fuzz_data(data, size, RCH_DATA_POSE | RCH_DATA_ALLOW_EMPTY);
    return 0;
}
