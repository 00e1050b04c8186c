/*
 * quality.c - the quality pass of st_fit (past the paper), and on a mesh
 * without a surface, fairing's (sm_quality_interior, sm_quality_fair).
 *
 * It works on the vertices of the tets whose score min(min dihedral,
 * 0.75 (180 - max dihedral)) is below the goal: for each, a handful of
 * candidate positions (toward its ODT target, toward its neighbours'
 * centroid, line searches along the gradient of its worst tet's score and
 * along the summed unit gradients of the tets within QUAL_ACTIVE of the
 * worst, small steps along the axes), best first; the first that raises
 * the lowest score of the star and keeps the fit's invariant (invariant.c; and,
 * for a boundary vertex, keeps it within max(d_offset, its distance) of
 * S) is taken. A boundary vertex at the band's edge, or past it where a
 * thin gap held it back, can take no step with an outward component, and
 * those are most of the gradient steps: on the armadillo the worst tets
 * (21.7 degrees) all had such vertices, every candidate refused by the
 * distance rule. So a boundary vertex also searches the same gradients
 * projected onto the tangent plane of S's distance (and a little inward
 * of it). Where several tets of a star are within a fraction of a degree
 * of the worst (a plateau: the worst tet's gradient lowers the next, the
 * summed one cancels), steps along the 26 directions to a cube's
 * neighbours at 0.1, 0.04 and 0.015 h still find a way up; st_fit adds
 * them (cube_steps) in one last pass after its rescues (doc/design/fit.md
 * says why). Rounds repeat until no tet scores below the goal or nothing
 * moves. Vertices move colour by colour, within a colour in parallel,
 * each check reading only its own star: the result does not depend on
 * the thread count.
 *
 * quality_vertex builds the candidates of one move in a qual_move, step
 * by step (qual_towards, qual_gradients, qual_gradient_steps,
 * qual_tangent_steps, qual_axis_steps), and qual_take tries them.
 */
#include "quality.h"
#include "../base/fpenv.h"

#include "souptet/mem.h"

#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

/* Quality pass: the smallest score gain (degrees) worth a move, so rounds
 * end instead of trading rounding noise. */
#define QUAL_MIN_GAIN 1e-3
/* Line search steps along the score gradient, in units of h. */
static const double qual_steps[] = {0.2, 0.1, 0.05, 0.025, 0.0125, 0.00625};
#define QUAL_NSTEPS (sizeof qual_steps / sizeof qual_steps[0])
/* Tangential candidates of a boundary vertex: inward components, as a
 * fraction of the step (0: in the tangent plane; 0.25: a quarter inward,
 * which keeps the distance from growing where S curves away by up to
 * about 14 degrees over the step). */
static const double qual_inward[] = {0.0, 0.25};
#define QUAL_NTANGENT 2
/* Tets within this many degrees of the worst one steer the combined
 * gradient direction. */
#define QUAL_ACTIVE 2.0
/* The axis-direction candidates' step, in units of h. */
#define QUAL_AXIS_STEP 0.03
/* Step lengths (units of h) along the 26 cube-neighbour directions. */
static const double qual_sphere[] = {0.1, 0.04, 0.015};
#define QUAL_NSPHERE (sizeof qual_sphere / sizeof qual_sphere[0])
/* Central-difference step for the score gradient, in units of h. */
#define QUAL_GRAD_EPS 1e-4
/* Candidates of one move at most: the ODT and centroid steps, the two
 * gradients' line searches, their tangential ones, the axes, the cube. */
#define QUAL_NCAND (5 + 2 * QUAL_NSTEPS + 2 * QUAL_NTANGENT * QUAL_NSTEPS + 6 + \
                    26 * QUAL_NSPHERE)

static int cmp_cand(const void *a, const void *b)
{
    const double *x = a, *y = b;   /* {score, px, py, pz, order} */
    if (x[0] != y[0])
        return x[0] > y[0] ? -1 : 1;
    return (x[4] > y[4]) - (x[4] < y[4]);
}

