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
#include "souptet/outfile.h"
#include "../adapters/gridio_internal.h"
#include "../base/fileio.h"

#include <stdlib.h>
#include <string.h>

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

st_status st_grid_blocks_write(const st_grid_blocks *b, const char *path,
                               st_error *err)
{
    if (st_path_is_stdio(path))
        return st_grid_blocks_write_vdb(b, NULL, err);
    switch (st_grid_format_from_path(path)) {
    case ST_GRID_FMT_VDB: return st_grid_blocks_write_vdb(b, path, err);
    case ST_GRID_FMT_VTI: {
        st_grid *g;
        st_status s = st_grid_blocks_dense(&g, b, 0, err);
        if (!s)
            s = st_grid_write_vti(g, path, err);
        st_grid_free(g);
        return s;
    }
    default: break;
    }
    return st_error_set(err, ST_EINPUT, path, 0,
                        "unknown field format (use .vdb or .vti)");
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
        st_status s = st_file_read(NULL, &data, &size, err);
        if (s)
            return s;
        if (st_looks_like_xml(data, size))
            s = st_gridio_read_vti_mem(out, data, size, ST_STDIN_NAME,
                                       max_bytes, err);
        else
            s = st_gridio_read_vdb_mem(out, data, size, ST_STDIN_NAME,
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
    unsigned char head[64];
    size_t n;
    st_status s = st_file_head(path, head, sizeof head, &n, err);
    if (s)
        return s;
    if (looks_like_vdb(head, n))
        return st_grid_read_vdb(out, path, max_bytes, err);
    if (st_looks_like_xml(head, n))
        return st_grid_read_vti(out, path, max_bytes, err);
    return st_error_set(err, ST_EINPUT, path, 0,
                        "unknown field format: neither OpenVDB nor VTK XML "
                        "(use .vdb or .vti)");
}
