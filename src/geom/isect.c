/*
 * isect.c - exact intersection tests for closed triangles, segments, points,
 * tetrahedra and boxes (see isect.h), on the predicates of pred.h only.
 *
 * Every decision is the sign of an orient2d / orient3d determinant of input
 * coordinates or an exact comparison of two input coordinates, so every
 * answer is exact. Degenerate inputs are reduced to the point sets they
 * are: a triangle whose vertices are collinear is the union of its three
 * edges (one of them is the whole segment), a flat tet is the union of its
 * four faces (Caratheodory: every point of the convex hull of four coplanar
 * points lies in a triangle of three of them).
 *
 * Projections. A nondegenerate triangle has a normal with some nonzero
 * component k (st_orient2d_drop says which, exactly); dropping axis k maps
 * its plane one-to-one onto the coordinate plane, so containment and
 * crossings of points in that plane are decided by orient2d there. For
 * points known to be collinear, one coordinate that is not the same for
 * all of them orders them along the line.
 */
#include "souptet/isect.h"
#include "../base/fpenv.h"
#include "souptet/pred.h"

#include <math.h>
#include <stddef.h>

/* ---- small helpers -------------------------------------------------------- */

static inline int o3(const double *a, const double *b, const double *c,
                     const double *d)
{
    return st_sign(st_orient3d(a, b, c, d));
}

static inline int o2(const double *a, const double *b, const double *c, int k)
{
    return st_sign(st_orient2d_drop(a, b, c, k));
}

static inline int same_point(const double *a, const double *b)
{
    return a[0] == b[0] && a[1] == b[1] && a[2] == b[2];
}

/* The axis to drop for a nondegenerate triangle (the normal component of
 * largest approximate magnitude, so the 2-D predicates are well
 * conditioned), with *s the sign of that component; -1 when the triangle
 * is degenerate (all three components exactly zero). */
static int tri_axis(const double *a, const double *b, const double *c, int *s)
{
    int best = -1;
    double bm = 0.0;
    *s = 0;
    for (int k = 0; k < 3; k++) {
        double v = st_orient2d_drop(a, b, c, k);
        if (fabs(v) > bm) {
            bm = fabs(v);
            best = k;
            *s = st_sign(v);
        }
    }
    return best;
}

/* Closed 1-D overlap of [p, q] and [a, b] along axis m. */
static int overlap_1d(const double *p, const double *q, const double *a,
                      const double *b, int m)
{
    double lo1 = fmin(p[m], q[m]), hi1 = fmax(p[m], q[m]);
    double lo2 = fmin(a[m], b[m]), hi2 = fmax(a[m], b[m]);
    return fmax(lo1, lo2) <= fmin(hi1, hi2);
}

/* An axis along which not all of the given points have the same coordinate,
 * or -1 when they are all the same point. */
static int varying_axis(const double *const *v, int n)
{
    for (int m = 0; m < 3; m++)
        for (int i = 1; i < n; i++)
            if (v[i][m] != v[0][m])
                return m;
    return -1;
}

/* Closed segments [p, q] and [a, b] known to lie on one line (either may
 * be a single point). */
static int collinear_segments(const double *p, const double *q,
                              const double *a, const double *b)
{
    const double *v[4] = {p, q, a, b};
    int m = varying_axis(v, 4);
    if (m < 0)
        return 1;
    return overlap_1d(p, q, a, b, m);
}

/* Closed segments [p, q] and [a, b] in the projection dropping axis k, which
 * must be one-to-one on a plane containing all four points. */
static int seg_seg_2d(const double *p, const double *q, const double *a,
                      const double *b, int k)
{
    int s1 = o2(p, q, a, k), s2 = o2(p, q, b, k);
    if (s1 * s2 > 0)
        return 0;
    int s3 = o2(a, b, p, k), s4 = o2(a, b, q, k);
    if (s3 * s4 > 0)
        return 0;
    if (s1 == 0 && s2 == 0 && s3 == 0 && s4 == 0)
        return collinear_segments(p, q, a, b);
    /* Not all collinear, no strict separation: both segments are proper
     * (a point segment gives s1 = s2 = 0 and s3 = s4), the lines are
     * distinct and not parallel (parallel distinct lines give s1 = s2 != 0),
     * and each segment meets the other's line, at their one common point. */
    return 1;
}

