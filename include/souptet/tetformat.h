/*
 * tetformat.h - the tet-mesh formats: their one enum and writer options,
 * and the simulator formats themselves, plain C, no library: Gmsh .msh
 * (4.1 and 2.2, ASCII and binary), TetGen .node/.ele and Medit .mesh,
 * and the writing of .vtu (src/tet/tetformat_vtu.c; reading .vtu is the VTK
 * adapter's). Tools and library callers read and write
 * every format through one front door, tetio.h (st_tetmesh_read,
 * st_tetmesh_save, st_tetmesh_write), which dispatches here; the
 * per-format functions below are for tests, fuzzers and callers that
 * hold the bytes. (One file per format: src/tet/tetformat_msh.c,
 * tetformat_tetgen.c, tetformat_medit.c, tetformat_vtu.c.)
 *
 * Units: model units, as in the file (coordinates are never rescaled).
 * Ownership: the caller owns a mesh read (st_tetmesh_free); a mesh written
 * is borrowed.
 * Threads: no global state; calls on different meshes and files may run at
 * once.
 * Errors: ST_EIO, ST_EINPUT (with file and line or byte offset), ST_ELIMIT
 * (over max_bytes), ST_ENOMEM; no mesh on error (what is refused: below).
 *
 * What is kept. Points and tets, exactly (coordinates are written with 17
 * significant digits or as raw doubles, so a round trip is bit-exact), and
 * the mesh's meta entries (source, h, history, ...) as comments: Gmsh's
 * $Comments section (which Gmsh and meshio skip), '#' lines in TetGen and
 * Medit files, each "souptet KEY: VALUE", one line per history line. Named
 * arrays are not written (use .vtu for per-cell quality).
 *
 * What is written.
 *  - Unless volume_only (st_tetformat_opts): the boundary faces (st_tetmesh_boundary's, each turned outward by
 *    the exact orientation of its tet, so also for an inverted tet) go
 *    into .msh and .mesh as triangles, after the tets.
 *  - .msh 4.1: $MeshFormat, $PhysicalNames (3-D 1 "volume", 2-D 2
 *    "boundary"), $Comments, $Entities (surface tag 2 in physical group 2;
 *    volume tag 1 in physical group 1, bounded by surface 2), $Nodes (one
 *    block on the volume, tags 1..n), $Elements (a block of type 4 on the
 *    volume, tags 1..m, then one of type 2 on the surface, tags m+1..).
 *    2.2: $MeshFormat, $PhysicalNames, $Comments, $Nodes, $Elements (type
 *    4 with tags physical 1, elementary 1; type 2 with 2, 2). Binary:
 *    native byte order with the format's "1" marker, data size 8.
 *  - .node/.ele: "n 3 0 0" / "m 4 0", numbered from 1.
 *  - .mesh: MeshVersionFormatted 2, Dimension 3, Vertices (ref 0),
 *    Tetrahedra (ref 1), Triangles (ref 2), End; 1-based.
 * Tets keep their corner order; souptet's positive orientation (signed
 * volume > 0, tetmesh.h) is also Gmsh's, TetGen's and Medit's.
 *
 * What is read. The same files and those other programs write: any node
 * and element numbering (msh tags are mapped, TetGen's first index 0 or 1
 * decides its base), node and element attributes and boundary markers
 * (ignored), msh parametric coordinates and $Entities, $PhysicalNames,
 * $NodeData, ... (skipped), lower-dimensional elements (points, lines,
 * triangles, quads of any order: skipped), binary files of either byte
 * order with 4- or 8-byte msh sizes. Refused with ST_EINPUT and the file
 * and line (text) or byte offset (binary): other 3-D cells (hexahedra,
 * prisms, pyramids, 10-node tets), unknown element types or sections where
 * a length is needed, truncation, counts larger than the bytes left,
 * duplicated node tags, indices out of range, NaN/Inf coordinates, a mesh
 * without tets. No allocation is ever sized by a count before the bytes
 * that would hold it are known to exist, and max_bytes (0: no limit) caps
 * the mesh memory (24 bytes a point, 16 a tet): more is ST_ELIMIT.
 */
#ifndef SOUPTET_TETFORMAT_H
#define SOUPTET_TETFORMAT_H

