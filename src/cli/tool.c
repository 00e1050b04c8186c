/* tool.c - shared tool plumbing (see tool.h). */
#define _GNU_SOURCE
#include "tool.h"
#include "souptet/outfile.h"

#include <errno.h>
#include <getopt.h>
#include <limits.h>
#include <math.h>
#include <signal.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>
#ifdef _OPENMP
#include <omp.h>
#endif

static const char *g_name = "souptet";
static char *g_command_line;   /* freed at exit, whatever path main takes */
static int g_progress_drawn;
static double g_progress_last;

static void on_signal(int sig)
{
    st_outfile_unlink_pending();
    signal(sig, SIG_DFL);
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

void tool_init(tool_ctx *t, const char *name, int argc, char *argv[])
{
    t->name = name;
    g_name = name;
    t->verbosity = 1;
    t->command_line = g_command_line = st_command_line(argc, argv);
    atexit(free_command_line);
    t->t0 = tool_now();
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_signal;
    sigemptyset(&sa.sa_mask);
    int sigs[] = {SIGINT, SIGTERM, SIGHUP, SIGPIPE};
    for (size_t i = 0; i < sizeof sigs / sizeof sigs[0]; i++)
        sigaction(sigs[i], &sa, NULL);
}

void tool_finish(tool_ctx *t)
{
    free_command_line();
    t->command_line = NULL;
}

int tool_fail(const tool_ctx *t, const st_error *err)
{
    char buf[1200];
    tool_progress_end((tool_ctx *)t);
    fprintf(stderr, "%s: %s\n", t->name, st_error_format(err, buf, sizeof buf));
    return TOOL_EXIT_FAIL;
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
    if (pages <= 0 || size <= 0)
        return 0;
    return (size_t)((double)pages * (double)size * 0.8);
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

static void progress_draw(void *ctx, const char *stage, double fraction)
{
    (void)ctx;
    double now = tool_now();
    /* Ten redraws a second are plenty for a person. */
    if (fraction < 1.0 && g_progress_drawn && now - g_progress_last < 0.1)
        return;
    g_progress_last = now;
    fprintf(stderr, "\r%s: %s %3.0f%%\033[K", g_name, stage, 100.0 * fraction);
    fflush(stderr);
    g_progress_drawn = 1;
}

st_progress tool_progress(tool_ctx *t)
{
    st_progress p = {NULL, NULL};
    if (t->verbosity >= 1 && isatty(STDERR_FILENO)) {
        p.fn = progress_draw;
        p.ctx = t;
    }
    return p;
}

void tool_progress_end(tool_ctx *t)
{
    (void)t;
    if (g_progress_drawn) {
        fprintf(stderr, "\r\033[K");
        fflush(stderr);
        g_progress_drawn = 0;
    }
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

tool_common tool_common_default(void)
{
    tool_common co;
    co.threads = 0;
    co.max_bytes = tool_default_max_memory();
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
        return tool_parse_bytes(t, "--max-memory", optarg, &co->max_bytes)
                   ? TOOL_EXIT_USAGE : TOOL_CONTINUE;
    case 'q':
        t->verbosity = 0;
        return TOOL_CONTINUE;
    case 'v':
        t->verbosity = 2;
        return TOOL_CONTINUE;
    case TOOL_OPT_HELP:
        usage();
        return TOOL_EXIT_OK;
    case TOOL_OPT_VERSION:
        tool_print_version(t);
        return TOOL_EXIT_OK;
    case ':':
        return tool_usage_error(t, "option '%s' needs a value", argv[optind - 1]);
    default:
        return tool_usage_error(t, "unknown option '%s'", argv[optind - 1]);
    }
}

void tool_print_version(const tool_ctx *t)
{
    printf("%s (souptet) %s\n", t->name, SOUPTET_VERSION);
}
