/*
 * lattice_clean.c - the density filter's cleanup: one face-connected piece
 * of tets per piece of the pseudo volume, a 2-manifold boundary, and the
 * pieces too thin for the lattice named (see lattice.h).
 *
 * Spillmann et al. 2006 (section 4) keep a tet when its density rho is at
 * least 1/2; nothing in that rule keeps the kept tets together. The repair
 * here works on the lattice's combinatorics (L->star, L->nbr): a vertex is
 * manifold when, on its link sphere, the kept tets and the others are each
 * one edge-connected set (then the kept set is a disc: on a sphere a
 * connected set whose complement is connected is a disc, and a pinch at a
 * link vertex - a non-manifold mesh edge - would split the complement by
 * the Jordan curve through it). Costs are masses of rho over tet volume,
 * so the cleanup changes the volume the least it can at each step.
 *
 * Everything is serial and in index order: the result depends only on the
 * input.
 */
#include "../base/fpenv.h"
#include "souptet/lattice.h"
#include "../base/unionfind.h"
#include "souptet/mem.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* Join path cost per tet on top of (1 - rho) vol, in units of the tet's
 * volume: so that among paths of full-density tets the shortest wins. */
#define JOIN_STEP 1e-3

typedef struct cleaner {
    const st_lattice *L;
    const st_grid *g;
    const double *rho;
    unsigned char *keep;
    unsigned char *fixed;     /* tets a join added: never dropped */
    double *vol;              /* tet volumes */
    uint32_t *tlabel;         /* voxel piece of each tet, 0: none */
    uint32_t *vlabel;         /* voxel piece of each voxel, 0: outside */
    size_t npieces;
    size_t *par;              /* scratch: 2 star-sized union-finds */
    unsigned char *scratch_keep;  /* 2 stars of keep flags */
    size_t *groot;            /* a star's groups and their costs */
    double *gcost;
    st_density_clean_stats *st;
} cleaner;

/* ---- pieces of the pseudo volume ---- */

static st_status label_voxels(cleaner *c, st_error *err)
{
    const st_grid *g = c->g;
    size_t n = g->nx * g->ny * g->nz;
    c->vlabel = st_calloc_array(n, sizeof *c->vlabel);
    size_t *queue = st_malloc_array(n + 1, sizeof *queue);
    if (!c->vlabel || !queue) {
        free(queue);
        return st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory");
    }
    uint32_t lab = 0;
    for (size_t s = 0; s < n; s++) {
        if (c->vlabel[s] || !(g->data[s] < 0.0f))
            continue;
        lab++;
        size_t qh = 0, qt = 0;
        queue[qt++] = s;
        c->vlabel[s] = lab;
        while (qh < qt) {
            size_t v = queue[qh++];
            size_t i = v % g->nx, j = (v / g->nx) % g->ny, k = v / (g->nx * g->ny);
            size_t nb[6];
            int nn = 0;
            if (i > 0) nb[nn++] = v - 1;
            if (i + 1 < g->nx) nb[nn++] = v + 1;
            if (j > 0) nb[nn++] = v - g->nx;
            if (j + 1 < g->ny) nb[nn++] = v + g->nx;
            if (k > 0) nb[nn++] = v - g->nx * g->ny;
            if (k + 1 < g->nz) nb[nn++] = v + g->nx * g->ny;
            for (int q = 0; q < nn; q++)
                if (!c->vlabel[nb[q]] && g->data[nb[q]] < 0.0f) {
                    c->vlabel[nb[q]] = lab;
                    queue[qt++] = nb[q];
                }
        }
    }
    free(queue);
    c->npieces = lab;
    return ST_OK;
}

static uint32_t point_label(const cleaner *c, const double p[3])
{
    size_t ijk[3];
    if (!st_grid_voxel_of(c->g, p, ijk))
        return 0;
    return c->vlabel[st_grid_index(c->g, ijk[0], ijk[1], ijk[2])];
}

