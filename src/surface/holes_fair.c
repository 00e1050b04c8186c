/*
 * holes_fair.c - caps that follow a smooth surface (for holes.c): where
 * the soup around a hole's rim is smooth, the cap of the loop's own points
 * is refined to about the rim's edge length and faired (Liepa 2003,
 * "Filling holes in meshes": refine, then fair), so that it continues the
 * surface's slope across the hole instead of taking a chord under a lost
 * bulge. Design notes and measurements: doc/design/holes.md ("Faired
 * caps").
 *
 *   1. the rim's ring: the soup's triangles around each loop point (its
 *      fan, found by the soup's BVH) and their welded neighbours;
 *   2. smooth: at most FAIR_SPIKES edges of those triangles (and across
 *      them to the next triangle) bend more than FAIR_SHARP; a
 *      non-manifold edge, or a loop through a point twice, is not smooth:
 *      the cap stays as it is;
 *   3. refine (Liepa 2003, section 3.2): a triangle is split at its
 *      centroid where the centroid is far from its corners beside their
 *      scales (each loop point's scale: the mean length of its soup
 *      edges), and the edges are relaxed (swapped where the two angles
 *      opposite them sum to more than pi); the rim's edges are never
 *      split, so the cap meets the soup exactly at the loop's points;
 *   4. fair: the interior points minimise the sum over the cap's points
 *      (the loop's included) of the squared cotangent Laplacian times the
 *      point's area (a third of its triangles'), the loop points' taken
 *      over their soup triangles and their cap triangles together, so the
 *      cap continues the slope of the ring (a thin plate, the discrete
 *      bilaplacian zero at the inner points; the weights from the refined
 *      flat cap; conjugate gradients on the normal equations, one
 *      coordinate at a time, serial: the same result for any thread
 *      count);
 *   5. check: a faired cap that pierces a kept triangle of the soup, or
 *      itself (st_tri_tri_cross, exact), is dropped for the cap as it
 *      was.
 */
#include "../base/fpenv.h"
#include "holes_internal.h"
#include "souptet/isect.h"
#include "souptet/mem.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#define NONE UINT32_MAX
#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif
/* An edge of the rim's ring bending more than this (radians) is sharp: a
 * CAD part's features bend 1.35 to 1.6 on the corpus, a scan's ring edges
 * up to 1.44, once (doc/design/holes.md, "Faired caps"). */
#define FAIR_SHARP 1.2
/* How many sharp edges a smooth ring may have (a scan's spike: one; a
 * feature line crossing the ring gives two or more). */
#define FAIR_SPIKES 1
/* A refined cap with more points than this is not faired. */
#define FAIR_MAX_VERTS 20000u
/* Liepa's density factor: a centroid is inserted where sqrt(2) times its
 * distance to each corner exceeds both scales. */
#define FAIR_ALPHA 1.4142135623730951
/* Passes of edge relaxation after each round of splits. */
#define FAIR_RELAX_PASSES 32
/* Conjugate gradient iterations per coordinate, and the residual's drop. */
#define FAIR_CG_ITERS 4000
#define FAIR_CG_TOL 1e-10

static st_status oom(st_error *err)
{
    return st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory for the faired caps");
}

/* The capacity for need items past cap: doubled, at least 64. */
static size_t next_cap(size_t cap, size_t need)
{
    const size_t c = cap ? 2 * cap : 64;
    return c < need ? need : c;
}

/* p reallocated to c items of size bytes; *ok cleared (and p kept) when
 * that fails. */
static void *regrow(void *p, size_t c, size_t size, int *ok)
{
    void *q = st_realloc_array(p, c, size);
    if (!q)
        *ok = 0;
    return q ? q : p;
}

/* ---- 1, 2: the rim's ring and its smoothness ---------------------------- */

typedef struct ring {
    const st_holes_rimref *ref;
    uint32_t w;                 /* the welded point being gathered */
    size_t cur;                 /* its place in the loop */
    uint32_t *tris;             /* the fans' triangles */
    size_t nt, ct;
    uint32_t *nb;               /* each loop point's soup neighbours (welded) */
    const double **nbp;         /* and a position of each */
    size_t *nstart;             /* n + 1 */
    size_t nn, cn;
    int failed;                 /* out of memory while gathering */
} ring;

