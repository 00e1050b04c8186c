/* test_symmetry_fill.c - the lost side filled from its symmetric copy
 * (symmetry.h, st_symmetry_fill), with the symmetries given (their
 * detection is test_symmetry's): a 64-sided cylinder missing 110 degrees
 * of its side, a hole too large to cap, filled from its continuous axis
 * (the fill is the missing strip, on the cylinder, the same on 1 and 2
 * threads); a 70-degree hole across a mirror plane whose copy is whole
 * (its cap dropped, the fill closes it) and whose copy is itself holed
 * (the fill leaves the hole partly open but lies behind the cap: the cap
 * is dropped, the partial fill kept); an 80-degree hole across the plane,
 * whose cap is split where the mirror sends the hole onto itself; the
 * mirrors' turns made only where a hole is left unclosed (turns_unread). */
#include "souptet/bvh.h"
#include "souptet/edges.h"
#include "souptet/holes.h"
#include "souptet/soup.h"
#include "souptet/symmetry.h"
#include "shapes.h"
#include "tap.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#ifdef _OPENMP
#include <omp.h>
#endif

#define SIDES 64
#define TOL 0.03   /* a voxel at 64 along the cylinder's 2 x 2 x 2 box */

/* Degrees a in [lo, hi), both in [0, 360) or lo > hi wrapping past 0. */
static int in_range(double a, double lo, double hi)
{
    return lo <= hi ? a >= lo && a < hi : a >= lo || a < hi;
}

/* A closed 64-sided cylinder (radius 1, z in [-h, h], outward) without
 * the side's segments whose middle angle lies in one of the nr ranges
 * (degrees, pairs lo, hi); *missing gets how many are gone. */
static st_soup *tall_cylinder(double h, const double *ranges, int nr, int *missing)
{
    st_soup *s = st_soup_new();
    for (int k = 0; k < SIDES; k++) {
        const double a = 2.0 * M_PI * k / SIDES;
        st_soup_add_vertex(s, cos(a), sin(a), -h, NULL);
        st_soup_add_vertex(s, cos(a), sin(a), h, NULL);
    }
    st_soup_add_vertex(s, 0, 0, -h, NULL);
    st_soup_add_vertex(s, 0, 0, h, NULL);
    *missing = 0;
    for (uint32_t k = 0; k < SIDES; k++) {
        const uint32_t k2 = (k + 1) % SIDES;
        const double mid = 360.0 * (k + 0.5) / SIDES;
        int gone = 0;
        for (int r = 0; r < nr; r++)
            gone |= in_range(mid, ranges[2 * r], ranges[2 * r + 1]);
        *missing += gone;
        if (!gone) {
            st_soup_add_triangle(s, 2 * k, 2 * k2, 2 * k2 + 1, NULL);
            st_soup_add_triangle(s, 2 * k, 2 * k2 + 1, 2 * k + 1, NULL);
        }
        st_soup_add_triangle(s, 2 * SIDES, 2 * k2, 2 * k, NULL);
        st_soup_add_triangle(s, 2 * SIDES + 1, 2 * k + 1, 2 * k2 + 1, NULL);
    }
    return s;
}

/* The cylinder of height 2. */
static st_soup *cylinder(const double *ranges, int nr, int *missing)
{
    return tall_cylinder(1.0, ranges, nr, missing);
}

typedef struct run {
    st_soup *caps, *fill, *kept;
    st_symmetry_fill_stats st;
} run;

static void run_free(run *r)
{
    st_soup_free(r->caps);
    st_soup_free(r->fill);
    st_soup_free(r->kept);
}

/* The caps (holes.h) and the fill of s under set. */
static int fill_of(run *r, const st_soup *s, const st_symmetry_set *set)
{
    memset(r, 0, sizeof *r);
    st_error err;
    st_soup_edges e;
    st_bvh *b = NULL;
    st_holes_params hp = st_holes_params_default();
    if (st_soup_edges_build(&e, s, &err))
        return 1;
    int rc = st_bvh_build(&b, s, &err) ||
             st_soup_hole_caps_shared(&r->caps, s, &e, b, &hp, NULL, &err) ||
             st_symmetry_fill(&r->fill, &r->kept, s, &e, b, set, r->caps, TOL, &r->st, &err);
    if (rc)
        printf("#   %s\n", err.msg);
    else
        printf("#   %zu cap triangles in %zu pieces, %zu open rims: fill %zu triangles "
               "(area %.4f), %zu caps dropped, %zu open filled, %zu left open\n",
               r->caps->ntris, r->st.caps, r->st.open, r->st.triangles, r->st.area,
               r->st.caps_covered, r->st.open_filled, r->st.unclosed);
    st_bvh_free(b);
    st_soup_edges_free(&e);
    return rc;
}

