/*
 * holes_planes.c - a hole's cap from a corner rebuilt from the planes
 * around it (holes_internal.h; issue 17, the large holes of CAD parts).
 * Design notes and measurements: doc/design/holes.md.
 *
 * A CAD part's large hole takes whole faces and the corners where they
 * met: a cap over the loop's own points cannot bring a lost corner back.
 * The faces along the loop still carry their planes (those of the soup's
 * triangles on its edges), and extended into the hole three of them meet
 * at the lost corner, two along the lost edge. The cone from such a point
 * over the loop (a triangle on each loop edge, all meeting there) lies in
 * the planes where the loop runs over one face each: a box's lost corner
 * comes back whole, a lost edge as its two faces.
 *
 * The apexes tried: the point where three of the planes meet, and the
 * point of the line where two meet nearest the loop's centroid, within
 * the loop's box grown by REACH of its extent; of the planes, once each
 * (SAME), at most MAX_PLANES, those along most of the loop. A cone is
 * measured by how well it continues the faces along the loop: the sum
 * over the loop's edges of length times the dihedral angle between its
 * triangle there and the soup's (as the caps that bend least are
 * measured in holes.c, their spokes left out: a lost corner's creases are
 * no fault). The cone that continues them best (ties by the bend of its
 * spokes too) is the cap when it does better than the caller's bound
 * (the cap of the loop's own points, which chamfers a lost corner: a
 * box's bends along all its loop by 55 degrees, the corner's cone by 0)
 * and none of its triangles pierces the surviving soup (st_tri_tri_cross
 * on the BVH; touching it, as at a crease along the loop, is allowed): a
 * point where far planes meet sends cones through the part. Of the
 * cones below the bound, the least bent that pierces nothing.
 *
 * A large hole spans several corners (a lost edge and both its ends, a
 * wing of a part): no one point continues all of its loop.
 * st_holes_planes_fans takes the point that continues the most of it
 * exactly (its triangle over an edge within FAN_FLAT of the soup's
 * plane there, on the hole's side, its fan piercing none of the soup),
 * fans from it over the edges it continues, and replaces each run of
 * them by the point; the loop left (split into several where it meets
 * the point more than once) is capped the same way, and one that no
 * point continues along two edges by the caller's triangulation of its
 * own points. That is done three ways: with the apexes as placed, and
 * with those a chain would place along one line merged into one, two
 * ways (MERGE); the fans that bend least along the loop are kept. The
 * caller keeps the fans or the single cone, whichever continues the soup
 * along the loop better. Where a loop edge runs along a crease (the
 * soup's triangle there is one face, and both its ends lie on the plane
 * of another face along the loop: a tunnel's mouth whose face around it
 * was lost), a cap that continues that other face bends nowhere there
 * (st_holes_creases, st_holes_crease_bend; doc/design/holes.md,
 * "Creases"). The fans' triangulations of a loop's own points
 * are not tested for piercing; that, the piercing test's cost and the
 * variants not kept are measured in doc/design/holes.md.
 */
#include "holes_internal.h"
#include "../base/fpenv.h"
#include "souptet/geom.h"
#include "souptet/isect.h"
#include "souptet/pred.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#ifdef HOLES_AVX
#include <immintrin.h>
#elif defined(__SSE2__)
#include <emmintrin.h>
#endif

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

/* Apexes within the loop's box grown by REACH times its extent each way:
 * a lost corner lies near the loop's box (a box's lost corner at a corner
 * of it), a point where nearly parallel planes meet far beyond (other
 * boxes tried: doc/design/holes.md, "REACH"). */
#define REACH 0.75
/* Planes whose offsets and normals differ by less than SAME (relative to
 * the loop's extent) are one face's (its triangles' rounding). */
#define SAME 1e-9
/* Triples of planes meeting at a point: |det| of their unit normals above
 * MIN_DET (three planes within about 6 degrees of a common line meet far
 * off or nowhere). */
#define MIN_DET 1e-2
/* The apexes from at most MAX_PLANES planes (MAX_PLANES^3 / 6 triples,
 * each cone measured over the loop): a curved face along the loop has a
 * plane on each edge; the planes along most of the loop are kept. */
#define MAX_PLANES 24

/* "out of memory" where the holes' scratch is allocated. */
static st_status oom(st_error *err)
{
    return st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory for the holes");
}

typedef struct plane {
    double n[3], d;     /* unit normal, n . x = d */
    double len;         /* the length of the loop edges on it */
} plane;

/* 1 when a loop edge runs along a crease (its two normals from
 * st_holes_creases, cr[6]): its bend may then be 0. */
static int on_crease(const double *cr)
{
    return st_dot3(cr, cr) != 0.0;
}

/* 1 when d lies on the plane through t[0], t[1], t[2] (exact). */
static int on_plane(const double *const *t, const double *d)
{
    return st_orient3d(t[0], t[1], t[2], d) == 0.0;
}

void st_holes_creases(double *crease, const double *const *pts, const double *const *side,
                      size_t n)
{
    memset(crease, 0, 6 * n * sizeof *crease);
    for (size_t i = 0; i < n; i++) {
        const double *p = pts[i], *q = pts[(i + 1) % n];
        const double *held[2][3];
        int got = 0;
        for (size_t j = 0; j < n && got < 2; j++) {
            const double *t[3] = {pts[j], side[j], pts[(j + 1) % n]};
            double nn[3];
            unit_normal(nn, t[0], t[1], t[2]);
            if (j == i || st_dot3(nn, nn) == 0.0 || !on_plane(t, p) || !on_plane(t, q) ||
                on_plane(t, side[i]))
                continue;
            int same = 0;
            for (int k = 0; k < got && !same; k++)
                same = on_plane(held[k], t[0]) && on_plane(held[k], t[1]) &&
                       on_plane(held[k], t[2]);
            if (same)
                continue;
            memcpy(crease + 6 * i + 3 * got, nn, sizeof nn);
            memcpy(held[got], t, sizeof t);
            got++;
        }
    }
}

void st_holes_cone_rim_fill(st_holes_cone_rim *cr, const double *const *pts, const double *rim,
                            const double *crease, size_t n)
{
    for (size_t i = 0; i <= n; i++)
        for (int c = 0; c < 3; c++)
            cr->p[(size_t)c * (n + 1) + i] = pts[i < n ? i : 0][c];
    for (size_t i = 0; i < n; i++) {
        for (int c = 0; c < 3; c++)
            cr->r[(size_t)c * n + i] = rim[3 * i + c];
        /* all bits set where the edge counts (an SSE2 mask), else 0 */
        const uint64_t all = crease && on_crease(crease + 6 * i) ? 0 : UINT64_MAX;
        memcpy(cr->mask + i, &all, sizeof all);
    }
}

/* One edge's part of st_holes_cone_above into *lb and *len (the sums so
 * far): -1 when its length is out of range (unsure), 1 when the sums
 * reach below, else 0. */
static int cone_term(double *lb, double *len, double ee, double l, double term, int counts,
                     double below)
{
    if (!(ee > 1e-200 && ee < 1e200))
        return -1;
    *len += l;
    if (counts)
        *lb += term;
    return *lb * (1.0 - 1e-10) - 1e-12 * *len >= below;
}

