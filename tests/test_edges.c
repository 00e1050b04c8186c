/*
 * test_edges.c - the one definition of a soup's topology: exact welding
 * (weld.h) and edges, duplicates and pieces (edges.h), on tiny inline
 * shapes with known answers.
 */
#include "souptet/edges.h"
#include "souptet/weld.h"
#include "shapes.h"
#define SPLITMIX_SEED 55
#include "splitmix.h"
#include "tap.h"

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static st_soup *new_soup(void)
{
    st_soup *s = st_soup_new();
    if (!s)
        abort();
    return s;
}

static uint32_t vert(st_soup *s, double x, double y, double z)
{
    st_soup_add_vertex(s, x, y, z, NULL);
    return (uint32_t)(s->nverts - 1);
}

/* Edges of e with exactly n half-edges. */
static size_t edges_of(const st_soup_edges *e, size_t n)
{
    size_t c = 0;
    for (size_t i = 0, j; i < e->nhalf; i = j) {
        j = st_soup_edges_run_end(e, i);
        c += j - i == n;
    }
    return c;
}

static size_t pieces(const st_soup_edges *e, const st_soup *s)
{
    size_t c = 0;
    for (size_t t = 0; t < s->ntris; t++)
        c += e->kept[t] && e->piece[t] == t;
    return c;
}

static void test_weld(void)
{
    st_soup *s = new_soup();
    uint32_t a = vert(s, 0, 0, 0), b = vert(s, 1, 0, 0), c = vert(s, 0, 1, 0);
    uint32_t a2 = vert(s, -0.0, 0, -0.0);                 /* a, signed zeros */
    uint32_t b2 = vert(s, 1 + 0x1p-52, 0, 0);             /* one ulp from b */
    vert(s, 5, 5, 5);                                     /* used by none */
    st_soup_add_triangle(s, a, b, c, NULL);
    st_soup_add_triangle(s, a2, c, b2, NULL);
    uint32_t w[6];
    size_t n = 0;
    st_error err;
    TAP_CHECK(st_weld_vertices(w, &n, s, &err) == ST_OK, "weld: ST_OK");
    TAP_CHECK(n == 4, "weld: 4 distinct points among 5 used vertices (%zu)", n);
    TAP_CHECK(w[a] == 0 && w[b] == 1 && w[c] == 2, "weld: ids in order of first use");
    TAP_CHECK(w[a2] == w[a], "weld: -0 is 0");
    TAP_CHECK(w[b2] != w[b], "weld: one ulp apart stays apart (no epsilon)");
    TAP_CHECK(w[5] == ST_WELD_NONE, "weld: an unused vertex has no id");
    st_soup_free(s);
}

