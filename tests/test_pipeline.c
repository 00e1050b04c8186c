/*
 * test_pipeline.c - the whole job in one call (pipeline.h) on a small
 * sphere: the mesh encloses it, the candidates' seeds and the winner's
 * order, the result does not depend on the thread count or on the events
 * being reported, the events come as documented, the candidates' threads
 * (a batch's share them; a single one is not nested), dry runs and bad
 * parameters.
 */
#include "souptet/lattice.h"
#include "souptet/pipeline.h"
#include "shapes.h"
#include "tap.h"

#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct counts {
    size_t field, size, sculpted, iteration, candidate;
    size_t last_k;
    int bad;
} counts;

static void on_event(void *ctx, const st_pipeline_event *ev)
{
    counts *c = ctx;
    if (strcmp(ev->what, "field") == 0)
        c->field++, c->bad |= !(ev->field_dims[0] > 0 && ev->voxel > 0);
    else if (strcmp(ev->what, "size") == 0)
        c->size++, c->bad |= !(ev->h > 0);
    else if (strcmp(ev->what, "sculpted") == 0)
        c->sculpted++, c->bad |= !(ev->tets > 0 && ev->h > 0);
    else if (strcmp(ev->what, "iteration") == 0)
        c->iteration++, c->bad |= !(ev->fit && ev->fit->iter >= 1);
    else if (strcmp(ev->what, "candidate") == 0)
        c->candidate++, c->bad |= !(ev->candidate && ev->candidate->seed != 0);
    else
        c->bad = 1;
}

static int same_mesh(const st_tetmesh *a, const st_tetmesh *b)
{
    return a && b && a->npoints == b->npoints && a->ntets == b->ntets &&
           memcmp(a->xyz, b->xyz, 3 * a->npoints * sizeof *a->xyz) == 0 &&
           memcmp(a->tets, b->tets, 4 * a->ntets * sizeof *a->tets) == 0;
}

/* The unit UV sphere (closed, half its triangles flipped), meshed with
 * 4 cells in a field of 40 voxels. */
static st_soup *sphere_soup(void)
{
    st_soup *s = st_soup_new();
    add_sphere(s, 1.0, 2.0);
    return s;
}

static st_pipeline_params sphere_params(void)
{
    st_pipeline_params p = st_pipeline_params_default();
    p.cells = 4;
    p.field_cells = 40;
    p.tries = 3;
    p.try_all = 1;
    return p;
}

static void test_candidate_seed(void)
{
    TAP_CHECK(st_pipeline_candidate_seed(7, 0) == 7, "candidate 0 takes the seed itself");
    TAP_CHECK(st_pipeline_candidate_seed(0, 1) != 0 && st_pipeline_candidate_seed(7, 1) !=
              st_pipeline_candidate_seed(7, 2), "later candidates: random, distinct, never 0");
}

/* 2 threads with events: the mesh m1 made on 1 thread without them. */
static void check_events(const st_soup *s, st_pipeline_params p, const st_tetmesh *m1)
{
    st_error err;
    st_tetmesh *m2 = NULL;
    st_pipeline_stats st2;
    counts c;
    memset(&c, 0, sizeof c);
    p.on_event = on_event;
    p.on_event_ctx = &c;
    omp_set_num_threads(2);
    st_status r2 = st_pipeline_run(&m2, &st2, s, &p, NULL, &err);
    TAP_CHECK(r2 == ST_OK && same_mesh(m1, m2),
              "2 threads and events reported: the same mesh as 1 thread without");
    TAP_CHECK(c.field == 1 && c.sculpted == 3 && c.candidate == 3 && c.size == 0,
              "events: the field once, each candidate sculpted and done (%zu %zu %zu)",
              c.field, c.sculpted, c.candidate);
    TAP_CHECK(c.iteration >= 3 && !c.bad, "events: the fit's iterations, well formed (%zu)",
              c.iteration);
    free(st2.candidates);
    st_tetmesh_free(m2);
}

