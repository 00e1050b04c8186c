/* test_sign.c - volume-event voting on hand-made rays and small shapes. */
#include "souptet/bvh.h"
#include "souptet/dist.h"
#include "souptet/sign.h"
#include "souptet/solid.h"
#include "souptet/soup.h"
#include "shapes.h"
#include "tap.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#ifdef _OPENMP
#include <omp.h>
#endif

#define N(a) (sizeof(a) / sizeof((a)[0]))

static int votes_are(const unsigned char *got, const unsigned char *want, size_t n)
{
    return memcmp(got, want, n) == 0;
}

static void print_votes(const unsigned char *v, size_t n)
{
    printf("#   votes:");
    for (size_t i = 0; i < n; i++)
        printf(" %u", v[i]);
    printf("\n");
}

static void test_rays(void)
{
    st_sign_params p = st_sign_params_paper();
    unsigned char v[32];

    /* Two thin surfaces: inside between them, both ways. */
    const float a[] = {3, 3, 2, 1, 0, 1, 2, 3, 3, 2, 1, 0, 1, 2, 3};
    /* The surface voxels themselves get one vote each: the forward ray
     * toggles on entering them, the backward ray only after leaving. */
    const unsigned char wa[] = {0, 0, 0, 0, 1, 2, 2, 2, 2, 2, 2, 1, 0, 0, 0};
    memset(v, 0, sizeof v);
    unsigned e = st_sign_line(a, N(a), 0.5f, &p, v, NULL);
    TAP_CHECK(e == 2 && votes_are(v, wa, N(a)), "two crossings: inside between, 2 votes each (26 rays)");
    if (!votes_are(v, wa, N(a)))
        print_votes(v, N(a));

    /* A run of three voxels below t is one event; the paper's toggle lands
     * on its first voxel going forward and its last going backward. */
    const float b[] = {3, 2, 0.2f, 0.1f, 0.3f, 2, 3, 2, 0.2f, 2, 3};
    const unsigned char wb_first[] = {0, 0, 1, 1, 1, 2, 2, 2, 1, 0, 0};
    const unsigned char wb_near[] = {0, 0, 0, 1, 2, 2, 2, 2, 1, 0, 0};
    memset(v, 0, sizeof v);
    e = st_sign_line(b, N(b), 0.5f, &p, v, NULL);
    TAP_CHECK(e == 2 && votes_are(v, wb_first, N(b)), "event runs: toggle on the run's first voxel each way");
    if (!votes_are(v, wb_first, N(b)))
        print_votes(v, N(b));
    st_sign_params q = p;
    q.toggle = ST_TOGGLE_NEAREST;
    memset(v, 0, sizeof v);
    st_sign_line(b, N(b), 0.5f, &q, v, NULL);
    TAP_CHECK(votes_are(v, wb_near, N(b)), "event runs: toggle on the voxel nearest the surface");
    if (!votes_are(v, wb_near, N(b)))
        print_votes(v, N(b));

    /* The crossing toggle: the surface lies between the nearest sample and
     * its nearer neighbour, and both rays of a line agree on which side of
     * it every voxel is. Here the first crossing is before voxel 3 (its
     * previous sample is nearer than its next), and voxel 8 is a voxel
     * center on the surface (a tie: counted past the crossing both ways). */
    const unsigned char wb_cross[] = {0, 0, 0, 2, 2, 2, 2, 2, 0, 0, 0};
    q.toggle = ST_TOGGLE_CROSSING;
    memset(v, 0, sizeof v);
    e = st_sign_line(b, N(b), 0.5f, &q, v, NULL);
    TAP_CHECK(e == 2 && votes_are(v, wb_cross, N(b)),
              "crossing toggle: before the nearest voxel when its previous sample is nearer");
    if (!votes_are(v, wb_cross, N(b)))
        print_votes(v, N(b));
    /* Two V-shaped dips whose crossings (about 2.3 and 6.4) both lie after
     * the nearest sample: inside is 3..6, from both directions. */
    const float x[] = {3, 1.3f, 0.3f, 0.7f, 1.7f, 1.4f, 0.4f, 0.6f, 1.6f, 3};
    const unsigned char wx_cross[] = {0, 0, 0, 2, 2, 2, 2, 0, 0, 0};
    memset(v, 0, sizeof v);
    e = st_sign_line(x, N(x), 0.5f, &q, v, NULL);
    TAP_CHECK(e == 2 && votes_are(v, wx_cross, N(x)),
              "crossing toggle: after the nearest voxel when its next sample is nearer");
    if (!votes_are(v, wx_cross, N(x)))
        print_votes(v, N(x));
    /* The nearest sample at either end of a line: the side comes from its
     * only neighbour and no mark falls off the line. A line with one event
     * is odd: forward inside after the crossing, backward before it. */
    const float y[] = {3, 2, 1, 0.2f}, yr[] = {0.2f, 1, 2, 3};
    const unsigned char wy_cross[] = {1, 1, 1, 1};
    memset(v, 0, sizeof v);
    e = st_sign_line(y, N(y), 0.5f, &q, v, NULL);
    unsigned e2 = st_sign_line(yr, N(yr), 0.5f, &q, v + 8, NULL);
    TAP_CHECK(e == 1 && e2 == 1 && votes_are(v, wy_cross, N(y)) && votes_are(v + 8, wy_cross, N(yr)),
              "crossing toggle at either end of a line: an odd line, marks on the line");
    if (!votes_are(v, wy_cross, N(y)) || !votes_are(v + 8, wy_cross, N(yr))) {
        print_votes(v, N(y));
        print_votes(v + 8, N(yr));
    }

    /* A new event only after P fell below k again: a dip that stays below
     * t is one event, not two. */
    const float c[] = {3, 0.1f, 0.4f, 0.1f, 3, 3};
    memset(v, 0, sizeof v);
    TAP_CHECK(st_sign_line(c, N(c), 0.5f, &p, v, NULL) == 1, "no second event without leaving the band");
    /* ... unless the run holds two crossings (split runs, the default):
     * the distance dips twice, rising by more than a fifth of t between
     * (two surfaces closer than t: a thin wall). Each dip is a crossing:
     * only voxel 2, between them, is inside, from both directions. */
    st_sign_params dflt = st_sign_params_default();
    const unsigned char wc_split[] = {0, 0, 2, 0, 0, 0};
    memset(v, 0, sizeof v);
    e = st_sign_line(c, N(c), 0.5f, &dflt, v, NULL);
    TAP_CHECK(e == 2 && votes_are(v, wc_split, N(c)), "split runs: two dips in one run are two crossings");
    if (!votes_are(v, wc_split, N(c)))
        print_votes(v, N(c));
    dflt.split_runs = 0;
    memset(v, 0, sizeof v);
    TAP_CHECK(st_sign_line(c, N(c), 0.5f, &dflt, v, NULL) == 1, "whole runs: the same run is one event");
    /* A rise of less than a fifth of t is not a second crossing. */
    const float c2[] = {3, 0.1f, 0.19f, 0.1f, 3, 3};
    dflt.split_runs = 1;
    memset(v, 0, sizeof v);
    TAP_CHECK(st_sign_line(c2, N(c2), 0.5f, &dflt, v, NULL) == 1, "split runs: a small rise is one event");

    /* An odd line (a ray through a hole): kept by the paper, dropped on
     * request, both directions. */
    const float o[] = {3, 2, 0, 2, 3};
    unsigned char valid[32] = {0};
    memset(v, 0, sizeof v);
    st_sign_line(o, N(o), 0.5f, &p, v, NULL);
    const unsigned char wo[] = {1, 1, 2, 1, 1};
    TAP_CHECK(votes_are(v, wo, N(o)), "odd line kept: forward inside after, backward inside before");
    if (!votes_are(v, wo, N(o)))
        print_votes(v, N(o));
    q = p;
    q.ignore_odd = 1;
    memset(v, 0, sizeof v);
    st_sign_line(o, N(o), 0.5f, &q, v, valid);
    TAP_CHECK(v[0] + v[1] + v[2] + v[3] + v[4] == 0 && valid[2] == 0,
              "odd line ignored: no votes, and it does not count as a ray");
    memset(v, 0, sizeof v);
    memset(valid, 0, sizeof valid);
    st_sign_line(a, N(a), 0.5f, &q, v, valid);
    TAP_CHECK(valid[0] == 2 && votes_are(v, wa, N(a)), "even lines count when odd ones are ignored");

    /* 13 rays: forward only. */
    q = p;
    q.rays = 13;
    memset(v, 0, sizeof v);
    st_sign_line(o, N(o), 0.5f, &q, v, NULL);
    const unsigned char wo13[] = {0, 0, 1, 1, 1};
    TAP_CHECK(votes_are(v, wo13, N(o)), "13 rays: one vote per line, forward");

    /* The event distance. */
    st_grid *g;
    st_error err;
    const double org[3] = {0, 0, 0};
    st_grid_new(&g, 4, 4, 4, org, 0.5, 2.0f, 0, &err);
    g->data[5] = 10.0f;
    p = st_sign_params_paper();
    TAP_NEAR(st_sign_event_distance(&p, g), 0.2 * 10.0, 1e-6, "paper: t = (1 - k) max|d|");
    p.band_voxels = 3;
    TAP_NEAR(st_sign_event_distance(&p, g), 0.2 * 3 * 0.5, 1e-12, "band variant: t = (1 - k) D voxels");
    st_sign_params_named(&p, "parity");
    TAP_NEAR(st_sign_event_distance(&p, g), 0.25, 1e-6, "k = 1: half a voxel (a crossing between samples)");
    TAP_CHECK(st_sign_event_distance(&p, g) > 0.25,
              "k = 1: a sample exactly half a voxel from the surface is an event");
    st_grid_free(g);
}