/* The share of points on a grid over the side between the angles lo and
 * hi (degrees, lo < hi) and heights -h and h within TOL of f or s. */
static double side_covered(const st_soup *f, const st_soup *s, double h, double lo, double hi)
{
    st_bvh *b = NULL;
    st_soup *both = st_soup_new();
    if (!both || st_soup_append(both, f, NULL) || st_soup_append(both, s, NULL) ||
        st_bvh_build(&b, both, NULL)) {
        st_soup_free(both);
        return 0.0;
    }
    int n = 0, near = 0;
    for (double a = lo + 0.5; a < hi; a += 1.0)
        for (double z = -h + 0.05; z < h; z += 0.1) {
            const double p[3] = {cos(a * M_PI / 180.0), sin(a * M_PI / 180.0), z};
            int64_t t;
            st_bvh_nearest(b, p, TOL * TOL, &t, NULL);
            near += t >= 0;
            n++;
        }
    st_bvh_free(b);
    st_soup_free(both);
    return (double)near / n;
}

static double seg_area_h(double h)
{
    return 2.0 * h * 2.0 * sin(M_PI / SIDES);   /* chord times height */
}

static double seg_area(void)
{
    return seg_area_h(1.0);
}

/* Whether every vertex of f is on the side of the cylinder of half height
 * h, within a segment of the angles [lo, hi]. */
static int on_side_in(const st_soup *f, double h, double lo, double hi)
{
    int ok = 1;
    for (size_t v = 0; v < f->nverts; v++) {
        const double *p = f->xyz + 3 * v;
        double a = atan2(p[1], p[0]) * 180.0 / M_PI;
        a = a < 0 ? a + 360.0 : a;
        ok &= fabs(hypot(p[0], p[1]) - 1.0) < 1e-9 && fabs(p[2]) <= h + 1e-12 &&
              in_range(a, lo - 360.0 / SIDES, hi + 360.0 / SIDES);
    }
    return ok;
}

static void test_open_hole(void)
{
    /* 110 degrees of the side: no cap (too large), its rim an open loop */
    const double hole[2] = {0.0, 110.0};
    int missing;
    st_soup *s = cylinder(hole, 1, &missing);
    const st_symmetry_set set = {{{ST_SYMMETRY_ROTATION, {0, 0, 0}, {0, 0, 1}, 0, 0.74, 0.0, 1.0}}, 1, 1};
    run r;
    TAP_CHECK(fill_of(&r, s, &set) == 0, "110 degrees missing: the fill runs");
    TAP_CHECK(r.caps->ntris == 0 && r.st.open == 1,
              "the hole is too large to cap: one open rim (%zu cap triangles, %zu open)",
              r.caps->ntris, r.st.open);
    TAP_CHECK(r.st.open_filled == 1 && r.st.unclosed == 0, "the fill closes it");
    const double want = missing * seg_area();
    TAP_NEAR(r.st.area / want, 1.0, 0.05, "fill area %.4f, the strip's %.4f", r.st.area, want);
    int on_side = 1, in_hole = 1;
    for (size_t v = 0; v < r.fill->nverts; v++) {
        const double *p = r.fill->xyz + 3 * v;
        const double rad = hypot(p[0], p[1]);
        double a = atan2(p[1], p[0]) * 180.0 / M_PI;
        a = a < 0 ? a + 360.0 : a;
        on_side &= fabs(rad - 1.0) < 1e-9 && fabs(p[2]) <= 1.0 + 1e-12;
        in_hole &= in_range(a, 360.0 - 360.0 / SIDES, 110.0 + 360.0 / SIDES);
    }
    TAP_CHECK(on_side, "every fill vertex on the cylinder's side");
    TAP_CHECK(in_hole, "every fill vertex in the hole (within a segment)");
    TAP_CHECK(r.kept->ntris == 0, "no caps to keep");
#ifdef _OPENMP
    const int threads = omp_get_max_threads();
    omp_set_num_threads(threads == 1 ? 2 : 1);
    run r2;
    int same = fill_of(&r2, s, &set) == 0 && r2.fill->ntris == r.fill->ntris &&
               memcmp(r2.fill->xyz, r.fill->xyz, 3 * r.fill->nverts * sizeof(double)) == 0;
    TAP_CHECK(same, "the same fill on %d and %d threads", threads, threads == 1 ? 2 : 1);
    omp_set_num_threads(threads);
    run_free(&r2);
#endif
    run_free(&r);
    st_soup_free(s);
}

