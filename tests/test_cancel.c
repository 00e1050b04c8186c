/*
 * test_cancel.c - a long call stops when its caller sets the cancel flag
 * (progress.h): the distance field, the signs, the fit, the candidates
 * and the pseudo volume each return ST_ECANCELLED with nothing made, the
 * flag set before the call stops it at once, and the next call (flag
 * cleared) gives the mesh an uncancelled run gives. The flag is set from
 * the progress callback at the first report of a stage, so the point of
 * the stop is deterministic; the time from the flag to the return is
 * printed (the target is about 0.1 s of work) and must stay under a
 * second, a bound no working stop comes near.
 */
#include "souptet/pipeline.h"
#include "souptet/pseudo.h"
#include "souptet/sculpt.h"
#include "tap.h"

#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

typedef struct stopper {
    const char *stage;   /* cancel at this stage's first report */
    double from;         /* ... at or past this fraction */
    volatile int flag;
    double t_set;
    int reports_after;   /* reports that came after the flag was set */
} stopper;

static void on_progress(void *ctx, const char *stage, double fraction)
{
    stopper *k = ctx;
    if (k->flag) {
        k->reports_after++;
        return;
    }
    if (strcmp(stage, k->stage) == 0 && fraction >= k->from) {
        k->t_set = now();
        st_progress_cancel(&k->flag);
    }
}

/* Run the pipeline with a stop at stage, once its fraction reaches from;
 * check and report. */
static void cancel_at(const st_soup *s, const char *stage, double from, size_t tries)
{
    st_pipeline_params p = st_pipeline_params_default();
    p.cells = 16;
    p.tries = tries;
    stopper k = {stage, from, 0, 0, 0};
    st_progress prog = {on_progress, &k, &k.flag};
    st_tetmesh *m = NULL;
    st_pipeline_stats st;
    st_error err;
    st_error_clear(&err);
    st_status rc = st_pipeline_run(&m, &st, s, &p, &prog, &err);
    double latency = now() - k.t_set;
    TAP_CHECK(k.flag, "%s %.2f (tries %zu): the stage was reached and the flag set", stage,
              from, tries);
    TAP_CHECK(rc == ST_ECANCELLED && m == NULL && strcmp(err.msg, "cancelled") == 0,
              "%s %.2f (tries %zu): ST_ECANCELLED, no mesh (%s: %s)", stage, from, tries,
              st_status_name(rc), err.msg);
    TAP_NOTE("%s %.2f (tries %zu): returned %.3f s after the flag", stage, from, tries,
             latency);
    TAP_CHECK(latency < 1.0, "%s %.2f (tries %zu): stopped within a second of the flag (%.3f s)",
              stage, from, tries, latency);
    free(st.candidates);
    st_tetmesh_free(m);
}

/* The bunny with a tenth of its triangles gone, read once by main. */
static st_soup *g_bunny;

/* The flag set before the call. */
static void test_flag_before(void)
{
    st_error err;
    st_pipeline_params p = st_pipeline_params_default();
    volatile int flag = 1;
    st_progress prog = {NULL, NULL, &flag};
    st_tetmesh *m = NULL;
    st_pipeline_stats st;
    double t0 = now();
    st_status rc = st_pipeline_run(&m, &st, g_bunny, &p, &prog, &err);
    TAP_CHECK(rc == ST_ECANCELLED && m == NULL, "a flag set before the call: cancelled "
              "(%.3f s)", now() - t0);
    free(st.candidates);
}

/* The pipeline stopped at each stage. */
static void test_stages(void)
{
    cancel_at(g_bunny, "distance band", 0, 1);
    cancel_at(g_bunny, "signs", 0, 1);
    /* a candidate's line (pipeline.c): past 0.1 it is in the fit, from
     * 0.6 in the quality pass; a batch of several, a third of the way */
    cancel_at(g_bunny, "candidate", 0.11, 1);
    cancel_at(g_bunny, "candidate", 0.6, 1);
    cancel_at(g_bunny, "candidates 1-2 of 3", 0.33, 3);
}

