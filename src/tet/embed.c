/*
 * embed.c - the containing tet and barycentric coordinates of every
 * surface vertex (see embed.h).
 *
 * Bins. A uniform grid over the box of the mesh's points, about one bin
 * per tet, cubic bins where the box allows. Each tet is listed in every
 * bin its bounding box meets; the lists are built by a counting pass and a
 * fill pass in tet order, so each list is sorted and the first hit is the
 * lowest-numbered containing tet. The bin of a coordinate is
 * floor((x - lo) * inv), a monotone function of x, so a tet whose box
 * holds a point is always in that point's bin: no tolerance is needed.
 */
#include "souptet/embed.h"
#include "../base/fpenv.h"
#include "souptet/isect.h"
#include "souptet/mem.h"
#include "souptet/outfile.h"
#include "souptet/pred.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Bins per axis at most: 2^10 keeps the grid below 2^30 bins. */
#define MAX_DIM 1024

typedef struct bins {
    double lo[3], hi[3], inv[3];
    size_t dim[3];
    size_t *start;      /* nbins + 1 offsets into items */
    uint32_t *items;    /* tet indices, ascending within each bin */
    unsigned char *flat;
} bins;

static size_t cell_of(const bins *b, int k, double x)
{
    double f = floor((x - b->lo[k]) * b->inv[k]);
    if (!(f > 0.0))
        return 0;
    if (f >= (double)(b->dim[k] - 1))
        return b->dim[k] - 1;
    return (size_t)f;
}

static void free_bins(bins *b)
{
    free(b->start);
    free(b->items);
    free(b->flat);
}

static void tet_box(const st_tetmesh *m, size_t t, double lo[3],
                    double hi[3])
{
    const uint32_t *v = m->tets + 4 * t;
    for (int k = 0; k < 3; k++) {
        lo[k] = hi[k] = m->xyz[3 * (size_t)v[0] + (size_t)k];
        for (int j = 1; j < 4; j++) {
            double x = m->xyz[3 * (size_t)v[j] + (size_t)k];
            if (x < lo[k])
                lo[k] = x;
            if (x > hi[k])
                hi[k] = x;
        }
    }
}

static st_status build_bins(bins *b, const st_tetmesh *m, st_error *err)
{
    memset(b, 0, sizeof *b);
    size_t nt = m->ntets;
    for (size_t t = 0; t < nt; t++) {
        double lo[3], hi[3];
        tet_box(m, t, lo, hi);
        for (int k = 0; k < 3; k++) {
            if (t == 0 || lo[k] < b->lo[k])
                b->lo[k] = lo[k];
            if (t == 0 || hi[k] > b->hi[k])
                b->hi[k] = hi[k];
        }
    }
    double ext[3], vol = 1.0, emax = 0.0;
    int nflat = 0;
    for (int k = 0; k < 3; k++) {
        ext[k] = b->hi[k] - b->lo[k];
        if (ext[k] > emax)
            emax = ext[k];
    }
    for (int k = 0; k < 3; k++) {
        if (ext[k] > 0.0)
            vol *= ext[k];
        else
            nflat++;
    }
    double want = nt ? (double)nt : 1.0;
    /* Edge of a cubic bin giving about `want` bins over the box's
     * non-flat axes. */
    double cell = emax > 0.0 ? pow(vol / want, 1.0 / (3 - nflat > 0
                                                          ? 3 - nflat
                                                          : 1))
                             : 1.0;
    size_t nbins = 1;
    for (int k = 0; k < 3; k++) {
        double d = ext[k] > 0.0 && cell > 0.0 ? ceil(ext[k] / cell) : 1.0;
        if (!(d >= 1.0))
            d = 1.0;
        if (d > MAX_DIM)
            d = MAX_DIM;
        b->dim[k] = (size_t)d;
        b->inv[k] = ext[k] > 0.0 ? (double)b->dim[k] / ext[k] : 0.0;
        nbins *= b->dim[k];
    }
    b->start = st_calloc_array(nbins + 1, sizeof *b->start);
    b->flat = st_malloc_array(nt, 1);
    if (!b->start || !b->flat) {
        free_bins(b);
        return st_error_set(err, ST_ENOMEM, NULL, 0,
                            "out of memory for the embedding bins");
    }
    size_t total = 0;
    for (int pass = 0; pass < 2; pass++) {
        for (size_t t = 0; t < nt; t++) {
            double lo[3], hi[3];
            tet_box(m, t, lo, hi);
            size_t c0[3], c1[3];
            for (int k = 0; k < 3; k++) {
                c0[k] = cell_of(b, k, lo[k]);
                c1[k] = cell_of(b, k, hi[k]);
            }
            for (size_t z = c0[2]; z <= c1[2]; z++)
                for (size_t y = c0[1]; y <= c1[1]; y++)
                    for (size_t x = c0[0]; x <= c1[0]; x++) {
                        size_t c = (z * b->dim[1] + y) * b->dim[0] + x;
                        if (pass == 0)
                            b->start[c + 1]++;
                        else
                            b->items[b->start[c]++] = (uint32_t)t;
                    }
        }
        if (pass == 0) {
            for (size_t c = 0; c < nbins; c++)
                if (st_size_add(&b->start[c + 1], b->start[c + 1],
                                b->start[c]) != 0) {
                    free_bins(b);
                    return st_error_set(err, ST_ENOMEM, NULL, 0,
                                        "too many embedding bin entries");
                }
            total = b->start[nbins];
            b->items = st_malloc_array(total, sizeof *b->items);
            if (!b->items) {
                free_bins(b);
                return st_error_set(err, ST_ENOMEM, NULL, 0,
                                    "out of memory for the embedding bins "
                                    "(%zu entries)", total);
            }
            /* The fill pass advances start[c] to start[c + 1]. */
        }
    }
    /* After the fill, start[c] is the old start[c + 1]: shift back. */
    memmove(b->start + 1, b->start, nbins * sizeof *b->start);
    b->start[0] = 0;
    const double *P = m->xyz;
    long long snt = (long long)nt;
#pragma omp parallel for schedule(static)
    for (long long t = 0; t < snt; t++) {
        const uint32_t *v = m->tets + 4 * (size_t)t;
        b->flat[t] = st_orient3d(P + 3 * (size_t)v[0], P + 3 * (size_t)v[1],
                                 P + 3 * (size_t)v[2],
                                 P + 3 * (size_t)v[3]) == 0.0;
    }
    return ST_OK;
}

