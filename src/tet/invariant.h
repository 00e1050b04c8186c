/*
 * invariant.h - the fit's move invariant (private; invariant.c): what a
 * vertex move must keep so that the mesh keeps enclosing the surface S
 * (Stuart et al. 2013, section 3.3, decided here by exact tests instead of
 * El Topo's collision detection), and the distances to S the fit (fit.c)
 * and the quality pass (quality.c) measure against. Design notes:
 * doc/design/fit.md.
 *
 * Units: the mesh's and S's (one space); h the lattice cell width,
 *   d_offset the band's width.
 * Ownership: fit_ctx borrows the mesh (moved in place), S, the BVHs given
 *   to it and the fill; it owns the incidence, the point grid, the BVHs it
 *   builds and its per-vertex arrays (sm_fit_ctx_close). star_pts and
 *   dirty own their arrays (freed by their users).
 * Threads: sm_move_ok reads the mesh and writes only v's own slots
 *   (blocker[v], *sp): vertices of one colour (smooth_mesh.h) may be
 *   checked and moved at once, one star_pts per thread. The distance
 *   queries read only.
 * Errors: sm_fit_ctx_open returns ST_ENOMEM or the BVH's or the tet
 *   neighbours' status (err set); sm_dirty_init ST_ENOMEM (err not set:
 *   its caller says which pass ran out). The checks cannot fail: out of
 *   memory while gathering a star refuses the move.
 */
#ifndef SOUPTET_INVARIANT_H
#define SOUPTET_INVARIANT_H

#include <stddef.h>
#include <stdint.h>

#include "pgrid.h"
#include "smooth_mesh.h"

#include "souptet/bvh.h"
#include "souptet/err.h"
#include "souptet/progress.h"
#include "souptet/smooth.h"
#include "souptet/soup.h"
#include "souptet/tetmesh.h"

typedef struct fit_ctx {
    sm_mesh sm;
    const st_soup *s;    /* S, or NULL: no surface (the quality pass after
                            fairing) */
    const st_bvh *bvh;
    const st_bvh *fbvh;  /* the fill's (st_fit_params.fill), or NULL:
                            distances are to S or it (sm_nearest_d2) */
    const pgrid *pg;     /* S's vertices in bins: own_pg, or the shared
                            set-up's (st_fit_shared) */
    double *dpos;        /* per vertex: where its distance in dist[] was
                            taken (3 each; NaN: not yet) */
    uint32_t *blocker;   /* per vertex: the S vertex that last stopped its
                            move (a point grid index), or UINT32_MAX */
    uint32_t *tblocker;  /* per vertex: the S triangle that a boundary face
                            of its star last newly met, or UINT32_MAX */
    double h, d_offset;
    int full_check;   /* non-conforming faces: test S vertices everywhere */
    int cube_steps;      /* the quality pass also tries the 26 cube
                            directions (quality.c; st_fit's last pass) */
    int fair_boundary;   /* no S (after fairing): boundary vertices move in
                            their tangent plane only (sm_quality_fair) */
    const st_progress *prog;   /* its cancel flag stops the fit between
                                  iterations and rounds (may be NULL) */
    sm_par_gate *gate;   /* the small loops' team gate (&own_gate, or NULL:
                            PAR_CHECKED alone) */
    sm_par_gate own_gate;
    st_bvh *own_bvh, *own_fbvh;   /* the BVHs sm_fit_ctx_open built */
    pgrid own_pg;                 /* the point grid it built */
} fit_ctx;

/* st_fit_shared (smooth.h): what sm_fit_ctx_open builds from S, the fill
 * and h alone, and what it was built from (st_fit checks them). */
struct st_fit_shared {
    const st_soup *s, *fill;
    double h;
    st_bvh *fbvh;        /* the fill's, or NULL (no fill or no triangles) */
    pgrid pg;            /* S's vertices in bins of h / 4 */
};

/* The invariant of fitting m (positively oriented, with tets) to s (with
 * triangles) in c: m's incidence, s's BVH (bvh, or built when NULL), the
 * fill's (none when fill is NULL or empty), full_check (m has a face of
 * three tets or more), the point grid (bins of h / 4), the blockers and
 * distance positions (none yet). sh (may be NULL; made from s, fill and h)
 * gives the fill's BVH and the point grid instead of building them. ST_OK,
 * or the failure (err set); either way sm_fit_ctx_close frees c. */
