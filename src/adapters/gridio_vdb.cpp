/*
 * gridio_vdb.cpp - st_grid <-> OpenVDB (.vdb files and VDB streams on
 * pipes). The only translation unit that includes OpenVDB headers (one
 * takes ~13 s and ~860 MB to compile: keep it that way).
 *
 * Mapping (writing; reading inverts it):
 *
 *   grid       one openvdb::FloatGrid named st_grid_name_for_kind(kind):
 *              "distance", "sdf" or "field"; creator "souptet VERSION".
 *   voxels     st_grid voxel (i,j,k) = VDB index coordinate (i,j,k); the
 *              dense box is (0,0,0)..(nx-1,ny-1,nz-1).
 *   transform  linear: uniform scale g->voxel, then a translation by
 *              g->origin, so index (0,0,0) - a voxel center, OpenVDB's
 *              convention - lands on g->origin exactly (both are stored as
 *              doubles in the map, no rounding).
 *   background finite band: (float)g->band. Every voxel whose value is
 *              exactly +background or -background is stored INACTIVE with
 *              its value (so the sign of the clamped outside of a signed
 *              field survives); all other voxels are active. This is
 *              OpenVDB's own narrow-band level-set convention (inactive
 *              values are +-background), so a banded field costs only its
 *              band, and the writer's mask compression stores the sign of
 *              inactive values in one bit. Constant regions collapse into
 *              tiles (prune with tolerance 0, exact).
 *              band = INFINITY (or not representable as a float): every
 *              voxel is active and the background is FLT_MAX ("far"); a
 *              finite number, not +inf, because OpenVDB's tolerance
 *              comparisons compute a - b, which is NaN for inf - inf.
 *   class      GRID_LEVEL_SET for a signed field with a finite band (it is
 *              one: world-unit distances, negative inside, +-background
 *              outside the band), so other VDB tools treat it as an SDF;
 *              GRID_UNKNOWN otherwise (an unsigned distance field is not a
 *              level set, OpenVDB's meshToUnsignedDistanceField uses
 *              GRID_UNKNOWN too).
 *   metadata   souptet_kind (string, st_grid_kind_name), voxel_size
 *              (double), origin (vec3d), dims (vec3i), band (double; +inf
 *              is stored as is: DoubleMetadata is the raw 8 bytes),
 *              souptet_meta_order (string: the st_meta keys joined by '\n',
 *              because VDB metadata is a sorted map and st_meta an ordered
 *              list), and every st_meta entry as string metadata under its
 *              own key. A key that is empty, starts with "souptet_meta:",
 *              or collides with a name above or with one OpenVDB puts on
 *              grids (name, class, creator, file_bbox_min, ...) is stored
 *              as "souptet_meta:" + key.
 *
 * Reading takes the first FloatGrid of the file or stream, preferring one
 * named "distance" or "sdf"; other grid types are refused. A grid with
 * souptet metadata gets dims, band and kind from it; a foreign grid gets
 * its active voxel bounding box as the dense box, kind SIGNED with band =
 * background if it is a level set, else kind UNKNOWN with band = INFINITY.
 * Origin and voxel size always come from the transform (a uniform scale
 * and a translation, else refused): for our files it holds the very
 * doubles of the origin/voxel_size metadata, and unlike them it is what
 * other tools update when they move a grid. Inactive voxels inside the
 * box read as their stored values (background or -background). Metadata
 * that is not one of the reserved names becomes st_meta entries.
 *
 * Files and streams: a file is written in OpenVDB's file format (grid
 * offsets, default compression: Blosc if built in, else zlib); stdout gets
 * the stream format (see ST_VDB_STREAM_COMPRESSION below). Both are read through
 * one sequential io::Stream reader, which accepts either format, so a
 * .vdb file's bytes on stdin work too. Input streams have exceptions
 * enabled: OpenVDB does not check its reads, and a truncated file would
 * otherwise yield garbage or a half-filled grid without an error.
 *
 * Every extern "C" function catches all exceptions; the library never
 * prints (OpenVDB's log4cplus logger is turned off at initialisation, see
 * init_openvdb).
 */
#include "souptet/gridio.h"
#include "../base/fpenv.h"
#include "souptet/meta.h"
#include "souptet/outfile.h"
#include "gridio_internal.h"
#include "../base/fileio.h"

#include <openvdb/openvdb.h>
#include <openvdb/io/Stream.h>
#include <openvdb/tools/Dense.h>
#include <openvdb/tools/LevelSetSphere.h>
#include <openvdb/tools/Prune.h>

#include <array>
#include <cerrno>
#include <cstdarg>
#include <cstdint>
#include <cfloat>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iostream>
#include <istream>
#include <limits>
#include <memory>
#include <new>
#include <ostream>
#include <set>
#include <sstream>
#include <streambuf>
#include <string>
#include <dlfcn.h>
#include <fcntl.h>
#include <sys/mman.h>
#include <unistd.h>
#include <sys/stat.h>
#include <vector>

#ifndef SOUPTET_VERSION
#define SOUPTET_VERSION "unknown"
#endif

/*
 * Compression of the VDB stream on stdout. Measured on this machine (2
 * cores, shared: load ~2.5) with the unsigned distance field of
 * corpus/bunny.obj at 256 cells (266x260x205 voxels, 56.7 MB dense), band
 * 3 voxels (6.2 % of the voxels in the band), the whole st_grid_write("-")
 * into a pipe to `sh -c 'cat >/dev/null'` and st_grid_read("-") from a
 * pipe fed by cat, best of 12 (all three with the active-mask encoding):
 *
 *   none    4 110 398 bytes   write 0.147 s   read 0.232 s
 *   zip     3 964 164 bytes   write 0.453 s   read 0.262 s
 *   blosc   3 781 288 bytes   write 0.171 s   read 0.241 s
 *
 * Distances are noisy floats: a compressor saves 8 % at best, and a pipe
 * moves 4 MB in about a millisecond. So: no compression on the stream
 * (the active mask alone already makes it sparse), the fastest on both
 * ends. Files keep OpenVDB's default (Blosc), where bytes on disk count.
 * (Overridable at compile time only to repeat this measurement.)
 */
#ifndef ST_VDB_STREAM_COMPRESSION
#define ST_VDB_STREAM_COMPRESSION (openvdb::io::COMPRESS_ACTIVE_MASK)
#endif

