/* test_dist.c - distance fields against brute force, layout, determinism. */
#include "souptet/bvh.h"
#include "souptet/dist.h"
#include "souptet/geom.h"
#include "souptet/soup.h"
#include "tap.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#ifdef _OPENMP
#include <omp.h>
#endif

static double brute_dist(const st_soup *s, const double p[3])
{
    double best = INFINITY;
    for (size_t t = 0; t < s->ntris; t++) {
        const uint32_t *v = s->tris + 3 * t;
        double d2 = st_point_triangle_dist2(p, s->xyz + 3 * (size_t)v[0],
                                            s->xyz + 3 * (size_t)v[1],
                                            s->xyz + 3 * (size_t)v[2], NULL);
        if (d2 < best)
            best = d2;
    }
    return sqrt(best);
}

static st_soup *soup_from(const double *xyz, size_t nv, const uint32_t *tri,
                          size_t nt)
{
    st_soup *s = st_soup_new();
    for (size_t i = 0; i < nv; i++)
        st_soup_add_vertex(s, xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2], NULL);
    for (size_t i = 0; i < nt; i++)
        st_soup_add_triangle(s, tri[3 * i], tri[3 * i + 1], tri[3 * i + 2], NULL);
    return s;
}

static unsigned rng = 777;
static double urand(void)
{
    rng = rng * 1103515245u + 12345u;
    return (double)((rng >> 8) & 0xffffff) / 16777216.0;
}

/* A random triangle of the given size around c appended to s; with
 * `collinear`, its third vertex continues the first two (degenerate). */
static void add_random_triangle(st_soup *s, const double c[3], double size, int collinear)
{
    for (int k = 0; k < 3; k++) {
        double x = c[0] + size * (urand() - 0.5);
        double y = c[1] + size * (urand() - 0.5);
        double z = c[2] + size * (urand() - 0.5);
        if (collinear && k == 2) {
            const double *a = s->xyz + 3 * (s->nverts - 2);
            const double *b = s->xyz + 3 * (s->nverts - 1);
            x = 2 * b[0] - a[0];
            y = 2 * b[1] - a[1];
            z = 2 * b[2] - a[2];
        }
        st_soup_add_vertex(s, x, y, z, NULL);
    }
    uint32_t v = (uint32_t)(s->nverts - 3);
    st_soup_add_triangle(s, v, v + 1, v + 2, NULL);
}

/* Random triangles of all sizes and orientations, some degenerate. */
static st_soup *random_soup(size_t n)
{
    st_soup *s = st_soup_new();
    for (size_t t = 0; t < n; t++) {
        double c[3] = {urand(), urand(), urand()};
        double size = t % 7 == 0 ? 0.8 : 0.05 + 0.1 * urand();
        add_random_triangle(s, c, size, t % 11 == 0);
    }
    return s;
}

/* Every voxel against brute force: exact (float rounding) within the band,
 * clamped beyond it. Returns the number of mismatches. */
static size_t check_field(const st_grid *g, const st_soup *s, double *max_err)
{
    size_t bad = 0;
    *max_err = 0.0;
    for (size_t k = 0; k < g->nz; k++)
        for (size_t j = 0; j < g->ny; j++)
            for (size_t i = 0; i < g->nx; i++) {
                double p[3];
                st_grid_center(g, i, j, k, p);
                double ref = brute_dist(s, p);
                double got = g->data[st_grid_index(g, i, j, k)];
                double want = ref < g->band ? ref : g->band;
                /* float storage: half an ulp of the value, plus the double
                 * computation's rounding */
                double tol = 1e-6 * fmax(want, g->voxel);
                double e = fabs(got - want);
                if (ref >= g->band && got == (float)g->band)
                    e = 0.0;
                if (e > *max_err)
                    *max_err = e;
                if (e > tol)
                    bad++;
            }
    return bad;
}

/* The true distance from p: brute force over every triangle, or, for a
 * real model, the BVH's nearest query (itself checked against brute force
 * in test_bvh_nearest), which keeps a whole-grid check to a fraction of a
 * second. */
static double true_dist(const st_soup *s, const st_bvh *bvh, const double p[3])
{
    if (!bvh)
        return brute_dist(s, p);
    int64_t tri;
    return sqrt(st_bvh_nearest(bvh, p, INFINITY, &tri, NULL));
}

/* A full field: exact within three voxels (the band pass), never below the
 * truth beyond (each value is a distance to a real triangle), and above it
 * in under 5% of the voxels by under a quarter voxel (propagation misses
 * the nearest triangle when triangles are much smaller than voxels and
 * near medial surfaces; measured: 2.8% by <= 0.055 voxel on the bunny at
 * 32 cells). */
static void check_full(const st_grid *g, const st_soup *s, const st_bvh *bvh,
                       const char *what)
{
    size_t n = 0, inband_bad = 0, below = 0, off = 0;
    double max_off = 0.0;
    const double band = 3.0 * g->voxel;
    const size_t count = st_grid_count(g);
    #pragma omp parallel for reduction(+ : n, inband_bad, below, off) \
        reduction(max : max_off) schedule(dynamic, 256)
    for (size_t idx = 0; idx < count; idx++) {
        size_t i = idx % g->nx, j = (idx / g->nx) % g->ny, k = idx / (g->nx * g->ny);
        double p[3];
        st_grid_center(g, i, j, k, p);
        double ref = true_dist(s, bvh, p);
        double got = g->data[idx];
        double tol = 1e-6 * fmax(ref, g->voxel);
        n++;
        if (ref < band && fabs(got - ref) > tol)
            inband_bad++;
        if (got < ref - tol)
            below++;
        if (got - ref > tol) {
            off++;
            max_off = fmax(max_off, (got - ref) / g->voxel);
        }
    }
    TAP_CHECK(inband_bad == 0, "%s full field: exact within the band (%zu bad)", what, inband_bad);
    TAP_CHECK(below == 0, "%s full field: never below the true distance (%zu below)", what, below);
    TAP_CHECK(off * 20 < n && max_off < 0.25,
              "%s full field: %zu of %zu voxels above the truth, by at most %.3f voxel",
              what, off, n, max_off);
}