/* Closed point p in the closed triangle (a b c) in the projection dropping
 * axis k, where the projected triangle is nondegenerate with orientation
 * s (+1 or -1). */
static int point_in_tri_2d(const double *p, const double *a, const double *b,
                           const double *c, int k, int s)
{
    return o2(a, b, p, k) != -s && o2(b, c, p, k) != -s &&
           o2(c, a, p, k) != -s;
}

/* Closed segments in 3-D (either may be a point). */
static int seg_seg_3d(const double *p, const double *q, const double *a,
                      const double *b)
{
    if (o3(p, q, a, b) != 0)
        return 0;
    /* Coplanar: find a projection one-to-one on their plane, from a triple
     * of the points that is not collinear. */
    const double *tri[4][3] = {{p, q, a}, {p, q, b}, {a, b, p}, {a, b, q}};
    for (int t = 0; t < 4; t++) {
        int s;
        int k = tri_axis(tri[t][0], tri[t][1], tri[t][2], &s);
        if (k >= 0)
            return seg_seg_2d(p, q, a, b, k);
    }
    return collinear_segments(p, q, a, b);
}

/* Closed point on the closed segment [a, b] (a may equal b). */
static int point_on_segment(const double *p, const double *a, const double *b)
{
    for (int k = 0; k < 3; k++)
        if (o2(a, b, p, k) != 0)
            return 0;
    /* (b - a) x (p - a) = 0: collinear (or a = b, then p must equal it). */
    for (int m = 0; m < 3; m++)
        if (p[m] < fmin(a[m], b[m]) || p[m] > fmax(a[m], b[m]))
            return 0;
    return 1;
}

/* Closed point in a closed triangle of any shape. */
static int point_in_tri(const double *p, const double *a, const double *b,
                        const double *c)
{
    int s;
    int k = tri_axis(a, b, c, &s);
    if (k < 0)
        return point_on_segment(p, a, b) || point_on_segment(p, b, c) ||
               point_on_segment(p, c, a);
    if (o3(a, b, c, p) != 0)
        return 0;
    return point_in_tri_2d(p, a, b, c, k, s);
}

/* Closed segment [p, q] against the closed nondegenerate triangle (a b c),
 * given sp, sq = sign orient3d(a, b, c, p / q). */
static int seg_tri_signed(const double *p, const double *q, int sp, int sq,
                          const double *a, const double *b, const double *c)
{
    if (sp * sq > 0)
        return 0;
    if (sp == 0 && sq == 0) {
        /* In the plane: an endpoint inside, or a crossing with an edge. */
        int s;
        int k = tri_axis(a, b, c, &s);
        return point_in_tri_2d(p, a, b, c, k, s) ||
               point_in_tri_2d(q, a, b, c, k, s) ||
               seg_seg_2d(p, q, a, b, k) || seg_seg_2d(p, q, b, c, k) ||
               seg_seg_2d(p, q, c, a, k);
    }
    /* The segment meets the plane in exactly one point X (the line is not
     * parallel to it: one endpoint is off the plane, and the other is on it
     * or on the other side). X is in the closed triangle iff the line pq
     * does not pass strictly on opposite sides of two edges: the signs of
     * orient3d(p, q, edge) are all >= 0 or all <= 0 (they cannot all be 0,
     * or the line would lie in the plane). */
    int e1 = o3(p, q, a, b);
    int e2 = o3(p, q, b, c);
    if (e1 * e2 < 0)
        return 0;
    int e3 = o3(p, q, c, a);
    return e1 * e3 >= 0 && e2 * e3 >= 0;
}

/* 1 when the bounding boxes of point sets P (np points) and Q (nq) are
 * disjoint on some axis (exact comparisons: then the sets are disjoint). */
