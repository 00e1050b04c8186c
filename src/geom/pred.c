/*
 * pred.c - exact orientation predicates (see pred.h).
 *
 * Each predicate evaluates its determinant in plain double arithmetic and
 * compares the result with an error bound proven below (the filter). When
 * the filter cannot decide, the determinant is evaluated exactly with
 * floating-point expansions: a value is held as a sum of doubles of
 * increasing magnitude that do not overlap, and sums and products are
 * carried out with error-free transformations (Knuth's two-sum, Dekker's
 * two-product with Veltkamp's split), so the expansion equals the
 * determinant exactly and its largest component has its sign.
 *
 * Reference: J. R. Shewchuk, "Adaptive Precision Floating-Point Arithmetic
 * and Fast Robust Geometric Predicates", Discrete & Computational Geometry
 * 18:305-363, 1997 (sections 2.2-2.6 for the expansion arithmetic and its
 * theorems, section 4 for the filter idea). Written here from the paper;
 * the error bounds are derived here for this evaluation order.
 *
 * Rounding model. IEEE double, round to nearest even, no FMA contraction
 * (the build uses -ffp-contract=off). u = 2^-53. For a normal result
 * fl(x op y) = (x op y)(1 + d) with |d| <= u. A sum or difference whose
 * result is subnormal is exact. A product whose result is subnormal is off
 * by at most eta = 2^-1075 (half the smallest subnormal). Overflow gives
 * inf, and inf then shows in the filter's bound (see "Overflow" below).
 *
 * ---- The orient3d filter --------------------------------------------------
 *
 * Exact D = adx (bdy cdz - bdz cdy) + bdx (cdy adz - cdz ady)
 *         + cdx (ady bdz - adz bdy),      with adx = ax - dx etc.,
 * a sum of six signed monomials x y z of differences; its permanent is
 * P = sum |x y z| over those six.
 *
 * (1) The nine differences are rounded once: x^ = x (1 + e), |e| <= u
 *     (exact when subnormal). Let D~ and P~ be D and P of the rounded
 *     differences, computed exactly. Each monomial moves by a factor
 *     (1 + e1)(1 + e2)(1 + e3), so |D~ - D| <= ((1 + u)^3 - 1) P and
 *     P~ <= (1 + u)^3 P, P~ >= (1 - u)^3 P.
 * (2) From the rounded differences, the code computes each monomial
 *     through at most five roundings: the product of two differences, the
 *     subtraction in the 2x2 minor, the product with the third difference
 *     and at most two additions of the three terms. Without underflow,
 *     D^ = sum +-x^ y^ z^ (1 + t_k), |t_k| <= g5 = 5u / (1 - 5u) (Higham's
 *     gamma_5), so |D^ - D~| <= g5 P~.
 * (3) The permanent is computed with the same structure from |x^| and the
 *     absolute values of the same products: P^ = sum |x^ y^ z^| (1 + s_k)
 *     with |s_k| <= g5 and all terms >= 0, so P^ >= (1 - g5) P~ and then
 *     P <= P^ / ((1 - g5)(1 - u)^3) <= P^ / (1 - u)^8.
 * Together: |D^ - D| <= K P^ with
 *     K = ((1 + g5)(1 + u)^3 - 1) / (1 - u)^8 = 8u + 107u^2 + O(u^3)
 *       < 8u (1 + 2^-45).
 * The code compares with fl(9u P^): the two roundings of fl(fl(9u P^) + A)
 * lose at most a factor (1 - u)^2 and 9u (1 - u)^2 > K.
 * Underflow. A product rounded into the subnormal range adds an absolute
 * error <= eta; the first-level products are then multiplied by a
 * difference and pass at most four more roundings, the second-level ones
 * pass at most two. So underflow adds at most
 *     2 eta (1 + u)^4 S + 3 eta (1 + u)^2,   S = |adx| + |bdx| + |cdx|,
 * to |D^ - D|, and the same amount can be missing from P^ (which enlarges
 * K P^ by a negligible K times it). The code adds A = fl((S^ + 1) 2^-1040)
 * (S^ the computed S + 1, >= (S + 1)(1 - u)^3; the product is >= 2^-1040
 * so it rounds with relative error <= 2^-34), which exceeds those terms by a
 * factor of about 2^32. So when |D^| > fl(fl(9u P^) + A), D^ has the sign
 * of D.
 * Overflow. If a difference or product overflows, the same inf (or an inf
 * times 0 = NaN) enters P^; if a subtraction or sum overflows, the sum of
 * the absolute values that P^ computes in its place is not smaller (fl is
 * monotone) and overflows too. Then the bound is inf or NaN, the comparison
 * is false and the exact stage answers.
 *
 * ---- The orient2d filter --------------------------------------------------
 *
 * D = (ax - cx)(by - cy) - (ay - cy)(bx - cx): two monomials, two rounded
 * differences each, then two roundings (product, subtraction). As above:
 * |D^ - D| <= ((1 + g2)(1 + u)^2 - 1) / (1 - u)^4 P^ < 4u (1 + 2^-47) P^,
 * compared with fl(5u P^). Underflow adds at most 2 eta (1 + u) to the
 * error and removes as much from P^; the constant A = 2^-1060 covers it.
 *
 * ---- The exact stage --------------------------------------------------------
 *
 * Repeated points. Two equal input points make the determinant exactly 0
 * (two equal rows, or a zero row); this is the common undecided case (a
 * vertex shared by the triangles being compared) and is answered first.
 *
 * Scaling. Every coordinate of the call is multiplied by 2^s, chosen so the
 * largest magnitude lands in [2^299, 2^300). A power of two scales the
 * determinant by 2^(2s) or 2^(3s), a positive factor, so the sign is kept;
 * the magnitude is scaled back at the end. If the coordinates are integer
 * multiples of 2^Q below 2^(Q + 640) (pred.h, ST_PRED_SPREAD_BITS), the
 * scaled ones are multiples of 2^-340 (the scaling itself is then exact),
 * so every value the exact stage forms is an integer multiple of 2^-680
 * (degree 2) or 2^-1020 (degree 3): all are normal or zero, never
 * subnormal, and no error-free transformation loses a bit to underflow.
 * At the top, the differences are below 2^301, so the degree-3 terms and
 * every partial sum stay below 6 * 2^903 and the Veltkamp split (a product
 * by 2^27 + 1) below 2^940: nothing overflows. The same scaling serves
 * orient2d. Outside that spread (a coordinate more than 2^640 times finer
 * than the largest) the scaling or the error terms of products underflow,
 * and the sign is no longer guaranteed; pred.h documents the range.
 *
 * Expansion invariants (Shewchuk 1997, section 2, round-to-even): two-sum
 * and two-product give nonadjacent pairs; scale_expansion keeps a
 * nonadjacent expansion nonadjacent; expansion_sum (the merge by magnitude
 * then the two-sum chain of the paper's fast expansion sum, with two-sum
 * at every step, which gives the same pair as fast-two-sum wherever that
 * applies) keeps strongly nonoverlapping expansions strongly
 * nonoverlapping; nonadjacent implies strongly nonoverlapping. Zero components are
 * dropped, which keeps every property. In a nonoverlapping expansion the
 * components below the largest sum to less than one unit in its last
 * place, so the largest component has the sign of the value and is within
 * a relative 2^-52 of it.
 */
