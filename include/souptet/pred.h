/*
 * pred.h - exact orientation predicates.
 *
 * Units: none: signs of determinants of the coordinates given.
 * Ownership: none: values in, values out.
 * Threads: pure functions, thread-safe (the count of exact evaluations is
 * atomic).
 * Errors: none: every finite input gets an exact sign.
 *
 * Every topological decision in souptet (which side of a plane, whether two
 * triangles cross, whether a lattice tet touches the surface, whether a ray
 * crosses a face) comes down to the sign of one of these determinants. The
 * sign returned is always the sign of the exact determinant of the given
 * doubles, never of a rounded one: a floating-point filter with a proven
 * error bound answers almost every call, and an exact evaluation in
 * floating-point expansion arithmetic (Shewchuk 1997) answers the rest.
 * The magnitude returned is only an approximation (within a factor of 2
 * when the exact stage answers, and clamped to the double range).
 *
 * Range. The filter is valid for every finite input (overflow sends the
 * call to the exact stage; underflow is covered by an absolute term in the
 * bound). The exact stage first scales the input by a power of two, so what
 * limits it is the *spread* of the coordinates, not their size: the sign is
 * exact whenever every coordinate of the call is an integer multiple of
 * 2^Q and smaller than 2^(Q + ST_PRED_SPREAD_BITS) in magnitude, for some
 * Q. Since a double is a multiple of its own ulp, that holds whenever the
 * nonzero coordinates of the call lie within a factor 2^588 (about 1e177)
 * of each other, whatever their size: all in [1e-150, 1e20], or in [1e-60,
 * 1e100], or in [1e-300, 1e-150]. Zeros never count. Models in metres or
 * millimetres are far inside. Inputs must be finite (soups are: soup.h
 * guarantees it).
 *
 * Conventions (those of Shewchuk's predicates):
 *   st_orient2d(a, b, c) > 0  when a, b, c turn counterclockwise,
 *                        < 0  clockwise, = 0 collinear. It equals
 *                        det | a-c ; b-c | = ((b - a) x (c - a)).z.
 *   st_orient3d(a, b, c, d) > 0 when d lies below the plane through a, b, c,
 *                        "below" meaning opposite the side from which a, b,
 *                        c appear counterclockwise: it equals
 *                        det | a-d ; b-d ; c-d | = -(d - a) . ((b - a) x (c - a)).
 *                        = 0 when the four points are coplanar.
 *
 * All functions are pure and thread-safe.
 *
 * Reference: J. R. Shewchuk, "Adaptive Precision Floating-Point Arithmetic
 * and Fast Robust Geometric Predicates", Discrete & Computational Geometry
 * 18:305-363, 1997. The code is written here from the paper.
 */
#ifndef SOUPTET_PRED_H
#define SOUPTET_PRED_H

#ifdef __cplusplus
extern "C" {
#endif

/* The exact stage is exact when the call's coordinates, written as integer
 * multiples of their finest common power of two, are all below
 * 2^ST_PRED_SPREAD_BITS in magnitude (pred.c derives it). */
#define ST_PRED_SPREAD_BITS 640

/* Sign of det | a-c ; b-c | for 2-D points (see the conventions above). */
double st_orient2d(const double a[2], const double b[2], const double c[2]);

/* st_orient2d of the 3-D points projected onto the coordinate plane that
 * drops axis `drop` (0, 1 or 2), keeping the cyclic order of the two other
 * axes: drop 0 uses (y, z), drop 1 uses (z, x), drop 2 uses (x, y). So the
 * result has the sign of component `drop` of (b - a) x (c - a), and a
 * triangle's three projections all vanish exactly when it is degenerate
 * (its vertices collinear or coincident). */
double st_orient2d_drop(const double a[3], const double b[3],
                        const double c[3], int drop);

/* Sign of det | a-d ; b-d ; c-d | (see the conventions above). */
double st_orient3d(const double a[3], const double b[3], const double c[3],
                   const double d[3]);

/* -1, 0 or +1: the sign of x. For the results above. */
static inline int st_sign(double x)
{
    return (x > 0.0) - (x < 0.0);
}

/* A filtered side test against the plane through o, a and b, for pruning
 * before an exact test, never for deciding (issue 23). It keeps the plane's
 * rounded normal (the cross product of a - o and b - o), the absolute sums
 * orient3d's error bound takes (the same six monomials through at most
 * five roundings, here with a margin of 16 u instead of 9 u and 2^-1000
 * instead of 2^-1040 for underflow), and the exact side of a reference
 * point r (st_orient3d). o is kept by address. */
typedef struct st_plane_filter {
    const double *o;
    double n[3], an[3];
    int side;   /* +1, -1: the side of r; 0: r on the plane */
} st_plane_filter;

#define ST_PLANE_FILTER_REL (16.0 * 0x1p-53)
#define ST_PLANE_FILTER_ABS 0x1p-1000

void st_plane_filter_init(st_plane_filter *pl, const double o[3], const double a[3],
                          const double b[3], const double r[3]);
/* The plane alone, without a reference point (side 0): st_plane_filter_init
 * without its orient3d, for st_plane_filter_sign. */
void st_plane_filter_plane(st_plane_filter *pl, const double o[3], const double a[3],
                           const double b[3]);

/* +1 or -1 when the filter certifies the side of the plane q lies on, in
 * the units of pl->side (+1: st_orient3d(o, a, b, q) < 0, -1: > 0); 0 when
 * q may be on the plane or the filter cannot tell. */
static inline int st_plane_filter_sign(const st_plane_filter *pl, const double q[3])
{
    double d0 = q[0] - pl->o[0], d1 = q[1] - pl->o[1], d2 = q[2] - pl->o[2];
    double det = d0 * pl->n[0] + d1 * pl->n[1] + d2 * pl->n[2];
    double a0 = d0 < 0 ? -d0 : d0, a1 = d1 < 0 ? -d1 : d1, a2 = d2 < 0 ? -d2 : d2;
    double perm = a0 * pl->an[0] + a1 * pl->an[1] + a2 * pl->an[2];
    double bound = ST_PLANE_FILTER_REL * perm + (a0 + a1 + a2 + 1.0) * ST_PLANE_FILTER_ABS;
    return det > bound ? 1 : (-det > bound ? -1 : 0);
}

/* 1 when q certainly lies strictly on the other side of the plane from r
 * (when r is on the plane: strictly off it); 0 when it may not, or the
 * filter cannot tell. */
static inline int st_plane_filter_rejects(const st_plane_filter *pl, const double q[3])
{
    const int s = st_plane_filter_sign(pl, q);
    return s != 0 && s != pl->side;
}

/* How many calls, since the program started, the filter could not decide
 * and the exact stage answered (all threads together; relaxed atomic
 * counters, for tests and measurements). */
unsigned long long st_pred_exact_calls(void);

#ifdef __cplusplus
}
#endif
#endif
