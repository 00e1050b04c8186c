/*
 * gwn - a peer for the accuracy stage of `make bench`: the generalized
 * winding number (Jacobson, Kavan and Sorkine-Hornung 2013) of the damaged
 * soup, thresholded at 1/2, against the solid of the undamaged model.
 *
 *   gwn [--step S] SHELL [SHELL...] -- SOUP [SOUP...] -- FIELD [FIELD...]
 *
 * The winding number of an oriented soup sums its triangles' signed solid
 * angles (Van Oosterom and Strackee) about a point; where the soup is
 * closed it is the exact inside, and on holes and deleted faces it degrades
 * gracefully, which is why it is the usual answer for damaged meshes. It
 * needs the soup's orientation, which soupsign does not read (so this peer
 * is only meaningful where the damage kept the faces' orientation: holes,
 * deleted faces, interpenetrating copies). It is summed exactly over every
 * triangle (no hierarchy), so it is evaluated at every S-th voxel center
 * along each axis (default 4) of the FIELDs' grid; the truth is the
 * shells' winding number (solid.h), as in bench/iou, and every FIELD's IoU
 * is measured at the same samples, as IoU and as core IoU (the samples
 * whose six neighbouring voxels all have the sample's own true side, as in
 * bench/iou: the metric of issue 17's targets). One JSON object per line on stdout:
 * the peer's first ("field": "gwn"), then one per FIELD.
 */
#include "souptet/gridio.h"
#include "souptet/soup.h"
#include "souptet/solid.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

/* The signed solid angle of triangle (a b c) seen from p. */
static double solid_angle(const double p[3], const double *a, const double *b, const double *c)
{
    double x[3], y[3], z[3];
    for (int k = 0; k < 3; k++) {
        x[k] = a[k] - p[k];
        y[k] = b[k] - p[k];
        z[k] = c[k] - p[k];
    }
    const double lx = sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]);
    const double ly = sqrt(y[0] * y[0] + y[1] * y[1] + y[2] * y[2]);
    const double lz = sqrt(z[0] * z[0] + z[1] * z[1] + z[2] * z[2]);
    const double det = x[0] * (y[1] * z[2] - y[2] * z[1]) - x[1] * (y[0] * z[2] - y[2] * z[0]) +
                       x[2] * (y[0] * z[1] - y[1] * z[0]);
    const double den = lx * ly * lz + (x[0] * y[0] + x[1] * y[1] + x[2] * y[2]) * lz +
                       (y[0] * z[0] + y[1] * z[1] + y[2] * z[2]) * lx +
                       (z[0] * x[0] + z[1] * x[1] + z[2] * x[2]) * ly;
    return 2.0 * atan2(det, den);
}

/* Whether voxel (i, j, k)'s six neighbours all have its own true side
 * (bench/iou's core: the voxels within a voxel of the true boundary are
 * left out of the core IoU). */
static int core_voxel(const uint8_t *truth, const st_grid *g, size_t i, size_t j, size_t k)
{
    const size_t id = st_grid_index(g, i, j, k), sx = 1, sy = g->nx, sz = g->nx * g->ny;
    const uint8_t t = truth[id] != 0;
    if ((i > 0 && (truth[id - sx] != 0) != t) || (i + 1 < g->nx && (truth[id + sx] != 0) != t) ||
        (j > 0 && (truth[id - sy] != 0) != t) || (j + 1 < g->ny && (truth[id + sy] != 0) != t) ||
        (k > 0 && (truth[id - sz] != 0) != t) || (k + 1 < g->nz && (truth[id + sz] != 0) != t))
        return 0;
    return 1;
}

static void print_iou(const char *name, size_t both, size_t t, size_t f, size_t core_both,
                      size_t core_either)
{
    const size_t uni = t + f - both;
    printf("{\"field\": \"%s\", \"iou\": %.6f, \"precision\": %.6f, \"recall\": %.6f, "
           "\"core_iou\": %.6f}\n",
           name, uni ? (double)both / (double)uni : 1.0, f ? (double)both / (double)f : 1.0,
           t ? (double)both / (double)t : 1.0,
           core_either ? (double)core_both / (double)core_either : 1.0);
}

