/*
 * bench/cgal_mesh3.cpp - the CGAL Mesh_3 peer of `make bench STAGE=mesh`.
 *
 *   cgal_mesh3 IN.off OUT.mesh [--size F] [--distance F] [--angle DEG]
 *              [--ratio R] [--no-optimise]
 *
 * Reads IN.off as a CGAL polyhedral surface, meshes the volume it bounds
 * with make_mesh_3 (Polyhedral_mesh_domain_3: the inside test is CGAL's
 * ray parity, so the surface must be closed), and writes the tets of the
 * complex as a Medit .mesh (Vertices, Tetrahedra; only the vertices the
 * tets use, 1-based). Sizes are fractions of the bounding-box diagonal:
 * --size F sets facet_size and cell_size (default 0.1, a coarse mesh),
 * --distance F the facet_distance (default F/10), --angle the facet angle
 * bound (25, the manual's value), --ratio the cell radius-edge ratio (3).
 * The manual's defaults for the optimisers are kept (perturb and exude on,
 * no Lloyd, no ODT); --no-optimise turns perturb and exude off.
 *
 * Prints one JSON line on stdout: tets, vertices, seconds (meshing only).
 * Messages on stderr as "cgal_mesh3: FILE: what"; exit 0 ok, 1 failure
 * (unreadable or open surface, empty mesh), 2 usage.
 *
 * Reference: CGAL 5.5 manual, "3D Mesh Generation", section "Domains
 * Bounded by Polyhedral Surfaces" (example mesh_polyhedral_domain.cpp).
 */
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Mesh_complex_3_in_triangulation_3.h>
#include <CGAL/Mesh_criteria_3.h>
#include <CGAL/Mesh_polyhedron_3.h>
#include <CGAL/Mesh_triangulation_3.h>
#include <CGAL/Polyhedral_mesh_domain_3.h>
#include <CGAL/make_mesh_3.h>
#include <CGAL/Polygon_mesh_processing/bbox.h>
#include <CGAL/boost/graph/helpers.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iostream>
#include <map>
#include <string>

typedef CGAL::Exact_predicates_inexact_constructions_kernel K;
typedef CGAL::Mesh_polyhedron_3<K>::type Polyhedron;
typedef CGAL::Polyhedral_mesh_domain_3<Polyhedron, K> Mesh_domain;
typedef CGAL::Mesh_triangulation_3<Mesh_domain, CGAL::Default, CGAL::Sequential_tag>::type Tr;
typedef CGAL::Mesh_complex_3_in_triangulation_3<Tr> C3t3;
typedef CGAL::Mesh_criteria_3<Tr> Mesh_criteria;

static int fail(const char *file, const std::string &what)
{
    std::fprintf(stderr, "cgal_mesh3: %s: %s\n", file, what.c_str());
    return 1;
}

static int usage(void)
{
    std::fprintf(stderr, "usage: cgal_mesh3 IN.off OUT.mesh [--size F] [--distance F]"
                         " [--angle DEG] [--ratio R] [--no-optimise]\n");
    return 2;
}

