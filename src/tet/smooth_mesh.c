/*
 * smooth_mesh.c - incidence, colouring and local checks shared by the
 * vertex-moving passes (fair.c, fit.c, quality.c, invariant.c; see
 * smooth_mesh.h).
 *
 * Colouring: greedy in vertex order over the edge graph. In a tet every
 * pair of corners is an edge, so two vertices of one colour never share a
 * tet: moving all of a colour at once, each checked against its own star,
 * gives the same result as moving them one by one, in any thread order.
 */
#include "smooth_mesh.h"
#include "tetqual_pairs.h"
#include "../base/fpenv.h"

#include "souptet/geom.h"
#include "souptet/mem.h"
#include "souptet/pred.h"
#include "souptet/smooth.h"
#include "souptet/tetqual.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static int cmp_u32(const void *a, const void *b)
{
    uint32_t x = *(const uint32_t *)a, y = *(const uint32_t *)b;
    return (x > y) - (x < y);
}

/* Sort buf[0..n) of distinct values: by insertion where short (a
 * vertex's neighbours, a dozen or two), qsort otherwise. */
static void sort_distinct(uint32_t *buf, size_t n)
{
    if (n > 48) {
        qsort(buf, n, sizeof *buf, cmp_u32);
        return;
    }
    for (size_t i = 1; i < n; i++) {
        uint32_t x = buf[i];
        size_t j = i;
        while (j > 0 && buf[j - 1] > x) {
            buf[j] = buf[j - 1];
            j--;
        }
        buf[j] = x;
    }
}

void sm_mesh_free(sm_mesh *sm)
{
    if (!sm)
        return;
    free(sm->vt_off);
    free(sm->vt);
    free(sm->vv_off);
    free(sm->vv);
    free(sm->bf);
    free(sm->vf_off);
    free(sm->vf);
    free(sm->onb);
    free(sm->bv_off);
    free(sm->bv);
    free(sm->col_off);
    free(sm->col_v);
    memset(sm, 0, sizeof *sm);
}

/* CSR of vertex -> items, from n items with k vertices each (idx). */
static st_status build_csr(size_t nv, const uint32_t *idx, size_t n, int k,
                           size_t **off_out, uint32_t **items_out)
{
    size_t *off = st_calloc_array(nv + 1, sizeof *off);
    size_t total;
    if (!off || st_size_mul(&total, n, (size_t)k)) {
        free(off);
        return ST_ENOMEM;
    }
    uint32_t *items = st_malloc_array(total, sizeof *items);
    size_t *fill = st_malloc_array(nv, sizeof *fill);
    if (!items || !fill) {
        free(off);
        free(items);
        free(fill);
        return ST_ENOMEM;
    }
    for (size_t i = 0; i < n * (size_t)k; i++)
        off[idx[i] + 1]++;
    for (size_t v = 0; v < nv; v++)
        off[v + 1] += off[v];
    memcpy(fill, off, nv * sizeof *fill);
    for (size_t i = 0; i < n; i++)
        for (int c = 0; c < k; c++)
            items[fill[idx[(size_t)k * i + (size_t)c]]++] = (uint32_t)i;
    free(fill);
    *off_out = off;
    *items_out = items;
    return ST_OK;
}

