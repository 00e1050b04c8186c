/*
 * symmetry.c - mirror planes and rotation axes of a soup's surviving
 * surface, and its screw motions (see symmetry.h for the algorithm).
 *
 * Reference: N. J. Mitra, L. J. Guibas, M. Pauly, "Partial and approximate
 * symmetry detection for 3D geometry", SIGGRAPH 2006 (the pair voting).
 *
 * Nothing here decides geometry for the output: a symmetry is evidence,
 * measured by its support, and every measure is a count of samples, so
 * doubles only rank and threshold.
 */
#include "souptet/symmetry.h"
#include "../base/fpenv.h"
#include "souptet/edges.h"
#include "souptet/geom.h"
#include "souptet/mem.h"
#include "../base/unionfind.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define PI 3.14159265358979323846
/* Normals of a pair within this angle count as mapped onto each other
 * (the vote), and an image's normal within MATCH_DEG of the triangle it
 * lands on (the support). */
#define VOTE_COS 0.9659258262890683   /* cos 15 degrees */
#define MATCH_COS 0.8660254037844387  /* cos 30 degrees */
#define SAME_COS 0.9993908270190958   /* cos 2 degrees: one plane or line */
#define VOTE_PAIRS 40000
#define VOTE_DIR_BINS 24              /* per cube face side */
#define VOTE_CANDIDATES 16
#define VOTE_PEAKS 8                  /* more, from the windows (vote_mirrors) */
#define REFINE_ROUNDS 6
#define REFINE_REACH 3.0              /* tolerances */
/* A peak's plane (the mean of a window of cells, a few degrees wide)
 * starts with up to REFINE_COARSE rounds that match within REFINE_WIDE
 * tolerances: a plane a few degrees off moves the images of the far
 * samples by more than REFINE_REACH, and only the samples near where it
 * crosses the true plane would match. */
#define REFINE_COARSE 3
#define REFINE_WIDE 8.0
#define REFINE_COARSE_STRIDE (4 * REFINE_STRIDE) /* the wide rounds: every 16th sample */
/* The rounds use every REFINE_STRIDE-th sample (a plane from some
 * hundreds of midpoints), and stop once the plane moves by less than
 * REFINE_STILL tolerances and turns by less than about REFINE_STILL
 * radians. */
#define REFINE_STRIDE 4
#define REFINE_STILL 1e-3
/* Candidates are screened on every SCREEN-th sample (and the orders of an
 * axis first on every 4 SCREEN-th); below SCREEN_SHARE of the share they
 * must reach there, they are not measured on all. */
#define SCREEN 8
#define SCREEN_SHARE 0.5

st_symmetry_params st_symmetry_params_default(void)
{
    st_symmetry_params p = {ST_SYMMETRY_DEFAULT_SAMPLES, 0.0,
                            ST_SYMMETRY_DEFAULT_MIN_SUPPORT,
                            ST_SYMMETRY_DEFAULT_MAX_ORDER};
    return p;
}

/* ---- maps ----------------------------------------------------------------- */

static void normalize(double v[3])
{
    double l = st_norm3(v);
    if (l > 0.0)
        for (int a = 0; a < 3; a++)
            v[a] /= l;
}

/* A symmetry by one angle, its turn's cosine and sine made once: the
 * counts apply one map to every sample, and the two library calls cost
 * about as much as the rest of the map. map_apply is st_symmetry_apply's
 * arithmetic on the same doubles. */
typedef struct sym_map {
    const st_symmetry *y;
    double angle, c, s;
} sym_map;

static sym_map map_of(const st_symmetry *y, double angle)
{
    sym_map m = {y, angle, 1.0, 0.0};
    if (y->kind != ST_SYMMETRY_MIRROR) {
        m.c = cos(angle);
        m.s = sin(angle);
    }
    return m;
}

static void map_apply(const sym_map *m, const double x[3], int w, double out[3])
{
    const st_symmetry *y = m->y;
    const double *n = y->dir;
    double r[3];
    for (int a = 0; a < 3; a++)
        r[a] = x[a] - (w ? y->point[a] : 0.0);
    if (y->kind == ST_SYMMETRY_MIRROR) {
        double d = 2.0 * st_dot3(r, n);
        for (int a = 0; a < 3; a++)
            r[a] -= d * n[a];
    } else {
        /* Rodrigues */
        double c = m->c, s = m->s, k[3], d = st_dot3(n, r);
        st_cross3(k, n, r);
        for (int a = 0; a < 3; a++)
            r[a] = r[a] * c + k[a] * s + n[a] * d * (1.0 - c);
        if (y->kind == ST_SYMMETRY_HELIX && w)
            for (int a = 0; a < 3; a++)
                r[a] += n[a] * m->angle * y->pitch / (2.0 * PI);
    }
    for (int a = 0; a < 3; a++)
        out[a] = r[a] + (w ? y->point[a] : 0.0);
}

void st_symmetry_apply(const st_symmetry *y, double angle, const double x[3],
                       int w, double out[3])
{
    const sym_map m = map_of(y, angle);
    map_apply(&m, x, w, out);
}

void st_symmetry_describe(const st_symmetry *y, char *buf, size_t size)
{
    if (y->kind == ST_SYMMETRY_MIRROR)
        snprintf(buf, size,
                 "mirror plane through (%.6g, %.6g, %.6g), normal (%.4f, "
                 "%.4f, %.4f), support %.3f, contradiction %.3f",
                 y->point[0], y->point[1], y->point[2], y->dir[0], y->dir[1],
                 y->dir[2], y->support, y->contradiction);
    else if (y->kind == ST_SYMMETRY_HELIX)
        snprintf(buf, size,
                 "helix axis through (%.6g, %.6g, %.6g), direction (%.4f, "
                 "%.4f, %.4f), pitch %.6g (%s-handed), support %.3f",
                 y->point[0], y->point[1], y->point[2], y->dir[0], y->dir[1],
                 y->dir[2], fabs(y->pitch), y->pitch >= 0 ? "right" : "left",
                 y->support);
    else if (y->order == 0)
        snprintf(buf, size,
                 "rotation axis through (%.6g, %.6g, %.6g), direction "
                 "(%.4f, %.4f, %.4f), continuous, support %.3f",
                 y->point[0], y->point[1], y->point[2], y->dir[0], y->dir[1],
                 y->dir[2], y->support);
    else
        snprintf(buf, size,
                 "rotation axis through (%.6g, %.6g, %.6g), direction "
                 "(%.4f, %.4f, %.4f), order %d, support %.3f",
                 y->point[0], y->point[1], y->point[2], y->dir[0], y->dir[1],
                 y->dir[2], y->order, y->support);
}

/* ---- samples -------------------------------------------------------------- */

typedef struct samples {
    size_t n;
    double *p;       /* 3n */
    double *nrm;     /* 3n, unit */
    double c[3];     /* area centroid */
    double area;     /* the soup's (its finite triangles') */
    double axes[3][3]; /* principal axes (rows), unit */
} samples;

static uint64_t mix64(uint64_t x)
{
    x ^= x >> 30;
    x *= 0xbf58476d1ce4e5b9ULL;
    x ^= x >> 27;
    x *= 0x94d049bb133111ebULL;
    return x ^ (x >> 31);
}

/* Eigenvectors of the symmetric 3x3 m (Jacobi), as rows of v. */
static void eigen3(double m[3][3], double v[3][3])
{
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            v[i][j] = i == j;
    for (int sweep = 0; sweep < 50; sweep++) {
        double off = fabs(m[0][1]) + fabs(m[0][2]) + fabs(m[1][2]);
        if (off == 0.0)
            break;
        for (int p = 0; p < 2; p++)
            for (int q = p + 1; q < 3; q++) {
                if (m[p][q] == 0.0)
                    continue;
                double th = 0.5 * (m[q][q] - m[p][p]) / m[p][q];
                double t = (th >= 0 ? 1.0 : -1.0) /
                           (fabs(th) + sqrt(th * th + 1.0));
                double c = 1.0 / sqrt(t * t + 1.0), s = t * c;
                for (int k = 0; k < 3; k++) {
                    double a = m[k][p], b = m[k][q];
                    m[k][p] = c * a - s * b;
                    m[k][q] = s * a + c * b;
                }
                for (int k = 0; k < 3; k++) {
                    double a = m[p][k], b = m[q][k];
                    m[p][k] = c * a - s * b;
                    m[q][k] = s * a + c * b;
                }
                for (int k = 0; k < 3; k++) {
                    double a = v[p][k], b = v[q][k];
                    v[p][k] = c * a - s * b;
                    v[q][k] = s * a + c * b;
                }
            }
    }
}

static int samples_make(samples *S, const st_soup *s, size_t want)
{
    memset(S, 0, sizeof *S);
    double *cum = st_malloc_array(s->ntris + 1, sizeof *cum);
    if (!cum)
        return -1;
    cum[0] = 0.0;
    for (size_t t = 0; t < s->ntris; t++) {
        const uint32_t *v = s->tris + 3 * t;
        double u[3], w[3], n[3];
        st_sub3(u, s->xyz + 3 * (size_t)v[1], s->xyz + 3 * (size_t)v[0]);
        st_sub3(w, s->xyz + 3 * (size_t)v[2], s->xyz + 3 * (size_t)v[0]);
        st_cross3(n, u, w);
        double a = 0.5 * st_norm3(n);
        cum[t + 1] = cum[t] + (isfinite(a) ? a : 0.0);
    }
    double total = cum[s->ntris];
    S->area = total;
    if (!(total > 0.0)) {
        free(cum);
        return 0;
    }
    S->p = st_malloc_array(3 * want, sizeof *S->p);
    S->nrm = st_malloc_array(3 * want, sizeof *S->nrm);
    if (!S->p || !S->nrm) {
        free(cum);
        return -1;
    }
    size_t t = 0;
    for (size_t k = 0; k < want; k++) {
        double target = total * ((double)k + 0.5) / (double)want;
        while (t + 1 < s->ntris && cum[t + 1] <= target)
            t++;
        const uint32_t *v = s->tris + 3 * t;
        const double *a = s->xyz + 3 * (size_t)v[0],
                     *b = s->xyz + 3 * (size_t)v[1],
                     *c = s->xyz + 3 * (size_t)v[2];
        /* a point of the triangle from two hashed uniforms */
        uint64_t h = mix64(k + 1);
        double r1 = (double)(h >> 11) * 0x1.0p-53,
               r2 = (double)(mix64(h) >> 11) * 0x1.0p-53;
        if (r1 + r2 > 1.0) {
            r1 = 1.0 - r1;
            r2 = 1.0 - r2;
        }
        double u[3], w[3], n[3];
        st_sub3(u, b, a);
        st_sub3(w, c, a);
        st_cross3(n, u, w);
        normalize(n);
        for (int x = 0; x < 3; x++) {
            S->p[3 * S->n + x] = a[x] + r1 * u[x] + r2 * w[x];
            S->nrm[3 * S->n + x] = n[x];
        }
        S->n++;
    }
    free(cum);
    double m[3][3] = {{0}};
    for (size_t k = 0; k < S->n; k++)
        for (int x = 0; x < 3; x++)
            S->c[x] += S->p[3 * k + x] / (double)S->n;
    for (size_t k = 0; k < S->n; k++) {
        double d[3];
        st_sub3(d, S->p + 3 * k, S->c);
        for (int x = 0; x < 3; x++)
            for (int y = 0; y < 3; y++)
                m[x][y] += d[x] * d[y];
    }
    eigen3(m, S->axes);
    return 0;
}

static void samples_free(samples *S)
{
    free(S->p);
    free(S->nrm);
}

/* ---- the near grid and the support ---------------------------------------- */

/* On a CAD part whose long, thin triangles lie slanted to the axes (a
 * gear's teeth, a screw's thread), the BVH's boxes overlap far beyond the
 * triangles, and a query within a tolerance scans most of the leaves
 * (pinion-symholes: about 25,000 instructions a query, 96 % of the
 * detection). So the queries within GRID_REACH tolerances go first to a
 * grid of cells GRID_CELL tolerances wide, each listing every triangle
 * that comes within GRID_REACH tolerances of it (from pieces of the
 * triangle no longer than a cell, each piece's box grown by the reach).
 * A query scans its cell's list with the BVH's own distance
 * (st_point_triangle_dist2, the same arguments): the least distance, its
 * triangle and point are the BVH's whenever that least is clear. Where
 * another triangle comes within GRID_TIE of it (a shared edge or corner:
 * the BVH takes the first it meets), or it lies within GRID_TIE of the
 * reach (the BVH's pruning by boxes then decides), the query goes to the
 * BVH: so every answer is the BVH's. Not built (the BVH alone) when the
 * lists would be long (a dense scan, whose BVH boxes are tight) or the
 * grid large. */
