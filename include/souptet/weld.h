/*
 * weld.h - exact welding: vertices at the same position (bit for bit, with
 * -0 equal to 0) become one. The topology of a soup (its edges, holes and
 * pieces) is read on welded vertices, so an exact soup (every triangle
 * with its own three vertices) has the topology of the mesh it came from.
 *
 * Units: none: bit patterns of coordinates, indices.
 * Ownership: the caller owns the weld array (s->nverts entries); the soup
 * is borrowed.
 * Threads: no global state; thread-safe on different arrays.
 * Errors: out of memory is the only failure, reported by the return value
 * (below).
 */
#ifndef SOUPTET_WELD_H
#define SOUPTET_WELD_H

#include <stdint.h>
#include "souptet/err.h"
#include "souptet/soup.h"

#ifdef __cplusplus
extern "C" {
#endif

#define ST_WELD_NONE UINT32_MAX

/* weld[v] (s->nverts entries) = the welded id of referenced vertex v, ids
 * 0.. in order of first appearance; ST_WELD_NONE for a vertex no triangle
 * uses; *nweld = the number of welded ids. Returns ST_OK, or ST_ENOMEM
 * (err set, *nweld 0). */
st_status st_weld_vertices(uint32_t *weld, size_t *nweld, const st_soup *s,
                           st_error *err);

#ifdef __cplusplus
}
#endif
#endif
