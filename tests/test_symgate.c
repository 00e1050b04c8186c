/* test_symgate.c - the gate on the symmetric fill (symmetry.h,
 * st_symmetry_fill_may_act): told without a search whether any fill
 * could change the caps. The claim is checked against the fill itself:
 * on a ringed cylinder with holes of several sizes, at tolerances from
 * fine to coarse, wherever the gate says no fill can act, the fill under
 * the cylinder's true symmetries (its axis, its mirror planes) keeps
 * every cap and adds nothing; small holes at a coarse tolerance are
 * gated, the same at a fine one are not (and there the fill acts); a
 * hole too large to cap is an open rim, never gated. */
#include "souptet/bvh.h"
#include "souptet/edges.h"
#include "souptet/holes.h"
#include "souptet/soup.h"
#include "souptet/symmetry.h"
#include "tap.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define PI 3.14159265358979323846
#define SIDES 64
#define RINGS 16   /* the side in 16 rings: quads 0.098 wide, 0.125 high */

/* A closed cylinder (radius 1, z in [-1, 1], outward) with its side in
 * RINGS rings, without the side's quads in columns [c0, c0 + nc) and
 * rings [r0, r0 + nr) (one triangle alone where half is set: the quad's
 * other half stays). */
static st_soup *ringed(int c0, int nc, int r0, int nr, int half)
{
    st_soup *s = st_soup_new();
    for (int r = 0; r <= RINGS; r++)
        for (int k = 0; k < SIDES; k++) {
            const double a = 2.0 * PI * k / SIDES;
            st_soup_add_vertex(s, cos(a), sin(a), -1.0 + 2.0 * r / RINGS, NULL);
        }
    const uint32_t bot = (uint32_t)s->nverts, top = bot + 1;
    st_soup_add_vertex(s, 0, 0, -1.0, NULL);
    st_soup_add_vertex(s, 0, 0, 1.0, NULL);
    for (int r = 0; r < RINGS; r++)
        for (int k = 0; k < SIDES; k++) {
            const uint32_t a = (uint32_t)(r * SIDES + k), b = (uint32_t)(r * SIDES + (k + 1) % SIDES);
            const int gone = k >= c0 && k < c0 + nc && r >= r0 && r < r0 + nr;
            if (!gone || half)
                st_soup_add_triangle(s, a, b, b + SIDES, NULL);
            if (!gone)
                st_soup_add_triangle(s, a, b + SIDES, a + SIDES, NULL);
        }
    for (int k = 0; k < SIDES; k++) {
        const uint32_t k2 = (uint32_t)((k + 1) % SIDES);
        st_soup_add_triangle(s, bot, k2, (uint32_t)k, NULL);
        st_soup_add_triangle(s, top, (uint32_t)(RINGS * SIDES + k),
                             (uint32_t)(RINGS * SIDES) + k2, NULL);
    }
    return s;
}

/* The cylinder's symmetries: its continuous axis and two mirror planes. */
static const st_symmetry_set cylinder_set = {
    {{ST_SYMMETRY_ROTATION, {0, 0, 0}, {0, 0, 1}, 0, 0.9, 0.0, 1.0},
     {ST_SYMMETRY_MIRROR, {0, 0, 0}, {0, 0, 1}, 0, 0.9, 0.0, 0.0},
     {ST_SYMMETRY_MIRROR, {0, 0, 0}, {0, 1, 0}, 0, 0.9, 0.0, 0.0}},
    3, 3};

typedef struct outcome {
    int may;
    st_symmetry_fill_gate gate;
    size_t caps, fill, kept;
    st_symmetry_fill_stats st;
} outcome;

/* The gate and the fill of s at tol. */
static int gate_and_fill(outcome *o, const st_soup *s, double tol)
{
    memset(o, 0, sizeof *o);
    st_error err;
    st_soup_edges e;
    st_bvh *b = NULL;
    st_soup *caps = NULL, *fill = NULL, *kept = NULL;
    st_holes_params hp = st_holes_params_default();
    if (st_soup_edges_build(&e, s, &err))
        return 1;
    int rc = st_bvh_build(&b, s, &err) ||
             st_soup_hole_caps_shared(&caps, s, &e, b, &hp, NULL, &err) ||
             st_symmetry_fill_may_act(&o->may, &o->gate, s, &e, b, caps, tol, &err) ||
             st_symmetry_fill(&fill, &kept, s, &e, b, &cylinder_set, caps, tol, &o->st, &err);
    if (rc) {
        printf("#   %s\n", err.msg);
    } else {
        o->caps = caps->ntris;
        o->fill = fill->ntris;
        o->kept = kept->ntris;
    }
    st_soup_free(caps);
    st_soup_free(fill);
    st_soup_free(kept);
    st_bvh_free(b);
    st_soup_edges_free(&e);
    return rc;
}