static void label_tets(cleaner *c)
{
    const st_lattice *L = c->L;
    for (size_t t = 0; t < L->ntets; t++) {
        const uint32_t *v = L->tets + 4 * t;
        const double *p[4];
        for (int a = 0; a < 4; a++)
            p[a] = L->xyz + 3 * (size_t)v[a];
        double e1[3], e2[3], e3[3], ct[3];
        for (int a = 0; a < 3; a++) {
            e1[a] = p[1][a] - p[0][a];
            e2[a] = p[2][a] - p[0][a];
            e3[a] = p[3][a] - p[0][a];
            ct[a] = 0.25 * (p[0][a] + p[1][a] + p[2][a] + p[3][a]);
        }
        c->vol[t] = fabs(e1[0] * (e2[1] * e3[2] - e2[2] * e3[1]) -
                         e1[1] * (e2[0] * e3[2] - e2[2] * e3[0]) +
                         e1[2] * (e2[0] * e3[1] - e2[1] * e3[0])) / 6.0;
        uint32_t l = c->rho[t] > 0.0 ? point_label(c, ct) : 0;
        for (int a = 0; a < 4 && !l && c->rho[t] > 0.0; a++)
            l = point_label(c, p[a]);
        c->tlabel[t] = l;
    }
}

/* ---- manifold vertices ---- */

/* Groups of the star tets of v with keep == want, joined through faces
 * at v; par[] is indexed by position in the star. Returns the count. */
static size_t star_groups(const cleaner *c, uint32_t v, int want)
{
    const st_lattice *L = c->L;
    size_t a0 = L->star_off[v], k = L->star_off[v + 1] - a0;
    const uint32_t *S = L->star + a0;
    for (size_t q = 0; q < k; q++)
        c->par[q] = q;
    for (size_t q = 0; q < k; q++) {
        size_t t = S[q];
        if ((c->keep[t] != 0) != want)
            continue;
        for (int i = 0; i < 4; i++) {
            if (L->tets[4 * t + (size_t)i] == v)
                continue;
            int64_t u = L->nbr[4 * t + (size_t)i];
            if (u < 0 || (c->keep[u] != 0) != want)
                continue;
            /* Stars are ascending: find u's position. */
            size_t lo = 0, hi = k;
            while (lo < hi) {
                size_t mid = (lo + hi) / 2;
                if (S[mid] < (uint32_t)u)
                    lo = mid + 1;
                else
                    hi = mid;
            }
            if (lo < k && S[lo] == (uint32_t)u)
                uf_join(c->par, q, lo);
        }
    }
    size_t n = 0;
    for (size_t q = 0; q < k; q++)
        n += (c->keep[S[q]] != 0) == want && uf_find(c->par, q) == q;
    return n;
}

static int star_complete(const st_lattice *L, uint32_t v)
{
    for (size_t a = L->star_off[v]; a < L->star_off[v + 1]; a++) {
        size_t t = L->star[a];
        for (int i = 0; i < 4; i++)
            if (L->tets[4 * t + (size_t)i] != v && L->nbr[4 * t + (size_t)i] < 0)
                return 0;
    }
    return 1;
}

/* 1 when v is on the kept set's boundary and not manifold there. */
static int vertex_bad(const cleaner *c, uint32_t v)
{
    const st_lattice *L = c->L;
    size_t kept = 0, k = L->star_off[v + 1] - L->star_off[v];
    for (size_t a = L->star_off[v]; a < L->star_off[v + 1]; a++)
        kept += c->keep[L->star[a]] != 0;
    if (kept == 0 || kept == k)
        return 0;
    return star_groups(c, v, 1) > 1 || star_groups(c, v, 0) > 1;
}

/* The groups of v's star with keep == want (after star_groups): their
 * roots (positions in the star) into root[] and rho-weighted costs into
 * cost[] (kept: rho vol, what dropping costs; unkept: (1 - rho) vol, what
 * filling costs), sorted by ascending cost (ties: star order). */
