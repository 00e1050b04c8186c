/*
 * mincut.h - inside/outside of a voxel grid by a minimum cut (an
 * augmenting-path max-flow, incremental breadth-first search: Goldberg,
 * Hed, Kaplan, Tarjan and Werneck, 2011, on the grid's 6-neighbour
 * graph).
 *
 * Units: voxels; capacities are integers.
 * Ownership: the caller owns the label array (one int8 a voxel); the grid
 * is borrowed.
 * Threads: sequential solver: the result does not depend on the thread
 * count; calls on different grids may run at once.
 * Errors: ST_ENOMEM, ST_ELIMIT.
 *
 * The labelling minimises
 *     sum over voxels of  evidence against its label
 *   + sum over neighbouring pairs labelled differently of  area(p, q),
 * where area(p, q) is small where the surface passes between p and q
 * (an unsigned distance below a voxel) and one face of free space (a
 * constant) elsewhere. So the inside/outside boundary follows the surface
 * where there is one and spans a gap in it (a hole, deleted faces) by the
 * least area, like a soap film, and voxels without evidence either way
 * join the side that closes them off most cheaply. Voxels on the grid's
 * border are outside whatever their evidence.
 *
 * Integer capacities: the result is exact (no rounding in the flow) and
 * does not depend on the thread count (the solver is sequential).
 */
#ifndef SOUPTET_MINCUT_H
#define SOUPTET_MINCUT_H

#include <stddef.h>
#include <stdint.h>

#include "souptet/err.h"
#include "souptet/grid.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct st_mincut_params {
    double free_area;       /* capacity of a face in free space (>= 1) */
    double surface_voxels;  /* faces with min |d| >= this many voxels are free */
    double power;           /* area = free_area * (min|d| / surface)^power */
    double evidence_weight; /* capacity per unit of evidence */
    int fixed_evidence;     /* |evidence| >= this: decided, not a node */
} st_mincut_params;

st_mincut_params st_mincut_params_default(void);

/* dist: the grid's unsigned distances (g->data, |values| are read).
 * label: one signed byte per voxel on entry, the evidence: > 0 for
 * inside, < 0 for outside, its magnitude the strength (0: none). On
 * return 1 where the voxel is inside, 0 where outside. ST_ENOMEM when the
 * graph does not fit. *flow (if not NULL) gets the cut's cost. */
st_status st_mincut_label(const st_grid *g, int8_t *label,
                          const st_mincut_params *p, double *flow,
                          st_error *err);

#ifdef __cplusplus
}
#endif
#endif
