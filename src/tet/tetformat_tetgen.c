/*
 * tetformat_tetgen.c - TetGen .node/.ele: reader and writer (see tetformat.h).
 *
 * References: TetGen 1.5 user's manual, section 5.2 (.node, .ele).
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
    return st_rd_int_in(r, v, lo, hi, what);
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
    if ((s = st_rd_hash_meta(r)))
        return s;
    if (!tg_next_record(r))
        return rd_fail(r, "empty .node file");
    long long n, dim, nattr, nbm;
    if ((s = st_rd_int_in(r, &n, 0, (long long)UINT32_MAX, "point count")) ||
        (s = tg_opt_int(r, &dim, 3, 0, LLONG_MAX, "dimension")) ||
        (s = tg_opt_int(r, &nattr, 0, 0, INT_MAX, "attribute count")) ||
        (s = tg_opt_int(r, &nbm, 0, 0, 1, "boundary marker flag")))
        return s;
    if (dim != 3)
        return rd_fail(r, "dimension %lld (3 expected)", dim);
    if (n == 0)
        return rd_fail(r, "0 points (the points are then in a .poly file, "
                       "which is not read)");
    if ((s = st_rd_count_fits(r, (unsigned long long)n, 8, "points")))
        return s;
    st_text_next_line(&r->t);
    for (long long i = 0; i < n; i++) {
        if (!tg_next_record(r))
            return rd_fail(r, "file ends after %lld of %lld points", i, n);
        long long idx;
        double p[3];
        if ((s = st_rd_int(r, &idx, "point number")))
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
                (s = st_rd_double(r, &p[k], "coordinate")))
                return s;
        if ((s = st_rd_point(r, p)))
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
    if ((s = st_rd_int_in(r, &n, 0, LLONG_MAX, "tet count")) ||
        (s = tg_opt_int(r, &npt, 4, 0, LLONG_MAX, "nodes per tet")) ||
        (s = tg_opt_int(r, &nreg, 0, 0, 1, "region attribute flag")))
        return s;
    if (npt != 4)
        return rd_fail(r, "%lld nodes per tet (only 4-node tets are read)",
                       npt);
    if (n == 0)
        return rd_fail(r, "0 tets");
    if ((s = st_rd_count_fits(r, (unsigned long long)n, 10, "tets")))
        return s;
    st_text_next_line(&r->t);
    size_t np = r->m->npoints;
    for (long long i = 0; i < n; i++) {
        if (!tg_next_record(r))
            return rd_fail(r, "file ends after %lld of %lld tets", i, n);
        long long idx, v;
        uint32_t t[4];
        if ((s = st_rd_int(r, &idx, "tet number")))
            return s;
        for (int k = 0; k < 4; k++) {
            if ((s = tg_need(r, "4 corners")) ||
                (s = st_rd_int(r, &v, "corner")))
                return s;
            if (v < base || v - base >= (long long)np)
                return rd_fail(r, "corner %lld out of range (points are "
                               "numbered %lld..%lld)", v, base,
                               base + (long long)np - 1);
            t[k] = (uint32_t)(v - base);
        }
        if ((s = st_rd_tet(r, t)))
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
    if (st_rd_begin(&r, max_bytes, err, node_name))
        return ST_ENOMEM;
    st_text_init(&r.t, node, node_size, ST_TEXT_HASH);
    r.name = node_name ? node_name : "<node>";
    long long base = 0;
    st_status s = tg_node(&r, &base);
    if (!s) {
        st_text_init(&r.t, ele, ele_size, ST_TEXT_HASH);
        r.name = ele_name ? ele_name : "<ele>";
        s = tg_ele(&r, base);
    }
    return st_rd_finish(&r, s, out);
}

st_status st_tetmesh_read_tetgen(st_tetmesh **out, const char *path,
                                 size_t max_bytes, st_error *err)
{
    *out = NULL;
    char *node, *ele;
    st_status s = st_tf_tetgen_names(path, &node, &ele, err);
    if (s)
        return s;
    unsigned char *nd = NULL, *ed = NULL;
    size_t nn = 0, en = 0;
    s = st_file_read(node, &nd, &nn, err);
    if (!s)
        s = st_file_read(ele, &ed, &en, err);
    if (!s)
        s = st_tetmesh_parse_tetgen(out, nd, nn, node, ed, en, ele,
                                    max_bytes, err);
    free(nd);
    free(ed);
    free(node);
    free(ele);
    return s;
}


/* ---- TetGen .node / .ele: writing ------------------------------------------ */

void st_tf_write_node_fp(FILE *fp, const st_tetmesh *m)
{
    st_tf_put_meta(fp, &m->meta, "# ");
    fprintf(fp, "%zu 3 0 0\n", m->npoints);
    for (size_t i = 0; i < m->npoints; i++) {
        const double *p = m->xyz + 3 * i;
        fprintf(fp, "%zu %.17g %.17g %.17g\n", i + 1, p[0], p[1], p[2]);
    }
}

void st_tf_write_ele_fp(FILE *fp, const st_tetmesh *m)
{
    /* With parts (parts.h): one attribute, the part index (TetGen's
     * region attribute). */
    const double *part;
    const size_t nparts = st_tf_parts(m, &part);
    fprintf(fp, "%zu 4 %d\n", m->ntets, nparts ? 1 : 0);
    for (size_t i = 0; i < m->ntets; i++) {
        const uint32_t *t = m->tets + 4 * i;
        fprintf(fp, "%zu %lu %lu %lu %lu", i + 1, (unsigned long)t[0] + 1,
                (unsigned long)t[1] + 1, (unsigned long)t[2] + 1,
                (unsigned long)t[3] + 1);
        if (nparts)
            fprintf(fp, " %zu", st_tf_tet_part(part, nparts, i));
        fputc('\n', fp);
    }
}

/* The target of st_outfile's temporary name (outfile.h) for a .node or
 * .ele file, malloc'd; NULL when path is not such a name. */
static char *outfile_target(const char *path)
{
    char *t = st_outfile_target_of(path);
    static const char *const ext[] = {"node", "ele"};
    if (t && st_path_ext_match(t, ext, 2, 0) < 0) {
        free(t);
        return NULL;
    }
    return t;
}

static st_status write_one(const st_tetmesh *m, const char *path,
                           int node, st_error *err)
{
    FILE *fp = st_tf_open_out(path, err);
    if (!fp)
        return err ? err->status : ST_EIO;
    if (node)
        st_tf_write_node_fp(fp, m);
    else
        st_tf_write_ele_fp(fp, m);
    return st_tf_close_written(fp, path, err);
}

st_status st_tetmesh_write_tetgen(const st_tetmesh *m, const char *path,
                                  st_error *err)
{
    char *target = outfile_target(path);
    char *node, *ele;
    st_status s = st_tf_tetgen_names(target ? target : path, &node, &ele, err);
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
                st_tf_write_ele_fp(o.fp, m);
            else
                st_tf_write_node_fp(o.fp, m);
            s = st_outfile_commit(&o, err);
        }
        st_outfile_abort(&o);
    }
    free(target);
    free(node);
    free(ele);
    return s;
}
