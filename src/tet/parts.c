/*
 * parts.c - a soup's parts, and each tet's part (see parts.h).
 *
 * Sections: names (UTF-8, unique), the split by names or pieces, the
 * owner grid (each part's pseudo volume, the inner part winning), the
 * tets' sampling, the mesh's meta.
 */
#include "souptet/parts.h"
#include "../base/fpenv.h"
#include "souptet/bvh.h"
#include "souptet/dist.h"
#include "souptet/edges.h"
#include "souptet/mem.h"
#include "souptet/meta.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define NO_PART UINT16_MAX   /* ST_PARTS_MAX parts use 0..65534 */

const char *st_parts_mode_name(st_parts_mode mode)
{
    switch (mode) {
    case ST_PARTS_AUTO: return "auto";
    case ST_PARTS_NAMES: return "names";
    case ST_PARTS_PIECES: return "pieces";
    default: return "none";
    }
}

int st_parts_mode_from_name(const char *name)
{
    static const char *k[] = {"none", "auto", "names", "pieces"};
    for (int i = 0; i < 4; i++)
        if (name && strcmp(name, k[i]) == 0)
            return i;
    return -1;
}

void st_parts_free(st_parts *p)
{
    if (!p)
        return;
    for (size_t i = 0; i < p->nparts; i++)
        free(p->names ? p->names[i] : NULL);
    free(p->names);
    free(p->tri_part);
    free(p->tris_of);
    memset(p, 0, sizeof *p);
}

/* ---- names ------------------------------------------------------------- */

/* 1 when s[0..n) is well-formed UTF-8 (no overlong forms, surrogates or
 * code points past U+10FFFF) without control bytes below 0x20: a name
 * goes into quoted gmsh names and XML. */
static int utf8_ok(const unsigned char *s, size_t n)
{
    size_t i = 0;
    while (i < n) {
        unsigned c = s[i];
        if (c < 0x20 || c == 0x7f || c == '"')
            return 0;
        if (c < 0x80) {
            i++;
            continue;
        }
        size_t len = c >= 0xf0 ? 4 : c >= 0xe0 ? 3 : c >= 0xc2 ? 2 : 0;
        if (len == 0 || c > 0xf4 || i + len > n)
            return 0;
        unsigned cp = c & (len == 2 ? 0x1f : len == 3 ? 0x0f : 0x07);
        for (size_t k = 1; k < len; k++) {
            if ((s[i + k] & 0xc0) != 0x80)
                return 0;
            cp = (cp << 6) | (s[i + k] & 0x3f);
        }
        if ((len == 3 && cp < 0x800) || (len == 4 && cp < 0x10000) || cp > 0x10ffff ||
            (cp >= 0xd800 && cp <= 0xdfff))
            return 0;
        i += len;
    }
    return 1;
}

static int cmp_name(const void *a, const void *b)
{
    return strcmp(*(char *const *)a, *(char *const *)b);
}

/* A name and its part, sorted by (name, part). */
typedef struct named {
    const char *name;
    size_t idx;
} named;

static int cmp_named(const void *a, const void *b)
{
    const named *x = a, *y = b;
    int c = strcmp(x->name, y->name);
    return c ? c : (x->idx > y->idx) - (x->idx < y->idx);
}

/* Make p's names unique: the second and later holders of a name (in part
 * order) get "_2", "_3", ... (the first number no name, given or made,
 * has yet). */