/* Neighbour lists from a vertex -> items CSR of items with k corners. */
static st_status build_nbrs(size_t nv, const size_t *ioff, const uint32_t *items,
                            const uint32_t *idx, int k, size_t **off_out,
                            uint32_t **nb_out)
{
    size_t total = ioff[nv];
    size_t cap;
    if (st_size_mul(&cap, total, (size_t)(k - 1)))
        return ST_ENOMEM;
    size_t *off = st_calloc_array(nv + 1, sizeof *off);
    uint32_t *nb = st_malloc_array(cap, sizeof *nb);
    if (!off || !nb) {
        free(off);
        free(nb);
        return ST_ENOMEM;
    }
    /* seen[u] == v: u is already in v's list (so each list is kept
     * duplicate-free as it is gathered, and only its distinct entries
     * are sorted) */
    uint32_t *seen = st_malloc_array(nv ? nv : 1, sizeof *seen);
    if (!seen) {
        free(off);
        free(nb);
        return ST_ENOMEM;
    }
    memset(seen, 0xff, (nv ? nv : 1) * sizeof *seen);
    size_t w = 0;
    for (size_t v = 0; v < nv; v++) {
        size_t start = w;
        for (size_t j = ioff[v]; j < ioff[v + 1]; j++)
            for (int c = 0; c < k; c++) {
                uint32_t u = idx[(size_t)k * items[j] + (size_t)c];
                if (u != (uint32_t)v && seen[u] != (uint32_t)v) {
                    seen[u] = (uint32_t)v;
                    nb[w++] = u;
                }
            }
        sort_distinct(nb + start, w - start);
        off[v + 1] = w;
    }
    free(seen);
    *off_out = off;
    *nb_out = nb;
    return ST_OK;
}

st_status sm_mesh_build(sm_mesh *sm, st_tetmesh *m, st_error *err)
{
    memset(sm, 0, sizeof *sm);
    sm->m = m;
    sm->nv = m->npoints;
    sm->nt = m->ntets;
    if (m->ntets == 0)
        return st_error_set(err, ST_EINPUT, NULL, 0, "the mesh has no tets");
    if (build_csr(sm->nv, m->tets, sm->nt, 4, &sm->vt_off, &sm->vt) ||
        build_nbrs(sm->nv, sm->vt_off, sm->vt, m->tets, 4, &sm->vv_off, &sm->vv))
        goto nomem;
    st_status s = st_tetmesh_boundary(m, &sm->bf, NULL, &sm->nbf, err);
    if (s) {
        sm_mesh_free(sm);
        return s;
    }
    if (build_csr(sm->nv, sm->bf, sm->nbf, 3, &sm->vf_off, &sm->vf) ||
        build_nbrs(sm->nv, sm->vf_off, sm->vf, sm->bf, 3, &sm->bv_off, &sm->bv))
        goto nomem;
    sm->onb = st_calloc_array(sm->nv, 1);
    if (!sm->onb)
        goto nomem;
    for (size_t i = 0; i < 3 * sm->nbf; i++)
        sm->onb[sm->bf[i]] = 1;
    for (size_t v = 0; v < sm->nv; v++)
        sm->nbv += sm->onb[v];

    /* greedy colouring in vertex order */
    uint32_t *col = st_malloc_array(sm->nv, sizeof *col);
    unsigned char *used = NULL;
    size_t maxdeg = 0;
    for (size_t v = 0; v < sm->nv; v++) {
        size_t d = sm->vv_off[v + 1] - sm->vv_off[v];
        if (d > maxdeg)
            maxdeg = d;
    }
    used = st_calloc_array(maxdeg + 2, 1);
    if (!col || !used) {
        free(col);
        free(used);
        goto nomem;
    }
    size_t ncol = 0;
    for (size_t v = 0; v < sm->nv; v++) {
        for (size_t j = sm->vv_off[v]; j < sm->vv_off[v + 1]; j++)
            if (sm->vv[j] < v && col[sm->vv[j]] <= maxdeg)
                used[col[sm->vv[j]]] = 1;
        uint32_t c = 0;
        while (used[c])
            c++;
        col[v] = c;
        if (c + 1 > ncol)
            ncol = c + 1;
        for (size_t j = sm->vv_off[v]; j < sm->vv_off[v + 1]; j++)
            if (sm->vv[j] < v && col[sm->vv[j]] <= maxdeg)
                used[col[sm->vv[j]]] = 0;
    }
    free(used);
    sm->ncolours = ncol;
    sm->col_off = st_calloc_array(ncol + 1, sizeof *sm->col_off);
    sm->col_v = st_malloc_array(sm->nv, sizeof *sm->col_v);
    if (!sm->col_off || !sm->col_v) {
        free(col);
        goto nomem;
    }
    for (size_t v = 0; v < sm->nv; v++)
        sm->col_off[col[v] + 1]++;
    for (size_t c = 0; c < ncol; c++)
        sm->col_off[c + 1] += sm->col_off[c];
    {
        size_t *fill = st_malloc_array(ncol + 1, sizeof *fill);
        if (!fill) {
            free(col);
            goto nomem;
        }
        memcpy(fill, sm->col_off, (ncol + 1) * sizeof *fill);
        for (size_t v = 0; v < sm->nv; v++)
            sm->col_v[fill[col[v]]++] = (uint32_t)v;
        free(fill);
    }
    free(col);
    return ST_OK;
nomem:
    sm_mesh_free(sm);
    return st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory (mesh incidence)");
}

