/*
 * soup.c - triangle soups: the type (see soup.h): building, names, bounds,
 * appending; and the unchecked appends the readers share (soup_internal.h).
 * Reading files is soupread.c's; the readers' text lexer is lexer.c's.
 */
#include "souptet/soup.h"
#include "../base/fpenv.h"
#include "souptet/mem.h"
#include "soup_internal.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#ifdef __SSE2__
#include <emmintrin.h>
#endif

/* ---- building ---------------------------------------------------------- */

/*
 * Capacity is implicit in the count, so st_soup needs no capacity field and
 * a zero-initialised st_soup works too: an array holding n > 0 elements has
 * room for max(64, the power of two >= n). It is full exactly when n is 0 or
 * a power of two >= 64, and then doubles.
 */
#define MIN_CAP 64

static st_status grow(void **arr, size_t n, size_t elem)
{
    if (n != 0 && (n < MIN_CAP || (n & (n - 1)) != 0))
        return ST_OK;
    size_t cap;
    if (n == 0)
        cap = MIN_CAP;
    else if (st_size_mul(&cap, n, 2) != 0)
        return ST_ENOMEM;
    size_t bytes;
    if (st_size_mul(&bytes, cap, elem) != 0)
        return ST_ENOMEM;
    /* Huge pages past a few MB (st_realloc_big): a 10M-triangle soup's
     * arrays are first touched here. */
    void *p = st_realloc_big(*arr, bytes);
    if (!p)
        return ST_ENOMEM;
    *arr = p;
    return ST_OK;
}

st_status st_soup__push_vertex(st_soup *s, double x, double y, double z)
{
    if (s->nverts >= UINT32_MAX)
        return ST_ELIMIT;
    if (grow((void **)&s->xyz, s->nverts, 3 * sizeof(double)) != 0)
        return ST_ENOMEM;
    double *v = s->xyz + 3 * s->nverts;
    v[0] = x;
    v[1] = y;
    v[2] = z;
    s->nverts++;
    return ST_OK;
}

st_status st_soup__push_tri(st_soup *s, uint32_t a, uint32_t b, uint32_t c)
{
    if (grow((void **)&s->tris, s->ntris, 3 * sizeof(uint32_t)) != 0)
        return ST_ENOMEM;
    uint32_t *t = s->tris + 3 * s->ntris;
    t[0] = a;
    t[1] = b;
    t[2] = c;
    s->ntris++;
    return ST_OK;
}

st_status st_soup__push_failed(st_error *err, st_status st, const char *name,
                               long long line, long long offset)
{
    const char *what = st == ST_ELIMIT
                           ? "more than 4294967295 vertices"
                           : "out of memory";
    if (offset >= 0)
        return st_error_set_offset(err, st, name, offset, "%s", what);
    return st_error_set(err, st, name, line, "%s", what);
}

st_soup *st_soup_new(void)
{
    return calloc(1, sizeof(st_soup));
}

void st_soup_free(st_soup *s)
{
    if (!s)
        return;
    free(s->xyz);
    free(s->tris);
    for (size_t i = 0; i < s->nnames; i++)
        free(s->names[i].name);
    free(s->names);
    free(s);
}

st_status st_soup_add_vertex(st_soup *s, double x, double y, double z,
                             st_error *err)
{
    st_status st = st_soup__push_vertex(s, x, y, z);
    if (st)
        return st_soup__push_failed(err, st, NULL, 0, -1);
    return ST_OK;
}

st_status st_soup_add_triangle(st_soup *s, uint32_t a, uint32_t b, uint32_t c,
                               st_error *err)
{
    if (a >= s->nverts || b >= s->nverts || c >= s->nverts)
        return st_error_set(err, ST_EINPUT, NULL, 0,
                            "triangle (%lu %lu %lu) refers past the %zu "
                            "vertices", (unsigned long)a, (unsigned long)b,
                            (unsigned long)c, s->nverts);
    st_status st = st_soup__push_tri(s, a, b, c);
    if (st)
        return st_soup__push_failed(err, st, NULL, 0, -1);
    return ST_OK;
}

