/*
 * edges.h - the edges and pieces of a soup, read on exactly welded
 * vertices (weld.h) with degenerate triangles (two corners welded
 * together) and all but the first of each set of duplicated triangles
 * (the same three welded corners, in any order) left out.
 *
 * Units: none: indices and counts only (welding compares coordinates bit
 * for bit).
 * Ownership: the caller owns the table (st_soup_edges_free); the soup is
 * borrowed and must outlive it.
 * Threads: no global state; the table is read-only once built and may be
 * read from many threads.
 * Errors: ST_ENOMEM, ST_ELIMIT (more vertices or half-edges than 32-bit
 * indices hold).
 *
 * An edge is a run of half-edges with the same unordered welded ends; its
 * length is the number of kept triangles that use it (1: a boundary edge,
 * 2: a manifold edge). Pieces are the classes of kept triangles joined by
 * shared edges, each named by its smallest triangle index, so nothing
 * depends on hashing or sorting details. The hole caps (holes.h), the
 * closed shells (shells.h) and the damage report (soupinfo.h) read the
 * soup's topology from here: it is the one place that welds, finds
 * degenerate and duplicated triangles, sorts half-edges and joins pieces.
 *
 * With ST_EDGES_DUPLICATES the duplicates are not left out of the edges:
 * every non-degenerate triangle gives its half-edges and joins its piece,
 * so a duplicated face makes its edges non-manifold (as it does for a
 * mesher, and as soupinfo counts it).
 */
#ifndef SOUPTET_EDGES_H
#define SOUPTET_EDGES_H

#include <stddef.h>
#include <stdint.h>
#include "souptet/err.h"
#include "souptet/soup.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct st_half_edge {
    uint64_t key;       /* lower welded end << 32 | higher */
    uint32_t t;         /* its triangle */
} st_half_edge;

typedef struct st_soup_edges {
    uint32_t *weld;     /* nverts: welded id of each vertex (weld.h) */
    size_t nweld;       /* number of welded ids */
    uint8_t *kept;      /* ntris: 1 for a kept triangle: non-degenerate
                         * and the first (smallest index) of its copies */
    size_t degenerate;  /* triangles with two corners welded together */
    size_t duplicates;  /* triangles whose welded corners (a multiset, in
                         * any order) equal an earlier triangle's,
                         * degenerate ones included: the extra copies */
    st_half_edge *he;   /* the kept triangles' half-edges (with
                         * ST_EDGES_DUPLICATES: every non-degenerate
                         * triangle's), sorted by key, ties by triangle */
    size_t nhalf;
    uint32_t *piece;    /* ntris: smallest triangle of t's piece (t itself
                         * for a triangle left out) */
} st_soup_edges;

/* Options of st_soup_edges_build_opts. */
#define ST_EDGES_DUPLICATES 1u   /* duplicates keep their half-edges */

/* ST_ENOMEM, ST_ELIMIT (more than 2^31 triangles). On failure *e is
 * zeroed and holds nothing to free. */
st_status st_soup_edges_build(st_soup_edges *e, const st_soup *s, st_error *err);
/* The same with options (flags: 0 or ST_EDGES_DUPLICATES). */
st_status st_soup_edges_build_opts(st_soup_edges *e, const st_soup *s, unsigned flags,
                                   st_error *err);

/* The edges are the runs of e->he with equal keys: the run starting at
 * half-edge i ends before st_soup_edges_run_end(e, i). */
size_t st_soup_edges_run_end(const st_soup_edges *e, size_t i);

/* The corner of triangle t (0, 1 or 2) at welded point w, or -1. */
int st_soup_edges_corner(const st_soup_edges *e, const st_soup *s, uint32_t t, uint32_t w);
void st_soup_edges_free(st_soup_edges *e);

/* 1 when triangle t of s runs along its edge from welded end a to welded
 * end b (a -> b as consecutive corners), 0 when b -> a. */
int st_soup_edges_forward(const st_soup_edges *e, const st_soup *s, uint32_t t,
                          uint32_t a, uint32_t b);

/* Each kept triangle's manifold neighbours: nbr[3t..3t+3) gets the
 * triangles across t's edges of exactly two triangles (ST_EDGES_NONE in
 * the unused slots), same[] 1 where the two run along that edge the same
 * way (one must be flipped to agree). open[piece] (if not NULL, indexed
 * by piece root, zeroed by the caller) is set for a piece with an edge of
 * one, or of three or more, triangles. nbr and same hold 3 ntris. */
#define ST_EDGES_NONE UINT32_MAX
void st_soup_edges_neighbours(const st_soup_edges *e, const st_soup *s, uint32_t *nbr,
                              uint8_t *same, uint8_t *open);

/* Orientable regions by propagation over nbr and same (from
 * st_soup_edges_neighbours): breadth first from each kept triangle not
 * yet reached, in index order, flip[t] (0 or 1: t is to be turned) such
 * that neighbours agree; a conflict (an edge the propagation already
 * oriented the other way) is left where it is found. region[t] (may be
 * NULL) gets the first triangle of t's region; queue (ntris) gets the
 * kept triangles region by region, each region's contiguous, in the
 * order reached. flip[t] is 2 for triangles not kept. Returns the number
 * of conflicts; *nkept (may be NULL) gets the kept triangles in queue. */
size_t st_soup_edges_orient(const st_soup_edges *e, const st_soup *s, const uint32_t *nbr,
                            const uint8_t *same, uint8_t *flip, uint32_t *region,
                            uint32_t *queue, size_t *nkept);

#ifdef __cplusplus
}
#endif
#endif
