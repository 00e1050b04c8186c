/*
 * sculpt.c - sculpting a lattice down to the tets that overlap the pseudo
 * volume or the input triangles, and bomb repair with snowflakes.
 *
 * Reference: D. A. Stuart, J. A. Levine, B. Jones, A. W. Bargteil,
 * "Automatic Construction of Coarse, High-Quality Tetrahedralizations that
 * Enclose and Approximate Surfaces for Animation", MIG 2013, section 3.2.
 * See sculpt.h for the contracts.
 *
 * Bomb repair, the reasoning.
 *
 * (1) A snowflake is the star of a lattice vertex v: every lattice tet
 * incident to v (24 in the BCC lattice). When v is interior to the lattice
 * (its star is closed; the padding guarantees it for every vertex of a tet
 * that meets the box), every face through v is shared by two tets of the
 * star, so once the whole star is kept, each tet of it has at most one
 * boundary face: the one opposite v. A complete snowflake holds no bomb.
 *
 * (2) The candidates of a bomb are therefore its four vertices: completing
 * the snowflake of a vertex v of bomb b makes every face of b through v
 * interior and leaves at most the face opposite v on the boundary. With
 * boundary faces {p q r} and {p q s}, a snowflake at p or q clears both,
 * one at r or s clears one of them - either way b is no longer a bomb. And
 * there is nothing to gain outside them: "the vertices of its boundary
 * faces" are all four vertices (two faces of a tet cover its four
 * vertices), and a snowflake around a vertex not in b does not contain b,
 * so it can only clear b's faces by luck of its neighbours, which the
 * one-per-bomb search does not rely on. This is the paper's "four choices
 * per bomb" (its 4^n). A vertex on the lattice's outer layer has an
 * incomplete star and is no candidate (with the padding it never occurs).
 *
 * (3) Adding tets never creates a bomb: a kept tet's boundary faces can only
 * become interior when neighbours are added, and every added tet belongs to
 * a now complete snowflake, so it has at most one boundary face by (1). So
 * one round of repair removes every bomb whose candidates include one
 * complete star; the loop that recounts and repeats is a safeguard, and
 * stats->repair_rounds says how many rounds ran.
 *
 * (4) The cost of a choice (one candidate vertex per bomb, the paper's
 * search space of 4^n) is the number of tets its snowflakes add, |union of
 * (star(v_b) minus kept)|. Two bombs interact when some candidate snowflake
 * of one and some of the other would add a common tet; otherwise their costs
 * add up and they can be chosen apart. So bombs are grouped into clusters
 * (union-find over the tets their candidates would add), and each cluster is
 * solved by a depth-first branch and bound over its 4^n choices: the greedy
 * choice first gives the bound; a bomb with a candidate that adds nothing
 * given the choices above it takes that one (it cannot be worse); others try
 * their candidates cheapest first and prune at the best cost so far. A
 * cluster larger than cluster_max bombs, or whose search exceeds
 * search_budget nodes, keeps the best choice found (never worse than
 * greedy) and is counted in clusters_greedy.
 *
 * (5) The memo makes the search of (4) cheaper without changing what it
 * does, node for node, budget included. Below depth i the search depends
 * on the choices above i only through (a) which tets of the options of
 * bombs i.. are covered, and only for the "frontier" tets that options of
 * bombs above i can cover (the others are uncovered), and (b) the slack
 * best_cost - cost: every test below (gain 0, the order by gain, cost +
 * gain >= best_cost) reads the covered bits and costs relative to the
 * entry. So while best_cost stays, the subtree entered with the same
 * (depth, covered frontier, slack) visits the same number of nodes and
 * finds the same leaves. A subtree that ran to its end (not cut by the
 * budget) without a cheaper leaf is stored with its node count; a later
 * entry with the same key adds that count to the nodes instead of
 * searching (no cheaper leaf can come of it), or, when the count would
 * exceed the budget, ends the search as the budget would have inside it.
 * The choice, clusters_exact and the node count (search_nodes) are those
 * of the search without memo; search_expanded counts the nodes searched.
 * This holds for any subset of the entries: a key not found is searched,
 * which is what the search without memo does. So the memo may forget:
 * it is made once a cluster's search has run MEMO_START nodes, small (4
 * KB) and grown by doubling up to MEMO_MAX_SLOTS slots and MEMO_MAX_POOL
 * key words, emptied when full; it stores subtrees of MEMO_MIN_NODES
 * nodes or more, probes only at depths with an entry, and is dropped for
 * the rest of the search when over a window of MEMO_WINDOW nodes its
 * hits replayed fewer nodes than it made probes and stores (the plain
 * search costs some 30 ns a node: a memo that rarely hits costs more in
 * cache misses than it saves).
 *
 * (6) The covered tets are a bitset (cov), each option a list of (word,
 * bits) pairs: a gain is a few popcounts instead of a count per tet.
 */
#include "souptet/sculpt.h"
#include "../base/unionfind.h"
#include "../base/fpenv.h"
#include "souptet/isect.h"
#include "souptet/mem.h"
#include "souptet/progress.h"

#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
st_sculpt_params st_sculpt_params_default(void)
{
    st_sculpt_params p;
    p.kind = ST_LATTICE_BCC;
    p.h = 1.0;
    p.seed = 0;
    p.pad = ST_LATTICE_PAD_DEFAULT;
    p.max_tets = 0;
    p.repair_bombs = 1;
    p.repair_manifold = 1;
    p.cluster_max = 64;
    p.search_budget = (size_t)1 << 20;
    p.search_memo = 1;
    p.cancel = NULL;
    return p;
}

/* ---- classification ---- */

typedef struct tri_ctx {
    const st_soup *s;
    const double *p[4];
} tri_ctx;

static int visit_tri(void *ctx, uint32_t tri)
{
    const tri_ctx *c = ctx;
    const uint32_t *v = c->s->tris + 3 * (size_t)tri;
    const double *a = c->s->xyz + 3 * (size_t)v[0];
    const double *b = c->s->xyz + 3 * (size_t)v[1];
    const double *d = c->s->xyz + 3 * (size_t)v[2];
    return st_tri_tet_intersect(a, b, d, c->p[0], c->p[1], c->p[2], c->p[3]);
}

static st_status classify(unsigned char *keep, st_sculpt_stats *stats,
                          const st_lattice *L, const st_grid *g,
                          const st_soup *s, const st_bvh *bvh,
                          volatile int *cancel, st_error *err);

