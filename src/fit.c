/*
 * fit.c - enclosing vertex adjustment of a tet mesh to a surface (st_fit,
 * smooth.h) and its invariant (smooth_internal.h), which the quality pass
 * (quality.c) keeps too.
 *
 * Stuart, Levine, Jones, Bargteil 2013 ("Cetra"), section 3.3. Each
 * iteration moves every vertex x by tau * (x* - x), x* the volume-weighted
 * mean of the circumcenters of its tets (the ODT optimum, Alliez et al.
 * 2005); a boundary vertex farther than d_offset from S is also pulled by
 * tau * (g - x) toward g, the point at FIT_GOAL_FRACTION * d_offset from
 * its nearest point on S. The paper keeps the mesh enclosing S with El
 * Topo's continuous collision detection; what has to hold is static, and
 * here it is checked exactly after every move (the invariant):
 *
 *   - the tets of the moved vertex's star are positively oriented;
 *   - every vertex of S that lay in the closed old star lies in the closed
 *     new star (outside the star nothing moved);
 *   - no boundary face of the new star meets a triangle of S it did not
 *     meet before (closed triangles: touching counts).
 *
 * Together (the mesh enclosing S on entry) these keep every vertex of S
 * inside the mesh and every triangle of S away from its boundary. For an
 * interior vertex of a conforming mesh the second test is implied by the
 * first (see star_pts_collect) and skipped. A move that fails is halved
 * FIT_HALVINGS times, then skipped for this iteration; a move may also not
 * flatten its star below FIT_SLIVER_FLOOR. Iterations stop when every
 * boundary vertex is within d_offset of S, when an iteration moves
 * nothing, when FIT_STALL_ITERS iterations bring no new vertex into the
 * band, or after max_iters.
 *
 * Rescue (past the paper). The vertices still beyond d_offset when the
 * iterations stop are held: every step toward their nearest point of S,
 * down to 1/16, would let an S vertex out of the star or a boundary face
 * into S (a thin gap, a sharp crease). A step in another direction that
 * still brings the vertex closer to S often passes: it slides past what
 * holds it. rescue_vertex tries directions up to 88 degrees off the way
 * to S at fractions of the way to the band's middle, closest to S first,
 * under the same invariant and a star score floor (RESCUE_FLOOR, the
 * quality pass raises it after); rounds repeat while a vertex moves. It
 * runs after the iterations, and after the quality pass (whose moves
 * change the held vertices' stars) again, followed by another quality
 * pass, at most FIT_LATE_RESCUES times (4 rather than 2, 12 azimuths
 * rather than 8 and a last fraction of 1/128: rotor 1 -> 0 beyond 0.4 h,
 * boeing and fandisk-noise 1 -> 0 beyond 0.25 h). Measured (--tries 1, cells 10):
 * beyond 0.4 h before -> after on fandisk 5 -> 0, armadillo 12 -> 0,
 * cheese 49 -> 0, bunny-soup 1 -> 0, elephant-with-holes 12 -> 0; at
 * 0.25 h fandisk, bunny-soup, elephant-with-holes, joint all reach 0.
 * Retrying the fit iterations between rescues did little (0.25 h: 10 ->
 * 10 beyond over four models) at twice the time, so it does not.
 *
 * Joint rescue (issue 18). What the late rescues leave beyond is held by
 * a boundary face whose two other corners already lie near S: swinging it
 * about their edge toward S would cut a concave feature narrower than h
 * (a step between two planes, a hole's rim, a noise bump). rescue_joint
 * moves one of those neighbours a little first (within d_offset, under
 * the same invariant) and keeps the step only when the held vertex then
 * moves. It runs after the plain late rescues, on what they leave only
 * (tried earlier it changed the stars they would have used: cheese-
 * deleted50 at 0.25 h went from 1 vertex beyond to 2). At 0.25 h, --tries
 * 8, it brings the last four damaged corpus inputs that missed within:
 * cheese-holes, -noise, -deleted50 and couplingdown-largeholes, 1-2
 * beyond (0.256..0.325 h) -> 0, min dihedral 32.2, 35.0, 33.6, 31.9.
 *
 * Peeling (past the paper; issue 18). After the last quality pass, a
 * boundary tet whose score is below the quality goal and that holds
 * nothing of S is removed (peel_round): no vertex of S in the closed tet,
 * no S triangle meeting a face it exposes (an S triangle inside the mesh
 * that entered the tet without a vertex in it crossed one of its faces,
 * and its boundary faces were clear), the boundary kept a manifold (one
 * boundary face: the corner opposite it an interior vertex, which becomes
 * a boundary vertex and must be within d_offset of S; two: the edge the
 * two exposed faces share not on the boundary; three or four: kept), and,
 * when the mesh has the sculpting's "sculpt" cell array, not a tet kept
 * for the pseudo volume (ST_SCULPT_VOLUME: peeling those eats the fill
 * of a one-sided or holed input). Worst first, no two sharing a vertex
 * per round, PEEL_ROUNDS rounds, then the quality pass on the new
 * boundary; PEEL_PASSES times. Removing tets lowers no score and the
 * quality pass raises only, so the worst score cannot drop, and the
 * invariant holds as for a move. Measured (soupmesh --tries 1 --cells 10,
 * min..max dihedral before -> after): rotor-largeholes at R 0.25
 * 31.74..137.43 -> 34.16..134.49 (28 tets peeled, mostly bomb repair's),
 * fandisk-onesided 23.75..148.25 -> 25.29..145.97 (50). Without the
 * ST_SCULPT_VOLUME rule fandisk-onesided reached 26.24 degrees but lost
 * 168 tets of its fill (S -> boundary 0.81 h -> 1.21 h) at 4 times the
 * CPU time. The clean corpus at --tries 8 is unchanged (its best
 * candidates have no tet below the goal), and so is `make demo`.
 *
 * The fill (st_fit_params.fill; issue 18). Where the input has no surface
 * (the far side of a one-sided scan, a large hole), the sculpted lattice
 * keeps the pseudo volume's fill, and its boundary vertices there are far
 * from S with nothing to pull them: measured against S alone they can
 * never meet the condition (bunny-onesided, --tries 8: 44 of 570 beyond
 * 0.4 h, up to 1.88 h). With a fill, every distance the fit takes (the
 * condition, the pull's nearest point, the rescue, the quality pass's
 * band) is to S or the fill, whichever is nearer (sm_nearest_d2): the
 * fill counts as surface; the invariant is S's alone.
 *
 * Not checked: that the boundary does not fold onto another part of the
 * mesh far from the moved star (a global self-intersection); small steps
 * and positive stars make it unlikely, tetstat would show it as overlap.
 *
 * The quality pass (quality.c) then raises the worst dihedral angles under
 * the same invariant.
 *
 * Cost. Most trial moves of a boundary vertex fail because an S vertex of
 * its star would leave it (on the armadillo, 38K of 46K checks), and a
 * vertex held back fails the same way every iteration. So: the S vertex
 * that stopped a vertex last is tried first (when it is in the star and
 * would leave, the move fails without gathering the star's points); the
 * star's points are gathered only when a trial passes the cheap tests,
 * each remembering its tet so the check after a small move is one tet
 * test; a vertex whose last attempt failed and whose star has not moved
 * since is not tried again (the attempt is a function of the star: same
 * result); faces are checked through the BVH's triangle query (nodes
 * pruned by the face itself, not its box); boundary distances are searched
 * within the old distance plus the way the vertex moved. None of these
 * changes a result.
 *
 * Vertices move colour by colour (smooth_mesh.c); within a colour in
 * parallel, each check reading only its own star, so the result does not
 * depend on the thread count.
 */
#include "smooth_internal.h"
#include "fpenv.h"

#include "souptet/isect.h"
#include "souptet/mem.h"
#include "souptet/pred.h"
#include "souptet/sculpt.h"
#include "souptet/smooth.h"
#include "souptet/enclose.h"
#include "souptet/tetqual.h"

#include "radix.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Halvings of a rejected fit move before it is skipped (the brief's "a
 * few times": 1/16 of a step is already below what one iteration of the
 * paper's scheme moves a vertex near convergence). */
#define FIT_HALVINGS 4
/* Iterations without a new boundary vertex reaching the band before the
 * fit gives up on the rest: past this the remaining ones are held by the
 * invariant (thin gaps), and more ODT steps only wear the angles down. */
