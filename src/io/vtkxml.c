/*
 * vtkxml.c - pre-flight check of VTK XML ImageData / UnstructuredGrid
 * documents (see vtkxml.h for the contract).
 *
 * The VTK XML format (VTK's "VTK File Formats" document, and the readers
 * in IO/XMLParser/vtkXMLDataParser.cxx):
 *
 *   <VTKFile type=T version=V byte_order=B header_type=H compressor=C>
 *     <T ...> ... <DataArray type= Name= NumberOfComponents= format= ...>
 *     <AppendedData encoding="raw|base64">  _PAYLOAD  </AppendedData>
 *   </VTKFile>
 *
 * Binary array data (inline base64, or appended at `offset` bytes/chars
 * after the `_`) start with a header of H words (UInt32 or UInt64, in
 * byte order B). Without a compressor: one word, the byte count, then the
 * bytes. With one: nblocks, block size, size of the last block (0: full),
 * then nblocks compressed sizes, then the compressed blocks. In base64
 * the uncompressed header and data are one base64 stream; a compressed
 * header is a stream of its own, the blocks another after it.
 *
 * VTK stops its XML parse at the first "<AppendedData" in the file and
 * looks for the raw payload after the first '>' that follows. Nothing
 * after the payload is parsed, by VTK or here.
 *
 * VTK sizes each array by the count it declares (a field array's
 * NumberOfTuples, the piece's points or cells) before reading it, and an
 * UnstructuredGrid's connectivity by the last of its offsets: a value in
 * the data. So every array's declared values must fit in the bytes its
 * data decode to, and the last offset, when it can be read without
 * decompressing (ascii, or binary without a compressor), must fit in the
 * connectivity. (With a compressor that value stays unchecked: VTK then
 * allocates what it says, which fails as std::bad_alloc, ST_ENOMEM, or
 * reserves untouched pages, before it finds the connectivity too short.)
 *
 * Nothing is allocated from a size in the file: the appended arrays and
 * the pieces are remembered in lists that grow with the elements actually
 * present.
 *
 * The XML lexer is this file's, not expat's (the parser VTK itself uses):
 * measured for issue 39 (bench/vtkxml_expat.c), expat alone over what VTK
 * parses costs as much as this whole check or more, and an expat-based
 * check would still make every check of structure, sizes and data here.
 * Instructions (callgrind), this check : expat's XML_Parse alone, on the
 * armadillo's files: soupmesh's .vtu (raw appended) 129k : 264k, soupdist's
 * .vti (zlib, raw appended) 233k : 230k, the .vti raw uncompressed 101k :
 * 254k, the .vtu ascii 3.26M : 6.70M, the .vti inline base64 (9.4 MB)
 * 201M : 198M, base64 zlib 19.1M : 19.4M; the .vti ascii (34 MB), best of
 * 9: 97 ms : 545 ms. Of the 36 fuzz findings under tests/data/fuzz/vt*,
 * expat refuses 2 (the other 34 are well-formed XML with bad sizes or
 * structure); it accepts all 54 good files there and in tests/data/vtk.
 */
#include "vtkxml.h"
#include "../base/fpenv.h"
#include "../base/bytes.h"

#include "souptet/mem.h"

#include <limits.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* Limits of what the check understands; VTK's writers stay far below. */
#define MAX_DEPTH 16     /* VTKFile > T > Piece > PointData > DataArray > .. */
#define MAX_ATTRS 256    /* attributes on one element (ComponentName0..) */
#define NAME_SHOWN 64    /* characters of an array name shown in messages */

typedef struct span {
    const unsigned char *p;
    size_t n;
} span;

typedef struct attr {
    span name, value;
} attr;

typedef enum kind {
    K_VTKFILE, K_DATASET, K_FIELDDATA, K_PIECE, K_POINTDATA, K_CELLDATA,
    K_POINTS, K_CELLS, K_ARRAY, K_INFOKEY, K_VALUE, K_APPENDED
} kind;

typedef enum format { F_ASCII, F_BINARY, F_APPENDED } format;

/* One Array/DataArray element. */
typedef struct array {
    long long line;
    const char *elem;   /* "Array" or "DataArray" */
    span name;
    int is_string;
    size_t tsize;       /* bytes per value */
    format fmt;
    size_t offset;      /* appended: into the payload */
    size_t values;      /* values the element declares (lower bound) */
    int has_text;       /* inline: text seen */
    span text;          /* inline: its text, trimmed */
    int role;           /* ROLE_*: a Cells array VTK sizes another by */
    size_t piece;       /* ROLE_*: index into ctx.cells */
    int int_kind;       /* 0 float/string, 1 signed, 2 unsigned integer */
    size_t strings;     /* String: the strings VTK allocates */
} array;

enum { ROLE_NONE, ROLE_CONN, ROLE_OFFSETS };

/* VTK allocates a piece's connectivity by the last of its offsets, a
 * value in the data: that value (when it can be read without
 * decompressing) is checked against what the connectivity's data hold. */
typedef struct cells_rec {
    int have_cap, have_last;
    uint64_t cap;       /* values the connectivity's data can hold */
    uint64_t last;      /* the last offset */
    array offsets;      /* for the message */
} cells_rec;

typedef struct open_elem {
    kind k;
    long long line;
    const char *tag;
    array arr;          /* K_ARRAY only */
} open_elem;

/* Where the base64 stream through a position ends (see reader_left). */
typedef struct b64_memo {
    const unsigned char *from, *end, *stop;   /* end: the final quad */
    int m;                                    /* bytes of the final quad */
} b64_memo;

typedef struct ctx {
    const unsigned char *d;
    size_t size;
    const char *name;
    const char *want;
    size_t max_bytes;
    st_error *err;
    /* line numbers, counted forward from the last position asked for */
    size_t line_pos;
    long long line_no;
    /* VTKFile */
    int big_endian;
    size_t ws;          /* header word size: 4 or 8 */
    int compressed;
    const char *compressor;   /* its name, when compressed */
    st_vtkxml_inflate_fn inflate;
    void *inflate_user;
    /* the dataset */
    int is_image;
    int have_dataset;
    long long whole[6];
    size_t npoints, ncells;   /* of the current Piece */
    /* appended arrays, checked once the payload is found */
    array *app;
    size_t napp, capp;
    size_t payload;           /* offset of the byte after '_' */
    int have_payload;
    int b64_payload;
    b64_memo memo[4];
    /* names of the arrays in the open FieldData, PointData, ... */
    struct named {
        span name;
        long long line;
        const char *elem;
    } *names;
    size_t nnames, cnames;
    /* UnstructuredGrid pieces */
    cells_rec *cells;
    size_t ncells_rec, ccells_rec;
    /* the open elements */
    open_elem stack[MAX_DEPTH];
    int depth;
} ctx;

/* ---- small helpers ----------------------------------------------------- */

static long long line_at(ctx *c, size_t pos)
{
    if (pos < c->line_pos) {
        c->line_pos = 0;
        c->line_no = 1;
    }
    if (pos > c->size)
        pos = c->size;
    const unsigned char *p = c->d + c->line_pos, *e = c->d + pos;
    while (p < e) {
        const unsigned char *nl = memchr(p, '\n', (size_t)(e - p));
        if (!nl)
            break;
        c->line_no++;
        p = nl + 1;
    }
    c->line_pos = pos;
    return c->line_no;
}

static int is_space(unsigned char ch)
{
    return ch == ' ' || ch == '\t' || ch == '\n' || ch == '\r';
}

static int is_name_start(unsigned char ch)
{
    return (ch >= 'A' && ch <= 'Z') || (ch >= 'a' && ch <= 'z') ||
           ch == '_' || ch == ':';
}

