/*
 * sides.c - the side of an oriented soup near each voxel (see sides.h).
 * Design notes and measurements: doc/design/sides.md.
 */
#include "../base/fpenv.h"
#include "souptet/sides.h"

#include "souptet/bvh.h"
#include "souptet/edges.h"
#include "souptet/mem.h"
#include "souptet/pred.h"
#include "souptet/sign.h"
#include "sides_internal.h"

#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>
#if defined(__GNUC__) && defined(__x86_64__)
#include <immintrin.h>
#endif

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

st_sides_params st_sides_params_default(void)
{
    /* band 2.5 voxels: the voxels the cut reads either side of a wall;
     * cube radius 3 voxels: a wall's solid angle from 1 voxel away is
     * two thirds of a hemisphere (w about 1/3); weight 24 turns that into
     * 8 votes of margin, below the 10 that decide a voxel alone
     * (mincut.h), so the votes and the cut's area still have a say. */
    /* one-sided below 0.25 and the column rule below 0.02 along an axis:
     * between what the corpus's one-sided scans and its other damaged
     * soups read (doc/design/sides.md) */
    st_sides_params p = {2.5, 3.0, 24.0, 9, 0.25, 0, 1e-3, 0.25, 0, 0.02, 0, 1, NULL};
    return p;
}

/* Van Oosterom and Strackee 1983: the signed solid angle of triangle
 * (a, b, c) seen from the origin is 2 atan2(*det, *den). */
static inline void solid_terms(const double a[3], const double b[3], const double c[3],
                               double *det, double *den)
{
    const double la = sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
    const double lb = sqrt(b[0] * b[0] + b[1] * b[1] + b[2] * b[2]);
    const double lc = sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
    *det = a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
           a[2] * (b[0] * c[1] - b[1] * c[0]);
    const double ab = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    const double bc = b[0] * c[0] + b[1] * c[1] + b[2] * c[2];
    const double ca = c[0] * a[0] + c[1] * a[1] + c[2] * a[2];
    *den = la * lb * lc + ab * lc + bc * la + ca * lb;
}

/* Signed solid angle of triangle (a, b, c) seen from the origin, positive
 * when the origin is behind it (the triangle counter-clockwise seen from
 * its front). */
static double solid_angle(const double a[3], const double b[3], const double c[3])
{
    double det, den;
    solid_terms(a, b, c, &det, &den);
    return 2.0 * atan2(det, den);
}

/* The voxel nearest point q, or SIZE_MAX outside the grid. */
static size_t voxel_at(const st_grid *g, const double q[3])
{
    const size_t dims[3] = {g->nx, g->ny, g->nz};
    size_t ijk[3];
    for (int k = 0; k < 3; k++) {
        const double f = floor((q[k] - g->origin[k]) / g->voxel + 0.5);
        if (!(f >= 0.0 && f < (double)dims[k]))
            return SIZE_MAX;
        ijk[k] = (size_t)f;
    }
    return st_grid_index(g, ijk[0], ijk[1], ijk[2]);
}

typedef struct wsum {
    const st_soup *o;
    const double *p;
    double sum;
} wsum;

/* Triangle t of o, its corners less p, in a, b, c. */
static void corners_from(const st_soup *o, uint32_t t, const double *p, double a[3], double b[3],
                         double c[3])
{
    const uint32_t *v = o->tris + 3 * (size_t)t;
    for (int k = 0; k < 3; k++) {
        a[k] = o->xyz[3 * (size_t)v[0] + k] - p[k];
        b[k] = o->xyz[3 * (size_t)v[1] + k] - p[k];
        c[k] = o->xyz[3 * (size_t)v[2] + k] - p[k];
    }
}

static int add_angle(void *ctx, uint32_t t)
{
    wsum *w = ctx;
    double a[3], b[3], c[3];
    corners_from(w->o, t, w->p, a, b, c);
    w->sum += solid_angle(a, b, c);
    return 0;
}

/* The same sum with one arc tangent per query: the half angles
 * atan2(det, den) are the arguments of the complex numbers den + i det,
 * and the argument of their product is their sum less the whole turns,
 * counted as the product goes (turns). The product is kept near 1 by
 * powers of two (exact): each term times unit (term_unit), then the
 * product brought back when it strays. A term on the negative real axis
 * (the point on the triangle's plane, its angle a sign of zero away from
 * -pi or pi) or out of [2^-300, 2^300] stops the query: the sum is then
 * taken as add_angle takes it. */
typedef struct wprod {
    const st_soup *o;
    const double *p;
    double re, im;      /* the product, scaled */
    long turns;         /* the whole turns taken off */
    size_t terms;
    double unit;        /* each term's power of two */
} wprod;

/* The power of two each term is taken times, for a cube of half-side r:
 * 1 / r^3 to within a factor 2^3 (a term is about the cube of the point's
 * distance from the triangle). Exact: times a power of two, every
 * operation of the product gives the same bits but for the exponent (a
 * term reaching it is within [2^-300, 2^300], the unit within 2^-600 and
 * 2^600; only a term's part under 2^-422, an angle under 2^-120 of it,
 * can fall under the doubles' range and then moves the product by less
 * than its rounding, well inside DRIFT), so the product's argument and
 * its turns are those of the unscaled terms and the evidence is the same;
 * only the rescales (rescale) become rare where r is far from 1
 * (dragon_res3 at 7 cells: 1.1 M of 2.7 M quads' terms rescaled). */
static double term_unit(double r)
{
    if (!(r > 0.0 && r < INFINITY))
        return 1.0;
    int k = -3 * ilogb(r);
    k = k < -600 ? -600 : k > 600 ? 600 : k;
    return ldexp(1.0, k);
}

/* The product brought back into [2^-64, 2^64] by powers of two. */
static void rescale(wprod *w)
{
    double r = fabs(w->re) > fabs(w->im) ? fabs(w->re) : fabs(w->im);
    for (; r > 0x1p64; r *= 0x1p-128)
        w->re *= 0x1p-128, w->im *= 0x1p-128;
    for (; r < 0x1p-64; r *= 0x1p128)
        w->re *= 0x1p128, w->im *= 0x1p128;
}

/* The triangle (a, b, c) (corners less the point) into the product; 1
 * when the query must take the sum instead. */
static inline int prod_term(wprod *w, const double a[3], const double b[3], const double c[3])
{
    double det, den;
    solid_terms(a, b, c, &det, &den);
    const double m = fabs(den) > fabs(det) ? fabs(den) : fabs(det);
    if ((det == 0.0 && !(den > 0.0)) || !(m >= 0x1p-300 && m <= 0x1p300))
        return 1;
    det *= w->unit;
    den *= w->unit;
    const double re = w->re * den - w->im * det, im = w->re * det + w->im * den;
    /* both arguments in [0, pi] (sign bits clear) sum to over pi when the
     * product's falls below the real axis, both in [-pi, -0] to under -pi
     * when it rises above: where the products it sums have one sign, no
     * cancellation can move it, and where they cancel the sum is near
     * pi (or -pi), where either turn reads the same angle */
    const int up = !signbit(w->im);
    if (up == !signbit(det) && up != !signbit(im))
        w->turns += up ? 1 : -1;
    w->re = re;
    w->im = im;
    const double r = fabs(re) > fabs(im) ? fabs(re) : fabs(im);
    if (!(r <= 0x1p64 && r >= 0x1p-64))
        rescale(w);
    w->terms++;
    return 0;
}

static int mul_angle(void *ctx, uint32_t t)
{
    wprod *w = ctx;
    double a[3], b[3], c[3];
    corners_from(w->o, t, w->p, a, b, c);
    return prod_term(w, a, b, c);
}

/* Twice the area vector of triangle t of s. */
static void tri_normal(const st_soup *s, size_t t, double n[3])
{
    const uint32_t *v = s->tris + 3 * t;
    const double *A = s->xyz + 3 * (size_t)v[0], *B = s->xyz + 3 * (size_t)v[1],
                 *C = s->xyz + 3 * (size_t)v[2];
    const double u[3] = {B[0] - A[0], B[1] - A[1], B[2] - A[2]};
    const double w[3] = {C[0] - A[0], C[1] - A[1], C[2] - A[2]};
    n[0] = u[1] * w[2] - u[2] * w[1];
    n[1] = u[2] * w[0] - u[0] * w[2];
    n[2] = u[0] * w[1] - u[1] * w[0];
}

/* The eigenvector of the least eigenvalue of the symmetric 3x3 matrix a
 * (cyclic Jacobi rotations; a is overwritten). */
