/*
 * sides.h - which side of an open soup the voxels near it are on, from the
 * soup's own orientation, as evidence for the pseudo volume's cut.
 *
 * Units: voxels for bands and radii; evidence in votes (int8).
 * Ownership: the caller owns the evidence array (one byte a voxel); grid,
 * votes and soup are borrowed.
 * Threads: OpenMP over voxels; deterministic for any thread count (below).
 * Errors: ST_ENOMEM, ST_ELIMIT.
 *
 * The votes (sign.h) read only where rays cross the surface, so through a
 * large hole a part comes out hollow; its surviving faces still say which
 * side is inside. Each orientable region of the soup, turned the way the
 * votes read it, gives the voxels near it its local generalized winding
 * number (Jacobson et al. 2013) as evidence for the cut (mincut.h), and a
 * one-sided scan is recognised (st_sides_mirror, st_sides_columns complete
 * it). The steps: doc/design/sides.md.
 *
 * Memory: one byte per voxel (the evidence, the caller's) and O(triangles).
 * Deterministic for any number of threads (each voxel sums its triangles
 * in the BVH's fixed order).
 */
#ifndef SOUPTET_SIDES_H
#define SOUPTET_SIDES_H

#include <stddef.h>
#include <stdint.h>

#include "souptet/edges.h"
#include "souptet/err.h"
#include "souptet/grid.h"
#include "souptet/progress.h"
#include "souptet/soup.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct st_sides_params {
    double band_voxels;     /* voxels nearer the soup than this get evidence */
    double radius_voxels;   /* triangles within this cube count */
    double weight;          /* evidence per unit of winding number */
    int max_evidence;       /* |evidence| at most this */
    double onesided_ratio;  /* one-sided below this back/front ratio (0: never) */
    size_t seen_triangles;  /* the view reads the first this many triangles
                               of the soup (the seen surface; the rest are
                               its caps); 0: all */
    double wall_cosine;     /* a rim face is a wall where |cos| to the view
                               is at most this */
    double walls_ratio;     /* mirrored below this walls' share of the rim */
    int past_caps;          /* the view of the seen soup alone, and the
                               mirror past its caps (0; see st_sides_mirror) */
    double column_ratio;    /* the column rule below this back/front ratio
                               along an axis (0: never; st_sides_columns) */
    size_t column_seen;     /* the column rule reads the first this many
                               triangles (the seen surface); 0: all */
    int column_caps;        /* the column rule reads the caps that face
                               away too (1; st_sides_columns) */
    const st_progress *progress;   /* NULL, or "sides" reports from the
                               winding numbers' slices (NULL) */
} st_sides_params;

st_sides_params st_sides_params_default(void);

