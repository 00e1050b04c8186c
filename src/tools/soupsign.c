/*
 * soupsign - the pseudo volume of a soup: signs for a distance field.
 *
 *   soupsign [FIELD] [-k K | --band D] [--rays 13|26] [--rule NAME] [-o OUT]
 *
 * Reads a distance field (from soupdist: .vdb, .vti, or an OpenVDB stream
 * on stdin) and writes the signed field: |value| the distance, negative
 * inside the pseudo volume. See man/man1/soupsign.1 and sign.h.
 */
#define _GNU_SOURCE
#include "../cli/tool.h"
#include "souptet/gridio.h"
#include "souptet/outfile.h"
#include "souptet/pseudo.h"

#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

/* CPU seconds of the process, all threads (for -v on a shared machine,
 * where wall time says little about the work); 0 if unavailable. */
static double cpu_now(void)
{
    struct timespec ts;
    if (clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts) != 0)
        return 0.0;
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static void usage(void)
{
    printf(
"Usage: soupsign [OPTION]... [FIELD]\n"
"Sign a distance field by volume-event voting: negative inside the pseudo\n"
"volume of the soup (Spillmann et al. 2006, section 3).\n"
"\n"
"FIELD is a distance field from soupdist (.vdb or .vti); '-' or none reads\n"
"an OpenVDB stream from stdin.\n"
"\n"
"  -k K                 event threshold on P = 1 - c|d|, in (0, 1] (default 1; paper: 0.8);\n"
"                       1 counts surface crossings (Nooruddin-Turk parity)\n"
"      --band D         c = 1/(D voxels) instead of 1/max|d| (a narrow band suffices)\n"
"      --rays 13|26     one or both directions along the 13 lines (default 26)\n"
"      --toggle first|nearest|crossing  where in an event run the parity\n"
"                       toggles (default crossing: where the surface crosses\n"
"                       the line, beside the nearest voxel on the side of its\n"
"                       nearer neighbour; nearest: on the nearest voxel;\n"
"                       the paper: first)\n"
"      --odd keep|ignore  keep or drop lines with an odd number of events\n"
"                       (default keep: the paper)\n"
"      --nested union|parity  union: a voxel hidden from outside along\n"
"                       every ray is inside whatever the parity (keeps\n"
"                       interpenetrating parts whole; default); parity: the paper\n"
"      --runs split|whole  split: an event run whose distance dips twice\n"
"                       holds two crossings (two surfaces closer than the\n"
"                       event distance; default, crossing toggle only);\n"
"                       whole: one event per run (the paper)\n"
"      --cut on|off     on: the votes are evidence for a minimum cut that\n"
"                       follows the surface and spans its holes by the least\n"
"                       area (default); off: the majority decides (the paper)\n"
"      --surface S|none the soup the field was computed from: its closed pieces,\n"
"                       its holes capped and the signs within a voxel of it\n"
"                       refined by exact segment crossings (pseudo.h). Default:\n"
"                       the soup soupdist recorded in the field, when that file\n"
"                       is still there with the same bytes (size and content\n"
"                       hash); else the vote alone, with a note. none: the vote\n"
"                       alone (as is --rule paper)\n"
"      --fill-holes on|off  with --surface: cap the surface's holes (loops of\n"
"                       boundary edges, by the caps --caps says,\n"
"                       when small beside the surface around them) before\n"
"                       voting (default on)\n"
"      --caps auto|area|bend|planes|planes-bend  with --fill-holes: each cap is\n"
"                       the loop's triangulation of least area (area) or the\n"
"                       one that bends least (bend); planes: lost corners\n"
"                       rebuilt where the faces' planes along the loop meet\n"
"                       (one cone, or fans from several), when that continues\n"
"                       them better, else the least-area cap (planes-bend:\n"
"                       else the one that bends least); auto (default):\n"
"                       planes-bend where the soup around its holes is\n"
"                       intact (the triangles on a hole's edge at most half\n"
"                       its area, and not seen from one side along an axis),\n"
"                       else area\n"
"      --shells on|off  with --surface: the surface's closed pieces (every edge\n"
"                       shared by two faces) bound their solid exactly: inside\n"
"                       them is inside, and when the surface is nothing else\n"
"                       the signs are exactly their solid (default on)\n"
"      --symmetry on|off  with --surface and --fill-holes: the surface's mirror\n"
"                       planes and rotation axes fill the holes their images\n"
"                       close, capped or too large to cap (default on)\n"
"      --sides on|off   with --surface: the side of the surface's oriented walls\n"
"                       each voxel near them is on (its pieces oriented by\n"
"                       propagation, each turned the way the votes read it)\n"
"                       joins the votes as evidence for the cut, and a\n"
"                       one-sided scan's far side is mirrored about its\n"
"                       horizon (default on)\n"
"      --onesided plain|past-caps  with --sides on: past-caps reads the view of\n"
"                       the surface alone (not its caps), mirrors only where\n"
"                       its rim folds (not walls along the view) and past\n"
"                       caps and the surface's lowest point (default plain)\n"
"      --columns on|off  with --sides on: a scan seen along an axis (under\n"
"                       0.02 of it faces away) is nothing before the first\n"
"                       surface on each line along the axis, and between two\n"
"                       of its surfaces leaves the solid; unless mirrored, a\n"
"                       flat hole cap facing away ends it, and the air under\n"
"                       a cap that rises is mirrored above it (default on)\n"
"      --refine-band D  refine voxels nearer than D voxels (default 1.5)\n"
"      --refine-radius R  neighbours within R voxels per axis (default 2)\n"
"      --refine-answers A  neighbours' answers combined per voxel (default 6)\n"
"      --rule NAME      a preset: paper (exactly the paper's rule), parity\n"
"                       (k = 1), default; options after it adjust it\n"
"  -o, --output OUT     .vdb or .vti file; '-' or none: OpenVDB stream on stdout\n"
"      --threads T      threads to use (default: all cores)\n"
"      --max-memory SZ  refuse fields larger than SZ (default 80%% of RAM)\n"
"  -q, --quiet          no messages but errors\n"
"  -v, --verbose        report the rule, the event distance, each step, the\n"
"                       fill (boundary with no soup near), the soup's\n"
"                       symmetries (reported, not used) and timings\n"
"  -h, --help           show this help and exit\n"
"  -V, --version        show the version and commit and exit\n"
"\n"
"Examples:\n"
"  soupdist bunny.obj | soupsign -o bunny-sdf.vti   (uses bunny.obj, recorded)\n"
"  soupdist bunny.obj | soupsign --surface none -o votes-only.vti\n"
"  soupdist --band full -r 128 scan.ply | soupsign --rule paper -o scan.vdb\n"
"\n"
"Exit status: 0 ok, 1 bad input or failure, 2 usage error.\n");
}

