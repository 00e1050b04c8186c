/*
 * fair.c - volume-keeping boundary fairing of a tet mesh (st_fair,
 * smooth.h).
 *
 * Spillmann, Wagner, Teschner 2006, section 4: "a smoothing filter similar
 * to [Desbrun et al. 1999] ... the mesh is locally scaled back to its
 * original volume". One step here:
 *
 *   1. Implicit fairing of the boundary vertices X: solve
 *      (I + lambda_dt L) X' = X, L = D - W the graph Laplacian of the
 *      boundary edges with uniform weights (the umbrella operator before
 *      its normalisation by the degree, which makes the matrix symmetric
 *      positive definite, so plain conjugate gradients solve it; Desbrun
 *      et al. use the normalised umbrella with a non-symmetric solver).
 *   2. Local rescale: every boundary vertex moves along its own area-
 *      weighted normal by one common distance delta, found by bracketing
 *      and regula falsi on the enclosed volume (a cubic in delta), so the
 *      volume comes back as a thin uniform layer over the faired surface
 *      rather than by a global scaling about a centre, which would shift
 *      far-away parts of a non-convex mesh. (Weighting delta by each
 *      vertex's fairing displacement was tried: it pushes the corners the
 *      fairing rounded right back out.)
 *   3. The boundary displacement is extended into the interior (Gauss-
 *      Seidel on the harmonic equation, boundary fixed), and every vertex
 *      moves by its displacement, checked: the tets of its star must stay
 *      positively oriented (exact st_orient3d); otherwise the move is
 *      halved, down to nothing. Sweeps repeat so that vertices held back by
 *      a neighbour catch up once it has moved.
 *   4. Interior vertices relax toward their ODT targets (volume-weighted
 *      circumcenter means), checked the same way (interior moves never
 *      change the volume of a conforming mesh).
 *   5. What the back-offs cost in volume is corrected by further rescale
 *      passes until within FAIR_VOLUME_AIM.
 *
 * After the last step, st_fit's quality pass (quality.c) runs on the interior
 * vertices, which raises the worst angles without touching the volume.
 * Every move, in every phase, keeps its star positive (exact) and may not
 * bring its star's score below p.min_angle (or below what it already was).
 * Positive orientation alone lets thin parts of a coarse density lattice
 * flatten to 0.01 degrees (the bunny at 8 cells); a floor of 10 degrees
 * ends at 10..166, 20 degrees at 20..153 with the volume still within
 * 0.01% (8, 12 and 16 cells), so 20 is the default.
 */
#include "quality.h"
#include "smooth_mesh.h"
#include "../base/fpenv.h"

#include "souptet/mem.h"
#include "souptet/smooth.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Halvings before a move is given up (2^-12 of the displacement is far
 * below anything visible; past it the move is just blocked). */
#define FAIR_HALVINGS 12
/* Move sweeps per displacement field. */
#define FAIR_SWEEPS 6
/* Gauss-Seidel sweeps extending the boundary displacement inward: lattice
 * meshes are at most a few dozen layers deep, and an approximate extension
 * is enough (it only has to keep the interior from being overrun). */
#define FAIR_EXTEND_SWEEPS 40
/* Relative volume error the rescale aims for (well inside volume_tol). */
#define FAIR_VOLUME_AIM 1e-4
/* Rescale passes after the back-offs. */
#define FAIR_VOLUME_PASSES 6
/* The quality pass works on the tets scoring below this (smooth.h: a
 * score of 35 is angles in [35, 133.3]), above the default floor so that
 * the floor is not where the angles end. */
#define FAIR_QUALITY_GOAL 40.0
/* Conjugate gradients: relative residual and iteration cap. */
#define FAIR_CG_TOL 1e-12
#define FAIR_CG_MAX 1000

st_fair_params st_fair_params_default(void)
{
    st_fair_params p;
    p.iters = 3;
    p.lambda_dt = 1.0;
    p.relax_iters = 3;
    p.volume_tol = 0.005;
    p.quality_rounds = 40;
    p.min_angle = 30.0;
    p.boundary_quality = 1;
    return p;
}