st_status sm_fit_ctx_open(fit_ctx *c, st_tetmesh *m, const st_soup *s, const st_bvh *bvh,
                          const st_soup *fill, const st_fit_shared *sh, double h,
                          double d_offset, const st_progress *prog, st_error *err);
void sm_fit_ctx_close(fit_ctx *c);

/* Which vertices can be skipped: a vertex move is a deterministic function
 * of the vertex's position and its neighbours' (its star), so a vertex
 * that was tried and did not move, with nothing in its star moved since,
 * would not move again; skipping it changes no result. Steps count colour
 * sets; a vertex and its neighbours never share a colour, so during a
 * colour step no vertex reads a stamp being written. */
typedef struct dirty {
    uint32_t *moved_at;   /* step of the last move (0: never) */
    uint32_t *tried_at;   /* step of the last attempt that did not move */
    uint32_t *todo;       /* a colour step's vertices to try (sm_dirty_todo) */
    uint32_t step;
} dirty;

/* ST_OK, or ST_ENOMEM (err not set); sm_dirty_free frees d either way. */
st_status sm_dirty_init(dirty *d, size_t nv);
void sm_dirty_free(dirty *d);
/* 1 when an attempt to move v would repeat one that did not move. */
int sm_dirty_unchanged(const dirty *d, const sm_mesh *sm, uint32_t v);
void sm_dirty_mark(dirty *d, uint32_t v, int moved);
/* The vertices of colour col worth an attempt at this step, in colour
 * order, into d->todo: those with mark[v] (every one when mark is NULL)
 * that sm_dirty_unchanged does not skip; their count. A colour's vertices
 * share no edge, so an attempt in the colour changes no other's answer:
 * the list is the one the colour step would find vertex by vertex, and
 * its length, not the colour's, is the work a parallel region holds. */
size_t sm_dirty_todo(dirty *d, const sm_mesh *sm, size_t col, const unsigned char *mark);

/* An S vertex in a star and the star tet that held it. */
typedef struct star_pt {
    uint32_t pt;     /* index into the point grid */
    uint32_t tet;    /* index from vt_off[v] */
} star_pt;

/* The scratch list of S vertices in a star (one per thread and call;
 * STAR_PTS_INIT, and free(list) after). */
typedef struct star_pts {
    star_pt *list;
    size_t n, cap;
    int ok;          /* 0: out of memory, refuse every move */
    int have;        /* 1: list holds the star of v as it is */
    int positive;    /* the star as it is: every tet positive */
    uint32_t v;
    int swept;       /* 1: no list; moves are checked by sm_swept_kept */
    uint32_t bq;     /* the blocker (fit_ctx.blocker) whose place in the
                        star as it is bt holds, or UINT32_MAX: none yet */
    ptrdiff_t bt;    /* its tet (from vt_off[v]), -1: outside the star */
} star_pts;
#define STAR_PTS_INIT {NULL, 0, 0, 1, 0, 0, 0, 0, UINT32_MAX, -1}

/* Start the moves of v (the list of S vertices is filled when a move
 * first needs it). */
void sm_star_pts_collect(const fit_ctx *c, uint32_t v, star_pts *sp);
/* The whole invariant for moving v to p (invariant.c's header comment):
 * 1 when the move keeps it. */
int sm_move_ok(const fit_ctx *c, uint32_t v, const double p[3], star_pts *sp);

/* The squared distance from p to S or the fill, whichever is nearer,
 * among those closer than sqrt(max_d2) (st_bvh_nearest's contract: max_d2
 * and *found -1 when none is; else *found >= 0). closest may be NULL. */
double sm_nearest_d2(const fit_ctx *c, const double p[3], double max_d2,
                     int64_t *found, double closest[3]);
/* The distance from p to S (or the fill); closest (may be NULL) gets the
 * nearest point. */
double sm_dist_to_s(const fit_ctx *c, const double p[3], double closest[3]);

typedef struct fit_counts {
    size_t moved, rejected, skipped;
} fit_counts;

typedef struct dist_summary {
    size_t within;
    double max, mean;
} dist_summary;

/* Every boundary vertex's distance to S into dist[] (0 for the interior). */
dist_summary sm_boundary_distances(const fit_ctx *c, double *dist);
/* Tell p->on_iter (when set) how the fit stands. */
void sm_fit_report(const st_fit_params *p, const fit_ctx *c, const char *phase,
                   int iter, const dist_summary *ds, const fit_counts *n, double t0);

#endif
