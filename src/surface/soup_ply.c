/*
 * soup_ply.c - the PLY reader (ascii, binary_little_endian and
 * binary_big_endian 1.0).
 *
 * The header is read into a small table of elements and properties. The
 * body is then walked element by element in header order: the vertex
 * element's x, y, z (any scalar type) become vertices, the face element's
 * vertex_indices / vertex_index list (any integer types) becomes fanned
 * triangles, and every other property, list and element is stepped over by
 * its declared type. Header problems are reported at a line, binary body
 * problems at a byte offset, ascii body problems at a line.
 */
#include "../base/lexer.h"
#include "soup_internal.h"
#include "soupread.h"
#include "../base/fpenv.h"
#include "souptet/mem.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef enum ptype {
    T_NONE = 0, T_I8, T_U8, T_I16, T_U16, T_I32, T_U32, T_F32, T_F64
} ptype;

typedef enum prole { R_NONE = 0, R_X, R_Y, R_Z, R_INDICES } prole;

typedef enum ekind { E_OTHER = 0, E_VERTEX, E_FACE } ekind;

typedef enum pformat { F_NONE = 0, F_ASCII, F_LE, F_BE } pformat;

typedef struct prop {
    ptype type;        /* scalar type, or the item type of a list */
    ptype count_type;  /* T_NONE for a scalar */
    prole role;
} prop;

typedef struct elem {
    ekind kind;
    unsigned long long count;
    prop *props;
    size_t nprops;
    long long line;    /* header line, for messages */
    char name[ST_QUOTE_SIZE];
} elem;

typedef struct ply {
    pformat format;
    elem *elems;
    size_t nelems;
    elem *vertex, *face;
    const char *name;
    st_soup_warnings *warn;
    st_error *err;
} ply;

static const struct {
    const char *name;
    ptype type;
} type_names[] = {
    {"char", T_I8},     {"uchar", T_U8},    {"short", T_I16},
    {"ushort", T_U16},  {"int", T_I32},     {"uint", T_U32},
    {"float", T_F32},   {"double", T_F64},  {"int8", T_I8},
    {"uint8", T_U8},    {"int16", T_I16},   {"uint16", T_U16},
    {"int32", T_I32},   {"uint32", T_U32},  {"float32", T_F32},
    {"float64", T_F64},
};

static size_t type_size(ptype t)
{
    switch (t) {
    case T_I8: case T_U8: return 1;
    case T_I16: case T_U16: return 2;
    case T_I32: case T_U32: case T_F32: return 4;
    case T_F64: return 8;
    case T_NONE: break;
    }
    return 0;
}

static int type_is_int(ptype t)
{
    return t != T_NONE && t != T_F32 && t != T_F64;
}

static ptype parse_type(const unsigned char *tok, size_t n)
{
    for (size_t i = 0; i < sizeof type_names / sizeof type_names[0]; i++)
        if (st_tok_eq(tok, n, type_names[i].name))
            return type_names[i].type;
    return T_NONE;
}

static void free_ply(ply *p)
{
    for (size_t i = 0; i < p->nelems; i++)
        free(p->elems[i].props);
    free(p->elems);
}

static st_status hdr_error(ply *p, long long line, const char *what,
                           const unsigned char *tok, size_t n)
{
    char q[ST_QUOTE_SIZE];
    if (tok)
        return st_error_set(p->err, ST_EINPUT, p->name, line, "%s '%s'",
                            what, st_text_quote(q, sizeof q, tok, n));
    return st_error_set(p->err, ST_EINPUT, p->name, line, "%s", what);
}

static st_status oom(ply *p, long long line)
{
    return st_error_set(p->err, ST_ENOMEM, p->name, line, "out of memory");
}

/* ---- header ------------------------------------------------------------- */

/* "element NAME COUNT" */
static st_status hdr_element(ply *p, st_text *t)
{
    const unsigned char *nm = NULL, *ct = NULL;
    size_t nn = st_text_token(t, &nm);
    size_t nc = nn ? st_text_token(t, &ct) : 0;
    if (!nc)
        return hdr_error(p, t->line, "element line needs a name and a count",
                         NULL, 0);
    long long count;
    if (st_text_int(ct, nc, &count) != 0 || count < 0)
        return hdr_error(p, t->line, "bad element count", ct, nc);
    /* One entry per header line: the header's own length bounds this. */
    elem *ne = st_realloc_array(p->elems, p->nelems + 1, sizeof *ne);
    if (!ne)
        return oom(p, t->line);
    p->elems = ne;
    elem *e = &p->elems[p->nelems++];
    memset(e, 0, sizeof *e);
    e->count = (unsigned long long)count;
    e->line = t->line;
    st_text_quote(e->name, sizeof e->name, nm, nn);
    if (st_tok_eq(nm, nn, "vertex"))
        e->kind = E_VERTEX;
    else if (st_tok_eq(nm, nn, "face"))
        e->kind = E_FACE;
    for (size_t i = 0; e->kind != E_OTHER && i + 1 < p->nelems; i++)
        if (p->elems[i].kind == e->kind)
            return hdr_error(p, t->line, "second element", nm, nn);
    /* Pointers into elems are taken after the header (realloc moves it). */
    return ST_OK;
}

