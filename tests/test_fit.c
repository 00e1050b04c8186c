/* test_fit.c - st_fit: the mesh encloses the surface after every iteration
 * (checked by brute force here, independently of fit.c's local checks),
 * the boundary reaches the offset on a convex shape, the quality pass
 * raises the worst angles, results do not depend on the thread count (also
 * with a few vertices per colour, where the colour steps now fork), and
 * what did not hold on entry does not get worse; the BVH's triangle query
 * (the fit's face check) misses no triangle; the quality pass keeps every
 * boundary vertex within max(d_offset, where the fit left it) of S while
 * it frees the vertices held at the band's edge; peeling keeps the
 * enclosure and a manifold boundary, never lowers the lowest score and
 * spares the tets that overlapped the pseudo volume; the swept-region
 * test (fit_swept.c, which skips whole bins) answers as a brute-force scan
 * of every S vertex; the quality pass reports each of its rounds. */
#include "souptet/bvh.h"
#include "souptet/enclose.h"
#include "souptet/geom.h"
#include "souptet/isect.h"
#include "souptet/pred.h"
#include "souptet/sculpt.h"
#include "souptet/smooth.h"
#include "souptet/tetmesh.h"
#include "souptet/tetqual.h"
#include "cubetets.h"
#include "shapes.h"
#include "tap.h"
#include "../src/tet/fit_swept.h"
#include "../src/tet/invariant.h"
#include "../src/tet/pgrid.h"
#include "../src/tet/smooth_mesh.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#ifdef _OPENMP
#include <omp.h>
#endif

static int near_ball(const double c[3], void *ctx)
{
    double r = *(const double *)ctx;
    return sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]) < r;
}

/* Brute force: S vertices outside every tet, S triangles meeting a
 * boundary face, tets not positive; every pair tried (with a box test). */
typedef struct brute {
    size_t outside, crossing, inverted;
} brute;

static brute brute_check(const st_tetmesh *m, const st_soup *s)
{
    brute r = {0, 0, nonpositive(m)};
    double (*tb)[6] = malloc(m->ntets * sizeof *tb);
    for (size_t t = 0; t < m->ntets; t++) {
        for (int a = 0; a < 3; a++) {
            tb[t][a] = INFINITY;
            tb[t][3 + a] = -INFINITY;
        }
        for (int k = 0; k < 4; k++)
            for (int a = 0; a < 3; a++) {
                double x = m->xyz[3 * (size_t)m->tets[4 * t + (size_t)k] + (size_t)a];
                tb[t][a] = fmin(tb[t][a], x);
                tb[t][3 + a] = fmax(tb[t][3 + a], x);
            }
    }
    for (size_t i = 0; i < s->nverts; i++) {
        const double *q = s->xyz + 3 * i;
        int in = 0;
        for (size_t t = 0; t < m->ntets && !in; t++) {
            if (q[0] < tb[t][0] || q[0] > tb[t][3] || q[1] < tb[t][1] || q[1] > tb[t][4] ||
                q[2] < tb[t][2] || q[2] > tb[t][5])
                continue;
            const uint32_t *k = m->tets + 4 * t;
            in = st_point_in_tet(q, m->xyz + 3 * (size_t)k[0], m->xyz + 3 * (size_t)k[1],
                                 m->xyz + 3 * (size_t)k[2], m->xyz + 3 * (size_t)k[3]) != ST_OUTSIDE;
        }
        r.outside += !in;
    }
    free(tb);
    uint32_t *faces;
    size_t nf;
    st_tetmesh_boundary(m, &faces, NULL, &nf, NULL);
    for (size_t t = 0; t < s->ntris; t++) {
        const uint32_t *v = s->tris + 3 * t;
        const double *a = s->xyz + 3 * (size_t)v[0], *b = s->xyz + 3 * (size_t)v[1],
                     *c = s->xyz + 3 * (size_t)v[2];
        int hit = 0;
        for (size_t f = 0; f < nf && !hit; f++)
            hit = st_tri_tri_intersect(m->xyz + 3 * (size_t)faces[3 * f],
                                       m->xyz + 3 * (size_t)faces[3 * f + 1],
                                       m->xyz + 3 * (size_t)faces[3 * f + 2], a, b, c);
        r.crossing += hit;
    }
    free(faces);
    return r;
}

typedef struct watch {
    st_tetmesh *m;
    const st_soup *s;
    int checks, broken, fit_iters, quality_rounds;
    double last_min;
} watch;

/* The default parameters with fn called after every iteration. */
static st_fit_params watched_params(st_fit_iter_fn fn, void *ctx)
{
    st_fit_params p = st_fit_params_default();
    p.on_iter = fn;
    p.on_iter_ctx = ctx;
    return p;
}

static void on_iter(void *ctx, const st_fit_iter *it)
{
    watch *w = ctx;
    brute b = brute_check(w->m, w->s);
    w->checks++;
    if (b.outside || b.crossing || b.inverted) {
        if (!w->broken)
            TAP_NOTE("%s iteration %d: %zu outside, %zu crossing, %zu inverted", it->phase,
                     it->iter, b.outside, b.crossing, b.inverted);
        w->broken++;
    }
    if (strcmp(it->phase, "fit") == 0)
        w->fit_iters++;
    else
        w->quality_rounds++;
    w->last_min = it->min_dihedral;
}

/* The sphere of radius 1 (a closed soup, every other triangle flipped)
 * and the 5-tet cells of width h that can touch it. */
static st_tetmesh *ball_mesh(double h, double reach)
{
    double lo[3] = {-2, -2, -2};
    double r = 1.0 + reach * h;
    st_tetmesh *m = lattice5((int)lrint(4.0 / h), h, lo, near_ball, &r);
    char buf[32];
    snprintf(buf, sizeof buf, "%.17g", h);
    st_meta_set(&m->meta, "h", buf);
    return m;
}

static void test_sphere(void)
{
    st_soup *s = st_soup_new();
    add_sphere(s, 1.0, 2.0);
    /* a cell whose centre is within 1 + 0.87 h of the origin reaches the
     * sphere (half a cell diagonal is 0.866 h); keep those and a layer
     * more, so the boundary has some way to go */
    st_tetmesh *m = ball_mesh(0.5, 1.6);
    brute b0 = brute_check(m, s);
    TAP_CHECK(b0.outside == 0 && b0.crossing == 0 && b0.inverted == 0,
              "the initial lattice encloses the sphere (%zu tets)", m->ntets);
    watch w = {m, s, 0, 0, 0, 0, 0.0};
    st_fit_params p = st_fit_params_default();
    p.on_iter = on_iter;
    p.on_iter_ctx = &w;
    st_fit_stats st;
    st_error err;
    st_status rc = st_fit(m, s, NULL, &p, &st, NULL, &err);
    TAP_CHECK(rc == ST_OK, "fit succeeds (%s)", rc ? err.msg : "ok");
    TAP_CHECK(w.checks > 3 && w.broken == 0,
              "enclosure held after each of %d fit iterations and %d quality rounds "
              "(brute force)", w.fit_iters, w.quality_rounds);
    brute b1 = brute_check(m, s);
    TAP_CHECK(b1.outside == 0 && b1.crossing == 0 && b1.inverted == 0,
              "the result encloses the sphere, nothing inverted");
    TAP_CHECK(st.outside_before == 0 && st.crossing_before == 0 && st.outside_after == 0 &&
                  st.crossing_after == 0,
              "stats agree: enclosed before and after");
    TAP_CHECK(st.converged && st.within_offset == st.boundary_vertices && st.beyond_offset == 0,
              "every boundary vertex within d_offset = %.3g (after %d iterations)", st.d_offset,
              st.iters);
    TAP_CHECK(st.max_distance <= st.d_offset, "max distance %.4f <= d_offset", st.max_distance);
    TAP_CHECK(st.min_dihedral_after > st.min_dihedral_fit,
              "the quality pass raises the min dihedral: %.2f -> %.2f", st.min_dihedral_fit,
              st.min_dihedral_after);
    TAP_CHECK(st.min_dihedral_after > 20.0 && st.max_dihedral_after < 150.0,
              "final angles %.2f..%.2f", st.min_dihedral_after, st.max_dihedral_after);
    TAP_NOTE("sphere h=0.5: %zu tets, %d iters, %zu moves, %zu rejected, %d quality rounds, "
             "dihedral %.1f-%.1f -> fit %.1f-%.1f -> quality %.1f-%.1f, %.3f s + %.3f s",
             m->ntets, st.iters, st.moves, st.rejected, st.quality_rounds,
             st.min_dihedral_before, st.max_dihedral_before, st.min_dihedral_fit,
             st.max_dihedral_fit, st.min_dihedral_after, st.max_dihedral_after,
             st.seconds_fit, st.seconds_quality);
    st_tetmesh_free(m);
    st_soup_free(s);
}

