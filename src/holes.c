/*
 * holes.c - caps for the holes of a soup (see holes.h).
 *
 *   1. the soup's edges and pieces on welded vertices (edges.h:
 *      degenerate and duplicated triangles left out);
 *   2. an edge of one triangle is a boundary edge; the pieces' areas are
 *      summed;
 *   3. pair the boundary edges at each vertex (where holes touch: by the
 *      angular gaps around it, or on a crease by the edges' hole sides)
 *      and walk them into loops;
 *   4. triangulate each loop by least area (O(n^3) in its n vertices)
 *      and keep the cap if it is small beside the pieces near the loop (a
 *      bounding volume hierarchy finds them); with bend, the cap is the
 *      triangulation that bends least instead (O(n^3) too).
 */
#include "souptet/holes.h"
#include "fpenv.h"
#include "holes_internal.h"
#include "souptet/geom.h"
#include "souptet/mem.h"
#include "souptet/bvh.h"
#include "souptet/edges.h"
#include "souptet/weld.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#define NONE UINT32_MAX
/* A cone from a rebuilt corner replaces the cap of the loop's own points
 * when its bend along the loop is below CONE_BETTER times the cap's: on
 * the corpus (issue 17) 0.999 rebuilds more of the large holes (core IoU
 * mean 0.822, worst 0.716) but costs deleted50 rotor 0.989 -> 0.940; 0.5
 * (0.819, 0.685) keeps it at 0.994; 0.25 rebuilds little (0.760). */
#define CONE_BETTER 0.5
#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

st_holes_params st_holes_params_default(void)
{
    /* 0.25: a hole's cap is at most a quarter of the surface around it (on
     * the corpus, holes of 3 rings of faces on models of 3 000 faces and
     * up: under 0.15); an open patch's own loop spans about its area. */
    /* History (the measurements that led here). planes on every soup:
     * rebuilt corners (a cone from one, or fans from several)
     * recover more of the large holes (core IoU at 128^3, mean / worst:
     * 0.743 / 0.584 -> 0.842 / 0.685; with bend 0.876 / 0.803; the cone
     * alone 0.819 / 0.685) and of the holes class (cheese 0.896 ->
     * 0.922), but lose on deleted faces and one-sided scans: deleted50
     * cheese 0.980 -> 0.925, pinion 0.999 -> 0.996, rotor 0.989 ->
     * 0.986; onesided cheese 0.845 -> 0.813, rotor 0.883 -> 0.871, anchor
     * 1.000 -> 0.995 (elephant onesided 0.801 -> 0.551 at CONE_BETTER
     * 0.999). A plane support bound does not make it the default: a
     * rebuilt corner's triangles on a face's plane at most k times the
     * area left of that face (the soup's triangles joined across edges
     * where they lie exactly in one plane, st_orient3d), largeholes 0.842
     * -> 0.784 (k 1), 0.821 (k 2; rotor 0.936 -> 0.829, fandisk 0.964 ->
     * 0.944), 0.831 (k 4), while deleted50 cheese 0.925 -> 0.945 (k 2; not
     * the 0.980 without planes, its loss is recall) and anchor 0.998 ->
     * 0.923 (0.911 without planes): on a CAD part's curved faces a face is
     * one facet, and a face that lost most of itself bears fans larger
     * than what is left of it. planes also costs soupsign 2.4 times the
     * user time on the armadillo's deleted faces at 256^3 (2.3 s -> 5.5 s;
     * its holes 1.4 s -> 1.5 s). With rebuilt corners that pierce the
     * soup rejected (holes_planes.c) it is closer but still not the
     * default: class means deleted50 0.9945, holes 0.9837, onesided
     * 0.8461, largeholes 0.838, but deleted50 cheese 0.971 (0.980
     * without planes), onesided cheese 0.879 (0.905), and 3.2 times the
     * user time on the armadillo's deleted faces (1.9 s -> 6.2 s). */
    /* bend on every soup: the caps that bend least recover more
     * of a CAD part's large holes (issue 17, the corpus's largeholes:
     * core IoU 0.743 -> 0.829) and of its small ones, but extend a face's
     * plane across a lost concave corner and continue a one-sided scan's
     * walls past its far side (deleted50 joint 0.974 -> 0.895, onesided
     * rotor 0.883 -> 0.754). */
    /* bend and planes where the soup is intact (issue 17): the rim at
     * most half the soup's area and not one-sided along an axis below
     * 0.02. On the corpus the rim reads 0.76-0.87 where faces were deleted
     * at random and 0.003-0.15 for the holes, large holes and one-sided
     * scans; along an axis the one-sided scans read 0.000 and every other
     * soup with holes 0.39 and up. Core IoU at 128^3 against the least-area
     * caps everywhere (mean / worst): large holes 0.743 / 0.584 -> 0.875 /
     * 0.803, holes 0.978 / 0.896 -> 0.986 / 0.920, every other class the
     * same to four digits; planes-bend on every soup instead: deleted50
     * joint 0.974 -> 0.895, onesided joint 1.000 -> 0.899. */
    st_holes_params p = {0.25, 256, 0.01, 1, 1, 0.5, 0.02};
    return p;
}

static double tri_area(const double *a, const double *b, const double *c)
{
    double u[3], v[3], n[3];
    st_sub3(u, b, a);
    st_sub3(v, c, a);
    st_cross3(n, u, v);
    return 0.5 * st_norm3(n);
}

/* The triangles of a polygon triangulation chosen by dynamic programming:
 * best[i n + j] is the apex over the edge (i, j); tri[3 (n - 2)] gets them
 * with local indices, from the edge (0, n - 1) down (stack holds 2 n). */