static void least_eigenvector(double a[3][3], double out[3])
{
    double v[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    for (int sweep = 0; sweep < 50; sweep++) {
        const double off = a[0][1] * a[0][1] + a[0][2] * a[0][2] + a[1][2] * a[1][2];
        if (!(off > 1e-30 * (a[0][0] * a[0][0] + a[1][1] * a[1][1] + a[2][2] * a[2][2])))
            break;
        for (int p = 0; p < 2; p++)
            for (int q = p + 1; q < 3; q++) {
                if (a[p][q] == 0.0)
                    continue;
                const double th = 0.5 * (a[q][q] - a[p][p]) / a[p][q];
                const double t = (th >= 0.0 ? 1.0 : -1.0) / (fabs(th) + sqrt(th * th + 1.0));
                const double c = 1.0 / sqrt(t * t + 1.0), sn = t * c;
                for (int k = 0; k < 3; k++) {   /* a <- a J */
                    const double akp = a[k][p], akq = a[k][q];
                    a[k][p] = c * akp - sn * akq;
                    a[k][q] = sn * akp + c * akq;
                }
                for (int k = 0; k < 3; k++) {   /* a <- J^T a */
                    const double apk = a[p][k], aqk = a[q][k];
                    a[p][k] = c * apk - sn * aqk;
                    a[q][k] = sn * apk + c * aqk;
                }
                for (int k = 0; k < 3; k++) {
                    const double vkp = v[k][p], vkq = v[k][q];
                    v[k][p] = c * vkp - sn * vkq;
                    v[k][q] = sn * vkp + c * vkq;
                }
            }
    }
    int m = 0;
    for (int k = 1; k < 3; k++)
        if (a[k][k] < a[m][m])
            m = k;
    for (int k = 0; k < 3; k++)
        out[k] = v[k][m];
}

/* The area share of o's rim faces (rim, of the first nview) within
 * p->wall_cosine of square to view: walls along the view. When mm is not
 * NULL it gets their second moments weighted 1/|cos| (at most 1e6). */
static double walls_share(const st_soup *o, size_t nview, const uint8_t *rim,
                          const double view[3], const st_sides_params *p, double mm[3][3])
{
    double all = 0.0, wall = 0.0;
    for (size_t t = 0; t < nview; t++) {
        double n[3];
        tri_normal(o, t, n);
        const double l = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        if (!rim[t] || !(l > 0.0))
            continue;
        const double c = fabs(n[0] * view[0] + n[1] * view[1] + n[2] * view[2]) / l;
        all += l;
        wall += c <= p->wall_cosine ? l : 0.0;
        const double w = 1.0 / (l * (c > 1e-6 ? c : 1e-6));
        for (int a = 0; mm && a < 3; a++)
            for (int b = 0; b < 3; b++)
                mm[a][b] += n[a] * n[b] * w;
    }
    return all > 0.0 ? wall / all : 0.0;
}

/* 4. A one-sided view (sides.h): the view v of the oriented soup o's
 * first nview triangles (the seen ones), and the lattice step nearest it.
 * A scan's faces turn away from the viewer at its horizon, where it was
 * cut off: there (the triangles rim marks, on a boundary of the seen
 * surface) the normals are square to v, so v is the direction most square
 * to them (the least eigenvector of their area-weighted normals' second
 * moments), turned to their mean normal; the mean normal alone where there
 * is no rim. */
static void view_of(const st_soup *o, size_t nview, const uint8_t *rim,
                    const st_sides_params *p, st_sides_stats *st)
{
    double m[3] = {0.0, 0.0, 0.0}, mm[3][3] = {{0}};
    size_t nrim = 0;
    for (size_t t = 0; t < nview; t++) {
        double n[3];
        tri_normal(o, t, n);
        for (int k = 0; k < 3; k++)
            m[k] += n[k];
        const double l = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        if (!rim[t] || !(l > 0.0))
            continue;
        nrim++;
        for (int a = 0; a < 3; a++)
            for (int b = 0; b < 3; b++)
                mm[a][b] += n[a] * n[b] / l;
    }
    const double lm = sqrt(m[0] * m[0] + m[1] * m[1] + m[2] * m[2]);
    if (!(lm > 0.0))
        return;
    for (int k = 0; k < 3; k++)
        st->view[k] = m[k] / lm;
    /* the least sum of |cos| rather than of its square, so that faces
     * square to the view outweigh the seen faces that meet unseen ones at
     * a sharp edge: iteratively reweighted by 1/|cos| (at most 1e6; on a
     * rim that folds smoothly this may tilt a few degrees, one lattice
     * step's worth of nothing) */
    for (int pass = 0; p->past_caps && pass < 12 && nrim >= 3; pass++) {
        double e[3];
        least_eigenvector(mm, e);
        const double d = e[0] * m[0] + e[1] * m[1] + e[2] * m[2];
        if (d == 0.0)
            break;
        for (int k = 0; k < 3; k++)
            st->view[k] = d > 0.0 ? e[k] : -e[k];
        memset(mm, 0, sizeof mm);
        st->walls = walls_share(o, nview, rim, st->view, p, mm);
    }
    /* a rim square to a direction far from where the faces face (a gear's
     * teeth seen askew: their flanks run along its axis) is not the view */
    if (p->past_caps &&
        st->view[0] * m[0] + st->view[1] * m[1] + st->view[2] * m[2] < 0.5 * sqrt(2.0) * lm) {
        for (int k = 0; k < 3; k++)
            st->view[k] = m[k] / lm;
        st->walls = walls_share(o, nview, rim, st->view, p, NULL);
    }
    double front = 0.0, back = 0.0;
    for (size_t t = 0; t < nview; t++) {
        double n[3];
        tri_normal(o, t, n);
        const double a = n[0] * st->view[0] + n[1] * st->view[1] + n[2] * st->view[2];
        if (a > 0.0)
            front += a;
        else
            back -= a;
    }
    st->back_front = front > 0.0 ? back / front : 1.0;
    st->onesided = st->back_front < p->onesided_ratio;
    st->fold = st->onesided && (!p->past_caps || st->walls < p->walls_ratio);
    st->past_caps = p->past_caps;
    st->far = p->past_caps ? -INFINITY : INFINITY;
    /* the lattice step nearest v (the first of equals) */
    double best = -2.0;
    for (int a = -2; a <= 2; a++)
        for (int b = -2; b <= 2; b++)
            for (int c = -2; c <= 2; c++) {
                const double l = sqrt((double)(a * a + b * b + c * c));
                if (!(l > 0.0))
                    continue;
                const double cs = (a * st->view[0] + b * st->view[1] + c * st->view[2]) / l;
                if (cs > best) {
                    best = cs;
                    st->step[0] = a;
                    st->step[1] = b;
                    st->step[2] = c;
                }
            }
    /* the soup's farthest point from the viewer, along the step */
    const double l = sqrt((double)(st->step[0] * st->step[0] + st->step[1] * st->step[1] +
                                   st->step[2] * st->step[2]));
    for (size_t v = 0; v < o->nverts && !p->past_caps; v++) {
        const double *x = o->xyz + 3 * v;
        const double h = (x[0] * st->step[0] + x[1] * st->step[1] + x[2] * st->step[2]) / l;
        st->far = h < st->far ? h : st->far;
    }
}

/* The center of sample i of the line from q0 by -s. */
static const double *point_of(const st_grid *g, const long q0[3], const int s[3], long i,
                              double pt[3])
{
    for (int c = 0; c < 3; c++)
        pt[c] = g->origin[c] + g->voxel * (double)(q0[c] - i * s[c]);
    return pt;
}

/* Whether point q is within sqrt(d2) of the seen soup (seen NULL: yes):
 * the first triangle within it will do (st_bvh_within finds one exactly
 * when the nearest search does). */
static int near_seen(const st_bvh *seen, const double q[3], double d2)
{
    return !seen || st_bvh_within(seen, q, d2);
}

st_status st_sides_mirror(st_grid *g, const st_soup *soup, size_t seen_triangles,
                          const st_sides_stats *st, size_t *changed, st_error *err)
{
    *changed = 0;
    if (!st->fold)
        return ST_OK;
    /* the seen soup alone, when soup has caps: the runs continue past them */
    st_bvh *seen = NULL;
    st_soup *o = NULL;   /* the BVH's soup: kept while it is */
    if (soup && seen_triangles && seen_triangles < soup->ntris) {
        o = st_soup_new();
        st_status rc = o ? ST_OK : st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory");
        for (size_t v = 0; !rc && v < soup->nverts; v++)
            rc = st_soup_add_vertex(o, soup->xyz[3 * v], soup->xyz[3 * v + 1],
                                    soup->xyz[3 * v + 2], err);
        for (size_t t = 0; !rc && t < seen_triangles; t++)
            rc = st_soup_add_triangle(o, soup->tris[3 * t], soup->tris[3 * t + 1],
                                      soup->tris[3 * t + 2], err);
        rc = rc ? rc : st_bvh_build(&seen, o, err);
        if (rc) {
            st_soup_free(o);
            return rc;
        }
    }
    const int *s = st->step;
    const double sl = sqrt((double)(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]));
    /* a line crossing the surface between two samples a step apart has
     * one of them within half a step of it */
    const float near = (float)(0.5 * sl * g->voxel);
    const long dims[3] = {(long)g->nx, (long)g->ny, (long)g->nz};
    const long maxlen = dims[0] + dims[1] + dims[2] + 1;
    const double d2 = (double)near * (double)near;
    size_t count = 0;
    int oom = 0;
    /* Each line {q - k s} starts where q + s leaves the grid; lines are
     * disjoint, so the threads write disjoint voxels. */
    #pragma omp parallel reduction(+ : count) reduction(| : oom)
    {
        size_t *line = malloc((size_t)maxlen * sizeof *line);
        if (!line)
            oom = 1;
        #pragma omp for schedule(dynamic, 16)
        for (size_t z = 0; z < g->nz; z++)
            for (size_t y = 0; y < g->ny && line; y++)
                for (size_t x = 0; x < g->nx; x++) {
                    const long q0[3] = {(long)x, (long)y, (long)z};
                    int start = 0;
                    for (int k = 0; k < 3; k++)
                        start |= q0[k] + s[k] < 0 || q0[k] + s[k] >= dims[k];
                    if (!start)
                        continue;
                    long n = 0;
                    double pt[3];
                    long q[3] = {q0[0], q0[1], q0[2]};
                    while (q[0] >= 0 && q[0] < dims[0] && q[1] >= 0 && q[1] < dims[1] &&
                           q[2] >= 0 && q[2] < dims[2]) {
                        line[n++] = st_grid_index(g, (size_t)q[0], (size_t)q[1], (size_t)q[2]);
                        for (int k = 0; k < 3; k++)
                            q[k] -= s[k];
                    }
                    /* the run of inside samples farthest from the viewer */
                    long b = n - 1;
                    while (b >= 0 && !(g->data[line[b]] < 0.0f))
                        b--;
                    if (b < 0)
                        continue;
                    long a = b;
                    while (a > 0 && g->data[line[a - 1]] < 0.0f)
                        a--;
                    /* ends on a seen wall: nothing to continue */
                    if ((fabsf(g->data[line[b]]) <= near &&
                         near_seen(seen, point_of(g, q0, s, b, pt), d2)) ||
                        (b + 1 < n && fabsf(g->data[line[b + 1]]) <= near &&
                         near_seen(seen, point_of(g, q0, s, b + 1, pt), d2)))
                        continue;
                    const long len = b - a + 1;
                    for (long i = b + 1; i < n && i <= b + len; i++) {
                        float *d = &g->data[line[i]];
                        double h = 0.0;
                        for (int c = 0; c < 3; c++)
                            h += (g->origin[c] + g->voxel * (double)(q0[c] - i * s[c])) * s[c];
                        if ((fabsf(*d) <= near && near_seen(seen, point_of(g, q0, s, i, pt), d2)) ||
                            h / sl < st->far)
                            break;
                        *d = st_grid_signed_value(*d, 1);
                        count++;
                    }
                }
        free(line);
    }
    st_bvh_free(seen);
    st_soup_free(o);
    *changed = count;
    if (oom)
        return st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory for the mirror");
    return ST_OK;
}