typedef struct fair_ctx {
    sm_mesh sm;
    uint32_t *bidx;      /* mesh vertex -> boundary unknown, or UINT32_MAX */
    uint32_t *bvert;     /* boundary unknown -> mesh vertex */
    double *tmp;         /* 3 * nv scratch coordinates */
    double *disp;        /* 3 * nv displacements */
    double *nrm;         /* 3 * nv area-weighted normals (boundary) */
    uint32_t *moved_at;  /* nv: apply_disp phase of the vertex's last move */
    uint32_t *tried_at;  /* nv: phase it was last blocked in, 0 if not */
    size_t moves, backoffs, stuck;
    double floor;        /* p.min_angle */
} fair_ctx;

/* y = (I + lambda L) x over the boundary unknowns, one coordinate. */
static void apply_a(const fair_ctx *c, double lambda, const double *x, double *y)
{
    const sm_mesh *sm = &c->sm;
    size_t nb = sm->nbv;
    #pragma omp parallel for schedule(static) if (PAR_CHEAP(nb))
    for (size_t i = 0; i < nb; i++) {
        uint32_t v = c->bvert[i];
        size_t deg = sm->bv_off[v + 1] - sm->bv_off[v];
        double s = (1.0 + lambda * (double)deg) * x[i];
        for (size_t j = sm->bv_off[v]; j < sm->bv_off[v + 1]; j++)
            s -= lambda * x[c->bidx[sm->bv[j]]];
        y[i] = s;
    }
}

/* Serial dot product: a fixed summation order keeps the result independent
 * of the thread count. */
static double dot(const double *a, const double *b, size_t n)
{
    double s = 0.0;
    for (size_t i = 0; i < n; i++)
        s += a[i] * b[i];
    return s;
}

/* Solve (I + lambda L) x = b by conjugate gradients (x holds the guess). */
static st_status cg_solve(const fair_ctx *c, double lambda, const double *b,
                          double *x, st_error *err)
{
    size_t n = c->sm.nbv;
    double *r = st_malloc_array(3 * n, sizeof *r);
    if (!r)
        return st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory (fairing)");
    double *pv = r + n, *ap = r + 2 * n;
    apply_a(c, lambda, x, ap);
    for (size_t i = 0; i < n; i++) {
        r[i] = b[i] - ap[i];
        pv[i] = r[i];
    }
    double bb = dot(b, b, n), rr = dot(r, r, n);
    double stop = FAIR_CG_TOL * FAIR_CG_TOL * (bb > 0 ? bb : 1.0);
    for (int it = 0; it < FAIR_CG_MAX && rr > stop; it++) {
        apply_a(c, lambda, pv, ap);
        double pap = dot(pv, ap, n);
        if (!(pap > 0.0))
            break;
        double alpha = rr / pap;
        for (size_t i = 0; i < n; i++) {
            x[i] += alpha * pv[i];
            r[i] -= alpha * ap[i];
        }
        double rr2 = dot(r, r, n);
        double beta = rr2 / rr;
        rr = rr2;
        for (size_t i = 0; i < n; i++)
            pv[i] = r[i] + beta * pv[i];
    }
    free(r);
    return ST_OK;
}

/* Area-weighted vertex normals of the boundary with points at xyz. */
static void boundary_normals(fair_ctx *c, const double *xyz)
{
    const sm_mesh *sm = &c->sm;
    memset(c->nrm, 0, 3 * sm->nv * sizeof *c->nrm);
    for (size_t f = 0; f < sm->nbf; f++) {
        const uint32_t *k = sm->bf + 3 * f;
        const double *a = xyz + 3 * (size_t)k[0], *b = xyz + 3 * (size_t)k[1],
                     *d = xyz + 3 * (size_t)k[2];
        double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
        double w[3] = {d[0] - a[0], d[1] - a[1], d[2] - a[2]};
        double n[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2],
                       u[0] * w[1] - u[1] * w[0]};
        /* |n|/2 is the area; a third of it to each corner */
        for (int j = 0; j < 3; j++)
            for (int a2 = 0; a2 < 3; a2++)
                c->nrm[3 * (size_t)k[j] + (size_t)a2] += n[a2] / 6.0;
    }
}

/* tgt = base + delta * w[v] * n_v / |n_v| on the boundary; returns the
 * enclosed volume. */
