/*
 * tetqual_pairs.h - the six dihedral angles of a tet as pairs (private,
 * header only; tetqual.c's range, smooth_mesh.c's scores).
 *
 * Edge i of tetqual.c's order ((0 1) (0 2) (0 3) (1 2) (1 3) (2 3)) has
 * the angle atan2(y_i, x_i) with y_i = |u x v| (st_norm3) and x_i = u . v
 * of tetqual.c's u and v, bit for bit: where no pair is degenerate,
 * atan2(y_i, x_i) * (180 / pi) is tetqual.c's angle itself. atan2(y, x)
 * with y > 0 falls as the ratio x / y grows, which lets a caller find the
 * extreme angles among a few pairs and skip the atan2 of the others.
 */
#ifndef SOUPTET_TETQUAL_PAIRS_H
#define SOUPTET_TETQUAL_PAIRS_H

#include "souptet/geom.h"

#include <math.h>
#ifdef __SSE2__
#include <emmintrin.h>
#endif

/* fmax for the non-negative operands of tq_norm3 (fabs values, maybe NaN
 * or infinite): returns what fmax returns, without the libm call. */
static inline double tq_fmax(double a, double b)
{
    return (a > b || b != b) ? a : b;
}

/* st_norm3 (geom.c) inline, operation for operation, so the value is the
 * same bit for bit. */
static inline double tq_norm3(const double v[3])
{
    double m = tq_fmax(fabs(v[0]), tq_fmax(fabs(v[1]), fabs(v[2])));
    if (!(m > 0.0) || !isfinite(m))
        return m;
    double x = v[0] / m, y = v[1] / m, z = v[2] / m;
    return m * sqrt(x * x + y * y + z * z);
}

/* The pair (|u x v|, s u . v) of one edge; 0 for a degenerate case. */
static inline int tq_edge_pair(const double u[3], const double v[3], double s, double *y,
                                double *x)
{
    double w[3];
    st_cross3(w, u, v);
    *y = tq_norm3(w);
    *x = s * st_dot3(u, v);
    return *y > 0.0 && isfinite(*y) && isfinite(*x);
}

#ifdef __SSE2__
/* Two 3-vectors side by side, one per lane (lane 0 the first). */
typedef struct {
    __m128d x, y, z;
} tq_v2;

static inline tq_v2 tq_v2_cross(tq_v2 u, tq_v2 v)
{
    /* st_cross3 per lane: the same products and differences, unfused */
    tq_v2 w;
    w.x = _mm_sub_pd(_mm_mul_pd(u.y, v.z), _mm_mul_pd(u.z, v.y));
    w.y = _mm_sub_pd(_mm_mul_pd(u.z, v.x), _mm_mul_pd(u.x, v.z));
    w.z = _mm_sub_pd(_mm_mul_pd(u.x, v.y), _mm_mul_pd(u.y, v.x));
    return w;
}

/* tq_edge_pair for two edges at once, (|u x v|, s u . v) per lane into y and
 * x; the returned mask has both bits set where both lanes pass tq_edge_pair's
 * test. The norm is tq_norm3's, operation for operation, with max for
 * tq_fmax: they differ only where a component of w is NaN, and then
 * either m is NaN (no lane test passes) or a quotient by m is NaN and so
 * is the norm (fails y > 0), as tq_edge_pair fails there. Where m is 0 or
 * infinite, tq_norm3 returns m and tq_edge_pair fails; here 0 / 0 or
 * inf / inf makes the norm NaN and the test fails too. */