static size_t group_costs(const cleaner *c, uint32_t v, int want,
                          size_t *root, double *cost)
{
    const st_lattice *L = c->L;
    size_t a0 = L->star_off[v], k = L->star_off[v + 1] - a0;
    const uint32_t *S = L->star + a0;
    star_groups(c, v, want);
    size_t n = 0;
    for (size_t q = 0; q < k; q++) {
        if ((c->keep[S[q]] != 0) != want || uf_find(c->par, q) != q)
            continue;
        double w = 0;
        for (size_t r = 0; r < k; r++)
            if ((c->keep[S[r]] != 0) == want && uf_find(c->par, r) == q)
                w += (want ? c->rho[S[r]] : 1.0 - c->rho[S[r]]) * c->vol[S[r]];
        size_t i = n++;
        while (i > 0 && cost[i - 1] > w) {
            cost[i] = cost[i - 1];
            root[i] = root[i - 1];
            i--;
        }
        cost[i] = w;
        root[i] = q;
    }
    return n;
}

/* Mend v the cheaper way; returns 1 when it changed something. Fill adds
 * the unkept groups of the star cheapest first, drop removes the kept
 * groups cheapest first, each until v is manifold (at most all groups but
 * the costliest); both are tried and the cheaper is kept. */
static int mend_vertex(cleaner *c, uint32_t v)
{
    const st_lattice *L = c->L;
    size_t a0 = L->star_off[v], k = L->star_off[v + 1] - a0;
    const uint32_t *S = L->star + a0;
    unsigned char *save = c->scratch_keep;
    for (size_t q = 0; q < k; q++)
        save[q] = c->keep[S[q]];
    /* Fill: allowed with a complete star and one voxel piece among the
     * kept tets. */
    int can_fill = star_complete(L, v);
    uint32_t lab = 0;
    for (size_t q = 0; q < k; q++) {
        size_t t = S[q];
        if (c->keep[t] && c->tlabel[t]) {
            if (lab && c->tlabel[t] != lab)
                can_fill = 0;
            lab = c->tlabel[t];
        }
    }
    double fill_cost = INFINITY, drop_cost = INFINITY;
    size_t *root = c->groot;
    double *cost = c->gcost;
    unsigned char *fill_keep = c->scratch_keep + k;
    if (can_fill) {
        size_t n = group_costs(c, v, 0, root, cost);
        /* keep a copy of the group ids: star_groups is rerun below */
        size_t *gid = c->par + k;
        for (size_t q = 0; q < k; q++)
            gid[q] = uf_find(c->par, q);
        double sum = 0;
        for (size_t i = 0; i + 1 < n || (i < n && n == 1); i++) {
            for (size_t q = 0; q < k; q++)
                if (!save[q] && gid[q] == root[i])
                    c->keep[S[q]] = 1;
            sum += cost[i];
            if (!vertex_bad(c, v))
                break;
        }
        if (!vertex_bad(c, v)) {
            fill_cost = sum;
            for (size_t q = 0; q < k; q++)
                fill_keep[q] = c->keep[S[q]];
        }
        for (size_t q = 0; q < k; q++)
            c->keep[S[q]] = save[q];
    }
    /* Drop: never tets a join added. */
    {
        size_t n = group_costs(c, v, 1, root, cost);
        size_t *gid = c->par + k;
        for (size_t q = 0; q < k; q++)
            gid[q] = uf_find(c->par, q);
        double sum = 0;
        int ok = n >= 2;
        for (size_t i = 0; ok && i + 1 < n; i++) {
            for (size_t q = 0; q < k; q++)
                if (save[q] && gid[q] == root[i]) {
                    if (c->fixed[S[q]])
                        ok = 0;
                    c->keep[S[q]] = 0;
                }
            sum += cost[i];
            if (!vertex_bad(c, v))
                break;
        }
        if (ok && !vertex_bad(c, v))
            drop_cost = sum;
        if (!(drop_cost < fill_cost))
            for (size_t q = 0; q < k; q++)
                c->keep[S[q]] = save[q];
    }
    if (fill_cost <= drop_cost && isfinite(fill_cost)) {
        for (size_t q = 0; q < k; q++) {
            c->keep[S[q]] = fill_keep[q];
            c->st->filled += fill_keep[q] && !save[q];
        }
        return 1;
    }
    if (isfinite(drop_cost)) {
        for (size_t q = 0; q < k; q++)
            c->st->dropped += save[q] && !c->keep[S[q]];
        return 1;
    }
    return 0;
}