/* "property TYPE NAME" or "property list COUNTTYPE ITEMTYPE NAME" */
static st_status hdr_property(ply *p, st_text *t)
{
    if (p->nelems == 0)
        return hdr_error(p, t->line, "property before any element", NULL,
                         0);
    elem *e = &p->elems[p->nelems - 1];
    prop pr = {T_NONE, T_NONE, R_NONE};
    const unsigned char *tok = NULL;
    size_t n = st_text_token(t, &tok);
    if (n && st_tok_eq(tok, n, "list")) {
        n = st_text_token(t, &tok);
        if (!n)
            return hdr_error(p, t->line, "incomplete list property", NULL, 0);
        pr.count_type = parse_type(tok, n);
        if (!type_is_int(pr.count_type))
            return hdr_error(p, t->line, "bad list count type", tok, n);
        n = st_text_token(t, &tok);
    }
    if (!n)
        return hdr_error(p, t->line, "incomplete property line", NULL, 0);
    pr.type = parse_type(tok, n);
    if (pr.type == T_NONE)
        return hdr_error(p, t->line, "unknown property type", tok, n);
    const unsigned char *nm;
    size_t nn = st_text_token(t, &nm);
    if (!nn)
        return hdr_error(p, t->line, "property has no name", NULL, 0);
    int list = pr.count_type != T_NONE;
    if (e->kind == E_VERTEX && nn == 1 && (nm[0] == 'x' || nm[0] == 'y' ||
                                           nm[0] == 'z')) {
        prole r = nm[0] == 'x' ? R_X : nm[0] == 'y' ? R_Y : R_Z;
        for (size_t i = 0; i < e->nprops; i++)
            if (e->props[i].role == r)
                return hdr_error(p, t->line, "second vertex property", nm,
                                 nn);
        if (list)
            return hdr_error(p, t->line, "vertex coordinate is a list", nm,
                             nn);
        pr.role = r;
    }
    if (e->kind == E_FACE && (st_tok_eq(nm, nn, "vertex_indices") ||
                              st_tok_eq(nm, nn, "vertex_index"))) {
        for (size_t i = 0; i < e->nprops; i++)
            if (e->props[i].role == R_INDICES)
                return hdr_error(p, t->line, "second face index list", nm,
                                 nn);
        if (!list)
            return hdr_error(p, t->line, "face indices are not a list", nm,
                             nn);
        if (!type_is_int(pr.type))
            return hdr_error(p, t->line, "face indices are not integers", nm,
                             nn);
        pr.role = R_INDICES;
    }
    prop *np = st_realloc_array(e->props, e->nprops + 1, sizeof *np);
    if (!np)
        return oom(p, t->line);
    e->props = np;
    e->props[e->nprops++] = pr;
    return ST_OK;
}

/* "format KIND 1.0" */
static st_status hdr_format(ply *p, st_text *t)
{
    const unsigned char *k = NULL, *v = NULL;
    size_t nk = st_text_token(t, &k);
    size_t nv = nk ? st_text_token(t, &v) : 0;
    if (!nv)
        return hdr_error(p, t->line, "format line needs a kind and a version",
                         NULL, 0);
    if (p->format != F_NONE)
        return hdr_error(p, t->line, "second format line", NULL, 0);
    if (st_tok_eq(k, nk, "ascii"))
        p->format = F_ASCII;
    else if (st_tok_eq(k, nk, "binary_little_endian"))
        p->format = F_LE;
    else if (st_tok_eq(k, nk, "binary_big_endian"))
        p->format = F_BE;
    else
        return hdr_error(p, t->line, "unknown PLY format", k, nk);
    if (!st_tok_eq(v, nv, "1.0") && !st_tok_eq(v, nv, "1"))
        return hdr_error(p, t->line, "unsupported PLY version", v, nv);
    return ST_OK;
}

/* Bytes a record of e needs at the least: binary, the scalars and list
 * counts; ascii, one digit and one separator per value. */
