/*
 * soupread.c - reading triangle soups (see soup.h): formats by name and by
 * content, the front door that reads a file into memory and dispatches to
 * the per-format readers (soup_obj.c, soup_off.c, soup_ply.c, soup_stl.c,
 * soup_gltf.c; soupread.h), the readers' warnings, and the source hash.
 */
#include "souptet/soup.h"
#include "../base/fpenv.h"
#include "../base/bytes.h"
#include "../base/lexer.h"
#include "soupread.h"
#include "../base/fileio.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <xxhash.h>

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
        uint32_t cnt = st_le32(data + 80);
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