/* The soup soupdist recorded in the field (source_path, source_size,
 * source_hash): *soup gets it when the file is there with the same bytes.
 * A missing, unreadable or changed file is a note, and *soup stays NULL
 * (the vote alone); never is a file with other bytes used. Fails only
 * when the very bytes soupdist read no longer parse. */
static int recorded_surface(tool_ctx *t, const st_grid *g, st_soup **soup, st_error *err)
{
    const char *path = st_meta_get(&g->meta, "source_path");
    const char *size = st_meta_get(&g->meta, "source_size");
    const char *hash = st_meta_get(&g->meta, "source_hash");
    *soup = NULL;
    if (!size || !hash) {
        tool_say(t, 1, "note: the field names its soup %s but not its size and hash: "
                       "signs by the vote alone (give --surface FILE)", path);
        return 0;
    }
    st_soup_source src;
    st_error e;
    st_error_clear(&e);
    st_status rc = st_soup_read_source(soup, path, &src, NULL, &e);
    char got[32];
    snprintf(got, sizeof got, "%llu", src.size);
    const int same = src.hash[0] && strcmp(got, size) == 0 && strcmp(src.hash, hash) == 0;
    if (rc && (same || rc == ST_ENOMEM)) {   /* out of memory is no "cannot be read" */
        *err = e;
        return 1;
    }
    if (rc || !same) {
        st_soup_free(*soup);
        *soup = NULL;
        if (src.hash[0] && !same)
            tool_say(t, 1, "note: %s has changed since soupdist read it (%s bytes, %s; now %s "
                           "bytes, %s): signs by the vote alone (give --surface FILE)",
                     path, size, hash, got, src.hash);
        else {
            char msg[512];
            st_error_format(&e, msg, sizeof msg);
            tool_say(t, 1, "note: the field's soup cannot be read (%s): signs by the vote "
                           "alone (give --surface FILE)", msg);
        }
        return 0;
    }
    tool_say(t, 2, "surface: %s, as soupdist read it (%s bytes, %s)", path, size, hash);
    return 0;
}

