/*
 * soup_off.c - the OFF reader (Geomview Object File Format, ASCII).
 *
 *   [ST][C][N]OFF [V F E]
 *   V F E                      (if not on the keyword line)
 *   x y z [anything]           V vertex lines (colours, normals ignored)
 *   n i0 ... i(n-1) [colour]   F face lines, fanned from i0
 *
 * '#' starts a comment anywhere; blank lines are skipped. The counts are
 * untrusted: they are checked against the bytes that follow and nothing is
 * allocated from them (the soup grows with the records actually read).
 */
#include "../base/lexer.h"
#include "soup_internal.h"
#include "soupread.h"
#include "../base/fpenv.h"

#include <math.h>
#include <string.h>

/* The shortest records: "0 0 0\n" and "3 0 0 0\n". The last record may
 * lack its newline, hence the +1 where these are used. */
#define MIN_VERTEX_BYTES 6
#define MIN_FACE_BYTES 8

static st_status bad(st_error *err, const char *name, long long line,
                     const char *what, const unsigned char *tok, size_t n)
{
    char q[ST_QUOTE_SIZE];
    return st_error_set(err, ST_EINPUT, name, line, "%s '%s'", what,
                        st_text_quote(q, sizeof q, tok, n));
}

/* Check the keyword: [ST][C][N]OFF. */
static st_status read_keyword(st_text *t, const char *name, st_error *err)
{
    const unsigned char *tok;
    size_t n = st_text_token_any(t, &tok);
    if (!n)
        return st_error_set(err, ST_EINPUT, name, st_text_eof_line(t),
                            "no OFF header");
    size_t i = 0;
    if (n >= 2 && tok[0] == 'S' && tok[1] == 'T')
        i += 2;
    if (i < n && tok[i] == 'C')
        i++;
    if (i < n && tok[i] == 'N')
        i++;
    if (n - i == 4 && (tok[i] == '4' || tok[i] == 'n') &&
        memcmp(tok + i + 1, "OFF", 3) == 0)
        return bad(err, name, t->line, "unsupported OFF variant", tok, n);
    if (n - i != 3 || memcmp(tok + i, "OFF", 3) != 0)
        return bad(err, name, t->line, "expected an OFF header, found", tok,
                   n);
    const unsigned char *p = t->p;
    long long line = t->line;
    size_t m = st_text_token(t, &tok);
    if (m && st_tok_ieq(tok, m, "binary"))
        return st_error_set(err, ST_EINPUT, name, t->line,
                            "binary OFF is not supported");
    t->p = p;   /* not BINARY: the counts, read again below */
    t->line = line;
    return ST_OK;
}

/* A non-negative count; `tok` may be absent (n == 0). */
static st_status read_count(st_text *t, const unsigned char *tok, size_t n,
                            long long *out, const char *name, st_error *err)
{
    if (!n)
        return st_error_set(err, ST_EINPUT, name, st_text_eof_line(t),
                            "missing vertex and face counts");
    if (st_text_int(tok, n, out) != 0 || *out < 0)
        return bad(err, name, t->line, "bad count", tok, n);
    return ST_OK;
}

st_status st_soup__parse_off(st_soup *s, const unsigned char *data,
                             size_t size, const char *name, st_error *err)
{
    st_text t;
    st_text_init(&t, data, size, ST_TEXT_HASH);
    st_status st = read_keyword(&t, name, err);
    if (st)
        return st;

    /* Counts "V F [E]": V and F may be on the keyword line or after it. */
    long long nv, nf, ne;
    const unsigned char *tok;
    size_t n = st_text_token_any(&t, &tok);
    if ((st = read_count(&t, tok, n, &nv, name, err)))
        return st;
    n = st_text_token_any(&t, &tok);
    if ((st = read_count(&t, tok, n, &nf, name, err)))
        return st;
    long long counts_line = t.line;
    n = st_text_token(&t, &tok);
    if (n && (st = read_count(&t, tok, n, &ne, name, err)))
        return st;      /* E is checked but not used */
    st_text_next_line(&t);

    /* Never believe a count the bytes cannot back: 10^12 vertices in a
     * small file is an error now, not an allocation or a long loop. */
    size_t rem = (size_t)(t.end - t.p) + 1;
    if ((unsigned long long)nv > rem / MIN_VERTEX_BYTES ||
        (unsigned long long)nf >
            (rem - (size_t)nv * MIN_VERTEX_BYTES) / MIN_FACE_BYTES)
        return st_error_set(err, ST_EINPUT, name, counts_line,
                            "header says %lld vertices and %lld faces but "
                            "only %zu bytes follow", nv, nf, rem - 1);
    if (nv > (long long)UINT32_MAX)
        return st_error_set(err, ST_ELIMIT, name, counts_line,
                            "more than 4294967295 vertices");

    for (long long i = 0; i < nv; i++) {
        n = st_text_token_any(&t, &tok);
        if (!n)
            return st_error_set(err, ST_EINPUT, name, st_text_eof_line(&t),
                                "header says %lld vertices, file ends after "
                                "%lld", nv, i);
        double c[3];
        for (int k = 0; k < 3; k++) {
            if (k > 0 && !(n = st_text_token(&t, &tok)))
                return st_error_set(err, ST_EINPUT, name, t.line,
                                    "vertex has %d coordinate%s (need 3)",
                                    k, k == 1 ? "" : "s");
            if (st_text_double(tok, n, &c[k]) != 0)
                return bad(err, name, t.line, "bad coordinate", tok, n);
            if (!isfinite(c[k]))
                return st_error_set(err, ST_EINPUT, name, t.line,
                                    "coordinate is not finite");
        }
        if ((st = st_soup__push_vertex(s, c[0], c[1], c[2])))
            return st_soup__push_failed(err, st, name, t.line, -1);
        st_text_next_line(&t);
    }

    for (long long f = 0; f < nf; f++) {
        n = st_text_token_any(&t, &tok);
        if (!n)
            return st_error_set(err, ST_EINPUT, name, st_text_eof_line(&t),
                                "header says %lld faces, file ends after "
                                "%lld", nf, f);
        long long cnt;
        if (st_text_int(tok, n, &cnt) != 0)
            return bad(err, name, t.line, "bad face vertex count", tok, n);
        if (cnt < 3)
            return st_error_set(err, ST_EINPUT, name, t.line,
                                "face has %lld %s (need at least 3)", cnt,
                                cnt == 1 ? "vertex" : "vertices");
        uint32_t first = 0, prev = 0;
        for (long long k = 0; k < cnt; k++) {
            if (!(n = st_text_token(&t, &tok)))
                return st_error_set(err, ST_EINPUT, name, t.line,
                                    "face lists %lld of its %lld vertices",
                                    k, cnt);
            long long idx;
            if (st_text_int(tok, n, &idx) != 0)
                return bad(err, name, t.line, "bad face index", tok, n);
            if (idx < 0 || idx >= nv)
                return st_error_set(err, ST_EINPUT, name, t.line,
                                    "face index %lld out of range (file has "
                                    "%lld vertices)", idx, nv);
            uint32_t v = (uint32_t)idx;
            if (k == 0) {
                first = v;
            } else if (k >= 2) {
                if ((st = st_soup__push_tri(s, first, prev, v)))
                    return st_soup__push_failed(err, st, name, t.line, -1);
            }
            prev = v;
        }
        st_text_next_line(&t);   /* optional colour values */
    }
    /* Edges and anything after the faces are not needed. */
    return ST_OK;
}
