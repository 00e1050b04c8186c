/*
 * test_fuzzregress.c - every fuzzing finding stays fixed.
 *
 * For each reader, every file under tests/data/fuzz/<reader>/ goes through
 * the entry point of its libFuzzer harness (fuzz/fuzz_<reader>.c) and must
 * end in ST_OK with sane output (every index in range, every coordinate
 * finite, counts consistent: the invariants the harnesses assert) or in an
 * error with a message and no object. Never a crash, a leak or a sanitizer
 * report: `make config=sanitize check` runs this under ASan/UBSan.
 *
 * The files are read in child processes (this program again, with
 * --batch READER DIR FIRST), one per reader, and after a crash another
 * from the next file: a crash names its file, shows its sanitizer report
 * as TAP comments and does not hide the other files. In a sanitized build
 * LeakSanitizer checks after every file (and at the child's exit); the
 * library-internal OpenVDB/VTK leaks are suppressed by tests/lsan.supp,
 * which `make check` passes in LSAN_OPTIONS.
 *
 * One outcome is marked TODO instead of failing: under ASan, OpenVDB 10's
 * io::bloscFromStream asks operator new[] for the buffer size a block
 * header claims; glibc's new throws std::bad_alloc, which the adapter
 * turns into an error (the release build passes these files), but ASan's
 * throwing new reports out-of-memory and aborts, whatever
 * allocator_may_return_null says. io::Stream's constructor does the same
 * with a count from the stream header. Only that exact report (allocator
 * out of memory, the caller of operator new an OpenVDB function) is
 * excused.
 *
 * Findings whose fix is pending in a file this work does not own are
 * listed in tests/data/fuzz/todo.txt ("<reader>/<file> <reason>"): a bad
 * verdict (never a crash or a sanitizer report) on one of them is a TAP
 * TODO, so `make check` stays green until the fix lands.
 *
 * The data directory: $SOUPTET_FUZZ_DATA, else tests/data/fuzz beside the
 * build directory holding this binary (BUILD/tests/test_fuzzregress ->
 * ../../tests/data/fuzz), else tests/data/fuzz from the current directory
 * (make check runs from the top). A reader whose directory is absent is a
 * TAP SKIP; an empty directory (vti/ and vtu/ may be, for a while) passes
 * with nothing to run.
 */
#define FUZZ_NO_ENTRY
#include "../fuzz/fuzz_tet.h"
#include "souptet/grid.h"
#include "souptet/soup.h"
#include "souptet/tetio.h"
#include "../src/adapters/gridio_internal.h"
#include "../src/adapters/tetio_internal.h"
#include "tap.h"

#include <dirent.h>
#include <errno.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

/* As the field and tet harnesses: impossible malloc sizes come back NULL,
 * as glibc's do, instead of aborting (see fuzz/fuzz_grid.h). */
const char *__asan_default_options(void);
const char *__asan_default_options(void)
{
    return "allocator_may_return_null=1";
}

typedef enum kind { K_SOUP, K_GRID, K_TET } kind;

typedef struct reader {
    const char *dir;      /* tests/data/fuzz/<dir>/ */
    kind k;
    st_soup_format soup;  /* K_SOUP; UNKNOWN: sniffed, as on stdin */
    st_status (*grid)(st_grid **, const unsigned char *, size_t,
                      const char *, size_t, st_error *);
    st_status (*tet)(st_tetmesh **, const unsigned char *, size_t,
                     size_t, st_error *);
} reader;

/* The ASan report `rep` is "allocator is out of memory" in operator new
 * or new[] called directly from OpenVDB (frame #1), the one excused crash. */
static int openvdb_sized_new(const char *rep)
{
    if (!strstr(rep, "allocator is out of memory"))
        return 0;
    const char *f1 = strstr(rep, "    #1 ");
    if (!f1)
        return 0;
    const char *eol = strchr(f1, '\n');
    size_t n = eol ? (size_t)(eol - f1) : strlen(f1);
    char line[1024];
    if (n >= sizeof line)
        n = sizeof line - 1;
    memcpy(line, f1, n);
    line[n] = '\0';
    return strstr(line, " in openvdb::") != NULL;
}

