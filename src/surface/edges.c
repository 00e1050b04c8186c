/*
 * edges.c - edges and pieces of a soup on welded vertices (see edges.h).
 *
 *   1. weld the vertices exactly; sort each triangle's welded corners
 *      (a <= b <= c); bucket the triangles by a (a counting sort, in
 *      triangle order) and, within each bucket, find the triangles whose
 *      (b, c) an earlier one has: the duplicates; keep every triangle that
 *      is neither degenerate nor a duplicate;
 *   2. bucket the kept triangles' half-edges (with ST_EDGES_DUPLICATES,
 *      every non-degenerate triangle's) by their lower welded end (a
 *      counting sort, in triangle order), then sort each bucket by the
 *      higher end, stably: the order by unordered ends, ties by triangle
 *      (total);
 *   3. join the triangles of every edge (unionfind.h: toward the smaller
 *      index, so every root is its piece's smallest triangle).
 *
 * The counting sorts place each element once, with no scratch copy of the
 * half-edges: on a 10M-triangle soup the radix sorts they replace (three
 * and five 16-bit passes, a 480 MB scratch array) took most of the table's
 * time and fresh memory (doc/design/edges.md).
 */
#include "souptet/edges.h"
#include "souptet/mem.h"
#include "souptet/weld.h"
#include "../base/unionfind.h"

#include <stdlib.h>
#include <string.h>

/* Buckets up to this long are searched or sorted in place by insertion
 * (a vertex's bucket holds about six half-edges on a mesh); longer ones
 * (fans) by qsort, on keys that are unique within a bucket, so the order
 * is the same either way. */
#define SMALL_BUCKET 32

/* Arrays of buckets this long are swept in parallel (each bucket is
 * independent: the result does not depend on the threads). */
#define PARALLEL_MIN 65536

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

/* Counts per bucket (bucket i's in cnt[i + 1], cnt[0] 0) into starts:
 * cnt[i] becomes the first slot of bucket i (the prefix sums). */
static void bucket_starts(size_t *cnt, size_t nb)
{
    for (size_t i = 1; i <= nb; i++)
        cnt[i] += cnt[i - 1];
}

/* (b, c, t) triples of one bucket, for qsort: by b, c, then t. */
static int triple_cmp(const void *x, const void *y)
{
    const uint32_t *p = x, *q = y;
    for (int k = 0; k < 3; k++)
        if (p[k] != q[k])
            return p[k] < q[k] ? -1 : 1;
    return 0;
}

/* Step 1 within the bucket ids[0..m) (triangles in increasing order, all
 * with the same smallest corner; srt their sorted corners): dup[i] = 1
 * when an earlier triangle of the bucket has the same two other corners.
 * Returns the duplicates, or SIZE_MAX when out of memory. */
static size_t bucket_duplicates(const uint32_t *ids, size_t m, const uint32_t *srt,
                                uint8_t *dup)
{
    size_t n = 0;
    if (m <= SMALL_BUCKET) {
        for (size_t i = 0; i < m; i++) {
            const uint32_t *k = srt + 3 * (size_t)ids[i];
            dup[i] = 0;
            for (size_t j = 0; j < i && !dup[i]; j++) {
                const uint32_t *q = srt + 3 * (size_t)ids[j];
                dup[i] = k[1] == q[1] && k[2] == q[2];
            }
            n += dup[i];
        }
        return n;
    }
    uint32_t *tr = malloc(m * 3 * sizeof *tr);
    if (!tr)
        return SIZE_MAX;
    for (size_t i = 0; i < m; i++) {
        tr[3 * i] = srt[3 * (size_t)ids[i] + 1];
        tr[3 * i + 1] = srt[3 * (size_t)ids[i] + 2];
        tr[3 * i + 2] = (uint32_t)i;   /* ids ascend: the index orders as t */
    }
    qsort(tr, m, 3 * sizeof *tr, triple_cmp);
    for (size_t i = 0; i < m; i++) {
        const int d = i > 0 && tr[3 * i] == tr[3 * i - 3] && tr[3 * i + 1] == tr[3 * i - 2];
        dup[tr[3 * i + 2]] = (uint8_t)d;
        n += (size_t)d;
    }
    free(tr);
    return n;
}

static int half_cmp(const void *x, const void *y)
{
    const st_half_edge *p = x, *q = y;
    if (p->key != q->key)
        return p->key < q->key ? -1 : 1;
    return p->t < q->t ? -1 : p->t > q->t;
}

/* Step 2 within one bucket: by key, stably (the bucket is in triangle
 * order, and a triangle has one half-edge per key, so (key, t) is unique
 * and qsort's order is the stable one). */
static void sort_bucket(st_half_edge *h, size_t m)
{
    if (m > SMALL_BUCKET) {
        qsort(h, m, sizeof *h, half_cmp);
        return;
    }
    for (size_t i = 1; i < m; i++) {
        const st_half_edge x = h[i];
        size_t j = i;
        for (; j > 0 && h[j - 1].key > x.key; j--)
            h[j] = h[j - 1];
        h[j] = x;
    }
}

/* Step 1: e->kept, e->degenerate, e->duplicates from the sorted corners
 * srt; cnt holds nweld + 1 zeroed counters. ST_ENOMEM. */