static int boxes_apart(const double *const *P, int np, const double *const *Q,
                       int nq)
{
    for (int k = 0; k < 3; k++) {
        double plo = P[0][k], phi = P[0][k], qlo = Q[0][k], qhi = Q[0][k];
        for (int i = 1; i < np; i++) {
            plo = fmin(plo, P[i][k]);
            phi = fmax(phi, P[i][k]);
        }
        for (int i = 1; i < nq; i++) {
            qlo = fmin(qlo, Q[i][k]);
            qhi = fmax(qhi, Q[i][k]);
        }
        if (phi < qlo || qhi < plo)
            return 1;
    }
    return 0;
}

/* ---- public tests ---------------------------------------------------------- */

int st_point_in_tri(const double p[3], const double a[3], const double b[3],
                    const double c[3])
{
    return point_in_tri(p, a, b, c);
}

int st_segment_tri_intersect(const double p[3], const double q[3],
                             const double a[3], const double b[3],
                             const double c[3])
{
    int sp = o3(a, b, c, p), sq = o3(a, b, c, q);
    if (sp * sq > 0)
        return 0;
    if (sp == 0 && sq == 0) {
        int s;
        if (tri_axis(a, b, c, &s) < 0)
            return seg_seg_3d(p, q, a, b) || seg_seg_3d(p, q, b, c) ||
                   seg_seg_3d(p, q, c, a);
    }
    /* Not both zero: the triangle is nondegenerate (a degenerate one gives
     * orient3d = 0 for every point). */
    return seg_tri_signed(p, q, sp, sq, a, b, c);
}

/* Closed triangles A and B of any shape. sa, when not NULL, holds the signs
 * of orient3d(B0, B1, B2, A_j) (the caller had them). */
static int tri_tri_core(const double *const A[3], const double *const B[3],
                        const int *sa_given)
{
    int sb[3], sa[3];
    for (int j = 0; j < 3; j++)
        sb[j] = o3(A[0], A[1], A[2], B[j]);
    if ((sb[0] > 0 && sb[1] > 0 && sb[2] > 0) ||
        (sb[0] < 0 && sb[1] < 0 && sb[2] < 0))
        return 0;
    for (int j = 0; j < 3; j++)
        sa[j] = sa_given ? sa_given[j] : o3(B[0], B[1], B[2], A[j]);
    if ((sa[0] > 0 && sa[1] > 0 && sa[2] > 0) ||
        (sa[0] < 0 && sa[1] < 0 && sa[2] < 0))
        return 0;
    int zb = sb[0] == 0 && sb[1] == 0 && sb[2] == 0;
    int za = sa[0] == 0 && sa[1] == 0 && sa[2] == 0;
    if (za || zb) {
        /* A degenerate triangle makes every sign against its plane 0, so
         * this is the case of a degenerate triangle or coplanar ones. */
        int s, ka = tri_axis(A[0], A[1], A[2], &s);
        if (ka < 0)
            return st_segment_tri_intersect(A[0], A[1], B[0], B[1], B[2]) ||
                   st_segment_tri_intersect(A[1], A[2], B[0], B[1], B[2]) ||
                   st_segment_tri_intersect(A[2], A[0], B[0], B[1], B[2]);
        int t, kb = tri_axis(B[0], B[1], B[2], &t);
        if (kb < 0)
            return st_segment_tri_intersect(B[0], B[1], A[0], A[1], A[2]) ||
                   st_segment_tri_intersect(B[1], B[2], A[0], A[1], A[2]) ||
                   st_segment_tri_intersect(B[2], B[0], A[0], A[1], A[2]);
        /* Coplanar, both proper: project along A's axis (one-to-one on the
         * common plane); B's projection is then proper too, with its own
         * orientation. Closed convex polygons meet iff two edges cross or
         * one contains a vertex of the other. */
        int tb = o2(B[0], B[1], B[2], ka);
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++)
                if (seg_seg_2d(A[i], A[(i + 1) % 3], B[j], B[(j + 1) % 3], ka))
                    return 1;
        return point_in_tri_2d(A[0], B[0], B[1], B[2], ka, tb) ||
               point_in_tri_2d(B[0], A[0], A[1], A[2], ka, s);
    }
    /* Both proper, not coplanar. If they meet, A n B lies on the line L
     * where the planes meet; A n L and B n L are segments with endpoints on
     * the edges of A and of B, and their overlap ends at one of those
     * endpoints: so some edge of one triangle meets the other triangle.
     * Only edges with endpoints not strictly on one side can. */
    for (int i = 0; i < 3; i++) {
        int j = (i + 1) % 3;
        if (sa[i] * sa[j] <= 0 &&
            seg_tri_signed(A[i], A[j], sa[i], sa[j], B[0], B[1], B[2]))
            return 1;
    }
    for (int i = 0; i < 3; i++) {
        int j = (i + 1) % 3;
        if (sb[i] * sb[j] <= 0 &&
            seg_tri_signed(B[i], B[j], sb[i], sb[j], A[0], A[1], A[2]))
            return 1;
    }
    return 0;
}

