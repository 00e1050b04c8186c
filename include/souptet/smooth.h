/*
 * smooth.h - moving the vertices of a tet mesh: Spillmann's volume-keeping
 * boundary fairing, and Cetra's enclosing vertex adjustment followed by a
 * quality pass.
 *
 * Units: model units (h, offsets, distances); angles in degrees.
 * Ownership: the mesh is changed in place and stays the caller's; soups,
 * fields and BVHs are borrowed.
 * Threads: OpenMP over independent sets; deterministic for any thread
 * count; no global state (below).
 * Errors: ST_EINPUT (an inverted or flat tet, bad parameters), ST_ENOMEM,
 * ST_ECANCELLED; on error the mesh may hold moves already accepted, each of
 * which kept the invariant.
 *
 * st_fair (Spillmann, Wagner, Teschner 2006, section 4): implicit fairing
 * of the boundary surface (Desbrun et al. 1999), a local rescale along the
 * vertex normals so the mesh keeps its volume, interior vertices carried
 * along and relaxed.
 *
 * st_fit (Stuart, Levine, Jones, Bargteil 2013, section 3.3): every vertex
 * moves toward the volume-weighted mean of the circumcenters of its tets
 * (ODT), boundary vertices also toward the surface S, until every boundary
 * vertex is within d_offset = offset_ratio * h of S; then a quality pass
 * that raises the worst dihedral angles. Throughout, the mesh keeps
 * enclosing S: after every accepted move every vertex of S that was inside
 * the mesh still is, no boundary triangle that did not meet a triangle of S
 * does, and every tet is positively oriented - all decided by the exact
 * predicates (pred.h, isect.h). A move that would break it is halved a few
 * times, then skipped. Boundary vertices the fit leaves beyond d_offset
 * (held by the invariant in thin gaps and at sharp features) get a rescue:
 * steps in other directions that still bring them closer to S, under the
 * same invariant; once after the fit, then after the quality pass (and the
 * quality pass again), see fit.c. Last, peeling (st_fit_params.peel):
 * boundary tets below the quality goal that hold no part of S, and were
 * not sculpted for the pseudo volume, are removed where the boundary stays
 * a manifold; so st_fit may leave fewer tets than it was given (never
 * more, and the points stay).
 *
 * Both require every tet of the input to be positively oriented (tetmesh.h)
 * and refuse the mesh otherwise; both never produce an inverted or flat tet.
 * Vertices move in a fixed order (independent sets of a greedy colouring,
 * each set in parallel), so the result does not depend on the thread count.
 * No global state: calls on different meshes may run concurrently.
 */
#ifndef SOUPTET_SMOOTH_H
#define SOUPTET_SMOOTH_H

#include <stddef.h>

#include "souptet/bvh.h"
#include "souptet/err.h"
#include "souptet/progress.h"
#include "souptet/soup.h"
#include "souptet/tetmesh.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ---- fairing (st_fair) ------------------------------------------------ */

typedef struct st_fair_params {
    int iters;            /* fairing steps (default 3) */
    double lambda_dt;     /* lambda*dt of each implicit step, for the
                             uniform-weight (umbrella) graph Laplacian
                             L = D - W of the boundary edges (default 1) */
    int relax_iters;      /* ODT relaxation sweeps of the interior vertices
                             after each step (default 3) */
    double volume_tol;    /* relative volume change allowed (default 0.005);
                             the rescale aims much closer than this */
    double min_angle;     /* degrees: no move brings the score of its star
                             (ST_FIT_MAX_WEIGHT below) under this, or under
                             what it already was (default 30: angles in
                             [30, 140]) */
    int quality_rounds;   /* then rounds of st_fit's quality pass on the
                             interior vertices (the volume does not change);
                             0: none (default 40) */
    int boundary_quality; /* 1: the quality pass moves boundary vertices
                             too, within their tangent plane, and the
                             volume is rescaled after it (default 1) */
} st_fair_params;

typedef struct st_fair_stats {
    int iters;                    /* fairing steps done */
    double volume_before, volume_after;
    size_t moves, backoffs;       /* vertex moves accepted; halvings taken */
    size_t stuck;                 /* moves backed off to zero (all steps) */
    size_t boundary_vertices;
    size_t quality_moves;         /* moves of the quality pass */
    double min_dihedral_before, max_dihedral_before;
    double min_dihedral_fair, max_dihedral_fair;    /* before the quality pass */
    double min_dihedral_after, max_dihedral_after;
    double seconds;
} st_fair_stats;

st_fair_params st_fair_params_default(void);

/* Fair the boundary of m in place. Fails (ST_EINPUT) on a mesh with
 * inverted or flat tets or without tets, and when the volume could not be
 * kept within p->volume_tol (m is then left as the last valid state, every
 * tet still positive; stats say how far it got). stats and prog may be
 * NULL; p NULL means the defaults. */
st_status st_fair(st_tetmesh *m, const st_fair_params *p,
                  st_fair_stats *stats, const st_progress *prog,
                  st_error *err);

/* ---- enclosing fit (st_fit) ------------------------------------------- */

/* What the fit reports after each iteration (and each quality round). */
typedef struct st_fit_iter {
    const char *phase;            /* "fit" or "quality" */
    int iter;                     /* 1-based within the phase */
    size_t boundary_vertices;
    size_t within_offset;         /* boundary vertices within d_offset */
    double max_distance;          /* largest boundary-vertex distance to S */
    double min_dihedral, max_dihedral;
    size_t moved, rejected;       /* vertex moves accepted / halvings taken */
    double seconds;               /* since st_fit started */
} st_fit_iter;