static void emit_triangles(const uint16_t *best, size_t n, size_t *stack, uint32_t *tri)
{
    size_t top = 0, nt = 0;
    stack[top++] = 0;
    stack[top++] = n - 1;
    while (top) {
        const size_t j = stack[--top], i = stack[--top];
        if (j - i < 2)
            continue;
        const size_t k = best[i * n + j];
        tri[3 * nt] = (uint32_t)i;
        tri[3 * nt + 1] = (uint32_t)k;
        tri[3 * nt + 2] = (uint32_t)j;
        nt++;
        stack[top++] = i;
        stack[top++] = k;
        stack[top++] = k;
        stack[top++] = j;
    }
}

/* The least-area triangulation of the polygon pts[0..n) (n >= 3): fills
 * tri[3 (n - 2)] with local indices and returns its area; -1 when out of
 * memory. */
static double least_area(const double *const *pts, size_t n, uint32_t *tri)
{
    double *w = malloc(n * n * sizeof *w);
    uint16_t *best = malloc(n * n * sizeof *best);
    size_t *stack = malloc(2 * n * sizeof *stack);
    if (!w || !best || !stack) {
        free(w);
        free(best);
        free(stack);
        return -1.0;
    }
    for (size_t i = 0; i + 1 < n; i++)
        w[i * n + i + 1] = 0.0;
    for (size_t len = 2; len < n; len++)
        for (size_t i = 0; i + len < n; i++) {
            const size_t j = i + len;
            double m = INFINITY;
            size_t mk = i + 1;
            for (size_t k = i + 1; k < j; k++) {
                double c = w[i * n + k] + w[k * n + j] + tri_area(pts[i], pts[k], pts[j]);
                if (c < m) {        /* ties keep the first k */
                    m = c;
                    mk = k;
                }
            }
            w[i * n + j] = m;
            best[i * n + j] = (uint16_t)mk;
        }
    const double area = w[n - 1];
    emit_triangles(best, n, stack, tri);
    free(w);
    free(best);
    free(stack);
    return area;
}

/* The triangulation of the polygon pts[0..n) (n >= 3) on its own vertices
 * that bends least: the sum over its edges of length times bend (bend()),
 * the discrete total mean curvature, is least; ties by area. The edges
 * are the cap's inner edges and the loop's own, where the cap meets the
 * soup's triangle across it (side[i]: that triangle's third vertex, on
 * edge pts[i] -> pts[i + 1 mod n]); the soup's triangles orient the bends,
 * not the soup: each is read as passing its loop edge the other way from
 * the cap. Dynamic programming as for least_area: the bend across the
 * diagonal (i, k) is taken with the triangle the best triangulation of
 * (i, k) puts on it (Liepa 2003, "Filling holes in meshes", who takes the
 * largest bend; the sum is what a missing face with a crease inside the
 * loop needs: a wall across it would bend along all its length). A
 * missing planar face bends only along its rim, a cylindrical or conical
 * one (ruled between two rims of the loop) only by its facets' small
 * angles; the least-area cap cuts straight across a curved face and,
 * where the loop runs over several faces of a part, folds through its
 * solid. Fills tri[3 (n - 2)] and returns the cap's area; -1 when out of
 * memory. */
static double least_bend(const double *const *pts, const double *const *side, size_t n,
                         uint32_t *tri)
{
    double *ang = malloc(n * n * sizeof *ang), *w = malloc(n * n * sizeof *w);
    double *nrm = malloc(3 * n * n * sizeof *nrm);
    uint16_t *best = malloc(n * n * sizeof *best);
    size_t *stack = malloc(2 * n * sizeof *stack);
    if (!ang || !w || !nrm || !best || !stack) {
        free(ang), free(w), free(nrm), free(best), free(stack);
        return -1.0;
    }
    /* (i, i + 1): the soup's triangle across the edge, passed i -> c -> i+1;
     * (i, j) above: the triangle (i, k, j) of its best triangulation */
    for (size_t i = 0; i + 1 < n; i++) {
        ang[i * n + i + 1] = 0.0;
        w[i * n + i + 1] = 0.0;
        unit_normal(nrm + 3 * (i * n + i + 1), pts[i], side[i], pts[i + 1]);
    }
    double last[3];     /* the soup's triangle on the closing edge, 0 -> n-1 -> c */
    unit_normal(last, pts[0], pts[n - 1], side[n - 1]);
    for (size_t len = 2; len < n; len++)
        for (size_t i = 0; i + len < n; i++) {
            const size_t j = i + len;
            double ba = INFINITY, bw = INFINITY, bn[3] = {0, 0, 0};     /* bend, area, normal */
            size_t mk = i + 1;
            for (size_t k = i + 1; k < j; k++) {
                double t[3];
                unit_normal(t, pts[i], pts[k], pts[j]);
                double a = ang[i * n + k] + ang[k * n + j];
                a += dist3(pts[i], pts[k]) * bend(t, nrm + 3 * (i * n + k));
                a += dist3(pts[k], pts[j]) * bend(t, nrm + 3 * (k * n + j));
                if (j - i == n - 1)     /* the closing edge, passed n-1 -> 0 */
                    a += dist3(pts[0], pts[n - 1]) * bend(t, last);
                const double c = w[i * n + k] + w[k * n + j] + tri_area(pts[i], pts[k], pts[j]);
                if (a < ba || (a == ba && c < bw)) {    /* ties keep the first k */
                    ba = a;
                    bw = c;
                    mk = k;
                    memcpy(bn, t, sizeof t);
                }
            }
            ang[i * n + j] = ba;
            w[i * n + j] = bw;
            best[i * n + j] = (uint16_t)mk;
            memcpy(nrm + 3 * (i * n + j), bn, sizeof bn);
        }
    const double area = w[n - 1];
    emit_triangles(best, n, stack, tri);
    free(ang), free(w), free(nrm), free(best), free(stack);
    return area;
}

