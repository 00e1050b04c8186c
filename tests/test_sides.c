/*
 * test_sides.c - the sides' local winding number (sides_internal.h): the
 * product of complex numbers with one arc tangent, over each point's own
 * query or over triangles gathered for a row, gives the evidence the sum
 * of arc tangents gives, also where rounding could tell them apart, and
 * also for points read together.
 */
#include "../src/field/sides_internal.h"
#include "souptet/bvh.h"
#include "souptet/grid.h"
#include "souptet/sides.h"
#include "souptet/sign.h"
#include "souptet/soup.h"
#include "shapes.h"
#include "tap.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>

/* A closed star-shaped bump of nu x nv quads (radius 1 + bump sin 3 theta
 * cos 2 phi), each triangle turned outward (its normal along its
 * centroid; the poles' triangles have no area). z_cut: without the
 * triangles above it (a hole). */
static st_soup *bumpy(int nu, int nv, double bump, double z_cut)
{
    st_soup *s = st_soup_new();
    for (int i = 0; i < nv; i++)
        for (int j = 0; j < nu; j++) {
            double p[4][3];
            for (int c = 0; c < 4; c++) {
                const double th = M_PI * (double)(i + (c >= 2)) / nv;
                const double ph = 2.0 * M_PI * (double)(j + (c == 1 || c == 2)) / nu;
                const double rr = 1.0 + bump * sin(3.0 * th) * cos(2.0 * ph);
                p[c][0] = rr * sin(th) * cos(ph);
                p[c][1] = rr * sin(th) * sin(ph);
                p[c][2] = rr * cos(th);
            }
            const int tri[2][3] = {{0, 1, 2}, {0, 2, 3}};
            for (int t = 0; t < 2; t++) {
                const double *a = p[tri[t][0]], *b = p[tri[t][1]], *c = p[tri[t][2]];
                if (a[2] > z_cut || b[2] > z_cut || c[2] > z_cut)
                    continue;
                double u[3], w[3], n[3], m[3];
                for (int k = 0; k < 3; k++) {
                    u[k] = b[k] - a[k];
                    w[k] = c[k] - a[k];
                    m[k] = a[k] + b[k] + c[k];
                }
                n[0] = u[1] * w[2] - u[2] * w[1];
                n[1] = u[2] * w[0] - u[0] * w[2];
                n[2] = u[0] * w[1] - u[1] * w[0];
                add_tri(s, a, b, c, n[0] * m[0] + n[1] * m[1] + n[2] * m[2] < 0.0);
            }
        }
    return s;
}

static uint64_t rng = 88172645463325252ull;
static double uniform(double lo, double hi)
{
    rng ^= rng << 13, rng ^= rng >> 7, rng ^= rng << 17;
    return lo + (hi - lo) * (double)(rng >> 11) / 9007199254740992.0;
}

/* The BVH of s (NULL, and a failed check, when it cannot be built). */
static st_bvh *bvh_of(const st_soup *s)
{
    st_bvh *b = NULL;
    st_error err;
    TAP_CHECK(st_bvh_build(&b, s, &err) == ST_OK, "bvh of %zu triangles", s->ntris);
    return b;
}

/* Evidence at n points along a row by all three ways; the number of
 * points where they differ; *nonzero counts those of way 0 not 0. */
static size_t disagree(const st_bvh *b, const double *x, size_t n, double y, double z, double r,
                       double scale, double cap, size_t *nonzero)
{
    int8_t e[3][16];
    for (int how = 0; how < 3; how++)
        st_sides_winding_points(e[how], b, x, n, y, z, r, scale, cap, how);
    size_t bad = 0;
    for (size_t k = 0; k < n; k++) {
        bad += e[0][k] != e[1][k] || e[0][k] != e[2][k];
        *nonzero += e[0][k] != 0;
    }
    return bad;
}

/* Inside the closed surface, its whole solid angle (4 pi: the product's
 * argument goes once round) at scale 1 rounds to 13, outside to 0: the
 * turns counted as the product goes. */
