/*
 * fit.c - enclosing vertex adjustment of a tet mesh to a surface (st_fit,
 * smooth.h), and the exact enclosure count (st_enclosure_count).
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
 * Not checked: that the boundary does not fold onto another part of the
 * mesh far from the moved star (a global self-intersection); small steps
 * and positive stars make it unlikely, tetstat would show it as overlap.
 *
 * The quality pass (past the paper) then works on the vertices of the
 * tets whose score min(min dihedral, 0.75 (180 - max dihedral)) is below
 * the goal: for each, a handful of candidate positions (toward its ODT
 * target, toward its neighbours' centroid, line searches along the
 * gradient of its worst tet's score and along the summed unit gradients of
 * the tets within QUAL_ACTIVE of the worst, small steps along the axes),
 * best first; the first that raises the lowest score of the star and keeps
 * the invariant (and, for a boundary vertex, keeps it within
 * max(d_offset, its distance) of S) is taken. A boundary vertex at the
 * band's edge, or past it where a thin gap held it back, can take no step
 * with an outward component, and those are most of the gradient steps: on
 * the armadillo the worst tets (21.7 degrees) all had such vertices, every
 * candidate refused by the distance rule. So a boundary vertex also
 * searches the same gradients projected onto the tangent plane of S's
 * distance (and a little inward of it). Rounds repeat until no tet scores
 * below the goal or nothing moves.
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
#include "souptet/smooth.h"
#include "souptet/enclose.h"
#include "souptet/tetqual.h"

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
/* Quality pass: the smallest score gain (degrees) worth a move, so rounds
 * end instead of trading rounding noise. */
#define QUAL_MIN_GAIN 1e-3
/* Line search steps along the score gradient, in units of h. */
static const double qual_steps[] = {0.2, 0.1, 0.05, 0.025, 0.0125, 0.00625};
#define QUAL_NSTEPS (sizeof qual_steps / sizeof qual_steps[0])
/* Tangential candidates of a boundary vertex: inward components, as a
 * fraction of the step (0: in the tangent plane; 0.25: a quarter inward,
 * which keeps the distance from growing where S curves away by up to
 * about 14 degrees over the step). */
static const double qual_inward[] = {0.0, 0.25};
#define QUAL_NTANGENT 2
/* Tets within this many degrees of the worst one steer the combined
 * gradient direction. */
#define QUAL_ACTIVE 2.0
/* The axis-direction candidates' step, in units of h. */
#define QUAL_AXIS_STEP 0.03
/* Central-difference step for the score gradient, in units of h. */
#define QUAL_GRAD_EPS 1e-4

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
    return p;
}

/* ---- the vertices of S in bins -------------------------------------- */

typedef struct pgrid {
    double *pts;          /* distinct vertices of S, 3 each */
    size_t npts;
    double lo[3], cell;
    size_t n[3];
    size_t *off;          /* bin -> points (CSR) */
    uint32_t *idx;
} pgrid;

static int cmp_pt(const void *a, const void *b)
{
    const double *x = a, *y = b;
    for (int k = 0; k < 3; k++)
        if (x[k] != y[k])
            return x[k] < y[k] ? -1 : 1;
    return 0;
}

