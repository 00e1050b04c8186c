/* test_pred.c - exact orientation predicates: signs against exact integer
 * arithmetic, near-degenerate inputs at extreme scales, symmetries, the
 * exact-stage counter, and the speed of the filter. */
#include "souptet/pred.h"
#include "tap.h"

#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <time.h>

#define SPLITMIX_SEED 0x9e3779b97f4a7c15ULL
#include "splitmix.h"

static int sign128(__int128 x)
{
    return (x > 0) - (x < 0);
}

static int ref_orient2d(const int64_t a[2], const int64_t b[2],
                        const int64_t c[2])
{
    __int128 acx = a[0] - c[0], acy = a[1] - c[1];
    __int128 bcx = b[0] - c[0], bcy = b[1] - c[1];
    return sign128(acx * bcy - acy * bcx);
}

static __int128 ref_det3(const int64_t a[3], const int64_t b[3],
                         const int64_t c[3], const int64_t d[3])
{
    __int128 adx = a[0] - d[0], ady = a[1] - d[1], adz = a[2] - d[2];
    __int128 bdx = b[0] - d[0], bdy = b[1] - d[1], bdz = b[2] - d[2];
    __int128 cdx = c[0] - d[0], cdy = c[1] - d[1], cdz = c[2] - d[2];
    return adx * (bdy * cdz - bdz * cdy) + bdx * (cdy * adz - cdz * ady) +
           cdx * (ady * bdz - adz * bdy);
}

/* Random integer points in [-r, r]^k, as doubles scaled by 2^shift (exact),
 * against __int128 determinants. Small r makes most calls degenerate or
 * nearly so; r = 2^40 keeps the 3-D determinant inside 127 bits. */
static void test_random_integers(void)
{
    const int64_t ranges[] = {1, 3, 20, 1000, 1LL << 26, 1LL << 40};
    const int shifts[] = {0, -30, 500, -1000};
    for (size_t ri = 0; ri < sizeof ranges / sizeof ranges[0]; ri++) {
        for (size_t si = 0; si < sizeof shifts / sizeof shifts[0]; si++) {
            int64_t r = ranges[ri];
            int sh = shifts[si];
            int bad2 = 0, bad3 = 0, bad_drop = 0, bad_mag = 0, zeros = 0;
            const int n = 20000;
            for (int it = 0; it < n; it++) {
                int64_t p[4][3];
                double q[4][3];
                for (int i = 0; i < 4; i++)
                    for (int k = 0; k < 3; k++) {
                        p[i][k] = rng_int(r);
                        q[i][k] = ldexp((double)p[i][k], sh);
                    }
                int e2 = ref_orient2d(p[0], p[1], p[2]);
                if (st_sign(st_orient2d(q[0], q[1], q[2])) != e2)
                    bad2++;
                __int128 d3 = ref_det3(p[0], p[1], p[2], p[3]);
                double o3 = st_orient3d(q[0], q[1], q[2], q[3]);
                if (st_sign(o3) != sign128(d3))
                    bad3++;
                zeros += d3 == 0;
                /* Magnitude within a factor 2 (scaled back by 2^(3 sh)),
                 * where it is representable. */
                if (d3 != 0 && sh == 0) {
                    double ratio = o3 / (double)d3;
                    if (!(ratio > 0.5 && ratio < 2.0))
                        bad_mag++;
                }
                /* drop 2 is the (x, y) projection. */
                if (st_sign(st_orient2d_drop(q[0], q[1], q[2], 2)) != e2)
                    bad_drop++;
            }
            TAP_CHECK(bad2 == 0, "orient2d sign = exact integer sign, r=%lld, "
                      "scale 2^%d (%d wrong)", (long long)r, sh, bad2);
            TAP_CHECK(bad3 == 0, "orient3d sign = exact integer sign, r=%lld, "
                      "scale 2^%d (%d wrong, %d of %d exactly coplanar)",
                      (long long)r, sh, bad3, zeros, n);
            TAP_CHECK(bad_drop == 0, "orient2d_drop(2) = orient2d of (x, y), "
                      "r=%lld, scale 2^%d", (long long)r, sh);
            if (sh == 0)
                TAP_CHECK(bad_mag == 0, "orient3d magnitude within a factor 2 "
                          "of the exact value, r=%lld (%d off)",
                          (long long)r, bad_mag);
        }
    }
}

