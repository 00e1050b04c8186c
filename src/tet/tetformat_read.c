/*
 * tetformat_read.c - the tet readers' shared reading state and helpers
 * (tetformat_read.h).
 */
#include "tetformat_read.h"
#include "../base/fpenv.h"
#include "souptet/meta.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

st_status st_rd_fail_at(rd *r, st_status st, const unsigned char *at,
                     const char *fmt, ...)
{
    char msg[RD_MSG];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    if (r->binary)
        return st_error_set_offset(r->err, st, r->name,
                                   (long long)(at - r->t.begin), "%s", msg);
    long long line = at >= r->t.end ? st_text_eof_line(&r->t) : r->t.line;
    return st_error_set(r->err, st, r->name, line, "%s", msg);
}

/* The mesh memory max_bytes allows: 24 bytes a point, 16 a tet. */
st_status st_rd_room(rd *r, size_t extra_points, size_t extra_tets)
{
    if (!r->max_bytes)
        return ST_OK;
    double need = 24.0 * (double)(r->m->npoints + extra_points) +
                  16.0 * (double)(r->m->ntets + extra_tets);
    if (need > (double)r->max_bytes)
        return st_rd_fail_at(r, ST_ELIMIT, r->t.p,
                          "the mesh needs more than the %zu bytes allowed",
                          r->max_bytes);
    return ST_OK;
}

/* A point p or a tet v (the other NULL), within max_bytes. */
static st_status rd_add(rd *r, const double *p, const uint32_t *v)
{
    st_status s = st_rd_room(r, p ? 1 : 0, p ? 0 : 1);
    if (s)
        return s;
    st_error e;
    st_error_clear(&e);
    s = p ? st_tetmesh_add_point(r->m, p, &e)
          : st_tetmesh_add_tet(r->m, v[0], v[1], v[2], v[3], &e);
    if (s)
        return st_rd_fail_at(r, s, r->t.p, "%s", e.msg);
    return ST_OK;
}

st_status st_rd_point(rd *r, const double p[3])
{
    return rd_add(r, p, NULL);
}

st_status st_rd_tet(rd *r, const uint32_t v[4])
{
    return rd_add(r, NULL, v);
}

/* The next token anywhere (text); fails with "what" at the end. */
st_status st_rd_token(rd *r, const unsigned char **tok, size_t *n,
                   const char *what)
{
    *n = st_text_token_any(&r->t, tok);
    if (!*n)
        return rd_fail(r, "file ends before %s", what);
    return ST_OK;
}

/* The next token as an integer (iv) or a double (dv), the other NULL. */
static st_status rd_number(rd *r, const char *what, long long *iv, double *dv)
{
    const unsigned char *tok = NULL;
    size_t n;
    st_status s = st_rd_token(r, &tok, &n, what);
    if (s)
        return s;
    if (iv ? st_text_int(tok, n, iv) : st_text_double(tok, n, dv)) {
        char q[ST_QUOTE_SIZE];
        return rd_fail(r, "bad %s '%s'", what,
                       st_text_quote(q, sizeof q, tok, n));
    }
    return ST_OK;
}

st_status st_rd_int(rd *r, long long *v, const char *what)
{
    return rd_number(r, what, v, NULL);
}

/* An integer in [lo, hi]. */
st_status st_rd_int_in(rd *r, long long *v, long long lo, long long hi,
                    const char *what)
{
    st_status s = st_rd_int(r, v, what);
    if (s)
        return s;
    if (*v < lo || *v > hi)
        return rd_fail(r, "%s %lld out of range", what, *v);
    return ST_OK;
}

st_status st_rd_double(rd *r, double *v, const char *what)
{
    st_status s = rd_number(r, what, NULL, v);
    if (s)
        return s;
    if (!isfinite(*v))
        return rd_fail(r, "%s is not finite", what);
    return ST_OK;
}

st_status st_rd_xyz(rd *r, double p[3])
{
    for (int k = 0; k < 3; k++) {
        st_status s = st_rd_double(r, &p[k], "coordinate");
        if (s)
            return s;
    }
    return ST_OK;
}

/* Bytes left after the cursor. */
size_t st_rd_left(const rd *r)
{
    return (size_t)(r->t.end - r->t.p);
}

/* A header's count of records of at least min_bytes each must fit. */
st_status st_rd_count_fits(rd *r, unsigned long long count, size_t min_bytes,
                        const char *what)
{
    size_t left = st_rd_left(r) + 1;  /* the last record may lack its '\n' */
    if (min_bytes && count > left / min_bytes)
        return rd_fail(r, "header says %llu %s but only %zu bytes follow",
                       count, what, st_rd_left(r));
    return ST_OK;
}

