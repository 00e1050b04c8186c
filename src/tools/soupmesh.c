/*
 * soupmesh - a triangle soup in, a coarse high-quality tet mesh that
 * encloses it out: distance, signs, sculpted BCC lattices with bomb
 * repair, the enclosing fit and the quality pass, best of N candidates.
 *
 *   soupmesh INPUT [-o OUT] [--cells N] [--offset R] [--tries K] [--seed S]
 *            [--density RHO] [--threads T]
 *
 * See man/man1/soupmesh.1 and pipeline.h.
 */
#define _GNU_SOURCE
#include "../cli/tool.h"
#include "souptet/embed.h"
#include "souptet/lattice.h"
#include "souptet/mem.h"
#include "souptet/outfile.h"
#include "souptet/parts.h"
#include "souptet/pipeline.h"
#include "souptet/soup.h"
#include "souptet/soupinfo.h"
#include "souptet/soupwrite.h"
#include "souptet/tetformat.h"
#include "souptet/tetio.h"
#include "souptet/tetstat.h"

#include <getopt.h>
#include <inttypes.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#ifdef _OPENMP
#include <omp.h>
#endif

static void usage(void)
{
    printf(
"Usage: soupmesh [OPTION]... [INPUT]\n"
"Mesh a triangle soup (any orientation, holes, interpenetrating parts) into a\n"
"coarse tetrahedral mesh that encloses it, with dihedral angles far from 0 and\n"
"180 degrees (Stuart et al. 2013 on the pseudo volume of Spillmann et al. 2006).\n"
"\n"
"INPUT is a surface: .obj .off .ply .stl .gltf .glb; '-' or none reads stdin\n"
"(format sniffed).\n"
"\n"
"  -o, --output OUT     the mesh, by extension: .vtu (VTK), .msh (Gmsh), .node/.ele\n"
"                       (TetGen), .mesh (Medit); '-' or none: .vtu on stdout\n"
TOOL_HELP_TETFORMAT
"      --embed FILE     where each input vertex lies: its tet and barycentric\n"
"                       coordinates, as text (.txt) or a point cloud (.vtu with\n"
"                       point arrays embed_tet, embed_bary)\n"
"      --boundary FILE  also write the mesh's boundary surface (closed, normals\n"
"                       outward; a collision proxy) as .obj, .off, .ply or .stl\n"
"                       (.stl holds floats: it turns on --float32)\n"
"      --float32        round the mesh's points to float32 values (outward on the\n"
"                       boundary, pushed further when needed) so that it still\n"
"                       encloses the input once stored as float (Blender, glTF,\n"
"                       STL, game engines), checked exactly\n"
"      --parts MODE     tag each tet with the input's part it mostly covers\n"
"                       (cell data part and part_share, a .msh group and a\n"
"                       .mesh reference per part): names (OBJ objects or\n"
"                       groups, glTF mesh nodes, STL solids), pieces (the\n"
"                       edge-connected pieces), auto (names where the file\n"
"                       has them, else pieces) or none (default none)\n"
"      --cells N        BCC lattice cells along the longest side of the\n"
"                       model's box (default 10; more cells, more tets)\n"
"      --size H         the lattice cell width in model units, instead of\n"
"                       --cells (as latticetet --size)\n"
"      --tets N         choose the cell width for about N tets (within 20%%;\n"
"                       --cells or --size give the first guess)\n"
"      --json           a summary of the run on stdout as JSON (needs -o FILE),\n"
"                       or of --dry-run's estimate\n"
"      --dry-run        print the cell width h, the estimated tets, memory\n"
"                       and the run's seconds (from a measured sculpt and the\n"
"                       threads), then exit (the field and signs are\n"
"                       computed, the fit is not)\n"
"      --offset R       stop fitting when every boundary vertex is within\n"
"                       R * h of the surface (h = cell width; default 0.4);\n"
"                       when some vertex stays farther: a message (even\n"
"                       with -q) and exit status 4\n"
"      --offset-best-effort  keep a mesh that misses --offset with exit\n"
"                       status 0 and a warning\n"
"      --offset-fill on|off  on (default): where the soup has no surface,\n"
"                       the pseudo volume's boundary (its fill) counts as\n"
"                       surface for --offset; off: the soup alone\n"
"      --tries K        candidates with randomly rotated and offset lattices,\n"
"                       at most, two at a time in parallel; the best\n"
"                       enclosing one is kept; no more start once one meets\n"
"                       every goal (encloses, --offset, dihedral 35..133)\n"
"                       (default 1)\n"
"      --try-all        run all --tries candidates even then\n"
"      --seed S         seed of the first candidate's lattice (default 1;\n"
"                       0: the axis-aligned lattice)\n"
"      --density RHO    the Spillmann mesher instead: cubic lattice tets with\n"
"                       pseudo-volume density >= RHO, boundary faired (does\n"
"                       not enclose)\n"
"  -r, --voxels N       voxels along the longest side of the distance field\n"
"                       (default 16 * cells up to 128, 8 * cells beyond:\n"
"                       max(8 * cells, min(16 * cells, 128)); as soupdist -r)\n"
"      --max-iters N    fit iterations at most (default 300)\n"
"      --fill-holes on|off  cap the soup's holes for its pseudo volume\n"
"                       (loops of boundary edges, when small beside the\n"
"                       surface around them; default on)\n"
"      --shells on|off  the soup's closed pieces (every edge shared by two\n"
"                       faces) bound their solid exactly (default on)\n"
"      --symmetry on|off  fill holes from the soup's symmetries, as soupsign\n"
"                       --symmetry (default on)\n"
"      --no-quality     skip the quality pass after the fit\n"
"      --threads T      threads to use (default: all cores)\n"
"      --max-memory SZ  refuse fields and lattices larger than SZ\n"
"                       (default 80%% of RAM)\n"
"  -q, --quiet          no messages but errors\n"
"  -v, --verbose        report every candidate, the timings and any guessed\n"
"                       part of the solid (said without -v past a cell),\n"
"                       the symmetries the signs searched (or why not)\n"
"  -h, --help           show this help and exit\n"
"  -V, --version        show the version and commit and exit\n"
"\n"
"Examples:\n"
"  soupmesh -o bunny.vtu bunny.obj\n"
"  soupmesh --cells 14 --tries 8 -o scan.vtu scan.ply && tetstat --surface scan.ply scan.vtu\n"
"\n"
"Exit status: 0 ok, 1 bad input or failure, 2 usage error, 3 the mesh was\n"
"written but does not enclose the input, 4 the mesh was written and encloses\n"
"the input but some boundary vertex is farther than --offset R * h from it.\n");
}

