/* test_core.c - errors, checked sizes, metadata, grids, atomic output. */
#include "souptet/err.h"
#include "souptet/grid.h"
#include "souptet/mem.h"
#include "souptet/meta.h"
#include "souptet/outfile.h"
#include "tap.h"

#include <errno.h>
#include <limits.h>
#include <signal.h>
#include <stdio.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

static void test_error_format(void)
{
    st_error e;
    char buf[256];
    st_error_set(&e, ST_EINPUT, "m.obj", 12, "face index %d out of range", 9);
    TAP_CHECK(strcmp(st_error_format(&e, buf, sizeof buf),
                     "m.obj:12: face index 9 out of range") == 0,
              "text errors read FILE:LINE: what (%s)", buf);
    st_error_set_offset(&e, ST_EINPUT, "m.stl", 80, "count disagrees");
    TAP_CHECK(strcmp(st_error_format(&e, buf, sizeof buf),
                     "m.stl: byte 80: count disagrees") == 0,
              "binary errors name the byte offset (%s)", buf);
    st_error_set(&e, ST_EIO, "x", 0, "gone");
    TAP_CHECK(strcmp(st_error_format(&e, buf, sizeof buf), "x: gone") == 0,
              "errors without a place read FILE: what");
    TAP_CHECK(st_error_set(NULL, ST_ENOMEM, NULL, 0, "x") == ST_ENOMEM,
              "a NULL error record still returns the status");
}

static void test_checked_sizes(void)
{
    size_t r = 7;
    TAP_CHECK(st_size_mul(&r, SIZE_MAX / 2 + 1, 2) == -1 && r == 7,
              "overflowing multiplication is refused and leaves the result");
    TAP_CHECK(st_size_mul(&r, 1u << 20, 1u << 10) == 0 && r == (size_t)1 << 30,
              "exact multiplication");
    TAP_CHECK(st_size_add(&r, SIZE_MAX, 1) == -1, "overflowing addition is refused");
    TAP_CHECK(st_malloc_array((size_t)1 << 62, 16) == NULL,
              "an array whose byte size overflows is never allocated");
    void *p = st_malloc_array(0, 8);
    TAP_CHECK(p != NULL, "zero elements give a valid pointer");
    free(p);
}

/* VmFlags of the mapping that holds p ("" when /proc/self/smaps cannot
 * be read). */
static void vm_flags_of(const void *p, char *flags, size_t n)
{
    flags[0] = 0;
    FILE *f = fopen("/proc/self/smaps", "r");
    if (!f)
        return;
    char line[512];
    int in = 0;
    uintptr_t a = (uintptr_t)p;
    while (fgets(line, sizeof line, f)) {
        unsigned long lo, hi;
        if (sscanf(line, "%lx-%lx ", &lo, &hi) == 2)
            in = a >= lo && a < hi;
        else if (in && strncmp(line, "VmFlags:", 8) == 0) {
            snprintf(flags, n, "%s", line + 8);
            break;
        }
    }
    fclose(f);
}

/* st_realloc_big: a block grown by doubling from 1 KiB to 64 MiB keeps
 * its bytes, and its large part is advised to use huge pages ("hg" in the
 * mapping's VmFlags, where the kernel has transparent huge pages). */
static void test_realloc_big(void)
{
    unsigned char *p = NULL;
    size_t n = 0, bad = 0;
    for (size_t cap = 1024; cap <= ((size_t)64 << 20); cap *= 2) {
        unsigned char *q = st_realloc_big(p, cap);
        if (!q)
            break;
        p = q;
        for (size_t i = 0; i < n; i++)
            bad += p[i] != (unsigned char)(i * 7 + i / 4096);
        for (size_t i = n; i < cap; i++)
            p[i] = (unsigned char)(i * 7 + i / 4096);
        n = cap;
    }
    TAP_CHECK(n == ((size_t)64 << 20) && bad == 0,
              "a doubling block keeps its bytes up to 64 MiB (%zu wrong)", bad);
    char flags[512];
    vm_flags_of(p + n / 2, flags, sizeof flags);
    FILE *thp = fopen("/sys/kernel/mm/transparent_hugepage/enabled", "r");
    if (thp && flags[0])
        TAP_CHECK(strstr(flags, " hg") != NULL,
                  "its middle is advised to use huge pages (VmFlags:%s)", flags);
    else
        TAP_NOTE("no transparent huge pages or no /proc/self/smaps: advice not checked");
    if (thp)
        fclose(thp);
    free(p);
}

