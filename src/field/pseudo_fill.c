/*
 * pseudo_fill.c - the fill: the part of the pseudo volume's boundary where
 * the soup has no surface (st_pseudo_fill, pseudo.h).
 *
 * The pseudo volume's boundary is the zero set of the signed field; on
 * the voxel grid, the faces between an inside and an outside voxel. Where
 * the soup passes between the two voxel centers, the soup is the surface
 * there. Where it does not, the sign changed without a surface: the vote,
 * the caps or a one-sided view's mirror closed the volume (the far side
 * of a one-sided scan, a large hole). Those faces are the fill. A face is
 * fill when no soup triangle comes within one voxel of its center: a soup
 * point on the segment between the two centers is within half a voxel of
 * it, so every face the soup explains is out, with half a voxel to spare
 * for the field's rounding. Each fill face is one voxel square, two
 * triangles, on the plane halfway between the centers.
 *
 * Faces are visited in grid order, so the fill does not depend on the
 * thread count (it runs serially: only the sign changes query the BVH).
 */
#include "../base/fpenv.h"
#include "souptet/pseudo.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>

static st_status add_square(st_soup *f, const double c[3], int axis, double half,
                            st_error *err)
{
    int u = (axis + 1) % 3, w = (axis + 2) % 3;
    size_t base = f->nverts;
    for (int q = 0; q < 4; q++) {
        double p[3] = {c[0], c[1], c[2]};
        p[u] += (q == 1 || q == 2) ? half : -half;
        p[w] += (q >= 2) ? half : -half;
        st_status rc = st_soup_add_vertex(f, p[0], p[1], p[2], err);
        if (rc)
            return rc;
    }
    uint32_t b = (uint32_t)base;
    st_status rc = st_soup_add_triangle(f, b, b + 1, b + 2, err);
    return rc ? rc : st_soup_add_triangle(f, b, b + 2, b + 3, err);
}

st_status st_pseudo_fill(st_soup **out, const st_grid *g, const st_bvh *bvh,
                         size_t *faces, st_error *err)
{
    *out = NULL;
    if (faces)
        *faces = 0;
    if (!g || !g->data || g->kind == ST_GRID_DISTANCE || !bvh)
        return st_error_set(err, ST_EINPUT, NULL, 0,
                            "the fill needs a signed field and the soup's BVH");
    st_soup *f = st_soup_new();
    if (!f)
        return st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory (fill)");
    const double v = g->voxel, reach2 = v * v;
    const size_t nx = g->nx, ny = g->ny, nz = g->nz;
    size_t count = 0;
    /* hints: the soup triangle found last at each column (the rows
     * before: the boundary passes near it), and the last found */
    uint32_t *col = malloc((nx + 1) * sizeof *col);
    if (!col) {
        st_soup_free(f);
        return st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory (fill)");
    }
    for (size_t i = 0; i <= nx; i++)
        col[i] = ST_BVH_NO_HINT;
    /* row by row: a voxel's sign and its three neighbours' above it (x,
     * y, z: the faces in that order, as before), most voxels passed over
     * at once (no neighbour differs) */
    for (size_t k = 0; k < nz; k++)
        for (size_t j = 0; j < ny; j++) {
            const float *row = g->data + nx * (j + ny * k);
            /* beyond the grid: the voxel's own row, which never differs */
            const float *up[3] = {row + 1, j + 1 < ny ? row + nx : row,
                                  k + 1 < nz ? row + nx * ny : row};
            for (size_t i = 0; i < nx; i++) {
                const int in = row[i] < 0.0f;
                const int dx = i + 1 < nx && (up[0][i] < 0.0f) != in;
                const int dy = (up[1][i] < 0.0f) != in, dz = (up[2][i] < 0.0f) != in;
                if (!(dx | dy | dz))
                    continue;
                const int differs[3] = {dx, dy, dz};
                for (int a = 0; a < 3; a++) {
                    if (!differs[a])
                        continue;
                    double c[3];
                    st_grid_center(g, i, j, k, c);
                    c[a] += 0.5 * v;
                    /* the first triangle within reach will do: st_bvh_within
                     * finds one exactly when the nearest search does; the
                     * one found for the face before, when it is within
                     * reach here too, says the same (st_bvh_within_hint) */
                    const uint32_t hints[2] = {col[i], col[nx]};
                    uint32_t found;
                    const int near = st_bvh_within_hint(bvh, c, reach2, hints, 2, &found);
                    if (found != ST_BVH_NO_HINT)
                        col[i] = col[nx] = found;
                    if (near)
                        continue;   /* the soup passes between them */
                    st_status rc = add_square(f, c, a, 0.5 * v, err);
                    if (rc) {
                        free(col);
                        st_soup_free(f);
                        return rc;
                    }
                    count++;
                }
            }
        }
    free(col);
    if (faces)
        *faces = count;
    *out = f;
    return ST_OK;
}