static int push_tri(ring *g, uint32_t t)
{
    int ok = 1;
    if (g->nt == g->ct) {
        const size_t c = next_cap(g->ct, g->nt + 1);
        g->tris = regrow(g->tris, c, sizeof *g->tris, &ok);
        g->ct = ok ? c : g->ct;
    }
    if (ok)
        g->tris[g->nt++] = t;
    return ok;
}

static int push_nb(ring *g, uint32_t w, const double *p)
{
    int ok = 1;
    if (g->nn == g->cn) {
        const size_t c = next_cap(g->cn, g->nn + 1);
        g->nb = regrow(g->nb, c, sizeof *g->nb, &ok);
        g->nbp = regrow(g->nbp, c, sizeof *g->nbp, &ok);
        g->cn = ok ? c : g->cn;
    }
    if (ok) {
        g->nb[g->nn] = w;
        g->nbp[g->nn++] = p;
    }
    return ok;
}

/* A kept triangle at welded point g->w: its other corners join the point's
 * neighbours (once each), the triangle the fans. */
static int fan_visit(void *ctx, uint32_t t)
{
    ring *g = ctx;
    const st_soup_edges *E = g->ref->E;
    const st_soup *s = g->ref->s;
    if (!E->kept[t] || st_soup_edges_corner(E, s, t, g->w) < 0)
        return 0;
    if (!push_tri(g, t)) {
        g->failed = 1;
        return 1;
    }
    const uint32_t *tv = s->tris + 3 * (size_t)t;
    for (int k = 0; k < 3; k++) {
        const uint32_t u = E->weld[tv[k]];
        if (u == g->w)
            continue;
        int seen = 0;
        for (size_t i = g->nstart[g->cur]; i < g->nn && !seen; i++)
            seen = g->nb[i] == u;
        if (!seen && !push_nb(g, u, s->xyz + 3 * (size_t)tv[k])) {
            g->failed = 1;
            return 1;
        }
    }
    return 0;
}

static int cmp_u32(const void *a, const void *b)
{
    const uint32_t x = *(const uint32_t *)a, y = *(const uint32_t *)b;
    return (x > y) - (x < y);
}

/* The other kept triangle on the edge (a, b) of the soup beside t, NONE
 * where the edge has one triangle; *many set where it has three or more. */
static uint32_t across(const st_soup_edges *E, uint32_t a, uint32_t b, uint32_t t, int *many)
{
    const uint64_t key = a < b ? (uint64_t)a << 32 | b : (uint64_t)b << 32 | a;
    size_t lo = 0, hi = E->nhalf;
    while (lo < hi) {
        const size_t mid = lo + (hi - lo) / 2;
        if (E->he[mid].key < key)
            lo = mid + 1;
        else
            hi = mid;
    }
    const size_t end = lo < E->nhalf ? st_soup_edges_run_end(E, lo) : lo;
    if (end - lo != 2) {
        *many |= end - lo > 2;
        return NONE;
    }
    return E->he[lo].t == t ? E->he[lo + 1].t : E->he[lo].t;
}

static int in_ring(const ring *g, uint32_t t)
{
    return bsearch(&t, g->tris, g->nt, sizeof *g->tris, cmp_u32) != NULL;
}

/* The edges of the ring's triangles (and across them to the next
 * triangle, in or out of the ring) that bend more than FAIR_SHARP, each
 * counted once; SIZE_MAX where an edge is not manifold. */
static size_t ring_sharp(const ring *g)
{
    const st_soup *s = g->ref->s;
    const st_soup_edges *E = g->ref->E;
    size_t sharp = 0;
    for (size_t i = 0; i < g->nt; i++) {
        const uint32_t t = g->tris[i];
        const uint32_t *tv = s->tris + 3 * (size_t)t;
        double nt[3];
        unit_normal(nt, s->xyz + 3 * (size_t)tv[0], s->xyz + 3 * (size_t)tv[1],
                    s->xyz + 3 * (size_t)tv[2]);
        for (int k = 0; k < 3; k++) {
            const uint32_t a = E->weld[tv[k]], b = E->weld[tv[(k + 1) % 3]];
            int many = 0;
            const uint32_t u = across(E, a, b, t, &many);
            if (many)
                return SIZE_MAX;
            if (u == NONE || (u < t && in_ring(g, u)))
                continue;
            const uint32_t *uv = s->tris + 3 * (size_t)u;
            double nu[3];
            unit_normal(nu, s->xyz + 3 * (size_t)uv[0], s->xyz + 3 * (size_t)uv[1],
                        s->xyz + 3 * (size_t)uv[2]);
            /* both running a -> b: one of them is turned */
            if (st_soup_edges_forward(E, s, u, a, b))
                for (int q = 0; q < 3; q++)
                    nu[q] = -nu[q];
            sharp += bend(nt, nu) > FAIR_SHARP;
        }
    }
    return sharp;
}

