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
