/*
 * gridio_internal.h - private glue between src/io/gridio.c (C) and the field
 * adapters src/adapters/gridio_vdb.cpp and gridio_vti.cpp (C++).
 *
 * Not installed and not part of the API: the tools use gridio.h only.
 * Everything here is extern "C", never throws, never prints. The calls go
 * one way, gridio.c to the adapters; what both need (reading standard
 * input, checking an input file) is src/base/fileio.h's.
 */
#ifndef SOUPTET_GRIDIO_INTERNAL_H
#define SOUPTET_GRIDIO_INTERNAL_H

#include <stddef.h>
#include "souptet/err.h"
#include "souptet/grid.h"
#include "souptet/tetmesh.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Parse a field held in memory; `name` is used in messages only. */
st_status st_gridio_read_vdb_mem(st_grid **out, const unsigned char *data,
                                 size_t size, const char *name,
                                 size_t max_bytes, st_error *err);
st_status st_gridio_read_vti_mem(st_grid **out, const unsigned char *data,
                                 size_t size, const char *name,
                                 size_t max_bytes, st_error *err);

/* The VTK adapters (gridio_vti.cpp, tetio_vtu.cpp, vtk_capture.cpp and
 * vtkxml.c's checks) are a library of their own, ST_VTK_PLUGIN, opened
 * with dlopen the first time a .vti or .vtu is read or a .vti written
 * (src/io/gridio_vtk.c): a process that never touches VTK does not pay
 * for loading and relocating its 20 libraries (issue 41). The plugin
 * leaves the core's names undefined: they bind to the program's own
 * (the tools export theirs, -Wl,--dynamic-list) or to libsouptet.so.0,
 * so that state such as st_outfile's pending list is the program's.
 * Inside the plugin the functions below keep the names of the public
 * ones (not exported from it); the program's copies of those names
 * forward through this table. */
#define ST_VTK_PLUGIN "libsouptet-vtk.so.0"

typedef struct st_vtk_plugin {
    const char *version;     /* SOUPTET_VERSION of the plugin's build */
    size_t size;             /* sizeof(st_vtk_plugin) there */
    st_status (*grid_write_vti)(const st_grid *g, const char *path, st_error *err);
    st_status (*grid_read_vti)(st_grid **out, const char *path, size_t max_bytes,
                               st_error *err);
    st_status (*grid_read_vti_mem)(st_grid **out, const unsigned char *data, size_t size,
                                   const char *name, size_t max_bytes, st_error *err);
    st_status (*tet_read_vtu_file)(st_tetmesh **out, const char *path,
                                   size_t max_bytes, st_error *err);
    st_status (*tet_read_vtu_mem)(st_tetmesh **out, const unsigned char *data,
                                  size_t size, const char *name, size_t max_bytes,
                                  st_error *err);
    size_t (*inflate)(void *user, const char *compressor, const unsigned char *in,
                      size_t n, unsigned char *out, size_t cap);
} st_vtk_plugin;

/* The plugin's one exported name (src/adapters/tetio_plugin.cpp). */
const st_vtk_plugin *st_vtk_plugin_entry(void);

/* The program's side: the plugin's table in *out, opened on the first
 * call (thread-safe); ST_EIO naming `name` when it cannot be loaded or is
 * another build's. */
st_status st_vtk_plugin_get(const st_vtk_plugin **out, const char *name, st_error *err);

/* A forwarder's body: return the plugin's `call` (a member and its
 * arguments), or the failure to load it. */
#define ST_VTK_FORWARD(name, err, call)                                       \
    do {                                                                      \
        const st_vtk_plugin *fwd_p;                                           \
        st_status fwd_s = st_vtk_plugin_get(&fwd_p, name, err);               \
        return fwd_s ? fwd_s : fwd_p->call;                                   \
    } while (0)

/* Test hook: write a .vdb that souptet did not make, to exercise the
 * reader's foreign paths. which = 0: only a Vec3s grid (no float grid);
 * 1: a FloatGrid "density" without souptet metadata, background -1,
 * voxel 0.5, transform translated by (1,2,3), active voxels where i+j+k
 * is even (and at both corners) of index box (2,-3,4)..(5,1,6), valued
 * i+10j+100k, string metadata note=foreign; 2: an OpenVDB level-set sphere of
 * radius 2 at the origin, voxel 0.25, half width 3 voxels, named "ls". */
st_status st_gridio_write_foreign_vdb(const char *path, int which,
                                      st_error *err);

#ifdef __cplusplus
}
#endif
#endif
