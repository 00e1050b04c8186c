/*
 * bytes.c - base64 for the readers (bytes.h): one decoder, the glTF data
 * URIs' (a stream with optional padding, URL-safe alphabet allowed) and
 * VTK XML's quads (standard alphabet) both on it.
 */
#include "bytes.h"

const unsigned char st_b64_table[256] = {
    ['A'] = 1, ['B'] = 2, ['C'] = 3, ['D'] = 4, ['E'] = 5, ['F'] = 6,
    ['G'] = 7, ['H'] = 8, ['I'] = 9, ['J'] = 10, ['K'] = 11, ['L'] = 12,
    ['M'] = 13, ['N'] = 14, ['O'] = 15, ['P'] = 16, ['Q'] = 17, ['R'] = 18,
    ['S'] = 19, ['T'] = 20, ['U'] = 21, ['V'] = 22, ['W'] = 23, ['X'] = 24,
    ['Y'] = 25, ['Z'] = 26, ['a'] = 27, ['b'] = 28, ['c'] = 29, ['d'] = 30,
    ['e'] = 31, ['f'] = 32, ['g'] = 33, ['h'] = 34, ['i'] = 35, ['j'] = 36,
    ['k'] = 37, ['l'] = 38, ['m'] = 39, ['n'] = 40, ['o'] = 41, ['p'] = 42,
    ['q'] = 43, ['r'] = 44, ['s'] = 45, ['t'] = 46, ['u'] = 47, ['v'] = 48,
    ['w'] = 49, ['x'] = 50, ['y'] = 51, ['z'] = 52, ['0'] = 53, ['1'] = 54,
    ['2'] = 55, ['3'] = 56, ['4'] = 57, ['5'] = 58, ['6'] = 59, ['7'] = 60,
    ['8'] = 61, ['9'] = 62, ['+'] = 63, ['/'] = 64,
};

int st_b64_value(unsigned char c, unsigned flags)
{
    if (flags & ST_B64_URL) {
        if (c == '-')
            return 62;
        if (c == '_')
            return 63;
    }
    return (int)st_b64_table[c] - 1;
}

size_t st_b64_decode(const unsigned char *s, size_t n, unsigned flags,
                     unsigned char *out, size_t *stop)
{
    size_t o = 0, i = 0;
    unsigned acc = 0;
    int bits = 0;
    for (; i < n; i++) {
        int v = st_b64_value(s[i], flags);
        if (v < 0)
            break;
        acc = acc << 6 | (unsigned)v;
        bits += 6;
        if (bits >= 8) {
            bits -= 8;
            out[o++] = (unsigned char)(acc >> bits);
        }
    }
    if (stop)
        *stop = i;
    return o;
}

int st_b64_quad(const unsigned char *p, size_t n, unsigned char out[3])
{
    if (n < 4)
        return 0;
    size_t stop;
    size_t got = st_b64_decode(p, 4, 0, out, &stop);
    if (stop == 4)
        return 3;
    if (stop == 3 && p[3] == '=')
        return (int)got;                    /* 2 */
    if (stop == 2 && p[2] == '=' && p[3] == '=')
        return (int)got;                    /* 1 */
    return 0;
}
