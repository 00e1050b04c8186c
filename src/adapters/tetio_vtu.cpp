/*
 * tetio_vtu.cpp - reading VTK XML UnstructuredGrid (.vtu) into an
 * st_tetmesh, for meshes from ParaView, simulators built on VTK and the
 * pipes between souptet's tools. Writing is C (src/tet/tetformat_vtu.c, whose
 * comment gives the mapping; reading inverts it): a tool that only writes
 * meshes need not load VTK.
 *
 * Reading accepts foreign files: float or double points, any numeric
 * point/cell arrays of 1..9 components (converted to double), string,
 * char and one-value numeric field data as meta (numbers formatted back
 * with %llu and %.17g, so souptet's meta round-trips exactly), vertex
 * cells i = point i as a points-only mesh. The three quality arrays
 * (min_dihedral, max_dihedral, volume) are derived data: they are not
 * read back (every write recomputes them from the geometry, which a tool
 * may have moved). Refused, with a message naming the file: input VTK
 * cannot parse, cells that are not tetrahedra, point indices out of range,
 * non-finite coordinates, arrays whose length does not match, more than
 * max_bytes of mesh. Before VTK sees a byte, every input (files by path
 * are read into memory first) passes st_vtkxml_check (src/io/vtkxml.h): VTK's
 * reader trusts the file's structure and the sizes in it.
 *
 * VTK's messages go into the st_error of the call that caused them, never
 * to stderr (vtk_capture.h).
 */
#include "souptet/tetio.h"
#include "../base/fpenv.h"
#include "souptet/mem.h"
#include "souptet/meta.h"
#include "souptet/tetmesh.h"
#include "../base/fileio.h"
#include "tetio_internal.h"
#include "../io/vtkxml.h"
#include "vtk_capture.h"

#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkCellType.h>
#include <vtkDataArray.h>
#include <vtkDoubleArray.h>
#include <vtkErrorCode.h>
#include <vtkFieldData.h>
#include <vtkIdTypeArray.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkStringArray.h>
#include <vtkTypeUInt64Array.h>
#include <vtkUnsignedCharArray.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLUnstructuredGridReader.h>
#include <vtkXMLUnstructuredGridWriter.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <new>
#include <string>
#include <sys/stat.h>