#define GRID_REACH REFINE_REACH
#define GRID_CELL 3.0
#define GRID_MIN_AREA 4.0    /* mean triangle area, tolerances squared */
#define GRID_TIE 1e-6
#define GRID_MAX_CELLS (1L << 22)
#define GRID_MAX_LIST 24.0   /* mean entries per filled cell, at most */
#define GRID_MAX_DEPTH 40    /* of the pieces' bisection */

typedef struct near_grid {
    double lo[3], h, reach, slack; /* slack: rounding units of the soup's size */
    long dim[3];
    uint32_t *start;   /* dim[0] dim[1] dim[2] + 1 offsets into tri; NULL: no grid */
    uint32_t *tri;
    double *tbox;      /* 6 per triangle: its box */
} near_grid;


/* Each triangle's boundary edges, made on the first count of
 * contradictions (rims_need): only candidates whose share falls between
 * accepted()'s two shares read them, and the soup's edges cost as much as
 * a few candidates' refinement (dragon_res3: 53 M instructions of the
 * detection's 492 M, where no candidate needed them). */
typedef struct rims {
    uint8_t *rim;    /* per triangle: bit j when its edge j (corners j,
                        j + 1) is a boundary edge (one triangle) */
    int tried;       /* rim_make ran (rim NULL after: it failed, err says) */
    st_error err;
} rims;

typedef struct ctx {
    const st_soup *s;
    const st_bvh *bvh;
    const samples *S;
    double tol;
    double *tn;      /* unit normal per soup triangle */
    st_tri_frame *fr; /* per soup triangle: its frame for the distances
                         (st_bvh_nearest_framed, the grid's scans) */
    rims *R;         /* made when first needed (rims_need) */
    near_grid grid;
} ctx;

/* The cells of the box [lo, hi] grown by the reach, as index ranges. */
static void grid_range(const near_grid *G, const double lo[3], const double hi[3],
                       long a[3], long b[3])
{
    for (int k = 0; k < 3; k++) {
        const double g = G->reach * (1.0 + GRID_TIE) + G->slack;
        a[k] = (long)floor((lo[k] - g - G->lo[k]) / G->h);
        b[k] = (long)floor((hi[k] + g - G->lo[k]) / G->h);
        a[k] = a[k] < 0 ? 0 : a[k];
        b[k] = b[k] >= G->dim[k] ? G->dim[k] - 1 : b[k];
    }
}

/* The build's pairs (cell, triangle), each once. */
typedef struct grid_pairs {
    uint64_t *v;    /* cell << 32 | triangle */
    size_t n, cap;
    int failed;
} grid_pairs;

/* x appended to P (P->failed when memory is short: nothing more goes in). */
static void pairs_push(grid_pairs *P, uint64_t x)
{
    if (P->n == P->cap && !P->failed) {
        /* doubling: amortized constant */
        uint64_t *grown = st_realloc_array(P->v, P->cap < 4096 ? 4096 : 2 * P->cap, sizeof *grown);
        P->failed = !grown;
        P->v = grown ? grown : P->v;
        P->cap = grown ? (P->cap < 4096 ? 4096 : 2 * P->cap) : P->cap;
    }
    if (!P->failed)
        P->v[P->n++] = x;
}

/* The cells one triangle goes into, gathered by column (grid_put): per
 * column (i, j), from the least to the greatest k its pieces' grown boxes
 * cover there. That is the cells the boxes cover (each of them marked
 * cell by cell before: 74 M instructions of anchor-largeholes' 221 M
 * detection), at a column's cost instead of a box's, and the same lists
 * but where a slanted piece's box reaches a column the triangle itself
 * does not come near, leaving a gap in its range (then filled): on the
 * 281 models, damaged inputs and CGAL demo files at 1/128, 17 of 194
 * grids differ, by at most 21 more entries. A list that holds more answers the same
 * (nearest: every triangle within the reach of the cell is still listed,
 * and a listed one counts only by its own distance). */
typedef struct grid_cols {
    uint32_t *stamp;   /* per column: the last triangle + 1 that met it */
    long *lo, *hi;     /* per column: its range of k for that triangle */
    size_t *touched;   /* the columns the triangle met, in order met */
    size_t n;
} grid_cols;

/* Triangle t (piece x of it) into the columns its piece's grown box
 * meets: the box's k range joined to each column's (K). */
static void grid_put(near_grid *G, grid_cols *K, uint32_t t, const double *x[3], int depth)
{
    double e[3];
    int m = 0;
    for (int k = 0; k < 3; k++) {
        double d[3];
        st_sub3(d, x[(k + 1) % 3], x[k]);
        e[k] = st_dot3(d, d);
        m = e[k] > e[m] ? k : m;
    }
    if (e[m] > G->h * G->h && depth < GRID_MAX_DEPTH) {
        /* bisect the longest edge, x[m] x[m + 1] */
        double mid[3];
        const double *p = x[m], *q = x[(m + 1) % 3], *r = x[(m + 2) % 3];
        for (int k = 0; k < 3; k++)
            mid[k] = 0.5 * (p[k] + q[k]);
        const double *one[3] = {p, mid, r}, *two[3] = {mid, q, r};
        grid_put(G, K, t, one, depth + 1);
        grid_put(G, K, t, two, depth + 1);
        return;
    }
    double lo[3], hi[3];
    long a[3], b[3];
    for (int k = 0; k < 3; k++) {
        lo[k] = fmin(x[0][k], fmin(x[1][k], x[2][k]));
        hi[k] = fmax(x[0][k], fmax(x[1][k], x[2][k]));
    }
    grid_range(G, lo, hi, a, b);
    for (long i = a[0]; i <= b[0]; i++)
        for (long j = a[1]; j <= b[1]; j++) {
            const size_t c = (size_t)(i * G->dim[1] + j);
            if (K->stamp[c] != t + 1) {
                K->stamp[c] = t + 1;
                K->lo[c] = a[2];
                K->hi[c] = b[2];
                K->touched[K->n++] = c;
            } else {
                K->lo[c] = a[2] < K->lo[c] ? a[2] : K->lo[c];
                K->hi[c] = b[2] > K->hi[c] ? b[2] : K->hi[c];
            }
        }
}

/* Triangle t's cells (gathered in K by grid_put) into the pairs. */
static void grid_emit(const near_grid *G, grid_cols *K, grid_pairs *P, uint32_t t)
{
    for (size_t n = 0; n < K->n; n++) {
        const size_t c = K->touched[n];
        for (long k = K->lo[c]; k <= K->hi[c]; k++)
            pairs_push(P, (uint64_t)(c * (size_t)G->dim[2] + (size_t)k) << 32 | t);
    }
    K->n = 0;
}

static void grid_free(near_grid *G)
{
    free(G->start);
    free(G->tri);
    free(G->tbox);
    G->start = G->tri = NULL;
    G->tbox = NULL;
}

/* Each triangle's box into G->tbox, the soup's into lo, hi. */
static void grid_boxes(near_grid *G, const st_soup *s, double lo[3], double hi[3])
{
    for (int k = 0; k < 3; k++) {
        lo[k] = INFINITY;
        hi[k] = -INFINITY;
    }
    for (size_t t = 0; t < s->ntris; t++) {
        const double *x[3];
        double *b = G->tbox + 6 * t;
        for (int v = 0; v < 3; v++)
            x[v] = s->xyz + 3 * (size_t)s->tris[3 * t + v];
        for (int k = 0; k < 3; k++) {
            b[k] = fmin(x[0][k], fmin(x[1][k], x[2][k]));
            b[k + 3] = fmax(x[0][k], fmax(x[1][k], x[2][k]));
            lo[k] = fmin(lo[k], b[k]);
            hi[k] = fmax(hi[k], b[k + 3]);
        }
    }
}

/* The lists from the pairs (sorted by cell: the triangles of a cell in
 * their order); 0 when they would be long on average, or memory short. */
static int grid_lists(near_grid *G, grid_pairs *P, size_t ncell)
{
    G->start = st_calloc_array(ncell + 1, sizeof *G->start);
    G->tri = st_malloc_array(P->n ? P->n : 1, sizeof *G->tri);
    if (!G->start || !G->tri)
        return 0;
    for (size_t i = 0; i < P->n; i++)
        G->start[(P->v[i] >> 32) + 1]++;
    size_t filled = 0;
    for (size_t c = 0; c < ncell; c++) {
        filled += G->start[c + 1] > 0;
        G->start[c + 1] += G->start[c];
    }
    if ((double)P->n > GRID_MAX_LIST * (double)filled)
        return 0;
    /* the pairs come by triangle: placed in order, each cell's list is
     * sorted by triangle */
    for (size_t i = 0; i < P->n; i++)
        G->tri[G->start[P->v[i] >> 32]++] = (uint32_t)P->v[i];
    for (size_t c = ncell; c > 0; c--)
        G->start[c] = G->start[c - 1];
    G->start[0] = 0;
    return 1;
}

/* The grid for tolerance tol, or none (G->start NULL: the queries go to
 * the BVH) when its lists would be long (mean triangle area below
 * GRID_MIN_AREA tolerances squared: a fine mesh, whose BVH boxes are
 * tight; or over GRID_MAX_LIST entries a cell), the grid large, or memory
 * short. */
static void grid_make(near_grid *G, const st_soup *s, double tol, double area)
{
    memset(G, 0, sizeof *G);
    if (s->ntris == 0 || s->ntris >= UINT32_MAX ||
        !(area >= GRID_MIN_AREA * tol * tol * (double)s->ntris))
        return;
    double lo[3], hi[3];
    G->tbox = st_malloc_array(6 * s->ntris, sizeof *G->tbox);
    if (!G->tbox)
        return;
    grid_boxes(G, s, lo, hi);
    double big = 0.0, cells = 1.0;
    for (int k = 0; k < 3; k++)
        big = fmax(big, fmax(fabs(lo[k]), fabs(hi[k])));
    G->h = GRID_CELL * tol;
    G->reach = GRID_REACH * tol;
    G->slack = ldexp(big, -40);
    for (int k = 0; k < 3; k++) {
        G->lo[k] = lo[k] - G->reach - G->h;
        G->dim[k] = (long)floor((hi[k] + G->reach + G->h - G->lo[k]) / G->h) + 1;
        cells *= (double)G->dim[k];
    }
    if (!isfinite(cells) || cells > (double)GRID_MAX_CELLS) {
        grid_free(G);
        return;
    }
    const size_t ncell = (size_t)cells;
    grid_pairs P = {NULL, 0, 0, 0};
    const size_t ncol = (size_t)G->dim[0] * (size_t)G->dim[1];
    grid_cols K = {st_calloc_array(ncol, sizeof *K.stamp), st_malloc_array(ncol, sizeof *K.lo),
                   st_malloc_array(ncol, sizeof *K.hi), st_malloc_array(ncol, sizeof *K.touched), 0};
    P.failed = !K.stamp || !K.lo || !K.hi || !K.touched;
    for (size_t t = 0; t < s->ntris && !P.failed; t++) {
        const double *x[3];
        for (int k = 0; k < 3; k++)
            x[k] = s->xyz + 3 * (size_t)s->tris[3 * t + k];
        grid_put(G, &K, (uint32_t)t, x, 0);
        grid_emit(G, &K, &P, (uint32_t)t);
    }
    free(K.stamp);
    free(K.lo);
    free(K.hi);
    free(K.touched);
    if (P.failed || !grid_lists(G, &P, ncell))
        grid_free(G);
    free(P.v);
}

/* st_bvh_nearest(C->bvh, p, reach * reach, tri, closest), answered by the
 * grid where it can be (see above), else by the BVH. */
