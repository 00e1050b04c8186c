/*
 * enclose.c - exact point location in a tet mesh and the enclosure counts
 * (see enclose.h).
 *
 * Locator: a uniform grid over the bounding box of the tets' points with
 * about as many bins as tets, each listing the tets whose bounding boxes
 * meet it, in increasing index order. A query takes p's bin, rejects tets
 * whose box misses p (exact double comparisons), and asks st_point_in_tet
 * of the rest, in order, so the first hit is the lowest index. Bin numbers
 * are floor((x - lo) * inv_cell), a monotone function of x in floating
 * point, so a point inside a tet's box always falls in one of the bins the
 * tet was listed in: the grid only prunes, it never decides.
 *
 * Enclosure: the vertices of every BVH subtree (of WALK_MIN_TRIS
 * triangles or more) whose box one tet holds (its eight corners in the
 * closed tet, exactly: a large soup under a coarse mesh has most of its
 * vertices deep inside tets); every other
 * used soup vertex through the locator (the tet that held the vertex
 * before tried first: any tet will do); every boundary
 * face of the mesh against the soup triangles a BVH triangle query
 * returns, with st_tri_tri_intersect. The loops write per-item flags
 * (the same value from any thread) or integer reductions only, and each
 * flag is an exact answer, so the results do not depend on the thread
 * count or on which test gave them.
 */
#include "souptet/enclose.h"
#include "../base/fpenv.h"
#include "souptet/mem.h"
#include "souptet/pred.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Bins per tet (about): more bins mean shorter lists but more list entries
 * per tet; with cell width near the tet size a tet meets ~8-27 bins. */
#define BINS_PER_TET 1.0
/* Bins along an axis at most: a mesh that is flat in one direction keeps
 * the grid's memory bounded (<= 256^2 bins per layer). */
#define MAX_BINS_AXIS 256

struct st_locator {
    const st_tetmesh *m;
    double lo[3], hi[3];      /* bounding box of the tets' points */
    double inv_cell;
    size_t n[3];              /* bins per axis */
    size_t *off;              /* n0 n1 n2 + 1 list offsets into idx */
    uint32_t *idx;
    double *tbox;             /* 6 per tet: lo xyz, hi xyz */
    int empty;                /* no tets */
};

static size_t bin_coord(const st_locator *l, double x, int a)
{
    double f = floor((x - l->lo[a]) * l->inv_cell);
    if (!(f > 0.0))
        return 0;
    if (f >= (double)(l->n[a] - 1))
        return l->n[a] - 1;
    return (size_t)f;
}

void st_locator_free(st_locator *l)
{
    if (!l)
        return;
    free(l->off);
    free(l->idx);
    free(l->tbox);
    free(l);
}

