/*
 * fit_swept.c - the fit invariant's point test for a boundary vertex,
 * without gathering the star's points (issue 23): only the S vertices in
 * the region the star's boundary faces sweep can leave the star.
 *
 * The claim. Let v be a boundary vertex of a mesh in which no face has
 * more than two tets (fit_ctx.full_check 0, invariant.h), moving from x
 * to p, its star positive at both (every tet orient3d < 0; sm_move_ok
 * tests p, the caller x). R(y) is the closed star with v at y; L its
 * faces not holding v (the link, which does not move); C(y) the boundary
 * faces holding v, (y, a, b).
 * Faces holding v shared by two star tets cancel in the boundary chain (two
 * positive tets on one face lie on its two sides, so they induce opposite
 * orientations), so the chain boundary of the star is L + C(y), and at a
 * point off every face the count of star tets holding it (positive tets)
 * is the winding number of L + C(y). The chain boundary of C(y) has no
 * edge holding v (it is minus that of L), so C(x) - C(p) is the boundary
 * of H = sum over the faces of the tets (x, p, a, b): the two counts differ
 * only inside the union of those closed tets. A point q of R(x) \ R(p) has
 * near it points inside a tet of R(x) and off R(p) (which is closed), off
 * every face: there the counts are >= 1 and 0, so they lie in a tet of H,
 * and so does q (finitely many closed tets). So every S vertex that leaves
 * the star lies in some closed (x, p, a, b): testing those S vertices alone
 * decides "every S vertex of R(x) is in R(p)" as the full list does, and
 * fails on a point that leaves (the blocker only orders the work).
 *
 * The sweep is thin for a small move, so most S vertices near the faces
 * are rejected by one plane test: q strictly on the other side of the plane
 * (x, a, b) from p, or of (p, a, b) from x, is not in the closed tet (for a
 * flat tet, p on the plane: q off it). The plane tests are pred.h's
 * st_plane_filter (orient3d's determinant with the face's two edge vectors
 * and their cross products computed once per face, filtered by orient3d's
 * error bound with a margin); a sign the filter cannot certify rejects
 * nothing. What passes is decided exactly by
 * st_point_in_tet and the star tests: no decision is taken in floating
 * point.
 *
 * Whole bins first. On a large soup a star's box holds hundreds of
 * thousands of S vertices and the sweep, a few thin slivers, meets few of
 * its bins. A bin's points lie in a box (the bin's extent widened against
 * rounding, cut to the scan's box); a face whose box
 * misses it, or whose plane filter rejects all eight of its corners,
 * rejects every point in it (the plane's determinant is affine in q, so a
 * sign the filter certifies at the corners holds inside), and a bin no
 * face keeps is skipped. Only points every face would have rejected are
 * skipped, in the same order: the answer and the failed point are the
 * per-point scan's.
 */
#include "fit_swept.h"
#include "../base/fpenv.h"

#include "souptet/isect.h"
#include "souptet/pred.h"
#include "../base/bits.h"

#include <math.h>
#include <stddef.h>

/* Boundary faces of a vertex handled here; a vertex with more (none in a
 * lattice) takes the gathering path. */
#define SWEPT_MAX_FACES 48
/* Bins an axis whose extents sm_swept_kept keeps at once: sm_pgrid_build
 * makes at most 256. */
#define SWEPT_SPAN 256
/* 1 when q lies in the closed star of v with v at y. */
static int in_closed_star(const sm_mesh *sm, uint32_t v, const double y[3], const double q[3])
{
    for (size_t j = sm->vt_off[v]; j < sm->vt_off[v + 1]; j++) {
        const uint32_t *c = sm->m->tets + 4 * (size_t)sm->vt[j];
        const double *t[4];
        for (int k = 0; k < 4; k++)
            t[k] = c[k] == v ? y : sm->m->xyz + 3 * (size_t)c[k];
        if (st_point_in_tet(q, t[0], t[1], t[2], t[3]) != ST_OUTSIDE)
            return 1;
    }
    return 0;
}

/* The smaller and the larger of two coordinates (finite here; libm's fmin
 * and fmax are calls). */
static inline double dmin(double a, double b)
{
    return a < b ? a : b;
}

static inline double dmax(double a, double b)
{
    return a > b ? a : b;
}

/* A face's plane filter with its box test's corner choice (box_rejected). */
typedef struct box_plane {
    st_plane_filter pl;
    int first;    /* bit k: hi along axis k where side * n_k > 0 */
    int unsure;   /* bit k: n_k's sign not certain */
} box_plane;

