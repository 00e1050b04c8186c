/*
 * mincut.c - a minimum cut on a voxel grid (see mincut.h): the incremental
 * breadth-first search max-flow (IBFS) of Goldberg, Hed, Kaplan, Tarjan
 * and Werneck ("Maximum flows by incremental breadth-first search", ESA
 * 2011), written here for the implicit 6-neighbour graph of a grid,
 * integer capacities.
 *
 * Two search trees grow from the terminals (S, the inside: voxels with
 * inside evidence; T, the outside: voxels with outside evidence and the
 * grid's border) along arcs with residual capacity, as in Boykov and
 * Kolmogorov's method, but a level at a time, alternately: every node
 * carries its level in its tree (roots 1) and a tree arc always goes one
 * level down. Where the trees touch, the path is augmented; the arcs it
 * saturates cut nodes off their tree (orphans), and an orphan takes a
 * neighbour one level above it as its parent, found in one look at its six
 * arcs (no walk to the root), or else moves down below its highest
 * reaching neighbour, its children orphans in turn, or leaves the tree if
 * that is beyond the level being grown. When S cannot grow, S is the
 * inside.
 *
 * Only the undecided voxels are nodes (|evidence| below p->fixed, off the
 * border); a decided neighbour is a terminal, its arc's capacity added to
 * the node's terminal capacity. The nodes are kept in storage order with
 * their six neighbours' node numbers (NO_NODE for a decided one), so the
 * graph costs about 74 bytes per undecided voxel and nothing per decided
 * one. Arcs are (node, direction): directions 0..5 are +x, -x, +y, -y, +z,
 * -z, so a ^ 1 is the opposite direction and the arc (v, a)'s sister is
 * (nbr(v, a), a ^ 1).
 *
 * The labels are the source's side of the residual graph at the end,
 * which every maximum flow shares (the least inside of the cheapest
 * labellings): the flow's paths and their order are free to change
 * (plant_roots pushes the one-arc paths before the trees grow).
 *
 * Measurements of the solver's work (and of Boykov and Kolmogorov's
 * trees, which it replaced): doc/design/mincut.md.
 */
#include "souptet/mincut.h"
#include "../base/fpenv.h"
#include "souptet/mem.h"

#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#define TREE_S 0x01u
#define TREE_T 0x02u
#define TREES (TREE_S | TREE_T)
#define F_QS 0x10u              /* in S's ring */
#define F_QT 0x20u              /* in T's ring */

#define P_TERMINAL 6u
#define P_ORPHAN 7u
#define P_NONE 8u

#define NO_NODE UINT32_MAX

/* A tree's nodes to scan: a FIFO ring of n + 1 (each node in it at most
 * once, by its flag); those at level D are the ones not yet scanned, and
 * every node of the tree below D has been. */
typedef struct level_ring {
    uint32_t *q;
    size_t h, t;
    uint32_t D;
    uint8_t flag;
} level_ring;

typedef struct ibfs {
    size_t n;             /* nodes */
    uint32_t *nbr;        /* nbr[6 v + a]: the neighbouring node, or NO_NODE */
    int32_t *rc;          /* residual capacity of arc (v, a): rc[6 v + a] */
    int32_t *tr;          /* terminal residual: > 0 from S, < 0 to T */
    uint8_t *tree;        /* TREE_S / TREE_T / free, F_QS, F_QT */
    uint8_t *parent;      /* direction to the parent, or P_* */
    uint32_t *up;         /* the parent node (when parent[v] is a direction) */
    uint32_t *lev;        /* the node's level in its tree (roots 1) */
    level_ring S, T;
    uint32_t *orphan;     /* FIFO ring of n + 1 */
    size_t oh, ot;
    int64_t flow;
} ibfs;

st_mincut_params st_mincut_params_default(void)
{
    /* Chosen on the damaged corpus (make bench STAGE=accuracy; the table is in
     * issue 4's closing note): evidence 100 per vote of margin against 1000
     * per face of free space (50 and 200 are each worse on some classes);
     * faces cheap below a voxel from the surface, by its cube; voxels with
     * a margin of 10 votes of 13 or more decided (12 gives the same IoU on
     * every corpus entry to four digits, with 8 times the nodes on a
     * closed model). */
    st_mincut_params p = {1000.0, 1.0, 3.0, 100.0, 10};
    return p;
}

