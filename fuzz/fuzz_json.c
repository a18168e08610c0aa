/* SPDX-License-Identifier: MIT */
/* fuzz_json.c - the strict JSON reader (rch_json_parse). Checks the tree it
 * builds: types, counts, keys, positions, the documented depth limit. */
#include <math.h>
#include <stdint.h>
#include <string.h>

#include "fuzz_check.h"
#include "rch_json.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static void walk(const rch_json *j, unsigned depth)
{
    FZ_CHECK(j != NULL);
    FZ_CHECK(depth <= 64 + 1); /* documented depth limit (64) */
    FZ_CHECK(j->line >= 1 && j->col >= 1);
    switch (j->type) {
    case RCH_JNULL:
        break;
    case RCH_JBOOL:
        FZ_CHECK(j->num == 0.0 || j->num == 1.0);
        break;
    case RCH_JNUM:
        FZ_CHECK(isfinite(j->num));
        break;
    case RCH_JSTR:
        FZ_CHECK(j->str != NULL);
        FZ_CHECK(strlen(j->str) <= 4096 * 4);
        break;
    case RCH_JARR:
        FZ_CHECK(j->n == 0 || j->items != NULL);
        for (size_t i = 0; i < j->n; ++i)
            walk(j->items[i], depth + 1);
        break;
    case RCH_JOBJ:
        FZ_CHECK(j->n == 0 || (j->items != NULL && j->keys != NULL));
        for (size_t i = 0; i < j->n; ++i) {
            FZ_CHECK(j->keys[i] != NULL);
            /* duplicate keys are refused: the first member with this key is this one */
            FZ_CHECK(rch_json_get(j, j->keys[i]) == j->items[i]);
            walk(j->items[i], depth + 1);
        }
        break;
    default:
        FZ_CHECK(0 && "unknown node type");
    }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    rch_diag diag;
    memset(&diag, 0, sizeof diag);
    rch_json *j = rch_json_parse((const char *)data, size, "fuzz.json", &diag);
    if (!j) {
        FZ_CHECK(diag.msg[0] != '\0');
        return 0;
    }
    walk(j, 1);
    rch_json_free(j);
    return 0;
}
