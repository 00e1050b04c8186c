/*
 * latticetet - a tet mesh of the pseudo volume from a lattice.
 *
 *   latticetet [FIELD] (--density RHO | --sculpt --surface S)
 *              [--lattice cubic5|bcc] [--cells N | --size SIZE] [--seed S]
 *              [-o OUT] [-q | -v] [--threads T]
 *
 * Reads a signed field (soupsign's output: .vdb, .vti, or an OpenVDB stream
 * on stdin), lays a lattice over its box and keeps the tets whose
 * pseudo-volume density is at least RHO (Spillmann et al. 2006, section 4),
 * or sculpts a BCC lattice to the tets that overlap the pseudo volume or a
 * triangle of S, with bomb repair (Stuart et al. 2013, section 3.2). Writes
 * .vtu. See man/man1/latticetet.1, lattice.h and sculpt.h.
 */
#define _GNU_SOURCE
#include "../cli/tool.h"
#include "souptet/bvh.h"
#include "souptet/gridio.h"
#include "souptet/lattice.h"
#include "souptet/outfile.h"
#include "souptet/parts.h"
#include "souptet/pipeline.h"
#include "souptet/pseudo.h"
#include "souptet/sculpt.h"
#include "souptet/soup.h"
#include "souptet/tetio.h"

#include <errno.h>
#include <getopt.h>
#include <inttypes.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static void usage(void)
{
    printf(
"Usage: latticetet [OPTION]... (--density RHO | --sculpt --surface S) [FIELD]\n"
"A tetrahedral mesh of the pseudo volume: a lattice laid over a signed field,\n"
"filtered by density (Spillmann et al. 2006) or sculpted with bomb repair\n"
"(Stuart et al. 2013).\n"
"\n"
"FIELD is a signed field from soupsign (.vdb or .vti); '-' or none reads an\n"
"OpenVDB stream from stdin.\n"
"\n"
"      --density RHO    keep tets whose pseudo-volume density is >= RHO, in\n"
"                       [0, 1] (the paper: 0.5)\n"
"      --sculpt         keep every tet that overlaps the pseudo volume or a\n"
"                       triangle of the surface, then repair bombs\n"
"      --surface S      the surface the field was made from (with --sculpt)\n"
"      --lattice KIND   cubic5 (5 tets per cube) or bcc (default: cubic5 for\n"
"                       --density, bcc for --sculpt)\n"
"      --cells N        cells along the longest side of the field's box with\n"
"                       --density, of the surface's box with --sculpt (as\n"
"                       soupmesh) (default 16 for --density, 10 for --sculpt); with\n"
"                       --density, 'auto': the coarsest of 8, 10, 12, 14,\n"
"                       16, 20, ..., 128 at which no part is too thin\n"
"      --size SIZE      cell width in model units (instead of --cells)\n"
"      --seed S         random rotation and offset of the lattice (0: axis-aligned\n"
"                       at the box's corner; default 0 for --density, 1 for\n"
"                       --sculpt, as soupmesh)\n"
"      --parts MODE     with --sculpt: tag each tet with the surface's part\n"
"                       it mostly covers (cell data part and part_share, as\n"
"                       soupmesh --parts): names, pieces, auto or none\n"
"                       (default none)\n"
"      --no-repair      sculpt without bomb and manifold repair; with\n"
"                       --density, the paper's rule alone: no cleanup of\n"
"                       hanging tets, islands and pinched boundaries\n"
"  -o, --output OUT     .vtu file (or .msh, .node/.ele, .mesh by extension,\n"
"                       without the arrays); '-' or none: .vtu on stdout\n"
TOOL_HELP_TETFORMAT
"      --threads T      threads to use (default: all cores)\n"
"      --max-memory SZ  refuse fields and lattices larger than SZ\n"
"                       (default 80%% of RAM)\n"
"  -q, --quiet          no messages but errors\n"
"  -v, --verbose        report tets kept, bombs, timings\n"
"  -h, --help           show this help and exit\n"
"  -V, --version        show the version and commit and exit\n"
"\n"
"Examples:\n"
"  soupdist bunny.obj | soupsign | latticetet --density 0.5 -o bunny.vtu\n"
"  soupdist bunny.obj | soupsign | latticetet --sculpt --surface bunny.obj \\\n"
"      --cells 12 -o bunny-bcc.vtu\n"
"\n"
"Exit status: 0 ok, 1 bad input or failure, 2 usage error.\n");
}