/* 200 degrees gone from the side of a cylinder four times as tall as
 * wide: no turn puts the rim back on the soup over more than 0.65 of its
 * length (one of the two long straight sides falls into the hole itself,
 * where the soup cannot say), and none contradicts it. The turns by 15 to
 * 150 degrees and 210 to 345 fill it together. Without counting only
 * what the soup can check, no map agreed and nothing was filled. */
static void test_rim_in_hole(void)
{
    const double hole[2] = {160.0, 360.0}, h = 4.0;
    int missing;
    st_soup *s = tall_cylinder(h, hole, 1, &missing);
    const st_symmetry_set set = {{{ST_SYMMETRY_ROTATION, {0, 0, 0}, {0, 0, 1}, 0, 0.5, 0.0, 1.0}}, 1, 1};
    run r;
    TAP_CHECK(fill_of(&r, s, &set) == 0, "200 degrees missing: the fill runs");
    TAP_CHECK(r.caps->ntris == 0 && r.st.open == 1, "one open rim (%zu cap triangles, %zu open)",
              r.caps->ntris, r.st.open);
    TAP_CHECK(r.st.open_filled == 1, "the maps that agree where the soup can check fill it");
    const double want = missing * seg_area_h(h), cover = side_covered(r.fill, s, h, 160.0, 360.0);
    TAP_CHECK(cover == 1.0, "the fill covers the hole within a tolerance (%.4f of it; area %.4f, "
              "the strip's %.4f)", cover, r.st.area, want);
    TAP_CHECK(on_side_in(r.fill, h, 160.0, 0.0), "every fill vertex on the side, in the hole");
    run_free(&r);
    st_soup_free(s);
}

/* A 70-degree hole centered on angle 0; the mirror x = 0 maps it onto
 * [145, 215]. copy_holed: [170, 190) is gone too. */
static void mirror_case(int copy_holed)
{
    const double ranges[4] = {325.0, 35.0, 170.0, 190.0};
    int missing;
    st_soup *s = cylinder(ranges, copy_holed ? 2 : 1, &missing);
    const st_symmetry_set set = {{{ST_SYMMETRY_MIRROR, {0, 0, 0}, {1, 0, 0}, 0, 0.8, 0.0, 0.0}}, 1, 1};
    run r;
    TAP_CHECK(fill_of(&r, s, &set) == 0, "%s: the fill runs",
              copy_holed ? "copy holed" : "copy whole");
    TAP_CHECK(r.st.caps == (copy_holed ? 2u : 1u) && r.st.open == 0, "%zu capped holes, no open one",
              r.st.caps);
    if (!copy_holed) {
        TAP_CHECK(r.st.caps_covered == 1 && r.kept->ntris == 0,
                  "copy whole: the fill closes the hole, its cap is dropped");
        TAP_NEAR(r.st.area / (missing * seg_area()), 1.0, 0.05, "the fill is the hole (%.4f)",
                 r.st.area);
    } else {
        /* the copy leaves [-10, 10] open, and the fill lies behind the
         * cap: the cap is dropped, the partial fill kept (on 571dedc: the
         * cap kept, no fill) */
        TAP_CHECK(r.st.caps_covered == 1 && r.st.unclosed == 0,
                  "copy holed: the fill contradicts the cap, the cap is dropped (%zu dropped, "
                  "%zu left open)", r.st.caps_covered, r.st.unclosed);
        const double a = side_covered(r.fill, s, 1.0, -35.0, -10.0),
                     b = side_covered(r.fill, s, 1.0, 10.0, 35.0),
                     mid = side_covered(r.fill, s, 1.0, -5.0, 5.0);
        TAP_CHECK(a == 1.0 && b == 1.0 && mid < 1.0,
                  "the partial fill covers the hole but the copy's own hole (%.4f, %.4f; "
                  "the middle %.4f)", a, b, mid);
        TAP_CHECK(r.kept->ntris > 0 && r.kept->ntris < r.caps->ntris,
                  "the copy's hole keeps its cap (%zu of %zu cap triangles kept)", r.kept->ntris,
                  r.caps->ntris);
    }
    run_free(&r);
    st_soup_free(s);
}

