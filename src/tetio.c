/*
 * tetio.c - which tet mesh format to read or write, and the pipes (see
 * tetio.h).
 *
 * The dispatch only: .vtu itself lives in the VTK adapter
 * (src/adapters/tetio_vtu.cpp), Gmsh, TetGen and Medit files in
 * tetformat.c. Standard input is read whole (VTK's XML
 * reader cannot read a pipe as it goes: it seeks to the appended data)
 * and parsed from memory; standard output gets the same document written
 * to memory first, so a failure leaves nothing half-written on the pipe.
 */
#include "souptet/tetio.h"
#include "souptet/mem.h"
#include "souptet/outfile.h"
#include "souptet/tetformat.h"
#include "adapters/gridio_internal.h"
#include "adapters/tetio_internal.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

static st_tet_format format_of_name(const char *path)
{
    const char *base = strrchr(path, '/');
    base = base ? base + 1 : path;
    const char *dot = strrchr(base, '.');
    if (!dot || dot == base)    /* ".vtu" alone is a hidden file, no ext */
        return ST_TET_FMT_UNKNOWN;
    if (strcasecmp(dot, ".vtu") == 0)
        return ST_TET_FMT_VTU;
    return ST_TET_FMT_UNKNOWN;
}

static st_tet_format from_tetformat(st_tetformat f)
{
    switch (f) {
    case ST_TETFORMAT_MSH: return ST_TET_FMT_MSH;
    case ST_TETFORMAT_TETGEN: return ST_TET_FMT_TETGEN;
    case ST_TETFORMAT_MEDIT: return ST_TET_FMT_MEDIT;
    default: return ST_TET_FMT_UNKNOWN;
    }
}

static st_tetformat to_tetformat(st_tet_format f)
{
    switch (f) {
    case ST_TET_FMT_MSH: return ST_TETFORMAT_MSH;
    case ST_TET_FMT_TETGEN: return ST_TETFORMAT_TETGEN;
    case ST_TET_FMT_MEDIT: return ST_TETFORMAT_MEDIT;
    default: return ST_TETFORMAT_NONE;
    }
}

st_tet_format st_tet_format_from_path(const char *path)
{
    if (st_path_is_stdio(path))
        return ST_TET_FMT_VTU;
    st_tet_format f = format_of_name(path);
    return f != ST_TET_FMT_UNKNOWN ? f
                                   : from_tetformat(st_tetformat_from_path(path));
}

/* The format of a path st_outfile_begin made: its target's. */
static st_tet_format format_for_writing(const char *path)
{
    st_tet_format f = st_tet_format_from_path(path);
    if (f != ST_TET_FMT_UNKNOWN)
        return f;
    char *p = st_outfile_target_of(path);
    if (!p)
        return ST_TET_FMT_UNKNOWN;
    f = format_of_name(p);
    free(p);
    return f;
}

st_status st_tetmesh_write_mem(unsigned char **data, size_t *size,
                               const st_tetmesh *m, st_error *err)
{
    return st_tetio_write_vtu_mem(data, size, m, err);
}

st_status st_tetmesh_write(const st_tetmesh *m, const char *path,
                           st_error *err)
{
    if (st_path_is_stdio(path)) {
        unsigned char *data;
        size_t size;
        st_status s = st_tetio_write_vtu_mem(&data, &size, m, err);
        if (s)
            return s;
        size_t put = fwrite(data, 1, size, stdout);
        int e = errno;
        free(data);
        if (put != size || fflush(stdout) != 0)
            return st_error_set(err, ST_EIO, ST_TETIO_STDOUT_NAME, 0,
                                "write failed: %s",
                                strerror(put != size ? e : errno));
        return ST_OK;
    }
    st_tet_format f = format_for_writing(path);
    switch (f) {
    case ST_TET_FMT_VTU: return st_tetio_write_vtu_file(m, path, err);
    case ST_TET_FMT_MSH:
    case ST_TET_FMT_TETGEN:
    case ST_TET_FMT_MEDIT:
        return st_tetformat_write(m, to_tetformat(f), path, NULL, err);
    default: break;
    }
    return st_error_set(err, ST_EINPUT, path, 0,
                        "unknown tet mesh format (use .vtu, .msh, .node, "
                        ".mesh)");
}

/* VTK XML, by its first significant byte: '<' after an optional UTF-8
 * byte-order mark and white space. */
