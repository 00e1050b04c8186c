/*
 * bvh.c - bounding volume hierarchy over soup triangles (see bvh.h).
 *
 * Build: top-down, splitting at the median centroid along the longest axis
 * of the centroid box (quickselect), so the tree is balanced and its depth
 * is about log2(n / ST_BVH_LEAF) whatever the input. Nearest query:
 * depth-first with an explicit stack, the nearer child first, pruning boxes
 * whose distance is not below the best so far. Box query: depth-first,
 * left child first, every triangle whose own box meets the query box.
 * Triangle query: the same walk, pruning every node whose box the query
 * triangle does not meet (exact, isect.h), so a large slanted triangle
 * visits the few leaves along it instead of all of its bounding box.
 *
 * Subtrees over many triangles are built as OpenMP tasks; the median
 * split makes the tree's shape depend on the triangle count alone, so each
 * task knows where its nodes go and the layout is the serial one.
 *
 * Each triangle's box is computed once at build time and kept in slot
 * order (tbox), so neither the build (node boxes at every level) nor the
 * leaf scans of the queries recompute it from the soup.
 */
#include "souptet/bvh.h"
#include "../base/fpenv.h"
#include "souptet/geom.h"
#include "souptet/isect.h"
#include "souptet/mem.h"
#include "souptet/pred.h"

#include <math.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

/* A median-split tree over n >= 1 leaves of >= 1 triangle has < 2n nodes and
 * depth below 64 for any n a uint32 can count. */
#define STACK_DEPTH 128

typedef struct build_ctx {
    const st_soup *s;
    double *cent;          /* 3 per position of order: the centroid of
                              triangle order[i] at cent + 3 i, swapped
                              with it (the scans read it in sequence) */
    uint32_t *order;
    st_bvh_node *nodes;
    size_t nnodes;
} build_ctx;

static void tri_box(const st_soup *s, uint32_t t, double lo[3], double hi[3])
{
    for (int a = 0; a < 3; a++) {
        lo[a] = INFINITY;
        hi[a] = -INFINITY;
    }
    for (int k = 0; k < 3; k++) {
        const double *v = s->xyz + 3 * (size_t)s->tris[3 * (size_t)t + k];
        for (int a = 0; a < 3; a++) {
            lo[a] = fmin(lo[a], v[a]);
            hi[a] = fmax(hi[a], v[a]);
        }
    }
}

/* Partition order[lo..hi) so the element at position mid is the one a sort
 * by centroid coordinate `axis` would put there: quickselect with Hoare's
 * partition (pivot at the lower middle, which keeps both sides non-empty,
 * so every round makes progress). */
static void select_median(build_ctx *c, size_t lo, size_t hi, size_t mid,
                          int axis)
{
    uint32_t *o = c->order;
    double *ce = c->cent;
    ptrdiff_t l = (ptrdiff_t)lo, r = (ptrdiff_t)hi - 1, m = (ptrdiff_t)mid;
    while (l < r) {
        double pivot = ce[3 * (size_t)(l + (r - l) / 2) + axis];
        ptrdiff_t i = l - 1, j = r + 1;
        for (;;) {
            do
                i++;
            while (ce[3 * (size_t)i + axis] < pivot);
            do
                j--;
            while (ce[3 * (size_t)j + axis] > pivot);
            if (i >= j)
                break;
            uint32_t t = o[i];
            o[i] = o[j];
            o[j] = t;
            for (int k = 0; k < 3; k++) {
                double x = ce[3 * (size_t)i + k];
                ce[3 * (size_t)i + k] = ce[3 * (size_t)j + k];
                ce[3 * (size_t)j + k] = x;
            }
        }
        /* [l, j] <= pivot <= [j+1, r], with l <= j < r */
        if (m <= j)
            r = j;
        else
            l = j + 1;
    }
}

/* Subtrees this large are built as tasks of their own (and node and
 * triangle arrays this long are swept in parallel). */
#define PARALLEL_MIN 32768

/* The axis along which the centroids of the triangles order[lo..hi)
 * spread widest (the split axis). The node's box is set after the build
 * (node_boxes). */
