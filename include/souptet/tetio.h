/*
 * tetio.h - tet meshes on disk and on pipes: the one front door for
 * reading and writing every tet-mesh format (tetformat.h names them:
 * .msh, .node/.ele and .mesh in tetformat_*.c; .vtu written by
 * tetformat_vtu.c in C, read by the VTK adapter src/adapters/tetio_vtu.cpp).
 *
 * Units: model units, as stored.
 * Ownership: the caller owns a mesh read (st_tetmesh_free) and the buffer
 * of st_tetmesh_write_mem (free()); a mesh written is borrowed.
 * Threads: no global state of ours (VTK's reader is used one call at a time
 * per mesh); calls on different files may run at once.
 * Errors: ST_EIO, ST_EINPUT (with file and line or byte offset), ST_ELIMIT
 * (over max_bytes), ST_ENOMEM; a failed save leaves no file (outfile.h).
 *
 * .vtu: VTK XML UnstructuredGrid, binary, zlib-compressed, VTK_TETRA
 * cells. The writer adds per-cell arrays min_dihedral, max_dihedral and
 * volume (degrees, model units^3) and stores the mesh's meta entries
 * (source, h, lattice, parameters, history, ...) as field data (a
 * UInt64 for a canonical integer, a Float64 for an exact %.17g number,
 * else UInt8 bytes),
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
#include "souptet/tetformat.h"
#include "souptet/tetmesh.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Write m to path ("-" or NULL: .vtu on stdout), in the format of its
 * extension (st_tetformat_from_path) with opts (NULL: defaults; only .msh
 * has options). The simulator formats keep points, tets and meta, not the
 * named arrays. The caller handles atomic output (st_outfile) for paths;
 * this writes exactly where it is told. */
st_status st_tetmesh_write(const st_tetmesh *m, const char *path,
                           const st_tetformat_opts *opts, st_error *err);

/* Read a tet mesh in any of the formats, by extension, else by content
 * (st_tetformat_sniff); "-" or NULL reads stdin (.vtu, .msh or .mesh).
 * Refuses more than max_bytes of mesh memory (0: no limit), point indices
 * out of range, non-finite points, non-tet cells. */
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

/* st_tetmesh_write with atomic output, what the tools call: every file
 * (both of a TetGen pair) is written to a temporary name beside its
 * target (st_outfile) and renamed when all are complete, so a failure
 * leaves nothing at path; "-" or NULL writes .vtu to stdout. Errors name
 * the target. */
st_status st_tetmesh_save(const st_tetmesh *m, const char *path,
                          const st_tetformat_opts *opts, st_error *err);

#ifdef __cplusplus
}
#endif
#endif