/* ---- 53-bit integers: the exact stage with inexact differences ---------- */

/* A 256-bit two's complement integer, enough for orient3d of integers
 * below 2^53 in magnitude (differences < 2^54, terms < 2^163). */
typedef struct i256 { uint64_t w[4]; } i256;

static i256 i256_mul(__int128 m, int64_t d)
{
    int neg = (m < 0) != (d < 0);
    unsigned __int128 um = m < 0 ? -(unsigned __int128)m : (unsigned __int128)m;
    uint64_t ud = d < 0 ? -(uint64_t)d : (uint64_t)d;
    unsigned __int128 p0 = (unsigned __int128)(uint64_t)um * ud;
    unsigned __int128 p1 = (unsigned __int128)(uint64_t)(um >> 64) * ud;
    unsigned __int128 t = (p0 >> 64) + (uint64_t)p1;
    i256 r = {{(uint64_t)p0, (uint64_t)t, (uint64_t)((t >> 64) + (p1 >> 64)), 0}};
    if (neg) {
        unsigned __int128 c = 1;
        for (int i = 0; i < 4; i++) {
            c += (uint64_t)~r.w[i];
            r.w[i] = (uint64_t)c;
            c >>= 64;
        }
    }
    return r;
}

static i256 i256_add(i256 a, i256 b)
{
    unsigned __int128 c = 0;
    for (int i = 0; i < 4; i++) {
        c += (unsigned __int128)a.w[i] + b.w[i];
        a.w[i] = (uint64_t)c;
        c >>= 64;
    }
    return a;
}

static int i256_sign(i256 a)
{
    if (a.w[3] >> 63)
        return -1;
    return (a.w[0] | a.w[1] | a.w[2] | a.w[3]) != 0;
}

static int ref_orient3d_53(const int64_t a[3], const int64_t b[3], const int64_t c[3],
                           const int64_t d[3])
{
    int64_t x[3][3];
    for (int k = 0; k < 3; k++) {
        x[0][k] = a[k] - d[k];
        x[1][k] = b[k] - d[k];
        x[2][k] = c[k] - d[k];
    }
    i256 sum = {{0, 0, 0, 0}};
    for (int p = 0; p < 3; p++) {
        int q = (p + 1) % 3, r = (p + 2) % 3;
        __int128 m = (__int128)x[q][1] * x[r][2] - (__int128)x[q][2] * x[r][1];
        sum = i256_add(sum, i256_mul(m, x[p][0]));
    }
    return i256_sign(sum);
}

/* Integers up to 2^53 (every one a double) whose differences are often not
 * doubles, nearly coplanar (d near the centroid of a, b, c, moved by -1, 0
 * or +1), so the exact stage works with two-component differences. */
