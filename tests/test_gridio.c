/*
 * test_gridio.c - fields through OpenVDB (.vdb files, VDB streams on
 * stdout/stdin) and VTK XML ImageData (.vti): exact round trips of values,
 * placement, kind, band and metadata; foreign files; every error names its
 * file; the library prints nothing and leaves no temporary files.
 */
#include "souptet/gridio.h"
#include "souptet/meta.h"
#include "../src/adapters/gridio_internal.h"
#include "tap.h"

#include <dirent.h>
#include <fcntl.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static char dir[64];

static const char *tpath(const char *name)
{
    /* a ring of buffers: each test keeps a few paths alive at once */
    static char buf[256][256];
    static int next;
    char *p = buf[next++ % 256];
    snprintf(p, sizeof buf[0], "%s/%s", dir, name);
    return p;
}

static const char *history =
    "soupdist corpus/bunny.obj -o 'a b.vdb' --band 3\n"
    "soupsign a.vdb -o - | tee\tx\n"
    "  indented, \"quoted\", <xml-ish> & unicode \xc3\xa9\xe2\x88\x9e";

/* A 7x5x3 grid with an awkward placement: origin and voxel are doubles
 * that decimal text with few digits would not reproduce. */
static st_grid *make_grid(st_grid_kind kind, double band)
{
    const double origin[3] = {-1.2345678901234567, 0.1, 1000.0 / 3.0};
    st_grid *g = NULL;
    st_error err;
    if (st_grid_new(&g, 7, 5, 3, origin, 0.0123456789012345, 0.0f, 0, &err))
        return NULL;
    g->kind = kind;
    g->band = band;
    for (size_t k = 0; k < g->nz; k++)
        for (size_t j = 0; j < g->ny; j++)
            for (size_t i = 0; i < g->nx; i++) {
                /* distinct values; some beyond the band, clamped */
                double v = 0.001 * (double)(i + 10 * j + 100 * k) + 1e-7 * i;
                float f = (float)v;
                if (isfinite(band) && v >= band)
                    f = (float)band;
                if (kind == ST_GRID_SIGNED) {
                    if ((i + j + k) % 3 == 0)
                        f = -f;         /* negative inside the band */
                    if (i == 0 && j == 0)
                        f = -(float)band; /* clamped, inside */
                    if (!isfinite(band) && i == 6)
                        f = -1e6f;      /* far inside, full field */
                }
                g->data[st_grid_index(g, i, j, k)] = f;
            }
    st_meta_set(&g->meta, "source", "corpus/bunny.obj");
    st_meta_set(&g->meta, "triangles", "69451");
    st_meta_set(&g->meta, "history", history);
    st_meta_set(&g->meta, "empty", "");
    /* keys that collide with names the formats use themselves */
    st_meta_set(&g->meta, "origin", "collides with both formats");
    st_meta_set(&g->meta, "name", "collides with OpenVDB's grid name");
    st_meta_set(&g->meta, "souptet_meta:x", "looks escaped already");
    st_meta_set(&g->meta, "band_voxels", "3");
    return g;
}

/* Everything must survive exactly; prints what differs. */
static int same_grid(const st_grid *a, const st_grid *b)
{
    if (!a || !b)
        return 0;
    int ok = 1;
    if (a->nx != b->nx || a->ny != b->ny || a->nz != b->nz) {
        TAP_NOTE("dims %zux%zux%zu vs %zux%zux%zu", a->nx, a->ny, a->nz,
                 b->nx, b->ny, b->nz);
        return 0;
    }
    for (int c = 0; c < 3; c++)
        if (a->origin[c] != b->origin[c]) {
            TAP_NOTE("origin[%d] %.17g vs %.17g", c, a->origin[c],
                     b->origin[c]);
            ok = 0;
        }
    if (a->voxel != b->voxel) {
        TAP_NOTE("voxel %.17g vs %.17g", a->voxel, b->voxel);
        ok = 0;
    }
    if (a->kind != b->kind) {
        TAP_NOTE("kind %d vs %d", (int)a->kind, (int)b->kind);
        ok = 0;
    }
    if (!(a->band == b->band)) {
        TAP_NOTE("band %.17g vs %.17g", a->band, b->band);
        ok = 0;
    }
    if (memcmp(a->data, b->data, st_grid_count(a) * sizeof(float)) != 0) {
        for (size_t i = 0; i < st_grid_count(a); i++)
            if (memcmp(&a->data[i], &b->data[i], sizeof(float)) != 0) {
                TAP_NOTE("value %zu: %.9g vs %.9g", i, a->data[i],
                         b->data[i]);
                break;
            }
        ok = 0;
    }
    if (a->meta.count != b->meta.count) {
        TAP_NOTE("meta count %zu vs %zu", a->meta.count, b->meta.count);
        for (size_t i = 0; i < b->meta.count; i++)
            TAP_NOTE("  read key '%s'", b->meta.entries[i].key);
        return 0;
    }
    for (size_t i = 0; i < a->meta.count; i++)
        if (strcmp(a->meta.entries[i].key, b->meta.entries[i].key) != 0 ||
            strcmp(a->meta.entries[i].value, b->meta.entries[i].value) != 0) {
            TAP_NOTE("meta %zu: '%s'='%s' vs '%s'='%s'", i,
                     a->meta.entries[i].key, a->meta.entries[i].value,
                     b->meta.entries[i].key, b->meta.entries[i].value);
            ok = 0;
        }
    return ok;
}

