/* test_enclose.c - exact point location in tet meshes and the enclosure
 * counts: known answers on a cube of five tets, touching contacts, inverted
 * and flat tets, agreement with brute force, thread-count independence and
 * the speed on a 70K-triangle soup; the rounding to float32 that keeps the
 * enclosure (st_enclosure_round_float32) where rounding to nearest loses
 * it. */
#include "souptet/enclose.h"
#include "souptet/pred.h"
#include "shapes.h"
#include "tap.h"

#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define SPLITMIX_SEED 0x5eed5eed5eed5eedULL
#include "splitmix.h"

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static void add_point(st_tetmesh *m, double x, double y, double z)
{
    const double p[3] = {x, y, z};
    st_tetmesh_add_point(m, p, NULL);
}

/* Add tet (a b c d), reordered to be positively oriented unless keep. */
static void add_tet_pos(st_tetmesh *m, uint32_t a, uint32_t b, uint32_t c, uint32_t d)
{
    const double *P = m->xyz;
    if (st_orient3d(P + 3 * a, P + 3 * b, P + 3 * c, P + 3 * d) > 0) {
        uint32_t t = a;
        a = b;
        b = t;
    }
    st_tetmesh_add_tet(m, a, b, c, d, NULL);
}

/* The cube [lo, hi]^3 as five positively oriented tets. */
static st_tetmesh *cube5(double lo, double hi)
{
    st_tetmesh *m = st_tetmesh_new();
    for (int i = 0; i < 8; i++)
        add_point(m, i & 1 ? hi : lo, i & 2 ? hi : lo, i & 4 ? hi : lo);
    static const uint32_t tet[5][4] = {{0, 1, 2, 4}, {3, 1, 2, 7}, {5, 1, 4, 7},
                                       {6, 2, 4, 7}, {1, 2, 4, 7}};
    for (int i = 0; i < 5; i++)
        add_tet_pos(m, tet[i][0], tet[i][1], tet[i][2], tet[i][3]);
    return m;
}

/* A lattice of n0 x n1 x n2 cubes of side h from o, six tets per cube
 * around the main diagonal (the same split everywhere, so conforming). */
static st_tetmesh *kuhn_lattice(const double o[3], double h, int n0, int n1, int n2)
{
    st_tetmesh *m = st_tetmesh_new();
    for (int z = 0; z <= n2; z++)
        for (int y = 0; y <= n1; y++)
            for (int x = 0; x <= n0; x++)
                add_point(m, o[0] + h * x, o[1] + h * y, o[2] + h * z);
#define VID(x, y, z) ((uint32_t)((x) + (n0 + 1) * ((y) + (n1 + 1) * (z))))
    static const int perm[6][3] = {{0,1,2},{0,2,1},{1,0,2},{1,2,0},{2,0,1},{2,1,0}};
    for (int z = 0; z < n2; z++)
        for (int y = 0; y < n1; y++)
            for (int x = 0; x < n0; x++)
                for (int p = 0; p < 6; p++) {
                    int c[3] = {x, y, z};
                    uint32_t v[4];
                    v[0] = VID(c[0], c[1], c[2]);
                    for (int s = 0; s < 3; s++) {
                        c[perm[p][s]]++;
                        v[s + 1] = VID(c[0], c[1], c[2]);
                    }
                    add_tet_pos(m, v[0], v[1], v[2], v[3]);
                }
#undef VID
    return m;
}

static void test_cube_encloses_small_soup(void)
{
    st_tetmesh *m = cube5(0, 1);
    st_soup *s = st_soup_new();
    const double lo[3] = {0.2, 0.2, 0.2}, hi[3] = {0.8, 0.8, 0.8};
    add_box(s, lo, hi);
    add_sphere(s, 0.3, 2.0);
    for (size_t i = 0; i < s->nverts; i++)
        for (int k = 0; k < 3; k++)
            if (i >= 36)
                s->xyz[3 * i + (size_t)k] += 0.5;
    st_enclosure e;
    st_error err = {0};
    TAP_CHECK(st_enclosure_compute(&e, m, s, NULL, NULL, NULL, &err) == ST_OK,
              "enclosure of a small soup in a cube of 5 tets");
    TAP_CHECK(e.vertices == s->nverts && e.vertices_inside == e.vertices &&
              e.fraction_inside == 1.0 && e.crossing_triangles == 0 &&
              e.boundary_faces == 12 && e.encloses,
              "all %zu vertices inside, 0 of %zu triangles crossing, 12 boundary faces (%zu)",
              e.vertices, s->ntris, e.boundary_faces);
    st_soup_free(s);
    st_tetmesh_free(m);
}

