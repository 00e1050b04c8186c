/*
 * lexer.c - the private text lexer of the readers (lexer.h): the cursor
 * over a buffer that is not NUL-terminated, and numbers from (pointer,
 * length) tokens.
 */
#include "lexer.h"
#include "fpenv.h"

#include <limits.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* ---- text cursor ------------------------------------------------------- */

const unsigned char st_text_class[256] = {
    ['\0'] = ST_TEXT_C_BLANK, ['\t'] = ST_TEXT_C_BLANK, ['\n'] = ST_TEXT_C_NL,
    ['\v'] = ST_TEXT_C_BLANK, ['\f'] = ST_TEXT_C_BLANK, ['\r'] = ST_TEXT_C_BLANK,
    [' '] = ST_TEXT_C_BLANK,
};

void st_text_init(st_text *t, const unsigned char *data,
                  size_t size, unsigned flags)
{
    t->p = t->begin = data;
    t->end = data + size;
    t->line = 1;
    t->flags = flags;
}

/* The rest of the current line as one name: blanks at both ends trimmed
 * (a backslash continuation is not followed: names are one line). The
 * cursor stays where it was. */
size_t st_text_rest(const st_text *t, const unsigned char **name)
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

const unsigned char *st_text_line(const unsigned char *p,
                                  const unsigned char *end,
                                  const unsigned char **q,
                                  const unsigned char **e)
{
    const unsigned char *nl = memchr(p, '\n', (size_t)(end - p));
    *e = nl ? nl : end;
    *q = p;
    while (*q < *e && st_text_blank(**q))
        ++*q;
    return nl ? nl + 1 : end;
}

/* The line to blame for "the file ends here": the last line that exists
 * (a final '\n' does not start a new one). */
long long st_text_eof_line(const st_text *t)
{
    if (t->p == t->end && t->p > t->begin && t->p[-1] == '\n' && t->line > 1)
        return t->line - 1;
    return t->line;
}

/* Token equals the keyword kw (lower case), ASCII case-insensitively. */
int st_tok_ieq(const unsigned char *tok, size_t n, const char *kw)
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
int st_tok_eq(const unsigned char *tok, size_t n, const char *kw)
{
    return strlen(kw) == n && memcmp(tok, kw, n) == 0;
}

/* ---- numbers ----------------------------------------------------------- */

/* 10^k for k <= 22 is exactly representable in a double (5^22 < 2^53). */
static const double pow10_exact[23] = {
    1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,  1e8,  1e9,  1e10, 1e11,
    1e12, 1e13, 1e14, 1e15, 1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};

/* The longest token handed to strtod; longer ones are not numbers we take. */
#define SLOW_MAX 400

/* One more digit d of the mantissa (frac: after the point): the first 19
 * significant ones into m (nd of them), a later one only moves the power
 * of ten e10 (before the point) and marks the value inexact (not 0). */
static inline void take_digit(uint64_t *m, int *nd, long *e10, int *inexact,
                              unsigned d, int frac)
{
    if (*nd < 19) {
        if (*m || d) {
            *m = *m * 10 + d;
            ++*nd;
        }
        *e10 -= frac;
    } else {
        *e10 += !frac;
        *inexact |= d != 0;
    }
}

