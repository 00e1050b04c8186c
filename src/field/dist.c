/*
 * dist.c - unsigned distance fields of triangle soups (see dist.h).
 *
 * Band pass. The grid is cut into bricks of 4^3 voxels. Every triangle is
 * binned into the bricks its band may reach (near its bounding ball and,
 * for a large CAD triangle, near its plane, so it costs its area times the
 * band and not its bounding box). Bricks are processed in parallel, each
 * writing only its own voxels. A brick's voxels are walked in 2x2x2
 * groups: a group keeps the brick's candidates whose ball comes within the
 * band of one of its voxels, in buckets by a lower bound on their distance
 * from the group's center (less the triangle's radius); each voxel then
 * walks the buckets in order and stops at the first whose bound, less the
 * voxel's offset from the center, is not below its best so far.
 * Candidates that survive a per-voxel ball bound and a plane bound are
 * measured exactly. The minimum is the same whatever the order, so the
 * pruning changes the work, never the answer. A full field also keeps
 * each voxel's nearest triangle, the first of any ties in a fixed order,
 * so its bricks walk their candidates whole, sorted by (bound, index).
 * A band field's bricks are walked by the 8^3 blocks that hold them, and
 * a block's bricks share their triangles' setups (a triangle reaches about
 * a dozen bricks; per block, three to five setups instead), each made the
 * first time a group's voxel passes the triangle's ball test.
 *
 * Stored by blocks (st_dist_field_blocks). The same bricks, walked by
 * the 8^3 blocks that hold them (a brick lies in one block): a block gets
 * a slot of values only if one of its bricks has candidates, and loses it
 * when every voxel came out at the band. Each voxel's value is the dense
 * field's, so no voxel far from the soup is allocated or written.
 *
 * Full field. Beyond the band, a vector distance transform over
 * triangles: four raster sweeps hand each voxel the nearest of the
 * triangles its already-swept neighbours hold, measured exactly (so never
 * below the truth; dist.h says how far above it can be). The sweeps run
 * on one thread, in one fixed order.
 */
#include "souptet/dist.h"
#include "../base/fpenv.h"
#include "souptet/geom.h"
#include "souptet/mem.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#ifdef __SSE2__
#include <emmintrin.h>
#endif
#include <string.h>
#ifdef _OPENMP
#include <omp.h>
#endif

st_dist_params st_dist_params_default(void)
{
    st_dist_params p;
    p.cells = ST_DIST_DEFAULT_CELLS;
    p.voxel = 0.0;
    p.pad = -1;
    p.band = ST_DIST_DEFAULT_BAND;
    p.max_bytes = 0;
    return p;
}

long st_dist_default_pad(double band)
{
    if (!isfinite(band))
        band = ST_DIST_DEFAULT_BAND;
    return (long)ceil(band) + 2;
}

st_status st_dist_layout(const st_soup *s, const st_dist_params *p,
                         size_t dims[3], double origin[3], double *voxel,
                         st_error *err)
{
    double lo[3], hi[3];
    st_status st = st_soup_bounds(s, lo, hi, err);
    if (st)
        return st;
    double ext = fmax(hi[0] - lo[0], fmax(hi[1] - lo[1], hi[2] - lo[2]));
    double h = p->voxel;
    if (h == 0.0) {
        if (p->cells == 0)
            return st_error_set(err, ST_EINPUT, NULL, 0,
                                "the resolution must be at least 1 cell");
        if (!(ext > 0.0))
            return st_error_set(err, ST_EINPUT, NULL, 0,
                                "the soup has no extent (all its vertices "
                                "coincide): give a voxel size with -s");
        h = ext / (double)p->cells;
    }
    if (!(h > 0.0) || !isfinite(h))
        return st_error_set(err, ST_EINPUT, NULL, 0,
                            "voxel size %g is not a positive number", h);
    long pad = p->pad >= 0 ? p->pad : st_dist_default_pad(p->band);
    for (int a = 0; a < 3; a++) {
        double n = ceil((hi[a] - lo[a]) / h - 1e-9);
        if (n < 1.0)
            n = 1.0;
        n += 2.0 * (double)pad;
        /* 2^40 voxels along an axis is far past any memory; refuse it here
         * so the size arithmetic below stays exact. */
        if (!(n < 1099511627776.0))
            return st_error_set(err, ST_ELIMIT, NULL, 0,
                                "a voxel size of %g makes %.3g voxels along "
                                "an axis", h, n);
        dims[a] = (size_t)n;
        origin[a] = 0.5 * (lo[a] + hi[a]) - 0.5 * (n - 1.0) * h;
    }
    *voxel = h;
    return ST_OK;
}

/* Everything the band kernel needs about one triangle. */
typedef struct tri_setup {
    double v[3][3];      /* vertices */
    double e[3][3];      /* edges v[i+1] - v[i] */
    double inv_ee[3];    /* 1 / |e_i|^2, 0 for a zero-length edge */
    double nu[3];        /* unit normal (zero when degenerate) */
    double m[3][3];      /* in-plane inward edge normals n x e_i */
    double mo[3];        /* m_i . v_i */
    int degenerate;
    int dom;             /* axis of the largest normal component */
} tri_setup;

/* fmin/fmax are library calls when NaN rules must be kept; nothing here is
 * NaN (coordinates are finite), so plain comparisons do. */
#define MIN2(a, b) ((a) < (b) ? (a) : (b))
#define MAX2(a, b) ((a) > (b) ? (a) : (b))

/* A ball around a triangle: the cheap part of a triangle, for binning and
 * for the lower bounds that order and prune the candidates. */
typedef struct tri_ball {
    double c[3];
    double r;
} tri_ball;

static void triangle_ball(tri_ball *b, const st_soup *s, size_t tri)
{
    const double *v[3];
    for (int k = 0; k < 3; k++)
        v[k] = s->xyz + 3 * (size_t)s->tris[3 * tri + k];
    for (int a = 0; a < 3; a++) {
        double lo = MIN2(v[0][a], MIN2(v[1][a], v[2][a]));
        double hi = MAX2(v[0][a], MAX2(v[1][a], v[2][a]));
        b->c[a] = 0.5 * (lo + hi);
    }
    double r2 = 0.0;
    for (int k = 0; k < 3; k++) {
        double w[3];
        st_sub3(w, v[k], b->c);
        r2 = MAX2(r2, st_dot3(w, w));
    }
    /* Slightly more than the farthest vertex, so rounding never makes the
     * ball miss a point of the triangle. */
    b->r = sqrt(r2) * (1.0 + 1e-12);
}

static void setup_triangle(tri_setup *t, const st_soup *s, size_t tri)
{
    for (int k = 0; k < 3; k++)
        memcpy(t->v[k], s->xyz + 3 * (size_t)s->tris[3 * tri + k],
               3 * sizeof(double));
    double eemax = 0.0;
    for (int i = 0; i < 3; i++) {
        st_sub3(t->e[i], t->v[(i + 1) % 3], t->v[i]);
        double ee = st_dot3(t->e[i], t->e[i]);
        t->inv_ee[i] = ee > 0.0 ? 1.0 / ee : 0.0;
        eemax = MAX2(eemax, ee);
    }
    double n[3];
    st_cross3(n, t->e[0], t->e[1]);
    double nl = st_norm3(n);
    /* Same rule as st_point_triangle_dist2 (geom.h explains the ratio),
     * with the longest edge squared as st_norm3 gives it. The plain square
     * eemax is that within a few ulps, so unless nl is within a 1e-12 of
     * the threshold (or eemax near the exponent range's ends) it decides
     * the same way without the three scaled norms. */
    const double thr = ST_DEGENERATE_AREA_RATIO * eemax;
    if (eemax > 1e-280 && eemax < 1e280 && nl > thr * (1.0 + 1e-12))
        t->degenerate = 0;
    else if (eemax > 1e-280 && eemax < 1e280 && nl < thr * (1.0 - 1e-12))
        t->degenerate = 1;
    else {
        const double emax = fmax(st_norm3(t->e[0]),
                                 fmax(st_norm3(t->e[1]), st_norm3(t->e[2])));
        t->degenerate = !(nl > ST_DEGENERATE_AREA_RATIO * emax * emax);
    }
    t->dom = 0;
    if (t->degenerate) {
        memset(t->nu, 0, sizeof t->nu);
        memset(t->m, 0, sizeof t->m);
        memset(t->mo, 0, sizeof t->mo);
        return;
    }
    for (int a = 0; a < 3; a++)
        t->nu[a] = n[a] / nl;
    for (int a = 1; a < 3; a++)
        if (fabs(t->nu[a]) > fabs(t->nu[t->dom]))
            t->dom = a;
    for (int i = 0; i < 3; i++) {
        st_cross3(t->m[i], t->nu, t->e[i]);
        t->mo[i] = st_dot3(t->m[i], t->v[i]);
    }
}

static inline double edge_dist2(const tri_setup *t, int i, const double p[3])
{
    double w[3];
    st_sub3(w, p, t->v[i]);
    double s = st_dot3(w, t->e[i]) * t->inv_ee[i];
    s = s < 0.0 ? 0.0 : (s > 1.0 ? 1.0 : s);
    double d[3] = {w[0] - s * t->e[i][0], w[1] - s * t->e[i][1],
                   w[2] - s * t->e[i][2]};
    return st_dot3(d, d);
}

/* Squared distance from p to the triangle; plane_d is n.(p - v0). */
static inline double tri_dist2(const tri_setup *t, const double p[3],
                               double plane_d)
{
    if (t->degenerate) {
        double d = edge_dist2(t, 0, p), d1 = edge_dist2(t, 1, p),
               d2 = edge_dist2(t, 2, p);
        d = MIN2(d, d1);
        return MIN2(d, d2);
    }
    int out0 = st_dot3(p, t->m[0]) < t->mo[0];
    int out1 = st_dot3(p, t->m[1]) < t->mo[1];
    int out2 = st_dot3(p, t->m[2]) < t->mo[2];
    if (!(out0 | out1 | out2))
        return plane_d * plane_d;
    double d = INFINITY, x;
    if (out0)
        d = edge_dist2(t, 0, p);
    if (out1 && (x = edge_dist2(t, 1, p)) < d)
        d = x;
    if (out2 && (x = edge_dist2(t, 2, p)) < d)
        d = x;
    return d;
}

/* Bricks: BRICK^3 voxels whose candidate triangles are gathered once. Four
 * keeps a brick's candidate list short for a band of three voxels while
 * the per-brick sort is amortised over 64 voxels. */
#define BRICK 4

typedef struct brick_grid {
    size_t n[3];        /* bricks per axis */
    double half_diag;   /* from a brick's center to its farthest voxel center */
    double *center[3];  /* the centers of the bricks' voxels along each axis */
} brick_grid;

