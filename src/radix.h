/*
 * radix.h - a stable least-significant-digit radix sort (private, header
 * only: each caller gets a copy with its digit function inlined).
 *
 * For sorts whose order is total and whose keys are short: qsort's
 * comparisons and indirect calls were a third of the dragon's edge table
 * and most of the fit's setup (issue 23).
 */
#ifndef SOUPTET_RADIX_H
#define SOUPTET_RADIX_H

#include <stddef.h>
#include <stdint.h>
#include <string.h>

/* The 16-bit digit number `pass` of element x (pass 0 the least
 * significant); bits is the caller's, passed through. */
typedef uint32_t (*st_radix_digit)(const void *x, int pass, unsigned bits);

/* Sort the n elements of `size` bytes at a by `passes` digits, stably:
 * elements with equal digits keep their order. tmp holds n elements,
 * count 65537 size_t. A pass whose digit is the same for every element
 * moves nothing. */
static inline void st_radix_sort(void *a, void *tmp, size_t n, size_t size, int passes,
                                 st_radix_digit digit, unsigned bits, size_t *count)
{
    unsigned char *src = a, *dst = tmp;
    for (int pass = 0; pass < passes; pass++) {
        memset(count, 0, 65537 * sizeof *count);
        for (size_t i = 0; i < n; i++)
            count[digit(src + i * size, pass, bits) + 1]++;
        if (n == 0 || count[digit(src, pass, bits) + 1] == n)
            continue;
        for (size_t d = 0; d < 65536; d++)
            count[d + 1] += count[d];
        for (size_t i = 0; i < n; i++)
            memcpy(dst + size * count[digit(src + i * size, pass, bits)]++, src + i * size,
                   size);
        unsigned char *x = src;
        src = dst;
        dst = x;
    }
    if (src != a)
        memcpy(a, src, n * size);
}

/* An unsigned key with the order of the double x: -0.0 and 0.0 get the
 * same key, as they compare equal (x not a NaN). */
static inline uint64_t st_radix_double_key(double x)
{
    union {
        double d;
        uint64_t u;
    } v;
    v.d = x == 0.0 ? 0.0 : x;
    return v.u >> 63 ? ~v.u : v.u | (uint64_t)1 << 63;
}

#endif