static st_status tet_msh(st_tetmesh **m, const unsigned char *d, size_t n,
                         size_t max, st_error *e)
{
    return st_tetmesh_parse_msh(m, d, n, "fuzz.msh", max, e);
}

static st_status tet_medit(st_tetmesh **m, const unsigned char *d, size_t n,
                           size_t max, st_error *e)
{
    return st_tetmesh_parse_medit(m, d, n, "fuzz.mesh", max, e);
}

static st_status tet_vtu(st_tetmesh **m, const unsigned char *d, size_t n,
                         size_t max, st_error *e)
{
    return st_tetio_read_vtu_mem(m, d, n, "fuzz.vtu", max, e);
}

static st_status tet_sniff(st_tetmesh **m, const unsigned char *d, size_t n,
                           size_t max, st_error *e)
{
    return st_tetmesh_read_mem(m, d, n, "<stdin>", max, e);
}

static const reader k_readers[] = {
    {"obj", K_SOUP, ST_SOUP_OBJ, NULL, NULL},
    {"off", K_SOUP, ST_SOUP_OFF, NULL, NULL},
    {"ply", K_SOUP, ST_SOUP_PLY, NULL, NULL},
    {"stl", K_SOUP, ST_SOUP_STL, NULL, NULL},
    {"gltf", K_SOUP, ST_SOUP_GLTF, NULL, NULL},
    /* A surface on stdin: the format sniffed (fuzz/fuzz_soupsniff.c). */
    {"soupsniff", K_SOUP, ST_SOUP_UNKNOWN, NULL, NULL},
    {"vdb", K_GRID, 0, st_gridio_read_vdb_mem, NULL},
    {"vti", K_GRID, 0, st_gridio_read_vti_mem, NULL},
    {"msh", K_TET, 0, NULL, tet_msh},
    {"medit", K_TET, 0, NULL, tet_medit},
    {"tetgen", K_TET, 0, NULL, fuzz_tet_parse_tetgen},
    {"vtu", K_TET, 0, NULL, tet_vtu},
    /* VTU findings not yet in vtu/ (whose owner is another engineer). */
    {"vtu-new", K_TET, 0, NULL, tet_vtu},
    {"tetmesh", K_TET, 0, NULL, tet_sniff},
};

/* The checks of fuzz/fuzz_soup.h. */
static const char *soup_verdict(st_status s, st_soup *p, const st_error *e)
{
    const char *why = NULL;
    if (s == ST_OK) {
        if (!p || p->ntris == 0)
            why = "ST_OK without triangles";
        for (size_t i = 0; !why && i < 3 * p->ntris; i++)
            if (p->tris[i] >= p->nverts)
                why = "triangle index out of range";
        for (size_t i = 0; !why && i < 3 * p->nverts; i++)
            if (!isfinite(p->xyz[i]))
                why = "non-finite coordinate";
    } else if (p) {
        why = "an error with a soup";
    } else if (!e->msg[0]) {
        why = "an error without a message";
    }
    st_soup_free(p);
    return why;
}

/* The checks of fuzz/fuzz_grid.h. */
static const char *grid_verdict(st_status s, st_grid *g, const st_error *e)
{
    const char *why = NULL;
    if (s == ST_OK) {
        if (!g || g->nx == 0 || g->ny == 0 || g->nz == 0 || !(g->voxel > 0.0))
            why = "ST_OK with an empty grid or a bad voxel size";
        else {
            size_t n = st_grid_count(g);
            volatile float sum = 0.0f;
            for (size_t i = 0; i < n; i++)
                sum += g->data[i];
            (void)sum;
        }
    } else if (g) {
        why = "an error with a grid";
    } else if (!e->msg[0]) {
        why = "an error without a message";
    }
    st_grid_free(g);
    return why;
}

