/*
 * tetformat_medit.c - Medit .mesh: reader and writer (see tetformat.h).
 *
 * References: the Medit / libMeshb ASCII keyword format (MeshVersionFormatted,
 * Dimension, Vertices, Tetrahedra, End).
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
    if ((s = st_rd_int_in(r, &v, 1, 4, "mesh version")))
        return s;
    int have_vertices = 0;
    while ((n = st_text_token_any(&r->t, &tok)) != 0) {
        if (st_tok_ieq(tok, n, "end"))
            break;
        if (st_tok_ieq(tok, n, "dimension")) {
            if ((s = st_rd_int(r, &v, "dimension")))
                return s;
            if (v != 3)
                return rd_fail(r, "dimension %lld (3 expected)", v);
        } else if (st_tok_ieq(tok, n, "vertices")) {
            if (have_vertices)
                return rd_fail(r, "second Vertices section");
            have_vertices = 1;
            if ((s = st_rd_int_in(r, &v, 0, (long long)UINT32_MAX,
                               "vertex count")) ||
                (s = st_rd_count_fits(r, (unsigned long long)v, 8,
                                   "vertices")))
                return s;
            for (long long i = 0; i < v; i++) {
                double p[3];
                long long ref;
                if ((s = st_rd_xyz(r, p)) ||
                    (s = st_rd_int(r, &ref, "vertex reference")) ||
                    (s = st_rd_point(r, p)))
                    return s;
            }
        } else if (st_tok_ieq(tok, n, "tetrahedra")) {
            if (!have_vertices)
                return rd_fail(r, "Tetrahedra before Vertices");
            if ((s = st_rd_int_in(r, &v, 0, LLONG_MAX, "tet count")) ||
                (s = st_rd_count_fits(r, (unsigned long long)v, 10, "tets")))
                return s;
            long long np = (long long)r->m->npoints;
            for (long long i = 0; i < v; i++) {
                uint32_t t[4];
                long long c, ref;
                for (int k = 0; k < 4; k++) {
                    if ((s = st_rd_int(r, &c, "tet corner")))
                        return s;
                    if (c < 1 || c > np)
                        return rd_fail(r, "tet corner %lld out of range "
                                       "(1..%lld)", c, np);
                    t[k] = (uint32_t)(c - 1);
                }
                if ((s = st_rd_int(r, &ref, "tet reference")) ||
                    (s = st_rd_tet(r, t)))
                    return s;
            }
        } else {
            size_t i;
            for (i = 0; i < sizeof k_medit_volume / sizeof *k_medit_volume;
                 i++)
                if (st_tok_ieq(tok, n, k_medit_volume[i]))
                    return rd_fail(r, "'%s': only tetrahedra are read",
                                   st_text_quote(q, sizeof q, tok, n));
            for (i = 0; i < sizeof k_medit_skip / sizeof *k_medit_skip; i++)
                if (st_tok_ieq(tok, n, k_medit_skip[i].kw))
                    break;
            if (i == sizeof k_medit_skip / sizeof *k_medit_skip)
                return rd_fail(r, "unknown keyword '%s'",
                               st_text_quote(q, sizeof q, tok, n));
            if ((s = st_rd_int_in(r, &v, 0, LLONG_MAX, "record count")))
                return s;
            int per = k_medit_skip[i].per;
            if ((s = st_rd_count_fits(r, (unsigned long long)v,
                                   2 * (size_t)per, "records")))
                return s;
            for (long long j = 0; j < v * per; j++) {
                double x;
                if ((s = st_rd_double(r, &x, "value")))
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
    if (st_rd_begin(&r, max_bytes, err, name))
        return ST_ENOMEM;
    st_text_init(&r.t, data, size, ST_TEXT_HASH);
    r.name = name ? name : "<mesh>";
    st_status s = st_rd_hash_meta(&r);
    if (!s)
        s = medit_parse(&r);
    return st_rd_finish(&r, s, out);
}

st_status st_tetmesh_read_medit(st_tetmesh **out, const char *path,
                                size_t max_bytes, st_error *err)
{
    return st_tf_read_with(st_tetmesh_parse_medit, out, path, max_bytes, err);
}

/* ---- Medit .mesh: writing ------------------------------------------------ */

void st_tf_write_medit_fp(FILE *fp, const st_tetmesh *m,
                          const uint32_t *faces, size_t nfaces)
{
    fputs("MeshVersionFormatted 2\n", fp);
    st_tf_put_meta(fp, &m->meta, "# ");
    fprintf(fp, "\nDimension 3\n\nVertices\n%zu\n", m->npoints);
    for (size_t i = 0; i < m->npoints; i++) {
        const double *p = m->xyz + 3 * i;
        fprintf(fp, "%.17g %.17g %.17g 0\n", p[0], p[1], p[2]);
    }
    /* The tets' reference: 1, or with parts (parts.h) part index + 1. */
    const double *part;
    const size_t nparts = st_tf_parts(m, &part);
    fprintf(fp, "\nTetrahedra\n%zu\n", m->ntets);
    for (size_t i = 0; i < m->ntets; i++) {
        const uint32_t *t = m->tets + 4 * i;
        fprintf(fp, "%lu %lu %lu %lu %zu\n", (unsigned long)t[0] + 1,
                (unsigned long)t[1] + 1, (unsigned long)t[2] + 1,
                (unsigned long)t[3] + 1, nparts ? st_tf_tet_part(part, nparts, i) + 1 : 1);
    }
    /* The boundary, outward, with reference 2. */
    if (nfaces) {
        fprintf(fp, "\nTriangles\n%zu\n", nfaces);
        for (size_t i = 0; i < nfaces; i++) {
            const uint32_t *q = faces + 3 * i;
            fprintf(fp, "%lu %lu %lu 2\n", (unsigned long)q[0] + 1,
                    (unsigned long)q[1] + 1, (unsigned long)q[2] + 1);
        }
    }
    fputs("\nEnd\n", fp);
}

st_status st_tetmesh_write_medit(const st_tetmesh *m, const char *path,
                                 st_error *err)
{
    return st_tf_write_medit_path(m, path, 0, err);
}

st_status st_tf_write_medit_path(const st_tetmesh *m, const char *path,
                                 int volume_only, st_error *err)
{
    uint32_t *faces = NULL;
    size_t nfaces = 0;
    st_status s = volume_only ? ST_OK : st_tf_boundary(m, &faces, &nfaces, path, err);
    if (s)
        return s;
    FILE *fp = st_tf_open_out(path, err);
    if (!fp) {
        free(faces);
        return err ? err->status : ST_EIO;
    }
    st_tf_write_medit_fp(fp, m, faces, nfaces);
    free(faces);
    return st_tf_close_written(fp, path, err);
}