/* Move the text cursor to q, counting the lines passed. */
void st_rd_jump(rd *r, const unsigned char *q)
{
    for (const unsigned char *p = r->t.p; p < q; p++)
        if (*p == '\n')
            r->t.line++;
    r->t.p = q;
}

/* Metadata from a "souptet KEY: VALUE" comment line [s, e): a repeated key
 * continues its value on a new line (history). Values grow by doubling,
 * so a file of many history lines costs linear time. */
st_status st_rd_meta_line(rd *r, const unsigned char *s, const unsigned char *e)
{
    static const char tag[] = "souptet ";
    while (s < e && st_text_blank(*s))
        s++;
    while (e > s && st_text_blank(e[-1]))
        e--;
    size_t n = (size_t)(e - s);
    if (n < sizeof tag - 1 || memcmp(s, tag, sizeof tag - 1) != 0)
        return ST_OK;
    s += sizeof tag - 1;
    const unsigned char *colon = memchr(s, ':', (size_t)(e - s));
    if (!colon || colon == s)
        return ST_OK;
    size_t kn = (size_t)(colon - s);
    const unsigned char *v = colon + 1;
    if (v < e && *v == ' ')
        v++;
    size_t vn = (size_t)(e - v);
    mval *mv = NULL;
    for (size_t i = 0; i < r->nmeta && !mv; i++)
        if (strlen(r->meta[i].key) == kn && memcmp(r->meta[i].key, s, kn) == 0)
            mv = &r->meta[i];
    if (!mv) {
        if (r->nmeta == RD_MAX_KEYS)
            return ST_OK;
        mv = &r->meta[r->nmeta];
        memset(mv, 0, sizeof *mv);
        mv->key = malloc(kn + 1);
        if (!mv->key)
            return st_rd_fail_at(r, ST_ENOMEM, r->t.p, "out of memory");
        memcpy(mv->key, s, kn);
        mv->key[kn] = '\0';
        r->nmeta++;
    }
    size_t need = mv->len + (mv->lines ? 1 : 0) + vn + 1;
    if (need > mv->cap) {
        size_t nc = mv->cap ? mv->cap : 64;
        while (nc < need)
            nc *= 2;
        char *nv = realloc(mv->val, nc);
        if (!nv)
            return st_rd_fail_at(r, ST_ENOMEM, r->t.p, "out of memory");
        mv->val = nv;
        mv->cap = nc;
    }
    if (mv->lines)
        mv->val[mv->len++] = '\n';
    memcpy(mv->val + mv->len, v, vn);
    mv->len += vn;
    mv->val[mv->len] = '\0';
    mv->lines++;
    return ST_OK;
}

/* Move the collected values into the mesh's meta. */
st_status st_rd_meta_flush(rd *r)
{
    for (size_t i = 0; i < r->nmeta; i++)
        if (st_meta_set(&r->m->meta, r->meta[i].key, r->meta[i].val))
            return st_error_set(r->err, ST_ENOMEM, r->name, 0,
                                "out of memory");
    return ST_OK;
}

void st_rd_meta_free(rd *r)
{
    for (size_t i = 0; i < r->nmeta; i++) {
        free(r->meta[i].key);
        free(r->meta[i].val);
    }
    r->nmeta = 0;
}

/* The start of every reader: r cleared, errors to err, meshes of
 * max_bytes at most, and an empty mesh (out of memory named NAME). */
st_status st_rd_begin(rd *r, size_t max_bytes, st_error *err, const char *name)
{
    memset(r, 0, sizeof *r);
    r->err = err;
    r->max_bytes = max_bytes;
    r->m = st_tetmesh_new();
    return r->m ? ST_OK : st_error_set(err, ST_ENOMEM, name, 0, "out of memory");
}

/* The end of every reader, after the parse's status s: the collected
 * meta into the mesh, then the mesh into *out (ST_OK), or freed (the
 * error returned). */
st_status st_rd_finish(rd *r, st_status s, st_tetmesh **out)
{
    if (!s)
        s = st_rd_meta_flush(r);
    st_rd_meta_free(r);
    if (s) {
        st_tetmesh_free(r->m);
        r->m = NULL;
        return s;
    }
    *out = r->m;
    return ST_OK;
}

/* Every "# souptet KEY: VALUE" line of a '#'-commented text file. */
st_status st_rd_hash_meta(rd *r)
{
    const unsigned char *p = r->t.begin, *end = r->t.end;
    while (p < end) {
        const unsigned char *q, *e, *next = st_text_line(p, end, &q, &e);
        if (q < e && *q == '#') {
            st_status s = st_rd_meta_line(r, q + 1, e);
            if (s)
                return s;
        }
        p = next;
    }
    return ST_OK;
}
