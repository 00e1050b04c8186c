/*
 * wrap.c - the repaired soup: extraction, quad splitting, checks and
 * guarded Taubin smoothing (see wrap.h for the algorithm).
 *
 * References: G. Taubin, "A signal processing approach to fair surface
 * design", SIGGRAPH 1995 (the lambda/mu smoothing); OpenVDB's
 * tools::volumeToMesh for the extraction (src/adapters/wrap_vdb.cpp).
 *
 * Every topological or geometric decision (degenerate, fold, intersection)
 * is exact (pred.h, isect.h via soupinfo.h). What is decided in double is
 * a preference only: which of two valid diagonals has the better angles,
 * and whether a smoothing move turned a normal by more than 90 degrees (a
 * guard against folds, which the intersection test does not see: two
 * triangles folded onto each other at an angle share only their edge).
 */
#include "souptet/wrap.h"
#include "../base/fpenv.h"
#include "souptet/bvh.h"
#include "souptet/geom.h"
#include "souptet/isect.h"
#include "souptet/mem.h"
#include "souptet/pred.h"
#include "souptet/soupinfo.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* Below this adaptivity the fallback goes straight to 0: volumeToMesh
 * merges almost nothing at such values, so another round would only
 * repeat the same mesh. */
#define ADAPTIVITY_FLOOR 1e-3
/* Rounds of re-splitting quads whose triangles intersect: each round
 * flips the diagonals of the quads involved; more rounds than this only
 * swap the same pairs back and forth. */
#define RESPLIT_ROUNDS 3
/* How far every value is held off the isovalue before extraction, in
 * voxels (hold_off_iso), tried in turn while the surface fails its check
 * at adaptivity 0: a 64th of a voxel moves no crossing visibly and
 * already separates the points that an exact isovalue puts on a voxel's
 * center; the larger margins are for crossings that still round together
 * (the surface moves by less than the margin, the inside not at all). */
static const double hold_off_margin[] = {1.0 / 64, 1.0 / 8, 1.0 / 2};
#define HOLD_OFF_STEPS (sizeof hold_off_margin / sizeof hold_off_margin[0])

st_wrap_params st_wrap_params_default(void)
{
    st_wrap_params p = {ST_WRAP_DEFAULT_ISO, ST_WRAP_DEFAULT_ADAPTIVITY,
                        ST_WRAP_DEFAULT_SMOOTH, ST_WRAP_DEFAULT_MIN_VOLUME, 0};
    return p;
}

/* ---- small exact helpers -------------------------------------------------- */

static const double *V(const st_soup *s, uint32_t v)
{
    return s->xyz + 3 * (size_t)v;
}

static int collinear3(const double *a, const double *b, const double *c)
{
    return st_orient2d_drop(a, b, c, 0) == 0.0 &&
           st_orient2d_drop(a, b, c, 1) == 0.0 &&
           st_orient2d_drop(a, b, c, 2) == 0.0;
}

/* Triangles (p q a) and (q p b) sharing edge pq overlap beyond it:
 * coplanar with a and b on the same side of pq (soupinfo.h's rule). */
static int folded(const double *p, const double *q, const double *a,
                  const double *b)
{
    if (st_orient3d(p, q, a, b) != 0.0)
        return 0;
    for (int drop = 0; drop < 3; drop++) {
        int sa = st_sign(st_orient2d_drop(p, q, a, drop));
        if (sa != 0)
            return sa == st_sign(st_orient2d_drop(p, q, b, drop));
    }
    return 1; /* a on the line pq: degenerate, refuse it */
}

static double angle_at(const double *o, const double *a, const double *b)
{
    double u[3], v[3], w[3];
    st_sub3(u, a, o);
    st_sub3(v, b, o);
    st_cross3(w, u, v);
    return atan2(st_norm3(w), st_dot3(u, v));
}

static double min_angle(const double *a, const double *b, const double *c)
{
    double x = angle_at(a, b, c), y = angle_at(b, c, a), z = angle_at(c, a, b);
    return fmin(x, fmin(y, z));
}

static void tri_normal(double n[3], const double *a, const double *b,
                       const double *c)
{
    double u[3], v[3];
    st_sub3(u, b, a);
    st_sub3(v, c, a);
    st_cross3(n, u, v);
}

/* ---- an edge set (open addressing on 64-bit keys) ------------------------- */

typedef struct edge_set {
    uint64_t *keys;      /* 0 = empty (no edge joins vertex 0 to itself) */
    size_t cap;
} edge_set;

static uint64_t edge_key(uint32_t a, uint32_t b)
{
    return a < b ? ((uint64_t)a << 32 | b) : ((uint64_t)b << 32 | a);
}

static size_t edge_slot(const edge_set *e, uint64_t k)
{
    uint64_t x = k * 0x9e3779b97f4a7c15ULL;
    size_t i = (size_t)(x >> 17) & (e->cap - 1);
    while (e->keys[i] != 0 && e->keys[i] != k)
        i = (i + 1) & (e->cap - 1);
    return i;
}

static int edge_set_init(edge_set *e, size_t n)
{
    e->cap = 16;
    while (e->cap < 2 * n)
        e->cap *= 2;
    e->keys = st_calloc_array(e->cap, sizeof *e->keys);
    return e->keys ? 0 : -1;
}

static void edge_add(edge_set *e, uint32_t a, uint32_t b)
{
    uint64_t k = edge_key(a, b);
    e->keys[edge_slot(e, k)] = k;
}

static int edge_has(const edge_set *e, uint32_t a, uint32_t b)
{
    uint64_t k = edge_key(a, b);
    return e->keys[edge_slot(e, k)] == k;
}

/* ---- the check ------------------------------------------------------------ */

