/*
 * gridio_vti.cpp - st_grid <-> VTK XML ImageData (.vti), for ParaView and
 * anything else built on VTK.
 *
 * Mapping (writing; reading inverts it):
 *
 *   image      extent 0..nx-1, 0..ny-1, 0..nz-1 (points = voxel centers,
 *              so point (i,j,k) is voxel (i,j,k)), Origin = g->origin,
 *              Spacing = (voxel, voxel, voxel), identity direction.
 *   values     one vtkFloatArray point-data array named
 *              st_grid_name_for_kind ("distance", "sdf", "field"), set as
 *              the active scalars. Floats are stored in binary: exact.
 *   metadata   field data: souptet_kind (vtkStringArray), band
 *              (vtkDoubleArray, +inf as is), origin (3-component
 *              vtkDoubleArray) and voxel_size (vtkDoubleArray) - binary
 *              copies of the Origin and Spacing attributes, which are
 *              decimal text (VTK 9.1 prints 17 digits, which round-trips,
 *              but other writers need not) - and
 *              every st_meta entry as a one-value vtkStringArray named by
 *              its key, in st_meta order (field data keeps its order). A
 *              key that is empty, starts with "souptet_meta:" or is one of
 *              the names above is stored as "souptet_meta:" + key.
 *   encoding   appended raw binary (not base64), zlib compression, UInt64
 *              block headers (VTK's advice for arrays whose byte counts
 *              may not fit 32 bits: a 1024^3 field is 4 GiB).
 *
 * Reading accepts foreign files too: the point array is the active scalars
 * if they are one-component float or double, else the first such array;
 * anything else is refused. Spacing must be uniform and the direction the
 * identity. The exact origin/voxel_size field data are used when they
 * agree with the image's own origin and spacing (they disagree when a tool
 * moved the image but carried the field data along: then the image wins).
 * Without souptet_kind the kind is UNKNOWN and the band INFINITY.
 *
 * VTK's XML reader trusts the file (fuzzing crashed it with misspelled
 * attributes and made it allocate from block headers), so every input is
 * read into memory and passes st_vtkxml_check (src/io/vtkxml.h) before VTK
 * sees a byte; files by path take the same in-memory path.
 *
 * VTK's messages go into the st_error of the call that caused them, never
 * to stderr (vtk_capture.h).
 */
#include "souptet/gridio.h"
#include "../base/fpenv.h"
#include "souptet/meta.h"
#include "souptet/outfile.h"
#include "gridio_internal.h"
#include "../base/fileio.h"
#include "../io/vtkxml.h"
#include "vtk_capture.h"

#include <vtkAbstractArray.h>
#include <vtkDataArray.h>
#include <vtkDoubleArray.h>
#include <vtkErrorCode.h>
#include <vtkFieldData.h>
#include <vtkFloatArray.h>
#include <vtkImageData.h>
#include <vtkInformation.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkStreamingDemandDrivenPipeline.h>
#include <vtkStringArray.h>
#include <vtkXMLImageDataReader.h>
#include <vtkXMLImageDataWriter.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <new>
#include <string>
#include <sys/stat.h>