static double offset_volume(fair_ctx *c, const double *base, double *tgt,
                            const double *w, double delta)
{
    const sm_mesh *sm = &c->sm;
    for (size_t i = 0; i < sm->nbv; i++) {
        uint32_t v = c->bvert[i];
        const double *n = c->nrm + 3 * (size_t)v;
        double len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        double s = (w ? w[v] : 1.0) * delta / (len > 0 ? len : 1.0);
        for (int a = 0; a < 3; a++)
            tgt[3 * (size_t)v + (size_t)a] = base[3 * (size_t)v + (size_t)a] + s * n[a];
    }
    return sm_boundary_volume(sm, tgt);
}

/* Move boundary vertices of tgt (3 * nv, boundary entries used) along
 * their normals at tgt by delta * w[v] until the enclosed volume is v0
 * (w NULL: uniform). The volume is a cubic in delta: bracket the root
 * from the first-order guess, then regula falsi (Illinois). */
static void rescale_volume(fair_ctx *c, double *tgt, const double *w, double v0)
{
    const sm_mesh *sm = &c->sm;
    boundary_normals(c, tgt);
    double *base = c->tmp;
    memcpy(base, tgt, 3 * sm->nv * sizeof *base);
    double tol = 1e-3 * FAIR_VOLUME_AIM * fabs(v0);
    double f0 = sm_boundary_volume(sm, base) - v0;
    if (fabs(f0) <= tol)
        return;
    double dvd = 0.0;   /* d volume / d delta at 0: sum of w_i * vertex area */
    for (size_t i = 0; i < sm->nbv; i++) {
        const double *n = c->nrm + 3 * (size_t)c->bvert[i];
        dvd += (w ? w[c->bvert[i]] : 1.0) * sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    }
    if (!(dvd > 0.0))
        return;
    double a = 0.0, fa = f0, b = -f0 / dvd, fb = offset_volume(c, base, tgt, w, b) - v0;
    for (int k = 0; k < 40 && fa * fb > 0.0 && isfinite(fb); k++) {
        a = b;
        fa = fb;
        b *= 2.0;
        fb = offset_volume(c, base, tgt, w, b) - v0;
    }
    if (!(fa * fb <= 0.0)) {   /* no bracket: leave the faired positions */
        memcpy(tgt, base, 3 * sm->nv * sizeof *tgt);
        return;
    }
    int side = 0;
    for (int k = 0; k < 100; k++) {
        double x = (a * fb - b * fa) / (fb - fa);
        double fx = offset_volume(c, base, tgt, w, x) - v0;
        if (fabs(fx) <= tol)
            return;
        if (fx * fb < 0.0) {
            a = b;
            fa = fb;
            side = 0;
        } else if (++side >= 2) {
            fa *= 0.5;   /* Illinois: keep the stale end from stalling */
        }
        b = x;
        fb = fx;
    }
    offset_volume(c, base, tgt, w, fabs(fa) < fabs(fb) ? a : b);
}

/* Extend the boundary displacement into the interior (Gauss-Seidel by
 * colour on the harmonic equation, boundary values fixed). */
static void extend_inward(fair_ctx *c)
{
    const sm_mesh *sm = &c->sm;
    double *d = c->disp;
    for (int sweep = 0; sweep < FAIR_EXTEND_SWEEPS; sweep++)
        for (size_t col = 0; col < sm->ncolours; col++) {
            #pragma omp parallel for schedule(static) if (PAR_CHEAP(sm->col_off[col + 1] - sm->col_off[col]))
            for (size_t j = sm->col_off[col]; j < sm->col_off[col + 1]; j++) {
                uint32_t v = sm->col_v[j];
                if (sm->onb[v])
                    continue;
                size_t n = sm->vv_off[v + 1] - sm->vv_off[v];
                double s[3] = {0, 0, 0};
                for (size_t k = sm->vv_off[v]; k < sm->vv_off[v + 1]; k++)
                    for (int a = 0; a < 3; a++)
                        s[a] += d[3 * (size_t)sm->vv[k] + (size_t)a];
                for (int a = 0; a < 3; a++)
                    d[3 * (size_t)v + (size_t)a] = n ? s[a] / (double)n : 0.0;
            }
        }
}

/* Move v by the fraction of disp that keeps its star positive: 1, 1/2, ...
 * Returns the fraction taken (0 when blocked). The star's score at p may
 * not fall below min(floor, its score now); a score at p of at least the
 * floor passes whatever the score now is, so that one is computed only
 * when a trial position scores under the floor. */
