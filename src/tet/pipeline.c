/*
 * pipeline.c - distance, signs, candidates, the best one (see pipeline.h).
 */
#include "souptet/pipeline.h"
#include "../base/fpenv.h"

#include "souptet/bvh.h"
#include "souptet/pseudo.h"
#include "souptet/dist.h"
#include "souptet/enclose.h"
#include "souptet/grid.h"
#include "souptet/lattice.h"
#include "souptet/mem.h"
#include "souptet/sculpt.h"
#include "souptet/smooth.h"
#include "souptet/tetqual.h"

#include <errno.h>
#include <math.h>
#include <omp.h>
#include <pthread.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

st_pipeline_params st_pipeline_params_default(void)
{
    st_pipeline_params p;
    memset(&p, 0, sizeof p);
    p.cells = 10;
    p.field_cells = 0;
    p.offset_ratio = 0.4;
    p.tries = 1;
    p.seed = 1;
    p.quality = 1;
    p.fit_max_iters = 0;
    p.density_rho = 0.0;
    p.max_bytes = 0;
    p.fill_holes = 1;
    p.closed_shells = 1;
    p.symmetry = 1;
    p.fill_counts = 1;
    p.float32 = 0;
    return p;
}

double st_pipeline_cell_width(const st_soup *s, const st_pipeline_params *p)
{
    double lo[3], hi[3];
    st_error e;
    if (st_soup_bounds(s, lo, hi, &e))
        return 0;
    return p->h > 0 ? p->h : st_lattice_h_for_cells(lo, hi, p->cells);
}

/* Cells along a lattice axis at most, at width h, for a box of diagonal
 * squared d2 (pipeline.h). */
static double lattice_cells_bound(double d2, double h)
{
    return floor(sqrt(d2) / h) + 3 + 2 * ST_LATTICE_PAD_DEFAULT;
}

double st_pipeline_lattice_bytes(const st_soup *s, double h, size_t tries,
                                 double *tets, double *at_once)
{
    double lo[3], hi[3], d2 = 0;
    st_error e;
    if (tets)
        *tets = 0;
    if (at_once)
        *at_once = 0;
    if (st_soup_bounds(s, lo, hi, &e) || !(h > 0) || !isfinite(h))
        return 0;
    for (int a = 0; a < 3; a++)
        d2 += (hi[a] - lo[a]) * (hi[a] - lo[a]);
    double n = lattice_cells_bound(d2, h);
    double t = 12.0 * n * n * n;
    double k = 1;
    if (tries > 1)
        k = (double)((size_t)omp_get_max_threads() < tries ? (size_t)omp_get_max_threads()
                                                            : tries);
    if (tets)
        *tets = t;
    if (at_once)
        *at_once = k;
    return t * k * ST_LATTICE_BYTES_PER_TET;
}

/* splitmix64's finaliser: a bijection of 64-bit words that mixes well. */
static uint64_t mix64(uint64_t z)
{
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
}

uint64_t st_pipeline_candidate_seed(uint64_t seed, size_t k)
{
    if (k == 0)
        return seed;
    uint64_t s = mix64(seed + 0x9e3779b97f4a7c15ULL * (uint64_t)k);
    return s ? s : 1;   /* 0 means "axis-aligned": keep candidates random */
}

static double now_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static void dihedral_range(const st_tetmesh *m, double *lo, double *hi)
{
    double mn = 180.0, mx = 0.0;
    for (size_t t = 0; t < m->ntets; t++) {
        const uint32_t *v = m->tets + 4 * t;
        double a, b;
        st_tet_dihedral_range(m->xyz + 3 * v[0], m->xyz + 3 * v[1],
                              m->xyz + 3 * v[2], m->xyz + 3 * v[3], &a, &b);
        if (a < mn)
            mn = a;
        if (b > mx)
            mx = b;
    }
    *lo = m->ntets ? mn : 0.0;
    *hi = m->ntets ? mx : 0.0;
}

/* Tell the caller (pipeline.h): one call at a time, whichever thread. */
static void emit(const st_pipeline_params *p, st_pipeline_event *ev)
{
    if (!p->on_event)
        return;
    #pragma omp critical(st_pipeline_event)
    p->on_event(p->on_event_ctx, ev);
}

/* The candidates' progress line (run_candidates): one stage a batch,
 * "candidates 1-2 of 8", whose fraction is the mean of its candidates'
 * shares done. A candidate's share moves through its inner stages, each
 * given a part of it by what it took on the models measured (soupmesh -v,
 * dragon_res2 at 20 cells: sculpt 0.34 s, fit 2.7 s, quality 1.9 s): the
 * sculpt to 0.1, the fit to 0.6 (its share of boundary vertices within
 * the offset), the quality pass to 1 (its steps, fit.c). A share only
 * grows (the fit's share falls a little as vertices move), so the line
 * never goes back. The fit reports from the candidate's thread; the
 * batch's report goes out under one lock, one call at a time. */
typedef struct batch_progress {
    const st_progress *parent;
    int report;               /* the parent wants reports */
    char stage[96];
    double done[ST_PIPELINE_BATCH];
    size_t n;
    int threads;              /* the run's threads (run_candidates) */
    int at_once;              /* the batch's candidates run at once: n, or 1 */
    int running;              /* of those, the ones still running */
} batch_progress;

typedef struct candidate_progress {
    batch_progress *b;
    size_t i;
} candidate_progress;

