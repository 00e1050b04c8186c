/*
 * tetio_internal.h - private glue between src/tetio.c (C) and the VTK
 * adapter src/adapters/tetio_vtu.cpp (C++). Not installed; extern "C",
 * never throws, never prints.
 */
#ifndef SOUPTET_TETIO_INTERNAL_H
#define SOUPTET_TETIO_INTERNAL_H

#include <stddef.h>
#include "souptet/err.h"
#include "souptet/tetmesh.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Write m as .vtu to the file path (exactly there, no temporary). */
st_status st_tetio_write_vtu_file(const st_tetmesh *m, const char *path,
                                  st_error *err);
/* Write m as .vtu into a malloc'd buffer. */
st_status st_tetio_write_vtu_mem(unsigned char **data, size_t *size,
                                 const st_tetmesh *m, st_error *err);
/* Read a .vtu file / a .vtu document in memory. */
st_status st_tetio_read_vtu_file(st_tetmesh **out, const char *path,
                                 size_t max_bytes, st_error *err);
st_status st_tetio_read_vtu_mem(st_tetmesh **out, const unsigned char *data,
                                size_t size, const char *name,
                                size_t max_bytes, st_error *err);

#ifdef __cplusplus
}
#endif
#endif