namespace {

using openvdb::FloatGrid;
using openvdb::GridBase;

const char *const kMetaPrefix = "souptet_meta:";
const char *const kMetaOrder = "souptet_meta_order";

void init_openvdb()
{
    // A function-local static is initialised exactly once, thread-safely.
    static const bool done = [] {
        openvdb::initialize();
        // Debian's libopenvdb logs through log4cplus, and initialize()
        // attaches a console appender that writes WARN lines (such as
        // "unsupported VDB file format" for a newer file version) to
        // *stdout*, where they would corrupt a VDB stream a tool writes.
        // The library must not print: turn OpenVDB's logger off. Through
        // log4cplus's C API looked up at run time, because the headers
        // compile logging out (no OPENVDB_USE_LOG4CPLUS) and the link line
        // has no -llog4cplus; a libopenvdb without log4cplus has no such
        // symbol and needs nothing. After the first initialize(), later
        // calls return early, so the setting sticks.
        using configure_fn = int (*)(const char *);
        if (void *sym = dlsym(RTLD_DEFAULT, "log4cplus_str_configure"))
            reinterpret_cast<configure_fn>(sym)(
                "log4cplus.logger.openvdb=OFF\n");
        return true;
    }();
    (void)done;
}

/* Metadata names that are not st_meta entries: ours and OpenVDB's. */
bool is_reserved_name(const std::string &name)
{
    static const std::set<std::string> reserved = {
        "souptet_kind", "voxel_size", "origin", "dims", "band", kMetaOrder,
        GridBase::META_GRID_CLASS, GridBase::META_GRID_CREATOR,
        GridBase::META_GRID_NAME, GridBase::META_SAVE_HALF_FLOAT,
        GridBase::META_IS_LOCAL_SPACE, GridBase::META_VECTOR_TYPE,
        GridBase::META_FILE_BBOX_MIN, GridBase::META_FILE_BBOX_MAX,
        GridBase::META_FILE_COMPRESSION, GridBase::META_FILE_MEM_BYTES,
        GridBase::META_FILE_VOXEL_COUNT, GridBase::META_FILE_DELAYED_LOAD};
    return reserved.count(name) != 0;
}

std::string escape_key(const std::string &key)
{
    if (key.empty() || is_reserved_name(key) ||
        key.compare(0, std::strlen(kMetaPrefix), kMetaPrefix) == 0)
        return kMetaPrefix + key;
    return key;
}

/* The st_meta key a VDB metadata name stands for; false if reserved. */
bool unescape_key(const std::string &name, std::string &key)
{
    size_t n = std::strlen(kMetaPrefix);
    if (name.compare(0, n, kMetaPrefix) == 0) {
        key = name.substr(n);
        return true;
    }
    if (is_reserved_name(name))
        return false;
    key = name;
    return true;
}

/* Archive::write(ostream, ..., seekable) is protected; io::File and
 * io::Stream wrap it but open the file themselves (File::write never
 * checks the stream after writing, so a full disk would go unnoticed) or
 * write the stream format. This exposes it for a stream we own. */
class Writer : public openvdb::io::Archive {
public:
    void put(std::ostream &os, const openvdb::GridCPtrVec &grids,
             bool seekable) const
    {
        openvdb::io::Archive::write(os, grids, seekable, openvdb::MetaMap());
    }
};

/* A read-only streambuf over a caller's buffer (no copy). istream::read
 * past its end sets eof|fail, which the reader turns into an exception. */
class MemBuf : public std::streambuf {
public:
    MemBuf(const unsigned char *p, size_t n)
    {
        char *b = const_cast<char *>(reinterpret_cast<const char *>(p));
        setg(b, b, b + n);
    }

protected:
    pos_type seekoff(off_type off, std::ios_base::seekdir dir,
                     std::ios_base::openmode which) override
    {
        if (!(which & std::ios_base::in))
            return pos_type(off_type(-1));
        off_type base = dir == std::ios_base::beg   ? 0
                        : dir == std::ios_base::cur ? off_type(gptr() - eback())
                                                    : off_type(egptr() - eback());
        off_type pos = base + off;
        if (pos < 0 || pos > off_type(egptr() - eback()))
            return pos_type(off_type(-1));
        setg(eback(), eback() + pos, egptr());
        return pos_type(pos);
    }
    pos_type seekpos(pos_type pos, std::ios_base::openmode which) override
    {
        return seekoff(off_type(pos), std::ios_base::beg, which);
    }
};

st_status copy_meta_in(st_grid *g, const std::string &key,
                       const std::string &value, const char *name,
                       st_error *err)
{
    if (st_meta_set(&g->meta, key.c_str(), value.c_str()))
        return st_error_set(err, ST_ENOMEM, name, 0, "out of memory");
    return ST_OK;
}

/* Metadata -> st_meta, in the order recorded by the writer, then the rest
 * (sorted, as the map holds them). */
st_status import_meta(st_grid *g, const FloatGrid &grid, const char *name,
                      st_error *err)
{
    std::vector<std::pair<std::string, std::string>> items;
    for (auto it = grid.beginMeta(); it != grid.endMeta(); ++it) {
        std::string key;
        if (!it->second || !unescape_key(it->first, key))
            continue;
        // Strings as they are; a foreign file's numbers etc. as text.
        std::string value =
            it->second->typeName() == openvdb::StringMetadata::staticTypeName()
                ? static_cast<const openvdb::StringMetadata &>(*it->second)
                      .value()
                : it->second->str();
        items.emplace_back(key, value);
    }
    std::vector<bool> done(items.size(), false);
    if (auto order = grid.getMetadata<openvdb::StringMetadata>(kMetaOrder)) {
        const std::string &s = order->value();
        size_t start = 0;
        while (start <= s.size() && !s.empty()) {
            size_t end = s.find('\n', start);
            if (end == std::string::npos)
                end = s.size();
            std::string key = s.substr(start, end - start);
            for (size_t i = 0; i < items.size(); i++)
                if (!done[i] && items[i].first == key) {
                    if (st_status st = copy_meta_in(g, key, items[i].second,
                                                    name, err))
                        return st;
                    done[i] = true;
                    break;
                }
            start = end + 1;
        }
    }
    for (size_t i = 0; i < items.size(); i++)
        if (!done[i])
            if (st_status st = copy_meta_in(g, items[i].first,
                                            items[i].second, name, err))
                return st;
    return ST_OK;
}

/* Fill in the file name of an error raised without one (st_grid_new). */
st_status name_error(st_error *err, st_status s, const char *name)
{
    if (err && err->file[0] == '\0')
        std::snprintf(err->file, sizeof err->file, "%s", name);
    return s;
}

FloatGrid::Ptr pick_grid(const openvdb::GridPtrVec &grids, std::string &seen)
{
    FloatGrid::Ptr first;
    for (const auto &base : grids) {
        if (!base)
            continue;
        if (!seen.empty())
            seen += ", ";
        seen += base->valueType() + " grid '" + base->getName() + "'";
        FloatGrid::Ptr f = openvdb::gridPtrCast<FloatGrid>(base);
        if (!f)
            continue;
        if (f->getName() == "distance" || f->getName() == "sdf")
            return f;
        if (!first)
            first = f;
    }
    return first;
}

/* Origin (the world position of index `at`) and voxel size from a grid's
 * transform, which must be a uniform scale and a translation. For the
 * maps we write these are the stored doubles exactly: indexToWorld(0) is
 * 0 * scale + translation, voxelSize() the scale itself. */
st_status transform_layout(const FloatGrid &grid, const openvdb::Coord &at,
                           const char *name, double origin[3], double *voxel,
                           st_error *err)
{
    const openvdb::math::Transform &xf = grid.constTransform();
    // The images of the index axes must be axis-aligned, of equal length.
    bool ok = xf.isLinear();
    const openvdb::Vec3d vs = ok ? xf.voxelSize() : openvdb::Vec3d(0, 0, 0);
    const double v = vs[0];
    const openvdb::Vec3d o = xf.indexToWorld(openvdb::Vec3d(0, 0, 0));
    for (int a = 0; ok && a < 3; a++) {
        openvdb::Vec3d e(0, 0, 0);
        e[a] = 1;
        const openvdb::Vec3d d = xf.indexToWorld(e) - o;
        for (int b = 0; b < 3; b++) {
            const double want = b == a ? v : 0.0;
            // Differences of world positions round: compare loosely.
            if (!(std::fabs(d[b] - want) <= 1e-9 * (std::fabs(v) +
                                                    std::fabs(o[b]))))
                ok = false;
        }
    }
    if (!ok || !(v > 0) || !std::isfinite(v))
        return st_error_set(err, ST_EINPUT, name, 0,
                            "grid '%s': the transform is not a uniform "
                            "scale and a translation (rotated, sheared, "
                            "frustum or non-uniform voxels are not "
                            "supported)",
                            grid.getName().c_str());
    const openvdb::Vec3d w = xf.indexToWorld(at);
    for (int a = 0; a < 3; a++)
        origin[a] = w[a];
    *voxel = v;
    return ST_OK;
}

/* A FloatGrid -> a new st_grid. */
st_status grid_to_st(st_grid **out, const FloatGrid &grid, const char *name,
                     size_t max_bytes, st_error *err)
{
    openvdb::CoordBBox box;
    double origin[3] = {0, 0, 0}, voxel = 0, band = INFINITY;
    st_grid_kind kind = ST_GRID_UNKNOWN;

    // Origin and voxel size come from the transform even for our own
    // grids: it holds the same doubles as the origin/voxel_size metadata
    // (those are informative copies for people reading metadata), and it
    // is what every other VDB tool moves, so metadata a tool carried
    // along unchanged cannot put the field in the wrong place.
    auto kmeta = grid.getMetadata<openvdb::StringMetadata>("souptet_kind");
    auto dmeta = grid.getMetadata<openvdb::Vec3IMetadata>("dims");
    auto bmeta = grid.getMetadata<openvdb::DoubleMetadata>("band");
    if (kmeta && dmeta && bmeta) {
        const openvdb::Vec3i d = dmeta->value();
        if (d[0] < 1 || d[1] < 1 || d[2] < 1)
            return st_error_set(err, ST_EINPUT, name, 0,
                                "grid '%s': dims %dx%dx%d in the metadata "
                                "are not positive",
                                grid.getName().c_str(), d[0], d[1], d[2]);
        box = openvdb::CoordBBox(openvdb::Coord(0, 0, 0),
                                 openvdb::Coord(d[0] - 1, d[1] - 1, d[2] - 1));
        // An active voxel outside the recorded box means the grid was
        // changed by a tool that kept our metadata: refuse rather than
        // silently cut it off.
        const openvdb::CoordBBox active = grid.evalActiveVoxelBoundingBox();
        if (!active.empty() && !box.isInside(active))
            return st_error_set(err, ST_EINPUT, name, 0,
                                "grid '%s' has active voxels outside the "
                                "%dx%dx%d box its metadata records",
                                grid.getName().c_str(), d[0], d[1], d[2]);
        band = bmeta->value();
        if (std::isnan(band))
            return st_error_set(err, ST_EINPUT, name, 0,
                                "grid '%s': band in the metadata is NaN",
                                grid.getName().c_str());
        kind = st_grid_kind_from_name(kmeta->value().c_str());
    } else {
        // A foreign grid: the dense box is its active voxel bounding box.
        box = grid.evalActiveVoxelBoundingBox();
        if (box.empty())
            return st_error_set(err, ST_EINPUT, name, 0,
                                "grid '%s' has no active voxels",
                                grid.getName().c_str());
        if (grid.getGridClass() == openvdb::GRID_LEVEL_SET) {
            kind = ST_GRID_SIGNED;
            band = grid.background();
        }
    }
    if (st_status s = transform_layout(grid, box.min(), name, origin, &voxel,
                                       err))
        return s;

    const openvdb::Coord dim = box.dim();
    st_grid *g = nullptr;
    // st_grid_new checks max_bytes before allocating anything.
    st_status s = st_grid_new(&g, size_t(dim[0]), size_t(dim[1]),
                              size_t(dim[2]), origin, voxel,
                              grid.background(), max_bytes, err);
    if (s)
        return name_error(err, s, name);
    try {
        openvdb::tools::Dense<float, openvdb::tools::LayoutXYZ> dense(box,
                                                                      g->data);
        openvdb::tools::copyToDense(grid, dense);
        g->kind = kind;
        g->band = band;
        if ((s = import_meta(g, grid, name, err))) {
            st_grid_free(g);
            return s;
        }
    } catch (...) {
        st_grid_free(g);
        throw;
    }
    *out = g;
    return ST_OK;
}

/* Before OpenVDB reads a byte: its reader sizes std::strings by 32-bit
 * lengths in the file and zero-fills them before reading (MetaMap::
 * readMeta, readString), so a 3 KB file could make it touch 4 GiB per
 * string. Walk the parts of the format laid out by length prefixes — the
 * header, the file's metadata, and each grid's descriptor and metadata
 * (the next grid found by its end offset when the file has offsets) —
 * and refuse a length or count that the bytes after it cannot hold. The
 * tree itself is OpenVDB's to read: its sizes are fixed by the node
 * types, and its compressed blocks are allocated but only filled from the
 * bytes present. Only file versions 221..224 are walked (what OpenVDB 10
 * reads); anything else goes straight to OpenVDB, which refuses it. */
class VdbWalk {
public:
    VdbWalk(const unsigned char *data, uint64_t size, const char *name,
            st_error *err)
        : data_(data), size_(size), name_(name), err_(err) {}