/* The threads of candidate cp's own loops (run_candidates): its share of
 * the run's while others of its batch run (threads / n, the first ones
 * one more for the remainder), all of them once it runs alone. Set on the
 * candidate's thread (an OpenMP setting is the calling thread's), at its
 * start and at each report of its fit and quality pass: a thread whose
 * candidate ended early goes to the loops of the one still running. No
 * result depends on it: every loop gives the same for any thread count. */
static void candidate_threads(candidate_progress *cp)
{
    const batch_progress *b = cp->b;
    const int n = b->at_once, i = n > 1 ? (int)cp->i : 0;
    int want = b->threads / n + (i < b->threads % n);
    if (__atomic_load_n(&b->running, __ATOMIC_ACQUIRE) <= 1)
        want = b->threads;
    if (want < 1)
        want = 1;
    if (omp_get_max_threads() != want)
        omp_set_num_threads(want);
}

static void candidate_share(candidate_progress *cp, double share)
{
    batch_progress *b = cp->b;
    if (!b->report)
        return;
    #pragma omp critical(st_pipeline_progress)
    {
        if (share > b->done[cp->i]) {
            b->done[cp->i] = share > 1.0 ? 1.0 : share;
            double sum = 0;
            for (size_t i = 0; i < b->n; i++)
                sum += b->done[i];
            st_progress_report(b->parent, b->stage, sum / (double)b->n);
        }
    }
}

/* A candidate's share at `fraction` of its inner stage. */
static double stage_share(const char *stage, double fraction)
{
    const int q = strcmp(stage, "quality") == 0;
    const double lo = q ? 0.6 : 0.1, hi = q ? 1.0 : 0.6;
    fraction = fraction < 0 ? 0 : fraction > 1 ? 1 : fraction;
    return lo + (hi - lo) * fraction;
}

/* st_fit's own reports. Its "fit" fraction, the share within the
 * offset, starts near 1 and then stalls for most of the fit: the
 * iterations (relay_iter) give the fit's part instead. */
static void candidate_relay(void *ctx, const char *stage, double fraction)
{
    candidate_threads(ctx);
    if (strcmp(stage, "fit") != 0)
        candidate_share(ctx, stage_share(stage, fraction));
}

/* The fit stops when every boundary vertex is within the offset or after
 * this many iterations that bring no new one (fit.c's FIT_STALL_ITERS;
 * here only for the progress line). */
#define PROGRESS_FIT_STALL 5

/* The fit's iterations: the "iteration" event, and the candidate's
 * progress through the fit and the quality pass. The fit's part: the
 * share of the vertices it had left out that it has brought within,
 * combined with how far it is into the stall that would end it (its work
 * is what ends first); the quality pass's part: its rounds out of the
 * most it runs (quality_rounds, an upper bound: the line may jump to the
 * end). */
typedef struct iter_relay {
    const st_pipeline_params *p;
    size_t k;
    candidate_progress *cp;   /* NULL: no progress line */
    int quality_rounds;
    size_t first_within, best_within;
    int since_best;
} iter_relay;

static void relay_iter(void *ctx, const st_fit_iter *it)
{
    iter_relay *r = ctx;
    if (r->cp && strcmp(it->phase, "fit") == 0) {
        if (it->iter == 1) {
            r->first_within = r->best_within = it->within_offset;
            r->since_best = 0;
        } else if (it->within_offset > r->best_within) {
            r->best_within = it->within_offset;
            r->since_best = 0;
        } else {
            r->since_best++;
        }
        const double left = (double)it->boundary_vertices - (double)r->first_within;
        const double fw = left > 0 ? ((double)r->best_within - (double)r->first_within) / left : 1;
        const double fs = (double)r->since_best / PROGRESS_FIT_STALL;
        candidate_share(r->cp, stage_share("fit", 1.0 - (1.0 - fw) * (1.0 - (fs < 1 ? fs : 1))));
    } else if (r->cp && strcmp(it->phase, "quality") == 0 && r->quality_rounds > 0) {
        double f = (double)it->iter / (double)r->quality_rounds;
        candidate_share(r->cp, stage_share("quality", f < 0.95 ? f : 0.95));
    }
    if (!r->p->on_event)
        return;
    st_pipeline_event ev;
    memset(&ev, 0, sizeof ev);
    ev.what = "iteration";
    ev.k = r->k;
    ev.fit = it;
    emit(r->p, &ev);
}

