/*
 * symmetry_fill.c - the lost side of a soup filled from its symmetric copy
 * (symmetry.h, st_symmetry_fill; issue 37).
 *
 * A hole's cap guesses the missing surface from the rim alone: flat, or
 * continuing the faces; a hole too large to cap gets no guess at all.
 * Where the soup is symmetric, the surviving side mapped across the
 * symmetry says what was there. The holes are pieces: each cap's
 * triangles joined by shared edges (one hole each), and each loop of the
 * soup's boundary no cap runs along (an open rim). The fill is every image
 * of a soup triangle that lands where the soup is not (its centroid
 * farther than the tolerance from the soup: the soup wins wherever it is)
 * and in a hole (near a cap, nearer it than the soup; or with an open rim
 * the soup's nearest part), through a map that puts the hole's rim back
 * on the soup (most of its length, and within a voxel on average; where
 * those maps leave a hole open or capped, a second round adds the
 * maps that put back most of what the soup can check of the rim: a large
 * hole's rim, turned, falls partly into the hole itself). A
 * hole's fill is kept only when it closes the hole: it runs along the rim,
 * and its own boundary lies on the soup or on another map's fill (a copy
 * itself holed leaves its holes in the fill, and the cap stays; with
 * mirrors alone, a third round tries there the turns two mirrors make,
 * whose copy can clear the hole where each mirror's overlaps it). A cap
 * the fill closes is dropped where the fill departs from it by more than
 * the map's error: the fill gives that hole its shape, and a flat cap
 * across it would cut the solid the fill bounds; where the two agree the
 * cap stays and the fill is left out. A cap whose fill does not close it
 * is dropped all the same where the fill lies behind it (contradicted:
 * the cap encloses space the copy shows empty). A cap still left that a
 * mirror's fill covers in part is split where the hole straddles the
 * plane (split_caps): the cap kept where the mirror sends the hole onto
 * itself (the copy of what is lost there is lost too), the fill over the
 * rest.
 *
 * Every decision is a distance compared with a tolerance of a voxel: the
 * fill is evidence for the signs (pseudo.c lowers it into the field as it
 * does the caps), never an output surface, so no exact predicate is
 * needed. Per map, the tests run in parallel into a value per triangle;
 * the kept images are appended in triangle order, so the fill does not
 * depend on the thread count.
 */
#include "souptet/symmetry.h"
#include "../base/fpenv.h"
#include "souptet/geom.h"
#include "souptet/mem.h"
#include "../base/unionfind.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#define PI 3.14159265358979323846
#define FILL_ANGLES 24          /* a continuous rotation: every 15 degrees */
#define RIM_REACH 3.0           /* tolerances: a rim point the fill covers */
#define RIM_COVERED 0.75        /* share of the rim's length: a covered cap */
#define RIM_AGREE 0.8           /* share of the rim's checked preimages on the
                                   soup: a map that may fill the piece */
#define RIM_VERIFIED 0.4        /* and the share of the whole rim they are,
                                   where no map verifies RIM_AGREE of it */

/* ---- the holes' pieces ------------------------------------------------------ */

/* A piece is a hole the fill may close: a cap's connected triangles, or a
 * loop of the soup's boundary no cap closes (too large or too long to
 * cap: the open rims). Each is anchored by its triangles (an open rim by
 * one degenerate triangle per edge) in one soup, `anchors`. */
typedef struct pieces {
    size_t n;            /* pieces: the caps' [0, ncap), then the open rims' */
    size_t ncap;
    size_t *of_tri;      /* piece of each anchor triangle */
    double *reach;       /* per piece: half its box diagonal */
    size_t *vrep;        /* each cap vertex's representative (same position) */
    double lo[3], hi[3]; /* the anchors' box, grown by the largest reach */
    double *box;         /* per piece: its anchors' box grown by its reach
                            and a margin (pieces_box), 6 each */
} pieces;

static const double *g_xyz;   /* qsort's context: set just before the call */

static int cmp_pos(const void *a, const void *b)
{
    const double *p = g_xyz + 3 * *(const size_t *)a, *q = g_xyz + 3 * *(const size_t *)b;
    for (int k = 0; k < 3; k++)
        if (p[k] != q[k])
            return p[k] < q[k] ? -1 : 1;
    return *(const size_t *)a < *(const size_t *)b ? -1 : *(const size_t *)a > *(const size_t *)b;
}

static void pieces_free(pieces *P)
{
    free(P->of_tri);
    free(P->reach);
    free(P->vrep);
    free(P->box);
    memset(P, 0, sizeof *P);
}

typedef struct rim_edge {
    size_t piece, a, b;   /* a < b: representatives */
    size_t tri;           /* a cap triangle it bounds (its coordinates) */
    int ia, ib;           /* corners in it */
} rim_edge;

static int cmp_edge(const void *x, const void *y)
{
    const rim_edge *p = x, *q = y;
    if (p->a != q->a)
        return p->a < q->a ? -1 : 1;
    if (p->b != q->b)
        return p->b < q->b ? -1 : 1;
    return p->tri < q->tri ? -1 : p->tri > q->tri;
}

/* The caps' edges (piece SIZE_MAX), sorted by their ends' representatives. */
static rim_edge *cap_edges(const st_soup *caps, const size_t *vrep)
{
    const size_t nt = caps->ntris, ne = 3 * nt;
    rim_edge *e = st_malloc_array(ne ? ne : 1, sizeof *e);
    if (!e)
        return NULL;
    for (size_t t = 0; t < nt; t++)
        for (int k = 0; k < 3; k++) {
            size_t a = vrep[caps->tris[3 * t + k]], b = vrep[caps->tris[3 * t + (k + 1) % 3]];
            e[3 * t + k] = (rim_edge){SIZE_MAX, a < b ? a : b, a < b ? b : a, t, k, (k + 1) % 3};
        }
    qsort(e, ne, sizeof *e, cmp_edge);
    return e;
}

/* Join the caps' vertices that share a position (each cap lists its rim's
 * points again), then the triangles that share an edge: a piece is one
 * hole's cap (two holes' caps meet at most at a vertex, where their loops
 * touch). */
static st_status pieces_make(pieces *P, const st_soup *caps)
{
    memset(P, 0, sizeof *P);
    const size_t nv = caps->nverts, nt = caps->ntris, ne = 3 * nt;
    size_t *order = st_malloc_array(nv ? nv : 1, sizeof *order);
    size_t *uf = st_malloc_array(nt ? nt : 1, sizeof *uf);
    double *box = st_malloc_array(nt ? 6 * nt : 1, sizeof *box);
    P->vrep = st_malloc_array(nv ? nv : 1, sizeof *P->vrep);
    P->of_tri = st_malloc_array(nt ? nt : 1, sizeof *P->of_tri);
    rim_edge *e = NULL;
    st_status rc = order && uf && box && P->vrep && P->of_tri ? ST_OK : ST_ENOMEM;
    if (rc)
        goto done;
    for (size_t v = 0; v < nv; v++)
        order[v] = P->vrep[v] = v;
    g_xyz = caps->xyz;
    qsort(order, nv, sizeof *order, cmp_pos);
    for (size_t i = 1; i < nv; i++)
        if (cmp_pos(order + i - 1, order + i) != 0 &&
            memcmp(caps->xyz + 3 * order[i - 1], caps->xyz + 3 * order[i], 3 * sizeof(double)) == 0)
            uf_join(P->vrep, order[i - 1], order[i]);
    for (size_t v = 0; v < nv; v++)
        P->vrep[v] = uf_find(P->vrep, v);
    if (!(e = cap_edges(caps, P->vrep))) {
        rc = ST_ENOMEM;
        goto done;
    }
    for (size_t t = 0; t < nt; t++)
        uf[t] = t;
    for (size_t i = 1; i < ne; i++)
        if (e[i].a == e[i - 1].a && e[i].b == e[i - 1].b)
            uf_join(uf, e[i - 1].tri, e[i].tri);
    /* pieces numbered by their smallest triangle, in triangle order */
    for (size_t t = 0; t < nt; t++) {
        const size_t r = uf_find(uf, t);
        if (r == t) {
            P->of_tri[t] = P->n++;
            for (int k = 0; k < 3; k++)
                box[6 * P->of_tri[t] + k] = box[6 * P->of_tri[t] + 3 + k] =
                    caps->xyz[3 * caps->tris[3 * t] + k];
        } else {
            P->of_tri[t] = P->of_tri[r];
        }
        double *b = box + 6 * P->of_tri[t];
        for (int c = 0; c < 3; c++)
            for (int k = 0; k < 3; k++) {
                b[k] = fmin(b[k], caps->xyz[3 * caps->tris[3 * t + c] + k]);
                b[3 + k] = fmax(b[3 + k], caps->xyz[3 * caps->tris[3 * t + c] + k]);
            }
    }
    P->reach = st_malloc_array(P->n ? P->n : 1, sizeof *P->reach);
    if (!P->reach) {
        rc = ST_ENOMEM;
        goto done;
    }
    for (size_t i = 0; i < P->n; i++) {
        const double *b = box + 6 * i;
        const double d[3] = {b[3] - b[0], b[4] - b[1], b[5] - b[2]};
        P->reach[i] = 0.5 * st_norm3(d);
    }
    P->ncap = P->n;
done:
    free(order);
    free(uf);
    free(box);
    free(e);
    if (rc)
        pieces_free(P);
    return rc;
}

/* The margin of a piece's box (PIECE_MARGIN of its reach, and of the
 * anchors' coordinates): far above the rounding of a distance, so a
 * point outside the grown box is certainly farther than the reach. */
#define PIECE_MARGIN 1e-6

/* The anchors' box, grown by the largest reach (nothing farther is
 * fill), and each piece's, grown by its reach and the margin. */
static st_status pieces_box(pieces *P, const st_soup *anchors)
{
    double most = 0.0, big = 0.0;
    for (size_t i = 0; i < P->n; i++)
        most = fmax(most, P->reach[i]);
    st_soup_bounds(anchors, P->lo, P->hi, NULL);
    for (int k = 0; k < 3; k++) {
        big = fmax(big, fmax(fabs(P->lo[k]), fabs(P->hi[k])));
        P->lo[k] -= most;
        P->hi[k] += most;
    }
    P->box = st_malloc_array(P->n ? 6 * P->n : 1, sizeof *P->box);
    if (!P->box)
        return ST_ENOMEM;
    for (size_t i = 0; i < 6 * P->n; i++)
        P->box[i] = i % 6 < 3 ? INFINITY : -INFINITY;
    for (size_t t = 0; t < anchors->ntris; t++) {
        double *b = P->box + 6 * P->of_tri[t];
        for (int c = 0; c < 3; c++)
            for (int k = 0; k < 3; k++) {
                const double x = anchors->xyz[3 * (size_t)anchors->tris[3 * t + c] + k];
                b[k] = fmin(b[k], x);
                b[3 + k] = fmax(b[3 + k], x);
            }
    }
    for (size_t i = 0; i < P->n; i++) {
        const double g = P->reach[i] * (1.0 + PIECE_MARGIN) + PIECE_MARGIN * big;
        for (int k = 0; k < 3; k++) {
            P->box[6 * i + k] -= g;
            P->box[6 * i + 3 + k] += g;
        }
    }
    return ST_OK;
}

