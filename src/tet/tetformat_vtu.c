/*
 * tetformat_vtu.c - writing .vtu (VTK XML UnstructuredGrid) in C, without
 * VTK: the format every souptet tool writes by default, so that a tool
 * that only writes meshes (soupmesh) need not load VTK's libraries, whose
 * relocations alone cost a process about 60 ms (issue 41). Reading .vtu
 * stays with VTK (src/adapters/tetio_vtu.cpp): foreign files come in all
 * of VTK's variants, and VTK is the reader that must agree.
 *
 * The document is the one VTK 9.1's vtkXMLUnstructuredGridWriter writes
 * for the same grid (what tetio_vtu.cpp gave it until issue 41), element
 * for element, without the optional RangeMin/RangeMax attributes:
 *
 *   points     one 3-component Float64 array (binary: exact).
 *   cells      VTK_TETRA only, connectivity in the mesh's own corner order
 *              (VTK's tetra has the same orientation convention as
 *              tetmesh.h: a positive tet has positive signed volume).
 *   cell data  min_dihedral, max_dihedral (degrees) and volume (signed,
 *              model units^3), computed at every write (min_dihedral is
 *              the active scalars, so ParaView colours by it at once),
 *              then the mesh's own per-cell arrays; point data: the mesh's
 *              per-point arrays. All Float64 but "part" (the part
 *              index, parts.h), Int32.
 *   field data every st_meta entry named by its key, in st_meta order: a
 *              canonical non-negative integer (seed, candidates) as a
 *              one-value UInt64 array, another value that is a number
 *              exactly as %.17g prints it as a one-value Float64 array,
 *              any other as a UInt8 array of its bytes (meshio cannot read
 *              VTK's String arrays). Reading formats numbers back with
 *              %llu and %.17g, so the meta round-trips exactly.
 *   no tets    a points-only mesh (soupmesh --embed F.vtu) gets one
 *              VTK_VERTEX cell per point and no cell arrays, so ParaView
 *              draws it and meshio reads it.
 *   encoding   appended raw binary, each array zlib-compressed in blocks
 *              of 32 KiB behind a UInt64 header (the number of blocks, the
 *              block size, the size of a partial last block or 0, then
 *              each block's compressed size), Int64 ids: vtkZLibDataCompressor's
 *              layout at VTK's default level.
 */
#include "souptet/tetformat.h"
#include "../base/fpenv.h"
#include "souptet/mem.h"
#include "souptet/meta.h"
#include "souptet/tetmesh.h"
#include "tetformat_internal.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <zlib.h>

/* VTK's block size and compression level (vtkZLibDataCompressor). */
#define VTU_BLOCK 32768u
#define VTU_LEVEL 5

/* A growing byte buffer; a failed allocation sets oom and stops growth. */
typedef struct {
    unsigned char *p;
    size_t n, cap;
    int oom;
} vbuf;

static int vbuf_reserve(vbuf *b, size_t extra)
{
    if (b->oom)
        return 0;
    if (extra <= b->cap - b->n)
        return 1;
    size_t cap = b->cap ? b->cap : 4096;
    while (cap - b->n < extra) {
        if (cap > SIZE_MAX / 2) {
            b->oom = 1;
            return 0;
        }
        cap *= 2;
    }
    unsigned char *q = realloc(b->p, cap);
    if (!q) {
        b->oom = 1;
        return 0;
    }
    b->p = q;
    b->cap = cap;
    return 1;
}

static void vbuf_put(vbuf *b, const void *data, size_t n)
{
    if (n && vbuf_reserve(b, n)) {
        memcpy(b->p + b->n, data, n);
        b->n += n;
    }
}

static void vbuf_printf(vbuf *b, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    char small[256];
    int k = vsnprintf(small, sizeof small, fmt, ap);
    va_end(ap);
    if (k < 0) {
        b->oom = 1;
        return;
    }
    if ((size_t)k < sizeof small) {
        vbuf_put(b, small, (size_t)k);
        return;
    }
    if (!vbuf_reserve(b, (size_t)k + 1))
        return;
    va_start(ap, fmt);
    vsnprintf((char *)b->p + b->n, (size_t)k + 1, fmt, ap);
    va_end(ap);
    b->n += (size_t)k;
}

