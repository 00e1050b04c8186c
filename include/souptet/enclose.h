/*
 * enclose.h - does a tet mesh enclose a triangle soup? Exact point location
 * in a tet mesh, and the two enclosure counts of DESIGN.md's metrics. The
 * first property Stuart 2013 asks of a control mesh (section 1: it must
 * enclose the surface; section 3.3 keeps it so while vertices move).
 *
 * Units: model units; counts are exact integers.
 * Ownership: the caller owns the locator (st_locator_free) and the optional
 * per-item arrays it passes; mesh, soup and BVH are borrowed.
 * Threads: the locator is read-only after st_locator_new and thread-safe;
 * st_enclosure_compute runs OpenMP loops whose results do not depend on the
 * thread count.
 * Errors: ST_EINPUT (a mesh without tets, an empty soup), ST_ELIMIT,
 * ST_ENOMEM; st_points_are_float32 cannot fail.
 *
 * A mesh M encloses a soup S when
 *   (a) every vertex of S lies in the closed union of M's tets, and
 *   (b) no triangle of S meets a boundary face of M (a face of exactly one
 *       tet, st_tetmesh_boundary).
 * When M is conforming and its tets are positively oriented, the
 * boundary of the union is the union of the boundary faces, so together
 * (a) and (b) put every triangle of S inside M (a triangle with its
 * vertices inside that left M would cross that boundary). With inverted
 * tets, two tets on one side of a shared face can leave that face on the
 * union's boundary unnoticed; tetstat reports inverted tets separately.
 * Both counts are decided exactly (st_point_in_tet, st_tri_tri_intersect)
 * on the closed sets, so contact counts:
 *   - a soup vertex exactly on a boundary face is INSIDE (the tets are
 *     closed), but
 *   - a soup triangle touching a boundary face (at one of its vertices,
 *     along an edge, or lying in the face) COUNTS AS CROSSING.
 * So a mesh whose boundary touches the soup does not enclose it: there must
 * be room between them, which is what the consumers need (the surface
 * strictly inside the mesh is safe to embed and to move).
 * Tets of either orientation cover the same points: an inverted tet still
 * covers its points; a flat tet covers its (planar) convex hull.
 */
#ifndef SOUPTET_ENCLOSE_H
#define SOUPTET_ENCLOSE_H

#include <stddef.h>
#include <stdint.h>

#include "souptet/bvh.h"
#include "souptet/err.h"
#include "souptet/isect.h"
#include "souptet/soup.h"
#include "souptet/tetmesh.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ---- point location ----------------------------------------------------- */

/* Exact point location in the tets of a mesh: a uniform grid of bins over
 * the bounding box of the tets' points, each bin listing (in increasing
 * index order) the tets whose bounding boxes meet it. */
typedef struct st_locator st_locator;

/* Build a locator over m's tets. m is borrowed: it must outlive the
 * locator and its points and tets must not change meanwhile (rebuild
 * after moving points). A mesh without tets gives a locator that finds
 * nothing. ST_ENOMEM, or ST_ELIMIT past UINT32_MAX tets. */
st_status st_locator_new(st_locator **out, const st_tetmesh *m,
                         st_error *err);
void st_locator_free(st_locator *l);   /* safe on NULL */

/* The lowest index of a tet whose closed point set contains p, or -1 when
 * p lies in no tet. The lowest index makes the answer unique for a point on
 * a face shared by several tets. *loc (may be NULL) gets p's location in
 * that tet (ST_INSIDE or ST_ON_BOUNDARY; ST_OUTSIDE with -1). Exact,
 * thread-safe. */
int64_t st_locator_find(const st_locator *l, const double p[3],
                        st_point_loc *loc);

/* ---- enclosure ----------------------------------------------------------- */

typedef struct st_enclosure {
    size_t vertices;            /* soup vertices used by some triangle */
    size_t vertices_inside;     /* of those, in the closed union of tets */
    size_t vertices_outside;    /* vertices - vertices_inside */
    double fraction_inside;     /* vertices_inside / vertices; 1 if none */
    size_t boundary_faces;      /* faces of M with exactly one tet */
    size_t crossing_triangles;  /* soup triangles meeting a boundary face */
    int encloses;               /* vertices_outside == 0 and
                                   crossing_triangles == 0 */
} st_enclosure;

/* Compute the enclosure of soup s by mesh m (see the top of this file).
 * Only soup vertices that some triangle uses are tested (readers keep
 * unreferenced vertices; they are not part of the surface).
 *
 * bvh: a BVH over s (st_bvh_build), or NULL to build one here.
 * vertex_in: NULL, or s->nverts bytes: 1 inside, 0 outside, 2 for a vertex
 *   no triangle uses (not tested).
 * tri_crossing: NULL, or s->ntris bytes: 1 for a triangle meeting a
 *   boundary face, else 0.
 * A mesh without tets encloses nothing (every used vertex is outside).
 * Errors: ST_ENOMEM; those of st_tetmesh_boundary and st_bvh_build. */
st_status st_enclosure_compute(st_enclosure *out, const st_tetmesh *m,
                               const st_soup *s, const st_bvh *bvh,
                               unsigned char *vertex_in,
                               unsigned char *tri_crossing, st_error *err);