static void test_53bit_nearly_coplanar(void)
{
    const int64_t R = (int64_t)1 << 53;
    int bad3 = 0, bad2 = 0, exact = 0, nz = 0;
    unsigned long long e0 = st_pred_exact_calls();
    for (int it = 0; it < 20000; it++) {
        int64_t p[4][3];
        double q[4][3];
        for (int i = 0; i < 3; i++)
            for (int k = 0; k < 3; k++)
                p[i][k] = rng_int(R);
        for (int k = 0; k < 3; k++) {
            __int128 sum = (__int128)p[0][k] + p[1][k] + p[2][k];
            p[3][k] = (int64_t)(sum / 3) + rng_int(1);
        }
        for (int i = 0; i < 4; i++)
            for (int k = 0; k < 3; k++)
                q[i][k] = (double)p[i][k];
        int ref = ref_orient3d_53(p[0], p[1], p[2], p[3]);
        nz += ref != 0;
        if (st_sign(st_orient3d(q[0], q[1], q[2], q[3])) != ref)
            bad3++;
        /* 2-D: the (x, y) of a, b and the point near their midpoint. */
        int64_t m2[2] = {(int64_t)(((__int128)p[0][0] + p[1][0]) / 2) + rng_int(1),
                         (int64_t)(((__int128)p[0][1] + p[1][1]) / 2) + rng_int(1)};
        double mq[2] = {(double)m2[0], (double)m2[1]};
        __int128 acx = (__int128)p[0][0] - m2[0], acy = (__int128)p[0][1] - m2[1];
        __int128 bcx = (__int128)p[1][0] - m2[0], bcy = (__int128)p[1][1] - m2[1];
        /* |products| < 2^108: the difference fits in __int128 */
        __int128 det = acx * bcy - acy * bcx;
        if (st_sign(st_orient2d(q[0], q[1], mq)) != sign128(det))
            bad2++;
    }
    exact = (int)(st_pred_exact_calls() - e0);
    /* The 256-bit reference against __int128 where both apply, and the
     * spread of signs it gives here. */
    int ref_bad = 0, pos = 0, neg = 0;
    for (int it = 0; it < 20000; it++) {
        int64_t p[4][3];
        for (int i = 0; i < 4; i++)
            for (int k = 0; k < 3; k++)
                p[i][k] = rng_int(1LL << 38);
        int r = ref_orient3d_53(p[0], p[1], p[2], p[3]);
        ref_bad += r != sign128(ref_det3(p[0], p[1], p[2], p[3]));
        pos += r > 0;
        neg += r < 0;
    }
    TAP_CHECK(ref_bad == 0 && pos > 5000 && neg > 5000,
              "the 256-bit reference agrees with __int128 (%d +, %d -)", pos, neg);
    TAP_CHECK(bad3 == 0, "orient3d exact on nearly coplanar 53-bit integers (%d wrong, "
              "%d exact-stage calls, %d nonzero)", bad3, exact, nz);
    TAP_CHECK(bad2 == 0, "orient2d exact on nearly collinear 53-bit integers (%d wrong)", bad2);
    TAP_CHECK(exact > 20000, "those calls went to the exact stage");
}

/* orient2d_drop: its sign is that of component `drop` of (b-a)x(c-a). */
static void test_drop_axes(void)
{
    const double a[3] = {0, 0, 0}, b[3] = {1, 0, 0}, c[3] = {0, 1, 0};
    /* (b-a)x(c-a) = (0, 0, 1) */
    TAP_CHECK(st_orient2d_drop(a, b, c, 2) > 0 &&
              st_orient2d_drop(a, b, c, 0) == 0 &&
              st_orient2d_drop(a, b, c, 1) == 0,
              "drop: triangle in the xy plane has normal +z only");
    const double d[3] = {0, 0, 1};
    /* (b-a)x(d-a) = (1,0,0)x(0,0,1) = (0, -1, 0) */
    TAP_CHECK(st_orient2d_drop(a, b, d, 1) < 0 &&
              st_orient2d_drop(a, b, d, 0) == 0 &&
              st_orient2d_drop(a, b, d, 2) == 0,
              "drop: (z, x) projection gives the y component (-1)");
    /* (c-a)x(d-a) = (0,1,0)x(0,0,1) = (1, 0, 0) */
    TAP_CHECK(st_orient2d_drop(a, c, d, 0) > 0,
              "drop: (y, z) projection gives the x component (+1)");
}

/* Points exactly on the line y = x (any doubles), the third moved one ulp
 * off it: the sign is known (above the line = counterclockwise when a
 * precedes b along the line). Scaled by 2^sh to reach tiny and huge
 * coordinates. */