enum { OPT_BAND = TOOL_OPT_FIRST, OPT_RAYS, OPT_TOGGLE, OPT_ODD, OPT_NESTED, OPT_RUNS, OPT_CUT,
       OPT_CAPS, OPT_SIDES, OPT_ONESIDED, OPT_COLUMNS, OPT_RULE, OPT_SURFACE, OPT_REFINE_BAND, OPT_REFINE_RADIUS,
       OPT_REFINE_ANSWERS };

static const struct option longopts[] = {
    {"band", required_argument, NULL, OPT_BAND},
    {"rays", required_argument, NULL, OPT_RAYS},
    {"toggle", required_argument, NULL, OPT_TOGGLE},
    {"odd", required_argument, NULL, OPT_ODD},
    {"nested", required_argument, NULL, OPT_NESTED},
    {"runs", required_argument, NULL, OPT_RUNS},
    {"cut", required_argument, NULL, OPT_CUT},
    TOOL_LONG_OPTIONS_PSEUDO,
    {"caps", required_argument, NULL, OPT_CAPS},
    {"sides", required_argument, NULL, OPT_SIDES},
    {"onesided", required_argument, NULL, OPT_ONESIDED},
    {"columns", required_argument, NULL, OPT_COLUMNS},
    {"rule", required_argument, NULL, OPT_RULE},
    {"surface", required_argument, NULL, OPT_SURFACE},
    {"refine-band", required_argument, NULL, OPT_REFINE_BAND},
    {"refine-radius", required_argument, NULL, OPT_REFINE_RADIUS},
    {"refine-answers", required_argument, NULL, OPT_REFINE_ANSWERS},
    TOOL_LONG_OPTIONS_OUTPUT,
    TOOL_LONG_OPTIONS_END};

/* What the command line asks for. */
typedef struct soupsign_settings {
    tool_common co;
    st_sign_params sign;
    st_sign_refine_params refine;
    const char *in, *surface;
    int paper, fill_holes, symmetry, bend_caps, use_shells, use_sides, past_caps, columns, no_surface;
} soupsign_settings;