#define FIT_STALL_ITERS 10
/* A fit move may not bring the score of its star (smooth.h) below this
 * many degrees, or below what it already was if lower: on the bunny the
 * unconstrained ODT steps next to vertices the invariant holds back flatten
 * tets to 0 degrees, which the quality pass then has to undo; with the
 * floor the fit ends at 10..163 degrees, converges as far, and the final
 * angles are the same (measured at 0, 5, 10 and 15 degrees). */
#define FIT_SLIVER_FLOOR 10.0
/* The surface pull aims at this fraction of d_offset from S: the middle of
 * the band leaves room for the ODT motion and the quality pass without
 * leaving it. */
#define FIT_GOAL_FRACTION 0.5

st_fit_params st_fit_params_default(void)
{
    st_fit_params p;
    memset(&p, 0, sizeof p);
    p.offset_ratio = 0.4;
    p.cell_width = 0.0;
    p.step = 0.5;
    p.max_iters = 300;
    p.quality = 1;
    p.quality_rounds = 40;
    p.quality_goal = 35.0;
    p.peel = 1;
    p.count_before = 1;
    return p;
}

/* ---- the vertices of S in bins -------------------------------------- */


static int cmp_pt(const void *a, const void *b)
{
    const double *x = a, *y = b;
    for (int k = 0; k < 3; k++)
        if (x[k] != y[k])
            return x[k] < y[k] ? -1 : 1;
    return 0;
}

/* Digit `pass` of the point's x key (st_radix_double_key) */
static uint32_t pt_x_digit(const void *x, int pass, unsigned bits)
{
    const double *p = x;
    (void)bits;
    return (uint32_t)(st_radix_double_key(p[0]) >> (16 * pass)) & 0xffffu;
}

ST_RADIX_SORT_DEFINE(sort_by_x, 3 * sizeof(double), pt_x_digit)

/* The n points at pts in cmp_pt's order, stably (as qsort's merge sort
 * did): a stable radix sort by x, then each run of equal x by cmp_pt
 * (glibc's qsort is a stable merge sort at these sizes). */
static st_status sort_points(double *pts, size_t n)
{
    double *tmp = st_malloc_array(n ? n : 1, 3 * sizeof *tmp);
    if (!tmp || sort_by_x(pts, tmp, n, 4, 0)) {
        free(tmp);
        return ST_ENOMEM;
    }
    free(tmp);
    for (size_t i = 0, j; i < n; i = j) {
        for (j = i + 1; j < n && pts[3 * j] == pts[3 * i]; j++)
            ;
        if (j - i > 1)
            qsort(pts + 3 * i, j - i, 3 * sizeof(double), cmp_pt);
    }
    return ST_OK;
}

static void pgrid_free(pgrid *g)
{
    free(g->pts);
    free(g->off);
    free(g->idx);
    free(g->bpts);
    memset(g, 0, sizeof *g);
}

static size_t pgrid_coord(const pgrid *g, double x, int a)
{
    double f = floor((x - g->lo[a]) / g->cell);
    if (!(f > 0.0))
        return 0;
    if (f >= (double)g->n[a])
        return g->n[a] - 1;
    return (size_t)f;
}

size_t sm_pgrid_coord(const pgrid *g, double x, int a)
{
    return pgrid_coord(g, x, a);
}

/* The distinct vertices of s's triangles, binned at about `cell`. */
static st_status pgrid_build(pgrid *g, const st_soup *s, double cell)
{
    memset(g, 0, sizeof *g);
    /* the used vertex indices first (a vertex is in ~6 triangles), then
     * the sort by position merges the ones at one position */
    unsigned char *used = st_calloc_array(s->nverts ? s->nverts : 1, 1);
    if (!used)
        return ST_ENOMEM;
    size_t n = 0;
    for (size_t i = 0; i < 3 * s->ntris; i++)
        if (!used[s->tris[i]]) {
            used[s->tris[i]] = 1;
            n++;
        }
    g->pts = st_malloc_array(n ? n : 1, 3 * sizeof *g->pts);
    if (!g->pts) {
        free(used);
        return ST_ENOMEM;
    }
    for (size_t v = 0, i = 0; v < s->nverts; v++)
        if (used[v])
            memcpy(g->pts + 3 * i++, s->xyz + 3 * v, 3 * sizeof(double));
    free(used);
    if (sort_points(g->pts, n))
        return ST_ENOMEM;
    size_t k = 0;
    for (size_t i = 0; i < n; i++)
        if (k == 0 || cmp_pt(g->pts + 3 * (k - 1), g->pts + 3 * i) != 0) {
            memmove(g->pts + 3 * k, g->pts + 3 * i, 3 * sizeof(double));
            k++;
        }
    g->npts = k;
    double hi[3];
    for (int a = 0; a < 3; a++) {
        g->lo[a] = INFINITY;
        hi[a] = -INFINITY;
    }
    for (size_t i = 0; i < k; i++)
        for (int a = 0; a < 3; a++) {
            g->lo[a] = fmin(g->lo[a], g->pts[3 * i + (size_t)a]);
            hi[a] = fmax(hi[a], g->pts[3 * i + (size_t)a]);
        }
    g->cell = cell;
    size_t nb = 1;
    for (int a = 0; a < 3; a++) {
        double ext = k ? hi[a] - g->lo[a] : 0.0;
        double c = floor(ext / cell) + 1.0;
        /* a bin count beyond 256 per axis buys nothing here */
        g->n[a] = c > 256.0 ? 256 : (size_t)c;
        nb *= g->n[a];
    }
    if (k) {
        double ext = 0.0;
        for (int a = 0; a < 3; a++)
            ext = fmax(ext, (hi[a] - g->lo[a]) / (double)g->n[a]);
        g->cell = fmax(cell, ext);
    }
    g->off = st_calloc_array(nb + 1, sizeof *g->off);
    g->idx = st_malloc_array(k ? k : 1, sizeof *g->idx);
    if (!g->off || !g->idx)
        return ST_ENOMEM;
    size_t *bin = st_malloc_array(k ? k : 1, sizeof *bin);
    if (!bin)
        return ST_ENOMEM;
    for (size_t i = 0; i < k; i++) {
        const double *p = g->pts + 3 * i;
        size_t ix = pgrid_coord(g, p[0], 0), iy = pgrid_coord(g, p[1], 1),
               iz = pgrid_coord(g, p[2], 2);
        bin[i] = ix + g->n[0] * (iy + g->n[1] * iz);
        g->off[bin[i] + 1]++;
    }
    for (size_t b = 0; b < nb; b++)
        g->off[b + 1] += g->off[b];
    size_t *fill = st_malloc_array(nb, sizeof *fill);
    if (!fill) {
        free(bin);
        return ST_ENOMEM;
    }
    memcpy(fill, g->off, nb * sizeof *fill);
    for (size_t i = 0; i < k; i++)
        g->idx[fill[bin[i]]++] = (uint32_t)i;
    free(fill);
    free(bin);
    g->bpts = st_malloc_array(k ? k : 1, 3 * sizeof *g->bpts);
    if (!g->bpts)
        return ST_ENOMEM;
    for (size_t j = 0; j < k; j++)
        memcpy(g->bpts + 3 * j, g->pts + 3 * (size_t)g->idx[j], 3 * sizeof *g->bpts);
    return ST_OK;
}

/* ---- the invariant -------------------------------------------------- */



int sm_dirty_init(dirty *d, size_t nv)
{
    d->step = 0;
    d->moved_at = st_calloc_array(nv ? nv : 1, sizeof *d->moved_at);
    d->tried_at = st_calloc_array(nv ? nv : 1, sizeof *d->tried_at);
    return d->moved_at && d->tried_at ? 0 : -1;
}

void sm_dirty_free(dirty *d)
{
    free(d->moved_at);
    free(d->tried_at);
    memset(d, 0, sizeof *d);
}

/* 1 when an attempt to move v would repeat one that did not move. */
int sm_dirty_unchanged(const dirty *d, const sm_mesh *sm, uint32_t v)
{
    uint32_t t = d->tried_at[v];
    if (t == 0 || d->moved_at[v] >= t)
        return 0;
    for (size_t j = sm->vv_off[v]; j < sm->vv_off[v + 1]; j++)
        if (d->moved_at[sm->vv[j]] >= t)
            return 0;
    return 1;
}

void sm_dirty_mark(dirty *d, uint32_t v, int moved)
{
    if (moved)
        d->moved_at[v] = d->step;
    else
        d->tried_at[v] = d->step;
}

