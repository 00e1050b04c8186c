/* tool.c - shared tool plumbing (see tool.h). */
#define _GNU_SOURCE
#include "tool.h"
#include "../base/fpenv.h"
#include "souptet_build.h"
#include "souptet/dist.h"
#include "souptet/grid.h"
#include "souptet/gridio.h"
#include "souptet/mem.h"
#include "souptet/outfile.h"
#include "souptet/soup.h"
#include "souptet/symmetry.h"

#include <errno.h>
#include <fcntl.h>
#include <pthread.h>
#include <getopt.h>
#include <limits.h>
#include <math.h>
#include <signal.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>
#ifdef _OPENMP
#include <omp.h>
#endif

static const char *g_name = "souptet";
static char *g_command_line;   /* freed at exit, whatever path main takes */

/* The progress line (tool_progress): its stage, the largest fraction
 * reported in it (the line never goes back), when the stage began, and a
 * thread that redraws it every second so the clock moves even while a
 * stage reports nothing. g_progress_drawn is volatile for the signal
 * handler, which ends the line (a bare write: nothing else is safe). */
static pthread_mutex_t g_progress_mu = PTHREAD_MUTEX_INITIALIZER;
static volatile sig_atomic_t g_progress_drawn;
static double g_progress_last;
static char g_progress_stage[64];
static double g_progress_frac, g_progress_t0, g_progress_tdone;
static int g_progress_ticker, g_progress_stop;
#define PROGRESS_DONE 0.995   /* what prints as 100% */
static int g_failed;           /* tool_fail has printed an error */
static size_t g_ulimit_left;   /* >0: the default --max-memory came from ulimit -v */

/* Remove the temporary outputs, then die of the signal at once (its
 * default action, unblocked: the raise does not return). The signal comes
 * to the main thread, which is the one writing (Linux gives a process's
 * signal to its main thread unless that blocks it), so nothing re-creates
 * a temporary by name between the unlink and the end. */
static void on_signal(int sig)
{
    signal(sig, SIG_DFL);
    /* The progress line ends, so the shell's prompt starts a line. */
    if (g_progress_drawn && write(STDERR_FILENO, "\n", 1) < 0)
        g_progress_drawn = 0;
    st_outfile_unlink_pending();
    sigset_t s;
    sigemptyset(&s);
    sigaddset(&s, sig);
    pthread_sigmask(SIG_UNBLOCK, &s, NULL);
    raise(sig);
}

double tool_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static void free_command_line(void)
{
    free(g_command_line);
    g_command_line = NULL;
}

/* At exit: whatever is still buffered for stdout goes out now, and a write
 * that failed at any time (a full disk, a closed descriptor) turns a
 * successful exit into exit 1 with a message, as the GNU tools do. A
 * closed pipe never gets here: SIGPIPE ends the tool first. */
static void close_stdout(void)
{
    errno = 0;
    int bad = fflush(stdout) != 0;
    int e = errno;
    bad |= ferror(stdout) != 0;
    if (!bad)
        return;
    if (!g_failed)
        fprintf(stderr, "%s: <stdout>: write failed: %s\n", g_name,
                e ? strerror(e) : "I/O error");
    _exit(TOOL_EXIT_FAIL);
}

/* A descriptor 0, 1 or 2 the tool was started without would be handed out
 * by the next open(), and a temporary output file could then receive what
 * is printed to stdout. Hold its place with one that fails every read and
 * write (a directory opened read-only: EISDIR, EBADF). */
static void hold_std_fds(void)
{
    for (int fd = 0; fd <= 2; fd++)
        if (fcntl(fd, F_GETFD) < 0 && errno == EBADF) {
            int h = open("/", O_RDONLY | O_DIRECTORY);
            if (h >= 0 && h != fd) {
                dup2(h, fd);
                close(h);
            }
        }
}

