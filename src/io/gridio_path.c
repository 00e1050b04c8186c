/*
 * gridio_path.c - a field file's format by its name (see gridio.h), in an
 * object of its own: the tools' shared code asks it of every output name,
 * and a tool that writes no field (soupmesh) then links neither the
 * readers and writers of gridio.c nor OpenVDB and VTK behind them.
 */
#include "souptet/gridio.h"
#include "../base/fileio.h"

st_grid_format st_grid_format_from_path(const char *path)
{
    static const char *const ext[] = {"vdb", "vti"};
    switch (st_path_ext_match(path, ext, 2, 0)) {
    case 0: return ST_GRID_FMT_VDB;
    case 1: return ST_GRID_FMT_VTI;
    default: return ST_GRID_FMT_UNKNOWN;
    }
}