/* 1 when the box of the tet p[0..3] meets the closed box [lo, hi]
 * (comparisons only: exact). */
static int tet_meets_box(const double *const p[4], const double lo[3], const double hi[3])
{
    for (int a = 0; a < 3; a++) {
        double l = p[0][a], h = p[0][a];
        for (int c = 1; c < 4; c++) {
            l = p[c][a] < l ? p[c][a] : l;
            h = p[c][a] > h ? p[c][a] : h;
        }
        if (h < lo[a] || l > hi[a])
            return 0;
    }
    return 1;
}

st_status st_sculpt_classify(unsigned char *keep, st_sculpt_stats *stats,
                             const st_lattice *L, const st_grid *g,
                             const st_soup *s, const st_bvh *bvh,
                             st_error *err)
{
    return classify(keep, stats, L, g, s, bvh, NULL, err);
}

/* st_sculpt_classify; a set cancel flag leaves the tets not yet classified
 * (keep 0) and returns ST_ECANCELLED. */
static st_status classify(unsigned char *keep, st_sculpt_stats *stats,
                          const st_lattice *L, const st_grid *g,
                          const st_soup *s, const st_bvh *bvh,
                          volatile int *cancel, st_error *err)
{
    const st_progress stop = {NULL, NULL, cancel};
    if (g->kind != ST_GRID_SIGNED)
        return st_error_set(err, ST_EINPUT, NULL, 0,
                            "the field is not signed (run soupsign first)");
    st_bvh *own = NULL;
    if (s && s->ntris && !bvh) {
        st_status st = st_bvh_build(&own, s, err);
        if (st)
            return st;
        bvh = own;
    }
    st_voxel_summary *sum = NULL;
    st_status st = st_voxel_summary_build(&sum, g, err);
    if (st) {
        st_bvh_free(own);
        return st;
    }
    /* The soup's box (the BVH root's, exact): a tet whose box misses it
     * meets no triangle, and needs no tet query (whose face planes cost
     * more than the walk it then does). */
    double root_lo[3] = {INFINITY, INFINITY, INFINITY};
    double root_hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    if (bvh && bvh->nnodes)
        for (int a = 0; a < 3; a++) {
            root_lo[a] = bvh->nodes[0].lo[a];
            root_hi[a] = bvh->nodes[0].hi[a];
        }
    size_t nvol = 0, nsurf = 0;
    long long nt = (long long)L->ntets;
#pragma omp parallel for schedule(dynamic, 256) reduction(+ : nvol, nsurf)
    for (long long t = 0; t < nt; t++) {
        if ((t & 255) == 0 && st_progress_cancelled(&stop)) {
            keep[t] = ST_SCULPT_REMOVED;
            continue;
        }
        const uint32_t *v = L->tets + 4 * (size_t)t;
        const double *p[4];
        for (int c = 0; c < 4; c++)
            p[c] = L->xyz + 3 * (size_t)v[c];
        size_t m, M;
        int r = st_tet_voxel_count(g, sum, p[0], p[1], p[2], p[3], 1, &m, &M,
                                   NULL);
        int vol = r > 0 || (r == 0 && m > 0);
        if (!vol && r == 0)
            for (int c = 0; c < 4 && !vol; c++) {
                size_t ijk[3];
                if (st_grid_voxel_of(g, p[c], ijk))
                    vol = g->data[st_grid_index(g, ijk[0], ijk[1], ijk[2])] < 0.0f;
            }
        unsigned char k = ST_SCULPT_REMOVED;
        if (vol) {
            k = ST_SCULPT_VOLUME;
            nvol++;
        } else if (bvh && tet_meets_box(p, root_lo, root_hi)) {
            tri_ctx ctx;
            ctx.s = s;
            for (int c = 0; c < 4; c++)
                ctx.p[c] = p[c];
            if (st_bvh_query_tet(bvh, p, visit_tri, &ctx)) {
                k = ST_SCULPT_SURFACE;
                nsurf++;
            }
        }
        keep[t] = k;
    }
    st_voxel_summary_free(sum);
    st_bvh_free(own);
    if (st_progress_cancelled(&stop))
        return st_error_set(err, ST_ECANCELLED, NULL, 0, "cancelled");
    if (stats) {
        stats->lattice_tets = L->ntets;
        stats->kept_volume = nvol;
        stats->kept_surface = nsurf;
    }
    return ST_OK;
}

/* ---- boundary counts and stars ---- */

static int boundary_faces(const st_lattice *L, const unsigned char *keep,
                          size_t t)
{
    int n = 0;
    for (int i = 0; i < 4; i++) {
        int64_t o = L->nbr[4 * t + (size_t)i];
        n += o < 0 || !keep[o];
    }
    return n;
}

size_t st_sculpt_count_bombs(const st_lattice *L, const unsigned char *keep,
                             size_t hist[5])
{
    size_t h[5] = {0, 0, 0, 0, 0};
    for (size_t t = 0; t < L->ntets; t++)
        if (keep[t])
            h[boundary_faces(L, keep, t)]++;
    if (hist)
        memcpy(hist, h, sizeof h);
    return h[2] + h[3] + h[4];
}

/* 1 when v's star is closed: every face through v has a tet on both
 * sides, so the snowflake of v is complete in the lattice. */
static int star_complete(const st_lattice *L, uint32_t v)
{
    for (size_t a = L->star_off[v]; a < L->star_off[v + 1]; a++) {
        size_t t = L->star[a];
        for (int i = 0; i < 4; i++)
            if (L->tets[4 * t + (size_t)i] != v && L->nbr[4 * t + (size_t)i] < 0)
                return 0;
    }
    return L->star_off[v + 1] > L->star_off[v];
}

/* Add v's snowflake; returns the number of tets added. */
static size_t add_star(const st_lattice *L, unsigned char *keep, uint32_t v,
                       unsigned char why)
{
    size_t added = 0;
    for (size_t a = L->star_off[v]; a < L->star_off[v + 1]; a++)
        if (!keep[L->star[a]]) {
            keep[L->star[a]] = why;
            added++;
        }
    return added;
}

/* ---- bomb repair ---- */

/* One cluster's search state. Option o of bomb i adds the local tets
 * opt_tets[opt_off[4i+o] .. opt_off[4i+o+1]); the search reads them as
 * pairs (word, bits) over cov, a bit per local tet set while a chosen
 * option covers it: pair_w[a], pair_m[a] for a in pair_off[4i+o] ..
 * pair_off[4i+o+1], one pair per word, and pair_new[a] the bits the
 * option newly covered when it was applied (its undo). */
