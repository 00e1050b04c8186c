/*
 * cubetets.h - what the tet-mesh tests build their meshes from (header
 * only): points one at a time, positive tets, the 5-tet cube lattice,
 * three tets on one face, the tets that are not positive, the volume.
 */
#ifndef SOUPTET_TESTS_CUBETETS_H
#define SOUPTET_TESTS_CUBETETS_H

#include <stdint.h>
#include "souptet/pred.h"
#include "souptet/tetmesh.h"
#include "souptet/tetqual.h"

static inline void add_pt(st_tetmesh *m, double x, double y, double z)
{
    const double p[3] = {x, y, z};
    st_tetmesh_add_point(m, p, NULL);
}

/* Adds tet (a b c d), swapping c and d when that makes it positive. */
static inline void add_pos(st_tetmesh *m, uint32_t a, uint32_t b, uint32_t c, uint32_t d)
{
    const double *x = m->xyz;
    if (st_tet_volume(x + 3 * a, x + 3 * b, x + 3 * c, x + 3 * d) < 0)
        st_tetmesh_add_tet(m, a, b, d, c, NULL);
    else
        st_tetmesh_add_tet(m, a, b, c, d, NULL);
}

/* The tets of nx x ny x nz cubes over the (nx+1)(ny+1)(nz+1) points of m
 * from point base on (x fastest, then y, then z): 5 positive tets a cube,
 * the middle one first, the split mirrored on alternating cubes so that
 * shared faces match. Cube corner q is (q&1, q>>1&1, q>>2&1): even cubes
 * have the middle tet on corners 1 2 4 7, odd cubes on 0 3 5 6; a corner
 * tet is a corner and its three neighbours along the edges. */
static inline void add_cube_tets(st_tetmesh *m, uint32_t base, int nx, int ny, int nz)
{
    static const int mid[2][4] = {{1, 2, 4, 7}, {0, 3, 5, 6}};
    static const int corners[2][4] = {{0, 3, 5, 6}, {1, 2, 4, 7}};
    for (int k = 0; k < nz; k++)
        for (int j = 0; j < ny; j++)
            for (int i = 0; i < nx; i++) {
                uint32_t c[8];
                for (int q = 0; q < 8; q++) {
                    int ii = i + (q & 1), jj = j + (q >> 1 & 1), kk = k + (q >> 2 & 1);
                    c[q] = base + (uint32_t)(ii + (nx + 1) * (jj + (ny + 1) * kk));
                }
                const int odd = (i + j + k) & 1;
                add_pos(m, c[mid[odd][0]], c[mid[odd][1]], c[mid[odd][2]], c[mid[odd][3]]);
                for (int q = 0; q < 4; q++) {
                    int a = corners[odd][q];
                    add_pos(m, c[a], c[a ^ 1], c[a ^ 2], c[a ^ 4]);
                }
            }
}

/* A 5-tet cube lattice of n^3 cells of width h from lo, keeping the cells
 * for which keep(center) is nonzero (NULL: all); mirrored splits on
 * alternating cells so shared faces match; every tet positive (by the
 * exact orient3d), the four corner tets of a cell before its middle one;
 * unused points dropped. */
static inline st_tetmesh *lattice5(int n, double h, const double lo[3],
                            int (*keep)(const double c[3], void *), void *ctx)
{
    st_tetmesh *m = st_tetmesh_new();
    int np = n + 1;
    for (int k = 0; k < np; k++)
        for (int j = 0; j < np; j++)
            for (int i = 0; i < np; i++) {
                double p[3] = {lo[0] + i * h, lo[1] + j * h, lo[2] + k * h};
                st_tetmesh_add_point(m, p, NULL);
            }
    for (int k = 0; k < n; k++)
        for (int j = 0; j < n; j++)
            for (int i = 0; i < n; i++) {
                double c[3] = {lo[0] + (i + 0.5) * h, lo[1] + (j + 0.5) * h, lo[2] + (k + 0.5) * h};
                if (keep && !keep(c, ctx))
                    continue;
                uint32_t v[8];
                for (int b = 0; b < 8; b++)
                    v[b] = (uint32_t)((i + (b & 1)) + np * ((j + ((b >> 1) & 1)) + np * (k + ((b >> 2) & 1))));
                int odd = (i + j + k) & 1;
                /* corner tets at the even (or odd) corners, the middle one
                 * at the others */
                static const int even_c[4] = {0, 3, 5, 6}, odd_c[4] = {1, 2, 4, 7};
                const int *cor = odd ? odd_c : even_c, *mid = odd ? even_c : odd_c;
                uint32_t t[5][4];
                for (int q = 0; q < 4; q++) {
                    int cc = cor[q];
                    t[q][0] = v[cc];
                    t[q][1] = v[cc ^ 1];
                    t[q][2] = v[cc ^ 2];
                    t[q][3] = v[cc ^ 4];
                }
                for (int q = 0; q < 4; q++)
                    t[4][q] = v[mid[q]];
                for (int q = 0; q < 5; q++) {
                    const double *a = m->xyz + 3 * (size_t)t[q][0], *b = m->xyz + 3 * (size_t)t[q][1],
                                 *d = m->xyz + 3 * (size_t)t[q][2], *e = m->xyz + 3 * (size_t)t[q][3];
                    if (st_orient3d(a, b, d, e) > 0) {
                        uint32_t s = t[q][0];
                        t[q][0] = t[q][1];
                        t[q][1] = s;
                    }
                    st_tetmesh_add_tet(m, t[q][0], t[q][1], t[q][2], t[q][3], NULL);
                }
            }
    st_tetmesh_compact(m, NULL);
    return m;
}

/* Three positive tets on the triangle of points 0 1 2: a face of more than
 * two tets (not conforming), on nobody's boundary. */
static inline st_tetmesh *three_tets_on_a_face(void)
{
    st_tetmesh *m = st_tetmesh_new();
    add_pt(m, 0, 0, 0);
    add_pt(m, 1, 0, 0);
    add_pt(m, 0, 1, 0);
    add_pt(m, 0, 0, 1);
    add_pt(m, 0, 0, -1);
    add_pt(m, 0.2, 0.2, 2);
    add_pos(m, 0, 1, 2, 3);
    add_pos(m, 0, 1, 2, 4);
    add_pos(m, 0, 1, 2, 5);
    return m;
}

/* The tets of m that are not positive (exact orient3d; souptet's positive
 * tets have orient3d < 0). */
static inline size_t nonpositive(const st_tetmesh *m)
{
    size_t bad = 0;
    for (size_t t = 0; t < m->ntets; t++) {
        const uint32_t *k = m->tets + 4 * t;
        bad += !(st_orient3d(m->xyz + 3 * (size_t)k[0], m->xyz + 3 * (size_t)k[1],
                             m->xyz + 3 * (size_t)k[2], m->xyz + 3 * (size_t)k[3]) < 0);
    }
    return bad;
}

/* The signed volume of m: its tets' volumes summed in order. */
static inline double mesh_volume(const st_tetmesh *m)
{
    double v = 0.0;
    for (size_t t = 0; t < m->ntets; t++) {
        const uint32_t *k = m->tets + 4 * t;
        v += st_tet_volume(m->xyz + 3 * (size_t)k[0], m->xyz + 3 * (size_t)k[1],
                           m->xyz + 3 * (size_t)k[2], m->xyz + 3 * (size_t)k[3]);
    }
    return v;
}

#endif