static void test_collinear_perturbed(int sh, const char *what)
{
    int bad = 0, bad_on = 0;
    for (int it = 0; it < 5000; it++) {
        double t[3];
        for (int i = 0; i < 3; i++)
            t[i] = ldexp(rng_unif(-1.0, 1.0), sh);
        if (t[0] == t[1])
            continue;
        double lo = fmin(t[0], t[1]), hi = fmax(t[0], t[1]);
        double a[2] = {lo, lo}, b[2] = {hi, hi}, c[2] = {t[2], t[2]};
        if (st_orient2d(a, b, c) != 0.0 || st_orient2d(c, a, b) != 0.0)
            bad_on++;
        double up[2] = {t[2], nextafter(t[2], INFINITY)};
        double dn[2] = {t[2], nextafter(t[2], -INFINITY)};
        if (!(st_orient2d(a, b, up) > 0) || !(st_orient2d(a, b, dn) < 0) ||
            !(st_orient2d(b, a, up) < 0) || !(st_orient2d(up, a, b) > 0))
            bad++;
    }
    TAP_CHECK(bad_on == 0, "orient2d of points on y = x is 0, %s", what);
    TAP_CHECK(bad == 0, "orient2d: one ulp off the line gives the right side, "
              "%s (%d wrong)", what, bad);
}

/* Points exactly on the plane z = x, the fourth moved one ulp in z; then
 * orient3d(a,b,c,d) = -dz * ((b-a)x(c-a)).z, and the z component comes from
 * integer (x, y) coordinates, so its sign is known from __int128. */
static void test_coplanar_perturbed(int sh, const char *what)
{
    int bad = 0, bad_on = 0, tested = 0;
    for (int it = 0; it < 5000; it++) {
        int64_t ip[4][2];
        double p[4][3];
        for (int i = 0; i < 4; i++) {
            for (int k = 0; k < 2; k++) {
                ip[i][k] = rng_int(1LL << 40);
                p[i][k] = ldexp((double)ip[i][k], sh - 40);
            }
            p[i][2] = p[i][0];
        }
        int nz = ref_orient2d(ip[0], ip[1], ip[2]);
        if (nz == 0)
            continue;
        tested++;
        /* ((b-a)x(c-a)).z = orient2d(a, b, c) */
        if (st_orient3d(p[0], p[1], p[2], p[3]) != 0.0)
            bad_on++;
        double up[3] = {p[3][0], p[3][1], nextafter(p[3][2], INFINITY)};
        double dn[3] = {p[3][0], p[3][1], nextafter(p[3][2], -INFINITY)};
        if (st_sign(st_orient3d(p[0], p[1], p[2], up)) != -nz ||
            st_sign(st_orient3d(p[0], p[1], p[2], dn)) != nz ||
            st_sign(st_orient3d(p[1], p[0], p[2], up)) != nz)
            bad++;
    }
    TAP_CHECK(tested > 4000 && bad_on == 0,
              "orient3d of points on the plane z = x is 0, %s", what);
    TAP_CHECK(bad == 0, "orient3d: one ulp off the plane gives the right side, "
              "%s (%d wrong)", what, bad);
}

/* Coordinates far apart in size in one call (within the documented spread
 * of 2^588). */