/* Rounds over all vertices until none changes; returns 1 if any did. */
static int mend_all(cleaner *c)
{
    int any = 0;
    for (int round = 0; round < ST_CLEAN_ROUNDS; round++) {
        int changed = 0;
        for (size_t v = 0; v < c->L->nverts; v++)
            if (vertex_bad(c, (uint32_t)v) && mend_vertex(c, (uint32_t)v))
                changed = 1;
        any |= changed;
        if (!changed)
            break;
    }
    return any;
}

/* ---- pieces of tets ---- */

typedef struct heap_item {
    double cost;
    size_t t;
} heap_item;

static void heap_push(heap_item *h, size_t *n, heap_item x)
{
    size_t i = (*n)++;
    while (i > 0) {
        size_t p = (i - 1) / 2;
        if (h[p].cost < x.cost || (h[p].cost == x.cost && h[p].t <= x.t))
            break;
        h[i] = h[p];
        i = p;
    }
    h[i] = x;
}

static heap_item heap_pop(heap_item *h, size_t *n)
{
    heap_item top = h[0], x = h[--(*n)];
    size_t i = 0;
    for (;;) {
        size_t l = 2 * i + 1, r = l + 1, m = i;
        heap_item best = x;
        if (l < *n && (h[l].cost < best.cost ||
                       (h[l].cost == best.cost && h[l].t < best.t))) {
            m = l;
            best = h[l];
        }
        if (r < *n && (h[r].cost < best.cost ||
                       (h[r].cost == best.cost && h[r].t < best.t))) {
            m = r;
            best = h[r];
        }
        if (m == i)
            break;
        h[i] = h[m];
        i = m;
    }
    if (*n)
        h[i] = x;
    return top;
}

/* Cheapest face path from the tets with root `from` to those with root
 * `to` through unkept tets; when it costs less than `budget`, keep (and fix)
 * its tets and set *joined. */
static st_status join_piece(cleaner *c, const size_t *root, size_t from,
                            size_t to, double budget, int *joined,
                            st_error *err)
{
    const st_lattice *L = c->L;
    size_t nt = L->ntets;
    double *dist = st_malloc_array(nt, sizeof *dist);
    int64_t *prev = st_malloc_array(nt, sizeof *prev);
    heap_item *h = st_malloc_array(4 * nt + 1, sizeof *h);
    if (!dist || !prev || !h) {
        free(dist); free(prev); free(h);
        return st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory");
    }
    size_t nh = 0;
    for (size_t t = 0; t < nt; t++) {
        dist[t] = INFINITY;
        prev[t] = -1;
        if (c->keep[t] && root[t] == from) {
            dist[t] = 0;
            heap_push(h, &nh, (heap_item){0, t});
        }
    }
    *joined = 0;
    int64_t hit = -1;
    while (nh) {
        heap_item x = heap_pop(h, &nh);
        if (x.cost > dist[x.t])
            continue;
        if (x.cost >= budget)
            break;
        if (c->keep[x.t] && root[x.t] == to) {
            hit = (int64_t)x.t;
            break;
        }
        for (int i = 0; i < 4; i++) {
            int64_t u = L->nbr[4 * x.t + (size_t)i];
            if (u < 0)
                continue;
            double step = 0;
            if (!c->keep[u])
                step = (1.0 - c->rho[u] + JOIN_STEP) * c->vol[u];
            else if (root[u] != to)
                continue;   /* through other kept pieces: no */
            if (x.cost + step < dist[u]) {
                dist[u] = x.cost + step;
                prev[u] = (int64_t)x.t;
                heap_push(h, &nh, (heap_item){dist[u], (size_t)u});
            }
        }
    }
    if (hit >= 0) {
        for (int64_t t = prev[hit]; t >= 0 && !c->keep[t]; t = prev[t]) {
            c->keep[t] = 1;
            c->fixed[t] = 1;
            c->st->join_tets++;
        }
        *joined = 1;
    }
    free(dist); free(prev); free(h);
    return ST_OK;
}

