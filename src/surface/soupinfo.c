/*
 * soupinfo.c - the damage report of a triangle soup (see soupinfo.h for
 * what every count means).
 *
 * Algorithm, in passes over the soup:
 *
 *   1-3. The soup's topology as edges.h gives it (the one definition the
 *      hole caps and shells read too), duplicates kept in the edges:
 *      exact welding (weld.h: vertex ids in order of first use), degenerate
 *      triangles (two corners welded together), duplicates (equal sorted
 *      corner triples), the half-edges of every non-degenerate triangle
 *      sorted by their unordered welded ends (ties by triangle, so the
 *      order is total and the result deterministic), and the pieces
 *      (union-find toward the smallest triangle).
 *   4. Edges: each run of equal keys is one edge; its length and the
 *      directions of its half-edges classify it. The same pass joins the
 *      boundary edges' endpoints (for the cycle rank), joins the corners
 *      on both sides of a manifold edge (for fans) and records manifold
 *      neighbours (for orientation propagation).
 *   5. Per piece: faces, edges, bad edges, fans and distinct vertices give
 *      whether it is a closed 2-manifold and its Euler characteristic; a
 *      breadth-first propagation of orientation across manifold edges says
 *      whether it is orientable.
 *   6. Self-intersections (a separate call): a BVH over the triangles; for
 *      every triangle, the candidates whose boxes meet its box, each pair
 *      decided once, exactly, by the rule for the corners it shares (see
 *      soupinfo.h).
 *
 * Union-find (unionfind.h) joins toward the smaller index, so every root is
 * the smallest member of its set: pieces are numbered by their first
 * triangle.
 */
#include "souptet/soupinfo.h"
#include "../base/fpenv.h"
#include "souptet/bvh.h"
#include "souptet/edges.h"
#include "souptet/geom.h"
#include "souptet/isect.h"
#include "souptet/mem.h"
#include "souptet/pred.h"
#include "souptet/weld.h"
#include "../base/unionfind.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>


static int cmp_u64(const void *pa, const void *pb)
{
    uint64_t a = *(const uint64_t *)pa, b = *(const uint64_t *)pb;
    return (a > b) - (a < b);
}

/* Three distinct points on one line: every projection of the triangle onto
 * a coordinate plane has zero area (exactly). */
static int collinear(const double *a, const double *b, const double *c)
{
    return st_orient2d_drop(a, b, c, 0) == 0.0 &&
           st_orient2d_drop(a, b, c, 1) == 0.0 &&
           st_orient2d_drop(a, b, c, 2) == 0.0;
}

static size_t *uf_new(size_t n)
{
    size_t *p = st_malloc_array(n ? n : 1, sizeof *p);
    if (p)
        for (size_t i = 0; i < n; i++)
            p[i] = i;
    return p;
}

/* What both reports take: a soup with triangles, its corners indexed in
 * 32 bits. */
static st_status soup_fits(const st_soup *s, st_error *err)
{
    if (!s || s->ntris == 0)
        return st_error_set(err, ST_EINPUT, NULL, 0, "no triangles");
    if (s->ntris > (size_t)(UINT32_MAX - 3) / 3)
        return st_error_set(err, ST_ELIMIT, NULL, 0,
                            "%zu triangles: soupinfo handles at most %lu",
                            s->ntris, (unsigned long)((UINT32_MAX - 3) / 3));
    return ST_OK;
}

/* ---- the report ---------------------------------------------------------- */

/* What the report's steps share: the soup's edges and the arrays one step
 * fills for the next (each step allocates what it fills; si_free frees
 * them all). */
