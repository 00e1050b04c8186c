/* test_dist_lower.c - st_dist_lower (caps and fill lowered into a field)
 * against the plain walk: every triangle measured at every voxel of its
 * box grown by the reach, bit for bit, for any number of threads. */
#include "souptet/dist.h"
#include "souptet/geom.h"
#include "souptet/grid.h"
#include "souptet/soup.h"
#include "tap.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#ifdef _OPENMP
#include <omp.h>
#endif

/* The reference: st_dist_lower before its culls, every triangle at every
 * voxel of its box grown by reach. */
static void plain_lower(st_grid *g, const st_soup *s, double reach)
{
    const double h = g->voxel;
    for (size_t k = 0; k < g->nz; k++) {
        const double z = g->origin[2] + h * (double)k;
        for (size_t t = 0; t < s->ntris; t++) {
            const double *v[3];   /* corners; the box grown by reach */
            double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
            for (int corner = 0; corner < 3; corner++) {
                v[corner] = s->xyz + 3 * (size_t)s->tris[3 * t + corner];
                for (int q = 0; q < 3; q++) {
                    lo[q] = fmin(lo[q], v[corner][q]);
                    hi[q] = fmax(hi[q], v[corner][q]);
                }
            }
            for (int q = 0; q < 3; q++) {
                lo[q] -= reach;
                hi[q] += reach;
            }
            if (z < lo[2] || z > hi[2])
                continue;
            const double i0 = fmax(0.0, ceil((lo[0] - g->origin[0]) / h));
            const double i1 = fmin((double)(g->nx - 1), floor((hi[0] - g->origin[0]) / h));
            const double j0 = fmax(0.0, ceil((lo[1] - g->origin[1]) / h));
            const double j1 = fmin((double)(g->ny - 1), floor((hi[1] - g->origin[1]) / h));
            for (double j = j0; j <= j1; j++)
                for (double i = i0; i <= i1; i++) {
                    const double p[3] = {g->origin[0] + h * i, g->origin[1] + h * j, z};
                    const double d2 = st_point_triangle_dist2(p, v[0], v[1], v[2], NULL);
                    float *val = g->data + st_grid_index(g, (size_t)i, (size_t)j, k);
                    if (d2 < reach * reach && (float)sqrt(d2) < *val)
                        *val = (float)sqrt(d2);
                }
        }
    }
}

static unsigned rng = 4242;
static double urand(void)
{
    rng = rng * 1103515245u + 12345u;
    return (double)((rng >> 8) & 0xffffff) / 16777216.0;
}

static void add_tri(st_soup *s, const double p[3][3])
{
    const uint32_t v = (uint32_t)s->nverts;
    for (int k = 0; k < 3; k++)
        st_soup_add_vertex(s, p[k][0], p[k][1], p[k][2], NULL);
    st_soup_add_triangle(s, v, v + 1, v + 2, NULL);
}

/* Triangles of every kind the caps and the fill have: small and many,
 * overlapping (copies moved by less than a voxel), large and oblique (a
 * CAD cap), in a voxel plane or along a row (the plane's normal across
 * the rows), degenerate (a sliver, a point), and reaching past the grid. */
static st_soup *mixed_soup(void)
{
    st_soup *s = st_soup_new();
    for (int t = 0; t < 300; t++) {
        double p[3][3];
        const double c[3] = {1.2 * urand() - 0.1, 1.2 * urand() - 0.1, 1.2 * urand() - 0.1};
        const double size = t % 10 == 0 ? 0.9 : 0.02 + 0.06 * urand();
        for (int k = 0; k < 3; k++)
            for (int a = 0; a < 3; a++)
                p[k][a] = c[a] + size * (urand() - 0.5);
        if (t % 13 == 0)   /* in the plane z = 0.5: on a voxel layer */
            p[0][2] = p[1][2] = p[2][2] = 0.5;
        if (t % 17 == 0)   /* along x: its normal across the rows */
            p[1][1] = p[0][1], p[1][2] = p[0][2];
        if (t % 19 == 0)   /* a sliver: its third corner on its first edge */
            for (int a = 0; a < 3; a++)
                p[2][a] = 0.5 * (p[0][a] + p[1][a]);
        if (t % 23 == 0)   /* a point */
            memcpy(p[1], p[0], sizeof p[0]), memcpy(p[2], p[0], sizeof p[0]);
        add_tri(s, p);
        if (t % 3 == 0) {  /* an overlapping copy, moved a little */
            for (int k = 0; k < 3; k++)
                for (int a = 0; a < 3; a++)
                    p[k][a] += 0.004 * (urand() - 0.5);
            add_tri(s, p);
        }
    }
    return s;
}

/* A 40^3 grid over [0, 1]^3 holding a field to lower: random values,
 * some zero, some infinite, some below any distance. */
static st_grid *start_grid(void)
{
    st_grid *g = NULL;
    const double o[3] = {0.0, 0.0, 0.0};
    if (st_grid_new(&g, 40, 40, 40, o, 1.0 / 39.0, 1.0f, 0, NULL))
        return NULL;
    for (size_t i = 0; i < st_grid_count(g); i++) {
        const double r = urand();
        g->data[i] = i % 97 == 0 ? 0.0f : i % 89 == 0 ? INFINITY : (float)(0.12 * r);
    }
    return g;
}

static void test_lower_exact(void)
{
    st_soup *s = mixed_soup();
    st_grid *ref = start_grid(), *g = NULL;
    const double o[3] = {0.0, 0.0, 0.0};
    st_error err;
    TAP_CHECK(ref && !st_grid_new(&g, 40, 40, 40, o, ref->voxel, 0.0f, 0, &err),
              "grids made");
    if (!ref || !g)
        goto out;
    const size_t n = st_grid_count(ref);
    for (int r = 0; r < 3; r++) {
        const double reach = (r == 0 ? 1.0 : r == 1 ? 3.0 : 7.5) * ref->voxel;
        const st_grid *start = start_grid();
        memcpy(ref->data, start->data, n * sizeof(float));
        plain_lower(ref, s, reach);
        size_t lowered = 0;
        for (size_t i = 0; i < n; i++)
            lowered += ref->data[i] != start->data[i];
        for (int threads = 1; threads <= 3; threads += 2) {
#ifdef _OPENMP
            omp_set_num_threads(threads);
#endif
            memcpy(g->data, start->data, n * sizeof(float));
            const st_status rc = st_dist_lower(g, s, reach, &err);
            size_t differ = 0;
            for (size_t i = 0; i < n; i++)
                differ += memcmp(g->data + i, ref->data + i, sizeof(float)) != 0;
            TAP_CHECK(rc == ST_OK && lowered > 1000 && differ == 0,
                      "reach %.1f voxels, %d threads: %zu voxels lowered, %zu differ from "
                      "the plain walk", reach / ref->voxel, threads, lowered, differ);
        }
        st_grid_free((st_grid *)start);
    }
out:
    st_grid_free(ref);
    st_grid_free(g);
    st_soup_free(s);
}

int main(int argc, char **argv)
{
    static const tap_test tests[] = {TAP_TEST(lower_exact), {0}};
    return tap_main(argc, argv, tests);
}