    st_status run()
    {
        int64_t magic;
        uint32_t version;
        if (!get(&magic, 8) || !get(&version, 4))
            return ST_OK;   /* OpenVDB says what is wrong */
        if (magic != 0x56444220)
            return ST_OK;   /* OpenVDB says it is not a VDB file */
        /* Older formats take other paths through OpenVDB (a root node's
         * table sized by the file's index range), a newer one is not this
         * OpenVDB's to read (it read on past a metadata length it zero-
         * fills, 1.7 GB in 10 s: a make fuzz timeout): neither is walked,
         * so neither is read. */
        if (version < 221 || version > 224)
            return st_error_set_offset(err_, ST_EINPUT, name_, 8,
                                       "OpenVDB file format version %lu: souptet reads "
                                       "versions 221 to 224", (unsigned long)version);
        version_ = version;
        unsigned char offsets = 0;
        if (!skip(8) || !get(&offsets, 1) || !skip(36))
            return ST_OK;
        if (st_status st = meta_map("the file's metadata"))
            return st;
        int32_t ngrids;
        if (!get(&ngrids, 4))
            return ST_OK;
        if (ngrids < 0 || uint64_t(ngrids) > left() / 8)
            return fail("the header says %ld grids, more than the %llu bytes "
                        "left can hold", long(ngrids),
                        (unsigned long long)left());
        for (int32_t g = 0; g < ngrids; g++) {
            std::string type, parent;
            if (st_status st = block("a grid descriptor's name"))
                return st;
            if (st_status st = block("a grid descriptor's type", &type))
                return st;
            if (st_status st = block("a grid descriptor's parent", &parent))
                return st;
            int64_t grid_pos, block_pos, end_pos;
            if (!get(&grid_pos, 8) || !get(&block_pos, 8) || !get(&end_pos, 8)
                || !get(&compression_, 4))   /* the grid's compression flags */
                return ST_OK;
            if (st_status st = meta_map("a grid's metadata"))
                return st;
            /* An instance shares another grid's tree: OpenVDB reads none
             * for it and takes the rest on trust; souptet writes none. */
            if (!parent.empty())
                return fail("grid %ld is an instance of another grid's tree (souptet "
                            "reads grids with trees of their own)", long(g));
            /* A float tree (as saved in full or as half floats) is walked
             * through: its transform, topology and buffers; an instance
             * has none of its own. Another type is OpenVDB's alone. */
            half_ = type == "Tree_float_5_4_3_HalfFloat";
            if (version_ >= 222 &&
                (type == "Tree_float_5_4_3" || half_)) {
                bool walked = false;
                if (st_status st = float_grid(&walked))
                    return st;
                if (!walked)
                    break;
                if (offsets && end_pos != int64_t(pos_))
                    return fail("a grid ends at byte %llu, not at the %lld its "
                                "descriptor gives", (unsigned long long)pos_,
                                (long long)end_pos);
                continue;
            }
            if (!offsets || end_pos <= int64_t(pos_) || uint64_t(end_pos) > size_)
                break;   /* the tree follows: OpenVDB's to read */
            pos_ = uint64_t(end_pos);
        }
        return ST_OK;
    }

private:
    const unsigned char *data_;
    uint64_t size_, pos_ = 0;
    const char *name_;
    st_error *err_;
    uint32_t version_ = 0, compression_ = 0;
    bool half_ = false;
    uint64_t leaves_ = 0;