static st_status unique_names(st_parts *p, st_error *err)
{
    const size_t n = p->nparts;
    named *srt = st_realloc_array(NULL, n, sizeof *srt);
    char **orig = st_realloc_array(NULL, n, sizeof *orig);
    char **made = st_realloc_array(NULL, n, sizeof *made);
    st_status st = ST_OK;
    size_t nmade = 0;
    if (!srt || !orig || !made) {
        st = st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory");
        goto out;
    }
    for (size_t i = 0; i < n; i++) {
        srt[i].name = p->names[i];
        srt[i].idx = i;
        orig[i] = p->names[i];
    }
    qsort(srt, n, sizeof *srt, cmp_named);
    qsort(orig, n, sizeof *orig, cmp_name);
    for (size_t i = 1; i < n; i++) {
        if (strcmp(srt[i - 1].name, srt[i].name) != 0)
            continue;
        const char *base = srt[i].name;
        const size_t len = strlen(base);
        char *nm = malloc(len + 24);
        if (!nm) {
            st = st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory");
            goto out;
        }
        for (size_t sfx = 2;; sfx++) {
            snprintf(nm, len + 24, "%s_%zu", base, sfx);
            const char *key = nm;
            int taken = bsearch(&key, orig, n, sizeof *orig, cmp_name) != NULL;
            for (size_t k = 0; k < nmade && !taken; k++)
                taken = strcmp(made[k], nm) == 0;
            if (!taken)
                break;
        }
        made[nmade++] = nm;
        p->duplicates++;
    }
    /* hand the made names over, in sorted order of their holders; the
     * replaced names are freed once nothing compares against them */
    size_t m = 0;
    char **old = orig;   /* reused: the replaced names */
    size_t nold = 0;
    for (size_t i = 1; i < n; i++) {
        if (strcmp(srt[i - 1].name, srt[i].name) != 0)
            continue;
        old[nold++] = p->names[srt[i].idx];
        p->names[srt[i].idx] = made[m++];
    }
    nmade = 0;
    for (size_t k = 0; k < nold; k++)
        free(old[k]);
out:
    for (size_t k = 0; k < nmade; k++)
        free(made[k]);
    free(made);
    free(orig);
    free(srt);
    return st;
}

/* A part's name from the file's bytes, or part_K (unnamed or not UTF-8). */
static char *part_name(st_parts *p, const char *given, size_t k)
{
    const size_t len = given ? strlen(given) : 0;
    int ok = len > 0 && utf8_ok((const unsigned char *)given, len);
    if (len == 0)
        p->unnamed++;
    else if (!ok)
        p->not_utf8++;
    char *nm = malloc(ok ? len + 1 : 32);
    if (!nm)
        return NULL;
    if (ok)
        memcpy(nm, given, len + 1);
    else
        snprintf(nm, 32, "part_%zu", k);
    return nm;
}

/* ---- the split --------------------------------------------------------- */

static st_status alloc_split(st_parts *p, size_t ntris, size_t nparts, st_error *err)
{
    p->ntris = ntris;
    p->tri_part = st_realloc_array(NULL, ntris ? ntris : 1, sizeof *p->tri_part);
    p->names = calloc(nparts ? nparts : 1, sizeof *p->names);
    p->tris_of = calloc(nparts ? nparts : 1, sizeof *p->tris_of);
    if (!p->tri_part || !p->names || !p->tris_of)
        return st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory");
    return ST_OK;
}

static st_status too_many(size_t n, const char *what, st_error *err)
{
    return st_error_set(err, ST_ELIMIT, NULL, 0,
                        "%zu %s, more than %d parts (try --parts names, or none)", n, what,
                        ST_PARTS_MAX);
}

/* By the file's named runs: the level-1 runs (objects) when there are
 * any, else the level-2 runs (groups). Triangles before the first run are
 * a part of their own (unnamed). */
static st_status split_names(st_parts *p, const st_soup *s, st_error *err)
{
    int level = 2;
    for (size_t i = 0; i < s->nnames; i++)
        if (s->names[i].level == 1)
            level = 1;
    /* runs: [start, end) of triangles, name; -1 name for the leading run */
    size_t nruns = 0;
    for (size_t i = 0; i < s->nnames; i++)
        nruns += s->names[i].level == level;
    size_t *start = st_realloc_array(NULL, nruns + 1, sizeof *start);
    const char **nm = st_realloc_array(NULL, nruns + 1, sizeof *nm);
    st_status st = ST_OK;
    if (!start || !nm) {
        st = st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory");
        goto out;
    }
    size_t r = 0;
    start[r] = 0;
    nm[r++] = NULL;
    for (size_t i = 0; i < s->nnames; i++)
        if (s->names[i].level == level) {
            start[r] = s->names[i].first;
            nm[r++] = s->names[i].name;
        }
    /* count the runs that hold triangles */
    size_t nparts = 0;
    for (size_t i = 0; i < r; i++) {
        const size_t end = i + 1 < r ? start[i + 1] : s->ntris;
        if (end > start[i])
            nparts++;
        else if (i > 0 && p->empty++ == 0)
            snprintf(p->first_empty, sizeof p->first_empty, "%s", nm[i]);
    }
    if (nparts > ST_PARTS_MAX) {
        st = too_many(nparts, "named parts", err);
        goto out;
    }
    if ((st = alloc_split(p, s->ntris, nparts, err)))
        goto out;
    size_t k = 0;
    for (size_t i = 0; i < r; i++) {
        const size_t end = i + 1 < r ? start[i + 1] : s->ntris;
        if (end <= start[i])
            continue;
        if (!(p->names[k] = part_name(p, nm[i], k))) {
            p->nparts = k;
            st = st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory");
            goto out;
        }
        for (size_t t = start[i]; t < end; t++)
            p->tri_part[t] = (uint16_t)k;
        p->tris_of[k] = end - start[i];
        k++;
    }
    p->nparts = nparts;
out:
    free(start);
    free(nm);
    return st;
}