static void test_refusals(void)
{
    st_grid *g;
    st_error err;
    const double org[3] = {0, 0, 0};
    st_sign_params p = st_sign_params_default();
    st_grid_new(&g, 4, 4, 4, org, 1.0, 1.0f, 0, &err);
    g->kind = ST_GRID_SIGNED;
    TAP_CHECK(st_sign_field(g, &p, NULL, &err) == ST_EINPUT, "a signed field is refused: %s", err.msg);
    g->kind = ST_GRID_DISTANCE;
    TAP_CHECK(st_sign_field(g, &p, NULL, &err) == ST_EINPUT, "a constant field is refused: %s", err.msg);
    g->data[3] = -1.0f;
    TAP_CHECK(st_sign_field(g, &p, NULL, &err) == ST_EINPUT, "negative values are refused: %s", err.msg);
    g->data[3] = NAN;
    TAP_CHECK(st_sign_field(g, &p, NULL, &err) == ST_EINPUT, "NaN is refused: %s", err.msg);
    st_grid_free(g);
}

/* --- small shapes ------------------------------------------------------ */

typedef int (*inside_fn)(const double p[3]);

/* IoU of the pseudo volume with an analytic solid. */
static double iou_of(const st_grid *g, inside_fn inside)
{
    size_t both = 0, either = 0;
    for (size_t k = 0; k < g->nz; k++)
        for (size_t j = 0; j < g->ny; j++)
            for (size_t i = 0; i < g->nx; i++) {
                double p[3];
                st_grid_center(g, i, j, k, p);
                int a = g->data[st_grid_index(g, i, j, k)] < 0, b = inside(p);
                both += a && b;
                either += a || b;
            }
    return either ? (double)both / (double)either : 1.0;
}