enum { OPT_DENSITY = TOOL_OPT_FIRST, OPT_SCULPT, OPT_SURFACE, OPT_LATTICE, OPT_CELLS,
       OPT_SEED, OPT_NOREPAIR, OPT_PARTS, OPT_SIZE };

/* What the command line asks for. */
typedef struct latticetet_settings {
    tool_common co;
    const char *in, *surface, *lattice_name;
    st_lattice_kind kind;
    size_t cells;      /* 0 until given, then the default of the mode */
    int auto_cells;    /* --cells auto */
    double rho;        /* --density; < 0 with --sculpt */
    double size;       /* --size; 0: from cells */
    int sculpt, repair, have_seed;
    int parts_mode;    /* --parts (st_parts_mode) */
    uint64_t seed;
} latticetet_settings;

static const struct option longopts[] = {
    {"density", required_argument, NULL, OPT_DENSITY},
    {"sculpt", no_argument, NULL, OPT_SCULPT},
    {"surface", required_argument, NULL, OPT_SURFACE},
    {"lattice", required_argument, NULL, OPT_LATTICE},
    {"cells", required_argument, NULL, OPT_CELLS},
    {"size", required_argument, NULL, OPT_SIZE},
    {"seed", required_argument, NULL, OPT_SEED},
    {"no-repair", no_argument, NULL, OPT_NOREPAIR},
    {"parts", required_argument, NULL, OPT_PARTS},
    TOOL_LONG_OPTIONS_OUTPUT,
    TOOL_LONG_OPTIONS_TETFORMAT,
    TOOL_LONG_OPTIONS_END};

static int option(tool_ctx *t, int c, const char *arg, void *settings)
{
    latticetet_settings *s = settings;
    switch (c) {
    case OPT_DENSITY:
        if (tool_parse_double(t, "--density", arg, 0.0, 1.0, &s->rho))
            return TOOL_EXIT_USAGE;
        break;
    case OPT_SCULPT:
        s->sculpt = 1;
        break;
    case OPT_SURFACE:
        s->surface = arg;
        break;
    case OPT_LATTICE:
        s->lattice_name = arg;
        break;
    case OPT_CELLS:
        if (!strcmp(arg, "auto")) {
            s->auto_cells = 1;
            break;
        }
        if (tool_parse_size(t, "--cells", arg, 1, 100000, &s->cells))
            return TOOL_EXIT_USAGE;
        s->auto_cells = 0;
        break;
    case OPT_SIZE:
        if (tool_parse_double(t, "--size", arg, 1e-300, 1e300, &s->size))
            return TOOL_EXIT_USAGE;
        break;
    case OPT_SEED: {
        char *end;
        errno = 0;
        unsigned long long v = strtoull(arg, &end, 10);
        if (!*arg || *end || errno || arg[0] == '-')
            return tool_usage_error(t, "--seed wants a non-negative integer, not '%s'", arg);
        s->seed = (uint64_t)v;
        s->have_seed = 1;
        break;
    }
    case OPT_PARTS:
        if ((s->parts_mode = st_parts_mode_from_name(arg)) < 0)
            return tool_usage_error(t, "--parts is auto, names, pieces or none, not '%s'", arg);
        break;
    case OPT_NOREPAIR:
        s->repair = 0;
        break;
    }
    return TOOL_CONTINUE;
}