size_t sm_count_nonpositive(const st_tetmesh *m)
{
    size_t bad = 0;
    #pragma omp parallel for schedule(static) reduction(+ : bad) if (PAR_CHEAP(m->ntets))
    for (size_t t = 0; t < m->ntets; t++) {
        const uint32_t *c = m->tets + 4 * t;
        if (!(st_orient3d(m->xyz + 3 * (size_t)c[0], m->xyz + 3 * (size_t)c[1],
                          m->xyz + 3 * (size_t)c[2], m->xyz + 3 * (size_t)c[3]) < 0))
            bad++;
    }
    return bad;
}

/* The corners of tet t with v replaced by p. */
static void star_corners(const sm_mesh *sm, uint32_t t, uint32_t v,
                         const double p[3], const double *q[4])
{
    const uint32_t *c = sm->m->tets + 4 * (size_t)t;
    for (int k = 0; k < 4; k++)
        q[k] = c[k] == v ? p : sm->m->xyz + 3 * (size_t)c[k];
}

int sm_star_positive(const sm_mesh *sm, uint32_t v, const double p[3])
{
    for (size_t j = sm->vt_off[v]; j < sm->vt_off[v + 1]; j++) {
        const double *q[4];
        star_corners(sm, sm->vt[j], v, p, q);
        /* positive orientation (tetmesh.h): orient3d < 0 */
        if (!(st_orient3d(q[0], q[1], q[2], q[3]) < 0))
            return 0;
    }
    return 1;
}

/* Degrees per radian, as tetqual.c has it, so the angles agree. */
#define SM_RAD2DEG (180.0 / 3.14159265358979323846)

/* The two extreme dihedrals of a tet as (|u x v|, u . v) pairs: the
 * smallest at (*ylo, *xlo), the largest at (*yhi, *xhi). Returns 0 for a
 * degenerate case (see sm_tet_score), which st_tet_dihedral_range must
 * score. */
static inline int tet_extremes(const double *a, const double *b, const double *c,
                               const double *d, double *ylo, double *xlo,
                               double *yhi, double *xhi)
{
    double y[6], x[6];
    if (!tq_tet_pairs(a, b, c, d, y, x))
        return 0;
    int imin = 0, imax = 0;   /* smallest angle: largest x / y */
    for (int i = 1; i < 6; i++) {
        if (x[i] * y[imin] > x[imin] * y[i])
            imin = i;
        if (x[i] * y[imax] < x[imax] * y[i])
            imax = i;
    }
    *ylo = y[imin];
    *xlo = x[imin];
    *yhi = y[imax];
    *xhi = x[imax];
    return 1;
}

static double degenerate_score(const double *a, const double *b, const double *c,
                               const double *d)
{
    double lo, hi;
    st_tet_dihedral_range(a, b, c, d, &lo, &hi);
    double s2 = ST_FIT_MAX_WEIGHT * (180.0 - hi);
    return lo < s2 ? lo : s2;
}

