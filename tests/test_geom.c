/* test_geom.c - point-segment and point-triangle distance. */
#include "souptet/geom.h"
#include "tap.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* The right triangle (0,0,0) (1,0,0) (0,1,0): known answers in each of its
 * seven Voronoi regions, at height z = 2. */
static void test_voronoi_regions(void)
{
    const double a[3] = {0, 0, 0}, b[3] = {1, 0, 0}, c[3] = {0, 1, 0};
    struct { double p[3]; double d2; double q[3]; const char *region; } cases[] = {
        {{0.2, 0.2, 2}, 4.0, {0.2, 0.2, 0}, "face"},
        {{-1, -1, 2}, 2.0 + 4.0, {0, 0, 0}, "vertex a"},
        {{2, -1, 2}, 1.0 + 1.0 + 4.0, {1, 0, 0}, "vertex b"},
        {{-1, 2, 2}, 1.0 + 1.0 + 4.0, {0, 1, 0}, "vertex c"},
        {{0.5, -1, 2}, 1.0 + 4.0, {0.5, 0, 0}, "edge ab"},
        {{-1, 0.5, 2}, 1.0 + 4.0, {0, 0.5, 0}, "edge ca"},
        {{1, 1, 2}, 0.5 + 4.0, {0.5, 0.5, 0}, "edge bc"},
        {{0.25, 0.25, 0}, 0.0, {0.25, 0.25, 0}, "on the face"},
        {{0.25, 0.25, -3}, 9.0, {0.25, 0.25, 0}, "face from below"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        double q[3];
        double d2 = st_point_triangle_dist2(cases[i].p, a, b, c, q);
        TAP_NEAR(d2, cases[i].d2, 1e-14, "distance in region %s", cases[i].region);
        double e = fabs(q[0] - cases[i].q[0]) + fabs(q[1] - cases[i].q[1]) +
                   fabs(q[2] - cases[i].q[2]);
        TAP_NEAR(e, 0.0, 1e-14, "closest point in region %s", cases[i].region);
    }
}

static void test_degenerate_triangles(void)
{
    const double p[3] = {0.5, 1.0, 0.0};
    /* collinear: the segment from 0 to 2 on the x axis */
    const double a[3] = {0, 0, 0}, b[3] = {1, 0, 0}, c[3] = {2, 0, 0};
    TAP_NEAR(st_point_triangle_dist2(p, a, b, c, NULL), 1.0, 1e-15,
             "collinear triangle is its longest segment");
    const double far[3] = {3, 0, 0};
    TAP_NEAR(st_point_triangle_dist2(far, a, b, c, NULL), 1.0, 1e-15,
             "collinear triangle: beyond the end vertex");
    /* repeated vertex: a segment */
    TAP_NEAR(st_point_triangle_dist2(p, a, b, b, NULL), 1.0, 1e-15,
             "triangle with a repeated vertex is a segment");
    /* all three equal: a point */
    const double q[3] = {3, 4, 0};
    TAP_NEAR(st_point_triangle_dist2(q, a, a, a, NULL), 25.0, 1e-15,
             "triangle with one vertex three times is a point");
    /* a needle: nearly collinear, width 1e-12 */
    const double n1[3] = {0, 0, 0}, n2[3] = {1, 1e-12, 0}, n3[3] = {2, 0, 0};
    double d2 = st_point_triangle_dist2(p, n1, n2, n3, NULL);
    TAP_CHECK(isfinite(d2) && fabs(sqrt(d2) - 1.0) < 1e-11,
              "needle triangle gives a finite, right distance (%.17g)", sqrt(d2));
    /* huge and tiny coordinates */
    const double h1[3] = {1e15, 0, 0}, h2[3] = {1e15 + 1e3, 0, 0},
                 h3[3] = {1e15, 1e3, 0}, hp[3] = {1e15 + 100, 100, 50};
    TAP_NEAR(st_point_triangle_dist2(hp, h1, h2, h3, NULL), 2500.0, 1e-2,
             "triangle far from the origin");
    /* 1e-150: the squared distance (1e-300) is still a normal double, but
     * the squared normal (1e-600) would not be. */
    const double t1[3] = {0, 0, 0}, t2[3] = {1e-150, 0, 0},
                 t3[3] = {0, 1e-150, 0}, tp[3] = {2e-151, 2e-151, 1e-150};
    double td = st_point_triangle_dist2(tp, t1, t2, t3, NULL);
    TAP_CHECK(isfinite(td) && fabs(sqrt(td) / 1e-150 - 1.0) < 1e-9,
              "triangle with tiny coordinates (%.3g)", sqrt(td));
}

static double urand(unsigned *s)
{
    *s = *s * 1103515245u + 12345u;
    return (double)((*s >> 8) & 0xffffff) / 16777216.0;
}

/* Random triangles and points: the closest point lies in the triangle,
 * matches the returned distance, and no sampled point of the triangle is
 * closer. */
static void test_random_against_sampling(void)
{
    unsigned seed = 12345;
    int bad_in = 0, bad_d = 0, bad_min = 0;
    const int trials = 2000, samples = 40;
    for (int t = 0; t < trials; t++) {
        double v[3][3], p[3];
        for (int k = 0; k < 3; k++)
            for (int a = 0; a < 3; a++)
                v[k][a] = urand(&seed) * 2 - 1;
        for (int a = 0; a < 3; a++)
            p[a] = urand(&seed) * 4 - 2;
        double q[3];
        double d2 = st_point_triangle_dist2(p, v[0], v[1], v[2], q);
        /* barycentrics of q by least squares on the two edges */
        double e1[3], e2[3], w[3];
        st_sub3(e1, v[1], v[0]);
        st_sub3(e2, v[2], v[0]);
        st_sub3(w, q, v[0]);
        double a11 = st_dot3(e1, e1), a12 = st_dot3(e1, e2), a22 = st_dot3(e2, e2);
        double b1 = st_dot3(w, e1), b2 = st_dot3(w, e2), det = a11 * a22 - a12 * a12;
        double s = (b1 * a22 - b2 * a12) / det, u = (a11 * b2 - a12 * b1) / det;
        if (s < -1e-9 || u < -1e-9 || s + u > 1 + 1e-9)
            bad_in++;
        double pq[3];
        st_sub3(pq, p, q);
        if (fabs(st_dot3(pq, pq) - d2) > 1e-12)
            bad_d++;
        for (int i = 0; i <= samples; i++)
            for (int j = 0; i + j <= samples; j++) {
                double x[3];
                for (int a = 0; a < 3; a++)
                    x[a] = v[0][a] + e1[a] * i / samples + e2[a] * j / samples;
                double px[3];
                st_sub3(px, p, x);
                if (st_dot3(px, px) < d2 - 1e-12)
                    bad_min++;
            }
    }
    TAP_CHECK(bad_in == 0, "closest point lies in the triangle (%d of %d off)", bad_in, trials);
    TAP_CHECK(bad_d == 0, "returned distance is the distance to the closest point (%d off)", bad_d);
    TAP_CHECK(bad_min == 0, "no sample of the triangle is closer (%d closer)", bad_min);
}

static void test_segment(void)
{
    const double a[3] = {0, 0, 0}, b[3] = {2, 0, 0};
    const double p1[3] = {1, 1, 0}, p2[3] = {-1, 0, 0}, p3[3] = {4, 0, 3};
    TAP_NEAR(st_point_segment_dist2(p1, a, b, NULL), 1.0, 0, "segment interior");
    TAP_NEAR(st_point_segment_dist2(p2, a, b, NULL), 1.0, 0, "segment start");
    TAP_NEAR(st_point_segment_dist2(p3, a, b, NULL), 13.0, 0, "segment end");
    TAP_NEAR(st_point_segment_dist2(p1, a, a, NULL), 2.0, 0, "zero-length segment");
}

/* The degeneracy test as it was decided before the squared-length screen
 * (geom.c's tri_degenerate): the three edge norms and the normal's, all by
 * st_norm3, the threshold ST_DEGENERATE_AREA_RATIO * emax^2; then the same
 * distance as st_point_triangle_dist2 (face, or the edges p lies outside
 * of). The reference the screened routine must match bit for bit. */
static double ref_tri_dist2(const double p[3], const double a[3], const double b[3],
                            const double c[3], double closest[3])
{
    const double *v[3] = {a, b, c};
    double e[3][3], n[3];
    st_sub3(e[0], b, a);
    st_sub3(e[1], c, b);
    st_sub3(e[2], a, c);
    st_cross3(n, e[0], e[1]);
    double emax = fmax(st_norm3(e[0]), fmax(st_norm3(e[1]), st_norm3(e[2])));
    double nl = st_norm3(n);
    int degenerate = !(nl > ST_DEGENERATE_AREA_RATIO * emax * emax);
    int outside[3] = {1, 1, 1}, inside = !degenerate;
    if (!degenerate) {
        for (int k = 0; k < 3; k++)
            n[k] /= nl;
        for (int i = 0; i < 3; i++) {
            double m[3], vp[3];
            st_cross3(m, n, e[i]);
            st_sub3(vp, p, v[i]);
            outside[i] = st_dot3(vp, m) < 0.0;
            inside &= !outside[i];
        }
    }
    if (inside) {
        double ap[3];
        st_sub3(ap, p, a);
        double s = st_dot3(ap, n);
        for (int k = 0; k < 3; k++)
            closest[k] = p[k] - s * n[k];
        return s * s;
    }
    double best = INFINITY, q[3];
    for (int i = 0; i < 3; i++)
        if (outside[i]) {
            double d2 = st_point_segment_dist2(p, v[i], v[(i + 1) % 3], q);
            if (d2 < best) {
                best = d2;
                for (int k = 0; k < 3; k++)
                    closest[k] = q[k];
            }
        }
    return best;
}

/* Case t at scale sc (test_screen_bit_identical, test_framed): a
 * triangle v near the degeneracy threshold (t % 5 of 0, 1), collinear or
 * with a repeated vertex (2) or random, and a point p around or across
 * it; returns t % 5. */
static int draw_case(int t, double sc, unsigned *seed, double v[3][3], double p[3])
{
    for (int k = 0; k < 3; k++)
        for (int a = 0; a < 3; a++)
            v[k][a] = sc * (urand(seed) * 2 - 1);
    const int kind = t % 5;
    if (kind <= 1) {   /* near the threshold: base L along u, height h along w */
        double L = sc * (0.5 + urand(seed)), rel = (urand(seed) * 2 - 1) * 1e-5;
        if (kind == 1)
            rel *= 1e-3;   /* inside the +-1e-6 band */
        double h = ST_DEGENERATE_AREA_RATIO * L * (1.0 + rel);
        double mid = 0.2 + 0.6 * urand(seed);
        for (int a = 0; a < 3; a++) {
            v[1][a] = v[0][a] + (a == t % 3 ? L : 0.0);
            v[2][a] = v[0][a] + (a == t % 3 ? mid * L : 0.0) + (a == (t + 1) % 3 ? h : 0.0);
        }
    } else if (kind == 2) {   /* collinear, or a repeated vertex */
        for (int a = 0; a < 3; a++)
            v[2][a] = t % 2 ? v[1][a] : v[0][a] + 0.5 * (v[1][a] - v[0][a]);
    }
    for (int a = 0; a < 3; a++)   /* around the triangle and across it */
        p[a] = (v[0][a] + v[1][a] + v[2][a]) / 3.0 + sc * (urand(seed) * 2 - 1) *
                                                           (t % 3 ? 1e-6 : 1.0);
    return kind;
}

/* Triangles right at the degeneracy threshold (height within 1e-5
 * relative of ST_DEGENERATE_AREA_RATIO times the base: both sides of it,
 * in and beyond the screen's undecided band), slivers, collinear and
 * repeated vertices, random ones, at scales from 1e-200 to 1e200 (and
 * with infinite and NaN coordinates): st_point_triangle_dist2 gives the
 * reference's distance and closest point, bit for bit. */
static void test_screen_bit_identical(void)
{
    unsigned seed = 4242;
    static const double scales[] = {1e-200, 1e-120, 1e-30, 1e-3, 1.0, 7.0, 1e30, 1e120, 1e200};
    size_t bad = 0, cases = 0, degenerate = 0, flat = 0;
    for (size_t si = 0; si < sizeof scales / sizeof *scales; si++) {
        const double sc = scales[si];
        for (int t = 0; t < 4000; t++) {
            double v[3][3], p[3];
            const int kind = draw_case(t, sc, &seed, v, p);
            double q[3] = {0, 0, 0}, rq[3] = {0, 0, 0};
            double d2 = st_point_triangle_dist2(p, v[0], v[1], v[2], q);
            double r2 = ref_tri_dist2(p, v[0], v[1], v[2], rq);
            cases++;
            bad += memcmp(&d2, &r2, sizeof d2) != 0 || memcmp(q, rq, sizeof q) != 0;
            double e[3][3], n[3];
            st_sub3(e[0], v[1], v[0]);
            st_sub3(e[1], v[2], v[1]);
            st_sub3(e[2], v[0], v[2]);
            st_cross3(n, e[0], e[1]);
            double emax = fmax(st_norm3(e[0]), fmax(st_norm3(e[1]), st_norm3(e[2])));
            int dg = !(st_norm3(n) > ST_DEGENERATE_AREA_RATIO * emax * emax);
            degenerate += dg;
            flat += kind <= 1 && !dg;
        }
    }
    const double big = 1e300, inf = INFINITY, nan = NAN;
    const double odd[][3][3] = {
        {{-big, 0, 0}, {big, 0, 0}, {0, big, 0}},   /* edges overflow */
        {{0, 0, 0}, {inf, 0, 0}, {0, 1, 0}},
        {{0, 0, 0}, {1, nan, 0}, {0, 1, 0}},
        {{0, 0, 0}, {4.9e-324, 0, 0}, {0, 4.9e-324, 0}},   /* subnormal */
    };
    for (size_t i = 0; i < sizeof odd / sizeof *odd; i++) {
        const double p[3] = {0.25, 0.25, 1.0};
        double q[3] = {0, 0, 0}, rq[3] = {0, 0, 0};
        double d2 = st_point_triangle_dist2(p, odd[i][0], odd[i][1], odd[i][2], q);
        double r2 = ref_tri_dist2(p, odd[i][0], odd[i][1], odd[i][2], rq);
        cases++;
        bad += memcmp(&d2, &r2, sizeof d2) != 0 || memcmp(q, rq, sizeof q) != 0;
    }
    TAP_CHECK(bad == 0, "screened degeneracy test: bit for bit the four-norm reference "
              "(%zu of %zu differ)", bad, cases);
    TAP_CHECK(degenerate > cases / 5 && flat > cases / 20,
              "the cases cover both sides of the threshold (%zu degenerate, %zu flat but not)",
              degenerate, flat);
}

/* st_point_triangle_dist2_framed with the triangle's st_tri_frame: the
 * distance and closest point of st_point_triangle_dist2, bit for bit, on
 * test_screen_bit_identical's cases (each triangle's frame measured from
 * five points: on its plane inside, on an edge's line, at a vertex, and
 * two off it), inside the prism and out, and from points on the plane of
 * a flat one. */
static void test_framed(void)
{
    unsigned seed = 977;
    static const double scales[] = {1e-200, 1e-30, 1e-3, 1.0, 7.0, 1e30, 1e200};
    size_t bad = 0, cases = 0, inside = 0;
    for (size_t si = 0; si < sizeof scales / sizeof *scales; si++)
        for (int t = 0; t < 3000; t++) {
            double v[3][3], p[3];
            (void)draw_case(t, scales[si], &seed, v, p);
            st_tri_frame f;
            st_tri_frame_make(&f, v[0], v[1], v[2]);
            for (int j = 0; j < 5; j++) {
                double x[3];
                for (int a = 0; a < 3; a++) {
                    const double c = (v[0][a] + v[1][a] + v[2][a]) / 3.0;
                    x[a] = j == 0 ? p[a] : j == 1 ? c : j == 2 ? 0.5 * (v[0][a] + v[1][a])
                           : j == 3 ? v[2][a] : 2.0 * c - p[a];
                }
                double q[3] = {0, 0, 0}, fq[3] = {0, 0, 0};
                const double d2 = st_point_triangle_dist2(x, v[0], v[1], v[2], q);
                const double f2 = st_point_triangle_dist2_framed(x, v[0], v[1], v[2], &f, fq);
                cases++;
                inside += !f.degenerate && j == 1;
                bad += memcmp(&d2, &f2, sizeof d2) != 0 || memcmp(q, fq, sizeof q) != 0;
                /* without the closest point: the same distance */
                const double g2 = st_point_triangle_dist2_framed(x, v[0], v[1], v[2], &f, NULL);
                bad += memcmp(&d2, &g2, sizeof d2) != 0;
            }
        }
    TAP_CHECK(bad == 0, "framed distances: bit for bit st_point_triangle_dist2's (%zu of %zu "
              "differ)", bad, cases);
    TAP_CHECK(inside > cases / 20, "the cases reach the face region (%zu centroids of "
              "non-degenerate triangles)", inside);
}

int main(int argc, char **argv)
{
    static const tap_test tests[] = {TAP_TEST(voronoi_regions), TAP_TEST(degenerate_triangles),
                                     TAP_TEST(segment), TAP_TEST(random_against_sampling),
                                     TAP_TEST(screen_bit_identical), TAP_TEST(framed), {0}};
    return tap_main(argc, argv, tests);
}