static void test_soup_sticking_out(void)
{
    st_tetmesh *m = cube5(0, 1);
    st_soup *s = st_soup_new();
    const double lo[3] = {0.5, 0.5, 0.5}, hi[3] = {1.5, 1.5, 1.5};
    add_box(s, lo, hi); /* 12 triangles, 36 vertices, corner (0.5)^3 inside */
    unsigned char *vin = malloc(s->nverts), *cr = malloc(s->ntris);
    st_enclosure e;
    st_error err = {0};
    TAP_CHECK(st_enclosure_compute(&e, m, s, NULL, vin, cr, &err) == ST_OK,
              "enclosure of a box sticking out of the cube");
    /* Vertices at (0.5, 0.5, 0.5) are inside; at any 1.5 coordinate outside. */
    size_t want_in = 0, bad = 0;
    for (size_t i = 0; i < s->nverts; i++) {
        const double *p = s->xyz + 3 * i;
        int in = p[0] < 1 && p[1] < 1 && p[2] < 1;
        want_in += (size_t)in;
        bad += vin[i] != in;
    }
    TAP_CHECK(bad == 0 && e.vertices_inside == want_in && e.vertices_inside > 0 &&
              e.fraction_inside < 1.0 && !e.encloses,
              "inside vertices exactly the corner ones (%zu of %zu, fraction %.3f)",
              e.vertices_inside, e.vertices, e.fraction_inside);
    /* The six triangles of the box's near faces (through (0.5, 0.5, 0.5))
     * meet the cube's boundary (crossing it, or touching its corner edge
     * at (.., 1, 1)); those of the far faces (a coordinate 1.5) miss it. */
    size_t want_cross = 0, bad_cross = 0;
    for (size_t t = 0; t < s->ntris; t++) {
        const uint32_t *v = s->tris + 3 * t;
        int far = 0;
        for (int a = 0; a < 3; a++)
            far |= s->xyz[3 * v[0] + (size_t)a] == 1.5 && s->xyz[3 * v[1] + (size_t)a] == 1.5 &&
                   s->xyz[3 * v[2] + (size_t)a] == 1.5;
        want_cross += (size_t)!far;
        bad_cross += cr[t] != !far;
    }
    TAP_CHECK(e.crossing_triangles == want_cross && want_cross == 6 && bad_cross == 0,
              "the 6 near-face triangles cross the boundary, the 6 far ones do not (%zu)",
              e.crossing_triangles);
    free(vin);
    free(cr);
    st_soup_free(s);
    st_tetmesh_free(m);
}

/* A soup vertex exactly on a boundary face is inside (closed tets), but
 * its triangle touches the boundary, which counts as crossing. */
static void test_touching_boundary(void)
{
    st_tetmesh *m = cube5(0, 1);
    st_soup *s = st_soup_new();
    const double a[3] = {1.0, 0.5, 0.5}, b[3] = {0.5, 0.4, 0.5}, c[3] = {0.5, 0.6, 0.6};
    add_tri(s, a, b, c, 0);
    const double d[3] = {0.3, 0.3, 0.3}, e2[3] = {0.4, 0.3, 0.3}, f[3] = {0.3, 0.4, 0.3};
    add_tri(s, d, e2, f, 0);
    st_enclosure e;
    st_error err = {0};
    unsigned char cr[2];
    TAP_CHECK(st_enclosure_compute(&e, m, s, NULL, NULL, cr, &err) == ST_OK &&
              e.vertices_inside == 6 && e.crossing_triangles == 1 && cr[0] == 1 &&
              cr[1] == 0 && !e.encloses,
              "vertex on a boundary face: inside, but its triangle touches (crossing)");
    /* One ulp inside the face: strictly inside, no crossing. */
    s->xyz[0] = nextafter(1.0, 0.0);
    TAP_CHECK(st_enclosure_compute(&e, m, s, NULL, NULL, cr, &err) == ST_OK &&
              e.vertices_inside == 6 && e.crossing_triangles == 0 && e.encloses,
              "one ulp inside the face: enclosed");
    s->xyz[0] = nextafter(1.0, 2.0);
    TAP_CHECK(st_enclosure_compute(&e, m, s, NULL, NULL, cr, &err) == ST_OK &&
              e.vertices_inside == 5 && e.crossing_triangles == 1,
              "one ulp outside the face: one vertex out, one crossing");
    st_soup_free(s);
    st_tetmesh_free(m);
}

