/*
 * symmetry_fill.c - the lost side of a soup filled from its symmetric copy
 * (symmetry.h, st_symmetry_fill; issue 37).
 *
 * A hole's cap guesses the missing surface from the rim alone: flat, or
 * continuing the faces. Where the soup is symmetric, the surviving side
 * mapped across the symmetry says what was there. The fill is every image
 * of a soup triangle that lands where the soup is not (its centroid
 * farther than the tolerance from the soup: the soup wins wherever it is)
 * and near a cap (so only holes are filled, never the open air an
 * imprecise map lands in). A cap whose rim the fill runs along is dropped:
 * the fill gives that hole its shape, and a flat cap across it would cut
 * the solid the fill bounds.
 *
 * Every decision is a distance compared with a tolerance of a voxel: the
 * fill is evidence for the signs (pseudo.c lowers it into the field as it
 * does the caps), never an output surface, so no exact predicate is
 * needed. Per map, the tests run in parallel into a flag per triangle; the
 * kept images are appended in triangle order, so the fill does not depend
 * on the thread count.
 */
#include "souptet/symmetry.h"
#include "../base/fpenv.h"
#include "souptet/geom.h"
#include "souptet/mem.h"
#include "../base/unionfind.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#define PI 3.14159265358979323846
#define FILL_ANGLES 24          /* a continuous rotation: every 15 degrees */
#define RIM_REACH 3.0           /* tolerances: a rim point the fill covers */
#define RIM_COVERED 0.75        /* share of the rim's length: a covered cap */
#define RIM_AGREE 0.8           /* share of the rim whose preimage is on the
                                   soup: a map that may fill the piece */

/* ---- the caps' pieces ------------------------------------------------------ */

typedef struct pieces {
    size_t n;            /* pieces */
    size_t *of_tri;      /* piece of each cap triangle */
    double *reach;       /* per piece: half its box diagonal */
    size_t *vrep;        /* each cap vertex's representative (same position) */
    double lo[3], hi[3]; /* the caps' box, grown by the largest reach */
} pieces;

static const double *g_xyz;   /* qsort's context: set just before the call */

static int cmp_pos(const void *a, const void *b)
{
    const double *p = g_xyz + 3 * *(const size_t *)a, *q = g_xyz + 3 * *(const size_t *)b;
    for (int k = 0; k < 3; k++)
        if (p[k] != q[k])
            return p[k] < q[k] ? -1 : 1;
    return *(const size_t *)a < *(const size_t *)b ? -1 : *(const size_t *)a > *(const size_t *)b;
}

static void pieces_free(pieces *P)
{
    free(P->of_tri);
    free(P->reach);
    free(P->vrep);
    memset(P, 0, sizeof *P);
}

/* Join the caps' vertices that share a position (each cap lists its rim's
 * points again), then the triangles through their vertices. */
