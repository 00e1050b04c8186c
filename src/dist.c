/*
 * dist.c - unsigned distance fields of triangle soups (see dist.h).
 *
 * Band pass. The grid's z layers are cut into chunks; every triangle is
 * binned into the chunks its band-expanded box reaches, and the chunks are
 * processed in parallel, so no two threads write the same voxel. Within a
 * chunk, each triangle visits the voxels of its expanded box row by row,
 * rows running along the axis closest to its normal: on such a row the
 * distance to the triangle's plane is linear in the index, so the voxels
 * whose plane distance is below the band form an interval computed up
 * front. A large triangle (CAD) thus costs its area times the band, not its
 * bounding box. Each voxel keeps the minimum squared distance.
 *
 * Full field. Voxels the band did not reach ask the BVH for their nearest
 * triangle, bounded by the previous voxel of the row plus one voxel: the
 * bound keeps the search near the answer, and the answer is exact.
 */
#include "souptet/dist.h"
#include "souptet/bvh.h"
#include "souptet/geom.h"
#include "souptet/mem.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#ifdef _OPENMP
#include <omp.h>
#endif

/* z layers per parallel chunk: small enough for load balance on a 128^3
 * grid, large enough that triangles rarely straddle chunks. */
#define CHUNK_LAYERS 4

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

static void setup_triangle(tri_setup *t, const st_soup *s, size_t tri)
{
    for (int k = 0; k < 3; k++)
        memcpy(t->v[k], s->xyz + 3 * (size_t)s->tris[3 * tri + k],
               3 * sizeof(double));
    double emax = 0.0;
    for (int i = 0; i < 3; i++) {
        st_sub3(t->e[i], t->v[(i + 1) % 3], t->v[i]);
        double ee = st_dot3(t->e[i], t->e[i]);
        t->inv_ee[i] = ee > 0.0 ? 1.0 / ee : 0.0;
        emax = fmax(emax, st_norm3(t->e[i]));
    }
    double n[3];
    st_cross3(n, t->e[0], t->e[1]);
    double nl = st_norm3(n);
    /* Same rule as st_point_triangle_dist2 (geom.h explains the ratio). */
    t->degenerate = !(nl > ST_DEGENERATE_AREA_RATIO * emax * emax);
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
        double d = edge_dist2(t, 0, p);
        d = fmin(d, edge_dist2(t, 1, p));
        return fmin(d, edge_dist2(t, 2, p));
    }
    int out0 = st_dot3(p, t->m[0]) < t->mo[0];
    int out1 = st_dot3(p, t->m[1]) < t->mo[1];
    int out2 = st_dot3(p, t->m[2]) < t->mo[2];
    if (!(out0 | out1 | out2))
        return plane_d * plane_d;
    double d = INFINITY;
    if (out0)
        d = edge_dist2(t, 0, p);
    if (out1)
        d = fmin(d, edge_dist2(t, 1, p));
    if (out2)
        d = fmin(d, edge_dist2(t, 2, p));
    return d;
}

/* Visit the voxels of triangle t within distance B (model units) whose z
 * index lies in [kz0, kz1], lowering data (squared distances) there. */
