/* mem.c - checked allocation (see mem.h). */
#include "souptet/mem.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

int st_size_mul(size_t *out, size_t a, size_t b)
{
    if (a != 0 && b > SIZE_MAX / a)
        return -1;
    *out = a * b;
    return 0;
}

int st_size_add(size_t *out, size_t a, size_t b)
{
    if (b > SIZE_MAX - a)
        return -1;
    *out = a + b;
    return 0;
}

void *st_malloc_array(size_t n, size_t size)
{
    size_t bytes;
    if (st_size_mul(&bytes, n, size) != 0)
        return NULL;
    return malloc(bytes ? bytes : 1);
}

void *st_calloc_array(size_t n, size_t size)
{
    size_t bytes;
    if (st_size_mul(&bytes, n, size) != 0)
        return NULL;
    return calloc(n ? n : 1, size ? size : 1);
}

void *st_realloc_array(void *p, size_t n, size_t size)
{
    size_t bytes;
    if (st_size_mul(&bytes, n, size) != 0)
        return NULL;
    return realloc(p, bytes ? bytes : 1);
}

char *st_strdup(const char *s)
{
    if (!s)
        return NULL;
    size_t n = strlen(s) + 1;
    char *d = malloc(n);
    if (d)
        memcpy(d, s, n);
    return d;
}
