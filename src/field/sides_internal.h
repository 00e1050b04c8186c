/*
 * sides_internal.h - the sides' local winding number at points along a
 * row (sides.c), for the tests.
 */
#ifndef SOUPTET_SIDES_INTERNAL_H
#define SOUPTET_SIDES_INTERNAL_H

#include <stddef.h>
#include <stdint.h>
#include "souptet/bvh.h"
#include "souptet/grid.h"
#include "souptet/sides.h"

/* The evidence at the points (x[k], y, z), k < n (x ascending), from the
 * triangles of the BVH's soup whose boxes meet the cube of half-side r
 * around each: scale times the sum of their signed solid angles, clamped
 * to [-cap, cap], rounded, into out[n]. how 0: the angles summed term by
 * term (Van Oosterom and Strackee's arc tangent each); 1: the product of
 * their complex numbers, one arc tangent, over each point's own query of
 * the BVH; 2: the same over the triangles gathered once for them all and
 * selected for them all (as the sides gather a block of rows, then select
 * for a run of voxels). 1 and 2 fall back on 0 where rounding
 * could tell, so all three give the same evidence. */
void st_sides_winding_points(int8_t *out, const st_bvh *bvh, const double *x, size_t n,
                             double y, double z, double r, double scale, double cap, int how);

/* The evidence of every voxel of g that takes it (|value| < p's band,
 * and with decided > 0 its votes' margin under decided), from the
 * triangles of bvh's soup as the sides read them (blocks of rows, runs of
 * voxels), into evidence (the others left as they are); returns how many
 * voxels. */
size_t st_sides_winding_grid(int8_t *evidence, const st_grid *g, const uint8_t *votes, int decided,
                             const st_bvh *bvh, const st_sides_params *p);

#endif
