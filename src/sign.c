/*
 * sign.c - volume-event voting (see sign.h; Spillmann et al. 2006, §3).
 *
 * Per direction, two streaming passes over the grid:
 *   1. walk every line, find its event runs (voxels with |d| < t), count
 *      them (E, per line) and mark in a byte per voxel where the forward
 *      ray toggles (S) and where the backward ray toggles (R);
 *   2. walk again, counting marks: the forward ray's parity at v is the
 *      number of S at or before v, the backward ray's is the number of R at
 *      or after v, which is E minus the R strictly before v; add the votes.
 * So 26 rays cost two passes per line, the same as 26 plain passes.
 *
 * Memory order. The four directions within a z layer are walked line by
 * line, a layer at a time (a layer stays in cache); layers are independent
 * and run in parallel. The nine directions that cross layers keep one state
 * per line and stream layer after layer, each layer read in storage order,
 * its rows in parallel (every voxel of a layer is on a different line).
 */
#include "souptet/sign.h"
#include "souptet/mem.h"

#include <limits.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define MARK_S 1u   /* forward ray toggles here */
#define MARK_R 2u   /* backward ray toggles here */

/* The 13 lines of the 26-neighbourhood; the first four stay in a layer. */
static const int DIRS[13][3] = {
    {1, 0, 0}, {0, 1, 0}, {1, 1, 0}, {1, -1, 0},
    {0, 0, 1}, {1, 0, 1}, {-1, 0, 1}, {0, 1, 1}, {0, -1, 1},
    {1, 1, 1}, {-1, 1, 1}, {1, -1, 1}, {-1, -1, 1}};
#define IN_LAYER 4

st_sign_params st_sign_params_paper(void)
{
    st_sign_params p = {0.8, 0.0, 26, ST_TOGGLE_FIRST, 0, 0};
    return p;
}

st_sign_params st_sign_params_default(void)
{
    /* Provisional, from the shape tests (tests/test_sign --variants): the
     * toggle nearest the surface keeps shapes from growing by a voxel, and
     * the union rule keeps interpenetrating parts. The corpus benchmark
     * decides the rest. */
    st_sign_params p = {0.8, 0.0, 26, ST_TOGGLE_NEAREST, 0, 1};
    return p;
}

int st_sign_params_named(st_sign_params *p, const char *name)
{
    if (strcmp(name, "paper") == 0)
        *p = st_sign_params_paper();
    else if (strcmp(name, "default") == 0)
        *p = st_sign_params_default();
    else if (strcmp(name, "parity") == 0) {
        *p = st_sign_params_paper();
        p->k = 1.0;
    } else
        return -1;
    return 0;
}

double st_sign_event_distance(const st_sign_params *p, const st_grid *g)
{
    if (p->k >= 1.0)
        return 0.5 * g->voxel;
    double range;
    if (p->band_voxels > 0)
        range = p->band_voxels * g->voxel;
    else {
        double mx = 0.0;
        size_t n = st_grid_count(g);
        #pragma omp parallel for reduction(max : mx) schedule(static)
        for (size_t i = 0; i < n; i++) {
            double a = fabs((double)g->data[i]);
            if (a > mx)
                mx = a;
        }
        range = mx;
    }
    return (1.0 - p->k) * range;
}

/* State of one line while it is streamed: only parities matter, so the
 * hot part is one byte per line; where the current event run started, ends
 * and comes nearest the surface lives in cold arrays touched only near the
 * surface. */
#define L_IN_RUN 1u
#define L_E_ODD 2u      /* events on the line, mod 2 (pass 1 result) */
#define L_CS_ODD 4u     /* pass 2: S marks at or before the voxel, mod 2 */
#define L_CR_ODD 8u     /* pass 2: R marks strictly before the voxel, mod 2 */
#define L_ANY 16u       /* the line has an event (pass 1 result) */
#define L_SEEN 32u      /* pass 2: an S mark at or before the voxel */

typedef struct run_state {
    float min;
    size_t start, last, argmin;
    size_t last_r;        /* the line's last R mark (pass 1 result) */
} run_state;

typedef struct sweep_ctx {
    const st_grid *g;
    const st_sign_params *p;
    uint8_t *mark;
    uint8_t *votes;       /* inside votes */
    uint8_t *valid;       /* valid votes (only when ignoring odd lines) */
    uint8_t *hidden;      /* rays that meet an event before the voxel */
    float t_axis;         /* event distance for an axis direction */
    int reverse;          /* this direction's steps move back in memory */
} sweep_ctx;

