/*
 * lattice.c - cubic (5 tets per cube, mirrored) and BCC lattices over a box,
 * voxel counting in tets, and the pseudo-volume density filter.
 *
 * References: J. Spillmann, M. Wagner, M. Teschner, "Robust Tetrahedral
 * Meshing of Triangle Soups", VMV 2006, section 4 (cubic lattice, density
 * rho); D. A. Stuart, J. A. Levine, B. Jones, A. W. Bargteil, "Automatic
 * Construction of Coarse, High-Quality Tetrahedralizations that Enclose and
 * Approximate Surfaces for Animation", MIG 2013, section 3.1 (BCC lattice);
 * K. Shoemake, "Uniform random rotations", Graphics Gems III, 1992.
 *
 * See lattice.h for the contracts. Vertex ids come from integer lattice
 * coordinates; adjacency is found by bucketing faces by their smallest
 * vertex id (linear time, no hashing, deterministic).
 */
#include "souptet/lattice.h"
#include "../base/fpenv.h"
#include "souptet/isect.h"
#include "souptet/mem.h"
#include "souptet/progress.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

const char *st_lattice_kind_name(st_lattice_kind kind)
{
    return kind == ST_LATTICE_BCC ? "bcc" : "cubic5";
}

int st_lattice_kind_from_name(const char *name, st_lattice_kind *kind)
{
    if (name && strcmp(name, "cubic5") == 0) {
        *kind = ST_LATTICE_CUBIC5;
        return 0;
    }
    if (name && strcmp(name, "bcc") == 0) {
        *kind = ST_LATTICE_BCC;
        return 0;
    }
    return -1;
}

st_lattice_params st_lattice_params_default(void)
{
    st_lattice_params p;
    p.kind = ST_LATTICE_CUBIC5;
    p.h = 1.0;
    p.seed = 0;
    p.pad = ST_LATTICE_PAD_DEFAULT;
    p.max_tets = 0;
    p.cancel = NULL;
    return p;
}

/* ---- the generator: splitmix64 (Steele, Lea, Flood 2014) ---- */