/* An XML attribute value: the five characters XML reserves escaped. */
static void vbuf_attr(vbuf *b, const char *s)
{
    for (; *s; s++) {
        switch (*s) {
        case '&': vbuf_put(b, "&amp;", 5); break;
        case '<': vbuf_put(b, "&lt;", 4); break;
        case '>': vbuf_put(b, "&gt;", 4); break;
        case '"': vbuf_put(b, "&quot;", 6); break;
        case '\'': vbuf_put(b, "&apos;", 6); break;
        default: vbuf_put(b, s, 1);
        }
    }
}

/* A canonical decimal integer ("0", or digits without a leading zero)
 * that fits 64 bits unsigned: seeds, counts, resolutions. Such a value is
 * written as a one-value UInt64 array whatever its size (a seed above
 * 2^53 is no exact double, and one key keeps one type: meshio gives
 * numpy.uint64 for every seed). */
static int meta_integer(const char *v, unsigned long long *x)
{
    const size_t n = strlen(v);
    if (n == 0 || n > 20 || (v[0] == '0' && n > 1))
        return 0;
    for (size_t i = 0; i < n; i++)
        if (v[i] < '0' || v[i] > '9')
            return 0;
    errno = 0;
    char *end;
    const unsigned long long u = strtoull(v, &end, 10);
    if (*end || errno)
        return 0;
    *x = u;
    return 1;
}

/* A value that is exactly the %.17g form of a finite double (h,
 * offset_ratio, ...): a one-value Float64 array, so ParaView can compute
 * with it. */
static int meta_number(const char *v, double *x)
{
    if (!v[0] || v[0] == ' ' || v[0] == '\t' || v[0] == '\n')
        return 0;
    char *end;
    errno = 0;
    const double d = strtod(v, &end);
    if (*end || errno || !isfinite(d))
        return 0;
    char buf[64];
    snprintf(buf, sizeof buf, "%.17g", d);
    if (strcmp(buf, v) != 0)
        return 0;
    *x = d;
    return 1;
}

/* The document being written: the XML part and the appended data. */
typedef struct {
    vbuf xml, app;
    int zfail;
} vtu_doc;

/* Append n bytes as one compressed array to the appended data and its
 * DataArray element (opened by the caller up to the attributes) to the
 * XML: the element's offset is where the array's header begins. */
static void vtu_array(vtu_doc *d, const void *data, size_t n)
{
    const unsigned char *src = data;
    const size_t nblocks = (n + VTU_BLOCK - 1) / VTU_BLOCK;
    vbuf_printf(&d->xml, " format=\"appended\" offset=\"%zu\"/>\n", d->app.n);
    const size_t hdr_at = d->app.n;
    uint64_t h[3] = {nblocks, VTU_BLOCK, n % VTU_BLOCK};
    vbuf_put(&d->app, h, sizeof h);
    for (size_t i = 0; i < nblocks; i++) {
        uint64_t zero = 0;
        vbuf_put(&d->app, &zero, sizeof zero);
    }
    for (size_t i = 0; i < nblocks && !d->app.oom; i++) {
        const size_t len = i + 1 < nblocks || n % VTU_BLOCK == 0 ? VTU_BLOCK : n % VTU_BLOCK;
        uLongf zlen = compressBound((uLong)len);
        if (!vbuf_reserve(&d->app, zlen))
            return;
        if (compress2(d->app.p + d->app.n, &zlen, src + i * VTU_BLOCK, (uLong)len,
                      VTU_LEVEL) != Z_OK) {
            d->zfail = 1;
            return;
        }
        d->app.n += zlen;
        uint64_t z = zlen;
        memcpy(d->app.p + hdr_at + (3 + i) * sizeof z, &z, sizeof z);
    }
}

/* A named Float64 array of n tuples of ncomp components. */
static void vtu_doubles(vtu_doc *d, const char *indent, const char *name,
                        const double *v, size_t n, int ncomp)
{
    vbuf_printf(&d->xml, "%s<DataArray type=\"Float64\" Name=\"", indent);
    vbuf_attr(&d->xml, name);
    vbuf_put(&d->xml, "\"", 1);
    if (ncomp != 1)
        vbuf_printf(&d->xml, " NumberOfComponents=\"%d\"", ncomp);
    vtu_array(d, v, n * (size_t)ncomp * sizeof *v);
}

/* The array of a mesh: "part" (one component, parts.h) as Int32, as
 * simulators read tags; any other as Float64. ST_ENOMEM. */