static int split_axis(const build_ctx *c, size_t lo, size_t hi)
{
    double clo[3] = {INFINITY, INFINITY, INFINITY};
    double chi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (size_t i = lo; i < hi; i++) {
        const double *ce = c->cent + 3 * i;
        for (int k = 0; k < 3; k++) {
            /* plain comparisons: coordinates are finite (soup.h) */
            if (ce[k] < clo[k])
                clo[k] = ce[k];
            if (ce[k] > chi[k])
                chi[k] = ce[k];
        }
    }
    int axis = 0;
    for (int k = 1; k < 3; k++)
        if (chi[k] - clo[k] > chi[axis] - clo[axis])
            axis = k;
    return axis;
}

/* Every node's box: a leaf's from its triangles' boxes (tbox, in order),
 * then, children being numbered after their parent, each inner node's as
 * the union of its children's, from the last node back. The same exact
 * minima and maxima as a scan of each node's triangles, without log n
 * passes over all of them. */
static void node_boxes(st_bvh_node *nodes, size_t nnodes, const double *tbox)
{
    #pragma omp parallel for schedule(static) if (nnodes >= PARALLEL_MIN)
    for (size_t i = 0; i < nnodes; i++) {
        st_bvh_node *n = &nodes[i];
        if (!n->count)
            continue;
        for (int k = 0; k < 3; k++) {
            n->lo[k] = INFINITY;
            n->hi[k] = -INFINITY;
        }
        for (uint32_t j = 0; j < n->count; j++) {
            const double *tb = tbox + 6 * (size_t)(n->start + j);
            for (int k = 0; k < 3; k++) {
                if (tb[k] < n->lo[k])
                    n->lo[k] = tb[k];
                if (tb[3 + k] > n->hi[k])
                    n->hi[k] = tb[3 + k];
            }
        }
    }
    for (size_t i = nnodes; i-- > 0;) {
        st_bvh_node *n = &nodes[i];
        if (n->count)
            continue;
        const st_bvh_node *l = &nodes[n->start], *r = &nodes[n->start + 1];
        for (int k = 0; k < 3; k++) {
            n->lo[k] = l->lo[k] < r->lo[k] ? l->lo[k] : r->lo[k];
            n->hi[k] = l->hi[k] > r->hi[k] ? l->hi[k] : r->hi[k];
        }
    }
}

/* The subtree of `node` over order[lo..hi), its nodes numbered from
 * `next` on, depth first, the right child's subtree before the left's
 * (the order of the explicit stack). */
static void build_serial(build_ctx *c, size_t node, size_t lo, size_t hi,
                         size_t next)
{
    /* Explicit stack of (node, lo, hi) to stay off the call stack. */
    size_t stack[STACK_DEPTH][3];
    int sp = 0;
    stack[sp][0] = node;
    stack[sp][1] = lo;
    stack[sp][2] = hi;
    sp++;
    while (sp > 0) {
        sp--;
        size_t nd = stack[sp][0], a = stack[sp][1], b = stack[sp][2];
        st_bvh_node *n = &c->nodes[nd];
        int axis = split_axis(c, a, b);
        if (b - a <= ST_BVH_LEAF) {
            n->start = (uint32_t)a;
            n->count = (uint32_t)(b - a);
            continue;
        }
        size_t mid = a + (b - a) / 2;
        select_median(c, a, b, mid, axis);
        size_t left = next;
        next += 2;
        n->start = (uint32_t)left;
        n->count = 0;
        stack[sp][0] = left;
        stack[sp][1] = a;
        stack[sp][2] = mid;
        sp++;
        stack[sp][0] = left + 1;
        stack[sp][1] = mid;
        stack[sp][2] = b;
        sp++;
    }
}

/* Leaves of a subtree over n triangles, as the pair (L(n), L(n + 1)): the
 * median split makes the tree's shape a function of n alone (halves
 * floor(n/2) and ceil(n/2)), and the pair recursion costs log n. */
static void leaves_pair(size_t n, size_t *ln, size_t *ln1)
{
    if (n + 1 <= ST_BVH_LEAF) {
        *ln = *ln1 = 1;
        return;
    }
    size_t a, b;
    leaves_pair(n / 2, &a, &b);   /* L(n/2), L(n/2 + 1) */
    if (n % 2 == 0) {
        *ln = n <= ST_BVH_LEAF ? 1 : 2 * a;
        *ln1 = a + b;
    } else {
        *ln = n <= ST_BVH_LEAF ? 1 : a + b;
        *ln1 = 2 * b;
    }
}

