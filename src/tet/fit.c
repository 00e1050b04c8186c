/*
 * fit.c - enclosing vertex adjustment of a tet mesh to a surface S (st_fit,
 * smooth.h; Stuart, Levine, Jones, Bargteil 2013, "Cetra", section 3.3),
 * every move under the invariant of invariant.c. Design notes and the
 * measurements behind the constants: doc/design/fit.md.
 *
 * The schedule (st_fit, around the state of one run, fit_run):
 *   fit_open      the checks, the invariant's context, the per-vertex arrays;
 *   fit_iterate   the paper's iterations: each moves every vertex x by
 *                 tau * (x* - x), x* its ODT target (Alliez et al. 2005),
 *                 a boundary vertex beyond d_offset also toward the band's
 *                 middle (FIT_GOAL_FRACTION); a refused move is halved
 *                 FIT_HALVINGS times, then skipped; they stop when every
 *                 boundary vertex is within d_offset (or a rescue pass
 *                 tried early, early_rescue, brings them there), nothing
 *                 moves, FIT_STALL_ITERS in a row bring no vertex into the
 *                 band for the first time (fit_reached), or at max_iters;
 *   rescue_pass   the vertices still beyond, held by S near their star,
 *                 try other directions that still bring them closer
 *                 (rescue_vertex), or, for the last few, a neighbour's
 *                 step first (rescue_joint);
 *   fit_polish    the quality pass (quality.c), the late rescues
 *                 (late_rescues), the quality pass with the cube steps,
 *                 the peeling of boundary tets below the goal that hold
 *                 nothing of S (fit_peel), the late rescues again;
 *   fit_finish    the statistics and the enclosure count after.
 *
 * Vertices move colour by colour (smooth_mesh.c); within a colour in
 * parallel, each check reading only its own star, so the result does not
 * depend on the thread count. The rescues and the peeling run serially.
 */
#include "invariant.h"
#include "quality.h"
#include "../base/fpenv.h"

#include "souptet/enclose.h"
#include "souptet/isect.h"
#include "souptet/mem.h"
#include "souptet/sculpt.h"
#include "souptet/smooth.h"

#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

/* Halvings of a rejected fit move before it is skipped (the brief's "a
 * few times": 1/16 of a step is already below what one iteration of the
 * paper's scheme moves a vertex near convergence). */
#define FIT_HALVINGS 4
/* Iterations in a row that bring no boundary vertex into the band for the
 * first time (fit_reached) before the fit gives up on the rest: past this
 * the remaining ones are held by the invariant (thin gaps) or go in and
 * out of the band as their neighbours' ODT steps swing them, and more
 * steps only wear the angles down (doc/design/fit.md: the count within
 * oscillated 222..227 for 18 iterations on the armadillo at 7 cells, and
 * each new high of the oscillation restarted the old count). */
#define FIT_STALL_ITERS 5
/* The early rescue: after FIT_EARLY_RESCUE iterations without a new
 * boundary vertex in the band, or when an iteration leaves at most
 * FIT_EARLY_FEW beyond it, the fit tries the rescue pass: when it brings
 * every boundary vertex into the band, the fit stops there (the stall's
 * ODT steps only wear the angles down to the sliver floor); otherwise its
 * moves are undone and the iterations go on exactly as before. After
 * FIT_EARLY_TRIALS such failures no more are tried: where the count
 * within oscillates (armadillo at 7 cells), each costs a rescue pass over
 * some 20 vertices and brings nothing. */
#define FIT_EARLY_RESCUE 1
#define FIT_EARLY_FEW 4
#define FIT_EARLY_TRIALS 2
/* A fit move may not bring the score of its star (smooth.h) below this
 * many degrees, or below what it already was if lower: next to vertices
 * the invariant holds back, unconstrained ODT steps flatten tets to 0
 * degrees (doc/design/fit.md). */
#define FIT_SLIVER_FLOOR 10.0
/* The surface pull aims at this fraction of d_offset from S: the middle of
 * the band leaves room for the ODT motion and the quality pass without
 * leaving it. */
#define FIT_GOAL_FRACTION 0.5

st_fit_params st_fit_params_default(void)
{
    st_fit_params p;
    memset(&p, 0, sizeof p);
    p.offset_ratio = 0.4;
    p.cell_width = 0.0;
    p.step = 0.5;
    p.max_iters = 300;
    p.quality = 1;
    p.quality_rounds = 40;
    p.quality_goal = 35.0;
    p.peel = 1;
    p.count_before = 1;
    return p;
}

/* ---- the state of one run -------------------------------------------- */

typedef struct fit_run {
    fit_ctx c;            /* the invariant, the mesh, S */
    st_fit_params p;
    st_fit_stats st;      /* what st_fit reports, filled as it goes */
    dirty dy;             /* the fit moves' dirty set */
    double *dist;         /* per vertex: its distance to S (boundary) */
    dist_summary ds;      /* of dist, as it stands */
    double *save;         /* the early rescue's undo: positions, then dist */
    unsigned char *reached;   /* per vertex: 1 once a boundary vertex has been
                                 within d_offset (on entry or after a fit
                                 iteration) */
    double t0;            /* when st_fit began (sm_now) */
} fit_run;

/* The quality pass (quality.c) on the run, and the distances after it. */
static st_status fit_quality(fit_run *r, st_error *err)
{
    st_status rc = sm_quality_pass(&r->c, &r->p, r->dist, &r->st, r->t0, err);
    if (rc == ST_OK)
        r->ds = sm_boundary_distances(&r->c, r->dist);
    return rc;
}

/* ---- fit iterations --------------------------------------------------- */

/* The index (from vt_off[v]) of the lowest-scoring tet of v's star as it
 * is, the first to try in star_keeps_floor. */
