/*
 * alpha_wrap.cpp - the bench's peer for soupwrap: CGAL's alpha_wrap_3
 * (Portaneri et al. 2022, "Alpha wrapping with an offset"), and the
 * distances the wrap stage reports for both tools.
 *
 *   alpha_wrap wrap IN OUT ALPHA OFFSET     wrap IN (any soup CGAL reads:
 *                                           .off .obj .ply .stl) with the
 *                                           given absolute alpha and offset,
 *                                           write OUT (.off); JSON on stdout:
 *                                           seconds (the wrap only), faces
 *   alpha_wrap distance A B                 max and mean distance from A's
 *                                           vertices to B's triangles
 *                                           (an AABB tree over B), JSON
 *   alpha_wrap check IN                     CGAL's own verdict on a surface
 *                                           (soupwrap's output): a polygon
 *                                           mesh at all, closed, no
 *                                           degenerate face, no self-
 *                                           intersection, outward; each by
 *                                           CGAL's exact predicates; JSON,
 *                                           exit 1 unless all hold
 *
 * Not installed; only scripts/bench.d/wrap.py runs it.
 */
#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/IO/polygon_soup_io.h>
#include <CGAL/Polygon_mesh_processing/IO/polygon_mesh_io.h>
#include <CGAL/Polygon_mesh_processing/orient_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/orientation.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Polygon_mesh_processing/shape_predicates.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/alpha_wrap_3.h>

#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = K::Point_3;
using Triangle = K::Triangle_3;
using Mesh = CGAL::Surface_mesh<Point>;

static bool read_soup(const char *path, std::vector<Point> &pts,
                      std::vector<std::vector<std::size_t>> &polys)
{
    if (!CGAL::IO::read_polygon_soup(path, pts, polys) || polys.empty()) {
        std::fprintf(stderr, "alpha_wrap: %s: cannot read a polygon soup\n",
                     path);
        return false;
    }
    return true;
}

static int do_wrap(const char *in, const char *out, double alpha,
                   double offset)
{
    std::vector<Point> pts;
    std::vector<std::vector<std::size_t>> polys;
    if (!read_soup(in, pts, polys))
        return 1;
    // Fan-triangulate: alpha_wrap_3 takes triangle soups.
    std::vector<std::array<std::size_t, 3>> tris;
    for (const auto &p : polys)
        for (std::size_t k = 2; k < p.size(); k++)
            tris.push_back({p[0], p[k - 1], p[k]});
    Mesh wrap;
    auto t0 = std::chrono::steady_clock::now();
    CGAL::alpha_wrap_3(pts, tris, alpha, offset, wrap);
    double s = std::chrono::duration<double>(std::chrono::steady_clock::now() -
                                             t0).count();
    if (!CGAL::IO::write_polygon_mesh(out, wrap,
                                      CGAL::parameters::stream_precision(17))) {
        std::fprintf(stderr, "alpha_wrap: %s: cannot write\n", out);
        return 1;
    }
    std::printf("{\"seconds\": %.6f, \"faces\": %zu, \"vertices\": %zu}\n", s,
                std::size_t(wrap.number_of_faces()),
                std::size_t(wrap.number_of_vertices()));
    return 0;
}

static int do_distance(const char *a, const char *b)
{
    std::vector<Point> pa, pb;
    std::vector<std::vector<std::size_t>> fa, fb;
    if (!read_soup(a, pa, fa) || !read_soup(b, pb, fb))
        return 1;
    std::vector<Triangle> tris;
    for (const auto &p : fb)
        for (std::size_t k = 2; k < p.size(); k++)
            tris.emplace_back(pb[p[0]], pb[p[k - 1]], pb[p[k]]);
    using Prim = CGAL::AABB_triangle_primitive<K, std::vector<Triangle>::iterator>;
    CGAL::AABB_tree<CGAL::AABB_traits<K, Prim>> tree(tris.begin(), tris.end());
    tree.accelerate_distance_queries();
    // Only the vertices A's polygons use.
    std::vector<char> used(pa.size(), 0);
    for (const auto &p : fa)
        for (std::size_t v : p)
            used[v] = 1;
    double mx = 0.0, sum = 0.0;
    std::size_t n = 0;
    for (std::size_t i = 0; i < pa.size(); i++) {
        if (!used[i])
            continue;
        double d = std::sqrt(CGAL::to_double(tree.squared_distance(pa[i])));
        mx = std::max(mx, d);
        sum += d;
        n++;
    }
    std::printf("{\"max\": %.9g, \"mean\": %.9g, \"points\": %zu}\n", mx,
                n ? sum / double(n) : 0.0, n);
    return 0;
}

/* The predicates (orientation, collinearity, triangle intersection) are
 * exact in this kernel; only constructions are not, and none is used. */
static int do_check(const char *in)
{
    namespace PMP = CGAL::Polygon_mesh_processing;
    std::vector<Point> pts;
    std::vector<std::vector<std::size_t>> polys;
    if (!read_soup(in, pts, polys))
        return 1;
    bool is_mesh = PMP::is_polygon_soup_a_polygon_mesh(polys);
    bool closed = false, outward = false, self = true;
    std::size_t degenerate = 0;
    if (is_mesh) {
        Mesh m;
        PMP::polygon_soup_to_polygon_mesh(pts, polys, m);
        closed = CGAL::is_closed(m);
        for (auto f : faces(m))
            degenerate += PMP::is_degenerate_triangle_face(f, m);
        self = PMP::does_self_intersect(m);
        outward = closed && PMP::is_outward_oriented(m);
    }
    bool ok = is_mesh && closed && degenerate == 0 && !self && outward;
    std::printf("{\"polygon_mesh\": %s, \"closed\": %s, \"degenerate_faces\": "
                "%zu, \"self_intersecting\": %s, \"outward\": %s, \"ok\": %s}\n",
                is_mesh ? "true" : "false", closed ? "true" : "false",
                degenerate, self ? "true" : "false",
                outward ? "true" : "false", ok ? "true" : "false");
    return ok ? 0 : 1;
}

int main(int argc, char **argv)
{
    if (argc == 3 && std::string(argv[1]) == "check")
        return do_check(argv[2]);
    if (argc == 6 && std::string(argv[1]) == "wrap")
        return do_wrap(argv[2], argv[3], std::atof(argv[4]),
                       std::atof(argv[5]));
    if (argc == 4 && std::string(argv[1]) == "distance")
        return do_distance(argv[2], argv[3]);
    std::fprintf(stderr, "usage: alpha_wrap wrap IN OUT ALPHA OFFSET\n"
                         "       alpha_wrap distance A B\n"
                         "       alpha_wrap check IN\n");
    return 2;
}
