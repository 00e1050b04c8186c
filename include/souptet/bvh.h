/*
 * bvh.h - a bounding volume hierarchy over the triangles of a soup.
 *
 * Units: model units (boxes and distances are the soup's coordinates).
 * Ownership: the caller owns the BVH (st_bvh_free); the soup is borrowed
 * and must outlive it.
 * Threads: build once; queries are read-only and thread-safe, and answer
 * the same for any thread count.
 * Errors: st_bvh_build: ST_EINPUT (no triangles), ST_ELIMIT (more than
 * 2^31 triangles), ST_ENOMEM; the queries cannot fail.
 *
 * Axis-aligned boxes, median splits on the longest axis of the centroids,
 * at most ST_BVH_LEAF triangles per leaf. Queries are read-only and may run
 * from many threads at once.
 */
#ifndef SOUPTET_BVH_H
#define SOUPTET_BVH_H

#include <stddef.h>
#include <stdint.h>
#include "souptet/err.h"
#include "souptet/soup.h"
#include "souptet/geom.h"

#ifdef __cplusplus
extern "C" {
#endif

#define ST_BVH_LEAF 4

typedef struct st_bvh_node {
    double lo[3], hi[3];
    uint32_t start;   /* leaf: first slot in order[]; inner: left child */
    uint32_t count;   /* leaf: number of triangles; inner: 0 */
} st_bvh_node;

typedef struct st_bvh {
    const st_soup *soup;   /* borrowed; must outlive the BVH */
    st_bvh_node *nodes;
    size_t nnodes;
    uint32_t *order;       /* triangle indices, grouped by leaf */
    double *tbox;          /* the box of the triangle in each slot of
                              order[]: lo[3], hi[3] (6 per slot) */
} st_bvh;

/* Build over every triangle of s (s is borrowed, not copied). */
st_status st_bvh_build(st_bvh **out, const st_soup *s, st_error *err);
void st_bvh_free(st_bvh *b);   /* safe on NULL */

/* The nearest triangle to p among those closer than sqrt(max_d2): returns
 * its squared distance and sets *tri (and *closest when not NULL). When no
 * triangle is that close, returns max_d2 and sets *tri to -1. Pass
 * INFINITY for an unbounded search; a tight max_d2 makes it fast. */
double st_bvh_nearest(const st_bvh *b, const double p[3], double max_d2,
                      int64_t *tri, double closest[3]);

/* st_bvh_nearest's answer, bit for bit, with frames[t] the soup's triangle
 * t's st_tri_frame (geom.h): for many queries against one soup, its
 * triangles' normals are not computed again at each. */
double st_bvh_nearest_framed(const st_bvh *b, const st_tri_frame *frames, const double p[3],
                             double max_d2, int64_t *tri, double closest[3]);

/* Whether some triangle is closer to p than sqrt(max_d2): exactly when
 * st_bvh_nearest(b, p, max_d2, ...) sets *tri >= 0, found at the first
 * such triangle (much faster where the soup is dense). Thread-safe. */
int st_bvh_within(const st_bvh *b, const double p[3], double max_d2);

/* st_bvh_within's answer, bit for bit, first trying the triangles
 * hints[0..nhints) name (slots of order[]; ST_BVH_NO_HINT, or any value
 * at least the soup's triangle count: none): when one is closer than
 * sqrt(max_d2) and the walk could not skip it, the walk would find a
 * triangle too (bvh.c, slot_within), and none is run. *found gets the
 * slot of the triangle that answered (the hint's, or the one the walk
 * found; ST_BVH_NO_HINT when none is within reach). A run of queries at
 * nearby points (a grid's faces, a mesh's triangles in order) passing
 * the last answers on skips most walks. Thread-safe: the hints are the
 * caller's. */
#define ST_BVH_NO_HINT UINT32_MAX
int st_bvh_within_hint(const st_bvh *b, const double p[3], double max_d2,
                       const uint32_t *hints, size_t nhints, uint32_t *found);

/* Call visit(ctx, tri) for every triangle whose bounding box meets the
 * closed box [lo, hi] (a superset of the triangles that meet the box: the
 * caller decides exactly). Stops at the first nonzero return of visit and
 * returns it; 0 when every visit returned 0. Thread-safe (read-only). */
int st_bvh_query_box(const st_bvh *b, const double lo[3], const double hi[3],
                     int (*visit)(void *ctx, uint32_t tri), void *ctx);

/* Call visit(ctx, tri) for every triangle whose bounding box meets the
 * closed box of triangle (a, b, c) and lies in a node whose box meets the
 * closed triangle itself (exact): a superset of the triangles that meet
 * (a, b, c), much smaller than st_bvh_query_box's for a large slanted
 * triangle. Stops at the first nonzero return of visit and returns it.
 * The visiting order is fixed for a given tree and triangle. Thread-safe. */
int st_bvh_query_tri(const st_bvh *b, const double a[3], const double bb[3],
                     const double c[3], int (*visit)(void *ctx, uint32_t tri),
                     void *ctx);

/* Call visit(ctx, tri) for every triangle whose bounding box meets the
 * box of the tet (p[0], p[1], p[2], p[3]) and is not certainly outside the
 * closed tet, in a node whose box is not (pred.h's st_plane_filter on the
 * tet's face planes, all eight corners): a superset of the triangles that
 * meet the closed tet, much smaller than st_bvh_query_box's where the
 * triangles are dense around a large tet (the coarse lattice of a 10 M
 * triangle soup). Stops at the first nonzero return of visit and returns
 * it. The visiting order is fixed for a given tree and tet. Thread-safe. */
int st_bvh_query_tet(const st_bvh *b, const double *const p[4],
                     int (*visit)(void *ctx, uint32_t tri), void *ctx);

#ifdef __cplusplus
}
#endif
#endif
