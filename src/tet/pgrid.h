/*
 * pgrid.h - the distinct vertices of a surface S in bins (private;
 * pgrid.c): where the fit's invariant (invariant.c) and its swept-region
 * test (fit_swept.c) look for the S vertices near a star.
 *
 * Units: S's. Ownership: the grid owns its arrays (sm_pgrid_free); it
 * copies the points, so S need not outlive it. Threads: read-only once
 * built. Errors: sm_pgrid_build returns ST_ENOMEM (no err record: the
 * caller says what ran out); the grid is then to be freed.
 */
#ifndef SOUPTET_PGRID_H
#define SOUPTET_PGRID_H

#include <math.h>
#include <stddef.h>
#include <stdint.h>

#include "souptet/err.h"
#include "souptet/soup.h"

typedef struct pgrid {
    double *pts;          /* distinct vertices of S, 3 each, sorted */
    size_t npts;
    double lo[3], cell;
    size_t n[3];
    size_t *off;          /* bin -> points (CSR) */
    uint32_t *idx;
    double *bpts;         /* the points in bin order: bpts + 3 j is
                             pts + 3 idx[j] (fit_swept.c's scans) */
} pgrid;

/* The distinct vertices of s's triangles, in bins of at most `cell`,
 * finer (down to cell / 8) where the points are dense, and at most 256
 * per axis. */
st_status sm_pgrid_build(pgrid *g, const st_soup *s, double cell);
void sm_pgrid_free(pgrid *g);

/* The bin of coordinate x along axis a, clamped to the grid. */
static inline size_t sm_pgrid_coord(const pgrid *g, double x, int a)
{
    double f = floor((x - g->lo[a]) / g->cell);
    if (!(f > 0.0))
        return 0;
    if (f >= (double)g->n[a])
        return g->n[a] - 1;
    return (size_t)f;
}

#endif
