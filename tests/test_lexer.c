/*
 * test_lexer.c - the readers' private lexer (src/base/lexer.h): its numbers
 * against the C library and its own general paths, its tokens against the
 * byte classes written out one comparison at a time. Random tokens, so the
 * fast paths (a short digit-only integer, a mantissa of at most 19 digits)
 * and the ones they hand over to (a sign, 19 or more digits, an exponent,
 * a stray byte) are all crossed.
 */
#include "../src/base/lexer.h"
#define SPLITMIX_SEED 41
#include "splitmix.h"
#include "tap.h"

#include <errno.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* n random decimal digits into p; a leading run of zeros one time in four. */
static size_t digits(char *p, size_t n)
{
    size_t zeros = rng_next() % 4 == 0 ? (size_t)(rng_next() % (n + 1)) : 0;
    for (size_t i = 0; i < n; i++)
        p[i] = i < zeros ? '0' : (char)('0' + rng_next() % 10);
    return n;
}

/* A number-like token: [sign] [digits] [. [digits]] [e [sign] digits],
 * 0 to 25 digits in all (often 17 to 21), now and then a stray byte. */
static size_t double_token(char *buf)
{
    size_t n = 0;
    if (rng_next() % 3 == 0)
        buf[n++] = rng_next() % 2 ? '-' : '+';
    /* one time in three 17 to 21 digits: where the fast path hands over */
    size_t all = (size_t)(rng_next() % 3 == 0 ? 17 + rng_next() % 5 : rng_next() % 26);
    size_t before = (size_t)(rng_next() % (all + 1));
    n += digits(buf + n, before);
    if (before < all || rng_next() % 4 == 0) {
        buf[n++] = '.';
        n += digits(buf + n, all - before);
    }
    if (rng_next() % 3 == 0) {
        buf[n++] = rng_next() % 2 ? 'e' : 'E';
        if (rng_next() % 2)
            buf[n++] = rng_next() % 2 ? '-' : '+';
        n += digits(buf + n, (size_t)(rng_next() % 4));
    }
    if (rng_next() % 20 == 0)
        buf[rng_next() % (n + 1)] = "x.e-+ "[rng_next() % 6];
    buf[n] = '\0';
    return n;
}

/* Every token converts to strtod's double, bit for bit, or is refused
 * exactly where strtod does not take the whole token. */
static void test_doubles(void)
{
    size_t bad = 0, fast = 0, refused = 0;
    const size_t N = 300000;
    for (size_t k = 0; k < N; k++) {
        char buf[64];
        size_t n = double_token(buf);
        char *end;
        errno = 0;
        double want = strtod(buf, &end);
        int ok_want = n > 0 && end == buf + n;
        double got = 0.0;
        int ok_got = st_text_double((const unsigned char *)buf, n, &got) == ST_OK;
        if (ok_want != ok_got || (ok_got && memcmp(&want, &got, sizeof got) != 0)) {
            if (bad++ < 5)
                TAP_NOTE("'%s': strtod %.17g (%s), lexer %.17g (%s)", buf, want,
                         ok_want ? "taken" : "refused", got, ok_got ? "taken" : "refused");
        }
        fast += ok_got && n <= 20 && !strpbrk(buf, "eE");
        refused += !ok_want;
    }
    TAP_CHECK(bad == 0, "st_text_double: %zu of %zu random tokens as strtod (%zu short, "
              "%zu refused)", N - bad, N, fast, refused);
}

/* An integer-like token: [sign] 0 to 22 digits, now and then a stray byte. */
static size_t int_token(char *buf)
{
    size_t n = 0;
    if (rng_next() % 4 == 0)
        buf[n++] = rng_next() % 2 ? '-' : '+';
    n += digits(buf + n, (size_t)(rng_next() % 23));
    if (n && rng_next() % 10 == 0)
        buf[rng_next() % n] = "x.e- "[rng_next() % 5];
    buf[n] = '\0';
    return n;
}

/* The inline st_text_int against the general st_text_int_any, and both
 * against strtoll where it does not saturate. */
static void test_ints(void)
{
    size_t bad = 0, taken = 0;
    const size_t N = 300000;
    for (size_t k = 0; k < N; k++) {
        char buf[64];
        size_t n = int_token(buf);
        const unsigned char *u = (const unsigned char *)buf;
        long long a = -7, b = -7;
        st_status ra = st_text_int(u, n, &a), rb = st_text_int_any(u, n, &b);
        char *end;
        errno = 0;
        long long c = strtoll(buf, &end, 10);
        int c_ok = n > 0 && end == buf + n && errno == 0 && buf[0] != ' ';
        int same = ra == rb && (ra != ST_OK || a == b) && (!c_ok || (ra == ST_OK && a == c));
        if (!same && bad++ < 5)
            TAP_NOTE("'%s': inline %d %lld, general %d %lld, strtoll %lld", buf, (int)ra, a,
                     (int)rb, b, c);
        taken += ra == ST_OK;
    }
    TAP_CHECK(bad == 0, "st_text_int: %zu of %zu random tokens as st_text_int_any and "
              "strtoll (%zu integers)", N - bad, N, taken);
}

/* The blanks of lexer.h, one comparison at a time. */
static int blank_ref(unsigned char c)
{
    return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f' || c == '\0';
}

/* Every byte's class, and the tokens of random lines: st_text_token_any
 * against a scan by blank_ref, with and without '#' comments. */
static void test_tokens(void)
{
    int classes = 1;
    for (int c = 0; c < 256; c++)
        classes &= !!st_text_blank((unsigned char)c) == blank_ref((unsigned char)c);
    TAP_CHECK(classes, "st_text_blank: the six blank bytes and no other");

    static const char alphabet[] = "ab9.-# \t\n\r\v\f\\";
    size_t bad = 0;
    const int N = 3000;
    for (int k = 0; k < N; k++) {
        unsigned char buf[200];
        size_t len = (size_t)(rng_next() % sizeof buf);
        for (size_t i = 0; i < len; i++)
            buf[i] = rng_next() % 40 == 0 ? 0 : (unsigned char)alphabet[rng_next() % (sizeof alphabet - 1)];
        unsigned flags = k % 2 ? ST_TEXT_HASH : 0;
        st_text t;
        st_text_init(&t, buf, len, flags);
        size_t p = 0;       /* the reference cursor */
        for (;;) {
            /* the reference: skip blanks, newlines and comments */
            size_t s, e;
            for (;;) {
                while (p < len && blank_ref(buf[p]))
                    p++;
                if (p < len && (flags & ST_TEXT_HASH) && buf[p] == '#') {
                    while (p < len && buf[p] != '\n')
                        p++;
                }
                if (p < len && buf[p] == '\n') {
                    p++;
                    continue;
                }
                break;
            }
            s = e = p;
            while (e < len && buf[e] != '\n' && !blank_ref(buf[e]))
                e++;
            p = e;
            const unsigned char *tok;
            size_t n = st_text_token_any(&t, &tok);
            if (n != e - s || (n && tok != buf + s)) {
                bad++;
                break;
            }
            if (!n)
                break;
        }
    }
    TAP_CHECK(bad == 0, "st_text_token_any: %d of %d random buffers cut as the reference",
              N - (int)bad, N);
}

int main(int argc, char **argv)
{
    static const tap_test tests[] = {TAP_TEST(doubles), TAP_TEST(ints), TAP_TEST(tokens), {NULL, NULL}};
    return tap_main(argc, argv, tests);
}