/* The Cetra candidate: sculpt, fit, quality pass. */
static st_status run_sculpt_candidate(st_tetmesh **out,
                                      st_pipeline_candidate *c, size_t k,
                                      const st_grid *g, const st_soup *s,
                                      const st_bvh *bvh, const st_soup *fill,
                                      const st_fit_shared *shared,
                                      double h, const st_pipeline_params *p,
                                      const st_progress *prog, st_error *err)
{
    st_sculpt_params sp = st_sculpt_params_default();
    sp.kind = ST_LATTICE_BCC;
    sp.h = h;
    sp.seed = c->seed;
    sp.cancel = prog ? prog->cancel : NULL;
    st_sculpt_stats ss;
    memset(&ss, 0, sizeof ss);
    double t0 = now_seconds();
    st_tetmesh *m = NULL;
    st_status rc = st_sculpt(&m, &ss, g, s, bvh, &sp, err);
    if (rc)
        return rc;
    c->bombs = ss.bombs;
    c->bombs_left = ss.bombs_left;
    candidate_progress *cp = prog && prog->fn == candidate_relay ? prog->ctx : NULL;
    if (cp)
        candidate_share(cp, 0.1);
    double t1 = now_seconds();
    c->seconds_sculpt = t1 - t0;
    st_pipeline_event ev;
    memset(&ev, 0, sizeof ev);
    ev.what = "sculpted";
    ev.k = k;
    ev.h = h;
    ev.tets = m->ntets;
    ev.seconds = c->seconds_sculpt;
    emit(p, &ev);

    st_fit_params fp = st_fit_params_default();
    iter_relay relay = {p, k, cp && cp->b->report ? cp : NULL, fp.quality_rounds, 0, 0, 0};
    if (p->on_event || relay.cp) {
        fp.on_iter = relay_iter;
        fp.on_iter_ctx = &relay;
    }
    fp.offset_ratio = p->offset_ratio;
    fp.cell_width = h;
    fp.quality = p->quality;
    fp.fill = fill;
    fp.shared = shared;
    fp.count_before = 0;   /* only the count after is reported */
    if (p->fit_max_iters > 0)
        fp.max_iters = p->fit_max_iters;
    st_fit_stats fs;
    memset(&fs, 0, sizeof fs);
    rc = st_fit(m, s, bvh, &fp, &fs, prog, err);
    if (rc) {
        st_tetmesh_free(m);
        return rc;
    }
    c->seconds_fit = now_seconds() - t1;
    c->converged = fs.converged;
    c->beyond_offset = fs.beyond_offset;
    c->boundary_vertices = fs.boundary_vertices;
    c->max_distance = fs.max_distance;
    c->verts_outside = fs.outside_after;
    c->tris_crossing = fs.crossing_after;
    *out = m;
    return ST_OK;
}

/* Choose h for about p->target_tets tets (pipeline.h): sculpt the first
 * candidate's lattice (the fit moves vertices and at most peels a few
 * boundary tets that hold nothing of the soup, so the sculpted count is
 * the mesh's count or a little above it) and step h in log-log space. The
 * slope starts at -3 (a solid: tets ~ 1/h^3) and is then measured from
 * the last two sculpts, kept within [-4, -1.5] (thin parts count like a
 * surface, ~ 1/h^2); a step changes h by a factor within [1/2, 2] so one
 * bad slope cannot ask for a lattice 8^k times too large. A lattice that
 * could not fit in max_bytes (the bound soupmesh checks) ends the search
 * with ST_ELIMIT. On return *h is the width whose count was closest. */
static st_status choose_h(double *h, st_pipeline_stats *st, const st_grid *g,
                          const st_soup *s, const st_bvh *bvh,
                          const st_pipeline_params *p, const double lo[3],
                          const double hi[3], const st_progress *prog, st_error *err)
{
    const double target = p->target_tets ? (double)p->target_tets : 0;
    double d2 = 0;
    for (int a = 0; a < 3; a++)
        d2 += (hi[a] - lo[a]) * (hi[a] - lo[a]);
    double hk = *h, hprev = 0, nprev = 0, slope = -3;
    double best_h = hk, best_err = INFINITY;
    size_t best_n = 0;
    for (int it = 0; it < ST_PIPELINE_SIZE_STEPS; it++) {
        if (st_progress_cancelled(prog))
            return st_error_set(err, ST_ECANCELLED, NULL, 0, "cancelled");
        double cells = lattice_cells_bound(d2, hk);
        if (p->max_bytes &&
            12.0 * cells * cells * cells * ST_LATTICE_BYTES_PER_TET > (double)p->max_bytes)
            return st_error_set(err, ST_ELIMIT, NULL, 0,
                                "about %.0f tets need cells of width %g, "
                                "whose lattice is over the memory limit",
                                target, hk);
        st_sculpt_params sp = st_sculpt_params_default();
        sp.kind = ST_LATTICE_BCC;
        sp.h = hk;
        sp.seed = st_pipeline_candidate_seed(p->seed, 0);
        sp.cancel = prog ? prog->cancel : NULL;
        st_sculpt_stats ss;
        memset(&ss, 0, sizeof ss);
        st_tetmesh *m = NULL;
        st_status rc = st_sculpt(&m, &ss, g, s, bvh, &sp, err);
        if (rc)
            return rc;
        double n = (double)m->ntets;
        st_tetmesh_free(m);
        st->sculpts++;
        st_pipeline_event ev;
        memset(&ev, 0, sizeof ev);
        ev.what = "size";
        ev.h = hk;
        ev.tets = (size_t)n;
        emit(p, &ev);
        double e = target > 0 && n > 0 ? fabs(log(n / target)) : 0;
        if (e < best_err) {
            best_err = e;
            best_h = hk;
            best_n = (size_t)n;
        }
        if (target <= 0 || (n > 0 && fabs(n / target - 1) <= 0.1))
            break;
        if (hprev > 0 && n > 0 && nprev > 0 && n != nprev)
            slope = log(n / nprev) / log(hk / hprev);
        if (!(slope <= -1.5))
            slope = -1.5;
        if (slope < -4)
            slope = -4;
        double step = n > 0 ? exp(log(target / n) / slope) : 0.5;
        step = step < 0.5 ? 0.5 : step > 2 ? 2 : step;
        hprev = hk;
        nprev = n;
        hk *= step;
    }
    *h = best_h;
    st->estimated_tets = best_n;
    return ST_OK;
}

