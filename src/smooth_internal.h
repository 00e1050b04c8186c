/*
 * smooth_internal.h - what fair.c, fit.c and quality.c share (not public):
 * the mesh's incidence (vertex -> tets, vertex -> vertices, boundary faces),
 * a colouring of the vertices into independent sets, and the local checks
 * a vertex move must pass.
 */
#ifndef SOUPTET_SMOOTH_INTERNAL_H
#define SOUPTET_SMOOTH_INTERNAL_H

#include <stddef.h>
#include <stdint.h>

#include "souptet/bvh.h"
#include "souptet/err.h"
#include "souptet/smooth.h"
#include "souptet/soup.h"
#include "souptet/tetmesh.h"

/* When a loop is worth a parallel region: each region costs a barrier,
 * and on a loaded machine a barrier among spinning threads costs
 * milliseconds (fairing the bunny at 12 cells took 14 s on 2 threads under
 * load, 0.5 s on one), so small colour sets run serially. The thresholds
 * are items per region for cheap items (a few flops), vertex moves (a star
 * of ~20 tets) and checked moves (exact tests against the surface). The
 * result does not depend on them. */
#define PAR_CHEAP(n) ((n) > 8192)
#define PAR_MOVES(n) ((n) > 512)
#define PAR_CHECKED(n) ((n) > 64)

typedef struct sm_mesh {
    st_tetmesh *m;            /* borrowed; xyz is moved in place */
    size_t nv, nt;
    size_t *vt_off;           /* vertex -> incident tets (CSR, nv + 1) */
    uint32_t *vt;
    size_t *vv_off;           /* vertex -> edge neighbours (CSR) */
    uint32_t *vv;
    uint32_t *bf;             /* boundary faces, 3 each, outward */
    size_t nbf;
    size_t *vf_off;           /* vertex -> boundary faces (CSR) */
    uint32_t *vf;
    unsigned char *onb;       /* 1 for a boundary vertex */
    size_t nbv;               /* boundary vertex count */
    size_t *bv_off;           /* boundary vertex -> boundary edge nbrs */
    uint32_t *bv;
    size_t ncolours;          /* vertices grouped by colour: a colour set */
    size_t *col_off;          /* shares no tet, so its vertices can move */
    uint32_t *col_v;          /* at once (ncolours + 1 offsets) */
} sm_mesh;

/* Build the incidence of m (which must have tets). */
st_status sm_mesh_build(sm_mesh *sm, st_tetmesh *m, st_error *err);
void sm_mesh_free(sm_mesh *sm);

/* Count tets that are not positively oriented (exact). */
size_t sm_count_nonpositive(const st_tetmesh *m);

/* 1 when every tet of v's star is positively oriented (exact) with v at p. */
int sm_star_positive(const sm_mesh *sm, uint32_t v, const double p[3]);

/* The score of a tet: min(min dihedral, ST_FIT_MAX_WEIGHT * (180 - max)). */
double sm_tet_score(const double *a, const double *b, const double *c,
                    const double *d);
/* The lowest tet score of v's star with v at p. */
double sm_star_score(const sm_mesh *sm, uint32_t v, const double p[3]);

/* Min and max dihedral over all tets (parallel, deterministic). */
void sm_dihedral_range(const st_tetmesh *m, double *mind, double *maxd);

/* The volume-weighted mean of the circumcenters of v's tets (ODT target,
 * Alliez et al. 2005); v's position when its star has no volume. */
void sm_odt_target(const sm_mesh *sm, uint32_t v, double out[3]);

/* The volume enclosed by the boundary faces (divergence theorem) with the
 * points at xyz (3 per mesh point): the mesh volume, for a conforming mesh. */
double sm_boundary_volume(const sm_mesh *sm, const double *xyz);

/* The quality pass of st_fit (quality.c) without a surface: only interior
 * vertices move, so the volume stays exactly as it is; h scales the trial
 * steps. *moves gets the number of moves. ST_OK, or ST_ENOMEM (nothing
 * moved). */
st_status sm_quality_interior(sm_mesh *sm, double h, int rounds, double goal,
                              size_t *moves, st_error *err);
/* The same pass with the boundary vertices too, each only in the plane
 * across its boundary faces' area-weighted normal (the volume's gradient
 * in it: first-order volume kept). As sm_quality_interior otherwise. */
st_status sm_quality_fair(sm_mesh *sm, double h, int rounds, double goal, size_t *moves,
                          st_error *err);

/* ---- the fit's invariant (fit.c), shared with the quality pass ---- */

/* The vertices of S in bins (fit.c builds it). */
typedef struct pgrid {
    double *pts;          /* distinct vertices of S, 3 each */
    size_t npts;
    double lo[3], cell;
    size_t n[3];
    size_t *off;          /* bin -> points (CSR) */
    uint32_t *idx;
    double *bpts;         /* the points in bin order: bpts + 3 j is
                             pts + 3 idx[j] (fit_swept.c's scans) */
} pgrid;

