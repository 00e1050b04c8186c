/*
 * soup_gltf.c - the glTF 2.0 reader (.gltf JSON with external or data-URI
 * buffers, and .glb binary containers).
 *
 * The Khronos glTF 2.0 specification, sections 3.5-3.7 and 4.4:
 *
 *   .glb      12-byte header "glTF", version 2, total length; a JSON chunk
 *             (type 0x4E4F534A), then optionally a BIN chunk (0x004E4942),
 *             which is buffer 0 when that buffer has no uri.
 *   buffers   byteLength, uri: absent (the GLB chunk), "data:...;base64,"
 *             or a relative reference to a file beside the .gltf (percent-
 *             decoded).
 *   views     buffer, byteOffset, byteLength, byteStride (4..252).
 *   accessors bufferView (absent: zeros), byteOffset, componentType
 *             (5120 i8, 5121 u8, 5122 i16, 5123 u16, 5125 u32, 5126 f32),
 *             normalized, count, type, sparse {count, indices, values}.
 *   meshes    primitives {attributes.POSITION, indices, mode}: 4 TRIANGLES,
 *             5 TRIANGLE_STRIP, 6 TRIANGLE_FAN are read; 0-3 (points,
 *             lines) ignored.
 *   nodes     mesh, children, matrix (16, column-major) or translation,
 *             rotation (x y z w), scale: world = parent * T * R * S.
 *   scenes    the default scene's nodes, or without "scene" every root.
 *
 * Positions are float, or with KHR_mesh_quantization (signed or unsigned)
 * bytes and shorts, normalized or not. Strips give (i, i+1, i+2) for even
 * i and (i+1, i, i+2) for odd i; fans (i+1, i+2, 0): the spec's orders.
 * Each node instance of a mesh adds its own transformed vertices (a soup
 * is never welded).
 *
 * Untrusted sizes: every accessor is checked against its buffer view and
 * every view against its buffer's bytes before a value is read; nothing is
 * allocated from a count in the file (an accessor is read element by
 * element where it lies; the soup grows with what is pushed). An accessor
 * without a buffer view (zeros, maybe sparse) may not count more elements
 * than the input has bytes, so a tiny file cannot ask for 2^32 vertices.
 * Errors name a JSON pointer (/accessors/3) or a byte offset (JSON syntax,
 * GLB structure).
 *
 * JSON: jansson (json_loadb on the unterminated buffer), fuzzed with the
 * reader. Its syntax errors are reported at byte offsets in this reader's
 * words (json_what); nesting is limited to 64 levels (glTF needs under
 * 10) by a pre-scan of the brackets and quotes. Numbers are read as
 * doubles (one too large for a double is an error); strings must be
 * UTF-8 (RFC 8259, glTF 3.2); of duplicate member names the last counts
 * (jansson's rule, JavaScript's JSON.parse's).
 */
#include "../base/fpenv.h"
#include "../base/bytes.h"
#include "soup_internal.h"
#include "soupread.h"
#include "souptet/mem.h"

#include <errno.h>
#include <jansson.h>
#include <fcntl.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* ==== JSON ================================================================ */

#define JSON_MAX_DEPTH 64      /* glTF documents nest less than 10 deep */

/* Member k of object o, element i of array a: NULL when absent or when o,
 * a is not an object, an array (or NULL). */
static const json_t *jget(const json_t *o, const char *k)
{
    return json_is_object(o) ? json_object_get(o, k) : NULL;
}

static const json_t *jat(const json_t *a, size_t i)
{
    return json_is_array(a) ? json_array_get(a, i) : NULL;
}

/* What a pass over the brackets and quotes of the text finds: the offset
 * of the first '[' or '{' nested more than JSON_MAX_DEPTH deep, and of the
 * opening quote of a string the text ends in (-1: none). */
typedef struct json_scan {
    long long deep, open_quote;
} json_scan;

static json_scan json_prescan(const unsigned char *p, size_t n)
{
    json_scan sc = {-1, -1};
    int depth = 0;
    for (size_t i = 0; i < n; i++) {
        unsigned char c = p[i];
        if (sc.open_quote >= 0) {
            if (c == '\\')
                i++;
            else if (c == '"')
                sc.open_quote = -1;
        } else if (c == '"') {
            sc.open_quote = (long long)i;
        } else if (c == '[' || c == '{') {
            if (++depth > JSON_MAX_DEPTH && sc.deep < 0)
                sc.deep = (long long)i;
        } else if ((c == ']' || c == '}') && depth > 0) {
            depth--;
        }
    }
    return sc;
}

/* Where a message of json_what points. */
enum { AT_TOKEN, AT_HERE, AT_BYTE, AT_ESCAPE, AT_NUMBER, AT_STRING };

/* jansson's syntax messages as this reader words them, and the offset to
 * blame in the text: the start of the token jansson quotes ("near '...'",
 * up to 20 bytes) else jansson's position (AT_TOKEN); a control character
 * where it stands (AT_HERE); the byte that is not UTF-8 (AT_BYTE); the
 * backslash of a bad escape (AT_ESCAPE); the start of a number too large
 * for a double (AT_NUMBER); the opening quote of a string the text ends
 * in (AT_STRING). */
