/*
 * tetstat.c - the metrics of a tet mesh, alone and against a surface or a
 * signed field (see tetstat.h).
 *
 * Decisions are exact: orientation of each tet (inverted / degenerate),
 * whether a voxel center lies in a tet, enclosure (enclose.h). Measured
 * values (angles, distances, volumes) are in double. Parallel loops write
 * per-item results or integer counts only, and every floating-point sum is
 * taken serially in item order, so the report does not depend on the
 * thread count.
 */
#include "souptet/tetstat.h"
#include "../base/unionfind.h"
#include "../base/fpenv.h"
#include "souptet/bvh.h"
#include "souptet/enclose.h"
#include "souptet/geom.h"
#include "souptet/mem.h"
#include "souptet/pred.h"
#include "souptet/pseudo.h"
#include "souptet/soupinfo.h"
#include "souptet/tetqual.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* ---- the mesh alone ------------------------------------------------------ */

/* ---- contacts and the boundary's manifoldness ---------------------------- */

/* Ascending CSR of the tets around each point (tets listed in index order,
 * so each list is sorted). */
static st_status point_stars(const st_tetmesh *m, size_t **off_out,
                             uint32_t **star_out, st_error *err)
{
    size_t np = m->npoints, nt = m->ntets;
    size_t *off = st_calloc_array(np + 1, sizeof *off);
    uint32_t *star = st_malloc_array(4 * nt + 1, sizeof *star);
    size_t *fill = st_malloc_array(np + 1, sizeof *fill);
    if (!off || !star || !fill) {
        free(off); free(star); free(fill);
        return st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory");
    }
    for (size_t i = 0; i < 4 * nt; i++)
        off[m->tets[i] + 1]++;
    for (size_t v = 0; v < np; v++)
        off[v + 1] += off[v];
    memcpy(fill, off, (np + 1) * sizeof *fill);
    for (size_t t = 0; t < nt; t++)
        for (int c = 0; c < 4; c++)
            star[fill[m->tets[4 * t + (size_t)c]]++] = (uint32_t)t;
    free(fill);
    *off_out = off;
    *star_out = star;
    return ST_OK;
}

static size_t find_sorted(const uint32_t *a, size_t n, uint32_t x)
{
    size_t lo = 0, hi = n;
    while (lo < hi) {
        size_t mid = lo + (hi - lo) / 2;
        if (a[mid] < x)
            lo = mid + 1;
        else
            hi = mid;
    }
    return lo;
}

/* Groups, through the faces holding both a and b (b == UINT32_MAX: the
 * faces holding a), of the tets sel[0..k) (ascending, each holding a and
 * b). par is scratch of k slots. */
static size_t face_groups(const st_tetmesh *m, const int64_t *nbr,
                          const uint32_t *sel, size_t k, uint32_t a,
                          uint32_t b, size_t *par)
{
    for (size_t q = 0; q < k; q++)
        par[q] = q;
    for (size_t q = 0; q < k; q++) {
        size_t t = sel[q];
        for (int i = 0; i < 4; i++) {
            uint32_t opp = m->tets[4 * t + (size_t)i];
            if (opp == a || opp == b)
                continue;   /* that face misses a or b */
            int64_t u = nbr[4 * t + (size_t)i];
            if (u < 0)
                continue;
            size_t r = find_sorted(sel, k, (uint32_t)u);
            if (r == k || sel[r] != (uint32_t)u)
                continue;
            size_t x = uf_find(par, q), y = uf_find(par, r);
            if (x != y)
                par[x > y ? x : y] = x > y ? y : x;
        }
    }
    size_t n = 0;
    for (size_t q = 0; q < k; q++)
        n += uf_find(par, q) == q;
    return n;
}

/* Pinched points and edges (tets around them in more than one group
 * through faces), and the boundary faces' non-manifold edges (in other
 * than two boundary faces) and points (whose boundary faces do not make
 * one closed fan). */
