/*
 * vdb_udf - OpenVDB's unsigned distance field as a peer for `make bench`.
 *
 *   vdb_udf MODEL REFERENCE.vdb [--threads T] [--repeat R]
 *
 * Reads the soup MODEL with souptet's reader and REFERENCE (a distance field
 * made by soupdist: voxel size, origin, dims and band in model units), then
 * runs openvdb::tools::meshToUnsignedDistanceField on exactly the same
 * transform (index (0,0,0) at the reference's origin, its voxel size) and
 * band (band / voxel voxels), R times with at most T TBB threads. Prints one
 * JSON object on stdout: the best wall time (file reading excluded), peak
 * RSS, and how OpenVDB's field compares with the reference at every voxel
 * where either is inside its band: voxels differing by more than 1e-4
 * voxel, the largest overstatement (openvdb - reference) and
 * understatement (reference - openvdb) in voxels, and reference band voxels
 * that OpenVDB leaves outside its band.
 *
 * Peak RSS covers the timed runs only: the reference is read once for its
 * layout and freed, then the kernel's high-water mark is reset (writing 5
 * to /proc/self/clear_refs) and VmHWM read after the runs; the reference
 * is read again for the comparison. "rss_before_mib" is what was resident
 * when the runs began (libraries, the soup). Where the reset is refused,
 * the peak is getrusage's and "peak_rss_reset" is false.
 *
 * Build (from the repository root, after `make BUILD=build-io` made the
 * library; OpenVDB headers take ~13 s and ~860 MB to compile):
 *
 *   mkdir -p build-io/bench && g++ -std=c++17 -O2 -g -Wall -Wextra \
 *     -ffp-contract=off -Iinclude bench/vdb_udf.cpp build-io/libsouptet.a \
 *     -lopenvdb -ltbb -lImath-3_1 -lvtkIOXML-9.1 -lvtkIOXMLParser-9.1 \
 *     -lvtkIOCore-9.1 -lvtkCommonExecutionModel-9.1 \
 *     -lvtkCommonDataModel-9.1 -lvtkCommonCore-9.1 -lvtksys-9.1 \
 *     -lgomp -lpthread -lm -o build-io/bench/vdb_udf
 *
 * (the VTK libraries because st_grid_read can also read .vti, so the
 * library's VTK adapter is linked in.)
 *
 * Exit status: 0 ok, 1 failure, 2 usage error.
 */
#include "souptet/gridio.h"
#include "souptet/soup.h"

#include <openvdb/openvdb.h>
#include <openvdb/tools/MeshToVolume.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <limits>
#include <string>
#include <sys/resource.h>
#include <vector>

namespace {

[[noreturn]] void usage()
{
    std::fprintf(stderr, "usage: vdb_udf MODEL REFERENCE.vdb [--threads T] "
                         "[--repeat R]\n");
    std::exit(2);
}

[[noreturn]] void fail(const st_error &err)
{
    char buf[1200];
    std::fprintf(stderr, "vdb_udf: %s\n",
                 st_error_format(&err, buf, sizeof buf));
    std::exit(1);
}

long positive_arg(const char *s)
{
    char *end;
    errno = 0;
    long v = std::strtol(s, &end, 10);
    if (errno || *end || v < 1)
        usage();
    return v;
}

/* A "Key:   N kB" line of /proc/self/status in MiB, or -1. */
double status_mib(const char *key)
{
    FILE *f = std::fopen("/proc/self/status", "r");
    char line[256];
    double v = -1;
    size_t n = std::strlen(key);
    while (f && std::fgets(line, sizeof line, f))
        if (!std::strncmp(line, key, n) && line[n] == ':') {
            v = std::atof(line + n + 1) / 1024.0;
            break;
        }
    if (f)
        std::fclose(f);
    return v;
}

/* Reset the peak RSS (VmHWM) to the current RSS (Linux >= 4.0). */
bool reset_peak_rss()
{
    FILE *f = std::fopen("/proc/self/clear_refs", "w");
    if (!f)
        return false;
    bool ok = std::fputs("5", f) >= 0;
    return std::fclose(f) == 0 && ok;
}

double peak_rss_mib(bool was_reset)
{
    if (was_reset) {
        double v = status_mib("VmHWM");
        if (v >= 0)
            return v;
    }
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    return double(ru.ru_maxrss) / 1024.0;   // KiB on Linux
}

std::string json_string(const char *s)
{
    std::string out = "\"";
    for (; *s; s++) {
        unsigned char c = (unsigned char)*s;
        if (c == '"' || c == '\\') {
            out += '\\';
            out += char(c);
        } else if (c < 0x20) {
            char buf[8];
            std::snprintf(buf, sizeof buf, "\\u%04x", c);
            out += buf;
        } else {
            out += char(c);
        }
    }
    return out + "\"";
}

} // namespace

