/* solid.c - exact ray parity and winding numbers at voxel centers (see
 * solid.h). */
#include "souptet/solid.h"
#include "../base/fpenv.h"

#include "souptet/mem.h"
#include "souptet/pred.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#ifdef _OPENMP
#include <omp.h>
#endif

/* Sign of orient2d(a, b, q') in the (y, z) plane for the perturbed query
 * q' = q + (e, e^2): the exact sign when it is not zero, else the sign of
 * the first nonzero coefficient of the perturbation. orient2d(a, b, q) =
 * (ay - qy)(bz - qz) - (az - qz)(by - qy), whose derivative in qy is
 * az - bz and in qz is by - ay. Zero only when a and b coincide in (y, z). */
static int orient_yz(const double a[3], const double b[3], const double q[2])
{
    const double a2[2] = {a[1], a[2]}, b2[2] = {b[1], b[2]};
    int s = st_sign(st_orient2d(a2, b2, q));
    if (s)
        return s;
    if (a[2] != b[2])
        return a[2] > b[2] ? 1 : -1;
    if (a[1] != b[1])
        return b[1] > a[1] ? 1 : -1;
    return 0;
}

/* Does the perturbed line {(t, y + e, z + e^2)} pass through the triangle?
 * All three edge signs equal and nonzero. A triangle whose (y, z)
 * projection is degenerate never passes: its three signed areas sum to
 * zero, and collinear edge directions cannot all give the same sign. */
static int line_hits(const double *v[3], const double q[2])
{
    int s0 = orient_yz(v[0], v[1], q);
    if (!s0)
        return 0;
    return orient_yz(v[1], v[2], q) == s0 && orient_yz(v[2], v[0], q) == s0;
}

/* Sign of orient3d(a, b, c, p') for p' = (x + e^3, y + e, z + e^2). The
 * gradient of orient3d in p is -(b - a) x (c - a), whose component signs
 * st_orient2d_drop gives exactly. */
static int side_of(const double *v[3], const double p[3], const int grad[3])
{
    int s = st_sign(st_orient3d(v[0], v[1], v[2], p));
    if (s)
        return s;
    if (grad[1])
        return grad[1];
    if (grad[2])
        return grad[2];
    return grad[0];
}

typedef struct row_bins {
    size_t *start;      /* nrows + 1 offsets into tri */
    uint32_t *tri;      /* triangle indices, grouped by row */
} row_bins;

/* The rows (j, k) whose perturbed line (y + e, z + e^2) may pass through
 * triangle t: those with ylo <= y < yhi and zlo <= z < zhi for the
 * triangle's (y, z) box (a row at y == yhi lies above the box once
 * perturbed, one at y == ylo inside it; the same for z). A line outside
 * the box misses the triangle, so only rows line_hits would refuse are
 * left out. The index arithmetic guesses one row wider each way; the
 * rows' own coordinates, computed as st_solid_inside computes them, then
 * trim it exactly. An empty range has *j0 > *j1 or *k0 > *k1. */
static double row_coord(const st_grid *g, int a, size_t j)
{
    return g->origin[1 + a] + g->voxel * (double)j;
}

static void tri_rows(const st_grid *g, const st_soup *s, size_t t,
                     size_t *j0, size_t *j1, size_t *k0, size_t *k1)
{
    double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
    for (int c = 0; c < 3; c++) {
        const double *p = s->xyz + 3 * (size_t)s->tris[3 * t + c];
        for (int a = 0; a < 2; a++) {
            lo[a] = fmin(lo[a], p[1 + a]);
            hi[a] = fmax(hi[a], p[1 + a]);
        }
    }
    size_t n[2] = {g->ny, g->nz}, r0[2], r1[2];
    for (int a = 0; a < 2; a++) {
        double f0 = floor((lo[a] - g->origin[1 + a]) / g->voxel) - 1.0;
        double f1 = ceil((hi[a] - g->origin[1 + a]) / g->voxel) + 1.0;
        r0[a] = 1;
        r1[a] = 0;  /* empty */
        if (f1 < 0.0 || f0 > (double)n[a] - 1.0)
            continue;
        size_t b = f0 < 0.0 ? 0 : (size_t)f0;
        size_t e = f1 > (double)n[a] - 1.0 ? n[a] : (size_t)f1 + 1;   /* rows [b, e) */
        while (b < e && row_coord(g, a, b) < lo[a])
            b++;
        while (e > b && !(row_coord(g, a, e - 1) < hi[a]))
            e--;
        if (b < e) {
            r0[a] = b;
            r1[a] = e - 1;
        }
    }
    *j0 = r0[0];
    *j1 = r1[0];
    *k0 = r0[1];
    *k1 = r1[1];
}

