/*
 * soup_stl.c - the STL reader, ASCII and binary.
 *
 * STL has no vertex indexing: every triangle gets three vertices of its
 * own (nothing is welded here).
 *
 * ASCII: solid NAME / facet [normal nx ny nz] / outer loop / vertex x y z
 * (3 of them; more are fanned) / endloop / endfacet / endsolid [NAME],
 * several solids per file allowed; keywords case-insensitive, any
 * whitespace between tokens.
 *
 * Binary: 80-byte header, uint32 little-endian triangle count, then per
 * triangle 12 float32 LE (normal, 3 vertices) and a uint16 attribute. The
 * count must match the file size exactly.
 */
#include "../base/bytes.h"
#include "../base/lexer.h"
#include "soup_internal.h"
#include "soupread.h"
#include "../base/fpenv.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#define STL_HEADER 80
#define STL_PREFIX 84       /* header + count */
#define STL_RECORD 50

/* No byte a text file would not contain (NUL and other controls). UTF-8
 * bytes >= 0x80 are allowed: solid names may use them. */
static int looks_like_text(const unsigned char *d, size_t n)
{
    for (size_t i = 0; i < n; i++)
        if (d[i] < 0x09 || (d[i] > 0x0d && d[i] < 0x20) || d[i] == 0x7f)
            return 0;
    return 1;
}

int st_soup__stl_is_ascii(const unsigned char *data, size_t size)
{
    st_text t;
    st_text_init(&t, data, size, 0);
    const unsigned char *tok = NULL;
    size_t n = st_text_token_any(&t, &tok);
    if (!st_tok_ieq(tok, n, "solid"))
        return 0;
    /* Many binary files start their 80-byte header with "solid" too. The
     * structure decides: ASCII when the solid line is followed by a facet
     * (or at once by endsolid). A file that is not structured like that is
     * still ASCII, if broken, when it is text and its size is not that of
     * a binary file -- so a damaged ASCII file gets ASCII messages while a
     * truncated binary one (which has NULs in its count or floats) gets a
     * size mismatch. */
    st_text_next_line(&t);
    n = st_text_token_any(&t, &tok);
    if (n && (st_tok_ieq(tok, n, "facet") || st_tok_ieq(tok, n, "endsolid")))
        return 1;
    if (size >= STL_PREFIX &&
        (uint64_t)st_le32(data + STL_HEADER) * STL_RECORD + STL_PREFIX == size)
        return 0;
    return looks_like_text(data, size < 1000 ? size : 1000);
}

/* ---- ASCII -------------------------------------------------------------- */

typedef struct asc {
    st_text t;
    const char *name;
    st_error *err;
} asc;

static st_status asc_eof(asc *a)
{
    return st_error_set(a->err, ST_EINPUT, a->name, st_text_eof_line(&a->t),
                        "file ends inside a facet");
}

static st_status asc_expected(asc *a, const char *what,
                              const unsigned char *tok, size_t n)
{
    char q[ST_QUOTE_SIZE];
    return st_error_set(a->err, ST_EINPUT, a->name, a->t.line,
                        "expected %s, found '%s'", what,
                        st_text_quote(q, sizeof q, tok, n));
}

/* The next token must be the keyword kw. */
static st_status asc_keyword(asc *a, const char *kw)
{
    const unsigned char *tok;
    size_t n = st_text_token_any(&a->t, &tok);
    if (!n)
        return asc_eof(a);
    if (!st_tok_ieq(tok, n, kw)) {
        char what[32];
        snprintf(what, sizeof what, "'%s'", kw);
        return asc_expected(a, what, tok, n);
    }
    return ST_OK;
}

/* A facet, after its "facet" keyword. */
static st_status asc_facet(asc *a, st_soup *s)
{
    const unsigned char *tok;
    size_t n = st_text_token_any(&a->t, &tok);
    if (!n)
        return asc_eof(a);
    if (st_tok_ieq(tok, n, "normal")) {
        /* The normal is not used; damaged files often have nan there. */
        for (int k = 0; k < 3; k++)
            if (!st_text_token_any(&a->t, &tok))
                return asc_eof(a);
        if (!(n = st_text_token_any(&a->t, &tok)))
            return asc_eof(a);
    }
    if (!st_tok_ieq(tok, n, "outer"))
        return asc_expected(a, "'outer loop'", tok, n);
    st_status st = asc_keyword(a, "loop");
    if (st)
        return st;
    size_t base = s->nverts;
    long long k = 0;
    for (;;) {
        if (!(n = st_text_token_any(&a->t, &tok)))
            return asc_eof(a);
        if (st_tok_ieq(tok, n, "endloop"))
            break;
        if (!st_tok_ieq(tok, n, "vertex"))
            return asc_expected(a, "'vertex' or 'endloop'", tok, n);
        double c[3];
        for (int j = 0; j < 3; j++) {
            if (!(n = st_text_token_any(&a->t, &tok)))
                return asc_eof(a);
            if (st_text_double(tok, n, &c[j]) != 0)
                return asc_expected(a, "a coordinate", tok, n);
            if (!isfinite(c[j]))
                return st_error_set(a->err, ST_EINPUT, a->name, a->t.line,
                                    "coordinate is not finite");
        }
        if ((st = st_soup__push_vertex(s, c[0], c[1], c[2])))
            return st_soup__push_failed(a->err, st, a->name, a->t.line, -1);
        if (k >= 2) {
            uint32_t b = (uint32_t)base;
            if ((st = st_soup__push_tri(s, b, b + (uint32_t)k - 1,
                                        b + (uint32_t)k)))
                return st_soup__push_failed(a->err, st, a->name, a->t.line,
                                            -1);
        }
        k++;
    }
    if (k < 3)
        return st_error_set(a->err, ST_EINPUT, a->name, a->t.line,
                            "facet has %lld %s (need at least 3)", k,
                            k == 1 ? "vertex" : "vertices");
    return asc_keyword(a, "endfacet");
}