static st_status contacts(st_tetstat *out, const st_tetmesh *m,
                          const int64_t *nbr, const uint32_t *bf, size_t nbf,
                          st_error *err)
{
    size_t *off = NULL;
    uint32_t *star = NULL;
    st_status s = point_stars(m, &off, &star, err);
    if (s)
        return s;
    const size_t np = m->npoints;
    size_t maxk = 0;
    for (size_t v = 0; v < np; v++)
        if (off[v + 1] - off[v] > maxk)
            maxk = off[v + 1] - off[v];
    /* Boundary faces around each point, as the pairs of their other
     * corners. */
    size_t *boff = st_calloc_array(np + 1, sizeof *boff);
    if (!boff) {
        free(off); free(star);
        return st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory");
    }
    for (size_t f = 0; f < nbf; f++)
        for (int c = 0; c < 3; c++)
            boff[bf[3 * f + (size_t)c] + 1]++;
    /* Scratch: the star's tets, or the link points (two per face). */
    for (size_t v = 0; v < np; v++)
        if (2 * boff[v + 1] > maxk)
            maxk = 2 * boff[v + 1];
    size_t *bfill = st_malloc_array(np + 1, sizeof *bfill);
    uint32_t *link = st_malloc_array(3 * nbf + 1, 2 * sizeof *link);
    size_t *par = st_malloc_array(maxk + 1, 2 * sizeof *par);
    uint32_t *sel = st_malloc_array(maxk + 1, 2 * sizeof *sel);
    if (!bfill || !link || !par || !sel) {
        free(off); free(star); free(boff); free(bfill); free(link);
        free(par); free(sel);
        return st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory");
    }
    for (size_t v = 0; v < np; v++)
        boff[v + 1] += boff[v];
    memcpy(bfill, boff, (np + 1) * sizeof *bfill);
    for (size_t f = 0; f < nbf; f++)
        for (int c = 0; c < 3; c++) {
            size_t q = bfill[bf[3 * f + (size_t)c]]++;
            link[2 * q] = bf[3 * f + (size_t)(c + 1) % 3];
            link[2 * q + 1] = bf[3 * f + (size_t)(c + 2) % 3];
        }
    free(bfill);
    uint32_t *lv = sel + maxk + 1;   /* link points (second half) */
    for (size_t v = 0; v < np; v++) {
        const uint32_t *st = star + off[v];
        size_t k = off[v + 1] - off[v];
        if (k == 0)
            continue;
        if (face_groups(m, nbr, st, k, (uint32_t)v, UINT32_MAX, par) > 1)
            out->pinched_points++;
        /* Edges (v, w), w > v: the tets of v's star holding w. */
        for (size_t a = 0; a < k; a++)
            for (int c = 0; c < 4; c++) {
                uint32_t w = m->tets[4 * (size_t)st[a] + (size_t)c];
                if (w <= v)
                    continue;
                /* Count each edge once: at the first tet holding it. */
                int first = 1;
                for (size_t b = 0; b < a && first; b++)
                    for (int d = 0; d < 4; d++)
                        if (m->tets[4 * (size_t)st[b] + (size_t)d] == w)
                            first = 0;
                if (!first)
                    continue;
                size_t ks = 0;
                for (size_t b = a; b < k; b++)
                    for (int d = 0; d < 4; d++)
                        if (m->tets[4 * (size_t)st[b] + (size_t)d] == w)
                            sel[ks++] = st[b];
                if (face_groups(m, nbr, sel, ks, (uint32_t)v, w, par) > 1)
                    out->pinched_edges++;
            }
        /* The boundary fan of v: every link point of degree 2 and the
         * link connected. */
        size_t b0 = boff[v], nb = boff[v + 1] - b0;
        if (nb == 0)
            continue;
        size_t nl = 0;
        size_t *deg = par + maxk + 1;
        int bad = 0;
        {
            for (size_t q = 0; q < 2 * nb; q++) {
                uint32_t w = link[2 * b0 + q];
                size_t r = 0;
                while (r < nl && lv[r] != w)
                    r++;
                if (r == nl) {
                    lv[nl] = w;
                    deg[nl] = 0;
                    par[nl] = nl;
                    nl++;
                }
                deg[r]++;
            }
            for (size_t q = 0; q < nb; q++) {
                size_t x = 0, y = 0;
                while (lv[x] != link[2 * (b0 + q)])
                    x++;
                while (lv[y] != link[2 * (b0 + q) + 1])
                    y++;
                x = uf_find(par, x);
                y = uf_find(par, y);
                if (x != y)
                    par[x > y ? x : y] = x > y ? y : x;
            }
            for (size_t r = 0; r < nl; r++) {
                if (deg[r] != 2) {
                    bad = 1;
                    if (v < lv[r])
                        out->nonmanifold_boundary_edges++;
                }
                if (uf_find(par, r) != 0)
                    bad = 1;
            }
        }
        out->nonmanifold_boundary_points += bad;
    }
    free(off); free(star); free(boff); free(link); free(par); free(sel);
    return ST_OK;
}