/* least_area and least_bend as st_holes_fill (holes_internal.h) */
static double fill_area(const double *const *pts, const double *const *side, size_t n,
                        uint32_t *tri)
{
    (void)side;
    return least_area(pts, n, tri);
}

static double fill_bend(const double *const *pts, const double *const *side, size_t n,
                        uint32_t *tri)
{
    return least_bend(pts, side, n, tri);
}

/* The bend along the loop of the cap tri[3 (n - 2)] (local indices, as
 * least_bend's): the sum over the loop's edges of length times the
 * dihedral between the cap's triangle on it and the soup's. */
static double rim_bend(const double *const *pts, const double *const *side, size_t n,
                       const uint32_t *tri)
{
    double b = 0.0;
    for (size_t t = 0; t + 2 < n; t++) {
        const uint32_t *c = tri + 3 * t;
        double nt[3], nr[3];
        unit_normal(nt, pts[c[0]], pts[c[1]], pts[c[2]]);
        for (int e = 0; e < 3; e++) {
            const size_t a = c[e], z = c[(e + 1) % 3];
            if ((a + 1) % n != z && (z + 1) % n != a)
                continue;
            /* the loop edge from i to i + 1 mod n */
            const size_t i = (a + 1) % n == z ? a : z;
            unit_normal(nr, pts[i], side[i], pts[(i + 1) % n]);
            b += dist3(pts[a], pts[z]) * bend(nt, nr);
        }
    }
    return b;
}

typedef struct around_ctx {
    const uint8_t *kept;
    const uint32_t *piece;
    uint32_t *stamp;
    uint32_t mark;
    const double *piece_area;
    double around;
} around_ctx;

/* A flat hole (any size): the loop lies within flat times its extent of
 * the plane of its Newell normal, and the triangles along it that lie in
 * that plane (normals within about 8 degrees of it) are mostly outside the
 * loop, as around a face that is missing, not inside it, as along the rim
 * of a flat sheet. A CAD part that lost a face: its cap is the face. */
static int flat_hole(const st_soup *s, const double *const *pts, size_t n, const uint32_t *be_t,
                     const uint32_t *loop_e, double flat)
{
    if (!(flat > 0.0))
        return 0;
    double nn[3] = {0, 0, 0}, c[3] = {0, 0, 0}, lo[3], hi[3];
    for (int q = 0; q < 3; q++)
        lo[q] = hi[q] = pts[0][q];
    for (size_t i = 0; i < n; i++) {
        const double *a = pts[i], *b = pts[(i + 1) % n];
        nn[0] += (a[1] - b[1]) * (a[2] + b[2]);
        nn[1] += (a[2] - b[2]) * (a[0] + b[0]);
        nn[2] += (a[0] - b[0]) * (a[1] + b[1]);
        for (int q = 0; q < 3; q++) {
            c[q] += a[q] / (double)n;
            lo[q] = fmin(lo[q], a[q]);
            hi[q] = fmax(hi[q], a[q]);
        }
    }
    const double len = sqrt(nn[0] * nn[0] + nn[1] * nn[1] + nn[2] * nn[2]);
    double ext = 0.0;
    for (int q = 0; q < 3; q++)
        ext = fmax(ext, hi[q] - lo[q]);
    if (!(len > 0.0) || !(ext > 0.0))
        return 0;
    for (int q = 0; q < 3; q++)
        nn[q] /= len;
    for (size_t i = 0; i < n; i++) {
        const double d = (pts[i][0] - c[0]) * nn[0] + (pts[i][1] - c[1]) * nn[1] +
                         (pts[i][2] - c[2]) * nn[2];
        if (fabs(d) > flat * ext)
            return 0;
    }
    size_t inner = 0, outer = 0;
    for (size_t i = 0; i < n; i++) {
        const double *a = pts[i], *b = pts[(i + 1) % n];
        const uint32_t *tv = s->tris + 3 * (size_t)be_t[loop_e[i]];
        const double *P = s->xyz + 3 * (size_t)tv[0], *Q = s->xyz + 3 * (size_t)tv[1],
                     *R = s->xyz + 3 * (size_t)tv[2];
        double u[3], w[3], tn[3];
        for (int q = 0; q < 3; q++) {
            u[q] = Q[q] - P[q];
            w[q] = R[q] - P[q];
        }
        tn[0] = u[1] * w[2] - u[2] * w[1];
        tn[1] = u[2] * w[0] - u[0] * w[2];
        tn[2] = u[0] * w[1] - u[1] * w[0];
        const double tl = sqrt(tn[0] * tn[0] + tn[1] * tn[1] + tn[2] * tn[2]);
        if (!(tl > 0.0) || fabs(tn[0] * nn[0] + tn[1] * nn[1] + tn[2] * nn[2]) < 0.99 * tl)
            continue;
        /* the triangle's centroid: left of a -> b is inside the loop */
        double e[3], m[3], x[3];
        for (int q = 0; q < 3; q++) {
            e[q] = b[q] - a[q];
            m[q] = (P[q] + Q[q] + R[q]) / 3.0 - a[q];
        }
        x[0] = e[1] * m[2] - e[2] * m[1];
        x[1] = e[2] * m[0] - e[0] * m[2];
        x[2] = e[0] * m[1] - e[1] * m[0];
        if (x[0] * nn[0] + x[1] * nn[1] + x[2] * nn[2] > 0.0)
            inner++;
        else
            outer++;
    }
    return inner * 2 <= outer;
}

static int add_piece(void *vc, uint32_t t)
{
    around_ctx *c = vc;
    if (!c->kept[t])
        return 0;
    const uint32_t r = c->piece[t];
    if (c->stamp[r] != c->mark) {
        c->stamp[r] = c->mark;
        c->around += c->piece_area[r];
    }
    return 0;
}