    /* What OpenVDB 10 reads of a FloatGrid after its metadata
     * (Archive::readGrid), checked before it allocates or reads anything
     * by a count in the file: the transform (a linear map: what souptet
     * reads), one buffer, the root's tiles (their active flag a bool: 0
     * or 1) and children at distinct origins, each internal node's masks
     * and values, the leaves' masks, then every leaf's buffer; every
     * compressed block's size within the bytes left (OpenVDB allocates
     * it first). *walked = false where this cannot follow (an unknown
     * map type: OpenVDB says what is wrong). */
    st_status float_grid(bool *walked)
    {
        std::string map;
        if (st_status st = block("the transform's type", &map))
            return st;
        uint64_t n = map == "AffineMap" || map == "UnitaryMap" ? 128
                     : map == "ScaleMap" || map == "UniformScaleMap" ? 120
                     : map == "TranslationMap" ? 24
                     : map == "ScaleTranslateMap" || map == "UniformScaleTranslateMap" ? 144
                     : 0;
        if (n == 0) {
            if (map == "NonlinearFrustumMap")
                return fail("the grid's transform is a frustum: souptet reads linear "
                            "transforms (a uniform scale and a translation)");
            return ST_OK;
        }
        int32_t buffers;
        float background;
        uint32_t tiles, children;
        if (!skip(n) || !get(&buffers, 4) || !get(&background, 4) || !get(&tiles, 4) ||
            !get(&children, 4))
            return fail("the grid's tree is cut short");
        if (buffers != 1)
            return fail("the tree has %ld buffers (OpenVDB reads one)", long(buffers));
        if (tiles > left() / 17 || children > left() / (12 + 2 * 4096))
            return fail("the root claims %lu tiles and %lu children, more than the "
                        "%llu bytes left can hold", (unsigned long)tiles,
                        (unsigned long)children, (unsigned long long)left());
        std::set<std::array<int32_t, 3>> origins;
        for (uint32_t i = 0; i < tiles + children; i++) {
            std::array<int32_t, 3> o;
            if (!get(o.data(), 12))
                return fail("the grid's tree is cut short");
            if (!origins.insert(o).second)
                return fail("two root entries at (%ld, %ld, %ld)", long(o[0]), long(o[1]),
                            long(o[2]));
            if (i < tiles) {
                unsigned char active;
                if (!skip(4) || !get(&active, 1))
                    return fail("the grid's tree is cut short");
                if (active > 1)
                    return fail("a root tile's active flag is %u, not 0 or 1",
                                unsigned(active));
            } else if (st_status st = internal(5))
                return st;
        }
        for (uint64_t i = 0; i < leaves_; i++) {
            std::vector<uint64_t> mask(8);
            if (!get(mask.data(), 64))
                return fail("a leaf's buffer is cut short");
            if (st_status st = values(mask, 512))
                return st;
        }
        *walked = true;
        return ST_OK;
    }

    /* An internal node of 2^(3 log2dim) entries (5: 32768, 4: 4096) and
     * its children (log2dim 4, then the leaves' masks). */
    st_status internal(int log2dim)
    {
        const uint64_t entries = uint64_t(1) << (3 * log2dim), words = entries / 64;
        std::vector<uint64_t> child(words), value(words);
        if (!get(child.data(), words * 8) || !get(value.data(), words * 8))
            return fail("an internal node is cut short");
        if (st_status st = values(value, entries))
            return st;
        uint64_t nchild = 0;
        for (uint64_t w : child)
            nchild += uint64_t(__builtin_popcountll(w));
        if (log2dim == 4) {
            if (nchild > left() / 64)
                return fail("a node claims %llu leaves, more than the bytes left hold",
                            (unsigned long long)nchild);
            leaves_ += nchild;
            return skip(nchild * 64) ? ST_OK : fail("a leaf's mask is cut short");
        }
        if (nchild > left() / (2 * 512))
            return fail("a node claims %llu children, more than the bytes left hold",
                        (unsigned long long)nchild);
        for (uint64_t i = 0; i < nchild; i++)
            if (st_status st = internal(4))
                return st;
        return ST_OK;
    }

    /* io::readCompressedValues of `entries` values whose value mask is
     * `mask` (the grid's compression flags). */
    st_status values(const std::vector<uint64_t> &mask, uint64_t entries)
    {
        int8_t meta;
        if (!get(&meta, 1))
            return fail("a node's values are cut short");
        if (meta == 2 || meta == 4 || meta == 5)
            if (!skip(meta == 5 ? 8 : 4))
                return fail("a node's values are cut short");
        if (meta == 3 || meta == 4 || meta == 5)
            if (!skip(entries / 8))
                return fail("a node's selection mask is cut short");
        uint64_t count = entries;
        if ((compression_ & 0x2) && meta != 6) {
            count = 0;
            for (uint64_t w : mask)
                count += uint64_t(__builtin_popcountll(w));
        }
        const uint64_t bytes = count * (half_ ? 2 : 4);
        if (!(compression_ & 0x5))
            return skip(bytes) ? ST_OK : fail("a node's values are cut short");
        int64_t packed;
        if (!get(&packed, 8))
            return fail("a node's values are cut short");
        if (packed <= 0 && uint64_t(-(packed + 1)) + 1 != bytes)
            return fail("an uncompressed block of %lld bytes where %llu are due",
                        -(long long)packed, (unsigned long long)bytes);
        uint64_t len = packed <= 0 ? bytes : uint64_t(packed);
        if (len > left())
            return fail("a compressed block claims %llu bytes but %llu remain",
                        (unsigned long long)len, (unsigned long long)left());
        pos_ += len;
        return ST_OK;
    }

