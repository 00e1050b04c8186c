/*
 * pipeline.h - the whole job in one call: a soup in, a coarse tet mesh
 * that encloses it out (what soupmesh runs). Stuart 2013, section 3 (the
 * lattice, sculpting, fitting and candidates), with the pseudo volume of
 * Spillmann 2006, section 3.
 *
 * Units: model units (h, offsets, distances); angles in degrees.
 * Ownership: the caller owns *out (st_tetmesh_free) and stats->candidates
 * (free()); the soup is borrowed.
 * Threads: candidates run in parallel (a batch's on POSIX threads the call
 * starts and joins, signals blocked in them, besides OpenMP's); the output
 * depends only on the soup and the parameters (below).
 * Errors: ST_EINPUT (bad parameters, an empty soup), ST_ELIMIT, ST_ENOMEM,
 * ST_ECANCELLED; no mesh on error.
 *
 *   distance field (dist.h) -> signs, the pseudo volume (sign.h)
 *     -> per candidate: a seeded lattice, sculpted with bomb repair
 *        (sculpt.h), fitted to the soup with the quality pass (smooth.h)
 *     -> the best candidate.
 *
 * Candidates (Stuart et al. 2013, section 3.4). Candidate k lays its
 * lattice with seed st_pipeline_candidate_seed(seed, k): a random rotation
 * and offset per candidate (seed 0 and k 0: the axis-aligned lattice). The
 * candidates run in batches of ST_PIPELINE_BATCH in index order, the
 * candidates of a batch at once, each on a thread of its own with its
 * share of the threads for its own loops (one each on 2 threads); once
 * one is done, the others take its threads for their loops (from their
 * next fit iteration or quality round on). They share the fits' set-up
 * that depends on the soup, the fill and h alone (st_fit_shared: the
 * fill's BVH, the point grid), built once. Once a batch has ended
 * with a candidate that meets every goal (it encloses, meets the fit's
 * stopping condition, and every tet scores at least the quality pass's
 * goal, min dihedral >= 35 degrees by default, smooth.h, and max <= 133),
 * no further batch runs, unless try_all: stats->ncandidates says how many
 * ran, stats->goal_met why. Which ran does not depend on the thread count.
 * Of those that ran, the winner is chosen by a total order that does not
 * depend on which finished first:
 *   1. enclosing before not enclosing (no soup vertex outside the mesh, no
 *      soup triangle meeting the boundary, counted exactly);
 *   2. the fit's stopping condition met (every boundary vertex within
 *      offset_ratio * h of the soup, or of the fill with fill_counts)
 *      before not met;
 *   3. the angle goals met (min dihedral >= 35, max <= 133, as above)
 *      before not met;
 *   4. larger minimum dihedral angle;
 *   5. smaller maximum dihedral angle;
 *   6. smaller k.
 * Every stage is deterministic for any thread count, so the output depends
 * only on the soup and the parameters.
 *
 * The Spillmann mesher (density_rho > 0): the cubic5 lattice filtered by
 * pseudo-volume density, then volume-preserving boundary fairing; it
 * approximates the pseudo volume and does not try to enclose the soup
 * (enclosure is still measured and reported).
 */
#ifndef SOUPTET_PIPELINE_H
#define SOUPTET_PIPELINE_H

#include <stddef.h>
#include <stdint.h>

#include "souptet/enclose.h"
#include "souptet/err.h"
#include "souptet/parts.h"
#include "souptet/pseudo.h"
#include "souptet/progress.h"
#include "souptet/smooth.h"
#include "souptet/soup.h"
#include "souptet/tetmesh.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Most candidates one call runs. */
#define ST_PIPELINE_MAX_TRIES 1024
/* Most lattice cells along the longest side (as soupmesh --cells). */
#define ST_PIPELINE_MAX_CELLS 4096
/* Candidates per batch (see above): a fixed count, so that which
 * candidates run does not depend on the thread count. */
#define ST_PIPELINE_BATCH 2
/* Sculpts at most when choosing h for target_tets. */
#define ST_PIPELINE_SIZE_STEPS 10

struct st_pipeline_candidate;

/* What a long run tells its caller as it goes (st_pipeline_params.on_event),
 * for progress lines: the library never prints. */
typedef struct st_pipeline_event {
    const char *what;      /* "field": the distance field and signs are
                              done (field_dims, voxel);
                              "size": a sculpt while choosing h for
                              target_tets or dry_run (h, tets);
                              "sculpted": candidate k's lattice is
                              sculpted (h, tets, seconds);
                              "iteration": one fit or quality iteration of
                              candidate k (fit);
                              "candidate": candidate k is done (candidate) */
    size_t k;              /* the candidate (0 for "field" and "size") */
    size_t field_dims[3];
    double voxel, h;
    size_t tets;
    double seconds;        /* the stage's time */
    const st_fit_iter *fit;
    const struct st_pipeline_candidate *candidate;
} st_pipeline_event;

