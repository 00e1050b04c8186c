/*
 * soup.h - triangle soups and the surface readers.
 *
 * Units: whatever the file's coordinates are (model units, never rescaled).
 * Ownership: the caller owns a soup (st_soup_free, safe on NULL) and
 * everything in it.
 * Threads: no global state; readers on different files may run at once; a
 * soup is read-only to everything but its owner.
 * Errors: ST_EIO (naming the path), ST_EINPUT (naming file and line or byte
 * offset), ST_ELIMIT, ST_ENOMEM; no soup on error.
 *
 * A soup is a vertex array and a triangle array, exactly as the file gives
 * them: vertices are never welded, duplicated or degenerate triangles are
 * kept, orientation is whatever the file says. Polygons are fan-triangulated
 * (v0 v1 v2, v0 v2 v3, ...). All OBJ groups and objects form one soup (their names
 * are noted, below).
 *
 * Formats: OBJ (v/f, negative indices), OFF (also COFF/NOFF/...), PLY (ascii,
 * binary_little_endian, binary_big_endian; any scalar property type; the
 * face list may be named vertex_indices or vertex_index), STL (ASCII and
 * binary), glTF 2.0 (.gltf with external or data-URI buffers, .glb: the
 * triangle, strip and fan primitives of the default scene's node trees,
 * in world space; see soup_gltf.c).
 *
 * Named parts: the readers also note where the file names a part (OBJ
 * `o` and `g` lines, a glTF node with a mesh, an ASCII STL `solid NAME`)
 * as runs in st_soup.names: a run starts at a triangle and lasts until the
 * next run of its level. Nothing is stored for a file without names, and
 * nothing else reads them: parts.h turns them into parts.
 *
 * Readers parse a memory buffer (so fuzzers and pipes use the same code) and
 * never trust a count from the file for an allocation: arrays grow with the
 * data actually present, and a header count is checked against the bytes
 * left before anything is reserved. Every error names the file and a line
 * (text) or a byte offset (binary).
 */
#ifndef SOUPTET_SOUP_H
#define SOUPTET_SOUP_H

#include <stddef.h>
#include <stdint.h>
#include "souptet/err.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum st_soup_format {
    ST_SOUP_UNKNOWN = 0,
    ST_SOUP_OBJ,
    ST_SOUP_OFF,
    ST_SOUP_PLY,
    ST_SOUP_STL,
    ST_SOUP_GLTF        /* .gltf (JSON) and .glb (binary), told apart by content */
} st_soup_format;

/* A zero-initialised st_soup is a valid empty soup. Grow xyz and tris only
 * through st_soup_add_vertex / st_soup_add_triangle: their capacity is
 * derived from the counts. */
/* One named run of triangles: from triangle `first` up to the next run
 * of the same level (or the end). level 1: an OBJ object (`o`), a glTF
 * mesh node, an STL solid; level 2: an OBJ group (`g`). name is the
 * rest of the line (blanks at both ends trimmed; "g a b" is "a b"), or the
 * glTF node's (else its mesh's) name: bytes, NUL-terminated, at most 255
 * (not checked as UTF-8; may be ""). */
typedef struct st_soup_name {
    size_t first;
    char *name;
    int level;
} st_soup_name;

typedef struct st_soup {
    double *xyz;        /* 3 * nverts coordinates, all finite */
    size_t nverts;
    uint32_t *tris;     /* 3 * ntris vertex indices, each < nverts */
    size_t ntris;
    st_soup_name *names;    /* the file's named runs in file order (NULL,
                               nnames 0: none); owned, freed by st_soup_free */
    size_t nnames;
} st_soup;

/* An empty soup; NULL when out of memory. */
st_soup *st_soup_new(void);
/* Safe on NULL. */
void st_soup_free(st_soup *s);

/* Append a vertex / a triangle, growing the arrays geometrically.
 * ST_ENOMEM, or ST_ELIMIT past UINT32_MAX vertices; add_triangle refuses
 * indices >= nverts (ST_EINPUT). */
st_status st_soup_add_vertex(st_soup *s, double x, double y, double z,
                             st_error *err);