static uint32_t uf_find(uint32_t *p, uint32_t x)
{
    while (p[x] != x) {
        p[x] = p[p[x]];
        x = p[x];
    }
    return x;
}

/* Ray parity, exactly: the number of triangles not in piece `self` that
 * the segment p-q crosses properly (through their interiors, p and q off
 * their planes). Returns -1 when the segment touches some triangle in a
 * degenerate way (through an edge or a vertex, or p or q on its plane):
 * then the caller tries another q. */
typedef struct ray_ctx {
    const st_soup *s;
    const uint32_t *piece;    /* per triangle */
    uint32_t self;
    const double *p, *q;
    long crossings;
} ray_ctx;

static int ray_visit(void *ctx, uint32_t t)
{
    ray_ctx *c = ctx;
    if (c->piece[t] == c->self)
        return 0;
    const uint32_t *v = c->s->tris + 3 * (size_t)t;
    const double *a = V(c->s, v[0]), *b = V(c->s, v[1]), *d = V(c->s, v[2]);
    int sp = st_sign(st_orient3d(a, b, d, c->p));
    int sq = st_sign(st_orient3d(a, b, d, c->q));
    if (sp == 0 || sq == 0) {
        if (st_segment_tri_intersect(c->p, c->q, a, b, d))
            return 1; /* degenerate */
        return 0;
    }
    if (sp == sq)
        return 0;
    int e0 = st_sign(st_orient3d(c->p, c->q, a, b));
    int e1 = st_sign(st_orient3d(c->p, c->q, b, d));
    int e2 = st_sign(st_orient3d(c->p, c->q, d, a));
    if ((e0 > 0 && e1 > 0 && e2 > 0) || (e0 < 0 && e1 < 0 && e2 < 0)) {
        c->crossings++;
        return 0;
    }
    if ((e0 >= 0 && e1 >= 0 && e2 >= 0) || (e0 <= 0 && e1 <= 0 && e2 <= 0))
        return 1; /* through an edge or a vertex */
    return 0;
}

/* Every piece's volume has the sign its nesting asks for: positive when
 * an even number of other pieces enclose it, negative (a cavity) when an
 * odd number do. Nesting by ray parity from one vertex of the piece. */
static st_status piece_parity(int *ok, int8_t *depth_odd, const st_soup *s,
                               uint32_t *parent, const double *vol,
                               const uint8_t *want, const double lo[3],
                               const double hi[3], st_error *err)
{
    *ok = 1;
    uint32_t *piece = st_malloc_array(s->ntris, sizeof *piece);
    uint8_t *done = st_calloc_array(s->nverts, 1);
    st_bvh *bvh = NULL;
    if (!piece || !done) {
        free(piece);
        free(done);
        return st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory");
    }
    for (size_t t = 0; t < s->ntris; t++)
        piece[t] = uf_find(parent, s->tris[3 * t]);
    st_status st = st_bvh_build(&bvh, s, err);
    if (st) {
        free(piece);
        free(done);
        return st;
    }
    double span = 0.0;
    for (int a = 0; a < 3; a++)
        span = fmax(span, hi[a] - lo[a]);
    for (size_t t = 0; t < s->ntris && (*ok || depth_odd); t++) {
        uint32_t pc = piece[t];
        if (done[pc] || (want && !want[pc]))
            continue;
        done[pc] = 1;
        if (!(vol[pc] != 0.0)) {
            *ok = 0;
            if (!depth_odd)
                break;
        }
        const double *p = V(s, s->tris[3 * t]);
        long parity = -1;
        /* Directions tried in turn: +x first (a thin box query), then
         * skewed ones; a degenerate hit on all of them is not expected on
         * any real surface (counted as not outward). */
        static const double dir[4][3] = {{1, 0, 0},
                                         {1, 0.3183098861837907, 0.1591549430918953},
                                         {0.2718281828459045, 1, 0.1414213562373095},
                                         {0.1732050807568877, 0.2236067977499790, 1}};
        for (int k = 0; k < 4 && parity < 0; k++) {
            double q[3], blo[3], bhi[3];
            for (int a = 0; a < 3; a++) {
                q[a] = p[a] + 4.0 * (span + 1.0) * dir[k][a];
                blo[a] = fmin(p[a], q[a]);
                bhi[a] = fmax(p[a], q[a]);
            }
            ray_ctx c = {s, piece, pc, p, q, 0};
            if (st_bvh_query_box(bvh, blo, bhi, ray_visit, &c) == 0)
                parity = c.crossings & 1;
        }
        if (depth_odd)
            depth_odd[pc] = (int8_t)parity;
        if (parity < 0 || (vol[pc] > 0.0) != (parity == 0))
            *ok = 0;
    }
    st_bvh_free(bvh);
    free(piece);
    free(done);
    return ST_OK;
}

