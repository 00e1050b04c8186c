/*
 * grid.h - dense scalar fields on a regular grid of voxels.
 *
 * Units: model units for origin, voxel size and distances; indices in
 * voxels.
 * Ownership: the caller owns a grid (st_grid_free, safe on NULL), its data
 * and its meta; a grid stored by blocks likewise (st_grid_blocks_free).
 * Threads: no global state; a grid may be read from many threads, written
 * by one.
 * Errors: st_grid_new: ST_EINPUT (no voxels, a voxel size or origin that
 * is not a finite positive number), ST_ELIMIT (over max_bytes, or sizes
 * that overflow), ST_ENOMEM; st_grid_blocks_dense likewise.
 *
 * Values live at voxel centers: voxel (i, j, k) is centered at
 * origin + voxel * (i, j, k). Storage is x fastest:
 * data[i + nx * (j + ny * k)].
 *
 * A distance field holds unsigned distances (in model units) that are exact
 * (to rounding) where they are below `band` and clamped to `band` beyond; a
 * full field has band = INFINITY. A signed field is negative inside the
 * pseudo volume.
 */
#ifndef SOUPTET_GRID_H
#define SOUPTET_GRID_H

#include <float.h>
#include <stddef.h>
#include "souptet/err.h"
#include "souptet/meta.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum st_grid_kind {
    ST_GRID_UNKNOWN = 0,
    ST_GRID_DISTANCE,   /* unsigned distance to a soup */
    ST_GRID_SIGNED      /* signed: negative inside the pseudo volume */
} st_grid_kind;

typedef struct st_grid {
    size_t nx, ny, nz;    /* voxels along each axis, each >= 1 */
    double origin[3];     /* center of voxel (0, 0, 0), model units */
    double voxel;         /* edge length of a voxel, > 0 */
    float *data;          /* nx * ny * nz values, x fastest */
    st_grid_kind kind;
    double band;          /* values >= band are clamped; INFINITY if none */
    st_meta meta;         /* source, triangles, parameters, history, ... */
} st_grid;

/* A grid of the given size with data set to `fill`. Sizes are checked for
 * overflow; ST_ELIMIT when more than max_bytes would be allocated
 * (max_bytes 0: no limit). */
st_status st_grid_new(st_grid **out, size_t nx, size_t ny, size_t nz,
                      const double origin[3], double voxel, float fill,
                      size_t max_bytes, st_error *err);
/* As st_grid_new, but the values are left unset: for a caller that writes
 * every voxel itself (in parallel, so the pages are first touched by the
 * threads that use them). */
st_status st_grid_new_unset(st_grid **out, size_t nx, size_t ny, size_t nz,
                            const double origin[3], double voxel,
                            size_t max_bytes, st_error *err);
void st_grid_free(st_grid *g);   /* safe on NULL */

/* A banded field stored by blocks (st_dist_field_blocks, st_grid_blocks_write):
 * the grid cut into blocks of ST_GRID_BLOCK^3 voxels at multiples of
 * ST_GRID_BLOCK (OpenVDB's leaf nodes), a block stored only where one of
 * its voxels holds less than the band, every other voxel holding the band
 * (head.band, as a float). head gives the placement, kind, band and meta
 * as for a dense grid; head.data is NULL. Block (bi, bj, bk) is number
 * bi + nb[0] * (bj + nb[1] * bk); at[b] is the first of its
 * ST_GRID_BLOCK^3 values in `values`, or ST_GRID_NO_BLOCK. Within a block,
 * voxel (i, j, k) is value 64 * (i % 8) + 8 * (j % 8) + k % 8 (z fastest,
 * as in OpenVDB's leaves); voxels of a block beyond the grid hold the band.
 * Ownership: st_grid_blocks_free (safe on NULL). */
#define ST_GRID_BLOCK 8
#define ST_GRID_NO_BLOCK ((size_t)-1)
typedef struct st_grid_blocks {
    st_grid head;         /* placement, kind, band, meta; data NULL */
    size_t nb[3];         /* blocks per axis: ceil(n / ST_GRID_BLOCK) */
    size_t *at;           /* nb[0] * nb[1] * nb[2] entries */
    float *values;        /* the stored blocks' values */
    size_t nstored;       /* blocks stored (at[b] != ST_GRID_NO_BLOCK) */
} st_grid_blocks;

/* A grid stored by blocks with no block stored (every voxel the band, set
 * by the caller in head.band): the checks of st_grid_new, max_bytes
 * against the dense size, so a field refused dense is refused here too. */
st_status st_grid_blocks_new(st_grid_blocks **out, size_t nx, size_t ny,
                             size_t nz, const double origin[3], double voxel,
                             size_t max_bytes, st_error *err);
void st_grid_blocks_free(st_grid_blocks *b);   /* safe on NULL */
/* The value of voxel (i, j, k) of a grid stored by blocks. */
static inline float st_grid_blocks_value(const st_grid_blocks *b, size_t i,
                                         size_t j, size_t k)
{
    const size_t at = b->at[i / ST_GRID_BLOCK + b->nb[0] *
                            (j / ST_GRID_BLOCK + b->nb[1] * (k / ST_GRID_BLOCK))];
    if (at == ST_GRID_NO_BLOCK)
        return (float)b->head.band;
    return b->values[at + ST_GRID_BLOCK * ST_GRID_BLOCK * (i % ST_GRID_BLOCK) +
                     ST_GRID_BLOCK * (j % ST_GRID_BLOCK) + k % ST_GRID_BLOCK];
}
/* The same field as a dense grid (a copy of the meta too). Errors as
 * st_grid_new's. */
st_status st_grid_blocks_dense(st_grid **out, const st_grid_blocks *b,
                               size_t max_bytes, st_error *err);

/* The name a field of this kind is stored under in files (gridio.h):
 * "distance", "sdf", else "field". */
const char *st_grid_name_for_kind(st_grid_kind kind);

/* Number of voxels (never overflows for a grid that exists). */
size_t st_grid_count(const st_grid *g);
/* Linear index of voxel (i, j, k). */
static inline size_t st_grid_index(const st_grid *g, size_t i, size_t j,
                                   size_t k)
{
    return i + g->nx * (j + g->ny * k);
}
/* The value of a signed field for distance d on the given side: |d|,
 * negative inside. A voxel inside at distance 0 (its center on the
 * surface) gets -FLT_MIN, not -0.0, so that value < 0 holds for exactly
 * the inside voxels, as every reader of a signed field tests. */
static inline float st_grid_signed_value(float d, int inside)
{
    const float a = d < 0.0f ? -d : d;
    return inside ? (a > 0.0f ? -a : -FLT_MIN) : a;
}
/* World position of the center of voxel (i, j, k). */
void st_grid_center(const st_grid *g, size_t i, size_t j, size_t k,
                    double p[3]);

/* The voxel containing point p (voxel i covers centres +- voxel/2, ties
 * rounded up): 1 and its indices when on the grid, 0 when off it. */
int st_grid_voxel_of(const st_grid *g, const double p[3], size_t ijk[3]);

/* "distance", "signed" or "unknown", and back (UNKNOWN for other text). */
const char *st_grid_kind_name(st_grid_kind kind);
st_grid_kind st_grid_kind_from_name(const char *name);

#ifdef __cplusplus
}
#endif
#endif