void tool_init(tool_ctx *t, const char *name, int argc, char *argv[])
{
    hold_std_fds();
    t->name = name;
    g_name = name;
    t->verbosity = 1;
    t->command_line = g_command_line = st_command_line(argc, argv);
    atexit(free_command_line);
    atexit(close_stdout);
    t->t0 = tool_now();
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_signal;
    sigemptyset(&sa.sa_mask);
    int sigs[] = {SIGINT, SIGTERM, SIGHUP, SIGPIPE, SIGQUIT, SIGXCPU};
    for (size_t i = 0; i < sizeof sigs / sizeof sigs[0]; i++)
        sigaction(sigs[i], &sa, NULL);
    /* Past a file size limit (ulimit -f), write(2) then fails with EFBIG
     * and the output's own error path reports it and removes the
     * temporary, instead of a core dump leaving it behind. */
    signal(SIGXFSZ, SIG_IGN);
}

void tool_finish(tool_ctx *t)
{
    free_command_line();
    t->command_line = NULL;
}

int tool_fail(const tool_ctx *t, const st_error *err)
{
    char buf[1200];
    g_failed = 1;
    tool_progress_end((tool_ctx *)t);
    st_error_format(err, buf, sizeof buf);
    /* Under ulimit -v an allocation fails long before the RAM runs out:
     * say which limit it met. */
    size_t cap;
    if (err && err->status == ST_ENOMEM && st_mem_address_space_left(&cap) != SIZE_MAX) {
        size_t n = strlen(buf);
        snprintf(buf + n, sizeof buf - n, " (ulimit -v caps this process's address space "
                 "at %.0f MiB: raise it, or ask for less)", (double)cap / 1048576.0);
    }
    fprintf(stderr, "%s: %s\n", t->name, buf);
    return TOOL_EXIT_FAIL;
}

int tool_fail_file(const tool_ctx *t, st_error *err, const char *file)
{
    if (!err->file[0])
        snprintf(err->file, sizeof err->file, "%s", file);
    return tool_fail(t, err);
}

int tool_fail_nomem(const tool_ctx *t, st_error *err)
{
    st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory");
    return tool_fail(t, err);
}

const char *tool_in_name(const char *path)
{
    return st_path_is_stdio(path) ? "<stdin>" : path;
}

const char *tool_out_name(const char *path)
{
    return st_path_is_stdio(path) ? "<stdout>" : path;
}

const char *tool_command(const tool_ctx *t)
{
    return t->command_line ? t->command_line : t->name;
}

st_status tool_soup_read(const tool_ctx *t, struct st_soup **out,
                         const char *path, st_error *err)
{
    return tool_soup_read_source(t, out, path, NULL, err);
}

st_status tool_soup_read_source(const tool_ctx *t, struct st_soup **out, const char *path,
                                struct st_soup_source *src, st_error *err)
{
    st_soup_warnings w;
    st_status st = st_soup_read_source(out, path, src, &w, err);
    if (w.count > 0 && t->verbosity >= 1) {
        char buf[1200];
        tool_progress_end((tool_ctx *)t);
        fprintf(stderr, "%s: warning: %s\n", t->name,
                st_error_format(&w.first, buf, sizeof buf));
        if (w.count > 1)
            fprintf(stderr, "%s: warning: %s: %zu more like it\n", t->name,
                    w.first.file, w.count - 1);
    }
    return st;
}

int tool_flush_stdout(const tool_ctx *t)
{
    errno = 0;
    int bad = fflush(stdout) != 0;
    int e = errno;
    bad |= ferror(stdout) != 0;
    if (!bad)
        return 0;
    st_error err;
    st_error_set(&err, ST_EIO, "<stdout>", 0, "write failed: %s",
                 e ? strerror(e) : "I/O error");
    return tool_fail(t, &err);
}

st_status tool_check_field_finite(const struct st_grid *g, const char *name,
                                  st_error *err)
{
    size_t n = st_grid_count(g), bad = 0;
    for (size_t i = 0; i < n; i++)
        bad += !isfinite(g->data[i]);
    if (!bad)
        return ST_OK;
    return st_error_set(err, ST_EINPUT, name, 0,
                        "the field has %zu values that are not finite", bad);
}

void tool_limit_hint(st_error *err, const char *hint)
{
    if (!err || err->status != ST_ELIMIT || !hint)
        return;
    size_t n = strlen(err->msg);
    /* The library's own advice, "... (lower the resolution)", gives way
     * to the tool's, which knows its option names. */
    char *paren = strrchr(err->msg, '(');
    if (n > 0 && err->msg[n - 1] == ')' && paren && paren > err->msg &&
        paren[-1] == ' ')
        n = (size_t)(paren - 1 - err->msg);
    if (g_ulimit_left)
        snprintf(err->msg + n, sizeof err->msg - n, " (%s; the default --max-memory "
                 "here is 80%% of the %.0f MiB that ulimit -v leaves)", hint,
                 (double)g_ulimit_left / 1048576.0);
    else
        snprintf(err->msg + n, sizeof err->msg - n, " (%s)", hint);
}