st_status st_wrap_check_compute(st_wrap_check *out, const st_soup *s,
                                st_error *err)
{
    memset(out, 0, sizeof *out);
    st_soupinfo r;
    st_status st = st_soupinfo_compute(&r, s, err);
    if (st)
        return st;
    st = st_soupinfo_self_intersections(&r, s, NULL, err);
    if (st)
        return st;
    out->closed = r.boundary_edges == 0 && r.nonmanifold_edges == 0;
    out->manifold = out->closed && r.nonmanifold_vertices == 0;
    out->oriented = r.inconsistent_edges == 0 && r.nonorientable_pieces == 0;
    out->nondegenerate = r.degenerate_triangles == 0 &&
                         r.collinear_triangles == 0;
    out->distinct = r.welded_vertices + r.unreferenced_vertices == r.vertices;
    out->self_intersection_free = r.self_intersecting_pairs == 0;
    out->self_intersecting_pairs = r.self_intersecting_pairs;
    out->pieces = r.pieces;

    /* Signed volume per piece (pieces by shared vertex indices, which are
     * the welded ones when the vertices are distinct), about the center
     * of the box so the terms do not cancel catastrophically. */
    double c[3];
    for (int a = 0; a < 3; a++)
        c[a] = 0.5 * (r.lo[a] + r.hi[a]);
    uint32_t *parent = st_malloc_array(s->nverts, sizeof *parent);
    double *vol = st_calloc_array(s->nverts, sizeof *vol);
    if (!parent || !vol) {
        free(parent);
        free(vol);
        return st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory");
    }
    for (size_t v = 0; v < s->nverts; v++)
        parent[v] = (uint32_t)v;
    for (size_t t = 0; t < s->ntris; t++) {
        const uint32_t *v = s->tris + 3 * t;
        for (int k = 1; k < 3; k++) {
            uint32_t x = uf_find(parent, v[0]), y = uf_find(parent, v[k]);
            if (x != y)
                parent[x > y ? x : y] = x < y ? x : y;
        }
    }
    double total = 0.0;
    for (size_t t = 0; t < s->ntris; t++) {
        const uint32_t *v = s->tris + 3 * t;
        double p[3][3], n[3];
        for (int k = 0; k < 3; k++)
            st_sub3(p[k], s->xyz + 3 * (size_t)v[k], c);
        st_cross3(n, p[1], p[2]);
        double dv = st_dot3(p[0], n) / 6.0;
        vol[uf_find(parent, v[0])] += dv;
        total += dv;
    }
    out->volume = total;
    st_status st2 = piece_parity(&out->outward, NULL, s, parent, vol, NULL,
                                 r.lo, r.hi, err);
    free(parent);
    free(vol);
    return st2;
}

int st_wrap_check_ok(const st_wrap_check *c)
{
    return c->closed && c->manifold && c->oriented && c->outward &&
           c->nondegenerate && c->distinct && c->self_intersection_free;
}

static const char *check_failure(const st_wrap_check *c)
{
    if (!c->closed)
        return "not closed";
    if (!c->manifold)
        return "a vertex with more than one fan";
    if (!c->oriented)
        return "inconsistently oriented";
    if (!c->outward)
        return "a piece encloses no positive volume";
    if (!c->nondegenerate)
        return "degenerate triangles";
    if (!c->distinct)
        return "two vertices at the same point";
    if (!c->self_intersection_free)
        return "self-intersecting triangles";
    return "ok";
}

/* ---- cavities and specks ------------------------------------------------- */

/* Drop from P the polygons of every cavity (unless keep_cavities), of
 * every outer piece enclosing less than min_volume, and of every piece
 * left inside another once its cavity is filled.
 *
 * volumeToMesh orients every polygon along the field's gradient, so a
 * piece enclosing negative volume bounds outside voxels: a cavity. (No ray
 * is needed for those: single-voxel pockets come by the thousand on the
 * 50%-deleted models, in rows whose identical vertices would make
 * axis-aligned rays graze each other.) A piece of positive volume big
 * enough to keep is tested by exact ray parity for lying inside another
 * piece (an island in a cavity), which filling the cavity would bury in
 * the solid. Pieces and volumes are found on P triangulated along 0-2:
 * any split encloses the same pieces, and the volume only meets a
 * threshold and a sign (a piece's volume is that of the voxels it
 * bounds, far from 0). */
static st_status filter_pieces(st_wrap_polys *P, double min_volume,
                               int keep_cavities, st_wrap_stats *stats,
                               st_error *err)
{
    st_status st = ST_ENOMEM;
    st_soup tmp = {0};
    uint32_t *parent = st_malloc_array(P->npoints, sizeof *parent);
    double *vol = st_calloc_array(P->npoints, sizeof *vol);
    int8_t *odd = st_calloc_array(P->npoints, 1);
    uint8_t *keep = st_calloc_array(P->npoints, 1);
    uint8_t *want = st_calloc_array(P->npoints, 1);
    if (!parent || !vol || !odd || !keep || !want)
        goto done;
    tmp.xyz = P->xyz;
    tmp.nverts = P->npoints;
    tmp.ntris = 2 * P->nquads + P->ntris;
    tmp.tris = st_malloc_array(3 * tmp.ntris, sizeof *tmp.tris);
    if (!tmp.tris)
        goto done;
    for (size_t i = 0; i < P->nquads; i++) {
        const uint32_t *q = P->quads + 4 * i;
        uint32_t *t = tmp.tris + 6 * i;
        t[0] = q[0], t[1] = q[1], t[2] = q[2];
        t[3] = q[0], t[4] = q[2], t[5] = q[3];
    }
    memcpy(tmp.tris + 6 * P->nquads, P->tris, 3 * P->ntris * sizeof *P->tris);
    for (size_t v = 0; v < P->npoints; v++)
        parent[v] = (uint32_t)v;
    for (size_t t = 0; t < tmp.ntris; t++) {
        const uint32_t *v = tmp.tris + 3 * t;
        for (int k = 1; k < 3; k++) {
            uint32_t x = uf_find(parent, v[0]), y = uf_find(parent, v[k]);
            if (x != y)
                parent[x > y ? x : y] = x < y ? x : y;
        }
    }
    double lo[3] = {INFINITY, INFINITY, INFINITY},
           hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (size_t v = 0; v < P->npoints; v++)
        for (int a = 0; a < 3; a++) {
            lo[a] = fmin(lo[a], P->xyz[3 * v + a]);
            hi[a] = fmax(hi[a], P->xyz[3 * v + a]);
        }
    double c[3];
    for (int a = 0; a < 3; a++)
        c[a] = 0.5 * (lo[a] + hi[a]);
    for (size_t t = 0; t < tmp.ntris; t++) {
        const uint32_t *v = tmp.tris + 3 * t;
        double p[3][3], n[3];
        for (int k = 0; k < 3; k++)
            st_sub3(p[k], P->xyz + 3 * (size_t)v[k], c);
        st_cross3(n, p[1], p[2]);
        vol[uf_find(parent, v[0])] += st_dot3(p[0], n) / 6.0;
    }
    size_t cavities = 0, big = 0;
    for (size_t v = 0; v < P->npoints; v++) {
        if (parent[v] != v || vol[v] == 0.0)
            continue;
        if (vol[v] < 0.0) {
            cavities++;
            keep[v] = (uint8_t)keep_cavities;
        } else if (vol[v] < min_volume) {
            stats->specks_dropped++;
        } else {
            keep[v] = 1;
            want[v] = 1;
            big++;
        }
    }
    if (!keep_cavities)
        stats->cavities_filled = cavities;
    if (!keep_cavities && cavities > 0 && big > 1) {
        int ok;
        if ((st = piece_parity(&ok, odd, &tmp, parent, vol, want, lo, hi,
                               err)))
            goto done;
        for (size_t v = 0; v < P->npoints; v++)
            if (want[v] && odd[v] != 0) {
                keep[v] = 0; /* an island in a filled cavity */
                stats->cavities_filled++;
            }
    }
    size_t nq = 0, nt = 0;
    for (size_t i = 0; i < P->nquads; i++)
        if (keep[uf_find(parent, P->quads[4 * i])])
            memmove(P->quads + 4 * nq++, P->quads + 4 * i, 4 * sizeof *P->quads);
    for (size_t i = 0; i < P->ntris; i++)
        if (keep[uf_find(parent, P->tris[3 * i])])
            memmove(P->tris + 3 * nt++, P->tris + 3 * i, 3 * sizeof *P->tris);
    P->nquads = nq;
    P->ntris = nt;
    st = ST_OK;
done:
    if (st == ST_ENOMEM)
        st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory");
    free(tmp.tris);
    free(parent);
    free(vol);
    free(odd);
    free(keep);
    free(want);
    return st;
}