/* Gathers the ring of the loop; *smooth 1 when it bends less than
 * FAIR_SHARP everywhere and the loop meets no point twice. */
static st_status ring_gather(ring *g, int *smooth, const st_holes_rimref *ref, size_t n,
                             const double *const *pts, st_error *err)
{
    memset(g, 0, sizeof *g);
    g->ref = ref;
    *smooth = 0;
    uint32_t *sorted = st_malloc_array(n, sizeof *sorted);
    g->nstart = st_malloc_array(n + 1, sizeof *g->nstart);
    if (!sorted || !g->nstart) {
        free(sorted);
        return oom(err);
    }
    memcpy(sorted, ref->lv, n * sizeof *sorted);
    qsort(sorted, n, sizeof *sorted, cmp_u32);
    int twice = 0;
    for (size_t i = 1; i < n; i++)
        twice |= sorted[i] == sorted[i - 1];
    free(sorted);
    if (twice)
        return ST_OK;
    for (size_t i = 0; i < n; i++) {
        g->nstart[i] = g->nn;
        g->w = ref->lv[i];
        g->cur = i;
        st_bvh_query_box(ref->bvh, pts[i], pts[i], fan_visit, g);
        if (g->failed)
            return oom(err);
    }
    g->nstart[n] = g->nn;
    qsort(g->tris, g->nt, sizeof *g->tris, cmp_u32);
    size_t m = 0;
    for (size_t i = 0; i < g->nt; i++)
        if (!m || g->tris[m - 1] != g->tris[i])
            g->tris[m++] = g->tris[i];
    g->nt = m;
    const size_t sharp = ring_sharp(g);
    *smooth = sharp <= FAIR_SPIKES;
    return ST_OK;
}

static void ring_free(ring *g)
{
    free(g->tris), free(g->nb), free(g->nbp), free(g->nstart);
}

/* ---- 3: refinement ------------------------------------------------------ */

/* The cap being refined: points (the loop's first, fixed), each one's
 * scale, triangles and, per half-edge 3 t + k (corner k to corner k + 1),
 * the half-edge across it (NONE on the rim). */
typedef struct fmesh {
    size_t n;                   /* the loop's points: x[0..n) */
    double *x, *sig;
    size_t nv, cv;
    uint32_t *v, *opp;
    size_t nt, ct;
} fmesh;

static void fmesh_free(fmesh *m)
{
    free(m->x), free(m->sig), free(m->v), free(m->opp);
}

static int fmesh_grow(fmesh *m, size_t nv, size_t nt)
{
    int ok = 1;
    if (nv > m->cv) {
        const size_t c = next_cap(m->cv, nv);
        m->x = regrow(m->x, 3 * c, sizeof *m->x, &ok);
        m->sig = regrow(m->sig, c, sizeof *m->sig, &ok);
        m->cv = ok ? c : m->cv;
    }
    if (ok && nt > m->ct) {
        const size_t c = next_cap(m->ct, nt);
        m->v = regrow(m->v, 3 * c, sizeof *m->v, &ok);
        m->opp = regrow(m->opp, 3 * c, sizeof *m->opp, &ok);
        m->ct = ok ? c : m->ct;
    }
    return ok;
}

/* The cap of the loop's points (tri: n - 2 triangles, local indices), its
 * half-edges paired; each point's scale the mean length of its soup edges
 * and the loop's two edges. 0: out of memory. */
static int fmesh_init(fmesh *m, const double *const *pts, size_t n, const uint32_t *tri,
                      const ring *g)
{
    memset(m, 0, sizeof *m);
    m->n = n;
    if (n < 3 || !fmesh_grow(m, n, n - 2))
        return 0;
    for (size_t i = 0; i < n; i++) {
        memcpy(m->x + 3 * i, pts[i], 3 * sizeof(double));
        double sum = dist3(pts[i], pts[(i + 1) % n]) + dist3(pts[i], pts[(i + n - 1) % n]);
        size_t cnt = 2;
        for (size_t k = g->nstart[i]; k < g->nstart[i + 1]; k++, cnt++)
            sum += dist3(pts[i], g->nbp[k]);
        m->sig[i] = sum / (double)cnt;
    }
    m->nv = n;
    m->nt = n - 2;
    memcpy(m->v, tri, 3 * (n - 2) * sizeof *tri);
    for (size_t h = 0; h < 3 * m->nt; h++) {
        m->opp[h] = NONE;
        const uint32_t a = m->v[h], b = m->v[h - h % 3 + (h + 1) % 3];
        for (size_t g2 = 0; g2 < 3 * m->nt && m->opp[h] == NONE; g2++)
            if (m->v[g2] == b && m->v[g2 - g2 % 3 + (g2 + 1) % 3] == a)
                m->opp[h] = (uint32_t)g2;
    }
    return 1;
}