/* Edge e's partner at its end v is `other`. */
static void set_partner(const uint32_t *be_a, uint32_t *pa, uint32_t *pb, uint32_t e,
                        uint32_t v, uint32_t other)
{
    if (be_a[e] == v)
        pa[e] = other;
    else
        pb[e] = other;
}

/* Is angle a (radians) strictly inside one of the sectors [lo, hi]? */
static int covered(const double *lo, const double *hi, size_t n, double a)
{
    for (size_t i = 0; i < n; i++)
        for (int w = -1; w <= 1; w++) {
            const double b = a + 2.0 * M_PI * w;
            if (b > lo[i] && b < hi[i])
                return 1;
        }
    return 0;
}

/* Where one plane does not order the triangles around v (a crease): each
 * boundary edge e at v has a direction d (from v along it) and a hole side
 * h (in the plane of e's triangle, perpendicular to e, away from the
 * triangle: where the missing triangles were). Two edges bound the same
 * gap when each lies on the other's hole side: the score dot(h1, d2) +
 * dot(h2, d1) is high (2 for two edges of a flat gap of 90 degrees, 0 for a
 * gap folded by a right-angled crease, -2 for two edges of one fan's ends
 * seen from inside it). Pairs are taken best score first (ties by position
 * in ev), never two edges of one triangle nor a pair scoring -1 or less
 * (each edge then lies more in the other's triangle than in its hole);
 * only a matching that pairs every edge is kept, else the edges stay
 * unpaired and their loops open. hit[] (k bytes) is scratch. */
static void pair_by_sides(const st_soup *s, const uint32_t *weld, const uint32_t *wpos,
                          const uint32_t *be_a, const uint32_t *be_b, const uint32_t *be_t,
                          uint32_t *pa, uint32_t *pb, uint32_t v, const uint32_t *ev, size_t k,
                          uint8_t *hit)
{
    enum { MAXK = 32 };
    if (k > MAXK)
        return;
    const double *o = s->xyz + 3 * (size_t)wpos[v];
    double d[MAXK][3], h[MAXK][3];
    for (size_t i = 0; i < k; i++) {
        const uint32_t e = ev[i], w = be_a[e] == v ? be_b[e] : be_a[e];
        const uint32_t *c = s->tris + 3 * (size_t)be_t[e];
        const double *third = NULL;
        for (int q = 0; q < 3; q++)
            if (weld[c[q]] != v && weld[c[q]] != w)
                third = s->xyz + 3 * (size_t)c[q];
        double t[3];
        st_sub3(d[i], s->xyz + 3 * (size_t)wpos[w], o);
        st_sub3(t, third, o);
        const double dd = st_dot3(d[i], d[i]), td = st_dot3(t, d[i]);
        for (int q = 0; q < 3; q++)     /* minus t's part across e, away from it */
            h[i][q] = -(t[q] - td / dd * d[i][q]);
        const double ld = sqrt(dd), lh = st_norm3(h[i]);
        if (!(ld > 0) || !(lh > 0))
            return;
        for (int q = 0; q < 3; q++) {
            d[i][q] /= ld;
            h[i][q] /= lh;
        }
    }
    uint32_t mate[MAXK];
    memset(hit, 0, k);
    for (size_t round = 0; round < k / 2; round++) {
        double best = -1.0;
        size_t bi = k, bj = k;
        for (size_t i = 0; i < k; i++)
            for (size_t j = i + 1; j < k; j++) {
                if (hit[i] || hit[j] || be_t[ev[i]] == be_t[ev[j]])
                    continue;
                const double sc = st_dot3(h[i], d[j]) + st_dot3(h[j], d[i]);
                if (sc > best) {
                    best = sc;
                    bi = i;
                    bj = j;
                }
            }
        if (bi == k)
            return;             /* an edge without a partner: all stay open */
        hit[bi] = hit[bj] = 1;
        mate[bi] = (uint32_t)bj;
        mate[bj] = (uint32_t)bi;
    }
    for (size_t i = 0; i < k; i++)
        set_partner(be_a, pa, pb, ev[i], v, ev[mate[i]]);
}

/* How one-sided along an axis the kept triangles of s are: for each axis,
 * each orientable region (triangles oriented to agree across every edge of
 * exactly two, breadth first; a conflict is left where it is found) turned
 * the way it faces most, the projected area facing the other way over that
 * facing it, summed over the regions; the least over the three axes. 0
 * for a scan seen from one side along an axis (its faces facing away were
 * never seen), near 1 for a closed part with holes in it. -1 when out of
 * memory. */