static void reset(st_tetstat *out)
{
    memset(out, 0, sizeof *out);
    out->min_dihedral = out->max_dihedral = NAN;
    out->h = NAN;
    out->dist_min = out->dist_max = out->dist_mean = NAN;
    out->surface_dist_max = NAN;
    out->surface_diag = NAN;
    out->offset_ratio = NAN;
    out->surface_volume = out->volume_ratio = NAN;
    out->fraction_inside = NAN;
    out->iou = NAN;
}

st_status st_tetstat_mesh(st_tetstat *out, const st_tetmesh *m,
                          st_error *err)
{
    reset(out);
    out->tets = m->ntets;
    out->points = m->npoints;
    const size_t nt = m->ntets;

    /* Quality and orientation per tet. */
    double *qmin = st_malloc_array(nt, sizeof(double));
    double *qmax = st_malloc_array(nt, sizeof(double));
    double *vol = st_malloc_array(nt, sizeof(double));
    unsigned char *used = st_calloc_array(m->npoints, 1);
    if (!qmin || !qmax || !vol || !used) {
        free(qmin);
        free(qmax);
        free(vol);
        free(used);
        return st_error_set(err, ST_ENOMEM, NULL, 0,
                            "out of memory for the quality of %zu tets", nt);
    }
    st_tetmesh_quality(m, qmin, qmax, vol);
    size_t inverted = 0, degenerate = 0;
    const long long n = (long long)nt;
#pragma omp parallel for schedule(static) reduction(+ : inverted, degenerate)
    for (long long t = 0; t < n; t++) {
        const uint32_t *q = m->tets + 4 * (size_t)t;
        /* Positive orientation (tetmesh.h) is st_orient3d < 0. */
        double o = st_orient3d(m->xyz + 3 * (size_t)q[0],
                               m->xyz + 3 * (size_t)q[1],
                               m->xyz + 3 * (size_t)q[2],
                               m->xyz + 3 * (size_t)q[3]);
        inverted += o > 0;
        degenerate += o == 0;
    }
    out->inverted = inverted;
    out->degenerate = degenerate;
    double vsum = 0;
    for (size_t t = 0; t < nt; t++) {
        if (t == 0 || qmin[t] < out->min_dihedral)
            out->min_dihedral = qmin[t];
        if (t == 0 || qmax[t] > out->max_dihedral)
            out->max_dihedral = qmax[t];
        int b = (int)floor(qmin[t] / ST_TETSTAT_BIN_DEG);
        if (b < 0)
            b = 0;
        if (b >= ST_TETSTAT_BINS)
            b = ST_TETSTAT_BINS - 1;
        out->hist[b]++;
        vsum += vol[t];
    }
    out->volume = vsum;
    free(qmin);
    free(qmax);
    free(vol);

    /* Used points and their bounds. */
    for (size_t i = 0; i < 4 * nt; i++)
        used[m->tets[i]] = 1;
    int first = 1;
    for (size_t i = 0; i < m->npoints; i++) {
        if (!used[i]) {
            out->unused_points++;
            continue;
        }
        const double *p = m->xyz + 3 * i;
        for (int k = 0; k < 3; k++) {
            if (first || p[k] < out->lo[k])
                out->lo[k] = p[k];
            if (first || p[k] > out->hi[k])
                out->hi[k] = p[k];
        }
        first = 0;
    }
    free(used);

    /* Faces and components. */
    int64_t *nbr;
    size_t nm;
    st_status s = st_tetmesh_neighbors(m, &nbr, &nm, err);
    if (s)
        return s;
    size_t *parent = st_malloc_array(nt, sizeof(size_t));
    if (!parent) {
        free(nbr);
        return st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory");
    }
    for (size_t t = 0; t < nt; t++)
        parent[t] = t;
    size_t shared = 0;
    for (size_t t = 0; t < nt; t++)
        for (int i = 0; i < 4; i++) {
            int64_t u = nbr[4 * t + (size_t)i];
            if (u < 0)
                continue;
            shared++;
            size_t a = uf_find(parent, t), b = uf_find(parent, (size_t)u);
            if (a != b)
                parent[a > b ? a : b] = a > b ? b : a;
        }
    for (size_t t = 0; t < nt; t++)
        out->components += uf_find(parent, t) == t;
    free(parent);
    out->nonmanifold_faces = nm;
    out->interior_faces = shared / 2;
    /* Not the faces without a neighbour: the sides of non-manifold faces
     * have none either. */
    uint32_t *bf;
    size_t nbf;
    if ((s = st_tetmesh_boundary(m, &bf, NULL, &nbf, err))) {
        free(nbr);
        return s;
    }
    s = contacts(out, m, nbr, bf, nbf, err);
    free(bf);
    free(nbr);
    if (s)
        return s;
    out->boundary_manifold = out->nonmanifold_boundary_edges == 0 &&
                             out->nonmanifold_boundary_points == 0;
    out->boundary_faces = nbf;
    out->conforming = nm == 0;

    const char *h = st_meta_get(&m->meta, "h");
    if (h) {
        char *end;
        double v = strtod(h, &end);
        if (end != h && *end == '\0' && isfinite(v)) {
            out->has_h = 1;
            out->h = v;
        }
    }
    const char *r = st_meta_get(&m->meta, "offset_ratio");
    if (r) {
        char *end;
        double v = strtod(r, &end);
        if (end != r && *end == '\0' && isfinite(v) && v > 0.0)
            out->offset_ratio = v;
    }
    return ST_OK;
}