static inline size_t nxt(size_t h)
{
    return h - h % 3 + (h + 1) % 3;
}

static inline size_t prv(size_t h)
{
    return h - h % 3 + (h + 2) % 3;
}

/* The angle opposite the side of length c in a triangle of sides a, b, c
 * (the law of cosines; 0 for a degenerate one). */
static double opposite(double a, double b, double c)
{
    const double den = 2.0 * a * b;
    if (!(den > 0.0))
        return 0.0;
    return acos(fmax(-1.0, fmin(1.0, (a * a + b * b - c * c) / den)));
}

/* 1 when the points a and b are joined by an edge of the cap. */
static int has_edge(const fmesh *m, uint32_t a, uint32_t b)
{
    for (size_t h = 0; h < 3 * m->nt; h++)
        if (m->v[h] == a && m->v[nxt(h)] == b)
            return 1;
    return 0;
}

static void link(fmesh *m, size_t h, uint32_t o)
{
    m->opp[h] = o;
    if (o != NONE)
        m->opp[o] = (uint32_t)h;
}

/* Swaps the interior half-edge h (a -> b, in (a, b, c) beside (b, a, d))
 * for c -> d where the angles at c and d sum to more than pi. Returns 1
 * when swapped. */
static int relax(fmesh *m, size_t h)
{
    const uint32_t g = m->opp[h];
    if (g == NONE)
        return 0;
    const uint32_t a = m->v[h], b = m->v[nxt(h)], c = m->v[prv(h)], d = m->v[prv(g)];
    const double *X = m->x;
    const double ab = dist3(X + 3 * a, X + 3 * b);
    const double s = opposite(dist3(X + 3 * c, X + 3 * a), dist3(X + 3 * c, X + 3 * b), ab) +
                     opposite(dist3(X + 3 * d, X + 3 * a), dist3(X + 3 * d, X + 3 * b), ab);
    if (!(s > M_PI + 1e-9) || c == d || has_edge(m, c, d))
        return 0;
    const size_t t = h / 3, u = g / 3;
    const uint32_t obc = m->opp[nxt(h)], oca = m->opp[prv(h)];
    const uint32_t oad = m->opp[nxt(g)], odb = m->opp[prv(g)];
    uint32_t *vt = m->v + 3 * t, *vu = m->v + 3 * u;
    vt[0] = c, vt[1] = a, vt[2] = d;
    vu[0] = d, vu[1] = b, vu[2] = c;
    link(m, 3 * t, oca);
    link(m, 3 * t + 1, oad);
    link(m, 3 * u, odb);
    link(m, 3 * u + 1, obc);
    link(m, 3 * t + 2, (uint32_t)(3 * u + 2));
    return 1;
}

/* Splits triangle t at its centroid where Liepa's test asks for it;
 * returns 1 when split, 0 when not, -1 past FAIR_MAX_VERTS, -2 out of
 * memory. */