/* By edge-connected pieces (edges.h), numbered in order of their first
 * triangle. A triangle the edges leave out (degenerate, or a repeat)
 * joins the piece of a kept triangle sharing a welded corner with it,
 * else the first piece: it has no area to give a piece of its own. */
static st_status split_pieces(st_parts *p, const st_soup *s, st_error *err)
{
    st_soup_edges e;
    st_status st = st_soup_edges_build(&e, s, err);
    if (st)
        return st;
    uint32_t *id = st_realloc_array(NULL, s->ntris, sizeof *id);
    uint32_t *by_weld = st_realloc_array(NULL, e.nweld ? e.nweld : 1, sizeof *by_weld);
    if (!id || !by_weld) {
        st = st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory");
        goto out;
    }
    size_t n = 0;
    for (size_t t = 0; t < s->ntris; t++) {
        id[t] = UINT32_MAX;
        if (!e.kept[t])
            continue;
        if (e.piece[t] == t)
            id[t] = (uint32_t)n++;
        else
            id[t] = id[e.piece[t]];   /* the root is smaller: numbered */
    }
    if (n == 0)
        n = 1;   /* every triangle degenerate: one part */
    if (n > ST_PARTS_MAX) {
        st = too_many(n, "pieces", err);
        goto out;
    }
    for (size_t w = 0; w < e.nweld; w++)
        by_weld[w] = UINT32_MAX;
    for (size_t t = 0; t < s->ntris; t++)
        if (id[t] != UINT32_MAX)
            for (int c = 0; c < 3; c++)
                by_weld[e.weld[s->tris[3 * t + c]]] = id[t];
    if ((st = alloc_split(p, s->ntris, n, err)))
        goto out;
    for (size_t t = 0; t < s->ntris; t++) {
        uint32_t k = id[t];
        for (int c = 0; c < 3 && k == UINT32_MAX; c++)
            k = by_weld[e.weld[s->tris[3 * t + c]]];
        if (k == UINT32_MAX)
            k = 0;
        p->tri_part[t] = (uint16_t)k;
        p->tris_of[k]++;
    }
    for (size_t k = 0; k < n; k++) {
        if (!(p->names[k] = malloc(32))) {
            p->nparts = k;
            st = st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory");
            goto out;
        }
        snprintf(p->names[k], 32, "piece_%zu", k);
    }
    p->nparts = n;
out:
    free(id);
    free(by_weld);
    st_soup_edges_free(&e);
    return st;
}

st_status st_parts_from_indices(st_parts *out, const uint32_t *part, size_t ntris,
                                const char *const *names, size_t nnames, st_error *err)
{
    memset(out, 0, sizeof *out);
    size_t n = 0;
    for (size_t t = 0; t < ntris; t++) {
        if (part[t] >= ST_PARTS_MAX)
            return st_error_set(err, ST_EINPUT, NULL, 0,
                                "triangle %zu: part %lu, past the %d parts allowed", t,
                                (unsigned long)part[t], ST_PARTS_MAX);
        if (part[t] >= n)
            n = (size_t)part[t] + 1;
    }
    if (n == 0)
        return st_error_set(err, ST_EINPUT, NULL, 0, "no triangles");
    st_status st = alloc_split(out, ntris, n, err);
    for (size_t t = 0; t < ntris && !st; t++) {
        out->tri_part[t] = (uint16_t)part[t];
        out->tris_of[part[t]]++;
    }
    for (size_t k = 0; k < n && !st; k++) {
        if (!(out->names[k] = part_name(out, names && k < nnames ? names[k] : NULL, k)))
            st = st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory");
        else
            out->nparts = k + 1;
    }
    out->mode = ST_PARTS_NAMES;
    if (!st)
        st = unique_names(out, err);
    if (st)
        st_parts_free(out);
    return st;
}