/* The sum of the area-weighted outward normals of v's boundary faces. */
static void fair_normal(const sm_mesh *sm, uint32_t v, double n[3])
{
    n[0] = n[1] = n[2] = 0.0;
    for (size_t j = sm->vf_off[v]; j < sm->vf_off[v + 1]; j++) {
        const uint32_t *f = sm->bf + 3 * (size_t)sm->vf[j];
        const double *a = sm->m->xyz + 3 * (size_t)f[0];
        const double *b = sm->m->xyz + 3 * (size_t)f[1];
        const double *d = sm->m->xyz + 3 * (size_t)f[2];
        double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
        double w[3] = {d[0] - a[0], d[1] - a[1], d[2] - a[2]};
        n[0] += u[1] * w[2] - u[2] * w[1];
        n[1] += u[2] * w[0] - u[0] * w[2];
        n[2] += u[0] * w[1] - u[1] * w[0];
    }
    double l = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (l > 0.0 && isfinite(l))
        for (int a = 0; a < 3; a++)
            n[a] /= l;
    else
        n[0] = n[1] = n[2] = 0.0;
}

/* One quality move of v: its candidate positions and what they are
 * built from. */
typedef struct qual_move {
    uint32_t v;
    const double *x;      /* v's position */
    double s0;            /* the lowest score of v's star as it is */
    int tangent_only;     /* no surface, a boundary vertex: fair_boundary */
    size_t worst;         /* the star's lowest-scoring tet (from vt_off[v]) */
    double gw[3], ga[3];  /* the worst tet's unit score gradient, and the
                             sum over the tets within QUAL_ACTIVE of it */
    double dx, nrm[3];    /* with S: the distance to it and the unit way
                             away from it; tangent_only: 1 and the
                             boundary's normal (0: none) */
    int nc;
    double cand[QUAL_NCAND][5];   /* {score, x, y, z, order} */
} qual_move;

/* Toward the ODT target (1, 1/2, 1/4 of the way) and toward the
 * neighbours' centroid (1, 1/2). */
static void qual_towards(const fit_ctx *c, qual_move *q)
{
    const sm_mesh *sm = &c->sm;
    const uint32_t v = q->v;
    const double *x = q->x;
    double t[3];
    sm_odt_target(sm, v, t);
    static const double fr[] = {1.0, 0.5, 0.25};
    for (int k = 0; k < 3; k++, q->nc++)
        for (int a = 0; a < 3; a++)
            q->cand[q->nc][1 + a] = x[a] + fr[k] * (t[a] - x[a]);
    double cen[3] = {0, 0, 0};
    size_t deg = sm->vv_off[v + 1] - sm->vv_off[v];
    for (size_t j = sm->vv_off[v]; j < sm->vv_off[v + 1]; j++)
        for (int a = 0; a < 3; a++)
            cen[a] += sm->m->xyz[3 * (size_t)sm->vv[j] + (size_t)a] / (double)deg;
    for (int k = 0; k < 2; k++, q->nc++)
        for (int a = 0; a < 3; a++)
            q->cand[q->nc][1 + a] = x[a] + fr[k] * (cen[a] - x[a]);
}

/* The gradients (central differences) of the worst tet's score, and the
 * sum of the unit gradients of every tet within QUAL_ACTIVE degrees of it
 * (so that raising the worst does not just lower the next one). */