/* The largest colour set of m: the fit and quality loops run a colour in
 * parallel only when PAR_CHECKED(its size). */
static size_t largest_colour(st_tetmesh *m)
{
    sm_mesh sm;
    st_error err;
    size_t big = 0;
    if (sm_mesh_build(&sm, m, &err))
        return 0;
    for (size_t c = 0; c < sm.ncolours; c++)
        if (sm.col_off[c + 1] - sm.col_off[c] > big)
            big = sm.col_off[c + 1] - sm.col_off[c];
    sm_mesh_free(&sm);
    return big;
}

static void test_threads(void)
{
#ifdef _OPENMP
    st_soup *s = st_soup_new();
    add_sphere(s, 1.0, 2.0);
    /* h = 0.25: colour sets of several hundred vertices, so the fit and
     * quality loops really run on several threads (at h = 0.5 the largest
     * had 48-81 and every loop ran serially). */
    st_tetmesh *a = ball_mesh(0.25, 0.9), *b = ball_mesh(0.25, 0.9);
    size_t big = largest_colour(a);
    TAP_CHECK(PAR_CHECKED(big), "the largest colour set (%zu vertices) takes the parallel path",
              big);
    int nt = omp_get_max_threads();
    st_error err;
    st_fit_params p = st_fit_params_default();
    p.quality_rounds = 10;
    st_fit_stats sa, sb;
    omp_set_num_threads(1);
    st_status r1 = st_fit(a, s, NULL, &p, &sa, NULL, &err);
    omp_set_num_threads(3);
    st_status r2 = st_fit(b, s, NULL, &p, &sb, NULL, &err);
    omp_set_num_threads(nt);
    TAP_CHECK(r1 == ST_OK && r2 == ST_OK && sa.moves > 0 && sa.quality_moves > 0,
              "both fits ran: %zu fit moves, %zu quality moves", sa.moves, sa.quality_moves);
    TAP_CHECK(r1 == ST_OK && r2 == ST_OK && a->npoints == b->npoints &&
                  memcmp(a->xyz, b->xyz, 3 * a->npoints * sizeof(double)) == 0,
              "1 and 3 threads give bit-identical points");
    st_tetmesh_free(a);
    st_tetmesh_free(b);
    st_soup_free(s);
#else
    TAP_CHECK(1, "1 and 3 threads give bit-identical points # SKIP no OpenMP");
#endif
}


/* Few vertices per colour (a coarse ball: every colour set at most 64,
 * where until batch 57 the fit and quality loops ran serially): the
 * colour steps whose vertices to try number PAR_CHECKED run on 2 threads,
 * and 1, 2 and 3 threads give bit-identical points and counts. */
static void test_threads_small(void)
{
#ifdef _OPENMP
    st_soup *s = st_soup_new();
    add_sphere(s, 1.0, 2.0);
    st_tetmesh *m[3];
    for (int k = 0; k < 3; k++)
        m[k] = ball_mesh(0.5, 0.9);
    size_t big = largest_colour(m[0]);
    TAP_CHECK(big > 1 && big <= 64, "the largest colour set holds %zu vertices (2..64)", big);
    TAP_CHECK(PAR_CHECKED(big / 4), "a colour step trying a quarter of it (%zu) takes the "
              "parallel path", big / 4);
    int nt = omp_get_max_threads(), forked = 0;
    omp_set_num_threads(2);
    #pragma omp parallel if (PAR_CHECKED(big / 4))
    {
        #pragma omp atomic
        forked++;
    }
    TAP_CHECK(forked == 2, "that path runs on 2 threads (%d)", forked);
    st_fit_params p = st_fit_params_default();
    p.quality_rounds = 10;
    st_fit_stats st[3];
    st_status rc[3];
    st_error err;
    for (int k = 0; k < 3; k++) {
        omp_set_num_threads(k + 1);
        rc[k] = st_fit(m[k], s, NULL, &p, &st[k], NULL, &err);
    }
    omp_set_num_threads(nt);
    TAP_CHECK(rc[0] == ST_OK && rc[1] == ST_OK && rc[2] == ST_OK && st[0].moves > 0 &&
                  st[0].quality_moves > 0,
              "the fits ran: %zu fit moves, %zu quality moves", st[0].moves,
              st[0].quality_moves);
    int same = 1;
    for (int k = 1; k < 3; k++)
        same &= rc[k] == ST_OK && m[k]->npoints == m[0]->npoints &&
                memcmp(m[k]->xyz, m[0]->xyz, 3 * m[0]->npoints * sizeof(double)) == 0 &&
                st[k].moves == st[0].moves && st[k].rejected == st[0].rejected &&
                st[k].skipped == st[0].skipped && st[k].quality_moves == st[0].quality_moves;
    TAP_CHECK(same, "1, 2 and 3 threads give bit-identical points and the same counts");
    for (int k = 0; k < 3; k++)
        st_tetmesh_free(m[k]);
    st_soup_free(s);
#else
    TAP_CHECK(1, "1, 2 and 3 threads give bit-identical points # SKIP no OpenMP");
#endif
}

/* The small loops' team gate (sm_par_gate): open below its slack, closed
 * for 16 steps after a region that waited (a thread without a core),
 * then 32 after a slow probe, and the wait halved by a fast one; a
 * region of one thread tells nothing; PAR_CHECKED still applies. */
static void test_par_gate(void)
{
    sm_par_gate g = {0, 0};
    TAP_CHECK(sm_par_gate_open(&g, 2) && !sm_par_gate_open(&g, 1) &&
                  sm_par_gate_open(NULL, 2),
              "open from 2 items (PAR_CHECKED), also without a gate");
    sm_par_gate_note(&g, 2, 0.0005, 0.0004);   /* 0.1 ms over: not a wait */
    sm_par_gate_note(&g, 2, 0.004, 0.0009);    /* 3 ms over: a thread waited */
    int open = sm_par_gate_open(&g, 8);
    sm_par_gate_note(&g, 1, 0.5, 0.001);       /* 1 thread: no evidence */
    TAP_CHECK(open == 0 && g.wait == 15 && g.backoff == 16,
              "a region 3 ms over its 0.9 ms of work closes the gate for 16 steps (%u, %u)",
              g.wait, g.backoff);
    int closed = 0;
    for (int k = 0; k < 15; k++)
        closed += !sm_par_gate_open(&g, 8);
    TAP_CHECK(closed == 15 && sm_par_gate_open(&g, 8), "it reopens for a probe after them");
    sm_par_gate_note(&g, 2, 0.02, 0.001);
    TAP_CHECK(g.wait == 32, "a slow probe doubles the wait (%u)", g.wait);
    g.wait = 0;
    sm_par_gate_note(&g, 2, 0.0006, 0.001);
    TAP_CHECK(g.wait == 0 && g.backoff == 16 && sm_par_gate_open(&g, 8),
              "a fast region halves the next wait (%u) and leaves the gate open", g.backoff);
}
/* The quality pass reports each round (stage "quality", rounds done out
 * of quality_rounds): the pipeline's candidates take threads freed by
 * the others at these reports (pipeline.c, candidate_threads). */
typedef struct quality_reports {
    size_t n, inside, bad;
} quality_reports;

static void on_report(void *ctx, const char *stage, double fraction)
{
    quality_reports *q = ctx;
    if (strcmp(stage, "quality") != 0)
        return;
    q->n++;
    q->inside += fraction > 0 && fraction < 1;
    q->bad += !(fraction >= 0 && fraction <= 1);
}

static void test_quality_reports(void)
{
    st_soup *s = st_soup_new();
    add_sphere(s, 1.0, 2.0);
    st_tetmesh *m = ball_mesh(0.5, 0.9);
    st_fit_params p = st_fit_params_default();
    p.quality_rounds = 10;
    quality_reports q = {0, 0, 0};
    const st_progress prog = {on_report, &q, NULL};
    st_fit_stats st;
    st_error err;
    st_status rc = st_fit(m, s, NULL, &p, &st, &prog, &err);
    TAP_CHECK(rc == ST_OK && st.quality_rounds >= 1 && q.n >= 2 + (size_t)st.quality_rounds &&
                  q.inside >= 1 && q.bad == 0,
              "the quality pass reports its rounds: %zu quality reports, %zu inside (0, 1) "
              "(the last pass ran %d rounds)", q.n, q.inside, st.quality_rounds);
    st_tetmesh_free(m);
    st_soup_free(s);
}

