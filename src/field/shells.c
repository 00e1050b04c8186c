/*
 * shells.c - closed shells of a soup and their solid (see shells.h).
 *
 *   1. the soup's edges and pieces (edges.h);
 *   2. per edge of two triangles: each one's manifold neighbour across it,
 *      and whether the two run along it the same way; an edge of one, or
 *      of three or more, triangles marks its piece open;
 *   3. breadth-first over each piece, flipping a triangle whenever it
 *      runs along a shared edge the same way as the one it was reached
 *      from; a conflict marks the piece open (non-orientable);
 *   4. each closed piece's signed volume (about one of its vertices) says
 *      whether the whole piece is flipped once more, to positive volume.
 */
#include "souptet/shells.h"
#include "../base/fpenv.h"
#include "souptet/edges.h"
#include "souptet/mem.h"
#include "souptet/meta.h"
#include "souptet/solid.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define NONE ST_EDGES_NONE

void st_shells_free(st_shells *sh)
{
    if (!sh)
        return;
    st_soup_free(sh->closed);
    memset(sh, 0, sizeof *sh);
}

static double tet_volume6(const double *r, const double *a, const double *b, const double *c)
{
    const double u[3] = {a[0] - r[0], a[1] - r[1], a[2] - r[2]};
    const double v[3] = {b[0] - r[0], b[1] - r[1], b[2] - r[2]};
    const double w[3] = {c[0] - r[0], c[1] - r[1], c[2] - r[2]};
    return u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0]) +
           u[2] * (v[0] * w[1] - v[1] * w[0]);
}

st_status st_soup_closed_shells(st_shells *out, const st_soup *s, st_error *err)
{
    return st_soup_closed_shells_edges(out, s, NULL, err);
}

st_status st_soup_closed_shells_edges(st_shells *out, const st_soup *s,
                                      const st_soup_edges *edges, st_error *err)
{
    memset(out, 0, sizeof *out);
    st_soup_edges own;
    st_status rc = edges ? ST_OK : st_soup_edges_build(&own, s, err);
    if (rc)
        return rc;
    const st_soup_edges E = edges ? *edges : own;
    const size_t nt = s->ntris;
    rc = ST_ENOMEM;
    uint32_t *nbr = st_malloc_array(3 * nt + 1, sizeof *nbr);     /* 3 slots per triangle */
    uint8_t *same = st_calloc_array(3 * nt + 1, 1);
    uint8_t *open = st_calloc_array(nt + 1, 1);                   /* per piece root */
    uint8_t *flip = st_malloc_array(nt + 1, 1);
    uint32_t *queue = st_malloc_array(nt + 1, sizeof *queue);
    double *vol = st_calloc_array(nt + 1, sizeof *vol);           /* per piece root */
    st_soup *closed = st_soup_new();
    if (!nbr || !same || !open || !flip || !queue || !vol || !closed)
        goto done;

    /* 2. manifold neighbours */
    st_soup_edges_neighbours(&E, s, nbr, same, open);

    /* 3. orientation by propagation; 4. signed volumes */
    memset(flip, 2, nt);        /* 2: not reached yet */
    for (size_t t0 = 0; t0 < nt; t0++) {
        if (!E.kept[t0] || flip[t0] != 2 || open[E.piece[t0]])
            continue;
        const uint32_t root = E.piece[t0];
        const double *ref = s->xyz + 3 * (size_t)s->tris[3 * t0];
        size_t qh = 0, qt = 0;
        flip[t0] = 0;
        queue[qt++] = (uint32_t)t0;
        while (qh < qt) {
            const uint32_t t = queue[qh++];
            const uint32_t *v = s->tris + 3 * (size_t)t;
            const double v6 = tet_volume6(ref, s->xyz + 3 * (size_t)v[0],
                                          s->xyz + 3 * (size_t)v[1], s->xyz + 3 * (size_t)v[2]);
            vol[root] += flip[t] ? -v6 : v6;
            for (size_t slot = 3 * (size_t)t; slot < 3 * (size_t)t + 3; slot++) {
                const uint32_t o = nbr[slot];
                if (o == NONE)
                    continue;
                const uint8_t want = (uint8_t)(flip[t] ^ same[slot]);
                if (flip[o] == 2) {
                    flip[o] = want;
                    queue[qt++] = o;
                } else if (flip[o] != want) {
                    open[root] = 1;
                }
            }
        }
    }

    /* the shells' triangles, in the soup's order */
    for (size_t v = 0; v < s->nverts; v++)
        if ((rc = st_soup_add_vertex(closed, s->xyz[3 * v], s->xyz[3 * v + 1],
                                     s->xyz[3 * v + 2], err)))
            goto fail;
    for (size_t t = 0; t < nt; t++) {
        if (!E.kept[t])
            continue;
        const uint32_t root = E.piece[t];
        if (open[root]) {
            out->open_triangles++;
            continue;
        }
        if (root == t)
            out->count++;
        const uint32_t *v = s->tris + 3 * t;
        const int back = flip[t] ^ (vol[root] < 0.0);
        if ((rc = st_soup_add_triangle(closed, v[0], back ? v[2] : v[1], back ? v[1] : v[2],
                                       err)))
            goto fail;
    }
    out->closed = closed;
    closed = NULL;
    rc = ST_OK;
done:
    if (rc == ST_ENOMEM)
        st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory for the closed shells");
fail:
    st_soup_free(closed);
    if (!edges)
        st_soup_edges_free(&own);
    free(nbr);
    free(same);
    free(open);
    free(flip);
    free(queue);
    free(vol);
    return rc;
}

st_status st_shells_sign(st_grid *g, const st_shells *sh, size_t *changed, st_error *err)
{
    if (changed)
        *changed = 0;
    if (g->kind != ST_GRID_SIGNED)
        return st_error_set(err, ST_EINPUT, NULL, 0,
                            "closed shells: the field must be signed first");
    const int exact = sh->count > 0 && sh->open_triangles == 0;
    size_t n = 0;
    if (sh->count > 0) {
        const size_t count = st_grid_count(g);
        uint8_t *inside = st_malloc_array(count, 1);
        if (!inside)
            return st_error_set(err, ST_ENOMEM, NULL, 0,
                                "out of memory for the closed shells' solid");
        const st_soup *const shells[1] = {sh->closed};
        st_status rc = st_solid_inside(inside, g, shells, 1, ST_SOLID_NONZERO, err);
        if (rc) {
            free(inside);
            return rc;
        }
        float *d = g->data;
        #pragma omp parallel for reduction(+ : n) schedule(static)
        for (size_t i = 0; i < count; i++) {
            const int was = d[i] < 0.0f;
            const int in = inside[i] || (!exact && was);
            n += (size_t)(in != was);
            d[i] = st_grid_signed_value(d[i], in);
        }
        free(inside);
    }
    char buf[160];
    snprintf(buf, sizeof buf, "%zu shells, %zu open triangles, %s, %zu signs changed",
             sh->count, sh->open_triangles, exact ? "exact" : sh->count ? "inside united" : "none",
             n);
    if (st_meta_set(&g->meta, "closed_shells", buf))
        return st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory for the metadata");
    if (changed)
        *changed = n;
    return ST_OK;
}