size_t tool_dist_cells_that_fit(const struct st_soup *s, const struct st_dist_params *p)
{
    if (!s || !p || p->voxel > 0 || p->cells < 2 || !p->max_bytes)
        return 0;
    st_dist_params q = *p;
    size_t dims[3], lo = 0, hi = p->cells;   /* lo fits (0: none yet), hi does not */
    double origin[3], h;
    while (hi - lo > 1) {
        q.cells = lo + (hi - lo) / 2;
        size_t n;
        /* The layout, then the grid's size as st_grid_new checks it. */
        if (st_dist_layout(s, &q, dims, origin, &h, NULL) == ST_OK &&
            !st_size_mul(&n, dims[0], dims[1]) && !st_size_mul(&n, n, dims[2]) &&
            !st_size_mul(&n, n, sizeof(float)) && n <= p->max_bytes)
            lo = q.cells;
        else
            hi = q.cells;
    }
    return lo;
}

int tool_usage_error(const tool_ctx *t, const char *fmt, ...)
{
    va_list ap;
    fprintf(stderr, "%s: ", t->name);
    va_start(ap, fmt);
    vfprintf(stderr, fmt, ap);
    va_end(ap);
    fprintf(stderr, "\nTry '%s --help'.\n", t->name);
    return TOOL_EXIT_USAGE;
}

void tool_say(const tool_ctx *t, int level, const char *fmt, ...)
{
    if (t->verbosity < level)
        return;
    tool_progress_end((tool_ctx *)t);
    va_list ap;
    fprintf(stderr, "%s: ", t->name);
    va_start(ap, fmt);
    vfprintf(stderr, fmt, ap);
    va_end(ap);
    fputc('\n', stderr);
}

int tool_parse_size(const tool_ctx *t, const char *opt, const char *arg,
                    size_t min, size_t max, size_t *out)
{
    char *end;
    errno = 0;
    if (arg[0] == '-' || arg[0] == '\0')
        goto bad;
    unsigned long long v = strtoull(arg, &end, 10);
    if (errno || *end || v < min || v > max)
        goto bad;
    *out = (size_t)v;
    return 0;
bad:
    tool_usage_error(t, "%s wants a whole number from %zu to %zu, not '%s'",
                     opt, min, max, arg);
    return -1;
}

int tool_parse_double(const tool_ctx *t, const char *opt, const char *arg,
                      double min, double max, double *out)
{
    char *end;
    errno = 0;
    double v = strtod(arg, &end);
    if (arg[0] == '\0' || errno || *end || !isfinite(v) || v < min || v > max) {
        tool_usage_error(t, "%s wants a number from %g to %g, not '%s'", opt,
                         min, max, arg);
        return -1;
    }
    *out = v;
    return 0;
}

int tool_parse_switch(const tool_ctx *t, const char *opt, const char *arg, int *out)
{
    if (strcmp(arg, "on") == 0)
        *out = 1;
    else if (strcmp(arg, "off") == 0)
        *out = 0;
    else {
        tool_usage_error(t, "%s is on or off, not '%s'", opt, arg);
        return -1;
    }
    return 0;
}

int tool_tetformat_option(const tool_ctx *t, int c, const char *arg,
                          st_tetformat_opts *o)
{
    size_t v;
    if (c == TOOL_OPT_MSH_BINARY) {
        o->binary = 1;
        return 0;
    }
    if (c == TOOL_OPT_VOLUME_ONLY) {
        o->volume_only = 1;
        return 0;
    }
    if (tool_parse_size(t, "--msh-version", arg, 2, 41, &v))
        return -1;
    if (v != 2 && v != 4 && v != 22 && v != 41) {
        tool_usage_error(t, "--msh-version is 2 or 4 (2.2 or 4.1), not '%s'", arg);
        return -1;
    }
    o->msh_version = (int)v;
    return 0;
}

