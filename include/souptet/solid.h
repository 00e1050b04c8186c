/*
 * solid.h - the exact solid of closed surfaces at voxel centers: ground
 * truth for measuring pseudo volumes.
 *
 * Units: the grid's model units; IoU, precision and recall are ratios.
 * Ownership: the caller owns the inside array (one byte a voxel); grids and
 * shells are borrowed.
 * Threads: OpenMP over rows; exact, so the same for any thread count.
 * Errors: ST_ELIMIT, ST_ENOMEM.
 *
 * A voxel center is inside a closed surface when a ray from it crosses the
 * surface an odd number of times. The ray runs along -x from the center
 * (so one pass over a row of voxels answers the whole row), and every
 * decision is exact: whether the ray's line passes through a triangle is
 * three st_orient2d signs in the (y, z) plane, and which voxel centers lie
 * beyond the triangle's plane is an st_orient3d sign. Rays through an edge,
 * a vertex or exactly along the surface are resolved by simulation of
 * simplicity: the query point is taken as (x + e^3, y + e, z + e^2) for an
 * infinitesimal e > 0, so a shared edge is counted for exactly one of its
 * triangles and a point exactly on the surface gets one consistent answer.
 *
 * Two rules. Parity (the count of crossings is odd) ignores orientation
 * and connectivity, but where a closed surface passes through itself it
 * cuts the overlap out. Nonzero winding (the signed count of crossings,
 * +1 where the ray meets a triangle from its back, -1 from its front, is
 * not zero) needs a consistently oriented surface, and then gives the
 * solid a person sees, overlaps included: the rule for the ground truth of
 * clean models, some of which (CGAL's man) intersect themselves. Either
 * way the surface must be closed (every edge used an even number of times)
 * for the answer to mean "inside". Shells are united: a voxel is inside
 * when it is inside any shell.
 */
#ifndef SOUPTET_SOLID_H
#define SOUPTET_SOLID_H

#include <stddef.h>
#include <stdint.h>

#include "souptet/err.h"
#include "souptet/grid.h"
#include "souptet/soup.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum st_solid_rule {
    ST_SOLID_NONZERO = 0,   /* winding number not zero (oriented shells) */
    ST_SOLID_PARITY         /* odd number of crossings (any orientation) */
} st_solid_rule;

/* inside[st_grid_index(g, i, j, k)] = 1 when voxel center (i, j, k) of g's
 * layout (g's values are not read) is inside any of the shells by the
 * rule, else 0. inside holds st_grid_count(g) bytes. OpenMP over rows; the
 * result does not depend on the thread count. Shells of more than
 * 2^31 - 1 triangles are refused (ST_ELIMIT: the winding count is 32-bit). */
st_status st_solid_inside(uint8_t *inside, const st_grid *g,
                          const st_soup *const *shells, size_t nshells,
                          st_solid_rule rule, st_error *err);

/* Compare a signed field's inside (value < 0) with a truth mask of the same
 * layout: IoU = |T and F| / |T or F|, precision = |T and F| / |F|, recall =
 * |T and F| / |T| (each 1 when its denominator is 0). */
st_status st_solid_iou(double *iou, double *precision, double *recall,
                       const uint8_t *truth, const st_grid *signed_field,
                       st_error *err);

#ifdef __cplusplus
}
#endif
#endif
