/*
 * splitmix.h - the tests' pseudo-random numbers (header only): SplitMix64
 * from the seed the including file defines as SPLITMIX_SEED first, so a
 * test draws the same numbers on every run.
 */
#ifndef SOUPTET_TESTS_SPLITMIX_H
#define SOUPTET_TESTS_SPLITMIX_H

#include <stdint.h>

static uint64_t rng_state = SPLITMIX_SEED;

static inline uint64_t rng_next(void)
{
    uint64_t z = (rng_state += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
}

/* A uniform integer in [-r, r]. */
static inline int64_t rng_int(int64_t r)
{
    return (int64_t)(rng_next() % (uint64_t)(2 * r + 1)) - r;
}

/* A uniform double in [lo, hi). */
static inline double rng_unif(double lo, double hi)
{
    return lo + (hi - lo) * (double)(rng_next() >> 11) * 0x1p-53;
}

#endif