/* 1 when the cone from apex bends surely no less than below along the
 * loop (cone_bend would say 0), from a lower bound of each term taken
 * without the arc tangent and the scaled norms: the sine of the angle
 * between the cone's unscaled normal u and the soup's r (|u x r| / |u|,
 * where u . r > 0; a right angle where not) is at most the angle, which
 * bend() rounds to within a few units in the last place (as the lengths
 * and sums): the margins, a relative 1e-10 and 1e-12 times the loop's
 * length in radians, are far beyond those. 0 when unsure. The terms two
 * edges at a time (SSE2: each lane the scalar operations in the same
 * order), summed one by one in order as before (cone_term; there
 * the terms that do not count add 0). */
#ifdef HOLES_AVX
/* st_holes_cone_above's terms four edges at a time (AVX) from the first,
 * summed one by one in order into *lb and *len: 1 as soon as they reach
 * below, else 0 with *i where it stopped (a multiple of four: before
 * four with an edge out of range, or with fewer than four left). */
static HOLES_AVX_FN int cone_above4(const double *apex, const st_holes_cone_rim *cr, size_t n,
                                    double below, double *lb, double *len, size_t *i)
{
    const double *px = cr->p, *py = cr->p + n + 1, *pz = cr->p + 2 * (n + 1);
    const double *rx = cr->r, *ry = cr->r + n, *rz = cr->r + 2 * n;
    const __m256d ax = _mm256_set1_pd(apex[0]), ay = _mm256_set1_pd(apex[1]);
    const __m256d az = _mm256_set1_pd(apex[2]);
    const __m256d tiny = _mm256_set1_pd(1e-200), huge = _mm256_set1_pd(1e200);
    const __m256d right = _mm256_set1_pd(0.5 * M_PI), zero = _mm256_setzero_pd();
    size_t q = 0;
    for (; q + 3 < n; q += 4) {
#define L_(a) _mm256_loadu_pd(a)
#define M_(a, b) _mm256_mul_pd(a, b)
#define S_(a, b) _mm256_sub_pd(a, b)
#define A_(a, b) _mm256_add_pd(a, b)
        const __m256d p0 = L_(px + q), p1 = L_(py + q), p2 = L_(pz + q);
        const __m256d e0 = S_(L_(px + q + 1), p0), e1 = S_(L_(py + q + 1), p1);
        const __m256d e2 = S_(L_(pz + q + 1), p2);
        const __m256d f0 = S_(ax, p0), f1 = S_(ay, p1), f2 = S_(az, p2);
        const __m256d u0 = S_(M_(e1, f2), M_(e2, f1)), u1 = S_(M_(e2, f0), M_(e0, f2));
        const __m256d u2 = S_(M_(e0, f1), M_(e1, f0));
        const __m256d r0 = L_(rx + q), r1 = L_(ry + q), r2 = L_(rz + q);
        const __m256d x0 = S_(M_(u1, r2), M_(u2, r1)), x1 = S_(M_(u2, r0), M_(u0, r2));
        const __m256d x2 = S_(M_(u0, r1), M_(u1, r0));
        const __m256d ee = A_(A_(M_(e0, e0), M_(e1, e1)), M_(e2, e2));
        const __m256d uu = A_(A_(M_(u0, u0), M_(u1, u1)), M_(u2, u2));
        const __m256d d = A_(A_(M_(u0, r0), M_(u1, r1)), M_(u2, r2));
        const __m256d xx = A_(A_(M_(x0, x0), M_(x1, x1)), M_(x2, x2));
#undef L_
#undef M_
#undef S_
#undef A_
        const __m256d l = _mm256_sqrt_pd(ee), pos = _mm256_cmp_pd(d, zero, _CMP_GT_OS);
        const __m256d sn = _mm256_sqrt_pd(_mm256_div_pd(xx, uu));
        const __m256d uu_in = _mm256_and_pd(_mm256_cmp_pd(uu, tiny, _CMP_GT_OS),
                                            _mm256_cmp_pd(uu, huge, _CMP_LT_OS));
        const __m256d counts = _mm256_and_pd(uu_in, _mm256_loadu_pd(cr->mask + q));
        const __m256d t = _mm256_and_pd(
            counts, _mm256_mul_pd(l, _mm256_blendv_pd(right, sn, pos)));
        if (_mm256_movemask_pd(_mm256_and_pd(_mm256_cmp_pd(ee, tiny, _CMP_GT_OS),
                                             _mm256_cmp_pd(ee, huge, _CMP_LT_OS))) != 15)
            break;      /* an edge out of range: the scalar loop says where */
        double ls[4], ts[4];
        _mm256_storeu_pd(ls, l);
        _mm256_storeu_pd(ts, t);
        for (int k = 0; k < 4; k++) {
            *len += ls[k];
            *lb += ts[k];
            if (*lb * (1.0 - 1e-10) - 1e-12 * *len >= below)
                return 1;
        }
    }
    *i = q;
    return 0;
}
#endif