static int in_ball(const double p[3]) { return p[0] * p[0] + p[1] * p[1] + p[2] * p[2] < 1.0; }
static int in_cross(const double p[3])
{
    int a = fabs(p[0]) < 1.0 && fabs(p[1]) < 0.3 && fabs(p[2]) < 0.3;
    int b = fabs(p[0]) < 0.3 && fabs(p[1]) < 1.0 && fabs(p[2]) < 0.3;
    return a || b;
}
static int in_cube(const double p[3]) { return fabs(p[0]) < 1 && fabs(p[1]) < 1 && fabs(p[2]) < 1; }

static st_grid *signed_field(const st_soup *s, size_t cells, const st_sign_params *sp)
{
    st_dist_params dp = st_dist_params_default();
    dp.cells = cells;
    st_grid *g;
    st_error err;
    if (st_dist_field(&g, s, &dp, NULL, &err) || st_sign_field(g, sp, NULL, &err)) {
        TAP_NOTE("field failed: %s", err.msg);
        return NULL;
    }
    return g;
}

static void test_shapes(void)
{
    st_sign_params paper = st_sign_params_paper();
    st_sign_params def = st_sign_params_default();
    st_sign_params parity;
    st_sign_params_named(&parity, "parity");
    const st_sign_params *rules[3] = {&paper, &def, &parity};
    const char *names[3] = {"paper", "default", "parity (k = 1)"};

    st_soup *sphere = st_soup_new();
    add_sphere(sphere, 1.0, 0.85);   /* a hole at the north pole */
    st_soup *cross = st_soup_new();
    const double alo[3] = {-1, -0.3, -0.3}, ahi[3] = {1, 0.3, 0.3};
    const double blo[3] = {-0.3, -1, -0.3}, bhi[3] = {0.3, 1, 0.3};
    add_box(cross, alo, ahi);
    add_box(cross, blo, bhi);
    st_soup *cube = st_soup_new();
    const double clo[3] = {-1, -1, -1}, chi[3] = {1, 1, 1};
    add_box(cube, clo, chi);

    /* Floors a little under what was measured (48 and 32 cells; tests/
     * test_sign --variants prints every variant): the paper's rule grows
     * shapes by about a voxel (its toggle lands on the first voxel of an
     * event run, and lines along a face form one odd run) and loses the
     * overlap of interpenetrating parts to parity, as does plain parity
     * counting (k = 1); the default rule (the toggle at the crossing, the
     * union of hidden parts, half-step events) fixes most of both:
     * measured 0.965, 0.959 and 1.000. */
    const double floor_sphere[3] = {0.92, 0.96, 0.90}, floor_cross[3] = {0.70, 0.95, 0.74},
                 floor_cube[3] = {0.82, 0.99, 0.78};
    for (int r = 0; r < 3; r++) {
        st_grid *g = signed_field(sphere, 48, rules[r]);
        double iou = g ? iou_of(g, in_ball) : 0;
        TAP_CHECK(iou > floor_sphere[r], "%s rule: a sphere with a hole is a ball (IoU %.3f > %.2f)",
                  names[r], iou, floor_sphere[r]);
        st_grid_free(g);
        g = signed_field(cross, 48, rules[r]);
        iou = g ? iou_of(g, in_cross) : 0;
        TAP_CHECK(iou > floor_cross[r], "%s rule: two crossing boxes are their union (IoU %.3f > %.2f)",
                  names[r], iou, floor_cross[r]);
        st_grid_free(g);
        g = signed_field(cube, 32, rules[r]);
        iou = g ? iou_of(g, in_cube) : 0;
        TAP_CHECK(iou > floor_cube[r], "%s rule: a cube soup with flipped triangles is a cube (IoU %.3f > %.2f)",
                  names[r], iou, floor_cube[r]);
        st_grid_free(g);
    }

    /* One open sheet encloses nothing: whatever the votes make of it stays
     * within a voxel or two of the sheet. */
    st_soup *sheet = st_soup_new();
    const double s0[3] = {-1, -1, 0}, s1[3] = {1, -1, 0}, s2[3] = {1, 1, 0}, s3[3] = {-1, 1, 0};
    add_tri(sheet, s0, s1, s2, 0);
    add_tri(sheet, s0, s2, s3, 0);
    for (int r = 0; r < 3; r++) {
        st_grid *g = signed_field(sheet, 32, rules[r]);
        size_t inside = 0, far = 0;
        for (size_t k = 0; k < g->nz; k++)
            for (size_t j = 0; j < g->ny; j++)
                for (size_t i = 0; i < g->nx; i++) {
                    double p[3];
                    st_grid_center(g, i, j, k, p);
                    if (g->data[st_grid_index(g, i, j, k)] < 0) {
                        inside++;
                        far += fabs(p[2]) > 2.0 * g->voxel;
                    }
                }
        TAP_CHECK(far == 0, "%s rule: an open sheet's pseudo volume hugs the sheet (%zu inside, %zu farther than 2 voxels)",
                  names[r], inside, far);
        st_grid_free(g);
    }

#ifdef _OPENMP
    omp_set_num_threads(1);
    st_grid *g1 = signed_field(cross, 40, &paper);
    omp_set_num_threads(3);
    st_grid *g2 = signed_field(cross, 40, &paper);
    TAP_CHECK(g1 && g2 && memcmp(g1->data, g2->data, st_grid_count(g1) * sizeof(float)) == 0,
              "1 and 3 threads give identical signs");
    st_grid_free(g1);
    st_grid_free(g2);
#endif
    st_soup_free(sphere);
    st_soup_free(cross);
    st_soup_free(cube);
    st_soup_free(sheet);
}


