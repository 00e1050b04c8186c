/*
 * soup.c - triangle soups: building, bounds, format detection, reading a
 * file into memory and dispatching to the per-format readers (see soup.h).
 *
 * Also the helpers the readers share (soup_parse.h): the number scanner and
 * the unchecked appends.
 */
#include "souptet/soup.h"
#include "fpenv.h"
#include "souptet/mem.h"
#include "soup_parse.h"
#include "fileio.h"

#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <stdio.h>
#include <string.h>
#include <xxhash.h>

/* ---- building ---------------------------------------------------------- */

/*
 * Capacity is implicit in the count, so st_soup needs no capacity field and
 * a zero-initialised st_soup works too: an array holding n > 0 elements has
 * room for max(64, the power of two >= n). It is full exactly when n is 0 or
 * a power of two >= 64, and then doubles.
 */
#define MIN_CAP 64

static int grow(void **arr, size_t n, size_t elem)
{
    if (n != 0 && (n < MIN_CAP || (n & (n - 1)) != 0))
        return 0;
    size_t cap;
    if (n == 0)
        cap = MIN_CAP;
    else if (st_size_mul(&cap, n, 2) != 0)
        return -1;
    void *p = st_realloc_array(*arr, cap, elem);
    if (!p)
        return -1;
    *arr = p;
    return 0;
}

st_status st_soup__push_vertex(st_soup *s, double x, double y, double z)
{
    if (s->nverts >= UINT32_MAX)
        return ST_ELIMIT;
    if (grow((void **)&s->xyz, s->nverts, 3 * sizeof(double)) != 0)
        return ST_ENOMEM;
    double *v = s->xyz + 3 * s->nverts;
    v[0] = x;
    v[1] = y;
    v[2] = z;
    s->nverts++;
    return ST_OK;
}

st_status st_soup__push_tri(st_soup *s, uint32_t a, uint32_t b, uint32_t c)
{
    if (grow((void **)&s->tris, s->ntris, 3 * sizeof(uint32_t)) != 0)
        return ST_ENOMEM;
    uint32_t *t = s->tris + 3 * s->ntris;
    t[0] = a;
    t[1] = b;
    t[2] = c;
    s->ntris++;
    return ST_OK;
}

st_status st_soup__push_failed(st_error *err, st_status st, const char *name,
                               long long line, long long offset)
{
    const char *what = st == ST_ELIMIT
                           ? "more than 4294967295 vertices"
                           : "out of memory";
    if (offset >= 0)
        return st_error_set_offset(err, st, name, offset, "%s", what);
    return st_error_set(err, st, name, line, "%s", what);
}

st_soup *st_soup_new(void)
{
    return calloc(1, sizeof(st_soup));
}

void st_soup_free(st_soup *s)
{
    if (!s)
        return;
    free(s->xyz);
    free(s->tris);
    for (size_t i = 0; i < s->nnames; i++)
        free(s->names[i].name);
    free(s->names);
    free(s);
}

st_status st_soup_add_vertex(st_soup *s, double x, double y, double z,
                             st_error *err)
{
    st_status st = st_soup__push_vertex(s, x, y, z);
    if (st)
        return st_soup__push_failed(err, st, NULL, 0, -1);
    return ST_OK;
}

st_status st_soup_add_triangle(st_soup *s, uint32_t a, uint32_t b, uint32_t c,
                               st_error *err)
{
    if (a >= s->nverts || b >= s->nverts || c >= s->nverts)
        return st_error_set(err, ST_EINPUT, NULL, 0,
                            "triangle (%lu %lu %lu) refers past the %zu "
                            "vertices", (unsigned long)a, (unsigned long)b,
                            (unsigned long)c, s->nverts);
    st_status st = st_soup__push_tri(s, a, b, c);
    if (st)
        return st_soup__push_failed(err, st, NULL, 0, -1);
    return ST_OK;
}

st_status st_soup__push_name(st_soup *s, int level, const unsigned char *name,
                             size_t len)
{
    if (len > ST_SOUP_NAME_MAX) {
        /* cut before a UTF-8 sequence, not inside it */
        len = ST_SOUP_NAME_MAX;
        while (len > 0 && (name[len] & 0xc0) == 0x80)
            len--;
    }
    if (grow((void **)&s->names, s->nnames, sizeof *s->names) != 0)
        return ST_ENOMEM;
    char *c = malloc(len + 1);
    if (!c)
        return ST_ENOMEM;
    if (len)
        memcpy(c, name, len);
    c[len] = '\0';
    /* A NUL inside a name would cut it short in every writer: make it '_'. */
    for (size_t i = 0; i < len; i++)
        if (c[i] == '\0')
            c[i] = '_';
    s->names[s->nnames].first = s->ntris;
    s->names[s->nnames].name = c;
    s->names[s->nnames].level = level;
    s->nnames++;
    return ST_OK;
}