static inline int tq_v2_edge_pairs(tq_v2 u, tq_v2 v, __m128d s, double *y, double *x)
{
    const __m128d sign = _mm_set1_pd(-0.0), inf = _mm_set1_pd(INFINITY);
    tq_v2 w = tq_v2_cross(u, v);
    __m128d m = _mm_max_pd(_mm_andnot_pd(sign, w.x),
                           _mm_max_pd(_mm_andnot_pd(sign, w.y), _mm_andnot_pd(sign, w.z)));
    __m128d qx = _mm_div_pd(w.x, m), qy = _mm_div_pd(w.y, m), qz = _mm_div_pd(w.z, m);
    __m128d q = _mm_add_pd(_mm_add_pd(_mm_mul_pd(qx, qx), _mm_mul_pd(qy, qy)),
                           _mm_mul_pd(qz, qz));
    __m128d ny = _mm_mul_pd(m, _mm_sqrt_pd(q));
    __m128d dot = _mm_add_pd(_mm_add_pd(_mm_mul_pd(u.x, v.x), _mm_mul_pd(u.y, v.y)),
                             _mm_mul_pd(u.z, v.z));
    __m128d nx = _mm_mul_pd(s, dot);
    _mm_storeu_pd(y, ny);
    _mm_storeu_pd(x, nx);
    /* y > 0, y finite, x finite (NaN fails every comparison) */
    __m128d ok = _mm_and_pd(_mm_and_pd(_mm_cmpgt_pd(ny, _mm_setzero_pd()), _mm_cmplt_pd(ny, inf)),
                            _mm_cmplt_pd(_mm_andnot_pd(sign, nx), inf));
    return _mm_movemask_pd(ok);
}

/* The cross products l x r of component vectors (lane 0, lane 1) of the
 * corner differences: l = (pl0 - ql0, pl1 - ql1), r likewise. */
#define TQ_V2_DIFF(p0, p1, q0, q1, k) \
    _mm_sub_pd(_mm_set_pd((p1)[k], (p0)[k]), _mm_set_pd((q1)[k], (q0)[k]))
#define TQ_V2_CROSS_OF(lp0, lp1, lq0, lq1, rp0, rp1, rq0, rq1)                       \
    tq_v2_cross((tq_v2){TQ_V2_DIFF(lp0, lp1, lq0, lq1, 0),                            \
                        TQ_V2_DIFF(lp0, lp1, lq0, lq1, 1),                            \
                        TQ_V2_DIFF(lp0, lp1, lq0, lq1, 2)},                           \
                (tq_v2){TQ_V2_DIFF(rp0, rp1, rq0, rq1, 0),                            \
                        TQ_V2_DIFF(rp0, rp1, rq0, rq1, 1),                            \
                        TQ_V2_DIFF(rp0, rp1, rq0, rq1, 2)})

/* The six pairs two edges per SSE2 operation: every lane does the scalar
 * code's operations (tq_tet_pairs without SSE2) on its operands in its
 * order (no fused multiply-add: -ffp-contract=off), so the pairs are the
 * same bit for bit. Returns 0 where the scalar code does. */
static inline int tq_tet_pairs_sse2(const double *a, const double *b, const double *c,
                                    const double *d, double y[6], double x[6])
{
    /* (A, B) = d1 x (d2, d3), (C, D) = (d2, c2) x (d3, c0),
     * (E, F) = (c2, c3) x (c3, c0), (G, H) = b3 x (b0, b1) */
    const tq_v2 P1 = TQ_V2_CROSS_OF(b, b, a, a, c, d, a, a);
    const tq_v2 P2 = TQ_V2_CROSS_OF(c, c, a, b, d, a, a, b);
    const tq_v2 P3 = TQ_V2_CROSS_OF(c, d, b, b, d, a, b, b);
    const tq_v2 P4 = TQ_V2_CROSS_OF(d, d, c, c, a, b, c, c);
    /* edges 0, 1: u (A, A), v (B, C); 2, 3: (B, D), (C, E); 4, 5: (F, G), (E, H) */
    tq_v2 U1 = {_mm_unpacklo_pd(P1.x, P1.x), _mm_unpacklo_pd(P1.y, P1.y),
                _mm_unpacklo_pd(P1.z, P1.z)};
    tq_v2 V1 = {_mm_shuffle_pd(P1.x, P2.x, 1), _mm_shuffle_pd(P1.y, P2.y, 1),
                _mm_shuffle_pd(P1.z, P2.z, 1)};
    tq_v2 U2 = {_mm_unpackhi_pd(P1.x, P2.x), _mm_unpackhi_pd(P1.y, P2.y),
                _mm_unpackhi_pd(P1.z, P2.z)};
    tq_v2 V2 = {_mm_unpacklo_pd(P2.x, P3.x), _mm_unpacklo_pd(P2.y, P3.y),
                _mm_unpacklo_pd(P2.z, P3.z)};
    tq_v2 U3 = {_mm_shuffle_pd(P3.x, P4.x, 1), _mm_shuffle_pd(P3.y, P4.y, 1),
                _mm_shuffle_pd(P3.z, P4.z, 1)};
    tq_v2 V3 = {_mm_shuffle_pd(P3.x, P4.x, 2), _mm_shuffle_pd(P3.y, P4.y, 2),
                _mm_shuffle_pd(P3.z, P4.z, 2)};
    int ok = tq_v2_edge_pairs(U1, V1, _mm_set_pd(-1.0, 1.0), y + 0, x + 0);
    ok &= tq_v2_edge_pairs(U2, V2, _mm_set1_pd(1.0), y + 2, x + 2);
    ok &= tq_v2_edge_pairs(U3, V3, _mm_set_pd(1.0, -1.0), y + 4, x + 4);
    return ok == 3;
}
#undef TQ_V2_CROSS_OF
#undef TQ_V2_DIFF
#endif