/* The Spillmann candidate: cubic5 lattice, density filter, fairing. */
static st_status run_density_candidate(st_tetmesh **out,
                                       st_pipeline_candidate *c,
                                       const st_grid *g, const st_soup *s,
                                       const st_bvh *bvh, double h,
                                       const st_pipeline_params *p,
                                       st_error *err)
{
    double lo[3], hi[3];
    st_lattice_grid_box(g, lo, hi);
    st_lattice_params lp = st_lattice_params_default();
    lp.kind = ST_LATTICE_CUBIC5;
    lp.h = h;
    lp.seed = c->seed;
    double t0 = now_seconds();
    st_lattice *L = NULL;
    st_status rc = st_lattice_build(&L, lo, hi, &lp, err);
    if (rc)
        return rc;
    st_tetmesh *m = NULL;
    rc = st_lattice_density_filter(&m, NULL, L, g, p->density_rho, err);
    st_lattice_free(L);
    if (rc)
        return rc;
    if (m->ntets == 0) {
        st_tetmesh_free(m);
        return st_error_set(err, ST_EINPUT, NULL, 0,
                            "no tet has density >= %g at %zu cells: lower "
                            "--density or raise --cells", p->density_rho,
                            p->cells);
    }
    double t1 = now_seconds();
    c->seconds_sculpt = t1 - t0;
    rc = st_fair(m, NULL, NULL, NULL, err);
    if (rc) {
        st_tetmesh_free(m);
        return rc;
    }
    rc = st_enclosure_count(m, s, bvh, &c->verts_outside, &c->tris_crossing,
                            err);
    if (rc) {
        st_tetmesh_free(m);
        return rc;
    }
    c->seconds_fit = now_seconds() - t1;
    c->converged = 1;
    *out = m;
    return ST_OK;
}

/* 1 when every tet of candidate c scores at least the quality pass's goal
 * (smooth.h: min dihedral >= 35 degrees by default) with its max dihedral
 * bound (180 - 35 / 0.75 = 133.3) rounded down to a whole degree, 133,
 * the bound the project holds its meshes to. */
static int angles_met(const st_pipeline_candidate *c)
{
    const double goal = st_fit_params_default().quality_goal;
    return c->min_dihedral >= goal &&
           c->max_dihedral <= 180.0 - ceil(goal / ST_FIT_MAX_WEIGHT);
}

/* 1 when candidate a is better than candidate b (see pipeline.h). */
static int better(const st_pipeline_candidate *a, size_t ka,
                  const st_pipeline_candidate *b, size_t kb)
{
    if (a->failed != b->failed)
        return !a->failed;
    int ea = a->verts_outside == 0 && a->tris_crossing == 0;
    int eb = b->verts_outside == 0 && b->tris_crossing == 0;
    if (ea != eb)
        return ea;
    /* then the stopping condition (the fit's promise), then the angle
     * goals met (35.05..133.3 does not beat 35.03..131.5), then angles */
    if (a->converged != b->converged)
        return a->converged;
    int ga = angles_met(a), gb = angles_met(b);
    if (ga != gb)
        return ga;
    if (a->min_dihedral != b->min_dihedral)
        return a->min_dihedral > b->min_dihedral;
    if (a->max_dihedral != b->max_dihedral)
        return a->max_dihedral < b->max_dihedral;
    return ka < kb;
}

/* 1 when candidate c meets every goal: it encloses, meets the fit's
 * stopping condition, and its angles meet the goals (angles_met). A
 * better one could only have larger angles within these. */
static int meets_goals(const st_pipeline_candidate *c, const st_pipeline_params *p)
{
    if (c->failed || c->verts_outside || c->tris_crossing || !c->converged)
        return 0;
    if (p->density_rho > 0)
        return 0;   /* the Spillmann mesher has no such goal */
    return angles_met(c);
}

/* Candidate k, start to end (its event: candidate_event). */
static void run_candidate(st_tetmesh **meshes, st_pipeline_stats *st, size_t k,
                          const st_grid *g, const st_soup *s, const st_bvh *bvh,
                          const st_soup *fill, const st_fit_shared *shared, double h,
                          const st_pipeline_params *p, const st_progress *prog)
{
    st_pipeline_candidate *c = &st->candidates[k];
    st_error e;
    st_error_clear(&e);
    st_status r = p->density_rho > 0
        ? run_density_candidate(&meshes[k], c, g, s, bvh, h, p, &e)
        : run_sculpt_candidate(&meshes[k], c, k, g, s, bvh, fill, shared, h, p, prog, &e);
    if (r) {
        c->failed = 1;
        st_error_format(&e, c->message, sizeof c->message);
    } else {
        c->tets = meshes[k]->ntets;
        c->points = meshes[k]->npoints;
        dihedral_range(meshes[k], &c->min_dihedral, &c->max_dihedral);
    }
}

/* Candidate k is done: the "candidate" event. */
static void candidate_event(const st_pipeline_stats *st, size_t k, double h,
                            const st_pipeline_params *p)
{
    st_pipeline_event ev;
    memset(&ev, 0, sizeof ev);
    ev.what = "candidate";
    ev.k = k;
    ev.h = h;
    ev.tets = st->candidates[k].tets;
    ev.candidate = &st->candidates[k];
    emit(p, &ev);
}

/* One candidate of a batch on the thread that runs it (run_candidates):
 * its loops' threads, the candidate, its end. */
typedef struct candidate_job {
    st_tetmesh **meshes;
    st_pipeline_stats *st;
    size_t k;
    const st_grid *g;
    const st_soup *s, *fill;
    const st_bvh *bvh;
    const st_fit_shared *shared;
    double h;
    const st_pipeline_params *p;
    const st_progress *prog;   /* the caller's (its cancel flag) */
    st_progress relay;         /* the candidate's (candidate_relay) */
    candidate_progress cp;
    pthread_t thread;
    int started;               /* on a thread of its own */
} candidate_job;