static size_t star_worst(const sm_mesh *sm, uint32_t v)
{
    size_t worst = SIZE_MAX;
    double lowest = INFINITY;
    for (size_t j = sm->vt_off[v]; j < sm->vt_off[v + 1]; j++) {
        const uint32_t *k = sm->m->tets + 4 * (size_t)sm->vt[j];
        double sc = sm_tet_score(sm->m->xyz + 3 * (size_t)k[0], sm->m->xyz + 3 * (size_t)k[1],
                                 sm->m->xyz + 3 * (size_t)k[2], sm->m->xyz + 3 * (size_t)k[3]);
        if (sc < lowest) {
            lowest = sc;
            worst = j - sm->vt_off[v];
        }
    }
    return worst;
}

/* 1 when the star of v with v at p scores at least floor_score
 * (sm_star_score(sm, v, p) >= floor_score), cut short for the rescues,
 * whose candidates mostly fall below it: the star's score is asked only
 * whether it is above the largest double below the floor
 * (sm_star_score_above: its exact score when above that, else a value at
 * most that), tet `first` first, so a position below the floor ends at
 * its first tet there instead of scoring the whole star. */
static int star_keeps_floor(const sm_mesh *sm, uint32_t v, const double p[3], size_t first,
                            double floor_score)
{
    double below = nextafter(floor_score, -INFINITY);
    return sm_star_score_above(sm, v, p, first, below) > below;
}

/* One fit move of v (the step tau toward its ODT target, and toward the
 * band when beyond it), halved while the invariant refuses it. 1 when v
 * moved; *n counts. */
static int fit_vertex(const fit_ctx *c, uint32_t v, double tau, const double *dist,
                      star_pts *sp, fit_counts *n)
{
    const sm_mesh *sm = &c->sm;
    double *x = sm->m->xyz + 3 * (size_t)v;
    double t[3], d[3];
    sm_odt_target(sm, v, t);
    for (int a = 0; a < 3; a++)
        d[a] = tau * (t[a] - x[a]);
    if (sm->onb[v] && dist[v] > c->d_offset) {
        double cp[3];
        double dd = sm_dist_to_s(c, x, cp);
        if (dd > 0.0) {
            double goal = FIT_GOAL_FRACTION * c->d_offset;
            for (int a = 0; a < 3; a++) {
                double g = cp[a] + (x[a] - cp[a]) * (goal / dd);
                d[a] += tau * (g - x[a]);
            }
        }
    }
    if (d[0] == 0.0 && d[1] == 0.0 && d[2] == 0.0)
        return 0;
    sm_star_pts_collect(c, v, sp);
    double floor_score = fmin(FIT_SLIVER_FLOOR, sm_star_score(sm, v, x));
    double f = 1.0;
    for (int k = 0; k <= FIT_HALVINGS; k++, f *= 0.5) {
        double p[3] = {x[0] + f * d[0], x[1] + f * d[1], x[2] + f * d[2]};
        if (sm_star_score(sm, v, p) >= floor_score && sm_move_ok(c, v, p, sp)) {
            memcpy(x, p, sizeof p);
            n->moved++;
            return 1;
        }
        n->rejected++;
    }
    n->skipped++;
    return 0;
}


/* ---- rescue: the vertices the fit left beyond the band --------------- */

/* Directions tried around the way to S (degrees off it) and azimuths. */
static const double rescue_tilt[] = {0.0, 30.0, 55.0, 75.0, 88.0};
#define RESCUE_AZIMUTHS 12
/* Step fractions of the way to the band's middle. */
static const double rescue_frac[] = {1.0, 0.5, 0.25, 0.125, 0.0625, 0.03125, 0.0078125};
#define RESCUE_NTILT (sizeof rescue_tilt / sizeof rescue_tilt[0])
#define RESCUE_NFRAC (sizeof rescue_frac / sizeof rescue_frac[0])
#define RESCUE_NCAND (((RESCUE_NTILT - 1) * RESCUE_AZIMUTHS + 1) * RESCUE_NFRAC)
/* Rescue and quality passes again after the quality pass, at most (4
 * rather than 2: doc/design/fit.md). */
#define FIT_LATE_RESCUES 4
/* Rounds over the vertices still beyond the band. */
#define RESCUE_ROUNDS 40
/* A rescue move may not bring its star's score below this (degrees), or
 * below what it was if lower; the quality pass raises it after. */
#define RESCUE_FLOOR 25.0
/* rescue_vertex's lower bound on a candidate's distance to S is dd - st
 * less this (units of h): far more than the rounding of the step and of
 * the distances, so the bound holds; a larger value only tests more. */
#define RESCUE_LB_SLACK 1e-6

static int cmp_rescue(const void *a, const void *b)
{
    const double *x = a, *y = b;   /* {distance, px, py, pz, order} */
    if (x[0] != y[0])
        return x[0] < y[0] ? -1 : 1;
    return (x[4] > y[4]) - (x[4] < y[4]);
}

/* The rescue's search (rescue_vertex) over its candidates cd[0 .. nc),
 * sorted by their distance's lower bound: the index of the first by
 * (distance to S, order) of those closer than dd that keep the star's
 * score floor and the invariant; SIZE_MAX when none does. The threads
 * take the candidates in the bound's order, each while its bound is no
 * more than the best distance found yet (which only falls: the rest are
 * past it too, so nothing closer is left), and a candidate closer than
 * the best, or as close and earlier in order, replaces it: the result is
 * the serial search's. sp (v's, the caller's) serves the first thread. */
