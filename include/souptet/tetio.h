/*
 * tetio.h - tet meshes on disk and on pipes (the C face of the VTK
 * adapter, src/adapters/tetio_vtu.cpp).
 *
 * .vtu: VTK XML UnstructuredGrid, binary, zlib-compressed, VTK_TETRA
 * cells. The writer adds per-cell arrays min_dihedral, max_dihedral and
 * volume (degrees, model units^3) and stores the mesh's meta entries
 * (source, h, lattice, parameters, history, ...) as string field data,
 * plus the mesh's own named arrays. The reader restores all of it; cells
 * that are not tetrahedra are refused with a message.
 *
 * Pipes: "-" or NULL means stdin/stdout, and the bytes on the pipe are the
 * same .vtu document (so `latticetet ... | tetsmooth ...` works and
 * `latticetet > m.vtu` gives a valid file).
 */
#ifndef SOUPTET_TETIO_H
#define SOUPTET_TETIO_H

#include <stddef.h>

#include "souptet/err.h"
#include "souptet/tetmesh.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum st_tet_format {
    ST_TET_FMT_UNKNOWN = 0,
    ST_TET_FMT_VTU,
    ST_TET_FMT_MSH,       /* Gmsh .msh (tetformat.h) */
    ST_TET_FMT_TETGEN,    /* TetGen .node/.ele (tetformat.h) */
    ST_TET_FMT_MEDIT      /* Medit .mesh (tetformat.h) */
} st_tet_format;

/* Format from a path's extension (".vtu", ".msh", ".node", ".ele",
 * ".mesh", case-insensitive); "-" / NULL give VTU (the pipe format).
 * Reading and writing dispatch on it: the simulator formats go to
 * tetformat.h (which keeps points, tets and meta, not the arrays). */
st_tet_format st_tet_format_from_path(const char *path);

/* Write m to path ("-" or NULL: stdout). The caller handles atomic output
 * (st_outfile) for paths; this writes exactly where it is told. */
st_status st_tetmesh_write(const st_tetmesh *m, const char *path,
                           st_error *err);

/* Read a tet mesh; "-" or NULL reads stdin. Refuses more than max_bytes
 * of mesh memory (0: no limit), point indices out of range, non-finite
 * points, non-tet cells. */
st_status st_tetmesh_read(st_tetmesh **out, const char *path,
                          size_t max_bytes, st_error *err);

/* The same .vtu document in memory, for pipes, tests and fuzzers: parse
 * size bytes (name is used in messages only), or write into a malloc'd
 * buffer *data of *size bytes that the caller frees. */
st_status st_tetmesh_read_mem(st_tetmesh **out, const unsigned char *data,
                              size_t size, const char *name,
                              size_t max_bytes, st_error *err);
st_status st_tetmesh_write_mem(unsigned char **data, size_t *size,
                               const st_tetmesh *m, st_error *err);

/* st_tetmesh_write with atomic output for the tools: a file is written to
 * a temporary name beside path (st_outfile) and renamed when complete, so
 * a failure leaves nothing at path; "-" or NULL writes stdout. */
st_status st_tetmesh_save(const st_tetmesh *m, const char *path,
                          st_error *err);

#ifdef __cplusplus
}
#endif
#endif