st_status st_locator_new(st_locator **out, const st_tetmesh *m,
                         st_error *err)
{
    *out = NULL;
    if (m->ntets > UINT32_MAX)
        return st_error_set(err, ST_ELIMIT, NULL, 0,
                            "more than %lu tets for point location",
                            (unsigned long)UINT32_MAX);
    st_locator *l = calloc(1, sizeof *l);
    if (!l)
        goto nomem;
    l->m = m;
    if (m->ntets == 0) {
        l->empty = 1;
        *out = l;
        return ST_OK;
    }
    const size_t nt = m->ntets;
    l->tbox = st_malloc_array(nt, 6 * sizeof(double));
    if (!l->tbox)
        goto nomem;
    for (int a = 0; a < 3; a++) {
        l->lo[a] = INFINITY;
        l->hi[a] = -INFINITY;
    }
    for (size_t t = 0; t < nt; t++) {
        double *b = l->tbox + 6 * t;
        for (int a = 0; a < 3; a++) {
            b[a] = INFINITY;
            b[3 + a] = -INFINITY;
        }
        for (int k = 0; k < 4; k++) {
            const double *p = m->xyz + 3 * (size_t)m->tets[4 * t + (size_t)k];
            for (int a = 0; a < 3; a++) {
                b[a] = fmin(b[a], p[a]);
                b[3 + a] = fmax(b[3 + a], p[a]);
            }
        }
        for (int a = 0; a < 3; a++) {
            l->lo[a] = fmin(l->lo[a], b[a]);
            l->hi[a] = fmax(l->hi[a], b[3 + a]);
        }
    }
    /* Cell width: the box volume shared among ~BINS_PER_TET * nt bins,
     * each extent taken at least 1/MAX_BINS_AXIS of the largest so a flat
     * mesh does not shrink the cell to nothing. */
    double ext[3], emax = 0.0;
    for (int a = 0; a < 3; a++) {
        ext[a] = l->hi[a] - l->lo[a];
        emax = fmax(emax, ext[a]);
    }
    double cell = 1.0;
    if (emax > 0.0 && isfinite(emax)) {
        double floor_ext = emax / MAX_BINS_AXIS, vol = 1.0;
        for (int a = 0; a < 3; a++)
            vol *= fmax(ext[a], floor_ext);
        cell = fmax(cbrt(vol / (BINS_PER_TET * (double)nt)), floor_ext);
    }
    l->inv_cell = 1.0 / cell;
    size_t nb = 1;
    for (int a = 0; a < 3; a++) {
        double c = floor(ext[a] * l->inv_cell) + 1.0;
        l->n[a] = c > MAX_BINS_AXIS + 1.0 ? MAX_BINS_AXIS + 1 : (size_t)c;
        nb *= l->n[a];
    }
    l->off = st_calloc_array(nb + 1, sizeof *l->off);
    if (!l->off)
        goto nomem;
    /* Count, prefix-sum, fill in tet order (so lists are sorted). */
    for (int pass = 0; pass < 2; pass++) {
        size_t *fill = NULL;
        if (pass == 1) {
            for (size_t b = 0; b < nb; b++)
                if (st_size_add(&l->off[b + 1], l->off[b + 1], l->off[b]))
                    goto nomem;
            l->idx = st_malloc_array(l->off[nb] ? l->off[nb] : 1,
                                     sizeof *l->idx);
            fill = st_malloc_array(nb, sizeof *fill);
            if (!l->idx || !fill) {
                free(fill);
                goto nomem;
            }
            memcpy(fill, l->off, nb * sizeof *fill);
        }
        for (size_t t = 0; t < nt; t++) {
            const double *b = l->tbox + 6 * t;
            size_t c0[3], c1[3];
            for (int a = 0; a < 3; a++) {
                c0[a] = bin_coord(l, b[a], a);
                c1[a] = bin_coord(l, b[3 + a], a);
            }
            for (size_t z = c0[2]; z <= c1[2]; z++)
                for (size_t y = c0[1]; y <= c1[1]; y++)
                    for (size_t x = c0[0]; x <= c1[0]; x++) {
                        size_t bi = x + l->n[0] * (y + l->n[1] * z);
                        if (pass == 0)
                            l->off[bi + 1]++;
                        else
                            l->idx[fill[bi]++] = (uint32_t)t;
                    }
        }
        free(fill);
    }
    *out = l;
    return ST_OK;
nomem:
    st_locator_free(l);
    return st_error_set(err, ST_ENOMEM, NULL, 0,
                        "out of memory for point location in %zu tets",
                        m->ntets);
}

int64_t st_locator_find(const st_locator *l, const double p[3],
                        st_point_loc *loc)
{
    if (loc)
        *loc = ST_OUTSIDE;
    if (l->empty)
        return -1;
    for (int a = 0; a < 3; a++)
        if (!(p[a] >= l->lo[a] && p[a] <= l->hi[a]))
            return -1;
    size_t bi = bin_coord(l, p[0], 0) +
                l->n[0] * (bin_coord(l, p[1], 1) +
                           l->n[1] * bin_coord(l, p[2], 2));
    const st_tetmesh *m = l->m;
    for (size_t j = l->off[bi]; j < l->off[bi + 1]; j++) {
        uint32_t t = l->idx[j];
        const double *b = l->tbox + 6 * (size_t)t;
        if (p[0] < b[0] || p[1] < b[1] || p[2] < b[2] || p[0] > b[3] ||
            p[1] > b[4] || p[2] > b[5])
            continue;
        const uint32_t *q = m->tets + 4 * (size_t)t;
        st_point_loc r = st_point_in_tet(p, m->xyz + 3 * (size_t)q[0],
                                         m->xyz + 3 * (size_t)q[1],
                                         m->xyz + 3 * (size_t)q[2],
                                         m->xyz + 3 * (size_t)q[3]);
        if (r != ST_OUTSIDE) {
            if (loc)
                *loc = r;
            return (int64_t)t;
        }
    }
    return -1;
}

