/*
 * pgrid.c - the distinct vertices of a surface in bins (pgrid.h).
 *
 * The points are sorted by position (a stable radix sort by x, then
 * cmp_pt within runs of equal x: the order glibc's qsort gave, which the
 * fit's results depend on through the scan order) and merged, then
 * binned in CSR form.
 */
#include "pgrid.h"
#include "../base/fpenv.h"

#include "souptet/mem.h"

#include "../base/radix.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static int cmp_pt(const void *a, const void *b)
{
    const double *x = a, *y = b;
    for (int k = 0; k < 3; k++)
        if (x[k] != y[k])
            return x[k] < y[k] ? -1 : 1;
    return 0;
}

/* Digit `pass` of the point's x key (st_radix_double_key) */
static uint32_t pt_x_digit(const void *x, int pass, unsigned bits)
{
    const double *p = x;
    (void)bits;
    return (uint32_t)(st_radix_double_key(p[0]) >> (16 * pass)) & 0xffffu;
}

ST_RADIX_SORT_DEFINE(sort_by_x, 3 * sizeof(double), pt_x_digit)

/* The n points at pts in cmp_pt's order, stably (as qsort's merge sort
 * did): a stable radix sort by x, then each run of equal x by cmp_pt
 * (glibc's qsort is a stable merge sort at these sizes). */
static st_status sort_points(double *pts, size_t n)
{
    double *tmp = st_malloc_big((n + 1) * 3 * sizeof *tmp);
    if (!tmp || sort_by_x(pts, tmp, n, 4, 0)) {
        free(tmp);
        return ST_ENOMEM;
    }
    free(tmp);
    for (size_t i = 0, j; i < n; i = j) {
        for (j = i + 1; j < n && pts[3 * j] == pts[3 * i]; j++)
            ;
        if (j - i > 1)
            qsort(pts + 3 * i, j - i, 3 * sizeof(double), cmp_pt);
    }
    return ST_OK;
}

void sm_pgrid_free(pgrid *g)
{
    free(g->pts);
    free(g->off);
    free(g->idx);
    free(g->bpts);
    memset(g, 0, sizeof *g);
}

/* The distinct vertices of s's triangles into g->pts (sorted), g->npts. */
static st_status pgrid_points(pgrid *g, const st_soup *s)
{
    /* the used vertex indices first (a vertex is in ~6 triangles), then
     * the sort by position merges the ones at one position */
    st_status rc = ST_ENOMEM;
    unsigned char *used = st_calloc_array(s->nverts ? s->nverts : 1, 1);
    if (!used)
        goto done;
    size_t n = 0;
    for (size_t i = 0; i < 3 * s->ntris; i++)
        if (!used[s->tris[i]]) {
            used[s->tris[i]] = 1;
            n++;
        }
    g->pts = st_malloc_big((n + 1) * 3 * sizeof *g->pts);
    if (!g->pts)
        goto done;
    for (size_t v = 0, i = 0; v < s->nverts; v++)
        if (used[v])
            memcpy(g->pts + 3 * i++, s->xyz + 3 * v, 3 * sizeof(double));
    if ((rc = sort_points(g->pts, n)))
        goto done;
    size_t k = 0;
    for (size_t i = 0; i < n; i++)
        if (k == 0 || cmp_pt(g->pts + 3 * (k - 1), g->pts + 3 * i) != 0) {
            memmove(g->pts + 3 * k, g->pts + 3 * i, 3 * sizeof(double));
            k++;
        }
    g->npts = k;
done:
    free(used);
    return rc;
}

/* Dense points: bins finer than the caller's cell, down to PGRID_FINEST
 * of it, so that the box holds about PGRID_POINTS_PER_BIN points per bin.
 * The swept test and the star scans read whole bins: on 10 million
 * triangles at --cells 10 a quarter-cell bin held thousands of points
 * (issue 41). Bins only order the scans; no answer depends on them. */
