/*
 * tool.h - what every souptet tool's main() shares (not part of the
 * library: this is where printing and exiting happen).
 *
 * Shape of a tool (after Netpbm): parse options into a settings struct,
 * open input ("-" = stdin), one library call per stage, write output
 * through st_outfile (temporary name, renamed at the end), exit 0 ok,
 * 1 bad input or failure, 2 usage, 3 a mesh written that does not
 * enclose its surface (soupmesh, tetsmooth --fit). Messages go to stderr as
 * "tool: file:line: what".
 */
#ifndef SOUPTET_CLI_TOOL_H
#define SOUPTET_CLI_TOOL_H

#include <getopt.h>
#include <stddef.h>
#include <stdio.h>
#include "souptet/err.h"
#include "souptet/lattice.h"
#include "souptet/meta.h"
#include "souptet/progress.h"
#include "souptet/tetformat.h"

#define TOOL_EXIT_OK 0
#define TOOL_EXIT_FAIL 1
#define TOOL_EXIT_USAGE 2
/* The output was written, complete, but the mesh does not enclose the
 * surface (or that cannot be verified): a failure of the tool's promise,
 * never only a warning, and always printed (even with -q). */
#define TOOL_EXIT_NOT_ENCLOSING 3
/* The output was written and encloses, but the fit's stopping condition
 * (every boundary vertex within R h of the surface, soupmesh --offset)
 * does not hold; always printed, like 3. */
#define TOOL_EXIT_OFFSET_NOT_MET 4

typedef struct tool_ctx {
    const char *name;      /* program name for messages */
    int verbosity;         /* 0 with -q, 1 default, 2 with -v */
    char *command_line;    /* the whole command line, for history */
    double t0;             /* start time, seconds */
} tool_ctx;

/* Set up a tool: name, command line, signal handlers that remove
 * temporary outputs (SIGINT, SIGTERM, SIGHUP, SIGPIPE, SIGQUIT, SIGXCPU;
 * SIGXFSZ is ignored, so a write past ulimit -f fails with EFBIG and is
 * reported like any write error), and a check at exit that everything
 * written to stdout got there (a failed write makes the exit status 1,
 * with "name: <stdout>: write failed: why" unless an error was already
 * printed). */
void tool_init(tool_ctx *t, const char *name, int argc, char *argv[]);
void tool_finish(tool_ctx *t);

/* Print "name: FILE:LINE: msg" and return TOOL_EXIT_FAIL. */
int tool_fail(const tool_ctx *t, const st_error *err);
/* The same, naming FILE when err names no file (the library knows the
 * data, the tool knows where it came from). */
int tool_fail_file(const tool_ctx *t, st_error *err, const char *file);
/* Fail with "out of memory" (set in err). */
int tool_fail_nomem(const tool_ctx *t, st_error *err);
/* What an input or output path is called in messages: "<stdin>" or
 * "<stdout>" for "-" and NULL (st_path_is_stdio), else the path. */
const char *tool_in_name(const char *path);
const char *tool_out_name(const char *path);
/* The command line for an output's history (the tool's name when it could
 * not be put together). */
const char *tool_command(const tool_ctx *t);
/* st_soup_read, printing the reader's warnings (unless -q) as
 * "name: warning: FILE:LINE: what" and "name: warning: FILE: N more like
 * it", before any error. */
struct st_soup;
struct st_soup_source;
st_status tool_soup_read(const tool_ctx *t, struct st_soup **out,
                         const char *path, st_error *err);
/* The same, with the file's size and content hash (soup.h). */
st_status tool_soup_read_source(const tool_ctx *t, struct st_soup **out, const char *path,
                                struct st_soup_source *src, st_error *err);
/* Flush stdout (a report): 0, or after a write error now or earlier,
 * print "name: <stdout>: write failed: why" and return TOOL_EXIT_FAIL. */
int tool_flush_stdout(const tool_ctx *t);
/* A field read from NAME (a file, or "<stdin>") must hold finite values
 * only (as soupsign requires of its input): ST_OK, or ST_EINPUT with "the
 * field has N values that are not finite" naming NAME. */
