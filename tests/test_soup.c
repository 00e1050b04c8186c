/*
 * test_soup.c - TAP tests of the triangle soup and the OBJ, OFF, PLY and STL
 * readers (soup.h): every format and variant, fan triangulation, no
 * welding, the same cube from all four formats, and every class of
 * malformed input with the file, line or byte offset it must name.
 *
 * Buffers handed to st_soup_parse are malloc'd to their exact size (no
 * terminating NUL), so valgrind or ASan catch any read past the end.
 */
#include "souptet/soup.h"
#include "tap.h"

#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#define ANY (-2)    /* line or offset not checked */

/* ---- helpers ------------------------------------------------------------ */

/* Parse len bytes of data from an exactly-sized heap copy. */
static st_status parse(st_soup **out, st_soup_format f, const void *data,
                       size_t len, const char *name, st_error *err)
{
    unsigned char *copy = malloc(len ? len : 1);
    if (!copy)
        abort();
    memcpy(copy, data, len);
    st_error_clear(err);
    st_status st = st_soup_parse(out, f, copy, len, name, err);
    free(copy);
    return st;
}

static st_soup *parse_text(st_soup_format f, const char *text,
                           const char *name, st_error *err)
{
    st_soup *s = NULL;
    parse(&s, f, text, strlen(text), name, err);
    return s;
}

static void note_error(const st_error *err)
{
    char buf[1200];
    TAP_NOTE("error: status %d, \"%s\"", (int)err->status,
             st_error_format(err, buf, sizeof buf));
}

/* The error must have the status, name the file, carry the line (text) or
 * offset (binary) given (ANY skips the check) and contain needle. */
static int error_is(st_status got, const st_error *err, st_status want,
                    const char *file, long long line, long long offset,
                    const char *needle)
{
    int ok = got == want && err->status == want &&
             strcmp(err->file, file) == 0 &&
             (line == ANY || err->line == line) &&
             (offset == ANY || err->offset == offset) &&
             strstr(err->msg, needle) != NULL;
    if (!ok)
        note_error(err);
    return ok;
}

/* Parse len bytes that must fail; check the error as error_is does. */
static void expect_error(const char *what, st_soup_format f, const void *data,
                         size_t len, const char *name, st_status want,
                         long long line, long long offset, const char *needle)
{
    st_error err;
    st_soup *s = NULL;
    st_status st = parse(&s, f, data, len, name, &err);
    TAP_CHECK(s == NULL &&
                  error_is(st, &err, want, name, line, offset, needle),
              "%s", what);
    st_soup_free(s);
}

/* Text input: the error is at a line. */
static void expect_text_error(const char *what, st_soup_format f,
                              const char *text, const char *name,
                              st_status want, long long line,
                              const char *needle)
{
    expect_error(what, f, text, strlen(text), name, want, line, -1, needle);
}

/* Binary input: the error is at a byte offset. */
static void expect_bin_error(const char *what, st_soup_format f,
                             const void *data, size_t len, const char *name,
                             st_status want, long long offset,
                             const char *needle)
{
    expect_error(what, f, data, len, name, want, 0, offset, needle);
}

static int tri_is(const st_soup *s, size_t t, uint32_t a, uint32_t b,
                  uint32_t c)
{
    return t < s->ntris && s->tris[3 * t] == a && s->tris[3 * t + 1] == b &&
           s->tris[3 * t + 2] == c;
}

static int vert_is(const st_soup *s, size_t v, double x, double y, double z)
{
    return v < s->nverts && s->xyz[3 * v] == x && s->xyz[3 * v + 1] == y &&
           s->xyz[3 * v + 2] == z;
}

/* Every index is below nverts and every coordinate finite. */
static int soup_valid(const st_soup *s)
{
    if (!s || s->ntris == 0)
        return 0;
    for (size_t i = 0; i < 3 * s->ntris; i++)
        if (s->tris[i] >= s->nverts)
            return 0;
    for (size_t i = 0; i < 3 * s->nverts; i++)
        if (!isfinite(s->xyz[i]))
            return 0;
    return 1;
}

/* A little byte builder for the binary files. */
typedef struct bytes {
    unsigned char d[8192];
    size_t n;
    int be;
} bytes;

static void put(bytes *b, const void *p, size_t n)
{
    if (b->n + n > sizeof b->d)
        abort();
    memcpy(b->d + b->n, p, n);
    b->n += n;
}

static void put_str(bytes *b, const char *s) { put(b, s, strlen(s)); }

static void put_uint(bytes *b, uint64_t v, size_t size)
{
    unsigned char q[8];
    for (size_t i = 0; i < size; i++)
        q[b->be ? size - 1 - i : i] = (unsigned char)(v >> (8 * i));
    put(b, q, size);
}

static void put_u8(bytes *b, unsigned v) { put_uint(b, v, 1); }
static void put_i16(bytes *b, int v) { put_uint(b, (uint16_t)(int16_t)v, 2); }
static void put_i32(bytes *b, long v) { put_uint(b, (uint32_t)(int32_t)v, 4); }

static void put_f32(bytes *b, float f)
{
    uint32_t u;
    memcpy(&u, &f, 4);
    put_uint(b, u, 4);
}

static void put_f64(bytes *b, double d)
{
    uint64_t u;
    memcpy(&u, &d, 8);
    put_uint(b, u, 8);
}

/* ---- temp files --------------------------------------------------------- */

static char tmpdir[256];

static const char *tmp_path(const char *name)
{
    static char path[512];
    snprintf(path, sizeof path, "%s/%s", tmpdir, name);
    return path;
}

static const char *write_tmp(const char *name, const void *data, size_t n)
{
    const char *path = tmp_path(name);
    FILE *f = fopen(path, "wb");
    if (!f || fwrite(data, 1, n, f) != n || fclose(f) != 0) {
        printf("Bail out! cannot write %s\n", path);
        exit(1);
    }
    return path;
}

/* ---- shared sample files ------------------------------------------------ */

static const char cube_obj[] =
    "# unit cube, quads\n"
    "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
    "v 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n"
    "f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n";

static const char cube_off[] =
    "OFF\n# unit cube\n8 6 12\n"
    "0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 0 1\n1 0 1\n1 1 1\n0 1 1\n"
    "4 0 3 2 1\n4 4 5 6 7\n4 0 1 5 4\n4 1 2 6 5\n4 2 3 7 6\n4 3 0 4 7\n";

static const char cube_ply[] =
    "ply\nformat ascii 1.0\nelement vertex 8\n"
    "property float x\nproperty float y\nproperty float z\n"
    "element face 6\nproperty list uchar int vertex_indices\nend_header\n"
    "0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 0 1\n1 0 1\n1 1 1\n0 1 1\n"
    "4 0 3 2 1\n4 4 5 6 7\n4 0 1 5 4\n4 1 2 6 5\n4 2 3 7 6\n4 3 0 4 7\n";

/* An ASCII STL of a soup. */
static size_t soup_to_stl_ascii(const st_soup *s, char *buf, size_t cap)
{
    size_t n = (size_t)snprintf(buf, cap, "solid cube\n");
    for (size_t t = 0; t < s->ntris && n < cap; t++) {
        n += (size_t)snprintf(buf + n, cap - n,
                              "  facet normal 0 0 0\n    outer loop\n");
        for (int k = 0; k < 3 && n < cap; k++) {
            const double *v = s->xyz + 3 * (size_t)s->tris[3 * t + k];
            n += (size_t)snprintf(buf + n, cap - n,
                                  "      vertex %g %g %g\n", v[0], v[1],
                                  v[2]);
        }
        if (n < cap)
            n += (size_t)snprintf(buf + n, cap - n,
                                  "    endloop\n  endfacet\n");
    }
    if (n < cap)
        n += (size_t)snprintf(buf + n, cap - n, "endsolid cube\n");
    if (n >= cap)
        abort();
    return n;
}

/* A binary STL of a soup; header is the 80-byte header text. */
static void soup_to_stl_binary(const st_soup *s, const char *header,
                               bytes *b)
{
    char h[80];
    memset(h, ' ', sizeof h);
    memcpy(h, header, strlen(header) < 80 ? strlen(header) : 80);
    b->n = 0;
    b->be = 0;
    put(b, h, 80);
    put_uint(b, s->ntris, 4);
    for (size_t t = 0; t < s->ntris; t++) {
        for (int k = 0; k < 3; k++)
            put_f32(b, 0.0f);
        for (int k = 0; k < 3; k++) {
            const double *v = s->xyz + 3 * (size_t)s->tris[3 * t + k];
            for (int a = 0; a < 3; a++)
                put_f32(b, (float)v[a]);
        }
        put_uint(b, 0, 2);
    }
}

/* A binary PLY of two triangles (a quad) with mixed property types, a list
 * on the vertex element and an extra element with lists on either side. */