/* An inverted tet still covers its points; a flat one covers its hull. */
static void test_inverted_and_flat(void)
{
    st_tetmesh *m = cube5(0, 1);
    /* Invert the corner tet at vertex 0: swap two of its corners. */
    uint32_t *t = m->tets;
    uint32_t x = t[1];
    t[1] = t[2];
    t[2] = x;
    TAP_CHECK(st_orient3d(m->xyz + 3 * t[0], m->xyz + 3 * t[1], m->xyz + 3 * t[2],
                          m->xyz + 3 * t[3]) > 0, "tet 0 is now inverted");
    st_locator *l = NULL;
    st_error err = {0};
    TAP_CHECK(st_locator_new(&l, m, &err) == ST_OK, "locator over a mesh with an inverted tet");
    const double p[3] = {0.1, 0.1, 0.1}; /* inside the corner tet at 0 only */
    st_point_loc loc;
    TAP_CHECK(st_locator_find(l, p, &loc) == 0 && loc == ST_INSIDE,
              "a point in the inverted tet is found in it");
    st_soup *s = st_soup_new();
    const double q0[3] = {0.1, 0.1, 0.1}, q1[3] = {0.15, 0.1, 0.1}, q2[3] = {0.1, 0.15, 0.1};
    add_tri(s, q0, q1, q2, 0);
    st_enclosure e;
    TAP_CHECK(st_enclosure_compute(&e, m, s, NULL, NULL, NULL, &err) == ST_OK &&
              e.vertices_inside == 3 && e.encloses,
              "the inverted tet counts as covering its points");
    st_locator_free(l);
    st_tetmesh_free(m);

    /* A mesh of one flat tet (a unit square in z = 0). */
    m = st_tetmesh_new();
    add_point(m, 0, 0, 0);
    add_point(m, 1, 0, 0);
    add_point(m, 0, 1, 0);
    add_point(m, 1, 1, 0);
    st_tetmesh_add_tet(m, 0, 1, 2, 3, NULL);
    TAP_CHECK(st_locator_new(&l, m, &err) == ST_OK, "locator over a flat tet");
    const double on[3] = {0.9, 0.9, 0}, off[3] = {0.9, 0.9, 1e-300};
    TAP_CHECK(st_locator_find(l, on, &loc) == 0 && loc == ST_ON_BOUNDARY &&
              st_locator_find(l, off, &loc) == -1 && loc == ST_OUTSIDE,
              "flat tet: its square, on the boundary; 1e-300 above it: nowhere");
    st_locator_free(l);
    st_tetmesh_free(m);
    st_soup_free(s);
}

static void test_empty_mesh(void)
{
    st_tetmesh *m = st_tetmesh_new();
    st_soup *s = st_soup_new();
    add_sphere(s, 1.0, 2.0);
    st_soup_add_vertex(s, 9, 9, 9, NULL); /* unused */
    unsigned char *vin = malloc(s->nverts);
    st_enclosure e;
    st_error err = {0};
    TAP_CHECK(st_enclosure_compute(&e, m, s, NULL, vin, NULL, &err) == ST_OK &&
              e.vertices == s->nverts - 1 && e.vertices_inside == 0 && !e.encloses &&
              e.boundary_faces == 0 && vin[s->nverts - 1] == 2 && vin[0] == 0,
              "a mesh without tets encloses nothing; unused vertices marked 2");
    free(vin);
    st_soup_free(s);
    st_tetmesh_free(m);
}

/* Locator = brute force (lowest index among all tets containing p), on a
 * conforming lattice, with points on faces, edges and vertices. */
static void test_locator_brute_force(void)
{
    const double o[3] = {0, 0, 0};
    st_tetmesh *m = kuhn_lattice(o, 1.0, 4, 3, 5);
    st_locator *l = NULL;
    st_error err = {0};
    TAP_CHECK(st_locator_new(&l, m, &err) == ST_OK, "locator over %zu tets", m->ntets);
    int bad = 0, found = 0, onb = 0;
    for (int it = 0; it < 20000; it++) {
        double p[3];
        for (int k = 0; k < 3; k++) {
            double n = k == 0 ? 4 : k == 1 ? 3 : 5;
            /* a quarter of the points on lattice planes, some beyond */
            p[k] = (it & 3) == 0 ? floor(rng_unif(-1, 2 * n + 2)) * 0.5
                                 : rng_unif(-0.5, n + 0.5);
        }
        st_point_loc loc;
        int64_t r = st_locator_find(l, p, &loc);
        int64_t want = -1;
        st_point_loc wl = ST_OUTSIDE;
        for (size_t t = 0; t < m->ntets && want < 0; t++) {
            const uint32_t *q = m->tets + 4 * t;
            wl = st_point_in_tet(p, m->xyz + 3 * q[0], m->xyz + 3 * q[1], m->xyz + 3 * q[2],
                                 m->xyz + 3 * q[3]);
            if (wl != ST_OUTSIDE)
                want = (int64_t)t;
        }
        if (want < 0)
            wl = ST_OUTSIDE;
        bad += r != want || loc != wl;
        found += r >= 0;
        onb += loc == ST_ON_BOUNDARY;
    }
    TAP_CHECK(bad == 0 && found > 5000 && onb > 1000,
              "locator = brute-force lowest-index tet (%d found, %d on a face, %d wrong)",
              found, onb, bad);
    st_locator_free(l);
    st_tetmesh_free(m);
}

