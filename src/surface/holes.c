/*
 * holes.c - caps for the holes of a soup (see holes.h).
 * Design notes and measurements: doc/design/holes.md.
 *
 *   1. the soup's edges and pieces on welded vertices (edges.h:
 *      degenerate and duplicated triangles left out);
 *   2. an edge of one triangle is a boundary edge; the pieces' areas are
 *      summed;
 *   3. pair the boundary edges at each vertex (where holes touch: by the
 *      angular gaps around it, or on a crease by the edges' hole sides)
 *      and walk them into loops;
 *   4. triangulate each loop by least area (O(n^3) in its n vertices)
 *      and keep the cap if it is small beside the pieces near the loop (a
 *      bounding volume hierarchy finds them); with bend, the cap is the
 *      triangulation that bends least instead (O(n^3) too).
 *
 * st_soup_hole_caps_shared reads as these steps around one state (a
 * capper: the rim, the loop being capped, the caps): rim_build (2),
 * rim_intact, rim_pair and trace_loops (3, on one thread), cap_all (4:
 * cap_loop on each loop by the threads, each into its own soup, the caps
 * appended in loop order; doc/design/holes.md, "Threads").
 */
#include "souptet/holes.h"
#include "../base/fpenv.h"
#include "holes_internal.h"
#include "souptet/geom.h"
#include "souptet/mem.h"
#include "souptet/bvh.h"
#include "souptet/edges.h"
#include "souptet/weld.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#ifdef HOLES_AVX
#include <immintrin.h>
#elif defined(__SSE2__)
#include <emmintrin.h>
#endif
#ifdef _OPENMP
#include <omp.h>
#endif

#define NONE UINT32_MAX
/* A cone from a rebuilt corner replaces the cap of the loop's own points
 * when its bend along the loop is below CONE_BETTER times the cap's: more
 * rebuilds more of the large holes but costs the deleted faces, less
 * rebuilds little (doc/design/holes.md, "CONE_BETTER"). */
#define CONE_BETTER 0.5
#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

/* The rim of the soup's holes: its boundary edges (an edge of one kept
 * triangle, on welded vertices), how they pair at their ends, and the
 * soup's areas the caps are measured against. */
typedef struct rim {
    size_t nb;                  /* boundary edges */
    uint32_t *a, *b, *t;        /* each one's welded ends and its triangle */
    uint32_t *pa, *pb;          /* its partner at end a, at end b (NONE: none) */
    uint8_t *used;              /* walked into a loop */
    uint32_t *vstart, *vlist;   /* the boundary edges at each welded vertex */
    uint32_t *tstart, *tlist;   /* the kept triangles at each vertex where holes touch */
    uint32_t *wpos;             /* a soup vertex welded to each welded vertex */
    double *piece_area;         /* each piece's area */
    uint32_t *stamp;            /* per triangle or piece: scratch marks */
    double total, area;         /* the kept soup's area, its rim triangles' */
} rim;

st_holes_params st_holes_params_default(void)
{
    /* 0.25: a hole's cap is at most a quarter of the surface around it (on
     * the corpus, holes of 3 rings of faces on models of 3 000 faces and
     * up: under 0.15); an open patch's own loop spans about its area. */
    /* bend and planes where the soup is intact (issue 17): the rim at
     * most half the soup's area (faces deleted at random leave a rim of
     * most of it) and not one-sided along an axis below 0.02 (one-sided
     * scans read 0.000, every other soup with holes 0.39 and up). The
     * measurements behind these values, and the variants not kept:
     * doc/design/holes.md. */
    st_holes_params p = {0.25, 256, 0.01, 1, 1, 0.5, 0.02};
    return p;
}

static double tri_area(const double *a, const double *b, const double *c)
{
    double u[3], v[3], n[3];
    st_sub3(u, b, a);
    st_sub3(v, c, a);
    st_cross3(n, u, v);
    return 0.5 * st_norm3(n);
}

/* The triangles of a polygon triangulation chosen by dynamic programming:
 * best[i n + j] is the apex over the edge (i, j); tri[3 (n - 2)] gets them
 * with local indices, from the edge (0, n - 1) down (stack holds 2 n). */
static void emit_triangles(const uint16_t *best, size_t n, size_t *stack, uint32_t *tri)
{
    size_t top = 0, nt = 0;
    stack[top++] = 0;
    stack[top++] = n - 1;
    while (top) {
        const size_t j = stack[--top], i = stack[--top];
        if (j - i < 2)
            continue;
        const size_t k = best[i * n + j];
        tri[3 * nt] = (uint32_t)i;
        tri[3 * nt + 1] = (uint32_t)k;
        tri[3 * nt + 2] = (uint32_t)j;
        nt++;
        stack[top++] = i;
        stack[top++] = k;
        stack[top++] = k;
        stack[top++] = j;
    }
}

/* "out of memory" where the holes' scratch is allocated. */
static st_status oom(st_error *err)
{
    return st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory for the holes");
}

st_status st_holes_least_area(double *area, const double *const *pts, size_t n, uint32_t *tri,
                              st_error *err)
{
    double *w = malloc(n * n * sizeof *w);
    uint16_t *best = malloc(n * n * sizeof *best);
    size_t *stack = malloc(2 * n * sizeof *stack);
    st_status rc = ST_OK;
    if (!w || !best || !stack) {
        rc = oom(err);
        goto done;
    }
    for (size_t i = 0; i + 1 < n; i++)
        w[i * n + i + 1] = 0.0;
    for (size_t len = 2; len < n; len++)
        for (size_t i = 0; i + len < n; i++) {
            const size_t j = i + len;
            double m = INFINITY;
            size_t mk = i + 1;
            for (size_t k = i + 1; k < j; k++) {
                double c = w[i * n + k] + w[k * n + j] + tri_area(pts[i], pts[k], pts[j]);
                if (c < m) {        /* ties keep the first k */
                    m = c;
                    mk = k;
                }
            }
            w[i * n + j] = m;
            best[i * n + j] = (uint16_t)mk;
        }
    *area = w[n - 1];
    emit_triangles(best, n, stack, tri);
done:
    free(w);
    free(best);
    free(stack);
    return rc;
}

/* The relative margin by which the screens below must clear the limit:
 * the rounding they can differ from least_area by is about 2 n units in
 * the last place (n <= 4096: under 1e-12), the margin a hundred times
 * that. */
#define SURE_MARGIN 1e-10

/* 1 when least_area's area of the loop pts[0..n) is surely above lim,
 * from the loop's vector area: every surface spanning it has at least
 * that area (the vector areas of its triangles sum to the loop's, and
 * their lengths are at least the sum's). In the loop's centroid frame
 * the rounding of the sum is below n units in the last place of the sum
 * of its points' squared distances (each cross product's length at most
 * the mean of its two squares). */
static int vector_area_above(const double *const *pts, size_t n, double lim)
{
    double o[3] = {0, 0, 0}, v[3] = {0, 0, 0}, r2 = 0.0;
    for (size_t i = 0; i < n; i++)
        for (int k = 0; k < 3; k++)
            o[k] += pts[i][k] / (double)n;
    for (size_t i = 0; i < n; i++) {
        double a[3], b[3], c[3];
        st_sub3(a, pts[i], o);
        st_sub3(b, pts[(i + 1) % n], o);
        st_cross3(c, a, b);
        for (int k = 0; k < 3; k++)
            v[k] += c[k];
        r2 += st_dot3(a, a);
    }
    const double area = 0.5 * sqrt(st_dot3(v, v)) - SURE_MARGIN * r2;
    return area * (1.0 - SURE_MARGIN) > lim;
}

/* The least over the apexes k in (i, j) of w[i n + k] + w[k n + j] plus
 * the area of (pts[i], pts[k], pts[j]) by a plain square root: with the
 * loop's coordinates in xs, ys, zs and the table also transposed (wt[j n
 * + k] = w[k n + j]). Four apexes at a time with AVX where the processor
 * has it (area_row4), then two at a time with SSE2: each lane's
 * operations are the scalar ones, in the same order (no fused
 * multiply-add), so every sum is the same to the bit, and the least of
 * them is the same in any order (none is NaN where it is taken). */

/* The lanes' broadcasts for area_row's row (i, j) (P: the intrinsics'
 * prefix, _mm for SSE2's two lanes, _mm256 for AVX's four; T their type),
 * and the step that takes the apexes from q on into vm, the least so far
 * (min_pd: t < vm ? t : vm, lane by lane). */