/* Triangles [t0, t1) into their rows: with tri NULL, count each row's in
 * slot[row]; else write each to tri[slot[row]++]. */
static void bin_run(const st_grid *g, const st_soup *s, size_t t0, size_t t1, size_t *slot,
                    uint32_t *tri)
{
    for (size_t t = t0; t < t1; t++) {
        size_t j0, j1, k0, k1;
        tri_rows(g, s, t, &j0, &j1, &k0, &k1);
        if (j0 > j1 || k0 > k1)
            continue;
        for (size_t k = k0; k <= k1; k++)
            for (size_t j = j0; j <= j1; j++) {
                size_t *x = &slot[j + g->ny * k];
                if (tri)
                    tri[*x] = (uint32_t)t;
                ++*x;
            }
    }
}

/* Bin the triangles by row, each row's triangles in input order: the
 * triangles cut into runs, each counted and filled by one thread into its
 * own part of every row's list (the runs' parts in run order), so the
 * lists are the serial ones for any thread count. */
static st_status bin_rows(row_bins *b, const st_grid *g, const st_soup *s,
                          st_error *err)
{
    const size_t nrows = g->ny * g->nz;
    b->start = st_calloc_array(nrows + 1, sizeof *b->start);
    b->tri = NULL;
    int runs = 1;
#ifdef _OPENMP
    runs = omp_get_max_threads();
#endif
    runs = runs < 1 ? 1 : runs > 8 ? 8 : runs;
    if (s->ntris < 4096)
        runs = 1;
    size_t *cnt = st_calloc_array((size_t)runs * (nrows + 1), sizeof *cnt);
    if (!b->start || !cnt) {
        free(cnt);
        return st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory binning triangles");
    }
    for (int pass = 0; pass < 2; pass++) {
        if (pass == 1) {
            /* b->start[r]: row r's first slot; cnt[c][r] becomes run c's */
            size_t total = 0;
            for (size_t r = 0; r < nrows; r++) {
                b->start[r] = total;
                for (int c = 0; c < runs; c++) {
                    size_t *x = &cnt[(size_t)c * (nrows + 1) + r];
                    const size_t k = *x;
                    *x = total;
                    total += k;
                }
            }
            b->start[nrows] = total;
            b->tri = st_malloc_array(total ? total : 1, sizeof *b->tri);
            if (!b->tri) {
                free(cnt);
                return st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory binning triangles");
            }
        }
        #pragma omp parallel for schedule(static, 1) num_threads(runs)
        for (int c = 0; c < runs; c++)
            bin_run(g, s, s->ntris * (size_t)c / (size_t)runs,
                    s->ntris * (size_t)(c + 1) / (size_t)runs, cnt + (size_t)c * (nrows + 1),
                    pass ? b->tri : NULL);
    }
    free(cnt);
    return ST_OK;
}

/* Add the crossing of triangle v with the perturbed row line at (y, z) to
 * wind[i] at the first voxel of the row beyond it: +1 where the triangle
 * faces +x (its normal's x component is positive), -1 where it faces -x.
 * Voxel centers beyond the crossing are those whose side of the plane has
 * the sign of the plane's slope along x; the side is monotonic along the
 * row, so a binary search finds the first. */
