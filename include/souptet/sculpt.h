/*
 * sculpt.h - Cetra's sculpting of a BCC lattice, made exact, with bomb
 * repair by whole snowflakes (Stuart, Levine, Jones, Bargteil 2013,
 * section 3.2).
 *
 * Units: model units (h, the lattice's); counts of tets.
 * Ownership: the caller owns *out (st_tetmesh_free); the lattice, field and
 * soup are borrowed.
 * Threads: classification in parallel, repair sequential: deterministic for
 * any thread count (below).
 * Errors: ST_EINPUT (bad parameters), ST_ENOMEM, ST_ECANCELLED (the cancel
 * flag), and what lattice.h returns; no mesh on error.
 *
 * Keep rule. A lattice tet is kept when it overlaps the pseudo volume of
 * the signed field - a voxel centre inside the pseudo volume (value < 0)
 * lies in the closed tet, or a corner of the tet lies in an inside voxel -
 * or when it meets an input triangle (st_tri_tet_intersect, exact, with a
 * BVH over the soup to find candidates). So every input triangle lies in
 * the union of the kept tets by construction: a triangle point lies in some
 * lattice tet (the lattice covers the box), and that tet meets the
 * triangle. This replaces the paper's three tests, which miss a triangle
 * that crosses a tet without touching its edges or holding a vertex.
 *
 * Bombs. A kept tet with two or more faces on the boundary of the kept set
 * flattens into a sliver when the boundary is pulled onto the surface.
 * Repair adds back whole snowflakes (the 24 tets around a BCC vertex, or
 * the star of any lattice vertex): see sculpt.c for why the four vertices
 * of a bomb are its candidates, why adding snowflakes never creates a bomb,
 * and how the choice is searched. Tets with three or four boundary faces
 * (nearly isolated and isolated tets, kept because a stray triangle or a
 * speck of pseudo volume touches them) are bombs too and repaired the same
 * way; they are counted apart.
 *
 * Manifold boundary. Later smoothing (tetsmooth --fit) needs a manifold
 * boundary. After bomb repair every boundary vertex whose boundary faces do
 * not form one disc (a pinch where two parts touch at a vertex, or an edge
 * on four boundary faces) gets its whole snowflake added, which makes it an
 * interior vertex; this is repeated (it can expose new pinches nearby, and
 * never creates a bomb) up to ST_SCULPT_MANIFOLD_ROUNDS times, and what is
 * left is reported.
 *
 * Everything is deterministic: classification runs in parallel (OpenMP)
 * per tet, repair sequentially in lattice order.
 */
#ifndef SOUPTET_SCULPT_H
#define SOUPTET_SCULPT_H

#include <stddef.h>
#include <stdint.h>

#include "souptet/bvh.h"
#include "souptet/err.h"
#include "souptet/grid.h"
#include "souptet/lattice.h"
#include "souptet/soup.h"
#include "souptet/tetmesh.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Why a tet is in the result: the values of keep[] and of the per-cell
 * array "sculpt" of the output mesh. */
enum {
    ST_SCULPT_REMOVED = 0,
    ST_SCULPT_VOLUME = 1,     /* overlaps the pseudo volume */
    ST_SCULPT_SURFACE = 2,    /* meets an input triangle (and not the volume) */
    ST_SCULPT_BOMB = 3,       /* added by bomb repair */
    ST_SCULPT_MANIFOLD = 4    /* added to make the boundary manifold */
};

#define ST_SCULPT_MANIFOLD_ROUNDS 8

typedef struct st_sculpt_params {
    st_lattice_kind kind;     /* ST_LATTICE_BCC (the paper's) */
    double h;                 /* cell width, > 0 */
    uint64_t seed;            /* lattice rotation and offset (0: none) */
    int pad;                  /* lattice padding, >= 2 for whole snowflakes */
    size_t max_tets;          /* lattice size limit (0: none) */
    int repair_bombs;         /* 1: repair bombs (default) */
    int repair_manifold;      /* 1: add snowflakes at pinched vertices */
    size_t cluster_max;       /* bombs per cluster searched at all (64) */
    size_t search_budget;     /* search nodes per cluster (1 << 20) */
    int search_memo;          /* 1: replay searched subtrees from a memo
                                 (the same choice and node count as
                                 without, fewer nodes expanded; default) */
    volatile int *cancel;     /* NULL, or a caller's flag (progress.h):
                                 once nonzero, st_sculpt stops between
                                 its steps and within the classification,
                                 returning ST_ECANCELLED (NULL) */
} st_sculpt_params;

/* BCC, h 1, seed 0, pad ST_LATTICE_PAD_DEFAULT, repairs on. */
st_sculpt_params st_sculpt_params_default(void);