/* --- the field sweep against the rule on single lines -------------------- */

/* The 13 line directions as sign.c walks them (each moving forward in
 * memory: the forward ray of a line is the one along these). */
static const int LINE_DIRS[13][3] = {
    {1, 0, 0}, {0, 1, 0}, {1, 1, 0}, {-1, 1, 0},
    {0, 0, 1}, {1, 0, 1}, {-1, 0, 1}, {0, 1, 1}, {0, -1, 1},
    {1, 1, 1}, {-1, 1, 1}, {1, -1, 1}, {-1, -1, 1}};

/* The signs st_sign_field must give, from st_sign_line on every line of
 * every direction (the per-line rule, walked the plain way), plus the
 * union rule read off its definition for the first-voxel toggle (a ray
 * meets an event before it reaches the voxel: forward, an event at or
 * before it; backward, one at or after it). inside[] gets 0/1. */
static int reference_signs(uint8_t *inside, const st_grid *g, const st_sign_params *p)
{
    const size_t n = st_grid_count(g);
    const long nx = (long)g->nx, ny = (long)g->ny, nz = (long)g->nz;
    unsigned *votes = calloc(n, sizeof *votes), *valid = calloc(n, sizeof *valid);
    unsigned *hidden = calloc(n, sizeof *hidden);
    float *line = malloc((size_t)(nx + ny + nz) * sizeof *line);
    size_t *at = malloc((size_t)(nx + ny + nz) * sizeof *at);
    unsigned char *lv = malloc((size_t)(nx + ny + nz)), *lc = malloc((size_t)(nx + ny + nz));
    if (!votes || !valid || !hidden || !line || !at || !lv || !lc)
        return -1;
    const float t_axis = (float)st_sign_event_distance(p, g);
    for (int d = 0; d < 13; d++) {
        const int *dv = LINE_DIRS[d];
        const int steps = abs(dv[0]) + abs(dv[1]) + abs(dv[2]);
        const float t = p->k >= 1.0 ? t_axis * (float)sqrt((double)steps) : t_axis;
        for (long k = 0; k < nz; k++)
            for (long j = 0; j < ny; j++)
                for (long i = 0; i < nx; i++) {
                    long pi = i - dv[0], pj = j - dv[1], pk = k - dv[2];
                    if (pi >= 0 && pi < nx && pj >= 0 && pj < ny && pk >= 0 && pk < nz)
                        continue;   /* not where a line starts */
                    size_t m = 0;
                    for (long a = i, b = j, c = k; a >= 0 && a < nx && b >= 0 && b < ny && c >= 0 && c < nz;
                         a += dv[0], b += dv[1], c += dv[2]) {
                        at[m] = st_grid_index(g, (size_t)a, (size_t)b, (size_t)c);
                        line[m] = g->data[at[m]];
                        m++;
                    }
                    memset(lv, 0, m);
                    memset(lc, 0, m);
                    st_sign_line(line, m, t, p, lv, lc);
                    size_t first = m, last = m;
                    for (size_t q = 0; q < m; q++)
                        if (line[q] < t) {
                            if (first == m)
                                first = q;
                            last = q;
                        }
                    for (size_t q = 0; q < m; q++) {
                        votes[at[q]] += lv[q];
                        valid[at[q]] += lc[q];
                        if (first < m && q >= first && (p->rays == 13 || q <= last))
                            hidden[at[q]]++;
                    }
                }
    }
    const unsigned per_line = p->rays == 26 ? 2 : 1;
    for (size_t v = 0; v < n; v++) {
        unsigned total = p->ignore_odd ? valid[v] : 13 * per_line;
        inside[v] = 2 * votes[v] > total || (p->nested_union && hidden[v] == 13);
    }
    free(votes);
    free(valid);
    free(hidden);
    free(line);
    free(at);
    free(lv);
    free(lc);
    return 0;
}