/* The pseudo volume alone. */
static void test_pseudo_volume(void)
{
    st_error err;
    st_dist_params dp = st_dist_params_default();
    dp.cells = 256;
    st_pseudo_params pp = st_pseudo_params_default();
    stopper k = {"signs", 0, 0, 0, 0};
    st_progress prog = {on_progress, &k, &k.flag};
    st_grid *g = NULL;
    st_status rc = st_pseudo_volume(&g, g_bunny, &dp, &pp, NULL, &prog, &err);
    TAP_CHECK(rc == ST_ECANCELLED && g == NULL, "the pseudo volume: cancelled in the "
              "signs, no grid (%.3f s after the flag)", now() - k.t_set);
}

/* The next call, flag cleared, is an ordinary run. */
static void test_cleared_flag(void)
{
    st_error err;
    st_pipeline_params p = st_pipeline_params_default();
    p.cells = 6;
    volatile int flag = 0;
    st_progress prog = {NULL, NULL, &flag};
    st_tetmesh *m1 = NULL, *m2 = NULL;
    st_status r1 = st_pipeline_run(&m1, NULL, g_bunny, &p, &prog, &err);
    st_status r2 = st_pipeline_run(&m2, NULL, g_bunny, &p, NULL, &err);
    TAP_CHECK(r1 == ST_OK && r2 == ST_OK && m1 && m2 && m1->npoints == m2->npoints &&
              m1->ntets == m2->ntets &&
              memcmp(m1->xyz, m2->xyz, 3 * m1->npoints * sizeof *m1->xyz) == 0 &&
              memcmp(m1->tets, m2->tets, 4 * m1->ntets * sizeof *m1->tets) == 0,
              "an unset flag changes nothing: the same mesh as without one");
    st_tetmesh_free(m1);
    st_tetmesh_free(m2);
}

/* The sculpt alone, the flag set: nothing classified, no mesh. */
static void test_sculpt(void)
{
    st_error err;
    st_dist_params dp = st_dist_params_default();
    st_pseudo_params pp = st_pseudo_params_default();
    st_grid *g = NULL;
    st_status rc = st_pseudo_volume(&g, g_bunny, &dp, &pp, NULL, NULL, &err);
    st_sculpt_params sp = st_sculpt_params_default();
    double lo[3], hi[3];
    st_soup_bounds(g_bunny, lo, hi, &err);
    sp.h = (hi[0] - lo[0]) / 30;
    volatile int flag = 1;
    sp.cancel = &flag;
    st_tetmesh *m = NULL;
    double t0 = now();
    st_status r2 = rc ? rc : st_sculpt(&m, NULL, g, g_bunny, NULL, &sp, &err);
    TAP_CHECK(rc == ST_OK && r2 == ST_ECANCELLED && m == NULL,
              "the sculpt at 30 cells, flag set: ST_ECANCELLED, no mesh (%.3f s)", now() - t0);
    st_grid_free(g);
}

int main(int argc, char **argv)
{
    static const tap_test tests[] = {TAP_TEST(flag_before), TAP_TEST(stages),
                                     TAP_TEST(pseudo_volume), TAP_TEST(sculpt), TAP_TEST(cleared_flag),
                                     {0}};
    tap_select(argc, argv, tests);
    st_error err;
    if (st_soup_read(&g_bunny, tap_path("corpus/bunny.obj"), &err) != ST_OK) {
        TAP_CHECK(0, "read corpus/bunny.obj: %s", err.msg);
        return tap_done();
    }
    /* a tenth of the triangles gone: holes, so the signs are voted (a
     * closed soup's are its shells' alone, with no vote to stop) */
    g_bunny->ntris -= g_bunny->ntris / 10;
    omp_set_num_threads(2);
    tap_run(tests);
    st_soup_free(g_bunny);
    return tap_done();
}