static int option(tool_ctx *t, int c, const char *arg, void *settings)
{
    soupsign_settings *s = settings;
    switch (c) {
    case 'k':
        if (tool_parse_double(t, "-k", arg, 1e-9, 1.0, &s->sign.k))
            return TOOL_EXIT_USAGE;
        break;
    case OPT_BAND:
        if (tool_parse_double(t, "--band", arg, 1e-3, 1e6, &s->sign.band_voxels))
            return TOOL_EXIT_USAGE;
        break;
    case OPT_RAYS:
        if (strcmp(arg, "13") == 0)
            s->sign.rays = 13;
        else if (strcmp(arg, "26") == 0)
            s->sign.rays = 26;
        else
            return tool_usage_error(t, "--rays is 13 or 26, not '%s'", arg);
        break;
    case OPT_TOGGLE:
        if (strcmp(arg, "first") == 0)
            s->sign.toggle = ST_TOGGLE_FIRST;
        else if (strcmp(arg, "nearest") == 0)
            s->sign.toggle = ST_TOGGLE_NEAREST;
        else if (strcmp(arg, "crossing") == 0)
            s->sign.toggle = ST_TOGGLE_CROSSING;
        else
            return tool_usage_error(t, "--toggle is first, nearest or crossing, not '%s'",
                                    arg);
        break;
    case OPT_ODD:
        if (strcmp(arg, "keep") == 0)
            s->sign.ignore_odd = 0;
        else if (strcmp(arg, "ignore") == 0)
            s->sign.ignore_odd = 1;
        else
            return tool_usage_error(t, "--odd is keep or ignore, not '%s'", arg);
        break;
    case OPT_NESTED:
        if (strcmp(arg, "union") == 0)
            s->sign.nested_union = 1;
        else if (strcmp(arg, "parity") == 0)
            s->sign.nested_union = 0;
        else
            return tool_usage_error(t, "--nested is union or parity, not '%s'", arg);
        break;
    case OPT_RUNS:
        if (strcmp(arg, "split") == 0)
            s->sign.split_runs = 1;
        else if (strcmp(arg, "whole") == 0)
            s->sign.split_runs = 0;
        else
            return tool_usage_error(t, "--runs is split or whole, not '%s'", arg);
        break;
    case OPT_CUT:
        if (tool_parse_switch(t, "--cut", arg, &s->sign.cut))
            return TOOL_EXIT_USAGE;
        break;
    case TOOL_OPT_FILL_HOLES:
    case TOOL_OPT_SHELLS:
    case TOOL_OPT_SYMMETRY:
        return tool_pseudo_option(t, c, arg,
                                  &(tool_pseudo_switches){&s->fill_holes, &s->use_shells,
                                                          &s->symmetry});
    case OPT_CAPS:
        if (strcmp(arg, "auto") == 0)
            s->bend_caps = -1;
        else if (strcmp(arg, "area") == 0)
            s->bend_caps = 0;
        else if (strcmp(arg, "bend") == 0)
            s->bend_caps = 1;
        else if (strcmp(arg, "planes") == 0)
            s->bend_caps = 2;
        else if (strcmp(arg, "planes-bend") == 0)
            s->bend_caps = 3;
        else
            return tool_usage_error(t, "--caps is auto, area, bend, planes or planes-bend, not '%s'",
                                    arg);
        break;
    case OPT_SIDES:
        if (tool_parse_switch(t, "--sides", arg, &s->use_sides))
            return TOOL_EXIT_USAGE;
        break;
    case OPT_ONESIDED:
        if (strcmp(arg, "plain") == 0)
            s->past_caps = 0;
        else if (strcmp(arg, "past-caps") == 0)
            s->past_caps = 1;
        else
            return tool_usage_error(t, "--onesided is plain or past-caps, not '%s'", arg);
        break;
    case OPT_COLUMNS:
        if (tool_parse_switch(t, "--columns", arg, &s->columns))
            return TOOL_EXIT_USAGE;
        break;
    case OPT_RULE:
        if (st_sign_params_named(&s->sign, arg))
            return tool_usage_error(t, "unknown rule '%s' (paper, parity, default)", arg);
        s->paper = strcmp(arg, "paper") == 0;
        break;
    case OPT_SURFACE:
        s->no_surface = strcmp(arg, "none") == 0;
        s->surface = s->no_surface ? NULL : arg;
        break;
    case OPT_REFINE_RADIUS:
    case OPT_REFINE_ANSWERS: {
        size_t v;
        if (tool_parse_size(t, c == OPT_REFINE_RADIUS ? "--refine-radius" : "--refine-answers",
                            arg, 1, c == OPT_REFINE_RADIUS ? 3 : 124, &v))
            return TOOL_EXIT_USAGE;
        if (c == OPT_REFINE_RADIUS)
            s->refine.radius = (int)v;
        else
            s->refine.answers = (int)v;
        break;
    }
    case OPT_REFINE_BAND:
        if (tool_parse_double(t, "--refine-band", arg, 1e-3, 8.0, &s->refine.band_voxels))
            return TOOL_EXIT_USAGE;
        break;
    }
    return TOOL_CONTINUE;
}

static int check(tool_ctx *t, int argc, char *argv[], void *settings)
{
    soupsign_settings *s = settings;
    TOOL_TRY(tool_one_input(t, argc, argv, "input field", "-", &s->in));
    TOOL_TRY(tool_refuse_terminal(t, s->in, STDIN_FILENO, "no input: give a field or pipe "
                                  "one in (soupdist mesh.obj | soupsign)"));
    if (s->surface)
        TOOL_TRY(tool_refuse_terminal(t, s->surface, STDIN_FILENO, TOOL_TTY_SURFACE));
    TOOL_TRY(tool_grid_output(t, s->co.out));
    if (s->surface && s->paper)
        return tool_usage_error(t, "--rule paper is the paper's rule exactly: it takes no --surface");
    if (s->surface && st_path_is_stdio(s->surface) && st_path_is_stdio(s->in))
        return tool_usage_error(t, "the field and the surface cannot both come from stdin");
    return tool_output_check(t, s->co.out);
}

/* The pseudo volume's settings the options give (pseudo.h). */
static st_pseudo_params pseudo_params(const soupsign_settings *s)
{
    st_pseudo_params pp = st_pseudo_params_default();
    pp.sign = s->sign;
    pp.refine = s->refine;
    pp.fill_holes = s->fill_holes;
    pp.symmetry = s->symmetry;
    if (s->bend_caps >= 0) {     /* chosen: on every soup */
        pp.holes.bend = s->bend_caps & 1;
        pp.holes.planes = (s->bend_caps & 2) != 0;
        pp.holes.intact = 1.0;
        pp.holes.onesided = 0.0;
    }
    pp.closed_shells = s->use_shells;
    pp.sides = s->use_sides;
    pp.sides_params.past_caps = s->past_caps;
    if (!s->columns)
        pp.sides_params.column_ratio = 0.0;
    return pp;
}