static st_status pieces_make(pieces *P, const st_soup *caps)
{
    memset(P, 0, sizeof *P);
    const size_t nv = caps->nverts, nt = caps->ntris;
    size_t *order = st_malloc_array(nv ? nv : 1, sizeof *order);
    size_t *box_of = st_malloc_array(nv ? nv : 1, sizeof *box_of);
    double *box = st_malloc_array(nv ? 6 * nv : 1, sizeof *box);
    P->vrep = st_malloc_array(nv ? nv : 1, sizeof *P->vrep);
    P->of_tri = st_malloc_array(nt ? nt : 1, sizeof *P->of_tri);
    st_status rc = order && box_of && box && P->vrep && P->of_tri ? ST_OK : ST_ENOMEM;
    if (rc)
        goto done;
    for (size_t v = 0; v < nv; v++)
        order[v] = P->vrep[v] = v;
    g_xyz = caps->xyz;
    qsort(order, nv, sizeof *order, cmp_pos);
    for (size_t i = 1; i < nv; i++)
        if (cmp_pos(order + i - 1, order + i) != 0 &&
            memcmp(caps->xyz + 3 * order[i - 1], caps->xyz + 3 * order[i], 3 * sizeof(double)) == 0)
            uf_join(P->vrep, order[i - 1], order[i]);
    /* the positions' representatives, then the pieces in `order` */
    for (size_t v = 0; v < nv; v++)
        order[v] = P->vrep[v] = uf_find(P->vrep, v);
    for (size_t t = 0; t < nt; t++) {
        const uint32_t *c = caps->tris + 3 * t;
        uf_join(order, c[0], c[1]);
        uf_join(order, c[0], c[2]);
    }
    /* pieces numbered by their smallest vertex, in vertex order */
    for (size_t v = 0; v < nv; v++)
        box_of[v] = SIZE_MAX;
    for (size_t v = 0; v < nv; v++) {
        const size_t r = uf_find(order, v);
        if (box_of[r] == SIZE_MAX) {
            box_of[r] = P->n++;
            for (int k = 0; k < 3; k++)
                box[6 * box_of[r] + k] = box[6 * box_of[r] + 3 + k] = caps->xyz[3 * v + k];
        }
        double *b = box + 6 * box_of[r];
        for (int k = 0; k < 3; k++) {
            b[k] = fmin(b[k], caps->xyz[3 * v + k]);
            b[3 + k] = fmax(b[3 + k], caps->xyz[3 * v + k]);
        }
    }
    P->reach = st_malloc_array(P->n ? P->n : 1, sizeof *P->reach);
    if (!P->reach) {
        rc = ST_ENOMEM;
        goto done;
    }
    double most = 0.0;
    for (size_t i = 0; i < P->n; i++) {
        const double *b = box + 6 * i;
        const double d[3] = {b[3] - b[0], b[4] - b[1], b[5] - b[2]};
        P->reach[i] = 0.5 * st_norm3(d);
        most = fmax(most, P->reach[i]);
    }
    for (size_t t = 0; t < nt; t++)
        P->of_tri[t] = box_of[uf_find(order, caps->tris[3 * t])];
    st_soup_bounds(caps, P->lo, P->hi, NULL);
    for (int k = 0; k < 3; k++) {
        P->lo[k] -= most;
        P->hi[k] += most;
    }
done:
    free(order);
    free(box_of);
    free(box);
    if (rc)
        pieces_free(P);
    return rc;
}

/* ---- the maps ----------------------------------------------------------------- */

typedef struct map {
    const st_symmetry *y;
    double angle;
} map;

/* Every map of the set: a mirror, each power of a discrete rotation, and
 * FILL_ANGLES - 1 turns of a continuous one. */
static size_t maps_of(const st_symmetry_set *set, map *out, size_t max)
{
    size_t n = 0;
    for (size_t i = 0; i < set->n; i++) {
        const st_symmetry *y = set->items + i;
        if (y->kind == ST_SYMMETRY_MIRROR) {
            if (n < max)
                out[n++] = (map){y, 0.0};
            continue;
        }
        const int steps = y->order >= 2 ? y->order : FILL_ANGLES;
        for (int k = 1; k < steps && n < max; k++)
            out[n++] = (map){y, 2.0 * PI * k / steps};
    }
    return n;
}

/* The image of triangle t under m, re-oriented for a mirror. */
static void image(const st_soup *s, size_t t, const map *m, double q[3][3])
{
    const uint32_t *c = s->tris + 3 * t;
    const int flip = m->y->kind == ST_SYMMETRY_MIRROR;
    for (int k = 0; k < 3; k++)
        st_symmetry_apply(m->y, m->angle, s->xyz + 3 * c[flip && k ? 3 - k : k], 1, q[k]);
}

typedef struct fill_ctx {
    const st_soup *s;
    const st_bvh *bvh, *caps_bvh, *fill_bvh;   /* fill_bvh: the maps before */
    const pieces *P;
    const uint8_t *piece_ok;   /* the map agrees with the piece's rim */
    double tol2;
} fill_ctx;

static int keeps(const fill_ctx *C, const double q[3][3])
{
    double c[3];
    for (int k = 0; k < 3; k++) {
        c[k] = (q[0][k] + q[1][k] + q[2][k]) / 3.0;
        if (c[k] < C->P->lo[k] || c[k] > C->P->hi[k])
            return 0;
    }
    int64_t tri;
    const double most = C->P->hi[0] - C->P->lo[0] + C->P->hi[1] - C->P->lo[1] +
                        C->P->hi[2] - C->P->lo[2];
    const double d2 = st_bvh_nearest(C->caps_bvh, c, most * most, &tri, NULL);
    if (tri < 0 || !C->piece_ok[C->P->of_tri[tri]] ||
        d2 > C->P->reach[C->P->of_tri[tri]] * C->P->reach[C->P->of_tri[tri]])
        return 0;
    /* off the soup, and nearer the caps than the soup: in a hole */
    const double bound = fmax(C->tol2, d2);
    st_bvh_nearest(C->bvh, c, bound, &tri, NULL);
    if (tri >= 0)
        return 0;
    if (C->fill_bvh) {
        st_bvh_nearest(C->fill_bvh, c, C->tol2, &tri, NULL);
        if (tri >= 0)
            return 0;
    }
    return 1;
}

