/*
 * pseudo.c - the pseudo volume of a soup, step by step (pseudo.h).
 */
#define _POSIX_C_SOURCE 200809L
#include "../base/fpenv.h"
#include "souptet/pseudo.h"

#include "souptet/mem.h"
#include "souptet/bvh.h"
#include "souptet/edges.h"
#include "souptet/holes.h"
#include "souptet/mincut.h"
#include "souptet/shells.h"

#include <math.h>
#include <stdlib.h>
#include <stdio.h>
#include <string.h>
#include <time.h>

static double now_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

st_pseudo_params st_pseudo_params_default(void)
{
    st_pseudo_params p;
    memset(&p, 0, sizeof p);
    p.sign = st_sign_params_default();
    p.refine = st_sign_refine_params_default();
    p.holes = st_holes_params_default();
    p.fill_holes = 1;
    p.closed_shells = 1;
    p.refine_signs = 1;
    p.cap_reach = 3.0;
    p.sides = 1;
    p.sides_params = st_sides_params_default();
    p.shells_shortcut = 1;
    p.signs_only = 0;
    p.symmetry = 1;
    return p;
}

/* The shortcut (pseudo.h): every kept triangle of s is in a closed shell,
 * so step 5 would overwrite every sign; g gets the shells' solid alone,
 * each voxel st_grid_signed_value(its distance, inside the solid). */
static st_status shells_only(st_grid *g, const st_shells *shells, const st_pseudo_params *p,
                             int far, st_pseudo_stats *st, st_error *err)
{
    st->failed_step = "vote";   /* the field's checks: the field is to blame */
    /* a field of far values (signs_only) is made here, and constant: only
     * the parameters are checked */
    st_status rc = far ? st_sign_check_params(&p->sign, err) : st_sign_check_field(g, &p->sign, err);
    if (rc)
        return rc;
    st->failed_step = "shells";
    /* an unsigned field read as signed is every voxel outside (no value is
     * negative); the shells then turn inside exactly their solid */
    g->kind = ST_GRID_SIGNED;
    rc = st_shells_sign(g, shells, &st->shell_changed, err);
    if (!rc && st_meta_set(&g->meta, "sign_rule",
                           "closed shells: every triangle is in one, the signs are their "
                           "solid (no caps, vote or refinement)"))
        rc = st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory");
    if (!rc && far && st_meta_set(&g->meta, "distances",
                                  "none: every voxel holds the band's far value, signed "
                                  "(signs_only)"))
        rc = st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory");
    return rc;
}

/* Step 1's tables: s's edges (when a step reads them; none after the
 * shortcut) and its closed shells; built by the sign step, or before the
 * field by st_pseudo_volume_bvh when the distances may be skipped
 * (signs_only) or come from the BVH (a dense soup). */
typedef struct sign_prep {
    st_soup_edges edges;
    int have_edges;
    st_shells shells;
    int shortcut;       /* every triangle in a closed shell (shells_shortcut) */
    int far;            /* the field holds far values (st_dist_field_far) */
    double seconds;     /* building them */
} sign_prep;

static void prep_free(sign_prep *pr)
{
    if (pr->have_edges)
        st_soup_edges_free(&pr->edges);
    pr->have_edges = 0;
    st_shells_free(&pr->shells);
}

/* pr from zero; on failure *failed names the step and the caller frees
 * pr (prep_free). */
static st_status prep_build(sign_prep *pr, const st_soup *s, const st_pseudo_params *p,
                            const st_progress *progress, const char **failed, st_error *err)
{
    memset(pr, 0, sizeof *pr);
    const double t0 = now_seconds();
    st_status rc;
    if (s && (p->closed_shells || p->fill_holes || (p->sides && p->sign.cut))) {
        *failed = p->closed_shells ? "shells" : p->fill_holes ? "holes" : "vote";
        if ((rc = st_soup_edges_build(&pr->edges, s, err)))
            return rc;
        pr->have_edges = 1;
    }
    if (s && p->closed_shells) {
        *failed = "shells";
        st_progress_report(progress, "shells", 0.0);
        if ((rc = st_soup_closed_shells_edges(&pr->shells, s, &pr->edges, err)))
            return rc;
        pr->shortcut = p->shells_shortcut && pr->shells.count > 0 &&
                       pr->shells.open_triangles == 0;
        if (pr->shortcut) {
            /* nothing after reads them: gone before a BVH is built */
            st_soup_edges_free(&pr->edges);
            pr->have_edges = 0;
        }
    }
    pr->seconds = now_seconds() - t0;
    return ST_OK;
}

