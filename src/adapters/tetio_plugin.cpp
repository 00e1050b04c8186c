/*
 * tetio_plugin.cpp - the table of libsouptet-vtk.so.0, the VTK adapters'
 * library (see gridio_internal.h): its one exported name. The functions
 * it points to are the adapters' own (gridio_vti.cpp, tetio_vtu.cpp,
 * vtk_capture.cpp), local to the plugin.
 */
#include "gridio_internal.h"
#include "tetio_internal.h"
#include "../io/vtkxml.h"
#include "souptet/gridio.h"

extern "C" const st_vtk_plugin *st_vtk_plugin_entry(void)
{
    static const st_vtk_plugin table = {
        SOUPTET_VERSION,        sizeof(st_vtk_plugin), st_grid_write_vti,
        st_grid_read_vti,       st_gridio_read_vti_mem, st_tetio_read_vtu_file,
        st_tetio_read_vtu_mem,  st_vtkxml_inflate_vtk,
    };
    return &table;
}