/* A sphere of about 70K triangles (not welded: each triangle has its own
 * three vertices, as soups come). */
static st_soup *big_sphere(void)
{
    st_soup *s = st_soup_new();
    const int nu = 256, nv = 140;
    for (int i = 0; i < nv; i++)
        for (int j = 0; j < nu; j++) {
            double p[4][3];
            for (int c = 0; c < 4; c++) {
                int ii = i + (c >= 2), jj = j + (c == 1 || c == 2);
                double th = M_PI * ii / nv, ph = 2 * M_PI * jj / nu;
                double r = 1.0 + 0.05 * sin(7 * th) * cos(5 * ph);
                p[c][0] = r * sin(th) * cos(ph);
                p[c][1] = r * sin(th) * sin(ph);
                p[c][2] = r * cos(th);
            }
            add_tri(s, p[0], p[1], p[2], 0);
            add_tri(s, p[0], p[2], p[3], 0);
        }
    return s;
}

/* The vertex flags where big tets hold whole BVH subtrees (enclose.c
 * marks those vertices without a per-vertex test): the same as a
 * brute-force test of every vertex against every tet, with the wavy
 * sphere (radius 0.95..1.05) in a lattice of 0.6-wide cubes with every
 * third tet left out, so that subtrees are held, cut and missed. */
static void test_subtree_flags_brute_force(void)
{
    st_soup *s = big_sphere();
    const double o[3] = {-1.2, -1.2, -1.2};
    st_tetmesh *full = kuhn_lattice(o, 0.6, 4, 4, 4), *m = st_tetmesh_new();
    for (size_t i = 0; i < full->npoints; i++)
        st_tetmesh_add_point(m, full->xyz + 3 * i, NULL);
    for (size_t t = 0; t < full->ntets; t++)
        if (t % 3 != 0)
            st_tetmesh_add_tet(m, full->tets[4 * t], full->tets[4 * t + 1],
                               full->tets[4 * t + 2], full->tets[4 * t + 3], NULL);
    st_error err = {0};
    unsigned char *vin = malloc(s->nverts);
    st_enclosure e;
    TAP_CHECK(vin && st_enclosure_compute(&e, m, s, NULL, vin, NULL, &err) == ST_OK,
              "enclosure of %zu triangles by %zu tets", s->ntris, m->ntets);
    size_t bad = 0, in = 0;
    for (size_t i = 0; i < s->nverts; i++) {
        int want = 0;
        for (size_t t = 0; t < m->ntets && !want; t++) {
            const uint32_t *q = m->tets + 4 * t;
            want = st_point_in_tet(s->xyz + 3 * i, m->xyz + 3 * q[0], m->xyz + 3 * q[1],
                                   m->xyz + 3 * q[2], m->xyz + 3 * q[3]) != ST_OUTSIDE;
        }
        bad += vin[i] != want;
        in += (size_t)want;
    }
    TAP_CHECK(bad == 0 && in == e.vertices_inside && in > s->nverts / 2 && in < s->nverts,
              "flags = brute force (%zu of %zu inside, %zu wrong)", in, s->nverts, bad);
    free(vin);
    st_tetmesh_free(full);
    st_tetmesh_free(m);
    st_soup_free(s);
}