typedef struct fit_ctx {
    sm_mesh sm;
    const st_soup *s;
    const st_bvh *bvh;
    const st_bvh *fbvh;  /* the fill's (st_fit_params.fill), or NULL:
                            distances are to S or it (sm_nearest_d2) */
    pgrid pg;
    double *dpos;        /* per vertex: where its distance in dist[] was
                            taken (3 each; NaN: not yet) */
    uint32_t *blocker;   /* per vertex: the S vertex that last stopped its
                            move (a point grid index), or UINT32_MAX */
    double h, d_offset;
    int full_check;   /* non-conforming faces: test S vertices everywhere */
    int joint;           /* rescue_pass also moves a held vertex's boundary
                            neighbours first (fit.c, rescue_joint) */
    int cube_steps;      /* the quality pass also tries the 26 cube
                            directions (quality.c; st_fit's last pass) */
    int fair_boundary;   /* no S (after fairing): boundary vertices move in
                            their tangent plane only (sm_quality_fair) */
    const st_progress *prog;   /* its cancel flag stops the fit between
                                  iterations and rounds (may be NULL) */
} fit_ctx;

/* Which vertices can be skipped: a vertex move is a deterministic function
 * of the vertex's position and its neighbours' (its star), so a vertex
 * that was tried and did not move, with nothing in its star moved since,
 * would not move again; skipping it changes no result. Steps count colour
 * sets; a vertex and its neighbours never share a colour, so during a
 * colour step no vertex reads a stamp being written. */
typedef struct dirty {
    uint32_t *moved_at;   /* step of the last move (0: never) */
    uint32_t *tried_at;   /* step of the last attempt that did not move */
    uint32_t step;
} dirty;

int sm_dirty_init(dirty *d, size_t nv);   /* 0, or -1 out of memory */
void sm_dirty_free(dirty *d);
/* 1 when an attempt to move v would repeat one that did not move. */
int sm_dirty_unchanged(const dirty *d, const sm_mesh *sm, uint32_t v);
void sm_dirty_mark(dirty *d, uint32_t v, int moved);

/* An S vertex in a star and the star tet that held it. */
typedef struct star_pt {
    uint32_t pt;     /* index into the point grid */
    uint32_t tet;    /* index from vt_off[v] */
} star_pt;

/* The scratch list of S vertices in a star (one per thread and call). */
typedef struct star_pts {
    star_pt *list;
    size_t n, cap;
    int ok;          /* 0: out of memory, refuse every move */
    int have;        /* 1: list holds the star of v as it is */
    int positive;    /* the star as it is: every tet positive */
    uint32_t v;
    int swept;       /* 1: no list; moves are checked by sm_swept_kept */
} star_pts;

/* Start the moves of v (the list of S vertices is filled when a move
 * first needs it). */
void sm_star_pts_collect(const fit_ctx *c, uint32_t v, star_pts *sp);
/* The whole invariant for moving v to p (fit.c's header comment). */
int sm_move_ok(const fit_ctx *c, uint32_t v, const double p[3], star_pts *sp);
/* The bin of coordinate x along axis a of the point grid. */
size_t sm_pgrid_coord(const pgrid *g, double x, int a);
/* 1 when sm_swept_kept may decide v's moves (at most as many boundary
 * faces as it handles). */
int sm_swept_applies(const fit_ctx *c, uint32_t v);
/* For a boundary vertex v of a mesh with no face of three tets, whose star
 * is positive with v where it is and with v at p: 1 when every S vertex in
 * the closed star stays in it with v at p, else 0 with *failed a point grid
 * index that would leave; -1 when it cannot tell (fit_swept.c). Exact. */
int sm_swept_kept(const fit_ctx *c, uint32_t v, const double p[3], uint32_t *failed);
/* The distance from p to S; closest (may be NULL) gets the nearest point. */
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

/* The squared distance from p to S or the fill, whichever is nearer,
 * among those closer than sqrt(max_d2) (st_bvh_nearest's contract: max_d2
 * and *found -1 when none is; else *found >= 0). closest may be NULL. */
double sm_nearest_d2(const fit_ctx *c, const double p[3], double max_d2,
                     int64_t *found, double closest[3]);

/* The quality pass (quality.c) of st_fit on c (c->s NULL: no surface, as
 * sm_quality_interior/sm_quality_fair). ST_OK, or ST_ENOMEM (err set)
 * before any vertex moved. */
st_status sm_quality_pass(fit_ctx *c, const st_fit_params *p, double *dist,
                          st_fit_stats *st, double t0, st_error *err);

/* Monotonic seconds. */
double sm_now(void);

#endif