static void set_orphan(ibfs *b, uint32_t v)
{
    b->parent[v] = P_ORPHAN;
    b->orphan[b->ot] = v;
    b->ot = b->ot == b->n ? 0 : b->ot + 1;
}

/* v to the tail of ring L unless it is in it already. */
static void ring_push(ibfs *b, level_ring *L, uint32_t v)
{
    if (b->tree[v] & L->flag)
        return;
    b->tree[v] |= L->flag;
    L->q[L->t] = v;
    L->t = L->t == b->n ? 0 : L->t + 1;
}

static uint32_t ring_pop(ibfs *b, level_ring *L)
{
    uint32_t v = L->q[L->h];
    L->h = L->h == b->n ? 0 : L->h + 1;
    b->tree[v] &= (uint8_t)~L->flag;
    return v;
}

static inline uint32_t nb(const ibfs *b, uint32_t v, unsigned a)
{
    return b->nbr[6 * (size_t)v + a];
}

/* Push the bottleneck along S root .. s -> t .. T root (arc (s, a)). */
static void augment(ibfs *b, uint32_t s, uint32_t t, unsigned a)
{
    int32_t m = b->rc[6 * (size_t)s + a];
    uint32_t x;
    for (x = s; b->parent[x] != P_TERMINAL;) {
        unsigned pa = b->parent[x];
        uint32_t y = b->up[x];
        int32_t c = b->rc[6 * (size_t)y + (pa ^ 1u)];
        if (c < m)
            m = c;
        x = y;
    }
    if (b->tr[x] < m)
        m = b->tr[x];
    for (x = t; b->parent[x] != P_TERMINAL;) {
        unsigned pa = b->parent[x];
        int32_t c = b->rc[6 * (size_t)x + pa];
        if (c < m)
            m = c;
        x = b->up[x];
    }
    if (-b->tr[x] < m)
        m = -b->tr[x];

    b->rc[6 * (size_t)s + a] -= m;
    b->rc[6 * (size_t)t + (a ^ 1u)] += m;
    for (x = s; b->parent[x] != P_TERMINAL;) {
        unsigned pa = b->parent[x];
        uint32_t y = b->up[x];
        b->rc[6 * (size_t)x + pa] += m;
        if ((b->rc[6 * (size_t)y + (pa ^ 1u)] -= m) == 0)
            set_orphan(b, x);
        x = y;
    }
    if ((b->tr[x] -= m) == 0)
        set_orphan(b, x);
    for (x = t; b->parent[x] != P_TERMINAL;) {
        unsigned pa = b->parent[x];
        uint32_t y = b->up[x];
        b->rc[6 * (size_t)y + (pa ^ 1u)] += m;
        if ((b->rc[6 * (size_t)x + pa] -= m) == 0)
            set_orphan(b, x);
        x = y;
    }
    if ((b->tr[x] += m) == 0)
        set_orphan(b, x);
    b->flow += m;
}

/* Residual capacity that lets v (in tree X) hang below its neighbour
 * j = v + off[a]: j -> v for S, v -> j for T. */
static inline int32_t tree_cap(const ibfs *b, unsigned X, uint32_t v, uint32_t j, unsigned a)
{
    return X == TREE_S ? b->rc[6 * (size_t)j + (a ^ 1u)] : b->rc[6 * (size_t)v + a];
}

/* A new parent for the orphan v: a neighbour of its tree one level above
 * it that reaches it (for T: that it reaches), kept at its level; else the
 * least-level such neighbour, v one level below it and its children
 * orphans (their levels no longer fit), and v pending if that is the
 * tree's pending level; beyond it, or with no such neighbour, v leaves the
 * tree. The levels fall strictly towards the roots, so no parent is ever
 * a descendant; every tree node that reaches v from below the pending
 * level was scanned, so had v a neighbour there it would have been
 * found, and v leaving is seen by the pending nodes that reach it. */