static void test_band_exact_on_random_soup(void)
{
    st_soup *s = random_soup(60);
    st_dist_params p = st_dist_params_default();
    p.cells = 24;
    st_grid *g;
    st_error err;
    TAP_CHECK(st_dist_field(&g, s, &p, NULL, &err) == ST_OK, "random soup field");
    double e;
    size_t bad = check_field(g, s, &e);
    TAP_CHECK(bad == 0, "band field equals brute force within the band (%zu bad, max err %.3g)", bad, e);
    TAP_CHECK(g->kind == ST_GRID_DISTANCE && fabs(g->band - 3 * g->voxel) < 1e-12,
              "kind distance, band 3 voxels");
    st_grid_free(g);

    p.band = INFINITY;
    TAP_CHECK(st_dist_field(&g, s, &p, NULL, &err) == ST_OK, "random soup full field");
    check_full(g, s, NULL, "random soup");
    st_grid_free(g);
    st_soup_free(s);
}

/* One huge triangle crossing the whole grid diagonally: the row intervals
 * must not cut off any band voxel. */
static void test_large_oblique_triangle(void)
{
    const double xyz[] = {0, 0, 0, 1, 0.1, 0.9, 0.2, 1, 0.5, 0.0, 0.0, 1.0};
    const uint32_t tri[] = {0, 1, 2, 0, 2, 3};
    st_soup *s = soup_from(xyz, 4, tri, 2);
    st_dist_params p = st_dist_params_default();
    p.cells = 40;
    p.band = 4.5;
    st_grid *g;
    st_error err;
    TAP_CHECK(st_dist_field(&g, s, &p, NULL, &err) == ST_OK, "large triangle field");
    double e;
    size_t bad = check_field(g, s, &e);
    TAP_CHECK(bad == 0, "large oblique triangles: band exact (%zu bad)", bad);
    st_grid_free(g);
    st_soup_free(s);
}

static void test_layout(void)
{
    const double xyz[] = {0, 0, 0, 4, 0, 0, 0, 2, 1};
    const uint32_t tri[] = {0, 1, 2};
    st_soup *s = soup_from(xyz, 3, tri, 1);
    st_dist_params p = st_dist_params_default();
    p.cells = 8;
    size_t dims[3];
    double origin[3], h;
    st_error err;
    TAP_CHECK(st_dist_layout(s, &p, dims, origin, &h, &err) == ST_OK, "layout ok");
    long pad = st_dist_default_pad(3.0);
    TAP_CHECK(pad == 5, "default pad is band + 2 = 5 (%ld)", pad);
    TAP_NEAR(h, 0.5, 1e-15, "voxel = longest side / cells");
    TAP_CHECK(dims[0] == 8 + 10 && dims[1] == 4 + 10 && dims[2] == 2 + 10,
              "dims = cells per side + 2 pad (%zu %zu %zu)", dims[0], dims[1], dims[2]);
    /* box centered in the grid */
    TAP_NEAR(origin[0] + 0.5 * (double)(dims[0] - 1) * h, 2.0, 1e-12, "centered in x");
    TAP_NEAR(origin[2] + 0.5 * (double)(dims[2] - 1) * h, 0.5, 1e-12, "centered in z");
    /* a flat soup still gets a grid along its flat axis */
    const double flat[] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    st_soup *f = soup_from(flat, 3, tri, 1);
    TAP_CHECK(st_dist_layout(f, &p, dims, origin, &h, &err) == ST_OK && dims[2] == 11,
              "flat soup: 1 + 2 pad voxels across (%zu)", dims[2]);
    /* a soup whose vertices coincide has no extent for -r */
    const double pt[] = {1, 1, 1, 1, 1, 1, 1, 1, 1};
    st_soup *q = soup_from(pt, 3, tri, 1);
    TAP_CHECK(st_dist_layout(q, &p, dims, origin, &h, &err) == ST_EINPUT,
              "a point soup is refused with -r: %s", err.msg);
    p.voxel = 0.1;
    TAP_CHECK(st_dist_layout(q, &p, dims, origin, &h, &err) == ST_OK,
              "a point soup works with a voxel size");
    /* limits */
    p.voxel = 1e-13;
    TAP_CHECK(st_dist_layout(s, &p, dims, origin, &h, &err) == ST_ELIMIT,
              "absurd voxel size refused: %s", err.msg);
    p.voxel = 0;
    p.cells = 8;
    p.max_bytes = 1000;
    st_grid *g;
    TAP_CHECK(st_dist_field(&g, s, &p, NULL, &err) == ST_ELIMIT,
              "grid over max_bytes refused: %s", err.msg);
    p.max_bytes = 0;
    p.band = 2.0;
    TAP_CHECK(st_dist_field(&g, s, &p, NULL, &err) == ST_EINPUT,
              "band below 3 voxels refused: %s", err.msg);
    st_soup_free(s);
    st_soup_free(f);
    st_soup_free(q);
}