st_status st_text_double(const unsigned char *tok, size_t n, double *out)
{
    /*
     * Fast path (Clinger): a decimal with at most 19 significant digits
     * whose mantissa m fits in 53 bits and whose power of ten |e| <= 22 is
     * m * 10^e or m / 10^e, both exact operands and one correctly rounded
     * operation, so the result equals strtod's. Everything else (long
     * mantissas, big exponents, nan, inf, hex) goes to strtod on a bounded,
     * NUL-terminated copy of the token.
     */
    size_t i = 0;
    int neg = 0;
    if (i < n && (tok[i] == '+' || tok[i] == '-')) {
        neg = tok[i] == '-';
        i++;
    }
    /* At most 19 digits in all (every coordinate of the usual files):
     * take_digit would take each into m, leading zeros included (they add
     * nothing), and count the ones after the point in e10; so do that
     * without its tests. More digits: again, digit by digit. */
    const size_t start = i;
    uint64_t m = 0;
    int nd = 0, inexact = 0;
    long e10 = 0;
    size_t all = 0;
    for (; i < n; i++, all++) {
        unsigned d = (unsigned)tok[i] - '0';
        if (d > 9)
            break;
        m = m * 10 + d;
    }
    if (i < n && tok[i] == '.') {
        for (i++; i < n; i++, all++, e10--) {
            unsigned d = (unsigned)tok[i] - '0';
            if (d > 9)
                break;
            m = m * 10 + d;
        }
    }
    if (all == 0)
        goto slow;
    if (all > 19) {
        i = start;
        m = 0;
        e10 = 0;
        for (; i < n && tok[i] >= '0' && tok[i] <= '9'; i++)
            take_digit(&m, &nd, &e10, &inexact, (unsigned)(tok[i] - '0'), 0);
        if (i < n && tok[i] == '.') {
            for (i++; i < n && tok[i] >= '0' && tok[i] <= '9'; i++)
                take_digit(&m, &nd, &e10, &inexact, (unsigned)(tok[i] - '0'), 1);
        }
    }
    if (i < n && (tok[i] == 'e' || tok[i] == 'E')) {
        i++;
        int eneg = 0;
        if (i < n && (tok[i] == '+' || tok[i] == '-')) {
            eneg = tok[i] == '-';
            i++;
        }
        if (i == n || tok[i] < '0' || tok[i] > '9')
            goto slow;
        long e = 0;
        for (; i < n && tok[i] >= '0' && tok[i] <= '9'; i++)
            if (e < 100000)
                e = e * 10 + (tok[i] - '0');
        e10 += eneg ? -e : e;
    }
    if (i != n)
        goto slow;
    if (m == 0) {
        *out = neg ? -0.0 : 0.0;
        return ST_OK;
    }
    if (!inexact && m <= (UINT64_C(1) << 53) && e10 >= -22 && e10 <= 22) {
        double d = (double)m;
        d = e10 < 0 ? d / pow10_exact[-e10] : d * pow10_exact[e10];
        *out = neg ? -d : d;
        return ST_OK;
    }
slow:;
    char buf[SLOW_MAX + 1];
    if (n == 0 || n > SLOW_MAX)
        return ST_EINPUT;
    memcpy(buf, tok, n);
    buf[n] = '\0';
    char *endp;
    double d = strtod(buf, &endp);
    if (endp != buf + n)
        return ST_EINPUT;
    *out = d;
    return ST_OK;
}

st_status st_text_int_any(const unsigned char *tok, size_t n, long long *out)
{
    size_t i = 0;
    int neg = 0;
    if (i < n && (tok[i] == '+' || tok[i] == '-')) {
        neg = tok[i] == '-';
        i++;
    }
    if (i == n)
        return ST_EINPUT;
    unsigned long long v = 0;
    int big = 0;
    for (; i < n; i++) {
        if (tok[i] < '0' || tok[i] > '9')
            return ST_EINPUT;
        if (v > (unsigned long long)LLONG_MAX / 10)
            big = 1;
        else
            v = v * 10 + (unsigned)(tok[i] - '0');
    }
    if (big || v > (unsigned long long)LLONG_MAX)
        v = (unsigned long long)LLONG_MAX;
    *out = neg ? -(long long)v : (long long)v;
    return ST_OK;
}

const char *st_text_quote(char *buf, size_t bufsize,
                          const unsigned char *tok, size_t n)
{
    if (bufsize < 8) {
        if (bufsize)
            buf[0] = '\0';
        return buf;
    }
    size_t room = bufsize - 1, j = 0;
    size_t keep = n <= room ? n : room - 3;
    for (size_t i = 0; i < keep; i++)
        buf[j++] = (tok[i] >= 0x20 && tok[i] < 0x7f) ? (char)tok[i] : '?';
    if (keep < n) {
        memcpy(buf + j, "...", 3);
        j += 3;
    }
    buf[j] = '\0';
    return buf;
}