/* The score is asked for tens of times per trial move (the quality pass
 * scores ~40 candidate positions of a star of ~20 tets): instead of six
 * atan2 calls (st_tet_dihedral_range), the dihedral at each edge is kept
 * as the pair (|u x v|, u . v) of tetqual.c's formula, the smallest and
 * largest angles are found by comparing the pairs (atan2(y, x) with y > 0
 * decreases as x / y grows: compare x_i y_j with x_j y_i), and only those
 * two go through atan2. Degenerate cases (a face without area, parallel
 * normals, non-finite values) go to st_tet_dihedral_range. */
double sm_tet_score(const double *a, const double *b, const double *c,
                    const double *d)
{
    double ylo, xlo, yhi, xhi;
    if (!tet_extremes(a, b, c, d, &ylo, &xlo, &yhi, &xhi))
        return degenerate_score(a, b, c, d);
    double lo = atan2(ylo, xlo) * SM_RAD2DEG;
    double hi = atan2(yhi, xhi) * SM_RAD2DEG;
    double s2 = ST_FIT_MAX_WEIGHT * (180.0 - hi);
    return lo < s2 ? lo : s2;
}

/* Tets per block of sm_star_score's pruned minimum. */
#define SM_STAR_BLOCK 64
/* Ratios r = x / y whose atan2 sm_star_score may skip: a tet is skipped
 * when its ratio is further than SM_PRUNE_GAP * (1 + |r*|)^2 from the
 * extreme r*, which parts the angles by more than 2e-7 rad, far beyond
 * the few ulps of atan2 and of the division; past |r*| > SM_PRUNE_MAX
 * (angles within 1e-6 rad of 0 or 180 degrees) nothing is skipped. */
#define SM_PRUNE_GAP 1e-6
#define SM_PRUNE_MAX 1e6

/* min over tets of min(lo_t, W (180 - hi_t)) is min(min_t lo_t,
 * W (180 - max_t hi_t)) exactly (the rounded subtraction and product are
 * monotone), and atan2(y, x) falls as x / y grows: so atan2 is needed only
 * for the tets whose ratio is near the extreme one. The per-tet choice of
 * the extreme edge is sm_tet_score's, so the result is sm_tet_score's
 * minimum bit for bit. */
/* A threshold for star_block_score: a tet whose ratios come near the
 * angles where its score is thr (rlo >= lo, rhi <= hi) is scored exactly
 * at once, and at or below thr ends the block (*below). */
typedef struct score_cut {
    double thr, lo, hi;
    int *below;
} score_cut;

/* The block's minimum over the tets j0 <= j < j1 of v's star but `skip`
 * (an index into vt; SIZE_MAX: none), with v at p. */
static double star_block_score(const sm_mesh *sm, uint32_t v, const double p[3],
                               size_t j0, size_t j1, size_t skip, const score_cut *cut)
{
    double ylo[SM_STAR_BLOCK], xlo[SM_STAR_BLOCK], yhi[SM_STAR_BLOCK], xhi[SM_STAR_BLOCK];
    double rlo[SM_STAR_BLOCK], rhi[SM_STAR_BLOCK];
    double s = INFINITY, rlo_max = -INFINITY, rhi_min = INFINITY;
    size_t n = 0;
    for (size_t j = j0; j < j1; j++) {
        if (j == skip)
            continue;
        const double *q[4];
        star_corners(sm, sm->vt[j], v, p, q);
        if (!tet_extremes(q[0], q[1], q[2], q[3], ylo + n, xlo + n, yhi + n, xhi + n)) {
            double x = degenerate_score(q[0], q[1], q[2], q[3]);
            if (cut && x <= cut->thr) {
                *cut->below = 1;
                return x;
            }
            if (x < s)
                s = x;
            continue;
        }
        rlo[n] = xlo[n] / ylo[n];
        rhi[n] = xhi[n] / yhi[n];
        if (cut && (!(rlo[n] < cut->lo) || !(rhi[n] > cut->hi))) {
            /* sm_tet_score's value for this tet, bit for bit */
            double a = atan2(ylo[n], xlo[n]) * SM_RAD2DEG;
            double b = ST_FIT_MAX_WEIGHT * (180.0 - atan2(yhi[n], xhi[n]) * SM_RAD2DEG);
            double x = a < b ? a : b;
            if (x <= cut->thr) {
                *cut->below = 1;
                return x;
            }
        }
        if (rlo[n] > rlo_max)
            rlo_max = rlo[n];
        if (rhi[n] < rhi_min)
            rhi_min = rhi[n];
        n++;
    }
    if (n == 0)
        return s;
    double cut_lo = -INFINITY, cut_hi = INFINITY;
    if (fabs(rlo_max) <= SM_PRUNE_MAX)
        cut_lo = rlo_max - SM_PRUNE_GAP * (1.0 + fabs(rlo_max)) * (1.0 + fabs(rlo_max));
    if (fabs(rhi_min) <= SM_PRUNE_MAX)
        cut_hi = rhi_min + SM_PRUNE_GAP * (1.0 + fabs(rhi_min)) * (1.0 + fabs(rhi_min));
    double lo = INFINITY, hi = -INFINITY;
    for (size_t i = 0; i < n; i++) {
        if (!(rlo[i] < cut_lo)) {
            double a = atan2(ylo[i], xlo[i]) * SM_RAD2DEG;
            if (a < lo)
                lo = a;
        }
        if (!(rhi[i] > cut_hi)) {
            double a = atan2(yhi[i], xhi[i]) * SM_RAD2DEG;
            if (a > hi)
                hi = a;
        }
    }
    double s2 = ST_FIT_MAX_WEIGHT * (180.0 - hi);
    double t = lo < s2 ? lo : s2;
    return t < s ? t : s;
}