static void test_mixed_scales(void)
{
    const double big = 0x1p300, tiny = 0x1p-200;
    double a[2] = {0, 0}, b[2] = {big, big};
    double c_up[2] = {tiny, nextafter(tiny, INFINITY)};
    double c_dn[2] = {tiny, nextafter(tiny, 0.0)};
    double c_on[2] = {tiny, tiny};
    TAP_CHECK(st_orient2d(a, b, c_up) > 0 && st_orient2d(a, b, c_dn) < 0 &&
              st_orient2d(a, b, c_on) == 0,
              "orient2d: 2^-200 next to 2^300 on one line");
    /* The line through +-(1e80, 1e80) passes through the origin; points
     * 1e-80 off it on either side (a spread of 1e160 < 2^588). */
    double p[2] = {1e80, 1e80}, q[2] = {-1e80, -1e80};
    double o_up[2] = {0, 1e-80}, o_dn[2] = {0, -1e-80}, o[2] = {0, 0};
    TAP_CHECK(st_orient2d(q, p, o_up) > 0 && st_orient2d(q, p, o_dn) < 0 &&
              st_orient2d(q, p, o) == 0,
              "orient2d: 1e-80 off a line through +-1e80");
    /* 3-D: the plane z = x with huge in-plane points and a tiny offset. */
    double A[3] = {big, 0, big}, B[3] = {0, big, 0}, C[3] = {-big, -big, -big};
    /* ((B-A)x(C-A)).z = orient2d of (x, y): (big,0) (0,big) (-big,-big) */
    double t2a[2] = {big, 0}, t2b[2] = {0, big}, t2c[2] = {-big, -big};
    int nz = st_sign(st_orient2d(t2a, t2b, t2c));
    double D_up[3] = {tiny, tiny, nextafter(tiny, INFINITY)};
    double D_on[3] = {tiny, 3 * tiny, tiny};
    TAP_CHECK(nz != 0 && st_sign(st_orient3d(A, B, C, D_up)) == -nz &&
              st_orient3d(A, B, C, D_on) == 0.0,
              "orient3d: 2^-200 offsets against a 2^300 plane");
    /* Subnormal coordinates. */
    double s0[2] = {0, 0}, s1[2] = {DBL_TRUE_MIN, DBL_TRUE_MIN},
           s2[2] = {3 * DBL_TRUE_MIN, 3 * DBL_TRUE_MIN},
           s3[2] = {3 * DBL_TRUE_MIN, 4 * DBL_TRUE_MIN};
    TAP_CHECK(st_orient2d(s0, s1, s2) == 0 && st_orient2d(s0, s1, s3) > 0 &&
              st_orient2d(s1, s0, s3) < 0,
              "orient2d on subnormal coordinates");
    double z0[3] = {0, 0, 0}, z1[3] = {DBL_TRUE_MIN, 0, 0},
           z2[3] = {0, DBL_TRUE_MIN, 0}, z3[3] = {0, 0, DBL_TRUE_MIN};
    /* (z1, z2, z3 counterclockwise seen from z0? orient3d(z0,z1,z2,z3):
     * z3 above the ccw triangle z0 z1 z2 -> negative. */
    TAP_CHECK(st_orient3d(z0, z1, z2, z3) < 0 && st_orient3d(z1, z0, z2, z3) > 0,
              "orient3d on subnormal coordinates");
    /* Huge coordinates whose products overflow in the filter. */
    double h0[3] = {0, 0, 0}, h1[3] = {1e300, 0, 0}, h2[3] = {0, 1e300, 0},
           h3[3] = {0, 0, 1e300}, h3n[3] = {0, 0, -1e300};
    TAP_CHECK(st_orient3d(h0, h1, h2, h3) < 0 && st_orient3d(h0, h1, h2, h3n) > 0,
              "orient3d at 1e300 (the filter overflows)");
    double g0[2] = {-1e300, -1e300}, g1[2] = {1e300, -1e300}, g2[2] = {0, 1e300};
    TAP_CHECK(st_orient2d(g0, g1, g2) > 0 && st_orient2d(g1, g0, g2) < 0,
              "orient2d at 1e300 (the filter overflows)");
    double m = st_orient3d(h0, h1, h2, h3n);
    TAP_CHECK(m == DBL_MAX, "overflowing magnitude is clamped to DBL_MAX (%g)", m);
}

/* Swapping two points negates the sign, cyclic shifts keep it (2-D), even
 * permutations keep it (3-D), on nearly degenerate random input. */