static int split(fmesh *m, size_t t)
{
    const uint32_t a = m->v[3 * t], b = m->v[3 * t + 1], c = m->v[3 * t + 2];
    double p[3];
    for (int q = 0; q < 3; q++)
        p[q] = (m->x[3 * a + q] + m->x[3 * b + q] + m->x[3 * c + q]) / 3.0;
    const double sc = (m->sig[a] + m->sig[b] + m->sig[c]) / 3.0;
    const uint32_t cv[3] = {a, b, c};
    for (int k = 0; k < 3; k++) {
        const double l = FAIR_ALPHA * dist3(p, m->x + 3 * cv[k]);
        if (!(l > sc && l > m->sig[cv[k]]))
            return 0;
    }
    if (m->nv >= FAIR_MAX_VERTS)
        return -1;
    if (!fmesh_grow(m, m->nv + 1, m->nt + 2))
        return -2;
    const uint32_t pv = (uint32_t)m->nv++;
    memcpy(m->x + 3 * pv, p, sizeof p);
    m->sig[pv] = sc;
    const size_t t1 = m->nt++, t2 = m->nt++;
    const uint32_t oab = m->opp[3 * t], obc = m->opp[3 * t + 1], oca = m->opp[3 * t + 2];
    uint32_t *v0 = m->v + 3 * t, *v1 = m->v + 3 * t1, *v2 = m->v + 3 * t2;
    v0[0] = a, v0[1] = b, v0[2] = pv;
    v1[0] = b, v1[1] = c, v1[2] = pv;
    v2[0] = c, v2[1] = a, v2[2] = pv;
    link(m, 3 * t, oab);
    link(m, 3 * t1, obc);
    link(m, 3 * t2, oca);
    link(m, 3 * t + 1, (uint32_t)(3 * t1 + 2));
    link(m, 3 * t1 + 1, (uint32_t)(3 * t2 + 2));
    link(m, 3 * t2 + 1, (uint32_t)(3 * t + 2));
    relax(m, 3 * t);
    relax(m, 3 * t1);
    relax(m, 3 * t2);
    return 1;
}

/* Liepa's refinement: rounds of splits, each followed by relaxing every
 * edge, until no triangle splits. 1 done, -1 past FAIR_MAX_VERTS, -2 out
 * of memory. */
static int refine(fmesh *m)
{
    for (;;) {
        int any = 0;
        const size_t nt = m->nt;
        for (size_t t = 0; t < nt; t++) {
            const int r = split(m, t);
            if (r < 0)
                return r;
            any |= r;
        }
        if (!any)
            return 1;
        for (int pass = 0; pass < FAIR_RELAX_PASSES; pass++) {
            int swapped = 0;
            for (size_t h = 0; h < 3 * m->nt; h++)
                swapped |= relax(m, h);
            if (!swapped)
                break;
        }
    }
}

/* ---- 4: fairing --------------------------------------------------------- */

/* The thin plate's rows: one per cap point, the cotangent Laplacian over
 * the unknowns (the points past the loop's, col = point - n) in CSR, and
 * what the fixed points give (cst, 3 per row). */
typedef struct plate {
    size_t rows, cols;
    size_t *start;
    uint32_t *col;
    double *val, *cst;
} plate;

static void plate_free(plate *P)
{
    free(P->start), free(P->col), free(P->val), free(P->cst);
}

/* The cap's neighbours of each point (CSR in *ns, *nl; sorted, once each). */
static int cap_neighbours(const fmesh *m, size_t **ns, uint32_t **nl)
{
    const size_t nh = 3 * m->nt;
    size_t *s = st_calloc_array(m->nv + 1, sizeof *s);
    uint32_t *l = st_malloc_array(2 * nh + 1, sizeof *l);
    if (!s || !l) {
        free(s), free(l);
        return 0;
    }
    for (size_t h = 0; h < nh; h++)
        s[m->v[h] + 1]++, s[m->v[nxt(h)] + 1]++;
    for (size_t i = 0; i < m->nv; i++)
        s[i + 1] += s[i];
    size_t *fill = st_malloc_array(m->nv, sizeof *fill);
    if (!fill) {
        free(s), free(l);
        return 0;
    }
    memcpy(fill, s, m->nv * sizeof *fill);
    for (size_t h = 0; h < nh; h++) {
        const uint32_t a = m->v[h], b = m->v[nxt(h)];
        l[fill[a]++] = b;
        l[fill[b]++] = a;
    }
    /* sort and squeeze each list in place; starts shift down */
    size_t out = 0;
    for (size_t i = 0; i < m->nv; i++) {
        const size_t b = s[i], e = fill[i];
        qsort(l + b, e - b, sizeof *l, cmp_u32);
        s[i] = out;
        for (size_t k = b; k < e; k++)
            if (k == b || l[k] != l[k - 1])
                l[out++] = l[k];
    }
    s[m->nv] = out;
    free(fill);
    *ns = s;
    *nl = l;
    return 1;
}

/* Half the cotangent of the angle at c in the triangle (c, a, b): the
 * weight it gives the edge (a, b) (0 where the triangle is degenerate). */
