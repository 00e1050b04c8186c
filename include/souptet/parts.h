/*
 * parts.h - parts and materials: which part of the input each tet of a
 * cage belongs to (soupmesh --parts).
 *
 * Units: model units.
 * Ownership: the caller owns every st_parts (st_parts_free) and tag stats
 * (st_parts_tag_stats_free); soups and meshes are borrowed.
 * Threads: st_parts_tag samples tets in parallel; results do not depend on
 * the thread count.
 * Errors: ST_EINPUT, ST_ELIMIT, ST_ENOMEM, ST_ECANCELLED, with a message.
 *
 * A soup's parts (st_parts_split) are either the parts its file names
 * (soup.h, st_soup_name: OBJ objects, or groups where the file has no
 * objects; glTF mesh nodes; ASCII STL solids) or its edge-connected pieces
 * (edges.h, on exactly welded vertices). Each part is a list of triangles
 * and a unique, UTF-8 name.
 *
 * Tagging a mesh (st_parts_tag): each part gets its own pseudo volume
 * (pseudo.h, st_pseudo_volume over the part's triangles alone) at the
 * voxel size of the mesh's field; its inside voxels are carried onto that
 * field's grid (the nearest voxel center), and where several parts' solids
 * hold a voxel the one with the fewest inside voxels - the inner part, the
 * bone in the flesh - owns it. Each tet is sampled at ST_PARTS_SAMPLES
 * points spread evenly through it (barycentric (i+1/2, j+1/2, k+1/2,
 * l+1/2) / (L+2) with i+j+k+l = L); its part is the one owning the most
 * samples (ties: the smaller index) and its share the fraction of samples
 * that part owns. A tet no part covers (the enclosure margin) takes the
 * part of the triangle nearest its centroid, with share 0.
 */
#ifndef SOUPTET_PARTS_H
#define SOUPTET_PARTS_H

#include <stddef.h>
#include <stdint.h>

#include "souptet/err.h"
#include "souptet/grid.h"
#include "souptet/progress.h"
#include "souptet/pseudo.h"
#include "souptet/soup.h"
#include "souptet/tetmesh.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Most parts a soup may have: a part index fits 16 bits, and gmsh's and
 * Medit's tags stay small. */
#define ST_PARTS_MAX 65535
/* Samples per tet (L = 4: C(7, 3) points). A coarse cage's tet spans
 * about 8 voxels of its field, so 35 points see every voxel layer. */
#define ST_PARTS_LEVEL 4
#define ST_PARTS_SAMPLES 35

typedef enum st_parts_mode {
    ST_PARTS_NONE = 0,
    ST_PARTS_AUTO,       /* names where the file has any (not empty),
                            else pieces */
    ST_PARTS_NAMES,      /* the file's names (one part when it has none) */
    ST_PARTS_PIECES      /* edge-connected pieces */
} st_parts_mode;

/* "none", "auto", "names", "pieces"; and back (-1 for other text). */
const char *st_parts_mode_name(st_parts_mode mode);
int st_parts_mode_from_name(const char *name);

typedef struct st_parts {
    uint16_t *tri_part;   /* ntris entries: each triangle's part */
    size_t ntris;
    char **names;         /* nparts unique UTF-8 names */
    size_t *tris_of;      /* nparts: triangles per part (>= 1 from
                             st_parts_split) */
    size_t nparts;
    st_parts_mode mode;   /* what was used: NAMES or PIECES */
    /* What was handled on the way (a tool says it): */
    size_t empty;         /* named runs with no triangles, skipped */
    size_t unnamed;       /* runs without a name (named part_K) */
    size_t duplicates;    /* names met again (suffixed _2, _3, ...) */
    size_t not_utf8;      /* names not UTF-8 (named part_K) */
    char first_empty[64]; /* the first skipped run's name (cut) */
} st_parts;

/* The parts of s by mode (not NONE). ST_ELIMIT with more than
 * ST_PARTS_MAX parts (say --parts names or none); ST_ENOMEM. *out is
 * zeroed on failure. */
st_status st_parts_split(st_parts *out, const st_soup *s, st_parts_mode mode,
                         st_error *err);
void st_parts_free(st_parts *p);   /* safe on NULL and on a zeroed one */

/* The parts a caller gives: part[t] for each of ntris triangles (each <
 * ST_PARTS_MAX; the parts are 0..max), names[k] for k < nnames (names may
 * be NULL; a missing, empty or non-UTF-8 name becomes part_K, duplicates
 * are suffixed, as st_parts_split does). A part no triangle names has
 * tris_of 0 and no solid. mode is NAMES. ST_EINPUT for an index too large
 * (naming the triangle), ST_ENOMEM. */
st_status st_parts_from_indices(st_parts *out, const uint32_t *part, size_t ntris,
                                const char *const *names, size_t nnames, st_error *err);

/* What st_parts_tag measured: per part (nparts entries each, the caller
 * frees with st_parts_tag_stats_free) its pseudo volume (inside voxels
 * times the voxel's volume, before the inner parts take their share),
 * the tets tagged with it and their volume; and the tets no part covered. */
typedef struct st_parts_tag_stats {
    size_t nparts;
    double *pseudo_volume;
    size_t *tets;
    double *volume;
    size_t uncovered;
} st_parts_tag_stats;
void st_parts_tag_stats_free(st_parts_tag_stats *st);

/* Tag mesh m (made over soup s, p = st_parts_split(s)) on the grid
 * layout of field g (its dims, origin and voxel; the values are not
 * read), each part's pseudo volume made with pp (st_pseudo_params). Adds
 * the cell arrays "part" (the part index) and "part_share" (0..1), and
 * meta "parts" (the count) and "part_name_K" for each part K. stats may be
 * NULL. prog's cancel flag is polled between parts. Meta
 * "part_pseudo_volume_K" keeps each part's pseudo volume (%.17g). */
st_status st_parts_tag(st_tetmesh *m, const st_soup *s, const st_parts *p,
                       const st_grid *g, const st_pseudo_params *pp,
                       st_parts_tag_stats *stats, const st_progress *prog,
                       st_error *err);

/* What a tagged mesh says of its parts (tetstat): per part, from the
 * cell arrays "part" and "part_share" and the meta, the tets and their
 * volume (st_tetmesh_quality's, signed), the pseudo volume st_parts_tag
 * recorded (meta "part_pseudo_volume_K"; NAN where missing), and the
 * tets no part covered (share 0) in uncovered. out->nparts is 0 for a
 * mesh without parts (ST_OK). ST_ENOMEM. */
st_status st_parts_measure(st_parts_tag_stats *out, const st_tetmesh *m, st_error *err);

/* The parts a mesh's meta names (st_parts_tag's "parts", "part_name_K"):
 * *count, and names[K] borrowed from m's meta (NULL where missing); 0 and
 * NULL without. The caller frees *names with free(). ST_ENOMEM,
 * ST_EINPUT for a count that is not a number in 1..ST_PARTS_MAX. */
st_status st_parts_of_mesh(const char ***names, size_t *count, const st_tetmesh *m,
                           st_error *err);

#ifdef __cplusplus
}
#endif
#endif