    uint64_t left() const { return size_ - pos_; }
    bool get(void *dst, size_t n)
    {
        if (left() < n)
            return false;
        std::memcpy(dst, data_ + pos_, n);
        pos_ += n;
        return true;
    }
    bool skip(uint64_t n)
    {
        if (left() < n)
            return false;
        pos_ += n;
        return true;
    }
    __attribute__((format(printf, 2, 3)))
    st_status fail(const char *fmt, ...)
    {
        char what[256];
        va_list ap;
        va_start(ap, fmt);
        std::vsnprintf(what, sizeof what, fmt, ap);
        va_end(ap);
        return st_error_set_offset(err_, ST_EINPUT, name_, pos_,
                                   "not a valid OpenVDB file (truncated or corrupt): %s",
                                   what);
    }
    /* One length-prefixed block (a string or a metadata value), into
     * *text when given. */
    st_status block(const char *what, std::string *text = nullptr)
    {
        uint32_t n;
        if (!get(&n, 4))
            return ST_OK;
        if (n > left())
            return fail("%s claims %lu bytes but %llu remain", what,
                        (unsigned long)n, (unsigned long long)left());
        if (text)
            text->assign(reinterpret_cast<const char *>(data_ + pos_), n);
        pos_ += n;
        return ST_OK;
    }
    /* A MetaMap: a count, then name, type name and value, each a block. */
    st_status meta_map(const char *what)
    {
        int32_t count;
        if (!get(&count, 4))
            return ST_OK;
        if (count < 0 || uint64_t(count) > left() / 12)
            return fail("%s claims %ld entries, more than the %llu bytes "
                        "left can hold", what, long(count),
                        (unsigned long long)left());
        for (int32_t i = 0; i < count; i++) {
            std::string key, type;
            if (st_status st = block(what, &key))
                return st;
            if (st_status st = block(what, &type))
                return st;
            if (type == "__delayedload") {
                if (st_status st = delayed_load())
                    return st;
                continue;
            }
            const uint64_t at = pos_;
            if (st_status st = block(what))
                return st;
            /* A value of a fixed-size type is read by its type's size,
             * whatever its length says: another length would put OpenVDB
             * out of step with the walk (and on to a 1.7 GB string). */
            const uint64_t want = fixed_size(type), got = pos_ - at - 4;
            if (want && pos_ >= at + 4 && got != want)
                return fail("%s: '%.40s' is a %.20s of %llu bytes, not %llu", what,
                            key.c_str(), type.c_str(), (unsigned long long)got,
                            (unsigned long long)want);
        }
        return ST_OK;
    }
    /* OpenVDB's delayed-load metadata (io::DelayedLoadMetadata::readValue,
     * type "__delayedload"): a leaf count, then a one-byte mask and an
     * 8-byte compressed size per leaf, each array stored raw or as one
     * blosc block (a 4-byte length first; the sizes' length 0xffffffff:
     * no sizes). OpenVDB sizes its arrays by the count and by the
     * uncompressed size in each blosc header, and allocates each block by
     * its length, all before it reads them: a 3 KB file asked for 2.6 GB.
     * So: every byte it reads lies within the value's length, the count is
     * at most one leaf per 64 bytes of the file (a leaf's value mask, in
     * every tree OpenVDB reads), and a blosc header gives the array's own
     * size and its block's length. souptet reads without delayed loading,
     * so the arrays themselves are not used. */
    st_status delayed_load()
    {
        const char *what = "the grid's delayed-load metadata";
        uint32_t n;
        if (!get(&n, 4))
            return ST_OK;
        if (n > left())
            return fail("%s claims %lu bytes but %llu remain", what, (unsigned long)n,
                        (unsigned long long)left());
        const uint64_t end = pos_ + n;
        if (n == 0)
            return ST_OK;   /* OpenVDB reads nothing */
        uint32_t count;
        if (end - pos_ < 4 || !get(&count, 4))
            return fail("%s is cut short", what);
        if (count > size_ / 64)
            return fail("%s claims %lu leaves, more than a file of %llu bytes holds "
                        "(64 bytes a leaf at least)", what, (unsigned long)count,
                        (unsigned long long)size_);
        for (int array = 0; array < 2; array++) {
            const uint64_t elem = array == 0 ? 1 : 8;
            uint32_t bytes;
            if (end - pos_ < 4 || !get(&bytes, 4))
                return fail("%s is cut short", what);
            if (array == 1 && bytes == 0xffffffffu)
                break;      /* no compressed sizes */
            const uint64_t want = bytes ? bytes : count * elem;
            if (want > end - pos_)
                return fail("%s claims %llu bytes for its %s but %llu remain", what,
                            (unsigned long long)want, array ? "sizes" : "mask",
                            (unsigned long long)(end - pos_));
            if (bytes) {
                /* blosc's header: version, flags, type size (4 bytes),
                 * then the uncompressed size, block size and compressed
                 * size, 32 bits each, little-endian. OpenVDB pads an
                 * array of fewer than 128 bytes to 128 before compressing
                 * it (a 78-leaf mask: 128 bytes). */
                const uint64_t raw = count * elem, padded = raw < 128 ? 128 : raw;
                uint32_t head[4] = {0, 0, 0, 0};
                if (bytes >= 16)
                    std::memcpy(head, data_ + pos_, 16);
                if (bytes < 16 || (head[1] != raw && head[1] != padded) || head[3] != bytes)
                    return fail("%s: the blosc block of its %s (%lu bytes) does not "
                                "hold %llu bytes", what, array ? "sizes" : "mask",
                                (unsigned long)bytes, (unsigned long long)(count * elem));
            }
            pos_ += want;
        }
        pos_ = end;         /* OpenVDB skips what follows, as unknown */
        return ST_OK;
    }