/* Count, exactly, the vertices of s (those its triangles use) not in the
 * closed union of m's tets, and the triangles of s that meet a boundary
 * face of m (closed sets: touching counts). Enclosing means both are 0.
 * On error (ST_ENOMEM, those of st_enclosure_compute) both are SIZE_MAX,
 * so a caller that ignores the status never reads "encloses".
 * bvh over s may be NULL. Thread-safe. */
st_status st_enclosure_count(const st_tetmesh *m, const st_soup *s,
                             const st_bvh *bvh, size_t *verts_outside,
                             size_t *tris_crossing, st_error *err);

/* ---- float32: enclosing after the points are rounded to float ----------
 *
 * Blender, glTF, STL, game engines and PhysX store float32. A mesh that
 * encloses a soup in double can lose it when its points are rounded to
 * float (an input vertex a fraction of a float ulp inside a boundary face
 * is outside once the face's corners move). st_enclosure_round_float32
 * rounds every point of m to a float32 value (stored back as the double
 * of that float, so every writer keeps it exactly and (double)(float)x ==
 * x for every coordinate afterwards) such that the rounded mesh still
 * encloses s, checked exactly:
 *   - a point on no boundary face goes to the nearest float;
 *   - a boundary point goes "outward": of the 8 floats around it (the
 *     largest float <= x or the smallest >= x, per coordinate; at push
 *     level k, k more float ulps beyond those) the one maximising the
 *     smallest of (displacement . unit outward normal) over the boundary
 *     faces around it (ties: the shorter displacement, then the lower
 *     corner index). The choice is a heuristic in floating point; the
 *     guarantee is the exact check that follows.
 *   - check: st_enclosure_compute of s by the rounded mesh (exact), and
 *     the orientation of every tet (st_orient3d, exact: a tet that is no
 *     longer positively oriented counts as inverted, flat included);
 *   - when the check fails, the boundary points near the failure (the
 *     boundary corners of the tet of the original mesh that held a soup
 *     vertex now outside, or every boundary point when that tet has
 *     none; the corners of boundary faces that meet a crossing soup
 *     triangle) go one float ulp further out, and the check is made
 *     again, at most ST_FLOAT32_MAX_ROUNDS checks in all. A point whose
 *     chosen float goes inward by some face around it (faces facing
 *     nearly opposite ways: a knife edge, a flat tet) is not pushed: that
 *     would take it farther in by that face; the other points named are. The
 *     rounds stop when nothing is left to push (a soup vertex outside the
 *     mesh before rounding names nothing). When no rounding encloses, the
 *     best tried (fewest vertices outside, then triangles crossing, then
 *     inverted tets) is the one kept and reported.
 * Why it usually holds at the first check: when every boundary point
 * moves out of every boundary face around it, each face moves outward at
 * each of its points (a convex combination of its corners' moves), so a
 * soup point behind it stays behind it (measured: soupmesh.1, --float32).
 * The guarantee is about s as given (in double) against the rounded mesh.
 * When s itself is not float32 (input_not_float32 > 0), a consumer that
 * rounds the soup too moves it by up to half an ulp, which this does not
 * cover.
 * On return m holds the last rounding tried, whether it holds or not:
 * st->encloses says (with verts_outside, tris_crossing and inverted of
 * that mesh); a rounding that does not enclose is not an error. Points
 * whose float would overflow (|x| > FLT_MAX) fail with ST_ELIMIT and leave
 * m unchanged. bvh over s may be NULL (one is built). A mesh already in
 * float32 that encloses s is left unchanged (1 round, 0 points moved).
 * Deterministic; the enclosure check runs OpenMP loops. Errors: ST_ENOMEM,
 * ST_ELIMIT, those of st_enclosure_compute. */

/* Exact checks at most (the first rounding and the pushes after it). */
#define ST_FLOAT32_MAX_ROUNDS 8

typedef struct st_float32_stats {
    int rounds;                 /* exact checks made (1: the first rounding
                                   held) */
    size_t points_moved;        /* points with some coordinate changed */
    size_t boundary_points;     /* points on a boundary face */
    size_t pushed;              /* boundary points pushed past the floats
                                   around them (push level > 0) */
    unsigned max_push;          /* the largest push level (float ulps) */
    double max_move;            /* the largest distance a point moved */
    size_t verts_outside;       /* of the last rounding, exact */
    size_t tris_crossing;
    size_t inverted;            /* tets not positively oriented */
    int encloses;               /* the three above are 0 */
    size_t input_not_float32;   /* soup vertices (used by a triangle) with a
                                   coordinate that is not a float */
    double seconds;             /* the call's wall-clock time */
} st_float32_stats;

st_status st_enclosure_round_float32(st_tetmesh *m, const st_soup *s,
                                     const st_bvh *bvh, st_float32_stats *st,
                                     st_error *err);

/* 1 when every coordinate of the n points xyz is a float32 value
 * ((double)(float)x == x); 0 otherwise. */
int st_points_are_float32(const double *xyz, size_t n);

#ifdef __cplusplus
}
#endif
#endif