static double half_cot(const double *c, const double *a, const double *b)
{
    const double u[3] = {a[0] - c[0], a[1] - c[1], a[2] - c[2]};
    const double v[3] = {b[0] - c[0], b[1] - c[1], b[2] - c[2]};
    const double x[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2],
                         u[0] * v[1] - u[1] * v[0]};
    const double sn = sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]);
    return sn > 0.0 ? 0.5 * (u[0] * v[0] + u[1] * v[1] + u[2] * v[2]) / sn : 0.0;
}

static double tri_area(const double *a, const double *b, const double *c)
{
    const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    const double v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    const double x[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2],
                         u[0] * v[1] - u[1] * v[0]};
    return 0.5 * sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]);
}

/* Adds w to the weight of v's cap neighbour u (ns, nl: the CSR lists). */
static void add_nb(const size_t *ns, const uint32_t *nl, double *cw, uint32_t v, uint32_t u,
                   double w)
{
    for (size_t k = ns[v]; k < ns[v + 1]; k++)
        if (nl[k] == u) {
            cw[k] += w;
            return;
        }
}

/* The cotangent weights of the cap's edges (cw, beside nl) and each
 * point's third of its triangles' area, from the cap's triangles. */
static void cap_cot(const fmesh *m, const size_t *ns, const uint32_t *nl, double *cw,
                    double *area)
{
    for (size_t t = 0; t < m->nt; t++) {
        const uint32_t *tv = m->v + 3 * t;
        const double *x[3] = {m->x + 3 * (size_t)tv[0], m->x + 3 * (size_t)tv[1],
                              m->x + 3 * (size_t)tv[2]};
        const double a3 = tri_area(x[0], x[1], x[2]) / 3.0;
        for (int k = 0; k < 3; k++) {
            const uint32_t p = tv[(k + 1) % 3], q = tv[(k + 2) % 3];
            const double w = half_cot(x[k], x[(k + 1) % 3], x[(k + 2) % 3]);
            add_nb(ns, nl, cw, p, q, w);
            add_nb(ns, nl, cw, q, p, w);
            area[tv[k]] += a3;
        }
    }
}

/* The same for the soup's side of each loop point: the weights of its
 * soup neighbours (sw, beside g->nb) and its soup triangles' area, from
 * the kept triangles at it (the ring's fans). */
static void ring_cot(const ring *g, size_t n, double *sw, double *area)
{
    const st_soup *s = g->ref->s;
    const st_soup_edges *E = g->ref->E;
    for (size_t v = 0; v < n; v++)
        for (size_t i = 0; i < g->nt; i++) {
            const uint32_t t = g->tris[i];
            const int c = st_soup_edges_corner(E, s, t, g->ref->lv[v]);
            if (c < 0)
                continue;
            const uint32_t *tv = s->tris + 3 * (size_t)t;
            const double *x[3] = {s->xyz + 3 * (size_t)tv[c], s->xyz + 3 * (size_t)tv[(c + 1) % 3],
                                  s->xyz + 3 * (size_t)tv[(c + 2) % 3]};
            area[v] += tri_area(x[0], x[1], x[2]) / 3.0;
            for (int j = 1; j <= 2; j++) {
                /* the edge (v, corner j) and the angle opposite it */
                const uint32_t u = E->weld[tv[(c + j) % 3]];
                const double w = half_cot(x[3 - j], x[0], x[j]);
                for (size_t k = g->nstart[v]; k < g->nstart[v + 1]; k++)
                    if (g->nb[k] == u) {
                        sw[k] += w;
                        break;
                    }
            }
        }
}

/* The rows of the plate over the refined cap m: each point's cotangent
 * Laplacian (the loop points' over their soup triangles and their cap
 * triangles together), scaled by 1 / sqrt of its area, so that the least
 * squares' optimum is the discrete bilaplacian (C^T A^-1 C u = 0 at the
 * inner points). 0: out of memory. */