int st_tri_tri_intersect(const double a0[3], const double a1[3],
                         const double a2[3], const double b0[3],
                         const double b1[3], const double b2[3])
{
    const double *A[3] = {a0, a1, a2}, *B[3] = {b0, b1, b2};
    if (boxes_apart(A, 3, B, 3))
        return 0;
    return tri_tri_core(A, B, NULL);
}

/* 1 when signs s[0..3) hold both a +1 and a -1. */
static int straddles(const int *s)
{
    return (s[0] > 0 || s[1] > 0 || s[2] > 0) && (s[0] < 0 || s[1] < 0 || s[2] < 0);
}

int st_tri_tri_cross(const double a0[3], const double a1[3], const double a2[3],
                     const double b0[3], const double b1[3], const double b2[3])
{
    const double *A[3] = {a0, a1, a2}, *B[3] = {b0, b1, b2};
    if (boxes_apart(A, 3, B, 3))
        return 0;
    int sa[3], sb[3];
    for (int j = 0; j < 3; j++)
        sb[j] = o3(a0, a1, a2, B[j]);
    if (!straddles(sb))
        return 0;
    for (int j = 0; j < 3; j++)
        sa[j] = o3(b0, b1, b2, A[j]);
    if (!straddles(sa))
        return 0;
    /* both proper, not coplanar; a common vertex is on both planes, so
     * there is at most one (a second would leave the third alone on one
     * side) */
    int ia = -1, ib = -1;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            if (same_point(A[i], B[j]))
                ia = i, ib = j;
    if (ia < 0)
        return tri_tri_core(A, B, sa);
    /* A n B is a segment of the line where the planes meet, from the
     * common vertex; its far end lies on the edge of A or of B opposite
     * that vertex (an edge at the vertex is off the line, the other
     * vertices straddling) */
    return st_segment_tri_intersect(A[(ia + 1) % 3], A[(ia + 2) % 3], b0, b1, b2) ||
           st_segment_tri_intersect(B[(ib + 1) % 3], B[(ib + 2) % 3], a0, a1, a2);
}

/* The faces of tet t, ordered so that orient3d(F[i][0], F[i][1], F[i][2], v)
 * equals orient3d of the tet with corner i replaced by v. */
static void tet_faces(const double *const t[4], const double *F[4][3])
{
    F[0][0] = t[2]; F[0][1] = t[1]; F[0][2] = t[3];
    F[1][0] = t[0]; F[1][1] = t[2]; F[1][2] = t[3];
    F[2][0] = t[1]; F[2][1] = t[0]; F[2][2] = t[3];
    F[3][0] = t[0]; F[3][1] = t[1]; F[3][2] = t[2];
}

st_point_loc st_point_in_tet(const double p[3], const double t0[3],
                             const double t1[3], const double t2[3],
                             const double t3[3])
{
    const double *t[4] = {t0, t1, t2, t3};
    const double *F[4][3];
    tet_faces(t, F);
    int o = o3(t0, t1, t2, t3);
    if (o == 0) {
        for (int i = 0; i < 4; i++)
            if (point_in_tri(p, F[i][0], F[i][1], F[i][2]))
                return ST_ON_BOUNDARY;
        return ST_OUTSIDE;
    }
    /* The signs are those of p's barycentric coordinates times o. */
    int zero = 0;
    for (int i = 0; i < 4; i++) {
        int s = o3(F[i][0], F[i][1], F[i][2], p);
        if (s == -o)
            return ST_OUTSIDE;
        zero |= s == 0;
    }
    return zero ? ST_ON_BOUNDARY : ST_INSIDE;
}