typedef struct st_sculpt_stats {
    size_t lattice_tets;      /* tets in the lattice */
    size_t kept_volume;       /* kept: overlap the pseudo volume */
    size_t kept_surface;      /* kept: meet a triangle (and not the volume) */
    size_t bombs;             /* bombs before repair (>= 2 boundary faces) */
    size_t bombs_3faces;      /*   of which with 3 boundary faces */
    size_t bombs_4faces;      /*   of which isolated (4 boundary faces) */
    size_t clusters;          /* clusters of interacting bombs */
    size_t clusters_exact;    /*   searched to the proven optimum */
    size_t clusters_greedy;   /*   too large: best of greedy and a bounded
                                   search, not proven optimal */
    size_t largest_cluster;   /* bombs in the largest cluster */
    size_t snowflakes;        /* snowflakes added for bombs */
    size_t bomb_tets;         /* tets added for bombs */
    size_t greedy_tets;       /* what the greedy choice (each bomb in turn,
                                 its cheapest snowflake) would have added */
    size_t search_nodes;      /* search nodes counted against the budgets
                                 (the same with and without the memo) */
    size_t search_expanded;   /*   of which expanded (the rest replayed) */
    size_t repair_rounds;     /* rounds of bomb repair (1 when it works) */
    size_t bombs_left;        /* bombs after repair (0 unless repair is off
                                 or a bomb had no complete snowflake) */
    size_t nonmanifold_vertices;  /* after bomb repair, before manifold fix */
    size_t nonmanifold_edges;
    size_t manifold_tets;     /* tets added to fix them */
    size_t nonmanifold_vertices_left, nonmanifold_edges_left;
    size_t tets;              /* tets in the result */
    double t_lattice, t_classify, t_repair, t_mesh;   /* seconds */
} st_sculpt_stats;

/* The keep rule above for every lattice tet: keep[t] (L->ntets slots) is
 * ST_SCULPT_VOLUME, ST_SCULPT_SURFACE or ST_SCULPT_REMOVED. g must be a
 * signed field; s (and bvh, which may be NULL: built here) may be NULL for
 * the volume alone. stats may be NULL (fills kept_volume, kept_surface,
 * lattice_tets). */
st_status st_sculpt_classify(unsigned char *keep, st_sculpt_stats *stats,
                             const st_lattice *L, const st_grid *g,
                             const st_soup *s, const st_bvh *bvh,
                             st_error *err);

/* hist[k] = kept tets (keep[t] != 0) with k faces on the boundary of the
 * kept set, k = 0..4. Returns the number of bombs (hist[2..4]). */
size_t st_sculpt_count_bombs(const st_lattice *L, const unsigned char *keep,
                             size_t hist[5]);

/* Repair every bomb by adding snowflakes (keep[t] = ST_SCULPT_BOMB for the
 * tets added), choosing per cluster the combination that adds the fewest
 * tets (see sculpt.c). Fills the bomb fields of stats (may be NULL). */
st_status st_sculpt_repair_bombs(unsigned char *keep, st_sculpt_stats *stats,
                                 const st_lattice *L,
                                 const st_sculpt_params *p, st_error *err);

/* Count the boundary vertices whose boundary faces are not one disc, and
 * the boundary edges on more than two boundary faces. */
st_status st_sculpt_count_nonmanifold(const st_lattice *L,
                                      const unsigned char *keep,
                                      size_t *vertices, size_t *edges,
                                      st_error *err);

/* Add the snowflakes of non-manifold boundary vertices (keep[t] =
 * ST_SCULPT_MANIFOLD), repeating up to ST_SCULPT_MANIFOLD_ROUNDS times.
 * Fills the manifold fields of stats (may be NULL). */
st_status st_sculpt_repair_manifold(unsigned char *keep,
                                    st_sculpt_stats *stats,
                                    const st_lattice *L, st_error *err);

/* The whole of sculpting in one call (what soupmesh uses): build the
 * lattice over the grid's box (st_lattice_grid_box) with p, classify,
 * repair bombs and the boundary, and return the kept tets as a mesh with
 * the per-cell array "sculpt" (the reason codes above) and meta "h",
 * "lattice", "seed", "bombs". g must be signed; s may be NULL (volume
 * only); bvh may be NULL (built from s). stats may be NULL. */
st_status st_sculpt(st_tetmesh **out, st_sculpt_stats *stats,
                    const st_grid *g, const st_soup *s, const st_bvh *bvh,
                    const st_sculpt_params *p, st_error *err);

#ifdef __cplusplus
}
#endif
#endif