int tool_pseudo_option(const tool_ctx *t, int c, const char *arg,
                       const tool_pseudo_switches *sw)
{
    const char *name = c == TOOL_OPT_FILL_HOLES ? "--fill-holes"
                     : c == TOOL_OPT_SHELLS ? "--shells" : "--symmetry";
    int *to = c == TOOL_OPT_FILL_HOLES ? sw->fill_holes
            : c == TOOL_OPT_SHELLS ? sw->shells : sw->symmetry;
    return tool_parse_switch(t, name, arg, to) ? TOOL_EXIT_USAGE : TOOL_CONTINUE;
}

int tool_parse_bytes(const tool_ctx *t, const char *opt, const char *arg,
                     size_t *out)
{
    char *end;
    errno = 0;
    double v = strtod(arg, &end);
    double mul = 1.0;
    switch (*end) {
    case 'k': case 'K': mul = 1024.0; end++; break;
    case 'm': case 'M': mul = 1048576.0; end++; break;
    case 'g': case 'G': mul = 1073741824.0; end++; break;
    case 't': case 'T': mul = 1099511627776.0; end++; break;
    default: break;
    }
    if (*end == 'B' || *end == 'b')
        end++;
    if (arg[0] == '\0' || errno || *end || !isfinite(v) || v <= 0 ||
        v * mul >= 1.8e19) {
        tool_usage_error(t, "%s wants a size such as 4G or 512M, not '%s'",
                         opt, arg);
        return -1;
    }
    *out = (size_t)(v * mul);
    return 0;
}

size_t tool_default_max_memory(void)
{
    long pages = sysconf(_SC_PHYS_PAGES), size = sysconf(_SC_PAGESIZE);
    size_t def = pages > 0 && size > 0 ? (size_t)((double)pages * (double)size * 0.8) : 0;
    /* Under ulimit -v, what it leaves (libraries, stacks and the reader's
     * temporaries need room too: 80% of it), so a job too large for it is
     * refused by the estimate, naming the option to lower, rather than by
     * a failed allocation midway. */
    size_t left = st_mem_address_space_left(NULL);
    g_ulimit_left = 0;
    if (left != SIZE_MAX && (def == 0 || (double)left * 0.8 < (double)def)) {
        g_ulimit_left = left > 0 ? left : 1;
        def = left > 1 ? (size_t)((double)left * 0.8) : 1;
    }
    return def;
}

size_t tool_max_lattice_tets(size_t max_bytes)
{
    size_t cap = (size_t)1 << 31;
    if (max_bytes && max_bytes / TOOL_LATTICE_BYTES_PER_TET < cap)
        cap = max_bytes / TOOL_LATTICE_BYTES_PER_TET;
    return cap > 0 ? cap : 1;
}

void tool_set_threads(size_t threads)
{
#ifdef _OPENMP
    if (threads > 0)
        omp_set_num_threads((int)threads);
#else
    (void)threads;
#endif
}

/* "12 s", "4 min 10 s", "1 h 05 min". */
static void progress_duration(char *buf, size_t n, double s)
{
    long v = (long)(s + 0.5);
    if (v < 60)
        snprintf(buf, n, "%ld s", v);
    else if (v < 3600)
        snprintf(buf, n, "%ld min %02ld s", v / 60, v % 60);
    else
        snprintf(buf, n, "%ld h %02ld min", v / 3600, v / 60 % 60);
}

/* The line, from the state (the mutex held): the stage, its percentage,
 * the time in it, and past 2% and 1 s of a stage, the time left at the
 * rate so far. */
static void progress_write(double now)
{
    char el[32], eta[32] = "";
    double in_stage = now - g_progress_t0, f = g_progress_frac;
    if (f >= PROGRESS_DONE && now - g_progress_tdone >= 1.0) {
        /* The stage is done and the next has not reported yet: the clock
         * since, so the line still moves. */
        progress_duration(el, sizeof el, now - g_progress_tdone);
        fprintf(stderr, "\r%s: %s done; working (%s)\033[K", g_name, g_progress_stage, el);
        fflush(stderr);
        g_progress_last = now;
        g_progress_drawn = 1;
        return;
    }
    progress_duration(el, sizeof el, in_stage);
    if (f >= 0.02 && f < PROGRESS_DONE && in_stage >= 1.0) {
        char left[24];
        progress_duration(left, sizeof left, in_stage * (1.0 - f) / f);
        snprintf(eta, sizeof eta, ", ETA %s", left);
    }
    fprintf(stderr, "\r%s: %s %3.0f%% (%s%s)\033[K", g_name, g_progress_stage, 100.0 * f,
            el, eta);
    fflush(stderr);
    g_progress_last = now;
    g_progress_drawn = 1;
}

