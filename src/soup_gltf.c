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
 * JSON: a small parser here (RFC 8259), not a library: glTF needs only a
 * tree of the document, the parser is fuzzed with the reader, gives byte
 * offsets, limits nesting (64 levels; glTF needs under 10) and allocates
 * only in proportion to the bytes it has read.
 */
#include "fpenv.h"
#include "bytes.h"
#include "soup_internal.h"
#include "soupread.h"
#include "souptet/mem.h"

#include <errno.h>
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
#define JSON_MAX_NUMBER 320    /* characters of one number token */

typedef enum jtype { J_NULL, J_BOOL, J_NUM, J_STR, J_ARR, J_OBJ } jtype;

typedef struct jnode {
    jtype type;
    size_t off;          /* byte offset in the JSON text */
    size_t parent;       /* SIZE_MAX for the root */
    double num;          /* J_NUM, J_BOOL (0/1) */
    size_t str, slen;    /* J_STR: decoded bytes in the string arena */
    size_t key, klen;    /* member of an object: its decoded key */
    size_t first, count; /* J_ARR/J_OBJ: children in kids[first..] */
} jnode;

typedef struct json {
    jnode *nodes;
    size_t n, cap;
    char *arena;         /* decoded strings, each NUL-terminated */
    size_t an, acap;
    size_t *kids;        /* children of every container, in order */
    const unsigned char *p, *begin, *end;
    const char *name;
    st_error *err;
} json;

static st_status jerr(json *j, const unsigned char *at, const char *what)
{
    return st_error_set_offset(j->err, ST_EINPUT, j->name,
                               (long long)(at - j->begin),
                               "JSON: %s", what);
}

static st_status joom(json *j)
{
    return st_error_set(j->err, ST_ENOMEM, j->name, 0, "out of memory");
}

static void jskip(json *j)
{
    while (j->p < j->end && (*j->p == ' ' || *j->p == '\t' ||
                             *j->p == '\n' || *j->p == '\r'))
        j->p++;
}

static st_status jnew(json *j, jtype type, size_t parent, size_t *out)
{
    if (j->n == j->cap) {
        size_t nc = j->cap ? 2 * j->cap : 64;
        jnode *nn = st_realloc_array(j->nodes, nc, sizeof *nn);
        if (!nn)
            return joom(j);
        j->nodes = nn;
        j->cap = nc;
    }
    jnode *x = &j->nodes[j->n];
    memset(x, 0, sizeof *x);
    x->type = type;
    x->off = (size_t)(j->p - j->begin);
    x->parent = parent;
    *out = j->n++;
    return ST_OK;
}

static st_status jput(json *j, const char *b, size_t n)
{
    if (j->acap - j->an < n) {
        size_t nc = j->acap ? j->acap : 256;
        while (nc - j->an < n) {
            if (nc > SIZE_MAX / 2)
                return joom(j);
            nc *= 2;
        }
        char *na = realloc(j->arena, nc);
        if (!na)
            return joom(j);
        j->arena = na;
        j->acap = nc;
    }
    memcpy(j->arena + j->an, b, n);
    j->an += n;
    return ST_OK;
}

static int hexval(unsigned char c)
{
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    return -1;
}

static int hex4(const unsigned char *p, const unsigned char *end, unsigned *u)
{
    if (end - p < 4)
        return -1;
    unsigned v = 0;
    for (int i = 0; i < 4; i++) {
        int h = hexval(p[i]);
        if (h < 0)
            return -1;
        v = v << 4 | (unsigned)h;
    }
    *u = v;
    return 0;
}

