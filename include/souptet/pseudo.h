/*
 * pseudo.h - the pseudo volume of a soup: the one entry point that
 * soupsign, soupwrap and the pipeline (soupmesh) call. Spillmann 2006,
 * section 3 (the vote), with steps of our own around it (below).
 *
 * Units: voxels for reaches and bands; the grid's model units for
 * distances.
 * Ownership: the caller owns *out (st_grid_free) and the BVH the _bvh
 * variants hand back (st_bvh_free); the field is changed in place
 * (st_pseudo_sign), the soup borrowed.
 * Threads: OpenMP inside each step; the same bytes for any thread count.
 * Errors: ST_EINPUT (a field that is not a distance field, bad parameters),
 * ST_ELIMIT, ST_ENOMEM, ST_ECANCELLED, ST_EINTERNAL; no grid on error.
 *
 * Given the unsigned distance field g of soup s (dist.h), in this order:
 *   1. the closed shells of s as given (shells.h), before any cap joins an
 *      open piece to them;
 *   2. caps for the holes of s (holes.h); g is lowered to the caps'
 *      distance within `cap_reach` voxels (st_dist_lower), so the rays
 *      meet them: every later step reads only distances below 1.5 voxels,
 *      so a reach of 3 voxels gives the same signs as a field computed
 *      from the soup and its caps together;
 *   3. the vote (sign.h, st_sign_field, the rule in p->sign), its cut
 *      also given the side of the soup's oriented walls that each voxel
 *      near them is on (sides.h: the soup and its caps, each orientable
 *      region turned the way the plain majority of the votes reads it;
 *      a one-sided scan's far side mirrored, and for one seen along an
 *      axis the column rule, st_sides_columns);
 *   4. the near-surface refinement against s and its caps (sign.h,
 *      st_sign_refine);
 *   5. the shells' solid (st_shells_sign).
 * The shortcut (shells_shortcut, on by default): when step 1 finds that
 * every triangle of s is in a closed shell (at least one shell, no open
 * triangle; degenerate and duplicated triangles do not count), step 5
 * decides every sign whatever steps 2 to 4 said, so they do not run: the
 * field is checked as the vote checks it, and each voxel becomes
 * st_grid_signed_value(its distance, inside the shells' solid). The signs
 * are the shells' alone, the same as the full path's voxel for voxel; a
 * voxel whose center lies on the surface (distance 0) is inside or outside
 * as the solid's simulation of simplicity says (solid.h), and holds
 * -FLT_MIN inside, +0.0 outside (the full path can leave +FLT_MIN there,
 * where an earlier step had called it inside: that bit pattern comes from
 * the skipped steps, not the shells). The metadata then records
 * "closed_shells" and a "sign_rule" naming the shells, and no "hole_caps"
 * or "sign_refine"; stats->shells_only is 1, and the other steps' stats
 * and seconds are 0.
 * Without the soup (s NULL) only step 3 runs: the vote of Spillmann et al.
 * 2006, section 3, and whatever the rule adds. Steps 1, 2 and 4 are not
 * in the paper; each can be turned off (fill_holes, closed_shells,
 * refine). The field need not come from this process: soupsign reads it
 * from soupdist, and the same call on the same field and soup gives the
 * same bytes, whoever calls it.
 */
#ifndef SOUPTET_PSEUDO_H
#define SOUPTET_PSEUDO_H

#include <stddef.h>

#include "souptet/bvh.h"
#include "souptet/dist.h"
#include "souptet/err.h"
#include "souptet/grid.h"
#include "souptet/holes.h"
#include "souptet/sides.h"
#include "souptet/progress.h"
#include "souptet/sign.h"
#include "souptet/soup.h"
#include "souptet/symmetry.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct st_pseudo_params {
    st_sign_params sign;            /* the vote (st_sign_params_default) */
    st_sign_refine_params refine;   /* step 4 (st_sign_refine_params_default) */
    st_holes_params holes;          /* step 2 (st_holes_params_default) */
    int fill_holes;                 /* step 2 (1) */
    int closed_shells;              /* steps 1 and 5 (1) */
    int refine_signs;               /* step 4 (1) */
    int sides;                      /* step 3 with the sides' evidence (1) */
    st_sides_params sides_params;   /* (st_sides_params_default) */
    double cap_reach;               /* voxels (3; the field's band if less) */
    int shells_shortcut;            /* the shells alone when they are the
                                       whole soup (1; 0: every step runs) */
    int signs_only;                 /* st_pseudo_volume(_bvh): the caller
                                       reads only the field's signs, so
                                       where the shortcut runs no distance
                                       is computed: every voxel holds the
                                       band's far value (st_dist_field_far)
                                       with the shells' sign, the same
                                       signs, and the metadata says
                                       "distances" (0: distances always) */
    int symmetry;                   /* step 2: the soup's symmetries
                                       (symmetry.h) fill the holes, capped
                                       or too large to cap, their images
                                       close, and those holes' caps are
                                       dropped (1: on; measured in
                                       doc/design/symmetry.md) */
    st_soup **symmetric_fill;       /* not NULL: *symmetric_fill gets the
                                       symmetric fill used (the caller's,
                                       st_soup_free; NULL when none), for
                                       st_pseudo_guess_symmetric */
} st_pseudo_params;

/* Every step on, the project's default rule. */
st_pseudo_params st_pseudo_params_default(void);

