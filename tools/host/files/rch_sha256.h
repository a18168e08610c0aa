/* SPDX-License-Identifier: MIT */
/* rch_sha256.h - SHA-256 (FIPS 180-4) of a file or a buffer, for the
 * provenance of a calibration (which data a model came from).
 * Host side (prefix rch_). */
#ifndef RCH_SHA256_H
#define RCH_SHA256_H

#include <stddef.h>
#include <stdint.h>

typedef struct {
    uint32_t h[8];
    uint64_t bytes;
    unsigned char buf[64];
    size_t used;
} rch_sha256;

void rch_sha256_init(rch_sha256 *c);
void rch_sha256_update(rch_sha256 *c, const void *data, size_t len);
/* hex: 65 bytes, lower-case hex digest and a NUL. */
void rch_sha256_final(rch_sha256 *c, char hex[65]);
/* Digest of a whole file; 0, or -1 when it cannot be read. */
int rch_sha256_file(char hex[65], const char *path);
/* The same for a path the user did not give (a name inside a file): only a
 * regular file of at most max_bytes (rch_open_regular); 0, or -1 with why
 * set. */
int rch_sha256_file_unasked(char hex[65], const char *path, size_t max_bytes, char *why, size_t why_len);

#endif
