/*
 * tetsmooth - move the vertices of a tet mesh: volume-keeping boundary
 * fairing (Spillmann et al. 2006) or the enclosing fit to a surface with a
 * quality pass (Stuart et al. 2013).
 *
 *   tetsmooth (--fair [--iters N] | --fit --surface S [--offset R]
 *             [--step T] [--max-iters N] [--no-quality]
 *             [--offset-best-effort]) [-o OUT] [MESH]
 *
 * See man/man1/tetsmooth.1 and smooth.h.
 */
#define _GNU_SOURCE
#include "../cli/tool.h"
#include "souptet/bvh.h"
#include "souptet/enclose.h"
#include "souptet/gridio.h"
#include "souptet/pseudo.h"
#include "souptet/outfile.h"
#include "souptet/pipeline.h"
#include "souptet/smooth.h"
#include "souptet/soup.h"
#include "souptet/tetio.h"

#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static void usage(void)
{
    printf(
"Usage: tetsmooth --fair [--iters N] [OPTION]... [MESH]\n"
"       tetsmooth --fit --surface S [--field F] [--offset R] [--step T] [--max-iters N]\n"
"                 [--no-quality] [OPTION]... [MESH]\n"
"Move the vertices of a tet mesh (.vtu; '-' or none reads stdin).\n"
"\n"
"  --fair               implicit fairing of the boundary (Desbrun et al. 1999),\n"
"                       volume kept by a rescale along the normals (Spillmann\n"
"                       et al. 2006, section 4)\n"
"      --iters N        fairing steps (default 3)\n"
"      --lambda L       lambda*dt of each step, umbrella weights (default 1)\n"
"      --min-angle A    no move makes a tet's angles worse than A degrees\n"
"                       (min A, max 180 - A/0.75; default 30)\n"
"      --interior-quality  the quality pass moves interior vertices only\n"
"                       (default: boundary vertices too, in their tangent\n"
"                       plane, then the volume is rescaled)\n"
"  --fit                pull the boundary onto the surface while the mesh keeps\n"
"                       enclosing it (Stuart et al. 2013, section 3.3), then\n"
"                       raise the worst dihedral angles\n"
"      --surface S      the surface to enclose (.obj .off .ply .stl .gltf .glb); required\n"
"      --offset R       stop when every boundary vertex is within R*h of S\n"
"                       (default 0.4)\n"
"      --field F        the signed field the mesh was sculpted from: where S\n"
"                       has no surface, its pseudo volume's boundary (the fill)\n"
"                       counts as surface for --offset, as in soupmesh\n"
"      --offset-best-effort  keep a mesh that misses --offset with exit\n"
"                       status 0 and a warning (default: an error, exit 4)\n"
"      --cell-width H   the lattice cell width h when the mesh does not record\n"
"                       it (meta \"h\", written by latticetet)\n"
"      --step T         fraction of the way to the target per iteration,\n"
"                       in (0, 1] (default 0.5)\n"
"      --max-iters N    fit iterations at most (default 300)\n"
"  either:\n"
"      --quality-rounds N  quality rounds at most (default 40)\n"
"      --no-quality     skip the quality pass (after --fair: interior vertices\n"
"                       only, the volume does not change)\n"
"  -o, --output OUT     .vtu file (or .msh, .node/.ele, .mesh by extension,\n"
"                       without the arrays); '-' or none: .vtu on stdout\n"
TOOL_HELP_TETFORMAT
"      --threads T      threads to use (default: all cores)\n"
"      --max-memory SZ  refuse meshes larger than SZ (default 80%% of RAM)\n"
"  -q, --quiet          no messages but errors\n"
"  -v, --verbose        per-iteration statistics\n"
"  -h, --help           show this help and exit\n"
"  -V, --version        show the version and commit and exit\n"
"\n"
"Examples:\n"
"  latticetet --density 0.5 --cells 16 f.vdb | tetsmooth --fair -o m.vtu\n"
"  soupdist b.obj | soupsign | latticetet --sculpt --surface b.obj --cells 12 \\\n"
"      | tetsmooth --fit --surface b.obj -o b.vtu\n"
"\n"
"Exit status: 0 ok, 1 bad input or failure, 2 usage error, 3 the fitted mesh\n"
"does not enclose S, 4 a boundary vertex stays farther than --offset R*h from S\n"
"(the mesh is written in both cases).\n");
}

