/*
 * invariant.c - the fit's move invariant (invariant.h): what every move of
 * st_fit (fit.c) and of its quality pass (quality.c) keeps, decided by
 * exact predicates. Design notes and measurements: doc/design/fit.md.
 *
 * Stuart, Levine, Jones, Bargteil 2013 ("Cetra"), section 3.3, keep the
 * mesh enclosing S with El Topo's continuous collision detection; what has
 * to hold is static, and here it is checked exactly after every move:
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
 * first (see star_pts_fill) and skipped; for a boundary vertex the swept
 * region decides it when it can (fit_swept.c). The fill
 * (st_fit_params.fill) counts as surface for the distances
 * (sm_nearest_d2), never for the invariant, which is S's alone.
 *
 * Not checked: that the boundary does not fold onto another part of the
 * mesh far from the moved star (a global self-intersection); small steps
 * and positive stars make it unlikely, tetstat would show it as overlap.
 *
 * Cost. Most trial moves of a boundary vertex fail because an S vertex of
 * its star would leave it, and a vertex held back fails the same way
 * every iteration. So: the S vertex that stopped a vertex last is tried
 * first (when it is in the star and would leave, the move fails without
 * gathering the star's points); the star's points are gathered only when
 * a trial passes the cheap tests, each remembering its tet so the check
 * after a small move is one tet test; a vertex whose last attempt failed
 * and whose star has not moved since is not tried again (the dirty set);
 * faces are checked through the BVH's triangle query (nodes pruned by the
 * face itself, not its box), and when the swept test found no S vertex in
 * the swept tets, through the thin side triangles of those tets instead
 * (sides_clear); boundary distances are searched within the
 * old distance plus the way the vertex moved. None of these changes a
 * result.
 */
#include "invariant.h"
#include "fit_swept.h"
#include "../base/fpenv.h"

#include "souptet/isect.h"
#include "souptet/mem.h"
#include "souptet/pred.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* ---- the dirty set --------------------------------------------------- */

st_status sm_dirty_init(dirty *d, size_t nv)
{
    d->step = 0;
    d->moved_at = st_calloc_array(nv ? nv : 1, sizeof *d->moved_at);
    d->tried_at = st_calloc_array(nv ? nv : 1, sizeof *d->tried_at);
    d->todo = st_malloc_array(nv ? nv : 1, sizeof *d->todo);
    return d->moved_at && d->tried_at && d->todo ? ST_OK : ST_ENOMEM;
}

void sm_dirty_free(dirty *d)
{
    free(d->moved_at);
    free(d->tried_at);
    free(d->todo);
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

size_t sm_dirty_todo(dirty *d, const sm_mesh *sm, size_t col, const unsigned char *mark)
{
    size_t n = 0;
    for (size_t j = sm->col_off[col]; j < sm->col_off[col + 1]; j++) {
        uint32_t v = sm->col_v[j];
        if ((!mark || mark[v]) && !sm_dirty_unchanged(d, sm, v))
            d->todo[n++] = v;
    }
    return n;
}

/* ---- the invariant -------------------------------------------------- */

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
 * ST_OK, or ST_ENOMEM. */
static st_status svertices_in_star(const fit_ctx *c, uint32_t v, star_pt **list,
                                   size_t *n, size_t *cap)
{
    const sm_mesh *sm = &c->sm;
    const pgrid *g = c->pg;
    *n = 0;
    if (g->npts == 0)
        return ST_OK;
    const double *x = sm->m->xyz + 3 * (size_t)v;
    double lo[3], hi[3];
    star_box(sm, v, x, lo, hi);
    size_t a0[3], a1[3];
    for (int a = 0; a < 3; a++) {
        a0[a] = sm_pgrid_coord(g, lo[a], a);
        a1[a] = sm_pgrid_coord(g, hi[a], a);
    }
    /* The star tets' boxes, once for all the points: in_star's test order
     * and answers, without recomputing a tet's box for every point (the
     * box rejects most (point, tet) pairs; doc/design/fit.md, Cost). */
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
                            return ST_ENOMEM;
                        *list = l;
                        *cap = nc;
                    }
                    (*list)[*n].pt = g->idx[j];
                    (*list)[*n].tet = (uint32_t)t;
                    (*n)++;
                }
            }
    return ST_OK;
}

/* Every listed S vertex lies in the closed star of v with v at p; when
 * one does not, *failed says which (a point grid index). The star with v
 * at p must be positive (move_ok tests that first); was_positive: it was
 * positive where the list was gathered, so each point is inside its tet's
 * face opposite v (the fit's hottest loop on large soups:
 * doc/design/fit.md, Cost). */