st_status st_parts_split(st_parts *out, const st_soup *s, st_parts_mode mode,
                         st_error *err)
{
    memset(out, 0, sizeof *out);
    if (!s || s->ntris == 0)
        return st_error_set(err, ST_EINPUT, NULL, 0, "the soup has no triangles");
    if (mode == ST_PARTS_AUTO) {
        /* names where the file gives one (an STL's bare "solid" is none) */
        mode = ST_PARTS_PIECES;
        for (size_t i = 0; i < s->nnames; i++)
            if (s->names[i].name[0])
                mode = ST_PARTS_NAMES;
    }
    st_status st;
    if (mode == ST_PARTS_NAMES)
        st = split_names(out, s, err);
    else if (mode == ST_PARTS_PIECES)
        st = split_pieces(out, s, err);
    else
        return st_error_set(err, ST_EINPUT, NULL, 0, "no parts mode");
    out->mode = mode;
    if (!st)
        st = unique_names(out, err);
    if (st)
        st_parts_free(out);
    return st;
}

/* ---- the owner grid ---------------------------------------------------- */

/* Every part's triangles as a soup of its own, in one pass over the soup:
 * qs[k] (nparts soups). A vertex that several parts use is copied into
 * each, and again when its part changes between uses: a soup is never
 * welded here (edges.h welds by position). */
static st_status part_soups(st_soup ***out, const st_soup *s, const st_parts *p,
                            st_error *err)
{
    *out = NULL;
    st_soup **qs = calloc(p->nparts, sizeof *qs);
    uint16_t *last = st_realloc_array(NULL, s->nverts ? s->nverts : 1, sizeof *last);
    uint32_t *idx = st_realloc_array(NULL, s->nverts ? s->nverts : 1, sizeof *idx);
    st_status st = ST_OK;
    if (!qs || !last || !idx)
        st = st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory");
    for (size_t k = 0; k < p->nparts && !st; k++)
        if (!(qs[k] = st_soup_new()))
            st = st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory");
    for (size_t v = 0; v < s->nverts && !st; v++)
        last[v] = NO_PART;
    for (size_t t = 0; t < s->ntris && !st; t++) {
        const uint16_t k = p->tri_part[t];
        st_soup *q = qs[k];
        uint32_t c[3];
        for (int j = 0; j < 3 && !st; j++) {
            const uint32_t v = s->tris[3 * t + j];
            if (last[v] != k) {
                const double *x = s->xyz + 3 * (size_t)v;
                st = st_soup_add_vertex(q, x[0], x[1], x[2], err);
                last[v] = k;
                idx[v] = (uint32_t)(q->nverts - 1);
            }
            c[j] = idx[v];
        }
        if (!st)
            st = st_soup_add_triangle(q, c[0], c[1], c[2], err);
    }
    free(last);
    free(idx);
    if (st) {
        for (size_t k = 0; qs && k < p->nparts; k++)
            st_soup_free(qs[k]);
        free(qs);
        return st;
    }
    *out = qs;
    return ST_OK;
}

/* The voxel of g nearest x, or SIZE_MAX outside g. */
static size_t voxel_of(const st_grid *g, const double x[3])
{
    const size_t dim[3] = {g->nx, g->ny, g->nz};
    size_t ijk[3];
    for (int a = 0; a < 3; a++) {
        const double f = floor((x[a] - g->origin[a]) / g->voxel + 0.5);
        if (!(f >= 0) || f >= (double)dim[a])
            return SIZE_MAX;
        ijk[a] = (size_t)f;
    }
    return st_grid_index(g, ijk[0], ijk[1], ijk[2]);
}