st_status st_soup_add_name(st_soup *s, int level, const char *name, size_t len,
                           st_error *err)
{
    if (st_soup__push_name(s, level, (const unsigned char *)name, len))
        return st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory");
    return ST_OK;
}

st_status st_soup_bounds(const st_soup *s, double lo[3], double hi[3],
                         st_error *err)
{
    if (!s || s->ntris == 0)
        return st_error_set(err, ST_EINPUT, NULL, 0, "no triangles");
    for (int a = 0; a < 3; a++) {
        lo[a] = INFINITY;
        hi[a] = -INFINITY;
    }
    for (size_t i = 0; i < 3 * s->ntris; i++) {
        uint32_t v = s->tris[i];
        if (v >= s->nverts)
            return st_error_set(err, ST_EINTERNAL, NULL, 0,
                                "triangle %zu refers to vertex %lu of %zu",
                                i / 3, (unsigned long)v, s->nverts);
        const double *p = s->xyz + 3 * (size_t)v;
        for (int a = 0; a < 3; a++) {
            if (p[a] < lo[a])
                lo[a] = p[a];
            if (p[a] > hi[a])
                hi[a] = p[a];
        }
    }
    return ST_OK;
}

/* ---- numbers ----------------------------------------------------------- */

/* 10^k for k <= 22 is exactly representable in a double (5^22 < 2^53). */
static const double pow10_exact[23] = {
    1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,  1e8,  1e9,  1e10, 1e11,
    1e12, 1e13, 1e14, 1e15, 1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};

/* The longest token handed to strtod; longer ones are not numbers we take. */
#define SLOW_MAX 400

int st_soup__scan_double(const unsigned char *tok, size_t n, double *out)
{
    /*
     * Fast path (Clinger): a decimal with at most 19 significant digits
     * whose mantissa m fits in 53 bits and whose power of ten |e| <= 22 is
     * m * 10^e or m / 10^e, both exact operands and one correctly rounded
     * operation, so the result equals strtod's. Everything else (long
     * mantissas, big exponents, nan, inf, hex) goes to strtod on a bounded,
     * NUL-terminated copy of the token.
     */
    size_t i = 0;
    int neg = 0;
    if (i < n && (tok[i] == '+' || tok[i] == '-')) {
        neg = tok[i] == '-';
        i++;
    }
    uint64_t m = 0;
    int nd = 0, digits = 0, inexact = 0;
    long e10 = 0;
    for (; i < n && tok[i] >= '0' && tok[i] <= '9'; i++) {
        digits = 1;
        unsigned d = (unsigned)(tok[i] - '0');
        if (nd < 19) {
            if (m || d) {
                m = m * 10 + d;
                nd++;
            }
        } else {
            e10++;
            inexact |= d != 0;
        }
    }
    if (i < n && tok[i] == '.') {
        for (i++; i < n && tok[i] >= '0' && tok[i] <= '9'; i++) {
            digits = 1;
            unsigned d = (unsigned)(tok[i] - '0');
            if (nd < 19) {
                if (m || d) {
                    m = m * 10 + d;
                    nd++;
                }
                e10--;
            } else {
                inexact |= d != 0;
            }
        }
    }
    if (!digits)
        goto slow;
    if (i < n && (tok[i] == 'e' || tok[i] == 'E')) {
        i++;
        int eneg = 0;
        if (i < n && (tok[i] == '+' || tok[i] == '-')) {
            eneg = tok[i] == '-';
            i++;
        }
        if (i == n || tok[i] < '0' || tok[i] > '9')
            goto slow;
        long e = 0;
        for (; i < n && tok[i] >= '0' && tok[i] <= '9'; i++)
            if (e < 100000)
                e = e * 10 + (tok[i] - '0');
        e10 += eneg ? -e : e;
    }
    if (i != n)
        goto slow;
    if (m == 0) {
        *out = neg ? -0.0 : 0.0;
        return 0;
    }
    if (!inexact && m <= (UINT64_C(1) << 53) && e10 >= -22 && e10 <= 22) {
        double d = (double)m;
        d = e10 < 0 ? d / pow10_exact[-e10] : d * pow10_exact[e10];
        *out = neg ? -d : d;
        return 0;
    }
slow:;
    char buf[SLOW_MAX + 1];
    if (n == 0 || n > SLOW_MAX)
        return -1;
    memcpy(buf, tok, n);
    buf[n] = '\0';
    char *endp;
    double d = strtod(buf, &endp);
    if (endp != buf + n)
        return -1;
    *out = d;
    return 0;
}