static void adopt(ibfs *b, uint32_t v)
{
    const unsigned X = b->tree[v] & TREES;
    level_ring *L = X == TREE_S ? &b->S : &b->T;
    const uint32_t lv = b->lev[v];
    uint32_t lmin = UINT32_MAX;
    unsigned amin = P_NONE;
    for (unsigned a = 0; a < 6; a++) {
        uint32_t j = nb(b, v, a);
        if (j == NO_NODE || (b->tree[j] & TREES) != X || tree_cap(b, X, v, j, a) <= 0)
            continue;
        if (b->lev[j] + 1 == lv) {
            b->parent[v] = (uint8_t)a;
            b->up[v] = j;
            return;
        }
        if (b->lev[j] < lmin) {
            lmin = b->lev[j];
            amin = a;
        }
    }
    for (unsigned a = 0; a < 6; a++) {
        uint32_t j = nb(b, v, a);
        if (j != NO_NODE && (b->tree[j] & TREES) == X && b->parent[j] == (a ^ 1u))
            set_orphan(b, j);
    }
    if (amin == P_NONE || lmin >= L->D) {
        b->tree[v] &= (uint8_t)~TREES;
        b->parent[v] = P_NONE;
        return;
    }
    b->parent[v] = (uint8_t)amin;
    b->up[v] = nb(b, v, amin);
    b->lev[v] = lmin + 1;
    if (lmin + 1 == L->D)
        ring_push(b, L, v);
}

/* Scan node v of tree X at level `level` (the one being grown): its free
 * neighbours join X a level below, and each arc to the other tree is
 * augmented until it is saturated or v has left the level. */
static void scan(ibfs *b, unsigned X, uint32_t v, uint32_t level, level_ring *L)
{
    for (unsigned a = 0; a < 6; a++) {
        const uint32_t q = nb(b, v, a);
        if (q == NO_NODE)
            continue;
        for (;;) {
            int32_t c = X == TREE_S ? b->rc[6 * (size_t)v + a] : b->rc[6 * (size_t)q + (a ^ 1u)];
            const unsigned Y = b->tree[q] & TREES;
            if (c <= 0 || Y == X)
                break;
            if (!Y) {
                b->tree[q] |= (uint8_t)X;
                b->parent[q] = (uint8_t)(a ^ 1u);
                b->up[q] = v;
                b->lev[q] = level + 1;
                ring_push(b, L, q);
                break;
            }
            if (X == TREE_S)
                augment(b, v, q, a);
            else
                augment(b, q, v, a ^ 1u);
            while (b->oh != b->ot) {
                uint32_t o = b->orphan[b->oh];
                b->oh = b->oh == b->n ? 0 : b->oh + 1;
                adopt(b, o);
            }
            if ((b->tree[v] & TREES) != X || b->lev[v] != level)
                return;
        }
    }
}

/* Grow tree X by its pending level: the nodes in its ring now (those
 * still at that level; one moved down to the next is kept for it). */
static void grow(ibfs *b, unsigned X)
{
    level_ring *L = X == TREE_S ? &b->S : &b->T;
    const uint32_t level = L->D;
    size_t k = L->t >= L->h ? L->t - L->h : L->t + b->n + 1 - L->h;
    L->D = level + 1;
    while (k--) {
        const uint32_t v = ring_pop(b, L);
        if ((b->tree[v] & TREES) != X)
            continue;
        if (b->lev[v] == level)
            scan(b, X, v, level, L);
        else if (b->lev[v] == L->D)
            ring_push(b, L, v);
    }
}

/* S and T grow a level each in turn (S first: until then the roots that
 * are not in the rings count as scanned) until S has no pending level. */
static void maxflow(ibfs *b)
{
    while (b->S.h != b->S.t) {
        grow(b, TREE_S);
        if (b->T.h != b->T.t)
            grow(b, TREE_T);
    }
}

