/* test_dist_bvh.c - the band by a BVH's walks (st_dist_field_bvh) against
 * the bricks' band (st_dist_field), bit for bit; when a soup is dense
 * enough for it (st_dist_wants_bvh); the pseudo volume that takes that way
 * (the signs' first steps, then the BVH, then the band) against the one
 * that does not. */
#include "souptet/bvh.h"
#include "souptet/dist.h"
#include "souptet/pseudo.h"
#include "souptet/soup.h"
#include "tap.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#ifdef _OPENMP
#include <omp.h>
#endif

static unsigned rng = 4242;
static double urand(void)
{
    rng = rng * 1103515245u + 12345u;
    return (double)((rng >> 8) & 0xffffff) / 16777216.0;
}

/* A closed UV sphere of radius r around c: rings x segments quads and two
 * pole fans, outward, vertices shared (one closed shell). */
static st_soup *uv_sphere(const double c[3], double r, unsigned rings, unsigned segs)
{
    st_soup *s = st_soup_new();
    const double pi = 3.14159265358979323846;
    st_soup_add_vertex(s, c[0], c[1], c[2] + r, NULL);
    for (unsigned i = 1; i < rings; i++) {
        const double th = pi * (double)i / (double)rings;
        for (unsigned j = 0; j < segs; j++) {
            const double ph = 2.0 * pi * (double)j / (double)segs;
            st_soup_add_vertex(s, c[0] + r * sin(th) * cos(ph), c[1] + r * sin(th) * sin(ph),
                               c[2] + r * cos(th), NULL);
        }
    }
    const uint32_t south = (uint32_t)s->nverts;
    st_soup_add_vertex(s, c[0], c[1], c[2] - r, NULL);
#define RING(i, j) (1u + ((i) - 1u) * segs + ((j) % segs))
    for (unsigned j = 0; j < segs; j++)
        st_soup_add_triangle(s, 0, RING(1u, j), RING(1u, j + 1), NULL);
    for (unsigned i = 1; i + 1 < rings; i++)
        for (unsigned j = 0; j < segs; j++) {
            st_soup_add_triangle(s, RING(i, j), RING(i + 1, j), RING(i + 1, j + 1), NULL);
            st_soup_add_triangle(s, RING(i, j), RING(i + 1, j + 1), RING(i, j + 1), NULL);
        }
    for (unsigned j = 0; j < segs; j++)
        st_soup_add_triangle(s, south, RING(rings - 1u, j + 1), RING(rings - 1u, j), NULL);
#undef RING
    return s;
}

/* Triangles of every kind in the unit box: tiny ones (many to a voxel),
 * middling, large oblique ones, collinear slivers and points. */
static st_soup *mixed_soup(size_t n)
{
    st_soup *s = st_soup_new();
    for (size_t t = 0; t < n; t++) {
        const double c[3] = {urand(), urand(), urand()};
        const double size = t % 97 == 0 ? 0.9 : t % 5 == 0 ? 0.1 * urand() : 0.004 * urand();
        for (int k = 0; k < 3; k++) {
            double v[3];
            for (int a = 0; a < 3; a++)
                v[a] = c[a] + size * (urand() - 0.5);
            if (t % 13 == 0 && k == 2) {      /* collinear */
                const double *p0 = s->xyz + 3 * (s->nverts - 2), *p1 = s->xyz + 3 * (s->nverts - 1);
                for (int a = 0; a < 3; a++)
                    v[a] = 2.0 * p1[a] - p0[a];
            }
            if (t % 29 == 0 && k > 0)         /* all three at one point */
                memcpy(v, s->xyz + 3 * (s->nverts - 1), sizeof v);
            st_soup_add_vertex(s, v[0], v[1], v[2], NULL);
        }
        const uint32_t v = (uint32_t)(s->nverts - 3);
        st_soup_add_triangle(s, v, v + 1, v + 2, NULL);
    }
    return s;
}

/* Voxels whose values differ bit for bit between the two fields (or
 * SIZE_MAX when their grids differ). */
static size_t fields_differ(const st_grid *a, const st_grid *b)
{
    if (a->nx != b->nx || a->ny != b->ny || a->nz != b->nz || a->voxel != b->voxel ||
        a->band != b->band || a->kind != b->kind)
        return SIZE_MAX;
    size_t bad = 0;
    for (size_t i = 0; i < st_grid_count(a); i++)
        bad += memcmp(&a->data[i], &b->data[i], sizeof(float)) != 0;
    return bad;
}

/* The band of s at `cells` both ways: how many voxels differ, and how
 * many hold less than the band (the walks had work to do). */