/* One pass over the tet pieces: join or drop every piece that is not the
 * main piece of a voxel piece. *changed says whether keep changed. */
static st_status settle_pieces(cleaner *c, int *changed, size_t *ntetpieces,
                               int edit, st_error *err)
{
    const st_lattice *L = c->L;
    size_t nt = L->ntets, np = c->npieces;
    *changed = 0;
    size_t *root = st_malloc_array(nt, sizeof *root);
    double *mass = st_calloc_array(nt, sizeof *mass);      /* per root */
    double *best = st_malloc_array(np + 1, sizeof *best);  /* per label */
    size_t *main = st_malloc_array(np + 1, sizeof *main);
    /* Per root: its heaviest voxel piece (by rho vol). */
    uint32_t *rlab = st_calloc_array(nt, sizeof *rlab);
    double *rlabw = st_calloc_array(nt, sizeof *rlabw);
    if (!root || !mass || !best || !main || !rlab || !rlabw) {
        free(root); free(mass); free(best); free(main); free(rlab); free(rlabw);
        return st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory");
    }
    for (size_t t = 0; t < nt; t++)
        root[t] = t;
    for (size_t t = 0; t < nt; t++)
        if (c->keep[t])
            for (int i = 0; i < 4; i++) {
                int64_t u = L->nbr[4 * t + (size_t)i];
                if (u >= 0 && c->keep[u])
                    uf_join(root, t, (size_t)u);
            }
    for (size_t t = 0; t < nt; t++)
        root[t] = uf_find(root, t);
    /* Mass of each (root, label) pair: sort the kept tets by (label, root)
     * and sum runs. */
    size_t nk = 0;
    for (size_t t = 0; t < nt; t++)
        nk += c->keep[t] != 0;
    for (size_t l = 0; l <= np; l++) {
        best[l] = 0;
        main[l] = SIZE_MAX;
    }
    /* Bucket by label (counting sort), then by root within a label using a
     * per-root accumulator that is reset after each label. */
    size_t *loff = st_calloc_array(np + 2, sizeof *loff);
    size_t *order = st_malloc_array(nk + 1, sizeof *order);
    double *acc = st_calloc_array(nt, sizeof *acc);
    if (!loff || !order || !acc) {
        free(loff); free(order); free(acc);
        free(root); free(mass); free(best); free(main); free(rlab); free(rlabw);
        return st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory");
    }
    for (size_t t = 0; t < nt; t++)
        if (c->keep[t])
            loff[c->tlabel[t] + 1]++;
    for (size_t l = 0; l <= np; l++)
        loff[l + 1] += loff[l];
    {
        size_t *fill = st_malloc_array(np + 2, sizeof *fill);
        if (!fill) {
            free(loff); free(order); free(acc);
            free(root); free(mass); free(best); free(main); free(rlab); free(rlabw);
            return st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory");
        }
        memcpy(fill, loff, (np + 2) * sizeof *fill);
        for (size_t t = 0; t < nt; t++)
            if (c->keep[t])
                order[fill[c->tlabel[t]]++] = t;
        free(fill);
    }
    for (size_t t = 0; t < nt; t++)
        if (c->keep[t])
            mass[root[t]] += c->rho[t] * c->vol[t];
    for (size_t l = 1; l <= np; l++) {
        for (size_t a = loff[l]; a < loff[l + 1]; a++) {
            size_t t = order[a];
            acc[root[t]] += c->rho[t] * c->vol[t];
        }
        for (size_t a = loff[l]; a < loff[l + 1]; a++) {
            size_t r = root[order[a]];
            double w = acc[r];
            if (w > best[l] || (w == best[l] && r < main[l])) {
                best[l] = w;
                main[l] = r;
            }
            if (w > rlabw[r] || (w == rlabw[r] && (!rlab[r] || l < rlab[r]))) {
                rlabw[r] = w;
                rlab[r] = (uint32_t)l;
            }
        }
        for (size_t a = loff[l]; a < loff[l + 1]; a++)
            acc[root[order[a]]] = 0;
    }
    free(loff); free(order); free(acc);
    /* Is each root a main piece? */
    unsigned char *is_main = st_calloc_array(nt, 1);
    st_status s = ST_OK;
    if (!is_main)
        s = st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory");
    size_t npieces = 0;
    for (size_t l = 1; !s && l <= np; l++)
        if (main[l] != SIZE_MAX)
            is_main[main[l]] = 1;
    for (size_t r = 0; !s && r < nt; r++) {
        if (!c->keep[r] || root[r] != r)
            continue;
        npieces++;
        if (is_main[r] || !edit)
            continue;
        int joined = 0;
        uint32_t l = rlab[r];
        if (l && main[l] != SIZE_MAX)
            s = join_piece(c, root, r, main[l], mass[r], &joined, err);
        if (s)
            break;
        if (joined) {
            c->st->joins++;
        } else {
            c->st->islands++;
            for (size_t t = r; t < nt; t++)
                if (c->keep[t] && root[t] == r && !c->fixed[t]) {
                    c->keep[t] = 0;
                    c->st->island_tets++;
                }
        }
        *changed = 1;
    }
    *ntetpieces = npieces;
    free(is_main);
    free(root); free(mass); free(best); free(main); free(rlab); free(rlabw);
    return s;
}