static double axis_one_sided(const st_soup *s, const st_soup_edges *E)
{
    const size_t nt = s->ntris;
    uint32_t *nbr = st_malloc_array(3 * nt + 1, sizeof *nbr);
    uint8_t *same = st_malloc_array(3 * nt + 1, 1);
    uint8_t *flip = st_malloc_array(nt + 1, 1);
    uint32_t *queue = st_malloc_array(nt + 1, sizeof *queue);
    uint32_t *region = st_malloc_array(nt + 1, sizeof *region);
    double ratio = -1.0;
    if (!nbr || !same || !flip || !queue || !region)
        goto done;
    st_soup_edges_neighbours(E, s, nbr, same, NULL);
    size_t nq = 0;
    st_soup_edges_orient(E, s, nbr, same, flip, region, queue, &nq);
    double back[3] = {0.0, 0.0, 0.0}, front[3] = {0.0, 0.0, 0.0};
    double pos[3] = {0.0, 0.0, 0.0}, neg[3] = {0.0, 0.0, 0.0};
    for (size_t i = 0; i < nq; i++) {   /* region by region */
        const uint32_t t = queue[i];
        const uint32_t *v = s->tris + 3 * (size_t)t;
        double u[3], w[3], n[3];
        st_sub3(u, s->xyz + 3 * (size_t)v[1], s->xyz + 3 * (size_t)v[0]);
        st_sub3(w, s->xyz + 3 * (size_t)v[2], s->xyz + 3 * (size_t)v[0]);
        st_cross3(n, u, w);
        for (int k = 0; k < 3; k++) {
            const double a = flip[t] ? -n[k] : n[k];
            if (a > 0.0)
                pos[k] += a;
            else
                neg[k] -= a;
        }
        if (i + 1 == nq || region[queue[i + 1]] != region[t])
            for (int k = 0; k < 3; k++) {
                back[k] += fmin(pos[k], neg[k]);
                front[k] += fmax(pos[k], neg[k]);
                pos[k] = neg[k] = 0.0;
            }
    }
    ratio = INFINITY;
    for (int k = 0; k < 3; k++)
        if (front[k] > 0.0)
            ratio = fmin(ratio, back[k] / front[k]);
done:
    free(nbr);
    free(same);
    free(flip);
    free(queue);
    free(region);
    return ratio;
}

/* The k (even, > 2) boundary edges ev at welded vertex v, where holes
 * touch: seen along the mean normal of the triangles around v (their
 * normals' signs aligned with the first: orientation is not read), the
 * triangles cover sectors of directions; a hole passes through v in each
 * gap between two consecutive boundary edges that no triangle covers, and
 * pairs those two edges. Pairs only when the gaps account for every edge
 * exactly once; otherwise (a vertex on a sharp crease, where one plane
 * does not order the fans) the edges are paired by their hole sides
 * (pair_by_sides) or stay unpaired. Returns -1 when out of memory. */
static int pair_by_angle(const st_soup *s, const uint32_t *weld, const uint32_t *wpos,
                         const uint32_t *be_a, const uint32_t *be_b, uint32_t *pa, uint32_t *pb,
                         uint32_t v, const uint32_t *ev, size_t k, const uint32_t *tv, size_t nt,
                         const uint32_t *be_t)
{
    const double *o = s->xyz + 3 * (size_t)wpos[v];
    double nsum[3] = {0, 0, 0}, first[3] = {0, 0, 0};
    for (size_t i = 0; i < nt; i++) {
        const uint32_t *c = s->tris + 3 * (size_t)tv[i];
        double u[3], w[3], n[3];
        st_sub3(u, s->xyz + 3 * (size_t)c[1], s->xyz + 3 * (size_t)c[0]);
        st_sub3(w, s->xyz + 3 * (size_t)c[2], s->xyz + 3 * (size_t)c[0]);
        st_cross3(n, u, w);
        if (i == 0)
            memcpy(first, n, sizeof n);
        const double sg = st_dot3(n, first) >= 0 ? 1.0 : -1.0;
        for (int q = 0; q < 3; q++)
            nsum[q] += sg * n[q];
    }
    const double len = st_norm3(nsum);
    if (!(len > 0))
        return 0;
    double nn[3] = {nsum[0] / len, nsum[1] / len, nsum[2] / len}, ax[3] = {1, 0, 0}, U[3], W[3];
    if (fabs(nn[0]) > 0.9)
        ax[0] = 0, ax[1] = 1;
    st_cross3(U, nn, ax);
    const double lu = st_norm3(U);
    for (int q = 0; q < 3; q++)
        U[q] /= lu;
    st_cross3(W, nn, U);
    double *lo = malloc((nt + 1) * sizeof *lo), *hi = malloc((nt + 1) * sizeof *hi);
    double *ang = malloc(k * sizeof *ang);
    uint32_t *ord = malloc(k * sizeof *ord);
    uint8_t *hit = calloc(k, 1);
    if (!lo || !hi || !ang || !ord || !hit) {
        free(lo), free(hi), free(ang), free(ord), free(hit);
        return -1;
    }
#define ANGLE(p) atan2(((p)[0] - o[0]) * W[0] + ((p)[1] - o[1]) * W[1] + ((p)[2] - o[2]) * W[2], \
                       ((p)[0] - o[0]) * U[0] + ((p)[1] - o[1]) * U[1] + ((p)[2] - o[2]) * U[2])
    for (size_t i = 0; i < nt; i++) {
        const uint32_t *c = s->tris + 3 * (size_t)tv[i];
        double a[2];
        int m = 0;
        for (int q = 0; q < 3 && m < 2; q++)
            if (weld[c[q]] != v)
                a[m++] = ANGLE(s->xyz + 3 * (size_t)c[q]);
        double l = fmin(a[0], a[1]), h = fmax(a[0], a[1]);
        if (h - l > M_PI) {     /* the short way round passes +-pi */
            const double t = l + 2.0 * M_PI;
            l = h;
            h = t;
        }
        lo[i] = l;
        hi[i] = h;
    }
    for (size_t i = 0; i < k; i++) {
        const uint32_t e = ev[i], w = be_a[e] == v ? be_b[e] : be_a[e];
        ang[i] = ANGLE(s->xyz + 3 * (size_t)wpos[w]);
        ord[i] = (uint32_t)i;
    }
