/*
 * geom.c - point-segment and point-triangle distance.
 *
 * The triangle routine classifies p against the three edge planes that
 * stand perpendicular to the triangle (the prism over it): inside the prism
 * the distance is the distance to the supporting plane; outside, the closest
 * point lies on an edge whose outer side holds p, so only those edges are
 * measured. That covers all seven Voronoi regions (face, three edges, three
 * vertices: a vertex is the clamped end of an edge).
 */
#include "souptet/geom.h"
#include "../base/fpenv.h"

#include <math.h>

/* fmax(a, b) for a, b that are not -0 (lengths and fabs values): the
 * other one when one is NaN, NaN when both are, else the larger. Inline,
 * where fmax is a call into libm unless NaN is compiled away (fpenv.h). */
static inline double max_len(double a, double b)
{
    return a > b || b != b ? a : b;
}

double st_norm3(const double v[3])
{
    double m = max_len(fabs(v[0]), max_len(fabs(v[1]), fabs(v[2])));
    if (!(m > 0.0) || !isfinite(m))
        return m;
    double x = v[0] / m, y = v[1] / m, z = v[2] / m;
    return m * sqrt(x * x + y * y + z * z);
}

double st_point_segment_dist2(const double p[3], const double a[3],
                              const double b[3], double closest[3])
{
    double e[3], ap[3];
    st_sub3(e, b, a);
    st_sub3(ap, p, a);
    double ee = st_dot3(e, e);
    double t = 0.0;
    if (ee > 0.0) {
        t = st_dot3(ap, e) / ee;
        t = t < 0.0 ? 0.0 : (t > 1.0 ? 1.0 : t);
    }
    double q[3] = {a[0] + t * e[0], a[1] + t * e[1], a[2] + t * e[2]};
    if (closest) {
        closest[0] = q[0];
        closest[1] = q[1];
        closest[2] = q[2];
    }
    double d[3];
    st_sub3(d, p, q);
    return st_dot3(d, d);
}

/* The degeneracy test of st_point_triangle_dist2 (geom.h): whether
 * !(|n| > ST_DEGENERATE_AREA_RATIO * emax * emax), |n| and emax (the
 * longest edge) by st_norm3; sets *nl = st_norm3(n) when it says no.
 *
 * Screen: where the longest edge squared (ee, a dot product) is in
 * [2^-400, 2^400], nothing below overflows and ee * ee and the threshold
 * t = R^2 ee^2 are normal doubles, so the dot products and st_norm3 are
 * each within 10 rounding units (2e-15) of the exact lengths of the same
 * rounded vectors n and e[i] (subnormal squares in n . n add at most
 * 2^-1074 each, far below 1e-6 t >= 2^-873). The squared test n . n
 * against t then agrees with the norms' test wherever the two sides
 * differ by more than 1e-6 (relative): it decides those, and only the
 * band between (and NaN, infinity, extreme scales) takes the three edge
 * norms, the same answer in both cases, bit for bit. */
/* (always inlined: st_point_triangle_dist2 and st_tri_frame_make both
 * call it, and a call costs the distance about 25 instructions) */
#if defined(__GNUC__)
__attribute__((always_inline))
#endif
static inline int tri_degenerate(const double e[3][3], const double n[3], double *nl)
{
    double ee = st_dot3(e[0], e[0]), e1 = st_dot3(e[1], e[1]), e2 = st_dot3(e[2], e[2]);
    ee = e1 > ee ? e1 : ee;
    ee = e2 > ee ? e2 : ee;
    if (ee >= 0x1p-400 && ee <= 0x1p400) {   /* false for NaN */
        const double t = ST_DEGENERATE_AREA_RATIO * ST_DEGENERATE_AREA_RATIO * ee * ee;
        const double nn = st_dot3(n, n);
        if (nn < t * (1.0 - 1e-6))
            return 1;
        if (nn > t * (1.0 + 1e-6)) {
            *nl = st_norm3(n);
            return 0;
        }
    }
    double emax = max_len(st_norm3(e[0]), max_len(st_norm3(e[1]), st_norm3(e[2])));
    *nl = st_norm3(n);
    return !(*nl > ST_DEGENERATE_AREA_RATIO * emax * emax);
}

/* Whether p lies outside the edge e from v: behind the in-plane normal
 * n x e, which points into the triangle (n its unit normal). */
static inline int edge_outside(const double n[3], const double e[3], const double p[3],
                               const double v[3])
{
    double m[3], vp[3];
    st_cross3(m, n, e);
    st_sub3(vp, p, v);
    return st_dot3(vp, m) < 0.0;
}

