/*
 * quality.h - the quality pass (private; quality.c): moves that raise the
 * lowest dihedral-angle score of the stars of the tets below a goal, each
 * under the fit's invariant (invariant.h) when there is a surface. st_fit
 * (fit.c) runs it after its iterations and rescues; st_fair (fair.c) runs
 * it without a surface.
 *
 * Units: h in the mesh's units, the goal in degrees (a tet's score,
 *   smooth_mesh.h).
 * Ownership: borrows the context and the mesh, whose points it moves.
 * Threads: runs its own parallel loops (colour by colour; the result does
 *   not depend on the thread count); one call per mesh at a time.
 * Errors: ST_ENOMEM (err set) before any vertex moved; ST_ECANCELLED
 *   (err set) between rounds, the moves so far kept.
 */
#ifndef SOUPTET_QUALITY_H
#define SOUPTET_QUALITY_H

#include <stddef.h>

#include "invariant.h"
#include "smooth_mesh.h"

#include "souptet/err.h"
#include "souptet/smooth.h"

/* The quality pass of st_fit on c (c->s NULL: no surface, as
 * sm_quality_interior/sm_quality_fair): rounds of moves (at most
 * p->quality_rounds) while a tet scores below p->quality_goal and
 * something moves; st gets the rounds and moves, p->on_iter (with a
 * surface) each round's distances (dist, as sm_boundary_distances). */
st_status sm_quality_pass(fit_ctx *c, const st_fit_params *p, double *dist,
                          st_fit_stats *st, double t0, st_error *err);

/* The pass without a surface: only interior vertices move, so the volume
 * stays exactly as it is; h scales the trial steps. *moves gets the
 * number of moves. */
st_status sm_quality_interior(sm_mesh *sm, double h, int rounds, double goal,
                              size_t *moves, st_error *err);
/* The same pass with the boundary vertices too, each only in the plane
 * across its boundary faces' area-weighted normal (the volume's gradient
 * in it: first-order volume kept). As sm_quality_interior otherwise. */
st_status sm_quality_fair(sm_mesh *sm, double h, int rounds, double goal, size_t *moves,
                          st_error *err);

#endif
