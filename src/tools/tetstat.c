/*
 * tetstat - the quality and fit of a tet mesh.
 *
 *   tetstat [--surface S] [--field F] [--json] [-q|-v] [--threads T] [MESH]
 *
 * Reads a tet mesh (.vtu, or stdin) and reports the metrics of tetstat.h:
 * counts, dihedral angles and their histogram, inverted and degenerate
 * tets, conformity, components, volume; with a surface the distances
 * between the mesh boundary and the surface, the volume ratio and
 * enclosure; with a signed field the IoU with its pseudo volume. A table,
 * or one JSON object. See man/man1/tetstat.1.
 */
#define _GNU_SOURCE
#include "../cli/tool.h"
#include "souptet/gridio.h"
#include "souptet/parts.h"
#include "souptet/pipeline.h"
#include "souptet/soup.h"
#include "souptet/tetio.h"
#include "souptet/tetstat.h"

#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static void usage(void)
{
    printf(
"Usage: tetstat [OPTION]... [MESH]\n"
"Report the quality of a tet mesh and how well it fits a surface: tets and\n"
"points, min and max dihedral angle and a histogram of each tet's smallest\n"
"one, inverted and degenerate tets (exact), conformity (faces of more than\n"
"two tets), connected components, boundary faces, volume, the lattice cell\n"
"width h when the mesh records it.\n"
"\n"
"MESH is a tet mesh (.vtu .msh .mesh .node/.ele, by extension; sniffed on\n"
"stdin); '-' or none reads stdin.\n"
"\n"
"  -S, --surface S      also measure against surface S (.obj .off .ply .stl .gltf .glb):\n"
"                       distances boundary <-> S, volume ratio (when S is\n"
"                       closed and oriented), enclosure of S by the mesh;\n"
"                       distances also in h and relative to S's box diagonal\n"
"      --offset R       with --surface: count the boundary vertices farther\n"
"                       than R * h from S (Cetra's stopping condition; default\n"
"                       the mesh's meta \"offset_ratio\", as soupmesh writes)\n"
"  -F, --field F        also give the IoU of the mesh with the pseudo volume\n"
"                       (negative voxels) of signed field F (.vdb .vti)\n"
"      --json           one JSON object (default: a table)\n"
"      --threads T      threads to use (default: all cores)\n"
"      --max-memory SZ  refuse meshes and fields larger than SZ (default 80%% of RAM)\n"
"  -q, --quiet          no messages but errors (no warnings about the mesh)\n"
"  -v, --verbose        report the time of each stage on stderr\n"
"  -h, --help           show this help and exit\n"
"  -V, --version        show the version and commit and exit\n"
"\n"
"Examples:\n"
"  tetstat bunny.vtu\n"
"  tetstat --surface bunny.obj --json bunny.vtu > report.json\n"
"  latticetet --density 0.5 bunny-sdf.vdb | tetstat --field bunny-sdf.vdb\n"
"\n"
"Exit status: 0 the report was made (whatever the mesh is like), 1 an input\n"
"could not be read, 2 usage error.\n");
}

/* ---- output ---------------------------------------------------------------- */

static const char *yesno(int b)
{
    return b ? "true" : "false";
}

/* "yes", "no", or "unverified": the counts are clean but the mesh has
 * inverted or flat tets or is not conforming, where they prove nothing
 * (enclose.h). */
static const char *enclosure_word(const st_tetstat *r)
{
    if (r->encloses)
        return "yes";
    if (r->vertices_inside == r->surface_vertices && r->crossing_triangles == 0)
        return "unverified";
    return "no";
}

/* The name of part k, from the mesh's meta, or part_k. */
static const char *part_label(char *buf, size_t size, const st_tetmesh *m, size_t k)
{
    char key[48];
    snprintf(key, sizeof key, "part_name_%zu", k);
    const char *v = st_meta_get(&m->meta, key);
    if (v)
        return v;
    snprintf(buf, size, "part_%zu", k);
    return buf;
}

/* The parts of a tagged mesh (parts.h, soupmesh --parts): per part its
 * tets, their volume, the pseudo volume soupmesh measured for the part
 * and the ratio of the two. */
