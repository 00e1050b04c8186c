/*
 * soupread.h - the per-format surface readers (soup_obj.c, soup_off.c,
 * soup_ply.c, soup_stl.c, soup_gltf.c) and what soupread.c, their front
 * door, shares with them. Not installed.
 *
 * The readers scan text with the private lexer (lexer.h), decode bytes
 * with bytes.h and build the soup with soup_internal.h's appends.
 */
#ifndef SOUPTET_SOUPREAD_H
#define SOUPTET_SOUPREAD_H

#include <stddef.h>

#include "souptet/err.h"
#include "souptet/soup.h"

/* Each appends to an empty soup s; on failure err is set (the caller frees
 * s). They do not check for "no triangles": st_soup_parse does. */
st_status st_soup__parse_obj(st_soup *s, const unsigned char *data,
                             size_t size, const char *name, st_error *err);
st_status st_soup__parse_off(st_soup *s, const unsigned char *data,
                             size_t size, const char *name, st_error *err);
st_status st_soup__parse_ply(st_soup *s, const unsigned char *data,
                             size_t size, const char *name,
                             st_soup_warnings *warn, st_error *err);
st_status st_soup__parse_stl(st_soup *s, const unsigned char *data,
                             size_t size, const char *name, st_error *err);

/* Told the bytes of each external buffer file a glTF reader loads, in
 * the order it loads them (so a caller can hash what the soup came from). */
typedef struct st_soup__file_hook {
    void (*bytes)(void *ctx, const unsigned char *data, size_t size);
    void *ctx;
} st_soup__file_hook;

/* glTF: path is the .gltf's own path, for buffers in files beside it
 * (NULL: such buffers are an error); hook (may be NULL) is told each such
 * file's bytes. */
st_status st_soup__parse_gltf(st_soup *s, const unsigned char *data,
                              size_t size, const char *name, const char *path,
                              const st_soup__file_hook *hook,
                              st_soup_warnings *warn, st_error *err);

/* Record a warning at a text line (offset < 0) or a byte offset: the first
 * is kept whole, the others counted. warn may be NULL. */
void st_soup__warn(st_soup_warnings *warn, const char *name, long long line,
                   long long offset, const char *fmt, ...)
#ifdef __GNUC__
    __attribute__((format(printf, 5, 6)))
#endif
    ;

/* STL kind from the content: 1 ASCII, 0 binary (see soup_stl.c). */
int st_soup__stl_is_ascii(const unsigned char *data, size_t size);

#endif
