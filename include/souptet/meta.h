/*
 * meta.h - string metadata carried by fields and meshes.
 *
 * Units: none: strings.
 * Ownership: a struct owns its keys and values (st_meta_clear frees them);
 * st_command_line's string is the caller's.
 * Threads: no global state; one writer per st_meta.
 * Errors: ST_ENOMEM (st_command_line: NULL).
 *
 * An ordered list of key/value strings. Every tool appends its command line
 * to the "history" key (lines joined by '\n'), so every output says how it
 * was made (after Radiance's headers).
 */
#ifndef SOUPTET_META_H
#define SOUPTET_META_H

#include <stddef.h>
#include "souptet/err.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct st_meta_entry {
    char *key;
    char *value;
} st_meta_entry;

typedef struct st_meta {
    st_meta_entry *entries;
    size_t count;
    size_t capacity;
} st_meta;

/* An empty list needs no allocation: st_meta m = {0}. */
void st_meta_clear(st_meta *m);                 /* frees everything */
/* Set key to value, replacing an existing value. ST_ENOMEM on failure. */
st_status st_meta_set(st_meta *m, const char *key, const char *value);
/* The value of key, or NULL. */
const char *st_meta_get(const st_meta *m, const char *key);
/* Append one line to the "history" entry. */
st_status st_meta_history_append(st_meta *m, const char *line);
/* Deep copy of src into dst (dst's old contents are freed). */
st_status st_meta_copy(st_meta *dst, const st_meta *src);
/* m inherits from's entries: afterwards it holds from's entries in from's
 * order, each replaced by m's own value where m has the key, then m's
 * other keys in m's order (what a tool's output keeps of its input's
 * source and history while its own keys win). On ST_ENOMEM m is
 * unchanged. */
st_status st_meta_inherit(st_meta *m, const st_meta *from);

/* A command line as one string, arguments with spaces or quotes shell-quoted.
 * Caller frees. NULL on allocation failure. */
char *st_command_line(int argc, char *const argv[]);

#ifdef __cplusplus
}
#endif
#endif