static void test_symmetries(void)
{
    int bad2 = 0, bad3 = 0;
    for (int it = 0; it < 20000; it++) {
        double p[4][3];
        /* Nearly coplanar: random points on z = 0.3 x + 0.7 y (rounded) */
        for (int i = 0; i < 4; i++) {
            p[i][0] = rng_unif(-1, 1);
            p[i][1] = rng_unif(-1, 1);
            p[i][2] = 0.3 * p[i][0] + 0.7 * p[i][1];
        }
        int s = st_sign(st_orient2d(p[0], p[1], p[2]));
        if (st_sign(st_orient2d(p[1], p[0], p[2])) != -s ||
            st_sign(st_orient2d(p[1], p[2], p[0])) != s ||
            st_sign(st_orient2d(p[0], p[2], p[1])) != -s)
            bad2++;
        int t = st_sign(st_orient3d(p[0], p[1], p[2], p[3]));
        if (st_sign(st_orient3d(p[1], p[0], p[2], p[3])) != -t ||
            st_sign(st_orient3d(p[0], p[1], p[3], p[2])) != -t ||
            st_sign(st_orient3d(p[1], p[2], p[0], p[3])) != t ||
            st_sign(st_orient3d(p[3], p[2], p[1], p[0])) != t ||
            st_sign(st_orient3d(p[1], p[0], p[3], p[2])) != t)
            bad3++;
    }
    TAP_CHECK(bad2 == 0, "orient2d: swaps negate, cyclic shifts keep (%d bad)", bad2);
    TAP_CHECK(bad3 == 0, "orient3d: swaps negate, even permutations keep (%d bad)",
              bad3);
}

static void test_exact_counter(void)
{
    unsigned long long before = st_pred_exact_calls();
    double a[3] = {0.1, 0.2, 0.3}, b[3] = {0.4, 0.5, 0.6}, c[3] = {0.7, 0.8, 0.9};
    double d[3] = {1.0, 2.0, 3.0};
    double o = st_orient2d(a, b, a) + st_orient3d(a, a, b, d) +
               st_orient3d(a, b, c, d);
    (void)o;
    (void)c;
    unsigned long long mid = st_pred_exact_calls();
    TAP_CHECK(mid >= before + 2, "exact calls counted on degenerate input "
              "(%llu -> %llu)", before, mid);
    double e[3] = {0, 0, 0}, f[3] = {1, 0, 0}, g[3] = {0, 1, 0}, h[3] = {0, 0, 1};
    o = st_orient3d(e, f, g, h) + st_orient2d(e, f, g);
    TAP_CHECK(st_pred_exact_calls() == mid,
              "a well-separated call is answered by the filter");
}

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts); /* CPU time: the machine is shared */
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* Speed on random (filter) and degenerate (exact) input, reported. */
static void test_speed(void)
{
    enum { N = 4096 };
    static double pts[N][3];
    for (int i = 0; i < N; i++)
        for (int k = 0; k < 3; k++)
            pts[i][k] = rng_unif(-1, 1);
    double acc = 0;
    const int reps = 500000;
    double t0 = now();
    for (int i = 0; i < reps; i++)
        acc += st_orient3d(pts[i % N], pts[(i + 1) % N], pts[(i + 7) % N],
                           pts[(i + 13) % N]);
    double t1 = now();
    for (int i = 0; i < reps; i++)
        acc += st_orient2d(pts[i % N], pts[(i + 1) % N], pts[(i + 7) % N]);
    double t2 = now();
    /* Coplanar: z = x exactly, so every call goes exact. */
    for (int i = 0; i < N; i++)
        pts[i][2] = pts[i][0];
    unsigned long long e0 = st_pred_exact_calls();
    const int reps_exact = 50000;
    double t3 = now();
    for (int i = 0; i < reps_exact; i++)
        acc += st_orient3d(pts[i % N], pts[(i + 1) % N], pts[(i + 7) % N],
                           pts[(i + 13) % N]);
    double t4 = now();
    unsigned long long e1 = st_pred_exact_calls();
    /* A shared vertex: the filter cannot decide a zero, the repeated-point
     * check does. */
    double t5 = now();
    for (int i = 0; i < reps_exact; i++)
        acc += st_orient3d(pts[i % N], pts[(i + 1) % N], pts[(i + 7) % N], pts[i % N]);
    double t6 = now();
    TAP_NOTE("orient3d filtered: %.1f M calls/s; orient2d filtered: %.1f M "
             "calls/s; orient3d exact (coplanar doubles): %.2f M calls/s; "
             "orient3d with a repeated point: %.1f M calls/s (%g)",
             reps / (t1 - t0) / 1e6, reps / (t2 - t1) / 1e6,
             reps_exact / (t4 - t3) / 1e6, reps_exact / (t6 - t5) / 1e6, acc);
    TAP_CHECK(e1 - e0 == (unsigned long long)reps_exact,
              "every coplanar call went to the exact stage");
}