static void qual_gradients(const fit_ctx *c, qual_move *q)
{
    const sm_mesh *sm = &c->sm;
    const uint32_t v = q->v;
    const double *x = q->x;
    double ws = q->s0, e = QUAL_GRAD_EPS * c->h, best = INFINITY, lowest = INFINITY;
    for (size_t j = sm->vt_off[v]; j < sm->vt_off[v + 1]; j++) {
        const uint32_t *k = sm->m->tets + 4 * (size_t)sm->vt[j];
        const double *p[4];
        for (int i = 0; i < 4; i++)
            p[i] = sm->m->xyz + 3 * (size_t)k[i];
        double sc = sm_tet_score(p[0], p[1], p[2], p[3]);
        if (sc < lowest) {
            lowest = sc;
            q->worst = j - sm->vt_off[v];
        }
        if (sc > ws + QUAL_ACTIVE)
            continue;
        double g[3];
        for (int a = 0; a < 3; a++) {
            double pp[3], pm[3];
            memcpy(pp, x, sizeof pp);
            memcpy(pm, x, sizeof pm);
            pp[a] += e;
            pm[a] -= e;
            const double *qp[4], *qm[4];
            for (int i = 0; i < 4; i++) {
                qp[i] = k[i] == v ? pp : p[i];
                qm[i] = k[i] == v ? pm : p[i];
            }
            g[a] = sm_tet_score(qp[0], qp[1], qp[2], qp[3]) -
                   sm_tet_score(qm[0], qm[1], qm[2], qm[3]);
        }
        double gl = sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
        if (!(gl > 0.0) || !isfinite(gl))
            continue;
        for (int a = 0; a < 3; a++)
            q->ga[a] += g[a] / gl;
        if (sc < best) {
            best = sc;
            for (int a = 0; a < 3; a++)
                q->gw[a] = g[a] / gl;
        }
    }
}

/* Line searches along both gradients. */
static void qual_gradient_steps(const fit_ctx *c, qual_move *q)
{
    const double *dirs[2] = {q->gw, q->ga};
    for (int d = 0; d < 2; d++) {
        const double *g = dirs[d];
        double gl = sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
        if (gl > 0.0 && isfinite(gl))
            for (size_t k = 0; k < QUAL_NSTEPS; k++, q->nc++)
                for (int a = 0; a < 3; a++)
                    q->cand[q->nc][1 + a] = q->x[a] + qual_steps[k] * c->h * g[a] / gl;
    }
}

/* A boundary vertex may not move away from S beyond the band (nor beyond
 * where it is), so at the band's edge or past it (held back by a thin
 * gap) every step with an outward component fails: the same gradients
 * within the tangent plane of S's distance too, and slightly inward of
 * it, where the surface curves away. With tangent_only, the boundary's
 * area-weighted normal instead (the gradient of the volume in v, so steps
 * across it keep the volume to first order), and only those candidates. */
static void qual_tangent_steps(const fit_ctx *c, qual_move *q)
{
    const sm_mesh *sm = &c->sm;
    if (c->s && sm->onb[q->v]) {
        double cp[3];
        q->dx = sm_dist_to_s(c, q->x, cp);
        if (q->dx > 0.0)
            for (int a = 0; a < 3; a++)
                q->nrm[a] = (q->x[a] - cp[a]) / q->dx;
    }
    if (q->tangent_only) {
        q->nc = 0;
        fair_normal(sm, q->v, q->nrm);
        q->dx = q->nrm[0] != 0.0 || q->nrm[1] != 0.0 || q->nrm[2] != 0.0 ? 1.0 : 0.0;
    }
    if (!(q->dx > 0.0))
        return;
    const double *dirs[2] = {q->gw, q->ga}, *nrm = q->nrm;
    for (int d = 0; d < 2; d++) {
        const double *g = dirs[d];
        double gn = g[0] * nrm[0] + g[1] * nrm[1] + g[2] * nrm[2];
        double gt[3] = {g[0] - gn * nrm[0], g[1] - gn * nrm[1], g[2] - gn * nrm[2]};
        double gl = sqrt(gt[0] * gt[0] + gt[1] * gt[1] + gt[2] * gt[2]);
        if (!(gl > 0.0) || !isfinite(gl))
            continue;
        for (int b = 0; b < (q->tangent_only ? 1 : QUAL_NTANGENT); b++)
            for (size_t k = 0; k < QUAL_NSTEPS; k++, q->nc++) {
                double st = qual_steps[k] * c->h;
                for (int a = 0; a < 3; a++)
                    q->cand[q->nc][1 + a] =
                        q->x[a] + st * (gt[a] / gl - qual_inward[b] * nrm[a]);
            }
    }
}