/* Part k's inside voxels, as voxels of g (the nearest center); *n of them. */
static st_status part_voxels(size_t **out, size_t *n, const st_soup *q, const st_grid *g,
                             const st_pseudo_params *pp, const st_progress *prog,
                             st_error *err)
{
    *out = NULL;
    *n = 0;
    st_dist_params dp = st_dist_params_default();
    dp.voxel = g->voxel;
    st_grid *f = NULL;
    st_error e2;
    st_error_clear(&e2);
    st_status st = st_pseudo_volume(&f, q, &dp, pp, NULL, prog, &e2);
    if (st == ST_EINPUT)
        return ST_OK;   /* a part without extent (a flat piece): no solid */
    if (st) {
        if (err)
            *err = e2;
        return st;
    }
    size_t cnt = 0;
    const size_t nv = st_grid_count(f);
    for (size_t i = 0; i < nv; i++)
        cnt += f->data[i] < 0;
    size_t *v = st_realloc_array(NULL, cnt ? cnt : 1, sizeof *v);
    if (!v) {
        st_grid_free(f);
        return st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory");
    }
    size_t m = 0;
    for (size_t k = 0; k < f->nz; k++)
        for (size_t j = 0; j < f->ny; j++)
            for (size_t i = 0; i < f->nx; i++) {
                if (!(f->data[st_grid_index(f, i, j, k)] < 0))
                    continue;
                double x[3];
                st_grid_center(f, i, j, k, x);
                const size_t at = voxel_of(g, x);
                if (at != SIZE_MAX)
                    v[m++] = at;
            }
    st_grid_free(f);
    *out = v;
    *n = m;
    return ST_OK;
}

typedef struct by_volume {
    size_t voxels;
    size_t part;
} by_volume;

/* Larger first; equal volumes: the larger index first, so the smaller
 * index is written last and wins. */
static int cmp_volume(const void *a, const void *b)
{
    const by_volume *x = a, *y = b;
    if (x->voxels != y->voxels)
        return x->voxels < y->voxels ? 1 : -1;
    return x->part < y->part ? 1 : x->part > y->part ? -1 : 0;
}

/* A part whose field has fewer voxels than this has its pseudo volume
 * made together with the other small ones, one part per thread (each
 * part's own loops on that thread), rather than one after another with
 * the threads sharing each: the many short parallel regions of a small
 * field cost more than the field. Measured: 1000 separate cubes (--parts
 * pieces, --cells 12) took 48 s on 2 busy cores one part after another,
 * 10.9 s on one thread. */
#define PART_SMALL_VOXELS (64 * 64 * 64)

/* The small parts' voxels, in parallel over the parts (see above). sts[k]
 * gets each part's status; the caller reports the first failure. */
static void small_parts(size_t **vox, size_t *voxels, st_status *sts, st_soup *const *qs,
                        const size_t *small, size_t nsmall, const st_grid *g,
                        const st_pseudo_params *pp, const st_progress *prog)
{
    const long long n = (long long)nsmall;
#pragma omp parallel for schedule(dynamic, 1)
    for (long long i = 0; i < n; i++) {
        const size_t k = small[i];
        if (st_progress_cancelled(prog)) {
            sts[k] = ST_ECANCELLED;
            continue;
        }
        st_error e;
        st_error_clear(&e);
        sts[k] = part_voxels(&vox[k], &voxels[k], qs[k], g, pp, NULL, &e);
    }
}

/* owner[v] for each voxel v of g: the part whose solid holds it with the
 * fewest inside voxels, NO_PART where none does. */