int main(int argc, char **argv)
{
    int first = 1;
    size_t step = 4;
    if (argc > 2 && strcmp(argv[1], "--step") == 0) {
        step = (size_t)strtoul(argv[2], NULL, 10);
        first = 3;
    }
    int sep1 = 0, sep2 = 0;
    for (int i = first; i < argc; i++)
        if (strcmp(argv[i], "--") == 0) {
            if (!sep1)
                sep1 = i;
            else if (!sep2)
                sep2 = i;
        }
    if (step < 1 || sep1 <= first || sep2 <= sep1 + 1 || sep2 == argc - 1) {
        fprintf(stderr, "usage: gwn [--step S] SHELL... -- SOUP... -- FIELD...\n");
        return 2;
    }
    st_error err;
    st_error_clear(&err);
    const int nshell = sep1 - first, nsoup = sep2 - sep1 - 1, nfield = argc - sep2 - 1;
    st_soup **shells = calloc((size_t)nshell, sizeof *shells);
    st_soup **soups = calloc((size_t)nsoup, sizeof *soups);
    st_grid **fields = calloc((size_t)nfield, sizeof *fields);
    if (!shells || !soups || !fields)
        return 1;
    for (int i = 0; i < nshell; i++)
        if (st_soup_read(&shells[i], argv[first + i], &err))
            goto fail;
    for (int i = 0; i < nsoup; i++)
        if (st_soup_read(&soups[i], argv[sep1 + 1 + i], &err))
            goto fail;
    for (int i = 0; i < nfield; i++) {
        if (st_grid_read(&fields[i], argv[sep2 + 1 + i], 0, &err))
            goto fail;
        if (st_grid_count(fields[i]) != st_grid_count(fields[0])) {
            fprintf(stderr, "gwn: %s is not on the grid of %s\n", argv[sep2 + 1 + i],
                    argv[sep2 + 1]);
            return 1;
        }
    }
    const st_grid *g = fields[0];
    const size_t n = st_grid_count(g);
    uint8_t *truth = malloc(n);
    if (!truth || st_solid_inside(truth, g, (const st_soup *const *)shells, (size_t)nshell,
                                  ST_SOLID_NONZERO, &err))
        goto fail;
    const size_t sx = (g->nx + step - 1) / step, sy = (g->ny + step - 1) / step,
                 sz = (g->nz + step - 1) / step, ns = sx * sy * sz;
    uint8_t *peer = malloc(ns);
    if (!peer)
        return 1;
    #pragma omp parallel for schedule(dynamic, 16)
    for (size_t q = 0; q < ns; q++) {
        const size_t i = step * (q % sx), j = step * (q / sx % sy), k = step * (q / (sx * sy));
        const double p[3] = {g->origin[0] + g->voxel * (double)i,
                             g->origin[1] + g->voxel * (double)j,
                             g->origin[2] + g->voxel * (double)k};
        double w = 0.0;
        for (int s = 0; s < nsoup; s++)
            for (size_t t = 0; t < soups[s]->ntris; t++) {
                const uint32_t *v = soups[s]->tris + 3 * t;
                w += solid_angle(p, soups[s]->xyz + 3 * (size_t)v[0],
                                 soups[s]->xyz + 3 * (size_t)v[1],
                                 soups[s]->xyz + 3 * (size_t)v[2]);
            }
        peer[q] = fabs(w) / (4.0 * M_PI) >= 0.5;
    }
    for (int f = -1; f < nfield; f++) {
        size_t both = 0, t = 0, in = 0, core_both = 0, core_either = 0;
        for (size_t q = 0; q < ns; q++) {
            const size_t i = step * (q % sx), j = step * (q / sx % sy), k = step * (q / (sx * sy));
            const size_t id = st_grid_index(g, i, j, k);
            const int a = truth[id] != 0, b = f < 0 ? peer[q] : fields[f]->data[id] < 0.0f;
            both += (size_t)(a & b);
            t += (size_t)a;
            in += (size_t)b;
            if (core_voxel(truth, g, i, j, k)) {
                core_both += (size_t)(a & b);
                core_either += (size_t)(a | b);
            }
        }
        print_iou(f < 0 ? "gwn" : argv[sep2 + 1 + f], both, t, in, core_both, core_either);
    }
    return 0;
fail:
    fprintf(stderr, "gwn: %s%s%s\n", err.file[0] ? err.file : "", err.file[0] ? ": " : "", err.msg);
    return 1;
}