static void parts_json(FILE *f, const st_tetmesh *m, const st_parts_tag_stats *ps)
{
    fprintf(f, ",\n  \"parts\": [");
    for (size_t k = 0; k < ps->nparts; k++) {
        char lb[32], b[3][32];
        const double pv = ps->pseudo_volume[k];
        fprintf(f, "%s\n    {\"part\": %zu, \"name\": ", k ? "," : "", k);
        tool_json_string(f, part_label(lb, sizeof lb, m, k));
        fprintf(f, ", \"tets\": %zu, \"volume\": %s, \"pseudo_volume\": %s, "
                   "\"volume_ratio\": %s}", ps->tets[k], tool_json_number(b[0], ps->volume[k]),
                isfinite(pv) ? tool_json_number(b[1], pv) : "null",
                isfinite(pv) && pv > 0 ? tool_json_number(b[2], ps->volume[k] / pv) : "null");
    }
    fprintf(f, "],\n  \"parts_uncovered_tets\": %zu", ps->uncovered);
}

static void parts_table(FILE *f, const st_tetmesh *m, const st_parts_tag_stats *ps)
{
    fprintf(f, "parts (%zu; %zu tets cover none):\n", ps->nparts, ps->uncovered);
    for (size_t k = 0; k < ps->nparts; k++) {
        char lb[32];
        const double pv = ps->pseudo_volume[k];
        fprintf(f, "  %-4zu %-23s %zu tets, volume %.6g", k, part_label(lb, sizeof lb, m, k),
                ps->tets[k], ps->volume[k]);
        if (isfinite(pv) && pv > 0)
            fprintf(f, ", its pseudo volume %.6g (ratio %.4f)", pv, ps->volume[k] / pv);
        fputc('\n', f);
    }
}

/* What made the mesh, as its metadata recorded it: the parameters
 * (version, commit, source, h, seed, offset_ratio, field_voxels, ...: every
 * key in its order) and the history, one command line each. JSON: a
 * "recorded" object of strings, "history" an array. */
static void print_meta_json(FILE *f, const st_meta *meta)
{
    fprintf(f, ",\n  \"recorded\": {");
    const char *sep = "";
    for (size_t i = 0; i < meta->count; i++) {
        const st_meta_entry *e = &meta->entries[i];
        fprintf(f, "%s", sep);
        tool_json_string(f, e->key);
        fprintf(f, ": ");
        sep = ", ";
        if (strcmp(e->key, "history") != 0) {
            tool_json_string(f, e->value);
            continue;
        }
        fputc('[', f);
        for (const char *l = e->value; *l;) {
            size_t n = strcspn(l, "\n");
            char *line = strndup(l, n);
            if (l != e->value)
                fprintf(f, ", ");
            tool_json_string(f, line ? line : "");
            free(line);
            l += n + (l[n] == '\n');
        }
        fputc(']', f);
    }
    fputc('}', f);
}

static void print_meta_table(FILE *f, const st_meta *meta)
{
    if (!meta->count)
        return;
    fprintf(f, "recorded in the mesh:\n");
    for (size_t i = 0; i < meta->count; i++) {
        const st_meta_entry *e = &meta->entries[i];
        if (strcmp(e->key, "history") == 0)
            continue;
        fprintf(f, "  %-28s %s\n", e->key, e->value);
    }
    const char *h = st_meta_get(meta, "history");
    for (const char *l = h; l && *l;) {
        size_t n = strcspn(l, "\n");
        fprintf(f, "  %-28s %.*s\n", l == h ? "history" : "", (int)n, l);
        l += n + (l[n] == '\n');
    }
}

