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
"      --symmetry on|off  with --surface: fill holes from the soup's\n"
"                       symmetries, as soupsign --symmetry (default on)\n"
"  -r, --voxels N       with --surface: voxels along the longest side\n"
"                       (default %d)\n"
"  -o, --output OUT     .obj .off .ply (binary) .stl (binary); '-' or none:\n"
"                       OBJ on stdout\n"
"      --threads T      threads to use (default: all cores)\n"
"      --max-memory SZ  refuse fields larger than SZ (default 80%% of RAM)\n"
"  -q, --quiet          no messages but errors\n"
"  -v, --verbose        report sizes, checks and timings\n"
"  -h, --help           show this help and exit\n"
"  -V, --version        show the version and commit and exit\n"
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
       OPT_CELLS_OLD };

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

/* What the command line asks for. */
typedef struct soupwrap_settings {
    tool_common co;
    st_wrap_params wrap;
    st_dist_params dist;
    const char *in, *surface;
    st_soup_format format;
    int have_cells, fill_holes, use_shells, symmetry;
} soupwrap_settings;

static const struct option longopts[] = {
    {"iso", required_argument, NULL, OPT_ISO},
    {"adaptivity", required_argument, NULL, OPT_ADAPT},
    {"smooth", required_argument, NULL, OPT_SMOOTH},
    {"min-volume", required_argument, NULL, OPT_MINVOL},
    {"keep-cavities", no_argument, NULL, OPT_CAVITIES},
    {"surface", required_argument, NULL, OPT_SURFACE},
    TOOL_LONG_OPTIONS_PSEUDO,
    {"voxels", required_argument, NULL, 'r'},
    {"cells", required_argument, NULL, OPT_CELLS_OLD},   /* before 0.2 */
    TOOL_LONG_OPTIONS_OUTPUT,
    TOOL_LONG_OPTIONS_END};

static int option(tool_ctx *t, int c, const char *arg, void *settings)
{
    soupwrap_settings *s = settings;
    size_t smooth;
    switch (c) {
    case OPT_ISO:
        if (tool_parse_double(t, "--iso", arg, -1e300, 1e300, &s->wrap.iso))
            return TOOL_EXIT_USAGE;
        break;
    case OPT_ADAPT:
        if (tool_parse_double(t, "--adaptivity", arg, 0.0, 1.0, &s->wrap.adaptivity))
            return TOOL_EXIT_USAGE;
        break;
    case OPT_SMOOTH:
        if (tool_parse_size(t, "--smooth", arg, 0, 1000, &smooth))
            return TOOL_EXIT_USAGE;
        s->wrap.smooth = (int)smooth;
        break;
    case OPT_MINVOL:
        if (tool_parse_double(t, "--min-volume", arg, 0.0, 1e300, &s->wrap.min_volume))
            return TOOL_EXIT_USAGE;
        break;
    case OPT_CAVITIES:
        s->wrap.keep_cavities = 1;
        break;
    case OPT_SURFACE:
        s->surface = arg;
        break;
    case TOOL_OPT_FILL_HOLES:
    case TOOL_OPT_SHELLS:
    case TOOL_OPT_SYMMETRY:
        return tool_pseudo_option(t, c, arg,
                                  &(tool_pseudo_switches){&s->fill_holes, &s->use_shells,
                                                          &s->symmetry});
    case OPT_CELLS_OLD:
        tool_deprecated(t, "--cells", "--voxels (-r)");
        /* fall through */
    case 'r':
        if (tool_parse_size(t, "-r", arg, 1, 65536, &s->dist.cells))
            return TOOL_EXIT_USAGE;
        s->have_cells = 1;
        break;
    }
    return TOOL_CONTINUE;
}

static int check(tool_ctx *t, int argc, char *argv[], void *settings)
{
    soupwrap_settings *s = settings;
    TOOL_TRY(tool_one_input(t, argc, argv, "input", NULL, &s->in));
    if (s->surface && s->in)
        return tool_usage_error(t, "give a FIELD or --surface INPUT, not both");
    if (s->have_cells && !s->surface)
        return tool_usage_error(t, "-r needs --surface (a field has its grid already)");
    if (!s->surface && !s->in)
        s->in = "-";
    if (s->in)
        TOOL_TRY(tool_refuse_terminal(t, s->in, STDIN_FILENO, "no input: give a field or "
                                      "pipe one in (soupdist mesh.obj | soupsign | soupwrap), "
                                      "or --surface INPUT"));
    if (s->surface)
        TOOL_TRY(tool_refuse_terminal(t, s->surface, STDIN_FILENO, TOOL_TTY_SURFACE));
    if (!st_path_is_stdio(s->co.out))
        s->format = st_soup_format_from_path(s->co.out);
    TOOL_TRY(tool_output_format(t, s->co.out, s->format != ST_SOUP_UNKNOWN,
                                ".obj, .off, .ply or .stl"));
    TOOL_TRY(tool_output_check(t, s->co.out));
    s->dist.max_bytes = s->co.max_bytes;
    return TOOL_CONTINUE;
}