/* Called with ctx and the event; calls never overlap (they may come from
 * different threads, one at a time, when candidates run in parallel),
 * and the order of the candidates' events depends on which runs first;
 * nothing about the result does. */
typedef void (*st_pipeline_event_fn)(void *ctx, const st_pipeline_event *ev);

typedef struct st_pipeline_params {
    size_t cells;          /* lattice cells along the longest side (10) */
    double h;              /* > 0: the lattice cell width in model units,
                              instead of cells (0); the field's default
                              resolution then counts ceil(longest side / h)
                              cells */
    size_t field_cells;    /* voxels along the longest side of the field;
                              0: 16 per cell up to 128, 8 per cell
                              beyond: max(8 cells, min(16 cells, 128)) */
    size_t target_tets;    /* > 0: choose h for about this many tets: the
                              first candidate's lattice is sculpted at the
                              h of cells (or h) and then at widths stepped
                              in log-log space (tets ~ h^slope, the slope
                              measured) until its count is within 10% of
                              this, ST_PIPELINE_SIZE_STEPS sculpts at most;
                              the closest one wins (0) */
    int dry_run;           /* 1: stop once h is chosen (and, without
                              target_tets, the first candidate sculpted):
                              no mesh; stats give h and estimated_tets (0) */
    double offset_ratio;   /* d_offset = offset_ratio * h (0.4) */
    size_t tries;          /* candidates (1) */
    uint64_t seed;         /* seed of candidate 0 (1) */
    int quality;           /* run the quality pass after the fit (1) */
    int fit_max_iters;     /* 0: smooth.h's default */
    double density_rho;    /* > 0: the Spillmann mesher with this rho_min */
    size_t max_bytes;      /* limit for the distance field (0: none) */
    int fill_holes;        /* the field of the soup with its holes capped
                              (holes.h) (1) */
    int closed_shells;     /* the soup's closed pieces sign their solid
                              exactly (shells.h) (1) */
    int symmetry;          /* with fill_holes: the soup's symmetries fill
                              the holes they cover (pseudo.h, symmetry.h) (1) */
    int fill_counts;       /* the fill counts as surface for the fit's
                              stopping condition (2. below, and the pull):
                              the pseudo volume's boundary where the soup
                              has none (st_pseudo_fill, st_fit_params.fill);
                              and the mesh encloses it as it encloses the
                              soup (st_pipeline_enclosed): a filled hole's
                              boundary is not cut inside the pseudo volume.
                              0: the soup alone (1) */
    int float32;           /* 1: the chosen mesh's points are rounded to
                              float32 so that it encloses the soup once
                              stored as float (Blender, glTF, STL, game
                              engines, PhysX): st_enclosure_round_float32
                              (enclose.h) on the chosen candidate, after
                              the choice; its enclosure counts (and the
                              dihedral range) are then the rounded mesh's,
                              checked exactly, and so are stats->encloses
                              and meta "encloses"; meta "float32" is
                              "yes"; stats->float32 says what it took.
                              Every coordinate x of *out then has
                              (double)(float)x == x. The fit's distances
                              and its stopping condition (max_distance,
                              converged, beyond_offset) are measured
                              before the rounding, which moves a point by
                              at most stats->float32.max_move (float ulps).
                              0: the points as the fit left them, in
                              double, and no meta "float32" (0) */
    st_pipeline_event_fn on_event;   /* may be NULL (NULL) */
    void *on_event_ctx;
    int try_all;           /* 1: run all tries candidates even once one
                              meets every goal (0) */
    const st_parts *parts; /* the soup's parts (st_parts_split of the
                              soup given to st_pipeline_run): the chosen
                              mesh is tagged (st_parts_tag, on the run's
                              field grid and pseudo-volume settings), and
                              stats->parts says how. NULL: no parts, and
                              the output is as without them (NULL) */
} st_pipeline_params;

st_pipeline_params st_pipeline_params_default(void);

/* The lattice seed of candidate k (k 0: seed itself). */
uint64_t st_pipeline_candidate_seed(uint64_t seed, size_t k);

/* What happened to one candidate. */
typedef struct st_pipeline_candidate {
    uint64_t seed;
    int failed;                    /* 1: a stage failed (message below) */
    char message[256];
    size_t tets, points;
    size_t bombs, bombs_left;
    int converged;                 /* every boundary vertex within d_offset */
    size_t beyond_offset;          /* of boundary_vertices */
    size_t boundary_vertices;
    double max_distance;           /* boundary vertices to the soup */
    double min_dihedral, max_dihedral;
    size_t verts_outside, tris_crossing;   /* exact, 0 and 0: encloses */
    double seconds_sculpt, seconds_fit;
} st_pipeline_candidate;