static void test_sweep_matches_lines(void)
{
    /* Odd sizes (rows shorter than, equal to, and a few voxels past a
     * multiple of the sweep's 32-voxel chunks) and a noisy field with many
     * events, runs and ties near the borders. */
    const size_t dims[4][3] = {{37, 45, 29}, {5, 70, 9}, {64, 3, 33}, {33, 17, 6}};
    st_sign_params rules[7];
    const char *names[7] = {"paper", "parity", "default, nested parity", "crossing, 13 rays, odd ignored",
                            "nearest, k 0.6 band 2, odd ignored", "first + union", "first + union, 13 rays"};
    rules[0] = st_sign_params_paper();
    st_sign_params_named(&rules[1], "parity");
    rules[2] = st_sign_params_default();
    rules[2].nested_union = 0;
    rules[2].cut = 0;   /* the per-line rule: the cut is a step after it */
    rules[3] = rules[2];
    rules[3].rays = 13;
    rules[3].ignore_odd = 1;
    rules[4] = st_sign_params_paper();
    rules[4].toggle = ST_TOGGLE_NEAREST;
    rules[4].k = 0.6;
    rules[4].band_voxels = 2;
    rules[4].ignore_odd = 1;
    rules[5] = st_sign_params_paper();
    rules[5].nested_union = 1;
    rules[6] = rules[5];
    rules[6].rays = 13;
    unsigned seed = 12345u;
    for (int r = 0; r < 7; r++) {
        size_t wrong = 0, inside = 0, total = 0;
        int failed = 0;
        for (int s = 0; s < 4; s++) {
            st_grid *g;
            st_error err;
            const double org[3] = {0, 0, 0};
            if (st_grid_new(&g, dims[s][0], dims[s][1], dims[s][2], org, 1.0, 0.0f, 0, &err)) {
                failed = 1;
                continue;
            }
            g->kind = ST_GRID_DISTANCE;
            const size_t n = st_grid_count(g);
            for (size_t v = 0; v < n; v++) {
                seed = seed * 1664525u + 1013904223u;
                /* mostly far, a fifth near: events of every length; a few
                 * exact repeats make ties */
                unsigned x = seed >> 8;
                g->data[v] = (x % 5 == 0) ? (float)(x % 97) / 100.0f : 1.0f + (float)(x % 300) / 100.0f;
            }
            uint8_t *want = malloc(n);
            if (!want || reference_signs(want, g, &rules[r]) ||
                st_sign_field(g, &rules[r], NULL, &err)) {
                failed = 1;
                free(want);
                st_grid_free(g);
                continue;
            }
            for (size_t v = 0; v < n; v++) {
                wrong += (signbit(g->data[v]) != 0) != want[v];   /* -0 is inside */
                inside += want[v];
            }
            total += n;
            free(want);
            st_grid_free(g);
        }
        TAP_CHECK(!failed && wrong == 0 && inside > 0 && inside < total,
                  "%s: the field sweep gives the per-line rule's signs (%zu of %zu voxels differ, %zu inside)",
                  names[r], wrong, total, inside);
    }
#ifdef _OPENMP
    /* The default rule on the noisy field: the same bytes for 1, 2 and 3
     * threads (blocks of lines are handed out dynamically). */
    st_grid *g[3] = {NULL, NULL, NULL};
    int same = 1;
    for (int th = 0; th < 3; th++) {
        st_error err;
        const double org[3] = {0, 0, 0};
        if (st_grid_new(&g[th], 37, 45, 29, org, 1.0, 0.0f, 0, &err)) {
            same = 0;
            continue;
        }
        g[th]->kind = ST_GRID_DISTANCE;
        unsigned sd = 777u;
        for (size_t v = 0; v < st_grid_count(g[th]); v++) {
            sd = sd * 1664525u + 1013904223u;
            g[th]->data[v] = (float)((sd >> 8) % 300) / 100.0f;
        }
        omp_set_num_threads(th + 1);
        st_sign_params p = st_sign_params_default();
        if (st_sign_field(g[th], &p, NULL, &err))
            same = 0;
    }
    for (int th = 1; th < 3 && same; th++)
        same = memcmp(g[0]->data, g[th]->data, st_grid_count(g[0]) * sizeof(float)) == 0;
    TAP_CHECK(same, "default rule on a noisy field: 1, 2 and 3 threads give identical signs");
    for (int th = 0; th < 3; th++)
        st_grid_free(g[th]);
#endif
}


/* --- the near-surface refinement -------------------------------------- */