/* Whether c lies in the grown box of a piece the map may fill: else
 * every anchor of such a piece is farther from c than the piece's reach,
 * and keeps() leaves c's image out whichever anchor is nearest. */
static int near_ok_piece(const pieces *P, const uint8_t *ok, const double c[3])
{
    for (size_t i = 0; i < P->n; i++) {
        const double *b = P->box + 6 * i;
        if (ok[i] && c[0] >= b[0] && c[0] <= b[3] && c[1] >= b[1] && c[1] <= b[4] &&
            c[2] >= b[2] && c[2] <= b[5])
            return 1;
    }
    return 0;
}

/* ---- the maps ----------------------------------------------------------------- */

typedef struct map {
    const st_symmetry *y;
    double angle;
} map;

/* Every map of the set: a mirror, each power of a discrete rotation, and
 * FILL_ANGLES - 1 turns of a continuous one or a helix. */
static size_t maps_of(const st_symmetry_set *set, map *out, size_t max)
{
    size_t n = 0;
    for (size_t i = 0; i < set->n; i++) {
        const st_symmetry *y = set->items + i;
        if (y->kind == ST_SYMMETRY_MIRROR) {
            if (n < max)
                out[n++] = (map){y, 0.0};
            continue;
        }
        const int steps = y->order >= 2 ? y->order : FILL_ANGLES;
        /* a helix by turns of at most half a turn either way: short moves */
        const int back = y->kind == ST_SYMMETRY_HELIX ? steps : 0;
        for (int k = 1; k < steps && n < max; k++)
            out[n++] = (map){y, 2.0 * PI * (k > steps / 2 ? k - back : k) / steps};
        /* and by whole turns, nearest first: a thread moved along itself */
        for (int k = 1; back && k <= FILL_ANGLES / 2; k++)
            for (int sg = 1; sg >= -1 && n < max; sg -= 2)
                out[n++] = (map){y, 2.0 * PI * sg * k};
    }
    return n;
}

/* Two maps within tol of each other over the box lo..hi (its corners:
 * a rigid motion's largest move over a box is at a corner). */
static int same_map(const map *a, const map *b, const double lo[3], const double hi[3],
                    double tol)
{
    for (int c = 0; c < 8; c++) {
        const double x[3] = {c & 1 ? hi[0] : lo[0], c & 2 ? hi[1] : lo[1], c & 4 ? hi[2] : lo[2]};
        double p[3], q[3], d[3];
        st_symmetry_apply(a->y, a->angle, x, 1, p);
        st_symmetry_apply(b->y, b->angle, x, 1, q);
        for (int k = 0; k < 3; k++)
            d[k] = p[k] - q[k];
        if (st_norm3(d) > tol)
            return 0;
    }
    return 1;
}

/* The rotation that mirror a then mirror b make (both symmetries, so it
 * is one: about the line where the planes meet, by twice the angle from
 * a's normal to b's) into *rot and its angle; 0 where the planes are
 * parallel (a move, not a turn). The line's point: the one nearest the
 * midpoint of the planes' points. */
static int composed(st_symmetry *rot, double *angle, const st_symmetry *a, const st_symmetry *b)
{
    double u[3];
    st_cross3(u, a->dir, b->dir);
    const double sn = st_norm3(u), cs = st_dot3(a->dir, b->dir), det = 1.0 - cs * cs;
    if (!(sn > 0.0) || !(det > 0.0))
        return 0;
    double c[3];
    for (int k = 0; k < 3; k++)
        c[k] = 0.5 * (a->point[k] + b->point[k]);
    const double ra = st_dot3(a->dir, a->point) - st_dot3(a->dir, c);
    const double rb = st_dot3(b->dir, b->point) - st_dot3(b->dir, c);
    const double ka = (ra - cs * rb) / det, kb = (rb - cs * ra) / det;
    *rot = (st_symmetry){.kind = ST_SYMMETRY_ROTATION, .order = 0,
                         .support = fmin(a->support, b->support)};
    for (int k = 0; k < 3; k++) {
        rot->point[k] = c[k] + ka * a->dir[k] + kb * b->dir[k];
        rot->dir[k] = u[k] / sn;
    }
    *angle = 2.0 * atan2(sn, cs);
    return 1;
}

static double tri_area(const double q[3][3]);

#define TURN_SAMPLES 2048      /* soup triangles a turn is checked on */
#define TURN_CONTRADICTED 0.07 /* at most this share of what the soup can
                                  check contradicts a turn (measured:
                                  pinion-symholes' turns 0.004-0.063;
                                  rotor-deleted50's and couplingdown-
                                  onesided's, their planes a few degrees
                                  apart, 0.075 and more) */

/* Whether turn m holds on soup s (bvh: its tree; bounds: its boundary
 * edges', NULL: none): of s's triangles (at most TURN_SAMPLES, evenly by
 * index), by area, those whose centroid m puts within tol of s are
 * verified, the others contradicted where s's nearest point is off its
 * boundary (else in a hole, unchecked); at most TURN_CONTRADICTED of the
 * verified and contradicted area. The turn of two exact mirrors is
 * exact; of two approximate ones, it may not be. */
static int turn_holds(const st_soup *s, const st_bvh *bvh, const st_bvh *bounds, const map *m,
                      double tol)
{
    const size_t step = s->ntris / TURN_SAMPLES + 1;
    double on = 0.0, con = 0.0;
    for (size_t t = 0; t < s->ntris; t += step) {
        double q[3][3], c[3], p[3];
        for (int k = 0; k < 3; k++)
            for (int a = 0; a < 3; a++)
                q[k][a] = s->xyz[3 * (size_t)s->tris[3 * t + k] + a];
        for (int a = 0; a < 3; a++)
            c[a] = (q[0][a] + q[1][a] + q[2][a]) / 3.0;
        st_symmetry_apply(m->y, m->angle, c, 1, p);
        const double w = tri_area(q);
        if (st_bvh_within(bvh, p, tol * tol)) {
            on += w;
            continue;
        }
        int64_t tri, edge = -1;
        const double d2 = st_bvh_nearest(bvh, p, INFINITY, &tri, NULL);
        if (bounds && tri >= 0) {
            const double slack = sqrt(d2) + 1e-6 * tol;
            st_bvh_nearest(bounds, p, slack * slack, &edge, NULL);
        }
        con += edge < 0 ? w : 0.0;
    }
    return on > 0.0 && con <= TURN_CONTRADICTED * (on + con);
}

/* Where the set has mirrors and no rotation (a gear whose axis detection
 * missed: pinion-symholes finds 5 of its 10 planes and no axis), the
 * turns two mirrors make, each way: a mirror's copy of a large hole
 * overlaps the hole (its own holes would stay in the fill), a turn's can
 * clear it. Rotations into rot (room for ST_SYMMETRY_MAX^2 / 2), maps
 * into out after its n; each new map at least tol away from the others
 * over the box lo..hi, and holding on soup s (turn_holds). Returns the
 * new n. */
static size_t mirror_turns(st_symmetry *rot, map *out, size_t n, size_t max,
                           const st_symmetry_set *set, const double lo[3], const double hi[3],
                           double tol, const st_soup *s, const st_bvh *bvh,
                           const st_bvh *bounds)
{
    for (size_t i = 0; i < set->n; i++)
        if (set->items[i].kind != ST_SYMMETRY_MIRROR)
            return n;
    size_t nr = 0;
    for (size_t i = 0; i < set->n; i++)
        for (size_t j = i + 1; j < set->n; j++) {
            double angle;
            if (!composed(rot + nr, &angle, set->items + i, set->items + j))
                continue;
            const map two[2] = {{rot + nr, angle}, {rot + nr, -angle}};
            int fresh = 0;
            for (int w = 0; w < 2 && n < max; w++) {
                int seen = 0;
                for (size_t m = 0; m < n && !seen; m++)
                    seen = same_map(out + m, two + w, lo, hi, tol);
                if (!seen && turn_holds(s, bvh, bounds, two + w, tol)) {
                    out[n++] = two[w];
                    fresh = 1;
                }
            }
            nr += fresh;
        }
    return n;
}

/* The image of triangle t under m, re-oriented for a mirror. */
static void image(const st_soup *s, size_t t, const map *m, double q[3][3])
{
    const uint32_t *c = s->tris + 3 * t;
    const int flip = m->y->kind == ST_SYMMETRY_MIRROR;
    for (int k = 0; k < 3; k++)
        st_symmetry_apply(m->y, m->angle, s->xyz + 3 * c[flip && k ? 3 - k : k], 1, q[k]);
}

/* image()'s corners taken from vimg, the images of s's vertices under m
 * (the same values: each corner's image is its vertex's). */
static void image_from(const st_soup *s, size_t t, const map *m, const double *vimg,
                       double q[3][3])
{
    const uint32_t *c = s->tris + 3 * t;
    const int flip = m->y->kind == ST_SYMMETRY_MIRROR;
    for (int k = 0; k < 3; k++)
        memcpy(q[k], vimg + 3 * (size_t)c[flip && k ? 3 - k : k], 3 * sizeof(double));
}

typedef struct fill_ctx {
    const st_soup *s;
    const st_bvh *bvh, *anchors_bvh, *fill_bvh;   /* fill_bvh: the maps before */
    const st_bvh *bounds;      /* the soup's boundary edges (NULL: none) */
    const pieces *P;
    const uint8_t *piece_ok;   /* the map agrees with the piece's rim */
    double tol;
    double reach2;             /* above the largest piece_ok reach squared
                                  (0: the anchors' whole box) */
    const st_soup *caps;       /* the caps (the anchors' first triangles) */
} fill_ctx;

/* st_bvh_within(b, c, d2), trying *hint first; *hint becomes the
 * triangle that answered (kept when none did). */