static void star_box(const sm_mesh *sm, uint32_t v, const double p[3],
                     double lo[3], double hi[3])
{
    for (int a = 0; a < 3; a++)
        lo[a] = hi[a] = p[a];
    for (size_t j = sm->vv_off[v]; j < sm->vv_off[v + 1]; j++) {
        const double *q = sm->m->xyz + 3 * (size_t)sm->vv[j];
        for (int a = 0; a < 3; a++) {
            lo[a] = q[a] < lo[a] ? q[a] : lo[a];
            hi[a] = q[a] > hi[a] ? q[a] : hi[a];
        }
    }
}

/* 1 when q lies in the closed tet j of v's star (j counts from vt_off[v])
 * with v at p. */
static int in_star_tet(const sm_mesh *sm, uint32_t v, size_t j, const double p[3],
                       const double q[3])
{
    const uint32_t *c = sm->m->tets + 4 * (size_t)sm->vt[sm->vt_off[v] + j];
    const double *t[4];
    for (int k = 0; k < 4; k++)
        t[k] = c[k] == v ? p : sm->m->xyz + 3 * (size_t)c[k];
    for (int a = 0; a < 3; a++)   /* outside the tet's box: outside the tet */
        if ((q[a] < t[0][a] && q[a] < t[1][a] && q[a] < t[2][a] && q[a] < t[3][a]) ||
            (q[a] > t[0][a] && q[a] > t[1][a] && q[a] > t[2][a] && q[a] > t[3][a]))
            return 0;
    return st_point_in_tet(q, t[0], t[1], t[2], t[3]) != ST_OUTSIDE;
}

/* The tet of v's star (with v at p) that holds q, trying `hint` first:
 * its index from vt_off[v], or -1 when q is outside the closed star. A
 * small move keeps most points in the tet they were in, so the hint makes
 * the usual answer one tet test instead of a scan of the star. */
static ptrdiff_t in_star(const sm_mesh *sm, uint32_t v, const double p[3],
                         const double q[3], ptrdiff_t hint)
{
    size_t n = sm->vt_off[v + 1] - sm->vt_off[v];
    if (hint >= 0 && (size_t)hint < n && in_star_tet(sm, v, (size_t)hint, p, q))
        return hint;
    for (size_t j = 0; j < n; j++)
        if ((ptrdiff_t)j != hint && in_star_tet(sm, v, j, p, q))
            return (ptrdiff_t)j;
    return -1;
}

/* in_star_tet for a star known to be positive with v at p (every tet's
 * orient3d < 0, as sm_star_positive checks, which move_ok does first):
 * st_point_in_tet's face tests, in its order, without its orientation
 * test, and with skip_opposite without the face opposite v, which the
 * caller knows q is on the closed inner side of (q was in the same closed
 * tet with v elsewhere, and that tet was positive: the face does not move).
 * Same answer as in_star_tet, two orient3d calls fewer of five. */
static int in_pos_star_tet(const sm_mesh *sm, uint32_t v, size_t j, const double p[3],
                           const double q[3], int skip_opposite)
{
    const uint32_t *c = sm->m->tets + 4 * (size_t)sm->vt[sm->vt_off[v] + j];
    const double *t[4];
    int kv = -1;
    for (int k = 0; k < 4; k++) {
        t[k] = c[k] == v ? p : sm->m->xyz + 3 * (size_t)c[k];
        if (c[k] == v)
            kv = k;
    }
    for (int a = 0; a < 3; a++)
        if ((q[a] < t[0][a] && q[a] < t[1][a] && q[a] < t[2][a] && q[a] < t[3][a]) ||
            (q[a] > t[0][a] && q[a] > t[1][a] && q[a] > t[2][a] && q[a] > t[3][a]))
            return 0;
    /* the faces opposite corners 0..3, ordered as isect.c's tet_faces so
     * that each orient3d is the tet's with that corner replaced by q */
    const double *F[4][3] = {{t[2], t[1], t[3]}, {t[0], t[2], t[3]},
                             {t[1], t[0], t[3]}, {t[0], t[1], t[2]}};
    for (int i = 0; i < 4; i++) {
        if (skip_opposite && i == kv)
            continue;
        if (st_orient3d(F[i][0], F[i][1], F[i][2], q) > 0)
            return 0;
    }
    return 1;
}

/* in_star_tet given o, the sign of st_orient3d of the tet's corners with v
 * at p (st_point_in_tet's first test, which does not depend on q): for a
 * positive tet (o < 0) in_pos_star_tet's face tests alone, the same
 * answer. */
static int in_star_tet_o(const sm_mesh *sm, uint32_t v, size_t j, const double p[3],
                         const double q[3], int o)
{
    return o < 0 ? in_pos_star_tet(sm, v, j, p, q, 0) : in_star_tet(sm, v, j, p, q);
}

/* in_star for a star that is positive with v at p (see in_pos_star_tet);
 * with hint_opposite, q is known to be inside the hint tet's face opposite
 * v. Returns the same tet as in_star. */
static ptrdiff_t in_pos_star(const sm_mesh *sm, uint32_t v, const double p[3],
                             const double q[3], ptrdiff_t hint, int hint_opposite)
{
    size_t n = sm->vt_off[v + 1] - sm->vt_off[v];
    if (hint >= 0 && (size_t)hint < n &&
        in_pos_star_tet(sm, v, (size_t)hint, p, q, hint_opposite))
        return hint;
    for (size_t j = 0; j < n; j++)
        if ((ptrdiff_t)j != hint && in_pos_star_tet(sm, v, j, p, q, 0))
            return (ptrdiff_t)j;
    return -1;
}

/* The S vertices in the closed star of v as it is, appended to *list.
 * Returns 0, or -1 out of memory. */
static int svertices_in_star(const fit_ctx *c, uint32_t v, star_pt **list,
                             size_t *n, size_t *cap)
{
    const sm_mesh *sm = &c->sm;
    const pgrid *g = &c->pg;
    *n = 0;
    if (g->npts == 0)
        return 0;
    const double *x = sm->m->xyz + 3 * (size_t)v;
    double lo[3], hi[3];
    star_box(sm, v, x, lo, hi);
    size_t a0[3], a1[3];
    for (int a = 0; a < 3; a++) {
        a0[a] = pgrid_coord(g, lo[a], a);
        a1[a] = pgrid_coord(g, hi[a], a);
    }
    /* The star tets' boxes, once for all the points: in_star's test order
     * and answers, without recomputing a tet's box for every point (the
     * box rejects most (point, tet) pairs; issue 23: this scan was the
     * largest part of the fit on dragon_res3, 9 million tet tests). */
    enum { BOXED_MAX = 96 };
    double tbox[BOXED_MAX][6];
    int tor[BOXED_MAX];   /* and their orientations (in_star_tet_o) */
    const size_t nst = sm->vt_off[v + 1] - sm->vt_off[v];
    const int boxed = nst <= BOXED_MAX;
    for (size_t j = 0; boxed && j < nst; j++) {
        const uint32_t *tc = sm->m->tets + 4 * (size_t)sm->vt[sm->vt_off[v] + j];
        for (int a = 0; a < 3; a++) {
            tbox[j][a] = INFINITY;
            tbox[j][3 + a] = -INFINITY;
        }
        for (int k = 0; k < 4; k++) {
            const double *y = sm->m->xyz + 3 * (size_t)tc[k];
            for (int a = 0; a < 3; a++) {
                tbox[j][a] = y[a] < tbox[j][a] ? y[a] : tbox[j][a];
                tbox[j][3 + a] = y[a] > tbox[j][3 + a] ? y[a] : tbox[j][3 + a];
            }
        }
        const double *y0 = sm->m->xyz + 3 * (size_t)tc[0], *y1 = sm->m->xyz + 3 * (size_t)tc[1],
                     *y2 = sm->m->xyz + 3 * (size_t)tc[2], *y3 = sm->m->xyz + 3 * (size_t)tc[3];
        tor[j] = st_sign(st_orient3d(y0, y1, y2, y3));
    }
    ptrdiff_t hint = -1;   /* neighbouring points tend to share a tet */
    for (size_t iz = a0[2]; iz <= a1[2]; iz++)
        for (size_t iy = a0[1]; iy <= a1[1]; iy++)
            for (size_t ix = a0[0]; ix <= a1[0]; ix++) {
                size_t b = ix + g->n[0] * (iy + g->n[1] * iz);
                for (size_t j = g->off[b]; j < g->off[b + 1]; j++) {
                    const double *q = g->pts + 3 * (size_t)g->idx[j];
                    if (q[0] < lo[0] || q[0] > hi[0] || q[1] < lo[1] || q[1] > hi[1] ||
                        q[2] < lo[2] || q[2] > hi[2])
                        continue;
                    ptrdiff_t t = -1;
                    if (!boxed)
                        t = in_star(sm, v, x, q, hint);
                    else
                        for (size_t r = 0; r <= nst; r++) {
                            /* hint first, then the others in order */
                            size_t u = r == 0 ? (size_t)hint : r - 1;
                            if ((r == 0 && (hint < 0 || (size_t)hint >= nst)) ||
                                (r > 0 && (ptrdiff_t)u == hint))
                                continue;
                            const double *bx = tbox[u];
                            if (q[0] < bx[0] || q[1] < bx[1] || q[2] < bx[2] ||
                                q[0] > bx[3] || q[1] > bx[4] || q[2] > bx[5])
                                continue;
                            if (in_star_tet_o(sm, v, u, x, q, tor[u])) {
                                t = (ptrdiff_t)u;
                                break;
                            }
                        }
                    if (t < 0)
                        continue;
                    hint = t;
                    if (*n == *cap) {
                        size_t nc = *cap ? 2 * *cap : 64;
                        star_pt *l = st_realloc_array(*list, nc, sizeof *l);
                        if (!l)
                            return -1;
                        *list = l;
                        *cap = nc;
                    }
                    (*list)[*n].pt = g->idx[j];
                    (*list)[*n].tet = (uint32_t)t;
                    (*n)++;
                }
            }
    return 0;
}