/* The steps of st_sides_evidence_edges (defined after it). */
static void region_scores(double *score, double *share, const st_grid *g, const uint8_t *votes,
                          const st_soup *s, const st_soup_edges *E, const uint8_t *flip,
                          const uint32_t *region);
static st_status oriented_soup(st_soup *o, uint8_t *rim, size_t *nview, st_sides_stats *st,
                               const st_soup *s, const st_soup_edges *E, const uint32_t *nbr,
                               const uint8_t *flip, const uint32_t *region, const double *score,
                               const st_sides_params *p, st_error *err);
static size_t winding_evidence(int8_t *evidence, const st_grid *g, const uint8_t *votes,
                               int decided, const st_bvh *bvh, const st_soup *o,
                               const st_sides_params *p);

st_status st_sides_evidence(int8_t *evidence, const st_grid *g, const uint8_t *votes,
                            int decided, const st_soup *s,
                            const st_sides_params *p, st_sides_stats *stats,
                            st_error *err)
{
    return st_sides_evidence_edges(evidence, g, votes, decided, s, NULL, p, stats, err);
}

st_status st_sides_evidence_edges(int8_t *evidence, const st_grid *g, const uint8_t *votes,
                                  int decided, const st_soup *s, const st_soup_edges *edges,
                                  const st_sides_params *p, st_sides_stats *stats,
                                  st_error *err)
{
    st_sides_stats local;
    st_sides_stats *st = stats ? stats : &local;
    memset(st, 0, sizeof *st);
    const size_t n = st_grid_count(g);
    memset(evidence, 0, n);
    st_soup_edges own;
    st_status rc = edges ? ST_OK : st_soup_edges_build(&own, s, err);
    if (rc)
        return rc;
    const st_soup_edges E = edges ? *edges : own;
    const size_t nt = s->ntris;
    uint32_t *nbr = st_malloc_array(3 * nt + 1, sizeof *nbr);
    uint8_t *same = st_malloc_array(3 * nt + 1, 1);
    uint8_t *flip = st_malloc_array(nt + 1, 1);
    uint8_t *rim = st_malloc_array(nt + 1, 1);
    uint32_t *region = st_malloc_array(nt + 1, sizeof *region);
    uint32_t *queue = st_malloc_array(nt + 1, sizeof *queue);
    double *score = st_calloc_array(nt + 1, sizeof *score);
    double *share = st_malloc_array(nt + 1, sizeof *share);
    st_soup *o = st_soup_new();
    st_bvh *bvh = NULL;
    if (!nbr || !same || !flip || !rim || !region || !queue || !score || !share || !o) {
        rc = st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory for the soup's sides");
        goto done;
    }
    st_soup_edges_neighbours(&E, s, nbr, same, NULL);

    /* 1. orientable regions, by propagation */
    st->conflicts = st_soup_edges_orient(&E, s, nbr, same, flip, region, queue, NULL);
    for (size_t t = 0; t < nt; t++)
        st->regions += E.kept[t] && region[t] == t;
    /* 2. each region turned to the votes' reading */
    region_scores(score, share, g, votes, s, &E, flip, region);
    size_t nview = 0;
    if ((rc = oriented_soup(o, rim, &nview, st, s, &E, nbr, flip, region, score, p, err)))
        goto done;
    if (o->ntris == 0)
        goto done;
    if ((rc = st_bvh_build(&bvh, o, err)))
        goto done;
    /* 3. the local winding number near the soup; 4. the view */
    st->voxels = winding_evidence(evidence, g, votes, decided, bvh, o, p);
    view_of(o, nview, rim, p, st);
done:
    st_bvh_free(bvh);
    st_soup_free(o);
    if (!edges)
        st_soup_edges_free(&own);
    free(nbr);
    free(same);
    free(flip);
    free(rim);
    free(region);
    free(queue);
    free(score);
    free(share);
    return rc;
}

/* 2. Triangle t's share of its region's score: the votes' reading of its
 * sides (front outside, back inside: agrees), its half area, signed; 0
 * where it has none (left out, no area, or both sides read alike). */
static double triangle_share(const st_grid *g, const uint8_t *votes, const st_soup *s,
                             const st_soup_edges *E, const uint8_t *flip, size_t t)
{
    if (!E->kept[t])
        return 0.0;
    const double off = 1.5 * g->voxel;
    const uint32_t *v = s->tris + 3 * t;
    const double *A = s->xyz + 3 * (size_t)v[0], *B = s->xyz + 3 * (size_t)v[1],
                 *C = s->xyz + 3 * (size_t)v[2];
    double u[3], w[3], nrm[3], c[3];
    for (int k = 0; k < 3; k++) {
        u[k] = B[k] - A[k];
        w[k] = C[k] - A[k];
        c[k] = (A[k] + B[k] + C[k]) / 3.0;
    }
    nrm[0] = u[1] * w[2] - u[2] * w[1];
    nrm[1] = u[2] * w[0] - u[0] * w[2];
    nrm[2] = u[0] * w[1] - u[1] * w[0];
    const double len = sqrt(nrm[0] * nrm[0] + nrm[1] * nrm[1] + nrm[2] * nrm[2]);
    if (!(len > 0.0))
        return 0.0;
    const double sgn = flip[t] ? -1.0 : 1.0;
    double front[3], back[3];
    for (int k = 0; k < 3; k++) {
        front[k] = c[k] + sgn * off * nrm[k] / len;
        back[k] = c[k] - sgn * off * nrm[k] / len;
    }
    const size_t fi = voxel_at(g, front), bi = voxel_at(g, back);
    const int fin = fi != SIZE_MAX && (votes[fi] & ST_SIGN_VOTES_INSIDE);
    const int bin = bi != SIZE_MAX && (votes[bi] & ST_SIGN_VOTES_INSIDE);
    if (fin == bin)
        return 0.0;
    return bin ? 0.5 * len : -0.5 * len;   /* front outside, back inside: agrees */
}

/* 2. Each region's score: its triangles' shares (triangle_share), taken
 * in parallel into share[], then added in triangle order (the sums of one
 * loop, bit for bit: a share of 0 adds nothing). */
static void region_scores(double *score, double *share, const st_grid *g, const uint8_t *votes,
                          const st_soup *s, const st_soup_edges *E, const uint8_t *flip,
                          const uint32_t *region)
{
    const ptrdiff_t nt = (ptrdiff_t)s->ntris;
    #pragma omp parallel for schedule(static) if (nt >= 4096)
    for (ptrdiff_t t = 0; t < nt; t++)
        share[t] = triangle_share(g, votes, s, E, flip, (size_t)t);
    for (size_t t = 0; t < s->ntris; t++)
        if (share[t] != 0.0)
            score[region[t]] += share[t];
}

