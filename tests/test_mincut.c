/*
 * test_mincut.c - the grid minimum cut (mincut.h): its labelling has the
 * least energy of all labellings (brute force on small grids), it spans a
 * gap in a surface (a jar's mouth) by the least area, and it joins evidence-free voxels
 * to the side that encloses them.
 */
#include "souptet/mincut.h"
#include "tap.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* The energy mincut.h defines, computed the plain way: evidence against
 * each voxel's label plus the face capacity of every pair labelled
 * differently (the capacities written out again from the header's words:
 * 1 + free_area * min(1, (min|d| / surface)^power), rounded). */
static double energy(const st_grid *g, const int8_t *ev, const uint8_t *in,
                     const st_mincut_params *p)
{
    const size_t nx = g->nx, ny = g->ny, nz = g->nz;
    const double s = p->surface_voxels * g->voxel;
    double e = 0;
    for (size_t k = 0; k < nz; k++)
        for (size_t j = 0; j < ny; j++)
            for (size_t i = 0; i < nx; i++) {
                const size_t v = st_grid_index(g, i, j, k);
                if (in[v] && ev[v] < 0)
                    e += (double)llround(-ev[v] * p->evidence_weight);
                if (!in[v] && ev[v] > 0)
                    e += (double)llround(ev[v] * p->evidence_weight);
                const size_t nb[3] = {i + 1 < nx ? v + 1 : v, j + 1 < ny ? v + nx : v,
                                      k + 1 < nz ? v + nx * ny : v};
                for (int a = 0; a < 3; a++) {
                    const size_t q = nb[a];
                    if (q == v || in[q] == in[v])
                        continue;
                    double x = fmin(fabsf(g->data[v]), fabsf(g->data[q])) / s;
                    e += 1 + (int32_t)(p->free_area * (x >= 1 ? 1 : pow(x, p->power)) + 0.5);
                }
            }
    return e;
}

static unsigned rnd(unsigned *seed)
{
    *seed = *seed * 1664525u + 1013904223u;
    return *seed >> 8;
}

static void test_brute_force(void)
{
    /* 5 x 5 x 4: 18 interior voxels; the border is outside, voxels with
     * |evidence| >= fixed keep their side, the rest are free: every
     * labelling of the free ones is tried. */
    st_mincut_params p = st_mincut_params_default();
    unsigned seed = 4242u;
    int all_least = 1, all_kept = 1, some_split = 0;
    for (int trial = 0; trial < 12; trial++) {
        st_grid *g;
        st_error err;
        const double org[3] = {0, 0, 0};
        if (st_grid_new(&g, 5, 5, 4, org, 0.5, 0.0f, 0, &err)) {
            all_least = 0;
            continue;
        }
        const size_t n = st_grid_count(g);
        int8_t *ev = malloc(n), *lab = malloc(n);
        uint8_t *in = calloc(n, 1), *best = calloc(n, 1);
        size_t freev[64], nf = 0;
        for (size_t v = 0; v < n; v++) {
            g->data[v] = (float)(rnd(&seed) % 100) / 100.0f * (trial % 3 ? 0.5f : 2.0f);
            int e = (int)(rnd(&seed) % 27) - 13;
            if (trial % 4 == 0 && e < 0)
                e = -e / 3;     /* mostly inside: the border must still win */
            ev[v] = (int8_t)e;
        }
        memcpy(lab, ev, n);
        if (st_mincut_label(g, lab, &p, NULL, &err)) {
            all_least = 0;
            free(ev); free(lab); free(in); free(best);
            st_grid_free(g);
            continue;
        }
        /* The fixed labels, and the free voxels. */
        for (size_t k = 0; k < g->nz; k++)
            for (size_t j = 0; j < g->ny; j++)
                for (size_t i = 0; i < g->nx; i++) {
                    const size_t v = st_grid_index(g, i, j, k);
                    const int border = !i || !j || !k || i == g->nx - 1 || j == g->ny - 1 ||
                                       k == g->nz - 1;
                    if (border || abs(ev[v]) >= p.fixed_evidence) {
                        in[v] = !border && ev[v] > 0;
                        all_kept &= lab[v] == (int8_t)in[v];
                    } else
                        freev[nf++] = v;
                }
        double least = INFINITY;
        for (unsigned long mask = 0; mask < (1ul << nf); mask++) {
            for (size_t f = 0; f < nf; f++)
                in[freev[f]] = (mask >> f) & 1u;
            double e = energy(g, ev, in, &p);
            if (e < least) {
                least = e;
                memcpy(best, in, n);
            }
        }
        for (size_t v = 0; v < n; v++)
            in[v] = (uint8_t)lab[v];
        const double got = energy(g, ev, in, &p);
        if (got != least) {
            all_least = 0;
            TAP_NOTE("trial %d: cut energy %.0f, least %.0f", trial, got, least);
        }
        size_t ins = 0;
        for (size_t f = 0; f < nf; f++)
            ins += lab[freev[f]] == 1;
        some_split |= ins > 0 && ins < nf;
        free(ev); free(lab); free(in); free(best);
        st_grid_free(g);
    }
    TAP_CHECK(all_least, "the cut's labelling has the least energy of all (12 random 5x5x4 grids)");
    TAP_CHECK(all_kept, "decided voxels keep their side, the border is outside");
    TAP_CHECK(some_split, "the random grids are not all trivially one side");
}