/* The distance from p to the segment [u, w] into *best, and its closest
 * point into closest (when not NULL), if it is below *best. */
static inline void nearer_edge(const double p[3], const double u[3], const double w[3],
                               double *best, double closest[3])
{
    double q[3];
    const double d2 = st_point_segment_dist2(p, u, w, q);
    if (d2 < *best) {
        *best = d2;
        if (closest) {
            closest[0] = q[0];
            closest[1] = q[1];
            closest[2] = q[2];
        }
    }
}

/* The squared distance from p to the triangle (a, b, c) of unit normal n,
 * given on which sides of its edges ab, bc, ca p lies (outside[k]; all 1
 * for a degenerate triangle): the plane's where p is inside all three,
 * else the nearest of the edges it lies outside, the first of equals in
 * the order ab, bc, ca; its closest point into closest (when not NULL).
 * (Always inlined, as tri_degenerate: both distances call it.) */
#if defined(__GNUC__)
__attribute__((always_inline))
#endif
static inline double dist2_given_sides(const double p[3], const double a[3],
                                       const double b[3], const double c[3],
                                       const double n[3], const int outside[3],
                                       double closest[3])
{
    if (!(outside[0] | outside[1] | outside[2])) {
        double ap[3];
        st_sub3(ap, p, a);
        double s = st_dot3(ap, n);
        if (closest) {
            closest[0] = p[0] - s * n[0];
            closest[1] = p[1] - s * n[1];
            closest[2] = p[2] - s * n[2];
        }
        return s * s;
    }
    double best = INFINITY;
    if (outside[0])
        nearer_edge(p, a, b, &best, closest);
    if (outside[1])
        nearer_edge(p, b, c, &best, closest);
    if (outside[2])
        nearer_edge(p, c, a, &best, closest);
    return best;
}

double st_point_triangle_dist2(const double p[3], const double a[3],
                               const double b[3], const double c[3],
                               double closest[3])
{
    double e[3][3], n[3];
    st_sub3(e[0], b, a);
    st_sub3(e[1], c, b);
    st_sub3(e[2], a, c);
    st_cross3(n, e[0], e[1]);
    double nl = 0.0;
    int degenerate = tri_degenerate(e, n, &nl);
    if (!degenerate) {   /* unit normal: no under/overflow */
        n[0] /= nl;
        n[1] /= nl;
        n[2] /= nl;
    }

    int outside[3] = {1, 1, 1};
    if (!degenerate) {
        outside[0] = edge_outside(n, e[0], p, a);
        outside[1] = edge_outside(n, e[1], p, b);
        outside[2] = edge_outside(n, e[2], p, c);
    }
    return dist2_given_sides(p, a, b, c, n, outside, closest);
}

/* The frame: st_point_triangle_dist2's normal, degeneracy test and the
 * cross products edge_outside takes, in the same operations. */
void st_tri_frame_make(st_tri_frame *f, const double a[3], const double b[3],
                       const double c[3])
{
    double e[3][3], n[3];
    st_sub3(e[0], b, a);
    st_sub3(e[1], c, b);
    st_sub3(e[2], a, c);
    st_cross3(n, e[0], e[1]);
    double nl = 0.0;
    f->degenerate = tri_degenerate(e, n, &nl);
    if (!f->degenerate) {
        n[0] /= nl;
        n[1] /= nl;
        n[2] /= nl;
        for (int k = 0; k < 3; k++)
            st_cross3(f->m[k], n, e[k]);
    }
    f->n[0] = n[0];
    f->n[1] = n[1];
    f->n[2] = n[2];
}

/* Whether p lies outside the edge from v whose in-plane normal is m (the
 * cross product edge_outside computes). */
static inline int framed_outside(const double m[3], const double p[3], const double v[3])
{
    double vp[3];
    st_sub3(vp, p, v);
    return st_dot3(vp, m) < 0.0;
}

double st_point_triangle_dist2_framed(const double p[3], const double a[3],
                                      const double b[3], const double c[3],
                                      const st_tri_frame *f, double closest[3])
{
    int outside[3] = {1, 1, 1};
    if (!f->degenerate) {
        outside[0] = framed_outside(f->m[0], p, a);
        outside[1] = framed_outside(f->m[1], p, b);
        outside[2] = framed_outside(f->m[2], p, c);
    }
    return dist2_given_sides(p, a, b, c, f->n, outside, closest);
}