static size_t rescue_search(const fit_ctx *c, uint32_t v, double (*cd)[5], size_t nc,
                            double dd, size_t worst, double floor_score, star_pts *sp)
{
    const sm_mesh *sm = &c->sm;
    double best = dd, best_ord = INFINITY;
    size_t bi = SIZE_MAX, next = 0;
    const int par = sm_par_gate_open(c->gate, nc);
    const double t0 = par ? omp_get_wtime() : 0.0;
    double busy = 0.0;
    int team = 1;
    /* v's blocker slots (blocker[v], tblocker[v]) are read and written by
     * sm_move_ok as v's own: here every thread tests v, so only the first
     * uses them; the others test without (they only order exact tests:
     * the same answers) */
    fit_ctx unslotted = *c;
    unslotted.blocker = NULL;
    unslotted.tblocker = NULL;
    #pragma omp parallel reduction(+ : busy) if (par)
    {
        const double b0 = par ? omp_get_wtime() : 0.0;
        if (omp_get_thread_num() == 0)
            team = omp_get_num_threads();
        star_pts own = STAR_PTS_INIT;
        star_pts *tp = omp_get_thread_num() == 0 ? sp : &own;
        const fit_ctx *tc = omp_get_thread_num() == 0 ? c : &unslotted;
        sm_star_pts_collect(c, v, tp);
        for (;;) {
            size_t i;
            double b;
            #pragma omp atomic capture
            i = next++;
            #pragma omp atomic read
            b = best;
            if (i >= nc || cd[i][0] > b)
                break;
            if (!star_keeps_floor(sm, v, cd[i] + 1, worst, floor_score) ||
                !sm_move_ok(tc, v, cd[i] + 1, tp))
                continue;
            int64_t tri;
            double d2 = sm_nearest_d2(c, cd[i] + 1, dd * dd, &tri, NULL);
            double d = tri >= 0 ? sqrt(d2) : INFINITY;
            if (!(d < dd))
                continue;
            #pragma omp critical(st_fit_rescue_best)
            if (d < best || (d == best && cd[i][4] < best_ord)) {
                #pragma omp atomic write
                best = d;
                best_ord = cd[i][4];
                bi = i;
            }
        }
        if (par)
            busy += omp_get_wtime() - b0;
        free(own.list);
    }
    if (par)
        sm_par_gate_note(c->gate, team, omp_get_wtime() - t0, busy);
    return bi;
}

/* A boundary vertex v beyond d_offset whose ODT-plus-pull step the
 * invariant refused is held by S near its star; a step along another
 * direction that still brings it closer to S often passes (it slides past
 * what holds it). Candidates: the directions within 88 degrees of the way
 * to S's nearest point, at fractions of the way to the band's middle; of
 * those that keep the star's score floor and the invariant, the closest to
 * S is taken (the first by order among equals). 1 when
 * v moved. */
static int rescue_vertex(const fit_ctx *c, uint32_t v, star_pts *sp)
{
    const sm_mesh *sm = &c->sm;
    double *x = sm->m->xyz + 3 * (size_t)v;
    double cp[3];
    double dd = sm_dist_to_s(c, x, cp);
    if (!(dd > c->d_offset))
        return 0;
    double n[3], t1[3], t2[3];
    for (int a = 0; a < 3; a++)
        n[a] = (cp[a] - x[a]) / dd;   /* toward S */
    int k = fabs(n[0]) < 0.6 ? 0 : (fabs(n[1]) < 0.6 ? 1 : 2);
    double e[3] = {0, 0, 0};
    e[k] = 1.0;
    t1[0] = n[1] * e[2] - n[2] * e[1];
    t1[1] = n[2] * e[0] - n[0] * e[2];
    t1[2] = n[0] * e[1] - n[1] * e[0];
    double l = sqrt(t1[0] * t1[0] + t1[1] * t1[1] + t1[2] * t1[2]);
    for (int a = 0; a < 3; a++)
        t1[a] /= l;
    t2[0] = n[1] * t1[2] - n[2] * t1[1];
    t2[1] = n[2] * t1[0] - n[0] * t1[2];
    t2[2] = n[0] * t1[1] - n[1] * t1[0];
    double way = dd - FIT_GOAL_FRACTION * c->d_offset;
    double floor_score = fmin(RESCUE_FLOOR, sm_star_score(sm, v, x));
    const size_t worst = star_worst(sm, v);
    double cd[RESCUE_NCAND][5];
    size_t nc = 0, ord = 0;
    for (size_t ti = 0; ti < RESCUE_NTILT; ti++) {
        double th = rescue_tilt[ti] * 3.14159265358979323846 / 180.0;
        int naz = ti == 0 ? 1 : RESCUE_AZIMUTHS;
        for (int az = 0; az < naz; az++) {
            double ph = 2.0 * 3.14159265358979323846 * az / RESCUE_AZIMUTHS;
            double dir[3];
            for (int a = 0; a < 3; a++)
                dir[a] = cos(th) * n[a] + sin(th) * (cos(ph) * t1[a] + sin(ph) * t2[a]);
            for (size_t fi = 0; fi < RESCUE_NFRAC; fi++, ord++) {
                double st = way * rescue_frac[fi];
                for (int a = 0; a < 3; a++)
                    cd[nc][1 + a] = x[a] + st * dir[a];
                cd[nc][0] = dd - st - RESCUE_LB_SLACK * c->h;
                cd[nc][4] = (double)ord;
                nc++;
            }
        }
    }
    /* The candidate taken is the first by (distance to S, order) of those
     * closer than dd that keep the star's score floor and the invariant.
     * Searched by a lower bound on the distance (the step is st long, so
     * the distance is at least dd - st; the slack covers the rounding): in
     * the bound's order, a candidate is tested (the score floor, then the
     * invariant, then the distance: cheapest first, and most candidates
     * fail the floor) while its bound is no more than the best distance
     * found, so a rescue that fails computes no distance, and one that
     * finds a close candidate early tests neither the floor nor the
     * invariant of the candidates whose bound is past it. A candidate that
     * fails the floor changes nothing of the search, so the candidates
     * tested past it, and the one taken, are those of filtering by the
     * floor before the sort (as until batch 55). The candidate taken is so
     * the first by (distance, order) of all that qualify, whatever order
     * they are tested in: rescue_search tests them on several threads. */
    qsort(cd, nc, sizeof cd[0], cmp_rescue);
    size_t bi = rescue_search(c, v, cd, nc, dd, worst, floor_score, sp);
    if (bi == SIZE_MAX)
        return 0;
    memcpy(x, cd[bi] + 1, 3 * sizeof *x);
    return 1;
}