int st_holes_cone_above(const double *apex, const st_holes_cone_rim *cr, size_t n, double below)
{
    const double *px = cr->p, *py = cr->p + n + 1, *pz = cr->p + 2 * (n + 1);
    const double *rx = cr->r, *ry = cr->r + n, *rz = cr->r + 2 * n;
    double lb = 0.0, len = 0.0;
    size_t i = 0;
#ifdef HOLES_AVX
    if (n >= 4 && holes_avx() && cone_above4(apex, cr, n, below, &lb, &len, &i))
        return 1;
#endif
#ifdef __SSE2__
    const __m128d ax = _mm_set1_pd(apex[0]), ay = _mm_set1_pd(apex[1]), az = _mm_set1_pd(apex[2]);
    const __m128d tiny = _mm_set1_pd(1e-200), huge = _mm_set1_pd(1e200);
    const __m128d right = _mm_set1_pd(0.5 * M_PI), zero = _mm_setzero_pd();
    _Static_assert(sizeof(double) == sizeof(uint64_t), "a mask per double");
    for (; i + 1 < n; i += 2) {
        const __m128d p0 = _mm_loadu_pd(px + i), p1 = _mm_loadu_pd(py + i);
        const __m128d p2 = _mm_loadu_pd(pz + i);
        const __m128d e0 = _mm_sub_pd(_mm_loadu_pd(px + i + 1), p0);
        const __m128d e1 = _mm_sub_pd(_mm_loadu_pd(py + i + 1), p1);
        const __m128d e2 = _mm_sub_pd(_mm_loadu_pd(pz + i + 1), p2);
        const __m128d f0 = _mm_sub_pd(ax, p0), f1 = _mm_sub_pd(ay, p1), f2 = _mm_sub_pd(az, p2);
        const __m128d u0 = _mm_sub_pd(_mm_mul_pd(e1, f2), _mm_mul_pd(e2, f1));
        const __m128d u1 = _mm_sub_pd(_mm_mul_pd(e2, f0), _mm_mul_pd(e0, f2));
        const __m128d u2 = _mm_sub_pd(_mm_mul_pd(e0, f1), _mm_mul_pd(e1, f0));
        const __m128d r0 = _mm_loadu_pd(rx + i), r1 = _mm_loadu_pd(ry + i);
        const __m128d r2 = _mm_loadu_pd(rz + i);
        const __m128d x0 = _mm_sub_pd(_mm_mul_pd(u1, r2), _mm_mul_pd(u2, r1));
        const __m128d x1 = _mm_sub_pd(_mm_mul_pd(u2, r0), _mm_mul_pd(u0, r2));
        const __m128d x2 = _mm_sub_pd(_mm_mul_pd(u0, r1), _mm_mul_pd(u1, r0));
        const __m128d ee = _mm_add_pd(_mm_add_pd(_mm_mul_pd(e0, e0), _mm_mul_pd(e1, e1)),
                                      _mm_mul_pd(e2, e2));
        const __m128d uu = _mm_add_pd(_mm_add_pd(_mm_mul_pd(u0, u0), _mm_mul_pd(u1, u1)),
                                      _mm_mul_pd(u2, u2));
        const __m128d d = _mm_add_pd(_mm_add_pd(_mm_mul_pd(u0, r0), _mm_mul_pd(u1, r1)),
                                     _mm_mul_pd(u2, r2));
        const __m128d xx = _mm_add_pd(_mm_add_pd(_mm_mul_pd(x0, x0), _mm_mul_pd(x1, x1)),
                                      _mm_mul_pd(x2, x2));
        const __m128d l = _mm_sqrt_pd(ee), pos = _mm_cmpgt_pd(d, zero);
        const __m128d sn = _mm_sqrt_pd(_mm_div_pd(xx, uu));
        /* the term where it counts, else 0 (lb + 0 is lb: lb is never -0) */
        const __m128d uu_in = _mm_and_pd(_mm_cmpgt_pd(uu, tiny), _mm_cmplt_pd(uu, huge));
        const __m128d counts = _mm_and_pd(uu_in, _mm_loadu_pd(cr->mask + i));
        const __m128d t = _mm_and_pd(
            counts, _mm_mul_pd(l, _mm_or_pd(_mm_and_pd(pos, sn), _mm_andnot_pd(pos, right))));
        if (_mm_movemask_pd(_mm_and_pd(_mm_cmpgt_pd(ee, tiny), _mm_cmplt_pd(ee, huge))) != 3)
            break;      /* an edge out of range: the scalar loop says where */
        len += _mm_cvtsd_f64(l);
        lb += _mm_cvtsd_f64(t);
        if (lb * (1.0 - 1e-10) - 1e-12 * len >= below)
            return 1;
        len += _mm_cvtsd_f64(_mm_unpackhi_pd(l, l));
        lb += _mm_cvtsd_f64(_mm_unpackhi_pd(t, t));
        if (lb * (1.0 - 1e-10) - 1e-12 * len >= below)
            return 1;
    }
#endif
    for (; i < n; i++) {
        const double e[3] = {px[i + 1] - px[i], py[i + 1] - py[i], pz[i + 1] - pz[i]};
        const double f[3] = {apex[0] - px[i], apex[1] - py[i], apex[2] - pz[i]};
        const double r[3] = {rx[i], ry[i], rz[i]};
        double u[3], x[3];
        st_cross3(u, e, f);
        st_cross3(x, u, r);
        const double ee = st_dot3(e, e), uu = st_dot3(u, u), d = st_dot3(u, r);
        const double l = sqrt(ee);
        /* the mask's bits all set read as a NaN: unequal to 0 */
        const int counts = uu > 1e-200 && uu < 1e200 && cr->mask[i] != 0.0;
        const int res = cone_term(&lb, &len, ee, l,
                                  counts ? l * (d > 0.0 ? sqrt(st_dot3(x, x) / uu) : 0.5 * M_PI)
                                         : 0.0,
                                  counts, below);
        if (res)
            return res > 0;
    }
    return 0;
}

/* The cone from apex over the loop, when it bends less than below along
 * the loop: 1, its total bend in *total (length times dihedral over its
 * edges; rim[i]: the unit normal of the soup's triangle on loop edge i,
 * which passes it the other way from the cone) and in *rimb that over the
 * loop's edges only; tn[3 n] is scratch. 0 as soon as the loop's edges
 * alone reach below: the terms are never negative, so the sum, taken in
 * the same order, could only grow (a NaN stays one and fails the test
 * too). */
static int cone_bend(const double *apex, const double *const *pts, const double *rim, size_t n,
                     const double *crease, double below, double *tn, double *total,
                     double *rimb)
{
    double b = 0.0;
    for (size_t i = 0; i < n; i++) {
        const double *p = pts[i], *q = pts[(i + 1) % n];
        unit_normal(tn + 3 * i, p, q, apex);
        b += dist3(p, q) * st_holes_crease_bend(tn + 3 * i, rim + 3 * i,
                                                crease ? crease + 6 * i : NULL);
        if (!(b < below))
            return 0;
    }
    *rimb = b;
    for (size_t i = 0; i < n; i++)
        b += dist3(apex, pts[(i + 1) % n]) * bend(tn + 3 * i, tn + 3 * ((i + 1) % n));
    *total = b;
    return 1;
}

/* Solves the 3x3 system rows . x = rhs (Cramer); 0 when |det| < MIN_DET
 * (unit rows). */
static int meet3(double *x, const plane *a, const plane *b, const plane *c)
{
    double bc[3], ca[3], ab[3];
    st_cross3(bc, b->n, c->n);
    st_cross3(ca, c->n, a->n);
    st_cross3(ab, a->n, b->n);
    const double det = st_dot3(a->n, bc);
    if (!(fabs(det) >= MIN_DET))
        return 0;
    for (int k = 0; k < 3; k++)
        x[k] = (a->d * bc[k] + b->d * ca[k] + c->d * ab[k]) / det;
    return 1;
}

/* The point of the line where a and b meet nearest o; 0 when they are
 * nearly parallel. */
static int meet2(double *x, const plane *a, const plane *b, const double *o)
{
    double t[3];
    st_cross3(t, a->n, b->n);
    const double tl = st_dot3(t, t);
    if (!(tl >= MIN_DET * MIN_DET))
        return 0;
    /* the third plane: through o, across the line */
    plane c;
    const double l = sqrt(tl);
    for (int k = 0; k < 3; k++)
        c.n[k] = t[k] / l;
    c.d = st_dot3(c.n, o);
    return meet3(x, a, b, &c);
}

/* The loop's box grown by REACH times its extent each way (lo, hi), its
 * centroid o and its extent. */
static void reach_box(double *lo, double *hi, double *o, double *ext, const double *const *pts,
                      size_t n)
{
    *ext = 0.0;
    for (int k = 0; k < 3; k++)
        lo[k] = hi[k] = pts[0][k], o[k] = 0.0;
    for (size_t i = 0; i < n; i++)
        for (int k = 0; k < 3; k++) {
            lo[k] = fmin(lo[k], pts[i][k]);
            hi[k] = fmax(hi[k], pts[i][k]);
            o[k] += pts[i][k] / (double)n;
        }
    for (int k = 0; k < 3; k++)
        *ext = fmax(*ext, hi[k] - lo[k]);
    for (int k = 0; k < 3; k++) {
        lo[k] -= REACH * *ext;
        hi[k] += REACH * *ext;
    }
}

/* The planes of the soup's triangles along the loop, once each (either
 * orientation), the MAX_PLANES with the most loop length on them first
 * (ties by order along the loop); rim[3 n] gets each loop edge's unit
 * normal. Returns how many (pl holds n). */