static void splat_triangle(const st_grid *g, float *data, const tri_setup *t,
                           double B, long kz0, long kz1)
{
    const double h = g->voxel;
    const long n[3] = {(long)g->nx, (long)g->ny, (long)g->nz};
    const size_t stride[3] = {1, g->nx, g->nx * g->ny};
    long lo[3], hi[3];
    for (int a = 0; a < 3; a++) {
        double mn = fmin(t->v[0][a], fmin(t->v[1][a], t->v[2][a])) - B;
        double mx = fmax(t->v[0][a], fmax(t->v[1][a], t->v[2][a])) + B;
        double l = ceil((mn - g->origin[a]) / h);
        double u = floor((mx - g->origin[a]) / h);
        lo[a] = l < 0.0 ? 0 : (long)l;
        hi[a] = u > (double)(n[a] - 1) ? n[a] - 1 : (long)u;
        if (lo[a] > hi[a])
            return;
    }
    if (lo[2] < kz0)
        lo[2] = kz0;
    if (hi[2] > kz1)
        hi[2] = kz1;
    if (lo[2] > hi[2])
        return;
    const int d = t->dom, u = (d + 1) % 3, w = (d + 2) % 3;
    const double B2 = B * B;
    /* Plane distance moves by this much per voxel along the row. */
    const double step = t->nu[d] * h;
    double p[3];
    for (long iw = lo[w]; iw <= hi[w]; iw++) {
        p[w] = g->origin[w] + h * (double)iw;
        for (long iu = lo[u]; iu <= hi[u]; iu++) {
            p[u] = g->origin[u] + h * (double)iu;
            long r0 = lo[d], r1 = hi[d];
            p[d] = g->origin[d];
            double pd0 = 0.0;
            if (!t->degenerate) {
                double q[3];
                st_sub3(q, p, t->v[0]);
                pd0 = st_dot3(q, t->nu);   /* plane distance at index 0 */
                /* |pd0 + i * step| < B on an interval of i; widen by one
                 * voxel each side against rounding. */
                double ta = (-B - pd0) / step, tb = (B - pd0) / step;
                if (ta > tb) {
                    double x = ta; ta = tb; tb = x;
                }
                ta = floor(ta) - 1.0;
                tb = ceil(tb) + 1.0;
                if (ta > (double)r0)
                    r0 = ta > (double)r1 ? r1 + 1 : (long)ta;
                if (tb < (double)r1)
                    r1 = tb < (double)r0 ? r0 - 1 : (long)tb;
            }
            size_t base = (size_t)iw * stride[w] + (size_t)iu * stride[u];
            for (long id = r0; id <= r1; id++) {
                p[d] = g->origin[d] + h * (double)id;
                double pd = pd0 + step * (double)id;
                if (pd * pd >= B2)
                    continue;
                double d2 = tri_dist2(t, p, pd);
                float *cell = &data[base + (size_t)id * stride[d]];
                if (d2 < B2 && (float)d2 < *cell)
                    *cell = (float)d2;
            }
        }
    }
}

/* Lowest and highest z index the band around triangle tri reaches. */
static void tri_zrange(const st_grid *g, const st_soup *s, size_t tri,
                       double B, long *k0, long *k1)
{
    double mn = INFINITY, mx = -INFINITY;
    for (int k = 0; k < 3; k++) {
        double z = s->xyz[3 * (size_t)s->tris[3 * tri + k] + 2];
        mn = fmin(mn, z);
        mx = fmax(mx, z);
    }
    double l = ceil((mn - B - g->origin[2]) / g->voxel);
    double u = floor((mx + B - g->origin[2]) / g->voxel);
    double top = (double)g->nz - 1.0;
    *k0 = l < 0.0 ? 0 : (l > top ? (long)g->nz : (long)l);
    *k1 = u > top ? (long)g->nz - 1 : (u < 0.0 ? -1 : (long)u);
}

static st_status band_pass(st_grid *g, const st_soup *s, double B,
                           const st_progress *progress, st_error *err)
{
    const size_t nchunks = (g->nz + CHUNK_LAYERS - 1) / CHUNK_LAYERS;
    size_t *start = st_calloc_array(nchunks + 1, sizeof(size_t));
    if (!start)
        return st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory");
    /* Counting sort of (chunk, triangle) pairs: triangles stay in input
     * order within a chunk. */
    for (size_t t = 0; t < s->ntris; t++) {
        long k0, k1;
        tri_zrange(g, s, t, B, &k0, &k1);
        if (k0 > k1)
            continue;
        for (long c = k0 / CHUNK_LAYERS; c <= k1 / CHUNK_LAYERS; c++)
            start[c + 1]++;
    }
    for (size_t c = 0; c < nchunks; c++)
        start[c + 1] += start[c];
    uint32_t *list = st_malloc_array(start[nchunks], sizeof(uint32_t));
    size_t *fill = st_malloc_array(nchunks, sizeof(size_t));
    if (!list || !fill) {
        free(start);
        free(list);
        free(fill);
        return st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory");
    }
    memcpy(fill, start, nchunks * sizeof(size_t));
    for (size_t t = 0; t < s->ntris; t++) {
        long k0, k1;
        tri_zrange(g, s, t, B, &k0, &k1);
        if (k0 > k1)
            continue;
        for (long c = k0 / CHUNK_LAYERS; c <= k1 / CHUNK_LAYERS; c++)
            list[fill[c]++] = (uint32_t)t;
    }
    free(fill);

    const float B2f = (float)(B * B);
    const size_t nvox = st_grid_count(g);
    #pragma omp parallel for schedule(static)
    for (size_t i = 0; i < nvox; i++)
        g->data[i] = B2f;

    size_t done = 0;
    #pragma omp parallel for schedule(dynamic, 1)
    for (size_t c = 0; c < nchunks; c++) {
        long kz0 = (long)(c * CHUNK_LAYERS);
        long kz1 = kz0 + CHUNK_LAYERS - 1;
        for (size_t i = start[c]; i < start[c + 1]; i++) {
            tri_setup t;
            setup_triangle(&t, s, list[i]);
            splat_triangle(g, g->data, &t, B, kz0, kz1);
        }
        size_t now;
        #pragma omp atomic capture
        now = ++done;
#ifdef _OPENMP
        if (omp_get_thread_num() == 0)
#endif
            st_progress_report(progress, "distance band",
                               (double)now / (double)nchunks);
    }
    free(list);
    free(start);

    /* Squared distances to distances; everything at or past B is B. */
    const float Bf = (float)B;
    #pragma omp parallel for schedule(static)
    for (size_t i = 0; i < nvox; i++) {
        float d2 = g->data[i];
        g->data[i] = d2 >= B2f ? Bf : (float)sqrt((double)d2);
    }
    return ST_OK;
}