static void test_bvh_nearest(void)
{
    st_soup *s = random_soup(300);
    st_bvh *b;
    st_error err;
    TAP_CHECK(st_bvh_build(&b, s, &err) == ST_OK, "bvh build");
    int bad = 0;
    for (int i = 0; i < 300; i++) {
        double p[3] = {urand() * 1.6 - 0.3, urand() * 1.6 - 0.3, urand() * 1.6 - 0.3};
        int64_t tri;
        double d = sqrt(st_bvh_nearest(b, p, INFINITY, &tri, NULL));
        if (fabs(d - brute_dist(s, p)) > 1e-12 || tri < 0)
            bad++;
    }
    TAP_CHECK(bad == 0, "bvh nearest equals brute force (%d bad)", bad);
    double p[3] = {5, 5, 5};
    int64_t tri;
    double d2 = st_bvh_nearest(b, p, 1.0, &tri, NULL);
    TAP_CHECK(tri == -1 && d2 == 1.0, "bvh: nothing within the bound gives -1");
    st_bvh_free(b);
    st_soup_free(s);
}

/* The leaf triangles' box test and st_bvh_within change no answer: over
 * points on, near and off a soup with slivers and degenerate triangles,
 * and bounds from none to everything, st_bvh_nearest gives bit for bit
 * the least st_point_triangle_dist2 of all triangles below the bound (its
 * closest point that triangle's), and st_bvh_within says whether there is
 * one. */
static void test_bvh_nearest_exact(void)
{
    st_soup *s = random_soup(400);
    for (int k = 0; k < 40; k++) {   /* slivers: a long edge, a tiny height */
        double c[3] = {urand(), urand(), urand()}, h = k % 2 ? 1e-7 : 1e-3;
        st_soup_add_vertex(s, c[0], c[1], c[2], NULL);
        st_soup_add_vertex(s, c[0] + 0.3, c[1] + 0.2 * urand(), c[2], NULL);
        st_soup_add_vertex(s, c[0] + 0.15, c[1] + 0.1 * urand(), c[2] + h, NULL);
        uint32_t v = (uint32_t)(s->nverts - 3);
        st_soup_add_triangle(s, v, v + 1, v + 2, NULL);
    }
    st_bvh *b;
    st_error err;
    TAP_CHECK(st_bvh_build(&b, s, &err) == ST_OK, "bvh build (slivers)");
    static const double bounds[] = {INFINITY, 1e-2, 1e-4, 1e-8, 1e-14, 0.0};
    size_t bad = 0, bad_within = 0, found = 0, queries = 0;
    for (int i = 0; i < 3000; i++) {
        double p[3];
        const uint32_t *v = s->tris + 3 * ((size_t)i % s->ntris);
        double r1 = urand(), r2 = urand() * (1.0 - r1), off = i % 3 == 0 ? 0.0 : 1e-3 * urand();
        for (int a = 0; a < 3; a++) {   /* on a triangle, a little off it, or anywhere */
            const double *x = s->xyz + 3 * (size_t)v[0], *y = s->xyz + 3 * (size_t)v[1],
                         *z = s->xyz + 3 * (size_t)v[2];
            p[a] = i % 5 == 4 ? urand() * 1.6 - 0.3
                              : x[a] + r1 * (y[a] - x[a]) + r2 * (z[a] - x[a]) + off;
        }
        for (size_t j = 0; j < sizeof bounds / sizeof *bounds; j++, queries++) {
            double want = bounds[j], wq[3] = {0, 0, 0}, q[3] = {0, 0, 0};
            int64_t wt = -1, tri;
            for (size_t t = 0; t < s->ntris; t++) {
                const uint32_t *u = s->tris + 3 * t;
                double c[3];
                double d2 = st_point_triangle_dist2(p, s->xyz + 3 * (size_t)u[0],
                                                    s->xyz + 3 * (size_t)u[1],
                                                    s->xyz + 3 * (size_t)u[2], c);
                if (d2 < want) {
                    want = d2;
                    wt = (int64_t)t;
                    memcpy(wq, c, sizeof c);
                }
            }
            double got = st_bvh_nearest(b, p, bounds[j], &tri, q);
            if (memcmp(&got, &want, sizeof got) != 0 || (tri < 0) != (wt < 0) ||
                (wt >= 0 && memcmp(q, wq, sizeof q) != 0))
                bad++;
            bad_within += st_bvh_within(b, p, bounds[j]) != (tri >= 0);
            found += tri >= 0;
        }
    }
    TAP_CHECK(bad == 0, "bvh nearest: bit for bit the brute force least distance (%zu of %zu "
              "differ)", bad, queries);
    TAP_CHECK(bad_within == 0 && found > queries / 3 && found < queries,
              "bvh within: whether nearest finds a triangle (%zu of %zu differ; %zu found)",
              bad_within, queries, found);
    st_bvh_free(b);
    st_soup_free(s);
}

/* The nearest walk as it was before its box distances went two lanes at
 * a time and before the leaf triangles' box test: depth first, the nearer
 * child first (the farther pushed first), a node skipped when its box
 * distance is no longer below the best, every leaf triangle measured. The
 * first triangle visited at the least distance wins: the tie rule
 * st_bvh_nearest must keep, bit for bit. */
static double ref_box_dist2(const st_bvh_node *n, const double p[3])
{
    double d2 = 0.0;
    for (int a = 0; a < 3; a++) {
        const double below = n->lo[a] - p[a], above = p[a] - n->hi[a];
        const double d = (below > 0.0 ? below : 0.0) + (above > 0.0 ? above : 0.0);
        d2 += d * d;
    }
    return d2;
}