/* A string at j->p (the opening quote): decoded into the arena. */
static st_status jstring(json *j, size_t *at, size_t *len)
{
    const unsigned char *start = j->p;
    j->p++;
    *at = j->an;
    for (;;) {
        if (j->p >= j->end)
            return jerr(j, start, "string without its closing quote");
        unsigned char c = *j->p;
        if (c == '"') {
            j->p++;
            break;
        }
        if (c < 0x20)
            return jerr(j, j->p, "control character in a string");
        if (c != '\\') {
            const unsigned char *q = j->p;
            while (q < j->end && *q != '"' && *q != '\\' && *q >= 0x20)
                q++;
            if (jput(j, (const char *)j->p, (size_t)(q - j->p)))
                return ST_ENOMEM;
            j->p = q;
            continue;
        }
        if (j->end - j->p < 2)
            return jerr(j, j->p, "string ends in an escape");
        unsigned char e = j->p[1];
        char ch;
        switch (e) {
        case '"': ch = '"'; break;
        case '\\': ch = '\\'; break;
        case '/': ch = '/'; break;
        case 'b': ch = '\b'; break;
        case 'f': ch = '\f'; break;
        case 'n': ch = '\n'; break;
        case 'r': ch = '\r'; break;
        case 't': ch = '\t'; break;
        case 'u': {
            unsigned u;
            if (hex4(j->p + 2, j->end, &u))
                return jerr(j, j->p, "bad \\u escape");
            const unsigned char *esc = j->p;
            j->p += 6;
            if (u >= 0xD800 && u <= 0xDBFF) {
                unsigned lo;
                if (j->end - j->p < 6 || j->p[0] != '\\' || j->p[1] != 'u' ||
                    hex4(j->p + 2, j->end, &lo) || lo < 0xDC00 || lo > 0xDFFF)
                    return jerr(j, esc, "unpaired UTF-16 surrogate");
                j->p += 6;
                u = 0x10000 + ((u - 0xD800) << 10) + (lo - 0xDC00);
            } else if (u >= 0xDC00 && u <= 0xDFFF) {
                return jerr(j, esc, "unpaired UTF-16 surrogate");
            }
            char b[4];
            size_t n;
            if (u < 0x80) {
                b[0] = (char)u; n = 1;
            } else if (u < 0x800) {
                b[0] = (char)(0xC0 | u >> 6);
                b[1] = (char)(0x80 | (u & 0x3F)); n = 2;
            } else if (u < 0x10000) {
                b[0] = (char)(0xE0 | u >> 12);
                b[1] = (char)(0x80 | (u >> 6 & 0x3F));
                b[2] = (char)(0x80 | (u & 0x3F)); n = 3;
            } else {
                b[0] = (char)(0xF0 | u >> 18);
                b[1] = (char)(0x80 | (u >> 12 & 0x3F));
                b[2] = (char)(0x80 | (u >> 6 & 0x3F));
                b[3] = (char)(0x80 | (u & 0x3F)); n = 4;
            }
            if (jput(j, b, n))
                return ST_ENOMEM;
            continue;
        }
        default:
            return jerr(j, j->p, "bad escape in a string");
        }
        if (jput(j, &ch, 1))
            return ST_ENOMEM;
        j->p += 2;
    }
    *len = j->an - *at;
    return jput(j, "", 1);
}

static st_status jnumber(json *j, double *out)
{
    const unsigned char *s = j->p, *q = j->p;
    if (q < j->end && *q == '-')
        q++;
    if (q >= j->end || *q < '0' || *q > '9')
        return jerr(j, s, "unexpected character");
    if (*q == '0')
        q++;
    else
        while (q < j->end && *q >= '0' && *q <= '9')
            q++;
    if (q < j->end && *q == '.') {
        q++;
        if (q >= j->end || *q < '0' || *q > '9')
            return jerr(j, s, "bad number");
        while (q < j->end && *q >= '0' && *q <= '9')
            q++;
    }
    if (q < j->end && (*q == 'e' || *q == 'E')) {
        q++;
        if (q < j->end && (*q == '+' || *q == '-'))
            q++;
        if (q >= j->end || *q < '0' || *q > '9')
            return jerr(j, s, "bad number");
        while (q < j->end && *q >= '0' && *q <= '9')
            q++;
    }
    size_t n = (size_t)(q - s);
    if (n > JSON_MAX_NUMBER)
        return jerr(j, s, "number too long");
    char buf[JSON_MAX_NUMBER + 1];
    memcpy(buf, s, n);
    buf[n] = '\0';
    *out = strtod(buf, NULL);   /* JSON's grammar is strtod's, in "C" */
    j->p = q;
    return ST_OK;
}

static int jlit(json *j, const char *lit)
{
    size_t n = strlen(lit);
    if ((size_t)(j->end - j->p) < n || memcmp(j->p, lit, n) != 0)
        return 0;
    j->p += n;
    return 1;
}

/* One value and everything in it, iteratively (an explicit stack of open
 * containers, JSON_MAX_DEPTH deep). */