/* The center of brick b's voxels along axis a. */
static double brick_center_axis(const st_grid *g, int a, size_t b)
{
    const size_t n = a == 0 ? g->nx : a == 1 ? g->ny : g->nz;
    size_t lo = b * BRICK;
    size_t hi = lo + BRICK - 1 < n - 1 ? lo + BRICK - 1 : n - 1;
    return g->origin[a] + g->voxel * 0.5 * (double)(lo + hi);
}

/* Call visit(b, ctx) for every brick the band around triangle t may reach:
 * bricks meeting its B-expanded box whose center is within reach of both
 * its ball and (for a proper triangle) its plane. */
typedef void (*brick_visit)(size_t brick, void *ctx);

static void triangle_bricks(const st_grid *g, const brick_grid *bg,
                            const st_soup *s, size_t tri,
                            const tri_ball *ball, double B,
                            brick_visit visit, void *ctx)
{
    const double h = g->voxel;
    const size_t n[3] = {g->nx, g->ny, g->nz};
    const double *v[3];
    for (int k = 0; k < 3; k++)
        v[k] = s->xyz + 3 * (size_t)s->tris[3 * tri + k];
    size_t lo[3], hi[3];
    for (int a = 0; a < 3; a++) {
        double mn = MIN2(v[0][a], MIN2(v[1][a], v[2][a])) - B;
        double mx = MAX2(v[0][a], MAX2(v[1][a], v[2][a])) + B;
        double l = ceil((mn - g->origin[a]) / h);
        double u = floor((mx - g->origin[a]) / h);
        if (u < 0.0 || l > (double)(n[a] - 1) || l > u)
            return;
        lo[a] = l < 0.0 ? 0 : (size_t)l;
        hi[a] = u > (double)(n[a] - 1) ? n[a] - 1 : (size_t)u;
        lo[a] /= BRICK;
        hi[a] /= BRICK;
    }
    double e1[3], e2[3], e3[3], nrm[3];
    st_sub3(e1, v[1], v[0]);
    st_sub3(e2, v[2], v[0]);
    st_sub3(e3, v[2], v[1]);
    st_cross3(nrm, e1, e2);
    double nl = st_norm3(nrm);
    const double ee = MAX2(st_dot3(e1, e1), MAX2(st_dot3(e2, e2), st_dot3(e3, e3)));
    /* The plane only for a triangle far from collinear: the rounding in
     * the normal of a sliver (or of a collinear triangle, whose normal is
     * rounding alone) tilts it by about 1e-16 * ee / nl radians, so the
     * triangle's far end leaves that plane; here the tilt is below 1e-9
     * of the longest edge, which the plane's slack covers. */
    int use_plane = nl > 1e-6 * ee && isfinite(ee);
    if (use_plane)
        for (int a = 0; a < 3; a++)
            nrm[a] /= nl;
    /* Small slack: these tests only prune, so erring wide is safe. */
    const double reach = (B + bg->half_diag) * (1.0 + 1e-9) + 1e-12 * h;
    const double reach_ball = reach + ball->r;
    const double reach_plane = reach + 1e-9 * sqrt(ee);
    /* The sums over the axes are kept as each loop's axis moves: the
     * tests round a little differently from a dot product, far inside the
     * slack. */
    const double rb2 = reach_ball * reach_ball;
    for (size_t bz = lo[2]; bz <= hi[2]; bz++) {
        const double cz = bg->center[2][bz];
        const double bz2 = (cz - ball->c[2]) * (cz - ball->c[2]);
        const double pz = (cz - v[0][2]) * nrm[2];
        for (size_t by = lo[1]; by <= hi[1]; by++) {
            const double cy = bg->center[1][by];
            const double byz2 = (cy - ball->c[1]) * (cy - ball->c[1]) + bz2;
            if (byz2 > rb2)
                continue;
            const double pyz = (cy - v[0][1]) * nrm[1] + pz;
            const size_t row = bg->n[0] * (by + bg->n[1] * bz);
            for (size_t bx = lo[0]; bx <= hi[0]; bx++) {
                const double cx = bg->center[0][bx];
                if ((cx - ball->c[0]) * (cx - ball->c[0]) + byz2 > rb2)
                    continue;
                if (use_plane && fabs((cx - v[0][0]) * nrm[0] + pyz) > reach_plane)
                    continue;
                visit(bx + row, ctx);
            }
        }
    }
}

typedef struct bin_ctx {
    size_t *count;     /* per brick (counting pass) */
    size_t *fill;      /* per brick write position (fill pass) */
    uint32_t *list;
    uint32_t tri;
} bin_ctx;

static void count_visit(size_t brick, void *ctx)
{
    ((bin_ctx *)ctx)->count[brick + 1]++;
}

static void fill_visit(size_t brick, void *ctx)
{
    bin_ctx *c = ctx;
    c->list[c->fill[brick]++] = c->tri;
}

/* The sort key of a candidate in a full field's brick: (key, tri) is a
 * total order (a triangle is binned into a brick once), so any correct
 * sort gives the same order, and with it the same nearest triangle where
 * several tie. */
typedef struct cand_key {
    double key;        /* |brick center - ball center| - ball radius */
    uint32_t tri;
    uint32_t at;       /* its position before the sort */
} cand_key;

static inline int cand_key_less(const cand_key *x, const cand_key *y)
{
    return x->key < y->key || (x->key == y->key && x->tri < y->tri);
}

/* Sort k[0..m) by (key, tri) with tmp[0..m) as scratch: insertion sort of
 * runs of 16, then bottom-up merges. qsort's indirect comparisons cost
 * more than the distances of a dense brick; this sorts 16-byte keys with
 * the comparison inlined, to the same order. */
static void sort_cand_keys(cand_key *k, cand_key *tmp, size_t m)
{
    enum { RUN = 16 };
    for (size_t a = 0; a < m; a += RUN) {
        size_t b = a + RUN < m ? a + RUN : m;
        for (size_t i = a + 1; i < b; i++) {
            cand_key x = k[i];
            size_t j = i;
            while (j > a && cand_key_less(&x, &k[j - 1])) {
                k[j] = k[j - 1];
                j--;
            }
            k[j] = x;
        }
    }
    cand_key *src = k, *dst = tmp;
    for (size_t w = RUN; w < m; w *= 2) {
        for (size_t a = 0; a < m; a += 2 * w) {
            size_t mid = a + w < m ? a + w : m, b = a + 2 * w < m ? a + 2 * w : m;
            size_t i = a, j = mid, o = a;
            while (i < mid && j < b)
                dst[o++] = cand_key_less(&src[j], &src[i]) ? src[j++] : src[i++];
            while (i < mid)
                dst[o++] = src[i++];
            while (j < b)
                dst[o++] = src[j++];
        }
        cand_key *t = src;
        src = dst;
        dst = t;
    }
    if (src != k)
        memcpy(k, src, m * sizeof *k);
}

/* Groups. In a band field a brick's voxels are walked in groups of
 * GROUP^3 (the brick's octants): each group keeps the candidates whose
 * ball comes within the band of one of its voxels, in NBUCKET buckets by
 * their lower bound from the group's center. A voxel walks the buckets in
 * order and stops at the first whose smallest bound, less its offset from
 * the center, is not below its best so far. The offset is 0.87 voxel
 * where a brick's is up to 2.6, and a bucket needs a counting pass where
 * a sorted list needs a sort. The value of a band voxel is a minimum over
 * the same triangles, so it is the same in any order; a full field also
 * keeps the nearest triangle, the first of the ties in (key, tri) order,
 * so it walks the whole brick in that order, each candidate a bucket. */
#define GROUP 2
#define NBUCKET 32
enum { BAND_NV = GROUP * GROUP * GROUP };

/* One group's candidates in walk order, structure of arrays. A band
 * group's list holds only bound and at (its balls are read from the
 * brick's arrays through at); a full field's holds the balls too. */
typedef struct walk_list {
    double *x, *y, *z, *r;   /* ball center and radius (full fields) */
    double *bound;           /* a lower bound of its key, nondecreasing */
    uint32_t *at;            /* index into the brick's candidates */
    size_t n;
} walk_list;

typedef struct brick_scratch {
    size_t cap;
    uint32_t *tri;           /* the brick's candidates */
    uint32_t *slot;          /* where each one's setup is cached, or UINT32_MAX */
    double *bx, *by, *bz, *br; /* their balls */
    cand_key *keys;          /* 2 * cap: a full field's keys and the merge's scratch */
    uint32_t *kept;          /* BAND_NV * cap: the groups' candidates
                              * (brick_group_balls), group e's at e * cap */
    double *gdd;             /* and their squared distances from its center */
    uint8_t *bucket;         /* a group's candidates' buckets */
    walk_list w;
    tri_setup *setups;
    uint32_t nsetup;
    /* A block's bricks share their setups (a field stored by blocks):
     * table maps a triangle to its setup, open addressing, 2 * tcap
     * entries (triangle, slot), empty UINT32_MAX; spos[slot] is where
     * each setup's entry is, to clear the table after the block. */
    int shared;
    size_t tcap, scap;
    uint32_t *table;
    size_t *spos;
} brick_scratch;

static void scratch_free(brick_scratch *sc)
{
    free(sc->tri);
    free(sc->slot);
    free(sc->bx);
    free(sc->by);
    free(sc->bz);
    free(sc->br);
    free(sc->keys);
    free(sc->w.x);
    free(sc->w.y);
    free(sc->w.z);
    free(sc->w.r);
    free(sc->w.at);
    free(sc->w.bound);
    free(sc->kept);
    free(sc->bucket);
    free(sc->gdd);
    free(sc->setups);
    free(sc->table);
    free(sc->spos);
}

static int scratch_grow(void **p, size_t n, size_t size)
{
    void *q = st_realloc_array(*p, n, size);
    if (!q)
        return -1;
    *p = q;
    return 0;
}

static int scratch_reserve(brick_scratch *sc, size_t m)
{
    if (m <= sc->cap)
        return 0;
    size_t cap = m < 64 ? 64 : m;
    void **d[] = {(void **)&sc->bx, (void **)&sc->by, (void **)&sc->bz,
                  (void **)&sc->br, (void **)&sc->w.x, (void **)&sc->w.y,
                  (void **)&sc->w.z, (void **)&sc->w.r, (void **)&sc->w.bound};
    for (size_t i = 0; i < sizeof d / sizeof d[0]; i++)
        if (scratch_grow(d[i], cap, sizeof(double)))
            return -1;
    void **u[] = {(void **)&sc->tri, (void **)&sc->slot, (void **)&sc->w.at};
    for (size_t i = 0; i < sizeof u / sizeof u[0]; i++)
        if (scratch_grow(u[i], cap, sizeof(uint32_t)))
            return -1;
    if (scratch_grow((void **)&sc->kept, (size_t)BAND_NV * cap, sizeof(uint32_t)) ||
        scratch_grow((void **)&sc->gdd, (size_t)BAND_NV * cap, sizeof(double)) ||
        scratch_grow((void **)&sc->bucket, cap, 1) ||
        scratch_grow((void **)&sc->keys, 2 * cap, sizeof(cand_key)))
        return -1;
    sc->cap = cap;
    return 0;
}