int st_tri_tet_intersect(const double a[3], const double b[3],
                         const double c[3], const double t0[3],
                         const double t1[3], const double t2[3],
                         const double t3[3])
{
    const double *A[3] = {a, b, c};
    const double *t[4] = {t0, t1, t2, t3};
    if (boxes_apart(A, 3, t, 4))
        return 0;
    const double *F[4][3];
    tet_faces(t, F);
    int o = o3(t0, t1, t2, t3);
    if (o == 0) {
        /* A flat tet is the union of its faces. */
        for (int i = 0; i < 4; i++)
            if (tri_tri_core(A, F[i], NULL))
                return 1;
        return 0;
    }
    /* s[i][j]: sign of orient3d(face i, A_j); o * s > 0 is the inner side. */
    int s[4][3];
    for (int i = 0; i < 4; i++) {
        int out = 0;
        for (int j = 0; j < 3; j++) {
            s[i][j] = o3(F[i][0], F[i][1], F[i][2], A[j]);
            out += s[i][j] == -o;
        }
        if (out == 3)
            return 0; /* all three strictly beyond the plane of face i */
    }
    for (int j = 0; j < 3; j++)
        if (s[0][j] != -o && s[1][j] != -o && s[2][j] != -o && s[3][j] != -o)
            return 1; /* a vertex in the closed tet */
    /* No vertex inside. If A meets the tet it also has a point outside, so
     * (A is connected) it meets the tet's boundary, the union of the four
     * faces; it can only meet face i if not all its vertices are strictly
     * on the inner side of that face's plane. */
    for (int i = 0; i < 4; i++) {
        if (s[i][0] == o && s[i][1] == o && s[i][2] == o)
            continue;
        if (tri_tri_core(A, F[i], s[i]))
            return 1;
    }
    return 0;
}

/* Triangle against a full-dimensional box (lo < hi on every axis) by the
 * separating axis theorem, every axis test exact:
 *  - the box normals: coordinate comparisons;
 *  - the triangle normal n: the box corners extreme along n (chosen from the
 *    exact signs of n's components) against the triangle's plane;
 *  - the nine axes e_k x edge: in the projection dropping axis k, the box is
 *    a proper rectangle R, and two disjoint convex polygons one of which is
 *    proper are separated by the line through an edge of one of them with
 *    the other strictly on its outer side (the Minkowski difference is a
 *    proper polygon whose edges are parallel to theirs). For an edge of R
 *    that is a box-normal test; for an edge of the projected triangle it
 *    is the test below, on the corner of R extreme across that edge. A
 *    projected triangle that is a segment has both sides of its line to
 *    test.
 * The axes e_k x edge, n and the box normals cover every facet direction of
 * the Minkowski difference of a triangle (of any shape) and a full box, so
 * a disjoint pair is always caught. */
