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
 * box's bends along all its loop by 55 degrees, the corner's cone by 0).
 */
#include "holes_internal.h"
#include "fpenv.h"
#include "souptet/geom.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Apexes within the loop's box grown by REACH times its extent each way:
 * a lost corner lies near the loop's box (a box's lost corner at a corner
 * of it), a point where nearly parallel planes meet far beyond. */
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

st_status st_holes_planes_cap(st_soup *out, int *done, const double *const *pts,
                              const double *const *side, size_t n, double below,
                              st_error *err)
{
    *done = 0;
    double *rim = malloc(3 * n * sizeof *rim), *tn = malloc(3 * n * sizeof *tn);
    plane *pl = malloc(n * sizeof *pl);
    st_status rc = ST_OK;
    if (!rim || !tn || !pl) {
        rc = st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory for the holes");
        goto out;
    }
    double lo[3], hi[3], o[3] = {0, 0, 0}, ext = 0.0;
    for (int k = 0; k < 3; k++)
        lo[k] = hi[k] = pts[0][k];
    for (size_t i = 0; i < n; i++)
        for (int k = 0; k < 3; k++) {
            lo[k] = fmin(lo[k], pts[i][k]);
            hi[k] = fmax(hi[k], pts[i][k]);
            o[k] += pts[i][k] / (double)n;
        }
    for (int k = 0; k < 3; k++)
        ext = fmax(ext, hi[k] - lo[k]);
    for (int k = 0; k < 3; k++) {
        lo[k] -= REACH * ext;
        hi[k] += REACH * ext;
    }
    /* the planes, once each (either orientation), by the length on them */
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
    /* the longest MAX_PLANES (insertion sort, ties by order along the loop) */
    for (size_t i = 1; i < m; i++)
        for (size_t j = i; j > 0 && pl[j].len > pl[j - 1].len; j--) {
            plane t = pl[j];
            pl[j] = pl[j - 1];
            pl[j - 1] = t;
        }
    if (m > MAX_PLANES)
        m = MAX_PLANES;
    double best = below, best_total = INFINITY, apex[3] = {0, 0, 0};
    int found = 0;
    for (size_t a = 0; a < m; a++)
        for (size_t b = a + 1; b < m; b++)
            for (size_t c = b; c < m; c++) {    /* c == b: the line of a and b */
                double x[3];
                if (!(c == b ? meet2(x, &pl[a], &pl[b], o) : meet3(x, &pl[a], &pl[b], &pl[c])))
                    continue;
                int inside = 1;
                for (int k = 0; k < 3; k++)
                    inside &= x[k] >= lo[k] && x[k] <= hi[k];
                if (!inside)
                    continue;
                double rb;
                const double cb = cone_bend(x, pts, rim, n, tn, &rb);
                if (rb < best || (rb == best && cb < best_total)) {
                    best = rb;
                    best_total = cb;
                    memcpy(apex, x, sizeof apex);
                    found = 1;
                }
            }
    if (!found)
        goto out;
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
out:
    free(rim), free(tn), free(pl);
    return rc;
}
