/*
 * soupdist - the unsigned distance field of a triangle soup.
 *
 *   soupdist INPUT [-r N | -s VOXEL] [--pad P] [--band B|full] [-o OUT]
 *
 * Reads a surface (.obj .off .ply .stl, or stdin), computes the distance
 * from every voxel center to the nearest triangle on a grid over the padded
 * bounding box, and writes it as .vdb, .vti, or an OpenVDB stream on
 * stdout. See man/man1/soupdist.1.
 */
#define _GNU_SOURCE
#include "../cli/tool.h"
#include "souptet/dist.h"
#include "souptet/gridio.h"
#include "souptet/outfile.h"
#include "souptet/soup.h"

#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static void usage(void)
{
    printf(
"Usage: soupdist [OPTION]... [INPUT]\n"
"Compute the unsigned distance field of a triangle soup.\n"
"\n"
"INPUT is a surface (.obj .off .ply .stl .gltf .glb); '-' or none reads stdin.\n"
"The grid covers the bounding box padded by P voxels; values within the band\n"
"are exact distances, values beyond it are clamped to the band.\n"
"\n"
"  -r, --voxels N       voxels along the longest side of the box (default %d)\n"
"  -s, --voxel-size SIZE  voxel size in model units (instead of -r)\n"
"      --pad P          voxels of padding on each side (default: band + 2)\n"
"      --band B         exact band in voxels, at least %g (default %g),\n"
"                       or 'full' for distances everywhere (beyond the band:\n"
"                       propagated, never below the truth)\n"
"  -o, --output OUT     .vdb or .vti file; '-' or none: OpenVDB stream on stdout\n"
"      --threads T      threads to use (default: all cores)\n"
"      --max-memory SZ  refuse grids larger than SZ (e.g. 8G; default 80%% of RAM)\n"
"  -q, --quiet          no messages but errors\n"
"  -v, --verbose        report grid size and timings\n"
"  -h, --help           show this help and exit\n"
"  -V, --version        show the version and commit and exit\n"
"\n"
"Examples:\n"
"  soupdist -r 256 -o bunny.vdb bunny.obj\n"
"  soupdist bunny.obj | soupsign -o bunny.vti\n"
"\n"
"Exit status: 0 ok, 1 bad input or failure, 2 usage error.\n",
        ST_DIST_DEFAULT_CELLS, ST_DIST_MIN_BAND, ST_DIST_DEFAULT_BAND);
}

enum { OPT_PAD = TOOL_OPT_FIRST, OPT_BAND, OPT_CELLS_OLD, OPT_VOXEL_OLD };

/* Which soup the field came from, so soupsign can use it as --surface
 * (pseudo.h): its absolute path, size and content hash. Nothing for stdin,
 * or where the path cannot be made absolute. */
static int record_source(st_grid *g, const char *in, const st_soup_source *src)
{
    if (strcmp(in, "-") == 0)
        return 0;
    char *abs = realpath(in, NULL);
    if (!abs)
        return 0;
    char size[32];
    snprintf(size, sizeof size, "%llu", src->size);
    int rc = st_meta_set(&g->meta, "source_path", abs) ||
             st_meta_set(&g->meta, "source_size", size) ||
             st_meta_set(&g->meta, "source_hash", src->hash);
    free(abs);
    return rc;
}

/* What the command line asks for. */
typedef struct soupdist_settings {
    tool_common co;
    st_dist_params dist;
    const char *in;
    int have_cells, have_voxel;
} soupdist_settings;

static const struct option longopts[] = {
    {"voxels", required_argument, NULL, 'r'},
    {"voxel-size", required_argument, NULL, 's'},
    {"cells", required_argument, NULL, OPT_CELLS_OLD},   /* before 0.2 */
    {"voxel", required_argument, NULL, OPT_VOXEL_OLD},   /* before 0.2 */
    {"pad", required_argument, NULL, OPT_PAD},
    {"band", required_argument, NULL, OPT_BAND},
    TOOL_LONG_OPTIONS_OUTPUT,
    TOOL_LONG_OPTIONS_END};

static int option(tool_ctx *t, int c, const char *arg, void *settings)
{
    soupdist_settings *s = settings;
    switch (c) {
    case OPT_CELLS_OLD:
        tool_deprecated(t, "--cells", "--voxels (-r)");
        /* fall through */
    case 'r':
        if (tool_parse_size(t, "-r", arg, 1, 65536, &s->dist.cells))
            return TOOL_EXIT_USAGE;
        s->have_cells = 1;
        break;
    case OPT_VOXEL_OLD:
        tool_deprecated(t, "--voxel", "--voxel-size (-s)");
        /* fall through */
    case 's':
        if (tool_parse_double(t, "-s", arg, 1e-300, 1e300, &s->dist.voxel))
            return TOOL_EXIT_USAGE;
        s->have_voxel = 1;
        break;
    case OPT_PAD: {
        size_t pad;
        if (tool_parse_size(t, "--pad", arg, 0, 1000000, &pad))
            return TOOL_EXIT_USAGE;
        s->dist.pad = (long)pad;
        break;
    }
    case OPT_BAND:
        if (strcmp(arg, "full") == 0)
            s->dist.band = INFINITY;
        else if (tool_parse_double(t, "--band", arg, ST_DIST_MIN_BAND, 1e6, &s->dist.band))
            return TOOL_EXIT_USAGE;
        break;
    }
    return TOOL_CONTINUE;
}