typedef struct st_pipeline_stats {
    size_t field_dims[3];
    double voxel, h;
    double seconds_dist, seconds_sign, seconds_candidates, seconds_total;
    size_t ncandidates;
    st_pipeline_candidate *candidates;   /* ncandidates entries, caller
                                            frees with free() */
    size_t best;                         /* index of the chosen one */
    int encloses;                        /* the chosen one encloses */
    size_t estimated_tets;               /* the first candidate's sculpted
                                            tets at h (target_tets or
                                            dry_run; the fit keeps them) */
    size_t sculpts;                      /* sculpts spent choosing h */
    double seconds_size;                 /* and their time */
    int shells_only;                     /* the pseudo volume's signs are
                                            its closed shells' alone
                                            (pseudo.h, the shortcut) */
    size_t fill_faces;                   /* voxel squares of the fill (0
                                            with fill_counts 0) */
    st_float32_stats float32;            /* with p->float32: the rounding
                                            (enclose.h; all 0 without) */
    st_pseudo_guess guess;               /* how much of the pseudo volume's
                                            boundary is fill, and how far
                                            from the input (pseudo.h; all 0
                                            for closed shells alone) */
    int goal_met;                        /* 1: a candidate met every goal
                                            and ended the run, maybe before
                                            all tries (see above) */
    st_symmetry_set symmetries;          /* the signs' step 2 (pseudo.h):
                                            found (candidates 0: not looked
                                            for) */
    st_symmetry_fill_stats symmetry_fill;/* and what the fill took */
    double seconds_symmetry;
    st_parts_tag_stats parts;            /* with p->parts: per part (the
                                            caller frees it with
                                            st_parts_tag_stats_free, also
                                            on failure; all 0 without) */
} st_pipeline_stats;

/* The lattice cell width p gives for s: p->h, or the width of p->cells
 * cells along the longest side of s's box. 0 when s has no bounds. */
double st_pipeline_cell_width(const st_soup *s, const st_pipeline_params *p);

/* A bound on the memory the candidates' lattices take at cell width h
 * (what a run is refused on before any lattice is allocated, and what
 * a dry run reports): any rotation of s's box spans at most its diagonal
 * d along a lattice axis, so a lattice has at most floor(d / h) + 3 +
 * 2 ST_LATTICE_PAD_DEFAULT cells along an axis, 12 tets a cell (BCC),
 * ST_LATTICE_BYTES_PER_TET bytes a tet, and min(tries, threads) lattices
 * are laid at once (one when tries is 1). *tets and *at_once (may be
 * NULL) get the tets of one lattice and the lattices at once. Returns the
 * bytes, or 0 (and 0s) when s has no bounds or h is not positive and
 * finite. */
double st_pipeline_lattice_bytes(const st_soup *s, double h, size_t tries,
                                 double *tets, double *at_once);

/* Mesh soup s. *out gets the chosen candidate's mesh, with meta "h",
 * "lattice", "seed", "offset_ratio", "offset_fill" (yes or no; not with density_rho),
 * "candidates", "encloses", and "float32" ("yes") with p->float32. stats may
 * be NULL; when given, stats->candidates must be freed by the caller even
 * on failure (it is NULL when nothing was allocated). Fails when the
 * soup is empty or every candidate failed (the first candidate's message
 * is reported). Not enclosing is not a failure: stats say it, and meta
 * "encloses" is "no". With p->dry_run, *out stays NULL on success. prog may be
 * NULL; its cancel flag (progress.h), once set, stops the run within
 * about 0.1 s of work (the field, the signs, between the fit's
 * iterations, the candidates not yet started): ST_ECANCELLED, *out NULL,
 * everything freed but stats->candidates. */
st_status st_pipeline_run(st_tetmesh **out, st_pipeline_stats *stats,
                          const st_soup *s, const st_pipeline_params *p,
                          const st_progress *prog, st_error *err);

/* The surface a mesh must enclose when the fill counts (fill_counts):
 * s and fill (st_pseudo_fill's for the pseudo volume of s) as one soup,
 * s's triangles first, and its BVH. The candidates are sculpted and
 * fitted to it, so the mesh holds the pseudo volume's guessed boundary
 * (a filled hole, a far side) as exactly as the soup; latticetet --sculpt
 * and tetsmooth --fit with a field do the same. With fill NULL or empty,
 * *out and *bvh are NULL: s alone. ST_ENOMEM, ST_ELIMIT; both NULL on
 * failure. */
st_status st_pipeline_enclosed(st_soup **out, st_bvh **bvh, const st_soup *s,
                               const st_soup *fill, st_error *err);

/* The pseudo volume a mesh of st_pipeline_run was fitted against: the
 * same field over s (its meta "field_voxels", "fill_holes",
 * "closed_shells"), so that a check of the fit's condition against the
 * soup and its fill (st_tetstat_fill with offset_fill yes) measures what
 * the run measured. ST_EINPUT when the meta does not say (a mesh from the
 * pipe of tools or elsewhere). */
st_status st_pipeline_field_of_mesh(st_grid **out, const st_tetmesh *m, const st_soup *s,
                                    size_t max_bytes, const st_progress *prog, st_error *err);

#ifdef __cplusplus
}
#endif
#endif