enum { OPT_CELLS = TOOL_OPT_FIRST, OPT_OFFSET, OPT_TRIES, OPT_TRY_ALL, OPT_SEED, OPT_DENSITY,
       OPT_FIELD_CELLS_OLD, OPT_MAX_ITERS, OPT_NO_QUALITY, OPT_EMBED, OPT_TETS, OPT_DRY_RUN,
       OPT_BOUNDARY, OPT_BEST_EFFORT, OPT_OFFSET_FILL, OPT_FLOAT32, OPT_PARTS, OPT_SIZE,
       OPT_JSON };

/* -v: a line as each stage, sculpt, fit iteration and candidate ends, so a
 * long run is never silent (pipeline.h, st_pipeline_event). */
static void on_event(void *ctx, const st_pipeline_event *ev)
{
    const tool_ctx *t = ctx;
    if (strcmp(ev->what, "field") == 0)
        tool_say(t, 2, "field %zux%zux%zu, voxel %.6g: distance and signs %.3f s",
                 ev->field_dims[0], ev->field_dims[1], ev->field_dims[2], ev->voxel,
                 ev->seconds);
    else if (strcmp(ev->what, "size") == 0)
        tool_say(t, 2, "size: h %.6g sculpts %zu tets", ev->h, ev->tets);
    else if (strcmp(ev->what, "sculpted") == 0)
        tool_say(t, 2, "candidate %zu: %zu tets sculpted at h %.6g, %.2f s", ev->k,
                 ev->tets, ev->h, ev->seconds);
    else if (strcmp(ev->what, "iteration") == 0)
        tool_say(t, 2, "candidate %zu: %s %3d: %zu/%zu boundary vertices within offset "
                 "(max distance %.4g), dihedral %.2f..%.2f, %zu moved, %zu rejected, %.2f s",
                 ev->k, ev->fit->phase, ev->fit->iter, ev->fit->within_offset,
                 ev->fit->boundary_vertices, ev->fit->max_distance, ev->fit->min_dihedral,
                 ev->fit->max_dihedral, ev->fit->moved, ev->fit->rejected,
                 ev->fit->seconds);
    else if (strcmp(ev->what, "candidate") == 0)
        tool_say(t, 2, "candidate %zu: done%s", ev->k,
                 ev->candidate->failed ? " (failed)" : "");
}

/* The diagonal of the box of the points s's triangles use (infinite
 * without triangles). st_soup_bounds, not fmin and fmax: libm calls, 7 M
 * instructions of a 230 M run on fandisk.off; the box may differ from
 * theirs only in the sign of a zero, which no difference keeps. */
static double box_diagonal(const st_soup *s)
{
    double lo[3], hi[3];
    if (st_soup_bounds(s, lo, hi, NULL))
        return INFINITY;
    return sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                (hi[2] - lo[2]) * (hi[2] - lo[2]));
}

/* What the pseudo volume guessed where the input has no surface, for the
 * note: caps over holes and the far side of one-sided parts need open
 * edges; an input without any (its holes 0) had nothing capped, and the
 * guess is where the vote's solid leaves the surface, which its
 * duplicated, non-manifold or mis-oriented parts do not tell (say which
 * of those it has). */
static void guess_words(char *buf, size_t n, const st_soup *soup)
{
    st_soupinfo si;
    st_error e;
    if (st_soupinfo_compute(&si, soup, &e)) {
        snprintf(buf, n, "hole caps, a one-sided view's far side");
        return;
    }
    if (si.boundary_edges) {
        snprintf(buf, n, "caps over the input's %zu hole%s, or the far side of a "
                 "part seen from one side", si.holes, si.holes == 1 ? "" : "s");
        return;
    }
    int k = snprintf(buf, n, "the input has no holes, so nothing was capped: where the "
                     "vote's solid leaves the surface");
    const char *sep = ", which has ";
    struct { size_t v; const char *what; } c[] = {
        {si.duplicated_triangles, "duplicated triangles"},
        {si.nonmanifold_edges, "non-manifold edges"},
        {si.inconsistent_edges, "mis-oriented edges"}};
    for (size_t i = 0; i < 3 && k > 0 && (size_t)k < n; i++)
        if (c[i].v) {
            k += snprintf(buf + k, n - (size_t)k, "%s%zu %s", sep, c[i].v, c[i].what);
            sep = ", ";
        }
}

static void report(const tool_ctx *t, const st_pipeline_stats *st, size_t tries, int density)
{
    tool_say(t, 2, "field %zux%zux%zu, voxel %.6g; lattice cell h %.6g",
             st->field_dims[0], st->field_dims[1], st->field_dims[2], st->voxel, st->h);
    if (st->fill_faces)
        tool_say(t, 2, "fill: %zu voxel faces of the pseudo volume's boundary where the "
                 "input has no surface count as surface for --offset", st->fill_faces);
    tool_say(t, 2, "distance %.3f s, signs %.3f s%s, %zu candidate%s %.3f s",
             st->seconds_dist, st->seconds_sign,
             st->shells_only ? " (the closed shells' solid: no caps, vote or refinement)" : "",
             st->ncandidates, st->ncandidates == 1 ? "" : "s", st->seconds_candidates);
    for (size_t k = 0; k < st->ncandidates; k++) {
        const st_pipeline_candidate *c = &st->candidates[k];
        if (c->failed) {
            tool_say(t, 2, "candidate %zu (seed %" PRIu64 "): failed: %s", k, c->seed,
                     c->message);
            continue;
        }
        tool_say(t, 2,
                 "candidate %zu (seed %" PRIu64 "): %zu tets, dihedral %.2f..%.2f, "
                 "%s%zu outside, %zu crossing, %s%s %.2f+%.2f s%s",
                 k, c->seed, c->tets, c->min_dihedral, c->max_dihedral,
                 "", c->verts_outside, c->tris_crossing,
                 density ? "" : (c->converged ? "converged" : "not converged"),
                 density ? "" : ",", c->seconds_sculpt, c->seconds_fit,
                 k == st->best ? "  <- best" : "");
    }
    if (st->goal_met && st->ncandidates < tries)
        tool_say(t, 2, "candidate %zu met every goal (encloses, --offset, dihedral "
                 "35..133): the other %zu of --tries %zu not run (--try-all runs them)",
                 st->best, tries - st->ncandidates, tries);
}