static const char *json_what(const json_error_t *je, const unsigned char *text,
                             const json_scan *sc, long long *at)
{
    static const struct { const char *jansson, *ours; int rule; } k[] = {
        {"unexpected token", "unexpected character", AT_TOKEN},
        {"invalid token", "unexpected character", AT_TOKEN},
        {"']' expected", "expected ',' or ']'", AT_TOKEN},
        {"'}' expected", "expected ',' or '}'", AT_TOKEN},
        {"':' expected", "expected ':'", AT_TOKEN},
        {"string or '}' expected", "expected a member name", AT_TOKEN},
        {"end of file expected", "text after the document", AT_TOKEN},
        {"'[' or '{' expected", "document ends inside a value", AT_TOKEN},
        {"premature end of input", "string without its closing quote", AT_STRING},
        {"unexpected newline", "control character in a string", AT_HERE},
        {"control character", "control character in a string", AT_HERE},
        {"invalid escape", "bad escape in a string", AT_ESCAPE},
        {"invalid Unicode", "unpaired UTF-16 surrogate", AT_ESCAPE},
        {"real number overflow", "number out of range", AT_NUMBER},
        {"unable to decode byte", "not UTF-8", AT_BYTE},
    };
    const char *t = je->text, *what = t;
    int rule = AT_TOKEN;
    for (size_t i = 0; i < sizeof k / sizeof k[0]; i++)
        if (strncmp(t, k[i].jansson, strlen(k[i].jansson)) == 0) {
            what = k[i].ours;
            rule = k[i].rule;
        }
    const char *near = strstr(t, " near '"), *q = NULL;
    size_t tlen = strlen(t), qlen = 0;
    if (near && t[tlen - 1] == '\'') {
        q = near + 7;
        qlen = (size_t)(t + tlen - 1 - q);
    }
    const long long pos = je->position;
    *at = q && (size_t)pos >= qlen ? pos - (long long)qlen : pos;
    switch (rule) {
    case AT_HERE:
        *at = pos;
        break;
    case AT_BYTE:
        *at = pos > 0 ? pos - 1 : 0;
        break;
    case AT_STRING:
        if (!q && sc->open_quote >= 0)
            *at = sc->open_quote;
        break;
    case AT_NUMBER:
        if (!q)
            while (*at > 0 && strchr("0123456789+-.eE", text[*at - 1]))
                --*at;
        break;
    case AT_ESCAPE: {
        const char *bs = NULL;
        for (const char *c = q; c && c < q + qlen; c++)
            if (*c == '\\')
                bs = c;
        if (bs) {
            *at += (long long)(bs - q);
            if (bs[1] == 'u' && strncmp(t, "invalid escape", 14) == 0)
                what = "bad \\u escape";
        }
        break;
    }
    default:                                    /* AT_TOKEN */
        if (strstr(t, "near end of file") && strncmp(t, "unexpected", 10) == 0)
            what = "document ends inside a value";
        else if (q && strncmp(t, "invalid token", 13) == 0 &&
                 ((q[0] >= '0' && q[0] <= '9') ||
                  (q[0] == '-' && qlen > 1 && q[1] >= '0' && q[1] <= '9')))
            what = "bad number";
        break;
    }
    return what;
}

/* The JSON text [data, data + size) as a tree in *root (the caller
 * json_decref's it). A UTF-8 byte order mark is tolerated (some exporters
 * write one). Errors at byte offsets from base (the text's place in the
 * file); numbers are all doubles, strings may hold NUL (a uri that does
 * is refused where it is used). */
static st_status json_parse(json_t **root, const unsigned char *data,
                            size_t size, long long base, const char *name,
                            st_error *err)
{
    size_t bom = 0;
    if (size >= 3 && data[0] == 0xEF && data[1] == 0xBB && data[2] == 0xBF)
        bom = 3;
    const json_scan sc = json_prescan(data + bom, size - bom);
    json_error_t je;
    *root = json_loadb((const char *)data + bom, size - bom,
                       JSON_DECODE_ANY | JSON_DECODE_INT_AS_REAL |
                           JSON_ALLOW_NUL,
                       &je);
    long long at = 0;
    const char *what = NULL;
    if (!*root && json_error_code(&je) == json_error_out_of_memory)
        return st_error_set(err, ST_ENOMEM, name, 0, "out of memory");
    if (!*root)
        what = json_what(&je, data + bom, &sc, &at);
    if (sc.deep >= 0 && (*root || sc.deep < at)) {
        at = sc.deep;
        what = "nested more than 64 deep";
    }
    if (!what)
        return ST_OK;
    json_decref(*root);
    *root = NULL;
    return st_error_set_offset(err, ST_EINPUT, name,
                               base + (long long)bom + at, "JSON: %s", what);
}

/* ==== glTF ================================================================ */

#define GLB_MAGIC 0x46546C67u      /* "glTF" */
#define GLB_JSON 0x4E4F534Au
#define GLB_BIN 0x004E4942u

typedef struct buffer {
    const unsigned char *data;  /* NULL until loaded */
    size_t size;                /* byteLength */
    unsigned char *owned;
} buffer;

typedef struct gltf {
    json_t *root;
    const char *name;           /* for messages */
    const char *path;           /* the .gltf's path, NULL: no files */
    const st_soup__file_hook *hook; /* told each file's bytes, or NULL */
    const unsigned char *glb_bin;
    size_t glb_bin_size;
    int have_glb_bin;
    size_t total_bytes;         /* input and buffers: bounds zero accessors */
    buffer *buffers;
    size_t nbuffers;
    st_soup *s;
    st_soup_warnings *warn;
    st_error *err;
    size_t ignored;             /* point and line primitives */
} gltf;

typedef struct accessor {
    const unsigned char *base;  /* first element, NULL: zeros */
    size_t stride, count;
    int ctype, ncomp, normalized;
    /* sparse */
    size_t scount;
    const unsigned char *sidx, *sval;
    int sidx_type;
    size_t idx;                 /* its index, for messages */
} accessor;

static st_status gbad(gltf *g, const char *fmt, ...)
#ifdef __GNUC__
    __attribute__((format(printf, 2, 3)))
#endif
    ;
static st_status gbad(gltf *g, const char *fmt, ...)
{
    char msg[400];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    return st_error_set(g->err, ST_EINPUT, g->name, 0, "%s", msg);
}

/* A non-negative integer member (absent: dflt; dflt < 0: required). */
static st_status get_index(gltf *g, const json_t *o, const char *key,
                           long long dflt, size_t limit, const char *where,
                           size_t wi, size_t *out)
{
    const json_t *v = jget(o, key);
    if (!v) {
        if (dflt < 0)
            return gbad(g, "%s/%zu: no \"%s\"", where, wi, key);
        *out = (size_t)dflt;
        return ST_OK;
    }
    if (!json_is_number(v) || !(json_number_value(v) >= 0) || json_number_value(v) != floor(json_number_value(v)) ||
        json_number_value(v) >= (double)limit)
        return gbad(g, "%s/%zu/%s: %s", where, wi, key,
                    !json_is_number(v) ? "not a number"
                                     : limit == SIZE_MAX
                                           ? "not a non-negative integer"
                                           : "out of range");
    *out = (size_t)json_number_value(v);
    return ST_OK;
}