static void ply_mixed(bytes *b, int be)
{
    b->n = 0;
    b->be = be;
    put_str(b, "ply\n");
    put_str(b, be ? "format binary_big_endian 1.0\n"
                  : "format binary_little_endian 1.0\n");
    put_str(b, "comment mixed types\nobj_info made by hand\n"
               "element material 1\nproperty list uchar float rgb\n"
               "property uchar id\n"
               "element vertex 4\nproperty double y\nproperty uchar red\n"
               "property list int ushort tags\nproperty float x\n"
               "property short z\nproperty int16 w\n"
               "element face 1\nproperty uint8 flags\n"
               "property list int uint32 vertex_indices\n"
               "property list uint16 float64 weights\n"
               "element edge 1\nproperty list uchar int vertex1\n"
               "end_header\n");
    /* material: rgb list of 3 floats, id */
    put_u8(b, 3);
    put_f32(b, 0.5f);
    put_f32(b, 0.25f);
    put_f32(b, 1.0f);
    put_u8(b, 7);
    static const double xs[4] = {0, 2, 2, 0}, ys[4] = {0, 0, 3, 3};
    static const int zs[4] = {-1, -1, 5, 5};
    for (int v = 0; v < 4; v++) {
        put_f64(b, ys[v]);
        put_u8(b, 200);
        put_i32(b, v);          /* tags: v items */
        for (int k = 0; k < v; k++)
            put_uint(b, 0xBEEF, 2);
        put_f32(b, (float)xs[v]);
        put_i16(b, zs[v]);
        put_i16(b, 9);
    }
    put_u8(b, 1);
    put_i32(b, 4);
    for (int k = 0; k < 4; k++)
        put_uint(b, (uint64_t)k, 4);
    put_uint(b, 2, 2);
    put_f64(b, 0.5);
    put_f64(b, 0.5);
    put_u8(b, 2);               /* edge: vertex1 list of 2 ints */
    put_i32(b, 0);
    put_i32(b, 1);
}

/* ---- the soup itself ---------------------------------------------------- */

static void test_soup_api(void)
{
    st_error err;
    st_error_clear(&err);
    st_soup *s = st_soup_new();
    TAP_CHECK(s && s->nverts == 0 && s->ntris == 0, "soup_new is empty");
    int ok = 1;
    for (int i = 0; i < 100000 && ok; i++)
        ok = st_soup_add_vertex(s, i, -i, 0.5 * i, &err) == ST_OK;
    for (uint32_t i = 0; i + 2 < 100000 && ok; i += 3)
        ok = st_soup_add_triangle(s, i, i + 1, i + 2, &err) == ST_OK;
    ok = ok && s->nverts == 100000 && s->ntris == 33333;
    for (size_t i = 0; i < 100000 && ok; i += 997)
        ok = vert_is(s, i, (double)i, -(double)i, 0.5 * (double)i);
    for (size_t t = 0; t < s->ntris && ok; t += 101)
        ok = tri_is(s, t, (uint32_t)(3 * t), (uint32_t)(3 * t + 1),
                    (uint32_t)(3 * t + 2));
    TAP_CHECK(ok, "add_vertex/add_triangle grow and keep every element");

    st_status st = st_soup_add_triangle(s, 0, 1, 100000, &err);
    TAP_CHECK(st == ST_EINPUT && s->ntris == 33333,
              "add_triangle refuses an index past the vertices");

    double lo[3], hi[3];
    st = st_soup_bounds(s, lo, hi, &err);
    TAP_CHECK(st == ST_OK && lo[0] == 0 && hi[0] == 99998 &&
                  lo[1] == -99998 && hi[1] == 0 && lo[2] == 0 &&
                  hi[2] == 49999,
              "bounds cover the referenced vertices");
    st_soup_free(s);

    /* A vertex no triangle uses does not widen the bounds. */
    s = st_soup_new();
    st_soup_add_vertex(s, 0, 0, 0, &err);
    st_soup_add_vertex(s, 1, 0, 0, &err);
    st_soup_add_vertex(s, 0, 1, 0, &err);
    st_soup_add_vertex(s, 100, 100, 100, &err);
    st_soup_add_triangle(s, 0, 1, 2, &err);
    st = st_soup_bounds(s, lo, hi, &err);
    TAP_CHECK(st == ST_OK && hi[0] == 1 && hi[1] == 1 && hi[2] == 0,
              "bounds ignore unreferenced vertices");
    st_soup_free(s);

    s = st_soup_new();
    st_error_clear(&err);
    st = st_soup_bounds(s, lo, hi, &err);
    TAP_CHECK(st == ST_EINPUT && err.status == ST_EINPUT,
              "bounds of a soup without triangles is an error");
    st_soup_free(s);

    /* Capacity is implicit in the count: a zeroed st_soup grows too. */
    st_soup z = {0};
    ok = 1;
    for (int i = 0; i < 1000 && ok; i++)
        ok = st_soup_add_vertex(&z, i, i, i, &err) == ST_OK;
    ok = ok && st_soup_add_triangle(&z, 0, 500, 999, &err) == ST_OK &&
         z.nverts == 1000 && vert_is(&z, 999, 999, 999, 999);
    TAP_CHECK(ok, "a zero-initialised soup grows like a new one");
    free(z.xyz);
    free(z.tris);

    st_soup_free(NULL);
    TAP_CHECK(1, "soup_free(NULL) is safe");
}

static void test_formats(void)
{
    TAP_CHECK(st_soup_format_from_path("a/b.obj") == ST_SOUP_OBJ &&
                  st_soup_format_from_path("X.OFF") == ST_SOUP_OFF &&
                  st_soup_format_from_path("m.Ply") == ST_SOUP_PLY &&
                  st_soup_format_from_path("dir.d/m.sTl") == ST_SOUP_STL,
              "format_from_path: extensions, case-insensitive");
    TAP_CHECK(st_soup_format_from_path("model") == ST_SOUP_UNKNOWN &&
                  st_soup_format_from_path("a.obj/model") ==
                      ST_SOUP_UNKNOWN &&
                  st_soup_format_from_path(".obj") == ST_SOUP_UNKNOWN &&
                  st_soup_format_from_path("m.objx") == ST_SOUP_UNKNOWN &&
                  st_soup_format_from_path("-") == ST_SOUP_UNKNOWN &&
                  st_soup_format_from_path(NULL) == ST_SOUP_UNKNOWN,
              "format_from_path: no or other extension is unknown");
    TAP_CHECK(strcmp(st_soup_format_name(ST_SOUP_OBJ), "obj") == 0 &&
                  strcmp(st_soup_format_name(ST_SOUP_OFF), "off") == 0 &&
                  strcmp(st_soup_format_name(ST_SOUP_PLY), "ply") == 0 &&
                  strcmp(st_soup_format_name(ST_SOUP_STL), "stl") == 0 &&
                  strcmp(st_soup_format_name(ST_SOUP_UNKNOWN), "unknown") ==
                      0,
              "format_name");

#define SNIFF(s) st_soup_format_sniff((const unsigned char *)(s), strlen(s))
    TAP_CHECK(SNIFF("ply\nformat ascii 1.0\n") == ST_SOUP_PLY &&
                  SNIFF("ply\r\nformat ascii 1.0\r\n") == ST_SOUP_PLY &&
                  SNIFF("plywood\n") != ST_SOUP_PLY,
              "sniff: PLY magic with LF or CRLF");
    TAP_CHECK(SNIFF("OFF\n3 1 0\n") == ST_SOUP_OFF &&
                  SNIFF("# c\n\nCOFF 3 1 0\n") == ST_SOUP_OFF &&
                  SNIFF("NOFF\n") == ST_SOUP_OFF &&
                  SNIFF("CNOFF\n") == ST_SOUP_OFF &&
                  SNIFF("STOFF\n") == ST_SOUP_OFF &&
                  SNIFF("OFFICE\n") != ST_SOUP_OFF,
              "sniff: OFF keyword and its prefixes");
    TAP_CHECK(SNIFF("solid x\n facet normal 0 0 1\n") == ST_SOUP_STL &&
                  SNIFF("# c\nv 1 2 3\nf 1 1 1\n") == ST_SOUP_OBJ &&
                  SNIFF("o thing\r\nf 1 2 3\r\n") == ST_SOUP_OBJ &&
                  SNIFF("hello world\n") == ST_SOUP_UNKNOWN &&
                  st_soup_format_sniff(NULL, 0) == ST_SOUP_UNKNOWN,
              "sniff: ASCII STL, OBJ, garbage");
#undef SNIFF
    bytes b;
    st_error err;
    st_soup *cube = parse_text(ST_SOUP_OBJ, cube_obj, "cube.obj", &err);
    soup_to_stl_binary(cube, "solid but binary", &b);
    TAP_CHECK(st_soup_format_sniff(b.d, b.n) == ST_SOUP_STL,
              "sniff: binary STL by its size, header starting with solid");
    st_soup_free(cube);
}

/* ---- OBJ ----------------------------------------------------------------- */