/* ---- from polygons to triangles ------------------------------------------ */

typedef struct mesh {
    st_soup *s;            /* the output soup */
    uint32_t *quads;       /* 4 per quad, output vertex indices */
    size_t nquads;
    uint8_t *split;        /* per quad: 0 diagonal 0-2, 1 diagonal 1-3 */
    size_t nfixed;         /* triangles that came as triangles */
} mesh;

/* The two triangles of quad q split along diagonal d, as corner indices
 * into the quad (orientation kept). */
static const int split_tri[2][2][3] = {{{0, 1, 2}, {0, 2, 3}},
                                       {{0, 1, 3}, {1, 2, 3}}};

/* A diagonal is allowed when both triangles are non-degenerate, it is no
 * edge yet, and the pair does not fold flat onto itself. */
static int split_ok(const st_soup *s, const uint32_t *q, int d,
                    const edge_set *edges)
{
    const double *p[4];
    for (int k = 0; k < 4; k++)
        p[k] = V(s, q[k]);
    if (d == 0) {
        if (edge_has(edges, q[0], q[2]))
            return 0;
        return !collinear3(p[0], p[1], p[2]) &&
               !collinear3(p[0], p[2], p[3]) &&
               !folded(p[0], p[2], p[1], p[3]);
    }
    if (edge_has(edges, q[1], q[3]))
        return 0;
    return !collinear3(p[0], p[1], p[3]) && !collinear3(p[1], p[2], p[3]) &&
           !folded(p[1], p[3], p[0], p[2]);
}

static double split_quality(const st_soup *s, const uint32_t *q, int d)
{
    const int(*t)[3] = split_tri[d];
    return fmin(min_angle(V(s, q[t[0][0]]), V(s, q[t[0][1]]), V(s, q[t[0][2]])),
                min_angle(V(s, q[t[1][0]]), V(s, q[t[1][1]]), V(s, q[t[1][2]])));
}

static void write_quad(mesh *m, size_t i)
{
    const uint32_t *q = m->quads + 4 * i;
    const int(*t)[3] = split_tri[m->split[i]];
    uint32_t *dst = m->s->tris + 3 * (m->nfixed + 2 * i);
    for (int k = 0; k < 2; k++)
        for (int c = 0; c < 3; c++)
            dst[3 * k + c] = q[t[k][c]];
}

/* Build the soup: referenced points (rounded to float), the polygons'
 * triangles first, then two per quad, in volumeToMesh's winding, which is
 * outward for a field negative inside (tests/test_wrap.c checks it: every
 * shape's pieces enclose positive volume). */