/* Nodes below the root of a subtree over n triangles. */
static size_t subtree_nodes(size_t n)
{
    size_t l, l1;
    leaves_pair(n, &l, &l1);
    return 2 * (l - 1);
}


/* build_serial's tree, node for node, with the two halves of large
 * subtrees built in parallel: each child's numbering starts where the
 * serial walk would start it (the right subtree first: its children from
 * next + 2, the left's after the right's nodes), so the layout, and every
 * query's answer and order, do not depend on the threads. */
static void build_parallel(build_ctx *c, size_t node, size_t lo, size_t hi,
                           size_t next)
{
    if (hi - lo < PARALLEL_MIN) {
        build_serial(c, node, lo, hi, next);
        return;
    }
    st_bvh_node *n = &c->nodes[node];
    int axis = split_axis(c, lo, hi);
    size_t mid = lo + (hi - lo) / 2;
    select_median(c, lo, hi, mid, axis);
    size_t left = next;
    n->start = (uint32_t)left;
    n->count = 0;
    size_t right_next = left + 2;
    size_t left_next = right_next + subtree_nodes(hi - mid);
    #pragma omp task default(none) firstprivate(c, left, mid, hi, right_next)
    build_parallel(c, left + 1, mid, hi, right_next);
    build_parallel(c, left, lo, mid, left_next);
    #pragma omp taskwait
}

/* Frees what st_bvh_build holds when memory runs out. */
static st_status bvh_build_failed(st_bvh *b, build_ctx *c, size_t ntris,
                                  st_error *err)
{
    free(b);
    free(c->cent);
    free(c->order);
    free(c->nodes);
    return st_error_set(err, ST_ENOMEM, NULL, 0,
                        "out of memory for a BVH over %zu triangles", ntris);
}

st_status st_bvh_build(st_bvh **out, const st_soup *s, st_error *err)
{
    *out = NULL;
    if (s->ntris == 0)
        return st_error_set(err, ST_EINPUT, NULL, 0, "no triangles");
    if (s->ntris > UINT32_MAX / 2)
        return st_error_set(err, ST_ELIMIT, NULL, 0,
                            "too many triangles for the BVH (%zu)", s->ntris);
    build_ctx c = {0};
    c.s = s;
    c.nnodes = 1 + subtree_nodes(s->ntris);
    /* every array is touched in full, most at random: huge pages past a
     * few MB (st_malloc_big; ntris < 2^31 keeps the products in range) */
    st_bvh *b = calloc(1, sizeof *b);
    c.cent = st_malloc_big(s->ntris * 3 * sizeof(double));
    c.order = st_malloc_big(s->ntris * sizeof(uint32_t));
    c.nodes = st_malloc_big(c.nnodes * sizeof(st_bvh_node));
    if (!b || !c.cent || !c.order || !c.nodes)
        return bvh_build_failed(b, &c, s->ntris, err);
    #pragma omp parallel for schedule(static) if (s->ntris >= PARALLEL_MIN)
    for (size_t t = 0; t < s->ntris; t++) {
        c.order[t] = (uint32_t)t;
        for (int a = 0; a < 3; a++) {
            double sum = 0.0;
            for (int k = 0; k < 3; k++)
                sum += s->xyz[3 * (size_t)s->tris[3 * t + k] + a];
            c.cent[3 * t + a] = sum / 3.0;
        }
    }
    if (s->ntris < PARALLEL_MIN)
        build_serial(&c, 0, 0, s->ntris, 1);
    else {
        #pragma omp parallel
        #pragma omp single
        build_parallel(&c, 0, 0, s->ntris, 1);
    }
    /* The centroids are freed before the triangles' boxes are taken, so
     * the two are never both resident: 240 MB less at the peak of a
     * 10M-triangle soup's build. (Growing the centroids' block into the
     * boxes' with realloc would keep its touched pages, but glibc copies
     * a block from posix_memalign into 4 KiB pages: measured slower.) */
    free(c.cent);
    c.cent = NULL;
    double *tbox = st_malloc_big(s->ntris * 6 * sizeof(double));
    if (!tbox)
        return bvh_build_failed(b, &c, s->ntris, err);
    #pragma omp parallel for schedule(static) if (s->ntris >= PARALLEL_MIN)
    for (size_t i = 0; i < s->ntris; i++)
        tri_box(s, c.order[i], tbox + 6 * i, tbox + 6 * i + 3);
    node_boxes(c.nodes, c.nnodes, tbox);
    b->tbox = tbox;
    b->soup = s;
    b->nodes = c.nodes;
    b->nnodes = c.nnodes;
    b->order = c.order;
    *out = b;
    return ST_OK;
}