static size_t compare_ways(const st_soup *s, size_t cells, double band, size_t *in_band)
{
    st_dist_params p = st_dist_params_default();
    p.cells = cells;
    p.band = band;
    st_error err;
    st_bvh *bvh = NULL;
    st_grid *g0 = NULL, *g1 = NULL;
    size_t bad = SIZE_MAX;
    *in_band = 0;
    if (st_bvh_build(&bvh, s, &err) == ST_OK && st_dist_field(&g0, s, &p, NULL, &err) == ST_OK &&
        st_dist_field_bvh(&g1, s, &p, bvh, NULL, &err) == ST_OK) {
        bad = fields_differ(g0, g1);
        for (size_t i = 0; i < st_grid_count(g0); i++)
            *in_band += g0->data[i] < (float)g0->band;
    }
    st_grid_free(g0);
    st_grid_free(g1);
    st_bvh_free(bvh);
    return bad;
}

static void test_same_field_sphere(void)
{
    const double c[3] = {0.1, -0.2, 0.3};
    st_soup *s = uv_sphere(c, 1.0, 110, 220);
    const size_t cells[] = {4, 12, 30};
    for (size_t k = 0; k < sizeof cells / sizeof cells[0]; k++) {
        size_t in_band;
        const size_t bad = compare_ways(s, cells[k], ST_DIST_DEFAULT_BAND, &in_band);
        TAP_CHECK(bad == 0 && in_band > 0,
                  "fine sphere (%zu triangles) at %zu cells: the BVH's band is the bricks' "
                  "bit for bit (%zu voxels differ, %zu in the band)", s->ntris, cells[k], bad,
                  in_band);
    }
    st_soup_free(s);
}

static void test_same_field_mixed(void)
{
    st_soup *s = mixed_soup(30000);
    const size_t cells[] = {4, 16, 40};
    const double bands[] = {ST_DIST_DEFAULT_BAND, 4.5, 6.0};
    for (size_t k = 0; k < sizeof cells / sizeof cells[0]; k++) {
        size_t in_band;
        const size_t bad = compare_ways(s, cells[k], bands[k], &in_band);
        TAP_CHECK(bad == 0 && in_band > 0,
                  "mixed soup (tiny, large, collinear, point triangles) at %zu cells, band %g: "
                  "the BVH's band is the bricks' bit for bit (%zu voxels differ, %zu in the band)",
                  cells[k], bands[k], bad, in_band);
    }
    size_t in_band;
    TAP_CHECK(compare_ways(s, 16, INFINITY, &in_band) == 0,
              "a full field takes the bricks' way with a BVH too: the same field");
    st_soup_free(s);
}

static void test_threads(void)
{
#ifdef _OPENMP
    st_soup *s = mixed_soup(20000);
    st_dist_params p = st_dist_params_default();
    p.cells = 24;
    st_error err;
    st_bvh *bvh = NULL;
    st_grid *g1 = NULL, *g3 = NULL;
    const int was = omp_get_max_threads();
    int ok = st_bvh_build(&bvh, s, &err) == ST_OK;
    omp_set_num_threads(1);
    ok = ok && st_dist_field_bvh(&g1, s, &p, bvh, NULL, &err) == ST_OK;
    omp_set_num_threads(3);
    ok = ok && st_dist_field_bvh(&g3, s, &p, bvh, NULL, &err) == ST_OK;
    omp_set_num_threads(was);
    TAP_CHECK(ok && fields_differ(g1, g3) == 0, "the BVH's band: 1 and 3 threads identical");
    st_grid_free(g1);
    st_grid_free(g3);
    st_bvh_free(bvh);
    st_soup_free(s);
#else
    TAP_CHECK(1, "# SKIP no OpenMP");
#endif
}