static double ref_nearest(const st_bvh *b, const double p[3], double max_d2, int64_t *tri,
                          double closest[3])
{
    const st_soup *s = b->soup;
    double best = max_d2, sd2[128];
    uint32_t stack[128];
    int sp = 0;
    *tri = -1;
    if (ref_box_dist2(&b->nodes[0], p) < best) {
        sd2[sp] = ref_box_dist2(&b->nodes[0], p);
        stack[sp++] = 0;
    }
    while (sp > 0) {
        sp--;
        if (sd2[sp] >= best)
            continue;
        const st_bvh_node *n = &b->nodes[stack[sp]];
        for (uint32_t i = 0; i < n->count; i++) {
            uint32_t t = b->order[n->start + i];
            const uint32_t *v = s->tris + 3 * (size_t)t;
            double q[3];
            double d2 = st_point_triangle_dist2(p, s->xyz + 3 * (size_t)v[0],
                                                s->xyz + 3 * (size_t)v[1],
                                                s->xyz + 3 * (size_t)v[2], q);
            if (d2 < best) {
                best = d2;
                *tri = t;
                memcpy(closest, q, sizeof q);
            }
        }
        if (n->count)
            continue;
        uint32_t l = n->start, r = n->start + 1;
        double dl = ref_box_dist2(&b->nodes[l], p), dr = ref_box_dist2(&b->nodes[r], p);
        if (dl > dr) {
            uint32_t t = l;
            l = r;
            r = t;
            double d = dl;
            dl = dr;
            dr = d;
        }
        if (dr < best) {
            sd2[sp] = dr;
            stack[sp++] = r;
        }
        if (dl < best) {
            sd2[sp] = dl;
            stack[sp++] = l;
        }
    }
    return best;
}

/* A G x G grid of squares over the unit square in z = 0.5, two triangles each, every
 * third square (by i + j) three times over: touching and duplicated
 * triangles, for the walks' ties. */
static void add_tied_sheet(st_soup *s, int G)
{
    for (int j = 0; j <= G; j++)
        for (int i = 0; i <= G; i++)
            st_soup_add_vertex(s, i / (double)G, j / (double)G, 0.5, NULL);
    for (int j = 0; j < G; j++)
        for (int i = 0; i < G; i++) {
            uint32_t a = (uint32_t)(j * (G + 1) + i), b = a + 1, c = a + (uint32_t)G + 1,
                     d = c + 1;
            for (int r = 0; r < ((i + j) % 3 == 0 ? 3 : 1); r++) {
                st_soup_add_triangle(s, a, b, d, NULL);
                st_soup_add_triangle(s, a, d, c, NULL);
            }
        }
}

/* Ties and degenerate triangles: a grid of squares, each split in two
 * (shared edges and vertices: points equidistant from several triangles),
 * every third triangle also twice more (exact duplicates), collinear,
 * repeated-vertex and one-point triangles, slivers and random ones.
 * Points on the grid's vertices and edges, just off them, far away (up to
 * 1e6 times the soup's size) and along the axes through vertices (equal
 * box distances of sibling nodes), with bounds from none to nothing:
 * st_bvh_nearest gives the reference walk's distance, triangle and
 * closest point bit for bit, and the distance is the brute force least
 * one, bit for bit. */
static void test_bvh_nearest_ties(void)
{
    st_soup *s = st_soup_new();
    const int G = 24;
    add_tied_sheet(s, G);
    for (int k = 0; k < 60; k++) {
        double c[3] = {urand(), urand(), urand()};
        add_random_triangle(s, c, k % 4 == 0 ? 0.5 : 0.05, k % 3 == 0);
        if (k % 5 == 0) {   /* a repeated vertex, and a point */
            uint32_t v = (uint32_t)(s->nverts - 1);
            st_soup_add_triangle(s, v, v - 1, v - 1, NULL);
            st_soup_add_triangle(s, v, v, v, NULL);
        }
    }
    st_bvh *b;
    st_error err;
    TAP_CHECK(st_bvh_build(&b, s, &err) == ST_OK, "bvh build (ties)");
    static const double bounds[] = {INFINITY, 1e-2, 1e-6, 0.0};
    size_t bad = 0, bad_ref = 0, queries = 0, ties = 0;
    for (int i = 0; i < 2500; i++) {
        double p[3];
        const int kind = i % 5;
        const double gx = (double)(i % (G + 1)) / G, gy = (double)((i / 7) % (G + 1)) / G;
        if (kind == 0) {   /* a grid vertex, at a height */
            p[0] = gx, p[1] = gy, p[2] = 0.5 + (i % 2 ? 0.0 : 0.1 * urand());
        } else if (kind == 1) {   /* a grid edge's midpoint, a little off it */
            p[0] = gx + 0.5 / G, p[1] = gy, p[2] = 0.5 + 1e-9 * (urand() - 0.5);
        } else if (kind == 2) {   /* far away */
            const double far = pow(10.0, 1 + (i % 6));
            p[0] = far * (urand() - 0.5), p[1] = far * (urand() - 0.5), p[2] = far * (urand() - 0.5);
        } else if (kind == 3) {   /* along an axis through a vertex */
            p[0] = gx, p[1] = gy, p[2] = (i % 2 ? -1.0 : 2.0) * urand();
        } else {
            p[0] = urand() * 1.6 - 0.3, p[1] = urand() * 1.6 - 0.3, p[2] = urand() * 1.6 - 0.3;
        }
        for (size_t j = 0; j < sizeof bounds / sizeof *bounds; j++, queries++) {
            double q[3] = {0, 0, 0}, rq[3] = {0, 0, 0}, want = bounds[j];
            int64_t tri, rtri;
            size_t at_min = 0;
            for (size_t t = 0; t < s->ntris; t++) {
                const uint32_t *u = s->tris + 3 * t;
                double d2 = st_point_triangle_dist2(p, s->xyz + 3 * (size_t)u[0],
                                                    s->xyz + 3 * (size_t)u[1],
                                                    s->xyz + 3 * (size_t)u[2], NULL);
                if (d2 < want) {
                    want = d2;
                    at_min = 1;
                } else if (d2 == want)
                    at_min++;
            }
            ties += at_min > 1;
            double got = st_bvh_nearest(b, p, bounds[j], &tri, q);
            double ref = ref_nearest(b, p, bounds[j], &rtri, rq);
            bad += memcmp(&got, &want, sizeof got) != 0;
            bad_ref += memcmp(&got, &ref, sizeof got) != 0 || tri != rtri ||
                       memcmp(q, rq, sizeof q) != 0;
        }
    }
    TAP_CHECK(bad == 0, "bvh nearest with ties: the brute force least distance bit for bit "
              "(%zu of %zu differ)", bad, queries);
    TAP_CHECK(bad_ref == 0 && ties > queries / 10,
              "bvh nearest with ties: the reference walk's triangle and closest point, the "
              "first visited at the least distance (%zu of %zu differ; %zu with ties)",
              bad_ref, queries, ties);
    st_bvh_free(b);
    st_soup_free(s);
}