static void test_obj(void)
{
    st_error err;
    st_soup *s = parse_text(ST_SOUP_OBJ,
                            "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\n"
                            "f 1 2 3 4 5\n",
                            "fan.obj", &err);
    TAP_CHECK(s && s->ntris == 3 && tri_is(s, 0, 0, 1, 2) &&
                  tri_is(s, 1, 0, 2, 3) && tri_is(s, 2, 0, 3, 4),
              "obj: a pentagon fans as v0 v1 v2, v0 v2 v3, v0 v3 v4");
    st_soup_free(s);

    s = parse_text(ST_SOUP_OBJ,
                   "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n"
                   "vt 0 0\nvt 1 0\nvt 0 1\nvn 0 0 1\n"
                   "f 1/1 2/2 3/3\nf 1//1 2//1 4//1\nf 1/1/1 3/3/1 4/2/1\n",
                   "slash.obj", &err);
    TAP_CHECK(s && s->ntris == 3 && tri_is(s, 0, 0, 1, 2) &&
                  tri_is(s, 1, 0, 1, 3) && tri_is(s, 2, 0, 2, 3),
              "obj: i/t, i//n and i/t/n take the vertex index");
    st_soup_free(s);

    s = parse_text(ST_SOUP_OBJ,
                   "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -3 -2 -1\n"
                   "v 5 5 5\nf -4 -1 -2/-2/-1\n",
                   "neg.obj", &err);
    TAP_CHECK(s && s->ntris == 2 && tri_is(s, 0, 0, 1, 2) &&
                  tri_is(s, 1, 0, 3, 2),
              "obj: negative indices count back from the last vertex read");
    st_soup_free(s);

    s = parse_text(ST_SOUP_OBJ,
                   "# header\nmtllib a.mtl\no first\ng g1 g2\nusemtl red\n"
                   "s 1\nv 0 0 0\nv 1 0 0\nv 0 1 0\n\n   \nv 0 0 1\n"
                   "vp 0.5\nf 1 2 3\nl 1 2\np 3\ns off\no second\ng g3\n"
                   "usemtl blue\nf 1 3 4\n# end\n",
                   "groups.obj", &err);
    TAP_CHECK(s && s->nverts == 4 && s->ntris == 2 &&
                  tri_is(s, 1, 0, 2, 3),
              "obj: groups, objects, materials, l, p form one soup");
    st_soup_free(s);

    s = parse_text(ST_SOUP_OBJ,
                   "v 0 0 0\r\nv 1 0 0\r\nv 0 1 0\r\nf 1 2 3\r\n",
                   "crlf.obj", &err);
    TAP_CHECK(s && s->ntris == 1 && vert_is(s, 1, 1, 0, 0),
              "obj: CRLF line endings");
    st_soup_free(s);

    s = parse_text(ST_SOUP_OBJ,
                   "v 0 0 0\nv 1 \\\n 0 0\nv 0 1 0\nv 1 1 0\n"
                   "f 1 2 \\\r\n  3 4\n",
                   "cont.obj", &err);
    TAP_CHECK(s && s->nverts == 4 && s->ntris == 2 && vert_is(s, 1, 1, 0, 0) &&
                  tri_is(s, 1, 0, 2, 3),
              "obj: backslash continues a line");
    if (!s)
        note_error(&err);
    st_soup_free(s);

    s = parse_text(ST_SOUP_OBJ,
                   "v 1 2 3 1.0\nv 4 5 6 0.1 0.2 0.3\nv 7e0 8.5 -9 # tail\n"
                   "f 1 2 3 # comment\n",
                   "extra.obj", &err);
    TAP_CHECK(s && s->nverts == 3 && vert_is(s, 0, 1, 2, 3) &&
                  vert_is(s, 1, 4, 5, 6) && vert_is(s, 2, 7, 8.5, -9),
              "obj: w and vertex colours are ignored");
    st_soup_free(s);

    s = parse_text(ST_SOUP_OBJ, "f 1 2 3\nv 0 0 0\nv 1 0 0\nv 0 1 0\n",
                   "fwd.obj", &err);
    TAP_CHECK(s && s->ntris == 1 && soup_valid(s),
              "obj: a face may name vertices defined later");
    st_soup_free(s);

    s = parse_text(ST_SOUP_OBJ,
                   "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 0\nv 1 0 0\nv 0 1 0\n"
                   "f 1 2 3\nf 1 2 3\nf 4 5 6\nf 1 1 2\nf 3 3 3\n",
                   "dup.obj", &err);
    TAP_CHECK(s && s->nverts == 6 && s->ntris == 5 && tri_is(s, 1, 0, 1, 2) &&
                  tri_is(s, 2, 3, 4, 5) && tri_is(s, 3, 0, 0, 1) &&
                  tri_is(s, 4, 2, 2, 2),
              "obj: no welding; duplicate and degenerate triangles kept");
    st_soup_free(s);

    /* Errors, each at its line. */
    expect_text_error("obj error: face with 2 vertices, at its line",
                      ST_SOUP_OBJ, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\n",
                      "e.obj", ST_EINPUT, 4, "face has 2 vertices");
    expect_text_error("obj error: face index 0", ST_SOUP_OBJ,
                      "v 0 0 0\nv 1 0 0\nv 0 1 0\n\nf 0 1 2\n", "e.obj",
                      ST_EINPUT, 5, "face index 0");
    expect_text_error("obj error: index out of range names the count",
                      ST_SOUP_OBJ,
                      "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 0\nv 1 0 0\n"
                      "v 0 1 0\nv 0 0 1\nv 1 1 1\nf 1 2 3\nf 1 9 2\n",
                      "e.obj", ST_EINPUT, 10,
                      "face index 9 out of range (file has 8 vertices)");
    expect_text_error("obj error: negative index before the first vertex",
                      ST_SOUP_OBJ, "v 0 0 0\nv 1 0 0\nf -1 -2 -3\n", "e.obj",
                      ST_EINPUT, 3, "face index -3 out of range");
    expect_text_error("obj error: nan coordinate", ST_SOUP_OBJ,
                      "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n", "e.obj",
                      ST_EINPUT, 2, "coordinate is not finite");
    expect_text_error("obj error: inf and overflowing coordinates",
                      ST_SOUP_OBJ, "v 0 0 0\nv 1 0 0\nv 0 1e999 0\nf 1 2 3\n",
                      "e.obj", ST_EINPUT, 3, "coordinate is not finite");
    expect_text_error("obj error: vertex with 2 coordinates", ST_SOUP_OBJ,
                      "v 0 0 0\nv 1 0\n", "e.obj", ST_EINPUT, 2,
                      "vertex has 2 coordinates");
    expect_text_error("obj error: a word where a number belongs",
                      ST_SOUP_OBJ, "v 0 0 0\nv 1 0 zero\n", "e.obj",
                      ST_EINPUT, 2, "bad coordinate 'zero'");
    expect_text_error("obj error: a bad face token", ST_SOUP_OBJ,
                      "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 x3\n", "e.obj",
                      ST_EINPUT, 4, "bad face vertex 'x3'");
    expect_text_error("obj error: vertices but no faces", ST_SOUP_OBJ,
                      "v 0 0 0\nv 1 0 0\nv 0 1 0\n", "e.obj", ST_EINPUT, 0,
                      "no triangles");
    expect_text_error("obj error: empty file", ST_SOUP_OBJ, "", "e.obj",
                      ST_EINPUT, 0, "empty");
    expect_text_error("obj error: forward reference never satisfied",
                      ST_SOUP_OBJ, "v 0 0 0\nf 1 2 3\nv 1 0 0\nv 0 1 0\n"
                      "f 1 2 7\n",
                      "e.obj", ST_EINPUT, 5,
                      "face index 7 out of range (file has 3 vertices)");
    static const unsigned char garbage[] = {0x00, 0xff, 0x13, 0x37, 0x0a,
                                            0x80, 0x7f, 'f', 0x01, 0x0a};
    expect_bin_error("obj error: binary garbage is not OBJ text (at its first binary byte)",
                     ST_SOUP_OBJ, garbage, sizeof garbage, "g.obj", ST_EINPUT,
                     0, "not OBJ text: a binary byte, 0x00");
    static const unsigned char stl_head[] = {'s', 'o', 'l', 'i', 'd', ' ', 'x', '\n',
                                             0x02, 0x00, 0x00, 0x00};
    expect_bin_error("obj error: a binary STL renamed .obj is not OBJ text",
                     ST_SOUP_OBJ, stl_head, sizeof stl_head, "s.obj", ST_EINPUT,
                     8, "not OBJ text: a binary byte, 0x02");
    expect_text_error("obj error: text without a v or f record is not an OBJ", ST_SOUP_OBJ,
                      "hello\nworld\n", "e.obj", ST_EINPUT, 0,
                      "not an OBJ file: no 'v' or 'f' record");
}

