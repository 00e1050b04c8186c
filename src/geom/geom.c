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

double st_norm3(const double v[3])
{
    double m = fmax(fabs(v[0]), fmax(fabs(v[1]), fabs(v[2])));
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

double st_point_triangle_dist2(const double p[3], const double a[3],
                               const double b[3], const double c[3],
                               double closest[3])
{
    const double *v[3] = {a, b, c};
    double e[3][3], n[3];
    st_sub3(e[0], b, a);
    st_sub3(e[1], c, b);
    st_sub3(e[2], a, c);
    st_cross3(n, e[0], e[1]);
    double emax = fmax(st_norm3(e[0]), fmax(st_norm3(e[1]), st_norm3(e[2])));
    double nl = st_norm3(n);
    int degenerate = !(nl > ST_DEGENERATE_AREA_RATIO * emax * emax);
    if (!degenerate)
        for (int k = 0; k < 3; k++)
            n[k] /= nl;                 /* unit normal: no under/overflow */

    int outside[3] = {1, 1, 1};
    if (!degenerate) {
        int inside = 1;
        for (int i = 0; i < 3; i++) {
            double m[3], vp[3];
            st_cross3(m, n, e[i]);      /* in-plane, points into the triangle */
            st_sub3(vp, p, v[i]);
            outside[i] = st_dot3(vp, m) < 0.0;
            inside &= !outside[i];
        }
        if (inside) {
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
    }
    double best = INFINITY, q[3];
    for (int i = 0; i < 3; i++) {
        if (!outside[i])
            continue;
        double d2 = st_point_segment_dist2(p, v[i], v[(i + 1) % 3], q);
        if (d2 < best) {
            best = d2;
            if (closest) {
                closest[0] = q[0];
                closest[1] = q[1];
                closest[2] = q[2];
            }
        }
    }
    return best;
}