static size_t loop_planes(plane *pl, double *rim, const double *const *pts,
                          const double *const *side, size_t n, double ext)
{
    size_t m = 0;
    for (size_t i = 0; i < n; i++) {
        unit_normal(rim + 3 * i, pts[i], side[i], pts[(i + 1) % n]);
        const double *nn = rim + 3 * i;
        if (st_dot3(nn, nn) == 0.0)
            continue;
        const double d = st_dot3(nn, pts[i]), len = dist3(pts[i], pts[(i + 1) % n]);
        size_t j = 0;
        for (; j < m; j++) {
            const double sg = st_dot3(nn, pl[j].n) < 0.0 ? -1.0 : 1.0;
            double dn = 0.0;
            for (int k = 0; k < 3; k++)
                dn += fabs(sg * nn[k] - pl[j].n[k]);
            if (dn <= SAME && fabs(sg * d - pl[j].d) <= SAME * ext)
                break;
        }
        if (j < m) {
            pl[j].len += len;
            continue;
        }
        memcpy(pl[m].n, nn, sizeof pl[m].n);
        pl[m].d = d;
        pl[m].len = len;
        m++;
    }
    for (size_t i = 1; i < m; i++)      /* insertion sort */
        for (size_t j = i; j > 0 && pl[j].len > pl[j - 1].len; j--) {
            plane t = pl[j];
            pl[j] = pl[j - 1];
            pl[j - 1] = t;
        }
    return m > MAX_PLANES ? MAX_PLANES : m;
}

/* 1 when triangle (a, b, apex) pierces a kept triangle of guard's soup
 * (st_tri_tri_cross: touching it, along the loop or at a crease, is no
 * crossing). */
typedef struct cross_ctx {
    const st_holes_guard *g;
    const double *t[3];
} cross_ctx;

static int cross_visit(void *ctx, uint32_t tri)
{
    const cross_ctx *c = ctx;
    if (!c->g->kept[tri])
        return 0;
    const st_soup *s = c->g->bvh->soup;
    const uint32_t *v = s->tris + 3 * (size_t)tri;
    return st_tri_tri_cross(c->t[0], c->t[1], c->t[2], s->xyz + 3 * (size_t)v[0],
                            s->xyz + 3 * (size_t)v[1], s->xyz + 3 * (size_t)v[2]);
}

static int crosses(const st_holes_guard *g, const double *a, const double *b, const double *apex)
{
    if (!g || !g->bvh)
        return 0;
    cross_ctx c = {g, {a, b, apex}};
    return st_bvh_query_tri(g->bvh, a, b, apex, cross_visit, &c);
}

/* An apex tried: its point, the planes it is made of (indices into the
 * loop's planes), its score (key, then tie: least first) and whether it
 * was taken up. */
typedef struct cand {
    double x[3], key, tie;
    size_t a, b, c;
    int done;
} cand;

/* At most this many apexes per loop: triples and pairs of MAX_PLANES. */
#define MAX_CAND (MAX_PLANES * MAX_PLANES * MAX_PLANES / 6 + MAX_PLANES * MAX_PLANES)

/* The candidate not taken up yet of least (key, tie), the first of equal
 * ones; NULL when none is left. */
static cand *least_cand(cand *cs, size_t nc)
{
    cand *b = NULL;
    for (size_t i = 0; i < nc; i++)
        if (!cs[i].done &&
            (!b || cs[i].key < b->key || (cs[i].key == b->key && cs[i].tie < b->tie)))
            b = cs + i;
    return b;
}

/* The apex where planes a, b and c meet (c == b: the point of the line of
 * a and b nearest o), when they meet within [lo, hi]. */
static int candidate(double *x, const plane *pl, size_t a, size_t b, size_t c, const double *o,
                     const double *lo, const double *hi)
{
    if (!(c == b ? meet2(x, &pl[a], &pl[b], o) : meet3(x, &pl[a], &pl[b], &pl[c])))
        return 0;
    int inside = 1;
    for (int k = 0; k < 3; k++)
        inside &= x[k] >= lo[k] && x[k] <= hi[k];
    return inside;
}

st_status st_holes_planes_cap(st_soup *out, int *done, const double *const *pts,
                              const double *const *side, size_t n, double below,
                              const st_holes_guard *guard, double *bent, st_error *err)
{
    *done = 0;
    *bent = INFINITY;
    double *rim = malloc(3 * n * sizeof *rim), *tn = malloc(3 * n * sizeof *tn);
    plane *pl = malloc(n * sizeof *pl);
    cand *cs = malloc(MAX_CAND * sizeof *cs);
    st_holes_cone_rim cr = {malloc(3 * (n + 1) * sizeof *cr.p), malloc(3 * n * sizeof *cr.r),
                            malloc(n * sizeof *cr.mask)};
    st_status rc = ST_OK;
    if (!rim || !tn || !pl || !cs || !cr.p || !cr.r || !cr.mask) {
        rc = oom(err);
        goto out;
    }
    double lo[3], hi[3], o[3], ext;
    reach_box(lo, hi, o, &ext, pts, n);
    const size_t m = loop_planes(pl, rim, pts, side, n, ext);
    const double *crease = guard ? guard->crease : NULL;
    st_holes_cone_rim_fill(&cr, pts, rim, crease, n);
    /* the cones that bend less than below, the least bent first (ties
     * by the bend of their spokes too): the first whose triangles pierce
     * none of the soup */
    size_t nc = 0;
    for (size_t a = 0; a < m; a++)
        for (size_t b = a + 1; b < m; b++)
            for (size_t c = b; c < m; c++) {    /* c == b: the line of a and b */
                cand *k = cs + nc;
                double rb, cb;
                if (!candidate(k->x, pl, a, b, c, o, lo, hi) ||
                    st_holes_cone_above(k->x, &cr, n, below) ||
                    !cone_bend(k->x, pts, rim, n, crease, below, tn, &cb, &rb))
                    continue;
                k->key = rb, k->tie = cb, k->a = a, k->b = b, k->c = c, k->done = 0;
                nc++;
            }
    const cand *k = NULL;
    for (; (k = least_cand(cs, nc)) != NULL; cs[k - cs].done = 1) {
        size_t i = 0;
        while (i < n && !crosses(guard, pts[i], pts[(i + 1) % n], k->x))
            i++;
        if (i == n)
            break;
    }
    if (!k)
        goto out;
    const double best = k->key, *apex = k->x;
    const size_t base = out->nverts;
    for (size_t i = 0; i < n; i++)
        if ((rc = st_soup_add_vertex(out, pts[i][0], pts[i][1], pts[i][2], err)))
            goto out;
    if ((rc = st_soup_add_vertex(out, apex[0], apex[1], apex[2], err)))
        goto out;
    for (size_t i = 0; i < n; i++)
        if ((rc = st_soup_add_triangle(out, (uint32_t)(base + i), (uint32_t)(base + (i + 1) % n),
                                       (uint32_t)(base + n), err)))
            goto out;
    *done = 1;
    *bent = best;
out:
    free(rim), free(tn), free(pl), free(cs), free(cr.p), free(cr.r), free(cr.mask);
    return rc;
}

/* ---- several corners per loop: fans to the points where the planes meet */

/* An apex continues loop edge i when the triangle (p_i, p_i+1, apex) lies
 * in the plane of the soup's triangle there, on the hole's side: its bend
 * below FAN_FLAT radians. */
#define FAN_FLAT 1e-6
/* At most MAX_APEX fans per loop, from as many apexes or fewer (an apex
 * met again, MERGE, fans once more). */
#define MAX_APEX 16
/* Merging apexes (doc/design/holes.md, "MERGE"). The point of the line
 * where two planes meet is taken nearest the loop's centroid; the loop
 * left by a fan takes its apex in, its centroid moves, and the next apex
 * on the same line lands a fraction of the way on: unmerged, a small
 * loop spends its MAX_APEX apexes on a chain converging along the line,
 * the last ones a rounding apart. Merged, an apex within MERGE times the
 * loop's extent of one placed before is that one (the loop left meets it
 * again and splits there), and the line's point is either one placed
 * before that lies on both planes (MERGE_SNAP) or the one nearest the
 * original loop's centroid (MERGE_FIXED). */
