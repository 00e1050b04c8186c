/*
 * tetio.c - the front door for tet meshes: which format to read or
 * write, atomic output, and the pipes (see tetio.h).
 *
 * The dispatch only: .vtu itself lives in the VTK adapter
 * (src/adapters/tetio_vtu.cpp), Gmsh, TetGen and Medit files in
 * tetformat_*.c. Standard input is read whole (VTK's XML reader cannot
 * read a pipe as it goes: it seeks to the appended data) and parsed from
 * memory; standard output gets the same document written to memory
 * first, so a failure leaves nothing half-written on the pipe.
 */
#include "souptet/tetio.h"
#include "souptet/outfile.h"
#include "souptet/tetformat.h"
#include "adapters/tetio_internal.h"
#include "fileio.h"
#include "tetformat_internal.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define UNKNOWN_FORMAT "unknown tet mesh format (use .vtu, .msh, .node, .mesh)"

st_status st_tetmesh_write_mem(unsigned char **data, size_t *size,
                               const st_tetmesh *m, st_error *err)
{
    return st_tetio_write_vtu_mem(data, size, m, err);
}

st_status st_tetmesh_write(const st_tetmesh *m, const char *path,
                           const st_tetformat_opts *opts, st_error *err)
{
    st_tetformat_opts o = {0};
    if (opts)
        o = *opts;
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
            return st_error_set(err, ST_EIO, ST_STDOUT_NAME, 0,
                                "write failed: %s",
                                strerror(put != size ? e : errno));
        return ST_OK;
    }
    /* A temporary name of st_outfile_begin gives its target's format. */
    switch (st_tetformat_from_path(path)) {
    case ST_TETFORMAT_VTU: return st_tetio_write_vtu_file(m, path, err);
    case ST_TETFORMAT_MSH:
        return st_tf_write_msh_path(m, path, o.msh_version, o.binary, o.volume_only, err);
    case ST_TETFORMAT_TETGEN: return st_tetmesh_write_tetgen(m, path, err);
    case ST_TETFORMAT_MEDIT: return st_tf_write_medit_path(m, path, o.volume_only, err);
    case ST_TETFORMAT_NONE: break;
    }
    return st_error_set(err, ST_EINPUT, path, 0, UNKNOWN_FORMAT);
}

st_status st_tetmesh_read_mem(st_tetmesh **out, const unsigned char *data,
                              size_t size, const char *name,
                              size_t max_bytes, st_error *err)
{
    *out = NULL;
    if (!name)
        name = ST_STDIN_NAME;
    if (size == 0)
        return st_error_set(err, ST_EINPUT, name, 0, "empty input");
    /* Gmsh and Medit files say what they are in their first bytes (TetGen
     * comes as two files and never on a pipe). */
    switch (st_tetformat_sniff(data, size)) {
    case ST_TETFORMAT_MSH:
        return st_tetmesh_parse_msh(out, data, size, name, max_bytes, err);
    case ST_TETFORMAT_MEDIT:
        return st_tetmesh_parse_medit(out, data, size, name, max_bytes, err);
    case ST_TETFORMAT_VTU:
        return st_tetio_read_vtu_mem(out, data, size, name, max_bytes, err);
    default: break;
    }
    return st_error_set(err, ST_EINPUT, name, 0,
                        "not a tet mesh: expected a .vtu (VTK XML), "
                        ".msh or .mesh document");
}

st_status st_tetmesh_read(st_tetmesh **out, const char *path,
                          size_t max_bytes, st_error *err)
{
    *out = NULL;
    if (st_path_is_stdio(path)) {
        unsigned char *data;
        size_t size;
        st_status s = st_file_read(NULL, &data, &size, err);
        if (s)
            return s;
        s = st_tetmesh_read_mem(out, data, size, ST_STDIN_NAME, max_bytes,
                                err);
        free(data);
        return s;
    }
    st_tetformat f = st_tetformat_from_path(path);
    if (f == ST_TETFORMAT_NONE) {
        /* No known extension: look at the first bytes. */
        unsigned char head[64];
        size_t n;
        st_status s = st_file_head(path, head, sizeof head, &n, err);
        if (s)
            return s;
        f = st_tetformat_sniff(head, n);
    }
    switch (f) {
    case ST_TETFORMAT_VTU:
        return st_tetio_read_vtu_file(out, path, max_bytes, err);
    case ST_TETFORMAT_MSH:
        return st_tetmesh_read_msh(out, path, max_bytes, err);
    case ST_TETFORMAT_TETGEN:
        return st_tetmesh_read_tetgen(out, path, max_bytes, err);
    case ST_TETFORMAT_MEDIT:
        return st_tetmesh_read_medit(out, path, max_bytes, err);
    case ST_TETFORMAT_NONE: break;
    }
    return st_error_set(err, ST_EINPUT, path, 0, UNKNOWN_FORMAT);
}

st_status st_tetmesh_save(const st_tetmesh *m, const char *path,
                          const st_tetformat_opts *opts, st_error *err)
{
    if (st_path_is_stdio(path))
        return st_tetmesh_write(m, NULL, opts, err);
    st_tetformat f = st_tetformat_from_path(path);
    if (f == ST_TETFORMAT_NONE)
        return st_error_set(err, ST_EINPUT, path, 0, UNKNOWN_FORMAT);
    if (f != ST_TETFORMAT_VTU)    /* atomic for both files of a TetGen pair */
        return st_tf_save(m, f, path, opts, err);
    st_outfile o;
    st_status s = st_outfile_begin(&o, path, 0, err);
    if (s)
        return s;
    s = st_tetio_write_vtu_file(m, o.tmp, err);
    if (s) {
        /* Name the target, not the temporary file. */
        if (err && strcmp(err->file, o.tmp) == 0)
            snprintf(err->file, sizeof err->file, "%s", path);
        st_outfile_abort(&o);
        return s;
    }
    return st_outfile_commit(&o, err);
}