int main(int argc, char **argv)
{
    const char *in = nullptr, *out = nullptr;
    double size = 0.1, distance = -1.0, angle = 25.0, ratio = 3.0;
    bool optimise = true;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        if (!std::strcmp(a, "--size") && i + 1 < argc) size = std::atof(argv[++i]);
        else if (!std::strcmp(a, "--distance") && i + 1 < argc) distance = std::atof(argv[++i]);
        else if (!std::strcmp(a, "--angle") && i + 1 < argc) angle = std::atof(argv[++i]);
        else if (!std::strcmp(a, "--ratio") && i + 1 < argc) ratio = std::atof(argv[++i]);
        else if (!std::strcmp(a, "--no-optimise")) optimise = false;
        else if (a[0] == '-' && a[1] != '\0') return usage();
        else if (!in) in = a;
        else if (!out) out = a;
        else return usage();
    }
    if (!in || !out || !(size > 0.0)) return usage();
    if (distance <= 0.0) distance = size / 10.0;

    Polyhedron poly;
    {
        std::ifstream f(in);
        if (!f) return fail(in, "cannot open");
        f >> poly;
        if (f.fail() && !f.eof())
            return fail(in, "not readable as a CGAL polyhedral surface (non-manifold or "
                            "inconsistently oriented faces)");
    }
    if (poly.size_of_facets() == 0)
        return fail(in, "not readable as a CGAL polyhedral surface (no facets: non-manifold "
                        "or inconsistently oriented faces)");
    if (!CGAL::is_triangle_mesh(poly)) return fail(in, "not a triangle mesh");
    poly.normalize_border();
    if (!poly.is_closed())
        return fail(in, "surface is not closed (" + std::to_string(poly.size_of_border_edges()) +
                        " border edges): Polyhedral_mesh_domain_3 needs a closed surface");

    CGAL::Bbox_3 bb = CGAL::Polygon_mesh_processing::bbox(poly);
    double diag = std::sqrt((bb.xmax() - bb.xmin()) * (bb.xmax() - bb.xmin()) +
                            (bb.ymax() - bb.ymin()) * (bb.ymax() - bb.ymin()) +
                            (bb.zmax() - bb.zmin()) * (bb.zmax() - bb.zmin()));

    auto t0 = std::chrono::steady_clock::now();
    C3t3 c3t3;
    try {
        Mesh_domain domain(poly);
        namespace params = CGAL::parameters;
        Mesh_criteria criteria(params::facet_angle = angle, params::facet_size = size * diag,
                               params::facet_distance = distance * diag,
                               params::cell_radius_edge_ratio = ratio,
                               params::cell_size = size * diag);
        if (optimise)
            c3t3 = CGAL::make_mesh_3<C3t3>(domain, criteria);
        else
            c3t3 = CGAL::make_mesh_3<C3t3>(domain, criteria, params::no_perturb(), params::no_exude());
    } catch (const std::exception &e) {
        return fail(in, std::string("make_mesh_3 failed: ") + e.what());
    }
    double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (c3t3.number_of_cells_in_complex() == 0)
        return fail(in, "make_mesh_3 produced no tetrahedra");

    std::map<Tr::Vertex_handle, long> index;
    std::string tmp = std::string(out) + ".tmp";
    {
        std::ofstream o(tmp);
        if (!o) return fail(out, "cannot write");
        o.precision(17);
        for (auto c = c3t3.cells_in_complex_begin(); c != c3t3.cells_in_complex_end(); ++c)
            for (int k = 0; k < 4; k++)
                index.emplace(c->vertex(k), 0);
        long n = 0;
        o << "MeshVersionFormatted 1\nDimension 3\nVertices\n" << index.size() << "\n";
        for (auto &v : index) {
            v.second = ++n;
            const auto &p = v.first->point().point();
            o << p.x() << " " << p.y() << " " << p.z() << " 0\n";
        }
        o << "Tetrahedra\n" << c3t3.number_of_cells_in_complex() << "\n";
        for (auto c = c3t3.cells_in_complex_begin(); c != c3t3.cells_in_complex_end(); ++c)
            o << index[c->vertex(0)] << " " << index[c->vertex(1)] << " "
              << index[c->vertex(2)] << " " << index[c->vertex(3)] << " 1\n";
        o << "End\n";
        if (!o.good()) { std::remove(tmp.c_str()); return fail(out, "write failed"); }
    }
    if (std::rename(tmp.c_str(), out) != 0) { std::remove(tmp.c_str()); return fail(out, "rename failed"); }
    std::printf("{\"tets\": %zu, \"vertices\": %zu, \"seconds\": %.4f}\n",
                (size_t)c3t3.number_of_cells_in_complex(), index.size(), secs);
    return 0;
}