/* Room for n setups (and, shared, their table). -1: out of memory. */
static int scratch_setups(brick_scratch *sc, size_t n)
{
    if (n > sc->scap) {
        size_t cap = n < 64 ? 64 : n;
        if (scratch_grow((void **)&sc->setups, cap, sizeof(tri_setup)) ||
            scratch_grow((void **)&sc->spos, cap, sizeof(size_t)))
            return -1;
        sc->scap = cap;
    }
    if (sc->shared && 2 * n > sc->tcap) {
        size_t t = 128;
        while (t < 2 * n)
            t *= 2;
        if (scratch_grow((void **)&sc->table, t, 2 * sizeof(uint32_t)))
            return -1;
        for (size_t i = 0; i < 2 * t; i++)
            sc->table[i] = UINT32_MAX;
        sc->tcap = t;
    }
    return 0;
}

/* The index in the table of triangle tri's entry: its own, or the empty
 * one where it would go. */
static inline size_t setup_entry(const brick_scratch *sc, uint32_t tri)
{
    size_t h = ((size_t)tri * 2654435761u) & (sc->tcap - 1);
    while (sc->table[2 * h] != UINT32_MAX && sc->table[2 * h] != tri)
        h = (h + 1) & (sc->tcap - 1);
    return 2 * h;
}

/* Empty the table: the entries of the setups made. */
static void setups_clear(brick_scratch *sc)
{
    if (sc->shared)
        for (uint32_t i = 0; i < sc->nsetup; i++)
            sc->table[sc->spos[i]] = UINT32_MAX;
    sc->nsetup = 0;
}

/* The voxels of a brick or group: [lo, hi) per axis, and their center. */
typedef struct voxel_box {
    size_t lo[3], hi[3];
    double c[3];
} voxel_box;

static void box_center(const st_grid *g, voxel_box *v)
{
    for (int a = 0; a < 3; a++)
        v->c[a] = g->origin[a] + g->voxel * 0.5 * (double)(v->lo[a] + v->hi[a] - 1);
}

/* Where a brick's values go: voxel (i, j, k) at val[(i - lo[0]) * s[0] +
 * (j - lo[1]) * s[1] + (k - lo[2]) * s[2]], its nearest triangle (a full
 * field's) at near[] likewise: a dense grid's rows, or a block's. */
typedef struct brick_out {
    float *val;
    int32_t *near;      /* NULL for a band field */
    size_t s[3];
    size_t lo[3];
} brick_out;

static inline size_t out_index(const brick_out *o, size_t i, size_t j, size_t k)
{
    return (i - o->lo[0]) * o->s[0] + (j - o->lo[1]) * o->s[1] +
           (k - o->lo[2]) * o->s[2];
}

/* Exact distances, and nearest triangles, for the voxels of a full
 * field's box v, walking list w (bounds from v's center) voxel by voxel.
 * A band field's groups are walked by walk_band. */
static void walk_box(const st_grid *g, const brick_out *o, const st_soup *s,
                     const voxel_box *v, const walk_list *w, double B,
                     brick_scratch *sc)
{
    const float Bf = (float)B;
    const double B2 = B * B;
    /* Locals: the stores to the setup cache could otherwise alias them. */
    const double *const x = w->x, *const y = w->y, *const z = w->z,
                 *const r = w->r, *const bound = w->bound;
    const uint32_t *const at = w->at;
    const size_t n = w->n;
    const uint32_t *const tri = sc->tri;
    uint32_t *const slot = sc->slot;
    tri_setup *const setups = sc->setups;
    uint32_t nsetup = sc->nsetup;
    double p[3];
    for (size_t k = v->lo[2]; k < v->hi[2]; k++) {
        p[2] = g->origin[2] + g->voxel * (double)k;
        for (size_t j = v->lo[1]; j < v->hi[1]; j++) {
            p[1] = g->origin[1] + g->voxel * (double)j;
            for (size_t i = v->lo[0]; i < v->hi[0]; i++) {
                p[0] = g->origin[0] + g->voxel * (double)i;
                double off[3];
                st_sub3(off, p, v->c);
                /* |p - c| - r >= bound - |p - center|: once that reaches
                 * the best distance so far, no later candidate can improve
                 * it. The relative shave keeps rounding on the safe side. */
                const double offset = sqrt(st_dot3(off, off)) * (1.0 + 1e-9) +
                                      1e-12 * g->voxel;
                double cur = B2, curd = B;
                int32_t best = -1;
                for (size_t q = 0; q < n; q++) {
                    if (bound[q] - offset >= curd)
                        break;          /* no later one is closer */
                    {
                        const double dx = p[0] - x[q], dy = p[1] - y[q],
                                     dz = p[2] - z[q];
                        const double reach = curd + r[q];
                        if (dx * dx + dy * dy + dz * dz >= reach * reach)
                            continue;   /* its ball is too far */
                        const uint32_t c = at[q];
                        if (slot[c] == UINT32_MAX) {
                            slot[c] = nsetup++;
                            setup_triangle(&setups[slot[c]], s, tri[c]);
                        }
                        const tri_setup *t = &setups[slot[c]];
                        double pd = 0.0;
                        if (!t->degenerate) {
                            double v0p[3];
                            st_sub3(v0p, p, t->v[0]);
                            pd = st_dot3(v0p, t->nu);
                            if (pd * pd >= cur)
                                continue;   /* its plane is too far */
                        }
                        double d2 = tri_dist2(t, p, pd);
                        if (d2 < cur) {
                            cur = d2;
                            curd = sqrt(d2);
                            best = (int32_t)tri[c];
                        }
                    }
                }
                const size_t idx = out_index(o, i, j, k);
                o->val[idx] = cur >= B2 ? Bf : (float)curd;
                if (o->near)
                    o->near[idx] = cur >= B2 ? -1 : best;
            }
        }
    }
    sc->nsetup = nsetup;
}

/* Candidate c's setup: made once per brick (or, shared, once per block)
 * and cached in the scratch. */
static inline const tri_setup *band_setup(const st_soup *s, brick_scratch *sc,
                                          uint32_t *nsetup, uint32_t c)
{
    if (sc->slot[c] == UINT32_MAX) {
        const uint32_t at = (*nsetup)++;
        sc->slot[c] = at;
        setup_triangle(&sc->setups[at], s, sc->tri[c]);
        if (sc->shared) {
            const size_t e = setup_entry(sc, sc->tri[c]);
            sc->table[e] = sc->tri[c];
            sc->table[e + 1] = at;
            sc->spos[at] = e;
        }
    }
    return &sc->setups[sc->slot[c]];
}

/* One band voxel's candidate t, measured, its plane first. Keeps the
 * smaller squared distance in *cur, its root in *curd. */
static inline void band_try(const tri_setup *t, const double p[3],
                            double *cur, double *curd)
{
    double pd = 0.0;
    if (!t->degenerate) {
        double v0p[3];
        st_sub3(v0p, p, t->v[0]);
        pd = st_dot3(v0p, t->nu);
        if (pd * pd >= *cur)
            return;         /* its plane is too far */
    }
    const double d2 = tri_dist2(t, p, pd);
    if (d2 < *cur) {
        *cur = d2;
        *curd = sqrt(d2);
    }
}

/* For a candidate (ball c, r, bound bd) and the voxels e of a band group:
 * bit e of *live
 * when walk_box's stop test lets voxel e go on (its bound, less the
 * voxel's offset, below its best distance), and of *pass when it is live
 * and the candidate's ball comes within its best distance too. The same
 * IEEE operations in the same order as walk_box's, two voxels at a time
 * where SSE2 is there. */
static inline void band_masks(const double *px, const double *py,
                              const double *pz, const double *off,
                              const double *curd, double bd, const double c[3],
                              double r, unsigned *live, unsigned *pass)
{
#ifdef __SSE2__
    const __m128d bq = _mm_set1_pd(bd), xq = _mm_set1_pd(c[0]),
                  yq = _mm_set1_pd(c[1]), zq = _mm_set1_pd(c[2]),
                  rq = _mm_set1_pd(r);
    unsigned l = 0, p = 0;
    /* Unrolled: the shifts are constants. */
#define BAND_PAIR(e)                                                          \
    do {                                                                      \
        const __m128d dx = _mm_sub_pd(_mm_loadu_pd(px + (e)), xq),            \
                      dy = _mm_sub_pd(_mm_loadu_pd(py + (e)), yq),            \
                      dz = _mm_sub_pd(_mm_loadu_pd(pz + (e)), zq);            \
        const __m128d cd = _mm_loadu_pd(curd + (e));                          \
        const __m128d dd = _mm_add_pd(_mm_add_pd(_mm_mul_pd(dx, dx),          \
                                                 _mm_mul_pd(dy, dy)),         \
                                      _mm_mul_pd(dz, dz));                    \
        const __m128d reach = _mm_add_pd(cd, rq);                             \
        const __m128d a =                                                     \
            _mm_cmplt_pd(_mm_sub_pd(bq, _mm_loadu_pd(off + (e))), cd);        \
        const __m128d b =                                                     \
            _mm_and_pd(a, _mm_cmplt_pd(dd, _mm_mul_pd(reach, reach)));       \
        l |= (unsigned)_mm_movemask_pd(a) << (e);                             \
        p |= (unsigned)_mm_movemask_pd(b) << (e);                             \
    } while (0)
    _Static_assert(BAND_NV == 8, "four pairs of voxels");
    BAND_PAIR(0);
    BAND_PAIR(2);
    BAND_PAIR(4);
    BAND_PAIR(6);
#undef BAND_PAIR
    *live = l;
    *pass = p;
#else
    const double bq = bd, xq = c[0], yq = c[1], zq = c[2], rq = r;
    unsigned l = 0, p = 0;
    for (unsigned e = 0; e < BAND_NV; e++) {
        const double dx = px[e] - xq, dy = py[e] - yq, dz = pz[e] - zq;
        const double reach = curd[e] + rq;
        const unsigned a = bq - off[e] < curd[e];
        l |= a << e;
        p |= (a & (dx * dx + dy * dy + dz * dz < reach * reach)) << e;
    }
    *live = l;
    *pass = p;
#endif
}

/* A band field's group v (at most GROUP^3 voxels), walking list w
 * candidate by candidate for all its voxels at once: the stop and ball
 * tests of walk_box for every voxel, without branches (the compiler may
 * do them side by side), then the voxels that pass measure the triangle.
 * A band value is a minimum over the same triangles as walk_box's, in
 * another order, so it is the same: each voxel keeps a candidate exactly
 * when walk_box keeps it, or after walk_box would have stopped (a
 * triangle past the stop is never closer). */
