/* test_wrap.c - soupwrap's surface: closed, manifold, outward, free of
 * degenerate and self-intersecting triangles on damaged shapes; the check
 * itself on surfaces that are wrong in known ways; the writers' round
 * trips. */
#include "souptet/dist.h"
#include "souptet/mem.h"
#include "souptet/sign.h"
#include "souptet/soup.h"
#include "souptet/soupinfo.h"
#include "souptet/soupwrite.h"
#include "souptet/wrap.h"
#include "shapes.h"
#include "tap.h"

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#ifdef _OPENMP
#include <omp.h>
#endif

/* soupdist | soupsign with their defaults at `cells`, then wrap. */
static st_soup *wrap_soup(const st_soup *s, size_t cells, st_wrap_params p,
                          st_wrap_stats *stats, double *voxel)
{
    st_error err;
    st_grid *g = NULL;
    st_soup *out = NULL;
    st_dist_params dp = st_dist_params_default();
    dp.cells = cells;
    st_sign_params sp = st_sign_params_default();
    if (st_dist_field(&g, s, &dp, NULL, &err) ||
        st_sign_field(g, &sp, NULL, &err) ||
        st_wrap_field(&out, g, &p, stats, NULL, &err)) {
        printf("#   error: %s\n", err.msg);
        st_grid_free(g);
        return NULL;
    }
    if (voxel)
        *voxel = g->voxel;
    st_grid_free(g);
    return out;
}

/* Everything soupwrap promises, with soupinfo's exact counts. */
static int valid(const st_soup *s, size_t want_pieces, const char *what)
{
    st_error err;
    st_wrap_check c;
    st_soupinfo r;
    if (!s || st_wrap_check_compute(&c, s, &err) ||
        st_soupinfo_compute(&r, s, &err) ||
        st_soupinfo_self_intersections(&r, s, NULL, &err))
        return 0;
    int ok = st_wrap_check_ok(&c) && r.closed && r.boundary_edges == 0 &&
             r.nonmanifold_edges == 0 && r.nonmanifold_vertices == 0 &&
             r.inconsistent_edges == 0 && r.degenerate_triangles == 0 &&
             r.collinear_triangles == 0 && r.self_intersecting_pairs == 0 &&
             r.pieces == want_pieces && c.volume > 0;
    if (!ok)
        printf("#   %s: closed %d manifold %d oriented %d outward %d "
               "nondeg %d distinct %d si-pairs %zu pieces %zu vol %g\n",
               what, c.closed, c.manifold, c.oriented, c.outward,
               c.nondegenerate, c.distinct, c.self_intersecting_pairs,
               r.pieces, c.volume);
    return ok;
}

static double volume_of(const st_soup *s)
{
    st_error err;
    st_wrap_check c;
    return st_wrap_check_compute(&c, s, &err) ? NAN : c.volume;
}