/* Step 2's symmetry (pseudo.h): the soup's symmetries at a voxel's
 * tolerance, searched only where a fill could change something (the
 * gate); where they are, *caps becomes the caps the fill does not cover
 * and the fill. */
static st_status symmetric_fill(st_grid *g, const st_soup *s, const st_soup_edges *edges,
                                const st_bvh *bvh, const st_pseudo_params *p,
                                st_pseudo_stats *st, st_soup **caps, st_error *err)
{
    const double t0 = now_seconds();
    st_symmetry_params sp = st_symmetry_params_default();
    sp.tolerance = g->voxel;
    /* the gate (symmetry.h): where no fill can drop a cap or close an open
     * rim, the search would change nothing; its record says why */
    int may = 1;
    st_symmetry_fill_gate gate;
    st_status rc = st_symmetry_fill_may_act(&may, &gate, s, edges, bvh, *caps, g->voxel, err);
    if (!rc && !may) {
        st->symmetry_fill.caps = gate.pieces;   /* considered, not searched */
        char why[200];
        snprintf(why, sizeof why, "not searched: no fill could change any of the %zu caps "
                 "by a voxel (%.6g; their largest reach %.6g) and no hole is too large to cap",
                 gate.pieces, g->voxel, gate.reach);
        if (st_meta_set(&g->meta, "symmetry_fill", why))
            rc = st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory");
    }
    rc = rc || !may ? rc : st_symmetry_detect(&st->symmetries, s, bvh, &sp, err);
    if (rc || st->symmetries.n == 0) {
        st->seconds_symmetry = now_seconds() - t0;
        return rc;
    }
    st_soup *fill = NULL, *kept = NULL;
    rc = st_symmetry_fill(&fill, &kept, s, edges, bvh, &st->symmetries, *caps, g->voxel,
                          &st->symmetry_fill, err);
    rc = rc ? rc : st_soup_append(kept, fill, err);
    char buf[200];
    const st_symmetry_fill_stats *f = &st->symmetry_fill;
    snprintf(buf, sizeof buf, "%zu symmetries, %zu maps: %zu triangles, %zu of %zu caps "
             "covered (%zu agreeing kept), %zu of %zu open holes filled, %zu left open",
             st->symmetries.n, f->maps, f->triangles, f->caps_covered, f->caps, f->caps_agree,
             f->open_filled, f->open, f->unclosed);
    if (!rc && st_meta_set(&g->meta, "symmetry_fill", buf))
        rc = st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory");
    if (!rc && p->symmetric_fill && fill->ntris) {
        *p->symmetric_fill = fill;
        fill = NULL;
    }
    st_soup_free(fill);
    if (rc) {
        st_soup_free(kept);
    } else {
        st_soup_free(*caps);
        *caps = kept;
    }
    st->seconds_symmetry = now_seconds() - t0;
    return rc;
}

/* Step 2: the caps of s's holes, lowered into g; *with_caps gets s and its
 * caps as one soup (NULL when there are none). */