/* IoU of g's inside with the exact solid of the closed soup s (parity: the
 * soups here have flipped triangles), at g's voxel centers. */
static double iou_exact(const st_grid *g, const st_soup *s)
{
    uint8_t *truth = malloc(st_grid_count(g));
    st_error err;
    double iou = -1, prec, rec;
    const st_soup *shells[1] = {s};
    if (truth && !st_solid_inside(truth, g, shells, 1, ST_SOLID_PARITY, &err))
        st_solid_iou(&iou, &prec, &rec, truth, g, &err);
    free(truth);
    return iou;
}

static st_grid *refined_field(const st_soup *s, size_t cells, double voxel, size_t *changed)
{
    st_dist_params dp = st_dist_params_default();
    dp.cells = cells;
    dp.voxel = voxel;
    st_sign_params sp = st_sign_params_default();
    st_sign_refine_params rp = st_sign_refine_params_default();
    st_grid *g;
    st_error err;
    if (st_dist_field(&g, s, &dp, NULL, &err) || st_sign_field(g, &sp, NULL, &err) ||
        st_sign_refine(g, s, &rp, changed, &err)) {
        TAP_NOTE("refined field failed: %s", err.msg);
        return NULL;
    }
    return g;
}

static st_grid *voted_field(const st_soup *s, size_t cells, double voxel)
{
    st_dist_params dp = st_dist_params_default();
    dp.cells = cells;
    dp.voxel = voxel;
    st_sign_params sp = st_sign_params_default();
    st_grid *g;
    st_error err;
    if (st_dist_field(&g, s, &dp, NULL, &err) || st_sign_field(g, &sp, NULL, &err)) {
        TAP_NOTE("field failed: %s", err.msg);
        return NULL;
    }
    return g;
}

static const double PLATE_VOXEL = 1.0 / 16.0;
static int in_plate(const double p[3])
{
    /* A plate 0.8 voxel thick: one layer of voxel centers in it (the grid
     * is centered on the soup's box and has an odd count along z). */
    return fabs(p[0]) < 1 && fabs(p[1]) < 1 && fabs(p[2]) < 0.4 * PLATE_VOXEL;
}

static void test_refine(void)
{
    /* A closed UV sphere, every other triangle flipped (shapes.h), at 20
     * cells: the vote misses some voxel centers within a voxel of the
     * faces; the refinement gets every one (the exact solid of the soup),
     * and the analytic ball no worse than the vote. */
    st_soup *sphere = st_soup_new();
    add_sphere(sphere, 1.0, 2.0);
    st_grid *v = voted_field(sphere, 20, 0);
    size_t changed = 0;
    st_grid *r = refined_field(sphere, 20, 0, &changed);
    double iv = v ? iou_exact(v, sphere) : 0, ir = r ? iou_exact(r, sphere) : 0;
    TAP_CHECK(v && r && iv < 1.0 && ir == 1.0 && changed > 0,
              "sphere: the vote misses near-surface voxels (IoU %.4f), the refinement "
              "none (IoU %.4f, %zu signs changed)", iv, ir, changed);
    double av = v ? iou_of(v, in_ball) : 0, ar = r ? iou_of(r, in_ball) : 0;
    TAP_CHECK(ar >= av, "sphere: against the analytic ball, refined %.4f >= voted %.4f", ar, av);

    /* The same sphere with every other triangle's orientation turned
     * again: orientation is never read, so the same signs. */
    st_soup *flipped = st_soup_new();
    for (size_t t = 0; t < sphere->ntris; t++) {
        const uint32_t *tri = sphere->tris + 3 * t;
        add_tri(flipped, sphere->xyz + 3 * (size_t)tri[0], sphere->xyz + 3 * (size_t)tri[1],
                sphere->xyz + 3 * (size_t)tri[2], (int)(t & 1));
    }
    st_grid *rf = refined_field(flipped, 20, 0, NULL);
    TAP_CHECK(r && rf && memcmp(r->data, rf->data, st_grid_count(r) * sizeof(float)) == 0,
              "a soup with every other triangle flipped: the same refined signs");

    /* A plate thinner than a voxel: its layer of voxel centers is between
     * two samples of every line across it, so the vote calls it outside;
     * the refinement finds it from voxels two layers away. */
    st_soup *plate = st_soup_new();
    const double plo[3] = {-1, -1, -0.4 * PLATE_VOXEL}, phi[3] = {1, 1, 0.4 * PLATE_VOXEL};
    add_box(plate, plo, phi);
    st_grid *pv = voted_field(plate, 0, PLATE_VOXEL);
    st_grid *pr = refined_field(plate, 0, PLATE_VOXEL, NULL);
    double pav = pv ? iou_of(pv, in_plate) : 0, par = pr ? iou_of(pr, in_plate) : 0;
    size_t inside = 0;
    if (pr)
        for (size_t k = 0; k < pr->nz; k++)
            for (size_t j = 0; j < pr->ny; j++)
                for (size_t i = 0; i < pr->nx; i++) {
                    double q[3];
                    st_grid_center(pr, i, j, k, q);
                    inside += in_plate(q);
                }
    TAP_CHECK(inside > 0 && pav < 0.5 && par == 1.0,
              "thin plate (0.8 voxel, %zu voxel centers in it): voted IoU %.4f, refined %.4f",
              inside, pav, par);

    /* Faces exactly halfway between voxel centers and edges on their
     * lines: many segments pass through an edge (not used), others decide. */
    st_soup *cube = st_soup_new();
    const double clo[3] = {-1, -1, -1}, chi[3] = {1, 1, 1};
    add_box(cube, clo, chi);
    st_grid *cr = refined_field(cube, 16, 0, NULL);
    double ic = cr ? iou_of(cr, in_cube) : 0;
    TAP_CHECK(ic == 1.0, "cube with faces halfway between centers: refined IoU %.4f", ic);

    /* Refusals. */
    st_error err;
    st_sign_refine_params rp = st_sign_refine_params_default();
    st_dist_params dp = st_dist_params_default();
    dp.cells = 8;
    st_grid *u = NULL;
    st_dist_field(&u, cube, &dp, NULL, &err);
    TAP_CHECK(u && st_sign_refine(u, cube, &rp, NULL, &err) == ST_EINPUT,
              "an unsigned field is refused: %s", err.msg);
    st_grid_free(u);
    rp.radius = 0;
    TAP_CHECK(r && st_sign_refine(r, sphere, &rp, NULL, &err) == ST_EINPUT,
              "a radius of 0 is refused: %s", err.msg);

#ifdef _OPENMP
    omp_set_num_threads(1);
    st_grid *g1 = refined_field(plate, 0, PLATE_VOXEL * 0.9, NULL);
    st_grid *s1 = refined_field(sphere, 24, 0, NULL);
    omp_set_num_threads(2);
    st_grid *g2 = refined_field(plate, 0, PLATE_VOXEL * 0.9, NULL);
    st_grid *s2 = refined_field(sphere, 24, 0, NULL);
    TAP_CHECK(g1 && g2 && s1 && s2 &&
              memcmp(g1->data, g2->data, st_grid_count(g1) * sizeof(float)) == 0 &&
              memcmp(s1->data, s2->data, st_grid_count(s1) * sizeof(float)) == 0,
              "refinement: 1 and 2 threads give identical signs");
    st_grid_free(g1);
    st_grid_free(g2);
    st_grid_free(s1);
    st_grid_free(s2);
#endif
    st_grid_free(v);
    st_grid_free(r);
    st_grid_free(rf);
    st_grid_free(pv);
    st_grid_free(pr);
    st_grid_free(cr);
    st_soup_free(sphere);
    st_soup_free(flipped);
    st_soup_free(plate);
    st_soup_free(cube);
}

