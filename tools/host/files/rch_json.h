/* SPDX-License-Identifier: MIT */
/* rch_json.h - a small strict JSON reader (RFC 8259) for model files.
 * Builds a tree on the heap; every node remembers its line and column so that
 * callers can report "file:line:col: what is wrong" (a line ends at LF, CRLF
 * or a lone CR; a UTF-8 byte-order mark is skipped). Depth is limited to 64,
 * strings and keys to 4096 bytes; duplicate keys are refused. */
#ifndef RCH_JSON_H
#define RCH_JSON_H

#include <stddef.h>

#include "rch_diag.h"

typedef enum { RCH_JNULL, RCH_JBOOL, RCH_JNUM, RCH_JSTR, RCH_JARR, RCH_JOBJ } rch_jtype;

typedef struct rch_json {
    rch_jtype type;
    double num;               /* RCH_JNUM, and 0/1 for RCH_JBOOL */
    char *str;                /* RCH_JSTR (NUL-terminated, no embedded NUL) */
    struct rch_json **items;  /* (n) array elements or object values */
    char **keys;              /* (n) object keys */
    size_t n;
    unsigned line, col;
    unsigned key_line, key_col; /* an object member's key (0 otherwise): where an unknown key is named */
} rch_json;

rch_json *rch_json_parse(const char *text, size_t len, const char *name, rch_diag *d);
/* most bytes rch_json_load reads: a parsed file takes up to about 40 times
 * its size in memory (a 64 MiB array of numbers took 2.4 GB); the largest
 * file rcal writes (calibrate --json) is a few KiB */
#define RCH_JSON_MAX_BYTES ((size_t)16 << 20)
rch_json *rch_json_load(const char *path, rch_diag *d);
void rch_json_free(rch_json *j);
/* Member of an object, or NULL. */
const rch_json *rch_json_get(const rch_json *obj, const char *key);

#endif