static void test_threads_and_speed(void)
{
    st_soup *s = big_sphere();
    /* 8 x 8 x 8 cubes x 6 = 3072 tets over [-1.2, 1.2]^2 x [-0.6, 1.8]: the
     * bottom of the sphere sticks out. */
    const double o[3] = {-1.2, -1.2, -0.6};
    st_tetmesh *m = kuhn_lattice(o, 0.3, 8, 8, 8);
    st_error err = {0};
    st_bvh *bvh = NULL;
    double t0 = now();
    TAP_CHECK(st_bvh_build(&bvh, s, &err) == ST_OK, "BVH over %zu triangles", s->ntris);
    double t1 = now();
    unsigned char *v1 = malloc(s->nverts), *v2 = malloc(s->nverts);
    unsigned char *c1 = malloc(s->ntris), *c2 = malloc(s->ntris);
    st_enclosure e1, e2;
    int nthreads = omp_get_max_threads();
    omp_set_num_threads(1);
    double t2 = now();
    st_status r1 = st_enclosure_compute(&e1, m, s, bvh, v1, c1, &err);
    double t3 = now();
    omp_set_num_threads(nthreads > 1 ? nthreads : 2);
    double t4 = now();
    st_status r2 = st_enclosure_compute(&e2, m, s, bvh, v2, c2, &err);
    double t5 = now();
    omp_set_num_threads(nthreads);
    TAP_CHECK(r1 == ST_OK && r2 == ST_OK && memcmp(v1, v2, s->nverts) == 0 &&
              memcmp(c1, c2, s->ntris) == 0 && e1.vertices_inside == e2.vertices_inside &&
              e1.crossing_triangles == e2.crossing_triangles,
              "same flags and counts on 1 and %d threads", nthreads > 1 ? nthreads : 2);
    /* Known answers: a vertex is inside iff in the box (z >= -0.6 here;
     * x, y within 1.2 always hold, |x| <= 1.05); a triangle crosses iff it
     * meets the plane z = -0.6 (bounding-box test is exact for that: the
     * triangle is a convex combination of its vertices). */
    size_t want_in = 0, want_cross = 0;
    for (size_t i = 0; i < s->nverts; i++)
        want_in += s->xyz[3 * i + 2] >= -0.6;
    for (size_t t = 0; t < s->ntris; t++) {
        double zl = INFINITY, zh = -INFINITY;
        for (int k = 0; k < 3; k++) {
            double z = s->xyz[3 * (size_t)s->tris[3 * t + (size_t)k] + 2];
            zl = fmin(zl, z);
            zh = fmax(zh, z);
        }
        want_cross += zl <= -0.6 && zh >= -0.6;
    }
    TAP_CHECK(e1.vertices_inside == want_in && e1.crossing_triangles == want_cross &&
              want_cross > 0 && e1.boundary_faces == 6 * 8 * 8 * 2,
              "sphere cut by the mesh bottom: %zu of %zu vertices inside, %zu crossing "
              "(expected %zu, %zu), %zu boundary faces",
              e1.vertices_inside, e1.vertices, e1.crossing_triangles, want_in, want_cross,
              e1.boundary_faces);
    TAP_NOTE("enclosure of %zu triangles (%zu vertices) by %zu tets: BVH build %.3f s, "
             "1 thread %.3f s, %d threads %.3f s (wall, shared machine)",
             s->ntris, s->nverts, m->ntets, t1 - t0, t3 - t2, nthreads > 1 ? nthreads : 2,
             t5 - t4);
    /* Locator speed */
    st_locator *l = NULL;
    st_locator_new(&l, m, &err);
    const int nq = 200000;
    size_t hits = 0;
    double t6 = now();
    for (int i = 0; i < nq; i++) {
        double p[3] = {rng_unif(-1.2, 1.2), rng_unif(-1.2, 1.2), rng_unif(-0.6, 1.8)};
        hits += st_locator_find(l, p, NULL) >= 0;
    }
    double t7 = now();
    TAP_CHECK(hits == (size_t)nq, "every point of the lattice box is located");
    TAP_NOTE("locator: %.2f M queries/s over %zu tets", nq / (t7 - t6) / 1e6, m->ntets);
    st_locator_free(l);
    free(v1);
    free(v2);
    free(c1);
    free(c2);
    st_bvh_free(bvh);
    st_tetmesh_free(m);
    st_soup_free(s);
}

/* ---- float32 ------------------------------------------------------------ */

static void round_nearest(st_tetmesh *m)
{
    for (size_t i = 0; i < 3 * m->npoints; i++)
        m->xyz[i] = (double)(float)m->xyz[i];
}

/* The points through float and back, as a float32 file holds them: a
 * new mesh whose enclosure of s is counted again. */
static int encloses_as_floats(const st_tetmesh *m, const st_soup *s)
{
    st_tetmesh *c = NULL;
    if (st_tetmesh_copy(&c, m, NULL))
        return 0;
    float *f = malloc(3 * m->npoints * sizeof *f);
    for (size_t i = 0; i < 3 * m->npoints; i++)
        f[i] = (float)m->xyz[i];
    for (size_t i = 0; i < 3 * m->npoints; i++)
        c->xyz[i] = (double)f[i];
    free(f);
    size_t out = 1, cross = 1;
    st_enclosure_count(c, s, NULL, &out, &cross, NULL);
    st_tetmesh_free(c);
    return out == 0 && cross == 0;
}

static size_t not_positive(const st_tetmesh *m)
{
    size_t n = 0;
    for (size_t t = 0; t < m->ntets; t++) {
        const uint32_t *q = m->tets + 4 * t;
        n += st_orient3d(m->xyz + 3 * q[0], m->xyz + 3 * q[1], m->xyz + 3 * q[2],
                         m->xyz + 3 * q[3]) >= 0;
    }
    return n;
}

/* An axis-aligned face x = hi a quarter of a float ulp above the float
 * 20.5 (ulp 2^-19 at 20), and an input vertex 0.1 ulp above 20.5: inside
 * in double, outside once hi goes to its nearest float 20.5; the rounding
 * outward takes hi to 20.5 + 1 ulp and keeps it. */
