/*
 * isect.h - exact intersection tests between triangles, segments, points
 * and tetrahedra, built only on the exact predicates of pred.h.
 *
 * Units: model units; answers are exact booleans.
 * Ownership: none: values in, values out.
 * Threads: pure functions, thread-safe.
 * Errors: none: every test answers for every finite input.
 *
 * Every answer is the exact answer for the closed sets given by the double
 * coordinates (boundaries included), with no tolerance: two triangles that
 * share only a vertex intersect; a point on a tet's face is in the tet.
 * Degenerate inputs (a triangle whose vertices are collinear, a flat tet)
 * are handled as the point sets they are (a segment, a point, a triangle).
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

/* 1 when the closed triangles (a0 a1 a2) and (b0 b1 b2) pierce each
 * other: each has vertices strictly on both sides of the other's plane,
 * and they share a point beyond the vertex they may have in common (equal
 * positions). Triangles that only touch (a vertex or an edge on the
 * other's plane, a common edge), coplanar and degenerate ones do not
 * cross (0). For a patch across a hole: does it pierce the surface whose
 * rim it meets? */
int st_tri_tri_cross(const double a0[3], const double a1[3], const double a2[3],
                     const double b0[3], const double b1[3], const double b2[3]);

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
 * [lo, hi], else 0 (exact: for BVH and lattice culling without misses).
 * A box with lo[k] == hi[k] on some axes is the rectangle, segment or
 * point it is; a box with lo[k] > hi[k] on some axis is empty (0).
 * (isect.c: separating axes with exact signs; flat boxes go through the
 * triangle tests.) */
int st_tri_box_intersect(const double a[3], const double b[3],
                         const double c[3], const double lo[3],
                         const double hi[3]);

/* 0 only when the closed triangle (a b c) certainly misses the closed box
 * [lo, hi]; 1 when it may meet it: a floating-point filter with a proven
 * slack (isect.c), for culling (a BVH walk whose visits must be a superset
 * of the triangles that meet), several times cheaper than
 * st_tri_box_intersect. Non-finite input: 1. */
int st_tri_box_maybe(const double a[3], const double b[3], const double c[3],
                     const double lo[3], const double hi[3]);

/* st_tri_box_maybe for one triangle against many boxes (a BVH walk): what
 * depends on the triangle alone, computed once by st_tri_box_filter_init
 * (the filter holds no pointer to a, b, c). st_tri_box_filter_maybe is a
 * filter with the same promise (0 only when the triangle certainly misses
 * [lo, hi]) and slack (isect.c), several times cheaper per box. */
typedef struct st_tri_box_filter {
    double tlo[3], thi[3];   /* the triangle's box */
    double m;                /* its largest coordinate magnitude */
    double n[3], nd;         /* the plane: normal, n . a */
    double an[3];            /* |n| */
    double ax[9][2];         /* axis k, edge j: (au, aw) */
    double aabs[9][2];       /* their magnitudes */
    double pmin[9], pmax[9]; /* the vertices' projections on each axis */
    double v[3][3];          /* the vertices (copied) */
    int ok;                  /* 0: keep every box (non-finite or out of range) */
} st_tri_box_filter;

void st_tri_box_filter_init(st_tri_box_filter *f, const double a[3], const double b[3],
                            const double c[3]);
int st_tri_box_filter_maybe(const st_tri_box_filter *f, const double lo[3],
                            const double hi[3]);

/* 1 when p lies in the closed triangle (a b c) of any shape (collinear:
 * its segment; coincident: its point), else 0. (Added by isect.c's
 * author; not part of the original contract.) */
int st_point_in_tri(const double p[3], const double a[3], const double b[3],
                    const double c[3]);

/* Cost (isect.c; tests/test_isect.c, one core of a loaded machine, CPU
 * time, small random triangles / tets / boxes of size ~0.1 in the unit
 * cube; "near" pairs share a centre, "far" pairs are random): millions of
 * calls per second, near / far:
 *   st_point_in_tet ~17 / ~17, st_segment_tri_intersect ~18 / ~24,
 *   st_tri_tri_intersect ~6 / ~30, st_tri_tet_intersect ~2.4 / ~25,
 *   st_tri_box_intersect ~11 / ~60.
 * The predicates' filter decides nearly every call; (near-)degenerate
 * input (coplanar points with inexact differences) costs ~0.3 us per
 * exact orient3d; a repeated point (shared vertex) is answered at once. */

#ifdef __cplusplus
}
#endif
#endif