static int within(const st_bvh *b, const double c[3], double d2, uint32_t *hint)
{
    uint32_t found;
    const int r = st_bvh_within_hint(b, c, d2, hint, 1, &found);
    if (found != ST_BVH_NO_HINT)
        *hint = found;
    return r;
}

/* The piece image q fills, or SIZE_MAX. It must be off the soup (farther
 * than tol: the soup wins wherever it is) and in a hole: within its
 * piece's reach and, for a cap, nearer the cap than the soup; for an open
 * rim (which is on the soup), with the rim the soup's nearest part, to
 * within tol, so an image beside a wall the rim is not on adds nothing. */
static size_t keeps(const fill_ctx *C, const double q[3][3], uint32_t hint[3])
{
    double c[3];
    for (int k = 0; k < 3; k++) {
        c[k] = (q[0][k] + q[1][k] + q[2][k]) / 3.0;
        if (c[k] < C->P->lo[k] || c[k] > C->P->hi[k])
            return SIZE_MAX;
    }
    if (!near_ok_piece(C->P, C->piece_ok, c))
        return SIZE_MAX;
    /* the soup wins wherever it is: the tests below (bound >= tol2) */
    const double tol2 = C->tol * C->tol;
    /* hint: the triangles these tests found last (the soup's, the fill's,
     * the soup's against bound), tried first (st_bvh_within_hint: the
     * same answers) */
    if (within(C->bvh, c, tol2, hint) || (C->fill_bvh && within(C->fill_bvh, c, tol2, hint + 1)))
        return SIZE_MAX;
    int64_t tri;
    const double most = C->P->hi[0] - C->P->lo[0] + C->P->hi[1] - C->P->lo[1] +
                        C->P->hi[2] - C->P->lo[2];
    /* an anchor no nearer than every reach the map may fill leaves the
     * image out whichever it is: the search stops there (the nearest
     * within it is the one the whole search finds) */
    const double far2 = C->reach2 > 0.0 && C->reach2 < most * most ? C->reach2 : most * most;
    const double d2 = st_bvh_nearest(C->anchors_bvh, c, far2, &tri, NULL);
    if (tri < 0)
        return SIZE_MAX;
    const size_t i = C->P->of_tri[tri];
    if (!C->piece_ok[i] || d2 > C->P->reach[i] * C->P->reach[i])
        return SIZE_MAX;
    const double near = sqrt(d2) - C->tol;
    const double bound = i < C->P->ncap ? fmax(tol2, d2) : near > C->tol ? near * near : tol2;
    return within(C->bvh, c, bound, hint + 2) ? SIZE_MAX : i;
}

/* ---- the rims ------------------------------------------------------------------ */

/* The holes' rims: the caps' (the edges in one cap triangle of their piece
 * alone), then the open rims' edges; each by its ends (the lexically
 * smaller first), midpoint, length and piece. */
typedef struct rims {
    size_t n, cap;
    double *ends;     /* 6n */
    double *mid;      /* 3n */
    double *len;      /* n */
    size_t *piece;    /* n */
    size_t *tri;      /* n: a cap triangle the edge bounds (SIZE_MAX: an
                         open rim's) */
} rims;

static void rims_free(rims *R)
{
    free(R->ends);
    free(R->mid);
    free(R->len);
    free(R->piece);
    free(R->tri);
    memset(R, 0, sizeof *R);
}

/* p reallocated to n items of size bytes, or p itself and *fail set. */
static void *grown(void *p, size_t n, size_t size, int *fail)
{
    void *q = realloc(p, n * size);
    if (!q)
        *fail = 1;
    return q ? q : p;
}

static st_status rims_grow(rims *R, size_t more)
{
    if (R->n + more <= R->cap)
        return ST_OK;
    const size_t cap = 2 * (R->n + more);
    int fail = 0;
    R->ends = grown(R->ends, 6 * cap, sizeof *R->ends, &fail);
    R->mid = grown(R->mid, 3 * cap, sizeof *R->mid, &fail);
    R->len = grown(R->len, cap, sizeof *R->len, &fail);
    R->piece = grown(R->piece, cap, sizeof *R->piece, &fail);
    R->tri = grown(R->tri, cap, sizeof *R->tri, &fail);
    if (fail)
        return ST_ENOMEM;
    R->cap = cap;
    return ST_OK;
}

/* Ends p, q in lexical order into e[6]. */
static void ends_of(double e[6], const double p[3], const double q[3])
{
    int swap = 0;
    for (int k = 0; k < 3; k++)
        if (p[k] != q[k]) {
            swap = q[k] < p[k];
            break;
        }
    memcpy(e, swap ? q : p, 3 * sizeof *e);
    memcpy(e + 3, swap ? p : q, 3 * sizeof *e);
}

static st_status rims_add(rims *R, const double p[3], const double q[3], size_t piece,
                          size_t tri)
{
    if (rims_grow(R, 1))
        return ST_ENOMEM;
    const double d[3] = {q[0] - p[0], q[1] - p[1], q[2] - p[2]};
    ends_of(R->ends + 6 * R->n, p, q);
    for (int k = 0; k < 3; k++)
        R->mid[3 * R->n + k] = 0.5 * (p[k] + q[k]);
    R->len[R->n] = st_norm3(d);
    R->tri[R->n] = tri;
    R->piece[R->n++] = piece;
    return ST_OK;
}

static st_status rims_make(rims *R, const st_soup *caps, const pieces *P)
{
    memset(R, 0, sizeof *R);
    const size_t ne = 3 * caps->ntris;
    rim_edge *e = cap_edges(caps, P->vrep);
    if (!e)
        return ST_ENOMEM;
    st_status rc = ST_OK;
    for (size_t i = 0; i < ne && !rc;) {
        size_t j = i + 1;
        while (j < ne && e[j].a == e[i].a && e[j].b == e[i].b)
            j++;
        if (j == i + 1 && e[i].a != e[i].b) {
            const uint32_t *c = caps->tris + 3 * e[i].tri;
            rc = rims_add(R, caps->xyz + 3 * c[e[i].ia], caps->xyz + 3 * c[e[i].ib],
                          P->of_tri[e[i].tri], e[i].tri);
        }
        i = j;
    }
    free(e);
    if (rc)
        rims_free(R);
    return rc;
}

static int cmp_ends(const void *x, const void *y)
{
    const double *p = x, *q = y;
    for (int k = 0; k < 6; k++)
        if (p[k] != q[k])
            return p[k] < q[k] ? -1 : 1;
    return 0;
}

/* Whether the edge run at half-edge i of E is a boundary edge of s (in
 * one triangle alone): then its triangle *t and its ends' corners in it. */
static int boundary_at(const st_soup_edges *E, const st_soup *s, size_t i, uint32_t *t,
                       int *ca, int *cb)
{
    if (st_soup_edges_run_end(E, i) != i + 1)
        return 0;
    *t = E->he[i].t;
    *ca = st_soup_edges_corner(E, s, *t, (uint32_t)(E->he[i].key >> 32));
    *cb = st_soup_edges_corner(E, s, *t, (uint32_t)E->he[i].key);
    return *ca >= 0 && *cb >= 0;
}

/* The soup's boundary edges (E: its table) as degenerate triangles of
 * out: ends and midpoint, for the nearest boundary point. */
static st_status bounds_make(st_soup *out, const st_soup *s, const st_soup_edges *E,
                             st_error *err)
{
    st_status rc = ST_OK;
    for (size_t i = 0; i < E->nhalf && !rc; i = st_soup_edges_run_end(E, i)) {
        uint32_t t;
        int ca, cb;
        if (!boundary_at(E, s, i, &t, &ca, &cb))
            continue;
        const double *p = s->xyz + 3 * s->tris[3 * t + ca], *q = s->xyz + 3 * s->tris[3 * t + cb];
        const uint32_t base = (uint32_t)out->nverts;
        rc = st_soup_add_vertex(out, p[0], p[1], p[2], err);
        rc = rc ? rc : st_soup_add_vertex(out, q[0], q[1], q[2], err);
        rc = rc ? rc : st_soup_add_vertex(out, 0.5 * (p[0] + q[0]), 0.5 * (p[1] + q[1]),
                                          0.5 * (p[2] + q[2]), err);
        rc = rc ? rc : st_soup_add_triangle(out, base, base + 1, base + 2, err);
    }
    return rc;
}

/* The open rims: the soup's boundary edges (edges: s's table) whose
 * midpoint is farther than tol from every cap (caps_bvh; NULL: none): a
 * cap runs along every edge of the loop it closes, joined or not to the
 * rim's vertices. They are joined into pieces by shared welded ends, and
 * a piece is kept when it is a loop (two of its edges at every vertex:
 * a hole too large or too long to cap, not the edges left open where
 * holes touch); each becomes a piece after the caps', its edges rims of R
 * and degenerate triangles of anchors. */