static int check(tool_ctx *t, int argc, char *argv[], void *settings)
{
    latticetet_settings *s = settings;
    TOOL_TRY(tool_one_input(t, argc, argv, "input field", "-", &s->in));
    if (s->sculpt && s->rho >= 0)
        return tool_usage_error(t, "--density and --sculpt exclude each other");
    if (!s->sculpt && s->rho < 0)
        return tool_usage_error(t, "say --density RHO or --sculpt --surface S");
    if (s->sculpt && !s->surface)
        return tool_usage_error(t, "--sculpt needs --surface S (the input surface)");
    if (!s->sculpt && s->surface)
        return tool_usage_error(t, "--surface goes with --sculpt");
    if (!s->sculpt && s->parts_mode > 0)
        return tool_usage_error(t, "--parts goes with --sculpt --surface S");
    if ((s->cells || s->auto_cells) && s->size > 0)
        return tool_usage_error(t, "--cells and --size exclude each other");
    if (s->auto_cells && (s->sculpt || !s->repair))
        return tool_usage_error(t, "--cells auto goes with --density (and its "
                                   "cleanup: not with --no-repair)");
    s->kind = s->sculpt ? ST_LATTICE_BCC : ST_LATTICE_CUBIC5;
    if (s->lattice_name && st_lattice_kind_from_name(s->lattice_name, &s->kind))
        return tool_usage_error(t, "--lattice is cubic5 or bcc, not '%s'", s->lattice_name);
    if (!s->cells)   /* sculpting keeps a layer more: coarser by default */
        s->cells = s->sculpt ? 10 : 16;
    /* Sculpting: soupmesh's defaults, so the pipe makes soupmesh's mesh. */
    if (!s->have_seed && s->sculpt)
        s->seed = 1;
    TOOL_TRY(tool_refuse_terminal(t, s->in, STDIN_FILENO, "no input: give a field or pipe "
                                  "one in (soupdist m.obj | soupsign | latticetet ...)"));
    if (s->surface)
        TOOL_TRY(tool_refuse_terminal(t, s->surface, STDIN_FILENO, TOOL_TTY_SURFACE));
    TOOL_TRY(tool_tetmesh_output(t, s->co.out, TOOL_TTY_VTU));
    return tool_output_check(t, s->co.out);
}

/* What run builds and reads as it goes, freed at its end. */
typedef struct lt_run {
    const latticetet_settings *s;
    const char *in_name;
    st_grid *g;
    st_soup *soup;
    st_lattice *L;
    st_tetmesh *m;
    double lo[3], hi[3];   /* the field's box */
    double h;              /* the cell width */
    size_t cells;          /* --cells (the last tried with auto) */
    size_t max_tets;       /* the most tets --max-memory allows */
    size_t thin_parts;     /* of the last density try: why no tets */
    double t_read;         /* seconds to read the inputs */
    double t_lattice;      /* when the lattices began (the end of the
                            * reading: with --cells auto, the lattice
                            * time of a try counts the tries before it) */
} lt_run;

/* --cells auto: the sizes it tries, coarse to fine; the first at which no
 * part of the pseudo volume is too thin is kept. */
static const size_t auto_seq[] = {8, 10, 12, 14, 16, 20, 24, 28, 32, 40,
                                  48, 56, 64, 80, 96, 112, 128};
#define N_AUTO (sizeof auto_seq / sizeof auto_seq[0])

static const char *const limit_hint = "use fewer --cells or a larger --size, or raise "
                                      "--max-memory";

/* The signed field, and with --sculpt the surface. 0, or the exit status
 * after an error was printed. */
static int read_inputs(tool_ctx *t, lt_run *R, st_error *err)
{
    const latticetet_settings *s = R->s;
    if (st_grid_read(&R->g, s->in, s->co.max_bytes, err) ||
        tool_check_field_finite(R->g, R->in_name, err))
        return tool_fail(t, err);
    if (R->g->kind != ST_GRID_SIGNED) {
        st_error_set(err, ST_EINPUT, R->in_name, 0,
                     "the field is %s, not signed (run soupsign first)",
                     st_grid_kind_name(R->g->kind));
        return tool_fail(t, err);
    }
    if (s->sculpt && tool_soup_read(t, &R->soup, s->surface, err))
        return tool_fail(t, err);
    return 0;
}

/* The cell width: --size, or --cells over the field's box (over the
 * surface's box with --sculpt, as soupmesh counts them). */
static int cell_width(tool_ctx *t, lt_run *R, st_error *err)
{
    st_lattice_grid_box(R->g, R->lo, R->hi);
    R->h = R->s->size > 0 ? R->s->size : st_lattice_h_for_cells(R->lo, R->hi, R->cells);
    if (R->s->sculpt && !(R->s->size > 0)) {
        double slo[3], shi[3];
        if (st_soup_bounds(R->soup, slo, shi, err))
            return tool_fail(t, err);
        R->h = st_lattice_h_for_cells(slo, shi, R->cells);
    }
    return 0;
}

/* -v (and warnings): what the density filter's cleanup did; final: the
 * thin parts are news (with --cells auto, only the last try's). */
