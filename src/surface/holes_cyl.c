/*
 * holes_cyl.c - a hole's cap that continues a cylinder across it (for
 * holes.c; issue 37, the large holes of CAD parts). Design notes and
 * measurements: doc/design/holes.md ("Caps along a cylinder").
 *
 * A turned part's large hole takes an arc of a cylindrical face (a
 * disc's rim, a ring's top) with the faces that met it there. The caps
 * of the loop's own points take the chord across the arc, and the planes
 * (holes_planes.c) cannot rebuild a curved face. Where the soup's
 * triangles along the loop include a cylinder, the cap is built in the
 * cylinder's developed space, where it is a plane:
 *
 *   1. fit: a pair of neighbouring triangles along the loop whose normals
 *      differ gives an axis (their normals' cross product); the
 *      triangles along the loop whose normals are perpendicular to it
 *      (within CYL_PERP) and whose corners lie on one circle around it
 *      (a least-squares circle, Kasa's, every corner within CYL_RES times
 *      the loop's extent of it) are the cylinder's facets; at least
 *      CYL_FACETS of them with distinct normals, or no cylinder. The axis
 *      is taken again from the two facets whose normals differ most, and
 *      where faces along the loop are perpendicular to it (a disc's
 *      faces) from their normals. The fit that covers the most of the
 *      loop's length is the cylinder;
 *   2. develop: each point p (the loop's, the soup's beside it) goes to
 *      (R theta, h, r), its angle around the axis (from the loop's mean
 *      direction, the loop within CYL_SPAN of it), height along it and
 *      distance from it; the cylinder's points (within the fit's
 *      tolerance of R) at r = R exactly. The cylinder is a plane there,
 *      and so are the planes across the axis (h constant) and through it
 *      (theta constant);
 *   3. cap the developed loop with the planes' caps (holes_planes.c: the
 *      cone from one rebuilt corner, or the fans from several), where the
 *      continued cylinder meets the continued planes;
 *   4. map back: the loop's points are the loop's (bit for bit), the
 *      others go back around the axis; a triangle edge spanning more than
 *      the cylinder's finest facet in angle (but the loop's edges, which
 *      meet the soup) is split at its developed midpoint, so the cap
 *      follows the arc;
 *   5. check: the cap is kept only if it pierces neither the soup's kept
 *      triangles, the caps made before, nor itself (st_tri_tri_cross,
 *      exact; touching is no crossing), and it continues the soup along
 *      the loop better (the sum over the loop's edges of length times
 *      dihedral angle) than the cap the caller has.
 *
 * A loop without a cylinder (no fit certified) is left to the caller, as
 * it was.
 */
#include "../base/fpenv.h"
#include "holes_internal.h"
#include "souptet/isect.h"
#include "souptet/mem.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif
/* A facet parallel to the axis: |n . a| below CYL_PERP (its normal's
 * rounding on a mesh written to 6 digits is about 1e-5). */
#define CYL_PERP 1e-3
/* The fit's residual: every facet corner within CYL_RES times the loop's
 * extent of the circle. */
#define CYL_RES 1e-4
/* A cylinder has at least this many facets along the loop with distinct
 * normals (two facets lie on a circle whatever they are). */
#define CYL_FACETS 3
/* A facet's normal within this (and half its angle) of the radius
 * through its centroid. */
#define CYL_RADIAL 1e-2
/* The loop's angles around the axis, from its mean direction: within
 * CYL_SPAN (a loop around the axis has no developed plane). */
#define CYL_SPAN (0.75 * M_PI)
/* The finest angle an edge of the cap is split to: not below this. */
#define CYL_MIN_STEP (2.0 * M_PI / 1024.0)
/* A cap's edge is split where it spans more than CYL_SPLIT times the
 * finest facet's angle or the widest loop edge's (which is never split:
 * the triangle on it keeps edges spanning half as much, and more than
 * that factor lets the splits end); no cap where a loop edge spans more
 * than CYL_WIDE facets' angle (a chord across the cylinder's faces). */
#define CYL_SPLIT 1.5
#define CYL_WIDE 2.0
/* Splits per triangle, and the cap's triangles, at most. */
#define CYL_DEPTH 64
#define CYL_MAX_TRIS 20000u

static st_status oom(st_error *err)
{
    return st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory for the holes");
}

/* A cylinder: a point c on its axis, the axis a (unit), u and v across
 * it, its radius R, the tolerance of its points, its finest facet's angle
 * (step), the developed angle's origin th0. */
typedef struct cyl {
    double c[3], a[3], u[3], v[3], R, tol, step, th0, len;
} cyl;

static void normalize(double *x)
{
    const double l = st_norm3(x);
    for (int k = 0; k < 3; k++)
        x[k] = l > 0.0 ? x[k] / l : 0.0;
}

