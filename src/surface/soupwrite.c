/*
 * soupwrite.c - OBJ, OFF, binary PLY and binary STL writers (soupwrite.h).
 *
 * Binary output is little-endian whatever the machine (bytes are
 * assembled explicitly), as PLY's binary_little_endian and STL require.
 */
#include "souptet/soupwrite.h"
#include "../base/fpenv.h"
#include "souptet/geom.h"

#include <errno.h>
#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* The shortest of 9 (enough for any float), 15, 16 or 17 significant
 * digits that reads back as exactly x. */
static const char *num(char buf[32], double x)
{
    static const int digits[] = {9, 15, 16, 17};
    for (size_t i = 0; i < sizeof digits / sizeof *digits; i++) {
        snprintf(buf, 32, "%.*g", digits[i], x);
        if (strtod(buf, NULL) == x)
            break;
    }
    return buf;
}

/* Comment lines with a prefix; a line break inside becomes a new line. */
static void put_comment(FILE *f, const char *prefix, const char *comment)
{
    if (!comment)
        return;
    const char *p = comment;
    while (*p) {
        const char *e = strchr(p, '\n');
        size_t n = e ? (size_t)(e - p) : strlen(p);
        fprintf(f, "%s%.*s\n", prefix, (int)n, p);
        p += n;
        if (*p == '\n')
            p++;
    }
}

static void put_u32(FILE *f, uint32_t x)
{
    unsigned char b[4] = {(unsigned char)x, (unsigned char)(x >> 8),
                          (unsigned char)(x >> 16), (unsigned char)(x >> 24)};
    fwrite(b, 1, 4, f);
}

static void put_f32(FILE *f, double x)
{
    float v = (float)x;
    uint32_t u;
    memcpy(&u, &v, 4);
    put_u32(f, u);
}

static void put_f64(FILE *f, double x)
{
    uint64_t u;
    memcpy(&u, &x, 8);
    put_u32(f, (uint32_t)u);
    put_u32(f, (uint32_t)(u >> 32));
}

static int all_float(const st_soup *s)
{
    for (size_t i = 0; i < 3 * s->nverts; i++)
        if ((double)(float)s->xyz[i] != s->xyz[i])
            return 0;
    return 1;
}

static void write_obj(FILE *f, const st_soup *s, const char *comment)
{
    char b[3][32];
    put_comment(f, "# ", comment);
    for (size_t v = 0; v < s->nverts; v++) {
        const double *p = s->xyz + 3 * v;
        fprintf(f, "v %s %s %s\n", num(b[0], p[0]), num(b[1], p[1]),
                num(b[2], p[2]));
    }
    for (size_t t = 0; t < s->ntris; t++) {
        const uint32_t *c = s->tris + 3 * t;
        fprintf(f, "f %lu %lu %lu\n", (unsigned long)c[0] + 1,
                (unsigned long)c[1] + 1, (unsigned long)c[2] + 1);
    }
}

static void write_off(FILE *f, const st_soup *s, const char *comment)
{
    char b[3][32];
    fputs("OFF\n", f);
    fprintf(f, "%zu %zu 0\n", s->nverts, s->ntris);
    for (size_t v = 0; v < s->nverts; v++) {
        const double *p = s->xyz + 3 * v;
        fprintf(f, "%s %s %s\n", num(b[0], p[0]), num(b[1], p[1]),
                num(b[2], p[2]));
    }
    for (size_t t = 0; t < s->ntris; t++) {
        const uint32_t *c = s->tris + 3 * t;
        fprintf(f, "3 %lu %lu %lu\n", (unsigned long)c[0],
                (unsigned long)c[1], (unsigned long)c[2]);
    }
    /* After the data: TetGen 1.5's OFF reader stops at a comment between
     * the header and the counts (it aborts), but ignores trailing text. */
    put_comment(f, "# ", comment);
}