#include "souptet/pred.h"
#include "../base/fpenv.h"

#include <float.h>
#include <math.h>
#include <stdatomic.h>

static atomic_ullong exact_calls;

unsigned long long st_pred_exact_calls(void)
{
    return atomic_load_explicit(&exact_calls, memory_order_relaxed);
}

static void count_exact(void)
{
    atomic_fetch_add_explicit(&exact_calls, 1ULL, memory_order_relaxed);
}

/* ---- error-free transformations ---------------------------------------- */

/* x + y = a + b exactly, x = fl(a + b) (Knuth; no precondition). */
static inline void two_sum(double a, double b, double *x, double *y)
{
    double s = a + b;
    double bv = s - a;
    double av = s - bv;
    *x = s;
    *y = (a - av) + (b - bv);
}

/* a = hi + lo, each with at most 26 significant bits (Veltkamp). */
static inline void split(double a, double *hi, double *lo)
{
    const double splitter = 134217729.0; /* 2^27 + 1 */
    double c = splitter * a;
    double big = c - a;
    double h = c - big;
    *hi = h;
    *lo = a - h;
}

/* x + y = a * b exactly, x = fl(a * b) (Dekker). */
static inline void two_product(double a, double b, double *x, double *y)
{
    double p = a * b;
    double ah, al, bh, bl;
    split(a, &ah, &al);
    split(b, &bh, &bl);
    double e1 = p - ah * bh;
    double e2 = e1 - al * bh;
    double e3 = e2 - ah * bl;
    *x = p;
    *y = al * bl - e3;
}