static void test_copy_whole(void)
{
    mirror_case(0);
}

static void test_copy_holed(void)
{
    mirror_case(1);
}

/* A 120-degree hole centered on angle 0, and two of the cylinder's
 * mirror planes (a gear's planes through its teeth), at -5.625 and 28.125
 * degrees: each mirror's copy of the hole overlaps the hole itself, and
 * the two copies together leave [-3.75, 48.75] open (the fill's boundary
 * there is the image of the hole's own rim), so without more the fill did
 * not close the hole and nothing was filled. The turns the two mirrors
 * make, by 67.5 degrees either way, each clear half of it. */
static void test_mirror_turn(void)
{
    const double hole[2] = {300.0, 60.0};
    int missing;
    st_soup *s = cylinder(hole, 1, &missing);
    const double b1 = -5.625 * M_PI / 180.0, b2 = 28.125 * M_PI / 180.0;
    const st_symmetry_set set = {
        {{ST_SYMMETRY_MIRROR, {0, 0, 0}, {-sin(b1), cos(b1), 0}, 0, 0.8, 0.0, 0.0},
         {ST_SYMMETRY_MIRROR, {0, 0, 0}, {-sin(b2), cos(b2), 0}, 0, 0.8, 0.0, 0.0}},
        2, 2};
    run r;
    TAP_CHECK(fill_of(&r, s, &set) == 0, "120 degrees missing, two mirrors: the fill runs");
    TAP_CHECK(r.st.maps == 4, "the two mirrors and their turn either way: %zu maps", r.st.maps);
    TAP_CHECK(r.st.caps_covered + r.st.open_filled == 1 && r.st.unclosed == 0,
              "the turns close the hole (%zu caps dropped, %zu open filled, %zu left open)",
              r.st.caps_covered, r.st.open_filled, r.st.unclosed);
    const double cover = side_covered(r.fill, s, 1.0, -60.0, 60.0);
    TAP_CHECK(cover == 1.0, "the fill covers the hole within a tolerance (%.4f of it; area %.4f, "
              "the strip's %.4f)", cover, r.st.area, missing * seg_area());
    TAP_CHECK(on_side_in(r.fill, 1.0, 300.0, 60.0), "every fill vertex on the side, in the hole");
    run_free(&r);
    st_soup_free(s);
}

/* The mirrors' turns (the third round) are made only where the first two
 * rounds leave a hole unclosed: the 70-degree hole across the mirror
 * x = 0, with the mirror y = 0 beside it (which sends the hole onto
 * itself). The first round closes it through x = 0, so the set's two
 * maps are all that is tried (on f6ab7ab also their half turn about z,
 * made and never read: 3 maps), and the fill is the one x = 0 alone
 * gives, triangle for triangle. */
static void test_turns_unread(void)
{
    const double ranges[2] = {325.0, 35.0};
    int missing;
    st_soup *s = cylinder(ranges, 1, &missing);
    const st_symmetry_set one = {{{ST_SYMMETRY_MIRROR, {0, 0, 0}, {1, 0, 0}, 0, 0.8, 0.0, 0.0}}, 1, 1};
    const st_symmetry_set two = {{{ST_SYMMETRY_MIRROR, {0, 0, 0}, {1, 0, 0}, 0, 0.8, 0.0, 0.0},
                                  {ST_SYMMETRY_MIRROR, {0, 0, 0}, {0, 1, 0}, 0, 0.8, 0.0, 0.0}},
                                 2, 2};
    run a, b;
    TAP_CHECK(fill_of(&a, s, &one) == 0 && fill_of(&b, s, &two) == 0,
              "turns unread: the fill runs with one mirror and with two");
    TAP_CHECK(b.st.caps_covered == 1 && b.st.unclosed == 0 && b.st.maps == 2,
              "the first round closes the hole: %zu maps tried (the set's two, no turn)",
              b.st.maps);
    const int same = a.fill->ntris == b.fill->ntris && a.fill->nverts == b.fill->nverts &&
                     a.fill->ntris > 0 &&
                     !memcmp(a.fill->xyz, b.fill->xyz, 3 * a.fill->nverts * sizeof *a.fill->xyz) &&
                     !memcmp(a.fill->tris, b.fill->tris, 3 * a.fill->ntris * sizeof *a.fill->tris);
    TAP_CHECK(same, "the fill is the mirror x = 0's alone (%zu and %zu triangles)", a.fill->ntris,
              b.fill->ntris);
    run_free(&a);
    run_free(&b);
    st_soup_free(s);
}