namespace {

const char *const kMetaPrefix = "souptet_meta:";

bool is_reserved_name(const std::string &n)
{
    return n == "souptet_kind" || n == "band" || n == "origin" ||
           n == "voxel_size";
}

std::string escape_key(const std::string &key)
{
    if (key.empty() || is_reserved_name(key) ||
        key.compare(0, std::strlen(kMetaPrefix), kMetaPrefix) == 0)
        return kMetaPrefix + key;
    return key;
}

/* The point array holding the field, or null. */
vtkDataArray *field_array(vtkImageData *img)
{
    vtkPointData *pd = img->GetPointData();
    if (!pd)
        return nullptr;
    auto usable = [](vtkDataArray *a) {
        return a && a->GetNumberOfComponents() == 1 &&
               (vtkFloatArray::SafeDownCast(a) ||
                vtkDoubleArray::SafeDownCast(a));
    };
    if (usable(pd->GetScalars()))
        return pd->GetScalars();
    for (int i = 0; i < pd->GetNumberOfArrays(); i++)
        if (usable(pd->GetArray(i)))
            return pd->GetArray(i);
    return nullptr;
}

/* One double from field data array `n` with `comps` components, if there. */
bool field_doubles(vtkFieldData *fd, const char *n, int comps, double *v)
{
    vtkDoubleArray *a =
        fd ? vtkDoubleArray::SafeDownCast(fd->GetAbstractArray(n)) : nullptr;
    if (!a || a->GetNumberOfComponents() != comps || a->GetNumberOfTuples() < 1)
        return false;
    for (int c = 0; c < comps; c++)
        v[c] = a->GetComponent(0, c);
    return true;
}

bool close_to(double a, double b, double scale)
{
    return std::fabs(a - b) <= 1e-9 * scale;
}

/* Run a configured reader: information, limit check, data, conversion. */
/* Where the grid lies: the spacing (uniform, positive, with the identity
 * as direction matrix), the voxel and origin (the field data's exact
 * values when they agree with the image's). */
st_status read_placement(st_grid *g, vtkImageData *img, const int ext[6],
                         const char *name, st_error *err)
{
    double sp[3], org[3];
    img->GetSpacing(sp);
    img->GetOrigin(org);
    // The direction matrix must be the identity: index steps must move
    // along the axes. Checked through the index-to-world transform rather
    // than vtkMatrix3x3, which lives in a library the link line lacks.
    double p0[3];
    img->TransformContinuousIndexToPhysicalPoint(0, 0, 0, p0);
    for (int a = 0; a < 3; a++) {
        double e[3] = {0, 0, 0}, pa[3];
        e[a] = 1;
        img->TransformContinuousIndexToPhysicalPoint(e, pa);
        for (int b = 0; b < 3; b++) {
            const double want = b == a ? sp[a] : 0.0;
            if (!close_to(pa[b] - p0[b], want,
                          std::fabs(sp[a]) + std::fabs(p0[b])))
                return st_error_set(err, ST_EINPUT, name, 0,
                                    "image has a rotated direction matrix, "
                                    "which is not supported");
        }
    }
    if (!(sp[0] > 0) || !std::isfinite(sp[0]) ||
        !close_to(sp[1], sp[0], sp[0]) || !close_to(sp[2], sp[0], sp[0]))
        return st_error_set(err, ST_EINPUT, name, 0,
                            "spacing %g %g %g is not uniform and positive",
                            sp[0], sp[1], sp[2]);
    double voxel = sp[0], origin[3];
    for (int a = 0; a < 3; a++)     // the point at the extent's start
        origin[a] = org[a] + sp[a] * ext[2 * a];
    vtkFieldData *fd = img->GetFieldData();
    double fv, fo[3];
    if (field_doubles(fd, "voxel_size", 1, &fv) && close_to(fv, voxel, voxel))
        voxel = fv;
    if (field_doubles(fd, "origin", 3, fo) &&
        close_to(fo[0], origin[0], std::fabs(origin[0]) + voxel) &&
        close_to(fo[1], origin[1], std::fabs(origin[1]) + voxel) &&
        close_to(fo[2], origin[2], std::fabs(origin[2]) + voxel))
        for (int a = 0; a < 3; a++)
            origin[a] = fo[a];
    for (int a = 0; a < 3; a++)
        if (!std::isfinite(origin[a]))
            return st_error_set(err, ST_EINPUT, name, 0,
                                "image origin is not finite");
    g->voxel = voxel;
    for (int a = 0; a < 3; a++)
        g->origin[a] = origin[a];
    return ST_OK;
}

/* The kind, the band and the other metadata, from the field data. */
st_status read_kind_meta(st_grid *g, vtkFieldData *fd, const char *name, st_error *err)
{
    g->kind = ST_GRID_UNKNOWN;
    g->band = INFINITY;
    double band;
    if (field_doubles(fd, "band", 1, &band) && !std::isnan(band))
        g->band = band;
    for (int i = 0; fd && i < fd->GetNumberOfArrays(); i++) {
        vtkStringArray *s =
            vtkStringArray::SafeDownCast(fd->GetAbstractArray(i));
        if (!s || !s->GetName() || s->GetNumberOfValues() < 1)
            continue;
        std::string key = s->GetName();
        const std::string value = s->GetValue(0);
        if (key == "souptet_kind") {
            g->kind = st_grid_kind_from_name(value.c_str());
            continue;
        }
        if (is_reserved_name(key))
            continue;
        if (key.compare(0, std::strlen(kMetaPrefix), kMetaPrefix) == 0)
            key = key.substr(std::strlen(kMetaPrefix));
        if (st_meta_set(&g->meta, key.c_str(), value.c_str()))
            return st_error_set(err, ST_ENOMEM, name, 0, "out of memory");
    }
    return ST_OK;
}

st_status read_with(vtkXMLImageDataReader *r, const char *name,
                    size_t max_bytes, st_grid **out, st_error *err)
{
    st_vtk::Capture cap;
    r->UpdateInformation();
    vtkInformation *info = r->GetOutputInformation(0);
    int ext[6];
    if (st_vtk::failed() || r->GetErrorCode() != vtkErrorCode::NoError ||
        !info || !info->Has(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT()))
        return st_vtk::fail(name, "not a readable VTK ImageData (.vti) file",
                          err);
    info->Get(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), ext);
    long long d[3];
    for (int a = 0; a < 3; a++)
        d[a] = (long long)ext[2 * a + 1] - ext[2 * a] + 1;
    if (d[0] < 1 || d[1] < 1 || d[2] < 1)
        return st_error_set(err, ST_EINPUT, name, 0,
                            "image extent %d..%d %d..%d %d..%d holds no "
                            "points",
                            ext[0], ext[1], ext[2], ext[3], ext[4], ext[5]);
    // Allocate (and check max_bytes) before VTK reads the array: the
    // limit must hold before anything of that size is allocated. VTK then
    // holds its own copy while we convert, so reading a .vti peaks at about
    // twice the dense size (VTK arrays are new[]-allocated; st_grid data
    // is malloc'd and freed with free(), so the array cannot be adopted).
    const double zero[3] = {0, 0, 0};
    st_grid *g = nullptr;
    if (st_status s = st_grid_new(&g, size_t(d[0]), size_t(d[1]),
                                  size_t(d[2]), zero, 1.0, 0.0f, max_bytes,
                                  err)) {
        if (err && !err->file[0])
            std::snprintf(err->file, sizeof err->file, "%s", name);
        return s;
    }
    struct Guard {
        st_grid *g;
        ~Guard() { st_grid_free(g); }
    } guard{g};