static void say_cleanup(tool_ctx *t, const lt_run *R, const st_density_clean_stats *cs,
                        int final)
{
    tool_say(t, 2, "cleanup: %zu pieces of pseudo volume, %zu of "
             "tets; %zu tets filled and %zu dropped at pinched "
             "vertices; %zu pieces joined (%zu tets), %zu islands "
             "dropped (%zu tets)", cs->pieces, cs->tet_pieces,
             cs->filled, cs->dropped, cs->joins, cs->join_tets,
             cs->islands, cs->island_tets);
    if (cs->specks)
        tool_say(t, 2, "%zu specks of the pseudo volume smaller than "
                 "a tet (%zu voxels) not meshed", cs->specks,
                 cs->speck_voxels);
    if (cs->bad_vertices_left)
        tool_say(t, 1, "warning: the boundary is not manifold at "
                 "%zu vertices", cs->bad_vertices_left);
    for (size_t q = 0; q < cs->nthin && q < ST_CLEAN_MAX_THIN; q++) {
        const st_thin_part *p = &cs->thin[q];
        tool_say(t, final ? 1 : 2, "%s: warning: a part of the pseudo volume is "
                 "too thin for this lattice (h %.4g): %zu voxels in "
                 "(%.4g %.4g %.4g)-(%.4g %.4g %.4g), %.4g thick, "
                 "%.0f%% of it meshed; --cells %zu would hold it",
                 R->in_name, R->h, p->voxels, p->lo[0], p->lo[1], p->lo[2],
                 p->hi[0], p->hi[1], p->hi[2], p->thickness,
                 100.0 * p->held, p->cells);
    }
    if (cs->nthin > ST_CLEAN_MAX_THIN)
        tool_say(t, final ? 1 : 2, "%s: warning: %zu more parts too thin",
                 R->in_name, cs->nthin - ST_CLEAN_MAX_THIN);
}

/* One density try at R->h: the lattice, the filter and its cleanup, the
 * -v report; *nthin the parts too thin. 0, or the exit status after an
 * error was printed. */
static int density_try(tool_ctx *t, lt_run *R, int final_try, size_t *nthin,
                       st_error *err)
{
    const latticetet_settings *s = R->s;
    st_density_stats ds;
    st_lattice_params lp = st_lattice_params_default();
    lp.kind = s->kind;
    lp.h = R->h;
    lp.seed = s->seed;
    lp.max_tets = R->max_tets;
    if (st_lattice_build(&R->L, R->lo, R->hi, &lp, err)) {
        if (!err->file[0])
            snprintf(err->file, sizeof err->file, "%s", R->in_name);
        tool_limit_hint(err, limit_hint);
        return tool_fail(t, err);
    }
    double t2 = tool_now();
    st_density_clean_stats cs;
    memset(&cs, 0, sizeof cs);
    if (st_lattice_density_filter_clean(&R->m, &ds, &cs, R->L, R->g, s->rho, s->repair,
                                        err))
        return tool_fail_file(t, err, R->in_name);
    double t3 = tool_now();
    const st_grid *g = R->g;
    const st_lattice *L = R->L;
    tool_say(t, 2, "grid %zux%zux%zu, voxel %.6g; %s lattice, h %.6g "
             "(%.3g voxels), %zux%zux%zu cells, seed %" PRIu64,
             g->nx, g->ny, g->nz, g->voxel, st_lattice_kind_name(s->kind), R->h,
             R->h / g->voxel, L->n[0], L->n[1], L->n[2], s->seed);
    tool_say(t, 2, "%zu of %zu lattice tets kept (rho >= %g); %zu decided "
             "by their centroid's voxel; %zu point tests",
             ds.kept, ds.lattice_tets, s->rho, ds.centroid_rule, ds.point_tests);
    tool_say(t, 2, "read %.3f s, lattice %.3f s, density %.3f s",
             R->t_read, t2 - R->t_lattice, t3 - t2);
    if (s->repair)
        say_cleanup(t, R, &cs, !s->auto_cells || cs.nthin == 0 || final_try);
    *nthin = cs.nthin;
    return 0;
}

/* --density: one try, or with --cells auto the tries of auto_seq until no
 * part is too thin. */