/* The six axis directions, a small step (a way out where the gradients
 * point into the invariant); with cube_steps the 26 directions to a
 * cube's neighbours at a few step lengths (where the worst tets'
 * gradients cancel, a plateau of equally bad tets, a step off them may
 * still raise the lowest score). Not with tangent_only. */
static void qual_axis_steps(const fit_ctx *c, qual_move *q)
{
    const double *x = q->x;
    if (q->tangent_only)
        return;
    for (int a = 0; a < 6; a++, q->nc++)
        for (int b = 0; b < 3; b++)
            q->cand[q->nc][1 + b] =
                x[b] + (b == a / 2 ? (a & 1 ? -1.0 : 1.0) * QUAL_AXIS_STEP * c->h : 0.0);
    for (int dz = -1; dz <= 1 && c->cube_steps; dz++)
        for (int dy = -1; dy <= 1; dy++)
            for (int dxx = -1; dxx <= 1; dxx++) {
                if (!dxx && !dy && !dz)
                    continue;
                double l = sqrt((double)(dxx * dxx + dy * dy + dz * dz));
                for (size_t k = 0; k < QUAL_NSPHERE; k++, q->nc++) {
                    double st = qual_sphere[k] * c->h / l;
                    q->cand[q->nc][1] = x[0] + st * dxx;
                    q->cand[q->nc][2] = x[1] + st * dy;
                    q->cand[q->nc][3] = x[2] + st * dz;
                }
            }
}

/* 1 when candidate p of a boundary vertex is surely within dmax of S:
 * the distance q->dx at x plus the way to p (the triangle inequality),
 * with room for the rounding of both distances (far more than it), is
 * within it. Otherwise the distance decides (qual_take). */
static int near_enough(const fit_ctx *c, const qual_move *q, const double p[3], double dmax)
{
    double w[3] = {p[0] - q->x[0], p[1] - q->x[1], p[2] - q->x[2]};
    double mag = 0.0;
    for (int a = 0; a < 3; a++)
        mag = fmax(mag, fmax(fabs(p[a]), fabs(q->x[a])));
    double slack = 1e-9 * (c->h + dmax + mag);
    return q->dx + sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]) <= dmax - slack;
}

/* Score the candidates: cand[i][0] is candidate i's score when exact[i],
 * else an upper bound on it (a tet's score at or below the cut it was
 * scored against; sm_star_score_above). Each is cut at the best exact
 * score so far (thr at least): one at or below that cannot come first,
 * and most end after a tet or two instead of scoring the whole star. */
static void qual_score(const sm_mesh *sm, qual_move *q, double thr, unsigned char *exact)
{
    double best = thr;
    for (int i = 0; i < q->nc; i++) {
        double x = sm_star_score_above(sm, q->v, q->cand[i] + 1, q->worst, best);
        q->cand[i][0] = x;
        q->cand[i][4] = i;
        exact[i] = x > best || best == thr;   /* at or below thr: never tried */
        if (x > best)
            best = x;
    }
}

/* The candidates by score, best first; the first that raises the star's
 * lowest score by QUAL_MIN_GAIN, keeps a boundary vertex within
 * max(d_offset, its distance) of S and keeps the invariant is taken.
 * The order is found lazily (qual_score): sorted by the scores and
 * bounds, a bound that reaches the front is scored exactly (cut at thr)
 * and moved back to its place; a score at the front is then at least
 * every bound behind it (and ahead of equal ones by order), so the
 * candidates are tried in the order of the exact scores, as a full sort
 * of them would give. 1 when v moved; *rejected counts the invariant's
 * refusals. */