    r->Update();
    vtkImageData *img = r->GetOutput();
    if (st_vtk::failed() || r->GetErrorCode() != vtkErrorCode::NoError ||
        !img)
        return st_vtk::fail(name,
                          "cannot read the image data (truncated or "
                          "corrupt file?)",
                          err);
    int *dims = img->GetDimensions();
    if (dims[0] != d[0] || dims[1] != d[1] || dims[2] != d[2])
        return st_error_set(err, ST_EINPUT, name, 0,
                            "image is %dx%dx%d points, its header says "
                            "%lldx%lldx%lld",
                            dims[0], dims[1], dims[2], d[0], d[1], d[2]);
    vtkDataArray *arr = field_array(img);
    if (!arr)
        return st_error_set(err, ST_EINPUT, name, 0,
                            "no scalar point data (one float or double "
                            "component) to read");
    const size_t n = st_grid_count(g);
    if (arr->GetNumberOfTuples() != vtkIdType(n))
        return st_error_set(err, ST_EINPUT, name, 0,
                            "point array '%s' has %lld values for %zu "
                            "points (truncated file?)",
                            arr->GetName() ? arr->GetName() : "",
                            (long long)arr->GetNumberOfTuples(), n);

    if (st_status s = read_placement(g, img, ext, name, err))
        return s;

    // Values.
    if (vtkFloatArray *f = vtkFloatArray::SafeDownCast(arr))
        std::memcpy(g->data, f->GetPointer(0), n * sizeof(float));
    else {
        vtkDoubleArray *dd = vtkDoubleArray::SafeDownCast(arr);
        const double *src = dd->GetPointer(0);
        for (size_t i = 0; i < n; i++)
            g->data[i] = float(src[i]);
    }

    if (st_status s = read_kind_meta(g, img->GetFieldData(), name, err))
        return s;
    guard.g = nullptr;
    *out = g;
    return ST_OK;
}

/* Check a document in memory, then read it with VTK. owned, if not null,
 * is data's malloc'd buffer: it is freed (on every way out) as soon as VTK
 * holds its own copy, so that a file read by path peaks at the two copies
 * VTK makes (its input string and the stream it parses), as a read from
 * memory always did. */
st_status read_mem(st_grid **out, const unsigned char *data, size_t size,
                   const char *name, size_t max_bytes, unsigned char *owned,
                   st_error *err)
{
    struct Owned {
        unsigned char *p;
        ~Owned() { std::free(p); }
    } own{owned};
    *out = nullptr;
    if (size == 0)
        return st_error_set(err, ST_EINPUT, name, 0, "empty input");
    return st_vtk::guarded(name, "reading", err, [&] {
        // VTK trusts the file's structure and sizes; it sees only a
        // document the pre-flight check has passed.
        if (st_status s = st_vtkxml_check(data, size, name, "ImageData",
                                          st_vtkxml_budget(max_bytes),
                                          st_vtkxml_inflate_vtk, nullptr,
                                          err))
            return s;
        vtkNew<vtkXMLImageDataReader> r;
        r->ReadFromInputStringOn();
        r->SetInputString(
            std::string(reinterpret_cast<const char *>(data), size));
        std::free(own.p);
        own.p = nullptr;
        return read_with(r, name, max_bytes, out, err);
    });
}