/* The refinement with the soup in two parts, a BVH each (the pipeline's
 * soup and its hole caps), gives the signs of one BVH over the whole. */
static void test_refine_parts(void)
{
    st_soup *sphere = st_soup_new();
    add_sphere(sphere, 1.0, 2.0);
    st_soup *a = st_soup_new(), *b = st_soup_new(), *all = st_soup_new();
    for (size_t t = 0; t < sphere->ntris; t++) {
        const uint32_t *tri = sphere->tris + 3 * t;
        add_tri(t % 3 ? a : b, sphere->xyz + 3 * (size_t)tri[0],
                sphere->xyz + 3 * (size_t)tri[1], sphere->xyz + 3 * (size_t)tri[2], 0);
    }
    st_error err;
    st_bvh *ba = NULL, *bb = NULL;
    const int ok = st_soup_append(all, a, &err) == ST_OK && st_soup_append(all, b, &err) == ST_OK &&
                   st_bvh_build(&ba, a, &err) == ST_OK && st_bvh_build(&bb, b, &err) == ST_OK;
    st_grid *one = voted_field(all, 20, 0), *two = voted_field(all, 20, 0);
    const st_sign_refine_params rp = st_sign_refine_params_default();
    const st_bvh *parts[2] = {ba, bb};
    size_t c1 = 0, c2 = 0;
    const st_status r1 = ok && one ? st_sign_refine(one, all, &rp, &c1, &err) : ST_EINTERNAL;
    const st_status r2 = ok && two ? st_sign_refine_parts(two, all, parts, 2, &rp, &c2, &err)
                                   : ST_EINTERNAL;
    TAP_CHECK(r1 == ST_OK && r2 == ST_OK && c1 > 0 && c1 == c2 &&
                  memcmp(one->data, two->data, st_grid_count(one) * sizeof(float)) == 0,
              "sphere in two parts (%zu + %zu triangles): the same signs as one BVH "
              "(%zu and %zu changed)", a->ntris, b->ntris, c1, c2);
    /* one part alone does not hold the soup's triangles */
    TAP_CHECK(two && st_sign_refine_parts(two, all, parts, 1, &rp, NULL, &err) == ST_EINPUT,
              "parts that do not add up to the soup are refused: %s", err.msg);
    st_grid_free(one);
    st_grid_free(two);
    st_bvh_free(ba);
    st_bvh_free(bb);
    st_soup_free(a);
    st_soup_free(b);
    st_soup_free(all);
    st_soup_free(sphere);
}