static void test_closed(void)
{
    st_soup *s = bumpy(48, 24, 0.1, 9.0);
    st_bvh *b = bvh_of(s);
    size_t in_ok = 0, out_ok = 0;
    for (int i = 0; i < 200; i++) {
        const double y = uniform(-0.5, 0.5), z = uniform(-0.5, 0.5);
        double x[4] = {uniform(-0.5, -0.3), uniform(-0.2, 0.0), uniform(0.1, 0.3), 0.45};
        int8_t e[4];
        for (int how = 1; how < 3; how++) {
            st_sides_winding_points(e, b, x, 4, y, z, 3.0, 1.0, 100.0, how);
            for (int k = 0; k < 4; k++)
                in_ok += e[k] == 13;
        }
        const double xo[2] = {1.6, 2.0};
        for (int how = 1; how < 3; how++) {
            st_sides_winding_points(e, b, xo, 2, y, z, 3.0, 1.0, 100.0, how);
            for (int k = 0; k < 2; k++)
                out_ok += e[k] == 0;
        }
    }
    TAP_CHECK(in_ok == 1600, "inside: 4 pi at scale 1 is 13 (%zu of 1600)", in_ok);
    TAP_CHECK(out_ok == 800, "outside: 0 (%zu of 800)", out_ok);
    st_bvh_free(b);
    st_soup_free(s);
}

/* Random rows near a closed and an open surface, random boxes and
 * scales: the three ways agree at every point. */
static void test_agree(void)
{
    for (int open = 0; open < 2; open++) {
        st_soup *s = bumpy(40, 20, 0.15, open ? 0.6 : 9.0);
        st_bvh *b = bvh_of(s);
        size_t bad = 0, nonzero = 0, points = 0;
        for (int i = 0; i < 1500; i++) {
            const size_t n = 1 + (size_t)uniform(0.0, 8.0);
            const double r = uniform(0.02, 0.8), step = uniform(0.01, 0.2);
            double x[16];
            x[0] = uniform(-1.4, 1.4);
            for (size_t k = 1; k < n; k++)
                x[k] = x[k - 1] + step * (double)(1 + (k % 2));
            const double scale = i % 2 ? 24.0 / (4.0 * M_PI) : uniform(0.3, 6.0);
            bad += disagree(b, x, n, uniform(-1.3, 1.3), uniform(-1.3, 1.3), r, scale,
                            i % 3 ? 9.0 : 100.0, &nonzero);
            points += n;
        }
        TAP_CHECK(bad == 0, "%s surface: the three ways agree (%zu of %zu points differ)",
                  open ? "open" : "closed", bad, points);
        TAP_CHECK(nonzero > points / 10, "%s surface: %zu of %zu points with evidence",
                  open ? "open" : "closed", nonzero, points);
        st_bvh_free(b);
        st_soup_free(s);
    }
}

/* Where rounding could tell: the whole solid angle scaled onto a half
 * integer (2.5 from 4 pi), and points on the triangles' centroids (a term
 * on the negative real axis, its sign of zero deciding pi or -pi): the
 * products fall back on the sum, and agree with it. */
static void test_threshold(void)
{
    st_soup *s = bumpy(24, 12, 0.1, 9.0);
    st_bvh *b = bvh_of(s);
    size_t bad = 0, nonzero = 0;
    for (int i = 0; i < 100; i++) {
        const double x[3] = {-0.4, uniform(-0.1, 0.1), 0.3};
        bad += disagree(b, x, 3, uniform(-0.3, 0.3), uniform(-0.3, 0.3), 3.0, 2.5 / (4.0 * M_PI),
                        9.0, &nonzero);
    }
    TAP_CHECK(bad == 0 && nonzero == 300, "a half integer: the ways agree (%zu differ, %zu set)",
              bad, nonzero);
    bad = 0;
    for (size_t t = 0; t < s->ntris; t++) {
        const uint32_t *v = s->tris + 3 * t;
        double c[3];
        for (int k = 0; k < 3; k++)
            c[k] = (s->xyz[3 * v[0] + k] + s->xyz[3 * v[1] + k] + s->xyz[3 * v[2] + k]) / 3.0;
        bad += disagree(b, c, 1, c[1], c[2], 0.2, 24.0 / (4.0 * M_PI), 9.0, &nonzero);
    }
    TAP_CHECK(bad == 0, "on the triangles: the ways agree (%zu of %zu differ)", bad, s->ntris);
    st_bvh_free(b);
    st_soup_free(s);
}