/* The joint rescue runs while at most this many boundary vertices are
 * beyond d_offset: it is for the few a feature narrower than h holds, and
 * each costs a search over its neighbours' steps (doc/design/fit.md). */
#define JOINT_MAX_BEYOND 4
/* Step lengths (units of h) of a neighbour's move in rescue_joint. */
static const double joint_step[] = {0.1, 0.05, 0.025};
#define JOINT_NSTEP (sizeof joint_step / sizeof joint_step[0])

/* A vertex v beyond d_offset that no rescue_vertex step moves is held by a
 * boundary face of its star whose two other corners lie near S: swinging
 * the face about their edge toward S would cut a concave feature of S
 * narrower than h (issue 18: a step between two planes, a hole's rim, a
 * noise bump). Moving one of those neighbours first can open the way:
 * each boundary neighbour u of v, in index order, tries the 26 directions
 * to a cube's neighbours at joint_step lengths; a step that keeps the
 * invariant, u within d_offset of S and u's star score floor is taken
 * when v's rescue then moves, and undone otherwise. 1 when v moved. */
static int rescue_joint(const fit_ctx *c, uint32_t v, star_pts *sp)
{
    const sm_mesh *sm = &c->sm;
    double *xyz = sm->m->xyz;
    for (size_t j = sm->vv_off[v]; j < sm->vv_off[v + 1]; j++) {
        const uint32_t u = sm->vv[j];
        if (!sm->onb[u])
            continue;
        double *xu = xyz + 3 * (size_t)u;
        const double save[3] = {xu[0], xu[1], xu[2]};
        const double floor_score = fmin(RESCUE_FLOOR, sm_star_score(sm, u, save));
        const size_t worst = star_worst(sm, u);
        int collected = 0;
        for (size_t si = 0; si < JOINT_NSTEP; si++)
            for (int dz = -1; dz <= 1; dz++)
                for (int dy = -1; dy <= 1; dy++)
                    for (int dx = -1; dx <= 1; dx++) {
                        if (!dx && !dy && !dz)
                            continue;
                        const double l = joint_step[si] * c->h /
                                         sqrt((double)(dx * dx + dy * dy + dz * dz));
                        const double p[3] = {save[0] + l * dx, save[1] + l * dy,
                                             save[2] + l * dz};
                        if (!(sm_dist_to_s(c, p, NULL) <= c->d_offset) ||
                            !star_keeps_floor(sm, u, p, worst, floor_score))
                            continue;
                        if (!collected) {
                            sm_star_pts_collect(c, u, sp);
                            collected = 1;
                        }
                        if (!sm_move_ok(c, u, p, sp))
                            continue;
                        memcpy(xu, p, sizeof save);
                        collected = 0;   /* sp now holds v's points */
                        if (rescue_vertex(c, v, sp))
                            return 1;
                        memcpy(xu, save, sizeof save);
                    }
    }
    return 0;
}

/* One round of rescue_vertex over the boundary vertices beyond d_offset,
 * in index order; a vertex that did not move and whose star has not
 * changed since is skipped (dy: the dirty set, one step per attempt; it
 * would fail again). Returns the moves. */
static size_t rescue_round(fit_ctx *c, double *dist, dirty *dy, star_pts *sp)
{
    size_t moved = 0;
    for (size_t v = 0; v < c->sm.nv; v++) {
        if (!c->sm.onb[v] || !(dist[v] > c->d_offset))
            continue;
        if (dy->moved_at && sm_dirty_unchanged(dy, &c->sm, (uint32_t)v))
            continue;
        int k = rescue_vertex(c, (uint32_t)v, sp);
        if (dy->moved_at) {
            dy->step++;
            sm_dirty_mark(dy, (uint32_t)v, k);
        }
        if (k) {
            moved++;
            dist[v] = sm_dist_to_s(c, c->sm.m->xyz + 3 * v, NULL);
        }
    }
    return moved;
}

/* Rounds of rescue_vertex over the boundary vertices beyond d_offset, in
 * index order (few vertices, serial: the result does not depend on the
 * thread count), and with joint the joint rescue when a round moves
 * nothing. Each round skips the vertices whose rescue failed with nothing
 * in their star moved since (no memory for the dirty set: none skipped,
 * the same result). Returns the moves. */
static size_t rescue_pass(fit_ctx *c, double *dist, int joint)
{
    size_t moves = 0;
    star_pts sp = STAR_PTS_INIT;
    dirty dy;
    if (sm_dirty_init(&dy, c->sm.nv) != ST_OK)
        sm_dirty_free(&dy);   /* moved_at NULL: no skips */
    for (int round = 0; round < RESCUE_ROUNDS; round++) {
        size_t moved = rescue_round(c, dist, &dy, &sp);
        /* when the rescues alone move nothing, the neighbours first */
        for (size_t v = 0; v < c->sm.nv && moved == 0 && joint; v++)
            if (c->sm.onb[v] && dist[v] > c->d_offset && rescue_joint(c, (uint32_t)v, &sp)) {
                moved++;
                dist[v] = sm_dist_to_s(c, c->sm.m->xyz + 3 * v, NULL);
            }
        if (moved && joint && dy.tried_at)   /* which neighbours moved is not */
            memset(dy.tried_at, 0, c->sm.nv * sizeof *dy.tried_at);   /* kept */
        moves += moved;
        if (moved == 0)
            break;
    }
    sm_dirty_free(&dy);
    free(sp.list);
    return moves;
}

