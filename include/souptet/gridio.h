/*
 * gridio.h - fields on disk and on pipes.
 *
 * Units: model units, as in the grid (the .vdb transform and the .vti
 * spacing carry the voxel size and origin).
 * Ownership: the caller owns a grid read (st_grid_free); a grid written is
 * borrowed.
 * Threads: calls on different grids and files may run at once (OpenVDB is
 * initialised once, thread-safely).
 * Errors: ST_EIO (open, read, write), ST_EINPUT (a malformed or foreign
 * file, named with its path), ST_ELIMIT (over max_bytes), ST_ENOMEM,
 * ST_EINTERNAL (the library refused what it was given); a failed write
 * leaves no file (outfile.h).
 *
 * Behind this C header sit the only C++ sources that touch fields:
 * src/adapters/gridio_vdb.cpp (OpenVDB) and src/adapters/gridio_vti.cpp
 * (VTK XML ImageData).
 *
 * .vdb: one FloatGrid (name "distance" for distance fields, "sdf" for signed
 * ones), index (i,j,k) = voxel (i,j,k) of the st_grid, a linear transform
 * with the voxel size and the origin, and metadata: souptet_kind, voxel_size,
 * origin, dims, band, and every st_meta entry (source, triangles, history...)
 * as string metadata. Voxels equal to the background (the clamp value of a
 * banded field) are stored inactive, so a narrow band file stays small.
 * On a pipe the same grid travels as an OpenVDB stream.
 *
 * .vti: VTK XML ImageData, binary and zlib-compressed; points are the voxel
 * centers, the values their point scalars (named after the grid); the
 * metadata as field data strings.
 */
#ifndef SOUPTET_GRIDIO_H
#define SOUPTET_GRIDIO_H

#include "souptet/err.h"
#include "souptet/grid.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum st_grid_format {
    ST_GRID_FMT_UNKNOWN = 0,
    ST_GRID_FMT_VDB,
    ST_GRID_FMT_VTI
} st_grid_format;

/* Format from a path's extension (".vdb", ".vti", case-insensitive). */
st_grid_format st_grid_format_from_path(const char *path);

/* Write g to path. "-" or NULL writes an OpenVDB stream to stdout.
 * Files are written to a temporary name beside path and renamed when
 * complete; on failure nothing is left at path. */
st_status st_grid_write(const st_grid *g, const char *path, st_error *err);

/* Write a field stored by blocks (grid.h) to path, as st_grid_write
 * writes the same field held densely: the same .vdb or stream, node for
 * node, built from the stored blocks alone; a .vti goes through a dense
 * copy. */
st_status st_grid_blocks_write(const st_grid_blocks *b, const char *path,
                               st_error *err);

/* Read a field from path; "-" or NULL reads stdin (an OpenVDB stream, or
 * a .vdb file's bytes). Format by extension, else by content.
 * max_bytes limits the dense array (0: none). */
st_status st_grid_read(st_grid **out, const char *path, size_t max_bytes,
                       st_error *err);

/* Format-specific entry points (used by the two above and by tests).
 */
st_status st_grid_write_vdb(const st_grid *g, const char *path,
                            st_error *err);
st_status st_grid_blocks_write_vdb(const st_grid_blocks *b,
                                   const char *path, st_error *err);
st_status st_grid_read_vdb(st_grid **out, const char *path, size_t max_bytes,
                           st_error *err);
st_status st_grid_write_vti(const st_grid *g, const char *path,
                            st_error *err);
st_status st_grid_read_vti(st_grid **out, const char *path, size_t max_bytes,
                           st_error *err);

#ifdef __cplusplus
}
#endif
#endif
