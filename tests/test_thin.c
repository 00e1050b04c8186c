/*
 * test_thin.c - Cetra's stopping condition on the shapes that hold the
 * fit back (issue 18): every boundary vertex within R h of the surface,
 * the mesh enclosing it, at R 0.4 and 0.25, for two parallel plates a
 * fraction of h apart, a thin slot cut into a block and a sharp crease
 * (a 20 degree wedge). Best of 8 candidates, as soupmesh --tries 8.
 */
#include "souptet/pipeline.h"
#include "shapes.h"
#include "tap.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

/* Cells along the longest side; h is the longest side / CELLS. */
#define CELLS 6

/* Two plates 4 x 4 x 0.5, gap apart. */
static void plates(st_soup *s, double gap)
{
    add_box(s, (double[3]){0, 0, 0}, (double[3]){4, 4, 0.5});
    add_box(s, (double[3]){0, 0, 0.5 + gap}, (double[3]){4, 4, 1.0 + gap});
}

/* A block 4 x 2 x 2 with a slot `width` wide and 1 deep along x in its
 * top: a base and two walls (touching boxes, a soup). */
static void slot(st_soup *s, double width)
{
    double w = (2.0 - width) / 2.0;
    add_box(s, (double[3]){0, 0, 0}, (double[3]){4, 2, 1});
    add_box(s, (double[3]){0, 0, 1}, (double[3]){4, w, 2});
    add_box(s, (double[3]){0, 2 - w, 1}, (double[3]){4, 2, 2});
}

/* A wedge: the triangle (0,0) (3,0) (3, 3 tan deg) in xz, 3 long in y. */
static void wedge(st_soup *s, double deg)
{
    double t = 3.0 * tan(deg * M_PI / 180.0);
    double a0[3] = {0, 0, 0}, b0[3] = {3, 0, 0}, c0[3] = {3, 0, t};
    double a1[3] = {0, 3, 0}, b1[3] = {3, 3, 0}, c1[3] = {3, 3, t};
    add_tri(s, a0, c0, b0, 0);
    add_tri(s, a1, b1, c1, 0);
    add_tri(s, a0, b0, b1, 0);
    add_tri(s, a0, b1, a1, 0);
    add_tri(s, b0, c0, c1, 0);
    add_tri(s, b0, c1, b1, 0);
    add_tri(s, a0, a1, c1, 0);
    add_tri(s, a0, c1, c0, 0);
}

static void check(const char *name, st_soup *s, double longest)
{
    static const double ratio[2] = {0.4, 0.25};
    static const double floor_deg[2] = {33.0, 30.0};
    for (int k = 0; k < 2; k++) {
        st_pipeline_params p = st_pipeline_params_default();
        p.cells = CELLS;
        p.tries = 8;
        p.offset_ratio = ratio[k];
        st_tetmesh *m = NULL;
        st_pipeline_stats st;
        st_error err;
        st_status rc = st_pipeline_run(&m, &st, s, &p, NULL, &err);
        const st_pipeline_candidate *b = rc == ST_OK ? &st.candidates[st.best] : NULL;
        TAP_CHECK(b && st.encloses && b->verts_outside == 0 && b->tris_crossing == 0,
                  "%s, R %.2f: the mesh encloses the soup (%s)", name, ratio[k],
                  rc ? err.msg : "ok");
        TAP_CHECK(b && b->beyond_offset == 0 && b->max_distance <= ratio[k] * st.h,
                  "%s, R %.2f: every boundary vertex within R h (%zu beyond, max %.3f h)",
                  name, ratio[k], b ? b->beyond_offset : 0,
                  b ? b->max_distance / st.h : 0.0);
        TAP_CHECK(b && b->min_dihedral >= floor_deg[k] && b->max_dihedral <= 140.0,
                  "%s, R %.2f: dihedral %.2f..%.2f (%zu tets, h %.3f of %.0f)", name,
                  ratio[k], b ? b->min_dihedral : 0.0, b ? b->max_dihedral : 0.0,
                  b ? b->tets : 0, st.h, longest);
        if (rc == ST_OK)
            free(st.candidates);
        st_tetmesh_free(m);
    }
}

static void test_plates(void)
{
    double h = 4.0 / CELLS;
    st_soup *s = st_soup_new();
    plates(s, 0.3 * h);
    check("plates 0.3 h apart", s, 4.0);
    st_soup_free(s);
}

static void test_slot(void)
{
    double h = 4.0 / CELLS;
    st_soup *s = st_soup_new();
    slot(s, 0.3 * h);
    check("a slot 0.3 h wide", s, 4.0);
    st_soup_free(s);
}

static void test_wedge(void)
{
    st_soup *s = st_soup_new();
    wedge(s, 20.0);
    check("a 20 degree crease", s, 3.0);
    st_soup_free(s);
}

int main(int argc, char **argv)
{
    static const tap_test tests[] = {TAP_TEST(plates), TAP_TEST(slot), TAP_TEST(wedge), {0}};
    return tap_main(argc, argv, tests);
}
