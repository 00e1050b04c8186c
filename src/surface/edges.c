/*
 * edges.c - edges and pieces of a soup on welded vertices (see edges.h).
 *
 *   1. weld the vertices exactly; sort the triangles by their sorted
 *      welded corners (ties by index): a run of equal corners is one
 *      triangle and its duplicates; keep the first of each run that is
 *      not degenerate;
 *   2. sort the kept triangles' half-edges (with ST_EDGES_DUPLICATES,
 *      every non-degenerate triangle's) by their unordered welded ends
 *      (ties by triangle: the order is total);
 *   3. join the triangles of every edge (unionfind.h: toward the smaller
 *      index, so every root is its piece's smallest triangle).
 */
#include "souptet/edges.h"
#include "souptet/mem.h"
#include "souptet/weld.h"
#include "../base/radix.h"
#include "../base/unionfind.h"

#include <stdlib.h>
#include <string.h>

typedef struct tri_key {
    uint32_t k[3];      /* sorted welded corners */
    uint32_t t;
} tri_key;

/* Digit `pass` of the key (k[0], k[1], k[2]) packed into 3 * bits bits
 * (every corner is below 2^bits), k[2] in the lowest: the key's order in
 * as few 16-bit passes as the packed width needs (4 rather than 6 on the
 * dragon). The keys are made in triangle order, so the stable passes
 * leave ties by t. */
static uint32_t tri_digit(const void *x, int pass, unsigned bits)
{
    const tri_key *k = x;
    const unsigned lo = 16u * (unsigned)pass;
    uint64_t d = 0;
    for (unsigned j = 0; j < 3; j++) {
        const unsigned start = j * bits;
        const uint64_t field = k->k[2 - j];
        if (start >= lo + 16 || start + bits <= lo)
            continue;
        d |= start >= lo ? field << (start - lo) : field >> (lo - start);
    }
    return (uint32_t)d & 0xffffu;
}

/* The key's ends packed into 2 * bits bits (both ends are below
 * 2^bits): the same order as the key's, in fewer passes. The half-edges
 * are made in triangle order, so the stable passes leave ties by t. */
static uint32_t half_digit(const void *x, int pass, unsigned bits)
{
    const st_half_edge *h = x;
    const uint64_t packed = (h->key >> 32) << bits | (h->key & 0xffffffffu);
    return (uint32_t)(packed >> (16 * pass)) & 0xffffu;
}

ST_RADIX_SORT_DEFINE(sort_tri_keys, sizeof(tri_key), tri_digit)
ST_RADIX_SORT_DEFINE(sort_half_edges, sizeof(st_half_edge), half_digit)

void st_soup_edges_free(st_soup_edges *e)
{
    if (!e)
        return;
    free(e->weld);
    free(e->kept);
    free(e->he);
    free(e->piece);
    memset(e, 0, sizeof *e);
}

st_status st_soup_edges_build(st_soup_edges *e, const st_soup *s, st_error *err)
{
    return st_soup_edges_build_opts(e, s, 0, err);
}

size_t st_soup_edges_run_end(const st_soup_edges *e, size_t i)
{
    size_t j = i + 1;
    while (j < e->nhalf && e->he[j].key == e->he[i].key)
        j++;
    return j;
}

int st_soup_edges_corner(const st_soup_edges *e, const st_soup *s, uint32_t t, uint32_t w)
{
    for (int c = 0; c < 3; c++)
        if (e->weld[s->tris[3 * (size_t)t + (size_t)c]] == w)
            return c;
    return -1;
}