/* The soup s oriented (o: each region turned to its score), the rim of
 * its seen triangles (rim[*nview]), the regions turned, and the column
 * rule's direction: the axis direction the seen soup faces most
 * exclusively. */
static st_status oriented_soup(st_soup *o, uint8_t *rim, size_t *nview, st_sides_stats *st,
                               const st_soup *s, const st_soup_edges *E, const uint32_t *nbr,
                               const uint8_t *flip, const uint32_t *region, const double *score,
                               const st_sides_params *p, st_error *err)
{
    const size_t nt = s->ntris;
    st_status rc = ST_OK;
    for (size_t v = 0; v < s->nverts; v++)
        if ((rc = st_soup_add_vertex(o, s->xyz[3 * v], s->xyz[3 * v + 1], s->xyz[3 * v + 2],
                                     err)))
            return rc;
    const size_t seen = p->seen_triangles && p->seen_triangles < nt ? p->seen_triangles : nt;
    const size_t cseen = p->column_seen && p->column_seen < nt ? p->column_seen : nt;
    double axis_area[3][2] = {{0.0}};   /* [axis][0: facing +, 1: facing -] */
    for (size_t t = 0; t < nt; t++) {
        if (!E->kept[t])
            continue;
        if (t < seen) {
            /* on the seen surface's boundary: a free edge or one shared
             * with a cap */
            int edge = 0;
            for (size_t slot = 3 * t; slot < 3 * t + 3; slot++)
                edge |= nbr[slot] == ST_EDGES_NONE || nbr[slot] >= seen;
            rim[(*nview)++] = (uint8_t)edge;
        }
        if (region[t] == t && score[t] < 0.0)
            st->turned++;
        const int back = flip[t] ^ (score[region[t]] < 0.0);
        const uint32_t *v = s->tris + 3 * t;
        if ((rc = st_soup_add_triangle(o, v[0], back ? v[2] : v[1], back ? v[1] : v[2], err)))
            return rc;
        if (t < cseen) {
            double an[3];
            tri_normal(o, o->ntris - 1, an);
            for (int k = 0; k < 3; k++)
                axis_area[k][an[k] < 0.0] += fabs(an[k]);
        }
    }
    st->column_back_front = INFINITY;
    for (int k = 0; k < 3; k++)
        for (int d = 0; d < 2; d++) {
            const double front = axis_area[k][d], back = axis_area[k][1 - d];
            const double r = front > 0.0 ? back / front : INFINITY;
            if (r < st->column_back_front) {
                st->column_back_front = r;
                st->column_axis = k;
                st->column_dir = d ? -1 : 1;
            }
        }
    st->columns = st->column_back_front < p->column_ratio;
    return ST_OK;
}

/* The triangles of o whose boxes meet a box, gathered by one query of the
 * BVH (st_bvh_query_box's triangles, in its order): their boxes along x
 * and y (the BVH's: the least and most of the corners) and their
 * corners. The box is a block of voxels' (a few rows of one z slice, a
 * stretch along x) with each voxel's extent along z, so only x and y are
 * tested again. sel: the ones a run of voxels along a row reads (indices
 * into v, in the query's order). box: the same boxes by groups of four
 * triangles (GROUP doubles a group: the four's least x, their most x,
 * least y, most y), so that the selection tests four at once; the last
 * group's lanes from n on never meet a box. oom: a growth failed (the
 * voxels then query the BVH each). */
typedef struct gather {
    const st_soup *o;
    size_t n, cap;
    double *v;          /* GATHERED a triangle: its box along x, along y, its corners */
    double *box;        /* cap / 4 groups */
    uint32_t *sel;      /* cap of them */
    size_t nsel;
    int oom;
} gather;
#define GATHERED 13
#define GROUP 16

static void gather_free(gather *g)
{
    free(g->v);
    free(g->box);
    free(g->sel);
}

/* ga's arrays grown to twice their size (256 at first); 1 (and ga->oom)
 * when memory runs out. Apart from gather_add, which then needs no
 * registers saved. */
#if defined(__GNUC__)
__attribute__((noinline))
#endif
static int gather_grow(gather *g)
{
    const size_t c = g->cap ? 2 * g->cap : 256;
    double *nv = st_realloc_array(g->v, c, GATHERED * sizeof *nv);
    if (nv)
        g->v = nv;
    double *nb = nv ? st_realloc_array(g->box, c / 4, GROUP * sizeof *nb) : NULL;
    if (nb)
        g->box = nb;
    uint32_t *ns = nb ? st_realloc_array(g->sel, c, sizeof *ns) : NULL;
    if (!ns) {
        g->oom = 1;
        return 1;
    }
    g->sel = ns;
    g->cap = c;
    return 0;
}

static int gather_add(void *ctx, uint32_t t)
{
    gather *g = ctx;
    if (g->n == g->cap && gather_grow(g))
        return 1;
    const uint32_t *tv = g->o->tris + 3 * (size_t)t;
    const double *A = g->o->xyz + 3 * (size_t)tv[0], *B = g->o->xyz + 3 * (size_t)tv[1],
                 *C = g->o->xyz + 3 * (size_t)tv[2];
    /* the corners read once, the box taken from them */
    const double ax = A[0], ay = A[1], az = A[2], bx = B[0], by = B[1], bz = B[2];
    const double cx = C[0], cy = C[1], cz = C[2];
    double *b = g->v + GATHERED * g->n++;
    /* finite coordinates (soup.h): the BVH's fmin and fmax */
    const double xlo = ax < bx ? ax : bx, xhi = ax > bx ? ax : bx;
    const double ylo = ay < by ? ay : by, yhi = ay > by ? ay : by;
    b[0] = cx < xlo ? cx : xlo;
    b[1] = cx > xhi ? cx : xhi;
    b[2] = cy < ylo ? cy : ylo;
    b[3] = cy > yhi ? cy : yhi;
    double *q = g->box + GROUP * ((g->n - 1) / 4) + (g->n - 1) % 4;
    q[0] = b[0], q[4] = b[1], q[8] = b[2], q[12] = b[3];
    b[4] = ax, b[5] = ay, b[6] = az;
    b[7] = bx, b[8] = by, b[9] = bz;
    b[10] = cx, b[11] = cy, b[12] = cz;
    return 0;
}

/* ga: the triangles meeting [lo, hi]. */
static void gather_box(gather *ga, const st_bvh *bvh, const double lo[3], const double hi[3])
{
    ga->n = 0;
    ga->nsel = 0;
    ga->oom = 0;
    st_bvh_query_box(bvh, lo, hi, gather_add, ga);
    /* the last group's other lanes: boxes from +inf to -inf */
    for (size_t i = ga->n; !ga->oom && i % 4; i++) {
        double *q = ga->box + GROUP * (i / 4) + i % 4;
        q[0] = q[8] = INFINITY;
        q[4] = q[12] = -INFINITY;
    }
}

#if defined(__GNUC__) && defined(__x86_64__)
/* gather_select four triangles at a time (AVX: the same tests, <= on
 * each bound, in the same order of the triangles). */
__attribute__((target("avx"))) static void gather_select4(gather *ga, double x0, double x1,
                                                           double y0, double y1)
{
    const __m256d vx0 = _mm256_set1_pd(x0), vx1 = _mm256_set1_pd(x1);
    const __m256d vy0 = _mm256_set1_pd(y0), vy1 = _mm256_set1_pd(y1);
    size_t m = 0;
    for (size_t i = 0; i < ga->n; i += 4) {
        const double *q = ga->box + GROUP * (i / 4);
        const __m256d in = _mm256_and_pd(
            _mm256_and_pd(_mm256_cmp_pd(_mm256_loadu_pd(q), vx1, _CMP_LE_OQ),
                          _mm256_cmp_pd(vx0, _mm256_loadu_pd(q + 4), _CMP_LE_OQ)),
            _mm256_and_pd(_mm256_cmp_pd(_mm256_loadu_pd(q + 8), vy1, _CMP_LE_OQ),
                          _mm256_cmp_pd(vy0, _mm256_loadu_pd(q + 12), _CMP_LE_OQ)));
        for (unsigned k = (unsigned)_mm256_movemask_pd(in); k; k &= k - 1)
            ga->sel[m++] = (uint32_t)(i + (size_t)__builtin_ctz(k));
    }
    ga->nsel = m;
}
#endif

/* ga->sel: the gathered triangles whose boxes meet [x0, x1] x [y0, y1]. */
static void gather_select(gather *ga, double x0, double x1, double y0, double y1)
{
#if defined(__GNUC__) && defined(__x86_64__)
    if (__builtin_cpu_supports("avx")) {
        gather_select4(ga, x0, x1, y0, y1);
        return;
    }
#endif
    size_t m = 0;
    for (size_t i = 0; i < ga->n; i++) {
        const double *b = ga->v + GATHERED * i;
        if (b[0] <= x1 && x0 <= b[1] && b[2] <= y1 && y0 <= b[3])
            ga->sel[m++] = (uint32_t)i;
    }
    ga->nsel = m;
}

/* The evidence from the triangles of the BVH's soup whose boxes meet
 * [lo, hi] at point q: scale times the sum of their solid angles (term by
 * term, in the BVH's order), clamped to [-cap, cap], rounded. */