static st_status vtu_mesh_array(vtu_doc *d, const st_tet_array *a, size_t n)
{
    if (strcmp(a->name, "part") != 0 || a->ncomp != 1) {
        vtu_doubles(d, "        ", a->name, a->values, n, a->ncomp);
        return ST_OK;
    }
    int32_t *v = st_malloc_array(n ? n : 1, sizeof *v);
    if (!v)
        return ST_ENOMEM;
    for (size_t i = 0; i < n; i++)
        v[i] = (int32_t)a->values[i];
    vbuf_printf(&d->xml, "        <DataArray type=\"Int32\" Name=\"part\"");
    vtu_array(d, v, n * sizeof *v);
    free(v);
    return ST_OK;
}

static void vtu_field_data(vtu_doc *d, const st_meta *meta)
{
    if (meta->count == 0)
        return;
    vbuf_printf(&d->xml, "    <FieldData>\n");
    for (size_t i = 0; i < meta->count; i++) {
        const char *key = meta->entries[i].key;
        const char *val = meta->entries[i].value ? meta->entries[i].value : "";
        unsigned long long u;
        double x;
        const char *type = "UInt8";
        const void *data = val;
        size_t n = strlen(val), size = n;
        uint64_t u64;
        if (meta_integer(val, &u)) {
            type = "UInt64";
            u64 = (uint64_t)u;
            data = &u64;
            n = 1;
            size = sizeof u64;
        } else if (meta_number(val, &x)) {
            type = "Float64";
            data = &x;
            n = 1;
            size = sizeof x;
        }
        vbuf_printf(&d->xml, "      <DataArray type=\"%s\" Name=\"", type);
        vbuf_attr(&d->xml, key);
        vbuf_printf(&d->xml, "\" NumberOfTuples=\"%zu\"", n);
        vtu_array(d, data, size);
    }
    vbuf_printf(&d->xml, "    </FieldData>\n");
}

/* The point data, the cell data (the three quality arrays first) and the
 * mesh's own arrays. ST_ENOMEM when the quality arrays do not fit. */
static st_status vtu_arrays(vtu_doc *d, const st_tetmesh *m)
{
    vbuf_printf(&d->xml, "      <PointData>\n");
    for (size_t i = 0; i < m->narrays; i++) {
        const st_tet_array *a = &m->arrays[i];
        if (a->assoc != ST_ON_CELLS && vtu_mesh_array(d, a, m->npoints))
            return ST_ENOMEM;
    }
    vbuf_printf(&d->xml, "      </PointData>\n");
    if (m->ntets == 0) {
        vbuf_printf(&d->xml, "      <CellData>\n      </CellData>\n");
        return ST_OK;
    }
    vbuf_printf(&d->xml, "      <CellData Scalars=\"min_dihedral\">\n");
    double *q = st_malloc_array(m->ntets, 3 * sizeof *q);
    if (!q)
        return ST_ENOMEM;
    st_tetmesh_quality(m, q, q + m->ntets, q + 2 * m->ntets);
    static const char *const qn[3] = {"min_dihedral", "max_dihedral", "volume"};
    for (int k = 0; k < 3; k++)
        vtu_doubles(d, "        ", qn[k], q + (size_t)k * m->ntets, m->ntets, 1);
    free(q);
    for (size_t i = 0; i < m->narrays; i++) {
        const st_tet_array *a = &m->arrays[i];
        if (a->assoc == ST_ON_CELLS && strcmp(a->name, qn[0]) && strcmp(a->name, qn[1]) &&
            strcmp(a->name, qn[2]) && vtu_mesh_array(d, a, m->ntets))
            return ST_ENOMEM;
    }
    vbuf_printf(&d->xml, "      </CellData>\n");
    return ST_OK;
}

/* The cells: tets, or one vertex cell per point for a points-only mesh. */
static st_status vtu_cells(vtu_doc *d, const st_tetmesh *m)
{
    const int tets = m->ntets > 0 || m->npoints == 0;
    const size_t nc = tets ? m->ntets : m->npoints, per = tets ? 4 : 1;
    int64_t *conn = st_malloc_array(nc * per + 1, sizeof *conn);
    int64_t *off = st_malloc_array(nc + 1, sizeof *off);
    unsigned char *type = st_malloc_array(nc + 1, 1);
    if (!conn || !off || !type) {
        free(conn);
        free(off);
        free(type);
        return ST_ENOMEM;
    }
    for (size_t i = 0; i < nc * per; i++)
        conn[i] = tets ? (int64_t)m->tets[i] : (int64_t)i;
    for (size_t c = 0; c < nc; c++) {
        off[c] = (int64_t)((c + 1) * per);
        type[c] = tets ? 10 : 1;   /* VTK_TETRA, VTK_VERTEX */
    }
    vbuf_printf(&d->xml, "      <Cells>\n        <DataArray type=\"Int64\" Name=\"connectivity\"");
    vtu_array(d, conn, nc * per * sizeof *conn);
    vbuf_printf(&d->xml, "        <DataArray type=\"Int64\" Name=\"offsets\"");
    vtu_array(d, off, nc * sizeof *off);
    vbuf_printf(&d->xml, "        <DataArray type=\"UInt8\" Name=\"types\"");
    vtu_array(d, type, nc);
    vbuf_printf(&d->xml, "      </Cells>\n");
    free(conn);
    free(off);
    free(type);
    return ST_OK;
}