/* LeakSanitizer's check between files, when this is a sanitized build
 * (weak: NULL otherwise). Nonzero when it found (and reported) a leak. */
int __lsan_do_recoverable_leak_check(void) __attribute__((weak));

/* In the child: read one input. NULL when the verdict is good (outcome
 * says what happened), else why not. */
static const char *run_one(const reader *r, const unsigned char *d,
                           size_t n, char *outcome, size_t outcome_size)
{
    st_error e;
    memset(&e, 0, sizeof e);
    const char *why;
    st_status s;
    if (r->k == K_SOUP) {
        st_soup *p = NULL;
        st_soup_format f = r->soup != ST_SOUP_UNKNOWN
                               ? r->soup
                               : st_soup_format_sniff(d, n);
        s = st_soup_parse(&p, f, d, n, "fuzz", &e);
        why = soup_verdict(s, p, &e);
    } else if (r->k == K_GRID) {
        st_grid *g = NULL;
        s = r->grid(&g, d, n, "fuzz", FUZZ_MAX_BYTES, &e);
        why = grid_verdict(s, g, &e);
    } else {
        st_tetmesh *m = NULL;
        s = r->tet(&m, d, n, FUZZ_MAX_BYTES, &e);
        why = fuzz_tet_verdict(s, m, &e);
    }
    snprintf(outcome, outcome_size, "%s%s%.200s (status %d)",
             s == ST_OK ? "read" : "refused", s == ST_OK ? "" : ": ",
             s == ST_OK ? "" : e.msg, (int)s);
    return why;
}

static unsigned char *slurp_file(const char *path, size_t *size)
{
    FILE *fp = fopen(path, "rb");
    if (!fp)
        return NULL;
    size_t cap = 1 << 16, n = 0;
    unsigned char *b = malloc(cap);
    while (b) {
        if (n == cap) {
            unsigned char *nb = realloc(b, cap *= 2);
            if (!nb) {
                free(b);
                b = NULL;
                break;
            }
            b = nb;
        }
        size_t got = fread(b + n, 1, cap - n, fp);
        n += got;
        if (got == 0)
            break;
    }
    fclose(fp);
    if (!b)
        return NULL;
    /* An exact-size copy, so ASan sees any overread past the end. */
    unsigned char *exact = malloc(n ? n : 1);
    if (exact)
        memcpy(exact, b, n);
    free(b);
    *size = n;
    return exact;
}

/* Read all of fd into a growing buffer (NUL-terminated). */
static char *slurp_fd(int fd)
{
    size_t cap = 4096, n = 0;
    char *b = malloc(cap);
    if (!b)
        return NULL;
    for (;;) {
        if (n + 1 == cap) {
            char *nb = realloc(b, cap *= 2);
            if (!nb) {
                free(b);
                return NULL;
            }
            b = nb;
        }
        ssize_t got = read(fd, b + n, cap - 1 - n);
        if (got < 0 && errno == EINTR)
            continue;
        if (got <= 0)
            break;
        n += (size_t)got;
    }
    b[n] = '\0';
    return b;
}

/* Print text[0..len) as TAP comments (at most 60 lines). */
static void note_lines(const char *text, size_t len)
{
    int lines = 0;
    const char *end = text + len;
    for (const char *p = text; p < end && lines < 60; lines++) {
        const char *nl = memchr(p, '\n', (size_t)(end - p));
        size_t l = nl ? (size_t)(nl - p) : (size_t)(end - p);
        if (l)
            printf("#   %.*s\n", (int)l, p);
        p += l + 1;
    }
}

static int cmp_names(const void *a, const void *b)
{
    return strcmp(*(char *const *)a, *(char *const *)b);
}

/* The regular files of dir, sorted; NULL and *n = 0 when dir is absent
 * (*absent = 1). */