typedef struct si_state {
    const st_soup *s;
    st_soupinfo *out;
    st_soup_edges e;
    size_t nt, nc, nw, nh;  /* triangles, corners, welded ids, half-edges */
    size_t nnd;             /* non-degenerate triangles */
    uint8_t *deg;           /* nt: 1 for a degenerate triangle */
    size_t *corner_uf;      /* nc: corners at one point joined across
                             * manifold edges; a root per fan */
    uint8_t *mark;          /* nw: scratch per welded id */
    uint32_t *nbr;          /* nc: the manifold neighbour across t's edge
                             * that starts at corner c (ST_EDGES_NONE:
                             * none) */
    uint8_t *same;          /* nc: 1 when both run along it the same way */
    uint32_t *pidx;         /* nt: the piece of t (ST_EDGES_NONE when
                             * degenerate) */
    size_t np;              /* pieces */
    size_t *pF, *pE, *pBad, *pFans, *pV;  /* per piece: faces, edges, bad
                                           * edges, fans, distinct points */
    uint8_t *pNonori;       /* per piece: an orientation conflict */
} si_state;

static st_status si_nomem(const si_state *S, st_error *err)
{
    return st_error_set(err, ST_ENOMEM, NULL, 0,
                        "out of memory analysing %zu triangles", S->nt);
}

static void si_free(si_state *S)
{
    st_soup_edges_free(&S->e);
    void *arrays[] = {S->deg, S->corner_uf, S->mark, S->nbr,   S->same,
                      S->pidx, S->pF,       S->pE,   S->pBad,  S->pFans,
                      S->pV,  S->pNonori};
    for (size_t i = 0; i < sizeof arrays / sizeof *arrays; i++)
        free(arrays[i]);
}

/* 1-3. welded, unreferenced, degenerate, duplicated and collinear counts
 * (the welding, duplicates and sorted half-edges are edges.h's). */
static st_status si_triangles(si_state *S, st_error *err)
{
    const st_soup *s = S->s;
    st_soupinfo *out = S->out;
    const uint32_t *weld = S->e.weld;
    out->welded_vertices = S->nw;
    for (size_t v = 0; v < s->nverts; v++)
        out->unreferenced_vertices += weld[v] == ST_WELD_NONE;
    out->degenerate_triangles = S->e.degenerate;
    out->duplicated_triangles = S->e.duplicates;

    S->deg = st_calloc_array(S->nt, 1);
    if (!S->deg)
        return si_nomem(S, err);
    for (size_t t = 0; t < S->nt; t++) {
        const uint32_t *v = s->tris + 3 * t;
        if (weld[v[0]] == weld[v[1]] || weld[v[1]] == weld[v[2]] ||
            weld[v[0]] == weld[v[2]]) {
            S->deg[t] = 1;
            continue;
        }
        S->nnd++;
        if (collinear(s->xyz + 3 * (size_t)v[0], s->xyz + 3 * (size_t)v[1],
                      s->xyz + 3 * (size_t)v[2]))
            out->collinear_triangles++;
    }
    return ST_OK;
}

/* One manifold edge u-v (half-edges i and i+1): its neighbours and
 * directions, its corners joined into fans. */
static void si_manifold_edge(si_state *S, size_t i, uint32_t u, uint32_t v)
{
    const st_soup_edges *e = &S->e;
    const st_soup *s = S->s;
    const uint32_t t1 = e->he[i].t, t2 = e->he[i + 1].t;
    S->out->manifold_edges++;
    const int f1 = st_soup_edges_forward(e, s, t1, u, v),
              f2 = st_soup_edges_forward(e, s, t2, u, v);
    const uint8_t samedir = f1 == f2;
    S->out->inconsistent_edges += samedir;
    const size_t cu1 = 3 * (size_t)t1 + (size_t)st_soup_edges_corner(e, s, t1, u),
                 cv1 = 3 * (size_t)t1 + (size_t)st_soup_edges_corner(e, s, t1, v),
                 cu2 = 3 * (size_t)t2 + (size_t)st_soup_edges_corner(e, s, t2, u),
                 cv2 = 3 * (size_t)t2 + (size_t)st_soup_edges_corner(e, s, t2, v);
    /* The edge starts at u in a triangle that runs u -> v. */
    const size_t h1 = f1 ? cu1 : cv1, h2 = f2 ? cu2 : cv2;
    S->nbr[h1] = t2;
    S->nbr[h2] = t1;
    S->same[h1] = S->same[h2] = samedir;
    /* The corners at the same point, across the edge. */
    uf_join(S->corner_uf, cu1, cu2);
    uf_join(S->corner_uf, cv1, cv2);
}