static size_t array_count(const json_t *a)
{
    return json_is_array(a) ? json_array_size(a) : 0;
}

static int type_ncomp(const json_t *t)
{
    static const struct { const char *n; int c; } k[] = {
        {"SCALAR", 1}, {"VEC2", 2}, {"VEC3", 3}, {"VEC4", 4},
        {"MAT2", 4},   {"MAT3", 9}, {"MAT4", 16}};
    if (!t || !json_is_string(t))
        return 0;
    for (size_t i = 0; i < sizeof k / sizeof k[0]; i++)
        if (strcmp(json_string_value(t), k[i].n) == 0)
            return k[i].c;
    return 0;
}

static size_t ctype_size(int ct)
{
    switch (ct) {
    case 5120: case 5121: return 1;
    case 5122: case 5123: return 2;
    case 5125: case 5126: return 4;
    default: return 0;
    }
}

/* ---- buffers ------------------------------------------------------------ */

/* Decode base64 text (padding optional, the URL-safe alphabet too) into
 * a new buffer. */
static st_status decode_b64(gltf *g, size_t bi, const char *s, size_t n,
                            buffer *b)
{
    unsigned char *out = malloc(n / 4 * 3 + 3);
    if (!out)
        return st_error_set(g->err, ST_ENOMEM, g->name, 0, "out of memory");
    size_t i;
    size_t o = st_b64_decode((const unsigned char *)s, n, ST_B64_URL, out, &i);
    if (i < n && s[i] != '=') {
        free(out);
        return gbad(g, "/buffers/%zu/uri: bad base64 at character %zu",
                    bi, i);
    }
    for (; i < n; i++)
        if (s[i] != '=') {
            free(out);
            return gbad(g, "/buffers/%zu/uri: text after base64 padding", bi);
        }
    b->owned = out;
    b->data = out;
    if (o < b->size) {
        return gbad(g, "/buffers/%zu: its data URI holds %zu bytes, "
                       "byteLength says %zu",
                    bi, o, b->size);
    }
    return ST_OK;
}

static int hexval(unsigned char c)
{
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    return -1;
}

/* Read a file beside the .gltf: uri is a relative reference, percent-
 * decoded here. */
static st_status load_file(gltf *g, size_t bi, const char *uri, buffer *b)
{
    for (const char *c = uri; *c && *c != '/'; c++)
        if (*c == ':')
            return gbad(g, "/buffers/%zu/uri: '%.100s': only data: URIs and "
                           "relative file names are read",
                        bi, uri);
    if (!g->path)
        return gbad(g, "/buffers/%zu: external buffer '%.100s' cannot be "
                       "found from standard input (give the .gltf by name)",
                    bi, uri);
    if (uri[0] == '/')
        return gbad(g, "/buffers/%zu/uri: '%.100s' is an absolute path, "
                       "not a relative reference",
                    bi, uri);
    const char *slash = strrchr(g->path, '/');
    size_t dl = slash ? (size_t)(slash - g->path) + 1 : 0;
    size_t ul = strlen(uri);
    char *full = malloc(dl + ul + 1);
    if (!full)
        return st_error_set(g->err, ST_ENOMEM, g->name, 0, "out of memory");
    memcpy(full, g->path, dl);
    size_t o = dl;
    for (size_t i = 0; i < ul; i++) {
        int h1, h2;
        if (uri[i] == '%' && i + 2 < ul &&
            (h1 = hexval((unsigned char)uri[i + 1])) >= 0 &&
            (h2 = hexval((unsigned char)uri[i + 2])) >= 0) {
            full[o++] = (char)(h1 << 4 | h2);
            i += 2;
        } else {
            full[o++] = uri[i];
        }
    }
    full[o] = '\0';
    if (strlen(full) != o) {
        free(full);
        return gbad(g, "/buffers/%zu/uri: a NUL in the file name", bi);
    }
    int fd;
    do
        fd = open(full, O_RDONLY | O_CLOEXEC);
    while (fd < 0 && errno == EINTR);
    if (fd < 0) {
        int e = errno;
        st_status st = gbad(g, "/buffers/%zu: cannot open '%.200s': %s", bi,
                            full, strerror(e));
        free(full);
        return st;
    }
    struct stat sb;
    if (fstat(fd, &sb) != 0 || !S_ISREG(sb.st_mode)) {
        close(fd);
        st_status st = gbad(g, "/buffers/%zu: '%.200s' is not a regular file",
                            bi, full);
        free(full);
        return st;
    }
    /* Only byteLength bytes are used; a shorter file is an error, and
     * nothing past byteLength is read. */
    if ((unsigned long long)sb.st_size < (unsigned long long)b->size) {
        close(fd);
        st_status st = gbad(g, "/buffers/%zu: '%.200s' has %lld bytes, "
                               "byteLength says %zu",
                            bi, full, (long long)sb.st_size, b->size);
        free(full);
        return st;
    }
    unsigned char *data = malloc(b->size ? b->size : 1);
    if (!data) {
        close(fd);
        free(full);
        return st_error_set(g->err, ST_ENOMEM, g->name, 0, "out of memory");
    }
    size_t got = 0;
    while (got < b->size) {
        ssize_t r = read(fd, data + got, b->size - got);
        if (r < 0 && errno == EINTR)
            continue;
        if (r <= 0)
            break;
        got += (size_t)r;
    }
    close(fd);
    if (got < b->size) {
        free(data);
        st_status st = gbad(g, "/buffers/%zu: '%.200s' could not be read "
                               "whole", bi, full);
        free(full);
        return st;
    }
    free(full);
    if (g->hook && g->hook->bytes)
        g->hook->bytes(g->hook->ctx, data, b->size);
    b->owned = data;
    b->data = data;
    return ST_OK;
}