static double nearest(const ctx *C, const double p[3], double reach, int64_t *tri,
                      double closest[3])
{
    const near_grid *G = &C->grid;
    const double r2 = reach * reach;
    if (!G->start || !(reach <= G->reach))
        return st_bvh_nearest_framed(C->bvh, C->fr, p, r2, tri, closest);
    long c[3];
    for (int k = 0; k < 3; k++) {
        const double f = floor((p[k] - G->lo[k]) / G->h);
        if (!(f >= 0.0 && f < (double)G->dim[k])) {
            *tri = -1; /* beyond the grown box of every triangle */
            return r2;
        }
        c[k] = (long)f;
    }
    const size_t cell = (size_t)((c[0] * G->dim[1] + c[1]) * G->dim[2] + c[2]);
    const double lim = reach * (1.0 + GRID_TIE) + G->slack;
    double best = INFINITY, second = INFINITY, q[3], bq[3];
    int64_t bt = -1;
    for (uint32_t i = G->start[cell]; i < G->start[cell + 1]; i++) {
        const uint32_t t = G->tri[i];
        const double *b = G->tbox + 6 * (size_t)t;
        double d2 = 0.0;
        for (int k = 0; k < 3; k++) {
            const double d = p[k] < b[k] ? b[k] - p[k] : p[k] > b[k + 3] ? p[k] - b[k + 3] : 0.0;
            d2 += d * d;
        }
        if (d2 > lim * lim)
            continue;
        const uint32_t *v = C->s->tris + 3 * (size_t)t;
        d2 = st_point_triangle_dist2_framed(p, C->s->xyz + 3 * (size_t)v[0],
                                            C->s->xyz + 3 * (size_t)v[1],
                                            C->s->xyz + 3 * (size_t)v[2], C->fr + t, q);
        if (d2 < best) {
            second = best;
            best = d2;
            bt = t;
            memcpy(bq, q, sizeof q);
        } else if (d2 < second) {
            second = d2;
        }
    }
    const double s2 = G->slack * G->slack;
    if (!(best < r2 + GRID_TIE * r2 + s2)) {
        *tri = -1; /* every triangle of the list clearly beyond the reach */
        return r2;
    }
    if (second <= best + GRID_TIE * best + s2 || !(best < r2 - GRID_TIE * r2 - s2))
        return st_bvh_nearest_framed(C->bvh, C->fr, p, r2, tri, closest);
    *tri = bt;
    if (closest)
        memcpy(closest, bq, sizeof bq);
    return best;
}

/* Whether the image (q, nq) lands on the soup within reach with a
 * compatible normal; *closest gets the nearest point, *tri its triangle
 * (-1: nothing within reach). */
static int lands_tri(const ctx *C, const double q[3], const double nq[3],
                     double reach, double closest[3], int64_t *tri)
{
    double d2 = nearest(C, q, reach, tri, closest);
    if (*tri < 0)
        return 0;
    return d2 <= C->tol * C->tol &&
           fabs(st_dot3(nq, C->tn + 3 * (size_t)*tri)) >= MATCH_COS;
}

static int lands_at(const ctx *C, const double q[3], const double nq[3],
                    double reach, double closest[3], int64_t *tri)
{
    double d2 = nearest(C, q, reach, tri, closest);
    (void)d2;
    if (*tri < 0)
        return 0;
    return fabs(st_dot3(nq, C->tn + 3 * (size_t)*tri)) >= MATCH_COS;
}

/* Each triangle's boundary edges (R->rim), read on the welded soup. */
static st_status rim_make(rims *R, const st_soup *s, st_error *err)
{
    st_soup_edges e;
    st_status rc = st_soup_edges_build(&e, s, err);
    if (rc)
        return rc;
    R->rim = st_calloc_array(s->ntris ? s->ntris : 1, sizeof *R->rim);
    if (!R->rim) {
        st_soup_edges_free(&e);
        return st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory for the soup's rims");
    }
    for (size_t i = 0; i < e.nhalf;) {
        size_t end = st_soup_edges_run_end(&e, i);
        if (end - i == 1) {
            uint32_t t = e.he[i].t, lo = (uint32_t)(e.he[i].key >> 32),
                     hi = (uint32_t)e.he[i].key;
            const uint32_t *v = s->tris + 3 * (size_t)t;
            for (int j = 0; j < 3; j++) {
                uint32_t a = e.weld[v[j]], b = e.weld[v[(j + 1) % 3]];
                if ((a == lo && b == hi) || (a == hi && b == lo))
                    R->rim[t] |= (uint8_t)(1u << j);
            }
        }
        i = end;
    }
    st_soup_edges_free(&e);
    return ST_OK;
}

/* The rims made once, before the first count that reads them (callers
 * may run in measure_mirrors' threads: one makes them, the others wait).
 * A failure leaves them NULL (no rims: the count goes on, every nearest
 * point inside) and st_symmetry_detect returns its error. */
static void rims_need(const ctx *C)
{
    rims *R = C->R;
#pragma omp critical(st_symmetry_rims)
    {
        if (!R->tried) {
            R->tried = 1;
            if (rim_make(R, C->s, &R->err) != ST_OK) {
                free(R->rim);
                R->rim = NULL;
            }
        }
    }
}

/* Whether point c of triangle t lies on one of its boundary edges: the
 * soup ends there, so what lies beyond it is unknown, not absent. */
static int on_rim(const ctx *C, int64_t t, const double c[3])
{
    uint8_t m = C->R->rim ? C->R->rim[t] : 0;
    if (!m)
        return 0;
    const uint32_t *v = C->s->tris + 3 * (size_t)t;
    for (int j = 0; j < 3; j++) {
        if (!(m >> j & 1))
            continue;
        const double *a = C->s->xyz + 3 * (size_t)v[j],
                     *b = C->s->xyz + 3 * (size_t)v[(j + 1) % 3];
        double e[3], x[3];
        st_sub3(e, b, a);
        double d2 = st_point_segment_dist2(c, a, b, x);
        if (d2 <= 1e-12 * st_dot3(e, e))
            return 1;
    }
    return 0;
}

/* What the images of the informative samples (below) find. verified:
 * on the soup within the tolerance, with a compatible normal. The rest,
 * with `full`, by the soup's nearest point to the image: unverifiable
 * when it lies on a boundary edge (a hole's rim: the image lands where
 * the damage is, and the soup cannot say what was there); contradicted
 * when it lies inside the surface: the soup was seen all around that
 * place, and is not where the map puts it (the image is in open space or
 * across the surface). A closed soup has no rims: there everything not
 * verified is contradicted. */
typedef struct tally {
    long all, informative, verified, contradicted;
} tally;

/* accepted()'s shares (below) */
#define MIN_VERIFIED 0.4
#define MAX_CONTRA ST_SYMMETRY_MAX_CONTRADICTION

/* The contradicted share of what the soup could check (verified or
 * contradicted); 1 when it could check nothing. */
static double contradiction(const tally *t)
{
    long seen = t->verified + t->contradicted;
    return seen ? (double)t->contradicted / (double)seen : 1.0;
}

/* The share of every stride-th sample whose image lands on the soup,
 * among the informative ones: those the map moves by more than the
 * tolerance, not along their own surface (the displacement at least
 * INFORM_SIN off the tangent plane). A surface sliding along itself (a
 * bar's sides under a mirror across the bar, a cylinder turned a little)
 * lands on itself under any such map and says nothing about it. Fewer
 * than MIN_INFORM of the samples informative: 0. */
#define INFORM_SIN 0.25881904510252074 /* sin 15 degrees */
#define MIN_INFORM 0.1
/* measure_need's blocks, in strided samples */
#define MEASURE_BLOCK 32

/* Whether accepted()'s contradiction bound is settled with c of the
 * contradictions counted and at most `rest` samples to come, the
 * verified count being known's: the share contradicted only grows with
 * the count (the same rounded division of a larger quotient), so above
 * MAX_CONTRA with c it stays above, and at most MAX_CONTRA with all the
 * rest contradicted it stays at most. Either way c gives accepted()'s
 * answer. */
static int contra_decided(const tally *known, long c, long rest)
{
    const tally lo = {0, 0, known->verified, c}, hi = {0, 0, known->verified, c + rest};
    return contradiction(&lo) > MAX_CONTRA || contradiction(&hi) <= MAX_CONTRA;
}
/* One block's counts (measure_run): samples, informative, verified,
 * contradicted. */
typedef struct block_count {
    long a, m, h, c;
} block_count;

/* The strided samples j0 <= j < j1 under y: what their images find
 * (measure_run). */
static block_count measure_block(const ctx *C, const st_symmetry *y, double angle,
                                 size_t stride, int full, size_t j0, size_t j1)
{
    const samples *S = C->S;
    const sym_map map = map_of(y, angle);
    block_count r = {0, 0, 0, 0};
    for (size_t j = j0; j < j1; j++) {
        const size_t k = j * stride;
        double q[3], nq[3], cl[3], d[3];
        r.a++;
        map_apply(&map, S->p + 3 * k, 1, q);
        st_sub3(d, q, S->p + 3 * k);
        double l = st_norm3(d);
        if (!(l > C->tol) || fabs(st_dot3(d, S->nrm + 3 * k)) < INFORM_SIN * l)
            continue;
        map_apply(&map, S->nrm + 3 * k, 0, nq);
        int64_t t;
        int hit = lands_tri(C, q, nq, C->tol, cl, &t);
        r.h += hit;
        if (full && !hit) {
            st_bvh_nearest_framed(C->bvh, C->fr, q, INFINITY, &t, cl);
            r.c += t >= 0 && !on_rim(C, t, cl);
        }
        r.m++;
    }
    return r;
}

/* The blocks' counts summed in block order (measure_run), and the
 * block end where the stop rule fired, if it did. */
typedef struct block_sums {
    block_count sum;  /* of blocks [0, front) */
    size_t front;     /* the first block not yet summed */
    int stop;         /* 0; 1: the share is below need; 2: the
                       * contradiction is decided */
} block_sums;

/* Block b's counts done: the blocks done in order from the front summed,
 * the stop rule tested at each block end (measure_run). */
static void block_done(block_sums *B, const block_count *cnt, unsigned char *done,
                       size_t b, size_t nb, size_t block, size_t total, double need,
                       const tally *known)
{
    done[b] = 1;
    while (!B->stop && B->front < nb && done[B->front]) {
        const block_count *k = cnt + B->front++;
        B->sum.a += k->a;
        B->sum.m += k->m;
        B->sum.h += k->h;
        B->sum.c += k->c;
        const size_t j1 = B->front * block < total ? B->front * block : total;
        const double rest = (double)(total - j1);
        if ((double)B->sum.h + rest < need * (1.0 - 1e-9) * ((double)B->sum.m + rest))
            B->stop = 1;
        else if (known && contra_decided(known, B->sum.c, (long)(total - j1)))
            B->stop = 2;
    }
}

/* With need > 0, the samples go in blocks of MEASURE_BLOCK, and after
 * each the count stops once even the rest all landing (each informative
 * and verified) would leave the share below need (times 1 - 1e-9, so no
 * rounding of the share can reach it): the tally is then one whose share
 * is 0. Callers compare the share with thresholds of at least need, so
 * they decide as on the whole count. With known (measure_contra), the
 * count stops where contra_decided settles accepted()'s bound.
 *
 * One parallel region per count: the threads take the blocks in order
 * and go on without waiting for each other; the blocks' counts are summed
 * in block order and the rules tested at each block end, as one thread
 * would, so where the count stops and what it returns are the same for
 * any thread count (blocks taken past the stop are not read). Without
 * memory for the blocks' counts, one block: the whole count, which
 * decides the same. */
static tally measure_run(const ctx *C, const st_symmetry *y, double angle,
                         size_t stride, int full, double need, const tally *known)
{
    const size_t total = (C->S->n + stride - 1) / stride;
    size_t block = MEASURE_BLOCK, nb = (total + block - 1) / block;
    block_count one, *cnt = nb > 1 ? st_malloc_array(nb, sizeof *cnt) : NULL;
    unsigned char one_done, *done = cnt ? calloc(nb, 1) : NULL;
    if (!done) {
        free(cnt);
        cnt = &one;
        done = &one_done;
        block = total ? total : 1;
        nb = total ? 1 : 0;
    }
    block_sums B = {{0, 0, 0, 0}, 0, 0};
    size_t next = 0;
    int stop = 0;
#pragma omp parallel if (nb > 1)
    for (;;) {
        size_t b;
#pragma omp atomic capture
        b = next++;
        int halt;
#pragma omp atomic read
        halt = stop;
        if (b >= nb || halt)
            break;
        const size_t j0 = b * block, j1 = total - j0 > block ? j0 + block : total;
        cnt[b] = measure_block(C, y, angle, stride, full, j0, j1);
#pragma omp critical(st_symmetry_measure)
        {
            block_done(&B, cnt, done, b, nb, block, total, need, known);
            if (B.stop) {
#pragma omp atomic write
                stop = 1;
            }
        }
    }
    if (cnt != &one) {
        free(cnt);
        free(done);
    }
    if (B.stop == 1) {
        tally none = {(long)total, 0, 0, 0};
        return none;
    }
    if (B.stop == 2) {
        tally r = {known->all, known->informative, known->verified, B.sum.c};
        return r;
    }
    tally r = {B.sum.a, B.sum.m, B.sum.h, full ? B.sum.c : 0};
    return r;
}

static tally measure_need(const ctx *C, const st_symmetry *y, double angle,
                          size_t stride, int full, double need)
{
    return measure_run(C, y, angle, stride, full, need, NULL);
}

