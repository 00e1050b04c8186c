/*
 * test_pseudo.c - the pseudo volume's entry point (pseudo.h) and the
 * sides of an oriented soup (sides.h): one call gives what the steps give
 * one by one, and large holes close: a box with a whole face missing (of
 * any size), a thin plate with half of one face gone, a one-sided
 * hemisphere shell, a one-sided scan of a ball whose horizon is not
 * flat, a block with a bore scanned from above; an unoriented soup gives what an oriented one gives; the steps
 * given the soup's edge table and BVH give what they give alone.
 */
#include "souptet/pseudo.h"
#include "souptet/shells.h"
#include "souptet/solid.h"
#include "shapes.h"
#include "tap.h"

#include <math.h>
#ifdef _OPENMP
#include <omp.h>
#endif
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
/* IoU of s's pseudo volume (cells, pp) against truth's solid by rule;
 * st (may be NULL) gets the pseudo volume's stats. */
static double iou_stats(const st_soup *s, const st_soup *truth, size_t cells,
                        const st_pseudo_params *pp, st_solid_rule rule, st_pseudo_stats *st)
{
    st_dist_params dp = st_dist_params_default();
    dp.cells = cells;
    st_grid *g = NULL;
    st_error err;
    double iou = -1, prec, rec;
    if (st_pseudo_volume(&g, s, &dp, pp, st, NULL, &err))
        return -1;
    uint8_t *in = malloc(st_grid_count(g));
    const st_soup *shells[1] = {truth};
    if (in && !st_solid_inside(in, g, shells, 1, rule, &err))
        st_solid_iou(&iou, &prec, &rec, in, g, &err);
    free(in);
    st_grid_free(g);
    return iou;
}