static int is_name_char(unsigned char ch)
{
    return is_name_start(ch) || (ch >= '0' && ch <= '9') || ch == '.' ||
           ch == '-';
}

static int span_is(span s, const char *lit)
{
    size_t n = strlen(lit);
    return s.n == n && memcmp(s.p, lit, n) == 0;
}

static span trim(span s)
{
    while (s.n && is_space(s.p[0])) {
        s.p++;
        s.n--;
    }
    while (s.n && is_space(s.p[s.n - 1]))
        s.n--;
    return s;
}

static const span *find_attr(const attr *a, int na, const char *n)
{
    for (int i = 0; i < na; i++)
        if (span_is(a[i].name, n))
            return &a[i].value;
    return NULL;
}

/* An integer, optional sign and blanks around it, in [lo, hi]. */
static int parse_ll(span s, long long lo, long long hi, long long *out)
{
    s = trim(s);
    size_t i = 0;
    int neg = 0;
    if (i < s.n && (s.p[i] == '+' || s.p[i] == '-'))
        neg = s.p[i++] == '-';
    if (i == s.n)
        return -1;
    unsigned long long v = 0;
    for (; i < s.n; i++) {
        if (s.p[i] < '0' || s.p[i] > '9')
            return -1;
        if (v > (ULLONG_MAX - 9) / 10)
            return -1;
        v = v * 10 + (unsigned)(s.p[i] - '0');
    }
    if (!neg && v > (unsigned long long)LLONG_MAX)
        return -1;
    if (neg && v > (unsigned long long)LLONG_MAX + 1)
        return -1;
    long long x = neg ? (v == (unsigned long long)LLONG_MAX + 1
                             ? LLONG_MIN
                             : -(long long)v)
                      : (long long)v;
    if (x < lo || x > hi)
        return -1;
    *out = x;
    return 0;
}

/* Exactly n blank-separated integers in [lo, hi]. */
static int parse_lls(span s, int n, long long lo, long long hi,
                     long long *out)
{
    size_t i = 0;
    for (int k = 0; k < n; k++) {
        while (i < s.n && is_space(s.p[i]))
            i++;
        size_t j = i;
        while (j < s.n && !is_space(s.p[j]))
            j++;
        if (j == i)
            return -1;
        span t = {s.p + i, j - i};
        if (parse_ll(t, lo, hi, &out[k]))
            return -1;
        i = j;
    }
    while (i < s.n && is_space(s.p[i]))
        i++;
    return i == s.n ? 0 : -1;
}

/* The array's name for messages: NAME_SHOWN characters at most, quotes
 * and control bytes left out (the message is one line). */
static const char *shown_name(const array *a, char *buf, size_t n)
{
    size_t k = 0;
    if (!a->name.p)
        return "(unnamed)";
    buf[k++] = '"';
    for (size_t i = 0; i < a->name.n && k + 5 < n && i < NAME_SHOWN; i++) {
        unsigned char ch = a->name.p[i];
        buf[k++] = (ch < 0x20 || ch == '"') ? '?' : (char)ch;
    }
    if (a->name.n > NAME_SHOWN && k + 4 < n) {
        buf[k++] = '.';
        buf[k++] = '.';
        buf[k++] = '.';
    }
    buf[k++] = '"';
    buf[k] = 0;
    return buf;
}

/* ---- XML lexing -------------------------------------------------------- */

/* A character XML 1.0 allows in text (bytes >= 0x80 are UTF-8, passed). */
static int bad_char(unsigned char ch)
{
    return ch < 0x20 && ch != '\t' && ch != '\n' && ch != '\r';
}

/* Length of a predefined entity or character reference at p, 0 if none. */
static size_t entity_len(const unsigned char *p, size_t n)
{
    static const char *const names[] = {"&amp;", "&lt;", "&gt;", "&quot;",
                                        "&apos;"};
    for (size_t i = 0; i < sizeof names / sizeof names[0]; i++) {
        size_t l = strlen(names[i]);
        if (n >= l && memcmp(p, names[i], l) == 0)
            return l;
    }
    if (n >= 4 && p[1] == '#') {
        size_t i = 2;
        int hex = p[2] == 'x';
        if (hex)
            i++;
        size_t start = i;
        while (i < n && i < start + 8 &&
               ((p[i] >= '0' && p[i] <= '9') ||
                (hex && ((p[i] >= 'a' && p[i] <= 'f') ||
                         (p[i] >= 'A' && p[i] <= 'F')))))
            i++;
        if (i > start && i < n && p[i] == ';')
            return i + 1;
    }
    return 0;
}

/* Text or an attribute value: no control bytes, '&' only in references;
 * in attribute values no '<' (XML). Returns the offset of the bad byte or
 * (size_t)-1. */
static size_t check_chars(span s, int in_attr, const char **why)
{
    for (size_t i = 0; i < s.n; i++) {
        unsigned char ch = s.p[i];
        if (bad_char(ch)) {
            *why = ch ? "control character" : "NUL byte";
            return i;
        }
        if (ch == '&') {
            size_t l = entity_len(s.p + i, s.n - i);
            if (!l) {
                *why = "'&' that is not a predefined entity reference";
                return i;
            }
            i += l - 1;
        } else if (in_attr && ch == '<') {
            *why = "'<' in an attribute value";
            return i;
        }
    }
    return (size_t)-1;
}

#ifdef __GNUC__
#define ST_PRINTF(a, b) __attribute__((format(printf, a, b)))
#else
#define ST_PRINTF(a, b)
#endif

/* An input error at byte pos. */
static st_status fail(ctx *c, size_t pos, const char *fmt, ...)
    ST_PRINTF(3, 4);
static st_status fail(ctx *c, size_t pos, const char *fmt, ...)
{
    char m[400];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(m, sizeof m, fmt, ap);
    va_end(ap);
    return st_error_set(c->err, ST_EINPUT, c->name, line_at(c, pos), "%s", m);
}

/* An error about array a: "DataArray "sdf": what", at its line. */
static st_status fail_arr(ctx *c, st_status s, const array *a,
                          const char *fmt, ...) ST_PRINTF(4, 5);
static st_status fail_arr(ctx *c, st_status s, const array *a,
                          const char *fmt, ...)
{
    char m[400], nb[NAME_SHOWN + 8];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(m, sizeof m, fmt, ap);
    va_end(ap);
    return st_error_set(c->err, s, c->name, a->line, "%s %s: %s", a->elem,
                        shown_name(a, nb, sizeof nb), m);
}

/* ---- block headers ----------------------------------------------------- */

/* Sequential reader over an array's data: raw bytes, or one base64
 * stream (which ends at its padding or at the first non-base64 char). */
typedef struct reader {
    const unsigned char *p;
    size_t n, i;        /* i: bytes (raw) or chars (base64) consumed */
    int b64, ended;
    unsigned char q[3];
    int qn, qi;         /* bytes in q, next to hand out */
} reader;

static void reader_init(reader *r, const unsigned char *p, size_t n, int b64)
{
    memset(r, 0, sizeof *r);
    r->p = p;
    r->n = n;
    r->b64 = b64;
}

static size_t reader_read(reader *r, unsigned char *out, size_t k)
{
    if (!r->b64) {
        size_t m = r->n - r->i < k ? r->n - r->i : k;
        memcpy(out, r->p + r->i, m);
        r->i += m;
        return m;
    }
    size_t got = 0;
    while (got < k) {
        if (r->qi == r->qn) {
            if (r->ended)
                break;
            int m = st_b64_quad(r->p + r->i, r->n - r->i, r->q);
            if (m == 0) {
                r->ended = 1;
                break;
            }
            r->i += 4;
            r->qn = m;
            r->qi = 0;
            if (m < 3)
                r->ended = 1;
        }
        out[got++] = r->q[r->qi++];
    }
    return got;
}