/* Every listed S vertex lies in the closed star of v with v at p; when
 * one does not, *failed says which (a point grid index). The star with v
 * at p must be positive (move_ok tests that first); was_positive: it was
 * positive where the list was gathered, so each point is inside its tet's
 * face opposite v (issue 23: this loop is most of the fit's time on large
 * soups, a few thousand points per star on the dragon). */
static int svertices_kept(const fit_ctx *c, uint32_t v, const double p[3],
                          const star_pt *list, size_t n, int was_positive,
                          uint32_t *failed)
{
    for (size_t i = 0; i < n; i++)
        if (in_pos_star(&c->sm, v, p, c->pg.pts + 3 * (size_t)list[i].pt,
                        (ptrdiff_t)list[i].tet, was_positive) < 0) {
            *failed = list[i].pt;
            return 0;
        }
    return 1;
}

typedef struct face_query {
    const st_soup *s;
    const double *f[3];     /* the face as it would be */
    const double *g[3];     /* the face as it is */
} face_query;

/* 1 (stop) when S triangle tri meets the new face but did not meet the
 * old one. */
static int face_visit(void *ctx, uint32_t tri)
{
    const face_query *q = ctx;
    const uint32_t *t = q->s->tris + 3 * (size_t)tri;
    const double *a = q->s->xyz + 3 * (size_t)t[0], *b = q->s->xyz + 3 * (size_t)t[1],
                 *d = q->s->xyz + 3 * (size_t)t[2];
    if (!st_tri_tri_intersect(q->f[0], q->f[1], q->f[2], a, b, d))
        return 0;
    return !st_tri_tri_intersect(q->g[0], q->g[1], q->g[2], a, b, d);
}

/* No boundary face of v's star, with v at p, newly meets a triangle of S.
 * The BVH walk prunes by the new face itself (st_bvh_query_tri), not by
 * its bounding box: a face is about h across and S triangles are much
 * smaller, so its box holds hundreds of triangles and the face a few. */
static int faces_clear(const fit_ctx *c, uint32_t v, const double p[3])
{
    const sm_mesh *sm = &c->sm;
    for (size_t j = sm->vf_off[v]; j < sm->vf_off[v + 1]; j++) {
        const uint32_t *k = sm->bf + 3 * (size_t)sm->vf[j];
        face_query q;
        q.s = c->s;
        for (int i = 0; i < 3; i++) {
            q.g[i] = sm->m->xyz + 3 * (size_t)k[i];
            q.f[i] = k[i] == v ? p : q.g[i];
        }
        if (st_bvh_query_tri(c->bvh, q.f[0], q.f[1], q.f[2], face_visit, &q))
            return 0;
    }
    return 1;
}


/* Collect the S vertices v's star holds now. Only a boundary vertex (or
 * any vertex of a non-conforming mesh) needs them: the faces of an
 * interior vertex's star opposite it form a closed surface that does not
 * move, and when every tet of the new star is positive, the new star
 * covers each point exactly winding-number-of-that-surface times, i.e.
 * it is the same closed region as before. */
static void star_pts_fill(const fit_ctx *c, star_pts *sp, int swept)
{
    sp->n = 0;
    sp->ok = 1;
    sp->have = 1;
    sp->positive = 0;
    sp->swept = 0;
    if (c->s && (c->sm.onb[sp->v] || c->full_check)) {
        /* a boundary vertex with a positive star: only the points its
         * boundary faces sweep can leave (fit_swept.c), no list */
        if (swept && !c->full_check && sm_swept_applies(c, sp->v) &&
            sm_star_positive(&c->sm, sp->v, c->sm.m->xyz + 3 * (size_t)sp->v)) {
            sp->swept = 1;
            return;
        }
        sp->ok = svertices_in_star(c, sp->v, &sp->list, &sp->n, &sp->cap) == 0;
        sp->positive = sp->n > 0 &&
                       sm_star_positive(&c->sm, sp->v, c->sm.m->xyz + 3 * (size_t)sp->v);
    }
}

/* Start the moves of v: the list is filled when a move first needs it
 * (most trial positions fail the cheaper tests). */
void sm_star_pts_collect(const fit_ctx *c, uint32_t v, star_pts *sp)
{
    (void)c;
    sp->have = 0;
    sp->v = v;
}

/* The whole invariant for moving v to p, cheapest test first. */
int sm_move_ok(const fit_ctx *c, uint32_t v, const double p[3], star_pts *sp)
{
    if (!(isfinite(p[0]) && isfinite(p[1]) && isfinite(p[2])))
        return 0;
    if (!sm_star_positive(&c->sm, v, p))
        return 0;
    /* The S vertex that stopped v last time usually stops it again: when
     * it is in the star now and would not be, the move fails whatever the
     * others do, and the star's points need not be gathered. */
    uint32_t b = c->blocker ? c->blocker[v] : UINT32_MAX;
    if (b != UINT32_MAX && c->s && (c->sm.onb[v] || c->full_check)) {
        const double *q = c->pg.pts + 3 * (size_t)b;
        const double *x = c->sm.m->xyz + 3 * (size_t)v;
        if (in_star(&c->sm, v, p, q, -1) < 0 && in_star(&c->sm, v, x, q, -1) >= 0)
            return 0;
    }
    if (!sp->have)
        star_pts_fill(c, sp, 1);
    uint32_t failed;
    int kept = sp->swept ? sm_swept_kept(c, v, p, &failed) : -1;
    if (kept < 0 && sp->swept)
        star_pts_fill(c, sp, 0);
    if (!sp->ok)
        return 0;
    if (kept < 0)
        kept = svertices_kept(c, v, p, sp->list, sp->n, sp->positive, &failed);
    if (!kept) {
        if (c->blocker)
            c->blocker[v] = failed;   /* v's own slot: v's colour writes it */
        return 0;
    }
    if (c->s && c->sm.onb[v] && !faces_clear(c, v, p))
        return 0;
    return 1;
}

double sm_nearest_d2(const fit_ctx *c, const double p[3], double max_d2,
                     int64_t *found, double closest[3])
{
    double d2 = st_bvh_nearest(c->bvh, p, max_d2, found, closest);
    if (c->fbvh) {
        int64_t ft;
        double fq[3];
        double f2 = st_bvh_nearest(c->fbvh, p, d2, &ft, fq);
        if (ft >= 0 && f2 < d2) {
            d2 = f2;
            *found = ft;
            if (closest)
                memcpy(closest, fq, sizeof fq);
        }
    }
    return d2;
}

double sm_dist_to_s(const fit_ctx *c, const double p[3], double closest[3])
{
    int64_t tri;
    double q[3];
    double d2 = sm_nearest_d2(c, p, INFINITY, &tri, closest ? closest : q);
    return sqrt(d2);
}

/* ---- fit iterations --------------------------------------------------- */


