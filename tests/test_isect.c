/* test_isect.c - exact intersection tests: hand-made cases for each branch
 * (touching, coplanar, degenerate, the thin triangle through a tet), random
 * comparisons with exact rational references and between the tests, and
 * the speed of each. Also st_bvh_query_box. */
#include "souptet/bvh.h"
#include "souptet/isect.h"
#include "souptet/pred.h"
#include "souptet/soup.h"
#include "tap.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define SPLITMIX_SEED 0x1234567887654321ULL
#include "splitmix.h"

static void rand_pt(double p[3], int64_t r)
{
    for (int k = 0; k < 3; k++)
        p[k] = (double)rng_int(r);
}

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts); /* CPU time: the machine is shared */
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* ---- exact integer references ---------------------------------------------- */

typedef __int128 i128;

static void isub(i128 r[3], const double a[3], const double b[3])
{
    for (int k = 0; k < 3; k++)
        r[k] = (i128)a[k] - (i128)b[k];
}

static void icross(i128 r[3], const i128 a[3], const i128 b[3])
{
    r[0] = a[1] * b[2] - a[2] * b[1];
    r[1] = a[2] * b[0] - a[0] * b[2];
    r[2] = a[0] * b[1] - a[1] * b[0];
}

static i128 idot(const i128 a[3], const i128 b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static i128 idotd(const i128 a[3], const double b[3])
{
    return a[0] * (i128)b[0] + a[1] * (i128)b[1] + a[2] * (i128)b[2];
}

typedef struct frac { i128 n, d; } frac; /* d > 0 */

static int frac_le(frac a, frac b)
{
    return a.n * b.d <= b.n * a.d;
}

/* The interval that the line direction D cuts from closed triangle T where
 * its vertices have plane values dv (not all zero, not all one strict
 * sign): the projections on D of the vertices on the plane and of the
 * crossing points of the edges with strictly opposite signs. */
static void cut_interval(const double *const T[3], const i128 dv[3],
                         const i128 D[3], frac *lo, frac *hi)
{
    int first = 1;
    for (int i = 0; i < 3; i++) {
        frac f[2];
        int nf = 0;
        if (dv[i] == 0)
            f[nf++] = (frac){idotd(D, T[i]), 1};
        int j = (i + 1) % 3;
        if ((dv[i] > 0 && dv[j] < 0) || (dv[i] < 0 && dv[j] > 0)) {
            i128 n = dv[i] * idotd(D, T[j]) - dv[j] * idotd(D, T[i]);
            i128 d = dv[i] - dv[j];
            if (d < 0) {
                n = -n;
                d = -d;
            }
            f[nf++] = (frac){n, d};
        }
        for (int k = 0; k < nf; k++) {
            if (first || frac_le(f[k], *lo))
                *lo = f[k];
            if (first || frac_le(*hi, f[k]))
                *hi = f[k];
            first = 0;
        }
    }
}

/* Exact reference for two proper triangles with integer coordinates: 1/0,
 * or -1 when they are coplanar (not handled here). */
static int ref_tri_tri(const double *const A[3], const double *const B[3])
{
    i128 e1[3], e2[3], nA[3], nB[3], D[3], dA[3], dB[3];
    isub(e1, A[1], A[0]);
    isub(e2, A[2], A[0]);
    icross(nA, e1, e2);
    isub(e1, B[1], B[0]);
    isub(e2, B[2], B[0]);
    icross(nB, e1, e2);
    for (int j = 0; j < 3; j++) {
        i128 t[3];
        isub(t, B[j], A[0]);
        dB[j] = idot(nA, t);
        isub(t, A[j], B[0]);
        dA[j] = idot(nB, t);
    }
    if ((dB[0] > 0 && dB[1] > 0 && dB[2] > 0) || (dB[0] < 0 && dB[1] < 0 && dB[2] < 0))
        return 0;
    if ((dA[0] > 0 && dA[1] > 0 && dA[2] > 0) || (dA[0] < 0 && dA[1] < 0 && dA[2] < 0))
        return 0;
    if (dB[0] == 0 && dB[1] == 0 && dB[2] == 0)
        return -1;
    icross(D, nA, nB);
    frac la, ha, lb, hb;
    cut_interval(A, dA, D, &la, &ha);
    cut_interval(B, dB, D, &lb, &hb);
    frac lo = frac_le(la, lb) ? lb : la, hi = frac_le(ha, hb) ? ha : hb;
    return frac_le(lo, hi);
}

/* 2-D separating axis reference for two proper triangles in the (x, y)
 * plane: disjoint iff some edge normal separates them (strictly). */
static int ref_tri_tri_2d(const double *const A[3], const double *const B[3])
{
    const double *const *P[2] = {A, B};
    for (int w = 0; w < 2; w++)
        for (int i = 0; i < 3; i++) {
            const double *p = P[w][i], *q = P[w][(i + 1) % 3];
            i128 nx = (i128)(q[1] - p[1]), ny = -(i128)(q[0] - p[0]);
            i128 lo[2], hi[2];
            for (int t = 0; t < 2; t++)
                for (int j = 0; j < 3; j++) {
                    i128 v = nx * (i128)P[t][j][0] + ny * (i128)P[t][j][1];
                    if (j == 0 || v < lo[t])
                        lo[t] = v;
                    if (j == 0 || v > hi[t])
                        hi[t] = v;
                }
            if (lo[0] > hi[1] || lo[1] > hi[0])
                return 0;
        }
    return 1;
}

/* Barycentric location of p in a proper tet, from __int128 volumes. */
static st_point_loc ref_point_in_tet(const double *p, const double *const t[4])
{
    i128 vol[5];
    const double *q[4];
    for (int i = 0; i <= 4; i++) {
        for (int j = 0; j < 4; j++)
            q[j] = (i < 4 && j == i) ? p : t[j];
        i128 a[3], b[3], c[3], n[3];
        isub(a, q[1], q[0]);
        isub(b, q[2], q[0]);
        isub(c, q[3], q[0]);
        icross(n, a, b);
        vol[i] = idot(n, c);
    }
    int zero = 0;
    for (int i = 0; i < 4; i++) {
        if ((vol[i] > 0 && vol[4] < 0) || (vol[i] < 0 && vol[4] > 0))
            return ST_OUTSIDE;
        zero |= vol[i] == 0;
    }
    return zero ? ST_ON_BOUNDARY : ST_INSIDE;
}

/* ---- point in tet ------------------------------------------------------------ */

static void test_point_in_tet(void)
{
    const double t0[3] = {0, 0, 0}, t1[3] = {1, 0, 0}, t2[3] = {0, 1, 0},
                 t3[3] = {0, 0, 1};
    const double in[3] = {0.1, 0.1, 0.1}, face[3] = {0.25, 0.25, 0.5},
                 edge[3] = {0.5, 0, 0.5}, out[3] = {0.5, 0.5, 0.5},
                 below[3] = {0.1, 0.1, -1e-300};
    TAP_CHECK(st_point_in_tet(in, t0, t1, t2, t3) == ST_INSIDE, "point in tet: interior");
    TAP_CHECK(st_point_in_tet(face, t0, t1, t2, t3) == ST_ON_BOUNDARY,
              "point in tet: on the slanted face");
    TAP_CHECK(st_point_in_tet(edge, t0, t1, t2, t3) == ST_ON_BOUNDARY, "point in tet: on an edge");
    TAP_CHECK(st_point_in_tet(t2, t0, t1, t2, t3) == ST_ON_BOUNDARY, "point in tet: at a vertex");
    TAP_CHECK(st_point_in_tet(out, t0, t1, t2, t3) == ST_OUTSIDE,
              "point in tet: just beyond the slanted face");
    TAP_CHECK(st_point_in_tet(below, t0, t1, t2, t3) == ST_OUTSIDE,
              "point in tet: 1e-300 below a face is outside");
    TAP_CHECK(st_point_in_tet(in, t0, t2, t1, t3) == ST_INSIDE &&
              st_point_in_tet(face, t1, t0, t2, t3) == ST_ON_BOUNDARY &&
              st_point_in_tet(out, t0, t2, t1, t3) == ST_OUTSIDE,
              "point in tet: an inverted tet covers the same points");
    /* Flat tets: the convex hull of four coplanar points. */
    const double f0[3] = {0, 0, 0}, f1[3] = {2, 0, 0}, f2[3] = {0, 2, 0}, f3[3] = {2, 2, 0};
    const double pin[3] = {1.5, 1.5, 0}, pout[3] = {1, 1, 1e-300}, pfar[3] = {3, 1, 0};
    TAP_CHECK(st_point_in_tet(pin, f0, f1, f2, f3) == ST_ON_BOUNDARY,
              "flat tet: a point of the hull is on its boundary");
    TAP_CHECK(st_point_in_tet(pout, f0, f1, f2, f3) == ST_OUTSIDE &&
              st_point_in_tet(pfar, f0, f1, f2, f3) == ST_OUTSIDE,
              "flat tet: points off the plane or beyond the hull are outside");
    const double l0[3] = {0, 0, 0}, l1[3] = {1, 1, 1}, l2[3] = {2, 2, 2}, l3[3] = {3, 3, 3};
    const double lin[3] = {2.5, 2.5, 2.5}, loff[3] = {2.5, 2.5, 2.4};
    TAP_CHECK(st_point_in_tet(lin, l0, l1, l2, l3) == ST_ON_BOUNDARY &&
              st_point_in_tet(loff, l0, l1, l2, l3) == ST_OUTSIDE,
              "collinear tet: its segment, and only it");
    TAP_CHECK(st_point_in_tet(l1, l1, l1, l1, l1) == ST_ON_BOUNDARY &&
              st_point_in_tet(l2, l1, l1, l1, l1) == ST_OUTSIDE,
              "a tet that is one point");
    /* Random small integers against __int128 barycentrics. */
    int bad = 0, n = 0;
    for (int it = 0; it < 20000; it++) {
        double t[4][3], p[3];
        for (int i = 0; i < 4; i++)
            rand_pt(t[i], 3);
        rand_pt(p, 3);
        const double *tt[4] = {t[0], t[1], t[2], t[3]};
        if (st_sign(st_orient3d(t[0], t[1], t[2], t[3])) == 0)
            continue;
        n++;
        if (st_point_in_tet(p, t[0], t[1], t[2], t[3]) != ref_point_in_tet(p, tt))
            bad++;
    }
    TAP_CHECK(bad == 0 && n > 5000, "point in tet = exact barycentric location "
              "on %d random integer cases (%d wrong)", n, bad);
}

/* ---- point in triangle ---------------------------------------------------------- */

static void test_point_in_tri(void)
{
    /* The triangle on the oblique plane z = x + 2y through (0,0), (4,0), (0,4). */
    const double a[3] = {0, 0, 0}, b[3] = {4, 0, 4}, c[3] = {0, 4, 8};
    const double in[3] = {1, 1, 3}, edge[3] = {2, 2, 6}, out[3] = {3, 2, 7};
    const double off[3] = {1, 1, nextafter(3.0, 4.0)};
    TAP_CHECK(st_point_in_tri(in, a, b, c) && st_point_in_tri(edge, a, b, c) &&
              st_point_in_tri(c, a, b, c) && !st_point_in_tri(out, a, b, c) &&
              !st_point_in_tri(off, a, b, c) && st_point_in_tri(edge, c, b, a),
              "point in triangle: interior, edge, vertex in; beside, one ulp off out");
    const double s0[3] = {0, 0, 0}, s1[3] = {1, 1, 1}, s2[3] = {3, 3, 3};
    const double m[3] = {2, 2, 2}, m2[3] = {2, 2, 2.5}, far[3] = {4, 4, 4};
    TAP_CHECK(st_point_in_tri(m, s0, s1, s2) && !st_point_in_tri(m2, s0, s1, s2) &&
              !st_point_in_tri(far, s0, s1, s2) && st_point_in_tri(m, s1, s2, s0),
              "point in a collinear triangle: on its segment only");
    TAP_CHECK(st_point_in_tri(s1, s1, s1, s1) && !st_point_in_tri(m, s1, s1, s1),
              "point in a one-point triangle");
}

/* ---- segment / triangle ------------------------------------------------------ */

static void test_segment_tri(void)
{
    const double a[3] = {0, 0, 0}, b[3] = {4, 0, 0}, c[3] = {0, 4, 0};
    struct { double p[3], q[3]; int want; const char *what; } cs[] = {
        {{1, 1, -1}, {1, 1, 1}, 1, "crossing the interior"},
        {{0, 0, -1}, {0, 0, 1}, 1, "through a vertex"},
        {{2, 0, -1}, {2, 0, 1}, 1, "through an edge"},
        {{2, 2, -1}, {2, 2, 1}, 1, "through the hypotenuse"},
        {{2.5, 2, -1}, {2.5, 2, 1}, 0, "just past the hypotenuse"},
        {{1, 1, 0}, {1, 1, 1}, 1, "endpoint on the face"},
        {{1, 1, 1e-300}, {1, 1, 1}, 0, "endpoint 1e-300 above the face"},
        {{-1, 1, 0}, {5, 1, 0}, 1, "coplanar, crossing"},
        {{-1, -1, 0}, {-2, 5, 0}, 0, "coplanar, beside"},
        {{-1, 0, 0}, {-3, 0, 0}, 0, "collinear with an edge, beyond"},
        {{-1, 0, 0}, {0, 0, 0}, 1, "collinear with an edge, touching the vertex"},
        {{1, 1, 0}, {2, 1, 0}, 1, "coplanar, inside"},
        {{-2, 3, 0}, {3, -2, 0}, 1, "coplanar, crossing two edges"},
        {{1, 1, 1}, {3, 3, 1}, 0, "parallel above"},
        {{1, 1, 5}, {1, 1, 5}, 0, "a point above"},
        {{1, 1, 0}, {1, 1, 0}, 1, "a point in the face"},
    };
    for (size_t i = 0; i < sizeof cs / sizeof cs[0]; i++)
        TAP_CHECK(st_segment_tri_intersect(cs[i].p, cs[i].q, a, b, c) == cs[i].want &&
                  st_segment_tri_intersect(cs[i].q, cs[i].p, c, a, b) == cs[i].want,
                  "segment-triangle: %s", cs[i].what);
    /* A degenerate triangle (a segment on the x axis) */
    const double d0[3] = {0, 0, 0}, d1[3] = {1, 0, 0}, d2[3] = {3, 0, 0};
    const double p1[3] = {2, -1, 0}, q1[3] = {2, 1, 0}, p2[3] = {2, -1, 1}, q2[3] = {2, 1, 1};
    const double p3[3] = {3, 0, 0}, q3[3] = {5, 0, 0}, p4[3] = {4, 0, 0};
    TAP_CHECK(st_segment_tri_intersect(p1, q1, d0, d1, d2) == 1,
              "segment crosses a collinear triangle in its middle");
    TAP_CHECK(st_segment_tri_intersect(p2, q2, d0, d1, d2) == 0,
              "segment passes over a collinear triangle");
    TAP_CHECK(st_segment_tri_intersect(p3, q3, d0, d1, d2) == 1 &&
              st_segment_tri_intersect(p4, q3, d0, d1, d2) == 0,
              "collinear segment touching / missing a collinear triangle");
}

/* ---- triangle / triangle ----------------------------------------------------- */

typedef struct tt_case { double a[3][3], b[3][3]; int want; const char *what; } tt_case;

static int tt_all_orders(const double a[3][3], const double b[3][3])
{
    /* All 6 x 6 vertex orders and both argument orders must agree. */
    static const int perm[6][3] = {{0,1,2},{1,2,0},{2,0,1},{0,2,1},{2,1,0},{1,0,2}};
    int r = st_tri_tri_intersect(a[0], a[1], a[2], b[0], b[1], b[2]);
    for (int i = 0; i < 6; i++)
        for (int j = 0; j < 6; j++) {
            const int *p = perm[i], *q = perm[j];
            if (st_tri_tri_intersect(a[p[0]], a[p[1]], a[p[2]], b[q[0]], b[q[1]], b[q[2]]) != r ||
                st_tri_tri_intersect(b[q[0]], b[q[1]], b[q[2]], a[p[0]], a[p[1]], a[p[2]]) != r)
                return -1;
        }
    return r;
}

static void test_tri_tri(void)
{
    static const tt_case cs[] = {
        {{{0,0,0},{4,0,0},{0,4,0}}, {{1,1,-1},{1,1,1},{2,2,1}}, 1, "crossing"},
        {{{0,0,0},{4,0,0},{0,4,0}}, {{1,1,1},{1,1,3},{2,2,3}}, 0, "above, disjoint"},
        {{{0,0,0},{4,0,0},{0,4,0}}, {{0,0,0},{-1,-1,1},{-2,0,3}}, 1, "sharing only a vertex"},
        {{{0,0,0},{4,0,0},{0,4,0}}, {{1,1,0},{1,1,3},{2,-1,3}}, 1, "vertex on the face"},
        {{{0,0,0},{4,0,0},{0,4,0}}, {{1,1,1e-300},{1,1,3},{2,-1,3}}, 0, "vertex 1e-300 above the face"},
        {{{0,0,0},{4,0,0},{0,4,0}}, {{2,-1,-1},{2,-1,1},{2,1,0}}, 1, "piercing through an edge"},
        {{{0,0,0},{4,0,0},{0,4,0}}, {{-1,2,-1},{-1,2,1},{-3,2,0}}, 0, "beside, straddling the plane"},
        {{{0,0,0},{4,0,0},{0,4,0}}, {{1,0,0},{3,0,0},{2,0,5}}, 1, "edge on an edge (vertical)"},
        {{{0,0,0},{4,0,0},{0,4,0}}, {{5,0,0},{6,0,0},{5,0,5}}, 0, "collinear edges, apart"},
        {{{0,0,0},{4,0,0},{0,4,0}}, {{4,0,0},{6,0,0},{5,0,5}}, 1, "collinear edges meeting at a vertex"},
        {{{0,0,0},{4,0,0},{0,4,0}}, {{1,1,0},{5,1,0},{1,5,0}}, 1, "coplanar overlapping"},
        {{{0,0,0},{4,0,0},{0,4,0}}, {{4,0,0},{0,4,0},{4,4,0}}, 1, "coplanar sharing an edge"},
        {{{0,0,0},{4,0,0},{0,4,0}}, {{4,0,0},{6,1,0},{5,3,0}}, 1, "coplanar touching at a vertex"},
        {{{0,0,0},{4,0,0},{0,4,0}}, {{2,2,0},{4,4,0},{2,5,0}}, 1, "coplanar, vertex on the other's edge"},
        {{{0,0,0},{4,0,0},{0,4,0}}, {{2.5,2,0},{4,4,0},{2,5,0}}, 0, "coplanar, just apart"},
        {{{0,0,0},{4,0,0},{0,4,0}}, {{1,1,0},{2,1,0},{1,2,0}}, 1, "coplanar, one inside the other"},
        {{{0,0,0},{4,0,0},{0,4,0}}, {{-1,-1,0},{9,-1,0},{-1,9,0}}, 1, "coplanar, containing the other"},
        {{{0,0,0},{4,0,0},{0,4,0}}, {{-1,1,0},{5,1,0},{2,-1,0}}, 1, "coplanar, star of David-like crossing"},
        {{{0,0,0},{4,0,0},{0,4,0}}, {{1,1,0},{2,2,0},{3,3,0}}, 1, "collinear triangle lying in the face"},
        {{{0,0,0},{4,0,0},{0,4,0}}, {{1,1,-1},{1,1,0.5},{1,1,2}}, 1, "collinear triangle piercing the face"},
        {{{0,0,0},{4,0,0},{0,4,0}}, {{3,3,-1},{3,3,0.5},{3,3,2}}, 0, "collinear triangle missing the face"},
        {{{0,0,0},{4,0,0},{0,4,0}}, {{1,1,0},{1,1,0},{1,1,0}}, 1, "a point triangle on the face"},
        {{{0,0,0},{4,0,0},{0,4,0}}, {{1,1,1},{1,1,1},{1,1,1}}, 0, "a point triangle above"},
        {{{0,0,0},{2,0,0},{4,0,0}}, {{1,-1,0},{1,1,0},{1,1,0}}, 1, "two collinear triangles crossing"},
        {{{0,0,0},{2,0,0},{4,0,0}}, {{1,-1,1},{1,1,1},{1,1,1}}, 0, "two collinear triangles skew"},
        {{{1,1,1},{1,1,1},{1,1,1}}, {{1,1,1},{1,1,1},{1,1,1}}, 1, "two equal points"},
    };
    for (size_t i = 0; i < sizeof cs / sizeof cs[0]; i++) {
        int r = tt_all_orders(cs[i].a, cs[i].b);
        TAP_CHECK(r == cs[i].want, "tri-tri: %s (got %d)", cs[i].what, r);
    }

    /* Random non-coplanar integer triangles against the rational interval
     * reference, small coordinates so touching and degenerate contacts are
     * common. */
    int bad = 0, n = 0, hits = 0, sym = 0;
    for (int it = 0; it < 100000; it++) {
        double a[3][3], b[3][3];
        for (int i = 0; i < 3; i++) {
            rand_pt(a[i], 2);
            rand_pt(b[i], 2);
        }
        const double *A[3] = {a[0], a[1], a[2]}, *B[3] = {b[0], b[1], b[2]};
        int degA = 1, degB = 1;
        for (int k = 0; k < 3; k++) {
            degA &= st_orient2d_drop(a[0], a[1], a[2], k) == 0;
            degB &= st_orient2d_drop(b[0], b[1], b[2], k) == 0;
        }
        if (degA || degB)
            continue;
        int ref = ref_tri_tri(A, B);
        if (ref < 0)
            continue;
        n++;
        hits += ref;
        int r = st_tri_tri_intersect(a[0], a[1], a[2], b[0], b[1], b[2]);
        if (r != ref)
            bad++;
        if (st_tri_tri_intersect(b[1], b[2], b[0], a[2], a[1], a[0]) != r)
            sym++;
    }
    TAP_CHECK(bad == 0, "tri-tri = exact rational reference on %d random "
              "non-coplanar integer pairs, %d meeting (%d wrong)", n, hits, bad);
    TAP_CHECK(sym == 0, "tri-tri symmetric under swapping and reordering");

    /* Random coplanar triangles on the oblique plane z = x + 2y against a
     * 2-D separating-axis reference. */
    bad = 0;
    n = 0;
    hits = 0;
    for (int it = 0; it < 50000; it++) {
        double a[3][3], b[3][3];
        for (int i = 0; i < 3; i++) {
            a[i][0] = (double)rng_int(3); a[i][1] = (double)rng_int(3);
            b[i][0] = (double)rng_int(3); b[i][1] = (double)rng_int(3);
            a[i][2] = a[i][0] + 2 * a[i][1];
            b[i][2] = b[i][0] + 2 * b[i][1];
        }
        if (st_orient2d_drop(a[0], a[1], a[2], 2) == 0 ||
            st_orient2d_drop(b[0], b[1], b[2], 2) == 0)
            continue;
        const double *A[3] = {a[0], a[1], a[2]}, *B[3] = {b[0], b[1], b[2]};
        int ref = ref_tri_tri_2d(A, B);
        n++;
        hits += ref;
        if (st_tri_tri_intersect(a[0], a[1], a[2], b[0], b[1], b[2]) != ref)
            bad++;
    }
    TAP_CHECK(bad == 0, "coplanar tri-tri = 2-D separating axes on %d random "
              "pairs, %d meeting (%d wrong)", n, hits, bad);
}

/* ---- triangle / tet ---------------------------------------------------------- */

static void test_tri_tet(void)
{
    const double t0[3] = {0, 0, 0}, t1[3] = {1, 0, 0}, t2[3] = {0, 1, 0}, t3[3] = {0, 0, 1};
    struct { double a[3], b[3], c[3]; int want; const char *what; } cs[] = {
        {{0.1, 0.1, 0.1}, {0.2, 0.1, 0.1}, {0.1, 0.2, 0.1}, 1, "triangle inside"},
        {{-10, -10, 0.2}, {10, -10, 0.2}, {0, 10, 0.2}, 1,
         "thin triangle through the tet, all vertices and edges outside"},
        {{-10, -10, 0.2}, {10, -10, 0.2}, {0, 10, 0.2 + 1e-12}, 1,
         "slightly tilted big triangle through the tet"},
        {{-10, -10, -0.2}, {10, -10, -0.2}, {0, 10, -0.2}, 0, "big triangle below"},
        {{-10, -10, 1}, {10, -10, 1}, {0, 10, 1}, 1, "big triangle touching the apex"},
        {{-10, -10, 1 + 1e-15}, {10, -10, 1 + 1e-15}, {0, 10, 1 + 1e-15}, 0,
         "big triangle just above the apex"},
        {{0.2, 0.2, 0}, {0.3, 0.2, 0}, {0.2, 0.3, 0}, 1, "triangle lying in a face"},
        {{0.2, 0.2, -1}, {0.3, 0.2, -1}, {0.2, 0.3, 0}, 1, "vertex on a face"},
        {{2, 2, 2}, {3, 2, 2}, {2, 3, 2}, 0, "far away"},
        {{0.6, 0.6, -1}, {0.6, 0.6, 1}, {2, 2, 0}, 0, "beside the slanted face"},
        {{0.5, 0.5, -1}, {0.5, 0.5, 1}, {2, 2, 0}, 1, "edge through the slanted edge"},
        {{-1, 0.5, 0.25}, {2, 0.5, 0.25}, {0.5, -3, 0.25}, 1, "edge through the tet"},
    };
    for (size_t i = 0; i < sizeof cs / sizeof cs[0]; i++) {
        int r = st_tri_tet_intersect(cs[i].a, cs[i].b, cs[i].c, t0, t1, t2, t3);
        int r_inv = st_tri_tet_intersect(cs[i].b, cs[i].a, cs[i].c, t1, t0, t2, t3);
        TAP_CHECK(r == cs[i].want && r_inv == r, "tri-tet: %s", cs[i].what);
    }
    /* A flat tet (a square) */
    const double f0[3] = {0, 0, 0}, f1[3] = {1, 0, 0}, f2[3] = {0, 1, 0}, f3[3] = {1, 1, 0};
    const double x0[3] = {0.9, 0.9, -1}, x1[3] = {0.9, 0.9, 1}, x2[3] = {5, 5, 0};
    const double y0[3] = {1.1, 0.9, -1}, y1[3] = {1.1, 0.9, 1}, y2[3] = {5, 5, 0};
    TAP_CHECK(st_tri_tet_intersect(x0, x1, x2, f0, f1, f2, f3) == 1 &&
              st_tri_tet_intersect(y0, y1, y2, f0, f1, f2, f3) == 0,
              "tri-tet: a flat tet is the square it spans");

    /* Dense sampling cannot find a common point the test misses: triangle
     * vertices are multiples of N, so the sample points a + (i (b-a) +
     * j (c-a)) / N are exact points of the triangle. */
    enum { N = 16 };
    int bad = 0, found = 0, tested = 0;
    for (int it = 0; it < 3000; it++) {
        double t[4][3], a[3], b[3], c[3];
        for (int i = 0; i < 4; i++)
            for (int k = 0; k < 3; k++)
                t[i][k] = (double)rng_int(3 * N);
        for (int k = 0; k < 3; k++) {
            a[k] = (double)(N * rng_int(4));
            b[k] = (double)(N * rng_int(4));
            c[k] = (double)(N * rng_int(4));
        }
        int r = st_tri_tet_intersect(a, b, c, t[0], t[1], t[2], t[3]);
        int hit = 0;
        for (int i = 0; i <= N && !hit; i++)
            for (int j = 0; i + j <= N && !hit; j++) {
                double p[3];
                for (int k = 0; k < 3; k++)
                    p[k] = a[k] + (i * (b[k] - a[k]) + j * (c[k] - a[k])) / N;
                hit = st_point_in_tet(p, t[0], t[1], t[2], t[3]) != ST_OUTSIDE;
            }
        tested++;
        found += hit;
        if (hit && !r)
            bad++;
    }
    TAP_CHECK(bad == 0 && found > 100, "tri-tet never misses a common point "
              "found by sampling (%d of %d cases sampled a common point, %d missed)",
              found, tested, bad);
}

/* ---- triangle / box ------------------------------------------------------------- */

/* The box as 5 tets (a corner tet at 0, 3, 5, 6 and the central one). */
static int tri_box_by_tets(const double a[3], const double b[3], const double c[3],
                           const double lo[3], const double hi[3])
{
    double v[8][3];
    for (int i = 0; i < 8; i++)
        for (int k = 0; k < 3; k++)
            v[i][k] = (i >> k) & 1 ? hi[k] : lo[k];
    static const int tet[5][4] = {{0, 1, 2, 4}, {3, 1, 2, 7}, {5, 1, 4, 7},
                                  {6, 2, 4, 7}, {1, 2, 4, 7}};
    for (int i = 0; i < 5; i++)
        if (st_tri_tet_intersect(a, b, c, v[tet[i][0]], v[tet[i][1]],
                                 v[tet[i][2]], v[tet[i][3]]))
            return 1;
    return 0;
}

static void test_tri_box(void)
{
    const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
    struct { double a[3], b[3], c[3]; int want; const char *what; } cs[] = {
        {{0.2, 0.2, 0.2}, {0.3, 0.2, 0.2}, {0.2, 0.3, 0.2}, 1, "inside"},
        {{-5, -5, 0.5}, {5, -5, 0.5}, {0, 5, 0.5}, 1, "big triangle through"},
        {{1.5, 0.5, -5}, {1.5, 0.5, 5}, {3, 0.5, 0}, 0, "beside"},
        {{1, 0.5, -5}, {1, 0.5, 5}, {3, 0.5, 0}, 1, "edge on a face"},
        {{1.5, -1, 0.5}, {3, 0.5, 0.5}, {1.5, 0.5, 3}, 0, "near a corner, outside"},
        /* The plane x + y + z = 3 touches the box at (1, 1, 1) only. */
        {{3, 0, 0}, {0, 3, 0}, {0, 0, 3}, 1, "touching the far corner with its face"},
        {{3, 0, 1e-15}, {0, 3, 1e-15}, {0, 0, 3 + 1e-15}, 0, "just missing the far corner"},
        /* Edge-edge: the segment from (2, 0, 0.5) to (0, 2, 0.5) passes the
         * box edge x = y = 1 at (1, 1, 0.5). */
        {{2, 0, 0.5}, {0, 2, 0.5}, {3, 3, 0.5}, 1, "edge crossing a box edge"},
        {{2.01, 0, 0.5}, {0, 2.01, 0.5}, {3, 3, 0.5}, 0, "edge passing beside a box edge"},
    };
    for (size_t i = 0; i < sizeof cs / sizeof cs[0]; i++)
        TAP_CHECK(st_tri_box_intersect(cs[i].a, cs[i].b, cs[i].c, lo, hi) == cs[i].want,
                  "tri-box: %s", cs[i].what);
    const double elo[3] = {1, 1, 1}, ehi[3] = {0, 2, 2};
    TAP_CHECK(st_tri_box_intersect(cs[0].a, cs[0].b, cs[0].c, elo, ehi) == 0,
              "tri-box: an empty box (lo > hi) meets nothing");

    /* Random small integer triangles and boxes (flat and point boxes
     * included): the separating-axis test must agree with the union of the
     * box's five tets. */
    int bad = 0, n = 0, hits = 0;
    for (int it = 0; it < 60000; it++) {
        double a[3], b[3], c[3], blo[3], bhi[3];
        rand_pt(a, 3);
        rand_pt(b, 3);
        rand_pt(c, 3);
        for (int k = 0; k < 3; k++) {
            double u = (double)rng_int(2), v = (double)rng_int(2);
            if (it % 4 != 0 && u == v)
                v = u + 1;
            blo[k] = fmin(u, v);
            bhi[k] = fmax(u, v);
        }
        int r = st_tri_box_intersect(a, b, c, blo, bhi);
        int ref = tri_box_by_tets(a, b, c, blo, bhi);
        n++;
        hits += ref;
        if (r != ref)
            bad++;
    }
    TAP_CHECK(bad == 0, "tri-box (separating axes) = union of its 5 tets "
              "(tri-tet) on %d random integer cases, %d meeting (%d wrong)",
              n, hits, bad);
}

/* st_tri_box_maybe never parts what meets (the exact test's 1 is its 1),
 * at every scale and far from the origin, on touching cases built to be
 * exact (a box corner on a vertex, a box face through a vertex); and it
 * parts most of what the exact test parts, or it would not be a filter. */
static double unit_rand(uint64_t *st)
{
    *st = *st * 6364136223846793005ull + 1442695040888963407ull;
    return (double)(*st >> 11) * (1.0 / 9007199254740992.0);
}

/* st_tri_box_filter_maybe after st_tri_box_filter_init on a, b, c (the
 * filter a BVH walk keeps for its query). */
static int filter_maybe(const double *a, const double *b, const double *c, const double *lo,
                        const double *hi)
{
    st_tri_box_filter f;
    st_tri_box_filter_init(&f, a, b, c);
    return st_tri_box_filter_maybe(&f, lo, hi);
}

static void test_tri_box_maybe(void)
{
    int missed = 0, n = 0, exact_apart = 0, maybe_apart = 0;
    int fmissed = 0, filter_apart = 0;
    for (int it = 0; it < 60000; it++) {
        double a[3], b[3], c[3], blo[3], bhi[3];
        rand_pt(a, 3);
        rand_pt(b, 3);
        rand_pt(c, 3);
        for (int k = 0; k < 3; k++) {
            double u = (double)rng_int(2), v = (double)rng_int(2);
            if (u == v)
                v = u + 1;
            blo[k] = fmin(u, v);
            bhi[k] = fmax(u, v);
        }
        int ex = st_tri_box_intersect(a, b, c, blo, bhi);
        int mb = st_tri_box_maybe(a, b, c, blo, bhi);
        n++;
        missed += ex && !mb;
        fmissed += ex && !filter_maybe(a, b, c, blo, bhi);
    }
    static const double scale[] = {1e-9, 1e-3, 1.0, 1e3, 1e9};
    static const double shift[] = {0.0, 1.0, 1e5};
    uint64_t st = 12345;
    for (int si = 0; si < 5; si++)
        for (int hi_ = 0; hi_ < 3; hi_++)
            for (int it = 0; it < 4000; it++) {
                const double S = scale[si], T = shift[hi_] * S;
                double v[3][3], lo[3], hi[3];
                for (int i = 0; i < 3; i++)
                    for (int k = 0; k < 3; k++)
                        v[i][k] = T + S * unit_rand(&st);
                /* a small box near the triangle: its corner on vertex 0
                 * (touching), or moved off it by a little (mostly apart) */
                const int touch = it % 2 == 0;
                for (int k = 0; k < 3; k++) {
                    double w = 0.05 * S * unit_rand(&st);
                    double off = touch ? 0.0 : 0.02 * S * (unit_rand(&st) - 0.5);
                    if ((it / 2) % 2) {
                        lo[k] = v[0][k] + off;
                        hi[k] = lo[k] + w;
                    } else {
                        hi[k] = v[0][k] + off;
                        lo[k] = hi[k] - w;
                    }
                }
                if (touch && it % 8 == 0)   /* a box face through vertex 0 */
                    lo[1] = hi[1] = v[0][1];
                int ex = st_tri_box_intersect(v[0], v[1], v[2], lo, hi);
                int mb = st_tri_box_maybe(v[0], v[1], v[2], lo, hi);
                int mf = filter_maybe(v[0], v[1], v[2], lo, hi);
                n++;
                missed += ex && !mb;
                fmissed += ex && !mf;
                exact_apart += !ex;
                maybe_apart += !mb;
                filter_apart += !mf;
            }
    TAP_CHECK(missed == 0, "tri-box filter: no meeting pair parted (%d cases, %d missed)",
              n, missed);
    TAP_CHECK(exact_apart > 1000 && maybe_apart * 10 >= exact_apart * 9,
              "tri-box filter: parts %d of the %d pairs the exact test parts", maybe_apart,
              exact_apart);
    TAP_CHECK(fmissed == 0, "tri-box filter, triangle part once: no meeting pair parted "
              "(%d cases, %d missed)", n, fmissed);
    TAP_CHECK(filter_apart * 10 >= exact_apart * 9,
              "tri-box filter, triangle part once: parts %d of the %d pairs the exact test parts",
              filter_apart, exact_apart);
    /* a non-finite coordinate keeps the pair (NaN escapes max and min, so
     * the filter must look), whichever vertex has it; an empty box does not */
    int kept = 0;
    for (int i = 0; i < 9; i++)
        for (int w = 0; w < 2; w++) {
            double v[3][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
            const double lo[3] = {5, 5, 5}, hi[3] = {6, 6, 6};
            v[i / 3][i % 3] = w ? NAN : INFINITY;
            kept += st_tri_box_maybe(v[0], v[1], v[2], lo, hi);
            kept += filter_maybe(v[0], v[1], v[2], lo, hi);
        }
    const double nlo[3] = {1, 0, 0}, nhi[3] = {0, 1, 1}, tri[3][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    TAP_CHECK(kept == 36 && !st_tri_box_maybe(tri[0], tri[1], tri[2], nlo, nhi),
              "tri-box filter: a NaN or infinite coordinate keeps a far box (%d of 36), "
              "an empty box is parted", kept);
}

/* ---- speed --------------------------------------------------------------------- */

/* M calls/s of each test on pairs of small random triangles / tets / boxes
 * (size ~0.1): far pairs in the unit cube (mostly quick rejections) and
 * near pairs around one centre (the candidates a BVH hands over). */
static void test_speed(void)
{
    enum { M = 4096 };
    static double P[M][3], Q[M][3], R[M][3];
    for (int i = 0; i < M; i++)
        for (int k = 0; k < 3; k++)
            P[i][k] = rng_unif(0, 1);
    for (int i = 0; i < M; i++)
        for (int k = 0; k < 3; k++) {
            Q[i][k] = P[i - i % 4][k] + rng_unif(-0.1, 0.1);
            R[i][k] = P[i - i % 4][k] + rng_unif(-0.1, 0.1);
        }
    const int reps = 200000;
    long acc = 0;
    for (int near = 0; near < 2; near++) {
        double (*S)[3] = near ? R : Q;
        int off = near ? 0 : 4 * 37;
        double t0 = now();
        for (int i = 0; i < reps; i++) {
            int j = (i * 4) % M, l = (i * 4 + off) % M;
            acc += st_tri_tri_intersect(Q[j], Q[j + 1], Q[j + 2], S[l], S[l + 1], S[l + 2]);
        }
        double t1 = now();
        for (int i = 0; i < reps; i++) {
            int j = (i * 4) % M, l = (i * 4 + off) % M;
            acc += st_tri_tet_intersect(Q[j], Q[j + 1], Q[j + 2], S[l], S[l + 1], S[l + 2],
                                        S[l + 3]);
        }
        double t2 = now();
        for (int i = 0; i < reps; i++) {
            int j = (i * 4) % M, l = (i * 4 + off) % M;
            double lo[3], hi[3];
            for (int k = 0; k < 3; k++) {
                lo[k] = S[l][k] - 0.05;
                hi[k] = S[l][k] + 0.05;
            }
            acc += st_tri_box_intersect(Q[j], Q[j + 1], Q[j + 2], lo, hi);
        }
        double t3 = now();
        for (int i = 0; i < reps; i++) {
            int j = i % M, l = ((i - i % 4) + off) % M;
            acc += st_point_in_tet(Q[j], S[l], S[l + 1], S[l + 2], S[l + 3]) != ST_OUTSIDE;
        }
        double t4 = now();
        for (int i = 0; i < reps; i++) {
            int j = (i * 4) % M, l = (i * 4 + off) % M;
            acc += st_segment_tri_intersect(Q[j], Q[j + 1], S[l], S[l + 1], S[l + 2]);
        }
        double t5 = now();
        TAP_NOTE("%s pairs, M calls/s: tri_tri %.2f, tri_tet %.2f, tri_box %.2f, "
                 "point_in_tet %.2f, segment_tri %.2f", near ? "near" : "far",
                 reps / (t1 - t0) / 1e6, reps / (t2 - t1) / 1e6, reps / (t3 - t2) / 1e6,
                 reps / (t4 - t3) / 1e6, reps / (t5 - t4) / 1e6);
    }
    TAP_CHECK(acc > 0, "speed loops found intersections (%ld)", acc);
}

/* ---- st_bvh_query_box ------------------------------------------------------------ */

typedef struct visit_ctx { unsigned char *seen; size_t count, dup; uint32_t stop_at; } visit_ctx;

static int visit_mark(void *vctx, uint32_t tri)
{
    visit_ctx *c = vctx;
    if (c->seen[tri])
        c->dup++;
    c->seen[tri] = 1;
    c->count++;
    return tri == c->stop_at ? 7 : 0;
}

static int visit_count(void *vctx, uint32_t tri)
{
    (void)tri;
    (*(size_t *)vctx)++;
    return 0;
}

static void test_bvh_query_box(void)
{
    st_soup *s = st_soup_new();
    const size_t nt = 3000;
    for (size_t t = 0; t < nt; t++) {
        double c[3];
        for (int k = 0; k < 3; k++)
            c[k] = rng_unif(0, 10);
        for (int v = 0; v < 3; v++)
            st_soup_add_vertex(s, c[0] + rng_unif(-0.3, 0.3), c[1] + rng_unif(-0.3, 0.3),
                               c[2] + rng_unif(-0.3, 0.3), NULL);
        st_soup_add_triangle(s, (uint32_t)(3 * t), (uint32_t)(3 * t + 1), (uint32_t)(3 * t + 2),
                             NULL);
    }
    st_bvh *b = NULL;
    st_error err = {0};
    TAP_CHECK(st_bvh_build(&b, s, &err) == ST_OK, "bvh over %zu triangles", nt);
    unsigned char *seen = calloc(nt, 1);
    int bad_set = 0, dups = 0, bad_exact = 0;
    size_t total = 0, exact_hits = 0;
    for (int q = 0; q < 300; q++) {
        double lo[3], hi[3];
        for (int k = 0; k < 3; k++) {
            double u = rng_unif(-1, 11), w = rng_unif(0, q % 3 == 0 ? 0.0 : 2.0);
            lo[k] = u;
            hi[k] = u + w; /* every third box is a point */
        }
        memset(seen, 0, nt);
        visit_ctx c = {seen, 0, 0, UINT32_MAX};
        int r = st_bvh_query_box(b, lo, hi, visit_mark, &c);
        dups += (int)c.dup + (r != 0);
        total += c.count;
        for (size_t t = 0; t < nt; t++) {
            const double *v0 = s->xyz + 9 * t, *v1 = v0 + 3, *v2 = v0 + 6;
            int meets = 1;
            for (int k = 0; k < 3; k++)
                meets &= fmin(fmin(v0[k], v1[k]), v2[k]) <= hi[k] &&
                         fmax(fmax(v0[k], v1[k]), v2[k]) >= lo[k];
            if (meets != seen[t])
                bad_set++;
            int ex = st_tri_box_intersect(v0, v1, v2, lo, hi);
            exact_hits += (size_t)ex;
            if (ex && !seen[t])
                bad_exact++;
        }
    }
    TAP_CHECK(bad_set == 0 && dups == 0, "query_box visits exactly the triangles whose "
              "boxes meet the query, once each (%zu visits, %zu meet exactly)", total,
              exact_hits);
    TAP_CHECK(bad_exact == 0, "no triangle meeting the box exactly is missed");
    /* Early stop: the first nonzero return ends the query and is returned. */
    double lo[3] = {-1, -1, -1}, hi[3] = {11, 11, 11};
    memset(seen, 0, nt);
    visit_ctx c = {seen, 0, 0, 1234};
    int r = st_bvh_query_box(b, lo, hi, visit_mark, &c);
    TAP_CHECK(r == 7 && c.count < nt && seen[1234], "query_box stops at the first nonzero "
              "visit and returns it (%zu visits)", c.count);
    double flo[3] = {20, 20, 20}, fhi[3] = {21, 21, 21};
    c.count = 0;
    TAP_CHECK(st_bvh_query_box(b, flo, fhi, visit_mark, &c) == 0 && c.count == 0,
              "query_box far from the soup visits nothing");
    /* Parallel queries give the same counts as serial ones. */
    enum { NQ = 2000 };
    static double qlo[NQ][3];
    static size_t serial[NQ], par[NQ];
    for (int q = 0; q < NQ; q++)
        for (int k = 0; k < 3; k++)
            qlo[q][k] = rng_unif(0, 10);
    unsigned char *scratch = calloc((size_t)NQ * nt, 1);
    memset(scratch, 1, (size_t)NQ * nt);
    memset(scratch, 0, (size_t)NQ * nt);
    double t0 = now();
    for (int q = 0; q < NQ; q++) {
        double qhi[3] = {qlo[q][0] + 0.5, qlo[q][1] + 0.5, qlo[q][2] + 0.5};
        visit_ctx cc = {scratch + (size_t)q * nt, 0, 0, UINT32_MAX};
        st_bvh_query_box(b, qlo[q], qhi, visit_mark, &cc);
        serial[q] = cc.count;
    }
    double t1 = now();
    memset(scratch, 0, (size_t)NQ * nt);
#pragma omp parallel for schedule(dynamic, 16)
    for (int q = 0; q < NQ; q++) {
        double qhi[3] = {qlo[q][0] + 0.5, qlo[q][1] + 0.5, qlo[q][2] + 0.5};
        visit_ctx cc = {scratch + (size_t)q * nt, 0, 0, UINT32_MAX};
        st_bvh_query_box(b, qlo[q], qhi, visit_mark, &cc);
        par[q] = cc.count;
    }
    TAP_CHECK(memcmp(serial, par, sizeof serial) == 0, "parallel box queries = serial ones");
    (void)t0;
    (void)t1;
    /* Speed: many queries with a counting visitor. */
    size_t visits = 0;
    const int nspeed = 200000;
    double t2 = now();
    for (int q = 0; q < nspeed; q++) {
        const double *ql = qlo[q % NQ];
        double qhi[3] = {ql[0] + 0.5, ql[1] + 0.5, ql[2] + 0.5};
        st_bvh_query_box(b, ql, qhi, visit_count, &visits);
    }
    double t3 = now();
    TAP_NOTE("query_box: %.2f M queries/s (box 0.5, %zu triangles of size ~0.5 in 10^3, "
             "%.1f visits per query)", nspeed / (t3 - t2) / 1e6, nt,
             (double)visits / nspeed);
    free(scratch);
    free(seen);
    st_bvh_free(b);
    st_soup_free(s);
}

/* st_tri_tri_cross: piercing, not touching, either way round. */
static void test_tri_tri_cross(void)
{
    static const double A[3][3] = {{0, 0, 0}, {2, 0, 0}, {0, 2, 0}};
    static const struct {
        double b[3][3];
        int cross, meet;
        const char *what;
    } c[] = {
        {{{0.5, 0.5, -1}, {0.5, 0.5, 1}, {0.6, 0.7, 1}}, 1, 1, "one through the other"},
        {{{0.5, 0.5, 0}, {0.9, 0.5, 0}, {0.5, 0.5, 1}}, 0, 1, "an edge lying on the other"},
        {{{0.5, 0.5, 0}, {0.5, 0.6, 1}, {0.7, 0.5, 1}}, 0, 1, "a vertex on the other"},
        {{{0.5, 0.5, 0}, {3, 0.5, 0}, {0.5, 3, 0}}, 0, 1, "coplanar, overlapping"},
        {{{0, 0, 0}, {1, 1, -1}, {1, 1, 1}}, 1, 1, "a common vertex, piercing beyond it"},
        {{{0, 0, 0}, {-1, -1, -1}, {-1, -1, 1}}, 0, 1, "a common vertex, meeting only there"},
        {{{0, 0, 0}, {2, 0, 0}, {1, -1, 1}}, 0, 1, "a common edge"},
        {{{0, 0, 0}, {2, 0, 0}, {1, 0.5, 0}}, 0, 1, "a common edge, folded onto it"},
        {{{3, 3, -1}, {3, 3, 1}, {4, 3, 0}}, 0, 0, "apart"},
    };
    for (size_t i = 0; i < sizeof c / sizeof c[0]; i++) {
        const double(*b)[3] = c[i].b;
        const int r = st_tri_tri_cross(A[0], A[1], A[2], b[0], b[1], b[2]);
        const int s = st_tri_tri_cross(b[2], b[0], b[1], A[1], A[2], A[0]);
        const int m = st_tri_tri_intersect(A[0], A[1], A[2], b[0], b[1], b[2]);
        TAP_CHECK(r == c[i].cross && s == r && m == c[i].meet,
                  "tri_tri_cross: %s: %d / %d (meet %d)", c[i].what, r, s, m);
    }
}

int main(int argc, char **argv)
{
    static const tap_test tests[] = {TAP_TEST(point_in_tet), TAP_TEST(tri_tri_cross),
                                     TAP_TEST(point_in_tri), TAP_TEST(segment_tri),
                                     TAP_TEST(tri_tri), TAP_TEST(tri_tet), TAP_TEST(tri_box),
                                     TAP_TEST(tri_box_maybe), TAP_TEST(bvh_query_box),
                                     TAP_TEST(speed), {0}};
    return tap_main(argc, argv, tests);
}