/* The pipeline lays one lattice per candidate (pipeline.h), up to one per
 * thread at a time, and does not hold them to a memory limit: refuse here,
 * before any of them is allocated, lattices whose bound
 * (st_pipeline_lattice_bytes) is over max_bytes. Returns 1 (err set) then;
 * 0 without a limit or when the pipeline will report the soup. */
static int lattice_over_limit(const st_soup *soup, const st_pipeline_params *p,
                              size_t max_bytes, st_error *err)
{
    if (!max_bytes)
        return 0;
    double h = st_pipeline_cell_width(soup, p), tets, at_once;
    double need = st_pipeline_lattice_bytes(soup, h, p->tries, &tets, &at_once);
    if (need <= (double)max_bytes)
        return 0;
    if (p->h > 0)
        st_error_set(err, ST_ELIMIT, NULL, 0,
                     "--size %g lays lattices of up to %.0f tets (%.0f at a "
                     "time), about %.1f MiB, over the limit of %.1f MiB (use "
                     "a larger --size or fewer --tries, or raise "
                     "--max-memory)",
                     h, tets, at_once, need / 1048576.0,
                     (double)max_bytes / 1048576.0);
    else
        st_error_set(err, ST_ELIMIT, NULL, 0,
                     "--cells %zu lays lattices of up to %.0f tets (%.0f at a "
                     "time), about %.1f MiB, over the limit of %.1f MiB (use "
                     "fewer --cells or --tries, or raise --max-memory)",
                     p->cells, tets, at_once, need / 1048576.0,
                     (double)max_bytes / 1048576.0);
    return 1;
}

/* How much longer a candidate's fit and quality pass take than its
 * sculpt (the sculpted lattice's tets, the fit's iterations over them):
 * measured with soupmesh -v at the defaults on this project's 2-core
 * machine, fit+quality over sculpt: bunny 1.30/0.32 s (4.1), fandisk
 * 1.09/0.22 (5.0), elephant 3.11/0.21 (14.8); 7 put the whole runs of
 * those three at 1, 4 and 16 cells, 1 and 4 tries, at 0.43-1.01 of the
 * estimate (geometric mean 0.7), 5 centres them. The estimate rests on
 * the dry run's own measured sculpt, so a slower or faster (or busier)
 * machine scales it. */
#define DRY_RUN_FIT_PER_SCULPT 5.0

/* soupmesh --dry-run: what a run would lay, on stdout, one "key value"
 * a line. Memory: the field (floats and a sign byte per voxel, twice for
 * the sweeps) and the lattices laid at once (the bound of
 * lattice_over_limit). Time: what the dry run measured (the field, the
 * signs and its sculpt of the first candidate's lattice, or the sizing
 * sculpts of --tets, which a run repeats), plus the first batch of
 * candidates (pipeline.h: ST_PIPELINE_BATCH at a time, in waves over the
 * threads, one thread each), each taking a sculpt and
 * DRY_RUN_FIT_PER_SCULPT sculpts' worth of fit: a measured rate, not a
 * class of tet counts (which was 10x off). A run stops after the batch in
 * which a candidate meets every goal, most often the first (the bunny,
 * a holed bunny and the fandisk at --tries 4 to 8 all stopped there), so
 * that is the estimate; seconds_all_batches is the run's time if every
 * batch runs (--try-all, or no candidate meets the goals). */
static int dry_run_report(tool_ctx *t, const st_soup *soup, const st_pipeline_params *p,
                          const st_pipeline_stats *st, int json)
{
    double lo[3], hi[3];
    st_error e;
    st_soup_bounds(soup, lo, hi, &e);   /* the run got here: it has bounds */
    double lattice = st_pipeline_lattice_bytes(soup, st->h, p->tries, NULL, NULL);
    double field = (double)st->field_dims[0] * (double)st->field_dims[1] *
                   (double)st->field_dims[2] * 2.0 * (sizeof(float) + 1);
    size_t threads = 1;
#ifdef _OPENMP
    threads = (size_t)omp_get_max_threads();
#endif
    const size_t batch = p->tries < ST_PIPELINE_BATCH ? p->tries : ST_PIPELINE_BATCH;
    size_t at_once = batch < threads ? batch : threads;
    double waves = ceil((double)batch / (double)(at_once ? at_once : 1));
    double batches = ceil((double)p->tries / (double)(batch ? batch : 1));
    double sculpt = st->sculpts ? st->seconds_size / (double)st->sculpts : 0.0;
    double before = st->seconds_total - (p->target_tets ? 0.0 : st->seconds_size);
    double one = waves * sculpt * (1.0 + DRY_RUN_FIT_PER_SCULPT);
    double all = before + batches * one;
    double seconds = p->try_all ? all : before + one;
    const char *cls = seconds < 60 ? "seconds" : seconds < 3600 ? "minutes" : "hours";
    double cells = ceil(st_lattice_h_for_cells(lo, hi, 1) / st->h);
    double mib = (lattice + field) / 1048576.0;
    if (json) {
        char n[2][32];
        printf("{\"h\": %s, \"cells\": %.0f, \"estimated_tets\": %zu, \"memory_mib\": %.1f, "
               "\"seconds\": %.1f, \"seconds_all_batches\": %.1f, \"batches\": %.0f, "
               "\"threads\": %zu, \"time\": \"%s\"}\n",
               tool_json_number(n[0], st->h), cells, st->estimated_tets, mib, seconds, all,
               batches, threads, cls);
    } else {
        printf("h %.17g\ncells %.0f\nestimated_tets %zu\nmemory_mib %.1f\nseconds %.1f\n"
               "seconds_all_batches %.1f\nbatches %.0f\nthreads %zu\ntime %s\n", st->h,
               cells, st->estimated_tets, mib, seconds, all, batches, threads, cls);
    }
    return tool_flush_stdout(t) ? TOOL_EXIT_FAIL : TOOL_EXIT_OK;
}

