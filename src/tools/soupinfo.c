/*
 * soupinfo - what is wrong with a triangle soup.
 *
 *   soupinfo [--json] [--no-self-check] [-q|-v] INPUT...
 *
 * Reads each surface (.obj .off .ply .stl, or stdin) and reports the counts
 * of soupinfo.h: vertices, welded points, degenerate and duplicated
 * triangles, edges by kind, holes, pieces, Euler characteristic and genus,
 * collinear and self-intersecting triangles (exact), as a table per file
 * or as one JSON array. See man/man1/soupinfo.1.
 */
#define _GNU_SOURCE
#include "../cli/tool.h"
#include "souptet/soup.h"
#include "souptet/soupinfo.h"

#include <getopt.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static void usage(void)
{
    printf(
"Usage: soupinfo [OPTION]... [INPUT]...\n"
"Report what is wrong with triangle soups: welded points, degenerate and\n"
"duplicated triangles, boundary, non-manifold and inconsistently oriented\n"
"edges, holes, pieces, Euler characteristic, genus, and self-intersecting\n"
"triangles (exact).\n"
"\n"
"INPUT is a surface (.obj .off .ply .stl .gltf .glb); '-' or none reads stdin.\n"
"Vertices are welded where their coordinates are exactly equal (no\n"
"tolerance) before edges and pieces are counted.\n"
"\n"
"      --json           one JSON array, an object per input (default: a table)\n"
"      --no-self-check  skip the self-intersection test (the slowest part)\n"
"  -q, --quiet          no messages but errors\n"
"  -v, --verbose        report read and analysis times on stderr\n"
"  -h, --help           show this help and exit\n"
"  -V, --version        show the version and commit and exit\n"
"\n"
"Examples:\n"
"  soupinfo bunny.obj\n"
"  soupinfo --json scan-*.ply > report.json\n"
"\n"
"Exit status: 0 ok, 1 an input could not be read, 2 usage error.\n");
}

/* ---- output ---------------------------------------------------------------- */

/* One JSON object. */
static void print_json(FILE *f, const char *name, const st_soupinfo *r)
{
    char b[7][32];
    fprintf(f, "{\"file\": ");
    tool_json_string(f, name);
    fprintf(f,
            ",\n  \"vertices\": %zu, \"triangles\": %zu, "
            "\"unreferenced_vertices\": %zu,\n"
            "  \"lo\": [%s, %s, %s], \"hi\": [%s, %s, %s], "
            "\"diagonal\": %s,\n"
            "  \"welded_vertices\": %zu, \"degenerate_triangles\": %zu, "
            "\"duplicated_triangles\": %zu,\n"
            "  \"edges\": %zu, \"boundary_edges\": %zu, \"manifold_edges\": %zu, "
            "\"nonmanifold_edges\": %zu, \"inconsistent_edges\": %zu,\n"
            "  \"nonmanifold_vertices\": %zu, \"holes\": %zu, \"pieces\": %zu, "
            "\"closed_pieces\": %zu, \"nonorientable_pieces\": %zu,\n"
            "  \"euler\": %lld, \"genus\": %lld, \"closed\": %s, "
            "\"consistently_oriented\": %s,\n"
            "  \"collinear_triangles\": %zu, ",
            r->vertices, r->triangles, r->unreferenced_vertices,
            tool_json_number(b[0], r->lo[0]), tool_json_number(b[1], r->lo[1]), tool_json_number(b[2], r->lo[2]),
            tool_json_number(b[3], r->hi[0]), tool_json_number(b[4], r->hi[1]), tool_json_number(b[5], r->hi[2]),
            tool_json_number(b[6], r->diagonal),
            r->welded_vertices, r->degenerate_triangles,
            r->duplicated_triangles, r->edges, r->boundary_edges,
            r->manifold_edges, r->nonmanifold_edges, r->inconsistent_edges,
            r->nonmanifold_vertices, r->holes, r->pieces, r->closed_pieces,
            r->nonorientable_pieces, r->euler, r->genus,
            r->closed ? "true" : "false",
            r->consistently_oriented ? "true" : "false",
            r->collinear_triangles);
    if (r->self_checked)
        fprintf(f, "\"self_intersecting_pairs\": %zu, "
                   "\"self_intersecting_triangles\": %zu}",
                r->self_intersecting_pairs, r->self_intersecting_triangles);
    else
        fprintf(f, "\"self_intersecting_pairs\": null, "
                   "\"self_intersecting_triangles\": null}");
}