/* Without try_all: the first batch (ST_PIPELINE_BATCH) runs, and the
 * rest only when none of it meets every goal; the same for any thread
 * count, and the winner is the best of those that ran (st1: try_all). */
static void check_without_try_all(const st_soup *s, st_pipeline_params p,
                                  const st_pipeline_stats *st1)
{
    st_error err;
    p.try_all = 0;
    size_t goal_k = SIZE_MAX;
    for (size_t k = 0; k < ST_PIPELINE_BATCH && k < st1->ncandidates; k++) {
        const st_pipeline_candidate *q = &st1->candidates[k];
        if (!q->failed && !q->verts_outside && !q->tris_crossing && q->converged &&
            q->min_dihedral >= 35.0 && q->max_dihedral <= 133.0)
            goal_k = k;
    }
    size_t want = goal_k != SIZE_MAX ? ST_PIPELINE_BATCH : 3;
    st_tetmesh *m3 = NULL, *m4 = NULL;
    st_pipeline_stats st3, st4;
    omp_set_num_threads(1);
    st_status r3 = st_pipeline_run(&m3, &st3, s, &p, NULL, &err);
    omp_set_num_threads(2);
    st_status r4 = st_pipeline_run(&m4, &st4, s, &p, NULL, &err);
    TAP_CHECK(r3 == ST_OK && r4 == ST_OK && st3.ncandidates == want &&
              st4.ncandidates == want && st3.goal_met == (goal_k != SIZE_MAX) &&
              same_mesh(m3, m4),
              "without try_all: %zu of 3 candidates ran (goal met by %zu), "
              "the same for 1 and 2 threads", st3.ncandidates, goal_k);
    size_t b = 0;
    for (size_t k = 1; k < want; k++) {
        const st_pipeline_candidate *x = &st1->candidates[k], *y = &st1->candidates[b];
        if (x->min_dihedral > y->min_dihedral ||
            (x->min_dihedral == y->min_dihedral && x->max_dihedral < y->max_dihedral))
            b = k;
    }
    TAP_CHECK(r3 == ST_OK && st3.best == b &&
              st3.candidates[b].min_dihedral == st1->candidates[b].min_dihedral,
              "without try_all: the best of those that ran (%zu), as with try_all", b);
    free(st3.candidates);
    free(st4.candidates);
    st_tetmesh_free(m3);
    st_tetmesh_free(m4);
}

/* Three candidates on 1 thread: the mesh, the winner, the meta; then the
 * same with 2 threads and events, and without try_all. */
static void test_candidates(void)
{
    st_soup *s = sphere_soup();
    st_pipeline_params p = sphere_params();
    st_error err;
    st_tetmesh *m1 = NULL;
    st_pipeline_stats st1;
    omp_set_num_threads(1);
    st_status r1 = st_pipeline_run(&m1, &st1, s, &p, NULL, &err);
    TAP_CHECK(r1 == ST_OK && m1 && m1->ntets > 0, "the sphere meshes (%zu tets)",
              m1 ? m1->ntets : 0);
    TAP_CHECK(st1.encloses && st1.candidates[st1.best].verts_outside == 0 &&
              st1.candidates[st1.best].tris_crossing == 0, "the mesh encloses the soup");
    TAP_CHECK(st1.ncandidates == 3 && st1.candidates[0].seed == p.seed,
              "three candidates, the first with the seed");
    int best_ok = 1;
    for (size_t k = 0; k < st1.ncandidates; k++) {
        const st_pipeline_candidate *c = &st1.candidates[k], *b = &st1.candidates[st1.best];
        int ce = c->verts_outside == 0 && c->tris_crossing == 0;
        if (ce && !c->failed && k != st1.best)
            best_ok &= b->min_dihedral > c->min_dihedral ||
                       (b->min_dihedral == c->min_dihedral && (b->max_dihedral < c->max_dihedral ||
                        (b->max_dihedral == c->max_dihedral && st1.best < k)));
    }
    TAP_CHECK(best_ok, "the best has the largest minimum angle among the enclosing (%zu)", st1.best);
    TAP_CHECK(m1 && st_meta_get(&m1->meta, "h") && st_meta_get(&m1->meta, "encloses") &&
              strcmp(st_meta_get(&m1->meta, "candidates"), "3") == 0,
              "meta: h, encloses, candidates");

    check_events(s, p, m1);
    check_without_try_all(s, p, &st1);
    free(st1.candidates);
    st_tetmesh_free(m1);
    st_soup_free(s);
}

