/*
 * holes.h - caps for the holes of a soup.
 *
 * A hole is a loop of boundary edges (edges of exactly one triangle, on
 * exactly welded vertices, degenerate and duplicated triangles left out).
 * At a vertex with two boundary edges the loop goes on along the other;
 * where holes touch (a vertex with 2m boundary edges) the edges are paired
 * by angle: seen along the mean normal of the triangles around the vertex
 * (their normals' signs aligned, orientation not read), each gap between
 * two consecutive boundary edges that no triangle covers is a hole
 * passing through, and pairs them. Its cap is the
 * triangulation of the loop of least area (dynamic programming over the
 * loop's vertices, Barequet and Sharir's minimal-area polygon
 * triangulation): a flat hole gets a flat cap, a hole across a tube the
 * chord across it. With bend, it is the
 * triangulation of the loop's own vertices that bends least: the sum over
 * its edges, inner ones and the loop's (where it meets the soup's triangle
 * there, whose orientation is read relative to the cap only), of length
 * times dihedral angle, the discrete total mean curvature, is least; ties
 * by area (dynamic programming over the loop's vertices as for the
 * minimal-area triangulation of Barequet and Sharir, the bends taken
 * across each diagonal with the best triangulation behind it, after
 * Liepa's fairest one). A flat hole gets a flat cap; a CAD part's missing
 * cylindrical or conical face (ruled between two rims of the loop) its
 * facets; a hole through both faces of a thin wall the faces, where the
 * least-area cap is a wall across the solid, and a hole over several
 * faces of a part a cap along them rather than one folding through the
 * solid. Lost corners (points of the part inside the hole) stay lost: the
 * cap has the loop's points only; where such a corner was concave (a
 * notch) the cap that bends least extends the faces across it, and on a
 * one-sided scan it continues the walls past the far side (the numbers at
 * st_holes_params_default in holes.c). With
 * planes, a lost corner is rebuilt where the planes of the soup's
 * triangles along the loop meet: the cone from the point where three of
 * them meet (or from the line where two meet, nearest the loop's
 * centroid), within the loop's box grown by 0.75 of its extent, over the
 * loop replaces the cap when its triangles continue the soup's along the
 * loop clearly better (the sum over the loop's edges of length times
 * dihedral angle below half the cap's) and none of its triangles pierces
 * the soup (isect.h's st_tri_tri_cross): a box's lost corner comes back
 * whole. Where a hole spans several corners, such a point of the planes
 * may continue only part of the loop: the fans from it over the edges it
 * continues (but those that pierce the soup) replace them, and the rest of the loop (split where it meets
 * the point more than once) is capped the same way, at most 16 points per
 * loop, what none continues by the cap of its own points; the fans or the
 * single cone, whichever continues the soup along the loop better: a
 * box's lost edge comes back with both its corners.
 *
 * Where the soup around its holes is intact: bend and planes (the
 * default) apply only where the rim, the kept triangles on a boundary
 * edge, is at most `intact` of the soup's area (where faces were deleted
 * at random nearly everything left touches a hole, the fragments' planes
 * say little and a bent cap fills lost notches), and, with `onesided`,
 * where the soup is not a scan seen from one side along an axis (each
 * orientable region, propagated across edges of two triangles, turned the
 * way it faces most along the axis: the projected area facing away under
 * `onesided` of that facing it; its loops are the horizon, not lost faces,
 * and a bent cap would carry its walls past the far side). Elsewhere every
 * cap is the least-area one.
 *
 * Not every loop is a hole: an open patch (a panel of a CAD part, one of a
 * teapot's patches, a sheet) has a loop around itself, and capping it would
 * add a second surface beside or across the patch. A loop is capped only
 * when its least-area triangulation is small beside the surface around
 * it: at most max_cap_ratio times the area of the pieces (edge-connected
 * triangles) near it, those with a triangle whose bounding box meets the
 * loop's box grown by a quarter of its extent each way (its own pieces
 * among them; where faces were deleted at random, the fragments beside
 * the hole).
 * A flat loop is capped whatever its size (a CAD part that lost a face:
 * its cap is the face) unless the triangles along it that lie in its plane
 * are mostly inside it (the rim of a flat sheet, which is no hole).
 * Where the gaps do not pair every edge exactly once (a vertex on a sharp
 * crease, where one plane does not order the triangles around it), each
 * boundary edge's hole side (in its triangle's plane, away from the
 * triangle) pairs it with an edge lying on that side whose own hole side
 * holds it, best pairs first; where that does not pair every edge (an odd
 * count, no such partner) the edges stay unpaired and their loops open: a
 * wrong pairing would span a cap across the surface.
 *
 * Orientation is not read; the result does not depend on how the soup's
 * vertices are shared, only on their positions.
 */
#ifndef SOUPTET_HOLES_H
#define SOUPTET_HOLES_H

#include <stddef.h>
#include "souptet/bvh.h"
#include "souptet/edges.h"
#include "souptet/err.h"
#include "souptet/soup.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct st_holes_params {
    double max_cap_ratio;   /* least-area cap / area of the pieces around it */
    size_t max_loop;        /* loops with more edges are left open */
    double flat;            /* a loop within flat times its extent of a
                             * plane, not along a flat sheet's rim, is
                             * capped whatever its size (0: never) */
    int bend;               /* 1: the cap that bends least; 0 (default):
                             * the cap of least area */
    int planes;             /* 1: the cap rebuilt from the planes along
                             * the loop where they agree on one, else as
                             * bend says */
    double intact;          /* bend and planes only where the rim (the
                             * triangles on a hole's edge) is at most this
                             * share of the soup's area (1: always) */
    double onesided;        /* and only where the soup is not seen from one
                             * side along an axis: its least back/front
                             * ratio (axis_one_sided in holes.c) at least
                             * this (0: always) */
} st_holes_params;

typedef struct st_holes_stats {
    size_t boundary_edges;
    size_t loops;           /* loops traced */
    size_t filled;          /* loops capped */
    size_t rebuilt;         /* of them, rebuilt from the planes around */
    size_t too_large;       /* cap above max_cap_ratio (or of no area) */
    size_t too_long;        /* more than max_loop edges */
    size_t pinched;         /* boundary edges on paths through a vertex
                             * whose edges could not be paired: left open */
    double rim_share;       /* the rim's share of the soup's area */
    double one_sided;       /* that ratio (-1 when not needed) */
    int continued;          /* bend or planes applied (rim_share at most
                             * intact, one_sided at least onesided) */
} st_holes_stats;

st_holes_params st_holes_params_default(void);

/* *caps gets a new soup of the caps' triangles (possibly none; its
 * vertices are copies of the loops' positions). stats may be NULL.
 * ST_ENOMEM, ST_ELIMIT (more than 2^31 triangles). */
st_status st_soup_hole_caps(st_soup **caps, const st_soup *s,
                            const st_holes_params *p, st_holes_stats *stats,
                            st_error *err);

/* The same with s's edge table (st_soup_edges_build) and BVH
 * (st_bvh_build) when the caller has them (either may be NULL: built here
 * and freed). The same caps. */
st_status st_soup_hole_caps_shared(st_soup **caps, const st_soup *s,
                                   const st_soup_edges *edges, const st_bvh *bvh,
                                   const st_holes_params *p, st_holes_stats *stats,
                                   st_error *err);

#ifdef __cplusplus
}
#endif
#endif