static void walk_band(const st_grid *g, const brick_out *o, const st_soup *s,
                      const voxel_box *v, const walk_list *w, double B,
                      brick_scratch *sc)
{
    const double B2 = B * B;
    double px[BAND_NV], py[BAND_NV], pz[BAND_NV], off[BAND_NV], cur[BAND_NV],
           curd[BAND_NV];
    /* The voxels' centers again, one point each: what band_try reads. */
    double pt[BAND_NV][3];
    size_t idx[BAND_NV];
    unsigned nv = 0;
    for (size_t k = v->lo[2]; k < v->hi[2]; k++)
        for (size_t j = v->lo[1]; j < v->hi[1]; j++)
            for (size_t i = v->lo[0]; i < v->hi[0]; i++) {
                const double p[3] = {g->origin[0] + g->voxel * (double)i,
                                     g->origin[1] + g->voxel * (double)j,
                                     g->origin[2] + g->voxel * (double)k};
                double d[3];
                st_sub3(d, p, v->c);
                memcpy(pt[nv], p, sizeof p);
                px[nv] = p[0];
                py[nv] = p[1];
                pz[nv] = p[2];
                /* As walk_box's offset. */
                off[nv] = sqrt(st_dot3(d, d)) * (1.0 + 1e-9) + 1e-12 * g->voxel;
                cur[nv] = B2;
                curd[nv] = B;
                idx[nv++] = out_index(o, i, j, k);
            }
    /* Missing voxels of a group at the grid's edge: never active. */
    for (unsigned e = nv; e < BAND_NV; e++) {
        px[e] = py[e] = pz[e] = 0.0;
        off[e] = 0.0;
        cur[e] = 0.0;
        curd[e] = -INFINITY;
    }
    uint32_t nsetup = sc->nsetup;
    for (size_t q = 0; q < w->n; q++) {
        unsigned live, pass;
        const uint32_t c = w->at[q];
        const double ball[3] = {sc->bx[c], sc->by[c], sc->bz[c]};
        band_masks(px, py, pz, off, curd, w->bound[q], ball, sc->br[c], &live,
                   &pass);
        if (!live)
            break;              /* no later one is closer to any voxel */
        if (!pass)
            continue;
        /* Set up once for the group's voxels it may reach. */
        const tri_setup *t = band_setup(s, sc, &nsetup, c);
        do {
            const unsigned e = (unsigned)__builtin_ctz(pass);
            pass &= pass - 1;
            band_try(t, pt[e], &cur[e], &curd[e]);
        } while (pass);
    }
    sc->nsetup = nsetup;
    const float Bf = (float)B;
    for (unsigned e = 0; e < nv; e++)
        o->val[idx[e]] = cur[e] >= B2 ? Bf : (float)curd[e];
}

/* Write `value` (and nearest -1) to every voxel of box v. */
static void fill_box(const brick_out *o, const voxel_box *v, float value)
{
    for (size_t k = v->lo[2]; k < v->hi[2]; k++)
        for (size_t j = v->lo[1]; j < v->hi[1]; j++)
            for (size_t i = v->lo[0]; i < v->hi[0]; i++) {
                const size_t at = out_index(o, i, j, k);
                o->val[at] = value;
                if (o->near)
                    o->near[at] = -1;
            }
}

/* A full field's brick: its m candidates by (key, tri), each its own run. */
static void walk_sorted(const st_grid *g, const brick_out *o,
                        const st_soup *s, const voxel_box *v, size_t m,
                        double B, brick_scratch *sc)
{
    cand_key *keys = sc->keys;
    for (size_t q = 0; q < m; q++) {
        const double w[3] = {v->c[0] - sc->bx[q], v->c[1] - sc->by[q],
                             v->c[2] - sc->bz[q]};
        /* From the brick's center; a voxel subtracts its own offset. */
        keys[q].key = sqrt(st_dot3(w, w)) - sc->br[q];
        keys[q].tri = sc->tri[q];
        keys[q].at = (uint32_t)q;
    }
    sort_cand_keys(keys, keys + m, m);
    walk_list *wl = &sc->w;
    for (size_t q = 0; q < m; q++) {
        const uint32_t c = keys[q].at;
        wl->x[q] = sc->bx[c];
        wl->y[q] = sc->by[c];
        wl->z[q] = sc->bz[c];
        wl->r[q] = sc->br[c];
        wl->at[q] = c;
        wl->bound[q] = keys[q].key;
    }
    wl->n = m;
    walk_box(g, o, s, v, wl, B, sc);
}

/* A band brick's groups, GROUP per axis (fewer where the grid ends):
 * group e = ex + GROUP (ey + GROUP ez) has the box box[e], its center
 * c[a][e_a] along each axis and its reach R[e]: beyond R + r from its
 * center, a ball is beyond B from every voxel of it. */
typedef struct brick_groups {
    voxel_box box[BAND_NV];
    double c[3][GROUP];
    double R[BAND_NV];
    unsigned n[3];
    size_t nkept[BAND_NV];  /* its candidates (brick_group_balls) */
} brick_groups;

static void brick_group_boxes(brick_groups *gr, const st_grid *g,
                              const voxel_box *v, double B)
{
    for (int a = 0; a < 3; a++)
        gr->n[a] = (unsigned)((v->hi[a] - v->lo[a] + GROUP - 1) / GROUP);
    for (unsigned e = 0; e < BAND_NV; e++) {
        const unsigned at[3] = {e % GROUP, e / GROUP % GROUP, e / (GROUP * GROUP)};
        voxel_box *u = &gr->box[e];
        double half = 0.0;
        for (int a = 0; a < 3; a++) {
            /* A missing group repeats the last one: never walked. */
            const unsigned i = at[a] < gr->n[a] ? at[a] : gr->n[a] - 1;
            u->lo[a] = v->lo[a] + GROUP * (size_t)i;
            u->hi[a] = u->lo[a] + GROUP < v->hi[a] ? u->lo[a] + GROUP : v->hi[a];
            const double h = 0.5 * g->voxel * (double)(u->hi[a] - u->lo[a] - 1);
            half += h * h;
        }
        box_center(g, u);
        for (int a = 0; a < 3; a++)
            gr->c[a][at[a]] = u->c[a];
        /* The slack only keeps more. */
        gr->R[e] = (B + sqrt(half)) * (1.0 + 1e-9) + 1e-12 * g->voxel;
    }
}

/* Group e's candidates (in sc->kept from e * cap, gr->nkept[e] of them):
 * those of the brick's m whose ball's squared distance from its center
 * (in sc->gdd beside them) is below (R[e] + r)^2. The same IEEE
 * operations, in the same order, as one group's own pass over them, the
 * axes' squares shared by the groups with a center in common along it. */
static void brick_group_balls(brick_groups *gr, size_t m, brick_scratch *sc)
{
    _Static_assert(GROUP == 2 && BAND_NV == 8, "two groups per axis");
    const double *bx = sc->bx, *by = sc->by, *bz = sc->bz, *br = sc->br;
    uint32_t *const kept = sc->kept;
    double *const gdd = sc->gdd;
    size_t n[BAND_NV] = {0};
#ifdef __SSE2__
    const __m128d cx = _mm_loadu_pd(gr->c[0]), cy = _mm_loadu_pd(gr->c[1]),
                  cz = _mm_loadu_pd(gr->c[2]);
    const __m128d R0 = _mm_loadu_pd(gr->R), R2 = _mm_loadu_pd(gr->R + 2),
                  R4 = _mm_loadu_pd(gr->R + 4), R6 = _mm_loadu_pd(gr->R + 6);
#endif
    for (size_t q = 0; q < m; q++) {
        double dd[BAND_NV];
        unsigned mask;
#ifdef __SSE2__
        const __m128d dx = _mm_sub_pd(cx, _mm_set1_pd(bx[q])),
                      dy = _mm_sub_pd(cy, _mm_set1_pd(by[q])),
                      dz = _mm_sub_pd(cz, _mm_set1_pd(bz[q]));
        const __m128d sx = _mm_mul_pd(dx, dx), sy = _mm_mul_pd(dy, dy),
                      sz = _mm_mul_pd(dz, dz);
        /* (x^2 + y^2) + z^2, x fastest: groups 2 i and 2 i + 1. */
        const __m128d sxy0 = _mm_add_pd(sx, _mm_unpacklo_pd(sy, sy)),
                      sxy1 = _mm_add_pd(sx, _mm_unpackhi_pd(sy, sy));
        const __m128d z0 = _mm_unpacklo_pd(sz, sz), z1 = _mm_unpackhi_pd(sz, sz);
        const __m128d d0 = _mm_add_pd(sxy0, z0), d2 = _mm_add_pd(sxy1, z0),
                      d4 = _mm_add_pd(sxy0, z1), d6 = _mm_add_pd(sxy1, z1);
        const __m128d r = _mm_set1_pd(br[q]);
        const __m128d a0 = _mm_add_pd(R0, r), a2 = _mm_add_pd(R2, r),
                      a4 = _mm_add_pd(R4, r), a6 = _mm_add_pd(R6, r);
        _mm_storeu_pd(dd, d0);
        _mm_storeu_pd(dd + 2, d2);
        _mm_storeu_pd(dd + 4, d4);
        _mm_storeu_pd(dd + 6, d6);
        mask = (unsigned)(_mm_movemask_pd(_mm_cmplt_pd(d0, _mm_mul_pd(a0, a0))) |
                          _mm_movemask_pd(_mm_cmplt_pd(d2, _mm_mul_pd(a2, a2))) << 2 |
                          _mm_movemask_pd(_mm_cmplt_pd(d4, _mm_mul_pd(a4, a4))) << 4 |
                          _mm_movemask_pd(_mm_cmplt_pd(d6, _mm_mul_pd(a6, a6))) << 6);
#else
        double sx[GROUP], sy[GROUP], sz[GROUP];
        for (unsigned i = 0; i < GROUP; i++) {
            const double dx = gr->c[0][i] - bx[q], dy = gr->c[1][i] - by[q],
                         dz = gr->c[2][i] - bz[q];
            sx[i] = dx * dx;
            sy[i] = dy * dy;
            sz[i] = dz * dz;
        }
        mask = 0;
        for (unsigned e = 0; e < BAND_NV; e++) {
            const double reach = gr->R[e] + br[q];
            dd[e] = sx[e & 1] + sy[(e >> 1) & 1] + sz[e >> 2];
            mask |= (unsigned)(dd[e] < reach * reach) << e;
        }
#endif
        while (mask) {
            const unsigned e = (unsigned)__builtin_ctz(mask);
            mask &= mask - 1;
            kept[e * sc->cap + n[e]] = (uint32_t)q;
            gdd[e * sc->cap + n[e]++] = dd[e];
        }
    }
    memcpy(gr->nkept, n, sizeof n);
}

/* A band field's group e of gr: the candidates whose ball comes within B
 * of one of its voxels (brick_group_balls), bucketed by their bound from
 * its center. */
