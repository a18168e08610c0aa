/* SPDX-License-Identifier: MIT */
/* fuzz_modbus_req.c - the device side of Modbus RTU: requests read by the
 * simulated display (rcd_parse_modbus_request).
 * Input: byte 0 the slave address, the rest the byte stream from the host. */
#include <stdint.h>
#include <string.h>

#include "fuzz_check.h"
#include "rcd_proto.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < 1)
        return 0;
    const uint8_t addr = data[0];
    size_t pos = 1, calls = 0;
    for (;;) {
        uint16_t reg = 0, count = 0;
        size_t c = (size_t)-1;
        const size_t left = size - pos;
        rc_status st = rcd_parse_modbus_request(&reg, &count, &c, addr, data + pos, left);
        FZ_CHECK(c <= left);
        FZ_CHECK(++calls <= size + 2);
        if (st == RC_OK) {
            FZ_CHECK(c >= RCD_MODBUS_REQ_LEN);
            FZ_CHECK(data[pos + c - RCD_MODBUS_REQ_LEN] == addr);
        } else if (st == RC_ERR_CHECKSUM) {
            FZ_CHECK(c >= 1);
        } else {
            FZ_CHECK(st == RC_ERR_INCOMPLETE);
        }
        pos += c;
        if (st == RC_ERR_INCOMPLETE)
            break;
    }
    return 0;
}