/* -v: how much of the pseudo volume's boundary has no soup within a voxel
 * (the fill), and of it the symmetric fill's (sym; NULL: none). */
static st_status say_fill(const tool_ctx *t, const st_grid *g, const st_bvh *bvh,
                          const st_soup *sym, st_error *err)
{
    st_soup *fill = NULL;
    st_pseudo_guess gs;
    st_status rc = st_pseudo_fill(&fill, g, bvh, NULL, err);
    if (rc)
        return rc;
    st_pseudo_guess_measure(&gs, g, fill, bvh);
    rc = st_pseudo_guess_symmetric(&gs, g, fill, sym, err);
    st_soup_free(fill);
    if (rc)
        return rc;
    const double all = gs.boundary_faces ? (double)gs.boundary_faces : 1.0;
    char of_sym[96] = "";
    if (sym)
        snprintf(of_sym, sizeof of_sym, "; %zu of them (%.1f%%) from the symmetric fill",
                 gs.symmetric_faces, 100.0 * (double)gs.symmetric_faces / all);
    tool_say(t, 2, "fill: %zu of %zu boundary faces (%.1f%%) have no soup within a voxel "
             "(caps, a far side), up to %.3g voxels (%.6g) from it%s", gs.fill_faces,
             gs.boundary_faces, 100.0 * (double)gs.fill_faces / all, gs.depth / g->voxel,
             gs.depth, of_sym);
    return ST_OK;
}