/* ---- enclosure --------------------------------------------------------- */

/* 1 when p lies in some closed tet. *hint: a tet to try first (the last
 * one found; a soup's consecutive vertices are usually near each other),
 * updated; the answer does not depend on it. */
static int locate_any(const st_locator *l, const double p[3], int64_t *hint)
{
    const st_tetmesh *m = l->m;
    if (*hint >= 0 && (size_t)*hint < m->ntets) {
        const double *b = l->tbox + 6 * (size_t)*hint;
        const uint32_t *q = m->tets + 4 * (size_t)*hint;
        if (p[0] >= b[0] && p[1] >= b[1] && p[2] >= b[2] && p[0] <= b[3] && p[1] <= b[4] &&
            p[2] <= b[5] &&
            st_point_in_tet(p, m->xyz + 3 * (size_t)q[0], m->xyz + 3 * (size_t)q[1],
                            m->xyz + 3 * (size_t)q[2], m->xyz + 3 * (size_t)q[3]) != ST_OUTSIDE)
            return 1;
    }
    int64_t t = st_locator_find(l, p, NULL);
    if (t >= 0)
        *hint = t;
    return t >= 0;
}

/* A tet that holds the whole box lo..hi, or -1 when none is found: the
 * first tet holding the corner lo (st_locator_find), if it holds the
 * other seven corners too (a closed tet is convex; the corners are exact
 * doubles, coordinates of the box's points, tested with
 * st_point_in_tet). Another tet holding lo could hold the box when lo is
 * on a face: missing it only leaves the points to the per-vertex test. */
static int64_t box_tet(const st_locator *l, const double lo[3], const double hi[3])
{
    if (l->empty)
        return -1;
    for (int a = 0; a < 3; a++)
        if (!(lo[a] >= l->lo[a] && hi[a] <= l->hi[a]))
            return -1;
    int64_t t = st_locator_find(l, lo, NULL);
    if (t < 0)
        return -1;
    const double *b = l->tbox + 6 * (size_t)t;
    if (hi[0] > b[3] || hi[1] > b[4] || hi[2] > b[5])
        return -1;
    const st_tetmesh *m = l->m;
    const uint32_t *q = m->tets + 4 * (size_t)t;
    const double *c0 = m->xyz + 3 * (size_t)q[0], *c1 = m->xyz + 3 * (size_t)q[1],
                 *c2 = m->xyz + 3 * (size_t)q[2], *c3 = m->xyz + 3 * (size_t)q[3];
    for (int k = 1; k < 8; k++) {
        const double p[3] = {k & 1 ? hi[0] : lo[0], k & 2 ? hi[1] : lo[1],
                             k & 4 ? hi[2] : lo[2]};
        if (st_point_in_tet(p, c0, c1, c2, c3) == ST_OUTSIDE)
            return -1;
    }
    return t;
}

/* Subtrees of fewer triangles are left to the per-vertex test: a few
 * vertices cost less to locate than a box's eight corners. */
#define WALK_MIN_TRIS 64

/* Nodes down to this depth are split before the parallel walk. */
#define WALK_SPLIT_DEPTH 8

/* The slots order[*first..*end) of node i's subtree (children numbered
 * left then right, holding the lower and upper part of the parent's). */