#define AREA_SETUP(P, T)                                                            \
    const T vp0 = P##_set1_pd(xs[i]), vp1 = P##_set1_pd(ys[i]);                     \
    const T vp2 = P##_set1_pd(zs[i]), half = P##_set1_pd(0.5);                      \
    const T vf0 = P##_set1_pd(xs[j] - xs[i]), vf1 = P##_set1_pd(ys[j] - ys[i]);     \
    const T vf2 = P##_set1_pd(zs[j] - zs[i])
#define AREA_STEP(P, T, q)                                                          \
    do {                                                                            \
        const T s_ = P##_add_pd(P##_loadu_pd(wi + (q)), P##_loadu_pd(wj + (q)));    \
        const T e0 = P##_sub_pd(P##_loadu_pd(xs + (q)), vp0);                       \
        const T e1 = P##_sub_pd(P##_loadu_pd(ys + (q)), vp1);                       \
        const T e2 = P##_sub_pd(P##_loadu_pd(zs + (q)), vp2);                       \
        const T c0 = P##_sub_pd(P##_mul_pd(e1, vf2), P##_mul_pd(e2, vf1));          \
        const T c1 = P##_sub_pd(P##_mul_pd(e2, vf0), P##_mul_pd(e0, vf2));          \
        const T c2 = P##_sub_pd(P##_mul_pd(e0, vf1), P##_mul_pd(e1, vf0));          \
        const T dd = P##_add_pd(P##_add_pd(P##_mul_pd(c0, c0), P##_mul_pd(c1, c1)), \
                                P##_mul_pd(c2, c2));                                \
        const T t_ = P##_add_pd(s_, P##_mul_pd(half, P##_sqrt_pd(dd)));             \
        vm = P##_min_pd(t_, vm);                                                    \
    } while (0)

#ifdef HOLES_AVX
/* area_row's least over the apexes *k, *k + 1, ... four at a time (AVX),
 * while four are left before j; *k moved past them. */
static HOLES_AVX_FN double area_row4(const double *xs, const double *ys, const double *zs,
                                     const double *wi, const double *wj, size_t i, size_t j,
                                     size_t *k)
{
    AREA_SETUP(_mm256, __m256d);
    __m256d vm = _mm256_set1_pd(INFINITY);
    size_t q = *k;
    for (; q + 3 < j; q += 4)
        AREA_STEP(_mm256, __m256d, q);
    *k = q;
    double lanes[4];
    _mm256_storeu_pd(lanes, vm);
    double m = lanes[0];
    for (int l = 1; l < 4; l++)
        m = lanes[l] < m ? lanes[l] : m;
    return m;
}
#endif

static double area_row(const double *xs, const double *ys, const double *zs, const double *w,
                       const double *wt, size_t n, size_t i, size_t j)
{
    const double p0 = xs[i], p1 = ys[i], p2 = zs[i];
    const double f0 = xs[j] - p0, f1 = ys[j] - p1, f2 = zs[j] - p2;
    const double *wi = w + i * n, *wj = wt + j * n;
    double m = INFINITY;
    size_t k = i + 1;
#ifdef HOLES_AVX
    if (k + 3 < j && holes_avx())
        m = area_row4(xs, ys, zs, wi, wj, i, j, &k);
#endif
#ifdef __SSE2__
    AREA_SETUP(_mm, __m128d);
    __m128d vm = _mm_set1_pd(m);
    for (; k + 1 < j; k += 2)
        AREA_STEP(_mm, __m128d, k);
    double lanes[2];
    _mm_storeu_pd(lanes, vm);
    m = lanes[1] < lanes[0] ? lanes[1] : lanes[0];
#endif
    for (; k < j; k++) {
        const double s = wi[k] + wj[k];
        if (!(s < m))
            continue;
        const double e0 = xs[k] - p0, e1 = ys[k] - p1, e2 = zs[k] - p2;
        const double c0 = e1 * f2 - e2 * f1, c1 = e2 * f0 - e0 * f2, c2 = e0 * f1 - e1 * f0;
        const double t = s + 0.5 * sqrt(c0 * c0 + c1 * c1 + c2 * c2);
        m = t < m ? t : m;
    }
    return m;
}

/* 1 when least_area's area of the loop pts[0..n) is surely above lim:
 * least_area's dynamic program on a plain square root for each triangle's
 * length (least_area's scaled one and this differ by a few units in the
 * last place per triangle, and both programs give the least over all
 * triangulations of their rounded sums, the additions being monotone),
 * with no triangulation kept (area_row). 0 when out of memory
 * (least_area then runs, and says so). */
static int least_area_above(const double *const *pts, size_t n, double lim)
{
    double *w = st_malloc_array(n * n, sizeof *w), *wt = st_malloc_array(n * n, sizeof *wt);
    double *xyz = st_malloc_array(3 * n, sizeof *xyz);
    int above = 0;
    if (w && wt && xyz) {
        double *xs = xyz, *ys = xyz + n, *zs = xyz + 2 * n;
        for (size_t i = 0; i < n; i++) {
            xs[i] = pts[i][0], ys[i] = pts[i][1], zs[i] = pts[i][2];
            if (i + 1 < n)
                w[i * n + i + 1] = wt[(i + 1) * n + i] = 0.0;
        }
        for (size_t len = 2; len < n; len++)
            for (size_t i = 0; i + len < n; i++) {
                const size_t j = i + len;
                w[i * n + j] = wt[j * n + i] = area_row(xs, ys, zs, w, wt, n, i, j);
            }
        above = w[n - 1] * (1.0 - SURE_MARGIN) > lim;
    }
    free(w);
    free(wt);
    free(xyz);
    return above;
}

int st_holes_area_above(const double *const *pts, size_t n, double lim)
{
    return vector_area_above(pts, n, lim) || least_area_above(pts, n, lim);
}

/* least_bend's program: its tables (n x n) and the soup's triangle on
 * the closing edge. */
typedef struct bend_dp {
    size_t n;
    const double *const *pts;
    double *ang, *w, *nrm, *el, last[3];
    uint16_t *best;
} bend_dp;

/* *a plus l times bend(t, r) (bend() exactly: the arc tangent of the
 * same two values) into *a, and 1; or 0, *a as it was, when the sum is
 * surely above lim: told before the arc tangent from a lower bound of
 * the bend, the sine of the angle (|t x r| of unit vectors, less a
 * relative 1e-6, far beyond the rounding of the norms and of atan2),
 * or 1.5 where the angle is at least a right angle, the sum's rounding
 * monotone in the bend. */
static int bend_add(double *a, double l, const double *t, const double *r, double lim)
{
    if (st_dot3(t, t) == 0.0 || st_dot3(r, r) == 0.0) {
        *a += l * 4.0;
        return 1;
    }
    double c[3];
    st_cross3(c, t, r);
    const double y = st_norm3(c), x = st_dot3(t, r);
    if (*a + l * (x > 0.0 ? y * (1.0 - 1e-6) : 1.5) > lim)
        return 0;
    *a += l * atan2(y, x);
    return 1;
}

/* The sub-polygon (i, j) of least_bend through apex k: its bend, area and
 * triangle's normal taken into (*ba, *bw, bn, *mk) when they are below
 * them, (bend, area) compared in that order, ties by the lower k. The
 * bends added are never negative (nor their sums' rounding): an apex whose
 * two sides alone, or with one of its bends, bend more than the best is
 * not taken, nor measured further. */
static void bend_apex(const bend_dp *d, size_t i, size_t k, size_t j, double *ba, double *bw,
                      double *bn, size_t *mk)
{
    const size_t n = d->n;
    const double *const *pts = d->pts;
    double a = d->ang[i * n + k] + d->ang[k * n + j];
    if (a > *ba)
        return;
    double t[3];
    unit_normal(t, pts[i], pts[k], pts[j]);
    if (!bend_add(&a, d->el[i * n + k], t, d->nrm + 3 * (i * n + k), *ba) ||
        !bend_add(&a, d->el[k * n + j], t, d->nrm + 3 * (k * n + j), *ba))
        return;
    if (j - i == n - 1)     /* the closing edge, passed n-1 -> 0 */
        a += d->el[n - 1] * bend(t, d->last);
    if (!(a <= *ba))        /* the area only breaks ties */
        return;
    const double c = d->w[i * n + k] + d->w[k * n + j] + tri_area(pts[i], pts[k], pts[j]);
    if (a < *ba || (a == *ba && (c < *bw || (c == *bw && k < *mk)))) {
        *ba = a;
        *bw = c;
        *mk = k;
        memcpy(bn, t, sizeof t);
    }
}