typedef struct search {
    size_t n;                 /* bombs */
    int *nopt;                /* options per bomb */
    size_t *opt_off;          /* 4n + 1 */
    uint32_t *opt_tets;
    size_t nloc;              /* local tets */
    size_t *pair_off;         /* 4n + 1 */
    uint32_t *pair_w;
    uint64_t *pair_m, *pair_new;
    uint64_t *cov;            /* nloc / 64 + 1 words */
    int *sel, *best_sel;
    size_t cost, best_cost;   /* cost: the covered bits */
    size_t nodes, budget;     /* nodes counted (memo hits count theirs) */
    size_t expanded;          /* nodes actually expanded */
    int exhausted;
    int memo_on;              /* 1: make a memo once MEMO_START nodes ran */
    struct memo *M;           /* NULL: no memo (yet) */
} search;

static size_t popcount64(uint64_t x)
{
    x = x - ((x >> 1) & 0x5555555555555555u);
    x = (x & 0x3333333333333333u) + ((x >> 2) & 0x3333333333333333u);
    x = (x + (x >> 4)) & 0x0f0f0f0f0f0f0f0fu;
    return (size_t)((x * 0x0101010101010101u) >> 56);
}

/* The tets option o of bomb i would add to the choice: its uncovered. */
static size_t opt_gain(const search *S, size_t i, int o)
{
    size_t g = 0, k = 4 * i + (size_t)o;
    for (size_t a = S->pair_off[k]; a < S->pair_off[k + 1]; a++)
        g += popcount64(S->pair_m[a] & ~S->cov[S->pair_w[a]]);
    return g;
}

/* Choose option o of bomb i: cover its tets (cost grows by its gain). */
static void opt_apply(search *S, size_t i, int o)
{
    size_t k = 4 * i + (size_t)o;
    for (size_t a = S->pair_off[k]; a < S->pair_off[k + 1]; a++) {
        uint64_t *c = S->cov + S->pair_w[a], nw = S->pair_m[a] & ~*c;
        S->pair_new[a] = nw;
        *c |= nw;
        S->cost += popcount64(nw);
    }
}

/* Undo opt_apply(S, i, o): the undos come in the reverse order of the
 * applies, or all of them at once. */
static void opt_undo(search *S, size_t i, int o)
{
    size_t k = 4 * i + (size_t)o;
    for (size_t a = S->pair_off[k]; a < S->pair_off[k + 1]; a++) {
        S->cov[S->pair_w[a]] &= ~S->pair_new[a];
        S->cost -= popcount64(S->pair_new[a]);
    }
}

/* ---- the memo of section (5) ---- */

#define MEMO_START ((size_t)1 << 15)   /* nodes before a memo is made */
#define MEMO_MIN_NODES 4               /* smaller subtrees: not stored */
#define MEMO_MAX_KEY 16                /* wider frontiers (words): no memo */
#define MEMO_SLOTS0 ((size_t)1 << 9)   /* slots at first (4 KB) */
#define MEMO_MAX_SLOTS ((size_t)1 << 17)
#define MEMO_POOL0 ((size_t)1 << 9)    /* pool words at first (4 KB) */
#define MEMO_MAX_POOL ((size_t)1 << 18)
#define MEMO_WINDOW ((size_t)1 << 15)  /* expanded nodes between checks */

/* The memo of section (5): subtrees searched to their end without a
 * cheaper leaf, keyed by (depth, slack, covered frontier tets), with the
 * nodes they counted. An entry is pool[e] = its nodes, then its key: one
 * word depth << 32 | slack, then the words of depth i's frontier, the
 * bits of mask[moff[i] .. moff[i + 1]) laid over cov from word wlo[i].
 * slot[s] is 0 (empty) or (the key's hash's high half | 1) << 32 | e: a
 * probe compares that first, the key in full on a match. count[i] is the
 * entries of depth i (no probe at a depth without). */
typedef struct memo {
    uint64_t *mask;
    size_t *moff, *wlo;
    uint32_t *count;
    uint64_t *slot;
    size_t cap, used;
    uint64_t *pool;
    size_t pool_len, pool_cap;
    uint64_t key[1 + MEMO_MAX_KEY];   /* the key at hand */
    size_t hits, stored, flushes;
    size_t probes, saved;     /* probes made, nodes the hits replayed */
    size_t win[4];            /* expanded, probes, stored, saved at the
                                 start of the window (section (5)) */
} memo;

/* The key of depth i with this slack into M->key: its words, or 0 when
 * depth i has no memo (its frontier is too wide). */
static size_t memo_key(const search *S, size_t i, size_t slack)
{
    memo *M = S->M;
    size_t w = M->moff[i + 1] - M->moff[i];
    if (w > MEMO_MAX_KEY || slack > UINT32_MAX)
        return 0;
    const uint64_t *mask = M->mask + M->moff[i], *cov = S->cov + M->wlo[i];
    M->key[0] = (uint64_t)i << 32 | (uint64_t)slack;
    for (size_t k = 0; k < w; k++)
        M->key[1 + k] = cov[k] & mask[k];
    return 1 + w;
}

static uint64_t memo_hash(const uint64_t *key, size_t w)
{
    uint64_t h = 0x9e3779b97f4a7c15u;
    for (size_t k = 0; k < w; k++) {
        h = (h ^ key[k]) * 0xff51afd7ed558ccdu;
        h ^= h >> 32;
    }
    return h;
}

static uint64_t memo_tag(uint64_t h)
{
    return (h >> 32 | 1) << 32;
}

/* The entry of M->key (w words, hash h): its pool offset + 1, or 0. */
static size_t memo_find(const memo *M, size_t w, uint64_t h)
{
    const size_t m = M->cap - 1;
    const uint64_t tag = memo_tag(h);
    for (size_t s = (size_t)h & m; M->slot[s]; s = (s + 1) & m) {
        if ((M->slot[s] & ~(uint64_t)UINT32_MAX) != tag)
            continue;
        const uint64_t *key = M->pool + (uint32_t)M->slot[s] + 1;
        size_t k = 0;
        while (k < w && key[k] == M->key[k])
            k++;
        if (k == w)
            return (size_t)(uint32_t)M->slot[s] + 1;
    }
    return 0;
}