/* The plane through o, a and b (st_plane_filter_plane) with the side
 * st_plane_filter_init(o, a, b, r) gives a reference point r for which
 * st_orient3d(o, a, b, r) has sign s, and its corner choice. */
static void box_plane_init(box_plane *bp, const double o[3], const double a[3],
                           const double b[3], int s)
{
    st_plane_filter_plane(&bp->pl, o, a, b);
    bp->pl.side = s < 0 ? 1 : (s > 0 ? -1 : 0);
    bp->first = bp->unsure = 0;
    for (int k = 0; k < 3; k++) {
        if ((double)bp->pl.side * bp->pl.n[k] > 0.0)
            bp->first |= 1 << k;
        if (!(fabs(bp->pl.n[k]) > ST_PLANE_FILTER_REL * bp->pl.an[k] + ST_PLANE_FILTER_ABS))
            bp->unsure |= 1 << k;
    }
}

/* The two face planes of the swept tet (x, p, a, b) through a and b, each
 * with the opposite corner as reference: (x, a, b) and p, (p, a, b) and x.
 * One orient3d gives both sides: s = st_orient3d(x, a, b, p), and
 * orient3d(p, a, b, x) is -s (a transposition). (The side planes (x, p, a)
 * and (x, p, b) as well cut the bins kept and cost more: armadillo 7,
 * sm_swept_kept 180.8 -> 198.7 M.) */
static void swept_planes(box_plane pl[2], const double x[3], const double p[3],
                         const double a[3], const double b[3])
{
    const int s = st_sign(st_orient3d(x, a, b, p));
    box_plane_init(&pl[0], x, a, b, s);
    box_plane_init(&pl[1], p, a, b, -s);
}

/* 1 when the filter certifies every point of the box lo..hi strictly on
 * the side that rejects (with r on the plane nothing is claimed).
 *
 * The plane's exact determinant at q is N . (q - o), N the exact cross
 * product the filter's n rounds, affine in q: over the box, side * N . q is
 * largest at the corner that takes hi along the axes where side * N_k > 0
 * and lo where it is < 0 (either where N_k = 0). Where n_k's sign is
 * certain (|n_k| beyond the rounding of its two products of rounded
 * differences and their difference, about 4 u an_k, here 16 u an_k and
 * 2^-1000 for underflow), N_k has it; where it is not, both ends are
 * tried. When the filter rejects each corner tried, the exact determinant
 * is strictly on the rejecting side at the box's largest corner, so at
 * every point of it: the claim of rejecting all eight corners (until
 * session 57), with one test for most faces. */
static inline int box_rejected(const box_plane *bp, const double lo[3], const double hi[3])
{
    if (bp->pl.side == 0)
        return 0;
    /* the subsets s of the unsure axes, the empty one first */
    int s = 0;
    do {
        const int c = bp->first ^ s;
        const double q[3] = {c & 1 ? hi[0] : lo[0], c & 2 ? hi[1] : lo[1], c & 4 ? hi[2] : lo[2]};
        if (!st_plane_filter_rejects(&bp->pl, q))
            return 0;
        s = (s - bp->unsure) & bp->unsure;
    } while (s != 0);
    return 1;
}

/* A bound on st_plane_filter_sign's error bound for every point q of the
 * box lo..hi: its expression at A_k = max |fl(lo_k - o_k)|, |fl(hi_k -
 * o_k)|. Rounding is monotone, so |fl(q_k - o_k)| <= A_k, and the
 * expression (sums and products of non-negative terms, each rounded) does
 * not decrease as any |d_k| grows. */
static double box_bound(const st_plane_filter *pl, const double lo[3], const double hi[3])
{
    double A[3];
    for (int k = 0; k < 3; k++)
        A[k] = dmax(fabs(lo[k] - pl->o[k]), fabs(hi[k] - pl->o[k]));
    double perm = A[0] * pl->an[0] + A[1] * pl->an[1] + A[2] * pl->an[2];
    return ST_PLANE_FILTER_REL * perm + (A[0] + A[1] + A[2] + 1.0) * ST_PLANE_FILTER_ABS;
}

/* st_plane_filter_rejects(pl, q) for q in a box whose box_bound is B: the
 * filter's determinant beyond B is beyond q's own bound too, so the sign
 * is the filter's without its bound; within B, the filter decides. */