static int fit_vertex(const fit_ctx *c, uint32_t v, double tau, const double *dist,
                      star_pts *sp, fit_counts *n)
{
    const sm_mesh *sm = &c->sm;
    double *x = sm->m->xyz + 3 * (size_t)v;
    double t[3], d[3];
    sm_odt_target(sm, v, t);
    for (int a = 0; a < 3; a++)
        d[a] = tau * (t[a] - x[a]);
    if (sm->onb[v] && dist[v] > c->d_offset) {
        double cp[3];
        double dd = sm_dist_to_s(c, x, cp);
        if (dd > 0.0) {
            double goal = FIT_GOAL_FRACTION * c->d_offset;
            for (int a = 0; a < 3; a++) {
                double g = cp[a] + (x[a] - cp[a]) * (goal / dd);
                d[a] += tau * (g - x[a]);
            }
        }
    }
    if (d[0] == 0.0 && d[1] == 0.0 && d[2] == 0.0)
        return 0;
    sm_star_pts_collect(c, v, sp);
    double floor_score = fmin(FIT_SLIVER_FLOOR, sm_star_score(sm, v, x));
    double f = 1.0;
    for (int k = 0; k <= FIT_HALVINGS; k++, f *= 0.5) {
        double p[3] = {x[0] + f * d[0], x[1] + f * d[1], x[2] + f * d[2]};
        if (sm_star_score(sm, v, p) >= floor_score && sm_move_ok(c, v, p, sp)) {
            memcpy(x, p, sizeof p);
            n->moved++;
            return 1;
        }
        n->rejected++;
    }
    n->skipped++;
    return 0;
}


dist_summary sm_boundary_distances(const fit_ctx *c, double *dist)
{
    const sm_mesh *sm = &c->sm;
    size_t within = 0;
    double mx = 0.0;
    #pragma omp parallel for schedule(dynamic, 64) reduction(+ : within) reduction(max : mx) \
        if (PAR_MOVES(sm->nv))
    for (size_t v = 0; v < sm->nv; v++) {
        if (!sm->onb[v]) {
            dist[v] = 0.0;
            continue;
        }
        const double *x = sm->m->xyz + 3 * v;
        double *o = c->dpos ? c->dpos + 3 * v : NULL;
        if (o && o[0] == x[0] && o[1] == x[1] && o[2] == x[2]) {
            /* not moved since dist[v] was found: the same distance */
        } else if (o && !isnan(o[0])) {
            /* the distance changed by at most the way the vertex moved:
             * a search bounded by that (with room for rounding) finds the
             * same nearest distance faster; unbounded if it finds none */
            double mv = sqrt((x[0] - o[0]) * (x[0] - o[0]) + (x[1] - o[1]) * (x[1] - o[1]) +
                             (x[2] - o[2]) * (x[2] - o[2]));
            double r = (dist[v] + mv) * (1.0 + 1e-9) + 1e-9 * c->h;
            int64_t tri;
            double d2 = sm_nearest_d2(c, x, r * r, &tri, NULL);
            dist[v] = tri >= 0 ? sqrt(d2) : sm_dist_to_s(c, x, NULL);
        } else {
            dist[v] = sm_dist_to_s(c, x, NULL);
        }
        if (o)
            memcpy(o, x, 3 * sizeof *o);
        if (dist[v] <= c->d_offset)
            within++;
        if (dist[v] > mx)
            mx = dist[v];
    }
    double sum = 0.0;   /* serial: a fixed order */
    for (size_t v = 0; v < sm->nv; v++)
        sum += dist[v];
    dist_summary r;
    r.within = within;
    r.max = mx;
    r.mean = sm->nbv ? sum / (double)sm->nbv : 0.0;
    return r;
}

void sm_fit_report(const st_fit_params *p, const fit_ctx *c, const char *phase,
                   int iter, const dist_summary *ds, const fit_counts *n, double t0)
{
    if (!p->on_iter)
        return;
    st_fit_iter it;
    memset(&it, 0, sizeof it);
    it.phase = phase;
    it.iter = iter;
    it.boundary_vertices = c->sm.nbv;
    it.within_offset = ds->within;
    it.max_distance = ds->max;
    sm_dihedral_range(c->sm.m, &it.min_dihedral, &it.max_dihedral);
    it.moved = n->moved;
    it.rejected = n->rejected;
    it.seconds = sm_now() - t0;
    p->on_iter(p->on_iter_ctx, &it);
}


/* ---- rescue: the vertices the fit left beyond the band --------------- */

/* Directions tried around the way to S (degrees off it) and azimuths. */
static const double rescue_tilt[] = {0.0, 30.0, 55.0, 75.0, 88.0};
#define RESCUE_AZIMUTHS 12
/* Step fractions of the way to the band's middle. */
static const double rescue_frac[] = {1.0, 0.5, 0.25, 0.125, 0.0625, 0.03125, 0.0078125};
#define RESCUE_NTILT (sizeof rescue_tilt / sizeof rescue_tilt[0])
#define RESCUE_NFRAC (sizeof rescue_frac / sizeof rescue_frac[0])
#define RESCUE_NCAND (((RESCUE_NTILT - 1) * RESCUE_AZIMUTHS + 1) * RESCUE_NFRAC)
/* Rescue and quality passes again after the quality pass, at most. */
#define FIT_LATE_RESCUES 4
/* Rounds over the vertices still beyond the band. */
#define RESCUE_ROUNDS 40
/* A rescue move may not bring its star's score below this (degrees), or
 * below what it was if lower; the quality pass raises it after. */
#define RESCUE_FLOOR 25.0

static int cmp_rescue(const void *a, const void *b)
{
    const double *x = a, *y = b;   /* {distance, px, py, pz, order} */
    if (x[0] != y[0])
        return x[0] < y[0] ? -1 : 1;
    return (x[4] > y[4]) - (x[4] < y[4]);
}

/* A boundary vertex v beyond d_offset whose ODT-plus-pull step the
 * invariant refused is held by S near its star; a step along another
 * direction that still brings it closer to S often passes (it slides past
 * what holds it). Candidates: the directions within 88 degrees of the way
 * to S's nearest point, at fractions of the way to the band's middle; the
 * closest to S first, the first that keeps the invariant and the star's
 * score floor is taken. 1 when v moved. */
static int rescue_vertex(const fit_ctx *c, uint32_t v, star_pts *sp)
{
    const sm_mesh *sm = &c->sm;
    double *x = sm->m->xyz + 3 * (size_t)v;
    double cp[3];
    double dd = sm_dist_to_s(c, x, cp);
    if (!(dd > c->d_offset))
        return 0;
    double n[3], t1[3], t2[3];
    for (int a = 0; a < 3; a++)
        n[a] = (cp[a] - x[a]) / dd;   /* toward S */
    int k = fabs(n[0]) < 0.6 ? 0 : (fabs(n[1]) < 0.6 ? 1 : 2);
    double e[3] = {0, 0, 0};
    e[k] = 1.0;
    t1[0] = n[1] * e[2] - n[2] * e[1];
    t1[1] = n[2] * e[0] - n[0] * e[2];
    t1[2] = n[0] * e[1] - n[1] * e[0];
    double l = sqrt(t1[0] * t1[0] + t1[1] * t1[1] + t1[2] * t1[2]);
    for (int a = 0; a < 3; a++)
        t1[a] /= l;
    t2[0] = n[1] * t1[2] - n[2] * t1[1];
    t2[1] = n[2] * t1[0] - n[0] * t1[2];
    t2[2] = n[0] * t1[1] - n[1] * t1[0];
    double way = dd - FIT_GOAL_FRACTION * c->d_offset;
    double cd[RESCUE_NCAND][5];
    size_t nc = 0;
    for (size_t ti = 0; ti < RESCUE_NTILT; ti++) {
        double th = rescue_tilt[ti] * 3.14159265358979323846 / 180.0;
        int naz = ti == 0 ? 1 : RESCUE_AZIMUTHS;
        for (int az = 0; az < naz; az++) {
            double ph = 2.0 * 3.14159265358979323846 * az / RESCUE_AZIMUTHS;
            double dir[3];
            for (int a = 0; a < 3; a++)
                dir[a] = cos(th) * n[a] + sin(th) * (cos(ph) * t1[a] + sin(ph) * t2[a]);
            for (size_t fi = 0; fi < RESCUE_NFRAC; fi++, nc++) {
                double st = way * rescue_frac[fi];
                for (int a = 0; a < 3; a++)
                    cd[nc][1 + a] = x[a] + st * dir[a];
                int64_t tri;
                double d2 = sm_nearest_d2(c, cd[nc] + 1, dd * dd, &tri, NULL);
                cd[nc][0] = tri >= 0 ? sqrt(d2) : INFINITY;
                cd[nc][4] = (double)nc;
            }
        }
    }
    qsort(cd, nc, sizeof cd[0], cmp_rescue);
    double floor_score = fmin(RESCUE_FLOOR, sm_star_score(sm, v, x));
    sm_star_pts_collect(c, v, sp);
    for (size_t i = 0; i < nc; i++) {
        if (!(cd[i][0] < dd))
            break;
        const double *p = cd[i] + 1;
        if (sm_star_score(sm, v, p) >= floor_score && sm_move_ok(c, v, p, sp)) {
            memcpy(x, p, 3 * sizeof *x);
            return 1;
        }
    }
    return 0;
}