static void test_closed_box(void)
{
    st_soup *s = new_soup();
    const double lo[3] = {0, 0, 0}, hi[3] = {1, 2, 3};
    add_box(s, lo, hi);   /* an exact soup, every other triangle flipped */
    st_soup_edges e;
    st_error err;
    TAP_CHECK(st_soup_edges_build(&e, s, &err) == ST_OK, "box: edges built");
    TAP_CHECK(e.nweld == 8, "box: 36 vertices weld to 8 (%zu)", e.nweld);
    TAP_CHECK(e.nhalf == 36 && edges_of(&e, 2) == 18 && edges_of(&e, 1) == 0,
              "box: 18 edges of two triangles, none open");
    TAP_CHECK(pieces(&e, s) == 1 && e.piece[11] == 0, "box: one piece, named 0");
    TAP_CHECK(e.degenerate == 0 && e.duplicates == 0, "box: nothing degenerate or duplicated");
    uint32_t *nbr = malloc(3 * s->ntris * sizeof *nbr);
    uint8_t *same = malloc(3 * s->ntris), open[12] = {0};
    st_soup_edges_neighbours(&e, s, nbr, same, open);
    size_t nsame = 0, nnone = 0;
    for (size_t i = 0; i < 3 * s->ntris; i++) {
        nsame += same[i];
        nnone += nbr[i] == ST_EDGES_NONE;
    }
    /* add_box flips every other triangle: inside a face the two halves
     * disagree (6 edges), across faces some do: the count is even (both
     * sides of an edge count) and not zero. */
    TAP_CHECK(nnone == 0 && nsame > 0 && nsame % 2 == 0,
              "box: every triangle has 3 neighbours, %zu slots run the same way", nsame);
    TAP_CHECK(open[0] == 0, "box: the piece is not open");
    /* orientation by propagation: one region, no conflict, and every
     * triangle turned where add_box flipped it relative to triangle 0 */
    uint8_t flip[12];
    uint32_t region[12], queue[12];
    size_t nq = 0;
    const size_t conflicts = st_soup_edges_orient(&e, s, nbr, same, flip, region, queue, &nq);
    int consistent = 1, one = 1;
    for (size_t t = 0; t < 12; t++) {
        consistent &= flip[t] == (uint8_t)((t & 1) != 0);
        one &= region[t] == 0;
    }
    TAP_CHECK(conflicts == 0 && nq == 12 && one && queue[0] == 0 && consistent,
              "box: one orientable region, the flipped triangles turned (%zu conflicts)",
              conflicts);
    free(nbr);
    free(same);
    st_soup_edges_free(&e);

    st_soup *o = new_soup();
    add_box_oriented(o, lo, hi);
    TAP_CHECK(st_soup_edges_build(&e, o, &err) == ST_OK, "oriented box: edges built");
    int agree = 1;
    for (size_t i = 0, j; i < e.nhalf; i = j) {
        j = st_soup_edges_run_end(&e, i);
        uint32_t u = (uint32_t)(e.he[i].key >> 32), v = (uint32_t)e.he[i].key;
        agree &= st_soup_edges_forward(&e, o, e.he[i].t, u, v) !=
                 st_soup_edges_forward(&e, o, e.he[i + 1].t, u, v);
    }
    TAP_CHECK(agree, "oriented box: the two triangles of every edge run along it opposite ways");
    uint32_t t0w = e.weld[o->tris[1]];
    TAP_CHECK(st_soup_edges_corner(&e, o, 0, t0w) == 1 &&
              st_soup_edges_corner(&e, o, 0, 1000) == -1, "corner: found by welded point");
    st_soup_edges_free(&e);
    st_soup_free(o);
    st_soup_free(s);
}

static void test_damage(void)
{
    /* Two triangles sharing an edge, a copy of the first in the other
     * order, a degenerate one (repeated index) twice, and a triangle apart. */
    st_soup *s = new_soup();
    uint32_t a = vert(s, 0, 0, 0), b = vert(s, 1, 0, 0), c = vert(s, 0, 1, 0),
             d = vert(s, 1, 1, 0), f = vert(s, 5, 0, 0), g = vert(s, 6, 0, 0),
             h = vert(s, 5, 1, 0);
    st_soup_add_triangle(s, a, b, c, NULL);   /* 0 */
    st_soup_add_triangle(s, b, d, c, NULL);   /* 1 */
    st_soup_add_triangle(s, c, b, a, NULL);   /* 2: copy of 0, flipped */
    st_soup_add_triangle(s, a, a, b, NULL);   /* 3: degenerate */
    st_soup_add_triangle(s, a, b, a, NULL);   /* 4: degenerate, a copy of 3 */
    st_soup_add_triangle(s, f, g, h, NULL);   /* 5: apart */
    st_soup_edges e;
    st_error err;
    TAP_CHECK(st_soup_edges_build(&e, s, &err) == ST_OK, "damage: edges built");
    TAP_CHECK(e.degenerate == 2 && e.duplicates == 2,
              "damage: 2 degenerate, 2 extra copies (one of them degenerate) (%zu, %zu)",
              e.degenerate, e.duplicates);
    TAP_CHECK(e.kept[0] && e.kept[1] && !e.kept[2] && !e.kept[3] && !e.kept[4] && e.kept[5],
              "damage: the first copy kept, the copy and the degenerate left out");
    TAP_CHECK(e.nhalf == 9 && edges_of(&e, 2) == 1 && edges_of(&e, 1) == 7,
              "damage: without the copy, one shared edge and 7 open ones");
    TAP_CHECK(pieces(&e, s) == 2 && e.piece[1] == 0 && e.piece[5] == 5 && e.piece[2] == 2,
              "damage: pieces {0, 1} and {5}; the copy left out is its own");
    st_soup_edges_free(&e);

    TAP_CHECK(st_soup_edges_build_opts(&e, s, ST_EDGES_DUPLICATES, &err) == ST_OK,
              "damage, duplicates kept: edges built");
    TAP_CHECK(e.nhalf == 12 && edges_of(&e, 3) == 1 && edges_of(&e, 2) == 2,
              "damage, duplicates kept: the copy makes edge bc of three triangles, ab and ca of two");
    TAP_CHECK(!e.kept[2] && e.piece[2] == 0, "damage, duplicates kept: the copy is in piece 0, still not kept");
    TAP_CHECK(e.degenerate == 2 && e.duplicates == 2, "damage, duplicates kept: the same counts");
    st_soup_edges_free(&e);
    st_soup_free(s);
}