enum { OPT_FAIR = TOOL_OPT_FIRST, OPT_FIT, OPT_ITERS, OPT_LAMBDA, OPT_MINANGLE, OPT_SURFACE, OPT_OFFSET,
       OPT_CELL, OPT_STEP, OPT_MAXIT, OPT_QROUNDS, OPT_NOQ, OPT_INTQ, OPT_BEST_EFFORT,
       OPT_FIELD };

typedef struct iter_ctx {
    tool_ctx *t;
} iter_ctx;

static void on_iter(void *ctx, const st_fit_iter *it)
{
    iter_ctx *c = ctx;
    tool_say(c->t, 2,
             "%s %3d: %zu/%zu boundary vertices within offset (max distance %.4g), "
             "dihedral %.2f..%.2f, %zu moved, %zu rejected, %.2f s",
             it->phase, it->iter, it->within_offset, it->boundary_vertices, it->max_distance,
             it->min_dihedral, it->max_dihedral, it->moved, it->rejected, it->seconds);
}

/* What the command line asks for. */
typedef struct tetsmooth_settings {
    tool_common co;
    st_fair_params fair;
    st_fit_params fit;
    const char *in, *surface, *field;
    int mode; /* 1 fair, 2 fit */
    int fair_only, fit_only, noq, best_effort;
} tetsmooth_settings;

static const struct option longopts[] = {
    {"fair", no_argument, NULL, OPT_FAIR},
    {"fit", no_argument, NULL, OPT_FIT},
    {"iters", required_argument, NULL, OPT_ITERS},
    {"lambda", required_argument, NULL, OPT_LAMBDA},
    {"min-angle", required_argument, NULL, OPT_MINANGLE},
    {"interior-quality", no_argument, NULL, OPT_INTQ},
    {"surface", required_argument, NULL, OPT_SURFACE},
    {"field", required_argument, NULL, OPT_FIELD},
    {"offset", required_argument, NULL, OPT_OFFSET},
    {"offset-best-effort", no_argument, NULL, OPT_BEST_EFFORT},
    {"cell-width", required_argument, NULL, OPT_CELL},
    {"step", required_argument, NULL, OPT_STEP},
    {"max-iters", required_argument, NULL, OPT_MAXIT},
    {"quality-rounds", required_argument, NULL, OPT_QROUNDS},
    {"no-quality", no_argument, NULL, OPT_NOQ},
    TOOL_LONG_OPTIONS_OUTPUT,
    TOOL_LONG_OPTIONS_TETFORMAT,
    TOOL_LONG_OPTIONS_END};

