/*
 * gridio_internal.h - private glue between src/gridio.c (C) and the field
 * adapters src/adapters/gridio_vdb.cpp and gridio_vti.cpp (C++).
 *
 * Not installed and not part of the API: the tools use gridio.h only.
 * Everything here is extern "C", never throws, never prints.
 */
#ifndef SOUPTET_GRIDIO_INTERNAL_H
#define SOUPTET_GRIDIO_INTERNAL_H

#include <stddef.h>
#include "souptet/err.h"
#include "souptet/grid.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The name errors use for standard input and output. */
#define ST_GRIDIO_STDIN_NAME "<stdin>"
#define ST_GRIDIO_STDOUT_NAME "<stdout>"

/* Read all of stdin into a malloc'd buffer (*data is never NULL on
 * success, even for 0 bytes; caller frees). Stdin has to be read whole
 * anyway: its format is sniffed from the first bytes, and neither reader
 * may seek on a pipe. ST_EIO on a read error. */
/* Checks by path before a library reads a file by name, so that the usual
 * failures get the system's words, not the library's: ST_EIO "cannot open:
 * why" or "is a directory", ST_EINPUT "empty file". Shared by the field
 * and tet-mesh adapters. */
st_status st_gridio_check_input_file(const char *path, st_error *err);

st_status st_gridio_read_stdin(unsigned char **data, size_t *size,
                               st_error *err);

/* Parse a field held in memory; `name` is used in messages only. */
st_status st_gridio_read_vdb_mem(st_grid **out, const unsigned char *data,
                                 size_t size, const char *name,
                                 size_t max_bytes, st_error *err);
st_status st_gridio_read_vti_mem(st_grid **out, const unsigned char *data,
                                 size_t size, const char *name,
                                 size_t max_bytes, st_error *err);

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