static void memo_insert(memo *M, uint64_t h, size_t e)
{
    const size_t m = M->cap - 1;
    size_t s = (size_t)h & m;
    while (M->slot[s])
        s = (s + 1) & m;
    M->slot[s] = memo_tag(h) | (uint64_t)e;
}

/* Double the slots (rehashing from the pool's keys); 0 when it cannot. */
static int memo_grow(memo *M)
{
    size_t cap = 2 * M->cap;
    uint64_t *slot = cap <= MEMO_MAX_SLOTS ? st_calloc_array(cap, sizeof *slot) : NULL;
    if (!slot)
        return 0;
    uint64_t *old = M->slot;
    size_t ocap = M->cap;
    M->slot = slot;
    M->cap = cap;
    for (size_t s = 0; s < ocap; s++)
        if (old[s]) {
            size_t e = (uint32_t)old[s];
            size_t i = (size_t)(M->pool[e + 1] >> 32);
            memo_insert(M, memo_hash(M->pool + e + 1, 1 + M->moff[i + 1] - M->moff[i]), e);
        }
    free(old);
    return 1;
}

/* Room for an entry of w key words: grow the slots or the pool within
 * their caps, else empty the memo. */
static void memo_room(memo *M, size_t w, size_t n)
{
    if (2 * (M->used + 1) > M->cap && !memo_grow(M))
        goto flush;
    if (M->pool_len + 1 + w > M->pool_cap) {
        size_t c = 2 * M->pool_cap;
        uint64_t *pool = c <= MEMO_MAX_POOL ? st_realloc_array(M->pool, c, sizeof *pool) : NULL;
        if (!pool)
            goto flush;
        M->pool = pool;
        M->pool_cap = c;
    }
    return;
flush:
    memset(M->slot, 0, M->cap * sizeof *M->slot);
    memset(M->count, 0, (n + 1) * sizeof *M->count);
    M->used = M->pool_len = 0;
    M->flushes++;
}

/* Store the subtree of depth i, back at its entry state, with its node
 * count (its key is not in the memo: it was probed at the entry, or
 * depth i had no entry then, and the subtree stores deeper keys only). */
static void memo_store(search *S, size_t i, size_t slack, size_t nodes)
{
    memo *M = S->M;
    size_t w = memo_key(S, i, slack);
    if (!w)
        return;
    memo_room(M, w, S->n);
    size_t e = M->pool_len;
    M->pool[e] = nodes;
    memcpy(M->pool + e + 1, M->key, w * sizeof *M->key);
    memo_insert(M, memo_hash(M->key, w), e);
    M->pool_len += 1 + w;
    M->used++;
    M->count[i]++;
    M->stored++;
}

static void memo_free(memo *M)
{
    if (!M)
        return;
    free(M->mask);
    free(M->moff);
    free(M->wlo);
    free(M->count);
    free(M->slot);
    free(M->pool);
    free(M);
}

/* The frontiers: local tet u is in the frontier of every depth i with
 * first(u) < i <= last(u), first and last the bombs whose options hold u;
 * depth i's mask spans the words of its lowest to its highest such u.
 * NULL when memory is short. */
static memo *memo_new(const search *S)
{
    const size_t n = S->n, nloc = S->nloc;
    memo *M = st_calloc_array(1, sizeof *M);
    size_t *first = st_malloc_array(nloc + 1, sizeof *first);
    size_t *last = st_malloc_array(nloc + 1, sizeof *last);
    size_t *hi = st_calloc_array(n + 1, sizeof *hi);
    if (!M || !first || !last || !hi || !(M->moff = st_calloc_array(n + 2, sizeof *M->moff)) ||
        !(M->wlo = st_malloc_array(n + 1, sizeof *M->wlo)))
        goto fail;
    for (size_t u = 0; u < nloc; u++)
        first[u] = SIZE_MAX;
    for (size_t q = 0; q < n; q++)
        for (size_t a = S->opt_off[4 * q]; a < S->opt_off[4 * q + 4]; a++) {
            uint32_t u = S->opt_tets[a];
            if (first[u] == SIZE_MAX)
                first[u] = q;
            last[u] = q;
        }
    for (size_t i = 0; i <= n; i++)
        M->wlo[i] = SIZE_MAX;
    for (size_t u = 0; u < nloc; u++)   /* the words of depth i: wlo .. hi */
        for (size_t i = first[u] + 1; i <= last[u]; i++) {
            if (M->wlo[i] == SIZE_MAX)
                M->wlo[i] = u / 64;
            hi[i] = u / 64 + 1;
        }
    for (size_t i = 0; i <= n; i++) {
        if (M->wlo[i] == SIZE_MAX)
            M->wlo[i] = hi[i] = 0;
        M->moff[i + 1] = M->moff[i] + hi[i] - M->wlo[i];
    }
    M->cap = MEMO_SLOTS0;
    M->pool_cap = MEMO_POOL0;
    M->mask = st_calloc_array(M->moff[n + 1] + 1, sizeof *M->mask);
    M->count = st_calloc_array(n + 1, sizeof *M->count);
    M->slot = st_calloc_array(M->cap, sizeof *M->slot);
    M->pool = st_malloc_array(M->pool_cap, sizeof *M->pool);
    if (!M->mask || !M->count || !M->slot || !M->pool)
        goto fail;
    for (size_t u = 0; u < nloc; u++)
        for (size_t i = first[u] + 1; i <= last[u]; i++)
            M->mask[M->moff[i] + u / 64 - M->wlo[i]] |= (uint64_t)1 << (u % 64);
    free(first);
    free(last);
    free(hi);
    return M;
fail:
    free(first);
    free(last);
    free(hi);
    memo_free(M);
    return NULL;
}

static void dfs(search *S, size_t i);

/* Every MEMO_WINDOW nodes expanded: a memo whose hits in the window
 * replayed fewer nodes than it made probes and stores costs more than it
 * saves, and is dropped for the rest of the cluster's search. */
static void memo_check(search *S)
{
    memo *M = S->M;
    if (M->saved - M->win[3] < (M->probes - M->win[1]) + (M->stored - M->win[2])) {
        memo_free(M);
        S->M = NULL;
        S->memo_on = 0;
        return;
    }
    M->win[0] = S->expanded;
    M->win[1] = M->probes;
    M->win[2] = M->stored;
    M->win[3] = M->saved;
}