int st_soup__scan_int(const unsigned char *tok, size_t n, long long *out)
{
    size_t i = 0;
    int neg = 0;
    if (i < n && (tok[i] == '+' || tok[i] == '-')) {
        neg = tok[i] == '-';
        i++;
    }
    if (i == n)
        return -1;
    unsigned long long v = 0;
    int big = 0;
    for (; i < n; i++) {
        if (tok[i] < '0' || tok[i] > '9')
            return -1;
        if (v > (unsigned long long)LLONG_MAX / 10)
            big = 1;
        else
            v = v * 10 + (unsigned)(tok[i] - '0');
    }
    if (big || v > (unsigned long long)LLONG_MAX)
        v = (unsigned long long)LLONG_MAX;
    *out = neg ? -(long long)v : (long long)v;
    return 0;
}

const char *st_soup__quote(char *buf, size_t bufsize,
                           const unsigned char *tok, size_t n)
{
    if (bufsize < 8) {
        if (bufsize)
            buf[0] = '\0';
        return buf;
    }
    size_t room = bufsize - 1, j = 0;
    size_t keep = n <= room ? n : room - 3;
    for (size_t i = 0; i < keep; i++)
        buf[j++] = (tok[i] >= 0x20 && tok[i] < 0x7f) ? (char)tok[i] : '?';
    if (keep < n) {
        memcpy(buf + j, "...", 3);
        j += 3;
    }
    buf[j] = '\0';
    return buf;
}

/* ---- formats ------------------------------------------------------------ */

st_soup_format st_soup_format_from_path(const char *path)
{
    static const char *const ext[] = {"obj", "off", "ply", "stl", "gltf",
                                      "glb"};
    static const st_soup_format fmt[] = {ST_SOUP_OBJ, ST_SOUP_OFF,
                                         ST_SOUP_PLY, ST_SOUP_STL,
                                         ST_SOUP_GLTF, ST_SOUP_GLTF};
    int k = st_path_ext_match(path, ext, 6, 0);
    return k < 0 ? ST_SOUP_UNKNOWN : fmt[k];
}

const char *st_soup_format_name(st_soup_format format)
{
    switch (format) {
    case ST_SOUP_OBJ: return "obj";
    case ST_SOUP_OFF: return "off";
    case ST_SOUP_PLY: return "ply";
    case ST_SOUP_STL: return "stl";
    case ST_SOUP_GLTF: return "gltf";
    case ST_SOUP_UNKNOWN: break;
    }
    return "unknown";
}

static int has_prefix(const unsigned char *d, size_t n, const char *s)
{
    size_t k = strlen(s);
    return n >= k && memcmp(d, s, k) == 0;
}

/* The OFF keyword: [ST][C][N]OFF (4OFF/nOFF are recognised as OFF too, so
 * the reader can say they are unsupported). */
static int is_off_keyword(const unsigned char *t, size_t n)
{
    size_t i = 0;
    if (n - i >= 2 && t[i] == 'S' && t[i + 1] == 'T')
        i += 2;
    if (i < n && t[i] == 'C')
        i++;
    if (i < n && t[i] == 'N')
        i++;
    if (i < n && (t[i] == '4' || t[i] == 'n'))
        i++;
    return n - i == 3 && memcmp(t + i, "OFF", 3) == 0;
}