#define MERGE 1e-6
#define MERGE_SNAP 1
#define MERGE_FIXED 2
/* Merged fans replace the unmerged ones when they bend along the loop
 * less than MERGE_BETTER times as much (doc/design/holes.md, "MERGE"). */
#define MERGE_BETTER 0.5
/* Merged fans are built only where the unmerged ones show a chain: two
 * apexes within CHAIN times the loop's extent of each other
 * (doc/design/holes.md, "MERGE"). */
#define CHAIN 1e-6

/* One vertex of a loop being capped: its point, the third point of the
 * triangle beyond its outgoing edge (the soup's or a fan's), and the
 * original loop edge that outgoing edge is (-1: a new one, to an apex). */
typedef struct fan_v {
    const double *p, *side;
    long orig;
} fan_v;

/* 1 when the triangle (a, b, apex) continues the soup's plane across
 * edge a -> b, whose unit normal is r: bend() between its unit normal and
 * r below FAN_FLAT. Most are far from it; those whose unscaled normal u
 * turns from r by more than FAN_SURE times FAN_FLAT (|u x r| against
 * u . r, rounding a few units in the last place of |u|, where the angles
 * compared are a millionth) are told without the normal's scaling and
 * the arc tangent: the answer is bend()'s. So are those that turn by
 * less than FAN_FLAT / FAN_SURE (most of those fanned: the apex on the
 * edge's plane), the other way. */
#define FAN_SURE 4.0
static int fan_flat(const double *a, const double *b, const double *apex, const double *r)
{
    double e[3], f[3], u[3], x[3];
    st_sub3(e, b, a);
    st_sub3(f, apex, a);
    st_cross3(u, e, f);
    st_cross3(x, u, r);
    const double d = st_dot3(u, r), lim = FAN_SURE * FAN_FLAT * d, uu = st_dot3(u, u);
    /* |u| between 1e-100 and 1e100: no product below underflows where it
     * would matter; r is a unit vector or zero (then d is 0: bend() says 4) */
    if (uu > 1e-200 && uu < 1e200) {
        const double xx = st_dot3(x, x), in = FAN_FLAT / FAN_SURE * d;
        if (!(d > 0.0) || xx > lim * lim)
            return 0;   /* at least a right angle, or beyond FAN_SURE times FAN_FLAT */
        if (xx < in * in)
            return 1;   /* within FAN_FLAT / FAN_SURE */
    }
    double t[3];
    unit_normal(t, a, b, apex);
    return bend(t, r) < FAN_FLAT;
}

/* A screen before fan_flat. The apex's height s above edge a -> b's
 * plane (unit normal r) against its distance |f| from a bounds the angle
 * t between r and the fan's normal u = e x f (e = b - a, f = apex - a):
 * u x r = f (e . r) - e (f . r), so sin t >= |s| / |f| - |e . r| / |e|,
 * less a few roundings of the cross product that fan_flat's u carries.
 * Where |s| is above (FAN_FAR + |e . r| / |e|) |f|, t is at least about
 * FAN_FAR (or beyond a right angle), a hundred times FAN_FLAT: fan_flat
 * would say 0, and the screen says it for a third of the work. scr holds
 * for the loop's edge i, a column of each: scr[i], scr[n + i], scr[2 n +
 * i] its a, scr[3 n + i ..] its r and scr[6 n + i] that factor squared
 * (INFINITY, no screen, where e is zero). */
#define FAN_FAR 1e-4
static void fan_screen(double *scr, const fan_v *v, const double *rim, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        double e[3];
        st_sub3(e, v[i + 1 < n ? i + 1 : 0].p, v[i].p);
        const double le = st_norm3(e);
        const double l = le > 0.0 ? FAN_FAR + fabs(st_dot3(e, rim + 3 * i)) / le : INFINITY;
        for (int c = 0; c < 3; c++) {
            scr[(size_t)c * n + i] = v[i].p[c];
            scr[(size_t)(3 + c) * n + i] = rim[3 * i + c];
        }
        scr[6 * n + i] = l * l;
    }
}

#ifdef HOLES_AVX
/* st_holes_fan_near's screen four edges at a time (AVX), from the first:
 * those passed appended to near[*k..] in order; returns where it
 * stopped (a multiple of four, the edges left fewer than four). */
static HOLES_AVX_FN size_t fan_near4(size_t *near, size_t *k, const double *scr, size_t n,
                                     const double *apex)
{
    const double *a0 = scr, *a1 = scr + n, *a2 = scr + 2 * n;
    const double *r0 = scr + 3 * n, *r1 = scr + 4 * n, *r2 = scr + 5 * n, *ll = scr + 6 * n;
    const __m256d x0 = _mm256_set1_pd(apex[0]), x1 = _mm256_set1_pd(apex[1]);
    const __m256d x2 = _mm256_set1_pd(apex[2]);
    size_t i = 0;
    for (; i + 3 < n; i += 4) {
        const __m256d f0 = _mm256_sub_pd(x0, _mm256_loadu_pd(a0 + i));
        const __m256d f1 = _mm256_sub_pd(x1, _mm256_loadu_pd(a1 + i));
        const __m256d f2 = _mm256_sub_pd(x2, _mm256_loadu_pd(a2 + i));
        const __m256d sv = _mm256_add_pd(
            _mm256_add_pd(_mm256_mul_pd(f0, _mm256_loadu_pd(r0 + i)),
                          _mm256_mul_pd(f1, _mm256_loadu_pd(r1 + i))),
            _mm256_mul_pd(f2, _mm256_loadu_pd(r2 + i)));
        const __m256d ff = _mm256_add_pd(
            _mm256_add_pd(_mm256_mul_pd(f0, f0), _mm256_mul_pd(f1, f1)), _mm256_mul_pd(f2, f2));
        const int pass = _mm256_movemask_pd(_mm256_cmp_pd(
            _mm256_mul_pd(sv, sv), _mm256_mul_pd(_mm256_loadu_pd(ll + i), ff), _CMP_NGT_US));
        for (int l = 0; pass && l < 4; l++)     /* most pass none */
            if (pass >> l & 1)
                near[(*k)++] = i + (size_t)l;
    }
    return i;
}
#endif