/* ---- covered caps ------------------------------------------------------------- */

typedef struct rim_edge {
    size_t piece, a, b;   /* a < b: representatives */
    size_t tri;           /* a cap triangle it bounds (its coordinates) */
    int ia, ib;           /* corners in it */
} rim_edge;

static int cmp_edge(const void *x, const void *y)
{
    const rim_edge *p = x, *q = y;
    if (p->a != q->a)
        return p->a < q->a ? -1 : 1;
    if (p->b != q->b)
        return p->b < q->b ? -1 : 1;
    return p->tri < q->tri ? -1 : p->tri > q->tri;
}

/* The caps' rims: the edges in one cap triangle of their piece alone,
 * by midpoint and length. */
typedef struct rims {
    size_t n;
    double *mid;      /* 3n */
    double *len;      /* n */
    size_t *piece;    /* n */
} rims;

static void rims_free(rims *R)
{
    free(R->mid);
    free(R->len);
    free(R->piece);
    memset(R, 0, sizeof *R);
}

static st_status rims_make(rims *R, const st_soup *caps, const pieces *P)
{
    memset(R, 0, sizeof *R);
    const size_t nt = caps->ntris, ne = 3 * nt;
    rim_edge *e = st_malloc_array(ne ? ne : 1, sizeof *e);
    R->mid = st_malloc_array(ne ? 3 * ne : 1, sizeof *R->mid);
    R->len = st_malloc_array(ne ? ne : 1, sizeof *R->len);
    R->piece = st_malloc_array(ne ? ne : 1, sizeof *R->piece);
    if (!e || !R->mid || !R->len || !R->piece) {
        free(e);
        rims_free(R);
        return ST_ENOMEM;
    }
    for (size_t t = 0; t < nt; t++)
        for (int k = 0; k < 3; k++) {
            size_t a = P->vrep[caps->tris[3 * t + k]], b = P->vrep[caps->tris[3 * t + (k + 1) % 3]];
            e[3 * t + k] = (rim_edge){P->of_tri[t], a < b ? a : b, a < b ? b : a, t, k, (k + 1) % 3};
        }
    qsort(e, ne, sizeof *e, cmp_edge);
    for (size_t i = 0; i < ne;) {
        size_t j = i + 1;
        while (j < ne && e[j].a == e[i].a && e[j].b == e[i].b)
            j++;
        if (j == i + 1 && e[i].a != e[i].b) {
            const uint32_t *c = caps->tris + 3 * e[i].tri;
            const double *p = caps->xyz + 3 * c[e[i].ia], *q = caps->xyz + 3 * c[e[i].ib];
            const double d[3] = {q[0] - p[0], q[1] - p[1], q[2] - p[2]};
            for (int k = 0; k < 3; k++)
                R->mid[3 * R->n + k] = 0.5 * (p[k] + q[k]);
            R->len[R->n] = st_norm3(d);
            R->piece[R->n++] = e[i].piece;
        }
        i = j;
    }
    free(e);
    return ST_OK;
}

/* share[i]: the share of piece i's rim length whose midpoint `near`
 * holds for; near(ctx, point) says whether a point is covered. */
static void rim_share(double *share, size_t npieces, const rims *R,
                      int (*near)(const void *, const double[3]), const void *ctx)
{
    for (size_t i = 0; i < 2 * npieces; i++)
        share[i] = 0.0;
    for (size_t r = 0; r < R->n; r++) {
        share[2 * R->piece[r]] += R->len[r];
        if (near(ctx, R->mid + 3 * r))
            share[2 * R->piece[r] + 1] += R->len[r];
    }
    for (size_t i = 0; i < npieces; i++)
        share[i] = share[2 * i] > 0.0 ? share[2 * i + 1] / share[2 * i] : 0.0;
}

typedef struct near_ctx {
    const st_bvh *bvh;
    double reach2;
    const map *inverse;   /* NULL: the point itself */
} near_ctx;