static void test_shapes(void)
{
    st_wrap_params p = st_wrap_params_default();
    double h;

    /* A cube soup: every triangle its own vertices, every other flipped. */
    st_soup cube = {0};
    const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
    add_box(&cube, lo, hi);
    st_soup *w = wrap_soup(&cube, 24, p, NULL, &h);
    TAP_CHECK(valid(w, 1, "cube"), "cube soup (flipped triangles): one closed manifold outward shell, no self-intersections");
    /* The surface lies where the soup is: the box's volume within a
     * layer of a voxel's fraction (the iso-surface runs through the
     * faces; corners are rounded off by at most a voxel). */
    double vol = w ? volume_of(w) : 0;
    TAP_CHECK(fabs(vol - 1.0) < 6 * h, "cube soup: encloses the unit cube's volume (%.4f, voxel %.3f)", vol, h);
    double maxd = 0;
    for (size_t v = 0; w && v < w->nverts; v++) {
        const double *x = w->xyz + 3 * v;
        /* distance to the cube's surface */
        double d = INFINITY;
        int in = 1;
        for (int a = 0; a < 3; a++)
            in &= x[a] >= 0 && x[a] <= 1;
        if (in) {
            for (int a = 0; a < 3; a++)
                d = fmin(d, fmin(x[a], 1 - x[a]));
        } else {
            double q = 0;
            for (int a = 0; a < 3; a++) {
                double e = fmax(0, fmax(-x[a], x[a] - 1));
                q += e * e;
            }
            d = sqrt(q);
        }
        maxd = fmax(maxd, d);
    }
    /* Within a voxel along the faces; the corners, where the sign voting
     * errs most, measured 1.125 voxels: the bound says 1.5. */
    TAP_CHECK(w && maxd <= 1.5 * h, "cube soup: every output vertex within 1.5 voxels of the cube (%.3f voxels)", maxd / h);
    st_soup_free(w);

    /* Adaptivity merges the flat faces into fewer triangles and stays
     * valid. */
    st_soup *w0 = wrap_soup(&cube, 24, p, NULL, NULL);
    st_wrap_params pa = p;
    pa.adaptivity = 0.5;
    st_wrap_stats sa;
    w = wrap_soup(&cube, 24, pa, &sa, NULL);
    TAP_CHECK(valid(w, 1, "cube adaptive") && w0 && w->ntris < w0->ntris,
              "cube, adaptivity 0.5: valid, fewer triangles (%zu < %zu)",
              w ? w->ntris : 0, w0 ? w0->ntris : 0);
    st_soup_free(w);
    st_soup_free(w0);
    free(cube.xyz);
    free(cube.tris);

    /* A sphere with a hole: closed anyway. */
    st_soup sph = {0};
    add_sphere(&sph, 1.0, 0.7);
    w = wrap_soup(&sph, 32, p, NULL, &h);
    TAP_CHECK(valid(w, 1, "sphere with hole"), "sphere with a hole: one closed manifold outward shell");
    vol = w ? volume_of(w) : 0;
    TAP_CHECK(vol > 0.85 * 4.0 / 3.0 * M_PI && vol < 1.1 * 4.0 / 3.0 * M_PI,
              "sphere with a hole: the hole is closed over (volume %.3f of %.3f)", vol, 4.0 / 3.0 * M_PI);
    st_soup_free(w);

    /* Smoothing keeps it valid and moves something. */
    st_wrap_params ps = p;
    ps.smooth = 2;
    st_wrap_stats ss;
    w0 = wrap_soup(&sph, 32, p, NULL, NULL);
    w = wrap_soup(&sph, 32, ps, &ss, NULL);
    int moved = w && w0 && w->nverts == w0->nverts &&
                memcmp(w->xyz, w0->xyz, 3 * w->nverts * sizeof *w->xyz) != 0;
    TAP_CHECK(valid(w, 1, "sphere smoothed") && moved && ss.smooth_steps == 2,
              "sphere, 2 Taubin steps: still valid, vertices moved (%zu moves undone)", ss.smooth_reverted);
    st_soup_free(w);
    st_soup_free(w0);

    /* The same answer on 1 and 3 threads. */
#ifdef _OPENMP
    omp_set_num_threads(1);
    w0 = wrap_soup(&sph, 32, ps, NULL, NULL);
    omp_set_num_threads(3);
    w = wrap_soup(&sph, 32, ps, NULL, NULL);
    TAP_CHECK(w && w0 && w->nverts == w0->nverts && w->ntris == w0->ntris &&
              memcmp(w->xyz, w0->xyz, 3 * w->nverts * sizeof *w->xyz) == 0 &&
              memcmp(w->tris, w0->tris, 3 * w->ntris * sizeof *w->tris) == 0,
              "same surface on 1 and 3 threads");
    st_soup_free(w);
    st_soup_free(w0);
#endif
    free(sph.xyz);
    free(sph.tris);

    /* Two interpenetrating boxes: one closed shell around their union. */
    st_soup two = {0};
    const double alo[3] = {0, 0, 0}, ahi[3] = {2, 1, 1};
    const double blo[3] = {1, 0.5, 0.25}, bhi[3] = {1.6, 1.8, 0.75};
    add_box(&two, alo, ahi);
    add_box(&two, blo, bhi);
    w = wrap_soup(&two, 32, p, NULL, &h);
    TAP_CHECK(valid(w, 1, "two boxes"), "two interpenetrating boxes: one closed shell");
    vol = w ? volume_of(w) : 0;
    double want = 2.0 + 0.6 * 0.8 * 0.5;
    TAP_CHECK(fabs(vol - want) < 12 * h, "two boxes: the union's volume (%.3f, want %.3f)", vol, want);
    st_soup_free(w);
    free(two.xyz);
    free(two.tris);
}