static void walk_group(const st_grid *g, const brick_out *o,
                       const st_soup *s, const brick_groups *gr, unsigned ge,
                       double B, brick_scratch *sc)
{
    const voxel_box *v = &gr->box[ge];
    const double width = gr->R[ge] / (double)(NBUCKET - 1);
    uint32_t count[NBUCKET + 1] = {0};
    double lo[NBUCKET];
    for (int b = 0; b < NBUCKET; b++)
        lo[b] = INFINITY;
    /* The count and smallest key of each bucket. */
    const uint32_t *const kept = sc->kept + ge * sc->cap;
    const double *const dd2 = sc->gdd + ge * sc->cap;
    const uint32_t nkept = (uint32_t)gr->nkept[ge];
    uint8_t *bucket = sc->bucket;
    const double *br = sc->br;
    for (uint32_t e = 0; e < nkept; e++) {
        const double k = sqrt(dd2[e]) - br[kept[e]];
        /* Nondecreasing in k: a later bucket's keys are never below an
         * earlier one's. */
        const double f = k / width;
        const uint32_t b = k <= 0.0 ? 0 : f >= NBUCKET - 2 ? NBUCKET - 1 : 1 + (uint32_t)f;
        bucket[e] = (uint8_t)b;
        count[b + 1]++;
        lo[b] = MIN2(lo[b], k);
    }
    if (nkept == 0) {
        fill_box(o, v, (float)B);
        return;
    }
    for (int b = 0; b < NBUCKET; b++)
        count[b + 1] += count[b];
    walk_list *wl = &sc->w;
    for (uint32_t e = 0; e < nkept; e++) {
        const uint32_t q = kept[e], at = count[bucket[e]]++;
        /* The balls stay where they are: the walk may stop early. */
        wl->bound[at] = lo[bucket[e]];
        wl->at[at] = q;
    }
    wl->n = nkept;
    walk_band(g, o, s, v, wl, B, sc);
}

/* The triangles binned into the bricks their band may reach. */
typedef struct band_bins {
    brick_grid bg;
    size_t nb;          /* bricks */
    tri_ball *balls;    /* per triangle */
    size_t *start;      /* brick b's candidates: list[start[b] .. start[b + 1]) */
    uint32_t *list;
    double *centers;    /* bg.center's storage */
} band_bins;

static void bins_free(band_bins *bb)
{
    void *owned[] = {bb->balls, bb->start, bb->list, bb->centers};
    for (size_t i = 0; i < sizeof owned / sizeof owned[0]; i++)
        free(owned[i]);
}

static size_t bin_count(const band_bins *bb, size_t brick)
{
    return bb->start[brick + 1] - bb->start[brick];
}

/* Exact band distances for the voxels of one brick, written through o. */
static void process_brick(const st_grid *g, const brick_out *o,
                          const st_soup *s, const band_bins *bb, size_t brick,
                          double B, brick_scratch *sc)
{
    const brick_grid *bg = &bb->bg;
    const uint32_t *list = bb->list + bb->start[brick];
    const size_t m = bin_count(bb, brick);
    const size_t n[3] = {g->nx, g->ny, g->nz};
    const size_t b[3] = {brick % bg->n[0], (brick / bg->n[0]) % bg->n[1],
                         brick / (bg->n[0] * bg->n[1])};
    voxel_box v;
    for (int a = 0; a < 3; a++) {
        v.lo[a] = b[a] * BRICK;
        v.hi[a] = v.lo[a] + BRICK < n[a] ? v.lo[a] + BRICK : n[a];
    }
    if (m == 0) {
        fill_box(o, &v, (float)B);
        return;
    }
    for (size_t q = 0; q < m; q++) {
        const tri_ball *tb = &bb->balls[list[q]];
        sc->tri[q] = list[q];
        if (sc->shared) {
            const size_t e = setup_entry(sc, list[q]);
            sc->slot[q] = sc->table[e] == UINT32_MAX ? UINT32_MAX : sc->table[e + 1];
        } else
            sc->slot[q] = UINT32_MAX;
        sc->bx[q] = tb->c[0];
        sc->by[q] = tb->c[1];
        sc->bz[q] = tb->c[2];
        sc->br[q] = tb->r;
    }
    if (!sc->shared)
        sc->nsetup = 0;
    if (o->near) {
        box_center(g, &v);
        walk_sorted(g, o, s, &v, m, B, sc);
        return;
    }
    brick_groups gr;
    brick_group_boxes(&gr, g, &v, B);
    brick_group_balls(&gr, m, sc);
    for (unsigned ez = 0; ez < gr.n[2]; ez++)
        for (unsigned ey = 0; ey < gr.n[1]; ey++)
            for (unsigned ex = 0; ex < gr.n[0]; ex++)
                walk_group(g, o, s, &gr, ex + GROUP * (ey + GROUP * ez), B, sc);
}

/* Bin s's triangles into the bricks of g (see triangle_bricks): bb gets
 * the balls, and each brick's candidates in input order. */
static st_status bin_triangles(band_bins *bb, const st_grid *g,
                               const st_soup *s, double B,
                               const st_progress *progress, st_error *err)
{
    memset(bb, 0, sizeof *bb);
    if (s->ntris > UINT32_MAX)
        return st_error_set(err, ST_ELIMIT, NULL, 0,
                            "too many triangles (%zu)", s->ntris);
    brick_grid *bg = &bb->bg;
    bg->n[0] = (g->nx + BRICK - 1) / BRICK;
    bg->n[1] = (g->ny + BRICK - 1) / BRICK;
    bg->n[2] = (g->nz + BRICK - 1) / BRICK;
    bg->half_diag = 0.5 * sqrt(3.0) * (double)(BRICK - 1) * g->voxel;
    const size_t nb = bb->nb = bg->n[0] * bg->n[1] * bg->n[2];
    /* The triangles cut into `chunks` runs (below). */
    int chunks = omp_get_max_threads();
    chunks = chunks < 1 ? 1 : chunks > 8 ? 8 : chunks;
    if (s->ntris < 4096)
        chunks = 1;
    /* The balls and the lists are hundreds of MB on a 10M-triangle soup,
     * touched once in order: huge pages (st_malloc_big; the sizes are
     * below 2^32 times a few words). */
    bb->balls = st_malloc_big(s->ntris * sizeof *bb->balls);
    bb->start = st_malloc_array(nb + 1, sizeof(size_t));
    bb->centers = st_malloc_array(bg->n[0] + bg->n[1] + bg->n[2], sizeof(double));
    size_t *cnt = st_calloc_array((size_t)chunks * (nb + 1), sizeof(size_t));
    st_status st = ST_OK;
    if (!bb->balls || !bb->start || !bb->centers || !cnt) {
        st = st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory");
        goto done;
    }
    for (int a = 0; a < 3; a++) {
        bg->center[a] = bb->centers + (a > 0 ? bg->n[0] : 0) + (a > 1 ? bg->n[1] : 0);
        for (size_t b = 0; b < bg->n[a]; b++)
            bg->center[a][b] = brick_center_axis(g, a, b);
    }
    #pragma omp parallel for schedule(static)
    for (size_t t = 0; t < s->ntris; t++)
        triangle_ball(&bb->balls[t], s, t);
    /* Counting sort of (brick, triangle) pairs, triangles in input order:
     * each run counted and filled by one thread into its own part of
     * every brick's list (the runs' parts in run order), so the lists are
     * the serial ones for any thread count. */
    #pragma omp parallel for schedule(static, 1) num_threads(chunks)
    for (int c = 0; c < chunks; c++) {
        const size_t t0 = s->ntris * (size_t)c / (size_t)chunks;
        const size_t t1 = s->ntris * (size_t)(c + 1) / (size_t)chunks;
        bin_ctx cc = {cnt + (size_t)c * (nb + 1), NULL, NULL, 0};
        for (size_t t = t0; t < t1; t++) {
            if ((t & 4095) == 0 && st_progress_cancelled(progress))
                break;
            triangle_bricks(g, bg, s, t, &bb->balls[t], B, count_visit, &cc);
        }
    }
    if (st_progress_cancelled(progress)) {
        st = st_error_set(err, ST_ECANCELLED, NULL, 0, "cancelled");
        goto done;
    }
    /* start[b]: brick b's first slot; cnt[c][b + 1] becomes run c's */
    size_t at = 0;
    for (size_t b = 0; b < nb; b++) {
        bb->start[b] = at;
        for (int c = 0; c < chunks; c++) {
            size_t *x = &cnt[(size_t)c * (nb + 1) + b + 1];
            const size_t k = *x;
            *x = at;
            at += k;
        }
    }
    bb->start[nb] = at;
    bb->list = at <= SIZE_MAX / sizeof(uint32_t) ? st_malloc_big(at * sizeof(uint32_t)) : NULL;
    if (!bb->list) {
        st = st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory for "
                          "%zu brick candidates", at);
        goto done;
    }
    #pragma omp parallel for schedule(static, 1) num_threads(chunks)
    for (int c = 0; c < chunks; c++) {
        const size_t t0 = s->ntris * (size_t)c / (size_t)chunks;
        const size_t t1 = s->ntris * (size_t)(c + 1) / (size_t)chunks;
        bin_ctx cc = {NULL, cnt + (size_t)c * (nb + 1) + 1, bb->list, 0};
        for (size_t t = t0; t < t1; t++) {
            if ((t & 4095) == 0 && st_progress_cancelled(progress))
                break;
            cc.tri = (uint32_t)t;
            triangle_bricks(g, bg, s, t, &bb->balls[t], B, fill_visit, &cc);
        }
    }
    if (st_progress_cancelled(progress))
        st = st_error_set(err, ST_ECANCELLED, NULL, 0, "cancelled");
done:
    free(cnt);
    if (st)
        bins_free(bb);
    return st;
}

/* Bricks per block along an axis: a brick lies in one block. */
#define BRICKS_PER_BLOCK (ST_GRID_BLOCK / BRICK)
_Static_assert(ST_GRID_BLOCK % BRICK == 0, "a brick must lie in one block");

/* The bricks of block b (block coordinates b[3]), their values written
 * through o, sharing their candidates' setups (see brick_scratch): each
 * triangle is set up once for the block, not once per brick. The values
 * are the same either way (a setup is a function of the triangle alone).
 * -1: out of memory. */