/* u, v: a right-handed frame across the unit vector a. */
static void frame(const double *a, double *u, double *v)
{
    double t[3] = {0, 0, 0};
    const double ax = fabs(a[0]), ay = fabs(a[1]), az = fabs(a[2]);
    t[ax <= ay && ax <= az ? 0 : ay <= az ? 1 : 2] = 1.0;
    st_cross3(u, a, t);
    normalize(u);
    st_cross3(v, a, u);
}

/* The three corners of the soup's triangle on loop edge i. */
static void facet(const double **q, const double *const *pts, const double *const *side,
                  size_t n, size_t i)
{
    q[0] = pts[i];
    q[1] = side[i];
    q[2] = pts[(i + 1) % n];
}

/* Kasa's least-squares circle through the corners of the facets in
 * sel[0..m), projected across cy->a (frame cy->u, cy->v): sets cy->c
 * (on the plane through the origin) and cy->R. 0 when degenerate. */
static int circle_fit(cyl *cy, const double *const *pts, const double *const *side, size_t n,
                      const size_t *sel, size_t m)
{
    double mx = 0, my = 0, sxx = 0, sxy = 0, syy = 0, sxz = 0, syz = 0, sz = 0;
    const double cnt = 3.0 * (double)m;
    for (size_t s = 0; s < m; s++) {    /* the means */
        const double *q[3];
        facet(q, pts, side, n, sel[s]);
        for (int k = 0; k < 3; k++) {
            mx += st_dot3(q[k], cy->u) / cnt;
            my += st_dot3(q[k], cy->v) / cnt;
        }
    }
    for (size_t s = 0; s < m; s++) {    /* the moments about them */
        const double *q[3];
        facet(q, pts, side, n, sel[s]);
        for (int k = 0; k < 3; k++) {
            const double x = st_dot3(q[k], cy->u) - mx, y = st_dot3(q[k], cy->v) - my;
            const double z = x * x + y * y;
            sxx += x * x, syy += y * y, sxy += x * y, sz += z, sxz += x * z, syz += y * z;
        }
    }
    const double det = sxx * syy - sxy * sxy;
    if (!(det > 1e-12 * (sxx + syy) * (sxx + syy)))
        return 0;
    /* x^2 + y^2 + D x + E y + F = 0 in the least squares (sums of x, y 0) */
    const double D = -(sxz * syy - syz * sxy) / det, E = -(syz * sxx - sxz * sxy) / det;
    const double F = -sz / cnt, r2 = 0.25 * (D * D + E * E) - F;
    if (!(r2 > 0.0))
        return 0;
    const double cx = mx - 0.5 * D, cyy = my - 0.5 * E;
    for (int k = 0; k < 3; k++)
        cy->c[k] = cx * cy->u[k] + cyy * cy->v[k];
    cy->R = sqrt(r2);
    return 1;
}

/* The distance of p from the axis of cy. */
static double radius(const cyl *cy, const double *p)
{
    double d[3];
    st_sub3(d, p, cy->c);
    const double x = st_dot3(d, cy->u), y = st_dot3(d, cy->v);
    return hypot(x, y);
}

/* 1 when the facet q[3] of unit normal w faces along the radius through
 * its middle, as a cylinder's facet does: its normal within half its
 * angle around the axis (and CYL_RADIAL) of the direction from the axis
 * to its centroid. */
static int radial(const cyl *cy, const double *const *q, const double *w)
{
    double g[3] = {0, 0, 0}, x[3];
    for (int k = 0; k < 3; k++)
        for (int j = 0; j < 3; j++)
            g[j] += q[k][j] / 3.0;
    st_sub3(g, g, cy->c);
    const double gu = st_dot3(g, cy->u), gv = st_dot3(g, cy->v), gl = hypot(gu, gv);
    if (!(gl > 0.0))
        return 0;
    for (int j = 0; j < 3; j++)
        g[j] = (gu * cy->u[j] + gv * cy->v[j]) / gl;
    st_cross3(x, g, w);
    /* the facet's half angle: half its widest chord over the radius */
    double chord = 0.0;
    for (int k = 0; k < 3; k++) {
        double d[3];
        st_sub3(d, q[k], q[(k + 1) % 3]);
        const double a = st_dot3(d, cy->u), b = st_dot3(d, cy->v);
        chord = fmax(chord, hypot(a, b));
    }
    return st_norm3(x) <= 0.5 * chord / cy->R + CYL_RADIAL;
}

/* The loop's facets on cy (normal across the axis, corners within tol of
 * its circle) into sel; returns how many. */
static size_t on_cyl(const cyl *cy, const double *const *pts, const double *const *side,
                     size_t n, const double *nrm, size_t *sel)
{
    size_t m = 0;
    for (size_t i = 0; i < n; i++) {
        const double *w = nrm + 3 * i, *q[3];
        if (st_dot3(w, w) == 0.0 || !(fabs(st_dot3(w, cy->a)) < CYL_PERP))
            continue;
        facet(q, pts, side, n, i);
        int ok = 1;
        for (int k = 0; k < 3; k++)
            ok &= fabs(radius(cy, q[k]) - cy->R) <= cy->tol;
        if (ok && radial(cy, q, w))
            sel[m++] = i;
    }
    return m;
}