struct st_grid;
st_status tool_check_field_finite(const struct st_grid *g, const char *name,
                                  st_error *err);
/* When err is a limit (ST_ELIMIT), end its message with "(hint)" naming
 * the options to change, in place of the library's own parenthesized
 * advice if it ends with one. */
void tool_limit_hint(st_error *err, const char *hint);
/* The largest cells (-r) below p->cells whose distance grid for s fits
 * p->max_bytes (its layout, 4 bytes a voxel, as st_grid_new checks); 0 when none does or p gives
 * a voxel size instead. For a refusal that names a value that fits. */
struct st_dist_params;
size_t tool_dist_cells_that_fit(const struct st_soup *s, const struct st_dist_params *p);
/* Print "name: msg" and "Try 'name --help'." and return TOOL_EXIT_USAGE. */
int tool_usage_error(const tool_ctx *t, const char *fmt, ...)
#ifdef __GNUC__
    __attribute__((format(printf, 2, 3)))
#endif
    ;
/* Print "name: msg" to stderr when verbosity >= level. */
void tool_say(const tool_ctx *t, int level, const char *fmt, ...)
#ifdef __GNUC__
    __attribute__((format(printf, 3, 4)))
#endif
    ;

/* Strict number parsing for option values: the whole string must be a
 * number within [min, max]. Return 0 ok, or print a usage error and return
 * -1. */
int tool_parse_size(const tool_ctx *t, const char *opt, const char *arg,
                    size_t min, size_t max, size_t *out);
int tool_parse_double(const tool_ctx *t, const char *opt, const char *arg,
                      double min, double max, double *out);
/* "on" (1) or "off" (0) into *out; anything else prints "OPT is on or
 * off, not 'ARG'" as a usage error and returns -1. */
int tool_parse_switch(const tool_ctx *t, const char *opt, const char *arg, int *out);
/* A byte count with an optional K, M, G or T suffix (powers of 1024). */
int tool_parse_bytes(const tool_ctx *t, const char *opt, const char *arg,
                     size_t *out);

/* The default memory limit: 80% of physical memory (0 if unknown). */
size_t tool_default_max_memory(void);

/* Before a long computation: 1 (after printing "name: PATH: cannot write
 * there: why") when the directory that would hold the output file PATH
 * does not exist or is not writable, or (after "name: PATH: is a
 * directory" or "...: not a regular file ...") when PATH exists and is not
 * a regular file, which st_outfile refuses to replace; else 0. NULL and
 * "-" (stdout) are always fine. The real write still checks everything; this only saves
 * the user a run whose result could not be kept. */
int tool_output_unwritable(const tool_ctx *t, const char *path);

/* What one lattice tet costs at least while a lattice is built
 * (lattice.h, ST_LATTICE_BYTES_PER_TET): a lattice of more tets than
 * max_bytes / this cannot fit and is refused before it is allocated. */
#define TOOL_LATTICE_BYTES_PER_TET ST_LATTICE_BYTES_PER_TET
/* The most lattice tets max_bytes allows (no memory limit: 2^31). */
size_t tool_max_lattice_tets(size_t max_bytes);

/* Set the OpenMP thread count (0: leave the default). */
void tool_set_threads(size_t threads);

/* A progress reporter that draws one line on stderr when stderr is a
 * terminal (or SOUPTET_PROGRESS=1 is set) and verbosity >= 1; otherwise
 * it does nothing. The line: "tool: STAGE NN% (T s, ETA E)", a stage's
 * percentage never going back (the furthest reported; a fall of more
 * than half starts the stage over), the ETA from the stage's rate past
 * 2% and 1 s; redrawn every second by a thread so the clock moves while
 * nothing is reported ("STAGE done; working (T s)" after a stage's end).
 * The line is cleared at exit and ended with a newline on a signal. */
st_progress tool_progress(tool_ctx *t);
/* Clear the progress line if one was drawn. */
void tool_progress_end(tool_ctx *t);

/* Wall-clock seconds since an arbitrary origin. */
double tool_now(void);

/* Print the version lines: "name (souptet) X.Y.Z" and "commit C" (git
 * describe of the tree it was built from, or "unknown" from a tarball
 * without one; the Makefile bakes both into build/gen/souptet_build.h). */