/* What --parts found in the input, and what it handled on the way. */
static void say_parts(tool_ctx *t, const char *in_name, const st_parts *p)
{
    tool_say(t, 1, "%zu part%s (%s)", p->nparts, p->nparts == 1 ? "" : "s",
             st_parts_mode_name(p->mode));
    if (p->empty)
        tool_say(t, 1, "%s: warning: %zu named part%s without faces skipped (first: '%s')",
                 in_name, p->empty, p->empty == 1 ? "" : "s", p->first_empty);
    if (p->unnamed)
        tool_say(t, 1, "%s: warning: %zu part%s without a name, named part_K by index",
                 in_name, p->unnamed, p->unnamed == 1 ? "" : "s");
    if (p->not_utf8)
        tool_say(t, 1, "%s: warning: %zu part name%s not UTF-8, named part_K by index",
                 in_name, p->not_utf8, p->not_utf8 == 1 ? "" : "s");
    if (p->duplicates)
        tool_say(t, 1, "%s: warning: %zu part name%s given twice, suffixed _2, _3, ...",
                 in_name, p->duplicates, p->duplicates == 1 ? "" : "s");
    for (size_t k = 0; k < p->nparts; k++)
        tool_say(t, 2, "part %zu '%s': %zu triangles", k, p->names[k], p->tris_of[k]);
}

/* Per part: the tets tagged, their volume, and the part's pseudo volume. */
static void report_parts(tool_ctx *t, const st_parts *p, const st_parts_tag_stats *ps)
{
    for (size_t k = 0; k < ps->nparts && k < p->nparts; k++)
        tool_say(t, 2, "part %zu '%s': %zu tets, volume %.6g (its pseudo volume %.6g)", k,
                 p->names[k], ps->tets[k], ps->volume[k], ps->pseudo_volume[k]);
    if (ps->uncovered)
        tool_say(t, 2, "%zu tets cover no part (the margin): the nearest part's",
                 ps->uncovered);
}

/* Each input vertex's part on the --embed point cloud: the part of the
 * first triangle using it (-1 for a vertex no triangle uses). */
static st_status embed_parts(st_tetmesh *side, const st_soup *soup, const st_parts *p,
                             st_error *err)
{
    double *v = NULL;
    st_status st = st_tetmesh_add_array(side, "part", ST_ON_POINTS, 1, &v, err);
    if (st)
        return st;
    for (size_t i = 0; i < soup->nverts; i++)
        v[i] = -1;
    for (size_t k = soup->ntris; k-- > 0;)
        for (int c = 0; c < 3; c++)
            v[soup->tris[3 * k + c]] = p->tri_part[k];
    return ST_OK;
}

/* What the command line asks for. */
typedef struct soupmesh_settings {
    tool_common co;
    st_pipeline_params pipeline;
    const char *in, *embed, *boundary;
    int have_cells, best_effort, json;
    int float32_by_stl;        /* --boundary .stl turned --float32 on */
    int embed_text;            /* --embed FILE.txt, else .vtu */
    st_soup_format boundary_format;
    int parts_mode;            /* --parts (st_parts_mode) */
} soupmesh_settings;

static const struct option longopts[] = {
    {"cells", required_argument, NULL, OPT_CELLS},
    {"size", required_argument, NULL, OPT_SIZE},
    {"tets", required_argument, NULL, OPT_TETS},
    {"dry-run", no_argument, NULL, OPT_DRY_RUN},
    {"json", no_argument, NULL, OPT_JSON},
    {"offset", required_argument, NULL, OPT_OFFSET},
    {"offset-best-effort", no_argument, NULL, OPT_BEST_EFFORT},
    {"offset-fill", required_argument, NULL, OPT_OFFSET_FILL},
    {"tries", required_argument, NULL, OPT_TRIES},
    {"try-all", no_argument, NULL, OPT_TRY_ALL},
    {"seed", required_argument, NULL, OPT_SEED},
    {"density", required_argument, NULL, OPT_DENSITY},
    {"voxels", required_argument, NULL, 'r'},
    {"field-cells", required_argument, NULL, OPT_FIELD_CELLS_OLD},
    {"max-iters", required_argument, NULL, OPT_MAX_ITERS},
    {"no-quality", no_argument, NULL, OPT_NO_QUALITY},
    TOOL_LONG_OPTIONS_PSEUDO,
    TOOL_LONG_OPTIONS_TETFORMAT,
    {"embed", required_argument, NULL, OPT_EMBED},
    {"boundary", required_argument, NULL, OPT_BOUNDARY},
    {"float32", no_argument, NULL, OPT_FLOAT32},
    {"parts", required_argument, NULL, OPT_PARTS},
    TOOL_LONG_OPTIONS_OUTPUT,
    TOOL_LONG_OPTIONS_END};

