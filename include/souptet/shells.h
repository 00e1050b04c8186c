/*
 * shells.h - the closed shells of a soup, and the solid they bound.
 *
 * Units: model units.
 * Ownership: the caller owns an st_shells (st_shells_free); the soup and
 * edge table are borrowed.
 * Threads: no global state; st_shells_sign runs OpenMP loops whose result
 * does not depend on the thread count.
 * Errors: ST_EINPUT (a field of the wrong kind), ST_ELIMIT, ST_ENOMEM.
 *
 * A closed shell is a piece of the soup (edges.h: exactly welded vertices,
 * degenerate and duplicated triangles left out) each of whose edges is
 * used by exactly two of its triangles, and whose triangles can be
 * oriented so that the two run along every edge in opposite directions
 * (orientation is propagated across the edges; the file's own orientation
 * is not trusted, so randomly flipped faces do not matter). Such a
 * surface bounds a solid exactly: a point is inside where the shell's
 * winding number about it is not zero (solid.h), whether the shell passes
 * through itself or not, and whatever the voxel size. No vote is needed
 * there, and where two closed shells overlap (interpenetrating parts) the
 * overlap is inside, which no count of crossings can tell.
 *
 * Each shell is oriented to a positive signed volume, so where shells
 * overlap their winding numbers add (a shell nested in another, a hollow,
 * is filled: the union, as the pseudo volume's rule for nested parts).
 * A shell that passes through itself can hold regions of negative winding
 * where a part of it is turned inside out; such a region inside another
 * shell can cancel to zero. Shells touching only at vertices are one
 * piece and one shell. Open pieces (holes, deleted faces, sheets) are not
 * shells: the vote decides beside them.
 */
#ifndef SOUPTET_SHELLS_H
#define SOUPTET_SHELLS_H

#include <stddef.h>
#include "souptet/edges.h"
#include "souptet/err.h"
#include "souptet/grid.h"
#include "souptet/soup.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct st_shells {
    st_soup *closed;        /* the closed shells' triangles, each shell
                             * oriented consistently to positive volume */
    size_t count;           /* closed shells */
    size_t open_triangles;  /* kept triangles in no closed shell */
} st_shells;

/* ST_ENOMEM, ST_ELIMIT (more than 2^31 triangles). */
st_status st_soup_closed_shells(st_shells *out, const st_soup *s, st_error *err);
/* The same with s's edge table (st_soup_edges_build) when the caller has
 * it (NULL: built here). */
st_status st_soup_closed_shells_edges(st_shells *out, const st_soup *s,
                                      const st_soup_edges *edges, st_error *err);
void st_shells_free(st_shells *sh);

/* Give the signed field g (st_sign_field) the closed shells' solid: every
 * voxel center inside a shell becomes inside; when the soup had no other
 * triangle (open_triangles == 0) the shells are the whole surface and
 * every other voxel becomes outside, so the signs are exact. |values| are
 * kept. *changed (if not NULL) gets the number of signs changed. Records
 * "closed_shells" in g->meta. ST_EINPUT for a field that is not signed,
 * ST_ENOMEM (one byte per voxel for the solid). */
st_status st_shells_sign(st_grid *g, const st_shells *sh, size_t *changed, st_error *err);

#ifdef __cplusplus
}
#endif
#endif