/* ---- thin parts ---- */

static st_status thin_parts(cleaner *c, double longest, st_error *err)
{
    const st_grid *g = c->g;
    size_t np = c->npieces, n = g->nx * g->ny * g->nz;
    size_t *count = st_calloc_array(np + 1, sizeof *count);
    double *depth = st_calloc_array(np + 1, sizeof *depth);
    double *held = st_calloc_array(np + 1, sizeof *held);
    size_t *box = st_malloc_array(np + 1, 6 * sizeof *box);
    if (!count || !depth || !held || !box) {
        free(count); free(depth); free(held); free(box);
        return st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory");
    }
    for (size_t l = 0; l <= np; l++) {
        box[6 * l] = box[6 * l + 1] = box[6 * l + 2] = SIZE_MAX;
        box[6 * l + 3] = box[6 * l + 4] = box[6 * l + 5] = 0;
    }
    for (size_t v = 0; v < n; v++) {
        uint32_t l = c->vlabel[v];
        if (!l)
            continue;
        count[l]++;
        double d = -(double)g->data[v];
        if (d > depth[l])
            depth[l] = d;
        size_t ijk[3] = {v % g->nx, (v / g->nx) % g->ny, v / (g->nx * g->ny)};
        for (int a = 0; a < 3; a++) {
            if (ijk[a] < box[6 * l + (size_t)a])
                box[6 * l + (size_t)a] = ijk[a];
            if (ijk[a] > box[6 * l + 3 + (size_t)a])
                box[6 * l + 3 + (size_t)a] = ijk[a];
        }
    }
    for (size_t t = 0; t < c->L->ntets; t++)
        if (c->keep[t] && c->tlabel[t])
            held[c->tlabel[t]] += c->vol[t];
    double vv = g->voxel * g->voxel * g->voxel;
    double hh = c->L->h;
    for (size_t l = 1; l <= np; l++) {
        double frac = held[l] / ((double)count[l] * vv);
        if (frac >= ST_CLEAN_HELD)
            continue;
        if ((double)count[l] * vv < ST_CLEAN_SPECK * hh * hh * hh) {
            c->st->specks++;
            c->st->speck_voxels += count[l];
            continue;
        }
        size_t q = c->st->nthin++;
        if (q >= ST_CLEAN_MAX_THIN)
            continue;
        st_thin_part *p = &c->st->thin[q];
        p->voxels = count[l];
        p->held = frac;
        /* The deepest voxel centre is within half a voxel of the middle
         * of the part: add a voxel (half on each side). */
        p->thickness = 2.0 * depth[l] + g->voxel;
        for (int a = 0; a < 3; a++) {
            p->lo[a] = g->origin[a] + ((double)box[6 * l + (size_t)a] - 0.5) * g->voxel;
            p->hi[a] = g->origin[a] + ((double)box[6 * l + 3 + (size_t)a] + 0.5) * g->voxel;
        }
        p->cells = (size_t)ceil(longest / (0.5 * p->thickness));
    }
    free(count); free(depth); free(held); free(box);
    return ST_OK;
}