static int option(tool_ctx *t, int c, const char *arg, void *settings)
{
    soupmesh_settings *s = settings;
    size_t n;
    switch (c) {
    case OPT_CELLS:
        if (tool_parse_size(t, "--cells", arg, 1, ST_PIPELINE_MAX_CELLS, &s->pipeline.cells))
            return TOOL_EXIT_USAGE;
        s->have_cells = 1;
        break;
    case OPT_SIZE:
        if (tool_parse_double(t, "--size", arg, 1e-300, 1e300, &s->pipeline.h))
            return TOOL_EXIT_USAGE;
        break;
    case OPT_TETS:
        if (tool_parse_size(t, "--tets", arg, 10, 100000000, &s->pipeline.target_tets))
            return TOOL_EXIT_USAGE;
        break;
    case OPT_DRY_RUN:
        s->pipeline.dry_run = 1;
        break;
    case OPT_JSON:
        s->json = 1;
        break;
    case OPT_OFFSET:
        if (tool_parse_double(t, "--offset", arg, 1e-3, 10.0, &s->pipeline.offset_ratio))
            return TOOL_EXIT_USAGE;
        break;
    case OPT_BEST_EFFORT:
        s->best_effort = 1;
        break;
    case OPT_TRIES:
        if (tool_parse_size(t, "--tries", arg, 1, ST_PIPELINE_MAX_TRIES, &s->pipeline.tries))
            return TOOL_EXIT_USAGE;
        break;
    case OPT_TRY_ALL:
        s->pipeline.try_all = 1;
        break;
    case OPT_SEED:
        if (tool_parse_size(t, "--seed", arg, 0, SIZE_MAX, &n))
            return TOOL_EXIT_USAGE;
        s->pipeline.seed = (uint64_t)n;
        break;
    case OPT_DENSITY:
        if (tool_parse_double(t, "--density", arg, 1e-6, 1.0, &s->pipeline.density_rho))
            return TOOL_EXIT_USAGE;
        break;
    case OPT_FIELD_CELLS_OLD:
        tool_deprecated(t, "--field-cells", "--voxels (-r)");
        /* fall through */
    case 'r':
        if (tool_parse_size(t, c == 'r' ? "--voxels" : "--field-cells", arg, 8, 4096,
                            &s->pipeline.field_cells))
            return TOOL_EXIT_USAGE;
        break;
    case OPT_MAX_ITERS:
        if (tool_parse_size(t, "--max-iters", arg, 1, 100000, &n))
            return TOOL_EXIT_USAGE;
        s->pipeline.fit_max_iters = (int)n;
        break;
    case OPT_NO_QUALITY:
        s->pipeline.quality = 0;
        break;
    case OPT_OFFSET_FILL:
        if (tool_parse_switch(t, "--offset-fill", arg, &s->pipeline.fill_counts))
            return TOOL_EXIT_USAGE;
        break;
    case TOOL_OPT_FILL_HOLES:
    case TOOL_OPT_SHELLS:
    case TOOL_OPT_SYMMETRY:
        return tool_pseudo_option(t, c, arg,
                                  &(tool_pseudo_switches){&s->pipeline.fill_holes,
                                                          &s->pipeline.closed_shells,
                                                          &s->pipeline.symmetry});
    case OPT_EMBED:
        s->embed = arg;
        break;
    case OPT_BOUNDARY:
        s->boundary = arg;
        break;
    case OPT_FLOAT32:
        s->pipeline.float32 = 1;
        break;
    case OPT_PARTS:
        if ((s->parts_mode = st_parts_mode_from_name(arg)) < 0)
            return tool_usage_error(t, "--parts is auto, names, pieces or none, not '%s'", arg);
        break;
    }
    return TOOL_CONTINUE;
}

static int check(tool_ctx *t, int argc, char *argv[], void *settings)
{
    soupmesh_settings *s = settings;
    const st_pipeline_params *p = &s->pipeline;
    if (s->have_cells && p->h > 0)
        return tool_usage_error(t, "--cells and --size exclude each other");
    if (p->density_rho > 0 && (p->target_tets || p->dry_run))
        return tool_usage_error(t, "--tets and --dry-run size the sculpted mesh, "
                                   "not --density's");
    TOOL_TRY(tool_one_input(t, argc, argv, "input surface", NULL, &s->in));
    /* No INPUT reads stdin, as in every tool; on a terminal, where a user
     * has forgotten it, say how to give one. */
    if (!s->in && isatty(STDIN_FILENO))
        return tool_usage_error(t, "no input surface (soupmesh -o out.vtu model.obj)");
    if (!s->in)
        s->in = "-";
    TOOL_TRY(tool_refuse_terminal(t, s->in, STDIN_FILENO,
                                  "will not read a surface from a terminal: give a file"));
    if (s->co.out && st_soup_format_from_path(s->co.out) != ST_SOUP_GLTF) {
        char hint[600];
        snprintf(hint, sizeof hint, "use --boundary %.500s for the cage's surface", s->co.out);
        TOOL_TRY(tool_surface_as_tetmesh(t, s->co.out, hint));
    }
    TOOL_TRY(tool_tetmesh_output(t, s->co.out, p->dry_run ? NULL : TOOL_TTY_VTU));
    if (s->json && !p->dry_run && st_path_is_stdio(s->co.out))
        return tool_usage_error(t, "--json prints on stdout: give the mesh -o FILE");
    const char *embed = s->embed, *boundary = s->boundary;
    size_t elen = embed ? strlen(embed) : 0;
    s->embed_text = elen > 4 && strcmp(embed + elen - 4, ".txt") == 0;
    if (embed && !s->embed_text && !(elen > 4 && strcmp(embed + elen - 4, ".vtu") == 0))
        return tool_usage_error(t, "--embed writes .txt or .vtu, not '%s'", embed);
    s->boundary_format = boundary ? st_soup_format_from_path(boundary) : ST_SOUP_UNKNOWN;
    if (boundary && (st_path_is_stdio(boundary) || s->boundary_format == ST_SOUP_UNKNOWN ||
                     s->boundary_format == ST_SOUP_GLTF))
        return tool_usage_error(t, "--boundary writes .obj, .off, .ply or .stl, not '%s'",
                                boundary);
    if (boundary && p->density_rho > 0)
        return tool_usage_error(t, "--boundary goes with the enclosing mesh, not --density");
    /* Binary STL holds floats: the surface written there must enclose
     * the input as floats, so the mesh it bounds is rounded (--float32). */
    if (boundary && s->boundary_format == ST_SOUP_STL) {
        s->float32_by_stl = !s->pipeline.float32;
        s->pipeline.float32 = 1;
    }
    if (tool_output_unwritable(t, s->co.out) || tool_output_unwritable(t, embed) ||
        tool_output_unwritable(t, boundary))
        return TOOL_EXIT_FAIL;
    s->pipeline.max_bytes = s->co.max_bytes;
    return TOOL_CONTINUE;
}

/* soupmesh --json: the run's summary on stdout, one JSON object (the keys
 * as soupmesh.1 lists them; numbers in model units unless named _h, in
 * cell widths h). */