static int run(tool_ctx *t, void *settings)
{
    const soupwrap_settings *s = settings;
    const char *in = s->in, *surface = s->surface, *out = s->co.out;
    tool_set_threads(s->co.threads);
    st_error err;
    st_error_clear(&err);
    st_grid *g = NULL;
    st_soup *input = NULL, *res = NULL;
    char *comment = NULL;
    st_outfile of = {0};
    int rc = TOOL_EXIT_FAIL;
    const char *src = surface ? surface : in;
    const char *srcname = tool_in_name(src);
    double t0 = tool_now(), t_field, t_wrap;
    st_progress prog = tool_progress(t);
    if (surface) {
        if (st_soup_read(&input, surface, &err)) {
            rc = tool_fail(t, &err);
            goto done;
        }
        /* As soupsign --surface (pseudo.h). */
        st_pseudo_params pp = st_pseudo_params_default();
        pp.fill_holes = s->fill_holes;
        pp.closed_shells = s->use_shells;
        pp.symmetry = s->symmetry;
        if (st_pseudo_volume(&g, input, &s->dist, &pp, NULL, &prog, &err)) {
            if (!err.file[0])
                snprintf(err.file, sizeof err.file, "%s", srcname);
            tool_limit_hint(&err, "use a smaller -r or raise --max-memory");
            rc = tool_fail(t, &err);
            goto done;
        }
    } else if (st_grid_read(&g, in, s->co.max_bytes, &err) ||
               tool_check_field_finite(g, srcname, &err)) {
        if (st_soup_format_from_path(in) != ST_SOUP_UNKNOWN) snprintf(err.msg + strlen(err.msg), sizeof err.msg - strlen(err.msg), "; a surface? soupwrap --surface %s", in);
        rc = tool_fail(t, &err);
        goto done;
    }
    t_field = tool_now();
    st_wrap_stats stats;
    if (st_wrap_field(&res, g, &s->wrap, &stats, &prog, &err)) {
        tool_progress_end(t);
        rc = tool_fail_file(t, &err, srcname);
        goto done;
    }
    tool_progress_end(t);
    t_wrap = tool_now();
    comment = history(g, surface ? srcname : st_meta_get(&g->meta, "source"),
                      tool_command(t));
    if (!comment) {
        rc = tool_fail_nomem(t, &err);
        goto done;
    }
    const char *outname = tool_out_name(out);
    if (st_outfile_begin(&of, out, 1, &err) ||
        st_soup_write(of.fp, res, s->format, comment, outname, &err) ||
        st_outfile_commit(&of, &err)) {
        st_outfile_abort(&of);
        rc = tool_fail(t, &err);
        goto done;
    }
    tool_say(t, 2, "grid %zux%zux%zu, voxel %.6g", g->nx, g->ny, g->nz,
             g->voxel);
    if (stats.edge_voxels_inside)
        tool_say(t, 1, "warning: %zu inside voxels on the grid's edge: the "
                        "surface is closed there, half a voxel beyond the "
                        "grid", stats.edge_voxels_inside);
    tool_say(t, 2, "volumeToMesh: %zu quads, %zu triangles (adaptivity "
                    "%.4g); %zu quads re-split",
             stats.quads, stats.triangles, stats.adaptivity_used,
             stats.resplit);
    tool_say(t, 2, "isovalue margin: %zu values held %.4g voxels off it",
             stats.iso_held_off, stats.iso_margin);
    tool_say(t, 2, "pieces: %zu cavities filled, %zu specks dropped",
             stats.cavities_filled, stats.specks_dropped);
    if (s->wrap.smooth)
        tool_say(t, 2, "smoothing: %zu steps, %zu moves undone",
                 stats.smooth_steps, stats.smooth_reverted);
    tool_say(t, 2, "output: %zu vertices, %zu triangles; closed, manifold, "
                    "outward, no degenerate or self-intersecting triangles "
                    "(checked)", res->nverts, res->ntris);
    tool_say(t, 2, "%s %.3f s, wrap %.3f s, write %.3f s",
             surface ? "distance and signs" : "read", t_field - t0,
             t_wrap - t_field, tool_now() - t_wrap);
    rc = TOOL_EXIT_OK;
done:
    free(comment);
    st_soup_free(res);
    st_soup_free(input);
    st_grid_free(g);
    return rc;
}

static const tool_spec spec = {"soupwrap", usage, ":r:o:qv", longopts, option, check, run};

int main(int argc, char *argv[])
{
    soupwrap_settings s = {.wrap = st_wrap_params_default(), .dist = st_dist_params_default(),
                           .format = ST_SOUP_OBJ, .fill_holes = 1, .use_shells = 1,
                           .symmetry = st_pseudo_params_default().symmetry};
    return tool_main(&spec, argc, argv, &s, &s.co);
}