static inline float event_distance(const sweep_ctx *c, const int d[3])
{
    /* At k = 1 the event distance is half of this direction's step. */
    if (c->p->k >= 1.0) {
        int n = abs(d[0]) + abs(d[1]) + abs(d[2]);
        return c->t_axis * (float)sqrt((double)n);
    }
    return c->t_axis;
}

/* Pass 1, one voxel: is_last says the line ends here. A line starts with
 * its flags cleared. Returns 1 when an event ended here. */
static inline unsigned pass1_step(const sweep_ctx *c, uint8_t *fl,
                                  run_state *r, size_t idx, float t,
                                  int is_last)
{
    float a = fabsf(c->g->data[idx]);
    int ev = a < t;
    if (!ev && !(*fl & L_IN_RUN))
        return 0;                       /* far from the surface: the usual */
    if (ev) {
        if (!(*fl & L_IN_RUN)) {
            *fl |= L_IN_RUN;
            r->start = r->argmin = idx;
            r->min = a;
        } else if (a < r->min) {        /* ties keep the first */
            r->min = a;
            r->argmin = idx;
        }
        r->last = idx;
        if (!is_last)
            return 0;
    }
    /* The run ends: here (ev and is_last) or at the previous voxel. */
    *fl = (uint8_t)(((*fl & ~L_IN_RUN) ^ L_E_ODD) | L_ANY);
    if (c->p->toggle == ST_TOGGLE_NEAREST) {
        c->mark[r->argmin] |= MARK_S | MARK_R;
        r->last_r = r->argmin;
    } else {
        c->mark[r->start] |= MARK_S;
        c->mark[r->last] |= MARK_R;
        r->last_r = r->last;
    }
    return 1;
}

/* Is idx at or before pos on its line? Every step along a line moves
 * forward in memory except in the direction (1, -1, 0), whose stride
 * 1 - nx is negative (c->reverse). */
static inline unsigned line_before_or_at(const sweep_ctx *c, size_t idx,
                                         size_t pos)
{
    return c->reverse ? idx >= pos : idx <= pos;
}

/* Pass 2, one voxel: add this line's votes and clear the mark. The line
 * state's flags keep L_E_ODD and L_ANY from pass 1; r->last_r says where
 * the backward ray's first event is. Lines are walked forward. */
static inline void pass2_step(const sweep_ctx *c, uint8_t *fl,
                              const run_state *r, size_t idx)
{
    uint8_t m = c->mark[idx];
    uint8_t f = *fl;
    if (m) {
        if (m & MARK_S)
            f = (uint8_t)((f ^ L_CS_ODD) | L_SEEN);
        c->mark[idx] = 0;
    }
    if (c->hidden && (f & L_ANY)) {
        /* Forward: an event at or before; backward: one at or after. */
        unsigned h = (f & L_SEEN) != 0;
        if (c->p->rays == 26)
            h += line_before_or_at(c, idx, r->last_r);
        c->hidden[idx] = (uint8_t)(c->hidden[idx] + h);
    }
    /* Backward parity at idx: R at or after idx = E - (R before idx). */
    unsigned back = ((f & L_E_ODD) != 0) ^ ((f & L_CR_ODD) != 0);
    unsigned fwd = (f & L_CS_ODD) != 0;
    if (m & MARK_R)
        f ^= L_CR_ODD;
    *fl = f;
    if (c->p->ignore_odd && (f & L_E_ODD))
        return;
    if (c->p->rays == 26) {
        c->votes[idx] = (uint8_t)(c->votes[idx] + fwd + back);
        if (c->valid)
            c->valid[idx] = (uint8_t)(c->valid[idx] + 2);
    } else {
        c->votes[idx] = (uint8_t)(c->votes[idx] + fwd);
        if (c->valid)
            c->valid[idx] = (uint8_t)(c->valid[idx] + 1);
    }
}

/* The four directions inside a layer: whole lines at a time, from each
 * line's start (the voxels whose predecessor is outside the layer). */
