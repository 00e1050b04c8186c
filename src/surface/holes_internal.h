/*
 * holes_internal.h - the caps rebuilt from the planes around a hole
 * (holes_planes.c), for holes.c; holes.c's least-area triangulation and
 * its screen, for holes_planes.c's callers and the tests.
 */
#ifndef SOUPTET_HOLES_INTERNAL_H
#define SOUPTET_HOLES_INTERNAL_H

#include <stddef.h>
#include <stdint.h>
#include <math.h>
#include "souptet/bvh.h"
#include "souptet/edges.h"
#include "souptet/err.h"
#include "souptet/geom.h"
#include "souptet/soup.h"

/* AVX, four lanes of doubles, where the processor has it (checked when
 * called, holes_avx): the loops that take two edges or apexes at a time
 * with SSE2 take four, each lane the scalar operations in the same order
 * (no contraction: the Makefile's FP_EXACT), so every answer is the same
 * to the bit (doc/design/holes.md, "Costs"). */
#if defined(__GNUC__) && defined(__x86_64__)
#define HOLES_AVX 1
#define HOLES_AVX_FN __attribute__((target("avx")))
static inline int holes_avx(void)
{
    return __builtin_cpu_supports("avx");
}
#endif

/* The distance between a and b. */
static inline double dist3(const double *a, const double *b)
{
    double d[3];
    st_sub3(d, a, b);
    return st_norm3(d);
}

/* Unit normal of triangle (p, q, r), (q - p) x (r - p); zero when
 * degenerate. */
static inline void unit_normal(double *nrm, const double *p, const double *q, const double *r)
{
    double u[3], v[3];
    st_sub3(u, q, p);
    st_sub3(v, r, p);
    st_cross3(nrm, u, v);
    const double l = st_norm3(nrm);
    for (int k = 0; k < 3; k++)
        nrm[k] = l > 0.0 ? nrm[k] / l : 0.0;
}

/* The bend across an edge between two triangles whose unit normals are a
 * and b (both of one orientation, each passing the edge the other way):
 * their dihedral deviation in radians, 0 where they continue flat, pi
 * where one folds back onto the other; 4 (more than any fold) where a
 * triangle is degenerate. */
static inline double bend(const double *a, const double *b)
{
    if (st_dot3(a, a) == 0.0 || st_dot3(b, b) == 0.0)
        return 4.0;
    double c[3];
    st_cross3(c, a, b);
    return atan2(st_norm3(c), st_dot3(a, b));
}

/* The least-area triangulation of the polygon pts[0..n) (n >= 3, holes.c):
 * fills tri[3 (n - 2)] with local indices and *area with its area
 * (dynamic programming, O(n^3); ties keep the first apex). ST_ENOMEM. */
st_status st_holes_least_area(double *area, const double *const *pts, size_t n, uint32_t *tri,
                              st_error *err);

/* The triangulation of the loop pts[0..n) (n >= 3) on its own points
 * that bends least along its edges and the soup's triangles beside the
 * loop (side[i]: the third point of the one on edge pts[i] -> pts[i + 1
 * mod n]), ties by area, then by the first apex (holes.c): fills
 * tri[3 (n - 2)] with local indices and *area with its area (an
 * st_holes_fill). ST_ENOMEM. */
st_status st_holes_least_bend(double *area, const double *const *pts, const double *const *side,
                              size_t n, uint32_t *tri, st_error *err);

/* 1 when st_holes_least_area's area of the loop pts[0..n) is surely above
 * lim, told without it where it can be (its vector area, or the same
 * program rounded otherwise, with a margin; holes.c); 0 when unsure.
 * Never 1 where that area is at most lim. */
int st_holes_area_above(const double *const *pts, size_t n, double lim);

/* A loop as the cones' screen reads it (holes_planes.c): its points
 * p[c (n + 1) + i] (coordinate c, the first point again at i = n), its
 * edges' unit normals r[c n + i] (rim, as loop_planes gives them) and
 * whether each edge counts (mask[i]: all bits set where it is not along a
 * crease, else 0.0), filled by
 * st_holes_cone_rim_fill from pts[0..n), rim[3 n] and crease (NULL:
 * none). */
typedef struct st_holes_cone_rim {
    double *p, *r, *mask;
} st_holes_cone_rim;
void st_holes_cone_rim_fill(st_holes_cone_rim *cr, const double *const *pts, const double *rim,
                            const double *crease, size_t n);
/* 1 when the cone from apex over the loop in cr (n edges) surely bends
 * no less than below along it: the sum over its edges, in order, of the
 * edge's length times the sine of the angle between the soup's normal and
 * the cone's (a right angle where they face apart), less a margin, reaches
 * below before an edge of a length out of [1e-100, 1e100]. 0 when unsure. */
int st_holes_cone_above(const double *apex, const st_holes_cone_rim *cr, size_t n, double below);

/* The screen before the fans' flatness test (holes_planes.c): the loop's
 * edges i (of n) whose fan to apex may continue the soup's plane across
 * them, |s| <= sqrt(l2) |f| with f = apex - a and s = f . r, decided as
 * !(s s > l2 (f . f)) with the dot products summed x, y, z: in near[]
 * (room for n), in order; returns how many. scr holds a column of each:
 * a's x, y, z, r's x, y, z, l2 (scr[c n + i]). */
size_t st_holes_fan_near(size_t *near, const double *scr, size_t n, const double *apex);

/* The surviving soup a rebuilt corner's triangles may not pierce
 * (st_tri_tri_cross; touching it is no crossing): its BVH and which of
 * its triangles count (edges.h's kept). NULL or bvh NULL: no test. */