/* The array allocators: from 1 MiB on a block is whole 2 MiB pages
 * advised to be transparent huge pages ("hg"), a calloc'd one is zero
 * even where a freed dirty block is reused, and realloc keeps the bytes
 * across both sides of that size. */
static void test_array_huge(void)
{
    const size_t n = (size_t)3 << 20;
    unsigned char *d = st_malloc_array(n, 1);
    TAP_CHECK(d != NULL, "a 3 MiB array");
    if (!d)
        return;
    memset(d, 0xab, n);
    char flags[512];
    vm_flags_of(d + n / 2, flags, sizeof flags);
    FILE *thp = fopen("/sys/kernel/mm/transparent_hugepage/enabled", "r");
    if (thp && flags[0])
        TAP_CHECK(strstr(flags, " hg") != NULL,
                  "a 3 MiB array is advised to use huge pages (VmFlags:%s)", flags);
    else
        TAP_NOTE("no transparent huge pages or no /proc/self/smaps: advice not checked");
    if (thp)
        fclose(thp);
    free(d);
    size_t nonzero = 0;
    uint32_t *z = st_calloc_array(n / 4, 4);
    for (size_t i = 0; z && i < n / 4; i++)
        nonzero += z[i] != 0;
    TAP_CHECK(z && nonzero == 0, "a 3 MiB calloc'd array is zero (%zu words not)", nonzero);
    free(z);
    size_t bad = 0, have = 0;
    unsigned char *p = NULL;
    for (size_t cap = (size_t)1 << 19; cap <= ((size_t)16 << 20); cap *= 2) {
        unsigned char *q = st_realloc_array(p, cap, 1);
        if (!q)
            break;
        p = q;
        for (size_t i = 0; i < have; i++)
            bad += p[i] != (unsigned char)(i * 13 + i / 4096);
        for (size_t i = have; i < cap; i++)
            p[i] = (unsigned char)(i * 13 + i / 4096);
        have = cap;
    }
    TAP_CHECK(have == ((size_t)16 << 20) && bad == 0,
              "an array grown 512 KiB -> 16 MiB keeps its bytes (%zu wrong)", bad);
    free(p);
}

static void test_meta(void)
{
    st_meta m = {0};
    st_meta_set(&m, "source", "a.obj");
    st_meta_set(&m, "source", "b.obj");
    TAP_CHECK(m.count == 1 && strcmp(st_meta_get(&m, "source"), "b.obj") == 0,
              "setting a key again replaces its value");
    st_meta_history_append(&m, "soupdist a.obj");
    st_meta_history_append(&m, "soupsign");
    TAP_CHECK(strcmp(st_meta_get(&m, "history"), "soupdist a.obj\nsoupsign") == 0,
              "history lines accumulate, one per tool");
    st_meta c = {0};
    st_meta_copy(&c, &m);
    st_meta_clear(&m);
    TAP_CHECK(c.count == 2 && strcmp(st_meta_get(&c, "source"), "b.obj") == 0,
              "a copy outlives its original");
    TAP_CHECK(st_meta_get(&c, "missing") == NULL, "a missing key is NULL");
    /* A tool's output inherits its input's keys; its own win. */
    st_meta own = {0};
    st_meta_set(&own, "h", "0.5");
    st_meta_set(&own, "source", "mine.obj");
    st_meta_inherit(&own, &c);
    TAP_CHECK(own.count == 3 && strcmp(own.entries[0].key, "source") == 0 &&
              strcmp(own.entries[0].value, "mine.obj") == 0 &&
              strcmp(own.entries[1].key, "history") == 0 &&
              strcmp(own.entries[2].key, "h") == 0 && strcmp(own.entries[2].value, "0.5") == 0,
              "inherit: the input's keys in its order, the output's values win, its new keys last");
    st_meta_clear(&own);
    st_meta_clear(&c);
    char *argv[] = {"soupdist", "-o", "my file.vdb", "it's", "x\ny"};
    char *cl = st_command_line(5, argv);
    TAP_CHECK(strcmp(cl, "soupdist -o 'my file.vdb' 'it'\\''s' 'x y'") == 0,
              "command lines are shell-quoted on one line (%s)", cl);
    free(cl);
}

