/*
 * tap.h - a few macros that print the Test Anything Protocol, run by prove.
 *
 *   TAP_CHECK(cond, "name %d", x);   prints "ok N - name" or "not ok N - name"
 *   TAP_NEAR(a, b, tol, "name");     |a - b| <= tol, printing both on failure
 *   return tap_done();               prints the plan "1..N", exit status
 *
 * Each program names its tests in a table and hands it to tap_main:
 *
 *   static const tap_test tests[] = {TAP_TEST(sphere), {"bend", bend_cases}, {0}};
 *   return tap_main(argc, argv, tests);
 *
 * so that "test_X" runs them all, "test_X name..." runs those named, in
 * the order given, and "test_X --list" prints the names, one a line. An
 * unknown name or option is an error (exit 2, naming it, nothing run).
 * The plan counts the checks that ran. A program with set-up of its own
 * calls tap_select first (it answers --list and bad names, and exits,
 * before any set-up), then tap_run and tap_done.
 *
 * tap_data(name) is tests/data/name, found from the program's own path
 * (build/tests/test_X, or any build directory's, -> tests/data), so a test
 * runs from any directory; SOUPTET_TESTDATA overrides it. tap_path does
 * the same for any path in the source tree (corpus/bunny.obj).
 */
#ifndef SOUPTET_TESTS_TAP_H
#define SOUPTET_TESTS_TAP_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static int tap_count, tap_failed;

static inline int tap_result(int ok, const char *file, int line)
{
    tap_count++;
    if (!ok)
        tap_failed++;
    printf("%s %d - ", ok ? "ok" : "not ok", tap_count);
    (void)file;
    (void)line;
    return ok;
}

#define TAP_CHECK(cond, ...)                                              \
    do {                                                                  \
        int tap_ok_ = (cond) ? 1 : 0;                                     \
        tap_result(tap_ok_, __FILE__, __LINE__);                          \
        printf(__VA_ARGS__);                                              \
        printf("\n");                                                     \
        if (!tap_ok_)                                                     \
            printf("#   failed at %s:%d: %s\n", __FILE__, __LINE__, #cond); \
    } while (0)

#define TAP_NEAR(a, b, tol, ...)                                          \
    do {                                                                  \
        double tap_a_ = (double)(a), tap_b_ = (double)(b);                \
        int tap_ok_ = fabs(tap_a_ - tap_b_) <= (double)(tol);             \
        tap_result(tap_ok_, __FILE__, __LINE__);                          \
        printf(__VA_ARGS__);                                              \
        printf("\n");                                                     \
        if (!tap_ok_)                                                     \
            printf("#   failed at %s:%d: %.17g vs %.17g (tol %g)\n",      \
                   __FILE__, __LINE__, tap_a_, tap_b_, (double)(tol));    \
    } while (0)

#define TAP_NOTE(...)                                                     \
    do {                                                                  \
        printf("# ");                                                     \
        printf(__VA_ARGS__);                                              \
        printf("\n");                                                     \
    } while (0)

static inline int tap_done(void)
{
    printf("1..%d\n", tap_count);
    return tap_failed ? 1 : 0;
}

/* One test: its name on the command line and the function that runs it. */
typedef struct tap_test {
    const char *name;
    void (*fn)(void);
} tap_test;

/* A table entry for test_NAME(), named NAME. */
#define TAP_TEST(n) {#n, test_##n}

static const char *tap_argv0;
static char **tap_names;   /* the names asked for, or NULL for all */
static int tap_nnames;

static inline const tap_test *tap_find(const tap_test *tests, const char *name)
{
    for (const tap_test *t = tests; t->name; t++)
        if (strcmp(t->name, name) == 0)
            return t;
    return NULL;
}

static inline const char *tap_prog(void)
{
    const char *slash = tap_argv0 ? strrchr(tap_argv0, '/') : NULL;
    return slash ? slash + 1 : tap_argv0 ? tap_argv0 : "test";
}

/* Reads the command line. After --list or --help it exits 0; for an
 * unknown name or option it exits 2, naming it on stderr, before any
 * set-up ran. Otherwise it returns, and tap_run runs what was asked. */
static inline void tap_select(int argc, char **argv, const tap_test *tests)
{
    tap_argv0 = argc > 0 ? argv[0] : NULL;
    if (argc == 2 && (strcmp(argv[1], "--list") == 0 || strcmp(argv[1], "--help") == 0)) {
        if (strcmp(argv[1], "--help") == 0)
            printf("usage: %s [--list | NAME...]: run the tests named (all by default)\n",
                   tap_prog());
        else
            for (const tap_test *t = tests; t->name; t++)
                printf("%s\n", t->name);
        exit(0);
    }
    for (int i = 1; i < argc; i++)
        if (argv[i][0] == '-' || !tap_find(tests, argv[i])) {
            fprintf(stderr, "%s: %s '%s' (--list lists the tests)\n", tap_prog(),
                    argv[i][0] == '-' ? "unknown option" : "no test named", argv[i]);
            exit(2);
        }
    tap_names = argc > 1 ? argv + 1 : NULL;
    tap_nnames = argc > 1 ? argc - 1 : 0;
}

/* Runs the tests tap_select chose: each named, or all in table order. */
static inline void tap_run(const tap_test *tests)
{
    if (!tap_names) {
        for (const tap_test *t = tests; t->name; t++) {
            printf("# %s\n", t->name);
            t->fn();
        }
        return;
    }
    for (int i = 0; i < tap_nnames; i++) {
        const tap_test *t = tap_find(tests, tap_names[i]);
        printf("# %s\n", t->name);
        t->fn();
    }
}

/* tap_select, tap_run and tap_done: the whole main of most programs. */
static inline int tap_main(int argc, char **argv, const tap_test *tests)
{
    tap_select(argc, argv, tests);
    tap_run(tests);
    return tap_done();
}

/* path (relative to the source tree: "corpus/bunny.obj") as seen from
 * here: the tree is the one holding this program (build/tests/test_X ->
 * ../..) when it has tests/data, else the working directory. In a static
 * buffer. */
static inline const char *tap_path(const char *path)
{
    static char out[4096];
    struct stat st;
    char self[4000];
    ssize_t n = readlink("/proc/self/exe", self, sizeof self - 1);
    if (n > 0)
        self[n] = 0;
    else
        snprintf(self, sizeof self, "%s", tap_argv0 ? tap_argv0 : "");
    char *slash = strrchr(self, '/');
    if (slash) {
        *slash = 0;
        snprintf(out, sizeof out, "%s/../../tests/data", self);
        if (stat(out, &st) == 0 && S_ISDIR(st.st_mode)) {
            snprintf(out, sizeof out, "%s/../../%s", self, path);
            return out;
        }
    }
    snprintf(out, sizeof out, "%s", path);
    return out;
}

/* tests/data/name (see the top of this file), in a static buffer. */
static inline const char *tap_data(const char *name)
{
    static char path[4096];
    const char *env = getenv("SOUPTET_TESTDATA");
    snprintf(path, sizeof path, "%.3800s/%.200s", env && *env ? env : tap_path("tests/data"),
             name);
    return path;
}

#endif
