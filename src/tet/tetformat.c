/*
 * tetformat.c - Gmsh .msh (4.1, 2.2; ASCII, binary), TetGen .node/.ele and
 * Medit .mesh readers and writers (see tetformat.h).
 *
 * References: the Gmsh reference manual, section "MSH file format" (4.1)
 * and its "legacy formats" appendix (2.2); TetGen 1.5 user's manual,
 * section 5.2 (.node, .ele); the Medit / libMeshb ASCII keyword format
 * (MeshVersionFormatted, Dimension, Vertices, Tetrahedra, End).
 *
 * This file: the names, the shared reading and writing helpers, the
 * dispatch and the atomic save; each format in its own file
 * (tetformat_msh.c, tetformat_tetgen.c, tetformat_medit.c), the parsing
 * state they share in tetformat_read.h (tetformat_read.c).
 *
 * Every reader parses a whole file held in memory through the bounded
 * cursor of lexer.h (the buffer is never NUL-terminated), converts
 * numbers from tokens, and grows the mesh only with records actually
 * present (st_tetmesh_add_point / add_tet grow geometrically): a header
 * count is checked against the bytes left before it is believed, only to
 * give a clear message early. Binary .msh data is read through a byte
 * cursor over the same buffer that stops at its end.
 */
#include "souptet/tetformat.h"
#include "../base/fpenv.h"
#include "souptet/mem.h"
#include "souptet/outfile.h"
#include "tetformat_internal.h"
#include "../base/fileio.h"
#include "souptet/pred.h"
#include "souptet/parts.h"

#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

/* ---- names and paths ----------------------------------------------------- */

st_tetformat st_tetformat_from_path(const char *path)
{
    static const char *const ext[] = {"vtu", "msh", "node", "ele", "mesh"};
    static const st_tetformat fmt[] = {
        ST_TETFORMAT_VTU, ST_TETFORMAT_MSH, ST_TETFORMAT_TETGEN,
        ST_TETFORMAT_TETGEN, ST_TETFORMAT_MEDIT};
    if (st_path_is_stdio(path))
        return ST_TETFORMAT_VTU;
    /* st_outfile's temporary name (outfile.h) too: its target's. */
    int k = st_path_ext_match(path, ext, 5, 1);
    return k < 0 ? ST_TETFORMAT_NONE : fmt[k];
}

const char *st_tetformat_name(st_tetformat f)
{
    switch (f) {
    case ST_TETFORMAT_VTU: return "vtu";
    case ST_TETFORMAT_MSH: return "msh";
    case ST_TETFORMAT_TETGEN: return "tetgen";
    case ST_TETFORMAT_MEDIT: return "medit";
    case ST_TETFORMAT_NONE: break;
    }
    return "none";
}

st_tetformat st_tetformat_sniff(const unsigned char *data, size_t size)
{
    if (st_looks_like_xml(data, size))
        return ST_TETFORMAT_VTU;
    st_text t;
    st_text_init(&t, data, size, ST_TEXT_HASH);
    const unsigned char *tok = NULL;
    size_t n = st_text_token_any(&t, &tok);
    if (st_tok_eq(tok, n, "$MeshFormat"))
        return ST_TETFORMAT_MSH;
    if (st_tok_ieq(tok, n, "meshversionformatted"))
        return ST_TETFORMAT_MEDIT;
    return ST_TETFORMAT_NONE;
}