static void ibfs_free(ibfs *b)
{
    free(b->nbr);
    free(b->rc);
    free(b->tr);
    free(b->tree);
    free(b->parent);
    free(b->up);
    free(b->lev);
    free(b->S.q);
    free(b->T.q);
    free(b->orphan);
}

/* The paths of one arc first (source -> u -> q -> sink for neighbours u
 * with terminal capacity from the source and q with capacity to the
 * sink, pushed in node order without the trees), then the trees' roots
 * (the nodes with terminal capacity left, level 1) and the pending ones
 * among them: a root is pending only if some neighbour is free or in the
 * other tree. A root among its own tree's roots alone has nothing to grow
 * into, and none of those neighbours can leave the tree while the root
 * reaches it (adopt() keeps it a level below). Neither changes the cut:
 * the S tree at the end is every node the source reaches in the residual
 * graph, the same set for every maximum flow whatever its paths and their
 * order (on b9_mesh at 7 cells, 274 K nodes, with Boykov and
 * Kolmogorov's trees: 534 -> 496 M Ir in the cut, the one-arc paths
 * sparing most of the trees' first augmentations, the roots left out
 * about 270 K scans of six same-tree neighbours). */
static void plant_roots(ibfs *b)
{
    const size_t m = b->n;
    for (size_t u = 0; u < m; u++)
        for (unsigned a = 0; a < 6 && b->tr[u] > 0; a++) {
            const uint32_t q = nb(b, (uint32_t)u, a);
            if (q == NO_NODE || b->tr[q] >= 0)
                continue;
            int32_t x = b->rc[6 * u + a];
            x = x < b->tr[u] ? x : b->tr[u];
            x = x < -b->tr[q] ? x : -b->tr[q];
            b->rc[6 * u + a] -= x;
            b->rc[6 * (size_t)q + (a ^ 1u)] += x;
            b->tr[u] -= x;
            b->tr[q] += x;
            b->flow += x;
        }
    for (size_t u = 0; u < m; u++) {
        b->tree[u] = b->tr[u] > 0 ? TREE_S : b->tr[u] < 0 ? TREE_T : 0;
        b->parent[u] = b->tr[u] ? P_TERMINAL : P_NONE;
    }
    for (size_t u = 0; u < m; u++) {
        const unsigned X = b->tree[u];
        if (!X)
            continue;
        unsigned other = 0;
        for (unsigned a = 0; a < 6; a++) {
            const uint32_t q = nb(b, (uint32_t)u, a);
            other |= q != NO_NODE && (b->tree[q] & TREES) != X;
        }
        if (other)
            ring_push(b, X == TREE_S ? &b->S : &b->T, (uint32_t)u);
    }
}

/* The first of the sorted voxels vox[lo, hi) not below w (hi if none). */
static size_t lower_node(const uint32_t *vox, size_t lo, size_t hi, uint32_t w)
{
    while (lo < hi) {
        size_t mid = lo + (hi - lo) / 2;
        if (vox[mid] < w)
            lo = mid + 1;
        else
            hi = mid;
    }
    return lo;
}

/* The capacity of a face whose nearer voxel is at unsigned distance a:
 * the face between voxels at a and b has vox_cap(a < b ? a : b), so each
 * node's own is taken once (node_caps) for its six faces and its
 * neighbours'. */
static int32_t vox_cap(const st_mincut_params *p, double s, float a)
{
    double x = a / s;
    return 1 + (int32_t)(p->free_area * (x >= 1.0 ? 1.0 : pow(x, p->power)) + 0.5);
}

/* vox_cap of nodes [u0, u1) into cap. */
static void node_caps(int32_t *cap, const st_grid *g, const uint32_t *vox, size_t u0, size_t u1,
                      const st_mincut_params *p, double s)
{
    for (size_t u = u0; u < u1; u++)
        cap[u] = vox_cap(p, s, fabsf(g->data[vox[u]]));
}

