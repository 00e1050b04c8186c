/*
 * lexer.h - the private text lexer the readers share: the surface readers
 * (soup_obj.c, soup_off.c, soup_ply.c, soup_stl.c) and the tet readers
 * (tetformat_msh.c, tetformat_medit.c, tetformat_tetgen.c). Not installed.
 *
 * Every reader works on a buffer that is NOT NUL-terminated: all scanning
 * goes through an st_text cursor that stops at `end`, and numbers are
 * converted from (pointer, length) tokens, never by handing the buffer to a
 * libc function that would look for a terminator.
 *
 * Threads: a cursor belongs to one reader; the functions keep no state.
 */
#ifndef SOUPTET_LEXER_H
#define SOUPTET_LEXER_H

#include <stddef.h>
#include <string.h>

#include "souptet/err.h"

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

void st_text_init(st_text *t, const unsigned char *data, size_t size,
                  unsigned flags);

/* The bytes' classes, one load where a token's every byte was up to seven
 * comparisons: ST_TEXT_C_BLANK for ' ', '\t', '\r', '\v', '\f' and '\0',
 * ST_TEXT_C_NL for '\n', 0 for every other byte (lexer.c). */
enum { ST_TEXT_C_BLANK = 1u, ST_TEXT_C_NL = 2u };
extern const unsigned char st_text_class[256];

/* Blank within a line: '\n' is the only line separator (CRLF leaves a '\r'
 * at the end of every line, which is just another blank). */
static inline int st_text_blank(unsigned char c)
{
    return st_text_class[c] & ST_TEXT_C_BLANK;
}

/* The cursor's inner loop (every token of every reader goes through it)
 * stays inline: out of line it cost the ASCII PLY reader 8% more
 * instructions (callgrind, dragon_res3.ply). */

/* Skip blanks on the current line; with ST_TEXT_CONT also a backslash that
 * ends a line, continuing on the next one. Stops at '\n', a token or end. */
static inline void st_text_skip_blank(st_text *t)
{
    for (;;) {
        /* locals: a store through t->p could alias the bytes read */
        const unsigned char *p = t->p, *end = t->end;
        while (p < end && st_text_blank(*p))
            p++;
        t->p = p;
        if (!(t->flags & ST_TEXT_CONT) || p == end || *p != '\\')
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
 * the line (the cursor then stays there, and *tok is the cursor). */
static inline size_t st_text_token(st_text *t, const unsigned char **tok)
{
    if (st_text_at_eol(t)) {
        *tok = t->p;
        return 0;
    }
    const unsigned char *s = t->p, *p = s, *end = t->end;
    while (p < end && !(st_text_class[*p] & (ST_TEXT_C_BLANK | ST_TEXT_C_NL)))
        p++;
    t->p = p;
    *tok = s;
    return (size_t)(p - s);
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

/* The rest of the current line as one name: blanks at both ends trimmed
 * (a backslash continuation is not followed: names are one line). The
 * cursor stays where it was. */
size_t st_text_rest(const st_text *t, const unsigned char **name);

/* The line at p (p < end), outside any cursor: its first byte that is
 * not blank in *q, its end ('\n' or end) in *e; returns the start of the
 * next line (end after the last). */
const unsigned char *st_text_line(const unsigned char *p,
                                  const unsigned char *end,
                                  const unsigned char **q,
                                  const unsigned char **e);

/* The line to blame for "the file ends here": the last line that exists
 * (a final '\n' does not start a new one). */
long long st_text_eof_line(const st_text *t);

/* Token equals the keyword kw (lower case), ASCII case-insensitively. */
int st_tok_ieq(const unsigned char *tok, size_t n, const char *kw);

/* Token equals kw exactly. */
int st_tok_eq(const unsigned char *tok, size_t n, const char *kw);

/* ---- numbers ----------------------------------------------------------- */

/* Convert a whole token to a double: ST_OK, or ST_EINPUT when the token
 * is not a number (no message). Non-finite results (nan, inf, 1e999) are
 * returned as such: the caller decides. */
st_status st_text_double(const unsigned char *tok, size_t n, double *out);

/* Convert a whole token "[+-]digits" to an integer, saturating at the
 * long long range (callers range-check): ST_OK, or ST_EINPUT when it is
 * not an integer. */
st_status st_text_int_any(const unsigned char *tok, size_t n, long long *out);

/* The same; a token of 1 to 18 digits alone (every face index of a file,
 * never beyond the range) is done here, inline: a call and a range check
 * per digit were half of what the OFF and PLY readers spent on a face. */
static inline st_status st_text_int(const unsigned char *tok, size_t n, long long *out)
{
    if (n - 1 < 18) {
        unsigned long long v = 0;
        size_t i = 0;
        for (; i < n; i++) {
            unsigned d = (unsigned)tok[i] - '0';
            if (d > 9)
                break;
            v = v * 10 + d;
        }
        if (i == n) {
            *out = (long long)v;
            return ST_OK;
        }
    }
    return st_text_int_any(tok, n, out);
}

/* Write tok as a short, printable quotation into buf (for messages):
 * non-printable bytes become '?', long tokens are cut with "...". */
const char *st_text_quote(char *buf, size_t bufsize,
                          const unsigned char *tok, size_t n);
#define ST_QUOTE_SIZE 48

#endif