/* Bytes left in the reader's stream; for base64, up to where the stream
 * ends. Appended arrays share one payload, and an array whose bytes fill
 * whole quads has no padding: its stream runs on into the next array's.
 * Walking to the end for every array would make many small arrays
 * quadratic, so the last walk on each quad alignment is remembered
 * (appended arrays are checked in offset order). */
static size_t reader_left(b64_memo memo[4], const reader *r)
{
    if (!r->b64)
        return r->n - r->i;
    size_t left = (size_t)(r->qn - r->qi);
    if (r->ended)
        return left;
    const unsigned char *p = r->p + r->i, *stop = r->p + r->n;
    b64_memo *mm = &memo[(uintptr_t)p & 3];
    if (!(mm->stop == stop && mm->from <= p && p <= mm->end)) {
        unsigned char q[3];
        const unsigned char *e = p;
        int m;
        while (stop - e >= 4 && st_b64_table[e[0]] && st_b64_table[e[1]] &&
               st_b64_table[e[2]] && st_b64_table[e[3]])
            e += 4;
        m = st_b64_quad(e, (size_t)(stop - e), q);   /* 0, 1 or 2 */
        *mm = (b64_memo){p, e, stop, m};
    }
    return left + (size_t)(mm->end - p) / 4 * 3 + (size_t)mm->m;
}

/* One header word; 0 when the data end first. */
static int read_word(ctx *c, reader *r, uint64_t *w)
{
    unsigned char b[8];
    if (reader_read(r, b, c->ws) != c->ws)
        return 0;
    uint64_t v = 0;
    for (size_t i = 0; i < c->ws; i++)
        v |= (uint64_t)b[c->big_endian ? c->ws - 1 - i : i] << (8 * i);
    *w = v;
    return 1;
}

/* An integer value of a's type from its bytes in the file's order. */
static int value_of(ctx *c, const array *a, const unsigned char *b,
                    uint64_t *v)
{
    uint64_t x = 0;
    for (size_t i = 0; i < a->tsize; i++)
        x |= (uint64_t)b[c->big_endian ? a->tsize - 1 - i : i] << (8 * i);
    if (a->int_kind == 1 && a->tsize < 8 &&
        (x >> (8 * a->tsize - 1)) & 1)
        return 0;   /* negative: VTK refuses such offsets itself */
    if (a->int_kind == 1 && a->tsize == 8 && (x >> 63))
        return 0;
    *v = x;
    return a->int_kind != 0;
}

/* Record what a Cells array's data say (see cells_rec). */
static void note_cells(ctx *c, const array *a, uint64_t cap, int have_last,
                       uint64_t last)
{
    if (a->role == ROLE_NONE || a->piece >= c->ncells_rec)
        return;
    cells_rec *r = &c->cells[a->piece];
    if (a->role == ROLE_CONN) {
        r->have_cap = 1;
        r->cap = cap;
    } else {
        r->have_last = have_last;
        r->last = last;
        r->offsets = *a;
    }
}

/* ---- strings ----------------------------------------------------------- */

/* VTK 9.1 reads a String array's data whole and stores one string per
 * NUL (and one for an unterminated tail) into the array it sized by the
 * declared count, without a bound: a string too many writes past its end
 * (fuzzing found it). So the strings in the data are counted. Compressed
 * string data are inflated for that, through the caller's decompressor,
 * and only this much of it: souptet's string arrays are metadata. */
#define MAX_STRING_BYTES ((size_t)16 << 20)

typedef struct strcount {
    size_t n;           /* terminated strings */
    int open;           /* bytes after the last NUL */
} strcount;

static void count_nuls(strcount *sc, const unsigned char *p, size_t n)
{
    const unsigned char *e = p + n;
    while (p < e) {
        const unsigned char *z = memchr(p, 0, (size_t)(e - p));
        if (!z) {
            sc->open = 1;
            return;
        }
        sc->n++;
        sc->open = 0;
        p = z + 1;
    }
}

static size_t strings_in(const strcount *sc)
{
    return sc->n + (sc->open ? 1 : 0);
}

static st_status too_many_strings(ctx *c, const array *a, size_t n)
{
    return fail_arr(c, ST_EINPUT, a,
                    "its data hold %zu strings, more than the %zu it "
                    "declares",
                    n, a->strings);
}

/* The strings of an uncompressed block: `bytes` of them at r. */
static st_status count_plain(ctx *c, const array *a, reader *r,
                             uint64_t bytes)
{
    strcount sc = {0, 0};
    if (!r->b64) {
        count_nuls(&sc, r->p + r->i, (size_t)bytes);
    } else {
        unsigned char buf[4096];
        while (bytes > 0) {
            size_t k = bytes < sizeof buf ? (size_t)bytes : sizeof buf;
            size_t got = reader_read(r, buf, k);
            count_nuls(&sc, buf, got);
            if (got < k)
                break;
            bytes -= k;
        }
    }
    return strings_in(&sc) > a->strings
               ? too_many_strings(c, a, strings_in(&sc))
               : ST_OK;
}

/* The strings of compressed blocks: the sizes are read by hr (past the
 * first three header words), the blocks by dr. */
static st_status count_compressed(ctx *c, const array *a, reader *hr,
                                  reader *dr, uint64_t nb, uint64_t bs,
                                  uint64_t last, uint64_t decoded)
{
    if (decoded == 0)
        return ST_OK;
    if (!c->inflate)
        return fail_arr(c, ST_EINPUT, a,
                        "compressed String data cannot be checked here");
    if (decoded > MAX_STRING_BYTES)
        return fail_arr(c, ST_ELIMIT, a,
                        "String data of %llu bytes, more than the %zu this "
                        "reader checks",
                        (unsigned long long)decoded, MAX_STRING_BYTES);
    strcount sc = {0, 0};
    st_status s = ST_OK;
    for (uint64_t b = 0; b < nb && s == ST_OK; b++) {
        uint64_t cs;
        if (!read_word(c, hr, &cs))
            return fail_arr(c, ST_EINTERNAL, a, "block sizes vanished");
        const size_t us = (size_t)(b + 1 < nb || last == 0 ? bs : last);
        /* both sizes are bounded: cs by the bytes present, us by
         * MAX_STRING_BYTES (us <= decoded) */
        unsigned char *in = malloc(cs ? (size_t)cs : 1);
        unsigned char *out = malloc(us ? us : 1);
        if (!in || !out)
            s = st_error_set(c->err, ST_ENOMEM, c->name, a->line,
                             "out of memory");
        else if (reader_read(dr, in, (size_t)cs) != cs)
            s = fail_arr(c, ST_EINPUT, a, "block %llu is cut short",
                         (unsigned long long)b);
        else {
            size_t got = c->inflate(c->inflate_user, c->compressor, in,
                                    (size_t)cs, out, us);
            if (got != us)
                s = fail_arr(c, ST_EINPUT, a,
                             "block %llu does not inflate to its %zu bytes",
                             (unsigned long long)b, us);
            else
                count_nuls(&sc, out, got);
        }
        free(in);
        free(out);
    }
    if (s == ST_OK && strings_in(&sc) > a->strings)
        s = too_many_strings(c, a, strings_in(&sc));
    return s;
}

/* The block header and sizes of one array's binary data at p[0..n);
 * where is "inline" or "appended", for messages. */
