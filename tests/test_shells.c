/*
 * test_shells.c - closed shells of a soup (shells.h): which pieces are
 * shells, their orientation, and the signs they give.
 */
#include "souptet/grid.h"
#include "souptet/shells.h"
#include "shapes.h"
#include "tap.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static double volume(const st_soup *s)
{
    double v = 0;
    for (size_t t = 0; t < s->ntris; t++) {
        const double *a = s->xyz + 3 * (size_t)s->tris[3 * t], *b = s->xyz + 3 * (size_t)s->tris[3 * t + 1],
                     *c = s->xyz + 3 * (size_t)s->tris[3 * t + 2];
        v += a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
             a[2] * (b[0] * c[1] - b[1] * c[0]);
    }
    return v / 6.0;
}

static int in_box(const double p[3], const double lo[3], const double hi[3])
{
    for (int a = 0; a < 3; a++)
        if (!(p[a] > lo[a] && p[a] < hi[a]))
            return 0;
    return 1;
}

/* A signed field over [-1, 3]^3 (voxel centers off every box face used
 * here) with every value +1 except where `neg` says. */
static st_grid *field(int (*neg)(const double p[3]))
{
    st_grid *g = NULL;
    const double origin[3] = {-0.95, -0.95, -0.95};
    st_grid_new(&g, 40, 40, 40, origin, 0.1, 1.0f, 0, NULL);
    g->kind = ST_GRID_SIGNED;
    for (size_t k = 0; k < g->nz; k++)
        for (size_t j = 0; j < g->ny; j++)
            for (size_t i = 0; i < g->nx; i++) {
                double p[3] = {origin[0] + 0.1 * i, origin[1] + 0.1 * j, origin[2] + 0.1 * k};
                if (neg && neg(p))
                    g->data[st_grid_index(g, i, j, k)] = -1.0f;
            }
    return g;
}

static const double lo1[3] = {0, 0, 0}, hi1[3] = {1.5, 1.5, 1.5};
static const double lo2[3] = {1, 1, 1}, hi2[3] = {2.5, 2.5, 2.5};
static const double slo[3] = {-0.5, 2.0, -0.5}, shi[3] = {0.5, 2.5, 0.5};

/* Parity of the two boxes: the overlap is outside. */
static int parity_two(const double p[3]) { return in_box(p, lo1, hi1) != in_box(p, lo2, hi2); }
static int far_corner(const double p[3]) { return p[0] > 2.7 && p[1] > 2.7 && p[2] > 2.7; }

static size_t mismatches(const st_grid *g, int (*want)(const double p[3]))
{
    size_t bad = 0;
    for (size_t k = 0; k < g->nz; k++)
        for (size_t j = 0; j < g->ny; j++)
            for (size_t i = 0; i < g->nx; i++) {
                double p[3] = {g->origin[0] + 0.1 * i, g->origin[1] + 0.1 * j, g->origin[2] + 0.1 * k};
                bad += (g->data[st_grid_index(g, i, j, k)] < 0.0f) != (want(p) != 0);
            }
    return bad;
}

static int union_two(const double p[3]) { return in_box(p, lo1, hi1) || in_box(p, lo2, hi2); }
static int box1_or_corner(const double p[3]) { return in_box(p, lo1, hi1) || far_corner(p); }

