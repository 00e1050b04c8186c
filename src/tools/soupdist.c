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
"  -r, --cells N        voxels along the longest side of the box (default %d)\n"
"  -s, --voxel SIZE     voxel size in model units (instead of -r)\n"
"      --pad P          voxels of padding on each side (default: band + 2)\n"
"      --band B         exact band in voxels, at least %g (default %g),\n"
"                       or 'full' for distances everywhere (beyond the band:\n"
"                       propagated, never below the truth)\n"
"  -o, --output OUT     .vdb or .vti file; '-' or none: OpenVDB stream on stdout\n"
"      --threads T      threads to use (default: all cores)\n"
"      --max-memory SZ  refuse grids larger than SZ (e.g. 8G; default 80%% of RAM)\n"
"  -q, --quiet          no messages but errors\n"
"  -v, --verbose        report grid size and timings\n"
"      --help           show this help and exit\n"
"      --version        show the version and exit\n"
"\n"
"Examples:\n"
"  soupdist -r 256 -o bunny.vdb bunny.obj\n"
"  soupdist bunny.obj | soupsign -o bunny.vti\n"
"\n"
"Exit status: 0 ok, 1 bad input or failure, 2 usage error.\n",
        ST_DIST_DEFAULT_CELLS, ST_DIST_MIN_BAND, ST_DIST_DEFAULT_BAND);
}

enum { OPT_PAD = TOOL_OPT_FIRST, OPT_BAND };

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

int main(int argc, char *argv[])
{
    tool_ctx t;
    tool_init(&t, "soupdist", argc, argv);
    tool_common co = tool_common_default();
    st_dist_params p = st_dist_params_default();
    const char *out = NULL, *in = NULL;
    int have_cells = 0, have_voxel = 0;
    static const struct option opts[] = {
        {"cells", required_argument, NULL, 'r'},
        {"voxel", required_argument, NULL, 's'},
        {"pad", required_argument, NULL, OPT_PAD},
        {"band", required_argument, NULL, OPT_BAND},
        {"output", required_argument, NULL, 'o'},
        TOOL_LONG_OPTIONS_BASIC,
        TOOL_LONG_OPTIONS_RESOURCES,
        {NULL, 0, NULL, 0}};
    int c;
    opterr = 0;
    while ((c = getopt_long(argc, argv, ":r:s:o:qv", opts, NULL)) != -1) {
        switch (c) {
        case 'r':
            if (tool_parse_size(&t, "-r", optarg, 1, 65536, &p.cells))
                return TOOL_EXIT_USAGE;
            have_cells = 1;
            break;
        case 's':
            if (tool_parse_double(&t, "-s", optarg, 1e-300, 1e300, &p.voxel))
                return TOOL_EXIT_USAGE;
            have_voxel = 1;
            break;
        case OPT_PAD: {
            size_t pad;
            if (tool_parse_size(&t, "--pad", optarg, 0, 1000000, &pad))
                return TOOL_EXIT_USAGE;
            p.pad = (long)pad;
            break;
        }
        case OPT_BAND:
            if (strcmp(optarg, "full") == 0)
                p.band = INFINITY;
            else if (tool_parse_double(&t, "--band", optarg, ST_DIST_MIN_BAND,
                                       1e6, &p.band))
                return TOOL_EXIT_USAGE;
            break;
        case 'o':
            out = optarg;
            break;
        default: {
            int rc_opt = tool_common_option(&t, c, argv, usage, &co);
            if (rc_opt != TOOL_CONTINUE) {
                tool_finish(&t);
                return rc_opt;
            }
            break;
        }
        }
    }
    if (have_cells && have_voxel)
        return tool_usage_error(&t, "give -r or -s, not both");
    TOOL_TRY(tool_one_input(&t, argc, argv, "input file", "-", &in));
    TOOL_TRY(tool_refuse_terminal(&t, in, STDIN_FILENO, TOOL_TTY_SURFACE));
    TOOL_TRY(tool_refuse_terminal(&t, out, STDOUT_FILENO, "will not write a binary VDB "
                                  "stream to a terminal: give -o FILE or pipe it"));
    TOOL_TRY(tool_output_format(&t, out, st_path_is_stdio(out) ||
                                st_grid_format_from_path(out) != ST_GRID_FMT_UNKNOWN,
                                ".vdb or .vti"));
    TOOL_TRY(tool_output_check(&t, out));
    tool_set_threads(co.threads);
    p.max_bytes = co.max_bytes;

    st_error err;
    st_error_clear(&err);
    st_soup *soup = NULL;
    st_grid *g = NULL;
    int rc = TOOL_EXIT_FAIL;
    double t_read = tool_now();
    st_soup_source src;
    if (tool_soup_read_source(&t, &soup, in, &src, &err)) {
        rc = tool_fail(&t, &err);
        goto done;
    }
    double t_dist = tool_now();
    st_progress prog = tool_progress(&t);
    if (st_dist_field(&g, soup, &p, &prog, &err)) {
        if (!err.file[0])
            snprintf(err.file, sizeof err.file, "%s", in);
        size_t fit = err.status == ST_ELIMIT ? tool_dist_cells_that_fit(soup, &p) : 0;
        char hint[160];
        if (fit)
            snprintf(hint, sizeof hint, "use -r %zu or less, a larger -s, or raise "
                     "--max-memory", fit);
        else
            snprintf(hint, sizeof hint, "use a smaller -r or a larger -s, or raise "
                     "--max-memory");
        tool_limit_hint(&err, hint);
        rc = tool_fail(&t, &err);
        goto done;
    }
    tool_progress_end(&t);
    double t_write = tool_now();
    if (st_meta_set(&g->meta, "source",
                    strcmp(in, "-") == 0 ? "<stdin>" : in) ||
        record_source(g, in, &src) ||
        st_meta_history_append(&g->meta, t.command_line ? t.command_line
                                                        : "soupdist")) {
        st_error_set(&err, ST_ENOMEM, NULL, 0, "out of memory");
        rc = tool_fail(&t, &err);
        goto done;
    }
    if (st_grid_write(g, out, &err)) {
        rc = tool_fail(&t, &err);
        goto done;
    }
    double t_end = tool_now();
    tool_say(&t, 2, "%s: %zu vertices, %zu triangles", in, soup->nverts,
             soup->ntris);
    if (isinf(g->band))
        tool_say(&t, 2, "grid %zux%zux%zu, voxel %.6g, full field",
                 g->nx, g->ny, g->nz, g->voxel);
    else
        tool_say(&t, 2, "grid %zux%zux%zu, voxel %.6g, band %.6g (%g voxels)",
                 g->nx, g->ny, g->nz, g->voxel, g->band, g->band / g->voxel);
    tool_say(&t, 2, "read %.3f s, distance %.3f s, write %.3f s",
             t_dist - t_read, t_write - t_dist, t_end - t_write);
    rc = TOOL_EXIT_OK;
done:
    st_grid_free(g);
    st_soup_free(soup);
    tool_finish(&t);
    return rc;
}