/* The joint rescue runs while at most this many boundary vertices are
 * beyond d_offset: it is for the few a feature narrower than h holds (the
 * damaged corpus leaves 1 to 3 at 0.25 h and --tries 1), and each costs
 * a search over its neighbours' steps (a one-sided bunny measured against
 * the input alone, --offset-fill off at 6 cells, leaves 6 at up to
 * 0.74 h; the joint rescue brings them within 0.4 h in 20 s instead of
 * 12.7: past this count the run is left to say it missed). */
#define JOINT_MAX_BEYOND 4
/* Step lengths (units of h) of a neighbour's move in rescue_joint. */
static const double joint_step[] = {0.1, 0.05, 0.025};
#define JOINT_NSTEP (sizeof joint_step / sizeof joint_step[0])

/* A vertex v beyond d_offset that no rescue_vertex step moves is held by a
 * boundary face of its star whose two other corners lie near S: swinging
 * the face about their edge toward S would cut a concave feature of S
 * narrower than h (issue 18: a step between two planes, a hole's rim, a
 * noise bump). Moving one of those neighbours first can open the way:
 * each boundary neighbour u of v, in index order, tries the 26 directions
 * to a cube's neighbours at joint_step lengths; a step that keeps the
 * invariant, u within d_offset of S and u's star score floor is taken
 * when v's rescue then moves, and undone otherwise. 1 when v moved. */
static int rescue_joint(const fit_ctx *c, uint32_t v, star_pts *sp)
{
    const sm_mesh *sm = &c->sm;
    double *xyz = sm->m->xyz;
    for (size_t j = sm->vv_off[v]; j < sm->vv_off[v + 1]; j++) {
        const uint32_t u = sm->vv[j];
        if (!sm->onb[u])
            continue;
        double *xu = xyz + 3 * (size_t)u;
        const double save[3] = {xu[0], xu[1], xu[2]};
        const double floor_score = fmin(RESCUE_FLOOR, sm_star_score(sm, u, save));
        int collected = 0;
        for (size_t si = 0; si < JOINT_NSTEP; si++)
            for (int dz = -1; dz <= 1; dz++)
                for (int dy = -1; dy <= 1; dy++)
                    for (int dx = -1; dx <= 1; dx++) {
                        if (!dx && !dy && !dz)
                            continue;
                        const double l = joint_step[si] * c->h /
                                         sqrt((double)(dx * dx + dy * dy + dz * dz));
                        const double p[3] = {save[0] + l * dx, save[1] + l * dy,
                                             save[2] + l * dz};
                        if (!(sm_dist_to_s(c, p, NULL) <= c->d_offset) ||
                            sm_star_score(sm, u, p) < floor_score)
                            continue;
                        if (!collected) {
                            sm_star_pts_collect(c, u, sp);
                            collected = 1;
                        }
                        if (!sm_move_ok(c, u, p, sp))
                            continue;
                        memcpy(xu, p, sizeof save);
                        collected = 0;   /* sp now holds v's points */
                        if (rescue_vertex(c, v, sp))
                            return 1;
                        memcpy(xu, save, sizeof save);
                    }
    }
    return 0;
}

/* Rounds of rescue_vertex over the boundary vertices beyond d_offset, in
 * index order (few vertices, serial: the result does not depend on the
 * thread count). Returns the moves. */
static size_t rescue_pass(fit_ctx *c, double *dist, int joint)
{
    size_t moves = 0;
    star_pts sp = {NULL, 0, 0, 1, 0, 0, 0, 0};
    for (int round = 0; round < RESCUE_ROUNDS; round++) {
        size_t moved = 0;
        for (size_t v = 0; v < c->sm.nv; v++)
            if (c->sm.onb[v] && dist[v] > c->d_offset && rescue_vertex(c, (uint32_t)v, &sp)) {
                moved++;
                dist[v] = sm_dist_to_s(c, c->sm.m->xyz + 3 * v, NULL);
            }
        /* when the rescues alone move nothing, the neighbours first */
        for (size_t v = 0; v < c->sm.nv && moved == 0 && joint; v++)
            if (c->sm.onb[v] && dist[v] > c->d_offset && rescue_joint(c, (uint32_t)v, &sp)) {
                moved++;
                dist[v] = sm_dist_to_s(c, c->sm.m->xyz + 3 * v, NULL);
            }
        moves += moved;
        if (moved == 0)
            break;
    }
    free(sp.list);
    return moves;
}

/* While a boundary vertex is beyond d_offset, FIT_LATE_RESCUES times at
 * most: a rescue pass, and when it moved something the quality pass after
 * it (the rescue's floor is below the quality goal); *ds follows. */
static st_status late_rescues(fit_ctx *c, const st_fit_params *p, double *dist,
                              st_fit_stats *st, double t0, dist_summary *ds, st_error *err)
{
    /* the plain rescues first; the joint ones (rescue_joint) only for the
     * vertices those leave: tried while many are still beyond, they change
     * the stars the later plain rescues would have used (cheese-deleted50
     * at 0.25 h: 1 beyond at 0.256 h -> 2 at 0.451 h, 34.1 -> 25.0 deg) */
    for (int joint = 0; joint <= 1; joint++)
        for (int k = 0; k < FIT_LATE_RESCUES && ds->within < c->sm.nbv &&
                        (!joint || c->sm.nbv - ds->within <= JOINT_MAX_BEYOND); k++) {
            if (rescue_pass(c, dist, joint) == 0)
                break;
            st_status rc = sm_quality_pass(c, p, dist, st, t0, err);
            if (rc)
                return rc;
            *ds = sm_boundary_distances(c, dist);
        }
    return ST_OK;
}

/* ---- peeling: boundary tets that hold nothing of S ------------------- */

/* Peel rounds (each exposes new boundary tets) before a quality pass,
 * and such passes at most. */
#define PEEL_ROUNDS 6
#define PEEL_PASSES 2

/* 1 when S triangle tri meets the closed face q->f. */
static int peel_face_visit(void *ctx, uint32_t tri)
{
    const face_query *q = ctx;
    const uint32_t *t = q->s->tris + 3 * (size_t)tri;
    return st_tri_tri_intersect(q->f[0], q->f[1], q->f[2], q->s->xyz + 3 * (size_t)t[0],
                                q->s->xyz + 3 * (size_t)t[1], q->s->xyz + 3 * (size_t)t[2]);
}

typedef struct tet_query {
    const st_soup *s;
    const double *t[4];
} tet_query;

/* 1 when a vertex of S triangle tri lies in the closed tet q->t. */
static int tet_vertex_visit(void *ctx, uint32_t tri)
{
    const tet_query *q = ctx;
    const uint32_t *k = q->s->tris + 3 * (size_t)tri;
    for (int i = 0; i < 3; i++)
        if (st_point_in_tet(q->s->xyz + 3 * (size_t)k[i], q->t[0], q->t[1], q->t[2], q->t[3]) !=
            ST_OUTSIDE)
            return 1;
    return 0;
}

/* 1 when some vertex of S lies in the closed tet t: the triangles whose
 * boxes meet the tet's box hold every such vertex. */
static int svertex_in_tet(const fit_ctx *c, const double *t[4])
{
    tet_query q;
    q.s = c->s;
    double lo[3], hi[3];
    for (int a = 0; a < 3; a++) {
        lo[a] = fmin(fmin(t[0][a], t[1][a]), fmin(t[2][a], t[3][a]));
        hi[a] = fmax(fmax(t[0][a], t[1][a]), fmax(t[2][a], t[3][a]));
    }
    for (int i = 0; i < 4; i++)
        q.t[i] = t[i];
    return st_bvh_query_box(c->bvh, lo, hi, tet_vertex_visit, &q) != 0;
}