/* Its event comes after it has left its threads to the others: what
 * follows the event in the others' events runs with them (test_pipeline). */
static void run_job(candidate_job *j)
{
    candidate_threads(&j->cp);
    const int run = !st_progress_cancelled(j->prog);
    if (run) {
        run_candidate(j->meshes, j->st, j->k, j->g, j->s, j->bvh, j->fill, j->shared, j->h,
                      j->p, &j->relay);
        candidate_share(&j->cp, 1.0);
    }
    __atomic_sub_fetch(&j->cp.b->running, 1, __ATOMIC_RELEASE);
    if (run)
        candidate_event(j->st, j->k, j->h, j->p);
}

static void *job_thread(void *arg)
{
    run_job(arg);
    return NULL;
}

/* The candidates b0..b1-1 of a batch at once: the first on this thread,
 * each other on a thread of its own (signals blocked: they stay with the
 * caller's threads), each with its share of the threads for its own loops
 * (candidate_threads). A thread that cannot be started leaves its
 * candidate to this one, after the first. */
static void run_batch(candidate_job *jobs, size_t n)
{
    sigset_t all, old;
    sigfillset(&all);
    int masked = n > 1 && pthread_sigmask(SIG_BLOCK, &all, &old) == 0;
    batch_progress *b = jobs[0].cp.b;
    for (size_t i = 1; i < n; i++) {
        jobs[i].started = pthread_create(&jobs[i].thread, NULL, job_thread, &jobs[i]) == 0;
        if (!jobs[i].started)
            __atomic_sub_fetch(&b->running, 1, __ATOMIC_RELEASE);   /* not yet */
    }
    if (masked)
        pthread_sigmask(SIG_SETMASK, &old, NULL);
    run_job(&jobs[0]);
    for (size_t i = 1; i < n; i++)
        if (!jobs[i].started) {
            __atomic_add_fetch(&b->running, 1, __ATOMIC_RELEASE);
            run_job(&jobs[i]);
        }
    for (size_t i = 1; i < n; i++)
        if (jobs[i].started)
            pthread_join(jobs[i].thread, NULL);
}

/* The candidates (see pipeline.h): batches of ST_PIPELINE_BATCH in
 * index order, the candidates of a batch at once (run_batch), a single
 * one on this thread with all threads for its own loops. A batch's
 * candidates share the threads; once one ends, the others take its
 * threads for their loops (candidate_threads). Each batch is a stage of
 * the progress line (batch_progress), moved by its candidates' sculpts,
 * fits and quality passes. After each batch, a candidate that meets
 * every goal ends the run: the batches do not depend on the thread
 * count, so neither does which candidates ran. st->ncandidates becomes
 * the number that ran. */
static void run_candidates(st_tetmesh **meshes, st_pipeline_stats *st, const st_grid *g,
                           const st_soup *s, const st_bvh *bvh, const st_soup *fill,
                           double h, const st_pipeline_params *p, const st_progress *prog)
{
    /* the fits' set-up that depends on s, the fill and h alone, built once
     * for all candidates (st_fit_shared_new: each fit runs as it would with
     * its own); none when it cannot be built, and each fit builds its own */
    st_fit_shared *shared = NULL;
    if (p->density_rho <= 0) {
        st_error e;
        st_error_clear(&e);
        if (st_fit_shared_new(&shared, s, fill, h, &e))
            shared = NULL;
    }
    const size_t K = st->ncandidates;
    const int threads = omp_get_max_threads();
    size_t ran = 0;
    for (size_t b0 = 0; b0 < K && !st->goal_met; b0 += ST_PIPELINE_BATCH) {
        size_t b1 = b0 + ST_PIPELINE_BATCH < K ? b0 + ST_PIPELINE_BATCH : K;
        batch_progress bp;
        memset(&bp, 0, sizeof bp);
        bp.parent = prog;
        bp.report = prog && prog->fn;
        bp.n = b1 - b0;
        bp.threads = threads;
        bp.at_once = threads > 1 ? (int)bp.n : 1;   /* one thread: one at a time */
        if (K == 1)
            snprintf(bp.stage, sizeof bp.stage, "candidate");
        else if (b1 - b0 == 1)
            snprintf(bp.stage, sizeof bp.stage, "candidates %zu of %zu", b1, K);
        else
            snprintf(bp.stage, sizeof bp.stage, "candidates %zu-%zu of %zu", b0 + 1, b1, K);
        candidate_job jobs[ST_PIPELINE_BATCH];
        memset(jobs, 0, sizeof jobs);
        for (size_t i = 0; i < bp.n; i++) {
            candidate_job *j = &jobs[i];
            *j = (candidate_job){.meshes = meshes, .st = st, .k = b0 + i, .g = g, .s = s,
                                 .fill = fill, .bvh = bvh, .shared = shared, .h = h,
                                 .p = p, .prog = prog,
                                 .cp = {&bp, i}};
            j->relay = (st_progress){candidate_relay, &j->cp, prog ? prog->cancel : NULL};
        }
        st_progress_report(prog, bp.stage, 0.0);
        if (bp.at_once > 1) {
            bp.running = bp.at_once;
            run_batch(jobs, bp.n);
        } else {
            for (size_t i = 0; i < bp.n; i++) {
                bp.running = 1;
                run_job(&jobs[i]);
            }
        }
        ran = b1;
        for (size_t k = b0; k < b1 && !p->try_all; k++)
            if (meets_goals(&st->candidates[k], p))
                st->goal_met = 1;
    }
    omp_set_num_threads(threads);
    st->ncandidates = ran;
    st_fit_shared_free(shared);
}

