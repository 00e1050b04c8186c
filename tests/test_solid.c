/* test_solid.c - exact ray parity at voxel centers (solid.h). */
#include "souptet/grid.h"
#include "souptet/pred.h"
#include "souptet/solid.h"
#include "souptet/soup.h"
#include "shapes.h"
#include "tap.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#ifdef _OPENMP
#include <omp.h>
#endif

static st_grid *layout(size_t n, double origin, double voxel)
{
    st_grid *g;
    const double o[3] = {origin, origin, origin};
    if (st_grid_new(&g, n, n, n, o, voxel, 0.0f, 0, NULL))
        abort();
    return g;
}

static uint8_t *solid_by(const st_grid *g, const st_soup *const *shells, size_t n,
                         st_solid_rule rule)
{
    uint8_t *in = malloc(st_grid_count(g));
    st_error err;
    if (!in || st_solid_inside(in, g, shells, n, rule, &err))
        abort();
    return in;
}

/* Parity: the test shapes below mix orientations on purpose. */
static uint8_t *solid_of(const st_grid *g, const st_soup *const *shells, size_t n)
{
    return solid_by(g, shells, n, ST_SOLID_PARITY);
}

/* The perturbation rule in solid.h makes a closed box half-open: a voxel
 * center on a face at lo is inside, one on a face at hi is outside. */
static int in_box_half_open(const double p[3], const double lo[3], const double hi[3])
{
    for (int a = 0; a < 3; a++)
        if (!(p[a] >= lo[a] && p[a] < hi[a]))
            return 0;
    return 1;
}

static void test_boxes(void)
{
    /* Voxel centers at multiples of 1/4: rows run exactly through the
     * box's edges and vertices and along its faces. */
    st_grid *g = layout(9, -0.5, 0.25);
    st_soup *box = st_soup_new();
    const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
    add_box(box, lo, hi);
    const st_soup *shells[2] = {box, NULL};
    uint8_t *in = solid_of(g, shells, 1);
    size_t wrong = 0, count = 0;
    for (size_t k = 0; k < g->nz; k++)
        for (size_t j = 0; j < g->ny; j++)
            for (size_t i = 0; i < g->nx; i++) {
                double p[3];
                st_grid_center(g, i, j, k, p);
                int v = in[st_grid_index(g, i, j, k)];
                count += (size_t)v;
                wrong += (size_t)(v != in_box_half_open(p, lo, hi));
            }
    TAP_CHECK(wrong == 0 && count == 64, "unit box on the voxel lattice: %zu inside, %zu wrong",
              count, wrong);
    free(in);

    /* Two interpenetrating boxes, as two shells: their union. */
    st_soup *b2 = st_soup_new();
    const double lo2[3] = {0.5, -0.25, 0.25}, hi2[3] = {1.25, 0.75, 0.75};
    add_box(b2, lo2, hi2);
    shells[1] = b2;
    in = solid_of(g, shells, 2);
    wrong = 0;
    for (size_t k = 0; k < g->nz; k++)
        for (size_t j = 0; j < g->ny; j++)
            for (size_t i = 0; i < g->nx; i++) {
                double p[3];
                st_grid_center(g, i, j, k, p);
                int want = in_box_half_open(p, lo, hi) || in_box_half_open(p, lo2, hi2);
                wrong += (size_t)(in[st_grid_index(g, i, j, k)] != want);
            }
    TAP_CHECK(wrong == 0, "two interpenetrating boxes give their union (%zu wrong)", wrong);
    free(in);

    /* Both boxes in one soup: parity alone would cut out the overlap. */
    st_soup *both = st_soup_new();
    add_box(both, lo, hi);
    add_box(both, lo2, hi2);
    shells[0] = both;
    in = solid_of(g, shells, 1);
    size_t overlap_in = 0;
    for (size_t k = 0; k < g->nz; k++)
        for (size_t j = 0; j < g->ny; j++)
            for (size_t i = 0; i < g->nx; i++) {
                double p[3];
                st_grid_center(g, i, j, k, p);
                if (in_box_half_open(p, lo, hi) && in_box_half_open(p, lo2, hi2))
                    overlap_in += in[st_grid_index(g, i, j, k)];
            }
    TAP_CHECK(overlap_in == 0, "one soup of two boxes: parity leaves the overlap outside");
    free(in);

    /* The same two boxes oriented, in one soup (a surface through itself):
     * the winding number is 2 in the overlap, so nonzero gives the union,
     * exactly as the two shells did. */
    st_soup *both_or = st_soup_new();
    add_box_oriented(both_or, lo, hi);
    add_box_oriented(both_or, lo2, hi2);
    shells[0] = both_or;
    in = solid_by(g, shells, 1, ST_SOLID_NONZERO);
    wrong = 0;
    for (size_t k = 0; k < g->nz; k++)
        for (size_t j = 0; j < g->ny; j++)
            for (size_t i = 0; i < g->nx; i++) {
                double p[3];
                st_grid_center(g, i, j, k, p);
                int want = in_box_half_open(p, lo, hi) || in_box_half_open(p, lo2, hi2);
                wrong += (size_t)(in[st_grid_index(g, i, j, k)] != want);
            }
    TAP_CHECK(wrong == 0, "one oriented soup of two boxes: nonzero winding gives the union (%zu wrong)",
              wrong);
    free(in);
    /* Inside out (every triangle reversed) the winding is -1 or -2: the
     * same solid; parity differs from it exactly in the overlap. */
    uint8_t *fwd = solid_by(g, shells, 1, ST_SOLID_NONZERO);
    for (size_t t = 0; t < both_or->ntris; t++) {
        uint32_t x = both_or->tris[3 * t + 1];
        both_or->tris[3 * t + 1] = both_or->tris[3 * t + 2];
        both_or->tris[3 * t + 2] = x;
    }
    uint8_t *rev = solid_by(g, shells, 1, ST_SOLID_NONZERO);
    uint8_t *par = solid_of(g, shells, 1);
    size_t differ = 0, overlap = 0;
    for (size_t k = 0; k < g->nz; k++)
        for (size_t j = 0; j < g->ny; j++)
            for (size_t i = 0; i < g->nx; i++) {
                double p[3];
                st_grid_center(g, i, j, k, p);
                size_t v = st_grid_index(g, i, j, k);
                differ += par[v] != rev[v];
                overlap += in_box_half_open(p, lo, hi) && in_box_half_open(p, lo2, hi2);
            }
    TAP_CHECK(memcmp(fwd, rev, st_grid_count(g)) == 0,
              "nonzero winding does not depend on the orientation");
    TAP_CHECK(differ == overlap && overlap > 0,
              "parity and winding differ exactly in the overlap (%zu of %zu voxels)", differ, overlap);
    free(fwd);
    free(rev);
    free(par);
    st_soup_free(both_or);
    st_soup_free(both);
    st_soup_free(b2);
    st_soup_free(box);
    st_grid_free(g);
}