static int density_mesh(tool_ctx *t, lt_run *R, st_error *err)
{
    const int auto_cells = R->s->auto_cells;
    for (size_t try_i = 0;; try_i++) {
        if (auto_cells) {
            st_lattice_free(R->L);
            st_tetmesh_free(R->m);
            R->L = NULL;
            R->m = NULL;
            R->cells = auto_seq[try_i];
            R->h = st_lattice_h_for_cells(R->lo, R->hi, R->cells);
        }
        int rc = density_try(t, R, try_i + 1 == N_AUTO, &R->thin_parts, err);
        if (rc || !auto_cells)
            return rc;
        if (R->thin_parts == 0) {
            tool_say(t, 1, "--cells auto: %zu cells (h %.6g)", R->cells, R->h);
            return 0;
        }
        if (try_i + 1 == N_AUTO) {
            tool_say(t, 1, "%s: warning: --cells auto: parts still too thin at "
                     "%zu cells, the finest it tries", R->in_name, R->cells);
            return 0;
        }
    }
}

/* -v (and warnings): what the sculpt and its repairs did. */
static void say_sculpt(tool_ctx *t, const lt_run *R, const st_sculpt_stats *ss)
{
    const latticetet_settings *s = R->s;
    const st_grid *g = R->g;
    tool_say(t, 2, "grid %zux%zux%zu, voxel %.6g; %s lattice, h %.6g "
             "(%.3g voxels), seed %" PRIu64 "; surface %s: %zu triangles",
             g->nx, g->ny, g->nz, g->voxel, st_lattice_kind_name(s->kind), R->h,
             R->h / g->voxel, s->seed, s->surface, R->soup->ntris);
    tool_say(t, 2, "%zu lattice tets: %zu overlap the pseudo volume, "
             "%zu more meet a triangle", ss->lattice_tets, ss->kept_volume,
             ss->kept_surface);
    tool_say(t, 2, "bombs: %zu found (%zu with 3 boundary faces, %zu "
             "isolated), %zu clusters (largest %zu; %zu searched exactly, "
             "%zu too large: greedy), %zu snowflakes add %zu tets "
             "(greedy: %zu), %zu rounds, %zu left",
             ss->bombs, ss->bombs_3faces, ss->bombs_4faces, ss->clusters,
             ss->largest_cluster, ss->clusters_exact, ss->clusters_greedy,
             ss->snowflakes, ss->bomb_tets, ss->greedy_tets, ss->repair_rounds,
             ss->bombs_left);
    tool_say(t, 2, "boundary: %zu non-manifold vertices, %zu edges; "
             "%zu tets added; %zu vertices, %zu edges left",
             ss->nonmanifold_vertices, ss->nonmanifold_edges,
             ss->manifold_tets, ss->nonmanifold_vertices_left,
             ss->nonmanifold_edges_left);
    tool_say(t, 2, "%zu tets; read %.3f s, lattice %.3f s, classify "
             "%.3f s, repair %.3f s, mesh %.3f s", ss->tets, R->t_read,
             ss->t_lattice, ss->t_classify, ss->t_repair, ss->t_mesh);
    if (ss->bombs_left)
        tool_say(t, 1, "warning: %zu bombs could not be repaired",
                 ss->bombs_left);
    if (ss->nonmanifold_vertices_left)
        tool_say(t, 1, "warning: the boundary is not manifold at %zu "
                 "vertices", ss->nonmanifold_vertices_left);
}

/* --sculpt: the BCC lattice sculpted to the field and the surface, bombs
 * and the boundary repaired. */
static int sculpt_mesh(tool_ctx *t, lt_run *R, st_error *err)
{
    const latticetet_settings *s = R->s;
    st_sculpt_params sp = st_sculpt_params_default();
    sp.kind = s->kind;
    sp.h = R->h;
    sp.seed = s->seed;
    sp.max_tets = R->max_tets;
    sp.repair_bombs = sp.repair_manifold = s->repair;
    st_sculpt_stats ss;
    /* the fill is enclosed as the surface is (st_pipeline_enclosed):
     * what soupmesh sculpts, and tetsmooth --fit --field fits */
    st_bvh *bvh = NULL, *enc_bvh = NULL;
    st_soup *fill = NULL, *enc = NULL;
    st_status rc = st_bvh_build(&bvh, R->soup, err);
    if (!rc)
        rc = st_pseudo_fill(&fill, R->g, bvh, NULL, err);
    if (!rc)
        rc = st_pipeline_enclosed(&enc, &enc_bvh, R->soup, fill, err);
    if (!rc)
        rc = st_sculpt(&R->m, &ss, R->g, enc ? enc : R->soup, enc_bvh, &sp, err);
    st_bvh_free(enc_bvh);
    st_soup_free(enc);
    st_soup_free(fill);
    st_bvh_free(bvh);
    if (rc) {
        if (!err->file[0])
            snprintf(err->file, sizeof err->file, "%s", R->in_name);
        tool_limit_hint(err, limit_hint);
        return tool_fail(t, err);
    }
    say_sculpt(t, R, &ss);
    return 0;
}