static char **list_files(const char *dir, size_t *n, int *absent)
{
    *n = 0;
    *absent = 0;
    DIR *dp = opendir(dir);
    if (!dp) {
        *absent = 1;
        return NULL;
    }
    char **names = NULL;
    size_t cap = 0;
    struct dirent *de;
    while ((de = readdir(dp)) != NULL) {
        char path[8192];
        struct stat st;
        int w = snprintf(path, sizeof path, "%s/%s", dir, de->d_name);
        if (de->d_name[0] == '.' || w < 0 || (size_t)w >= sizeof path ||
            stat(path, &st) != 0 || !S_ISREG(st.st_mode))
            continue;
        if (*n == cap) {
            cap = cap ? 2 * cap : 64;
            char **nb = realloc(names, cap * sizeof *names);
            if (!nb)
                break;
            names = nb;
        }
        if ((names[*n] = strdup(de->d_name)) != NULL)
            (*n)++;
    }
    closedir(dp);
    if (*n)
        qsort(names, *n, sizeof *names, cmp_names);
    return names;
}

static const reader *find_reader(const char *name)
{
    for (size_t i = 0; i < sizeof k_readers / sizeof k_readers[0]; i++)
        if (strcmp(k_readers[i].dir, name) == 0)
            return &k_readers[i];
    return NULL;
}

/* The child: test_fuzzregress --batch READER DIR FIRST reads the files of
 * DIR from the FIRST (in sorted order) on, saying "@@ begin I" before
 * file I and "@@ done I ok|bad|leak outcome" after it. A crash ends it
 * inside a file; the parent then starts another from the next file. It
 * exits normally, so LeakSanitizer also checks at the end. */
static int batch(const char *rname, const char *dir, size_t first)
{
    const reader *r = find_reader(rname);
    size_t n;
    int absent;
    char **names = list_files(dir, &n, &absent);
    if (!r)
        return 2;
    for (size_t i = first; i < n; i++) {
        char path[8192], outcome[512];
        snprintf(path, sizeof path, "%s/%s", dir, names[i]);
        printf("@@ begin %zu\n", i);
        fflush(stdout);
        size_t size = 0;
        unsigned char *data = slurp_file(path, &size);
        const char *why = "cannot read the file";
        snprintf(outcome, sizeof outcome, "%s", strerror(errno));
        if (data)
            why = run_one(r, data, size, outcome, sizeof outcome);
        free(data);
        int leak = __lsan_do_recoverable_leak_check &&
                   __lsan_do_recoverable_leak_check() != 0;
        fflush(stderr);
        printf("@@ done %zu %s %s%s%s\n", i, why ? "bad" : leak ? "leak" : "ok",
               outcome, why ? ": " : "", why ? why : "");
        fflush(stdout);
        /* After a leak, a fresh process for the next file: every later
         * check (and the one at exit) would report the same leak again. */
        if (leak)
            _exit(0);
    }
    for (size_t i = 0; i < n; i++)
        free(names[i]);
    free(names);
    return 0;
}

static const char *g_self;

/* tests/data/fuzz/todo.txt: "<reader>/<file> <reason>" lines, findings
 * whose fix is pending elsewhere; their bad verdicts are TODO. */
static char *g_todo;

static void load_todo(const char *base)
{
    char path[4200];
    snprintf(path, sizeof path, "%s/todo.txt", base);
    size_t n = 0;
    unsigned char *t = slurp_file(path, &n);
    if (!t)
        return;
    g_todo = malloc(n + 2);
    if (g_todo) {
        g_todo[0] = '\n';   /* every entry is found as "\nreader/file " */
        memcpy(g_todo + 1, t, n);
        g_todo[n + 1] = '\0';
    }
    free(t);
}

/* The reason listed for reader/file, or NULL; *len its length. */
static const char *todo_reason(const char *rdir, const char *file, int *len)
{
    if (!g_todo)
        return NULL;
    char key[600];
    snprintf(key, sizeof key, "\n%s/%s ", rdir, file);
    const char *p = strstr(g_todo, key);
    if (!p)
        return NULL;
    p += strlen(key);
    *len = (int)strcspn(p, "\n");
    return p;
}