/* 4. edges: each run of equal keys; the corners on both sides of a
 * manifold edge joined (fans), the boundary edges' ends joined (the
 * cycle rank) */
static st_status si_edges(si_state *S, st_error *err)
{
    st_soupinfo *out = S->out;
    const st_soup_edges *e = &S->e;
    const size_t nc = S->nc, nw = S->nw;
    S->corner_uf = uf_new(nc);
    size_t *vert_uf = uf_new(nw);
    S->mark = st_calloc_array(nw ? nw : 1, 1);
    S->nbr = st_malloc_array(nc, sizeof *S->nbr);
    S->same = st_calloc_array(nc, 1);
    if (!S->corner_uf || !vert_uf || !S->mark || !S->nbr || !S->same) {
        free(vert_uf);
        return si_nomem(S, err);
    }
    for (size_t h = 0; h < nc; h++)
        S->nbr[h] = ST_EDGES_NONE;
    size_t bverts = 0, bcomps = 0;
    for (size_t i = 0, j; i < S->nh; i = j) {
        j = st_soup_edges_run_end(e, i);
        const uint32_t u = (uint32_t)(e->he[i].key >> 32),
                       v = (uint32_t)(e->he[i].key & 0xffffffffu);
        out->edges++;
        if (j - i == 1) {
            out->boundary_edges++;
            S->mark[u] = S->mark[v] = 1;
            uf_join(vert_uf, u, v);
        } else if (j - i == 2) {
            si_manifold_edge(S, i, u, v);
        } else {
            out->nonmanifold_edges++;
        }
    }
    for (size_t v = 0; v < nw; v++) {
        if (!S->mark[v])
            continue;
        bverts++;
        if (uf_find(vert_uf, v) == v)
            bcomps++;
    }
    /* Cycle rank of the boundary graph; never negative (a forest has
     * E = V - C). */
    out->holes = out->boundary_edges + bcomps - bverts;
    free(vert_uf);
    return ST_OK;
}

/* non-manifold vertices: more than one fan (root corner) per point;
 * Euler characteristic of the non-degenerate part */
static st_status si_fans(si_state *S, st_error *err)
{
    st_soupinfo *out = S->out;
    const uint32_t *weld = S->e.weld;
    const size_t nw = S->nw;
    size_t *fans = st_calloc_array(nw ? nw : 1, sizeof *fans);
    if (!fans)
        return si_nomem(S, err);
    memset(S->mark, 0, nw);
    size_t nv_nd = 0;
    for (size_t c = 0; c < S->nc; c++) {
        if (S->deg[c / 3])
            continue;
        const uint32_t w = weld[S->s->tris[c]];
        if (uf_find(S->corner_uf, c) == c)
            fans[w]++;
        if (!S->mark[w]) {
            S->mark[w] = 1;
            nv_nd++;
        }
    }
    for (size_t v = 0; v < nw; v++)
        if (fans[v] > 1)
            out->nonmanifold_vertices++;
    free(fans);
    out->euler = (long long)nv_nd - (long long)out->edges + (long long)S->nnd;
    out->closed = out->edges > 0 && out->boundary_edges == 0 &&
                  out->nonmanifold_edges == 0;
    out->consistently_oriented = out->inconsistent_edges == 0;
    return ST_OK;
}

/* 5. pieces (edges.h names each by its smallest triangle), numbered in
 * that order; their faces, edges and bad edges */
