/*
 * tetformat_msh.c - Gmsh .msh 4.1 and 2.2, ASCII and binary: reader and
 * writer (see tetformat.h).
 *
 * References: the Gmsh reference manual, section "MSH file format" (4.1)
 * and its "legacy formats" appendix (2.2).
 */
#include "souptet/tetformat.h"
#include "../base/fpenv.h"
#include "souptet/mem.h"
#include "souptet/outfile.h"
#include "tetformat_internal.h"
#include "../base/fileio.h"

#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

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
    if (st_rd_left(r) < sz)
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
                       st_text_quote(q, sizeof q, tok, n));
    }
    return ST_OK;
}

/* A count or tag: a size_t in 4.1 binary, a text integer otherwise. */
static st_status msh_size(msh *ms, uint64_t *v, const char *what)
{
    if (ms->r.binary && ms->version == 41)
        return bin_uint(ms, (size_t)ms->dsize, v, what);
    long long x;
    st_status s = st_rd_int_in(&ms->r, &x, 0, LLONG_MAX, what);
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
    return st_rd_int(&ms->r, v, what);
}

static st_status msh_coord(msh *ms, double *v)
{
    if (!ms->r.binary)
        return st_rd_double(&ms->r, v, "coordinate");
    st_status s = bin_f64(ms, v, "a node's coordinates");
    if (!s && !isfinite(*v))
        return st_rd_fail_at(&ms->r, ST_EINPUT, ms->r.t.p - 8,
                          "coordinate is not finite");
    return s;
}