static int near_bvh(const void *ctx, const double x[3])
{
    const near_ctx *N = ctx;
    double q[3];
    if (N->inverse)
        st_symmetry_apply(N->inverse->y, N->inverse->angle, x, 1, q);
    else
        memcpy(q, x, sizeof q);
    int64_t tri = -1;
    if (N->bvh)
        st_bvh_nearest(N->bvh, q, N->reach2, &tri, NULL);
    return tri >= 0;
}

/* ---- the fill ----------------------------------------------------------------- */

static double tri_area(const double q[3][3])
{
    double u[3], v[3], n[3];
    for (int k = 0; k < 3; k++) {
        u[k] = q[1][k] - q[0][k];
        v[k] = q[2][k] - q[0][k];
    }
    st_cross3(n, u, v);
    return 0.5 * st_norm3(n);
}

/* A triangle of its own three vertices, appended to out. */
static st_status add_tri(st_soup *out, const double q[3][3], st_error *err)
{
    const size_t base = out->nverts;
    st_status rc = ST_OK;
    for (int k = 0; k < 3 && !rc; k++)
        rc = st_soup_add_vertex(out, q[k][0], q[k][1], q[k][2], err);
    return rc ? rc : st_soup_add_triangle(out, (uint32_t)base, (uint32_t)(base + 1),
                                          (uint32_t)(base + 2), err);
}

/* Append the images m of s's triangles flagged in keep (counted once the
 * fill is final: fill_of_covered). */
static st_status append_images(st_soup *fill, const st_soup *s, const map *m,
                               const uint8_t *keep, st_error *err)
{
    for (size_t t = 0; t < s->ntris; t++) {
        if (!keep[t])
            continue;
        double q[3][3];
        image(s, t, m, q);
        st_status rc = add_tri(fill, q, err);
        if (rc)
            return rc;
    }
    return ST_OK;
}

/* kept: the caps' triangles outside the covered pieces, their vertices
 * shared as in caps. */
static st_status keep_uncovered(st_soup *kept, const st_soup *caps, const pieces *P,
                                const uint8_t *covered, st_error *err)
{
    size_t *to = st_malloc_array(caps->nverts ? caps->nverts : 1, sizeof *to);
    if (!to)
        return ST_ENOMEM;
    st_status rc = ST_OK;
    for (size_t v = 0; v < caps->nverts; v++)
        to[v] = SIZE_MAX;
    for (size_t t = 0; t < caps->ntris && !rc; t++) {
        if (covered[P->of_tri[t]])
            continue;
        uint32_t w[3];
        for (int k = 0; k < 3 && !rc; k++) {
            const uint32_t v = caps->tris[3 * t + k];
            if (to[v] == SIZE_MAX) {
                to[v] = kept->nverts;
                rc = st_soup_add_vertex(kept, caps->xyz[3 * v], caps->xyz[3 * v + 1],
                                        caps->xyz[3 * v + 2], err);
            }
            w[k] = (uint32_t)to[v];
        }
        rc = rc ? rc : st_soup_add_triangle(kept, w[0], w[1], w[2], err);
    }
    free(to);
    return rc;
}

/* The fill goes all or nothing with its piece: *fill keeps the triangles
 * whose nearest cap is in a covered piece (where a cap stays, a partial
 * fill beside it would cut the solid the cap closes). */
static st_status fill_of_covered(st_soup **fill, const pieces *P, const st_bvh *caps_bvh,
                                 const uint8_t *covered, st_symmetry_fill_stats *st,
                                 st_error *err)
{
    st_soup *in = *fill, *out = st_soup_new();
    if (!out)
        return ST_ENOMEM;
    for (size_t t = 0; t < in->ntris; t++) {
        double q[3][3], c[3] = {0.0, 0.0, 0.0};
        for (int k = 0; k < 3; k++)
            for (int a = 0; a < 3; a++) {
                q[k][a] = in->xyz[3 * in->tris[3 * t + k] + a];
                c[a] += q[k][a] / 3.0;
            }
        int64_t tri;
        st_bvh_nearest(caps_bvh, c, INFINITY, &tri, NULL);
        if (tri < 0 || !covered[P->of_tri[tri]])
            continue;
        st_status rc = add_tri(out, q, err);
        if (rc) {
            st_soup_free(out);
            return rc;
        }
        st->triangles++;
        st->area += tri_area(q);
    }
    st_soup_free(in);
    *fill = out;
    return ST_OK;
}