/* The perturbed cases at three scales each. */
static void test_collinear_perturbed_scales(void)
{
    test_collinear_perturbed(0, "coordinates in [-1, 1]");
    test_collinear_perturbed(-997, "coordinates near 1e-300");
    test_collinear_perturbed(498, "coordinates near 1e150");
}

static void test_coplanar_perturbed_scales(void)
{
    test_coplanar_perturbed(0, "coordinates near 1");
    test_coplanar_perturbed(-960, "coordinates near 1e-289");
    test_coplanar_perturbed(498, "coordinates near 1e150");
}

/* st_plane_filter_sign: wherever it decides, the side is orient3d's
 * (+1 where st_orient3d(o, a, b, q) < 0), on points far from the plane
 * and on points a unit or so off it at 2^53 (near-ties the filter must
 * leave undecided); on the plane's own corners it decides nothing. */
static void test_plane_filter_sign(void)
{
    const int64_t R = (int64_t)1 << 53;
    int wrong = 0, decided_far = 0, decided_near = 0, on_plane = 0;
    for (int it = 0; it < 20000; it++) {
        double p[3][3], far[3], near[3];
        for (int i = 0; i < 3; i++)
            for (int k = 0; k < 3; k++)
                p[i][k] = (double)rng_int(R);
        for (int k = 0; k < 3; k++) {
            far[k] = (double)rng_int(R);
            int64_t sum = ((int64_t)p[0][k] + (int64_t)p[1][k] + (int64_t)p[2][k]) / 3;
            near[k] = (double)(sum + rng_int(1));
        }
        st_plane_filter pl;
        st_plane_filter_plane(&pl, p[0], p[1], p[2]);
        const double *q[2] = {far, near};
        for (int j = 0; j < 2; j++) {
            int s = st_plane_filter_sign(&pl, q[j]);
            int o = st_sign(st_orient3d(p[0], p[1], p[2], q[j]));
            wrong += s != 0 && s != -o;
            decided_far += j == 0 && s != 0;
            decided_near += j == 1 && s != 0;
        }
        for (int i = 0; i < 3; i++)
            on_plane += st_plane_filter_sign(&pl, p[i]) != 0;
    }
    TAP_CHECK(wrong == 0 && on_plane == 0,
              "the plane filter's sign is orient3d's wherever it decides (%d wrong, %d "
              "decided on a corner)", wrong, on_plane);
    TAP_CHECK(decided_far > 19900 && decided_near < 20000,
              "it decides almost every far point (%d of 20000) and leaves near-ties (%d "
              "of 20000 near points decided)", decided_far, decided_near);
}

int main(int argc, char **argv)
{
    static const tap_test tests[] = {TAP_TEST(random_integers), TAP_TEST(drop_axes),
                                     TAP_TEST(53bit_nearly_coplanar),
                                     {"collinear_perturbed", test_collinear_perturbed_scales},
                                     {"coplanar_perturbed", test_coplanar_perturbed_scales},
                                     TAP_TEST(mixed_scales), TAP_TEST(symmetries),
                                     TAP_TEST(exact_counter), TAP_TEST(plane_filter_sign),
                                     TAP_TEST(speed), {0}};
    return tap_main(argc, argv, tests);
}