static void test_overlapping_boxes(void)
{
    st_error err;
    st_soup *s = st_soup_new();
    add_box(s, lo1, hi1);            /* every other triangle flipped */
    add_box(s, lo2, hi2);
    st_shells sh;
    int ok = !st_soup_closed_shells(&sh, s, &err);
    TAP_CHECK(ok && sh.count == 2 && sh.open_triangles == 0 && sh.closed->ntris == 24,
              "two interpenetrating boxes with flipped faces: two shells, nothing open");
    if (ok)
        TAP_NEAR(volume(sh.closed), 1.5 * 1.5 * 1.5 * 2, 1e-12,
                 "each shell oriented outward: the volumes add");
    /* The field's signs as a crossing count gives them: the overlap out. */
    st_grid *g = field(parity_two);
    size_t changed = 0;
    ok = ok && !st_shells_sign(g, &sh, &changed, &err);
    TAP_CHECK(ok && mismatches(g, union_two) == 0,
              "the signs are the union exactly, overlap inside (%zu changed)", changed);
    TAP_CHECK(changed == 5 * 5 * 5, "the overlap's 125 voxels changed, no other");
    st_grid_free(g);
    /* Exact: a stray inside sign in the open is cleared too. */
    g = field(far_corner);
    ok = !st_shells_sign(g, &sh, NULL, &err);
    TAP_CHECK(ok && mismatches(g, union_two) == 0, "only shells: stray inside signs cleared");
    st_grid_free(g);
    st_shells_free(&sh);

    /* The same with every triangle reversed, and each one twice. */
    st_soup *r = st_soup_new();
    for (size_t t = 0; t < s->ntris; t++)
        for (int copy = 0; copy < 2; copy++) {
            const double *a = s->xyz + 3 * (size_t)s->tris[3 * t], *b = s->xyz + 3 * (size_t)s->tris[3 * t + 1],
                         *c = s->xyz + 3 * (size_t)s->tris[3 * t + 2];
            add_tri(r, a, b, c, 1);
        }
    ok = !st_soup_closed_shells(&sh, r, &err);
    TAP_CHECK(ok && sh.count == 2 && sh.open_triangles == 0 && sh.closed->ntris == 24,
              "reversed and duplicated: the same two shells");
    if (ok)
        TAP_NEAR(volume(sh.closed), 1.5 * 1.5 * 1.5 * 2, 1e-12, "reversed: oriented outward");
    st_shells_free(&sh);
    st_soup_free(r);
    st_soup_free(s);
}

static void test_open_pieces(void)
{
    st_error err;
    st_shells sh;
    /* A box without a face is no shell; the field is left alone. */
    st_soup *s = st_soup_new();
    add_box(s, lo1, hi1);
    s->ntris -= 2;
    int ok = !st_soup_closed_shells(&sh, s, &err);
    TAP_CHECK(ok && sh.count == 0 && sh.open_triangles == 10, "a box without a face: no shell, 10 open");
    st_grid *g = field(far_corner);
    size_t changed = 1;
    ok = ok && !st_shells_sign(g, &sh, &changed, &err);
    TAP_CHECK(ok && changed == 0 && mismatches(g, far_corner) == 0, "no shell: no sign changed");
    st_grid_free(g);
    st_shells_free(&sh);
    st_soup_free(s);

    /* A closed box beside an open sheet: the box's inside is inside, the
     * rest keeps the vote's signs. */
    s = st_soup_new();
    add_box(s, lo1, hi1);
    const double q[4][3] = {{slo[0], slo[1], slo[2]}, {shi[0], slo[1], slo[2]},
                            {shi[0], slo[1], shi[2]}, {slo[0], slo[1], shi[2]}};
    add_tri(s, q[0], q[1], q[2], 0);
    add_tri(s, q[0], q[2], q[3], 1);
    ok = !st_soup_closed_shells(&sh, s, &err);
    TAP_CHECK(ok && sh.count == 1 && sh.open_triangles == 2, "a box and a sheet: one shell, two open");
    g = field(far_corner);
    ok = ok && !st_shells_sign(g, &sh, &changed, &err);
    TAP_CHECK(ok && mismatches(g, box1_or_corner) == 0 && changed == 15 * 15 * 15,
              "beside open triangles: the box's inside added, other signs kept");
    st_grid_free(g);
    st_shells_free(&sh);
    st_soup_free(s);

    /* Two boxes sharing an edge: an edge of four faces, no shell. */
    s = st_soup_new();
    const double lo3[3] = {1.5, 1.5, 0};
    const double hi3[3] = {2.5, 2.5, 1.5};
    add_box(s, lo1, hi1);
    add_box(s, lo3, hi3);
    ok = !st_soup_closed_shells(&sh, s, &err);
    TAP_CHECK(ok && sh.count == 0 && sh.open_triangles == 24,
              "two boxes sharing an edge: one piece with an edge of four faces, not a shell");
    st_shells_free(&sh);
    st_soup_free(s);

    /* An unsigned field is refused. */
    s = st_soup_new();
    add_box(s, lo1, hi1);
    st_soup_closed_shells(&sh, s, &err);
    g = field(NULL);
    g->kind = ST_GRID_DISTANCE;
    TAP_CHECK(st_shells_sign(g, &sh, NULL, &err) == ST_EINPUT, "an unsigned field is refused");
    st_grid_free(g);
    st_shells_free(&sh);
    st_soup_free(s);
}

int main(int argc, char **argv)
{
    static const tap_test tests[] = {TAP_TEST(overlapping_boxes), TAP_TEST(open_pieces), {0}};
    return tap_main(argc, argv, tests);
}
