/* SPDX-License-Identifier: MIT */
/* rc_rand.h - deterministic random numbers and the logistic-tent chaotic map.
 *
 * No global state: every generator is a caller-owned struct, so runs are
 * reproducible from a seed and independent of call order elsewhere.
 */
#ifndef RC_RAND_H
#define RC_RAND_H

#include <stdint.h>

typedef struct rc_rng {
    uint64_t s[4]; /* xoshiro256** state */
} rc_rng;

/* Seed through splitmix64; any seed (including 0) gives a valid state. */
void rc_rng_seed(rc_rng *g, uint64_t seed);
uint64_t rc_rng_u64(rc_rng *g);
/* Uniform in [0, 1). */
double rc_rng_u01(rc_rng *g);
/* Standard normal (Box-Muller, one value per call). */
double rc_rng_normal(rc_rng *g);
/* Uniform integer in [0, n) for n > 0. */
uint32_t rc_rng_below(rc_rng *g, uint32_t n);

/* One step of the logistic-tent map of the LTLM paper (its Eq. 11):
 *   N' = mod(r N (1 - N) + (4 - r) N / 2, 1)        for N < 0.5
 *   N' = mod(r N (1 - N) + (4 - r) (1 - N) / 2, 1)  for N >= 0.5
 * with r in [0, 4] and N in [0, 1). */
double rc_lt_map(double n, double r);

#endif /* RC_RAND_H */