static st_status mesh_build(mesh *m, const st_wrap_polys *P, st_error *err)
{
    st_status st = ST_ENOMEM;
    uint32_t *map = st_malloc_array(P->npoints, sizeof *map);
    edge_set edges = {0};
    memset(m, 0, sizeof *m);
    m->s = st_soup_new();
    m->quads = st_malloc_array(4 * P->nquads, sizeof *m->quads);
    m->split = st_calloc_array(P->nquads, 1);
    if (!map || !m->s || !m->quads || !m->split ||
        edge_set_init(&edges, 4 * P->nquads + 3 * P->ntris))
        goto fail;
    for (size_t i = 0; i < P->npoints; i++)
        map[i] = UINT32_MAX;
    for (size_t i = 0; i < 4 * P->nquads; i++)
        map[P->quads[i]] = 0;
    for (size_t i = 0; i < 3 * P->ntris; i++)
        map[P->tris[i]] = 0;
    for (size_t i = 0; i < P->npoints; i++) {
        if (map[i] == UINT32_MAX)
            continue;
        map[i] = (uint32_t)m->s->nverts;
        const double *x = P->xyz + 3 * i;
        if ((st = st_soup_add_vertex(m->s, (double)(float)x[0],
                                     (double)(float)x[1], (double)(float)x[2],
                                     err)))
            goto fail;
    }
    st = ST_ENOMEM;
    for (size_t i = 0; i < P->ntris; i++) {
        const uint32_t *t = P->tris + 3 * i;
        if ((st = st_soup_add_triangle(m->s, map[t[0]], map[t[1]], map[t[2]],
                                       err)))
            goto fail;
        edge_add(&edges, map[t[0]], map[t[1]]);
        edge_add(&edges, map[t[1]], map[t[2]]);
        edge_add(&edges, map[t[2]], map[t[0]]);
    }
    m->nfixed = P->ntris;
    m->nquads = P->nquads;
    for (size_t i = 0; i < P->nquads; i++) {
        const uint32_t *q = P->quads + 4 * i;
        uint32_t *d = m->quads + 4 * i;
        for (int k = 0; k < 4; k++)
            d[k] = map[q[k]];
        for (int k = 0; k < 4; k++)
            edge_add(&edges, d[k], d[(k + 1) % 4]);
    }
    /* Choose diagonals in quad order (deterministic); a chosen diagonal
     * is an edge from then on. */
    for (size_t i = 0; i < P->nquads; i++) {
        const uint32_t *q = m->quads + 4 * i;
        int ok0 = split_ok(m->s, q, 0, &edges),
            ok1 = split_ok(m->s, q, 1, &edges);
        int d = 0;
        if (ok0 && ok1)
            d = split_quality(m->s, q, 1) > split_quality(m->s, q, 0);
        else if (ok1)
            d = 1;
        m->split[i] = (uint8_t)d;
        if (d == 0)
            edge_add(&edges, q[0], q[2]);
        else
            edge_add(&edges, q[1], q[3]);
        for (int k = 0; k < 2; k++) {
            const int *t = split_tri[d][k];
            if ((st = st_soup_add_triangle(m->s, q[t[0]], q[t[1]], q[t[2]],
                                           err)))
                goto fail;
        }
    }
    free(map);
    free(edges.keys);
    return ST_OK;
fail:
    if (st == ST_ENOMEM)
        st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory building the "
                                              "surface");
    free(map);
    free(edges.keys);
    st_soup_free(m->s);
    free(m->quads);
    free(m->split);
    memset(m, 0, sizeof *m);
    return st;
}

static void mesh_clear(mesh *m)
{
    st_soup_free(m->s);
    free(m->quads);
    free(m->split);
    memset(m, 0, sizeof *m);
}

/* Re-split the quads whose triangles intersect something, where the other
 * diagonal is allowed; keep the round only when it lowers the count. */
static st_status resplit(mesh *m, size_t *count, st_error *err)
{
    st_soup *s = m->s;
    unsigned char *flags = st_malloc_array(s->ntris, 1);
    edge_set edges = {0};
    st_status st = ST_ENOMEM;
    if (!flags || edge_set_init(&edges, 3 * s->ntris))
        goto done;
    st_soupinfo r;
    if ((st = st_soupinfo_self_intersections(&r, s, flags, err)))
        goto done;
    size_t before = r.self_intersecting_pairs;
    for (int round = 0; round < RESPLIT_ROUNDS && before > 0; round++) {
        memset(edges.keys, 0, edges.cap * sizeof *edges.keys);
        for (size_t t = 0; t < s->ntris; t++)
            for (int k = 0; k < 3; k++)
                edge_add(&edges, s->tris[3 * t + k],
                         s->tris[3 * t + (k + 1) % 3]);
        size_t changed = 0;
        uint8_t *old = st_malloc_array(m->nquads, 1);
        if (!old) {
            st = ST_ENOMEM;
            goto done;
        }
        memcpy(old, m->split, m->nquads);
        for (size_t i = 0; i < m->nquads; i++) {
            size_t t = m->nfixed + 2 * i;
            if (!flags[t] && !flags[t + 1])
                continue;
            int d = !m->split[i];
            if (!split_ok(s, m->quads + 4 * i, d, &edges))
                continue;
            m->split[i] = (uint8_t)d;
            write_quad(m, i);
            changed++;
        }
        if (changed == 0) {
            free(old);
            break;
        }
        if ((st = st_soupinfo_self_intersections(&r, s, flags, err))) {
            free(old);
            goto done;
        }
        if (r.self_intersecting_pairs >= before) {
            memcpy(m->split, old, m->nquads);
            for (size_t i = 0; i < m->nquads; i++)
                write_quad(m, i);
            free(old);
            break;
        }
        *count += changed;
        before = r.self_intersecting_pairs;
        free(old);
    }
    st = ST_OK;
done:
    if (st == ST_ENOMEM)
        st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory");
    free(flags);
    free(edges.keys);
    return st;
}

/* ---- guarded Taubin smoothing --------------------------------------------- */

typedef struct adj {
    uint32_t *start;   /* nverts + 1 */
    uint32_t *nbr;     /* neighbours (edges, both ways) */
    uint32_t *tstart;  /* nverts + 1 */
    uint32_t *tri;     /* incident triangles */
} adj;

static void adj_free(adj *a)
{
    free(a->start);
    free(a->nbr);
    free(a->tstart);
    free(a->tri);
}

static int cmp_u32(const void *x, const void *y)
{
    uint32_t a = *(const uint32_t *)x, b = *(const uint32_t *)y;
    return (a > b) - (a < b);
}