static int qual_take(const fit_ctx *c, qual_move *q, star_pts *sp, size_t *rejected)
{
    const sm_mesh *sm = &c->sm;
    const uint32_t v = q->v;
    if (q->nc == 0)
        return 0;
    /* a candidate at or below the gain's threshold is never tried, and
     * any score there sorts it after those that are: the worst tet as it
     * is, scored first, turns most of them away after one tet */
    const double thr = q->s0 + QUAL_MIN_GAIN;
    unsigned char exact[QUAL_NCAND];
    qual_score(sm, q, thr, exact);
    qsort(q->cand, (size_t)q->nc, sizeof q->cand[0], cmp_cand);
    if (!(q->cand[0][0] > thr))
        return 0;
    sm_star_pts_collect(c, v, sp);
    double dmax = fmax(c->d_offset, q->dx);
    for (int i = 0; i < q->nc;) {
        if (!(q->cand[i][0] > thr))
            break;
        const int o = (int)q->cand[i][4];
        if (!exact[o]) {
            q->cand[i][0] = sm_star_score_above(sm, v, q->cand[i] + 1, q->worst, thr);
            exact[o] = 1;
            for (int j = i; j + 1 < q->nc && cmp_cand(q->cand[j], q->cand[j + 1]) > 0; j++) {
                double t[5];
                memcpy(t, q->cand[j], sizeof t);
                memcpy(q->cand[j], q->cand[j + 1], sizeof t);
                memcpy(q->cand[j + 1], t, sizeof t);
            }
            continue;
        }
        const double *p = q->cand[i++] + 1;
        if (sm->onb[v] && c->s && !near_enough(c, q, p, dmax)) {
            int64_t tri;
            double d2 = sm_nearest_d2(c, p, dmax * dmax, &tri, NULL);
            if (tri < 0 || sqrt(d2) > dmax)
                continue;
        }
        if (sm_move_ok(c, v, p, sp)) {
            memcpy(sm->m->xyz + 3 * (size_t)v, p, 3 * sizeof *p);
            return 1;
        }
        (*rejected)++;
    }
    return 0;
}

/* Try to raise the lowest score of v's star; 1 when v moved. */
static int quality_vertex(const fit_ctx *c, uint32_t v, star_pts *sp, size_t *rejected)
{
    const sm_mesh *sm = &c->sm;
    qual_move q;
    q.v = v;
    q.x = sm->m->xyz + 3 * (size_t)v;
    /* no surface (after fairing): the boundary stays, or with
     * fair_boundary moves only within its tangent plane */
    q.tangent_only = !c->s && sm->onb[v];
    if (q.tangent_only && !c->fair_boundary)
        return 0;
    q.s0 = sm_star_score(sm, v, q.x);
    q.worst = SIZE_MAX;   /* none: qual_gradients finds it */
    q.nc = 0;
    q.dx = 0.0;
    for (int a = 0; a < 3; a++)
        q.gw[a] = q.ga[a] = q.nrm[a] = 0.0;
    qual_towards(c, &q);
    qual_gradients(c, &q);
    qual_gradient_steps(c, &q);
    qual_tangent_steps(c, &q);
    qual_axis_steps(c, &q);
    return qual_take(c, &q, sp, rejected);
}

/* Mark the corners of the tets scoring below goal; the count of those. */
static size_t qual_mark(const st_tetmesh *m, double goal, unsigned char *mark)
{
    size_t nbad = 0;
    for (size_t t = 0; t < m->ntets; t++) {
        const uint32_t *k = m->tets + 4 * t;
        double sc = sm_tet_score(m->xyz + 3 * (size_t)k[0], m->xyz + 3 * (size_t)k[1],
                                 m->xyz + 3 * (size_t)k[2], m->xyz + 3 * (size_t)k[3]);
        if (sc < goal) {
            nbad++;
            for (int i = 0; i < 4; i++)
                mark[k[i]] = 1;
        }
    }
    return nbad;
}

/* One colour set's quality moves of the marked vertices, in parallel over
 * those to try (sm_dirty_todo); *moved and *rejected count. */