static st_status load_buffer(gltf *g, size_t bi)
{
    buffer *b = &g->buffers[bi];
    if (b->data)
        return ST_OK;
    const json_t *bn = jat(jget(g->root, "buffers"), bi);
    const json_t *uri = jget(bn, "uri");
    st_status st;
    if (!uri) {
        if (bi != 0 || !g->have_glb_bin)
            return gbad(g, "/buffers/%zu: no uri (and no GLB binary chunk)",
                        bi);
        if (g->glb_bin_size < b->size)
            return gbad(g, "/buffers/0: the GLB binary chunk has %zu bytes, "
                           "byteLength says %zu",
                        g->glb_bin_size, b->size);
        b->data = g->glb_bin;
        return ST_OK;
    }
    if (!json_is_string(uri))
        return gbad(g, "/buffers/%zu/uri: not a string", bi);
    const char *u = json_string_value(uri);
    if (json_string_length(uri) != strlen(u))
        return gbad(g, "/buffers/%zu/uri: a NUL in the URI", bi);
    if (strncmp(u, "data:", 5) == 0) {
        const char *comma = strchr(u, ',');
        if (!comma || comma - u < 12 || strncmp(comma - 7, ";base64", 7) != 0)
            return gbad(g, "/buffers/%zu/uri: a data URI that is not "
                           "base64", bi);
        st = decode_b64(g, bi, comma + 1, strlen(comma + 1), b);
    } else {
        st = load_file(g, bi, u, b);
    }
    if (st == ST_OK && st_size_add(&g->total_bytes, g->total_bytes, b->size))
        g->total_bytes = SIZE_MAX;
    return st;
}

/* ---- accessors ---------------------------------------------------------- */

/* Where a buffer view lies: its bytes and stride. */
static st_status get_view(gltf *g, size_t vi, const unsigned char **data,
                          size_t *len, size_t *stride)
{
    const json_t *views = jget(g->root, "bufferViews");
    const json_t *v = jat(views, vi);
    if (!v || !json_is_object(v))
        return gbad(g, "/bufferViews/%zu: no such buffer view", vi);
    size_t bi, off, bl, bs;
    st_status st;
    if ((st = get_index(g, v, "buffer", -1, g->nbuffers, "/bufferViews", vi,
                        &bi)) ||
        (st = get_index(g, v, "byteOffset", 0, SIZE_MAX, "/bufferViews", vi,
                        &off)) ||
        (st = get_index(g, v, "byteLength", -1, SIZE_MAX, "/bufferViews", vi,
                        &bl)) ||
        (st = get_index(g, v, "byteStride", 0, 253, "/bufferViews", vi, &bs)))
        return st;
    if (bs && (bs < 4 || bs % 4))
        return gbad(g, "/bufferViews/%zu/byteStride: %zu (4..252, a "
                       "multiple of 4)", vi, bs);
    if ((st = load_buffer(g, bi)))
        return st;
    size_t end;
    if (st_size_add(&end, off, bl) || end > g->buffers[bi].size)
        return gbad(g, "/bufferViews/%zu: bytes %zu..%zu past the %zu of "
                       "buffer %zu",
                    vi, off, off + bl, g->buffers[bi].size, bi);
    *data = g->buffers[bi].data + off;
    *len = bl;
    *stride = bs;
    return ST_OK;
}

/* Element-range check: count elements of esize bytes every stride bytes
 * from off must lie within len. */
static int fits(size_t off, size_t count, size_t stride, size_t esize,
                size_t len)
{
    if (count == 0)
        return off <= len;
    size_t span, end;
    if (st_size_mul(&span, count - 1, stride) || st_size_add(&end, off, span) ||
        st_size_add(&end, end, esize))
        return 0;
    return end <= len;
}

