/*
 * test_mincut.c - the grid minimum cut (mincut.h): its labelling has the
 * least energy of all labellings (brute force on small grids), it spans a
 * gap in a surface (a jar's mouth) by the least area, and it joins evidence-free voxels
 * to the side that encloses them; its labels are a plain max-flow's (the
 * source side of the residual graph) on random grids.
 */
#include "souptet/mincut.h"
#include "tap.h"

#include <math.h>
#include <omp.h>
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

/* A plain max-flow for reference: Edmonds and Karp's shortest augmenting
 * paths with capacity scaling (only residuals of at least delta, delta
 * halved when no such path is left, down to 1: without it grids of weak
 * evidence and cheap faces take millions of one-unit paths) on the graph
 * mincut.h describes, written out with every voxel a node (decided ones
 * tied to their terminal by an unbounded link). Its labels: the voxels
 * the source reaches in the residual graph once delta 1 finds no path,
 * which is the same set for every maximum flow (the least inside of all
 * the cheapest labellings). */
#define REF_INF ((int64_t)1 << 40)
#define NONE SIZE_MAX
static void reference_cut(const st_grid *g, const int8_t *ev, const st_mincut_params *p,
                          uint8_t *in)
{
    const size_t nx = g->nx, ny = g->ny, nz = g->nz, n = st_grid_count(g);
    const ptrdiff_t off[6] = {1, -1, (ptrdiff_t)nx, -(ptrdiff_t)nx, (ptrdiff_t)(nx * ny),
                              -(ptrdiff_t)(nx * ny)};
    const double s = p->surface_voxels * g->voxel;
    int64_t *r = calloc(6 * n, sizeof *r), *rs = calloc(n, sizeof *rs), *rt = calloc(n, sizeof *rt);
    size_t *queue = malloc(n * sizeof *queue), *from = malloc(n * sizeof *from);
    for (size_t k = 0; k < nz; k++)
        for (size_t j = 0; j < ny; j++)
            for (size_t i = 0; i < nx; i++) {
                const size_t v = st_grid_index(g, i, j, k);
                const int border = !i || !j || !k || i == nx - 1 || j == ny - 1 || k == nz - 1;
                const int has[6] = {i + 1 < nx, i > 0, j + 1 < ny, j > 0, k + 1 < nz, k > 0};
                if (border || ev[v] <= -p->fixed_evidence)
                    rt[v] = REF_INF;
                else if (ev[v] >= p->fixed_evidence)
                    rs[v] = REF_INF;
                else if (ev[v] > 0)
                    rs[v] = llround(ev[v] * p->evidence_weight);
                else
                    rt[v] = llround(-ev[v] * p->evidence_weight);
                for (int a = 0; a < 6; a++) {
                    if (!has[a])
                        continue;
                    const size_t w = (size_t)((ptrdiff_t)v + off[a]);
                    double x = fmin(fabsf(g->data[v]), fabsf(g->data[w])) / s;
                    r[6 * v + a] = 1 + (int32_t)(p->free_area * (x >= 1 ? 1 : pow(x, p->power)) + 0.5);
                }
            }
    int64_t delta = (int64_t)1 << 20;   /* above every finite capacity */
    for (;;) {
        /* breadth first from the source; from[w]: the arc into w (6 v + a), or
         * NONE for a source (n itself can be an arc's index) */
        size_t head = 0, tail = 0, last = n;
        memset(in, 0, n);
        for (size_t v = 0; v < n; v++)
            if (rs[v] >= delta) {
                in[v] = 1;
                from[v] = NONE;
                queue[tail++] = v;
            }
        while (head < tail && last == n) {
            const size_t v = queue[head++];
            if (rt[v] >= delta) {
                last = v;
                break;
            }
            for (int a = 0; a < 6; a++)
                if (r[6 * v + a] >= delta) {
                    const size_t w = (size_t)((ptrdiff_t)v + off[a]);
                    if (!in[w]) {
                        in[w] = 1;
                        from[w] = 6 * v + (size_t)a;
                        queue[tail++] = w;
                    }
                }
        }
        if (last == n && delta > 1) {
            delta /= 2;
            continue;
        }
        if (last == n)
            break;      /* in: what the source reaches */
        int64_t m = rt[last];
        size_t v = last;
        for (; from[v] != NONE; v = from[v] / 6)
            m = r[from[v]] < m ? r[from[v]] : m;
        m = rs[v] < m ? rs[v] : m;
        rt[last] -= m;
        for (v = last; from[v] != NONE; v = from[v] / 6) {
            const int a = (int)(from[v] % 6);
            r[from[v]] -= m;
            r[6 * v + (size_t)(a ^ 1)] += m;
        }
        rs[v] -= m;
    }
    free(r); free(rs); free(rt); free(queue); free(from);
}

