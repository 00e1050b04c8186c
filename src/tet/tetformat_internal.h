/*
 * tetformat_internal.h - what the files of the tetformat module share
 * (tetformat.c, tetformat_msh.c, tetformat_tetgen.c, tetformat_medit.c,
 * tetformat_vtu.c): the reading state (tetformat_read.h), the writers
 * tetio calls (tetformat_write.h), and the helpers one file defines for
 * the others. Not installed.
 */
#ifndef SOUPTET_TETFORMAT_INTERNAL_H
#define SOUPTET_TETFORMAT_INTERNAL_H

#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "souptet/err.h"
#include "souptet/meta.h"
#include "souptet/tetformat.h"
#include "souptet/tetmesh.h"
#include "tetformat_read.h"
#include "tetformat_write.h"

/* ---- defined in one file, used by others ------------------------------- */

/* base.node and base.ele for a TetGen path (.node, .ele or a base name);
 * malloc'd. (tetformat.c) */
st_status st_tf_tetgen_names(const char *path, char **node, char **ele,
                             st_error *err);

/* Read the file path whole and parse it with parse (one of
 * st_tetmesh_parse_msh, _medit). (tetformat.c) */
typedef st_status (*st_tf_parser)(st_tetmesh **, const unsigned char *,
                                  size_t, const char *, size_t, st_error *);
st_status st_tf_read_with(st_tf_parser parse, st_tetmesh **out,
                          const char *path, size_t max_bytes, st_error *err);

/* Writing (tetformat.c): meta entries as "PREFIXsouptet KEY: LINE" lines;
 * the msh version normalised (41 or 22; -1: not one); what no file of
 * format f can hold; open a file for writing; flush, close and report. */
void st_tf_put_meta(FILE *fp, const st_meta *meta, const char *prefix);
/* The mesh's parts (parts.h: the cell array "part", meta "parts" and
 * "part_name_K"): the count (0: no parts), and tet t's part through
 * st_tf_tet_part (values not a part index in 0..count-1 read as 0). */
size_t st_tf_parts(const st_tetmesh *m, const double **part);
static inline size_t st_tf_tet_part(const double *part, size_t nparts, size_t t)
{
    const double v = part[t];
    return v >= 0 && v < (double)nparts && v == floor(v) ? (size_t)v : 0;
}
/* Part k's name for a quoted field: meta part_name_k, else part_k, with '"',
 * '\\' and control bytes as '_'. */
void st_tf_part_name(char *buf, size_t size, const st_tetmesh *m, size_t k);
int st_tf_msh_version(int v);
st_status st_tf_check_writable(const st_tetmesh *m, st_tetformat f,
                               int version, int binary, const char *path,
                               st_error *err);
/* The boundary faces written as triangles by .msh and .mesh: those of
 * st_tetmesh_boundary, each turned outward also when its tet is
 * negatively oriented (the exact sign of st_orient3d decides; a flat tet's
 * face is kept as it is). *faces (3 point indices a face) is freed by
 * the caller with free(). (tetformat.c) */
st_status st_tf_boundary(const st_tetmesh *m, uint32_t **faces,
                         size_t *nfaces, const char *path, st_error *err);
FILE *st_tf_open_out(const char *path, st_error *err);
st_status st_tf_close_written(FILE *fp, const char *path, st_error *err);

/* The writers on an open stream (tetformat_msh.c, tetformat_tetgen.c,
 * tetformat_medit.c); errors show in ferror(fp). The .msh and .mesh
 * writers also write the nfaces boundary triangles faces (st_tf_boundary).
 * The .msh writer with volume_only writes the volume's physical group and
 * entity alone (no "boundary" group, no surface entity; faces unused). */
void st_tf_write_msh_fp(FILE *fp, const st_tetmesh *m, int version,
                        int binary, int volume_only, const uint32_t *faces,
                        size_t nfaces);
void st_tf_write_node_fp(FILE *fp, const st_tetmesh *m);
void st_tf_write_ele_fp(FILE *fp, const st_tetmesh *m);
void st_tf_write_medit_fp(FILE *fp, const st_tetmesh *m,
                          const uint32_t *faces, size_t nfaces);



#endif