/* A signed field of a ball that fills the grid past its edges. */
static void test_grid_edge(void)
{
    st_error err;
    st_grid *g = NULL;
    const double o[3] = {0, 0, 0};
    if (st_grid_new(&g, 12, 12, 12, o, 1.0, 0.0f, 0, &err)) {
        TAP_CHECK(0, "grid");
        return;
    }
    g->kind = ST_GRID_SIGNED;
    g->band = INFINITY;
    for (size_t k = 0; k < 12; k++)
        for (size_t j = 0; j < 12; j++)
            for (size_t i = 0; i < 12; i++) {
                double x = (double)i - 5.5, y = (double)j - 5.5, z = (double)k - 5.5;
                g->data[st_grid_index(g, i, j, k)] = (float)(sqrt(x * x + y * y + z * z) - 7.0);
            }
    st_wrap_params p = st_wrap_params_default();
    st_wrap_stats st;
    st_soup *w = NULL;
    st_status s = st_wrap_field(&w, g, &p, &st, NULL, &err);
    TAP_CHECK(s == ST_OK && valid(w, 1, "edge"), "inside reaching the grid's edge: closed there (outside the grid is outside)");
    TAP_CHECK(st.edge_voxels_inside > 0, "inside voxels on the grid's edge are counted (%zu)", st.edge_voxels_inside);
    double maxc = 0;
    for (size_t v = 0; w && v < w->nverts; v++)
        for (int a = 0; a < 3; a++)
            maxc = fmax(maxc, fabs(w->xyz[3 * v + a] - 5.5));
    /* between the last voxel centers (5.5 from the middle) and the
     * outside layer's (6.5) */
    TAP_CHECK(w && maxc > 5.5 && maxc <= 6.5, "the cap lies between the grid's last voxels and the outside layer (%.3f)", maxc);
    st_soup_free(w);

    /* Nothing inside; an unsigned field. */
    for (size_t i = 0; i < st_grid_count(g); i++)
        g->data[i] = 1.0f;
    w = NULL;
    TAP_CHECK(st_wrap_field(&w, g, &p, NULL, NULL, &err) == ST_EINPUT && !w, "nothing inside: ST_EINPUT");
    g->kind = ST_GRID_DISTANCE;
    TAP_CHECK(st_wrap_field(&w, g, &p, NULL, NULL, &err) == ST_EINPUT && !w, "unsigned distance field: ST_EINPUT");
    st_grid_free(g);
}

/* Values at the isovalue: the signs give -FLT_MIN to an inside voxel
 * whose center lies on the soup (st_grid_signed_value), so volumeToMesh
 * put the crossings next to it on that center, and the points of the
 * cells around it on one point: quads degenerate whichever way they were
 * split. Before the values were held off the isovalue, variants 2 and 3
 * failed with "degenerate triangles"; variants 0 and 1 hold exact zeros
 * (outside) only. A stepped cylinder (a screw's thread as rings of two
 * radii, flat steps between them) and a box with a slot, their faces on
 * voxel centers. */
