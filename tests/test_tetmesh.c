/*
 * test_tetmesh.c - tet meshes (tetmesh.h) and the quality of one tet
 * (tetqual.h): known dihedral angles, volumes, circumcenters, adjacency
 * and the outward boundary on hand-made meshes.
 */
#include "souptet/tetmesh.h"
#include "souptet/tetqual.h"
#include "cubetets.h"
#include "tap.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static const double k_regular = 70.528779365509308630754;   /* acos(1/3) */
static const double k_cube_slant = 54.735610317245345684622; /* acos(1/sqrt 3) */

/* n x n x n unit cubes, 5 tets each, the split mirrored on alternating
 * cubes so that shared faces match. Cube corner c = (c&1, c>>1&1, c>>2&1). */
static void add_lattice(st_tetmesh *m, int nx, int ny, int nz)
{
    const uint32_t base = (uint32_t)m->npoints;
    for (int k = 0; k <= nz; k++)
        for (int j = 0; j <= ny; j++)
            for (int i = 0; i <= nx; i++)
                add_pt(m, i, j, k);
    add_cube_tets(m, base, nx, ny, nz);
}

static void test_regular(void)
{
    const double p[4][3] = {{1, 1, 1}, {1, -1, -1}, {-1, 1, -1}, {-1, -1, 1}};
    double a[6], lo, hi, c[3];
    st_tet_dihedrals(p[0], p[1], p[2], p[3], a);
    double worst = 0;
    for (int i = 0; i < 6; i++)
        worst = fmax(worst, fabs(a[i] - k_regular));
    TAP_NEAR(worst, 0, 1e-12, "regular tet: all six dihedral angles 70.5288");
    st_tet_dihedral_range(p[0], p[1], p[2], p[3], &lo, &hi);
    TAP_NEAR(hi - lo, 0, 1e-12, "regular tet: range is one value");
    /* det[b-a, c-a, d-a] for these points is -16, volume -8/3 (negative
     * order); swapping two corners flips it. */
    TAP_NEAR(st_tet_volume(p[0], p[1], p[2], p[3]), -8.0 / 3.0, 1e-14,
             "regular tet: signed volume -8/3 in this order");
    TAP_NEAR(st_tet_volume(p[0], p[1], p[3], p[2]), 8.0 / 3.0, 1e-14,
             "regular tet: +8/3 with two corners swapped");
    TAP_CHECK(st_tet_circumcenter(p[0], p[1], p[2], p[3], c) == 1 &&
                  fabs(c[0]) + fabs(c[1]) + fabs(c[2]) < 1e-15,
              "regular tet: circumcenter at the origin");
    /* Far from the origin the angles keep their digits (differences are
     * taken first). */
    double q[4][3];
    for (int i = 0; i < 4; i++)
        for (int k = 0; k < 3; k++)
            q[i][k] = p[i][k] + 1e6;
    st_tet_dihedral_range(q[0], q[1], q[2], q[3], &lo, &hi);
    TAP_NEAR(lo, k_regular, 1e-8, "regular tet at 1e6: min 70.5288");
    TAP_NEAR(hi, k_regular, 1e-8, "regular tet at 1e6: max 70.5288");
}

static void test_cube_tets(void)
{
    /* Corner tet at the origin and the middle (regular) tet of the cube. */
    const double o[3] = {0, 0, 0}, x[3] = {1, 0, 0}, y[3] = {0, 1, 0},
                 z[3] = {0, 0, 1}, xyz[3] = {1, 1, 1};
    double a[6];
    st_tet_dihedrals(o, x, y, z, a);
    /* Edges (0 1) (0 2) (0 3) meet at the right-angled corner: 90; the
     * edges of the slanted face: 54.7356. */
    TAP_NEAR(a[0], 90, 1e-12, "corner tet: edge (0 1) 90");
    TAP_NEAR(a[1], 90, 1e-12, "corner tet: edge (0 2) 90");
    TAP_NEAR(a[2], 90, 1e-12, "corner tet: edge (0 3) 90");
    TAP_NEAR(a[3], k_cube_slant, 1e-12, "corner tet: edge (1 2) 54.7356");
    TAP_NEAR(a[4], k_cube_slant, 1e-12, "corner tet: edge (1 3) 54.7356");
    TAP_NEAR(a[5], k_cube_slant, 1e-12, "corner tet: edge (2 3) 54.7356");
    TAP_NEAR(st_tet_volume(o, x, y, z), 1.0 / 6.0, 1e-15,
             "corner tet (o x y z): volume +1/6, positive");
    double lo, hi;
    st_tet_dihedral_range(x, y, z, xyz, &lo, &hi);
    TAP_CHECK(fabs(lo - k_regular) < 1e-12 && fabs(hi - k_regular) < 1e-12,
              "middle tet of the cube: 70.5288 (%.6f..%.6f)", lo, hi);
    double c[3];
    st_tet_circumcenter(o, x, y, z, c);
    TAP_CHECK(fabs(c[0] - 0.5) + fabs(c[1] - 0.5) + fabs(c[2] - 0.5) < 1e-15,
              "corner tet: circumcenter at the cube center");
}