/* Numbers: the fast path must agree with strtod bit for bit. */
static void test_numbers(void)
{
    static const char *const nums[] = {
        "0", "-0", "1", "-1", "0.1", "0.3", "1e-5", "1E+2", ".5", "5.",
        "+7.25", "123456789012345678901234", "0.000000000000000000001234",
        "1.7976931348623157e308", "2.2250738585072014e-308",
        "4.9e-324", "9007199254740993", "3.14159265358979323846264338",
        "1e22", "1e23", "8.98846567431158e307", "0x1p3", "00012.500",
        "1.00000000000000011102230246251565404236316680908203125",
        "-2.5e-3", "6.02214076e23", "1e-22", "123.456e-7"};
    size_t n = sizeof nums / sizeof nums[0];
    int ok = 1;
    for (size_t i = 0; i < n && ok; i++) {
        char text[256];
        snprintf(text, sizeof text, "v %s 0 0\nv 0 0 0\nv 0 0 0\nf 1 2 3\n",
                 nums[i]);
        st_error err;
        st_soup *s = parse_text(ST_SOUP_OBJ, text, "n.obj", &err);
        double want = strtod(nums[i], NULL);
        ok = s && memcmp(&s->xyz[0], &want, sizeof want) == 0;
        if (!ok)
            TAP_NOTE("%s: got %.17g want %.17g", nums[i], s ? s->xyz[0] : 0,
                     want);
        st_soup_free(s);
    }
    TAP_CHECK(ok, "numbers: edge-case decimals convert exactly as strtod");

    /* Random values printed in the usual ways. */
    unsigned long long state = 88172645463325252ULL;
    ok = 1;
    for (int i = 0; i < 20000 && ok; i++) {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        double m = (double)(state >> 11) / 9007199254740992.0;
        int e = (int)(state % 40) - 20;
        double v = (m - 0.5) * pow(10.0, e);
        char tok[64];
        switch (i % 5) {
        case 0: snprintf(tok, sizeof tok, "%.17g", v); break;
        case 1: snprintf(tok, sizeof tok, "%.6f", v); break;
        case 2: snprintf(tok, sizeof tok, "%g", v); break;
        case 3: snprintf(tok, sizeof tok, "%.9e", v); break;
        default: snprintf(tok, sizeof tok, "%.15g", v); break;
        }
        char text[128];
        snprintf(text, sizeof text, "v %s 0 0\nf 1 1 1\n", tok);
        st_error err;
        st_soup *s = parse_text(ST_SOUP_OBJ, text, "r.obj", &err);
        double want = strtod(tok, NULL);
        ok = s && memcmp(&s->xyz[0], &want, sizeof want) == 0;
        if (!ok)
            TAP_NOTE("%s: got %.17g want %.17g", tok, s ? s->xyz[0] : 0,
                     want);
        st_soup_free(s);
    }
    TAP_CHECK(ok, "numbers: 20000 random decimals convert exactly as strtod");
}

/* ---- OFF ----------------------------------------------------------------- */

static void test_off(void)
{
    st_error err;
    st_soup *s = parse_text(ST_SOUP_OFF,
                            "# leading comment\n\nOFF # keyword\n"
                            "# counts next\n4 2 0\n"
                            "0 0 0 # origin\n1 0 0\n\n1 1 0\n0 1 0\n"
                            "# faces\n3 0 1 2\n3 0 2 3 # tail\n",
                            "c.off", &err);
    TAP_CHECK(s && s->nverts == 4 && s->ntris == 2 && tri_is(s, 1, 0, 2, 3),
              "off: comments and blank lines anywhere");
    st_soup_free(s);

    s = parse_text(ST_SOUP_OFF,
                   "COFF 4 1 0\n0 0 0 255 0 0 255\n2 0 0 0 255 0 255\n"
                   "2 2 0 0 0 255 255\n0 2 0 1 1 1 1\n"
                   "4 0 1 2 3 0.5 0.5 0.5 1\n",
                   "col.off", &err);
    TAP_CHECK(s && s->nverts == 4 && s->ntris == 2 &&
                  vert_is(s, 2, 2, 2, 0) && tri_is(s, 0, 0, 1, 2) &&
                  tri_is(s, 1, 0, 2, 3),
              "off: counts on the keyword line, vertex and face colours");
    st_soup_free(s);

    static const char *const kws[] = {"NOFF", "CNOFF", "STOFF", "STCNOFF"};
    int ok = 1;
    for (int i = 0; i < 4 && ok; i++) {
        char text[256];
        snprintf(text, sizeof text,
                 "%s\n3 1 0\n0 0 0 0 0 1 0.5 0.5\n1 0 0 0 0 1 0.5 0.5\n"
                 "0 1 0 0 0 1 0.5 0.5\n3 0 1 2\n",
                 kws[i]);
        s = parse_text(ST_SOUP_OFF, text, "v.off", &err);
        ok = s && s->ntris == 1 && vert_is(s, 1, 1, 0, 0);
        st_soup_free(s);
    }
    TAP_CHECK(ok, "off: NOFF, CNOFF, STOFF, STCNOFF");

    s = parse_text(ST_SOUP_OFF,
                   "OFF\r\n6 3 0\r\n0 0 0\r\n1 0 0\r\n0 1 0\r\n0 0 0\r\n"
                   "1 0 0\r\n0 1 0\r\n3 0 1 2\r\n3 3 4 5\r\n3 0 1 2\r\n",
                   "dup.off", &err);
    TAP_CHECK(s && s->nverts == 6 && s->ntris == 3 && tri_is(s, 2, 0, 1, 2),
              "off: CRLF, no welding, duplicate faces kept");
    st_soup_free(s);

    s = parse_text(ST_SOUP_OFF,
                   "OFF\n5 1 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 0 1\n"
                   "5 4 3 2 1 0\n",
                   "fan.off", &err);
    TAP_CHECK(s && s->ntris == 3 && tri_is(s, 0, 4, 3, 2) &&
                  tri_is(s, 1, 4, 2, 1) && tri_is(s, 2, 4, 1, 0),
              "off: a pentagon fans from its first vertex");
    st_soup_free(s);

    /* Errors. The padding comment keeps the byte check from firing first
     * where the test is about the data running out. */
    expect_text_error("off error: file ends before the vertices do",
                      ST_SOUP_OFF,
                      "OFF\n10 1 0\n# padding padding padding padding\n"
                      "0.000000 0.000000 0.000000\n"
                      "1.000000 0.000000 0.000000\n"
                      "0.000000 1.000000 0.000000\n"
                      "0.000000 0.000000 1.000000\n",
                      "t.off", ST_EINPUT, 7,
                      "header says 10 vertices, file ends after 4");
    expect_text_error("off error: file ends before the faces do",
                      ST_SOUP_OFF,
                      "OFF\n3 4 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"
                      "# padding padding padding padding\n",
                      "t.off", ST_EINPUT, 7,
                      "header says 4 faces, file ends after 1");
    expect_text_error("off error: an absurd count is refused at its line",
                      ST_SOUP_OFF,
                      "OFF\n# big\n1000000000000 1 0\n0 0 0\n1 0 0\n0 1 0\n"
                      "3 0 1 2\n",
                      "big.off", ST_EINPUT, 3,
                      "header says 1000000000000 vertices");
    expect_text_error("off error: absurd face count", ST_SOUP_OFF,
                      "OFF 3 1000000000000 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n",
                      "big.off", ST_EINPUT, 1,
                      "1000000000000 faces");
    expect_text_error("off error: face index out of range", ST_SOUP_OFF,
                      "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n", "e.off",
                      ST_EINPUT, 6,
                      "face index 3 out of range (file has 3 vertices)");
    expect_text_error("off error: negative face index", ST_SOUP_OFF,
                      "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 -1 2\n", "e.off",
                      ST_EINPUT, 6, "face index -1 out of range");
    expect_text_error("off error: face with 2 vertices", ST_SOUP_OFF,
                      "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n2 0 1\n# pad\n",
                      "e.off",
                      ST_EINPUT, 6, "face has 2 vertices");
    expect_text_error("off error: face line shorter than its count",
                      ST_SOUP_OFF,
                      "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n4 0 1 2\n", "e.off",
                      ST_EINPUT, 6, "face lists 3 of its 4 vertices");
    expect_text_error("off error: nan coordinate", ST_SOUP_OFF,
                      "OFF\n3 1 0\n0 0 0\n1 NaN 0\n0 1 0\n3 0 1 2\n", "e.off",
                      ST_EINPUT, 4, "coordinate is not finite");
    expect_text_error("off error: vertex line too short", ST_SOUP_OFF,
                      "OFF\n3 1 0\n0 0 0\n1 0\n0 1 0\n3 0 1 2\n# pad\n",
                      "e.off",
                      ST_EINPUT, 4, "vertex has 2 coordinates");
    expect_text_error("off error: missing counts", ST_SOUP_OFF,
                      "OFF\n# nothing\n", "e.off", ST_EINPUT, 2,
                      "missing vertex and face counts");
    expect_text_error("off error: a bad count", ST_SOUP_OFF,
                      "OFF\n3 one 0\n", "e.off", ST_EINPUT, 2,
                      "bad count 'one'");
    expect_text_error("off error: not an OFF header", ST_SOUP_OFF,
                      "# c\nOBJ\n3 1 0\n", "e.off", ST_EINPUT, 2,
                      "expected an OFF header, found 'OBJ'");
    expect_text_error("off error: 4OFF is unsupported", ST_SOUP_OFF,
                      "4OFF\n3 1 0\n", "e.off", ST_EINPUT, 1,
                      "unsupported OFF variant '4OFF'");
    expect_text_error("off error: binary OFF is unsupported", ST_SOUP_OFF,
                      "OFF BINARY\n", "e.off", ST_EINPUT, 1, "binary OFF");
    expect_text_error("off error: no faces", ST_SOUP_OFF,
                      "OFF\n3 0 0\n0 0 0\n1 0 0\n0 1 0\n", "e.off", ST_EINPUT,
                      0, "no triangles");
    expect_text_error("off error: blank file", ST_SOUP_OFF, "\n\n  \n",
                      "e.off", ST_EINPUT, 3, "no OFF header");
}

/* ---- PLY ----------------------------------------------------------------- */