static void test_claim(void)
{
    /* holes: a triangle, a quad, 2 x 2 quads, 6 x 6 quads */
    const int holes[4][3] = {{1, 1, 1}, {1, 1, 0}, {2, 2, 0}, {6, 6, 0}};
    const double tols[5] = {0.01, 0.03, 0.06, 0.12, 0.25};
    int runs = 0, gated = 0, wrong = 0, acted_ungated = 0;
    for (int h = 0; h < 4; h++) {
        st_soup *s = ringed(3, holes[h][0], 5, holes[h][1], holes[h][2]);
        for (int t = 0; t < 5; t++) {
            outcome o;
            if (gate_and_fill(&o, s, tols[t]))
                continue;
            runs++;
            const int acts = o.fill > 0 || o.kept != o.caps || o.st.caps_covered ||
                             o.st.open_filled;
            printf("#   hole %d x %d%s, tol %.2f: gate %d (%zu of %zu pieces active, "
                   "reach %.4f, spread %.4f, %zu open edges); fill %zu triangles, "
                   "%zu of %zu caps dropped, %zu agree\n",
                   holes[h][0], holes[h][1], holes[h][2] ? " (half)" : "", tols[t], o.may,
                   o.gate.active, o.gate.pieces, o.gate.reach, o.gate.spread,
                   o.gate.open_edges, o.fill, o.st.caps_covered, o.st.caps, o.st.caps_agree);
            gated += !o.may;
            wrong += !o.may && acts;
            acted_ungated += o.may && acts;
        }
        st_soup_free(s);
    }
    TAP_CHECK(runs == 20, "20 runs of the gate and the fill (%d)", runs);
    TAP_CHECK(wrong == 0, "where the gate says no fill can act, none does (%d wrong)", wrong);
    TAP_CHECK(gated >= 3, "the small holes at 0.25 are gated (%d of 20)", gated);
    TAP_CHECK(acted_ungated > 0, "and the fill does act where it is not (%d runs)",
              acted_ungated);
}

static void test_cases(void)
{
    outcome o;
    st_soup *s = ringed(3, 1, 5, 1, 0);   /* one quad */
    TAP_CHECK(gate_and_fill(&o, s, 0.25) == 0 && o.may == 0 && o.gate.pieces == 1 &&
              o.gate.active == 0 && o.gate.open_edges == 0,
              "one quad's hole at 0.25: gated (%d, %zu pieces)", o.may, o.gate.pieces);
    TAP_CHECK(gate_and_fill(&o, s, 0.03) == 0 && o.may == 1 && o.gate.active == 1,
              "the same at 0.03: not gated");
    st_soup_free(s);
    s = ringed(3, 2, 5, 2, 0);
    TAP_CHECK(gate_and_fill(&o, s, 0.03) == 0 && o.may == 1 && o.st.caps_covered == 1 &&
              o.fill > 0,
              "2 x 2 quads at 0.03: not gated, and the fill drops the cap (%zu triangles)",
              o.fill);
    st_soup_free(s);
    /* a hole too large to cap: the side's 32 columns, every ring */
    s = ringed(0, 32, 0, RINGS, 0);
    TAP_CHECK(gate_and_fill(&o, s, 0.25) == 0 && o.may == 1 && o.gate.open_edges > 0 &&
              o.st.open == 1,
              "half the side gone, an open rim: not gated (%zu open edges)",
              o.gate.open_edges);
    st_soup_free(s);
    /* a closed soup: nothing to fill */
    s = ringed(0, 0, 0, 0, 0);
    TAP_CHECK(gate_and_fill(&o, s, 0.03) == 0 && o.may == 0 && o.gate.pieces == 0,
              "a closed soup: gated");
    st_error err;
    st_bvh *b = NULL;
    int may = 7;
    TAP_CHECK(st_bvh_build(&b, s, &err) == ST_OK &&
              st_symmetry_fill_may_act(&may, NULL, s, NULL, b, NULL, 0.0, &err) == ST_EINPUT &&
              may == 1, "a tolerance of 0: ST_EINPUT, *may 1 (%s)", err.msg);
    TAP_CHECK(st_symmetry_fill_may_act(&may, NULL, s, NULL, b, NULL, NAN, &err) == ST_EINPUT,
              "NaN: ST_EINPUT");
    st_bvh_free(b);
    st_soup_free(s);
}

int main(int argc, char **argv)
{
    static const tap_test tests[] = {TAP_TEST(claim), TAP_TEST(cases), {0}};
    return tap_main(argc, argv, tests);
}