static int looks_like_xml(const unsigned char *p, size_t n)
{
    size_t i = 0;
    if (n >= 3 && p[0] == 0xEF && p[1] == 0xBB && p[2] == 0xBF)
        i = 3;
    while (i < n && (p[i] == ' ' || p[i] == '\t' || p[i] == '\r' ||
                     p[i] == '\n'))
        i++;
    return i < n && p[i] == '<';
}

st_status st_tetmesh_read_mem(st_tetmesh **out, const unsigned char *data,
                              size_t size, const char *name,
                              size_t max_bytes, st_error *err)
{
    *out = NULL;
    if (!name)
        name = ST_TETIO_STDIN_NAME;
    if (size == 0)
        return st_error_set(err, ST_EINPUT, name, 0, "empty input");
    /* Gmsh and Medit files say what they are in their first bytes (TetGen
     * comes as two files and never on a pipe). */
    st_tetformat tf = st_tetformat_sniff(data, size);
    if (tf == ST_TETFORMAT_MSH)
        return st_tetmesh_parse_msh(out, data, size, name, max_bytes, err);
    if (tf == ST_TETFORMAT_MEDIT)
        return st_tetmesh_parse_medit(out, data, size, name, max_bytes, err);
    if (!looks_like_xml(data, size))
        return st_error_set(err, ST_EINPUT, name, 0,
                            "not a tet mesh: expected a .vtu (VTK XML), "
                            ".msh or .mesh document");
    return st_tetio_read_vtu_mem(out, data, size, name, max_bytes, err);
}

st_status st_tetmesh_read(st_tetmesh **out, const char *path,
                          size_t max_bytes, st_error *err)
{
    *out = NULL;
    if (st_path_is_stdio(path)) {
        unsigned char *data;
        size_t size;
        st_status s = st_gridio_read_stdin(&data, &size, err);
        if (s)
            return s;
        s = st_tetmesh_read_mem(out, data, size, ST_TETIO_STDIN_NAME,
                                max_bytes, err);
        free(data);
        return s;
    }
    st_tet_format f = st_tet_format_from_path(path);
    if (f == ST_TET_FMT_VTU)
        return st_tetio_read_vtu_file(out, path, max_bytes, err);
    if (f != ST_TET_FMT_UNKNOWN)
        return st_tetformat_read(out, to_tetformat(f), path, max_bytes, err);
    /* No known extension: look at the first bytes. */
    FILE *fp = fopen(path, "rb");
    if (!fp)
        return st_error_set(err, ST_EIO, path, 0, "cannot open: %s",
                            strerror(errno));
    unsigned char head[64];
    size_t n = fread(head, 1, sizeof head, fp);
    int bad = ferror(fp);
    int e = errno;
    fclose(fp);
    if (bad)
        return st_error_set(err, ST_EIO, path, 0, "read failed: %s",
                            strerror(e));
    if (n == 0)
        return st_error_set(err, ST_EINPUT, path, 0, "empty file");
    if (looks_like_xml(head, n))
        return st_tetio_read_vtu_file(out, path, max_bytes, err);
    if (st_tetformat_sniff(head, n) != ST_TETFORMAT_NONE)
        return st_tetformat_read(out, st_tetformat_sniff(head, n), path,
                                 max_bytes, err);
    return st_error_set(err, ST_EINPUT, path, 0,
                        "unknown tet mesh format (use .vtu, .msh, .node, "
                        ".mesh)");
}

st_status st_tetmesh_save(const st_tetmesh *m, const char *path,
                          st_error *err)
{
    if (st_path_is_stdio(path))
        return st_tetmesh_write(m, NULL, err);
    st_tet_format f = st_tet_format_from_path(path);
    if (f == ST_TET_FMT_UNKNOWN)
        return st_error_set(err, ST_EINPUT, path, 0,
                            "unknown tet mesh format (use .vtu, .msh, "
                            ".node, .mesh)");
    if (f != ST_TET_FMT_VTU)    /* atomic for both files of a TetGen pair */
        return st_tetformat_save(m, to_tetformat(f), path, NULL, err);
    st_outfile o;
    st_status s = st_outfile_begin(&o, path, 0, err);
    if (s)
        return s;
    s = st_tetmesh_write(m, o.tmp, err);
    if (s) {
        /* Name the target, not the temporary file. */
        if (err && strcmp(err->file, o.tmp) == 0)
            snprintf(err->file, sizeof err->file, "%s", path);
        st_outfile_abort(&o);
        return s;
    }
    return st_outfile_commit(&o, err);
}
