/*
 * soupinfo.h - what is wrong with a triangle soup: counts of the damage
 * that makes meshers refuse it (holes, cracks, non-manifold and
 * mis-oriented edges, degenerate and duplicated triangles, pieces).
 *
 * Everything is decided on exact coordinates, never with a tolerance:
 *
 * - Welding: two vertices are the same point when their three coordinates
 *   are equal as doubles (-0.0 equals 0.0). No epsilon: a crack of any
 *   width, however small, stays a crack, which is what the distance field
 *   sees too. All topology below is on welded vertices, so a soup whose
 *   triangles each carry their own vertices has the topology of the surface
 *   it came from.
 * - Degenerate triangle: two of its corners weld to the same point (a
 *   repeated index, or equal coordinates). A triangle with three distinct
 *   but collinear corners is NOT counted: deciding collinearity exactly
 *   needs exact orientation predicates, and a floating-point
 *   cross product would misjudge near-collinear triangles. Degenerate
 *   triangles take no part in edges, pieces, holes or the Euler
 *   characteristic (their "edges" join a point to itself).
 * - Duplicated triangle: one whose three corner points (as a multiset, any
 *   order, any orientation) equal those of an earlier triangle; the count is
 *   the number of extra copies. Duplicates do take part in the edge counts
 *   (they make their edges non-manifold, as they do for a mesher).
 * - Edge: an unordered pair of distinct welded points used by at least one
 *   non-degenerate triangle. Boundary: used once; manifold: twice;
 *   non-manifold: three times or more. Inconsistent: a manifold edge whose
 *   two triangles traverse it in the same direction (one of them is flipped
 *   relative to the other).
 * - Piece: a connected component of non-degenerate triangles joined across
 *   shared edges (manifold or not). Pieces that touch only at a vertex are
 *   separate pieces.
 * - Holes: the independent cycles formed by the boundary edges (the cycle
 *   rank E - V + C of the graph they form), so a simple boundary loop is one
 *   hole, two loops touching at a vertex are two, and an open chain of
 *   boundary edges (the free edges of a fin) is none.
 * - Non-manifold vertex: one whose non-degenerate triangles form more than
 *   one fan when joined across manifold edges (a pinch: two cones touching
 *   at their tips; every vertex of a non-manifold edge).
 * - Closed piece: a piece that is a closed 2-manifold on its own: each of
 *   its edges used exactly twice by its triangles and each of its vertices
 *   with a single fan within the piece. Its Euler characteristic is
 *   V - E + F; when it is also orientable its genus is (2 - chi) / 2.
 *   Orientability is decided by propagating orientation across manifold
 *   edges, so a closed piece with randomly flipped triangles is still
 *   orientable (and has a genus), a Klein bottle is not.
 *
 * Module order: err -> mem -> ... -> soup -> soupinfo.
 */
#ifndef SOUPTET_SOUPINFO_H
#define SOUPTET_SOUPINFO_H

#include <stddef.h>
#include "souptet/err.h"
#include "souptet/soup.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct st_soupinfo {
    /* as read */
    size_t vertices;              /* vertices in the file */
    size_t triangles;             /* triangles in the file */
    size_t unreferenced_vertices; /* file vertices no triangle uses */
    double lo[3], hi[3];          /* bounds of the referenced vertices */
    double diagonal;              /* |hi - lo| */

    /* after exact welding */
    size_t welded_vertices;       /* distinct points among referenced vertices */
    size_t degenerate_triangles;  /* two corners at the same point */
    size_t duplicated_triangles;  /* extra copies of a triangle */
    size_t edges;                 /* distinct edges of non-degenerate triangles */
    size_t boundary_edges;        /* used by one triangle */
    size_t manifold_edges;        /* used by two */
    size_t nonmanifold_edges;     /* used by three or more */
    size_t inconsistent_edges;    /* manifold, both traversed the same way */
    size_t nonmanifold_vertices;  /* more than one fan */
    size_t holes;                 /* independent cycles of boundary edges */
    size_t pieces;                /* edge-connected components */
    size_t closed_pieces;         /* pieces that are closed 2-manifolds */
    size_t nonorientable_pieces;  /* orientation propagation conflicts */
    long long euler;              /* V - E + F of the non-degenerate part */
    long long genus;              /* sum over closed orientable pieces */

    /* summary flags */
    int closed;                   /* no boundary and no non-manifold edge */
    int consistently_oriented;    /* no inconsistent edge */
} st_soupinfo;

/* Analyse a soup (see the definitions above). s must hold at least one
 * triangle (st_soup_read guarantees it). Runs in O(n log n) time with
 * about 100 bytes of scratch memory per triangle (plus 20 per vertex);
 * deterministic; never prints, never changes s.
 * Returns ST_OK and fills *out, or ST_ENOMEM / ST_ELIMIT (more than
 * 2^32 / 3 triangles) / ST_EINPUT (no triangles) with err filled. */
st_status st_soupinfo_compute(st_soupinfo *out, const st_soup *s,
                              st_error *err);

#ifdef __cplusplus
}
#endif
#endif