/* One node of section (4)'s search below the checks of dfs(). */
static void dfs_expand(search *S, size_t i)
{
    if (++S->nodes > S->budget) {
        S->exhausted = 1;
        return;
    }
    S->expanded++;
    size_t gain[4];
    int order[4], no = S->nopt[i];
    for (int o = 0; o < no; o++) {
        gain[o] = opt_gain(S, i, o);
        order[o] = o;
        if (gain[o] == 0) {   /* free: dominates every other option */
            S->sel[i] = o;
            dfs(S, i + 1);
            return;
        }
    }
    for (int a = 1; a < no; a++)   /* cheapest first, stable */
        for (int b = a; b > 0 && gain[order[b]] < gain[order[b - 1]]; b--) {
            int x = order[b];
            order[b] = order[b - 1];
            order[b - 1] = x;
        }
    for (int k = 0; k < no && !S->exhausted; k++) {
        int o = order[k];
        if (S->cost + gain[o] >= S->best_cost)
            break;   /* sorted: the rest cost no less */
        opt_apply(S, i, o);
        S->sel[i] = o;
        dfs(S, i + 1);
        opt_undo(S, i, o);
    }
}

static void dfs(search *S, size_t i)
{
    if (S->cost >= S->best_cost)
        return;
    if (i == S->n) {
        S->best_cost = S->cost;
        memcpy(S->best_sel, S->sel, S->n * sizeof *S->sel);
        return;
    }
    if (S->memo_on && !S->M && S->nodes >= MEMO_START) {
        S->M = memo_new(S);   /* a search this long: worth a memo */
        S->memo_on = S->M != NULL;
        if (S->M)
            S->M->win[0] = S->expanded;
    }
    if (S->M && S->expanded - S->M->win[0] >= MEMO_WINDOW)
        memo_check(S);
    memo *M = S->M;
    size_t slack = S->best_cost - S->cost, n0 = S->nodes, best0 = S->best_cost;
    if (M && M->count[i]) {
        size_t w = memo_key(S, i, slack), e;
        M->probes++;
        if (w && (e = memo_find(M, w, memo_hash(M->key, w))) != 0) {
            M->hits++;   /* replay: count its nodes, it finds nothing */
            M->saved += M->pool[e - 1];
            if (S->nodes + M->pool[e - 1] > S->budget) {
                S->nodes = S->budget + 1;
                S->exhausted = 1;
            } else
                S->nodes += M->pool[e - 1];
            return;
        }
    }
    dfs_expand(S, i);
    if (S->M && !S->exhausted && S->best_cost == best0 && S->nodes - n0 >= MEMO_MIN_NODES)
        memo_store(S, i, slack, S->nodes - n0);
}

/* One repair round's bombs (section (2), (4) above): bomb[b] is the
 * lattice tet of bomb b, optv[4b .. 4b + nopt[b]) its candidate vertices,
 * parent[] the union-find of its cluster, and order[coff[r] ..
 * coff[r + 1]) the bombs of the cluster whose root is r. claim[] (per
 * lattice tet, -1 between rounds) is the first bomb whose candidates
 * would add the tet, then a cluster's local tet numbering. */
typedef struct bomb_round {
    const st_lattice *L;
    unsigned char *keep;
    int64_t *claim;
    size_t nb;
    size_t *bomb;
    uint32_t *optv;
    int *nopt;
    size_t *parent, *order, *coff;
} bomb_round;

/* The bombs, their candidates (the vertices with a complete snowflake),
 * and their clusters: bombs whose candidates would add a common tet. */
static void round_candidates(bomb_round *R)
{
    const st_lattice *L = R->L;
    for (size_t t = 0; t < L->ntets; t++)
        if (R->keep[t] && boundary_faces(L, R->keep, t) >= 2)
            R->bomb[R->nb++] = t;
    for (size_t b = 0; b < R->nb; b++) {
        R->parent[b] = b;
        R->nopt[b] = 0;
        for (int c = 0; c < 4; c++) {
            uint32_t v = L->tets[4 * R->bomb[b] + (size_t)c];
            if (star_complete(L, v))
                R->optv[4 * b + (size_t)R->nopt[b]++] = v;
        }
    }
    for (size_t b = 0; b < R->nb; b++)
        for (int o = 0; o < R->nopt[b]; o++) {
            uint32_t v = R->optv[4 * b + (size_t)o];
            for (size_t a = L->star_off[v]; a < L->star_off[v + 1]; a++) {
                size_t t = L->star[a];
                if (R->keep[t])
                    continue;
                if (R->claim[t] < 0)
                    R->claim[t] = (int64_t)b;
                else
                    uf_join(R->parent, b, (size_t)R->claim[t]);
            }
        }
}

/* Group bombs by cluster root (roots are the smallest members, so
 * clusters come in order of their first bomb). */
static st_status round_group(bomb_round *R, st_error *err)
{
    const size_t nb = R->nb;
    for (size_t b = 0; b < nb; b++)
        R->coff[uf_find(R->parent, b) + 1]++;
    for (size_t b = 0; b < nb; b++)
        R->coff[b + 1] += R->coff[b];
    size_t *fill = st_malloc_array(nb + 1, sizeof *fill);
    if (!fill)
        return st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory");
    memcpy(fill, R->coff, (nb + 1) * sizeof *fill);
    for (size_t b = 0; b < nb; b++)
        R->order[fill[uf_find(R->parent, b)]++] = b;
    free(fill);
    return ST_OK;
}

/* Reset the claims of this round. */
static void round_reset_claims(bomb_round *R)
{
    const st_lattice *L = R->L;
    for (size_t b = 0; b < R->nb; b++)
        for (int o = 0; o < R->nopt[b]; o++) {
            uint32_t v = R->optv[4 * b + (size_t)o];
            for (size_t a = L->star_off[v]; a < L->star_off[v + 1]; a++)
                R->claim[L->star[a]] = -1;
        }
}

/* The cluster's options as local tets: claim[] becomes the local index
 * (-2 - index) at a tet's first sight. */