static void test_grid(void)
{
    st_grid *g;
    st_error e;
    const double o[3] = {1.0, -2.0, 0.5};
    TAP_CHECK(st_grid_new(&g, 4, 3, 2, o, 0.25, 7.0f, 0, &e) == ST_OK, "grid 4x3x2");
    TAP_CHECK(st_grid_count(g) == 24 && st_grid_index(g, 3, 2, 1) == 23 &&
              st_grid_index(g, 1, 0, 0) == 1 && st_grid_index(g, 0, 1, 0) == 4 &&
              st_grid_index(g, 0, 0, 1) == 12, "x fastest, then y, then z");
    double p[3];
    st_grid_center(g, 2, 1, 1, p);
    TAP_CHECK(p[0] == 1.5 && p[1] == -1.75 && p[2] == 0.75,
              "voxel centers are origin + voxel * index");
    TAP_CHECK(g->data[17] == 7.0f && isinf(g->band) && g->kind == ST_GRID_UNKNOWN,
              "filled, no band, no kind yet");
    st_grid_free(g);
    TAP_CHECK(st_grid_new(&g, 0, 3, 2, o, 0.25, 0, 0, &e) == ST_EINPUT, "zero-size grid refused: %s", e.msg);
    TAP_CHECK(st_grid_new(&g, 2, 3, 2, o, 0.0, 0, 0, &e) == ST_EINPUT, "voxel size 0 refused: %s", e.msg);
    TAP_CHECK(st_grid_new(&g, 2, 3, 2, o, -1.0, 0, 0, &e) == ST_EINPUT, "negative voxel size refused");
    TAP_CHECK(st_grid_new(&g, SIZE_MAX / 2, SIZE_MAX / 2, 2, o, 1.0, 0, 0, &e) == ST_ELIMIT,
              "overflowing grid size refused: %s", e.msg);
    TAP_CHECK(st_grid_new(&g, 1000, 1000, 1000, o, 1.0, 0, 1u << 20, &e) == ST_ELIMIT &&
              strstr(e.msg, "max-memory") != NULL,
              "a grid over the limit is refused, saying what to change: %s", e.msg);
    TAP_CHECK(st_grid_kind_from_name(st_grid_kind_name(ST_GRID_SIGNED)) == ST_GRID_SIGNED &&
              st_grid_kind_from_name("nonsense") == ST_GRID_UNKNOWN, "kind names round-trip");
}