static st_status add_caps(st_grid *g, const st_soup *s, const st_soup_edges *edges,
                          const st_bvh *bvh, const st_pseudo_params *p,
                          st_pseudo_stats *st, st_soup **with_caps, st_soup **caps_out,
                          st_error *err)
{
    *with_caps = NULL;
    *caps_out = NULL;
    st_soup *caps = NULL;
    st_status rc = st_soup_hole_caps_shared(&caps, s, edges, bvh, &p->holes, &st->holes, err);
    if (rc)
        return rc;
    /* the symmetric fill where there are caps, or loops too large to cap */
    const int open = st->holes.loops > st->holes.filled;
    if (p->symmetry && (caps->ntris || open) &&
        (rc = symmetric_fill(g, s, edges, bvh, p, st, &caps, err))) {
        st_soup_free(caps);
        return rc;
    }
    st->cap_triangles = caps->ntris;
    double reach = p->cap_reach * g->voxel;
    if (g->band < reach)
        reach = g->band;
    char buf[96];
    snprintf(buf, sizeof buf, "%zu of %zu loops capped, %zu triangles", st->holes.filled,
             st->holes.loops, caps->ntris);
    rc = st_meta_set(&g->meta, "hole_caps", buf)
             ? st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory") : ST_OK;
    if (!rc && caps->ntris) {
        st_soup *all = st_soup_new();
        rc = all ? ST_OK : st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory");
        rc = rc ? rc : st_dist_lower(g, caps, reach, err);
        rc = rc ? rc : st_soup_append(all, s, err);
        rc = rc ? rc : st_soup_append(all, caps, err);
        if (rc)
            st_soup_free(all);
        else {
            *with_caps = all;
            *caps_out = caps;
            caps = NULL;
        }
    }
    st_soup_free(caps);
    return rc;
}

/* Step 3 with the sides (sides.h): the plain majority turns each
 * orientable region, the regions' local winding numbers join the votes as
 * the cut's evidence. */
static st_status vote_with_sides(st_grid *g, const st_soup *s, const st_soup_edges *edges,
                                 const st_pseudo_params *p, st_pseudo_stats *st,
                                 const st_progress *progress, st_error *err)
{
    const size_t n = st_grid_count(g);
    uint8_t *votes = st_malloc_array(n ? n : 1, 1);
    int8_t *evidence = st_malloc_array(n ? n : 1, 1);
    st_status rc = votes && evidence ? ST_OK
                 : st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory for the sides");
    st_sides_params sp = p->sides_params;
    if (!sp.progress)
        sp.progress = progress;
    /* s: the soup, then its caps */
    const size_t seen = !edges && st->cap_triangles ? s->ntris - st->cap_triangles : 0;
    if (sp.past_caps && !sp.seen_triangles)
        sp.seen_triangles = seen;
    if (!sp.column_seen)
        sp.column_seen = seen;
    /* voxels the cut takes as the votes say get no evidence (mincut.h) */
    const int decided = st_mincut_params_default().fixed_evidence;
    rc = rc ? rc : st_sign_votes_progress(g, &p->sign, votes, progress, err);
    if (!rc)
        st_progress_report(progress, "sides", 0.0);
    rc = rc ? rc : st_sides_evidence_edges(evidence, g, votes, decided, s, edges, &sp,
                                           &st->sides, err);
    if (!rc)
        st_progress_report(progress, "cut", 0.0);
    rc = rc ? rc : st_sign_field_evidence(g, &p->sign, evidence, votes, progress, err);
    if (!rc)
        st_progress_report(progress, "sides", 0.5);
    rc = rc ? rc : st_sides_mirror(g, s, sp.seen_triangles, &st->sides, &st->mirrored, err);
    rc = rc ? rc : st_sides_columns(g, s, &sp, &st->sides, p->refine.band_voxels,
                                    &st->columned, err);
    if (!rc)
        st_progress_report(progress, "sides", 1.0);
    free(votes);
    free(evidence);
    return rc;
}

st_status st_pseudo_sign(st_grid *g, const st_soup *s, const st_pseudo_params *p,
                         st_pseudo_stats *stats, const st_progress *progress,
                         st_error *err)
{
    return st_pseudo_sign_bvh(g, s, p, stats, progress, NULL, err);
}

/* Between the steps: a caller that asked to stop gets ST_ECANCELLED. */
#define STOP_IF_CANCELLED()                                                    \
    do {                                                                       \
        if (st_progress_cancelled(progress)) {                                 \
            rc = st_error_set(err, ST_ECANCELLED, NULL, 0, "cancelled");       \
            goto done;                                                         \
        }                                                                      \
    } while (0)

/* st_pseudo_sign_bvh, with step 1's tables given (and freed here) or
 * built here (given NULL), and s's BVH already built (bvh_given, may be
 * NULL; bvh_seconds its time, counted as the BVH's): the steps use it
 * instead of building one, and it is the one handed out (freed on
 * failure, or when bvh_out is NULL). */