static void cluster_options(bomb_round *R, search *S, size_t c0)
{
    const st_lattice *L = R->L;
    size_t nloc = 0, k = 0;
    for (size_t q = 0; q < S->n; q++) {
        size_t b = R->order[c0 + q];
        S->nopt[q] = R->nopt[b];
        for (int o = 0; o < 4; o++) {
            S->opt_off[4 * q + (size_t)o] = k;
            if (o >= R->nopt[b])
                continue;
            uint32_t v = R->optv[4 * b + (size_t)o];
            for (size_t a = L->star_off[v]; a < L->star_off[v + 1]; a++) {
                size_t t = L->star[a];
                if (R->keep[t])
                    continue;
                if (R->claim[t] >= 0)   /* first sight: number it */
                    R->claim[t] = -2 - (int64_t)nloc++;
                S->opt_tets[k++] = (uint32_t)(-2 - R->claim[t]);
            }
        }
    }
    S->opt_off[4 * S->n] = k;
    S->nloc = nloc;
    /* The pairs: an option's tets grouped by word of cov. */
    size_t np = 0;
    for (size_t j = 0; j < 4 * S->n; j++) {
        S->pair_off[j] = np;
        for (size_t a = S->opt_off[j]; a < S->opt_off[j + 1]; a++) {
            uint32_t u = S->opt_tets[a];
            size_t x = S->pair_off[j];
            while (x < np && S->pair_w[x] != u / 64)
                x++;
            if (x == np) {
                S->pair_w[np] = u / 64;
                S->pair_m[np++] = 0;
            }
            S->pair_m[x] |= (uint64_t)1 << (u % 64);
        }
    }
    S->pair_off[4 * S->n] = np;
}

/* Greedy: each bomb, in order, its cheapest candidate. Leaves the choice
 * in best_sel and best_cost, nothing applied; returns its cost. */
static size_t search_greedy(search *S)
{
    const size_t n = S->n;
    for (size_t q = 0; q < n; q++) {
        int bo = -1;
        size_t bg = 0;
        for (int o = 0; o < S->nopt[q]; o++) {
            size_t g = opt_gain(S, q, o);
            if (bo < 0 || g < bg) {
                bo = o;
                bg = g;
            }
        }
        S->sel[q] = bo < 0 ? 0 : bo;
        if (bo >= 0)
            opt_apply(S, q, bo);
    }
    S->best_cost = S->cost;
    memcpy(S->best_sel, S->sel, n * sizeof *S->sel);
    for (size_t q = n; q-- > 0;)
        if (S->nopt[q] > 0)
            opt_undo(S, q, S->sel[q]);
    return S->best_cost;
}

/* The branch and bound from the greedy choice, for a cluster of at most
 * cluster_max bombs that all have a candidate: 1 when it searched every
 * choice within the budget (best_sel is then the cheapest), else 0
 * (best_sel the best found, never worse than greedy). */
static int search_exact(search *S, const st_sculpt_params *p)
{
    const size_t n = S->n;
    if (n > p->cluster_max)
        return 0;
    int searched = 0;
    S->budget = p->search_budget;
    S->best_cost++;   /* let the search reach the greedy cost */
    size_t greedy_cost = S->best_cost - 1;
    int *greedy_sel = st_malloc_array(n, sizeof *greedy_sel);
    if (greedy_sel)
        memcpy(greedy_sel, S->best_sel, n * sizeof *greedy_sel);
    int any_empty = 0;
    for (size_t q = 0; q < n; q++)
        any_empty |= S->nopt[q] == 0;
    if (greedy_sel && !any_empty) {
        S->memo_on = p->search_memo;
        dfs(S, 0);
        searched = !S->exhausted;
        memo_free(S->M);
        S->M = NULL;
        if (S->best_cost > greedy_cost) {   /* nothing better */
            S->best_cost = greedy_cost;
            memcpy(S->best_sel, greedy_sel, n * sizeof *greedy_sel);
        }
    } else
        S->best_cost = greedy_cost;
    free(greedy_sel);
    return searched;
}

/* One cluster, the bombs order[c0 .. c0 + n): its options, the greedy
 * choice, the search, and the snowflakes of the choice added to keep. */
static st_status solve_cluster(bomb_round *R, size_t c0, size_t n,
                               const st_sculpt_params *p, st_sculpt_stats *ss,
                               st_error *err)
{
    const st_lattice *L = R->L;
    st_status st = ST_OK;
    search S = {.n = n};
    S.nopt = st_malloc_array(n, sizeof *S.nopt);
    S.opt_off = st_calloc_array(4 * n + 1, sizeof *S.opt_off);
    size_t total = 0;
    for (size_t q = 0; q < n; q++)
        for (int o = 0; o < R->nopt[R->order[c0 + q]]; o++) {
            uint32_t v = R->optv[4 * R->order[c0 + q] + (size_t)o];
            total += L->star_off[v + 1] - L->star_off[v];
        }
    S.opt_tets = st_malloc_array(total + 1, sizeof *S.opt_tets);
    S.pair_off = st_calloc_array(4 * n + 1, sizeof *S.pair_off);
    S.pair_w = st_malloc_array(total + 1, sizeof *S.pair_w);
    S.pair_m = st_malloc_array(total + 1, sizeof *S.pair_m);
    S.pair_new = st_malloc_array(total + 1, sizeof *S.pair_new);
    S.cov = st_calloc_array(total / 64 + 1, sizeof *S.cov);
    S.sel = st_calloc_array(n, sizeof *S.sel);
    S.best_sel = st_calloc_array(n, sizeof *S.best_sel);
    if (!S.nopt || !S.opt_off || !S.opt_tets || !S.pair_off || !S.pair_w || !S.pair_m ||
        !S.pair_new || !S.cov || !S.sel || !S.best_sel) {
        st = st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory");
        goto done;
    }
    cluster_options(R, &S, c0);
    ss->greedy_tets += search_greedy(&S);
    if (search_exact(&S, p))
        ss->clusters_exact++;
    else
        ss->clusters_greedy++;
    ss->search_nodes += S.nodes;
    ss->search_expanded += S.expanded;
    /* Apply the choice. */
    for (size_t q = 0; q < n; q++) {
        if (S.nopt[q] == 0)
            continue;
        uint32_t v = R->optv[4 * R->order[c0 + q] + (size_t)S.best_sel[q]];
        size_t added = add_star(L, R->keep, v, ST_SCULPT_BOMB);
        if (added) {
            ss->snowflakes++;
            ss->bomb_tets += added;
        }
    }
done:
    free(S.nopt);
    free(S.opt_off);
    free(S.opt_tets);
    free(S.pair_off);
    free(S.pair_w);
    free(S.pair_m);
    free(S.pair_new);
    free(S.cov);
    free(S.sel);
    free(S.best_sel);
    return st;
}

