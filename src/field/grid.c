/* grid.c - dense voxel grids (see grid.h). */
#include "souptet/grid.h"
#include "../base/fpenv.h"
#include "souptet/mem.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static st_status grid_new(st_grid **out, size_t nx, size_t ny, size_t nz,
                          const double origin[3], double voxel,
                          const float *fill, size_t max_bytes, st_error *err)
{
    *out = NULL;
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
    size_t n, bytes;
    if (st_size_mul(&n, nx, ny) || st_size_mul(&n, n, nz) ||
        st_size_mul(&bytes, n, sizeof(float)))
        return st_error_set(err, ST_ELIMIT, NULL, 0,
                            "grid size %zux%zux%zu overflows memory sizes",
                            nx, ny, nz);
    if (max_bytes && bytes > max_bytes)
        return st_error_set(err, ST_ELIMIT, NULL, 0,
                            "a %zux%zux%zu grid needs %.1f MiB, over the "
                            "limit of %.1f MiB (lower the resolution or "
                            "raise --max-memory)",
                            nx, ny, nz, (double)bytes / 1048576.0,
                            (double)max_bytes / 1048576.0);
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
    g->nx = nx;
    g->ny = ny;
    g->nz = nz;
    memcpy(g->origin, origin, sizeof g->origin);
    g->voxel = voxel;
    g->data = data;
    g->kind = ST_GRID_UNKNOWN;
    g->band = INFINITY;
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