static int block_bricks(const st_grid *g, const brick_out *o, const st_soup *s,
                        const band_bins *bb, const size_t b[3], double B,
                        brick_scratch *sc)
{
    const brick_grid *bg = &bb->bg;
    size_t bricks[BRICKS_PER_BLOCK * BRICKS_PER_BLOCK * BRICKS_PER_BLOCK];
    size_t nbricks = 0, total = 0;
    for (size_t z = 0; z < BRICKS_PER_BLOCK; z++)
        for (size_t y = 0; y < BRICKS_PER_BLOCK; y++)
            for (size_t x = 0; x < BRICKS_PER_BLOCK; x++) {
                const size_t c[3] = {b[0] * BRICKS_PER_BLOCK + x,
                                     b[1] * BRICKS_PER_BLOCK + y,
                                     b[2] * BRICKS_PER_BLOCK + z};
                if (c[0] >= bg->n[0] || c[1] >= bg->n[1] || c[2] >= bg->n[2])
                    continue;
                const size_t brick = c[0] + bg->n[0] * (c[1] + bg->n[1] * c[2]);
                bricks[nbricks++] = brick;
                total += bin_count(bb, brick);
            }
    sc->shared = 1;
    sc->nsetup = 0;
    if (total > UINT32_MAX || scratch_setups(sc, total))
        return -1;
    int bad = 0;
    for (size_t i = 0; i < nbricks && !bad; i++)
        if (!(bad = scratch_reserve(sc, bin_count(bb, bricks[i]))))
            process_brick(g, o, s, bb, bricks[i], B, sc);
    setups_clear(sc);
    return bad ? -1 : 0;
}

/* One block of a field stored by blocks: its bricks' values into its
 * slot; then, if every voxel holds the band, no slot. A block whose
 * bricks have no candidates has none to begin with. -1: out of memory. */
static int process_block(st_grid_blocks *bk, const st_soup *s,
                         const band_bins *bb, size_t block, double B,
                         brick_scratch *sc)
{
    const size_t at = bk->at[block];
    if (at == ST_GRID_NO_BLOCK)
        return 0;
    const st_grid *g = &bk->head;
    const size_t n[3] = {g->nx, g->ny, g->nz};
    const size_t b[3] = {block % bk->nb[0], (block / bk->nb[0]) % bk->nb[1],
                         block / (bk->nb[0] * bk->nb[1])};
    enum { E = ST_GRID_BLOCK * ST_GRID_BLOCK * ST_GRID_BLOCK };
    const brick_out o = {bk->values + at, NULL,
                         {ST_GRID_BLOCK * ST_GRID_BLOCK, ST_GRID_BLOCK, 1},
                         {b[0] * ST_GRID_BLOCK, b[1] * ST_GRID_BLOCK,
                          b[2] * ST_GRID_BLOCK}};
    const float Bf = (float)B;
    /* Voxels beyond the grid hold the band; the bricks write the rest. */
    if (o.lo[0] + ST_GRID_BLOCK > n[0] || o.lo[1] + ST_GRID_BLOCK > n[1] ||
        o.lo[2] + ST_GRID_BLOCK > n[2])
        for (size_t q = 0; q < E; q++)
            o.val[q] = Bf;
    if (block_bricks(g, &o, s, bb, b, B, sc))
        return -1;
    size_t q = 0;
    while (q < E && o.val[q] == Bf)
        q++;
    if (q == E)
        bk->at[block] = ST_GRID_NO_BLOCK;
    return 0;
}

/* Give every block a brick of which has candidates a slot of values. */
static st_status block_slots(st_grid_blocks *bk, const band_bins *bb,
                             st_error *err)
{
    const brick_grid *bg = &bb->bg;
    const size_t E = ST_GRID_BLOCK * ST_GRID_BLOCK * ST_GRID_BLOCK;
    size_t nslots = 0;
    for (size_t k = 0; k < bg->n[2]; k++)
        for (size_t j = 0; j < bg->n[1]; j++)
            for (size_t i = 0; i < bg->n[0]; i++) {
                const size_t brick = i + bg->n[0] * (j + bg->n[1] * k);
                const size_t block = i / BRICKS_PER_BLOCK + bk->nb[0] *
                    (j / BRICKS_PER_BLOCK + bk->nb[1] * (k / BRICKS_PER_BLOCK));
                if (bin_count(bb, brick) && bk->at[block] == ST_GRID_NO_BLOCK)
                    bk->at[block] = E * nslots++;
            }
    size_t bytes;
    if (st_size_mul(&bytes, nslots, E * sizeof(float)) ||
        !(bk->values = st_malloc_big(bytes ? bytes : 1)))
        return st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory for "
                            "%zu blocks of the band", nslots);
    return ST_OK;
}

/* One more of the band's `total` units done: count it in *done (shared by
 * the threads) and report the fraction from thread 0 every mask + 1 units
 * (mask + 1 a power of two). */
static void band_progress(const st_progress *progress, size_t *done, size_t total,
                          size_t mask)
{
    size_t now;
    #pragma omp atomic capture
    now = ++*done;
#ifdef _OPENMP
    if (omp_get_thread_num() != 0)
        return;
#endif
    if ((now & mask) == 0)
        st_progress_report(progress, "distance band", (double)now / (double)total);
}

/* The band's exact distances for every brick of g (dense: through near as
 * well, if given), or of every block of bk (then g is bk's head). */
static st_status band_bricks(const st_grid *g, int32_t *near,
                             st_grid_blocks *bk, const st_soup *s,
                             const band_bins *bb, double B,
                             const st_progress *progress, st_error *err)
{
    /* A dense band field is walked by the blocks of bricks too (the
     * setups shared within each); a full field brick by brick, each
     * brick's candidates sorted whole. */
    const size_t nbl[3] = {(bb->bg.n[0] + BRICKS_PER_BLOCK - 1) / BRICKS_PER_BLOCK,
                           (bb->bg.n[1] + BRICKS_PER_BLOCK - 1) / BRICKS_PER_BLOCK,
                           (bb->bg.n[2] + BRICKS_PER_BLOCK - 1) / BRICKS_PER_BLOCK};
    const int by_block = bk || !near;
    const size_t nunits = bk ? bk->nb[0] * bk->nb[1] * bk->nb[2]
                          : by_block ? nbl[0] * nbl[1] * nbl[2] : bb->nb;
    const brick_out dense = {g->data, near, {1, g->nx, g->nx * g->ny}, {0, 0, 0}};
    int oom = 0;
    size_t done = 0;
    /* A cancelled run skips the bricks left (a brick is well under a
     * millisecond of work). */
    const int stopped = st_progress_cancelled(progress);
    #pragma omp parallel if (!stopped)
    {
        brick_scratch sc;
        memset(&sc, 0, sizeof sc);
        #pragma omp for schedule(dynamic, by_block ? 4 : 16)
        for (size_t u = 0; u < nunits; u++) {
            if (st_progress_cancelled(progress))
                continue;
            int bad;
            if (bk)
                bad = process_block(bk, s, bb, u, B, &sc);
            else if (by_block) {
                const size_t b[3] = {u % nbl[0], (u / nbl[0]) % nbl[1],
                                     u / (nbl[0] * nbl[1])};
                bad = block_bricks(g, &dense, s, bb, b, B, &sc);
            } else if (!(bad = scratch_reserve(&sc, bin_count(bb, u)) ||
                             scratch_setups(&sc, bin_count(bb, u))))
                process_brick(g, &dense, s, bb, u, B, &sc);
            if (bad) {
                #pragma omp atomic write
                oom = 1;
                continue;
            }
            band_progress(progress, &done, nunits, 1023);
        }
        scratch_free(&sc);
    }
    if (oom)
        return st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory");
    if (st_progress_cancelled(progress))
        return st_error_set(err, ST_ECANCELLED, NULL, 0, "cancelled");
    st_progress_report(progress, "distance band", 1.0);
    return ST_OK;
}

/* The band pass: every voxel of g (a dense grid, with near for a full
 * field), or of bk's blocks, gets its exact distance where it is below B,
 * else B. */
static st_status band_pass(st_grid *g, int32_t *near, st_grid_blocks *bk,
                           const st_soup *s, double B,
                           const st_progress *progress, st_error *err)
{
    band_bins bb;
    st_status st = bin_triangles(&bb, g, s, B, progress, err);
    if (st)
        return st;
    if (bk)
        st = block_slots(bk, &bb, err);
    if (!st)
        st = band_bricks(g, near, bk, s, &bb, B, progress, err);
    bins_free(&bb);
    if (st || !bk)
        return st;
    bk->nstored = 0;
    const size_t n = bk->nb[0] * bk->nb[1] * bk->nb[2];
    for (size_t b = 0; b < n; b++)
        bk->nstored += bk->at[b] != ST_GRID_NO_BLOCK;
    return ST_OK;
}

/* The band by a BVH (st_dist_field_bvh): one nearest-triangle walk per
 * voxel. Depth first, the nearer child first; a node or a leaf's
 * triangle is skipped when its box is farther than the best distance so
 * far times (1 + 1e-9) plus 1e-12 voxel, the slack of the bricks' ball
 * tests (a box is the exact min/max of its triangles' coordinates, so
 * it is never farther than a triangle in it); the others are measured by
 * band_try, as a brick measures them. So a voxel's value is, as there,
 * the minimum over every triangle within B, in another order. */
#define DIST_BVH_STACK 128

/* The band value of the voxel at p: B, or its distance to s below B. */
static float bvh_voxel(const st_bvh *bvh, const st_soup *s, const double p[3],
                       double B, double slack)
{
    const double B2 = B * B;
    double cur = B2, curd = B;
    double lim = curd * (1.0 + 1e-9) + slack, lim2 = lim * lim;
    uint32_t stack[DIST_BVH_STACK];
    double sd2[DIST_BVH_STACK];
    int sp = 0;
    const st_bvh_node *nodes = bvh->nodes;
    const double d0 = st_box_dist2(nodes[0].lo, nodes[0].hi, p);
    if (d0 <= lim2) {
        stack[0] = 0;
        sd2[sp++] = d0;
    }
    tri_setup t;
    while (sp > 0) {
        sp--;
        if (sd2[sp] > lim2)
            continue;               /* the best shrank since it was pushed */
        const st_bvh_node *n = &nodes[stack[sp]];
        if (n->count) {
            for (uint32_t i = 0; i < n->count; i++) {
                const double *tb = bvh->tbox + 6 * (size_t)(n->start + i);
                if (st_box_dist2(tb, tb + 3, p) > lim2)
                    continue;
                setup_triangle(&t, s, bvh->order[n->start + i]);
                const double before = cur;
                band_try(&t, p, &cur, &curd);
                if (cur < before) {
                    lim = curd * (1.0 + 1e-9) + slack;
                    lim2 = lim * lim;
                }
            }
            continue;
        }
        uint32_t l = n->start, r = n->start + 1;
        double dl = st_box_dist2(nodes[l].lo, nodes[l].hi, p);
        double dr = st_box_dist2(nodes[r].lo, nodes[r].hi, p);
        if (dl > dr) {              /* the nearer one on top */
            const uint32_t x = l;
            l = r;
            r = x;
            const double d = dl;
            dl = dr;
            dr = d;
        }
        /* A tree of at most 2^32 triangles, median splits: far shallower
         * than the stack (each level leaves at most one node behind). */
        if (dr <= lim2 && sp < DIST_BVH_STACK) {
            stack[sp] = r;
            sd2[sp++] = dr;
        }
        if (dl <= lim2 && sp < DIST_BVH_STACK) {
            stack[sp] = l;
            sd2[sp++] = dl;
        }
    }
    return cur >= B2 ? (float)B : (float)curd;
}