void tool_print_version(const tool_ctx *t);
/* The version and the commit the tool was built from (as printed by
 * --version), for a mesh's or a field's metadata. */
const char *tool_version(void);
const char *tool_commit(void);
/* Record in meta what made it: "version" and "commit" (tool_version,
 * tool_commit) and the command line appended to its history. ST_ENOMEM
 * on failure. */
st_status tool_meta_record(const tool_ctx *t, st_meta *meta);

/* An old option spelling kept for one release: "name: OLD is now NEW (OLD
 * goes in the next release)" on stderr unless -q. */
void tool_deprecated(const tool_ctx *t, const char *old_name, const char *new_name);

/* JSON output: s as a quoted, escaped JSON string; x as the shortest of 15,
 * 16 or 17 significant digits that reads back as exactly x (so 0.1 does not
 * print as 0.10000000000000001), or "null" for NaN and infinities (JSON has
 * neither). tool_json_number writes into buf and returns it (or "null"). */
void tool_json_string(FILE *f, const char *s);
const char *tool_json_number(char buf[32], double x);

/* ---- the end of option parsing -----------------------------------------
 *
 * What every tool checks once its options are read, in this order: its
 * one input operand, no terminal where data would flow, an output format
 * it can tell, an output it can write. Each returns TOOL_CONTINUE when all
 * is well, else the exit status main returns at once (the message already
 * printed). */

/* In main(): return the exit status call gives unless it is TOOL_CONTINUE. */
#define TOOL_TRY(call)                                                    \
    do {                                                                  \
        int tool_rc_ = (call);                                            \
        if (tool_rc_ != TOOL_CONTINUE)                                    \
            return tool_rc_;                                              \
    } while (0)

/* Where several inputs may come from stdin (n paths, NULL ones not
 * given): "-" more than once is a usage error "standard input ('-') given
 * N times", and "-" when stdin is a terminal one with tty_msg. */
int tool_stdin_once(const tool_ctx *t, const char *const *paths, size_t n,
                    const char *tty_msg);
/* The operand after the options: *in gets it, or dflt when there is none
 * (dflt may be NULL); a second one is a usage error "one NAME at most
 * ('X' is extra)". */
int tool_one_input(const tool_ctx *t, int argc, char *argv[], const char *name,
                   const char *dflt, const char **in);
/* The messages of tool_refuse_terminal for a surface and for binary data. */
#define TOOL_TTY_SURFACE "will not read a surface from a terminal: give a file or pipe one"
#define TOOL_TTY_VTU "will not write a .vtu document to a terminal: give -o FILE or pipe it"
/* When path names stdin or stdout ("-" or NULL) and that descriptor (fd 0
 * or 1) is a terminal: a usage error with msg. */
int tool_refuse_terminal(const tool_ctx *t, const char *path, int fd, const char *msg);
/* When out is a file (not stdout) and known is 0: a usage error "cannot
 * tell the format of 'OUT' (use EXTS)". */
int tool_output_format(const tool_ctx *t, const char *out, int known, const char *exts);
/* The two checks above for a tool's output: a grid (.vdb or .vti; an
 * OpenVDB stream on stdout, never to a terminal), or a tet mesh (.vtu
 * .msh .node .ele .mesh; on stdout .vtu, and with tty_msg not NULL never
 * to a terminal). */
int tool_grid_output(const tool_ctx *t, const char *out);
int tool_tetmesh_output(const tool_ctx *t, const char *out, const char *tty_msg);
/* When out names a surface file (.stl .obj .off .ply .gltf .glb): a usage
 * error "STL is a surface format: HINT (a tet mesh is ...)" (tool_tetmesh_output
 * checks it with a plain hint; soupmesh first, naming --boundary). */
int tool_surface_as_tetmesh(const tool_ctx *t, const char *out, const char *hint);
/* When an output (NULL and "-" are fine) cannot be written there
 * (tool_output_unwritable): TOOL_EXIT_FAIL after tool_finish. */
int tool_output_check(tool_ctx *t, const char *out);

