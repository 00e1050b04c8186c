/*
 * embed.h - embedding a surface in a tet mesh: for every surface vertex,
 * the tet that contains it and its barycentric coordinates there, so a
 * simulator can move the high-resolution surface with the coarse mesh
 * (x = b0 p0 + b1 p1 + b2 p2 + b3 p3 of the deformed tet's corners).
 *
 * Units: model units; barycentric coordinates are unitless and add up to 1.
 * Ownership: the caller owns the output arrays (n entries, 4 doubles a
 * vertex for bary) and any *out mesh (st_tetmesh_free); the mesh and
 * surface are borrowed.
 * Threads: OpenMP over vertices; the answer does not depend on the thread
 * count (below).
 * Errors: ST_EINPUT (a mesh without tets), ST_ENOMEM, ST_EIO
 * (st_embed_write_text); a vertex in no tet is counted, not an error.
 *
 * Containment is exact (st_point_in_tet, isect.h: a point on a face, edge
 * or corner is in the tet). A vertex in several tets (on a shared face,
 * edge or corner) gets the first of them in tet order, so the answer
 * depends only on the mesh and the surface, not on the thread count. Flat
 * tets (zero volume, no barycentric coordinates) are never chosen. A
 * vertex in no tet gets tet -1 and coordinates 0 0 0 0, and is counted.
 *
 * Coordinates are doubles from the four sub-tet volumes, divided by their
 * sum (so they add up to 1 within rounding); a sub-volume that the exact
 * orientation predicate finds zero (the vertex on the face opposite that
 * corner) is exactly 0, and rounding never makes one negative.
 *
 * Speed: a uniform grid of bins over the mesh's box, each bin listing the
 * tets whose bounding boxes meet it (about one tet per bin), in tet order;
 * a vertex tests only its bin's tets. Parallel over vertices.
 */
#ifndef SOUPTET_EMBED_H
#define SOUPTET_EMBED_H

#include <stddef.h>
#include <stdint.h>

#include "souptet/err.h"
#include "souptet/soup.h"
#include "souptet/tetmesh.h"

#ifdef __cplusplus
extern "C" {
#endif

/* For each of the n points xyz[3*i..3*i+2]: tet[i] (the containing tet or
 * -1) and bary[4*i..4*i+3] (its coordinates, or zeros), caller-owned
 * arrays of n and 4 n values. *outside (may be NULL) is the number of
 * points with tet -1; *first_outside (may be NULL) the first such point's
 * index, or -1. ST_EINPUT when xyz has a non-finite coordinate, ST_ENOMEM
 * when the bins do not fit. */
st_status st_embed_points(int64_t *tet, double *bary, size_t *outside,
                          int64_t *first_outside, const st_tetmesh *m,
                          const double *xyz, size_t n, st_error *err);

/* The same for every vertex of a surface (s->nverts of them). */
st_status st_embed_compute(int64_t *tet, double *bary, size_t *outside,
                           int64_t *first_outside, const st_tetmesh *m,
                           const st_soup *s, st_error *err);

/* The plain-text sidecar, atomically (st_outfile; "-" writes stdout):
 *
 *     # souptet embedding: N vertices of SURFACE in the T tets of MESH
 *     # one line per surface vertex, in the surface's order:
 *     # tet b0 b1 b2 b3  (tet numbered from 0 in the mesh's order; -1 when
 *     # outside; x = b0 p[t0] + b1 p[t1] + b2 p[t2] + b3 p[t3])
 *     7 0.25 0.25 0.25 0.25
 *     ...
 *
 * Coordinates are written with 17 significant digits. mesh_name and
 * surface_name (may be NULL) only label the header. */
st_status st_embed_write_text(const char *path, const int64_t *tet,
                              const double *bary, size_t n,
                              size_t ntets, const char *mesh_name,
                              const char *surface_name, st_error *err);

/* A points-only mesh for a sidecar .vtu (tetio.h's writer): the n points
 * xyz as points, no tets, point arrays "embed_tet" (1 component, the tet
 * index as a double, -1 outside) and "embed_bary" (4 components). */
st_status st_embed_to_tetmesh(st_tetmesh **out, const double *xyz,
                              const int64_t *tet, const double *bary,
                              size_t n, st_error *err);

#ifdef __cplusplus
}
#endif
#endif
