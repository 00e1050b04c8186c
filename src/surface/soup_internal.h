/*
 * soup_internal.h - what the soup type (soup.c) offers its readers
 * (soupread.h): appends without the checks the public ones make. Not
 * installed.
 */
#ifndef SOUPTET_SOUP_INTERNAL_H
#define SOUPTET_SOUP_INTERNAL_H

#include <stddef.h>
#include <stdint.h>

#include "souptet/err.h"
#include "souptet/soup.h"

/* Append without the index check st_soup_add_triangle does (PLY faces may
 * come before the vertices; OBJ may refer to later vertices): the readers
 * check the indices themselves. ST_ENOMEM or ST_ELIMIT, no message. */
st_status st_soup__push_vertex(st_soup *s, double x, double y, double z);
st_status st_soup__push_tri(st_soup *s, uint32_t a, uint32_t b, uint32_t c);
/* Note a named run at the next triangle (soup.h, st_soup_name); a name is
 * kept to ST_SOUP_NAME_MAX bytes (longer ones are cut: a part's name is a
 * label, and gmsh's physical names are short). ST_ENOMEM. */
#define ST_SOUP_NAME_MAX 255
st_status st_soup__push_name(st_soup *s, int level, const unsigned char *name,
                             size_t len);

/* Fill err for a failed push at a text line (offset < 0) or byte offset. */
st_status st_soup__push_failed(st_error *err, st_status st, const char *name,
                               long long line, long long offset);

#endif