static int tri_box_sat(const double *const V[3], const double lo[3],
                       const double hi[3])
{
    int ns[3];
    for (int k = 0; k < 3; k++)
        ns[k] = o2(V[0], V[1], V[2], k);
    if (ns[0] != 0 || ns[1] != 0 || ns[2] != 0) {
        double pmax[3], pmin[3];
        for (int k = 0; k < 3; k++) {
            pmax[k] = ns[k] >= 0 ? hi[k] : lo[k];
            pmin[k] = ns[k] >= 0 ? lo[k] : hi[k];
        }
        /* n . (x - a) has the sign of -orient3d(a, b, c, x) */
        if (o3(V[0], V[1], V[2], pmax) > 0)
            return 0; /* the whole box strictly below the plane */
        if (o3(V[0], V[1], V[2], pmin) < 0)
            return 0; /* strictly above */
    }
    for (int k = 0; k < 3; k++) {
        int u = (k + 1) % 3, v = (k + 2) % 3;
        /* orient2d_drop(V_i, V_j, V_m, k) = ns[k] for each edge in cyclic
         * order, so ns[k] tells on which side of edge ij the triangle is. */
        for (int i = 0; i < 3; i++) {
            const double *P = V[i], *Q = V[(i + 1) % 3];
            int su = (Q[u] > P[u]) - (Q[u] < P[u]);
            int sv = (Q[v] > P[v]) - (Q[v] < P[v]);
            if (su == 0 && sv == 0)
                continue;
            /* f(x) = orient2d(P, Q, x) = du (x_v - P_v) - dv (x_u - P_u)
             * with d = Q - P (su, sv its exact signs): largest at x_v high
             * when du > 0 and x_u low when dv > 0. */
            double cmax[2], cmin[2], p2[2] = {P[u], P[v]}, q2[2] = {Q[u], Q[v]};
            cmax[0] = sv > 0 ? lo[u] : hi[u];
            cmax[1] = su > 0 ? hi[v] : lo[v];
            cmin[0] = sv > 0 ? hi[u] : lo[u];
            cmin[1] = su > 0 ? lo[v] : hi[v];
            if (ns[k] >= 0 && st_orient2d(p2, q2, cmax) < 0)
                return 0; /* the rectangle strictly on the outer side */
            if (ns[k] <= 0 && st_orient2d(p2, q2, cmin) > 0)
                return 0;
        }
    }
    return 1;
}

/* Separating-axis filter in floating point (Akenine-Moller's test about
 * the box's centre), conservative. M is the largest coordinate magnitude
 * of the triangle and the box, L the largest magnitude after moving the
 * box's centre to the origin (the triangle's offsets and the half
 * extents), plus 1e-15 M. Computed about the centre, every factor is
 * such an offset or a difference of two, at most 4L, and off by at most about 3 ulps of M
 * (two roundings from the input, one more for a difference). An edge
 * axis's projections and radius are sums of two or three products of two
 * factors: off by under 50 * 2^-53 * L (M + 2L) = 6e-15 L (M + 2L), the
 * factors' errors times the other factor plus the products' roundings.
 * The plane's offset and radius are degree 3 (the normal is degree 2):
 * off by under 400 * 2^-53 * L^2 (M + 2L) = 5e-14 L^2 (M + 2L). An axis
 * separates only when the gap exceeds TRI_BOX_SLACK L (M + L) (edges) or
 * TRI_BOX_SLACK L^2 (M + L) (the plane): over 50 times those bounds, so
 * the filter can keep a pair the exact test would part, and never parts
 * a pair that meets; far from the origin (M >> L) it still parts what is
 * a few millionths of L apart. Outside M in [1e-60, 1e60] (where the
 * bounds could leave the normal range), or with a non-finite coordinate,
 * it keeps everything. The filter below computes the same axes in
 * absolute coordinates, the triangle's part once (its own bounds there). */
#define TRI_BOX_SLACK 1e-11

/* max and min as comparisons: fmax and fmin are calls into libm here
 * (their NaN and signed-zero rules keep GCC from inlining them), a
 * thousand instructions a filter call. A NaN makes no axis separate. */
#define MAXD(x, y) ((x) > (y) ? (x) : (y))
#define MIND(x, y) ((x) < (y) ? (x) : (y))

/* The test, with the triangle's part computed once, in absolute
 * coordinates: an axis's projections of the vertices (au V_u + aw V_w)
 * once per triangle, the box centre's per box, their difference the
 * gap. Rounding: the axis (au, aw) and the normal are whatever was
 * computed; any axis separates what it separates, so only the products
 * and sums below err: a projection and the centre's are off by under
 * 4 * 2^-53 |a| M each and the difference by one more rounding, under
 * 10 * 2^-53 * 2 L * M for an edge axis (|a| <= 2 L, the edge between two
 * vertices within L of the centre per axis), under 50 * 2^-53 * 8 L^2 * M
 * for the plane (|n| <= 8 L^2); the triangle's vertices off the rounded
 * normal by under 10 * 2^-53 * 8 L^2 * 2 L. All far below TRI_BOX_SLACK
 * L (M + L) and TRI_BOX_SLACK L^2 (M + L). L is taken from the
 * triangle's box (its corners' offsets bound the vertices'), not smaller
 * than the L above, so the slack is at least as large. */