static double move_checked(fair_ctx *c, uint32_t v, const double disp[3],
                           size_t *backoffs)
{
    double *x = c->sm.m->xyz + 3 * (size_t)v;
    double floor_score = c->floor;
    int have_floor = 0;
    double f = 1.0;
    for (int h = 0; h <= FAIR_HALVINGS; h++, f *= 0.5) {
        double p[3] = {x[0] + f * disp[0], x[1] + f * disp[1], x[2] + f * disp[2]};
        if (sm_star_positive(&c->sm, v, p)) {
            double sp = sm_star_score(&c->sm, v, p);
            if (!(sp >= c->floor) && !have_floor) {
                floor_score = fmin(c->floor, sm_star_score(&c->sm, v, x));
                have_floor = 1;
            }
            if (sp >= floor_score) {
                memcpy(x, p, sizeof p);
                return f;
            }
        }
        (*backoffs)++;
    }
    return 0.0;
}

/* 1 when no edge neighbour of v has moved since phase t. */
static int star_unchanged(const fair_ctx *c, uint32_t v, uint32_t t)
{
    const sm_mesh *sm = &c->sm;
    for (size_t k = sm->vv_off[v]; k < sm->vv_off[v + 1]; k++)
        if (c->moved_at[sm->vv[k]] > t)
            return 0;
    return 1;
}

/* Move every vertex by c->disp, in colour order, in sweeps. A vertex that
 * was blocked outright keeps its displacement, so while no neighbour has
 * moved its star and its trials are the same as last time: it is blocked
 * again without the trials (counted as if they were made). Phases number
 * the (sweep, colour) steps from 1; a neighbour never shares a phase. */
static void apply_disp(fair_ctx *c)
{
    const sm_mesh *sm = &c->sm;
    double *d = c->disp;
    memset(c->moved_at, 0, sm->nv * sizeof *c->moved_at);
    memset(c->tried_at, 0, sm->nv * sizeof *c->tried_at);
    uint32_t phase = 0;
    for (int sweep = 0; sweep < FAIR_SWEEPS; sweep++) {
        size_t pending = 0, moves = 0, backoffs = 0, stuck = 0;
        for (size_t col = 0; col < sm->ncolours; col++) {
            uint32_t ph = ++phase;
            #pragma omp parallel for schedule(dynamic, 32) reduction(+ : pending, moves, backoffs, stuck) \
                if (PAR_MOVES(sm->col_off[col + 1] - sm->col_off[col]))
            for (size_t j = sm->col_off[col]; j < sm->col_off[col + 1]; j++) {
                uint32_t v = sm->col_v[j];
                double *dv = d + 3 * (size_t)v;
                if (dv[0] == 0.0 && dv[1] == 0.0 && dv[2] == 0.0)
                    continue;
                double f;
                if (c->tried_at[v] && star_unchanged(c, v, c->tried_at[v])) {
                    backoffs += FAIR_HALVINGS + 1;
                    f = 0.0;
                } else {
                    f = move_checked(c, v, dv, &backoffs);
                }
                c->tried_at[v] = f == 0.0 ? ph : 0;
                if (f > 0.0)
                    c->moved_at[v] = ph;
                if (f == 1.0) {
                    dv[0] = dv[1] = dv[2] = 0.0;
                    moves++;
                } else {
                    for (int a = 0; a < 3; a++)
                        dv[a] *= 1.0 - f;
                    pending++;
                    if (f > 0.0)
                        moves++;
                    else
                        stuck++;
                }
            }
        }
        c->moves += moves;
        c->backoffs += backoffs;
        if (pending == 0 || sweep == FAIR_SWEEPS - 1) {
            c->stuck += stuck;
            break;
        }
    }
}

/* Interior ODT relaxation, one sweep by colour. */
static void relax_interior(fair_ctx *c)
{
    const sm_mesh *sm = &c->sm;
    size_t moves = 0, backoffs = 0;
    for (size_t col = 0; col < sm->ncolours; col++) {
        #pragma omp parallel for schedule(dynamic, 32) reduction(+ : moves, backoffs) \
            if (PAR_MOVES(sm->col_off[col + 1] - sm->col_off[col]))
        for (size_t j = sm->col_off[col]; j < sm->col_off[col + 1]; j++) {
            uint32_t v = sm->col_v[j];
            if (sm->onb[v])
                continue;
            double t[3], *x = sm->m->xyz + 3 * (size_t)v;
            sm_odt_target(sm, v, t);
            double dv[3] = {t[0] - x[0], t[1] - x[1], t[2] - x[2]};
            if (move_checked(c, v, dv, &backoffs) > 0.0)
                moves++;
        }
    }
    c->moves += moves;
    c->backoffs += backoffs;
}

