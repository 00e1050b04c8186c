/*
 * sides.h - which side of an open soup the voxels near it are on, from the
 * soup's own orientation, as evidence for the pseudo volume's cut.
 *
 * The votes (sign.h) read only where rays cross the surface. Through a
 * large hole most rays reach a voxel inside the part without crossing
 * anything, and parity calls it outside: the part comes out hollow. Its
 * surviving faces still say which side is inside: orientation. A soup's
 * file orientation is not trusted; instead
 *   1. each piece's triangles are oriented to agree across every edge of
 *      exactly two triangles (breadth-first, as shells.h does; a conflict
 *      is left where it is found), giving orientable regions;
 *   2. each region is turned, as a whole, to the way the votes read it
 *      (the majority of the votes, st_sign_votes): for each triangle,
 *      the voxels a voxel and a half in front of and behind its centroid,
 *      weighted by area, where they disagree; a tie keeps it;
 *   3. every voxel within band_voxels of the soup whose votes leave it to
 *      the cut
 *      gets the local generalized winding number of the oriented soup
 *      (Jacobson et al. 2013): the signed solid angles (Van Oosterom and
 *      Strackee 1983) of the triangles in the cube of radius_voxels
 *      around it, over 4 pi: near +1/2 just inside a wall, near -1/2 just
 *      outside, less where the wall has a hole. Times `weight`, clamped to
 *      +-max_evidence, rounded, it is evidence in votes of margin.
 * So the cut (mincut.h) has, on each side of every surviving wall, the
 * side it is on, and spans the holes between walls by the least area.
 *
 * Memory: one byte per voxel (the evidence, the caller's) and O(triangles).
 * Deterministic for any number of threads (each voxel sums its triangles
 * in the BVH's fixed order).
 */
#ifndef SOUPTET_SIDES_H
#define SOUPTET_SIDES_H

#include <stddef.h>
#include <stdint.h>

#include "souptet/err.h"
#include "souptet/grid.h"
#include "souptet/soup.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct st_sides_params {
    double band_voxels;     /* voxels nearer the soup than this get evidence */
    double radius_voxels;   /* triangles within this cube count */
    double weight;          /* evidence per unit of winding number */
    int max_evidence;       /* |evidence| at most this */
} st_sides_params;

st_sides_params st_sides_params_default(void);

typedef struct st_sides_stats {
    size_t regions;         /* orientable regions */
    size_t turned;          /* regions turned to agree with the votes */
    size_t conflicts;       /* edges where the propagation disagreed */
    size_t voxels;          /* voxels given evidence */
} st_sides_stats;

/* evidence (n bytes) gets each voxel's evidence (0 where none). g: the
 * soup's unsigned distance field; votes: its votes (st_sign_votes);
 * decided > 0: voxels whose votes' margin is at least that (the cut takes
 * them as they are, mincut.h) get none. stats may be NULL. ST_ENOMEM,
 * ST_ELIMIT. */
st_status st_sides_evidence(int8_t *evidence, const st_grid *g, const uint8_t *votes,
                            int decided, const st_soup *s,
                            const st_sides_params *p, st_sides_stats *stats,
                            st_error *err);

#ifdef __cplusplus
}
#endif
#endif
