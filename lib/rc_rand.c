/* SPDX-License-Identifier: MIT */
#include "rc_rand.h"

#include <math.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

static uint64_t rotl(uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }

void rc_rng_seed(rc_rng *g, uint64_t seed)
{
    uint64_t z = seed;
    for (int i = 0; i < 4; ++i) {
        z += 0x9E3779B97F4A7C15ull;
        uint64_t t = z;
        t = (t ^ (t >> 30)) * 0xBF58476D1CE4E5B9ull;
        t = (t ^ (t >> 27)) * 0x94D049BB133111EBull;
        g->s[i] = t ^ (t >> 31);
    }
}

uint64_t rc_rng_u64(rc_rng *g)
{
    uint64_t *s = g->s;
    const uint64_t result = rotl(s[1] * 5, 7) * 9;
    const uint64_t t = s[1] << 17;
    s[2] ^= s[0];
    s[3] ^= s[1];
    s[1] ^= s[2];
    s[0] ^= s[3];
    s[2] ^= t;
    s[3] = rotl(s[3], 45);
    return result;
}

double rc_rng_u01(rc_rng *g) { return (double)(rc_rng_u64(g) >> 11) * 0x1.0p-53; }

double rc_rng_normal(rc_rng *g)
{
    double u1 = rc_rng_u01(g);
    const double u2 = rc_rng_u01(g);
    if (u1 < 1e-300)
        u1 = 1e-300;
    return sqrt(-2.0 * log(u1)) * cos(2.0 * M_PI * u2);
}

uint32_t rc_rng_below(rc_rng *g, uint32_t n)
{
    return (uint32_t)(((rc_rng_u64(g) >> 32) * (uint64_t)n) >> 32);
}

double rc_lt_map(double n, double r)
{
    const double tent = (n < 0.5) ? n / 2.0 : (1.0 - n) / 2.0;
    const double v = r * n * (1.0 - n) + (4.0 - r) * tent;
    double f = fmod(v, 1.0);
    if (f < 0.0)
        f += 1.0;
    return f;
}