static void subtree_slots(const st_bvh *b, uint32_t i, size_t *first, size_t *end)
{
    uint32_t a = i, z = i;
    while (b->nodes[a].count == 0)
        a = b->nodes[a].start;
    while (b->nodes[z].count == 0)
        z = b->nodes[z].start + 1;
    *first = b->nodes[a].start;
    *end = (size_t)b->nodes[z].start + b->nodes[z].count;
}

/* Under node `root`: every subtree whose box one tet holds marks the
 * vertices of its triangles inside (vin 1); the rest are left as they
 * are. Writes only 1s (atomically), so the flags are the same whichever
 * thread reaches them. */
static void mark_covered(const st_locator *l, const st_bvh *b, uint32_t root,
                         unsigned char *vin)
{
    uint32_t stack[128];
    int sp = 0;
    stack[sp++] = root;
    while (sp > 0) {
        uint32_t i = stack[--sp];
        const st_bvh_node *n = &b->nodes[i];
        size_t first, end;
        subtree_slots(b, i, &first, &end);
        if (end - first < WALK_MIN_TRIS)
            continue;
        if (box_tet(l, n->lo, n->hi) >= 0) {
            const uint32_t *tris = b->soup->tris;
            for (size_t j = first; j < end; j++)
                for (int k = 0; k < 3; k++) {
                    uint32_t v = tris[3 * (size_t)b->order[j] + (size_t)k];
#pragma omp atomic write
                    vin[v] = 1;
                }
        } else if (n->count == 0 && sp + 2 <= 128) {
            stack[sp++] = n->start + 1;
            stack[sp++] = n->start;
        }
    }
}

/* The nodes at depth WALK_SPLIT_DEPTH (and leaves above it) into *list
 * (room for 2^WALK_SPLIT_DEPTH). */
static void split_nodes(const st_bvh *b, uint32_t i, int depth, uint32_t *list, size_t *n)
{
    if (depth == WALK_SPLIT_DEPTH || b->nodes[i].count != 0) {
        list[(*n)++] = i;
        return;
    }
    split_nodes(b, b->nodes[i].start, depth + 1, list, n);
    split_nodes(b, b->nodes[i].start + 1, depth + 1, list, n);
}

typedef struct cross_ctx {
    const st_soup *s;
    const double *f[3];
    unsigned char *hit;
} cross_ctx;

static int cross_visit(void *ctx, uint32_t tri)
{
    cross_ctx *c = ctx;
    unsigned char done;
#pragma omp atomic read
    done = c->hit[tri];
    if (done)
        return 0;
    const st_soup *s = c->s;
    const uint32_t *v = s->tris + 3 * (size_t)tri;
    if (st_tri_tri_intersect(c->f[0], c->f[1], c->f[2],
                             s->xyz + 3 * (size_t)v[0],
                             s->xyz + 3 * (size_t)v[1],
                             s->xyz + 3 * (size_t)v[2])) {
#pragma omp atomic write
        c->hit[tri] = 1;
    }
    return 0;
}