static int plate_build(plate *P, const fmesh *m, const ring *g)
{
    size_t *ns = NULL;
    uint32_t *nl = NULL;
    memset(P, 0, sizeof *P);
    if (!cap_neighbours(m, &ns, &nl))
        return 0;
    const size_t n = m->n;
    P->rows = m->nv;
    P->cols = m->nv - n;
    P->start = st_malloc_array(m->nv + 1, sizeof *P->start);
    P->col = st_malloc_array(ns[m->nv] + m->nv, sizeof *P->col);
    P->val = st_malloc_array(ns[m->nv] + m->nv, sizeof *P->val);
    P->cst = st_calloc_array(3 * m->nv, sizeof *P->cst);
    double *cw = st_calloc_array(ns[m->nv] + 1, sizeof *cw);
    double *sw = st_calloc_array(g->nn + 1, sizeof *sw);
    double *area = st_calloc_array(m->nv, sizeof *area);
    int ok = P->start && P->col && P->val && P->cst && cw && sw && area;
    if (ok) {
        cap_cot(m, ns, nl, cw, area);
        ring_cot(g, n, sw, area);
    }
    size_t e = 0;
    for (size_t v = 0; ok && v < m->nv; v++) {
        P->start[v] = e;
        const double r = area[v] > 0.0 ? 1.0 / sqrt(area[v]) : 0.0;
        double tw = 0.0, sum[3] = {0.0, 0.0, 0.0};
        for (size_t k = ns[v]; k < ns[v + 1]; k++) {
            tw += cw[k];
            if (nl[k] < n)
                for (int q = 0; q < 3; q++)
                    sum[q] += cw[k] * m->x[3 * nl[k] + q];
            else {
                P->col[e] = (uint32_t)(nl[k] - n);
                P->val[e++] = r * cw[k];
            }
        }
        if (v < n)
            for (size_t k = g->nstart[v]; k < g->nstart[v + 1]; k++) {
                tw += sw[k];
                for (int q = 0; q < 3; q++)
                    sum[q] += sw[k] * g->nbp[k][q];
            }
        if (v >= n) {
            P->col[e] = (uint32_t)(v - n);
            P->val[e++] = -r * tw;
        }
        for (int q = 0; q < 3; q++)
            P->cst[3 * v + q] = r * (sum[q] - (v < n ? tw * m->x[3 * v + q] : 0.0));
    }
    if (ok)
        P->start[m->nv] = e;
    free(ns), free(nl), free(cw), free(sw), free(area);
    return ok;
}

/* y = C x (rows), and z = C^T r (cols). */
static void plate_mul(const plate *P, const double *x, double *y)
{
    for (size_t r = 0; r < P->rows; r++) {
        double a = 0.0;
        for (size_t k = P->start[r]; k < P->start[r + 1]; k++)
            a += P->val[k] * x[P->col[k]];
        y[r] = a;
    }
}

static void plate_mul_t(const plate *P, const double *r, double *z)
{
    memset(z, 0, P->cols * sizeof *z);
    for (size_t i = 0; i < P->rows; i++)
        for (size_t k = P->start[i]; k < P->start[i + 1]; k++)
            z[P->col[k]] += P->val[k] * r[i];
}

static double dot(const double *a, const double *b, size_t n)
{
    double s = 0.0;
    for (size_t i = 0; i < n; i++)
        s += a[i] * b[i];
    return s;
}

/* Least squares |C u + cst_q|^2 over u (u in, the start; out, the
 * solution) by conjugate gradients on the normal equations; work holds
 * 2 rows + 2 cols. */
static void plate_solve(const plate *P, int q, double *u, double *work)
{
    double *e = work, *w = e + P->rows, *z = w + P->rows, *p = z + P->cols;
    plate_mul(P, u, e);
    for (size_t r = 0; r < P->rows; r++)
        e[r] = -P->cst[3 * r + q] - e[r];
    plate_mul_t(P, e, z);
    memcpy(p, z, P->cols * sizeof *p);
    double zz = dot(z, z, P->cols);
    const double stop = zz * FAIR_CG_TOL * FAIR_CG_TOL;
    for (int it = 0; it < FAIR_CG_ITERS && zz > stop && zz > 0.0; it++) {
        plate_mul(P, p, w);
        const double ww = dot(w, w, P->rows);
        if (!(ww > 0.0))
            break;
        const double al = zz / ww;
        for (size_t i = 0; i < P->cols; i++)
            u[i] += al * p[i];
        for (size_t r = 0; r < P->rows; r++)
            e[r] -= al * w[r];
        plate_mul_t(P, e, z);
        const double zn = dot(z, z, P->cols);
        const double be = zn / zz;
        zz = zn;
        for (size_t i = 0; i < P->cols; i++)
            p[i] = z[i] + be * p[i];
    }
}

/* Moves the refined cap's inner points to the thin plate. 0: out of
 * memory. */