st_status write_vti(const st_grid *g, const char *path, st_error *err)
{
    if (!g || !g->data)
        return st_error_set(err, ST_EINTERNAL, path, 0, "no grid to write");
    const size_t lim = size_t(std::numeric_limits<int>::max());
    if (g->nx > lim || g->ny > lim || g->nz > lim)
        return st_error_set(err, ST_ELIMIT, path, 0,
                            "grid size %zux%zux%zu does not fit VTK's int "
                            "extents",
                            g->nx, g->ny, g->nz);
    vtkNew<vtkImageData> img;
    img->SetExtent(0, int(g->nx - 1), 0, int(g->ny - 1), 0, int(g->nz - 1));
    img->SetOrigin(g->origin[0], g->origin[1], g->origin[2]);
    img->SetSpacing(g->voxel, g->voxel, g->voxel);

    vtkNew<vtkFloatArray> values;
    values->SetName(st_grid_name_for_kind(g->kind));
    values->SetNumberOfComponents(1);
    // Borrow the grid's array instead of copying it (save = 1: VTK never
    // frees it); the writer only reads.
    values->SetArray(const_cast<float *>(g->data), vtkIdType(st_grid_count(g)),
                     1);
    img->GetPointData()->SetScalars(values);

    vtkFieldData *fd = img->GetFieldData();
    auto add_string = [&](const std::string &n, const char *v) {
        vtkNew<vtkStringArray> s;
        s->SetName(n.c_str());
        s->InsertNextValue(v ? v : "");
        fd->AddArray(s);
    };
    auto add_doubles = [&](const char *n, const double *v, int comps) {
        vtkNew<vtkDoubleArray> a;
        a->SetName(n);
        a->SetNumberOfComponents(comps);
        a->InsertNextTuple(v);
        fd->AddArray(a);
    };
    add_string("souptet_kind", st_grid_kind_name(g->kind));
    add_doubles("band", &g->band, 1);
    add_doubles("origin", g->origin, 3);
    add_doubles("voxel_size", &g->voxel, 1);
    for (size_t i = 0; i < g->meta.count; i++)
        add_string(escape_key(g->meta.entries[i].key),
                   g->meta.entries[i].value);

    st_outfile o;
    if (st_status s = st_outfile_begin(&o, path, 0, err))
        return s;
    // Removes the temporary file on every way out but the commit,
    // exceptions included.
    struct Abort {
        st_outfile *o;
        ~Abort()
        {
            if (o)
                st_outfile_abort(o);
        }
    } abort_tmp{&o};
    vtkNew<vtkXMLImageDataWriter> w;
    w->SetInputData(img);
    w->SetFileName(o.tmp);
    w->SetDataModeToAppended();
    w->EncodeAppendedDataOff();     // raw binary, not base64
    w->SetCompressorTypeToZLib();
    w->SetHeaderTypeToUInt64();
    st_vtk::Capture cap;
    errno = 0;
    const int ok = w->Write();
    const int e = errno;
    if (!ok || st_vtk::failed() ||
        w->GetErrorCode() != vtkErrorCode::NoError) {
        std::string m = st_vtk::message();
        if (m.empty() && e)
            m = std::strerror(e);
        return st_error_set(err, ST_EIO, path, 0, "write failed%s%s",
                            m.empty() ? "" : ": ", m.c_str());
    }
    abort_tmp.o = nullptr;   // commit removes it itself on failure
    return st_outfile_commit(&o, err);
}

} // namespace

extern "C" {

st_status st_grid_write_vti(const st_grid *g, const char *path, st_error *err)
{
    if (st_path_is_stdio(path))
        return st_error_set(err, ST_EINPUT, ST_STDOUT_NAME, 0,
                            "standard output carries OpenVDB streams only; "
                            "write .vti to a file");
    return st_vtk::guarded(path, "writing", err,
                   [&] { return write_vti(g, path, err); });
}

st_status st_gridio_read_vti_mem(st_grid **out, const unsigned char *data,
                                 size_t size, const char *name,
                                 size_t max_bytes, st_error *err)
{
    return read_mem(out, data, size, name, max_bytes, nullptr, err);
}

st_status st_grid_read_vti(st_grid **out, const char *path, size_t max_bytes,
                           st_error *err)
{
    *out = nullptr;
    unsigned char *data;
    size_t size;
    if (st_path_is_stdio(path)) {
        if (st_status s = st_file_read(nullptr, &data, &size, err))
            return s;
        return read_mem(out, data, size, ST_STDIN_NAME, max_bytes,
                        data, err);
    }
    if (st_status s = st_file_check_input(path, err))
        return s;
    // Through memory, so that the bytes checked are the bytes VTK reads.
    if (st_status s = st_file_read(path, &data, &size, err))
        return s;
    return read_mem(out, data, size, path, max_bytes, data, err);
}

} // extern "C"