void st_bvh_free(st_bvh *b)
{
    if (!b)
        return;
    free(b->nodes);
    free(b->order);
    free(b->tbox);
    free(b);
}


static double box_dist2(const st_bvh_node *n, const double p[3])
{
    return st_box_dist2(n->lo, n->hi, p);
}

/* box_dist2 of two nodes at once, bit for bit: with SSE2 (every x86-64)
 * one lane per node, the same operations in the same order (maxpd(x, 0)
 * is x > 0 ? x : 0, NaN and -0 included); elsewhere two calls. */
static void box_dist2_pair(const st_bvh_node *l, const st_bvh_node *r, const double p[3],
                           double *dl, double *dr)
{
#if defined(__SSE2__)
    const __m128d zero = _mm_setzero_pd();
    __m128d d2 = zero;
    for (int a = 0; a < 3; a++) {
        const __m128d pa = _mm_set1_pd(p[a]);
        const __m128d lo = _mm_loadh_pd(_mm_load_sd(&l->lo[a]), &r->lo[a]);
        const __m128d hi = _mm_loadh_pd(_mm_load_sd(&l->hi[a]), &r->hi[a]);
        const __m128d d = _mm_add_pd(_mm_max_pd(_mm_sub_pd(lo, pa), zero),
                                     _mm_max_pd(_mm_sub_pd(pa, hi), zero));
        d2 = _mm_add_pd(d2, _mm_mul_pd(d, d));
    }
    _mm_storel_pd(dl, d2);
    _mm_storeh_pd(dr, d2);
#else
    *dl = box_dist2(l, p);
    *dr = box_dist2(r, p);
#endif
}

/* A leaf's triangle is skipped when its own box lies so far beyond the
 * best distance so far that st_point_triangle_dist2 cannot return less,
 * rounding included, so the answer is the one without the test. What the
 * computed distance can fall short of the true one (which is at least the
 * box's): the closest point on an edge is off the segment by a few
 * rounding units of the coordinates (at most the soup's magnitude m); an
 * interior one (the plane's distance, along the computed unit normal of a
 * triangle whose area is above ST_DEGENERATE_AREA_RATIO of its longest
 * edge squared, so the normal is off by under 2e-7 radians) by under 4e-7
 * of the distance plus 2e-6 of the triangle's box side. TRI_SKIP_REL and
 * TRI_SKIP_SIDE are those bounds times 250 and 50; TRI_SKIP_ABS, 2^7
 * rounding units. The test costs a box distance and spares the triangle's
 * three square roots. */
#define TRI_SKIP_REL 1e-4
#define TRI_SKIP_SIDE 1e-4
#define TRI_SKIP_ABS 3e-14
#if defined(__GNUC__)
__attribute__((always_inline))
#endif
static inline int tri_beyond(const double *tb, const double p[3], double reach, double m)
{
    double side = tb[3] - tb[0];
    side = tb[4] - tb[1] > side ? tb[4] - tb[1] : side;
    side = tb[5] - tb[2] > side ? tb[5] - tb[2] : side;
    const double lim = (reach + TRI_SKIP_SIDE * side + TRI_SKIP_ABS * m) * (1.0 + TRI_SKIP_REL);
    return st_box_dist2(tb, tb + 3, p) > lim * lim;
}

/* The largest coordinate magnitude of the soup (its root box's). */
static double magnitude(const st_bvh *b)
{
    double m = 0.0;
    for (int a = 0; a < 3; a++) {
        m = fabs(b->nodes[0].lo[a]) > m ? fabs(b->nodes[0].lo[a]) : m;
        m = fabs(b->nodes[0].hi[a]) > m ? fabs(b->nodes[0].hi[a]) : m;
    }
    return m;
}

