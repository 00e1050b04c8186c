/*
 * tetio_internal.h - private glue between src/io/tetio.c (C) and the VTK
 * reading adapter src/adapters/tetio_vtu.cpp (C++). Not installed; extern "C",
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