double sm_star_score(const sm_mesh *sm, uint32_t v, const double p[3])
{
    double s = INFINITY;
    for (size_t j = sm->vt_off[v]; j < sm->vt_off[v + 1]; j += SM_STAR_BLOCK) {
        size_t j1 = j + SM_STAR_BLOCK < sm->vt_off[v + 1] ? j + SM_STAR_BLOCK : sm->vt_off[v + 1];
        double x = star_block_score(sm, v, p, j, j1, SIZE_MAX, NULL);
        if (x < s)
            s = x;
    }
    return s;
}

double sm_star_score_above(const sm_mesh *sm, uint32_t v, const double p[3], size_t first,
                           double thr)
{
    size_t n = sm->vt_off[v + 1] - sm->vt_off[v];
    /* Tet `first` is not scored again below: its score (sm_tet_score's,
     * bit for bit the value the blocks take for it) joins the minimum
     * as s0, and being above thr it never ends a block early, so the
     * result is the same with it in the blocks or out. */
    double s0 = INFINITY;
    size_t skip = SIZE_MAX;
    if (first < n) {
        const double *q[4];
        star_corners(sm, sm->vt[sm->vt_off[v] + first], v, p, q);
        s0 = sm_tet_score(q[0], q[1], q[2], q[3]);
        if (s0 <= thr)
            return s0;   /* a tet of the star's minimum: at most thr too */
        skip = sm->vt_off[v] + first;
    }
    /* The ratios r = x / y at the angles where a tet's score is thr: its
     * min dihedral is at most thr where r >= cot(thr), its max at least
     * 180 - thr / W where r <= cot(that); loosened by far more than the
     * rounding, since the exact score decides (outside (0, 60) degrees,
     * every tet is scored exactly). */
    int below = 0;
    score_cut cut = {thr, -INFINITY, INFINITY, &below};
    if (thr > 0.0 && thr < 60.0) {
        const double r = 3.14159265358979323846 / 180.0;
        double a = thr * r, b = (180.0 - thr / ST_FIT_MAX_WEIGHT) * r;
        double ca = cos(a) / sin(a), cb = cos(b) / sin(b);
        cut.lo = ca - 1e-6 * (1.0 + fabs(ca));
        cut.hi = cb + 1e-6 * (1.0 + fabs(cb));
    }
    double s = s0;
    for (size_t j = sm->vt_off[v]; j < sm->vt_off[v + 1]; j += SM_STAR_BLOCK) {
        size_t j1 = j + SM_STAR_BLOCK < sm->vt_off[v + 1] ? j + SM_STAR_BLOCK : sm->vt_off[v + 1];
        double x = star_block_score(sm, v, p, j, j1, skip, &cut);
        if (below)
            return x;
        if (x < s)
            s = x;
    }
    return s;
}