static st_status open_rims(pieces *P, rims *R, st_soup *anchors, const st_soup *s,
                           const st_soup_edges *E, const st_bvh *caps_bvh, double tol,
                           st_error *err)
{
    const size_t nw = E->nweld ? E->nweld : 1;
    size_t *uf = st_malloc_array(nw, sizeof *uf), *id = st_malloc_array(nw, sizeof *id);
    uint32_t *deg = calloc(nw, sizeof *deg);
    uint8_t *bad = calloc(nw, 1);
    st_status rc = uf && id && deg && bad ? ST_OK : ST_ENOMEM;
    if (rc)
        goto done;
    for (size_t w = 0; w < nw; w++) {
        uf[w] = w;
        id[w] = SIZE_MAX;
    }
    /* the open edges: their welded ends joined, then numbered in order */
    const size_t first = R->n;
    for (size_t i = 0; i < E->nhalf && !rc; i = st_soup_edges_run_end(E, i)) {
        uint32_t t;
        int ca, cb;
        if (!boundary_at(E, s, i, &t, &ca, &cb))
            continue;
        const uint32_t wa = (uint32_t)(E->he[i].key >> 32), wb = (uint32_t)E->he[i].key;
        const double *p = s->xyz + 3 * s->tris[3 * t + ca], *q = s->xyz + 3 * s->tris[3 * t + cb];
        const double m[3] = {0.5 * (p[0] + q[0]), 0.5 * (p[1] + q[1]), 0.5 * (p[2] + q[2])};
        int64_t near = -1;
        if (caps_bvh)
            st_bvh_nearest(caps_bvh, m, tol * tol, &near, NULL);
        if (near >= 0)
            continue;
        uf_join(uf, wa, wb);
        deg[wa]++;
        deg[wb]++;
        rc = rims_add(R, p, q, wa, SIZE_MAX);   /* piece: its welded end, for now */
    }
    /* a loop: two open edges at every vertex; the edges the holes left
     * open where loops touch (a vertex of other degree) stay as they are */
    for (size_t w = 0; w < nw; w++)
        if (deg[w] && deg[w] != 2)
            bad[uf_find(uf, w)] = 1;
    size_t kept = first;
    for (size_t r = first; r < R->n; r++) {
        if (bad[uf_find(uf, R->piece[r])])
            continue;
        memmove(R->ends + 6 * kept, R->ends + 6 * r, 6 * sizeof *R->ends);
        memmove(R->mid + 3 * kept, R->mid + 3 * r, 3 * sizeof *R->mid);
        R->len[kept] = R->len[r];
        R->tri[kept] = R->tri[r];
        R->piece[kept++] = R->piece[r];
    }
    R->n = kept;
    size_t *of = rc ? NULL : realloc(P->of_tri, (anchors->ntris + R->n - first + 1) * sizeof *of);
    if (!rc && !of)
        rc = ST_ENOMEM;
    else if (of)
        P->of_tri = of;
    double *box = NULL;
    for (size_t r = first; r < R->n && !rc; r++) {
        const size_t root = uf_find(uf, R->piece[r]);
        if (id[root] == SIZE_MAX) {
            double *b2 = realloc(box, 6 * (P->n - P->ncap + 1) * sizeof *b2);
            if (!b2) {
                rc = ST_ENOMEM;
                break;
            }
            box = b2;
            id[root] = P->n++;
            memcpy(box + 6 * (id[root] - P->ncap), R->ends + 6 * r, 6 * sizeof *box);
        }
        const size_t i = R->piece[r] = id[root];
        double *b = box + 6 * (i - P->ncap);
        for (int k = 0; k < 3; k++) {
            b[k] = fmin(b[k], fmin(R->ends[6 * r + k], R->ends[6 * r + 3 + k]));
            b[3 + k] = fmax(b[3 + k], fmax(R->ends[6 * r + k], R->ends[6 * r + 3 + k]));
        }
        const size_t base = anchors->nverts;
        for (int v = 0; v < 3 && !rc; v++) {
            const double *x = v == 0 ? R->ends + 6 * r : v == 1 ? R->ends + 6 * r + 3 : R->mid + 3 * r;
            rc = st_soup_add_vertex(anchors, x[0], x[1], x[2], err);
        }
        P->of_tri[anchors->ntris] = i;
        rc = rc ? rc : st_soup_add_triangle(anchors, (uint32_t)base, (uint32_t)base + 1,
                                            (uint32_t)base + 2, err);
    }
    double *reach = rc ? NULL : realloc(P->reach, (P->n ? P->n : 1) * sizeof *reach);
    if (!rc && !reach)
        rc = ST_ENOMEM;
    for (size_t i = P->ncap; i < P->n && !rc; i++) {
        const double *b = box + 6 * (i - P->ncap);
        const double d[3] = {b[3] - b[0], b[4] - b[1], b[5] - b[2]};
        reach[i] = 0.5 * st_norm3(d);
    }
    if (reach)
        P->reach = reach;
    free(box);
done:
    free(deg);
    free(bad);
    free(uf);
    free(id);
    return rc;
}

/* share[i]: the share of piece i's rim length whose midpoint `near`
 * holds for; near(ctx, point) says whether a point is covered. total (if
 * not NULL) gets each piece's rim length. */
static void rim_share(double *share, size_t npieces, const rims *R,
                      int (*near)(const void *, const double[3]), const void *ctx,
                      double *total)
{
    for (size_t i = 0; i < 2 * npieces; i++)
        share[i] = 0.0;
    for (size_t r = 0; r < R->n; r++) {
        share[2 * R->piece[r]] += R->len[r];
        if (near(ctx, R->mid + 3 * r))
            share[2 * R->piece[r] + 1] += R->len[r];
    }
    for (size_t i = 0; i < npieces; i++) {
        if (total)
            total[i] = share[2 * i];
        share[i] = share[2 * i] > 0.0 ? share[2 * i + 1] / share[2 * i] : 0.0;
    }
}

typedef struct near_ctx {
    const st_bvh *bvh;
    double reach2;
    const map *inverse;   /* NULL: the point itself */
} near_ctx;

static int near_bvh(const void *ctx, const double x[3])
{
    const near_ctx *N = ctx;
    double q[3];
    if (N->inverse)
        st_symmetry_apply(N->inverse->y, N->inverse->angle, x, 1, q);
    else
        memcpy(q, x, sizeof q);
    return N->bvh && st_bvh_within(N->bvh, q, N->reach2);
}

/* err[i]: the map's error at piece i: the length-weighted mean distance
 * from the soup of the preimages of the rim's midpoints (back: the map's
 * inverse), over the rim edges within back's reach (those rim_share
 * counts). */
static void rim_error(double *err, size_t npieces, const rims *R, const near_ctx *back,
                      double *weight)
{
    for (size_t i = 0; i < npieces; i++)
        err[i] = weight[i] = 0.0;
    for (size_t r = 0; r < R->n; r++) {
        double q[3];
        st_symmetry_apply(back->inverse->y, back->inverse->angle, R->mid + 3 * r, 1, q);
        int64_t tri;
        const double d2 = st_bvh_nearest(back->bvh, q, back->reach2, &tri, NULL);
        if (tri < 0)
            continue;
        err[R->piece[r]] += R->len[r] * sqrt(d2);
        weight[R->piece[r]] += R->len[r];
    }
    for (size_t i = 0; i < npieces; i++)
        err[i] = weight[i] > 0.0 ? err[i] / weight[i] : 0.0;
}

/* The preimages of the rims' midpoints under back's inverse, by length per
 * piece: ver[i] the share of piece i's rim within back's reach of the
 * soup (verified), con[i] the share farther whose nearest soup point is
 * off the soup's boundary (contradicted: the soup was seen all around
 * that place and is not where the map puts the rim). The rest lands in a
 * hole (the soup's nearest point on a boundary edge, bounds: those edges;
 * NULL: none), where the soup cannot say: a rotation of a large hole's rim
 * falls partly into the hole itself. */
static void rim_checks(double *ver, double *con, size_t npieces, const rims *R,
                       const near_ctx *back, const st_bvh *bounds, double tol)
{
    double *total = con + npieces;   /* con has 2 npieces: total gets the
                                        rim's length */
    for (size_t i = 0; i < npieces; i++)
        ver[i] = con[i] = total[i] = 0.0;
    for (size_t r = 0; r < R->n; r++) {
        double q[3];
        st_symmetry_apply(back->inverse->y, back->inverse->angle, R->mid + 3 * r, 1, q);
        int64_t tri, edge = -1;
        /* without bounds, a preimage beyond reach is contradicted however
         * far: the search stops at the reach */
        const double d2 = st_bvh_nearest(back->bvh, q, bounds ? INFINITY : back->reach2, &tri,
                                         NULL);
        const size_t i = R->piece[r];
        total[i] += R->len[r];
        if (tri >= 0 && d2 < back->reach2) {
            ver[i] += R->len[r];
            continue;
        }
        if (bounds && tri >= 0) {
            const double slack = sqrt(d2) + 1e-6 * tol;
            st_bvh_nearest(bounds, q, slack * slack, &edge, NULL);
        }
        con[i] += edge < 0 ? R->len[r] : 0.0;
    }
    for (size_t i = 0; i < npieces; i++)
        if (total[i] > 0.0) {
            ver[i] /= total[i];
            con[i] /= total[i];
        }
}

/* ---- the fill ----------------------------------------------------------------- */

typedef struct fill_set {
    st_soup *soup;        /* each triangle of its own three vertices */
    size_t *piece, *map;  /* per triangle */
    size_t *src;          /* per triangle: the soup triangle it is the image of */
    double *err;          /* per triangle: its map's error at its piece */
    uint8_t *rim;         /* per soup triangle: bit k when its edge k (corners
                             k, k + 1) is a boundary edge (NULL: unknown) */
    const map *maps;      /* the maps F->map indexes */
    size_t cap;
} fill_set;

static double tri_area(const double q[3][3])
{
    double u[3], v[3], n[3];
    for (int k = 0; k < 3; k++) {
        u[k] = q[1][k] - q[0][k];
        v[k] = q[2][k] - q[0][k];
    }
    st_cross3(n, u, v);
    return 0.5 * st_norm3(n);
}

/* A triangle of its own three vertices, appended to out. */
static st_status add_tri(st_soup *out, const double q[3][3], st_error *err)
{
    const size_t base = out->nverts;
    st_status rc = ST_OK;
    for (int k = 0; k < 3 && !rc; k++)
        rc = st_soup_add_vertex(out, q[k][0], q[k][1], q[k][2], err);
    return rc ? rc : st_soup_add_triangle(out, (uint32_t)base, (uint32_t)(base + 1),
                                          (uint32_t)(base + 2), err);
}

/* Append the images under map mi of s's triangles whose keep[] names a
 * piece (not SIZE_MAX). */
static st_status append_images(fill_set *F, const st_soup *s, const map *maps, size_t mi,
                               const size_t *keep, const double *map_err, st_error *err)
{
    for (size_t t = 0; t < s->ntris; t++) {
        if (keep[t] == SIZE_MAX)
            continue;
        if (F->soup->ntris >= F->cap) {
            const size_t cap = 2 * F->cap + 64;
            int fail = 0;
            F->piece = grown(F->piece, cap, sizeof *F->piece, &fail);
            F->map = grown(F->map, cap, sizeof *F->map, &fail);
            F->err = grown(F->err, cap, sizeof *F->err, &fail);
            F->src = grown(F->src, cap, sizeof *F->src, &fail);
            if (fail)
                return ST_ENOMEM;
            F->cap = cap;
        }
        F->piece[F->soup->ntris] = keep[t];
        F->map[F->soup->ntris] = mi;
        F->src[F->soup->ntris] = t;
        F->err[F->soup->ntris] = map_err[keep[t]];
        double q[3][3];
        image(s, t, maps + mi, q);
        st_status rc = add_tri(F->soup, q, err);
        if (rc)
            return rc;
    }
    return ST_OK;
}

/* ---- closed: the fill's boundary on the soup --------------------------------- */

typedef struct fill_edge {
    double e[6];
    size_t tri;
    int k;
} fill_edge;

static int cmp_fill_edge(const void *x, const void *y)
{
    const fill_edge *p = x, *q = y;
    const int c = cmp_ends(p->e, q->e);
    return c ? c : p->tri < q->tri ? -1 : p->tri > q->tri;
}

