/*
 * tetio.c - the front door for reading tet meshes: which format, and the
 * pipes (see tetio.h); writing is tetio_write.c's, which needs no VTK.
 *
 * The dispatch only: .vtu itself is read by the VTK adapter
 * (src/adapters/tetio_vtu.cpp), Gmsh, TetGen and Medit files by
 * tetformat_*.c. Standard input is read whole (VTK's XML reader cannot
 * read a pipe as it goes: it seeks to the appended data) and parsed from
 * memory.
 */
#include "souptet/tetio.h"
#include "souptet/outfile.h"
#include "souptet/tetformat.h"
#include "../adapters/tetio_internal.h"
#include "../base/fileio.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define UNKNOWN_FORMAT "unknown tet mesh format (use .vtu, .msh, .node, .mesh)"

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