/* st_bvh_within_hint answers as st_bvh_within, bit for bit, whatever the
 * hints: on a grid of squares in the plane z = 0.5 (shared edges and
 * vertices: triangles that touch; every third square twice more, exact
 * duplicates), with slivers, collinear and one-point triangles, at
 * points exactly a bound above the plane (the distance, and the box
 * distance, equal to the bound: not within), on it, a little off it and
 * anywhere, with each point's hints from the query before (a run at
 * nearby points, as the fill passes them), from every slot in turn, and
 * none or out of range. A 1 names a slot whose triangle is within; a 0
 * names none. */
static void test_bvh_within_hint(void)
{
    st_soup *s = st_soup_new();
    const int G = 16;
    add_tied_sheet(s, G);
    for (int k = 0; k < 40; k++) {
        double c[3] = {urand(), urand(), urand()};
        add_random_triangle(s, c, k % 4 == 0 ? 0.3 : 0.03, k % 3 == 0);
        if (k % 5 == 0) {
            uint32_t v = (uint32_t)(s->nverts - 1);
            st_soup_add_triangle(s, v, v, v, NULL);
        }
    }
    st_bvh *b;
    st_error err;
    TAP_CHECK(st_bvh_build(&b, s, &err) == ST_OK, "bvh build (hints)");
    /* bounds exactly representable squares: a point that high above the
     * plane is at exactly the bound */
    static const double h[] = {0.25, 0.0625, 1.0 / 64, 1.0 / 1024, 0.0};
    const uint32_t nt = (uint32_t)s->ntris;
    uint32_t run = ST_BVH_NO_HINT;
    size_t bad = 0, bad_found = 0, queries = 0, at_bound = 0, hit = 0, yes = 0;
    for (int i = 0; i < 4000; i++) {
        double p[3];
        const int kind = i % 4;
        const double x = (double)(i % (2 * G + 1)) / (2 * G), y = (double)((i / 5) % (G + 1)) / G;
        const double hh = h[(i / 4) % 5];
        p[0] = x, p[1] = y;
        p[2] = kind == 0 ? 0.5 + hh : kind == 1 ? 0.5 - hh
             : kind == 2 ? 0.5 + hh * (1.0 + 1e-12 * (urand() - 0.5)) : urand() * 1.4 - 0.2;
        if (kind == 3)
            p[0] = urand() * 1.4 - 0.2, p[1] = urand() * 1.4 - 0.2;
        for (size_t j = 0; j < sizeof h / sizeof *h; j++) {
            const double bound = h[j] * h[j];
            const int want = st_bvh_within(b, p, bound);
            at_bound += kind < 2 && h[j] == hh && !want;
            /* the run's hint, one slot after another, none, out of range */
            const uint32_t tries[4] = {run, (uint32_t)(i * 7 + (int)j) % nt, ST_BVH_NO_HINT,
                                       nt + (uint32_t)j};
            for (int t = 0; t < 4; t++, queries++) {
                uint32_t found = 12345;
                const int got = st_bvh_within_hint(b, p, bound, tries + t, t == 3 ? 1 : 2,
                                                   &found);
                bad += got != want;
                if (got) {
                    const uint32_t *v = found < nt ? s->tris + 3 * (size_t)b->order[found] : NULL;
                    bad_found += !v || !(st_point_triangle_dist2(p, s->xyz + 3 * (size_t)v[0],
                                                                 s->xyz + 3 * (size_t)v[1],
                                                                 s->xyz + 3 * (size_t)v[2],
                                                                 NULL) < bound);
                    hit += found == tries[0] || (t != 3 && found == tries[1]);
                } else
                    bad_found += found != ST_BVH_NO_HINT;
                if (t == 0 && found != ST_BVH_NO_HINT)
                    run = found;
                yes += got;
            }
        }
    }
    TAP_CHECK(bad == 0 && queries > 0, "bvh within hint: st_bvh_within's answer whatever the hints "
              "(%zu of %zu differ)", bad, queries);
    TAP_CHECK(bad_found == 0, "bvh within hint: the slot found is within, none when 0 (%zu bad)",
              bad_found);
    TAP_CHECK(at_bound > 100 && hit > queries / 16 && yes > queries / 4 && yes < queries,
              "bvh within hint: points at exactly the bound (%zu), hints taken (%zu), found %zu of "
              "%zu", at_bound, hit, yes, queries);
    st_bvh_free(b);
    st_soup_free(s);
}

/* A BVH over enough triangles to be built by parallel tasks has the
 * serial build's layout: inner nodes numbered depth first, the right
 * child's subtree before the left's, leaves of at most ST_BVH_LEAF slots
 * covering order[] once, boxes holding their triangles; the same nodes
 * with 1 and 3 threads; nearest answers equal to brute force. */
