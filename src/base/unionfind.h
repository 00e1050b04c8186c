/*
 * unionfind.h - disjoint sets over 0..n-1 (private to the library):
 * path halving, and the smaller root always wins a join, so the classes'
 * names (their smallest member) do not depend on the order of the joins.
 */
#ifndef SOUPTET_UNIONFIND_H
#define SOUPTET_UNIONFIND_H

#include <stddef.h>

static inline size_t uf_find(size_t *parent, size_t x)
{
    while (parent[x] != x) {
        parent[x] = parent[parent[x]];
        x = parent[x];
    }
    return x;
}

static inline void uf_join(size_t *parent, size_t a, size_t b)
{
    a = uf_find(parent, a);
    b = uf_find(parent, b);
    if (a != b)
        parent[a > b ? a : b] = a > b ? b : a;
}

#endif