st_status st_soup__push_name(st_soup *s, int level, const unsigned char *name,
                             size_t len)
{
    if (len > ST_SOUP_NAME_MAX) {
        /* cut before a UTF-8 sequence, not inside it */
        len = ST_SOUP_NAME_MAX;
        while (len > 0 && (name[len] & 0xc0) == 0x80)
            len--;
    }
    if (grow((void **)&s->names, s->nnames, sizeof *s->names) != 0)
        return ST_ENOMEM;
    char *c = malloc(len + 1);
    if (!c)
        return ST_ENOMEM;
    if (len)
        memcpy(c, name, len);
    c[len] = '\0';
    /* A NUL inside a name would cut it short in every writer: make it '_'. */
    for (size_t i = 0; i < len; i++)
        if (c[i] == '\0')
            c[i] = '_';
    s->names[s->nnames].first = s->ntris;
    s->names[s->nnames].name = c;
    s->names[s->nnames].level = level;
    s->nnames++;
    return ST_OK;
}

st_status st_soup_add_name(st_soup *s, int level, const char *name, size_t len,
                           st_error *err)
{
    if (st_soup__push_name(s, level, (const unsigned char *)name, len))
        return st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory");
    return ST_OK;
}

st_status st_soup_bounds(const st_soup *s, double lo[3], double hi[3],
                         st_error *err)
{
    if (!s || s->ntris == 0)
        return st_error_set(err, ST_EINPUT, NULL, 0, "no triangles");
    /* Selects, not branches through lo and hi: x < l ? x : l is minsd and
     * minpd (maxsd, maxpd for the other) exactly, the same value as the
     * branch, signed zeros and all; x and y as one pair under SSE2.
     * 1.44 M -> 0.5 M instructions a call on fandisk.off (13 K
     * triangles), and a soupmesh run makes six. */
    const uint32_t *tri = s->tris;
    const double *xyz = s->xyz;
    const size_t n = 3 * s->ntris, nv = s->nverts;
    size_t i = 0;
#ifdef __SSE2__
    __m128d lxy = _mm_set1_pd(INFINITY), lz = lxy;
    __m128d hxy = _mm_set1_pd(-INFINITY), hz = hxy;
    for (; i < n && tri[i] < nv; i++) {
        const double *p = xyz + 3 * (size_t)tri[i];
        const __m128d xy = _mm_loadu_pd(p), z = _mm_load_sd(p + 2);
        lxy = _mm_min_pd(xy, lxy);
        hxy = _mm_max_pd(xy, hxy);
        lz = _mm_min_sd(z, lz);
        hz = _mm_max_sd(z, hz);
    }
    _mm_storeu_pd(lo, lxy);
    _mm_store_sd(lo + 2, lz);
    _mm_storeu_pd(hi, hxy);
    _mm_store_sd(hi + 2, hz);
#else
    double l0 = INFINITY, l1 = INFINITY, l2 = INFINITY;
    double h0 = -INFINITY, h1 = -INFINITY, h2 = -INFINITY;
    for (; i < n && tri[i] < nv; i++) {
        const double *p = xyz + 3 * (size_t)tri[i];
        const double x = p[0], y = p[1], z = p[2];
        l0 = x < l0 ? x : l0;
        l1 = y < l1 ? y : l1;
        l2 = z < l2 ? z : l2;
        h0 = x > h0 ? x : h0;
        h1 = y > h1 ? y : h1;
        h2 = z > h2 ? z : h2;
    }
    lo[0] = l0, lo[1] = l1, lo[2] = l2;
    hi[0] = h0, hi[1] = h1, hi[2] = h2;
#endif
    if (i < n)      /* lo and hi as far as it got */
        return st_error_set(err, ST_EINTERNAL, NULL, 0,
                            "triangle %zu refers to vertex %lu of %zu",
                            i / 3, (unsigned long)tri[i], nv);
    return ST_OK;
}

st_status st_soup_append(st_soup *dst, const st_soup *src, st_error *err)
{
    const size_t base = dst->nverts;
    for (size_t v = 0; v < src->nverts; v++) {
        const double *q = src->xyz + 3 * v;
        st_status st = st_soup_add_vertex(dst, q[0], q[1], q[2], err);
        if (st)
            return st;
    }
    for (size_t t = 0; t < src->ntris; t++) {
        const uint32_t *c = src->tris + 3 * t;
        st_status st = st_soup_add_triangle(dst, (uint32_t)(base + c[0]), (uint32_t)(base + c[1]),
                                            (uint32_t)(base + c[2]), err);
        if (st)
            return st;
    }
    return ST_OK;
}