static void print_json(const soupmesh_settings *s, const st_pipeline_stats *st,
                       int rc, double seconds)
{
    const st_pipeline_params *p = &s->pipeline;
    const st_pipeline_candidate *b = &st->candidates[st->best];
    char n[12][32];
    printf("{\"tool\": \"soupmesh\", \"version\": ");
    tool_json_string(stdout, tool_version());
    printf(", \"commit\": ");
    tool_json_string(stdout, tool_commit());
    printf(",\n  \"input\": ");
    tool_json_string(stdout, tool_in_name(s->in));
    printf(", \"output\": ");
    tool_json_string(stdout, tool_out_name(s->co.out));
    printf(",\n  \"h\": %s, \"voxels\": [%zu, %zu, %zu], \"voxel\": %s, \"offset\": %s, "
           "\"candidates\": %zu, \"best\": %zu, \"seed\": %" PRIu64 ",\n",
           tool_json_number(n[0], st->h), st->field_dims[0], st->field_dims[1],
           st->field_dims[2], tool_json_number(n[1], st->voxel),
           tool_json_number(n[2], p->offset_ratio), st->ncandidates, st->best, b->seed);
    printf("  \"tets\": %zu, \"points\": %zu, \"min_dihedral\": %s, \"max_dihedral\": %s,\n"
           "  \"encloses\": %s, \"vertices_outside\": %zu, \"triangles_crossing\": %zu,\n",
           b->tets, b->points, tool_json_number(n[3], b->min_dihedral),
           tool_json_number(n[4], b->max_dihedral), st->encloses ? "true" : "false",
           b->verts_outside, b->tris_crossing);
    if (p->density_rho > 0)
        printf("  \"offset_met\": null, \"beyond_offset\": null, \"boundary_vertices\": null, "
               "\"max_distance_h\": null, \"measured_against\": null,\n");
    else
        printf("  \"offset_met\": %s, \"beyond_offset\": %zu, \"boundary_vertices\": %zu, "
               "\"max_distance_h\": %s, \"measured_against\": \"%s\",\n",
               b->converged ? "true" : "false", b->beyond_offset, b->boundary_vertices,
               tool_json_number(n[5], b->max_distance / st->h),
               st->fill_faces ? "input and fill" : "input");
    double share = st->guess.boundary_faces
                       ? (double)st->guess.fill_faces / (double)st->guess.boundary_faces : 0.0;
    double sym = st->guess.boundary_faces
                     ? (double)st->guess.symmetric_faces / (double)st->guess.boundary_faces : 0.0;
    printf("  \"guessed_share\": %s, \"guessed_symmetric_share\": %s, "
           "\"guessed_depth_h\": %s,\n  \"seconds\": %s, \"exit_status\": %d}\n",
           tool_json_number(n[6], share), tool_json_number(n[9], sym),
           tool_json_number(n[7], st->guess.depth / st->h), tool_json_number(n[8], seconds),
           rc);
}

/* What --float32's rounding did (-v), and a note when the input itself is
 * not float32. */
static void report_float32(const tool_ctx *t, const soupmesh_settings *s,
                           const st_pipeline_stats *st, const st_tetmesh *m)
{
    const st_float32_stats *f = &st->float32;
    tool_say(t, 2, "float32%s: %zu of %zu points moved (%zu on the boundary, %zu of "
             "them pushed, up to %u ulps further out), the farthest by %.3g (%.3g h); "
             "%d exact check%s, %.3f s: %s (%zu vertices outside, %zu triangles "
             "crossing, %zu inverted tets)",
             s->float32_by_stl ? " (for the .stl boundary)" : "", f->points_moved,
             m->npoints, f->boundary_points, f->pushed, f->max_push, f->max_move,
             f->max_move / st->h, f->rounds, f->rounds == 1 ? "" : "s", f->seconds,
             f->encloses ? "encloses the input" : "DOES NOT enclose the input",
             f->verts_outside, f->tris_crossing, f->inverted);
    if (f->input_not_float32)
        tool_say(t, 1, "note: %zu input vertices are not float32 values: the mesh "
                 "in float32 encloses the input as given (in double); rounding the "
                 "input too moves it by up to half a float ulp", f->input_not_float32);
}

/* The note on the guessed part of the solid (pseudo.h's fill), if any. */
static void say_guess(const tool_ctx *t, const st_pipeline_stats *st, const st_soup *soup,
                      double diag)
{
    if (!st->guess.fill_faces)
        return;
    /* The solid where the input has no surface is the pseudo volume's
     * guess: said by default when it reaches past a lattice cell from
     * the input, where the mesh resolves it (its volume, a
     * simulation's mass, rest on it), naming what was guessed. */
    const double depth_h = st->guess.depth / st->h;
    char what[200], sym[120] = "";
    guess_words(what, sizeof what, soup);
    /* the symmetric fill apart from the caps (issue 37) */
    if (st->guess.symmetric_faces)
        snprintf(sym, sizeof sym, "; %.1f%% from the input's own symmetric copy, the "
                 "rest %.1f%%",
                 100.0 * (double)st->guess.symmetric_faces / (double)st->guess.boundary_faces,
                 100.0 * (double)(st->guess.fill_faces - st->guess.symmetric_faces) /
                     (double)st->guess.boundary_faces);
    tool_say(t, depth_h > 1.0 ? 1 : 2,
             "note: %.1f%% of the solid's boundary is not on the input but guessed "
             "(%s%s), up to %.2f h (%.3f of the diagonal) from it; the mesh's volume "
             "there rests on that guess",
             100.0 * (double)st->guess.fill_faces / (double)st->guess.boundary_faces,
             what, sym, depth_h, st->guess.depth / diag);
}

/* The exit status of a run that wrote its mesh: not enclosing (level 0,
 * even with -q), Cetra's stopping condition missed (level 0 unless
 * --offset-best-effort), else OK. */