st_status st_soup_edges_build_opts(st_soup_edges *e, const st_soup *s, unsigned flags,
                                   st_error *err)
{
    memset(e, 0, sizeof *e);
    if (s->ntris > (size_t)INT32_MAX)
        return st_error_set(err, ST_ELIMIT, NULL, 0,
                            "%zu triangles: the soup's edges are read for at most 2^31",
                            s->ntris);
    const size_t nt = s->ntris;
    /* arrays over every triangle or vertex, sorted and read at random:
     * huge pages past a few MB (st_malloc_big; nt < 2^31 and the vertex
     * count below 2^32 keep the products in range) */
    tri_key *keys = st_malloc_big((nt + 1) * sizeof *keys);
    e->weld = st_malloc_big((s->nverts + 1) * sizeof *e->weld);
    e->kept = st_calloc_big(nt + 1);
    e->he = st_malloc_big((3 * nt + 1) * sizeof *e->he);
    e->piece = st_malloc_big((nt + 1) * sizeof *e->piece);
    size_t *uf = st_malloc_big((nt + 1) * sizeof *uf);
    /* the radix sorts' scratch: the half-edges */
    st_half_edge *tmp = st_malloc_big((3 * nt + 1) * sizeof *tmp);
    if (!keys || !e->weld || st_weld_vertices(e->weld, &e->nweld, s, err) ||
        !e->kept || !e->he || !e->piece || !uf || !tmp) {
        free(keys);
        free(uf);
        free(tmp);
        st_soup_edges_free(e);
        return st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory for the soup's edges");
    }

    /* 1. welded, non-degenerate, first of its duplicates */
    size_t nk = 0;
    for (size_t t = 0; t < nt; t++) {
        uint32_t a = e->weld[s->tris[3 * t]], b = e->weld[s->tris[3 * t + 1]],
                 c = e->weld[s->tris[3 * t + 2]], x;
        e->degenerate += a == b || b == c || a == c;
        if (a > b) { x = a; a = b; b = x; }
        if (b > c) { x = b; b = c; c = x; }
        if (a > b) { x = a; a = b; b = x; }
        keys[nk].k[0] = a;
        keys[nk].k[1] = b;
        keys[nk].k[2] = c;
        keys[nk].t = (uint32_t)t;
        nk++;
    }
    _Static_assert(sizeof(tri_key) <= sizeof(st_half_edge), "the scratch holds the keys");
    unsigned bits = 0;   /* every welded index is below 2^bits */
    while (bits < 32 && (e->nweld - 1) >> bits)
        bits++;
    if (sort_tri_keys(keys, tmp, nk, (int)((3 * bits + 15) / 16), bits)) {
        free(keys);
        free(uf);
        free(tmp);
        st_soup_edges_free(e);
        return st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory for the soup's edges");
    }

    /* 2. half-edges of the kept triangles (with ST_EDGES_DUPLICATES, of
     * every non-degenerate one), made in triangle order */
    for (size_t i = 0; i < nk; i++) {
        const uint32_t *k = keys[i].k, t = keys[i].t;
        const int dup = i > 0 && memcmp(k, keys[i - 1].k, sizeof keys[i].k) == 0;
        e->duplicates += dup;
        e->kept[t] = (uint8_t)(k[0] != k[1] && k[1] != k[2] && !dup);
    }
    free(keys);
    size_t nh = 0;
    for (size_t t = 0; t < nt; t++) {
        uint32_t a = e->weld[s->tris[3 * t]], b = e->weld[s->tris[3 * t + 1]],
                 c = e->weld[s->tris[3 * t + 2]], x;
        if (a > b) { x = a; a = b; b = x; }
        if (b > c) { x = b; b = c; c = x; }
        if (a > b) { x = a; a = b; b = x; }
        if (a == b || b == c || (!e->kept[t] && !(flags & ST_EDGES_DUPLICATES)))
            continue;
        const uint64_t ends[3] = {(uint64_t)a << 32 | b, (uint64_t)b << 32 | c,
                                  (uint64_t)a << 32 | c};
        for (int j = 0; j < 3; j++) {
            e->he[nh].key = ends[j];
            e->he[nh].t = (uint32_t)t;
            nh++;
        }
    }
    const int sorted = sort_half_edges(e->he, tmp, nh, (int)((2 * bits + 15) / 16), bits);
    free(tmp);
    if (sorted) {
        free(uf);
        st_soup_edges_free(e);
        return st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory for the soup's edges");
    }
    e->nhalf = nh;

    /* 3. pieces */
    for (size_t t = 0; t < nt; t++)
        uf[t] = t;
    for (size_t i = 0, j; i < nh; i = j)
        for (j = i + 1; j < nh && e->he[j].key == e->he[i].key; j++)
            uf_join(uf, e->he[i].t, e->he[j].t);
    for (size_t t = 0; t < nt; t++)
        e->piece[t] = (uint32_t)uf_find(uf, t);
    free(uf);
    return ST_OK;
}

int st_soup_edges_forward(const st_soup_edges *e, const st_soup *s, uint32_t t,
                          uint32_t a, uint32_t b)
{
    const uint32_t *v = s->tris + 3 * (size_t)t;
    for (int c = 0; c < 3; c++)
        if (e->weld[v[c]] == a)
            return e->weld[v[(c + 1) % 3]] == b;
    return 0;
}

void st_soup_edges_neighbours(const st_soup_edges *e, const st_soup *s, uint32_t *nbr,
                              uint8_t *same, uint8_t *open)
{
    for (size_t i = 0; i < 3 * s->ntris; i++) {
        nbr[i] = ST_EDGES_NONE;
        same[i] = 0;
    }
    for (size_t i = 0, j; i < e->nhalf; i = j) {
        for (j = i + 1; j < e->nhalf && e->he[j].key == e->he[i].key; j++)
            ;
        const uint32_t t1 = e->he[i].t;
        if (j - i != 2) {
            if (open)
                open[e->piece[t1]] = 1;
            continue;
        }
        const uint32_t t2 = e->he[i + 1].t;
        const uint32_t a = (uint32_t)(e->he[i].key >> 32), b = (uint32_t)e->he[i].key;
        const uint8_t sd = st_soup_edges_forward(e, s, t1, a, b) ==
                           st_soup_edges_forward(e, s, t2, a, b);
        for (int k = 0; k < 2; k++) {
            const uint32_t t = k ? t2 : t1, o = k ? t1 : t2;
            size_t slot = 3 * (size_t)t;
            while (nbr[slot] != ST_EDGES_NONE)
                slot++;          /* at most 3: one per edge of t */
            nbr[slot] = o;
            same[slot] = sd;
        }
    }
}

size_t st_soup_edges_orient(const st_soup_edges *e, const st_soup *s, const uint32_t *nbr,
                            const uint8_t *same, uint8_t *flip, uint32_t *region,
                            uint32_t *queue, size_t *nkept)
{
    const size_t nt = s->ntris;
    size_t conflicts = 0, qt = 0;
    memset(flip, 2, nt);
    for (size_t t0 = 0; t0 < nt; t0++) {
        if (!e->kept[t0] || flip[t0] != 2)
            continue;
        size_t qh = qt;
        flip[t0] = 0;
        if (region)
            region[t0] = (uint32_t)t0;
        queue[qt++] = (uint32_t)t0;
        while (qh < qt) {
            const uint32_t t = queue[qh++];
            for (size_t slot = 3 * (size_t)t; slot < 3 * (size_t)t + 3; slot++) {
                const uint32_t q = nbr[slot];
                if (q == ST_EDGES_NONE)
                    continue;
                const uint8_t want = (uint8_t)(flip[t] ^ same[slot]);
                if (flip[q] == 2) {
                    flip[q] = want;
                    if (region)
                        region[q] = (uint32_t)t0;
                    queue[qt++] = q;
                } else if (flip[q] != want) {
                    conflicts++;
                }
            }
        }
    }
    if (nkept)
        *nkept = qt;
    return conflicts;
}