static void test_iso_values(void)
{
    const double o[3] = {0.25, -1.0, 3.0};
    for (int variant = 0; variant < 4; variant++) {
        st_error err;
        st_grid *g = NULL;
        if (st_grid_new(&g, 20, 20, 20, o, 0.5, 0.0f, 0, &err)) {
            TAP_CHECK(0, "grid");
            return;
        }
        g->kind = ST_GRID_SIGNED;
        g->band = INFINITY;
        size_t zeros = 0, inside = 0;
        for (int k = 0; k < 20; k++)
            for (int j = 0; j < 20; j++)
                for (int i = 0; i < 20; i++) {
                    double x = i - 9.5, y = j - 9.5, z = k - 9.5, d;
                    if (variant & 1) {
                        d = fmax(fabs(x), fmax(fabs(y), fabs(z))) - 5.5;
                        if (z > 0 && fabs(x) < 2.6)
                            d = fmax(d, 2.5 - z);
                    } else {
                        double r = sqrt(x * x + y * y);
                        double R = ((int)floor(z + 10) % 2) ? 4.0 : 5.5;
                        d = fmax(r - R, fabs(z) - 7.5);
                        if (fabs(z) - 7.5 == 0 || r - R == 0)
                            d = 0;
                    }
                    float v = (float)(d * 0.5);
                    if (v == 0.0f) {
                        zeros++;
                        if ((variant & 2) && (i + j + k) % 3 == 0)
                            v = -FLT_MIN;
                    }
                    inside += v < 0.0f;
                    g->data[st_grid_index(g, i, j, k)] = v;
                }
        st_wrap_params p = st_wrap_params_default();
        st_wrap_stats st;
        st_soup *w = NULL;
        st_status s = st_wrap_field(&w, g, &p, &st, NULL, &err);
        if (s)
            printf("#   %s\n", err.msg);
        char what[32];
        snprintf(what, sizeof what, "variant %d", variant);
        TAP_CHECK(s == ST_OK && valid(w, 1, what),
                  "%s, %zu values at the isovalue%s: a valid surface", what,
                  zeros, variant & 2 ? ", some -FLT_MIN (inside)" : "");
        /* the inside is the same voxels: the surface encloses each of
         * them (within half a voxel of the voxels' boundary) */
        double vol = w ? volume_of(w) : 0.0, h3 = 0.125;
        TAP_CHECK(st.iso_held_off >= zeros && st.iso_margin == 1.0 / 64 &&
                      vol > 0.5 * (double)inside * h3 &&
                      vol < 2.0 * (double)inside * h3,
                  "%s: %zu values held %g voxels off; volume %.4g for %zu "
                  "inside voxels of %g", what, st.iso_held_off, st.iso_margin,
                  vol, inside, h3);
        st_soup_free(w);
        st_grid_free(g);
    }
}

/* A closed box with shared vertices (8 points, 12 triangles, outward). */
static void box_indexed(st_soup *s, const double lo[3], const double hi[3], int inward)
{
    uint32_t b = (uint32_t)s->nverts;
    for (int c = 0; c < 8; c++)
        st_soup_add_vertex(s, c & 1 ? hi[0] : lo[0], c & 2 ? hi[1] : lo[1], c & 4 ? hi[2] : lo[2], NULL);
    static const uint32_t f[12][3] = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6},
                                      {0, 1, 4}, {1, 5, 4}, {2, 6, 3}, {3, 6, 7},
                                      {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
    for (int t = 0; t < 12; t++) {
        if (inward)
            st_soup_add_triangle(s, b + f[t][0], b + f[t][2], b + f[t][1], NULL);
        else
            st_soup_add_triangle(s, b + f[t][0], b + f[t][1], b + f[t][2], NULL);
    }
}

static void test_check(void)
{
    st_error err;
    st_wrap_check c;
    const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
    const double ilo[3] = {0.25, 0.25, 0.25}, ihi[3] = {0.75, 0.75, 0.75};
    const double slo[3] = {0.5, 0.5, 0.5}, shi[3] = {1.5, 1.5, 1.5};

    st_soup s = {0};
    box_indexed(&s, lo, hi, 0);
    TAP_CHECK(st_wrap_check_compute(&c, &s, &err) == ST_OK && st_wrap_check_ok(&c) && fabs(c.volume - 1) < 1e-12,
              "check: a closed outward box passes, volume 1");
    box_indexed(&s, ilo, ihi, 1);
    TAP_CHECK(st_wrap_check_compute(&c, &s, &err) == ST_OK && st_wrap_check_ok(&c) && c.pieces == 2,
              "check: a box with an inward cavity box passes (nesting by ray parity)");
    free(s.xyz);
    free(s.tris);

    memset(&s, 0, sizeof s);
    box_indexed(&s, lo, hi, 0);
    box_indexed(&s, ilo, ihi, 0);
    TAP_CHECK(st_wrap_check_compute(&c, &s, &err) == ST_OK && !c.outward && c.closed,
              "check: a cavity facing the wrong way is not outward");
    free(s.xyz);
    free(s.tris);

    memset(&s, 0, sizeof s);
    box_indexed(&s, lo, hi, 1);
    TAP_CHECK(st_wrap_check_compute(&c, &s, &err) == ST_OK && !c.outward && c.oriented,
              "check: an inward box is oriented but not outward");
    free(s.xyz);
    free(s.tris);

    memset(&s, 0, sizeof s);
    box_indexed(&s, lo, hi, 0);
    uint32_t x = s.tris[1];
    s.tris[1] = s.tris[2];
    s.tris[2] = x;
    TAP_CHECK(st_wrap_check_compute(&c, &s, &err) == ST_OK && !c.oriented && c.closed,
              "check: one flipped triangle is not oriented");
    s.ntris = 11;
    TAP_CHECK(st_wrap_check_compute(&c, &s, &err) == ST_OK && !c.closed,
              "check: a missing triangle is not closed");
    free(s.xyz);
    free(s.tris);

    memset(&s, 0, sizeof s);
    box_indexed(&s, lo, hi, 0);
    box_indexed(&s, slo, shi, 0);
    TAP_CHECK(st_wrap_check_compute(&c, &s, &err) == ST_OK && !c.self_intersection_free && c.closed &&
              c.self_intersecting_pairs > 0,
              "check: two overlapping boxes self-intersect (%zu pairs)", c.self_intersecting_pairs);
    free(s.xyz);
    free(s.tris);
}