static void test_degenerate(void)
{
    const double a[3] = {0, 0, 0}, b[3] = {1, 0, 0}, c[3] = {0, 1, 0},
                 d[3] = {1, 1, 0}, e[3] = {0.25, 0.25, 0};
    double lo, hi, cc[3];
    st_tet_dihedral_range(a, b, c, d, &lo, &hi);
    TAP_CHECK(lo == 0 && hi == 180, "flat tet (square): min 0, max 180 (%g %g)",
              lo, hi);
    st_tet_dihedral_range(a, b, c, e, &lo, &hi);
    TAP_CHECK(lo == 0, "flat tet (point inside a face): min 0 (%g)", lo);
    st_tet_dihedral_range(a, a, b, c, &lo, &hi);
    TAP_CHECK(lo == 0, "tet with a repeated corner: min 0 (%g)", lo);
    TAP_CHECK(st_tet_volume(a, b, c, d) == 0, "flat tet: volume 0");
    TAP_CHECK(st_tet_circumcenter(a, b, c, d, cc) == 0 && cc[0] == 0.5 &&
                  cc[1] == 0.5 && cc[2] == 0,
              "flat tet: no circumcenter, the centroid instead");
    /* A sliver: four points near a square, lifted by 1e-9. */
    const double s[4][3] = {{0, 0, 0}, {1, 0, 1e-9}, {0, 1, 1e-9}, {1, 1, 0}};
    st_tet_dihedral_range(s[0], s[1], s[2], s[3], &lo, &hi);
    TAP_CHECK(lo > 0 && lo < 1e-6 && hi > 180 - 1e-6 && hi < 180,
              "sliver: min just above 0, max just below 180 (%.3g, 180-%.3g)",
              lo, 180 - hi);
}

static void test_circumcenter_random(void)
{
    unsigned s = 12345;
    double worst = 0;
    for (int n = 0; n < 200; n++) {
        double p[4][3], c[3];
        for (int i = 0; i < 4; i++)
            for (int k = 0; k < 3; k++) {
                s = s * 1103515245u + 12345u;
                p[i][k] = 100.0 + (double)(s >> 8) / (1 << 24);
            }
        if (!st_tet_circumcenter(p[0], p[1], p[2], p[3], c))
            continue;
        double r[4];
        for (int i = 0; i < 4; i++)
            r[i] = sqrt((p[i][0] - c[0]) * (p[i][0] - c[0]) +
                        (p[i][1] - c[1]) * (p[i][1] - c[1]) +
                        (p[i][2] - c[2]) * (p[i][2] - c[2]));
        for (int i = 1; i < 4; i++)
            worst = fmax(worst, fabs(r[i] - r[0]) / r[0]);
    }
    TAP_CHECK(worst < 1e-8,
              "random tets near (100,100,100): circumcenter equidistant "
              "(worst relative spread %.2g)", worst);
}