void sm_dihedral_range(const st_tetmesh *m, double *mind, double *maxd)
{
    double lo = 180.0, hi = 0.0;
    #pragma omp parallel for schedule(static) reduction(min : lo) reduction(max : hi) \
        if (PAR_MOVES(m->ntets))
    for (size_t t = 0; t < m->ntets; t++) {
        const uint32_t *c = m->tets + 4 * t;
        double a, b;
        st_tet_dihedral_range(m->xyz + 3 * (size_t)c[0], m->xyz + 3 * (size_t)c[1],
                              m->xyz + 3 * (size_t)c[2], m->xyz + 3 * (size_t)c[3],
                              &a, &b);
        if (a < lo)
            lo = a;
        if (b > hi)
            hi = b;
    }
    if (mind)
        *mind = lo;
    if (maxd)
        *maxd = hi;
}

void sm_odt_target(const sm_mesh *sm, uint32_t v, double out[3])
{
    double acc[3] = {0, 0, 0}, w = 0.0;
    const double *x = sm->m->xyz + 3 * (size_t)v;
    for (size_t j = sm->vt_off[v]; j < sm->vt_off[v + 1]; j++) {
        const double *q[4];
        star_corners(sm, sm->vt[j], v, x, q);
        double vol = st_tet_volume(q[0], q[1], q[2], q[3]);
        double cc[3];
        if (vol <= 0.0 || !st_tet_circumcenter(q[0], q[1], q[2], q[3], cc))
            continue;
        for (int a = 0; a < 3; a++)
            acc[a] += vol * cc[a];
        w += vol;
    }
    for (int a = 0; a < 3; a++)
        out[a] = w > 0.0 ? acc[a] / w : x[a];
    if (!(isfinite(out[0]) && isfinite(out[1]) && isfinite(out[2])))
        memcpy(out, x, 3 * sizeof *out);
}

double sm_boundary_volume(const sm_mesh *sm, const double *xyz)
{
    if (sm->nbf == 0)
        return 0.0;
    /* relative to one boundary vertex, so far-from-origin models keep
     * their digits */
    const double *o = xyz + 3 * (size_t)sm->bf[0];
    double v = 0.0;
    for (size_t f = 0; f < sm->nbf; f++) {
        const double *pa = xyz + 3 * (size_t)sm->bf[3 * f];
        const double *pb = xyz + 3 * (size_t)sm->bf[3 * f + 1];
        const double *pc = xyz + 3 * (size_t)sm->bf[3 * f + 2];
        double a[3], b[3], c[3];
        for (int k = 0; k < 3; k++) {
            a[k] = pa[k] - o[k];
            b[k] = pb[k] - o[k];
            c[k] = pc[k] - o[k];
        }
        v += a[0] * (b[1] * c[2] - b[2] * c[1]) + a[1] * (b[2] * c[0] - b[0] * c[2]) +
             a[2] * (b[0] * c[1] - b[1] * c[0]);
    }
    return v / 6.0;
}

double sm_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

int sm_par_gate_open(sm_par_gate *g, size_t n)
{
    if (!PAR_CHECKED(n))
        return 0;
    if (g && g->wait) {
        g->wait--;
        return 0;
    }
    return 1;
}

void sm_par_gate_note(sm_par_gate *g, int team, double wall, double busy)
{
    if (!g || team < 2)
        return;
    if (wall - busy > fmax(PAR_GATE_SLACK, busy)) {
        g->backoff = g->backoff ? (g->backoff < 2048 ? 2 * g->backoff : 4096) : 16;
        g->wait = g->backoff;
    } else {
        g->backoff /= 2;
    }
}