static tally measure(const ctx *C, const st_symmetry *y, double angle,
                     size_t stride, int full)
{
    return measure_need(C, y, angle, stride, full, 0.0);
}

/* The contradictions of the whole count (stride 1) where its verified
 * counts are known (t: measure's, stride 1, without them): they matter
 * only to accepted()'s bound (MAX_CONTRA), so the count stops where
 * the rest can no longer move the share across it (contra_decided). */
static tally measure_contra(const ctx *C, const st_symmetry *y, double angle, const tally *t)
{
    rims_need(C);
    return measure_run(C, y, angle, 1, 1, 0.0, t);
}

static double share(const tally *t)
{
    if ((double)t->informative < MIN_INFORM * (double)t->all)
        return 0.0;
    return (double)t->verified / (double)t->informative;
}

/* The share of every stride-th sample's images verified (measure), where
 * only whether it reaches need matters (measure_need): below need it may
 * be 0 instead. */
static double support_need(const ctx *C, const st_symmetry *y, double angle,
                           size_t stride, double need)
{
    tally t = measure_need(C, y, angle, stride, 0, need);
    return share(&t);
}

/* Accepted: a clear majority of the informative samples verified, or
 * (a damaged part, whose images fall into its holes) at least
 * MIN_VERIFIED of them verified and at most MAX_CONTRA of what the soup
 * could check contradicted. doc/design/symmetry.md has the measurements
 * behind both. */
static int accepted(const tally *t, double min_support)
{
    double v = share(t);
    return v >= min_support || (v >= MIN_VERIFIED && contradiction(t) <= MAX_CONTRA);
}


/* ---- mirrors -------------------------------------------------------------- */

/* The plane's sign made canonical: the largest component of the normal
 * positive. */
static void canon_plane(double n[3], double *off)
{
    int m = 0;
    for (int a = 1; a < 3; a++)
        if (fabs(n[a]) > fabs(n[m]))
            m = a;
    if (n[m] < 0) {
        for (int a = 0; a < 3; a++)
            n[a] = -n[a];
        *off = -*off;
    }
}

static st_symmetry mirror_of(const double n[3], double off)
{
    st_symmetry y;
    memset(&y, 0, sizeof y);
    y.kind = ST_SYMMETRY_MIRROR;
    for (int a = 0; a < 3; a++) {
        y.dir[a] = n[a];
        y.point[a] = off * n[a];
    }
    return y;
}

/* A refinement's match of sample k under mirror map->y: its image q, and the
 * nearest point c (triangle *t) of the soup where the image lands within
 * the round's reach with a matching normal. 0 where the sample lies on the
 * plane or slides along it (no evidence for the plane), or does not land. */
static int image_lands(const ctx *C, const sym_map *map, size_t k, int coarse,
                       double q[3], double c[3], int64_t *t)
{
    const samples *S = C->S;
    const double *p = S->p + 3 * k;
    double nq[3], d[3];
    map_apply(map, p, 1, q);
    st_sub3(d, q, p);
    double l = st_norm3(d);
    if (!(l > C->tol) || fabs(st_dot3(d, S->nrm + 3 * k)) < INFORM_SIN * l)
        return 0;
    map_apply(map, S->nrm + 3 * k, 0, nq);
    return lands_at(C, q, nq, (coarse ? REFINE_WIDE : REFINE_REACH) * C->tol, c, t);
}

/* ICP rounds, point to point: match each sample's image to the nearest
 * point of the soup, re-estimate the plane from the pairs' midpoints. */
static void refine_mirror_mid(const ctx *C, st_symmetry *y, int coarse_rounds)
{
    const samples *S = C->S;
    double *mid = st_malloc_array(3 * (S->n / REFINE_STRIDE + 1), sizeof *mid);
    if (!mid)
        return; /* unrefined: only a weaker support */
    for (int round = 0; round < coarse_rounds + REFINE_ROUNDS; round++) {
        const int coarse = round < coarse_rounds;
        double mean[3] = {0, 0, 0};
        size_t m = 0;
        const sym_map map = map_of(y, 0.0);
        /* sequential: the sums are in sample order, independent of
         * threads */
        for (size_t k = 0; k < S->n; k += coarse ? REFINE_COARSE_STRIDE : REFINE_STRIDE) {
            double q[3], c[3];
            const double *p = S->p + 3 * k;
            int64_t t;
            if (!image_lands(C, &map, k, coarse, q, c, &t))
                continue;
            for (int x = 0; x < 3; x++) {
                mid[3 * m + x] = 0.5 * (p[x] + c[x]);
                mean[x] += mid[3 * m + x];
            }
            m++;
        }
        /* (a wide round that fails leaves the plane to the close ones) */
        if (m < 16 / REFINE_STRIDE + 4) {
            if (!coarse)
                break;
            round = coarse_rounds - 1;
            continue;
        }
        for (int x = 0; x < 3; x++)
            mean[x] /= (double)m;
        /* the midpoints of matched pairs lie on the plane: its normal is
         * their direction of least spread */
        double cov[3][3] = {{0}}, ev[3][3];
        for (size_t k = 0; k < m; k++) {
            double d[3];
            st_sub3(d, mid + 3 * k, mean);
            for (int x = 0; x < 3; x++)
                for (int z = 0; z < 3; z++)
                    cov[x][z] += d[x] * d[z];
        }
        eigen3(cov, ev);
        int least = 0;
        for (int x = 1; x < 3; x++)
            if (cov[x][x] < cov[least][least])
                least = x;
        double n[3] = {ev[least][0], ev[least][1], ev[least][2]};
        normalize(n);
        if (fabs(st_dot3(n, y->dir)) < 0.9) {
            if (!coarse)
                break; /* the fit turned away: keep the plane */
            round = coarse_rounds - 1;
            continue;
        }
        double off = st_dot3(n, mean);
        canon_plane(n, &off);
        double moved = fabs(off - st_dot3(y->point, y->dir)) / C->tol,
               turned = 1.0 - st_dot3(n, y->dir);
        *y = mirror_of(n, off);
        if (moved < REFINE_STILL && turned < REFINE_STILL * REFINE_STILL) {
            if (!coarse)
                break; /* settled */
            round = coarse_rounds - 1; /* settled at the wide reach */
        }
    }
    free(mid);
}

/* The normal equations of one point-to-plane round (refine_mirror): the
 * plane's normal turned by x[0] u + x[1] v and its offset moved by x[2]
 * L, in coordinates centred at the samples' centroid and divided by L. */
typedef struct plane_step {
    double a[3][3], b[3];
    double n[3], u[3], v[3], off, L;
    const double *c0;
    size_t m;
} plane_step;

static void step_start(plane_step *F, const st_symmetry *y, const double c0[3], double L)
{
    memset(F, 0, sizeof *F);
    memcpy(F->n, y->dir, sizeof F->n);
    int k = 0; /* the axis least along n */
    for (int x = 1; x < 3; x++)
        if (fabs(F->n[x]) < fabs(F->n[k]))
            k = x;
    double e[3] = {0, 0, 0};
    e[k] = 1.0;
    st_cross3(F->u, F->n, e);
    normalize(F->u);
    st_cross3(F->v, F->n, F->u);
    F->c0 = c0;
    F->L = L;
    F->off = (st_dot3(y->dir, y->point) - st_dot3(F->n, c0)) / L;
}

/* The pair: sample p, its image's nearest point c on a triangle of unit
 * normal m. The residual is the image's distance from c's tangent plane
 * (m . (q - c)); the row its derivative by the three unknowns. */
static void step_add(plane_step *F, const double p[3], const double q[3],
                     const double c[3], const double m[3])
{
    double pl[3], d[3];
    for (int x = 0; x < 3; x++) {
        pl[x] = (p[x] - F->c0[x]) / F->L;
        d[x] = (q[x] - c[x]) / F->L;
    }
    const double sd = st_dot3(F->n, pl) - F->off, mn = st_dot3(m, F->n);
    const double row[3] = {-2.0 * (mn * st_dot3(F->u, pl) + sd * st_dot3(m, F->u)),
                           -2.0 * (mn * st_dot3(F->v, pl) + sd * st_dot3(m, F->v)),
                           2.0 * mn};
    const double r = st_dot3(m, d);
    for (int i = 0; i < 3; i++) {
        for (int j = 0; j < 3; j++)
            F->a[i][j] += row[i] * row[j];
        F->b[i] -= row[i] * r;
    }
    F->m++;
}

/* The least-squares step (Cholesky, a relative 1e-9 of the trace added to
 * the diagonal so an unconstrained direction stays still) into *y.
 * 0 when the system has no solution. */
static int step_solve(const plane_step *F, st_symmetry *y)
{
    double a[3][3], x[3];
    const double tr = F->a[0][0] + F->a[1][1] + F->a[2][2];
    if (!(tr > 0.0))
        return 0;
    memcpy(a, F->a, sizeof a);
    for (int i = 0; i < 3; i++)
        a[i][i] += 1e-9 * tr;
    for (int j = 0; j < 3; j++) { /* a = l l^T, l in the lower half */
        for (int k = 0; k < j; k++)
            a[j][j] -= a[j][k] * a[j][k];
        if (!(a[j][j] > 0.0))
            return 0;
        a[j][j] = sqrt(a[j][j]);
        for (int i = j + 1; i < 3; i++) {
            for (int k = 0; k < j; k++)
                a[i][j] -= a[i][k] * a[j][k];
            a[i][j] /= a[j][j];
        }
    }
    for (int i = 0; i < 3; i++) {
        x[i] = F->b[i];
        for (int k = 0; k < i; k++)
            x[i] -= a[i][k] * x[k];
        x[i] /= a[i][i];
    }
    for (int i = 2; i >= 0; i--) {
        for (int k = i + 1; k < 3; k++)
            x[i] -= a[k][i] * x[k];
        x[i] /= a[i][i];
    }
    double n[3];
    for (int k = 0; k < 3; k++)
        n[k] = F->n[k] + x[0] * F->u[k] + x[1] * F->v[k];
    normalize(n);
    double off = (F->off + x[2]) * F->L + st_dot3(n, F->c0);
    if (!isfinite(off) || !isfinite(n[0] + n[1] + n[2]))
        return 0;
    canon_plane(n, &off);
    *y = mirror_of(n, off);
    return 1;
}

/* ICP rounds, point to plane (Chen & Medioni 1992, for the mirror's three
 * degrees of freedom): match each sample's image to the nearest point of
 * the soup, then move the plane so the images lie on the matched points'
 * tangent planes (a Gauss-Newton step). Point to point (the pairs'
 * midpoints fitted by a plane) settles slowly where the images' error runs
 * along the surface: on the clean couplingdown it stopped 0.9 degrees off
 * the true plane (support 0.832 against 1.000), and a start 5.3 degrees off
 * moved only to 4.7. */
static void refine_mirror_plane(const ctx *C, st_symmetry *y, int coarse_rounds)
{
    const samples *S = C->S;
    const double L = sqrt(S->area) > C->tol ? sqrt(S->area) : C->tol;
    for (int round = 0; round < coarse_rounds + REFINE_ROUNDS; round++) {
        const int coarse = round < coarse_rounds;
        plane_step F;
        step_start(&F, y, S->c, L);
        const sym_map map = map_of(y, 0.0);
        /* sequential: the sums are in sample order, independent of
         * threads */
        for (size_t k = 0; k < S->n; k += coarse ? REFINE_COARSE_STRIDE : REFINE_STRIDE) {
            double q[3], c[3];
            const double *p = S->p + 3 * k;
            int64_t t;
            if (!image_lands(C, &map, k, coarse, q, c, &t))
                continue;
            step_add(&F, p, q, c, C->tn + 3 * (size_t)t);
        }
        st_symmetry z = *y;
        /* (a wide round that fails leaves the plane to the close ones) */
        if (F.m < 16 / REFINE_STRIDE + 4 || !step_solve(&F, &z) ||
            fabs(st_dot3(z.dir, y->dir)) < 0.9) {
            if (!coarse)
                break; /* too few pairs, or the fit turned away: keep the plane */
            round = coarse_rounds - 1;
            continue;
        }
        double moved = fabs(st_dot3(z.dir, z.point) - st_dot3(y->point, y->dir)) / C->tol,
               turned = 1.0 - fabs(st_dot3(z.dir, y->dir));
        *y = z;
        if (moved < REFINE_STILL && turned < REFINE_STILL * REFINE_STILL) {
            if (!coarse)
                break; /* settled */
            round = coarse_rounds - 1; /* settled at the wide reach */
        }
    }
}

