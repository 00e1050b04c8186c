/*
 * radix.c - a stable least-significant-digit radix sort (see radix.h).
 */
#include "radix.h"

#include <string.h>

void st_radix_sort(void *a, void *tmp, size_t n, size_t size, int passes,
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
