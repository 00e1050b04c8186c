/*
 * holes_planes.c - a hole's cap from a corner rebuilt from the planes
 * around it (holes_internal.h; issue 17, the large holes of CAD parts).
 *
 * A CAD part's large hole takes whole faces and the corners where they
 * met: a cap over the loop's own points cannot bring a lost corner back.
 * The faces along the loop still carry their planes (those of the soup's
 * triangles on its edges), and extended into the hole three of them meet
 * at the lost corner, two along the lost edge. The cone from such a point
 * over the loop (a triangle on each loop edge, all meeting there) lies in
 * the planes where the loop runs over one face each: a box's lost corner
 * comes back whole, a lost edge as its two faces.
 *
 * The apexes tried: the point where three of the planes meet, and the
 * point of the line where two meet nearest the loop's centroid, within
 * the loop's box grown by REACH of its extent; of the planes, once each
 * (SAME), at most MAX_PLANES, those along most of the loop. A cone is
 * measured by how well it continues the faces along the loop: the sum
 * over the loop's edges of length times the dihedral angle between its
 * triangle there and the soup's (as the caps that bend least are
 * measured in holes.c, their spokes left out: a lost corner's creases are
 * no fault). The cone that continues them best (ties by the bend of its
 * spokes too) is the cap when it does better than the caller's bound
 * (the cap of the loop's own points, which chamfers a lost corner: a
 * box's bends along all its loop by 55 degrees, the corner's cone by 0)
 * and none of its triangles pierces the surviving soup (st_tri_tri_cross
 * on the BVH; touching it, as at a crease along the loop, is allowed): a
 * point where far planes meet sends cones through the part. Of the
 * cones below the bound, the least bent that pierces nothing.
 *
 * A large hole spans several corners (a lost edge and both its ends, a
 * wing of a part): no one point continues all of its loop.
 * st_holes_planes_fans takes the point that continues the most of it
 * exactly (its triangle over an edge within FAN_FLAT of the soup's
 * plane there, on the hole's side, its fan piercing none of the soup),
 * fans from it over the edges it continues, and replaces each run of
 * them by the point; the loop left (split into several where it meets
 * the point more than once) is capped the same way, and one that no
 * point continues along two edges by the caller's triangulation of its
 * own points. The caller keeps the fans or the single cone, whichever
 * continues the soup along the loop better. (That last triangulation is
 * not tested for piercing: with it, a rebuilt cap that pierces falls
 * back whole, and the corpus's large holes lose, core IoU at 128^3,
 * 0.838 -> 0.808 with planes, 0.875 -> 0.850 with planes-bend, joint
 * 0.751 -> 0.587, for deleted faces' 0.9945 -> 0.9958, cheese 0.971 ->
 * 0.980.)
 *
 * The piercing test (issue 17, core IoU at 128^3, planes, class means,
 * before -> after): deleted50 0.9903 -> 0.9945 (cheese 0.925 -> 0.971),
 * holes 0.9825 -> 0.9837, onesided 0.8389 -> 0.8461, largeholes 0.8414
 * -> 0.8381 (rotor 0.936 -> 0.886, pinion 0.770 -> 0.794); planes-bend
 * within 0.001 of before. It costs soupsign 1.4 times the user time with
 * planes on the armadillo's deleted faces at 256^3 (4.4 s -> 6.2 s; the
 * least-area caps 1.9 s). Not kept: apexes made of the soup's planes
 * only, each set of planes once per loop (a fan's plane taken as that of
 * the edge it continues; it stops a small loop taking up to 16 apexes a
 * rounding apart, each from the line of two planes nearest the loop's
 * moving centroid): rotor 0.886 -> 0.931, but fandisk 0.970 -> 0.944,
 * joint 0.751 -> 0.738, cheese deleted50 0.971 -> 0.959 (0.963 -> 0.938
 * with planes-bend), man onesided 0.775 -> 0.679.
 */
