/* SPDX-License-Identifier: MIT */
#include "rc_status.h"

const char *rc_strerror(rc_status st)
{
    switch (st) {
    case RC_OK: return "ok";
    case RC_ERR_ARG: return "invalid argument";
    case RC_ERR_RANGE: return "value out of range";
    case RC_ERR_NUMERIC: return "numerical failure (NaN, infinity or indefinite matrix)";
    case RC_ERR_NOCONV: return "did not converge within the iteration limit";
    case RC_ERR_CAPACITY: return "compile-time capacity exceeded";
    case RC_ERR_FORMAT: return "malformed input";
    case RC_ERR_CHECKSUM: return "checksum mismatch";
    case RC_ERR_INCOMPLETE: return "incomplete input";
    case RC_ERR_IO: return "input/output error";
    case RC_ERR_TIMEOUT: return "timed out";
    case RC_ERR_CLOSED: return "connection closed";
    case RC_ERR_DEVICE: return "device reported an error";
    case RC_ERR_UNSUPPORTED: return "not supported";
    case RC_ERR_RANK: return "not identifiable from the data";
    case RC_ERR_SINGULAR: return "kinematic singularity";
    }
    return "unknown status";
}