/* The fill (pseudo.h): the pseudo volume's boundary where the soup has
 * none. It counts as surface for the fit's condition (fill_counts), and
 * how much of the boundary it is, how far from the soup, says how much of
 * the solid is a guess (the closed shells' alone: none, and no call).
 * *fill stays NULL where it does not count. */
static st_status make_fill(st_soup **fill, st_pipeline_stats *st, const st_grid *g,
                           const st_bvh *bvh, const st_soup *sym,
                           const st_pipeline_params *p, const st_progress *prog,
                           st_error *err)
{
    size_t nfill = 0;
    st_progress_report(prog, "fill", 0.0);
    st_status rc = st_pseudo_fill(fill, g, bvh, &nfill, err);
    if (rc)
        return rc;
    st_pseudo_guess_measure(&st->guess, g, *fill, bvh);
    if ((rc = st_pseudo_guess_symmetric(&st->guess, g, *fill, sym, err)))
        return rc;
    if (p->density_rho <= 0 && p->fill_counts) {
        st->fill_faces = nfill;
    } else {
        st_soup_free(*fill);
        *fill = NULL;
    }
    return ST_OK;
}

st_status st_pipeline_enclosed(st_soup **out, st_bvh **bvh, const st_soup *s,
                               const st_soup *fill, st_error *err)
{
    *out = NULL;
    *bvh = NULL;
    if (!fill || fill->ntris == 0)
        return ST_OK;
    st_soup *u = st_soup_new();
    if (!u)
        return st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory");
    st_status rc = st_soup_append(u, s, err);
    if (!rc)
        rc = st_soup_append(u, fill, err);
    if (!rc)
        rc = st_bvh_build(bvh, u, err);
    if (rc) {
        st_soup_free(u);
        return rc;
    }
    *out = u;
    return ST_OK;
}

/* The field's default voxels along the longest side for a lattice of
 * cells: 16 voxels per lattice cell up to 128 (soupdist's default), 8 per
 * cell beyond (pipeline.h). The fit and the sculpt read the field per
 * cell: 8 per cell is what runs at 16 cells and over always had; a coarse
 * lattice gets twice that, no longer a 128^3 field for 4 cells. */
static size_t field_voxels(size_t cells)
{
    const size_t fine = cells * 16 < 128 ? cells * 16 : 128;
    return cells * 8 > fine ? cells * 8 : fine;
}

/* The field and the pseudo volume's settings a run uses (voxels along the
 * longest side of the soup's box, its hole caps and closed shells): one
 * place for st_pipeline_run and st_pipeline_field_of_mesh. */
static void field_params(st_dist_params *dp, st_pseudo_params *pp, size_t voxels,
                         size_t max_bytes, int fill_holes, int closed_shells, int symmetry)
{
    *dp = st_dist_params_default();
    dp->cells = voxels;
    dp->max_bytes = max_bytes;
    *pp = st_pseudo_params_default();
    pp->fill_holes = fill_holes;
    pp->closed_shells = closed_shells;
    pp->symmetry = symmetry;
}

static st_status set_meta(st_tetmesh *m, const st_pipeline_params *p,
                          const st_pipeline_stats *st, size_t field_voxels, st_error *err)
{
    char buf[64];
    /* what the fill (offset_fill) was made from: st_pipeline_field_of_mesh */
    snprintf(buf, sizeof buf, "%zu", field_voxels);
    if (st_meta_set(&m->meta, "field_voxels", buf) ||
        st_meta_set(&m->meta, "fill_holes", p->fill_holes ? "yes" : "no") ||
        st_meta_set(&m->meta, "closed_shells", p->closed_shells ? "yes" : "no") ||
        (p->symmetry && st_meta_set(&m->meta, "symmetry", "yes")))
        goto oom;
    snprintf(buf, sizeof buf, "%.17g", p->offset_ratio);
    if (st_meta_set(&m->meta, "offset_ratio", buf))
        goto oom;
    snprintf(buf, sizeof buf, "%zu", st->ncandidates);
    if (st_meta_set(&m->meta, "candidates", buf))
        goto oom;
    if (st_meta_set(&m->meta, "encloses", st->encloses ? "yes" : "no"))
        goto oom;
    if (p->float32 && st_meta_set(&m->meta, "float32", "yes"))
        goto oom;
    if (p->density_rho <= 0 && st_meta_set(&m->meta, "offset_fill", p->fill_counts ? "yes" : "no"))
        goto oom;
    if (p->density_rho > 0) {
        snprintf(buf, sizeof buf, "%.17g", p->density_rho);
        if (st_meta_set(&m->meta, "rho_min", buf))
            goto oom;
    }
    return ST_OK;
oom:
    return st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory");
}

/* The arguments' checks; *cells: p->cells, or with an absolute cell
 * width the cells it makes along the longest side (the field's resolution
 * follows them). */
