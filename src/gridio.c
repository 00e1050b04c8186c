/*
 * gridio.c - which field format to read or write (see gridio.h).
 *
 * The dispatch only: the formats themselves live in the C++ adapters
 * (src/adapters/gridio_vdb.cpp for OpenVDB, gridio_vti.cpp for VTK XML
 * ImageData). Files go by extension (".vdb", ".vti", any case); a file
 * with another extension is read by content. Standard input ("-" or NULL)
 * is read whole and sniffed: VTK XML starts with '<' (after an optional
 * byte-order mark and white space), anything else goes to OpenVDB, which
 * accepts both its stream format and a .vdb file's bytes. Standard output
 * always carries an OpenVDB stream: it is the format tools pipe to each
 * other.
 */
#include "souptet/gridio.h"
#include "souptet/mem.h"
#include "souptet/outfile.h"
#include "adapters/gridio_internal.h"

#include <errno.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>

st_grid_format st_grid_format_from_path(const char *path)
{
    if (!path)
        return ST_GRID_FMT_UNKNOWN;
    /* The extension of the last path component only: "a.vdb/field" has
     * none. */
    const char *base = strrchr(path, '/');
    base = base ? base + 1 : path;
    const char *dot = strrchr(base, '.');
    if (!dot || dot == base)    /* ".vdb" alone is a hidden file, no ext */
        return ST_GRID_FMT_UNKNOWN;
    if (strcasecmp(dot, ".vdb") == 0)
        return ST_GRID_FMT_VDB;
    if (strcasecmp(dot, ".vti") == 0)
        return ST_GRID_FMT_VTI;
    return ST_GRID_FMT_UNKNOWN;
}

const char *st_grid_name_for_kind(st_grid_kind kind)
{
    switch (kind) {
    case ST_GRID_DISTANCE: return "distance";
    case ST_GRID_SIGNED: return "sdf";
    default: return "field";
    }
}

st_status st_grid_write(const st_grid *g, const char *path, st_error *err)
{
    if (st_path_is_stdio(path))
        return st_grid_write_vdb(g, NULL, err);
    switch (st_grid_format_from_path(path)) {
    case ST_GRID_FMT_VDB: return st_grid_write_vdb(g, path, err);
    case ST_GRID_FMT_VTI: return st_grid_write_vti(g, path, err);
    default: break;
    }
    return st_error_set(err, ST_EINPUT, path, 0,
                        "unknown field format (use .vdb or .vti)");
}

st_status st_gridio_check_input_file(const char *path, st_error *err)
{
    struct stat st;
    if (stat(path, &st) != 0)
        return st_error_set(err, ST_EIO, path, 0, "cannot open: %s",
                            strerror(errno));
    if (S_ISDIR(st.st_mode))
        return st_error_set(err, ST_EIO, path, 0, "is a directory");
    if (S_ISREG(st.st_mode) && st.st_size == 0)
        return st_error_set(err, ST_EINPUT, path, 0, "empty file");
    FILE *fp = fopen(path, "rb");
    if (!fp)
        return st_error_set(err, ST_EIO, path, 0, "cannot open: %s",
                            strerror(errno));
    fclose(fp);
    return ST_OK;
}

st_status st_gridio_read_stdin(unsigned char **data, size_t *size,
                               st_error *err)
{
    size_t cap = 1 << 16, n = 0;
    unsigned char *buf = malloc(cap);
    *data = NULL;
    *size = 0;
    if (!buf)
        return st_error_set(err, ST_ENOMEM, ST_GRIDIO_STDIN_NAME, 0,
                            "out of memory");
    for (;;) {
        if (n == cap) {
            size_t ncap;
            unsigned char *nb = NULL;
            if (st_size_mul(&ncap, cap, 2) == 0)
                nb = realloc(buf, ncap);
            if (!nb) {
                free(buf);
                return st_error_set(err, ST_ENOMEM, ST_GRIDIO_STDIN_NAME, 0,
                                    "out of memory after %zu bytes", n);
            }
            buf = nb;
            cap = ncap;
        }
        size_t got = fread(buf + n, 1, cap - n, stdin);
        n += got;
        if (got == 0) {
            if (ferror(stdin)) {
                int e = errno;
                free(buf);
                clearerr(stdin);
                return st_error_set(err, ST_EIO, ST_GRIDIO_STDIN_NAME, 0,
                                    "read failed: %s", strerror(e));
            }
            break;      /* end of file */
        }
    }
    *data = buf;
    *size = n;
    return ST_OK;
}

/* VTK XML, by its first significant byte: '<' after an optional UTF-8
 * byte-order mark and white space. */
static int looks_like_xml(const unsigned char *p, size_t n)
{
    size_t i = 0;
    if (n >= 3 && p[0] == 0xEF && p[1] == 0xBB && p[2] == 0xBF)
        i = 3;
    while (i < n && (p[i] == ' ' || p[i] == '\t' || p[i] == '\r' ||
                     p[i] == '\n'))
        i++;
    return i < n && p[i] == '<';
}

/* OpenVDB files and streams begin with the 64-bit magic number 0x56444220
 * ("VDB " read as a little-endian integer), the high half zero. */
static int looks_like_vdb(const unsigned char *p, size_t n)
{
    static const unsigned char magic[8] = {0x20, 0x42, 0x44, 0x56,
                                           0, 0, 0, 0};
    return n >= 8 && memcmp(p, magic, 8) == 0;
}

st_status st_grid_read(st_grid **out, const char *path, size_t max_bytes,
                       st_error *err)
{
    *out = NULL;
    if (st_path_is_stdio(path)) {
        unsigned char *data;
        size_t size;
        st_status s = st_gridio_read_stdin(&data, &size, err);
        if (s)
            return s;
        if (looks_like_xml(data, size))
            s = st_gridio_read_vti_mem(out, data, size, ST_GRIDIO_STDIN_NAME,
                                       max_bytes, err);
        else
            s = st_gridio_read_vdb_mem(out, data, size, ST_GRIDIO_STDIN_NAME,
                                       max_bytes, err);
        free(data);
        return s;
    }
    switch (st_grid_format_from_path(path)) {
    case ST_GRID_FMT_VDB: return st_grid_read_vdb(out, path, max_bytes, err);
    case ST_GRID_FMT_VTI: return st_grid_read_vti(out, path, max_bytes, err);
    default: break;
    }
    /* No known extension: look at the first bytes. */
    FILE *fp = fopen(path, "rb");
    if (!fp)
        return st_error_set(err, ST_EIO, path, 0, "cannot open: %s",
                            strerror(errno));
    unsigned char head[64];
    size_t n = fread(head, 1, sizeof head, fp);
    int bad = ferror(fp);
    int e = errno;
    fclose(fp);
    if (bad)
        return st_error_set(err, ST_EIO, path, 0, "read failed: %s",
                            strerror(e));
    if (n == 0)
        return st_error_set(err, ST_EINPUT, path, 0, "empty file");
    if (looks_like_vdb(head, n))
        return st_grid_read_vdb(out, path, max_bytes, err);
    if (looks_like_xml(head, n))
        return st_grid_read_vti(out, path, max_bytes, err);
    return st_error_set(err, ST_EINPUT, path, 0,
                        "unknown field format: neither OpenVDB nor VTK XML "
                        "(use .vdb or .vti)");
}
