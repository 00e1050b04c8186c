/*
 * tetformat_write.h - the tet format writers tetio's front door calls
 * (tetio.c, tetio_write.c): .msh, .mesh and .vtu to a path or memory, and
 * the atomic save of any of them. The readers' machinery stays in
 * tetformat_read.h. Not installed.
 */
#ifndef SOUPTET_TETFORMAT_WRITE_H
#define SOUPTET_TETFORMAT_WRITE_H

#include <stddef.h>

#include "souptet/err.h"
#include "souptet/tetformat.h"
#include "souptet/tetmesh.h"

/* st_tetmesh_write_msh and st_tetmesh_write_medit with the option
 * volume_only (st_tetformat_opts): the tets alone. */
st_status st_tf_write_msh_path(const st_tetmesh *m, const char *path,
                               int version, int binary, int volume_only,
                               st_error *err);
st_status st_tf_write_medit_path(const st_tetmesh *m, const char *path,
                                 int volume_only, st_error *err);

/* .vtu (tetformat_vtu.c): m as a VTK XML UnstructuredGrid document in a
 * malloc'd buffer (name: for messages), or written to the file path
 * (exactly there, no temporary). */
st_status st_tf_write_vtu_mem(unsigned char **data, size_t *size, const st_tetmesh *m,
                              const char *name, st_error *err);
st_status st_tf_write_vtu_path(const st_tetmesh *m, const char *path, st_error *err);

/* m to path in format f (NONE: by path; MSH, TETGEN or MEDIT) with opts
 * (NULL: defaults), atomically: every file (both of a TetGen pair) goes
 * to a temporary name beside its target and is renamed only when all
 * were written, so a failure leaves nothing at the targets. Errors name
 * the target. tetio.h's st_tetmesh_save is the front door. (tetformat.c) */
st_status st_tf_save(const st_tetmesh *m, st_tetformat f, const char *path,
                     const st_tetformat_opts *opts, st_error *err);

#endif