/* 1 when r and s share a boundary face (rs is a boundary edge). */
static int boundary_edge(const sm_mesh *sm, uint32_t r, uint32_t s)
{
    for (size_t j = sm->vf_off[r]; j < sm->vf_off[r + 1]; j++) {
        const uint32_t *f = sm->bf + 3 * (size_t)sm->vf[j];
        if (f[0] == s || f[1] == s || f[2] == s)
            return 1;
    }
    return 0;
}

/* Whether boundary tet t (nbr: its face neighbours) can go: it holds no
 * vertex of S, none of the faces it would expose meets S (so every S
 * triangle that was inside the mesh still is: one that entered t without
 * a vertex in it crossed a face of t, and its boundary faces are clear),
 * and the boundary stays a manifold: with one boundary face, the corner
 * opposite it is an interior vertex (it becomes a boundary vertex, and
 * must be within d_offset of S); with two, the edge of the two exposed
 * faces is not a boundary edge. Three or four boundary faces: kept. */
static int peelable(const fit_ctx *c, size_t t, const int64_t *nbr)
{
    const sm_mesh *sm = &c->sm;
    const uint32_t *k = sm->m->tets + 4 * t;
    int nb = 0, bc[4];
    for (int i = 0; i < 4; i++)
        if (nbr[4 * t + (size_t)i] < 0)
            bc[nb++] = i;
    if (nb == 1) {
        uint32_t a = k[bc[0]];
        if (sm->onb[a] || !(sm_dist_to_s(c, sm->m->xyz + 3 * (size_t)a, NULL) <= c->d_offset))
            return 0;
    } else if (nb == 2) {
        if (boundary_edge(sm, k[bc[0]], k[bc[1]]))
            return 0;
    } else {
        return 0;
    }
    const double *p[4];
    for (int i = 0; i < 4; i++)
        p[i] = sm->m->xyz + 3 * (size_t)k[i];
    if (svertex_in_tet(c, p))
        return 0;
    for (int i = 0; i < 4; i++) {
        if (nbr[4 * t + (size_t)i] < 0)
            continue;
        face_query q;
        q.s = c->s;
        for (int j = 0, n = 0; j < 4; j++)
            if (j != i)
                q.f[n++] = p[j];
        if (st_bvh_query_tri(c->bvh, q.f[0], q.f[1], q.f[2], peel_face_visit, &q))
            return 0;
    }
    return 1;
}

typedef struct peel_cand {
    double score;
    size_t tet;
} peel_cand;

static int cmp_peel(const void *a, const void *b)
{
    const peel_cand *x = a, *y = b;
    if (x->score != y->score)
        return x->score < y->score ? -1 : 1;
    return (x->tet > y->tet) - (x->tet < y->tet);
}

/* One round: the boundary tets scoring below `goal` that peelable allows,
 * worst first, no two sharing a vertex (so each check sees the mesh it
 * changes), are removed, with their cell arrays; the incidence is rebuilt.
 * *peeled gets the count. A non-conforming mesh is left alone. */
static st_status peel_round(fit_ctx *c, double goal, size_t *peeled, st_error *err)
{
    st_tetmesh *m = c->sm.m;
    *peeled = 0;
    int64_t *nbr = NULL;
    size_t nonmanifold = 0;
    st_status rc = st_tetmesh_neighbors(m, &nbr, &nonmanifold, err);
    if (rc || nonmanifold) {
        free(nbr);
        return rc;
    }
    peel_cand *cand = st_malloc_array(m->ntets ? m->ntets : 1, sizeof *cand);
    unsigned char *gone = st_calloc_array(m->ntets ? m->ntets : 1, 1);
    unsigned char *touched = st_calloc_array(m->npoints ? m->npoints : 1, 1);
    if (!cand || !gone || !touched) {
        rc = st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory (peeling)");
        goto out;
    }
    const st_tet_array *cls = st_tetmesh_find_array(m, "sculpt", ST_ON_CELLS);
    if (cls && (cls->assoc != ST_ON_CELLS || cls->ncomp != 1))
        cls = NULL;
    size_t nc = 0;
    for (size_t t = 0; t < m->ntets; t++) {
        const uint32_t *k = m->tets + 4 * t;
        if (cls && cls->values[t] == (double)ST_SCULPT_VOLUME)
            continue;
        if (nbr[4 * t] >= 0 && nbr[4 * t + 1] >= 0 && nbr[4 * t + 2] >= 0 && nbr[4 * t + 3] >= 0)
            continue;
        double sc = sm_tet_score(m->xyz + 3 * (size_t)k[0], m->xyz + 3 * (size_t)k[1],
                                 m->xyz + 3 * (size_t)k[2], m->xyz + 3 * (size_t)k[3]);
        if (sc < goal) {
            cand[nc].score = sc;
            cand[nc].tet = t;
            nc++;
        }
    }
    qsort(cand, nc, sizeof *cand, cmp_peel);
    for (size_t i = 0; i < nc; i++) {
        size_t t = cand[i].tet;
        const uint32_t *k = m->tets + 4 * t;
        if (touched[k[0]] || touched[k[1]] || touched[k[2]] || touched[k[3]] ||
            !peelable(c, t, nbr))
            continue;
        gone[t] = 1;
        for (int j = 0; j < 4; j++)
            touched[k[j]] = 1;
        (*peeled)++;
    }
    if (*peeled) {
        size_t n = 0;
        for (size_t t = 0; t < m->ntets; t++) {
            if (gone[t])
                continue;
            memmove(m->tets + 4 * n, m->tets + 4 * t, 4 * sizeof *m->tets);
            for (size_t a = 0; a < m->narrays; a++) {
                st_tet_array *ar = &m->arrays[a];
                if (ar->assoc == ST_ON_CELLS)
                    memmove(ar->values + (size_t)ar->ncomp * n, ar->values + (size_t)ar->ncomp * t,
                            (size_t)ar->ncomp * sizeof *ar->values);
            }
            n++;
        }
        m->ntets = n;
        sm_mesh_free(&c->sm);
        rc = sm_mesh_build(&c->sm, m, err);
    }
out:
    free(nbr);
    free(cand);
    free(gone);
    free(touched);
    return rc;
}

/* ---- entry points ----------------------------------------------------- */

static double mesh_h(const st_tetmesh *m, double given)
{
    if (given > 0.0)
        return given;
    const char *s = st_meta_get(&m->meta, "h");
    if (!s)
        return 0.0;
    char *end;
    double h = strtod(s, &end);
    if (end == s || !isfinite(h) || !(h > 0.0))
        return 0.0;
    return h;
}

