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

#include <omp.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* The 16-bit digit number `pass` of element x (pass 0 the least
 * significant); bits is the caller's, passed through. */
typedef uint32_t (*st_radix_digit)(const void *x, int pass, unsigned bits);

/* Arrays at least this long are counted and scattered in parallel. */
#define ST_RADIX_PARALLEL_MIN 65536

/* ST_RADIX_SORT_DEFINE(name, esize, digit) defines
 *
 *   static int name(void *a, void *tmp, size_t n, int passes, unsigned bits);
 *
 * which sorts the n elements of esize bytes (a constant) at a by `passes`
 * digits of digit (an st_radix_digit, named so that the loops call it
 * directly: with it and the size constants, the compiler inlines the digit
 * and the copies, as it would not through a pointer into OpenMP's
 * outlined loops; the dragon's edge table took 1.39 G instructions that
 * way, 0.64 G serial and inlined), stably: elements with equal digits
 * keep their order. tmp holds n elements. A pass whose digit is the same
 * for every element moves nothing. Long arrays are cut into one chunk per thread, each
 * counted and scattered by one thread, the chunks' slots for a digit in
 * chunk order: the sort is the same for any number of threads (a stable
 * sort's result is unique). Returns 0, or -1 when out of memory (a
 * untouched). */
#define ST_RADIX_SORT_DEFINE(name, esize, digit)                                      \
    static int name(void *a, void *tmp, size_t n, int passes, unsigned bits)           \
    {                                                                                  \
        size_t nc = 1;                                                                 \
        if (n >= ST_RADIX_PARALLEL_MIN) {                                              \
            int t_ = omp_get_max_threads();                                            \
            nc = t_ > 1 ? (size_t)t_ : 1;                                              \
        }                                                                              \
        size_t *hist = malloc(nc * 65536 * sizeof *hist);                              \
        if (!hist)                                                                     \
            return -1;                                                                 \
        unsigned char *src = a, *dst = tmp;                                            \
        const long long lnc = (long long)nc;                                           \
        for (int pass = 0; pass < passes && n > 0; pass++) {                           \
            _Pragma("omp parallel for schedule(static) if (nc > 1)")                   \
            for (long long c = 0; c < lnc; c++) {                                      \
                size_t *h = hist + 65536 * (size_t)c;                                  \
                memset(h, 0, 65536 * sizeof *h);                                       \
                const size_t lo = n * (size_t)c / nc, hi = n * (size_t)(c + 1) / nc;   \
                const unsigned char *s_ = src;                                         \
                for (size_t i = lo; i < hi; i++)                                       \
                    h[digit(s_ + i * (esize), pass, bits)]++;                          \
            }                                                                          \
            const uint32_t d0 = digit(src, pass, bits);                                \
            size_t same = 0;                                                           \
            for (size_t c = 0; c < nc; c++)                                            \
                same += hist[65536 * c + d0];                                          \
            if (same == n)                                                             \
                continue;                                                              \
            size_t run = 0; /* each chunk's first slot for each digit */               \
            for (size_t d = 0; d < 65536; d++)                                         \
                for (size_t c = 0; c < nc; c++) {                                      \
                    size_t k = hist[65536 * c + d];                                    \
                    hist[65536 * c + d] = run;                                         \
                    run += k;                                                          \
                }                                                                      \
            _Pragma("omp parallel for schedule(static) if (nc > 1)")                   \
            for (long long c = 0; c < lnc; c++) {                                      \
                size_t *h = hist + 65536 * (size_t)c;                                  \
                const size_t lo = n * (size_t)c / nc, hi = n * (size_t)(c + 1) / nc;   \
                const unsigned char *s_ = src;                                         \
                unsigned char *d_ = dst;                                               \
                const int p_ = pass;                                                   \
                for (size_t i = lo; i < hi; i++)                                       \
                    memcpy(d_ + (esize) * h[digit(s_ + i * (esize), p_, bits)]++,      \
                           s_ + i * (esize), (esize));                                 \
            }                                                                          \
            unsigned char *x = src;                                                    \
            src = dst;                                                                 \
            dst = x;                                                                   \
        }                                                                              \
        free(hist);                                                                    \
        if (src != a)                                                                  \
            memcpy(a, src, n * (esize));                                               \
        return 0;                                                                      \
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