static void test_bvh_parallel_layout(void)
{
    st_soup *s = random_soup(70001);
    st_error err;
    st_bvh *b1 = NULL, *b3 = NULL;
#ifdef _OPENMP
    omp_set_num_threads(1);
#endif
    TAP_CHECK(st_bvh_build(&b1, s, &err) == ST_OK, "bvh over 70001 triangles, 1 thread");
#ifdef _OPENMP
    omp_set_num_threads(3);
#endif
    TAP_CHECK(st_bvh_build(&b3, s, &err) == ST_OK, "bvh over 70001 triangles, 3 threads");
    TAP_CHECK(b1->nnodes == b3->nnodes &&
                  memcmp(b1->nodes, b3->nodes, b1->nnodes * sizeof *b1->nodes) == 0 &&
                  memcmp(b1->order, b3->order, s->ntris * sizeof *b1->order) == 0,
              "bvh: 1 and 3 threads build the same nodes and order");
    size_t *stack = malloc(b3->nnodes * sizeof *stack);
    unsigned char *seen = calloc(s->ntris, 1);
    size_t sp = 0, next = 1, bad_number = 0, bad_leaf = 0, bad_box = 0, slots = 0;
    stack[sp++] = 0;
    while (sp > 0) {
        const st_bvh_node *n = &b3->nodes[stack[--sp]];
        if (n->count == 0) {
            if (n->start != next || n->start + 1 >= b3->nnodes) {
                bad_number++;
                break;
            }
            next += 2;
            stack[sp++] = n->start;
            stack[sp++] = n->start + 1;
            continue;
        }
        if (n->count > ST_BVH_LEAF)
            bad_leaf++;
        for (uint32_t i = n->start; i < n->start + n->count; i++) {
            uint32_t t = b3->order[i];
            if (seen[t]++)
                bad_leaf++;
            slots++;
            for (int k = 0; k < 3; k++) {
                const double *v = s->xyz + 3 * (size_t)s->tris[3 * (size_t)t + (size_t)k];
                for (int a = 0; a < 3; a++)
                    if (v[a] < n->lo[a] || v[a] > n->hi[a])
                        bad_box++;
            }
        }
    }
    TAP_CHECK(bad_number == 0 && next == b3->nnodes,
              "bvh: nodes numbered as the serial walk numbers them (%zu of %zu)", next,
              b3->nnodes);
    TAP_CHECK(bad_leaf == 0 && slots == s->ntris && bad_box == 0,
              "bvh: leaves hold every triangle once, in their boxes");
    int bad = 0;
    for (int i = 0; i < 20; i++) {
        double p[3] = {urand() * 1.6 - 0.3, urand() * 1.6 - 0.3, urand() * 1.6 - 0.3};
        int64_t tri;
        double d = sqrt(st_bvh_nearest(b3, p, INFINITY, &tri, NULL));
        if (fabs(d - brute_dist(s, p)) > 1e-12 || tri < 0)
            bad++;
    }
    TAP_CHECK(bad == 0, "bvh over 70001 triangles: nearest equals brute force (%d bad)", bad);
    free(stack);
    free(seen);
    st_bvh_free(b1);
    st_bvh_free(b3);
    st_soup_free(s);
}

static void test_threads_identical(void)
{
#ifdef _OPENMP
    st_soup *s = random_soup(400);
    st_dist_params p = st_dist_params_default();
    p.cells = 48;
    p.band = INFINITY;
    st_grid *g1, *g2;
    st_error err;
    omp_set_num_threads(1);
    st_dist_field(&g1, s, &p, NULL, &err);
    omp_set_num_threads(3);
    st_dist_field(&g2, s, &p, NULL, &err);
    TAP_CHECK(memcmp(g1->data, g2->data, st_grid_count(g1) * sizeof(float)) == 0,
              "1 and 3 threads give identical fields");
    st_grid_free(g1);
    st_grid_free(g2);
    st_soup_free(s);
#else
    TAP_CHECK(1, "# SKIP no OpenMP");
#endif
}

/* How the blocks of b differ from the dense field g of the same soup:
 * voxels with another value (bitwise), stored blocks of the band alone,
 * voxels of a stored block beyond the grid not holding the band, a wrong
 * count of stored blocks. */
static size_t blocks_differ(const st_grid_blocks *b, const st_grid *g)
{
    const st_grid *h = &b->head;
    size_t bad = 0;
    if (h->data || h->nx != g->nx || h->ny != g->ny || h->nz != g->nz ||
        h->voxel != g->voxel || h->band != g->band || h->kind != g->kind ||
        memcmp(h->origin, g->origin, sizeof g->origin) != 0)
        return 1;
    for (size_t k = 0; k < g->nz; k++)
        for (size_t j = 0; j < g->ny; j++)
            for (size_t i = 0; i < g->nx; i++) {
                const float v = st_grid_blocks_value(b, i, j, k);
                bad += memcmp(&v, &g->data[st_grid_index(g, i, j, k)], sizeof v) != 0;
            }
    const float bf = (float)h->band;
    size_t stored = 0;
    for (size_t bk = 0; bk < b->nb[2]; bk++)
        for (size_t bj = 0; bj < b->nb[1]; bj++)
            for (size_t bi = 0; bi < b->nb[0]; bi++) {
                const size_t at = b->at[bi + b->nb[0] * (bj + b->nb[1] * bk)];
                if (at == ST_GRID_NO_BLOCK)
                    continue;
                stored++;
                size_t below = 0;
                for (size_t q = 0; q < 512; q++) {
                    const size_t i = bi * 8 + q / 64, j = bj * 8 + q / 8 % 8,
                                 k = bk * 8 + q % 8;
                    below += b->values[at + q] != bf;
                    bad += (i >= g->nx || j >= g->ny || k >= g->nz) &&
                           b->values[at + q] != bf;
                }
                bad += below == 0;
            }
    return bad + (stored != b->nstored);
}