st_status st_tf_write_vtu_mem(unsigned char **data, size_t *size, const st_tetmesh *m,
                              const char *name, st_error *err)
{
    *data = NULL;
    *size = 0;
    if (!m)
        return st_error_set(err, ST_EINTERNAL, name, 0, "no mesh to write");
    for (size_t i = 0; i < 4 * m->ntets; i++)
        if (m->tets[i] >= m->npoints)
            return st_error_set(err, ST_EINTERNAL, name, 0, "tet %zu refers to point %lu of %zu",
                                i / 4, (unsigned long)m->tets[i], m->npoints);
    for (size_t i = 0; i < m->narrays; i++)
        if (m->arrays[i].ncomp < 1 || m->arrays[i].ncomp > 9)
            return st_error_set(err, ST_EINTERNAL, name, 0, "mesh array '%s' has %d components",
                                m->arrays[i].name, m->arrays[i].ncomp);
    const uint16_t one = 1;
    const int little = *(const unsigned char *)&one == 1;
    vtu_doc d;
    memset(&d, 0, sizeof d);
    vbuf_printf(&d.xml,
                "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"%s\" "
                "header_type=\"UInt64\" compressor=\"vtkZLibDataCompressor\">\n"
                "  <UnstructuredGrid>\n",
                little ? "LittleEndian" : "BigEndian");
    vtu_field_data(&d, &m->meta);
    const size_t ncells = m->ntets > 0 || m->npoints == 0 ? m->ntets : m->npoints;
    vbuf_printf(&d.xml, "    <Piece NumberOfPoints=\"%zu\" NumberOfCells=\"%zu\">\n",
                m->npoints, ncells);
    st_status s = vtu_arrays(&d, m);
    if (s == ST_OK) {
        vbuf_printf(&d.xml, "      <Points>\n");
        vtu_doubles(&d, "        ", "Points", m->xyz, m->npoints, 3);
        vbuf_printf(&d.xml, "      </Points>\n");
        s = vtu_cells(&d, m);
    }
    vbuf_printf(&d.xml, "    </Piece>\n  </UnstructuredGrid>\n"
                        "  <AppendedData encoding=\"raw\">\n   _");
    vbuf_put(&d.xml, d.app.p, d.app.n);
    vbuf_printf(&d.xml, "\n  </AppendedData>\n</VTKFile>\n");
    free(d.app.p);
    if (s == ST_OK && (d.xml.oom || d.app.oom))
        s = ST_ENOMEM;
    if (s == ST_OK && d.zfail)
        s = st_error_set(err, ST_EINTERNAL, name, 0, "zlib failed to compress");
    else if (s == ST_ENOMEM)
        st_error_set(err, ST_ENOMEM, name, 0, "out of memory writing the .vtu document");
    if (s) {
        free(d.xml.p);
        return s;
    }
    *data = d.xml.p;
    *size = d.xml.n;
    return ST_OK;
}

st_status st_tf_write_vtu_path(const st_tetmesh *m, const char *path, st_error *err)
{
    unsigned char *data;
    size_t size;
    st_status s = st_tf_write_vtu_mem(&data, &size, m, path, err);
    if (s)
        return s;
    FILE *fp = st_tf_open_out(path, err);
    if (!fp) {
        free(data);
        return ST_EIO;
    }
    size_t put = fwrite(data, 1, size, fp);
    int e = errno;
    free(data);
    if (put != size) {
        fclose(fp);
        return st_error_set(err, ST_EIO, path, 0, "write failed: %s", strerror(e));
    }
    if (fclose(fp) != 0)
        return st_error_set(err, ST_EIO, path, 0, "write failed: %s", strerror(errno));
    return ST_OK;
}