/* One round of repair over the nbombs bombs of keep: candidates,
 * clusters, each cluster solved; the claims reset for the next round. */
static st_status repair_round(unsigned char *keep, int64_t *claim, size_t nbombs,
                              const st_lattice *L, const st_sculpt_params *p,
                              st_sculpt_stats *ss, st_error *err)
{
    st_status st = ST_OK;
    bomb_round R = {.L = L, .keep = keep, .claim = claim};
    R.bomb = st_malloc_array(nbombs, sizeof *R.bomb);
    R.optv = st_malloc_array(nbombs, 4 * sizeof *R.optv);
    R.nopt = st_malloc_array(nbombs, sizeof *R.nopt);
    R.parent = st_malloc_array(nbombs, sizeof *R.parent);
    R.order = st_malloc_array(nbombs, sizeof *R.order);
    R.coff = st_calloc_array(nbombs + 1, sizeof *R.coff);
    if (!R.bomb || !R.optv || !R.nopt || !R.parent || !R.order || !R.coff) {
        st = st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory");
        goto done;
    }
    round_candidates(&R);
    st = round_group(&R, err);
    for (size_t r = 0; r < R.nb && st == ST_OK; r++) {
        size_t c0 = R.coff[r], n = R.coff[r + 1] - c0;
        if (n == 0)
            continue;
        ss->clusters++;
        if (n > ss->largest_cluster)
            ss->largest_cluster = n;
        st = solve_cluster(&R, c0, n, p, ss, err);
    }
    round_reset_claims(&R);
done:
    free(R.bomb);
    free(R.optv);
    free(R.nopt);
    free(R.parent);
    free(R.order);
    free(R.coff);
    return st;
}

st_status st_sculpt_repair_bombs(unsigned char *keep, st_sculpt_stats *stats,
                                 const st_lattice *L,
                                 const st_sculpt_params *p, st_error *err)
{
    st_sculpt_stats local;
    memset(&local, 0, sizeof local);
    st_sculpt_stats *ss = stats ? stats : &local;
    size_t hist[5];
    size_t nbombs = st_sculpt_count_bombs(L, keep, hist);
    ss->bombs = nbombs;
    ss->bombs_3faces = hist[3];
    ss->bombs_4faces = hist[4];
    ss->clusters = ss->clusters_exact = ss->clusters_greedy = 0;
    ss->largest_cluster = ss->snowflakes = ss->bomb_tets = 0;
    ss->greedy_tets = 0;
    ss->search_nodes = ss->search_expanded = 0;
    ss->repair_rounds = 0;
    size_t nt = L->ntets;
    int64_t *claim = st_malloc_array(nt, sizeof *claim);
    if (!claim)
        return st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory");
    for (size_t t = 0; t < nt; t++)
        claim[t] = -1;
    st_status st = ST_OK;
    for (int round = 0; round < 10 && nbombs; round++) {
        ss->repair_rounds++;
        if ((st = repair_round(keep, claim, nbombs, L, p, ss, err)))
            break;
        nbombs = st_sculpt_count_bombs(L, keep, NULL);
    }
    free(claim);
    ss->bombs_left = st_sculpt_count_bombs(L, keep, NULL);
    return st;
}

/* ---- manifold boundary ---- */

/* The non-manifold boundary vertices (ascending) into *list (may be NULL)
 * and the counts. */
static st_status nonmanifold(const st_lattice *L, const unsigned char *keep,
                             uint32_t **list, size_t *nlist, size_t *nedges,
                             st_error *err)
{
    size_t nv = L->nverts, nt = L->ntets;
    size_t *off = st_calloc_array(nv + 1, sizeof *off);
    if (!off)
        return st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory");
    size_t nf = 0;
    for (size_t t = 0; t < nt; t++)
        if (keep[t])
            for (int i = 0; i < 4; i++) {
                int64_t o = L->nbr[4 * t + (size_t)i];
                if (o >= 0 && keep[o])
                    continue;
                nf++;
                for (int c = 0; c < 4; c++)
                    if (c != i)
                        off[L->tets[4 * t + (size_t)c] + 1]++;
            }
    for (size_t v = 0; v < nv; v++)
        off[v + 1] += off[v];
    /* Per vertex: the two other vertices of each incident boundary face. */
    uint32_t *link = st_malloc_array(off[nv] + 1, 2 * sizeof *link);
    size_t *fill = st_malloc_array(nv + 1, sizeof *fill);
    uint32_t *out = st_malloc_array(nv + 1, sizeof *out);
    if (!link || !fill || !out) {
        free(off); free(link); free(fill); free(out);
        return st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory");
    }
    memcpy(fill, off, (nv + 1) * sizeof *fill);
    for (size_t t = 0; t < nt; t++)
        if (keep[t])
            for (int i = 0; i < 4; i++) {
                int64_t o = L->nbr[4 * t + (size_t)i];
                if (o >= 0 && keep[o])
                    continue;
                uint32_t f[3];
                int k = 0;
                for (int c = 0; c < 4; c++)
                    if (c != i)
                        f[k++] = L->tets[4 * t + (size_t)c];
                for (int c = 0; c < 3; c++) {
                    size_t s = fill[f[c]]++;
                    link[2 * s] = f[(c + 1) % 3];
                    link[2 * s + 1] = f[(c + 2) % 3];
                }
            }
    size_t nout = 0, ne = 0;
    for (size_t v = 0; v < nv; v++) {
        size_t a0 = off[v], a1 = off[v + 1], k = a1 - a0;
        if (k == 0)
            continue;
        /* Local link vertices, their degrees and components. */
        uint32_t lv[128];
        int deg[128];
        size_t par[128];
        size_t nl = 0;
        int bad = 0;
        if (2 * k > 128) {
            bad = 1;   /* cannot happen on a lattice; be safe */
        } else {
            for (size_t a = a0; a < a1; a++)
                for (int e = 0; e < 2; e++) {
                    uint32_t w = link[2 * a + (size_t)e];
                    size_t q = 0;
                    while (q < nl && lv[q] != w)
                        q++;
                    if (q == nl) {
                        lv[nl] = w;
                        deg[nl] = 0;
                        par[nl] = nl;
                        nl++;
                    }
                    deg[q]++;
                }
            for (size_t a = a0; a < a1; a++) {
                size_t qa = 0, qb = 0;
                while (lv[qa] != link[2 * a])
                    qa++;
                while (lv[qb] != link[2 * a + 1])
                    qb++;
                uf_join(par, qa, qb);
            }
            for (size_t q = 0; q < nl; q++) {
                if (deg[q] != 2)
                    bad = 1;
                if (deg[q] > 2 && v < lv[q])
                    ne++;
                if (uf_find(par, q) != 0)
                    bad = 1;
            }
        }
        if (bad)
            out[nout++] = (uint32_t)v;
    }
    free(off);
    free(link);
    free(fill);
    if (list)
        *list = out;
    else
        free(out);
    *nlist = nout;
    if (nedges)
        *nedges = ne;
    return ST_OK;
}