typedef struct other_ctx {
    const fill_set *F;
    size_t map;
    const double *x;
    double reach2;
} other_ctx;

/* A fill triangle of another map within reach of x: 1. */
static int near_other(void *ctx, uint32_t t)
{
    const other_ctx *O = ctx;
    if (O->F->map[t] == O->map)
        return 0;
    const double *v = O->F->soup->xyz;
    const uint32_t *c = O->F->soup->tris + 3 * (size_t)t;
    return st_point_triangle_dist2(O->x, v + 3 * c[0], v + 3 * c[1], v + 3 * c[2], NULL) <=
           O->reach2;
}

/* The soup's boundary edges as bits per triangle (fill_set.rim). */
static uint8_t *rim_bits(const st_soup *s, const st_soup_edges *E)
{
    uint8_t *rim = calloc(s->ntris ? s->ntris : 1, 1);
    if (!rim)
        return NULL;
    for (size_t i = 0; i < E->nhalf; i = st_soup_edges_run_end(E, i)) {
        uint32_t t;
        int ca, cb;
        if (boundary_at(E, s, i, &t, &ca, &cb))
            rim[t] |= (uint8_t)(1u << ((ca + 1) % 3 == cb ? ca : cb));
    }
    return rim;
}

/* Whether fill triangle t's edge k (image corners k, k + 1) is the image
 * of a boundary edge of the soup (a hole in the copy); every edge when the
 * soup's boundary is unknown. */
static int copy_rim(const fill_set *F, size_t t, int k)
{
    if (!F->rim)
        return 1;
    const int flip = F->maps[F->map[t]].y->kind == ST_SYMMETRY_MIRROR;
    const int c1 = flip && k ? 3 - k : k, k2 = (k + 1) % 3, c2 = flip && k2 ? 3 - k2 : k2;
    const int edge = (c1 + 1) % 3 == c2 ? c1 : c2;
    return (F->rim[F->src[t]] >> edge) & 1;
}

/* open[i]: the length of piece i's fill boundary that is the image of the
 * copy's own rim and lies farther than reach from the soup and from every
 * other map's fill: where the fill, its copy itself holed, leaves the hole
 * open (where an image was left out beside the soup or another map's fill,
 * the fill has an edge too, but no hole of the copy). A fill boundary edge
 * is an edge in one fill triangle alone (the images of one map share their
 * corners' coordinates exactly where the soup's triangles share them). */
static st_status open_length(double *open, size_t npieces, const fill_set *F,
                             const st_bvh *bvh, const st_bvh *fill_bvh, double reach)
{
    const st_soup *f = F->soup;
    const size_t ne = 3 * f->ntris;
    for (size_t i = 0; i < npieces; i++)
        open[i] = 0.0;
    if (!ne)
        return ST_OK;
    fill_edge *e = st_malloc_array(ne, sizeof *e);
    if (!e)
        return ST_ENOMEM;
    for (size_t t = 0; t < f->ntris; t++)
        for (int k = 0; k < 3; k++) {
            const uint32_t *c = f->tris + 3 * t;
            ends_of(e[3 * t + k].e, f->xyz + 3 * c[k], f->xyz + 3 * c[(k + 1) % 3]);
            e[3 * t + k].tri = t;
            e[3 * t + k].k = k;
        }
    qsort(e, ne, sizeof *e, cmp_fill_edge);
    for (size_t i = 0; i < ne;) {
        size_t j = i + 1;
        while (j < ne && cmp_ends(e[j].e, e[i].e) == 0)
            j++;
        if (j == i + 1 && copy_rim(F, e[i].tri, e[i].k)) {
            const double *p = e[i].e, *q = e[i].e + 3;
            const double m[3] = {0.5 * (p[0] + q[0]), 0.5 * (p[1] + q[1]), 0.5 * (p[2] + q[2])};
            const double d[3] = {q[0] - p[0], q[1] - p[1], q[2] - p[2]};
            int64_t tri;
            st_bvh_nearest(bvh, m, reach * reach, &tri, NULL);
            other_ctx O = {F, F->map[e[i].tri], m, reach * reach};
            const double lo[3] = {m[0] - reach, m[1] - reach, m[2] - reach};
            const double hi[3] = {m[0] + reach, m[1] + reach, m[2] + reach};
            if (tri < 0 && !st_bvh_query_box(fill_bvh, lo, hi, near_other, &O))
                open[F->piece[e[i].tri]] += st_norm3(d);
        }
        i = j;
    }
    free(e);
    return ST_OK;
}

/* kept: the caps' triangles outside the covered pieces, and those of a
 * split cap it keeps (cap_keep: 0 elsewhere), their vertices shared as in
 * caps. */
static st_status keep_uncovered(st_soup *kept, const st_soup *caps, const pieces *P,
                                const uint8_t *covered, const uint8_t *cap_keep, st_error *err)
{
    size_t *to = st_malloc_array(caps->nverts ? caps->nverts : 1, sizeof *to);
    if (!to)
        return ST_ENOMEM;
    st_status rc = ST_OK;
    for (size_t v = 0; v < caps->nverts; v++)
        to[v] = SIZE_MAX;
    for (size_t t = 0; t < caps->ntris && !rc; t++) {
        if (covered[P->of_tri[t]] && !(cap_keep && cap_keep[t]))
            continue;
        uint32_t w[3];
        for (int k = 0; k < 3 && !rc; k++) {
            const uint32_t v = caps->tris[3 * t + k];
            if (to[v] == SIZE_MAX) {
                to[v] = kept->nverts;
                rc = st_soup_add_vertex(kept, caps->xyz[3 * v], caps->xyz[3 * v + 1],
                                        caps->xyz[3 * v + 2], err);
            }
            w[k] = (uint32_t)to[v];
        }
        rc = rc ? rc : st_soup_add_triangle(kept, w[0], w[1], w[2], err);
    }
    free(to);
    return rc;
}

/* The fill goes all or nothing with its piece: *fill gets the triangles of
 * the covered pieces (where a cap stays, a partial fill beside it would
 * cut the solid the cap closes; where a rim stays open, a partial fill
 * would be a wall the votes cannot read); of a split cap's, those it keeps
 * (fill_keep: the part the cap is dropped from). */
static st_status fill_of_covered(st_soup **fill, const fill_set *F, const uint8_t *covered,
                                 const uint8_t *fill_keep, st_symmetry_fill_stats *st,
                                 st_error *err)
{
    st_soup *in = F->soup, *out = st_soup_new();
    if (!out)
        return ST_ENOMEM;
    for (size_t t = 0; t < in->ntris; t++) {
        if (!covered[F->piece[t]] || (fill_keep && !fill_keep[t]))
            continue;
        double q[3][3];
        for (int k = 0; k < 3; k++)
            for (int a = 0; a < 3; a++)
                q[k][a] = in->xyz[3 * in->tris[3 * t + k] + a];
        st_status rc = add_tri(out, q, err);
        if (rc) {
            st_soup_free(out);
            return rc;
        }
        st->triangles++;
        st->area += tri_area(q);
    }
    *fill = out;
    return ST_OK;
}

/* held[t]: a helix holds at triangle t: the image of its centroid by a
 * turn of 0.382 either way (detection's odd turn) lies within tol of s. A
 * helix may hold on a part only (a thread, not the turned head it
 * carries), and only there are its whole turns a copy. */
static void helix_held(uint8_t *held, const st_soup *s, const st_bvh *bvh,
                       const st_symmetry *y, double tol)
{
    const long long nt = (long long)s->ntris;
#pragma omp parallel for schedule(dynamic, 1024)
    for (long long t = 0; t < nt; t++) {
        double c[3] = {0, 0, 0}, q[3];
        for (int k = 0; k < 3; k++)
            for (int a = 0; a < 3; a++)
                c[a] += s->xyz[3 * (size_t)s->tris[3 * t + k] + a] / 3.0;
        held[t] = 0;
        for (int sg = -1; sg <= 1 && !held[t]; sg += 2) {
            int64_t tri;
            st_symmetry_apply(y, sg * 2.0 * PI * 0.3819660112501051, c, 1, q);
            st_bvh_nearest(bvh, q, tol * tol, &tri, NULL);
            held[t] = tri >= 0;
        }
    }
}

/* ok[i]: map m may fill piece i: its inverse puts the piece's rim back
 * on the soup (RIM_AGREE of the rim's length within RIM_REACH tol of it),
 * and within tol there on average (the map's error, map_err[i]: the
 * issue's "maps onto itself within about a voxel", at the hole). With
 * open (the pieces the maps so verified left open), for those pieces
 * alone: RIM_AGREE of what the soup can check, and RIM_VERIFIED of the
 * rim (a large hole's rim turned falls partly into the hole itself).
 * Returns the rim's length verified over the pieces it may fill (0:
 * none). share: 2 npieces scratch. */
static double map_agrees(uint8_t *ok, double *map_err, double *share, const fill_ctx *C,
                         const rims *R, const map *m, const uint8_t *open)
{
    const pieces *P = C->P;
    const map inv = {m->y, -m->angle};
    const near_ctx back = {C->bvh, RIM_REACH * C->tol * RIM_REACH * C->tol, &inv};
    double *ver = map_err, *con = share, *total = share + P->n;
    rim_checks(ver, con, P->n, R, &back, open ? C->bounds : NULL, C->tol);
    size_t agree = 0;
    for (size_t i = 0; i < P->n; i++) {
        agree += ok[i] = open ? open[i] && ver[i] >= RIM_VERIFIED &&
                                    ver[i] >= RIM_AGREE * (ver[i] + con[i])
                              : ver[i] >= RIM_AGREE;
        share[i] = ver[i] * total[i];   /* the length verified */
    }
    if (!agree)
        return 0.0;
    rim_error(map_err, P->n, R, &back, total);
    double verified = 0.0;
    for (size_t i = 0; i < P->n; i++) {
        ok[i] = ok[i] && map_err[i] <= C->tol;
        verified += ok[i] ? share[i] : 0.0;
    }
    return verified;
}

/* map_agrees, for the pieces where only[i] alone (NULL: all). */
static double agrees_in(uint8_t *ok, double *map_err, double *share, const fill_ctx *C,
                        const rims *R, const map *m, const uint8_t *open, const uint8_t *only)
{
    double verified = map_agrees(ok, map_err, share, C, R, m, open);
    if (!only || verified == 0.0)
        return verified;
    verified = 0.0;
    for (size_t i = 0; i < C->P->n; i++) {
        ok[i] = ok[i] && only[i];
        verified += ok[i] ? share[i] : 0.0;
    }
    return verified;
}