/* The arcs and terminal capacities of nodes [u0, u1) (vox ascending). A
 * neighbour w = v + off[a] is a node when its evidence is undecided (the
 * label says so, no search); the arc between two nodes is written by the
 * lower one, both ways (the same face, the same capacity), so each face
 * is done once and each arc slot written by one thread: the higher node's
 * slot in direction a ^ 1 is left to it. The lower node finds the higher
 * one's number as v + 1's is u + 1 (storage order), and v + nx's and v +
 * nx ny's by cursors that only move forward (one binary search to start
 * each), since w rises with the node. */
static void node_arcs(ibfs *b, const st_grid *g, const int8_t *label, const uint32_t *vox,
                      const int32_t *vcap, size_t u0, size_t u1, const ptrdiff_t off[6],
                      const st_mincut_params *p, double s, int fixed, const int64_t *ecap)
{
    const size_t m = b->n;
    if (u0 >= u1)
        return;
    size_t cur[6] = {0};
    for (unsigned a = 2; a < 6; a += 2)
        cur[a] = lower_node(vox, u0, m, (uint32_t)((ptrdiff_t)vox[u0] + off[a]));
    for (size_t u = u0; u < u1; u++) {
        const uint32_t v = vox[u];
        const float dv = fabsf(g->data[v]);
        int64_t t = ecap[label[v] + 128];
        for (unsigned a = 0; a < 6; a++) {
            const uint32_t w = (uint32_t)((ptrdiff_t)v + off[a]);
            const int lw = label[w];
            const float dw = fabsf(g->data[w]);
            if (lw > -fixed && lw < fixed) {    /* a node */
                if (a & 1u)
                    continue;                   /* the lower node's to write */
                size_t q = u + 1;
                if (a) {
                    for (q = cur[a]; vox[q] < w; q++)
                        ;
                    cur[a] = q;
                }
                const int32_t cap = dv < dw ? vcap[u] : vcap[q];
                b->nbr[6 * u + a] = (uint32_t)q;
                b->rc[6 * u + a] = cap;
                b->nbr[6 * q + (a ^ 1u)] = (uint32_t)u;
                b->rc[6 * q + (a ^ 1u)] = cap;
                continue;
            }
            /* a decided neighbour: a terminal */
            const int32_t cap = dv < dw ? vcap[u] : vox_cap(p, s, dw);
            b->nbr[6 * u + a] = NO_NODE;
            b->rc[6 * u + a] = 0;
            t += lw >= fixed ? cap : -cap;
        }
        if (t > INT32_MAX / 2 || t < -INT32_MAX / 2)
            t = t > 0 ? INT32_MAX / 2 : -INT32_MAX / 2;
        b->tr[u] = (int32_t)t;
        b->lev[u] = 1;
    }
}

/* The border of a z layer (all of it if `outer`) set outside, then the
 * count of its undecided voxels (|evidence| < fixed), the rows' insides
 * counted without a test per voxel for the border. */
static size_t mark_layer(int8_t *lab, size_t nx, size_t ny, int outer, int fixed)
{
    size_t cnt = 0;
    for (size_t j = 0; j < ny; j++) {
        int8_t *row = lab + j * nx;
        if (outer || j == 0 || j == ny - 1) {
            memset(row, -127, nx);
            continue;
        }
        row[0] = row[nx - 1] = -127;
        for (size_t i = 1; i + 1 < nx; i++)
            cnt += row[i] > -fixed && row[i] < fixed;
    }
    return cnt;
}