static void qual_colour(const fit_ctx *c, size_t col, const unsigned char *mark, dirty *dy,
                        size_t *moved, size_t *rejected)
{
    const sm_mesh *sm = &c->sm;
    size_t mv = 0, rj = 0;
    dy->step++;
    const size_t nt = sm_dirty_todo(dy, sm, col, mark);
    const uint32_t *todo = dy->todo;
    const int par = sm_par_gate_open(c->gate, nt);
    const double t0 = par ? omp_get_wtime() : 0.0;
    double busy = 0.0;
    int team = 1;
    #pragma omp parallel reduction(+ : mv, rj, busy) if (par)
    {
        const double b0 = par ? omp_get_wtime() : 0.0;
        star_pts sp = STAR_PTS_INIT;
        if (omp_get_thread_num() == 0)
            team = omp_get_num_threads();
        #pragma omp for schedule(dynamic, 1) nowait
        for (size_t j = 0; j < nt; j++) {
            uint32_t v = todo[j];
            int k = quality_vertex(c, v, &sp, &rj);
            sm_dirty_mark(dy, v, k);
            mv += (size_t)k;
        }
        if (par)
            busy += omp_get_wtime() - b0;
        free(sp.list);
    }
    if (par)
        sm_par_gate_note(c->gate, team, omp_get_wtime() - t0, busy);
    *moved += mv;
    *rejected += rj;
}

st_status sm_quality_pass(fit_ctx *c, const st_fit_params *p, double *dist,
                          st_fit_stats *st, double t0, st_error *err)
{
    sm_mesh *sm = &c->sm;
    st_status rc = ST_OK;
    dirty dy;
    memset(&dy, 0, sizeof dy);
    unsigned char *mark = st_calloc_array(sm->nv, 1);
    if (!mark || sm_dirty_init(&dy, sm->nv)) {
        rc = st_error_set(err, ST_ENOMEM, NULL, 0,
                          "out of memory for the quality pass (%zu vertices)", sm->nv);
        goto done;
    }
    for (int round = 0; round < p->quality_rounds; round++) {
        if (st_progress_cancelled(c->prog)) {
            rc = st_error_set(err, ST_ECANCELLED, NULL, 0, "cancelled");
            goto done;
        }
        memset(mark, 0, sm->nv);
        if (qual_mark(sm->m, p->quality_goal, mark) == 0)
            break;
        size_t moved = 0, rejected = 0;
        for (size_t col = 0; col < sm->ncolours; col++)
            qual_colour(c, col, mark, &dy, &moved, &rejected);
        st->quality_rounds = round + 1;
        st->quality_moves += moved;
        st_progress_report(c->prog, "quality",
                           (double)(round + 1) / (double)p->quality_rounds);
        if (p->on_iter && c->s) {
            dist_summary ds = sm_boundary_distances(c, dist);
            fit_counts n = {moved, rejected, 0};
            sm_fit_report(p, c, "quality", round + 1, &ds, &n, t0);
        }
        if (moved == 0)
            break;
    }
done:
    free(mark);
    sm_dirty_free(&dy);
    return rc;
}

/* The quality pass on a borrowed mesh (fairing's), with or without the
 * boundary's tangent moves. No surface: of the fit's parameters only the
 * rounds and the goal count (no on_iter). */
static st_status quality_on(sm_mesh *sm, double h, int rounds, double goal, int boundary,
                            size_t *moves, st_error *err)
{
    fit_ctx c;
    memset(&c, 0, sizeof c);
    c.sm = *sm;   /* borrowed: not freed here */
    c.gate = &c.own_gate;
    c.pg = &c.own_pg;   /* empty: no surface */
    c.h = h;
    c.fair_boundary = boundary;
    st_fit_params p;
    memset(&p, 0, sizeof p);
    p.quality_rounds = rounds;
    p.quality_goal = goal;
    st_fit_stats st;
    memset(&st, 0, sizeof st);
    st_status rc = sm_quality_pass(&c, &p, NULL, &st, 0.0, err);
    *moves = st.quality_moves;
    return rc;
}

st_status sm_quality_interior(sm_mesh *sm, double h, int rounds, double goal,
                              size_t *moves, st_error *err)
{
    return quality_on(sm, h, rounds, goal, 0, moves, err);
}

st_status sm_quality_fair(sm_mesh *sm, double h, int rounds, double goal, size_t *moves,
                          st_error *err)
{
    return quality_on(sm, h, rounds, goal, 1, moves, err);
}