/* A dry run: h and the sculpted count, no mesh. */
static void test_dry_run(void)
{
    counts c;
    memset(&c, 0, sizeof c);
    st_pipeline_params p = sphere_params();
    st_soup *s = sphere_soup();
    st_tetmesh *m2 = NULL;
    st_pipeline_stats st2;
    st_error err;
    p.on_event = on_event;
    p.on_event_ctx = &c;
    p.try_all = 0;
    p.dry_run = 1;
    p.tries = 1;
    st_status r3 = st_pipeline_run(&m2, &st2, s, &p, NULL, &err);
    TAP_CHECK(r3 == ST_OK && m2 == NULL && st2.estimated_tets > 0 && st2.h > 0,
              "dry run: no mesh, h %g and %zu tets estimated", st2.h, st2.estimated_tets);
    TAP_CHECK(c.size == 1 && c.sculpted == 0, "dry run: one sizing sculpt, no candidate");
    free(st2.candidates);
    st_soup_free(s);
}

/* float32: the same candidate, its points rounded to floats, still
 * enclosing; the stats and meta say so. The sphere moved off the
 * float grid (centre 20 + 1e-9) so every point has to move. */
static void test_float32(void)
{
    st_pipeline_params p = sphere_params();
    p.try_all = 0;
    st_error err;
    st_soup *f = st_soup_new();
    add_sphere(f, 1.0, 2.0);
    for (size_t i = 0; i < f->nverts; i++)
        for (int a = 0; a < 3; a++)
            f->xyz[3 * i + (size_t)a] += 20.0 + 1e-9 * (a + 1);
    st_tetmesh *md = NULL, *mf = NULL;
    st_pipeline_stats sd, sf;
    p.tries = 1;
    st_status rd = st_pipeline_run(&md, &sd, f, &p, NULL, &err);
    p.float32 = 1;
    st_status rf = st_pipeline_run(&mf, &sf, f, &p, NULL, &err);
    p.float32 = 0;
    TAP_CHECK(rd == ST_OK && rf == ST_OK && md && mf && md->ntets == mf->ntets &&
              memcmp(md->tets, mf->tets, 4 * md->ntets * sizeof *md->tets) == 0,
              "float32: the same tets as without");
    TAP_CHECK(mf && st_points_are_float32(mf->xyz, mf->npoints) &&
              md && !st_points_are_float32(md->xyz, md->npoints),
              "float32: every coordinate a float (without: not)");
    size_t out = 9, cross = 9;
    if (mf)
        st_enclosure_count(mf, f, NULL, &out, &cross, &err);
    TAP_CHECK(sf.encloses && sf.float32.encloses && out == 0 && cross == 0 &&
              sf.float32.rounds >= 1 && sf.float32.points_moved == mf->npoints &&
              sf.candidates[sf.best].verts_outside == 0,
              "float32: encloses, counted again on the result (%d checks, %zu moved, "
              "farthest %.3g)", sf.float32.rounds, sf.float32.points_moved,
              sf.float32.max_move);
    const char *yes = mf ? st_meta_get(&mf->meta, "float32") : NULL;
    TAP_CHECK(yes && strcmp(yes, "yes") == 0 && md && !st_meta_get(&md->meta, "float32") &&
              sd.float32.rounds == 0,
              "float32: meta float32 yes; without it, no meta and no rounding");
    free(sd.candidates);
    free(sf.candidates);
    st_tetmesh_free(md);
    st_tetmesh_free(mf);
    st_soup_free(f);
}