#define PGRID_POINTS_PER_BIN 8.0
#define PGRID_FINEST 8.0

/* The bin width for k points in the box lo..hi given the coarsest, cell. */
static double pgrid_cell(size_t k, const double lo[3], const double hi[3], double cell)
{
    double vol = 1.0;
    for (int a = 0; a < 3; a++)
        vol *= fmax(hi[a] - lo[a], cell / PGRID_FINEST);
    double dense = cbrt(vol * PGRID_POINTS_PER_BIN / (double)(k ? k : 1));
    return dense < cell ? fmax(dense, cell / PGRID_FINEST) : cell;
}

/* The grid's extent and bin counts over g->pts; returns the bin count. */
static size_t pgrid_extent(pgrid *g, double cell)
{
    const size_t k = g->npts;
    double hi[3];
    for (int a = 0; a < 3; a++) {
        g->lo[a] = INFINITY;
        hi[a] = -INFINITY;
    }
    for (size_t i = 0; i < k; i++)
        for (int a = 0; a < 3; a++) {
            g->lo[a] = fmin(g->lo[a], g->pts[3 * i + (size_t)a]);
            hi[a] = fmax(hi[a], g->pts[3 * i + (size_t)a]);
        }
    if (k)
        cell = pgrid_cell(k, g->lo, hi, cell);
    g->cell = cell;
    size_t nb = 1;
    for (int a = 0; a < 3; a++) {
        double ext = k ? hi[a] - g->lo[a] : 0.0;
        double c = floor(ext / cell) + 1.0;
        /* a bin count beyond 256 per axis buys nothing here */
        g->n[a] = c > 256.0 ? 256 : (size_t)c;
        nb *= g->n[a];
    }
    if (k) {
        double ext = 0.0;
        for (int a = 0; a < 3; a++)
            ext = fmax(ext, (hi[a] - g->lo[a]) / (double)g->n[a]);
        g->cell = fmax(cell, ext);
    }
    return nb;
}

st_status sm_pgrid_build(pgrid *g, const st_soup *s, double cell)
{
    memset(g, 0, sizeof *g);
    size_t *bin = NULL, *fill = NULL;
    st_status rc = pgrid_points(g, s);
    if (rc)
        goto done;
    const size_t k = g->npts, nb = pgrid_extent(g, cell);
    rc = ST_ENOMEM;
    g->off = st_calloc_array(nb + 1, sizeof *g->off);
    /* arrays over every point (a vertex count: the products are in
     * range): huge pages past a few MB */
    g->idx = st_malloc_big((k + 1) * sizeof *g->idx);
    g->bpts = st_malloc_big((k + 1) * 3 * sizeof *g->bpts);
    bin = st_malloc_big((k + 1) * sizeof *bin);
    fill = st_malloc_array(nb, sizeof *fill);
    if (!g->off || !g->idx || !g->bpts || !bin || !fill)
        goto done;
    for (size_t i = 0; i < k; i++) {
        const double *p = g->pts + 3 * i;
        size_t ix = sm_pgrid_coord(g, p[0], 0), iy = sm_pgrid_coord(g, p[1], 1),
               iz = sm_pgrid_coord(g, p[2], 2);
        bin[i] = ix + g->n[0] * (iy + g->n[1] * iz);
        g->off[bin[i] + 1]++;
    }
    for (size_t b = 0; b < nb; b++)
        g->off[b + 1] += g->off[b];
    memcpy(fill, g->off, nb * sizeof *fill);
    for (size_t i = 0; i < k; i++)
        g->idx[fill[bin[i]]++] = (uint32_t)i;
    for (size_t j = 0; j < k; j++)
        memcpy(g->bpts + 3 * j, g->pts + 3 * (size_t)g->idx[j], 3 * sizeof *g->bpts);
    rc = ST_OK;
done:
    free(bin);
    free(fill);
    return rc;
}