size_t st_holes_fan_near(size_t *near, const double *scr, size_t n, const double *apex)
{
    const double *a0 = scr, *a1 = scr + n, *a2 = scr + 2 * n;
    const double *r0 = scr + 3 * n, *r1 = scr + 4 * n, *r2 = scr + 5 * n, *ll = scr + 6 * n;
    size_t k = 0, i = 0;
#ifdef HOLES_AVX
    if (n >= 4 && holes_avx())
        i = fan_near4(near, &k, scr, n, apex);
#endif
#ifdef __SSE2__
    const __m128d x0 = _mm_set1_pd(apex[0]), x1 = _mm_set1_pd(apex[1]), x2 = _mm_set1_pd(apex[2]);
    for (; i + 1 < n; i += 2) {
        const __m128d f0 = _mm_sub_pd(x0, _mm_loadu_pd(a0 + i));
        const __m128d f1 = _mm_sub_pd(x1, _mm_loadu_pd(a1 + i));
        const __m128d f2 = _mm_sub_pd(x2, _mm_loadu_pd(a2 + i));
        const __m128d sv = _mm_add_pd(_mm_add_pd(_mm_mul_pd(f0, _mm_loadu_pd(r0 + i)),
                                                 _mm_mul_pd(f1, _mm_loadu_pd(r1 + i))),
                                      _mm_mul_pd(f2, _mm_loadu_pd(r2 + i)));
        const __m128d ff = _mm_add_pd(_mm_add_pd(_mm_mul_pd(f0, f0), _mm_mul_pd(f1, f1)),
                                      _mm_mul_pd(f2, f2));
        const int pass = _mm_movemask_pd(
            _mm_cmpngt_pd(_mm_mul_pd(sv, sv), _mm_mul_pd(_mm_loadu_pd(ll + i), ff)));
        if (pass) {     /* most pass neither */
            if (pass & 1)
                near[k++] = i;
            if (pass & 2)
                near[k++] = i + 1;
        }
    }
#endif
    for (; i < n; i++) {
        const double f0 = apex[0] - a0[i], f1 = apex[1] - a1[i], f2 = apex[2] - a2[i];
        const double sv = f0 * r0[i] + f1 * r1[i] + f2 * r2[i];
        near[k] = i;
        k += !(sv * sv > ll[i] * (f0 * f0 + f1 * f1 + f2 * f2));
    }
    return k;
}

/* Which of the loop's edges apex continues (FAN_FLAT): flag[n], scr from
 * fan_screen, near[n] room for the edges it passes. Returns their
 * length. (All of them are fanned: doc/design/holes.md.) */
static double fan_flags(const double *apex, const fan_v *v, const double *rim,
                        const double *scr, size_t n, int *flag, size_t *near)
{
    memset(flag, 0, n * sizeof *flag);
    const size_t k = st_holes_fan_near(near, scr, n, apex);
    double g = 0.0;
    for (size_t j = 0; j < k; j++) {
        const size_t i = near[j];
        const double *a = v[i].p, *b = v[i + 1 < n ? i + 1 : 0].p;
        flag[i] = fan_flat(a, b, apex, rim + 3 * i);
        if (flag[i])
            g += dist3(a, b);
    }
    return g;
}

/* Unflags the edges whose fan from apex pierces guard's soup; returns
 * the length of those left. */
static double fans_uncross(const st_holes_guard *g, const double *apex, const fan_v *v, size_t n,
                           int *flag)
{
    double len = 0.0;
    for (size_t i = 0; i < n; i++)
        if (flag[i]) {
            if (crosses(g, v[i].p, v[(i + 1) % n].p, apex))
                flag[i] = 0;
            else
                len += dist3(v[i].p, v[(i + 1) % n].p);
        }
    return len;
}

typedef struct fan_out {
    const double **tri;     /* 3 points a triangle */
    long *orig;             /* per triangle edge: the original loop edge or -1 */
    size_t nt, cap;
} fan_out;

static st_status fan_push(fan_out *o, const double *a, const double *b, const double *c, long oa,
                          long ob, long oc, st_error *err)
{
    if (o->nt == o->cap) {
        size_t nc = o->cap ? 2 * o->cap : 64;
        const double **t = realloc(o->tri, 3 * nc * sizeof *t);
        if (!t)
            return oom(err);
        o->tri = t;
        long *g = realloc(o->orig, 3 * nc * sizeof *g);
        if (!g)
            return oom(err);
        o->orig = g;
        o->cap = nc;
    }
    o->tri[3 * o->nt] = a, o->tri[3 * o->nt + 1] = b, o->tri[3 * o->nt + 2] = c;
    o->orig[3 * o->nt] = oa, o->orig[3 * o->nt + 1] = ob, o->orig[3 * o->nt + 2] = oc;
    o->nt++;
    return ST_OK;
}

/* The fans of one loop being built: the loops still to cap, one after
 * another in stk (each led by its length in lens), the one being capped
 * (cur, m vertices; lp, ls its points and sides), its planes and apexes,
 * and the triangles so far (fo). */
typedef struct fanner {
    size_t maxv, nloops, napex, nstep, top;
    int merge;          /* apexes merged (MERGE): 0 no, MERGE_SNAP, MERGE_FIXED */
    fan_v *stk, *cur, *nxt;
    size_t *lens;
    double *rim, *scr;
    size_t *near;       /* the edges fan_screen passes */
    plane *pl;
    const double **lp, **ls;
    uint32_t *tri;
    double (*apx)[3];
    int *flag, *best;   /* the edges an apex continues; the best apex's */
    cand *cs;
    fan_out fo;
    double lo[3], hi[3], ext;   /* the original loop's reach box, extent */
    double o0[3];               /* and its centroid */
    const st_holes_guard *guard;
    /* the original loop's first apex and the edges it continues (its
     * best_apex, the same however the apexes are merged: none placed
     * yet, o the centroid), from lead when set */
    const struct fanner *lead;
    double ax0[3];
    int *flag0;
    size_t ncont0;
} fanner;

static st_status fanner_alloc(fanner *f, size_t n, st_error *err)
{
    const size_t maxv = f->maxv = n + 2 * MAX_APEX + 2;
    f->stk = malloc(2 * maxv * (MAX_APEX + 2) * sizeof *f->stk);
    f->cur = malloc(maxv * sizeof *f->cur);
    f->nxt = malloc(2 * maxv * sizeof *f->nxt);
    f->lens = malloc(maxv * sizeof *f->lens);
    f->rim = malloc(3 * maxv * sizeof *f->rim);
    f->scr = malloc(8 * maxv * sizeof *f->scr);
    f->near = malloc(maxv * sizeof *f->near);
    f->pl = malloc(maxv * sizeof *f->pl);
    f->lp = malloc(maxv * sizeof *f->lp);
    f->ls = malloc(maxv * sizeof *f->ls);
    f->tri = malloc(3 * maxv * sizeof *f->tri);
    f->apx = malloc(MAX_APEX * sizeof *f->apx);
    f->flag = malloc(maxv * sizeof *f->flag);
    f->best = malloc(maxv * sizeof *f->best);
    f->cs = malloc(MAX_CAND * sizeof *f->cs);
    f->flag0 = malloc(maxv * sizeof *f->flag0);
    if (!f->flag0 || !f->flag || !f->best || !f->stk || !f->cur || !f->nxt || !f->lens ||
        !f->rim || !f->scr || !f->near || !f->pl || !f->lp || !f->ls || !f->tri || !f->apx ||
        !f->cs)
        return oom(err);
    return ST_OK;
}

static void fanner_free(fanner *f)
{
    free(f->stk), free(f->cur), free(f->nxt), free(f->lens), free(f->rim), free(f->pl);
    free(f->scr), free(f->near);
    free(f->lp), free(f->ls), free(f->tri), free(f->apx), free(f->fo.tri), free(f->fo.orig);
    free(f->flag), free(f->best), free(f->cs), free(f->flag0);
}

/* The point of the line where planes a and b meet: an apex placed
 * before when one lies on both (within MERGE times the extent; the first
 * such), in x; else x as it was (the point nearest the centroid, which
 * moves as the loop takes the apexes in and would place a chain of
 * points converging along the line, doc/design/holes.md "MERGE"). */
