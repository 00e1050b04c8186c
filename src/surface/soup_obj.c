/*
 * soup_obj.c - the Wavefront OBJ reader.
 *
 * Takes `v x y z [w ...]` and `f` records (i, i/t, i//n, i/t/n, negative
 * relative indices, polygons fanned from their first vertex). The names
 * of `o` and `g` lines are noted as named runs (soup.h, st_soup_name);
 * everything else -- vn, vt, l, p, s, mtllib, usemtl, unknown statements,
 * comments -- is skipped, and all groups and objects form one soup. CRLF
 * line ends and backslash line continuations are handled by the st_text
 * cursor.
 */
#include "../base/lexer.h"
#include "soup_internal.h"
#include "soupread.h"
#include "../base/fpenv.h"

#include <math.h>
#include <string.h>

/* Read the three coordinates of a `v` record (more values are ignored). */
static st_status read_vertex(st_soup *s, st_text *t, const char *name,
                             st_error *err)
{
    double c[3];
    for (int k = 0; k < 3; k++) {
        const unsigned char *tok;
        size_t n = st_text_token(t, &tok);
        if (!n)
            return st_error_set(err, ST_EINPUT, name, t->line,
                                "vertex has %d coordinate%s (need 3)", k,
                                k == 1 ? "" : "s");
        if (st_text_double(tok, n, &c[k]) != 0) {
            char q[ST_QUOTE_SIZE];
            return st_error_set(err, ST_EINPUT, name, t->line,
                                "bad coordinate '%s'",
                                st_text_quote(q, sizeof q, tok, n));
        }
        if (!isfinite(c[k]))
            return st_error_set(err, ST_EINPUT, name, t->line,
                                "coordinate is not finite");
    }
    st_status st = st_soup__push_vertex(s, c[0], c[1], c[2]);
    return st ? st_soup__push_failed(err, st, name, t->line, -1) : ST_OK;
}

/* The tail of a face vertex after its index ("/t", "//n", "/t/n"). */
static int valid_tail(const unsigned char *p, size_t n)
{
    for (size_t i = 0; i < n; i++)
        if (!(p[i] == '/' || p[i] == '-' || p[i] == '+' ||
              (p[i] >= '0' && p[i] <= '9')))
            return 0;
    return 1;
}

/* Forward references: a positive index may name a vertex defined later in
 * the file, so it is only checked at the end; the largest one and its line
 * are enough to report the problem. */
typedef struct fwd_ref {
    long long max;  /* largest 1-based index seen beyond the vertices read */
    long long line;
} fwd_ref;

/* Read an `f` record and fan it into triangles. */
static st_status read_face(st_soup *s, st_text *t, fwd_ref *fwd,
                           const char *name, st_error *err)
{
    uint32_t first = 0, prev = 0;
    long long count = 0;
    const unsigned char *tok;
    size_t n;
    while ((n = st_text_token(t, &tok)) != 0) {
        char q[ST_QUOTE_SIZE];
        size_t il = 0;
        while (il < n && tok[il] != '/')
            il++;
        long long idx;
        if (st_text_int(tok, il, &idx) != 0 ||
            !valid_tail(tok + il, n - il))
            return st_error_set(err, ST_EINPUT, name, t->line,
                                "bad face vertex '%s'",
                                st_text_quote(q, sizeof q, tok, n));
        uint32_t v;
        if (idx == 0)
            return st_error_set(err, ST_EINPUT, name, t->line,
                                "face index 0 (OBJ indices start at 1)");
        if (idx < 0) {
            /* -1 is the last vertex read so far. */
            if (idx < -(long long)s->nverts)
                return st_error_set(err, ST_EINPUT, name, t->line,
                                    "face index %lld out of range (%zu "
                                    "vertices so far)", idx, s->nverts);
            v = (uint32_t)((long long)s->nverts + idx);
        } else {
            if (idx > (long long)UINT32_MAX)
                return st_error_set(err, ST_EINPUT, name, t->line,
                                    "face index %lld out of range", idx);
            v = (uint32_t)(idx - 1);
            if (v >= s->nverts && idx > fwd->max) {
                fwd->max = idx;
                fwd->line = t->line;
            }
        }
        if (count == 0) {
            first = v;
        } else if (count >= 2) {
            st_status st = st_soup__push_tri(s, first, prev, v);
            if (st)
                return st_soup__push_failed(err, st, name, t->line, -1);
        }
        prev = v;
        count++;
    }
    if (count < 3)
        return st_error_set(err, ST_EINPUT, name, t->line,
                            "face has %lld %s (need at least 3)", count,
                            count == 1 ? "vertex" : "vertices");
    return ST_OK;
}

/* A file that gave no triangles: when it is not OBJ text at all (a
 * binary file, another format renamed .obj), say so rather than "no
 * triangles". Text is what an OBJ may hold: printable bytes, tabs, line
 * ends, form feeds, and UTF-8 (bytes >= 0x80, in comments and names);
 * a NUL or another control byte in the first 64 KiB says binary. A text
 * with no v or f record also is not an OBJ. Returns ST_OK when the file
 * is an OBJ without faces (the caller's "no triangles"). */
static st_status not_obj_text(const unsigned char *data, size_t size, size_t nverts,
                              const char *name, st_error *err)
{
    const size_t n = size < 65536 ? size : 65536;
    for (size_t i = 0; i < n; i++) {
        const unsigned char c = data[i];
        if (c < 0x20 && c != '\t' && c != '\n' && c != '\r' && c != '\f' && c != '\v')
            return st_error_set_offset(err, ST_EINPUT, name, (long long)i,
                                       "not OBJ text: a binary byte, 0x%02x (a mesh in "
                                       "another format renamed .obj?)", c);
    }
    if (nverts == 0)
        return st_error_set(err, ST_EINPUT, name, 0,
                            "not an OBJ file: no 'v' or 'f' record");
    return ST_OK;
}

st_status st_soup__parse_obj(st_soup *s, const unsigned char *data,
                             size_t size, const char *name, st_error *err)
{
    st_text t;
    st_text_init(&t, data, size, ST_TEXT_HASH | ST_TEXT_CONT);
    fwd_ref fwd = {0, 0};
    while (t.p < t.end) {
        const unsigned char *kw;
        size_t n = st_text_token(&t, &kw);
        st_status st = ST_OK;
        if (n == 1 && kw[0] == 'v')
            st = read_vertex(s, &t, name, err);
        else if (n == 1 && kw[0] == 'f')
            st = read_face(s, &t, &fwd, name, err);
        else if (n == 1 && (kw[0] == 'o' || kw[0] == 'g')) {
            /* A part's name (parts.h): objects, or groups where the file
             * has no objects. */
            const unsigned char *nm;
            size_t nl = st_text_rest(&t, &nm);
            st = st_soup__push_name(s, kw[0] == 'o' ? 1 : 2, nm, nl);
            if (st)
                return st_soup__push_failed(err, st, name, t.line, -1);
        }
        if (st)
            return st;
        st_text_next_line(&t);
    }
    if (fwd.max > (long long)s->nverts)
        return st_error_set(err, ST_EINPUT, name, fwd.line,
                            "face index %lld out of range (file has %zu "
                            "vertices)", fwd.max, s->nverts);
    if (s->ntris == 0)
        return not_obj_text(data, size, s->nverts, name, err);
    return ST_OK;
}