/* The triangulation of the polygon pts[0..n) (n >= 3) on its own vertices
 * that bends least: the sum over its edges of length times bend (bend()),
 * the discrete total mean curvature, is least; ties by area. The edges
 * are the cap's inner edges and the loop's own, where the cap meets the
 * soup's triangle across it (side[i]: that triangle's third vertex, on
 * edge pts[i] -> pts[i + 1 mod n]); the soup's triangles orient the bends,
 * not the soup: each is read as passing its loop edge the other way from
 * the cap. Dynamic programming as for least_area: the bend across the
 * diagonal (i, k) is taken with the triangle the best triangulation of
 * (i, k) puts on it (Liepa 2003, "Filling holes in meshes", who takes the
 * largest bend; the sum is what a missing face with a crease inside the
 * loop needs: a wall across it would bend along all its length). A
 * missing planar face bends only along its rim, a cylindrical or conical
 * one (ruled between two rims of the loop) only by its facets' small
 * angles; the least-area cap cuts straight across a curved face and,
 * where the loop runs over several faces of a part, folds through its
 * solid. Each sub-polygon tries first the apex that (i, j - 1) took
 * (usually the best or near it: the apexes after it are then mostly
 * passed over unmeasured), then the others in order; the least (bend,
 * area, apex) is the same in any order (ties keep the first k). Fills
 * tri[3 (n - 2)] and *area with the cap's area (an st_holes_fill,
 * holes_internal.h). ST_ENOMEM. */
st_status st_holes_least_bend(double *area, const double *const *pts, const double *const *side,
                              size_t n, uint32_t *tri, st_error *err)
{
    bend_dp d = {n, pts, malloc(n * n * sizeof *d.ang), malloc(n * n * sizeof *d.w),
                 malloc(3 * n * n * sizeof *d.nrm), malloc(n * n * sizeof *d.el), {0, 0, 0},
                 malloc(n * n * sizeof *d.best)};
    size_t *stack = malloc(2 * n * sizeof *stack);
    st_status rc = ST_OK;
    if (!d.ang || !d.w || !d.nrm || !d.el || !d.best || !stack) {
        rc = oom(err);
        goto done;
    }
    for (size_t i = 0; i < n; i++)     /* el[i n + k], i < k: dist3(pts[i], pts[k]) */
        for (size_t k = i + 1; k < n; k++)
            d.el[i * n + k] = dist3(pts[i], pts[k]);
    /* (i, i + 1): the soup's triangle across the edge, passed i -> c -> i+1;
     * (i, j) above: the triangle (i, k, j) of its best triangulation */
    for (size_t i = 0; i + 1 < n; i++) {
        d.ang[i * n + i + 1] = 0.0;
        d.w[i * n + i + 1] = 0.0;
        unit_normal(d.nrm + 3 * (i * n + i + 1), pts[i], side[i], pts[i + 1]);
    }
    /* the soup's triangle on the closing edge, 0 -> n-1 -> c */
    unit_normal(d.last, pts[0], pts[n - 1], side[n - 1]);
    for (size_t len = 2; len < n; len++)
        for (size_t i = 0; i + len < n; i++) {
            const size_t j = i + len;
            double ba = INFINITY, bw = INFINITY, bn[3] = {0, 0, 0};     /* bend, area, normal */
            size_t mk = j;
            const size_t k0 = len > 2 ? d.best[i * n + j - 1] : i + 1;
            bend_apex(&d, i, k0, j, &ba, &bw, bn, &mk);
            for (size_t k = i + 1; k < j; k++)
                if (k != k0)
                    bend_apex(&d, i, k, j, &ba, &bw, bn, &mk);
            d.ang[i * n + j] = ba;
            d.w[i * n + j] = bw;
            d.best[i * n + j] = (uint16_t)(mk < j ? mk : i + 1);
            memcpy(d.nrm + 3 * (i * n + j), bn, sizeof bn);
        }
    *area = d.w[n - 1];
    emit_triangles(d.best, n, stack, tri);
done:
    free(d.ang), free(d.w), free(d.nrm), free(d.el), free(d.best), free(stack);
    return rc;
}

/* least_area as an st_holes_fill (holes_internal.h) */
static st_status fill_area(double *area, const double *const *pts, const double *const *side,
                           size_t n, uint32_t *tri, st_error *err)
{
    (void)side;
    return st_holes_least_area(area, pts, n, tri, err);
}

/* The bend along the loop of the cap tri[3 (n - 2)] (local indices, as
 * least_bend's): the sum over the loop's edges of length times the
 * dihedral between the cap's triangle on it and the soup's, or, where the
 * edge runs along a crease (crease: st_holes_creases, or NULL), the
 * other face's plane there (st_holes_crease_bend). */
static double rim_bend(const double *const *pts, const double *const *side, size_t n,
                       const uint32_t *tri, const double *crease)
{
    double b = 0.0;
    for (size_t t = 0; t + 2 < n; t++) {
        const uint32_t *c = tri + 3 * t;
        double nt[3], nr[3];
        unit_normal(nt, pts[c[0]], pts[c[1]], pts[c[2]]);
        for (int e = 0; e < 3; e++) {
            const size_t a = c[e], z = c[(e + 1) % 3];
            if ((a + 1) % n != z && (z + 1) % n != a)
                continue;
            /* the loop edge from i to i + 1 mod n */
            const size_t i = (a + 1) % n == z ? a : z;
            unit_normal(nr, pts[i], side[i], pts[(i + 1) % n]);
            b += dist3(pts[a], pts[z]) * st_holes_crease_bend(nt, nr, crease ? crease + 6 * i : NULL);
        }
    }
    return b;
}

typedef struct around_ctx {
    const uint8_t *kept;
    const uint32_t *piece;
    uint32_t *stamp;
    uint32_t mark;
    const double *piece_area;
    double around;
} around_ctx;

/* A flat hole (any size): the loop lies within flat times its extent of
 * the plane of its Newell normal, and the triangles along it that lie in
 * that plane (normals within about 8 degrees of it) are mostly outside the
 * loop, as around a face that is missing, not inside it, as along the rim
 * of a flat sheet. A CAD part that lost a face: its cap is the face. */
static int flat_hole(const st_soup *s, const double *const *pts, size_t n, const uint32_t *be_t,
                     const uint32_t *loop_e, double flat)
{
    if (!(flat > 0.0))
        return 0;
    double nn[3] = {0, 0, 0}, c[3] = {0, 0, 0}, lo[3], hi[3];
    for (int q = 0; q < 3; q++)
        lo[q] = hi[q] = pts[0][q];
    for (size_t i = 0; i < n; i++) {
        const double *a = pts[i], *b = pts[(i + 1) % n];
        nn[0] += (a[1] - b[1]) * (a[2] + b[2]);
        nn[1] += (a[2] - b[2]) * (a[0] + b[0]);
        nn[2] += (a[0] - b[0]) * (a[1] + b[1]);
        for (int q = 0; q < 3; q++) {
            c[q] += a[q] / (double)n;
            lo[q] = fmin(lo[q], a[q]);
            hi[q] = fmax(hi[q], a[q]);
        }
    }
    const double len = sqrt(nn[0] * nn[0] + nn[1] * nn[1] + nn[2] * nn[2]);
    double ext = 0.0;
    for (int q = 0; q < 3; q++)
        ext = fmax(ext, hi[q] - lo[q]);
    if (!(len > 0.0) || !(ext > 0.0))
        return 0;
    for (int q = 0; q < 3; q++)
        nn[q] /= len;
    for (size_t i = 0; i < n; i++) {
        const double d = (pts[i][0] - c[0]) * nn[0] + (pts[i][1] - c[1]) * nn[1] +
                         (pts[i][2] - c[2]) * nn[2];
        if (fabs(d) > flat * ext)
            return 0;
    }
    size_t inner = 0, outer = 0;
    for (size_t i = 0; i < n; i++) {
        const double *a = pts[i], *b = pts[(i + 1) % n];
        const uint32_t *tv = s->tris + 3 * (size_t)be_t[loop_e[i]];
        const double *P = s->xyz + 3 * (size_t)tv[0], *Q = s->xyz + 3 * (size_t)tv[1],
                     *R = s->xyz + 3 * (size_t)tv[2];
        double u[3], w[3], tn[3];
        for (int q = 0; q < 3; q++) {
            u[q] = Q[q] - P[q];
            w[q] = R[q] - P[q];
        }
        tn[0] = u[1] * w[2] - u[2] * w[1];
        tn[1] = u[2] * w[0] - u[0] * w[2];
        tn[2] = u[0] * w[1] - u[1] * w[0];
        const double tl = sqrt(tn[0] * tn[0] + tn[1] * tn[1] + tn[2] * tn[2]);
        if (!(tl > 0.0) || fabs(tn[0] * nn[0] + tn[1] * nn[1] + tn[2] * nn[2]) < 0.99 * tl)
            continue;
        /* the triangle's centroid: left of a -> b is inside the loop */
        double e[3], m[3], x[3];
        for (int q = 0; q < 3; q++) {
            e[q] = b[q] - a[q];
            m[q] = (P[q] + Q[q] + R[q]) / 3.0 - a[q];
        }
        x[0] = e[1] * m[2] - e[2] * m[1];
        x[1] = e[2] * m[0] - e[0] * m[2];
        x[2] = e[0] * m[1] - e[1] * m[0];
        if (x[0] * nn[0] + x[1] * nn[1] + x[2] * nn[2] > 0.0)
            inner++;
        else
            outer++;
    }
    return inner * 2 <= outer;
}