static void on_line_apex(const fanner *f, double *x, size_t a, size_t b)
{
    const plane *pa = f->pl + a, *pb = f->pl + b;
    for (size_t i = 0; i < f->napex; i++) {
        const double *A = f->apx[i];
        if (fabs(st_dot3(pa->n, A) - pa->d) <= MERGE * f->ext &&
            fabs(st_dot3(pb->n, A) - pb->d) <= MERGE * f->ext) {
            memcpy(x, A, 3 * sizeof *x);
            return;
        }
    }
}

/* The apex for the loop in f->cur (m vertices, centroid o): by the length
 * of the loop they continue, the most first, each without the edges
 * whose fans pierce the soup, until none left could continue more. Its
 * point in ax and its continued edges in f->flag; returns how many. */
static size_t best_apex(fanner *f, size_t m, const double *o, double *ax)
{
    const size_t np = loop_planes(f->pl, f->rim, (const double *const *)f->lp,
                                  (const double *const *)f->ls, m, f->ext);
    fan_screen(f->scr, f->cur, f->rim, m);
    size_t nc = 0;
    if (f->nstep < MAX_APEX)
        for (size_t a = 0; a < np; a++)
            for (size_t b = a + 1; b < np; b++)
                for (size_t c = b; c < np; c++) {
                    cand *k = f->cs + nc;
                    if (!candidate(k->x, f->pl, a, b, c, o, f->lo, f->hi))
                        continue;
                    if (c == b && f->merge == MERGE_SNAP)
                        on_line_apex(f, k->x, a, b);
                    const double g = fan_flags(k->x, f->cur, f->rim, f->scr, m, f->flag, f->near);
                    if (!(g > 0.0))
                        continue;
                    k->key = -g, k->tie = (double)nc, k->done = 0;
                    nc++;
                }
    double best = 0.0;
    for (cand *k; (k = least_cand(f->cs, nc)) != NULL && -k->key > best; k->done = 1) {
        fan_flags(k->x, f->cur, f->rim, f->scr, m, f->flag, f->near);
        const double g = fans_uncross(f->guard, k->x, f->cur, m, f->flag);
        if (g > best) {   /* its flags kept: not tested again */
            best = g;
            memcpy(ax, k->x, 3 * sizeof *ax);
            memcpy(f->best, f->flag, m * sizeof *f->best);
        }
    }
    size_t ncont = 0;
    if (best > 0.0) {
        memcpy(f->flag, f->best, m * sizeof *f->flag);
        for (size_t i = 0; i < m; i++)
            ncont += (size_t)f->flag[i];
    }
    return ncont;
}

/* The loop in f->cur (m vertices) by fill, the triangulation of its own
 * points. */
static st_status fill_loop(fanner *f, size_t m, st_holes_fill fill, st_error *err)
{
    double area;
    st_status rc = fill(&area, (const double *const *)f->lp, (const double *const *)f->ls, m,
                        f->tri, err);
    for (size_t t = 0; !rc && t + 2 < m; t++) {
        const uint32_t *c = f->tri + 3 * t;
        long og[3];
        for (int e = 0; e < 3; e++) {
            const size_t u = c[e], w = c[(e + 1) % 3];
            og[e] = (u + 1) % m == w ? f->cur[u].orig : (w + 1) % m == u ? f->cur[w].orig : -1;
        }
        rc = fan_push(&f->fo, f->lp[c[0]], f->lp[c[1]], f->lp[c[2]], og[0], og[1], og[2], err);
    }
    return rc;
}

/* The fans from apex A over the flagged edges of f->cur (m vertices),
 * and in f->nxt (*k vertices) the loop with each run of them replaced by
 * A, started at an edge A does not continue; *s0 == m when A continues
 * them all (a cone over the whole loop). */
static st_status fan_apex(fanner *f, size_t m, const double *A, size_t *k, size_t *s0,
                          st_error *err)
{
    const int *flag = f->flag;
    fan_v *nxt = f->nxt;
    size_t s = 0;
    while (s < m && flag[s])
        s++;
    *s0 = s;
    *k = 0;
    for (size_t r = 0; r < m; r++) {
        const size_t i = (s + r) % m;
        const fan_v *vi = f->cur + i, *vj = f->cur + (i + 1) % m;
        if (!flag[i]) {
            nxt[(*k)++] = *vi;
            continue;
        }
        const st_status rc = fan_push(&f->fo, vi->p, vj->p, A, vi->orig, -1, -1, err);
        if (rc)
            return rc;
        const int first = r == 0 || !flag[(i + m - 1) % m];
        const int last = r + 1 == m || !flag[(i + 1) % m];
        if (first && s < m) {      /* vi stays, its edge now to the apex */
            nxt[*k].p = vi->p;
            nxt[*k].side = vj->p;
            nxt[*k].orig = -1;
            (*k)++;
        }
        if (last) {
            nxt[*k].p = A;
            nxt[*k].side = vi->p;
            nxt[*k].orig = -1;
            (*k)++;
        }
    }
    return ST_OK;
}

/* Pushes the loop in f->nxt (k vertices) onto the stack, split where it
 * meets apex A more than once: rotated to start at A, cut before each
 * later occurrence of it. 0 when the stack is full (never on a loop of
 * this size). */
static int push_split(fanner *f, size_t k, const double *A)
{
    fan_v *nxt = f->nxt;
    size_t firstA = 0;
    while (nxt[firstA].p != A)
        firstA++;
    for (size_t i = 0; i < k; i++)
        nxt[k + i] = nxt[(firstA + i) % k];
    size_t st = k;
    for (size_t i = k + 1; i <= 2 * k; i++)
        if (i == 2 * k || nxt[i].p == A) {
            const size_t len = i - st;
            if (len >= 3) {
                if (f->nloops == f->maxv || f->top + len > 2 * f->maxv * (MAX_APEX + 2))
                    return 0;
                memcpy(f->stk + f->top, nxt + st, len * sizeof *f->stk);
                f->top += len;
                f->lens[f->nloops++] = len;
            }
            st = i;
        }
    return 1;
}

/* The caps' bend along the original loop pts[0..n) (crease: the loop's
 * creases, st_holes_crease_bend; NULL: against the soup's triangles
 * only). */
static double fans_bend(const fan_out *fo, const double *const *pts, const double *const *side,
                        size_t n, const double *crease)
{
    double rb = 0.0;
    for (size_t t = 0; t < fo->nt; t++) {
        double nt[3], nr[3];
        const double **c = fo->tri + 3 * t;
        unit_normal(nt, c[0], c[1], c[2]);
        for (int e = 0; e < 3; e++) {
            const long i = fo->orig[3 * t + e];
            if (i < 0)
                continue;
            unit_normal(nr, pts[i], side[i], pts[((size_t)i + 1) % n]);
            rb += dist3(pts[i], pts[((size_t)i + 1) % n]) *
                  st_holes_crease_bend(nt, nr, crease ? crease + 6 * i : NULL);
        }
    }
    return rb;
}

/* The apex ax for the loop in f->cur (m vertices, its edges in f->flag):
 * one placed before when within MERGE times the extent of it (the
 * first such; the edges at it, which it would fan flat, no longer
 * flagged), else a new one. NULL when it no longer continues two edges,
 * or no apex is left. */