static void test_not_enclosing(void)
{
    /* cells whose centres are inside radius 1.05: parts of the sphere
     * stick out. What was broken must not spread. */
    st_soup *s = st_soup_new();
    add_sphere(s, 1.0, 2.0);
    st_tetmesh *m = ball_mesh(0.5, 0.1);
    st_fit_params p = st_fit_params_default();
    p.max_iters = 20;
    p.quality_rounds = 5;
    st_fit_stats st;
    st_error err;
    st_status rc = st_fit(m, s, NULL, &p, &st, NULL, &err);
    brute b = brute_check(m, s);
    TAP_CHECK(rc == ST_OK && st.outside_before > 0 && st.crossing_before > 0,
              "a lattice that misses parts of the sphere: %zu vertices out, %zu crossing",
              st.outside_before, st.crossing_before);
    TAP_CHECK(st.outside_after <= st.outside_before && st.crossing_after <= st.crossing_before &&
                  b.outside == st.outside_after && b.crossing == st.crossing_after &&
                  b.inverted == 0,
              "no more vertices out (%zu) nor crossings (%zu) after the fit; stats match "
              "brute force", st.outside_after, st.crossing_after);
    st_tetmesh_free(m);
    st_soup_free(s);
}

static void test_refusals(void)
{
    st_soup *s = st_soup_new();
    add_sphere(s, 1.0, 2.0);
    st_tetmesh *m = ball_mesh(0.5, 0.9);
    st_meta_clear(&m->meta);
    st_error err;
    st_status rc = st_fit(m, s, NULL, NULL, NULL, NULL, &err);
    TAP_CHECK(rc == ST_EINPUT && strstr(err.msg, "cell width"),
              "no meta h and no cell width: refused (%s)", err.msg);
    st_fit_params p = st_fit_params_default();
    p.cell_width = 0.5;
    p.max_iters = 1;
    p.quality = 0;
    rc = st_fit(m, s, NULL, &p, NULL, NULL, &err);
    TAP_CHECK(rc == ST_OK, "a given cell width is used instead");
    uint32_t t = m->tets[0];
    m->tets[0] = m->tets[1];
    m->tets[1] = t;
    rc = st_fit(m, s, NULL, &p, NULL, NULL, &err);
    TAP_CHECK(rc == ST_EINPUT && strstr(err.msg, "inverted"), "an inverted tet is refused");
    /* A failed enclosure count cannot read as "encloses" (0 and 0). */
    st_soup *other = st_soup_new();
    add_sphere(other, 0.5, 2.0);
    st_bvh *ob = NULL;
    size_t vo = 0, tc = 0;
    rc = st_bvh_build(&ob, other, &err) ? ST_ENOMEM
                                        : st_enclosure_count(m, s, ob, &vo, &tc, &err);
    TAP_CHECK(rc != ST_OK && vo == SIZE_MAX && tc == SIZE_MAX,
              "st_enclosure_count on error: SIZE_MAX vertices out and triangles crossing");
    st_bvh_free(ob);
    st_soup_free(other);
    st_tetmesh_free(m);
    st_soup_free(s);
}


typedef struct tri_hits {
    const st_soup *s;
    const double *q[3];
    size_t visited, meeting;
    unsigned char *seen;
} tri_hits;

static int count_visit(void *ctx, uint32_t t)
{
    tri_hits *h = ctx;
    const uint32_t *v = h->s->tris + 3 * (size_t)t;
    h->visited++;
    h->seen[t] = 1;
    h->meeting += (size_t)st_tri_tri_intersect(h->q[0], h->q[1], h->q[2],
                                               h->s->xyz + 3 * (size_t)v[0],
                                               h->s->xyz + 3 * (size_t)v[1],
                                               h->s->xyz + 3 * (size_t)v[2]);
    return 0;
}

static int box_visit(void *ctx, uint32_t t)
{
    (*(size_t *)ctx)++;
    (void)t;
    return 0;
}

/* The next of the tests' linear congruential draws, in [0, 1). */
static double unit_draw(unsigned *rng)
{
    *rng = *rng * 1103515245u + 12345u;
    return (double)(*rng >> 8) / (double)(1u << 24);
}

/* The BVH query tests' soup: a sphere of radius 1 (add_sphere) and its BVH. */
static st_bvh *sphere_bvh(st_soup **s)
{
    *s = st_soup_new();
    add_sphere(*s, 1.0, 2.0);
    st_bvh *b = NULL;
    st_error err;
    TAP_CHECK(st_bvh_build(&b, *s, &err) == ST_OK, "bvh over the sphere");
    return b;
}

/* st_bvh_query_tri against brute force: every sphere triangle that meets
 * a query triangle (large, slanted, some through the sphere, some touching
 * it at a vertex) is visited; and it visits far fewer than the box query. */
static void test_bvh_query_tri(void)
{
    st_soup *s;
    st_bvh *b = sphere_bvh(&s);
    unsigned char *seen = calloc(s->ntris, 1);
    size_t missed = 0, meeting = 0, visited = 0, boxed = 0;
    unsigned rng = 12345u;
    for (int k = 0; k < 200; k++) {
        double p[3][3];
        for (int i = 0; i < 3; i++)
            for (int a = 0; a < 3; a++) {
                p[i][a] = -1.5 + 3.0 * unit_draw(&rng);
            }
        if (k % 10 == 0)   /* a corner exactly on a sphere vertex */
            memcpy(p[0], s->xyz + 3 * (size_t)s->tris[3 * (size_t)k], sizeof p[0]);
        tri_hits h = {s, {p[0], p[1], p[2]}, 0, 0, seen};
        memset(seen, 0, s->ntris);
        st_bvh_query_tri(b, p[0], p[1], p[2], count_visit, &h);
        for (size_t t = 0; t < s->ntris; t++) {
            const uint32_t *v = s->tris + 3 * t;
            if (!seen[t] && st_tri_tri_intersect(p[0], p[1], p[2], s->xyz + 3 * (size_t)v[0],
                                                 s->xyz + 3 * (size_t)v[1],
                                                 s->xyz + 3 * (size_t)v[2]))
                missed++;
        }
        double lo[3], hi[3];
        for (int a = 0; a < 3; a++) {
            lo[a] = fmin(p[0][a], fmin(p[1][a], p[2][a]));
            hi[a] = fmax(p[0][a], fmax(p[1][a], p[2][a]));
        }
        st_bvh_query_box(b, lo, hi, box_visit, &boxed);
        meeting += h.meeting;
        visited += h.visited;
    }
    TAP_CHECK(missed == 0 && meeting > 0,
              "the triangle query visits every triangle that meets the query (%zu meet, "
              "%zu missed)", meeting, missed);
    TAP_CHECK(2 * visited < boxed, "and visits fewer than half of the box query's (%zu vs %zu)",
              visited, boxed);
    free(seen);
    st_bvh_free(b);
    st_soup_free(s);
}

/* st_bvh_nearest_framed with every sphere triangle's frame answers as
 * st_bvh_nearest, bit for bit (distance, triangle and closest point), at
 * random points near the sphere and far, at its vertices and on its
 * edges' midpoints (ties between triangles: the walk's first), within
 * reaches from a hundredth to no limit. */
static void test_bvh_nearest_framed(void)
{
    st_soup *s;
    st_bvh *b = sphere_bvh(&s);
    st_tri_frame *f = malloc(s->ntris * sizeof *f);
    for (size_t t = 0; t < s->ntris; t++) {
        const uint32_t *v = s->tris + 3 * t;
        st_tri_frame_make(f + t, s->xyz + 3 * (size_t)v[0], s->xyz + 3 * (size_t)v[1],
                          s->xyz + 3 * (size_t)v[2]);
    }
    static const double reach[] = {0.01, 0.1, 0.5, INFINITY};
    size_t bad = 0, found = 0, cases = 0;
    unsigned rng = 4711u;
    for (int k = 0; k < 4000; k++) {
        double p[3];
        const uint32_t *v = s->tris + 3 * ((size_t)k % s->ntris);
        const double *x0 = s->xyz + 3 * (size_t)v[0], *x1 = s->xyz + 3 * (size_t)v[1];
        for (int a = 0; a < 3; a++)
            p[a] = k % 4 == 0 ? x0[a] : k % 4 == 1 ? 0.5 * (x0[a] + x1[a])
                 : (k % 4 == 2 ? 1.2 : 3.0) * (unit_draw(&rng) - 0.5) * 2.0;
        for (size_t r = 0; r < sizeof reach / sizeof *reach; r++) {
            int64_t t0 = -2, t1 = -3;
            double q0[3] = {0, 0, 0}, q1[3] = {0, 0, 0};
            const double r2 = reach[r] * reach[r];
            const double d0 = st_bvh_nearest(b, p, r2, &t0, q0);
            const double d1 = st_bvh_nearest_framed(b, f, p, r2, &t1, q1);
            cases++;
            found += t0 >= 0;
            bad += t0 != t1 || memcmp(&d0, &d1, sizeof d0) != 0 || memcmp(q0, q1, sizeof q0) != 0;
        }
    }
    TAP_CHECK(bad == 0 && found > cases / 2,
              "framed nearest queries answer as st_bvh_nearest (%zu of %zu differ, %zu found)",
              bad, cases, found);
    free(f);
    st_bvh_free(b);
    st_soup_free(s);
}