namespace {

bool is_quality_name(const char *n)
{
    return n && (std::strcmp(n, "min_dihedral") == 0 ||
                 std::strcmp(n, "max_dihedral") == 0 ||
                 std::strcmp(n, "volume") == 0);
}

/* ---- reading ----------------------------------------------------------- */

struct MeshGuard {
    st_tetmesh *m;
    ~MeshGuard() { st_tetmesh_free(m); }
};

/* Copy the usable numeric arrays of one attribute set into the mesh. */
st_status read_arrays(st_tetmesh *m, vtkFieldData *src, st_tet_assoc assoc,
                      const char *name, size_t *bytes, size_t max_bytes,
                      st_error *err)
{
    if (!src)
        return ST_OK;
    const size_t n = assoc == ST_ON_CELLS ? m->ntets : m->npoints;
    const char *what = assoc == ST_ON_CELLS ? "cell" : "point";
    for (int i = 0; i < src->GetNumberOfArrays(); i++) {
        vtkDataArray *a = src->GetArray(i);   // null for string arrays
        if (!a || !a->GetName() || !a->GetName()[0])
            continue;
        if (assoc == ST_ON_CELLS && is_quality_name(a->GetName()))
            continue;   // derived: recomputed by every write
        const int nc = a->GetNumberOfComponents();
        if (nc < 1 || nc > 9)
            continue;   // not representable in an st_tetmesh: skipped
        if (a->GetNumberOfTuples() != vtkIdType(n))
            return st_error_set(err, ST_EINPUT, name, 0,
                                "%s array '%s' has %lld tuples for %zu "
                                "%ss",
                                what, a->GetName(),
                                (long long)a->GetNumberOfTuples(), n, what);
        size_t add = n * size_t(nc) * sizeof(double);
        if (st_size_add(bytes, *bytes, add) != 0 ||
            (max_bytes && *bytes > max_bytes))
            return st_error_set(err, ST_ELIMIT, name, 0,
                                "mesh needs more than the memory limit of "
                                "%zu bytes",
                                max_bytes);
        double *v;
        if (st_status s = st_tetmesh_add_array(m, a->GetName(), assoc, nc,
                                               &v, err)) {
            if (err && !err->file[0])
                std::snprintf(err->file, sizeof err->file, "%s", name);
            return s;
        }
        for (size_t t = 0; t < n; t++)
            for (int c = 0; c < nc; c++) {
                const double x = a->GetComponent(vtkIdType(t), c);
                v[t * size_t(nc) + size_t(c)] = x;
            }
    }
    return ST_OK;
}

/* The header's counts: np points and nc cells, refused when negative,
 * past 32-bit point ids, or over max_bytes (*bytes: what they take). */
st_status check_counts(vtkXMLUnstructuredGridReader *r, const char *name,
                       size_t max_bytes, long long *np, long long *nc,
                       size_t *bytes, st_error *err)
{
    r->SetupUpdateExtent(0, 1, 0);
    *np = (long long)r->GetNumberOfPoints();
    *nc = (long long)r->GetNumberOfCells();
    if (*np < 0 || *nc < 0)
        return st_error_set(err, ST_EINPUT, name, 0,
                            "negative point or cell count");
    if ((unsigned long long)*np >= UINT32_MAX)
        return st_error_set(err, ST_ELIMIT, name, 0,
                            "%lld points: more than a mesh can hold", *np);
    size_t tmp;
    if (st_size_mul(bytes, size_t(*np), 3 * sizeof(double)) != 0 ||
        st_size_mul(&tmp, size_t(*nc), 4 * sizeof(uint32_t)) != 0 ||
        st_size_add(bytes, *bytes, tmp) != 0 ||
        (max_bytes && *bytes > max_bytes))
        return st_error_set(err, ST_ELIMIT, name, 0,
                            "%lld points and %lld cells need more than the "
                            "memory limit of %zu bytes",
                            *np, *nc, max_bytes);
    return ST_OK;
}

/* The points, every one finite. */
st_status read_points(st_tetmesh *m, vtkUnstructuredGrid *ug, const char *name,
                      st_error *err)
{
    const vtkIdType npts = ug->GetNumberOfPoints();
    vtkPoints *pts = ug->GetPoints();
    if (npts > 0 && !pts)
        return st_error_set(err, ST_EINPUT, name, 0, "no points");
    for (vtkIdType i = 0; i < npts; i++) {
        double p[3];
        pts->GetPoint(i, p);
        if (!std::isfinite(p[0]) || !std::isfinite(p[1]) ||
            !std::isfinite(p[2]))
            return st_error_set(err, ST_EINPUT, name, 0,
                                "point %lld is not finite (%g %g %g)",
                                (long long)i, p[0], p[1], p[2]);
        std::memcpy(m->xyz + 3 * size_t(i), p, sizeof p);
    }
    m->npoints = size_t(npts);
    return ST_OK;
}

/* A points-only mesh as this file writes it: cell i is VTK_VERTEX i. */
bool is_points_only(vtkUnstructuredGrid *ug)
{
    const vtkIdType npts = ug->GetNumberOfPoints(), ncells = ug->GetNumberOfCells();
    bool points_only = ncells == npts && ncells > 0;
    for (vtkIdType c = 0; points_only && c < ncells; c++) {
        vtkIdType n;
        const vtkIdType *ids;
        if (ug->GetCellType(c) != VTK_VERTEX)
            return false;
        ug->GetCellPoints(c, n, ids);
        points_only = n == 1 && ids[0] == c;
    }
    return points_only;
}

/* The cells, every one a tetrahedron of points in range. */
st_status read_tets(st_tetmesh *m, vtkUnstructuredGrid *ug, const char *name,
                    st_error *err)
{
    const vtkIdType npts = ug->GetNumberOfPoints(), ncells = ug->GetNumberOfCells();
    for (vtkIdType c = 0; c < ncells; c++) {
        const int type = ug->GetCellType(c);
        vtkIdType n;
        const vtkIdType *ids;
        if (type != VTK_TETRA)
            return st_error_set(err, ST_EINPUT, name, 0,
                                "cell %lld is not a tetrahedron (VTK cell "
                                "type %d; only type %d, VTK_TETRA, is "
                                "accepted)",
                                (long long)c, type, VTK_TETRA);
        ug->GetCellPoints(c, n, ids);
        if (n != 4)
            return st_error_set(err, ST_EINPUT, name, 0,
                                "tetrahedron %lld has %lld points",
                                (long long)c, (long long)n);
        uint32_t *t = m->tets + 4 * size_t(c);
        for (int k = 0; k < 4; k++) {
            if (ids[k] < 0 || ids[k] >= npts)
                return st_error_set(err, ST_EINPUT, name, 0,
                                    "tetrahedron %lld refers to point %lld "
                                    "of %lld",
                                    (long long)c, (long long)ids[k],
                                    (long long)npts);
            t[k] = uint32_t(ids[k]);
        }
    }
    m->ntets = size_t(ncells);
    return ST_OK;
}

/* Field data as metadata: strings, char arrays (C strings) and one-value
 * numbers (%llu for 64-bit unsigned, else %.17g), into v with *keep true;
 * *keep false for an array souptet does not keep. ST_ELIMIT (err set)
 * past max_bytes. */
st_status meta_value(vtkAbstractArray *a, std::string &v, bool *keep, const char *name,
                     size_t *bytes, size_t max_bytes, st_error *err)
{
    *keep = false;
    const int type = a->GetDataType();
    vtkDataArray *d = vtkDataArray::SafeDownCast(a);
    if (vtkStringArray *sa = vtkStringArray::SafeDownCast(a)) {
        if (sa->GetNumberOfValues() < 1)
            return ST_OK;
        v = sa->GetValue(0);   // files before numbers were numbers
    } else if (d && d->GetNumberOfComponents() == 1 &&
               (type == VTK_UNSIGNED_CHAR || type == VTK_SIGNED_CHAR ||
                type == VTK_CHAR)) {
        const vtkIdType n = d->GetNumberOfTuples();
        if (st_size_add(bytes, *bytes, size_t(n)) != 0 ||
            (max_bytes && *bytes > max_bytes))
            return st_error_set(err, ST_ELIMIT, name, 0,
                                "mesh needs more than the memory limit "
                                "of %zu bytes", max_bytes);
        v.reserve(size_t(n));
        for (vtkIdType k = 0; k < n; k++) {
            const int c = int(d->GetComponent(k, 0)) & 0xff;
            if (c == 0)
                break;   // a C string ends there
            v.push_back(char(c));
        }
    } else if (d && d->GetNumberOfComponents() == 1 && d->GetNumberOfTuples() == 1 &&
               d->GetDataTypeSize() == 8 &&
               (type == VTK_UNSIGNED_LONG || type == VTK_UNSIGNED_LONG_LONG ||
                type == VTK_TYPE_UINT64)) {
        // (the reader makes a vtkUnsignedLongArray, not the typed one)
        char buf[32];
        std::snprintf(buf, sizeof buf, "%llu",
                      (unsigned long long)a->GetVariantValue(0).ToTypeUInt64());
        v = buf;
    } else if (d && d->GetNumberOfComponents() == 1 &&
               d->GetNumberOfTuples() == 1) {
        char buf[64];
        std::snprintf(buf, sizeof buf, "%.17g", d->GetComponent(0, 0));
        v = buf;
    } else {
        return ST_OK;   // not metadata souptet knows how to keep
    }
    *keep = true;
    return ST_OK;
}

/* The field data into m's metadata (meta_value). */
st_status read_meta(st_tetmesh *m, vtkFieldData *fd, const char *name, size_t *bytes,
                    size_t max_bytes, st_error *err)
{
    for (int i = 0; fd && i < fd->GetNumberOfArrays(); i++) {
        vtkAbstractArray *a = fd->GetAbstractArray(i);
        if (!a || !a->GetName() || !a->GetName()[0])
            continue;
        std::string v;
        bool keep;
        if (st_status st = meta_value(a, v, &keep, name, bytes, max_bytes, err))
            return st;
        if (keep && st_meta_set(&m->meta, a->GetName(), v.c_str()))
            return st_error_set(err, ST_ENOMEM, name, 0, "out of memory");
    }
    return ST_OK;
}

st_status read_with(vtkXMLUnstructuredGridReader *r, const char *name,
                    size_t max_bytes, st_tetmesh **out, st_error *err)
{
    st_vtk::Capture cap;
    r->UpdateInformation();
    if (st_vtk::failed() || r->GetErrorCode() != vtkErrorCode::NoError)
        return st_vtk::fail(name,
                          "not a readable VTK UnstructuredGrid (.vtu) file",
                          err);
    long long np, nc;
    size_t bytes = 0;
    if (st_status s = check_counts(r, name, max_bytes, &np, &nc, &bytes, err))
        return s;

    r->Update();
    vtkUnstructuredGrid *ug = r->GetOutput();
    if (st_vtk::failed() || r->GetErrorCode() != vtkErrorCode::NoError ||
        !ug)
        return st_vtk::fail(name,
                          "cannot read the mesh data (truncated or corrupt "
                          "file?)",
                          err);
    const vtkIdType npts = ug->GetNumberOfPoints();
    const vtkIdType ncells = ug->GetNumberOfCells();
    if (npts != np || ncells != nc)
        return st_error_set(err, ST_EINPUT, name, 0,
                            "read %lld points and %lld cells, the header "
                            "says %lld and %lld (truncated file?)",
                            (long long)npts, (long long)ncells, np, nc);

    st_tetmesh *m = st_tetmesh_new();
    if (!m)
        return st_error_set(err, ST_ENOMEM, name, 0, "out of memory");
    MeshGuard guard{m};
    if (st_status s = st_tetmesh_reserve(m, size_t(npts), size_t(ncells),
                                         err)) {
        std::snprintf(err->file, sizeof err->file, "%s", name);
        return s;
    }
    if (st_status s = read_points(m, ug, name, err))
        return s;
    const bool points_only = is_points_only(ug);
    if (!points_only) {
        if (st_status s = read_tets(m, ug, name, err))
            return s;
        if (st_status s = read_arrays(m, ug->GetCellData(), ST_ON_CELLS,
                                      name, &bytes, max_bytes, err))
            return s;
    }
    if (st_status s = read_arrays(m, ug->GetPointData(), ST_ON_POINTS, name,
                                  &bytes, max_bytes, err))
        return s;
    if (st_status s = read_meta(m, ug->GetFieldData(), name, &bytes, max_bytes, err))
        return s;
    guard.m = nullptr;
    *out = m;
    return ST_OK;
}

/* Check a document in memory, then read it with VTK. owned, if not null,
 * is data's malloc'd buffer: it is freed (on every way out) as soon as VTK
 * holds its own copy, so that a file read by path peaks at the two copies
 * VTK makes (its input string and the stream it parses). */
st_status read_mem(st_tetmesh **out, const unsigned char *data, size_t size,
                   const char *name, size_t max_bytes, unsigned char *owned,
                   st_error *err)
{
    struct Owned {
        unsigned char *p;
        ~Owned() { std::free(p); }
    } own{owned};
    *out = nullptr;
    if (!name)
        name = ST_STDIN_NAME;
    if (size == 0)
        return st_error_set(err, ST_EINPUT, name, 0, "empty input");
    return st_vtk::guarded(name, "reading", err, [&] {
        // VTK trusts the file's structure and sizes; it sees only a
        // document the pre-flight check has passed.
        if (st_status s = st_vtkxml_check(data, size, name,
                                          "UnstructuredGrid",
                                          st_vtkxml_budget(max_bytes),
                                          st_vtkxml_inflate_vtk, nullptr,
                                          err))
            return s;
        vtkNew<vtkXMLUnstructuredGridReader> r;
        r->ReadFromInputStringOn();
        r->SetInputString(
            std::string(reinterpret_cast<const char *>(data), size));
        std::free(own.p);
        own.p = nullptr;
        return read_with(r, name, max_bytes, out, err);
    });
}

} // namespace

extern "C" {

st_status st_tetio_read_vtu_mem(st_tetmesh **out, const unsigned char *data,
                                size_t size, const char *name,
                                size_t max_bytes, st_error *err)
{
    return read_mem(out, data, size, name, max_bytes, nullptr, err);
}

st_status st_tetio_read_vtu_file(st_tetmesh **out, const char *path,
                                 size_t max_bytes, st_error *err)
{
    *out = nullptr;
    if (st_status s = st_file_check_input(path, err))
        return s;
    // Through memory, so that the bytes checked are the bytes VTK reads.
    unsigned char *data;
    size_t size;
    if (st_status s = st_file_read(path, &data, &size, err))
        return s;
    return read_mem(out, data, size, path, max_bytes, data, err);
}

} // extern "C"