static void test_float32_face(void)
{
    const double ulp = 0x1p-19, f0 = 20.5, hi = f0 + 0.25 * ulp;
    st_tetmesh *m = cube5(18.25, hi);
    st_soup *s = st_soup_new();
    const double v = f0 + 0.1 * ulp;
    st_soup_add_vertex(s, v, 19.0, 19.5, NULL);
    st_soup_add_vertex(s, 19.0, 19.25, 19.5, NULL);
    st_soup_add_vertex(s, 19.0, 19.0, 19.875, NULL);
    st_soup_add_triangle(s, 0, 1, 2, NULL);
    size_t out = 9, cross = 9;
    st_enclosure_count(m, s, NULL, &out, &cross, NULL);
    TAP_CHECK(out == 0 && cross == 0, "float32 face: the double mesh encloses the vertex "
              "0.15 float ulp inside its face");
    st_tetmesh *n = NULL;
    st_tetmesh_copy(&n, m, NULL);
    round_nearest(n);
    st_enclosure_count(n, s, NULL, &out, &cross, NULL);
    TAP_CHECK(out == 1, "float32 face: rounded to nearest, the vertex is outside (%zu)", out);
    st_tetmesh_free(n);

    st_float32_stats fs;
    st_status rc = st_enclosure_round_float32(m, s, NULL, &fs, NULL);
    TAP_CHECK(rc == ST_OK && fs.encloses && fs.rounds == 1 && fs.inverted == 0,
              "float32 face: rounded outward it encloses, exactly, at the first check "
              "(rc %d, encloses %d, rounds %d)", (int)rc, fs.encloses, fs.rounds);
    TAP_CHECK(st_points_are_float32(m->xyz, m->npoints), "float32 face: every coordinate "
              "is a float");
    TAP_CHECK(m->xyz[3 * 1] == f0 + ulp && m->xyz[0] == 18.25,
              "float32 face: the face went one ulp out (%.17g), the far side stayed (%.17g)",
              m->xyz[3], m->xyz[0]);
    TAP_CHECK(encloses_as_floats(m, s), "float32 face: through float and back, it encloses");
    TAP_CHECK(fs.boundary_points == 8 && fs.points_moved == 7 && fs.input_not_float32 == 1,
              "float32 face: 8 boundary points, 7 moved (those with a coordinate hi), 1 "
              "input vertex not a float "
              "(%zu, %zu, %zu)", fs.boundary_points, fs.points_moved, fs.input_not_float32);

    /* Already floats and enclosing: nothing moves. */
    double before[24];
    memcpy(before, m->xyz, sizeof before);
    rc = st_enclosure_round_float32(m, s, NULL, &fs, NULL);
    TAP_CHECK(rc == ST_OK && fs.encloses && fs.rounds == 1 && fs.points_moved == 0 &&
              memcmp(before, m->xyz, sizeof before) == 0,
              "float32: a float mesh that encloses is left as it is");
    st_tetmesh_free(m);

    /* Past the float range: refused, the mesh unchanged. */
    m = cube5(0.0, 1e39);
    memcpy(before, m->xyz, sizeof before);
    rc = st_enclosure_round_float32(m, s, NULL, &fs, NULL);
    TAP_CHECK(rc == ST_ELIMIT && memcmp(before, m->xyz, sizeof before) == 0,
              "float32: a coordinate past FLT_MAX is refused (ST_ELIMIT), nothing changed");
    st_tetmesh_free(m);

    /* A soup the mesh never enclosed: no error, not enclosing, bounded. */
    m = cube5(18.25, 19.0);
    rc = st_enclosure_round_float32(m, s, NULL, &fs, NULL);
    TAP_CHECK(rc == ST_OK && !fs.encloses && fs.verts_outside >= 1 &&
              fs.rounds >= 1 && fs.rounds <= ST_FLOAT32_MAX_ROUNDS,
              "float32: a soup outside from the start is reported, not an error "
              "(rounds %d, %zu outside)", fs.rounds, fs.verts_outside);
    st_tetmesh_free(m);
    st_soup_free(s);
}

/* A rotated lattice near (20, 21, 19), not in floats, and 400 input
 * vertices each 0.05..0.45 float ulp inside a random boundary face
 * (each on a small triangle reaching inward): plain rounding to nearest
 * loses some of them, the outward rounding none, and no tet inverts. */
