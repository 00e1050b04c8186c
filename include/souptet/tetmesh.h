/*
 * tetmesh.h - tetrahedral meshes: points, tets, named arrays, metadata.
 *
 * Units: model units for points; volumes in units^3, angles in degrees.
 * Ownership: the caller owns a mesh (st_tetmesh_free, safe on NULL), its
 * arrays and meta; copies are deep.
 * Threads: no global state; a mesh may be read from many threads, written
 * by one; st_tetmesh_quality runs OpenMP loops independent of the thread
 * count.
 * Errors: ST_EINPUT (bad indices, array sizes), ST_ELIMIT, ST_ENOMEM.
 *
 * A tet (a, b, c, d) is positively oriented when st_orient3d(a, b, c, d) < 0,
 * i.e. d lies on the side of triangle (a, b, c) from which a, b, c appear
 * counterclockwise; its signed volume (b-a).((c-a)x(d-a))/6 is then > 0.
 * Every mesh souptet writes has only positively oriented tets; a mesh read
 * from a file may have any, and the tools say so (tetstat counts them).
 *
 * Arrays: any number of named double arrays, each either per point or per
 * cell, with 1..9 components (e.g. "min_dihedral" per cell, "h" as field
 * data goes into meta instead). The .vtu writer adds the per-cell quality
 * arrays min_dihedral, max_dihedral and volume itself.
 */
#ifndef SOUPTET_TETMESH_H
#define SOUPTET_TETMESH_H

#include <stddef.h>
#include <stdint.h>

#include "souptet/err.h"
#include "souptet/meta.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum st_tet_assoc {
    ST_ON_POINTS = 0,
    ST_ON_CELLS
} st_tet_assoc;

typedef struct st_tet_array {
    char *name;
    st_tet_assoc assoc;
    int ncomp;            /* components per tuple, 1..9 */
    double *values;       /* ncomp * (npoints or ntets) */
} st_tet_array;

/* A zero-initialised st_tetmesh is a valid empty mesh. Grow xyz and tets
 * only through st_tetmesh_add_point / st_tetmesh_add_tet (or
 * st_tetmesh_reserve followed by direct writes and count updates). */
typedef struct st_tetmesh {
    double *xyz;          /* 3 * npoints coordinates, all finite */
    size_t npoints;
    uint32_t *tets;       /* 4 * ntets point indices, each < npoints */
    size_t ntets;
    size_t cap_points, cap_tets;
    st_tet_array *arrays;
    size_t narrays;
    st_meta meta;         /* source, lattice "h", parameters, history */
} st_tetmesh;

/* An empty mesh; NULL when out of memory. */
st_tetmesh *st_tetmesh_new(void);
void st_tetmesh_free(st_tetmesh *m);          /* safe on NULL */

/* Capacity for at least npoints points and ntets tets (checked sizes). */
st_status st_tetmesh_reserve(st_tetmesh *m, size_t npoints, size_t ntets,
                             st_error *err);
/* Append; ST_ELIMIT past UINT32_MAX points; add_tet refuses indices >=
 * npoints (ST_EINPUT). Both invalidate per-point / per-cell arrays of the
 * wrong length: callers add arrays after the geometry is final. */
st_status st_tetmesh_add_point(st_tetmesh *m, const double p[3],
                               st_error *err);
st_status st_tetmesh_add_tet(st_tetmesh *m, uint32_t a, uint32_t b,
                             uint32_t c, uint32_t d, st_error *err);

/* Add (or replace) a named array of ncomp components, zero-filled, sized
 * for the current point or tet count; *values points at its storage. */
st_status st_tetmesh_add_array(st_tetmesh *m, const char *name,
                               st_tet_assoc assoc, int ncomp,
                               double **values, st_error *err);
/* The array of that name and association, or NULL. */
const st_tet_array *st_tetmesh_find_array(const st_tetmesh *m,
                                          const char *name,
                                          st_tet_assoc assoc);
/* Remove every array (geometry and meta stay). */
void st_tetmesh_clear_arrays(st_tetmesh *m);

/* Drop points no tet uses and renumber (arrays on points follow). */
st_status st_tetmesh_compact(st_tetmesh *m, st_error *err);

/* Face adjacency. nbr[4*t + i] is the tet across the face of t opposite
 * its corner i, or -1 when that face is on the boundary. A face shared by
 * more than two tets makes the mesh non-conforming: those faces are
 * counted in *nonmanifold_faces (may be NULL) and their tets get -1 there.
 * The caller frees *nbr with free(). Deterministic (no hashing order). */
st_status st_tetmesh_neighbors(const st_tetmesh *m, int64_t **nbr,
                               size_t *nonmanifold_faces, st_error *err);

/* The boundary faces (those of exactly one tet), each oriented so that its
 * normal (b-a)x(c-a) points out of the mesh for a positively oriented tet:
 * faces[3*f..3*f+2] are point indices, face_tet[f] the owning tet (may be
 * NULL). Sorted by (owning tet, corner). The caller frees with free(). */
st_status st_tetmesh_boundary(const st_tetmesh *m, uint32_t **faces,
                              uint32_t **face_tet, size_t *nfaces,
                              st_error *err);

/* The boundary surface of m as a soup (the collision proxy soupmesh
 * --boundary writes): the boundary faces of st_tetmesh_boundary, in its
 * order, each turned by the exact orientation test (pred.h) so that the
 * tet's fourth point lies behind it, i.e. its normal (b-a)x(c-a) points
 * out of the mesh whatever the tets' own orientation (a face of a flat
 * tet keeps st_tetmesh_boundary's order); only the points the faces use,
 * numbered in order of first use, with their coordinates copied bit for
 * bit. For a conforming mesh the surface is closed (every edge on an even
 * number of faces) and consistently oriented. *out is a new soup (empty
 * for a mesh without tets); ST_ENOMEM, ST_ELIMIT. */
struct st_soup;
st_status st_tetmesh_boundary_soup(struct st_soup **out, const st_tetmesh *m,
                                   st_error *err);

/* A deep copy of src (geometry, arrays, meta) into a new mesh *out. */
st_status st_tetmesh_copy(st_tetmesh **out, const st_tetmesh *src,
                          st_error *err);

/* Per-tet quality into caller-owned arrays of m->ntets values (any may be
 * NULL): smallest and largest dihedral angle in degrees and the signed
 * volume (tetqual.h). Parallel; the values do not depend on the thread
 * count. */
void st_tetmesh_quality(const st_tetmesh *m, double *min_deg,
                        double *max_deg, double *volume);

#ifdef __cplusplus
}
#endif
#endif