static void progress_draw(void *ctx, const char *stage, double fraction)
{
    (void)ctx;
    double now = tool_now();
    pthread_mutex_lock(&g_progress_mu);
    if (g_progress_stop) {
        pthread_mutex_unlock(&g_progress_mu);
        return;
    }
    /* A stage's line never goes back: rounds that report in turn (the
     * fit's share of vertices within the offset falls a little as others
     * move) show the furthest point reached. A new stage, or the same
     * one starting over (back by more than half: a new sizing sculpt, a
     * new pass), starts afresh. */
    if (strncmp(stage, g_progress_stage, sizeof g_progress_stage - 1) != 0 ||
        fraction < g_progress_frac - 0.5) {
        snprintf(g_progress_stage, sizeof g_progress_stage, "%s", stage);
        g_progress_frac = 0.0;
        g_progress_t0 = now;
    }
    if (fraction > g_progress_frac) {
        if (g_progress_frac < PROGRESS_DONE && fraction >= PROGRESS_DONE)
            g_progress_tdone = now;
        g_progress_frac = fraction > 1.0 ? 1.0 : fraction;
    }
    /* Ten redraws a second are plenty for a person. */
    if (fraction >= 1.0 || !g_progress_drawn || now - g_progress_last >= 0.1)
        progress_write(now);
    pthread_mutex_unlock(&g_progress_mu);
}

/* Once a second, the line again with its clock moved, while a stage
 * reports nothing new (detached; stops at exit). */
static void *progress_ticker(void *arg)
{
    (void)arg;
    for (;;) {
        struct timespec ts = {0, 250000000};
        nanosleep(&ts, NULL);
        pthread_mutex_lock(&g_progress_mu);
        int stop = g_progress_stop;
        double now = tool_now();
        if (!stop && g_progress_drawn && now - g_progress_last >= 1.0)
            progress_write(now);
        pthread_mutex_unlock(&g_progress_mu);
        if (stop)
            return NULL;
    }
}

/* At exit, whatever the path: the line is ended and the ticker stops. */
static void progress_at_exit(void)
{
    pthread_mutex_lock(&g_progress_mu);
    g_progress_stop = 1;
    if (g_progress_drawn) {
        fprintf(stderr, "\r\033[K");
        fflush(stderr);
        g_progress_drawn = 0;
    }
    pthread_mutex_unlock(&g_progress_mu);
}

st_progress tool_progress(tool_ctx *t)
{
    st_progress p = {NULL, NULL, NULL};
    /* SOUPTET_PROGRESS=1 draws the line on a stderr that is not a
     * terminal too (tests; a log read as it grows). */
    const char *force = getenv("SOUPTET_PROGRESS");
    if (t->verbosity >= 1 && (isatty(STDERR_FILENO) || (force && strcmp(force, "1") == 0))) {
        p.fn = progress_draw;
        p.ctx = t;
        pthread_mutex_lock(&g_progress_mu);
        if (!g_progress_ticker) {
            pthread_t th;
            g_progress_ticker = 1;
            if (pthread_create(&th, NULL, progress_ticker, NULL) == 0)
                pthread_detach(th);
            atexit(progress_at_exit);
        }
        pthread_mutex_unlock(&g_progress_mu);
    }
    return p;
}

void tool_progress_end(tool_ctx *t)
{
    (void)t;
    pthread_mutex_lock(&g_progress_mu);
    if (g_progress_drawn) {
        fprintf(stderr, "\r\033[K");
        fflush(stderr);
        g_progress_drawn = 0;
    }
    pthread_mutex_unlock(&g_progress_mu);
}