static int option(tool_ctx *t, int c, const char *arg, void *settings)
{
    tetsmooth_settings *s = settings;
    size_t n;
    switch (c) {
    case OPT_FAIR:
    case OPT_FIT:
        if (s->mode && s->mode != (c == OPT_FAIR ? 1 : 2))
            return tool_usage_error(t, "--fair and --fit exclude each other");
        s->mode = c == OPT_FAIR ? 1 : 2;
        break;
    case OPT_ITERS:
        if (tool_parse_size(t, "--iters", arg, 0, 10000, &n))
            return TOOL_EXIT_USAGE;
        s->fair.iters = (int)n;
        s->fair_only = 1;
        break;
    case OPT_LAMBDA:
        if (tool_parse_double(t, "--lambda", arg, 0.0, 1e6, &s->fair.lambda_dt))
            return TOOL_EXIT_USAGE;
        s->fair_only = 1;
        break;
    case OPT_MINANGLE:
        if (tool_parse_double(t, "--min-angle", arg, 0.0, 59.0, &s->fair.min_angle))
            return TOOL_EXIT_USAGE;
        s->fair_only = 1;
        break;
    case OPT_SURFACE:
        s->surface = arg;
        s->fit_only = 1;
        break;
    case OPT_FIELD:
        s->field = arg;
        s->fit_only = 1;
        break;
    case OPT_OFFSET:
        if (tool_parse_double(t, "--offset", arg, 1e-6, 1e6, &s->fit.offset_ratio))
            return TOOL_EXIT_USAGE;
        s->fit_only = 1;
        break;
    case OPT_CELL:
        if (tool_parse_double(t, "--cell-width", arg, 1e-300, 1e300, &s->fit.cell_width))
            return TOOL_EXIT_USAGE;
        s->fit_only = 1;
        break;
    case OPT_BEST_EFFORT:
        s->best_effort = 1;
        s->fit_only = 1;
        break;
    case OPT_STEP:
        if (tool_parse_double(t, "--step", arg, 1e-6, 1.0, &s->fit.step))
            return TOOL_EXIT_USAGE;
        s->fit_only = 1;
        break;
    case OPT_MAXIT:
        if (tool_parse_size(t, "--max-iters", arg, 0, 1000000, &n))
            return TOOL_EXIT_USAGE;
        s->fit.max_iters = (int)n;
        s->fit_only = 1;
        break;
    case OPT_QROUNDS:
        if (tool_parse_size(t, "--quality-rounds", arg, 0, 1000000, &n))
            return TOOL_EXIT_USAGE;
        s->fit.quality_rounds = (int)n;
        s->fair.quality_rounds = (int)n;
        break;
    case OPT_INTQ:
        s->fair.boundary_quality = 0;
        s->fair_only = 1;
        break;
    case OPT_NOQ:
        s->fit.quality = 0;
        s->fair.quality_rounds = 0;
        s->noq = 1;
        break;
    }
    return TOOL_CONTINUE;
}

static int check(tool_ctx *t, int argc, char *argv[], void *settings)
{
    tetsmooth_settings *s = settings;
    if (!s->mode)
        return tool_usage_error(t, "say what to do: --fair or --fit --surface S");
    if (s->mode == 1 && s->fit_only)
        return tool_usage_error(t, "--surface, --field, --offset, --offset-best-effort, --cell-width, "
                                   "--step and --max-iters go with --fit");
    if (s->mode == 2 && s->fair_only)
        return tool_usage_error(t, "--iters, --lambda, --min-angle and --interior-quality go with --fair");
    if (s->noq)
        s->fair.quality_rounds = 0;   /* whatever the order of the options */
    if (s->mode == 2 && !s->surface)
        return tool_usage_error(t, "--fit needs --surface S (the surface to enclose)");
    if (s->field && strcmp(s->field, "-") == 0)
        return tool_usage_error(t, "--field reads a file, not standard input");
    TOOL_TRY(tool_one_input(t, argc, argv, "input mesh", "-", &s->in));
    TOOL_TRY(tool_refuse_terminal(t, s->in, STDIN_FILENO, "no input: give a mesh or pipe one "
                                  "in (latticetet ... | tetsmooth ...)"));
    if (s->surface)
        TOOL_TRY(tool_refuse_terminal(t, s->surface, STDIN_FILENO, TOOL_TTY_SURFACE));
    TOOL_TRY(tool_tetmesh_output(t, s->co.out, "will not write a binary mesh to a "
                                 "terminal: give -o FILE or pipe it"));
    return tool_output_check(t, s->co.out);
}

/* With --field: the fill of the field's pseudo volume (pseudo.h), which
 * counts as surface for --offset, and S with it as one soup (*enc, NULL
 * without a fill), which the mesh encloses as it does S
 * (st_pipeline_enclosed). 0, or the exit status. */