/* ---- against a surface --------------------------------------------------- */

/* The boundary of m as a soup over all of m's points. */
static st_status boundary_soup(st_soup **out, const st_tetmesh *m,
                               uint32_t **faces, size_t *nfaces,
                               st_error *err)
{
    *out = NULL;
    st_status s = st_tetmesh_boundary(m, faces, NULL, nfaces, err);
    if (s)
        return s;
    st_soup *b = st_soup_new();
    if (!b) {
        free(*faces);
        *faces = NULL;
        return st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory");
    }
    for (size_t i = 0; i < m->npoints && !s; i++)
        s = st_soup_add_vertex(b, m->xyz[3 * i], m->xyz[3 * i + 1],
                               m->xyz[3 * i + 2], err);
    for (size_t f = 0; f < *nfaces && !s; f++)
        s = st_soup_add_triangle(b, (*faces)[3 * f], (*faces)[3 * f + 1],
                                 (*faces)[3 * f + 2], err);
    if (s) {
        st_soup_free(b);
        free(*faces);
        *faces = NULL;
        return s;
    }
    *out = b;
    return ST_OK;
}

/* Signed volume of a soup by the divergence theorem (sum of the tets from
 * the origin to each triangle, taken relative to the first vertex so a
 * model far from the origin keeps its digits). */