static void note_error(const st_error *err)
{
    char buf[1200];
    TAP_NOTE("%s", st_error_format(err, buf, sizeof buf));
}

/* Write g (or, g NULL, b) to stdout (redirected into file), or read file
 * via stdin. */
static st_status stdout_to(const st_grid *g, const st_grid_blocks *b,
                           const char *file, st_error *err)
{
    fflush(stdout);
    int saved = dup(1);
    int fd = open(file, O_WRONLY | O_CREAT | O_TRUNC, 0644);
    dup2(fd, 1);
    close(fd);
    st_status s = g ? st_grid_write(g, "-", err) : st_grid_blocks_write(b, "-", err);
    fflush(stdout);
    dup2(saved, 1);
    close(saved);
    return s;
}

static st_status write_stdout_to(const st_grid *g, const char *file,
                                 st_error *err)
{
    return stdout_to(g, NULL, file, err);
}

static st_status read_stdin_from(st_grid **out, const char *file,
                                 st_error *err)
{
    int saved = dup(0);
    int fd = open(file, O_RDONLY);
    dup2(fd, 0);
    close(fd);
    clearerr(stdin);
    st_status s = st_grid_read(out, NULL, 0, err);
    dup2(saved, 0);
    close(saved);
    clearerr(stdin);
    return s;
}

static long file_size(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0 ? (long)st.st_size : -1;
}

static int copy_prefix(const char *from, const char *to, long n)
{
    FILE *in = fopen(from, "rb"), *out = fopen(to, "wb");
    if (!in || !out) {
        if (in)
            fclose(in);
        if (out)
            fclose(out);
        return -1;
    }
    for (long i = 0; i < n; i++) {
        int c = getc(in);
        if (c == EOF)
            break;
        putc(c, out);
    }
    fclose(in);
    return fclose(out);
}

static void write_text(const char *path, const char *text)
{
    FILE *f = fopen(path, "w");
    if (f) {
        fputs(text, f);
        fclose(f);
    }
}

static int names_file(const st_error *err, const char *path)
{
    return strcmp(err->file, path) == 0;
}

static void round_trips(const char *label, st_grid_kind kind, double band)
{
    st_grid *g = make_grid(kind, band), *h = NULL;
    st_error err;
    st_error_clear(&err);
    char name[64];

    /* .vdb file */
    snprintf(name, sizeof name, "%s.vdb", label);
    const char *vdb = tpath(name);
    st_status s = st_grid_write(g, vdb, &err);
    TAP_CHECK(s == ST_OK, "%s: write .vdb", label);
    if (s)
        note_error(&err);
    s = st_grid_read(&h, vdb, 0, &err);
    TAP_CHECK(s == ST_OK && same_grid(g, h), "%s: .vdb file round trip",
              label);
    if (s)
        note_error(&err);
    st_grid_free(h);
    h = NULL;

    /* the .vdb file's bytes on stdin */
    s = read_stdin_from(&h, vdb, &err);
    TAP_CHECK(s == ST_OK && same_grid(g, h), "%s: .vdb file bytes on stdin",
              label);
    if (s)
        note_error(&err);
    st_grid_free(h);
    h = NULL;

    /* VDB stream: stdout -> file -> stdin */
    snprintf(name, sizeof name, "%s.stream", label);
    const char *stream = tpath(name);
    s = write_stdout_to(g, stream, &err);
    TAP_CHECK(s == ST_OK && file_size(stream) > 0, "%s: write stream to "
              "stdout (%ld bytes)", label, file_size(stream));
    if (s)
        note_error(&err);
    s = read_stdin_from(&h, stream, &err);
    TAP_CHECK(s == ST_OK && same_grid(g, h), "%s: VDB stream round trip",
              label);
    if (s)
        note_error(&err);
    st_grid_free(h);
    h = NULL;

    /* the stream format from a file with an unknown extension (sniffed) */
    s = st_grid_read(&h, stream, 0, &err);
    TAP_CHECK(s == ST_OK && same_grid(g, h), "%s: stream bytes in a file "
              "without extension, by content", label);
    if (s)
        note_error(&err);
    st_grid_free(h);
    h = NULL;

    /* .vti file */
    snprintf(name, sizeof name, "%s.VTI", label);  /* extension any case */
    const char *vti = tpath(name);
    s = st_grid_write(g, vti, &err);
    TAP_CHECK(s == ST_OK, "%s: write .vti", label);
    if (s)
        note_error(&err);
    s = st_grid_read(&h, vti, 0, &err);
    TAP_CHECK(s == ST_OK && same_grid(g, h), "%s: .vti file round trip",
              label);
    if (s)
        note_error(&err);
    st_grid_free(h);
    h = NULL;

    /* .vti on stdin (sniffed as XML) */
    s = read_stdin_from(&h, vti, &err);
    TAP_CHECK(s == ST_OK && same_grid(g, h), "%s: .vti bytes on stdin",
              label);
    if (s)
        note_error(&err);
    st_grid_free(h);
    st_grid_free(g);
}

