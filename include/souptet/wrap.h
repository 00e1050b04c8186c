/*
 * wrap.h - the repaired soup: a closed, oriented, 2-manifold triangle
 * surface around the pseudo volume of a signed field (soupwrap).
 *
 * Algorithm:
 *   1. Extraction (src/adapters/wrap_vdb.cpp): OpenVDB's volumeToMesh on
 *      the field at the isovalue, with a layer of "outside" voxels put
 *      around the grid, so a pseudo volume that reaches the grid's edge is
 *      closed there instead of left open (outside the grid is outside).
 *      Every value is first held at least a 64th of a voxel off the
 *      isovalue, on its own side (the inside voxels stay the same): at a
 *      value equal to the isovalue volumeToMesh puts the points of up to
 *      eight cells on one voxel center, and their quads are degenerate
 *      (a CAD face lying on voxel centers, at distance 0, does that).
 *   2. Cavities and specks: volumeToMesh orients every polygon along the
 *      field's gradient, so a piece enclosing negative volume bounds
 *      outside voxels: a cavity. Cavities are dropped, so the solid is
 *      filled (sign voting leaves such pockets where it errs, thousands
 *      of single voxels on a 50%-deleted model; a real cavity is "hidden
 *      from every ray" and already inside under the default rule), unless
 *      keep_cavities; so is a piece found inside another by exact ray
 *      parity once cavities are filled (an island in a cavity), and every
 *      outer piece enclosing less than min_volume voxels. Whole closed
 *      pieces go, so what stays is as closed and manifold as before.
 *   3. Coordinates are rounded to float, once, before anything is decided:
 *      every output format (OBJ, OFF, PLY, STL) then holds the very points
 *      the checks below were made on (STL has nothing but floats).
 *   4. Quads are split into two triangles along the diagonal that keeps
 *      both triangles non-degenerate (exactly: their corners not collinear),
 *      does not duplicate an existing edge (which would make it
 *      non-manifold) and does not fold the pair onto itself; of two such
 *      diagonals the one with the larger smallest angle.
 *   5. Triangles found to self-intersect (exact test, soupinfo.h) have
 *      their quads re-split along the other diagonal where that is allowed
 *      and removes the intersection.
 *   6. --smooth N: N steps of Taubin smoothing (lambda/mu, a low-pass that
 *      does not shrink). After every half step each moved vertex whose
 *      move makes a triangle degenerate, turns a triangle's normal by more
 *      than 90 degrees, or creates a self-intersection, is put back, until
 *      the surface is as valid as before the step. Topology never changes.
 *
 * Adaptivity > 0 lets volumeToMesh merge flat regions into larger
 * polygons. Merged meshes are not always manifold: when the result fails
 * the check (st_wrap_check), the extraction is repeated with half the
 * adaptivity, down to 0; then with the values held an 8th, then half a
 * voxel off the isovalue; stats say what was used.
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
