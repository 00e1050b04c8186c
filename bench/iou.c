/*
 * iou - the pseudo volume against the solid of the undamaged model, for
 * `make bench`.
 *
 *   iou [--parity] SHELL [SHELL...] -- FIELD [FIELD...]
 *
 * SHELLs are the closed surfaces whose union is the true solid (one for
 * most damages, two for the interpenetrating copy), each consistently
 * oriented: a voxel is inside where a shell's winding number is not zero
 * (the corpus's clean models are checked oriented by damage-corpus; CGAL's
 * man passes through itself, where parity would cut the overlap out).
 * --parity uses crossing parity instead (for shells of any orientation). Every FIELD is a signed
 * field (soupsign's output) on the same grid; the truth is evaluated once at
 * its voxel centers with exact inside tests (solid.h) and each field's
 * inside (value < 0) is compared: one JSON object per field on stdout with
 * IoU, precision and recall, and the core IoU: the same over the voxels
 * whose six neighbours all have the voxel's own true side (the voxels
 * within a voxel of the true boundary left out, where a field of this
 * resolution cannot be held to either side).
 */
#include "souptet/gridio.h"
#include "souptet/soup.h"
#include "souptet/solid.h"

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* IoU over the voxels away from the true boundary (see above). */
static double core_iou(const uint8_t *truth, const st_grid *g)
{
    const size_t nx = g->nx, ny = g->ny, nz = g->nz;
    size_t both = 0, either = 0;
    for (size_t z = 0; z < nz; z++)
        for (size_t y = 0; y < ny; y++)
            for (size_t x = 0; x < nx; x++) {
                const size_t i = x + nx * (y + ny * z);
                const uint8_t t = truth[i] != 0;
                int edge = 0;
                if (x > 0) edge |= (truth[i - 1] != 0) != t;
                if (x + 1 < nx) edge |= (truth[i + 1] != 0) != t;
                if (y > 0) edge |= (truth[i - nx] != 0) != t;
                if (y + 1 < ny) edge |= (truth[i + nx] != 0) != t;
                if (z > 0) edge |= (truth[i - nx * ny] != 0) != t;
                if (z + 1 < nz) edge |= (truth[i + nx * ny] != 0) != t;
                if (edge)
                    continue;
                const int f = g->data[i] < 0.0f;
                both += t && f;
                either += t || f;
            }
    return either ? (double)both / (double)either : 1.0;
}

int main(int argc, char **argv)
{
    int sep = 0, first = 1;
    st_solid_rule rule = ST_SOLID_NONZERO;
    if (argc > 1 && strcmp(argv[1], "--parity") == 0) {
        rule = ST_SOLID_PARITY;
        first = 2;
    }
    for (int i = first; i < argc; i++)
        if (strcmp(argv[i], "--") == 0) {
            sep = i;
            break;
        }
    if (sep <= first || sep == argc - 1) {
        fprintf(stderr, "usage: iou [--parity] SHELL [SHELL...] -- FIELD [FIELD...]\n");
        return 2;
    }
    size_t nshells = (size_t)(sep - first);
    st_soup **shells = calloc(nshells, sizeof *shells);
    st_error err;
    if (!shells) {
        fprintf(stderr, "iou: out of memory\n");
        return 1;
    }
    for (size_t s = 0; s < nshells; s++)
        if (st_soup_read(&shells[s], argv[first + (int)s], &err)) {
            fprintf(stderr, "iou: %s: %s\n", argv[first + (int)s], err.msg);
            return 1;
        }
    uint8_t *truth = NULL;
    st_grid *layout = NULL;
    int rc = 0;
    for (int f = sep + 1; f < argc; f++) {
        st_grid *g;
        if (st_grid_read(&g, argv[f], 0, &err)) {
            fprintf(stderr, "iou: %s: %s\n", argv[f], err.msg);
            rc = 1;
            continue;
        }
        if (!layout || g->nx != layout->nx || g->ny != layout->ny || g->nz != layout->nz ||
            memcmp(g->origin, layout->origin, sizeof g->origin) || g->voxel != layout->voxel) {
            free(truth);
            truth = malloc(st_grid_count(g));
            if (!truth) {
                fprintf(stderr, "iou: out of memory for the ground truth\n");
                return 1;
            }
            if (st_solid_inside(truth, g, (const st_soup *const *)shells, nshells, rule, &err)) {
                fprintf(stderr, "iou: ground truth: %s\n", err.msg);
                return 1;
            }
            st_grid_free(layout);
            layout = g;
            g = NULL;
        }
        const st_grid *field = g ? g : layout;
        double iou, precision, recall;
        if (st_solid_iou(&iou, &precision, &recall, truth, field, &err)) {
            fprintf(stderr, "iou: %s: %s\n", argv[f], err.msg);
            rc = 1;
        } else {
            printf("{\"field\": \"%s\", \"iou\": %.6f, \"precision\": %.6f, \"recall\": %.6f, "
                   "\"core_iou\": %.6f}\n",
                   argv[f], iou, precision, recall, core_iou(truth, field));
        }
        st_grid_free(g);
    }
    free(truth);
    st_grid_free(layout);
    for (size_t s = 0; s < nshells; s++)
        st_soup_free(shells[s]);
    free(shells);
    return rc;
}