/* While a boundary vertex is beyond d_offset, FIT_LATE_RESCUES times at
 * most: a rescue pass, and when it moved something the quality pass after
 * it (the rescue's floor is below the quality goal); r->ds follows. The
 * plain rescues first; the joint ones (rescue_joint) only for the few
 * vertices those leave: tried while many are still beyond, they change
 * the stars the later plain rescues would have used (doc/design/fit.md). */
static st_status late_rescues(fit_run *r, st_error *err)
{
    fit_ctx *c = &r->c;
    for (int joint = 0; joint <= 1; joint++)
        for (int k = 0; k < FIT_LATE_RESCUES && r->ds.within < c->sm.nbv &&
                        (!joint || c->sm.nbv - r->ds.within <= JOINT_MAX_BEYOND); k++) {
            if (rescue_pass(c, r->dist, joint) == 0)
                break;
            st_status rc = fit_quality(r, err);
            if (rc)
                return rc;
        }
    return ST_OK;
}

/* ---- peeling: boundary tets that hold nothing of S ------------------- */

/* Peel rounds (each exposes new boundary tets) before a quality pass,
 * and such passes at most. */
#define PEEL_ROUNDS 6
#define PEEL_PASSES 2

typedef struct face_query {
    const st_soup *s;
    const double *f[3];
} face_query;

/* 1 when S triangle tri meets the closed face q->f. */
static int peel_face_visit(void *ctx, uint32_t tri)
{
    const face_query *q = ctx;
    const uint32_t *t = q->s->tris + 3 * (size_t)tri;
    return st_tri_tri_intersect(q->f[0], q->f[1], q->f[2], q->s->xyz + 3 * (size_t)t[0],
                                q->s->xyz + 3 * (size_t)t[1], q->s->xyz + 3 * (size_t)t[2]);
}

typedef struct tet_query {
    const st_soup *s;
    const double *t[4];
} tet_query;

/* 1 when a vertex of S triangle tri lies in the closed tet q->t. */
static int tet_vertex_visit(void *ctx, uint32_t tri)
{
    const tet_query *q = ctx;
    const uint32_t *k = q->s->tris + 3 * (size_t)tri;
    for (int i = 0; i < 3; i++)
        if (st_point_in_tet(q->s->xyz + 3 * (size_t)k[i], q->t[0], q->t[1], q->t[2], q->t[3]) !=
            ST_OUTSIDE)
            return 1;
    return 0;
}

/* 1 when some vertex of S lies in the closed tet t: the triangles whose
 * boxes meet the tet's box hold every such vertex. */
static int svertex_in_tet(const fit_ctx *c, const double *t[4])
{
    tet_query q;
    q.s = c->s;
    double lo[3], hi[3];
    for (int a = 0; a < 3; a++) {
        lo[a] = fmin(fmin(t[0][a], t[1][a]), fmin(t[2][a], t[3][a]));
        hi[a] = fmax(fmax(t[0][a], t[1][a]), fmax(t[2][a], t[3][a]));
    }
    for (int i = 0; i < 4; i++)
        q.t[i] = t[i];
    return st_bvh_query_box(c->bvh, lo, hi, tet_vertex_visit, &q) != 0;
}

/* 1 when r and s share a boundary face (rs is a boundary edge). */
static int boundary_edge(const sm_mesh *sm, uint32_t r, uint32_t s)
{
    for (size_t j = sm->vf_off[r]; j < sm->vf_off[r + 1]; j++) {
        const uint32_t *f = sm->bf + 3 * (size_t)sm->vf[j];
        if (f[0] == s || f[1] == s || f[2] == s)
            return 1;
    }
    return 0;
}

/* Whether boundary tet t (nbr: its face neighbours) can go: it holds no
 * vertex of S, none of the faces it would expose meets S (so every S
 * triangle that was inside the mesh still is: one that entered t without
 * a vertex in it crossed a face of t, and its boundary faces are clear),
 * and the boundary stays a manifold: with one boundary face, the corner
 * opposite it is an interior vertex (it becomes a boundary vertex, and
 * must be within d_offset of S); with two, the edge of the two exposed
 * faces is not a boundary edge. Three or four boundary faces: kept. */
static int peelable(const fit_ctx *c, size_t t, const int64_t *nbr)
{
    const sm_mesh *sm = &c->sm;
    const uint32_t *k = sm->m->tets + 4 * t;
    int nb = 0, bc[4];
    for (int i = 0; i < 4; i++)
        if (nbr[4 * t + (size_t)i] < 0)
            bc[nb++] = i;
    if (nb == 1) {
        uint32_t a = k[bc[0]];
        if (sm->onb[a] || !(sm_dist_to_s(c, sm->m->xyz + 3 * (size_t)a, NULL) <= c->d_offset))
            return 0;
    } else if (nb == 2) {
        if (boundary_edge(sm, k[bc[0]], k[bc[1]]))
            return 0;
    } else {
        return 0;
    }
    const double *p[4];
    for (int i = 0; i < 4; i++)
        p[i] = sm->m->xyz + 3 * (size_t)k[i];
    if (svertex_in_tet(c, p))
        return 0;
    for (int i = 0; i < 4; i++) {
        if (nbr[4 * t + (size_t)i] < 0)
            continue;
        face_query q;
        q.s = c->s;
        for (int j = 0, n = 0; j < 4; j++)
            if (j != i)
                q.f[n++] = p[j];
        if (st_bvh_query_tri(c->bvh, q.f[0], q.f[1], q.f[2], peel_face_visit, &q))
            return 0;
    }
    return 1;
}