static void test_build(void)
{
    st_tetmesh *m = st_tetmesh_new();
    st_error err;
    st_error_clear(&err);
    TAP_CHECK(m && m->npoints == 0 && m->ntets == 0, "new mesh is empty");
    add_pt(m, 0, 0, 0);
    add_pt(m, 1, 0, 0);
    add_pt(m, 0, 1, 0);
    add_pt(m, 0, 0, 1);
    TAP_CHECK(st_tetmesh_add_tet(m, 0, 1, 2, 3, &err) == ST_OK,
              "add a tet");
    TAP_CHECK(st_tetmesh_add_tet(m, 0, 1, 2, 4, &err) == ST_EINPUT &&
                  m->ntets == 1,
              "a tet referring to point 4 of 4 is refused");
    const double bad[3] = {0, NAN, 0};
    TAP_CHECK(st_tetmesh_add_point(m, bad, &err) == ST_EINPUT &&
                  m->npoints == 4,
              "a non-finite point is refused");
    double *v;
    TAP_CHECK(st_tetmesh_add_array(m, "w", ST_ON_POINTS, 2, &v, &err) ==
                      ST_OK &&
                  v[0] == 0 && v[7] == 0,
              "a zero-filled 2-component point array");
    for (int i = 0; i < 8; i++)
        v[i] = i;
    TAP_CHECK(st_tetmesh_add_array(m, "w", ST_ON_CELLS, 1, &v, &err) ==
                      ST_OK && m->narrays == 2,
              "the same name on cells is another array");
    v[0] = 42;
    TAP_CHECK(st_tetmesh_add_array(m, "x", ST_ON_CELLS, 10, &v, &err) ==
                  ST_EINPUT,
              "10 components are refused");
    const st_tet_array *a = st_tetmesh_find_array(m, "w", ST_ON_CELLS);
    TAP_CHECK(a && a->values[0] == 42 && a->ncomp == 1, "find_array by name "
              "and association");
    TAP_CHECK(!st_tetmesh_find_array(m, "nope", ST_ON_CELLS),
              "find_array: NULL for a missing name");
    st_meta_set(&m->meta, "h", "0.5");
    st_tetmesh *c = NULL;
    TAP_CHECK(st_tetmesh_copy(&c, m, &err) == ST_OK && c->npoints == 4 &&
                  c->ntets == 1 && c->narrays == 2 &&
                  st_tetmesh_find_array(c, "w", ST_ON_POINTS)->values[7] ==
                      7 &&
                  strcmp(st_meta_get(&c->meta, "h"), "0.5") == 0 &&
                  c->xyz != m->xyz,
              "copy is deep: geometry, arrays, meta");
    st_tetmesh_clear_arrays(m);
    TAP_CHECK(m->narrays == 0 && m->ntets == 1, "clear_arrays keeps "
              "geometry");
    st_tetmesh_free(c);
    st_tetmesh_free(m);
    st_tetmesh_free(NULL);
}

static void test_compact(void)
{
    st_tetmesh *m = st_tetmesh_new();
    st_error err;
    for (int i = 0; i < 7; i++)
        add_pt(m, i, i * i, i * i * i);
    st_tetmesh_add_tet(m, 6, 1, 3, 5, NULL);
    double *v;
    st_tetmesh_add_array(m, "id", ST_ON_POINTS, 1, &v, NULL);
    for (int i = 0; i < 7; i++)
        v[i] = i;
    TAP_CHECK(st_tetmesh_compact(m, &err) == ST_OK && m->npoints == 4,
              "compact drops the 3 unused points");
    const st_tet_array *a = st_tetmesh_find_array(m, "id", ST_ON_POINTS);
    int ok = 1;
    for (int k = 0; k < 4; k++) {
        uint32_t p = m->tets[k];
        double old = a->values[p];
        ok &= m->xyz[3 * p] == old && m->xyz[3 * p + 1] == old * old;
    }
    TAP_CHECK(ok && m->tets[0] == 3 && m->tets[1] == 0,
              "compact: tets, points and point arrays renumbered together, "
              "old order kept");
    st_tetmesh_free(m);
}

/* Checks the boundary of m: every face's normal points away from the
 * centroid of its own tet, and the divergence theorem over the faces gives
 * the total volume. */
