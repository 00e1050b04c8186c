/*
 * tetformat_internal.h - what the files of the tetformat module share
 * (tetformat.c, tetformat_msh.c, tetformat_tetgen.c, tetformat_medit.c):
 * the reading state over a file held in memory, with its helpers (static
 * inline, as soup_parse.h's), and the helpers one file defines for the
 * others. Not installed.
 */
#ifndef SOUPTET_TETFORMAT_INTERNAL_H
#define SOUPTET_TETFORMAT_INTERNAL_H

#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "souptet/err.h"
#include "souptet/meta.h"
#include "souptet/tetformat.h"
#include "souptet/tetmesh.h"
#include "soup_parse.h"

/* ---- shared parsing state ------------------------------------------------ */

/* A meta value being collected from comment lines. */
typedef struct mval {
    char *key, *val;
    size_t len, cap, lines;
} mval;

/* Distinct meta keys kept from one file: more are ignored (each lookup
 * is a linear search). */
#define RD_MAX_KEYS 64

typedef struct rd {
    st_text t;
    const char *name;
    st_error *err;
    int binary;          /* errors at byte offsets instead of lines */
    size_t max_bytes;
    st_tetmesh *m;
    mval meta[RD_MAX_KEYS];
    size_t nmeta;
} rd;

#define RD_MSG 400

static inline st_status rd_fail_at(rd *r, st_status st, const unsigned char *at,
                            const char *fmt, ...)
#ifdef __GNUC__
    __attribute__((format(printf, 4, 5)))
#endif
    ;