/* Start a batch child from file first; its combined stdout and stderr
 * whole, and its wait status. */
static char *run_batch(const reader *r, const char *dir, size_t first,
                       int *status)
{
    int fds[2];
    *status = -1;
    if (pipe(fds) != 0)
        return NULL;
    char firsts[32];
    snprintf(firsts, sizeof firsts, "%zu", first);
    fflush(stdout);
    pid_t pid = fork();
    if (pid == 0) {
        /* A fresh process (exec, not only fork): the libraries start
         * threads when they load (log4cplus, for OpenVDB), and a forked
         * copy without them hangs in their exit handlers. */
        close(fds[0]);
        dup2(fds[1], 1);
        dup2(fds[1], 2);
        close(fds[1]);
        char *args[] = {(char *)g_self, "--batch", (char *)r->dir,
                        (char *)dir, firsts, NULL};
        execv("/proc/self/exe", args);
        fprintf(stderr, "cannot run %s: %s\n", g_self, strerror(errno));
        _exit(127);
    }
    close(fds[1]);
    char *out = pid > 0 ? slurp_fd(fds[0]) : NULL;
    close(fds[0]);
    while (pid > 0 && waitpid(pid, status, 0) < 0 && errno == EINTR)
        ;
    return out;
}

/* Every file of base/r->dir through r, one TAP line each. */
static void run_reader(const char *base, const reader *r)
{
    char dir[4096];
    int w = snprintf(dir, sizeof dir, "%s/%s", base, r->dir);
    if (w < 0 || (size_t)w >= sizeof dir) {
        TAP_CHECK(0, "%s: data directory name too long", r->dir);
        return;
    }
    size_t n;
    int absent;
    char **names = list_files(dir, &n, &absent);
    if (absent) {
        printf("ok %d - %s # SKIP no directory %s\n", ++tap_count, r->dir,
               dir);
        return;
    }
    if (n == 0)
        printf("ok %d - %s: no files in %s yet\n", ++tap_count, r->dir, dir);
    size_t next = 0;
    while (next < n) {
        int status;
        char *out = run_batch(r, dir, next, &status);
        if (!out) {
            TAP_CHECK(0, "%s: cannot start a child: %s", r->dir,
                      strerror(errno));
            break;
        }
        const char *p = out;
        size_t file = next;
        int ended_inside = 1;
        for (; file < n; file++) {
            char tag[64];
            snprintf(tag, sizeof tag, "@@ begin %zu\n", file);
            const char *b = strstr(p, tag);
            if (!b)
                break;   /* the child died before this file */
            b += strlen(tag);
            snprintf(tag, sizeof tag, "@@ done %zu ", file);
            const char *d = strstr(b, tag);
            if (!d) {
                /* Died inside this file: its report follows the begin. */
                const char *rep = b;
                if (openvdb_sized_new(rep)) {
                    printf("not ok %d - %s/%s: OpenVDB's new of a size "
                           "read from the file # TODO ASan's throwing new "
                           "aborts where glibc's throws std::bad_alloc\n",
                           ++tap_count, r->dir, names[file]);
                } else {
                    TAP_CHECK(0, "%s/%s: crashed", r->dir, names[file]);
                    if (WIFSIGNALED(status))
                        TAP_NOTE("killed by signal %d", WTERMSIG(status));
                    else if (WIFEXITED(status))
                        TAP_NOTE("exit status %d", WEXITSTATUS(status));
                    note_lines(rep, strlen(rep));
                }
                file++;
                ended_inside = 1;
                break;
            }
            const char *verdict = d + strlen(tag);
            size_t vlen = strcspn(verdict, "\n");
            size_t wlen = strcspn(verdict, " \n");   /* ok, bad or leak */
            int ok = wlen == 2 && strncmp(verdict, "ok", 2) == 0;
            const char *what = verdict + wlen + (verdict[wlen] == ' ');
            int rlen = 0;
            const char *reason = todo_reason(r->dir, names[file], &rlen);
            if (reason && wlen == 3) {   /* "bad": a listed, open finding */
                printf("not ok %d - %s/%s: %.*s # TODO %.*s\n", ++tap_count,
                       r->dir, names[file], (int)(verdict + vlen - what),
                       what, rlen, reason);
            } else {
                TAP_CHECK(ok, "%s/%s: %s%.*s", r->dir, names[file],
                          ok ? "" : wlen == 4 ? "LEAK: " : "BAD VERDICT: ",
                          (int)(verdict + vlen - what), what);
                if (!ok)
                    note_lines(b, (size_t)(d - b));
            }
            p = verdict + vlen;
            ended_inside = 0;
        }
        if (!ended_inside && file == n &&
            !(WIFEXITED(status) && WEXITSTATUS(status) == 0)) {
            /* Every file done, then a failure at exit (a leak
             * LeakSanitizer found at the end). */
            TAP_CHECK(0, "%s: the reading process failed at exit", r->dir);
            note_lines(p, strlen(p));
        }
        if (file == next) {
            /* Not even the first file began: do not loop. */
            TAP_CHECK(0, "%s: the child did not start", r->dir);
            note_lines(out, strlen(out));
            file = n;
        }
        free(out);
        next = file;
    }
    for (size_t i = 0; i < n; i++)
        free(names[i]);
    free(names);
}