static void test_ply(void)
{
    st_error err;
    st_soup *s = parse_text(
        ST_SOUP_PLY,
        "ply\nformat ascii 1.0\ncomment made by hand\nobj_info nothing\n"
        "element edge 1\nproperty int vertex1\nproperty int vertex2\n"
        "element vertex 4\nproperty float nx\nproperty float32 x\n"
        "property list uchar int tags\nproperty double y\n"
        "property uchar red\nproperty float z\n"
        "element face 2\nproperty list uchar int vertex_indices\n"
        "property list int float texcoord\n"
        "element material 1\nproperty list uint8 float rgb\n"
        "end_header\n"
        "0 1\n"
        "9 0 2 5 5 0 255 0\n9 1 0 0 255 0\n9 1 1 7 1 255 0\n"
        "9 0 3 1 2 3 1 255 0.5\n"
        "3 0 1 2 6 0 0 1 0 1 1\n3 0 2 3 0\n"
        "3 0.1 0.2 0.3\n",
        "a.ply", &err);
    TAP_CHECK(s && s->nverts == 4 && s->ntris == 2 &&
                  vert_is(s, 0, 0, 0, 0) && vert_is(s, 2, 1, 1, 0) &&
                  vert_is(s, 3, 0, 1, 0.5) && tri_is(s, 1, 0, 2, 3),
              "ply ascii: extra properties, lists and elements skipped");
    if (!s)
        note_error(&err);
    st_soup_free(s);

    s = parse_text(ST_SOUP_PLY,
                   "ply\r\nformat ascii 1.0\r\nelement face 1\r\n"
                   "property list int uint vertex_index\r\n"
                   "element vertex 4\r\nproperty int x\r\nproperty int y\r\n"
                   "property int z\r\nend_header\r\n"
                   "4 3 2 1 0\r\n0 0 0\r\n1 0 0\r\n1 1 0\r\n0 1 0\r\n",
                   "b.ply", &err);
    TAP_CHECK(s && s->nverts == 4 && s->ntris == 2 && tri_is(s, 0, 3, 2, 1) &&
                  tri_is(s, 1, 3, 1, 0) && vert_is(s, 2, 1, 1, 0),
              "ply ascii: faces before vertices, vertex_index, int counts, "
              "CRLF");
    if (!s)
        note_error(&err);
    st_soup_free(s);

    for (int be = 0; be <= 1; be++) {
        bytes b;
        ply_mixed(&b, be);
        st_soup *t = NULL;
        parse(&t, ST_SOUP_PLY, b.d, b.n, "m.ply", &err);
        TAP_CHECK(t && t->nverts == 4 && t->ntris == 2 &&
                      vert_is(t, 0, 0, 0, -1) && vert_is(t, 2, 2, 3, 5) &&
                      tri_is(t, 0, 0, 1, 2) && tri_is(t, 1, 0, 2, 3),
                  "ply %s: mixed scalar types, lists everywhere, extra "
                  "elements",
                  be ? "binary_big_endian" : "binary_little_endian");
        if (!t)
            note_error(&err);
        st_soup_free(t);
    }

    /* uint16 counts and int8 indices, little endian, no welding. */
    bytes b = {.n = 0, .be = 0};
    put_str(&b, "ply\nformat binary_little_endian 1.0\nelement vertex 3\n"
                "property uint16 x\nproperty int8 y\nproperty float64 z\n"
                "element face 2\nproperty list ushort char vertex_indices\n"
                "end_header\n");
    for (int v = 0; v < 3; v++) {
        put_uint(&b, (uint64_t)v, 2);
        put_u8(&b, (unsigned)(v == 2));
        put_f64(&b, -0.5);
    }
    for (int f = 0; f < 2; f++) {
        put_uint(&b, 3, 2);
        put_u8(&b, 0);
        put_u8(&b, 1);
        put_u8(&b, 2);
    }
    s = NULL;
    parse(&s, ST_SOUP_PLY, b.d, b.n, "c.ply", &err);
    TAP_CHECK(s && s->ntris == 2 && tri_is(s, 1, 0, 1, 2) &&
                  vert_is(s, 2, 2, 1, -0.5),
              "ply binary: ushort counts, char indices, duplicate faces");
    st_soup_free(s);

    /* Header errors, at their lines. */
    static const char hdr[] =
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
        "property float y\nproperty float z\n";
    char text[1024];
    snprintf(text, sizeof text,
             "%selement face 1000000000000\n"
             "property list uchar int vertex_indices\nend_header\n"
             "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n", hdr);
    expect_text_error("ply error: absurd element count, at its header line",
                      ST_SOUP_PLY, text, "h.ply", ST_EINPUT, 7,
                      "header says 1000000000000 'face' records");
    snprintf(text, sizeof text,
             "%selement face 1\nproperty list uchar int vertex_indices\n",
             hdr);
    expect_text_error("ply error: header without end_header", ST_SOUP_PLY,
                      text, "h.ply", ST_EINPUT, 8, "no end_header");
    snprintf(text, sizeof text,
             "%sproperty float128 w\nend_header\n", hdr);
    expect_text_error("ply error: unknown property type", ST_SOUP_PLY, text,
                      "h.ply", ST_EINPUT, 7,
                      "unknown property type 'float128'");
    expect_text_error("ply error: no vertex element", ST_SOUP_PLY,
                      "ply\nformat ascii 1.0\nelement face 1\n"
                      "property list uchar int vertex_indices\nend_header\n"
                      "3 0 1 2\n",
                      "h.ply", ST_EINPUT, 5, "no vertex element");
    expect_text_error("ply error: vertex element without z", ST_SOUP_PLY,
                      "ply\nformat ascii 1.0\nelement vertex 3\n"
                      "property float x\nproperty float y\nend_header\n"
                      "0 0\n1 0\n0 1\n",
                      "h.ply", ST_EINPUT, 3, "no 'z' property");
    snprintf(text, sizeof text, "%selement face 1\nproperty int n\n"
                                "end_header\n0 0 0\n1 0 0\n0 1 0\n3\n", hdr);
    expect_text_error("ply error: face element without an index list",
                      ST_SOUP_PLY, text, "h.ply", ST_EINPUT, 7,
                      "no vertex_indices list");
    snprintf(text, sizeof text,
             "%selement face 1\nproperty list uchar float vertex_indices\n"
             "end_header\n", hdr);
    expect_text_error("ply error: float face indices", ST_SOUP_PLY, text,
                      "h.ply", ST_EINPUT, 8, "not integers");
    expect_text_error("ply error: unknown format", ST_SOUP_PLY,
                      "ply\nformat binary_middle_endian 1.0\n", "h.ply",
                      ST_EINPUT, 2, "unknown PLY format");
    {
        /* A header line without a keyword (Blender 2.4x's "Created by
         * ...") is skipped with a warning, the first one whole and the
         * others counted; the soup is the same as without them. */
        const char *blender =
            "ply\nformat ascii 1.0\n"
            "Created by Blender3D 247 - www.blender.org, source file: 'x.blend'\n"
            "element vertex 3\nproperty float x\nproperty float y\n"
            "property float z\nhello there\n"
            "element face 1\nproperty list uchar int vertex_indices\n"
            "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
        st_soup_warnings w;
        st_soup *ws = NULL;
        st_error werr;
        st_error_clear(&werr);
        st_status st = st_soup_parse_warn(&ws, ST_SOUP_PLY,
                                          (const unsigned char *)blender,
                                          strlen(blender), "b.ply", &w, &werr);
        TAP_CHECK(st == ST_OK && ws && ws->nverts == 3 && ws->ntris == 1,
                  "ply: header lines without a keyword are skipped");
        TAP_CHECK(w.count == 2 && w.first.status == ST_OK &&
                      w.first.line == 3 &&
                      strcmp(w.first.file, "b.ply") == 0 &&
                      strstr(w.first.msg, "without a keyword skipped: "
                                          "'Created by Blender3D 247") != NULL,
                  "ply: the first skipped line is a warning at its line, "
                  "the second counted");
        if (w.count != 2 || !strstr(w.first.msg, "Created"))
            TAP_NOTE("warnings %zu, first line %lld: %s", w.count,
                     w.first.line, w.first.msg);
        st_soup_free(ws);
        ws = NULL;
        const char *clean = "ply\nformat ascii 1.0\n"
                            "element vertex 3\nproperty float x\n"
                            "property float y\nproperty float z\n"
                            "element face 1\n"
                            "property list uchar int vertex_indices\n"
                            "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
        st = st_soup_parse_warn(&ws, ST_SOUP_PLY, (const unsigned char *)clean,
                                strlen(clean), "c.ply", &w, &werr);
        TAP_CHECK(st == ST_OK && w.count == 0 && w.first.msg[0] == '\0',
                  "ply: a clean header gives no warning");
        st_soup_free(ws);
        /* A misspelled keyword is a warning, and the error that follows
         * still names its line's consequence. */
        ws = NULL;
        const char *typo = "ply\nformat ascii 1.0\nelment vertex 3\n"
                           "end_header\n";
        st = st_soup_parse_warn(&ws, ST_SOUP_PLY, (const unsigned char *)typo,
                                strlen(typo), "t.ply", &w, &werr);
        TAP_CHECK(st == ST_EINPUT && !ws && w.count == 1 && w.first.line == 3 &&
                      strstr(werr.msg, "no vertex element") != NULL,
                  "ply: a misspelled keyword warns, then 'no vertex element'");
    }
    expect_text_error("ply error: no magic", ST_SOUP_PLY,
                      "format ascii 1.0\n", "h.ply", ST_EINPUT, 1,
                      "not a PLY file");

    /* ASCII body errors, at their lines. */
    snprintf(text, sizeof text,
             "%selement face 1\nproperty list uchar int vertex_indices\n"
             "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n", hdr);
    expect_text_error("ply ascii error: face index out of range",
                      ST_SOUP_PLY, text, "a.ply", ST_EINPUT, 13,
                      "face index 3 out of range (file has 3 vertices)");
    snprintf(text, sizeof text,
             "%selement face 2\nproperty list uchar int vertex_indices\n"
             "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n3 0 1\n", hdr);
    expect_text_error("ply ascii error: truncated, at the last line",
                      ST_SOUP_PLY, text, "a.ply", ST_EINPUT, 14,
                      "file ends in element 'face' (record 2 of 2)");
    snprintf(text, sizeof text,
             "%selement face 1\nproperty list uchar int vertex_indices\n"
             "end_header\n0 0 0\n1 inf 0\n0 1 0\n3 0 1 2\n", hdr);
    expect_text_error("ply ascii error: infinite coordinate", ST_SOUP_PLY,
                      text, "a.ply", ST_EINPUT, 11,
                      "coordinate is not finite");
    snprintf(text, sizeof text,
             "%selement face 1\nproperty list uchar int vertex_indices\n"
             "end_header\n0 0 0\n1 0 0\n0 1 0\n2 0 1\n", hdr);
    expect_text_error("ply ascii error: face with 2 vertices", ST_SOUP_PLY,
                      text, "a.ply", ST_EINPUT, 13, "face has 2 vertices");

    /* Binary body errors, at their byte offsets. */
    bytes m;
    ply_mixed(&m, 0);
    size_t body = (size_t)(strstr((const char *)m.d, "end_header\n") -
                           (const char *)m.d) + 11;
    /* The first vertex record starts after the material (1 + 12 + 1);
     * the face record after the 4 vertices (21 bytes + 2 per tag each). */
    size_t v0 = body + 14;
    size_t f0 = body + 14 + (8 + 1 + 4 + 4 + 2 + 2) * 4 + 2 * (0 + 1 + 2 + 3);
    expect_error("ply binary error: cut in the vertices, too few bytes for "
                 "the header's counts, at its line",
                 ST_SOUP_PLY, m.d, body + 45, "m.ply", ST_EINPUT, 8, -1,
                 "header says 4 'vertex' records but only 45 bytes");
    expect_bin_error("ply binary error: truncated in a list, at the offset",
                     ST_SOUP_PLY, m.d, f0 + 13, "m.ply", ST_EINPUT,
                     (long long)(f0 + 5),
                     "file ends in element 'face' (record 1 of 1)");
    bytes bad = m;
    uint64_t nanbits = 0x7ff8000000000000ULL;
    memcpy(bad.d + v0, &nanbits, 8);
    expect_bin_error("ply binary error: nan coordinate, at its offset",
                     ST_SOUP_PLY, bad.d, bad.n, "m.ply", ST_EINPUT,
                     (long long)v0, "coordinate is not finite");
    /* The face record: flags (1), count (4), then four uint32 indices. */
    bad = m;
    bad.d[f0 + 5 + 4 * 2] = 9;
    expect_bin_error("ply binary error: index out of range, at its offset",
                     ST_SOUP_PLY, bad.d, bad.n, "m.ply", ST_EINPUT,
                     (long long)(f0 + 5 + 8),
                     "face index 9 out of range (file has 4 vertices)");
    bad = m;
    bad.d[f0 + 1] = 0xff;   /* count 0xffffffff as an int: -1 */
    bad.d[f0 + 2] = 0xff;
    bad.d[f0 + 3] = 0xff;
    bad.d[f0 + 4] = 0xff;
    expect_bin_error("ply binary error: negative list length", ST_SOUP_PLY,
                     bad.d, bad.n, "m.ply", ST_EINPUT, (long long)(f0 + 1),
                     "negative list length");
    bad = m;
    bad.d[f0 + 1] = 0x00;
    bad.d[f0 + 4] = 0x7f;   /* 0x7f000000 indices in a small file */
    expect_bin_error("ply binary error: huge list length runs off the end",
                     ST_SOUP_PLY, bad.d, bad.n, "m.ply", ST_EINPUT,
                     (long long)(f0 + 5), "file ends in element 'face'");
}

