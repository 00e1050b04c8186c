/*
 * shapes.h - small closed and damaged test surfaces built in code (header
 * only, for the unit tests): exact soups of boxes, UV spheres read from
 * fixtures in tests/data, and signed fields of shapes given by a function.
 */
#ifndef SOUPTET_TESTS_SHAPES_H
#define SOUPTET_TESTS_SHAPES_H

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

#include "souptet/grid.h"
#include "souptet/soup.h"
#include "tap.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

static inline void add_tri(st_soup *s, const double a[3], const double b[3], const double c[3], int flip)
{
    uint32_t v = (uint32_t)s->nverts;
    st_soup_add_vertex(s, a[0], a[1], a[2], NULL);
    st_soup_add_vertex(s, b[0], b[1], b[2], NULL);
    st_soup_add_vertex(s, c[0], c[1], c[2], NULL);
    if (flip)
        st_soup_add_triangle(s, v, v + 2, v + 1, NULL);
    else
        st_soup_add_triangle(s, v, v + 1, v + 2, NULL);
}

/* The 12 triangles of an axis-aligned box: every other one flipped, or
 * (oriented) all with their normals outward. */
static inline void box_triangles(st_soup *s, const double lo[3], const double hi[3],
                                 int oriented)
{
    for (int axis = 0; axis < 3; axis++)
        for (int side = 0; side < 2; side++) {
            int u = (axis + 1) % 3, w = (axis + 2) % 3;
            double q[4][3];
            for (int c = 0; c < 4; c++) {
                q[c][axis] = side ? hi[axis] : lo[axis];
                q[c][u] = (c == 1 || c == 2) ? hi[u] : lo[u];
                q[c][w] = (c >= 2) ? hi[w] : lo[w];
            }
            /* (q0, q1, q2) faces +axis: oriented, flip it on the low side. */
            add_tri(s, q[0], q[1], q[2], oriented ? !side : side);
            add_tri(s, q[0], q[2], q[3], !side);
        }
}

/* An axis-aligned box as an exact soup, every other triangle flipped. */
static inline void add_box(st_soup *s, const double lo[3], const double hi[3])
{
    box_triangles(s, lo, hi, 0);
}

/* An axis-aligned box, consistently oriented (normals outward). */
static inline void add_box_oriented(st_soup *s, const double lo[3], const double hi[3])
{
    box_triangles(s, lo, hi, 1);
}

/* A signed field on [-w, w]^3 in n^3 voxels: f(center, arg) at each
 * voxel (NULL when it cannot be allocated). */
static inline st_grid *signed_grid(size_t n, double w,
                                   double (*f)(const double c[3], double arg), double arg)
{
    double vox = 2.0 * w / (double)n;
    double o[3] = {-w + vox / 2, -w + vox / 2, -w + vox / 2};
    st_grid *g = NULL;
    st_error err;
    if (st_grid_new(&g, n, n, n, o, vox, 0.0f, 0, &err))
        return NULL;
    g->kind = ST_GRID_SIGNED;
    for (size_t k = 0; k < n; k++)
        for (size_t j = 0; j < n; j++)
            for (size_t i = 0; i < n; i++) {
                double c[3];
                st_grid_center(g, i, j, k, c);
                g->data[st_grid_index(g, i, j, k)] = (float)f(c, arg);
            }
    return g;
}

/* A UV sphere of radius r at the origin, without the faces above z_cut:
 * the fixture tests/data/sphere_uv32x16.off (32 x 16 quads, every other
 * triangle flipped, its south pole 32 points 1e-16 apart: the tests are
 * tuned to it as it is, so it is a file, where a fix shows). Radius 0.3
 * has its own file (r sin cos rounds otherwise than a scaled unit
 * sphere); any other r must be a power of 2, for which scaling is exact.
 * Each triangle keeps its own three vertices, in the file's order. */
static inline void add_sphere(st_soup *s, double r, double z_cut)
{
    const char *name = r == 0.3 ? "sphere_uv32x16_r0.3.off" : "sphere_uv32x16.off";
    double scale = r == 0.3 ? 1.0 : r;
    int e;
    if (r != 0.3 && (!(r > 0) || frexp(r, &e) != 0.5)) {
        printf("Bail out! add_sphere: no fixture for radius %.17g\n", r);
        fflush(stdout);   /* LeakSanitizer's exit does not flush it */
        exit(1);
    }
    st_soup *f = NULL;
    st_error err;
    if (st_soup_read(&f, tap_data(name), &err) != ST_OK || f->nverts != 3 * f->ntris) {
        printf("Bail out! add_sphere: %s: %s\n", tap_data(name),
               f ? "not one vertex triple a triangle" : err.msg);
        fflush(stdout);   /* LeakSanitizer's exit does not flush it */
        exit(1);
    }
    for (size_t t = 0; t < f->ntris; t++) {
        const double *v = f->xyz + 9 * t;
        if (v[2] * scale > z_cut || v[5] * scale > z_cut || v[8] * scale > z_cut)
            continue;
        uint32_t n = (uint32_t)s->nverts;
        for (int k = 0; k < 3; k++)
            st_soup_add_vertex(s, v[3 * k] * scale, v[3 * k + 1] * scale,
                               v[3 * k + 2] * scale, NULL);
        const uint32_t *tri = f->tris + 3 * t;
        uint32_t b = (uint32_t)(3 * t);
        st_soup_add_triangle(s, n + tri[0] - b, n + tri[1] - b, n + tri[2] - b, NULL);
    }
    st_soup_free(f);
}

#endif