static void print_json(FILE *f, const char *name, const char *sname,
                       const char *fname, const st_tetstat *r, const st_tetmesh *m,
                       const st_parts_tag_stats *ps)
{
    char b[15][32];
    fprintf(f, "{\"file\": ");
    tool_json_string(f, name);
    fprintf(f,
            ",\n  \"tets\": %zu, \"points\": %zu, \"unused_points\": %zu,\n"
            "  \"lo\": [%s, %s, %s], \"hi\": [%s, %s, %s],\n"
            "  \"min_dihedral\": %s, \"max_dihedral\": %s,\n"
            "  \"min_dihedral_histogram\": {\"bin_degrees\": %g, \"counts\": [",
            r->tets, r->points, r->unused_points, tool_json_number(b[0], r->lo[0]),
            tool_json_number(b[1], r->lo[1]), tool_json_number(b[2], r->lo[2]), tool_json_number(b[3], r->hi[0]),
            tool_json_number(b[4], r->hi[1]), tool_json_number(b[5], r->hi[2]),
            tool_json_number(b[6], r->min_dihedral), tool_json_number(b[7], r->max_dihedral),
            ST_TETSTAT_BIN_DEG);
    for (int i = 0; i < ST_TETSTAT_BINS; i++)
        fprintf(f, "%s%zu", i ? ", " : "", r->hist[i]);
    fprintf(f,
            "]},\n"
            "  \"inverted\": %zu, \"degenerate\": %zu,\n"
            "  \"boundary_faces\": %zu, \"interior_faces\": %zu, "
            "\"nonmanifold_faces\": %zu, \"conforming\": %s,\n"
            "  \"components\": %zu, \"pinched_edges\": %zu, "
            "\"pinched_points\": %zu,\n"
            "  \"nonmanifold_boundary_edges\": %zu, "
            "\"nonmanifold_boundary_points\": %zu, \"boundary_manifold\": %s,\n"
            "  \"volume\": %s, \"h\": %s",
            r->inverted, r->degenerate, r->boundary_faces, r->interior_faces,
            r->nonmanifold_faces, yesno(r->conforming), r->components,
            r->pinched_edges, r->pinched_points, r->nonmanifold_boundary_edges,
            r->nonmanifold_boundary_points, yesno(r->boundary_manifold),
            tool_json_number(b[0], r->volume), r->has_h ? tool_json_number(b[1], r->h) : "null");
    if (r->has_surface) {
        fprintf(f, ",\n  \"surface\": {\"file\": ");
        tool_json_string(f, sname);
        fprintf(f,
                ", \"vertices\": %zu, \"triangles\": %zu,\n"
                "    \"boundary_vertices\": %zu, \"dist_min\": %s, "
                "\"dist_max\": %s, \"dist_mean\": %s,\n"
                "    \"surface_dist_max\": %s, \"closed\": %s, "
                "\"surface_volume\": %s, \"volume_ratio\": %s",
                r->surface_vertices, r->surface_triangles,
                r->boundary_vertices, tool_json_number(b[0], r->dist_min),
                tool_json_number(b[1], r->dist_max), tool_json_number(b[2], r->dist_mean),
                tool_json_number(b[3], r->surface_dist_max), yesno(r->surface_closed),
                tool_json_number(b[4], r->surface_volume), tool_json_number(b[5], r->volume_ratio));
        /* both distances in h and relative to S's box diagonal */
        int hh = r->has_h && r->h > 0.0, dd = r->surface_diag > 0.0;
        fprintf(f,
                ",\n    \"diagonal\": %s, \"dist_max_h\": %s, \"dist_max_diag\": %s, "
                "\"surface_dist_max_h\": %s, \"surface_dist_max_diag\": %s",
                tool_json_number(b[6], r->surface_diag),
                hh ? tool_json_number(b[7], r->dist_max / r->h) : "null",
                dd ? tool_json_number(b[8], r->dist_max / r->surface_diag) : "null",
                hh ? tool_json_number(b[9], r->surface_dist_max / r->h) : "null",
                dd ? tool_json_number(b[10], r->surface_dist_max / r->surface_diag) : "null");
        if (r->has_offset)
            fprintf(f, ",\n    \"offset_ratio\": %s, \"beyond_offset\": %zu, \"offset_met\": %s",
                    tool_json_number(b[11], r->offset_ratio), r->beyond_offset,
                    yesno((r->has_fill ? r->beyond_offset_fill : r->beyond_offset) == 0));
        else
            fprintf(f, ",\n    \"offset_ratio\": null, \"beyond_offset\": null, "
                       "\"offset_met\": null");
        if (r->has_fill)
            fprintf(f, ",\n    \"fill_faces\": %zu, \"fill_dist_max\": %s, "
                       "\"fill_dist_max_h\": %s, \"beyond_offset_fill\": %s",
                    r->fill_faces, tool_json_number(b[12], r->fill_dist_max),
                    hh ? tool_json_number(b[13], r->fill_dist_max / r->h) : "null",
                    r->has_offset ? tool_json_number(b[14], (double)r->beyond_offset_fill)
                                  : "null");
        else
            fprintf(f, ",\n    \"fill_faces\": null, \"fill_dist_max\": null, "
                       "\"fill_dist_max_h\": null, \"beyond_offset_fill\": null");
        if (r->has_enclosure)
            fprintf(f,
                    ",\n    \"vertices_inside\": %zu, \"fraction_inside\": "
                    "%s, \"crossing_triangles\": %zu, \"encloses\": %s, "
                    "\"enclosure\": \"%s\"}",
                    r->vertices_inside, tool_json_number(b[6], r->fraction_inside),
                    r->crossing_triangles, yesno(r->encloses), enclosure_word(r));
        else
            fprintf(f, ",\n    \"vertices_inside\": null, "
                       "\"fraction_inside\": null, \"crossing_triangles\": "
                       "null, \"encloses\": null, \"enclosure\": null}");
    }
    if (r->has_field) {
        fprintf(f, ",\n  \"field\": {\"file\": ");
        tool_json_string(f, fname);
        fprintf(f,
                ", \"voxels\": %zu, \"field_inside\": %zu, "
                "\"mesh_inside\": %zu, \"both\": %zu, \"iou\": %s}",
                r->field_voxels, r->field_inside, r->mesh_voxels,
                r->both_voxels, tool_json_number(b[0], r->iou));
    }
    if (ps && ps->nparts)
        parts_json(f, m, ps);
    print_meta_json(f, &m->meta);
    fprintf(f, "}\n");
}