static void test_reference(void)
{
    /* Random grids with a blob of inside evidence in weak outside
     * evidence (or, every other grid, evidence either way at random),
     * voxels without evidence and a few decided ones, and
     * distances from the surface to beyond it (cheap faces and free
     * space): the cut's labels are the reference max-flow's, voxel for
     * voxel, not merely as cheap. */
    st_mincut_params p = st_mincut_params_default();
    unsigned seed = 977u;
    size_t differ = 0, inside = 0, outside = 0;
    for (int trial = 0; trial < 16; trial++) {
        st_grid *g;
        st_error err;
        const double org[3] = {0, 0, 0};
        const size_t nx = 9 + (size_t)trial % 4, ny = 10, nz = 8 + (size_t)trial % 3;
        if (st_grid_new(&g, nx, ny, nz, org, 0.5, 0.0f, 0, &err)) {
            differ++;
            continue;
        }
        const size_t n = st_grid_count(g);
        int8_t *ev = malloc(n), *lab = malloc(n);
        uint8_t *in = malloc(n);
        const double c[3] = {(double)(rnd(&seed) % nx), (double)(rnd(&seed) % ny),
                             (double)(rnd(&seed) % nz)};
        const double rad = 1.5 + rnd(&seed) % 3;
        for (size_t k = 0; k < nz; k++)
            for (size_t j = 0; j < ny; j++)
                for (size_t i = 0; i < nx; i++) {
                    const size_t v = st_grid_index(g, i, j, k);
                    const double dr = sqrt((i - c[0]) * (i - c[0]) + (j - c[1]) * (j - c[1]) +
                                           (k - c[2]) * (k - c[2])) - rad;
                    g->data[v] = (float)(fabs(dr) * 0.5 * (0.5 + (rnd(&seed) % 100) / 100.0));
                    const unsigned r = rnd(&seed) % 16;
                    int e = dr < 0 ? (int)(rnd(&seed) % 14) - 2 : -(int)(rnd(&seed) % 9);
                    if (trial % 2)      /* salt and pepper: roots of both trees side by side */
                        e = (int)(rnd(&seed) % 19) - 9 - (dr > 0);
                    if (r == 0)
                        e = 0;
                    else if (r == 1)
                        e = (rnd(&seed) & 1u) ? 12 : -12;
                    ev[v] = (int8_t)e;
                }
        memcpy(lab, ev, n);
        if (st_mincut_label(g, lab, &p, NULL, &err)) {
            differ++;
        } else {
            reference_cut(g, ev, &p, in);
            for (size_t v = 0; v < n; v++) {
                differ += lab[v] != (int8_t)in[v];
                inside += in[v] != 0;
                outside += in[v] == 0;
            }
        }
        free(ev); free(lab); free(in);
        st_grid_free(g);
    }
    TAP_CHECK(differ == 0, "the cut's labels are the reference max-flow's (%zu voxels differ)", differ);
    TAP_CHECK(inside > 0 && outside > inside, "the random grids have both sides (%zu inside, %zu outside)",
              inside, outside);
}

/* The voxels where st_mincut_label's labels differ from the reference's
 * on grid g with evidence ev (ev is kept); 1 + n when the cut fails. */
static size_t differ_from_reference(const st_grid *g, const int8_t *ev, const st_mincut_params *p)
{
    const size_t n = st_grid_count(g);
    int8_t *lab = malloc(n);
    uint8_t *in = malloc(n);
    st_error err;
    size_t differ = 1 + n;
    memcpy(lab, ev, n);
    if (st_mincut_label(g, lab, p, NULL, &err) == ST_OK) {
        reference_cut(g, ev, p, in);
        differ = 0;
        for (size_t v = 0; v < n; v++)
            differ += lab[v] != (int8_t)in[v];
    }
    free(lab);
    free(in);
    return differ;
}

