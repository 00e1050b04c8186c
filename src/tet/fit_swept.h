/*
 * fit_swept.h - the fit invariant's point test for a boundary vertex
 * without gathering its star's points (private; fit_swept.c, which proves
 * the claim): only the S vertices in the region the star's boundary faces
 * sweep can leave the star. The invariant (invariant.c) calls it first and
 * falls back on the full list when it cannot tell.
 *
 * Units: the mesh's and S's (one space). Ownership: borrows the mesh and
 * the point grid. Threads: reads only; any number of calls at once.
 * Errors: none (decided exactly: pred.h, isect.h).
 */
#ifndef SOUPTET_FIT_SWEPT_H
#define SOUPTET_FIT_SWEPT_H

#include <stdint.h>

#include "pgrid.h"
#include "smooth_mesh.h"

/* 1 when sm_swept_kept may decide v's moves (at most as many boundary
 * faces as it handles). */
int sm_swept_applies(const sm_mesh *sm, uint32_t v);
/* For a boundary vertex v of a mesh with no face of three tets, whose star
 * is positive with v where it is and with v at p: 1 when every S vertex
 * (the points of g) in the closed star stays in it with v at p, else 0
 * with *failed a point grid index that would leave; -1 when it cannot
 * tell. Exact. *empty (may be NULL) is 1 when it returns 1, every swept
 * tet (x, p, a, b) of a boundary face (x, a, b) is non-degenerate and no
 * S vertex lies in any of them (closed), else 0. */
int sm_swept_kept(const sm_mesh *sm, const pgrid *g, uint32_t v, const double p[3],
                  uint32_t *failed, int *empty);

#endif