static int8_t winding_sum(const st_bvh *bvh, const double q[3], const double lo[3],
                          const double hi[3], double scale, double cap)
{
    wsum s = {bvh->soup, q, 0.0};
    st_bvh_query_box(bvh, lo, hi, add_angle, &s);
    double e = scale * s.sum;
    e = e > cap ? cap : e < -cap ? -cap : e;
    return (int8_t)lround(e);
}

/* winding_sum's evidence (from the triangles of ga's selection meeting
 * [lo, hi], when that holds every triangle meeting [lo, hi]), from the
 * product of mul_angle when rounding is sure: that and add_angle's sum
 * each differ from the true sum by a few units in the last place per term
 * (one argument's rounding; a complex product's), and those on the
 * partial sums, well within DRIFT (m + 4)^2 radians for m terms, in any
 * order of the terms; else by winding_sum, as it always was. */
#define DRIFT 1e-13

/* The evidence the product w reads: 1 and *e when its rounding is sure
 * (DRIFT), else 0. */
static int prod_evidence(const wprod *w, double scale, double cap, int8_t *e)
{
    const double m = (double)w->terms + 4.0;
    const double sum = 2.0 * (atan2(w->im, w->re) + 2.0 * M_PI * (double)w->turns);
    const double d = scale * 2.0 * DRIFT * m * m;
    double e0 = scale * sum - d, e1 = scale * sum + d;
    e0 = e0 > cap ? cap : e0 < -cap ? -cap : e0;
    e1 = e1 > cap ? cap : e1 < -cap ? -cap : e1;
    if (lround(e0) != lround(e1))
        return 0;
    *e = (int8_t)lround(e0);
    return 1;
}

static int8_t winding_at(const st_bvh *bvh, const gather *ga, const double q[3], const double lo[3],
                         const double hi[3], double scale, double cap, double unit)
{
    wprod w = {bvh->soup, q, 1.0, 0.0, 0, 0, unit};
    int exact = 0;
    if (ga) {   /* its selection meets [lo, hi] along y and z */
        wprod acc = w;  /* kept apart from the BVH's callback, in registers */
        for (size_t i = 0; i < ga->nsel && !exact; i++) {
            const double *b = ga->v + GATHERED * (size_t)ga->sel[i];
            if (!(b[0] <= hi[0] && lo[0] <= b[1]))
                continue;
            const double u0[3] = {b[4] - q[0], b[5] - q[1], b[6] - q[2]};
            const double u1[3] = {b[7] - q[0], b[8] - q[1], b[9] - q[2]};
            const double u2[3] = {b[10] - q[0], b[11] - q[1], b[12] - q[2]};
            exact = prod_term(&acc, u0, u1, u2);
        }
        w = acc;
    } else {
        exact = st_bvh_query_box(bvh, lo, hi, mul_angle, &w);
    }
    int8_t e;
    if (!exact && prod_evidence(&w, scale, cap, &e))
        return e;
    return winding_sum(bvh, q, lo, hi, scale, cap);
}

#if defined(__GNUC__) && defined(__x86_64__)
#define SIDES_AVX 1
#define AVX_FN __attribute__((target("avx")))
/* V (= 4) points at once: AVX's four lanes of doubles, where the processor
 * has it (st_sides_winding_points' how 2; the others read one point at a
 * time). Each lane mirrors the scalar code operation for operation. */
#define V 4
#define M_ _mm256_mul_pd
#define A_ _mm256_add_pd
#define S_ _mm256_sub_pd

/* solid_terms for V points at once (lane l: the corners less point l), by
 * the same operations in the same order: each lane's det and den are
 * solid_terms' bit for bit (no contraction: the Makefile's FP_EXACT). */
static inline AVX_FN void solid_terms4(const __m256d a[3], const __m256d b[3], const __m256d c[3],
                                       __m256d *det, __m256d *den)
{
    const __m256d la = _mm256_sqrt_pd(A_(A_(M_(a[0], a[0]), M_(a[1], a[1])), M_(a[2], a[2])));
    const __m256d lb = _mm256_sqrt_pd(A_(A_(M_(b[0], b[0]), M_(b[1], b[1])), M_(b[2], b[2])));
    const __m256d lc = _mm256_sqrt_pd(A_(A_(M_(c[0], c[0]), M_(c[1], c[1])), M_(c[2], c[2])));
    *det = A_(S_(M_(a[0], S_(M_(b[1], c[2]), M_(b[2], c[1]))),
                 M_(a[1], S_(M_(b[0], c[2]), M_(b[2], c[0])))),
              M_(a[2], S_(M_(b[0], c[1]), M_(b[1], c[0]))));
    const __m256d ab = A_(A_(M_(a[0], b[0]), M_(a[1], b[1])), M_(a[2], b[2]));
    const __m256d bc = A_(A_(M_(b[0], c[0]), M_(b[1], c[1])), M_(b[2], c[2]));
    const __m256d ca = A_(A_(M_(c[0], a[0]), M_(c[1], a[1])), M_(c[2], a[2]));
    *den = A_(A_(A_(M_(M_(la, lb), lc), M_(ab, lc)), M_(bc, la)), M_(ca, lb));
}

/* V products of prod_term's at once (lane l: point l's), with their turns
 * (whole numbers; taken lane by lane, rarely) and terms (whole numbers,
 * exact as doubles). */
typedef struct wprod4 {
    __m256d re, im, terms, unit;
    long turns[V];
} wprod4;

/* b where mask's lanes are all ones, else a: vblendvpd, by hand (GCC 12
 * takes _mm256_blendv_pd lane by lane where it sees a mask of compares). */
static inline AVX_FN __m256d blend4(__m256d a, __m256d b, __m256d mask)
{
    __m256d out;
    __asm__("vblendvpd %3, %2, %1, %0" : "=x"(out) : "x"(a), "x"(b), "x"(mask));
    return out;
}

/* prod_term for the lanes of act (all ones in a lane it takes) with their
 * det and den: returns the lanes that must take the sum instead (left as
 * they were; all ones). */
static inline AVX_FN __m256d prod_term4(wprod4 *w, __m256d act, __m256d det, __m256d den)
{
    const __m256d mag = _mm256_castsi256_pd(_mm256_set1_epi64x(0x7FFFFFFFFFFFFFFFLL));
    const __m256d zero = _mm256_setzero_pd();
    /* prod_term's m: |den| > |det| ? |den| : |det| (maxpd's order) */
    const __m256d m = _mm256_max_pd(_mm256_and_pd(den, mag), _mm256_and_pd(det, mag));
    const __m256d bad = _mm256_or_pd(
        _mm256_and_pd(_mm256_cmp_pd(det, zero, _CMP_EQ_OQ), _mm256_cmp_pd(den, zero, _CMP_NGT_UQ)),
        _mm256_or_pd(_mm256_cmp_pd(m, _mm256_set1_pd(0x1p-300), _CMP_NGE_UQ),
                     _mm256_cmp_pd(m, _mm256_set1_pd(0x1p300), _CMP_NLE_UQ)));
    const __m256d upd = _mm256_andnot_pd(bad, act);
    det = M_(det, w->unit);
    den = M_(den, w->unit);
    const __m256d re = S_(M_(w->re, den), M_(w->im, det));
    const __m256d im = A_(M_(w->re, det), M_(w->im, den));
    /* prod_term's turn: in the sign bits, the old imaginary part's equal
     * to det's and unequal to the new one's; up (the old one's clear) one
     * turn more, else one less. Rare: lane by lane. */
    const int turn = _mm256_movemask_pd(_mm256_and_pd(
        upd, _mm256_andnot_pd(_mm256_xor_pd(w->im, det), _mm256_xor_pd(w->im, im))));
    if (turn) {
        const int down = _mm256_movemask_pd(w->im);
        for (int l = 0; l < V; l++)
            if (turn >> l & 1)
                w->turns[l] += down >> l & 1 ? -1 : 1;
    }
    w->re = blend4(w->re, re, upd);
    w->im = blend4(w->im, im, upd);
    w->terms = A_(w->terms, _mm256_and_pd(upd, _mm256_set1_pd(1.0)));
    /* (the lanes not taking it are as they were: within range) */
    const __m256d r = _mm256_max_pd(_mm256_and_pd(w->re, mag), _mm256_and_pd(w->im, mag));
    const int far = _mm256_movemask_pd(
        _mm256_or_pd(_mm256_cmp_pd(r, _mm256_set1_pd(0x1p64), _CMP_NLE_UQ),
                     _mm256_cmp_pd(r, _mm256_set1_pd(0x1p-64), _CMP_NGE_UQ)));
    if (far) {   /* prod_term's rescale, lane by lane */
        double vr[V], vi[V];
        _mm256_storeu_pd(vr, w->re);
        _mm256_storeu_pd(vi, w->im);
        for (int l = 0; l < V; l++)
            if (far >> l & 1) {
                wprod o = {NULL, NULL, vr[l], vi[l], 0, 0, 1.0};
                rescale(&o);
                vr[l] = o.re;
                vi[l] = o.im;
            }
        w->re = _mm256_loadu_pd(vr);
        w->im = _mm256_loadu_pd(vi);
    }
    return _mm256_and_pd(act, bad);
}