static st_status si_pieces(si_state *S, st_error *err)
{
    const st_soup_edges *e = &S->e;
    const size_t nt = S->nt;
    S->pidx = st_malloc_array(nt, sizeof *S->pidx);
    if (!S->pidx)
        return si_nomem(S, err);
    size_t np = 0;
    for (size_t t = 0; t < nt; t++)
        S->pidx[t] = !S->deg[t] && e->piece[t] == t ? (uint32_t)np++ : ST_EDGES_NONE;
    for (size_t t = 0; t < nt; t++)
        if (!S->deg[t])
            S->pidx[t] = S->pidx[e->piece[t]];
    S->out->pieces = S->np = np;
    S->pF = st_calloc_array(np ? np : 1, sizeof *S->pF);
    S->pE = st_calloc_array(np ? np : 1, sizeof *S->pE);
    S->pBad = st_calloc_array(np ? np : 1, sizeof *S->pBad);
    S->pFans = st_calloc_array(np ? np : 1, sizeof *S->pFans);
    S->pV = st_calloc_array(np ? np : 1, sizeof *S->pV);
    S->pNonori = st_calloc_array(np ? np : 1, 1);
    if (!S->pF || !S->pE || !S->pBad || !S->pFans || !S->pV || !S->pNonori)
        return si_nomem(S, err);
    for (size_t t = 0; t < nt; t++)
        if (!S->deg[t])
            S->pF[S->pidx[t]]++;
    for (size_t i = 0, j; i < S->nh; i = j) {
        j = st_soup_edges_run_end(e, i);
        const uint32_t p = S->pidx[e->he[i].t];
        S->pE[p]++;
        if (j - i != 2)
            S->pBad[p]++;
    }
    return ST_OK;
}

/* distinct (piece, point) pairs among the fans */
static st_status si_piece_points(si_state *S, st_error *err)
{
    const size_t nc = S->nc;
    size_t nfans = 0;
    for (size_t c = 0; c < nc; c++)
        if (!S->deg[c / 3] && uf_find(S->corner_uf, c) == c)
            nfans++;
    uint64_t *pv = st_malloc_array(nfans ? nfans : 1, sizeof *pv);
    if (!pv)
        return si_nomem(S, err);
    size_t k = 0;
    for (size_t c = 0; c < nc; c++) {
        if (!S->deg[c / 3] && uf_find(S->corner_uf, c) == c) {
            const uint32_t p = S->pidx[c / 3];
            S->pFans[p]++;
            pv[k++] = (uint64_t)p << 32 | S->e.weld[S->s->tris[c]];
        }
    }
    qsort(pv, nfans, sizeof *pv, cmp_u64);
    for (size_t i = 0; i < nfans; i++)
        if (i == 0 || pv[i] != pv[i - 1])
            S->pV[pv[i] >> 32]++;
    free(pv);
    return ST_OK;
}

/* orientation propagation across manifold edges: a conflict marks the
 * piece non-orientable */
static st_status si_orient(si_state *S, st_error *err)
{
    const size_t nt = S->nt;
    uint8_t *flip = st_malloc_array(nt, 1);
    uint32_t *queue = st_malloc_array(nt, sizeof *queue);
    if (!flip || !queue) {
        free(flip);
        free(queue);
        return si_nomem(S, err);
    }
    memset(flip, 2, nt); /* 2: not reached yet */
    for (size_t t0 = 0; t0 < nt; t0++) {
        if (S->deg[t0] || flip[t0] != 2)
            continue;
        size_t qh = 0, qt = 0;
        flip[t0] = 0;
        queue[qt++] = (uint32_t)t0;
        while (qh < qt) {
            const uint32_t t = queue[qh++];
            for (size_t h = 3 * (size_t)t; h < 3 * (size_t)t + 3; h++) {
                const uint32_t o = S->nbr[h];
                if (o == ST_EDGES_NONE)
                    continue;
                /* Traversing the shared edge the same way means one of the
                 * two must flip to agree with the other. */
                const uint8_t want = (uint8_t)(flip[t] ^ S->same[h]);
                if (flip[o] == 2) {
                    flip[o] = want;
                    queue[qt++] = o;
                } else if (flip[o] != want) {
                    S->pNonori[S->pidx[t]] = 1;
                }
            }
        }
    }
    free(flip);
    free(queue);
    return ST_OK;
}