/* Reversing the order of the triangles renames pieces by their smallest
 * triangle, nothing else: the same number of edges of each length. */
static void test_order(void)
{
    st_soup *s = new_soup(), *r = new_soup();
    add_sphere(s, 1.0, 0.5);   /* open at the top */
    for (size_t v = 0; v < s->nverts; v++)
        st_soup_add_vertex(r, s->xyz[3 * v], s->xyz[3 * v + 1], s->xyz[3 * v + 2], NULL);
    for (size_t t = s->ntris; t-- > 0;)
        st_soup_add_triangle(r, s->tris[3 * t], s->tris[3 * t + 1], s->tris[3 * t + 2], NULL);
    st_soup_edges e, f;
    st_error err;
    st_soup_edges_build(&e, s, &err);
    st_soup_edges_build(&f, r, &err);
    int same = e.nhalf == f.nhalf && e.nweld == f.nweld;
    for (size_t n = 1; n <= 3; n++)
        same &= edges_of(&e, n) == edges_of(&f, n);
    TAP_CHECK(same && edges_of(&e, 1) > 0, "order: reversed triangles, the same edges (%zu open)",
              edges_of(&e, 1));
    TAP_CHECK(pieces(&e, s) == 1 && pieces(&f, r) == 1 && f.piece[0] == 0,
              "order: one piece either way, named by its smallest triangle");
    st_soup_edges_free(&e);
    st_soup_edges_free(&f);
    st_soup_free(s);
    st_soup_free(r);
}

/* More than 2^16 welded vertices, the triangles scrambled and some
 * duplicated: the half-edges still run by key, ties by triangle, and a
 * grid's edges come out as counted by hand. */