/* What each step did, and how long it took (wall seconds). */
typedef struct st_pseudo_stats {
    int surface;                    /* the soup was given */
    double event_distance;          /* the vote's, model units */
    st_holes_stats holes;
    size_t cap_triangles;           /* the caps', and the symmetric fill's */
    st_symmetry_set symmetries;     /* found (step 2 with symmetry on and caps) */
    st_symmetry_fill_stats symmetry_fill;   /* where the gate
                                       (st_symmetry_fill_may_act) skipped
                                       the search: caps the cap groups it
                                       tested, no candidates above */
    double seconds_symmetry;        /* detection and fill, within seconds_holes */
    st_sides_stats sides;
    size_t mirrored;                /* voxels a one-sided view's mirror added */
    size_t columned;                /* voxels the column rule made outside */
    size_t refined;                 /* signs the refinement changed */
    size_t shells;                  /* closed shells */
    size_t shell_open_triangles;    /* triangles in none */
    size_t shell_changed;           /* signs the shells changed (the
                                       shortcut: voxels inside, from all
                                       outside) */
    int shells_only;                /* the shortcut ran: steps 2 to 4 did not */
    size_t inside;                  /* voxels inside at the end */
    double seconds_shells, seconds_holes, seconds_vote, seconds_refine;
    double seconds_bvh;             /* the BVH handed over (_bvh calls) when
                                       no step built it (the shortcut) */
    const char *failed_step;        /* on failure: "shells", "holes", "vote",
                                       "refine" (whose input to blame) */
} st_pseudo_stats;

/* Sign the unsigned distance field g of soup s in place (negative inside
 * the pseudo volume); s may be NULL (the vote alone). stats may be NULL.
 * Records what ran in g->meta ("sign_rule", "hole_caps", "sign_refine",
 * "closed_shells"). Errors as st_sign_field's, ST_ENOMEM. */
st_status st_pseudo_sign(st_grid *g, const st_soup *s, const st_pseudo_params *p,
                         st_pseudo_stats *stats, const st_progress *progress,
                         st_error *err);

/* The distance field of s (dp) and its signs (st_pseudo_sign): what
 * `soupdist | soupsign --surface` computes, in one call. */
st_status st_pseudo_volume(st_grid **out, const st_soup *s, const st_dist_params *dp,
                           const st_pseudo_params *p, st_pseudo_stats *stats,
                           const st_progress *progress, st_error *err);

/* The same, handing the caller s's BVH (st_bvh_build; the one the caps
 * and the refinement used, else built at the end): *bvh gets it (the
 * caller's to free with st_bvh_free), NULL on failure. */
st_status st_pseudo_sign_bvh(st_grid *g, const st_soup *s, const st_pseudo_params *p,
                             st_pseudo_stats *stats, const st_progress *progress,
                             st_bvh **bvh, st_error *err);
st_status st_pseudo_volume_bvh(st_grid **out, const st_soup *s, const st_dist_params *dp,
                               const st_pseudo_params *p, st_pseudo_stats *stats,
                               const st_progress *progress, st_bvh **bvh, st_error *err);

/* The fill of signed field g (pseudo_fill.c): the faces between an
 * inside and an outside voxel whose center is farther than one voxel from
 * every triangle of the soup bvh was built over - where the pseudo volume
 * has a boundary and the soup has no surface (the far side of a one-sided
 * scan, a large hole's cap) - as a soup of voxel squares, two triangles
 * each. Empty (no triangles) when the soup explains every sign change.
 * *faces (may be NULL) gets the squares. ST_EINPUT for a field that is not
 * signed (an unknown kind is taken as signed), ST_ENOMEM, ST_ELIMIT. */
st_status st_pseudo_fill(st_soup **out, const st_grid *g, const st_bvh *bvh,
                         size_t *faces, st_error *err);

/* How much of the pseudo volume's boundary is a guess rather than the
 * soup: the faces of signed field g's boundary (between an inside and an
 * outside voxel), of them the fill's (fill: st_pseudo_fill's output for g
 * and bvh; NULL: none), and the fill's farthest point from the soup (bvh:
 * the soup's; each fill square's center; model units, 0 without fill).
 * A hole's cap, a one-sided view's far side or a large hole's rebuilt
 * face are fill; the soup's own surface is not. */
typedef struct st_pseudo_guess {
    size_t boundary_faces;
    size_t fill_faces;
    double depth;
    size_t symmetric_faces;   /* of the fill's, those its symmetry filled
                                 (st_pseudo_guess_symmetric; 0 before) */
} st_pseudo_guess;
void st_pseudo_guess_measure(st_pseudo_guess *out, const st_grid *g, const st_soup *fill,
                             const st_bvh *bvh);

/* out->symmetric_faces: the squares of fill (st_pseudo_fill's, for grid g)
 * whose center lies within one voxel of sym (the symmetric fill the
 * pseudo volume used: st_pseudo_params.symmetric_fill), as st_pseudo_fill
 * tells the soup's faces: the part of the guess its symmetric copy
 * supplied, the rest being caps and far sides. 0 when fill or sym is NULL
 * or empty. ST_ENOMEM. */
st_status st_pseudo_guess_symmetric(st_pseudo_guess *out, const st_grid *g,
                                    const st_soup *fill, const st_soup *sym, st_error *err);

#ifdef __cplusplus
}
#endif
#endif