/* ---- STL ----------------------------------------------------------------- */

static void test_stl(void)
{
    st_error err;
    st_soup *s = parse_text(
        ST_SOUP_STL,
        "solid first part\n"
        "facet normal 0 0 1\n outer loop\n  vertex 0 0 0\n  vertex 1 0 0\n"
        "  vertex 0 1 0\n endloop\nendfacet\nendsolid first part\n"
        "SOLID second\r\n\tFACET NORMAL nan nan nan\r\n\t\tOuter Loop\r\n"
        "  VERTEX 0 0 0   vertex 1 0 0\r\n vertex   0 1 0\r\n"
        "EndLoop EndFacet\r\n"
        "facet normal 0 0 1 outer loop vertex 5 5 5 vertex 6 5 5 "
        "vertex 5 6 5 endloop endfacet\n"
        "endsolid\n",
        "two.stl", &err);
    TAP_CHECK(s && s->ntris == 3 && s->nverts == 9 && tri_is(s, 1, 3, 4, 5) &&
                  vert_is(s, 3, 0, 0, 0) && vert_is(s, 8, 5, 6, 5),
              "stl ascii: two solids, any case and whitespace, "
              "three vertices per triangle");
    if (!s)
        note_error(&err);
    st_soup_free(s);

    s = parse_text(ST_SOUP_STL,
                   "solid q\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\n"
                   "vertex 1 0 0\nvertex 1 1 0\nvertex 0 1 0\nendloop\n"
                   "endfacet\nendsolid q\n",
                   "quad.stl", &err);
    TAP_CHECK(s && s->ntris == 2 && s->nverts == 4 && tri_is(s, 1, 0, 2, 3),
              "stl ascii: a loop of 4 vertices is fanned");
    st_soup_free(s);

    st_soup *cube = parse_text(ST_SOUP_OBJ, cube_obj, "cube.obj", &err);
    bytes plain, b;
    soup_to_stl_binary(cube, "binary cube", &plain);
    s = NULL;
    parse(&s, ST_SOUP_STL, plain.d, plain.n, "b.stl", &err);
    TAP_CHECK(s && s->ntris == 12 && s->nverts == 36 && soup_valid(s) &&
                  tri_is(s, 11, 33, 34, 35),
              "stl binary: 12 triangles, 36 vertices");
    st_soup_free(s);

    soup_to_stl_binary(cube, "solid cube exported by a CAD tool, facets 12",
                       &b);
    s = NULL;
    parse(&s, ST_SOUP_STL, b.d, b.n, "solid.stl", &err);
    TAP_CHECK(s && s->ntris == 12 && s->nverts == 36,
              "stl binary: a header starting with 'solid' is still binary");
    if (!s)
        note_error(&err);
    st_soup_free(s);

    /* Binary errors at their offsets. */
    bytes bad = b;
    bad.n -= 7;
    expect_bin_error("stl binary error: count disagrees with the size",
                     ST_SOUP_STL, bad.d, bad.n, "b.stl", ST_EINPUT, 80,
                     "header says 12 triangles");
    bad = b;
    bad.d[80] = 0xff;
    bad.d[81] = 0xff;
    bad.d[82] = 0xff;
    bad.d[83] = 0x7f;
    expect_bin_error("stl binary error: absurd count", ST_SOUP_STL, bad.d,
                     bad.n, "b.stl", ST_EINPUT, 80,
                     "header says 2147483647 triangles");
    bad = b;
    uint32_t infbits = 0x7f800000u;
    size_t off = 84 + 50 * 5 + 12 + 12 + 4;   /* triangle 5, vertex 1, y */
    for (int k = 0; k < 4; k++)
        bad.d[off + (size_t)k] = (unsigned char)(infbits >> (8 * k));
    expect_bin_error("stl binary error: infinite coordinate at its offset",
                     ST_SOUP_STL, bad.d, bad.n, "b.stl", ST_EINPUT,
                     (long long)off, "coordinate is not finite");
    expect_bin_error("stl binary error: too short", ST_SOUP_STL, plain.d, 60,
                     "b.stl", ST_EINPUT, 60, "too short");
    bad = b;
    bad.n = 84;
    memset(bad.d + 80, 0, 4);
    expect_bin_error("stl binary error: zero triangles", ST_SOUP_STL, bad.d,
                     bad.n, "b.stl", ST_EINPUT, -1, "no triangles");
    st_soup_free(cube);

    /* ASCII errors at their lines. */
    expect_text_error("stl ascii error: truncated inside a facet",
                      ST_SOUP_STL,
                      "solid t\nfacet normal 0 0 1\nouter loop\n"
                      "vertex 0 0 0\nvertex 1 0 0\n",
                      "t.stl", ST_EINPUT, 5, "file ends inside a facet");
    expect_text_error("stl ascii error: missing endsolid", ST_SOUP_STL,
                      "solid t\nfacet normal 0 0 1\nouter loop\n"
                      "vertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\n"
                      "endfacet\n",
                      "t.stl", ST_EINPUT, 8, "file ends before endsolid");
    expect_text_error("stl ascii error: nan vertex", ST_SOUP_STL,
                      "solid t\nfacet normal 0 0 1\nouter loop\n"
                      "vertex 0 0 0\nvertex 1 nan 0\nvertex 0 1 0\n"
                      "endloop\nendfacet\nendsolid\n",
                      "t.stl", ST_EINPUT, 5, "coordinate is not finite");
    expect_text_error("stl ascii error: bad coordinate", ST_SOUP_STL,
                      "solid t\nfacet normal 0 0 1\nouter loop\n"
                      "vertex 0 0 0\nvertex 1 0 0\nvertex 0 1,5 0\n"
                      "endloop\nendfacet\nendsolid\n",
                      "t.stl", ST_EINPUT, 6,
                      "expected a coordinate, found '1,5'");
    expect_text_error("stl ascii error: facet with 2 vertices", ST_SOUP_STL,
                      "solid t\nfacet normal 0 0 1\nouter loop\n"
                      "vertex 0 0 0\nvertex 1 0 0\nendloop\nendfacet\n"
                      "endsolid\n",
                      "t.stl", ST_EINPUT, 6, "facet has 2 vertices");
    expect_text_error("stl ascii error: unexpected keyword", ST_SOUP_STL,
                      "solid t\nfacet normal 0 0 1\nouter loop\n"
                      "vertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\n"
                      "endloop\nendloop\nendsolid\n",
                      "t.stl", ST_EINPUT, 8,
                      "expected 'endfacet', found 'endloop'");
    expect_text_error("stl ascii error: garbage after endsolid", ST_SOUP_STL,
                      "solid t\nendsolid t\nhello\n", "t.stl", ST_EINPUT, 3,
                      "expected 'solid', found 'hello'");
    expect_text_error("stl ascii error: text that is not facets",
                      ST_SOUP_STL, "solid x\nhello\n", "t.stl", ST_EINPUT,
                      2, "expected 'facet' or 'endsolid', found 'hello'");
    expect_text_error("stl ascii error: an empty solid", ST_SOUP_STL,
                      "solid t\nendsolid t\n", "t.stl", ST_EINPUT, 0,
                      "no triangles");
}