static void test_float32_rotated(void)
{
    const double o[3] = {0, 0, 0};
    st_tetmesh *m = kuhn_lattice(o, 1.0, 3, 3, 3);
    const double ax[3] = {0.48, -0.6, 0.64};   /* unit */
    const double ang = 0.7, c = cos(ang), sn = sin(ang), C = 1 - c;
    const double R[3][3] = {
        {c + ax[0] * ax[0] * C, ax[0] * ax[1] * C - ax[2] * sn, ax[0] * ax[2] * C + ax[1] * sn},
        {ax[1] * ax[0] * C + ax[2] * sn, c + ax[1] * ax[1] * C, ax[1] * ax[2] * C - ax[0] * sn},
        {ax[2] * ax[0] * C - ax[1] * sn, ax[2] * ax[1] * C + ax[0] * sn, c + ax[2] * ax[2] * C}};
    const double shift[3] = {20.0 + 1e-9, 21.0 - 3e-9, 19.0 + 7e-10};
    for (size_t i = 0; i < m->npoints; i++) {
        double *p = m->xyz + 3 * i, q[3];
        for (int a = 0; a < 3; a++)
            q[a] = R[a][0] * (p[0] - 1.5) + R[a][1] * (p[1] - 1.5) + R[a][2] * (p[2] - 1.5) +
                   shift[a];
        memcpy(p, q, sizeof q);
    }
    TAP_CHECK(not_positive(m) == 0, "float32 rotated: the lattice's tets are positive");
    uint32_t *faces = NULL;
    size_t nf = 0;
    st_tetmesh_boundary(m, &faces, NULL, &nf, NULL);
    st_soup *s = st_soup_new();
    const double ulp = 0x1p-19;   /* of floats in [16, 32) */
    for (int k = 0; k < 400; k++) {
        const uint32_t *q = faces + 3 * (size_t)(rng_next() % nf);
        const double *a = m->xyz + 3 * q[0], *b = m->xyz + 3 * q[1], *d = m->xyz + 3 * q[2];
        double u = rng_unif(0.05, 1), v = rng_unif(0.05, 1), w = rng_unif(0.05, 1);
        double sum = u + v + w, n[3], e1[3], e2[3], p[3];
        for (int i = 0; i < 3; i++) {
            e1[i] = b[i] - a[i];
            e2[i] = d[i] - a[i];
        }
        n[0] = e1[1] * e2[2] - e1[2] * e2[1];
        n[1] = e1[2] * e2[0] - e1[0] * e2[2];
        n[2] = e1[0] * e2[1] - e1[1] * e2[0];
        double len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        double depth = rng_unif(0.05, 0.45) * ulp;
        for (int i = 0; i < 3; i++)
            p[i] = (u * a[i] + v * b[i] + w * d[i]) / sum - depth * n[i] / len;
        uint32_t base = (uint32_t)s->nverts;
        st_soup_add_vertex(s, p[0], p[1], p[2], NULL);
        st_soup_add_vertex(s, p[0] - 0.2 * n[0] / len, p[1] - 0.2 * n[1] / len,
                           p[2] - 0.2 * n[2] / len, NULL);
        double g[3];   /* toward the face's centroid: over the face */
        for (int i = 0; i < 3; i++)
            g[i] = 0.3 * ((a[i] + b[i] + d[i]) / 3 - p[i]);
        st_soup_add_vertex(s, p[0] - 0.2 * n[0] / len + g[0], p[1] - 0.2 * n[1] / len + g[1],
                           p[2] - 0.2 * n[2] / len + g[2], NULL);
        st_soup_add_triangle(s, base, base + 1, base + 2, NULL);
    }
    free(faces);
    size_t out = 9, cross = 9;
    st_enclosure_count(m, s, NULL, &out, &cross, NULL);
    TAP_CHECK(out == 0 && cross == 0, "float32 rotated: the double mesh encloses the "
              "400 near-boundary triangles (%zu, %zu)", out, cross);
    st_tetmesh *n = NULL;
    st_tetmesh_copy(&n, m, NULL);
    round_nearest(n);
    st_enclosure_count(n, s, NULL, &out, &cross, NULL);
    TAP_CHECK(out > 0, "float32 rotated: rounded to nearest, %zu input vertices fall "
              "outside (%zu triangles crossing)", out, cross);
    st_tetmesh_free(n);
    st_float32_stats fs;
    st_status rc = st_enclosure_round_float32(m, s, NULL, &fs, NULL);
    TAP_CHECK(rc == ST_OK && fs.encloses && fs.inverted == 0 && not_positive(m) == 0,
              "float32 rotated: rounded outward it encloses, exactly, no tet inverted "
              "(%d checks, %zu pushed up to %u ulps, largest move %.3g)", fs.rounds,
              fs.pushed, fs.max_push, fs.max_move);
    TAP_CHECK(st_points_are_float32(m->xyz, m->npoints) && encloses_as_floats(m, s),
              "float32 rotated: every coordinate a float; through float and back it "
              "encloses");
    TAP_CHECK(fs.max_move < 4 * ulp, "float32 rotated: no point moved 4 ulps (%.3g ulp)",
              fs.max_move / ulp);
    st_tetmesh_free(m);
    st_soup_free(s);
}

/* A flat tet (height 1e-3 over a base of side 1, coordinates near 20 and
 * about half an ulp from floats) with input vertices 0.1..0.4 ulp inside each of its faces near
 * every corner: at a corner the faces' outward normals point nearly
 * opposite ways, so no float around it is outward for all of them and the
 * first rounding may fail; whatever the rounds give, what is reported is
 * what an independent exact count finds on the mesh left behind. */