static st_status get_accessor(gltf *g, size_t ai, accessor *a)
{
    memset(a, 0, sizeof *a);
    a->idx = ai;
    const json_t *an = jat(jget(g->root, "accessors"), ai);
    if (!an || !json_is_object(an))
        return gbad(g, "/accessors/%zu: no such accessor", ai);
    size_t ct, count, off = 0;
    st_status st;
    if ((st = get_index(g, an, "componentType", -1, SIZE_MAX, "/accessors",
                        ai, &ct)) ||
        (st = get_index(g, an, "count", -1, SIZE_MAX, "/accessors", ai,
                        &count)) ||
        (st = get_index(g, an, "byteOffset", 0, SIZE_MAX, "/accessors", ai,
                        &off)))
        return st;
    a->ctype = (int)ct;
    size_t cs = ctype_size(a->ctype);
    if (!cs)
        return gbad(g, "/accessors/%zu/componentType: %zu is not a glTF "
                       "component type", ai, ct);
    a->ncomp = type_ncomp(jget(an, "type"));
    if (!a->ncomp)
        return gbad(g, "/accessors/%zu/type: not SCALAR, VEC2..4 or "
                       "MAT2..4", ai);
    const json_t *nz = jget(an, "normalized");
    a->normalized = json_is_true(nz);
    if (count == 0)
        return gbad(g, "/accessors/%zu/count: 0 (at least 1)", ai);
    a->count = count;
    size_t esize = cs * (size_t)a->ncomp;
    size_t vi;
    const json_t *bv = jget(an, "bufferView");
    if (bv) {
        if ((st = get_index(g, an, "bufferView", -1, SIZE_MAX, "/accessors",
                            ai, &vi)))
            return st;
        const unsigned char *d;
        size_t len, stride;
        if ((st = get_view(g, vi, &d, &len, &stride)))
            return st;
        a->stride = stride ? stride : esize;
        if (stride && stride < esize)
            return gbad(g, "/accessors/%zu: byteStride %zu is less than its "
                           "%zu-byte elements", ai, stride, esize);
        if (!fits(off, count, a->stride, esize, len))
            return gbad(g, "/accessors/%zu: %zu elements of %zu bytes from "
                           "byte %zu do not fit in buffer view %zu (%zu "
                           "bytes)",
                        ai, count, esize, off, vi, len);
        a->base = d + off;
    } else if (count > g->total_bytes) {
        return gbad(g, "/accessors/%zu: %zu elements without a buffer view, "
                       "more than the input's %zu bytes",
                    ai, count, g->total_bytes);
    }
    const json_t *sp = jget(an, "sparse");
    if (sp) {
        size_t sc;
        if ((st = get_index(g, sp, "count", -1, SIZE_MAX, "/accessors", ai,
                            &sc)))
            return st;
        if (sc == 0 || sc > count)
            return gbad(g, "/accessors/%zu/sparse/count: %zu (1..%zu)", ai,
                        sc, count);
        const json_t *si = jget(sp, "indices");
        const json_t *sv = jget(sp, "values");
        size_t iv, ioff = 0, it, vv, voff = 0;
        if (!si || !sv)
            return gbad(g, "/accessors/%zu/sparse: needs indices and values",
                        ai);
        if ((st = get_index(g, si, "bufferView", -1, SIZE_MAX,
                            "/accessors/sparse/indices", ai, &iv)) ||
            (st = get_index(g, si, "byteOffset", 0, SIZE_MAX,
                            "/accessors/sparse/indices", ai, &ioff)) ||
            (st = get_index(g, si, "componentType", -1, SIZE_MAX,
                            "/accessors/sparse/indices", ai, &it)) ||
            (st = get_index(g, sv, "bufferView", -1, SIZE_MAX,
                            "/accessors/sparse/values", ai, &vv)) ||
            (st = get_index(g, sv, "byteOffset", 0, SIZE_MAX,
                            "/accessors/sparse/values", ai, &voff)))
            return st;
        if (it != 5121 && it != 5123 && it != 5125)
            return gbad(g, "/accessors/%zu/sparse/indices/componentType: "
                           "%zu (5121, 5123 or 5125)", ai, it);
        const unsigned char *d;
        size_t len, stride;
        if ((st = get_view(g, iv, &d, &len, &stride)))
            return st;
        size_t is = ctype_size((int)it);
        if (!fits(ioff, sc, is, is, len))
            return gbad(g, "/accessors/%zu/sparse/indices: %zu indices do "
                           "not fit in buffer view %zu", ai, sc, iv);
        a->sidx = d + ioff;
        a->sidx_type = (int)it;
        if ((st = get_view(g, vv, &d, &len, &stride)))
            return st;
        if (!fits(voff, sc, esize, esize, len))
            return gbad(g, "/accessors/%zu/sparse/values: %zu values do "
                           "not fit in buffer view %zu", ai, sc, vv);
        a->sval = d + voff;
        a->scount = sc;
        /* Strictly increasing indices below count (the spec's rule, and
         * what makes the lookup below a binary search). */
        size_t prev = 0;
        for (size_t k = 0; k < sc; k++) {
            const unsigned char *p = a->sidx + k * is;
            size_t x = is == 1 ? p[0]
                     : is == 2 ? (size_t)st_le16(p)
                               : (size_t)st_le32(p);
            if (x >= count || (k > 0 && x <= prev))
                return gbad(g, "/accessors/%zu/sparse/indices: index %zu "
                               "(entry %zu) is %s",
                            ai, x, k,
                            x >= count ? "out of range"
                                       : "not above the one before");
            prev = x;
        }
    }
    return ST_OK;
}

static double read_comp(const unsigned char *p, int ct, int normalized)
{
    switch (ct) {
    case 5120: {
        double v = (double)(int8_t)p[0];
        return normalized ? fmax(v / 127.0, -1.0) : v;
    }
    case 5121: {
        double v = p[0];
        return normalized ? v / 255.0 : v;
    }
    case 5122: {
        double v = (double)(int16_t)(uint16_t)st_le16(p);
        return normalized ? fmax(v / 32767.0, -1.0) : v;
    }
    case 5123: {
        double v = (double)st_le16(p);
        return normalized ? v / 65535.0 : v;
    }
    case 5125: {
        double v = (double)st_le32(p);
        return normalized ? v / 4294967295.0 : v;
    }
    case 5126: {
        uint32_t u = st_le32(p);
        float f;
        memcpy(&f, &u, 4);
        return f;
    }
    default:
        return 0;
    }
}

/* Components c of element i into out[ncomp]. */
static void acc_read(const accessor *a, size_t i, double *out)
{
    const size_t cs = ctype_size(a->ctype);
    const unsigned char *p = NULL;
    if (a->scount) {
        size_t is = ctype_size(a->sidx_type), lo = 0, hi = a->scount;
        while (lo < hi) {
            size_t mid = lo + (hi - lo) / 2;
            const unsigned char *q = a->sidx + mid * is;
            size_t x = is == 1 ? q[0]
                     : is == 2 ? (size_t)st_le16(q)
                               : (size_t)st_le32(q);
            if (x == i) {
                p = a->sval + mid * cs * (size_t)a->ncomp;
                break;
            }
            if (x < i)
                lo = mid + 1;
            else
                hi = mid;
        }
    }
    if (!p && a->base)
        p = a->base + i * a->stride;
    for (int c = 0; c < a->ncomp; c++)
        out[c] = p ? read_comp(p + (size_t)c * cs, a->ctype, a->normalized)
                   : 0.0;
}

/* ---- meshes and nodes --------------------------------------------------- */

static void mat_mul(double out[16], const double a[16], const double b[16])
{
    double r[16];
    for (int c = 0; c < 4; c++)
        for (int rr = 0; rr < 4; rr++) {
            double s = 0;
            for (int k = 0; k < 4; k++)
                s += a[k * 4 + rr] * b[c * 4 + k];
            r[c * 4 + rr] = s;
        }
    memcpy(out, r, sizeof r);
}

/* n numbers of member key into v (absent: v unchanged). */
static st_status get_numbers(gltf *g, const json_t *o, const char *key,
                             size_t n, double *v, size_t ni)
{
    const json_t *a = jget(o, key);
    if (!a)
        return ST_OK;
    if (!json_is_array(a) || json_array_size(a) != n)
        return gbad(g, "/nodes/%zu/%s: not an array of %zu numbers", ni, key,
                    n);
    for (size_t i = 0; i < n; i++) {
        const json_t *x = jat(a, i);
        if (!json_is_number(x) || !isfinite(json_number_value(x)))
            return gbad(g, "/nodes/%zu/%s/%zu: not a finite number", ni, key,
                        i);
        v[i] = json_number_value(x);
    }
    return ST_OK;
}