/* Grids made to be hard for the solver's shortcuts, each against the
 * reference: a serpentine corridor of free space walled by cheap faces
 * (long augmenting paths, deep trees, orphans re-adopted along it), a
 * checkerboard of opposite evidence (roots of both trees side by side
 * everywhere), exact ties (a voxel whose evidence equals the cost of
 * cutting it out: the least inside leaves it out), no evidence at all,
 * evidence one way everywhere, grids one voxel thick between their
 * borders, and random parameters (the decided threshold from 1 to 127,
 * the faces' cost and power). */
static void fill_case(st_grid *g, int8_t *ev, int kind, unsigned *seed)
{
    const size_t nx = g->nx, ny = g->ny, nz = g->nz;
    for (size_t k = 0; k < nz; k++)
        for (size_t j = 0; j < ny; j++)
            for (size_t i = 0; i < nx; i++) {
                const size_t v = st_grid_index(g, i, j, k);
                float d = 2.0f;
                int e = 0;
                if (kind == 0) {        /* serpentine: rows j odd are walls with one gap */
                    const int wall = j % 2 == 1 && i != ((j / 2) % 2 ? 1 : nx - 2);
                    d = wall ? 0.05f * (float)(rnd(seed) % 8) : 2.0f;
                    e = j == 1 && i == 1 ? 9 : j == ny - 2 ? -3 : 0;
                    if (k == nz / 2 && j % 2 == 0 && i == nx / 2)
                        e = (int)(rnd(seed) % 19) - 9;
                } else if (kind == 1) { /* checkerboard */
                    e = (i + j + k) % 2 ? 4 : -4;
                    d = 0.25f * (float)(rnd(seed) % 9);
                } else if (kind == 2) { /* ties: cap 100 a free face, 100 a vote */
                    e = i == nx / 2 && j == ny / 2 && k == nz / 2 ? 6 : 0;
                    if (i == 2 && j == 2 && k == 2)
                        e = 7;
                } else if (kind == 3) { /* nothing */
                    d = 0.3f * (float)(rnd(seed) % 5);
                } else if (kind == 4) { /* inside evidence everywhere */
                    e = 1 + (int)(rnd(seed) % 9);
                    d = 0.1f * (float)(rnd(seed) % 4);  /* cheap faces: a small flow */
                } else {                /* random evidence and distances */
                    e = (int)(rnd(seed) % 255) - 127;
                    if (rnd(seed) % 3)
                        e /= 16;
                    d = 0.2f * (float)(rnd(seed) % 12);
                }
                g->data[v] = d;
                ev[v] = (int8_t)e;
            }
}

static void test_adversarial(void)
{
    unsigned seed = 31337u;
    size_t differ = 0, cases = 0;
    static const size_t dims[][3] = {{15, 13, 5}, {9, 8, 7}, {9, 9, 9}, {8, 7, 6}, {10, 9, 8},
                                     {3, 9, 8}, {9, 3, 8}, {9, 8, 3}, {2, 2, 2}, {1, 5, 5},
                                     {4, 4, 4}, {12, 5, 4}};
    for (int kind = 0; kind < 6; kind++)
        for (size_t t = 0; t < sizeof dims / sizeof dims[0]; t++) {
            st_grid *g;
            st_error err;
            const double org[3] = {0, 0, 0};
            if (st_grid_new(&g, dims[t][0], dims[t][1], dims[t][2], org, 1.0, 0.0f, 0, &err)) {
                differ++;
                continue;
            }
            if (kind == 1 && st_grid_count(g) > 400) {
                st_grid_free(g);        /* the reference augments a unit at a time */
                continue;
            }
            int8_t *ev = malloc(st_grid_count(g));
            st_mincut_params p = st_mincut_params_default();
            if (kind == 2)
                p.free_area = 99.0;     /* a free face costs 100, six of them a vote of 6 */
            if (kind == 5) {
                p.fixed_evidence = 1 + (int)(rnd(&seed) % 127);
                p.free_area = 1.0 + rnd(&seed) % 3000;
                p.power = 1.0 + rnd(&seed) % 3;
                p.evidence_weight = 1.0 + rnd(&seed) % 300;
            }
            fill_case(g, ev, kind, &seed);
            differ += differ_from_reference(g, ev, &p);
            cases++;
            free(ev);
            st_grid_free(g);
        }
    TAP_CHECK(differ == 0, "adversarial grids: the cut's labels are the reference's (%zu voxels differ in %zu grids)",
              differ, cases);
    /* The tie: the voxel of evidence 6 (its cut costs exactly its
     * evidence) is outside, the one of 7 inside. */
    st_grid *g;
    st_error err;
    const double org[3] = {0, 0, 0};
    if (st_grid_new(&g, 9, 9, 9, org, 1.0, 0.0f, 0, &err) == ST_OK) {
        const size_t n = st_grid_count(g);
        int8_t *ev = malloc(n);
        fill_case(g, ev, 2, &seed);
        st_mincut_params p = st_mincut_params_default();
        p.free_area = 99.0;
        int ok = st_mincut_label(g, ev, &p, NULL, &err) == ST_OK;
        TAP_CHECK(ok && ev[st_grid_index(g, 4, 4, 4)] == 0 && ev[st_grid_index(g, 2, 2, 2)] == 1,
                  "an exact tie goes outside (the least inside), one more vote inside");
        free(ev);
        st_grid_free(g);
    }
}