void tool_json_string(FILE *f, const char *s)
{
    fputc('"', f);
    for (const unsigned char *p = (const unsigned char *)s; *p; p++) {
        if (*p == '"' || *p == '\\')
            fprintf(f, "\\%c", *p);
        else if (*p < 0x20)
            fprintf(f, "\\u%04x", *p);
        else
            fputc(*p, f);
    }
    fputc('"', f);
}

const char *tool_json_number(char buf[32], double x)
{
    if (!isfinite(x))
        return "null";
    for (int digits = 15; digits <= 17; digits++) {
        snprintf(buf, 32, "%.*g", digits, x);
        if (strtod(buf, NULL) == x)
            break;
    }
    return buf;
}

int tool_output_unwritable(const tool_ctx *t, const char *path)
{
    if (st_path_is_stdio(path))
        return 0;
    struct stat st;
    if (stat(path, &st) == 0 && !S_ISREG(st.st_mode)) {
        fprintf(stderr, "%s: %s: %s\n", t->name, path,
                S_ISDIR(st.st_mode) ? "is a directory"
                                    : "not a regular file (write to '-' for "
                                      "standard output)");
        return 1;
    }
    size_t n = strlen(path);
    char *dir = malloc(n + 2);
    if (!dir)
        return 0;   /* let the real write report it */
    memcpy(dir, path, n + 1);
    char *slash = strrchr(dir, '/');
    if (!slash)
        strcpy(dir, ".");
    else if (slash == dir)
        dir[1] = '\0';   /* "/name": the root */
    else
        *slash = '\0';
    int bad = access(dir, W_OK | X_OK) != 0;
    if (bad)
        fprintf(stderr, "%s: %s: cannot write there: %s\n", t->name, path,
                strerror(errno));
    free(dir);
    return bad;
}

int tool_one_input(const tool_ctx *t, int argc, char *argv[], const char *name,
                   const char *dflt, const char **in)
{
    if (optind < argc)
        *in = argv[optind++];
    if (optind < argc)
        return tool_usage_error(t, "one %s at most ('%s' is extra)", name, argv[optind]);
    if (!*in)
        *in = dflt;
    return TOOL_CONTINUE;
}

int tool_stdin_once(const tool_ctx *t, const char *const *paths, size_t n,
                    const char *tty_msg)
{
    int nstdin = 0;
    for (size_t i = 0; i < n; i++)
        nstdin += paths[i] && strcmp(paths[i], "-") == 0;
    if (nstdin > 1)
        return tool_usage_error(t, "standard input ('-') given %d times", nstdin);
    if (nstdin && isatty(STDIN_FILENO))
        return tool_usage_error(t, "%s", tty_msg);
    return TOOL_CONTINUE;
}

int tool_refuse_terminal(const tool_ctx *t, const char *path, int fd, const char *msg)
{
    if (st_path_is_stdio(path) && isatty(fd))
        return tool_usage_error(t, "%s", msg);
    return TOOL_CONTINUE;
}

int tool_output_format(const tool_ctx *t, const char *out, int known, const char *exts)
{
    if (!st_path_is_stdio(out) && !known)
        return tool_usage_error(t, "cannot tell the format of '%s' (use %s)", out, exts);
    return TOOL_CONTINUE;
}

int tool_grid_output(const tool_ctx *t, const char *out)
{
    TOOL_TRY(tool_refuse_terminal(t, out, STDOUT_FILENO, "will not write a binary VDB "
                                  "stream to a terminal: give -o FILE or pipe it"));
    return tool_output_format(t, out, st_path_is_stdio(out) ||
                              st_grid_format_from_path(out) != ST_GRID_FMT_UNKNOWN,
                              ".vdb or .vti");
}

/* "STL" for a surface file's path, else NULL. */
static const char *surface_format_upper(const char *path, char buf[8])
{
    st_soup_format f = st_path_is_stdio(path) ? ST_SOUP_UNKNOWN : st_soup_format_from_path(path);
    if (f == ST_SOUP_UNKNOWN)
        return NULL;
    const char *n = st_soup_format_name(f);
    size_t i = 0;
    for (; n[i] && i < 7; i++)
        buf[i] = (char)(n[i] >= 'a' && n[i] <= 'z' ? n[i] - 'a' + 'A' : n[i]);
    buf[i] = '\0';
    return f == ST_SOUP_GLTF ? "glTF" : buf;
}