/* order[0..n): the maps by score, highest first, ties by index (an
 * insertion sort: a few hundred maps at most, and no shared state). */
static void by_score(size_t *order, const double *score, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        size_t j = i;
        for (; j > 0 && score[order[j - 1]] < score[i]; j--)
            order[j] = order[j - 1];
        order[j] = i;
    }
}

/* Each map's images into F (the pieces map_agrees gives it, open as
 * there, of those where only[i] (NULL: all); keeps), the maps from first
 * on that verify the most rim first (the first map that covers a place
 * wins there). ok: npieces scratch. */
static st_status map_all(fill_set *F, st_bvh **fill_bvh, const fill_ctx *C0, const rims *R,
                         const map *maps, size_t first, size_t nmaps, const uint8_t *open,
                         const uint8_t *only, size_t *keep, uint8_t *ok, double *share,
                         double *map_err, st_error *err)
{
    const st_soup *s = C0->s;
    st_status rc = ST_OK;
    uint8_t *held = NULL;           /* of held_by, a helix */
    const st_symmetry *held_by = NULL;
    double score[ST_SYMMETRY_MAX * ST_SYMMETRY_DEFAULT_MAX_ORDER];
    size_t order[ST_SYMMETRY_MAX * ST_SYMMETRY_DEFAULT_MAX_ORDER];
    /* each map's ok and map_err, kept from its score for its images */
    const size_t np = C0->P->n ? C0->P->n : 1;
    uint8_t *oks = st_malloc_array(nmaps ? nmaps * np : 1, 1);
    double *errs = st_malloc_array(nmaps ? nmaps * np : 1, sizeof *errs);
    double *vimg = st_malloc_array(s->nverts ? 3 * s->nverts : 1, sizeof *vimg);
    if (!oks || !errs || !vimg) {
        rc = ST_ENOMEM; /* said by the caller */
        goto done;
    }
    for (size_t mi = 0; mi < nmaps; mi++) {
        score[mi] = 0.0;
        if (mi < first)
            continue;
        score[mi] = agrees_in(ok, map_err, share, C0, R, maps + mi, open, only);
        memcpy(oks + mi * np, ok, C0->P->n);
        memcpy(errs + mi * np, map_err, C0->P->n * sizeof *errs);
    }
    by_score(order, score, nmaps);
    for (size_t oi = 0; oi < nmaps && score[order[oi]] > 0.0; oi++) {
        const size_t mi = order[oi];
        memcpy(ok, oks + mi * np, C0->P->n);
        memcpy(map_err, errs + mi * np, C0->P->n * sizeof *errs);
        const int helix = maps[mi].y->kind == ST_SYMMETRY_HELIX;
        if (helix && held_by != maps[mi].y) {
            if (!held && !(held = st_malloc_array(s->ntris ? s->ntris : 1, 1))) {
                rc = ST_ENOMEM; /* said by the caller */
                goto done;
            }
            helix_held(held, s, C0->bvh, held_by = maps[mi].y, C0->tol);
        }
        fill_ctx C = *C0;
        C.fill_bvh = *fill_bvh;
        C.piece_ok = ok;
        for (size_t i = 0; i < C0->P->n; i++)
            if (ok[i])
                C.reach2 = fmax(C.reach2, C0->P->reach[i] * C0->P->reach[i]);
        C.reach2 = nextafter(C.reach2, INFINITY);
        const long long nt = (long long)s->ntris, nv = (long long)s->nverts;
#pragma omp parallel for schedule(static)
        for (long long v = 0; v < nv; v++)
            st_symmetry_apply(maps[mi].y, maps[mi].angle, s->xyz + 3 * v, 1, vimg + 3 * v);
        size_t any = 0;
        /* the images of triangles in order lie near one another: each
         * thread's tests pass on what they found (keeps' hint) */
#pragma omp parallel reduction(+ : any)
        {
            uint32_t hint[3] = {ST_BVH_NO_HINT, ST_BVH_NO_HINT, ST_BVH_NO_HINT};
#pragma omp for schedule(dynamic, 1024)
            for (long long t = 0; t < nt; t++) {
                double q[3][3];
                image_from(s, (size_t)t, maps + mi, vimg, q);
                keep[t] = helix && !held[t] ? SIZE_MAX : keeps(&C, q, hint);
                any += keep[t] != SIZE_MAX;
            }
        }
        if (!any)
            continue;
        rc = append_images(F, s, maps, mi, keep, map_err, err);
        st_bvh_free(*fill_bvh);
        *fill_bvh = NULL;
        if (rc || (rc = st_bvh_build(fill_bvh, F->soup, err)))
            goto done;
    }
done:
    free(held);
    free(oks);
    free(errs);
    free(vimg);
    return rc;
}

/* depart[i]: 1 when some corner or centroid of piece i's fill lies
 * farther from the anchors (a cap's piece: its cap) than tol plus its
 * map's error there (what the map's own error explains is no evidence). */
static void departs(uint8_t *depart, size_t npieces, const fill_set *F,
                    const st_bvh *anchors_bvh, double tol)
{
    memset(depart, 0, npieces);
    const st_soup *f = F->soup;
    for (size_t t = 0; t < f->ntris; t++) {
        if (depart[F->piece[t]])
            continue;
        double x[4][3];
        for (int a = 0; a < 3; a++) {
            x[3][a] = 0.0;
            for (int k = 0; k < 3; k++) {
                x[k][a] = f->xyz[3 * f->tris[3 * t + k] + a];
                x[3][a] += x[k][a] / 3.0;
            }
        }
        for (int k = 0; k < 4 && !depart[F->piece[t]]; k++) {
            int64_t tri;
            const double r = tol + F->err[t];
            st_bvh_nearest(anchors_bvh, x[k], r * r, &tri, NULL);
            depart[F->piece[t]] = tri < 0;
        }
    }
}

/* What became of a piece. */
enum { PIECE_LEFT, PIECE_CLOSED, PIECE_UNCLOSED, PIECE_AGREES, PIECE_CONTRADICTED,
       PIECE_SPLIT };

/* state[i] (for the pieces where todo[i]; NULL: all): PIECE_CLOSED when
 * piece i's fill closes it: the fill runs along its rim (at least
 * RIM_COVERED of the rim's length within RIM_REACH tol of it) and its own
 * boundary off the soup is at most the rest, 1 - RIM_COVERED of the
 * rim's length (a copy itself holed leaves its holes in the fill:
 * PIECE_UNCLOSED). A cap the fill does not depart from (every corner and
 * centroid of it within tol of the cap, plus the map's error at the rim)
 * is kept, without fill (PIECE_AGREES): the copy agrees with the cap's
 * guess there, and the map's error would be all it adds. */
static st_status decide(uint8_t *state, const uint8_t *todo, const pieces *P, const rims *R,
                        const fill_set *F, const st_bvh *bvh, const st_bvh *fill_bvh,
                        const st_bvh *anchors_bvh, double tol)
{
    const size_t n = P->n ? P->n : 1;
    double *share = st_malloc_array(2 * n, sizeof *share);
    double *total = st_malloc_array(n, sizeof *total), *open = st_malloc_array(n, sizeof *open);
    uint8_t *depart = st_malloc_array(n, 1);
    st_status rc = share && total && open && depart ? ST_OK : ST_ENOMEM;
    if (!rc)
        departs(depart, P->n, F, anchors_bvh, tol);
    if (!rc) {
        const near_ctx on_fill = {fill_bvh, RIM_REACH * tol * RIM_REACH * tol, NULL};
        rim_share(share, P->n, R, near_bvh, &on_fill, total);
        rc = fill_bvh ? open_length(open, P->n, F, bvh, fill_bvh, RIM_REACH * tol) : ST_OK;
    }
    for (size_t i = 0; i < P->n && !rc; i++) {
        if (todo && !todo[i])
            continue;
        const int along = share[i] >= RIM_COVERED;
        const int closed = along && (!fill_bvh || open[i] <= (1.0 - RIM_COVERED) * total[i]);
        state[i] = !along ? PIECE_LEFT : !closed ? PIECE_UNCLOSED
                   : i < P->ncap && !depart[i] ? PIECE_AGREES : PIECE_CLOSED;
    }
    free(share);
    free(total);
    free(open);
    free(depart);
    return rc;
}

/* A third round, where the first two leave a hole unclosed (the copy
 * itself holed: state[i] PIECE_UNCLOSED) and maps[nset, nmaps) has the
 * turns two mirrors make (mirror_turns): those turns, for those pieces
 * alone, by the first round's rule for a cap and the second's for a
 * hole too large to cap; state[i] decided again. Only there:
 * with the turns among the maps of every round, the rotor's approximate
 * mirrors (a few degrees apart) turned its blades into holes the mirrors
 * close, rotor-deleted50 0.994 -> 0.952, rotor-largeholes 0.965 -> 0.948.
 * only: npieces scratch. */
static st_status turn_round(uint8_t *state, uint8_t *only, fill_set *F, st_bvh **fill_bvh,
                            const fill_ctx *C, const rims *R, const map *maps, size_t nset,
                            size_t nmaps, size_t *keep, uint8_t *ok, double *share,
                            double *map_err, st_error *err)
{
    const pieces *P = C->P;
    size_t ncaps = 0, nrims = 0;
    for (size_t i = 0; i < P->n; i++) {
        only[i] = state[i] == PIECE_UNCLOSED;
        ncaps += only[i] && i < P->ncap;
        nrims += only[i] && i >= P->ncap;
    }
    if ((!ncaps && !nrims) || nmaps == nset)
        return ST_OK;
    st_status rc = ST_OK;
    if (ncaps) {
        for (size_t i = P->ncap; i < P->n; i++)
            only[i] = 0;
        rc = map_all(F, fill_bvh, C, R, maps, nset, nmaps, NULL, only, keep, ok, share, map_err,
                     err);
    }
    for (size_t i = 0; i < P->n; i++)
        only[i] = state[i] == PIECE_UNCLOSED && i >= P->ncap;
    if (!rc && nrims && C->bounds)
        rc = map_all(F, fill_bvh, C, R, maps, nset, nmaps, only, NULL, keep, ok, share, map_err,
                     err);
    for (size_t i = 0; i < P->n; i++)
        only[i] = state[i] == PIECE_UNCLOSED;
    return rc ? rc : decide(state, only, P, R, F, C->bvh, *fill_bvh, C->anchors_bvh, C->tol);
}