st_status st_sculpt_count_nonmanifold(const st_lattice *L,
                                      const unsigned char *keep,
                                      size_t *vertices, size_t *edges,
                                      st_error *err)
{
    return nonmanifold(L, keep, NULL, vertices, edges, err);
}

st_status st_sculpt_repair_manifold(unsigned char *keep,
                                    st_sculpt_stats *stats,
                                    const st_lattice *L, st_error *err)
{
    size_t nvtx = 0, nedg = 0, added = 0;
    uint32_t *list = NULL;
    st_status st = nonmanifold(L, keep, &list, &nvtx, &nedg, err);
    if (st)
        return st;
    if (stats) {
        stats->nonmanifold_vertices = nvtx;
        stats->nonmanifold_edges = nedg;
    }
    for (int round = 0; round < ST_SCULPT_MANIFOLD_ROUNDS && nvtx; round++) {
        size_t fixed = 0;
        for (size_t q = 0; q < nvtx; q++)
            if (star_complete(L, list[q])) {
                added += add_star(L, keep, list[q], ST_SCULPT_MANIFOLD);
                fixed++;
            }
        free(list);
        list = NULL;
        st = nonmanifold(L, keep, &list, &nvtx, &nedg, err);
        if (st)
            return st;
        if (!fixed)
            break;
    }
    free(list);
    if (stats) {
        stats->manifold_tets = added;
        stats->nonmanifold_vertices_left = nvtx;
        stats->nonmanifold_edges_left = nedg;
    }
    return ST_OK;
}

/* ---- all of it ---- */

st_status st_sculpt(st_tetmesh **out, st_sculpt_stats *stats,
                    const st_grid *g, const st_soup *s, const st_bvh *bvh,
                    const st_sculpt_params *p, st_error *err)
{
    *out = NULL;
    st_sculpt_stats ss;
    memset(&ss, 0, sizeof ss);
    if (g->kind != ST_GRID_SIGNED)
        return st_error_set(err, ST_EINPUT, NULL, 0,
                            "the field is not signed (run soupsign first)");
    double t0 = omp_get_wtime();
    double lo[3], hi[3];
    st_lattice_grid_box(g, lo, hi);
    if (s && s->ntris) {
        /* The lattice must reach every triangle for the enclosure
         * argument, even one outside the field's box. */
        double slo[3], shi[3];
        if (st_soup_bounds(s, slo, shi, NULL) == ST_OK)
            for (int a = 0; a < 3; a++) {
                lo[a] = fmin(lo[a], slo[a]);
                hi[a] = fmax(hi[a], shi[a]);
            }
    }
    st_lattice_params lp = st_lattice_params_default();
    lp.kind = p->kind;
    lp.h = p->h;
    lp.seed = p->seed;
    lp.pad = p->pad;
    lp.max_tets = p->max_tets;
    lp.cancel = p->cancel;
    st_lattice *L = NULL;
    st_status st = st_lattice_build(&L, lo, hi, &lp, err);
    if (st)
        return st;
    double t1 = omp_get_wtime();
    unsigned char *keep = st_malloc_array(L->ntets, 1);
    if (!keep) {
        st_lattice_free(L);
        return st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory");
    }
    const st_progress stop = {NULL, NULL, p->cancel};
    st = classify(keep, &ss, L, g, s, bvh, p->cancel, err);
    double t2 = omp_get_wtime();
    if (!st && st_progress_cancelled(&stop))
        st = st_error_set(err, ST_ECANCELLED, NULL, 0, "cancelled");
    if (!st && p->repair_bombs)
        st = st_sculpt_repair_bombs(keep, &ss, L, p, err);
    else if (!st) {
        size_t hist[5];
        ss.bombs = ss.bombs_left = st_sculpt_count_bombs(L, keep, hist);
        ss.bombs_3faces = hist[3];
        ss.bombs_4faces = hist[4];
    }
    if (!st && st_progress_cancelled(&stop))
        st = st_error_set(err, ST_ECANCELLED, NULL, 0, "cancelled");
    if (!st && p->repair_manifold)
        st = st_sculpt_repair_manifold(keep, &ss, L, err);
    else if (!st) {
        st = st_sculpt_count_nonmanifold(L, keep, &ss.nonmanifold_vertices,
                                         &ss.nonmanifold_edges, err);
        ss.nonmanifold_vertices_left = ss.nonmanifold_vertices;
        ss.nonmanifold_edges_left = ss.nonmanifold_edges;
    }
    /* Manifold repair never creates bombs (sculpt.c, point 3); recount to
     * report what the caller gets. */
    if (!st)
        ss.bombs_left = st_sculpt_count_bombs(L, keep, NULL);
    double t3 = omp_get_wtime();
    st_tetmesh *m = NULL;
    if (!st)
        st = st_lattice_to_tetmesh(&m, L, keep, err);
    if (!st) {
        double *a = NULL;
        st = st_tetmesh_add_array(m, "sculpt", ST_ON_CELLS, 1, &a, err);
        if (!st) {
            size_t k = 0;
            for (size_t t = 0; t < L->ntets; t++)
                if (keep[t])
                    a[k++] = (double)keep[t];
            char buf[64];
            snprintf(buf, sizeof buf, "%zu found, %zu left", ss.bombs,
                     ss.bombs_left);
            if (st_meta_set(&m->meta, "bombs", buf))
                st = st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory");
        }
    }
    double t4 = omp_get_wtime();
    free(keep);
    st_lattice_free(L);
    if (st) {
        st_tetmesh_free(m);
        return st;
    }
    ss.tets = m->ntets;
    ss.t_lattice = t1 - t0;
    ss.t_classify = t2 - t1;
    ss.t_repair = t3 - t2;
    ss.t_mesh = t4 - t3;
    if (stats)
        *stats = ss;
    *out = m;
    return ST_OK;
}