static void pgrid_free(pgrid *g)
{
    free(g->pts);
    free(g->off);
    free(g->idx);
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

/* The distinct vertices of s's triangles, binned at about `cell`. */
static st_status pgrid_build(pgrid *g, const st_soup *s, double cell)
{
    memset(g, 0, sizeof *g);
    size_t n3;
    if (st_size_mul(&n3, s->ntris, 9))
        return ST_ENOMEM;
    g->pts = st_malloc_array(n3 ? n3 : 1, sizeof *g->pts);
    if (!g->pts)
        return ST_ENOMEM;
    for (size_t i = 0; i < 3 * s->ntris; i++)
        memcpy(g->pts + 3 * i, s->xyz + 3 * (size_t)s->tris[i], 3 * sizeof(double));
    size_t n = 3 * s->ntris;
    qsort(g->pts, n, 3 * sizeof(double), cmp_pt);
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
    return ST_OK;
}

/* ---- the invariant -------------------------------------------------- */

typedef struct fit_ctx {
    sm_mesh sm;
    const st_soup *s;
    const st_bvh *bvh;
    pgrid pg;
    double *dpos;        /* per vertex: where its distance in dist[] was
                            taken (3 each; NaN: not yet) */
    uint32_t *blocker;   /* per vertex: the S vertex that last stopped its
                            move (a point grid index), or UINT32_MAX */
    double h, d_offset;
    int full_check;   /* non-conforming faces: test S vertices everywhere */
    int fair_boundary;   /* no S (after fairing): boundary vertices move in
                            their tangent plane only (sm_quality_fair) */
} fit_ctx;

/* Which vertices can be skipped: a vertex move is a deterministic function
 * of the vertex's position and its neighbours' (its star), so a vertex
 * that was tried and did not move, with nothing in its star moved since,
 * would not move again; skipping it changes no result. Steps count colour
 * sets; a vertex and its neighbours never share a colour, so during a
 * colour step no vertex reads a stamp being written. */
typedef struct dirty {
    uint32_t *moved_at;   /* step of the last move (0: never) */
    uint32_t *tried_at;   /* step of the last attempt that did not move */
    uint32_t step;
} dirty;

static int dirty_init(dirty *d, size_t nv)
{
    d->step = 0;
    d->moved_at = st_calloc_array(nv ? nv : 1, sizeof *d->moved_at);
    d->tried_at = st_calloc_array(nv ? nv : 1, sizeof *d->tried_at);
    return d->moved_at && d->tried_at ? 0 : -1;
}

static void dirty_free(dirty *d)
{
    free(d->moved_at);
    free(d->tried_at);
    memset(d, 0, sizeof *d);
}

/* 1 when an attempt to move v would repeat one that did not move. */
static int dirty_unchanged(const dirty *d, const sm_mesh *sm, uint32_t v)
{
    uint32_t t = d->tried_at[v];
    if (t == 0 || d->moved_at[v] >= t)
        return 0;
    for (size_t j = sm->vv_off[v]; j < sm->vv_off[v + 1]; j++)
        if (d->moved_at[sm->vv[j]] >= t)
            return 0;
    return 1;
}

static void dirty_mark(dirty *d, uint32_t v, int moved)
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

/* An S vertex in a star and the star tet that held it. */
typedef struct star_pt {
    uint32_t pt;     /* index into the point grid */
    uint32_t tet;    /* index from vt_off[v] */
} star_pt;

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
                            if (in_star_tet(sm, v, u, x, q)) {
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

/* The scratch list of S vertices in a star (one per thread and call). */
typedef struct star_pts {
    star_pt *list;
    size_t n, cap;
    int ok;          /* 0: out of memory, refuse every move */
    int have;        /* 1: list holds the star of v as it is */
    int positive;    /* the star as it is: every tet positive */
    uint32_t v;
} star_pts;

/* Collect the S vertices v's star holds now. Only a boundary vertex (or
 * any vertex of a non-conforming mesh) needs them: the faces of an
 * interior vertex's star opposite it form a closed surface that does not
 * move, and when every tet of the new star is positive, the new star
 * covers each point exactly winding-number-of-that-surface times, i.e.
 * it is the same closed region as before. */
static void star_pts_fill(const fit_ctx *c, star_pts *sp)
{
    sp->n = 0;
    sp->ok = 1;
    sp->have = 1;
    sp->positive = 0;
    if (c->s && (c->sm.onb[sp->v] || c->full_check)) {
        sp->ok = svertices_in_star(c, sp->v, &sp->list, &sp->n, &sp->cap) == 0;
        sp->positive = sp->n > 0 &&
                       sm_star_positive(&c->sm, sp->v, c->sm.m->xyz + 3 * (size_t)sp->v);
    }
}

/* Start the moves of v: the list is filled when a move first needs it
 * (most trial positions fail the cheaper tests). */
static void star_pts_collect(const fit_ctx *c, uint32_t v, star_pts *sp)
{
    (void)c;
    sp->have = 0;
    sp->v = v;
}

/* The whole invariant for moving v to p, cheapest test first. */
static int move_ok(const fit_ctx *c, uint32_t v, const double p[3], star_pts *sp)
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
        star_pts_fill(c, sp);
    if (!sp->ok)
        return 0;
    uint32_t failed;
    if (!svertices_kept(c, v, p, sp->list, sp->n, sp->positive, &failed)) {
        if (c->blocker)
            c->blocker[v] = failed;   /* v's own slot: v's colour writes it */
        return 0;
    }
    if (c->s && c->sm.onb[v] && !faces_clear(c, v, p))
        return 0;
    return 1;
}

static double dist_to_s(const fit_ctx *c, const double p[3], double closest[3])
{
    int64_t tri;
    double q[3];
    double d2 = st_bvh_nearest(c->bvh, p, INFINITY, &tri, closest ? closest : q);
    return sqrt(d2);
}

/* ---- fit iterations --------------------------------------------------- */

typedef struct fit_counts {
    size_t moved, rejected, skipped;
} fit_counts;

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
        double dd = dist_to_s(c, x, cp);
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
    star_pts_collect(c, v, sp);
    double floor_score = fmin(FIT_SLIVER_FLOOR, sm_star_score(sm, v, x));
    double f = 1.0;
    for (int k = 0; k <= FIT_HALVINGS; k++, f *= 0.5) {
        double p[3] = {x[0] + f * d[0], x[1] + f * d[1], x[2] + f * d[2]};
        if (sm_star_score(sm, v, p) >= floor_score && move_ok(c, v, p, sp)) {
            memcpy(x, p, sizeof p);
            n->moved++;
            return 1;
        }
        n->rejected++;
    }
    n->skipped++;
    return 0;
}