/* ---- options every tool shares ----------------------------------------
 *
 * A tool's option table starts with its own long options, then
 * TOOL_LONG_OPTIONS_OUTPUT (-o) when it writes a file, then
 * TOOL_LONG_OPTIONS_BASIC (-q, -v, -h/--help, -V/--version: tool_main adds
 * "hV" to every tool's short options, so no tool may use -h or -V for
 * anything else) and, for tools that
 * compute, TOOL_LONG_OPTIONS_RESOURCES (--threads, --max-memory), the two
 * of them with the table's end as TOOL_LONG_OPTIONS_END; its own option
 * codes start at TOOL_OPT_FIRST. tool_main's getopt_long loop hands the
 * shared codes to tool_common_option (below). */
enum { TOOL_OPT_THREADS = 1000, TOOL_OPT_MAXMEM, TOOL_OPT_HELP, TOOL_OPT_VERSION,
       TOOL_OPT_MSH_VERSION, TOOL_OPT_MSH_BINARY, TOOL_OPT_FILL_HOLES, TOOL_OPT_SHELLS,
       TOOL_OPT_SYMMETRY, TOOL_OPT_VOLUME_ONLY, TOOL_OPT_FIRST = 1100 };
#define TOOL_LONG_OPTIONS_BASIC                              \
    {"quiet", no_argument, NULL, 'q'},                       \
    {"verbose", no_argument, NULL, 'v'},                     \
    {"help", no_argument, NULL, 'h'},                        \
    {"version", no_argument, NULL, 'V'}
/* -o, --output OUT (into tool_common's out). */
#define TOOL_LONG_OPTIONS_OUTPUT {"output", required_argument, NULL, 'o'}
#define TOOL_LONG_OPTIONS_RESOURCES                          \
    {"threads", required_argument, NULL, TOOL_OPT_THREADS},  \
    {"max-memory", required_argument, NULL, TOOL_OPT_MAXMEM}
/* The end of the table of a tool that computes. */
#define TOOL_LONG_OPTIONS_END                                \
    TOOL_LONG_OPTIONS_BASIC,                                 \
    TOOL_LONG_OPTIONS_RESOURCES,                             \
    {NULL, 0, NULL, 0}

/* The pseudo volume's switches --fill-holes, --shells and --symmetry,
 * each on|off (soupsign, soupwrap, soupmesh: pseudo.h): their table
 * entries, and their handling for c TOOL_OPT_FILL_HOLES, TOOL_OPT_SHELLS
 * or TOOL_OPT_SYMMETRY into the matching field of *sw. Returns
 * TOOL_CONTINUE, or TOOL_EXIT_USAGE after a usage error (printed). */
#define TOOL_LONG_OPTIONS_PSEUDO                                   \
    {"fill-holes", required_argument, NULL, TOOL_OPT_FILL_HOLES},  \
    {"shells", required_argument, NULL, TOOL_OPT_SHELLS},          \
    {"symmetry", required_argument, NULL, TOOL_OPT_SYMMETRY}
typedef struct tool_pseudo_switches {
    int *fill_holes, *shells, *symmetry;
} tool_pseudo_switches;
int tool_pseudo_option(const tool_ctx *t, int c, const char *arg,
                       const tool_pseudo_switches *sw);

/* The tet-mesh format options of every tool that writes a tet mesh
 * (soupmesh, latticetet, tetsmooth): their table entries, their --help
 * lines, and their handling: for c TOOL_OPT_MSH_VERSION (2, 4, 22 or 41
 * into o->msh_version), TOOL_OPT_MSH_BINARY (o->binary = 1) or
 * TOOL_OPT_VOLUME_ONLY (o->volume_only = 1: the tets alone in .msh and
 * .mesh, for SfePy's Mesh.from_file; no effect on .vtu and TetGen, which
 * hold nothing else). Returns 0, or -1 after a usage error (printed). */
#define TOOL_LONG_OPTIONS_TETFORMAT                                \
    {"msh-version", required_argument, NULL, TOOL_OPT_MSH_VERSION}, \
    {"msh-binary", no_argument, NULL, TOOL_OPT_MSH_BINARY},        \
    {"volume-only", no_argument, NULL, TOOL_OPT_VOLUME_ONLY}