static size_t min_record(const ply *p, const elem *e)
{
    size_t m = 0;
    for (size_t i = 0; i < e->nprops; i++) {
        const prop *pr = &e->props[i];
        if (p->format == F_ASCII)
            m += 2;
        else
            m += type_size(pr->count_type != T_NONE ? pr->count_type
                                                    : pr->type);
    }
    return m;
}

/* Read the header; on success t is at the first byte of the body. */
static st_status read_header(ply *p, st_text *t)
{
    const unsigned char *tok = NULL;
    size_t n = st_text_token(t, &tok);
    if (!st_tok_eq(tok, n, "ply") || !st_text_at_eol(t))
        return hdr_error(p, 1, "not a PLY file (no 'ply' first line)", NULL,
                         0);
    st_text_next_line(t);
    for (;;) {
        if (t->p == t->end)
            return hdr_error(p, st_text_eof_line(t),
                             "file ends in the header (no end_header)", NULL,
                             0);
        st_status st = ST_OK;
        n = st_text_token(t, &tok);
        if (n == 0 || st_tok_eq(tok, n, "comment") ||
            st_tok_eq(tok, n, "obj_info"))
            ; /* blank, comment: nothing to do */
        else if (st_tok_eq(tok, n, "format"))
            st = hdr_format(p, t);
        else if (st_tok_eq(tok, n, "element"))
            st = hdr_element(p, t);
        else if (st_tok_eq(tok, n, "property"))
            st = hdr_property(p, t);
        else if (st_tok_eq(tok, n, "end_header"))
            break;
        else {
            /* Exporters put free text there (Blender 2.4x: "Created by
             * Blender3D 247 - www.blender.org, source file: ..."); assimp
             * and VTK skip it, so do we, saying so. */
            char q[ST_QUOTE_SIZE];
            size_t len = n;
            while (tok + len < t->end && tok[len] != '\n' &&
                   tok[len] != '\r')
                len++;
            st_soup__warn(p->warn, p->name, t->line, -1,
                          "header line without a keyword skipped: '%s'",
                          st_text_quote(q, sizeof q, tok, len));
        }
        if (st)
            return st;
        st_text_next_line(t);
    }
    long long end_line = t->line;
    st_text_next_line(t);

    if (p->format == F_NONE)
        return hdr_error(p, end_line, "no format line", NULL, 0);
    for (size_t i = 0; i < p->nelems; i++) {
        if (p->elems[i].kind == E_VERTEX)
            p->vertex = &p->elems[i];
        else if (p->elems[i].kind == E_FACE)
            p->face = &p->elems[i];
    }
    if (!p->vertex)
        return hdr_error(p, end_line, "no vertex element", NULL, 0);
    static const char *const axis = "xyz";
    for (int r = R_X; r <= R_Z; r++) {
        size_t i = 0;
        while (i < p->vertex->nprops && p->vertex->props[i].role != (prole)r)
            i++;
        if (i == p->vertex->nprops)
            return st_error_set(p->err, ST_EINPUT, p->name, p->vertex->line,
                                "vertex element has no '%c' property",
                                axis[r - R_X]);
    }
    if (!p->face)
        return hdr_error(p, end_line, "no face element", NULL, 0);
    size_t i = 0;
    while (i < p->face->nprops && p->face->props[i].role != R_INDICES)
        i++;
    if (i == p->face->nprops)
        return st_error_set(p->err, ST_EINPUT, p->name, p->face->line,
                            "face element has no vertex_indices list");

    /* The counts are untrusted: every element must fit in the bytes left,
     * at its smallest record size, before the body is walked. */
    size_t body = (size_t)(t->end - t->p);
    size_t room = body + (p->format == F_ASCII ? 1 : 0);
    for (i = 0; i < p->nelems; i++) {
        elem *e = &p->elems[i];
        size_t m = min_record(p, e);
        if (m == 0)
            continue;
        if (e->count > room / m)
            return st_error_set(p->err, ST_EINPUT, p->name, e->line,
                                "header says %llu '%s' records but only %zu "
                                "bytes follow", e->count, e->name, body);
        room -= (size_t)e->count * m;
    }
    if (p->vertex->count > UINT32_MAX)
        return st_error_set(p->err, ST_ELIMIT, p->name, p->vertex->line,
                            "more than 4294967295 vertices");
    return ST_OK;
}

/* ---- binary body -------------------------------------------------------- */

/* The raw bits of a scalar of size sz at q, in host order. */
static uint64_t load_bits(const unsigned char *q, size_t sz, int be)
{
    uint64_t v = 0;
    for (size_t i = 0; i < sz; i++)
        v |= (uint64_t)q[be ? sz - 1 - i : i] << (8 * i);
    return v;
}