static st_status check_params(size_t *cells, const st_soup *s, const st_pipeline_params *p,
                              st_error *err)
{
    if (!p || p->cells < 1)
        return st_error_set(err, ST_EINPUT, NULL, 0, "cells must be >= 1");
    if (p->tries < 1 || p->tries > ST_PIPELINE_MAX_TRIES)
        return st_error_set(err, ST_EINPUT, NULL, 0,
                            "tries must be in 1..%d", ST_PIPELINE_MAX_TRIES);
    if (!(p->offset_ratio > 0) || !isfinite(p->offset_ratio))
        return st_error_set(err, ST_EINPUT, NULL, 0,
                            "the offset ratio must be > 0");
    if (!s || s->ntris == 0)
        return st_error_set(err, ST_EINPUT, NULL, 0, "the soup has no triangles");
    *cells = p->cells;
    if (p->h != 0) {
        double blo[3], bhi[3];
        st_status bs = st_soup_bounds(s, blo, bhi, err);
        if (bs)
            return bs;
        double n = ceil(st_lattice_h_for_cells(blo, bhi, 1) / p->h);
        if (!(p->h > 0) || !isfinite(p->h))
            return st_error_set(err, ST_EINPUT, NULL, 0,
                                "the cell width must be > 0 and finite");
        if (!(n <= ST_PIPELINE_MAX_CELLS))
            return st_error_set(err, ST_ELIMIT, NULL, 0,
                                "a cell width of %g makes %.0f cells along "
                                "the longest side, more than %d",
                                p->h, n, ST_PIPELINE_MAX_CELLS);
        *cells = n < 1 ? 1 : (size_t)n;
    }
    return ST_OK;
}

/* The pseudo volume (pseudo.h), as soupsign --surface gives it: the field
 * and its refinement see the hole caps; the mesh is fitted to, and must
 * enclose, the soup itself. *bvh: the soup's BVH from the pseudo volume
 * (the caps and the refinement used it), the fit's, the sculpting's and
 * the checks'. Its times and dimensions go to st, and the "field" event
 * out. */
static st_status make_field(st_grid **g, st_bvh **bvh, st_pipeline_stats *st,
                            const st_soup *s, const st_dist_params *dp,
                            const st_pseudo_params *pp, const st_pipeline_params *p,
                            double t_start, const st_progress *prog, st_error *err)
{
    st_pseudo_stats ps;
    st_status rc = st_pseudo_volume_bvh(g, s, dp, pp, &ps, prog, bvh, err);
    if (rc)
        return rc;
    double t_sign = t_start + (now_seconds() - t_start) -
                    (ps.seconds_shells + ps.seconds_holes + ps.seconds_vote + ps.seconds_refine +
                     ps.seconds_bvh);
    st->seconds_dist = t_sign - t_start;
    double t_cand = now_seconds();
    st->seconds_sign = t_cand - t_sign;
    st->shells_only = ps.shells_only;
    st->symmetries = ps.symmetries;
    st->symmetry_fill = ps.symmetry_fill;
    st->seconds_symmetry = ps.seconds_symmetry;
    st->field_dims[0] = (*g)->nx;
    st->field_dims[1] = (*g)->ny;
    st->field_dims[2] = (*g)->nz;
    st->voxel = (*g)->voxel;
    st_pipeline_event ev;
    memset(&ev, 0, sizeof ev);
    ev.what = "field";
    memcpy(ev.field_dims, st->field_dims, sizeof ev.field_dims);
    ev.voxel = (*g)->voxel;
    ev.seconds = t_cand - t_start;
    emit(p, &ev);
    return ST_OK;
}

/* The best of the candidates that ran (better) into st->best, and
 * whether it encloses s; with float32, its counts, angles and enclosure as
 * a float32 consumer will hold it (the rounded mesh's). with_fill: the
 * candidates' counts are of s and the fill (st_pipeline_enclosed); where
 * the best one misses those, its counts become s's alone, the input's,
 * which is what the run reports. All failed: the first one's message. */
static st_status choose_best(st_pipeline_stats *st, st_tetmesh **meshes, const st_soup *s,
                             const st_bvh *bvh, int with_fill,
                             const st_pipeline_params *p, st_error *err)
{
    size_t best = 0;
    for (size_t k = 1; k < st->ncandidates; k++)
        if (better(&st->candidates[k], k, &st->candidates[best], best))
            best = k;
    if (st->candidates[best].failed)
        return st_error_set(err, ST_EINPUT, NULL, 0, "%s", st->candidates[0].message);
    st->best = best;
    st_pipeline_candidate *b = &st->candidates[best];
    if (with_fill && (b->verts_outside || b->tris_crossing)) {
        st_status rc = st_enclosure_count(meshes[best], s, bvh, &b->verts_outside,
                                          &b->tris_crossing, err);
        if (rc)
            return rc;
    }
    st->encloses = st->candidates[best].verts_outside == 0 &&
                   st->candidates[best].tris_crossing == 0;
    if (p->float32) {
        st_pipeline_candidate *c = &st->candidates[best];
        st_status rc = st_enclosure_round_float32(meshes[best], s, bvh, &st->float32, err);
        if (rc)
            return rc;
        c->verts_outside = st->float32.verts_outside;
        c->tris_crossing = st->float32.tris_crossing;
        dihedral_range(meshes[best], &c->min_dihedral, &c->max_dihedral);
        st->encloses = st->float32.encloses;
    }
    return ST_OK;
}