/* A 64^3 field of the distance to a sphere, banded at 3 voxels: the .vdb
 * must hold only the band. Signed: the inside must stay negative. */
static void sparse_files(void)
{
    const double origin[3] = {0, 0, 0};
    const size_t n = 64;
    const double voxel = 1.0 / 64, band = 3 * voxel;
    long unsigned_size = 0;
    for (int sgn = 0; sgn < 2; sgn++) {
        st_grid *g = NULL, *h = NULL;
        st_error err;
        st_grid_new(&g, n, n, n, origin, voxel, 0.0f, 0, &err);
        g->kind = sgn ? ST_GRID_SIGNED : ST_GRID_DISTANCE;
        g->band = band;
        for (size_t k = 0; k < n; k++)
            for (size_t j = 0; j < n; j++)
                for (size_t i = 0; i < n; i++) {
                    double p[3];
                    st_grid_center(g, i, j, k, p);
                    double d = sqrt((p[0] - .5) * (p[0] - .5) +
                                    (p[1] - .5) * (p[1] - .5) +
                                    (p[2] - .5) * (p[2] - .5)) - 0.3;
                    double a = fabs(d) < band ? fabs(d) : band;
                    g->data[st_grid_index(g, i, j, k)] =
                        (float)(sgn && d < 0 ? -a : a);
                }
        const char *f = tpath(sgn ? "sphere_sdf.vdb" : "sphere.vdb");
        st_status s = st_grid_write(g, f, &err);
        long dense = (long)(n * n * n * sizeof(float));
        /* ~10% of the voxels are in the band; the signed field must not
         * cost much more than the unsigned one: its clamped inside is
         * stored as inactive tiles, not voxel by voxel */
        if (!sgn)
            unsigned_size = file_size(f);
        TAP_CHECK(s == ST_OK && file_size(f) > 0 && file_size(f) < dense / 4 &&
                      (!sgn || file_size(f) < unsigned_size * 11 / 10),
                  "%s banded 64^3 .vdb is sparse: %ld bytes (dense %ld)",
                  sgn ? "signed" : "unsigned", file_size(f), dense);
        s = st_grid_read(&h, f, 0, &err);
        TAP_CHECK(s == ST_OK && same_grid(g, h), "%s banded 64^3 round trip",
                  sgn ? "signed" : "unsigned");
        if (sgn && h) {
            size_t c = n / 2;
            TAP_CHECK(h->data[st_grid_index(h, c, c, c)] == -(float)band,
                      "center of the signed sphere reads -band");
        }
        const char *fs = tpath("sphere.stream");
        s = write_stdout_to(g, fs, &err);
        TAP_NOTE("stream of the %s 64^3 sphere: %ld bytes",
                 sgn ? "signed" : "unsigned", file_size(fs));
        st_grid_free(h);
        st_grid_free(g);
    }
}