/* The node's local transform, column-major. */
static st_status local_matrix(gltf *g, const json_t *nd, size_t ni,
                              double m[16])
{
    static const double id[16] = {1, 0, 0, 0, 0, 1, 0, 0,
                                  0, 0, 1, 0, 0, 0, 0, 1};
    memcpy(m, id, sizeof id);
    st_status st;
    if (jget(nd, "matrix"))
        return get_numbers(g, nd, "matrix", 16, m, ni);
    double t[3] = {0, 0, 0}, r[4] = {0, 0, 0, 1}, s[3] = {1, 1, 1};
    if ((st = get_numbers(g, nd, "translation", 3, t, ni)) ||
        (st = get_numbers(g, nd, "rotation", 4, r, ni)) ||
        (st = get_numbers(g, nd, "scale", 3, s, ni)))
        return st;
    /* A unit quaternion (x y z w); normalised here, as viewers do. */
    double qn = sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2] + r[3] * r[3]);
    if (!(qn > 0))
        return gbad(g, "/nodes/%zu/rotation: a zero quaternion", ni);
    double x = r[0] / qn, y = r[1] / qn, z = r[2] / qn, w = r[3] / qn;
    double R[9] = {1 - 2 * (y * y + z * z), 2 * (x * y + z * w),
                   2 * (x * z - y * w),     2 * (x * y - z * w),
                   1 - 2 * (x * x + z * z), 2 * (y * z + x * w),
                   2 * (x * z + y * w),     2 * (y * z - x * w),
                   1 - 2 * (x * x + y * y)};   /* column-major */
    for (int c = 0; c < 3; c++)
        for (int rr = 0; rr < 3; rr++)
            m[c * 4 + rr] = R[c * 3 + rr] * s[c];
    m[12] = t[0];
    m[13] = t[1];
    m[14] = t[2];
    return ST_OK;
}

static st_status add_primitive(gltf *g, const json_t *prim, size_t mi,
                               size_t pi, const double M[16])
{
    size_t mode;
    st_status st;
    if ((st = get_index(g, prim, "mode", 4, 7, "/meshes/primitives", mi,
                        &mode)))
        return st;
    const json_t *ext = jget(prim, "extensions");
    if (jget(ext, "KHR_draco_mesh_compression"))
        return gbad(g, "/meshes/%zu/primitives/%zu: Draco-compressed "
                       "(KHR_draco_mesh_compression) geometry is not read; "
                       "decompress it first (e.g. gltf-transform copy)",
                    mi, pi);
    if (mode < 4) {
        g->ignored++;
        return ST_OK;
    }
    const json_t *attrs = jget(prim, "attributes");
    size_t pa;
    if (!jget(attrs, "POSITION")) {
        g->ignored++;
        return ST_OK;
    }
    if ((st = get_index(g, attrs, "POSITION", -1, SIZE_MAX,
                        "/meshes/primitives/attributes", mi, &pa)))
        return st;
    accessor pos, idx;
    if ((st = get_accessor(g, pa, &pos)))
        return st;
    if (pos.ncomp != 3 || pos.ctype == 5125)
        return gbad(g, "/accessors/%zu: POSITION must be VEC3 of floats, "
                       "bytes or shorts", pa);
    const size_t base = g->s->nverts;
    for (size_t i = 0; i < pos.count; i++) {
        double p[3], w[3];
        acc_read(&pos, i, p);
        for (int r = 0; r < 3; r++)
            w[r] = M[r] * p[0] + M[4 + r] * p[1] + M[8 + r] * p[2] +
                   M[12 + r];
        if (!isfinite(w[0]) || !isfinite(w[1]) || !isfinite(w[2]))
            return gbad(g, "/accessors/%zu: position %zu is not finite "
                           "(%g %g %g) in world space",
                        pa, i, w[0], w[1], w[2]);
        if ((st = st_soup__push_vertex(g->s, w[0], w[1], w[2])))
            return st_soup__push_failed(g->err, st, g->name, 0, -1);
    }
    size_t n = pos.count;
    int indexed = jget(prim, "indices") != NULL;
    if (indexed) {
        size_t ii;
        if ((st = get_index(g, prim, "indices", -1, SIZE_MAX,
                            "/meshes/primitives", mi, &ii)) ||
            (st = get_accessor(g, ii, &idx)))
            return st;
        if (idx.ncomp != 1 || (idx.ctype != 5121 && idx.ctype != 5123 &&
                               idx.ctype != 5125))
            return gbad(g, "/accessors/%zu: indices must be SCALAR unsigned "
                           "bytes, shorts or ints", ii);
        idx.normalized = 0;   /* indices are plain integers */
        n = idx.count;
    }
    if (mode == 4 && n % 3)
        return gbad(g, "/meshes/%zu/primitives/%zu: %zu TRIANGLES vertices, "
                       "not a multiple of 3", mi, pi, n);
    size_t ntri = mode == 4 ? n / 3 : n >= 3 ? n - 2 : 0;
    for (size_t t = 0; t < ntri; t++) {
        size_t k[3];
        if (mode == 4) {
            k[0] = 3 * t; k[1] = 3 * t + 1; k[2] = 3 * t + 2;
        } else if (mode == 5) {
            if (t % 2 == 0) {
                k[0] = t; k[1] = t + 1;
            } else {
                k[0] = t + 1; k[1] = t;
            }
            k[2] = t + 2;
        } else {
            k[0] = t + 1; k[1] = t + 2; k[2] = 0;
        }
        uint32_t v[3];
        for (int c = 0; c < 3; c++) {
            size_t x = k[c];
            if (indexed) {
                double d;
                acc_read(&idx, k[c], &d);
                if (d >= (double)pos.count)
                    return gbad(g, "/accessors/%zu: index %.0f (entry %zu) "
                                   "out of range (POSITION has %zu)",
                                idx.idx, d, k[c], pos.count);
                x = (size_t)d;
            }
            v[c] = (uint32_t)(base + x);
        }
        if ((st = st_soup__push_tri(g->s, v[0], v[1], v[2])))
            return st_soup__push_failed(g->err, st, g->name, 0, -1);
    }
    return ST_OK;
}