#define ROW(label, ...)                                                     \
    do {                                                                    \
        fprintf(f, "  %-28s ", label);                                      \
        fprintf(f, __VA_ARGS__);                                            \
        fputc('\n', f);                                                     \
    } while (0)

/* The row of the stopping condition: how many are beyond R h of what. */
static void beyond_row(FILE *f, double ratio, const char *what, size_t n)
{
    char lab[64];
    snprintf(lab, sizeof lab, "beyond %.3g h (%s)", ratio, what);
    ROW(lab, "%zu%s", n, n ? "   <- OFFSET NOT MET" : "   (met)");
}

static void print_table(FILE *f, const char *name, const char *sname,
                        const char *fname, const st_tetstat *r, const st_tetmesh *m,
                        const st_parts_tag_stats *ps)
{
    fprintf(f, "%s:\n", name);
    ROW("tets", "%zu", r->tets);
    ROW("points", "%zu", r->points);
    ROW("  unused", "%zu", r->unused_points);
    ROW("bounds", "%.9g %.9g %.9g .. %.9g %.9g %.9g", r->lo[0], r->lo[1],
        r->lo[2], r->hi[0], r->hi[1], r->hi[2]);
    if (r->tets) {
        ROW("min dihedral", "%.4f", r->min_dihedral);
        ROW("max dihedral", "%.4f", r->max_dihedral);
    } else {
        ROW("min dihedral", "n/a");
        ROW("max dihedral", "n/a");
    }
    fprintf(f, "  per-tet min dihedral:\n");
    for (int i = 0; i < ST_TETSTAT_BINS; i++) {
        char label[32];
        double lo = i * ST_TETSTAT_BIN_DEG, hi = lo + ST_TETSTAT_BIN_DEG;
        snprintf(label, sizeof label, "  %2.0f..%2.0f", lo, hi);
        ROW(label, "%zu", r->hist[i]);
    }
    ROW("inverted tets", "%zu%s", r->inverted,
        r->inverted ? "   <- INVERTED TETS" : "");
    ROW("degenerate tets", "%zu%s", r->degenerate,
        r->degenerate ? "   <- FLAT TETS" : "");
    ROW("boundary faces", "%zu", r->boundary_faces);
    ROW("interior faces", "%zu", r->interior_faces);
    ROW("non-manifold faces", "%zu", r->nonmanifold_faces);
    ROW("conforming", "%s", r->conforming ? "yes" : "no   <- NOT CONFORMING");
    ROW("components", "%zu", r->components);
    ROW("pinched edges", "%zu%s", r->pinched_edges,
        r->pinched_edges ? "   <- TETS MEET ONLY ALONG AN EDGE" : "");
    ROW("pinched points", "%zu%s", r->pinched_points,
        r->pinched_points ? "   <- TETS MEET ONLY AT A POINT OR EDGE" : "");
    ROW("non-manifold boundary edges", "%zu", r->nonmanifold_boundary_edges);
    ROW("non-manifold boundary points", "%zu", r->nonmanifold_boundary_points);
    ROW("boundary manifold", "%s", r->boundary_manifold ? "yes" : "no   <- NOT MANIFOLD");
    ROW("volume", "%.9g", r->volume);
    if (r->has_h)
        ROW("lattice h", "%.9g", r->h);
    if (r->has_surface) {
        fprintf(f, "surface %s:\n", sname);
        ROW("vertices", "%zu", r->surface_vertices);
        ROW("triangles", "%zu", r->surface_triangles);
        ROW("boundary vertices", "%zu", r->boundary_vertices);
        ROW("boundary -> S min", "%.9g", r->dist_min);
        ROW("boundary -> S max", "%.9g", r->dist_max);
        ROW("boundary -> S mean", "%.9g", r->dist_mean);
        ROW("S -> boundary max", "%.9g", r->surface_dist_max);
        ROW("S box diagonal", "%.9g", r->surface_diag);
        if (r->has_h && r->h > 0.0) {
            ROW("boundary -> S max / h", "%.4f", r->dist_max / r->h);
            ROW("S -> boundary max / h", "%.4f", r->surface_dist_max / r->h);
        }
        if (r->surface_diag > 0.0) {
            ROW("boundary -> S max / diag", "%.6f", r->dist_max / r->surface_diag);
            ROW("S -> boundary max / diag", "%.6f", r->surface_dist_max / r->surface_diag);
        }
        if (r->has_offset && r->has_fill && r->fill_faces > 0) {
            /* the condition is the next row's: this one only informs */
            char lab[64];
            snprintf(lab, sizeof lab, "beyond %.3g h (S alone)", r->offset_ratio);
            ROW(lab, "%zu   (the condition counts the fill too)", r->beyond_offset);
        } else if (r->has_offset) {
            beyond_row(f, r->offset_ratio, "offset", r->beyond_offset);
        }
        if (r->has_fill) {
            ROW("fill (field, no S) faces", "%zu", r->fill_faces);
            ROW("boundary -> S|fill max", "%.9g", r->fill_dist_max);
            if (r->has_h && r->h > 0.0)
                ROW("boundary -> S|fill max / h", "%.4f", r->fill_dist_max / r->h);
            if (r->has_offset)
                beyond_row(f, r->offset_ratio, "S|fill", r->beyond_offset_fill);
        }
        if (r->surface_closed) {
            ROW("surface volume", "%.9g", r->surface_volume);
            ROW("volume ratio", "%.6f", r->volume_ratio);
        } else {
            ROW("surface volume", "n/a (S is not closed and oriented)");
            ROW("volume ratio", "n/a");
        }
        if (r->has_enclosure) {
            ROW("S vertices inside", "%zu of %zu (%.4f%%)",
                r->vertices_inside, r->surface_vertices,
                100.0 * r->fraction_inside);
            ROW("S triangles crossing", "%zu", r->crossing_triangles);
            if (r->encloses)
                ROW("encloses S", "yes");
            else if (!strcmp(enclosure_word(r), "unverified"))
                ROW("encloses S", "unverified (the counts are clean, but they prove "
                    "enclosure only without inverted or flat tets, conforming)");
            else
                ROW("encloses S", "no   <- DOES NOT ENCLOSE");
        } else {
            ROW("encloses S", "n/a (enclosure test not available)");
        }
    }
    if (r->has_field) {
        fprintf(f, "field %s:\n", fname);
        ROW("voxels", "%zu", r->field_voxels);
        ROW("inside the field (< 0)", "%zu", r->field_inside);
        ROW("inside the mesh", "%zu", r->mesh_voxels);
        ROW("both", "%zu", r->both_voxels);
        ROW("IoU", "%.6f", r->iou);
    }
    if (ps && ps->nparts)
        parts_table(f, m, ps);
}
#undef ROW