static st_status pseudo_sign(st_grid *g, const st_soup *s, const st_pseudo_params *p,
                             st_pseudo_stats *stats, const st_progress *progress,
                             st_bvh **bvh_out, sign_prep *given, st_bvh *bvh_given,
                             double bvh_seconds, st_error *err)
{
    sign_prep own, *pr = given ? given : &own;
    if (!given)
        memset(&own, 0, sizeof own);
    if (bvh_out)
        *bvh_out = NULL;
    if (p && p->symmetric_fill)
        *p->symmetric_fill = NULL;
    st_pseudo_stats local;
    st_pseudo_stats *st = stats ? stats : &local;
    memset(st, 0, sizeof *st);
    if (!g || !p) {
        prep_free(pr);
        st_bvh_free(bvh_given);
        return st_error_set(err, ST_EINTERNAL, NULL, 0, "st_pseudo_sign: bad arguments");
    }
    st->surface = s != NULL;
    st->event_distance = st_sign_event_distance(&p->sign, g);
    st_soup *with_caps = NULL, *caps = NULL;
    st_bvh *caps_bvh = NULL;
    /* s's BVH, built once for the steps that read it (the edge table is
     * step 1's, pr's) */
    st_bvh *bvh = bvh_given;
    st->seconds_bvh = bvh_seconds;
    st_status rc = ST_OK;
    double t0 = now_seconds() - (given ? given->seconds : 0.0);
    STOP_IF_CANCELLED();
    if (!given && (rc = prep_build(&own, s, p, progress, &st->failed_step, err)))
        goto done;
    st->shells = pr->shells.count;
    st->shell_open_triangles = pr->shells.open_triangles;
    if (pr->shortcut) {
        st->shells_only = 1;
        if ((rc = shells_only(g, &pr->shells, p, pr->far, st, err)))
            goto done;
        st->seconds_shells = now_seconds() - t0;
        goto count_inside;
    }
    STOP_IF_CANCELLED();
    double t1 = now_seconds();
    st->seconds_shells = t1 - t0;
    st->failed_step = "holes";
    if (s && p->fill_holes) {
        st_progress_report(progress, "holes", 0.0);
        if ((!bvh && (rc = st_bvh_build(&bvh, s, err))) ||
            (rc = add_caps(g, s, &pr->edges, bvh, p, st, &with_caps, &caps, err)))
            goto done;
    }
    STOP_IF_CANCELLED();
    double t2 = now_seconds();
    st->seconds_holes = t2 - t1;
    st->failed_step = "vote";
    if (s && p->sides && p->sign.cut) {
        /* the caps are new triangles: their soup gets its own edges */
        if ((rc = vote_with_sides(g, with_caps ? with_caps : s, with_caps ? NULL : &pr->edges, p, st,
                                  progress, err)))
            goto done;
    } else if ((rc = st_sign_field(g, &p->sign, progress, err)))
        goto done;
    if (pr->have_edges) {
        st_soup_edges_free(&pr->edges);
        pr->have_edges = 0;
    }
    STOP_IF_CANCELLED();
    double t3 = now_seconds();
    st->seconds_vote = t3 - t2;
    st->failed_step = "refine";
    if (s && p->refine_signs) {
        st_progress_report(progress, "refine", 0.0);
        if (!with_caps && bvh && s->ntris)
            rc = st_sign_refine_bvh(g, bvh, &p->refine, &st->refined, err);
        else if (with_caps && bvh && !(rc = st_bvh_build(&caps_bvh, caps, err))) {
            /* s's BVH and one over the caps alone: with_caps is s, then the caps */
            const st_bvh *parts[2] = {bvh, caps_bvh};
            rc = st_sign_refine_parts(g, with_caps, parts, 2, &p->refine, &st->refined, err);
        } else if (!rc)
            rc = st_sign_refine(g, with_caps ? with_caps : s, &p->refine, &st->refined, err);
        if (rc)
            goto done;
        st_progress_report(progress, "refine", 1.0);
    }
    STOP_IF_CANCELLED();
    double t4 = now_seconds();
    st->seconds_refine = t4 - t3;
    st->failed_step = "shells";
    if (s && p->closed_shells && (rc = st_shells_sign(g, &pr->shells, &st->shell_changed, err)))
        goto done;
    st->seconds_shells += now_seconds() - t4;
count_inside:;
    size_t inside = 0;
    const size_t n = st_grid_count(g);
    #pragma omp parallel for reduction(+ : inside) schedule(static) if (n >= 65536)
    for (size_t i = 0; i < n; i++)
        inside += g->data[i] < 0.0f;
    st->inside = inside;
    st->failed_step = NULL;
    if (bvh_out && s) {
        const double tb = now_seconds();
        st_progress_report(progress, "bvh", 0.0);
        if (!bvh && (rc = st_bvh_build(&bvh, s, err)))
            goto done;
        st->seconds_bvh += now_seconds() - tb;
        *bvh_out = bvh;
        bvh = NULL;
    }
done:
    if (rc && p->symmetric_fill) {
        st_soup_free(*p->symmetric_fill);
        *p->symmetric_fill = NULL;
    }
    st_bvh_free(bvh);
    st_soup_free(with_caps);
    st_soup_free(caps);
    st_bvh_free(caps_bvh);
    prep_free(pr);
    return rc;
}

