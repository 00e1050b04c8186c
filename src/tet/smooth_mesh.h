/*
 * smooth_mesh.h - the mesh the vertex-moving passes work on (private;
 * smooth_mesh.c): a tet mesh's incidence (vertex -> tets, vertex ->
 * vertices, boundary faces), a colouring of its vertices into independent
 * sets, and the scores and exact star checks every pass uses (fair.c,
 * fit.c, quality.c and the fit's invariant, invariant.c).
 *
 * Units: the mesh's; scores and dihedral angles in degrees.
 * Ownership: sm_mesh borrows its st_tetmesh (whose xyz the passes move in
 *   place) and owns its arrays (sm_mesh_free).
 * Threads: the queries read only; vertices of one colour share no tet, so
 *   each may move in parallel while the others' stars stay as they are.
 * Errors: sm_mesh_build returns ST_ENOMEM (err set); the rest cannot fail.
 */
#ifndef SOUPTET_SMOOTH_MESH_H
#define SOUPTET_SMOOTH_MESH_H

#include <stddef.h>
#include <stdint.h>

#include "souptet/err.h"
#include "souptet/tetmesh.h"

/* When a loop is worth a parallel region: each region costs a barrier,
 * and on a loaded machine a barrier among spinning threads costs
 * milliseconds (fairing the bunny at 12 cells took 14 s on 2 threads under
 * load, 0.5 s on one), so small sets of cheap items run serially. The
 * thresholds are items per region for cheap items (a few flops) and
 * vertex moves (a star of ~20 tets). A checked move (exact tests against
 * the surface; the fit's and the quality pass's, counted over the
 * vertices to try, sm_dirty_todo) costs 100k-400k instructions, 30-100 us
 * (callgrind, man at 6 cells), against 1-3 us for a region of 2 hot
 * threads, so two such moves are worth one. A boundary vertex's nearest
 * point on the surface (sm_boundary_distances) costs ~10k-30k
 * instructions when it moved, none when not, so a few dozen boundary
 * vertices are. The result does not depend on them. */
#define PAR_CHEAP(n) ((n) > 8192)
#define PAR_MOVES(n) ((n) > 512)
#define PAR_CHECKED(n) ((n) > 1)
#define PAR_QUERIES(n) ((n) > 32)

/* Whether a loop of few checked moves gets a team, beyond PAR_CHECKED: on
 * a loaded machine a thread of the team can wait a time slice (ms) to
 * run, and one spinning at a barrier loses its slice, so a colour step of
 * a few hundred us takes ms (man at 6 cells, 2 threads under load 18,
 * without the gate: 1.8 s -> 9.3 s). After each region of 2 threads or
 * more, the gate compares its wall time with its threads' summed busy
 * time (the serial estimate): a region that took longer than that by more
 * than the estimate itself and PAR_GATE_SLACK (1 ms, a time slice's
 * order: a thread waited for a core; under callgrind, whose serialized
 * threads make every item ~50 times slower but not the waits, the gate
 * stays open and the per-thread counts show the team's split) closes it
 * for 16 steps, then 32, 64, ... up to 4096 while the probes stay slow; a
 * region faster halves the next wait. It decides thread counts only: no
 * result depends on it. Used by the master thread alone, outside the
 * regions. */
#define PAR_GATE_SLACK 1e-3
typedef struct sm_par_gate {
    unsigned wait;      /* steps left to run serially */
    unsigned backoff;   /* the wait after the last slow region (0: none) */
} sm_par_gate;

/* 1 when a loop of n checked moves should fork: PAR_CHECKED(n) and g open
 * (g may be NULL: the threshold alone); a closed gate counts the step. */
int sm_par_gate_open(sm_par_gate *g, size_t n);
/* Record a region's wall time and its threads' summed busy time (both in
 * seconds) when it ran on team threads (g may be NULL). */
void sm_par_gate_note(sm_par_gate *g, int team, double wall, double busy);

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
/* sm_star_score when that is above thr; otherwise a value at most thr (the
 * score of the star's tet `first`, its index from vt_off[v], tried alone
 * first: the star's minimum is sm_tet_score's per tet, bit for bit, so a
 * tet at or below thr puts the star there). */
double sm_star_score_above(const sm_mesh *sm, uint32_t v, const double p[3], size_t first,
                           double thr);

/* Min and max dihedral over all tets (parallel, deterministic). */
void sm_dihedral_range(const st_tetmesh *m, double *mind, double *maxd);

/* The volume-weighted mean of the circumcenters of v's tets (ODT target,
 * Alliez et al. 2005); v's position when its star has no volume. */
void sm_odt_target(const sm_mesh *sm, uint32_t v, double out[3]);

/* The volume enclosed by the boundary faces (divergence theorem) with the
 * points at xyz (3 per mesh point): the mesh volume, for a conforming mesh. */
double sm_boundary_volume(const sm_mesh *sm, const double *xyz);

/* Monotonic seconds. */
double sm_now(void);

#endif