static int same_plane(const st_symmetry *a, const st_symmetry *b, double tol)
{
    double d = st_dot3(a->dir, b->dir);
    if (fabs(d) < SAME_COS)
        return 0;
    double oa = st_dot3(a->point, a->dir), ob = st_dot3(b->point, a->dir);
    return fabs(oa - ob) < tol;
}

/* Candidates by voting: each pair votes for the cell of its plane, over
 * the cube map of the direction and the offset; the heaviest cells
 * become planes (the cell's mean). A plane whose votes are few spreads
 * them over the cells around it (the plane of an axis-aligned part
 * through the origin lies on a corner of eight cells), and loses to
 * cells of sharper false planes: so the cells are also ranked by the
 * votes of their window (the cell and its neighbours, 3 x 3 x 3 cells of
 * one cube face), and the cells that rank above every other in their
 * window (the peaks) become planes too: the window's mean. */
typedef struct vote {
    uint64_t key;    /* 0: an empty slot */
    double n[3], off;
    long count;
    long win;        /* the window's votes */
} vote;

static int cmp_vote(const void *x, const void *y)
{
    const vote *a = x, *b = y;
    if (a->count != b->count)
        return a->count < b->count ? 1 : -1;
    return (a->key > b->key) - (a->key < b->key);
}

static int cmp_peak(const void *x, const void *y)
{
    const vote *a = x, *b = y;
    if (a->win != b->win)
        return a->win < b->win ? 1 : -1;
    return (a->key > b->key) - (a->key < b->key);
}

/* A cell's key from its face m, direction cells (iu, iw) and offset io
 * (in 2 tolerances, odd: an offset cell spans 4 tolerances, and the key
 * is never 0). */
static uint64_t cell_key(int m, long iu, long iw, long io)
{
    return ((uint64_t)m << 60) ^ ((uint64_t)(iu & 0xff) << 52) ^
           ((uint64_t)(iw & 0xff) << 44) ^ ((uint64_t)io & 0xfffffffffffULL);
}

static uint64_t vote_key(const double n[3], double off, double tol)
{
    int m = 0;
    for (int a = 1; a < 3; a++)
        if (fabs(n[a]) > fabs(n[m]))
            m = a;
    int u = (m + 1) % 3, w = (m + 2) % 3;
    long iu = (long)floor((n[u] / fabs(n[m]) + 1.0) * 0.5 * VOTE_DIR_BINS);
    long iw = (long)floor((n[w] / fabs(n[m]) + 1.0) * 0.5 * VOTE_DIR_BINS);
    long io = (long)floor(off / (2.0 * tol));
    return cell_key(m, iu, iw, io | 1);
}

static vote *vote_find(vote *tab, size_t cap, uint64_t key)
{
    size_t slot = (size_t)(mix64(key) & (cap - 1));
    while (tab[slot].key != 0 && tab[slot].key != key)
        slot = (slot + 1) & (cap - 1);
    return tab + slot;
}

/* The pairs' votes into tab (cap slots, a power of two, over twice the
 * pairs). */
static void vote_pairs(const ctx *C, vote *tab, size_t cap)
{
    const samples *S = C->S;
    uint64_t h = 0x243f6a8885a308d3ULL;
    for (long k = 0; k < VOTE_PAIRS; k++) {
        h = mix64(h + (uint64_t)k);
        size_t i = (size_t)(h % S->n), j = (size_t)((h >> 32) % S->n);
        double d[3];
        st_sub3(d, S->p + 3 * i, S->p + 3 * j);
        double l = st_norm3(d);
        if (!(l > 2.0 * C->tol))
            continue;
        double n[3] = {d[0] / l, d[1] / l, d[2] / l};
        const double *ni = S->nrm + 3 * i, *nj = S->nrm + 3 * j;
        /* two points of one surface that slides along itself (a bar's
         * side, d in its plane) vote for every plane across it */
        if (fabs(st_dot3(ni, n)) < INFORM_SIN)
            continue;
        double r[3], dn = 2.0 * st_dot3(ni, n);
        for (int a = 0; a < 3; a++)
            r[a] = ni[a] - dn * n[a];
        if (fabs(st_dot3(r, nj)) < VOTE_COS)
            continue;
        double mid[3];
        for (int a = 0; a < 3; a++)
            mid[a] = 0.5 * (S->p[3 * i + a] + S->p[3 * j + a]);
        double off = st_dot3(mid, n);
        canon_plane(n, &off);
        uint64_t key = vote_key(n, off, C->tol);
        vote *v = vote_find(tab, cap, key);
        v->key = key;
        for (int a = 0; a < 3; a++)
            v->n[a] += n[a];
        v->off += off;
        v->count++;
    }
}

/* Cell c's window: its votes (into c->win), and with `plane` its mean
 * plane (into n, off). 1 when no cell of the window ranks above c
 * (cmp_peak, on the windows' votes set before). */
static int vote_window(vote *tab, size_t cap, vote *c, int plane, double n[3],
                       double *off)
{
    const int m = (int)(c->key >> 60 & 3);
    const long iu = (long)(c->key >> 52 & 0xff), iw = (long)(c->key >> 44 & 0xff);
    long io = (long)(c->key & 0xfffffffffffULL);
    if (io >= 1L << 43)
        io -= 1L << 44; /* sign-extended from its 44 bits */
    long win = 0;
    int peak = 1;
    double sn[3] = {0, 0, 0}, so = 0.0;
    for (long du = -1; du <= 1; du++)
        for (long dw = -1; dw <= 1; dw++)
            for (long dof = -2; dof <= 2; dof += 2) {
                const vote *v = vote_find(tab, cap, cell_key(m, iu + du, iw + dw, io + dof));
                if (v->key == 0)
                    continue;
                if (plane)
                    peak &= v == c || cmp_peak(c, v) < 0;
                for (int a = 0; a < 3; a++)
                    sn[a] += v->n[a];
                so += v->off;
                win += v->count;
            }
    c->win = win;
    if (plane) {
        for (int a = 0; a < 3; a++)
            n[a] = sn[a];
        normalize(n);
        *off = so / (double)win;
    }
    return peak;
}

/* Up to max planes of the heaviest cells into out (*nout), then up to
 * peaks planes of the peaks (*npeak) after them. */
static void vote_mirrors(const ctx *C, st_symmetry *out, size_t max, size_t peaks,
                         size_t *nout, size_t *npeak)
{
    *nout = *npeak = 0;
    size_t cap = 1;
    while (cap < 2 * (size_t)VOTE_PAIRS)
        cap *= 2;
    vote *tab = st_calloc_array(cap, sizeof *tab);
    vote *cells = st_malloc_array(cap, sizeof *cells);
    if (!tab || !cells) {
        free(tab);
        free(cells);
        return;
    }
    vote_pairs(C, tab, cap);
    /* the filled cells alone are sorted (their keys differ: a total
     * order, so the same ranking as sorting the whole table) */
    size_t filled = 0;
    for (size_t i = 0; i < cap; i++)
        if (tab[i].key != 0) {
            vote_window(tab, cap, tab + i, 0, NULL, NULL);
            cells[filled++] = tab[i];
        }
    qsort(cells, filled, sizeof *cells, cmp_vote);
    size_t m = 0;
    for (size_t i = 0; i < filled && m < max && cells[i].count >= 3; i++) {
        double n[3] = {cells[i].n[0], cells[i].n[1], cells[i].n[2]};
        normalize(n);
        out[m++] = mirror_of(n, cells[i].off / (double)cells[i].count);
    }
    *nout = m;
    /* the peaks, by their windows' votes */
    size_t np = 0;
    for (size_t i = 0; i < cap; i++) {
        double n[3], off;
        if (tab[i].key != 0 && tab[i].win >= 3 &&
            vote_window(tab, cap, tab + i, 1, n, &off)) {
            cells[np] = tab[i];
            for (int a = 0; a < 3; a++)
                cells[np].n[a] = n[a];
            cells[np++].off = off;
        }
    }
    qsort(cells, np, sizeof *cells, cmp_peak);
    for (size_t i = 0; i < np && *npeak < peaks; i++) {
        st_symmetry y = mirror_of(cells[i].n, cells[i].off);
        int dup = 0;
        for (size_t j = 0; j < m + *npeak && !dup; j++)
            dup = same_plane(out + j, &y, C->tol);
        if (!dup)
            out[m + (*npeak)++] = y;
    }
    free(tab);
    free(cells);
}

/* Candidates [from, to) refined (after `coarse` wide rounds), their
 * supports set, ok[i] whether accepted, screened[i] whether they passed
 * the screen. With `plane`, only those that passed it, refined again
 * point to plane (refine_mirror_plane) from where they are. Each
 * candidate on its own: the same result for any thread count. */
static void measure_mirrors(const ctx *C, const st_symmetry_params *p, st_symmetry *cand,
                            int *ok, int *screened, size_t from, size_t to, int coarse,
                            int plane)
{
#pragma omp parallel for schedule(dynamic, 1)
    for (long i = (long)from; i < (long)to; i++) {
        ok[i] = 0;
        if (plane && !screened[i])
            continue;
        if (plane)
            refine_mirror_plane(C, cand + i, 0);
        else
            refine_mirror_mid(C, cand + i, coarse);
        /* a plane that fails on every SCREEN-th sample by far is not
         * measured on all: only accepted planes' supports are read */
        /* (below the needs, measure_need may stop early: a share that
         * low is refused either way, and only accepted ones are read) */
        tally t = measure_need(C, cand + i, 0.0, SCREEN, 0,
                               fmin(SCREEN_SHARE * MIN_VERIFIED, p->min_support));
        screened[i] = share(&t) >= SCREEN_SHARE * MIN_VERIFIED;
        if (screened[i])
            t = measure_need(C, cand + i, 0.0, 1, 0, fmin(MIN_VERIFIED, p->min_support));
        /* the contradictions matter only between the two shares */
        if (share(&t) >= MIN_VERIFIED && share(&t) < p->min_support)
            t = measure_contra(C, cand + i, 0.0, &t);
        cand[i].support = share(&t);
        ok[i] = accepted(&t, p->min_support);
    }
}

/* The accepted candidates of [from, to) into mirrors (*nm), one per
 * plane: the best supported. */
static void collect_mirrors(const st_symmetry *cand, const int *ok, size_t from,
                            size_t to, double tol, st_symmetry *mirrors, size_t *nm)
{
    for (size_t i = from; i < to; i++) {
        if (!ok[i])
            continue;
        size_t j = 0;
        while (j < *nm && !same_plane(mirrors + j, cand + i, tol))
            j++;
        if (j == *nm)
            mirrors[(*nm)++] = cand[i];
        else if (cand[i].support > mirrors[j].support)
            mirrors[j] = cand[i];
    }
}

/* ---- rotations ------------------------------------------------------------ */

static int same_line(const st_symmetry *a, const st_symmetry *b, double tol)
{
    if (fabs(st_dot3(a->dir, b->dir)) < SAME_COS)
        return 0;
    double d[3], x[3];
    st_sub3(d, b->point, a->point);
    st_cross3(x, d, a->dir);
    return st_norm3(x) < tol;
}

/* Order of the axis y: 0 continuous, n >= 2, or -1 none; *sup its
 * support (the least over the angles tested). Continuous: three turns by
 * angles that are no simple fraction of a full turn all hold. Order n:
 * the turn by 360/n degrees and the one by (n/2) times that (near a half
 * turn: a small turn about any axis near a smooth surface slides it along
 * itself) both hold; the largest such n. Screened on every SCREEN-th
 * sample, confirmed on all. */
/* Turns that are no simple fraction of a full turn. */
static const double odd[3] = {0.3819660112501051, 0.1415926535897932,
                              0.7071067811865476};

static int axis_order(const ctx *C, const st_symmetry *y, int max_order,
                      double min_support, double *sup)
{
    double least = 1.0;
    for (int i = 0; i < 3 && least >= min_support; i++)
        least = fmin(least, support_need(C, y, 2.0 * PI * odd[i], SCREEN, min_support));
    if (least >= min_support) {
        least = 1.0;
        for (int i = 0; i < 3 && least >= min_support; i++)
            least = fmin(least, support_need(C, y, 2.0 * PI * odd[i], 1, min_support));
        if (least >= min_support) {
            *sup = least;
            return 0;
        }
    }
    for (int n = max_order; n >= 2; n--) {
        /* every turn up to the half: a small turn alone passes on any
         * axis that a surface nearly slides along */
        /* the first turn on every 4 SCREEN-th sample, far below: no */
        if (support_need(C, y, 2.0 * PI / (double)n, 4 * SCREEN,
                         SCREEN_SHARE * min_support) < SCREEN_SHARE * min_support)
            continue;
        int k = 1;
        while (k <= n / 2 &&
               support_need(C, y, 2.0 * PI * k / (double)n, SCREEN, min_support) >=
                   min_support)
            k++;
        if (k <= n / 2)
            continue;
        double a1 = 2.0 * PI / (double)n, a2 = a1 * (double)(n / 2);
        double s = fmin(support_need(C, y, a1, 1, min_support),
                        support_need(C, y, a2, 1, min_support));
        if (s >= min_support) {
            *sup = s;
            return n;
        }
    }
    return -1;
}