#include <stddef.h>

#include "souptet/err.h"
#include "souptet/tetmesh.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The tet-mesh formats, one enum for all of them. */
typedef enum st_tetformat {
    ST_TETFORMAT_NONE = 0,   /* unknown */
    ST_TETFORMAT_VTU,        /* .vtu, and the pipes (tetio.h) */
    ST_TETFORMAT_MSH,        /* .msh */
    ST_TETFORMAT_TETGEN,     /* .node or .ele (the pair) */
    ST_TETFORMAT_MEDIT       /* .mesh */
} st_tetformat;

/* Writer options; a zeroed struct (or NULL where one is taken) means the
 * defaults. */
typedef struct st_tetformat_opts {
    int msh_version;  /* 41 (default, also 0 and 4) or 22 (also 2) */
    int binary;       /* msh only: 0 ASCII (default), 1 binary */
    int volume_only;  /* 1: .msh and .mesh hold the tets alone: no boundary
                         triangles, and in .msh no "boundary" physical group
                         or surface entity (the "volume" group stays). For
                         readers that take one cell kind only: SfePy's
                         Mesh.from_file gives a mesh its FEDomain refuses
                         ("meshes with several cell kinds are not
                         supported!") when the triangles are there. .vtu
                         and TetGen hold the tets alone anyway: no effect
                         there. 0: the boundary too, as below (default) */
} st_tetformat_opts;

/* The format of a path's extension (case-insensitive): .vtu, .msh,
 * .node, .ele, .mesh; NONE otherwise. NULL and "-" give VTU (the pipe
 * format). A temporary name made by st_outfile_begin for such a path
 * ("dir/.name.msh.XXXXXX") gives the target's format. */
st_tetformat st_tetformat_from_path(const char *path);

/* "vtu", "msh", "tetgen", "medit" or "none". */
const char *st_tetformat_name(st_tetformat f);

/* The format of a document from its first bytes: MSH ("$MeshFormat"),
 * MEDIT ("MeshVersion..."), VTU (XML: '<' after an optional byte-order
 * mark and white space) or NONE; TetGen files have no signature. */
st_tetformat st_tetformat_sniff(const unsigned char *data, size_t size);

/* ---- reading ------------------------------------------------------------ */

/* Read a mesh file of that format. For TetGen, path may be the .node, the
 * .ele or the base name without extension; both files are read. On
 * failure *out is NULL. */
st_status st_tetmesh_read_msh(st_tetmesh **out, const char *path,
                              size_t max_bytes, st_error *err);
st_status st_tetmesh_read_tetgen(st_tetmesh **out, const char *path,
                                 size_t max_bytes, st_error *err);
st_status st_tetmesh_read_medit(st_tetmesh **out, const char *path,
                                size_t max_bytes, st_error *err);

/* The same parsers on memory (for fuzzers and tests); name is used in
 * messages only. TetGen takes both files' bytes and names. */
st_status st_tetmesh_parse_msh(st_tetmesh **out, const unsigned char *data,
                               size_t size, const char *name,
                               size_t max_bytes, st_error *err);
st_status st_tetmesh_parse_tetgen(st_tetmesh **out,
                                  const unsigned char *node, size_t node_size,
                                  const char *node_name,
                                  const unsigned char *ele, size_t ele_size,
                                  const char *ele_name, size_t max_bytes,
                                  st_error *err);
st_status st_tetmesh_parse_medit(st_tetmesh **out, const unsigned char *data,
                                 size_t size, const char *name,
                                 size_t max_bytes, st_error *err);

/* ---- writing ------------------------------------------------------------ */

/* Write m exactly at path (no temporary file; the tools write through
 * st_tetmesh_save, tetio.h). version: 41 or 22 (0 means 41); binary 0
 * or 1. */
st_status st_tetmesh_write_msh(const st_tetmesh *m, const char *path,
                               int version, int binary, st_error *err);
/* path: the .node, the .ele or the base name; writes base.node and
 * base.ele. */
st_status st_tetmesh_write_tetgen(const st_tetmesh *m, const char *path,
                                  st_error *err);
st_status st_tetmesh_write_medit(const st_tetmesh *m, const char *path,
                                 st_error *err);

#ifdef __cplusplus
}
#endif
#endif