static void test_float32_knife(void)
{
    st_tetmesh *m = st_tetmesh_new();
    const double u = 0x1p-19;   /* heights mid-way between floats */
    add_point(m, 20.0 + 0.3 * u, 20.0 + 0.6 * u, 20.0 + 0.5 * u);
    add_point(m, 21.0 + 0.4 * u, 20.1 + 0.2 * u, 20.0 + 0.45 * u);
    add_point(m, 20.3 - 0.5 * u, 21.0 + 0.5 * u, 20.0 + 0.55 * u);
    add_point(m, 20.4 + 0.5 * u, 20.4 - 0.5 * u, 20.001 + 0.5 * u);
    add_tet_pos(m, 0, 1, 2, 3);
    uint32_t *faces = NULL;
    size_t nf = 0;
    st_tetmesh_boundary(m, &faces, NULL, &nf, NULL);
    st_soup *s = st_soup_new();
    const double ulp = 0x1p-19;
    double cen[3] = {0, 0, 0};
    for (int k = 0; k < 4; k++)
        for (int a = 0; a < 3; a++)
            cen[a] += m->xyz[3 * k + a] / 4;
    for (size_t f = 0; f < nf; f++)
        for (int c = 0; c < 3; c++) {
            const uint32_t *q = faces + 3 * f;
            const double *a = m->xyz + 3 * q[c], *b = m->xyz + 3 * q[(c + 1) % 3],
                         *d = m->xyz + 3 * q[(c + 2) % 3];
            double e1[3], e2[3], n[3], p[3];
            for (int i = 0; i < 3; i++) {
                e1[i] = b[i] - a[i];
                e2[i] = d[i] - a[i];
            }
            n[0] = e1[1] * e2[2] - e1[2] * e2[1];
            n[1] = e1[2] * e2[0] - e1[0] * e2[2];
            n[2] = e1[0] * e2[1] - e1[1] * e2[0];
            double len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
            double depth = (0.1 + 0.1 * (double)c) * ulp;
            for (int i = 0; i < 3; i++)
                p[i] = 0.9 * a[i] + 0.05 * b[i] + 0.05 * d[i] - depth * n[i] / len;
            uint32_t base = (uint32_t)s->nverts;
            st_soup_add_vertex(s, p[0], p[1], p[2], NULL);
            st_soup_add_vertex(s, 0.5 * (p[0] + cen[0]), 0.5 * (p[1] + cen[1]),
                               0.5 * (p[2] + cen[2]), NULL);
            st_soup_add_vertex(s, cen[0], cen[1], cen[2], NULL);
            st_soup_add_triangle(s, base, base + 1, base + 2, NULL);
        }
    free(faces);
    size_t out = 9, cross = 9;
    st_enclosure_count(m, s, NULL, &out, &cross, NULL);
    TAP_CHECK(out == 0 && cross == 0, "float32 knife: the double tet encloses its 12 "
              "near-face triangles (%zu, %zu)", out, cross);
    st_float32_stats fs;
    st_status rc = st_enclosure_round_float32(m, s, NULL, &fs, NULL);
    st_enclosure_count(m, s, NULL, &out, &cross, NULL);
    size_t inv = not_positive(m);
    TAP_CHECK(rc == ST_OK && fs.rounds >= 1 && fs.rounds <= ST_FLOAT32_MAX_ROUNDS &&
              st_points_are_float32(m->xyz, m->npoints),
              "float32 knife: rounded to floats in %d checks (%zu pushed, up to %u ulps)",
              fs.rounds, fs.pushed, fs.max_push);
    TAP_CHECK(fs.verts_outside == out && fs.tris_crossing == cross && fs.inverted == inv &&
              fs.encloses == (out == 0 && cross == 0 && inv == 0),
              "float32 knife: the report is the result's (%s: %zu outside, %zu crossing, "
              "%zu inverted)", fs.encloses ? "encloses" : "does not enclose", out, cross,
              inv);
    st_tetmesh_free(m);
    st_soup_free(s);
}

int main(int argc, char **argv)
{
    static const tap_test tests[] = {TAP_TEST(cube_encloses_small_soup),
                                     TAP_TEST(soup_sticking_out),
                                     TAP_TEST(touching_boundary),
                                     TAP_TEST(inverted_and_flat),
                                     TAP_TEST(empty_mesh),
                                     TAP_TEST(locator_brute_force),
                                     TAP_TEST(subtree_flags_brute_force),
                                     TAP_TEST(threads_and_speed),
                                     TAP_TEST(float32_face),
                                     TAP_TEST(float32_rotated),
                                     TAP_TEST(float32_knife), {0}};
    return tap_main(argc, argv, tests);
}