/* ---- the same cube from every format ------------------------------------ */

static int cube_ok(const st_soup *s)
{
    double lo[3], hi[3];
    st_error err;
    if (!s || s->ntris != 12 || !soup_valid(s) ||
        st_soup_bounds(s, lo, hi, &err) != ST_OK)
        return 0;
    for (int a = 0; a < 3; a++)
        if (lo[a] != 0.0 || hi[a] != 1.0)
            return 0;
    return 1;
}

static void test_cube_everywhere(void)
{
    st_error err;
    st_soup *obj = parse_text(ST_SOUP_OBJ, cube_obj, "cube.obj", &err);
    char stl_ascii[8192];
    size_t stl_n = soup_to_stl_ascii(obj, stl_ascii, sizeof stl_ascii);
    bytes stl_bin;
    soup_to_stl_binary(obj, "solid cube", &stl_bin);
    bytes ply_bin = {.n = 0, .be = 1};
    put_str(&ply_bin, "ply\nformat binary_big_endian 1.0\nelement vertex 8\n"
                      "property float x\nproperty float y\n"
                      "property float z\nelement face 6\n"
                      "property list uchar int vertex_indices\nend_header\n");
    for (size_t v = 0; v < obj->nverts; v++)
        for (int a = 0; a < 3; a++)
            put_f32(&ply_bin, (float)obj->xyz[3 * v + (size_t)a]);
    static const int quads[6][4] = {{0, 3, 2, 1}, {4, 5, 6, 7},
                                    {0, 1, 5, 4}, {1, 2, 6, 5},
                                    {2, 3, 7, 6}, {3, 0, 4, 7}};
    for (int f = 0; f < 6; f++) {
        put_u8(&ply_bin, 4);
        for (int k = 0; k < 4; k++)
            put_i32(&ply_bin, quads[f][k]);
    }

    struct {
        const char *file;
        const void *data;
        size_t n;
        size_t nverts;
    } cases[] = {
        {"cube.obj", cube_obj, strlen(cube_obj), 8},
        {"cube.OFF", cube_off, strlen(cube_off), 8},
        {"cube.ply", cube_ply, strlen(cube_ply), 8},
        {"cube_be.ply", ply_bin.d, ply_bin.n, 8},
        {"cube.stl", stl_ascii, stl_n, 36},
        {"cube_bin.Stl", stl_bin.d, stl_bin.n, 36},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        const char *path = write_tmp(cases[i].file, cases[i].data, cases[i].n);
        st_soup *s = NULL;
        st_status st = st_soup_read(&s, path, &err);
        TAP_CHECK(st == ST_OK && cube_ok(s) && s->nverts == cases[i].nverts,
                  "cube from %s: 12 triangles, %zu vertices, bounds [0,1]^3",
                  cases[i].file, cases[i].nverts);
        if (st)
            note_error(&err);
        st_soup_free(s);

        /* The same bytes without an extension: format sniffed. */
        char noext[64];
        snprintf(noext, sizeof noext, "sniff%zu", i);
        path = write_tmp(noext, cases[i].data, cases[i].n);
        s = NULL;
        st = st_soup_read(&s, path, &err);
        TAP_CHECK(st == ST_OK && cube_ok(s),
                  "cube from %s without extension: format sniffed",
                  cases[i].file);
        if (st)
            note_error(&err);
        st_soup_free(s);
    }
    st_soup_free(obj);
}

/* ---- st_soup_read errors -------------------------------------------------- */

static void test_read_errors(void)
{
    st_error err;
    st_soup *s = NULL;
    const char *path = tmp_path("missing.obj");
    st_status st = st_soup_read(&s, path, &err);
    TAP_CHECK(s == NULL && error_is(st, &err, ST_EIO, path, 0, -1,
                                    "cannot open"),
              "read error: a missing file");

    path = tmp_path("dir.obj");
    mkdir(path, 0700);
    st = st_soup_read(&s, path, &err);
    TAP_CHECK(s == NULL && error_is(st, &err, ST_EIO, path, 0, -1,
                                    "is a directory"),
              "read error: a directory");
    rmdir(path);

    path = write_tmp("empty.stl", "", 0);
    st = st_soup_read(&s, path, &err);
    TAP_CHECK(s == NULL && error_is(st, &err, ST_EINPUT, path, 0, -1,
                                    "file is empty"),
              "read error: an empty file");

    path = write_tmp("notri.obj", "v 1 2 3\n", 8);
    st = st_soup_read(&s, path, &err);
    TAP_CHECK(s == NULL && error_is(st, &err, ST_EINPUT, path, 0, -1,
                                    "no triangles"),
              "read error: a file without triangles");

    path = write_tmp("what.txt", "hello world\n", 12);
    st = st_soup_read(&s, path, &err);
    TAP_CHECK(s == NULL && error_is(st, &err, ST_EINPUT, path, 0, -1,
                                    "unknown format"),
              "read error: unknown extension and content");

    static const char bad_off[] =
        "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 5\n";
    path = write_tmp("bad.off", bad_off, strlen(bad_off));
    st = st_soup_read(&s, path, &err);
    TAP_CHECK(s == NULL && error_is(st, &err, ST_EINPUT, path, 6, -1,
                                    "face index 5 out of range"),
              "read error: a reader's error names the path and line");

    char locked[512];   /* tmp_path's buffer is reused below */
    snprintf(locked, sizeof locked, "%s", write_tmp("locked.obj", cube_obj, strlen(cube_obj)));
    path = locked;
    chmod(path, 0);
    if (geteuid() != 0) {
        st = st_soup_read(&s, path, &err);
        TAP_CHECK(s == NULL && error_is(st, &err, ST_EIO, path, 0, -1,
                                        "cannot open"),
                  "read error: an unreadable file");
    } else {
        /* Root reads any file (CI runs as root): drop to nobody (65534)
         * in a child for this check. The directory is opened up so that
         * only the file's own mode refuses, and the child first reads a
         * readable file beside it to show that. */
        char open_path[512];
        snprintf(open_path, sizeof open_path, "%s",
                 write_tmp("open.obj", cube_obj, strlen(cube_obj)));
        chmod(open_path, 0644);
        chmod(tmpdir, 0755);
        fflush(stdout);
        pid_t pid = fork();
        if (pid == 0) {
            if (setgid(65534) || setuid(65534) || geteuid() != 65534)
                _exit(3);
            st_soup *s2 = NULL;
            st_error e2;
            if (st_soup_read(&s2, open_path, &e2) != ST_OK)
                _exit(4);
            st_soup_free(s2);
            s2 = NULL;
            st_status st2 = st_soup_read(&s2, path, &e2);
            _exit(s2 == NULL && error_is(st2, &e2, ST_EIO, path, 0, -1, "cannot open") ? 0 : 1);
        }
        int status = -1;
        if (pid > 0)
            waitpid(pid, &status, 0);
        chmod(tmpdir, 0700);
        unlink(open_path);
        TAP_CHECK(pid > 0 && WIFEXITED(status) && WEXITSTATUS(status) == 0,
                  "read error: an unreadable file (as root: checked as uid 65534; "
                  "child status %d)", status);
    }
    chmod(path, 0600);

    /* Opens, but read() fails (EIO at offset 0), even for root. */
    if (access("/proc/self/mem", R_OK) == 0) {
        st = st_soup_read(&s, "/proc/self/mem", &err);
        TAP_CHECK(s == NULL && error_is(st, &err, ST_EIO, "/proc/self/mem",
                                        0, -1, "cannot read"),
                  "read error: a file that opens but cannot be read");
    } else {
        TAP_CHECK(1, "read error: a file that cannot be read # SKIP no "
                     "/proc/self/mem");
    }
}