static double soup_volume(const st_soup *s)
{
    const double *o = s->xyz + 3 * (size_t)s->tris[0];
    double v = 0;
    for (size_t t = 0; t < s->ntris; t++) {
        const uint32_t *q = s->tris + 3 * t;
        v += st_tet_volume(o, s->xyz + 3 * (size_t)q[0],
                           s->xyz + 3 * (size_t)q[1],
                           s->xyz + 3 * (size_t)q[2]);
    }
    return v;
}

/* Relative slack on the triangle-inequality bounds below: it covers the
 * rounding of a sum of two distances and a norm (a few ulps), so that a
 * bound never falls below the true distance it bounds. */
#define BOUND_SLACK 1e-12

/* Max over the samples of S (every triangle's corners, centroid and the
 * points halfway from the centroid to the corners) of the distance to the
 * nearest face in bb. Only the max is wanted, so a sample is skipped when
 * the triangle inequality, d(p) <= d(q) + |p - q| for the previous sample
 * q of the same thread, already puts it below the largest distance found
 * so far; otherwise that bound limits the BVH search. Skipped samples are
 * at most the running max, which is at most the final max, so the result
 * is the exact max over all samples whatever the thread schedule. */
static double surface_to_boundary(const st_bvh *bb, const st_soup *s)
{
    double worst = 0;
    const long long ntr = (long long)s->ntris;
#pragma omp parallel reduction(max : worst)
    {
        double q[3] = {0, 0, 0}, dq = INFINITY;   /* dq >= d(q) */
#pragma omp for schedule(static)
        for (long long t = 0; t < ntr; t++) {
            const uint32_t *v = s->tris + 3 * (size_t)t;
            const double *c[3] = {s->xyz + 3 * (size_t)v[0],
                                  s->xyz + 3 * (size_t)v[1],
                                  s->xyz + 3 * (size_t)v[2]};
            double g[3];
            for (int k = 0; k < 3; k++)
                g[k] = (c[0][k] + c[1][k] + c[2][k]) / 3.0;
            for (int j = 0; j < 3 + ST_TETSTAT_TRI_SAMPLES; j++) {
                double p[3];
                for (int k = 0; k < 3; k++)
                    p[k] = j < 3 ? c[j][k]
                           : j == 3 ? g[k]
                                    : 0.5 * (g[k] + c[j - 4][k]);
                double e[3];
                st_sub3(e, p, q);
                double ub = (dq + st_norm3(e)) * (1 + BOUND_SLACK);
                double d;
                if (ub <= worst) {
                    d = ub;
                } else {
                    int64_t tri;
                    double d2 = st_bvh_nearest(bb, p, isfinite(ub) ? ub * ub
                                                                   : INFINITY,
                                               &tri, NULL);
                    if (tri < 0)
                        d2 = st_bvh_nearest(bb, p, INFINITY, &tri, NULL);
                    d = sqrt(d2);
                    if (d > worst)
                        worst = d;
                }
                memcpy(q, p, sizeof q);
                dq = d;
            }
        }
    }
    return worst;
}