static void test_many_vertices(void)
{
    enum { N = 260 };   /* N * N = 67600 vertices */
    const size_t quads = (size_t)(N - 1) * (N - 1), nt = 2 * quads;
    st_soup *s = new_soup();
    for (int j = 0; j < N; j++)
        for (int i = 0; i < N; i++)
            vert(s, i, j, 0.25 * ((i * 7 + j * 3) % 5));
    for (size_t q = 0; q < nt; q++) {
        const size_t x = (q * 40503u) % nt;   /* 40503 is coprime to nt: a permutation */
        const uint32_t i = (uint32_t)(x / 2 % (N - 1)), j = (uint32_t)(x / 2 / (N - 1));
        const uint32_t a = j * N + i, b = a + 1, c = a + N, d = c + 1;
        if (x % 2)
            st_soup_add_triangle(s, b, d, c, NULL);
        else
            st_soup_add_triangle(s, a, b, c, NULL);
    }
    for (size_t t = 0; t < nt; t += 97)       /* reversed copies */
        st_soup_add_triangle(s, s->tris[3 * t + 2], s->tris[3 * t + 1], s->tris[3 * t], NULL);
    for (unsigned flags = 0; flags <= ST_EDGES_DUPLICATES; flags += ST_EDGES_DUPLICATES) {
        st_soup_edges e;
        st_error err;
        TAP_CHECK(st_soup_edges_build_opts(&e, s, flags, &err) == ST_OK && e.nweld == N * N,
                  "many vertices (flags %u): built, %zu welded", flags, e.nweld);
        int sorted = 1, ends = 1;
        for (size_t h = 0; h < e.nhalf; h++) {
            const uint64_t lo = e.he[h].key >> 32, hi = e.he[h].key & 0xffffffffu;
            ends &= lo < hi && hi < e.nweld;
            if (h > 0)
                sorted &= e.he[h - 1].key < e.he[h].key ||
                          (e.he[h - 1].key == e.he[h].key && e.he[h - 1].t < e.he[h].t);
        }
        TAP_CHECK(sorted && ends, "many vertices (flags %u): by key, ties by triangle", flags);
        const size_t copies = (nt + 96) / 97, boundary = 4 * (N - 1);
        const size_t all = 3 * quads + 2 * (N - 1);    /* the grid's edges */
        int first_kept = 1;   /* the first of each set of copies is kept */
        for (size_t t = 0; t < s->ntris; t++)
            first_kept &= e.kept[t] == (t < nt);
        TAP_CHECK(first_kept, "many vertices (flags %u): each original kept, each later "
                  "reversed copy not", flags);
        TAP_CHECK(e.duplicates == copies &&
                  e.nhalf == 3 * (flags ? nt + copies : nt), "many vertices (flags %u): "
                  "%zu duplicates, %zu half-edges", flags, e.duplicates, e.nhalf);
        if (!flags)
            TAP_CHECK(edges_of(&e, 1) == boundary && edges_of(&e, 2) == all - boundary &&
                      pieces(&e, s) == 1, "many vertices: the grid's %zu boundary and %zu "
                      "inner edges, one piece", boundary, all - boundary);
        else
            TAP_CHECK(edges_of(&e, 1) + edges_of(&e, 2) + edges_of(&e, 3) + edges_of(&e, 4) ==
                      all && edges_of(&e, 3) + edges_of(&e, 4) > 0,
                      "many vertices, duplicates kept: the same %zu edges, some of 3 or 4", all);
        st_soup_edges_free(&e);
    }
    st_soup_free(s);
}

/* The table by its definition (edges.h), the slow way: every triangle's
 * sorted welded corners compared with every earlier one's through one
 * qsort by (corners, triangle), and the half-edges through one qsort by
 * (key, triangle). */
typedef struct ref_key {
    uint32_t k[3], t;
} ref_key;

static int ref_key_cmp(const void *x, const void *y)
{
    const ref_key *p = x, *q = y;
    for (int j = 0; j < 3; j++)
        if (p->k[j] != q->k[j])
            return p->k[j] < q->k[j] ? -1 : 1;
    return p->t < q->t ? -1 : p->t > q->t;
}

static int ref_half_cmp(const void *x, const void *y)
{
    const st_half_edge *p = x, *q = y;
    if (p->key != q->key)
        return p->key < q->key ? -1 : 1;
    return p->t < q->t ? -1 : p->t > q->t;
}