static int fair(fmesh *m, const ring *g)
{
    plate P;
    if (!plate_build(&P, m, g)) {
        plate_free(&P);
        return 0;
    }
    double *u = st_malloc_array(P.cols, sizeof *u);
    double *work = st_malloc_array(2 * P.rows + 2 * P.cols, sizeof *work);
    const int ok = u && work;
    for (int q = 0; ok && q < 3; q++) {
        for (size_t i = 0; i < P.cols; i++)
            u[i] = m->x[3 * (m->n + i) + q];
        plate_solve(&P, q, u, work);
        for (size_t i = 0; i < P.cols; i++)
            m->x[3 * (m->n + i) + q] = u[i];
    }
    free(u), free(work);
    plate_free(&P);
    return ok;
}

/* ---- 5: the check, and the cap -------------------------------------------- */

typedef struct pierce {
    const st_bvh *bvh;
    const uint8_t *kept;        /* NULL: every triangle counts */
    uint32_t self;              /* a triangle not to test (NONE: none) */
    const double *t[3];
} pierce;

static int pierce_visit(void *ctx, uint32_t tri)
{
    const pierce *c = ctx;
    if (tri == c->self || (c->kept && !c->kept[tri]))
        return 0;
    const st_soup *s = c->bvh->soup;
    const uint32_t *v = s->tris + 3 * (size_t)tri;
    return st_tri_tri_cross(c->t[0], c->t[1], c->t[2], s->xyz + 3 * (size_t)v[0],
                            s->xyz + 3 * (size_t)v[1], s->xyz + 3 * (size_t)v[2]);
}

/* 1 when a triangle of cap pierces a kept triangle of the soup or
 * another of the cap's own. */
static st_status pierces(int *hit, const st_soup *cap, const st_holes_rimref *ref, st_error *err)
{
    st_bvh *own = NULL;
    *hit = 0;
    st_status rc = st_bvh_build(&own, cap, err);
    if (rc)
        return rc;
    for (size_t t = 0; t < cap->ntris && !*hit; t++) {
        const uint32_t *v = cap->tris + 3 * t;
        pierce c = {ref->bvh, ref->E->kept, NONE,
                    {cap->xyz + 3 * (size_t)v[0], cap->xyz + 3 * (size_t)v[1],
                     cap->xyz + 3 * (size_t)v[2]}};
        *hit = st_bvh_query_tri(ref->bvh, c.t[0], c.t[1], c.t[2], pierce_visit, &c);
        c.bvh = own;
        c.kept = NULL;
        c.self = (uint32_t)t;
        *hit = *hit || st_bvh_query_tri(own, c.t[0], c.t[1], c.t[2], pierce_visit, &c);
    }
    st_bvh_free(own);
    return ST_OK;
}

static st_status fmesh_soup(st_soup *cap, const fmesh *m, const double *const *pts,
                            st_error *err)
{
    st_status rc = ST_OK;
    for (size_t i = 0; !rc && i < m->nv; i++) {
        const double *p = i < m->n ? pts[i] : m->x + 3 * i;
        rc = st_soup_add_vertex(cap, p[0], p[1], p[2], err);
    }
    for (size_t t = 0; !rc && t < m->nt; t++)
        rc = st_soup_add_triangle(cap, m->v[3 * t], m->v[3 * t + 1], m->v[3 * t + 2], err);
    return rc;
}

st_status st_holes_fair_cap(st_soup *out, int *done, const st_holes_rimref *ref,
                            const double *const *pts, size_t n, const uint32_t *tri,
                            st_error *err)
{
    ring g;
    fmesh m;
    int smooth = 0, hit = 1;
    st_soup *cap = NULL;
    memset(&m, 0, sizeof m);
    *done = 0;
    st_status rc = ring_gather(&g, &smooth, ref, n, pts, err);
    if (rc || !smooth)
        goto done;
    if (!fmesh_init(&m, pts, n, tri, &g)) {
        rc = oom(err);
        goto done;
    }
    /* past FAIR_MAX_VERTS, or nothing to split: as it was */
    const int refined = refine(&m);
    if (refined == -2) {
        rc = oom(err);
        goto done;
    }
    if (refined < 0 || m.nv == n)
        goto done;
    if (!fair(&m, &g)) {
        rc = oom(err);
        goto done;
    }
    if (!(cap = st_soup_new())) {
        rc = oom(err);
        goto done;
    }
    if ((rc = fmesh_soup(cap, &m, pts, err)) || (rc = pierces(&hit, cap, ref, err)))
        goto done;
    if (!hit && !(rc = st_soup_append(out, cap, err)))
        *done = 1;
done:
    st_soup_free(cap);
    fmesh_free(&m);
    ring_free(&g);
    return rc;
}