st_status st_enclosure_compute(st_enclosure *out, const st_tetmesh *m,
                               const st_soup *s, const st_bvh *bvh,
                               unsigned char *vertex_in,
                               unsigned char *tri_crossing, st_error *err)
{
    memset(out, 0, sizeof *out);
    out->fraction_inside = 1.0;
    if (bvh && bvh->soup != s)
        return st_error_set(err, ST_EINPUT, NULL, 0,
                            "enclosure: the BVH is not over this soup");
    st_status rc;
    st_locator *loc = NULL;
    st_bvh *own = NULL;
    unsigned char *vin = vertex_in, *hit = tri_crossing;
    unsigned char *vin_own = NULL, *hit_own = NULL;
    uint32_t *faces = NULL;
    size_t nf = 0;

    if (!vin)
        vin = vin_own = st_malloc_array(s->nverts ? s->nverts : 1, 1);
    if (!hit)
        hit = hit_own = st_malloc_array(s->ntris ? s->ntris : 1, 1);
    if (!vin || !hit) {
        rc = st_error_set(err, ST_ENOMEM, NULL, 0,
                          "out of memory for the enclosure of %zu vertices",
                          s->nverts);
        goto out;
    }
    if ((rc = st_locator_new(&loc, m, err)))
        goto out;

    /* (a) used vertices in the closed union of the tets: first those of
     * the BVH subtrees whose box lies in one tet (most of a large soup
     * under a coarse mesh), then each other one through the locator. */
    memset(vin, 2, s->nverts);
    for (size_t i = 0; i < 3 * s->ntris; i++)
        vin[s->tris[i]] = 0;
    if (!bvh && s->ntris > 0 && m->ntets > 0 && (rc = st_bvh_build(&own, s, err)))
        goto out;
    if (!bvh)
        bvh = own;
    if (bvh && m->ntets > 0) {
        uint32_t split[1u << WALK_SPLIT_DEPTH];
        size_t ns = 0;
        split_nodes(bvh, 0, 0, split, &ns);
        const long long n = (long long)ns;
#pragma omp parallel for schedule(dynamic, 1)
        for (long long k = 0; k < n; k++)
            mark_covered(loc, bvh, split[k], vin);
    }
    size_t used = 0, inside = 0;
    {
        const long long nv = (long long)s->nverts;
#pragma omp parallel reduction(+ : used, inside)
        {
            int64_t hint = -1;   /* per thread */
#pragma omp for schedule(dynamic, 1024)
            for (long long i = 0; i < nv; i++) {
                if (vin[i] == 2)
                    continue;
                used++;
                int in = vin[i] == 1 || locate_any(loc, s->xyz + 3 * (size_t)i, &hint);
                vin[i] = (unsigned char)in;
                inside += (size_t)in;
            }
        }
    }
    out->vertices = used;
    out->vertices_inside = inside;
    out->vertices_outside = used - inside;
    out->fraction_inside = used ? (double)inside / (double)used : 1.0;

    /* (b) soup triangles meeting a boundary face. */
    memset(hit, 0, s->ntris);
    if ((rc = st_tetmesh_boundary(m, &faces, NULL, &nf, err)))
        goto out;
    out->boundary_faces = nf;
    if (nf > 0 && s->ntris > 0) {
        const long long n = (long long)nf;
#pragma omp parallel for schedule(dynamic, 16)
        for (long long f = 0; f < n; f++) {
            cross_ctx c;
            c.s = s;
            c.hit = hit;
            for (int k = 0; k < 3; k++)
                c.f[k] = m->xyz + 3 * (size_t)faces[3 * (size_t)f + (size_t)k];
            /* nodes pruned by the face itself: a face is much larger
             * than the soup's triangles, and its box holds many more
             * of them than it meets (every triangle meeting it is
             * visited, so the flags are those of a box query) */
            st_bvh_query_tri(bvh, c.f[0], c.f[1], c.f[2], cross_visit, &c);
        }
    }
    size_t crossing = 0;
    for (size_t t = 0; t < s->ntris; t++)
        crossing += hit[t];
    out->crossing_triangles = crossing;
    out->encloses = out->vertices_outside == 0 && crossing == 0;
    rc = ST_OK;
out:
    free(faces);
    free(vin_own);
    free(hit_own);
    st_locator_free(loc);
    st_bvh_free(own);
    return rc;
}

/* st_enclosure_count (enclose.h): the counts of st_enclosure_compute. */
st_status st_enclosure_count(const st_tetmesh *m, const st_soup *s,
                             const st_bvh *bvh, size_t *verts_outside,
                             size_t *tris_crossing, st_error *err)
{
    st_enclosure e;
    st_status rc = st_enclosure_compute(&e, m, s, bvh, NULL, NULL, err);
    /* On error SIZE_MAX, which no caller can read as "encloses". */
    if (verts_outside)
        *verts_outside = rc ? SIZE_MAX : e.vertices_outside;
    if (tris_crossing)
        *tris_crossing = rc ? SIZE_MAX : e.crossing_triangles;
    return rc;
}