static double bits_to_double(uint64_t v, ptype t)
{
    switch (t) {
    case T_I8: return (double)(int8_t)(uint8_t)v;
    case T_U8: return (double)(uint8_t)v;
    case T_I16: return (double)(int16_t)(uint16_t)v;
    case T_U16: return (double)(uint16_t)v;
    case T_I32: return (double)(int32_t)(uint32_t)v;
    case T_U32: return (double)(uint32_t)v;
    case T_F32: {
        uint32_t u = (uint32_t)v;
        float f;
        memcpy(&f, &u, sizeof f);
        return (double)f;
    }
    case T_F64: {
        double d;
        memcpy(&d, &v, sizeof d);
        return d;
    }
    case T_NONE: break;
    }
    return 0.0;
}

static long long bits_to_int(uint64_t v, ptype t)
{
    switch (t) {
    case T_I8: return (int8_t)(uint8_t)v;
    case T_U8: return (uint8_t)v;
    case T_I16: return (int16_t)(uint16_t)v;
    case T_U16: return (uint16_t)v;
    case T_I32: return (int32_t)(uint32_t)v;
    case T_U32: return (uint32_t)v;
    default: break;
    }
    return 0;  /* not reached: the header only allows integer types */
}

static st_status bin_truncated(ply *p, const elem *e,
                               unsigned long long rec, size_t off)
{
    return st_error_set_offset(p->err, ST_EINPUT, p->name, (long long)off,
                               "file ends in element '%s' (record %llu of "
                               "%llu)", e->name, rec + 1, e->count);
}

static st_status read_binary(ply *p, st_soup *s, const unsigned char *data,
                             size_t size, size_t off)
{
    int be = p->format == F_BE;
    unsigned long long nv = p->vertex->count;
    for (size_t ei = 0; ei < p->nelems; ei++) {
        const elem *e = &p->elems[ei];
        if (e->nprops == 0)
            continue;       /* records of no bytes: nothing to step over */
        for (unsigned long long r = 0; r < e->count; r++) {
            double c[3] = {0, 0, 0};
            for (size_t pi = 0; pi < e->nprops; pi++) {
                const prop *pr = &e->props[pi];
                size_t isz = type_size(pr->type);
                if (pr->count_type == T_NONE) {
                    if (size - off < isz)
                        return bin_truncated(p, e, r, off);
                    if (pr->role != R_NONE) {
                        double d = bits_to_double(
                            load_bits(data + off, isz, be), pr->type);
                        if (!isfinite(d))
                            return st_error_set_offset(
                                p->err, ST_EINPUT, p->name, (long long)off,
                                "coordinate is not finite");
                        c[pr->role - R_X] = d;
                    }
                    off += isz;
                    continue;
                }
                size_t csz = type_size(pr->count_type);
                if (size - off < csz)
                    return bin_truncated(p, e, r, off);
                long long cnt = bits_to_int(load_bits(data + off, csz, be),
                                            pr->count_type);
                if (cnt < 0)
                    return st_error_set_offset(
                        p->err, ST_EINPUT, p->name, (long long)off,
                        "negative list length %lld", cnt);
                size_t list_off = off;
                off += csz;
                if ((unsigned long long)cnt > (size - off) / isz)
                    return bin_truncated(p, e, r, off);
                if (pr->role != R_INDICES) {
                    off += (size_t)cnt * isz;
                    continue;
                }
                if (cnt < 3)
                    return st_error_set_offset(
                        p->err, ST_EINPUT, p->name, (long long)list_off,
                        "face has %lld %s (need at least 3)", cnt,
                        cnt == 1 ? "vertex" : "vertices");
                uint32_t first = 0, prev = 0;
                for (long long k = 0; k < cnt; k++, off += isz) {
                    long long idx =
                        bits_to_int(load_bits(data + off, isz, be), pr->type);
                    if (idx < 0 || (unsigned long long)idx >= nv)
                        return st_error_set_offset(
                            p->err, ST_EINPUT, p->name, (long long)off,
                            "face index %lld out of range (file has %llu "
                            "vertices)", idx, nv);
                    uint32_t v = (uint32_t)idx;
                    if (k == 0) {
                        first = v;
                    } else if (k >= 2) {
                        st_status st = st_soup__push_tri(s, first, prev, v);
                        if (st)
                            return st_soup__push_failed(p->err, st, p->name,
                                                        0, (long long)off);
                    }
                    prev = v;
                }
            }
            if (e->kind == E_VERTEX) {
                st_status st = st_soup__push_vertex(s, c[0], c[1], c[2]);
                if (st)
                    return st_soup__push_failed(p->err, st, p->name, 0,
                                                (long long)off);
            }
        }
    }
    /* Bytes after the last element are ignored. */
    return ST_OK;
}

