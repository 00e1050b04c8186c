/*
 * enclose_float32.c - a mesh's points rounded to float32 so that it still
 * encloses its soup, checked exactly (see enclose.h,
 * st_enclosure_round_float32).
 *
 * The rounding itself is chosen in floating point (which of the floats
 * around a point, by the outward normals of the boundary faces around
 * it); nothing is decided there: the exact enclosure test and the exact
 * orientation of every tet judge each rounding, and the pushes that follow
 * a failed check only choose what to try next.
 */
#include "souptet/enclose.h"
#include "../base/fpenv.h"
#include "souptet/mem.h"
#include "souptet/pred.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static double now_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

int st_points_are_float32(const double *xyz, size_t n)
{
    for (size_t i = 0; i < 3 * n; i++)
        if ((double)(float)xyz[i] != xyz[i])
            return 0;
    return 1;
}

/* The float below (dir < 0) or above (dir > 0) x, stepped `steps` more
 * ulps that way: the largest float <= x, or the smallest >= x, and then
 * further out; never past +-FLT_MAX. x is finite and within the float
 * range (checked by the caller). */
static double float_side(double x, int dir, unsigned steps)
{
    float f = (float)x;
    if (dir < 0) {
        if ((double)f > x)
            f = nextafterf(f, -INFINITY);
        for (unsigned i = 0; i < steps && f > -FLT_MAX; i++)
            f = nextafterf(f, -INFINITY);
    } else {
        if ((double)f < x)
            f = nextafterf(f, INFINITY);
        for (unsigned i = 0; i < steps && f < FLT_MAX; i++)
            f = nextafterf(f, INFINITY);
    }
    return (double)f;
}

/* Point v's rounding at push level `level`: interior points (nfaces 0)
 * to the nearest float; boundary points to the corner of the box of
 * floats around them that goes farthest out by the worst of their faces'
 * unit outward normals (normals: 3 per face; adj: the faces around v).
 * Returns that worst (displacement . normal) of the corner chosen: > 0
 * when the point moved out of every face around it (0 for interior
 * points). */
static double round_point(double out[3], const double x[3], unsigned level,
                          const uint32_t *adj, size_t nadj, const double *normals)
{
    if (nadj == 0) {
        for (int a = 0; a < 3; a++)
            out[a] = (double)(float)x[a];
        return 0.0;
    }
    double side[3][2];
    for (int a = 0; a < 3; a++) {
        side[a][0] = float_side(x[a], -1, level);
        side[a][1] = float_side(x[a], +1, level);
    }
    double best_score = -INFINITY, best_len = INFINITY;
    int best = 0;
    for (int c = 0; c < 8; c++) {
        double d[3];
        for (int a = 0; a < 3; a++)
            d[a] = side[a][(c >> a) & 1] - x[a];
        double score = INFINITY;
        for (size_t j = 0; j < nadj; j++) {
            const double *n = normals + 3 * (size_t)adj[j];
            double s = d[0] * n[0] + d[1] * n[1] + d[2] * n[2];
            if (s < score)
                score = s;
        }
        double len = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
        if (score > best_score || (score == best_score && len < best_len)) {
            best_score = score;
            best_len = len;
            best = c;
        }
    }
    for (int a = 0; a < 3; a++)
        out[a] = side[a][(best >> a) & 1];
    return best_score;
}

typedef struct face_ctx {
    const st_soup *s;
    const unsigned char *crossing;
    const double *f[3];
} face_ctx;

/* Stop (1) at the first crossing soup triangle that meets the face. */
static int face_visit(void *ctx, uint32_t tri)
{
    const face_ctx *c = ctx;
    if (!c->crossing[tri])
        return 0;
    const uint32_t *v = c->s->tris + 3 * (size_t)tri;
    return st_tri_tri_intersect(c->f[0], c->f[1], c->f[2], c->s->xyz + 3 * (size_t)v[0],
                                c->s->xyz + 3 * (size_t)v[1], c->s->xyz + 3 * (size_t)v[2]);
}

/* How many of s's used vertices are not float32 values (*n); ST_ENOMEM
 * (err set) when out of memory. */
static st_status input_not_float32(const st_soup *s, size_t *n, st_error *err)
{
    unsigned char *used = st_calloc_array(s->nverts ? s->nverts : 1, 1);
    if (!used)
        return st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory");
    for (size_t i = 0; i < 3 * s->ntris; i++)
        used[s->tris[i]] = 1;
    for (size_t v = 0; v < s->nverts; v++)
        if (used[v] && !st_points_are_float32(s->xyz + 3 * v, 1))
            (*n)++;
    free(used);
    return ST_OK;
}

