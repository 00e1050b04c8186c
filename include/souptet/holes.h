/*
 * holes.h - caps for the holes of a soup: each loop of boundary edges that
 * is a hole (not the rim of an open patch) gets a triangulation of its own
 * points, the least-area one or, where the soup around the holes is
 * intact, the one that bends least or a lost corner rebuilt from the
 * planes along the loop. Not in Spillmann 2006 or Stuart 2013: the caps
 * give the pseudo volume's rays (sign.h, pseudo.h, step 2) a surface to
 * meet across a hole. How the loops are traced and paired, which are
 * capped, and the caps' shapes: doc/design/holes.md.
 *
 * Units: model units (the caps' vertices are copies of the loops' points,
 * and inner points of the caps faired over a smooth surface;
 * the parameters are ratios).
 * Ownership: the caller owns *caps (st_soup_free); s, edges and bvh are
 * borrowed for the call only.
 * Threads: no global state; calls on different soups may run at once, and
 * the caps do not depend on the thread count.
 * Errors: ST_EINPUT (max_loop over 4096, max_cap_ratio negative or NaN),
 * ST_ELIMIT (more than 2^31 triangles), ST_ENOMEM; *caps is NULL on any
 * error.
 *
 * Orientation is not read; the result does not depend on how the soup's
 * vertices are shared, only on their positions.
 */
#ifndef SOUPTET_HOLES_H
#define SOUPTET_HOLES_H

#include <stddef.h>
#include "souptet/bvh.h"
#include "souptet/edges.h"
#include "souptet/err.h"
#include "souptet/soup.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct st_holes_params {
    double max_cap_ratio;   /* least-area cap / area of the pieces around it */
    size_t max_loop;        /* loops with more edges are left open */
    double flat;            /* a loop within flat times its extent of a
                             * plane, not along a flat sheet's rim, is
                             * capped whatever its size (0: never) */
    int bend;               /* 1 (default): the cap that bends least;
                             * 0: the cap of least area */
    int planes;             /* 1: the cap rebuilt from the planes along
                             * the loop where they agree on one, else as
                             * bend says */
    double intact;          /* bend and planes only where the rim (the
                             * triangles on a hole's edge) is at most this
                             * share of the soup's area (1: always) */
    double onesided;        /* and only where the soup is not seen from one
                             * side along an axis: its least back/front
                             * ratio (doc/design/holes.md) at least this
                             * (0: always) */
} st_holes_params;

typedef struct st_holes_stats {
    size_t boundary_edges;
    size_t loops;           /* loops traced */
    size_t filled;          /* loops capped */
    size_t rebuilt;         /* of them, rebuilt from the planes around */
    size_t too_large;       /* cap above max_cap_ratio (or of no area) */
    size_t too_long;        /* more than max_loop edges */
    size_t pinched;         /* boundary edges on paths through a vertex
                             * whose edges could not be paired: left open */
    double rim_share;       /* the rim's share of the soup's area */
    double one_sided;       /* that ratio (-1 when not needed) */
    int continued;          /* bend or planes applied (rim_share at most
                             * intact, one_sided at least onesided) */
} st_holes_stats;

st_holes_params st_holes_params_default(void);

/* *caps gets a new soup of the caps' triangles (possibly none; its
 * vertices are copies of the loops' positions, and a faired cap's inner
 * points: doc/design/holes.md, "Faired caps"). stats may be NULL.
 * ST_EINPUT (bad parameters), ST_ENOMEM, ST_ELIMIT (more than 2^31
 * triangles). */
st_status st_soup_hole_caps(st_soup **caps, const st_soup *s,
                            const st_holes_params *p, st_holes_stats *stats,
                            st_error *err);

/* The same with s's edge table (st_soup_edges_build) and BVH
 * (st_bvh_build) when the caller has them (either may be NULL: built here
 * and freed). The same caps. */
st_status st_soup_hole_caps_shared(st_soup **caps, const st_soup *s,
                                   const st_soup_edges *edges, const st_bvh *bvh,
                                   const st_holes_params *p, st_holes_stats *stats,
                                   st_error *err);

#ifdef __cplusplus
}
#endif
#endif
