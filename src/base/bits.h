/*
 * bits.h - bit tricks on words (private to the library, header only).
 */
#ifndef SOUPTET_BITS_H
#define SOUPTET_BITS_H

#include <stdint.h>

/* The index of the lowest set bit of m; m must not be 0. */
static inline int st_lowest_bit(uint64_t m)
{
#if defined(__GNUC__)
    return __builtin_ctzll(m);
#else
    int b = 0;
    while (!(m & 1u)) {
        m >>= 1;
        b++;
    }
    return b;
#endif
}

#endif
