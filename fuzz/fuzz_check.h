/* SPDX-License-Identifier: MIT */
/* fuzz_check.h - invariant checks inside fuzz targets.
 * A broken invariant aborts, which libFuzzer reports as a crash and saves the
 * input (crash-<sha1>), exactly like a sanitizer finding. */
#ifndef FUZZ_CHECK_H
#define FUZZ_CHECK_H

#include <stdio.h>
#include <stdlib.h>

#define FZ_CHECK(cond)                                                                      \
    do {                                                                                    \
        if (!(cond)) {                                                                      \
            fprintf(stderr, "%s:%d: fuzz invariant broken: %s\n", __FILE__, __LINE__, #cond); \
            abort();                                                                        \
        }                                                                                   \
    } while (0)

#endif
