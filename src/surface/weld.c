/*
 * weld.c - exact welding of a soup's vertices (see weld.h): open
 * addressing on a hash of the coordinates' bits, compared exactly.
 */
#include "souptet/weld.h"
#include "../base/fpenv.h"
#include "souptet/mem.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#define NONE ST_WELD_NONE

static uint64_t mix64(uint64_t x)
{
    /* splitmix64's finaliser: every input bit affects every output bit */
    x ^= x >> 30;
    x *= 0xbf58476d1ce4e5b9ULL;
    x ^= x >> 27;
    x *= 0x94d049bb133111ebULL;
    x ^= x >> 31;
    return x;
}

static uint64_t coord_bits(double x)
{
    /* -0.0 == 0.0 compares equal, so both must hash alike. */
    if (x == 0.0)
        x = 0.0;
    uint64_t b;
    memcpy(&b, &x, sizeof b);
    return b;
}

static uint64_t point_hash(const double *p)
{
    return mix64(coord_bits(p[0]) ^
                 mix64(coord_bits(p[1]) ^ mix64(coord_bits(p[2]))));
}

st_status st_weld_vertices(uint32_t *weld, size_t *nweld, const st_soup *s,
                           st_error *err)
{
    *nweld = 0;
    size_t nref = 0;
    for (size_t v = 0; v < s->nverts; v++)
        weld[v] = NONE;
    for (size_t i = 0; i < 3 * s->ntris; i++) {
        if (weld[s->tris[i]] == NONE) {
            weld[s->tris[i]] = 0; /* mark: referenced */
            nref++;
        }
    }
    /* A load factor of at most 1/2 keeps probe sequences short. */
    size_t cap = 16;
    while (cap < 2 * nref)
        cap *= 2;
    /* the table is probed at random: huge pages past a few MB */
    uint32_t *table = st_malloc_big(cap * sizeof *table);
    uint32_t *rep = st_malloc_big((nref + 1) * sizeof *rep);
    if (!table || !rep) {
        free(table);
        free(rep);
        return st_error_set(err, ST_ENOMEM, NULL, 0,
                            "out of memory welding %zu vertices", nref);
    }
    for (size_t i = 0; i < cap; i++)
        table[i] = NONE;
    uint32_t n = 0;
    for (size_t v = 0; v < s->nverts; v++) {
        if (weld[v] == NONE)
            continue;
        const double *p = s->xyz + 3 * v;
        size_t slot = (size_t)point_hash(p) & (cap - 1);
        for (;;) {
            uint32_t w = table[slot];
            if (w == NONE) {
                table[slot] = n;
                rep[n] = (uint32_t)v;
                weld[v] = n++;
                break;
            }
            const double *q = s->xyz + 3 * (size_t)rep[w];
            if (p[0] == q[0] && p[1] == q[1] && p[2] == q[2]) {
                weld[v] = w;
                break;
            }
            slot = (slot + 1) & (cap - 1);
        }
    }
    free(table);
    free(rep);
    *nweld = n;
    return ST_OK;
}