typedef struct peel_cand {
    double score;
    size_t tet;
} peel_cand;

static int cmp_peel(const void *a, const void *b)
{
    const peel_cand *x = a, *y = b;
    if (x->score != y->score)
        return x->score < y->score ? -1 : 1;
    return (x->tet > y->tet) - (x->tet < y->tet);
}

/* One round: the boundary tets scoring below `goal` that peelable allows,
 * worst first, no two sharing a vertex (so each check sees the mesh it
 * changes), are removed, with their cell arrays; the incidence is rebuilt.
 * *peeled gets the count. A non-conforming mesh is left alone. */
static st_status peel_round(fit_ctx *c, double goal, size_t *peeled, st_error *err)
{
    st_tetmesh *m = c->sm.m;
    *peeled = 0;
    int64_t *nbr = NULL;
    size_t nonmanifold = 0;
    st_status rc = st_tetmesh_neighbors(m, &nbr, &nonmanifold, err);
    if (rc || nonmanifold) {
        free(nbr);
        return rc;
    }
    peel_cand *cand = st_malloc_array(m->ntets ? m->ntets : 1, sizeof *cand);
    unsigned char *gone = st_calloc_array(m->ntets ? m->ntets : 1, 1);
    unsigned char *touched = st_calloc_array(m->npoints ? m->npoints : 1, 1);
    if (!cand || !gone || !touched) {
        rc = st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory (peeling)");
        goto out;
    }
    const st_tet_array *cls = st_tetmesh_find_array(m, "sculpt", ST_ON_CELLS);
    if (cls && (cls->assoc != ST_ON_CELLS || cls->ncomp != 1))
        cls = NULL;
    size_t nc = 0;
    for (size_t t = 0; t < m->ntets; t++) {
        const uint32_t *k = m->tets + 4 * t;
        if (cls && cls->values[t] == (double)ST_SCULPT_VOLUME)
            continue;
        if (nbr[4 * t] >= 0 && nbr[4 * t + 1] >= 0 && nbr[4 * t + 2] >= 0 && nbr[4 * t + 3] >= 0)
            continue;
        double sc = sm_tet_score(m->xyz + 3 * (size_t)k[0], m->xyz + 3 * (size_t)k[1],
                                 m->xyz + 3 * (size_t)k[2], m->xyz + 3 * (size_t)k[3]);
        if (sc < goal) {
            cand[nc].score = sc;
            cand[nc].tet = t;
            nc++;
        }
    }
    qsort(cand, nc, sizeof *cand, cmp_peel);
    for (size_t i = 0; i < nc; i++) {
        size_t t = cand[i].tet;
        const uint32_t *k = m->tets + 4 * t;
        if (touched[k[0]] || touched[k[1]] || touched[k[2]] || touched[k[3]] ||
            !peelable(c, t, nbr))
            continue;
        gone[t] = 1;
        for (int j = 0; j < 4; j++)
            touched[k[j]] = 1;
        (*peeled)++;
    }
    if (*peeled) {
        size_t n = 0;
        for (size_t t = 0; t < m->ntets; t++) {
            if (gone[t])
                continue;
            memmove(m->tets + 4 * n, m->tets + 4 * t, 4 * sizeof *m->tets);
            for (size_t a = 0; a < m->narrays; a++) {
                st_tet_array *ar = &m->arrays[a];
                if (ar->assoc == ST_ON_CELLS)
                    memmove(ar->values + (size_t)ar->ncomp * n, ar->values + (size_t)ar->ncomp * t,
                            (size_t)ar->ncomp * sizeof *ar->values);
            }
            n++;
        }
        m->ntets = n;
        sm_mesh_free(&c->sm);
        rc = sm_mesh_build(&c->sm, m, err);
    }
out:
    free(nbr);
    free(cand);
    free(gone);
    free(touched);
    return rc;
}

/* ---- the schedule ----------------------------------------------------- */

/* The cell width: given, or the mesh's meta "h"; 0 when neither is. */
static double mesh_h(const st_tetmesh *m, double given)
{
    if (given > 0.0)
        return given;
    const char *s = st_meta_get(&m->meta, "h");
    if (!s)
        return 0.0;
    char *end;
    double h = strtod(s, &end);
    if (end == s || !isfinite(h) || !(h > 0.0))
        return 0.0;
    return h;
}

/* st_fit's arguments: ST_OK with *h the cell width, or ST_EINPUT. */
static st_status fit_check(const st_tetmesh *m, const st_soup *s, const st_fit_params *p,
                           double *h, st_error *err)
{
    if (!(p->offset_ratio > 0.0) || !(p->step > 0.0 && p->step <= 1.0) || p->max_iters < 0 ||
        p->quality_rounds < 0 || !(p->cell_width >= 0.0))
        return st_error_set(err, ST_EINPUT, NULL, 0, "bad fit parameters");
    if (m->ntets == 0)
        return st_error_set(err, ST_EINPUT, NULL, 0, "the mesh has no tets");
    if (!s || s->ntris == 0)
        return st_error_set(err, ST_EINPUT, NULL, 0, "the surface has no triangles");
    *h = mesh_h(m, p->cell_width);
    if (!(*h > 0.0))
        return st_error_set(err, ST_EINPUT, NULL, 0,
                            "no cell width: the mesh has no meta \"h\" (give the "
                            "lattice cell width)");
    const st_fit_shared *sh = p->shared;
    if (sh && (sh->s != s || sh->fill != p->fill || sh->h != *h))
        return st_error_set(err, ST_EINPUT, NULL, 0,
                            "the fit's shared set-up was made for another surface, "
                            "fill or cell width");
    size_t bad = sm_count_nonpositive(m);
    if (bad)
        return st_error_set(err, ST_EINPUT, NULL, 0,
                            "%zu of %zu tets are inverted or flat: the fit needs a "
                            "positively oriented mesh", bad, m->ntets);
    return ST_OK;
}