static st_status owner_grid(uint16_t **owner, const st_soup *s, const st_parts *p,
                            const st_grid *g, const st_pseudo_params *pp,
                            st_parts_tag_stats *stats, const st_progress *prog,
                            st_error *err)
{
    const size_t nv = st_grid_count(g), np = p->nparts;
    uint16_t *own = st_realloc_array(NULL, nv, sizeof *own);
    size_t **vox = calloc(np, sizeof *vox);
    size_t *voxels = calloc(np, sizeof *voxels);
    size_t *small = st_realloc_array(NULL, np, sizeof *small);
    st_status *sts = calloc(np, sizeof *sts);
    by_volume *order = st_realloc_array(NULL, np, sizeof *order);
    st_soup **qs = NULL;
    st_status st = ST_OK;
    if (!own || !vox || !voxels || !small || !sts || !order) {
        st = st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory");
        goto out;
    }
    if ((st = part_soups(&qs, s, p, err)))
        goto out;
    /* the large parts one after another, each with every thread */
    size_t nsmall = 0;
    st_dist_params dp = st_dist_params_default();
    dp.voxel = g->voxel;
    for (size_t k = 0; k < np && !st; k++) {
        if (qs[k]->ntris == 0)   /* a caller's part may have no triangles */
            continue;
        size_t dims[3];
        double origin[3], voxel;
        st_error e;
        if (st_dist_layout(qs[k], &dp, dims, origin, &voxel, &e) ||
            (double)dims[0] * (double)dims[1] * (double)dims[2] < PART_SMALL_VOXELS) {
            small[nsmall++] = k;
            continue;
        }
        if (st_progress_cancelled(prog))
            st = st_error_set(err, ST_ECANCELLED, NULL, 0, "cancelled");
        else
            st = part_voxels(&vox[k], &voxels[k], qs[k], g, pp, prog, err);
        st_progress_report(prog, "parts", (double)(k + 1) / (double)np);
    }
    if (st)
        goto out;
    small_parts(vox, voxels, sts, qs, small, nsmall, g, pp, prog);
    for (size_t i = 0; i < nsmall && !st; i++) {
        const size_t k = small[i];
        if (sts[k] == ST_ECANCELLED)
            st = st_error_set(err, ST_ECANCELLED, NULL, 0, "cancelled");
        else if (sts[k]) {
            /* again, alone, for its message (the first failing part's) */
            free(vox[k]);
            vox[k] = NULL;
            st = part_voxels(&vox[k], &voxels[k], qs[k], g, pp, prog, err);
            if (!st)
                st = st_error_set(err, sts[k], NULL, 0, "part %zu: its pseudo volume failed", k);
        }
    }
    if (st)
        goto out;
    st_progress_report(prog, "parts", 1.0);
    for (size_t k = 0; k < np; k++) {
        order[k].part = k;
        order[k].voxels = voxels[k];
        if (stats)
            stats->pseudo_volume[k] = (double)voxels[k] * g->voxel * g->voxel * g->voxel;
    }
    qsort(order, np, sizeof *order, cmp_volume);
    for (size_t v = 0; v < nv; v++)
        own[v] = NO_PART;
    for (size_t r = 0; r < np; r++) {
        const size_t k = order[r].part;
        for (size_t i = 0; i < order[r].voxels; i++)
            own[vox[k][i]] = (uint16_t)k;
    }
out:
    for (size_t k = 0; k < np; k++) {
        free(vox ? vox[k] : NULL);
        st_soup_free(qs ? qs[k] : NULL);
    }
    free(qs);
    free(vox);
    free(voxels);
    free(small);
    free(sts);
    free(order);
    if (st) {
        free(own);
        own = NULL;
    }
    *owner = own;
    return st;
}

/* ---- the tets ---------------------------------------------------------- */

/* Tet t's part and share: the owner of most of its samples. */
static void tag_tet(const st_tetmesh *m, size_t t, const st_grid *g, const uint16_t *own,
                    uint16_t *part, double *share)
{
    const uint32_t *c = m->tets + 4 * t;
    uint16_t lab[ST_PARTS_SAMPLES];
    size_t n = 0;
    const double den = ST_PARTS_LEVEL + 2;
    for (int i = 0; i <= ST_PARTS_LEVEL; i++)
        for (int j = 0; i + j <= ST_PARTS_LEVEL; j++)
            for (int k = 0; i + j + k <= ST_PARTS_LEVEL; k++) {
                const int l = ST_PARTS_LEVEL - i - j - k;
                const double w[4] = {(i + 0.5) / den, (j + 0.5) / den, (k + 0.5) / den,
                                     (l + 0.5) / den};
                double x[3] = {0, 0, 0};
                for (int q = 0; q < 4; q++)
                    for (int a = 0; a < 3; a++)
                        x[a] += w[q] * m->xyz[3 * (size_t)c[q] + a];
                const size_t v = voxel_of(g, x);
                lab[n++] = v == SIZE_MAX ? NO_PART : own[v];
            }
    uint16_t best = NO_PART;
    size_t best_n = 0;
    for (size_t i = 0; i < n; i++) {
        if (lab[i] == NO_PART)
            continue;
        size_t cnt = 0;
        for (size_t j = 0; j < n; j++)
            cnt += lab[j] == lab[i];
        if (cnt > best_n || (cnt == best_n && lab[i] < best)) {
            best = lab[i];
            best_n = cnt;
        }
    }
    *part = best;
    *share = (double)best_n / (double)n;
}