/* g stored by blocks: the blocks with a voxel other than the band. */
static st_grid_blocks *to_blocks(const st_grid *g)
{
    st_grid_blocks *b = NULL;
    st_error err;
    if (st_grid_blocks_new(&b, g->nx, g->ny, g->nz, g->origin, g->voxel, 0, &err))
        return NULL;
    b->head.kind = g->kind;
    b->head.band = g->band;
    st_meta_copy(&b->head.meta, &g->meta);
    const size_t nb = b->nb[0] * b->nb[1] * b->nb[2];
    b->values = malloc(nb * 512 * sizeof(float));
    const float bf = (float)g->band;
    for (size_t n = 0; n < nb; n++) {
        const size_t bi = n % b->nb[0], bj = n / b->nb[0] % b->nb[1],
                     bk = n / b->nb[0] / b->nb[1];
        float *v = b->values + b->nstored * 512;
        int keep = 0;
        for (size_t q = 0; q < 512; q++) {
            const size_t i = bi * 8 + q / 64, j = bj * 8 + q / 8 % 8, k = bk * 8 + q % 8;
            v[q] = i < g->nx && j < g->ny && k < g->nz ? g->data[st_grid_index(g, i, j, k)]
                                                        : bf;
            keep |= v[q] != bf;
        }
        if (keep)
            b->at[n] = 512 * b->nstored++;
    }
    return b;
}

/* The same bytes but the archive's UUID (bytes 21 to 56 of the header). */
static int same_but_uuid(const char *a, const char *b)
{
    FILE *fa = fopen(a, "rb"), *fb = fopen(b, "rb");
    int same = fa && fb && file_size(a) == file_size(b) && file_size(a) > 57;
    for (long at = 0; same; at++) {
        const int ca = fgetc(fa), cb = fgetc(fb);
        if (ca == EOF || cb == EOF) {
            same = ca == cb;
            break;
        }
        if (ca != cb && (at < 21 || at >= 57)) {
            TAP_NOTE("%s and %s differ at byte %ld", a, b, at);
            same = 0;
        }
    }
    if (fa)
        fclose(fa);
    if (fb)
        fclose(fb);
    return same;
}

/* A field stored by blocks is written as the dense field is: the same
 * .vdb and stream byte for byte (but the UUID), the same .vti. A banded
 * sphere on a 45x38x29 grid (sides not multiples of a block), with a block
 * of one value other than the band (an active tile); unsigned and
 * signed (the clamped inside: -band, inactive). */
static void blocks_files(void)
{
    const double origin[3] = {-0.3, 0.1234567890123, 7.0 / 3.0};
    const double voxel = 1.0 / 40, band = 3 * voxel;
    for (int sgn = 0; sgn < 2; sgn++) {
        st_grid *g = NULL, *h = NULL;
        st_error err;
        st_grid_new(&g, 45, 38, 29, origin, voxel, 0.0f, 0, &err);
        g->kind = sgn ? ST_GRID_SIGNED : ST_GRID_DISTANCE;
        g->band = band;
        for (size_t k = 0; k < g->nz; k++)
            for (size_t j = 0; j < g->ny; j++)
                for (size_t i = 0; i < g->nx; i++) {
                    double p[3];
                    st_grid_center(g, i, j, k, p);
                    const double c[3] = {0.25, 0.6, 2.7};
                    double d = sqrt((p[0] - c[0]) * (p[0] - c[0]) + (p[1] - c[1]) * (p[1] - c[1]) +
                                    (p[2] - c[2]) * (p[2] - c[2])) - 0.25;
                    double a = fabs(d) < band ? fabs(d) : band;
                    g->data[st_grid_index(g, i, j, k)] = (float)(sgn && d < 0 ? -a : a);
                }
        for (size_t k = 16; k < 24; k++)    /* one block of one value */
            for (size_t j = 0; j < 8; j++)
                for (size_t i = 0; i < 8; i++)
                    g->data[st_grid_index(g, i, j, k)] = (float)(band / 2);
        st_meta_set(&g->meta, "source", "sphere");
        st_meta_set(&g->meta, "history", history);
        st_grid_blocks *b = to_blocks(g);
        const char *kind = sgn ? "signed" : "unsigned";
        TAP_CHECK(b && b->nstored > 10 && b->nstored < b->nb[0] * b->nb[1] * b->nb[2],
                  "%s: %zu of %zu blocks stored", kind, b ? b->nstored : 0,
                  b ? b->nb[0] * b->nb[1] * b->nb[2] : 0);
        const char *fd = tpath("dense.vdb"), *fb = tpath("blocks.vdb");
        TAP_CHECK(st_grid_write(g, fd, &err) == ST_OK &&
                      st_grid_blocks_write(b, fb, &err) == ST_OK && same_but_uuid(fd, fb),
                  "%s: the .vdb from blocks is the dense one's (%ld bytes)", kind,
                  file_size(fb));
        TAP_CHECK(st_grid_read(&h, fb, 0, &err) == ST_OK && same_grid(g, h),
                  "%s: read back, the blocks' .vdb is the dense field", kind);
        st_grid_free(h);
        const char *sd = tpath("dense.stream"), *sb = tpath("blocks.stream");
        TAP_CHECK(write_stdout_to(g, sd, &err) == ST_OK &&
                      stdout_to(NULL, b, sb, &err) == ST_OK && same_but_uuid(sd, sb),
                  "%s: the stream from blocks is the dense one's", kind);
        const char *vd = tpath("dense.vti"), *vb = tpath("blocks.vti");
        TAP_CHECK(st_grid_write(g, vd, &err) == ST_OK &&
                      st_grid_blocks_write(b, vb, &err) == ST_OK && same_but_uuid(vd, vb),
                  "%s: the .vti from blocks is the dense one's", kind);
        if (sgn) {
            b->values[b->at[1 + b->nb[0] * (2 + b->nb[1] * 2)] + 64 * 3 + 8 * 4 + 5] = NAN;
            TAP_CHECK(st_grid_blocks_write(b, tpath("nan.vdb"), &err) == ST_EINPUT &&
                          strstr(err.msg, "(11,20,21)") && file_size(tpath("nan.vdb")) < 0,
                      "a NaN in a block is refused, named by its voxel: %s", err.msg);
        }
        st_grid_blocks_free(b);
        st_grid_free(g);
    }
}

