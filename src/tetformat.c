/*
 * tetformat.c - Gmsh .msh (4.1, 2.2; ASCII, binary), TetGen .node/.ele and
 * Medit .mesh readers and writers (see tetformat.h).
 *
 * References: the Gmsh reference manual, section "MSH file format" (4.1)
 * and its "legacy formats" appendix (2.2); TetGen 1.5 user's manual,
 * section 5.2 (.node, .ele); the Medit / libMeshb ASCII keyword format
 * (MeshVersionFormatted, Dimension, Vertices, Tetrahedra, End).
 *
 * Every reader parses a whole file held in memory through the bounded
 * cursor of soup_parse.h (the buffer is never NUL-terminated), converts
 * numbers from tokens, and grows the mesh only with records actually
 * present (st_tetmesh_add_point / add_tet grow geometrically): a header
 * count is checked against the bytes left before it is believed, only to
 * give a clear message early. Binary .msh data is read through a byte
 * cursor over the same buffer that stops at its end.
 */
#include "souptet/tetformat.h"
#include "fpenv.h"
#include "souptet/mem.h"
#include "souptet/outfile.h"
#include "soup_parse.h"

#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

/* ---- names and paths ----------------------------------------------------- */

static st_tetformat format_of_ext(const char *path)
{
    const char *base = strrchr(path, '/');
    base = base ? base + 1 : path;
    const char *dot = strrchr(base, '.');
    if (!dot || dot == base)
        return ST_TETFORMAT_NONE;
    if (strcasecmp(dot, ".msh") == 0)
        return ST_TETFORMAT_MSH;
    if (strcasecmp(dot, ".node") == 0 || strcasecmp(dot, ".ele") == 0)
        return ST_TETFORMAT_TETGEN;
    if (strcasecmp(dot, ".mesh") == 0)
        return ST_TETFORMAT_MEDIT;
    return ST_TETFORMAT_NONE;
}

st_tetformat st_tetformat_from_path(const char *path)
{
    if (!path || st_path_is_stdio(path))
        return ST_TETFORMAT_NONE;
    st_tetformat f = format_of_ext(path);
    /* st_outfile's temporary name: its target's format. */
    char *p = f == ST_TETFORMAT_NONE ? st_outfile_target_of(path) : NULL;
    if (p)
        f = format_of_ext(p);
    free(p);
    return f;
}

const char *st_tetformat_name(st_tetformat f)
{
    switch (f) {
    case ST_TETFORMAT_MSH: return "msh";
    case ST_TETFORMAT_TETGEN: return "tetgen";
    case ST_TETFORMAT_MEDIT: return "medit";
    case ST_TETFORMAT_NONE: break;
    }
    return "none";
}

st_tetformat st_tetformat_sniff(const unsigned char *data, size_t size)
{
    st_text t;
    st_text_init(&t, data, size, ST_TEXT_HASH);
    const unsigned char *tok;
    size_t n = st_text_token_any(&t, &tok);
    if (st_tok_eq(tok, n, "$MeshFormat"))
        return ST_TETFORMAT_MSH;
    if (st_tok_ieq(tok, n, "meshversionformatted"))
        return ST_TETFORMAT_MEDIT;
    return ST_TETFORMAT_NONE;
}

/* base.node and base.ele for a TetGen path (.node, .ele or a base name). */
static st_status tetgen_names(const char *path, char **node, char **ele,
                              st_error *err)
{
    size_t n = strlen(path), keep = n;
    const char *base = strrchr(path, '/');
    base = base ? base + 1 : path;
    const char *dot = strrchr(base, '.');
    if (dot && dot != base &&
        (strcasecmp(dot, ".node") == 0 || strcasecmp(dot, ".ele") == 0))
        keep = (size_t)(dot - path);
    *node = malloc(keep + 6);
    *ele = malloc(keep + 5);
    if (!*node || !*ele) {
        free(*node);
        free(*ele);
        *node = *ele = NULL;
        return st_error_set(err, ST_ENOMEM, path, 0, "out of memory");
    }
    memcpy(*node, path, keep);
    memcpy(*node + keep, ".node", 6);
    memcpy(*ele, path, keep);
    memcpy(*ele + keep, ".ele", 5);
    return ST_OK;
}

/* ---- files --------------------------------------------------------------- */

/* The whole file; *data is malloc'd (size 0 gives a valid pointer). */
static st_status slurp(const char *path, unsigned char **data, size_t *size,
                       st_error *err)
{
    *data = NULL;
    *size = 0;
    FILE *fp = fopen(path, "rb");
    if (!fp)
        return st_error_set(err, ST_EIO, path, 0, "cannot open: %s",
                            strerror(errno));
    size_t cap = 1 << 16, n = 0;
    unsigned char *buf = malloc(cap);
    if (!buf) {
        fclose(fp);
        return st_error_set(err, ST_ENOMEM, path, 0, "out of memory");
    }
    for (;;) {
        if (n == cap) {
            size_t nc;
            unsigned char *nb = NULL;
            if (st_size_mul(&nc, cap, 2) == 0)
                nb = realloc(buf, nc);
            if (!nb) {
                free(buf);
                fclose(fp);
                return st_error_set(err, ST_ENOMEM, path, 0,
                                    "out of memory reading the file");
            }
            buf = nb;
            cap = nc;
        }
        size_t got = fread(buf + n, 1, cap - n, fp);
        n += got;
        if (got == 0)
            break;
    }
    int bad = ferror(fp);
    int e = errno;
    fclose(fp);
    if (bad) {
        free(buf);
        /* fread on a directory fails with EISDIR. */
        return st_error_set(err, ST_EIO, path, 0, "read failed: %s",
                            strerror(e));
    }
    *data = buf;
    *size = n;
    return ST_OK;
}

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

static st_status rd_fail_at(rd *r, st_status st, const unsigned char *at,
                            const char *fmt, ...)
#ifdef __GNUC__
    __attribute__((format(printf, 4, 5)))
#endif
    ;