static int svertices_kept(const fit_ctx *c, uint32_t v, const double p[3],
                          const star_pt *list, size_t n, int was_positive,
                          uint32_t *failed)
{
    for (size_t i = 0; i < n; i++)
        if (in_pos_star(&c->sm, v, p, c->pg->pts + 3 * (size_t)list[i].pt,
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
    st_plane_filter pl;     /* the plane of f (st_plane_filter_plane) */
    uint32_t hit;           /* the triangle face_visit stopped at */
} face_query;

/* Whether S triangle tri (its corners into *a, *b, *d) meets the triangle
 * q->f: first the plane filter on q->pl, which certifies most triangles
 * strictly on one side of its plane for some 60 instructions, then the
 * exact test. */
static inline int meets_f(const face_query *q, uint32_t tri, const double **a,
                          const double **b, const double **d)
{
    const uint32_t *t = q->s->tris + 3 * (size_t)tri;
    *a = q->s->xyz + 3 * (size_t)t[0];
    *b = q->s->xyz + 3 * (size_t)t[1];
    *d = q->s->xyz + 3 * (size_t)t[2];
    const int sa = st_plane_filter_sign(&q->pl, *a);
    if (sa != 0 && st_plane_filter_sign(&q->pl, *b) == sa &&
        st_plane_filter_sign(&q->pl, *d) == sa)
        return 0;
    return st_tri_tri_intersect(q->f[0], q->f[1], q->f[2], *a, *b, *d);
}

/* 1 (stop) when S triangle tri meets the new face but did not meet the
 * old one. A triangle the plane filter certifies strictly on one side of
 * the new face's plane does not meet it: st_tri_tri_intersect's first
 * exact test (the signs of orient3d(f, each corner), all + or all -)
 * would say so, for some 800 instructions instead of some 60 (most
 * triangles the BVH walk visits; doc/design/fit.md, Cost). */
static int face_visit(void *ctx, uint32_t tri)
{
    face_query *q = ctx;
    const double *a, *b, *d;
    if (!meets_f(q, tri, &a, &b, &d))
        return 0;
    if (st_tri_tri_intersect(q->g[0], q->g[1], q->g[2], a, b, d))
        return 0;
    q->hit = tri;
    return 1;
}

/* Boundary face j of v's star as it is and with v at p, in q. */
static void face_of(const fit_ctx *c, uint32_t v, size_t j, const double p[3], face_query *q)
{
    const sm_mesh *sm = &c->sm;
    const uint32_t *k = sm->bf + 3 * (size_t)sm->vf[j];
    q->s = c->s;
    for (int i = 0; i < 3; i++) {
        q->g[i] = sm->m->xyz + 3 * (size_t)k[i];
        q->f[i] = k[i] == v ? p : q->g[i];
    }
    st_plane_filter_plane(&q->pl, q->f[0], q->f[1], q->f[2]);
}

/* No boundary face of v's star, with v at p, newly meets a triangle of S.
 * The BVH walk prunes by the new face itself (st_bvh_query_tri), not by
 * its bounding box: a face is about h across and S triangles are much
 * smaller, so its box holds hundreds of triangles and the face a few.
 * Most refusals (two in three of the bunny's fit) come from the triangle
 * that refused v's last move: tblocker_clear tries it alone first, before
 * the points' test too (the answer is the same, whichever test and
 * triangle say it). */
/* 0 when the triangle that last refused v (tblocker) newly meets a
 * boundary face of v's star with v at p: faces_clear would refuse too. */
static int tblocker_clear(const fit_ctx *c, uint32_t v, const double p[3])
{
    const sm_mesh *sm = &c->sm;
    face_query q;
    uint32_t tb = c->tblocker ? c->tblocker[v] : UINT32_MAX;
    if (tb != UINT32_MAX)
        for (size_t j = sm->vf_off[v]; j < sm->vf_off[v + 1]; j++) {
            face_of(c, v, j, p, &q);
            if (face_visit(&q, tb))
                return 0;
        }
    return 1;
}

/* faces_clear's BVH walks (after tblocker_clear passed). */
static int faces_clear(const fit_ctx *c, uint32_t v, const double p[3])
{
    const sm_mesh *sm = &c->sm;
    face_query q;
    for (size_t j = sm->vf_off[v]; j < sm->vf_off[v + 1]; j++) {
        face_of(c, v, j, p, &q);
        if (st_bvh_query_tri(c->bvh, q.f[0], q.f[1], q.f[2], face_visit, &q)) {
            if (c->tblocker)
                c->tblocker[v] = q.hit;   /* v's own slot, as blocker */
            return 0;
        }
    }
    return 1;
}

/* 1 (stop) when S triangle tri meets the side triangle in q->f (q->pl its
 * plane, the corners certified on one side first, as face_visit). */
static int side_visit(void *ctx, uint32_t tri)
{
    face_query *q = ctx;
    const double *a, *b, *d;
    if (!meets_f(q, tri, &a, &b, &d))
        return 0;
    q->hit = tri;
    return 1;
}

/* Boundary link vertices a side test visits at most (a lattice vertex has
 * far fewer); with more, sides_clear answers 0 (the face walks decide). */
#define SIDES_MAX 64

/* 1 when no triangle of S meets a side triangle (x, p, a) of the swept
 * tets (x, p, a, b), x where v is, (x, a, b) its boundary faces, each
 * boundary link vertex a once. With sm_swept_kept's *empty (no S vertex
 * in any closed swept tet K = (x, p, a, b), none degenerate), every face
 * (p, a, b) is then clear: a triangle T meeting F' = (p, a, b) at y with
 * no vertex in K meets F = (x, a, b) or a side. If y lies on an edge of
 * F', that edge is in F or a side. Else, when a corner t of T lies
 * strictly on x's side of F''s plane, the segment y t enters K's interior
 * (y inside F', K non-degenerate) and leaves it before t (t not in K) at
 * a point of T off that plane: on F or a side. Else T lies on the closed
 * other side, so T meets K only on F''s plane: T's corners on it are not
 * in F' and span an edge of T crossing F''s edges, or T is in the plane
 * and holds F' (a corner of F in T) or crosses its edges. A triangle
 * meeting F met it before the move: not new. So the face walks
 * (faces_clear) would find nothing; the thin sides meet far fewer BVH
 * nodes than the faces. 0 when a triangle meets a side (faces_clear
 * decides then). */
static int sides_clear(const fit_ctx *c, uint32_t v, const double p[3])
{
    const sm_mesh *sm = &c->sm;
    const double *x = sm->m->xyz + 3 * (size_t)v;
    uint32_t seen[SIDES_MAX];
    size_t ns = 0;
    face_query q;
    q.s = c->s;
    q.f[0] = x;
    q.f[1] = p;
    for (size_t j = sm->vf_off[v]; j < sm->vf_off[v + 1]; j++) {
        const uint32_t *k = sm->bf + 3 * (size_t)sm->vf[j];
        for (int i = 0; i < 3; i++) {
            if (k[i] == v)
                continue;
            size_t u = 0;
            while (u < ns && seen[u] != k[i])
                u++;
            if (u < ns)
                continue;
            if (ns == SIDES_MAX)
                return 0;
            seen[ns++] = k[i];
            q.f[2] = sm->m->xyz + 3 * (size_t)k[i];
            st_plane_filter_plane(&q.pl, q.f[0], q.f[1], q.f[2]);
            if (st_bvh_query_tri(c->bvh, q.f[0], q.f[1], q.f[2], side_visit, &q))
                return 0;
        }
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
        if (swept && !c->full_check && sm_swept_applies(&c->sm, sp->v) &&
            sm_star_positive(&c->sm, sp->v, c->sm.m->xyz + 3 * (size_t)sp->v)) {
            sp->swept = 1;
            return;
        }
        sp->ok = svertices_in_star(c, sp->v, &sp->list, &sp->n, &sp->cap) == ST_OK;
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
    sp->bq = UINT32_MAX;
}

/* The whole invariant for moving v to p, cheapest test first. */
int sm_move_ok(const fit_ctx *c, uint32_t v, const double p[3], star_pts *sp)
{
    if (!(isfinite(p[0]) && isfinite(p[1]) && isfinite(p[2])))
        return 0;
    /* The S vertex that stopped v last time usually stops it again: when
     * it is in the star now and would not be, the move fails whatever the
     * others do, and the star's points need not be gathered. Where it is
     * in the star as it is does not change while v's moves are tried
     * (sm_star_pts_collect starts them): found once (sp->bq, sp->bt), and
     * a blocker outside the star needs no test at p. At p it is located
     * by in_pos_star (two orient3d calls fewer a tet, its tet as it is
     * tried first), whose answer is in_star's when the star with v at p is
     * positive; when it is not, the move fails whatever in_pos_star says
     * (sm_star_positive after), so the blocker is asked first: three in
     * four trial moves end there (armadillo 7) without the star's
     * orientations. */
    uint32_t b = c->blocker ? c->blocker[v] : UINT32_MAX;
    if (b != UINT32_MAX && c->s && (c->sm.onb[v] || c->full_check)) {
        const double *q = c->pg->pts + 3 * (size_t)b;
        if (sp->bq != b) {
            sp->bq = b;
            sp->bt = in_star(&c->sm, v, c->sm.m->xyz + 3 * (size_t)v, q, -1);
        }
        if (sp->bt >= 0 && in_pos_star(&c->sm, v, p, q, sp->bt, 0) < 0)
            return 0;
    }
    if (!sm_star_positive(&c->sm, v, p))
        return 0;
    if (c->s && c->sm.onb[v] && !tblocker_clear(c, v, p))
        return 0;
    if (!sp->have)
        star_pts_fill(c, sp, 1);
    uint32_t failed;
    int empty = 0;
    int kept = sp->swept ? sm_swept_kept(&c->sm, c->pg, v, p, &failed, &empty) : -1;
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
    if (c->s && c->sm.onb[v] && !(empty && sides_clear(c, v, p)) && !faces_clear(c, v, p))
        return 0;
    return 1;
}

/* ---- distances to S -------------------------------------------------- */

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

dist_summary sm_boundary_distances(const fit_ctx *c, double *dist)
{
    const sm_mesh *sm = &c->sm;
    size_t within = 0;
    double mx = 0.0;
    #pragma omp parallel for schedule(dynamic, 16) reduction(+ : within) reduction(max : mx) \
        if (PAR_QUERIES(sm->nbv))
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

/* ---- the context ---------------------------------------------------- */

st_status sm_fit_ctx_open(fit_ctx *c, st_tetmesh *m, const st_soup *s, const st_bvh *bvh,
                          const st_soup *fill, const st_fit_shared *sh, double h,
                          double d_offset, const st_progress *prog, st_error *err)
{
    memset(c, 0, sizeof *c);
    c->s = s;
    c->h = h;
    c->d_offset = d_offset;
    c->prog = prog;
    c->gate = &c->own_gate;
    int64_t *nbr = NULL;
    size_t nonmanifold = 0;
    st_status rc = ST_OK;
    if (!bvh && (rc = st_bvh_build(&c->own_bvh, s, err)))
        goto done;
    c->bvh = bvh ? bvh : c->own_bvh;
    if (sh) {
        c->fbvh = sh->fbvh;
    } else if (fill && fill->ntris > 0) {
        if ((rc = st_bvh_build(&c->own_fbvh, fill, err)))
            goto done;
        c->fbvh = c->own_fbvh;
    }
    if ((rc = sm_mesh_build(&c->sm, m, err)) ||
        (rc = st_tetmesh_neighbors(m, &nbr, &nonmanifold, err)))
        goto done;
    c->full_check = nonmanifold > 0;
    /* the point grid's bins a quarter of the cell at most (finer on dense
     * soups: pgrid.c): the swept test and the
     * star scans visit whole bins (doc/design/fit.md, Cost) */
    c->pg = sh ? &sh->pg : &c->own_pg;
    if ((!sh && sm_pgrid_build(&c->own_pg, s, h / 4.0)) ||
        !(c->blocker = st_malloc_array(m->npoints, sizeof *c->blocker)) ||
        !(c->tblocker = st_malloc_array(m->npoints, sizeof *c->tblocker)) ||
        !(c->dpos = st_malloc_array(m->npoints, 3 * sizeof *c->dpos))) {
        rc = st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory (fit)");
        goto done;
    }
    for (size_t v = 0; v < m->npoints; v++) {
        c->blocker[v] = UINT32_MAX;
        c->tblocker[v] = UINT32_MAX;
        c->dpos[3 * v] = NAN;
    }
done:
    free(nbr);
    return rc;
}

void sm_fit_ctx_close(fit_ctx *c)
{
    free(c->blocker);
    free(c->tblocker);
    free(c->dpos);
    sm_pgrid_free(&c->own_pg);
    sm_mesh_free(&c->sm);
    st_bvh_free(c->own_bvh);
    st_bvh_free(c->own_fbvh);
    memset(c, 0, sizeof *c);
}

/* ---- the shared set-up (smooth.h) ---------------------------------- */

st_status st_fit_shared_new(st_fit_shared **out, const st_soup *s, const st_soup *fill,
                            double h, st_error *err)
{
    *out = NULL;
    if (!s || s->ntris == 0 || !(h > 0.0) || !isfinite(h))
        return st_error_set(err, ST_EINPUT, NULL, 0,
                            "the fit's set-up needs a surface with triangles and h > 0");
    st_fit_shared *sh = calloc(1, sizeof *sh);
    if (!sh)
        return st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory (fit)");
    sh->s = s;
    sh->fill = fill;
    sh->h = h;
    st_status rc = ST_OK;
    /* as sm_fit_ctx_open builds them */
    if (fill && fill->ntris > 0 && (rc = st_bvh_build(&sh->fbvh, fill, err))) {
        st_fit_shared_free(sh);
        return rc;
    }
    if (sm_pgrid_build(&sh->pg, s, h / 4.0)) {
        st_fit_shared_free(sh);
        return st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory (fit)");
    }
    *out = sh;
    return ST_OK;
}

void st_fit_shared_free(st_fit_shared *sh)
{
    if (!sh)
        return;
    st_bvh_free(sh->fbvh);
    sm_pgrid_free(&sh->pg);
    free(sh);
}
