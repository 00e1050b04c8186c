/*
 * soupinfo.h - what is wrong with a triangle soup: counts of the damage
 * that makes meshers refuse it (holes, cracks, non-manifold and
 * mis-oriented edges, degenerate and duplicated triangles, pieces).
 *
 * Units: model units (areas, volumes); counts of edges, triangles and
 * pieces.
 * Ownership: the caller owns *out (a plain struct) and the optional flags
 * array; the soup is borrowed.
 * Threads: OpenMP in the self-intersection search; counts do not depend on
 * the thread count.
 * Errors: ST_EINPUT (an empty soup), ST_ELIMIT, ST_ENOMEM.
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
 * - Collinear triangle: a non-degenerate one whose three distinct corners
 *   lie on one line (decided exactly with pred.h). Counted apart; it takes
 *   part in edges and pieces like any other.
 * - Self-intersection (st_soupinfo_self_intersections, exact, isect.h):
 *   a pair of distinct non-degenerate triangles whose closed point sets
 *   share more than the welded corners they have in common:
 *     no corner in common:  they share any point (touching counts);
 *     one corner v:         they share a point other than v, which holds
 *                           exactly when the edge opposite v in either
 *                           one meets the other triangle (their
 *                           intersection is convex and contains v, so a
 *                           second point makes an extreme point other
 *                           than v, and that lies on an opposite edge);
 *     one edge uw:          they overlap beyond uw: coplanar, with their
 *                           third corners on the same side of uw (a fold
 *                           flat onto itself); two triangles meeting at an
 *                           angle share only the edge;
 *     all three corners:    always (a duplicate covers its original).
 *   A collinear triangle is tested only against triangles with no corner
 *   in common (its point set is a segment: "opposite edge" and "side"
 *   have no meaning for it).
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

    size_t collinear_triangles;   /* distinct corners on one line */
    /* filled by st_soupinfo_self_intersections only: */
    int self_checked;             /* 1 once the two counts below are set */
    size_t self_intersecting_pairs;
    size_t self_intersecting_triangles;  /* in at least one pair */
} st_soupinfo;

/* Analyse a soup (see the definitions above). s must hold at least one
 * triangle (st_soup_read guarantees it). Runs in O(n log n) time with
 * about 100 bytes of scratch memory per triangle (plus 20 per vertex);
 * deterministic; never prints, never changes s.
 * Returns ST_OK and fills *out, or ST_ENOMEM / ST_ELIMIT (more than
 * 2^32 / 3 triangles) / ST_EINPUT (no triangles) with err filled. */
st_status st_soupinfo_compute(st_soupinfo *out, const st_soup *s,
                              st_error *err);

/* The self-intersections of s (see the definition above), found with a
 * BVH (bvh.h) over the triangles and decided exactly. Sets out's
 * self_checked, self_intersecting_pairs and self_intersecting_triangles
 * and leaves the rest of *out alone. flags, when not NULL, holds
 * s->ntris bytes and gets 1 for every triangle in at least one pair, else
 * 0. Parallel (OpenMP); the result does not depend on the thread count.
 * ST_ENOMEM, ST_ELIMIT as above. */
st_status st_soupinfo_self_intersections(st_soupinfo *out, const st_soup *s,
                                         unsigned char *flags,
                                         st_error *err);

#ifdef __cplusplus
}
#endif
#endif