static uint64_t splitmix64(uint64_t *state)
{
    uint64_t z = (*state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

/* Uniform in [0, 1) with 53 random bits. */
static double uniform01(uint64_t *state)
{
    return (double)(splitmix64(state) >> 11) * 0x1.0p-53;
}

/* Shoemake's uniformly random unit quaternion, as a rotation matrix. */
static void random_rotation(uint64_t *state, double R[9])
{
    double u1 = uniform01(state), u2 = uniform01(state), u3 = uniform01(state);
    double a = sqrt(1.0 - u1), b = sqrt(u1);
    double x = a * sin(2 * M_PI * u2), y = a * cos(2 * M_PI * u2);
    double z = b * sin(2 * M_PI * u3), w = b * cos(2 * M_PI * u3);
    R[0] = 1 - 2 * (y * y + z * z);
    R[1] = 2 * (x * y - z * w);
    R[2] = 2 * (x * z + y * w);
    R[3] = 2 * (x * y + z * w);
    R[4] = 1 - 2 * (x * x + z * z);
    R[5] = 2 * (y * z - x * w);
    R[6] = 2 * (x * z - y * w);
    R[7] = 2 * (y * z + x * w);
    R[8] = 1 - 2 * (x * x + y * y);
}

/* ---- small helpers ---- */

void st_lattice_grid_box(const st_grid *g, double lo[3], double hi[3])
{
    size_t n[3] = {g->nx, g->ny, g->nz};
    for (int a = 0; a < 3; a++) {
        lo[a] = g->origin[a] - 0.5 * g->voxel;
        hi[a] = g->origin[a] + ((double)n[a] - 0.5) * g->voxel;
    }
}

double st_lattice_h_for_cells(const double lo[3], const double hi[3],
                              size_t cells)
{
    double ext = 0;
    for (int a = 0; a < 3; a++)
        if (hi[a] - lo[a] > ext)
            ext = hi[a] - lo[a];
    return cells ? ext / (double)cells : 0.0;
}

static size_t corner_count(const st_lattice *L)
{
    return (L->n[0] + 1) * (L->n[1] + 1) * (L->n[2] + 1);
}

static uint32_t corner_id(const st_lattice *L, size_t i, size_t j, size_t k)
{
    return (uint32_t)(i + (L->n[0] + 1) * (j + (L->n[1] + 1) * k));
}

static uint32_t centre_id(const st_lattice *L, size_t i, size_t j, size_t k)
{
    return (uint32_t)(corner_count(L) + i + L->n[0] * (j + L->n[1] * k));
}

/* Integer coordinates relative to the block (half cells). */
static void local_coords(const st_lattice *L, uint32_t v, int64_t g[3])
{
    size_t nc = corner_count(L);
    if (v < nc) {
        size_t i = v % (L->n[0] + 1), r = v / (L->n[0] + 1);
        g[0] = 2 * (int64_t)i;
        g[1] = 2 * (int64_t)(r % (L->n[1] + 1));
        g[2] = 2 * (int64_t)(r / (L->n[1] + 1));
    } else {
        size_t c = v - nc;
        size_t i = c % L->n[0], r = c / L->n[0];
        g[0] = 2 * (int64_t)i + 1;
        g[1] = 2 * (int64_t)(r % L->n[1]) + 1;
        g[2] = 2 * (int64_t)(r / L->n[1]) + 1;
    }
}

void st_lattice_vertex_coords(const st_lattice *L, uint32_t v, int64_t g[3])
{
    local_coords(L, v, g);
    for (int a = 0; a < 3; a++)
        g[a] += 2 * L->cell_lo[a];
}

/* Sign of (b-a).((c-a)x(d-a)) on integer coordinates (exact: the values
 * are a few cells apart, far from overflow). */
static int64_t idet(const int64_t a[3], const int64_t b[3], const int64_t c[3],
                    const int64_t d[3])
{
    int64_t u[3], v[3], w[3];
    for (int k = 0; k < 3; k++) {
        u[k] = b[k] - a[k];
        v[k] = c[k] - a[k];
        w[k] = d[k] - a[k];
    }
    return u[0] * (v[1] * w[2] - v[2] * w[1]) -
           u[1] * (v[0] * w[2] - v[2] * w[0]) +
           u[2] * (v[0] * w[1] - v[1] * w[0]);
}

/* Append tet (a b c d), positively oriented by its integer coordinates. */
static void put_tet(st_lattice *L, size_t *nt, uint32_t a, uint32_t b,
                    uint32_t c, uint32_t d)
{
    int64_t ga[3], gb[3], gc[3], gd[3];
    local_coords(L, a, ga);
    local_coords(L, b, gb);
    local_coords(L, c, gc);
    local_coords(L, d, gd);
    uint32_t *t = L->tets + 4 * *nt;
    t[0] = a;
    t[1] = b;
    if (idet(ga, gb, gc, gd) > 0) {
        t[2] = c;
        t[3] = d;
    } else {
        t[2] = d;
        t[3] = c;
    }
    (*nt)++;
}

void st_lattice_free(st_lattice *L)
{
    if (!L)
        return;
    free(L->xyz);
    free(L->tets);
    free(L->nbr);
    free(L->star_off);
    free(L->star);
    free(L);
}

/* Face (t, i), the face opposite corner i: its vertex ids ascending. */
static void face_sorted(const st_lattice *L, size_t t, int i, uint32_t f[3])
{
    int n = 0;
    for (int c = 0; c < 4; c++)
        if (c != i)
            f[n++] = L->tets[4 * t + (size_t)c];
    uint32_t x;
    if (f[0] > f[1]) { x = f[0]; f[0] = f[1]; f[1] = x; }
    if (f[1] > f[2]) { x = f[1]; f[1] = f[2]; f[2] = x; }
    if (f[0] > f[1]) { x = f[0]; f[0] = f[1]; f[1] = x; }
}

/* One stable counting-sort pass: the faces in[0 .. nf) by their id
 * number c (fs[3 f + c]) into out; cnt has nv + 1 slots. */
static void face_pass(const uint32_t *fs, int c, const uint32_t *in, uint32_t *out, size_t nf,
                      size_t *cnt, size_t nv)
{
    memset(cnt, 0, (nv + 1) * sizeof *cnt);
    for (size_t a = 0; a < nf; a++)
        cnt[fs[3 * (size_t)in[a] + (size_t)c] + 1]++;
    for (size_t v = 0; v < nv; v++)
        cnt[v + 1] += cnt[v];
    for (size_t a = 0; a < nf; a++)
        out[cnt[fs[3 * (size_t)in[a] + (size_t)c]]++] = in[a];
}

/* Face adjacency: the faces sorted by their three ids (three counting
 * passes, the largest id first), a face and the next one with the same ids
 * are the two sides of one face; star CSR. */
static st_status build_topology(st_lattice *L, const st_progress *stop, st_error *err)
{
    size_t nv = L->nverts, nt = L->ntets, nf = 4 * nt;
    if (nf > UINT32_MAX)   /* faces are numbered in 32 bits */
        return st_error_set(err, ST_ELIMIT, NULL, 0, "lattice of %zu tets is too large", nt);
    size_t *cnt = st_malloc_array(nv + 1, sizeof *cnt);
    uint32_t *fs = st_malloc_array(nf ? 3 * nf : 1, sizeof *fs);
    uint32_t *ord = st_malloc_array(nf ? nf : 1, sizeof *ord);
    uint32_t *tmp = st_malloc_array(nf ? nf : 1, sizeof *tmp);
    L->nbr = st_malloc_array(nf, sizeof *L->nbr);
    L->star_off = st_calloc_array(nv + 1, sizeof *L->star_off);
    L->star = st_malloc_array(nf, sizeof *L->star);
    st_status st = ST_OK;
    if (!cnt || !fs || !ord || !tmp || !L->nbr || !L->star_off || !L->star) {
        st = st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory for the lattice's adjacency");
        goto done;
    }
    for (size_t t = 0; t < nt; t++)
        for (int i = 0; i < 4; i++) {
            size_t f = 4 * t + (size_t)i;
            face_sorted(L, t, i, fs + 3 * f);
            ord[f] = (uint32_t)f;
            L->star_off[L->tets[f] + 1]++;
        }
    for (size_t v = 0; v < nv; v++)
        L->star_off[v + 1] += L->star_off[v];
    memcpy(cnt, L->star_off, (nv + 1) * sizeof *cnt);
    for (size_t t = 0; t < nt; t++)
        for (int i = 0; i < 4; i++)
            L->star[cnt[L->tets[4 * t + (size_t)i]]++] = (uint32_t)t;
    if (st_progress_cancelled(stop)) {
        st = st_error_set(err, ST_ECANCELLED, NULL, 0, "cancelled");
        goto done;
    }
    face_pass(fs, 2, ord, tmp, nf, cnt, nv);
    face_pass(fs, 1, tmp, ord, nf, cnt, nv);
    face_pass(fs, 0, ord, tmp, nf, cnt, nv);
    for (size_t f = 0; f < nf; f++)
        L->nbr[f] = -1;
    for (size_t a = 0; a + 1 < nf; a++) {
        const uint32_t *x = fs + 3 * (size_t)tmp[a], *y = fs + 3 * (size_t)tmp[a + 1];
        if (x[0] != y[0] || x[1] != y[1] || x[2] != y[2])
            continue;
        if (a + 2 < nf && memcmp(fs + 3 * (size_t)tmp[a + 2], x, 3 * sizeof *x) == 0) {
            st = st_error_set(err, ST_EINTERNAL, NULL, 0,
                              "lattice face shared by more than two tets");
            break;
        }
        L->nbr[tmp[a]] = (int64_t)(tmp[a + 1] / 4);
        L->nbr[tmp[a + 1]] = (int64_t)(tmp[a] / 4);
        a++;
    }
done:
    free(cnt);
    free(fs);
    free(ord);
    free(tmp);
    return st;
}

/* The lattice's frame: centred on the box; axis-aligned at the box's
 * corner with seed 0, else a random rotation and offset from the seed. */
static void lattice_frame(st_lattice *L, const double lo[3], const double hi[3],
                          const st_lattice_params *p)
{
    L->kind = p->kind;
    L->h = p->h;
    L->seed = p->seed;
    for (int a = 0; a < 3; a++)
        L->center[a] = 0.5 * (lo[a] + hi[a]);
    if (p->seed == 0) {
        for (int k = 0; k < 9; k++)
            L->rot[k] = (k % 4 == 0) ? 1.0 : 0.0;
        for (int a = 0; a < 3; a++)
            L->offset[a] = lo[a] - L->center[a];
    } else {
        uint64_t state = p->seed;
        random_rotation(&state, L->rot);
        for (int a = 0; a < 3; a++)
            L->offset[a] = uniform01(&state) * p->h;
    }
}

/* The cells that cover the box in the lattice frame, padded (cell_lo, n),
 * and the vertex count; *cap the tet count. ST_ELIMIT when an axis or the
 * whole is over the limits. */
static st_status lattice_cells(st_lattice *L, size_t *cap, const double lo[3],
                               const double hi[3], const st_lattice_params *p,
                               st_error *err)
{
    /* The box in the lattice frame: u = R^T (x - center). */
    double umin[3] = {INFINITY, INFINITY, INFINITY};
    double umax[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (int c = 0; c < 8; c++) {
        double x[3] = {(c & 1) ? hi[0] : lo[0], (c & 2) ? hi[1] : lo[1],
                       (c & 4) ? hi[2] : lo[2]};
        for (int a = 0; a < 3; a++) {
            double u = 0;
            for (int b = 0; b < 3; b++)
                u += L->rot[3 * b + a] * (x[b] - L->center[b]);
            if (u < umin[a])
                umin[a] = u;
            if (u > umax[a])
                umax[a] = u;
        }
    }
    double ncells = 1;
    for (int a = 0; a < 3; a++) {
        double c0 = floor((umin[a] - L->offset[a]) / p->h);
        double c1 = ceil((umax[a] - L->offset[a]) / p->h);
        if (c1 <= c0)
            c1 = c0 + 1;   /* a flat box still gets one layer of cells */
        c0 -= p->pad;
        c1 += p->pad;
        if (!(c1 - c0 < 1e7))
            return st_error_set(err, ST_ELIMIT, NULL, 0,
                                "lattice of cell width %g has too many "
                                "cells along an axis", p->h);
        L->cell_lo[a] = (int64_t)c0;
        L->n[a] = (size_t)(c1 - c0);
        ncells *= (double)L->n[a];
    }
    double tets_per_cell = p->kind == ST_LATTICE_BCC ? 12.0 : 5.0;
    double ntets_d = ncells * tets_per_cell;
    double nverts_d = (double)(L->n[0] + 1) * (double)(L->n[1] + 1) *
                      (double)(L->n[2] + 1) +
                      (p->kind == ST_LATTICE_BCC ? ncells : 0.0);
    if ((p->max_tets && ntets_d > (double)p->max_tets) ||
        nverts_d >= 4294967295.0 || ntets_d >= 4294967295.0 / 4)
        return st_error_set(err, ST_ELIMIT, NULL, 0,
                            "a lattice of %.0f tets (%zux%zux%zu cells) is over "
                            "the limit (use fewer cells)",
                            ntets_d, L->n[0], L->n[1], L->n[2]);
    L->nverts = (size_t)nverts_d;
    *cap = (size_t)ntets_d;
    return ST_OK;
}

/* Every vertex's position: x = center + R (offset + g h / 2). */
static void lattice_vertices(st_lattice *L)
{
    for (size_t v = 0; v < L->nverts; v++) {
        int64_t g[3];
        st_lattice_vertex_coords(L, (uint32_t)v, g);
        double u[3];
        for (int a = 0; a < 3; a++)
            u[a] = L->offset[a] + (double)g[a] * (0.5 * L->h);
        for (int a = 0; a < 3; a++)
            L->xyz[3 * v + (size_t)a] = L->center[a] + L->rot[3 * a] * u[0] +
                                        L->rot[3 * a + 1] * u[1] +
                                        L->rot[3 * a + 2] * u[2];
    }
}

/* Cube (i, j, k) of the 5-tet lattice: a central tet and four corners. */
static void cubic5_cell(st_lattice *L, size_t *nt, size_t i, size_t j, size_t k)
{
    /* Corner c = (a, b, cc) bits; global parity decides which four
     * corners form the central tet. */
    int64_t par = (int64_t)(i + j + k) + L->cell_lo[0] + L->cell_lo[1] +
                  L->cell_lo[2];
    uint32_t v[8];
    uint32_t ev[4], od[4];
    int ne = 0, no = 0;
    for (int c = 0; c < 8; c++) {
        int a = c & 1, b = (c >> 1) & 1, cc = (c >> 2) & 1;
        v[c] = corner_id(L, i + (size_t)a, j + (size_t)b, k + (size_t)cc);
        if (((a + b + cc + par) & 1) == 0)
            ev[ne++] = (uint32_t)c;
        else
            od[no++] = (uint32_t)c;
    }
    put_tet(L, nt, v[ev[0]], v[ev[1]], v[ev[2]], v[ev[3]]);
    for (int o = 0; o < 4; o++) {
        uint32_t nb[3];
        for (int b = 0; b < 3; b++)
            nb[b] = v[od[o] ^ (1u << b)];
        put_tet(L, nt, v[od[o]], nb[0], nb[1], nb[2]);
    }
}

/* Cell (i, j, k) of the BCC lattice: the four tets around each face it
 * shares with its lower neighbours, between the two centres. */
static void bcc_cell(st_lattice *L, size_t *nt, size_t i, size_t j, size_t k)
{
    size_t ci[3] = {i, j, k};
    uint32_t cthis = centre_id(L, i, j, k);
    for (int ax = 0; ax < 3; ax++) {
        if (ci[ax] == 0)
            continue;
        size_t cn[3] = {i, j, k};
        cn[ax]--;
        uint32_t cnbr = centre_id(L, cn[0], cn[1], cn[2]);
        int u = (ax + 1) % 3, w = (ax + 2) % 3;
        /* The face's corners in cyclic order. */
        static const int du[4] = {0, 1, 1, 0};
        static const int dw[4] = {0, 0, 1, 1};
        uint32_t fc[4];
        for (int q = 0; q < 4; q++) {
            size_t cc[3] = {i, j, k};
            cc[u] += (size_t)du[q];
            cc[w] += (size_t)dw[q];
            fc[q] = corner_id(L, cc[0], cc[1], cc[2]);
        }
        for (int q = 0; q < 4; q++)
            put_tet(L, nt, fc[q], fc[(q + 1) % 4], cthis, cnbr);
    }
}

st_status st_lattice_build(st_lattice **out, const double lo[3],
                           const double hi[3], const st_lattice_params *p,
                           st_error *err)
{
    *out = NULL;
    for (int a = 0; a < 3; a++)
        if (!isfinite(lo[a]) || !isfinite(hi[a]) || lo[a] > hi[a])
            return st_error_set(err, ST_EINPUT, NULL, 0,
                                "lattice box is empty or not finite");
    if (!(p->h > 0) || !isfinite(p->h))
        return st_error_set(err, ST_EINPUT, NULL, 0,
                            "lattice cell width %g is not a positive number",
                            p->h);
    if (p->pad < 0 || p->pad > 1000)
        return st_error_set(err, ST_EINPUT, NULL, 0,
                            "lattice padding %d is out of range", p->pad);
    st_lattice *L = calloc(1, sizeof *L);
    if (!L)
        return st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory");
    const st_progress stop = {NULL, NULL, p->cancel};
    size_t cap = 0, nt = 0;
    lattice_frame(L, lo, hi, p);
    st_status st = lattice_cells(L, &cap, lo, hi, p, err);
    if (st)
        goto done;
    L->xyz = st_malloc_array(L->nverts, 3 * sizeof(double));
    L->tets = st_malloc_array(cap, 4 * sizeof(uint32_t));
    if (!L->xyz || !L->tets) {
        st = st_error_set(err, ST_ENOMEM, NULL, 0,
                          "out of memory for a lattice of %zu tets", cap);
        goto done;
    }
    lattice_vertices(L);
    for (size_t k = 0; k < L->n[2]; k++) {
        if (st_progress_cancelled(&stop)) {
            st = st_error_set(err, ST_ECANCELLED, NULL, 0, "cancelled");
            goto done;
        }
        for (size_t j = 0; j < L->n[1]; j++)
            for (size_t i = 0; i < L->n[0]; i++) {
                if (p->kind == ST_LATTICE_CUBIC5)
                    cubic5_cell(L, &nt, i, j, k);
                else
                    bcc_cell(L, &nt, i, j, k);
            }
    }
    L->ntets = nt;
    st = build_topology(L, &stop, err);
done:
    if (st)
        st_lattice_free(L);
    else
        *out = L;
    return st;
}

st_status st_lattice_to_tetmesh(st_tetmesh **out, const st_lattice *L,
                                const unsigned char *keep, st_error *err)
{
    *out = NULL;
    uint32_t *map = st_malloc_array(L->nverts, sizeof *map);
    st_tetmesh *m = st_tetmesh_new();
    if (!map || !m) {
        free(map);
        st_tetmesh_free(m);
        return st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory");
    }
    const uint32_t unused = UINT32_MAX;
    for (size_t v = 0; v < L->nverts; v++)
        map[v] = unused;
    size_t nt = 0;
    for (size_t t = 0; t < L->ntets; t++)
        if (!keep || keep[t]) {
            nt++;
            for (int c = 0; c < 4; c++)
                map[L->tets[4 * t + (size_t)c]] = 0;
        }
    size_t np = 0;
    for (size_t v = 0; v < L->nverts; v++)
        if (map[v] != unused)
            map[v] = (uint32_t)np++;
    st_status st = st_tetmesh_reserve(m, np, nt, err);
    if (st) {
        free(map);
        st_tetmesh_free(m);
        return st;
    }
    for (size_t v = 0; v < L->nverts; v++)
        if (map[v] != unused)
            memcpy(m->xyz + 3 * (size_t)map[v], L->xyz + 3 * v,
                   3 * sizeof(double));
    m->npoints = np;
    size_t k = 0;
    for (size_t t = 0; t < L->ntets; t++)
        if (!keep || keep[t]) {
            for (int c = 0; c < 4; c++)
                m->tets[4 * k + (size_t)c] = map[L->tets[4 * t + (size_t)c]];
            k++;
        }
    m->ntets = nt;
    free(map);
    char buf[64];
    snprintf(buf, sizeof buf, "%.17g", L->h);
    int bad = st_meta_set(&m->meta, "h", buf) != ST_OK;
    bad |= st_meta_set(&m->meta, "lattice", st_lattice_kind_name(L->kind)) != ST_OK;
    snprintf(buf, sizeof buf, "%llu", (unsigned long long)L->seed);
    bad |= st_meta_set(&m->meta, "seed", buf) != ST_OK;
    if (bad) {
        st_tetmesh_free(m);
        return st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory");
    }
    *out = m;
    return ST_OK;
}

/* ---- voxels in a tet ---- */

struct st_voxel_summary {
    size_t nb[3];            /* bricks along each axis */
    unsigned char *flags;    /* bit 0: has an inside voxel; bit 1: outside */
};

st_status st_voxel_summary_build(st_voxel_summary **out, const st_grid *g,
                                 st_error *err)
{
    *out = NULL;
    st_voxel_summary *s = calloc(1, sizeof *s);
    size_t n[3] = {g->nx, g->ny, g->nz}, total = 1;
    for (int a = 0; a < 3; a++) {
        if (s)
            s->nb[a] = (n[a] + ST_VOXEL_BRICK - 1) / ST_VOXEL_BRICK;
        total *= (n[a] + ST_VOXEL_BRICK - 1) / ST_VOXEL_BRICK;
    }
    if (s)
        s->flags = st_calloc_array(total, 1);
    if (!s || !s->flags) {
        st_voxel_summary_free(s);
        return st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory");
    }
    /* Parallel over brick slabs (each k-brick row owned by one thread). */
    long long nbk = (long long)s->nb[2];
#pragma omp parallel for schedule(static)
    for (long long bk = 0; bk < nbk; bk++) {
        size_t k0 = (size_t)bk * ST_VOXEL_BRICK;
        size_t k1 = k0 + ST_VOXEL_BRICK < g->nz ? k0 + ST_VOXEL_BRICK : g->nz;
        for (size_t k = k0; k < k1; k++)
            for (size_t j = 0; j < g->ny; j++) {
                const float *row = g->data + st_grid_index(g, 0, j, k);
                unsigned char *fl = s->flags + s->nb[0] *
                                   (j / ST_VOXEL_BRICK + s->nb[1] * (size_t)bk);
                /* a brick's voxels of the row first, then its flag once:
                 * 1 for a voxel inside (< 0), 2 otherwise (NaN too) */
                size_t bi = 0;
#if ST_VOXEL_BRICK == 4
                for (; 4 * bi + 4 <= g->nx; bi++) {
                    const float *r4 = row + 4 * bi;
                    fl[bi] |= (unsigned char)((2u - (r4[0] < 0.0f)) | (2u - (r4[1] < 0.0f)) |
                                              (2u - (r4[2] < 0.0f)) | (2u - (r4[3] < 0.0f)));
                }
#endif
                for (size_t i = bi * ST_VOXEL_BRICK; i < g->nx; i++)
                    fl[i / ST_VOXEL_BRICK] |= row[i] < 0.0f ? 1 : 2;
            }
    }
    *out = s;
    return ST_OK;
}

void st_voxel_summary_free(st_voxel_summary *s)
{
    if (!s)
        return;
    free(s->flags);
    free(s);
}

/* A filtered test of "p is outside the closed tet", exact-equivalent to
 * st_point_in_tet(...) == ST_OUTSIDE: each face plane's value n.(p - a),
 * n = (b - a) x (c - a), is computed in double together with a bound on its
 * rounding error; only when some plane is too close to call does the exact
 * predicate answer. The bound: every term w_k u_l v_m of the triple product
 * passes through at most 8 roundings (the three input differences, two
 * products, the difference in the cross product, the sum of three terms
 * taking two), so the error is below 8 eps (1 + eps)^8 times the permanent
 * sum |w_k| (|u_l v_m| + |u_m v_l|), itself computed with a relative error
 * far below 2; TET_FILTER_ERR = 16 eps covers both, and TET_FILTER_ABS
 * covers underflow of the products (coordinates of models are nowhere near
 * it, but the bound must hold for every finite input). */
#define TET_FILTER_ERR (16.0 * 0x1.0p-53)
#define TET_FILTER_ABS 0x1.0p-960
/* row_span's slope limit and margin (see there) */
#define TET_ROW_SLOPE 1024.0
#define TET_ROW_MARGIN 1.0

typedef struct tet_filter {
    const double *p[4];
    double a[4][3], n[4][3], m[4][3];
    double s[4];     /* +1/-1: the inside side of each face */
    int ok;          /* 0: use the exact test for every point */
    int row[4];      /* row_span: -1 / +1 the face bounds x below / above,
                      * 0 it is too near parallel to x to use */
} tet_filter;

static void tet_filter_init(tet_filter *f, const double *p0, const double *p1,
                            const double *p2, const double *p3)
{
    f->p[0] = p0;
    f->p[1] = p1;
    f->p[2] = p2;
    f->p[3] = p3;
    f->ok = 1;
    for (int i = 0; i < 4; i++) {
        const double *A = f->p[(i + 1) % 4], *B = f->p[(i + 2) % 4],
                     *C = f->p[(i + 3) % 4], *D = f->p[i];
        double u[3], v[3];
        for (int k = 0; k < 3; k++) {
            f->a[i][k] = A[k];
            u[k] = B[k] - A[k];
            v[k] = C[k] - A[k];
        }
        for (int k = 0; k < 3; k++) {
            int l = (k + 1) % 3, q = (k + 2) % 3;
            f->n[i][k] = u[l] * v[q] - u[q] * v[l];
            f->m[i][k] = fabs(u[l] * v[q]) + fabs(u[q] * v[l]);
        }
        double val = 0, bnd = 0;
        for (int k = 0; k < 3; k++) {
            double w = D[k] - A[k];
            val += w * f->n[i][k];
            bnd += fabs(w) * f->m[i][k];
        }
        bnd = bnd * TET_FILTER_ERR + TET_FILTER_ABS;
        if (val > bnd)
            f->s[i] = 1.0;
        else if (val < -bnd)
            f->s[i] = -1.0;
        else
            f->ok = 0;   /* flat or nearly: leave it to the exact test */
    }
    for (int i = 0; i < 4 && f->ok; i++) {
        const double *n = f->n[i], *m = f->m[i];
        double big = fmax(fmax(fmax(fabs(n[0]), fabs(n[1])), fabs(n[2])),
                          fmax(fmax(m[0], m[1]), m[2]));
        f->row[i] = 0;
        if (fabs(n[0]) * TET_ROW_SLOPE >= big)
            f->row[i] = f->s[i] * n[0] > 0 ? -1 : 1;
    }
}

static int tet_filter_outside(const tet_filter *f, const double c[3])
{
    if (f->ok) {
        int sure = 1;
        for (int i = 0; i < 4; i++) {
            double val = 0, bnd = 0;
            for (int k = 0; k < 3; k++) {
                double w = c[k] - f->a[i][k];
                val += w * f->n[i][k];
                bnd += fabs(w) * f->m[i][k];
            }
            val *= f->s[i];
            bnd = bnd * TET_FILTER_ERR + TET_FILTER_ABS;
            if (val < -bnd)
                return 1;   /* strictly on the outer side of a face */
            if (val <= bnd)
                sure = 0;
        }
        if (sure)
            return 0;       /* strictly inside every face */
    }
    return st_point_in_tet(c, f->p[0], f->p[1], f->p[2], f->p[3]) == ST_OUTSIDE;
}

/* Narrow the voxel row (j, k) to the x-span the tet can occupy: each face
 * plane that is not nearly parallel to the x axis (|n_x| at least
 * 1/TET_ROW_SLOPE of the largest of |n| and its permanent m, so n_x is
 * known to a relative 3 eps TET_ROW_SLOPE) bounds x on one side at its root
 * x* = a_x - (n_y (y - a_y) + n_z (z - a_z)) / n_x. The computed root is
 * within about 1e4 TET_ROW_SLOPE eps times the box size of the true one,
 * below 1e-6 voxel for any box under 1e6 voxels, so widening the span by
 * TET_ROW_MARGIN voxels loses no centre that the exact test would accept:
 * this only skips points, every counted point still passes the filtered
 * exact test. Returns 0 when the span is empty. */
static int row_span(const tet_filter *f, const st_grid *g, size_t j, size_t k,
                    size_t *i0, size_t *i1)
{
    double y = g->origin[1] + g->voxel * (double)j;
    double z = g->origin[2] + g->voxel * (double)k;
    double xl = -INFINITY, xr = INFINITY;
    for (int i = 0; i < 4; i++) {
        if (!f->row[i])
            continue;
        const double *n = f->n[i], *a = f->a[i];
        double x = a[0] - (n[1] * (y - a[1]) + n[2] * (z - a[2])) / n[0];
        /* fmax / fmin without the calls: a NaN root bounds nothing */
        if (f->row[i] < 0)
            xl = x > xl ? x : xl;   /* inside where x >= x* */
        else
            xr = x < xr ? x : xr;
    }
    double lo = floor((xl - g->origin[0]) / g->voxel - TET_ROW_MARGIN);
    double hi = ceil((xr - g->origin[0]) / g->voxel + TET_ROW_MARGIN);
    if (lo > (double)*i0)
        *i0 = lo > (double)*i1 ? *i1 + 1 : (size_t)lo;
    if (hi < (double)*i1) {
        if (hi < (double)*i0)
            return 0;
        *i1 = (size_t)hi;
    }
    return *i0 <= *i1;
}

/* 1 when a brick holding voxels i0..i1 of row (j, k) has an inside voxel. */
static int row_has_inside(const st_voxel_summary *s, size_t i0, size_t i1, size_t j, size_t k)
{
    const unsigned char *fl =
        s->flags + s->nb[0] * (j / ST_VOXEL_BRICK + s->nb[1] * (k / ST_VOXEL_BRICK));
    for (size_t bi = i0 / ST_VOXEL_BRICK; bi <= i1 / ST_VOXEL_BRICK; bi++)
        if (fl[bi] & 1)
            return 1;
    return 0;
}

int st_tet_voxel_count(const st_grid *g, const st_voxel_summary *s,
                       const double p0[3], const double p1[3],
                       const double p2[3], const double p3[3],
                       int stop_at_inside, size_t *m, size_t *M,
                       size_t *tests)
{
    *m = 0;
    *M = 0;
    size_t n[3] = {g->nx, g->ny, g->nz};
    size_t r0[3], r1[3], q0[3], q1[3];
    int clamped = 0, empty = 0;
    for (int a = 0; a < 3; a++) {
        /* comparisons, not fmin / fmax (calls into libm here) */
        double lo = p0[a] < p1[a] ? p0[a] : p1[a], hi = p0[a] > p1[a] ? p0[a] : p1[a];
        lo = p2[a] < lo ? p2[a] : lo;
        lo = p3[a] < lo ? p3[a] : lo;
        hi = p2[a] > hi ? p2[a] : hi;
        hi = p3[a] > hi ? p3[a] : hi;
        /* Scan range [floor, ceil] of the box in voxel units: holds every
         * centre in the box despite rounding in the division (the computed
         * quotient is within an ulp of the true one). The summary range has
         * one voxel more on each side: every voxel that contains a point of
         * the box (lattice.h). */
        double e0 = floor((lo - g->origin[a]) / g->voxel);
        double e1 = ceil((hi - g->origin[a]) / g->voxel);
        double f0 = e0 - 1, f1 = e1 + 1;
        if (f1 < 0 || f0 > (double)n[a] - 1)
            return -1;   /* off the grid: nothing in it is inside */
        clamped |= f0 < 0 || f1 > (double)n[a] - 1;
        r0[a] = f0 < 0 ? 0 : (size_t)f0;
        r1[a] = f1 > (double)n[a] - 1 ? n[a] - 1 : (size_t)f1;
        if (e1 < 0 || e0 > (double)n[a] - 1) {
            empty = 1;
            q0[a] = 1;
            q1[a] = 0;
        } else {
            q0[a] = e0 < 0 ? 0 : (size_t)e0;
            q1[a] = e1 > (double)n[a] - 1 ? n[a] - 1 : (size_t)e1;
        }
    }
    if (s) {
        unsigned char any = 0;
        for (size_t bk = r0[2] / ST_VOXEL_BRICK; bk <= r1[2] / ST_VOXEL_BRICK; bk++)
            for (size_t bj = r0[1] / ST_VOXEL_BRICK; bj <= r1[1] / ST_VOXEL_BRICK; bj++)
                for (size_t bi = r0[0] / ST_VOXEL_BRICK; bi <= r1[0] / ST_VOXEL_BRICK; bi++)
                    any |= s->flags[bi + s->nb[0] * (bj + s->nb[1] * bk)];
        if (any == 2)
            return -1;
        /* All inside only counts when the whole voxel box is on the grid
         * (off the grid is outside). */
        if (any == 1 && !clamped)
            return +1;
    }
    size_t cm = 0, cM = 0, ct = 0;
    if (empty)
        goto out;
    tet_filter f;
    tet_filter_init(&f, p0, p1, p2, p3);
    for (size_t k = q0[2]; k <= q1[2]; k++)
        for (size_t j = q0[1]; j <= q1[1]; j++) {
            const float *row = g->data + st_grid_index(g, 0, j, k);
            size_t i0 = q0[0], i1 = q1[0];
            if (stop_at_inside && s && !row_has_inside(s, i0, i1, j, k))
                continue;   /* no inside voxel in the row's bricks */
            if (f.ok && !row_span(&f, g, j, k, &i0, &i1))
                continue;
            if (stop_at_inside) {
                /* only whether an inside voxel's centre is in the tet:
                 * test the inside voxels alone (*M counts the tested
                 * centres that are in it, a lower bound) */
                for (size_t i = i0; i <= i1; i++) {
                    if (!(row[i] < 0.0f))
                        continue;
                    double c[3];
                    st_grid_center(g, i, j, k, c);
                    ct++;
                    if (!tet_filter_outside(&f, c)) {
                        cM++;
                        cm++;
                        goto out;
                    }
                }
                continue;
            }
            /* The row's centres share y and z and their x grows with i,
             * so those in the closed (convex) tet are one run: find its
             * ends with the exact-equivalent test, count what lies
             * between without testing it. */
            double c[3];
            size_t il = i0, ir = i1;
            for (; il <= i1; il++) {
                st_grid_center(g, il, j, k, c);
                ct++;
                if (!tet_filter_outside(&f, c))
                    break;
            }
            if (il > i1)
                continue;
            for (; ir > il; ir--) {
                st_grid_center(g, ir, j, k, c);
                ct++;
                if (!tet_filter_outside(&f, c))
                    break;
            }
            cM += ir - il + 1;
            for (size_t i = il; i <= ir; i++)
                cm += row[i] < 0.0f;
        }
out:
    *m = cm;
    *M = cM;
    if (tests)
        *tests += ct;
    return 0;
}

/* ---- density ---- */

static int centroid_inside(const st_grid *g, const double *p0,
                           const double *p1, const double *p2,
                           const double *p3)
{
    double c[3];
    size_t ijk[3];
    for (int a = 0; a < 3; a++)
        c[a] = 0.25 * (p0[a] + p1[a] + p2[a] + p3[a]);
    if (!st_grid_voxel_of(g, c, ijk))
        return 0;
    return g->data[st_grid_index(g, ijk[0], ijk[1], ijk[2])] < 0.0f;
}

st_status st_lattice_density(double *rho, st_density_stats *stats,
                             const st_lattice *L, const st_grid *g,
                             st_error *err)
{
    if (g->kind != ST_GRID_SIGNED)
        return st_error_set(err, ST_EINPUT, NULL, 0,
                            "the field is not signed (run soupsign first)");
    st_voxel_summary *sum = NULL;
    st_status st = st_voxel_summary_build(&sum, g, err);
    if (st)
        return st;
    size_t n_centroid = 0, n_tests = 0;
    long long nt = (long long)L->ntets;
#pragma omp parallel for schedule(dynamic, 256) reduction(+ : n_centroid, n_tests)
    for (long long t = 0; t < nt; t++) {
        const uint32_t *v = L->tets + 4 * (size_t)t;
        const double *p0 = L->xyz + 3 * (size_t)v[0], *p1 = L->xyz + 3 * (size_t)v[1];
        const double *p2 = L->xyz + 3 * (size_t)v[2], *p3 = L->xyz + 3 * (size_t)v[3];
        size_t m, M, tests = 0;
        int r = st_tet_voxel_count(g, sum, p0, p1, p2, p3, 0, &m, &M, &tests);
        n_tests += tests;
        if (r < 0)
            rho[t] = 0.0;
        else if (r > 0)
            rho[t] = 1.0;
        else if (M == 0) {
            n_centroid++;
            rho[t] = centroid_inside(g, p0, p1, p2, p3) ? 1.0 : 0.0;
        } else
            rho[t] = (double)m / (double)M;
    }
    st_voxel_summary_free(sum);
    if (stats) {
        stats->lattice_tets = L->ntets;
        stats->centroid_rule = n_centroid;
        stats->point_tests = n_tests;
        stats->kept = 0;
    }
    return ST_OK;
}

st_status st_lattice_density_filter(st_tetmesh **out, st_density_stats *stats,
                                    const st_lattice *L, const st_grid *g,
                                    double rho_min, st_error *err)
{
    return st_lattice_density_filter_clean(out, stats, NULL, L, g, rho_min,
                                           0, err);
}

st_status st_lattice_density_filter_clean(st_tetmesh **out,
                                          st_density_stats *stats,
                                          st_density_clean_stats *cs,
                                          const st_lattice *L,
                                          const st_grid *g, double rho_min,
                                          int clean, st_error *err)
{
    *out = NULL;
    if (!(rho_min >= 0.0 && rho_min <= 1.0))
        return st_error_set(err, ST_EINPUT, NULL, 0,
                            "density threshold %g is not in [0, 1]", rho_min);
    double *rho = st_malloc_array(L->ntets, sizeof *rho);
    unsigned char *keep = st_malloc_array(L->ntets, 1);
    if (!rho || !keep) {
        free(rho);
        free(keep);
        return st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory");
    }
    st_density_stats s;
    st_status st = st_lattice_density(rho, &s, L, g, err);
    st_tetmesh *m = NULL;
    if (!st) {
        for (size_t t = 0; t < L->ntets; t++)
            keep[t] = rho[t] >= rho_min;
        if (clean) {
            double lo[3], hi[3];
            st_lattice_grid_box(g, lo, hi);
            double longest = 0;
            for (int a = 0; a < 3; a++)
                if (hi[a] - lo[a] > longest)
                    longest = hi[a] - lo[a];
            st = st_lattice_density_clean(keep, cs, L, g, rho, longest, err);
        }
        for (size_t t = 0; t < L->ntets; t++)
            s.kept += keep[t];
    }
    if (!st) {
        st = st_lattice_to_tetmesh(&m, L, keep, err);
    }
    if (!st) {
        double *a = NULL;
        st = st_tetmesh_add_array(m, "density", ST_ON_CELLS, 1, &a, err);
        if (!st) {
            size_t k = 0;
            for (size_t t = 0; t < L->ntets; t++)
                if (keep[t])
                    a[k++] = rho[t];
            char buf[64];
            snprintf(buf, sizeof buf, "%.17g", rho_min);
            if (st_meta_set(&m->meta, "rho_min", buf))
                st = st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory");
        }
    }
    free(rho);
    free(keep);
    if (st) {
        st_tetmesh_free(m);
        return st;
    }
    if (stats)
        *stats = s;
    *out = m;
    return ST_OK;
}