/* The distance from q to a jar: the box [-1,1]^3 whose top face (z = 1)
 * has a square mouth |x|, |y| < 0.5 cut out of it. */
static double jar_distance(const double q[3])
{
    double best = INFINITY;
    for (int axis = 0; axis < 3; axis++)
        for (int side = -1; side <= 1; side += 2) {
            double c[3];
            for (int a = 0; a < 3; a++)
                c[a] = q[a] < -1 ? -1 : q[a] > 1 ? 1 : q[a];
            c[axis] = side;
            if (axis == 2 && side == 1 && fabs(c[0]) < 0.5 && fabs(c[1]) < 0.5) {
                int a = fabs(c[0]) > fabs(c[1]) ? 0 : 1;   /* to the mouth's edge */
                c[a] = c[a] < 0 ? -0.5 : 0.5;
            }
            double d = sqrt((q[0] - c[0]) * (q[0] - c[0]) + (q[1] - c[1]) * (q[1] - c[1]) +
                            (q[2] - c[2]) * (q[2] - c[2]));
            if (d < best)
                best = d;
        }
    return best;
}

static void test_cup(void)
{
    /* A jar with an open mouth: the votes say inside only in its lower
     * half (rays out through the mouth make the upper half a tie) and
     * outside far from it. The cut closes the jar across its mouth, the
     * least area (a cut through the jar's middle would be four times as
     * large): the whole jar is inside, nothing outside it. */
    const double h = 0.125, org[3] = {-1.5, -1.5, -1.5};
    st_grid *g;
    st_error err;
    if (st_grid_new(&g, 25, 25, 25, org, h, 0.0f, 0, &err)) {
        TAP_CHECK(0, "jar grid");
        return;
    }
    const size_t n = st_grid_count(g);
    int8_t *lab = malloc(n);
    for (size_t k = 0; k < g->nz; k++)
        for (size_t j = 0; j < g->ny; j++)
            for (size_t i = 0; i < g->nx; i++) {
                const double q[3] = {org[0] + h * i, org[1] + h * j, org[2] + h * k};
                const size_t v = st_grid_index(g, i, j, k);
                g->data[v] = (float)jar_distance(q);
                const int in = fabs(q[0]) < 1 && fabs(q[1]) < 1 && fabs(q[2]) < 1;
                lab[v] = (int8_t)(in ? (q[2] < 0 ? 6 : 0) : (g->data[v] > 0.3 ? -13 : 0));
            }
    st_mincut_params p = st_mincut_params_default();
    size_t wrong_in = 0, wrong_out = 0, cup = 0;
    int8_t *ev = malloc(n);
    memcpy(ev, lab, n);
    if (st_mincut_label(g, lab, &p, NULL, &err) == ST_OK)
        for (size_t k = 0; k < g->nz; k++)
            for (size_t j = 0; j < g->ny; j++)
                for (size_t i = 0; i < g->nx; i++) {
                    const double q[3] = {org[0] + h * i, org[1] + h * j, org[2] + h * k};
                    const size_t v = st_grid_index(g, i, j, k);
                    const int in = fabs(q[0]) < 1 && fabs(q[1]) < 1 && fabs(q[2]) < 1;
                    cup += in;
                    wrong_in += !in && lab[v] == 1;
                    wrong_out += in && lab[v] == 0;
                }
    TAP_CHECK(cup > 0 && wrong_in == 0 && wrong_out == 0,
              "open jar: closed across its mouth (%zu of %zu jar voxels outside, %zu others inside)",
              wrong_out, cup, wrong_in);
    /* Make sure the test is about the cut: the jar's upper half has no
     * evidence either way. */
    size_t none = 0;
    for (size_t k = 0; k < g->nz; k++)
        for (size_t j = 0; j < g->ny; j++)
            for (size_t i = 0; i < g->nx; i++) {
                const double q[3] = {org[0] + h * i, org[1] + h * j, org[2] + h * k};
                none += fabs(q[0]) < 1 && fabs(q[1]) < 1 && fabs(q[2]) < 1 &&
                        ev[st_grid_index(g, i, j, k)] == 0;
            }
    TAP_CHECK(none >= cup / 3, "the jar's upper half had no evidence (%zu voxels)", none);
    free(ev);
    free(lab);
    st_grid_free(g);
}