/* The field stored by blocks is the dense one, voxel for voxel, on 1 and
 * 3 threads: a random soup (some triangles large, some degenerate) on
 * grids whose sides are not multiples of a block, two bands. */
static void test_blocks_equal_dense(void)
{
    st_soup *s = random_soup(300);
    const size_t cells[] = {21, 37};
    const double bands[] = {3.0, 4.5};
    for (int c = 0; c < 2; c++) {
        st_dist_params p = st_dist_params_default();
        p.cells = cells[c];
        p.band = bands[c];
        st_grid *g = NULL;
        st_error err;
        TAP_CHECK(st_dist_field(&g, s, &p, NULL, &err) == ST_OK, "dense field at %zu cells",
                  cells[c]);
        for (int threads = 1; threads <= 3; threads += 2) {
#ifdef _OPENMP
            omp_set_num_threads(threads);
#endif
            st_grid_blocks *b = NULL;
            TAP_CHECK(st_dist_field_blocks(&b, s, &p, NULL, &err) == ST_OK,
                      "blocks at %zu cells, %d threads", cells[c], threads);
            size_t bad = b && g ? blocks_differ(b, g) : 1;
            const size_t nb = b ? b->nb[0] * b->nb[1] * b->nb[2] : 0;
            TAP_CHECK(bad == 0 && b->nstored > 0 && b->nstored < nb,
                      "%zu cells, band %g, %d threads: blocks equal the dense field "
                      "(%zu of %zu blocks stored, %zu differences)", cells[c], bands[c],
                      threads, b ? b->nstored : 0, nb, bad);
            st_grid *d = NULL;
            TAP_CHECK(b && st_grid_blocks_dense(&d, b, 0, &err) == ST_OK &&
                          memcmp(d->data, g->data, st_grid_count(g) * sizeof(float)) == 0 &&
                          d->meta.count == g->meta.count && d->meta.count == 3 &&
                          strcmp(d->meta.entries[2].value, g->meta.entries[2].value) == 0,
                      "st_grid_blocks_dense gives the dense field and its meta");
            st_grid_free(d);
            st_grid_blocks_free(b);
        }
        st_grid_free(g);
    }
#ifdef _OPENMP
    omp_set_num_threads(2);
#endif
    st_dist_params p = st_dist_params_default();
    p.band = INFINITY;
    st_grid_blocks *b = NULL;
    st_error err;
    TAP_CHECK(st_dist_field_blocks(&b, s, &p, NULL, &err) == ST_EINPUT && !b,
              "blocks refuse a full field: %s", err.msg);
    p = st_dist_params_default();
    p.cells = 2000;
    p.max_bytes = 1 << 20;
    TAP_CHECK(st_dist_field_blocks(&b, s, &p, NULL, &err) == ST_ELIMIT && !b,
              "blocks keep the dense size limit: %s", err.msg);
    st_soup_free(s);
}

/* A fine soup: many triangles per voxel near a sphere, a few large and
 * degenerate ones among them. */
static st_soup *fine_soup(size_t n)
{
    st_soup *s = st_soup_new();
    for (size_t t = 0; t < n; t++) {
        double c[3], r2 = 0.0;
        for (int a = 0; a < 3; a++) {
            c[a] = urand() - 0.5;
            r2 += c[a] * c[a];
        }
        const double f = 0.4 / sqrt(r2 > 1e-12 ? r2 : 1e-12);
        const double size = t % 97 == 0 ? 0.3 : 0.004 + 0.01 * urand();
        const double on[3] = {c[0] * f, c[1] * f, c[2] * f};
        add_random_triangle(s, on, size, t % 13 == 0);
    }
    return s;
}

/* The band pass on a fine soup (many candidates per brick, large
 * collinear triangles whose normal is rounding noise): every voxel is the
 * true distance, with the default padding and with none (bricks, and the
 * 2x2x2 groups a brick is walked in, cut by the grid's sides to 1, 2 or 3
 * voxels), for bands of 3 to 7.5 voxels. */
static void test_fine_soup_exact(void)
{
    st_soup *s = fine_soup(20000);
    st_error err;
    st_bvh *bvh = NULL;
    if (st_bvh_build(&bvh, s, &err) != ST_OK) {
        TAP_CHECK(0, "bvh of the fine soup: %s", err.msg);
        st_soup_free(s);
        return;
    }
    static const struct { long pad; size_t cells; double band; } run[] = {
        {-1, 41, 3.0}, {0, 41, 4.5}, {0, 42, 3.0}, {0, 43, 7.5}};
    for (size_t r = 0; r < sizeof run / sizeof run[0]; r++) {
        st_dist_params p = st_dist_params_default();
        p.cells = run[r].cells;
        p.pad = run[r].pad;
        p.band = run[r].band;
        const long pad = p.pad;
        st_grid *g = NULL;
        if (st_dist_field(&g, s, &p, NULL, &err) != ST_OK) {
            TAP_CHECK(0, "fine soup field: %s", err.msg);
            continue;
        }
        const size_t n = st_grid_count(g);
        size_t bad = 0, inband = 0;
        #pragma omp parallel for reduction(+ : bad, inband) schedule(dynamic, 256)
        for (size_t idx = 0; idx < n; idx++) {
            size_t i = idx % g->nx, j = (idx / g->nx) % g->ny, k = idx / (g->nx * g->ny);
            double q[3];
            st_grid_center(g, i, j, k, q);
            double ref = true_dist(s, bvh, q);
            double want = ref < g->band ? ref : g->band;
            inband += ref < g->band;
            if (fabs(g->data[idx] - want) > 1e-6 * fmax(want, g->voxel))
                bad++;
        }
        TAP_CHECK(bad == 0 && inband > 1000, "fine soup, %zu cells, pad %ld, band %g: every "
                  "voxel is the true distance (%zu bad, %zu in band, grid %zux%zux%zu)",
                  p.cells, pad, p.band, bad, inband, g->nx, g->ny, g->nz);
        st_grid_free(g);
    }
    st_bvh_free(bvh);
    st_soup_free(s);
}