int main(int argc, char **argv)
{
    const char *model = nullptr, *ref_path = nullptr;
    long threads = 0, repeat = 1;
    for (int i = 1; i < argc; i++) {
        if (!std::strcmp(argv[i], "--threads") && i + 1 < argc)
            threads = positive_arg(argv[++i]);
        else if (!std::strcmp(argv[i], "--repeat") && i + 1 < argc)
            repeat = positive_arg(argv[++i]);
        else if (argv[i][0] == '-' && argv[i][1])
            usage();
        else if (!model)
            model = argv[i];
        else if (!ref_path)
            ref_path = argv[i];
        else
            usage();
    }
    if (!model || !ref_path)
        usage();

    try {
        openvdb::initialize();
        st_error err;
        st_error_clear(&err);
        st_soup *soup = nullptr;
        if (st_soup_read(&soup, model, &err))
            fail(err);

        // The layout only; the dense reference is read again afterwards so
        // that it does not count in the peak RSS of the computation.
        st_grid *ref = nullptr;
        if (st_grid_read(&ref, ref_path, 0, &err))
            fail(err);
        const size_t nx = ref->nx, ny = ref->ny, nz = ref->nz;
        const double voxel = ref->voxel, band = ref->band;
        const double origin[3] = {ref->origin[0], ref->origin[1],
                                  ref->origin[2]};
        st_grid_free(ref);
        ref = nullptr;
        if (!std::isfinite(band) || !(band > 0)) {
            std::fprintf(stderr, "vdb_udf: %s: the reference has no finite "
                                 "band; OpenVDB computes narrow bands only\n",
                         ref_path);
            return 1;
        }
        const float band_voxels = float(band / voxel);

        // Same transform as souptet's .vdb files: voxel centers at integer
        // index coordinates, index (0,0,0) at the origin.
        openvdb::math::Transform::Ptr xf =
            openvdb::math::Transform::createLinearTransform(voxel);
        xf->postTranslate(openvdb::Vec3d(origin[0], origin[1], origin[2]));

        std::vector<openvdb::Vec3s> points(soup->nverts);
        for (size_t i = 0; i < soup->nverts; i++)
            points[i] = openvdb::Vec3s(float(soup->xyz[3 * i]),
                                       float(soup->xyz[3 * i + 1]),
                                       float(soup->xyz[3 * i + 2]));
        std::vector<openvdb::Vec3I> tris(soup->ntris);
        for (size_t i = 0; i < soup->ntris; i++)
            tris[i] = openvdb::Vec3I(soup->tris[3 * i], soup->tris[3 * i + 1],
                                     soup->tris[3 * i + 2]);
        const std::vector<openvdb::Vec4I> quads;
        const size_t nverts = soup->nverts, ntris = soup->ntris;
        st_soup_free(soup);

        const size_t max_threads = threads > 0
            ? size_t(threads)
            : tbb::global_control::active_value(
                  tbb::global_control::max_allowed_parallelism);
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism,
                                  max_threads);

        const bool was_reset = reset_peak_rss();
        const double rss_before = status_mib("VmRSS");
        std::vector<double> times;
        openvdb::FloatGrid::Ptr grid;
        for (long r = 0; r < repeat; r++) {
            grid.reset();   // free the previous result before timing anew
            const auto t0 = std::chrono::steady_clock::now();
            grid = openvdb::tools::meshToUnsignedDistanceField<
                openvdb::FloatGrid>(*xf, points, tris, quads, band_voxels);
            const auto t1 = std::chrono::steady_clock::now();
            times.push_back(std::chrono::duration<double>(t1 - t0).count());
        }
        const double rss = peak_rss_mib(was_reset);
        const double best = *std::min_element(times.begin(), times.end());

        if (st_grid_read(&ref, ref_path, 0, &err))
            fail(err);
        const float ref_bg = float(band);
        const float ov_bg = grid->background();
        auto acc = grid->getConstAccessor();
        size_t compared = 0, ref_in_band = 0, differ = 0, outside = 0;
        double max_over = 0, max_under = 0;
        for (size_t k = 0; k < nz; k++)
            for (size_t j = 0; j < ny; j++)
                for (size_t i = 0; i < nx; i++) {
                    const float rv = ref->data[st_grid_index(ref, i, j, k)];
                    const openvdb::Coord ijk{int(i), int(j), int(k)};
                    const float ov = acc.getValue(ijk);
                    const bool ov_in = acc.isValueOn(ijk) && ov < ov_bg;
                    const bool ref_in = rv < ref_bg;
                    if (!ref_in && !ov_in)
                        continue;
                    compared++;
                    ref_in_band += ref_in;
                    const double d = (double(ov) - double(rv)) / voxel;
                    if (std::fabs(d) > 1e-4)
                        differ++;
                    max_over = std::max(max_over, d);
                    max_under = std::max(max_under, -d);
                    if (ref_in && !ov_in)
                        outside++;
                }
        st_grid_free(ref);

        std::printf("{\"peer\": \"openvdb\", \"openvdb_version\": \"%s\", "
                    "\"model\": %s, \"reference\": %s, ",
                    openvdb::getLibraryVersionString(),
                    json_string(model).c_str(), json_string(ref_path).c_str());
        std::printf("\"vertices\": %zu, \"triangles\": %zu, "
                    "\"dims\": [%zu, %zu, %zu], \"voxel\": %.17g, "
                    "\"band\": %.17g, \"band_voxels\": %.9g, ",
                    nverts, ntris, nx, ny, nz, voxel, band,
                    double(band_voxels));
        std::printf("\"threads\": %zu, \"repeat\": %ld, \"times_s\": [",
                    max_threads, repeat);
        for (size_t i = 0; i < times.size(); i++)
            std::printf("%s%.6f", i ? ", " : "", times[i]);
        std::printf("], \"best_s\": %.6f, \"rss_before_mib\": %.1f, "
                    "\"peak_rss_mib\": %.1f, \"peak_rss_reset\": %s, ",
                    best, rss_before, rss, was_reset ? "true" : "false");
        std::printf("\"openvdb_active_voxels\": %llu, "
                    "\"compared_voxels\": %zu, \"reference_band_voxels\": "
                    "%zu, \"differ_over_1e-4_voxel\": %zu, "
                    "\"max_over_voxels\": %.6g, \"max_under_voxels\": %.6g, "
                    "\"reference_band_outside_openvdb_band\": %zu}\n",
                    (unsigned long long)grid->activeVoxelCount(), compared,
                    ref_in_band, differ, max_over, max_under, outside);
        return std::fflush(stdout) == 0 ? 0 : 1;
    } catch (const std::exception &e) {
        std::fprintf(stderr, "vdb_udf: %s\n", e.what());
        return 1;
    } catch (...) {
        std::fprintf(stderr, "vdb_udf: unknown exception\n");
        return 1;
    }
}