/* The axis from the two facets of sel whose normals differ most. */
static void best_axis(cyl *cy, const double *nrm, const size_t *sel, size_t m)
{
    double best = -1.0, a[3];
    for (size_t s = 0; s < m; s++)
        for (size_t t = s + 1; t < m; t++) {
            double x[3];
            st_cross3(x, nrm + 3 * sel[s], nrm + 3 * sel[t]);
            const double l = st_dot3(x, x);
            if (l > best) {
                best = l;
                memcpy(a, x, sizeof a);
            }
        }
    if (best > 0.0) {
        if (st_dot3(a, cy->a) < 0.0)
            for (int k = 0; k < 3; k++)
                a[k] = -a[k];
        normalize(a);
        memcpy(cy->a, a, sizeof a);
    }
}

/* Where triangles along the loop face along the axis (a turned part's
 * faces across it), the axis from their normals (length-weighted, signs
 * aligned): they are exact where the cylinder's facets are not. */
static void flat_axis(cyl *cy, const double *const *pts, size_t n, const double *nrm)
{
    double s[3] = {0, 0, 0};
    for (size_t i = 0; i < n; i++) {
        const double *w = nrm + 3 * i;
        double x[3];
        st_cross3(x, w, cy->a);
        if (st_dot3(w, w) == 0.0 || !(st_norm3(x) < CYL_PERP))
            continue;
        const double l = dist3(pts[i], pts[(i + 1) % n]) * (st_dot3(w, cy->a) < 0.0 ? -1.0 : 1.0);
        for (int k = 0; k < 3; k++)
            s[k] += l * w[k];
    }
    if (st_dot3(s, s) > 0.0) {
        normalize(s);
        memcpy(cy->a, s, sizeof s);
    }
}

/* The number of distinct normals among the facets sel[0..m), up to
 * CYL_FACETS. */
static int distinct(const double *nrm, const size_t *sel, size_t m)
{
    size_t got[CYL_FACETS];
    int k = 0;
    for (size_t s = 0; s < m && k < CYL_FACETS; s++) {
        int same = 0;
        for (int j = 0; j < k && !same; j++) {
            double x[3];
            st_cross3(x, nrm + 3 * sel[s], nrm + 3 * got[j]);
            same = st_norm3(x) < 10.0 * CYL_PERP;
        }
        if (!same)
            got[k++] = sel[s];
    }
    return k;
}

/* Fits the cylinder seeded by the axis cy->a (and cy->tol): its facets in
 * sel (*m of them), cy's circle. 1 when certified. */
static int fit_seed(cyl *cy, const double *const *pts, const double *const *side, size_t n,
                    const double *nrm, size_t *sel, size_t *m, const size_t *seed)
{
    frame(cy->a, cy->u, cy->v);
    if (!circle_fit(cy, pts, side, n, seed, 2))
        return 0;
    for (int round = 0; round < 3; round++) {
        *m = on_cyl(cy, pts, side, n, nrm, sel);
        if (*m < CYL_FACETS || distinct(nrm, sel, *m) < CYL_FACETS)
            return 0;
        if (round == 0)
            best_axis(cy, nrm, sel, *m);
        if (round == 1)
            flat_axis(cy, pts, n, nrm);
        frame(cy->a, cy->u, cy->v);
        if (!circle_fit(cy, pts, side, n, sel, *m))
            return 0;
    }
    const size_t m0 = *m;
    *m = on_cyl(cy, pts, side, n, nrm, sel);
    return *m == m0 && distinct(nrm, sel, *m) >= CYL_FACETS;
}

/* The cylinder along the loop that covers most of its length (1), else 0
 * (no certified fit). nrm[3 n]: the unit normals of the soup's triangles
 * along the loop; sel[n] scratch. */
static int fit_cyl(cyl *best, const double *const *pts, const double *const *side, size_t n,
                   const double *nrm, size_t *sel, double ext)
{
    int found = 0;
    best->len = 0.0;
    for (size_t i = 0; i < n; i++) {
        const size_t seed[2] = {i, (i + 1) % n};
        const double *p = nrm + 3 * seed[0], *q = nrm + 3 * seed[1];
        double x[3];
        st_cross3(x, p, q);
        /* neighbouring facets of one cylinder: normals apart, not folded */
        if (!(st_norm3(x) > 10.0 * CYL_PERP) || !(st_dot3(p, q) > 0.5))
            continue;
        cyl cy;
        memset(&cy, 0, sizeof cy);
        memcpy(cy.a, x, sizeof x);
        normalize(cy.a);
        cy.tol = CYL_RES * ext;
        size_t m = 0;
        if (!fit_seed(&cy, pts, side, n, nrm, sel, &m, seed))
            continue;
        double len = 0.0;
        for (size_t s = 0; s < m; s++)
            len += dist3(pts[sel[s]], pts[(sel[s] + 1) % n]);
        if (len > best->len) {
            *best = cy;
            best->len = len;
            found = 1;
        }
    }
    return found;
}