/* Every voxel of the dense band field g by bvh_voxel, rows in parallel
 * (each voxel's walk is its own: the same for any thread count). */
static st_status band_pass_bvh(st_grid *g, const st_soup *s, const st_bvh *bvh,
                               double B, const st_progress *progress, st_error *err)
{
    const size_t nx = g->nx, rows = g->ny * g->nz;
    const double slack = 1e-12 * g->voxel;
    size_t done = 0;
    const int stopped = st_progress_cancelled(progress);
    #pragma omp parallel for schedule(dynamic, 4) if (!stopped)
    for (size_t r = 0; r < rows; r++) {
        if (st_progress_cancelled(progress))
            continue;
        const size_t j = r % g->ny, k = r / g->ny;
        double p[3] = {0.0, g->origin[1] + g->voxel * (double)j,
                       g->origin[2] + g->voxel * (double)k};
        float *row = g->data + nx * r;
        for (size_t i = 0; i < nx; i++) {
            p[0] = g->origin[0] + g->voxel * (double)i;
            row[i] = bvh_voxel(bvh, s, p, B, slack);
        }
        band_progress(progress, &done, rows, 255);
    }
    if (st_progress_cancelled(progress))
        return st_error_set(err, ST_ECANCELLED, NULL, 0, "cancelled");
    st_progress_report(progress, "distance band", 1.0);
    return ST_OK;
}

/* Distance from p to triangle t of s, squared. */
static double soup_tri_dist2(const st_soup *s, int32_t t, const double p[3])
{
    const uint32_t *v = s->tris + 3 * (size_t)t;
    return st_point_triangle_dist2(p, s->xyz + 3 * (size_t)v[0],
                                   s->xyz + 3 * (size_t)v[1],
                                   s->xyz + 3 * (size_t)v[2], NULL);
}

/* One raster sweep (forward: dir = +1, backward: -1) over the voxels the
 * band did not fix: each takes the nearest of the triangles its 13
 * already-swept neighbours found, measured exactly. */
static int sweep(st_grid *g, int32_t *near, const uint8_t *fixed,
                 const st_soup *s, int dir, const st_progress *progress)
{
    const long nx = (long)g->nx, ny = (long)g->ny, nz = (long)g->nz;
    /* The 13 neighbours that precede a voxel in raster order. */
    static const int off[13][3] = {
        {-1, 0, 0}, {-1, -1, 0}, {0, -1, 0}, {1, -1, 0},
        {-1, -1, -1}, {0, -1, -1}, {1, -1, -1},
        {-1, 0, -1}, {0, 0, -1}, {1, 0, -1},
        {-1, 1, -1}, {0, 1, -1}, {1, 1, -1}};
    for (long kk = 0; kk < nz; kk++) {
        long k = dir > 0 ? kk : nz - 1 - kk;
        if (st_progress_cancelled(progress))
            return 0;
        for (long jj = 0; jj < ny; jj++) {
            long j = dir > 0 ? jj : ny - 1 - jj;
            for (long ii = 0; ii < nx; ii++) {
                long i = dir > 0 ? ii : nx - 1 - ii;
                size_t idx = (size_t)i + (size_t)nx * ((size_t)j + (size_t)ny * (size_t)k);
                if (fixed[idx])
                    continue;
                double p[3];
                st_grid_center(g, (size_t)i, (size_t)j, (size_t)k, p);
                int32_t best = near[idx];
                double best_d2 = best >= 0 ? soup_tri_dist2(s, best, p) : INFINITY;
                int32_t tried[13];
                int ntried = 0;
                for (int q = 0; q < 13; q++) {
                    long a = i + dir * off[q][0], b = j + dir * off[q][1],
                         c = k + dir * off[q][2];
                    if (a < 0 || a >= nx || b < 0 || b >= ny || c < 0 || c >= nz)
                        continue;
                    int32_t t = near[(size_t)a + (size_t)nx * ((size_t)b + (size_t)ny * (size_t)c)];
                    if (t < 0 || t == best)
                        continue;
                    int seen = 0;
                    for (int r = 0; r < ntried; r++)
                        seen |= tried[r] == t;
                    if (seen)
                        continue;
                    tried[ntried++] = t;
                    double d2 = soup_tri_dist2(s, t, p);
                    /* Ties go to the lower index, so the sweep order does
                     * not decide which triangle a voxel keeps. */
                    if (d2 < best_d2 || (d2 == best_d2 && t < best)) {
                        best_d2 = d2;
                        best = t;
                    }
                }
                near[idx] = best;
                g->data[idx] = best >= 0 ? (float)sqrt(best_d2) : INFINITY;
            }
        }
    }
    return 1;
}

/* Beyond the band: a vector distance transform over triangles. The band
 * fixed every voxel within B exactly, with its nearest triangle; sweeps in
 * raster order and back hand nearest triangles outward, each voxel keeping
 * the nearest of those its neighbours hold (Danielsson's propagation, with
 * triangles instead of points: values are exact distances to a real
 * triangle, so never below the truth; the test suite measures how often
 * the propagated triangle is not the nearest and by how much). */
#define SWEEPS 4
static st_status full_pass(st_grid *g, int32_t *near, const st_soup *s,
                           double B, const st_progress *progress,
                           st_error *err)
{
    const size_t n = st_grid_count(g);
    uint8_t *fixed = st_malloc_array(n, 1);
    if (!fixed)
        return st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory");
    const float Bf = (float)B;
    for (size_t i = 0; i < n; i++) {
        fixed[i] = g->data[i] < Bf;
        if (!fixed[i])
            g->data[i] = INFINITY;
    }
    static const char *stage = "distance beyond the band";
    st_progress_report(progress, stage, 0.0);
    for (int pass = 0; pass < SWEEPS; pass++) {
        if (!sweep(g, near, fixed, s, pass % 2 ? -1 : +1, progress)) {
            free(fixed);
            return st_error_set(err, ST_ECANCELLED, NULL, 0, "cancelled");
        }
        st_progress_report(progress, stage, (double)(pass + 1) / SWEEPS);
    }
    free(fixed);
    return ST_OK;
}

/* A field's layout and band. */
typedef struct dist_plan {
    int full;            /* band = INFINITY */
    size_t dims[3];
    double origin[3], h;
    double band_vox;     /* the exact band in voxels (the default if full) */
} dist_plan;

/* The parameters' checks and the layout. */
static st_status dist_setup(dist_plan *pl, const st_soup *s,
                            const st_dist_params *p, st_error *err)
{
    pl->full = isinf(p->band) && p->band > 0;
    if (!pl->full && !(p->band >= ST_DIST_MIN_BAND))
        return st_error_set(err, ST_EINPUT, NULL, 0,
                            "band %g is below the minimum of %g voxels",
                            p->band, ST_DIST_MIN_BAND);
    pl->band_vox = pl->full ? ST_DIST_DEFAULT_BAND : p->band;
    return st_dist_layout(s, p, pl->dims, pl->origin, &pl->h, err);
}

/* The metadata every distance field carries (dist.h). */
static st_status dist_meta(st_meta *m, const st_soup *s, int full,
                           double band_vox, st_error *err)
{
    char buf[64];
    snprintf(buf, sizeof buf, "%zu", s->ntris);
    st_status st = st_meta_set(m, "triangles", buf);
    snprintf(buf, sizeof buf, "%zu", s->nverts);
    st = st ? st : st_meta_set(m, "vertices", buf);
    if (full)
        snprintf(buf, sizeof buf, "full");
    else
        snprintf(buf, sizeof buf, "%.17g", band_vox);
    st = st ? st : st_meta_set(m, "band_voxels", buf);
    if (st)
        return st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory");
    return ST_OK;
}

int st_dist_wants_bvh(const st_soup *s, const st_dist_params *p)
{
    dist_plan pl;
    if (!s || !p || s->ntris == 0 || dist_setup(&pl, s, p, NULL) || pl.full)
        return 0;
    const double voxels = (double)pl.dims[0] * (double)pl.dims[1] * (double)pl.dims[2];
    return (double)s->ntris >= ST_DIST_BVH_TRIS_PER_VOXEL * voxels;
}

st_status st_dist_field(st_grid **out, const st_soup *s,
                        const st_dist_params *p, const st_progress *progress,
                        st_error *err)
{
    return st_dist_field_bvh(out, s, p, NULL, progress, err);
}

st_status st_dist_field_bvh(st_grid **out, const st_soup *s,
                            const st_dist_params *p, const st_bvh *bvh,
                            const st_progress *progress, st_error *err)
{
    *out = NULL;
    dist_plan pl;
    st_status st = dist_setup(&pl, s, p, err);
    if (st)
        return st;
    const int full = pl.full;
    st_grid *g;
    double B = pl.band_vox * pl.h;
    /* The band pass writes every voxel. */
    st = st_grid_new_unset(&g, pl.dims[0], pl.dims[1], pl.dims[2], pl.origin,
                           pl.h, p->max_bytes, err);
    if (st)
        return st;
    g->kind = ST_GRID_DISTANCE;
    int32_t *near = NULL;
    if (full && !(near = st_malloc_array(st_grid_count(g), sizeof *near))) {
        st_grid_free(g);
        return st_error_set(err, ST_ENOMEM, NULL, 0,
                            "out of memory for the nearest-triangle map");
    }
    if (bvh && !full)
        st = band_pass_bvh(g, s, bvh, B, progress, err);
    else
        st = band_pass(g, near, NULL, s, B, progress, err);
    if (!st && full)
        st = full_pass(g, near, s, B, progress, err);
    free(near);
    g->band = full ? INFINITY : B;
    if (!st)
        st = dist_meta(&g->meta, s, full, pl.band_vox, err);
    if (st) {
        st_grid_free(g);
        return st;
    }
    *out = g;
    return ST_OK;
}

st_status st_dist_field_far(st_grid **out, const st_soup *s,
                            const st_dist_params *p, st_error *err)
{
    *out = NULL;
    dist_plan pl;
    st_status st = dist_setup(&pl, s, p, err);
    if (st)
        return st;
    if (pl.full)
        return st_error_set(err, ST_EINPUT, NULL, 0,
                            "a field of far values needs a finite band");
    const double B = pl.band_vox * pl.h;
    st_grid *g;
    st = st_grid_new_unset(&g, pl.dims[0], pl.dims[1], pl.dims[2], pl.origin,
                           pl.h, p->max_bytes, err);
    if (st)
        return st;
    g->kind = ST_GRID_DISTANCE;
    g->band = B;
    const float Bf = (float)B;
    const long long n = (long long)st_grid_count(g);
    #pragma omp parallel for schedule(static)
    for (long long i = 0; i < n; i++)
        g->data[i] = Bf;
    if ((st = dist_meta(&g->meta, s, 0, pl.band_vox, err))) {
        st_grid_free(g);
        return st;
    }
    *out = g;
    return ST_OK;
}