static inline st_status rd_fail_at(rd *r, st_status st, const unsigned char *at,
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

#define rd_fail(r, ...) rd_fail_at((r), ST_EINPUT, (r)->t.p, __VA_ARGS__)

/* The mesh memory max_bytes allows: 24 bytes a point, 16 a tet. */
static inline st_status rd_room(rd *r, size_t extra_points, size_t extra_tets)
{
    if (!r->max_bytes)
        return ST_OK;
    double need = 24.0 * (double)(r->m->npoints + extra_points) +
                  16.0 * (double)(r->m->ntets + extra_tets);
    if (need > (double)r->max_bytes)
        return rd_fail_at(r, ST_ELIMIT, r->t.p,
                          "the mesh needs more than the %zu bytes allowed",
                          r->max_bytes);
    return ST_OK;
}

static inline st_status rd_point(rd *r, const double p[3])
{
    st_status s = rd_room(r, 1, 0);
    if (s)
        return s;
    st_error e;
    st_error_clear(&e);
    s = st_tetmesh_add_point(r->m, p, &e);
    if (s)
        return rd_fail_at(r, s, r->t.p, "%s", e.msg);
    return ST_OK;
}

static inline st_status rd_tet(rd *r, const uint32_t v[4])
{
    st_status s = rd_room(r, 0, 1);
    if (s)
        return s;
    st_error e;
    st_error_clear(&e);
    s = st_tetmesh_add_tet(r->m, v[0], v[1], v[2], v[3], &e);
    if (s)
        return rd_fail_at(r, s, r->t.p, "%s", e.msg);
    return ST_OK;
}

/* The next token anywhere (text); fails with "what" at the end. */
static inline st_status rd_token(rd *r, const unsigned char **tok, size_t *n,
                          const char *what)
{
    *n = st_text_token_any(&r->t, tok);
    if (!*n)
        return rd_fail(r, "file ends before %s", what);
    return ST_OK;
}

static inline st_status rd_int(rd *r, long long *v, const char *what)
{
    const unsigned char *tok = NULL;
    size_t n;
    st_status s = rd_token(r, &tok, &n, what);
    if (s)
        return s;
    if (st_soup__scan_int(tok, n, v) != 0) {
        char q[ST_QUOTE_SIZE];
        return rd_fail(r, "bad %s '%s'", what,
                       st_soup__quote(q, sizeof q, tok, n));
    }
    return ST_OK;
}

/* An integer in [lo, hi]. */
static inline st_status rd_int_in(rd *r, long long *v, long long lo, long long hi,
                           const char *what)
{
    st_status s = rd_int(r, v, what);
    if (s)
        return s;
    if (*v < lo || *v > hi)
        return rd_fail(r, "%s %lld out of range", what, *v);
    return ST_OK;
}

static inline st_status rd_double(rd *r, double *v, const char *what)
{
    const unsigned char *tok = NULL;
    size_t n;
    st_status s = rd_token(r, &tok, &n, what);
    if (s)
        return s;
    if (st_soup__scan_double(tok, n, v) != 0) {
        char q[ST_QUOTE_SIZE];
        return rd_fail(r, "bad %s '%s'", what,
                       st_soup__quote(q, sizeof q, tok, n));
    }
    if (!isfinite(*v))
        return rd_fail(r, "%s is not finite", what);
    return ST_OK;
}

static inline st_status rd_xyz(rd *r, double p[3])
{
    for (int k = 0; k < 3; k++) {
        st_status s = rd_double(r, &p[k], "coordinate");
        if (s)
            return s;
    }
    return ST_OK;
}

/* Bytes left after the cursor. */
static inline size_t rd_left(const rd *r)
{
    return (size_t)(r->t.end - r->t.p);
}

/* A header's count of records of at least min_bytes each must fit. */
static inline st_status rd_count_fits(rd *r, unsigned long long count,
                               size_t min_bytes, const char *what)
{
    size_t left = rd_left(r) + 1;  /* the last record may lack its '\n' */
    if (min_bytes && count > left / min_bytes)
        return rd_fail(r, "header says %llu %s but only %zu bytes follow",
                       count, what, rd_left(r));
    return ST_OK;
}

/* Move the text cursor to q, counting the lines passed. */
static inline void rd_jump(rd *r, const unsigned char *q)
{
    for (const unsigned char *p = r->t.p; p < q; p++)
        if (*p == '\n')
            r->t.line++;
    r->t.p = q;
}

/* Metadata from a "souptet KEY: VALUE" comment line [s, e): a repeated key
 * continues its value on a new line (history). Values grow by doubling,
 * so a file of many history lines costs linear time. */
static inline st_status rd_meta_line(rd *r, const unsigned char *s,
                              const unsigned char *e)
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
            return rd_fail_at(r, ST_ENOMEM, r->t.p, "out of memory");
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
            return rd_fail_at(r, ST_ENOMEM, r->t.p, "out of memory");
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
static inline st_status rd_meta_flush(rd *r)
{
    for (size_t i = 0; i < r->nmeta; i++)
        if (st_meta_set(&r->m->meta, r->meta[i].key, r->meta[i].val))
            return st_error_set(r->err, ST_ENOMEM, r->name, 0,
                                "out of memory");
    return ST_OK;
}

static inline void rd_meta_free(rd *r)
{
    for (size_t i = 0; i < r->nmeta; i++) {
        free(r->meta[i].key);
        free(r->meta[i].val);
    }
    r->nmeta = 0;
}

/* The start of every reader: r cleared, errors to err, meshes of
 * max_bytes at most, and an empty mesh (out of memory named NAME). */
static inline st_status rd_begin(rd *r, size_t max_bytes, st_error *err, const char *name)
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
static inline st_status rd_finish(rd *r, st_status s, st_tetmesh **out)
{
    if (!s)
        s = rd_meta_flush(r);
    rd_meta_free(r);
    if (s) {
        st_tetmesh_free(r->m);
        r->m = NULL;
        return s;
    }
    *out = r->m;
    return ST_OK;
}

/* Every "# souptet KEY: VALUE" line of a '#'-commented text file. */
static inline st_status rd_hash_meta(rd *r)
{
    const unsigned char *p = r->t.begin, *end = r->t.end;
    while (p < end) {
        const unsigned char *nl = memchr(p, '\n', (size_t)(end - p));
        const unsigned char *e = nl ? nl : end;
        const unsigned char *q = p;
        while (q < e && st_text_blank(*q))
            q++;
        if (q < e && *q == '#') {
            st_status s = rd_meta_line(r, q + 1, e);
            if (s)
                return s;
        }
        p = nl ? nl + 1 : end;
    }
    return ST_OK;
}

/* ---- defined in one file, used by others ------------------------------- */

/* base.node and base.ele for a TetGen path (.node, .ele or a base name);
 * malloc'd. (tetformat.c) */
st_status st_tf_tetgen_names(const char *path, char **node, char **ele,
                             st_error *err);

/* Read the file path whole and parse it with parse (one of
 * st_tetmesh_parse_msh, _medit). (tetformat.c) */
typedef st_status (*st_tf_parser)(st_tetmesh **, const unsigned char *,
                                  size_t, const char *, size_t, st_error *);
st_status st_tf_read_with(st_tf_parser parse, st_tetmesh **out,
                          const char *path, size_t max_bytes, st_error *err);

/* Writing (tetformat.c): meta entries as "PREFIXsouptet KEY: LINE" lines;
 * the msh version normalised (41 or 22; -1: not one); what no file of
 * format f can hold; open a file for writing; flush, close and report. */
void st_tf_put_meta(FILE *fp, const st_meta *meta, const char *prefix);
/* The mesh's parts (parts.h: the cell array "part", meta "parts" and
 * "part_name_K"): the count (0: no parts), and tet t's part through
 * st_tf_tet_part (values not a part index in 0..count-1 read as 0). */
size_t st_tf_parts(const st_tetmesh *m, const double **part);
static inline size_t st_tf_tet_part(const double *part, size_t nparts, size_t t)
{
    const double v = part[t];
    return v >= 0 && v < (double)nparts && v == floor(v) ? (size_t)v : 0;
}
/* Part k's name for a quoted field: meta part_name_k, else part_k, with '"',
 * '\\' and control bytes as '_'. */
void st_tf_part_name(char *buf, size_t size, const st_tetmesh *m, size_t k);
int st_tf_msh_version(int v);
st_status st_tf_check_writable(const st_tetmesh *m, st_tetformat f,
                               int version, int binary, const char *path,
                               st_error *err);
/* The boundary faces written as triangles by .msh and .mesh: those of
 * st_tetmesh_boundary, each turned outward also when its tet is
 * negatively oriented (the exact sign of st_orient3d decides; a flat tet's
 * face is kept as it is). *faces (3 point indices a face) is freed by
 * the caller with free(). (tetformat.c) */
st_status st_tf_boundary(const st_tetmesh *m, uint32_t **faces,
                         size_t *nfaces, const char *path, st_error *err);
FILE *st_tf_open_out(const char *path, st_error *err);
/* st_tetmesh_write_msh and st_tetmesh_write_medit with the option
 * volume_only (st_tetformat_opts): the tets alone. */
st_status st_tf_write_msh_path(const st_tetmesh *m, const char *path,
                               int version, int binary, int volume_only,
                               st_error *err);
st_status st_tf_write_medit_path(const st_tetmesh *m, const char *path,
                                 int volume_only, st_error *err);
st_status st_tf_close_written(FILE *fp, const char *path, st_error *err);

/* The writers on an open stream (tetformat_msh.c, tetformat_tetgen.c,
 * tetformat_medit.c); errors show in ferror(fp). The .msh and .mesh
 * writers also write the nfaces boundary triangles faces (st_tf_boundary).
 * The .msh writer with volume_only writes the volume's physical group and
 * entity alone (no "boundary" group, no surface entity; faces unused). */
void st_tf_write_msh_fp(FILE *fp, const st_tetmesh *m, int version,
                        int binary, int volume_only, const uint32_t *faces,
                        size_t nfaces);
void st_tf_write_node_fp(FILE *fp, const st_tetmesh *m);
void st_tf_write_ele_fp(FILE *fp, const st_tetmesh *m);
void st_tf_write_medit_fp(FILE *fp, const st_tetmesh *m,
                          const uint32_t *faces, size_t nfaces);

/* .vtu (tetformat_vtu.c): m as a VTK XML UnstructuredGrid document in a
 * malloc'd buffer (name: for messages), or written to the file path
 * (exactly there, no temporary). */
st_status st_tf_write_vtu_mem(unsigned char **data, size_t *size, const st_tetmesh *m,
                              const char *name, st_error *err);
st_status st_tf_write_vtu_path(const st_tetmesh *m, const char *path, st_error *err);

/* m to path in format f (NONE: by path; MSH, TETGEN or MEDIT) with opts
 * (NULL: defaults), atomically: every file (both of a TetGen pair) goes
 * to a temporary name beside its target and is renamed only when all
 * were written, so a failure leaves nothing at the targets. Errors name
 * the target. tetio.h's st_tetmesh_save is the front door. (tetformat.c) */
st_status st_tf_save(const st_tetmesh *m, st_tetformat f, const char *path,
                     const st_tetformat_opts *opts, st_error *err);

#endif