/* The walk of st_bvh_nearest and st_bvh_within: depth first, the nearer
 * child first, each node on the stack with its box distance (computed
 * once: a node is skipped when that is no longer below the best). With
 * `any`, it stops at the first triangle closer than sqrt(max_d2): the
 * walk to it is the nearest search's while best is still max_d2, so it
 * finds a triangle exactly when that search does. */
static double nearest_walk(const st_bvh *b, const st_tri_frame *frames, const double p[3],
                           double max_d2, int any, int64_t *tri, double closest[3],
                           uint32_t *slot)
{
    const st_soup *s = b->soup;
    double best = max_d2;
    int64_t best_tri = -1;
    uint32_t stack[STACK_DEPTH];
    double sd2[STACK_DEPTH];
    int sp = 0;
    const double d0 = box_dist2(&b->nodes[0], p);
    if (d0 < best) {
        sd2[sp] = d0;
        stack[sp++] = 0;
    }
    const double m = magnitude(b);
    double reach = sqrt(best);   /* of best, for tri_beyond */
    while (sp > 0) {
        sp--;
        if (sd2[sp] >= best)
            continue;           /* best shrank since this was pushed */
        const st_bvh_node *n = &b->nodes[stack[sp]];
        if (n->count) {
            for (uint32_t i = 0; i < n->count; i++) {
                if (tri_beyond(b->tbox + 6 * (size_t)(n->start + i), p, reach, m))
                    continue;
                uint32_t t = b->order[n->start + i];
                const uint32_t *v = s->tris + 3 * (size_t)t;
                double q[3];
                const double *x0 = s->xyz + 3 * (size_t)v[0], *x1 = s->xyz + 3 * (size_t)v[1],
                             *x2 = s->xyz + 3 * (size_t)v[2];
                double d2 = frames ? st_point_triangle_dist2_framed(p, x0, x1, x2, frames + t, q)
                                   : st_point_triangle_dist2(p, x0, x1, x2, q);
                if (d2 < best) {
                    best = d2;
                    reach = sqrt(best);
                    best_tri = t;
                    if (closest)
                        memcpy(closest, q, sizeof q);
                    if (any) {
                        *tri = best_tri;
                        if (slot)
                            *slot = n->start + i;
                        return best;
                    }
                }
            }
            continue;
        }
        uint32_t l = n->start, r = n->start + 1;
        double dl, dr;
        box_dist2_pair(&b->nodes[l], &b->nodes[r], p, &dl, &dr);
        /* Push the farther first so the nearer is searched first. */
        if (dl > dr) {
            uint32_t t = l; l = r; r = t;
            double d = dl; dl = dr; dr = d;
        }
        if (dr < best) {
            sd2[sp] = dr;
            stack[sp++] = r;
        }
        if (dl < best) {
            sd2[sp] = dl;
            stack[sp++] = l;
        }
    }
    *tri = best_tri;
    return best;
}

double st_bvh_nearest(const st_bvh *b, const double p[3], double max_d2,
                      int64_t *tri, double closest[3])
{
    return nearest_walk(b, NULL, p, max_d2, 0, tri, closest, NULL);
}

double st_bvh_nearest_framed(const st_bvh *b, const st_tri_frame *frames, const double p[3],
                             double max_d2, int64_t *tri, double closest[3])
{
    return nearest_walk(b, frames, p, max_d2, 0, tri, closest, NULL);
}

int st_bvh_within(const st_bvh *b, const double p[3], double max_d2)
{
    int64_t tri;
    (void)nearest_walk(b, NULL, p, max_d2, 1, &tri, NULL, NULL);
    return tri >= 0;
}

/* The triangle in slot i answers st_bvh_within's walk for p and max_d2
 * when its box is nearer than max_d2, the leaf scan would not skip it
 * (tri_beyond, as the walk calls it) and its distance is below max_d2.
 * The walk then reaches its leaf unless it stops before: every node
 * above holds the triangle's box, and the computed box distance of a
 * larger box is never the greater (each rounded subtraction, maximum
 * with zero, square and sum is monotone in its operands), so each of
 * them is pushed and popped while nothing is found (best is still
 * max_d2); in the leaf the triangle is found, or one before it. Either
 * way st_bvh_within says 1: exactly the walk's answer, with no margin. */