static void write_ply(FILE *f, const st_soup *s, const char *comment)
{
    const int single = all_float(s);
    const char *type = single ? "float" : "double";
    fputs("ply\nformat binary_little_endian 1.0\n", f);
    put_comment(f, "comment ", comment);
    fprintf(f, "element vertex %zu\nproperty %s x\nproperty %s y\n"
               "property %s z\nelement face %zu\n"
               "property list uchar uint vertex_indices\nend_header\n",
            s->nverts, type, type, type, s->ntris);
    for (size_t i = 0; i < 3 * s->nverts; i++)
        if (single)
            put_f32(f, s->xyz[i]);
        else
            put_f64(f, s->xyz[i]);
    for (size_t t = 0; t < s->ntris; t++) {
        fputc(3, f);
        for (int k = 0; k < 3; k++)
            put_u32(f, s->tris[3 * t + (size_t)k]);
    }
}

static void write_stl(FILE *f, const st_soup *s, const char *comment)
{
    char head[80];
    memset(head, ' ', sizeof head);
    /* "souptet: " and the last comment line, as much as fits. */
    const char *last = "";
    if (comment && *comment) {
        const char *p = comment + strlen(comment);
        while (p > comment && p[-1] == '\n')
            p--;
        const char *q = p;
        while (q > comment && q[-1] != '\n')
            q--;
        last = q;
        size_t n = (size_t)(p - q);
        snprintf(head, sizeof head, "souptet: %.*s", (int)n, last);
        for (size_t i = 0; i < sizeof head; i++)
            if (head[i] == '\0')
                head[i] = ' ';
    } else {
        memcpy(head, "souptet", 7);
    }
    fwrite(head, 1, sizeof head, f);
    put_u32(f, (uint32_t)s->ntris);
    for (size_t t = 0; t < s->ntris; t++) {
        const uint32_t *c = s->tris + 3 * t;
        float p[3][3];
        for (int k = 0; k < 3; k++)
            for (int a = 0; a < 3; a++)
                p[k][a] = (float)s->xyz[3 * (size_t)c[k] + (size_t)a];
        double u[3], v[3], n[3];
        for (int a = 0; a < 3; a++) {
            u[a] = (double)p[1][a] - (double)p[0][a];
            v[a] = (double)p[2][a] - (double)p[0][a];
        }
        st_cross3(n, u, v);
        double len = st_norm3(n);
        for (int a = 0; a < 3; a++)
            put_f32(f, len > 0.0 ? n[a] / len : 0.0);
        for (int k = 0; k < 3; k++)
            for (int a = 0; a < 3; a++)
                put_f32(f, p[k][a]);
        fputc(0, f);
        fputc(0, f);
    }
}

st_status st_soup_write(FILE *f, const st_soup *s, st_soup_format format,
                        const char *comment, const char *name, st_error *err)
{
    switch (format) {
    case ST_SOUP_OBJ:
        write_obj(f, s, comment);
        break;
    case ST_SOUP_OFF:
        write_off(f, s, comment);
        break;
    case ST_SOUP_PLY:
        if (s->nverts > UINT32_MAX)
            return st_error_set(err, ST_ELIMIT, name, 0,
                                "too many vertices for 32-bit PLY indices");
        write_ply(f, s, comment);
        break;
    case ST_SOUP_STL:
        if (s->ntris > UINT32_MAX)
            return st_error_set(err, ST_ELIMIT, name, 0,
                                "%zu triangles: binary STL counts at most "
                                "%lu", s->ntris, (unsigned long)UINT32_MAX);
        write_stl(f, s, comment);
        break;
    default:
        return st_error_set(err, ST_EINPUT, name, 0,
                            "cannot write this surface format (use .obj, "
                            ".off, .ply or .stl)");
    }
    if (ferror(f))
        return st_error_set(err, ST_EIO, name, 0, "write failed: %s",
                            errno ? strerror(errno) : "stream error");
    return ST_OK;
}