typedef struct tet_seen {
    size_t visited;
    unsigned char *seen;
} tet_seen;

static int tet_visit(void *ctx, uint32_t t)
{
    tet_seen *h = ctx;
    h->visited++;
    h->seen[t] = 1;
    return 0;
}

/* st_bvh_query_tet against brute force (the sculpting's test): every
 * sphere triangle that meets a tet (random ones, large and small; ones with
 * a corner on a sphere vertex; ones with a face on a sphere triangle) is
 * visited; and it visits far fewer than the box query of the tet's box. */
static void test_bvh_query_tet(void)
{
    st_soup *s;
    st_bvh *b = sphere_bvh(&s);
    tet_seen h = {0, calloc(s->ntris, 1)};
    size_t missed = 0, meeting = 0, boxed = 0;
    unsigned rng = 4242u;
    for (int k = 0; k < 300; k++) {
        double p[4][3];
        const double size = k % 3 == 0 ? 0.3 : 2.0;
        double c[3];
        for (int a = 0; a < 3; a++) {
            c[a] = -1.2 + 2.4 * unit_draw(&rng);
        }
        for (int i = 0; i < 4; i++)
            for (int a = 0; a < 3; a++) {
                p[i][a] = c[a] + size * (unit_draw(&rng) - 0.5);
            }
        const uint32_t *tv = s->tris + 3 * (size_t)(k % s->ntris);
        if (k % 10 == 1)   /* a corner exactly on a sphere vertex */
            memcpy(p[0], s->xyz + 3 * (size_t)tv[0], sizeof p[0]);
        if (k % 10 == 2)   /* a face exactly on a sphere triangle */
            for (int i = 0; i < 3; i++)
                memcpy(p[i], s->xyz + 3 * (size_t)tv[i], sizeof p[i]);
        if (st_orient3d(p[0], p[1], p[2], p[3]) == 0.0)
            continue;
        const double *q[4] = {p[0], p[1], p[2], p[3]};
        memset(h.seen, 0, s->ntris);
        st_bvh_query_tet(b, q, tet_visit, &h);
        for (size_t t = 0; t < s->ntris; t++) {
            const uint32_t *v = s->tris + 3 * t;
            if (st_tri_tet_intersect(s->xyz + 3 * (size_t)v[0], s->xyz + 3 * (size_t)v[1],
                                     s->xyz + 3 * (size_t)v[2], p[0], p[1], p[2], p[3])) {
                meeting++;
                missed += !h.seen[t];
            }
        }
        double lo[3], hi[3];
        for (int a = 0; a < 3; a++) {
            lo[a] = fmin(fmin(p[0][a], p[1][a]), fmin(p[2][a], p[3][a]));
            hi[a] = fmax(fmax(p[0][a], p[1][a]), fmax(p[2][a], p[3][a]));
        }
        st_bvh_query_box(b, lo, hi, box_visit, &boxed);
    }
    TAP_CHECK(missed == 0 && meeting > 0,
              "the tet query visits every triangle that meets the tet (%zu meet, %zu missed)",
              meeting, missed);
    TAP_CHECK(2 * h.visited < boxed, "and visits fewer than half of the box query's (%zu vs %zu)",
              h.visited, boxed);
    free(h.seen);
    st_bvh_free(b);
    st_soup_free(s);
}

/* A flat tet (four corners in the plane z = c, exactly): its closed set
 * is the union of its four faces, and the tet query visits every sphere
 * triangle that meets one of them (bvh.h: a superset of the triangles
 * that meet the closed tet; a face whose opposite corner lies on its
 * plane must not take every point off that plane as outside). */
static void test_bvh_query_flat_tet(void)
{
    st_soup *s;
    st_bvh *b = sphere_bvh(&s);
    tet_seen h = {0, calloc(s->ntris, 1)};
    size_t missed = 0, meeting = 0;
    unsigned rng = 777u;
    for (int k = 0; k < 100; k++) {
        double p[4][3];
        const double z = -0.9 + 1.8 * unit_draw(&rng);
        for (int i = 0; i < 4; i++) {
            for (int a = 0; a < 2; a++) {
                p[i][a] = 2.4 * (unit_draw(&rng) - 0.5);
            }
            p[i][2] = z;
        }
        const double *q[4] = {p[0], p[1], p[2], p[3]};
        memset(h.seen, 0, s->ntris);
        st_bvh_query_tet(b, q, tet_visit, &h);
        for (size_t t = 0; t < s->ntris; t++) {
            const double *v[3];
            for (int i = 0; i < 3; i++)
                v[i] = s->xyz + 3 * (size_t)s->tris[3 * t + (size_t)i];
            int meets = 0;
            for (int f = 0; f < 4 && !meets; f++) {
                const double *r[3];
                for (int c = 0, n = 0; c < 4; c++)
                    if (c != f)
                        r[n++] = p[c];
                meets = st_tri_tri_intersect(v[0], v[1], v[2], r[0], r[1], r[2]);
            }
            meeting += (size_t)meets;
            missed += (size_t)(meets && !h.seen[t]);
        }
    }
    TAP_CHECK(missed == 0 && meeting > 0,
              "a flat tet's query visits every triangle that meets it (%zu meet, %zu missed)",
              meeting, missed);
    free(h.seen);
    st_bvh_free(b);
    st_soup_free(s);
}

typedef struct band_watch {
    st_tetmesh *m;
    const st_bvh *b;
    double *fit_dist;   /* per point, at the last fit iteration */
} band_watch;

static void band_on_iter(void *ctx, const st_fit_iter *it)
{
    band_watch *w = ctx;
    if (strcmp(it->phase, "fit") != 0)
        return;
    for (size_t v = 0; v < w->m->npoints; v++) {
        int64_t tri;
        w->fit_dist[v] = sqrt(st_bvh_nearest(w->b, w->m->xyz + 3 * v, INFINITY, &tri, NULL));
    }
}

/* A thin band (offset 0.15 h) on the sphere: the fit leaves many boundary
 * vertices at or past the band's edge, where every quality step with an
 * outward component is refused. The quality pass must still lift the
 * angles there (its tangential steps), without moving any boundary vertex
 * farther from S than max(d_offset, its distance after the fit), and the
 * result must still enclose S (brute force). */
static void test_band_edge(void)
{
    st_soup *s = st_soup_new();
    add_sphere(s, 1.0, 2.0);
    st_bvh *b = NULL;
    st_error err;
    st_bvh_build(&b, s, &err);
    st_tetmesh *m = ball_mesh(0.5, 1.6);
    band_watch w = {m, b, calloc(m->npoints, sizeof(double))};
    st_fit_params p = watched_params(band_on_iter, &w);
    p.offset_ratio = 0.15;
    st_fit_stats st;
    st_status rc = st_fit(m, s, b, &p, &st, NULL, &err);
    uint32_t *faces = NULL;
    size_t nf = 0;
    st_tetmesh_boundary(m, &faces, NULL, &nf, NULL);
    size_t farther = 0, at_edge = 0;
    for (size_t i = 0; i < 3 * nf; i++) {
        uint32_t v = faces[i];
        int64_t tri;
        double d = sqrt(st_bvh_nearest(b, m->xyz + 3 * (size_t)v, INFINITY, &tri, NULL));
        /* 1e-9 h: the pass compares the same distances; only rounding */
        if (d > fmax(st.d_offset, w.fit_dist[v]) + 1e-9 * st.h)
            farther++;
        if (w.fit_dist[v] > 0.9 * st.d_offset)
            at_edge++;
    }
    brute r = brute_check(m, s);
    TAP_CHECK(rc == ST_OK && at_edge > 0 && farther == 0,
              "quality steps keep every boundary vertex within max(d_offset, its fit "
              "distance) (%zu of %zu boundary corners at the band's edge after the fit)",
              at_edge, 3 * nf);
    TAP_CHECK(r.outside == 0 && r.crossing == 0 && r.inverted == 0,
              "the thin-band fit encloses the sphere, nothing inverted");
    /* without the tangential steps: 23.6..148.2 (measured) */
    TAP_CHECK(st.min_dihedral_after >= 25.0 && st.max_dihedral_after <= 145.0,
              "thin band: angles %.2f..%.2f within [25, 145] (after the fit %.2f..%.2f; "
              "%d iterations, %.2f s + %.2f s)",
              st.min_dihedral_after, st.max_dihedral_after, st.min_dihedral_fit,
              st.max_dihedral_fit, st.iters, st.seconds_fit, st.seconds_quality);
    free(faces);
    free(w.fit_dist);
    st_tetmesh_free(m);
    st_bvh_free(b);
    st_soup_free(s);
}