    /* The bytes of OpenVDB's fixed-size metadata types; 0 for the others
     * (strings, and types it keeps as unknown, read by their length). */
    static uint64_t fixed_size(const std::string &t)
    {
        static const struct { const char *name; uint64_t size; } k[] = {
            {"bool", 1}, {"int32", 4}, {"int64", 8}, {"float", 4}, {"double", 8},
            {"vec2i", 8}, {"vec2s", 8}, {"vec2d", 16}, {"vec3i", 12}, {"vec3s", 12},
            {"vec3d", 24}, {"vec4i", 16}, {"vec4s", 16}, {"vec4d", 32}, {"mat4s", 64},
            {"mat4d", 128}};
        for (const auto &e : k)
            if (t == e.name)
                return e.size;
        return 0;
    }
};

/* OpenVDB's header code (trees, nodes, the stream's readers, compiled
 * here) warns on std::cerr ("WARNING: multi-buffer trees are no longer
 * supported"), not through the logger init_openvdb turns off: the library
 * must not print, so while a file is read std::cerr goes nowhere. What
 * was wrong still comes back as the read's error. */
class CerrMuted {
public:
    CerrMuted() : old_(std::cerr.rdbuf(&sink_)) {}
    ~CerrMuted() { std::cerr.rdbuf(old_); }
    CerrMuted(const CerrMuted &) = delete;
    CerrMuted &operator=(const CerrMuted &) = delete;

private:
    std::stringbuf sink_;
    std::streambuf *old_;
};

/* Read the first usable FloatGrid from a stream (file or memory). */
st_status read_stream(st_grid **out, std::istream &is, const char *name,
                      size_t max_bytes, st_error *err)
{
    // OpenVDB reads without checking: make a short read throw.
    is.exceptions(std::ios_base::failbit | std::ios_base::badbit);
    int c = is.peek();      // peek() at the end sets only eofbit
    if (c == std::char_traits<char>::eof())
        return st_error_set(err, ST_EINPUT, name, 0, "empty %s",
                            std::strcmp(name, ST_STDIN_NAME) == 0
                                ? "input"
                                : "file");
    if (c == '<')
        return st_error_set(err, ST_EINPUT, name, 0,
                            "not an OpenVDB file: this looks like XML "
                            "(a VTK .vti field?)");
    // delayLoad = false: otherwise OpenVDB may copy a stream into a
    // temporary file to load grids lazily.
    CerrMuted muted;
    openvdb::io::Stream strm(is, false);
    openvdb::GridPtrVecPtr grids = strm.getGrids();
    std::string seen;
    FloatGrid::Ptr grid = grids ? pick_grid(*grids, seen) : nullptr;
    if (!grid)
        return st_error_set(err, ST_EINPUT, name, 0,
                            "no float grid to read (the file holds %s)",
                            seen.empty() ? "no grids" : seen.c_str());
    return grid_to_st(out, *grid, name, max_bytes, err);
}

/* Run f, turning every exception into an st_error naming `name`. `is`
 * (may be null) tells a truncated input from other stream failures. */
template <class F>
st_status guarded(const char *name, const char *what, st_error *err,
                  const std::istream *is, F &&f)
{
    try {
        return f();
    } catch (const std::bad_alloc &) {
        /* Reading, OpenVDB sizes some buffers by counts in the file before
         * it reads them: an absurd count lands here, not a real shortage. */
        return st_error_set(err, ST_ENOMEM, name, 0, "out of memory %s%s",
                            what, is ? " (the file asks for more memory "
                            "than there is: is it corrupt?)" : "");
    } catch (const std::ios_base::failure &e) {
        if (is && is->eof())
            return st_error_set(err, ST_EINPUT, name, 0,
                                "truncated OpenVDB data: the input ends "
                                "early");
        return st_error_set(err, ST_EIO, name, 0, "I/O error %s: %s", what,
                            e.what());
    } catch (const openvdb::Exception &e) {
        return st_error_set(err, ST_EINPUT, name, 0, "OpenVDB error %s: %s",
                            what, e.what());
    } catch (const std::exception &e) {
        return st_error_set(err, ST_EINPUT, name, 0, "error %s: %s", what,
                            e.what());
    } catch (...) {
        return st_error_set(err, ST_EINTERNAL, name, 0,
                            "unknown exception %s", what);
    }
}

/* The placement and band of a grid to write (not its values). */
st_status check_head(const st_grid *g, const char *name, st_error *err)
{
    const size_t lim = size_t(std::numeric_limits<int32_t>::max());
    if (g->nx < 1 || g->ny < 1 || g->nz < 1 || g->nx > lim || g->ny > lim ||
        g->nz > lim)
        return st_error_set(err, ST_ELIMIT, name, 0,
                            "grid size %zux%zux%zu does not fit OpenVDB's "
                            "32-bit coordinates",
                            g->nx, g->ny, g->nz);
    if (!(g->voxel > 0) || !std::isfinite(g->voxel) ||
        !std::isfinite(g->origin[0]) || !std::isfinite(g->origin[1]) ||
        !std::isfinite(g->origin[2]))
        return st_error_set(err, ST_EINPUT, name, 0,
                            "grid placement is not finite");
    if (std::isnan(g->band))
        return st_error_set(err, ST_EINPUT, name, 0, "grid band is NaN");
    return ST_OK;
}

st_status nan_error(const char *name, size_t x, size_t y, size_t z,
                    st_error *err)
{
    return st_error_set(err, ST_EINPUT, name, 0,
                        "value at voxel (%zu,%zu,%zu) is NaN; "
                        "OpenVDB cannot store it exactly",
                        x, y, z);
}

st_status check_grid(const st_grid *g, const char *name, st_error *err)
{
    if (!g || !g->data)
        return st_error_set(err, ST_EINTERNAL, name, 0, "no grid to write");
    if (st_status s = check_head(g, name, err))
        return s;
    // OpenVDB compares values with !(|a - b| > tol), which is true for a
    // NaN: NaN voxels would silently become background. A field with NaN
    // is a bug upstream; say so instead of writing something else.
    size_t n = st_grid_count(g);
    for (size_t i = 0; i < n; i++)
        if (std::isnan(g->data[i]))
            return nan_error(name, i % g->nx, i / g->nx % g->ny,
                             i / g->nx / g->ny, err);
    return ST_OK;
}

constexpr size_t kBlockValues = ST_GRID_BLOCK * ST_GRID_BLOCK * ST_GRID_BLOCK;
static_assert(ST_GRID_BLOCK == FloatGrid::TreeType::LeafNodeType::DIM,
              "a block is an OpenVDB leaf");

/* As check_grid, for a grid stored by blocks: its stored values. */
st_status check_blocks(const st_grid_blocks *b, const char *name,
                       st_error *err)
{
    if (!b || b->head.data || (b->nstored && !b->values))
        return st_error_set(err, ST_EINTERNAL, name, 0, "no grid to write");
    if (st_status s = check_head(&b->head, name, err))
        return s;
    if (!std::isfinite(b->head.band) || std::fabs(b->head.band) > FLT_MAX)
        return st_error_set(err, ST_EINTERNAL, name, 0,
                            "a grid stored by blocks needs a finite band");
    const size_t n = b->nb[0] * b->nb[1] * b->nb[2];
    for (size_t i = 0; i < n; i++) {
        if (b->at[i] == ST_GRID_NO_BLOCK)
            continue;
        const float *v = b->values + b->at[i];
        for (size_t q = 0; q < kBlockValues; q++)
            if (std::isnan(v[q]))
                return nan_error(name,
                                 i % b->nb[0] * ST_GRID_BLOCK + q / 64,
                                 i / b->nb[0] % b->nb[1] * ST_GRID_BLOCK + q / 8 % 8,
                                 i / b->nb[0] / b->nb[1] * ST_GRID_BLOCK + q % 8,
                                 err);
    }
    return ST_OK;
}

/* The background a grid is written with; see the header comment. */
bool finite_background(const st_grid *g, float *bg)
{
    if (std::isfinite(g->band) && std::fabs(g->band) <= FLT_MAX) {
        *bg = float(g->band);
        return true;
    }
    *bg = FLT_MAX;
    return false;
}

/* A dense grid's values into an empty tree. */
bool fill_dense(FloatGrid &grid, const st_grid *g)
{
    const openvdb::CoordBBox box(
        openvdb::Coord(0, 0, 0),
        openvdb::Coord(int(g->nx - 1), int(g->ny - 1), int(g->nz - 1)));
    // copyFromDense only reads the array.
    openvdb::tools::Dense<float, openvdb::tools::LayoutXYZ> dense(
        box, const_cast<float *>(g->data));
    // Tolerance 0: exactly the voxels equal to the background are left
    // inactive (with the background value), everything else is active.
    openvdb::tools::copyFromDense(dense, grid, 0.0f);
    return false;
}

/* The stored blocks' values into an empty tree: a leaf per stored block,
 * its voxels equal to +-background inactive (st_to_grid's rule), the rest
 * active; nothing for a block not stored (the background alone).
 * copyFromDense builds the same from the dense field (fill_dense), but
 * that a block of one active value becomes a tile there; the prune every
 * banded grid gets (st_to_grid; a grid stored by blocks is banded) makes
 * it one here, so the trees written are the same node for node. The
 * leaves are filled in parallel and added in one thread. */
bool fill_blocks(FloatGrid &grid, const st_grid_blocks *b)
{
    using LeafT = FloatGrid::TreeType::LeafNodeType;
    const float bg = grid.background(), neg = -bg;
    const size_t n = b->nb[0] * b->nb[1] * b->nb[2];
    std::vector<size_t> ids;
    ids.reserve(b->nstored);
    for (size_t i = 0; i < n; i++)
        if (b->at[i] != ST_GRID_NO_BLOCK)
            ids.push_back(i);
    const auto origin = [&](size_t i) {
        return openvdb::Coord(int(i % b->nb[0] * ST_GRID_BLOCK),
                              int(i / b->nb[0] % b->nb[1] * ST_GRID_BLOCK),
                              int(i / b->nb[0] / b->nb[1] * ST_GRID_BLOCK));
    };
    std::vector<std::unique_ptr<LeafT>> leaves(ids.size());
    bool oom = false;
    #pragma omp parallel for schedule(dynamic, 64)
    for (size_t q = 0; q < ids.size(); q++) {
        LeafT *leaf = new (std::nothrow) LeafT(origin(ids[q]), bg, false);
        if (!leaf) {
            #pragma omp atomic write
            oom = true;
            continue;
        }
        leaves[q].reset(leaf);
        const float *v = b->values + b->at[ids[q]];
        float *dst = leaf->buffer().data();
        LeafT::NodeMaskType mask;
        for (openvdb::Index i = 0; i < kBlockValues; i++) {
            dst[i] = v[i];
            if (v[i] != bg && v[i] != neg)
                mask.setOn(i);
        }
        leaf->setValueMask(mask);
    }
    if (oom)
        throw std::bad_alloc();
    openvdb::tree::ValueAccessor<FloatGrid::TreeType> acc(grid.tree());
    for (size_t q = 0; q < ids.size(); q++)
        acc.addLeaf(leaves[q].release());
    return true;
}

/* g's placement, band and meta around a tree filled by fill(grid), which
 * says whether it left -background inactive already. */
template <class Fill>
FloatGrid::Ptr st_to_grid(const st_grid *g, Fill &&fill)
{
    float bg;
    const bool banded = finite_background(g, &bg);
    FloatGrid::Ptr grid = FloatGrid::create(bg);
    const bool neg_done = fill(*grid);
    if (banded) {
        // -background (the clamped outside of a signed field) is outside
        // the band too: inactive, value kept. Tiles included.
        const float neg = -bg;
        if (!neg_done)
            for (auto it = grid->tree().beginValueOn(); it; ++it)
                if (*it == neg)
                    it.setActiveState(false);
        openvdb::tools::prune(grid->tree(), 0.0f);
    }

    openvdb::math::Transform::Ptr xf =
        openvdb::math::Transform::createLinearTransform(g->voxel);
    xf->postTranslate(openvdb::Vec3d(g->origin[0], g->origin[1],
                                     g->origin[2]));
    grid->setTransform(xf);
    grid->setName(st_grid_name_for_kind(g->kind));
    grid->setCreator("souptet " SOUPTET_VERSION);
    grid->setGridClass(g->kind == ST_GRID_SIGNED && banded
                           ? openvdb::GRID_LEVEL_SET
                           : openvdb::GRID_UNKNOWN);

    grid->insertMeta("souptet_kind",
                     openvdb::StringMetadata(st_grid_kind_name(g->kind)));
    grid->insertMeta("voxel_size", openvdb::DoubleMetadata(g->voxel));
    grid->insertMeta("origin", openvdb::Vec3DMetadata(openvdb::Vec3d(
                                   g->origin[0], g->origin[1], g->origin[2])));
    grid->insertMeta("dims", openvdb::Vec3IMetadata(openvdb::Vec3i(
                                 int(g->nx), int(g->ny), int(g->nz))));
    grid->insertMeta("band", openvdb::DoubleMetadata(g->band));
    std::string order;
    bool order_ok = true;
    for (size_t i = 0; i < g->meta.count; i++) {
        const st_meta_entry &e = g->meta.entries[i];
        const std::string key = e.key;
        grid->insertMeta(escape_key(key), openvdb::StringMetadata(e.value));
        if (key.find('\n') != std::string::npos)
            order_ok = false;   // cannot be listed; falls back to sorted
        order += (i ? "\n" : "") + key;
    }
    if (order_ok && g->meta.count > 0)
        grid->insertMeta(kMetaOrder, openvdb::StringMetadata(order));
    return grid;
}

template <class Fill>
st_status write_file(const st_grid *g, Fill &&fill, const char *path,
                     st_error *err)
{
    st_outfile o;
    if (st_status s = st_outfile_begin(&o, path, 0, err))
        return s;
    st_status s = guarded(path, "writing", err, nullptr, [&]() -> st_status {
        FloatGrid::Ptr grid = st_to_grid(g, fill);
        std::ofstream os(o.tmp, std::ios_base::out | std::ios_base::binary |
                                    std::ios_base::trunc);
        if (!os)
            return st_error_set(err, ST_EIO, path, 0, "cannot open: %s",
                                std::strerror(errno));
        Writer w;   // default compression: Blosc if available, else zlib
        errno = 0;
        w.put(os, openvdb::GridCPtrVec{grid}, /*seekable=*/true);
        os.close();
        if (os.fail())
            return st_error_set(err, ST_EIO, path, 0, "write failed: %s",
                                errno ? std::strerror(errno) : "I/O error");
        return ST_OK;
    });
    if (s) {
        st_outfile_abort(&o);
        return s;
    }
    return st_outfile_commit(&o, err);
}

template <class Fill>
st_status write_stdout(const st_grid *g, Fill &&fill, st_error *err)
{
    const char *name = ST_STDOUT_NAME;
    return guarded(name, "writing", err, nullptr, [&]() -> st_status {
        FloatGrid::Ptr grid = st_to_grid(g, fill);
        // Whatever C stdio holds goes out first. A fresh ostream on
        // cout's buffer (not std::cout itself): OpenVDB leaves a pointer
        // to a destroyed local in the stream's pword after writing, which
        // a second write to the same ostream would follow; a fresh stream
        // also starts with clean flags and format state. With
        // sync_with_stdio (the default) cout's buffer writes into C's
        // stdout, otherwise it has its own buffer: flush both after.
        if (std::fflush(stdout) != 0)
            return st_error_set(err, ST_EIO, name, 0, "write failed: %s",
                                std::strerror(errno));
        std::ostream os(std::cout.rdbuf());
        if (!os.rdbuf())
            return st_error_set(err, ST_EIO, name, 0, "no stdout stream");
        Writer w;
        w.setCompression(ST_VDB_STREAM_COMPRESSION);
        errno = 0;
        w.put(os, openvdb::GridCPtrVec{grid}, /*seekable=*/false);
        os.flush();
        int e = errno;
        if (!os || std::fflush(stdout) != 0 || std::ferror(stdout)) {
            if (!e)
                e = errno;
            return st_error_set(err, ST_EIO, name, 0, "write failed: %s",
                                e ? std::strerror(e) : "I/O error");
        }
        return ST_OK;
    });
}

/* Check, then write to path or stdout the grid `head` whose tree fill
 * builds. No exception can leave this function: guarded() catches
 * everything, and so does this for what happens outside it
 * (initialize()). */
template <class Check, class Fill>
st_status write_vdb(const st_grid *head, const char *path, Check &&check,
                    Fill &&fill, st_error *err)
{
    const bool out = st_path_is_stdio(path);
    const char *name = out ? ST_STDOUT_NAME : path;
    try {
        init_openvdb();
        if (st_status s = check(name))
            return s;
        return out ? write_stdout(head, fill, err) : write_file(head, fill, path, err);
    } catch (...) {
        return st_error_set(err, ST_EINTERNAL, name, 0,
                            "unexpected exception writing OpenVDB");
    }
}

} // namespace