st_status st_soup_add_triangle(st_soup *s, uint32_t a, uint32_t b, uint32_t c,
                               st_error *err);

/* What a reader accepted but did not expect (a PLY header line without a
 * keyword, ...): the first such note with its place (first.status is
 * ST_OK, first.msg "" when there was none) and how many there were. The
 * library never prints them; a tool does (tool_soup_read). */
typedef struct st_soup_warnings {
    st_error first;
    size_t count;
} st_soup_warnings;

/* Parse a whole file held in memory (format must be known: ST_SOUP_UNKNOWN
 * is an error). A glTF document parsed from memory can only use data-URI
 * and GLB buffers (st_soup_read also finds the files beside it). name is used in messages only. Numbers with more than 19
 * significant digits or unusual exponents go through strtod, which follows
 * the C locale's decimal point: tools run in the "C" locale.
 * On success *out owns a soup with at least one triangle. On failure *out
 * is NULL and err says what and where. */
st_status st_soup_parse(st_soup **out, st_soup_format format,
                        const unsigned char *data, size_t size,
                        const char *name, st_error *err);

/* As st_soup_parse / st_soup_read, and the warnings into *warn (cleared
 * first; may be NULL), also when parsing fails. */
st_status st_soup_parse_warn(st_soup **out, st_soup_format format,
                             const unsigned char *data, size_t size,
                             const char *name, st_soup_warnings *warn,
                             st_error *err);
st_status st_soup_read_warn(st_soup **out, const char *path,
                            st_soup_warnings *warn, st_error *err);

/* The format named by a path's extension (case-insensitive), or UNKNOWN. */
st_soup_format st_soup_format_from_path(const char *path);
/* The format recognised from a file's first bytes (for stdin), or UNKNOWN. */
st_soup_format st_soup_format_sniff(const unsigned char *data, size_t size);
/* "obj", "off", "ply", "stl", "gltf" or "unknown". */
const char *st_soup_format_name(st_soup_format format);

/* Read a surface file; "-" reads stdin (format sniffed). The format comes
 * from the extension, else from the content. Directories, missing and
 * unreadable files, empty files and files without triangles are errors. */
st_status st_soup_read(st_soup **out, const char *path, st_error *err);

/* What a file's bytes were, so a later reader can tell the same file from
 * a changed one: its size and a 128-bit content hash (XXH3-128, as
 * "xxh3-128:" and 32 hex digits). Not a cryptographic hash: it tells
 * accidental changes, not a forgery. */
#define ST_SOUP_HASH_LEN 48
typedef struct st_soup_source {
    unsigned long long size;
    char hash[ST_SOUP_HASH_LEN];
} st_soup_source;

/* st_soup_read that also gives the source's size and hash (src may be
 * NULL) and the reader's warnings (warn may be NULL; st_soup_read_warn).
 * For a .gltf the hash covers the JSON file and the external buffer files
 * the reader loaded (each after its length), and the size is their sum: a
 * changed .bin is a changed source. *src is filled whenever the file's
 * bytes were read, even when
 * they do not parse (so a changed file is told from a broken one), and
 * zeroed otherwise. */
st_status st_soup_read_source(st_soup **out, const char *path, st_soup_source *src,
                              st_soup_warnings *warn, st_error *err);
/* The size and hash of bytes held in memory. */
void st_soup_source_of(st_soup_source *src, const void *data, size_t size);

/* Axis-aligned bounds of the referenced vertices: lo[3], hi[3].
 * Returns ST_EINPUT when the soup has no triangles. */
st_status st_soup_bounds(const st_soup *s, double lo[3], double hi[3],
                         st_error *err);

/* Note a named run starting at the next triangle (s->ntris): name is
 * len bytes, copied. ST_ENOMEM. */
st_status st_soup_add_name(st_soup *s, int level, const char *name, size_t len,
                           st_error *err);

/* Append src's vertices and triangles to dst (src's indices shifted; the
 * names are not carried).
 * ST_ENOMEM or ST_ELIMIT; dst keeps what it had on failure only in part. */
st_status st_soup_append(st_soup *dst, const st_soup *src, st_error *err);

#ifdef __cplusplus
}
#endif
#endif