/* ---- expansions: arrays of increasing magnitude, zeros dropped ---------- */

/* h = e + f; h may not alias e or f; returns the length (<= elen + flen). */
static int expansion_sum(int elen, const double *e, int flen, const double *f,
                         double *h)
{
    int i = 0, j = 0, k = 0;
    double q;
    if (elen == 0 && flen == 0)
        return 0;
    /* The merge by magnitude: take the smaller head. */
#define NEXT_SMALLER(out)                                                  \
    do {                                                                   \
        if (j >= flen || (i < elen && fabs(e[i]) < fabs(f[j])))            \
            (out) = e[i++];                                                \
        else                                                               \
            (out) = f[j++];                                                \
    } while (0)
    NEXT_SMALLER(q);
    while (i < elen || j < flen) {
        double g, err;
        NEXT_SMALLER(g);
        two_sum(q, g, &q, &err);
        if (err != 0.0)
            h[k++] = err;
    }
#undef NEXT_SMALLER
    if (q != 0.0 || k == 0)
        h[k++] = q;
    if (k == 1 && h[0] == 0.0)
        return 0;
    return k;
}

/* h = b * e; h may not alias e; returns the length (<= 2 elen). */
static int scale_expansion(int elen, const double *e, double b, double *h)
{
    int k = 0;
    double q, err;
    if (elen == 0 || b == 0.0)
        return 0;
    two_product(e[0], b, &q, &err);
    if (err != 0.0)
        h[k++] = err;
    for (int i = 1; i < elen; i++) {
        double p1, p0, s;
        two_product(e[i], b, &p1, &p0);
        two_sum(q, p0, &s, &err);
        if (err != 0.0)
            h[k++] = err;
        two_sum(p1, s, &q, &err);
        if (err != 0.0)
            h[k++] = err;
    }
    if (q != 0.0)
        h[k++] = q;
    return k;
}

/* h = e * f for a short f (at most 2 components); returns the length
 * (<= 4 elen). h may not alias e or f. */
static int mul_expansion2(int elen, const double *e, int flen,
                          const double *f, double *h)
{
    double t0[64], t1[64];
    if (flen == 0 || elen == 0)
        return 0;
    if (flen == 1)
        return scale_expansion(elen, e, f[0], h);
    int n0 = scale_expansion(elen, e, f[0], t0);
    int n1 = scale_expansion(elen, e, f[1], t1);
    return expansion_sum(n0, t0, n1, t1, h);
}

/* The exact difference a - b as an expansion of 0..2 components. */
static int diff_expansion(double a, double b, double *h)
{
    double x, y;
    int k = 0;
    two_sum(a, -b, &x, &y);
    if (y != 0.0)
        h[k++] = y;
    if (x != 0.0)
        h[k++] = x;
    return k;
}

/* e1 * f1 - e2 * f2 for expansions of at most 2 components each; h has
 * room for 16. */
static int minor2(int n1, const double *e1, int m1, const double *f1,
                  int n2, const double *e2, int m2, const double *f2,
                  double *h)
{
    double p[8], q[8];
    int np = mul_expansion2(n1, e1, m1, f1, p);
    int nq = mul_expansion2(n2, e2, m2, f2, q);
    for (int i = 0; i < nq; i++)
        q[i] = -q[i];
    return expansion_sum(np, p, nq, q, h);
}