static const double *place_apex(fanner *f, size_t m, const double *ax)
{
    const double *A = NULL;
    for (size_t a = 0; f->merge && a < f->napex && !A; a++)
        if (dist3(f->apx[a], ax) <= MERGE * f->ext)
            A = f->apx[a];
    if (A) {
        size_t left = 0;
        for (size_t i = 0; i < m; i++) {
            if (f->cur[i].p == A || f->cur[(i + 1) % m].p == A)
                f->flag[i] = 0;
            left += (size_t)f->flag[i];
        }
        if (left < 2)
            return NULL;
    } else {
        if (f->napex == MAX_APEX)
            return NULL;
        memcpy(f->apx[f->napex], ax, sizeof f->apx[f->napex]);
        A = f->apx[f->napex++];
    }
    f->nstep++;
    return A;
}

/* best_apex for the loop in f->cur (m vertices, centroid o; the
 * original loop's with MERGE_FIXED); the original loop's (the first
 * popped: no step taken) kept in f, or taken from f->lead. */
static size_t step_apex(fanner *f, size_t m, const double *o, double *ax)
{
    const int first = f->nstep == 0 && f->napex == 0;
    const fanner *l = f->lead;
    if (first && l) {
        memcpy(ax, l->ax0, sizeof l->ax0);
        memcpy(f->flag, l->flag0, m * sizeof *f->flag);
        return l->ncont0;
    }
    const size_t c = best_apex(f, m, f->merge == MERGE_FIXED ? f->o0 : o, ax);
    if (first) {
        memcpy(f->ax0, ax, sizeof f->ax0);
        memcpy(f->flag0, f->flag, m * sizeof *f->flag0);
        f->ncont0 = c;
    }
    return c;
}

/* Caps the loops on f's stack, from the original loop pts[0..n) down:
 * each by the fans from its best apex, the loop left pushed back, or by
 * fill when no apex continues two of its edges. *whole 0 when the stack
 * overflowed (the fans are then not used). */
static st_status fan_loops(fanner *f, int *whole, st_holes_fill fill, st_error *err)
{
    st_status rc = ST_OK;
    *whole = 1;
    while (f->nloops && !rc) {
        /* pop the last loop */
        const size_t m = f->lens[--f->nloops];
        f->top -= m;
        memcpy(f->cur, f->stk + f->top, m * sizeof *f->cur);
        if (m < 3)
            continue;
        double o[3] = {0, 0, 0}, ax[3] = {0, 0, 0};
        for (size_t i = 0; i < m; i++)
            for (int k = 0; k < 3; k++)
                o[k] += f->cur[i].p[k] / (double)m;
        for (size_t i = 0; i < m; i++) {
            f->lp[i] = f->cur[i].p;
            f->ls[i] = f->cur[i].side;
        }
        if (step_apex(f, m, o, ax) < 2) {
            rc = fill_loop(f, m, fill, err);
            continue;
        }
        const double *A = place_apex(f, m, ax);
        if (!A) {
            rc = fill_loop(f, m, fill, err);
            continue;
        }
        size_t k, s0;
        rc = fan_apex(f, m, A, &k, &s0, err);
        if (!rc && s0 < m && !push_split(f, k, A)) {
            *whole = 0;
            break;
        }
    }
    return rc;
}

/* 1 when two of the fans' triangles pierce each other
 * (st_tri_tri_cross). */
static int fans_cross(const fan_out *fo)
{
    for (size_t t = 0; t < fo->nt; t++)
        for (size_t u = t + 1; u < fo->nt; u++) {
            const double *const *a = fo->tri + 3 * t, *const *b = fo->tri + 3 * u;
            if (st_tri_tri_cross(a[0], a[1], a[2], b[0], b[1], b[2]))
                return 1;
        }
    return 0;
}

/* The fans of the loop pts[0..n) in f (merge: f->merge; its first apex
 * from lead when set), their bend
 * along it in *rb (INFINITY when there are none: no apex, or the stack
 * overflowed; or, merged, when two of them pierce each other). */
static st_status fans_run(fanner *f, int merge, const fanner *lead, const double *const *pts,
                          const double *const *side, size_t n, st_holes_fill fill,
                          const st_holes_guard *guard, double *rb, double *rbc, st_error *err)
{
    *rb = *rbc = INFINITY;
    f->guard = guard;
    f->merge = merge;
    f->lead = lead;
    int whole = 0;
    st_status rc = fanner_alloc(f, n, err);
    if (rc)
        return rc;
    reach_box(f->lo, f->hi, f->o0, &f->ext, pts, n);
    for (size_t i = 0; i < n; i++) {
        f->stk[i].p = pts[i];
        f->stk[i].side = side[i];
        f->stk[i].orig = (long)i;
    }
    f->lens[0] = n;
    f->top = n;
    f->nloops = 1;
    if ((rc = fan_loops(f, &whole, fill, err)) || !whole || f->napex == 0)
        return rc;
    /* merged, two lines' apexes can be one point far from where either
     * chain went: such fans may cross themselves */
    if (!merge || !fans_cross(&f->fo)) {
        *rb = fans_bend(&f->fo, pts, side, n, NULL);
        *rbc = guard && guard->crease ? fans_bend(&f->fo, pts, side, n, guard->crease) : *rb;
    }
    return ST_OK;
}

/* 1 when the fans in f (unmerged) show a chain (MERGE): two of their
 * apexes within CHAIN times the loop's extent of each other. */
static int fans_chain(const fanner *f)
{
    for (size_t a = 0; a < f->napex; a++)
        for (size_t b = a + 1; b < f->napex; b++)
            if (dist3(f->apx[a], f->apx[b]) <= CHAIN * f->ext)
                return 1;
    return 0;
}

st_status st_holes_planes_fans(st_soup *out, int *done, const double *const *pts,
                               const double *const *side, size_t n, double below,
                               st_holes_fill fill, const st_holes_guard *guard, double *bent,
                               st_error *err)
{
    *done = 0;
    *bent = INFINITY;
    fanner fs[3];
    memset(fs, 0, sizeof fs);
    double rbs[3], rbc[3];
    /* without the apexes merged, and, where those show a chain
     * (fans_chain), merged each way (MERGE; the first apex is the same in
     * all three): the merged ones that bend least along the loop where
     * they bend less than MERGE_BETTER times the unmerged ones, else
     * those. That choice by their bend against the soup's triangles
     * alone: along creases every one may bend nowhere, and a rounding
     * would pick merged fans that fold (doc/design/holes.md, "Creases");
     * the caller's bound by the bend with the creases (rbc) */
    size_t v = 0;
    st_status rc = fans_run(fs, 0, NULL, pts, side, n, fill, guard, rbs, rbc, err);
    const int chain = !rc && fans_chain(fs);
    for (int k = 1; k < 3 && chain && !rc; k++) {
        rc = fans_run(fs + k, k, fs, pts, side, n, fill, guard, rbs + k, rbc + k, err);
        if (!rc && rbs[k] < MERGE_BETTER * rbs[0] && rbs[k] < rbs[v])
            v = (size_t)k;
    }
    const fanner *f = fs + v;
    const double rb = rbc[v];
    if (rc || !(rb < below))
        goto done;
    for (size_t t = 0; t < f->fo.nt; t++) {
        const size_t base = out->nverts;
        for (int c = 0; c < 3; c++) {
            const double *q = f->fo.tri[3 * t + c];
            if ((rc = st_soup_add_vertex(out, q[0], q[1], q[2], err)))
                goto done;
        }
        if ((rc = st_soup_add_triangle(out, (uint32_t)base, (uint32_t)(base + 1),
                                       (uint32_t)(base + 2), err)))
            goto done;
    }
    *done = 1;
    *bent = rb;
done:
    for (int k = 0; k < 3; k++)
        fanner_free(fs + k);
    return rc;
}