static st_status parse_ascii(st_soup *s, const unsigned char *data,
                             size_t size, const char *name, st_error *err)
{
    asc a;
    st_text_init(&a.t, data, size, 0);
    a.name = name;
    a.err = err;
    int inside = 0;
    for (;;) {
        const unsigned char *tok;
        size_t n = st_text_token_any(&a.t, &tok);
        if (!n) {
            if (inside)
                return st_error_set(err, ST_EINPUT, name,
                                    st_text_eof_line(&a.t),
                                    "file ends before endsolid");
            return ST_OK;
        }
        st_status st = ST_OK;
        if (!inside) {
            if (!st_tok_ieq(tok, n, "solid"))
                return asc_expected(&a, "'solid'", tok, n);
            /* The solid's name: a part (parts.h). */
            const unsigned char *nm;
            size_t nl = st_text_rest(&a.t, &nm);
            st = st_soup__push_name(s, 1, nm, nl);
            if (st)
                return st_soup__push_failed(err, st, name, a.t.line, -1);
            st_text_next_line(&a.t);
            inside = 1;
        } else if (st_tok_ieq(tok, n, "endsolid")) {
            st_text_next_line(&a.t);
            inside = 0;
        } else if (st_tok_ieq(tok, n, "facet")) {
            st = asc_facet(&a, s);
        } else {
            st = asc_expected(&a, "'facet' or 'endsolid'", tok, n);
        }
        if (st)
            return st;
    }
}

/* ---- binary ------------------------------------------------------------- */

static st_status parse_binary(st_soup *s, const unsigned char *data,
                              size_t size, const char *name, st_error *err)
{
    if (size < STL_PREFIX)
        return st_error_set_offset(err, ST_EINPUT, name, (long long)size,
                                   "too short for a binary STL (%zu bytes, "
                                   "need at least %d)", size, STL_PREFIX);
    uint32_t count = st_le32(data + STL_HEADER);
    uint64_t want = (uint64_t)count * STL_RECORD + STL_PREFIX;
    if (want != size)
        return st_error_set_offset(err, ST_EINPUT, name, STL_HEADER,
                                   "header says %lu triangles (%llu bytes) "
                                   "but the file has %zu bytes",
                                   (unsigned long)count,
                                   (unsigned long long)want, size);
    if (count > UINT32_MAX / 3)
        return st_error_set_offset(err, ST_ELIMIT, name, STL_HEADER,
                                   "more than 4294967295 vertices");
    for (uint32_t i = 0; i < count; i++) {
        size_t rec = STL_PREFIX + (size_t)i * STL_RECORD;
        uint32_t base = (uint32_t)s->nverts;
        for (int v = 0; v < 3; v++) {
            double c[3];
            for (int j = 0; j < 3; j++) {
                size_t off = rec + 12 + 12 * (size_t)v + 4 * (size_t)j;
                uint32_t bits = st_le32(data + off);
                float f;
                memcpy(&f, &bits, sizeof f);
                if (!isfinite(f))
                    return st_error_set_offset(err, ST_EINPUT, name,
                                               (long long)off,
                                               "coordinate is not finite");
                c[j] = (double)f;
            }
            st_status st = st_soup__push_vertex(s, c[0], c[1], c[2]);
            if (st)
                return st_soup__push_failed(err, st, name, 0,
                                            (long long)rec);
        }
        st_status st = st_soup__push_tri(s, base, base + 1, base + 2);
        if (st)
            return st_soup__push_failed(err, st, name, 0, (long long)rec);
    }
    return ST_OK;
}

st_status st_soup__parse_stl(st_soup *s, const unsigned char *data,
                             size_t size, const char *name, st_error *err)
{
    if (st_soup__stl_is_ascii(data, size))
        return parse_ascii(s, data, size, name, err);
    return parse_binary(s, data, size, name, err);
}
