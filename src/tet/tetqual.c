/*
 * tetqual.c - volume, dihedral angles and circumcenter of one tet (see
 * tetqual.h). Measurements in double; no decision is taken here.
 *
 * Dihedral angle of edge (i j), with k and l the two other corners: with
 * e = pj - pi, u = e x (pk - pi) and v = e x (pl - pi) are normal to e and
 * lie in the planes of the faces (i j k) and (i j l) turned by the same
 * quarter turn about e, so the angle between u and v is the angle between
 * the faces. It is taken as atan2(|u x v|, u.v), which keeps full relative
 * accuracy near 0 and 180 degrees where acos of a normalised dot product
 * loses half the digits (acos'(x) is unbounded at x = +-1).
 *
 * Circumcenter, relative to p0 with a = p1-p0, b = p2-p0, c = p3-p0:
 *     (|a|^2 (b x c) + |b|^2 (c x a) + |c|^2 (a x b)) / (2 a.(b x c))
 * (Shewchuk, "Lecture Notes on Geometric Robustness", 2013, sec. 6): the
 * differences are taken first so that a mesh far from the origin does not
 * lose digits, and the only division is by the (doubled, sixfold) volume.
 */
#include "souptet/tetqual.h"
#include "../base/fpenv.h"
#include "souptet/geom.h"
#include "tetqual_pairs.h"

#include <math.h>

#define RAD2DEG (180.0 / 3.14159265358979323846)

double st_tet_volume(const double p0[3], const double p1[3],
                     const double p2[3], const double p3[3])
{
    double a[3], b[3], c[3], bc[3];
    st_sub3(a, p1, p0);
    st_sub3(b, p2, p0);
    st_sub3(c, p3, p0);
    st_cross3(bc, b, c);
    return st_dot3(a, bc) / 6.0;
}

/* The dihedral angle at edge (pi pj) between faces (pi pj pk), (pi pj pl). */
static double dihedral(const double *pi, const double *pj, const double *pk,
                       const double *pl)
{
    double e[3], a[3], b[3], u[3], v[3], w[3];
    st_sub3(e, pj, pi);
    st_sub3(a, pk, pi);
    st_sub3(b, pl, pi);
    st_cross3(u, e, a);
    st_cross3(v, e, b);
    /* A face of zero area has no plane: the angle is undefined, and 0
     * makes the tet read as the worst there is (tetqual.h). */
    if ((u[0] == 0 && u[1] == 0 && u[2] == 0) ||
        (v[0] == 0 && v[1] == 0 && v[2] == 0))
        return 0.0;
    st_cross3(w, u, v);
    double ang = atan2(st_norm3(w), st_dot3(u, v)) * RAD2DEG;
    return isfinite(ang) ? ang : 0.0;
}

void st_tet_dihedrals(const double p0[3], const double p1[3],
                      const double p2[3], const double p3[3],
                      double angles[6])
{
    angles[0] = dihedral(p0, p1, p2, p3);   /* (0 1) */
    angles[1] = dihedral(p0, p2, p1, p3);   /* (0 2) */
    angles[2] = dihedral(p0, p3, p1, p2);   /* (0 3) */
    angles[3] = dihedral(p1, p2, p0, p3);   /* (1 2) */
    angles[4] = dihedral(p1, p3, p0, p2);   /* (1 3) */
    angles[5] = dihedral(p2, p3, p0, p1);   /* (2 3) */
}

/* Ratios r = x / y (tetqual_pairs.h) whose atan2 the range skips: an
 * edge whose ratio is further than TQ_PRUNE_GAP * (1 + |r*|)^2 from the
 * extreme r* has an angle more than 2e-7 rad from the extreme one, far
 * beyond the few ulps of atan2 and of the division, so it cannot be the
 * smallest (largest) angle; past |r*| > TQ_PRUNE_MAX (angles within 1e-6
 * rad of 0 or 180 degrees) nothing is skipped. smooth_mesh.c's star
 * scores skip tets by the same rule. */
#define TQ_PRUNE_GAP 1e-6
#define TQ_PRUNE_MAX 1e6

/* The range from the six pairs: the angles of the edges whose ratio is
 * near the extremes, each tetqual's angle bit for bit (dihedral: the same
 * y, x and atan2), so the minimum and maximum are st_tet_dihedrals'. */
static void range_of_pairs(const double y[6], const double x[6], double *lo, double *hi)
{
    double r[6], rmax = -INFINITY, rmin = INFINITY;
    for (int i = 0; i < 6; i++) {
        r[i] = x[i] / y[i];
        rmax = r[i] > rmax ? r[i] : rmax;
        rmin = r[i] < rmin ? r[i] : rmin;
    }
    double cut_lo = -INFINITY, cut_hi = INFINITY;
    if (fabs(rmax) <= TQ_PRUNE_MAX)
        cut_lo = rmax - TQ_PRUNE_GAP * (1.0 + fabs(rmax)) * (1.0 + fabs(rmax));
    if (fabs(rmin) <= TQ_PRUNE_MAX)
        cut_hi = rmin + TQ_PRUNE_GAP * (1.0 + fabs(rmin)) * (1.0 + fabs(rmin));
    *lo = INFINITY;
    *hi = -INFINITY;
    for (int i = 0; i < 6; i++) {
        const int near_lo = !(r[i] < cut_lo), near_hi = !(r[i] > cut_hi);
        if (!near_lo && !near_hi)
            continue;
        double a = atan2(y[i], x[i]) * RAD2DEG;
        if (near_lo && a < *lo)
            *lo = a;
        if (near_hi && a > *hi)
            *hi = a;
    }
}

void st_tet_dihedral_range(const double p0[3], const double p1[3],
                           const double p2[3], const double p3[3],
                           double *min_deg, double *max_deg)
{
    double lo, hi, y[6], x[6];
    if (tq_tet_pairs(p0, p1, p2, p3, y, x)) {
        range_of_pairs(y, x, &lo, &hi);
    } else {
        /* a degenerate pair: the angles one by one (dihedral's 0 for a
         * face without area or a value not finite) */
        double a[6];
        st_tet_dihedrals(p0, p1, p2, p3, a);
        lo = a[0];
        hi = a[0];
        for (int i = 1; i < 6; i++) {
            if (a[i] < lo)
                lo = a[i];
            if (a[i] > hi)
                hi = a[i];
        }
    }
    if (min_deg)
        *min_deg = lo;
    if (max_deg)
        *max_deg = hi;
}

int st_tet_circumcenter(const double p0[3], const double p1[3],
                        const double p2[3], const double p3[3],
                        double c[3])
{
    double a[3], b[3], d[3], bd[3], da[3], ab[3];
    st_sub3(a, p1, p0);
    st_sub3(b, p2, p0);
    st_sub3(d, p3, p0);
    st_cross3(bd, b, d);
    st_cross3(da, d, a);
    st_cross3(ab, a, b);
    const double den = 2.0 * st_dot3(a, bd);
    const double la = st_dot3(a, a), lb = st_dot3(b, b), ld = st_dot3(d, d);
    int ok = den != 0.0;
    double r[3];
    for (int i = 0; i < 3 && ok; i++) {
        r[i] = (la * bd[i] + lb * da[i] + ld * ab[i]) / den;
        ok = isfinite(r[i]);
    }
    if (!ok) {
        for (int i = 0; i < 3; i++)
            c[i] = 0.25 * (p0[i] + p1[i] + p2[i] + p3[i]);
        return 0;
    }
    for (int i = 0; i < 3; i++)
        c[i] = p0[i] + r[i];
    return 1;
}