static int run(tool_ctx *t, void *settings)
{
    const soupsign_settings *s = settings;
    const char *in = s->in, *surface = s->surface;
    const st_sign_params *p = &s->sign;
    tool_set_threads(s->co.threads);
    st_error err;
    st_error_clear(&err);
    st_grid *g = NULL;
    st_soup *soup = NULL;
    st_bvh *bvh = NULL;   /* -v with the soup: for the fill's report */
    st_soup *sym = NULL;  /* -v: the symmetric fill, for the guess's share */
    st_pseudo_stats ps;
    memset(&ps, 0, sizeof ps);
    int rc = TOOL_EXIT_FAIL;
    double t0 = tool_now();
    if (st_grid_read(&g, in, s->co.max_bytes, &err)) {
        rc = tool_fail(t, &err);
        goto done;
    }
    double t1 = tool_now();
    if (surface) {
        if (tool_soup_read(t, &soup, surface, &err)) {
            rc = tool_fail(t, &err);
            goto done;
        }
        t1 = tool_now();   /* reading the surface is not signing */
    } else if (!s->no_surface && !s->paper && st_meta_get(&g->meta, "source_path")) {
        if (recorded_surface(t, g, &soup, &err)) {
            rc = tool_fail(t, &err);
            goto done;
        }
        if (soup)
            surface = st_meta_get(&g->meta, "source_path");
        t1 = tool_now();
    }
    st_pseudo_params pp = pseudo_params(s);
    if (soup && t->verbosity >= 2)
        pp.symmetric_fill = &sym;
    st_progress prog = tool_progress(t);
    const double c0 = cpu_now();
    /* -v with the soup: its BVH too, for how much of the boundary is a
     * guess (st_pseudo_guess_measure) */
    if (st_pseudo_sign_bvh(g, soup, &pp, &ps, &prog,
                           soup && t->verbosity >= 2 ? &bvh : NULL, &err)) {
        tool_progress_end(t);
        rc = tool_fail_file(t, &err, surface && ps.failed_step &&
                                         strcmp(ps.failed_step, "vote") != 0 ? surface
                                                                             : tool_in_name(in));
        goto done;
    }
    const double cpu_sign = cpu_now() - c0;
    tool_progress_end(t);
    double t2 = tool_now();
    if (tool_meta_record(t, &g->meta)) {
        rc = tool_fail_nomem(t, &err);
        goto done;
    }
    if (st_grid_write(g, s->co.out, &err)) {
        rc = tool_fail(t, &err);
        goto done;
    }
    double t3 = tool_now();
    size_t n = st_grid_count(g);
    tool_say(t, 2, "grid %zux%zux%zu, rule: %s", g->nx, g->ny, g->nz,
             st_meta_get(&g->meta, "sign_rule"));
    tool_say(t, 2, "event distance %.6g (%.3g voxels); %zu of %zu voxels inside (%.2f%%)",
             ps.event_distance, ps.event_distance / g->voxel, ps.inside, n,
             100.0 * (double)ps.inside / (double)n);
    if (ps.shells_only)
        tool_say(t, 2, "every triangle is in a closed shell: the signs are the shells' "
                 "solid; no caps, sides, vote or refinement");
    if (surface && s->fill_holes && !ps.shells_only)
        tool_say(t, 2, "holes: %zu of %zu boundary loops capped (%zu too large, %zu too long, "
                 "%zu edges left open where holes touch unpaired), %.3f s",
                 ps.holes.filled, ps.holes.loops, ps.holes.too_large, ps.holes.too_long,
                 ps.holes.pinched, ps.seconds_holes);
    if (surface && s->fill_holes && ps.holes.loops && !ps.shells_only) {
        char axis[64] = "";
        if (ps.holes.one_sided >= 0.0)
            snprintf(axis, sizeof axis, "; along an axis its back/front is %.3f",
                     ps.holes.one_sided);
        tool_say(t, 2, "caps: %s (the rim is %.3f of the soup's area%s)",
                 ps.holes.continued ? "continuing the faces (planes, else the least bend)"
                                    : "least area",
                 ps.holes.rim_share, axis);
    }
    const int voted = !ps.shells_only;
    if (surface && s->use_sides && p->cut && voted)
        tool_say(t, 2, "sides: %zu orientable regions (%zu turned to the votes, %zu edges "
                 "disagreeing), %zu voxels given their side", ps.sides.regions, ps.sides.turned,
                 ps.sides.conflicts, ps.sides.voxels);
    if (surface && s->use_sides && p->cut && voted)
        tool_say(t, 2, "view: back/front %.3f along (%.3f %.3f %.3f): %s; walls %.2f of its rim",
                 ps.sides.back_front, ps.sides.view[0], ps.sides.view[1], ps.sides.view[2],
                 ps.sides.onesided ? "one-sided" : "not one-sided", ps.sides.walls);
    if (surface && s->use_sides && p->cut && voted && ps.sides.fold)
        tool_say(t, 2, "far side mirrored along step (%d %d %d): %zu voxels",
                 ps.sides.step[0], ps.sides.step[1], ps.sides.step[2], ps.mirrored);
    if (surface && s->use_sides && p->cut && voted)
        tool_say(t, 2, "columns: back/front %.3f along %c%c: %s, %zu voxels made outside",
                 ps.sides.column_back_front, ps.sides.column_dir > 0 ? '+' : '-',
                 "xyz"[ps.sides.column_axis], ps.sides.columns ? "one-sided" : "not one-sided",
                 ps.columned);
    if (surface && voted)
        tool_say(t, 2, "refinement (band %g voxels): %zu signs changed, %.3f s",
                 s->refine.band_voxels, ps.refined, ps.seconds_refine);
    if (surface && s->use_shells)
        tool_say(t, 2, "closed shells: %zu (%zu triangles in none%s), %zu signs changed, "
                 "%.3f s", ps.shells, ps.shell_open_triangles,
                 ps.shells && !ps.shell_open_triangles ? ": the signs are their solid" : "",
                 ps.shell_changed, ps.seconds_shells);
    if (bvh && voted && say_fill(t, g, bvh, sym, &err)) {
        rc = tool_fail(t, &err);
        goto done;
    }
    if (bvh && soup && (rc = tool_report_symmetries(t, soup, bvh, g->voxel, &ps.symmetries,
                                                    &ps.symmetry_fill, ps.seconds_symmetry)))
        goto done;
    tool_say(t, 2, "read %.3f s, signs %.3f s (CPU %.3f s, all threads), write %.3f s",
             t1 - t0, voted ? ps.seconds_vote : ps.seconds_shells, cpu_sign, t3 - t2);
    rc = TOOL_EXIT_OK;
done:
    st_soup_free(sym);
    st_bvh_free(bvh);
    st_grid_free(g);
    st_soup_free(soup);
    return rc;
}

static const tool_spec spec = {"soupsign", usage, ":k:o:qv", longopts, option, check, run};

int main(int argc, char *argv[])
{
    soupsign_settings s = {.sign = st_sign_params_default(),
                           .refine = st_sign_refine_params_default(), .fill_holes = 1,
                           .symmetry = st_pseudo_params_default().symmetry,
                           .bend_caps = -1,
                           .use_shells = 1, .use_sides = 1,
                           .columns = 1};
    return tool_main(&spec, argc, argv, &s, &s.co);
}
