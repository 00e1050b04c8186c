/*
 * soupwrite.h - writing a triangle soup as OBJ, OFF, binary PLY or binary
 * STL (the format picked by the caller, usually from the extension).
 *
 * Units: model units, as stored (binary STL rounds to float).
 * Ownership: the caller owns the stream and opens and commits it
 * (outfile.h); the soup is borrowed.
 * Threads: no global state; writes to different streams may run at once.
 * Errors: ST_EIO (a failed write), ST_EINPUT (a format that cannot hold the
 * soup), ST_ELIMIT.
 *
 * The writers put the vertices and triangles out as they are (no welding,
 * no reordering), so reading a file back with st_soup_read gives the same
 * soup: coordinates are printed with the fewest digits that read back as
 * the same double (9 for a float, at most 17), PLY stores float when
 * every coordinate is a float and double otherwise. Binary STL has
 * nothing but float triangles: coordinates are rounded to float there
 * (exact for soupwrap's output, which is float from the start), and the
 * vertices of each triangle are written out, as STL has no indices.
 *
 * History: `comment` (may be NULL; lines separated by '\n') goes into the
 * file as comments ('#' lines at the top of OBJ and at the end of OFF,
 * where TetGen 1.5, which aborts on a comment before the counts, ignores
 * them; "comment" lines in the PLY header);
 * STL has only its 80-byte header, which gets "souptet" and as much of
 * the last comment line as fits (never starting with "solid", so no
 * reader takes it for ASCII STL).
 *
 * The caller opens and commits the stream (souptet/outfile.h), so a
 * failed write leaves no file behind; these functions only write.
 */
#ifndef SOUPTET_SOUPWRITE_H
#define SOUPTET_SOUPWRITE_H

#include <stdio.h>
#include "souptet/err.h"
#include "souptet/soup.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Write s to f in `format` (OBJ, OFF, PLY or STL; UNKNOWN is an error).
 * name is used in messages. ST_EIO when a write fails, ST_ELIMIT when
 * binary STL's 32-bit triangle count would overflow, ST_EINPUT for an
 * unknown format. */
st_status st_soup_write(FILE *f, const st_soup *s, st_soup_format format,
                        const char *comment, const char *name,
                        st_error *err);

#ifdef __cplusplus
}
#endif
#endif