st_status st_lattice_density_clean(unsigned char *keep,
                                   st_density_clean_stats *stats,
                                   const st_lattice *L, const st_grid *g,
                                   const double *rho, double longest,
                                   st_error *err)
{
    st_density_clean_stats local;
    memset(&local, 0, sizeof local);
    cleaner c;
    memset(&c, 0, sizeof c);
    c.L = L;
    c.g = g;
    c.rho = rho;
    c.keep = keep;
    c.st = &local;
    size_t maxk = 0;
    for (size_t v = 0; v < L->nverts; v++)
        if (L->star_off[v + 1] - L->star_off[v] > maxk)
            maxk = L->star_off[v + 1] - L->star_off[v];
    c.fixed = st_calloc_array(L->ntets + 1, 1);
    c.vol = st_malloc_array(L->ntets + 1, sizeof *c.vol);
    c.tlabel = st_calloc_array(L->ntets + 1, sizeof *c.tlabel);
    c.par = st_malloc_array(2 * maxk + 1, sizeof *c.par);
    c.scratch_keep = st_malloc_array(2 * maxk + 1, 1);
    c.groot = st_malloc_array(maxk + 1, sizeof *c.groot);
    c.gcost = st_malloc_array(maxk + 1, sizeof *c.gcost);
    st_status s = ST_OK;
    if (!c.fixed || !c.vol || !c.tlabel || !c.par || !c.scratch_keep ||
        !c.groot || !c.gcost)
        s = st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory");
    if (!s)
        s = label_voxels(&c, err);
    if (!s) {
        label_tets(&c);
        for (size_t t = 0; t < L->ntets; t++)
            keep[t] = keep[t] != 0;
        local.pieces = c.npieces;
        for (int round = 0; round < ST_CLEAN_ROUNDS; round++) {
            int a = mend_all(&c), b = 0;
            s = settle_pieces(&c, &b, &local.tet_pieces, 1, err);
            if (s || (!a && !b))
                break;
        }
    }
    if (!s) {
        for (size_t v = 0; v < L->nverts; v++)
            local.bad_vertices_left += vertex_bad(&c, (uint32_t)v);
        int dummy;
        /* The final count of pieces (settle_pieces counted them before its
         * last edits, if any). */
        s = settle_pieces(&c, &dummy, &local.tet_pieces, 0, err);
    }
    if (!s)
        s = thin_parts(&c, longest, err);
    free(c.fixed);
    free(c.vol);
    free(c.tlabel);
    free(c.vlabel);
    free(c.par);
    free(c.scratch_keep);
    free(c.groot);
    free(c.gcost);
    if (!s && stats)
        *stats = local;
    return s;
}