static int exit_status(const tool_ctx *t, const soupmesh_settings *s,
                       const st_pipeline_stats *st, const char *in_name)
{
    const st_pipeline_params *p = &s->pipeline;
    const char *out = s->co.out;
    const st_pipeline_candidate *b = &st->candidates[st->best];
    int rc = TOOL_EXIT_OK;
    if (!st->encloses && p->density_rho <= 0) {
        /* Level 0: printed even with -q, and the exit status says it. */
        if (p->float32 && st->float32.inverted)
            tool_say(t, 0, "%s: error: the mesh written to %s has %zu inverted tets once "
                     "rounded to float32 (--float32)", in_name, tool_out_name(out),
                     st->float32.inverted);
        tool_say(t, 0, "%s: error: the mesh written to %s does not enclose the input%s "
                 "(%zu vertices outside, %zu triangles crossing; best of %zu candidates); "
                 "try more --cells or --tries", in_name, tool_out_name(out),
                 p->float32 ? " once rounded to float32" : "",
                 b->verts_outside, b->tris_crossing, st->ncandidates);
        rc = TOOL_EXIT_NOT_ENCLOSING;
    }
    if (p->density_rho <= 0 && !b->converged) {
        /* Cetra's stopping condition (every boundary vertex within
         * R h of the input) is the fit's promise: said at level 0 and in
         * the exit status unless the user settles for less. */
        tool_say(t, s->best_effort ? 1 : 0,
                 "%s: %s: %zu of %zu boundary vertices stay farther than %.3g h from the "
                 "input%s, the farthest %.4g h (%.4g); best of %zu candidates%s",
                 in_name, s->best_effort ? "warning" : "error",
                 b->beyond_offset, b->boundary_vertices, p->offset_ratio,
                 st->fill_faces ? " or its fill" : "", b->max_distance / st->h, b->max_distance, st->ncandidates,
                 s->best_effort ? "" : "; try more --tries or --cells, or --offset-best-effort");
        if (!s->best_effort && rc == TOOL_EXIT_OK)
            rc = TOOL_EXIT_OFFSET_NOT_MET;
    }
    return rc;
}

/* What run makes on its way, freed at its end. */
typedef struct soupmesh_run {
    soupmesh_settings *s;
    const char *in_name;
    st_soup *soup;
    st_tetmesh *m;
    st_pipeline_stats st;
    st_parts parts;
    int64_t *et;           /* --embed: each input vertex's tet */
    double *eb;            /* and its barycentric coordinates */
    size_t nout;           /* input vertices in no tet */
    int64_t first;         /* the first of them */
    st_tetmesh *side;      /* --embed .vtu: the point cloud */
    st_soup *bsoup;        /* --boundary: the mesh's boundary */
    st_outfile bof;        /* and its file, renamed after the mesh */
} soupmesh_run;

/* The soup read, the memory check, --parts, the pipeline. 0, or the exit
 * status after an error was printed. */
static int make_mesh(tool_ctx *t, soupmesh_run *R, st_error *err)
{
    soupmesh_settings *s = R->s;
    const st_pipeline_params *p = &s->pipeline;
    if (st_soup_read(&R->soup, s->in, err))
        return tool_fail(t, err);
    tool_say(t, 2, "%s: %zu vertices, %zu triangles", s->in, R->soup->nverts,
             R->soup->ntris);
    if (lattice_over_limit(R->soup, p, s->co.max_bytes, err))
        return tool_fail_file(t, err, R->in_name);
    if (s->parts_mode != ST_PARTS_NONE) {
        if (st_parts_split(&R->parts, R->soup, (st_parts_mode)s->parts_mode, err))
            return tool_fail_file(t, err, R->in_name);
        say_parts(t, R->in_name, &R->parts);
        s->pipeline.parts = &R->parts;
    }
    st_progress prog = tool_progress(t);
    if (st_pipeline_run(&R->m, &R->st, R->soup, p, &prog, err)) {
        tool_progress_end(t);
        if (!err->file[0])
            snprintf(err->file, sizeof err->file, "%s", R->in_name);
        tool_limit_hint(err, "use fewer --cells or --voxels, or raise --max-memory");
        report(t, &R->st, p->tries, p->density_rho > 0);
        return tool_fail(t, err);
    }
    tool_progress_end(t);
    return 0;
}

/* --embed: where the input vertices lie, worked out before anything is
 * written, so a failure there leaves no mesh behind either. */
static int embed_mesh(tool_ctx *t, soupmesh_run *R, st_error *err)
{
    const st_soup *soup = R->soup;
    R->et = st_malloc_array(soup->nverts ? soup->nverts : 1, sizeof *R->et);
    R->eb = st_malloc_array(soup->nverts ? soup->nverts : 1, 4 * sizeof *R->eb);
    if (!R->et || !R->eb)
        return tool_fail_nomem(t, err);
    if (st_embed_compute(R->et, R->eb, &R->nout, &R->first, R->m, soup, err) ||
        (!R->s->embed_text &&
         st_embed_to_tetmesh(&R->side, soup->xyz, R->et, R->eb, soup->nverts, err)) ||
        (R->side && R->s->pipeline.parts && embed_parts(R->side, soup, &R->parts, err)))
        return tool_fail(t, err);
    return 0;
}

/* --boundary: the boundary surface written to its temporary file before
 * the mesh is saved (and renamed into place after it), so a failure on
 * either side leaves neither half-done. */
static int begin_boundary(tool_ctx *t, soupmesh_run *R, st_error *err)
{
    const soupmesh_settings *s = R->s;
    const char *cmd = tool_command(t);
    size_t n = strlen(cmd) + strlen(s->in) + 64;
    char *comment = malloc(n);
    if (!comment)
        return tool_fail_nomem(t, err);
    snprintf(comment, n, "souptet soupmesh: the boundary of the mesh; source: %s\n%s",
             R->in_name, cmd);
    st_status bs = st_tetmesh_boundary_soup(&R->bsoup, R->m, err);
    if (!bs && !(bs = st_outfile_begin(&R->bof, s->boundary, 1, err)))
        bs = st_soup_write(R->bof.fp, R->bsoup, s->boundary_format, comment, s->boundary,
                           err);
    free(comment);
    return bs ? tool_fail(t, err) : 0;
}