/* A real model: sampled voxels against brute force. */
static void test_real_model(void)
{
    st_soup *s;
    st_error err;
    if (st_soup_read(&s, tap_path("corpus/bunny.obj"), &err) != ST_OK) {
        TAP_CHECK(0, "read corpus/bunny.obj: %s", err.msg);
        return;
    }
    st_dist_params p = st_dist_params_default();
    p.cells = 64;
    st_grid *g;
    TAP_CHECK(st_dist_field(&g, s, &p, NULL, &err) == ST_OK, "bunny field at 64 cells");
    size_t n = st_grid_count(g), bad = 0, inband = 0, checked = 0;
    #pragma omp parallel for reduction(+ : bad, inband, checked) schedule(dynamic, 64)
    for (size_t idx = 0; idx < n; idx += 37) {   /* every 37th voxel */
        size_t i = idx % g->nx, j = (idx / g->nx) % g->ny, k = idx / (g->nx * g->ny);
        double q[3];
        st_grid_center(g, i, j, k, q);
        double ref = brute_dist(s, q);
        double want = ref < g->band ? ref : g->band;
        if (ref < g->band)
            inband++;
        if (fabs(g->data[idx] - want) > 1e-6 * fmax(want, g->voxel))
            bad++;
        checked++;
    }
    TAP_CHECK(bad == 0 && inband > 100,
              "bunny: %zu sampled voxels (%zu in band) equal brute force (%zu bad)",
              checked, inband, bad);
    st_grid_free(g);
    p.band = INFINITY;
    p.cells = 32;
    TAP_CHECK(st_dist_field(&g, s, &p, NULL, &err) == ST_OK, "bunny full field at 32 cells");
    st_bvh *bvh = NULL;
    if (st_bvh_build(&bvh, s, &err) != ST_OK)
        TAP_CHECK(0, "bvh of the bunny: %s", err.msg);
    else
        check_full(g, s, bvh, "bunny");
    st_bvh_free(bvh);
    st_grid_free(g);
    st_soup_free(s);
}

/* st_dist_field_far: st_dist_field's layout, band and metadata, every
 * voxel at the value st_dist_field gives a voxel beyond the band (the
 * field's largest); a full band is refused. */
static void test_far_field(void)
{
    st_soup *s = random_soup(60);
    st_dist_params p = st_dist_params_default();
    p.cells = 24;
    st_grid *d = NULL, *f = NULL;
    st_error err;
    const int ok = !st_dist_field(&d, s, &p, NULL, &err) && !st_dist_field_far(&f, s, &p, &err);
    int same = ok && f->nx == d->nx && f->ny == d->ny && f->nz == d->nz &&
               f->voxel == d->voxel && f->band == d->band && f->kind == d->kind &&
               !memcmp(f->origin, d->origin, sizeof f->origin);
    const char *keys[] = {"triangles", "vertices", "band_voxels"};
    for (int k = 0; same && k < 3; k++)
        same = st_meta_get(&f->meta, keys[k]) && st_meta_get(&d->meta, keys[k]) &&
               !strcmp(st_meta_get(&f->meta, keys[k]), st_meta_get(&d->meta, keys[k]));
    TAP_CHECK(same, "the far field has the distance field's layout, band and metadata");
    float dmax = 0.0f;
    size_t far = 0, n = ok ? st_grid_count(d) : 0, at_far = 0;
    for (size_t i = 0; i < n; i++) {
        dmax = d->data[i] > dmax ? d->data[i] : dmax;
        far += f->data[i] == (float)f->band;
    }
    for (size_t i = 0; i < n; i++)
        at_far += d->data[i] == dmax;
    TAP_CHECK(ok && n > 0 && far == n && dmax == (float)f->band && at_far > 0 && at_far < n,
              "every voxel holds the band's far value %g, the distance field's largest "
              "(%zu of %zu voxels there)", ok ? f->band : 0.0, at_far, n);
    st_grid_free(f);
    f = NULL;
    p.band = INFINITY;
    TAP_CHECK(st_dist_field_far(&f, s, &p, &err) == ST_EINPUT && !f,
              "a full band is refused: %s", err.msg);
    st_grid_free(d);
    st_soup_free(s);
}

int main(int argc, char **argv)
{
    static const tap_test tests[] = {TAP_TEST(layout), TAP_TEST(band_exact_on_random_soup),
                                     TAP_TEST(large_oblique_triangle), TAP_TEST(bvh_nearest),
                                     TAP_TEST(bvh_nearest_exact), TAP_TEST(bvh_nearest_ties),
                                     TAP_TEST(bvh_within_hint),
                                     TAP_TEST(bvh_parallel_layout),
                                     TAP_TEST(threads_identical), TAP_TEST(fine_soup_exact),
                                     TAP_TEST(real_model), TAP_TEST(blocks_equal_dense),
                                     TAP_TEST(far_field), {0}};
    return tap_main(argc, argv, tests);
}