/* 1 when the boundary of m is a closed manifold: every boundary vertex's
 * boundary faces form one cycle around it (each link vertex on exactly
 * two of its link edges, the link edges connected). */
static int boundary_manifold(const st_tetmesh *m)
{
    uint32_t *faces = NULL;
    size_t nf = 0;
    st_tetmesh_boundary(m, &faces, NULL, &nf, NULL);
    int ok = 1;
    uint32_t (*link)[2] = malloc((nf ? nf : 1) * sizeof *link);
    for (size_t v = 0; v < m->npoints && ok; v++) {
        size_t n = 0;
        for (size_t f = 0; f < nf; f++)
            for (int i = 0; i < 3; i++)
                if (faces[3 * f + (size_t)i] == v) {
                    link[n][0] = faces[3 * f + (size_t)((i + 1) % 3)];
                    link[n][1] = faces[3 * f + (size_t)((i + 2) % 3)];
                    n++;
                }
        if (n == 0)
            continue;
        /* walk the cycle from link[0]: each step finds the one edge that
         * starts where the last ended (oriented faces: a disc's link is a
         * directed cycle); a walk that closes before using every edge, or
         * a vertex starting two edges, is not a manifold */
        size_t steps = 0;
        uint32_t at = link[0][1];
        while (ok && steps < n) {
            size_t hits = 0, next = 0;
            for (size_t j = 0; j < n; j++)
                if (link[j][0] == at) {
                    hits++;
                    next = j;
                }
            if (hits != 1)
                ok = 0;
            at = link[next][1];
            steps++;
            if (next == 0)
                break;
        }
        if (steps != n)
            ok = 0;
    }
    free(link);
    free(faces);
    return ok;
}

/* The lowest tet score of m (smooth_mesh.h). */
static double min_score(const st_tetmesh *m)
{
    double lo = INFINITY;
    for (size_t t = 0; t < m->ntets; t++) {
        const uint32_t *k = m->tets + 4 * t;
        lo = fmin(lo, sm_tet_score(m->xyz + 3 * (size_t)k[0], m->xyz + 3 * (size_t)k[1],
                                   m->xyz + 3 * (size_t)k[2], m->xyz + 3 * (size_t)k[3]));
    }
    return lo;
}

/* Every tet in a "sculpt" cell array: class `cls`, and every other one
 * `other` (a different class). */
static void set_classes(st_tetmesh *m, double cls, double other)
{
    double *a = NULL;
    st_tetmesh_add_array(m, "sculpt", ST_ON_CELLS, 1, &a, NULL);
    for (size_t t = 0; t < m->ntets; t++)
        a[t] = t % 2 ? cls : other;
}

static size_t count_class(const st_tetmesh *m, double cls)
{
    const st_tet_array *a = st_tetmesh_find_array(m, "sculpt", ST_ON_CELLS);
    size_t n = 0;
    for (size_t t = 0; a && t < m->ntets; t++)
        n += a->values[t] == cls;
    return n;
}

/* Peeling (fit.c): on the thin band of test_band_edge, the fit removes
 * boundary tets below the goal that hold nothing of S. The mesh must still
 * enclose S (brute force), stay positive with a manifold boundary, lose
 * only tets (no worse lowest score than without peeling, which runs the
 * same up to the peel), keep its cell arrays in step with its tets, and
 * never peel a tet classed ST_SCULPT_VOLUME (it overlapped the pseudo
 * volume when sculpted). */
static void test_peel(void)
{
    st_soup *s = st_soup_new();
    add_sphere(s, 1.0, 2.0);
    st_bvh *b = NULL;
    st_error err;
    st_bvh_build(&b, s, &err);
    st_fit_params p = st_fit_params_default();
    p.offset_ratio = 0.15;
    st_fit_stats st0, st1, st2;
    st_tetmesh *m0 = ball_mesh(0.5, 1.6), *m1 = ball_mesh(0.5, 1.6), *m2 = ball_mesh(0.5, 1.6);
    size_t n = m1->ntets;
    set_classes(m1, ST_SCULPT_SURFACE, ST_SCULPT_BOMB);
    set_classes(m2, ST_SCULPT_VOLUME, ST_SCULPT_BOMB);
    size_t vol2 = count_class(m2, ST_SCULPT_VOLUME);
    p.peel = 0;
    st_status rc0 = st_fit(m0, s, b, &p, &st0, NULL, &err);
    p.peel = 1;
    st_status rc1 = st_fit(m1, s, b, &p, &st1, NULL, &err);
    st_status rc2 = st_fit(m2, s, b, &p, &st2, NULL, &err);
    brute r = brute_check(m1, s);
    TAP_CHECK(rc0 == ST_OK && rc1 == ST_OK && st0.peeled == 0 && st1.peeled > 0 &&
              m1->ntets + st1.peeled == n && m0->ntets == n,
              "peeling removes boundary tets (%zu of %zu)", st1.peeled, n);
    TAP_CHECK(r.outside == 0 && r.crossing == 0 && r.inverted == 0 && boundary_manifold(m1) &&
              boundary_manifold(m0),
              "the peeled mesh encloses the sphere, nothing inverted, its boundary a manifold");
    TAP_CHECK(min_score(m1) >= min_score(m0),
              "peeling does not lower the lowest score (%.2f, %.2f without; angles %.2f..%.2f "
              "-> %.2f..%.2f)", min_score(m1), min_score(m0), st0.min_dihedral_after,
              st0.max_dihedral_after, st1.min_dihedral_after, st1.max_dihedral_after);
    TAP_CHECK(count_class(m1, ST_SCULPT_SURFACE) + count_class(m1, ST_SCULPT_BOMB) == m1->ntets &&
              rc2 == ST_OK && count_class(m2, ST_SCULPT_VOLUME) == vol2 &&
              m2->ntets + st2.peeled == n,
              "the cell array follows the tets; no ST_SCULPT_VOLUME tet peeled (%zu peeled of "
              "the other half)", st2.peeled);
    st_tetmesh_free(m0);
    st_tetmesh_free(m1);
    st_tetmesh_free(m2);
    st_bvh_free(b);
    st_soup_free(s);
}

/* The fill (st_fit_params.fill): S is the sphere's upper half, the fill
 * its lower half. Alone, S leaves the lower boundary vertices far from
 * it; with the fill counting as surface every boundary vertex gets within
 * d_offset of S or the fill, and the mesh still encloses S (brute force). */
static void split_z(const st_soup *s, st_soup *up, st_soup *down)
{
    for (size_t t = 0; t < s->ntris; t++) {
        const uint32_t *v = s->tris + 3 * t;
        double cz = 0.0;
        for (int k = 0; k < 3; k++)
            cz += s->xyz[3 * (size_t)v[k] + 2] / 3.0;
        st_soup *d = cz > 0.0 ? up : down;
        size_t b = d->nverts;
        for (int k = 0; k < 3; k++) {
            const double *x = s->xyz + 3 * (size_t)v[k];
            st_soup_add_vertex(d, x[0], x[1], x[2], NULL);
        }
        st_soup_add_triangle(d, (uint32_t)b, (uint32_t)b + 1, (uint32_t)b + 2, NULL);
    }
}

