/*
 * fileio.h - the file plumbing every reader and writer shares: path
 * extensions, whole-file and standard-input reads, a file's first bytes,
 * the VTK XML sniff, and the check before a library opens a file by name.
 * Private (not installed): soupread.c, gridio.c, tetio.c, tetformat*.c,
 * vtkxml.c and the C++ adapters use it; extern "C", never prints.
 */
#ifndef SOUPTET_FILEIO_H
#define SOUPTET_FILEIO_H

#include <stddef.h>

#include "souptet/err.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The names messages use for standard input and output. */
#define ST_STDIN_NAME "<stdin>"
#define ST_STDOUT_NAME "<stdout>"

/* Which of the n extensions exts[] (without the dot, ASCII
 * case-insensitive) path has: its index, or -1. The extension is the
 * last path component's, after its last dot: "a.vdb/field" and the
 * hidden file ".vtu" have none. With outfile_tmp, a path whose own
 * extension matches none and that is a temporary name of st_outfile_begin
 * ("dir/.name.msh.tmp-PID@HOST.XXXXXX") is matched by its target's name
 * (st_outfile_target_of). NULL gives -1. */
int st_path_ext_match(const char *path, const char *const *exts, size_t n,
                      int outfile_tmp);

/* Read all of path into a malloc'd buffer *data of *size bytes (never
 * NULL on success, even for 0 bytes; the caller frees). NULL or "-"
 * reads standard input to its end. Messages name path (ST_STDIN_NAME
 * for standard input): ST_EIO "cannot open: why", "is a directory",
 * "cannot read: why"; ST_ENOMEM "out of memory". A regular file's size
 * is only a first guess: the bytes that arrive decide. */
st_status st_file_read(const char *path, unsigned char **data, size_t *size,
                       st_error *err);

/* The first bytes of the file path: up to cap into buf, *n of them (0 for
 * an empty file, which fails). ST_EIO "cannot open: why" or "cannot read:
 * why"; ST_EINPUT "empty file". */
st_status st_file_head(const char *path, unsigned char *buf, size_t cap,
                       size_t *n, st_error *err);

/* VTK XML, by its first significant byte: '<' after an optional UTF-8
 * byte-order mark and white space. */
int st_looks_like_xml(const unsigned char *p, size_t n);

/* The checks by path before a library (VTK, OpenVDB) reads a file by
 * name, so that the usual failures get the system's words, not the
 * library's: ST_EIO "cannot open: why" or "is a directory", ST_EINPUT
 * "empty file". */
st_status st_file_check_input(const char *path, st_error *err);

#ifdef __cplusplus
}
#endif
#endif
