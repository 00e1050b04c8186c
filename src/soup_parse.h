/*
 * soup_parse.h - internal helpers shared by the surface readers
 * (soup_obj.c, soup_off.c, soup_ply.c, soup_stl.c). Not installed.
 *
 * Every reader works on a buffer that is NOT NUL-terminated: all scanning
 * goes through an st_text cursor that stops at `end`, and numbers are
 * converted from (pointer, length) tokens, never by handing the buffer to a
 * libc function that would look for a terminator.
 */
#ifndef SOUPTET_SOUP_PARSE_H
#define SOUPTET_SOUP_PARSE_H

#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "souptet/err.h"
#include "souptet/soup.h"

/* ---- text cursor ------------------------------------------------------ */

enum {
    ST_TEXT_HASH = 1u, /* '#' at the start of a token comments out the line */
    ST_TEXT_CONT = 2u  /* backslash-newline joins lines (OBJ) */
};

typedef struct st_text {
    const unsigned char *p;     /* cursor */
    const unsigned char *begin; /* first byte of the buffer */
    const unsigned char *end;   /* one past the last byte; never read */
    long long line;             /* 1-based line of *p */
    unsigned flags;
} st_text;

static inline void st_text_init(st_text *t, const unsigned char *data,
                                size_t size, unsigned flags)
{
    t->p = t->begin = data;
    t->end = data + size;
    t->line = 1;
    t->flags = flags;
}

/* Blank within a line: '\n' is the only line separator (CRLF leaves a '\r'
 * at the end of every line, which is just another blank). */
static inline int st_text_blank(unsigned char c)
{
    return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f' ||
           c == '\0';
}

/* Skip blanks on the current line; with ST_TEXT_CONT also a backslash that
 * ends a line, continuing on the next one. Stops at '\n', a token or end. */
static inline void st_text_skip_blank(st_text *t)
{
    for (;;) {
        while (t->p < t->end && st_text_blank(*t->p))
            t->p++;
        if (!(t->flags & ST_TEXT_CONT) || t->p == t->end || *t->p != '\\')
            return;
        const unsigned char *q = t->p + 1;
        while (q < t->end && *q == '\r')
            q++;
        if (q == t->end) {              /* a lone backslash at the end */
            t->p = q;
            return;
        }
        if (*q != '\n')
            return;                     /* an ordinary backslash token */
        t->p = q + 1;
        t->line++;
    }
}

/* True at the end of the current line (after blanks): '\n', end of buffer
 * or, with ST_TEXT_HASH, a comment. */
static inline int st_text_at_eol(st_text *t)
{
    st_text_skip_blank(t);
    return t->p == t->end || *t->p == '\n' ||
           ((t->flags & ST_TEXT_HASH) && *t->p == '#');
}

/* The next token on the current line: *tok and its length, 0 at the end of
 * the line (the cursor then stays there). */
static inline size_t st_text_token(st_text *t, const unsigned char **tok)
{
    if (st_text_at_eol(t))
        return 0;
    const unsigned char *s = t->p;
    while (t->p < t->end && *t->p != '\n' && !st_text_blank(*t->p))
        t->p++;
    *tok = s;
    return (size_t)(t->p - s);
}

/* The rest of the current line as one name: blanks at both ends trimmed
 * (a backslash continuation is not followed: names are one line). The
 * cursor stays where it was. */
static inline size_t st_text_rest(const st_text *t, const unsigned char **name)
{
    const unsigned char *p = t->p, *q;
    while (p < t->end && *p != '\n' && st_text_blank(*p))
        p++;
    q = p;
    while (q < t->end && *q != '\n')
        q++;
    while (q > p && st_text_blank(q[-1]))
        q--;
    *name = p;
    return (size_t)(q - p);
}

/* Move to the start of the next line (or to the end). */
static inline void st_text_next_line(st_text *t)
{
    const unsigned char *nl =
        memchr(t->p, '\n', (size_t)(t->end - t->p));
    if (!nl) {
        t->p = t->end;
        return;
    }
    t->p = nl + 1;
    t->line++;
}

/* The next token anywhere: skips blank lines and (with ST_TEXT_HASH)
 * comments. 0 at the end of the buffer. */
static inline size_t st_text_token_any(st_text *t, const unsigned char **tok)
{
    for (;;) {
        size_t n = st_text_token(t, tok);
        if (n)
            return n;
        if (t->p == t->end)
            return 0;
        st_text_next_line(t);
    }
}

/* The line to blame for "the file ends here": the last line that exists
 * (a final '\n' does not start a new one). */
static inline long long st_text_eof_line(const st_text *t)
{
    if (t->p == t->end && t->p > t->begin && t->p[-1] == '\n' && t->line > 1)
        return t->line - 1;
    return t->line;
}

/* Token equals the keyword kw (lower case), ASCII case-insensitively. */
static inline int st_tok_ieq(const unsigned char *tok, size_t n,
                             const char *kw)
{
    size_t i = 0;
    for (; i < n; i++) {
        unsigned char c = tok[i];
        if (c >= 'A' && c <= 'Z')
            c = (unsigned char)(c - 'A' + 'a');
        if (kw[i] == '\0' || c != (unsigned char)kw[i])
            return 0;
    }
    return kw[i] == '\0';
}

/* Token equals kw exactly. */
static inline int st_tok_eq(const unsigned char *tok, size_t n,
                            const char *kw)
{
    return strlen(kw) == n && memcmp(tok, kw, n) == 0;
}

/* ---- numbers (soup.c) ------------------------------------------------- */

/* Convert a whole token to a double. Returns 0, or -1 when the token is
 * not a number. Non-finite results (nan, inf, 1e999) are returned as such:
 * the caller decides. */
int st_soup__scan_double(const unsigned char *tok, size_t n, double *out);

/* Convert a whole token "[+-]digits" to an integer, saturating at the
 * long long range (callers range-check). Returns 0, or -1 when it is not an
 * integer. */
int st_soup__scan_int(const unsigned char *tok, size_t n, long long *out);

/* Write tok as a short, printable quotation into buf (for messages):
 * non-printable bytes become '?', long tokens are cut with "...". */
const char *st_soup__quote(char *buf, size_t bufsize,
                           const unsigned char *tok, size_t n);
#define ST_QUOTE_SIZE 48

/* ---- building the soup (soup.c) ---------------------------------------- */

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

/* ---- the readers ------------------------------------------------------- */

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