st_status st_fit(st_tetmesh *m, const st_soup *s, const st_bvh *bvh,
                 const st_fit_params *pp, st_fit_stats *stats,
                 const st_progress *prog, st_error *err)
{
    st_fit_params p = pp ? *pp : st_fit_params_default();
    double t0 = sm_now();
    st_fit_stats st;
    memset(&st, 0, sizeof st);
    if (stats)
        memset(stats, 0, sizeof *stats);
    if (!(p.offset_ratio > 0.0) || !(p.step > 0.0 && p.step <= 1.0) || p.max_iters < 0 ||
        p.quality_rounds < 0 || !(p.cell_width >= 0.0))
        return st_error_set(err, ST_EINPUT, NULL, 0, "bad fit parameters");
    if (m->ntets == 0)
        return st_error_set(err, ST_EINPUT, NULL, 0, "the mesh has no tets");
    if (!s || s->ntris == 0)
        return st_error_set(err, ST_EINPUT, NULL, 0, "the surface has no triangles");
    double h = mesh_h(m, p.cell_width);
    if (!(h > 0.0))
        return st_error_set(err, ST_EINPUT, NULL, 0,
                            "no cell width: the mesh has no meta \"h\" (give the "
                            "lattice cell width)");
    size_t bad = sm_count_nonpositive(m);
    if (bad)
        return st_error_set(err, ST_EINPUT, NULL, 0,
                            "%zu of %zu tets are inverted or flat: the fit needs a "
                            "positively oriented mesh", bad, m->ntets);
    fit_ctx c;
    memset(&c, 0, sizeof c);
    c.s = s;
    c.h = h;
    c.d_offset = p.offset_ratio * h;
    st_bvh *own = NULL, *fown = NULL;
    double *dist = NULL;
    dirty dy;
    memset(&dy, 0, sizeof dy);
    st_status rc = ST_OK;
    if (!bvh) {
        rc = st_bvh_build(&own, s, err);
        if (rc)
            return rc;
        bvh = own;
    }
    c.bvh = bvh;
    c.prog = prog;
    if (p.fill && p.fill->ntris > 0) {
        rc = st_bvh_build(&fown, p.fill, err);
        if (rc)
            goto done;
        c.fbvh = fown;
    }
    rc = sm_mesh_build(&c.sm, m, err);
    if (rc)
        goto done;
    {
        int64_t *nbr = NULL;
        size_t nonmanifold = 0;
        rc = st_tetmesh_neighbors(m, &nbr, &nonmanifold, err);
        free(nbr);
        if (rc)
            goto done;
        c.full_check = nonmanifold > 0;
    }
    /* the point grid's bins a quarter of the cell: the swept test and the
     * star scans visit whole bins (issue 23: 10 million triangles at
     * --cells 10 put ~100k S vertices in an h bin) */
    if (pgrid_build(&c.pg, s, h / 4.0) || sm_dirty_init(&dy, m->npoints) ||
        !(c.blocker = st_malloc_array(m->npoints, sizeof *c.blocker)) ||
        !(c.dpos = st_malloc_array(m->npoints, 3 * sizeof *c.dpos)) ||
        !(dist = st_malloc_array(m->npoints, sizeof *dist))) {
        rc = st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory (fit)");
        goto done;
    }
    st.h = h;
    st.d_offset = c.d_offset;
    st.boundary_vertices = c.sm.nbv;
    for (size_t v = 0; v < m->npoints; v++) {
        c.blocker[v] = UINT32_MAX;
        c.dpos[3 * v] = NAN;
    }
    sm_dihedral_range(m, &st.min_dihedral_before, &st.max_dihedral_before);
    if (p.count_before &&
        (rc = st_enclosure_count(m, s, bvh, &st.outside_before, &st.crossing_before, err)))
        goto done;

    dist_summary ds = sm_boundary_distances(&c, dist);
    size_t best_within = ds.within;
    int since_best = 0;
    for (int it = 0; it < p.max_iters && ds.within < c.sm.nbv; it++) {
        if (st_progress_cancelled(prog)) {
            rc = st_error_set(err, ST_ECANCELLED, NULL, 0, "cancelled");
            goto done;
        }
        st_progress_report(prog, "fit", (double)ds.within / (double)(c.sm.nbv ? c.sm.nbv : 1));
        fit_counts n = {0, 0, 0};
        for (size_t col = 0; col < c.sm.ncolours; col++) {
            size_t moved = 0, rejected = 0, skipped = 0;
            dy.step++;
            #pragma omp parallel reduction(+ : moved, rejected, skipped) \
                if (PAR_CHECKED(c.sm.col_off[col + 1] - c.sm.col_off[col]))
            {
                star_pts sp = {NULL, 0, 0, 1, 0, 0, 0, 0};
                #pragma omp for schedule(dynamic, 4)
                for (size_t j = c.sm.col_off[col]; j < c.sm.col_off[col + 1]; j++) {
                    fit_counts k = {0, 0, 0};
                    uint32_t v = c.sm.col_v[j];
                    if (sm_dirty_unchanged(&dy, &c.sm, v)) {
                        skipped++;   /* it would fail as it did */
                        continue;
                    }
                    sm_dirty_mark(&dy, v, fit_vertex(&c, v, p.step, dist, &sp, &k));
                    moved += k.moved;
                    rejected += k.rejected;
                    skipped += k.skipped;
                }
                free(sp.list);
            }
            n.moved += moved;
            n.rejected += rejected;
            n.skipped += skipped;
        }
        st.iters = it + 1;
        st.moves += n.moved;
        st.rejected += n.rejected;
        st.skipped += n.skipped;
        ds = sm_boundary_distances(&c, dist);
        sm_fit_report(&p, &c, "fit", it + 1, &ds, &n, t0);
        if (n.moved == 0)
            break;
        if (ds.within > best_within) {
            best_within = ds.within;
            since_best = 0;
        } else if (++since_best >= FIT_STALL_ITERS) {
            break;   /* the rest are held back: thin gaps or blocked moves */
        }
    }
    if (ds.within < c.sm.nbv) {
        rescue_pass(&c, dist, 0);
        ds = sm_boundary_distances(&c, dist);
    }
    st.converged = ds.within == c.sm.nbv;
    sm_dihedral_range(m, &st.min_dihedral_fit, &st.max_dihedral_fit);
    st.seconds_fit = sm_now() - t0;
    if (p.quality) {
        st_progress_report(prog, "quality", 0.0);
        if ((rc = sm_quality_pass(&c, &p, dist, &st, t0, err)))
            goto done;
        ds = sm_boundary_distances(&c, dist);
        /* the quality moves change the stars of the vertices still held:
         * another rescue, and the quality pass again after it */
        if ((rc = late_rescues(&c, &p, dist, &st, t0, &ds, err)))
            goto done;
        /* A last quality pass that also steps along the 26 cube
         * directions (quality.c). Last, so that the rescues above run as
         * before: it keeps every boundary vertex within max(d_offset, its
         * distance) and raises the lowest score of every star it changes,
         * so neither the beyond count nor the worst score can get worse.
         * Issue 18, --tries 1, min dihedral before -> after, R 0.4:
         * armadillo 29.24 -> 30.09, man-interpenetrating 27.58 -> 29.20,
         * teapot 31.24 -> 34.77; tetsmooth --fit on the bunny's 6-cell
         * lattice 29.96 -> 34.13 (R 0.25: 26.23 -> 29.76). With the cube
         * steps in every quality pass the angles rose further (armadillo
         * 31.06, man-interpenetrating 30.21, bunny 35.09) but the rescues
         * after them then left one vertex at 0.402 h on rotor-soup,
         * -duplicated and -flipped and 0.404 h on b9_mesh (0 before). */
        c.cube_steps = 1;
        if ((rc = sm_quality_pass(&c, &p, dist, &st, t0, err)))
            goto done;
        ds = sm_boundary_distances(&c, dist);
        /* Peeling: boundary tets below the goal that hold nothing of S go
         * (peel_round), and the quality pass runs on the new boundary. */
        for (int k = 0; k < PEEL_PASSES && p.peel; k++) {
            size_t peeled = 0, n;
            for (int r = 0; r < PEEL_ROUNDS; r++, peeled += n) {
                if ((rc = peel_round(&c, p.quality_goal, &n, err)))
                    goto done;
                if (n == 0)
                    break;
            }
            if (peeled == 0)
                break;
            st.peeled += peeled;
            ds = sm_boundary_distances(&c, dist);
            if ((rc = sm_quality_pass(&c, &p, dist, &st, t0, err)))
                goto done;
            ds = sm_boundary_distances(&c, dist);
        }
        /* The cube steps and the peeling change the stars of the vertices
         * still held, as the quality pass did: the rescue once more, each
         * followed by the quality pass (with the cube steps). Issue 18,
         * soupmesh --tries 1 at R 0.25, beyond (farthest) before -> after:
         * cheese-deleted50 --seed 1 2 (0.443 h) -> 1 (0.256 h), whose
         * straight step to the band passed the invariant after the last
         * pass; couplingdown-largeholes --seed 13757245211066428519
         * 1 (0.336 h) -> 1 (0.311 h). */
        if ((rc = late_rescues(&c, &p, dist, &st, t0, &ds, err)))
            goto done;
    }
    st.boundary_vertices = c.sm.nbv;
    st.within_offset = ds.within;
    st.converged = ds.within == c.sm.nbv;
    st.beyond_offset = c.sm.nbv - ds.within;
    st.max_distance = ds.max;
    st.mean_distance = ds.mean;
    sm_dihedral_range(m, &st.min_dihedral_after, &st.max_dihedral_after);
    st.seconds_quality = sm_now() - t0 - st.seconds_fit;
    rc = st_enclosure_count(m, s, bvh, &st.outside_after, &st.crossing_after, err);
    st_progress_report(prog, "quality", 1.0);
done:
    if (stats)
        *stats = st;
    free(dist);
    free(c.blocker);
    free(c.dpos);
    sm_dirty_free(&dy);
    pgrid_free(&c.pg);
    sm_mesh_free(&c.sm);
    st_bvh_free(own);
    st_bvh_free(fown);
    return rc;
}