static void foreign_files(void)
{
    st_error err;
    st_grid *h = NULL;

    const char *f1 = tpath("foreign_density.vdb");
    st_status s = st_gridio_write_foreign_vdb(f1, 1, &err);
    s = s ? s : st_grid_read(&h, f1, 0, &err);
    TAP_CHECK(s == ST_OK, "foreign FloatGrid without souptet metadata reads");
    if (s)
        note_error(&err);
    if (h) {
        TAP_CHECK(h->nx == 4 && h->ny == 5 && h->nz == 3,
                  "foreign: dims = active bounding box (%zux%zux%zu)", h->nx,
                  h->ny, h->nz);
        TAP_CHECK(h->origin[0] == 2.0 && h->origin[1] == 0.5 &&
                      h->origin[2] == 5.0 && h->voxel == 0.5,
                  "foreign: origin (%g %g %g) and voxel %g from the "
                  "transform",
                  h->origin[0], h->origin[1], h->origin[2], h->voxel);
        TAP_CHECK(h->kind == ST_GRID_UNKNOWN && isinf(h->band),
                  "foreign: kind unknown, band infinite");
        /* index (2,-3,4) active: 2 - 30 + 400; (3,-3,5) inactive: -1 */
        TAP_CHECK(h->data[st_grid_index(h, 0, 0, 0)] == 372.0f &&
                      h->data[st_grid_index(h, 1, 0, 1)] == -1.0f &&
                      h->data[st_grid_index(h, 3, 4, 2)] == 615.0f,
                  "foreign: active values and background");
        const char *note = st_meta_get(&h->meta, "note");
        TAP_CHECK(note && strcmp(note, "foreign") == 0 &&
                      !st_meta_get(&h->meta, "class") &&
                      !st_meta_get(&h->meta, "file_bbox_min"),
                  "foreign: its own metadata kept, OpenVDB's left out");
    }
    st_grid_free(h);
    h = NULL;

    const char *f2 = tpath("foreign_sphere.vdb");
    s = st_gridio_write_foreign_vdb(f2, 2, &err);
    s = s ? s : st_grid_read(&h, f2, 0, &err);
    TAP_CHECK(s == ST_OK && h && h->kind == ST_GRID_SIGNED &&
                  h->band == 0.75,
              "foreign level set: kind signed, band = background");
    if (h) {
        size_t c[3];
        for (int a = 0; a < 3; a++)     /* index of the world origin */
            c[a] = (size_t)lround(-h->origin[a] / h->voxel);
        TAP_CHECK(h->data[st_grid_index(h, c[0], c[1], c[2])] == -0.75f &&
                      h->data[0] == 0.75f,
                  "foreign level set: inside reads -band, corner +band");
    }
    st_grid_free(h);
}