static void check_boundary(const st_tetmesh *m, size_t want_faces,
                           double want_volume, const char *what)
{
    uint32_t *f, *ft;
    size_t nf;
    st_error err;
    st_status s = st_tetmesh_boundary(m, &f, &ft, &nf, &err);
    TAP_CHECK(s == ST_OK && nf == want_faces, "%s: %zu boundary faces "
              "(got %zu)", what, want_faces, nf);
    if (s)
        return;
    int outward = 1, sorted = 1;
    double vol = 0;
    for (size_t i = 0; i < nf; i++) {
        const double *a = m->xyz + 3 * f[3 * i], *b = m->xyz + 3 * f[3 * i + 1],
                     *c = m->xyz + 3 * f[3 * i + 2];
        const uint32_t *t = m->tets + 4 * ft[i];
        double g[3] = {0, 0, 0}, n[3], u[3], w[3];
        for (int k = 0; k < 4; k++)
            for (int d = 0; d < 3; d++)
                g[d] += 0.25 * m->xyz[3 * t[k] + d];
        for (int d = 0; d < 3; d++) {
            u[d] = b[d] - a[d];
            w[d] = c[d] - a[d];
        }
        n[0] = u[1] * w[2] - u[2] * w[1];
        n[1] = u[2] * w[0] - u[0] * w[2];
        n[2] = u[0] * w[1] - u[1] * w[0];
        outward &= n[0] * (a[0] - g[0]) + n[1] * (a[1] - g[1]) +
                       n[2] * (a[2] - g[2]) > 0;
        vol += (a[0] * n[0] + a[1] * n[1] + a[2] * n[2]) / 6.0;
        if (i > 0 && ft[i] < ft[i - 1])
            sorted = 0;
    }
    TAP_CHECK(outward, "%s: every boundary face points out of its tet", what);
    TAP_NEAR(vol, want_volume, 1e-12, "%s: divergence over the boundary "
             "gives the volume", what);
    TAP_CHECK(sorted, "%s: faces sorted by owning tet", what);
    free(f);
    free(ft);
}

/* nbr is symmetric, and counts of -1 entries. */
static void check_neighbors(const st_tetmesh *m, size_t want_boundary,
                            size_t want_nonmanifold, const char *what)
{
    int64_t *nbr;
    size_t nm = 99, nb = 0;
    st_error err;
    TAP_CHECK(st_tetmesh_neighbors(m, &nbr, &nm, &err) == ST_OK &&
                  nm == want_nonmanifold,
              "%s: %zu non-manifold faces (got %zu)", what, want_nonmanifold,
              nm);
    int sym = 1;
    for (size_t t = 0; t < m->ntets; t++)
        for (int i = 0; i < 4; i++) {
            int64_t u = nbr[4 * t + (size_t)i];
            if (u < 0) {
                nb++;
                continue;
            }
            int back = 0;
            for (int k = 0; k < 4; k++)
                back += nbr[4 * (size_t)u + (size_t)k] == (int64_t)t;
            sym &= back == 1;
        }
    TAP_CHECK(sym, "%s: adjacency is symmetric", what);
    TAP_CHECK(nb == want_boundary, "%s: %zu faces without neighbour (got "
              "%zu)", what, want_boundary, nb);
    free(nbr);
}

static void test_adjacency(void)
{
    st_tetmesh *m = st_tetmesh_new();
    add_lattice(m, 1, 1, 1);
    TAP_CHECK(m->ntets == 5 && m->npoints == 8, "unit cube: 5 tets, 8 points");
    double lo[5], hi[5], vol[5], sum = 0, mn = 180, mx = 0;
    st_tetmesh_quality(m, lo, hi, vol);
    for (int t = 0; t < 5; t++) {
        sum += vol[t];
        mn = fmin(mn, lo[t]);
        mx = fmax(mx, hi[t]);
    }
    TAP_NEAR(sum, 1, 1e-15, "unit cube: volume 1");
    TAP_NEAR(mn, k_cube_slant, 1e-12, "unit cube: min dihedral 54.7356");
    TAP_NEAR(mx, 90, 1e-12, "unit cube: max dihedral 90");
    check_neighbors(m, 12, 0, "unit cube");
    int64_t *nbr;
    st_tetmesh_neighbors(m, &nbr, NULL, NULL);
    TAP_CHECK(nbr[0] >= 1 && nbr[1] >= 1 && nbr[2] >= 1 && nbr[3] >= 1,
              "unit cube: the middle tet has four neighbours");
    free(nbr);
    check_boundary(m, 12, 1.0, "unit cube");
    st_tetmesh_free(m);

    m = st_tetmesh_new();
    add_lattice(m, 2, 1, 1);
    check_neighbors(m, 20, 0, "two cubes sharing a face");
    check_boundary(m, 20, 2.0, "two cubes sharing a face");
    st_tetmesh_free(m);

    m = st_tetmesh_new();
    add_lattice(m, 4, 3, 5);
    check_neighbors(m, 4 * (12 + 20 + 15), 0, "4x3x5 cubes");
    check_boundary(m, 4 * (12 + 20 + 15), 60.0, "4x3x5 cubes");
    st_tetmesh_free(m);

    /* Three tets on one triangle: a non-manifold face, on nobody's
     * boundary and nobody's neighbour. */
    m = three_tets_on_a_face();
    check_neighbors(m, 12, 1, "three tets on one face");
    uint32_t *f;
    size_t nf;
    st_tetmesh_boundary(m, &f, NULL, &nf, NULL);
    TAP_CHECK(nf == 9, "three tets on one face: 9 boundary faces (got %zu)",
              nf);
    free(f);
    st_tetmesh_free(m);

    /* Empty mesh. */
    m = st_tetmesh_new();
    check_neighbors(m, 0, 0, "empty mesh");
    st_tetmesh_free(m);
}