static st_status check_blocks(ctx *c, const array *a, const unsigned char *p,
                              size_t n, int b64, const char *where)
{
    reader r, hr;
    reader_init(&r, p, n, b64);
    uint64_t decoded, nb = 0, bs = 0, last = 0;
    if (!c->compressed) {
        if (!read_word(c, &r, &decoded))
            return fail_arr(c, ST_EINPUT, a,
                            "%s block header is cut short (%zu bytes "
                            "needed, %zu there)",
                            where, c->ws, reader_left(c->memo, &r));
        size_t left = reader_left(c->memo, &r);
        if (decoded > left)
            return fail_arr(c, ST_EINPUT, a,
                            "%s block claims %llu bytes but %zu remain",
                            where, (unsigned long long)decoded, left);
        if (a->role == ROLE_OFFSETS && a->values > 0 &&
            (uint64_t)a->values * a->tsize <= decoded) {
            /* the last offset VTK reads: value values-1 */
            size_t skip = (a->values - 1) * a->tsize;
            unsigned char b[64];
            if (!r.b64) {   /* raw: jump; inside the data (checked above) */
                r.i += skip;
                skip = 0;
            }
            while (skip > 0) {
                size_t k = skip < sizeof b ? skip : sizeof b;
                reader_read(&r, b, k);
                skip -= k;
            }
            uint64_t v = 0;
            int known = reader_read(&r, b, a->tsize) == a->tsize &&
                        value_of(c, a, b, &v);
            note_cells(c, a, 0, known, v);
        }
    } else {
        if (!read_word(c, &r, &nb) || !read_word(c, &r, &bs) ||
            !read_word(c, &r, &last))
            return fail_arr(c, ST_EINPUT, a,
                            "%s compression header is cut short (%zu "
                            "bytes needed)",
                            where, 3 * c->ws);
        /* The block sizes must lie inside the data: bound nb by what is
         * there before anything is multiplied by it. */
        size_t left = reader_left(c->memo, &r);
        if (nb > left / c->ws)
            return fail_arr(c, ST_EINPUT, a,
                            "%s compression header claims %llu blocks, "
                            "more than the %zu bytes that remain can list",
                            where, (unsigned long long)nb, left);
        hr = r;   /* at the block sizes: count_compressed reads them again */
        uint64_t sum = 0;
        for (uint64_t b = 0; b < nb; b++) {
            uint64_t cs;
            if (!read_word(c, &r, &cs))
                return fail_arr(c, ST_EINPUT, a,
                                "%s compression header is cut short (%llu "
                                "of %llu block sizes)",
                                where, (unsigned long long)b,
                                (unsigned long long)nb);
            sum = cs > UINT64_MAX - sum ? UINT64_MAX : sum + cs;
        }
        if (b64) {
            /* The blocks are a base64 stream of their own after the
             * header's (VTK ends one and starts the other). */
            size_t hchars = r.i;
            reader_init(&r, p + hchars, n - hchars, 1);
        }
        left = reader_left(c->memo, &r);
        if (sum > left)
            return fail_arr(c, ST_EINPUT, a,
                            "%s compressed blocks claim %llu bytes but %zu "
                            "remain",
                            where, (unsigned long long)sum, left);
        if (nb == 0) {
            /* VTK computes 0 * size - size + last: refuse a last block. */
            if (last != 0)
                return fail_arr(c, ST_EINPUT, a,
                                "%s compression header has no blocks but a "
                                "last block of %llu bytes",
                                where, (unsigned long long)last);
            decoded = 0;
        } else {
            /* VTK divides by the block size, and a last block larger than
             * the others would overrun its buffer. */
            if (bs == 0 || last > bs)
                return fail_arr(c, ST_EINPUT, a,
                                "%s compression header has block size %llu "
                                "and last block size %llu",
                                where, (unsigned long long)bs,
                                (unsigned long long)last);
            uint64_t full = nb - 1, tail = last ? last : bs;
            if (full > UINT64_MAX / bs || full * bs > UINT64_MAX - tail)
                return fail_arr(c, ST_EINPUT, a,
                                "%s compression header claims %llu blocks "
                                "of %llu bytes, more than any memory",
                                where, (unsigned long long)nb,
                                (unsigned long long)bs);
            decoded = full * bs + tail;
        }
    }
    if (decoded > SIZE_MAX || (c->max_bytes && decoded > c->max_bytes))
        return fail_arr(c, ST_ELIMIT, a,
                        "decodes to %llu bytes, more than the memory limit "
                        "allows (raise --max-memory)",
                        (unsigned long long)decoded);
    size_t need;
    if (st_size_mul(&need, a->values, a->tsize) != 0 || need > decoded)
        return fail_arr(c, ST_EINPUT, a,
                        "declares %zu values of %zu bytes but its data "
                        "decode to %llu bytes",
                        a->values, a->tsize, (unsigned long long)decoded);
    if (a->role == ROLE_CONN)
        note_cells(c, a, decoded / a->tsize, 0, 0);
    if (a->is_string)
        return c->compressed
                   ? count_compressed(c, a, &hr, &r, nb, bs, last, decoded)
                   : count_plain(c, a, &r, decoded);
    return ST_OK;
}

/* The data of an inline array, at its end tag. */
static st_status check_inline(ctx *c, const array *a)
{
    span t = a->has_text && a->text.p ? a->text : (span){c->d, 0};
    if (a->fmt == F_ASCII) {
        /* Every value takes a character and a blank after it but the
         * last, so n characters hold (n + 1) / 2 values at most. VTK sizes
         * the array by the declared count: bound it by the text. */
        if (a->values > 0 && t.n == 0)
            return fail_arr(c, ST_EINPUT, a,
                            "ascii array has no text for its %zu values",
                            a->values);
        if (a->values > (t.n + 1) / 2)
            return fail_arr(c, ST_EINPUT, a,
                            "declares %zu values but its text has only %zu "
                            "characters",
                            a->values, t.n);
        size_t need;
        if (st_size_mul(&need, a->values, a->tsize) != 0 ||
            (c->max_bytes && need > c->max_bytes))
            return fail_arr(c, ST_ELIMIT, a,
                            "%zu values are more than the memory limit "
                            "allows (raise --max-memory)",
                            a->values);
        if (a->role == ROLE_CONN)
            note_cells(c, a, (t.n + 1) / 2, 0, 0);
        if (a->is_string) {
            /* one number per character, a 0 ending each string */
            strcount sc = {0, 0};
            for (size_t i = 0; i < t.n;) {
                while (i < t.n && is_space(t.p[i]))
                    i++;
                size_t start = i;
                while (i < t.n && !is_space(t.p[i]))
                    i++;
                if (i == start)
                    break;
                long long v;
                span tok = {t.p + start, i - start};
                if (parse_ll(tok, LLONG_MIN, LLONG_MAX, &v) == 0 && v == 0) {
                    sc.n++;
                    sc.open = 0;
                } else
                    sc.open = 1;
            }
            if (strings_in(&sc) > a->strings)
                return too_many_strings(c, a, strings_in(&sc));
        }
        if (a->role == ROLE_OFFSETS && a->values > 0) {
            /* the token VTK reads last: number values-1 */
            size_t i = 0, k = 0, start = 0, end = 0;
            while (i < t.n && k < a->values) {
                while (i < t.n && is_space(t.p[i]))
                    i++;
                start = i;
                while (i < t.n && !is_space(t.p[i]))
                    i++;
                end = i;
                k++;
            }
            long long v;
            span tok = {t.p + start, end - start};
            int known = k == a->values && a->int_kind != 0 &&
                        parse_ll(tok, 0, LLONG_MAX, &v) == 0;
            note_cells(c, a, 0, known, known ? (uint64_t)v : 0);
        }
        return ST_OK;
    }
    for (size_t i = 0; i < t.n; i++)
        if (t.p[i] != '=' && st_b64_value(t.p[i], 0) < 0)
            return fail_arr(c, ST_EINPUT, a,
                            "binary data has a byte that is not base64 "
                            "(code %u) at character %zu",
                            (unsigned)t.p[i], i);
    return check_blocks(c, a, t.p, t.n, 1, "inline");
}