#undef ANGLE
    for (size_t i = 1; i < k; i++)      /* insertion sort by angle, k small */
        for (size_t j = i; j > 0 && ang[ord[j]] < ang[ord[j - 1]]; j--) {
            uint32_t x = ord[j];
            ord[j] = ord[j - 1];
            ord[j - 1] = x;
        }
    size_t gaps = 0;
    int ok = 1;
    for (size_t i = 0; i < k && ok; i++) {
        const size_t j = (i + 1) % k;
        const double a = ang[ord[i]], b = ang[ord[j]] + (j == 0 ? 2.0 * M_PI : 0.0);
        if (covered(lo, hi, nt, 0.5 * (a + b)))
            continue;
        if (hit[ord[i]] || hit[ord[j]])
            ok = 0;
        hit[ord[i]] = hit[ord[j]] = 1;
        gaps++;
    }
    if (ok && 2 * gaps == k)
        for (size_t i = 0; i < k; i++) {
            const size_t j = (i + 1) % k;
            const double a = ang[ord[i]], b = ang[ord[j]] + (j == 0 ? 2.0 * M_PI : 0.0);
            if (!covered(lo, hi, nt, 0.5 * (a + b))) {
                set_partner(be_a, pa, pb, ev[ord[i]], v, ev[ord[j]]);
                set_partner(be_a, pa, pb, ev[ord[j]], v, ev[ord[i]]);
            }
        }
    else
        pair_by_sides(s, weld, wpos, be_a, be_b, be_t, pa, pb, v, ev, k, hit);
    (void)be_b;
    free(lo), free(hi), free(ang), free(ord), free(hit);
    return 0;
}

st_status st_soup_hole_caps(st_soup **caps, const st_soup *s,
                            const st_holes_params *p, st_holes_stats *stats,
                            st_error *err)
{
    return st_soup_hole_caps_shared(caps, s, NULL, NULL, p, stats, err);
}