/* Write, read back, compare (vertices and triangles as they were). */
static void test_write(void)
{
    st_soup s = {0};
    const double lo[3] = {0, 0, 0}, hi[3] = {1, 2, 3};
    box_indexed(&s, lo, hi, 0);
    s.xyz[0] = 0.1; /* not a float: OBJ/OFF/PLY keep the double */
    static const struct { st_soup_format f; const char *name; int exact; } fm[] = {
        {ST_SOUP_OBJ, "obj", 1}, {ST_SOUP_OFF, "off", 1}, {ST_SOUP_PLY, "ply", 1}, {ST_SOUP_STL, "stl", 0}};
    for (size_t i = 0; i < 4; i++) {
        char *buf = NULL;
        size_t len = 0;
        FILE *f = open_memstream(&buf, &len);
        st_error err;
        st_status st = st_soup_write(f, &s, fm[i].f, "line one\nsoupwrap -o x", fm[i].name, &err);
        fclose(f);
        st_soup *r = NULL;
        int same = 0;
        if (st == ST_OK && st_soup_parse(&r, fm[i].f, (unsigned char *)buf, len, fm[i].name, &err) == ST_OK) {
            if (fm[i].exact) {
                same = r->nverts == s.nverts && r->ntris == s.ntris &&
                       memcmp(r->xyz, s.xyz, 3 * s.nverts * sizeof *s.xyz) == 0 &&
                       memcmp(r->tris, s.tris, 3 * s.ntris * sizeof *s.tris) == 0;
            } else {
                /* STL: three vertices per triangle, coordinates as floats */
                same = r->ntris == s.ntris && r->nverts == 3 * s.ntris;
                for (size_t t = 0; same && t < s.ntris; t++)
                    for (int k = 0; k < 3; k++)
                        for (int a = 0; a < 3; a++)
                            same &= r->xyz[3 * (3 * t + (size_t)k) + (size_t)a] ==
                                    (double)(float)s.xyz[3 * s.tris[3 * t + (size_t)k] + (size_t)a];
            }
        }
        TAP_CHECK(same, "%s: written and read back, the same soup%s", fm[i].name,
                  fm[i].exact ? " (exact doubles)" : " (float coordinates)");
        if (fm[i].f == ST_SOUP_STL)
            TAP_CHECK(len == 84 + 50 * s.ntris && memcmp(buf, "solid", 5) != 0,
                      "stl: 84 + 50 bytes per triangle, header not 'solid'");
        else
            TAP_CHECK(buf && strstr(buf, "soupwrap -o x") != NULL, "%s: the history is in the file", fm[i].name);
        st_soup_free(r);
        free(buf);
    }
    free(s.xyz);
    free(s.tris);
}

int main(int argc, char **argv)
{
    static const tap_test tests[] = {TAP_TEST(check), TAP_TEST(write), TAP_TEST(grid_edge),
                                     TAP_TEST(iso_values), TAP_TEST(shapes), {0}};
    return tap_main(argc, argv, tests);
}