static void test_fill(void)
{
    st_soup *full = st_soup_new(), *up = st_soup_new(), *down = st_soup_new();
    add_sphere(full, 1.0, 2.0);
    split_z(full, up, down);
    st_fit_stats st[2];
    for (int k = 0; k < 2; k++) {
        st_tetmesh *m = ball_mesh(0.5, 1.6);
        st_fit_params p = st_fit_params_default();
        p.fill = k ? down : NULL;
        st_error err;
        st_status rc = st_fit(m, up, NULL, &p, &st[k], NULL, &err);
        brute b = brute_check(m, up);
        TAP_CHECK(rc == ST_OK && b.outside == 0 && b.crossing == 0 && b.inverted == 0,
                  "%s: the mesh encloses the half sphere, nothing inverted",
                  k ? "with the fill" : "without a fill");
        st_tetmesh_free(m);
    }
    TAP_CHECK(!st[0].converged && st[0].max_distance > 2 * st[0].d_offset,
              "without a fill the lower boundary stays far from S: %zu beyond, %.3f > 2 d_offset",
              st[0].beyond_offset, st[0].max_distance);
    TAP_CHECK(st[1].converged && st[1].beyond_offset == 0 && st[1].max_distance <= st[1].d_offset,
              "with it every boundary vertex is within d_offset of S or the fill (max %.4f <= %.3g)",
              st[1].max_distance, st[1].d_offset);
    TAP_CHECK(st[1].min_dihedral_after > 20.0, "angles %.2f..%.2f", st[1].min_dihedral_after,
              st[1].max_dihedral_after);
    st_soup_free(full);
    st_soup_free(up);
    st_soup_free(down);
}

/* The shared set-up (st_fit_shared_new): fits given it, twice from one
 * set-up and at once (the pipeline's candidates), move every vertex
 * exactly as fits that built their own (the fill's BVH, the point grid);
 * a set-up made for another surface, fill or cell width is refused. */
static int same_mesh(const st_tetmesh *a, const st_tetmesh *b)
{
    return a->npoints == b->npoints && a->ntets == b->ntets &&
           memcmp(a->xyz, b->xyz, 3 * a->npoints * sizeof *a->xyz) == 0 &&
           memcmp(a->tets, b->tets, 4 * a->ntets * sizeof *a->tets) == 0;
}

static void test_shared(void)
{
    st_soup *full = st_soup_new(), *up = st_soup_new(), *down = st_soup_new();
    add_sphere(full, 1.0, 2.0);
    split_z(full, up, down);
    const double h = 0.5;
    st_fit_shared *sh = NULL;
    st_error err;
    TAP_CHECK(st_fit_shared_new(&sh, up, down, h, &err) == ST_OK && sh, "the set-up is made");
    st_tetmesh *m[3];
    st_fit_stats st[3];
    st_status rc[3];
    for (int k = 0; k < 3; k++)
        m[k] = ball_mesh(h, 1.6);
    #pragma omp parallel for num_threads(2) schedule(static, 1)
    for (int k = 0; k < 3; k++) {
        st_fit_params p = st_fit_params_default();
        p.cell_width = h;
        p.fill = down;
        p.shared = k ? sh : NULL;
        st_error e;
        rc[k] = st_fit(m[k], up, NULL, &p, &st[k], NULL, &e);
    }
    for (int k = 1; k < 3; k++)
        TAP_CHECK(rc[0] == ST_OK && rc[k] == ST_OK && same_mesh(m[0], m[k]) &&
                      st[0].moves == st[k].moves && st[0].iters == st[k].iters &&
                      st[0].max_distance == st[k].max_distance &&
                      st[0].min_dihedral_after == st[k].min_dihedral_after,
                  "fit %d with the shared set-up: the same mesh as with its own "
                  "(%zu moves, max distance %.6f, angles %.3f..%.3f)",
                  k, st[k].moves, st[k].max_distance, st[k].min_dihedral_after,
                  st[k].max_dihedral_after);
    struct {
        const st_soup *s, *fill;
        double h;
        const char *what;
    } bad[3] = {{full, down, h, "another surface"}, {up, NULL, h, "another fill"},
                {up, down, 0.25, "another cell width"}};
    for (int k = 0; k < 3; k++) {
        st_tetmesh *b = ball_mesh(h, 1.6);
        st_fit_params p = st_fit_params_default();
        p.cell_width = bad[k].h;
        p.fill = bad[k].fill;
        p.shared = sh;
        TAP_CHECK(st_fit(b, bad[k].s, NULL, &p, NULL, NULL, &err) == ST_EINPUT,
                  "a set-up made for %s is refused", bad[k].what);
        st_tetmesh_free(b);
    }
    st_fit_shared *none = sh;
    TAP_CHECK(st_fit_shared_new(&none, up, down, 0.0, &err) == ST_EINPUT && !none,
              "no set-up without a cell width");
    for (int k = 0; k < 3; k++)
        st_tetmesh_free(m[k]);
    st_fit_shared_free(sh);
    st_fit_shared_free(NULL);
    st_soup_free(full);
    st_soup_free(up);
    st_soup_free(down);
}

/* The fit's stall rule, as fit.c promises it: a fit that stops with a
 * boundary vertex still beyond d_offset, having moved something in its
 * last iteration and before max_iters, has had STALL_ITERS iterations in a
 * row in which no boundary vertex came within d_offset for the first time.
 * Kept here as its own copy: fit.c stopping sooner fails this test. */
#define STALL_ITERS 5

typedef struct stall_watch {
    const st_tetmesh *m;
    const st_soup *s;
    const unsigned char *onb;   /* boundary vertices (the fit phase keeps them) */
    double d_offset;
    unsigned char *ever;        /* within d_offset after some fit iteration */
    int iters, last_new;        /* fit iterations seen; the last that added one */
    size_t last_within, last_moved, disagree;
} stall_watch;

/* Every boundary vertex's distance to S by brute force over S's triangles:
 * marks those within d_offset in w->ever; 1 when one was not marked. */
static int stall_mark(stall_watch *w, size_t *within)
{
    int added = 0;
    *within = 0;
    for (size_t v = 0; v < w->m->npoints; v++) {
        if (!w->onb[v])
            continue;
        const double *x = w->m->xyz + 3 * v;
        double d2 = INFINITY;
        for (size_t t = 0; t < w->s->ntris; t++) {
            const uint32_t *c = w->s->tris + 3 * t;
            d2 = fmin(d2, st_point_triangle_dist2(x, w->s->xyz + 3 * (size_t)c[0],
                                                  w->s->xyz + 3 * (size_t)c[1],
                                                  w->s->xyz + 3 * (size_t)c[2], NULL));
        }
        if (sqrt(d2) <= w->d_offset) {
            (*within)++;
            added |= !w->ever[v];
            w->ever[v] = 1;
        }
    }
    return added;
}

/* After each fit iteration: the vertices within d_offset for the first
 * time, and the count within against the fit's own. */
static void stall_iter(void *ctx, const st_fit_iter *it)
{
    stall_watch *w = ctx;
    if (strcmp(it->phase, "fit") != 0)
        return;
    size_t within;
    if (stall_mark(w, &within))
        w->last_new = it->iter;
    w->iters = it->iter;
    w->disagree += within != it->within_offset;
    w->last_within = it->within_offset;
    w->last_moved = it->moved;
}

/* The half sphere without its fill: the lower boundary can never come
 * within d_offset of S, so the fit must end on its stall rule; it may do so
 * only STALL_ITERS iterations after the last that brought a vertex into the
 * band for the first time. */
static void test_stall(void)
{
    st_soup *full = st_soup_new(), *up = st_soup_new(), *down = st_soup_new();
    add_sphere(full, 1.0, 2.0);
    split_z(full, up, down);
    st_tetmesh *m = ball_mesh(0.5, 1.6);
    sm_mesh sm;
    st_error err;
    if (sm_mesh_build(&sm, m, &err)) {
        TAP_CHECK(0, "mesh build: %s", err.msg);
        return;
    }
    stall_watch w = {m, up, sm.onb, 0.4 * 0.5, calloc(m->npoints, 1), 0, 0, 0, 0, 0};
    size_t within0;
    stall_mark(&w, &within0);   /* what is within on entry counts as reached */
    st_fit_params p = watched_params(stall_iter, &w);
    p.quality = 0;
    st_fit_stats st;
    st_status rc = st_fit(m, up, NULL, &p, &st, NULL, &err);
    TAP_CHECK(rc == ST_OK && w.disagree == 0 && w.iters == st.iters,
              "%d fit iterations, the count within d_offset as brute force finds it", w.iters);
    TAP_CHECK(w.last_within < sm.nbv && w.last_moved > 0 && w.iters < p.max_iters,
              "the fit ended on its stall rule: %zu of %zu within, %zu moved in the last "
              "iteration", w.last_within, sm.nbv, w.last_moved);
    TAP_CHECK(w.iters - w.last_new >= STALL_ITERS,
              "it stopped %d iterations after the last that brought a vertex into the band "
              "for the first time (iteration %d), not before %d", w.iters - w.last_new,
              w.last_new, STALL_ITERS);
    free(w.ever);
    sm_mesh_free(&sm);
    st_tetmesh_free(m);
    st_soup_free(full);
    st_soup_free(up);
    st_soup_free(down);
}

