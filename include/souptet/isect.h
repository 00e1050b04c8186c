/*
 * isect.h - exact intersection tests between triangles, segments, points
 * and tetrahedra, built only on the exact predicates of pred.h.
 *
 * Every answer is the exact answer for the closed sets given by the double
 * coordinates (boundaries included), with no tolerance: two triangles that
 * share only a vertex intersect; a point on a tet's face is in the tet.
 * Degenerate inputs (a triangle whose vertices are collinear, a flat tet)
 * are handled as the point sets they are (a segment, a point, a triangle).
 *
 * Module order: ... -> pred -> isect -> ...
 */
#ifndef SOUPTET_ISECT_H
#define SOUPTET_ISECT_H

#ifdef __cplusplus
extern "C" {
#endif

/* Where a point lies relative to a closed tetrahedron. */
typedef enum st_point_loc {
    ST_OUTSIDE = 0,
    ST_ON_BOUNDARY = 1,   /* on a face, edge or vertex */
    ST_INSIDE = 2         /* in the open interior */
} st_point_loc;

/* Location of p relative to tet (t0, t1, t2, t3), of either orientation.
 * A flat tet (all four points coplanar) has no interior: the answer is
 * ST_ON_BOUNDARY when p lies in its convex hull, else ST_OUTSIDE. */
st_point_loc st_point_in_tet(const double p[3], const double t0[3],
                             const double t1[3], const double t2[3],
                             const double t3[3]);

/* 1 when the closed triangles (a0 a1 a2) and (b0 b1 b2) share a point
 * (coplanar overlap, touching at an edge or a vertex included), else 0. */
int st_tri_tri_intersect(const double a0[3], const double a1[3],
                         const double a2[3], const double b0[3],
                         const double b1[3], const double b2[3]);

/* 1 when the closed segment [p, q] and the closed triangle (a b c) share
 * a point, else 0. */
int st_segment_tri_intersect(const double p[3], const double q[3],
                             const double a[3], const double b[3],
                             const double c[3]);

/* 1 when the closed triangle (a b c) and the closed tetrahedron
 * (t0 t1 t2 t3) share a point, else 0: a triangle inside the tet, crossing
 * it without touching its edges, or touching a face all count. This is the
 * sculpting test (Cetra section 3.2, made exact and complete). */
int st_tri_tet_intersect(const double a[3], const double b[3],
                         const double c[3], const double t0[3],
                         const double t1[3], const double t2[3],
                         const double t3[3]);

/* 1 when the closed triangle (a b c) meets the closed axis-aligned box
 * [lo, hi], else 0 (exact: for BVH and lattice culling without misses). */
int st_tri_box_intersect(const double a[3], const double b[3],
                         const double c[3], const double lo[3],
                         const double hi[3]);

#ifdef __cplusplus
}
#endif
#endif