static st_status rd_fail_at(rd *r, st_status st, const unsigned char *at,
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
static st_status rd_room(rd *r, size_t extra_points, size_t extra_tets)
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

static st_status rd_point(rd *r, const double p[3])
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

static st_status rd_tet(rd *r, const uint32_t v[4])
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
static st_status rd_token(rd *r, const unsigned char **tok, size_t *n,
                          const char *what)
{
    *n = st_text_token_any(&r->t, tok);
    if (!*n)
        return rd_fail(r, "file ends before %s", what);
    return ST_OK;
}

static st_status rd_int(rd *r, long long *v, const char *what)
{
    const unsigned char *tok;
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
static st_status rd_int_in(rd *r, long long *v, long long lo, long long hi,
                           const char *what)
{
    st_status s = rd_int(r, v, what);
    if (s)
        return s;
    if (*v < lo || *v > hi)
        return rd_fail(r, "%s %lld out of range", what, *v);
    return ST_OK;
}

static st_status rd_double(rd *r, double *v, const char *what)
{
    const unsigned char *tok;
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

static st_status rd_xyz(rd *r, double p[3])
{
    for (int k = 0; k < 3; k++) {
        st_status s = rd_double(r, &p[k], "coordinate");
        if (s)
            return s;
    }
    return ST_OK;
}

/* Bytes left after the cursor. */
static size_t rd_left(const rd *r)
{
    return (size_t)(r->t.end - r->t.p);
}

/* A header's count of records of at least min_bytes each must fit. */
static st_status rd_count_fits(rd *r, unsigned long long count,
                               size_t min_bytes, const char *what)
{
    size_t left = rd_left(r) + 1;  /* the last record may lack its '\n' */
    if (min_bytes && count > left / min_bytes)
        return rd_fail(r, "header says %llu %s but only %zu bytes follow",
                       count, what, rd_left(r));
    return ST_OK;
}

/* Move the text cursor to q, counting the lines passed. */
static void rd_jump(rd *r, const unsigned char *q)
{
    for (const unsigned char *p = r->t.p; p < q; p++)
        if (*p == '\n')
            r->t.line++;
    r->t.p = q;
}

/* Metadata from a "souptet KEY: VALUE" comment line [s, e): a repeated key
 * continues its value on a new line (history). Values grow by doubling,
 * so a file of many history lines costs linear time. */
static st_status rd_meta_line(rd *r, const unsigned char *s,
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
static st_status rd_meta_flush(rd *r)
{
    for (size_t i = 0; i < r->nmeta; i++)
        if (st_meta_set(&r->m->meta, r->meta[i].key, r->meta[i].val))
            return st_error_set(r->err, ST_ENOMEM, r->name, 0,
                                "out of memory");
    return ST_OK;
}

static void rd_meta_free(rd *r)
{
    for (size_t i = 0; i < r->nmeta; i++) {
        free(r->meta[i].key);
        free(r->meta[i].val);
    }
    r->nmeta = 0;
}

/* Every "# souptet KEY: VALUE" line of a '#'-commented text file. */
static st_status rd_hash_meta(rd *r)
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

/* ---- Gmsh .msh: reading ---------------------------------------------------- */

/* Nodes per element and dimension of the Gmsh element types 1..31. */
static const struct {
    unsigned char nn, dim;
} k_msh_type[32] = {
    {0, 0},  {2, 1},  {3, 2},  {4, 2},  {4, 3},  {8, 3},  {6, 3},  {5, 3},
    {3, 1},  {6, 2},  {9, 2},  {10, 3}, {27, 3}, {18, 3}, {14, 3}, {1, 0},
    {8, 2},  {20, 3}, {15, 3}, {13, 3}, {9, 2},  {10, 2}, {12, 2}, {15, 2},
    {15, 2}, {21, 2}, {4, 1},  {5, 1},  {6, 1},  {20, 3}, {35, 3}, {56, 3},
};

typedef struct tagidx {
    uint64_t tag;
    uint32_t idx;
} tagidx;

typedef struct msh {
    rd r;
    int version;        /* 41 or 22 */
    int dsize;          /* binary size_t bytes (4.1) */
    int big;            /* binary data is big-endian */
    int have_nodes;
    tagidx *tags;       /* node tags, file order, then sorted if sparse */
    size_t ntags, cap_tags;
    int dense;          /* tags[i].tag == first + i for all i */
    uint64_t first;
} msh;

/* An unsigned binary value of sz bytes (<= 8). */
static st_status bin_uint(msh *ms, size_t sz, uint64_t *v, const char *what)
{
    rd *r = &ms->r;
    if (rd_left(r) < sz)
        return rd_fail(r, "file ends in %s", what);
    uint64_t x = 0;
    const unsigned char *q = r->t.p;
    for (size_t i = 0; i < sz; i++)
        x |= (uint64_t)q[ms->big ? sz - 1 - i : i] << (8 * i);
    r->t.p += sz;
    *v = x;
    return ST_OK;
}

static st_status bin_int(msh *ms, int32_t *v, const char *what)
{
    uint64_t x = 0;
    st_status s = bin_uint(ms, 4, &x, what);
    *v = (int32_t)(uint32_t)x;
    return s;
}

static st_status bin_f64(msh *ms, double *v, const char *what)
{
    uint64_t x = 0;
    st_status s = bin_uint(ms, 8, &x, what);
    memcpy(v, &x, sizeof *v);
    return s;
}

/* The next text token must be kw. */
static st_status msh_expect(msh *ms, const char *kw)
{
    const unsigned char *tok;
    size_t n = st_text_token_any(&ms->r.t, &tok);
    if (!st_tok_eq(tok, n, kw)) {
        char q[ST_QUOTE_SIZE];
        if (!n)
            return rd_fail(&ms->r, "file ends before %s", kw);
        return rd_fail(&ms->r, "expected %s, found '%s'", kw,
                       st_soup__quote(q, sizeof q, tok, n));
    }
    return ST_OK;
}

/* A count or tag: a size_t in 4.1 binary, a text integer otherwise. */
static st_status msh_size(msh *ms, uint64_t *v, const char *what)
{
    if (ms->r.binary && ms->version == 41)
        return bin_uint(ms, (size_t)ms->dsize, v, what);
    long long x;
    st_status s = rd_int_in(&ms->r, &x, 0, LLONG_MAX, what);
    *v = (uint64_t)x;
    return s;
}

/* An int field (entity dimension, tag, element type). */
static st_status msh_i32(msh *ms, long long *v, const char *what)
{
    if (ms->r.binary) {
        int32_t x = 0;
        st_status s = bin_int(ms, &x, what);
        *v = x;
        return s;
    }
    return rd_int(&ms->r, v, what);
}

static st_status msh_coord(msh *ms, double *v)
{
    if (!ms->r.binary)
        return rd_double(&ms->r, v, "coordinate");
    st_status s = bin_f64(ms, v, "a node's coordinates");
    if (!s && !isfinite(*v))
        return rd_fail_at(&ms->r, ST_EINPUT, ms->r.t.p - 8,
                          "coordinate is not finite");
    return s;
}

static st_status msh_add_tag(msh *ms, uint64_t tag)
{
    if (ms->ntags == ms->cap_tags) {
        size_t nc = ms->cap_tags < 64 ? 64 : ms->cap_tags * 2;
        tagidx *nt = st_realloc_array(ms->tags, nc, sizeof *nt);
        if (!nt)
            return rd_fail_at(&ms->r, ST_ENOMEM, ms->r.t.p, "out of memory");
        ms->tags = nt;
        ms->cap_tags = nc;
    }
    ms->tags[ms->ntags].tag = tag;
    ms->tags[ms->ntags].idx = (uint32_t)ms->ntags;
    ms->ntags++;
    return ST_OK;
}

static int cmp_tag(const void *a, const void *b)
{
    uint64_t x = ((const tagidx *)a)->tag, y = ((const tagidx *)b)->tag;
    return x < y ? -1 : x > y;
}

/* After $Nodes: a dense map when tags run first, first+1, ...; else sort
 * and refuse duplicates. */
static st_status msh_index_tags(msh *ms, const unsigned char *section,
                                 long long line)
{
    ms->dense = 1;
    ms->first = ms->ntags ? ms->tags[0].tag : 0;
    for (size_t i = 0; i < ms->ntags; i++)
        if (ms->tags[i].tag != ms->first + i) {
            ms->dense = 0;
            break;
        }
    if (ms->dense)
        return ST_OK;
    qsort(ms->tags, ms->ntags, sizeof *ms->tags, cmp_tag);
    for (size_t i = 1; i < ms->ntags; i++)
        if (ms->tags[i].tag == ms->tags[i - 1].tag) {
            ms->r.t.line = line;   /* blame the section's first line */
            return rd_fail_at(&ms->r, ST_EINPUT, section,
                              "node tag %llu appears twice in $Nodes",
                              (unsigned long long)ms->tags[i].tag);
        }
    return ST_OK;
}

/* The point index of a node tag, or -1. */
static long long msh_lookup(const msh *ms, uint64_t tag)
{
    if (ms->dense)
        return tag >= ms->first && tag - ms->first < ms->ntags
                   ? (long long)(tag - ms->first)
                   : -1;
    size_t lo = 0, hi = ms->ntags;
    while (lo < hi) {
        size_t mid = lo + (hi - lo) / 2;
        if (ms->tags[mid].tag < tag)
            lo = mid + 1;
        else
            hi = mid;
    }
    return lo < ms->ntags && ms->tags[lo].tag == tag
               ? (long long)ms->tags[lo].idx
               : -1;
}

/* One node: tag already read; reads x y z and extra parametric values. */
static st_status msh_node(msh *ms, uint64_t tag, int nparam)
{
    double p[3], u;
    for (int k = 0; k < 3; k++) {
        st_status s = msh_coord(ms, &p[k]);
        if (s)
            return s;
    }
    for (int k = 0; k < nparam; k++) {
        st_status s = msh_coord(ms, &u);
        if (s)
            return s;
    }
    st_status s = msh_add_tag(ms, tag);
    return s ? s : rd_point(&ms->r, p);
}

static st_status msh_nodes(msh *ms)
{
    rd *r = &ms->r;
    const unsigned char *section = r->t.p;
    long long section_line = r->t.line;
    if (ms->have_nodes)
        return rd_fail(r, "second $Nodes section");
    ms->have_nodes = 1;
    st_status s;
    if (r->binary && ms->version == 41)
        st_text_next_line(&r->t); /* binary data from the next line */
    if (ms->version == 22) {
        uint64_t n;
        if ((s = msh_size(ms, &n, "node count")))
            return s;
        if (r->binary)
            st_text_next_line(&r->t);
        if ((s = rd_count_fits(r, n, r->binary ? 28 : 8, "nodes")))
            return s;
        for (uint64_t i = 0; i < n; i++) {
            uint64_t tag;
            if (r->binary) {
                int32_t t32;
                if ((s = bin_int(ms, &t32, "a node's tag")))
                    return s;
                if (t32 < 0)
                    return rd_fail(r, "negative node tag %ld", (long)t32);
                tag = (uint64_t)t32;
            } else if ((s = msh_size(ms, &tag, "node tag"))) {
                return s;
            }
            if ((s = msh_node(ms, tag, 0)))
                return s;
        }
    } else {
        uint64_t nblocks, n, mintag, maxtag, done = 0;
        if ((s = msh_size(ms, &nblocks, "entity block count")) ||
            (s = msh_size(ms, &n, "node count")) ||
            (s = msh_size(ms, &mintag, "smallest node tag")) ||
            (s = msh_size(ms, &maxtag, "largest node tag")))
            return s;
        if ((s = rd_count_fits(r, n,
                               r->binary ? (size_t)ms->dsize + 24 : 8,
                               "nodes")))
            return s;
        for (uint64_t b = 0; b < nblocks; b++) {
            long long dim, etag, param;
            uint64_t cnt;
            if ((s = msh_i32(ms, &dim, "entity dimension")) ||
                (s = msh_i32(ms, &etag, "entity tag")) ||
                (s = msh_i32(ms, &param, "parametric flag")) ||
                (s = msh_size(ms, &cnt, "block node count")))
                return s;
            if (dim < 0 || dim > 3)
                return rd_fail(r, "entity dimension %lld (0..3)", dim);
            if (param != 0 && param != 1)
                return rd_fail(r, "parametric flag %lld (0 or 1)", param);
            if (cnt > n - done)
                return rd_fail(r, "node blocks hold more than the %llu "
                               "nodes the header says",
                               (unsigned long long)n);
            /* The tags come first, then the coordinates, in the same
             * order: remember where this block's tags start. */
            size_t t0 = ms->ntags;
            for (uint64_t i = 0; i < cnt; i++) {
                uint64_t tag;
                if ((s = msh_size(ms, &tag, "node tag")) ||
                    (s = msh_add_tag(ms, tag)))
                    return s;
            }
            ms->ntags = t0;
            for (uint64_t i = 0; i < cnt; i++) {
                uint64_t tag = ms->tags[t0 + i].tag;
                if ((s = msh_node(ms, tag, param ? (int)dim : 0)))
                    return s;
            }
            done += cnt;
        }
        if (done != n)
            return rd_fail(r, "node blocks hold %llu nodes, the header "
                           "says %llu", (unsigned long long)done,
                           (unsigned long long)n);
    }
    if ((s = msh_expect(ms, "$EndNodes")))
        return s;
    return msh_index_tags(ms, section, section_line);
}

/* One element of type `type` (its tag read): nn node tags, kept if tet. */
static st_status msh_element(msh *ms, uint64_t etag, int type, int ntags22)
{
    rd *r = &ms->r;
    st_status s;
    for (int k = 0; k < ntags22; k++) {
        long long x = 0;
        if ((s = msh_i32(ms, &x, "element tag")))
            return s;
    }
    int nn = k_msh_type[type].nn;
    uint32_t v[4];
    for (int k = 0; k < nn; k++) {
        uint64_t nt;
        if (r->binary && ms->version == 22) {
            int32_t x;
            if ((s = bin_int(ms, &x, "an element's nodes")))
                return s;
            nt = (uint64_t)(int64_t)x;
        } else if ((s = msh_size(ms, &nt, "element node"))) {
            return s;
        }
        if (type != 4)
            continue;
        long long idx = msh_lookup(ms, nt);
        if (idx < 0)
            return rd_fail(r, "element %llu refers to node %llu, which "
                           "$Nodes does not have",
                           (unsigned long long)etag, (unsigned long long)nt);
        v[k] = (uint32_t)idx;
    }
    return type == 4 ? rd_tet(r, v) : ST_OK;
}

/* Check an element type: known, and a tet or lower-dimensional. */
static st_status msh_type_ok(msh *ms, long long type)
{
    if (type < 1 || type > 31)
        return rd_fail(&ms->r, "unknown element type %lld", type);
    if (type != 4 && k_msh_type[type].dim == 3)
        return rd_fail(&ms->r, "element type %lld is a %d-node volume "
                       "element, not a 4-node tetrahedron (only tets are "
                       "read)", type, k_msh_type[type].nn);
    return ST_OK;
}

static st_status msh_elements(msh *ms)
{
    rd *r = &ms->r;
    st_status s;
    if (!ms->have_nodes)
        return rd_fail(r, "$Elements before $Nodes");
    if (r->binary && ms->version == 41)
        st_text_next_line(&r->t);
    if (ms->version == 22) {
        uint64_t n;
        if ((s = msh_size(ms, &n, "element count")))
            return s;
        if (r->binary)
            st_text_next_line(&r->t);
        if ((s = rd_count_fits(r, n, r->binary ? 12 : 8, "elements")))
            return s;
        uint64_t done = 0;
        while (done < n) {
            if (r->binary) {
                int32_t type, cnt, ntags;
                if ((s = bin_int(ms, &type, "an element header")) ||
                    (s = bin_int(ms, &cnt, "an element header")) ||
                    (s = bin_int(ms, &ntags, "an element header")))
                    return s;
                if ((s = msh_type_ok(ms, type)))
                    return s;
                if (cnt <= 0 || (uint64_t)cnt > n - done || ntags < 0)
                    return rd_fail(r, "bad element header (%ld elements, "
                                   "%ld tags)", (long)cnt, (long)ntags);
                for (int32_t i = 0; i < cnt; i++) {
                    int32_t etag;
                    if ((s = bin_int(ms, &etag, "an element")) ||
                        (s = msh_element(ms, (uint64_t)(uint32_t)etag, type,
                                         ntags)))
                        return s;
                }
                done += (uint64_t)cnt;
            } else {
                uint64_t etag;
                long long type, ntags;
                if ((s = msh_size(ms, &etag, "element tag")) ||
                    (s = rd_int(r, &type, "element type")) ||
                    (s = msh_type_ok(ms, type)) ||
                    (s = rd_int_in(r, &ntags, 0, INT_MAX, "tag count")) ||
                    (s = msh_element(ms, etag, (int)type, (int)ntags)))
                    return s;
                done++;
            }
        }
    } else {
        uint64_t nblocks, n, mintag, maxtag, done = 0;
        if ((s = msh_size(ms, &nblocks, "entity block count")) ||
            (s = msh_size(ms, &n, "element count")) ||
            (s = msh_size(ms, &mintag, "smallest element tag")) ||
            (s = msh_size(ms, &maxtag, "largest element tag")))
            return s;
        if ((s = rd_count_fits(r, n, r->binary ? 2 * (size_t)ms->dsize : 4,
                               "elements")))
            return s;
        for (uint64_t b = 0; b < nblocks; b++) {
            long long dim, etag, type;
            uint64_t cnt;
            if ((s = msh_i32(ms, &dim, "entity dimension")) ||
                (s = msh_i32(ms, &etag, "entity tag")) ||
                (s = msh_i32(ms, &type, "element type")) ||
                (s = msh_type_ok(ms, type)) ||
                (s = msh_size(ms, &cnt, "block element count")))
                return s;
            if (cnt > n - done)
                return rd_fail(r, "element blocks hold more than the %llu "
                               "elements the header says",
                               (unsigned long long)n);
            for (uint64_t i = 0; i < cnt; i++) {
                uint64_t tag;
                if ((s = msh_size(ms, &tag, "element tag")) ||
                    (s = msh_element(ms, tag, (int)type, 0)))
                    return s;
            }
            done += cnt;
        }
        if (done != n)
            return rd_fail(r, "element blocks hold %llu elements, the "
                           "header says %llu", (unsigned long long)done,
                           (unsigned long long)n);
    }
    return msh_expect(ms, "$EndElements");
}

/* [s, e) is at the start of a line equal to "$End<name>" (then blanks). */
static const unsigned char *find_end(const unsigned char *p,
                                     const unsigned char *end,
                                     const unsigned char *name, size_t nn)
{
    while (p < end) {
        const unsigned char *nl = memchr(p, '\n', (size_t)(end - p));
        const unsigned char *e = nl ? nl : end;
        const unsigned char *q = p;
        while (q < e && st_text_blank(*q))
            q++;
        if ((size_t)(e - q) >= 4 + nn && memcmp(q, "$End", 4) == 0 &&
            memcmp(q + 4, name, nn) == 0) {
            const unsigned char *z = q + 4 + nn;
            while (z < e && st_text_blank(*z))
                z++;
            if (z == e)
                return p;
        }
        p = nl ? nl + 1 : end;
    }
    return NULL;
}

/* $Comments: "souptet KEY: VALUE" lines become meta. */
static st_status msh_comments(msh *ms)
{
    rd *r = &ms->r;
    st_text_next_line(&r->t);
    const unsigned char *stop =
        find_end(r->t.p, r->t.end, (const unsigned char *)"Comments", 8);
    if (!stop)
        return rd_fail(r, "$Comments has no $EndComments");
    while (r->t.p < stop) {
        const unsigned char *nl =
            memchr(r->t.p, '\n', (size_t)(stop - r->t.p));
        st_status s = rd_meta_line(r, r->t.p, nl ? nl : stop);
        if (s)
            return s;
        st_text_next_line(&r->t);
    }
    return msh_expect(ms, "$EndComments");
}

static st_status msh_format(msh *ms)
{
    rd *r = &ms->r;
    const unsigned char *tok;
    size_t n;
    char q[ST_QUOTE_SIZE];
    st_status s = rd_token(r, &tok, &n, "the format version");
    if (s)
        return s;
    if (st_tok_eq(tok, n, "4.1"))
        ms->version = 41;
    else if (st_tok_eq(tok, n, "2.2") || st_tok_eq(tok, n, "2.1") ||
             st_tok_eq(tok, n, "2.0") || st_tok_eq(tok, n, "2"))
        ms->version = 22;
    else
        return rd_fail(r, "Gmsh format version '%s' is not read (4.1 and "
                       "2.2 are)", st_soup__quote(q, sizeof q, tok, n));
    long long ftype, dsize;
    if ((s = rd_int_in(r, &ftype, 0, 1, "file type")) ||
        (s = rd_int(r, &dsize, "data size")))
        return s;
    if (ftype == 1) {
        if (ms->version == 41 ? dsize != 4 && dsize != 8 : dsize != 8)
            return rd_fail(r, "binary data size %lld is not read", dsize);
        ms->dsize = (int)dsize;
        st_text_next_line(&r->t);
        r->binary = 1;
        /* The integer 1 in the writer's byte order. */
        if (rd_left(r) < 4)
            return rd_fail(r, "file ends in $MeshFormat");
        const unsigned char *p = r->t.p;
        if (p[0] == 1 && !p[1] && !p[2] && !p[3])
            ms->big = 0;
        else if (!p[0] && !p[1] && !p[2] && p[3] == 1)
            ms->big = 1;
        else
            return rd_fail(r, "bad byte-order mark (the integer 1)");
        r->t.p += 4;
    }
    return msh_expect(ms, "$EndMeshFormat");
}

static st_status msh_parse(msh *ms)
{
    rd *r = &ms->r;
    const unsigned char *tok;
    size_t n = st_text_token_any(&r->t, &tok);
    if (!st_tok_eq(tok, n, "$MeshFormat"))
        return rd_fail_at(r, ST_EINPUT, r->t.begin,
                          "not a Gmsh .msh file (no $MeshFormat)");
    st_status s = msh_format(ms);
    if (s)
        return s;
    while ((n = st_text_token_any(&r->t, &tok)) != 0) {
        if (st_tok_eq(tok, n, "$Nodes"))
            s = msh_nodes(ms);
        else if (st_tok_eq(tok, n, "$Elements"))
            s = msh_elements(ms);
        else if (st_tok_eq(tok, n, "$Comments"))
            s = msh_comments(ms);
        else if (st_tok_eq(tok, n, "$MeshFormat"))
            s = rd_fail(r, "second $MeshFormat");
        else if (n > 1 && tok[0] == '$') {
            /* Any other section ($Entities, $PhysicalNames, $NodeData,
             * ...) is skipped to its end marker, as Gmsh does. */
            const unsigned char *stop = find_end(r->t.p, r->t.end, tok + 1,
                                                 n - 1);
            char q[ST_QUOTE_SIZE];
            if (!stop)
                return rd_fail(r, "section '%s' has no end marker",
                               st_soup__quote(q, sizeof q, tok, n));
            rd_jump(r, stop);
            st_text_next_line(&r->t);
        } else {
            char q[ST_QUOTE_SIZE];
            s = rd_fail(r, "expected a section ($Nodes, ...), found '%s'",
                        st_soup__quote(q, sizeof q, tok, n));
        }
        if (s)
            return s;
    }
    if (!ms->have_nodes)
        return rd_fail(r, "no $Nodes section");
    if (r->m->ntets == 0)
        return rd_fail(r, "no tetrahedra (element type 4) in the file");
    return ST_OK;
}

st_status st_tetmesh_parse_msh(st_tetmesh **out, const unsigned char *data,
                               size_t size, const char *name,
                               size_t max_bytes, st_error *err)
{
    *out = NULL;
    msh ms;
    memset(&ms, 0, sizeof ms);
    st_text_init(&ms.r.t, data, size, 0);
    ms.r.name = name ? name : "<msh>";
    ms.r.err = err;
    ms.r.max_bytes = max_bytes;
    ms.r.m = st_tetmesh_new();
    if (!ms.r.m)
        return st_error_set(err, ST_ENOMEM, name, 0, "out of memory");
    st_status s = msh_parse(&ms);
    if (!s)
        s = rd_meta_flush(&ms.r);
    rd_meta_free(&ms.r);
    free(ms.tags);
    if (s) {
        st_tetmesh_free(ms.r.m);
        return s;
    }
    *out = ms.r.m;
    return ST_OK;
}

/* ---- TetGen .node / .ele: reading ------------------------------------------ */

/* The first non-blank, non-comment line; 0 when there is none. */
static int tg_next_record(rd *r)
{
    while (r->t.p < r->t.end) {
        if (!st_text_at_eol(&r->t))
            return 1;
        st_text_next_line(&r->t);
    }
    return 0;
}

/* An integer on the current line, or dflt when the line has ended. */
static st_status tg_opt_int(rd *r, long long *v, long long dflt,
                            long long lo, long long hi, const char *what)
{
    if (st_text_at_eol(&r->t)) {
        *v = dflt;
        return ST_OK;
    }
    return rd_int_in(r, v, lo, hi, what);
}

/* A value on the current line (a record never continues on the next). */
static st_status tg_need(rd *r, const char *what)
{
    if (st_text_at_eol(&r->t))
        return rd_fail(r, "line ends before %s", what);
    return ST_OK;
}

static st_status tg_node(rd *r, long long *base)
{
    st_status s;
    if ((s = rd_hash_meta(r)))
        return s;
    if (!tg_next_record(r))
        return rd_fail(r, "empty .node file");
    long long n, dim, nattr, nbm;
    if ((s = rd_int_in(r, &n, 0, (long long)UINT32_MAX, "point count")) ||
        (s = tg_opt_int(r, &dim, 3, 0, LLONG_MAX, "dimension")) ||
        (s = tg_opt_int(r, &nattr, 0, 0, INT_MAX, "attribute count")) ||
        (s = tg_opt_int(r, &nbm, 0, 0, 1, "boundary marker flag")))
        return s;
    if (dim != 3)
        return rd_fail(r, "dimension %lld (3 expected)", dim);
    if (n == 0)
        return rd_fail(r, "0 points (the points are then in a .poly file, "
                       "which is not read)");
    if ((s = rd_count_fits(r, (unsigned long long)n, 8, "points")))
        return s;
    st_text_next_line(&r->t);
    for (long long i = 0; i < n; i++) {
        if (!tg_next_record(r))
            return rd_fail(r, "file ends after %lld of %lld points", i, n);
        long long idx;
        double p[3];
        if ((s = rd_int(r, &idx, "point number")))
            return s;
        if (i == 0) {
            if (idx != 0 && idx != 1)
                return rd_fail(r, "first point is numbered %lld (0 or 1 "
                               "expected)", idx);
            *base = idx;
        } else if (idx != *base + i) {
            return rd_fail(r, "point numbered %lld where %lld was expected",
                           idx, *base + i);
        }
        for (int k = 0; k < 3; k++)
            if ((s = tg_need(r, "3 coordinates")) ||
                (s = rd_double(r, &p[k], "coordinate")))
                return s;
        if ((s = rd_point(r, p)))
            return s;
        st_text_next_line(&r->t); /* attributes and markers: ignored */
    }
    return ST_OK;
}

static st_status tg_ele(rd *r, long long base)
{
    st_status s;
    if (!tg_next_record(r))
        return rd_fail(r, "empty .ele file");
    long long n, npt, nreg;
    if ((s = rd_int_in(r, &n, 0, LLONG_MAX, "tet count")) ||
        (s = tg_opt_int(r, &npt, 4, 0, LLONG_MAX, "nodes per tet")) ||
        (s = tg_opt_int(r, &nreg, 0, 0, 1, "region attribute flag")))
        return s;
    if (npt != 4)
        return rd_fail(r, "%lld nodes per tet (only 4-node tets are read)",
                       npt);
    if (n == 0)
        return rd_fail(r, "0 tets");
    if ((s = rd_count_fits(r, (unsigned long long)n, 10, "tets")))
        return s;
    st_text_next_line(&r->t);
    size_t np = r->m->npoints;
    for (long long i = 0; i < n; i++) {
        if (!tg_next_record(r))
            return rd_fail(r, "file ends after %lld of %lld tets", i, n);
        long long idx, v;
        uint32_t t[4];
        if ((s = rd_int(r, &idx, "tet number")))
            return s;
        for (int k = 0; k < 4; k++) {
            if ((s = tg_need(r, "4 corners")) ||
                (s = rd_int(r, &v, "corner")))
                return s;
            if (v < base || v - base >= (long long)np)
                return rd_fail(r, "corner %lld out of range (points are "
                               "numbered %lld..%lld)", v, base,
                               base + (long long)np - 1);
            t[k] = (uint32_t)(v - base);
        }
        if ((s = rd_tet(r, t)))
            return s;
        st_text_next_line(&r->t);
    }
    return ST_OK;
}

st_status st_tetmesh_parse_tetgen(st_tetmesh **out,
                                  const unsigned char *node, size_t node_size,
                                  const char *node_name,
                                  const unsigned char *ele, size_t ele_size,
                                  const char *ele_name, size_t max_bytes,
                                  st_error *err)
{
    *out = NULL;
    rd r;
    memset(&r, 0, sizeof r);
    r.err = err;
    r.max_bytes = max_bytes;
    r.m = st_tetmesh_new();
    if (!r.m)
        return st_error_set(err, ST_ENOMEM, node_name, 0, "out of memory");
    st_text_init(&r.t, node, node_size, ST_TEXT_HASH);
    r.name = node_name ? node_name : "<node>";
    long long base = 0;
    st_status s = tg_node(&r, &base);
    if (!s) {
        st_text_init(&r.t, ele, ele_size, ST_TEXT_HASH);
        r.name = ele_name ? ele_name : "<ele>";
        s = tg_ele(&r, base);
    }
    if (!s)
        s = rd_meta_flush(&r);
    rd_meta_free(&r);
    if (s) {
        st_tetmesh_free(r.m);
        return s;
    }
    *out = r.m;
    return ST_OK;
}

/* ---- Medit .mesh: reading ------------------------------------------------ */

/* Sections skipped: keyword, numbers per record. */
static const struct {
    const char *kw;
    int per;
} k_medit_skip[] = {
    {"edges", 3},           {"triangles", 4},
    {"quadrilaterals", 5},  {"corners", 1},
    {"ridges", 1},          {"requiredvertices", 1},
    {"requirededges", 1},   {"requiredtriangles", 1},
    {"requiredquadrilaterals", 1},
    {"normals", 3},         {"tangents", 3},
    {"normalatvertices", 2}, {"tangentatvertices", 2},
    {"normalattrianglevertices", 3},
};

static const char *const k_medit_volume[] = {
    "hexahedra", "prisms", "pyramids", "tetrahedrap2", "hexahedraq2",
};

static st_status medit_parse(rd *r)
{
    st_status s;
    const unsigned char *tok;
    size_t n = st_text_token_any(&r->t, &tok);
    char q[ST_QUOTE_SIZE];
    if (!st_tok_ieq(tok, n, "meshversionformatted"))
        return rd_fail(r, "not a Medit .mesh file (no "
                       "MeshVersionFormatted)");
    long long v;
    if ((s = rd_int_in(r, &v, 1, 4, "mesh version")))
        return s;
    int have_vertices = 0;
    while ((n = st_text_token_any(&r->t, &tok)) != 0) {
        if (st_tok_ieq(tok, n, "end"))
            break;
        if (st_tok_ieq(tok, n, "dimension")) {
            if ((s = rd_int(r, &v, "dimension")))
                return s;
            if (v != 3)
                return rd_fail(r, "dimension %lld (3 expected)", v);
        } else if (st_tok_ieq(tok, n, "vertices")) {
            if (have_vertices)
                return rd_fail(r, "second Vertices section");
            have_vertices = 1;
            if ((s = rd_int_in(r, &v, 0, (long long)UINT32_MAX,
                               "vertex count")) ||
                (s = rd_count_fits(r, (unsigned long long)v, 8,
                                   "vertices")))
                return s;
            for (long long i = 0; i < v; i++) {
                double p[3];
                long long ref;
                if ((s = rd_xyz(r, p)) ||
                    (s = rd_int(r, &ref, "vertex reference")) ||
                    (s = rd_point(r, p)))
                    return s;
            }
        } else if (st_tok_ieq(tok, n, "tetrahedra")) {
            if (!have_vertices)
                return rd_fail(r, "Tetrahedra before Vertices");
            if ((s = rd_int_in(r, &v, 0, LLONG_MAX, "tet count")) ||
                (s = rd_count_fits(r, (unsigned long long)v, 10, "tets")))
                return s;
            long long np = (long long)r->m->npoints;
            for (long long i = 0; i < v; i++) {
                uint32_t t[4];
                long long c, ref;
                for (int k = 0; k < 4; k++) {
                    if ((s = rd_int(r, &c, "tet corner")))
                        return s;
                    if (c < 1 || c > np)
                        return rd_fail(r, "tet corner %lld out of range "
                                       "(1..%lld)", c, np);
                    t[k] = (uint32_t)(c - 1);
                }
                if ((s = rd_int(r, &ref, "tet reference")) ||
                    (s = rd_tet(r, t)))
                    return s;
            }
        } else {
            size_t i;
            for (i = 0; i < sizeof k_medit_volume / sizeof *k_medit_volume;
                 i++)
                if (st_tok_ieq(tok, n, k_medit_volume[i]))
                    return rd_fail(r, "'%s': only tetrahedra are read",
                                   st_soup__quote(q, sizeof q, tok, n));
            for (i = 0; i < sizeof k_medit_skip / sizeof *k_medit_skip; i++)
                if (st_tok_ieq(tok, n, k_medit_skip[i].kw))
                    break;
            if (i == sizeof k_medit_skip / sizeof *k_medit_skip)
                return rd_fail(r, "unknown keyword '%s'",
                               st_soup__quote(q, sizeof q, tok, n));
            if ((s = rd_int_in(r, &v, 0, LLONG_MAX, "record count")))
                return s;
            int per = k_medit_skip[i].per;
            if ((s = rd_count_fits(r, (unsigned long long)v,
                                   2 * (size_t)per, "records")))
                return s;
            for (long long j = 0; j < v * per; j++) {
                double x;
                if ((s = rd_double(r, &x, "value")))
                    return s;
            }
        }
    }
    if (r->m->ntets == 0)
        return rd_fail(r, "no Tetrahedra in the file");
    return ST_OK;
}

st_status st_tetmesh_parse_medit(st_tetmesh **out, const unsigned char *data,
                                 size_t size, const char *name,
                                 size_t max_bytes, st_error *err)
{
    *out = NULL;
    rd r;
    memset(&r, 0, sizeof r);
    st_text_init(&r.t, data, size, ST_TEXT_HASH);
    r.name = name ? name : "<mesh>";
    r.err = err;
    r.max_bytes = max_bytes;
    r.m = st_tetmesh_new();
    if (!r.m)
        return st_error_set(err, ST_ENOMEM, name, 0, "out of memory");
    st_status s = rd_hash_meta(&r);
    if (!s)
        s = medit_parse(&r);
    if (!s)
        s = rd_meta_flush(&r);
    rd_meta_free(&r);
    if (s) {
        st_tetmesh_free(r.m);
        return s;
    }
    *out = r.m;
    return ST_OK;
}

/* ---- reading files --------------------------------------------------------- */

typedef st_status (*mem_parser)(st_tetmesh **, const unsigned char *, size_t,
                                const char *, size_t, st_error *);

static st_status read_with(mem_parser parse, st_tetmesh **out,
                           const char *path, size_t max_bytes, st_error *err)
{
    *out = NULL;
    unsigned char *data;
    size_t size;
    st_status s = slurp(path, &data, &size, err);
    if (s)
        return s;
    if (size == 0)
        s = st_error_set(err, ST_EINPUT, path, 0, "empty file");
    else
        s = parse(out, data, size, path, max_bytes, err);
    free(data);
    return s;
}

st_status st_tetmesh_read_msh(st_tetmesh **out, const char *path,
                              size_t max_bytes, st_error *err)
{
    return read_with(st_tetmesh_parse_msh, out, path, max_bytes, err);
}

st_status st_tetmesh_read_medit(st_tetmesh **out, const char *path,
                                size_t max_bytes, st_error *err)
{
    return read_with(st_tetmesh_parse_medit, out, path, max_bytes, err);
}

st_status st_tetmesh_read_tetgen(st_tetmesh **out, const char *path,
                                 size_t max_bytes, st_error *err)
{
    *out = NULL;
    char *node, *ele;
    st_status s = tetgen_names(path, &node, &ele, err);
    if (s)
        return s;
    unsigned char *nd = NULL, *ed = NULL;
    size_t nn = 0, en = 0;
    s = slurp(node, &nd, &nn, err);
    if (!s)
        s = slurp(ele, &ed, &en, err);
    if (!s)
        s = st_tetmesh_parse_tetgen(out, nd, nn, node, ed, en, ele,
                                    max_bytes, err);
    free(nd);
    free(ed);
    free(node);
    free(ele);
    return s;
}

st_status st_tetformat_read(st_tetmesh **out, st_tetformat f,
                            const char *path, size_t max_bytes,
                            st_error *err)
{
    *out = NULL;
    if (!path || st_path_is_stdio(path))
        return st_error_set(err, ST_EINPUT, NULL, 0,
                            "msh, TetGen and Medit meshes are read from "
                            "files, not stdin");
    if (f == ST_TETFORMAT_NONE)
        f = st_tetformat_from_path(path);
    if (f == ST_TETFORMAT_NONE) {
        unsigned char *data;
        size_t size;
        st_status s = slurp(path, &data, &size, err);
        if (s)
            return s;
        f = st_tetformat_sniff(data, size);
        if (f == ST_TETFORMAT_MSH)
            s = st_tetmesh_parse_msh(out, data, size, path, max_bytes, err);
        else if (f == ST_TETFORMAT_MEDIT)
            s = st_tetmesh_parse_medit(out, data, size, path, max_bytes,
                                       err);
        else
            s = st_error_set(err, ST_EINPUT, path, 0,
                             "unknown tet mesh format");
        free(data);
        return s;
    }
    switch (f) {
    case ST_TETFORMAT_MSH:
        return st_tetmesh_read_msh(out, path, max_bytes, err);
    case ST_TETFORMAT_TETGEN:
        return st_tetmesh_read_tetgen(out, path, max_bytes, err);
    case ST_TETFORMAT_MEDIT:
        return st_tetmesh_read_medit(out, path, max_bytes, err);
    case ST_TETFORMAT_NONE: break;
    }
    return st_error_set(err, ST_EINTERNAL, path, 0, "bad format");
}

/* ---- writing ------------------------------------------------------------- */

/* Meta entries as "PREFIXsouptet KEY: LINE" lines, one per line of the
 * value; keys that could not be read back (blanks, ':') are left out. */
static void put_meta(FILE *fp, const st_meta *meta, const char *prefix)
{
    for (size_t i = 0; i < meta->count; i++) {
        const char *k = meta->entries[i].key, *v = meta->entries[i].value;
        if (!k || !*k || strpbrk(k, " \t\r\n:") || !v)
            continue;
        for (;;) {
            const char *nl = strchr(v, '\n');
            int len = nl ? (int)(nl - v) : (int)strlen(v);
            fprintf(fp, "%ssouptet %s: %.*s\n", prefix, k, len, v);
            if (!nl)
                break;
            v = nl + 1;
        }
    }
}

static void put_u64(FILE *fp, uint64_t v) { fwrite(&v, sizeof v, 1, fp); }
static void put_i32(FILE *fp, int32_t v) { fwrite(&v, sizeof v, 1, fp); }
static void put_f64(FILE *fp, double v) { fwrite(&v, sizeof v, 1, fp); }

static void write_msh_fp(FILE *fp, const st_tetmesh *m, int version,
                         int binary)
{
    size_t np = m->npoints, nt = m->ntets;
    fprintf(fp, "$MeshFormat\n%s %d 8\n", version == 22 ? "2.2" : "4.1",
            binary);
    if (binary) {
        put_i32(fp, 1);
        fputc('\n', fp);
    }
    fputs("$EndMeshFormat\n", fp);
    if (m->meta.count) {
        fputs("$Comments\n", fp);
        put_meta(fp, &m->meta, "");
        fputs("$EndComments\n", fp);
    }
    if (version == 22) {
        fprintf(fp, "$Nodes\n%zu\n", np);
        for (size_t i = 0; i < np; i++) {
            const double *p = m->xyz + 3 * i;
            if (binary) {
                put_i32(fp, (int32_t)(i + 1));
                fwrite(p, sizeof *p, 3, fp);
            } else {
                fprintf(fp, "%zu %.17g %.17g %.17g\n", i + 1, p[0], p[1],
                        p[2]);
            }
        }
        fprintf(fp, "%s$EndNodes\n$Elements\n%zu\n", binary ? "\n" : "", nt);
        if (binary && nt) {
            put_i32(fp, 4);
            put_i32(fp, (int32_t)nt);
            put_i32(fp, 2);
        }
        for (size_t i = 0; i < nt; i++) {
            const uint32_t *t = m->tets + 4 * i;
            if (binary) {
                int32_t rec[7] = {(int32_t)(i + 1), 1, 1,
                                  (int32_t)(t[0] + 1), (int32_t)(t[1] + 1),
                                  (int32_t)(t[2] + 1), (int32_t)(t[3] + 1)};
                fwrite(rec, sizeof rec[0], 7, fp);
            } else {
                fprintf(fp, "%zu 4 2 1 1 %lu %lu %lu %lu\n", i + 1,
                        (unsigned long)t[0] + 1, (unsigned long)t[1] + 1,
                        (unsigned long)t[2] + 1, (unsigned long)t[3] + 1);
            }
        }
        fprintf(fp, "%s$EndElements\n", binary ? "\n" : "");
        return;
    }

    /* 4.1: one volume entity (tag 1, physical group 1) holding everything. */
    double lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
    for (size_t i = 0; i < np; i++)
        for (int k = 0; k < 3; k++) {
            double x = m->xyz[3 * i + k];
            if (i == 0 || x < lo[k])
                lo[k] = x;
            if (i == 0 || x > hi[k])
                hi[k] = x;
        }
    fputs("$Entities\n", fp);
    if (binary) {
        put_u64(fp, 0);
        put_u64(fp, 0);
        put_u64(fp, 0);
        put_u64(fp, 1);
        put_i32(fp, 1);
        for (int k = 0; k < 3; k++)
            put_f64(fp, lo[k]);
        for (int k = 0; k < 3; k++)
            put_f64(fp, hi[k]);
        put_u64(fp, 1);
        put_i32(fp, 1);
        put_u64(fp, 0);
        fputc('\n', fp);
    } else {
        fprintf(fp, "0 0 0 1\n1 %.17g %.17g %.17g %.17g %.17g %.17g 1 1 0\n",
                lo[0], lo[1], lo[2], hi[0], hi[1], hi[2]);
    }
    fputs("$EndEntities\n$Nodes\n", fp);
    size_t nb = np ? 1 : 0;
    if (binary) {
        put_u64(fp, nb);
        put_u64(fp, np);
        put_u64(fp, np ? 1 : 0);
        put_u64(fp, np);
        if (np) {
            put_i32(fp, 3);
            put_i32(fp, 1);
            put_i32(fp, 0);
            put_u64(fp, np);
            for (size_t i = 0; i < np; i++)
                put_u64(fp, i + 1);
            fwrite(m->xyz, sizeof(double), 3 * np, fp);
        }
        fputc('\n', fp);
    } else {
        fprintf(fp, "%zu %zu %zu %zu\n", nb, np, np ? (size_t)1 : 0, np);
        if (np) {
            fprintf(fp, "3 1 0 %zu\n", np);
            for (size_t i = 0; i < np; i++)
                fprintf(fp, "%zu\n", i + 1);
            for (size_t i = 0; i < np; i++) {
                const double *p = m->xyz + 3 * i;
                fprintf(fp, "%.17g %.17g %.17g\n", p[0], p[1], p[2]);
            }
        }
    }
    fputs("$EndNodes\n$Elements\n", fp);
    nb = nt ? 1 : 0;
    if (binary) {
        put_u64(fp, nb);
        put_u64(fp, nt);
        put_u64(fp, nt ? 1 : 0);
        put_u64(fp, nt);
        if (nt) {
            put_i32(fp, 3);
            put_i32(fp, 1);
            put_i32(fp, 4);
            put_u64(fp, nt);
            for (size_t i = 0; i < nt; i++) {
                const uint32_t *t = m->tets + 4 * i;
                uint64_t rec[5] = {i + 1, (uint64_t)t[0] + 1,
                                   (uint64_t)t[1] + 1, (uint64_t)t[2] + 1,
                                   (uint64_t)t[3] + 1};
                fwrite(rec, sizeof rec[0], 5, fp);
            }
        }
        fputc('\n', fp);
    } else {
        fprintf(fp, "%zu %zu %zu %zu\n", nb, nt, nt ? (size_t)1 : 0, nt);
        if (nt) {
            fprintf(fp, "3 1 4 %zu\n", nt);
            for (size_t i = 0; i < nt; i++) {
                const uint32_t *t = m->tets + 4 * i;
                fprintf(fp, "%zu %lu %lu %lu %lu\n", i + 1,
                        (unsigned long)t[0] + 1, (unsigned long)t[1] + 1,
                        (unsigned long)t[2] + 1, (unsigned long)t[3] + 1);
            }
        }
    }
    fputs("$EndElements\n", fp);
}

static void write_node_fp(FILE *fp, const st_tetmesh *m)
{
    put_meta(fp, &m->meta, "# ");
    fprintf(fp, "%zu 3 0 0\n", m->npoints);
    for (size_t i = 0; i < m->npoints; i++) {
        const double *p = m->xyz + 3 * i;
        fprintf(fp, "%zu %.17g %.17g %.17g\n", i + 1, p[0], p[1], p[2]);
    }
}

static void write_ele_fp(FILE *fp, const st_tetmesh *m)
{
    fprintf(fp, "%zu 4 0\n", m->ntets);
    for (size_t i = 0; i < m->ntets; i++) {
        const uint32_t *t = m->tets + 4 * i;
        fprintf(fp, "%zu %lu %lu %lu %lu\n", i + 1, (unsigned long)t[0] + 1,
                (unsigned long)t[1] + 1, (unsigned long)t[2] + 1,
                (unsigned long)t[3] + 1);
    }
}

static void write_medit_fp(FILE *fp, const st_tetmesh *m)
{
    fputs("MeshVersionFormatted 2\n", fp);
    put_meta(fp, &m->meta, "# ");
    fprintf(fp, "\nDimension 3\n\nVertices\n%zu\n", m->npoints);
    for (size_t i = 0; i < m->npoints; i++) {
        const double *p = m->xyz + 3 * i;
        fprintf(fp, "%.17g %.17g %.17g 0\n", p[0], p[1], p[2]);
    }
    fprintf(fp, "\nTetrahedra\n%zu\n", m->ntets);
    for (size_t i = 0; i < m->ntets; i++) {
        const uint32_t *t = m->tets + 4 * i;
        fprintf(fp, "%lu %lu %lu %lu 1\n", (unsigned long)t[0] + 1,
                (unsigned long)t[1] + 1, (unsigned long)t[2] + 1,
                (unsigned long)t[3] + 1);
    }
    fputs("\nEnd\n", fp);
}

static int norm_version(int v)
{
    if (v == 0 || v == 4 || v == 41)
        return 41;
    if (v == 2 || v == 22)
        return 22;
    return -1;
}

/* What no file of format f can hold. */
static st_status check_writable(const st_tetmesh *m, st_tetformat f,
                                int version, int binary, const char *path,
                                st_error *err)
{
    if (f == ST_TETFORMAT_MSH && version < 0)
        return st_error_set(err, ST_EINPUT, path, 0,
                            "msh version must be 41 or 22");
    if (f == ST_TETFORMAT_MSH && version == 22 && binary &&
        (m->npoints > INT32_MAX || m->ntets > INT32_MAX))
        return st_error_set(err, ST_ELIMIT, path, 0,
                            "msh 2.2 binary holds at most %ld nodes and "
                            "elements", (long)INT32_MAX);
    return ST_OK;
}

/* fp was written by one of the writers: flush, close, report. */
static st_status close_written(FILE *fp, const char *path, st_error *err)
{
    int bad = ferror(fp);
    int e = errno;
    if (fclose(fp) != 0 && !bad) {
        bad = 1;
        e = errno;
    }
    if (bad)
        return st_error_set(err, ST_EIO, path, 0, "write failed: %s",
                            strerror(e));
    return ST_OK;
}

static FILE *open_out(const char *path, st_error *err)
{
    FILE *fp = fopen(path, "wb");
    if (!fp)
        st_error_set(err, ST_EIO, path, 0, "cannot create: %s",
                     strerror(errno));
    return fp;
}

st_status st_tetmesh_write_msh(const st_tetmesh *m, const char *path,
                               int version, int binary, st_error *err)
{
    version = norm_version(version);
    st_status s = check_writable(m, ST_TETFORMAT_MSH, version, binary, path,
                                 err);
    if (s)
        return s;
    FILE *fp = open_out(path, err);
    if (!fp)
        return err ? err->status : ST_EIO;
    write_msh_fp(fp, m, version, binary ? 1 : 0);
    return close_written(fp, path, err);
}

st_status st_tetmesh_write_medit(const st_tetmesh *m, const char *path,
                                 st_error *err)
{
    FILE *fp = open_out(path, err);
    if (!fp)
        return err ? err->status : ST_EIO;
    write_medit_fp(fp, m);
    return close_written(fp, path, err);
}

/* The target of st_outfile's temporary name (outfile.h) for a .node or
 * .ele file, malloc'd; NULL when path is not such a name. */
static char *outfile_target(const char *path)
{
    char *t = st_outfile_target_of(path);
    if (t && format_of_ext(t) != ST_TETFORMAT_TETGEN) {
        free(t);
        return NULL;
    }
    return t;
}

static st_status write_one(const st_tetmesh *m, const char *path,
                           int node, st_error *err)
{
    FILE *fp = open_out(path, err);
    if (!fp)
        return err ? err->status : ST_EIO;
    if (node)
        write_node_fp(fp, m);
    else
        write_ele_fp(fp, m);
    return close_written(fp, path, err);
}

st_status st_tetmesh_write_tetgen(const st_tetmesh *m, const char *path,
                                  st_error *err)
{
    char *target = outfile_target(path);
    char *node, *ele;
    st_status s = tetgen_names(target ? target : path, &node, &ele, err);
    if (s) {
        free(target);
        return s;
    }
    if (!target) {
        s = write_one(m, node, 1, err);
        if (!s)
            s = write_one(m, ele, 0, err);
    } else {
        /* A tool writes through st_outfile into one temporary file, which
         * it renames to the target: that file gets its own half of the
         * pair, the other half is written atomically beside it. */
        int is_node = strcasecmp(strrchr(target, '.'), ".node") == 0;
        s = write_one(m, path, is_node, err);
        st_outfile o;
        memset(&o, 0, sizeof o);
        if (!s)
            s = st_outfile_begin(&o, is_node ? ele : node, 1, err);
        if (!s) {
            if (is_node)
                write_ele_fp(o.fp, m);
            else
                write_node_fp(o.fp, m);
            s = st_outfile_commit(&o, err);
        }
        st_outfile_abort(&o);
    }
    free(target);
    free(node);
    free(ele);
    return s;
}

st_status st_tetformat_write(const st_tetmesh *m, st_tetformat f,
                             const char *path, const st_tetformat_opts *opts,
                             st_error *err)
{
    st_tetformat_opts o = {0, 0};
    if (opts)
        o = *opts;
    if (f == ST_TETFORMAT_NONE)
        f = st_tetformat_from_path(path);
    switch (f) {
    case ST_TETFORMAT_MSH:
        return st_tetmesh_write_msh(m, path, o.msh_version, o.binary, err);
    case ST_TETFORMAT_TETGEN: return st_tetmesh_write_tetgen(m, path, err);
    case ST_TETFORMAT_MEDIT: return st_tetmesh_write_medit(m, path, err);
    case ST_TETFORMAT_NONE: break;
    }
    return st_error_set(err, ST_EINPUT, path, 0,
                        "not a .msh, .node, .ele or .mesh path");
}

st_status st_tetformat_save(const st_tetmesh *m, st_tetformat f,
                            const char *path, const st_tetformat_opts *opts,
                            st_error *err)
{
    st_tetformat_opts o = {0, 0};
    if (opts)
        o = *opts;
    if (!path || st_path_is_stdio(path))
        return st_error_set(err, ST_EINPUT, NULL, 0,
                            "msh, TetGen and Medit meshes are written to "
                            "files, not stdout");
    if (f == ST_TETFORMAT_NONE)
        f = st_tetformat_from_path(path);
    if (f == ST_TETFORMAT_NONE)
        return st_error_set(err, ST_EINPUT, path, 0,
                            "not a .msh, .node, .ele or .mesh path");
    int version = norm_version(o.msh_version);
    st_status s = check_writable(m, f, version, o.binary, path, err);
    if (s)
        return s;
    char *names[2] = {NULL, NULL};
    int nfiles = 1;
    if (f == ST_TETFORMAT_TETGEN) {
        if ((s = tetgen_names(path, &names[0], &names[1], err)))
            return s;
        nfiles = 2;
    } else {
        names[0] = st_strdup(path);
        if (!names[0])
            return st_error_set(err, ST_ENOMEM, path, 0, "out of memory");
    }
    st_outfile out[2];
    memset(out, 0, sizeof out);
    int begun = 0;
    for (; begun < nfiles; begun++)
        if ((s = st_outfile_begin(&out[begun], names[begun], 1, err)))
            break;
    if (!s) {
        if (f == ST_TETFORMAT_MSH)
            write_msh_fp(out[0].fp, m, version, o.binary ? 1 : 0);
        else if (f == ST_TETFORMAT_MEDIT)
            write_medit_fp(out[0].fp, m);
        else {
            write_node_fp(out[0].fp, m);
            write_ele_fp(out[1].fp, m);
        }
        /* Check both streams before renaming either. */
        for (int i = 0; i < nfiles && !s; i++)
            if (fflush(out[i].fp) != 0 || ferror(out[i].fp))
                s = st_error_set(err, ST_EIO, names[i], 0,
                                 "write failed: %s", strerror(errno));
        for (int i = 0; i < nfiles && !s; i++)
            s = st_outfile_commit(&out[i], err);
    }
    for (int i = 0; i < begun; i++)
        st_outfile_abort(&out[i]);
    free(names[0]);
    free(names[1]);
    return s;
}