static int field_fill(tool_ctx *t, tetsmooth_settings *s, const st_soup *soup,
                      const st_bvh *bvh, st_soup **fill, st_soup **enc, st_bvh **enc_bvh,
                      st_error *err)
{
    if (!s->field)
        return 0;
    st_grid *g = NULL;
    size_t nfill = 0;
    if (st_grid_read(&g, s->field, s->co.max_bytes, err) ||
        st_pseudo_fill(fill, g, bvh, &nfill, err)) {
        if (g && g->kind == ST_GRID_DISTANCE)
            st_error_set(err, ST_EINPUT, tool_in_name(s->field), 0,
                         "the field is distance, not signed (run soupsign first)");
        st_grid_free(g);
        return tool_fail(t, err);
    }
    st_grid_free(g);
    s->fit.fill = *fill;
    tool_say(t, 2, "fill: %zu voxel faces of the pseudo volume's boundary where S has "
             "no surface count as surface for --offset", nfill);
    if (st_pipeline_enclosed(enc, enc_bvh, soup, *fill, err))
        return tool_fail(t, err);
    return 0;
}

static int run(tool_ctx *t, void *settings)
{
    tetsmooth_settings *s = settings;
    const char *in = s->in, *out = s->co.out, *surface = s->surface;
    tool_set_threads(s->co.threads);
    st_error err;
    st_error_clear(&err);
    st_tetmesh *m = NULL;
    st_soup *soup = NULL, *fill = NULL, *enc = NULL;
    st_bvh *bvh = NULL, *enc_bvh = NULL;
    int rc = TOOL_EXIT_FAIL;
    int not_enclosing = 0;
    st_fit_stats fst;
    memset(&fst, 0, sizeof fst);
    const char *inname = tool_in_name(in);
    double t0 = tool_now();
    if (st_tetmesh_read(&m, in, s->co.max_bytes, &err)) {
        tool_limit_hint(&err, "raise --max-memory");
        rc = tool_fail(t, &err);
        goto done;
    }
    tool_say(t, 2, "%s: %zu points, %zu tets (read in %.3f s)", inname, m->npoints, m->ntets,
             tool_now() - t0);
    st_progress prog = tool_progress(t);
    char param[256];
    if (s->mode == 1) {
        st_fair_stats st;
        st_status s1 = st_fair(m, &s->fair, &st, &prog, &err);
        tool_progress_end(t);
        if (s1) {
            rc = tool_fail_file(t, &err, inname);
            goto done;
        }
        tool_say(t, 2, "fair: %d steps, volume %.6g -> %.6g (%+.4f%%), %zu moves, "
                        "%zu back-offs, %zu blocked, %.3f s",
                 st.iters, st.volume_before, st.volume_after,
                 100.0 * (st.volume_after / st.volume_before - 1.0), st.moves, st.backoffs,
                 st.stuck, st.seconds);
        tool_say(t, 2, "dihedral: input %.2f..%.2f, after fairing %.2f..%.2f, after quality "
                        "%.2f..%.2f (%zu moves)",
                 st.min_dihedral_before, st.max_dihedral_before, st.min_dihedral_fair,
                 st.max_dihedral_fair, st.min_dihedral_after, st.max_dihedral_after,
                 st.quality_moves);
        snprintf(param, sizeof param, "fair iters=%d lambda_dt=%.6g min_angle=%.6g quality_rounds=%d",
                 s->fair.iters, s->fair.lambda_dt, s->fair.min_angle, s->fair.quality_rounds);
    } else {
        if (tool_soup_read(t, &soup, surface, &err) || st_bvh_build(&bvh, soup, &err)) {
            rc = tool_fail(t, &err);
            goto done;
        }
        if ((rc = field_fill(t, s, soup, bvh, &fill, &enc, &enc_bvh, &err)))
            goto done;
        rc = TOOL_EXIT_FAIL;
        iter_ctx ic = {t};
        if (t->verbosity >= 2) {
            s->fit.on_iter = on_iter;
            s->fit.on_iter_ctx = &ic;
        }
        st_fit_stats st;
        st_status s2 = st_fit(m, enc ? enc : soup, enc ? enc_bvh : bvh, &s->fit, &st, &prog,
                              &err);
        if (!s2 && enc && (st.outside_after || st.crossing_after))
            s2 = st_enclosure_count(m, soup, bvh, &st.outside_after, &st.crossing_after, &err);
        tool_progress_end(t);
        if (s2) {
            rc = tool_fail_file(t, &err, inname);
            goto done;
        }
        tool_say(t, 2, "fit: h %.6g, d_offset %.6g, %d iterations, %zu moves, %zu halvings, "
                        "%zu skipped, %.3f s",
                 st.h, st.d_offset, st.iters, st.moves, st.rejected, st.skipped, st.seconds_fit);
        tool_say(t, 2, "dihedral: input %.2f..%.2f, after fit %.2f..%.2f, after quality "
                        "%.2f..%.2f (%d rounds, %zu moves, %zu tets peeled, %.3f s)",
                 st.min_dihedral_before, st.max_dihedral_before, st.min_dihedral_fit,
                 st.max_dihedral_fit, st.min_dihedral_after, st.max_dihedral_after,
                 st.quality_rounds, st.quality_moves, st.peeled, st.seconds_quality);
        tool_say(t, 2, "enclosure: S vertices outside %zu -> %zu, S triangles crossing "
                        "%zu -> %zu",
                 st.outside_before, st.outside_after, st.crossing_before, st.crossing_after);
        tool_say(t, 2, "boundary: %zu of %zu vertices within %.6g of S%s; distance mean %.4g, "
                        "max %.4g",
                 st.within_offset, st.boundary_vertices, st.d_offset,
                 fill && fill->ntris ? " or the fill" : "", st.mean_distance,
                 st.max_distance);
        not_enclosing = st.outside_after || st.crossing_after;
        fst = st;
        snprintf(param, sizeof param, "fit offset=%.6g h=%.6g step=%.6g quality=%d "
                 "converged=%d beyond_offset=%zu",
                 s->fit.offset_ratio, st.h, s->fit.step, s->fit.quality, st.converged, st.beyond_offset);
    }
    if (st_meta_set(&m->meta, "tetsmooth", param) ||
        tool_meta_record(t, &m->meta)) {
        rc = tool_fail_nomem(t, &err);
        goto done;
    }
    if (st_tetmesh_save(m, out, &s->co.tetformat, &err)) {
        rc = tool_fail(t, &err);
        goto done;
    }
    tool_say(t, 2, "total %.3f s", tool_now() - t0);
    rc = TOOL_EXIT_OK;
    if (not_enclosing) {
        /* Level 0: printed even with -q, and the exit status says it. */
        tool_say(t, 0, "%s: error: the mesh written to %s does not enclose %s: %zu of its "
                        "vertices outside, %zu triangles crossing the boundary (as on input: "
                        "%zu, %zu)",
                 inname, tool_out_name(out), surface, fst.outside_after,
                 fst.crossing_after, fst.outside_before, fst.crossing_before);
        rc = TOOL_EXIT_NOT_ENCLOSING;
    }
    if (s->mode == 2 && fst.beyond_offset) {
        /* Cetra's stopping condition missed: soupmesh's message and exit
         * status (level 0, exit 4) unless the user settles for less. */
        tool_say(t, s->best_effort ? 1 : 0,
                 "%s: %s: %zu of %zu boundary vertices stay farther than %.3g h from the "
                 "input, the farthest %.4g h (%.4g)%s",
                 inname, s->best_effort ? "warning" : "error", fst.beyond_offset,
                 fst.boundary_vertices, s->fit.offset_ratio, fst.max_distance / fst.h,
                 fst.max_distance, s->best_effort ? "" : "; try a finer lattice, or "
                 "--offset-best-effort");
        if (!s->best_effort && rc == TOOL_EXIT_OK)
            rc = TOOL_EXIT_OFFSET_NOT_MET;
    }
done:
    st_bvh_free(enc_bvh);
    st_soup_free(enc);
    st_bvh_free(bvh);
    st_soup_free(fill);
    st_soup_free(soup);
    st_tetmesh_free(m);
    return rc;
}

static const tool_spec spec = {"tetsmooth", usage, ":o:qv", longopts, option, check, run};

int main(int argc, char *argv[])
{
    tetsmooth_settings s = {.fair = st_fair_params_default(), .fit = st_fit_params_default()};
    return tool_main(&spec, argc, argv, &s, &s.co);
}