st_status st_dist_field_blocks(st_grid_blocks **out, const st_soup *s,
                               const st_dist_params *p,
                               const st_progress *progress, st_error *err)
{
    *out = NULL;
    if (isinf(p->band))
        return st_error_set(err, ST_EINPUT, NULL, 0, "a field stored by "
                            "blocks needs a finite band");
    dist_plan pl;
    st_status st = dist_setup(&pl, s, p, err);
    st_grid_blocks *bk = NULL;
    if (!st)
        st = st_grid_blocks_new(&bk, pl.dims[0], pl.dims[1], pl.dims[2],
                                pl.origin, pl.h, p->max_bytes, err);
    if (st)
        return st;
    const double B = pl.band_vox * pl.h;
    bk->head.kind = ST_GRID_DISTANCE;
    bk->head.band = B;
    st = band_pass(&bk->head, NULL, bk, s, B, progress, err);
    if (!st)
        st = dist_meta(&bk->head.meta, s, 0, pl.band_vox, err);
    if (st) {
        st_grid_blocks_free(bk);
        return st;
    }
    *out = bk;
    return ST_OK;
}

/* st_dist_lower's triangles: each one's voxel range within reach (its
 * box grown by reach, clipped to the grid), its own box, its unit normal
 * (zero for a triangle st_point_triangle_dist2 takes as degenerate) and
 * the slack of a lower bound on its distance. */
typedef struct lower_tri {
    uint32_t t;
    size_t i0, i1, j0, j1;
    double zlo, zhi;
    double lo[3], hi[3], n[3];
    double slack;
} lower_tri;

/* Cull bounds (bvh.c's tri_beyond gives the analysis): a voxel whose
 * distance from the triangle's box or plane exceeds (lim + slack) (1 +
 * LOWER_REL) is farther than lim by st_point_triangle_dist2 too, rounding
 * included, where slack is LOWER_SIDE of the triangle's box side plus
 * LOWER_ABS of the coordinates' magnitude. */
#define LOWER_REL 1e-4
#define LOWER_SIDE 1e-4
#define LOWER_ABS 3e-14

static void lower_shape(lower_tri *r, const double *a, const double *b, const double *c,
                        double m)
{
    double e0[3], e1[3], e2[3];
    st_sub3(e0, b, a);
    st_sub3(e1, c, b);
    st_sub3(e2, a, c);
    st_cross3(r->n, e0, e1);
    const double emax = fmax(st_norm3(e0), fmax(st_norm3(e1), st_norm3(e2)));
    const double nl = st_norm3(r->n);
    for (int q = 0; q < 3; q++)
        r->n[q] = nl > ST_DEGENERATE_AREA_RATIO * emax * emax ? r->n[q] / nl : 0.0;
    double side = 0.0;
    for (int q = 0; q < 3; q++) {
        r->lo[q] = fmin(a[q], fmin(b[q], c[q]));
        r->hi[q] = fmax(a[q], fmax(b[q], c[q]));
        side = fmax(side, r->hi[q] - r->lo[q]);
    }
    r->slack = LOWER_SIDE * side + LOWER_ABS * m;
}

/* r[0..n): the triangles of s whose columns meet the grid's; returns n. */
static size_t lower_ranges(lower_tri *r, const st_grid *g, const st_soup *s, double reach)
{
    const size_t nx = g->nx, ny = g->ny;
    const double h = g->voxel;
    double m = 0.0;   /* the magnitude of the soup's and the grid's coordinates */
    for (size_t v = 0; v < 3 * s->nverts; v++)
        m = fmax(m, fabs(s->xyz[v]));
    const size_t nn[3] = {g->nx, g->ny, g->nz};
    for (int q = 0; q < 3; q++)
        m = fmax(m, fabs(g->origin[q]) + h * (double)nn[q]);
    size_t n = 0;
    for (size_t t = 0; t < s->ntris; t++) {
        const double *a = s->xyz + 3 * (size_t)s->tris[3 * t],
                     *b = s->xyz + 3 * (size_t)s->tris[3 * t + 1],
                     *c = s->xyz + 3 * (size_t)s->tris[3 * t + 2];
        double lo[3], hi[3];
        for (int q = 0; q < 3; q++) {
            lo[q] = fmin(a[q], fmin(b[q], c[q])) - reach;
            hi[q] = fmax(a[q], fmax(b[q], c[q])) + reach;
        }
        double fi0 = ceil((lo[0] - g->origin[0]) / h), fi1 = floor((hi[0] - g->origin[0]) / h);
        double fj0 = ceil((lo[1] - g->origin[1]) / h), fj1 = floor((hi[1] - g->origin[1]) / h);
        if (fi1 < 0 || fj1 < 0 || fi0 > (double)(nx - 1) || fj0 > (double)(ny - 1) ||
            fi0 > fi1 || fj0 > fj1)
            continue;
        r[n].t = (uint32_t)t;
        r[n].zlo = lo[2];
        r[n].zhi = hi[2];
        r[n].i0 = fi0 < 0 ? 0 : (size_t)fi0;
        r[n].j0 = fj0 < 0 ? 0 : (size_t)fj0;
        r[n].i1 = fi1 > (double)(nx - 1) ? nx - 1 : (size_t)fi1;
        r[n].j1 = fj1 > (double)(ny - 1) ? ny - 1 : (size_t)fj1;
        lower_shape(r + n, a, b, c, m);
        n++;
    }
    return n;
}

/* Whether p is certainly farther than lim from triangle r: from its box
 * or, when it has a normal, its plane through a. */
static int lower_beyond(const lower_tri *r, const double *a, const double p[3], double lim)
{
    const double x = (lim + r->slack) * (1.0 + LOWER_REL), x2 = x * x;
    double d2 = 0.0;
    for (int q = 0; q < 3; q++) {
        const double below = r->lo[q] - p[q], above = p[q] - r->hi[q];
        const double d = below > 0.0 ? below : above > 0.0 ? above : 0.0;
        d2 += d * d;
    }
    if (d2 > x2)
        return 1;
    const double w = r->n[0] * (p[0] - a[0]) + r->n[1] * (p[1] - a[1]) + r->n[2] * (p[2] - a[2]);
    return w * w > x2;
}

/* The columns [*i0, *i1] of row (y, z) where triangle r may be within
 * reach: its box and its plane (when the plane is not nearly along the
 * row) by the bounds of lower_beyond, a voxel wider on each side than
 * computed, so every voxel left out is one lower_beyond skips. Returns 0
 * when none is. */
static int lower_span(const lower_tri *r, const double *a, const st_grid *g, double y, double z,
                      double reach, size_t *i0, size_t *i1)
{
    const double x = (reach + r->slack) * (1.0 + LOWER_REL), h = g->voxel, o = g->origin[0];
    const double dy = y < r->lo[1] ? r->lo[1] - y : y > r->hi[1] ? y - r->hi[1] : 0.0;
    const double dz = z < r->lo[2] ? r->lo[2] - z : z > r->hi[2] ? z - r->hi[2] : 0.0;
    const double left = x * x - dy * dy - dz * dz;
    if (left < 0.0)
        return 0;
    double xlo = r->lo[0] - sqrt(left), xhi = r->hi[0] + sqrt(left);
    if (fabs(r->n[0]) * h > 1e-3 * x) {
        /* |n0 (px - a0) + w| <= x, w the rest of the plane's distance */
        const double w = r->n[1] * (y - a[1]) + r->n[2] * (z - a[2]);
        const double p0 = a[0] + (-x - w) / r->n[0], p1 = a[0] + (x - w) / r->n[0];
        xlo = fmax(xlo, fmin(p0, p1));
        xhi = fmin(xhi, fmax(p0, p1));
    }
    const double f0 = floor((xlo - o) / h) - 1.0, f1 = ceil((xhi - o) / h) + 1.0;
    if (f1 < (double)r->i0 || f0 > (double)r->i1 || f0 > f1)
        return 0;
    *i0 = f0 > (double)r->i0 ? (size_t)f0 : r->i0;
    *i1 = f1 < (double)r->i1 ? (size_t)f1 : r->i1;
    return 1;
}

/* Layer k of st_dist_lower: each triangle's voxels in reach get its
 * distance where that is below reach and lowers them. A voxel is skipped
 * where the triangle is certainly farther than reach or than its value
 * (neither would change it), so the value is the same minimum. */
static void lower_layer(st_grid *g, const st_soup *s, const lower_tri *r, size_t n,
                        size_t k, double reach)
{
    const double h = g->voxel, z = g->origin[2] + h * (double)k;
    for (size_t u = 0; u < n; u++) {
        if (z < r[u].zlo || z > r[u].zhi)
            continue;
        const uint32_t *c = s->tris + 3 * (size_t)r[u].t;
        const double *a = s->xyz + 3 * (size_t)c[0], *b = s->xyz + 3 * (size_t)c[1],
                     *cc = s->xyz + 3 * (size_t)c[2];
        for (size_t j = r[u].j0; j <= r[u].j1; j++) {
            const double y = g->origin[1] + h * (double)j;
            size_t i0, i1;
            if (!lower_span(r + u, a, g, y, z, reach, &i0, &i1))
                continue;
            for (size_t i = i0; i <= i1; i++) {
                float *v = g->data + st_grid_index(g, i, j, k);
                if (!(*v > 0.0f))
                    continue;   /* no distance is below it */
                const double p[3] = {g->origin[0] + h * (double)i, y, z};
                /* fmin(reach, *v) without the libm call (both above 0) */
                const double lim = (double)*v < reach ? (double)*v : reach;
                if (lower_beyond(r + u, a, p, lim))
                    continue;
                const double d2 = st_point_triangle_dist2(p, a, b, cc, NULL);
                if (!(d2 < reach * reach))
                    continue;
                const float d = (float)sqrt(d2);
                if (d < *v)
                    *v = d;
            }
        }
    }
}

st_status st_dist_lower(st_grid *g, const st_soup *s, double reach,
                        st_error *err)
{
    if (!(reach > 0) || !s->ntris)
        return ST_OK;
    lower_tri *r = st_malloc_array(s->ntris, sizeof *r);
    if (!r)
        return st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory for the caps' distances");
    const size_t n = lower_ranges(r, g, s, reach), nz = g->nz;
    /* A z layer per iteration: every voxel's minimum over the triangles
     * within reach of it, in any order (a minimum), so the threads never
     * share a voxel. */
    #pragma omp parallel for schedule(dynamic, 1)
    for (size_t k = 0; k < nz; k++)
        lower_layer(g, s, r, n, k, reach);
    free(r);
    return ST_OK;
}