static st_status check_appended(ctx *c, const array *a)
{
    const size_t len = c->size - c->payload;
    if (a->offset > len)
        return fail_arr(c, ST_EINPUT, a,
                        "offset %zu lies beyond the %zu bytes of appended "
                        "data",
                        a->offset, len);
    return check_blocks(c, a, c->d + c->payload + a->offset, len - a->offset,
                        c->b64_payload, "appended");
}

/* ---- elements ---------------------------------------------------------- */

static const struct {
    const char *name;
    size_t size;
} k_types[] = {
    {"Int8", 1},    {"UInt8", 1},   {"Int16", 2},   {"UInt16", 2},
    {"Int32", 4},   {"UInt32", 4},  {"Int64", 8},   {"UInt64", 8},
    {"Float32", 4}, {"Float64", 8}, {"String", 1},
};

static const char *const k_compressors[] = {
    "vtkZLibDataCompressor", "vtkLZ4DataCompressor", "vtkLZMADataCompressor"};

static st_status open_vtkfile(ctx *c, size_t pos, const attr *a, int na)
{
    static const char *const known[] = {"type", "version", "byte_order",
                                        "header_type", "compressor"};
    for (int i = 0; i < na; i++) {
        int ok = 0;
        for (size_t k = 0; k < sizeof known / sizeof known[0]; k++)
            ok |= span_is(a[i].name, known[k]);
        if (!ok) {
            char n[NAME_SHOWN + 1];
            size_t l = a[i].name.n < NAME_SHOWN ? a[i].name.n : NAME_SHOWN;
            memcpy(n, a[i].name.p, l);
            n[l] = 0;
            return fail(c, pos, "VTKFile: unknown attribute '%s'", n);
        }
    }
    const span *t = find_attr(a, na, "type");
    if (!t)
        return fail(c, pos, "VTKFile: no type attribute");
    if (!span_is(*t, c->want))
        return fail(c, pos, "VTKFile type is not %s%s", c->want,
                    span_is(*t, "ImageData") || span_is(*t, "UnstructuredGrid")
                        ? " (wrong kind of VTK file for this input)"
                        : "");
    const span *v = find_attr(a, na, "version");
    {
        int ok = v != NULL && v->n > 0;
        size_t dots = 0, digits = 0;
        for (size_t i = 0; ok && i < v->n; i++) {
            if (v->p[i] == '.')
                dots++;
            else if (v->p[i] >= '0' && v->p[i] <= '9')
                digits++;
            else
                ok = 0;
        }
        if (!ok || dots != 1 || digits < 2 || v->p[0] == '.' ||
            v->p[v->n - 1] == '.')
            return fail(c, pos,
                        "VTKFile: %s version attribute (want MAJOR.MINOR)",
                        v ? "bad" : "no");
    }
    const span *bo = find_attr(a, na, "byte_order");
    if (bo && !span_is(*bo, "LittleEndian") && !span_is(*bo, "BigEndian"))
        return fail(c, pos,
                    "VTKFile: byte_order is neither LittleEndian nor "
                    "BigEndian");
    c->big_endian = bo && span_is(*bo, "BigEndian");
    const span *ht = find_attr(a, na, "header_type");
    if (ht && !span_is(*ht, "UInt32") && !span_is(*ht, "UInt64"))
        return fail(c, pos,
                    "VTKFile: header_type is neither UInt32 nor UInt64");
    c->ws = ht && span_is(*ht, "UInt64") ? 8 : 4;
    const span *cp = find_attr(a, na, "compressor");
    if (cp) {
        int ok = 0;
        for (size_t k = 0; k < sizeof k_compressors / sizeof *k_compressors;
             k++)
            ok |= span_is(*cp, k_compressors[k]);
        if (!ok)
            return fail(c, pos,
                        "VTKFile: unknown compressor (want "
                        "vtkZLibDataCompressor, vtkLZ4DataCompressor or "
                        "vtkLZMADataCompressor)");
        c->compressed = 1;
        for (size_t k = 0; k < sizeof k_compressors / sizeof *k_compressors;
             k++)
            if (span_is(*cp, k_compressors[k]))
                c->compressor = k_compressors[k];
    }
    return ST_OK;
}

static st_status open_piece(ctx *c, size_t pos, const attr *a, int na)
{
    if (c->is_image) {
        const span *e = find_attr(a, na, "Extent");
        long long x[6];
        if (!e || parse_lls(*e, 6, INT_MIN, INT_MAX, x))
            return fail(c, pos, "Piece: %s Extent attribute (want six "
                        "integers)",
                        e ? "bad" : "no");
        size_t np = 1, nc = 1;
        for (int k = 0; k < 3; k++) {
            if (x[2 * k] > x[2 * k + 1])
                return fail(c, pos, "Piece: Extent has lo > hi");
            if (x[2 * k] < c->whole[2 * k] ||
                x[2 * k + 1] > c->whole[2 * k + 1])
                return fail(c, pos,
                            "Piece: Extent lies outside the WholeExtent");
            long long d = x[2 * k + 1] - x[2 * k];
            if (st_size_mul(&np, np, (size_t)d + 1) != 0 ||
                st_size_mul(&nc, nc, d > 0 ? (size_t)d : 1) != 0)
                return st_error_set(c->err, ST_ELIMIT, c->name,
                                    line_at(c, pos),
                                    "Piece: Extent holds more points than "
                                    "fit in memory");
        }
        c->npoints = np;
        c->ncells = nc;
        return ST_OK;
    }
    const span *p = find_attr(a, na, "NumberOfPoints");
    const span *q = find_attr(a, na, "NumberOfCells");
    long long np, nc;
    if (!p || parse_ll(*p, 0, LLONG_MAX, &np))
        return fail(c, pos,
                    "Piece: %s NumberOfPoints attribute (want a "
                    "non-negative integer)",
                    p ? "bad" : "no");
    if (!q || parse_ll(*q, 0, LLONG_MAX, &nc))
        return fail(c, pos,
                    "Piece: %s NumberOfCells attribute (want a "
                    "non-negative integer)",
                    q ? "bad" : "no");
    if ((unsigned long long)np > SIZE_MAX || (unsigned long long)nc > SIZE_MAX)
        return st_error_set(c->err, ST_ELIMIT, c->name, line_at(c, pos),
                            "Piece: more points or cells than fit in "
                            "memory");
    c->npoints = (size_t)np;
    c->ncells = (size_t)nc;
    if (c->ncells_rec == c->ccells_rec) {
        size_t cap = c->ccells_rec ? 2 * c->ccells_rec : 4;
        cells_rec *r = st_realloc_array(c->cells, cap, sizeof *r);
        if (!r)
            return st_error_set(c->err, ST_ENOMEM, c->name, 0,
                                "out of memory");
        c->cells = r;
        c->ccells_rec = cap;
    }
    memset(&c->cells[c->ncells_rec++], 0, sizeof *c->cells);
    return ST_OK;
}