static void test_enclosed(void)
{
    /* Two overlapping boxes' surfaces: parity calls the overlap outside
     * (two crossings from anywhere), so it has no evidence; the boxes
     * alone are inside. The cut keeps the union whole: the overlap is
     * enclosed by the inside, and cutting it out costs its surfaces. */
    const double h = 0.1, org[3] = {-1.5, -1.5, -1.0};
    st_grid *g;
    st_error err;
    if (st_grid_new(&g, 31, 31, 21, org, h, 0.0f, 0, &err)) {
        TAP_CHECK(0, "boxes grid");
        return;
    }
    const size_t n = st_grid_count(g);
    int8_t *lab = malloc(n);
    const double lo[2][3] = {{-1, -1, -0.5}, {-0.2, -0.2, -0.5}}, hi[2][3] = {{0.3, 0.3, 0.5}, {1, 1, 0.5}};
    for (size_t k = 0; k < g->nz; k++)
        for (size_t j = 0; j < g->ny; j++)
            for (size_t i = 0; i < g->nx; i++) {
                const double q[3] = {org[0] + h * i, org[1] + h * j, org[2] + h * k};
                const size_t v = st_grid_index(g, i, j, k);
                double d = INFINITY;
                int inb[2];
                for (int b = 0; b < 2; b++) {
                    inb[b] = 1;
                    double out2 = 0, in_min = INFINITY;
                    for (int a = 0; a < 3; a++) {
                        double e = fmax(lo[b][a] - q[a], q[a] - hi[b][a]);
                        if (e > 0)
                            out2 += e * e, inb[b] = 0;
                        in_min = fmin(in_min, -e);
                    }
                    d = fmin(d, inb[b] ? in_min : sqrt(out2));
                }
                g->data[v] = (float)d;
                lab[v] = (int8_t)(inb[0] != inb[1] ? 13 : inb[0] ? 0 : -13);
            }
    st_mincut_params p = st_mincut_params_default();
    size_t overlap = 0, lost = 0;
    if (st_mincut_label(g, lab, &p, NULL, &err) == ST_OK)
        for (size_t k = 0; k < g->nz; k++)
            for (size_t j = 0; j < g->ny; j++)
                for (size_t i = 0; i < g->nx; i++) {
                    const double q[3] = {org[0] + h * i, org[1] + h * j, org[2] + h * k};
                    int both = 1;
                    for (int b = 0; b < 2; b++)
                        for (int a = 0; a < 3; a++)
                            both &= q[a] > lo[b][a] && q[a] < hi[b][a];
                    overlap += both;
                    lost += both && lab[st_grid_index(g, i, j, k)] == 0;
                }
    TAP_CHECK(overlap > 0 && lost == 0,
              "overlapping boxes: the overlap without evidence is inside (%zu of %zu lost)", lost,
              overlap);
    free(lab);
    st_grid_free(g);
}

int main(int argc, char **argv)
{
    static const tap_test tests[] = {TAP_TEST(brute_force), TAP_TEST(cup), TAP_TEST(enclosed),
                                     {0}};
    return tap_main(argc, argv, tests);
}