static void errors(void)
{
    st_error err;
    st_grid *h = NULL;
    st_grid *g = make_grid(ST_GRID_DISTANCE, 0.02);
    st_status s;

    /* stderr into a file: the library must not print anything */
    fflush(stderr);
    int saved = dup(2);
    const char *errlog = tpath("stderr.txt");
    int fd = open(errlog, O_WRONLY | O_CREAT | O_TRUNC, 0644);
    dup2(fd, 2);
    close(fd);

    const char *missing[] = {"missing.vdb", "missing.vti", "missing.field"};
    for (int i = 0; i < 3; i++) {
        const char *p = tpath(missing[i]);
        s = st_grid_read(&h, p, 0, &err);
        TAP_CHECK(s == ST_EIO && h == NULL && names_file(&err, p),
                  "missing %s: I/O error naming the file", missing[i]);
        note_error(&err);
    }

    const char *empty[] = {"empty.vdb", "empty.vti", "empty.field"};
    for (int i = 0; i < 3; i++) {
        const char *p = tpath(empty[i]);
        write_text(p, "");
        s = st_grid_read(&h, p, 0, &err);
        TAP_CHECK(s == ST_EINPUT && names_file(&err, p),
                  "empty %s: input error naming the file", empty[i]);
        note_error(&err);
    }

    /* truncated: at half, and at many other lengths (no crash, no hang,
     * never a grid) */
    const char *full[2] = {tpath("trunc_src.vdb"), tpath("trunc_src.vti")};
    const char *cut[2] = {tpath("trunc.vdb"), tpath("trunc.vti")};
    for (int f = 0; f < 2; f++) {
        st_grid_write(g, full[f], &err);
        long size = file_size(full[f]);
        copy_prefix(full[f], cut[f], size / 2);
        s = st_grid_read(&h, cut[f], 0, &err);
        TAP_CHECK(s == ST_EINPUT && h == NULL && names_file(&err, cut[f]),
                  "%s cut in half: input error naming the file",
                  f ? ".vti" : ".vdb");
        note_error(&err);
        int bad = 0;
        for (long n = 1; n < size; n += (size / 97) + 1) {
            copy_prefix(full[f], cut[f], n);
            h = NULL;
            s = st_grid_read(&h, cut[f], 0, &err);
            if (s == ST_OK || h || !names_file(&err, cut[f])) {
                TAP_NOTE("cut at %ld of %ld: status %d", n, size, (int)s);
                bad++;
            }
            st_grid_free(h);
            h = NULL;
        }
        TAP_CHECK(bad == 0, "%s cut at ~100 lengths: always an error",
                  f ? ".vti" : ".vdb");
    }

    /* a bigger .vti cut inside its appended binary data, not its XML */
    {
        const double o[3] = {0, 0, 0};
        st_grid *big = NULL;
        st_grid_new(&big, 40, 40, 40, o, 1.0, 0.0f, 0, &err);
        unsigned x = 12345;
        for (size_t i = 0; i < st_grid_count(big); i++) {
            x = x * 1103515245u + 12345u;   /* incompressible values */
            big->data[i] = (float)(x >> 8);
        }
        const char *bf = tpath("big.vti"), *bc = tpath("big_cut.vti");
        st_grid_write(big, bf, &err);
        long size = file_size(bf);
        const long at[3] = {size / 2, size * 9 / 10, size - 64};
        for (int i = 0; i < 3; i++) {
            copy_prefix(bf, bc, at[i]);
            s = st_grid_read(&h, bc, 0, &err);
            TAP_CHECK(s == ST_EINPUT && h == NULL && names_file(&err, bc),
                      ".vti of %ld bytes cut at %ld (in the binary data): "
                      "input error", size, at[i]);
            note_error(&err);
            st_grid_free(h);
            h = NULL;
        }
        st_grid_free(big);
    }

    const char *vec = tpath("vec3s_only.vdb");
    st_gridio_write_foreign_vdb(vec, 0, &err);
    s = st_grid_read(&h, vec, 0, &err);
    TAP_CHECK(s == ST_EINPUT && names_file(&err, vec) &&
                  strstr(err.msg, "no float grid"),
              ".vdb with only a vec3s grid: refused");
    note_error(&err);

    const char *txt_vdb = tpath("text.vdb");
    write_text(txt_vdb, "this is not a VDB file, just some text\n");
    s = st_grid_read(&h, txt_vdb, 0, &err);
    TAP_CHECK(s == ST_EINPUT && names_file(&err, txt_vdb),
              "text named .vdb: input error naming the file");
    note_error(&err);

    const char *txt_vti = tpath("text.vti");
    write_text(txt_vti, "this is not XML either\n");
    s = st_grid_read(&h, txt_vti, 0, &err);
    TAP_CHECK(s == ST_EINPUT && names_file(&err, txt_vti),
              "text named .vti: input error naming the file");
    note_error(&err);

    const char *xml_vti = tpath("other.vti");
    write_text(xml_vti, "<?xml version=\"1.0\"?>\n<VTKFile type=\"PolyData\" "
                        "version=\"1.0\"><PolyData></PolyData></VTKFile>\n");
    s = st_grid_read(&h, xml_vti, 0, &err);
    TAP_CHECK(s == ST_EINPUT && names_file(&err, xml_vti),
              "VTK XML of another type named .vti: input error");
    note_error(&err);

    const char *txt = tpath("text.field");
    write_text(txt, "neither\n");
    s = st_grid_read(&h, txt, 0, &err);
    TAP_CHECK(s == ST_EINPUT && names_file(&err, txt),
              "text with unknown extension: input error");
    note_error(&err);

    /* max_bytes: 7*5*3 floats = 420 bytes */
    const char *lim[2] = {full[0], full[1]};
    for (int f = 0; f < 2; f++) {
        s = st_grid_read(&h, lim[f], 419, &err);
        TAP_CHECK(s == ST_ELIMIT && h == NULL && names_file(&err, lim[f]),
                  "%s over max_bytes: limit error naming the file",
                  f ? ".vti" : ".vdb");
        note_error(&err);
        s = st_grid_read(&h, lim[f], 420, &err);
        TAP_CHECK(s == ST_OK, "%s at exactly max_bytes: reads",
                  f ? ".vti" : ".vdb");
        st_grid_free(h);
        h = NULL;
    }

    const char *nodir[2] = {tpath("no/such/dir/x.vdb"),
                            tpath("no/such/dir/x.vti")};
    for (int f = 0; f < 2; f++) {
        s = st_grid_write(g, nodir[f], &err);
        TAP_CHECK(s == ST_EIO && names_file(&err, nodir[f]) &&
                      file_size(nodir[f]) < 0,
                  "write %s into a missing directory: I/O error, no file",
                  f ? ".vti" : ".vdb");
        note_error(&err);
    }

    /* a directory as target */
    s = st_grid_write(g, dir, &err);
    TAP_CHECK(s != ST_OK, "write to a directory path fails");
    const char *sub = tpath("adir.vdb");
    mkdir(sub, 0755);
    s = st_grid_write(g, sub, &err);
    TAP_CHECK(s == ST_EIO && names_file(&err, sub),
              "write .vdb over a directory: I/O error naming it");
    note_error(&err);

    const char *unk = tpath("x.dat");
    s = st_grid_write(g, unk, &err);
    TAP_CHECK(s == ST_EINPUT && names_file(&err, unk) &&
                  strcmp(err.msg, "unknown field format (use .vdb or .vti)")
                      == 0 && file_size(unk) < 0,
              "unknown extension on write: refused, nothing written");

    /* stdout that cannot take the stream: an I/O error, not silence */
    {
        fflush(stdout);
        int saved1 = dup(1);
        int devfull = open("/dev/full", O_WRONLY);
        if (devfull >= 0) {
            dup2(devfull, 1);
            close(devfull);
            s = st_grid_write(g, "-", &err);
            clearerr(stdout);
            dup2(saved1, 1);
            close(saved1);
            TAP_CHECK(s == ST_EIO && strcmp(err.file, "<stdout>") == 0,
                      "stream to a full stdout (/dev/full): I/O error");
            note_error(&err);
        } else {
            close(saved1);
            TAP_CHECK(1, "stream to a full stdout (/dev/full): I/O error # SKIP no /dev/full");
        }
    }

    g->data[7] = NAN;
    const char *nan = tpath("nan.vdb");
    s = st_grid_write(g, nan, &err);
    TAP_CHECK(s == ST_EINPUT && file_size(nan) < 0,
              "NaN in a field: .vdb refuses, nothing written");
    note_error(&err);
    st_grid_free(g);

    /* stdin that is empty or not a field */
    const char *e = tpath("empty.vdb");
    s = read_stdin_from(&h, e, &err);
    TAP_CHECK(s == ST_EINPUT && strcmp(err.file, "<stdin>") == 0,
              "empty stdin: input error naming <stdin>");
    note_error(&err);
    s = read_stdin_from(&h, txt_vdb, &err);
    TAP_CHECK(s == ST_EINPUT && strcmp(err.file, "<stdin>") == 0,
              "text on stdin: input error naming <stdin>");
    note_error(&err);

    /* a file from a newer OpenVDB: OpenVDB warns (through its logger,
     * which writes to stdout) and reads on; nothing may appear on stdout */
    {
        const char *src = tpath("banded.vdb"), *fut = tpath("future.vdb");
        long size = file_size(src);
        copy_prefix(src, fut, size);
        FILE *f = fopen(fut, "r+b");
        unsigned char v[4] = {0xe7, 0x03, 0, 0};    /* version 999 */
        if (f) {
            fseek(f, 8, SEEK_SET);
            fwrite(v, 1, 4, f);
            fclose(f);
        }
        const char *outlog = tpath("stdout.txt");
        fflush(stdout);
        int saved1 = dup(1);
        int fd1 = open(outlog, O_WRONLY | O_CREAT | O_TRUNC, 0644);
        dup2(fd1, 1);
        close(fd1);
        s = st_grid_read(&h, fut, 0, &err);
        fflush(stdout);
        dup2(saved1, 1);
        close(saved1);
        TAP_CHECK(file_size(outlog) == 0, "newer file version: nothing "
                  "printed to stdout (%ld bytes), status %d",
                  file_size(outlog), (int)s);
        st_grid_free(h);
        h = NULL;
    }

    fflush(stderr);
    dup2(saved, 2);
    close(saved);
    long printed = file_size(errlog);
    TAP_CHECK(printed == 0, "the library printed nothing to stderr (%ld "
              "bytes)", printed);
    if (printed > 0) {
        FILE *f = fopen(errlog, "r");
        char line[256];
        for (int i = 0; f && i < 10 && fgets(line, sizeof line, f); i++)
            TAP_NOTE("stderr: %s", line);
        if (f)
            fclose(f);
    }
}