/* st_tet_dihedral_range takes the atan2 of the edges near the extremes
 * only: its values must be the smallest and largest of st_tet_dihedrals
 * bit for bit, on random tets, lattice tets (equal angles), near-flat and
 * flat ones, needles, tets far from the origin or near overflow and
 * underflow, and with a NaN or infinite corner; in every corner order. */
static uint64_t range_rng = 0x9e3779b97f4a7c15ull;
static double range_rnd(void)   /* xorshift64, uniform in [0, 1) */
{
    range_rng ^= range_rng << 13;
    range_rng ^= range_rng >> 7;
    range_rng ^= range_rng << 17;
    return (double)(range_rng >> 11) / 9007199254740992.0;
}

static void range_tet(double q[4][3], int t)
{
    for (int i = 0; i < 4; i++)
        for (int a = 0; a < 3; a++)
            q[i][a] = 2.0 * range_rnd() - 1.0;
    static const double bcc[4][3] = {{0, 0, 0}, {2, 0, 0}, {1, 1, 1}, {1, 1, -1}};
    switch (t % 9) {
    case 1:   /* a BCC lattice tet, scaled and moved: equal angles */
        for (int i = 0; i < 4; i++)
            for (int a = 0; a < 3; a++)
                q[i][a] = 37.0 * range_rnd() + (0.5 + range_rnd()) * bcc[i][a];
        break;
    case 2:   /* sliver */
        for (int a = 0; a < 3; a++)
            q[3][a] = 0.3 * q[0][a] + 0.3 * q[1][a] + 0.4 * q[2][a] + 1e-9 * range_rnd();
        break;
    case 3:   /* flat, or a repeated corner */
        for (int a = 0; a < 3; a++)
            q[3][a] = t % 2 ? 2.0 * q[0][a] - q[1][a] : q[1][a];
        break;
    case 4:   /* needle */
        for (int a = 0; a < 3; a++)
            q[1][a] = q[0][a] + 1e-12 * range_rnd();
        break;
    case 5:   /* far from the origin */
        for (int i = 0; i < 4; i++)
            for (int a = 0; a < 3; a++)
                q[i][a] = 1e6 + 1e-4 * q[i][a];
        break;
    case 6:   /* near overflow or underflow */
        for (int i = 0; i < 4; i++)
            for (int a = 0; a < 3; a++)
                q[i][a] *= t % 2 ? 1e80 : 1e-80;
        break;
    case 7:   /* a NaN or infinite coordinate */
        q[t % 4][t % 3] = t % 2 ? NAN : INFINITY;
        break;
    default:
        break;
    }
}

static void test_range_is_dihedrals(void)
{
    static const int perm[6][4] = {{0, 1, 2, 3}, {1, 0, 3, 2}, {2, 3, 0, 1},
                                   {3, 2, 1, 0}, {0, 2, 3, 1}, {1, 3, 2, 0}};
    int same = 1, n = 0, flat = 0;
    for (int t = 0; t < 2000; t++) {
        double q[4][3];
        range_tet(q, t);
        for (int k = 0; k < 6; k++) {
            const double *a = q[perm[k][0]], *b = q[perm[k][1]], *c = q[perm[k][2]],
                         *d = q[perm[k][3]];
            double ang[6], lo, hi;
            st_tet_dihedrals(a, b, c, d, ang);
            double wlo = ang[0], whi = ang[0];
            for (int i = 1; i < 6; i++) {
                wlo = ang[i] < wlo ? ang[i] : wlo;
                whi = ang[i] > whi ? ang[i] : whi;
            }
            st_tet_dihedral_range(a, b, c, d, &lo, &hi);
            if (memcmp(&lo, &wlo, sizeof lo) != 0 || memcmp(&hi, &whi, sizeof hi) != 0) {
                if (same)
                    TAP_NOTE("tet %d order %d: %.17g..%.17g, the angles %.17g..%.17g", t, k,
                             lo, hi, wlo, whi);
                same = 0;
            }
            flat += wlo == 0.0;
            n++;
        }
    }
    TAP_CHECK(same && flat > n / 20 && flat < n / 2,
              "the dihedral range is the smallest and largest dihedral bit for bit "
              "(%d tets, %d with a 0 angle)", n, flat);
}