/* A cap the rounds leave in place (its fill runs along too little of the
 * rim, or leaves the copy's own holes open) while its fill lies behind it:
 * the copy, through a map its rim verified, puts the surface deeper than
 * the cap, so the cap encloses space the part does not have (a cap guessed
 * across a concave corner). By area, of the fill's triangles whose
 * centroid departs from the cap (beyond tol and the map's error: what the
 * map's own error explains is no evidence), more lie behind the cap than
 * before it (the cap's nearest point on the side the fill faces: an
 * image keeps its triangle's orientation, a mirror's re-oriented). The
 * cap is dropped and the partial fill kept (PIECE_CONTRADICTED); what the
 * fill leaves open the votes decide, as for a hole too large to cap.
 * Where the fill lies before the cap (the cap cuts into the solid), the
 * cap stays: it is a guess on the side of too little, and a partial fill
 * without it leaves an opening the votes may carve. Open rims keep the
 * rule all or nothing: there is no guess to contradict. */
static st_status contradicted(uint8_t *state, const pieces *P, const fill_set *F,
                              const st_bvh *anchors_bvh, double tol)
{
    double *side = calloc(2 * (P->n ? P->n : 1), sizeof *side);   /* behind, before */
    if (!side)
        return ST_ENOMEM;
    const st_soup *f = F->soup;
    for (size_t t = 0; t < f->ntris; t++) {
        const size_t i = F->piece[t];
        if (i >= P->ncap || (state[i] != PIECE_LEFT && state[i] != PIECE_UNCLOSED))
            continue;
        double q[3][3], c[3], u[3], v[3], n[3], p[3], d[3];
        for (int k = 0; k < 3; k++)
            for (int a = 0; a < 3; a++)
                q[k][a] = f->xyz[3 * f->tris[3 * t + k] + a];
        for (int a = 0; a < 3; a++) {
            c[a] = (q[0][a] + q[1][a] + q[2][a]) / 3.0;
            u[a] = q[1][a] - q[0][a];
            v[a] = q[2][a] - q[0][a];
        }
        int64_t tri;
        const double r = tol + F->err[t];
        const double d2 = st_bvh_nearest(anchors_bvh, c, INFINITY, &tri, p);
        if (tri < 0 || !(d2 > r * r))
            continue;
        st_cross3(n, u, v);
        for (int a = 0; a < 3; a++)
            d[a] = p[a] - c[a];
        side[2 * i + (st_dot3(d, n) > 0.0 ? 0 : 1)] += 0.5 * st_norm3(n);
    }
    for (size_t i = 0; i < P->ncap; i++)
        if ((state[i] == PIECE_LEFT || state[i] == PIECE_UNCLOSED) && side[2 * i] > side[2 * i + 1])
            state[i] = PIECE_CONTRADICTED;
    free(side);
    return ST_OK;
}

/* ---- split: a cap a mirror covers in part ------------------------------------ */

typedef struct kept_fill_ctx {
    const fill_set *F;
    const uint8_t *fill_keep;
    size_t piece;
    const double *x;
    double reach2;
} kept_fill_ctx;

/* A kept fill triangle of the piece within reach of x: 1. */
static int near_kept_fill(void *ctx, uint32_t t)
{
    const kept_fill_ctx *K = ctx;
    if (K->F->piece[t] != K->piece || !K->fill_keep[t])
        return 0;
    const double *v = K->F->soup->xyz;
    const uint32_t *c = K->F->soup->tris + 3 * (size_t)t;
    return st_point_triangle_dist2(K->x, v + 3 * c[0], v + 3 * c[1], v + 3 * c[2], NULL) <=
           K->reach2;
}

/* What mirror m says of point x of cap piece i: x's image lies nearer
 * the soup than the holes' anchors (SPOKEN: the copy of what is lost
 * there survives), or in this same hole (SELF: the hole straddles the
 * plane, the copy of what is lost there is lost too: only the cap can
 * say), or in another hole (OTHER: the copy itself holed). */
enum { SPOKEN, SELF, OTHER };

static int spoken_for(const fill_ctx *C, const map *m, size_t i, const double x[3])
{
    double q[3];
    int64_t tri;
    st_symmetry_apply(m->y, m->angle, x, 1, q);
    const double ds = st_bvh_nearest(C->bvh, q, INFINITY, &tri, NULL);
    if (tri < 0)
        return OTHER;
    const double da = st_bvh_nearest(C->anchors_bvh, q, ds, &tri, NULL);
    return tri < 0 || da > ds ? SPOKEN : C->P->of_tri[tri] == i ? SELF : OTHER;
}

/* by[i]: for each cap piece the rounds leave in place (PIECE_LEFT or
 * PIECE_UNCLOSED) with fill, the mirror that gave it the most fill
 * triangles (ties: the lower map); SIZE_MAX where none did. */
static st_status split_mirror(size_t *by, const uint8_t *state, const pieces *P,
                              const fill_set *F, const map *maps, size_t nmaps)
{
    size_t *count = calloc(P->ncap * nmaps, sizeof *count);
    if (!count)
        return ST_ENOMEM;
    for (size_t t = 0; t < F->soup->ntris; t++) {
        const size_t i = F->piece[t];
        if (i < P->ncap && (state[i] == PIECE_LEFT || state[i] == PIECE_UNCLOSED) &&
            maps[F->map[t]].y->kind == ST_SYMMETRY_MIRROR)
            count[i * nmaps + F->map[t]]++;
    }
    for (size_t i = 0; i < P->ncap; i++) {
        by[i] = SIZE_MAX;
        for (size_t m = 0; m < nmaps; m++)
            if (count[i * nmaps + m] && (by[i] == SIZE_MAX || count[i * nmaps + m] >
                                                                 count[i * nmaps + by[i]]))
                by[i] = m;
    }
    free(count);
    return ST_OK;
}

/* The caps the rounds leave in place while a mirror fills them in part
 * (split_mirror): the mirror speaks for one part of the lost surface and
 * not for the rest, where it sends the hole onto itself (spoken_for). The
 * cap is split there: its triangles the mirror speaks for are dropped
 * (cap_keep[t] SPOKEN, 0) and its fill kept over them (a fill triangle of
 * that mirror whose nearest cap triangle is dropped: fill_keep), the rest
 * of the cap kept. The piece is split (PIECE_SPLIT) when a triangle is
 * dropped, the self-mapped part (SELF) straddles the plane (corners
 * farther than tol on both sides), at most 1 - RIM_COVERED of the cap's
 * area maps into other holes (OTHER: the copy itself holed, as on a soup
 * with half its faces deleted), and the kept cap's rim edges and the
 * ones within RIM_REACH tol of the kept fill are RIM_COVERED of the rim's
 * length (the two close the hole together); else nothing changes.
 * cap_keep: one per cap triangle, 1 where a split cap is kept, else 0;
 * fill_keep: one per fill triangle, 1 outside the split pieces. len, by:
 * 5 and 1 per cap piece, scratch. */
static void split_caps(uint8_t *state, uint8_t *cap_keep, uint8_t *fill_keep, double *len,
                       const size_t *by, const fill_ctx *C, const rims *R, const fill_set *F,
                       const st_bvh *fill_bvh, const map *maps)
{
    const pieces *P = C->P;
    const st_soup *caps = C->caps, *f = F->soup;
    const long long nc = (long long)caps->ntris;
#pragma omp parallel for schedule(dynamic, 256)
    for (long long t = 0; t < nc; t++) {
        const size_t i = P->of_tri[t];
        double x[3] = {0, 0, 0};
        for (int k = 0; k < 3 && by[i] != SIZE_MAX; k++)
            for (int a = 0; a < 3; a++)
                x[a] += caps->xyz[3 * (size_t)caps->tris[3 * t + k] + a] / 3.0;
        cap_keep[t] = by[i] == SIZE_MAX ? OTHER : (uint8_t)spoken_for(C, maps + by[i], i, x);
    }
    /* per piece: rim, along, the cap's area and its part mapped into
     * other holes, and the self-mapped part's sides of the plane (bit 1:
     * before, 2: behind; bit 4: a triangle dropped) */
    memset(len, 0, 5 * P->ncap * sizeof *len);
    for (size_t t = 0; t < caps->ntris; t++) {
        const size_t i = P->of_tri[t];
        if (by[i] == SIZE_MAX)
            continue;
        double q[3][3];
        for (int k = 0; k < 3; k++)
            memcpy(q[k], caps->xyz + 3 * (size_t)caps->tris[3 * t + k], sizeof q[k]);
        len[5 * i + 2] += tri_area(q);
        len[5 * i + 3] += cap_keep[t] == OTHER ? tri_area(q) : 0.0;
        if (cap_keep[t] == SPOKEN)
            len[5 * i + 4] = (double)((int)len[5 * i + 4] | 4);
        if (cap_keep[t] != SELF)
            continue;
        const st_symmetry *y = maps[by[i]].y;
        int side = (int)len[5 * i + 4];
        for (int k = 0; k < 3; k++) {
            const double *v = caps->xyz + 3 * (size_t)caps->tris[3 * t + k];
            const double d[3] = {v[0] - y->point[0], v[1] - y->point[1], v[2] - y->point[2]};
            const double h = st_dot3(d, y->dir);
            side |= h > C->tol ? 1 : h < -C->tol ? 2 : 0;
        }
        len[5 * i + 4] = side;
    }
    for (size_t t = 0; t < f->ntris; t++) {
        const size_t i = F->piece[t];
        if (i >= P->ncap || by[i] == SIZE_MAX)
            continue;
        double c[3] = {0, 0, 0};
        for (int k = 0; k < 3; k++)
            for (int a = 0; a < 3; a++)
                c[a] += f->xyz[3 * f->tris[3 * t + k] + a] / 3.0;
        int64_t tri;
        st_bvh_nearest(C->anchors_bvh, c, INFINITY, &tri, NULL);
        fill_keep[t] = F->map[t] == by[i] && tri >= 0 && (size_t)tri < caps->ntris &&
                       P->of_tri[tri] == i && !cap_keep[tri];
    }
    const double reach = RIM_REACH * C->tol;
    for (size_t r = 0; r < R->n; r++) {
        const size_t i = R->piece[r];
        if (i >= P->ncap || by[i] == SIZE_MAX)
            continue;
        len[5 * i] += R->len[r];
        int along = cap_keep[R->tri[r]];
        if (!along) {
            const double *m = R->mid + 3 * r;
            kept_fill_ctx K = {F, fill_keep, i, m, reach * reach};
            const double lo[3] = {m[0] - reach, m[1] - reach, m[2] - reach};
            const double hi[3] = {m[0] + reach, m[1] + reach, m[2] + reach};
            along = st_bvh_query_box(fill_bvh, lo, hi, near_kept_fill, &K);
        }
        len[5 * i + 1] += along ? R->len[r] : 0.0;
    }
    for (size_t i = 0; i < P->ncap; i++) {
        const double *l = len + 5 * i;
        if (by[i] != SIZE_MAX && l[4] == 7.0 && l[3] <= (1.0 - RIM_COVERED) * l[2] &&
            l[1] >= RIM_COVERED * l[0])
            state[i] = PIECE_SPLIT;
    }
    for (size_t t = 0; t < caps->ntris; t++)
        cap_keep[t] = cap_keep[t] && state[P->of_tri[t]] == PIECE_SPLIT;
    for (size_t t = 0; t < f->ntris; t++)
        fill_keep[t] = fill_keep[t] || F->piece[t] >= P->ncap || state[F->piece[t]] != PIECE_SPLIT;
}