static void test_refusals(void)
{
    st_pipeline_params p = sphere_params();
    p.tries = 0;
    st_soup *s = sphere_soup();
    st_tetmesh *m2 = NULL;
    st_error err;
    TAP_CHECK(st_pipeline_run(&m2, NULL, s, &p, NULL, &err) == ST_EINPUT && !m2,
              "tries 0: refused");
    p.tries = 1;
    p.offset_ratio = 0;
    TAP_CHECK(st_pipeline_run(&m2, NULL, s, &p, NULL, &err) == ST_EINPUT,
              "offset 0: refused");
    st_soup_free(s);
}

/* The lattice bound: the sphere's box has diagonal 2 sqrt(3); at
 * h 0.5, floor(6.93) + 3 + 2 * 2 = 13 cells an axis, 12 tets a cell. */
static void test_lattice_bound(void)
{
    st_soup *s = sphere_soup();
    st_pipeline_params p = sphere_params();
    double tets, at_once;
    double bytes = st_pipeline_lattice_bytes(s, 0.5, 1, &tets, &at_once);
    TAP_CHECK(tets == 12.0 * 13 * 13 * 13 && at_once == 1 &&
              bytes == tets * ST_LATTICE_BYTES_PER_TET,
              "lattice bound at h 0.5: %.0f tets, %.0f at once, %.0f bytes", tets, at_once, bytes);
    omp_set_num_threads(2);
    st_pipeline_lattice_bytes(s, 0.5, 8, NULL, &at_once);
    TAP_CHECK(at_once == 2, "8 tries on 2 threads: 2 lattices at once");
    TAP_CHECK(st_pipeline_lattice_bytes(s, 0, 1, &tets, NULL) == 0 && tets == 0,
              "no bound for a width of 0");
    p.cells = 4;
    TAP_CHECK(st_pipeline_cell_width(s, &p) == 0.5, "4 cells over a box of side 2: h 0.5 (%g)",
              st_pipeline_cell_width(s, &p));
    st_soup_free(s);
}

/* What the candidates' events saw of their threads: per "iteration" and
 * "candidate" event, in order, its candidate and the thread's OpenMP
 * settings (the event comes from the candidate's thread). */
typedef struct thread_log {
    size_t n;
    struct {
        size_t k;
        int done, threads, level;
    } e[8192];
} thread_log;

static void on_thread_event(void *ctx, const st_pipeline_event *ev)
{
    thread_log *l = ctx;
    int done = strcmp(ev->what, "candidate") == 0;
    if (l->n < sizeof l->e / sizeof l->e[0] && (done || strcmp(ev->what, "iteration") == 0)) {
        l->e[l->n].k = ev->k;
        l->e[l->n].done = done;
        l->e[l->n].threads = omp_get_max_threads();
        l->e[l->n].level = omp_get_level();
        l->n++;
    }
}

/* The candidates' threads (run_candidates): one candidate on 2 threads
 * has both for its loops, not nested in a region of its own (a nested
 * region starts new threads each time); two at once have one each, and
 * once one is done the other takes both, from its next report on; the
 * mesh is the one thread's. */