st_status st_pipeline_run(st_tetmesh **out, st_pipeline_stats *stats,
                          const st_soup *s, const st_pipeline_params *p,
                          const st_progress *prog, st_error *err)
{
    *out = NULL;
    st_pipeline_stats local;
    st_pipeline_stats *st = stats ? stats : &local;
    memset(st, 0, sizeof *st);
    size_t cells = 0;
    st_status rc = check_params(&cells, s, p, err);
    if (rc)
        return rc;
    double t_start = now_seconds();
    st_dist_params dp;
    st_pseudo_params pp;
    field_params(&dp, &pp, p->field_cells ? p->field_cells : field_voxels(cells),
                 p->max_bytes, p->fill_holes, p->closed_shells, p->symmetry);
    st_grid *g = NULL;
    st_bvh *bvh = NULL;
    st_tetmesh **meshes = NULL;
    st_soup *fill = NULL, *sym = NULL, *enc = NULL;
    st_bvh *enc_bvh = NULL;
    pp.symmetric_fill = &sym;   /* the guess's symmetric part (make_fill) */
    /* The sculpting, the fill and the parts read only the field's signs;
     * the density filter's clean-up reads its depths too (thin parts). */
    pp.signs_only = p->density_rho <= 0;
    rc = make_field(&g, &bvh, st, s, &dp, &pp, p, t_start, prog, err);
    pp.symmetric_fill = NULL;
    if (rc)
        goto done;
    double t_cand = now_seconds();

    double lo[3], hi[3];
    rc = st_soup_bounds(s, lo, hi, err);
    if (rc)
        goto done;
    double h = p->h > 0 ? p->h : st_lattice_h_for_cells(lo, hi, p->cells);
    if (p->density_rho <= 0 && (p->target_tets || p->dry_run)) {
        double t_size = now_seconds();
        rc = choose_h(&h, st, g, s, bvh, p, lo, hi, prog, err);
        st->seconds_size = now_seconds() - t_size;
        if (rc)
            goto done;
    }
    st->h = h;
    if (p->dry_run) {
        st->seconds_total = now_seconds() - t_start;
        goto done;
    }

    if (st_progress_cancelled(prog)) {
        rc = st_error_set(err, ST_ECANCELLED, NULL, 0, "cancelled");
        goto done;
    }
    if (!st->shells_only && (rc = make_fill(&fill, st, g, bvh, sym, p, prog, err)))
        goto done;
    size_t K = p->tries;
    st->candidates = calloc(K, sizeof *st->candidates);
    meshes = calloc(K, sizeof *meshes);
    if (!st->candidates || !meshes) {
        rc = st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory");
        goto done;
    }
    st->ncandidates = K;
    for (size_t k = 0; k < K; k++)
        st->candidates[k].seed = st_pipeline_candidate_seed(p->seed, k);

    /* the fill is enclosed as the soup is (st_pipeline_enclosed) */
    if ((rc = st_pipeline_enclosed(&enc, &enc_bvh, s, fill, err)))
        goto done;
    run_candidates(meshes, st, g, enc ? enc : s, enc ? enc_bvh : bvh, fill, h, p, prog);
    st->seconds_candidates = now_seconds() - t_cand;
    if (st_progress_cancelled(prog)) {
        rc = st_error_set(err, ST_ECANCELLED, NULL, 0, "cancelled");
        goto done;
    }

    if ((rc = choose_best(st, meshes, s, bvh, enc != NULL, p, err)))
        goto done;
    const size_t best = st->best;
    rc = set_meta(meshes[best], p, st, dp.cells, err);
    if (rc)
        goto done;
    if (p->parts && (rc = st_parts_tag(meshes[best], s, p->parts, g, &pp, &st->parts, prog, err)))
        goto done;
    *out = meshes[best];
    meshes[best] = NULL;
    st->seconds_total = now_seconds() - t_start;
done:
    if (meshes)
        for (size_t k = 0; k < st->ncandidates; k++)
            st_tetmesh_free(meshes[k]);
    free(meshes);
    if (!stats) {
        free(local.candidates);
    }
    st_bvh_free(bvh);
    st_soup_free(fill);
    st_soup_free(sym);
    st_bvh_free(enc_bvh);
    st_soup_free(enc);
    st_grid_free(g);
    return rc;
}

/* yes or no in m's meta: 1, 0, or -1 when absent or neither. */
static int meta_yes(const st_tetmesh *m, const char *key)
{
    const char *v = st_meta_get(&m->meta, key);
    return !v ? -1 : strcmp(v, "yes") == 0 ? 1 : strcmp(v, "no") == 0 ? 0 : -1;
}

st_status st_pipeline_field_of_mesh(st_grid **out, const st_tetmesh *m, const st_soup *s,
                                    size_t max_bytes, const st_progress *prog, st_error *err)
{
    *out = NULL;
    const char *v = st_meta_get(&m->meta, "field_voxels");
    const int holes = meta_yes(m, "fill_holes"), shells = meta_yes(m, "closed_shells");
    char *end = NULL;
    errno = 0;
    const unsigned long long n = v ? strtoull(v, &end, 10) : 0;
    if (!v || !*v || *end || errno || n < 1 || n > 65536 || holes < 0 || shells < 0)
        return st_error_set(err, ST_EINPUT, NULL, 0,
                            "the mesh does not say what field it was fitted against (meta "
                            "field_voxels, fill_holes, closed_shells: a soupmesh mesh does)");
    st_dist_params dp;
    st_pseudo_params pp;
    /* "symmetry" is recorded only when it was on */
    field_params(&dp, &pp, (size_t)n, max_bytes, holes, shells, meta_yes(m, "symmetry") == 1);
    return st_pseudo_volume(out, s, &dp, &pp, NULL, prog, err);
}