/* Corner k of tet t of m, with point v at y. */
static const double *corner_at(const st_tetmesh *m, uint32_t t, int k, uint32_t v,
                               const double y[3])
{
    uint32_t c = m->tets[4 * (size_t)t + (size_t)k];
    return c == v ? y : m->xyz + 3 * (size_t)c;
}

/* 1 when q lies in the closed star of v with v at y (brute force). */
static int brute_in_star(const sm_mesh *sm, uint32_t v, const double y[3], const double q[3])
{
    int in = 0;
    for (size_t j = sm->vt_off[v]; j < sm->vt_off[v + 1] && !in; j++) {
        uint32_t t = sm->vt[j];
        in = st_point_in_tet(q, corner_at(sm->m, t, 0, v, y), corner_at(sm->m, t, 1, v, y),
                             corner_at(sm->m, t, 2, v, y),
                             corner_at(sm->m, t, 3, v, y)) != ST_OUTSIDE;
    }
    return in;
}

/* The S vertex sm_swept_kept's scan names when v's move to p loses one:
 * in bin order (z, then y, then x, as the scan visits them; each bin's
 * points in their order), the first that lies in some closed tet
 * (x, p, a, b) of a boundary face (v, a, b) and leaves the star. Every
 * face is tested at every point, as the scan did before it visited only
 * the faces a bin keeps; UINT32_MAX when none leaves. */
static uint32_t first_swept_leaving(const sm_mesh *sm, const pgrid *g, uint32_t v,
                                    const double p[3])
{
    const double *x = sm->m->xyz + 3 * (size_t)v;
    const size_t nb = g->n[0] * g->n[1] * g->n[2];
    for (size_t b = 0; b < nb; b++)
        for (size_t j = g->off[b]; j < g->off[b + 1]; j++) {
            const double *q = g->bpts + 3 * j;
            int swept = 0;
            for (size_t f = sm->vf_off[v]; f < sm->vf_off[v + 1] && !swept; f++) {
                const uint32_t *k = sm->bf + 3 * (size_t)sm->vf[f];
                const double *ab[2];
                int n = 0;
                for (int i = 0; i < 3; i++)
                    if (k[i] != v)
                        ab[n++] = sm->m->xyz + 3 * (size_t)k[i];
                swept = st_point_in_tet(q, x, p, ab[0], ab[1]) != ST_OUTSIDE;
            }
            if (swept && brute_in_star(sm, v, x, q) && !brute_in_star(sm, v, p, q))
                return g->idx[j];
        }
    return UINT32_MAX;
}

/* sm_swept_kept against every S vertex: a dense cloud of tiny triangles
 * in the shell the boundary stars cover (many points per bin, so whole
 * bins are skipped and kept), moves of every size from a hair to a third
 * of a cell, in and out. The answer must be the brute force's, and a
 * failed point one that leaves. */
static void test_swept(void)
{
    const double h = 0.5;
    st_tetmesh *m = ball_mesh(h, 1.6);
    st_soup *s = st_soup_new();
    uint64_t seed = 12345;
    for (int i = 0; i < 3000; i++) {
        double c[3], a[3], b[3], d[3];
        double r2;
        do {
            for (int k = 0; k < 3; k++) {
                seed = seed * 6364136223846793005ULL + 1442695040888963407ULL;
                c[k] = -1.9 + 3.8 * (double)(seed >> 11) / 9007199254740992.0;
            }
            r2 = c[0] * c[0] + c[1] * c[1] + c[2] * c[2];
        } while (r2 < 0.8 * 0.8 || r2 > 1.75 * 1.75);
        for (int k = 0; k < 3; k++) {
            a[k] = c[k];
            b[k] = c[k] + (k == 0 ? 1e-3 : 0.0);
            d[k] = c[k] + (k == 1 ? 1e-3 : 0.0);
        }
        add_tri(s, a, b, d, 0);
    }
    sm_mesh sm;
    pgrid g;
    st_error err;
    TAP_CHECK(sm_mesh_build(&sm, m, &err) == ST_OK && sm_pgrid_build(&g, s, h / 4.0) == ST_OK,
              "mesh incidence and point grid");
    size_t tried = 0, kept = 0, left = 0, wrong = 0, bad_failed = 0, other_failed = 0;
    static const double scale[] = {1e-6, 1e-3, 0.02, 0.1, 0.35};
    for (uint32_t v = 0; v < sm.nv; v++) {
        const double *x = m->xyz + 3 * (size_t)v;
        if (!sm.onb[v] || !sm_swept_applies(&sm, v) || !sm_star_positive(&sm, v, x))
            continue;
        for (int t = (int)(v % 5); t < (int)(v % 5) + 2; t++) {
            double p[3];
            for (int k = 0; k < 3; k++) {
                seed = seed * 6364136223846793005ULL + 1442695040888963407ULL;
                p[k] = x[k] + scale[t % 5] * h * (2.0 * (double)(seed >> 11) / 9007199254740992.0 - 1.0);
            }
            if (!sm_star_positive(&sm, v, p))
                continue;
            uint32_t failed = UINT32_MAX;
            int r = sm_swept_kept(&sm, &g, v, p, &failed, NULL);
            int leaves_none = 1;
            for (size_t i = 0; i < g.npts && leaves_none; i++) {
                const double *q = g.pts + 3 * i;
                if (brute_in_star(&sm, v, x, q) && !brute_in_star(&sm, v, p, q))
                    leaves_none = 0;
            }
            tried++;
            kept += r == 1;
            left += r == 0;
            wrong += r != leaves_none;
            if (r == 0) {
                const double *q = failed < g.npts ? g.pts + 3 * (size_t)failed : NULL;
                bad_failed += !q || !brute_in_star(&sm, v, x, q) || brute_in_star(&sm, v, p, q);
                other_failed += failed != first_swept_leaving(&sm, &g, v, p);
            }
        }
    }
    TAP_CHECK(tried > 200 && kept > 10 && left > 10,
              "%zu moves of boundary vertices over %zu S vertices: %zu keep, %zu lose a point",
              tried, g.npts, kept, left);
    TAP_CHECK(wrong == 0, "the swept test answers as the brute force every time (%zu differ)",
              wrong);
    TAP_CHECK(bad_failed == 0, "every failed point named is one that leaves (%zu not)", bad_failed);
    TAP_CHECK(other_failed == 0,
              "the point named is the per-point scan's: the first swept point that leaves, in "
              "bin order, every face tested (%zu differ)", other_failed);
    sm_pgrid_free(&g);
    sm_mesh_free(&sm);
    st_tetmesh_free(m);
    st_soup_free(s);
}

/* 1 when boundary face f (an index into vf) of v's star, with v at y,
 * meets S triangle t (closed, exact). */
static int brute_face_meets(const sm_mesh *sm, const st_soup *s, size_t f, uint32_t v,
                            const double y[3], size_t t)
{
    const uint32_t *k = sm->bf + 3 * (size_t)sm->vf[f];
    const double *c[3];
    for (int i = 0; i < 3; i++)
        c[i] = k[i] == v ? y : sm->m->xyz + 3 * (size_t)k[i];
    const uint32_t *w = s->tris + 3 * t;
    return st_tri_tri_intersect(c[0], c[1], c[2], s->xyz + 3 * (size_t)w[0],
                                s->xyz + 3 * (size_t)w[1], s->xyz + 3 * (size_t)w[2]);
}

/* The move invariant by brute force (invariant.c's header): v's star
 * positive at p, every S vertex of the closed star at x in the closed star
 * at p, and no boundary face of the star newly meeting an S triangle; every
 * point and triangle tested. *faces_only: only the last part fails. */
static int brute_move_ok(const sm_mesh *sm, const st_soup *s, uint32_t v, const double p[3],
                         int *faces_only)
{
    const double *x = sm->m->xyz + 3 * (size_t)v;
    *faces_only = 0;
    if (!sm_star_positive(sm, v, p))
        return 0;
    for (size_t i = 0; i < s->nverts; i++)
        if (brute_in_star(sm, v, x, s->xyz + 3 * i) && !brute_in_star(sm, v, p, s->xyz + 3 * i))
            return 0;
    for (size_t f = sm->vf_off[v]; f < sm->vf_off[v + 1]; f++)
        for (size_t t = 0; t < s->ntris; t++)
            if (brute_face_meets(sm, s, f, v, p, t) && !brute_face_meets(sm, s, f, v, x, t)) {
                *faces_only = 1;
                return 0;
            }
    return 1;
}