static void print_table(FILE *f, const char *name, const st_soupinfo *r)
{
#define ROW(label, fmt, ...) fprintf(f, "  %-24s " fmt "\n", label, __VA_ARGS__)
    fprintf(f, "%s:\n", name);
    ROW("vertices", "%zu", r->vertices);
    ROW("  unreferenced", "%zu", r->unreferenced_vertices);
    ROW("  welded (distinct)", "%zu", r->welded_vertices);
    ROW("triangles", "%zu", r->triangles);
    ROW("  degenerate", "%zu", r->degenerate_triangles);
    ROW("  duplicated", "%zu", r->duplicated_triangles);
    ROW("  collinear", "%zu", r->collinear_triangles);
    if (r->self_checked) {
        ROW("  self-intersecting", "%zu", r->self_intersecting_triangles);
        ROW("self-intersecting pairs", "%zu", r->self_intersecting_pairs);
    } else {
        ROW("  self-intersecting", "%s", "not checked");
    }
    ROW("edges", "%zu", r->edges);
    ROW("  boundary", "%zu", r->boundary_edges);
    ROW("  manifold", "%zu", r->manifold_edges);
    ROW("  non-manifold", "%zu", r->nonmanifold_edges);
    ROW("  inconsistent", "%zu", r->inconsistent_edges);
    ROW("non-manifold vertices", "%zu", r->nonmanifold_vertices);
    ROW("holes", "%zu", r->holes);
    ROW("pieces", "%zu", r->pieces);
    ROW("  closed", "%zu", r->closed_pieces);
    ROW("  non-orientable", "%zu", r->nonorientable_pieces);
    ROW("euler characteristic", "%lld", r->euler);
    ROW("genus (closed pieces)", "%lld", r->genus);
    ROW("closed", "%s", r->closed ? "yes" : "no");
    ROW("consistently oriented", "%s", r->consistently_oriented ? "yes" : "no");
    ROW("bounds", "%.9g %.9g %.9g .. %.9g %.9g %.9g", r->lo[0], r->lo[1],
        r->lo[2], r->hi[0], r->hi[1], r->hi[2]);
    ROW("diagonal", "%.9g", r->diagonal);
#undef ROW
}

/* ---- main ------------------------------------------------------------------ */

enum { OPT_JSON = TOOL_OPT_FIRST, OPT_NOSELF };

/* What the command line asks for. */
typedef struct soupinfo_settings {
    tool_common co;
    int json, self_check;
    char *const *inputs;   /* ninputs paths; "-" is stdin */
    int ninputs;
} soupinfo_settings;

static const struct option longopts[] = {
    {"json", no_argument, NULL, OPT_JSON},
    {"no-self-check", no_argument, NULL, OPT_NOSELF},
    TOOL_LONG_OPTIONS_BASIC,
    {NULL, 0, NULL, 0}};

static int option(tool_ctx *t, int c, const char *arg, void *settings)
{
    soupinfo_settings *s = settings;
    (void)t;
    (void)arg;
    if (c == OPT_JSON)
        s->json = 1;
    else if (c == OPT_NOSELF)
        s->self_check = 0;
    return TOOL_CONTINUE;
}

static int check(tool_ctx *t, int argc, char *argv[], void *settings)
{
    static char *const stdin_only[] = {"-", NULL};
    soupinfo_settings *s = settings;
    s->inputs = optind < argc ? argv + optind : stdin_only;
    s->ninputs = optind < argc ? argc - optind : 1;
    return tool_stdin_once(t, (const char *const *)s->inputs, (size_t)s->ninputs,
                           TOOL_TTY_SURFACE);
}

static int run(tool_ctx *t, void *settings)
{
    const soupinfo_settings *s = settings;
    /* A bad input is reported and skipped: the others are still worth a
     * report (as wc does), and the exit status says something failed. */
    int rc = TOOL_EXIT_OK, printed = 0;
    if (s->json)
        fputs("[", stdout);
    for (int i = 0; i < s->ninputs; i++) {
        const char *in = s->inputs[i];
        const char *name = tool_in_name(in);
        st_error err;
        st_error_clear(&err);
        st_soup *soup = NULL;
        st_soupinfo r;
        double t_read = tool_now();
        if (tool_soup_read(t, &soup, in, &err)) {
            rc = tool_fail(t, &err);
            continue;
        }
        double t_info = tool_now();
        if (st_soupinfo_compute(&r, soup, &err) ||
            (s->self_check && st_soupinfo_self_intersections(&r, soup, NULL, &err))) {
            rc = tool_fail_file(t, &err, name);
            st_soup_free(soup);
            continue;
        }
        double t_end = tool_now();
        st_soup_free(soup);
        if (s->json) {
            fputs(printed ? ",\n " : "", stdout);
            print_json(stdout, name, &r);
        } else {
            if (printed)
                fputc('\n', stdout);
            print_table(stdout, name, &r);
        }
        printed++;
        tool_say(t, 2, "%s: read %.3f s, analysis %.3f s", name,
                 t_info - t_read, t_end - t_info);
    }
    if (s->json)
        fputs("]\n", stdout);
    if (tool_flush_stdout(t))
        rc = TOOL_EXIT_FAIL;
    return rc;
}

static const tool_spec spec = {"soupinfo", usage, ":qv", longopts, option, check, run};

int main(int argc, char *argv[])
{
    soupinfo_settings s = {.self_check = 1};
    return tool_main(&spec, argc, argv, &s, &s.co);
}