/* The mesh, the boundary renamed after it, the --embed file. */
static int write_outputs(tool_ctx *t, soupmesh_run *R, st_error *err)
{
    const soupmesh_settings *s = R->s;
    if (st_tetmesh_save(R->m, s->co.out, &s->co.tetformat, err))
        return tool_fail(t, err);
    if (s->boundary && st_outfile_commit(&R->bof, err))
        return tool_fail(t, err);
    if (s->embed) {
        if (s->embed_text
                ? st_embed_write_text(s->embed, R->et, R->eb, R->soup->nverts, R->m->ntets,
                                      tool_out_name(s->co.out), s->in, err)
                : st_tetmesh_save(R->side, s->embed, NULL, err))
            return tool_fail(t, err);
        if (R->nout)
            tool_say(t, 1, "warning: %zu input vertices are in no tet (first: %lld)",
                     R->nout, (long long)R->first);
    }
    return 0;
}

/* -v's symmetries: those the signs' step 2 searched, with what the fill
 * took (tool_report_symmetries), or why it did not search. No search of
 * its own: on a closed or gated soup that was a second BVH and detection
 * over every triangle after the mesh was written (12 dragons, 10M
 * triangles: about 50 s of CPU and 0.8 GB, for lines the mesh never used). */
static int say_symmetries(tool_ctx *t, const soupmesh_run *R, const st_pipeline_stats *st)
{
    if (st->symmetries.candidates > 0)
        return tool_report_symmetries(t, R->soup, NULL, st->voxel, &st->symmetries,
                                      &st->symmetry_fill, st->seconds_symmetry);
    if (!R->s->pipeline.symmetry)
        tool_say(t, 2, "symmetries: not searched (--symmetry off)");
    else if (st->symmetry_fill.caps)
        tool_say(t, 2, "symmetries: not searched by the signs (no fill could change any of "
                 "the %zu caps by a voxel, and no hole is too large to cap)",
                 st->symmetry_fill.caps);
    else
        tool_say(t, 2, "symmetries: not searched by the signs (no holes to fill)");
    return 0;
}

/* The closing line, the note on what was guessed, -v: the symmetries and
 * the distances both ways. 0, or the exit status after an error. */
static int say_result(tool_ctx *t, soupmesh_run *R, double t0, st_error *err)
{
    const st_pipeline_params *p = &R->s->pipeline;
    const st_pipeline_stats *st = &R->st;
    const st_pipeline_candidate *b = &st->candidates[st->best];
    tool_say(t, 1, "%zu tets, %zu points, dihedral %.2f..%.2f degrees, %s "
             "(%zu vertices outside, %zu triangles crossing), %.2f s",
             b->tets, b->points, b->min_dihedral, b->max_dihedral,
             st->encloses ? "encloses the input" : "DOES NOT enclose the input",
             b->verts_outside, b->tris_crossing, tool_now() - t0);
    const double diag = box_diagonal(R->soup);
    say_guess(t, st, R->soup, diag);
    int rc = say_symmetries(t, R, st);
    if (rc)
        return rc;
    if (t->verbosity >= 2 && p->density_rho <= 0) {
        /* both directions, in h and per the input's box diagonal */
        double sb = NAN;
        if (st_tetstat_surface_to_boundary(&sb, R->m, R->soup, err))
            return tool_fail(t, err);
        tool_say(t, 2, "boundary -> input%s max %.4f h (%.6f diag), input -> boundary max "
                 "%.4f h (%.6f diag); %zu of %zu boundary vertices beyond %.3g h",
                 st->fill_faces ? " or fill" : "",
                 b->max_distance / st->h, b->max_distance / diag, sb / st->h, sb / diag,
                 b->beyond_offset, b->boundary_vertices, p->offset_ratio);
    }
    return 0;
}

static int run(tool_ctx *t, void *settings)
{
    soupmesh_settings *s = settings;
    const st_pipeline_params *p = &s->pipeline;
    tool_set_threads(s->co.threads);
    if (t->verbosity >= 2) {
        s->pipeline.on_event = on_event;
        s->pipeline.on_event_ctx = t;
    }
    st_error err;
    st_error_clear(&err);
    soupmesh_run R = {.s = s, .in_name = tool_in_name(s->in), .first = -1, .bof.slot = -1};
    double t0 = tool_now();
    int rc = make_mesh(t, &R, &err);
    if (rc)
        goto done;
    if (p->dry_run) {
        rc = dry_run_report(t, R.soup, p, &R.st, s->json);
        goto done;
    }
    if (p->target_tets)
        tool_say(t, 2, "h %.6g for about %zu tets: %zu sculpts, %.2f s", R.st.h,
                 p->target_tets, R.st.sculpts, R.st.seconds_size);
    report(t, &R.st, p->tries, p->density_rho > 0);
    if (p->parts)
        report_parts(t, &R.parts, &R.st.parts);
    if (p->float32)
        report_float32(t, s, &R.st, R.m);
    if (st_meta_set(&R.m->meta, "source", R.in_name) ||
        tool_meta_record(t, &R.m->meta)) {
        rc = tool_fail_nomem(t, &err);
        goto done;
    }
    if ((s->embed && (rc = embed_mesh(t, &R, &err))) ||
        (s->boundary && (rc = begin_boundary(t, &R, &err))) ||
        (rc = write_outputs(t, &R, &err)) || (rc = say_result(t, &R, t0, &err)))
        goto done;
    rc = exit_status(t, s, &R.st, R.in_name);
    if (s->json) {
        print_json(s, &R.st, rc, tool_now() - t0);
        if (tool_flush_stdout(t))
            rc = TOOL_EXIT_FAIL;
    }
done:
    st_outfile_abort(&R.bof);
    st_soup_free(R.bsoup);
    free(R.et);
    free(R.eb);
    st_tetmesh_free(R.side);
    free(R.st.candidates);
    st_parts_tag_stats_free(&R.st.parts);
    st_parts_free(&R.parts);
    st_tetmesh_free(R.m);
    st_soup_free(R.soup);
    return rc;
}

static const tool_spec spec = {"soupmesh", usage, ":o:r:qv", longopts, option, check, run};

int main(int argc, char *argv[])
{
    soupmesh_settings s = {.pipeline = st_pipeline_params_default()};
    return tool_main(&spec, argc, argv, &s, &s.co);
}