st_status st_tetstat_surface(st_tetstat *out, const st_tetmesh *m,
                             const st_soup *s, st_error *err)
{
    out->has_surface = 1;
    out->surface_triangles = s->ntris;
    out->surface_vertices = out->boundary_vertices = 0;
    out->dist_min = out->dist_max = out->dist_mean = NAN;
    out->surface_dist_max = NAN;
    out->surface_diag = NAN;
    out->has_offset = 0;
    out->beyond_offset = 0;
    out->surface_closed = 0;
    out->surface_volume = out->volume_ratio = NAN;
    out->has_enclosure = out->encloses = out->enclosure_verified = 0;
    out->vertices_inside = out->crossing_triangles = 0;
    out->fraction_inside = NAN;
    st_status st;
    uint32_t *faces = NULL;
    size_t nf = 0;
    st_soup *bs = NULL;
    st_bvh *sb = NULL, *bb = NULL;
    unsigned char *mark = NULL;
    double *d = NULL;
    uint32_t *list = NULL;

    if ((st = boundary_soup(&bs, m, &faces, &nf, err)))
        goto done;
    if ((st = st_bvh_build(&sb, s, err)))
        goto done;

    /* Boundary vertices -> S. */
    mark = st_calloc_array(m->npoints > s->nverts ? m->npoints : s->nverts,
                           1);
    if (!mark) {
        st = st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory");
        goto done;
    }
    for (size_t i = 0; i < 3 * nf; i++)
        mark[faces[i]] = 1;
    size_t nbv = 0;
    for (size_t i = 0; i < m->npoints; i++)
        nbv += mark[i];
    list = st_malloc_array(nbv, sizeof(uint32_t));
    d = st_malloc_array(nbv, sizeof(double));
    if (!list || !d) {
        st = st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory");
        goto done;
    }
    nbv = 0;
    for (size_t i = 0; i < m->npoints; i++)
        if (mark[i])
            list[nbv++] = (uint32_t)i;
    out->boundary_vertices = nbv;
    {
        const long long n = (long long)nbv;
#pragma omp parallel for schedule(dynamic, 64)
        for (long long i = 0; i < n; i++) {
            int64_t tri;
            d[i] = sqrt(st_bvh_nearest(sb, m->xyz + 3 * (size_t)list[i],
                                       INFINITY, &tri, NULL));
        }
    }
    if (nbv) {
        double sum = 0;
        out->dist_min = out->dist_max = d[0];
        for (size_t i = 0; i < nbv; i++) {
            out->dist_min = fmin(out->dist_min, d[i]);
            out->dist_max = fmax(out->dist_max, d[i]);
            sum += d[i];
        }
        out->dist_mean = sum / (double)nbv;
    }
    if (out->has_h && out->h > 0.0 && out->offset_ratio > 0.0) {
        const double lim = out->offset_ratio * out->h;
        out->has_offset = 1;
        for (size_t i = 0; i < nbv; i++)
            out->beyond_offset += d[i] > lim;
    }

    /* S -> boundary (its referenced vertices are counted here). */
    memset(mark, 0, s->nverts);
    for (size_t i = 0; i < 3 * s->ntris; i++)
        mark[s->tris[i]] = 1;
    size_t nsv = 0;
    for (size_t i = 0; i < s->nverts; i++)
        nsv += mark[i];
    out->surface_vertices = nsv;
    {
        double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
        for (size_t i = 0; i < s->nverts; i++)
            if (mark[i])
                for (int a = 0; a < 3; a++) {
                    lo[a] = fmin(lo[a], s->xyz[3 * i + (size_t)a]);
                    hi[a] = fmax(hi[a], s->xyz[3 * i + (size_t)a]);
                }
        if (nsv)
            out->surface_diag = sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) +
                                     (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                                     (hi[2] - lo[2]) * (hi[2] - lo[2]));
    }
    if (nf) {
        if ((st = st_bvh_build(&bb, bs, err)))
            goto done;
        out->surface_dist_max = surface_to_boundary(bb, s);
    }

    /* Enclosure (enclose.h), over the same BVH of S. */
    {
        st_enclosure enc;
        if ((st = st_enclosure_compute(&enc, m, s, sb, NULL, NULL, err)))
            goto done;
        out->has_enclosure = 1;
        out->vertices_inside = enc.vertices_inside;
        out->fraction_inside = enc.fraction_inside;
        out->crossing_triangles = enc.crossing_triangles;
        /* The counts prove enclosure only for a conforming mesh of
         * positively oriented tets (enclose.h). */
        out->enclosure_verified = out->inverted == 0 && out->degenerate == 0 &&
                                  out->nonmanifold_faces == 0;
        out->encloses = enc.encloses && out->enclosure_verified;
    }

    /* Volume of S, when it has one. */
    {
        st_soupinfo info;
        if ((st = st_soupinfo_compute(&info, s, err)))
            goto done;
        out->surface_closed = info.closed && info.consistently_oriented &&
                              info.nonorientable_pieces == 0;
        if (out->surface_closed) {
            out->surface_volume = fabs(soup_volume(s));
            if (out->surface_volume > 0)
                out->volume_ratio = out->volume / out->surface_volume;
        }
    }
    st = ST_OK;