/* Faces by brute force: the neighbour of each tet face is the one other
 * tet with the same three corners, none (-1) for a boundary face or one
 * on three or more tets (counted as non-manifold). A vertex with hundreds
 * of faces where it is the smallest index (the adjacency sorts each
 * vertex's faces: runs, then merges) and a face on many tets. */
static void test_adjacency_many(void)
{
    st_tetmesh *m = st_tetmesh_new();
    for (int i = 0; i < 120; i++) {
        double p[3] = {cos(0.1 * i), sin(0.1 * i), 0.01 * i};
        add_pt(m, p[0], p[1], p[2]);
    }
    /* point 0 in every tet; faces (0 a b) shared along fans, (0 1 2) on
     * a book of 30 tets, some tets twice over (their four faces are on
     * two tets each, or more) */
    for (uint32_t k = 3; k < 33; k++)
        st_tetmesh_add_tet(m, 0, 1, 2, k, NULL);
    for (uint32_t k = 3; k < 118; k++)
        st_tetmesh_add_tet(m, 0, k, k + 1, 119 - (k % 3), NULL);
    for (uint32_t k = 40; k < 100; k += 7)
        st_tetmesh_add_tet(m, 0, 119 - (k % 3), k + 1, k, NULL);
    const size_t nt = m->ntets;
    int64_t *nbr = NULL;
    size_t nm = 0;
    st_status rc = st_tetmesh_neighbors(m, &nbr, &nm, NULL);
    static const int fc[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};
    int ok = rc == ST_OK, shared = 0;
    size_t want_nm = 0;
    uint32_t (*key)[3] = malloc(4 * nt * sizeof *key);
    for (size_t f = 0; f < 4 * nt; f++) {
        const uint32_t *q = m->tets + 4 * (f / 4);
        uint32_t v[3] = {q[fc[f % 4][0]], q[fc[f % 4][1]], q[fc[f % 4][2]]};
        for (int a = 0; a < 3; a++)
            for (int b = a + 1; b < 3; b++)
                if (v[b] < v[a]) {
                    uint32_t t = v[a];
                    v[a] = v[b];
                    v[b] = t;
                }
        memcpy(key[f], v, sizeof v);
    }
    for (size_t f = 0; f < 4 * nt && ok; f++) {
        size_t same = 0, other = 0, first = f;
        for (size_t g = 0; g < 4 * nt; g++)
            if (memcmp(key[f], key[g], sizeof key[f]) == 0) {
                same++;
                if (g != f)
                    other = g;
                if (g < first)
                    first = g;
            }
        int64_t want = same == 2 ? (int64_t)(other / 4) : -1;
        ok = nbr[f] == want;
        shared += same == 2;
        want_nm += same > 2 && first == f;
    }
    TAP_CHECK(ok && nm == want_nm && want_nm > 0 && shared > 50,
              "many faces on one vertex: neighbours as by brute force (%zu tets, %d shared "
              "faces, %zu non-manifold)", nt, shared, nm);
    free(key);
    free(nbr);
    st_tetmesh_free(m);
}

int main(int argc, char **argv)
{
    static const tap_test tests[] = {TAP_TEST(regular), TAP_TEST(cube_tets),
                                     TAP_TEST(degenerate), TAP_TEST(range_is_dihedrals), TAP_TEST(circumcenter_random),
                                     TAP_TEST(build), TAP_TEST(compact), TAP_TEST(adjacency), TAP_TEST(adjacency_many),
                                     {0}};
    return tap_main(argc, argv, tests);
}
