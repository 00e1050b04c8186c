/*
 * sign.h - the pseudo volume of a soup: signs for a distance field by
 * multi-direction volume-event voting (Spillmann, Wagner, Teschner 2006, §3).
 *
 * Units: voxels (event distances, steps); the field's model units for
 * distances.
 * Ownership: the field is signed in place and stays the caller's, as do the
 * vote arrays it passes; soups and BVHs are borrowed.
 * Threads: OpenMP over lines; results do not depend on the thread count.
 * Errors: ST_EINPUT (a field that is not a distance field, bad parameters),
 * ST_ENOMEM, ST_ECANCELLED.
 *
 * Along each of the 13 lines of the 26-neighbourhood through every voxel, a
 * ray reads the distance field. The paper's probability P = 1 - c|d| marks
 * a volume event where P rises above k, i.e. where |d| falls below the
 * event distance t = (1 - k) / c; consecutive voxels below t are one event.
 * Parity toggles per event; a voxel's vote along a ray is the parity the ray
 * has when it reaches it; the majority of the votes decides the sign.
 *
 * What the paper leaves open (the constant c, where in an event run the
 * toggle lands, rays with an odd count of events, k = 1, ties,
 * interpenetrating parts, two crossings in one run, the cut) and how each
 * is decided here, each selectable in st_sign_params: doc/design/sign.md.
 * Results do not depend on the thread count.
 *
 * Memory: st_sign_field needs the grid (4 bytes per voxel) plus ONE BYTE PER
 * VOXEL for the votes, for every rule and option (the cut adds about 70
 * bytes per undecided voxel, nothing on a closed surface's far voxels): the votes (each of the 13 lines adds
 * 0..2; a line dropped for odd parity adds 1, neutral), one bit "some ray
 * sees the voxel from outside" for nested_union, and the two toggle marks
 * of the direction being swept. Each thread also keeps line states for a
 * block of lines (O(32 (nx + nz)) bytes), not per voxel.
 */
#ifndef SOUPTET_SIGN_H
#define SOUPTET_SIGN_H

#include "souptet/err.h"
#include "souptet/grid.h"
#include "souptet/progress.h"
#include "souptet/soup.h"
#include "souptet/bvh.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum st_sign_toggle {
    ST_TOGGLE_FIRST = 0,    /* first voxel of the event run */
    ST_TOGGLE_NEAREST,      /* voxel of least distance in the run */
    ST_TOGGLE_CROSSING      /* between the two samples the surface passes:
                             * beside the voxel of least distance, on the
                             * side of its nearer neighbour on the line */
} st_sign_toggle;

typedef struct st_sign_params {
    double k;               /* event threshold on P, in (0, 1] */
    double band_voxels;     /* > 0: c = 1 / (band_voxels * voxel); 0: 1/max|d| */
    int rays;               /* 13 (one way per line) or 26 (both ways) */
    st_sign_toggle toggle;
    int ignore_odd;         /* drop lines with an odd number of events */
    int nested_union;       /* hidden from all rays = inside (see above) */
    int split_runs;         /* crossing toggle: an event run with two dips
                             * is two events (see above) */
    int cut;                /* the sides by a minimum cut (see above) */
} st_sign_params;

/* The paper's rule exactly: k 0.8, c = 1/max|d|, 26 rays, toggle on the
 * first voxel, odd lines kept. */
st_sign_params st_sign_params_paper(void);
/* The project's default rule (chosen by the accuracy benchmark; see
 * sign.c for the table that decided it). */
st_sign_params st_sign_params_default(void);

/* Named rules for --rule: "paper", "default", "parity" (k = 1). Returns 0
 * and fills *p, or -1 for an unknown name. */
int st_sign_params_named(st_sign_params *p, const char *name);

/* The event distance the parameters give on grid g (model units), for the
 * axis direction; diagonal rays at k = 1 scale it by their step. */
double st_sign_event_distance(const st_sign_params *p, const st_grid *g);

/* Give the distance field g signs in place: negative inside the pseudo
 * volume. g must be an unsigned distance field (kind ST_GRID_DISTANCE, or
 * UNKNOWN with no negative value); anything else is refused with ST_EINPUT.
 * On success g->kind is ST_GRID_SIGNED and the parameters are recorded in
 * g->meta. */
st_status st_sign_field(st_grid *g, const st_sign_params *p,
                        const st_progress *progress, st_error *err);

/* st_sign_field's checks alone (g unsigned, finite, not constant; k and
 * rays in range): ST_OK, or the ST_EINPUT st_sign_field would give. */
st_status st_sign_check_field(const st_grid *g, const st_sign_params *p, st_error *err);

/* The parameters' part of those checks alone (k and rays in range), for a
 * field made to be signed without a vote (pseudo.h, signs_only). */
st_status st_sign_check_params(const st_sign_params *p, st_error *err);