static void add_crossing(int32_t *wind, const st_grid *g, const double *v[3],
                         double y, double z)
{
    int grad[3];
    for (int a = 0; a < 3; a++)
        grad[a] = -st_sign(st_orient2d_drop(v[0], v[1], v[2], a));
    int beyond = grad[0];   /* nonzero: the projection is not degenerate */
    size_t lo = 0, hi = g->nx;  /* first beyond in [lo, hi] */
    while (lo < hi) {
        size_t mid = lo + (hi - lo) / 2;
        const double p[3] = {g->origin[0] + g->voxel * (double)mid, y, z};
        if (side_of(v, p, grad) == beyond)
            hi = mid;
        else
            lo = mid + 1;
    }
    if (lo < g->nx)
        wind[lo] += beyond > 0 ? -1 : 1;
}

st_status st_solid_inside(uint8_t *inside, const st_grid *g,
                          const st_soup *const *shells, size_t nshells,
                          st_solid_rule rule, st_error *err)
{
    size_t count = st_grid_count(g);
    memset(inside, 0, count);
    size_t nrows = g->ny * g->nz;
    for (size_t sh = 0; sh < nshells; sh++) {
        const st_soup *s = shells[sh];
        if (s->ntris > (size_t)INT32_MAX)
            return st_error_set(err, ST_ELIMIT, NULL, 0,
                                "a shell of %zu triangles is over the limit of %d",
                                s->ntris, INT32_MAX);
        row_bins b;
        st_status st = bin_rows(&b, g, s, err);
        if (st) {
            free(b.start);
            return st;
        }
        int oom = 0;
        #pragma omp parallel reduction(| : oom)
        {
            int32_t *wind = malloc(g->nx * sizeof *wind);
            if (!wind)
                oom = 1;
            #pragma omp for schedule(dynamic, 64)
            for (size_t r = 0; r < nrows; r++) {
                if (!wind)
                    continue;
                size_t j = r % g->ny, k = r / g->ny;
                double y = row_coord(g, 0, j);
                double z = row_coord(g, 1, k);
                const double q[2] = {y, z};
                memset(wind, 0, g->nx * sizeof *wind);
                for (size_t e = b.start[r]; e < b.start[r + 1]; e++) {
                    const uint32_t *t = s->tris + 3 * (size_t)b.tri[e];
                    const double *v[3] = {s->xyz + 3 * (size_t)t[0], s->xyz + 3 * (size_t)t[1],
                                          s->xyz + 3 * (size_t)t[2]};
                    if (line_hits(v, q))
                        add_crossing(wind, g, v, y, z);
                }
                /* The winding number of the voxel center: the signed
                 * crossings on the ray from it along -x. */
                int32_t w = 0;
                uint8_t *row = inside + g->nx * r;
                for (size_t i = 0; i < g->nx; i++) {
                    w += wind[i];
                    row[i] |= (uint8_t)(rule == ST_SOLID_PARITY ? (w & 1) : (w != 0));
                }
            }
            free(wind);
        }
        free(b.start);
        free(b.tri);
        if (oom)
            return st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory");
    }
    return ST_OK;
}

st_status st_solid_iou(double *iou, double *precision, double *recall,
                       const uint8_t *truth, const st_grid *f, st_error *err)
{
    (void)err;
    size_t n = st_grid_count(f), both = 0, t = 0, p = 0;
    #pragma omp parallel for reduction(+ : both, t, p) schedule(static)
    for (size_t i = 0; i < n; i++) {
        int in_f = f->data[i] < 0.0f, in_t = truth[i] != 0;
        both += (size_t)(in_f & in_t);
        t += (size_t)in_t;
        p += (size_t)in_f;
    }
    size_t uni = t + p - both;
    *iou = uni ? (double)both / (double)uni : 1.0;
    *precision = p ? (double)both / (double)p : 1.0;
    *recall = t ? (double)both / (double)t : 1.0;
    return ST_OK;
}