static st_status open_array(ctx *c, size_t pos, kind parent, const char *tag,
                            const attr *at, int na, array *a)
{
    memset(a, 0, sizeof *a);
    a->line = line_at(c, pos);
    a->elem = tag;
    const span *nm = find_attr(at, na, "Name");
    if (nm)
        a->name = *nm;
    if (!nm && parent != K_POINTS)
        return fail_arr(c, ST_EINPUT, a, "no Name attribute");
    const span *t = find_attr(at, na, "type");
    if (!t)
        return fail_arr(c, ST_EINPUT, a, "no type attribute");
    a->tsize = 0;
    for (size_t k = 0; k < sizeof k_types / sizeof k_types[0]; k++)
        if (span_is(*t, k_types[k].name)) {
            a->tsize = k_types[k].size;
            a->is_string = strcmp(k_types[k].name, "String") == 0;
            a->int_kind = k_types[k].name[0] == 'I'   ? 1
                          : k_types[k].name[0] == 'U' ? 2
                                                      : 0;
        }
    if (!a->tsize)
        return fail_arr(c, ST_EINPUT, a,
                        "type is not one of Int8..UInt64, Float32, "
                        "Float64, String");
    long long ncomp = 1, ntup = -1, off = 0;
    const span *s = find_attr(at, na, "NumberOfComponents");
    if (s && parse_ll(*s, 1, INT_MAX, &ncomp))
        return fail_arr(c, ST_EINPUT, a,
                        "NumberOfComponents is not a positive "
                        "integer");
    s = find_attr(at, na, "NumberOfTuples");
    if (s && parse_ll(*s, 0, LLONG_MAX, &ntup))
        return fail_arr(c, ST_EINPUT, a,
                        "NumberOfTuples is not a non-negative "
                        "integer");
    const span *f = find_attr(at, na, "format");
    if (!f)
        return fail_arr(c, ST_EINPUT, a,
                        "no format attribute");
    if (span_is(*f, "ascii"))
        a->fmt = F_ASCII;
    else if (span_is(*f, "binary"))
        a->fmt = F_BINARY;
    else if (span_is(*f, "appended"))
        a->fmt = F_APPENDED;
    else
        return fail_arr(c, ST_EINPUT, a,
                        "format is not ascii, binary or "
                        "appended");
    if (a->fmt == F_APPENDED) {
        s = find_attr(at, na, "offset");
        if (!s || parse_ll(*s, 0, LLONG_MAX, &off))
            return fail_arr(c, ST_EINPUT, a,
                            "appended array without a non-negative "
                            "integer offset");
        if ((unsigned long long)off > SIZE_MAX)
            off = LLONG_MAX;   /* beyond any payload: refused later */
        a->offset = (size_t)off;
    }
    /* The tuples VTK will size the array by. */
    size_t tuples = 0;
    switch (parent) {
    case K_FIELDDATA:
        tuples = ntup < 0 ? 0 : (size_t)ntup;
        if ((unsigned long long)ntup > SIZE_MAX)
            tuples = SIZE_MAX;
        break;
    case K_POINTDATA: tuples = c->npoints; break;
    case K_CELLDATA: tuples = c->ncells; break;
    case K_POINTS:
        if (ncomp != 3)
            return fail_arr(c, ST_EINPUT, a,
                            "points have %lld components, not 3", ncomp);
        tuples = c->npoints;
        break;
    case K_CELLS:
        /* offsets and types have one value per cell; connectivity's
         * length is the last offset (see cells_rec). */
        if (nm && (span_is(*nm, "offsets") || span_is(*nm, "types")))
            tuples = c->ncells;
        if (nm && (span_is(*nm, "offsets") || span_is(*nm, "connectivity")) &&
            c->ncells_rec > 0) {
            a->role = span_is(*nm, "offsets") ? ROLE_OFFSETS : ROLE_CONN;
            a->piece = c->ncells_rec - 1;
        }
        break;
    default: break;
    }
    if (a->is_string) {
        if (st_size_mul(&a->strings, tuples, (size_t)ncomp) != 0)
            a->strings = SIZE_MAX;
        ncomp = 1;   /* each string takes at least its terminator */
    }
    if (st_size_mul(&a->values, tuples, (size_t)ncomp) != 0 ||
        st_size_mul(&(size_t){0}, a->values, a->tsize) != 0)
        return fail_arr(c, ST_ELIMIT, a,
                        "%llu tuples of %llu components are more "
                        "than fit in memory",
                        (unsigned long long)tuples,
                        (unsigned long long)ncomp);
    return ST_OK;
}

/* Which children each element may have. */
static int child_kind(ctx *c, kind parent, span tag, kind *k)
{
    switch (parent) {
    case K_VTKFILE:
        if (span_is(tag, c->want)) {
            *k = K_DATASET;
            return 1;
        }
        if (span_is(tag, "AppendedData")) {
            *k = K_APPENDED;
            return 1;
        }
        return 0;
    case K_DATASET:
        if (span_is(tag, "FieldData"))
            *k = K_FIELDDATA;
        else if (span_is(tag, "Piece"))
            *k = K_PIECE;
        else
            return 0;
        return 1;
    case K_PIECE:
        if (span_is(tag, "PointData"))
            *k = K_POINTDATA;
        else if (span_is(tag, "CellData"))
            *k = K_CELLDATA;
        else if (!c->is_image && span_is(tag, "Points"))
            *k = K_POINTS;
        else if (!c->is_image && span_is(tag, "Cells"))
            *k = K_CELLS;
        else
            return 0;
        return 1;
    case K_FIELDDATA:
    case K_POINTDATA:
    case K_CELLDATA:
    case K_POINTS:
    case K_CELLS:
        if (span_is(tag, "DataArray") || span_is(tag, "Array")) {
            *k = K_ARRAY;
            return 1;
        }
        return 0;
    case K_ARRAY:
        if (span_is(tag, "InformationKey")) {
            *k = K_INFOKEY;
            return 1;
        }
        return 0;
    case K_INFOKEY:
        if (span_is(tag, "Value")) {
            *k = K_VALUE;
            return 1;
        }
        return 0;
    default: return 0;
    }
}

static st_status open_elem_check(ctx *c, size_t pos, span tag,
                                 const attr *a, int na, open_elem *e)
{
    char tn[NAME_SHOWN + 1];
    size_t l = tag.n < NAME_SHOWN ? tag.n : NAME_SHOWN;
    memcpy(tn, tag.p, l);
    tn[l] = 0;
    e->line = line_at(c, pos);
    if (c->depth == 0) {
        if (!span_is(tag, "VTKFile"))
            return fail(c, pos, "the root element is <%s>, not <VTKFile>",
                        tn);
        e->k = K_VTKFILE;
        e->tag = "VTKFile";
        return open_vtkfile(c, pos, a, na);
    }
    open_elem *parent = &c->stack[c->depth - 1];
    if (!child_kind(c, parent->k, tag, &e->k))
        return fail(c, pos, "unexpected element <%s> in <%s>", tn,
                    parent->tag);
    switch (e->k) {
    case K_DATASET:
        if (c->have_dataset)
            return fail(c, pos, "a second <%s> element", tn);
        c->have_dataset = 1;
        e->tag = c->want;
        if (c->is_image) {
            const span *w = find_attr(a, na, "WholeExtent");
            if (!w || parse_lls(*w, 6, INT_MIN, INT_MAX, c->whole))
                return fail(c, pos,
                            "ImageData: %s WholeExtent attribute (want six "
                            "integers)",
                            w ? "bad" : "no");
            for (int k = 0; k < 3; k++)
                if (c->whole[2 * k] > c->whole[2 * k + 1])
                    return fail(c, pos,
                                "ImageData: WholeExtent has lo > hi");
        }
        return ST_OK;
    case K_PIECE:
        e->tag = "Piece";
        return open_piece(c, pos, a, na);
    case K_ARRAY:
        e->tag = span_is(tag, "Array") ? "Array" : "DataArray";
        {
            st_status s = open_array(c, pos, parent->k, e->tag, a, na,
                                     &e->arr);
            if (s || !e->arr.name.p)
                return s;
        }
        if (c->nnames == c->cnames) {
            size_t cap = c->cnames ? 2 * c->cnames : 16;
            struct named *p = st_realloc_array(c->names, cap, sizeof *p);
            if (!p)
                return st_error_set(c->err, ST_ENOMEM, c->name, 0,
                                    "out of memory");
            c->names = p;
            c->cnames = cap;
        }
        c->names[c->nnames++] =
            (struct named){e->arr.name, e->arr.line, e->tag};
        return ST_OK;
    case K_APPENDED: {
        e->tag = "AppendedData";
        const span *enc = find_attr(a, na, "encoding");
        if (!enc || (!span_is(*enc, "raw") && !span_is(*enc, "base64")))
            return fail(c, pos,
                        "AppendedData: encoding is neither raw nor "
                        "base64");
        c->b64_payload = span_is(*enc, "base64");
        return ST_OK;
    }
    default:
        e->tag = e->k == K_FIELDDATA   ? "FieldData"
                 : e->k == K_POINTDATA ? "PointData"
                 : e->k == K_CELLDATA  ? "CellData"
                 : e->k == K_POINTS    ? "Points"
                 : e->k == K_CELLS     ? "Cells"
                 : e->k == K_INFOKEY   ? "InformationKey"
                                       : "Value";
        return ST_OK;
    }
}