/* 1 when e is the table the definition gives for s with flags. */
static int matches_reference(const st_soup_edges *e, const st_soup *s, unsigned flags)
{
    const size_t nt = s->ntris;
    ref_key *k = calloc(nt + 1, sizeof *k);
    uint8_t *kept = calloc(nt + 1, 1);
    st_half_edge *he = calloc(3 * nt + 1, sizeof *he);
    if (!k || !kept || !he)
        abort();
    size_t dups = 0, degenerate = 0, nh = 0;
    for (size_t t = 0; t < nt; t++) {
        uint32_t c[3];
        for (int j = 0; j < 3; j++)
            c[j] = e->weld[s->tris[3 * t + (size_t)j]];
        for (int i = 0; i < 3; i++)
            for (int j = i + 1; j < 3; j++)
                if (c[j] < c[i]) {
                    const uint32_t x = c[i];
                    c[i] = c[j];
                    c[j] = x;
                }
        memcpy(k[t].k, c, sizeof c);
        k[t].t = (uint32_t)t;
        degenerate += c[0] == c[1] || c[1] == c[2];
    }
    qsort(k, nt, sizeof *k, ref_key_cmp);
    for (size_t i = 0; i < nt; i++) {
        const int dup = i > 0 && memcmp(k[i].k, k[i - 1].k, sizeof k[i].k) == 0;
        dups += (size_t)dup;
        kept[k[i].t] = (uint8_t)(k[i].k[0] != k[i].k[1] && k[i].k[1] != k[i].k[2] && !dup);
        if (k[i].k[0] == k[i].k[1] || k[i].k[1] == k[i].k[2] ||
            (!kept[k[i].t] && !(flags & ST_EDGES_DUPLICATES)))
            continue;
        const uint64_t a = k[i].k[0], b = k[i].k[1], c = k[i].k[2];
        const uint64_t keys[3] = {a << 32 | b, b << 32 | c, a << 32 | c};
        for (int j = 0; j < 3; j++) {
            he[nh].key = keys[j];
            he[nh++].t = k[i].t;
        }
    }
    qsort(he, nh, sizeof *he, ref_half_cmp);
    int same = e->nhalf == nh && e->duplicates == dups && e->degenerate == degenerate;
    for (size_t t = 0; t < nt && same; t++)
        same = e->kept[t] == kept[t];
    for (size_t h = 0; h < nh && same; h++)
        same = e->he[h].key == he[h].key && e->he[h].t == he[h].t;
    free(k);
    free(kept);
    free(he);
    return same;
}

/* Random soups over few points: fans of hundreds of triangles around one
 * vertex (the buckets sorted by qsort), duplicates in any corner order,
 * degenerate triangles, triangles repeated far apart; each table is the
 * definition's, half-edge for half-edge. Pins the counting sorts (edges.c)
 * to the order of the radix sorts they replaced. */
static void test_reference(void)
{
    int all = 1;
    size_t tables = 0;
    for (int round = 0; round < 12; round++) {
        st_soup *s = new_soup();
        const int npts = round < 4 ? 6 : round < 8 ? 40 : 400;
        for (int v = 0; v < npts; v++)
            vert(s, (double)rng_int(3), (double)rng_int(3), (double)(v / 8));
        for (int t = 0; t < 3000; t++) {
            uint32_t c[3];
            for (int j = 0; j < 3; j++)
                c[j] = (uint32_t)(rng_next() % (uint64_t)npts);
            if (t % 3 == 0)
                c[0] = 0;                       /* a fan around point 0 */
            if (t > 10 && t % 7 == 0) {         /* an earlier triangle, rotated or turned */
                const uint32_t *o = s->tris + 3 * (rng_next() % (uint64_t)s->ntris);
                const int r = (int)(rng_next() % 3), turn = (int)(rng_next() % 2);
                for (int j = 0; j < 3; j++)
                    c[j] = o[turn ? (r + 3 - j) % 3 : (r + j) % 3];
            }
            st_soup_add_triangle(s, c[0], c[1], c[2], NULL);
        }
        for (unsigned flags = 0; flags <= ST_EDGES_DUPLICATES; flags += ST_EDGES_DUPLICATES) {
            st_soup_edges e;
            st_error err;
            if (st_soup_edges_build_opts(&e, s, flags, &err) != ST_OK) {
                all = 0;
                continue;
            }
            all &= matches_reference(&e, s, flags) && e.duplicates > 0 && e.degenerate > 0;
            tables++;
            st_soup_edges_free(&e);
        }
        st_soup_free(s);
    }
    TAP_CHECK(all && tables == 24, "reference: %zu random tables with fans, duplicates and "
              "degenerate triangles are the definition's", tables);
}

int main(int argc, char **argv)
{
    static const tap_test tests[] = {TAP_TEST(weld), TAP_TEST(closed_box), TAP_TEST(damage),
                                     TAP_TEST(order), TAP_TEST(many_vertices),
                                     TAP_TEST(reference), {0}};
    return tap_main(argc, argv, tests);
}