static st_status set_part_meta(st_tetmesh *m, const st_parts *p, const double *pv,
                               st_error *err)
{
    char key[48], buf[32];
    snprintf(buf, sizeof buf, "%zu", p->nparts);
    if (st_meta_set(&m->meta, "parts", buf))
        return st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory");
    for (size_t k = 0; k < p->nparts; k++) {
        snprintf(key, sizeof key, "part_name_%zu", k);
        if (st_meta_set(&m->meta, key, p->names[k]))
            return st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory");
    }
    for (size_t k = 0; k < p->nparts; k++) {
        snprintf(key, sizeof key, "part_pseudo_volume_%zu", k);
        snprintf(buf, sizeof buf, "%.17g", pv[k]);
        if (st_meta_set(&m->meta, key, buf))
            return st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory");
    }
    return ST_OK;
}

void st_parts_tag_stats_free(st_parts_tag_stats *st)
{
    if (!st)
        return;
    free(st->pseudo_volume);
    free(st->tets);
    free(st->volume);
    memset(st, 0, sizeof *st);
}

st_status st_parts_tag(st_tetmesh *m, const st_soup *s, const st_parts *p,
                       const st_grid *g, const st_pseudo_params *pp,
                       st_parts_tag_stats *stats, const st_progress *prog,
                       st_error *err)
{
    if (!p || p->nparts == 0 || p->ntris != s->ntris)
        return st_error_set(err, ST_EINPUT, NULL, 0, "the parts are not the soup's");
    st_parts_tag_stats local;
    st_parts_tag_stats *sts = stats ? stats : &local;
    memset(sts, 0, sizeof *sts);
    sts->nparts = p->nparts;
    sts->pseudo_volume = calloc(p->nparts, sizeof *sts->pseudo_volume);
    sts->tets = calloc(p->nparts, sizeof *sts->tets);
    sts->volume = calloc(p->nparts, sizeof *sts->volume);
    uint16_t *own = NULL, *part = NULL;
    double *share = NULL, *vol = NULL;
    st_bvh *bvh = NULL;
    st_status st = ST_OK;
    part = st_realloc_array(NULL, m->ntets ? m->ntets : 1, sizeof *part);
    share = st_realloc_array(NULL, m->ntets ? m->ntets : 1, sizeof *share);
    vol = st_realloc_array(NULL, m->ntets ? m->ntets : 1, sizeof *vol);
    if (!sts->pseudo_volume || !sts->tets || !sts->volume || !part || !share || !vol) {
        st = st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory");
        goto out;
    }
    if ((st = owner_grid(&own, s, p, g, pp, sts, prog, err)) ||
        (st = st_bvh_build(&bvh, s, err)))
        goto out;
    const long long nt = (long long)m->ntets;
#pragma omp parallel for schedule(static)
    for (long long t = 0; t < nt; t++) {
        tag_tet(m, (size_t)t, g, own, &part[t], &share[t]);
        if (part[t] == NO_PART) {
            /* the margin: the part of the nearest triangle */
            const uint32_t *c = m->tets + 4 * t;
            double x[3] = {0, 0, 0};
            for (int q = 0; q < 4; q++)
                for (int a = 0; a < 3; a++)
                    x[a] += 0.25 * m->xyz[3 * (size_t)c[q] + a];
            int64_t tri = -1;
            st_bvh_nearest(bvh, x, INFINITY, &tri, NULL);
            part[t] = tri >= 0 ? p->tri_part[tri] : 0;
            share[t] = 0;
        }
    }
    st_tetmesh_quality(m, NULL, NULL, vol);
    double *pa = NULL, *sa = NULL;
    if ((st = st_tetmesh_add_array(m, "part", ST_ON_CELLS, 1, &pa, err)) ||
        (st = st_tetmesh_add_array(m, "part_share", ST_ON_CELLS, 1, &sa, err)))
        goto out;
    for (size_t t = 0; t < m->ntets; t++) {
        pa[t] = part[t];
        sa[t] = share[t];
        sts->tets[part[t]]++;
        sts->volume[part[t]] += vol[t];
        sts->uncovered += share[t] == 0;
    }
    st = set_part_meta(m, p, sts->pseudo_volume, err);
out:
    st_bvh_free(bvh);
    free(own);
    free(part);
    free(share);
    free(vol);
    if (st || !stats)
        st_parts_tag_stats_free(sts);
    return st;
}