/* p developed on cy: (R theta, h, r), theta from th0 wrapped into
 * (-pi, pi]; r snapped to R within the fit's tolerance. */
static void develop(const cyl *cy, const double *p, double *d)
{
    double w[3];
    st_sub3(w, p, cy->c);
    const double x = st_dot3(w, cy->u), y = st_dot3(w, cy->v);
    double th = atan2(y, x) - cy->th0;
    while (th > M_PI)
        th -= 2.0 * M_PI;
    while (th <= -M_PI)
        th += 2.0 * M_PI;
    const double r = hypot(x, y);
    d[0] = cy->R * th;
    d[1] = st_dot3(w, cy->a);
    d[2] = fabs(r - cy->R) <= cy->tol ? cy->R : r;
}

/* The point developed as d, back around the axis. */
static void undevelop(const cyl *cy, const double *d, double *p)
{
    const double th = d[0] / cy->R + cy->th0, c = cos(th), s = sin(th);
    for (int k = 0; k < 3; k++)
        p[k] = cy->c[k] + d[1] * cy->a[k] + d[2] * (c * cy->u[k] + s * cy->v[k]);
}

/* th0 from the loop's mean direction around the axis; the angle a cap's
 * edge may span (step: CYL_SPLIT times the finest facet's, or the widest
 * loop edge's). 0 when the loop goes around the axis (beyond CYL_SPAN),
 * reaches it, or has an edge wider than CYL_WIDE facets. */
static int orient_cyl(cyl *cy, const double *const *pts, const double *const *side, size_t n,
                      const size_t *sel, size_t m)
{
    double mx = 0.0, my = 0.0;
    for (size_t i = 0; i < n; i++) {
        double w[3];
        st_sub3(w, pts[i], cy->c);
        const double x = st_dot3(w, cy->u), y = st_dot3(w, cy->v), r = hypot(x, y);
        if (!(r > 1e-3 * cy->R))
            return 0;
        mx += x / r, my += y / r;
    }
    if (!(hypot(mx, my) > 0.25 * (double)n))
        return 0;
    cy->th0 = atan2(my, mx);
    for (size_t i = 0; i < n; i++) {
        double d[3];
        develop(cy, pts[i], d);
        if (!(fabs(d[0]) <= CYL_SPAN * cy->R))
            return 0;
    }
    cy->step = 2.0 * M_PI;
    for (size_t s = 0; s < m; s++) {
        const double *q[3];
        double lo = INFINITY, hi = -INFINITY;
        facet(q, pts, side, n, sel[s]);
        for (int k = 0; k < 3; k++) {
            double d[3];
            develop(cy, q[k], d);
            lo = fmin(lo, d[0]), hi = fmax(hi, d[0]);
        }
        if ((hi - lo) / cy->R > 1e-9)
            cy->step = fmin(cy->step, (hi - lo) / cy->R);
    }
    cy->step = fmax(cy->step, CYL_MIN_STEP);
    double wide = 0.0;
    for (size_t i = 0; i < n; i++) {
        double d[3], e[3];
        develop(cy, pts[i], d);
        develop(cy, pts[(i + 1) % n], e);
        wide = fmax(wide, fabs(d[0] - e[0]) / cy->R);
    }
    if (!(wide <= CYL_WIDE * cy->step))
        return 0;
    cy->step = CYL_SPLIT * fmax(cy->step, wide);
    return 1;
}

/* What a cap on the cylinders around the axis may bend more than the
 * soup's facets along the loop: where the soup's triangle on a loop edge
 * is a facet of a cylinder around the axis (its normal across it, its
 * corners at one radius within the fit's tolerance: the fitted one or one
 * coaxial with it, a disc's rim around its bore), the cap follows the arc,
 * not the facet's chord, and its triangle there (spanning at most
 * cy->step) turns from the facet by at most half of that and half the
 * facet's own angle: the edge's length times it. */