/* Multiply v[0..n) by 2^s so that max|v| lands in [2^299, 2^300); 0 when
 * all are 0. s is in [300 - 1024, 300 + 1074]; the factor is applied as one
 * or two normal powers of two, each product exact unless it underflows
 * (only outside the documented spread), exactly what ldexp would give. */
static int scale_to_300(double *v, int n, int *s)
{
    double m = 0.0;
    for (int i = 0; i < n; i++)
        m = fmax(m, fabs(v[i]));
    if (m == 0.0)
        return 0;
    int e;
    (void)frexp(m, &e); /* m < 2^e */
    *s = 300 - e;
    int s1 = *s > 1000 ? *s / 2 : *s, s2 = *s - s1;
    double f1 = ldexp(1.0, s1), f2 = ldexp(1.0, s2);
    for (int i = 0; i < n; i++)
        v[i] = v[i] * f1 * f2;
    return 1;
}

static inline int same2(const double *a, const double *b)
{
    return a[0] == b[0] && a[1] == b[1];
}

static inline int same3(const double *a, const double *b)
{
    return a[0] == b[0] && a[1] == b[1] && a[2] == b[2];
}

/* The top component of an exact determinant of scaled coordinates, scaled
 * back by 2^-shift and clamped to the nonzero double range. */
static double unscale(int n, const double *h, int shift)
{
    if (n == 0)
        return 0.0;
    double top = h[n - 1];
    double r = ldexp(top, -shift);
    if (r == 0.0)
        r = copysign(DBL_TRUE_MIN, top);
    else if (isinf(r))
        r = copysign(DBL_MAX, top);
    return r;
}

/* ---- orient2d ---------------------------------------------------------- */

static double orient2d_exact(const double a[2], const double b[2],
                             const double c[2])
{
    double v[6] = {a[0], a[1], b[0], b[1], c[0], c[1]};
    int s;
    if (!scale_to_300(v, 6, &s))
        return 0.0;
    double acx[2], acy[2], bcx[2], bcy[2];
    int nacx = diff_expansion(v[0], v[4], acx);
    int nacy = diff_expansion(v[1], v[5], acy);
    int nbcx = diff_expansion(v[2], v[4], bcx);
    int nbcy = diff_expansion(v[3], v[5], bcy);
    double h[16];
    int n = minor2(nacx, acx, nbcy, bcy, nacy, acy, nbcx, bcx, h);
    return unscale(n, h, 2 * s);
}

/* The filter's constants (derivation in the file comment). */
#define U 0x1p-53
#define ERR2_REL (5.0 * U)
#define ERR2_ABS 0x1p-1060
#define ERR3_REL (9.0 * U)
#define ERR3_ABS_SCALE 0x1p-1040

double st_orient2d(const double a[2], const double b[2], const double c[2])
{
    double acx = a[0] - c[0], bcx = b[0] - c[0];
    double acy = a[1] - c[1], bcy = b[1] - c[1];
    double l = acx * bcy;
    double r = acy * bcx;
    double det = l - r;
    double perm = fabs(l) + fabs(r);
    double bound = ERR2_REL * perm + ERR2_ABS;
    if (det > bound || -det > bound)
        return det;
    count_exact();
    /* A repeated point (a shared vertex, the common case) makes it 0. */
    if (same2(a, b) || same2(b, c) || same2(a, c))
        return 0.0;
    return orient2d_exact(a, b, c);
}

double st_orient2d_drop(const double a[3], const double b[3],
                        const double c[3], int drop)
{
    int i = (drop + 1) % 3, j = (drop + 2) % 3;
    double a2[2] = {a[i], a[j]}, b2[2] = {b[i], b[j]}, c2[2] = {c[i], c[j]};
    return st_orient2d(a2, b2, c2);
}

/* ---- orient3d ---------------------------------------------------------- */