/* What mirror_turns needs besides the fill's context: room for the
 * rotations, the set, and the room for maps. */
typedef struct turn_src {
    st_symmetry *rot;
    const st_symmetry_set *set;
    size_t max;
} turn_src;

/* The fill in two rounds: the maps that put a piece's whole rim back on
 * the soup; then, for the holes they left open or uncapped (no fill, or
 * one that does not close), also the maps that put back what the soup can
 * check of the rim: a rim whose preimage falls in the copy's own holes
 * (the damage removed the faces that would verify it) is judged on the
 * rest; then turn_round with the mirrors' turns (T: made here, into
 * maps[nset, *nmaps), only where a piece is left unclosed: elsewhere no
 * round reads them, and on a round part with many mirrors they cost more
 * than the fill); then the caps the fill contradicts (contradicted).
 * covered[i]: piece i's cap dropped and its fill kept. */
static st_status fill_rounds(uint8_t *covered, uint8_t **cap_keep, uint8_t **fill_keep,
                             fill_set *F, st_bvh **fill_bvh, const fill_ctx *C,
                             const rims *R, map *maps, size_t nset, size_t *nmaps,
                             const turn_src *T, size_t *keep, uint8_t *ok, double *share,
                             double *map_err, st_symmetry_fill_stats *st, st_error *err)
{
    const pieces *P = C->P;
    uint8_t *state = calloc(P->n, 1), *open = st_malloc_array(P->n, 1);
    st_status rc = state && open ? ST_OK : ST_ENOMEM;
    rc = rc ? rc : map_all(F, fill_bvh, C, R, maps, 0, nset, NULL, NULL, keep, ok, share, map_err,
                           err);
    rc = rc ? rc : decide(state, NULL, P, R, F, C->bvh, *fill_bvh, C->anchors_bvh, C->tol);
    size_t left = 0;
    for (size_t i = 0; i < P->n && !rc; i++)
        left += open[i] = state[i] == PIECE_LEFT || state[i] == PIECE_UNCLOSED;
    if (!rc && left && C->bounds) {
        rc = map_all(F, fill_bvh, C, R, maps, 0, nset, open, NULL, keep, ok, share, map_err, err);
        rc = rc ? rc : decide(state, open, P, R, F, C->bvh, *fill_bvh, C->anchors_bvh, C->tol);
    }
    size_t unclosed = 0;
    for (size_t i = 0; i < P->n && !rc; i++)
        unclosed += state[i] == PIECE_UNCLOSED;
    *nmaps = nset;
    if (!rc && unclosed)
        *nmaps = mirror_turns(T->rot, maps, nset, T->max, T->set, P->lo, P->hi, C->tol, C->s,
                              C->bvh, C->bounds);
    rc = rc ? rc : turn_round(state, open, F, fill_bvh, C, R, maps, nset, *nmaps, keep, ok, share,
                              map_err, err);
    rc = rc ? rc : contradicted(state, P, F, C->anchors_bvh, C->tol);
    if (!rc && !(*cap_keep = st_malloc_array(C->caps->ntris ? C->caps->ntris : 1, 1)))
        rc = ST_ENOMEM;
    if (!rc && !(*fill_keep = st_malloc_array(F->soup->ntris ? F->soup->ntris : 1, 1)))
        rc = ST_ENOMEM;
    double *len = rc ? NULL : st_malloc_array(P->ncap ? 5 * P->ncap : 1, sizeof *len);
    size_t *by = rc ? NULL : st_malloc_array(P->ncap ? P->ncap : 1, sizeof *by);
    if (!rc && (!len || !by))
        rc = ST_ENOMEM;
    rc = rc ? rc : split_mirror(by, state, P, F, maps, *nmaps);
    if (!rc)
        split_caps(state, *cap_keep, *fill_keep, len, by, C, R, F, *fill_bvh, maps);
    free(len);
    free(by);
    for (size_t i = 0; i < P->n && !rc; i++) {
        covered[i] = state[i] == PIECE_CLOSED || state[i] == PIECE_CONTRADICTED ||
                     state[i] == PIECE_SPLIT;
        st->caps_split += state[i] == PIECE_SPLIT;
        st->unclosed += state[i] == PIECE_UNCLOSED;
        st->caps_agree += state[i] == PIECE_AGREES;
        if (i < P->ncap)
            st->caps_covered += covered[i];
        else
            st->open_filled += covered[i];
    }
    free(state);
    free(open);
    return rc;
}

st_status st_symmetry_fill(st_soup **fill_out, st_soup **kept_out, const st_soup *s,
                           const st_soup_edges *edges, const st_bvh *bvh,
                           const st_symmetry_set *set, const st_soup *caps, double tol,
                           st_symmetry_fill_stats *stats, st_error *err)
{
    st_symmetry_fill_stats local;
    st_symmetry_fill_stats *st = stats ? stats : &local;
    memset(st, 0, sizeof *st);
    *fill_out = *kept_out = NULL;
    if (!(tol > 0.0) || !isfinite(tol))
        return st_error_set(err, ST_EINPUT, NULL, 0,
                            "symmetry fill: the tolerance must be positive and finite");
    st_soup *kept = st_soup_new(), *anchors = st_soup_new(), *bounds = st_soup_new();
    st_soup *fill = NULL;
    map maps[ST_SYMMETRY_MAX * ST_SYMMETRY_DEFAULT_MAX_ORDER];
    st_symmetry turns[ST_SYMMETRY_MAX * ST_SYMMETRY_MAX / 2];   /* mirror_turns' */
    fill_set F = {.soup = st_soup_new(), .maps = maps};
    st_bvh *anchors_bvh = NULL, *fill_bvh = NULL, *bounds_bvh = NULL;
    size_t *keep = NULL;
    uint8_t *covered = NULL, *ok = NULL, *cap_keep = NULL, *fill_keep = NULL;
    double *share = NULL, *map_err = NULL;
    pieces P;
    rims R;
    memset(&P, 0, sizeof P);
    memset(&R, 0, sizeof R);
    st_status rc = kept && anchors && bounds && F.soup ? ST_OK : ST_ENOMEM;
    if (rc || !set || set->n == 0 || s->ntris == 0 || (!(caps && caps->ntris) && !edges)) {
        if (!rc && caps)
            rc = st_soup_append(kept, caps, err);
        goto done;
    }
    static const st_soup none;
    const st_soup *cp = caps ? caps : &none;
    if ((rc = pieces_make(&P, cp)) || (rc = rims_make(&R, cp, &P)) ||
        (rc = st_soup_append(anchors, cp, err)) ||
        (cp->ntris && (rc = st_bvh_build(&anchors_bvh, cp, err))) ||
        (edges && (rc = open_rims(&P, &R, anchors, s, edges, anchors_bvh, tol, err))))
        goto done;
    st_bvh_free(anchors_bvh);   /* the caps' alone: built again with the rims */
    anchors_bvh = NULL;
    st->caps = P.ncap;
    st->open = P.n - P.ncap;
    if (P.n == 0)
        goto done;
    if ((rc = pieces_box(&P, anchors)))
        goto done;
    if (edges && !(F.rim = rim_bits(s, edges))) {
        rc = ST_ENOMEM;
        goto done;
    }
    keep = st_malloc_array(s->ntris, sizeof *keep);
    covered = st_malloc_array(P.n, 1);
    ok = st_malloc_array(P.n, 1);
    share = st_malloc_array(2 * P.n, sizeof *share);
    map_err = st_malloc_array(P.n, sizeof *map_err);
    if (!keep || !covered || !ok || !share || !map_err) {
        rc = ST_ENOMEM;
        goto done;
    }
    if ((rc = st_bvh_build(&anchors_bvh, anchors, err)))
        goto done;
    if (edges && ((rc = bounds_make(bounds, s, edges, err)) ||
                  (bounds->ntris && (rc = st_bvh_build(&bounds_bvh, bounds, err)))))
        goto done;
    const size_t nset = maps_of(set, maps, sizeof maps / sizeof *maps);
    size_t nmaps = nset;
    const turn_src T = {turns, set, sizeof maps / sizeof *maps};
    const fill_ctx C = {s, bvh, anchors_bvh, NULL, bounds_bvh, &P, NULL, tol, 0.0, cp};
    rc = fill_rounds(covered, &cap_keep, &fill_keep, &F, &fill_bvh, &C, &R, maps, nset, &nmaps,
                     &T, keep, ok, share, map_err, st, err);
    st->maps = nmaps;
    if (rc ||
        (rc = keep_uncovered(kept, cp, &P, covered, cap_keep, err)))
        goto done;
    rc = fill_of_covered(&fill, &F, covered, fill_keep, st, err);
done:
    if (rc == ST_ENOMEM)
        st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory for the symmetric fill");
    st_bvh_free(anchors_bvh);
    st_bvh_free(fill_bvh);
    st_bvh_free(bounds_bvh);
    st_soup_free(bounds);
    st_soup_free(anchors);
    st_soup_free(F.soup);
    free(F.piece);
    free(F.map);
    free(F.err);
    free(F.src);
    free(F.rim);
    free(map_err);
    pieces_free(&P);
    rims_free(&R);
    free(share);
    free(keep);
    free(covered);
    free(ok);
    free(cap_keep);
    free(fill_keep);
    if (!rc && !fill && !(fill = st_soup_new()))
        rc = st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory for the symmetric fill");
    if (rc) {
        st_soup_free(fill);
        st_soup_free(kept);
        return rc;
    }
    *fill_out = fill;
    *kept_out = kept;
    return ST_OK;
}