static int check(tool_ctx *t, int argc, char *argv[], void *settings)
{
    soupdist_settings *s = settings;
    if (s->have_cells && s->have_voxel)
        return tool_usage_error(t, "give -r or -s, not both");
    TOOL_TRY(tool_one_input(t, argc, argv, "input file", "-", &s->in));
    TOOL_TRY(tool_refuse_terminal(t, s->in, STDIN_FILENO, TOOL_TTY_SURFACE));
    TOOL_TRY(tool_grid_output(t, s->co.out));
    TOOL_TRY(tool_output_check(t, s->co.out));
    s->dist.max_bytes = s->co.max_bytes;
    return TOOL_CONTINUE;
}

/* A banded field goes to a .vdb or a stream stored by blocks: no dense
 * grid is allocated, and the file is the same. */
static int use_blocks(const soupdist_settings *s)
{
    return isfinite(s->dist.band) &&
           (st_path_is_stdio(s->co.out) ||
            st_grid_format_from_path(s->co.out) == ST_GRID_FMT_VDB);
}

/* The field, dense (*g) or stored by blocks (*b, then (*b)->head is its
 * grid head); a failure's message names the input and the fix. */
static int compute(tool_ctx *t, const soupdist_settings *s,
                   const st_soup *soup, st_grid **g, st_grid_blocks **b)
{
    st_error err;
    st_error_clear(&err);
    st_progress prog = tool_progress(t);
    st_status st = use_blocks(s) ? st_dist_field_blocks(b, soup, &s->dist, &prog, &err)
                                 : st_dist_field(g, soup, &s->dist, &prog, &err);
    if (!st) {
        tool_progress_end(t);
        return TOOL_EXIT_OK;
    }
    if (!err.file[0])
        snprintf(err.file, sizeof err.file, "%s", s->in);
    size_t fit = err.status == ST_ELIMIT ? tool_dist_cells_that_fit(soup, &s->dist) : 0;
    char hint[160];
    if (fit)
        snprintf(hint, sizeof hint, "use -r %zu or less, a larger -s, or raise "
                 "--max-memory", fit);
    else
        snprintf(hint, sizeof hint, "use a smaller -r or a larger -s, or raise "
                 "--max-memory");
    tool_limit_hint(&err, hint);
    return tool_fail(t, &err);
}

static int run(tool_ctx *t, void *settings)
{
    const soupdist_settings *s = settings;
    const char *in = s->in;
    tool_set_threads(s->co.threads);
    st_error err;
    st_error_clear(&err);
    st_soup *soup = NULL;
    st_grid *dense = NULL;
    st_grid_blocks *blocks = NULL;
    int rc = TOOL_EXIT_FAIL;
    double t_read = tool_now();
    st_soup_source src;
    if (tool_soup_read_source(t, &soup, in, &src, &err)) {
        rc = tool_fail(t, &err);
        goto done;
    }
    double t_dist = tool_now();
    rc = compute(t, s, soup, &dense, &blocks);
    if (rc != TOOL_EXIT_OK)
        goto done;
    rc = TOOL_EXIT_FAIL;
    st_grid *g = blocks ? &blocks->head : dense;
    double t_write = tool_now();
    if (st_meta_set(&g->meta, "source", tool_in_name(in)) ||
        record_source(g, in, &src) ||
        tool_meta_record(t, &g->meta)) {
        rc = tool_fail_nomem(t, &err);
        goto done;
    }
    if (blocks ? st_grid_blocks_write(blocks, s->co.out, &err)
               : st_grid_write(g, s->co.out, &err)) {
        rc = tool_fail(t, &err);
        goto done;
    }
    double t_end = tool_now();
    tool_say(t, 2, "%s: %zu vertices, %zu triangles", in, soup->nverts,
             soup->ntris);
    if (isinf(g->band))
        tool_say(t, 2, "grid %zux%zux%zu, voxel %.6g, full field",
                 g->nx, g->ny, g->nz, g->voxel);
    else
        tool_say(t, 2, "grid %zux%zux%zu, voxel %.6g, band %.6g (%g voxels)",
                 g->nx, g->ny, g->nz, g->voxel, g->band, g->band / g->voxel);
    tool_say(t, 2, "read %.3f s, distance %.3f s, write %.3f s",
             t_dist - t_read, t_write - t_dist, t_end - t_write);
    rc = TOOL_EXIT_OK;
done:
    st_grid_free(dense);
    st_grid_blocks_free(blocks);
    st_soup_free(soup);
    return rc;
}

static const tool_spec spec = {"soupdist", usage, ":r:s:o:qv", longopts, option, check, run};

int main(int argc, char *argv[])
{
    soupdist_settings s = {.dist = st_dist_params_default()};
    return tool_main(&spec, argc, argv, &s, &s.co);
}