/* Random grids of undecided voxels with weak evidence either way at
 * random and distances across the cheap band (mostly 0 to 1.5 voxels),
 * the free face 1000, 50 or 7: many short augmenting paths whose orphans move down
 * a level or two (in the tree's level being grown, some while waiting to
 * be scanned), each grid against the reference. */
static void test_levels(void)
{
    static const double free_area[] = {1000.0, 50.0, 7.0};
    unsigned seed = 4242u;
    size_t differ = 0;
    for (int trial = 0; trial < 64; trial++) {
        st_grid *g;
        st_error err;
        const double org[3] = {0, 0, 0};
        const size_t nx = 4 + rnd(&seed) % 6, ny = 4 + rnd(&seed) % 6, nz = 4 + rnd(&seed) % 6;
        if (st_grid_new(&g, nx, ny, nz, org, 1.0, 0.0f, 0, &err)) {
            differ++;
            continue;
        }
        const size_t n = st_grid_count(g);
        int8_t *ev = malloc(n);
        const double scale = rnd(&seed) % 2 ? 1.5 : 0.2;
        for (size_t v = 0; v < n; v++) {
            g->data[v] = (float)(scale * (rnd(&seed) % 1000) / 1000.0);
            ev[v] = (int8_t)((int)(rnd(&seed) % 25) - 12);
        }
        st_mincut_params p = st_mincut_params_default();
        p.free_area = free_area[rnd(&seed) % 3];
        differ += differ_from_reference(g, ev, &p);
        free(ev);
        st_grid_free(g);
    }
    TAP_CHECK(differ == 0, "levels: the cut's labels are the reference's (%zu voxels differ in 64 grids)",
              differ);
}

/* Larger random grids (about 60 K voxels, too big for the reference's
 * pace): the labels and the cut's cost are the same on 1 and 3 threads. */
static void test_threads(void)
{
    unsigned seed = 4711u;
    size_t differ = 0, flows_differ = 0;
    for (int trial = 0; trial < 3; trial++) {
        st_grid *g;
        st_error err;
        const double org[3] = {0, 0, 0};
        if (st_grid_new(&g, 41 + (size_t)trial, 38, 37, org, 1.0, 0.0f, 0, &err)) {
            differ++;
            continue;
        }
        const size_t n = st_grid_count(g);
        int8_t *ev = malloc(n), *l1 = malloc(n), *l3 = malloc(n);
        fill_case(g, ev, trial == 1 ? 0 : 5, &seed);
        st_mincut_params p = st_mincut_params_default();
        double f1 = -1, f3 = -2;
        memcpy(l1, ev, n);
        memcpy(l3, ev, n);
        omp_set_num_threads(1);
        int ok = st_mincut_label(g, l1, &p, &f1, &err) == ST_OK;
        omp_set_num_threads(3);
        ok &= st_mincut_label(g, l3, &p, &f3, &err) == ST_OK;
        differ += ok ? 0 : 1;
        for (size_t v = 0; v < n; v++)
            differ += l1[v] != l3[v];
        flows_differ += f1 != f3;
        free(ev); free(l1); free(l3);
        st_grid_free(g);
    }
    TAP_CHECK(differ == 0 && flows_differ == 0,
              "1 and 3 threads: the same labels (%zu differ) and cut cost (%zu differ)", differ,
              flows_differ);
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
                                     TAP_TEST(reference), TAP_TEST(adversarial), TAP_TEST(levels),
                                     TAP_TEST(threads), {0}};
    return tap_main(argc, argv, tests);
}