static void test_threads(void)
{
    st_soup *s = sphere_soup();
    st_pipeline_params p = sphere_params();
    static thread_log l;
    st_error err;
    p.on_event = on_thread_event;
    p.on_event_ctx = &l;
    p.tries = 1;
    omp_set_num_threads(2);
    l.n = 0;
    st_tetmesh *m = NULL;
    st_status r = st_pipeline_run(&m, NULL, s, &p, NULL, &err);
    int ok = r == ST_OK && l.n > 1;
    for (size_t i = 0; i < l.n; i++)
        ok &= l.e[i].threads == 2 && l.e[i].level == 0;
    TAP_CHECK(ok, "one candidate, 2 threads: both for its loops, at level 0 (%zu events; "
              "the first: %d threads, level %d)", l.n, l.n ? l.e[0].threads : 0,
              l.n ? l.e[0].level : 0);
    st_tetmesh_free(m);

    p.tries = 2;
    omp_set_num_threads(1);
    st_tetmesh *m1 = NULL;
    st_status r1 = st_pipeline_run(&m1, NULL, s, &p, NULL, &err);
    omp_set_num_threads(2);
    l.n = 0;
    r = st_pipeline_run(&m, NULL, s, &p, NULL, &err);
    size_t first_done = l.n, after = 0;
    int shared = 1, taken = 1;
    for (size_t i = 0; i < l.n; i++) {
        if (l.e[i].done && first_done == l.n)
            first_done = i;
        else if (i < first_done)
            shared &= l.e[i].threads == 1 && l.e[i].level == 0;
        else if (!l.e[i].done && l.e[i - 1].k == l.e[i].k && !l.e[i - 1].done &&
                 i - 1 > first_done)
            taken &= l.e[i].threads == 2, after++;
    }
    TAP_CHECK(r == ST_OK && r1 == ST_OK && first_done < l.n && first_done > 0 && shared,
              "two candidates, 2 threads: one each until one is done (%zu events before)",
              first_done);
    TAP_CHECK(taken, "then the other takes both (%zu of its events checked)", after);
    TAP_CHECK(same_mesh(m1, m), "the same mesh as on 1 thread");
    omp_set_num_threads(1);
    st_tetmesh_free(m1);
    st_tetmesh_free(m);
    st_soup_free(s);
}

/* The field's default resolution (pipeline.c field_voxels, soupmesh -r):
 * 16 voxels per lattice cell up to 128, 8 per cell beyond. A dry run at
 * each cell count makes the field of the explicit -r the rule gives. */
static void test_field_rule(void)
{
    static const size_t cells[] = {4, 7, 10, 20}, voxels[] = {64, 112, 128, 160};
    st_soup *s = sphere_soup();
    for (size_t i = 0; i < sizeof cells / sizeof *cells; i++) {
        size_t dims[2][3] = {{0}};
        int ok = 1;
        for (int k = 0; k < 2; k++) {
            st_pipeline_params p = sphere_params();
            st_tetmesh *m = NULL;
            st_pipeline_stats st;
            st_error err;
            p.cells = cells[i];
            p.field_cells = k ? voxels[i] : 0;
            p.tries = 1;
            p.try_all = 0;
            p.dry_run = 1;
            ok &= st_pipeline_run(&m, &st, s, &p, NULL, &err) == ST_OK;
            memcpy(dims[k], st.field_dims, sizeof dims[k]);
            free(st.candidates);
        }
        TAP_CHECK(ok && memcmp(dims[0], dims[1], sizeof dims[0]) == 0,
                  "%zu cells: the default field is -r %zu's (%zux%zux%zu, %zux%zux%zu)", cells[i],
                  voxels[i], dims[0][0], dims[0][1], dims[0][2], dims[1][0], dims[1][1], dims[1][2]);
    }
    st_soup_free(s);
}

static void test_empty_soup(void)
{
    st_pipeline_params p = sphere_params();
    st_error err;
    st_tetmesh *m2 = NULL;
    p.tries = 1;
    p.offset_ratio = 0.4;
    st_soup *empty = st_soup_new();
    TAP_CHECK(st_pipeline_run(&m2, NULL, empty, &p, NULL, &err) == ST_EINPUT,
              "an empty soup: refused (%s)", err.msg);
    st_soup_free(empty);
}

int main(int argc, char **argv)
{
    static const tap_test tests[] = {TAP_TEST(candidate_seed), TAP_TEST(candidates),
                                     TAP_TEST(dry_run), TAP_TEST(float32), TAP_TEST(refusals),
                                     TAP_TEST(lattice_bound), TAP_TEST(threads),
                                     TAP_TEST(field_rule), TAP_TEST(empty_soup), {0}};
    return tap_main(argc, argv, tests);
}
