/*
 * wrap.h - the repaired soup: a closed, oriented, 2-manifold triangle
 * surface around the pseudo volume of a signed field (soupwrap).
 *
 * Units: the field's model units; iso in distance units; min_volume in
 * voxels.
 * Ownership: the caller owns *out (st_soup_free) and polys
 * (st_wrap_polys_clear); the field is borrowed.
 * Threads: OpenVDB's extraction and our checks are deterministic for any
 * thread count.
 * Errors: ST_EINPUT (a field that is not signed), ST_ENOMEM, ST_ELIMIT,
 * ST_ECANCELLED, ST_EINTERNAL (no adaptivity gave a valid surface).
 *
 * The steps (extraction with OpenVDB's volumeToMesh, cavities and specks
 * dropped, coordinates rounded to float, quads split, self-intersections
 * re-split, Taubin smoothing, and the retries with less adaptivity that the
 * stats report): doc/design/wrap.md.
 */
#ifndef SOUPTET_WRAP_H
#define SOUPTET_WRAP_H

#include <stddef.h>
#include <stdint.h>
#include "souptet/err.h"
#include "souptet/grid.h"
#include "souptet/progress.h"
#include "souptet/soup.h"

#ifdef __cplusplus
extern "C" {
#endif

#define ST_WRAP_DEFAULT_ISO 0.0
#define ST_WRAP_DEFAULT_ADAPTIVITY 0.0
#define ST_WRAP_DEFAULT_SMOOTH 0
/* Outermost pieces enclosing less than this many voxels (cubed voxel
 * sizes) are dropped: a blob two voxels across is below what the grid
 * resolves, and sign voting leaves such specks (measured: 5-voxel
 * pockets at the corners of a box soup at 24 cells). */
#define ST_WRAP_DEFAULT_MIN_VOLUME 8.0
/* Taubin's pass band (lambda > 0 smooths, mu < -lambda undoes the
 * shrinking): the values of Taubin 1995, k_PB = 1/lambda + 1/mu = 0.1. */
#define ST_WRAP_TAUBIN_LAMBDA 0.5
#define ST_WRAP_TAUBIN_MU (-0.5263157894736842)

typedef struct st_wrap_params {
    double iso;          /* isovalue in model units (negative: inward) */
    double adaptivity;   /* in [0, 1]: 0 keeps every cell's polygon */
    int smooth;          /* Taubin steps, >= 0 */
    double min_volume;   /* drop outer pieces smaller (voxels), >= 0 */
    int keep_cavities;   /* 0: fill cavities (pieces inside others) */
} st_wrap_params;

st_wrap_params st_wrap_params_default(void);

typedef struct st_wrap_stats {
    size_t quads, triangles;     /* polygons volumeToMesh gave */
    double adaptivity_used;      /* after any fallback (see above) */
    size_t resplit;              /* quads re-split to remove an intersection */
    size_t cavities_filled;      /* cavities (and islands in them) dropped */
    size_t specks_dropped;       /* outer pieces under min_volume, dropped */
    size_t smooth_steps;         /* Taubin steps done */
    size_t smooth_reverted;      /* vertex moves undone by the checks */
    size_t edge_voxels_inside;   /* inside voxels on the grid's outer layer */
    double iso_margin;           /* voxels every value was held off iso */
    size_t iso_held_off;         /* values that moved to keep that margin */
} st_wrap_stats;

/* What the output must be; each flag 1 when it holds. */
typedef struct st_wrap_check {
    int closed;          /* every edge in exactly two triangles */
    int manifold;        /* and every vertex a single fan */
    int oriented;        /* every edge traversed once each way */
    int outward;         /* every piece's volume positive, or negative
                            for a cavity (inside an odd number of other
                            pieces, by exact ray parity) */
    int nondegenerate;   /* no two corners equal, no three collinear */
    int distinct;        /* no two vertices at the same point */
    int self_intersection_free;
    size_t pieces;
    size_t self_intersecting_pairs;
    double volume;       /* signed volume enclosed, model units cubed */
} st_wrap_check;

/* Check a surface against everything above (exactly: soupinfo.h's
 * welding, edges and fans; exact self-intersection test; volume in
 * double). Vertices no triangle uses are ignored. */
st_status st_wrap_check_compute(st_wrap_check *out, const st_soup *s,
                                st_error *err);
/* 1 when every flag of c holds. */
int st_wrap_check_ok(const st_wrap_check *c);

/* The surface of the pseudo volume of signed field g (kind SIGNED, or
 * UNKNOWN with negative values): *out gets a new soup of indexed,
 * float-representable vertices and triangles. stats may be NULL.
 * ST_EINPUT when g is an unsigned distance field or nothing lies inside
 * (no value below iso); ST_EINTERNAL when no adaptivity gives a surface
 * that passes st_wrap_check (a bug: the message says which property
 * failed). Deterministic for any thread count (OpenMP's here; OpenVDB
 * runs volumeToMesh on TBB's threads, whose count it picks itself, and
 * numbers its points by prefix sums over leaf nodes, so the order does
 * not depend on them either: the tests compare runs). */
st_status st_wrap_field(st_soup **out, const st_grid *g,
                        const st_wrap_params *p, st_wrap_stats *stats,
                        const st_progress *progress, st_error *err);

/* ---- the OpenVDB adapter (src/adapters/wrap_vdb.cpp) --------------------- */

/* Polygons as volumeToMesh gives them, in world coordinates. */
typedef struct st_wrap_polys {
    double *xyz;         /* 3 * npoints */
    size_t npoints;
    uint32_t *quads;     /* 4 * nquads */
    size_t nquads;
    uint32_t *tris;      /* 3 * ntris */
    size_t ntris;
} st_wrap_polys;

/* Run volumeToMesh on g (values < iso inside) with a one-voxel layer of
 * outside values (iso + half a voxel) around the grid. Fills *out
 * (arrays from malloc; release with st_wrap_polys_clear). Never throws,
 * never prints. */
st_status st_wrap_polys_vdb(st_wrap_polys *out, const st_grid *g, double iso,
                            double adaptivity, st_error *err);
void st_wrap_polys_clear(st_wrap_polys *p);   /* safe on a zeroed struct */

#ifdef __cplusplus
}
#endif
#endif
