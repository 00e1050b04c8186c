/*
 * dist.h - unsigned distance fields of triangle soups. The field the volume
 * events are read from (Spillmann 2006, section 3; section 2.2 for the
 * related work).
 *
 * Units: model units; voxel, pad and band in voxels where the parameter
 * says so.
 * Ownership: the caller owns the new grid (st_grid_free); the soup is
 * borrowed for the call.
 * Threads: OpenMP inside; the values are identical for any thread count
 * (below).
 * Errors: ST_EINPUT (bad parameters, an empty soup), ST_ELIMIT, ST_ENOMEM,
 * ST_ECANCELLED (progress.h); no grid on error.
 *
 * The grid covers the bounding box of the soup's triangles padded by `pad`
 * voxels on every side. With `cells` the voxel size is the longest side of
 * the box divided by cells (so `cells` voxels span it); with `voxel` it is
 * given. Voxel centers sample the field.
 *
 * Band mode: every voxel whose distance is below band * voxel holds that
 * distance exactly (to rounding of the float it is stored in); the others
 * hold band * voxel. Full mode (band = INFINITY): every voxel holds a
 * distance: within the default band exactly as above; beyond it, the
 * distance to the nearest of the triangles its neighbours found (a vector
 * distance transform over triangles, four raster sweeps). Such a value is
 * the exact distance to a real triangle, so never below the truth; it is
 * above the truth where the nearest triangle is nobody's neighbour's
 * nearest (measured: under 3% of the voxels, by at most 0.06 voxel, on the
 * bunny at 32 cells, where triangles are far smaller than voxels).
 *
 * Results are identical for any number of threads: each band voxel's value
 * is a minimum over triangles, which does not depend on the order of
 * evaluation, and the sweeps beyond the band run in one fixed order.
 */
#ifndef SOUPTET_DIST_H
#define SOUPTET_DIST_H

#include <stddef.h>
#include "souptet/bvh.h"
#include "souptet/err.h"
#include "souptet/grid.h"
#include "souptet/progress.h"
#include "souptet/soup.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The band a distance field gets by default, in voxels. A ray along any of
 * the 26 lattice directions passes a voxel center within sqrt(3)/2 voxels
 * of every surface it crosses, so three voxels hold every volume event the
 * sign voting looks for, with room to spare; the project allows no less. */
#define ST_DIST_DEFAULT_BAND 3.0
#define ST_DIST_MIN_BAND 3.0
#define ST_DIST_DEFAULT_CELLS 128

typedef struct st_dist_params {
    size_t cells;       /* voxels along the longest side; used if voxel == 0 */
    double voxel;       /* voxel size in model units; 0: from cells */
    long pad;           /* voxels of padding per side; < 0: the default */
    double band;        /* band in voxels (>= ST_DIST_MIN_BAND) or INFINITY */
    size_t max_bytes;   /* limit for the grid; 0: none */
} st_dist_params;

/* Parameters with every default filled in. */
st_dist_params st_dist_params_default(void);

/* The default padding for a band: enough that the outermost voxels lie
 * beyond the band (rays start outside the model, clamped) plus two. */
long st_dist_default_pad(double band);

/* Grid placement for soup s: dims, origin (center of voxel 0) and voxel
 * size. The box is centered in the grid. Errors: a soup without extent,
 * a voxel size that is not positive, a grid over max_bytes. */
st_status st_dist_layout(const st_soup *s, const st_dist_params *p,
                         size_t dims[3], double origin[3], double *voxel,
                         st_error *err);

/* Compute the unsigned distance field of s. *out gets a grid of kind
 * ST_GRID_DISTANCE with band (model units) set, and metadata "triangles",
 * "vertices", "band_voxels". */
st_status st_dist_field(st_grid **out, const st_soup *s,
                        const st_dist_params *p, const st_progress *progress,
                        st_error *err);

/* A soup with at least this many triangles per voxel of its grid is
 * dense: its band is found faster by a BVH's nearest-triangle walks, one
 * per voxel (st_dist_field_bvh), than by binning every triangle into the
 * bricks its band reaches. Measured (instructions, default band, the BVH
 * already built; doc/design/dist.md): the two cost the same between 0.3
 * (armadillo) and 0.7 (cheese, large CAD triangles) triangles per voxel;
 * at 1 the walks take 0.35-0.67 of the bricks' instructions on the
 * seven soups measured, at 10 a tenth. */
#define ST_DIST_BVH_TRIS_PER_VOXEL 1.0

/* 1 when st_dist_field_bvh would walk a BVH for soup s under p: a finite
 * band and at least ST_DIST_BVH_TRIS_PER_VOXEL triangles per voxel of the
 * grid st_dist_layout gives (0 when the layout fails: st_dist_field says
 * why). A caller that builds s's BVH anyway (st_pseudo_volume_bvh) builds
 * it first when this says so. */
int st_dist_wants_bvh(const st_soup *s, const st_dist_params *p);

/* st_dist_field, with bvh over s (st_bvh_build; may be NULL). With a BVH
 * and a finite band, each voxel's value is a minimum over the triangles a
 * depth-first walk of the BVH cannot rule out (nearer child first, boxes
 * against the best distance so far, with the same slack as the bricks'
 * ball tests), each measured as the brick pass measures it: the same
 * field as st_dist_field's (tests/test_dist_bvh.c compares them bit for
 * bit), without the bins. A full field (band INFINITY) or a NULL bvh
 * goes st_dist_field's way. Same errors; identical for any number of
 * threads. */
st_status st_dist_field_bvh(st_grid **out, const st_soup *s,
                            const st_dist_params *p, const st_bvh *bvh,
                            const st_progress *progress, st_error *err);

/* The same field with a finite band, stored by blocks (grid.h): only the
 * blocks within reach of the band are computed and stored, so a far
 * voxel costs nothing. Every voxel's value is st_dist_field's, for any
 * number of threads. max_bytes limits the dense size, as there. Errors
 * as st_dist_field's, and ST_EINPUT for band = INFINITY. */
st_status st_dist_field_blocks(st_grid_blocks **out, const st_soup *s,
                               const st_dist_params *p,
                               const st_progress *progress, st_error *err);

/* The field st_dist_field would make for s and p (the same layout, band
 * and metadata) with every voxel at the band's far value, the value
 * st_dist_field gives a voxel no triangle comes within the band of: no
 * distance is computed. For a caller that reads only signs it decides
 * without distances (the closed shells' solid: pseudo.h, signs_only).
 * p's band must be finite (ST_EINPUT otherwise); errors as
 * st_dist_layout's, ST_ENOMEM. */
st_status st_dist_field_far(st_grid **out, const st_soup *s,
                            const st_dist_params *p, st_error *err);

/* Lower g's values to the distance to s's triangles where that is below
 * `reach` (model units): the field of the union of g's soup and s, as far
 * as reach (hole caps added to a field from a file). Exact point-triangle
 * distances; identical for any number of threads. */
st_status st_dist_lower(st_grid *g, const st_soup *s, double reach,
                        st_error *err);

#ifdef __cplusplus
}
#endif
#endif
