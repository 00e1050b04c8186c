/*
 * test_pseudo.c - the pseudo volume's entry point (pseudo.h) and the
 * sides of an oriented soup (sides.h): one call gives what the steps give
 * one by one, and large holes close: a box with a whole face missing (of
 * any size), a thin plate with half of one face gone, a one-sided
 * hemisphere shell, a one-sided scan of a ball whose horizon is not
 * flat; an unoriented soup gives what an oriented one gives; the sides'
 * evidence from far-field bounds is the brute-force winding sum.
 */
#include "souptet/pseudo.h"
#include "souptet/solid.h"
#include "shapes.h"
#include "tap.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* An axis-aligned box's faces as an oriented soup, leaving out the faces
 * `skip` says (axis, side, the face's center), each face split into n x n
 * quads so that part of one can go. */
typedef int (*skip_fn)(int axis, int side, const double c[3]);

static void add_box_faces(st_soup *s, const double lo[3], const double hi[3], int n, skip_fn skip,
                          int flip_some)
{
    for (int axis = 0; axis < 3; axis++)
        for (int side = 0; side < 2; side++) {
            const int u = (axis + 1) % 3, w = (axis + 2) % 3;
            for (int a = 0; a < n; a++)
                for (int b = 0; b < n; b++) {
                    double q[4][3], c[3] = {0, 0, 0};
                    for (int k = 0; k < 4; k++) {
                        const int ia = a + (k == 1 || k == 2), ib = b + (k >= 2);
                        q[k][axis] = side ? hi[axis] : lo[axis];
                        q[k][u] = lo[u] + (hi[u] - lo[u]) * ia / n;
                        q[k][w] = lo[w] + (hi[w] - lo[w]) * ib / n;
                        for (int d = 0; d < 3; d++)
                            c[d] += 0.25 * q[k][d];
                    }
                    if (skip && skip(axis, side, c))
                        continue;
                    const int f = flip_some && ((a + b) & 1);
                    add_tri(s, q[0], q[1], q[2], !side ^ f);
                    add_tri(s, q[0], q[2], q[3], !side ^ f);
                }
        }
}

/* IoU of the pseudo volume of `s` (a field of `cells` voxels along the
 * longest side) with the solid of the closed `truth` by `rule`. */
static double iou_by(const st_soup *s, const st_soup *truth, size_t cells,
                     const st_pseudo_params *pp, st_solid_rule rule)
{
    st_dist_params dp = st_dist_params_default();
    dp.cells = cells;
    st_grid *g = NULL;
    st_error err;
    double iou = -1, prec, rec;
    if (st_pseudo_volume(&g, s, &dp, pp, NULL, NULL, &err))
        return -1;
    uint8_t *in = malloc(st_grid_count(g));
    const st_soup *shells[1] = {truth};
    if (in && !st_solid_inside(in, g, shells, 1, rule, &err))
        st_solid_iou(&iou, &prec, &rec, in, g, &err);
    free(in);
    st_grid_free(g);
    return iou;
}

static double iou_of(const st_soup *s, const st_soup *truth, size_t cells,
                     const st_pseudo_params *pp)
{
    return iou_by(s, truth, cells, pp, ST_SOLID_NONZERO);
}

static int top_face(int axis, int side, const double c[3])
{
    (void)c;
    return axis == 2 && side == 1;
}
static int big_side_face(int axis, int side, const double c[3])
{
    (void)c;
    return axis == 1 && side == 0;
}
static int half_top(int axis, int side, const double c[3])
{
    return axis == 2 && side == 1 && c[0] < 1.0;
}

static void test_entry_point(void)
{
    /* st_pseudo_volume is the field and then st_pseudo_sign: the same bytes */
    st_soup *s = st_soup_new();
    const double lo[3] = {0, 0, 0}, hi[3] = {1, 0.7, 0.5};
    add_box_faces(s, lo, hi, 3, top_face, 1);
    st_pseudo_params pp = st_pseudo_params_default();
    st_dist_params dp = st_dist_params_default();
    dp.cells = 40;
    st_grid *a = NULL, *b = NULL;
    st_error err;
    st_pseudo_stats st;
    int ok = !st_pseudo_volume(&a, s, &dp, &pp, &st, NULL, &err) &&
             !st_dist_field(&b, s, &dp, NULL, &err) &&
             !st_pseudo_sign(b, s, &pp, NULL, NULL, &err);
    TAP_CHECK(ok, "st_pseudo_volume and st_dist_field + st_pseudo_sign both run");
    TAP_CHECK(ok && st_grid_count(a) == st_grid_count(b) &&
              memcmp(a->data, b->data, st_grid_count(a) * sizeof(float)) == 0,
              "they give identical signs and distances");
    TAP_CHECK(ok && st.holes.filled == 1 && st.sides.regions >= 1 && st.inside > 0,
              "the stats say what ran (%zu loops capped, %zu regions, %zu inside)",
              st.holes.filled, st.sides.regions, st.inside);
    TAP_CHECK(ok && st_meta_get(&a->meta, "hole_caps") && st_meta_get(&a->meta, "sign_rule") &&
              st_meta_get(&a->meta, "closed_shells"), "and record it in the metadata");
    st_grid_free(a);
    st_grid_free(b);
    /* without the soup: the vote alone, nothing else */
    b = NULL;
    ok = !st_dist_field(&b, s, &dp, NULL, &err) && !st_pseudo_sign(b, NULL, &pp, &st, NULL, &err);
    TAP_CHECK(ok && !st.surface && st.holes.loops == 0 && !st_meta_get(&b->meta, "hole_caps"),
              "no soup: the vote alone");
    st_grid_free(b);
    st_soup_free(s);
}

static void test_large_holes(void)
{
    const st_pseudo_params pp = st_pseudo_params_default();
    /* a box without one whole face, of three sizes and shapes */
    const double his[3][3] = {{1, 1, 1}, {4, 1, 1}, {3, 2, 0.3}};
    for (int k = 0; k < 3; k++) {
        const double lo[3] = {0, 0, 0};
        st_soup *s = st_soup_new(), *t = st_soup_new();
        add_box_faces(s, lo, his[k], 2, k == 2 ? top_face : big_side_face, 0);
        add_box_oriented(t, lo, his[k]);
        const double iou = iou_of(s, t, 64, &pp);
        TAP_CHECK(iou >= 0.999, "a %gx%gx%g box without its %s face signs as the full box "
                  "(IoU %.4f)", his[k][0], his[k][1], his[k][2], k == 2 ? "largest" : "y = 0",
                  iou);
        st_soup_free(s);
        st_soup_free(t);
    }
    /* a thin plate with half of its top face gone, faces turned at random */
    {
        const double lo[3] = {0, 0, 0}, hi[3] = {2, 1, 0.1};
        st_soup *s = st_soup_new(), *t = st_soup_new();
        add_box_faces(s, lo, hi, 8, half_top, 1);
        add_box_oriented(t, lo, hi);
        const double iou = iou_of(s, t, 96, &pp);
        TAP_CHECK(iou >= 0.99, "a thin plate with half of one face missing (IoU %.4f)", iou);
        st_soup_free(s);
        st_soup_free(t);
    }
}

static void test_hemisphere(void)
{
    /* the lower half of a UV sphere, open at its equator: closes there */
    st_soup *s = st_soup_new(), *t = st_soup_new();
    add_sphere(s, 1.0, 1e-9);
    add_sphere(t, 1.0, 1e-9);
    /* the truth: the same shell and the disc across its rim (its faces
     * turned at random, so compared by parity) */
    const int nu = 32;
    for (int j = 0; j < nu; j++) {
        const double p0 = 2 * M_PI * j / nu, p1 = 2 * M_PI * (j + 1) / nu;
        const double a[3] = {cos(p0), sin(p0), cos(M_PI / 2)};
        const double b[3] = {cos(p1), sin(p1), cos(M_PI / 2)};
        const double c[3] = {0, 0, cos(M_PI / 2)};
        add_tri(t, a, b, c, 0);
    }
    const st_pseudo_params pp = st_pseudo_params_default();
    /* t is closed but not consistently oriented: compare by parity */
    const double iou = iou_by(s, t, 64, &pp, ST_SOLID_PARITY);
    TAP_CHECK(iou >= 0.98, "a one-sided hemisphere shell closes across its rim (IoU %.4f)",
              iou);
    st_soup_free(s);
    st_soup_free(t);
}

/* A ball whose equator waves (z + a cos(3 phi) sin^2 theta), outward:
 * all of it (up < 0), or only its faces that face up (up > 0). */
static void add_wavy_ball(st_soup *s, double a, int up)
{
    const int nu = 48, nv = 24;
    for (int i = 0; i < nv; i++)
        for (int j = 0; j < nu; j++) {
            double p[4][3];
            for (int c = 0; c < 4; c++) {
                int ii = i + (c >= 2), jj = j + (c == 1 || c == 2);
                double th = M_PI * ii / nv, ph = 2 * M_PI * jj / nu;
                p[c][0] = sin(th) * cos(ph);
                p[c][1] = sin(th) * sin(ph);
                p[c][2] = cos(th) + a * cos(3 * ph) * sin(th) * sin(th);
            }
            const int tri[2][3] = {{0, 2, 1}, {0, 3, 2}};   /* outward */
            for (int k = 0; k < 2; k++) {
                const double *A = p[tri[k][0]], *B = p[tri[k][1]], *C = p[tri[k][2]];
                const double nz = (B[0] - A[0]) * (C[1] - A[1]) - (B[1] - A[1]) * (C[0] - A[0]);
                if (up > 0 && nz < 0.0)
                    continue;
                add_tri(s, A, B, C, 0);
            }
        }
}

static void test_onesided(void)
{
    /* A one-sided scan from above of a ball whose horizon waves (not flat,
     * so no hole cap): the least-area closure stops at the horizon; the
     * mirror (sides.h) continues it below by as much as above. */
    st_soup *s = st_soup_new(), *t = st_soup_new();
    add_wavy_ball(s, 0.3, 1);
    add_wavy_ball(t, 0.3, -1);
    st_pseudo_params pp = st_pseudo_params_default();
    const double with = iou_of(s, t, 64, &pp);
    pp.sides_params.onesided_ratio = 0.0;
    const double without = iou_of(s, t, 64, &pp);
    TAP_CHECK(with >= 0.85 && with > without + 0.2,
              "a one-sided scan of a wavy ball closes below its horizon (IoU %.4f, %.4f "
              "without the mirror)", with, without);
    /* the whole ball is not one-sided: the mirror leaves it alone */
    st_pseudo_stats st;
    st_dist_params dp = st_dist_params_default();
    dp.cells = 32;
    st_grid *g = NULL;
    st_error err;
    pp = st_pseudo_params_default();
    const int ok = !st_pseudo_volume(&g, t, &dp, &pp, &st, NULL, &err);
    TAP_CHECK(ok && !st.sides.onesided && st.mirrored == 0 && st.sides.back_front > 0.9,
              "a closed ball is not one-sided (back/front %.3f)", st.sides.back_front);
    st_grid_free(g);
    st_soup_free(s);
    st_soup_free(t);
}

static void test_sides_orientation(void)
{
    /* The sides' evidence does not read the file's orientation: a box
     * without its top, faces turned at random or all the right way, gives
     * the same evidence; and it is positive inside, negative outside. */
    const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
    st_soup *a = st_soup_new(), *b = st_soup_new();
    add_box_faces(a, lo, hi, 4, top_face, 0);
    add_box_faces(b, lo, hi, 4, top_face, 1);
    st_dist_params dp = st_dist_params_default();
    dp.cells = 32;
    st_grid *g = NULL;
    st_error err;
    int ok = !st_dist_field(&g, a, &dp, NULL, &err);
    const size_t n = ok ? st_grid_count(g) : 1;
    uint8_t *maj = malloc(n);
    int8_t *ea = malloc(n), *eb = malloc(n);
    const st_sides_params sp = st_sides_params_default();
    const st_sign_params sgp = st_sign_params_default();
    st_sides_stats sa, sb;
    ok = ok && maj && ea && eb && !st_sign_votes(g, &sgp, maj, &err) &&
         !st_sides_evidence(ea, g, maj, 0, a, &sp, &sa, &err) &&
         !st_sides_evidence(eb, g, maj, 0, b, &sp, &sb, &err);
    TAP_CHECK(ok && memcmp(ea, eb, n) == 0, "the same evidence for faces turned at random");
    TAP_CHECK(ok && sa.regions == 1 && sb.regions == 1,
              "one orientable region each (%zu, %zu)", ok ? sa.regions : 0, ok ? sb.regions : 0);
    if (ok) {
        /* a voxel a voxel and a half inside the bottom wall, one outside it */
        const double vx = g->voxel;
        size_t in_i = 0, out_i = 0;
        double best_in = 1e9, best_out = 1e9;
        for (size_t k = 0; k < g->nz; k++)
            for (size_t j = 0; j < g->ny; j++)
                for (size_t i = 0; i < g->nx; i++) {
                    const double x = g->origin[0] + vx * i, y = g->origin[1] + vx * j,
                                 z = g->origin[2] + vx * k;
                    const double dx = fabs(x - 0.5) + fabs(y - 0.5);
                    const double din = dx + fabs(z - 1.5 * vx), dout = dx + fabs(z + 1.5 * vx);
                    if (din < best_in) {
                        best_in = din;
                        in_i = st_grid_index(g, i, j, k);
                    }
                    if (dout < best_out) {
                        best_out = dout;
                        out_i = st_grid_index(g, i, j, k);
                    }
                }
        TAP_CHECK(ea[in_i] > 0 && ea[out_i] < 0, "inside the floor positive (%d), under it "
                  "negative (%d)", ea[in_i], ea[out_i]);
    } else
        TAP_CHECK(0, "inside the floor positive, under it negative");
    free(maj);
    free(ea);
    free(eb);
    st_grid_free(g);
    st_soup_free(a);
    st_soup_free(b);
}

/* The signed solid angle of (a, b, c) seen from q (Van Oosterom and
 * Strackee 1983), for the brute force below. */
static double tri_solid_angle(const double *A, const double *B, const double *C, const double q[3])
{
    double a[3], b[3], c[3];
    for (int k = 0; k < 3; k++) {
        a[k] = A[k] - q[k];
        b[k] = B[k] - q[k];
        c[k] = C[k] - q[k];
    }
    const double la = sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
    const double lb = sqrt(b[0] * b[0] + b[1] * b[1] + b[2] * b[2]);
    const double lc = sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
    const double det = a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
                       a[2] * (b[0] * c[1] - b[1] * c[0]);
    const double den = la * lb * lc + (a[0] * b[0] + a[1] * b[1] + a[2] * b[2]) * lc +
                       (b[0] * c[0] + b[1] * c[1] + b[2] * c[2]) * la +
                       (c[0] * a[0] + c[1] * a[1] + c[2] * a[2]) * lb;
    return 2.0 * atan2(det, den);
}

static void test_sides_far_field(void)
{
    /* A finely meshed ball (triangles much smaller than a voxel, shared
     * vertices, outward) with a cap cut off above z = 0.6: the evidence,
     * summed in part from far-field bounds, is the brute-force local
     * winding number of every triangle whose box meets the voxel's cube
     * (up to the one turn of the whole region to the votes); with
     * decided > 0 the cut sees the same sides; and most voxels never need
     * the triangle-by-triangle sum. */
    const int nu = 160, nv = 80;
    st_soup *s = st_soup_new();
    for (int i = 0; i <= nv; i++)
        for (int j = 0; j < nu; j++) {
            const double th = M_PI * i / nv, ph = 2 * M_PI * j / nu;
            st_soup_add_vertex(s, sin(th) * cos(ph), sin(th) * sin(ph), cos(th), NULL);
        }
    for (int i = 0; i < nv; i++)
        for (int j = 0; j < nu; j++) {
            const uint32_t a = (uint32_t)(i * nu + j), b = (uint32_t)(i * nu + (j + 1) % nu);
            const uint32_t c = a + (uint32_t)nu, d = b + (uint32_t)nu;
            if (cos(M_PI * i / nv) > 0.6)
                continue;
            if (i > 0)
                st_soup_add_triangle(s, a, c, b, NULL);
            if (i < nv - 1)
                st_soup_add_triangle(s, b, c, d, NULL);
        }
    st_dist_params dp = st_dist_params_default();
    dp.cells = 32;
    st_grid *g = NULL;
    st_error err;
    int ok = !st_dist_field(&g, s, &dp, NULL, &err);
    const size_t n = ok ? st_grid_count(g) : 1;
    uint8_t *votes = malloc(n);
    int8_t *e0 = malloc(n), *e1 = malloc(n);
    const st_sides_params sp = st_sides_params_default();
    const st_sign_params sgp = st_sign_params_default();
    const int decided = 10;
    st_sides_stats s0, s1;
    ok = ok && votes && e0 && e1 && !st_sign_votes(g, &sgp, votes, &err) &&
         !st_sides_evidence(e0, g, votes, 0, s, &sp, &s0, &err) &&
         !st_sides_evidence(e1, g, votes, decided, s, &sp, &s1, &err);
    TAP_CHECK(ok && s0.regions == 1, "one region (%zu)", ok ? s0.regions : 0);
    size_t wrong = 0, open = 0, same_side = 0, checked = 0;
    int turn = 0;
    if (ok) {
        const double r = sp.radius_voxels * g->voxel, scale = sp.weight / (4.0 * M_PI);
        const float band = (float)(sp.band_voxels * g->voxel);
        for (size_t z = 0; z < g->nz; z++)
            for (size_t y = 0; y < g->ny; y++)
                for (size_t x = 0; x < g->nx; x++) {
                    const size_t i = st_grid_index(g, x, y, z);
                    /* a quarter of the band's voxels, for time */
                    if (!(fabsf(g->data[i]) < band) || (x + y + z) % 4)
                        continue;
                    const double q[3] = {g->origin[0] + g->voxel * (double)x,
                                         g->origin[1] + g->voxel * (double)y,
                                         g->origin[2] + g->voxel * (double)z};
                    double sum = 0.0;
                    for (size_t t = 0; t < s->ntris; t++) {
                        const double *P[3];
                        int meets = 1;
                        for (int k = 0; k < 3; k++)
                            P[k] = s->xyz + 3 * (size_t)s->tris[3 * t + k];
                        for (int k = 0; k < 3; k++) {
                            const double lo = fmin(P[0][k], fmin(P[1][k], P[2][k]));
                            const double hi = fmax(P[0][k], fmax(P[1][k], P[2][k]));
                            meets &= lo <= q[k] + r && q[k] - r <= hi;
                        }
                        if (meets)
                            sum += tri_solid_angle(P[0], P[1], P[2], q);
                    }
                    double e = scale * sum;
                    e = e > sp.max_evidence ? sp.max_evidence
                      : e < -sp.max_evidence ? -sp.max_evidence : e;
                    const int want = (int)lround(e);
                    if (!turn && want)
                        turn = e0[i] == -want ? -1 : 1;
                    checked++;
                    /* the brute force sums in another order: a value within
                     * 1e-9 of a rounding boundary may round either way */
                    const double frac = fabs(e - floor(e));
                    if (e0[i] != turn * want && fabs(frac - 0.5) > 1e-9)
                        wrong++;
                    const int m = (int)(votes[i] & ST_SIGN_VOTES_COUNT) - 13;
                    if (abs(m) >= decided)
                        continue;
                    if (e1[i] != e0[i]) {
                        const int seen = m > 0 || (votes[i] & ST_SIGN_VOTES_SEEN);
                        if (seen && ((m + e0[i] >= decided && m + e1[i] >= decided) ||
                                     (m + e0[i] <= -decided && m + e1[i] <= -decided)))
                            same_side++;
                        else
                            open++;
                    }
                }
    }
    TAP_CHECK(ok && checked > 1000 && wrong == 0,
              "the evidence is the brute-force winding sum (%zu of %zu voxels differ)", wrong,
              checked);
    TAP_CHECK(ok && open == 0,
              "with decided voxels skipped the cut sees the same evidence (%zu differ, %zu on "
              "the same decided side)", open, same_side);
    TAP_CHECK(ok && s1.exact * 4 < s1.voxels,
              "most voxels' sums stay within their bound (%zu of %zu summed exactly; "
              "%zu of %zu when every value counts)", ok ? s1.exact : 0,
              ok ? s1.voxels : 0, ok ? s0.exact : 0, ok ? s0.voxels : 0);
    free(votes);
    free(e0);
    free(e1);
    st_grid_free(g);
    st_soup_free(s);
}

int main(void)
{
    test_entry_point();
    test_large_holes();
    test_hemisphere();
    test_onesided();
    test_sides_orientation();
    test_sides_far_field();
    return tap_done();
}