void st_tri_box_filter_init(st_tri_box_filter *f, const double a[3], const double b[3],
                            const double c[3])
{
    const double *V[3] = {a, b, c};
    double m = 0.0, e[3][3];
    for (int k = 0; k < 3; k++) {
        f->tlo[k] = MIND(a[k], MIND(b[k], c[k]));
        f->thi[k] = MAXD(a[k], MAXD(b[k], c[k]));
        for (int i = 0; i < 3; i++) {
            m = MAXD(m, fabs(V[i][k]));
            f->v[i][k] = V[i][k];
        }
        e[0][k] = b[k] - a[k];
        e[1][k] = c[k] - b[k];
        e[2][k] = a[k] - c[k];
    }
    f->m = m;
    /* NaN is not seen by MAXD: every coordinate is checked */
    f->ok = m <= 1e60;
    for (int k = 0; k < 3; k++)
        f->ok &= isfinite(a[k]) && isfinite(b[k]) && isfinite(c[k]);
    f->n[0] = e[0][1] * e[1][2] - e[0][2] * e[1][1];
    f->n[1] = e[0][2] * e[1][0] - e[0][0] * e[1][2];
    f->n[2] = e[0][0] * e[1][1] - e[0][1] * e[1][0];
    f->nd = f->n[0] * a[0] + f->n[1] * a[1] + f->n[2] * a[2];
    for (int k = 0; k < 3; k++)
        f->an[k] = fabs(f->n[k]);
    for (int k = 0; k < 3; k++) {
        const int u = (k + 1) % 3, w = (k + 2) % 3;
        for (int j = 0; j < 3; j++) {
            const int x = 3 * k + j;
            const double au = -e[j][w], aw = e[j][u];
            double p0 = au * a[u] + aw * a[w], p1 = au * b[u] + aw * b[w];
            double p2 = au * c[u] + aw * c[w];
            f->ax[x][0] = au;
            f->ax[x][1] = aw;
            f->aabs[x][0] = fabs(au);
            f->aabs[x][1] = fabs(aw);
            f->pmin[x] = MIND(p0, MIND(p1, p2));
            f->pmax[x] = MAXD(p0, MAXD(p1, p2));
        }
    }
}

/* 1 when the edge axis x (of axis k: its u, w components cu, cw of the
 * box's centre and eu, ew of its half extents) separates the box. */
static inline int axis_apart(const st_tri_box_filter *f, int x, double cu, double cw,
                             double eu, double ew, double tol2)
{
    double cp = f->ax[x][0] * cu + f->ax[x][1] * cw;
    double re = eu * f->aabs[x][0] + ew * f->aabs[x][1];
    return f->pmin[x] - cp > re + tol2 || f->pmax[x] - cp < -re - tol2;
}