/* st_sign_field with more evidence for the cut (p->cut only): extra[i]
 * (NULL: none) is added to voxel i's evidence from the votes (a margin of
 * U - 13 votes; see mincut.h for its weight), for what the votes cannot
 * see: the side of an oriented surface (sides.h). votes: NULL, or what
 * st_sign_votes gave for this g and p (not voted again; overwritten). */
st_status st_sign_field_evidence(st_grid *g, const st_sign_params *p, const int8_t *extra,
                                 uint8_t *votes, const st_progress *progress, st_error *err);

/* The votes alone, without touching g: votes[i] (n bytes) gets voxel i's
 * inside votes U (0..26, 13 neutral; ST_SIGN_VOTES_COUNT) and
 * ST_SIGN_VOTES_INSIDE where the majority says inside (ties outside;
 * hidden voxels inside under nested_union). Same checks as st_sign_field. */
#define ST_SIGN_VOTES_COUNT 0x1fu
#define ST_SIGN_VOTES_SEEN 0x20u     /* some ray sees the voxel from outside */
#define ST_SIGN_VOTES_INSIDE 0x80u
st_status st_sign_votes(const st_grid *g, const st_sign_params *p, uint8_t *votes,
                        st_error *err);
/* The same, reporting "signs" to progress and stopping on its cancel flag
 * between the 13 sweeps (ST_ECANCELLED). */
st_status st_sign_votes_progress(const st_grid *g, const st_sign_params *p, uint8_t *votes,
                                 const st_progress *progress, st_error *err);

/* The rule on one line of samples (for tests and for reading the rule):
 * d[0..n) are the distances along the line, t the event distance; adds the
 * line's inside votes to votes[] (one per ray: up to 2 with 26 rays) and,
 * when valid is not NULL, the number of counted rays to valid[]. Returns
 * the number of events on the line. */
unsigned st_sign_line(const float *d, size_t n, float t,
                      const st_sign_params *p, unsigned char *votes,
                      unsigned char *valid);

/* Near-surface refinement (not in the paper; the project's default when
 * the soup is at hand). An unsigned field cannot tell on which side of the
 * surface a voxel center within a fraction of a voxel of it lies, nor the
 * inside of a feature thinner than a voxel; the soup can. For every voxel v
 * with |d| < band voxels, each "confident" neighbour u (|d_u| >= band,
 * within `radius` voxels in each axis, nearest first) whose segment v-u
 * meets no triangle degenerately gives the answer
 *     inside(v) = inside(u) xor (number of distinct triangles the open
 *                               segment crosses properly is odd),
 * counted with exact orient3d signs (pred.h). A segment that touches a
 * triangle's edge or vertex, has an end on a triangle or lies in its plane
 * is not used (another neighbour is taken): no symbolic perturbation is
 * needed. Triangles with the same three vertex positions count once
 * (duplicated faces). The first `answers` answers are taken; v gets their
 * side when they are unanimous and keeps the vote's sign otherwise, or
 * when no neighbour answered. Confident voxels are never changed and
 * refined voxels read only confident ones, so the result does not depend
 * on the order or the thread count. |values| are kept. */
typedef struct st_sign_refine_params {
    double band_voxels;     /* refine |d| < band voxels; confident >= band */
    int radius;             /* neighbours within this many voxels, 1..3 */
    int answers;            /* answers to combine per voxel, >= 1 */
} st_sign_refine_params;

st_sign_refine_params st_sign_refine_params_default(void);

/* Refine the signs of the signed field g (from st_sign_field) with the
 * soup it was computed from (the same model units). *changed (if not
 * NULL) gets the number of voxels whose sign changed. Records the
 * parameters in g->meta ("sign_refine"). ST_EINPUT for an unsigned field
 * or bad parameters, ST_ENOMEM. */
st_status st_sign_refine(st_grid *g, const st_soup *soup,
                         const st_sign_refine_params *p, size_t *changed,
                         st_error *err);
/* The same with a BVH already built over the soup (bvh->soup), for a
 * caller that keeps one (the pipeline's candidate search). */
st_status st_sign_refine_bvh(st_grid *g, const st_bvh *bvh,
                             const st_sign_refine_params *p, size_t *changed,
                             st_error *err);
/* The same with the soup's triangles in parts, one BVH each: soup holds
 * bvhs[0]->soup's triangles, then bvhs[1]->soup's, ... in order, at the
 * same vertex positions (st_soup_append), so a soup's BVH is reused when
 * triangles are added to it (the hole caps). The field is the one
 * st_sign_refine(g, soup) gives. ST_EINPUT when the parts' triangles do
 * not add up to soup's. */
st_status st_sign_refine_parts(st_grid *g, const st_soup *soup, const st_bvh *const *bvhs,
                               size_t nbvh, const st_sign_refine_params *p, size_t *changed,
                               st_error *err);

#ifdef __cplusplus
}
#endif
#endif