/* The line where mirror planes a and b meet; 0 when they are parallel. */
static int meet(const st_symmetry *a, const st_symmetry *b, st_symmetry *line)
{
    double u[3];
    st_cross3(u, a->dir, b->dir);
    double l = st_norm3(u);
    if (!(l > 0.05))
        return 0;
    for (int x = 0; x < 3; x++)
        u[x] /= l;
    /* the point of the line nearest the origin: p = (oa (nb x u) + ob
     * (u x na)) / (u . (na x nb)) */
    double oa = st_dot3(a->point, a->dir), ob = st_dot3(b->point, b->dir);
    double t1[3], t2[3];
    st_cross3(t1, b->dir, u);
    st_cross3(t2, u, a->dir);
    memset(line, 0, sizeof *line);
    line->kind = ST_SYMMETRY_ROTATION;
    for (int x = 0; x < 3; x++) {
        line->point[x] = (oa * t1[x] + ob * t2[x]) / l;
        line->dir[x] = u[x];
    }
    return 1;
}

/* ---- helices -------------------------------------------------------------- */

/* A surface that a continuous motion maps onto itself has its normal
 * across the motion's velocity everywhere (Pottmann & Randrup 1998,
 * "Rotational and helical surface approximation for reverse
 * engineering"). The screw motion about the line through a along the unit
 * c, with pitch 2 pi h, moves x at c x (x - a) + h c; so a sample x with
 * unit normal m on such a surface has
 *     h (m . c) + ((x - a) x m) . c = 0,
 * linear in (c, cbar = a x c + h c): every sample whose normal is not
 * across the axis says h, and every sample of a turned part (h free, its
 * normal line meets the axis) says where the axis is. */
#define AXIS_SIN 0.3420201433256687     /* sin 20 degrees */
#define AXIS_ROUNDS 4
#define PITCH_BIN 1.25      /* the ratio of a pitch bin's ends */
#define PITCH_WINDOW 5      /* bins: pitches within a ratio of about 3 */
#define PITCH_SHARE 0.1     /* of all samples in that window, at least */
#define PITCH_STEPS 24      /* the scan of the pitch */
/* A helix must verify this much more of the informative samples than the
 * pure rotation about its axis: measured over 264 helix candidates of the
 * corpus (doc/design/symmetry.md), the false ones (turned parts and tori
 * read with a short move along the axis) beat the rotation by at most
 * 0.035, the screw's thread by 0.33 (holed) and 0.58 (whole). */
#define HELIX_MARGIN 0.1

/* Symmetric 3x3 m's pseudo-inverse: eigenvalues below 1e-6 of the largest
 * dropped (a turned part says nothing of the move along its axis). */
static void pinv3(const double m[3][3], double out[3][3])
{
    double t[3][3], v[3][3];
    memcpy(t, m, sizeof t);
    eigen3(t, v);
    double big = fmax(fmax(t[0][0], t[1][1]), t[2][2]);
    memset(out, 0, 9 * sizeof(double));
    for (int e = 0; e < 3; e++) {
        if (!(t[e][e] > 1e-6 * big))
            continue;
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++)
                out[i][j] += v[e][i] * v[e][j] / t[e][e];
    }
}

/* One round of the axis fit: the line that the normal lines of the
 * samples near y's surface of revolution best meet (those whose normal is
 * within 20 degrees of across the axis, off the axis, with the normal
 * line within REFINE_REACH tolerances of it): minimize the sum of
 * (m . cbar + ((x - o) x m) . c)^2 over |c| = 1, cbar eliminated through
 * the pseudo-inverse of sum m m^T (so a pure turn where the samples say
 * nothing of a move). 0 when too few samples. */
static int axis_round(const ctx *C, const st_symmetry *y, double c[3], double at[3])
{
    const samples *S = C->S;
    double mm[3][3] = {{0}}, mu[3][3] = {{0}}, uu[3][3] = {{0}};
    size_t n = 0;
    for (size_t k = 0; k < S->n; k++) {
        const double *x = S->p + 3 * k, *m = S->nrm + 3 * k;
        double r[3], u[3], mc[3];
        if (fabs(st_dot3(m, y->dir)) >= AXIS_SIN)
            continue;
        st_sub3(r, x, y->point);
        st_cross3(mc, m, y->dir);
        double along = st_dot3(r, y->dir);
        if (fabs(st_dot3(r, mc)) > REFINE_REACH * C->tol * st_norm3(mc) ||
            st_dot3(r, r) - along * along <= C->tol * C->tol)
            continue;
        st_cross3(u, r, m);
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++) {
                mm[i][j] += m[i] * m[j];
                mu[i][j] += m[i] * u[j];
                uu[i][j] += u[i] * u[j];
            }
        n++;
    }
    if (n < 16)
        return 0;
    double pm[3][3], pmu[3][3] = {{0}}, k[3][3], v[3][3];
    pinv3(mm, pm);
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            for (int l = 0; l < 3; l++)
                pmu[i][j] += pm[i][l] * mu[l][j];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            k[i][j] = uu[i][j];
            for (int l = 0; l < 3; l++)
                k[i][j] -= mu[l][i] * pmu[l][j];
        }
    eigen3(k, v);
    int least = 0;
    for (int e = 1; e < 3; e++)
        if (k[e][e] < k[least][least])
            least = e;
    double cbar[3] = {0, 0, 0}, x[3];
    for (int i = 0; i < 3; i++)
        c[i] = v[least][i];
    normalize(c);
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            cbar[i] -= pmu[i][j] * c[j];
    st_cross3(x, c, cbar);    /* the axis' point nearest the old one */
    for (int i = 0; i < 3; i++)
        at[i] = y->point[i] + x[i];
    return 1;
}

/* y's axis moved onto the line its turned surfaces meet (rounds of
 * axis_round until it settles); a fit that turns by more than 10 degrees
 * is not taken. */
static void fit_axis(const ctx *C, st_symmetry *y)
{
    for (int round = 0; round < AXIS_ROUNDS; round++) {
        double c[3], at[3];
        if (!axis_round(C, y, c, at))
            return;
        double d = st_dot3(c, y->dir);
        if (fabs(d) < 0.984807753012208) /* cos 10 degrees */
            return;
        double moved[3];
        st_sub3(moved, at, y->point);
        for (int i = 0; i < 3; i++) {
            y->dir[i] = d < 0 ? -c[i] : c[i];
            y->point[i] = at[i];
        }
        if (st_norm3(moved) < REFINE_STILL * C->tol && 1.0 - fabs(d) < REFINE_STILL * REFINE_STILL)
            return;
    }
}

/* The pitch most samples of y's axis say (each sample's h above), or 0:
 * pitches between 2 tolerances (below, a turn by the odd angles moves the
 * surface by less than a tolerance: a pure rotation says as much) and the
 * samples' extent along the axis vote in bins whose ends differ by
 * PITCH_BIN; the heaviest window of PITCH_WINDOW bins of one sign, if it
 * holds PITCH_SHARE of the samples, gives the least-squares pitch of its
 * samples. */
static double vote_pitch(const ctx *C, const st_symmetry *y)
{
    const samples *S = C->S;
    enum { BINS = 64 };
    double lo = INFINITY, hi = -INFINITY, pmin = 2.0 * C->tol;
    for (size_t k = 0; k < S->n; k++) {
        double r[3];
        st_sub3(r, S->p + 3 * k, y->point);
        lo = fmin(lo, st_dot3(r, y->dir));
        hi = fmax(hi, st_dot3(r, y->dir));
    }
    int nb = hi - lo > pmin ? (int)ceil(log((hi - lo) / pmin) / log(PITCH_BIN)) : 0;
    nb = nb < BINS ? nb : BINS;
    if (nb < 1)
        return 0.0;
    long cnt[2][BINS] = {{0}};
    for (int pass = 0; pass < 2; pass++) {
        int best_s = 0, best_b = 0;
        long best = 0;
        if (pass == 1) {
            for (int sg = 0; sg < 2; sg++)
                for (int b = 0; b + PITCH_WINDOW <= nb || b == 0; b++) {
                    long sum = 0;
                    for (int i = b; i < b + PITCH_WINDOW && i < nb; i++)
                        sum += cnt[sg][i];
                    if (sum > best) {
                        best = sum;
                        best_s = sg;
                        best_b = b;
                    }
                }
            if ((double)best < PITCH_SHARE * (double)S->n)
                return 0.0;
        }
        double num = 0.0, den = 0.0;
        for (size_t k = 0; k < S->n; k++) {
            const double *m = S->nrm + 3 * k;
            double r[3], u[3], mc = st_dot3(m, y->dir);
            if (fabs(mc) < INFORM_SIN)
                continue;
            st_sub3(r, S->p + 3 * k, y->point);
            st_cross3(u, r, m);
            double q = st_dot3(u, y->dir), p = -2.0 * PI * q / mc;
            if (!(fabs(p) >= pmin))
                continue;
            int b = (int)floor(log(fabs(p) / pmin) / log(PITCH_BIN)), sg = p < 0;
            if (b >= nb)
                continue;
            if (pass == 0)
                cnt[sg][b]++;
            else if (sg == best_s && b >= best_b && b < best_b + PITCH_WINDOW) {
                num -= mc * q;
                den += mc * mc;
            }
        }
        if (pass == 1)
            return den > 0.0 ? 2.0 * PI * num / den : 0.0;
    }
    return 0.0;
}

/* The pitch p0 bracketed: the share of every 4 SCREEN-th sample that a
 * turn by odd[0] verifies, over pitches from p0 / 2 to 3 p0 / 2 in at most
 * PITCH_STEPS steps (none finer than half a tolerance); the best, or 0
 * when it is below the screens' floor (SCREEN_SHARE of MIN_VERIFIED).
 * The share is flat near the true pitch (a thread's
 * faces are steep: a move along the axis changes their distance little),
 * so refine_pitch makes it precise. */
static double scan_pitch(const ctx *C, st_symmetry *y, double p0)
{
    double step = fmax(0.5 * C->tol, fabs(p0) / PITCH_STEPS), sup[PITCH_STEPS + 2];
    int n = (int)(fabs(p0) / step) + 1, best = 0;
    if (n > PITCH_STEPS + 2)
        n = PITCH_STEPS + 2;
    for (int i = 0; i < n; i++) {
        y->pitch = 0.5 * p0 + copysign(step * i, p0);
        sup[i] = fabs(y->pitch) >= 2.0 * C->tol
                     ? support_need(C, y, 2.0 * PI * odd[0], 4 * SCREEN,
                                    SCREEN_SHARE * MIN_VERIFIED)
                     : 0.0;
        if (sup[i] > sup[best])
            best = i;
    }
    return sup[best] >= SCREEN_SHARE * MIN_VERIFIED ? 0.5 * p0 + copysign(step * best, p0)
                                                    : 0.0;
}

/* ICP rounds on the pitch alone (every REFINE_STRIDE-th sample, turns by
 * odd[0] and odd[2] - 1): each informative image matched to the soup's
 * nearest point within REFINE_REACH tolerances with a compatible normal,
 * and within a tolerance of that triangle's plane (so the faces a move
 * along the axis takes off themselves, a head's flat ends, do not pull the
 * pitch to 0); the pitch moved by the least-squares step along the axis
 * (point to plane). Stops once the move along the axis at the turns is
 * below REFINE_STILL tolerances. */