#define TOOL_HELP_TETFORMAT                                               \
    "      --msh-version V  Gmsh format 4 (4.1, default) or 2 (2.2)\n"   \
    "      --msh-binary     binary .msh instead of ASCII\n"              \
    "      --volume-only    .msh and .mesh: the tets alone, without the boundary\n" \
    "                       triangles and their group (SfePy's Mesh.from_file\n" \
    "                       wants one cell kind); .vtu, TetGen: no change\n"
int tool_tetformat_option(const tool_ctx *t, int c, const char *arg,
                          st_tetformat_opts *o);

/* What the shared options set: threads (0: all cores), the memory limit
 * (tool_default_max_memory() unless --max-memory), the output (-o; NULL
 * when not given) and, in the tools that write tet meshes, the format
 * options (TOOL_LONG_OPTIONS_TETFORMAT). */
typedef struct tool_common {
    size_t threads;
    size_t max_bytes;
    const char *out;
    st_tetformat_opts tetformat;
} tool_common;

/* The shared options' defaults. */
tool_common tool_common_default(void);

/* When to go on parsing (see tool_common_option). */
#define TOOL_CONTINUE (-1)

/* Handle getopt_long's code c when it is a shared option (-q, -v,
 * --threads, --max-memory, --help, --version), a missing value (':') or an
 * unknown option (anything else): returns TOOL_CONTINUE when parsing goes
 * on, else the exit status the tool returns at once (TOOL_EXIT_OK after
 * --help, which calls usage(), and --version; TOOL_EXIT_USAGE after a
 * usage error, already printed). Uses optarg and optind. */
int tool_common_option(tool_ctx *t, int c, char *const argv[],
                       void (*usage)(void), tool_common *co);

/* ---- a tool's main: parse into settings, then run ----------------------
 *
 * Every tool parses its command line into a settings struct of its own
 * (the library's defaults first), then runs from that struct alone:
 *
 *     static const tool_spec spec = {"NAME", usage, ":o:qv", longopts,
 *                                    option, check, run};
 *     int main(int argc, char *argv[])
 *     {
 *         NAME_settings s = {...the library's defaults...};
 *         return tool_main(&spec, argc, argv, &s, &s.co);
 *     }
 *
 * tool_main: tool_init; *co = tool_common_default(); the getopt_long
 * loop over shortopts (":" first, for missing values) and longopts (the
 * tool's own, then the TOOL_LONG_OPTIONS_* tables it takes), where the
 * shared options go to tool_common_option, tool_tetformat_option and -o
 * (into co) and every other code to option; then check (the operands from
 * optind, the checks between options and of the output); then run;
 * tool_finish. option and check return TOOL_CONTINUE or the exit status
 * at once (a usage error already printed); run returns the exit status. */
typedef int (*tool_option_fn)(tool_ctx *t, int c, const char *arg, void *settings);
typedef int (*tool_check_fn)(tool_ctx *t, int argc, char *argv[], void *settings);
typedef int (*tool_run_fn)(tool_ctx *t, void *settings);
typedef struct tool_spec {
    const char *name;
    void (*usage)(void);
    const char *shortopts;
    const struct option *longopts;
    tool_option_fn option;
    tool_check_fn check;
    tool_run_fn run;
} tool_spec;
int tool_main(const tool_spec *spec, int argc, char *argv[], void *settings,
              tool_common *co);

/* -v: the soup's symmetries (symmetry.h) at the field's voxel
 * (tolerance), each on its own line at level 2 with its support, and what
 * the pseudo volume's fill took from them (pseudo.h, step 2). set and fill:
 * the step's, when it looked (set->candidates > 0); else this looks
 * itself (bvh may be NULL: one is built) and says they were not used. 0,
 * or the exit status after an error was printed. */
struct st_soup;
struct st_bvh;
struct st_symmetry_set;
struct st_symmetry_fill_stats;
int tool_report_symmetries(tool_ctx *t, const struct st_soup *soup, const struct st_bvh *bvh,
                           double tolerance, const struct st_symmetry_set *set,
                           const struct st_symmetry_fill_stats *fill, double seconds);

#endif