typedef struct st_sides_stats {
    size_t regions;         /* orientable regions */
    size_t turned;          /* regions turned to agree with the votes */
    size_t conflicts;       /* edges where the propagation disagreed */
    size_t voxels;          /* voxels given evidence */
    double back_front;      /* projected area facing away from the view over
                               facing it (0 for a one-sided view, 1 closed) */
    double view[3];         /* the view direction (unit; the mean normal) */
    int onesided;           /* back_front < onesided_ratio */
    double walls;           /* the rim's area share of walls (faces along
                               the view) */
    int fold;               /* mirrored: onesided, and with past_caps
                               walls < walls_ratio */
    int past_caps;          /* the params' past_caps */
    double far;             /* without past_caps: the soup's farthest point
                               along the step (-INFINITY with it) */
    int step[3];            /* the lattice step nearest view */
    double column_back_front;   /* the least back/front of the seen soup
                                   along an axis direction */
    int column_axis, column_dir;    /* that direction: +-1 along axis 0..2 */
    int columns;            /* column_back_front < column_ratio */
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
/* The same with s's edge table (st_soup_edges_build) when the caller has
 * it (NULL: built here). */
st_status st_sides_evidence_edges(int8_t *evidence, const st_grid *g, const uint8_t *votes,
                                  int decided, const st_soup *s, const st_soup_edges *edges,
                                  const st_sides_params *p, st_sides_stats *stats,
                                  st_error *err);

/* A one-sided view's far side (stats->fold; nothing otherwise), on
 * the signed field g of its pseudo volume: along each line of the lattice
 * step nearest the view (components in -2..2), the run of inside voxels
 * farthest from the viewer, if it does not end on the soup (its far end is
 * the cut's least-area cap across the horizon, not a seen wall), is
 * continued away from the viewer by its own length, stopping at the soup
 * and, without past_caps, at the depth of its farthest point from the
 * viewer (stats->far): the solid taken as symmetric about the horizon it
 * was seen to. A prior, not evidence: right for a body whose far half
 * mirrors its near half (a ball seen to a wavy horizon, a scanned animal),
 * too much where the part was seen past its widest section. Without
 * past_caps a horizon loop that holes.h caps (a flat one) ends the runs on
 * the cap and is left as it is. With it (s given, its first
 * seen_triangles the seen surface, the rest caps: the soup
 * st_sides_evidence read) only the seen surface ends a run or stops its
 * continuation, and stats->fold also asks that walls along the view are
 * under walls_ratio of the rim (a crease where an unseen flat face begins
 * is closed flat). s may be NULL (every near voxel is the soup). *changed
 * gets the voxels made inside. Deterministic: each line is one thread's.
 * ST_ENOMEM. */
st_status st_sides_mirror(st_grid *g, const st_soup *s, size_t seen_triangles,
                          const st_sides_stats *stats, size_t *changed, st_error *err);

/* The column rule, for a scan seen along an axis (stats->columns:
 * the oriented seen soup's faces facing away from the axis direction
 * column_dir * e_column_axis add up, in projected area, to under
 * column_ratio of those facing it; nothing otherwise). Seen from there,
 * every surface a line along the axis enters the solid through faces the
 * viewer, so it was seen, and every one it leaves through faces away, so
 * it was not: along each line of voxel centers (from the viewer), the
 * solid is nothing before the first crossing of the seen soup (s's first
 * p->column_seen triangles; 0: all), and after each crossing one run of inside
 * (the solid it enters) and then nothing up to the next crossing. Each
 * such segment keeps the step (inside, then outside) that the voxels of g
 * at least band_voxels from the soup agree with most (ties: the longer
 * inside run); the voxels after it are made outside, none made inside. A
 * line that crosses nothing seen is empty (the bore of a part seen along
 * it). Where a segment's solid ends is the field's (the cut, the caps, the
 * mirror), but for the caps the lines read when p->column_caps is set and
 * the scan is not mirrored (!stats->fold): s's triangles after the first
 * p->column_seen, oriented as the seen soup around them (each seen
 * triangle facing the viewer, carried across edges of two triangles,
 * breadth first), those that face away. The first such cap a segment
 * crosses (half a voxel clear of its ends) ends its solid there at the
 * latest when the cap's piece (its caps joined across edges) rises less
 * than a voxel above the crossing, toward the viewer: a flat cap is the
 * lost face (a pocket's ceiling). Otherwise, when the segment's step is at
 * or below the cap and a next crossing follows, the air from the cap down
 * to it is mirrored above the cap, if solid is left after the first
 * crossing: a bore seen along a line square to it shows its lower half,
 * and its least-area cap runs across the middle (rising up the half
 * circles at its ends), so the upper half is the lower one mirrored.
 * Crossings: each lattice line against each triangle's projection, exact
 * orient2d signs (a closed triangle; the seen soup's crossings within half
 * a voxel of each other are one).
 * *changed gets the voxels made outside. Deterministic: each line is one
 * thread's. ST_ENOMEM. */
st_status st_sides_columns(st_grid *g, const st_soup *s, const st_sides_params *p,
                           const st_sides_stats *st, double band_voxels, size_t *changed,
                           st_error *err);

#ifdef __cplusplus
}
#endif
#endif
