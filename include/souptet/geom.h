/*
 * geom.h - small vector helpers and point-triangle distance.
 *
 * Units: model units (distances squared where the name says dist2).
 * Ownership: none: values in, values out.
 * Threads: pure functions, thread-safe.
 * Errors: none: nothing here can fail.
 *
 * Distances are computed in double from the input coordinates; no tolerance
 * decides anything topological here (those decisions go through pred.h).
 */
#ifndef SOUPTET_GEOM_H
#define SOUPTET_GEOM_H

#ifdef __cplusplus
extern "C" {
#endif

static inline double st_dot3(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
static inline void st_sub3(double out[3], const double a[3], const double b[3])
{
    out[0] = a[0] - b[0];
    out[1] = a[1] - b[1];
    out[2] = a[2] - b[2];
}
static inline void st_cross3(double out[3], const double a[3], const double b[3])
{
    double x = a[1] * b[2] - a[2] * b[1];
    double y = a[2] * b[0] - a[0] * b[2];
    double z = a[0] * b[1] - a[1] * b[0];
    out[0] = x;
    out[1] = y;
    out[2] = z;
}

/* The squared distance from p to the box [lo, hi]: per axis the larger of
 * lo - p, p - hi and 0 (at most one is positive, so the sum is exact and
 * the same as choosing the positive one), without branches. */
static inline double st_box_dist2(const double lo[3], const double hi[3], const double p[3])
{
    double d2 = 0.0;
    for (int a = 0; a < 3; a++) {
        const double below = lo[a] - p[a], above = p[a] - hi[a];
        const double d = (below > 0.0 ? below : 0.0) + (above > 0.0 ? above : 0.0);
        d2 += d * d;
    }
    return d2;
}

/* Euclidean length, scaled so that tiny or huge components neither
 * underflow nor overflow when squared. */
double st_norm3(const double v[3]);

/* Squared distance from p to the closed segment [a, b]; a == b is a point.
 * If closest is not NULL it receives the closest point. */
double st_point_segment_dist2(const double p[3], const double a[3],
                              const double b[3], double closest[3]);

/* Squared distance from p to the closed triangle (a, b, c), and the closest
 * point when `closest` is not NULL. Works for every triangle, including
 * degenerate ones (collinear or repeated vertices: the distance to its
 * edges). A triangle is treated as degenerate when its doubled area is at
 * most ST_DEGENERATE_AREA_RATIO times the square of its longest edge: the
 * plane through it is then too ill-conditioned to project onto, while the
 * distance to its edges differs from the true one by at most its width,
 * which is below that ratio times the longest edge. */
#define ST_DEGENERATE_AREA_RATIO 1e-8
double st_point_triangle_dist2(const double p[3], const double a[3],
                               const double b[3], const double c[3],
                               double closest[3]);

/* What st_point_triangle_dist2 computes from the triangle alone, kept for
 * a triangle that many points are measured against: its unit normal n,
 * whether it is degenerate (as above), and the in-plane normals of its
 * edges ab, bc, ca (n x (b - a) and so on; unset when degenerate). */
typedef struct st_tri_frame {
    double n[3];
    double m[3][3];
    int degenerate;
} st_tri_frame;

void st_tri_frame_make(st_tri_frame *f, const double a[3], const double b[3],
                       const double c[3]);

/* st_point_triangle_dist2(p, a, b, c, closest) for the triangle f was made
 * from (st_tri_frame_make(f, a, b, c)): the same distance and closest
 * point, bit for bit. */
double st_point_triangle_dist2_framed(const double p[3], const double a[3],
                                      const double b[3], const double c[3],
                                      const st_tri_frame *f, double closest[3]);

#ifdef __cplusplus
}
#endif
#endif