static int slot_within(const st_bvh *b, uint32_t i, const double p[3], double max_d2)
{
    const double *tb = b->tbox + 6 * (size_t)i;
    if (!(st_box_dist2(tb, tb + 3, p) < max_d2) ||
        tri_beyond(tb, p, sqrt(max_d2), magnitude(b)))
        return 0;
    const st_soup *s = b->soup;
    const uint32_t *v = s->tris + 3 * (size_t)b->order[i];
    return st_point_triangle_dist2(p, s->xyz + 3 * (size_t)v[0], s->xyz + 3 * (size_t)v[1],
                                   s->xyz + 3 * (size_t)v[2], NULL) < max_d2;
}

int st_bvh_within_hint(const st_bvh *b, const double p[3], double max_d2,
                       const uint32_t *hints, size_t nhints, uint32_t *found)
{
    for (size_t h = 0; h < nhints; h++)
        if (hints[h] < b->soup->ntris && slot_within(b, hints[h], p, max_d2)) {
            *found = hints[h];
            return 1;
        }
    int64_t tri;
    *found = ST_BVH_NO_HINT;
    (void)nearest_walk(b, NULL, p, max_d2, 1, &tri, NULL, found);
    return tri >= 0;
}

static int boxes_meet(const double alo[3], const double ahi[3],
                      const double blo[3], const double bhi[3])
{
    return alo[0] <= bhi[0] && blo[0] <= ahi[0] && alo[1] <= bhi[1] &&
           blo[1] <= ahi[1] && alo[2] <= bhi[2] && blo[2] <= ahi[2];
}

/* Depth-first, left child first, so the visiting order is fixed for a given
 * tree and box. Node boxes are the exact min/max of their triangles'
 * coordinates, so no triangle whose box meets the query box is pruned; in
 * a leaf each triangle's own box is checked, so exactly those triangles
 * are visited. */
static int box_outside_tet(const st_plane_filter pl[4], const double lo[3], const double hi[3]);

/* st_bvh_query_box, and with pl (not NULL) st_bvh_query_tet: nodes and
 * triangles whose boxes miss [lo, hi], or that the tet's face planes pl
 * certainly exclude, are skipped. */
static int query_box(const st_bvh *b, const double lo[3], const double hi[3],
                     const st_plane_filter *pl, int (*visit)(void *ctx, uint32_t tri), void *ctx)
{
    uint32_t stack[STACK_DEPTH];
    int sp = 0;
    if (b->nnodes == 0 || !boxes_meet(b->nodes[0].lo, b->nodes[0].hi, lo, hi))
        return 0;
    stack[sp++] = 0;
    while (sp > 0) {
        const st_bvh_node *n = &b->nodes[stack[--sp]];
        if (pl && box_outside_tet(pl, n->lo, n->hi))
            continue;
        if (n->count) {
            for (uint32_t i = 0; i < n->count; i++) {
                const double *tb = b->tbox + 6 * (size_t)(n->start + i);
                if (boxes_meet(tb, tb + 3, lo, hi) && !(pl && box_outside_tet(pl, tb, tb + 3))) {
                    int r = visit(ctx, b->order[n->start + i]);
                    if (r)
                        return r;
                }
            }
            continue;
        }
        uint32_t l = n->start, r = n->start + 1;
        /* Right pushed first so the left is visited first. */
        if (boxes_meet(b->nodes[r].lo, b->nodes[r].hi, lo, hi))
            stack[sp++] = r;
        if (boxes_meet(b->nodes[l].lo, b->nodes[l].hi, lo, hi))
            stack[sp++] = l;
    }
    return 0;
}

int st_bvh_query_box(const st_bvh *b, const double lo[3], const double hi[3],
                     int (*visit)(void *ctx, uint32_t tri), void *ctx)
{
    return query_box(b, lo, hi, NULL, visit, ctx);
}

/* Node boxes are exact, and st_tri_box_intersect is exact for closed sets,
 * so no node holding a triangle whose box meets the query triangle is
 * pruned: the visits are a superset of the triangles meeting it. The box
 * test first, since it rejects most nodes for a few comparisons. */