static st_status add_mesh(gltf *g, size_t mi, const double M[16])
{
    const json_t *mesh = jat(jget(g->root, "meshes"), mi);
    if (!mesh || !json_is_object(mesh))
        return gbad(g, "/meshes/%zu: no such mesh", mi);
    const json_t *prims = jget(mesh, "primitives");
    if (!prims || !json_is_array(prims))
        return gbad(g, "/meshes/%zu: no primitives", mi);
    for (size_t p = 0; p < json_array_size(prims); p++) {
        st_status st = add_primitive(g, jat(prims, p), mi, p, M);
        if (st)
            return st;
    }
    return ST_OK;
}

/* Depth-first through the node trees under roots, with an explicit stack
 * (a chain of nodes may be as long as the file). A node reached twice is
 * a cycle or a node with two parents: both invalid glTF. */
/* A mesh node is a part (parts.h): its name, else its mesh's, else "". */
static st_status node_name(gltf *g, const json_t *nd, size_t mi)
{
    const json_t *nm = jget(nd, "name");
    if (!nm || !json_is_string(nm)) {
        const json_t *mesh = jat(jget(g->root, "meshes"), mi);
        nm = mesh && json_is_object(mesh) ? jget(mesh, "name") : NULL;
    }
    const int named = nm && json_is_string(nm);
    if (st_soup__push_name(g->s, 1,
                           named ? (const unsigned char *)json_string_value(nm) : NULL,
                           named ? json_string_length(nm) : 0))
        return st_error_set(g->err, ST_ENOMEM, g->name, 0, "out of memory");
    return ST_OK;
}

static st_status walk(gltf *g, const size_t *roots, size_t nroots)
{
    const json_t *nodes = jget(g->root, "nodes");
    size_t nn = array_count(nodes);
    if (nn == 0)
        return ST_OK;
    typedef struct frame {
        size_t node;
        double M[16];
    } frame;
    unsigned char *seen = calloc(nn, 1);
    frame *stack = st_realloc_array(NULL, nn, sizeof *stack);
    st_status st = ST_OK;
    if (!seen || !stack) {
        st = st_error_set(g->err, ST_ENOMEM, g->name, 0, "out of memory");
        goto out;
    }
    for (size_t r = 0; r < nroots && !st; r++) {
        size_t top = 0;
        static const double id[16] = {1, 0, 0, 0, 0, 1, 0, 0,
                                      0, 0, 1, 0, 0, 0, 0, 1};
        size_t ni = roots[r];
        if (seen[ni]) {
            st = gbad(g, "/nodes/%zu: reached twice (a cycle, or a node "
                         "with two parents)", ni);
            break;
        }
        seen[ni] = 1;
        stack[top].node = ni;
        memcpy(stack[top].M, id, sizeof id);
        top++;
        while (top > 0 && !st) {
            frame f = stack[--top];
            const json_t *nd = jat(nodes, f.node);
            if (!nd || !json_is_object(nd)) {
                st = gbad(g, "/nodes/%zu: not an object", f.node);
                break;
            }
            double L[16], W[16];
            if ((st = local_matrix(g, nd, f.node, L)))
                break;
            mat_mul(W, f.M, L);
            if (jget(nd, "mesh")) {
                size_t mi;
                if ((st = get_index(g, nd, "mesh", -1, SIZE_MAX, "/nodes",
                                    f.node, &mi)) ||
                    (st = node_name(g, nd, mi)) ||
                    (st = add_mesh(g, mi, W)))
                    break;
            }
            /* Children pushed last first: they are visited in order. */
            const json_t *ch = jget(nd, "children");
            for (size_t cc = array_count(ch); cc > 0; cc--) {
                const size_t c = cc - 1;
                const json_t *x = jat(ch, c);
                if (!json_is_number(x) || !(json_number_value(x) >= 0) ||
                    json_number_value(x) != floor(json_number_value(x)) || json_number_value(x) >= (double)nn) {
                    st = gbad(g, "/nodes/%zu/children/%zu: not a node index",
                              f.node, c);
                    break;
                }
                size_t k = (size_t)json_number_value(x);
                if (seen[k]) {
                    st = gbad(g, "/nodes/%zu/children/%zu: node %zu reached "
                                 "twice (a cycle, or a node with two "
                                 "parents)", f.node, c, k);
                    break;
                }
                seen[k] = 1;
                stack[top].node = k;
                memcpy(stack[top].M, W, sizeof W);
                top++;
            }
        }
    }
out:
    free(seen);
    free(stack);
    return st;
}