static int add_piece(void *vc, uint32_t t)
{
    around_ctx *c = vc;
    if (!c->kept[t])
        return 0;
    const uint32_t r = c->piece[t];
    if (c->stamp[r] != c->mark) {
        c->stamp[r] = c->mark;
        c->around += c->piece_area[r];
    }
    return 0;
}

/* Edge e's partner at its end v is `other`. */
static void set_partner(const uint32_t *be_a, uint32_t *pa, uint32_t *pb, uint32_t e,
                        uint32_t v, uint32_t other)
{
    if (be_a[e] == v)
        pa[e] = other;
    else
        pb[e] = other;
}

/* Is angle a (radians) strictly inside one of the sectors [lo, hi]? */
static int covered(const double *lo, const double *hi, size_t n, double a)
{
    for (size_t i = 0; i < n; i++)
        for (int w = -1; w <= 1; w++) {
            const double b = a + 2.0 * M_PI * w;
            if (b > lo[i] && b < hi[i])
                return 1;
        }
    return 0;
}

/* Where one plane does not order the triangles around v (a crease): each
 * boundary edge e at v has a direction d (from v along it) and a hole side
 * h (in the plane of e's triangle, perpendicular to e, away from the
 * triangle: where the missing triangles were). Two edges bound the same
 * gap when each lies on the other's hole side: the score dot(h1, d2) +
 * dot(h2, d1) is high (2 for two edges of a flat gap of 90 degrees, 0 for a
 * gap folded by a right-angled crease, -2 for two edges of one fan's ends
 * seen from inside it). Pairs are taken best score first (ties by position
 * in ev), never two edges of one triangle nor a pair scoring -1 or less
 * (each edge then lies more in the other's triangle than in its hole);
 * only a matching that pairs every edge is kept, else the edges stay
 * unpaired and their loops open. hit[] (k bytes) is scratch. */
static void pair_by_sides(rim *r, const st_soup *s, const uint32_t *weld, uint32_t v,
                          const uint32_t *ev, size_t k, uint8_t *hit)
{
    const uint32_t *wpos = r->wpos, *be_a = r->a, *be_b = r->b, *be_t = r->t;
    uint32_t *pa = r->pa, *pb = r->pb;
    enum { MAXK = 32 };
    if (k > MAXK)
        return;
    const double *o = s->xyz + 3 * (size_t)wpos[v];
    double d[MAXK][3], h[MAXK][3];
    for (size_t i = 0; i < k; i++) {
        const uint32_t e = ev[i], w = be_a[e] == v ? be_b[e] : be_a[e];
        const uint32_t *c = s->tris + 3 * (size_t)be_t[e];
        const double *third = NULL;
        for (int q = 0; q < 3; q++)
            if (weld[c[q]] != v && weld[c[q]] != w)
                third = s->xyz + 3 * (size_t)c[q];
        double t[3];
        st_sub3(d[i], s->xyz + 3 * (size_t)wpos[w], o);
        st_sub3(t, third, o);
        const double dd = st_dot3(d[i], d[i]), td = st_dot3(t, d[i]);
        for (int q = 0; q < 3; q++)     /* minus t's part across e, away from it */
            h[i][q] = -(t[q] - td / dd * d[i][q]);
        const double ld = sqrt(dd), lh = st_norm3(h[i]);
        if (!(ld > 0) || !(lh > 0))
            return;
        for (int q = 0; q < 3; q++) {
            d[i][q] /= ld;
            h[i][q] /= lh;
        }
    }
    uint32_t mate[MAXK];
    memset(hit, 0, k);
    for (size_t round = 0; round < k / 2; round++) {
        double best = -1.0;
        size_t bi = k, bj = k;
        for (size_t i = 0; i < k; i++)
            for (size_t j = i + 1; j < k; j++) {
                if (hit[i] || hit[j] || be_t[ev[i]] == be_t[ev[j]])
                    continue;
                const double sc = st_dot3(h[i], d[j]) + st_dot3(h[j], d[i]);
                if (sc > best) {
                    best = sc;
                    bi = i;
                    bj = j;
                }
            }
        if (bi == k)
            return;             /* an edge without a partner: all stay open */
        hit[bi] = hit[bj] = 1;
        mate[bi] = (uint32_t)bj;
        mate[bj] = (uint32_t)bi;
    }
    for (size_t i = 0; i < k; i++)
        set_partner(be_a, pa, pb, ev[i], v, ev[mate[i]]);
}

/* How one-sided along an axis the kept triangles of s are: for each axis,
 * each orientable region (triangles oriented to agree across every edge of
 * exactly two, breadth first; a conflict is left where it is found) turned
 * the way it faces most, the projected area facing the other way over that
 * facing it, summed over the regions; the least over the three axes. 0
 * for a scan seen from one side along an axis (its faces facing away were
 * never seen), near 1 for a closed part with holes in it: in *ratio.
 * ST_ENOMEM. */
static st_status axis_one_sided(double *ratio, const st_soup *s, const st_soup_edges *E,
                                st_error *err)
{
    const size_t nt = s->ntris;
    uint32_t *nbr = st_malloc_array(3 * nt + 1, sizeof *nbr);
    uint8_t *same = st_malloc_array(3 * nt + 1, 1);
    uint8_t *flip = st_malloc_array(nt + 1, 1);
    uint32_t *queue = st_malloc_array(nt + 1, sizeof *queue);
    uint32_t *region = st_malloc_array(nt + 1, sizeof *region);
    st_status rc = ST_OK;
    if (!nbr || !same || !flip || !queue || !region) {
        rc = oom(err);
        goto done;
    }
    st_soup_edges_neighbours(E, s, nbr, same, NULL);
    size_t nq = 0;
    st_soup_edges_orient(E, s, nbr, same, flip, region, queue, &nq);
    double back[3] = {0.0, 0.0, 0.0}, front[3] = {0.0, 0.0, 0.0};
    double pos[3] = {0.0, 0.0, 0.0}, neg[3] = {0.0, 0.0, 0.0};
    for (size_t i = 0; i < nq; i++) {   /* region by region */
        const uint32_t t = queue[i];
        const uint32_t *v = s->tris + 3 * (size_t)t;
        double u[3], w[3], n[3];
        st_sub3(u, s->xyz + 3 * (size_t)v[1], s->xyz + 3 * (size_t)v[0]);
        st_sub3(w, s->xyz + 3 * (size_t)v[2], s->xyz + 3 * (size_t)v[0]);
        st_cross3(n, u, w);
        for (int k = 0; k < 3; k++) {
            const double a = flip[t] ? -n[k] : n[k];
            if (a > 0.0)
                pos[k] += a;
            else
                neg[k] -= a;
        }
        if (i + 1 == nq || region[queue[i + 1]] != region[t])
            for (int k = 0; k < 3; k++) {
                back[k] += fmin(pos[k], neg[k]);
                front[k] += fmax(pos[k], neg[k]);
                pos[k] = neg[k] = 0.0;
            }
    }
    *ratio = INFINITY;
    for (int k = 0; k < 3; k++)
        if (front[k] > 0.0)
            *ratio = fmin(*ratio, back[k] / front[k]);
done:
    free(nbr);
    free(same);
    free(flip);
    free(queue);
    free(region);
    return rc;
}

/* The k (even, > 2) boundary edges ev at welded vertex v, where holes
 * touch: seen along the mean normal of the triangles around v (their
 * normals' signs aligned with the first: orientation is not read), the
 * triangles cover sectors of directions; a hole passes through v in each
 * gap between two consecutive boundary edges that no triangle covers, and
 * pairs those two edges. Pairs only when the gaps account for every edge
 * exactly once; otherwise (a vertex on a sharp crease, where one plane
 * does not order the fans) the edges are paired by their hole sides
 * (pair_by_sides) or stay unpaired. ST_ENOMEM. */