static void sweep_in_layer(const sweep_ctx *c, const int d[3])
{
    const st_grid *g = c->g;
    const long nx = (long)g->nx, ny = (long)g->ny, nz = (long)g->nz;
    const float t = event_distance(c, d);
    const long stride = d[0] + d[1] * nx;
    /* Starts: the edge i = i_edge (when dx != 0) and the edge j = j_edge
     * (when dy != 0), each start once. */
    const long i_edge = d[0] > 0 ? 0 : nx - 1, j_edge = d[1] > 0 ? 0 : ny - 1;
    const long nstarts = (d[0] ? ny : 0) + (d[1] ? nx : 0);
    #pragma omp parallel for schedule(dynamic, 1)
    for (long k = 0; k < nz; k++) {
        size_t layer = (size_t)nx * (size_t)ny * (size_t)k;
        for (long q = 0; q < nstarts; q++) {
            long i0, j0;
            if (d[0] && q < ny) {
                i0 = i_edge;
                j0 = q;
            } else {
                i0 = d[0] ? q - ny : q;
                j0 = j_edge;
                if (d[0] && i0 == i_edge)
                    continue;       /* the corner, already a start above */
            }
            /* Length of the line from (i0, j0). */
            long len = LONG_MAX;
            if (d[0] > 0)
                len = nx - i0;
            else if (d[0] < 0)
                len = i0 + 1;
            if (d[1] > 0 && ny - j0 < len)
                len = ny - j0;
            else if (d[1] < 0 && j0 + 1 < len)
                len = j0 + 1;
            size_t idx0 = layer + (size_t)i0 + (size_t)nx * (size_t)j0;
            uint8_t fl = 0;
            run_state r = {0};
            size_t idx = idx0;
            for (long s = 0; s < len; s++, idx += (size_t)stride)
                pass1_step(c, &fl, &r, idx, t, s == len - 1);
            fl &= L_E_ODD | L_ANY;
            idx = idx0;
            for (long s = 0; s < len; s++, idx += (size_t)stride)
                pass2_step(c, &fl, &r, idx);
        }
    }
}

/* The nine directions that cross layers (d[2] == 1): a state per line,
 * layer after layer. A line is named by where it meets layer 0,
 * (i - dx k, j - dy k), shifted to be non-negative. */
static void sweep_across(const sweep_ctx *c, const int d[3], uint8_t *flags,
                         run_state *runs)
{
    const st_grid *g = c->g;
    const long nx = (long)g->nx, ny = (long)g->ny, nz = (long)g->nz;
    const long W = nx + (d[0] ? nz - 1 : 0);
    const long offx = d[0] > 0 ? nz - 1 : 0, offy = d[1] > 0 ? nz - 1 : 0;
    const float t = event_distance(c, d);
    for (int pass = 1; pass <= 2; pass++) {
        for (long k = 0; k < nz; k++) {
            #pragma omp parallel for schedule(static)
            for (long j = 0; j < ny; j++) {
                const long ly = j - d[1] * k + offy;
                const size_t lbase = (size_t)(W * ly - d[0] * k + offx);
                const size_t vbase = (size_t)nx * ((size_t)j + (size_t)ny * (size_t)k);
                /* A line starts where its predecessor is outside the grid:
                 * in layer 0, on the row edge it enters through, or at the
                 * column it enters through. */
                const int row_first = k == 0 || j - d[1] < 0 || j - d[1] >= ny;
                const int row_last = k == nz - 1 || j + d[1] < 0 || j + d[1] >= ny;
                for (long i = 0; i < nx; i++) {
                    size_t idx = vbase + (size_t)i;
                    uint8_t *fl = &flags[lbase + (size_t)i];
                    int first = row_first || i - d[0] < 0 || i - d[0] >= nx;
                    int last = row_last || i + d[0] < 0 || i + d[0] >= nx;
                    if (pass == 1) {
                        if (first)
                            *fl = 0;
                        pass1_step(c, fl, &runs[lbase + (size_t)i], idx, t, last);
                    } else {
                        if (first)
                            *fl &= L_E_ODD | L_ANY;
                        pass2_step(c, fl, &runs[lbase + (size_t)i], idx);
                    }
                }
            }
        }
    }
}

unsigned st_sign_line(const float *d, size_t n, float t,
                      const st_sign_params *p, unsigned char *votes,
                      unsigned char *valid)
{
    /* A 1 x 1 x n view of the samples, walked with the same steps. */
    st_grid g;
    memset(&g, 0, sizeof g);
    g.nx = n;
    g.ny = g.nz = 1;
    g.data = (float *)d;
    uint8_t *mark = calloc(n ? n : 1, 1);
    if (!mark)
        return 0;
    sweep_ctx c = {&g, p, mark, votes, valid, NULL, t, 0};
    uint8_t fl = 0;
    run_state r = {0};
    unsigned events = 0;
    for (size_t i = 0; i < n; i++)
        events += pass1_step(&c, &fl, &r, i, t, i + 1 == n);
    fl &= L_E_ODD | L_ANY;
    for (size_t i = 0; i < n; i++)
        pass2_step(&c, &fl, &r, i);
    free(mark);
    return events;
}