static double facet_slack(const cyl *cy, const double *const *pts, const double *const *side,
                          size_t n, const double *nrm)
{
    double slack = 0.0;
    for (size_t i = 0; i < n; i++) {
        const double *w = nrm + 3 * i, *q[3];
        if (st_dot3(w, w) == 0.0 || !(fabs(st_dot3(w, cy->a)) < CYL_PERP))
            continue;
        facet(q, pts, side, n, i);
        double d[3][3];
        for (int k = 0; k < 3; k++)
            develop(cy, q[k], d[k]);
        const double r0 = radius(cy, q[0]);
        int one = 1;
        for (int k = 1; k < 3; k++)
            one &= fabs(radius(cy, q[k]) - r0) <= cy->tol;
        const double lo = fmin(d[0][0], fmin(d[1][0], d[2][0]));
        const double hi = fmax(d[0][0], fmax(d[1][0], d[2][0]));
        if (one && hi - lo < M_PI * cy->R)
            slack += dist3(pts[i], pts[(i + 1) % n]) * 0.5 * ((hi - lo) / cy->R + cy->step);
    }
    return slack;
}

/* ---- the developed cap, back around the axis */

/* A triangle of the cap: its corners developed and as weights of the
 * developed triangle it was split from (dyadic, exact), each one's loop
 * point (-1: none), and how many times it was split. */
typedef struct ctri {
    double d[3][3], w[3][3];    /* developed corners, their weights of the root's */
    long id[3];
    int depth;
} ctri;

/* The cap in real space: 3 points a triangle (x[9 nt]), each corner's
 * loop point or -1 (id[3 nt]). */
typedef struct rcap {
    double *x;
    long *id;
    size_t nt, cap;
} rcap;

typedef struct stack {
    ctri *t;
    size_t n, cap;
} stack;

static int push_ctri(stack *s, const ctri *t)
{
    if (s->n == s->cap) {
        const size_t nc = s->cap ? 2 * s->cap : 64;
        ctri *g = realloc(s->t, nc * sizeof *g);
        if (!g)
            return 0;
        s->t = g;
        s->cap = nc;
    }
    s->t[s->n++] = *t;
    return 1;
}

static int push_rtri(rcap *o, const cyl *cy, const ctri *t, const double *const *pts)
{
    if (o->nt == o->cap) {
        const size_t nc = o->cap ? 2 * o->cap : 64;
        double *x = realloc(o->x, 9 * nc * sizeof *x);
        if (!x)
            return 0;
        o->x = x;
        long *id = realloc(o->id, 3 * nc * sizeof *id);
        if (!id)
            return 0;
        o->id = id;
        o->cap = nc;
    }
    for (int k = 0; k < 3; k++) {
        double *p = o->x + 9 * o->nt + 3 * k;
        if (t->id[k] >= 0)
            memcpy(p, pts[t->id[k]], 3 * sizeof *p);
        else
            undevelop(cy, t->d[k], p);
        o->id[3 * o->nt + k] = t->id[k];
    }
    o->nt++;
    return 1;
}

/* 1 when a and b are neighbours along the loop of n points. */
static int loop_edge(long a, long b, size_t n)
{
    return a >= 0 && b >= 0 && ((size_t)(a + 1) % n == (size_t)b || (size_t)(b + 1) % n == (size_t)a);
}

/* The developed point of weights w of the root triangle rt: a corner as
 * it is; a point of an edge from its two ends taken in one order (by
 * their coordinates), so that the triangles on both sides of the edge
 * get the same point, bit for bit; else all three. */
static void at_weights(const double rt[3][3], const double *w, double *d)
{
    int nz = 0, a = -1, b = -1;
    for (int k = 0; k < 3; k++)
        if (w[k] != 0.0) {
            nz++;
            b = a < 0 ? b : k;
            a = a < 0 ? k : a;
        }
    if (nz == 1) {
        memcpy(d, rt[a], 3 * sizeof *d);
        return;
    }
    if (nz == 2) {
        if (
            (rt[a][0] > rt[b][0] || (rt[a][0] == rt[b][0] && (rt[a][1] > rt[b][1] ||
                                     (rt[a][1] == rt[b][1] && rt[a][2] > rt[b][2]))))) {
            const int t = a;
            a = b, b = t;
        }
        for (int q = 0; q < 3; q++)
            d[q] = w[a] * rt[a][q] + w[b] * rt[b][q];
        return;
    }
    for (int q = 0; q < 3; q++)
        d[q] = w[0] * rt[0][q] + w[1] * rt[1][q] + w[2] * rt[2][q];
}

/* The developed cap dev (its triangles' corners developed; dpts[n] the
 * loop's developed points) back around the axis into o: each edge but
 * the loop's spanning more than cy->step in angle is split at its
 * developed midpoint (the same midpoint from either side, so the cap
 * stays closed; a triangle with two corners at one point, which covers
 * nothing, is kept as it is), the loop's points taken as they are. 0: a
 * corner off the cylinder's side of the axis, too many splits or
 * triangles (o is then not a cap). ST_ENOMEM through *rc. */