static void formats(void)
{
    TAP_CHECK(st_grid_format_from_path("a/b.vdb") == ST_GRID_FMT_VDB &&
                  st_grid_format_from_path("B.VDB") == ST_GRID_FMT_VDB &&
                  st_grid_format_from_path("x.Vti") == ST_GRID_FMT_VTI &&
                  st_grid_format_from_path("x.vtk") == ST_GRID_FMT_UNKNOWN &&
                  st_grid_format_from_path("vdb") == ST_GRID_FMT_UNKNOWN &&
                  st_grid_format_from_path("d.vdb/x") == ST_GRID_FMT_UNKNOWN &&
                  st_grid_format_from_path(NULL) == ST_GRID_FMT_UNKNOWN,
              "format from path");
    TAP_CHECK(strcmp(st_grid_name_for_kind(ST_GRID_DISTANCE), "distance") ==
                      0 &&
                  strcmp(st_grid_name_for_kind(ST_GRID_SIGNED), "sdf") == 0 &&
                  strcmp(st_grid_name_for_kind(ST_GRID_UNKNOWN), "field") == 0,
              "grid names for kinds");
}

/* No temporary ".name.XXXXXX" left behind by any write. */
static void no_leftovers(void)
{
    DIR *d = opendir(dir);
    int hidden = 0;
    struct dirent *e;
    while (d && (e = readdir(d)))
        if (e->d_name[0] == '.' && strcmp(e->d_name, ".") &&
            strcmp(e->d_name, "..")) {
            TAP_NOTE("left over: %s", e->d_name);
            hidden++;
        }
    if (d)
        closedir(d);
    TAP_CHECK(hidden == 0, "no temporary files left in the output directory");
}

