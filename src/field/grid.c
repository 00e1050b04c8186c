/* grid.c - dense voxel grids (see grid.h). */
#include "souptet/grid.h"
#include "../base/fpenv.h"
#include "souptet/mem.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* The checks every new grid passes; *bytes: its dense size. */
static st_status grid_check(size_t nx, size_t ny, size_t nz,
                            const double origin[3], double voxel,
                            size_t max_bytes, size_t *bytes, st_error *err)
{
    if (nx == 0 || ny == 0 || nz == 0)
        return st_error_set(err, ST_EINPUT, NULL, 0,
                            "grid size %zux%zux%zu has no voxels", nx, ny, nz);
    if (!(voxel > 0) || !isfinite(voxel))
        return st_error_set(err, ST_EINPUT, NULL, 0,
                            "voxel size %g is not a positive number", voxel);
    for (int a = 0; a < 3; a++)
        if (!isfinite(origin[a]))
            return st_error_set(err, ST_EINPUT, NULL, 0,
                                "grid origin is not finite");
    size_t n;
    if (st_size_mul(&n, nx, ny) || st_size_mul(&n, n, nz) ||
        st_size_mul(bytes, n, sizeof(float)))
        return st_error_set(err, ST_ELIMIT, NULL, 0,
                            "grid size %zux%zux%zu overflows memory sizes",
                            nx, ny, nz);
    if (max_bytes && *bytes > max_bytes)
        return st_error_set(err, ST_ELIMIT, NULL, 0,
                            "a %zux%zux%zu grid needs %.1f MiB, over the "
                            "limit of %.1f MiB (lower the resolution or "
                            "raise --max-memory)",
                            nx, ny, nz, (double)*bytes / 1048576.0,
                            (double)max_bytes / 1048576.0);
    return ST_OK;
}

static void grid_place(st_grid *g, size_t nx, size_t ny, size_t nz,
                       const double origin[3], double voxel)
{
    g->nx = nx;
    g->ny = ny;
    g->nz = nz;
    memcpy(g->origin, origin, sizeof g->origin);
    g->voxel = voxel;
    g->kind = ST_GRID_UNKNOWN;
    g->band = INFINITY;
}

static st_status grid_new(st_grid **out, size_t nx, size_t ny, size_t nz,
                          const double origin[3], double voxel,
                          const float *fill, size_t max_bytes, st_error *err)
{
    *out = NULL;
    size_t bytes;
    st_status st = grid_check(nx, ny, nz, origin, voxel, max_bytes, &bytes, err);
    if (st)
        return st;
    const size_t n = bytes / sizeof(float);
    st_grid *g = calloc(1, sizeof *g);
    /* Large grids ask for transparent huge pages (see st_malloc_big). */
    float *data = g ? st_malloc_big(bytes) : NULL;
    if (!data) {
        free(g);
        return st_error_set(err, ST_ENOMEM, NULL, 0,
                            "out of memory for a %zux%zux%zu grid (%.1f MiB)",
                            nx, ny, nz, (double)bytes / 1048576.0);
    }
    if (fill)
        for (size_t i = 0; i < n; i++)
            data[i] = *fill;
    grid_place(g, nx, ny, nz, origin, voxel);
    g->data = data;
    *out = g;
    return ST_OK;
}

st_status st_grid_new(st_grid **out, size_t nx, size_t ny, size_t nz,
                      const double origin[3], double voxel, float fill,
                      size_t max_bytes, st_error *err)
{
    return grid_new(out, nx, ny, nz, origin, voxel, &fill, max_bytes, err);
}

st_status st_grid_new_unset(st_grid **out, size_t nx, size_t ny, size_t nz,
                            const double origin[3], double voxel,
                            size_t max_bytes, st_error *err)
{
    return grid_new(out, nx, ny, nz, origin, voxel, NULL, max_bytes, err);
}

void st_grid_free(st_grid *g)
{
    if (!g)
        return;
    free(g->data);
    st_meta_clear(&g->meta);
    free(g);
}