static st_status mark_kept(st_soup_edges *e, const uint32_t *srt, size_t nt, size_t *cnt)
{
    const size_t nw = e->nweld;
    uint32_t *ids = st_malloc_big((nt + 1) * sizeof *ids);
    uint8_t *dup = st_malloc_big(nt + 1);
    if (!ids || !dup) {
        free(ids);
        free(dup);
        return ST_ENOMEM;
    }
    for (size_t t = 0; t < nt; t++) {
        cnt[srt[3 * t] + 1]++;
        e->degenerate += srt[3 * t] == srt[3 * t + 1] || srt[3 * t + 1] == srt[3 * t + 2];
    }
    bucket_starts(cnt, nw);
    for (size_t t = 0; t < nt; t++)
        ids[cnt[srt[3 * t]]++] = (uint32_t)t;   /* cnt[a] ends at bucket a + 1's start */
    size_t dups = 0, failed = 0;
    const long long lnw = (long long)nw;
    #pragma omp parallel for schedule(static) reduction(+ : dups, failed) if (nw >= PARALLEL_MIN)
    for (long long a = 0; a < lnw; a++) {
        const size_t lo = a ? cnt[a - 1] : 0, hi = cnt[a];
        const size_t n = bucket_duplicates(ids + lo, hi - lo, srt, dup + lo);
        if (n == SIZE_MAX)
            failed++;
        else
            dups += n;
    }
    for (size_t i = 0; i < nt && !failed; i++) {
        const uint32_t t = ids[i], *k = srt + 3 * (size_t)t;
        e->kept[t] = (uint8_t)(k[0] != k[1] && k[1] != k[2] && !dup[i]);
    }
    free(ids);
    free(dup);
    e->duplicates = dups;
    return failed ? ST_ENOMEM : ST_OK;
}

/* Step 2: e->he, e->nhalf from the sorted corners srt of the triangles
 * that give half-edges; cnt holds nweld + 1 counters. ST_ENOMEM. */
static st_status sort_half_edges(st_soup_edges *e, const uint32_t *srt, size_t nt,
                                 unsigned flags, size_t *cnt)
{
    const size_t nw = e->nweld;
    memset(cnt, 0, (nw + 1) * sizeof *cnt);
    size_t nh = 0;
    for (size_t t = 0; t < nt; t++) {
        const uint32_t *k = srt + 3 * t;
        if (k[0] == k[1] || k[1] == k[2] || (!e->kept[t] && !(flags & ST_EDGES_DUPLICATES)))
            continue;
        cnt[k[0] + 1] += 2;   /* (a, b) and (a, c) */
        cnt[k[1] + 1]++;      /* (b, c) */
        nh += 3;
    }
    bucket_starts(cnt, nw);
    for (size_t t = 0; t < nt; t++) {
        const uint32_t *k = srt + 3 * t;
        if (k[0] == k[1] || k[1] == k[2] || (!e->kept[t] && !(flags & ST_EDGES_DUPLICATES)))
            continue;
        const uint64_t a = k[0], b = k[1], c = k[2];
        st_half_edge *h = &e->he[cnt[a]++];
        h->key = a << 32 | b;
        h->t = (uint32_t)t;
        h = &e->he[cnt[b]++];
        h->key = b << 32 | c;
        h->t = (uint32_t)t;
        h = &e->he[cnt[a]++];
        h->key = a << 32 | c;
        h->t = (uint32_t)t;
    }
    const long long lnw = (long long)nw;
    #pragma omp parallel for schedule(static) if (nw >= PARALLEL_MIN)
    for (long long a = 0; a < lnw; a++) {
        const size_t lo = a ? cnt[a - 1] : 0;
        sort_bucket(e->he + lo, cnt[a] - lo);
    }
    e->nhalf = nh;
    return ST_OK;
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
    /* arrays over every triangle or vertex, read at random: huge pages
     * past a few MB (st_malloc_big; nt < 2^31 and the vertex count below
     * 2^32 keep the products in range) */
    e->weld = st_malloc_big((s->nverts + 1) * sizeof *e->weld);
    uint32_t *srt = st_malloc_big((3 * nt + 1) * sizeof *srt);
    if (!e->weld || !srt || st_weld_vertices(e->weld, &e->nweld, s, err)) {
        free(srt);
        st_soup_edges_free(e);
        return st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory for the soup's edges");
    }
    e->kept = st_calloc_big(nt + 1);
    size_t *cnt = st_calloc_big((e->nweld + 2) * sizeof *cnt);
    st_status rc = !e->kept || !cnt ? ST_ENOMEM : ST_OK;
    for (size_t t = 0; t < nt && !rc; t++) {
        uint32_t a = e->weld[s->tris[3 * t]], b = e->weld[s->tris[3 * t + 1]],
                 c = e->weld[s->tris[3 * t + 2]], x;
        if (a > b) { x = a; a = b; b = x; }
        if (b > c) { x = b; b = c; c = x; }
        if (a > b) { x = a; a = b; b = x; }
        srt[3 * t] = a;
        srt[3 * t + 1] = b;
        srt[3 * t + 2] = c;
    }
    /* 1. welded, non-degenerate, first of its duplicates */
    rc = rc ? rc : mark_kept(e, srt, nt, cnt);
    /* 2. half-edges of the kept triangles (with ST_EDGES_DUPLICATES, of
     * every non-degenerate one) */
    if (!rc && !(e->he = st_malloc_big((3 * nt + 1) * sizeof *e->he)))
        rc = ST_ENOMEM;
    rc = rc ? rc : sort_half_edges(e, srt, nt, flags, cnt);
    free(srt);
    free(cnt);
    size_t *uf = rc ? NULL : st_malloc_big((nt + 1) * sizeof *uf);
    e->piece = rc ? NULL : st_malloc_big((nt + 1) * sizeof *e->piece);
    if (rc || !uf || !e->piece) {
        free(uf);
        st_soup_edges_free(e);
        return st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory for the soup's edges");
    }

    /* 3. pieces */
    const size_t nh = e->nhalf;
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