/* The angle of the centroid of f's triangle t, in [0, 360). */
static double tri_angle(const st_soup *f, size_t t)
{
    double c[2] = {0, 0};
    for (int k = 0; k < 3; k++)
        for (int a = 0; a < 2; a++)
            c[a] += f->xyz[3 * f->tris[3 * t + k] + a] / 3.0;
    const double a = atan2(c[1], c[0]) * 180.0 / M_PI;
    return a < 0 ? a + 360.0 : a;
}

/* An 80-degree hole [60, 140] across the mirror x = 0 (angle a to
 * 180 - a): the mirror sends [60, 120] onto itself (the copy of what is
 * lost there is lost too) and [120, 140] onto [40, 60], which the soup
 * has. The fill runs along too little of the rim to close the hole, so
 * on 73c174e the cap stayed whole and no fill was kept ([120, 140] as
 * the cap's guess). The cap is split: the fill kept over [120, 140], the
 * cap kept over the part the mirror sends onto itself alone. */
static void test_straddles(void)
{
    const double hole[2] = {60.0, 140.0};
    int missing;
    st_soup *s = cylinder(hole, 1, &missing);
    for (size_t t = 0; t < s->ntris; t++) {   /* a bore: the solid outside */
        const uint32_t v = s->tris[3 * t + 1];
        s->tris[3 * t + 1] = s->tris[3 * t + 2];
        s->tris[3 * t + 2] = v;
    }
    const st_symmetry_set set = {{{ST_SYMMETRY_MIRROR, {0, 0, 0}, {1, 0, 0}, 0, 0.8, 0.0, 0.0}}, 1, 1};
    run r;
    TAP_CHECK(fill_of(&r, s, &set) == 0, "a hole across the plane: the fill runs");
    TAP_CHECK(r.st.caps == 1 && r.st.open == 0, "one capped hole (%zu)", r.st.caps);
    const double spoken = side_covered(r.fill, s, 1.0, 122.0, 138.0),
                 self = side_covered(r.fill, s, 1.0, 65.0, 115.0);
    TAP_CHECK(spoken == 1.0, "the fill covers the part the mirror speaks for (%.4f of [122, "
              "138]; area %.4f)", spoken, r.st.area);
    TAP_CHECK(self == 0.0, "and nothing of the part it sends onto itself (%.4f of [65, 115])",
              self);
    TAP_CHECK(on_side_in(r.fill, 1.0, 120.0, 140.0), "every fill vertex on the side, in "
              "[120, 140]");
    int in_self = 1;
    for (size_t t = 0; t < r.kept->ntris; t++)
        in_self &= in_range(tri_angle(r.kept, t), 55.0, 125.0);
    TAP_CHECK(r.kept->ntris > 0 && r.kept->ntris < r.caps->ntris && in_self,
              "the cap kept over the self-mapped part alone (%zu of %zu cap triangles)",
              r.kept->ntris, r.caps->ntris);
    TAP_CHECK(r.st.caps_split == 1 && r.st.caps_covered == 1, "the cap is split (%zu split, "
              "%zu covered)", r.st.caps_split, r.st.caps_covered);
    run_free(&r);
    st_soup_free(s);
}

static void test_no_symmetry(void)
{
    const double hole[2] = {0.0, 40.0};
    int missing;
    st_soup *s = cylinder(hole, 1, &missing);
    const st_symmetry_set set = {{{0}}, 0, 0};
    run r;
    TAP_CHECK(fill_of(&r, s, &set) == 0 && r.fill->ntris == 0 &&
                  r.kept->ntris == r.caps->ntris,
              "no symmetry: no fill, the caps as they were");
    run_free(&r);
    st_error err;
    st_soup *f = NULL, *k = NULL;
    TAP_CHECK(st_symmetry_fill(&f, &k, s, NULL, NULL, &set, NULL, 0.0, NULL, &err) == ST_EINPUT,
              "tolerance 0: ST_EINPUT");
    st_soup_free(s);
}

int main(int argc, char **argv)
{
    static const tap_test tests[] = {TAP_TEST(open_hole), TAP_TEST(rim_in_hole),
                                     TAP_TEST(copy_whole),
                                     TAP_TEST(copy_holed), TAP_TEST(mirror_turn), TAP_TEST(turns_unread),
                                     TAP_TEST(straddles),
                                     TAP_TEST(no_symmetry), {0}};
    return tap_main(argc, argv, tests);
}