/* sm_move_ok against brute_move_ok: triangles a fifth to a half of a cell
 * across in the shell the boundary crosses (some meeting it already), so
 * that boundary faces sweep into them; each boundary vertex tried at four
 * positions in a row, a fiftieth to 0.4 of a cell away, as the fit tries
 * its halvings (the blockers on). The answers must be the brute force's,
 * and the face test must be what refuses many of the moves. */
static void test_move_brute(void)
{
    const double h = 0.5;
    st_tetmesh *m = ball_mesh(h, 1.6);
    st_soup *s = st_soup_new();
    uint64_t seed = 4242;
    double u[12];
    for (int i = 0; i < 500; i++) {
        double c[3], r2, e[3][3];
        do {
            for (int k = 0; k < 12; k++) {
                seed = seed * 6364136223846793005ULL + 1442695040888963407ULL;
                u[k] = (double)(seed >> 11) / 9007199254740992.0;
            }
            for (int k = 0; k < 3; k++)
                c[k] = -2.0 + 4.0 * u[k];
            r2 = c[0] * c[0] + c[1] * c[1] + c[2] * c[2];
        } while (r2 < 1.5 * 1.5 || r2 > 2.1 * 2.1);
        const double size = h * (0.2 + 0.3 * u[3]);
        for (int j = 0; j < 3; j++)
            for (int k = 0; k < 3; k++)
                e[j][k] = c[k] + size * (u[3 + 3 * j + k] - 0.5);
        add_tri(s, e[0], e[1], e[2], 0);
    }
    fit_ctx c;
    st_error err;
    TAP_CHECK(sm_fit_ctx_open(&c, m, s, NULL, NULL, NULL, h, 0.4 * h, NULL, &err) == ST_OK,
              "the invariant's context over %zu triangles", s->ntris);
    static const double scale[] = {0.02, 0.1, 0.25, 0.4};
    size_t tried = 0, ok = 0, faces = 0, wrong = 0;
    star_pts sp = STAR_PTS_INIT;
    for (uint32_t v = 0; v < c.sm.nv; v += 2) {
        if (!c.sm.onb[v])
            continue;
        const double *x = m->xyz + 3 * (size_t)v;
        sm_star_pts_collect(&c, v, &sp);
        for (int t = 0; t < 4; t++) {
            double p[3];
            for (int k = 0; k < 3; k++) {
                seed = seed * 6364136223846793005ULL + 1442695040888963407ULL;
                p[k] = x[k] + scale[t] * h * (2.0 * (double)(seed >> 11) / 9007199254740992.0 - 1.0);
            }
            int faces_only;
            int want = brute_move_ok(&c.sm, s, v, p, &faces_only);
            tried++;
            ok += want;
            faces += faces_only;
            wrong += sm_move_ok(&c, v, p, &sp) != want;
        }
    }
    TAP_CHECK(tried > 300 && ok > 30 && faces > 30,
              "%zu moves of boundary vertices: %zu keep the invariant, %zu refused by the "
              "face test alone", tried, ok, faces);
    TAP_CHECK(wrong == 0, "sm_move_ok answers as the brute force every time (%zu differ)", wrong);
    free(sp.list);
    sm_fit_ctx_close(&c);
    st_tetmesh_free(m);
    st_soup_free(s);
}

/* The side test (invariant.c, sides_clear) must not clear a face that a
 * triangle newly meets with no S vertex in the swept tet: one boundary
 * face F = (x, a, b) of a vertex v, v moved to p a twentieth of a cell
 * along F's normal (tilted a little), and one long triangle T through the middle of the
 * swept tet K = (x, p, a, b), parallel to F below its plane's lift (two
 * corners 2 h away on either side) and up through F' = (p, a, b) (the
 * third 2 h above): T meets F' and not F, and none of its corners is in K,
 * so the swept test finds K empty. sm_move_ok must refuse as the brute
 * force does (the face walks decide after the sides meet T). */
static void test_sides(void)
{
    const double h = 0.5;
    st_tetmesh *m = ball_mesh(h, 1.6);
    sm_mesh sm;
    st_error err;
    TAP_CHECK(sm_mesh_build(&sm, m, &err) == ST_OK, "the ball's incidence");
    size_t tried = 0, empty_refused = 0, wrong = 0;
    for (uint32_t v = 0; v < sm.nv && tried < 40; v += 7) {
        if (!sm.onb[v] || !sm_swept_applies(&sm, v))
            continue;
        const double *x = m->xyz + 3 * (size_t)v;
        const uint32_t *k = sm.bf + 3 * (size_t)sm.vf[sm.vf_off[v]];
        const double *c0 = m->xyz + 3 * (size_t)k[0], *c1 = m->xyz + 3 * (size_t)k[1],
                     *c2 = m->xyz + 3 * (size_t)k[2];
        const double *ab[2];
        for (int i = 0, n = 0; i < 3; i++)
            if (k[i] != v)
                ab[n++] = m->xyz + 3 * (size_t)k[i];
        double e1[3], e2[3], nrm[3], p[3], w[3], u[3], t[3][3];
        /* off F's normal a little: no other face of the star keeps p in
         * its plane (a flat swept tet: the faces decide alone) */
        const double tilt[3] = {0.11, -0.07, 0.05};
        for (int a = 0; a < 3; a++) {
            e1[a] = c1[a] - c0[a];
            e2[a] = c2[a] - c0[a];
        }
        nrm[0] = e1[1] * e2[2] - e1[2] * e2[1];
        nrm[1] = e1[2] * e2[0] - e1[0] * e2[2];
        nrm[2] = e1[0] * e2[1] - e1[1] * e2[0];
        double ln = sqrt(nrm[0] * nrm[0] + nrm[1] * nrm[1] + nrm[2] * nrm[2]), lu = 0.0;
        for (int a = 0; a < 3; a++) {
            nrm[a] /= ln;
            p[a] = x[a] + 0.05 * h * (nrm[a] + tilt[a]);
            w[a] = 0.25 * (x[a] + p[a] + ab[0][a] + ab[1][a]);
            u[a] = ab[0][a] - ab[1][a];
            lu += u[a] * u[a];
        }
        for (int a = 0; a < 3; a++) {
            u[a] /= sqrt(lu);
            t[0][a] = w[a] - 2.0 * h * u[a];
            t[1][a] = w[a] + 2.0 * h * u[a];
            t[2][a] = w[a] + 2.0 * h * nrm[a];
        }
        if (!sm_star_positive(&sm, v, x) || !sm_star_positive(&sm, v, p))
            continue;
        st_soup *s = st_soup_new();
        add_tri(s, t[0], t[1], t[2], 0);
        fit_ctx c;
        if (sm_fit_ctx_open(&c, m, s, NULL, NULL, NULL, h, 0.4 * h, NULL, &err) != ST_OK) {
            sm_fit_ctx_close(&c);
            st_soup_free(s);
            continue;
        }
        uint32_t failed;
        int empty = 0;
        int kept = sm_swept_kept(&c.sm, c.pg, v, p, &failed, &empty);
        int faces_only;
        int want = brute_move_ok(&c.sm, s, v, p, &faces_only);
        star_pts sp = STAR_PTS_INIT;
        sm_star_pts_collect(&c, v, &sp);
        int got = sm_move_ok(&c, v, p, &sp);
        tried++;
        empty_refused += kept == 1 && empty && !want && faces_only;
        wrong += got != want;
        free(sp.list);
        sm_fit_ctx_close(&c);
        st_soup_free(s);
    }
    TAP_CHECK(tried >= 20 && empty_refused * 2 >= tried,
              "%zu moves, %zu with no S vertex in a swept tet refused by a face alone", tried,
              empty_refused);
    TAP_CHECK(wrong == 0, "sm_move_ok answers as the brute force every time (%zu differ)", wrong);
    sm_mesh_free(&sm);
    st_tetmesh_free(m);
}

int main(int argc, char **argv)
{
    static const tap_test tests[] = {TAP_TEST(sphere), TAP_TEST(threads), TAP_TEST(threads_small),
                                     TAP_TEST(par_gate),
                                     TAP_TEST(quality_reports),
                                     TAP_TEST(not_enclosing), TAP_TEST(refusals),
                                     TAP_TEST(bvh_query_tri), TAP_TEST(bvh_query_tet),
                                     TAP_TEST(bvh_query_flat_tet), TAP_TEST(bvh_nearest_framed),
                                     TAP_TEST(band_edge), TAP_TEST(peel), TAP_TEST(fill), TAP_TEST(shared),
                                     TAP_TEST(stall),
                                     TAP_TEST(swept), TAP_TEST(move_brute),
                                     TAP_TEST(sides), {0}};
    return tap_main(argc, argv, tests);
}