/* A point is inside a tet under the perturbation (x + e^3, y + e, z + e^2)
 * when it is on the inner side of all four face planes, each side decided
 * with the same perturbation: an oracle independent of ray parity. */
static int perturbed_side(const double *a, const double *b, const double *c, const double p[3])
{
    int s = st_sign(st_orient3d(a, b, c, p));
    if (s)
        return s;
    static const int order[3] = {1, 2, 0};
    for (int o = 0; o < 3; o++) {
        int g = -st_sign(st_orient2d_drop(a, b, c, order[o]));
        if (g)
            return g;
    }
    return 0;
}

static int in_tet_perturbed(const double *v[4], const double p[3])
{
    static const int f[4][3] = {{1, 2, 3}, {0, 2, 3}, {0, 1, 3}, {0, 1, 2}};
    for (int i = 0; i < 4; i++) {
        const double *a = v[f[i][0]], *b = v[f[i][1]], *c = v[f[i][2]];
        /* Inside: on the side of face i where the opposite vertex is. */
        if (perturbed_side(a, b, c, p) != st_sign(st_orient3d(a, b, c, v[i])))
            return 0;
    }
    return 1;
}

static void add_tet(st_soup *s, const double *v[4])
{
    add_tri(s, v[1], v[2], v[3], 0);
    add_tri(s, v[0], v[3], v[2], 1);
    add_tri(s, v[0], v[1], v[3], 0);
    add_tri(s, v[0], v[2], v[1], 1);
}

/* The same tet, consistently oriented (each edge used once each way). */
static void add_tet_oriented(st_soup *s, const double *v[4])
{
    add_tri(s, v[1], v[2], v[3], 0);
    add_tri(s, v[0], v[3], v[2], 0);
    add_tri(s, v[0], v[1], v[3], 0);
    add_tri(s, v[0], v[2], v[1], 0);
}

static unsigned long long rng = 0x9e3779b97f4a7c15ull;
static double uniform(void)
{
    rng ^= rng << 13;
    rng ^= rng >> 7;
    rng ^= rng << 17;
    return (double)(rng >> 11) / 9007199254740992.0;
}