static int by_name(const void *a, const void *b)
{
    const struct named *x = a, *y = b;
    size_t n = x->name.n < y->name.n ? x->name.n : y->name.n;
    int d = memcmp(x->name.p, y->name.p, n);
    if (d)
        return d;
    if (x->name.n != y->name.n)
        return x->name.n < y->name.n ? -1 : 1;
    return x->line < y->line ? -1 : x->line > y->line;
}

/* Two arrays of one name in one element: VTK 9.1 replaces the first by
 * the second in the data set and then reads into the one it dropped
 * (fuzzing found the crash). Checked when the element closes. */
static st_status check_names(ctx *c, const open_elem *e)
{
    st_status s = ST_OK;
    if (c->nnames > 1) {
        qsort(c->names, c->nnames, sizeof *c->names, by_name);
        for (size_t i = 1; i < c->nnames && !s; i++)
            if (c->names[i].name.n == c->names[i - 1].name.n &&
                memcmp(c->names[i].name.p, c->names[i - 1].name.p,
                       c->names[i].name.n) == 0) {
                array a;
                memset(&a, 0, sizeof a);
                a.elem = c->names[i].elem;
                a.name = c->names[i].name;
                a.line = c->names[i].line;
                char tag[32];
                snprintf(tag, sizeof tag, "%s", e->tag);
                s = fail_arr(c, ST_EINPUT, &a,
                             "a second array of this name in <%s>", tag);
            }
    }
    c->nnames = 0;
    return s;
}

static st_status close_elem(ctx *c, open_elem *e)
{
    if (e->k == K_FIELDDATA || e->k == K_POINTDATA || e->k == K_CELLDATA ||
        e->k == K_POINTS || e->k == K_CELLS)
        return check_names(c, e);
    if (e->k != K_ARRAY)
        return ST_OK;
    if (e->arr.fmt != F_APPENDED)
        return check_inline(c, &e->arr);
    if (c->napp == c->capp) {
        size_t cap = c->capp ? 2 * c->capp : 16;
        array *p = st_realloc_array(c->app, cap, sizeof *p);
        if (!p)
            return st_error_set(c->err, ST_ENOMEM, c->name, 0,
                                "out of memory");
        c->app = p;
        c->capp = cap;
    }
    c->app[c->napp++] = e->arr;
    return ST_OK;
}

/* ---- the parse --------------------------------------------------------- */

/* Parse the start tag at d[*pos] ('<' already seen at *pos). */
static st_status start_tag(ctx *c, size_t *pos, int *stop)
{
    const unsigned char *d = c->d;
    const size_t start = *pos;
    size_t i = start + 1;
    if (i >= c->size || !is_name_start(d[i]))
        return fail(c, start, "'<' that does not start a tag");
    span tag = {d + i, 0};
    while (i < c->size && is_name_char(d[i]))
        i++;
    tag.n = (size_t)(d + i - tag.p);
    attr at[MAX_ATTRS];
    int na = 0, empty = 0;
    for (;;) {
        size_t sp = i;
        while (i < c->size && is_space(d[i]))
            i++;
        if (i >= c->size)
            return fail(c, start, "the tag is not closed");
        if (d[i] == '>') {
            i++;
            break;
        }
        if (d[i] == '/') {
            if (i + 1 >= c->size || d[i + 1] != '>')
                return fail(c, i, "'/' inside a tag");
            i += 2;
            empty = 1;
            break;
        }
        if (i == sp || !is_name_start(d[i]))
            return fail(c, i, "bad attribute syntax in a tag");
        if (na == MAX_ATTRS)
            return fail(c, start, "more attributes than this reader "
                        "understands in one tag");
        attr *a = &at[na];
        a->name.p = d + i;
        while (i < c->size && is_name_char(d[i]))
            i++;
        a->name.n = (size_t)(d + i - a->name.p);
        while (i < c->size && is_space(d[i]))
            i++;
        if (i >= c->size || d[i] != '=')
            return fail(c, i, "attribute without '='");
        i++;
        while (i < c->size && is_space(d[i]))
            i++;
        if (i >= c->size || (d[i] != '"' && d[i] != '\''))
            return fail(c, i, "attribute value not in quotes");
        const unsigned char q = d[i++];
        const unsigned char *e = memchr(d + i, q, c->size - i);
        if (!e)
            return fail(c, i, "attribute value not closed");
        a->value.p = d + i;
        a->value.n = (size_t)(e - (d + i));
        const char *why;
        size_t bad = check_chars(a->value, 1, &why);
        if (bad != (size_t)-1)
            return fail(c, i + bad, "%s", why);
        for (int k = 0; k < na; k++)
            if (at[k].name.n == a->name.n &&
                memcmp(at[k].name.p, a->name.p, a->name.n) == 0)
                return fail(c, i, "an attribute appears twice in a tag");
        i = (size_t)(e - d) + 1;
        na++;
    }
    if (c->depth == MAX_DEPTH)
        return fail(c, start, "elements nested too deep");
    open_elem *e = &c->stack[c->depth];
    memset(e, 0, sizeof *e);
    st_status s = open_elem_check(c, start, tag, at, na, e);
    if (s)
        return s;
    /* VTK finds inline data, and the appended payload, after the first
     * '>' following the start of the tag: a '>' in an attribute value of
     * such an element would make it read the tag's rest as data. */
    if ((e->k == K_ARRAY && e->arr.fmt != F_APPENDED) || e->k == K_APPENDED) {
        const unsigned char *gt = memchr(d + start, '>', i - start);
        if (gt && gt != d + i - 1)
            return fail(c, (size_t)(gt - d),
                        "'>' in an attribute value of <%s> (VTK would take "
                        "it for the end of the tag)",
                        e->tag);
    }
    *pos = i;
    if (e->k == K_APPENDED) {
        /* VTK takes the payload from after the tag and any blanks, past
         * one '_' marker; the XML ends here for it and for us. */
        while (i < c->size && is_space(d[i]))
            i++;
        if (i >= c->size || d[i] != '_')
            return fail(c, i, "AppendedData: no '_' before the data");
        c->payload = i + 1;
        c->have_payload = 1;
        *stop = 1;
        return ST_OK;
    }
    c->depth++;
    if (empty) {
        c->depth--;
        return close_elem(c, e);
    }
    return ST_OK;
}

