/*
 * soupwrap - the repaired soup: a closed, oriented, manifold surface
 * around the pseudo volume.
 *
 *   soupwrap [FIELD] [--iso V] [--adaptivity A] [--smooth N] [-o OUT]
 *   soupwrap --surface INPUT [-r N] [...]
 *
 * Reads a signed field (from soupsign) or, with --surface, a soup that it
 * runs through soupdist's and soupsign's defaults in-process, extracts the
 * boundary of the pseudo volume (wrap.h) and writes it as OBJ, OFF, PLY or
 * STL by extension (OBJ on stdout). See man/man1/soupwrap.1.
 */
#define _GNU_SOURCE
#include "../cli/tool.h"
#include "souptet/dist.h"
#include "souptet/gridio.h"
#include "souptet/outfile.h"
#include "souptet/pseudo.h"
#include "souptet/soup.h"
#include "souptet/soupwrite.h"
#include "souptet/wrap.h"

#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static void usage(void)
{
    printf(
"Usage: soupwrap [OPTION]... [FIELD]\n"
"       soupwrap --surface INPUT [-r N] [OPTION]...\n"
"Extract the boundary of the pseudo volume as a closed, consistently and\n"
"outward oriented, 2-manifold triangle surface without degenerate or\n"
"self-intersecting triangles (each checked exactly before it is written).\n"
"\n"
"FIELD is a signed field from soupsign (.vdb or .vti); '-' or none reads an\n"
"OpenVDB stream from stdin. With --surface, INPUT (.obj .off .ply .stl .gltf .glb) is\n"
"run through soupdist and soupsign with their defaults first.\n"
"\n"
"      --iso V          isovalue in model units (default %g; negative shrinks)\n"
"      --adaptivity A   merge flat regions, A in [0, 1] (default %g); halved\n"
"                       until the result is manifold\n"
"      --smooth N       N steps of Taubin smoothing, each move checked\n"
"                       (default %d)\n"
"      --min-volume V   drop outer pieces enclosing less than V cubic voxels\n"
"                       (default %g; 0 keeps every piece)\n"
"      --keep-cavities  keep pieces that lie inside others (default: fill)\n"
"      --surface INPUT  wrap a soup: distance and signs (its holes capped and\n"
"                       the signs refined next to it, as soupsign --surface)\n"
"                       in-process\n"
"      --fill-holes on|off  with --surface: cap the soup's holes (default on)\n"
"      --shells on|off  with --surface: the soup's closed pieces bound their\n"
"                       solid exactly, as soupsign --shells (default on)\n"
"  -r, --cells N        with --surface: voxels along the longest side\n"
"                       (default %d)\n"
"  -o, --output OUT     .obj .off .ply (binary) .stl (binary); '-' or none:\n"
"                       OBJ on stdout\n"
"      --threads T      threads to use (default: all cores)\n"
"      --max-memory SZ  refuse fields larger than SZ (default 80%% of RAM)\n"
"  -q, --quiet          no messages but errors\n"
"  -v, --verbose        report sizes, checks and timings\n"
"      --help           show this help and exit\n"
"      --version        show the version and exit\n"
"\n"
"Examples:\n"
"  soupdist scan.ply | soupsign | soupwrap -o scan-closed.ply\n"
"  soupwrap --surface parts.stl -r 256 --smooth 5 -o closed.stl\n"
"\n"
"Exit status: 0 ok, 1 bad input or failure, 2 usage error.\n",
        ST_WRAP_DEFAULT_ISO, ST_WRAP_DEFAULT_ADAPTIVITY, ST_WRAP_DEFAULT_SMOOTH,
        ST_WRAP_DEFAULT_MIN_VOLUME, ST_DIST_DEFAULT_CELLS);
}

enum { OPT_ISO = TOOL_OPT_FIRST, OPT_ADAPT, OPT_SMOOTH, OPT_MINVOL, OPT_CAVITIES, OPT_SURFACE,
       OPT_FILL_HOLES, OPT_SHELLS };

/* The history lines of the field plus this command line. Caller frees. */
static char *history(const st_grid *g, const char *source, const char *cmd)
{
    const char *h = st_meta_get(&g->meta, "history");
    size_t n = (h ? strlen(h) + 1 : 0) + strlen(cmd) + 1 +
               (source ? strlen(source) + 16 : 0) + 32;
    char *s = malloc(n);
    if (!s)
        return NULL;
    snprintf(s, n, "souptet soupwrap%s%s\n%s%s%s", source ? "; source: " : "",
             source ? source : "", h ? h : "", h ? "\n" : "", cmd);
    return s;
}