/* winding_at over ga's selection for the n (2..V) points (x[l], y, z) at
 * once: each lane takes the terms winding_at takes for its point, in the
 * same order, by the same operations, so its product, turns and terms are
 * winding_at's bit for bit, and so is its evidence (the same fallback on
 * winding_sum). Lanes from n on copy the last point and take nothing. */
static AVX_FN void winding_quad(int8_t *out, const st_bvh *bvh, const gather *ga, const double *x,
                                size_t n, double y, double z, double r, double scale, double cap)
{
    double xs[V], ys[V], zs[V];
    for (size_t l = 0; l < V; l++) {
        xs[l] = x[l < n ? l : n - 1];
        ys[l] = y;
        zs[l] = z;
    }
    /* (y and z loaded as vectors: GCC 12 takes what it sees is the same
     * in every lane one lane at a time, then broadcasts each result) */
    const __m256d qx = _mm256_loadu_pd(xs), qy = _mm256_loadu_pd(ys), qz = _mm256_loadu_pd(zs);
    const __m256d lox = S_(qx, _mm256_set1_pd(r)), hix = A_(qx, _mm256_set1_pd(r));
    const __m256d zero = _mm256_setzero_pd();
    wprod4 w = {_mm256_set1_pd(1.0), zero, zero, _mm256_set1_pd(term_unit(r)), {0, 0, 0, 0}};
    __m256d stop = _mm256_castsi256_pd(_mm256_set_epi64x(-(long long)(n < 4), -(long long)(n < 3),
                                                         -(long long)(n < 2), 0));
    for (size_t i = 0; i < ga->nsel; i++) {
        const double *b = ga->v + GATHERED * (size_t)ga->sel[i];
        const __m256d act = _mm256_andnot_pd(
            stop, _mm256_and_pd(_mm256_cmp_pd(_mm256_set1_pd(b[0]), hix, _CMP_LE_OQ),
                                _mm256_cmp_pd(lox, _mm256_set1_pd(b[1]), _CMP_LE_OQ)));
        if (!_mm256_movemask_pd(act))
            continue;
        const __m256d u0[3] = {S_(_mm256_set1_pd(b[4]), qx), S_(_mm256_set1_pd(b[5]), qy),
                               S_(_mm256_set1_pd(b[6]), qz)};
        const __m256d u1[3] = {S_(_mm256_set1_pd(b[7]), qx), S_(_mm256_set1_pd(b[8]), qy),
                               S_(_mm256_set1_pd(b[9]), qz)};
        const __m256d u2[3] = {S_(_mm256_set1_pd(b[10]), qx), S_(_mm256_set1_pd(b[11]), qy),
                               S_(_mm256_set1_pd(b[12]), qz)};
        __m256d det, den;
        solid_terms4(u0, u1, u2, &det, &den);
        stop = _mm256_or_pd(stop, prod_term4(&w, act, det, den));
    }
    double vr[V], vi[V], vn[V];
    _mm256_storeu_pd(vr, w.re);
    _mm256_storeu_pd(vi, w.im);
    _mm256_storeu_pd(vn, w.terms);
    const int stopped = _mm256_movemask_pd(stop);
    for (size_t l = 0; l < n; l++) {
        const double q[3] = {x[l], y, z};
        const double lo[3] = {q[0] - r, q[1] - r, q[2] - r};
        const double hi[3] = {q[0] + r, q[1] + r, q[2] + r};
        const wprod o = {bvh->soup, q, vr[l], vi[l], w.turns[l], (size_t)vn[l], 1.0};
        if (stopped >> l & 1 || !prod_evidence(&o, scale, cap, &out[l]))
            out[l] = winding_sum(bvh, q, lo, hi, scale, cap);
    }
}
#undef M_
#undef A_
#undef S_
#endif

/* Voxels along a row whose triangles are selected at once: at most RUN,
 * spanning at most RUN voxels. Rows gathered by one query: BLOCK of a z
 * slice, over a stretch of at most SPAN voxels along x. */
#define RUN 12
#define BLOCK 8
#define SPAN 24

/* The evidence at the points (x[k], y, z), k < n, x ascending (see
 * sides_internal.h): how 2 with ga reads the triangles ga gathered (by a
 * box holding the cube of half-side r around each point, with their
 * extent along z), selected for them all at once. */
static void winding_points(int8_t *out, const st_bvh *bvh, gather *ga, const double *x, size_t n,
                           double y, double z, double r, double scale, double cap, int how)
{
    const gather *use = how == 2 && ga && !ga->oom ? ga : NULL;
    size_t k = 0;
    if (use)
        gather_select(ga, x[0] - r, x[n - 1] + r, y - r, y + r);
#ifdef SIDES_AVX
    if (use && n >= 2 && __builtin_cpu_supports("avx"))
        for (; k + 2 <= n; k += V)   /* V points at a time (at least 2) */
            winding_quad(out + k, bvh, use, x + k, n - k < V ? n - k : V, y, z, r, scale, cap);
#endif
    for (; k < n; k++) {
        const double q[3] = {x[k], y, z};
        const double lo[3] = {q[0] - r, q[1] - r, q[2] - r};
        const double hi[3] = {q[0] + r, q[1] + r, q[2] + r};
        out[k] = how == 0 ? winding_sum(bvh, q, lo, hi, scale, cap)
                          : winding_at(bvh, use, q, lo, hi, scale, cap, term_unit(r));
    }
}

void st_sides_winding_points(int8_t *out, const st_bvh *bvh, const double *x, size_t n,
                             double y, double z, double r, double scale, double cap, int how)
{
    gather ga = {bvh->soup, 0, 0, NULL, NULL, NULL, 0, 0};
    if (n && how == 2) {
        const double lo[3] = {x[0] - r, y - r, z - r}, hi[3] = {x[n - 1] + r, y + r, z + r};
        gather_box(&ga, bvh, lo, hi);
    }
    if (n)
        winding_points(out, bvh, &ga, x, n, y, z, r, scale, cap, how);
    gather_free(&ga);
}

/* What the sides' evidence reads: the field's band, the votes that decide
 * a voxel alone, the oriented soup's BVH, the cube's half-side r, the
 * scale and the cap of the evidence. */
typedef struct wctx {
    const st_grid *g;
    const uint8_t *votes;
    int decided;
    float band;
    const st_bvh *bvh;
    double r, scale, cap;
} wctx;

/* Whether voxel (x, y, z) takes evidence: in the band, undecided. */
static int takes(const wctx *c, size_t x, size_t y, size_t z)
{
    const size_t i = st_grid_index(c->g, x, y, z);
    const int margin = (int)(c->votes[i] & ST_SIGN_VOTES_COUNT) - 13;
    return fabsf(c->g->data[i]) < c->band && !(c->decided > 0 && abs(margin) >= c->decided);
}

/* The evidence of the voxels run[0..nr) of row (y, z), from the
 * triangles ga gathered around them; returns nr. */
static size_t winding_run(int8_t *evidence, const wctx *c, gather *ga, const size_t *run, size_t nr,
                          size_t y, size_t z)
{
    const st_grid *g = c->g;
    double x[RUN];
    int8_t e[RUN];
    for (size_t k = 0; k < nr; k++)
        x[k] = g->origin[0] + g->voxel * (double)run[k];
    winding_points(e, c->bvh, ga, x, nr, g->origin[1] + g->voxel * (double)y,
                   g->origin[2] + g->voxel * (double)z, c->r, c->scale, c->cap, 2);
    for (size_t k = 0; k < nr; k++)
        evidence[st_grid_index(g, run[k], y, z)] = e[k];
    return nr;
}

/* The evidence of the voxels that take it in rows y0..y1 (inclusive) of
 * slice z, x in [x0, x1), x0 and the last x taking it x1l: the triangles
 * near them gathered by one query, then read by runs (RUN) along each
 * row; returns how many voxels. */
static size_t winding_block(int8_t *evidence, const wctx *c, gather *ga, size_t x0, size_t x1,
                            size_t x1l, size_t y0, size_t y1, size_t z)
{
    const st_grid *g = c->g;
    const double zc = g->origin[2] + g->voxel * (double)z;
    const double lo[3] = {g->origin[0] + g->voxel * (double)x0 - c->r,
                          g->origin[1] + g->voxel * (double)y0 - c->r, zc - c->r};
    const double hi[3] = {g->origin[0] + g->voxel * (double)x1l + c->r,
                          g->origin[1] + g->voxel * (double)y1 + c->r, zc + c->r};
    gather_box(ga, c->bvh, lo, hi);
    size_t count = 0;
    for (size_t y = y0; y <= y1; y++) {
        size_t run[RUN], nr = 0;
        for (size_t x = x0; x <= x1; x++) {
            const int take = x < x1 && takes(c, x, y, z);
            if (nr && (x == x1 || (take && (nr == RUN || x - run[0] >= RUN)))) {
                count += winding_run(evidence, c, ga, run, nr, y, z);
                nr = 0;
            }
            if (take)
                run[nr++] = x;
        }
    }
    return count;
}

/* The evidence of the voxels that take it in rows y0..y1 of slice z, by
 * stretches of at most SPAN voxels along x (winding_block); returns how
 * many voxels. */