static int map_back(rcap *o, const cyl *cy, const st_soup *dev, const double *dpts, size_t n,
                    const double *const *pts, st_status *rc, st_error *err)
{
    stack s = {NULL, 0, 0};
    int ok = 1;
    o->nt = 0;
    for (size_t t = 0; t < dev->ntris && ok; t++) {
        ctri c;
        double rt[3][3];
        memset(&c, 0, sizeof c);
        for (int k = 0; k < 3; k++) {
            const double *q = dev->xyz + 3 * (size_t)dev->tris[3 * t + k];
            memcpy(c.d[k], q, sizeof c.d[k]);
            memcpy(rt[k], q, sizeof rt[k]);
            c.w[k][k] = 1.0;
            c.id[k] = -1;
            for (size_t i = 0; i < n && c.id[k] < 0; i++)
                if (q[0] == dpts[3 * i] && q[1] == dpts[3 * i + 1] && q[2] == dpts[3 * i + 2])
                    c.id[k] = (long)i;
            ok &= q[2] > 0.0;
        }
        if (ok && !push_ctri(&s, &c))
            goto nomem;
        while (ok && s.n) {
            const ctri t0 = s.t[--s.n];
            /* of its edges that span too much, the longest (developed;
             * ties: the first) is split */
            int k = 3, same = 0;
            double kl = -1.0;
            for (int e = 0; e < 3; e++)    /* two corners at one point: no area to follow */
                same |= !memcmp(t0.d[e], t0.d[(e + 1) % 3], sizeof t0.d[e]);
            for (int e = 0; e < 3 && !same; e++) {
                const double *p = t0.d[e], *q = t0.d[(e + 1) % 3], l = dist3(p, q);
                if (fabs(p[0] - q[0]) > cy->R * cy->step && l > kl &&
                    !loop_edge(t0.id[e], t0.id[(e + 1) % 3], n))
                    k = e, kl = l;
            }
            if (k == 3) {
                if (!push_rtri(o, cy, &t0, pts))
                    goto nomem;
                ok = o->nt <= CYL_MAX_TRIS;
                continue;
            }
            /* (A, B, C) split on A B at M: (A, M, C) and (M, B, C) */
            const int b = (k + 1) % 3;
            ctri h[2] = {t0, t0};
            double m[3], mw[3];
            for (int q = 0; q < 3; q++)
                mw[q] = 0.5 * (t0.w[k][q] + t0.w[b][q]);
            at_weights(rt, mw, m);
            memcpy(h[0].d[b], m, sizeof m);
            memcpy(h[1].d[k], m, sizeof m);
            memcpy(h[0].w[b], mw, sizeof mw);
            memcpy(h[1].w[k], mw, sizeof mw);
            h[0].id[b] = h[1].id[k] = -1;
            h[0].depth = h[1].depth = t0.depth + 1;
            ok = t0.depth < CYL_DEPTH;
            if (ok && (!push_ctri(&s, &h[1]) || !push_ctri(&s, &h[0])))
                goto nomem;
        }
    }
    free(s.t);
    return ok;
nomem:
    free(s.t);
    *rc = oom(err);
    return 0;
}

/* The cap's bend along the loop (length times dihedral over the loop's
 * edges, against the soup's triangles there, or the planes of the
 * creases the loop runs along: st_holes_crease_bend); INFINITY unless each loop
 * edge is the edge of exactly one of its triangles. cnt[n] scratch. */
static double cap_rim_bend(const rcap *o, const double *const *pts, const double *const *side,
                           size_t n, const double *crease, unsigned *cnt)
{
    double b = 0.0;
    memset(cnt, 0, n * sizeof *cnt);
    for (size_t t = 0; t < o->nt; t++) {
        const double *x = o->x + 9 * t;
        const long *id = o->id + 3 * t;
        double nt[3], nr[3];
        unit_normal(nt, x, x + 3, x + 6);
        for (int k = 0; k < 3; k++) {
            const long a = id[k], z = id[(k + 1) % 3];
            if (!loop_edge(a, z, n))
                continue;
            const size_t i = (size_t)(a + 1) % n == (size_t)z ? (size_t)a : (size_t)z;
            cnt[i]++;
            unit_normal(nr, pts[i], side[i], pts[(i + 1) % n]);
            b += dist3(pts[i], pts[(i + 1) % n]) *
                 st_holes_crease_bend(nt, nr, crease ? crease + 6 * i : NULL);
        }
    }
    for (size_t i = 0; i < n; i++)
        if (cnt[i] != 1)
            return INFINITY;
    return b;
}

/* ---- the checks: the soup, the caps before, the cap itself */

typedef struct cross_ctx {
    const st_holes_guard *g;
    const double *t;
} cross_ctx;

static int cross_visit(void *ctx, uint32_t tri)
{
    const cross_ctx *c = ctx;
    if (c->g->kept && !c->g->kept[tri])
        return 0;
    const st_soup *s = c->g->bvh->soup;
    const uint32_t *v = s->tris + 3 * (size_t)tri;
    return st_tri_tri_cross(c->t, c->t + 3, c->t + 6, s->xyz + 3 * (size_t)v[0],
                            s->xyz + 3 * (size_t)v[1], s->xyz + 3 * (size_t)v[2]);
}