/* The six pairs (y[i], x[i]) of the tet (a, b, c, d) in tetqual.c's edge
 * order. Returns 0 for a degenerate case: a pair with y not > 0 (a face
 * without area, parallel normals) or a value not finite; y and x are then
 * unspecified and tetqual.c's angles must be taken one by one. */
static inline int tq_tet_pairs(const double *a, const double *b, const double *c,
                               const double *d, double y[6], double x[6])
{
#ifdef __SSE2__
    return tq_tet_pairs_sse2(a, b, c, d, y, x);
#else
    /* edge i = (pi, pj), others pk, pl, takes u = e x f,
     * v = e x g with e = pj - pi, f = pk - pi, g = pl - pi. The edges from
     * one corner share their differences, and a x b = -(b x a) exactly in
     * floating point (a1 b2 - a2 b1 = -(a2 b1 - a1 b2)); negating u or v
     * negates w = u x v and u . v exactly too, so the 18 cross products
     * come down to 14 with the same |w| and, up to sign, u . v. */
    double d1[3], d2[3], d3[3], c0[3], c2[3], c3[3], b0[3], b1[3], b3[3];
    st_sub3(d1, b, a);
    st_sub3(d2, c, a);
    st_sub3(d3, d, a);
    st_sub3(c0, a, b);
    st_sub3(c2, c, b);
    st_sub3(c3, d, b);
    st_sub3(b0, a, c);
    st_sub3(b1, b, c);
    st_sub3(b3, d, c);
    double A[3], B[3], C[3], D[3], E[3], F[3], G[3], H[3];
    st_cross3(A, d1, d2);   /* edge 0: u = A, v = B */
    st_cross3(B, d1, d3);   /* edge 1: u = -A, v = C */
    st_cross3(C, d2, d3);   /* edge 2: u = -B, v = -C */
    st_cross3(D, c2, c0);   /* edge 3: u = D, v = E */
    st_cross3(E, c2, c3);   /* edge 4: u = F, v = -E */
    st_cross3(F, c3, c0);
    st_cross3(G, b3, b0);   /* edge 5: u = G, v = H */
    st_cross3(H, b3, b1);
    /* the sign of u . v: edge 1 has one factor negated, edge 4 one, edge 2
     * two */
    if (!tq_edge_pair(A, B, 1.0, y + 0, x + 0) || !tq_edge_pair(A, C, -1.0, y + 1, x + 1) ||
        !tq_edge_pair(B, C, 1.0, y + 2, x + 2) || !tq_edge_pair(D, E, 1.0, y + 3, x + 3) ||
        !tq_edge_pair(F, E, -1.0, y + 4, x + 4) || !tq_edge_pair(G, H, 1.0, y + 5, x + 5))
        return 0;
    return 1;
#endif
}

#endif