static void test_wants_bvh(void)
{
    const double c[3] = {0.0, 0.0, 0.0};
    st_soup *fine = uv_sphere(c, 1.0, 110, 220);   /* 48 180 triangles */
    st_soup *coarse = uv_sphere(c, 1.0, 8, 16);
    st_dist_params p = st_dist_params_default();
    p.cells = 4;                                    /* 14^3 voxels with the padding */
    TAP_CHECK(st_dist_wants_bvh(fine, &p), "48 K triangles on 14^3 voxels: dense, the BVH's way");
    TAP_CHECK(!st_dist_wants_bvh(coarse, &p), "240 triangles on 14^3 voxels: the bricks' way");
    p.cells = 5;
    TAP_CHECK(st_dist_wants_bvh(fine, &p), "48 K triangles on 15^3 voxels: 14.3 a voxel, the BVH's way");
    /* The threshold, one triangle a voxel (dist.h: measured) */
    p.cells = 26;
    TAP_CHECK(st_dist_wants_bvh(fine, &p), "48 K triangles on 36^3 voxels: 1.03 a voxel, the BVH's way");
    p.cells = 27;
    TAP_CHECK(!st_dist_wants_bvh(fine, &p), "48 K triangles on 37^3 voxels: 0.95 a voxel, the bricks' way");
    p.cells = 128;
    TAP_CHECK(!st_dist_wants_bvh(fine, &p), "48 K triangles on 138^3 voxels: the bricks' way");
    p.cells = 4;
    p.band = INFINITY;
    TAP_CHECK(!st_dist_wants_bvh(fine, &p), "a full field: the bricks' way");
    p.band = 0.1;
    TAP_CHECK(!st_dist_wants_bvh(fine, &p), "a band below the minimum: no (st_dist_field says why)");
    st_soup_free(fine);
    st_soup_free(coarse);
}

/* st_pseudo_volume_bvh on a dense closed soup takes the BVH's way (the
 * shells first, then the BVH, then its band) and must give the grid
 * st_pseudo_volume gives (the bricks, the shells after), the same stats,
 * and a BVH over the soup. A dense soup with an open hole too (the caps
 * use the BVH built before the band). */
static void check_pseudo_same(st_soup *s, const char *what, int closed)
{
    st_dist_params dp = st_dist_params_default();
    dp.cells = 4;
    const st_pseudo_params pp = st_pseudo_params_default();
    st_pseudo_stats s0, s1;
    st_error err;
    st_grid *g0 = NULL, *g1 = NULL;
    st_bvh *bvh = NULL;
    const int ok0 = st_pseudo_volume(&g0, s, &dp, &pp, &s0, NULL, &err) == ST_OK;
    const int ok1 = st_pseudo_volume_bvh(&g1, s, &dp, &pp, &s1, NULL, &bvh, &err) == ST_OK;
    TAP_CHECK(ok0 && ok1 && st_dist_wants_bvh(s, &dp), "%s: both pseudo volumes (%s)", what,
              ok1 ? "ok" : err.msg);
    if (!(ok0 && ok1)) {
        st_grid_free(g0);
        st_grid_free(g1);
        st_bvh_free(bvh);
        return;
    }
    size_t inside = 0;
    for (size_t i = 0; i < st_grid_count(g0); i++)
        inside += g0->data[i] < 0.0f;
    TAP_CHECK(fields_differ(g0, g1) == 0 && inside > 0,
              "%s: the signed field is the same bit for bit (%zu voxels inside)", what, inside);
    TAP_CHECK(s0.shells == s1.shells && s0.shells_only == s1.shells_only &&
              s0.shells_only == closed && s0.shell_open_triangles == s1.shell_open_triangles &&
              s0.inside == s1.inside,
              "%s: the same shells (%zu), shortcut (%d), inside (%zu)", what, s1.shells,
              s1.shells_only, s1.inside);
    const double p[3] = {0.0, 0.0, -2.0};
    int64_t tri = -1;
    TAP_CHECK(bvh && bvh->soup == s && st_bvh_nearest(bvh, p, INFINITY, &tri, NULL) < 1.0001 &&
              tri >= 0, "%s: the BVH handed out is s's", what);
    st_grid_free(g0);
    st_grid_free(g1);
    st_bvh_free(bvh);
}

static void test_pseudo_same(void)
{
    const double c[3] = {0.0, 0.0, 0.0};
    st_soup *s = uv_sphere(c, 1.0, 110, 220);
    check_pseudo_same(s, "closed fine sphere", 1);
    /* drop the north pole's fan: a hole, so no shortcut */
    st_soup *open = st_soup_new();
    for (size_t v = 0; v < s->nverts; v++)
        st_soup_add_vertex(open, s->xyz[3 * v], s->xyz[3 * v + 1], s->xyz[3 * v + 2], NULL);
    for (size_t t = 220; t < s->ntris; t++)
        st_soup_add_triangle(open, s->tris[3 * t], s->tris[3 * t + 1], s->tris[3 * t + 2], NULL);
    check_pseudo_same(open, "fine sphere with a hole", 0);
    st_soup_free(open);
    st_soup_free(s);
}

int main(int argc, char **argv)
{
    static const tap_test tests[] = {TAP_TEST(same_field_sphere), TAP_TEST(same_field_mixed),
                                     TAP_TEST(threads), TAP_TEST(wants_bvh),
                                     TAP_TEST(pseudo_same), {0}};
    return tap_main(argc, argv, tests);
}