static void tri_box(const double *x, double *lo, double *hi)
{
    for (int q = 0; q < 3; q++) {
        lo[q] = fmin(x[q], fmin(x[3 + q], x[6 + q]));
        hi[q] = fmax(x[q], fmax(x[3 + q], x[6 + q]));
    }
}

static int boxes_meet(const double *alo, const double *ahi, const double *blo, const double *bhi)
{
    return alo[0] <= bhi[0] && blo[0] <= ahi[0] && alo[1] <= bhi[1] && blo[1] <= ahi[1] &&
           alo[2] <= bhi[2] && blo[2] <= ahi[2];
}

/* 1 when triangle x (9 doubles) pierces one of out's triangles [0, nt). */
static int cross_caps(const st_soup *out, size_t nt, const double *x)
{
    double lo[3], hi[3];
    tri_box(x, lo, hi);
    for (size_t t = 0; t < nt; t++) {
        const uint32_t *v = out->tris + 3 * t;
        double y[9], blo[3], bhi[3];
        for (int k = 0; k < 3; k++)
            memcpy(y + 3 * k, out->xyz + 3 * (size_t)v[k], 3 * sizeof *y);
        tri_box(y, blo, bhi);
        if (boxes_meet(lo, hi, blo, bhi) && st_tri_tri_cross(x, x + 3, x + 6, y, y + 3, y + 6))
            return 1;
    }
    return 0;
}

int st_holes_caps_cross(const st_soup *caps, const st_soup *cap)
{
    for (size_t t = 0; cap && t < cap->ntris; t++) {
        double x[9];
        for (int k = 0; k < 3; k++)
            memcpy(x + 3 * k, cap->xyz + 3 * (size_t)cap->tris[3 * t + k], 3 * sizeof *x);
        if (cross_caps(caps, caps->ntris, x))
            return 1;
    }
    return 0;
}

static int by_lo_x(const void *a, const void *b)
{
    const double *x = a, *y = b;
    return x[0] < y[0] ? -1 : x[0] > y[0];
}

/* 1 when the cap pierces the soup's kept triangles (guard), out's
 * triangles [0, nt) (the caps before), or itself. ST_ENOMEM through
 * *rc. */
static int cap_crosses(const rcap *o, const st_holes_guard *g, const st_soup *out, size_t nt,
                       st_status *rc, st_error *err)
{
    for (size_t t = 0; t < o->nt; t++) {
        const double *x = o->x + 9 * t;
        cross_ctx cc = {g, x};
        if ((g && g->bvh && st_bvh_query_tri(g->bvh, x, x + 3, x + 6, cross_visit, &cc)) ||
            cross_caps(out, nt, x))
            return 1;
    }
    /* itself: the boxes swept along x (lo x, then the triangle's index) */
    double *key = malloc(2 * o->nt * sizeof *key);
    if (!key) {
        *rc = oom(err);
        return 1;
    }
    for (size_t t = 0; t < o->nt; t++) {
        double lo[3], hi[3];
        tri_box(o->x + 9 * t, lo, hi);
        key[2 * t] = lo[0];
        key[2 * t + 1] = (double)t;
    }
    qsort(key, o->nt, 2 * sizeof *key, by_lo_x);
    int hit = 0;
    for (size_t s = 0; s < o->nt && !hit; s++) {
        const double *x = o->x + 9 * (size_t)key[2 * s + 1];
        double lo[3], hi[3];
        tri_box(x, lo, hi);
        for (size_t u = s + 1; u < o->nt && key[2 * u] <= hi[0] && !hit; u++) {
            const double *y = o->x + 9 * (size_t)key[2 * u + 1];
            double blo[3], bhi[3];
            tri_box(y, blo, bhi);
            hit = boxes_meet(lo, hi, blo, bhi) && st_tri_tri_cross(x, x + 3, x + 6, y, y + 3, y + 6);
        }
    }
    free(key);
    return hit;
}

/* ---- the cap */

/* The developed loop (dpts[3 n]) and the soup's points beside it
 * (dside[3 n], each unwrapped to its edge's side of the cut). */
static void develop_loop(const cyl *cy, const double *const *pts, const double *const *side,
                         size_t n, double *dpts, double *dside)
{
    for (size_t i = 0; i < n; i++)
        develop(cy, pts[i], dpts + 3 * i);
    for (size_t i = 0; i < n; i++) {
        double *d = dside + 3 * i;
        develop(cy, side[i], d);
        if (d[0] - dpts[3 * i] > M_PI * cy->R)
            d[0] -= 2.0 * M_PI * cy->R;
        else if (d[0] - dpts[3 * i] < -M_PI * cy->R)
            d[0] += 2.0 * M_PI * cy->R;
    }
}