static inline int rejects_within(const st_plane_filter *pl, double B, const double q[3])
{
    const double det = (q[0] - pl->o[0]) * pl->n[0] + (q[1] - pl->o[1]) * pl->n[1] +
                       (q[2] - pl->o[2]) * pl->n[2];
    if (det > B)
        return pl->side != 1;
    if (-det > B)
        return pl->side != -1;
    return st_plane_filter_rejects(pl, q);
}

/* The margin of the bins' extents along axis a: m = 1e-10 of the grid's
 * coordinates (sm_pgrid_coord's rounding is a few units of 2^-53 of them).
 * NaN when m is not small beside a bin (then nothing is skipped). */
static double bin_margin(const pgrid *g, int a)
{
    double m = 1e-10 * (fabs(g->lo[a]) + (double)g->n[a] * g->cell);
    return m < 0.01 * g->cell ? m : NAN;
}

/* The extent of bin i along axis a holding every point the grid puts
 * there, cut to lo..hi: the bin widened by the margin m (bin_margin), the
 * end bins open (clamped coordinates). */
static void bin_extent(const pgrid *g, size_t i, int a, double m, double lo, double hi,
                       double out[2])
{
    double b0 = i == 0 ? -INFINITY : g->lo[a] + (double)i * g->cell - m;
    double b1 = i + 1 >= g->n[a] ? INFINITY : g->lo[a] + (double)(i + 1) * g->cell + m;
    out[0] = dmax(b0, lo);
    out[1] = dmin(b1, hi);
}

/* The faces (bits) that may hold a point of the bin box blo..bhi; 0 when
 * none can (or the box is empty). */
static uint64_t bin_faces(size_t nf, const double (*box)[6], const box_plane (*pl)[2],
                          const double blo[3], const double bhi[3])
{
    uint64_t keep = 0;
    for (int a = 0; a < 3; a++)
        if (blo[a] > bhi[a])
            return 0;
    for (size_t i = 0; i < nf; i++) {
        const double *bx = box[i];
        if (bhi[0] < bx[0] || bhi[1] < bx[1] || bhi[2] < bx[2] || blo[0] > bx[3] ||
            blo[1] > bx[4] || blo[2] > bx[5])
            continue;
        if (box_rejected(&pl[i][0], blo, bhi) || box_rejected(&pl[i][1], blo, bhi))
            continue;
        keep |= (uint64_t)1 << i;
    }
    return keep;
}

int sm_swept_applies(const sm_mesh *sm, uint32_t v)
{
    return sm->vf_off[v + 1] - sm->vf_off[v] <= SWEPT_MAX_FACES;
}