/* --parts: each tet's part, on the field's grid (parts.h). */
static int tag_parts(tool_ctx *t, lt_run *R, st_error *err)
{
    st_parts parts;
    st_pseudo_params pp = st_pseudo_params_default();
    st_status ps = st_parts_split(&parts, R->soup, (st_parts_mode)R->s->parts_mode, err);
    if (!ps) {
        tool_say(t, 1, "%zu part%s (%s)", parts.nparts, parts.nparts == 1 ? "" : "s",
                 st_parts_mode_name(parts.mode));
        st_progress prog = tool_progress(t);
        ps = st_parts_tag(R->m, R->soup, &parts, R->g, &pp, NULL, &prog, err);
        tool_progress_end(t);
    }
    st_parts_free(&parts);
    if (ps)
        return tool_fail_file(t, err, tool_in_name(R->s->surface));
    return 0;
}

/* The mesh on disk, with the field's metadata (source, history; the
 * lattice's own keys win) and this run's. */
static int write_mesh(tool_ctx *t, lt_run *R, st_error *err)
{
    st_tetmesh *m = R->m;
    if (st_meta_inherit(&m->meta, &R->g->meta) != ST_OK ||
        tool_meta_record(t, &m->meta) != ST_OK)
        return tool_fail_nomem(t, err);
    double tw = tool_now();
    if (st_tetmesh_save(m, R->s->co.out, &R->s->co.tetformat, err))
        return tool_fail(t, err);
    tool_say(t, 2, "%zu tets, %zu points; write %.3f s", m->ntets, m->npoints,
             tool_now() - tw);
    return 0;
}

static int run(tool_ctx *t, void *settings)
{
    const latticetet_settings *s = settings;
    tool_set_threads(s->co.threads);
    st_error err;
    st_error_clear(&err);
    lt_run R = {.s = s, .in_name = tool_in_name(s->in), .cells = s->cells};
    double t0 = tool_now();
    int rc = read_inputs(t, &R, &err);
    if (rc)
        goto done;
    R.t_lattice = tool_now();
    R.t_read = R.t_lattice - t0;
    if ((rc = cell_width(t, &R, &err)))
        goto done;
    /* A lattice that cannot fit in --max-memory (or past 2^31 tets, far
     * beyond what a coarse mesh needs) is refused before it is built. */
    R.max_tets = tool_max_lattice_tets(s->co.max_bytes);
    if ((rc = s->sculpt ? sculpt_mesh(t, &R, &err) : density_mesh(t, &R, &err)))
        goto done;
    /* An empty mesh is no mesh: say why and write nothing (a pipe after
     * latticetet would mesh nothing without a word). */
    if (R.m->ntets == 0) {
        st_error_set(&err, ST_EINPUT, R.in_name, 0, R.thin_parts
                     ? "no tets kept: the pseudo volume is thinner than this lattice "
                       "holds (the --cells above would hold it); nothing written"
                     : "no tets kept: the pseudo volume is empty (a field soupsign "
                       "made has its inside negative); nothing written");
        rc = tool_fail(t, &err);
        goto done;
    }
    if (s->parts_mode > 0 && (rc = tag_parts(t, &R, &err)))
        goto done;
    rc = write_mesh(t, &R, &err);
done:
    st_tetmesh_free(R.m);
    st_lattice_free(R.L);
    st_soup_free(R.soup);
    st_grid_free(R.g);
    return rc;
}

static const tool_spec spec = {"latticetet", usage, ":o:qv", longopts, option, check, run};

int main(int argc, char *argv[])
{
    latticetet_settings s = {.rho = -1, .repair = 1};
    return tool_main(&spec, argc, argv, &s, &s.co);
}