static void remove_tree(const char *path)
{
    DIR *d = opendir(path);
    struct dirent *e;
    while (d && (e = readdir(d))) {
        if (!strcmp(e->d_name, ".") || !strcmp(e->d_name, ".."))
            continue;
        char p[512];
        snprintf(p, sizeof p, "%s/%s", path, e->d_name);
        struct stat st;
        if (lstat(p, &st) == 0 && S_ISDIR(st.st_mode))
            remove_tree(p);
        else
            unlink(p);
    }
    if (d)
        closedir(d);
    rmdir(path);
}

/* The round trips of each kind of grid. */
static void round_trips_banded(void)
{
    round_trips("banded", ST_GRID_DISTANCE, 0.02);
}

static void round_trips_full(void)
{
    round_trips("full", ST_GRID_DISTANCE, INFINITY);
}

static void round_trips_signed(void)
{
    round_trips("signed", ST_GRID_SIGNED, 0.02);
}

static void round_trips_signed_full(void)
{
    round_trips("signed_full", ST_GRID_SIGNED, INFINITY);
}

static void round_trips_unknown(void)
{
    round_trips("unknown", ST_GRID_UNKNOWN, 0.35);
}

int main(int argc, char **argv)
{
    static const tap_test tests[] = {{"formats", formats},
                                     {"round_trips_banded", round_trips_banded},
                                     {"round_trips_full", round_trips_full},
                                     {"round_trips_signed", round_trips_signed},
                                     {"round_trips_signed_full", round_trips_signed_full},
                                     {"round_trips_unknown", round_trips_unknown},
                                     {"sparse_files", sparse_files},
                                     {"blocks_files", blocks_files},
                                     {"foreign_files", foreign_files}, {"errors", errors},
                                     {"no_leftovers", no_leftovers}, {0}};
    tap_select(argc, argv, tests);
    snprintf(dir, sizeof dir, "/tmp/test_gridio.XXXXXX");
    if (!mkdtemp(dir)) {
        printf("Bail out! cannot create a temporary directory\n");
        return 1;
    }
    tap_run(tests);
    if (!getenv("TEST_GRIDIO_KEEP"))
        remove_tree(dir);
    else
        TAP_NOTE("files kept in %s", dir);
    return tap_done();
}
