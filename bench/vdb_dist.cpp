/*
 * vdb_dist - soupdist's job done with OpenVDB, as a whole process: the
 * peer of `make bench`'s whole-process distance rows (scripts/bench.d/
 * dist.py, scale.py).
 *
 *   vdb_dist MODEL -r N [--band B] [--threads T] -o OUT.vdb
 *
 * Reads the soup MODEL with souptet's reader (the same parser soupdist
 * uses, so reading costs both the same), lays the grid out as `soupdist -r
 * N --band B` does (st_dist_layout: same voxel, origin, dims and padding),
 * runs openvdb::tools::meshToUnsignedDistanceField with a band of B voxels
 * on at most T TBB threads, and writes the grid to OUT.vdb with
 * openvdb::io::File (OpenVDB's default compression, as soupdist's .vdb
 * files). Prints one line on stderr: the read, distance and write times.
 * What a user calling OpenVDB for soupdist's output would write; unlike
 * vdb_udf it reads no reference and links no VTK (--as-needed), so its
 * process start is OpenVDB's and the soup reader's alone.
 *
 * Exit status: 0 ok, 1 failure, 2 usage error.
 */
#include "souptet/dist.h"
#include "souptet/soup.h"

#include <openvdb/openvdb.h>
#include <openvdb/tools/MeshToVolume.h>
#include <tbb/global_control.h>

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <memory>
#include <vector>

namespace {

// Exit with status 2 and the usage line, or 1 and the error record's text.
[[noreturn]] void stop(const st_error *err)
{
    char buf[1200];
    if (err)
        std::fprintf(stderr, "vdb_dist: %s\n", st_error_format(err, buf, sizeof buf));
    else
        std::fputs("usage: vdb_dist MODEL -r N [--band B] [--threads T] -o OUT.vdb\n", stderr);
    std::exit(err ? 1 : 2);
}

// A positive number (-r, --band, --threads), or the usage.
double number_arg(const char *s)
{
    char *end;
    errno = 0;
    const double v = std::strtod(s, &end);
    if (errno != 0 || *end != '\0' || !(v > 0))
        stop(nullptr);
    return v;
}

double now()
{
    return std::chrono::duration<double>(
               std::chrono::steady_clock::now().time_since_epoch())
        .count();
}

} // namespace

int main(int argc, char **argv)
{
    const char *model = nullptr, *out = nullptr;
    double cells = 0, band = ST_DIST_DEFAULT_BAND, threads = 0;
    for (int i = 1; i < argc; i++) {
        if (!std::strcmp(argv[i], "-r") && i + 1 < argc)
            cells = number_arg(argv[++i]);
        else if (!std::strcmp(argv[i], "--band") && i + 1 < argc)
            band = number_arg(argv[++i]);
        else if (!std::strcmp(argv[i], "--threads") && i + 1 < argc)
            threads = number_arg(argv[++i]);
        else if (!std::strcmp(argv[i], "-o") && i + 1 < argc)
            out = argv[++i];
        else if (argv[i][0] == '-' && argv[i][1])
            stop(nullptr);
        else if (!model)
            model = argv[i];
        else
            stop(nullptr);
    }
    if (!model || !out || cells < 1)
        stop(nullptr);

    try {
        const double t0 = now();
        st_error err;
        st_error_clear(&err);
        st_soup *soup = nullptr;
        if (st_soup_read(&soup, model, &err))
            stop(&err);
        st_dist_params dp = st_dist_params_default();
        dp.cells = size_t(cells);
        dp.band = band;
        size_t dims[3];
        double origin[3], voxel;
        if (st_dist_layout(soup, &dp, dims, origin, &voxel, &err))
            stop(&err);
        std::vector<openvdb::Vec3s> points(soup->nverts);
        for (size_t i = 0; i < soup->nverts; i++)
            points[i] = openvdb::Vec3s(float(soup->xyz[3 * i]), float(soup->xyz[3 * i + 1]),
                                       float(soup->xyz[3 * i + 2]));
        std::vector<openvdb::Vec3I> tris(soup->ntris);
        for (size_t i = 0; i < soup->ntris; i++)
            tris[i] = openvdb::Vec3I(soup->tris[3 * i], soup->tris[3 * i + 1],
                                     soup->tris[3 * i + 2]);
        st_soup_free(soup);
        const std::vector<openvdb::Vec4I> quads;

        openvdb::initialize();
        std::unique_ptr<tbb::global_control> limit;
        if (threads > 0)
            limit.reset(new tbb::global_control(
                tbb::global_control::max_allowed_parallelism, size_t(threads)));
        // soupdist's transform: voxel centers at integer index
        // coordinates, index (0,0,0) at the origin.
        openvdb::math::Transform::Ptr xf =
            openvdb::math::Transform::createLinearTransform(voxel);
        xf->postTranslate(openvdb::Vec3d(origin[0], origin[1], origin[2]));
        const double t1 = now();
        openvdb::FloatGrid::Ptr grid =
            openvdb::tools::meshToUnsignedDistanceField<openvdb::FloatGrid>(
                *xf, points, tris, quads, float(band));
        grid->setName("distance");
        const double t2 = now();
        openvdb::io::File file(out);
        file.write({grid});
        file.close();
        const double t3 = now();
        std::fprintf(stderr, "vdb_dist: %zux%zux%zu, read %.3f s, distance %.3f s, "
                             "write %.3f s\n",
                     dims[0], dims[1], dims[2], t1 - t0, t2 - t1, t3 - t2);
        return 0;
    } catch (const std::exception &e) {
        std::fprintf(stderr, "vdb_dist: %s\n", e.what());
    } catch (...) {
        std::fputs("vdb_dist: unknown exception\n", stderr);
    }
    return 1;
}