/* ---- robustness: every truncation and many byte changes ------------------ */

/* Parse must end in a valid soup or an error that names the file and (for
 * data problems) where. */
static int robust_one(st_soup_format f, const unsigned char *d, size_t n,
                      const char *name)
{
    st_error err;
    st_soup *s = NULL;
    st_status st = parse(&s, f, d, n, name, &err);
    int ok;
    if (st == ST_OK)
        ok = soup_valid(s);
    else
        ok = s == NULL && err.status == st && strcmp(err.file, name) == 0 &&
             (err.line > 0 || err.offset >= 0 ||
              strstr(err.msg, "no triangles") || strstr(err.msg, "empty") ||
              strstr(err.msg, "not an OBJ file") ||
              st == ST_ENOMEM || st == ST_ELIMIT);
    if (!ok)
        note_error(&err);
    st_soup_free(s);
    return ok;
}

static void test_robust(void)
{
    st_error err;
    st_soup *cube = parse_text(ST_SOUP_OBJ, cube_obj, "cube.obj", &err);
    static char stl_ascii[8192];
    size_t stl_n = soup_to_stl_ascii(cube, stl_ascii, sizeof stl_ascii);
    static bytes stl_bin, ply_le, ply_be;
    soup_to_stl_binary(cube, "solid x", &stl_bin);
    ply_mixed(&ply_le, 0);
    ply_mixed(&ply_be, 1);
    st_soup_free(cube);
    struct {
        const char *name;
        st_soup_format f;
        const unsigned char *d;
        size_t n;
    } cases[] = {
        {"r.obj", ST_SOUP_OBJ, (const unsigned char *)cube_obj,
         strlen(cube_obj)},
        {"r.off", ST_SOUP_OFF, (const unsigned char *)cube_off,
         strlen(cube_off)},
        {"r.ply", ST_SOUP_PLY, (const unsigned char *)cube_ply,
         strlen(cube_ply)},
        {"le.ply", ST_SOUP_PLY, ply_le.d, ply_le.n},
        {"be.ply", ST_SOUP_PLY, ply_be.d, ply_be.n},
        {"a.stl", ST_SOUP_STL, (const unsigned char *)stl_ascii, stl_n},
        {"b.stl", ST_SOUP_STL, stl_bin.d, stl_bin.n},
    };
    static const unsigned char subs[] = {'\n', '0', '9', '-', ' ', 0xff,
                                         0x00, '#', '/', 'e'};
    static unsigned char work[8192];
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        int ok = 1;
        for (size_t len = 0; len < cases[i].n && ok; len++)
            ok = robust_one(cases[i].f, cases[i].d, len, cases[i].name);
        TAP_CHECK(ok, "robust: every truncation of %s ends cleanly",
                  cases[i].name);
        ok = 1;
        for (size_t pos = 0; pos < cases[i].n && ok; pos++) {
            for (size_t k = 0; k < sizeof subs && ok; k++) {
                memcpy(work, cases[i].d, cases[i].n);
                work[pos] = subs[k];
                ok = robust_one(cases[i].f, work, cases[i].n, cases[i].name);
            }
        }
        TAP_CHECK(ok, "robust: every single-byte change of %s ends cleanly",
                  cases[i].name);
    }
}

/* test_soup --compare EXPECTED FILE: FILE (any reader, by extension or
 * content) holds the soup EXPECTED does: the same triangles, in order,
 * and vertices within 1e-9 of the model's size (the glTF tests compute
 * their expected world positions in Python, in double). Prints the
 * reader's warnings as "warning: ..." lines. */
static int compare_main(const char *want, const char *got)
{
    st_soup *a = NULL, *b = NULL;
    st_soup_warnings w;
    st_error err;
    char buf[1200];
    if (st_soup_read(&a, want, &err) ||
        st_soup_read_warn(&b, got, &w, &err)) {
        printf("error: %s\n", st_error_format(&err, buf, sizeof buf));
        st_soup_free(a);
        return 1;
    }
    if (w.count)
        printf("warning: %s (%zu)\n",
               st_error_format(&w.first, buf, sizeof buf), w.count);
    int bad = 0;
    if (a->nverts != b->nverts || a->ntris != b->ntris) {
        printf("counts: %zu vertices %zu triangles, want %zu and %zu\n",
               b->nverts, b->ntris, a->nverts, a->ntris);
        bad = 1;
    } else {
        double scale = 0;
        for (size_t i = 0; i < 3 * a->nverts; i++)
            scale = fmax(scale, fabs(a->xyz[i]));
        double tol = 1e-9 * fmax(scale, 1.0);
        for (size_t i = 0; i < 3 * a->nverts && !bad; i++)
            if (!(fabs(a->xyz[i] - b->xyz[i]) <= tol)) {
                printf("vertex %zu: %.17g, want %.17g\n", i / 3, b->xyz[i],
                       a->xyz[i]);
                bad = 1;
            }
        for (size_t i = 0; i < 3 * a->ntris && !bad; i++)
            if (a->tris[i] != b->tris[i]) {
                printf("triangle %zu: corner %u, want %u\n", i / 3,
                       (unsigned)b->tris[i], (unsigned)a->tris[i]);
                bad = 1;
            }
    }
    if (!bad)
        printf("same: %zu vertices, %zu triangles\n", a->nverts, a->ntris);
    st_soup_free(a);
    st_soup_free(b);
    return bad;
}

/* st_soup_bounds against the comparisons written out (lo moves only where
 * a coordinate is strictly below it, hi strictly above), bit for bit: the
 * first of equal values stays, so -0.0 and 0.0 in either order, and only
 * the vertices of triangles count. */
static void test_bounds(void)
{
    static const double vals[] = {-0.0, 0.0, 1.0, -1.0, 0.5, -2.5, 3.0};
    uint64_t r = 12345;
    size_t bad = 0;
    const int N = 2000;
    for (int k = 0; k < N; k++) {
        st_soup *s = st_soup_new();
        if (!s)
            abort();
        size_t nv = 3 + (size_t)(k % 9);
        for (size_t v = 0; v < nv; v++) {
            double c[3];
            for (int a = 0; a < 3; a++) {
                r = r * 6364136223846793005ULL + 1442695040888963407ULL;
                c[a] = vals[(r >> 33) % (sizeof vals / sizeof *vals)];
            }
            st_soup_add_vertex(s, c[0], c[1], c[2], NULL);
        }
        for (size_t t = 0; t + 2 < nv; t += 2)   /* the last vertex or two unused */
            st_soup_add_triangle(s, (uint32_t)t, (uint32_t)t + 1, (uint32_t)t + 2, NULL);
        double lo[3], hi[3], rlo[3] = {INFINITY, INFINITY, INFINITY},
                             rhi[3] = {-INFINITY, -INFINITY, -INFINITY};
        for (size_t i = 0; i < 3 * s->ntris; i++)
            for (int a = 0; a < 3; a++) {
                double x = s->xyz[3 * (size_t)s->tris[i] + a];
                if (x < rlo[a])
                    rlo[a] = x;
                if (x > rhi[a])
                    rhi[a] = x;
            }
        if (st_soup_bounds(s, lo, hi, NULL) != ST_OK || memcmp(lo, rlo, sizeof lo) != 0 ||
            memcmp(hi, rhi, sizeof hi) != 0)
            bad++;
        st_soup_free(s);
    }
    TAP_CHECK(bad == 0, "st_soup_bounds: %d of %d soups of signed zeros and repeats bit for bit "
              "as the comparisons", N - (int)bad, N);
}

int main(int argc, char **argv)
{
    static const tap_test tests[] = {TAP_TEST(soup_api), TAP_TEST(formats), TAP_TEST(obj),
                                     TAP_TEST(numbers), TAP_TEST(off), TAP_TEST(ply),
                                     TAP_TEST(stl), TAP_TEST(cube_everywhere),
                                     TAP_TEST(read_errors), TAP_TEST(robust), TAP_TEST(bounds),
                                     {0}};
    if (argc == 4 && strcmp(argv[1], "--compare") == 0)
        return compare_main(argv[2], argv[3]);
    tap_select(argc, argv, tests);
    snprintf(tmpdir, sizeof tmpdir, "%s/test_soup.XXXXXX",
             getenv("TMPDIR") ? getenv("TMPDIR") : "/tmp");
    if (!mkdtemp(tmpdir)) {
        printf("Bail out! mkdtemp: %s\n", strerror(errno));
        return 1;
    }
    tap_run(tests);

    /* Clean up the temp dir (only the files this test wrote). */
    static const char *const files[] = {
        "cube.obj", "cube.OFF", "cube.ply", "cube_be.ply", "cube.stl",
        "cube_bin.Stl", "sniff0", "sniff1", "sniff2", "sniff3", "sniff4",
        "sniff5", "empty.stl", "notri.obj", "what.txt", "bad.off",
        "locked.obj"};
    for (size_t i = 0; i < sizeof files / sizeof files[0]; i++)
        unlink(tmp_path(files[i]));
    rmdir(tmpdir);
    return tap_done();
}