static void fair_ctx_free(fair_ctx *c)
{
    sm_mesh_free(&c->sm);
    free(c->bidx);
    free(c->bvert);
    free(c->tmp);
    free(c->disp);
    free(c->nrm);
    free(c->moved_at);
    free(c->tried_at);
}

/* Rescale passes from the current positions (uniform weights) until the
 * volume is within FAIR_VOLUME_AIM of v0. */
static void correct_volume(fair_ctx *c, double v0)
{
    sm_mesh *sm = &c->sm;
    size_t nv = sm->nv;
    double *tgt = st_malloc_array(3 * nv, sizeof *tgt);
    if (!tgt)
        return;
    for (int pass = 0; pass < FAIR_VOLUME_PASSES; pass++) {
        double vol = sm_boundary_volume(sm, sm->m->xyz);
        if (fabs(vol - v0) <= FAIR_VOLUME_AIM * fabs(v0))
            break;
        memcpy(tgt, sm->m->xyz, 3 * nv * sizeof *tgt);
        rescale_volume(c, tgt, NULL, v0);
        memset(c->disp, 0, 3 * nv * sizeof *c->disp);
        for (size_t i = 0; i < sm->nbv; i++) {
            uint32_t v = c->bvert[i];
            for (int a = 0; a < 3; a++)
                c->disp[3 * (size_t)v + (size_t)a] =
                    tgt[3 * (size_t)v + (size_t)a] - sm->m->xyz[3 * (size_t)v + (size_t)a];
        }
        extend_inward(c);
        apply_disp(c);
    }
    free(tgt);
}