/* The data directory (see the top of this file). */
static void find_data(char *dir, size_t n, const char *argv0)
{
    const char *env = getenv("SOUPTET_FUZZ_DATA");
    struct stat st;
    if (env && *env) {
        snprintf(dir, n, "%s", env);
        return;
    }
    const char *slash = argv0 ? strrchr(argv0, '/') : NULL;
    if (slash) {
        snprintf(dir, n, "%.*s/../../tests/data/fuzz",
                 (int)(slash - argv0), argv0);
        if (stat(dir, &st) == 0 && S_ISDIR(st.st_mode))
            return;
    }
    snprintf(dir, n, "tests/data/fuzz");
}

/* One test a reader, named for its directory. */
static char g_base[4096];
#define READER_TEST(fn, name)                      \
    static void fn(void)                           \
    {                                              \
        run_reader(g_base, find_reader(name));     \
    }
READER_TEST(test_obj, "obj")
READER_TEST(test_off, "off")
READER_TEST(test_ply, "ply")
READER_TEST(test_stl, "stl")
READER_TEST(test_gltf, "gltf")
READER_TEST(test_soupsniff, "soupsniff")
READER_TEST(test_vdb, "vdb")
READER_TEST(test_vti, "vti")
READER_TEST(test_msh, "msh")
READER_TEST(test_medit, "medit")
READER_TEST(test_tetgen, "tetgen")
READER_TEST(test_vtu, "vtu")
READER_TEST(test_vtu_new, "vtu-new")
READER_TEST(test_tetmesh, "tetmesh")

int main(int argc, char **argv)
{
    static const tap_test tests[] = {TAP_TEST(obj), TAP_TEST(off), TAP_TEST(ply), TAP_TEST(stl),
                                     TAP_TEST(gltf), TAP_TEST(soupsniff), TAP_TEST(vdb),
                                     TAP_TEST(vti), TAP_TEST(msh), TAP_TEST(medit),
                                     TAP_TEST(tetgen), TAP_TEST(vtu), {"vtu-new", test_vtu_new},
                                     TAP_TEST(tetmesh), {0}};
    g_self = argv[0];
    if (argc == 5 && strcmp(argv[1], "--batch") == 0)
        return batch(argv[2], argv[3], (size_t)strtoull(argv[4], NULL, 10));
    tap_select(argc, argv, tests);
    /* A child that dies must not kill the run with SIGPIPE on our side. */
    signal(SIGPIPE, SIG_IGN);
    find_data(g_base, sizeof g_base, argv[0]);
    TAP_NOTE("fuzz regression inputs from %s", g_base);
    load_todo(g_base);
    tap_run(tests);
    free(g_todo);
    return tap_done();
}