static int adj_build(adj *a, const st_soup *s)
{
    size_t nv = s->nverts, nc = 3 * s->ntris;
    memset(a, 0, sizeof *a);
    a->start = st_calloc_array(nv + 1, sizeof *a->start);
    a->tstart = st_calloc_array(nv + 1, sizeof *a->tstart);
    a->nbr = st_malloc_array(2 * nc, sizeof *a->nbr);
    a->tri = st_malloc_array(nc, sizeof *a->tri);
    if (!a->start || !a->tstart || !a->nbr || !a->tri)
        return -1;
    for (size_t i = 0; i < nc; i++) {
        a->start[s->tris[i] + 1] += 2;
        a->tstart[s->tris[i] + 1]++;
    }
    for (size_t v = 0; v < nv; v++) {
        a->start[v + 1] += a->start[v];
        a->tstart[v + 1] += a->tstart[v];
    }
    uint32_t *fill = st_malloc_array(nv, sizeof *fill);
    uint32_t *tfill = st_malloc_array(nv, sizeof *tfill);
    if (!fill || !tfill) {
        free(fill);
        free(tfill);
        return -1;
    }
    memcpy(fill, a->start, nv * sizeof *fill);
    memcpy(tfill, a->tstart, nv * sizeof *tfill);
    for (size_t t = 0; t < s->ntris; t++)
        for (int k = 0; k < 3; k++) {
            uint32_t v = s->tris[3 * t + k];
            a->nbr[fill[v]++] = s->tris[3 * t + (k + 1) % 3];
            a->nbr[fill[v]++] = s->tris[3 * t + (k + 2) % 3];
            a->tri[tfill[v]++] = (uint32_t)t;
        }
    /* Each neighbour appears twice on a closed manifold (once per
     * incident triangle): sort and keep one of each, compacting in place
     * but keeping start[] valid through a second array of ends. */
    uint32_t w = 0;
    for (size_t v = 0; v < nv; v++) {
        uint32_t b = a->start[v], e = a->start[v + 1];
        qsort(a->nbr + b, e - b, sizeof *a->nbr, cmp_u32);
        a->start[v] = w;
        for (uint32_t i = b; i < e; i++)
            if (i == b || a->nbr[i] != a->nbr[i - 1])
                a->nbr[w++] = a->nbr[i];
    }
    a->start[nv] = w;
    free(fill);
    free(tfill);
    return 0;
}

/* Triangle t is acceptable after a move: not degenerate, its normal
 * turned by less than 90 degrees from n0 (before the step). */
static int tri_ok(const st_soup *s, size_t t, const double *n0)
{
    const uint32_t *v = s->tris + 3 * t;
    const double *a = V(s, v[0]), *b = V(s, v[1]), *c = V(s, v[2]);
    if (collinear3(a, b, c))
        return 0;
    double n[3];
    tri_normal(n, a, b, c);
    return st_dot3(n, n0 + 3 * t) > 0.0;
}

static uint64_t point_hash(const double *p)
{
    uint64_t h = 0x9e3779b97f4a7c15ULL;
    for (int a = 0; a < 3; a++) {
        double x = p[a] == 0.0 ? 0.0 : p[a];
        uint64_t b;
        memcpy(&b, &x, sizeof b);
        h ^= b + 0x9e3779b97f4a7c15ULL + (h << 6) + (h >> 2);
        h *= 0xbf58476d1ce4e5b9ULL;
    }
    return h ^ (h >> 31);
}

/* Mark (in bad[]) every moved vertex that now shares its point with
 * another vertex. Returns the number marked, or -1 out of memory. */
static long coincident(const st_soup *s, const uint8_t *moved, uint8_t *bad)
{
    size_t cap = 16;
    while (cap < 2 * s->nverts)
        cap *= 2;
    uint32_t *tab = st_malloc_array(cap, sizeof *tab);
    if (!tab)
        return -1;
    for (size_t i = 0; i < cap; i++)
        tab[i] = UINT32_MAX;
    long n = 0;
    for (size_t v = 0; v < s->nverts; v++) {
        const double *p = V(s, (uint32_t)v);
        size_t i = (size_t)point_hash(p) & (cap - 1);
        for (;; i = (i + 1) & (cap - 1)) {
            uint32_t w = tab[i];
            if (w == UINT32_MAX) {
                tab[i] = (uint32_t)v;
                break;
            }
            const double *q = V(s, w);
            if (p[0] == q[0] && p[1] == q[1] && p[2] == q[2]) {
                if (moved[v] && !bad[v]) {
                    bad[v] = 1;
                    n++;
                }
                if (moved[w] && !bad[w]) {
                    bad[w] = 1;
                    n++;
                }
                break;
            }
        }
    }
    free(tab);
    return n;
}

/* One half step: x += f * (mean of neighbours - x), then undo the moves
 * that break the surface. *reverted counts the undone moves. */