st_soup_format st_soup_format_sniff(const unsigned char *data, size_t size)
{
    if (!data || size == 0)
        return ST_SOUP_UNKNOWN;
    if (has_prefix(data, size, "ply\n") || has_prefix(data, size, "ply\r\n"))
        return ST_SOUP_PLY;
    /* glTF: the GLB magic, or a JSON object (no other format starts with
     * '{' after blanks). */
    if (has_prefix(data, size, "glTF"))
        return ST_SOUP_GLTF;
    {
        size_t i = 0;
        if (has_prefix(data, size, "\xEF\xBB\xBF"))
            i = 3;
        while (i < size && (data[i] == ' ' || data[i] == '\t' ||
                            data[i] == '\n' || data[i] == '\r'))
            i++;
        if (i < size && data[i] == '{')
            return ST_SOUP_GLTF;
    }

    /* OFF: the first token, after blank and comment lines. */
    st_text t;
    st_text_init(&t, data, size, ST_TEXT_HASH);
    const unsigned char *tok;
    size_t n = st_text_token_any(&t, &tok);
    if (n && is_off_keyword(tok, n))
        return ST_SOUP_OFF;

    /* STL: "solid" then facets (ASCII), or a size of 84 + 50n (binary,
     * whatever its header says). */
    if (n == 5 && st_tok_ieq(tok, n, "solid")) {
        size_t lim = size < 1000 ? size : 1000;
        for (size_t i = 0; i + 5 <= lim; i++)
            if (st_tok_ieq(data + i, 5, "facet"))
                return ST_SOUP_STL;
    }
    if (size >= 84) {
        uint32_t cnt = (uint32_t)data[80] | (uint32_t)data[81] << 8 |
                       (uint32_t)data[82] << 16 | (uint32_t)data[83] << 24;
        if ((uint64_t)cnt * 50 + 84 == size)
            return ST_SOUP_STL;
    }

    /* OBJ: some line starting with "v " or "f ". */
    int bol = 1;
    for (size_t i = 0; i < size; i++) {
        unsigned char c = data[i];
        if (bol && (c == 'v' || c == 'f') && i + 1 < size &&
            (data[i + 1] == ' ' || data[i + 1] == '\t'))
            return ST_SOUP_OBJ;
        bol = c == '\n';
    }
    return ST_SOUP_UNKNOWN;
}

/* ---- parsing and reading ------------------------------------------------ */

void st_soup__warn(st_soup_warnings *warn, const char *name, long long line,
                   long long offset, const char *fmt, ...)
{
    if (!warn)
        return;
    if (warn->count++ > 0)
        return;
    char msg[sizeof warn->first.msg];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    if (offset >= 0)
        st_error_set_offset(&warn->first, ST_OK, name, offset, "%s", msg);
    else
        st_error_set(&warn->first, ST_OK, name, line, "%s", msg);
}

static void warnings_clear(st_soup_warnings *warn)
{
    if (warn) {
        st_error_clear(&warn->first);
        warn->count = 0;
    }
}

st_status st_soup_parse(st_soup **out, st_soup_format format,
                        const unsigned char *data, size_t size,
                        const char *name, st_error *err)
{
    return st_soup_parse_warn(out, format, data, size, name, NULL, err);
}

static st_status parse_at(st_soup **out, st_soup_format format,
                          const unsigned char *data, size_t size,
                          const char *name, const char *path,
                          const st_soup__file_hook *hook,
                          st_soup_warnings *warn, st_error *err);

st_status st_soup_parse_warn(st_soup **out, st_soup_format format,
                             const unsigned char *data, size_t size,
                             const char *name, st_soup_warnings *warn,
                             st_error *err)
{
    return parse_at(out, format, data, size, name, NULL, NULL, warn, err);
}

/* st_soup_parse_warn, with the file's path for glTF's external buffers. */
static st_status parse_at(st_soup **out, st_soup_format format,
                          const unsigned char *data, size_t size,
                          const char *name, const char *path,
                          const st_soup__file_hook *hook,
                          st_soup_warnings *warn, st_error *err)
{
    warnings_clear(warn);
    if (out)
        *out = NULL;
    if (!name)
        name = "<input>";
    if (!out || (!data && size))
        return st_error_set(err, ST_EINTERNAL, name, 0,
                            "st_soup_parse: bad arguments");
    if (size == 0)
        return st_error_set(err, ST_EINPUT, name, 0, "file is empty");
    st_soup *s = st_soup_new();
    if (!s)
        return st_error_set(err, ST_ENOMEM, name, 0, "out of memory");
    st_status st;
    switch (format) {
    case ST_SOUP_OBJ: st = st_soup__parse_obj(s, data, size, name, err); break;
    case ST_SOUP_OFF: st = st_soup__parse_off(s, data, size, name, err); break;
    case ST_SOUP_PLY: st = st_soup__parse_ply(s, data, size, name, warn, err); break;
    case ST_SOUP_STL: st = st_soup__parse_stl(s, data, size, name, err); break;
    case ST_SOUP_GLTF:
        st = st_soup__parse_gltf(s, data, size, name, path, hook, warn, err);
        break;
    default:
        st = st_error_set(err, ST_EINPUT, name, 0,
                          "unknown format (not OBJ, OFF, PLY, STL or glTF)");
        break;
    }
    if (st == ST_OK && s->ntris == 0)
        st = st_error_set(err, ST_EINPUT, name, 0, "no triangles");
    if (st != ST_OK) {
        st_soup_free(s);
        return st;
    }
    *out = s;
    return ST_OK;
}