/* det[b - a, c - a, d - a] in double. */
static double vol6(const double a[3], const double b[3], const double c[3],
                   const double d[3])
{
    double u[3], v[3], w[3];
    for (int k = 0; k < 3; k++) {
        u[k] = b[k] - a[k];
        v[k] = c[k] - a[k];
        w[k] = d[k] - a[k];
    }
    return u[0] * (v[1] * w[2] - v[2] * w[1]) -
           u[1] * (v[0] * w[2] - v[2] * w[0]) +
           u[2] * (v[0] * w[1] - v[1] * w[0]);
}

/* Barycentric coordinates of p in the non-flat tet q[0..3] that holds it. */
static void barycentric(double out[4], const double p[3],
                        const double *const q[4])
{
    const double *c[4];
    /* The orientation of the tet (exact): sub-tets of a point in the
     * closed tet have this sign or are flat. */
    int s = st_sign(st_orient3d(q[0], q[1], q[2], q[3]));
    double sum = 0.0;
    int nz = 0;
    for (int i = 0; i < 4; i++) {
        for (int j = 0; j < 4; j++)
            c[j] = j == i ? p : q[j];
        if (st_sign(st_orient3d(c[0], c[1], c[2], c[3])) == 0) {
            out[i] = 0.0;
            continue;
        }
        nz++;
        /* st_orient3d has the opposite sign of vol6. */
        double w = -(double)s * vol6(c[0], c[1], c[2], c[3]);
        out[i] = w > 0.0 ? w : 0.0;
        sum += out[i];
    }
    if (sum > 0.0) {
        for (int i = 0; i < 4; i++)
            out[i] /= sum;
        return;
    }
    /* Volumes too small for double (never in practice): share equally
     * among the corners the exact test left. */
    for (int i = 0; i < 4; i++) {
        for (int j = 0; j < 4; j++)
            c[j] = j == i ? p : q[j];
        out[i] = st_orient3d(c[0], c[1], c[2], c[3]) != 0.0 ? 1.0 / nz : 0.0;
    }
}