static void test_outfile(void)
{
    char dir[] = "/tmp/souptet-outfile.XXXXXX";
    TAP_CHECK(mkdtemp(dir) != NULL, "temp dir");
    char path[256];
    snprintf(path, sizeof path, "%s/out.txt", dir);
    st_outfile o;
    st_error e;
    TAP_CHECK(st_outfile_begin(&o, path, 1, &e) == ST_OK, "begin");
    struct stat st;
    TAP_CHECK(stat(path, &st) != 0, "nothing at the target while writing");
    fputs("hello\n", o.fp);
    TAP_CHECK(st_outfile_commit(&o, &e) == ST_OK && stat(path, &st) == 0 && st.st_size == 6,
              "commit puts the whole file in place");
    TAP_CHECK(st_outfile_begin(&o, path, 1, &e) == ST_OK, "begin again over it");
    fputs("partial", o.fp);
    st_outfile_abort(&o);
    TAP_CHECK(stat(path, &st) == 0 && st.st_size == 6,
              "abort leaves the old file untouched");
    snprintf(path, sizeof path, "%s/missing/out.txt", dir);
    TAP_CHECK(st_outfile_begin(&o, path, 1, &e) == ST_EIO && strstr(e.file, "missing"),
              "a missing directory is an error naming the target: %s", e.msg);
    TAP_CHECK(st_outfile_begin(&o, dir, 1, &e) == ST_EIO, "a directory as target is refused");
    snprintf(path, sizeof path, "%s/out.txt", dir);
    TAP_CHECK(st_outfile_begin(&o, path, 0, &e) == ST_OK && o.tmp != NULL, "begin by name");
    char tmp[256];
    snprintf(tmp, sizeof tmp, "%s", o.tmp);
    st_outfile_unlink_pending();
    TAP_CHECK(stat(tmp, &st) != 0, "the signal-safe cleanup removes temporaries in flight");
    st_outfile_abort(&o);

    /* A write that failed long before the commit, errno overwritten since
     * (any library call may): the message still says why, not "Success". */
    struct rlimit rl0, rl;
    getrlimit(RLIMIT_FSIZE, &rl0);
    rl = rl0;
    rl.rlim_cur = 4096;
    void (*old_xfsz)(int) = signal(SIGXFSZ, SIG_IGN);
    TAP_CHECK(setrlimit(RLIMIT_FSIZE, &rl) == 0 && st_outfile_begin(&o, path, 1, &e) == ST_OK,
              "begin under a 4 KiB file size limit");
    static char big[65536];
    memset(big, 'x', sizeof big);
    size_t nw = fwrite(big, 1, sizeof big, o.fp);
    errno = 0;
    st_status cs = st_outfile_commit(&o, &e);
    setrlimit(RLIMIT_FSIZE, &rl0);
    signal(SIGXFSZ, old_xfsz);
    TAP_CHECK(nw < sizeof big && cs == ST_EIO && strstr(e.msg, strerror(EFBIG)) &&
                  stat(path, &st) == 0 && st.st_size == 6,
              "an earlier failed write is reported with its errno: %s", e.msg);
    unlink(path);
    rmdir(dir);
}

/* Temporaries are named for their target, pid and machine; a rerun removes
 * the ones whose process is gone (SIGKILL leaves them: no handler runs),
 * and only those. */
static void test_outfile_stale(void)
{
    char dir[] = "/tmp/souptet-stale.XXXXXX";
    TAP_CHECK(mkdtemp(dir) != NULL, "temp dir");
    char path[512], name[1024];
    snprintf(path, sizeof path, "%s/a.b@c.tmp-1@x.vtu", dir);
    st_outfile o;
    st_error e;
    TAP_CHECK(st_outfile_begin(&o, path, 1, &e) == ST_OK, "begin");
    char want[600];
    snprintf(want, sizeof want, "%s/.a.b@c.tmp-1@x.vtu.tmp-%ld@", dir, (long)getpid());
    TAP_CHECK(strncmp(o.tmp, want, strlen(want)) == 0,
              "the temporary says its target, pid and host: %s", o.tmp);
    char *t = st_outfile_target_of(o.tmp);
    TAP_CHECK(t && strcmp(t, path) == 0, "st_outfile_target_of gives the target back: %s",
              t ? t : "(null)");
    free(t);
    const char *host = strrchr(o.tmp, '@') + 1;
    char hostbuf[300];
    snprintf(hostbuf, sizeof hostbuf, "%.*s", (int)(strrchr(o.tmp, '.') - host), host);
    TAP_CHECK(st_outfile_target_of("dir/.x.vtu.ABCDEF") == NULL &&
                  st_outfile_target_of("dir/x.vtu.tmp-12@h.ABCDEF") == NULL &&
                  st_outfile_target_of(".x.vtu.tmp-@h.ABCDEF") == NULL,
              "names st_outfile did not make have no target");
    t = st_outfile_target_of(".x.vtu.tmp-12@h.ABCDEF");
    TAP_CHECK(t && strcmp(t, "x.vtu") == 0, "a name without a directory");
    free(t);
    st_outfile_abort(&o);

    /* A dead pid: a child that has exited and been reaped. */
    pid_t child = fork();
    if (child == 0)
        _exit(0);
    waitpid(child, NULL, 0);
    const char *kinds[4] = {"dead", "live", "other host", "other target"};
    char files[4][1024];
    snprintf(files[0], sizeof files[0], "%s/.a.b@c.tmp-1@x.vtu.tmp-%ld@%s.Ab12Cd", dir,
             (long)child, hostbuf);
    snprintf(files[1], sizeof files[1], "%s/.a.b@c.tmp-1@x.vtu.tmp-%ld@%s.Ab12Cd", dir,
             (long)getppid(), hostbuf);
    snprintf(files[2], sizeof files[2], "%s/.a.b@c.tmp-1@x.vtu.tmp-%ld@%s-elsewhere.Ab12Cd",
             dir, (long)child, hostbuf);
    snprintf(files[3], sizeof files[3], "%s/.other.vtu.tmp-%ld@%s.Ab12Cd", dir, (long)child,
             hostbuf);
    for (int i = 0; i < 4; i++) {
        FILE *f = fopen(files[i], "w");
        if (f)
            fclose(f);
    }
    TAP_CHECK(st_outfile_begin(&o, path, 1, &e) == ST_OK, "begin beside four leftovers");
    struct stat st;
    for (int i = 0; i < 4; i++)
        TAP_CHECK((stat(files[i], &st) == 0) == (i != 0),
                  "a leftover of a %s %s", kinds[i], i == 0 ? "process is removed" : "is kept");
    fputs("x", o.fp);
    TAP_CHECK(st_outfile_commit(&o, &e) == ST_OK, "and the output is written");
    for (int i = 0; i < 4; i++)
        unlink(files[i]);
    unlink(path);
    snprintf(name, sizeof name, "%s", dir);
    TAP_CHECK(rmdir(name) == 0, "nothing else is left");
}