static void source_set(st_soup_source *src, XXH128_hash_t h,
                       unsigned long long size)
{
    src->size = size;
    snprintf(src->hash, sizeof src->hash, "xxh3-128:%016llx%016llx",
             (unsigned long long)h.high64, (unsigned long long)h.low64);
}

void st_soup_source_of(st_soup_source *src, const void *data, size_t size)
{
    source_set(src, XXH3_128bits(data, size), (unsigned long long)size);
}

/* A glTF's source is its JSON (or GLB) file followed by every external
 * buffer file the reader loads, each after its length: a changed .bin
 * beside an unchanged .gltf is a changed source. */
typedef struct source_stream {
    XXH3_state_t *state;
    unsigned long long size;
} source_stream;

static void source_stream_bytes(void *ctx, const unsigned char *data,
                                size_t size)
{
    source_stream *ss = ctx;
    unsigned char len[8];
    for (int i = 0; i < 8; i++)
        len[i] = (unsigned char)((unsigned long long)size >> (8 * i));
    XXH3_128bits_update(ss->state, len, sizeof len);
    XXH3_128bits_update(ss->state, data, size);
    ss->size += (unsigned long long)size;
}

st_status st_soup_read(st_soup **out, const char *path, st_error *err)
{
    return st_soup_read_source(out, path, NULL, NULL, err);
}

st_status st_soup_read_warn(st_soup **out, const char *path,
                            st_soup_warnings *warn, st_error *err)
{
    return st_soup_read_source(out, path, NULL, warn, err);
}

st_status st_soup_read_source(st_soup **out, const char *path, st_soup_source *src,
                              st_soup_warnings *warn, st_error *err)
{
    if (src)
        memset(src, 0, sizeof *src);
    warnings_clear(warn);
    if (out)
        *out = NULL;
    if (!out || !path)
        return st_error_set(err, ST_EINTERNAL, NULL, 0,
                            "st_soup_read: bad arguments");
    int is_stdin = strcmp(path, "-") == 0;
    const char *name = is_stdin ? ST_STDIN_NAME : path;
    unsigned char *data = NULL;
    size_t size = 0;
    st_status st = st_file_read(path, &data, &size, err);
    if (st)
        return st;
    if (size == 0) {
        free(data);
        return st_error_set(err, ST_EINPUT, name, 0, "file is empty");
    }
    st_soup_format fmt =
        is_stdin ? ST_SOUP_UNKNOWN : st_soup_format_from_path(path);
    if (fmt == ST_SOUP_UNKNOWN)
        fmt = st_soup_format_sniff(data, size);
    source_stream ss = {NULL, 0};
    st_soup__file_hook hook = {source_stream_bytes, &ss};
    if (src && fmt == ST_SOUP_GLTF && !is_stdin) {
        ss.state = XXH3_createState();
        if (!ss.state) {
            free(data);
            return st_error_set(err, ST_ENOMEM, name, 0, "out of memory");
        }
        XXH3_128bits_reset(ss.state);
        XXH3_128bits_update(ss.state, data, size);
        ss.size = (unsigned long long)size;
    } else if (src) {
        st_soup_source_of(src, data, size);
    }
    if (fmt == ST_SOUP_UNKNOWN)
        st = st_error_set(err, ST_EINPUT, name, 0,
                          "unknown format (not OBJ, OFF, PLY, STL or glTF)");
    else
        st = parse_at(out, fmt, data, size, name, is_stdin ? NULL : path,
                      ss.state ? &hook : NULL, warn, err);
    if (ss.state) {
        source_set(src, XXH3_128bits_digest(ss.state), ss.size);
        XXH3_freeState(ss.state);
    }
    free(data);
    return st;
}

st_status st_soup_append(st_soup *dst, const st_soup *src, st_error *err)
{
    const size_t base = dst->nverts;
    for (size_t v = 0; v < src->nverts; v++) {
        const double *q = src->xyz + 3 * v;
        st_status st = st_soup_add_vertex(dst, q[0], q[1], q[2], err);
        if (st)
            return st;
    }
    for (size_t t = 0; t < src->ntris; t++) {
        const uint32_t *c = src->tris + 3 * t;
        st_status st = st_soup_add_triangle(dst, (uint32_t)(base + c[0]), (uint32_t)(base + c[1]),
                                            (uint32_t)(base + c[2]), err);
        if (st)
            return st;
    }
    return ST_OK;
}