static st_status jparse_value(json *j)
{
    size_t stack[JSON_MAX_DEPTH];
    int depth = 0;
    size_t parent = SIZE_MAX;
    for (;;) {
        /* A member's key first, when the open container is an object. */
        size_t key = 0, klen = 0;
        int has_key = 0;
        jskip(j);
        if (parent != SIZE_MAX) {
            jnode *pn = &j->nodes[parent];
            int first = pn->count == 0;
            if (j->p < j->end &&
                *j->p == (pn->type == J_ARR ? ']' : '}')) {
                j->p++;
                depth--;
                parent = depth ? stack[depth - 1] : SIZE_MAX;
                goto after_value;
            }
            if (!first) {
                if (j->p >= j->end || *j->p != ',')
                    return jerr(j, j->p, pn->type == J_ARR
                                             ? "expected ',' or ']'"
                                             : "expected ',' or '}'");
                j->p++;
                jskip(j);
            }
            if (pn->type == J_OBJ) {
                if (j->p >= j->end || *j->p != '"')
                    return jerr(j, j->p, "expected a member name");
                st_status ks = jstring(j, &key, &klen);
                if (ks)
                    return ks;
                jskip(j);
                if (j->p >= j->end || *j->p != ':')
                    return jerr(j, j->p, "expected ':'");
                j->p++;
                jskip(j);
                has_key = 1;
            }
            j->nodes[parent].count++;
        }
        if (j->p >= j->end)
            return jerr(j, j->p, "document ends inside a value");
        size_t id;
        unsigned char c = *j->p;
        st_status st;
        if (c == '{' || c == '[') {
            if (depth == JSON_MAX_DEPTH)
                return jerr(j, j->p, "nested more than 64 deep");
            if ((st = jnew(j, c == '{' ? J_OBJ : J_ARR, parent, &id)))
                return st;
            j->p++;
            if (has_key) {
                j->nodes[id].key = key;
                j->nodes[id].klen = klen;
            }
            stack[depth++] = id;
            parent = id;
            continue;
        }
        if ((st = jnew(j, J_NULL, parent, &id)))
            return st;
        jnode *x = &j->nodes[id];
        if (has_key) {
            x->key = key;
            x->klen = klen;
        }
        if (c == '"') {
            size_t at, len;
            if ((st = jstring(j, &at, &len)))
                return st;
            x = &j->nodes[id];
            x->type = J_STR;
            x->str = at;
            x->slen = len;
        } else if (jlit(j, "true")) {
            x->type = J_BOOL;
            x->num = 1;
        } else if (jlit(j, "false")) {
            x->type = J_BOOL;
        } else if (jlit(j, "null")) {
            x->type = J_NULL;
        } else {
            double v = 0;
            if ((st = jnumber(j, &v)))
                return st;
            x->type = J_NUM;
            x->num = v;
        }
    after_value:
        if (depth == 0)
            return ST_OK;
    }
}

static void json_free(json *j)
{
    free(j->nodes);
    free(j->arena);
    free(j->kids);
}

/* Parse the whole text; node 0 is the root. */
static st_status json_parse(json *j, const unsigned char *data, size_t size,
                            const char *name, st_error *err)
{
    memset(j, 0, sizeof *j);
    j->p = j->begin = data;
    j->end = data + size;
    j->name = name;
    j->err = err;
    /* A UTF-8 byte order mark is tolerated (some exporters write one). */
    if (size >= 3 && data[0] == 0xEF && data[1] == 0xBB && data[2] == 0xBF)
        j->p += 3;
    st_status st = jparse_value(j);
    if (st)
        return st;
    jskip(j);
    if (j->p != j->end)
        return jerr(j, j->p, "text after the document");
    /* Children of each container contiguous, in document order: a stable
     * counting sort by parent (nodes are numbered in document order). */
    j->kids = st_realloc_array(NULL, j->n ? j->n : 1, sizeof *j->kids);
    if (!j->kids)
        return joom(j);
    size_t next = 0;
    for (size_t i = 0; i < j->n; i++)
        if (j->nodes[i].type == J_ARR || j->nodes[i].type == J_OBJ) {
            j->nodes[i].first = next;
            next += j->nodes[i].count;
            j->nodes[i].count = 0;
        }
    for (size_t i = 1; i < j->n; i++) {
        jnode *pn = &j->nodes[j->nodes[i].parent];
        j->kids[pn->first + pn->count++] = i;
    }
    return ST_OK;
}