static st_status pair_by_angle(rim *r, const st_soup *s, const uint32_t *weld, uint32_t v,
                               st_error *err)
{
    const uint32_t *wpos = r->wpos, *be_a = r->a, *be_b = r->b;
    uint32_t *pa = r->pa, *pb = r->pb;
    const uint32_t *ev = r->vlist + r->vstart[v], *tv = r->tlist + r->tstart[v];
    const size_t k = r->vstart[v + 1] - r->vstart[v], nt = r->tstart[v + 1] - r->tstart[v];
    const double *o = s->xyz + 3 * (size_t)wpos[v];
    double nsum[3] = {0, 0, 0}, first[3] = {0, 0, 0};
    for (size_t i = 0; i < nt; i++) {
        const uint32_t *c = s->tris + 3 * (size_t)tv[i];
        double u[3], w[3], n[3];
        st_sub3(u, s->xyz + 3 * (size_t)c[1], s->xyz + 3 * (size_t)c[0]);
        st_sub3(w, s->xyz + 3 * (size_t)c[2], s->xyz + 3 * (size_t)c[0]);
        st_cross3(n, u, w);
        if (i == 0)
            memcpy(first, n, sizeof n);
        const double sg = st_dot3(n, first) >= 0 ? 1.0 : -1.0;
        for (int q = 0; q < 3; q++)
            nsum[q] += sg * n[q];
    }
    const double len = st_norm3(nsum);
    if (!(len > 0))
        return ST_OK;
    double nn[3] = {nsum[0] / len, nsum[1] / len, nsum[2] / len}, ax[3] = {1, 0, 0}, U[3], W[3];
    if (fabs(nn[0]) > 0.9)
        ax[0] = 0, ax[1] = 1;
    st_cross3(U, nn, ax);
    const double lu = st_norm3(U);
    for (int q = 0; q < 3; q++)
        U[q] /= lu;
    st_cross3(W, nn, U);
    double *lo = malloc((nt + 1) * sizeof *lo), *hi = malloc((nt + 1) * sizeof *hi);
    double *ang = malloc(k * sizeof *ang);
    uint32_t *ord = malloc(k * sizeof *ord);
    uint8_t *hit = calloc(k, 1);
    st_status rc = ST_OK;
    if (!lo || !hi || !ang || !ord || !hit) {
        rc = oom(err);
        goto done;
    }
#define ANGLE(p) atan2(((p)[0] - o[0]) * W[0] + ((p)[1] - o[1]) * W[1] + ((p)[2] - o[2]) * W[2], \
                       ((p)[0] - o[0]) * U[0] + ((p)[1] - o[1]) * U[1] + ((p)[2] - o[2]) * U[2])
    for (size_t i = 0; i < nt; i++) {
        const uint32_t *c = s->tris + 3 * (size_t)tv[i];
        double a[2];
        int m = 0;
        for (int q = 0; q < 3 && m < 2; q++)
            if (weld[c[q]] != v)
                a[m++] = ANGLE(s->xyz + 3 * (size_t)c[q]);
        double l = fmin(a[0], a[1]), h = fmax(a[0], a[1]);
        if (h - l > M_PI) {     /* the short way round passes +-pi */
            const double t = l + 2.0 * M_PI;
            l = h;
            h = t;
        }
        lo[i] = l;
        hi[i] = h;
    }
    for (size_t i = 0; i < k; i++) {
        const uint32_t e = ev[i], w = be_a[e] == v ? be_b[e] : be_a[e];
        ang[i] = ANGLE(s->xyz + 3 * (size_t)wpos[w]);
        ord[i] = (uint32_t)i;
    }
#undef ANGLE
    for (size_t i = 1; i < k; i++)      /* insertion sort by angle, k small */
        for (size_t j = i; j > 0 && ang[ord[j]] < ang[ord[j - 1]]; j--) {
            uint32_t x = ord[j];
            ord[j] = ord[j - 1];
            ord[j - 1] = x;
        }
    size_t gaps = 0;
    int ok = 1;
    for (size_t i = 0; i < k && ok; i++) {
        const size_t j = (i + 1) % k;
        const double a = ang[ord[i]], b = ang[ord[j]] + (j == 0 ? 2.0 * M_PI : 0.0);
        if (covered(lo, hi, nt, 0.5 * (a + b)))
            continue;
        if (hit[ord[i]] || hit[ord[j]])
            ok = 0;
        hit[ord[i]] = hit[ord[j]] = 1;
        gaps++;
    }
    if (ok && 2 * gaps == k)
        for (size_t i = 0; i < k; i++) {
            const size_t j = (i + 1) % k;
            const double a = ang[ord[i]], b = ang[ord[j]] + (j == 0 ? 2.0 * M_PI : 0.0);
            if (!covered(lo, hi, nt, 0.5 * (a + b))) {
                set_partner(be_a, pa, pb, ev[ord[i]], v, ev[ord[j]]);
                set_partner(be_a, pa, pb, ev[ord[j]], v, ev[ord[i]]);
            }
        }
    else
        pair_by_sides(r, s, weld, v, ev, k, hit);
done:
    free(lo), free(hi), free(ang), free(ord), free(hit);
    return rc;
}

/* ---- the rim, its loops and their caps --------------------------------- */

static void rim_free(rim *r)
{
    free(r->a), free(r->b), free(r->t), free(r->pa), free(r->pb), free(r->used);
    free(r->vstart), free(r->vlist), free(r->tstart), free(r->tlist), free(r->wpos);
    free(r->piece_area), free(r->stamp);
    memset(r, 0, sizeof *r);
}

/* 2. The pieces' areas, and the boundary edges of E (r->a, b, t, their
 * partners none yet), counted at their ends in bdeg[nweld + 1]. */
static st_status rim_edges(rim *r, const st_soup *s, const st_soup_edges *E, uint32_t *bdeg,
                           st_error *err)
{
    const size_t nt = s->ntris, nh = E->nhalf;
    const st_half_edge *he = E->he;
    r->piece_area = st_calloc_array(nt ? nt : 1, sizeof *r->piece_area);
    if (!r->piece_area)
        return oom(err);
    for (size_t t = 0; t < nt; t++)
        if (E->kept[t]) {
            const uint32_t *v = s->tris + 3 * t;
            const double a = tri_area(s->xyz + 3 * (size_t)v[0], s->xyz + 3 * (size_t)v[1],
                                      s->xyz + 3 * (size_t)v[2]);
            r->piece_area[E->piece[t]] += a;
            r->total += a;
        }
    size_t nb = 0;
    for (size_t i = 0, j; i < nh; i = j) {
        for (j = i + 1; j < nh && he[j].key == he[i].key; j++)
            ;
        nb += j - i == 1;
    }
    r->nb = nb;
    r->a = st_malloc_array(nb ? nb : 1, sizeof *r->a);
    r->b = st_malloc_array(nb ? nb : 1, sizeof *r->b);
    r->t = st_malloc_array(nb ? nb : 1, sizeof *r->t);
    r->pa = st_malloc_array(nb ? nb : 1, sizeof *r->pa);
    r->pb = st_malloc_array(nb ? nb : 1, sizeof *r->pb);
    r->used = st_calloc_array(nb ? nb : 1, 1);
    r->stamp = st_malloc_array(nt ? nt : 1, sizeof *r->stamp);
    if (!r->a || !r->b || !r->t || !r->pa || !r->pb || !r->used || !r->stamp)
        return oom(err);
    for (size_t t = 0; t < nt; t++)
        r->stamp[t] = NONE;
    size_t e = 0;
    for (size_t i = 0, j; i < nh; i = j) {
        for (j = i + 1; j < nh && he[j].key == he[i].key; j++)
            ;
        if (j - i != 1)
            continue;
        const uint32_t a = (uint32_t)(he[i].key >> 32), b = (uint32_t)he[i].key;
        r->a[e] = a;
        r->b[e] = b;
        r->t[e] = he[i].t;
        r->pa[e] = r->pb[e] = NONE;
        bdeg[a]++;
        bdeg[b]++;
        e++;
    }
    return ST_OK;
}

/* The boundary edges at each welded vertex (bdeg: how many), a position
 * for each welded vertex (the first soup vertex welded to it), and the
 * kept triangles at each vertex where holes touch. */