/* Per piece: closed 2-manifold (no bad edge, one fan per point), and the
 * genus of the orientable ones. */
static void si_tally(si_state *S)
{
    st_soupinfo *out = S->out;
    for (size_t p = 0; p < S->np; p++) {
        if (S->pNonori[p])
            out->nonorientable_pieces++;
        if (S->pBad[p] != 0 || S->pFans[p] != S->pV[p])
            continue;
        out->closed_pieces++;
        if (!S->pNonori[p]) {
            long long chi = (long long)S->pV[p] - (long long)S->pE[p] +
                            (long long)S->pF[p];
            out->genus += (2 - chi) / 2;
        }
    }
}

st_status st_soupinfo_compute(st_soupinfo *out, const st_soup *s,
                              st_error *err)
{
    memset(out, 0, sizeof *out);
    st_status st = soup_fits(s, err);
    if (st || (st = st_soup_bounds(s, out->lo, out->hi, err)))
        return st;
    double d[3];
    st_sub3(d, out->hi, out->lo);
    out->diagonal = st_norm3(d);
    out->vertices = s->nverts;
    out->triangles = s->ntris;

    si_state S = {.s = s, .out = out};
    /* 1-3. weld, degenerate and duplicated triangles, the half-edges of
     * every non-degenerate triangle (duplicates too: they make their edges
     * non-manifold) sorted, pieces (edges.h) */
    st = st_soup_edges_build_opts(&S.e, s, ST_EDGES_DUPLICATES, err);
    if (st)
        goto done;
    S.nt = s->ntris;
    S.nc = 3 * S.nt;
    S.nw = S.e.nweld;
    S.nh = S.e.nhalf;
    if ((st = si_triangles(&S, err)) || (st = si_edges(&S, err)) ||
        (st = si_fans(&S, err)) || (st = si_pieces(&S, err)) ||
        (st = si_piece_points(&S, err)) || (st = si_orient(&S, err)))
        goto done;
    si_tally(&S);
done:
    si_free(&S);
    return st;
}

/* ---- self-intersections --------------------------------------------------- */

typedef struct si_ctx {
    const st_soup *s;
    const uint32_t *W;       /* welded corners, 3 per triangle */
    const uint8_t *kind;     /* 0 ordinary, 1 collinear, 2 degenerate */
    uint8_t *hit;            /* per triangle: in a pair */
    uint32_t t;              /* the triangle being queried */
    size_t pairs;            /* pairs (t, u > t) found */
} si_ctx;

static const double *corner(const st_soup *s, uint32_t t, int k)
{
    return s->xyz + 3 * (size_t)s->tris[3 * (size_t)t + (size_t)k];
}

/* The rule of soupinfo.h for triangles t and u (both non-degenerate). */
static int pair_intersects(const si_ctx *c, uint32_t t, uint32_t u)
{
    const st_soup *s = c->s;
    const uint32_t *A = c->W + 3 * (size_t)t, *B = c->W + 3 * (size_t)u;
    int ia[3], ib[3], nshared = 0; /* slots of the shared corners */
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            if (A[i] == B[j]) {
                ia[nshared] = i;
                ib[nshared] = j;
                nshared++;
            }
    if (nshared == 0)
        return st_tri_tri_intersect(corner(s, t, 0), corner(s, t, 1),
                                    corner(s, t, 2), corner(s, u, 0),
                                    corner(s, u, 1), corner(s, u, 2));
    if (c->kind[t] || c->kind[u])
        return 0; /* a collinear triangle with a shared corner: untested */
    if (nshared == 3)
        return 1;
    if (nshared == 1) {
        /* the edges opposite the shared corner */
        int a1 = (ia[0] + 1) % 3, a2 = (ia[0] + 2) % 3;
        int b1 = (ib[0] + 1) % 3, b2 = (ib[0] + 2) % 3;
        return st_segment_tri_intersect(corner(s, t, a1), corner(s, t, a2),
                                        corner(s, u, 0), corner(s, u, 1),
                                        corner(s, u, 2)) ||
               st_segment_tri_intersect(corner(s, u, b1), corner(s, u, b2),
                                        corner(s, t, 0), corner(s, t, 1),
                                        corner(s, t, 2));
    }
    /* one shared edge (p, q); apexes a of t and b of u */
    const double *p = corner(s, t, ia[0]), *q = corner(s, t, ia[1]);
    const double *a = corner(s, t, 3 - ia[0] - ia[1]);
    const double *b = corner(s, u, 3 - ib[0] - ib[1]);
    if (st_orient3d(p, q, a, b) != 0.0)
        return 0;
    /* Coplanar: both have the same nonzero normal component on some
     * axis; project along it and compare the apexes' sides of pq. */
    for (int drop = 0; drop < 3; drop++) {
        int sa = st_sign(st_orient2d_drop(p, q, a, drop));
        if (sa != 0)
            return sa == st_sign(st_orient2d_drop(p, q, b, drop));
    }
    return 0; /* not reached: t is not collinear */
}