/* ---- main ------------------------------------------------------------------ */

enum { OPT_JSON = TOOL_OPT_FIRST, OPT_OFFSET };

/* What the command line asks for. */
typedef struct tetstat_settings {
    tool_common co;
    int json;
    double offset;   /* 0: the mesh's meta "offset_ratio" */
    const char *in, *surface, *field;
} tetstat_settings;

static const struct option longopts[] = {
    {"surface", required_argument, NULL, 'S'},
    {"field", required_argument, NULL, 'F'},
    {"json", no_argument, NULL, OPT_JSON},
    {"offset", required_argument, NULL, OPT_OFFSET},
    TOOL_LONG_OPTIONS_END};

static int option(tool_ctx *t, int c, const char *arg, void *settings)
{
    tetstat_settings *s = settings;
    switch (c) {
    case 'S':
        s->surface = arg;
        break;
    case 'F':
        s->field = arg;
        break;
    case OPT_JSON:
        s->json = 1;
        break;
    case OPT_OFFSET:
        if (tool_parse_double(t, "--offset", arg, 1e-3, 10.0, &s->offset))
            return TOOL_EXIT_USAGE;
        break;
    }
    return TOOL_CONTINUE;
}

static int check(tool_ctx *t, int argc, char *argv[], void *settings)
{
    tetstat_settings *s = settings;
    if (argc - optind > 1)
        return tool_usage_error(t, "one mesh at a time (got %d)", argc - optind);
    if (s->offset > 0.0 && !s->surface)
        return tool_usage_error(t, "--offset needs --surface");
    s->in = optind < argc ? argv[optind] : "-";
    const char *inputs[] = {s->in, s->surface, s->field};
    return tool_stdin_once(t, inputs, 3, "will not read from a terminal: give a file or "
                                         "pipe one");
}