int st_tri_box_filter_maybe(const st_tri_box_filter *f, const double lo[3],
                            const double hi[3])
{
    if (!(lo[0] <= hi[0] && lo[1] <= hi[1] && lo[2] <= hi[2]))
        return 0;   /* empty box (exact) */
    if (!f->ok)
        return 1;
    /* a vertex of the triangle in the box: they meet (comparisons: exact).
     * The axes below would keep the box too (conservative), for some 250
     * instructions; in the fit's face walks about two in five of the
     * boxes they keep hold a vertex (doc/design/fit.md, Cost). */
    for (int i = 0; i < 3; i++) {
        const double *q = f->v[i];
        if (q[0] >= lo[0] && q[0] <= hi[0] && q[1] >= lo[1] && q[1] <= hi[1] &&
            q[2] >= lo[2] && q[2] <= hi[2])
            return 1;
    }
    double ctr[3], e[3], M = f->m, L = 0.0;
    for (int k = 0; k < 3; k++) {
        M = MAXD(M, MAXD(fabs(lo[k]), fabs(hi[k])));
        ctr[k] = 0.5 * (lo[k] + hi[k]);
        e[k] = 0.5 * (hi[k] - lo[k]);
        L = MAXD(L, MAXD(e[k], MAXD(fabs(f->tlo[k] - ctr[k]), fabs(f->thi[k] - ctr[k]))));
    }
    if (!(M >= 1e-60 && M <= 1e60))
        return 1;   /* no bound here: keep it, the exact tests decide */
    L += 1e-15 * M;
    const double tol2 = TRI_BOX_SLACK * L * (M + L), tol3 = tol2 * L;
    double d = f->nd - (f->n[0] * ctr[0] + f->n[1] * ctr[1] + f->n[2] * ctr[2]);
    double r = e[0] * f->an[0] + e[1] * f->an[1] + e[2] * f->an[2];
    if (fabs(d) > r + tol3)
        return 0;
    /* axis k, edge j (x = 3 k + j) with u = k + 1, w = k + 2 (mod 3),
     * written out: the loop's u and w were computed at run time */
    return !(axis_apart(f, 0, ctr[1], ctr[2], e[1], e[2], tol2) ||
             axis_apart(f, 1, ctr[1], ctr[2], e[1], e[2], tol2) ||
             axis_apart(f, 2, ctr[1], ctr[2], e[1], e[2], tol2) ||
             axis_apart(f, 3, ctr[2], ctr[0], e[2], e[0], tol2) ||
             axis_apart(f, 4, ctr[2], ctr[0], e[2], e[0], tol2) ||
             axis_apart(f, 5, ctr[2], ctr[0], e[2], e[0], tol2) ||
             axis_apart(f, 6, ctr[0], ctr[1], e[0], e[1], tol2) ||
             axis_apart(f, 7, ctr[0], ctr[1], e[0], e[1], tol2) ||
             axis_apart(f, 8, ctr[0], ctr[1], e[0], e[1], tol2));
}

/* One box: the filter's two halves in one call. */
int st_tri_box_maybe(const double a[3], const double b[3], const double c[3],
                     const double lo[3], const double hi[3])
{
    st_tri_box_filter f;
    st_tri_box_filter_init(&f, a, b, c);
    return st_tri_box_filter_maybe(&f, lo, hi);
}

#undef MAXD
#undef MIND

int st_tri_box_intersect(const double a[3], const double b[3],
                         const double c[3], const double lo[3],
                         const double hi[3])
{
    const double *V[3] = {a, b, c};
    int flat = 0, flat_axis = -1;
    for (int k = 0; k < 3; k++) {
        if (!(lo[k] <= hi[k]))
            return 0; /* empty box */
        if (fmax(fmax(a[k], b[k]), c[k]) < lo[k] ||
            fmin(fmin(a[k], b[k]), c[k]) > hi[k])
            return 0;
        if (lo[k] == hi[k]) {
            flat++;
            flat_axis = k;
        }
    }
    if (flat == 0)
        return tri_box_sat(V, lo, hi);
    if (flat == 3)
        return point_in_tri(lo, a, b, c);
    if (flat == 2) {
        /* A segment along the one axis where lo < hi. */
        double q[3] = {lo[0], lo[1], lo[2]};
        for (int k = 0; k < 3; k++)
            if (lo[k] < hi[k])
                q[k] = hi[k];
        return st_segment_tri_intersect(lo, q, a, b, c);
    }
    /* A rectangle in the plane x_k = lo_k: two triangles. */
    int u = (flat_axis + 1) % 3, v = (flat_axis + 2) % 3;
    double r0[3], r1[3], r2[3], r3[3];
    r0[flat_axis] = r1[flat_axis] = r2[flat_axis] = r3[flat_axis] = lo[flat_axis];
    r0[u] = lo[u]; r0[v] = lo[v];
    r1[u] = hi[u]; r1[v] = lo[v];
    r2[u] = hi[u]; r2[v] = hi[v];
    r3[u] = lo[u]; r3[v] = hi[v];
    return st_tri_tri_intersect(a, b, c, r0, r1, r2) ||
           st_tri_tri_intersect(a, b, c, r0, r2, r3);
}