static st_status rim_vertices(rim *r, const st_soup *s, const st_soup_edges *E, uint32_t *bdeg,
                              st_error *err)
{
    const size_t nt = s->ntris, nw = E->nweld, nb = r->nb;
    const uint32_t *weld = E->weld;
    r->vstart = st_calloc_array(nw + 2, sizeof *r->vstart);
    r->vlist = st_malloc_array(2 * nb + 1, sizeof *r->vlist);
    r->tstart = st_calloc_array(nw + 2, sizeof *r->tstart);
    r->wpos = st_malloc_array(nw + 1, sizeof *r->wpos);
    if (!r->vstart || !r->vlist || !r->tstart || !r->wpos)
        return oom(err);
    uint32_t *vstart = r->vstart, *tstart = r->tstart;
    for (size_t v = 0; v < nw; v++)
        vstart[v + 1] = vstart[v] + bdeg[v];
    for (size_t v = 0; v < nw; v++)
        bdeg[v] = 0;
    for (size_t i = 0; i < nb; i++) {
        r->vlist[vstart[r->a[i]] + bdeg[r->a[i]]++] = (uint32_t)i;
        r->vlist[vstart[r->b[i]] + bdeg[r->b[i]]++] = (uint32_t)i;
    }
    for (size_t v = s->nverts; v-- > 0;)
        if (weld[v] != ST_WELD_NONE)
            r->wpos[weld[v]] = (uint32_t)v;
    for (size_t t = 0; t < nt; t++)
        if (E->kept[t])
            for (int c = 0; c < 3; c++) {
                const uint32_t w = weld[s->tris[3 * t + c]];
                if (bdeg[w] > 2)
                    tstart[w + 1]++;
            }
    for (size_t v = 0; v < nw; v++)
        tstart[v + 1] += tstart[v];
    r->tlist = st_malloc_array(tstart[nw] + 1, sizeof *r->tlist);
    size_t *tfill = st_calloc_array(nw + 1, sizeof *tfill);
    if (!r->tlist || !tfill) {
        free(tfill);
        return oom(err);
    }
    for (size_t t = 0; t < nt; t++)
        if (E->kept[t])
            for (int c = 0; c < 3; c++) {
                const uint32_t w = weld[s->tris[3 * t + c]];
                if (vstart[w + 1] - vstart[w] > 2)
                    r->tlist[tstart[w] + tfill[w]++] = (uint32_t)t;
            }
    free(tfill);
    return ST_OK;
}

/* The rim's area: the kept triangles on a boundary edge, each once. */
static void rim_area(rim *r, const st_soup *s)
{
    for (size_t i = 0; i < r->nb; i++) {
        const uint32_t t = r->t[i];
        if (r->stamp[t] == NONE) {
            const uint32_t *v = s->tris + 3 * (size_t)t;
            r->area += tri_area(s->xyz + 3 * (size_t)v[0], s->xyz + 3 * (size_t)v[1],
                                s->xyz + 3 * (size_t)v[2]);
            r->stamp[t] = 0;
        }
    }
    for (size_t i = 0; i < r->nb; i++)
        r->stamp[r->t[i]] = NONE;
}

static st_status rim_build(rim *r, const st_soup *s, const st_soup_edges *E, st_error *err)
{
    uint32_t *bdeg = st_calloc_array(E->nweld + 1, sizeof *bdeg);
    st_status rc = bdeg ? rim_edges(r, s, E, bdeg, err) : oom(err);
    rc = rc ? rc : rim_vertices(r, s, E, bdeg, err);
    if (!rc)
        rim_area(r, s);
    free(bdeg);
    return rc;
}

/* 3. Pair the boundary edges at every vertex: the two of a vertex with
 * two; where holes touch, by the angular gaps between the triangles
 * around it (pair_by_angle), or on a crease by their hole sides
 * (pair_by_sides). */
static st_status rim_pair(rim *r, const st_soup *s, const st_soup_edges *E, st_error *err)
{
    for (size_t v = 0; v < E->nweld; v++) {
        const size_t k = r->vstart[v + 1] - r->vstart[v];
        const uint32_t *ev = r->vlist + r->vstart[v];
        st_status rc;
        if (k == 2) {
            set_partner(r->a, r->pa, r->pb, ev[0], (uint32_t)v, ev[1]);
            set_partner(r->a, r->pa, r->pb, ev[1], (uint32_t)v, ev[0]);
        } else if (k > 2 && !(k & 1) && (rc = pair_by_angle(r, s, E->weld, (uint32_t)v, err)))
            return rc;
    }
    return ST_OK;
}

/* Whether the caps continue the faces (bend, planes): where the rim is
 * more than p->intact of the soup's area (faces deleted at random: most
 * of what is left touches a hole), the fragments' planes and bends say
 * little about the lost surface; a scan seen from one side along an axis
 * (p->onesided) has loops that are the horizon where it turned away, not
 * lost faces of a part (the bent caps would continue its walls past the
 * far side). Else every cap is the least-area one. */
static st_status rim_intact(int *intact, const rim *r, const st_soup *s, const st_soup_edges *E,
                            const st_holes_params *p, st_holes_stats *st, st_error *err)
{
    st->rim_share = r->total > 0.0 ? r->area / r->total : 0.0;
    *intact = r->area <= p->intact * r->total;
    st->one_sided = -1.0;
    if (*intact && (p->bend || p->planes) && p->onesided > 0.0) {
        const st_status rc = axis_one_sided(&st->one_sided, s, E, err);
        if (rc)
            return rc;
        *intact = st->one_sided >= p->onesided;
    }
    return ST_OK;
}

/* One loop of the rim: its welded vertices and boundary edges (n each,
 * in a queue's arrays), their points (a soup vertex welded to each), the
 * third point of the soup's triangle beside each edge, and a
 * triangulation: the working arrays of one thread. */
typedef struct loop {
    size_t n;
    uint32_t *v, *e;            /* n each */
    const double **pts, **side; /* max_loop + 1 each */
    uint32_t *tri;              /* 3 (max_loop + 1) */
    double *crease;             /* 6 (max_loop + 1): st_holes_creases */
} loop;

static st_status loop_alloc(loop *l, size_t max_loop, st_error *err)
{
    l->v = l->e = NULL;
    l->pts = st_malloc_array(max_loop + 1, sizeof *l->pts);
    l->side = st_malloc_array(max_loop + 1, sizeof *l->side);
    l->tri = st_malloc_array(3 * (max_loop + 1), sizeof *l->tri);
    l->crease = st_malloc_array(6 * (max_loop + 1), sizeof *l->crease);
    return l->pts && l->side && l->tri && l->crease ? ST_OK : oom(err);
}

static void loop_free(loop *l)
{
    free(l->pts), free(l->side), free(l->tri), free(l->crease);
}

/* Walks the loop from boundary edge e0 (not used yet) by the partners,
 * marking its edges used, into l->v and l->e (l->n edges; each edge is
 * walked once, so all the loops take at most nb entries). Returns 1 when
 * it closes, 0 when it is pinched (an odd vertex, one not paired, or an
 * edge met twice). */
static int trace_loop(rim *r, size_t e0, loop *l)
{
    size_t n = 0;
    const uint32_t start = r->a[e0];
    uint32_t v = r->b[e0], cur = (uint32_t)e0;
    int closed = 1;
    r->used[e0] = 1;
    l->v[n] = start;
    l->e[n++] = cur;
    for (;;) {
        const uint32_t next = r->a[cur] == v ? r->pa[cur] : r->pb[cur];
        if (next == NONE) {
            closed = 0;
            break;
        }
        if (next == e0 && v == start)
            break;
        if (r->used[next] || n > r->nb) {
            closed = 0;
            break;
        }
        r->used[next] = 1;
        l->v[n] = v;
        l->e[n++] = next;
        cur = next;
        v = r->a[cur] == v ? r->b[cur] : r->a[cur];
    }
    l->n = n;
    return closed;
}

/* Capping the loops of one soup: what cap_loop reads (the soup, its
 * edges, BVH and rim, shared by the threads) and fills (the loop's
 * working arrays, the caps and their counts, one thread's). */
typedef struct capper {
    const st_soup *s;
    const st_soup_edges *E;
    const st_bvh *bvh;
    const st_holes_params *p;
    int bend, planes;           /* how the caps continue the faces */
    rim *r;                     /* read only while the loops are capped */
    loop l;
    st_soup *out;               /* the caps */
    st_holes_stats st;
    int cyl;                    /* the last cap is the cylinder's */
} capper;

/* The loop's points (pts) and, beside each edge, the third point of the
 * soup's triangle on it (side; a kept triangle has one). */
static void loop_points(capper *c, int sides)
{
    const st_soup *s = c->s;
    const uint32_t *weld = c->E->weld;
    loop *l = &c->l;
    for (size_t i = 0; i < l->n; i++) {
        const uint32_t *tv = s->tris + 3 * (size_t)c->r->t[l->e[i]];
        if (!sides) {
            const double *q = NULL;
            for (int k = 0; k < 3; k++)
                if (weld[tv[k]] == l->v[i])
                    q = s->xyz + 3 * (size_t)tv[k];
            l->pts[i] = q;
            continue;
        }
        const uint32_t a = l->v[i], b = l->v[(i + 1) % l->n];
        l->side[i] = l->pts[i];
        for (int k = 0; k < 3; k++)
            if (weld[tv[k]] != a && weld[tv[k]] != b)
                l->side[i] = s->xyz + 3 * (size_t)tv[k];
    }
}

