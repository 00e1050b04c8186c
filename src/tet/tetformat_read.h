/*
 * tetformat_read.h - the reading state the tet readers share (tetformat.c,
 * tetformat_msh.c, tetformat_tetgen.c, tetformat_medit.c): a file held in
 * memory under the text lexer's cursor (lexer.h), the mesh being built,
 * the "souptet KEY: VALUE" metadata collected, and the helpers that read
 * numbers and records with messages at a line or byte offset
 * (tetformat_read.c). Not installed.
 */
#ifndef SOUPTET_TETFORMAT_READ_H
#define SOUPTET_TETFORMAT_READ_H

#include <stddef.h>
#include <stdint.h>

#include "souptet/err.h"
#include "souptet/tetmesh.h"
#include "../base/lexer.h"

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

st_status st_rd_fail_at(rd *r, st_status st, const unsigned char *at,
                     const char *fmt, ...)
#ifdef __GNUC__
    __attribute__((format(printf, 4, 5)))
#endif
    ;

#define rd_fail(r, ...) st_rd_fail_at((r), ST_EINPUT, (r)->t.p, __VA_ARGS__)

/* The mesh memory max_bytes allows: 24 bytes a point, 16 a tet. */
st_status st_rd_room(rd *r, size_t extra_points, size_t extra_tets);

st_status st_rd_point(rd *r, const double p[3]);

st_status st_rd_tet(rd *r, const uint32_t v[4]);

/* The next token anywhere (text); fails with "what" at the end. */
st_status st_rd_token(rd *r, const unsigned char **tok, size_t *n,
                   const char *what);

st_status st_rd_int(rd *r, long long *v, const char *what);

/* An integer in [lo, hi]. */
st_status st_rd_int_in(rd *r, long long *v, long long lo, long long hi,
                    const char *what);

st_status st_rd_double(rd *r, double *v, const char *what);

st_status st_rd_xyz(rd *r, double p[3]);

/* Bytes left after the cursor. */
size_t st_rd_left(const rd *r);

/* A header's count of records of at least min_bytes each must fit. */
st_status st_rd_count_fits(rd *r, unsigned long long count, size_t min_bytes,
                        const char *what);

/* Move the text cursor to q, counting the lines passed. */
void st_rd_jump(rd *r, const unsigned char *q);

/* Metadata from a "souptet KEY: VALUE" comment line [s, e): a repeated key
 * continues its value on a new line (history). Values grow by doubling,
 * so a file of many history lines costs linear time. */
st_status st_rd_meta_line(rd *r, const unsigned char *s, const unsigned char *e);

/* Move the collected values into the mesh's meta. */
st_status st_rd_meta_flush(rd *r);

void st_rd_meta_free(rd *r);

/* The start of every reader: r cleared, errors to err, meshes of
 * max_bytes at most, and an empty mesh (out of memory named NAME). */
st_status st_rd_begin(rd *r, size_t max_bytes, st_error *err, const char *name);

/* The end of every reader, after the parse's status s: the collected
 * meta into the mesh, then the mesh into *out (ST_OK), or freed (the
 * error returned). */
st_status st_rd_finish(rd *r, st_status s, st_tetmesh **out);

/* Every "# souptet KEY: VALUE" line of a '#'-commented text file. */
st_status st_rd_hash_meta(rd *r);

#endif