static void test_tets(void)
{
    st_grid *g = layout(8, 0.0, 1.0);
    size_t wrong = 0, inside = 0, checked = 0, wrong_nz = 0;
    for (int trial = 0; trial < 300; trial++) {
        double pts[4][3];
        for (int c = 0; c < 4; c++)
            for (int a = 0; a < 3; a++) {
                /* Half the tets have vertices on voxel centers (every
                 * degenerate coincidence), half anywhere. */
                double u = uniform() * 7.0;
                pts[c][a] = trial & 1 ? floor(u + 0.5) : u;
            }
        const double *v[4] = {pts[0], pts[1], pts[2], pts[3]};
        if (st_orient3d(v[0], v[1], v[2], v[3]) == 0.0)
            continue;
        st_soup *s = st_soup_new();
        add_tet(s, v);
        const st_soup *sh[1] = {s};
        uint8_t *in = solid_of(g, sh, 1);
        st_soup *o = st_soup_new();
        add_tet_oriented(o, v);
        const st_soup *sho[1] = {o};
        uint8_t *nz = solid_by(g, sho, 1, ST_SOLID_NONZERO);
        for (size_t v2 = 0; v2 < st_grid_count(g); v2++)
            wrong_nz += nz[v2] != in[v2];
        free(nz);
        st_soup_free(o);
        for (size_t k = 0; k < g->nz; k++)
            for (size_t j = 0; j < g->ny; j++)
                for (size_t i = 0; i < g->nx; i++) {
                    double p[3];
                    st_grid_center(g, i, j, k, p);
                    int got = in[st_grid_index(g, i, j, k)];
                    wrong += (size_t)(got != in_tet_perturbed(v, p));
                    inside += (size_t)got;
                    checked++;
                }
        free(in);
        st_soup_free(s);
    }
    TAP_CHECK(wrong == 0 && inside > 1000,
              "ray parity = four plane tests on random tets (%zu voxel tests, %zu inside, %zu wrong)",
              checked, inside, wrong);
    TAP_CHECK(wrong_nz == 0, "nonzero winding of the oriented tets = their parity (%zu differ)",
              wrong_nz);
    st_grid_free(g);
}

static void test_sphere(void)
{
    st_grid *g = layout(41, -1.25, 2.5 / 40.0);
    st_soup *s = st_soup_new();
    add_sphere(s, 1.0, 2.0);
    const st_soup *sh[1] = {s};
    uint8_t *in = solid_of(g, sh, 1);
    size_t wrong = 0;
    for (size_t k = 0; k < g->nz; k++)
        for (size_t j = 0; j < g->ny; j++)
            for (size_t i = 0; i < g->nx; i++) {
                double p[3];
                st_grid_center(g, i, j, k, p);
                double r = sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
                int v = in[st_grid_index(g, i, j, k)];
                /* The UV sphere's facets lie within 2% of the unit sphere. */
                if ((r < 0.97 && !v) || (r > 1.0 && v))
                    wrong++;
            }
    TAP_CHECK(wrong == 0, "UV sphere: inside below r 0.97, outside beyond 1 (%zu wrong)", wrong);

#ifdef _OPENMP
    int nt = omp_get_max_threads();
    omp_set_num_threads(1);
    uint8_t *one = solid_of(g, sh, 1);
    omp_set_num_threads(nt < 2 ? 2 : nt);
    TAP_CHECK(memcmp(one, in, st_grid_count(g)) == 0, "same solid on 1 and %d threads",
              nt < 2 ? 2 : nt);
    free(one);
    omp_set_num_threads(nt);
#endif

    /* IoU of a field against the truth. */
    for (size_t v = 0; v < st_grid_count(g); v++)
        g->data[v] = in[v] ? -1.0f : 1.0f;
    double iou, prec, rec;
    st_error err;
    st_solid_iou(&iou, &prec, &rec, in, g, &err);
    TAP_CHECK(iou == 1.0 && prec == 1.0 && rec == 1.0, "a field equal to the truth: IoU 1");
    size_t n_in = 0, flipped = 0;
    for (size_t v = 0; v < st_grid_count(g); v++) {
        n_in += in[v];
        if (in[v] && flipped * 4 < n_in) {   /* drop a quarter of the inside */
            g->data[v] = 1.0f;
            flipped++;
        }
    }
    st_solid_iou(&iou, &prec, &rec, in, g, &err);
    TAP_NEAR(rec, (double)(n_in - flipped) / (double)n_in, 1e-12, "recall counts the lost voxels");
    TAP_CHECK(prec == 1.0, "precision stays 1 when only inside voxels are lost");
    TAP_NEAR(iou, rec, 1e-12, "IoU equals recall then");
    free(in);
    st_soup_free(s);
    st_grid_free(g);
}

int main(int argc, char **argv)
{
    static const tap_test tests[] = {TAP_TEST(boxes), TAP_TEST(tets), TAP_TEST(sphere), {0}};
    return tap_main(argc, argv, tests);
}
