/* SPDX-License-Identifier: MIT */
/* rc_status.h - the single status enum of the project.
 *
 * RC_OK is zero; every error is negative. "Called wrong" (RC_ERR_ARG) is kept
 * apart from "the data or the numbers failed" and from "the device or OS
 * failed" (RC_ERR_IO). Counts (bytes, samples) are never folded into a status:
 * they are returned through separate output parameters.
 */
#ifndef RC_STATUS_H
#define RC_STATUS_H

typedef enum rc_status {
    RC_OK = 0,
    RC_ERR_ARG = -1,          /* invalid argument: the caller broke the contract */
    RC_ERR_RANGE = -2,        /* a value is outside its physical or configured range */
    RC_ERR_NUMERIC = -3,      /* NaN/inf met, or a matrix is not positive definite */
    RC_ERR_NOCONV = -4,       /* an iteration did not converge within its limit */
    RC_ERR_CAPACITY = -5,     /* a compile-time capacity (RC_MAX_*) would be exceeded */
    RC_ERR_FORMAT = -6,       /* malformed input text or frame */
    RC_ERR_CHECKSUM = -7,     /* frame checksum or CRC mismatch */
    RC_ERR_INCOMPLETE = -8,   /* more input bytes are needed */
    RC_ERR_IO = -9,           /* the operating system or device failed */
    RC_ERR_TIMEOUT = -10,     /* no answer within the timeout */
    RC_ERR_CLOSED = -11,      /* the peer or device went away */
    RC_ERR_DEVICE = -12,      /* the device answered with an error (e.g. Modbus exception) */
    RC_ERR_UNSUPPORTED = -13, /* valid request, not supported by this build or device */
    RC_ERR_RANK = -14,        /* the data cannot identify what was asked */
    RC_ERR_SINGULAR = -15     /* a kinematic singularity prevents a unique answer */
} rc_status;

/* Static English text for a status; never NULL, even for unknown codes. */
const char *rc_strerror(rc_status st);

#endif /* RC_STATUS_H */