typedef struct dist_summary {
    size_t within;
    double max, mean;
} dist_summary;

static dist_summary boundary_distances(const fit_ctx *c, double *dist)
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
        if (o && !isnan(o[0])) {
            /* the distance changed by at most the way the vertex moved:
             * a search bounded by that (with room for rounding) finds the
             * same nearest distance faster; unbounded if it finds none */
            double mv = sqrt((x[0] - o[0]) * (x[0] - o[0]) + (x[1] - o[1]) * (x[1] - o[1]) +
                             (x[2] - o[2]) * (x[2] - o[2]));
            double r = (dist[v] + mv) * (1.0 + 1e-9) + 1e-9 * c->h;
            int64_t tri;
            double d2 = st_bvh_nearest(c->bvh, x, r * r, &tri, NULL);
            dist[v] = tri >= 0 ? sqrt(d2) : dist_to_s(c, x, NULL);
        } else {
            dist[v] = dist_to_s(c, x, NULL);
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

static void report(const st_fit_params *p, const fit_ctx *c, const char *phase,
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

/* ---- quality pass ----------------------------------------------------- */

static int cmp_cand(const void *a, const void *b)
{
    const double *x = a, *y = b;   /* {score, px, py, pz, order} */
    if (x[0] != y[0])
        return x[0] > y[0] ? -1 : 1;
    return (x[4] > y[4]) - (x[4] < y[4]);
}

/* Try to raise the lowest score of v's star; 1 when v moved. */
/* The sum of the area-weighted outward normals of v's boundary faces. */
static void fair_normal(const sm_mesh *sm, uint32_t v, double n[3])
{
    n[0] = n[1] = n[2] = 0.0;
    for (size_t j = sm->vf_off[v]; j < sm->vf_off[v + 1]; j++) {
        const uint32_t *f = sm->bf + 3 * (size_t)sm->vf[j];
        const double *a = sm->m->xyz + 3 * (size_t)f[0];
        const double *b = sm->m->xyz + 3 * (size_t)f[1];
        const double *d = sm->m->xyz + 3 * (size_t)f[2];
        double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
        double w[3] = {d[0] - a[0], d[1] - a[1], d[2] - a[2]};
        n[0] += u[1] * w[2] - u[2] * w[1];
        n[1] += u[2] * w[0] - u[0] * w[2];
        n[2] += u[0] * w[1] - u[1] * w[0];
    }
    double l = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (l > 0.0 && isfinite(l))
        for (int a = 0; a < 3; a++)
            n[a] /= l;
    else
        n[0] = n[1] = n[2] = 0.0;
}

static int quality_vertex(const fit_ctx *c, uint32_t v, star_pts *sp, size_t *rejected)
{
    const sm_mesh *sm = &c->sm;
    /* no surface (after fairing): the boundary stays, or with
     * fair_boundary moves only within its tangent plane */
    const int tangent_only = !c->s && sm->onb[v];
    if (tangent_only && !c->fair_boundary)
        return 0;
    double *x = sm->m->xyz + 3 * (size_t)v;
    double s0 = sm_star_score(sm, v, x);
    /* candidates: {score, x, y, z, order} */
    double cand[5 + 2 * QUAL_NSTEPS + 6 + 2 * QUAL_NTANGENT * QUAL_NSTEPS][5];
    int nc = 0;
    double t[3];
    sm_odt_target(sm, v, t);
    static const double fr[] = {1.0, 0.5, 0.25};
    for (int k = 0; k < 3; k++, nc++)
        for (int a = 0; a < 3; a++)
            cand[nc][1 + a] = x[a] + fr[k] * (t[a] - x[a]);
    double cen[3] = {0, 0, 0};
    size_t deg = sm->vv_off[v + 1] - sm->vv_off[v];
    for (size_t j = sm->vv_off[v]; j < sm->vv_off[v + 1]; j++)
        for (int a = 0; a < 3; a++)
            cen[a] += sm->m->xyz[3 * (size_t)sm->vv[j] + (size_t)a] / (double)deg;
    for (int k = 0; k < 2; k++, nc++)
        for (int a = 0; a < 3; a++)
            cand[nc][1 + a] = x[a] + fr[k] * (cen[a] - x[a]);
    /* gradients (central differences) of the worst tet's score, and the
     * sum of the unit gradients of every tet within QUAL_ACTIVE degrees of
     * it (so that raising the worst does not just lower the next one) */
    double ws = sm_star_score(sm, v, x);
    double gw[3] = {0, 0, 0}, ga[3] = {0, 0, 0}, e = QUAL_GRAD_EPS * c->h, best = INFINITY;
    for (size_t j = sm->vt_off[v]; j < sm->vt_off[v + 1]; j++) {
        const uint32_t *k = sm->m->tets + 4 * (size_t)sm->vt[j];
        const double *q[4];
        for (int i = 0; i < 4; i++)
            q[i] = sm->m->xyz + 3 * (size_t)k[i];
        double sc = sm_tet_score(q[0], q[1], q[2], q[3]);
        if (sc > ws + QUAL_ACTIVE)
            continue;
        double g[3];
        for (int a = 0; a < 3; a++) {
            double pp[3], pm[3];
            memcpy(pp, x, sizeof pp);
            memcpy(pm, x, sizeof pm);
            pp[a] += e;
            pm[a] -= e;
            const double *qp[4], *qm[4];
            for (int i = 0; i < 4; i++) {
                qp[i] = k[i] == v ? pp : q[i];
                qm[i] = k[i] == v ? pm : q[i];
            }
            g[a] = sm_tet_score(qp[0], qp[1], qp[2], qp[3]) -
                   sm_tet_score(qm[0], qm[1], qm[2], qm[3]);
        }
        double gl = sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
        if (!(gl > 0.0) || !isfinite(gl))
            continue;
        for (int a = 0; a < 3; a++)
            ga[a] += g[a] / gl;
        if (sc < best) {
            best = sc;
            for (int a = 0; a < 3; a++)
                gw[a] = g[a] / gl;
        }
    }
    const double *dirs[2] = {gw, ga};
    for (int d = 0; d < 2; d++) {
        const double *g = dirs[d];
        double gl = sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
        if (gl > 0.0 && isfinite(gl))
            for (size_t k2 = 0; k2 < QUAL_NSTEPS; k2++, nc++)
                for (int a = 0; a < 3; a++)
                    cand[nc][1 + a] = x[a] + qual_steps[k2] * c->h * g[a] / gl;
    }
    /* a boundary vertex may not move away from S beyond the band (nor
     * beyond where it is), so at the band's edge or past it (held back by
     * a thin gap) every step with an outward component fails: search the
     * same gradients within the tangent plane of S's distance too, and
     * slightly inward of it, where the surface curves away */
    double dx = 0.0, nrm[3] = {0, 0, 0};
    if (c->s && sm->onb[v]) {
        double cp[3];
        dx = dist_to_s(c, x, cp);
        if (dx > 0.0)
            for (int a = 0; a < 3; a++)
                nrm[a] = (x[a] - cp[a]) / dx;
    }
    if (tangent_only) {
        /* the boundary's area-weighted normal: the gradient of the volume
         * in v, so steps across it keep the volume to first order; only
         * those candidates are kept */
        nc = 0;
        fair_normal(sm, v, nrm);
        dx = nrm[0] != 0.0 || nrm[1] != 0.0 || nrm[2] != 0.0 ? 1.0 : 0.0;
    }
    if (dx > 0.0)
        for (int d = 0; d < 2; d++) {
            const double *g = dirs[d];
            double gn = g[0] * nrm[0] + g[1] * nrm[1] + g[2] * nrm[2];
            double gt[3] = {g[0] - gn * nrm[0], g[1] - gn * nrm[1], g[2] - gn * nrm[2]};
            double gl = sqrt(gt[0] * gt[0] + gt[1] * gt[1] + gt[2] * gt[2]);
            if (!(gl > 0.0) || !isfinite(gl))
                continue;
            for (int b = 0; b < (tangent_only ? 1 : QUAL_NTANGENT); b++)
                for (size_t k2 = 0; k2 < QUAL_NSTEPS; k2++, nc++) {
                    double st = qual_steps[k2] * c->h;
                    for (int a = 0; a < 3; a++)
                        cand[nc][1 + a] = x[a] + st * (gt[a] / gl - qual_inward[b] * nrm[a]);
                }
        }
    /* the six axis directions, a small step: a way out where the
     * gradients point into the invariant */
    for (int a = 0; a < 6 && !tangent_only; a++, nc++)
        for (int b2 = 0; b2 < 3; b2++)
            cand[nc][1 + b2] = x[b2] + (b2 == a / 2 ? (a & 1 ? -1.0 : 1.0) * QUAL_AXIS_STEP * c->h : 0.0);
    if (nc == 0)
        return 0;
    for (int i = 0; i < nc; i++) {
        cand[i][0] = sm_star_score(sm, v, cand[i] + 1);
        cand[i][4] = i;
    }
    qsort(cand, (size_t)nc, sizeof cand[0], cmp_cand);
    if (!(cand[0][0] > s0 + QUAL_MIN_GAIN))
        return 0;
    star_pts_collect(c, v, sp);
    double dmax = fmax(c->d_offset, dx);
    for (int i = 0; i < nc; i++) {
        if (!(cand[i][0] > s0 + QUAL_MIN_GAIN))
            break;
        const double *p = cand[i] + 1;
        if (sm->onb[v] && c->s) {
            int64_t tri;
            double d2 = st_bvh_nearest(c->bvh, p, dmax * dmax, &tri, NULL);
            if (tri < 0 || sqrt(d2) > dmax)
                continue;
        }
        if (move_ok(c, v, p, sp)) {
            memcpy(x, p, 3 * sizeof *x);
            return 1;
        }
        (*rejected)++;
    }
    return 0;
}

/* ST_OK, or ST_ENOMEM (err set) before any vertex moved. */
static st_status quality_pass(fit_ctx *c, const st_fit_params *p, double *dist,
                              st_fit_stats *st, double t0, st_error *err)
{
    sm_mesh *sm = &c->sm;
    st_tetmesh *m = sm->m;
    unsigned char *mark = st_calloc_array(sm->nv, 1);
    dirty dy;
    if (!mark || dirty_init(&dy, sm->nv)) {
        free(mark);
        dirty_free(&dy);
        return st_error_set(err, ST_ENOMEM, NULL, 0,
                            "out of memory for the quality pass (%zu vertices)", sm->nv);
    }
    for (int round = 0; round < p->quality_rounds; round++) {
        memset(mark, 0, sm->nv);
        size_t nbad = 0;
        for (size_t t = 0; t < m->ntets; t++) {
            const uint32_t *k = m->tets + 4 * t;
            double sc = sm_tet_score(m->xyz + 3 * (size_t)k[0], m->xyz + 3 * (size_t)k[1],
                                     m->xyz + 3 * (size_t)k[2], m->xyz + 3 * (size_t)k[3]);
            if (sc < p->quality_goal) {
                nbad++;
                for (int i = 0; i < 4; i++)
                    mark[k[i]] = 1;
            }
        }
        if (nbad == 0)
            break;
        size_t moved = 0, rejected = 0;
        for (size_t col = 0; col < sm->ncolours; col++) {
            dy.step++;
            #pragma omp parallel reduction(+ : moved, rejected) \
                if (PAR_CHECKED(sm->col_off[col + 1] - sm->col_off[col]))
            {
                star_pts sp = {NULL, 0, 0, 1, 0, 0, 0};
                #pragma omp for schedule(dynamic, 8)
                for (size_t j = sm->col_off[col]; j < sm->col_off[col + 1]; j++) {
                    uint32_t v = sm->col_v[j];
                    if (mark[v] && !dirty_unchanged(&dy, sm, v)) {
                        int k = quality_vertex(c, v, &sp, &rejected);
                        dirty_mark(&dy, v, k);
                        moved += (size_t)k;
                    }
                }
                free(sp.list);
            }
        }
        st->quality_rounds = round + 1;
        st->quality_moves += moved;
        if (p->on_iter && c->s) {
            dist_summary ds = boundary_distances(c, dist);
            fit_counts n = {moved, rejected, 0};
            report(p, c, "quality", round + 1, &ds, &n, t0);
        }
        if (moved == 0)
            break;
    }
    free(mark);
    dirty_free(&dy);
    return ST_OK;
}

/* The quality pass on a borrowed mesh (fairing's), with or without the
 * boundary's tangent moves. */
static st_status quality_on(sm_mesh *sm, double h, int rounds, double goal, int boundary,
                            size_t *moves, st_error *err)
{
    fit_ctx c;
    memset(&c, 0, sizeof c);
    c.sm = *sm;   /* borrowed: not freed here */
    c.h = h;
    c.fair_boundary = boundary;
    st_fit_params p = st_fit_params_default();
    p.quality_rounds = rounds;
    p.quality_goal = goal;
    st_fit_stats st;
    memset(&st, 0, sizeof st);
    st_status rc = quality_pass(&c, &p, NULL, &st, 0.0, err);
    *moves = st.quality_moves;
    return rc;
}

st_status sm_quality_interior(sm_mesh *sm, double h, int rounds, double goal,
                              size_t *moves, st_error *err)
{
    return quality_on(sm, h, rounds, goal, 0, moves, err);
}

st_status sm_quality_fair(sm_mesh *sm, double h, int rounds, double goal, size_t *moves,
                          st_error *err)
{
    return quality_on(sm, h, rounds, goal, 1, moves, err);
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
    st_bvh *own = NULL;
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
    if (pgrid_build(&c.pg, s, h) || dirty_init(&dy, m->npoints) ||
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
    rc = st_enclosure_count(m, s, bvh, &st.outside_before, &st.crossing_before, err);
    if (rc)
        goto done;

    dist_summary ds = boundary_distances(&c, dist);
    size_t best_within = ds.within;
    int since_best = 0;
    for (int it = 0; it < p.max_iters && ds.within < c.sm.nbv; it++) {
        st_progress_report(prog, "fit", (double)ds.within / (double)(c.sm.nbv ? c.sm.nbv : 1));
        fit_counts n = {0, 0, 0};
        for (size_t col = 0; col < c.sm.ncolours; col++) {
            size_t moved = 0, rejected = 0, skipped = 0;
            dy.step++;
            #pragma omp parallel reduction(+ : moved, rejected, skipped) \
                if (PAR_CHECKED(c.sm.col_off[col + 1] - c.sm.col_off[col]))
            {
                star_pts sp = {NULL, 0, 0, 1, 0, 0, 0};
                #pragma omp for schedule(dynamic, 4)
                for (size_t j = c.sm.col_off[col]; j < c.sm.col_off[col + 1]; j++) {
                    fit_counts k = {0, 0, 0};
                    uint32_t v = c.sm.col_v[j];
                    if (dirty_unchanged(&dy, &c.sm, v)) {
                        skipped++;   /* it would fail as it did */
                        continue;
                    }
                    dirty_mark(&dy, v, fit_vertex(&c, v, p.step, dist, &sp, &k));
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
        ds = boundary_distances(&c, dist);
        report(&p, &c, "fit", it + 1, &ds, &n, t0);
        if (n.moved == 0)
            break;
        if (ds.within > best_within) {
            best_within = ds.within;
            since_best = 0;
        } else if (++since_best >= FIT_STALL_ITERS) {
            break;   /* the rest are held back: thin gaps or blocked moves */
        }
    }
    st.converged = ds.within == c.sm.nbv;
    sm_dihedral_range(m, &st.min_dihedral_fit, &st.max_dihedral_fit);
    st.seconds_fit = sm_now() - t0;
    if (p.quality) {
        st_progress_report(prog, "quality", 0.0);
        if ((rc = quality_pass(&c, &p, dist, &st, t0, err)))
            goto done;
        ds = boundary_distances(&c, dist);
    }
    st.within_offset = ds.within;
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
    dirty_free(&dy);
    pgrid_free(&c.pg);
    sm_mesh_free(&c.sm);
    st_bvh_free(own);
    return rc;
}

/* ---- enclosure count -------------------------------------------------- */

/* The whole-mesh count is enclose.h's (one implementation of the exact
 * enclosure semantics for the project: tetstat, soupmesh and this). */
st_status st_enclosure_count(const st_tetmesh *m, const st_soup *s,
                             const st_bvh *bvh, size_t *verts_outside,
                             size_t *tris_crossing, st_error *err)
{
    st_enclosure e;
    st_status rc = st_enclosure_compute(&e, m, s, bvh, NULL, NULL, err);
    /* On error SIZE_MAX, which no caller can read as "encloses". */
    if (verts_outside)
        *verts_outside = rc ? SIZE_MAX : e.vertices_outside;
    if (tris_crossing)
        *tris_crossing = rc ? SIZE_MAX : e.crossing_triangles;
    return rc;
}