static st_status taubin_half(st_soup *s, const adj *a, double f,
                             size_t *reverted, st_error *err)
{
    const size_t nv = s->nverts, nt = s->ntris;
    st_status st = ST_ENOMEM;
    double *old = st_malloc_array(3 * nv, sizeof *old);
    double *n0 = st_malloc_array(3 * nt, sizeof *n0);
    uint8_t *moved = st_calloc_array(nv, 1);
    uint8_t *bad = st_calloc_array(nv, 1);
    unsigned char *flags = st_malloc_array(nt, 1);
    if (!old || !n0 || !moved || !bad || !flags)
        goto done;
    memcpy(old, s->xyz, 3 * nv * sizeof *old);
    for (size_t t = 0; t < nt; t++) {
        const uint32_t *v = s->tris + 3 * t;
        tri_normal(n0 + 3 * t, V(s, v[0]), V(s, v[1]), V(s, v[2]));
    }
#pragma omp parallel for schedule(static)
    for (size_t v = 0; v < nv; v++) {
        uint32_t b = a->start[v], e = a->start[v + 1];
        if (b == e)
            continue;
        double m[3] = {0, 0, 0};
        for (uint32_t i = b; i < e; i++)
            for (int k = 0; k < 3; k++)
                m[k] += old[3 * (size_t)a->nbr[i] + k];
        for (int k = 0; k < 3; k++) {
            double x = old[3 * v + k];
            double y = (double)(float)(x + f * (m[k] / (double)(e - b) - x));
            s->xyz[3 * v + k] = y;
            if (y != x)
                moved[v] = 1;
        }
    }
    for (;;) {
        /* local checks until no triangle fails */
        size_t nbad = 0;
        for (;;) {
            size_t n = 0;
            for (size_t t = 0; t < nt; t++) {
                if (tri_ok(s, t, n0))
                    continue;
                for (int k = 0; k < 3; k++) {
                    uint32_t v = s->tris[3 * t + k];
                    if (moved[v] && !bad[v]) {
                        bad[v] = 1;
                        n++;
                    }
                }
            }
            long c = coincident(s, moved, bad);
            if (c < 0)
                goto done;
            n += (size_t)c;
            for (size_t v = 0; v < nv; v++)
                if (bad[v]) {
                    memcpy(s->xyz + 3 * v, old + 3 * v, 3 * sizeof *old);
                    moved[v] = 0;
                    bad[v] = 0;
                }
            nbad += n;
            *reverted += n;
            if (n == 0)
                break;
        }
        st_soupinfo r;
        if ((st = st_soupinfo_self_intersections(&r, s, flags, err)))
            goto done;
        st = ST_ENOMEM;
        if (r.self_intersecting_pairs == 0)
            break;
        size_t n = 0;
        for (size_t t = 0; t < nt; t++) {
            if (!flags[t])
                continue;
            for (int k = 0; k < 3; k++) {
                uint32_t v = s->tris[3 * t + k];
                if (moved[v]) {
                    memcpy(s->xyz + 3 * (size_t)v, old + 3 * (size_t)v,
                           3 * sizeof *old);
                    moved[v] = 0;
                    n++;
                }
            }
        }
        *reverted += n;
        if (n == 0)
            break; /* intersections not caused by this step */
        (void)nbad;
    }
    st = ST_OK;
done:
    if (st == ST_ENOMEM)
        st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory smoothing");
    free(old);
    free(n0);
    free(moved);
    free(bad);
    free(flags);
    return st;
}

/* ---- values at the isovalue ----------------------------------------------- */

/* Away from the isovalue by at least delta (model units): every value in
 * [iso - delta, iso) becomes iso - delta, every value in [iso, iso + delta)
 * iso + delta, so the inside (value < iso) stays the same voxels.
 *
 * Why: a voxel whose value is the isovalue, or so close to it that the
 * crossing rounds onto the voxel's center in volumeToMesh's float index
 * coordinates, has every edge crossing next to it at that center; each
 * cell around it whose crossings are all on those edges puts its point
 * there too, so distinct vertices share one point and their quads are
 * degenerate whichever diagonal splits them (measured: a CAD part whose
 * axis-aligned faces lie on voxel centers, distance 0 there, gave 13 such
 * quads at 200 cells, anchor-largeholes). Held apart by delta, the
 * crossings on the edges from such a voxel are at least
 * delta / (delta + the neighbour's distance) of a voxel from its center.
 * *moved gets the number of values changed; *out is g itself when none
 * is, else a shallow copy whose data the caller frees. */
static st_status hold_off_iso(st_grid *out, float **data, size_t *moved,
                              const st_grid *g, float iso, float delta,
                              st_error *err)
{
    *out = *g;
    *data = NULL;
    *moved = 0;
    const size_t n = st_grid_count(g);
    const float lo = iso - delta, hi = iso + delta;
    size_t m = 0;
    for (size_t i = 0; i < n; i++)
        m += g->data[i] > lo && g->data[i] < hi;
    if (m == 0)
        return ST_OK;
    float *d = st_malloc_array(n, sizeof *d);
    if (!d)
        return st_error_set(err, ST_ENOMEM, NULL, 0,
                            "out of memory for a copy of the field");
#pragma omp parallel for schedule(static)
    for (size_t i = 0; i < n; i++) {
        float v = g->data[i];
        d[i] = v < iso ? (v > lo ? lo : v) : (v < hi ? hi : v);
    }
    out->data = d;
    *data = d;
    *moved = m;
    return ST_OK;
}

/* ---- the whole job -------------------------------------------------------- */

/* Extraction, pieces, quads to triangles and the check, with the
 * fallbacks of wrap.h: halving the adaptivity, then the larger margins
 * off the isovalue. *m gets the checked surface. */