/* Fill every voxel the band left at B with its exact distance. */
static st_status full_pass(st_grid *g, const st_soup *s, double B,
                           const st_progress *progress, st_error *err)
{
    st_bvh *bvh;
    st_status st = st_bvh_build(&bvh, s, err);
    if (st)
        return st;
    const float Bf = (float)B;
    const size_t rows = g->ny * g->nz;
    const double h = g->voxel;
    size_t done = 0;
    #pragma omp parallel for schedule(dynamic, 16)
    for (size_t r = 0; r < rows; r++) {
        size_t j = r % g->ny, k = r / g->ny;
        float *row = g->data + g->nx * r;
        double prev = INFINITY;   /* exact distance of the previous voxel */
        for (size_t i = 0; i < g->nx; i++) {
            if (row[i] < Bf) {
                prev = row[i];
                continue;
            }
            double p[3];
            st_grid_center(g, i, j, k, p);
            /* d(p) <= d(prev) + h; the relative slack covers the float
             * rounding of prev, so the bound never excludes the answer. */
            double bound = isfinite(prev) ? (prev + h) * (1.0 + 1e-6) : INFINITY;
            int64_t tri;
            double d2 = st_bvh_nearest(bvh, p, bound * bound, &tri, NULL);
            if (tri < 0)
                d2 = st_bvh_nearest(bvh, p, INFINITY, &tri, NULL);
            double d = sqrt(d2);
            row[i] = (float)d;
            prev = d;
        }
        size_t now;
        #pragma omp atomic capture
        now = ++done;
#ifdef _OPENMP
        if (omp_get_thread_num() == 0 && (now & 63) == 0)
#endif
            st_progress_report(progress, "distance beyond the band",
                               (double)now / (double)rows);
    }
    st_bvh_free(bvh);
    return ST_OK;
}

st_status st_dist_field(st_grid **out, const st_soup *s,
                        const st_dist_params *p, const st_progress *progress,
                        st_error *err)
{
    *out = NULL;
    int full = isinf(p->band) && p->band > 0;
    if (!full && !(p->band >= ST_DIST_MIN_BAND))
        return st_error_set(err, ST_EINPUT, NULL, 0,
                            "band %g is below the minimum of %g voxels",
                            p->band, ST_DIST_MIN_BAND);
    size_t dims[3];
    double origin[3], h;
    st_status st = st_dist_layout(s, p, dims, origin, &h, err);
    if (st)
        return st;
    st_grid *g;
    double band_vox = full ? ST_DIST_DEFAULT_BAND : p->band;
    double B = band_vox * h;
    st = st_grid_new(&g, dims[0], dims[1], dims[2], origin, h, (float)B,
                     p->max_bytes, err);
    if (st)
        return st;
    g->kind = ST_GRID_DISTANCE;
    st = band_pass(g, s, B, progress, err);
    if (!st && full)
        st = full_pass(g, s, B, progress, err);
    if (st) {
        st_grid_free(g);
        return st;
    }
    g->band = full ? INFINITY : B;
    char buf[64];
    snprintf(buf, sizeof buf, "%zu", s->ntris);
    st = st_meta_set(&g->meta, "triangles", buf);
    snprintf(buf, sizeof buf, "%zu", s->nverts);
    st = st ? st : st_meta_set(&g->meta, "vertices", buf);
    if (full)
        snprintf(buf, sizeof buf, "full");
    else
        snprintf(buf, sizeof buf, "%.17g", band_vox);
    st = st ? st : st_meta_set(&g->meta, "band_voxels", buf);
    if (st) {
        st_grid_free(g);
        return st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory");
    }
    *out = g;
    return ST_OK;
}