/* The run's context (the invariant's), its arrays, the statistics before
 * and the first distances. */
static st_status fit_open(fit_run *r, st_tetmesh *m, const st_soup *s, const st_bvh *bvh,
                          double h, const st_progress *prog, st_error *err)
{
    st_status rc = sm_fit_ctx_open(&r->c, m, s, bvh, r->p.fill, r->p.shared, h,
                                   r->p.offset_ratio * h, prog, err);
    if (rc)
        return rc;
    if (sm_dirty_init(&r->dy, m->npoints) ||
        !(r->dist = st_malloc_array(m->npoints, sizeof *r->dist)) ||
        !(r->reached = st_calloc_array(m->npoints, 1)))
        return st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory (fit)");
    r->st.h = h;
    r->st.d_offset = r->c.d_offset;
    r->st.boundary_vertices = r->c.sm.nbv;
    sm_dihedral_range(m, &r->st.min_dihedral_before, &r->st.max_dihedral_before);
    if (r->p.count_before &&
        (rc = st_enclosure_count(m, s, r->c.bvh, &r->st.outside_before,
                                 &r->st.crossing_before, err)))
        return rc;
    r->ds = sm_boundary_distances(&r->c, r->dist);
    return ST_OK;
}

static void fit_close(fit_run *r)
{
    free(r->save);
    free(r->reached);
    free(r->dist);
    sm_dirty_free(&r->dy);
    sm_fit_ctx_close(&r->c);
}

/* One colour set's fit moves, in parallel over the vertices to try
 * (sm_dirty_todo); *n counts. */
static void fit_colour(fit_run *r, size_t col, fit_counts *n)
{
    const fit_ctx *c = &r->c;
    size_t moved = 0, rejected = 0, skipped = 0;
    r->dy.step++;
    const size_t nt = sm_dirty_todo(&r->dy, &c->sm, col, NULL);
    const uint32_t *todo = r->dy.todo;
    /* the rest would fail as they did */
    n->skipped += c->sm.col_off[col + 1] - c->sm.col_off[col] - nt;
    const int par = sm_par_gate_open(c->gate, nt);
    const double t0 = par ? omp_get_wtime() : 0.0;
    double busy = 0.0;
    int team = 1;
    #pragma omp parallel reduction(+ : moved, rejected, skipped, busy) if (par)
    {
        const double b0 = par ? omp_get_wtime() : 0.0;
        star_pts sp = STAR_PTS_INIT;
        if (omp_get_thread_num() == 0)
            team = omp_get_num_threads();
        #pragma omp for schedule(dynamic, 1) nowait
        for (size_t j = 0; j < nt; j++) {
            fit_counts k = {0, 0, 0};
            uint32_t v = todo[j];
            sm_dirty_mark(&r->dy, v, fit_vertex(c, v, r->p.step, r->dist, &sp, &k));
            moved += k.moved;
            rejected += k.rejected;
            skipped += k.skipped;
        }
        if (par)
            busy += omp_get_wtime() - b0;
        free(sp.list);
    }
    if (par)
        sm_par_gate_note(c->gate, team, omp_get_wtime() - t0, busy);
    n->moved += moved;
    n->rejected += rejected;
    n->skipped += skipped;
}

/* The rescue pass tried in the middle of the fit (FIT_EARLY_RESCUE):
 * 1 when it brought every boundary vertex within d_offset, and the fit
 * stops; 0 when it did not, and the positions and distances are as they
 * were (so the fit goes on exactly as without the trial: the dirty set
 * still holds), or when there is no memory for the undo. */
static int early_rescue(fit_run *r)
{
    fit_ctx *c = &r->c;
    const size_t np = c->sm.m->npoints;
    if (!r->save && !(r->save = st_malloc_array(np, 4 * sizeof *r->save)))
        return 0;   /* no undo, no trial: the fit goes on as it would */
    memcpy(r->save, c->sm.m->xyz, 3 * np * sizeof *r->save);
    memcpy(r->save + 3 * np, r->dist, np * sizeof *r->save);
    if (rescue_pass(c, r->dist, 0) > 0) {
        dist_summary ds = sm_boundary_distances(c, r->dist);
        if (ds.within == c->sm.nbv) {
            r->ds = ds;
            return 1;
        }
    }
    memcpy(c->sm.m->xyz, r->save, 3 * np * sizeof *r->save);
    memcpy(r->dist, r->save + 3 * np, np * sizeof *r->save);
    return 0;
}

/* Marks the boundary vertices within d_offset as reached; how many were
 * not before. */
static size_t fit_reached(fit_run *r)
{
    const sm_mesh *sm = &r->c.sm;
    size_t fresh = 0;
    for (size_t v = 0; v < sm->nv; v++)
        if (sm->onb[v] && !r->reached[v] && !(r->dist[v] > r->c.d_offset)) {
            r->reached[v] = 1;
            fresh++;
        }
    return fresh;
}

/* The paper's iterations until every boundary vertex is within d_offset
 * (or an early rescue pass brings them there), an iteration moves
 * nothing, FIT_STALL_ITERS in a row bring no boundary vertex into the
 * band that had never been in it, or max_iters; then a rescue pass. */