int tool_surface_as_tetmesh(const tool_ctx *t, const char *out, const char *hint)
{
    char buf[8];
    const char *fmt = surface_format_upper(out, buf);
    if (!fmt)
        return TOOL_CONTINUE;
    return tool_usage_error(t, "%s is a surface format: %s (a tet mesh is .vtu, .msh, "
                            ".node, .ele or .mesh)", fmt, hint ? hint : "not for -o");
}

int tool_tetmesh_output(const tool_ctx *t, const char *out, const char *tty_msg)
{
    if (tty_msg)
        TOOL_TRY(tool_refuse_terminal(t, out, STDOUT_FILENO, tty_msg));
    TOOL_TRY(tool_surface_as_tetmesh(t, out, NULL));
    return tool_output_format(t, out, st_path_is_stdio(out) ||
                              st_tetformat_from_path(out) != ST_TETFORMAT_NONE,
                              ".vtu, .msh, .node, .ele or .mesh");
}

int tool_output_check(tool_ctx *t, const char *out)
{
    if (!tool_output_unwritable(t, out))
        return TOOL_CONTINUE;
    tool_finish(t);
    return TOOL_EXIT_FAIL;
}

tool_common tool_common_default(void)
{
    tool_common co;
    co.threads = 0;
    co.max_bytes = tool_default_max_memory();
    co.out = NULL;
    co.tetformat.msh_version = 0;
    co.tetformat.binary = 0;
    return co;
}

int tool_common_option(tool_ctx *t, int c, char *const argv[],
                       void (*usage)(void), tool_common *co)
{
    switch (c) {
    case TOOL_OPT_THREADS:
        return tool_parse_size(t, "--threads", optarg, 1, 4096, &co->threads)
                   ? TOOL_EXIT_USAGE : TOOL_CONTINUE;
    case TOOL_OPT_MAXMEM:
        g_ulimit_left = 0;   /* the limit is the user's now */
        return tool_parse_bytes(t, "--max-memory", optarg, &co->max_bytes)
                   ? TOOL_EXIT_USAGE : TOOL_CONTINUE;
    case 'q':
        t->verbosity = 0;
        return TOOL_CONTINUE;
    case 'v':
        t->verbosity = 2;
        return TOOL_CONTINUE;
    case 'h':
    case TOOL_OPT_HELP:
        usage();
        return TOOL_EXIT_OK;
    case 'V':
    case TOOL_OPT_VERSION:
        tool_print_version(t);
        return TOOL_EXIT_OK;
    case ':':
        return tool_usage_error(t, "option '%s' needs a value", argv[optind - 1]);
    default:
        return tool_usage_error(t, "unknown option '%s'", argv[optind - 1]);
    }
}

/* --msh-version and --msh-binary shape a .msh file only: with another
 * output (stdout is .vtu) they are a usage error, not silently ignored. */
static int tetformat_fits(const tool_ctx *t, const tool_common *co)
{
    const st_tetformat_opts *o = &co->tetformat;
    if (!o->msh_version && !o->binary)
        return TOOL_CONTINUE;
    if (st_tetformat_from_path(co->out) == ST_TETFORMAT_MSH)
        return TOOL_CONTINUE;
    return tool_usage_error(t, "%s shapes a .msh output, not '%s' (give -o FILE.msh)",
                            o->msh_version ? "--msh-version" : "--msh-binary",
                            tool_out_name(co->out));
}