static size_t winding_rows(int8_t *evidence, const wctx *c, gather *ga, size_t y0, size_t y1,
                           size_t z)
{
    const size_t nx = c->g->nx;
    size_t count = 0;
    for (size_t x = 0; x < nx;) {
        size_t first = SIZE_MAX, last = 0;
        const size_t end = x + SPAN < nx ? x + SPAN : nx;
        for (size_t xi = x; xi < end; xi++)
            for (size_t y = y0; y <= y1; y++)
                if (takes(c, xi, y, z)) {
                    if (first == SIZE_MAX)
                        first = xi;
                    last = xi;
                    break;
                }
        if (first == SIZE_MAX) {
            x = end;
            continue;
        }
        /* the stretch from the first voxel taking it */
        const size_t x1 = first + SPAN < nx ? first + SPAN : nx;
        for (size_t xi = end; xi < x1; xi++)
            for (size_t y = y0; y <= y1; y++)
                if (takes(c, xi, y, z)) {
                    last = xi;
                    break;
                }
        count += winding_block(evidence, c, ga, first, x1, last, y0, y1, z);
        x = x1;
    }
    return count;
}

/* 3. The local winding number of the oriented soup (its BVH) near each
 * undecided voxel in the band, as evidence; returns how many voxels. The
 * triangles near a block of voxels (BLOCK rows of a slice, SPAN voxels
 * along x) are gathered by one query of the BVH, and each run of voxels
 * along a row (RUN) reads those of them near it. */
static size_t winding_evidence(int8_t *evidence, const st_grid *g, const uint8_t *votes,
                               int decided, const st_bvh *bvh, const st_soup *o,
                               const st_sides_params *p)
{
    const wctx c = {g, votes, decided, (float)(p->band_voxels * g->voxel), bvh,
                    p->radius_voxels * g->voxel, p->weight / (4.0 * M_PI),
                    (double)p->max_evidence};
    size_t count = 0, slices = 0;
    #pragma omp parallel for schedule(dynamic, 1) reduction(+ : count)
    for (size_t z = 0; z < g->nz; z++) {
        /* the progress line: the slices done, from the calling thread */
        const size_t done = __atomic_fetch_add(&slices, 1, __ATOMIC_RELAXED);
        if (omp_get_thread_num() == 0)
            st_progress_report(p->progress, "sides", 0.5 * (double)done / (double)g->nz);
        gather ga = {o, 0, 0, NULL, NULL, NULL, 0, 0};
        for (size_t y = 0; y < g->ny; y += BLOCK)
            count += winding_rows(evidence, &c, &ga, y, y + BLOCK < g->ny ? y + BLOCK - 1 : g->ny - 1,
                                  z);
        gather_free(&ga);
    }
    return count;
}

size_t st_sides_winding_grid(int8_t *evidence, const st_grid *g, const uint8_t *votes, int decided,
                             const st_bvh *bvh, const st_sides_params *p)
{
    return winding_evidence(evidence, g, votes, decided, bvh, bvh->soup, p);
}

typedef struct col_hit {
    double h;       /* dir * the coordinate along the axis, voxel units */
    uint32_t t;     /* the triangle */
} col_hit;

static int cmp_hit_desc(const void *a, const void *b)
{
    const col_hit *x = a, *y = b;
    return (x->h < y->h) - (x->h > y->h) ? (x->h < y->h) - (x->h > y->h)
                                         : (x->t > y->t) - (x->t < y->t);
}

/* Where the line of lattice point (i, j) (voxel units, axes a and b)
 * crosses triangle (A, B, C) (voxel units): 1 and *h its coordinate along
 * axis k, when the point is in the closed projected triangle (exact signs;
 * a projection of zero area crosses nothing). */
static int line_crosses(const double A[3], const double B[3], const double C[3], int k,
                        double i, double j, double *h)
{
    const int a = (k + 1) % 3, b = (k + 2) % 3;
    const double pa[2] = {A[a], A[b]}, pb[2] = {B[a], B[b]}, pc[2] = {C[a], C[b]};
    const double q[2] = {i, j};
    const int s = st_sign(st_orient2d(pa, pb, pc));
    if (!s)
        return 0;
    const double w0 = st_orient2d(pb, pc, q), w1 = st_orient2d(pc, pa, q),
                 w2 = st_orient2d(pa, pb, q);
    if (st_sign(w0) == -s || st_sign(w1) == -s || st_sign(w2) == -s)
        return 0;
    /* the depth by barycentric weights (a position, not a decision) */
    const double area = (pb[0] - pa[0]) * (pc[1] - pa[1]) - (pb[1] - pa[1]) * (pc[0] - pa[0]);
    const double l1 = ((pc[0] - pb[0]) * (q[1] - pb[1]) - (pc[1] - pb[1]) * (q[0] - pb[0])) / area;
    const double l2 = ((pa[0] - pc[0]) * (q[1] - pc[1]) - (pa[1] - pc[1]) * (q[0] - pc[0])) / area;
    *h = l1 * A[k] + l2 * B[k] + (1.0 - l1 - l2) * C[k];
    return 1;
}

/* For the caps of s (its triangles from the first nt on): *away gets 1
 * for each that faces away from the viewer (direction dir along axis k)
 * when oriented as the seen soup around it: each seen triangle faces the
 * viewer (walls square to the axis are left to their neighbours), and
 * that is carried across the edges of two triangles, breadth first from
 * the seen triangles in order (a conflict keeps the first). *top gets the
 * highest point along dir of its piece (the caps joined across their
 * edges of two; model units). Both hold s->ntris entries. */
static st_status exit_caps(uint8_t **away, double **top, const st_soup *s, size_t nt, int k,
                           int dir, st_error *err)
{
    const size_t n = s->ntris;
    st_soup_edges E;
    st_status rc = st_soup_edges_build(&E, s, err);
    if (rc)
        return rc;
    uint32_t *nbr = st_malloc_array(3 * n + 1, sizeof *nbr);
    uint8_t *same = st_malloc_array(3 * n + 1, 1);
    uint8_t *flip = st_malloc_array(n + 1, 1);
    uint32_t *queue = st_malloc_array(n + 1, sizeof *queue);
    *away = st_calloc_array(n + 1, 1);
    *top = st_calloc_array(n + 1, sizeof **top);
    if (!nbr || !same || !flip || !queue || !*away || !*top) {
        rc = st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory for the columns");
        goto done;
    }
    st_soup_edges_neighbours(&E, s, nbr, same, NULL);
    memset(flip, 2, n);
    size_t qt = 0;
    for (size_t t = 0; t < nt; t++) {
        double nrm[3];
        tri_normal(s, t, nrm);
        if (!E.kept[t] || nrm[k] == 0.0)
            continue;
        flip[t] = dir * nrm[k] < 0.0;
        queue[qt++] = (uint32_t)t;
    }
    for (size_t qh = 0; qh < qt; qh++) {
        const uint32_t t = queue[qh];
        for (size_t slot = 3 * (size_t)t; slot < 3 * (size_t)t + 3; slot++) {
            const uint32_t q = nbr[slot];
            if (q == ST_EDGES_NONE || flip[q] != 2)
                continue;
            flip[q] = (uint8_t)(flip[t] ^ same[slot]);
            queue[qt++] = q;
        }
    }
    /* the caps' pieces: bit 2 of *away marks a cap reached */
    for (size_t t0 = nt; t0 < n; t0++) {
        if (!E.kept[t0] || (*away)[t0] & 2)
            continue;
        size_t qh = 0, q1 = 0;
        double hi = -INFINITY;
        (*away)[t0] = 2;
        queue[q1++] = (uint32_t)t0;
        while (qh < q1) {
            const uint32_t t = queue[qh++];
            for (int c = 0; c < 3; c++)
                hi = fmax(hi, dir * s->xyz[3 * (size_t)s->tris[3 * (size_t)t + c] + k]);
            for (size_t slot = 3 * (size_t)t; slot < 3 * (size_t)t + 3; slot++) {
                const uint32_t q = nbr[slot];
                if (q != ST_EDGES_NONE && q >= nt && !((*away)[q] & 2)) {
                    (*away)[q] = 2;
                    queue[q1++] = q;
                }
            }
        }
        for (size_t i = 0; i < q1; i++) {
            const uint32_t t = queue[i];
            double nrm[3];
            tri_normal(s, t, nrm);
            (*away)[t] = (uint8_t)(2 | (flip[t] != 2 && dir * nrm[k] * (flip[t] ? -1.0 : 1.0) < 0.0));
            (*top)[t] = hi;
        }
    }
done:
    if (rc) {
        free(*away);
        free(*top);
        *away = NULL;
        *top = NULL;
    }
    st_soup_edges_free(&E);
    free(nbr);
    free(same);
    free(flip);
    free(queue);
    return rc;
}

/* The column rule on one field: the axis k (a and b across it) and the
 * direction dir the viewer looks along, the crossings of each line along
 * k (hit[start[col]..start[col + 1]), voxel units) and the caps' exits
 * (exit_caps: exits, ctop). */
