/*
 * err.h - error records for the souptet library.
 *
 * Units: none.
 * Ownership: the caller owns every st_error (a plain struct, nothing to
 * free).
 * Threads: no global state: each thread fills its own st_error.
 * Errors: this module defines them: st_status below; st_error_set returns
 * the status it stores.
 *
 * The library never prints and never exits.  A function that can fail takes
 * a caller-owned st_error as its last argument, fills it on failure, and
 * returns the status it stored there.  The message names what went wrong;
 * file, line and byte offset say where, so a tool can print
 * "tool: FILE:LINE: what" (or "FILE: byte N: what" for binary input).
 *
 * The module order, err first, is written once, in src/MODULES: a module
 * uses only those above it (make check: tests/tools/layering.t).
 */
#ifndef SOUPTET_ERR_H
#define SOUPTET_ERR_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef enum st_status {
    ST_OK = 0,
    ST_EINPUT,    /* malformed or unsuitable input data */
    ST_EIO,       /* the operating system refused: open, read, write */
    ST_ENOMEM,    /* allocation failed or a size overflowed */
    ST_ELIMIT,    /* a size exceeds a configured limit */
    ST_EINTERNAL, /* a bug: an invariant did not hold */
    ST_ECANCELLED /* the caller asked to stop (progress.h's cancel flag) */
} st_status;

typedef struct st_error {
    st_status status;
    char file[512];     /* file the problem is in, "" when none */
    long long line;     /* 1-based line in a text file, 0 when none */
    long long offset;   /* byte offset in a binary file, -1 when none */
    char msg[512];      /* what went wrong, no trailing newline */
} st_error;

/* Reset to "no error". Safe on NULL. */
void st_error_clear(st_error *err);

/* Store status, location and a printf-style message; returns status.
 * file may be NULL; line 0 means no line; err may be NULL (then only the
 * status is returned). */
st_status st_error_set(st_error *err, st_status status, const char *file,
                       long long line, const char *fmt, ...)
#ifdef __GNUC__
    __attribute__((format(printf, 5, 6)))
#endif
    ;

/* As st_error_set, with a byte offset instead of a line (binary input). */
st_status st_error_set_offset(st_error *err, st_status status,
                              const char *file, long long offset,
                              const char *fmt, ...)
#ifdef __GNUC__
    __attribute__((format(printf, 5, 6)))
#endif
    ;

/* Format as "FILE:LINE: msg", "FILE: byte N: msg", "FILE: msg" or "msg"
 * into buf (always NUL-terminated when n > 0). Returns buf. */
char *st_error_format(const st_error *err, char *buf, size_t n);

/* A short name of a status ("bad input", "I/O error", ...). */
const char *st_status_name(st_status status);

#ifdef __cplusplus
}
#endif
#endif