int tool_main(const tool_spec *spec, int argc, char *argv[], void *settings,
              tool_common *co)
{
    tool_ctx t;
    tool_init(&t, spec->name, argc, argv);
    *co = tool_common_default();
    int c, rc = TOOL_CONTINUE;
    /* -h and -V in every tool (help and version, as TetGen, Gmsh and the
     * GNU tools have them). */
    char shortopts[64];
    snprintf(shortopts, sizeof shortopts, "%shV", spec->shortopts);
    opterr = 0;
    while (rc == TOOL_CONTINUE &&
           (c = getopt_long(argc, argv, shortopts, spec->longopts, NULL)) != -1) {
        if (c == 'o')
            co->out = optarg;
        else if (c == TOOL_OPT_MSH_VERSION || c == TOOL_OPT_MSH_BINARY ||
                 c == TOOL_OPT_VOLUME_ONLY)
            rc = tool_tetformat_option(&t, c, optarg, &co->tetformat) ? TOOL_EXIT_USAGE
                                                                       : TOOL_CONTINUE;
        else if (c == 'q' || c == 'v' || c == ':' || c == '?' || c == TOOL_OPT_THREADS ||
                 c == TOOL_OPT_MAXMEM || c == TOOL_OPT_HELP || c == TOOL_OPT_VERSION ||
                 c == 'h' || c == 'V')
            rc = tool_common_option(&t, c, argv, spec->usage, co);
        else
            rc = spec->option(&t, c, optarg, settings);
    }
    if (rc == TOOL_CONTINUE)
        rc = tetformat_fits(&t, co);
    if (rc == TOOL_CONTINUE)
        rc = spec->check(&t, argc, argv, settings);
    if (rc == TOOL_CONTINUE)
        rc = spec->run(&t, settings);
    tool_finish(&t);
    return rc;
}

const char *tool_version(void)
{
    return SOUPTET_VERSION;
}

const char *tool_commit(void)
{
    return SOUPTET_COMMIT;
}

void tool_print_version(const tool_ctx *t)
{
    printf("%s (souptet) %s\ncommit %s\n", t->name, SOUPTET_VERSION, SOUPTET_COMMIT);
}

st_status tool_meta_record(const tool_ctx *t, st_meta *meta)
{
    if (st_meta_set(meta, "version", SOUPTET_VERSION) ||
        st_meta_set(meta, "commit", SOUPTET_COMMIT) ||
        st_meta_history_append(meta, tool_command(t)))
        return ST_ENOMEM;
    return ST_OK;
}

void tool_deprecated(const tool_ctx *t, const char *old_name, const char *new_name)
{
    tool_say(t, 1, "%s is now %s (%s goes in the next release)", old_name, new_name,
             old_name);
}

int tool_report_symmetries(tool_ctx *t, const st_soup *soup, const st_bvh *bvh,
                           double tolerance, const st_symmetry_set *set,
                           const st_symmetry_fill_stats *fill, double seconds)
{
    if (t->verbosity < 2 || !soup || !(tolerance > 0.0))
        return 0;
    st_symmetry_params sp = st_symmetry_params_default();
    st_symmetry_set own;
    if (set->candidates > 0) {
        tool_say(t, 2, "symmetries: %zu accepted (support >= %.2f, or a mirror seldom "
                 "contradicted) within %.6g (%zu candidates measured); fill: %zu triangles from %zu maps, %zu of %zu caps dropped as "
                 "covered (%zu split), %zu kept (the fill agrees with them), %zu of %zu holes too large "
                 "to cap filled, %zu left as they were (the copy itself holed), %.3f s",
                 set->n, sp.min_support, tolerance, set->candidates, fill->triangles,
                 fill->maps, fill->caps_covered, fill->caps, fill->caps_split, fill->caps_agree,
                 fill->open_filled, fill->open, fill->unclosed, seconds);
    } else {
        st_error err;
        st_bvh *built = NULL;
        const double t0 = tool_now();
        if (!bvh && st_bvh_build(&built, soup, &err))
            return tool_fail(t, &err);
        sp.tolerance = tolerance;
        st_status st = st_symmetry_detect(&own, soup, bvh ? bvh : built, &sp, &err);
        st_bvh_free(built);
        if (st)
            return tool_fail(t, &err);
        /* fill->caps without candidates: the gate (symmetry.h) skipped the search */
        char why[160];
        snprintf(why, sizeof why, fill->caps ? "not searched by the signs (no fill could change "
                 "any of the %zu caps by a voxel, and no hole is too large to cap)"
                 : "not used (no holes to fill, or --symmetry off)", fill->caps);
        tool_say(t, 2, "symmetries: %zu accepted (support >= %.2f, or a mirror seldom "
                 "contradicted) within %.6g (%zu candidates measured, %.3f s); %s",
                 own.n, sp.min_support, tolerance, own.candidates, tool_now() - t0, why);
        set = &own;
    }
    for (size_t i = 0; i < set->n; i++) {
        char line[256];
        st_symmetry_describe(set->items + i, line, sizeof line);
        tool_say(t, 2, "  %s", line);
    }
    return 0;
}