/* Points read together (how 2 reads up to four points of a row at once
 * where the processor has AVX): a point on a triangle's centroid (its
 * term on the negative real axis: it falls back on the sum) among 1 to 4
 * others of its row, at each place in the row, and boxes that meet a
 * triangle for some of the points only: the ways agree at every point. */
static void test_together(void)
{
    st_soup *s = bumpy(24, 12, 0.1, 0.7);
    st_bvh *b = bvh_of(s);
    size_t bad = 0, nonzero = 0, points = 0;
    for (size_t t = 0; t < s->ntris; t++) {
        const uint32_t *v = s->tris + 3 * t;
        double c[3];
        for (int k = 0; k < 3; k++)
            c[k] = (s->xyz[3 * v[0] + k] + s->xyz[3 * v[1] + k] + s->xyz[3 * v[2] + k]) / 3.0;
        const size_t n = 2 + t % 4, on = (t / 4) % n;
        double x[8];
        for (size_t k = 0; k < n; k++)
            x[k] = c[0] + 0.07 * ((double)k - (double)on);
        bad += disagree(b, x, n, c[1], c[2], 0.05 + 0.05 * (double)(t % 3), 24.0 / (4.0 * M_PI),
                        9.0, &nonzero);
        points += n;
    }
    TAP_CHECK(bad == 0 && nonzero > points / 10,
              "a point on a triangle among others: the ways agree (%zu of %zu differ, %zu set)",
              bad, points, nonzero);
    st_bvh_free(b);
    st_soup_free(s);
}

/* The sides' evidence over a grid (blocks of rows, stretches along x,
 * runs of voxels): at every voxel that takes it, the sum's at its center;
 * 0 at the others. The grid is not a multiple of the blocks along x or y;
 * random values and votes leave voxels out of the band and decided, and
 * then every voxel takes it (full runs, rows and blocks: all rows of a
 * block taking it, runs as long as they go). */
static void grid_case(int full)
{
    st_soup *s = bumpy(40, 20, 0.15, 0.6);
    st_bvh *b = bvh_of(s);
    st_grid *g = NULL;
    st_error err;
    const double origin[3] = {-1.37, -1.29, -1.23};
    TAP_CHECK(st_grid_new(&g, 53, 27, 25, origin, 0.1, 0.0f, 0, &err) == ST_OK, "grid");
    const size_t n = g ? st_grid_count(g) : 0;
    uint8_t *votes = malloc(n ? n : 1);
    int8_t *e = calloc(n ? n : 1, 1);
    size_t bad = 0, taken = 0, nonzero = 0;
    if (g && votes && e && b) {
        for (size_t i = 0; i < n; i++) {
            g->data[i] = full ? 0.05f : (float)uniform(0.0, 0.4);
            votes[i] = full ? 13 : (uint8_t)uniform(0.0, 27.0);
        }
        const st_sides_params p = st_sides_params_default();
        const double r = p.radius_voxels * g->voxel, scale = p.weight / (4.0 * M_PI);
        const size_t count = st_sides_winding_grid(e, g, votes, 10, b, &p);
        for (size_t z = 0; z < g->nz; z++)
            for (size_t y = 0; y < g->ny; y++)
                for (size_t x = 0; x < g->nx; x++) {
                    const size_t i = st_grid_index(g, x, y, z);
                    const int margin = (int)(votes[i] & ST_SIGN_VOTES_COUNT) - 13;
                    const int take = g->data[i] < (float)(p.band_voxels * g->voxel) &&
                                     abs(margin) < 10;
                    int8_t want = 0;
                    if (take) {
                        const double q[3] = {origin[0] + 0.1 * (double)x,
                                             origin[1] + 0.1 * (double)y,
                                             origin[2] + 0.1 * (double)z};
                        st_sides_winding_points(&want, b, q, 1, q[1], q[2], r, scale,
                                                (double)p.max_evidence, 0);
                    }
                    bad += e[i] != want;
                    taken += (size_t)take;
                    nonzero += e[i] != 0;
                }
        TAP_CHECK(count == taken, "the voxels that take evidence: %zu of %zu", count, taken);
    }
    TAP_CHECK(bad == 0 && taken > n / 4 && (full ? taken == n : taken < n) && nonzero > n / 20,
              "%s: every voxel as the sum at its center (%zu of %zu differ, %zu taken, %zu set)",
              full ? "all taking it" : "random", bad, n, taken, nonzero);
    free(votes);
    free(e);
    st_grid_free(g);
    st_bvh_free(b);
    st_soup_free(s);
}