st_status st_symmetry_fill(st_soup **fill_out, st_soup **kept_out, const st_soup *s,
                           const st_bvh *bvh, const st_symmetry_set *set,
                           const st_soup *caps, double tol,
                           st_symmetry_fill_stats *stats, st_error *err)
{
    st_symmetry_fill_stats local;
    st_symmetry_fill_stats *st = stats ? stats : &local;
    memset(st, 0, sizeof *st);
    *fill_out = *kept_out = NULL;
    if (!(tol > 0.0) || !isfinite(tol))
        return st_error_set(err, ST_EINPUT, NULL, 0,
                            "symmetry fill: the tolerance must be positive and finite");
    st_soup *fill = st_soup_new(), *kept = st_soup_new();
    st_bvh *caps_bvh = NULL, *fill_bvh = NULL;
    uint8_t *keep = NULL, *covered = NULL;
    double *share = NULL;
    pieces P;
    rims R;
    memset(&P, 0, sizeof P);
    memset(&R, 0, sizeof R);
    map maps[ST_SYMMETRY_MAX * ST_SYMMETRY_DEFAULT_MAX_ORDER];
    st_status rc = fill && kept ? ST_OK : ST_ENOMEM;
    if (rc || !set || set->n == 0 || !caps || caps->ntris == 0 || s->ntris == 0) {
        if (!rc && caps)
            rc = st_soup_append(kept, caps, err);
        goto done;
    }
    st->caps = 0;
    if ((rc = pieces_make(&P, caps)) || (rc = rims_make(&R, caps, &P)) ||
        (rc = st_bvh_build(&caps_bvh, caps, err)))
        goto done;
    st->caps = P.n;
    keep = st_malloc_array(s->ntris, 1);
    covered = st_malloc_array(P.n ? P.n : 1, 1);
    share = st_malloc_array(P.n ? 2 * P.n : 1, sizeof *share);
    if (!keep || !covered || !share) {
        rc = ST_ENOMEM;
        goto done;
    }
    const size_t nmaps = maps_of(set, maps, sizeof maps / sizeof *maps);
    st->maps = nmaps;
    for (size_t mi = 0; mi < nmaps; mi++) {
        /* the pieces whose rim the map's inverse puts back on the soup */
        const map inv = {maps[mi].y, -maps[mi].angle};
        const near_ctx back = {bvh, RIM_REACH * tol * RIM_REACH * tol, &inv};
        rim_share(share, P.n, &R, near_bvh, &back);
        size_t agree = 0;
        for (size_t i = 0; i < P.n; i++)
            agree += covered[i] = share[i] >= RIM_AGREE;
        if (!agree)
            continue;
        const fill_ctx C = {s, bvh, caps_bvh, fill_bvh, &P, covered, tol * tol};
        const long long nt = (long long)s->ntris;
        size_t any = 0;
#pragma omp parallel for schedule(dynamic, 1024) reduction(+ : any)
        for (long long t = 0; t < nt; t++) {
            double q[3][3];
            image(s, (size_t)t, maps + mi, q);
            keep[t] = (uint8_t)keeps(&C, q);
            any += keep[t];
        }
        if (!any)
            continue;
        if ((rc = append_images(fill, s, maps + mi, keep, err)))
            goto done;
        st_bvh_free(fill_bvh);
        fill_bvh = NULL;
        if ((rc = st_bvh_build(&fill_bvh, fill, err)))
            goto done;
    }
    const near_ctx on_fill = {fill_bvh, RIM_REACH * tol * RIM_REACH * tol, NULL};
    rim_share(share, P.n, &R, near_bvh, &on_fill);
    for (size_t i = 0; i < P.n; i++)
        covered[i] = share[i] >= RIM_COVERED;
    if ((rc = keep_uncovered(kept, caps, &P, covered, err)) ||
        (rc = fill_of_covered(&fill, &P, caps_bvh, covered, st, err)))
        goto done;
    for (size_t i = 0; i < P.n; i++)
        st->caps_covered += covered[i];
done:
    if (rc == ST_ENOMEM)
        st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory for the symmetric fill");
    st_bvh_free(caps_bvh);
    st_bvh_free(fill_bvh);
    pieces_free(&P);
    rims_free(&R);
    free(share);
    free(keep);
    free(covered);
    if (rc) {
        st_soup_free(fill);
        st_soup_free(kept);
        return rc;
    }
    *fill_out = fill;
    *kept_out = kept;
    return ST_OK;
}