/* ---- ascii body --------------------------------------------------------- */

static st_status asc_truncated(ply *p, const st_text *t, const elem *e,
                               unsigned long long rec)
{
    return st_error_set(p->err, ST_EINPUT, p->name, st_text_eof_line(t),
                        "file ends in element '%s' (record %llu of %llu)",
                        e->name, rec + 1, e->count);
}

static st_status asc_int(ply *p, st_text *t, const unsigned char *tok,
                         size_t n, long long *v, const char *what)
{
    if (st_text_int(tok, n, v) == 0)
        return ST_OK;
    return hdr_error(p, t->line, what, tok, n);
}

static st_status read_ascii(ply *p, st_soup *s, st_text *t)
{
    unsigned long long nv = p->vertex->count;
    for (size_t ei = 0; ei < p->nelems; ei++) {
        const elem *e = &p->elems[ei];
        if (e->nprops == 0)
            continue;
        for (unsigned long long r = 0; r < e->count; r++) {
            double c[3] = {0, 0, 0};
            for (size_t pi = 0; pi < e->nprops; pi++) {
                const prop *pr = &e->props[pi];
                const unsigned char *tok;
                size_t n = st_text_token_any(t, &tok);
                if (!n)
                    return asc_truncated(p, t, e, r);
                if (pr->count_type == T_NONE) {
                    if (pr->role == R_NONE)
                        continue;
                    double d;
                    if (st_text_double(tok, n, &d) != 0)
                        return hdr_error(p, t->line, "bad coordinate", tok,
                                         n);
                    if (!isfinite(d))
                        return hdr_error(p, t->line,
                                         "coordinate is not finite", NULL, 0);
                    c[pr->role - R_X] = d;
                    continue;
                }
                long long cnt;
                st_status st = asc_int(p, t, tok, n, &cnt, "bad list length");
                if (st)
                    return st;
                if (cnt < 0)
                    return st_error_set(p->err, ST_EINPUT, p->name, t->line,
                                        "negative list length %lld", cnt);
                if (pr->role == R_INDICES && cnt < 3)
                    return st_error_set(p->err, ST_EINPUT, p->name, t->line,
                                        "face has %lld %s (need at least 3)",
                                        cnt, cnt == 1 ? "vertex" : "vertices");
                uint32_t first = 0, prev = 0;
                /* Bounded by the tokens actually there, not by cnt. */
                for (long long k = 0; k < cnt; k++) {
                    n = st_text_token_any(t, &tok);
                    if (!n)
                        return asc_truncated(p, t, e, r);
                    if (pr->role != R_INDICES)
                        continue;
                    long long idx;
                    if ((st = asc_int(p, t, tok, n, &idx, "bad face index")))
                        return st;
                    if (idx < 0 || (unsigned long long)idx >= nv)
                        return st_error_set(p->err, ST_EINPUT, p->name,
                                            t->line,
                                            "face index %lld out of range "
                                            "(file has %llu vertices)",
                                            idx, nv);
                    uint32_t v = (uint32_t)idx;
                    if (k == 0) {
                        first = v;
                    } else if (k >= 2) {
                        st = st_soup__push_tri(s, first, prev, v);
                        if (st)
                            return st_soup__push_failed(p->err, st, p->name,
                                                        t->line, -1);
                    }
                    prev = v;
                }
            }
            if (e->kind == E_VERTEX) {
                st_status st = st_soup__push_vertex(s, c[0], c[1], c[2]);
                if (st)
                    return st_soup__push_failed(p->err, st, p->name, t->line,
                                                -1);
            }
        }
    }
    return ST_OK;
}

st_status st_soup__parse_ply(st_soup *s, const unsigned char *data,
                             size_t size, const char *name,
                             st_soup_warnings *warn, st_error *err)
{
    ply p;
    memset(&p, 0, sizeof p);
    p.name = name;
    p.warn = warn;
    p.err = err;
    st_text t;
    st_text_init(&t, data, size, 0);
    st_status st = read_header(&p, &t);
    if (st == ST_OK) {
        if (p.format == F_ASCII)
            st = read_ascii(&p, s, &t);
        else
            st = read_binary(&p, s, data, size, (size_t)(t.p - data));
    }
    free_ply(&p);
    return st;
}
