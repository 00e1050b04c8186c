/*
 * tetio_write.c - the front door for writing tet meshes: which format,
 * atomic output, and the pipes (see tetio.h).
 *
 * Every format is written by the core (tetformat_*.c, .vtu included), so
 * this object needs neither VTK nor OpenVDB: a tool that writes meshes
 * but reads none (soupmesh) links without them (issue 41: their loading
 * cost every process about 60 ms). Standard output gets the .vtu document
 * written to memory first, so a failure leaves nothing half-written on
 * the pipe.
 */
#include "souptet/tetio.h"
#include "souptet/outfile.h"
#include "souptet/tetformat.h"
#include "../base/fileio.h"
#include "../tet/tetformat_write.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define UNKNOWN_FORMAT "unknown tet mesh format (use .vtu, .msh, .node, .mesh)"

st_status st_tetmesh_write_mem(unsigned char **data, size_t *size,
                               const st_tetmesh *m, st_error *err)
{
    return st_tf_write_vtu_mem(data, size, m, ST_STDOUT_NAME, err);
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
        st_status s = st_tf_write_vtu_mem(&data, &size, m, ST_STDOUT_NAME, err);
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
    case ST_TETFORMAT_VTU: return st_tf_write_vtu_path(m, path, err);
    case ST_TETFORMAT_MSH:
        return st_tf_write_msh_path(m, path, o.msh_version, o.binary, o.volume_only, err);
    case ST_TETFORMAT_TETGEN: return st_tetmesh_write_tetgen(m, path, err);
    case ST_TETFORMAT_MEDIT: return st_tf_write_medit_path(m, path, o.volume_only, err);
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
    s = st_tf_write_vtu_path(m, o.tmp, err);
    if (s) {
        /* Name the target, not the temporary file. */
        if (err && strcmp(err->file, o.tmp) == 0)
            snprintf(err->file, sizeof err->file, "%s", path);
        st_outfile_abort(&o);
        return s;
    }
    return st_outfile_commit(&o, err);
}