static int node_meets_tri(const st_bvh_node *n, const st_tri_box_filter *q,
                          const double qlo[3], const double qhi[3])
{
    return boxes_meet(n->lo, n->hi, qlo, qhi) && st_tri_box_filter_maybe(q, n->lo, n->hi);
}

int st_bvh_query_tri(const st_bvh *b, const double a[3], const double bb[3],
                     const double c[3], int (*visit)(void *ctx, uint32_t tri),
                     void *ctx)
{
    st_tri_box_filter q;
    st_tri_box_filter_init(&q, a, bb, c);
    double lo[3], hi[3];
    for (int k = 0; k < 3; k++) {
        lo[k] = a[k] < bb[k] ? a[k] : bb[k];
        lo[k] = c[k] < lo[k] ? c[k] : lo[k];
        hi[k] = a[k] > bb[k] ? a[k] : bb[k];
        hi[k] = c[k] > hi[k] ? c[k] : hi[k];
    }
    uint32_t stack[STACK_DEPTH];
    int sp = 0;
    if (b->nnodes == 0 || !node_meets_tri(&b->nodes[0], &q, lo, hi))
        return 0;
    stack[sp++] = 0;
    while (sp > 0) {
        const st_bvh_node *n = &b->nodes[stack[--sp]];
        if (n->count) {
            for (uint32_t i = 0; i < n->count; i++) {
                const double *tb = b->tbox + 6 * (size_t)(n->start + i);
                if (boxes_meet(tb, tb + 3, lo, hi)) {
                    int r = visit(ctx, b->order[n->start + i]);
                    if (r)
                        return r;
                }
            }
            continue;
        }
        uint32_t l = n->start, r = n->start + 1;
        if (node_meets_tri(&b->nodes[r], &q, lo, hi))
            stack[sp++] = r;
        if (node_meets_tri(&b->nodes[l], &q, lo, hi))
            stack[sp++] = l;
    }
    return 0;
}

/* 1 when the closed box [lo, hi] certainly lies strictly outside the tet
 * whose face planes (each with the opposite corner as reference) are pl:
 * one plane rejects all eight corners. The corner furthest toward the
 * tet's side of a plane (by the rounded normal) is tried first: for a box
 * the plane does not reject, that one test usually says so. */
static int box_outside_tet(const st_plane_filter pl[4], const double lo[3], const double hi[3])
{
    for (int f = 0; f < 4; f++) {
        /* A flat tet (its corner on this face's plane, side 0): rejects
         * would take every point strictly off the plane, on either side,
         * as outside; the face cannot exclude anything on its own. */
        if (pl[f].side == 0)
            continue;
        int first = 0;
        for (int k = 0; k < 3; k++)
            if (pl[f].n[k] * (double)pl[f].side > 0.0)
                first |= 1 << k;
        int all = 1;
        for (int c = 0; c < 8 && all; c++) {
            const int corner = c ^ first;
            const double q[3] = {corner & 1 ? hi[0] : lo[0], corner & 2 ? hi[1] : lo[1],
                                 corner & 4 ? hi[2] : lo[2]};
            all = st_plane_filter_rejects(&pl[f], q);
        }
        if (all)
            return 1;
    }
    return 0;
}

int st_bvh_query_tet(const st_bvh *b, const double *const p[4],
                     int (*visit)(void *ctx, uint32_t tri), void *ctx)
{
    double lo[3], hi[3];
    for (int a = 0; a < 3; a++) {
        lo[a] = hi[a] = p[0][a];
        for (int c = 1; c < 4; c++) {
            lo[a] = p[c][a] < lo[a] ? p[c][a] : lo[a];
            hi[a] = p[c][a] > hi[a] ? p[c][a] : hi[a];
        }
    }
    st_plane_filter pl[4];
    for (int f = 0; f < 4; f++) {
        const double *q[3];
        for (int c = 0, n = 0; c < 4; c++)
            if (c != f)
                q[n++] = p[c];
        st_plane_filter_init(&pl[f], q[0], q[1], q[2], p[f]);
    }
    return query_box(b, lo, hi, pl, visit, ctx);
}