/* The area of the surface around loop e0: the pieces with a triangle
 * whose box meets the loop's box grown by a quarter of its extent each
 * way (the loop's own pieces among them). */
static double around_loop(capper *c, size_t e0)
{
    const double *const *pts = c->l.pts;
    double blo[3], bhi[3], ext = 0.0;
    for (int q = 0; q < 3; q++)
        blo[q] = bhi[q] = pts[0][q];
    for (size_t i = 1; i < c->l.n; i++)
        for (int q = 0; q < 3; q++) {
            blo[q] = fmin(blo[q], pts[i][q]);
            bhi[q] = fmax(bhi[q], pts[i][q]);
        }
    for (int q = 0; q < 3; q++)
        ext = fmax(ext, bhi[q] - blo[q]);
    for (int q = 0; q < 3; q++) {
        blo[q] -= 0.25 * ext;
        bhi[q] += 0.25 * ext;
    }
    around_ctx ac = {c->E->kept, c->E->piece, c->r->stamp, (uint32_t)e0, c->r->piece_area, 0.0};
    st_bvh_query_box(c->bvh, blo, bhi, add_piece, &ac);
    return ac.around;
}

/* The loop's cap rebuilt from the planes along it, appended to the caps
 * with *rebuilt 1 when it continues the faces clearly better than the
 * cap of the loop's own points in l->tri (a flat hole's cap continues
 * them exactly): the cone from one corner or the fans from several,
 * whichever continues them better. */
static st_status cap_planes(capper *c, int *rebuilt, double *bent, st_error *err)
{
    const loop *l = &c->l;
    const size_t n = l->n;
    const double below = CONE_BETTER * rim_bend(l->pts, l->side, n, l->tri, l->crease);
    int coned = 0, fanned = 0;
    double cb, fb = INFINITY;
    st_soup *cone = st_soup_new(), *fans = st_soup_new();
    st_status rc = ST_OK;
    *rebuilt = 0;
    if (!cone || !fans) {
        rc = oom(err);
        goto done;
    }
    const st_holes_guard guard = {c->bvh, c->E->kept, l->crease};
    rc = st_holes_planes_cap(cone, &coned, l->pts, l->side, n, below, &guard, &cb, err);
    if (!rc)
        rc = st_holes_planes_fans(fans, &fanned, l->pts, l->side, n, below,
                                  c->bend ? st_holes_least_bend : fill_area, &guard, &fb, err);
    if (!rc && (coned || fanned))
        rc = st_soup_append(c->out, fanned && (!coned || fb < cb) ? fans : cone, err);
    *rebuilt = !rc && (coned || fanned);
    *bent = fanned && (!coned || fb < cb) ? fb : cb;
done:
    st_soup_free(cone);
    st_soup_free(fans);
    return rc;
}

/* 4. The cap of the closed loop in c->l (3 to max_loop edges; lim: the
 * largest cap, max_cap_ratio times around_loop): by least area, kept if
 * small beside the surface around it (or a flat hole); then with planes
 * rebuilt from the planes along it, else with bend spanned by the least
 * bend. Appended to c->out (c->cyl 1 where it is the cylinder's);
 * counted in c->st. */
static st_status cap_loop(capper *c, double lim, st_error *err)
{
    const st_holes_params *p = c->p;
    loop *l = &c->l;
    const size_t n = l->n;
    c->cyl = 0;
    loop_points(c, 0);
    double cap, bent;
    /* a loop surely too large needs no triangulation (least_area is
     * O(n^3)); else least_area decides, as it always did */
    if (st_holes_area_above(l->pts, n, lim) &&
        !flat_hole(c->s, l->pts, n, c->r->t, l->e, p->flat)) {
        c->st.too_large++;
        return ST_OK;
    }
    st_status rc = st_holes_least_area(&cap, l->pts, n, l->tri, err);
    if (rc)
        return rc;
    if (!(cap > 0.0) || (cap > lim && !flat_hole(c->s, l->pts, n, c->r->t, l->e, p->flat))) {
        c->st.too_large++;
        return ST_OK;
    }
    if (c->bend || c->planes)
        loop_points(c, 1);
    if (c->planes)
        st_holes_creases(l->crease, l->pts, l->side, n);
    if (c->bend && (rc = st_holes_least_bend(&bent, l->pts, l->side, n, l->tri, err)))
        return rc;
    int rebuilt = 0, cyl = 0;
    double rb = INFINITY;
    const size_t vb = c->out->nverts, tb = c->out->ntris;
    if (c->planes && (rc = cap_planes(c, &rebuilt, &rb, err)))
        return rc;
    /* where a cylinder runs along the loop, continued across it when that
     * continues the soup better (holes_cyl.c) */
    const st_holes_guard guard = {c->bvh, c->E->kept, l->crease};
    if (c->planes && (rc = st_holes_cyl_cap(c->out, &cyl, vb, tb, l->pts, l->side, n,
                                            rebuilt ? rb : rim_bend(l->pts, l->side, n, l->tri,
                                                                    l->crease),
                                            c->bend ? st_holes_least_bend : fill_area, &guard, err)))
        return rc;
    if (rebuilt || cyl) {
        c->st.filled++;
        c->st.rebuilt++;
        c->cyl = cyl;
        return ST_OK;
    }
    /* on an intact soup, a cap of the loop's points faired where the
     * surface around it is smooth (holes_fair.c) */
    int faired = 0;
    const st_holes_rimref ref = {c->s, c->E, c->bvh, l->v};
    if (c->bend && (rc = st_holes_fair_cap(c->out, &faired, &ref, l->pts, n, l->tri, err)))
        return rc;
    if (faired) {
        c->st.filled++;
        return ST_OK;
    }
    const size_t base = c->out->nverts;
    for (size_t i = 0; i < n; i++)
        if ((rc = st_soup_add_vertex(c->out, l->pts[i][0], l->pts[i][1], l->pts[i][2], err)))
            return rc;
    for (size_t i = 0; i + 2 < n; i++)
        if ((rc = st_soup_add_triangle(c->out, (uint32_t)(base + l->tri[3 * i]),
                                       (uint32_t)(base + l->tri[3 * i + 1]),
                                       (uint32_t)(base + l->tri[3 * i + 2]), err)))
            return rc;
    c->st.filled++;
    return ST_OK;
}

/* The closed loops to cap (3 to max_loop edges), in the order they were
 * traced: loop k's welded vertices and boundary edges at v + off[k] and
 * e + off[k] (n[k] each) and the largest cap it may take (lim[k]); the
 * order the threads take them in, the longest first (ord: pairs of a
 * loop's length and its index, sorted). */
typedef struct queue {
    size_t nq;
    size_t *off, *n, *ord;
    double *lim;
    uint32_t *v, *e;
} queue;

static st_status queue_alloc(queue *q, size_t nb, st_error *err)
{
    const size_t m = nb + 1;
    q->nq = 0;
    q->off = st_malloc_array(m, sizeof *q->off);
    q->n = st_malloc_array(m, sizeof *q->n);
    q->ord = st_malloc_array(2 * m, sizeof *q->ord);
    q->lim = st_malloc_array(m, sizeof *q->lim);
    q->v = st_malloc_array(m, sizeof *q->v);
    q->e = st_malloc_array(m, sizeof *q->e);
    return q->off && q->n && q->ord && q->lim && q->v && q->e ? ST_OK : oom(err);
}

static void queue_free(queue *q)
{
    free(q->off), free(q->n), free(q->ord), free(q->lim), free(q->v), free(q->e);
}

/* The longer loop first, then the one traced first. */
static int longer_first(const void *a, const void *b)
{
    const size_t *x = a, *y = b;
    return x[0] != y[0] ? (x[0] < y[0] ? 1 : -1) : (x[1] > y[1]) - (x[1] < y[1]);
}

/* 3. Walks the rim's loops (from each boundary edge not walked yet, in
 * order) into q: the closed ones of 3 to max_loop edges, each with the
 * largest cap it may take (max_cap_ratio times the surface around it,
 * around_loop, whose stamps are the rim's: here, on one thread); the
 * others counted in c->st. */