/* The boundary faces around each point (CSR: aoff, np + 1 zeroed slots;
 * adj, 3 nf) and each face's unit outward normal (st_tetmesh_boundary
 * turns them out of positive tets), at the points xyz. ST_ENOMEM (err
 * set) when out of memory. */
static st_status boundary_stars(const uint32_t *faces, size_t nf, const double *xyz,
                                size_t np, double *normals, size_t *aoff, uint32_t *adj,
                                st_error *err)
{
    for (size_t f = 0; f < nf; f++) {
        const uint32_t *q = faces + 3 * f;
        for (int k = 0; k < 3; k++)
            aoff[q[k] + 1]++;
        const double *a = xyz + 3 * (size_t)q[0], *b = xyz + 3 * (size_t)q[1],
                     *c = xyz + 3 * (size_t)q[2];
        double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
        double w[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
        double *n = normals + 3 * f;
        n[0] = u[1] * w[2] - u[2] * w[1];
        n[1] = u[2] * w[0] - u[0] * w[2];
        n[2] = u[0] * w[1] - u[1] * w[0];
        double len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        for (int k = 0; k < 3; k++)
            n[k] = len > 0 ? n[k] / len : 0.0;
    }
    for (size_t v = 0; v < np; v++)
        aoff[v + 1] += aoff[v];
    size_t *fill = st_malloc_array(np ? np : 1, sizeof *fill);
    if (!fill)
        return st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory");
    if (np)
        memcpy(fill, aoff, np * sizeof *fill);
    for (size_t f = 0; f < nf; f++)
        for (int k = 0; k < 3; k++)
            adj[fill[faces[3 * f + (size_t)k]]++] = (uint32_t)f;
    free(fill);
    return ST_OK;
}

/* Tets of m that are not positively oriented (exact). */
static size_t count_not_positive(const st_tetmesh *m)
{
    size_t inverted = 0;
    const long long nt = (long long)m->ntets;
#pragma omp parallel for reduction(+ : inverted) schedule(static)
    for (long long t = 0; t < nt; t++) {
        const uint32_t *q = m->tets + 4 * (size_t)t;
        inverted += st_orient3d(m->xyz + 3 * (size_t)q[0], m->xyz + 3 * (size_t)q[1],
                                m->xyz + 3 * (size_t)q[2], m->xyz + 3 * (size_t)q[3]) >= 0;
    }
    return inverted;
}

/* What the rounding did: points moved, the farthest move, points pushed
 * and the most ulps. */
static void move_stats(st_float32_stats *st, const double *orig, const double *xyz,
                       const unsigned *level, size_t np)
{
    for (size_t v = 0; v < np; v++) {
        const double *a = orig + 3 * v, *b = xyz + 3 * v;
        double d2 = 0;
        for (int k = 0; k < 3; k++)
            d2 += (b[k] - a[k]) * (b[k] - a[k]);
        if (a[0] != b[0] || a[1] != b[1] || a[2] != b[2])
            st->points_moved++;
        if (sqrt(d2) > st->max_move)
            st->max_move = sqrt(d2);
        if (level[v]) {
            st->pushed++;
            if (level[v] > st->max_push)
                st->max_push = level[v];
        }
    }
}

/* The boundary points of the rounded mesh m near where its enclosure
 * failed (e from st_enclosure_compute, vin and hit its per-vertex and
 * per-triangle results): the points of the tet (in m_before, found by
 * *loc, made here once) that held each soup vertex now outside, and the
 * corners of the boundary faces that meet a crossing triangle. mark gets
 * 1 at them (np bytes, zeroed here; fmark: nf bytes of scratch); *all
 * becomes 1 when a vertex's tet has no boundary point to push. */
static st_status mark_failures(unsigned char *mark, unsigned char *fmark, int *all,
                               st_locator **loc, const st_tetmesh *m_before,
                               const st_tetmesh *m, const st_soup *s, const st_bvh *bvh,
                               const uint32_t *faces, size_t nf, const size_t *aoff,
                               const st_enclosure *e, const unsigned char *vin,
                               unsigned char *hit, st_error *err)
{
    memset(mark, 0, m->npoints);
    *all = 0;
    st_status rc;
    if (e->vertices_outside) {
        if (!*loc && (rc = st_locator_new(loc, m_before, err)))
            return rc;
        for (size_t i = 0; i < s->nverts && !*all; i++) {
            if (vin[i] != 0)
                continue;
            int64_t t = st_locator_find(*loc, s->xyz + 3 * i, NULL);
            if (t < 0)
                continue;   /* outside before rounding too */
            int named = 0;
            for (int k = 0; k < 4; k++) {
                uint32_t v = m->tets[4 * (size_t)t + (size_t)k];
                if (aoff[v + 1] > aoff[v]) {
                    mark[v] = 1;
                    named = 1;
                }
            }
            if (!named)
                *all = 1;
        }
    }
    if (e->crossing_triangles && !*all) {
        const long long n = (long long)nf;
#pragma omp parallel for schedule(dynamic, 64)
        for (long long f = 0; f < n; f++) {
            face_ctx c;
            c.s = s;
            c.crossing = hit;
            for (int k = 0; k < 3; k++)
                c.f[k] = m->xyz + 3 * (size_t)faces[3 * (size_t)f + (size_t)k];
            fmark[f] = (unsigned char)(st_bvh_query_tri(bvh, c.f[0], c.f[1], c.f[2],
                                                        face_visit, &c) != 0);
        }
        for (size_t f = 0; f < nf; f++)
            if (fmark[f])
                for (int k = 0; k < 3; k++)
                    mark[faces[3 * f + (size_t)k]] = 1;
    }
    return ST_OK;
}

/* The rounding's state: the mesh as it was (orig, before), its boundary
 * faces with their normals and the faces around each point (aoff, adj),
 * each point's push level and score, the best rounding tried, and the
 * enclosure test's scratch. */
typedef struct f32_state {
    st_tetmesh *m;
    const st_soup *s;
    const st_bvh *bvh;
    size_t np, nf;
    uint32_t *faces;
    double *orig, *normals;
    size_t *aoff;
    uint32_t *adj;
    unsigned *level;
    double *score, *best_xyz;
    unsigned *best_level;
    unsigned char *vin, *hit, *mark, *fmark;
    st_bvh *own;
    st_locator *loc;
    st_tetmesh before;   /* m at orig, for finding where a soup vertex lay */
    int copied;          /* orig holds m's points */
} f32_state;

static void f32_free(f32_state *F)
{
    st_locator_free(F->loc);
    st_bvh_free(F->own);
    void *arrays[] = {F->faces, F->orig,  F->normals, F->aoff,  F->adj,
                      F->level, F->score, F->best_xyz, F->best_level, F->mark,
                      F->fmark, F->vin,   F->hit};
    for (size_t i = 0; i < sizeof arrays / sizeof *arrays; i++)
        free(arrays[i]);
}

/* The boundary, its stars and normals (st->boundary_points), the
 * scratch, and a BVH over the soup when none was given. */
static st_status f32_setup(f32_state *F, st_float32_stats *st, st_error *err)
{
    st_status rc = st_tetmesh_boundary(F->m, &F->faces, NULL, &F->nf, err);
    if (rc)
        return rc;
    const size_t np = F->np, nf = F->nf;
    F->orig = st_malloc_array(np ? np : 1, 3 * sizeof *F->orig);
    F->normals = st_malloc_array(nf ? nf : 1, 3 * sizeof *F->normals);
    F->aoff = st_calloc_array(np + 1, sizeof *F->aoff);
    F->adj = st_malloc_array(nf ? 3 * nf : 1, sizeof *F->adj);
    F->level = st_calloc_array(np ? np : 1, sizeof *F->level);
    F->score = st_malloc_array(np ? np : 1, sizeof *F->score);
    F->best_xyz = st_malloc_array(np ? np : 1, 3 * sizeof *F->best_xyz);
    F->best_level = st_malloc_array(np ? np : 1, sizeof *F->best_level);
    F->mark = st_calloc_array(np ? np : 1, 1);
    F->fmark = st_calloc_array(nf ? nf : 1, 1);
    F->vin = st_malloc_array(F->s->nverts ? F->s->nverts : 1, 1);
    F->hit = st_malloc_array(F->s->ntris ? F->s->ntris : 1, 1);
    if (!F->orig || !F->normals || !F->aoff || !F->adj || !F->level || !F->score ||
        !F->best_xyz || !F->best_level || !F->mark || !F->fmark || !F->vin || !F->hit)
        return st_error_set(err, ST_ENOMEM, NULL, 0,
                            "out of memory rounding %zu points to float32", np);
    if (np)
        memcpy(F->orig, F->m->xyz, np * 3 * sizeof *F->orig);
    F->copied = 1;
    if ((rc = boundary_stars(F->faces, nf, F->orig, np, F->normals, F->aoff, F->adj, err)))
        return rc;
    for (size_t v = 0; v < np; v++)
        st->boundary_points += F->aoff[v + 1] > F->aoff[v];
    if (!F->bvh && F->s->ntris) {
        if ((rc = st_bvh_build(&F->own, F->s, err)))
            return rc;
        F->bvh = F->own;
    }
    F->before = *F->m;
    F->before.xyz = F->orig;
    return ST_OK;
}

/* 1 when a has fewer failures than b: vertices outside, then triangles
 * crossing, then inverted tets. */
static int f32_fewer_failures(const st_float32_stats *a, const st_float32_stats *b)
{
    return a->verts_outside < b->verts_outside ||
           (a->verts_outside == b->verts_outside &&
            (a->tris_crossing < b->tris_crossing ||
             (a->tris_crossing == b->tris_crossing && a->inverted < b->inverted)));
}

/* Push out the boundary points named near the failure (all of them when
 * *all): the next round rounds them one float further out. A point whose
 * float goes inward by some face around it (score < 0: faces around it
 * facing nearly opposite ways, a knife edge) would only go farther in by
 * it: it stays. (Score 0: a point on the float grid under a face along
 * it; one ulp out is outward.) Returns the number pushed. */
static size_t f32_push(f32_state *F, int all)
{
    size_t bumped = 0;
    for (size_t v = 0; v < F->np; v++)
        if ((all || F->mark[v]) && F->aoff[v + 1] > F->aoff[v] && F->score[v] >= 0) {
            F->level[v]++;
            bumped++;
        }
    return bumped;
}

/* The rounds: round every point at its level, check exactly, keep the
 * best rounding tried, push the points near the failure; at the end m
 * holds the best rounding and *st its counts. */
static st_status f32_rounds(f32_state *F, st_float32_stats *st, st_error *err)
{
    st_tetmesh *m = F->m;
    const size_t np = F->np;
    st_status rc;
    st_float32_stats best = *st;
    int have_best = 0;
    for (int round = 1; round <= ST_FLOAT32_MAX_ROUNDS; round++) {
        for (size_t v = 0; v < np; v++)
            F->score[v] = round_point(m->xyz + 3 * v, F->orig + 3 * v, F->level[v],
                                      F->adj + F->aoff[v], F->aoff[v + 1] - F->aoff[v],
                                      F->normals);
        st->rounds = round;
        st_enclosure e;
        if ((rc = st_enclosure_compute(&e, m, F->s, F->bvh, F->vin, F->hit, err)))
            return rc;
        const size_t inverted = count_not_positive(m);
        st->verts_outside = e.vertices_outside;
        st->tris_crossing = e.crossing_triangles;
        st->inverted = inverted;
        st->encloses = e.encloses && inverted == 0;
        if (!have_best || f32_fewer_failures(st, &best)) {
            best = *st;
            have_best = 1;
            if (np) {
                memcpy(F->best_xyz, m->xyz, np * 3 * sizeof *F->best_xyz);
                memcpy(F->best_level, F->level, np * sizeof *F->best_level);
            }
        }
        if (st->encloses || round == ST_FLOAT32_MAX_ROUNDS)
            break;
        if (e.encloses)
            break;   /* only inversions: pushing out is no cure */
        /* Name the boundary points near the failure. */
        int all = 0;
        if ((rc = mark_failures(F->mark, F->fmark, &all, &F->loc, &F->before, m, F->s,
                                F->bvh, F->faces, F->nf, F->aoff, &e, F->vin, F->hit,
                                err)))
            return rc;
        if (f32_push(F, all) == 0)
            break;   /* nothing left to try */
    }
    if (!st->encloses && have_best) {
        /* Keep the best rounding tried, with its counts. */
        int rounds = st->rounds;
        *st = best;
        st->rounds = rounds;
        if (np) {
            memcpy(m->xyz, F->best_xyz, np * 3 * sizeof *F->best_xyz);
            memcpy(F->level, F->best_level, np * sizeof *F->level);
        }
    }
    return ST_OK;
}

st_status st_enclosure_round_float32(st_tetmesh *m, const st_soup *s,
                                     const st_bvh *bvh, st_float32_stats *st,
                                     st_error *err)
{
    st_float32_stats local;
    if (!st)
        st = &local;
    memset(st, 0, sizeof *st);
    const double t0 = now_seconds();
    if (bvh && bvh->soup != s)
        return st_error_set(err, ST_EINPUT, NULL, 0,
                            "float32 rounding: the BVH is not over this soup");
    const size_t np = m->npoints;
    for (size_t i = 0; i < 3 * np; i++)
        if (!(fabs(m->xyz[i]) <= (double)FLT_MAX))
            return st_error_set(err, ST_ELIMIT, NULL, 0,
                                "a mesh coordinate (%g) is beyond the float32 range",
                                m->xyz[i]);
    st_status rc = input_not_float32(s, &st->input_not_float32, err);
    if (rc)
        return rc;

    f32_state F = {.m = m, .s = s, .bvh = bvh, .np = np};
    if ((rc = f32_setup(&F, st, err)) || (rc = f32_rounds(&F, st, err)))
        goto out;
    move_stats(st, F.orig, m->xyz, F.level, np);
out:
    st->seconds = now_seconds() - t0;
    if (rc && F.copied && np)
        memcpy(m->xyz, F.orig, np * 3 * sizeof *F.orig);   /* as it was */
    f32_free(&F);
    return rc;
}