st_status st_fair(st_tetmesh *m, const st_fair_params *pp, st_fair_stats *stats,
                  const st_progress *prog, st_error *err)
{
    st_fair_params p = pp ? *pp : st_fair_params_default();
    double t0 = sm_now();
    if (stats)
        memset(stats, 0, sizeof *stats);
    if (p.iters < 0 || !(p.lambda_dt >= 0.0) || p.relax_iters < 0 || !(p.volume_tol > 0.0) ||
        !(p.min_angle >= 0.0 && p.min_angle < 60.0))
        return st_error_set(err, ST_EINPUT, NULL, 0, "bad fairing parameters");
    if (m->ntets == 0)
        return st_error_set(err, ST_EINPUT, NULL, 0, "the mesh has no tets");
    size_t bad = sm_count_nonpositive(m);
    if (bad)
        return st_error_set(err, ST_EINPUT, NULL, 0,
                            "%zu of %zu tets are inverted or flat: fairing needs a "
                            "positively oriented mesh", bad, m->ntets);
    fair_ctx c;
    memset(&c, 0, sizeof c);
    c.floor = p.min_angle;
    st_status s = sm_mesh_build(&c.sm, m, err);
    if (s)
        return s;
    sm_mesh *sm = &c.sm;
    size_t nv = sm->nv, nb = sm->nbv;
    c.bidx = st_malloc_array(nv, sizeof *c.bidx);
    c.bvert = st_malloc_array(nb ? nb : 1, sizeof *c.bvert);
    c.tmp = st_malloc_array(3 * nv, sizeof *c.tmp);
    c.disp = st_calloc_array(3 * nv, sizeof *c.disp);
    c.nrm = st_malloc_array(3 * nv, sizeof *c.nrm);
    c.moved_at = st_malloc_array(nv, sizeof *c.moved_at);
    c.tried_at = st_malloc_array(nv, sizeof *c.tried_at);
    double *rhs = st_malloc_array(6 * (nb ? nb : 1), sizeof *rhs);
    double *tgt = st_malloc_array(3 * nv, sizeof *tgt);
    if (!c.bidx || !c.bvert || !c.tmp || !c.disp || !c.nrm || !c.moved_at || !c.tried_at ||
        !rhs || !tgt) {
        s = st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory (fairing)");
        goto done;
    }
    for (size_t v = 0, i = 0; v < nv; v++) {
        c.bidx[v] = sm->onb[v] ? (uint32_t)i : UINT32_MAX;
        if (sm->onb[v])
            c.bvert[i++] = (uint32_t)v;
    }
    double v0 = sm_boundary_volume(sm, m->xyz);
    st_fair_stats st;
    memset(&st, 0, sizeof st);
    st.volume_before = v0;
    st.boundary_vertices = nb;
    sm_dihedral_range(m, &st.min_dihedral_before, &st.max_dihedral_before);

    for (int it = 0; it < p.iters; it++) {
        st_progress_report(prog, "fair", (double)it / (double)p.iters);
        /* 1. implicit fairing, coordinate by coordinate */
        memcpy(tgt, m->xyz, 3 * nv * sizeof *tgt);
        double *b = rhs, *x = rhs + nb;
        for (int a = 0; a < 3; a++) {
            for (size_t i = 0; i < nb; i++)
                b[i] = x[i] = m->xyz[3 * (size_t)c.bvert[i] + (size_t)a];
            s = cg_solve(&c, p.lambda_dt, b, x, err);
            if (s)
                goto done;
            for (size_t i = 0; i < nb; i++)
                tgt[3 * (size_t)c.bvert[i] + (size_t)a] = x[i];
        }
        /* 2. local rescale along the normals */
        int moved = 0;
        for (size_t i = 0; i < nb && !moved; i++)
            for (int a = 0; a < 3; a++)
                moved |= tgt[3 * (size_t)c.bvert[i] + (size_t)a] !=
                         m->xyz[3 * (size_t)c.bvert[i] + (size_t)a];
        if (!moved)
            break;   /* nothing to fair */
        rescale_volume(&c, tgt, NULL, v0);
        /* 3. carry the interior along, move checked */
        memset(c.disp, 0, 3 * nv * sizeof *c.disp);
        for (size_t i = 0; i < nb; i++) {
            uint32_t v = c.bvert[i];
            for (int a = 0; a < 3; a++)
                c.disp[3 * (size_t)v + (size_t)a] =
                    tgt[3 * (size_t)v + (size_t)a] - m->xyz[3 * (size_t)v + (size_t)a];
        }
        extend_inward(&c);
        apply_disp(&c);
        /* 4. interior relaxation */
        for (int r = 0; r < p.relax_iters; r++)
            relax_interior(&c);
        /* 5. what the back-offs cost */
        correct_volume(&c, v0);
        st.iters = it + 1;
    }
    sm_dihedral_range(m, &st.min_dihedral_fair, &st.max_dihedral_fair);
    if (p.quality_rounds > 0) {
        /* the trial steps scale with the mean boundary edge length */
        double len = 0.0;
        size_t ne = 0;
        for (size_t i = 0; i < 3 * sm->nbf; i++) {
            const double *a = m->xyz + 3 * (size_t)sm->bf[i];
            const double *b = m->xyz + 3 * (size_t)sm->bf[i % 3 == 2 ? i - 2 : i + 1];
            len += sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                        (a[2] - b[2]) * (a[2] - b[2]));
            ne++;
        }
        double h = ne ? len / (double)ne : 1.0;
        s = p.boundary_quality
            ? sm_quality_fair(sm, h, p.quality_rounds, FAIR_QUALITY_GOAL, &st.quality_moves, err)
            : sm_quality_interior(sm, h, p.quality_rounds, FAIR_QUALITY_GOAL, &st.quality_moves,
                                  err);
        if (s)
            goto done;
        /* tangent moves keep the volume to first order: what the curvature
         * costs goes back by the rescale (its moves keep the floor) */
        if (p.boundary_quality)
            correct_volume(&c, v0);
    }
    st_progress_report(prog, "fair", 1.0);
    st.volume_after = sm_boundary_volume(sm, m->xyz);
    st.moves = c.moves;
    st.backoffs = c.backoffs;
    st.stuck = c.stuck;
    sm_dihedral_range(m, &st.min_dihedral_after, &st.max_dihedral_after);
    st.seconds = sm_now() - t0;
    if (stats)
        *stats = st;
    if (fabs(st.volume_after - v0) > p.volume_tol * fabs(v0))
        s = st_error_set(err, ST_EINPUT, NULL, 0,
                         "the volume changed by %.3g%% (more than %.3g%%): too many "
                         "moves were blocked; try fewer --iters",
                         100.0 * (st.volume_after - v0) / v0, 100.0 * p.volume_tol);
done:
    free(rhs);
    free(tgt);
    fair_ctx_free(&c);
    return s;
}