done:
    st_bvh_free(sb);
    st_bvh_free(bb);
    st_soup_free(bs);
    free(faces);
    free(mark);
    free(list);
    free(d);
    return st;
}

st_status st_tetstat_surface_to_boundary(double *out, const st_tetmesh *m,
                                         const st_soup *s, st_error *err)
{
    *out = NAN;
    uint32_t *faces = NULL;
    size_t nf = 0;
    st_soup *bs = NULL;
    st_bvh *bb = NULL;
    st_status st = boundary_soup(&bs, m, &faces, &nf, err);
    if (!st && nf && !(st = st_bvh_build(&bb, bs, err)))
        *out = surface_to_boundary(bb, s);
    st_bvh_free(bb);
    st_soup_free(bs);
    free(faces);
    return st;
}

/* ---- against a surface and a field's fill ------------------------------- */

st_status st_tetstat_fill(st_tetstat *out, const st_tetmesh *m,
                          const st_soup *s, const st_grid *f, st_error *err)
{
    out->has_fill = 0;
    out->fill_faces = 0;
    out->fill_dist_max = NAN;
    out->beyond_offset_fill = 0;
    uint32_t *faces = NULL;
    size_t nf = 0;
    st_soup *bs = NULL, *fill = NULL;
    st_bvh *sb = NULL, *fb = NULL;
    unsigned char *mark = NULL;
    st_status st = boundary_soup(&bs, m, &faces, &nf, err);
    if (st || (st = st_bvh_build(&sb, s, err)) ||
        (st = st_pseudo_fill(&fill, f, sb, &out->fill_faces, err)))
        goto done;
    if (fill->ntris && (st = st_bvh_build(&fb, fill, err)))
        goto done;
    if (!(mark = st_calloc_array(m->npoints ? m->npoints : 1, 1))) {
        st = st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory");
        goto done;
    }
    for (size_t i = 0; i < 3 * nf; i++)
        mark[faces[i]] = 1;
    const double lim = out->has_offset ? out->offset_ratio * out->h : INFINITY;
    double mx = 0.0;
    size_t beyond = 0;
    const long long n = (long long)m->npoints;
#pragma omp parallel for schedule(dynamic, 64) reduction(max : mx) reduction(+ : beyond)
    for (long long i = 0; i < n; i++) {
        if (!mark[i])
            continue;
        const double *p = m->xyz + 3 * (size_t)i;
        int64_t tri;
        double d2 = st_bvh_nearest(sb, p, INFINITY, &tri, NULL);
        if (fb)
            d2 = st_bvh_nearest(fb, p, d2, &tri, NULL);
        double d = sqrt(d2);
        mx = fmax(mx, d);
        beyond += d > lim;
    }
    out->has_fill = 1;
    out->fill_dist_max = nf ? mx : NAN;
    out->beyond_offset_fill = beyond;
done:
    st_bvh_free(sb);
    st_bvh_free(fb);
    st_soup_free(bs);
    st_soup_free(fill);
    free(faces);
    free(mark);
    return st;
}

/* ---- against a signed field ---------------------------------------------- */

/* p in the closed tet (a b c d) of exact orientation o (nonzero): every
 * orient3d with p in place of one corner has o's sign or is 0. */