static int run(tool_ctx *t, void *settings)
{
    const tetstat_settings *s = settings;
    const char *in = s->in, *surface = s->surface, *field = s->field;
    const char *name = tool_in_name(in);
    tool_set_threads(s->co.threads);
    st_error err;
    st_error_clear(&err);
    st_tetmesh *m = NULL;
    st_soup *soup = NULL;
    st_grid *g = NULL;
    st_tetstat r;
    st_parts_tag_stats parts;
    memset(&parts, 0, sizeof parts);
    int rc = TOOL_EXIT_FAIL;
    double t0 = tool_now();
    /* Read every input first: a bad one gives no half report. */
    if (st_tetmesh_read(&m, in, s->co.max_bytes, &err)) {
        tool_limit_hint(&err, "raise --max-memory");
        rc = tool_fail(t, &err);
        goto done;
    }
    if (surface && tool_soup_read(t, &soup, surface, &err)) {
        rc = tool_fail(t, &err);
        goto done;
    }
    if (field && st_grid_read(&g, field, s->co.max_bytes, &err)) {
        rc = tool_fail(t, &err);
        goto done;
    }
    if (g && tool_check_field_finite(g, tool_in_name(field),
                                     &err)) {
        rc = tool_fail(t, &err);
        goto done;
    }
    /* The IoU is with the negative voxels: an unsigned field has none,
     * and a report of 0 would look like a finding. (A foreign field of
     * unknown kind is taken as signed.) */
    if (g && g->kind == ST_GRID_DISTANCE) {
        st_error_set(&err, ST_EINPUT, tool_in_name(field),
                     0, "the field is %s, not signed (run soupsign first)",
                     st_grid_kind_name(g->kind));
        rc = tool_fail(t, &err);
        goto done;
    }
    double t1 = tool_now();
    if (st_tetstat_mesh(&r, m, &err))
        goto failed;
    if (s->offset > 0.0)
        r.offset_ratio = s->offset;
    double t2 = tool_now();
    if (soup && st_tetstat_surface(&r, m, soup, &err))
        goto failed;
    double t3 = tool_now();
    if (g && st_tetstat_field(&r, m, g, &err))
        goto failed;
    /* both: the fill counts as surface, as soupmesh's condition takes it */
    if (soup && g && st_tetstat_fill(&r, m, soup, g, &err))
        goto failed;
    /* A soupmesh mesh whose condition counted the fill (meta offset_fill
     * yes) and no field given: the same fill, rebuilt from the soup as the
     * run made it (pipeline.h), so tetstat reports the condition soupmesh
     * reported. A mesh that does not say how: the soup alone, as before. */
    int rebuilt = 0;
    const char *of = st_meta_get(&m->meta, "offset_fill");
    if (soup && !g && of && strcmp(of, "yes") == 0 && st_meta_get(&m->meta, "field_voxels")) {
        st_grid *fg = NULL;
        st_progress prog = tool_progress(t);
        st_status fs = st_pipeline_field_of_mesh(&fg, m, soup, s->co.max_bytes, &prog, &err);
        tool_progress_end(t);
        if (!fs)
            fs = st_tetstat_fill(&r, m, soup, fg, &err);
        st_grid_free(fg);
        if (fs)
            goto failed;
        rebuilt = 1;
    }
    double t4 = tool_now();
    tool_say(t, 2, "read %.3f s, mesh %.3f s, surface %.3f s, field %.3f s",
             t1 - t0, t2 - t1, t3 - t2, t4 - t3);

    const char *sname = surface ? tool_in_name(surface) : "<stdin>";
    const char *fname = rebuilt ? "the mesh's field (rebuilt from its meta)"
                        : field ? tool_in_name(field) : "<stdin>";
    if (st_parts_measure(&parts, m, &err))
        goto failed;
    if (s->json)
        print_json(stdout, name, sname, fname, &r, m, &parts);
    else {
        print_table(stdout, name, sname, fname, &r, m, &parts);
        print_meta_table(stdout, &m->meta);
    }
    if (tool_flush_stdout(t)) {
        rc = TOOL_EXIT_FAIL;
        goto done;
    }
    /* The report is the result; what is wrong with the mesh is also said
     * where a script's user sees it. */
    if (r.inverted)
        tool_say(t, 1, "%s: warning: %zu inverted tet%s", name, r.inverted,
                 r.inverted == 1 ? "" : "s");
    if (r.degenerate)
        tool_say(t, 1, "%s: warning: %zu degenerate (flat) tet%s", name,
                 r.degenerate, r.degenerate == 1 ? "" : "s");
    if (r.nonmanifold_faces)
        tool_say(t, 1, "%s: warning: not conforming: %zu faces shared by "
                 "more than two tets", name, r.nonmanifold_faces);
    if (r.has_surface && r.has_enclosure && !r.encloses &&
        !strcmp(enclosure_word(&r), "unverified"))
        tool_say(t, 1, "%s: warning: enclosure of %s unverified: no vertex outside and "
                 "no triangle crossing, but the mesh has inverted or flat tets or is not "
                 "conforming", name, sname);
    else if (r.has_surface && r.has_enclosure && !r.encloses)
        tool_say(t, 1,
                 "%s: warning: does not enclose %s: %zu of %zu vertices "
                 "outside, %zu triangles crossing the boundary",
                 name, sname, r.surface_vertices - r.vertices_inside,
                 r.surface_vertices, r.crossing_triangles);
    if (s->offset > 0.0 && !r.has_h)
        tool_say(t, 1, "%s: warning: no cell width h in the mesh (meta \"h\"): "
                 "--offset not reported", name);
    if (r.has_fill && r.has_offset && r.beyond_offset_fill)
        tool_say(t, 1, "%s: warning: %zu boundary vertices farther than %.3g h from %s "
                 "and the fill of %s (up to %.4g h)", name, r.beyond_offset_fill,
                 r.offset_ratio, sname, fname, r.fill_dist_max / r.h);
    else if (!r.has_fill && r.has_surface && r.has_offset && r.beyond_offset)
        tool_say(t, 1, "%s: warning: %zu boundary vertices farther than %.3g h from %s "
                 "(up to %.4g h)", name, r.beyond_offset, r.offset_ratio, sname,
                 r.dist_max / r.h);
    rc = TOOL_EXIT_OK;
    goto done;
failed:
    rc = tool_fail_file(t, &err, name);
done:
    st_parts_tag_stats_free(&parts);
    st_tetmesh_free(m);
    st_soup_free(soup);
    st_grid_free(g);
    return rc;
}

static const tool_spec spec = {"tetstat", usage, ":S:F:qv", longopts, option, check, run};

int main(int argc, char *argv[])
{
    tetstat_settings s = {.offset = 0.0};   /* 0: the mesh's offset_ratio */
    return tool_main(&spec, argc, argv, &s, &s.co);
}