st_status st_grid_blocks_new(st_grid_blocks **out, size_t nx, size_t ny,
                             size_t nz, const double origin[3], double voxel,
                             size_t max_bytes, st_error *err)
{
    *out = NULL;
    size_t bytes;
    st_status st = grid_check(nx, ny, nz, origin, voxel, max_bytes, &bytes, err);
    if (st)
        return st;
    const size_t B = ST_GRID_BLOCK;
    const size_t nb[3] = {(nx + B - 1) / B, (ny + B - 1) / B, (nz + B - 1) / B};
    const size_t n = nb[0] * nb[1] * nb[2];   /* at most the voxels: no overflow */
    st_grid_blocks *b = calloc(1, sizeof *b);
    size_t *at = b ? st_malloc_array(n, sizeof *at) : NULL;
    if (!at) {
        free(b);
        return st_error_set(err, ST_ENOMEM, NULL, 0,
                            "out of memory for a %zux%zux%zu grid's blocks",
                            nx, ny, nz);
    }
    for (size_t i = 0; i < n; i++)
        at[i] = ST_GRID_NO_BLOCK;
    grid_place(&b->head, nx, ny, nz, origin, voxel);
    memcpy(b->nb, nb, sizeof b->nb);
    b->at = at;
    *out = b;
    return ST_OK;
}

void st_grid_blocks_free(st_grid_blocks *b)
{
    if (!b)
        return;
    free(b->at);
    free(b->values);
    st_meta_clear(&b->head.meta);
    free(b);
}

st_status st_grid_blocks_dense(st_grid **out, const st_grid_blocks *b,
                               size_t max_bytes, st_error *err)
{
    *out = NULL;
    const st_grid *h = &b->head;
    st_grid *g;
    st_status st = st_grid_new_unset(&g, h->nx, h->ny, h->nz, h->origin,
                                     h->voxel, max_bytes, err);
    if (st)
        return st;
    g->kind = h->kind;
    g->band = h->band;
    if (st_meta_copy(&g->meta, &h->meta)) {
        st_grid_free(g);
        return st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory");
    }
    #pragma omp parallel for schedule(static)
    for (size_t k = 0; k < g->nz; k++)
        for (size_t j = 0; j < g->ny; j++) {
            float *row = g->data + st_grid_index(g, 0, j, k);
            for (size_t i = 0; i < g->nx; i++)
                row[i] = st_grid_blocks_value(b, i, j, k);
        }
    *out = g;
    return ST_OK;
}

const char *st_grid_name_for_kind(st_grid_kind kind)
{
    switch (kind) {
    case ST_GRID_DISTANCE: return "distance";
    case ST_GRID_SIGNED: return "sdf";
    default: return "field";
    }
}

size_t st_grid_count(const st_grid *g)
{
    return g->nx * g->ny * g->nz;
}

void st_grid_center(const st_grid *g, size_t i, size_t j, size_t k,
                    double p[3])
{
    p[0] = g->origin[0] + g->voxel * (double)i;
    p[1] = g->origin[1] + g->voxel * (double)j;
    p[2] = g->origin[2] + g->voxel * (double)k;
}

int st_grid_voxel_of(const st_grid *g, const double p[3], size_t ijk[3])
{
    size_t n[3] = {g->nx, g->ny, g->nz};
    for (int a = 0; a < 3; a++) {
        double f = floor((p[a] - g->origin[a]) / g->voxel + 0.5);
        if (!(f >= 0) || !(f < (double)n[a]))
            return 0;
        ijk[a] = (size_t)f;
    }
    return 1;
}

const char *st_grid_kind_name(st_grid_kind kind)
{
    switch (kind) {
    case ST_GRID_DISTANCE: return "distance";
    case ST_GRID_SIGNED: return "signed";
    default: return "unknown";
    }
}

st_grid_kind st_grid_kind_from_name(const char *name)
{
    if (name && strcmp(name, "distance") == 0)
        return ST_GRID_DISTANCE;
    if (name && strcmp(name, "signed") == 0)
        return ST_GRID_SIGNED;
    return ST_GRID_UNKNOWN;
}