typedef void (*st_fit_iter_fn)(void *ctx, const st_fit_iter *it);

/* A fit's shared set-up (st_fit_shared_new). */
typedef struct st_fit_shared st_fit_shared;

typedef struct st_fit_params {
    double offset_ratio;   /* d_offset = offset_ratio * h (default 0.4) */
    double cell_width;     /* h; 0: the mesh's meta "h" (default 0) */
    double step;           /* tau, fraction of the way to the target per
                              iteration, in (0, 1] (default 0.5) */
    int max_iters;         /* fit iterations at most (default 300) */
    int quality;           /* run the quality pass (default 1) */
    int quality_rounds;    /* quality rounds at most (default 40) */
    double quality_goal;   /* degrees: the pass works on tets whose min
                              dihedral is below this or whose max is above
                              180 - goal / ST_FIT_MAX_WEIGHT (default 35) */
    int peel;              /* 1: after the quality pass, remove boundary
                              tets scoring below quality_goal that hold no
                              part of S, where the boundary stays a manifold
                              (fit.c); the tet count may drop (default 1) */
    const st_soup *fill;   /* where the surface S has none, what counts as
                              surface for the stopping condition and the
                              pull: the distance of a boundary vertex is to
                              S or the fill, whichever is nearer (the
                              pseudo volume's fill, st_pseudo_fill). The
                              mesh still encloses S alone. NULL: none
                              (default NULL) */
    const st_fit_shared *shared;
                           /* what st_fit would otherwise build from S, the
                              fill and h alone (st_fit_shared_new), made
                              once for several fits of meshes to the same
                              S (the pipeline's candidates); it must have
                              been made from this s, fill and cell width
                              (ST_EINPUT otherwise). NULL: st_fit builds
                              its own (default NULL) */
    int count_before;      /* 1: count the enclosure on entry into the
                              stats' *_before (an exact pass over S, as
                              long as the one after); 0: skip it, the
                              counts read 0 (the pipeline's sculpted
                              meshes, checked after the fit anyway)
                              (default 1) */
    st_fit_iter_fn on_iter;   /* called after every iteration; may be NULL */
    void *on_iter_ctx;
} st_fit_params;

/* The quality score of a tet is min(min dihedral, ST_FIT_MAX_WEIGHT *
 * (180 - max dihedral)): with the weight 0.75, a tet that scores 30 has
 * its angles in [30, 140], the project's target. */
#define ST_FIT_MAX_WEIGHT 0.75

typedef struct st_fit_stats {
    double h, d_offset;
    int iters;                    /* fit iterations done */
    int converged;                /* 1: every boundary vertex within d_offset */
    size_t boundary_vertices;
    size_t within_offset;         /* at the end */
    size_t beyond_offset;         /* boundary vertices that did not get there */
    double max_distance;          /* largest boundary-vertex distance to S */
    double mean_distance;
    size_t moves, rejected, skipped;  /* fit: accepted, halvings, given up */
    int quality_rounds;
    size_t quality_moves;
    size_t peeled;                /* tets removed by peeling */
    double min_dihedral_before, max_dihedral_before;   /* the input */
    double min_dihedral_fit, max_dihedral_fit;         /* after the fit */
    double min_dihedral_after, max_dihedral_after;     /* after quality */
    /* Enclosure of S, counted over the whole mesh before (unless
     * !count_before) and after (exact): S vertices outside the mesh, S
     * triangles meeting a boundary face. */
    size_t outside_before, crossing_before;
    size_t outside_after, crossing_after;
    double seconds_fit, seconds_quality;
} st_fit_stats;

st_fit_params st_fit_params_default(void);

/* The part of a fit's set-up that depends only on the surface s, the fill
 * (st_fit_params.fill, may be NULL) and the cell width h > 0: the fill's
 * BVH and the grid of S's vertices. Built once, it serves any number of
 * st_fit calls with these s, fill and h, at once too (read-only); a fit
 * given it runs exactly as one that built its own. s and fill are
 * borrowed and must outlive it. ST_OK, ST_EINPUT (no triangles, bad h) or
 * ST_ENOMEM; *out NULL on failure. st_fit_shared_free is safe on NULL. */
st_status st_fit_shared_new(st_fit_shared **out, const st_soup *s, const st_soup *fill,
                            double h, st_error *err);
void st_fit_shared_free(st_fit_shared *sh);

/* Fit m in place to the surface s. bvh is a BVH over s (NULL: st_fit
 * builds one). The mesh need not enclose s on entry: what holds on entry
 * (each S vertex inside, each boundary face clear of S) keeps holding,
 * and stats report the global counts before and after. Fails with
 * ST_EINPUT on inverted or flat tets, a mesh without tets, or no cell
 * width (neither p->cell_width nor a meta "h" > 0); ST_ENOMEM when out of
 * memory, the quality pass's memory included (never a silently skipped
 * pass). Not converging is not an error: stats->converged says it (of the
 * final mesh, after the quality pass). stats and prog may be NULL. */
st_status st_fit(st_tetmesh *m, const st_soup *s, const st_bvh *bvh,
                 const st_fit_params *p, st_fit_stats *stats,
                 const st_progress *prog, st_error *err);

#ifdef __cplusplus
}
#endif
#endif