typedef struct st_holes_guard {
    const st_bvh *bvh;
    const uint8_t *kept;
    const double *crease;   /* NULL, or st_holes_creases' planes per loop
                             * edge: the caps' bend along the loop is then
                             * st_holes_crease_bend's */
} st_holes_guard;

/* The creases the loop pts[0..n) runs along: for each loop edge i, the
 * unit normals (crease[6 i], crease[6 i + 3]; zero where none) of up to
 * two planes of the soup's other triangles along the loop (pts[j],
 * side[j], pts[j + 1]) that hold both of its ends exactly (st_orient3d)
 * and not its own triangle's third point: the edge lies on the line where
 * its triangle's face meets another face of the part, and the face lost
 * across it may be that one (holes.c; doc/design/holes.md, "Creases"). */
void st_holes_creases(double *crease, const double *const *pts, const double *const *side,
                      size_t n);

/* The bend along a loop edge of a cap triangle of unit normal nt, against
 * the soup's triangle there (unit normal nr, as bend()) or, where the
 * edge runs along a crease (cr: its two normals from st_holes_creases, or
 * NULL), against the other face's plane there (the angle between the two
 * planes, 0 where the cap lies in it): the least. */
static inline double st_holes_crease_bend(const double *nt, const double *nr, const double *cr)
{
    double b = bend(nt, nr);
    if (!cr || st_dot3(nt, nt) == 0.0)
        return b;
    for (int k = 0; k < 2; k++) {
        const double *a = cr + 3 * k;
        if (st_dot3(a, a) == 0.0)
            continue;
        double c[3];
        st_cross3(c, nt, a);
        b = fmin(b, atan2(st_norm3(c), fabs(st_dot3(nt, a))));
    }
    return b;
}

/* The cap of the loop pts[0..n) (n >= 3) from a corner rebuilt from the
 * planes of the soup's triangles along it (side[i]: the third point of
 * the triangle on edge pts[i] -> pts[i + 1 mod n]; see holes_planes.c):
 * the cone from the apex that bends least (of those whose cone pierces
 * no triangle of guard's soup), when it bends less than
 * `below`, is appended to out (n + 1 vertices, n triangles) and *done set
 * to 1; else out is left as it was and *done is 0. ST_ENOMEM, ST_ELIMIT. */
st_status st_holes_planes_cap(st_soup *out, int *done, const double *const *pts,
                              const double *const *side, size_t n, double below,
                              const st_holes_guard *guard, double *bent, st_error *err);

/* A triangulation of the loop pts[0..n) (side as above): fills
 * tri[3 (n - 2)] with local indices and *area with its area. ST_ENOMEM. */
typedef st_status (*st_holes_fill)(double *area, const double *const *pts,
                                   const double *const *side, size_t n, uint32_t *tri,
                                   st_error *err);

/* The cap of the loop from several rebuilt corners: the point where planes
 * along the loop meet that continues most of its length, fans from it over
 * the edges it continues (where its fan pierces none of guard's soup),
 * the rest of the loop (split where it meets the
 * point more than once) capped the same way, and what no such point
 * continues by fill (see holes_planes.c). Appended to out with *done 1 when
 * it bends along the loop less than `below`; else out is left as it was.
 * ST_ENOMEM, ST_ELIMIT. */
st_status st_holes_planes_fans(st_soup *out, int *done, const double *const *pts,
                               const double *const *side, size_t n, double below,
                               st_holes_fill fill, const st_holes_guard *guard, double *bent,
                               st_error *err);

/* The cap of the loop pts[0..n) (side as above) where the soup's
 * triangles along it include a cylinder (a fit certified against the
 * loop's extent; see holes_cyl.c): the cylinder continued across the
 * hole and rebuilt where it meets the continued planes. out holds the
 * caps so far, the caller's cap of this loop from vertex vbase and
 * triangle tbase on; when the cylinder's cap bends along the loop less
 * than `below` and pierces neither guard's soup, out's triangles before
 * tbase nor itself, it replaces the caller's (out cut back to vbase,
 * tbase) with *done 1; else out is left as it was and *done is 0.
 * ST_ENOMEM, ST_ELIMIT. */
st_status st_holes_cyl_cap(st_soup *out, int *done, size_t vbase, size_t tbase,
                           const double *const *pts, const double *const *side, size_t n,
                           double below, st_holes_fill fill, const st_holes_guard *guard,
                           st_error *err);

/* 1 when a triangle of cap (NULL: none) pierces one of caps'
 * (st_tri_tri_cross, as st_holes_cyl_cap tests its cap against the caps
 * before it; holes_cyl.c). */
int st_holes_caps_cross(const st_soup *caps, const st_soup *cap);

/* What a faired cap reads of the soup around its loop: the soup, its edge
 * table, its BVH, and the loop's welded points (lv[0..n), one per point of
 * pts, see holes_fair.c). */
typedef struct st_holes_rimref {
    const st_soup *s;
    const st_soup_edges *E;
    const st_bvh *bvh;
    const uint32_t *lv;
} st_holes_rimref;

/* The cap of the loop pts[0..n) (n >= 3; tri its triangulation, n - 2
 * triangles of local indices) refined and faired to continue the soup
 * around it (Liepa 2003; holes_fair.c), where that soup is smooth within
 * a ring of the loop: appended to out (the loop's points first, as they
 * are, then the inner points) with *done 1. Where the ring has a sharp or
 * non-manifold edge, the loop meets a point twice, nothing needs refining,
 * or the faired cap pierces the soup or itself (exact), out is left as it
 * was and *done is 0. ST_ENOMEM. */
st_status st_holes_fair_cap(st_soup *out, int *done, const st_holes_rimref *ref,
                            const double *const *pts, size_t n, const uint32_t *tri,
                            st_error *err);

#endif
