/*
 * tetio_vtk.c - the program's side of the .vtu reader: it forwards to the
 * VTK adapters' library, opened on first use (src/io/gridio_vtk.c).
 */
#include "../adapters/gridio_internal.h"
#include "../adapters/tetio_internal.h"

#include <stddef.h>

st_status st_tetio_read_vtu_file(st_tetmesh **out, const char *path, size_t max_bytes,
                                 st_error *err)
{
    *out = NULL;
    ST_VTK_FORWARD(path, err, tet_read_vtu_file(out, path, max_bytes, err));
}

st_status st_tetio_read_vtu_mem(st_tetmesh **out, const unsigned char *data, size_t size,
                                const char *name, size_t max_bytes, st_error *err)
{
    *out = NULL;
    ST_VTK_FORWARD(name, err, tet_read_vtu_mem(out, data, size, name, max_bytes, err));
}