static void refine_pitch(const ctx *C, st_symmetry *y)
{
    const samples *S = C->S;
    const double turn[2] = {2.0 * PI * odd[0], 2.0 * PI * (odd[2] - 1.0)};
    for (int round = 0; round < REFINE_ROUNDS; round++) {
        double num = 0.0, den = 0.0;
        size_t m = 0;
        /* sequential: the sums in sample order, whatever the threads */
        for (int j = 0; j < 2; j++) {
            const sym_map map = map_of(y, turn[j]);
            for (size_t k = 0; k < S->n; k += REFINE_STRIDE) {
                double q[3], nq[3], c[3], d[3];
                const double *p = S->p + 3 * k;
                map_apply(&map, p, 1, q);
                st_sub3(d, q, p);
                double l = st_norm3(d);
                if (!(l > C->tol) || fabs(st_dot3(d, S->nrm + 3 * k)) < INFORM_SIN * l)
                    continue;
                map_apply(&map, S->nrm + 3 * k, 0, nq);
                int64_t t;
                double reach = REFINE_REACH * C->tol;
                nearest(C, q, reach, &t, c);
                if (t < 0)
                    continue;
                const double *tn = C->tn + 3 * (size_t)t;
                st_sub3(d, c, q);
                double e = st_dot3(tn, d), g = st_dot3(tn, y->dir) * turn[j] / (2.0 * PI);
                if (fabs(st_dot3(nq, tn)) < MATCH_COS || fabs(e) > C->tol)
                    continue;
                num += g * e;
                den += g * g;
                m++;
            }
        }
        if (m < 16 || !(den > 0.0))
            return;
        double step = num / den;
        y->pitch += step;
        if (fabs(step) * fabs(turn[1]) / (2.0 * PI) < REFINE_STILL * C->tol)
            return;
    }
}

/* The helix about axis y, if there is one: y's axis refined, the pitch
 * voted and scanned, then measured like a continuous rotation (turns by
 * the odd angles, wrapped to half a turn either way so the moves along
 * the axis stay short), each turn accepted as a mirror is (accepted());
 * and it must hold on HELIX_MARGIN more than the pure rotation about the
 * same axis does (a turned part maps onto itself under any screw motion
 * about its axis where it is a cylinder, and only under the rotation
 * elsewhere: the rotation is the reading there). 1 with
 * *y the helix and its support; *measured 1 when it got as far as a
 * pitch. */
static int find_helix(const ctx *C, st_symmetry *y, double min_support, int *measured)
{
    *measured = 0;
    y->kind = ST_SYMMETRY_HELIX;
    y->order = 0;
    y->pitch = 0.0;
    fit_axis(C, y);
    double p0 = vote_pitch(C, y);
    if (p0 == 0.0 || !(y->pitch = scan_pitch(C, y, p0)))
        return 0;
    refine_pitch(C, y);
    if (!(fabs(y->pitch) >= 2.0 * C->tol))
        return 0;
    *measured = 1;
    double turn[3];
    for (int i = 0; i < 3; i++) {
        turn[i] = 2.0 * PI * (odd[i] > 0.5 ? odd[i] - 1.0 : odd[i]);
        if (support_need(C, y, turn[i], SCREEN, SCREEN_SHARE * MIN_VERIFIED) <
            SCREEN_SHARE * MIN_VERIFIED)
            return 0;
    }
    double least = 1.0;
    for (int i = 0; i < 3; i++) {
        tally t = measure(C, y, turn[i], 1, 0);
        if (share(&t) >= MIN_VERIFIED && share(&t) < min_support)
            t = measure_contra(C, y, turn[i], &t);
        if (!accepted(&t, min_support))
            return 0;
        least = fmin(least, share(&t));
    }
    st_symmetry turned = *y;
    turned.kind = ST_SYMMETRY_ROTATION;
    turned.pitch = 0.0;
    double plain = 1.0;
    for (int i = 0; i < 3 && plain + HELIX_MARGIN > least; i++)
        plain = fmin(plain, support_need(C, &turned, turn[i], 1, 0.0));
    if (plain + HELIX_MARGIN > least)
        return 0;
    y->support = least;
    return 1;
}

/* ---- the whole job -------------------------------------------------------- */

static int cmp_sym(const void *x, const void *y)
{
    const st_symmetry *a = x, *b = y;
    if (a->kind != b->kind)
        return a->kind < b->kind ? -1 : 1;
    if (a->support != b->support)
        return a->support < b->support ? 1 : -1;
    return 0;
}

static void keep(st_symmetry_set *out, const st_symmetry *y, double tol)
{
    for (size_t i = 0; i < out->n; i++) {
        st_symmetry *o = out->items + i;
        if (o->kind != y->kind)
            continue;
        int same = y->kind == ST_SYMMETRY_MIRROR ? same_plane(o, y, tol)
                                                 : same_line(o, y, tol);
        if (!same)
            continue;
        if (y->support > o->support)
            *o = *y;
        return;
    }
    if (out->n < ST_SYMMETRY_MAX) {
        out->items[out->n++] = *y;
        return;
    }
    /* full: replace the weakest of the same kind if y is better */
    size_t w = SIZE_MAX;
    for (size_t i = 0; i < out->n; i++)
        if (out->items[i].kind == y->kind &&
            (w == SIZE_MAX || out->items[i].support < out->items[w].support))
            w = i;
    if (w != SIZE_MAX && out->items[w].support < y->support)
        out->items[w] = *y;
}

/* Whether keep(out, y, ..) can change out for a y of this kind: the set
 * has room, or holds one of that kind (which y may replace). A set full
 * of other kinds (a ball's 16 mirrors) keeps none. */
static int room_for(const st_symmetry_set *out, st_symmetry_kind kind)
{
    if (out->n < ST_SYMMETRY_MAX)
        return 1;
    for (size_t i = 0; i < out->n; i++)
        if (out->items[i].kind == kind)
            return 1;
    return 0;
}

/* A continuous rotation and a helix about one line (within REFINE_REACH
 * tolerances: the helix' axis is refined, the rotation's is not) are two
 * readings of one turned part: the one with the lower support goes. */
static void one_screw_per_line(st_symmetry_set *out, double tol)
{
    for (size_t i = 0; i < out->n; i++) {
        st_symmetry *h = out->items + i;
        if (h->kind != ST_SYMMETRY_HELIX)
            continue;
        for (size_t j = 0; j < out->n; j++) {
            st_symmetry *r = out->items + j;
            if (r->kind != ST_SYMMETRY_ROTATION || r->order != 0 ||
                !same_line(h, r, REFINE_REACH * tol))
                continue;
            size_t gone = r->support >= h->support ? i : j;
            out->items[gone] = out->items[--out->n];
            i = (size_t)-1; /* start over: the set changed */
            break;
        }
    }
}

/* Each accepted mirror's contradiction (st_symmetry.contradiction),
 * counted on every sample (the soup's rims made if no count made them);
 * rotations and helices 1, not counted. A sum per mirror: the same for
 * any thread count. */
static void mirror_contradictions(const ctx *C, st_symmetry_set *out)
{
    for (size_t i = 0; i < out->n; i++) {
        st_symmetry *y = out->items + i;
        y->contradiction = 1.0;
        if (y->kind != ST_SYMMETRY_MIRROR)
            continue;
        rims_need(C);
        const tally t = measure_run(C, y, 0.0, 1, 1, 0.0, NULL);
        y->contradiction = contradiction(&t);
    }
}

/* The samples and each triangle's unit normal (the rims come later:
 * rims_need). */
static st_status ctx_make(ctx *C, const st_soup *s, samples *S, size_t want, st_error *err)
{
    memset(S, 0, sizeof *S);
    C->tn = st_malloc_array(3 * (s->ntris ? s->ntris : 1), sizeof *C->tn);
    C->fr = st_malloc_array(s->ntris ? s->ntris : 1, sizeof *C->fr);
    if (!C->tn || !C->fr || samples_make(S, s, want))
        return st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory for the symmetry samples");
    if (S->n == 0)
        return ST_OK;
    for (size_t t = 0; t < s->ntris; t++) {
        const uint32_t *v = s->tris + 3 * t;
        double u[3], w[3];
        st_sub3(u, s->xyz + 3 * (size_t)v[1], s->xyz + 3 * (size_t)v[0]);
        st_sub3(w, s->xyz + 3 * (size_t)v[2], s->xyz + 3 * (size_t)v[0]);
        st_cross3(C->tn + 3 * t, u, w);
        normalize(C->tn + 3 * t);
        st_tri_frame_make(C->fr + t, s->xyz + 3 * (size_t)v[0], s->xyz + 3 * (size_t)v[1],
                          s->xyz + 3 * (size_t)v[2]);
    }
    grid_make(&C->grid, s, C->tol, S->area);
    return ST_OK;
}

static void ctx_free(ctx *C, samples *S)
{
    grid_free(&C->grid);
    free(C->tn);
    free(C->fr);
    free(C->R->rim);
    samples_free(S);
}

st_status st_symmetry_detect(st_symmetry_set *out, const st_soup *s,
                             const st_bvh *bvh, const st_symmetry_params *p,
                             st_error *err)
{
    memset(out, 0, sizeof *out);
    if (!(p->tolerance > 0.0) || !isfinite(p->tolerance) || p->samples < 16 ||
        p->max_order < 2 || !(p->min_support > 0.0 && p->min_support <= 1.0))
        return st_error_set(err, ST_EINPUT, NULL, 0,
                            "symmetry: the tolerance must be positive, at "
                            "least 16 samples, order >= 2, support in (0, "
                            "1]");
    samples S;
    rims R = {NULL, 0, {0}};
    ctx C = {.s = s, .bvh = bvh, .S = &S, .tol = p->tolerance, .R = &R};
    st_status rc = ctx_make(&C, s, &S, p->samples, err);
    if (rc || S.n == 0) {
        ctx_free(&C, &S);
        return rc;
    }

    /* mirrors: principal planes and the votes, refined, measured */
    st_symmetry cand[3 + VOTE_CANDIDATES + VOTE_PEAKS];
    size_t nc = 0, nv, npeak;
    for (int a = 0; a < 3; a++) {
        double n[3] = {S.axes[a][0], S.axes[a][1], S.axes[a][2]};
        double off = st_dot3(n, S.c);
        canon_plane(n, &off);
        cand[nc++] = mirror_of(n, off);
    }
    vote_mirrors(&C, cand + nc, VOTE_CANDIDATES, VOTE_PEAKS, &nv, &npeak);
    nc += nv;
    const size_t first_peak = nc;
    nc += npeak;
    st_symmetry mirrors[3 + VOTE_CANDIDATES + VOTE_PEAKS];
    size_t nm = 0;
    int ok[3 + VOTE_CANDIDATES + VOTE_PEAKS], screened[3 + VOTE_CANDIDATES + VOTE_PEAKS];
    measure_mirrors(&C, p, cand, ok, screened, 0, first_peak, 0, 0);
    collect_mirrors(cand, ok, 0, first_peak, p->tolerance, mirrors, &nm);
    /* the peaks: a second look where the sharpest cells give no plane */
    if (nm == 0 && nc > first_peak) {
        measure_mirrors(&C, p, cand, ok, screened, first_peak, nc, REFINE_COARSE, 0);
        collect_mirrors(cand, ok, first_peak, nc, p->tolerance, mirrors, &nm);
    } else {
        nc = first_peak;
    }
    /* a third where still none holds: the screened candidates refined
     * point to plane (doc/design/symmetry.md, "Point to plane") */
    if (nm == 0) {
        measure_mirrors(&C, p, cand, ok, screened, 0, nc, 0, 1);
        collect_mirrors(cand, ok, 0, nc, p->tolerance, mirrors, &nm);
    }
    out->candidates += nc;
    for (size_t i = 0; i < nm; i++)
        keep(out, mirrors + i, p->tolerance);

    /* rotation axes: where two mirrors meet, and the principal axes */
    st_symmetry axes[3 + 15]; /* the meets of the best six mirrors */
    size_t na = 0;
    /* the best mirrors first; the meets of the best six */
    qsort(mirrors, nm, sizeof *mirrors, cmp_sym);
    for (size_t i = 0; i < nm && i < 6; i++)
        for (size_t j = i + 1; j < nm && j < 6; j++) {
            st_symmetry l;
            if (meet(mirrors + i, mirrors + j, &l))
                axes[na++] = l;
        }
    for (int a = 0; a < 3; a++) {
        st_symmetry l;
        memset(&l, 0, sizeof l);
        l.kind = ST_SYMMETRY_ROTATION;
        for (int x = 0; x < 3; x++) {
            l.point[x] = S.c[x];
            l.dir[x] = S.axes[a][x];
        }
        axes[na++] = l;
    }
    for (size_t i = 0; i < na; i++) {
        int dup = 0;
        for (size_t j = 0; j < i && !dup; j++)
            dup = same_line(axes + j, axes + i, p->tolerance);
        if (dup)
            continue;
        /* a set full of other kinds takes no axis (keep): not measured */
        const int helix = room_for(out, ST_SYMMETRY_HELIX),
                  turn = room_for(out, ST_SYMMETRY_ROTATION);
        if (!helix && !turn)
            continue;
        double sup = 0.0;
        out->candidates++;
        st_symmetry hx = axes[i];
        int measured = 0;
        if (helix && find_helix(&C, &hx, p->min_support, &measured))
            keep(out, &hx, p->tolerance);
        out->candidates += (size_t)measured;
        if (!turn)
            continue;
        int order = axis_order(&C, axes + i, p->max_order, p->min_support,
                               &sup);
        if (order < 0)
            continue;
        axes[i].order = order;
        axes[i].support = sup;
        keep(out, axes + i, p->tolerance);
    }
    one_screw_per_line(out, p->tolerance);
    qsort(out->items, out->n, sizeof *out->items, cmp_sym);
    mirror_contradictions(&C, out);
    const int rims_failed = R.tried && !R.rim;
    ctx_free(&C, &S);
    if (rims_failed) {
        memset(out, 0, sizeof *out);
        if (err)
            *err = R.err;
        return R.err.status ? R.err.status : ST_ENOMEM;
    }
    return ST_OK;
}

