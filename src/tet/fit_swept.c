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

/* 1 when the filter certifies every point of the box lo..hi strictly on
 * the side that rejects (st_plane_filter_rejects at all eight corners:
 * with r off the plane a rejected corner is on the side opposite r, so all
 * are on one side; with r on it, corners could straddle it, and nothing is
 * claimed). */
static int box_rejected(const st_plane_filter *pl, const double lo[3], const double hi[3])
{
    if (pl->side == 0)
        return 0;
    /* The corner furthest toward r's side first (bit k: hi along k where
     * the plane's normal leans that way): where any corner is kept, that
     * one is the likeliest, and most bins end after one test. The answer
     * is the same whichever order (all eight must be rejected). */
    int first = 0;
    for (int k = 0; k < 3; k++)
        if ((double)pl->side * pl->n[k] > 0.0)
            first |= 1 << k;
    for (int i = 0; i < 8; i++) {
        const int c = i ^ first;
        const double q[3] = {c & 1 ? hi[0] : lo[0], c & 2 ? hi[1] : lo[1], c & 4 ? hi[2] : lo[2]};
        if (!st_plane_filter_rejects(pl, q))
            return 0;
    }
    return 1;
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
    out[0] = fmax(b0, lo);
    out[1] = fmin(b1, hi);
}

/* The faces (bits) that may hold a point of the bin box blo..bhi; 0 when
 * none can (or the box is empty). */
static uint64_t bin_faces(size_t nf, const double (*box)[6], const st_plane_filter *in,
                          const st_plane_filter *out, const double blo[3], const double bhi[3])
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
        if (box_rejected(&in[i], blo, bhi) || box_rejected(&out[i], blo, bhi))
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
                  uint32_t *failed)
{
    const size_t nf = sm->vf_off[v + 1] - sm->vf_off[v];
    if (nf > SWEPT_MAX_FACES)
        return -1;
    if (g->npts == 0 || nf == 0)
        return 1;
    const double *x = sm->m->xyz + 3 * (size_t)v;
    st_plane_filter in[SWEPT_MAX_FACES], out[SWEPT_MAX_FACES];
    double box[SWEPT_MAX_FACES][6];
    const double *ab[SWEPT_MAX_FACES][2];
    double lo[3], hi[3];
    for (int a = 0; a < 3; a++) {
        lo[a] = fmin(x[a], p[a]);
        hi[a] = fmax(x[a], p[a]);
    }
    for (size_t i = 0; i < nf; i++) {
        const uint32_t *k = sm->bf + 3 * (size_t)sm->vf[sm->vf_off[v] + i];
        int n = 0;
        for (int j = 0; j < 3; j++)
            if (k[j] != v)
                ab[i][n++] = sm->m->xyz + 3 * (size_t)k[j];
        if (n != 2)
            return -1;   /* not a face of v: leave it to the full test */
        st_plane_filter_init(&in[i], x, ab[i][0], ab[i][1], p);
        st_plane_filter_init(&out[i], p, ab[i][0], ab[i][1], x);
        for (int a = 0; a < 3; a++) {
            box[i][a] = fmin(fmin(x[a], p[a]), fmin(ab[i][0][a], ab[i][1][a]));
            box[i][3 + a] = fmax(fmax(x[a], p[a]), fmax(ab[i][0][a], ab[i][1][a]));
            lo[a] = fmin(lo[a], box[i][a]);
            hi[a] = fmax(hi[a], box[i][3 + a]);
        }
    }
    size_t a0[3], a1[3];
    for (int a = 0; a < 3; a++) {
        a0[a] = sm_pgrid_coord(g, lo[a], a);
        a1[a] = sm_pgrid_coord(g, hi[a], a);
    }
    const uint64_t all = ((uint64_t)1 << nf) - 1;   /* nf <= SWEPT_MAX_FACES < 64 */
    /* the margins once per call, each axis's extent once per row */
    const double m[3] = {bin_margin(g, 0), bin_margin(g, 1), bin_margin(g, 2)};
    const int whole_bins = !isnan(m[0]) && !isnan(m[1]) && !isnan(m[2]);
    double ez[2], ey[2], ex[2];
    for (size_t iz = a0[2]; iz <= a1[2]; iz++) {
        if (whole_bins)
            bin_extent(g, iz, 2, m[2], lo[2], hi[2], ez);
        for (size_t iy = a0[1]; iy <= a1[1]; iy++) {
            if (whole_bins)
                bin_extent(g, iy, 1, m[1], lo[1], hi[1], ey);
            for (size_t ix = a0[0]; ix <= a1[0]; ix++) {
                size_t b = ix + g->n[0] * (iy + g->n[1] * iz);
                if (g->off[b] == g->off[b + 1])
                    continue;
                uint64_t keep = all;
                if (whole_bins) {
                    bin_extent(g, ix, 0, m[0], lo[0], hi[0], ex);
                    const double blo[3] = {ex[0], ey[0], ez[0]}, bhi[3] = {ex[1], ey[1], ez[1]};
                    keep = bin_faces(nf, (const double(*)[6])box, in, out, blo, bhi);
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
                        if (st_plane_filter_rejects(&in[i], q) || st_plane_filter_rejects(&out[i], q))
                            continue;
                        swept = st_point_in_tet(q, x, p, ab[i][0], ab[i][1]) != ST_OUTSIDE;
                    }
                    if (swept && in_closed_star(sm, v, x, q) && !in_closed_star(sm, v, p, q)) {
                        *failed = g->idx[j];
                        return 0;
                    }
                }
            }
        }
    }
    return 1;
}