st_status st_pseudo_sign_bvh(st_grid *g, const st_soup *s, const st_pseudo_params *p,
                             st_pseudo_stats *stats, const st_progress *progress,
                             st_bvh **bvh_out, st_error *err)
{
    return pseudo_sign(g, s, p, stats, progress, bvh_out, NULL, NULL, 0.0, err);
}

st_status st_pseudo_volume(st_grid **out, const st_soup *s, const st_dist_params *dp,
                           const st_pseudo_params *p, st_pseudo_stats *stats,
                           const st_progress *progress, st_error *err)
{
    return st_pseudo_volume_bvh(out, s, dp, p, stats, progress, NULL, err);
}

st_status st_pseudo_volume_bvh(st_grid **out, const st_soup *s, const st_dist_params *dp,
                               const st_pseudo_params *p, st_pseudo_stats *stats,
                               const st_progress *progress, st_bvh **bvh_out, st_error *err)
{
    if (bvh_out)
        *bvh_out = NULL;
    if (out)
        *out = NULL;
    if (!out || !s || !dp || !p)
        return st_error_set(err, ST_EINTERNAL, NULL, 0, "st_pseudo_volume: bad arguments");
    st_grid *g = NULL;
    st_status rc = ST_OK;
    const int far_may = p->signs_only && p->closed_shells && isfinite(dp->band);
    const int dense = bvh_out && st_dist_wants_bvh(s, dp);
    if (!far_may && !dense) {
        rc = st_dist_field(&g, s, dp, progress, err);
        rc = rc ? rc : st_pseudo_sign_bvh(g, s, p, stats, progress, bvh_out, err);
    } else {
        /* Step 1 first: where the shells decide every sign and only signs
         * are read, the field needs no distance (st_dist_field_far); a
         * dense soup's band comes from the BVH the caller gets anyway
         * (st_dist_wants_bvh), built after step 1 so that a closed soup's
         * edge table (gone after it) and its BVH are never held at once. */
        sign_prep pr;
        const char *failed = NULL;
        st_bvh *bvh = NULL;
        double bvh_seconds = 0.0;
        if ((rc = prep_build(&pr, s, p, progress, &failed, err)) && stats) {
            memset(stats, 0, sizeof *stats);
            stats->failed_step = failed;
        }
        pr.far = far_may && pr.shortcut;
        if (!rc && pr.far) {
            rc = st_dist_field_far(&g, s, dp, err);
        } else if (!rc) {
            const double tb = now_seconds();
            if (dense)
                rc = st_bvh_build(&bvh, s, err);
            bvh_seconds = now_seconds() - tb;
            rc = rc ? rc : st_dist_field_bvh(&g, s, dp, bvh, progress, err);
        }
        if (rc) {
            prep_free(&pr);
            st_bvh_free(bvh);
        } else
            rc = pseudo_sign(g, s, p, stats, progress, bvh_out, &pr, bvh, bvh_seconds, err);
    }
    if (rc) {
        st_grid_free(g);
        return rc;
    }
    *out = g;
    return ST_OK;
}