st_status st_mincut_label(const st_grid *g, int8_t *label,
                          const st_mincut_params *p, double *flow,
                          st_error *err)
{
    const size_t nx = g->nx, ny = g->ny, nz = g->nz, n = st_grid_count(g);
    if (n >= UINT32_MAX)
        return st_error_set(err, ST_ELIMIT, NULL, 0,
                            "the grid has too many voxels for the cut (%zu)", n);
    const int fixed = p->fixed_evidence < 1 ? 1 : p->fixed_evidence > 127 ? 127 : p->fixed_evidence;
    /* Decided: |evidence| >= fixed; the border is decided outside. */
    /* The undecided voxels, a z layer at a time in parallel (each layer's
     * count, then their prefix sums: the same node order for any number
     * of threads). */
    const size_t layer = nx * ny;
    size_t *first = st_malloc_array(nz + 1, sizeof *first);
    if (!first)
        return st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory for the cut");
    #pragma omp parallel for schedule(static)
    for (size_t k = 0; k < nz; k++)
        first[k + 1] = mark_layer(label + k * layer, nx, ny, k == 0 || k == nz - 1, fixed);
    first[0] = 0;
    for (size_t k = 0; k < nz; k++)
        first[k + 1] += first[k];
    const size_t m = first[nz];
    ibfs b = {0};
    b.n = m;
    b.S.flag = F_QS;
    b.T.flag = F_QT;
    b.S.D = b.T.D = 1;
    uint32_t *vox = st_malloc_array(m ? m : 1, sizeof *vox);
    b.nbr = st_malloc_array(6 * m + 1, sizeof *b.nbr);
    b.rc = st_malloc_array(6 * m + 1, sizeof *b.rc);
    b.tr = st_malloc_array(m + 1, sizeof *b.tr);
    b.tree = st_malloc_array(m + 1, 1);
    b.parent = st_malloc_array(m + 1, 1);
    b.up = st_malloc_array(m + 1, sizeof *b.up);
    b.lev = st_malloc_array(m + 1, sizeof *b.lev);
    b.S.q = st_malloc_array(m + 1, sizeof *b.S.q);
    b.T.q = st_malloc_array(m + 1, sizeof *b.T.q);
    b.orphan = st_malloc_array(m + 1, sizeof *b.orphan);
    int32_t *vcap = st_malloc_array(m ? m : 1, sizeof *vcap);   /* each node's face capacity */
    if (!vox || !b.nbr || !b.rc || !b.tr || !b.tree || !b.parent || !b.up || !b.lev || !b.S.q ||
        !b.T.q || !b.orphan || !vcap) {
        free(first);
        free(vox);
        free(vcap);
        ibfs_free(&b);
        return st_error_set(err, ST_ENOMEM, NULL, 0,
                            "out of memory for the cut (%zu undecided voxels)", m);
    }
    #pragma omp parallel for schedule(static)
    for (size_t k = 0; k < nz; k++) {
        size_t c = first[k];
        for (size_t v = k * layer; v < (k + 1) * layer; v++)
            if (abs(label[v]) < fixed)
                vox[c++] = (uint32_t)v;
    }
    const ptrdiff_t off[6] = {1, -1, (ptrdiff_t)nx, -(ptrdiff_t)nx, (ptrdiff_t)layer,
                              -(ptrdiff_t)layer};
    const double s = p->surface_voxels * g->voxel;
    int64_t ecap[256];      /* an evidence's terminal capacity, by evidence + 128 */
    for (int e = -128; e < 128; e++)
        ecap[e + 128] = (int64_t)llround(e * p->evidence_weight);
    /* Each node's face capacity, then its arcs and terminal capacity (a
     * decided neighbour's arc goes to its terminal), a z layer at a time
     * in parallel; then the trees' roots in order. */
    #pragma omp parallel for schedule(static)
    for (size_t k = 0; k < nz; k++)
        node_caps(vcap, g, vox, first[k], first[k + 1], p, s);
    #pragma omp parallel for schedule(dynamic, 1)
    for (size_t k = 0; k < nz; k++)
        node_arcs(&b, g, label, vox, vcap, first[k], first[k + 1], off, p, s, fixed, ecap);
    free(vcap);
    free(first);
    plant_roots(&b);
    maxflow(&b);
    /* Decided voxels keep the side of their evidence (the border: out). */
    #pragma omp parallel for schedule(static)
    for (size_t v = 0; v < n; v++)
        label[v] = label[v] >= fixed;
    #pragma omp parallel for schedule(static)
    for (size_t u = 0; u < m; u++)
        label[vox[u]] = (b.tree[u] & TREE_S) ? 1 : 0;
    if (flow)
        *flow = (double)b.flow;
    free(vox);
    ibfs_free(&b);
    return ST_OK;
}