static st_status read_document(gltf *g)
{
    const json_t *root = g->root;
    if (!json_is_object(root))
        return gbad(g, "the document is not a JSON object");
    const json_t *asset = jget(root, "asset");
    const json_t *ver = jget(asset, "version");
    if (!ver || !json_is_string(ver))
        return gbad(g, "/asset/version: missing (not a glTF file?)");
    if (strncmp(json_string_value(ver), "2.", 2) != 0)
        return gbad(g, "/asset/version: \"%.20s\" (only glTF 2.x is read)",
                    json_string_value(ver));
    const json_t *req = jget(root, "extensionsRequired");
    for (size_t i = 0; i < array_count(req); i++) {
        const json_t *e = jat(req, i);
        if (!json_is_string(e))
            continue;
        const char *en = json_string_value(e);
        if (strcmp(en, "KHR_draco_mesh_compression") == 0)
            return gbad(g, "/extensionsRequired/%zu: Draco-compressed "
                           "(KHR_draco_mesh_compression) geometry is not "
                           "read; decompress it first (e.g. gltf-transform "
                           "copy)", i);
        if (strcmp(en, "EXT_meshopt_compression") == 0 ||
            strcmp(en, "EXT_mesh_gpu_instancing") == 0)
            return gbad(g, "/extensionsRequired/%zu: %s is not supported",
                        i, en);
    }
    const json_t *bufs = jget(root, "buffers");
    g->nbuffers = array_count(bufs);
    if (g->nbuffers) {
        g->buffers = calloc(g->nbuffers, sizeof *g->buffers);
        if (!g->buffers)
            return st_error_set(g->err, ST_ENOMEM, g->name, 0,
                                "out of memory");
        for (size_t i = 0; i < g->nbuffers; i++) {
            size_t bl;
            st_status st = get_index(g, jat(bufs, i), "byteLength", -1,
                                     SIZE_MAX, "/buffers", i, &bl);
            if (st)
                return st;
            g->buffers[i].size = bl;
        }
    }
    /* The roots: the default scene's nodes, else every node no other
     * lists as a child. */
    const json_t *nodes = jget(root, "nodes");
    size_t nn = array_count(nodes);
    size_t *roots = st_realloc_array(NULL, nn ? nn : 1, sizeof *roots);
    if (!roots)
        return st_error_set(g->err, ST_ENOMEM, g->name, 0, "out of memory");
    size_t nr = 0;
    st_status st = ST_OK;
    const json_t *scene = jget(root, "scene");
    if (scene) {
        size_t si;
        const json_t *scenes = jget(root, "scenes");
        st = get_index(g, root, "scene", -1, array_count(scenes), "", 0, &si);
        if (st) {
            st = gbad(g, "/scene: not an index into /scenes");
        } else {
            const json_t *sn = jget(jat(scenes, si), "nodes");
            for (size_t i = 0; i < array_count(sn) && !st; i++) {
                const json_t *x = jat(sn, i);
                if (!json_is_number(x) || !(json_number_value(x) >= 0) ||
                    json_number_value(x) != floor(json_number_value(x)) || json_number_value(x) >= (double)nn)
                    st = gbad(g, "/scenes/%zu/nodes/%zu: not a node index",
                              si, i);
                else
                    roots[nr++] = (size_t)json_number_value(x);
            }
        }
    } else if (nn) {
        unsigned char *child = calloc(nn, 1);
        if (!child) {
            free(roots);
            return st_error_set(g->err, ST_ENOMEM, g->name, 0,
                                "out of memory");
        }
        for (size_t n = 0; n < nn; n++) {
            const json_t *ch = jget(jat(nodes, n), "children");
            for (size_t c = 0; c < array_count(ch); c++) {
                const json_t *x = jat(ch, c);
                if (json_is_number(x) && json_number_value(x) >= 0 && json_number_value(x) < (double)nn)
                    child[(size_t)json_number_value(x)] = 1;
            }
        }
        for (size_t n = 0; n < nn; n++)
            if (!child[n])
                roots[nr++] = n;
        free(child);
        if (nr == 0)
            st = gbad(g, "/nodes: every node is a child (a cycle)");
    }
    if (!st)
        st = walk(g, roots, nr);
    free(roots);
    if (!st && g->s->ntris == 0 && g->ignored)
        st = gbad(g, "no triangles (%zu point or line primitives ignored)",
                  g->ignored);
    else if (!st && g->ignored)
        st_soup__warn(g->warn, g->name, 0, -1,
                      "%zu point or line primitives ignored", g->ignored);
    return st;
}

st_status st_soup__parse_gltf(st_soup *s, const unsigned char *data,
                              size_t size, const char *name, const char *path,
                              const st_soup__file_hook *hook,
                              st_soup_warnings *warn, st_error *err)
{
    gltf g;
    memset(&g, 0, sizeof g);
    g.name = name;
    g.path = path;
    g.hook = hook;
    g.s = s;
    g.warn = warn;
    g.err = err;
    g.total_bytes = size;
    const unsigned char *js = data;
    size_t jn = size;
    st_status st = ST_OK;
    if (size >= 4 && st_le32(data) == GLB_MAGIC) {
        if (size < 20)
            return st_error_set_offset(err, ST_EINPUT, name, 0,
                                       "GLB: %zu bytes, shorter than its "
                                       "headers", size);
        uint32_t version = st_le32(data + 4), length = st_le32(data + 8);
        if (version != 2)
            return st_error_set_offset(err, ST_EINPUT, name, 4,
                                       "GLB version %lu (only 2 is read)",
                                       (unsigned long)version);
        if (length > size)
            return st_error_set_offset(err, ST_EINPUT, name, 8,
                                       "GLB length %lu, the file has %zu "
                                       "bytes (truncated?)",
                                       (unsigned long)length, size);
        if (length < 20)
            return st_error_set_offset(err, ST_EINPUT, name, 8,
                                       "GLB length %lu, shorter than its "
                                       "headers", (unsigned long)length);
        size_t pos = 12;
        uint32_t clen = st_le32(data + pos), ctype = st_le32(data + pos + 4);
        if (ctype != GLB_JSON)
            return st_error_set_offset(err, ST_EINPUT, name, 16,
                                       "GLB: the first chunk is not JSON");
        if (clen > length - 20)
            return st_error_set_offset(err, ST_EINPUT, name, 12,
                                       "GLB: JSON chunk of %lu bytes past "
                                       "the end", (unsigned long)clen);
        js = data + 20;
        jn = clen;
        pos = 20 + (size_t)clen;
        if (length - pos >= 8) {
            uint32_t blen = st_le32(data + pos), btype = st_le32(data + pos + 4);
            if (btype == GLB_BIN) {
                if (blen > length - pos - 8)
                    return st_error_set_offset(err, ST_EINPUT, name,
                                               (long long)pos,
                                               "GLB: BIN chunk of %lu bytes "
                                               "past the end",
                                               (unsigned long)blen);
                g.glb_bin = data + pos + 8;
                g.glb_bin_size = blen;
                g.have_glb_bin = 1;
            }
        }
        /* JSON chunk offsets are reported from the file's start. */
        st = json_parse(&g.root, js, jn, 20, name, err);
    } else {
        st = json_parse(&g.root, js, jn, 0, name, err);
    }
    if (st == ST_OK)
        st = read_document(&g);
    for (size_t i = 0; i < g.nbuffers; i++)
        free(g.buffers[i].owned);
    free(g.buffers);
    json_decref(g.root);
    return st;
}