static int in_tet(const double *p, const double *a, const double *b,
                  const double *c, const double *d, int o)
{
    int s;
    s = st_sign(st_orient3d(p, b, c, d));
    if (s && s != o)
        return 0;
    s = st_sign(st_orient3d(a, p, c, d));
    if (s && s != o)
        return 0;
    s = st_sign(st_orient3d(a, b, p, d));
    if (s && s != o)
        return 0;
    s = st_sign(st_orient3d(a, b, c, p));
    return !(s && s != o);
}

/* First and last voxel index along an axis whose centers lie in [lo, hi]
 * (a conservative range: the exact test decides). Returns 0 when empty. */
static int index_range(double lo, double hi, double origin, double voxel,
                       size_t n, size_t *i0, size_t *i1)
{
    double a = floor((lo - origin) / voxel), b = ceil((hi - origin) / voxel);
    if (!(b >= 0) || !(a <= (double)(n - 1)))
        return 0;
    *i0 = a < 0 ? 0 : (size_t)a;
    *i1 = b > (double)(n - 1) ? n - 1 : (size_t)b;
    return *i0 <= *i1;
}

st_status st_tetstat_field(st_tetstat *out, const st_tetmesh *m,
                           const st_grid *f, st_error *err)
{
    out->has_field = 1;
    const size_t nvox = st_grid_count(f);
    unsigned char *in = st_calloc_big(nvox);
    if (!in)
        return st_error_set(err, ST_ENOMEM, NULL, 0,
                            "out of memory for a mask of %zu voxels", nvox);
    const long long nt = (long long)m->ntets;
#pragma omp parallel for schedule(dynamic, 16)
    for (long long t = 0; t < nt; t++) {
        const uint32_t *q = m->tets + 4 * (size_t)t;
        const double *v[4];
        double lo[3], hi[3];
        for (int k = 0; k < 4; k++)
            v[k] = m->xyz + 3 * (size_t)q[k];
        int o = st_sign(st_orient3d(v[0], v[1], v[2], v[3]));
        if (o == 0)
            continue;   /* a flat tet holds no voxel of its own */
        for (int a = 0; a < 3; a++) {
            lo[a] = hi[a] = v[0][a];
            for (int k = 1; k < 4; k++) {
                lo[a] = fmin(lo[a], v[k][a]);
                hi[a] = fmax(hi[a], v[k][a]);
            }
        }
        size_t r0[3], r1[3];
        if (!index_range(lo[0], hi[0], f->origin[0], f->voxel, f->nx, &r0[0],
                         &r1[0]) ||
            !index_range(lo[1], hi[1], f->origin[1], f->voxel, f->ny, &r0[1],
                         &r1[1]) ||
            !index_range(lo[2], hi[2], f->origin[2], f->voxel, f->nz, &r0[2],
                         &r1[2]))
            continue;
        for (size_t k = r0[2]; k <= r1[2]; k++)
            for (size_t j = r0[1]; j <= r1[1]; j++)
                for (size_t i = r0[0]; i <= r1[0]; i++) {
                    size_t idx = st_grid_index(f, i, j, k);
                    unsigned char seen;
#pragma omp atomic read
                    seen = in[idx];
                    if (seen)
                        continue;
                    double p[3];
                    st_grid_center(f, i, j, k, p);
                    if (in_tet(p, v[0], v[1], v[2], v[3], o)) {
#pragma omp atomic write
                        in[idx] = 1;
                    }
                }
    }
    size_t fin = 0, min_ = 0, both = 0;
    const long long nv = (long long)nvox;
#pragma omp parallel for schedule(static) reduction(+ : fin, min_, both)
    for (long long i = 0; i < nv; i++) {
        int a = f->data[i] < 0, b = in[i] != 0;
        fin += (size_t)a;
        min_ += (size_t)b;
        both += (size_t)(a && b);
    }
    free(in);
    out->field_voxels = nvox;
    out->field_inside = fin;
    out->mesh_voxels = min_;
    out->both_voxels = both;
    size_t uni = fin + min_ - both;
    out->iou = uni ? (double)both / (double)uni : 1.0;
    return ST_OK;
}