typedef struct col_ctx {
    st_grid *g;
    int k, a, b, dir;
    size_t na, nb, nk, nt;      /* nt: the seen triangles (the caps after) */
    size_t *start;
    col_hit *hit;
    const uint8_t *exits;
    const double *ctop;
    float band;
} col_ctx;

/* The triangles' (the seen ones, then the caps exits marks) crossings of
 * each line along axis k, in voxel coordinates: counted, then stored
 * (pass 0, 1) in c->start, c->hit. */
static st_status col_crossings(col_ctx *c, const st_soup *s, size_t nall, st_error *err)
{
    const st_grid *g = c->g;
    const int k = c->k, a = c->a, b = c->b;
    const size_t na = c->na, nb = c->nb, ncol = na * nb;
    size_t *fill = st_calloc_array(ncol + 1, sizeof *fill);
    c->start = st_calloc_array(ncol + 1, sizeof *c->start);
    if (!c->start || !fill) {
        free(fill);
        return st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory for the columns");
    }
    size_t *start = c->start;
    for (int pass = 0; pass < 2; pass++) {
        for (size_t t = 0; t < nall; t++) {
            if (t >= c->nt && !(c->exits[t] & 1))
                continue;
            double P[3][3], lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
            for (int v = 0; v < 3; v++)
                for (int q = 0; q < 3; q++)
                    P[v][q] = (s->xyz[3 * (size_t)s->tris[3 * t + v] + q] - g->origin[q]) /
                              g->voxel;
            for (int v = 0; v < 3; v++) {
                lo[0] = fmin(lo[0], P[v][a]);
                hi[0] = fmax(hi[0], P[v][a]);
                lo[1] = fmin(lo[1], P[v][b]);
                hi[1] = fmax(hi[1], P[v][b]);
            }
            const double i0 = fmax(ceil(lo[0]), 0.0), i1 = fmin(floor(hi[0]), (double)na - 1);
            const double j0 = fmax(ceil(lo[1]), 0.0), j1 = fmin(floor(hi[1]), (double)nb - 1);
            for (double j = j0; j <= j1; j++)
                for (double i = i0; i <= i1; i++) {
                    double h;
                    if (!line_crosses(P[0], P[1], P[2], k, i, j, &h))
                        continue;
                    const size_t col = (size_t)i + na * (size_t)j;
                    if (pass) {
                        col_hit *x = &c->hit[start[col] + fill[col]++];
                        x->h = c->dir * h;
                        x->t = (uint32_t)t;
                    } else {
                        start[col + 1]++;
                    }
                }
        }
        if (pass)
            break;
        for (size_t q = 0; q < ncol; q++)
            start[q + 1] += start[q];
        c->hit = st_malloc_array(start[ncol] + 1, sizeof *c->hit);
        if (!c->hit) {
            free(fill);
            return st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory for the columns");
        }
    }
    free(fill);
    return ST_OK;
}

/* Where the solid of the segment line[first..end) after crossing seg - 1
 * (of n; h the crossings) ends: the step (inside, then outside) that the
 * confident voxels (|d| >= band) agree with most, then the first cap
 * that faces away below the entry (half a voxel clear of it and of the
 * next): where its piece rises less than a voxel above the crossing
 * (flat: the lost face, a pocket's ceiling), the solid ends there at the
 * latest; else, where the segment's solid ends at it or below, the air
 * run from it down to the next entry is mirrored above it (a bore's
 * lower half seen, its cap across the middle: the upper half), where
 * that leaves solid below the entry. */
static size_t col_split(const col_ctx *c, const size_t *line, size_t first, size_t end,
                        const col_hit *h, size_t seg, size_t n, const col_hit *cap, size_t ncap)
{
    const st_grid *g = c->g;
    const int dir = c->dir;
    const size_t nk = c->nk;
    size_t split = first;   /* inside before split */
    if (seg == 0)
        return split;
    long score = 0, best = 0;
    for (size_t i = first; i < end; i++) {
        const float d = g->data[line[i]];
        if (fabsf(d) >= c->band)
            score += d < 0.0f ? 1 : -1;
        if (score >= best) {
            best = score;
            split = i + 1;
        }
    }
    const double top = h[seg - 1].h - 0.5;
    const double bottom = seg < n ? h[seg].h + 0.5 : -INFINITY;
    for (size_t q = 0; q < ncap; q++) {
        if (!(cap[q].h < top && cap[q].h > bottom) || !(c->exits[cap[q].t] & 1))
            continue;
        size_t capi = first;   /* the first voxel below the cap */
        while (capi < end && dir * (double)(dir > 0 ? nk - 1 - capi : capi) > cap[q].h)
            capi++;
        const double rise = ((c->ctop[cap[q].t] - dir * g->origin[c->k]) / g->voxel) - cap[q].h;
        const size_t air = end - capi;
        if (rise < 1.0 && capi < split)
            split = capi;
        if (seg < n && split + 1 >= capi && rise >= 1.0 && air > 0 && air < capi - first &&
            capi - air < split)
            split = capi - air;
        break;
    }
    return split;
}

/* The column worker: line col's crossings sorted from the viewer, each
 * segment between them: nothing before the first crossing; after one,
 * the solid it enters and then nothing (col_split), its end not below
 * the cut; only made outside (counted in *count). ST_ENOMEM (the caller
 * says so). */
static st_status column(const col_ctx *c, size_t col, size_t *count)
{
    st_grid *g = c->g;
    const int dir = c->dir;
    const size_t nk = c->nk, ci = col % c->na, cj = col / c->na;
    col_hit *h = c->hit + c->start[col];
    size_t n = c->start[col + 1] - c->start[col];
    /* from the viewer: the greatest dir * coordinate first */
    qsort(h, n, sizeof *h, cmp_hit_desc);
    /* the caps' crossings apart (in order); the seen soup's: within half
     * a voxel are one (an edge or vertex on the line, or a sliver) */
    col_hit *cap = malloc((n + 1) * sizeof *cap);
    size_t *line = malloc((nk + 1) * sizeof *line);
    if (!line || !cap) {
        free(line);
        free(cap);
        return ST_ENOMEM;
    }
    size_t u = 0, ncap = 0;
    for (size_t m = 0; m < n; m++)
        if (h[m].t >= c->nt)
            cap[ncap++] = h[m];
        else if (u == 0 || h[u - 1].h - h[m].h > 0.5)
            h[u++] = h[m];
    n = u;
    for (size_t step = 0; step < nk; step++) {
        const size_t m = dir > 0 ? nk - 1 - step : step;
        size_t ijk[3];
        ijk[c->k] = m;
        ijk[c->a] = ci;
        ijk[c->b] = cj;
        line[step] = st_grid_index(g, ijk[0], ijk[1], ijk[2]);
    }
    size_t first = 0;
    for (size_t seg = 0; seg <= n; seg++) {
        size_t end = first;   /* the segment: line[first..end) */
        while (end < nk && (seg == n || dir * (double)(dir > 0 ? nk - 1 - end : end) > h[seg].h))
            end++;
        const size_t split = col_split(c, line, first, end, h, seg, n, cap, ncap);
        for (size_t i = split; i < end; i++) {
            float *d = &g->data[line[i]];
            if (*d < 0.0f) {
                *d = st_grid_signed_value(*d, 0);
                (*count)++;
            }
        }
        first = end;
    }
    free(line);
    free(cap);
    return ST_OK;
}

st_status st_sides_columns(st_grid *g, const st_soup *s, const st_sides_params *p,
                           const st_sides_stats *st, double band_voxels, size_t *changed,
                           st_error *err)
{
    *changed = 0;
    if (!st->columns || !s)
        return ST_OK;
    col_ctx c;
    memset(&c, 0, sizeof c);
    c.g = g;
    c.k = st->column_axis, c.a = (c.k + 1) % 3, c.b = (c.k + 2) % 3, c.dir = st->column_dir;
    const size_t dims[3] = {g->nx, g->ny, g->nz};
    c.na = dims[c.a], c.nb = dims[c.b], c.nk = dims[c.k];
    const size_t seen = p->column_seen;
    c.nt = seen && seen < s->ntris ? seen : s->ntris;
    c.band = (float)(band_voxels * g->voxel);
    /* the crossings of the caps that face away too (not past a fold,
     * where the mirror has continued the solid past them) */
    const size_t nall = p->column_caps && !st->fold ? s->ntris : c.nt;
    const size_t ncol = c.na * c.nb;
    uint8_t *exits = NULL;
    double *ctop = NULL;
    st_status rc = ST_OK;
    if (nall > c.nt && (rc = exit_caps(&exits, &ctop, s, c.nt, c.k, c.dir, err)))
        goto done;
    c.exits = exits;
    c.ctop = ctop;
    if ((rc = col_crossings(&c, s, nall, err)))
        goto done;
    size_t count = 0;
    int oom = 0;
    #pragma omp parallel for schedule(dynamic, 64) reduction(+ : count) reduction(| : oom)
    for (size_t col = 0; col < ncol; col++)
        oom |= column(&c, col, &count) != ST_OK;
    *changed = count;
    if (oom)
        rc = st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory for the columns");
done:
    free(c.start);
    free(c.hit);
    free(exits);
    free(ctop);
    return rc;
}