st_status st_soup_hole_caps_shared(st_soup **caps, const st_soup *s,
                                   const st_soup_edges *edges, const st_bvh *shared_bvh,
                                   const st_holes_params *p, st_holes_stats *stats,
                                   st_error *err)
{
    st_holes_stats st0;
    memset(&st0, 0, sizeof st0);
    *caps = NULL;
    if (s->ntris > (size_t)INT32_MAX)
        return st_error_set(err, ST_ELIMIT, NULL, 0,
                            "%zu triangles: hole filling handles at most 2^31", s->ntris);
    if (p->max_loop > 4096 || !(p->max_cap_ratio >= 0))
        return st_error_set(err, ST_EINPUT, NULL, 0,
                            "hole filling: loops of at most 4096 edges, a cap ratio >= 0");
    const size_t nt = s->ntris;
    st_status rc = ST_ENOMEM;
    st_soup_edges own_edges;
    const st_soup_edges *Ep = edges;
    if (!Ep) {
        if ((rc = st_soup_edges_build(&own_edges, s, err)))
            return rc;
        Ep = &own_edges;
    }
    rc = ST_ENOMEM;
    const uint32_t *weld = Ep->weld, *piece = Ep->piece;
    const uint8_t *kept = Ep->kept;
    const st_half_edge *he = Ep->he;
    const size_t nh = Ep->nhalf, nw = Ep->nweld;
    st_soup *out = st_soup_new();
    double *piece_area = st_calloc_array(nt ? nt : 1, sizeof *piece_area);
    uint32_t *stamp = NULL, *be_a = NULL, *be_b = NULL, *be_t = NULL,
             *loop_v = NULL, *loop_e = NULL, *tri = NULL;
    uint8_t *used = NULL;
    uint32_t *pa = NULL, *pb = NULL, *bdeg = NULL, *vstart = NULL, *vlist = NULL,
             *tstart = NULL, *tlist = NULL, *wpos = NULL;
    const double **pts = NULL, **side = NULL;
    st_bvh *own_bvh = NULL;
    const st_bvh *bvh = shared_bvh;
    if (!out || !piece_area)
        goto done;
    if (!bvh && (rc = st_bvh_build(&own_bvh, s, err)))
        goto fail;
    bvh = bvh ? bvh : own_bvh;
    rc = ST_ENOMEM;

    /* the pieces' areas and the boundary edges */
    double total = 0.0;
    for (size_t t = 0; t < nt; t++)
        if (kept[t]) {
            const uint32_t *v = s->tris + 3 * t;
            const double a = tri_area(s->xyz + 3 * (size_t)v[0], s->xyz + 3 * (size_t)v[1],
                                      s->xyz + 3 * (size_t)v[2]);
            piece_area[piece[t]] += a;
            total += a;
        }
    size_t nb = 0;
    for (size_t i = 0, j; i < nh; i = j) {
        for (j = i + 1; j < nh && he[j].key == he[i].key; j++)
            ;
        nb += j - i == 1;
    }
    st0.boundary_edges = nb;
    be_a = st_malloc_array(nb ? nb : 1, sizeof *be_a);
    be_b = st_malloc_array(nb ? nb : 1, sizeof *be_b);
    be_t = st_malloc_array(nb ? nb : 1, sizeof *be_t);
    used = st_calloc_array(nb ? nb : 1, 1);
    stamp = st_malloc_array(nt ? nt : 1, sizeof *stamp);
    loop_v = st_malloc_array(nb + 1, sizeof *loop_v);
    loop_e = st_malloc_array(nb + 1, sizeof *loop_e);
    tri = st_malloc_array(3 * (p->max_loop + 1), sizeof *tri);
    pts = st_malloc_array(p->max_loop + 1, sizeof *pts);
    side = st_malloc_array(p->max_loop + 1, sizeof *side);
    pa = st_malloc_array(nb ? nb : 1, sizeof *pa);
    pb = st_malloc_array(nb ? nb : 1, sizeof *pb);
    bdeg = st_calloc_array((size_t)nw + 1, sizeof *bdeg);
    vstart = st_calloc_array((size_t)nw + 2, sizeof *vstart);
    vlist = st_malloc_array(2 * nb + 1, sizeof *vlist);
    tstart = st_calloc_array((size_t)nw + 2, sizeof *tstart);
    wpos = st_malloc_array((size_t)nw + 1, sizeof *wpos);
    if (!be_a || !be_b || !be_t || !used || !stamp || !loop_v || !loop_e || !tri || !pts || !side ||
        !pa || !pb || !bdeg || !vstart || !vlist || !tstart || !wpos)
        goto done;
    for (size_t t = 0; t < nt; t++)
        stamp[t] = NONE;
    size_t e = 0;
    for (size_t i = 0, j; i < nh; i = j) {
        for (j = i + 1; j < nh && he[j].key == he[i].key; j++)
            ;
        if (j - i != 1)
            continue;
        const uint32_t a = (uint32_t)(he[i].key >> 32), b = (uint32_t)he[i].key;
        be_a[e] = a;
        be_b[e] = b;
        be_t[e] = he[i].t;
        pa[e] = pb[e] = NONE;
        bdeg[a]++;
        bdeg[b]++;
        e++;
    }
    /* The boundary edges at each vertex, and a position for each welded
     * vertex (the first soup vertex welded to it). */
    for (size_t v = 0; v < (size_t)nw; v++)
        vstart[v + 1] = vstart[v] + bdeg[v];
    for (size_t v = 0; v < (size_t)nw; v++)
        bdeg[v] = 0;
    for (size_t i = 0; i < nb; i++) {
        vlist[vstart[be_a[i]] + bdeg[be_a[i]]++] = (uint32_t)i;
        vlist[vstart[be_b[i]] + bdeg[be_b[i]]++] = (uint32_t)i;
    }
    for (size_t v = s->nverts; v-- > 0;)
        if (weld[v] != ST_WELD_NONE)
            wpos[weld[v]] = (uint32_t)v;
    /* The kept triangles at each vertex where holes touch. */
    for (size_t t = 0; t < nt; t++)
        if (kept[t])
            for (int c = 0; c < 3; c++) {
                const uint32_t w = weld[s->tris[3 * t + c]];
                if (bdeg[w] > 2)
                    tstart[w + 1]++;
            }
    for (size_t v = 0; v < (size_t)nw; v++)
        tstart[v + 1] += tstart[v];
    tlist = st_malloc_array(tstart[nw] + 1, sizeof *tlist);
    if (!tlist)
        goto done;
    size_t *tfill = st_calloc_array((size_t)nw + 1, sizeof *tfill);
    if (!tfill)
        goto done;
    for (size_t t = 0; t < nt; t++)
        if (kept[t])
            for (int c = 0; c < 3; c++) {
                const uint32_t w = weld[s->tris[3 * t + c]];
                if (vstart[w + 1] - vstart[w] > 2)
                    tlist[tstart[w] + tfill[w]++] = (uint32_t)t;
            }
    free(tfill);
    /* The rim: the kept triangles on a boundary edge. Where it is more
     * than p->intact of the soup's area (faces deleted at random: most of
     * what is left touches a hole), the fragments' planes and bends say
     * little about the lost surface, and every cap is the least-area one. */
    double rim = 0.0;
    for (size_t i = 0; i < nb; i++) {
        const uint32_t t = be_t[i];
        if (stamp[t] == NONE) {
            const uint32_t *v = s->tris + 3 * (size_t)t;
            rim += tri_area(s->xyz + 3 * (size_t)v[0], s->xyz + 3 * (size_t)v[1],
                            s->xyz + 3 * (size_t)v[2]);
            stamp[t] = 0;
        }
    }
    for (size_t i = 0; i < nb; i++)
        stamp[be_t[i]] = NONE;
    st0.rim_share = total > 0.0 ? rim / total : 0.0;
    /* A scan seen from one side along an axis: its loops are the horizon
     * where it turned away, not lost faces of a part (the bent caps would
     * continue its walls past the far side): the least-area caps. */
    int intact = rim <= p->intact * total;
    st0.one_sided = -1.0;
    if (intact && (p->bend || p->planes) && p->onesided > 0.0) {
        st0.one_sided = axis_one_sided(s, Ep);
        if (st0.one_sided < 0.0)
            goto done;
        intact = st0.one_sided >= p->onesided;
    }
    const int bend = p->bend && intact, planes = p->planes && intact;
    st0.continued = bend || planes;
    /* Pair the boundary edges at every vertex: the two of a vertex with
     * two; where holes touch, by the angular gaps between the triangles
     * around it (pair_by_angle), or on a crease by their hole sides
     * (pair_by_sides). */
    for (size_t v = 0; v < (size_t)nw; v++) {
        const size_t k = vstart[v + 1] - vstart[v];
        const uint32_t *ev = vlist + vstart[v];
        if (k == 2) {
            set_partner(be_a, pa, pb, ev[0], (uint32_t)v, ev[1]);
            set_partner(be_a, pa, pb, ev[1], (uint32_t)v, ev[0]);
        } else if (k > 2 && !(k & 1)) {
            int r = pair_by_angle(s, weld, wpos, be_a, be_b, pa, pb, (uint32_t)v, ev, k,
                                  tlist + tstart[v], tstart[v + 1] - tstart[v], be_t);
            if (r < 0)
                goto done;
        }
    }
    /* 3, 4. loops and caps */
    for (size_t e0 = 0; e0 < nb; e0++) {
        if (used[e0])
            continue;
        size_t n = 0;
        int pinched = 0;
        const uint32_t start = be_a[e0];
        uint32_t v = be_b[e0], cur = (uint32_t)e0;
        used[e0] = 1;
        loop_v[n] = start;
        loop_e[n++] = cur;
        for (;;) {
            const uint32_t next = be_a[cur] == v ? pa[cur] : pb[cur];
            if (next == NONE) {     /* an odd vertex, or one not paired */
                pinched = 1;
                break;
            }
            if (next == e0 && v == start)
                break;
            if (used[next] || n > nb) {
                pinched = 1;
                break;
            }
            used[next] = 1;
            loop_v[n] = v;
            loop_e[n++] = next;
            cur = next;
            v = be_a[cur] == v ? be_b[cur] : be_a[cur];
        }
        if (pinched) {
            st0.pinched += n;
            continue;
        }
        st0.loops++;
        if (n < 3)
            continue;
        if (n > p->max_loop) {
            st0.too_long++;
            continue;
        }
        /* The loop's positions: a vertex of the soup welded to each. */
        for (size_t i = 0; i < n; i++) {
            const uint32_t *tv = s->tris + 3 * (size_t)be_t[loop_e[i]];
            const double *q = NULL;
            for (int c = 0; c < 3; c++)
                if (weld[tv[c]] == loop_v[i])
                    q = s->xyz + 3 * (size_t)tv[c];
            pts[i] = q;
        }
        const double cap = least_area(pts, n, tri);
        if (cap < 0) {
            rc = ST_ENOMEM;
            goto done;
        }
        /* The surface around the loop: the pieces with a triangle whose box
         * meets the loop's box grown by a quarter of its extent each way
         * (the loop's own pieces among them). */
        double blo[3], bhi[3], ext = 0.0;
        for (int q = 0; q < 3; q++)
            blo[q] = bhi[q] = pts[0][q];
        for (size_t i = 1; i < n; i++)
            for (int q = 0; q < 3; q++) {
                blo[q] = fmin(blo[q], pts[i][q]);
                bhi[q] = fmax(bhi[q], pts[i][q]);
            }
        for (int q = 0; q < 3; q++)
            ext = fmax(ext, bhi[q] - blo[q]);
        for (int q = 0; q < 3; q++) {
            blo[q] -= 0.25 * ext;
            bhi[q] += 0.25 * ext;
        }
        around_ctx ac = {kept, piece, stamp, (uint32_t)e0, piece_area, 0.0};
        st_bvh_query_box(bvh, blo, bhi, add_piece, &ac);
        const double around = ac.around;
        if (!(cap > 0.0) || (cap > p->max_cap_ratio * around &&
                             !flat_hole(s, pts, n, be_t, loop_e, p->flat))) {
            st0.too_large++;
            continue;
        }
        /* Accepted by its least area; with planes rebuilt from the
         * planes along it, else with bend spanned by the least bend,
         * the soup's triangle on each loop edge beside it. */
        if (bend || planes)
            for (size_t i = 0; i < n; i++) {
                const uint32_t *tv = s->tris + 3 * (size_t)be_t[loop_e[i]];
                const uint32_t a = loop_v[i], b = loop_v[(i + 1) % n];
                side[i] = pts[i];   /* (a kept triangle has a third point) */
                for (int c = 0; c < 3; c++)
                    if (weld[tv[c]] != a && weld[tv[c]] != b)
                        side[i] = s->xyz + 3 * (size_t)tv[c];
            }
        if (bend && least_bend(pts, side, n, tri) < 0) {
            rc = ST_ENOMEM;
            goto done;
        }
        if (planes) {
            /* the cone from a rebuilt corner when it continues the faces
             * along the loop clearly better than the cap of the loop's own
             * points (a flat hole's cap continues them exactly) */
            int coned = 0;
            const double below = CONE_BETTER * rim_bend(pts, side, n, tri);
            /* the cone from one corner, with planes 2 the fans from
             * several too: whichever continues the faces better */
            double cb, fb = INFINITY;
            int fanned = 0;
            st_soup *cone = st_soup_new(), *fans = planes ? st_soup_new() : NULL;
            if (!cone || (planes && !fans)) {
                st_soup_free(cone);
                st_soup_free(fans);
                rc = ST_ENOMEM;
                goto done;
            }
            const st_holes_guard guard = {bvh, kept};
            rc = st_holes_planes_cap(cone, &coned, pts, side, n, below, &guard, &cb, err);
            if (!rc && fans)
                rc = st_holes_planes_fans(fans, &fanned, pts, side, n, below,
                                          bend ? fill_bend : fill_area, &guard, &fb, err);
            if (!rc && (coned || fanned))
                rc = st_soup_append(out, fanned && (!coned || fb < cb) ? fans : cone, err);
            coned |= fanned;
            st_soup_free(cone);
            st_soup_free(fans);
            if (rc)
                goto fail;
            if (coned) {
                st0.filled++;
                st0.rebuilt++;
                continue;
            }
        }
        const size_t base = out->nverts;
        for (size_t i = 0; i < n; i++)
            if ((rc = st_soup_add_vertex(out, pts[i][0], pts[i][1], pts[i][2], err)))
                goto fail;
        for (size_t i = 0; i + 2 < n; i++)
            if ((rc = st_soup_add_triangle(out, (uint32_t)(base + tri[3 * i]),
                                           (uint32_t)(base + tri[3 * i + 1]),
                                           (uint32_t)(base + tri[3 * i + 2]), err)))
                goto fail;
        st0.filled++;
    }
    rc = ST_OK;
done:
    if (rc == ST_ENOMEM)
        st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory for the holes");
fail:
    if (!edges)
        st_soup_edges_free(&own_edges);
    st_bvh_free(own_bvh);
    free(piece_area);
    free(stamp);
    free(be_a);
    free(be_b);
    free(be_t);
    free(pa);
    free(pb);
    free(bdeg);
    free(vstart);
    free(vlist);
    free(tstart);
    free(tlist);
    free(wpos);
    free(used);
    free(loop_v);
    free(loop_e);
    free(tri);
    free(pts);
    free(side);
    if (rc) {
        st_soup_free(out);
        return rc;
    }
    if (stats)
        *stats = st0;
    *caps = out;
    return ST_OK;
}