st_status st_parts_of_mesh(const char ***names, size_t *count, const st_tetmesh *m,
                           st_error *err)
{
    *names = NULL;
    *count = 0;
    const char *v = st_meta_get(&m->meta, "parts");
    if (!v)
        return ST_OK;
    char *end = NULL;
    unsigned long long n = strtoull(v, &end, 10);
    if (!*v || *end || n < 1 || n > ST_PARTS_MAX)
        return st_error_set(err, ST_EINPUT, NULL, 0, "meta parts '%s' is not a count in 1..%d",
                            v, ST_PARTS_MAX);
    const char **nm = calloc((size_t)n, sizeof *nm);
    if (!nm)
        return st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory");
    char key[48];
    for (size_t k = 0; k < n; k++) {
        snprintf(key, sizeof key, "part_name_%zu", k);
        nm[k] = st_meta_get(&m->meta, key);
    }
    *names = nm;
    *count = (size_t)n;
    return ST_OK;
}

st_status st_parts_measure(st_parts_tag_stats *out, const st_tetmesh *m, st_error *err)
{
    memset(out, 0, sizeof *out);
    const st_tet_array *pa = st_tetmesh_find_array(m, "part", ST_ON_CELLS);
    const st_tet_array *sa = st_tetmesh_find_array(m, "part_share", ST_ON_CELLS);
    if (!pa || pa->ncomp != 1 || m->ntets == 0)
        return ST_OK;
    const char **names = NULL;
    size_t n = 0;
    st_status st = st_parts_of_mesh(&names, &n, m, err);
    free((void *)names);
    if (st)
        return st;
    for (size_t t = 0; t < m->ntets; t++) {
        const double x = pa->values[t];
        if (x >= 0 && x < ST_PARTS_MAX && x == floor(x) && (size_t)x >= n)
            n = (size_t)x + 1;
    }
    if (n == 0)
        return ST_OK;
    out->nparts = n;
    out->pseudo_volume = st_realloc_array(NULL, n, sizeof *out->pseudo_volume);
    out->tets = calloc(n, sizeof *out->tets);
    out->volume = calloc(n, sizeof *out->volume);
    double *vol = st_realloc_array(NULL, m->ntets, sizeof *vol);
    if (!out->pseudo_volume || !out->tets || !out->volume || !vol) {
        free(vol);
        st_parts_tag_stats_free(out);
        return st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory");
    }
    for (size_t k = 0; k < n; k++) {
        char key[48];
        snprintf(key, sizeof key, "part_pseudo_volume_%zu", k);
        const char *v = st_meta_get(&m->meta, key);
        char *end = NULL;
        const double x = v ? strtod(v, &end) : NAN;
        out->pseudo_volume[k] = v && *v && !*end ? x : NAN;
    }
    st_tetmesh_quality(m, NULL, NULL, vol);
    for (size_t t = 0; t < m->ntets; t++) {
        const double x = pa->values[t];
        const size_t k = x >= 0 && x < (double)n && x == floor(x) ? (size_t)x : 0;
        out->tets[k]++;
        out->volume[k] += vol[t];
        out->uncovered += sa && sa->ncomp == 1 && sa->values[t] == 0;
    }
    free(vol);
    return ST_OK;
}