static void test_grid(void)
{
    grid_case(0);
    grid_case(1);
}

/* The same soup and rows scaled by s (coordinates, boxes): the terms
 * are taken times a power of two near 1 / r^3 (sides.c term_unit), so
 * the product seldom needs a rescale. Scaled by a power of two the
 * evidence is the unscaled one, by all three ways (every operation
 * scales exactly); scaled far (terms underflowing, overflowing) the ways
 * agree. Boxes of half-side down to 2^-700 around points on the
 * triangles (terms near 1, a unit past the range of doubles unless it
 * is bounded): the ways agree. */
static void test_scales(void)
{
    const double by[5] = {0x1p-40, 0x1p+37, 0x1p-700, 1e-200, 3e120};
    st_soup *s0 = bumpy(40, 20, 0.15, 0.6);
    st_bvh *b0 = bvh_of(s0);
    for (int f = 0; f < 5; f++) {
        st_soup *s = bumpy(40, 20, 0.15, 0.6);
        for (size_t i = 0; i < 3 * s->nverts; i++)
            s->xyz[i] *= by[f];
        st_bvh *b = bvh_of(s);
        size_t bad = 0, moved = 0, nonzero = 0, points = 0;
        for (int i = 0; i < 400 && b && b0; i++) {
            const size_t n = 1 + (size_t)uniform(0.0, 8.0);
            const double r = uniform(0.02, 0.8), step = uniform(0.01, 0.2);
            double x[16], xs[16];
            x[0] = uniform(-1.4, 1.4);
            for (size_t k = 1; k < n; k++)
                x[k] = x[k - 1] + step * (double)(1 + (k % 2));
            for (size_t k = 0; k < n; k++)
                xs[k] = x[k] * by[f];
            const double y = uniform(-1.3, 1.3), z = uniform(-1.3, 1.3);
            const double scale = 24.0 / (4.0 * M_PI);
            bad += disagree(b, xs, n, y * by[f], z * by[f], r * by[f], scale, 9.0, &nonzero);
            if (f < 2) {
                int8_t e0[16], e[16];
                st_sides_winding_points(e0, b0, x, n, y, z, r, scale, 9.0, 0);
                for (int how = 0; how < 3; how++) {
                    st_sides_winding_points(e, b, xs, n, y * by[f], z * by[f], r * by[f], scale,
                                            9.0, how);
                    for (size_t k = 0; k < n; k++)
                        moved += e[k] != e0[k];
                }
            }
            points += n;
        }
        TAP_CHECK(bad == 0 && moved == 0 && (f > 1 || nonzero > points / 10),
                  "scaled by %g: the ways agree (%zu of %zu points differ, %zu moved, %zu set)",
                  by[f], bad, points, moved, nonzero);
        st_bvh_free(b);
        st_soup_free(s);
    }
    for (int f = 0; f < 3; f++) {
        const double r = f == 0 ? 0x1p-100 : f == 1 ? 0x1p-400 : 0x1p-700;
        size_t bad = 0, nonzero = 0;
        for (size_t t = 0; t < s0->ntris && b0; t++) {
            const uint32_t *v = s0->tris + 3 * t;
            double c[3];
            for (int k = 0; k < 3; k++)
                c[k] = (s0->xyz[3 * v[0] + k] + s0->xyz[3 * v[1] + k] + s0->xyz[3 * v[2] + k]) /
                       3.0;
            const double x[2] = {c[0], c[0] + 2.0 * r};
            bad += disagree(b0, x, 2, c[1], c[2], r, 24.0 / (4.0 * M_PI), 9.0, &nonzero);
        }
        TAP_CHECK(bad == 0 && nonzero > s0->ntris / 2,
                  "boxes of half-side %g on the triangles: the ways agree (%zu of %zu differ, "
                  "%zu set)", r, bad, 2 * s0->ntris, nonzero);
    }
    st_bvh_free(b0);
    st_soup_free(s0);
}

static const tap_test all_tests[] = {TAP_TEST(closed), TAP_TEST(agree), TAP_TEST(threshold),
                                     TAP_TEST(together), TAP_TEST(grid), TAP_TEST(scales), {0}};

int main(int argc, char **argv)
{
    return tap_main(argc, argv, all_tests);
}