st_status st_embed_points(int64_t *tet, double *bary, size_t *outside,
                          int64_t *first_outside, const st_tetmesh *m,
                          const double *xyz, size_t n, st_error *err)
{
    if (outside)
        *outside = 0;
    if (first_outside)
        *first_outside = -1;
    for (size_t i = 0; i < 3 * n; i++)
        if (!isfinite(xyz[i]))
            return st_error_set(err, ST_EINPUT, NULL, 0,
                                "surface vertex %zu is not finite", i / 3);
    bins b;
    memset(&b, 0, sizeof b);
    if (m->ntets) {
        st_status s = build_bins(&b, m, err);
        if (s)
            return s;
    }
    const double *P = m->xyz;
    long long sn = (long long)n;
#pragma omp parallel for schedule(dynamic, 256)
    for (long long i = 0; i < sn; i++) {
        const double *p = xyz + 3 * (size_t)i;
        int64_t found = -1;
        int in_box = m->ntets > 0;
        for (int k = 0; k < 3 && in_box; k++)
            in_box = p[k] >= b.lo[k] && p[k] <= b.hi[k];
        if (in_box) {
            size_t c = (cell_of(&b, 2, p[2]) * b.dim[1] +
                        cell_of(&b, 1, p[1])) * b.dim[0] +
                       cell_of(&b, 0, p[0]);
            for (size_t j = b.start[c]; j < b.start[c + 1]; j++) {
                uint32_t t = b.items[j];
                if (b.flat[t])
                    continue;
                const uint32_t *v = m->tets + 4 * (size_t)t;
                const double *q[4] = {P + 3 * (size_t)v[0],
                                      P + 3 * (size_t)v[1],
                                      P + 3 * (size_t)v[2],
                                      P + 3 * (size_t)v[3]};
                if (st_point_in_tet(p, q[0], q[1], q[2], q[3]) !=
                    ST_OUTSIDE) {
                    found = t;
                    barycentric(bary + 4 * (size_t)i, p, q);
                    break;
                }
            }
        }
        tet[i] = found;
        if (found < 0)
            for (int k = 0; k < 4; k++)
                bary[4 * (size_t)i + (size_t)k] = 0.0;
    }
    free_bins(&b);
    size_t nout = 0;
    for (size_t i = 0; i < n; i++)
        if (tet[i] < 0) {
            if (nout == 0 && first_outside)
                *first_outside = (int64_t)i;
            nout++;
        }
    if (outside)
        *outside = nout;
    return ST_OK;
}

st_status st_embed_compute(int64_t *tet, double *bary, size_t *outside,
                           int64_t *first_outside, const st_tetmesh *m,
                           const st_soup *s, st_error *err)
{
    return st_embed_points(tet, bary, outside, first_outside, m, s->xyz,
                           s->nverts, err);
}

st_status st_embed_write_text(const char *path, const int64_t *tet,
                              const double *bary, size_t n,
                              size_t ntets, const char *mesh_name,
                              const char *surface_name, st_error *err)
{
    st_outfile o;
    st_status s = st_outfile_begin(&o, path, 1, err);
    if (s)
        return s;
    FILE *fp = o.fp;
    fprintf(fp, "# souptet embedding: %zu vertices of %s in the %zu tets "
                "of %s\n", n, surface_name ? surface_name : "the surface",
            ntets, mesh_name ? mesh_name : "the mesh");
    fputs("# one line per surface vertex, in the surface's order:\n"
          "# tet b0 b1 b2 b3  (tet numbered from 0 in the mesh's order; -1 "
          "when outside;\n"
          "# x = b0 p[t0] + b1 p[t1] + b2 p[t2] + b3 p[t3])\n", fp);
    for (size_t i = 0; i < n; i++) {
        const double *w = bary + 4 * i;
        if (tet[i] < 0)
            fputs("-1 0 0 0 0\n", fp);
        else
            fprintf(fp, "%lld %.17g %.17g %.17g %.17g\n", (long long)tet[i],
                    w[0], w[1], w[2], w[3]);
    }
    s = st_outfile_commit(&o, err);
    st_outfile_abort(&o);
    return s;
}

st_status st_embed_to_tetmesh(st_tetmesh **out, const double *xyz,
                              const int64_t *tet, const double *bary,
                              size_t n, st_error *err)
{
    *out = NULL;
    st_tetmesh *m = st_tetmesh_new();
    if (!m)
        return st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory");
    st_status s = st_tetmesh_reserve(m, n, 0, err);
    for (size_t i = 0; i < n && !s; i++)
        s = st_tetmesh_add_point(m, xyz + 3 * i, err);
    double *vt = NULL, *vb = NULL;
    if (!s)
        s = st_tetmesh_add_array(m, "embed_tet", ST_ON_POINTS, 1, &vt, err);
    if (!s)
        s = st_tetmesh_add_array(m, "embed_bary", ST_ON_POINTS, 4, &vb, err);
    if (s) {
        st_tetmesh_free(m);
        return s;
    }
    for (size_t i = 0; i < n; i++) {
        vt[i] = (double)tet[i];
        memcpy(vb + 4 * i, bary + 4 * i, 4 * sizeof(double));
    }
    *out = m;
    return ST_OK;
}