extern "C" {

st_status st_grid_write_vdb(const st_grid *g, const char *path, st_error *err)
{
    return write_vdb(
        g, path, [&](const char *name) { return check_grid(g, name, err); },
        [g](FloatGrid &grid) { return fill_dense(grid, g); }, err);
}

st_status st_grid_blocks_write_vdb(const st_grid_blocks *b, const char *path,
                                   st_error *err)
{
    return write_vdb(
        b ? &b->head : nullptr, path,
        [&](const char *name) { return check_blocks(b, name, err); },
        [b](FloatGrid &grid) { return fill_blocks(grid, b); }, err);
}

st_status st_gridio_read_vdb_mem(st_grid **out, const unsigned char *data,
                                 size_t size, const char *name,
                                 size_t max_bytes, st_error *err)
{
    *out = nullptr;
    try {
        init_openvdb();
        if (st_status st = VdbWalk(data, size, name, err).run())
            return st;
        MemBuf buf(data, size);
        std::istream is(&buf);
        return guarded(name, "reading", err, &is, [&] {
            return read_stream(out, is, name, max_bytes, err);
        });
    } catch (...) {
        return st_error_set(err, ST_EINTERNAL, name, 0,
                            "unexpected exception reading OpenVDB");
    }
}

st_status st_grid_read_vdb(st_grid **out, const char *path, size_t max_bytes,
                           st_error *err)
{
    *out = nullptr;
    if (st_path_is_stdio(path)) {
        unsigned char *data;
        size_t size;
        if (st_status s = st_file_read(nullptr, &data, &size, err))
            return s;
        st_status s = st_gridio_read_vdb_mem(out, data, size,
                                             ST_STDIN_NAME, max_bytes,
                                             err);
        std::free(data);
        return s;
    }
    if (st_status s = st_file_check_input(path, err))
        return s;
    struct stat st;
    if (stat(path, &st) != 0)
        return st_error_set(err, ST_EIO, path, 0, "cannot open: %s",
                            std::strerror(errno));
    if (S_ISREG(st.st_mode)) {
        /* Walk the length-prefixed parts first (see VdbWalk), mapped, not
         * copied; a FIFO is read by OpenVDB as it comes. */
        int fd = open(path, O_RDONLY);
        if (fd < 0)
            return st_error_set(err, ST_EIO, path, 0, "cannot open: %s",
                                std::strerror(errno));
        void *map = mmap(nullptr, size_t(st.st_size), PROT_READ, MAP_PRIVATE,
                         fd, 0);
        close(fd);
        if (map == MAP_FAILED)
            return st_error_set(err, ST_EIO, path, 0, "cannot map: %s",
                                std::strerror(errno));
        st_status ws = VdbWalk(static_cast<const unsigned char *>(map),
                               uint64_t(st.st_size), path, err).run();
        munmap(map, size_t(st.st_size));
        if (ws)
            return ws;
    }
    try {
        init_openvdb();
        // Read straight from the file (no copy in memory): io::Stream
        // reads sequentially, so FIFOs such as <(cmd) work as well.
        std::ifstream is(path, std::ios_base::in | std::ios_base::binary);
        if (!is)
            return st_error_set(err, ST_EIO, path, 0, "cannot open: %s",
                                std::strerror(errno));
        return guarded(path, "reading", err, &is, [&] {
            return read_stream(out, is, path, max_bytes, err);
        });
    } catch (...) {
        return st_error_set(err, ST_EINTERNAL, path, 0,
                            "unexpected exception reading OpenVDB");
    }
}

st_status st_gridio_write_foreign_vdb(const char *path, int which,
                                      st_error *err)
{
    try {
        init_openvdb();
        return guarded(path, "writing", err, nullptr, [&]() -> st_status {
            openvdb::GridBase::Ptr grid;
            if (which == 0) {
                auto v = openvdb::Vec3SGrid::create(openvdb::Vec3s(0, 0, 0));
                v->tree().setValue(openvdb::Coord(1, 2, 3),
                                   openvdb::Vec3s(1, 2, 3));
                v->setName("velocity");
                grid = v;
            } else if (which == 1) {
                auto f = FloatGrid::create(-1.0f);
                auto acc = f->getAccessor();
                for (int k = 4; k <= 6; k++)
                    for (int j = -3; j <= 1; j++)
                        for (int i = 2; i <= 5; i++)
                            if ((i + j + k) % 2 == 0 ||
                                (i == 2 && j == -3 && k == 4) ||
                                (i == 5 && j == 1 && k == 6))
                                acc.setValue(openvdb::Coord(i, j, k),
                                             float(i + 10 * j + 100 * k));
                auto xf = openvdb::math::Transform::createLinearTransform(0.5);
                xf->postTranslate(openvdb::Vec3d(1, 2, 3));
                f->setTransform(xf);
                f->setName("density");
                f->insertMeta("note", openvdb::StringMetadata("foreign"));
                grid = f;
            } else {
                auto ls = openvdb::tools::createLevelSetSphere<FloatGrid>(
                    2.0f, openvdb::Vec3f(0, 0, 0), 0.25f, 3.0f);
                ls->setName("ls");
                grid = ls;
            }
            std::ofstream os(path, std::ios_base::out |
                                       std::ios_base::binary |
                                       std::ios_base::trunc);
            if (!os)
                return st_error_set(err, ST_EIO, path, 0, "cannot open");
            Writer().put(os, openvdb::GridCPtrVec{grid}, true);
            os.close();
            return os.fail() ? st_error_set(err, ST_EIO, path, 0,
                                            "write failed")
                             : ST_OK;
        });
    } catch (...) {
        return st_error_set(err, ST_EINTERNAL, path, 0,
                            "unexpected exception");
    }
}

} // extern "C"