static double iou_by(const st_soup *s, const st_soup *truth, size_t cells,
                     const st_pseudo_params *pp, st_solid_rule rule)
{
    return iou_stats(s, truth, cells, pp, rule, NULL);
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
static int bottom_face(int axis, int side, const double c[3])
{
    (void)c;
    return axis == 2 && side == 0;
}
static int half_top(int axis, int side, const double c[3])
{
    return axis == 2 && side == 1 && c[0] < 1.0;
}
/* every other quad of the faces (a checkerboard) */
static int checker(int axis, int side, const double c[3])
{
    const int u = (int)floor(c[(axis + 1) % 3] * 4.0), w = (int)floor(c[(axis + 2) % 3] * 4.0);
    return (u + w + side) & 1;
}
/* the three faces' quads at the corner (0, 0, 0) of a box of side 2 cut
 * into 4 x 4 */
static int corner_quads(int axis, int side, const double c[3])
{
    return side == 0 && c[(axis + 1) % 3] < 0.5 && c[(axis + 2) % 3] < 0.5;
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
    /* a box without the corner of its three faces at (0, 0, 0): the hole's
     * loop is not flat, and its least-area cap cuts the corner off across
     * the loop; the cap that bends least continues each face along its
     * L-shaped edge and cuts off only the lost corner's tip (a 1/48 of the
     * quads' cube: IoU 0.9974) */
    {
        const double lo[3] = {0, 0, 0}, hi[3] = {2, 2, 2};
        st_soup *s = st_soup_new(), *t = st_soup_new();
        add_box_faces(s, lo, hi, 4, corner_quads, 0);
        add_box_oriented(t, lo, hi);
        /* the caps alone: the box's mirror planes would fill the corner
         * from the opposite ones (symmetry, on by default) either way */
        st_pseudo_params caps = pp;
        caps.symmetry = 0;
        st_pseudo_params area = caps;
        area.holes.bend = area.holes.planes = 0;
        st_pseudo_stats st;
        const double iou = iou_stats(s, t, 64, &caps, ST_SOLID_NONZERO, &st);
        const double least = iou_of(s, t, 64, &area);
        TAP_CHECK(iou >= 0.995 && iou > least && st.holes.continued,
                  "a box without a corner: its faces continued by default (IoU %.4f, rim %.3f "
                  "of the area; %.4f with the least-area cap)",
                  iou, st.holes.rim_share, least);
        st_soup_free(s);
        s = st_soup_new();
        /* every other quad gone: all that is left is rim, whose fragments'
         * planes say little: the least-area caps (as the deleted faces of
         * the corpus, where the bent caps lose) */
        add_box_faces(s, lo, hi, 8, checker, 0);
        const double frag = iou_stats(s, t, 64, &caps, ST_SOLID_NONZERO, &st);
        const double frag_area = iou_of(s, t, 64, &area);
        TAP_CHECK(!st.holes.continued && st.holes.rim_share > pp.holes.intact && frag == frag_area,
                  "a box with every other face quad gone keeps the least-area caps (rim %.3f "
                  "of the area, IoU %.4f)", st.holes.rim_share, frag);
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
    st_pseudo_stats st;
    const double iou = iou_stats(s, t, 64, &pp, ST_SOLID_PARITY, &st);
    TAP_CHECK(iou >= 0.98, "a one-sided hemisphere shell closes across its rim (IoU %.4f)",
              iou);
    /* and the column rule reads it as a scan from below */
    TAP_CHECK(st.sides.columns && st.sides.column_axis == 2 && st.sides.column_dir == -1,
              "it is a scan along -z (back/front %.3f)", st.sides.column_back_front);
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
    pp.shells_shortcut = 0;   /* the ball is one closed shell: the sides
                                 run only on the full path */
    const int ok = !st_pseudo_volume(&g, t, &dp, &pp, &st, NULL, &err);
    TAP_CHECK(ok && !st.sides.onesided && st.mirrored == 0 && st.sides.back_front > 0.9,
              "a closed ball is not one-sided (back/front %.3f)", st.sides.back_front);
    st_grid_free(g);
    st_soup_free(s);
    st_soup_free(t);
}

/* A torus lying flat (major radius 1, minor 0.35), outward: all of it
 * (up < 0), or its upper half only (up > 0): a scan from above, cut off at
 * its two equators, which are flat loops (the hole caps close them). */
static void add_torus(st_soup *s, int up)
{
    const int nu = 48, nv = 24;
    for (int i = 0; i < nu; i++)
        for (int j = 0; j < nv; j++) {
            if (up > 0 && j >= nv / 2)
                continue;
            double p[4][3];
            for (int c = 0; c < 4; c++) {
                const double u = 2 * M_PI * (i + (c == 1 || c == 2)) / nu;
                const double v = 2 * M_PI * (j + (c >= 2)) / nv;
                p[c][0] = (1.0 + 0.35 * cos(v)) * cos(u);
                p[c][1] = (1.0 + 0.35 * cos(v)) * sin(u);
                p[c][2] = 0.35 * sin(v);
            }
            add_tri(s, p[0], p[1], p[2], 0);
            add_tri(s, p[0], p[2], p[3], 0);
        }
}

static void test_onesided_caps(void)
{
    /* A one-sided scan of a torus cut off at its equators, the soup's
     * lowest points: by default the mirror stops there; with past_caps
     * (the view of the seen soup alone, the mirror past its caps and past
     * the soup's lowest point, only where the rim folds) it continues the
     * runs to the grid's end. */
    st_soup *s = st_soup_new(), *t = st_soup_new();
    add_torus(s, 1);
    add_torus(t, -1);
    st_pseudo_params pp = st_pseudo_params_default();
    const double plain = iou_of(s, t, 64, &pp);
    pp.sides_params.past_caps = 1;
    st_pseudo_stats st;
    double iou = iou_stats(s, t, 64, &pp, ST_SOLID_NONZERO, &st);
    TAP_CHECK(st.sides.onesided && st.sides.fold && st.mirrored > 0 && iou >= 0.95 &&
                  plain < 0.8,
              "with past_caps, a one-sided torus closes below its equators (IoU %.4f, "
              "%.4f by default; back/front %.3f, walls %.2f, %zu voxels mirrored)", iou, plain,
              st.sides.back_front, st.sides.walls, st.mirrored);
    TAP_CHECK(st.sides.view[2] > 0.99, "its view is within 8 degrees of its axis (%.4f %.4f %.4f)",
              st.sides.view[0], st.sides.view[1], st.sides.view[2]);
    /* A box scanned from above, its bottom unseen: the rim is walls along
     * the view, a crease where an unseen flat face begins; no mirror */
    st_soup *b = st_soup_new(), *bt = st_soup_new();
    const double lo[3] = {0, 0, 0}, hi[3] = {1, 0.7, 0.5};
    add_box_faces(b, lo, hi, 3, bottom_face, 0);
    add_box_oriented(bt, lo, hi);
    pp = st_pseudo_params_default();
    const double box_plain = iou_of(b, bt, 64, &pp);
    pp.sides_params.past_caps = 1;
    iou = iou_stats(b, bt, 64, &pp, ST_SOLID_NONZERO, &st);
    TAP_CHECK(st.sides.onesided && !st.sides.fold && st.sides.walls > 0.5 && st.mirrored == 0 &&
                  iou == box_plain,
              "a box seen from above: walls %.2f of its rim, not mirrored (IoU %.4f, %.4f by "
              "default)", st.sides.walls, iou, box_plain);
    st_soup_free(b);
    st_soup_free(bt);
    st_soup_free(s);
    st_soup_free(t);
}

/* The quad (x0..x1, y0..y1) at height z, or the wall over segment
 * (a, b) of the xy plane from z0 to z1: two triangles, either winding. */
static void add_hquad(st_soup *s, double x0, double x1, double y0, double y1, double z)
{
    const double p[4][3] = {{x0, y0, z}, {x1, y0, z}, {x1, y1, z}, {x0, y1, z}};
    add_tri(s, p[0], p[1], p[2], 0);
    add_tri(s, p[0], p[2], p[3], 0);
}
static void add_wall(st_soup *s, const double a[2], const double b[2], double z0, double z1)
{
    const double p[4][3] = {{a[0], a[1], z0}, {b[0], b[1], z0}, {b[0], b[1], z1},
                            {a[0], a[1], z1}};
    add_tri(s, p[0], p[1], p[2], 0);
    add_tri(s, p[0], p[2], p[3], 0);
}

/* The walls of the square ring through cuts (the corners' coordinates,
 * ncut of them, the same along x and y) from z0 to z1: each side split at
 * every cut, so that its edges meet the faces beside it. */
static void add_square_walls(st_soup *s, const double *cut, int ncut, double z0, double z1)
{
    const double lo = cut[0], hi = cut[ncut - 1];
    for (int i = 0; i + 1 < ncut; i++) {
        const double w[4][2][2] = {{{cut[i], lo}, {cut[i + 1], lo}},
                                   {{cut[i], hi}, {cut[i + 1], hi}},
                                   {{lo, cut[i]}, {lo, cut[i + 1]}},
                                   {{hi, cut[i]}, {hi, cut[i + 1]}}};
        for (int k = 0; k < 4; k++)
            add_wall(s, w[k][0], w[k][1], z0, z1);
    }
}

/* A block 1 x 1 x 0.5 with a square bore 0.2 wide from its top down to
 * z = 0.25 and a counterbore 0.5 wide from there to its bottom: the faces
 * a scan from above sees (up > 0: its top, every wall; no face that faces
 * down), or all of it (up < 0; not consistently oriented, for parity). */
static void add_counterbored(st_soup *s, int up)
{
    const double c4[4] = {0, 0.4, 0.6, 1}, bore[2] = {0.4, 0.6}, cb[2] = {0.25, 0.75};
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            if (i != 1 || j != 1)
                add_hquad(s, c4[i], c4[i + 1], c4[j], c4[j + 1], 0.5);
    add_square_walls(s, c4, 4, 0.0, 0.5);
    add_square_walls(s, bore, 2, 0.25, 0.5);
    add_square_walls(s, cb, 2, 0.0, 0.25);
    if (up > 0)
        return;
    /* the counterbore's ceiling and the bottom, around their openings */
    const double c4b[4] = {0.25, 0.4, 0.6, 0.75}, c4o[4] = {0, 0.25, 0.75, 1};
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            if (i != 1 || j != 1) {
                add_hquad(s, c4b[i], c4b[i + 1], c4b[j], c4b[j + 1], 0.25);
                add_hquad(s, c4o[i], c4o[i + 1], c4o[j], c4o[j + 1], 0.0);
            }
}

/* Voxels of g inside the pseudo volume whose centers are in the box
 * (lo, hi). */
static size_t inside_in_box(const st_grid *g, const double lo[3], const double hi[3])
{
    size_t n = 0;
    for (size_t z = 0; z < g->nz; z++)
        for (size_t y = 0; y < g->ny; y++)
            for (size_t x = 0; x < g->nx; x++) {
                const double p[3] = {g->origin[0] + g->voxel * (double)x,
                                     g->origin[1] + g->voxel * (double)y,
                                     g->origin[2] + g->voxel * (double)z};
                int in = 1;
                for (int k = 0; k < 3; k++)
                    in &= p[k] > lo[k] && p[k] < hi[k];
                n += in && g->data[st_grid_index(g, x, y, z)] < 0.0f;
            }
    return n;
}

/* A rule on and off (off turns it off in the params), on the pseudo
 * volume of s at 64 cells: the voxels inside the box (lo, hi) and the IoU
 * against truth's solid by rule, each way; st: the stats with it on. */
typedef struct on_off {
    int ok;
    st_pseudo_stats st;
    size_t in, in0;
    double with, without;
} on_off;

static on_off rule_on_off(const st_soup *s, const st_soup *truth, const double lo[3],
                          const double hi[3], void (*off)(st_pseudo_params *),
                          st_solid_rule rule)
{
    on_off r;
    memset(&r, 0, sizeof r);
    st_pseudo_params pp = st_pseudo_params_default();
    st_dist_params dp = st_dist_params_default();
    dp.cells = 64;
    st_grid *g = NULL, *g0 = NULL;
    st_error err;
    r.ok = !st_pseudo_volume(&g, s, &dp, &pp, &r.st, NULL, &err);
    off(&pp);
    r.ok = r.ok && !st_pseudo_volume(&g0, s, &dp, &pp, NULL, NULL, &err);
    r.in = r.ok ? inside_in_box(g, lo, hi) : 1;
    r.in0 = r.ok ? inside_in_box(g0, lo, hi) : 0;
    pp = st_pseudo_params_default();
    r.with = iou_by(s, truth, 64, &pp, rule);
    off(&pp);
    r.without = iou_by(s, truth, 64, &pp, rule);
    st_grid_free(g);
    st_grid_free(g0);
    return r;
}

static void columns_off(st_pseudo_params *pp)
{
    pp->sides_params.column_ratio = 0.0;
}

static void column_caps_off(st_pseudo_params *pp)
{
    pp->sides_params.column_caps = 0;
}

static void test_columns(void)
{
    /* A one-sided scan of a counterbored block, from above: the lines
     * through the bore cross none of the seen faces (its walls run along
     * them), so they are empty; without the column rule the caps close
     * the bore's bottom and the counterbore's ends, and the cut fills the
     * bore and the counterbore below it. */
    st_soup *s = st_soup_new(), *t = st_soup_new();
    add_counterbored(s, 1);
    add_counterbored(t, -1);
    const double lo[3] = {0.42, 0.42, 0.02}, hi[3] = {0.58, 0.58, 0.48};
    const on_off r = rule_on_off(s, t, lo, hi, columns_off, ST_SOLID_PARITY);
    TAP_CHECK(r.ok && r.st.sides.columns && r.st.sides.column_axis == 2 &&
                  r.st.sides.column_dir == 1 && r.st.columned > 0,
              "a counterbored block scanned from above is one-sided along +z (back/front "
              "%.3f, %zu voxels made outside)", r.st.sides.column_back_front, r.st.columned);
    TAP_CHECK(r.ok && r.in == 0 && r.in0 > 100, "its bore is empty (%zu voxels inside, %zu "
              "without the column rule)", r.in, r.in0);
    TAP_CHECK(r.with > r.without + 0.01, "and its IoU gains (%.4f, %.4f without)", r.with,
              r.without);
    /* its loops are the horizon, not lost faces: not continued (the bent
     * caps would carry its walls past the far side) */
    TAP_CHECK(r.ok && !r.st.holes.continued && r.st.holes.one_sided < 0.02 &&
                  r.st.holes.rim_share < 0.5,
              "its caps are the least-area ones: one-sided along an axis (%.3f), though its "
              "rim is %.3f of the area", r.st.holes.one_sided, r.st.holes.rim_share);
    st_soup_free(s);
    st_soup_free(t);
}

/* Triangle (a, b, c) turned so that its normal has a positive component
 * along hint; left out when skip_down and it then faces down (z). */
static void add_tri_facing(st_soup *s, const double a[3], const double b[3], const double c[3],
                           const double hint[3], int skip_down)
{
    const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    const double w[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    const double n[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2],
                         u[0] * w[1] - u[1] * w[0]};
    const int flip = n[0] * hint[0] + n[1] * hint[1] + n[2] * hint[2] < 0.0;
    if (skip_down && (flip ? -n[2] : n[2]) < 0.0)
        return;
    add_tri(s, a, b, c, flip);
}

/* A point of the bore's circle (r 0) or of the block's square around it
 * (r 1) at angle t about the x axis, at x. */
static void bored_point(double x, int r, double t, double p[3])
{
    const double c = cos(t), sn = sin(t);
    const double m = r ? 0.5 / fmax(fabs(c), fabs(sn)) : 0.2;
    p[0] = x;
    p[1] = m * c;
    p[2] = m * sn;
}

/* A block along x (x in [-1, 1], y and z in [-0.5, 0.5]) with a bore of
 * radius 0.2 along the x axis, outward: all of it (up < 0), or its faces
 * that do not face down (up > 0: a scan from above; the ends, which face
 * along x, stay). */
static void add_bored_block(st_soup *s, int up)
{
    const int nu = 32;   /* a multiple of 8: the square's corners are points */
    for (int j = 0; j < nu; j++) {
        const double t0 = 2 * M_PI * j / nu, t1 = 2 * M_PI * (j + 1) / nu;
        const double tm = 0.5 * (t0 + t1);
        for (int r = 0; r < 2; r++) {
            /* the walls: outward on the square, inward in the bore */
            const double sg = r ? 1.0 : -1.0, hint[3] = {0, sg * cos(tm), sg * sin(tm)};
            double a[3], b[3], c[3], d[3];
            bored_point(-1, r, t0, a);
            bored_point(1, r, t0, b);
            bored_point(1, r, t1, c);
            bored_point(-1, r, t1, d);
            add_tri_facing(s, a, b, c, hint, up > 0);
            add_tri_facing(s, a, c, d, hint, up > 0);
        }
        for (int e = 0; e < 2; e++) {   /* the ends */
            const double x = e ? 1.0 : -1.0, hint[3] = {x, 0, 0};
            double a[3], b[3], c[3], d[3];
            bored_point(x, 0, t0, a);
            bored_point(x, 1, t0, b);
            bored_point(x, 1, t1, c);
            bored_point(x, 0, t1, d);
            add_tri_facing(s, a, b, c, hint, 0);
            add_tri_facing(s, a, c, d, hint, 0);
        }
    }
}

static void test_columns_caps(void)
{
    /* A block with a bore along x, scanned from above: the bore's lower
     * half is seen, its upper half is not; the least-area cap of the
     * bore's loop runs flat across its middle (and up the ends' half
     * circles), and the cut fills the bore's upper half. The column
     * rule reads the caps that face away: this one rises above the lines'
     * crossings, so the air run below it is mirrored above it and the
     * bore is empty again. */
    st_soup *s = st_soup_new(), *t = st_soup_new();
    add_bored_block(s, 1);
    add_bored_block(t, -1);
    const double lo[3] = {-0.8, -0.1, 0.03}, hi[3] = {0.8, 0.1, 0.16};
    const on_off r = rule_on_off(s, t, lo, hi, column_caps_off, ST_SOLID_NONZERO);
    TAP_CHECK(r.ok && r.st.sides.columns && r.st.sides.column_axis == 2 && r.in == 0 &&
                  r.in0 > 100,
              "a bored block scanned from above: its bore's upper half is empty (%zu voxels "
              "inside, %zu without the caps in the column rule)", r.in, r.in0);
    TAP_CHECK(r.with >= 0.9 && r.with > r.without + 0.05,
              "and its IoU gains (%.4f, %.4f without)", r.with, r.without);
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

static void test_shared_tables(void)
{
    /* The steps given the soup's edge table and BVH (built once) give what
     * they give building their own; st_pseudo_sign_bvh signs as
     * st_pseudo_sign does and hands over the soup's BVH. */
    const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
    st_soup *s = st_soup_new();
    add_box_faces(s, lo, hi, 4, top_face, 1);
    st_error err;
    st_soup_edges E;
    st_bvh *own = NULL, *handed = NULL;
    int ok = !st_soup_edges_build(&E, s, &err) && !st_bvh_build(&own, s, &err);
    st_shells a, b;
    memset(&a, 0, sizeof a);
    memset(&b, 0, sizeof b);
    ok = ok && !st_soup_closed_shells(&a, s, &err) && !st_soup_closed_shells_edges(&b, s, &E, &err);
    TAP_CHECK(ok && a.count == b.count && a.open_triangles == b.open_triangles &&
              a.closed->ntris == b.closed->ntris,
              "closed shells from a shared edge table");
    st_soup *ca = NULL, *cb = NULL;
    const st_holes_params hp = st_holes_params_default();
    ok = ok && !st_soup_hole_caps(&ca, s, &hp, NULL, &err) &&
         !st_soup_hole_caps_shared(&cb, s, &E, own, &hp, NULL, &err);
    TAP_CHECK(ok && ca->ntris > 0 && ca->ntris == cb->ntris && ca->nverts == cb->nverts &&
              !memcmp(ca->tris, cb->tris, 3 * ca->ntris * sizeof *ca->tris) &&
              !memcmp(ca->xyz, cb->xyz, 3 * ca->nverts * sizeof *ca->xyz),
              "the same hole caps from a shared edge table and BVH (%zu triangles)",
              ok ? ca->ntris : 0);
    st_dist_params dp = st_dist_params_default();
    dp.cells = 24;
    st_grid *g1 = NULL, *g2 = NULL;
    const st_pseudo_params pp = st_pseudo_params_default();
    ok = ok && !st_dist_field(&g1, s, &dp, NULL, &err) && !st_dist_field(&g2, s, &dp, NULL, &err) &&
         !st_pseudo_sign(g1, s, &pp, NULL, NULL, &err) &&
         !st_pseudo_sign_bvh(g2, s, &pp, NULL, NULL, &handed, &err);
    TAP_CHECK(ok && !memcmp(g1->data, g2->data, st_grid_count(g1) * sizeof *g1->data),
              "st_pseudo_sign_bvh signs as st_pseudo_sign");
    TAP_CHECK(ok && handed && handed->soup == s && handed->nnodes == own->nnodes &&
              !memcmp(handed->nodes, own->nodes, own->nnodes * sizeof *own->nodes) &&
              !memcmp(handed->order, own->order, s->ntris * sizeof *own->order),
              "and hands over the soup's BVH");
    st_grid_free(g1);
    st_grid_free(g2);
    st_soup_free(ca);
    st_soup_free(cb);
    st_shells_free(&a);
    st_shells_free(&b);
    st_bvh_free(own);
    st_bvh_free(handed);
    st_soup_edges_free(&E);
    st_soup_free(s);
}

/* A UV ball of radius 1 that is exactly closed (add_sphere's seam and
 * poles are not: sin(2 pi) and sin(pi) are not 0): each vertex computed
 * once from its grid position, the poles exact; faces turned at random. */
static void ball_vertex(int i, int j, double p[3])
{
    const int nu = 24, nv = 12;
    j %= nu;
    const double th = M_PI * i / nv, ph = 2 * M_PI * j / nu;
    p[0] = i == 0 || i == nv ? 0.0 : sin(th) * cos(ph);
    p[1] = i == 0 || i == nv ? 0.0 : sin(th) * sin(ph);
    p[2] = i == 0 ? 1.0 : i == nv ? -1.0 : cos(th);
}

static void add_closed_ball(st_soup *s)
{
    const int nu = 24, nv = 12;
    for (int i = 0; i < nv; i++)
        for (int j = 0; j < nu; j++) {
            double p[4][3];
            ball_vertex(i, j, p[0]);
            ball_vertex(i, j + 1, p[1]);
            ball_vertex(i + 1, j + 1, p[2]);
            ball_vertex(i + 1, j, p[3]);
            if (i > 0)
                add_tri(s, p[0], p[1], p[2], (i + j) & 1);
            if (i < nv - 1)
                add_tri(s, p[0], p[2], p[3], (i * j) & 1);
        }
}

/* The pseudo volume of s on the shortcut (pp as given) and on the full
 * path (shells_shortcut 0), and s's unsigned field; 0 on failure. */
static int both_paths(const st_soup *s, size_t cells, st_grid **fast, st_grid **full,
                      st_grid **dist, st_pseudo_stats *sf, st_pseudo_stats *sl)
{
    st_dist_params dp = st_dist_params_default();
    dp.cells = cells;
    st_pseudo_params pp = st_pseudo_params_default();
    st_error err;
    *fast = *full = *dist = NULL;
    if (st_pseudo_volume(fast, s, &dp, &pp, sf, NULL, &err))
        return 0;
    pp.shells_shortcut = 0;
    return !st_pseudo_volume(full, s, &dp, &pp, sl, NULL, &err) &&
           !st_dist_field(dist, s, &dp, NULL, &err);
}

/* Voxels where the fast field's value is not st_grid_signed_value(the
 * distance, inside the truth), or its sign is not the full path's. */
static size_t disagree(const st_grid *fast, const st_grid *full, const st_grid *dist,
                       const uint8_t *truth, size_t *sign_vs_full)
{
    size_t bad = 0, sign = 0;
    for (size_t i = 0; i < st_grid_count(fast); i++) {
        const float want = st_grid_signed_value(dist->data[i], truth[i]);
        bad += memcmp(&fast->data[i], &want, sizeof want) != 0;
        sign += (fast->data[i] < 0.0f) != (full->data[i] < 0.0f);
    }
    *sign_vs_full = sign;
    return bad;
}

static void test_shells_shortcut(void)
{
    /* A closed ball (faces turned at random), and two interpenetrating
     * closed boxes: every triangle in a closed shell, so the signs are the
     * shells' solid alone (pseudo.h, the shortcut), each voxel
     * st_grid_signed_value(its distance, inside) by the exact solid
     * (solid.h): the ball by parity, the boxes' union (their overlap
     * inside) by nonzero winding. The full path's signs are the same. */
    for (int shape = 0; shape < 2; shape++) {
        st_soup *s = st_soup_new();
        const double lo1[3] = {0.01, 0.02, 0.03}, hi1[3] = {2.01, 2.02, 2.03};
        const double lo2[3] = {1.3, 1.31, 1.32}, hi2[3] = {3.3, 3.31, 3.32};
        st_soup *b1 = st_soup_new(), *b2 = st_soup_new();
        if (shape == 0)
            add_closed_ball(s);
        else {
            add_box_oriented(b1, lo1, hi1);
            add_box_oriented(b2, lo2, hi2);
            st_error e;
            st_soup_append(s, b1, &e);
            st_soup_append(s, b2, &e);
        }
        st_grid *fast, *full, *dist;
        st_pseudo_stats sf, sl;
        int ok = both_paths(s, 40, &fast, &full, &dist, &sf, &sl);
        const size_t n = ok ? st_grid_count(fast) : 1;
        uint8_t *truth = malloc(n);
        st_error err;
        const st_soup *ball[1] = {s}, *boxes[2] = {b1, b2};
        ok = ok && truth &&
             !st_solid_inside(truth, dist, shape ? boxes : ball, shape ? 2 : 1,
                              shape ? ST_SOLID_NONZERO : ST_SOLID_PARITY, &err);
        size_t sign_vs_full = 0, inside = 0, overlap = 0;
        const size_t bad = ok ? disagree(fast, full, dist, truth, &sign_vs_full) : n;
        for (size_t i = 0; ok && i < n; i++) {
            inside += truth[i];
            if (shape && truth[i]) {
                double c[3];
                const size_t i0 = i % dist->nx, j0 = (i / dist->nx) % dist->ny,
                             k0 = i / (dist->nx * dist->ny);
                st_grid_center(dist, i0, j0, k0, c);
                overlap += c[0] > lo2[0] && c[1] > lo2[1] && c[2] > lo2[2] && c[0] < hi1[0] &&
                           c[1] < hi1[1] && c[2] < hi1[2];
            }
        }
        const char *name = shape ? "two interpenetrating boxes" : "a closed ball";
        TAP_CHECK(ok && sf.shells_only && sf.shells == (size_t)(shape ? 2 : 1) &&
                  sf.shell_open_triangles == 0 && sf.holes.loops == 0 && sf.sides.regions == 0 &&
                  sf.refined == 0 && sf.seconds_vote == 0 && sf.shell_changed == sf.inside,
                  "%s takes the shortcut: the shells' signs alone (%zu inside)", name,
                  sf.inside);
        TAP_CHECK(ok && !sl.shells_only && sl.sides.regions > 0,
                  "%s with shells_shortcut 0: every step runs (%zu regions)", name,
                  ok ? sl.sides.regions : 0);
        TAP_CHECK(ok && inside > 0 && bad == 0 && (!shape || overlap > 0),
                  "%s: every value is its distance signed by the exact solid (%zu of %zu "
                  "differ; %zu inside, %zu in the overlap)", name, bad, n, inside, overlap);
        TAP_CHECK(ok && sign_vs_full == 0, "%s: the full path's signs, voxel for voxel "
                  "(%zu differ)", name, sign_vs_full);
        TAP_CHECK(ok && st_meta_get(&fast->meta, "closed_shells") &&
                  st_meta_get(&fast->meta, "sign_rule") && !st_meta_get(&fast->meta, "hole_caps") &&
                  !st_meta_get(&fast->meta, "sign_refine"),
                  "%s: the metadata records the shells, no caps, no refinement", name);
        if (shape == 0) {
            /* the shortcut checks the field as the vote does */
            st_pseudo_params pp = st_pseudo_params_default();
            st_pseudo_stats st;
            const st_status rc = ok ? st_pseudo_sign(fast, s, &pp, &st, NULL, &err) : ST_OK;
            TAP_CHECK(rc == ST_EINPUT && st.failed_step && !strcmp(st.failed_step, "vote"),
                      "a signed field is refused on the shortcut too");
        }
        free(truth);
        st_grid_free(fast);
        st_grid_free(full);
        st_grid_free(dist);
        st_soup_free(s);
        st_soup_free(b1);
        st_soup_free(b2);
    }
    /* One open triangle beside the ball: no shortcut, the same bytes with
     * shells_shortcut on and off. */
    st_soup *s = st_soup_new();
    add_closed_ball(s);
    const double a[3] = {0.1, 0.1, 0.1}, b[3] = {0.5, 0.1, 0.2}, c[3] = {0.1, 0.6, 0.3};
    add_tri(s, a, b, c, 0);
    st_grid *fast, *full, *dist;
    st_pseudo_stats sf, sl;
    const int ok = both_paths(s, 40, &fast, &full, &dist, &sf, &sl);
    TAP_CHECK(ok && !sf.shells_only && sf.shells == 1 && sf.shell_open_triangles == 1 &&
              sf.sides.regions > 0 && st_meta_get(&fast->meta, "sign_refine"),
              "one open triangle: every step runs (%zu open)", ok ? sf.shell_open_triangles : 0);
    TAP_CHECK(ok && !memcmp(fast->data, full->data, st_grid_count(fast) * sizeof *fast->data),
              "and gives the bytes it gives without the shortcut");
    st_grid_free(fast);
    st_grid_free(full);
    st_grid_free(dist);
    st_soup_free(s);
}

/* The fill (st_pseudo_fill): a box without its top face signs as the
 * full box; the pseudo volume's boundary the soup does not explain is the
 * top, less a rim a voxel wide: voxel squares within half a voxel of the
 * plane z = 1, inside the top's square. The closed box has none; an
 * unsigned field is refused. */
static void test_fill(void)
{
    const st_pseudo_params pp = st_pseudo_params_default();
    st_dist_params dp = st_dist_params_default();
    dp.cells = 40;
    const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
    for (int closed = 0; closed < 2; closed++) {
        st_soup *s = st_soup_new(), *f = NULL;
        if (closed)
            add_box_oriented(s, lo, hi);
        else
            add_box_faces(s, lo, hi, 2, top_face, 0);
        st_grid *g = NULL;
        st_bvh *bvh = NULL;
        st_error err;
        size_t faces = 0;
        int ok = !st_pseudo_volume_bvh(&g, s, &dp, &pp, NULL, NULL, &bvh, &err) &&
                 !st_pseudo_fill(&f, g, bvh, &faces, &err);
        TAP_CHECK(ok && f->ntris == 2 * faces, "%s box: the fill runs (%zu squares)",
                  closed ? "closed" : "open", faces);
        if (closed) {
            TAP_CHECK(ok && faces == 0, "the closed box has no fill");
        } else {
            const double v = ok ? g->voxel : 0, n = 1.0 / (v > 0 ? v : 1);
            int near = ok && faces > 0;
            for (size_t i = 0; near && i < f->nverts; i++) {
                const double *p = f->xyz + 3 * i;
                near = fabs(p[2] - 1.0) <= 0.5 * v + 1e-12 && p[0] >= -v && p[0] <= 1 + v &&
                       p[1] >= -v && p[1] <= 1 + v;
            }
            TAP_CHECK(near, "the open box's fill lies on its missing top (voxel %g)", v);
            TAP_CHECK(ok && (double)faces >= 0.6 * n * n && (double)faces <= n * n + 1,
                      "and covers most of it: %zu squares of about %.0f", faces, n * n);
        }
        /* the same squares as the nearest search gives (the fill asks only
         * whether a triangle is within a voxel: st_bvh_within), in grid
         * order: each square's first corner is its center less half a
         * voxel along both other axes */
        size_t ref = 0, same = 0;
        for (size_t k = 0; ok && k < g->nz; k++)
            for (size_t j = 0; j < g->ny; j++)
                for (size_t i = 0; i < g->nx; i++)
                    for (int a = 0; a < 3; a++) {
                        size_t o[3] = {i, j, k};
                        const size_t nn[3] = {g->nx, g->ny, g->nz};
                        if (o[a] + 1 >= nn[a])
                            continue;
                        o[a]++;
                        if ((g->data[st_grid_index(g, i, j, k)] < 0.0f) ==
                            (g->data[st_grid_index(g, o[0], o[1], o[2])] < 0.0f))
                            continue;
                        double c[3];
                        int64_t tri;
                        st_grid_center(g, i, j, k, c);
                        c[a] += 0.5 * g->voxel;
                        (void)st_bvh_nearest(bvh, c, g->voxel * g->voxel, &tri, NULL);
                        if (tri >= 0)
                            continue;
                        const double *q = ref < faces ? f->xyz + 12 * ref : NULL;
                        c[(a + 1) % 3] -= 0.5 * g->voxel;
                        c[(a + 2) % 3] -= 0.5 * g->voxel;
                        same += q && q[0] == c[0] && q[1] == c[1] && q[2] == c[2];
                        ref++;
                    }
        TAP_CHECK(ok && ref == faces && same == faces,
                  "%s box: the squares of the nearest search (%zu of %zu, %zu in place)",
                  closed ? "closed" : "open", ref, faces, same);
        /* how much of the boundary is a guess: the top's share of a cube's
         * boundary faces, about 1/6 (less the rim within a voxel of the
         * walls), as far from the soup as its middle from the walls' top
         * edges (1/2) */
        st_pseudo_guess gs = {0, 0, -1.0, 0};
        if (ok)
            st_pseudo_guess_measure(&gs, g, f, bvh);
        const double share = gs.boundary_faces ? (double)gs.fill_faces / gs.boundary_faces : -1;
        const double v = ok ? g->voxel : 0;
        if (closed)
            TAP_CHECK(ok && gs.fill_faces == 0 && gs.depth == 0.0 && gs.boundary_faces > 0,
                      "the closed box: nothing guessed (%zu boundary faces)", gs.boundary_faces);
        else
            TAP_CHECK(ok && gs.fill_faces == faces && share >= 0.1 && share <= 1.0 / 6 + 0.01 &&
                      fabs(gs.depth - 0.5) <= v,
                      "the open box: its top is the guess, %.3f of the boundary, up to %.4f "
                      "from the soup (voxel %g)", share, gs.depth, v);
        if (!closed) {
            /* the part a symmetric fill supplied: a triangle over half the
             * top (x + y <= 1) takes about half the fill's squares, none
             * without one */
            st_soup *half = st_soup_new();
            add_tri(half, (double[3]){0, 0, 1}, (double[3]){1, 0, 1}, (double[3]){0, 1, 1}, 0);
            st_pseudo_guess gh = gs;
            int sym_ok = ok && !st_pseudo_guess_symmetric(&gh, g, f, half, &err);
            const double part = gh.fill_faces ? (double)gh.symmetric_faces / gh.fill_faces : -1;
            TAP_CHECK(sym_ok && part >= 0.45 && part <= 0.65,
                      "half the top from a symmetric fill: %.3f of the guess", part);
            TAP_CHECK(ok && !st_pseudo_guess_symmetric(&gh, g, f, NULL, &err) &&
                          gh.symmetric_faces == 0, "no symmetric fill: none of it");
            st_soup_free(half);
        }
        if (ok) {
            /* an unsigned field has no pseudo volume */
            st_grid *d = NULL;
            st_soup *f2 = NULL;
            int refused = !st_dist_field(&d, s, &dp, NULL, &err) &&
                          st_pseudo_fill(&f2, d, bvh, NULL, &err) == ST_EINPUT && !f2;
            if (!closed)
                TAP_CHECK(refused, "an unsigned field is refused");
            st_grid_free(d);
        }
        st_soup_free(f);
        st_bvh_free(bvh);
        st_grid_free(g);
        st_soup_free(s);
    }
}

/* The fill (st_pseudo_fill) is the one the voxel-by-voxel scan gave
 * (kept here: every voxel, each axis's neighbour through st_grid_index),
 * square for square and in order, to the bit: random signs on grids of 1
 * to 9 voxels a side (sign changes on every side of the grid, in the last
 * row and column too), a few triangles explaining some faces. */
static void test_fill_scan(void)
{
    uint64_t r = 0x510e527fade682d1ull;
    size_t differ = 0, squares = 0, grids = 0;
    st_error err;
    for (int it = 0; it < 200; it++) {
        const size_t n[3] = {1 + (size_t)(it % 9), 1 + (size_t)(it / 9 % 9),
                             1 + (size_t)(it * 7 % 9)};
        st_grid *g = NULL;
        st_soup *s = st_soup_new(), *f = NULL;
        st_bvh *bvh = NULL;
        add_tri(s, (double[3]){0.1, 0.2, 0.3}, (double[3]){0.9, 0.2, 0.5},
                (double[3]){0.3, 0.8, 0.6 + 0.01 * it}, 0);
        if (st_grid_new(&g, n[0], n[1], n[2], (double[3]){0, 0, 0}, 0.11, 1.0f, 0, &err) ||
            st_bvh_build(&bvh, s, &err)) {
            st_grid_free(g), st_bvh_free(bvh), st_soup_free(s);
            continue;
        }
        g->kind = ST_GRID_SIGNED;
        for (size_t q = 0; q < st_grid_count(g); q++) {
            r ^= r << 13, r ^= r >> 7, r ^= r << 17;
            g->data[q] = (r >> 40) % 3 == 0 ? -1.0f : 1.0f;
        }
        if (st_pseudo_fill(&f, g, bvh, NULL, &err)) {
            st_grid_free(g), st_bvh_free(bvh), st_soup_free(s);
            continue;
        }
        grids++;
        size_t at = 0, bad = 0;
        for (size_t k = 0; k < n[2]; k++)
            for (size_t j = 0; j < n[1]; j++)
                for (size_t i = 0; i < n[0]; i++)
                    for (int a = 0; a < 3; a++) {
                        size_t o[3] = {i, j, k};
                        if (o[a] + 1 >= n[a])
                            continue;
                        o[a]++;
                        if ((g->data[st_grid_index(g, i, j, k)] < 0.0f) ==
                            (g->data[st_grid_index(g, o[0], o[1], o[2])] < 0.0f))
                            continue;
                        double c[3];
                        st_grid_center(g, i, j, k, c);
                        c[a] += 0.5 * g->voxel;
                        if (st_bvh_within(bvh, c, g->voxel * g->voxel))
                            continue;
                        const int u = (a + 1) % 3, w = (a + 2) % 3;
                        for (int q = 0; q < 4; q++) {
                            double p[3] = {c[0], c[1], c[2]};
                            p[u] += (q == 1 || q == 2) ? 0.5 * g->voxel : -0.5 * g->voxel;
                            p[w] += q >= 2 ? 0.5 * g->voxel : -0.5 * g->voxel;
                            bad += at + 4 > f->nverts || memcmp(p, f->xyz + 3 * (at + (size_t)q),
                                                                sizeof p) != 0;
                        }
                        at += 4;
                    }
        differ += bad || at != f->nverts || f->ntris != at / 2;
        squares += at / 4;
        st_grid_free(g), st_bvh_free(bvh), st_soup_free(s), st_soup_free(f);
    }
    TAP_CHECK(grids == 200 && differ == 0 && squares > 1000,
              "fill the voxel-by-voxel scan's, square for square (%zu of %zu grids differ, %zu "
              "squares)", differ, grids, squares);
}

/* The guess's depth (st_pseudo_guess_measure) is the largest distance
 * from a fill square's center to the soup, to the bit, as measured square
 * by square with the unbounded nearest search (kept here: the measure
 * passes over the centers that cannot raise it), on 1 and 3 threads:
 * random soups of 1 to 400 triangles, thousands of squares in and around
 * them (some on them: depth 0 there). */
static void test_guess_depth(void)
{
    uint64_t r = 0x853c49e6748fea9bull;
    size_t differ = 0, cases = 0, positive = 0;
    st_error err;
    for (int it = 0; it < 60; it++) {
        st_soup *s = st_soup_new(), *f = st_soup_new();
        const size_t nt = 1 + (size_t)(it * 37 % 400), nsq = 200 + (size_t)(it * 53 % 2000);
        double u[9];
        for (size_t t = 0; t < nt; t++) {
            for (int k = 0; k < 9; k++) {
                r ^= r << 13, r ^= r >> 7, r ^= r << 17;
                u[k] = (double)(r >> 11) / 9007199254740992.0;
            }
            const double sc = it % 3 ? 0.1 : 1.0;  /* small triangles or large ones */
            add_tri(s, u, (double[3]){u[0] + sc * (u[3] - 0.5), u[1] + sc * (u[4] - 0.5), u[2]},
                    (double[3]){u[0], u[1] + sc * (u[7] - 0.5), u[2] + sc * (u[8] - 0.5)}, 0);
        }
        for (size_t q = 0; q < nsq; q++) {     /* squares as st_pseudo_fill makes them */
            for (int k = 0; k < 3; k++) {
                r ^= r << 13, r ^= r >> 7, r ^= r << 17;
                u[k] = 1.6 * (double)(r >> 11) / 9007199254740992.0 - 0.3;
            }
            if (q % 97 == 0)
                memcpy(u, s->xyz, 3 * sizeof *u);   /* on the soup */
            const size_t b = f->nverts;
            for (int c = 0; c < 4; c++)
                st_soup_add_vertex(f, u[0] + 0.01 * (c == 1 || c == 2), u[1] + 0.01 * (c >= 2),
                                   u[2], &err);
            st_soup_add_triangle(f, (uint32_t)b, (uint32_t)b + 1, (uint32_t)b + 2, &err);
            st_soup_add_triangle(f, (uint32_t)b, (uint32_t)b + 2, (uint32_t)b + 3, &err);
        }
        st_bvh *bvh = NULL;
        st_grid *g = NULL;
        if (st_bvh_build(&bvh, s, &err) || st_grid_new(&g, 4, 4, 4, (double[3]){0, 0, 0}, 0.25,
                                                        1.0f, 0, &err)) {
            st_bvh_free(bvh), st_grid_free(g), st_soup_free(s), st_soup_free(f);
            continue;
        }
        g->data[5] = -1.0f;
        double ref = 0.0;
        for (size_t q = 0; q < f->ntris / 2; q++) {
            const uint32_t *t = f->tris + 6 * q;
            const double *a = f->xyz + 3 * (size_t)t[0], *c = f->xyz + 3 * (size_t)t[2];
            const double m[3] = {0.5 * (a[0] + c[0]), 0.5 * (a[1] + c[1]), 0.5 * (a[2] + c[2])};
            int64_t tri;
            const double d2 = st_bvh_nearest(bvh, m, INFINITY, &tri, NULL);
            ref = d2 > ref ? d2 : ref;
        }
        ref = sqrt(ref);
        for (int threads = 1; threads <= 3; threads += 2) {
#ifdef _OPENMP
            omp_set_num_threads(threads);
#endif
            st_pseudo_guess gs = {0, 0, -1.0, 0};
            st_pseudo_guess_measure(&gs, g, f, bvh);
            differ += !(gs.depth == ref) || gs.fill_faces != f->ntris / 2;
            cases++;
        }
        positive += ref > 0.0;
        st_bvh_free(bvh), st_grid_free(g), st_soup_free(s), st_soup_free(f);
    }
#ifdef _OPENMP
    omp_set_num_threads(omp_get_num_procs());
#endif
    TAP_CHECK(cases == 120 && differ == 0 && positive == 60,
              "guess depth the nearest search's, square by square (%zu of %zu differ)", differ,
              cases);
}

/* signs_only (pseudo.h): on a closed ball and on two interpenetrating
 * closed boxes the shortcut runs without distances: the same layout and
 * the same sign voxel for voxel as with the distances, every value the
 * band's far value, and the metadata says so; with one open triangle
 * beside the ball, or a full band, the distances are computed: the same
 * bytes as without signs_only. */
static void test_signs_only(void)
{
    for (int shape = 0; shape < 4; shape++) {
        st_soup *s = st_soup_new(), *b = st_soup_new();
        const double lo1[3] = {0.01, 0.02, 0.03}, hi1[3] = {2.01, 2.02, 2.03};
        const double lo2[3] = {1.3, 1.31, 1.32}, hi2[3] = {3.3, 3.31, 3.32};
        st_error err;
        if (shape == 1) {
            add_box_oriented(s, lo1, hi1);
            add_box_oriented(b, lo2, hi2);
            st_soup_append(s, b, &err);
        } else
            add_closed_ball(s);
        if (shape == 2)
            add_tri(s, (double[3]){0.1, 0.1, 0.1}, (double[3]){0.5, 0.1, 0.2},
                    (double[3]){0.1, 0.6, 0.3}, 0);
        st_dist_params dp = st_dist_params_default();
        dp.cells = 40;
        if (shape == 3)
            dp.band = INFINITY;
        st_pseudo_params pp = st_pseudo_params_default();
        pp.symmetry = 0;   /* the ball's many symmetries: slow, and beside the point */
        st_grid *with = NULL, *without = NULL;
        st_pseudo_stats sw, so;
        int ok = !st_pseudo_volume(&with, s, &dp, &pp, &sw, NULL, &err);
        pp.signs_only = 1;
        ok = ok && !st_pseudo_volume(&without, s, &dp, &pp, &so, NULL, &err);
        const size_t n = ok ? st_grid_count(with) : 0;
        size_t sign = 0, far = 0;
        for (size_t i = 0; i < n; i++) {
            sign += (with->data[i] < 0.0f) != (without->data[i] < 0.0f);
            far += fabsf(without->data[i]) == (float)without->band;
        }
        const int layout = ok && with->nx == without->nx && with->ny == without->ny &&
                           with->nz == without->nz && with->voxel == without->voxel &&
                           with->band == without->band && with->kind == without->kind &&
                           !memcmp(with->origin, without->origin, sizeof with->origin);
        static const char *const names[] = {"a closed ball", "two interpenetrating boxes",
                                            "the ball and an open triangle",
                                            "the ball on a full band"};
        if (shape < 2)
            TAP_CHECK(layout && sign == 0 && far == n && so.shells_only &&
                          so.inside == sw.inside && so.inside > 0 &&
                          st_meta_get(&without->meta, "distances") &&
                          !st_meta_get(&with->meta, "distances"),
                      "%s, signs only: no distance, the same %zu signs (%zu differ), every "
                      "value the far one (%zu of %zu)", names[shape], so.inside, sign, far, n);
        else
            TAP_CHECK(layout && !memcmp(with->data, without->data, n * sizeof *with->data) &&
                          so.shells_only == (shape == 3) &&
                          !st_meta_get(&without->meta, "distances"),
                      "%s, signs only: the distances are computed, the same bytes",
                      names[shape]);
        st_grid_free(with);
        st_grid_free(without);
        st_soup_free(s);
        st_soup_free(b);
    }
}

int main(int argc, char **argv)
{
    static const tap_test tests[] = {TAP_TEST(entry_point), TAP_TEST(large_holes),
                                     TAP_TEST(hemisphere), TAP_TEST(onesided),
                                     TAP_TEST(onesided_caps), TAP_TEST(columns),
                                     TAP_TEST(columns_caps), TAP_TEST(sides_orientation),
                                     TAP_TEST(shared_tables), TAP_TEST(shells_shortcut),
                                     TAP_TEST(fill), TAP_TEST(fill_scan), TAP_TEST(guess_depth),
                                     TAP_TEST(signs_only), {0}};
    return tap_main(argc, argv, tests);
}