static st_status extract_checked(mesh *m, const st_grid *g, const st_wrap_params *p,
                                 st_wrap_stats *stats, const st_progress *progress,
                                 st_error *err)
{
    const float iso = (float)p->iso;
    double A = p->adaptivity;
    st_wrap_check chk;
    size_t margin = 0;      /* index into hold_off_margin[] */
    st_grid held;
    float *held_data = NULL;
    double held_for = -1.0; /* the margin `held` was made for */
    for (;;) {
        if (st_progress_cancelled(progress)) {
            free(held_data);
            return st_error_set(err, ST_ECANCELLED, NULL, 0, "cancelled");
        }
        st_progress_report(progress, "extract", 0.0);
        st_status st = ST_OK;
        if (held_for != hold_off_margin[margin]) {
            free(held_data);
            held_for = stats->iso_margin = hold_off_margin[margin];
            st = hold_off_iso(&held, &held_data, &stats->iso_held_off, g,
                              iso, (float)(stats->iso_margin * g->voxel),
                              err);
            if (st)
                return st;
        }
        st_wrap_polys P;
        st = st_wrap_polys_vdb(&P, &held, p->iso, A, err);
        if (st) {
            free(held_data);
            return st;
        }
        stats->quads = P.nquads;
        stats->triangles = P.ntris;
        stats->cavities_filled = stats->specks_dropped = 0;
        st = filter_pieces(&P, p->min_volume * g->voxel * g->voxel * g->voxel,
                           p->keep_cavities, stats, err);
        if (st == ST_OK && P.nquads + P.ntris == 0)
            st = st_error_set(err, ST_EINPUT, NULL, 0,
                              "every piece of the surface is smaller than "
                              "--min-volume (%g voxels)", p->min_volume);
        if (st == ST_OK)
            st = mesh_build(m, &P, err);
        st_wrap_polys_clear(&P);
        if (st) {
            free(held_data);
            return st;
        }
        st_progress_report(progress, "check", 0.5);
        if ((st = st_wrap_check_compute(&chk, m->s, err)) ||
            (!chk.self_intersection_free &&
             ((st = resplit(m, &stats->resplit, err)) ||
              (st = st_wrap_check_compute(&chk, m->s, err))))) {
            mesh_clear(m);
            free(held_data);
            return st;
        }
        if (st_wrap_check_ok(&chk))
            break;
        mesh_clear(m);
        if (A > 0.0) {
            A = A / 2 < ADAPTIVITY_FLOOR ? 0.0 : A / 2;
        } else if (margin + 1 < HOLD_OFF_STEPS) {
            margin++; /* the values held farther off the isovalue */
        } else {
            free(held_data);
            return st_error_set(err, ST_EINTERNAL, NULL, 0,
                                "the extracted surface fails its check: %s "
                                "(%zu self-intersecting pairs)",
                                check_failure(&chk),
                                chk.self_intersecting_pairs);
        }
    }
    free(held_data);
    stats->adaptivity_used = A;
    return ST_OK;
}

st_status st_wrap_field(st_soup **out, const st_grid *g,
                        const st_wrap_params *p, st_wrap_stats *stats,
                        const st_progress *progress, st_error *err)
{
    *out = NULL;
    st_wrap_stats dummy;
    if (!stats)
        stats = &dummy;
    memset(stats, 0, sizeof *stats);
    if (!g || !g->data)
        return st_error_set(err, ST_EINTERNAL, NULL, 0, "no field");
    if (g->kind == ST_GRID_DISTANCE)
        return st_error_set(err, ST_EINPUT, NULL, 0,
                            "an unsigned distance field has no inside: "
                            "sign it first (soupsign)");
    if (!isfinite(p->iso) || !(p->adaptivity >= 0.0 && p->adaptivity <= 1.0) ||
        p->smooth < 0 || !(p->min_volume >= 0.0))
        return st_error_set(err, ST_EINPUT, NULL, 0,
                            "isovalue must be finite, adaptivity in [0, 1], "
                            "smoothing steps >= 0");
    const size_t n = st_grid_count(g);
    size_t inside = 0, edge_inside = 0;
    const float iso = (float)p->iso;
    for (size_t k = 0; k < g->nz; k++)
        for (size_t j = 0; j < g->ny; j++)
            for (size_t i = 0; i < g->nx; i++) {
                if (!(g->data[st_grid_index(g, i, j, k)] < iso))
                    continue;
                inside++;
                if (i == 0 || j == 0 || k == 0 || i == g->nx - 1 ||
                    j == g->ny - 1 || k == g->nz - 1)
                    edge_inside++;
            }
    (void)n;
    stats->edge_voxels_inside = edge_inside;
    if (inside == 0)
        return st_error_set(err, ST_EINPUT, NULL, 0,
                            "nothing inside: no value of the field is below "
                            "the isovalue %g", p->iso);

    mesh m = {0};
    st_wrap_check chk;
    st_status xst = extract_checked(&m, g, p, stats, progress, err);
    if (xst)
        return xst;
    free(m.quads);
    free(m.split);
    m.quads = NULL;
    m.split = NULL;

    if (p->smooth > 0) {
        adj a;
        if (adj_build(&a, m.s)) {
            adj_free(&a);
            st_soup_free(m.s);
            return st_error_set(err, ST_ENOMEM, NULL, 0,
                                "out of memory smoothing");
        }
        for (int step = 0; step < p->smooth; step++) {
            st_progress_report(progress, "smooth",
                               (double)step / (double)p->smooth);
            st_status st = ST_OK;
            if (st_progress_cancelled(progress)) {
                adj_free(&a);
                st_soup_free(m.s);
                return st_error_set(err, ST_ECANCELLED, NULL, 0, "cancelled");
            }
            if ((st = taubin_half(m.s, &a, ST_WRAP_TAUBIN_LAMBDA,
                                  &stats->smooth_reverted, err)) ||
                (st = taubin_half(m.s, &a, ST_WRAP_TAUBIN_MU,
                                  &stats->smooth_reverted, err))) {
                adj_free(&a);
                st_soup_free(m.s);
                return st;
            }
            stats->smooth_steps++;
        }
        adj_free(&a);
        st_status st = st_wrap_check_compute(&chk, m.s, err);
        if (st) {
            st_soup_free(m.s);
            return st;
        }
        if (!st_wrap_check_ok(&chk)) {
            st_soup_free(m.s);
            return st_error_set(err, ST_EINTERNAL, NULL, 0,
                                "smoothing broke the surface: %s",
                                check_failure(&chk));
        }
    }
    st_progress_report(progress, "done", 1.0);
    *out = m.s;
    return ST_OK;
}