int sm_swept_kept(const sm_mesh *sm, const pgrid *g, uint32_t v, const double p[3],
                  uint32_t *failed, int *empty)
{
    int scratch;
    if (!empty)
        empty = &scratch;
    *empty = 0;
    const size_t nf = sm->vf_off[v + 1] - sm->vf_off[v];
    if (nf > SWEPT_MAX_FACES)
        return -1;
    if (g->npts == 0 || nf == 0)
        return 1;
    const double *x = sm->m->xyz + 3 * (size_t)v;
    box_plane pl[SWEPT_MAX_FACES][2];   /* swept_planes: in and out */
    double box[SWEPT_MAX_FACES][6];
    const double *ab[SWEPT_MAX_FACES][2];
    double lo[3], hi[3];
    for (int a = 0; a < 3; a++) {
        lo[a] = dmin(x[a], p[a]);
        hi[a] = dmax(x[a], p[a]);
    }
    for (size_t i = 0; i < nf; i++) {
        const uint32_t *k = sm->bf + 3 * (size_t)sm->vf[sm->vf_off[v] + i];
        int n = 0;
        for (int j = 0; j < 3; j++)
            if (k[j] != v)
                ab[i][n++] = sm->m->xyz + 3 * (size_t)k[j];
        if (n != 2)
            return -1;   /* not a face of v: leave it to the full test */
        swept_planes(pl[i], x, p, ab[i][0], ab[i][1]);
        for (int a = 0; a < 3; a++) {
            box[i][a] = dmin(dmin(x[a], p[a]), dmin(ab[i][0][a], ab[i][1][a]));
            box[i][3 + a] = dmax(dmax(x[a], p[a]), dmax(ab[i][0][a], ab[i][1][a]));
            lo[a] = dmin(lo[a], box[i][a]);
            hi[a] = dmax(hi[a], box[i][3 + a]);
        }
    }
    size_t a0[3], a1[3];
    for (int a = 0; a < 3; a++) {
        a0[a] = sm_pgrid_coord(g, lo[a], a);
        a1[a] = sm_pgrid_coord(g, hi[a], a);
    }
    /* per face, the bin's bounds of its two planes' filters (box_bound;
     * infinite: the filter decides every point) */
    double bnd[SWEPT_MAX_FACES][2];
    for (size_t i = 0; i < nf; i++)
        bnd[i][0] = bnd[i][1] = INFINITY;
    int flat = 0;   /* a degenerate swept tet: p on its face's plane */
    for (size_t i = 0; i < nf; i++)
        flat |= pl[i][0].pl.side == 0;
    int met = 0;    /* an S vertex in a swept tet */
    const uint64_t all = ((uint64_t)1 << nf) - 1;   /* nf <= SWEPT_MAX_FACES < 64 */
    /* the margins and each scanned bin's extent along each axis, once per
     * call (the grid has at most SWEPT_SPAN bins an axis: pgrid.c) */
    const double m[3] = {bin_margin(g, 0), bin_margin(g, 1), bin_margin(g, 2)};
    int whole_bins = !isnan(m[0]) && !isnan(m[1]) && !isnan(m[2]);
    double ext[3][SWEPT_SPAN][2];
    for (int a = 0; a < 3 && whole_bins; a++) {
        if (a1[a] - a0[a] >= SWEPT_SPAN) {
            whole_bins = 0;   /* not from sm_pgrid_build: scan every bin */
            break;
        }
        for (size_t i = a0[a]; i <= a1[a]; i++)
            bin_extent(g, i, a, m[a], lo[a], hi[a], ext[a][i - a0[a]]);
    }
    for (size_t iz = a0[2]; iz <= a1[2]; iz++) {
        for (size_t iy = a0[1]; iy <= a1[1]; iy++) {
            for (size_t ix = a0[0]; ix <= a1[0]; ix++) {
                size_t b = ix + g->n[0] * (iy + g->n[1] * iz);
                if (g->off[b] == g->off[b + 1])
                    continue;
                uint64_t keep = all;
                if (whole_bins) {
                    const double *ex = ext[0][ix - a0[0]], *ey = ext[1][iy - a0[1]],
                                 *ez = ext[2][iz - a0[2]];
                    const double blo[3] = {ex[0], ey[0], ez[0]}, bhi[3] = {ex[1], ey[1], ez[1]};
                    keep = bin_faces(nf, (const double(*)[6])box, (const box_plane(*)[2])pl, blo, bhi);
                    /* the bin's points lie in blo..bhi (cut to lo..hi,
                     * which the scan below checks first) */
                    for (uint64_t kb = keep; kb; kb &= kb - 1) {
                        const size_t i = (size_t)st_lowest_bit(kb);
                        bnd[i][0] = box_bound(&pl[i][0].pl, blo, bhi);
                        bnd[i][1] = box_bound(&pl[i][1].pl, blo, bhi);
                    }
                }
                for (size_t j = g->off[b]; keep && j < g->off[b + 1]; j++) {
                    const double *q = g->bpts + 3 * j;
                    if (q[0] < lo[0] || q[0] > hi[0] || q[1] < lo[1] || q[1] > hi[1] ||
                        q[2] < lo[2] || q[2] > hi[2])
                        continue;
                    int swept = 0;
                    /* the faces the bin keeps, in index order */
                    for (uint64_t kb = keep; kb && !swept; kb &= kb - 1) {
                        const size_t i = (size_t)st_lowest_bit(kb);
                        const double *bx = box[i];
                        if (q[0] < bx[0] || q[1] < bx[1] || q[2] < bx[2] || q[0] > bx[3] ||
                            q[1] > bx[4] || q[2] > bx[5])
                            continue;
                        if (rejects_within(&pl[i][0].pl, bnd[i][0], q) ||
                            rejects_within(&pl[i][1].pl, bnd[i][1], q))
                            continue;
                        swept = st_point_in_tet(q, x, p, ab[i][0], ab[i][1]) != ST_OUTSIDE;
                    }
                    met |= swept;
                    if (swept && in_closed_star(sm, v, x, q) && !in_closed_star(sm, v, p, q)) {
                        *failed = g->idx[j];
                        return 0;
                    }
                }
            }
        }
    }
    *empty = !flat && !met;
    return 1;
}