static st_status end_tag(ctx *c, size_t *pos)
{
    const unsigned char *d = c->d;
    const size_t start = *pos;
    size_t i = start + 2;
    span tag = {d + i, 0};
    while (i < c->size && is_name_char(d[i]))
        i++;
    tag.n = (size_t)(d + i - tag.p);
    while (i < c->size && is_space(d[i]))
        i++;
    if (i >= c->size || d[i] != '>')
        return fail(c, start, "bad end tag");
    if (c->depth == 0)
        return fail(c, start, "end tag without a start tag");
    open_elem *e = &c->stack[c->depth - 1];
    char tn[NAME_SHOWN + 1];
    size_t l = tag.n < NAME_SHOWN ? tag.n : NAME_SHOWN;
    memcpy(tn, tag.p, l);
    tn[l] = 0;
    int match = e->k == K_DATASET ? span_is(tag, c->want)
                                  : span_is(tag, e->tag);
    if (!match)
        return fail(c, start, "</%s> closes <%s>", tn, e->tag);
    *pos = i + 1;
    c->depth--;
    return close_elem(c, e);
}

static int by_offset(const void *a, const void *b)
{
    const array *x = a, *y = b;
    return x->offset < y->offset ? -1 : x->offset > y->offset;
}

static st_status parse(ctx *c)
{
    const unsigned char *d = c->d;
    size_t pos = 0;
    if (c->size >= 3 && d[0] == 0xEF && d[1] == 0xBB && d[2] == 0xBF)
        pos = 3;   /* UTF-8 byte order mark */
    if (c->size - pos >= 6 && memcmp(d + pos, "<?xml", 5) == 0 &&
        is_space(d[pos + 5])) {
        size_t i = pos + 5;
        while (i + 1 < c->size && !(d[i] == '?' && d[i + 1] == '>')) {
            if (d[i] == '<' || d[i] == '>' || bad_char(d[i]))
                return fail(c, i, "bad <?xml ?> declaration");
            i++;
        }
        if (i + 1 >= c->size)
            return fail(c, pos, "<?xml declaration is not closed");
        pos = i + 2;
    }
    int root_done = 0, stop = 0;
    while (!stop) {
        /* text up to the next '<' */
        const unsigned char *lt = memchr(d + pos, '<', c->size - pos);
        size_t end = lt ? (size_t)(lt - d) : c->size;
        span text = {d + pos, end - pos};
        const char *why;
        open_elem *in = c->depth ? &c->stack[c->depth - 1] : NULL;
        /* The base64 of a binary array is checked, stricter, in
         * check_inline: one pass over it less. */
        size_t bad = in && in->k == K_ARRAY && in->arr.fmt == F_BINARY &&
                             !in->arr.has_text
                         ? (size_t)-1
                         : check_chars(text, 0, &why);
        if (bad != (size_t)-1)
            return fail(c, pos + bad, "%s", why);
        span tt = trim(text);
        if (tt.n) {
            open_elem *top = c->depth ? &c->stack[c->depth - 1] : NULL;
            if (top && top->k == K_ARRAY && !top->arr.has_text) {
                top->arr.has_text = 1;
                top->arr.text = tt;
            } else if (!top || (top->k != K_VALUE && top->k != K_ARRAY))
                return top ? fail(c, (size_t)(tt.p - d),
                                  "unexpected text in <%s>", top->tag)
                           : fail(c, (size_t)(tt.p - d),
                                  "unexpected text outside the root "
                                  "element");
            /* text after an array's child elements: VTK ignores it */
        } else if (c->depth && c->stack[c->depth - 1].k == K_ARRAY &&
                   !c->stack[c->depth - 1].arr.has_text) {
            c->stack[c->depth - 1].arr.has_text = 1;   /* empty */
        }
        if (!lt)
            break;
        pos = end;
        size_t left = c->size - pos;
        if (left >= 4 && memcmp(d + pos, "<!--", 4) == 0) {
            size_t i = pos + 4;
            const unsigned char *e = NULL;
            while (i + 2 < c->size) {
                const unsigned char *m = memchr(d + i, '-', c->size - i - 2);
                if (!m)
                    break;
                if (m[1] == '-' && m[2] == '>') {
                    e = m;
                    break;
                }
                i = (size_t)(m - d) + 1;
            }
            if (!e)
                return fail(c, pos, "comment is not closed");
            span body = {d + pos + 4, (size_t)(e - (d + pos + 4))};
            for (size_t k = 0; k + 13 <= body.n; k++)
                if (memcmp(body.p + k, "<AppendedData", 13) == 0)
                    return fail(c, pos,
                                "comment holds \"<AppendedData\" (VTK would "
                                "take it for the data)");
            for (size_t k = 0; k < body.n; k++)
                if (bad_char(body.p[k]))
                    return fail(c, pos, "control character in a comment");
            pos = (size_t)(e - d) + 3;
            continue;
        }
        if (left >= 2 && d[pos + 1] == '!')
            return fail(c, pos,
                        "DOCTYPE or CDATA sections are not supported");
        if (left >= 2 && d[pos + 1] == '?')
            return fail(c, pos, "processing instructions are not "
                        "supported");
        if (left >= 2 && d[pos + 1] == '/') {
            st_status s = end_tag(c, &pos);
            if (s)
                return s;
            if (c->depth == 0)
                root_done = 1;
            continue;
        }
        if (root_done)
            return fail(c, pos, "a second root element");
        st_status s = start_tag(c, &pos, &stop);
        if (s)
            return s;
    }
    if (!stop && c->depth)
        return fail(c, c->size, "the file ends inside <%s> (truncated?)",
                    c->stack[c->depth - 1].tag);
    if (!stop && !root_done)
        return fail(c, c->size, "no <VTKFile> element");
    if (!c->have_dataset)
        return fail(c, c->size, "no <%s> element in <VTKFile>", c->want);
    if (c->napp)
        qsort(c->app, c->napp, sizeof *c->app, by_offset);
    for (size_t i = 0; i < c->napp; i++) {
        if (!c->have_payload)
            return fail_arr(c, ST_EINPUT, &c->app[i],
                            "appended array but the file has no "
                            "AppendedData");
        st_status s = check_appended(c, &c->app[i]);
        if (s)
            return s;
    }
    for (size_t i = 0; i < c->ncells_rec; i++) {
        const cells_rec *r = &c->cells[i];
        if (r->have_cap && r->have_last && r->last > r->cap)
            return fail_arr(c, ST_EINPUT, &r->offsets,
                            "the offsets end at %llu, but the connectivity "
                            "holds at most %llu values",
                            (unsigned long long)r->last,
                            (unsigned long long)r->cap);
    }
    return ST_OK;
}

st_status st_vtkxml_check(const unsigned char *data, size_t size,
                          const char *name, const char *want_type,
                          size_t max_bytes, st_vtkxml_inflate_fn inflate,
                          void *inflate_user, st_error *err)
{
    if (!name)
        name = "<input>";
    if (!data || size == 0)
        return st_error_set(err, ST_EINPUT, name, 0, "empty input");
    if (!want_type || (strcmp(want_type, "ImageData") != 0 &&
                       strcmp(want_type, "UnstructuredGrid") != 0))
        return st_error_set(err, ST_EINTERNAL, name, 0,
                            "st_vtkxml_check: unsupported type '%s'",
                            want_type ? want_type : "(null)");
    ctx c;
    memset(&c, 0, sizeof c);
    c.d = data;
    c.size = size;
    c.name = name;
    c.want = want_type;
    c.max_bytes = max_bytes;
    c.inflate = inflate;
    c.inflate_user = inflate_user;
    c.err = err;
    c.line_no = 1;
    c.ws = 4;
    c.is_image = strcmp(want_type, "ImageData") == 0;
    st_status s = parse(&c);
    free(c.app);
    free(c.cells);
    free(c.names);
    return s;
}