/* Member k of object o, or NULL. Names are compared whole (a key with an
 * embedded NUL matches nothing glTF defines). */
static const jnode *jget(const json *j, const jnode *o, const char *k)
{
    if (!o || o->type != J_OBJ)
        return NULL;
    size_t kl = strlen(k);
    for (size_t i = 0; i < o->count; i++) {
        const jnode *m = &j->nodes[j->kids[o->first + i]];
        if (m->klen == kl && memcmp(j->arena + m->key, k, kl) == 0)
            return m;
    }
    return NULL;
}

static const jnode *jat(const json *j, const jnode *a, size_t i)
{
    if (!a || (a->type != J_ARR) || i >= a->count)
        return NULL;
    return &j->nodes[j->kids[a->first + i]];
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
    json j;
    const jnode *root;
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
static st_status get_index(gltf *g, const jnode *o, const char *key,
                           long long dflt, size_t limit, const char *where,
                           size_t wi, size_t *out)
{
    const jnode *v = jget(&g->j, o, key);
    if (!v) {
        if (dflt < 0)
            return gbad(g, "%s/%zu: no \"%s\"", where, wi, key);
        *out = (size_t)dflt;
        return ST_OK;
    }
    if (v->type != J_NUM || !(v->num >= 0) || v->num != floor(v->num) ||
        v->num >= (double)limit)
        return gbad(g, "%s/%zu/%s: %s", where, wi, key,
                    v->type != J_NUM ? "not a number"
                                     : limit == SIZE_MAX
                                           ? "not a non-negative integer"
                                           : "out of range");
    *out = (size_t)v->num;
    return ST_OK;
}

static size_t array_count(const jnode *a)
{
    return a && a->type == J_ARR ? a->count : 0;
}

static int type_ncomp(const json *j, const jnode *t)
{
    static const struct { const char *n; int c; } k[] = {
        {"SCALAR", 1}, {"VEC2", 2}, {"VEC3", 3}, {"VEC4", 4},
        {"MAT2", 4},   {"MAT3", 9}, {"MAT4", 16}};
    if (!t || t->type != J_STR)
        return 0;
    for (size_t i = 0; i < sizeof k / sizeof k[0]; i++)
        if (strcmp(j->arena + t->str, k[i].n) == 0)
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
    const jnode *bn = jat(&g->j, jget(&g->j, g->root, "buffers"), bi);
    const jnode *uri = jget(&g->j, bn, "uri");
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
    if (uri->type != J_STR)
        return gbad(g, "/buffers/%zu/uri: not a string", bi);
    const char *u = g->j.arena + uri->str;
    if (uri->slen != strlen(u))
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
    const jnode *views = jget(&g->j, g->root, "bufferViews");
    const jnode *v = jat(&g->j, views, vi);
    if (!v || v->type != J_OBJ)
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
    const jnode *an = jat(&g->j, jget(&g->j, g->root, "accessors"), ai);
    if (!an || an->type != J_OBJ)
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
    a->ncomp = type_ncomp(&g->j, jget(&g->j, an, "type"));
    if (!a->ncomp)
        return gbad(g, "/accessors/%zu/type: not SCALAR, VEC2..4 or "
                       "MAT2..4", ai);
    const jnode *nz = jget(&g->j, an, "normalized");
    a->normalized = nz && nz->type == J_BOOL && nz->num != 0;
    if (count == 0)
        return gbad(g, "/accessors/%zu/count: 0 (at least 1)", ai);
    a->count = count;
    size_t esize = cs * (size_t)a->ncomp;
    size_t vi;
    const jnode *bv = jget(&g->j, an, "bufferView");
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
    const jnode *sp = jget(&g->j, an, "sparse");
    if (sp) {
        size_t sc;
        if ((st = get_index(g, sp, "count", -1, SIZE_MAX, "/accessors", ai,
                            &sc)))
            return st;
        if (sc == 0 || sc > count)
            return gbad(g, "/accessors/%zu/sparse/count: %zu (1..%zu)", ai,
                        sc, count);
        const jnode *si = jget(&g->j, sp, "indices");
        const jnode *sv = jget(&g->j, sp, "values");
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
static st_status get_numbers(gltf *g, const jnode *o, const char *key,
                             size_t n, double *v, size_t ni)
{
    const jnode *a = jget(&g->j, o, key);
    if (!a)
        return ST_OK;
    if (a->type != J_ARR || a->count != n)
        return gbad(g, "/nodes/%zu/%s: not an array of %zu numbers", ni, key,
                    n);
    for (size_t i = 0; i < n; i++) {
        const jnode *x = jat(&g->j, a, i);
        if (x->type != J_NUM || !isfinite(x->num))
            return gbad(g, "/nodes/%zu/%s/%zu: not a finite number", ni, key,
                        i);
        v[i] = x->num;
    }
    return ST_OK;
}

/* The node's local transform, column-major. */
static st_status local_matrix(gltf *g, const jnode *nd, size_t ni,
                              double m[16])
{
    static const double id[16] = {1, 0, 0, 0, 0, 1, 0, 0,
                                  0, 0, 1, 0, 0, 0, 0, 1};
    memcpy(m, id, sizeof id);
    st_status st;
    if (jget(&g->j, nd, "matrix"))
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

static st_status add_primitive(gltf *g, const jnode *prim, size_t mi,
                               size_t pi, const double M[16])
{
    size_t mode;
    st_status st;
    if ((st = get_index(g, prim, "mode", 4, 7, "/meshes/primitives", mi,
                        &mode)))
        return st;
    const jnode *ext = jget(&g->j, prim, "extensions");
    if (jget(&g->j, ext, "KHR_draco_mesh_compression"))
        return gbad(g, "/meshes/%zu/primitives/%zu: Draco-compressed "
                       "(KHR_draco_mesh_compression) geometry is not read; "
                       "decompress it first (e.g. gltf-transform copy)",
                    mi, pi);
    if (mode < 4) {
        g->ignored++;
        return ST_OK;
    }
    const jnode *attrs = jget(&g->j, prim, "attributes");
    size_t pa;
    if (!jget(&g->j, attrs, "POSITION")) {
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
    int indexed = jget(&g->j, prim, "indices") != NULL;
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
    const jnode *mesh = jat(&g->j, jget(&g->j, g->root, "meshes"), mi);
    if (!mesh || mesh->type != J_OBJ)
        return gbad(g, "/meshes/%zu: no such mesh", mi);
    const jnode *prims = jget(&g->j, mesh, "primitives");
    if (!prims || prims->type != J_ARR)
        return gbad(g, "/meshes/%zu: no primitives", mi);
    for (size_t p = 0; p < prims->count; p++) {
        st_status st = add_primitive(g, jat(&g->j, prims, p), mi, p, M);
        if (st)
            return st;
    }
    return ST_OK;
}

/* Depth-first through the node trees under roots, with an explicit stack
 * (a chain of nodes may be as long as the file). A node reached twice is
 * a cycle or a node with two parents: both invalid glTF. */
/* A mesh node is a part (parts.h): its name, else its mesh's, else "". */
static st_status node_name(gltf *g, const jnode *nd, size_t mi)
{
    const jnode *nm = jget(&g->j, nd, "name");
    if (!nm || nm->type != J_STR) {
        const jnode *mesh = jat(&g->j, jget(&g->j, g->root, "meshes"), mi);
        nm = mesh && mesh->type == J_OBJ ? jget(&g->j, mesh, "name") : NULL;
    }
    const int named = nm && nm->type == J_STR;
    if (st_soup__push_name(g->s, 1,
                           named ? (const unsigned char *)g->j.arena + nm->str : NULL,
                           named ? nm->slen : 0))
        return st_error_set(g->err, ST_ENOMEM, g->name, 0, "out of memory");
    return ST_OK;
}

static st_status walk(gltf *g, const size_t *roots, size_t nroots)
{
    const jnode *nodes = jget(&g->j, g->root, "nodes");
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
            const jnode *nd = jat(&g->j, nodes, f.node);
            if (!nd || nd->type != J_OBJ) {
                st = gbad(g, "/nodes/%zu: not an object", f.node);
                break;
            }
            double L[16], W[16];
            if ((st = local_matrix(g, nd, f.node, L)))
                break;
            mat_mul(W, f.M, L);
            if (jget(&g->j, nd, "mesh")) {
                size_t mi;
                if ((st = get_index(g, nd, "mesh", -1, SIZE_MAX, "/nodes",
                                    f.node, &mi)) ||
                    (st = node_name(g, nd, mi)) ||
                    (st = add_mesh(g, mi, W)))
                    break;
            }
            /* Children pushed last first: they are visited in order. */
            const jnode *ch = jget(&g->j, nd, "children");
            for (size_t cc = array_count(ch); cc > 0; cc--) {
                const size_t c = cc - 1;
                const jnode *x = jat(&g->j, ch, c);
                if (x->type != J_NUM || !(x->num >= 0) ||
                    x->num != floor(x->num) || x->num >= (double)nn) {
                    st = gbad(g, "/nodes/%zu/children/%zu: not a node index",
                              f.node, c);
                    break;
                }
                size_t k = (size_t)x->num;
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
    const json *j = &g->j;
    const jnode *root = g->root;
    if (root->type != J_OBJ)
        return gbad(g, "the document is not a JSON object");
    const jnode *asset = jget(j, root, "asset");
    const jnode *ver = jget(j, asset, "version");
    if (!ver || ver->type != J_STR)
        return gbad(g, "/asset/version: missing (not a glTF file?)");
    if (strncmp(j->arena + ver->str, "2.", 2) != 0)
        return gbad(g, "/asset/version: \"%.20s\" (only glTF 2.x is read)",
                    j->arena + ver->str);
    const jnode *req = jget(j, root, "extensionsRequired");
    for (size_t i = 0; i < array_count(req); i++) {
        const jnode *e = jat(j, req, i);
        if (e->type != J_STR)
            continue;
        const char *en = j->arena + e->str;
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
    const jnode *bufs = jget(j, root, "buffers");
    g->nbuffers = array_count(bufs);
    if (g->nbuffers) {
        g->buffers = calloc(g->nbuffers, sizeof *g->buffers);
        if (!g->buffers)
            return st_error_set(g->err, ST_ENOMEM, g->name, 0,
                                "out of memory");
        for (size_t i = 0; i < g->nbuffers; i++) {
            size_t bl;
            st_status st = get_index(g, jat(j, bufs, i), "byteLength", -1,
                                     SIZE_MAX, "/buffers", i, &bl);
            if (st)
                return st;
            g->buffers[i].size = bl;
        }
    }
    /* The roots: the default scene's nodes, else every node no other
     * lists as a child. */
    const jnode *nodes = jget(j, root, "nodes");
    size_t nn = array_count(nodes);
    size_t *roots = st_realloc_array(NULL, nn ? nn : 1, sizeof *roots);
    if (!roots)
        return st_error_set(g->err, ST_ENOMEM, g->name, 0, "out of memory");
    size_t nr = 0;
    st_status st = ST_OK;
    const jnode *scene = jget(j, root, "scene");
    if (scene) {
        size_t si;
        const jnode *scenes = jget(j, root, "scenes");
        st = get_index(g, root, "scene", -1, array_count(scenes), "", 0, &si);
        if (st) {
            st = gbad(g, "/scene: not an index into /scenes");
        } else {
            const jnode *sn = jget(j, jat(j, scenes, si), "nodes");
            for (size_t i = 0; i < array_count(sn) && !st; i++) {
                const jnode *x = jat(j, sn, i);
                if (x->type != J_NUM || !(x->num >= 0) ||
                    x->num != floor(x->num) || x->num >= (double)nn)
                    st = gbad(g, "/scenes/%zu/nodes/%zu: not a node index",
                              si, i);
                else
                    roots[nr++] = (size_t)x->num;
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
            const jnode *ch = jget(j, jat(j, nodes, n), "children");
            for (size_t c = 0; c < array_count(ch); c++) {
                const jnode *x = jat(j, ch, c);
                if (x->type == J_NUM && x->num >= 0 && x->num < (double)nn)
                    child[(size_t)x->num] = 1;
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
        st = json_parse(&g.j, js, jn, name, err);
        if (st && err && err->offset >= 0)
            err->offset += 20;
    } else {
        st = json_parse(&g.j, js, jn, name, err);
    }
    if (st == ST_OK) {
        g.root = &g.j.nodes[0];
        st = read_document(&g);
    }
    for (size_t i = 0; i < g.nbuffers; i++)
        free(g.buffers[i].owned);
    free(g.buffers);
    json_free(&g.j);
    return st;
}