static int si_visit(void *ctx, uint32_t u)
{
    si_ctx *c = ctx;
    if (u <= c->t || c->kind[u] == 2)
        return 0;
    if (pair_intersects(c, c->t, u)) {
        c->pairs++;
#pragma omp atomic write
        c->hit[c->t] = 1;
#pragma omp atomic write
        c->hit[u] = 1;
    }
    return 0;
}

st_status st_soupinfo_self_intersections(st_soupinfo *out, const st_soup *s,
                                         unsigned char *flags, st_error *err)
{
    st_status st = soup_fits(s, err);
    if (st)
        return st;
    const size_t nt = s->ntris;
    st = ST_ENOMEM;
    uint32_t *weld = st_malloc_array(s->nverts, sizeof *weld);
    uint32_t *W = st_malloc_array(3 * nt, sizeof *W);
    uint8_t *kind = st_malloc_array(nt, 1);
    uint8_t *hit = st_calloc_array(nt, 1);
    st_bvh *bvh = NULL;
    size_t pairs = 0;
    size_t nweld;
    if (!weld || !W || !kind || !hit || st_weld_vertices(weld, &nweld, s, err) != ST_OK)
        goto done;
    for (size_t i = 0; i < 3 * nt; i++)
        W[i] = weld[s->tris[i]];
    for (size_t t = 0; t < nt; t++) {
        const uint32_t *w = W + 3 * t;
        if (w[0] == w[1] || w[1] == w[2] || w[0] == w[2])
            kind[t] = 2;
        else
            kind[t] = (uint8_t)collinear(corner(s, (uint32_t)t, 0),
                                         corner(s, (uint32_t)t, 1),
                                         corner(s, (uint32_t)t, 2));
    }
    st = st_bvh_build(&bvh, s, err);
    if (st)
        goto done;
#pragma omp parallel for schedule(dynamic, 256) reduction(+ : pairs)
    for (size_t t = 0; t < nt; t++) {
        if (kind[t] == 2)
            continue;
        si_ctx c = {s, W, kind, hit, (uint32_t)t, 0};
        /* candidates: boxes meeting t's box, in nodes meeting t itself */
        st_bvh_query_tri(bvh, corner(s, c.t, 0), corner(s, c.t, 1),
                         corner(s, c.t, 2), si_visit, &c);
        pairs += c.pairs;
    }
    out->self_checked = 1;
    out->self_intersecting_pairs = pairs;
    out->self_intersecting_triangles = 0;
    for (size_t t = 0; t < nt; t++) {
        out->self_intersecting_triangles += hit[t];
        if (flags)
            flags[t] = hit[t];
    }
    st = ST_OK;
done:
    if (st == ST_ENOMEM)
        st_error_set(err, ST_ENOMEM, NULL, 0,
                     "out of memory checking %zu triangles for "
                     "self-intersections", nt);
    st_bvh_free(bvh);
    free(weld);
    free(W);
    free(kind);
    free(hit);
    return st;
}