static double orient3d_exact(const double a[3], const double b[3],
                             const double c[3], const double d[3])
{
    double v[12];
    for (int i = 0; i < 3; i++) {
        v[i] = a[i];
        v[3 + i] = b[i];
        v[6 + i] = c[i];
        v[9 + i] = d[i];
    }
    int s;
    if (!scale_to_300(v, 12, &s))
        return 0.0;
    /* x[p][k]: component k of point p minus d, as an expansion. */
    double x[3][3][2];
    int nx[3][3];
    for (int p = 0; p < 3; p++)
        for (int k = 0; k < 3; k++)
            nx[p][k] = diff_expansion(v[3 * p + k], v[9 + k], x[p][k]);
    /* D = sum over p of x[p][0] * (x[q][1] x[r][2] - x[q][2] x[r][1]) with
     * (p, q, r) the cyclic rotations of (a, b, c). */
    double term[3][64];
    int nterm[3];
    for (int p = 0; p < 3; p++) {
        int q = (p + 1) % 3, r = (p + 2) % 3;
        double m[16];
        int nm = minor2(nx[q][1], x[q][1], nx[r][2], x[r][2],
                        nx[q][2], x[q][2], nx[r][1], x[r][1], m);
        nterm[p] = mul_expansion2(nm, m, nx[p][0], x[p][0], term[p]);
    }
    double t01[128], h[192];
    int n01 = expansion_sum(nterm[0], term[0], nterm[1], term[1], t01);
    int n = expansion_sum(n01, t01, nterm[2], term[2], h);
    return unscale(n, h, 3 * s);
}

double st_orient3d(const double a[3], const double b[3], const double c[3],
                   const double d[3])
{
    double adx = a[0] - d[0], bdx = b[0] - d[0], cdx = c[0] - d[0];
    double ady = a[1] - d[1], bdy = b[1] - d[1], cdy = c[1] - d[1];
    double adz = a[2] - d[2], bdz = b[2] - d[2], cdz = c[2] - d[2];

    double bdycdz = bdy * cdz, bdzcdy = bdz * cdy;
    double cdyadz = cdy * adz, cdzady = cdz * ady;
    double adybdz = ady * bdz, adzbdy = adz * bdy;

    double det = adx * (bdycdz - bdzcdy) + bdx * (cdyadz - cdzady)
               + cdx * (adybdz - adzbdy);
    double aadx = fabs(adx), abdx = fabs(bdx), acdx = fabs(cdx);
    double perm = aadx * (fabs(bdycdz) + fabs(bdzcdy))
                + abdx * (fabs(cdyadz) + fabs(cdzady))
                + acdx * (fabs(adybdz) + fabs(adzbdy));
    double abs_term = (aadx + abdx + acdx + 1.0) * ERR3_ABS_SCALE;
    double bound = ERR3_REL * perm + abs_term;
    if (det > bound || -det > bound)
        return det;
    count_exact();
    /* A repeated point (a shared vertex, the common case) makes it 0. */
    if (same3(a, b) || same3(a, c) || same3(a, d) || same3(b, c) ||
        same3(b, d) || same3(c, d))
        return 0.0;
    return orient3d_exact(a, b, c, d);
}

void st_plane_filter_plane(st_plane_filter *pl, const double o[3], const double a[3],
                           const double b[3])
{
    double e1[3], e2[3];
    for (int k = 0; k < 3; k++) {
        e1[k] = a[k] - o[k];
        e2[k] = b[k] - o[k];
    }
    double m[6] = {e1[1] * e2[2], e1[2] * e2[1], e1[2] * e2[0],
                   e1[0] * e2[2], e1[0] * e2[1], e1[1] * e2[0]};
    for (int k = 0; k < 3; k++) {
        pl->n[k] = m[2 * k] - m[2 * k + 1];
        pl->an[k] = fabs(m[2 * k]) + fabs(m[2 * k + 1]);
    }
    pl->o = o;
    pl->side = 0;
}

void st_plane_filter_init(st_plane_filter *pl, const double o[3], const double a[3],
                          const double b[3], const double r[3])
{
    st_plane_filter_plane(pl, o, a, b);
    /* orient3d(o, a, b, r) = -det [a - o; b - o; r - o] */
    double s = st_orient3d(o, a, b, r);
    pl->side = s < 0 ? 1 : (s > 0 ? -1 : 0);
}
