/*
 * test_soupinfo.c - the damage report (soupinfo.h) on tiny inline shapes
 * with known answers: a unit cube indexed and as an exact soup, with a face
 * removed, a flipped triangle, duplicated faces, a fin, degenerate
 * triangles, two cubes apart and touching, a torus, a Moebius band; and
 * that the report does not depend on the order of the triangles.
 */
#include "souptet/soupinfo.h"
#include "tap.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---- shapes ---------------------------------------------------------------- */

static const double cube_v[8][3] = {
    {0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0},
    {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
/* Outward, counter-clockwise seen from outside. */
static const uint32_t cube_t[12][3] = {
    {0, 2, 1}, {0, 3, 2},   /* bottom z = 0 */
    {4, 5, 6}, {4, 6, 7},   /* top z = 1 */
    {0, 1, 5}, {0, 5, 4},   /* front y = 0 */
    {2, 3, 7}, {2, 7, 6},   /* back y = 1 */
    {0, 4, 7}, {0, 7, 3},   /* left x = 0 */
    {1, 2, 6}, {1, 6, 5}};  /* right x = 1 */

static st_soup *soup_or_die(void)
{
    st_soup *s = st_soup_new();
    if (!s)
        abort();
    return s;
}

static uint32_t vert(st_soup *s, double x, double y, double z)
{
    if (st_soup_add_vertex(s, x, y, z, NULL))
        abort();
    return (uint32_t)(s->nverts - 1);
}

static void tri(st_soup *s, uint32_t a, uint32_t b, uint32_t c)
{
    if (st_soup_add_triangle(s, a, b, c, NULL))
        abort();
}

/* Append the cube shifted by (dx, dy, dz), skipping the triangles whose
 * bit is set in skip; flip reverses the triangles whose bit is set. */
static void add_cube(st_soup *s, double dx, double dy, double dz,
                     unsigned skip, unsigned flip)
{
    uint32_t base = (uint32_t)s->nverts;
    for (int i = 0; i < 8; i++)
        vert(s, cube_v[i][0] + dx, cube_v[i][1] + dy, cube_v[i][2] + dz);
    for (int t = 0; t < 12; t++) {
        if (skip >> t & 1u)
            continue;
        const uint32_t *c = cube_t[t];
        if (flip >> t & 1u)
            tri(s, base + c[0], base + c[2], base + c[1]);
        else
            tri(s, base + c[0], base + c[1], base + c[2]);
    }
}

static st_soupinfo info_of(const st_soup *s)
{
    st_soupinfo r;
    st_error err;
    st_error_clear(&err);
    if (st_soupinfo_compute(&r, s, &err) != ST_OK) {
        char buf[1200];
        printf("# soupinfo failed: %s\n", st_error_format(&err, buf, sizeof buf));
        abort();
    }
    return r;
}

/* ---- tests ----------------------------------------------------------------- */

static void test_cube_indexed(void)
{
    st_soup *s = soup_or_die();
    add_cube(s, 0, 0, 0, 0, 0);
    st_soupinfo r = info_of(s);
    TAP_CHECK(r.vertices == 8 && r.welded_vertices == 8 && r.triangles == 12,
              "cube: 8 vertices, 12 triangles");
    TAP_CHECK(r.edges == 18 && r.manifold_edges == 18 && r.boundary_edges == 0 &&
                  r.nonmanifold_edges == 0,
              "cube: 18 edges, all manifold");
    TAP_CHECK(r.pieces == 1 && r.closed_pieces == 1 && r.closed,
              "cube: one closed piece");
    TAP_CHECK(r.euler == 2 && r.genus == 0, "cube: euler 2, genus 0 (got %lld, %lld)",
              r.euler, r.genus);
    TAP_CHECK(r.consistently_oriented && r.inconsistent_edges == 0 &&
                  r.nonorientable_pieces == 0,
              "cube: consistently oriented");
    TAP_CHECK(r.holes == 0 && r.degenerate_triangles == 0 &&
                  r.duplicated_triangles == 0 && r.nonmanifold_vertices == 0 &&
                  r.unreferenced_vertices == 0,
              "cube: no holes, degenerate, duplicated or unreferenced");
    TAP_CHECK(r.lo[0] == 0 && r.lo[1] == 0 && r.lo[2] == 0 && r.hi[0] == 1 &&
                  r.hi[1] == 1 && r.hi[2] == 1,
              "cube: bounds");
    TAP_NEAR(r.diagonal, sqrt(3.0), 1e-15, "cube: diagonal");
    st_soup_free(s);
}

static void test_cube_exact_soup(void)
{
    /* Every triangle with its own three vertices. */
    st_soup *s = soup_or_die();
    for (int t = 0; t < 12; t++) {
        uint32_t a = vert(s, cube_v[cube_t[t][0]][0], cube_v[cube_t[t][0]][1],
                          cube_v[cube_t[t][0]][2]);
        uint32_t b = vert(s, cube_v[cube_t[t][1]][0], cube_v[cube_t[t][1]][1],
                          cube_v[cube_t[t][1]][2]);
        uint32_t c = vert(s, cube_v[cube_t[t][2]][0], cube_v[cube_t[t][2]][1],
                          cube_v[cube_t[t][2]][2]);
        tri(s, a, b, c);
    }
    st_soupinfo r = info_of(s);
    TAP_CHECK(r.vertices == 36 && r.welded_vertices == 8,
              "exact soup: 36 vertices weld to 8 points");
    TAP_CHECK(r.pieces == 1 && r.closed && r.closed_pieces == 1 && r.edges == 18 &&
                  r.manifold_edges == 18,
              "exact soup: still one closed piece after welding");
    TAP_CHECK(r.euler == 2 && r.genus == 0 && r.consistently_oriented,
              "exact soup: euler 2, genus 0, oriented");
    st_soup_free(s);
}

static void test_negative_zero_welds(void)
{
    /* -0.0 == 0.0: the same point. */
    st_soup *s = soup_or_die();
    add_cube(s, 0, 0, 0, 1u << 0, 0);   /* bottom triangle 0 2 1 left out */
    uint32_t a = vert(s, -0.0, -0.0, -0.0);
    tri(s, a, 2, 1);
    st_soupinfo r = info_of(s);
    TAP_CHECK(r.welded_vertices == 8 && r.closed && r.pieces == 1,
              "-0.0 and 0.0 weld (welded %zu, closed %d)", r.welded_vertices,
              r.closed);
    st_soup_free(s);
}

static void test_face_removed(void)
{
    /* Both triangles of the bottom face gone: the square's four sides are
     * boundary, its diagonal is no edge at all any more. */
    st_soup *s = soup_or_die();
    add_cube(s, 0, 0, 0, 3u, 0);
    st_soupinfo r = info_of(s);
    TAP_CHECK(r.boundary_edges == 4 && r.edges == 17 && r.manifold_edges == 13,
              "face removed: 4 boundary edges of 17 (got %zu of %zu)",
              r.boundary_edges, r.edges);
    TAP_CHECK(r.holes == 1, "face removed: one hole (got %zu)", r.holes);
    TAP_CHECK(!r.closed && r.closed_pieces == 0 && r.pieces == 1,
              "face removed: one open piece");
    TAP_CHECK(r.euler == 1, "face removed: euler 1, a disk (got %lld)", r.euler);
    TAP_CHECK(r.nonmanifold_vertices == 0, "face removed: boundary vertices are manifold");
    st_soup_free(s);

    s = soup_or_die();
    add_cube(s, 0, 0, 0, 1u, 0);
    r = info_of(s);
    TAP_CHECK(r.boundary_edges == 3 && r.holes == 1 && r.edges == 18,
              "one triangle removed: 3 boundary edges, one hole");
    st_soup_free(s);
}

static void test_two_holes_at_one_vertex(void)
{
    /* Triangles 0 2 1 (bottom) and 0 5 4 (front) share only vertex 0:
     * without them, two boundary triangles pinch at 0. */
    st_soup *s = soup_or_die();
    add_cube(s, 0, 0, 0, 1u << 0 | 1u << 5, 0);
    st_soupinfo r = info_of(s);
    TAP_CHECK(r.boundary_edges == 6 && r.holes == 2,
              "two holes touching at a vertex count as two (got %zu holes)", r.holes);
    TAP_CHECK(r.nonmanifold_vertices == 1,
              "the pinch vertex is non-manifold (got %zu)", r.nonmanifold_vertices);
    st_soup_free(s);
}

static void test_flipped(void)
{
    st_soup *s = soup_or_die();
    add_cube(s, 0, 0, 0, 0, 1u << 4);
    st_soupinfo r = info_of(s);
    TAP_CHECK(r.inconsistent_edges == 3 && !r.consistently_oriented,
              "one flipped triangle: its 3 edges inconsistent (got %zu)",
              r.inconsistent_edges);
    TAP_CHECK(r.closed && r.closed_pieces == 1 && r.nonorientable_pieces == 0 &&
                  r.genus == 0,
              "one flipped triangle: still closed, orientable, genus 0");
    st_soup_free(s);

    s = soup_or_die();
    add_cube(s, 0, 0, 0, 0, 0xfffu);
    r = info_of(s);
    TAP_CHECK(r.inconsistent_edges == 0 && r.consistently_oriented,
              "all triangles flipped: consistent again (inside out)");
    st_soup_free(s);

    s = soup_or_die();
    add_cube(s, 0, 0, 0, 0, 1u << 0 | 1u << 1);
    r = info_of(s);
    TAP_CHECK(r.inconsistent_edges == 4,
              "a flipped face (2 triangles): its 4 sides inconsistent, not the "
              "diagonal (got %zu)", r.inconsistent_edges);
    st_soup_free(s);
}

static void test_duplicated(void)
{
    st_soup *s = soup_or_die();
    add_cube(s, 0, 0, 0, 0, 0);
    tri(s, 0, 2, 1);                            /* same indices */
    uint32_t a = vert(s, 0, 0, 1), b = vert(s, 1, 0, 1), c = vert(s, 1, 1, 1);
    tri(s, c, b, a);                            /* own vertices, reversed */
    st_soupinfo r = info_of(s);
    TAP_CHECK(r.duplicated_triangles == 2,
              "duplicates by position, any order (got %zu)", r.duplicated_triangles);
    TAP_CHECK(r.nonmanifold_edges == 6 && !r.closed,
              "a duplicated face makes its edges non-manifold (got %zu)",
              r.nonmanifold_edges);
    TAP_CHECK(r.welded_vertices == 8 && r.pieces == 1, "duplicates: one piece");
    st_soup_free(s);

    s = soup_or_die();
    add_cube(s, 0, 0, 0, 0, 0);
    tri(s, 0, 2, 1);
    tri(s, 1, 0, 2);
    r = info_of(s);
    TAP_CHECK(r.duplicated_triangles == 2,
              "a triangle three times: two extra copies (got %zu)",
              r.duplicated_triangles);
    st_soup_free(s);
}

static void test_fin(void)
{
    /* A triangle standing on the cube's edge 1-2. */
    st_soup *s = soup_or_die();
    add_cube(s, 0, 0, 0, 0, 0);
    uint32_t apex = vert(s, 2, 0.5, -1);
    tri(s, 1, 2, apex);
    st_soupinfo r = info_of(s);
    TAP_CHECK(r.nonmanifold_edges == 1 && r.boundary_edges == 2 && r.edges == 20,
              "fin: one non-manifold edge, two boundary edges");
    TAP_CHECK(r.holes == 0, "fin: its free edges are an open chain, no hole (got %zu)",
              r.holes);
    TAP_CHECK(r.nonmanifold_vertices == 2 && r.pieces == 1 && !r.closed &&
                  r.closed_pieces == 0,
              "fin: both ends of the edge non-manifold, one open piece");
    st_soup_free(s);
}

static void test_two_cubes(void)
{
    st_soup *s = soup_or_die();
    add_cube(s, 0, 0, 0, 0, 0);
    add_cube(s, 3, 0, 0, 0, 0);
    st_soupinfo r = info_of(s);
    TAP_CHECK(r.pieces == 2 && r.closed_pieces == 2 && r.closed,
              "two disjoint cubes: two closed pieces");
    TAP_CHECK(r.euler == 4 && r.genus == 0, "two cubes: euler 4, genus 0");
    st_soup_free(s);

    /* Touching at one corner: (1,1,1) of the first is (0,0,0) of the
     * second. Separate pieces (no shared edge), each a closed manifold on
     * its own; the shared corner has two fans. */
    s = soup_or_die();
    add_cube(s, 0, 0, 0, 0, 0);
    add_cube(s, 1, 1, 1, 0, 0);
    r = info_of(s);
    TAP_CHECK(r.welded_vertices == 15 && r.pieces == 2 && r.closed_pieces == 2,
              "cubes touching at a corner: 15 points, two closed pieces");
    TAP_CHECK(r.nonmanifold_vertices == 1 && r.euler == 3 && r.genus == 0,
              "cubes touching at a corner: one non-manifold vertex, euler 3 "
              "(got %zu, %lld)", r.nonmanifold_vertices, r.euler);
    st_soup_free(s);
}

static void test_degenerate(void)
{
    st_soup *s = soup_or_die();
    add_cube(s, 0, 0, 0, 0, 0);
    tri(s, 0, 0, 1);                              /* repeated index */
    uint32_t twin = vert(s, 1, 1, 1);             /* same point as vertex 6 */
    tri(s, 6, twin, 2);                           /* coincident corners */
    tri(s, 5, 5, 5);                              /* a point */
    vert(s, 9, 9, 9);                             /* nobody uses it */
    st_soupinfo r = info_of(s);
    TAP_CHECK(r.degenerate_triangles == 3, "degenerate: repeated index and "
              "coincident corners (got %zu)", r.degenerate_triangles);
    TAP_CHECK(r.closed && r.edges == 18 && r.pieces == 1 && r.euler == 2,
              "degenerate triangles take no part in the topology");
    TAP_CHECK(r.unreferenced_vertices == 1 && r.vertices == 10 &&
                  r.welded_vertices == 8,
              "one unreferenced vertex; the twin welds");
    TAP_CHECK(r.hi[0] == 1, "bounds ignore unreferenced vertices");
    st_soup_free(s);

    /* Nothing but degenerate triangles: no edges, no pieces, not closed. */
    s = soup_or_die();
    uint32_t a = vert(s, 0, 0, 0), b = vert(s, 1, 0, 0), c = vert(s, 0, 0, 0);
    tri(s, a, a, b);
    tri(s, a, c, b);
    r = info_of(s);
    TAP_CHECK(r.degenerate_triangles == 2 && r.edges == 0 && r.pieces == 0 &&
                  !r.closed && r.euler == 0 && r.holes == 0,
              "only degenerate triangles: no edges, no pieces, not closed");
    st_soup_free(s);
}

static void test_torus(void)
{
    /* A 4 x 6 torus grid: V 24, E 72, F 48, euler 0, genus 1. */
    enum { N = 4, M = 6 };
    st_soup *s = soup_or_die();
    const double pi = 3.14159265358979323846;
    for (int j = 0; j < M; j++)
        for (int i = 0; i < N; i++) {
            double u = 2 * pi * i / N, v = 2 * pi * j / M;
            vert(s, (2 + cos(u)) * cos(v), (2 + cos(u)) * sin(v), sin(u));
        }
    for (int j = 0; j < M; j++)
        for (int i = 0; i < N; i++) {
            uint32_t a = (uint32_t)(j * N + i), b = (uint32_t)(j * N + (i + 1) % N),
                     c = (uint32_t)((j + 1) % M * N + (i + 1) % N),
                     d = (uint32_t)((j + 1) % M * N + i);
            tri(s, a, b, c);
            tri(s, a, c, d);
        }
    st_soupinfo r = info_of(s);
    TAP_CHECK(r.edges == 72 && r.closed && r.consistently_oriented &&
                  r.closed_pieces == 1,
              "torus: 72 edges, closed, oriented");
    TAP_CHECK(r.euler == 0 && r.genus == 1, "torus: euler 0, genus 1 (got %lld, %lld)",
              r.euler, r.genus);
    st_soup_free(s);
}

static void test_moebius(void)
{
    /* A band of N squares between rails t_i and b_i, glued with a half
     * twist: the last square joins t, b of the end to b, t of the start. */
    enum { N = 6 };
    st_soup *s = soup_or_die();
    uint32_t t[N], b[N];
    for (int i = 0; i < N; i++) {
        t[i] = vert(s, cos(i), sin(i), 1 + 0.1 * i);
        b[i] = vert(s, cos(i), sin(i), -1 - 0.1 * i);
    }
    for (int i = 0; i < N; i++) {
        uint32_t t1 = i + 1 < N ? t[i + 1] : b[0];
        uint32_t b1 = i + 1 < N ? b[i + 1] : t[0];
        tri(s, t[i], b[i], b1);
        tri(s, t[i], b1, t1);
    }
    st_soupinfo r = info_of(s);
    TAP_CHECK(r.nonorientable_pieces == 1 && r.pieces == 1,
              "Moebius band: one non-orientable piece");
    TAP_CHECK(r.boundary_edges == 2 * N && r.holes == 1 && r.euler == 0,
              "Moebius band: one boundary loop of %d edges, euler 0 (got %zu, %zu, %lld)",
              2 * N, r.boundary_edges, r.holes, r.euler);
    TAP_CHECK(r.inconsistent_edges >= 1,
              "Moebius band: some edge is always inconsistent (%zu)",
              r.inconsistent_edges);
    st_soup_free(s);
}

static void test_order_independent(void)
{
    /* The same damaged soup with its triangles in reverse order. */
    st_soup *s = soup_or_die(), *rev = soup_or_die();
    add_cube(s, 0, 0, 0, 1u << 3, 1u << 7);
    add_cube(s, 0.5, 0.5, 0.5, 0, 0);
    tri(s, 0, 2, 1);
    for (size_t v = 0; v < s->nverts; v++)
        vert(rev, s->xyz[3 * v], s->xyz[3 * v + 1], s->xyz[3 * v + 2]);
    for (size_t i = s->ntris; i-- > 0;)
        tri(rev, s->tris[3 * i], s->tris[3 * i + 1], s->tris[3 * i + 2]);
    st_soupinfo a = info_of(s), b = info_of(rev);
    TAP_CHECK(memcmp(&a, &b, sizeof a) == 0,
              "the report does not depend on triangle order");
    st_soup_free(s);
    st_soup_free(rev);
}

static void test_errors(void)
{
    st_soup *s = soup_or_die();
    st_soupinfo r;
    st_error err;
    st_error_clear(&err);
    TAP_CHECK(st_soupinfo_compute(&r, s, &err) == ST_EINPUT &&
                  err.status == ST_EINPUT,
              "an empty soup is refused");
    st_soup_free(s);
}


/* ---- self-intersections: one known answer per case of the definition ---- */

/* Pairs found in a soup of the given triangles (each its own vertices, so
 * sharing comes from exact welding). */
static size_t si_pairs(const double (*v)[3], size_t nv, const uint32_t (*t)[3],
                       size_t nt, size_t *collinear)
{
    st_soup *s = soup_or_die();
    for (size_t i = 0; i < nt; i++) {
        uint32_t a = vert(s, v[t[i][0]][0], v[t[i][0]][1], v[t[i][0]][2]);
        uint32_t b = vert(s, v[t[i][1]][0], v[t[i][1]][1], v[t[i][1]][2]);
        uint32_t c = vert(s, v[t[i][2]][0], v[t[i][2]][1], v[t[i][2]][2]);
        tri(s, a, b, c);
    }
    (void)nv;
    st_soupinfo r = info_of(s);
    st_error err;
    unsigned char flags[8];
    if (st_soupinfo_self_intersections(&r, s, nt <= 8 ? flags : NULL, &err))
        abort();
    if (collinear)
        *collinear = r.collinear_triangles;
    st_soup_free(s);
    return r.self_checked ? r.self_intersecting_pairs : (size_t)-1;
}

static void test_self_intersections(void)
{
    static const double v[][3] = {
        {0, 0, 0}, {1, 0, 0}, {0, 1, 0},      /* 0-2: base triangle */
        {0, 0, 1}, {1, 1, 0}, {0.5, 0.5, 1},  /* 3-5 */
        {1, 1, 0.0}, {0.5, -1, 0},            /* 6, 7 */
        {0.25, 0.25, -1}, {0.25, 0.25, 1},    /* 8, 9: a needle through 0-2 */
        {0.2, 0.2, 0}, {2, 2, 1}, {2, 0, 1},  /* 10: in 0-2's interior */
        {0.5, 0, 0}, {0.5, 0.5, 0},           /* 13, 14 */
    };
    static const uint32_t edge_bent[][3] = {{0, 1, 2}, {1, 0, 3}};
    TAP_CHECK(si_pairs(v, 15, edge_bent, 2, NULL) == 0, "self: sharing an edge at an angle is no self-intersection");
    static const uint32_t edge_open[][3] = {{0, 1, 2}, {1, 0, 7}};
    TAP_CHECK(si_pairs(v, 15, edge_open, 2, NULL) == 0, "self: sharing an edge, coplanar, apexes on opposite sides: none");
    static const uint32_t edge_fold[][3] = {{0, 1, 2}, {1, 0, 14}};
    TAP_CHECK(si_pairs(v, 15, edge_fold, 2, NULL) == 1, "self: sharing an edge, folded flat onto each other: one pair");
    static const uint32_t vert_apart[][3] = {{0, 1, 2}, {0, 3, 7}};
    TAP_CHECK(si_pairs(v, 15, vert_apart, 2, NULL) == 0, "self: sharing only a vertex, apart elsewhere: none");
    static const uint32_t vert_pierce[][3] = {{0, 1, 2}, {0, 8, 9}};
    TAP_CHECK(si_pairs(v, 15, vert_pierce, 2, NULL) == 1, "self: sharing a vertex, the other's far edge through its interior: one pair");
    static const uint32_t vert_cross[][3] = {{0, 1, 2}, {0, 11, 12}};
    TAP_CHECK(si_pairs(v, 15, vert_cross, 2, NULL) == 0, "self: sharing a vertex, rising away from the base: none");
    static const uint32_t touch[][3] = {{0, 1, 2}, {10, 11, 12}};
    TAP_CHECK(si_pairs(v, 15, touch, 2, NULL) == 1, "self: no shared corner, touching at one point: one pair");
    static const uint32_t dup[][3] = {{0, 1, 2}, {2, 1, 0}};
    TAP_CHECK(si_pairs(v, 15, dup, 2, NULL) == 1, "self: a duplicate (reversed) covers its original: one pair");
    static const uint32_t col[][3] = {{0, 13, 1}, {0, 1, 2}};
    size_t ncol = 0;
    size_t nc = si_pairs(v, 15, col, 2, &ncol);
    TAP_CHECK(ncol == 1 && nc == 0, "self: a collinear triangle is counted and not tested against its neighbour (%zu, %zu)", ncol, nc);

    /* The closed cube: none; two cubes overlapping: some. */
    st_soup *s = soup_or_die();
    add_cube(s, 0, 0, 0, 0, 0);
    st_soupinfo r = info_of(s);
    st_error err;
    TAP_CHECK(st_soupinfo_self_intersections(&r, s, NULL, &err) == ST_OK && r.self_checked &&
              r.self_intersecting_pairs == 0, "self: a closed cube has none");
    add_cube(s, 0.5, 0.5, 0.5, 0, 0);
    TAP_CHECK(st_soupinfo_self_intersections(&r, s, NULL, &err) == ST_OK && r.self_intersecting_pairs > 0 &&
              r.self_intersecting_triangles > 0, "self: two overlapping cubes cross (%zu pairs)", r.self_intersecting_pairs);
    st_soup_free(s);
}

int main(int argc, char **argv)
{
    static const tap_test tests[] = {TAP_TEST(cube_indexed), TAP_TEST(cube_exact_soup),
                                     TAP_TEST(negative_zero_welds), TAP_TEST(face_removed),
                                     TAP_TEST(two_holes_at_one_vertex), TAP_TEST(flipped),
                                     TAP_TEST(duplicated), TAP_TEST(fin), TAP_TEST(two_cubes),
                                     TAP_TEST(degenerate), TAP_TEST(torus), TAP_TEST(moebius),
                                     TAP_TEST(order_independent), TAP_TEST(errors),
                                     TAP_TEST(self_intersections), {0}};
    return tap_main(argc, argv, tests);
}