/* ---- the gate: where no fill can matter (st_symmetry_fill_may_act) -------- */

typedef struct gate_point {
    double x[3];
    size_t v;
} gate_point;

static int cmp_gate_point(const void *a, const void *b)
{
    const gate_point *p = a, *q = b;
    for (int k = 0; k < 3; k++)
        if (p->x[k] != q->x[k])
            return p->x[k] < q->x[k] ? -1 : 1;
    return p->v < q->v ? -1 : p->v > q->v;
}

/* group[v]: the caps' groups, each named by its smallest vertex:
 * triangles joined by a shared vertex or position (coarser than the
 * fill's pieces, which share an edge, so no piece's reach exceeds its
 * group's); reach[g]: half group g's box diagonal. ST_ENOMEM. */
static st_status caps_groups(size_t *group, double *reach, const st_soup *caps)
{
    const size_t nv = caps->nverts;
    gate_point *pt = st_malloc_array(nv ? nv : 1, sizeof *pt);
    double *box = st_malloc_array(nv ? 6 * nv : 1, sizeof *box);
    if (!pt || !box) {
        free(pt);
        free(box);
        return ST_ENOMEM;
    }
    for (size_t v = 0; v < nv; v++) {
        memcpy(pt[v].x, caps->xyz + 3 * v, sizeof pt[v].x);
        pt[v].v = group[v] = v;
    }
    qsort(pt, nv, sizeof *pt, cmp_gate_point);
    for (size_t i = 1; i < nv; i++)
        if (memcmp(pt[i - 1].x, pt[i].x, sizeof pt[i].x) == 0)
            uf_join(group, pt[i - 1].v, pt[i].v);
    for (size_t t = 0; t < caps->ntris; t++) {
        uf_join(group, caps->tris[3 * t], caps->tris[3 * t + 1]);
        uf_join(group, caps->tris[3 * t], caps->tris[3 * t + 2]);
    }
    /* each group's box at its name, which comes first */
    for (size_t v = 0; v < nv; v++) {
        const size_t g = group[v] = uf_find(group, v);
        const double *x = caps->xyz + 3 * v;
        for (int k = 0; k < 3; k++) {
            box[6 * g + k] = g == v ? x[k] : fmin(box[6 * g + k], x[k]);
            box[6 * g + 3 + k] = g == v ? x[k] : fmax(box[6 * g + 3 + k], x[k]);
        }
    }
    for (size_t v = 0; v < nv; v++) {
        const double *b = box + 6 * v;
        const double d[3] = {b[3] - b[0], b[4] - b[1], b[5] - b[2]};
        reach[v] = group[v] == v ? 0.5 * st_norm3(d) : 0.0;
    }
    free(pt);
    free(box);
    return ST_OK;
}

/* The largest distance from a triangle's centroid to its corners, over s. */
static double triangle_spread(const st_soup *s)
{
    double most = 0.0;
    for (size_t t = 0; t < s->ntris; t++) {
        const double *x[3];
        double c[3];
        for (int k = 0; k < 3; k++)
            x[k] = s->xyz + 3 * s->tris[3 * t + k];
        for (int a = 0; a < 3; a++)
            c[a] = (x[0][a] + x[1][a] + x[2][a]) / 3.0;
        for (int k = 0; k < 3; k++) {
            const double d[3] = {x[k][0] - c[0], x[k][1] - c[1], x[k][2] - c[2]};
            most = fmax(most, st_dot3(d, d));
        }
    }
    return sqrt(most);
}

/* The largest distance from a point of triangle x to its nearest corner.
 * That distance, over a cell of the corners' Voronoi diagram within the
 * triangle, is convex, so it peaks at a vertex of the cell: on the
 * triangle's boundary, within half its edge of an end of that edge, or at
 * the circumcentre, inside where x is acute. So: the circumradius (with
 * 2^-20 of it for rounding) where x is acute, else half the longest edge. */
static double corner_reach(const double *x[3])
{
    double e[3][3], l2[3];
    for (int k = 0; k < 3; k++) {
        const double *a = x[(k + 1) % 3], *b = x[(k + 2) % 3];
        for (int c = 0; c < 3; c++)
            e[k][c] = b[c] - a[c];
        l2[k] = st_dot3(e[k], e[k]);
    }
    const double most = fmax(l2[0], fmax(l2[1], l2[2]));
    double n[3];
    st_cross3(n, e[0], e[1]);
    const double twice_area = st_norm3(n);
    if (2.0 * most < l2[0] + l2[1] + l2[2] && twice_area > 0.0) {
        const double r = sqrt(l2[0]) * sqrt(l2[1]) * sqrt(l2[2]) / (2.0 * twice_area);
        return fmax(r * (1.0 + ldexp(1.0, -20)), 0.5 * sqrt(most));
    }
    return 0.5 * sqrt(most);
}

/* How many of the caps' groups an image may fill: those where neither
 * holds, for every cap triangle t of the group:
 * - no image is kept: t's corners lie within `on` of s, and a point
 *   within the group's reach of t (the centroid of an image the fill
 *   keeps for it: within its piece's reach of the caps, nearest t) is
 *   within sqrt(reach^2 + h^2) of a corner (h: corner_reach; t is convex
 *   and the point's nearest in t is a foot), so within tol of s, where
 *   the fill keeps no image;
 * - no image kept departs from the caps: reach + spread < tol.
 * bad[g] (g: the group's name, size caps->nverts) is scratch. */
static size_t groups_active(uint8_t *bad, const size_t *group, const double *reach,
                            const st_soup *caps, const st_bvh *bvh, double spread,
                            double margin, double tol)
{
    memset(bad, 0, caps->nverts);
    for (size_t t = 0; t < caps->ntris; t++) {
        const size_t g = group[caps->tris[3 * t]];
        if (bad[g] || reach[g] + spread + margin < tol)
            continue;
        const double *x[3];
        double on = 0.0;
        for (int k = 0; k < 3; k++) {
            x[k] = caps->xyz + 3 * caps->tris[3 * t + k];
            int64_t tri;
            const double d2 = st_bvh_nearest(bvh, x[k], tol * tol, &tri, NULL);
            on = tri < 0 ? INFINITY : fmax(on, sqrt(d2));
        }
        const double h = corner_reach(x);
        bad[g] = !(sqrt(reach[g] * reach[g] + h * h) + on + margin < tol);
    }
    size_t n = 0;
    for (size_t v = 0; v < caps->nverts; v++)
        n += bad[v];
    return n;
}

/* The boundary edges of s (in one triangle alone; E: its table) whose
 * midpoint lies farther than tol from every cap (caps_bvh; NULL: no
 * caps) and that close into loops: two such edges at each welded end of
 * theirs, as st_symmetry_fill's open rims (an open rim is such a loop).
 * *n gets their number. ST_ENOMEM. */
static st_status loops_off_caps(size_t *n, const st_soup *s, const st_soup_edges *E,
                                const st_bvh *caps_bvh, double tol)
{
    *n = 0;
    const size_t nw = E->nweld ? E->nweld : 1;
    size_t *uf = st_malloc_array(nw, sizeof *uf);
    uint32_t *deg = calloc(nw, sizeof *deg);
    uint64_t *off = st_malloc_array(E->nhalf ? E->nhalf : 1, sizeof *off);
    uint8_t *pinched = calloc(nw, 1);
    st_status rc = uf && deg && off && pinched ? ST_OK : ST_ENOMEM;
    for (size_t w = 0; w < nw && !rc; w++)
        uf[w] = w;
    size_t m = 0;
    for (size_t i = 0, next; i < E->nhalf && !rc; i = next) {
        next = st_soup_edges_run_end(E, i);
        if (next != i + 1)
            continue;   /* not a boundary edge */
        const uint32_t t = E->he[i].t, wa = (uint32_t)(E->he[i].key >> 32);
        const uint32_t wb = (uint32_t)E->he[i].key;
        const int a = st_soup_edges_corner(E, s, t, wa), b = st_soup_edges_corner(E, s, t, wb);
        if (a < 0 || b < 0)
            continue;
        const double *p = s->xyz + 3 * s->tris[3 * t + a], *q = s->xyz + 3 * s->tris[3 * t + b];
        const double mid[3] = {0.5 * (p[0] + q[0]), 0.5 * (p[1] + q[1]), 0.5 * (p[2] + q[2])};
        if (caps_bvh && st_bvh_within(caps_bvh, mid, tol * tol))
            continue;
        off[m++] = E->he[i].key;
        uf_join(uf, wa, wb);
        deg[wa]++;
        deg[wb]++;
    }
    for (size_t w = 0; w < nw && !rc; w++)
        if (deg[w] && deg[w] != 2)
            pinched[uf_find(uf, w)] = 1;
    for (size_t k = 0; k < m; k++)
        *n += !pinched[uf_find(uf, (size_t)(off[k] >> 32))];
    free(uf);
    free(deg);
    free(off);
    free(pinched);
    return rc;
}

st_status st_symmetry_fill_may_act(int *may, st_symmetry_fill_gate *gate, const st_soup *s,
                                   const st_soup_edges *edges, const st_bvh *bvh,
                                   const st_soup *caps, double tol, st_error *err)
{
    st_symmetry_fill_gate local;
    st_symmetry_fill_gate *g = gate ? gate : &local;
    memset(g, 0, sizeof *g);
    *may = 1;
    if (!s || !bvh || !(tol > 0.0) || !isfinite(tol))
        return st_error_set(err, ST_EINPUT, NULL, 0,
                            "symmetry gate: no soup, or a tolerance not positive and finite");
    if (s->ntris == 0) {
        *may = 0;   /* the fill has nothing to map */
        return ST_OK;
    }
    const size_t nv = caps ? caps->nverts : 0;
    size_t *group = st_malloc_array(nv ? nv : 1, sizeof *group);
    double *reach = st_malloc_array(nv ? nv : 1, sizeof *reach);
    uint8_t *bad = st_malloc_array(nv ? nv : 1, 1);
    st_bvh *caps_bvh = NULL;
    st_status rc = group && reach && bad ? ST_OK : ST_ENOMEM;
    const int any = caps && caps->ntris;
    rc = rc || !any ? rc : caps_groups(group, reach, caps);
    rc = rc || !any || !edges ? rc : st_bvh_build(&caps_bvh, caps, err);
    rc = rc || !edges ? rc : loops_off_caps(&g->open_edges, s, edges, caps_bvh, tol);
    if (!rc && g->open_edges) {
        g->spread = NAN;   /* not needed: an open rim is enough */
    } else if (!rc) {
        /* the images' rounding: a few units in the last place of
         * coordinates of the soup's size, far below 2^-30 of them */
        double lo[3], hi[3], big = 0.0;
        st_soup_bounds(s, lo, hi, NULL);
        for (int k = 0; k < 3; k++)
            big = fmax(big, fmax(fabs(lo[k]), fabs(hi[k])));
        for (size_t v = 0; v < nv && any; v++)
            if (group[v] == v) {
                g->reach = fmax(g->reach, reach[v]);
                g->pieces++;
            }
        /* the first test alone; the second needs the spread, a pass over
         * s, and runs only where the first fails */
        g->spread = INFINITY;
        g->margin = ldexp(big + g->reach, -30);
        g->active = any ? groups_active(bad, group, reach, caps, bvh, INFINITY, g->margin, tol)
                        : 0;
        if (g->active) {
            g->spread = triangle_spread(s);
            g->margin = ldexp(big + g->spread + g->reach, -30);
            g->active = groups_active(bad, group, reach, caps, bvh, g->spread, g->margin, tol);
        }
        *may = g->open_edges > 0 || g->active > 0;
    }
    st_bvh_free(caps_bvh);
    free(group);
    free(reach);
    free(bad);
    if (rc == ST_ENOMEM)
        return st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory for the symmetry gate");
    return rc;
}