#include "holes_internal.h"
#include "fpenv.h"
#include "souptet/geom.h"
#include "souptet/isect.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* Apexes within the loop's box grown by REACH times its extent each way:
 * a lost corner lies near the loop's box (a box's lost corner at a corner
 * of it), a point where nearly parallel planes meet far beyond. Not kept:
 * that box cut to the kept soup's box (a lost corner lies within the
 * part's surviving extent). It removes the spike that pinion's large
 * holes send out a gear's length past its teeth, but the apexes the
 * loops take next are worse elsewhere (core IoU at 128^3, planes-bend:
 * pinion 0.803 -> 0.830, rotor 0.950 -> 0.879, joint 0.803 -> 0.782; the
 * soup's box grown by a tenth of its extent: rotor 0.950, joint 0.659). */
#define REACH 0.75
/* Planes whose offsets and normals differ by less than SAME (relative to
 * the loop's extent) are one face's (its triangles' rounding). */
#define SAME 1e-9
/* Triples of planes meeting at a point: |det| of their unit normals above
 * MIN_DET (three planes within about 6 degrees of a common line meet far
 * off or nowhere). */
#define MIN_DET 1e-2
/* The apexes from at most MAX_PLANES planes (MAX_PLANES^3 / 6 triples,
 * each cone measured over the loop): a curved face along the loop has a
 * plane on each edge; the planes along most of the loop are kept. */
#define MAX_PLANES 24

typedef struct plane {
    double n[3], d;     /* unit normal, n . x = d */
    double len;         /* the length of the loop edges on it */
} plane;

/* The cone from apex over the loop: its total bend, length times
 * dihedral over its edges (rim[i]: the unit normal of the soup's triangle
 * on loop edge i, which passes it the other way from the cone), and in
 * *rimb that over the loop's edges only; tn[3 n] is scratch. */
static double cone_bend(const double *apex, const double *const *pts, const double *rim,
                        size_t n, double *tn, double *rimb)
{
    double b = 0.0;
    for (size_t i = 0; i < n; i++) {
        const double *p = pts[i], *q = pts[(i + 1) % n];
        unit_normal(tn + 3 * i, p, q, apex);
        b += dist3(p, q) * bend(tn + 3 * i, rim + 3 * i);
    }
    *rimb = b;
    for (size_t i = 0; i < n; i++)
        b += dist3(apex, pts[(i + 1) % n]) * bend(tn + 3 * i, tn + 3 * ((i + 1) % n));
    return b;
}

/* Solves the 3x3 system rows . x = rhs (Cramer); 0 when |det| < MIN_DET
 * (unit rows). */
static int meet3(double *x, const plane *a, const plane *b, const plane *c)
{
    double bc[3], ca[3], ab[3];
    st_cross3(bc, b->n, c->n);
    st_cross3(ca, c->n, a->n);
    st_cross3(ab, a->n, b->n);
    const double det = st_dot3(a->n, bc);
    if (!(fabs(det) >= MIN_DET))
        return 0;
    for (int k = 0; k < 3; k++)
        x[k] = (a->d * bc[k] + b->d * ca[k] + c->d * ab[k]) / det;
    return 1;
}

/* The point of the line where a and b meet nearest o; 0 when they are
 * nearly parallel. */
static int meet2(double *x, const plane *a, const plane *b, const double *o)
{
    double t[3];
    st_cross3(t, a->n, b->n);
    const double tl = st_dot3(t, t);
    if (!(tl >= MIN_DET * MIN_DET))
        return 0;
    /* the third plane: through o, across the line */
    plane c;
    const double l = sqrt(tl);
    for (int k = 0; k < 3; k++)
        c.n[k] = t[k] / l;
    c.d = st_dot3(c.n, o);
    return meet3(x, a, b, &c);
}

/* The loop's box grown by REACH times its extent each way (lo, hi), its
 * centroid o and its extent. */
static void reach_box(double *lo, double *hi, double *o, double *ext, const double *const *pts,
                      size_t n)
{
    *ext = 0.0;
    for (int k = 0; k < 3; k++)
        lo[k] = hi[k] = pts[0][k], o[k] = 0.0;
    for (size_t i = 0; i < n; i++)
        for (int k = 0; k < 3; k++) {
            lo[k] = fmin(lo[k], pts[i][k]);
            hi[k] = fmax(hi[k], pts[i][k]);
            o[k] += pts[i][k] / (double)n;
        }
    for (int k = 0; k < 3; k++)
        *ext = fmax(*ext, hi[k] - lo[k]);
    for (int k = 0; k < 3; k++) {
        lo[k] -= REACH * *ext;
        hi[k] += REACH * *ext;
    }
}

/* The planes of the soup's triangles along the loop, once each (either
 * orientation), the MAX_PLANES with the most loop length on them first
 * (ties by order along the loop); rim[3 n] gets each loop edge's unit
 * normal. Returns how many (pl holds n). */
static size_t loop_planes(plane *pl, double *rim, const double *const *pts,
                          const double *const *side, size_t n, double ext)
{
    size_t m = 0;
    for (size_t i = 0; i < n; i++) {
        unit_normal(rim + 3 * i, pts[i], side[i], pts[(i + 1) % n]);
        const double *nn = rim + 3 * i;
        if (st_dot3(nn, nn) == 0.0)
            continue;
        const double d = st_dot3(nn, pts[i]), len = dist3(pts[i], pts[(i + 1) % n]);
        size_t j = 0;
        for (; j < m; j++) {
            const double sg = st_dot3(nn, pl[j].n) < 0.0 ? -1.0 : 1.0;
            double dn = 0.0;
            for (int k = 0; k < 3; k++)
                dn += fabs(sg * nn[k] - pl[j].n[k]);
            if (dn <= SAME && fabs(sg * d - pl[j].d) <= SAME * ext)
                break;
        }
        if (j < m) {
            pl[j].len += len;
            continue;
        }
        memcpy(pl[m].n, nn, sizeof pl[m].n);
        pl[m].d = d;
        pl[m].len = len;
        m++;
    }
    for (size_t i = 1; i < m; i++)      /* insertion sort */
        for (size_t j = i; j > 0 && pl[j].len > pl[j - 1].len; j--) {
            plane t = pl[j];
            pl[j] = pl[j - 1];
            pl[j - 1] = t;
        }
    return m > MAX_PLANES ? MAX_PLANES : m;
}

/* 1 when triangle (a, b, apex) pierces a kept triangle of guard's soup
 * (st_tri_tri_cross: touching it, along the loop or at a crease, is no
 * crossing). */
typedef struct cross_ctx {
    const st_holes_guard *g;
    const double *t[3];
} cross_ctx;

static int cross_visit(void *ctx, uint32_t tri)
{
    const cross_ctx *c = ctx;
    if (!c->g->kept[tri])
        return 0;
    const st_soup *s = c->g->bvh->soup;
    const uint32_t *v = s->tris + 3 * (size_t)tri;
    return st_tri_tri_cross(c->t[0], c->t[1], c->t[2], s->xyz + 3 * (size_t)v[0],
                            s->xyz + 3 * (size_t)v[1], s->xyz + 3 * (size_t)v[2]);
}

static int crosses(const st_holes_guard *g, const double *a, const double *b, const double *apex)
{
    if (!g || !g->bvh)
        return 0;
    cross_ctx c = {g, {a, b, apex}};
    return st_bvh_query_tri(g->bvh, a, b, apex, cross_visit, &c);
}

/* An apex tried: its point, the planes it is made of (indices into the
 * loop's planes), its score (key, then tie: least first) and whether it
 * was taken up. */
typedef struct cand {
    double x[3], key, tie;
    size_t a, b, c;
    int done;
} cand;

/* At most this many apexes per loop: triples and pairs of MAX_PLANES. */
#define MAX_CAND (MAX_PLANES * MAX_PLANES * MAX_PLANES / 6 + MAX_PLANES * MAX_PLANES)

/* The candidate not taken up yet of least (key, tie), the first of equal
 * ones; NULL when none is left. */
static cand *least_cand(cand *cs, size_t nc)
{
    cand *b = NULL;
    for (size_t i = 0; i < nc; i++)
        if (!cs[i].done &&
            (!b || cs[i].key < b->key || (cs[i].key == b->key && cs[i].tie < b->tie)))
            b = cs + i;
    return b;
}

/* The apex where planes a, b and c meet (c == b: the point of the line of
 * a and b nearest o), when they meet within [lo, hi]. */
static int candidate(double *x, const plane *pl, size_t a, size_t b, size_t c, const double *o,
                     const double *lo, const double *hi)
{
    if (!(c == b ? meet2(x, &pl[a], &pl[b], o) : meet3(x, &pl[a], &pl[b], &pl[c])))
        return 0;
    int inside = 1;
    for (int k = 0; k < 3; k++)
        inside &= x[k] >= lo[k] && x[k] <= hi[k];
    return inside;
}

st_status st_holes_planes_cap(st_soup *out, int *done, const double *const *pts,
                              const double *const *side, size_t n, double below,
                              const st_holes_guard *guard, double *bent, st_error *err)
{
    *done = 0;
    *bent = INFINITY;
    double *rim = malloc(3 * n * sizeof *rim), *tn = malloc(3 * n * sizeof *tn);
    plane *pl = malloc(n * sizeof *pl);
    cand *cs = malloc(MAX_CAND * sizeof *cs);
    st_status rc = ST_OK;
    if (!rim || !tn || !pl || !cs) {
        rc = st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory for the holes");
        goto out;
    }
    double lo[3], hi[3], o[3], ext;
    reach_box(lo, hi, o, &ext, pts, n);
    const size_t m = loop_planes(pl, rim, pts, side, n, ext);
    /* the cones that bend less than below, the least bent first (ties
     * by the bend of their spokes too): the first whose triangles pierce
     * none of the soup */
    size_t nc = 0;
    for (size_t a = 0; a < m; a++)
        for (size_t b = a + 1; b < m; b++)
            for (size_t c = b; c < m; c++) {    /* c == b: the line of a and b */
                cand *k = cs + nc;
                double rb;
                if (!candidate(k->x, pl, a, b, c, o, lo, hi))
                    continue;
                const double cb = cone_bend(k->x, pts, rim, n, tn, &rb);
                if (!(rb < below))
                    continue;
                k->key = rb, k->tie = cb, k->a = a, k->b = b, k->c = c, k->done = 0;
                nc++;
            }
    const cand *k = NULL;
    for (; (k = least_cand(cs, nc)) != NULL; cs[k - cs].done = 1) {
        size_t i = 0;
        while (i < n && !crosses(guard, pts[i], pts[(i + 1) % n], k->x))
            i++;
        if (i == n)
            break;
    }
    if (!k)
        goto out;
    const double best = k->key, *apex = k->x;
    const size_t base = out->nverts;
    for (size_t i = 0; i < n; i++)
        if ((rc = st_soup_add_vertex(out, pts[i][0], pts[i][1], pts[i][2], err)))
            goto out;
    if ((rc = st_soup_add_vertex(out, apex[0], apex[1], apex[2], err)))
        goto out;
    for (size_t i = 0; i < n; i++)
        if ((rc = st_soup_add_triangle(out, (uint32_t)(base + i), (uint32_t)(base + (i + 1) % n),
                                       (uint32_t)(base + n), err)))
            goto out;
    *done = 1;
    *bent = best;
out:
    free(rim), free(tn), free(pl), free(cs);
    return rc;
}

/* ---- several corners per loop: fans to the points where the planes meet */

/* An apex continues loop edge i when the triangle (p_i, p_i+1, apex) lies
 * in the plane of the soup's triangle there, on the hole's side: its bend
 * below FAN_FLAT radians. */
#define FAN_FLAT 1e-6
/* At most MAX_APEX apexes per loop. */
#define MAX_APEX 16

/* One vertex of a loop being capped: its point, the third point of the
 * triangle beyond its outgoing edge (the soup's or a fan's), and the
 * original loop edge that outgoing edge is (-1: a new one, to an apex). */
typedef struct fan_v {
    const double *p, *side;
    long orig;
} fan_v;

/* Which of the loop's edges apex continues (FAN_FLAT): flag[n]. Returns
 * their length. (Fanning only the longest run of them, when it spans two
 * planes: core IoU on the corpus's largeholes 0.842 -> 0.824, rotor
 * 0.936 -> 0.851; only the runs that span two planes: 0.828.) */
static double fan_flags(const double *apex, const fan_v *v, const double *rim, size_t n,
                        int *flag)
{
    double g = 0.0;
    for (size_t i = 0; i < n; i++) {
        double t[3];
        const double *a = v[i].p, *b = v[(i + 1) % n].p;
        unit_normal(t, a, b, apex);
        flag[i] = bend(t, rim + 3 * i) < FAN_FLAT;
        if (flag[i])
            g += dist3(a, b);
    }
    return g;
}

/* Unflags the edges whose fan from apex pierces guard's soup; returns
 * the length of those left. */
static double fans_uncross(const st_holes_guard *g, const double *apex, const fan_v *v, size_t n,
                           int *flag)
{
    double len = 0.0;
    for (size_t i = 0; i < n; i++)
        if (flag[i]) {
            if (crosses(g, v[i].p, v[(i + 1) % n].p, apex))
                flag[i] = 0;
            else
                len += dist3(v[i].p, v[(i + 1) % n].p);
        }
    return len;
}

typedef struct fan_out {
    const double **tri;     /* 3 points a triangle */
    long *orig;             /* per triangle edge: the original loop edge or -1 */
    size_t nt, cap;
} fan_out;

static int fan_push(fan_out *o, const double *a, const double *b, const double *c, long oa,
                    long ob, long oc)
{
    if (o->nt == o->cap) {
        size_t nc = o->cap ? 2 * o->cap : 64;
        const double **t = realloc(o->tri, 3 * nc * sizeof *t);
        if (!t)
            return -1;
        o->tri = t;
        long *g = realloc(o->orig, 3 * nc * sizeof *g);
        if (!g)
            return -1;
        o->orig = g;
        o->cap = nc;
    }
    o->tri[3 * o->nt] = a, o->tri[3 * o->nt + 1] = b, o->tri[3 * o->nt + 2] = c;
    o->orig[3 * o->nt] = oa, o->orig[3 * o->nt + 1] = ob, o->orig[3 * o->nt + 2] = oc;
    o->nt++;
    return 0;
}

st_status st_holes_planes_fans(st_soup *out, int *done, const double *const *pts,
                               const double *const *side, size_t n, double below,
                               st_holes_fill fill, const st_holes_guard *guard, double *bent,
                               st_error *err)
{
    *done = 0;
    *bent = INFINITY;
    const size_t maxv = n + 2 * MAX_APEX + 2;
    /* the loops still to cap, one after another in stk (each led by its
     * length), and the scratch of one */
    fan_v *stk = malloc(2 * maxv * (MAX_APEX + 2) * sizeof *stk), *cur = malloc(maxv * sizeof *cur),
          *nxt = malloc(2 * maxv * sizeof *nxt);
    size_t *lens = malloc(maxv * sizeof *lens);
    double *rim = malloc(3 * maxv * sizeof *rim);
    plane *pl = malloc(maxv * sizeof *pl);
    const double **lp = malloc(maxv * sizeof *lp), **ls = malloc(maxv * sizeof *ls);
    uint32_t *tri = malloc(3 * maxv * sizeof *tri);
    double (*apx)[3] = malloc(MAX_APEX * sizeof *apx);
    int *flag = malloc(maxv * sizeof *flag);
    cand *cs = malloc(MAX_CAND * sizeof *cs);
    fan_out fo = {NULL, NULL, 0, 0};
    st_status rc = ST_OK;
    if (!flag || !stk || !cur || !nxt || !lens || !rim || !pl || !lp || !ls || !tri || !apx || !cs)
        goto oom;
    double lo[3], hi[3], o0[3], ext;
    reach_box(lo, hi, o0, &ext, pts, n);
    size_t nloops = 1, napex = 0, top = 0;
    for (size_t i = 0; i < n; i++) {
        stk[i].p = pts[i];
        stk[i].side = side[i];
        stk[i].orig = (long)i;
    }
    lens[0] = n;
    top = n;
    while (nloops) {
        /* pop the last loop */
        const size_t m = lens[--nloops];
        top -= m;
        memcpy(cur, stk + top, m * sizeof *cur);
        if (m < 3)
            continue;
        double o[3] = {0, 0, 0};
        for (size_t i = 0; i < m; i++)
            for (int k = 0; k < 3; k++)
                o[k] += cur[i].p[k] / (double)m;
        for (size_t i = 0; i < m; i++) {
            lp[i] = cur[i].p;
            ls[i] = cur[i].side;
        }
        const size_t np = loop_planes(pl, rim, (const double *const *)lp,
                                      (const double *const *)ls, m, ext);
        /* the apexes by the length of the loop they continue, the most
         * first, each without the edges whose fans pierce the soup, until
         * none left could continue more */
        size_t nc = 0;
        if (napex < MAX_APEX)
            for (size_t a = 0; a < np; a++)
                for (size_t b = a + 1; b < np; b++)
                    for (size_t c = b; c < np; c++) {
                        cand *k = cs + nc;
                        if (!candidate(k->x, pl, a, b, c, o, lo, hi))
                            continue;
                        const double g = fan_flags(k->x, cur, rim, m, flag);
                        if (!(g > 0.0))
                            continue;
                        k->key = -g, k->tie = (double)nc, k->done = 0;
                        nc++;
                    }
        double best = 0.0, ax[3] = {0, 0, 0};
        for (cand *k; (k = least_cand(cs, nc)) != NULL && -k->key > best; k->done = 1) {
            fan_flags(k->x, cur, rim, m, flag);
            const double g = fans_uncross(guard, k->x, cur, m, flag);
            if (g > best) {
                best = g;
                memcpy(ax, k->x, sizeof ax);
            }
        }
        /* which edges the apex continues */
        size_t ncont = 0;
        if (best > 0.0) {
            fan_flags(ax, cur, rim, m, flag);
            fans_uncross(guard, ax, cur, m, flag);
            for (size_t i = 0; i < m; i++)
                ncont += (size_t)flag[i];
        }
        if (ncont < 2) {
            /* no apex: the loop's own triangulation */
            if (fill((const double *const *)lp, (const double *const *)ls, m, tri) < 0)
                goto oom;
            for (size_t t = 0; t + 2 < m; t++) {
                const uint32_t *c = tri + 3 * t;
                long og[3];
                for (int e = 0; e < 3; e++) {
                    const size_t u = c[e], w = c[(e + 1) % 3];
                    og[e] = (u + 1) % m == w ? cur[u].orig : (w + 1) % m == u ? cur[w].orig : -1;
                }
                if (fan_push(&fo, lp[c[0]], lp[c[1]], lp[c[2]], og[0], og[1], og[2]))
                    goto oom;
            }
            continue;
        }
        memcpy(apx[napex], ax, sizeof ax);
        const double *A = apx[napex++];
        /* start at an edge the apex does not continue (all: the cone) */
        size_t s0 = 0;
        while (s0 < m && flag[s0])
            s0++;
        /* the fans, and the loop with each run of continued edges replaced
         * by the apex */
        size_t k = 0;
        for (size_t r = 0; r < m; r++) {
            const size_t i = (s0 + r) % m;
            const fan_v *vi = cur + i, *vj = cur + (i + 1) % m;
            if (!flag[i]) {
                nxt[k++] = *vi;
                continue;
            }
            if (fan_push(&fo, vi->p, vj->p, A, vi->orig, -1, -1))
                goto oom;
            const int first = r == 0 || !flag[(i + m - 1) % m];
            const int last = r + 1 == m || !flag[(i + 1) % m];
            if (first && s0 < m) {      /* vi stays, its edge now to the apex */
                nxt[k].p = vi->p;
                nxt[k].side = vj->p;
                nxt[k].orig = -1;
                k++;
            }
            if (last) {
                nxt[k].p = A;
                nxt[k].side = vi->p;
                nxt[k].orig = -1;
                k++;
            }
        }
        if (s0 == m)
            continue;           /* a cone over the whole loop */
        /* split where the loop meets the apex more than once */
        size_t firstA = 0;
        while (nxt[firstA].p != A)
            firstA++;
        /* rotate so the loop starts at the apex, then cut before each
         * later occurrence of it */
        for (size_t i = 0; i < k; i++)
            nxt[k + i] = nxt[(firstA + i) % k];
        size_t st = k;
        for (size_t i = k + 1; i <= 2 * k; i++)
            if (i == 2 * k || nxt[i].p == A) {
                const size_t len = i - st;
                if (len >= 3) {
                    if (nloops == maxv || top + len > 2 * maxv * (MAX_APEX + 2))
                        goto out;   /* (never on a loop of this size) */
                    memcpy(stk + top, nxt + st, len * sizeof *stk);
                    top += len;
                    lens[nloops++] = len;
                }
                st = i;
            }
    }
    /* the caps' bend along the original loop */
    double rb = 0.0;
    for (size_t t = 0; t < fo.nt; t++) {
        double nt[3], nr[3];
        const double **c = fo.tri + 3 * t;
        unit_normal(nt, c[0], c[1], c[2]);
        for (int e = 0; e < 3; e++) {
            const long i = fo.orig[3 * t + e];
            if (i < 0)
                continue;
            unit_normal(nr, pts[i], side[i], pts[((size_t)i + 1) % n]);
            rb += dist3(pts[i], pts[((size_t)i + 1) % n]) * bend(nt, nr);
        }
    }
    if (napex == 0 || !(rb < below))
        goto out;
    for (size_t t = 0; t < fo.nt; t++) {
        const size_t base = out->nverts;
        for (int c = 0; c < 3; c++) {
            const double *q = fo.tri[3 * t + c];
            if ((rc = st_soup_add_vertex(out, q[0], q[1], q[2], err)))
                goto out;
        }
        if ((rc = st_soup_add_triangle(out, (uint32_t)base, (uint32_t)(base + 1),
                                       (uint32_t)(base + 2), err)))
            goto out;
    }
    *done = 1;
    *bent = rb;
    goto out;
oom:
    rc = st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory for the holes");
out:
    free(stk), free(cur), free(nxt), free(lens), free(rim), free(pl), free(lp), free(ls);
    free(tri), free(apx), free(fo.tri), free(fo.orig), free(flag), free(cs);
    return rc;
}