/* base.node and base.ele for a TetGen path (.node, .ele or a base name). */
st_status st_tf_tetgen_names(const char *path, char **node, char **ele,
                              st_error *err)
{
    static const char *const ext[] = {"node", "ele"};
    size_t n = strlen(path), keep = n;
    if (st_path_ext_match(path, ext, 2, 0) >= 0)
        keep = (size_t)(strrchr(path, '.') - path);
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

/* ---- reading files --------------------------------------------------------- */

st_status st_tf_read_with(st_tf_parser parse, st_tetmesh **out,
                           const char *path, size_t max_bytes, st_error *err)
{
    *out = NULL;
    unsigned char *data;
    size_t size;
    st_status s = st_file_read(path, &data, &size, err);
    if (s)
        return s;
    if (size == 0)
        s = st_error_set(err, ST_EINPUT, path, 0, "empty file");
    else
        s = parse(out, data, size, path, max_bytes, err);
    free(data);
    return s;
}

/* ---- writing ------------------------------------------------------------- */

/* Meta entries as "PREFIXsouptet KEY: LINE" lines, one per line of the
 * value; keys that could not be read back (blanks, ':') are left out. */
void st_tf_put_meta(FILE *fp, const st_meta *meta, const char *prefix)
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

int st_tf_msh_version(int v)
{
    if (v == 0 || v == 4 || v == 41)
        return 41;
    if (v == 2 || v == 22)
        return 22;
    return -1;
}

/* What no file of format f can hold. */
st_status st_tf_check_writable(const st_tetmesh *m, st_tetformat f,
                                int version, int binary, const char *path,
                                st_error *err)
{
    if (f == ST_TETFORMAT_MSH && version < 0)
        return st_error_set(err, ST_EINPUT, path, 0,
                            "msh version must be 41 or 22");
    /* Elements are the tets and their boundary faces (at most 4 each). */
    if (f == ST_TETFORMAT_MSH && version == 22 && binary &&
        (m->npoints > INT32_MAX || m->ntets > INT32_MAX / 5))
        return st_error_set(err, ST_ELIMIT, path, 0,
                            "msh 2.2 binary holds at most %ld nodes and "
                            "%ld tets (with their boundary faces, %ld "
                            "elements)", (long)INT32_MAX,
                            (long)(INT32_MAX / 5), (long)INT32_MAX);
    return ST_OK;
}

st_status st_tf_boundary(const st_tetmesh *m, uint32_t **faces,
                         size_t *nfaces, const char *path, st_error *err)
{
    uint32_t *owner = NULL;
    st_status s = st_tetmesh_boundary(m, faces, &owner, nfaces, err);
    if (s) {
        if (err && !err->file[0] && path) {
            char msg[sizeof err->msg];
            snprintf(msg, sizeof msg, "%s", err->msg);
            return st_error_set(err, s, path, 0, "%s", msg);
        }
        return s;
    }
    for (size_t f = 0; f < *nfaces; f++) {
        const uint32_t *t = m->tets + 4 * (size_t)owner[f];
        /* Positive orientation (tetmesh.h) is st_orient3d < 0. */
        if (st_orient3d(m->xyz + 3 * (size_t)t[0], m->xyz + 3 * (size_t)t[1],
                        m->xyz + 3 * (size_t)t[2],
                        m->xyz + 3 * (size_t)t[3]) > 0) {
            uint32_t *q = *faces + 3 * f;
            uint32_t x = q[1];
            q[1] = q[2];
            q[2] = x;
        }
    }
    free(owner);
    return ST_OK;
}

/* fp was written by one of the writers: flush, close, report. */
st_status st_tf_close_written(FILE *fp, const char *path, st_error *err)
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

FILE *st_tf_open_out(const char *path, st_error *err)
{
    FILE *fp = fopen(path, "wb");
    if (!fp)
        st_error_set(err, ST_EIO, path, 0, "cannot create: %s",
                     strerror(errno));
    return fp;
}

st_status st_tf_save(const st_tetmesh *m, st_tetformat f, const char *path,
                     const st_tetformat_opts *opts, st_error *err)
{
    st_tetformat_opts o = {0};
    if (opts)
        o = *opts;
    if (!path || st_path_is_stdio(path))
        return st_error_set(err, ST_EINPUT, NULL, 0,
                            "msh, TetGen and Medit meshes are written to "
                            "files, not stdout");
    if (f == ST_TETFORMAT_NONE)
        f = st_tetformat_from_path(path);
    if (f != ST_TETFORMAT_MSH && f != ST_TETFORMAT_TETGEN &&
        f != ST_TETFORMAT_MEDIT)
        return st_error_set(err, ST_EINPUT, path, 0,
                            "not a .msh, .node, .ele or .mesh path");
    int version = st_tf_msh_version(o.msh_version);
    st_status s = st_tf_check_writable(m, f, version, o.binary, path, err);
    if (s)
        return s;
    uint32_t *faces = NULL;
    size_t nfaces = 0;
    if (f != ST_TETFORMAT_TETGEN && !o.volume_only &&
        (s = st_tf_boundary(m, &faces, &nfaces, path, err)))
        return s;
    char *names[2] = {NULL, NULL};
    int nfiles = 1;
    if (f == ST_TETFORMAT_TETGEN) {
        if ((s = st_tf_tetgen_names(path, &names[0], &names[1], err)))
            return s;
        nfiles = 2;
    } else {
        names[0] = st_strdup(path);
        if (!names[0]) {
            free(faces);
            return st_error_set(err, ST_ENOMEM, path, 0, "out of memory");
        }
    }
    st_outfile out[2];
    memset(out, 0, sizeof out);
    int begun = 0;
    for (; begun < nfiles; begun++)
        if ((s = st_outfile_begin(&out[begun], names[begun], 1, err)))
            break;
    if (!s) {
        if (f == ST_TETFORMAT_MSH)
            st_tf_write_msh_fp(out[0].fp, m, version, o.binary ? 1 : 0,
                               o.volume_only, faces, nfaces);
        else if (f == ST_TETFORMAT_MEDIT)
            st_tf_write_medit_fp(out[0].fp, m, faces, nfaces);
        else {
            st_tf_write_node_fp(out[0].fp, m);
            st_tf_write_ele_fp(out[1].fp, m);
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
    free(faces);
    return s;
}

/* ---- parts (parts.h) ------------------------------------------------------ */

size_t st_tf_parts(const st_tetmesh *m, const double **part)
{
    *part = NULL;
    const st_tet_array *a = st_tetmesh_find_array(m, "part", ST_ON_CELLS);
    if (!a || a->ncomp != 1 || m->ntets == 0)
        return 0;
    size_t n = 1;
    const char *v = st_meta_get(&m->meta, "parts");
    if (v) {
        char *end = NULL;
        unsigned long long c = strtoull(v, &end, 10);
        if (*v && !*end && c >= 1 && c <= ST_PARTS_MAX)
            n = (size_t)c;
    }
    for (size_t t = 0; t < m->ntets; t++) {
        const double x = a->values[t];
        if (x >= 0 && x < ST_PARTS_MAX && x == floor(x) && (size_t)x >= n)
            n = (size_t)x + 1;
    }
    *part = a->values;
    return n;
}

void st_tf_part_name(char *buf, size_t size, const st_tetmesh *m, size_t k)
{
    char key[48];
    snprintf(key, sizeof key, "part_name_%zu", k);
    const char *v = st_meta_get(&m->meta, key);
    if (v && *v)
        snprintf(buf, size, "%s", v);
    else
        snprintf(buf, size, "part_%zu", k);
    for (char *c = buf; *c; c++)
        if (*c == '"' || *c == '\\' || (unsigned char)*c < 0x20 || *c == 0x7f)
            *c = '_';
}