st_status st_sign_field(st_grid *g, const st_sign_params *p,
                        const st_progress *progress, st_error *err)
{
    if (g->kind == ST_GRID_SIGNED)
        return st_error_set(err, ST_EINPUT, NULL, 0,
                            "the field is already signed (give soupsign a "
                            "distance field from soupdist)");
    if (g->kind != ST_GRID_DISTANCE && g->kind != ST_GRID_UNKNOWN)
        return st_error_set(err, ST_EINPUT, NULL, 0,
                            "not a distance field");
    if (!(p->k > 0.0 && p->k <= 1.0))
        return st_error_set(err, ST_EINPUT, NULL, 0,
                            "k must be in (0, 1], not %g", p->k);
    if (p->rays != 13 && p->rays != 26)
        return st_error_set(err, ST_EINPUT, NULL, 0,
                            "rays must be 13 or 26, not %d", p->rays);
    const size_t n = st_grid_count(g);
    size_t negative = 0, nonfinite = 0;
    float lo = INFINITY, hi = -INFINITY;
    #pragma omp parallel for reduction(+ : negative, nonfinite) \
        reduction(min : lo) reduction(max : hi) schedule(static)
    for (size_t i = 0; i < n; i++) {
        float v = g->data[i];
        if (!isfinite(v))
            nonfinite++;
        else if (v < 0.0f)
            negative++;
        if (v < lo)
            lo = v;
        if (v > hi)
            hi = v;
    }
    if (nonfinite)
        return st_error_set(err, ST_EINPUT, NULL, 0,
                            "the field has %zu values that are not finite",
                            nonfinite);
    if (negative)
        return st_error_set(err, ST_EINPUT, NULL, 0,
                            "not an unsigned distance field: %zu values are "
                            "negative", negative);
    if (!(lo < hi))
        return st_error_set(err, ST_EINPUT, NULL, 0,
                            "the field is constant (%g): no surface in it",
                            (double)lo);

    sweep_ctx c;
    c.g = g;
    c.p = p;
    double t = st_sign_event_distance(p, g);
    c.t_axis = (float)t;
    c.mark = st_calloc_array(n, 1);
    c.votes = st_calloc_array(n, 1);
    c.valid = p->ignore_odd ? st_calloc_array(n, 1) : NULL;
    c.hidden = p->nested_union ? st_calloc_array(n, 1) : NULL;
    c.reverse = 0;
    /* Line states for the widest crossing direction. */
    size_t W = g->nx + g->nz, H = g->ny + g->nz, nstates;
    uint8_t *flags = NULL;
    run_state *runs = NULL;
    if (!st_size_mul(&nstates, W, H)) {
        flags = st_malloc_array(nstates, 1);
        runs = st_malloc_array(nstates, sizeof *runs);
    }
    if (!c.mark || !c.votes || (p->ignore_odd && !c.valid) ||
        (p->nested_union && !c.hidden) || !flags || !runs) {
        free(c.mark);
        free(c.votes);
        free(c.valid);
        free(c.hidden);
        free(flags);
        free(runs);
        return st_error_set(err, ST_ENOMEM, NULL, 0,
                            "out of memory for the votes");
    }
    for (int d = 0; d < 13; d++) {
        c.reverse = DIRS[d][0] + DIRS[d][1] * (long)g->nx +
                    DIRS[d][2] * (long)(g->nx * g->ny) < 0;
        if (d < IN_LAYER)
            sweep_in_layer(&c, DIRS[d]);
        else
            sweep_across(&c, DIRS[d], flags, runs);
        st_progress_report(progress, "signs", (d + 1) / 13.0);
    }
    const int per_line = p->rays == 26 ? 2 : 1;
    #pragma omp parallel for schedule(static)
    for (size_t i = 0; i < n; i++) {
        int total = c.valid ? c.valid[i] : 13 * per_line;
        /* Majority; ties (and voxels no valid ray reached) are outside.
         * With nested_union, a voxel no ray reaches from outside without
         * meeting the surface is inside whatever the parity. */
        int inside = 2 * (int)c.votes[i] > total ||
                     (c.hidden && c.hidden[i] == 13 * per_line);
        g->data[i] = inside ? -fabsf(g->data[i]) : fabsf(g->data[i]);
    }
    free(c.mark);
    free(c.votes);
    free(c.valid);
    free(c.hidden);
    free(flags);
    free(runs);
    g->kind = ST_GRID_SIGNED;
    char buf[160];
    snprintf(buf, sizeof buf,
             "k=%g c=%s rays=%d toggle=%s odd=%s nested=%s "
             "event_distance=%.9g",
             p->k, p->band_voxels > 0 ? "band" : "1/max|d|", p->rays,
             p->toggle == ST_TOGGLE_NEAREST ? "nearest" : "first",
             p->ignore_odd ? "ignored" : "kept",
             p->nested_union ? "union" : "parity", t);
    if (st_meta_set(&g->meta, "sign_rule", buf))
        return st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory");
    return ST_OK;
}