static void trace_loops(capper *c, queue *q)
{
    rim *r = c->r;
    size_t pos = 0;
    for (size_t e0 = 0; e0 < r->nb; e0++) {
        if (r->used[e0])
            continue;
        c->l.v = q->v + pos;
        c->l.e = q->e + pos;
        if (!trace_loop(r, e0, &c->l)) {
            c->st.pinched += c->l.n;
            continue;
        }
        c->st.loops++;
        const size_t n = c->l.n;
        if (n < 3)
            continue;
        if (n > c->p->max_loop) {
            c->st.too_long++;
            continue;
        }
        loop_points(c, 0);
        q->off[q->nq] = pos;
        q->n[q->nq] = n;
        q->lim[q->nq] = c->p->max_cap_ratio * around_loop(c, e0);
        q->ord[2 * q->nq] = n;
        q->ord[2 * q->nq + 1] = q->nq;
        q->nq++;
        pos += n;
    }
    qsort(q->ord, q->nq, 2 * sizeof *q->ord, longer_first);
}

/* Loop k of q in c->l. */
static void loop_of(capper *c, const queue *q, size_t k)
{
    c->l.v = q->v + q->off[k];
    c->l.e = q->e + q->off[k];
    c->l.n = q->n[k];
}

/* One loop's cap as a thread made it: its triangles (NULL: none), its
 * counts, and whether it is the cylinder's (made without the caps before
 * it, which it must not pierce: merge_caps tests that). */
typedef struct loop_cap {
    st_soup *cap;
    size_t too_large, filled, rebuilt;
    int cyl;
} loop_cap;

/* The first failure in loop order: its loop (SIZE_MAX: none), status
 * and error. */
typedef struct first_fail {
    size_t k;
    st_status rc;
    st_error err;
} first_fail;

/* Loop k of q capped by w (one thread's capper, its own loop arrays) into
 * a soup of its own, res. */
static st_status cap_one(capper *w, const queue *q, size_t k, loop_cap *res, st_error *err)
{
    loop_of(w, q, k);
    memset(&w->st, 0, sizeof w->st);
    st_status rc = (w->out = st_soup_new()) ? cap_loop(w, q->lim[k], err) : oom(err);
    res->too_large = w->st.too_large;
    res->filled = w->st.filled;
    res->rebuilt = w->st.rebuilt;
    res->cyl = w->cyl;
    if (rc || !w->out->ntris) {
        st_soup_free(w->out);
        w->out = NULL;
    }
    res->cap = w->out;
    w->out = NULL;
    return rc;
}

static int thread_num(void)
{
#ifdef _OPENMP
    return omp_get_thread_num();
#else
    return 0;
#endif
}

/* 4. Every loop of q capped (cap_one) into res[k], by the threads, the
 * longest loops first (a loop's cap reads the soup, its edges, BVH and
 * rim, and writes only its own arrays, ls[thread], and soup); the first
 * failure in loop order into *f (a loop after one that failed is not
 * capped). */
static void cap_loops(const capper *c, const queue *q, const loop *ls, loop_cap *res,
                      first_fail *f)
{
    f->k = SIZE_MAX;
    #pragma omp parallel if (q->nq > 1)
    {
        capper w = *c;
        w.l = ls[thread_num()];
        st_error e;
        #pragma omp for schedule(dynamic, 1)
        for (size_t j = 0; j < q->nq; j++) {
            const size_t k = q->ord[2 * j + 1];
            size_t fk;
            #pragma omp atomic read
            fk = f->k;
            if (k > fk)
                continue;
            const st_status rc = cap_one(&w, q, k, res + k, &e);
            if (rc) {
                #pragma omp critical(holes_first_fail)
                if (k < f->k) {
                    f->rc = rc;
                    f->err = e;
                    #pragma omp atomic write
                    f->k = k;
                }
            }
        }
    }
}

/* The loops' caps (res) appended to c->out in loop order, their counts
 * to c->st: the caps are those the loops capped one after another make.
 * A cylinder's cap (holes_cyl.c) may not pierce the caps before it: one
 * that does is made again here against them, as cap_loop makes it then
 * (the cylinder then not taken; a cylinder's cap that pierces none is the
 * same either way, the test the only part that reads them). Stops at f's
 * failure, and returns it. */
static st_status merge_caps(capper *c, const queue *q, const loop_cap *res, const first_fail *f,
                            st_error *err)
{
    for (size_t k = 0; k < q->nq; k++) {
        if (k == f->k) {
            if (err)
                *err = f->err;
            return f->rc;
        }
        const loop_cap *r = res + k;
        st_status rc = ST_OK;
        if (r->cyl && st_holes_caps_cross(c->out, r->cap)) {
            loop_of(c, q, k);
            rc = cap_loop(c, q->lim[k], err);
        } else {
            c->st.too_large += r->too_large;
            c->st.filled += r->filled;
            c->st.rebuilt += r->rebuilt;
            if (r->cap)
                rc = st_soup_append(c->out, r->cap, err);
        }
        if (rc)
            return rc;
    }
    return ST_OK;
}

/* 4. The caps of q's loops into c->out: made by the threads (cap_loops),
 * each with its own loop arrays, appended in loop order (merge_caps):
 * the same caps for any number of threads. */
static st_status cap_all(capper *c, const queue *q, st_error *err)
{
#ifdef _OPENMP
    const size_t nth = q->nq > 1 ? (size_t)omp_get_max_threads() : 1;
#else
    const size_t nth = 1;
#endif
    loop *ls = st_calloc_array(nth, sizeof *ls);
    loop_cap *res = st_calloc_array(q->nq + 1, sizeof *res);
    first_fail f;
    st_status rc = ls && res ? ST_OK : oom(err);
    for (size_t t = 0; t < nth && !rc; t++)
        rc = loop_alloc(ls + t, c->p->max_loop, err);
    if (!rc) {
        cap_loops(c, q, ls, res, &f);
        rc = merge_caps(c, q, res, &f, err);
    }
    for (size_t t = 0; ls && t < nth; t++)
        loop_free(ls + t);
    for (size_t k = 0; res && k < q->nq; k++)
        st_soup_free(res[k].cap);
    free(ls);
    free(res);
    return rc;
}

st_status st_soup_hole_caps(st_soup **caps, const st_soup *s,
                            const st_holes_params *p, st_holes_stats *stats,
                            st_error *err)
{
    return st_soup_hole_caps_shared(caps, s, NULL, NULL, p, stats, err);
}

st_status st_soup_hole_caps_shared(st_soup **caps, const st_soup *s,
                                   const st_soup_edges *edges, const st_bvh *shared_bvh,
                                   const st_holes_params *p, st_holes_stats *stats,
                                   st_error *err)
{
    *caps = NULL;
    if (s->ntris > (size_t)INT32_MAX)
        return st_error_set(err, ST_ELIMIT, NULL, 0,
                            "%zu triangles: hole filling handles at most 2^31", s->ntris);
    if (p->max_loop > 4096 || !(p->max_cap_ratio >= 0))
        return st_error_set(err, ST_EINPUT, NULL, 0,
                            "hole filling: loops of at most 4096 edges, a cap ratio >= 0");
    /* 1. the edges and pieces (the caller's, else built here) */
    st_soup_edges own_edges;
    st_status rc = edges ? ST_OK : st_soup_edges_build(&own_edges, s, err);
    if (rc)
        return rc;
    capper c;
    memset(&c, 0, sizeof c);
    rim r;
    memset(&r, 0, sizeof r);
    queue q;
    memset(&q, 0, sizeof q);
    c.s = s;
    c.E = edges ? edges : &own_edges;
    c.bvh = shared_bvh;
    c.p = p;
    c.r = &r;
    st_bvh *own_bvh = NULL;
    int intact = 0;
    if (!(c.out = st_soup_new())) {
        rc = oom(err);
        goto done;
    }
    if (!c.bvh && (rc = st_bvh_build(&own_bvh, s, err)))
        goto done;
    c.bvh = c.bvh ? c.bvh : own_bvh;
    /* 2, 3. the rim, its pairs and loops; 4. their caps */
    if ((rc = rim_build(&r, s, c.E, err)) || (rc = loop_alloc(&c.l, p->max_loop, err)))
        goto done;
    c.st.boundary_edges = r.nb;
    if ((rc = rim_intact(&intact, &r, s, c.E, p, &c.st, err)))
        goto done;
    c.bend = p->bend && intact;
    c.planes = p->planes && intact;
    c.st.continued = c.bend || c.planes;
    if ((rc = rim_pair(&r, s, c.E, err)) || (rc = queue_alloc(&q, r.nb, err)))
        goto done;
    trace_loops(&c, &q);
    rc = cap_all(&c, &q, err);
done:
    if (!edges)
        st_soup_edges_free(&own_edges);
    st_bvh_free(own_bvh);
    rim_free(&r);
    loop_free(&c.l);
    queue_free(&q);
    if (rc) {
        st_soup_free(c.out);
        return rc;
    }
    if (stats)
        *stats = c.st;
    *caps = c.out;
    return ST_OK;
}