void st_pseudo_guess_measure(st_pseudo_guess *out, const st_grid *g, const st_soup *fill,
                             const st_bvh *bvh)
{
    size_t all = 0;
    const long long nz = (long long)g->nz;
    #pragma omp parallel for schedule(static) reduction(+ : all)
    for (long long kk = 0; kk < nz; kk++) {
        const size_t k = (size_t)kk;
        for (size_t j = 0; j < g->ny; j++)
            for (size_t i = 0; i < g->nx; i++) {
                const int in = g->data[st_grid_index(g, i, j, k)] < 0.0f;
                if (i + 1 < g->nx)
                    all += (g->data[st_grid_index(g, i + 1, j, k)] < 0.0f) != in;
                if (j + 1 < g->ny)
                    all += (g->data[st_grid_index(g, i, j + 1, k)] < 0.0f) != in;
                if (k + 1 < g->nz)
                    all += (g->data[st_grid_index(g, i, j, k + 1)] < 0.0f) != in;
            }
    }
    /* a square's two triangles are (b, b+1, b+2) and (b, b+2, b+3)
     * (add_square): b and b+2 are opposite corners */
    /* the depth: the largest of the squares' centers' distances to the
     * soup. A center with a triangle closer than the largest so far (in
     * its thread) cannot raise it, and st_bvh_within tells that at the
     * first such triangle (where the nearest search would look on); the
     * others are measured as before. The largest is the same whatever
     * the threads took. */
    const long long nsq = fill && bvh ? (long long)(fill->ntris / 2) : 0;
    double depth2 = 0.0;
    #pragma omp parallel for schedule(dynamic, 256) reduction(max : depth2)
    for (long long q = 0; q < nsq; q++) {
        const uint32_t *t = fill->tris + 6 * (size_t)q;
        const double *a = fill->xyz + 3 * (size_t)t[0], *c = fill->xyz + 3 * (size_t)t[2];
        const double m[3] = {0.5 * (a[0] + c[0]), 0.5 * (a[1] + c[1]), 0.5 * (a[2] + c[2])};
        if (depth2 > 0.0 && st_bvh_within(bvh, m, depth2))
            continue;
        int64_t tri;
        const double d2 = st_bvh_nearest(bvh, m, INFINITY, &tri, NULL);
        depth2 = d2 > depth2 ? d2 : depth2;
    }
    out->boundary_faces = all;
    out->fill_faces = (size_t)nsq;
    out->depth = sqrt(depth2);
    out->symmetric_faces = 0;
}

st_status st_pseudo_guess_symmetric(st_pseudo_guess *out, const st_grid *g,
                                    const st_soup *fill, const st_soup *sym, st_error *err)
{
    out->symmetric_faces = 0;
    if (!fill || !sym || !fill->ntris || !sym->ntris)
        return ST_OK;
    st_bvh *b = NULL;
    st_status rc = st_bvh_build(&b, sym, err);
    if (rc)
        return rc;
    const double reach2 = g->voxel * g->voxel;
    const long long nsq = (long long)(fill->ntris / 2);
    size_t near = 0;
    #pragma omp parallel for schedule(dynamic, 256) reduction(+ : near)
    for (long long q = 0; q < nsq; q++) {
        const uint32_t *t = fill->tris + 6 * (size_t)q;
        const double *a = fill->xyz + 3 * (size_t)t[0], *c = fill->xyz + 3 * (size_t)t[2];
        const double m[3] = {0.5 * (a[0] + c[0]), 0.5 * (a[1] + c[1]), 0.5 * (a[2] + c[2])};
        near += (size_t)st_bvh_within(b, m, reach2);
    }
    st_bvh_free(b);
    out->symmetric_faces = near;
    return ST_OK;
}