/* Of the developed caps dev[0..2) (NULL: none), the one that, back
 * around the axis, bends least along the loop, below *best and pierces
 * nothing: into o (its bend in *best). */
static st_status pick_cap(rcap *o, double *best, const cyl *cy, st_soup *const *dev,
                          const double *dpts, const double *const *pts,
                          const double *const *side, size_t n, const st_holes_guard *g,
                          const st_soup *out, size_t tbase, st_error *err)
{
    rcap r = {NULL, NULL, 0, 0};
    unsigned *cnt = malloc(n * sizeof *cnt);
    st_status rc = cnt ? ST_OK : oom(err);
    for (int k = 0; k < 2 && !rc; k++) {
        if (!dev[k] || !map_back(&r, cy, dev[k], dpts, n, pts, &rc, err))
            continue;
        const double b = cap_rim_bend(&r, pts, side, n, g ? g->crease : NULL, cnt);
        if (!(b < *best) || cap_crosses(&r, g, out, tbase, &rc, err))
            continue;
        *best = b;
        rcap t = *o;
        *o = r;
        r = t;
    }
    free(r.x), free(r.id), free(cnt);
    return rc;
}

st_status st_holes_cyl_cap(st_soup *out, int *done, size_t vbase, size_t tbase,
                           const double *const *pts, const double *const *side, size_t n,
                           double below, st_holes_fill fill, const st_holes_guard *guard,
                           st_error *err)
{
    *done = 0;
    double *nrm = malloc(3 * n * sizeof *nrm), *dp = malloc(6 * n * sizeof *dp);
    size_t *sel = malloc(n * sizeof *sel);
    const double **dpp = malloc(2 * n * sizeof *dpp);
    st_soup *dev[2] = {NULL, NULL};
    rcap o = {NULL, NULL, 0, 0};
    st_status rc = nrm && dp && sel && dpp ? ST_OK : oom(err);
    if (rc || n < 3)
        goto done;
    double lo[3], hi[3], ext = 0.0;
    for (int q = 0; q < 3; q++)
        lo[q] = hi[q] = pts[0][q];
    for (size_t i = 0; i < n; i++) {
        unit_normal(nrm + 3 * i, pts[i], side[i], pts[(i + 1) % n]);
        for (int q = 0; q < 3; q++)
            lo[q] = fmin(lo[q], pts[i][q]), hi[q] = fmax(hi[q], pts[i][q]);
    }
    for (int q = 0; q < 3; q++)
        ext = fmax(ext, hi[q] - lo[q]);
    cyl cy;
    if (!(ext > 0.0) || !fit_cyl(&cy, pts, side, n, nrm, sel, ext))
        goto done;
    size_t m = on_cyl(&cy, pts, side, n, nrm, sel);
    if (!orient_cyl(&cy, pts, side, n, sel, m))
        goto done;
    /* 3. the planes' caps of the developed loop */
    double *dpts = dp, *dside = dp + 3 * n;
    develop_loop(&cy, pts, side, n, dpts, dside);
    for (size_t i = 0; i < n; i++)
        dpp[i] = dpts + 3 * i, dpp[n + i] = dside + 3 * i;
    int coned = 0, fanned = 0;
    double cb, fb;
    if (!(dev[0] = st_soup_new()) || !(dev[1] = st_soup_new())) {
        rc = oom(err);
        goto done;
    }
    if ((rc = st_holes_planes_cap(dev[0], &coned, dpp, dpp + n, n, INFINITY, NULL, &cb, err)) ||
        (rc = st_holes_planes_fans(dev[1], &fanned, dpp, dpp + n, n, INFINITY, fill, NULL, &fb,
                                   err)))
        goto done;
    st_soup *const use[2] = {coned ? dev[0] : NULL, fanned ? dev[1] : NULL};
    /* 4, 5. back around the axis, checked */
    double best = below + facet_slack(&cy, pts, side, n, nrm);
    if ((rc = pick_cap(&o, &best, &cy, use, dpts, pts, side, n, guard, out, tbase, err)) ||
        o.nt == 0)
        goto done;
    out->nverts = vbase;
    out->ntris = tbase;
    for (size_t t = 0; t < o.nt && !rc; t++) {
        const size_t base = out->nverts;
        for (int k = 0; k < 3 && !rc; k++) {
            const double *x = o.x + 9 * t + 3 * k;
            rc = st_soup_add_vertex(out, x[0], x[1], x[2], err);
        }
        if (!rc)
            rc = st_soup_add_triangle(out, (uint32_t)base, (uint32_t)(base + 1),
                                      (uint32_t)(base + 2), err);
    }
    *done = !rc;
done:
    free(nrm), free(dp), free(sel), free(dpp), free(o.x), free(o.id);
    st_soup_free(dev[0]);
    st_soup_free(dev[1]);
    return rc;
}