/* Not a check: the IoU of each variant on the shapes, printed as notes so
 * the default rule's choice can be read off the test log. */
static void report_variants(void)
{
    st_soup *cube = st_soup_new();
    const double clo[3] = {-1, -1, -1}, chi[3] = {1, 1, 1};
    add_box(cube, clo, chi);
    st_soup *sphere = st_soup_new();
    add_sphere(sphere, 1.0, 0.85);
    st_soup *cross = st_soup_new();
    const double alo[3] = {-1, -0.3, -0.3}, ahi[3] = {1, 0.3, 0.3};
    const double blo[3] = {-0.3, -1, -0.3}, bhi[3] = {0.3, 1, 0.3};
    add_box(cross, alo, ahi);
    add_box(cross, blo, bhi);
    for (int nested = 0; nested < 2; nested++)
    for (int toggle = 0; toggle < 3; toggle++)
        for (int odd = 0; odd < 2; odd++)
            for (int band = 0; band < 2; band++) {
                st_sign_params p = st_sign_params_paper();
                p.toggle = toggle == 2 ? ST_TOGGLE_CROSSING
                           : toggle ? ST_TOGGLE_NEAREST : ST_TOGGLE_FIRST;
                p.ignore_odd = odd;
                p.nested_union = nested;
                p.band_voxels = band == 0 ? 0 : 5;
                st_grid *a = signed_field(cube, 32, &p), *b = signed_field(sphere, 48, &p),
                        *c = signed_field(cross, 48, &p);
                TAP_NOTE("%-6s toggle %-8s odd %-6s c %-8s: cube %.3f  holed sphere %.3f  cross %.3f",
                         nested ? "union" : "parity",
                         toggle == 2 ? "crossing" : toggle ? "nearest" : "first",
                         odd ? "ignore" : "keep",
                         band == 0 ? "1/max|d|" : (band == 1 ? "band 5" : "band 8"),
                         iou_of(a, in_cube), iou_of(b, in_ball), iou_of(c, in_cross));
                st_grid_free(a);
                st_grid_free(b);
                st_grid_free(c);
            }
    st_soup_free(cube);
    st_soup_free(sphere);
    st_soup_free(cross);
}

/* Voxel centers exactly on the surface (distance 0) that the vote puts
 * inside must read as inside (value < 0): -0.0 would not. The box
 * [3, 12]^3 on a grid of unit voxels centered on integers has whole
 * planes of centers on its faces. */
static void test_zero_distance(void)
{
    st_grid *g;
    st_error err;
    const double org[3] = {0, 0, 0};
    const double lo = 3, hi = 12;
    for (int variant = 0; variant < 2; variant++) {
        st_grid_new(&g, 16, 16, 16, org, 1.0, 0.0f, 0, &err);
        g->kind = ST_GRID_DISTANCE;
        for (size_t k = 0; k < 16; k++)
            for (size_t j = 0; j < 16; j++)
                for (size_t i = 0; i < 16; i++) {
                    const double c[3] = {(double)i, (double)j, (double)k};
                    double out = 0, in = 1e9;
                    for (int a = 0; a < 3; a++) {
                        const double e = c[a] < lo ? lo - c[a] : c[a] > hi ? c[a] - hi : 0;
                        out += e * e;
                        in = fmin(in, fmin(c[a] - lo, hi - c[a]));
                    }
                    g->data[st_grid_index(g, i, j, k)] = (float)(out > 0 ? sqrt(out) : in);
                }
        st_sign_params p = st_sign_params_default();
        p.cut = variant;
        int ok = !st_sign_field(g, &p, NULL, &err);
        size_t negzero = 0, zero_in = 0, zero = 0, wrong = 0;
        for (size_t k = 0; k < 16; k++)
            for (size_t j = 0; j < 16; j++)
                for (size_t i = 0; i < 16; i++) {
                    const float v = g->data[st_grid_index(g, i, j, k)];
                    const int strictly = i > lo && i < hi && j > lo && j < hi && k > lo && k < hi;
                    negzero += v == 0.0f && signbit(v);
                    zero += fabsf(v) <= FLT_MIN;
                    zero_in += v < 0.0f && fabsf(v) <= FLT_MIN;
                    wrong += strictly && !(v < 0.0f);
                }
        TAP_CHECK(ok && negzero == 0 && zero_in > 0 && wrong == 0,
                  "%s: %zu of %zu centers on the surface inside, all < 0 (%zu -0.0), the box's "
                  "inside inside (%zu wrong)", variant ? "cut" : "votes", zero_in, zero, negzero,
                  wrong);
        st_grid_free(g);
    }
}

int main(int argc, char **argv)
{
    if (argc > 1 && strcmp(argv[1], "--variants") == 0) {
        report_variants();
        return 0;
    }
    static const tap_test tests[] = {TAP_TEST(rays), TAP_TEST(refusals), TAP_TEST(shapes),
                                     TAP_TEST(sweep_matches_lines), TAP_TEST(refine),
                                     TAP_TEST(refine_parts), TAP_TEST(zero_distance), {0}};
    return tap_main(argc, argv, tests);
}