static st_status fit_iterate(fit_run *r, st_error *err)
{
    fit_ctx *c = &r->c;
    int since_best = 0, failed_trials = 0;
    fit_reached(r);
    for (int it = 0; it < r->p.max_iters && r->ds.within < c->sm.nbv; it++) {
        if (st_progress_cancelled(c->prog))
            return st_error_set(err, ST_ECANCELLED, NULL, 0, "cancelled");
        st_progress_report(c->prog, "fit",
                           (double)r->ds.within / (double)(c->sm.nbv ? c->sm.nbv : 1));
        fit_counts n = {0, 0, 0};
        for (size_t col = 0; col < c->sm.ncolours; col++)
            fit_colour(r, col, &n);
        r->st.iters = it + 1;
        r->st.moves += n.moved;
        r->st.rejected += n.rejected;
        r->st.skipped += n.skipped;
        r->ds = sm_boundary_distances(c, r->dist);
        sm_fit_report(&r->p, c, "fit", it + 1, &r->ds, &n, r->t0);
        if (n.moved == 0)
            break;
        if (fit_reached(r) > 0) {
            since_best = 0;
        } else if (++since_best >= FIT_STALL_ITERS) {
            break;   /* the rest are held back, or swing in and out */
        }
        if (failed_trials < FIT_EARLY_TRIALS &&
            (since_best == FIT_EARLY_RESCUE ||
             (since_best == 0 && c->sm.nbv - r->ds.within <= FIT_EARLY_FEW))) {
            if (early_rescue(r))
                break;   /* every boundary vertex within: no stall to wait out */
            failed_trials++;
        }
    }
    if (r->ds.within < c->sm.nbv) {
        rescue_pass(c, r->dist, 0);
        r->ds = sm_boundary_distances(c, r->dist);
    }
    r->st.converged = r->ds.within == c->sm.nbv;
    sm_dihedral_range(c->sm.m, &r->st.min_dihedral_fit, &r->st.max_dihedral_fit);
    r->st.seconds_fit = sm_now() - r->t0;
    return ST_OK;
}

/* Peeling: boundary tets below the goal that hold nothing of S go
 * (peel_round, PEEL_ROUNDS rounds), and the quality pass runs on the new
 * boundary; PEEL_PASSES times at most. */
static st_status fit_peel(fit_run *r, st_error *err)
{
    st_status rc = ST_OK;
    for (int k = 0; k < PEEL_PASSES && r->p.peel && rc == ST_OK; k++) {
        size_t peeled = 0, n;
        for (int round = 0; round < PEEL_ROUNDS; round++, peeled += n)
            if ((rc = peel_round(&r->c, r->p.quality_goal, &n, err)) || n == 0)
                break;
        if (rc || peeled == 0)
            break;
        r->st.peeled += peeled;
        r->ds = sm_boundary_distances(&r->c, r->dist);
        rc = fit_quality(r, err);
    }
    return rc;
}

/* After the fit: the quality pass; the late rescues (its moves change the
 * stars of the vertices still held); a last quality pass that also steps
 * along the 26 cube directions (last, so that the rescues run as before:
 * it keeps every boundary vertex within max(d_offset, its distance) and
 * raises the lowest score of every star it changes, so neither the beyond
 * count nor the worst score can get worse); the peeling; and the late
 * rescues once more, since the cube steps and the peeling changed the held
 * vertices' stars too (doc/design/fit.md). */
static st_status fit_polish(fit_run *r, st_error *err)
{
    st_status rc;
    st_progress_report(r->c.prog, "quality", 0.0);
    if ((rc = fit_quality(r, err)) || (rc = late_rescues(r, err)))
        return rc;
    r->c.cube_steps = 1;
    if ((rc = fit_quality(r, err)) || (rc = fit_peel(r, err)))
        return rc;
    return late_rescues(r, err);
}

/* The statistics after, and the enclosure count. */
static st_status fit_finish(fit_run *r, st_error *err)
{
    const fit_ctx *c = &r->c;
    st_fit_stats *st = &r->st;
    st->boundary_vertices = c->sm.nbv;
    st->within_offset = r->ds.within;
    st->converged = r->ds.within == c->sm.nbv;
    st->beyond_offset = c->sm.nbv - r->ds.within;
    st->max_distance = r->ds.max;
    st->mean_distance = r->ds.mean;
    sm_dihedral_range(c->sm.m, &st->min_dihedral_after, &st->max_dihedral_after);
    st->seconds_quality = sm_now() - r->t0 - st->seconds_fit;
    st_status rc = st_enclosure_count(c->sm.m, c->s, c->bvh, &st->outside_after,
                                      &st->crossing_after, err);
    st_progress_report(c->prog, "quality", 1.0);
    return rc;
}

st_status st_fit(st_tetmesh *m, const st_soup *s, const st_bvh *bvh,
                 const st_fit_params *pp, st_fit_stats *stats,
                 const st_progress *prog, st_error *err)
{
    fit_run r;
    memset(&r, 0, sizeof r);
    r.p = pp ? *pp : st_fit_params_default();
    r.t0 = sm_now();
    double h = 0.0;
    st_status rc = fit_check(m, s, &r.p, &h, err);
    if (rc == ST_OK)
        rc = fit_open(&r, m, s, bvh, h, prog, err);
    if (rc == ST_OK)
        rc = fit_iterate(&r, err);
    if (rc == ST_OK && r.p.quality)
        rc = fit_polish(&r, err);
    if (rc == ST_OK)
        rc = fit_finish(&r, err);
    if (stats)
        *stats = r.st;
    fit_close(&r);
    return rc;
}