static st_status msh_add_tag(msh *ms, uint64_t tag)
{
    if (ms->ntags == ms->cap_tags) {
        size_t nc = ms->cap_tags < 64 ? 64 : ms->cap_tags * 2;
        tagidx *nt = st_realloc_array(ms->tags, nc, sizeof *nt);
        if (!nt)
            return st_rd_fail_at(&ms->r, ST_ENOMEM, ms->r.t.p, "out of memory");
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
            return st_rd_fail_at(&ms->r, ST_EINPUT, section,
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
    return s ? s : st_rd_point(&ms->r, p);
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
        if ((s = st_rd_count_fits(r, n, r->binary ? 28 : 8, "nodes")))
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
        if ((s = st_rd_count_fits(r, n,
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
    return type == 4 ? st_rd_tet(r, v) : ST_OK;
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
        if ((s = st_rd_count_fits(r, n, r->binary ? 12 : 8, "elements")))
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
                    (s = st_rd_int(r, &type, "element type")) ||
                    (s = msh_type_ok(ms, type)) ||
                    (s = st_rd_int_in(r, &ntags, 0, INT_MAX, "tag count")) ||
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
        if ((s = st_rd_count_fits(r, n, r->binary ? 2 * (size_t)ms->dsize : 4,
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
        const unsigned char *q, *e, *next = st_text_line(p, end, &q, &e);
        if ((size_t)(e - q) >= 4 + nn && memcmp(q, "$End", 4) == 0 &&
            memcmp(q + 4, name, nn) == 0) {
            const unsigned char *z = q + 4 + nn;
            while (z < e && st_text_blank(*z))
                z++;
            if (z == e)
                return p;
        }
        p = next;
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
        st_status s = st_rd_meta_line(r, r->t.p, nl ? nl : stop);
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
    st_status s = st_rd_token(r, &tok, &n, "the format version");
    if (s)
        return s;
    if (st_tok_eq(tok, n, "4.1"))
        ms->version = 41;
    else if (st_tok_eq(tok, n, "2.2") || st_tok_eq(tok, n, "2.1") ||
             st_tok_eq(tok, n, "2.0") || st_tok_eq(tok, n, "2"))
        ms->version = 22;
    else
        return rd_fail(r, "Gmsh format version '%s' is not read (4.1 and "
                       "2.2 are)", st_text_quote(q, sizeof q, tok, n));
    long long ftype, dsize;
    if ((s = st_rd_int_in(r, &ftype, 0, 1, "file type")) ||
        (s = st_rd_int(r, &dsize, "data size")))
        return s;
    if (ftype == 1) {
        if (ms->version == 41 ? dsize != 4 && dsize != 8 : dsize != 8)
            return rd_fail(r, "binary data size %lld is not read", dsize);
        ms->dsize = (int)dsize;
        st_text_next_line(&r->t);
        r->binary = 1;
        /* The integer 1 in the writer's byte order. */
        if (st_rd_left(r) < 4)
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
        return st_rd_fail_at(r, ST_EINPUT, r->t.begin,
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
                               st_text_quote(q, sizeof q, tok, n));
            st_rd_jump(r, stop);
            st_text_next_line(&r->t);
        } else {
            char q[ST_QUOTE_SIZE];
            s = rd_fail(r, "expected a section ($Nodes, ...), found '%s'",
                        st_text_quote(q, sizeof q, tok, n));
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
    if (st_rd_begin(&ms.r, max_bytes, err, name))
        return ST_ENOMEM;
    st_text_init(&ms.r.t, data, size, 0);
    ms.r.name = name ? name : "<msh>";
    st_status s = msh_parse(&ms);
    free(ms.tags);
    return st_rd_finish(&ms.r, s, out);
}

st_status st_tetmesh_read_msh(st_tetmesh **out, const char *path,
                              size_t max_bytes, st_error *err)
{
    return st_tf_read_with(st_tetmesh_parse_msh, out, path, max_bytes, err);
}

/* ---- Gmsh .msh: writing --------------------------------------------------- */

static void put_u64(FILE *fp, uint64_t v) { fwrite(&v, sizeof v, 1, fp); }
static void put_i32(FILE *fp, int32_t v) { fwrite(&v, sizeof v, 1, fp); }
static void put_f64(FILE *fp, double v) { fwrite(&v, sizeof v, 1, fp); }

/* The physical groups, as gmsh and meshio name them: the volume (3-D,
 * physical 1) and its boundary triangles (2-D, physical 2). The entity
 * tags equal the physical tags, so a reader that mixes the two up still
 * sees the right group. */
#define MSH_VOLUME 1
#define MSH_BOUNDARY 2
/* With parts (parts.h), one volume group per part instead of "volume":
 * part k is physical (and entity) tag MSH_PART + k, named by the part. */
#define MSH_PART 3

/* The physical tag of tet t: the volume, or its part's. */
static int32_t msh_tet_tag(const double *part, size_t nparts, size_t t)
{
    return nparts ? (int32_t)(MSH_PART + st_tf_tet_part(part, nparts, t)) : MSH_VOLUME;
}

static void msh_physical_names(FILE *fp, const st_tetmesh *m, size_t nparts, int volume_only)
{
    if (nparts) {
        fprintf(fp, "$PhysicalNames\n%zu\n", nparts + (volume_only ? 0 : 1));
        if (!volume_only)
            fprintf(fp, "2 %d \"boundary\"\n", MSH_BOUNDARY);
        for (size_t k = 0; k < nparts; k++) {
            char nm[300];
            st_tf_part_name(nm, sizeof nm, m, k);
            fprintf(fp, "3 %zu \"%s\"\n", MSH_PART + k, nm);
        }
        fputs("$EndPhysicalNames\n", fp);
    } else if (volume_only)
        fprintf(fp, "$PhysicalNames\n1\n3 %d \"volume\"\n$EndPhysicalNames\n",
                MSH_VOLUME);
    else
        fprintf(fp, "$PhysicalNames\n2\n2 %d \"boundary\"\n3 %d \"volume\"\n"
                "$EndPhysicalNames\n", MSH_BOUNDARY, MSH_VOLUME);
}

static void msh22_elements(FILE *fp, const st_tetmesh *m, int binary,
                           const uint32_t *faces, size_t nf)
{
    size_t nt = m->ntets;
    const double *part;
    const size_t nparts = st_tf_parts(m, &part);
    fprintf(fp, "$Elements\n%zu\n", nt + nf);
    if (binary && nt) {
        put_i32(fp, 4);
        put_i32(fp, (int32_t)nt);
        put_i32(fp, 2);
    }
    for (size_t i = 0; i < nt; i++) {
        const uint32_t *t = m->tets + 4 * i;
        if (binary) {
            const int32_t tag = msh_tet_tag(part, nparts, i);
            int32_t rec[7] = {(int32_t)(i + 1), tag, tag,
                              (int32_t)(t[0] + 1), (int32_t)(t[1] + 1),
                              (int32_t)(t[2] + 1), (int32_t)(t[3] + 1)};
            fwrite(rec, sizeof rec[0], 7, fp);
        } else {
            const int32_t tag = msh_tet_tag(part, nparts, i);
            fprintf(fp, "%zu 4 2 %d %d %lu %lu %lu %lu\n", i + 1, (int)tag,
                    (int)tag, (unsigned long)t[0] + 1,
                    (unsigned long)t[1] + 1, (unsigned long)t[2] + 1,
                    (unsigned long)t[3] + 1);
        }
    }
    if (binary && nf) {
        put_i32(fp, 2);
        put_i32(fp, (int32_t)nf);
        put_i32(fp, 2);
    }
    for (size_t i = 0; i < nf; i++) {
        const uint32_t *q = faces + 3 * i;
        if (binary) {
            int32_t rec[6] = {(int32_t)(nt + i + 1), MSH_BOUNDARY,
                              MSH_BOUNDARY, (int32_t)(q[0] + 1),
                              (int32_t)(q[1] + 1), (int32_t)(q[2] + 1)};
            fwrite(rec, sizeof rec[0], 6, fp);
        } else {
            fprintf(fp, "%zu 2 2 %d %d %lu %lu %lu\n", nt + i + 1,
                    MSH_BOUNDARY, MSH_BOUNDARY, (unsigned long)q[0] + 1,
                    (unsigned long)q[1] + 1, (unsigned long)q[2] + 1);
        }
    }
    fprintf(fp, "%s$EndElements\n", binary ? "\n" : "");
}

/* One 4.1 entity (a surface or a volume) with one physical tag and, for
 * the volume, the surface bounding it. */
static void msh41_entity(FILE *fp, int binary, int tag, const double lo[3],
                         const double hi[3], int bounded_by)
{
    if (binary) {
        put_i32(fp, tag);
        for (int k = 0; k < 3; k++)
            put_f64(fp, lo[k]);
        for (int k = 0; k < 3; k++)
            put_f64(fp, hi[k]);
        put_u64(fp, 1);
        put_i32(fp, tag);
        put_u64(fp, bounded_by ? 1 : 0);
        if (bounded_by)
            put_i32(fp, bounded_by);
    } else {
        fprintf(fp, "%d %.17g %.17g %.17g %.17g %.17g %.17g 1 %d ", tag,
                lo[0], lo[1], lo[2], hi[0], hi[1], hi[2], tag);
        if (bounded_by)
            fprintf(fp, "1 %d\n", bounded_by);
        else
            fputs("0\n", fp);
    }
}

/* The 4.1 element blocks of the tets: one (the volume's) without parts,
 * one per part that has tets with them, each in tet order (tet i is
 * element i+1). fp NULL: only the count of blocks. */
static size_t msh41_tet_blocks(FILE *fp, const st_tetmesh *m, int binary, const double *part,
                               size_t nparts)
{
    const size_t nt = m->ntets;
    size_t nb = 0;
    for (size_t k = 0; k < (nparts ? nparts : 1) && nt; k++) {
        size_t cnt = 0;
        for (size_t i = 0; i < nt; i++)
            cnt += !nparts || st_tf_tet_part(part, nparts, i) == k;
        if (!cnt)
            continue;
        nb++;
        if (!fp)
            continue;
        const int tag = nparts ? (int)(MSH_PART + k) : MSH_VOLUME;
        if (binary) {
            put_i32(fp, 3);
            put_i32(fp, tag);
            put_i32(fp, 4);
            put_u64(fp, cnt);
        } else {
            fprintf(fp, "3 %d 4 %zu\n", tag, cnt);
        }
        for (size_t i = 0; i < nt; i++) {
            if (nparts && st_tf_tet_part(part, nparts, i) != k)
                continue;
            const uint32_t *t = m->tets + 4 * i;
            if (binary) {
                uint64_t rec[5] = {i + 1, (uint64_t)t[0] + 1, (uint64_t)t[1] + 1,
                                   (uint64_t)t[2] + 1, (uint64_t)t[3] + 1};
                fwrite(rec, sizeof rec[0], 5, fp);
            } else {
                fprintf(fp, "%zu %lu %lu %lu %lu\n", i + 1, (unsigned long)t[0] + 1,
                        (unsigned long)t[1] + 1, (unsigned long)t[2] + 1,
                        (unsigned long)t[3] + 1);
            }
        }
    }
    return nb;
}

void st_tf_write_msh_fp(FILE *fp, const st_tetmesh *m, int version,
                        int binary, int volume_only, const uint32_t *faces,
                        size_t nf)
{
    if (volume_only)
        nf = 0;
    size_t np = m->npoints, nt = m->ntets;
    fprintf(fp, "$MeshFormat\n%s %d 8\n", version == 22 ? "2.2" : "4.1",
            binary);
    if (binary) {
        put_i32(fp, 1);
        fputc('\n', fp);
    }
    fputs("$EndMeshFormat\n", fp);
    const double *part;
    const size_t nparts = st_tf_parts(m, &part);
    msh_physical_names(fp, m, nparts, volume_only);
    if (m->meta.count) {
        fputs("$Comments\n", fp);
        st_tf_put_meta(fp, &m->meta, "");
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
        fprintf(fp, "%s$EndNodes\n", binary ? "\n" : "");
        msh22_elements(fp, m, binary, faces, nf);
        return;
    }

    /* 4.1: the boundary surface entity (tag 2, physical 2) and the volume
     * it bounds (tag 1, physical 1), which holds every node. */
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
    const int nsurf = volume_only ? 0 : 1;
    const size_t nvol = nparts ? nparts : 1;
    const int node_tag = nparts ? MSH_PART : MSH_VOLUME;
    if (binary) {
        put_u64(fp, 0);
        put_u64(fp, 0);
        put_u64(fp, (uint64_t)nsurf);
        put_u64(fp, nvol);
    } else {
        fprintf(fp, "0 0 %d %zu\n", nsurf, nvol);
    }
    if (nsurf)
        msh41_entity(fp, binary, MSH_BOUNDARY, lo, hi, 0);
    for (size_t k = 0; k < nvol; k++)
        msh41_entity(fp, binary, nparts ? (int)(MSH_PART + k) : MSH_VOLUME, lo, hi,
                     nsurf ? MSH_BOUNDARY : 0);
    if (binary)
        fputc('\n', fp);
    fputs("$EndEntities\n$Nodes\n", fp);
    size_t nb = np ? 1 : 0;
    if (binary) {
        put_u64(fp, nb);
        put_u64(fp, np);
        put_u64(fp, np ? 1 : 0);
        put_u64(fp, np);
        if (np) {
            put_i32(fp, 3);
            put_i32(fp, node_tag);
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
            fprintf(fp, "3 %d 0 %zu\n", node_tag, np);
            for (size_t i = 0; i < np; i++)
                fprintf(fp, "%zu\n", i + 1);
            for (size_t i = 0; i < np; i++) {
                const double *p = m->xyz + 3 * i;
                fprintf(fp, "%.17g %.17g %.17g\n", p[0], p[1], p[2]);
            }
        }
    }
    /* The tets are elements 1..nt, the boundary triangles nt+1..nt+nf. */
    fputs("$EndNodes\n$Elements\n", fp);
    size_t ne = nt + nf;
    nb = msh41_tet_blocks(NULL, m, binary, part, nparts) + (nf ? 1 : 0);
    if (binary) {
        put_u64(fp, nb);
        put_u64(fp, ne);
        put_u64(fp, ne ? 1 : 0);
        put_u64(fp, ne);
        msh41_tet_blocks(fp, m, binary, part, nparts);
        if (nf) {
            put_i32(fp, 2);
            put_i32(fp, MSH_BOUNDARY);
            put_i32(fp, 2);
            put_u64(fp, nf);
            for (size_t i = 0; i < nf; i++) {
                const uint32_t *q = faces + 3 * i;
                uint64_t rec[4] = {nt + i + 1, (uint64_t)q[0] + 1,
                                   (uint64_t)q[1] + 1, (uint64_t)q[2] + 1};
                fwrite(rec, sizeof rec[0], 4, fp);
            }
        }
        fputc('\n', fp);
    } else {
        fprintf(fp, "%zu %zu %zu %zu\n", nb, ne, ne ? (size_t)1 : 0, ne);
        msh41_tet_blocks(fp, m, binary, part, nparts);
        if (nf) {
            fprintf(fp, "2 %d 2 %zu\n", MSH_BOUNDARY, nf);
            for (size_t i = 0; i < nf; i++) {
                const uint32_t *q = faces + 3 * i;
                fprintf(fp, "%zu %lu %lu %lu\n", nt + i + 1,
                        (unsigned long)q[0] + 1, (unsigned long)q[1] + 1,
                        (unsigned long)q[2] + 1);
            }
        }
    }
    fputs("$EndElements\n", fp);
}

st_status st_tetmesh_write_msh(const st_tetmesh *m, const char *path,
                               int version, int binary, st_error *err)
{
    return st_tf_write_msh_path(m, path, version, binary, 0, err);
}

st_status st_tf_write_msh_path(const st_tetmesh *m, const char *path,
                               int version, int binary, int volume_only,
                               st_error *err)
{
    version = st_tf_msh_version(version);
    st_status s = st_tf_check_writable(m, ST_TETFORMAT_MSH, version, binary, path,
                                 err);
    if (s)
        return s;
    uint32_t *faces = NULL;
    size_t nfaces = 0;
    if (!volume_only && (s = st_tf_boundary(m, &faces, &nfaces, path, err)))
        return s;
    FILE *fp = st_tf_open_out(path, err);
    if (!fp) {
        free(faces);
        return err ? err->status : ST_EIO;
    }
    st_tf_write_msh_fp(fp, m, version, binary ? 1 : 0, volume_only, faces, nfaces);
    free(faces);
    return st_tf_close_written(fp, path, err);
}