int main(int argc, char *argv[])
{
    tool_ctx t;
    tool_init(&t, "soupwrap", argc, argv);
    tool_common co = tool_common_default();
    st_wrap_params p = st_wrap_params_default();
    st_dist_params dp = st_dist_params_default();
    size_t smooth = 0;
    const char *out = NULL, *in = NULL, *surface = NULL;
    int have_cells = 0, fill_holes = 1, use_shells = 1;
    static const struct option opts[] = {
        {"iso", required_argument, NULL, OPT_ISO},
        {"adaptivity", required_argument, NULL, OPT_ADAPT},
        {"smooth", required_argument, NULL, OPT_SMOOTH},
        {"min-volume", required_argument, NULL, OPT_MINVOL},
        {"keep-cavities", no_argument, NULL, OPT_CAVITIES},
        {"surface", required_argument, NULL, OPT_SURFACE},
        {"fill-holes", required_argument, NULL, OPT_FILL_HOLES},
        {"shells", required_argument, NULL, OPT_SHELLS},
        {"cells", required_argument, NULL, 'r'},
        {"output", required_argument, NULL, 'o'},
        TOOL_LONG_OPTIONS_BASIC,
        TOOL_LONG_OPTIONS_RESOURCES,
        {NULL, 0, NULL, 0}};
    int c;
    opterr = 0;
    while ((c = getopt_long(argc, argv, ":r:o:qv", opts, NULL)) != -1) {
        switch (c) {
        case OPT_ISO:
            if (tool_parse_double(&t, "--iso", optarg, -1e300, 1e300, &p.iso))
                return TOOL_EXIT_USAGE;
            break;
        case OPT_ADAPT:
            if (tool_parse_double(&t, "--adaptivity", optarg, 0.0, 1.0,
                                  &p.adaptivity))
                return TOOL_EXIT_USAGE;
            break;
        case OPT_SMOOTH:
            if (tool_parse_size(&t, "--smooth", optarg, 0, 1000, &smooth))
                return TOOL_EXIT_USAGE;
            p.smooth = (int)smooth;
            break;
        case OPT_MINVOL:
            if (tool_parse_double(&t, "--min-volume", optarg, 0.0, 1e300,
                                  &p.min_volume))
                return TOOL_EXIT_USAGE;
            break;
        case OPT_CAVITIES:
            p.keep_cavities = 1;
            break;
        case OPT_SURFACE:
            surface = optarg;
            break;
        case OPT_FILL_HOLES:
            if (tool_parse_switch(&t, "--fill-holes", optarg, &fill_holes))
                return TOOL_EXIT_USAGE;
            break;
        case OPT_SHELLS:
            if (tool_parse_switch(&t, "--shells", optarg, &use_shells))
                return TOOL_EXIT_USAGE;
            break;
        case 'r':
            if (tool_parse_size(&t, "-r", optarg, 1, 65536, &dp.cells))
                return TOOL_EXIT_USAGE;
            have_cells = 1;
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
    TOOL_TRY(tool_one_input(&t, argc, argv, "input", NULL, &in));
    if (surface && in)
        return tool_usage_error(&t, "give a FIELD or --surface INPUT, not "
                                    "both");
    if (have_cells && !surface)
        return tool_usage_error(&t, "-r needs --surface (a field has its "
                                    "grid already)");
    if (!surface && !in)
        in = "-";
    if (in)
        TOOL_TRY(tool_refuse_terminal(&t, in, STDIN_FILENO, "no input: give a field or pipe "
                                      "one in (soupdist mesh.obj | soupsign | soupwrap), "
                                      "or --surface INPUT"));
    if (surface)
        TOOL_TRY(tool_refuse_terminal(&t, surface, STDIN_FILENO, TOOL_TTY_SURFACE));
    st_soup_format fmt = ST_SOUP_OBJ;
    if (!st_path_is_stdio(out)) {
        fmt = st_soup_format_from_path(out);
        if (fmt == ST_SOUP_UNKNOWN)
            return tool_usage_error(&t, "cannot tell the format of '%s' "
                                        "(use .obj, .off, .ply or .stl)",
                                    out);
    }
    TOOL_TRY(tool_output_check(&t, out));
    tool_set_threads(co.threads);
    dp.max_bytes = co.max_bytes;

    st_error err;
    st_error_clear(&err);
    st_grid *g = NULL;
    st_soup *input = NULL, *res = NULL;
    char *comment = NULL;
    st_outfile of = {0};
    int rc = TOOL_EXIT_FAIL;
    const char *src = surface ? surface : in;
    const char *srcname = st_path_is_stdio(src) ? "<stdin>" : src;
    double t0 = tool_now(), t_field, t_wrap;
    st_progress prog = tool_progress(&t);
    if (surface) {
        if (st_soup_read(&input, surface, &err)) {
            rc = tool_fail(&t, &err);
            goto done;
        }
        /* As soupsign --surface (pseudo.h). */
        st_pseudo_params pp = st_pseudo_params_default();
        pp.fill_holes = fill_holes;
        pp.closed_shells = use_shells;
        if (st_pseudo_volume(&g, input, &dp, &pp, NULL, &prog, &err)) {
            if (!err.file[0])
                snprintf(err.file, sizeof err.file, "%s", srcname);
            tool_limit_hint(&err, "use a smaller -r or raise --max-memory");
            rc = tool_fail(&t, &err);
            goto done;
        }
    } else if (st_grid_read(&g, in, co.max_bytes, &err) ||
               tool_check_field_finite(g, srcname, &err)) {
        if (st_soup_format_from_path(in) != ST_SOUP_UNKNOWN) snprintf(err.msg + strlen(err.msg), sizeof err.msg - strlen(err.msg), "; a surface? soupwrap --surface %s", in);
        rc = tool_fail(&t, &err);
        goto done;
    }
    t_field = tool_now();
    st_wrap_stats stats;
    if (st_wrap_field(&res, g, &p, &stats, &prog, &err)) {
        tool_progress_end(&t);
        if (!err.file[0])
            snprintf(err.file, sizeof err.file, "%s", srcname);
        rc = tool_fail(&t, &err);
        goto done;
    }
    tool_progress_end(&t);
    t_wrap = tool_now();
    comment = history(g, surface ? srcname : st_meta_get(&g->meta, "source"),
                      t.command_line ? t.command_line : "soupwrap");
    if (!comment) {
        st_error_set(&err, ST_ENOMEM, NULL, 0, "out of memory");
        rc = tool_fail(&t, &err);
        goto done;
    }
    const char *outname = st_path_is_stdio(out) ? "<stdout>" : out;
    if (st_outfile_begin(&of, out, 1, &err) ||
        st_soup_write(of.fp, res, fmt, comment, outname, &err) ||
        st_outfile_commit(&of, &err)) {
        st_outfile_abort(&of);
        rc = tool_fail(&t, &err);
        goto done;
    }
    tool_say(&t, 2, "grid %zux%zux%zu, voxel %.6g", g->nx, g->ny, g->nz,
             g->voxel);
    if (stats.edge_voxels_inside)
        tool_say(&t, 1, "warning: %zu inside voxels on the grid's edge: the "
                        "surface is closed there, half a voxel beyond the "
                        "grid", stats.edge_voxels_inside);
    tool_say(&t, 2, "volumeToMesh: %zu quads, %zu triangles (adaptivity "
                    "%.4g); %zu quads re-split",
             stats.quads, stats.triangles, stats.adaptivity_used,
             stats.resplit);
    tool_say(&t, 2, "pieces: %zu cavities filled, %zu specks dropped",
             stats.cavities_filled, stats.specks_dropped);
    if (p.smooth)
        tool_say(&t, 2, "smoothing: %zu steps, %zu moves undone",
                 stats.smooth_steps, stats.smooth_reverted);
    tool_say(&t, 2, "output: %zu vertices, %zu triangles; closed, manifold, "
                    "outward, no degenerate or self-intersecting triangles "
                    "(checked)", res->nverts, res->ntris);
    tool_say(&t, 2, "%s %.3f s, wrap %.3f s, write %.3f s",
             surface ? "distance and signs" : "read", t_field - t0,
             t_wrap - t_field, tool_now() - t_wrap);
    rc = TOOL_EXIT_OK;
done:
    free(comment);
    st_soup_free(res);
    st_soup_free(input);
    st_grid_free(g);
    tool_finish(&t);
    return rc;
}
