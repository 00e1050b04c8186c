/*
 * wrap_vdb.cpp - OpenVDB's volumeToMesh behind a C function (wrap.h).
 * The only translation unit that calls volumeToMesh; OpenVDB headers cost
 * ~13 s and ~860 MB to compile, so nothing else belongs here.
 *
 * The st_grid becomes a FloatGrid in index space (identity transform:
 * voxel (i,j,k) at index (i,j,k), as in gridio_vdb.cpp), so volumeToMesh
 * returns points in voxel units; they are mapped to world coordinates
 * here in double (origin + voxel * p).
 *
 * Values: every voxel of the dense box is copied (background FLT_MAX, a
 * value no field voxel holds, so no voxel is dropped and no leaf turns
 * into a tile), and a one-voxel layer around the box is set, active, to
 * iso + voxel / 2: outside the grid is outside, so a pseudo volume that
 * touches the grid's edge is closed half a voxel beyond it instead of
 * being left open. Beyond that layer the background (FLT_MAX) is outside
 * too and has no crossing with the layer.
 *
 * volumeToMesh does not need openvdb::initialize() (that registers types
 * for file I/O), so this file never calls it and never touches the
 * logger.
 */
#include "souptet/wrap.h"
#include "../base/fpenv.h"
#include "souptet/mem.h"

#include <openvdb/openvdb.h>
#include <openvdb/tools/Dense.h>
#include <openvdb/tools/VolumeToMesh.h>

#include <cfloat>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <limits>
#include <new>
#include <vector>

namespace {

st_status polys_from_grid(st_wrap_polys *out, const st_grid *g, double iso,
                          double adaptivity, st_error *err)
{
    using openvdb::Coord;
    using openvdb::FloatGrid;
    const int nx = int(g->nx), ny = int(g->ny), nz = int(g->nz);
    FloatGrid::Ptr grid = FloatGrid::create(FLT_MAX);
    {
        const openvdb::CoordBBox box(Coord(0, 0, 0),
                                     Coord(nx - 1, ny - 1, nz - 1));
        // copyFromDense only reads the array.
        openvdb::tools::Dense<float, openvdb::tools::LayoutXYZ> dense(
            box, const_cast<float *>(g->data));
        openvdb::tools::copyFromDense(dense, *grid, 0.0f);
    }
    const float shell = float(iso + 0.5 * g->voxel);
    {
        FloatGrid::Accessor acc = grid->getAccessor();
        for (int k = -1; k <= nz; k++)
            for (int j = -1; j <= ny; j++)
                for (int i = -1; i <= nx; i++) {
                    const bool edge = i == -1 || i == nx || j == -1 ||
                                      j == ny || k == -1 || k == nz;
                    if (!edge) {
                        // Skip the interior of a row in one jump.
                        if (i == 0)
                            i = nx - 1;
                        continue;
                    }
                    acc.setValueOn(Coord(i, j, k), shell);
                }
    }
    std::vector<openvdb::Vec3s> points;
    std::vector<openvdb::Vec3I> tris;
    std::vector<openvdb::Vec4I> quads;
    openvdb::tools::volumeToMesh(*grid, points, tris, quads, iso, adaptivity,
                                 true);
    grid.reset();

    if (points.size() >= size_t(UINT32_MAX))
        return st_error_set(err, ST_ELIMIT, NULL, 0,
                            "%zu surface points: more than 32-bit indices "
                            "hold", points.size());
    out->xyz = static_cast<double *>(st_malloc_array(3 * points.size(),
                                                     sizeof(double)));
    out->quads = static_cast<uint32_t *>(st_malloc_array(4 * quads.size(),
                                                         sizeof(uint32_t)));
    out->tris = static_cast<uint32_t *>(st_malloc_array(3 * tris.size(),
                                                        sizeof(uint32_t)));
    if (!out->xyz || !out->quads || !out->tris) {
        st_wrap_polys_clear(out);
        return st_error_set(err, ST_ENOMEM, NULL, 0,
                            "out of memory for %zu surface points",
                            points.size());
    }
    out->npoints = points.size();
    for (size_t i = 0; i < points.size(); i++)
        for (int a = 0; a < 3; a++)
            out->xyz[3 * i + a] =
                g->origin[a] + g->voxel * double(points[i][a]);
    out->nquads = quads.size();
    for (size_t i = 0; i < quads.size(); i++)
        for (int a = 0; a < 4; a++)
            out->quads[4 * i + a] = quads[i][a];
    out->ntris = tris.size();
    for (size_t i = 0; i < tris.size(); i++)
        for (int a = 0; a < 3; a++)
            out->tris[3 * i + a] = tris[i][a];
    return ST_OK;
}

} // namespace

extern "C" st_status st_wrap_polys_vdb(st_wrap_polys *out, const st_grid *g,
                                       double iso, double adaptivity,
                                       st_error *err)
{
    std::memset(out, 0, sizeof *out);
    if (!g || !g->data)
        return st_error_set(err, ST_EINTERNAL, NULL, 0, "no grid to mesh");
    const size_t lim = size_t(std::numeric_limits<int32_t>::max()) - 2;
    if (g->nx > lim || g->ny > lim || g->nz > lim)
        return st_error_set(err, ST_ELIMIT, NULL, 0,
                            "grid size %zux%zux%zu does not fit OpenVDB's "
                            "32-bit coordinates", g->nx, g->ny, g->nz);
    if (!std::isfinite(iso) || !(adaptivity >= 0.0 && adaptivity <= 1.0))
        return st_error_set(err, ST_EINPUT, NULL, 0,
                            "isovalue must be finite and adaptivity in "
                            "[0, 1]");
    try {
        return polys_from_grid(out, g, iso, adaptivity, err);
    } catch (const std::bad_alloc &) {
        st_wrap_polys_clear(out);
        return st_error_set(err, ST_ENOMEM, NULL, 0,
                            "out of memory extracting the surface");
    } catch (const std::exception &e) {
        st_wrap_polys_clear(out);
        return st_error_set(err, ST_EINTERNAL, NULL, 0,
                            "OpenVDB volumeToMesh failed: %s", e.what());
    } catch (...) {
        st_wrap_polys_clear(out);
        return st_error_set(err, ST_EINTERNAL, NULL, 0,
                            "OpenVDB volumeToMesh failed");
    }
}

extern "C" void st_wrap_polys_clear(st_wrap_polys *p)
{
    if (!p)
        return;
    std::free(p->xyz);
    std::free(p->quads);
    std::free(p->tris);
    std::memset(p, 0, sizeof *p);
}