/* st_mem_address_space_left: SIZE_MAX with no ulimit -v; under one, the
 * cap and what is left of it (checked in a child, which the cap cannot
 * outlive). */
static void test_address_space(void)
{
    struct rlimit rl;
    getrlimit(RLIMIT_AS, &rl);
    size_t cap;
    if (rl.rlim_cur == RLIM_INFINITY)
        TAP_CHECK(st_mem_address_space_left(&cap) == SIZE_MAX && cap == SIZE_MAX,
                  "no ulimit -v: no cap, all of it left");
    pid_t child = fork();
    if (child == 0) {
        size_t used = 0;
        FILE *f = fopen("/proc/self/statm", "r");
        unsigned long pages = 0;
        if (f && fscanf(f, "%lu", &pages) == 1)
            used = (size_t)pages * (size_t)sysconf(_SC_PAGESIZE);
        if (f)
            fclose(f);
        struct rlimit r = rl;
        r.rlim_cur = (rlim_t)(used + ((size_t)256 << 20));
        if (r.rlim_max != RLIM_INFINITY && r.rlim_cur > r.rlim_max)
            _exit(2);
        if (setrlimit(RLIMIT_AS, &r) != 0)
            _exit(2);
        size_t lim, left = st_mem_address_space_left(&lim);
        /* About 256 MiB left: what the fopen maps may take a little. */
        _exit(lim == (size_t)r.rlim_cur && left <= ((size_t)256 << 20) &&
              left > ((size_t)200 << 20) ? 0 : 1);
    }
    int ws = 0;
    waitpid(child, &ws, 0);
    TAP_CHECK(WIFEXITED(ws) && WEXITSTATUS(ws) == 0,
              "under ulimit -v: the cap, and what is left of it (exit %d)",
              WIFEXITED(ws) ? WEXITSTATUS(ws) : -1);
}

int main(int argc, char **argv)
{
    static const tap_test tests[] = {TAP_TEST(error_format), TAP_TEST(checked_sizes), TAP_TEST(realloc_big), TAP_TEST(array_huge),
                                     TAP_TEST(meta), TAP_TEST(grid), TAP_TEST(outfile),
                                     TAP_TEST(outfile_stale), TAP_TEST(address_space), {0}};
    return tap_main(argc, argv, tests);
}
