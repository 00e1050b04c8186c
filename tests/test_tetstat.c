/*
 * test_tetstat.c - the metrics of tetstat.h on hand-made meshes with known
 * answers: a regular tet, the 5-tet cube, two cubes sharing a face, two
 * apart, an inverted and a flat tet, a non-manifold face; distances, volume
 * ratio and enclosure against surfaces inside and sticking out; IoU
 * against a field.
 */
#include "souptet/tetstat.h"
#include "souptet/tetmesh.h"
#include "souptet/tetqual.h"
#include "cubetets.h"
#include "shapes.h"
#include "tap.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static const double k_regular = 70.528779365509308630754;    /* acos(1/3) */
static const double k_cube_slant = 54.735610317245345684622; /* acos(1/sqrt 3) */

/* nx x ny x nz cubes of edge s from o, 5 tets each, mirrored on
 * alternating cubes so faces match. */
static void add_lattice(st_tetmesh *m, const double o[3], double s, int nx,
                        int ny, int nz)
{
    const uint32_t base = (uint32_t)m->npoints;
    for (int k = 0; k <= nz; k++)
        for (int j = 0; j <= ny; j++)
            for (int i = 0; i <= nx; i++)
                add_pt(m, o[0] + s * i, o[1] + s * j, o[2] + s * k);
    add_cube_tets(m, base, nx, ny, nz);
}

static st_tetmesh *cubes(const double o[3], double s, int nx, int ny, int nz)
{
    st_tetmesh *m = st_tetmesh_new();
    add_lattice(m, o, s, nx, ny, nz);
    return m;
}

/* The outward boundary of a lattice block as a soup: a closed, oriented
 * box surface. */
static st_soup *box_surface(const double o[3], double s, int n)
{
    st_tetmesh *m = cubes(o, s, n, n, n);
    uint32_t *f;
    size_t nf;
    st_tetmesh_boundary(m, &f, NULL, &nf, NULL);
    st_soup *b = st_soup_new();
    for (size_t i = 0; i < m->npoints; i++)
        st_soup_add_vertex(b, m->xyz[3 * i], m->xyz[3 * i + 1],
                           m->xyz[3 * i + 2], NULL);
    for (size_t i = 0; i < nf; i++)
        st_soup_add_triangle(b, f[3 * i], f[3 * i + 1], f[3 * i + 2], NULL);
    free(f);
    st_tetmesh_free(m);
    return b;
}

static void test_regular(void)
{
    st_tetmesh *m = st_tetmesh_new();
    add_pt(m, 1, 1, 1);
    add_pt(m, 1, -1, -1);
    add_pt(m, -1, 1, -1);
    add_pt(m, -1, -1, 1);
    add_pos(m, 0, 1, 2, 3);
    st_tetstat r;
    st_error err;
    TAP_CHECK(st_tetstat_mesh(&r, m, &err) == ST_OK, "regular tet: computed");
    TAP_NEAR(r.min_dihedral, k_regular, 1e-12, "regular tet: min 70.5288");
    TAP_NEAR(r.max_dihedral, k_regular, 1e-12, "regular tet: max 70.5288");
    TAP_CHECK(r.hist[7] == 1 && r.tets == 1 && r.points == 4,
              "regular tet: one tet in the 70..80 bin");
    TAP_CHECK(r.inverted == 0 && r.degenerate == 0 && r.boundary_faces == 4 &&
                  r.interior_faces == 0 && r.components == 1 && r.conforming,
              "regular tet: positive, 4 boundary faces, 1 component");
    TAP_NEAR(r.volume, 8.0 / 3.0, 1e-14, "regular tet: volume 8/3");
    TAP_CHECK(!r.has_h && !r.has_surface && !r.has_field,
              "no h, surface or field parts");
    st_tetmesh_free(m);
}

static void test_cubes(void)
{
    const double o[3] = {0, 0, 0};
    st_tetmesh *m = cubes(o, 1, 1, 1, 1);
    st_meta_set(&m->meta, "h", "1");
    st_tetstat r;
    st_error err;
    st_tetstat_mesh(&r, m, &err);
    TAP_NEAR(r.min_dihedral, k_cube_slant, 1e-12, "cube: min 54.7356");
    TAP_NEAR(r.max_dihedral, 90, 1e-12, "cube: max 90");
    TAP_NEAR(r.volume, 1, 1e-15, "cube: volume 1");
    TAP_CHECK(r.tets == 5 && r.components == 1 && r.conforming &&
                  r.boundary_faces == 12 && r.interior_faces == 4 &&
                  r.nonmanifold_faces == 0,
              "cube: 5 tets, 1 component, conforming, 12 boundary and 4 "
              "interior faces");
    TAP_CHECK(r.hist[5] == 4 && r.hist[7] == 1,
              "cube: histogram 4 corner tets in 50..60, the middle in 70..80");
    TAP_CHECK(r.has_h && r.h == 1, "cube: h from meta");
    TAP_CHECK(r.lo[0] == 0 && r.hi[2] == 1, "cube: bounds");
    st_tetmesh_free(m);

    m = cubes(o, 1, 2, 1, 1);
    st_tetstat_mesh(&r, m, &err);
    TAP_CHECK(r.tets == 10 && r.components == 1 && r.conforming &&
                  r.boundary_faces == 20 && r.interior_faces == 10,
              "two cubes sharing a face: 20 boundary, 10 interior faces, "
              "1 component");
    TAP_NEAR(r.volume, 2, 1e-15, "two cubes: volume 2");
    st_tetmesh_free(m);

    m = cubes(o, 1, 1, 1, 1);
    const double o2[3] = {3, 0, 0};
    add_lattice(m, o2, 1, 1, 1, 1);
    add_pt(m, 9, 9, 9);   /* unused */
    st_tetstat_mesh(&r, m, &err);
    TAP_CHECK(r.components == 2 && r.unused_points == 1 &&
                  r.boundary_faces == 24 && r.hi[0] == 4,
              "two cubes apart: 2 components, the unused point counted but "
              "outside the bounds");
    st_tetmesh_free(m);
}

static void test_bad_tets(void)
{
    const double o[3] = {0, 0, 0};
    st_tetmesh *m = cubes(o, 1, 1, 1, 1);
    uint32_t t = m->tets[4 * 2 + 2];   /* flip a corner tet */
    m->tets[4 * 2 + 2] = m->tets[4 * 2 + 3];
    m->tets[4 * 2 + 3] = t;
    st_tetstat r;
    st_error err;
    st_tetstat_mesh(&r, m, &err);
    TAP_CHECK(r.inverted == 1 && r.degenerate == 0,
              "one flipped tet: 1 inverted (%zu)", r.inverted);
    TAP_NEAR(r.volume, 1 - 2.0 / 6.0, 1e-15,
             "one flipped tet: its volume counts negative");
    TAP_CHECK(r.conforming && r.components == 1,
              "a flipped tet still shares its faces");
    /* A flat tet on four corners of the bottom face. */
    add_pos(m, 0, 1, 2, 3);
    st_tetstat_mesh(&r, m, &err);
    TAP_CHECK(r.degenerate == 1 && r.min_dihedral == 0 && r.hist[0] == 1,
              "a flat tet: 1 degenerate, min dihedral 0, in the 0..10 bin");
    st_tetmesh_free(m);

    /* Three tets on one face. */
    m = three_tets_on_a_face();
    st_tetstat_mesh(&r, m, &err);
    TAP_CHECK(r.nonmanifold_faces == 1 && !r.conforming &&
                  r.boundary_faces == 9 && r.interior_faces == 0,
              "three tets on one face: 1 non-manifold face, not conforming");
    st_tetmesh_free(m);

    m = st_tetmesh_new();
    st_tetstat_mesh(&r, m, &err);
    TAP_CHECK(r.tets == 0 && isnan(r.min_dihedral) && r.components == 0,
              "empty mesh: no angles, no components");
    st_tetmesh_free(m);
}

static void test_surface(void)
{
    const double o[3] = {0, 0, 0}, si[3] = {0.5, 0.5, 0.5};
    st_tetmesh *m = cubes(o, 1, 2, 2, 2);   /* [0,2]^3 */
    st_soup *s = box_surface(si, 1, 1);      /* [0.5,1.5]^3, oriented */
    st_tetstat r;
    st_error err;
    st_tetstat_mesh(&r, m, &err);
    TAP_CHECK(st_tetstat_surface(&r, m, s, &err) == ST_OK && r.has_surface,
              "inner box: computed");
    TAP_CHECK(r.surface_vertices == 8 && r.surface_triangles == 12 &&
                  r.boundary_vertices == 26,
              "inner box: 8 vertices, 12 triangles; 26 boundary vertices");
    TAP_NEAR(r.dist_min, 0.5, 1e-15, "boundary -> S min 0.5 (face centers)");
    TAP_NEAR(r.dist_max, 0.5 * sqrt(3), 1e-15,
             "boundary -> S max sqrt(3)/2 (corners)");
    TAP_NEAR(r.surface_dist_max, 0.5, 1e-15, "S -> boundary max 0.5");
    TAP_CHECK(r.surface_closed, "inner box: closed and oriented");
    TAP_NEAR(r.surface_volume, 1, 1e-15, "inner box: volume 1");
    TAP_NEAR(r.volume_ratio, 8, 1e-14, "inner box: volume ratio 8");
    TAP_CHECK(r.has_enclosure && r.vertices_inside == 8 && r.fraction_inside == 1 &&
                  r.crossing_triangles == 0 && r.encloses && r.enclosure_verified,
              "inner box: enclosed, every vertex inside, no crossing");

    /* One tet turned inside out (two corners swapped): it covers the same
     * points and the counts stay clean, but they no longer prove
     * enclosure (enclose.h), so it is not reported as enclosing. */
    uint32_t sw = m->tets[1];
    m->tets[1] = m->tets[2];
    m->tets[2] = sw;
    st_tetstat_mesh(&r, m, &err);
    TAP_CHECK(r.inverted == 1, "one tet inverted");
    TAP_CHECK(st_tetstat_surface(&r, m, s, &err) == ST_OK && r.has_enclosure &&
                  r.vertices_inside == 8 && r.crossing_triangles == 0 &&
                  !r.enclosure_verified && !r.encloses,
              "inner box, an inverted tet: clean counts, unverified, not 'encloses'");
    m->tets[2] = m->tets[1];
    m->tets[1] = sw;
    st_tetstat_mesh(&r, m, &err);
    st_tetstat_surface(&r, m, s, &err);
    st_soup_free(s);

    /* A box sticking out of the mesh by 0.25 on +x. */
    const double so[3] = {1.25, 0.5, 0.5};
    s = box_surface(so, 1, 1);
    st_tetstat_surface(&r, m, s, &err);
    /* The center of its -x face, (1.25, 1, 1), is 0.75 from the mesh
     * boundary (and a triangle centroid there samples it). */
    TAP_NEAR(r.surface_dist_max, 0.75, 1e-15,
             "box sticking out: S -> boundary max 0.75");
    TAP_CHECK(r.has_enclosure && r.vertices_inside == 4 && r.crossing_triangles > 0 &&
                  !r.encloses,
              "box sticking out: 4 of 8 vertices inside, triangles "
              "crossing, does not enclose (%zu, %zu)",
              r.vertices_inside, r.crossing_triangles);
    st_soup_free(s);

    /* add_box flips every other triangle: closed but not oriented, so no
     * volume. */
    s = st_soup_new();
    const double lo[3] = {0.5, 0.5, 0.5}, hi[3] = {1.5, 1.5, 1.5};
    add_box(s, lo, hi);
    st_tetstat_surface(&r, m, s, &err);
    TAP_CHECK(!r.surface_closed && isnan(r.surface_volume) &&
                  isnan(r.volume_ratio),
              "inconsistently oriented box: volume n/a");
    TAP_NEAR(r.dist_min, 0.5, 1e-15, "... distances still measured");
    st_soup_free(s);
    st_tetmesh_free(m);
}

static void test_field(void)
{
    const double o[3] = {0, 0, 0}, go[3] = {-0.5, -0.5, -0.5};
    st_tetmesh *m = cubes(o, 1, 2, 2, 2);   /* [0,2]^3 */
    st_grid *g;
    st_error err;
    st_grid_new(&g, 6, 6, 6, go, 0.5, 0, 0, &err);
    /* Centers at -0.5, 0, ..., 2: 5^3 = 125 in the closed mesh (faces
     * count); negative where every coordinate is in {0.5, 1, 1.5}. */
    for (size_t k = 0; k < 6; k++)
        for (size_t j = 0; j < 6; j++)
            for (size_t i = 0; i < 6; i++) {
                double p[3];
                st_grid_center(g, i, j, k, p);
                double d = fmax(fabs(p[0] - 1), fmax(fabs(p[1] - 1),
                                                     fabs(p[2] - 1)));
                g->data[st_grid_index(g, i, j, k)] = (float)(d - 0.6);
            }
    st_tetstat r;
    st_tetstat_mesh(&r, m, &err);
    TAP_CHECK(st_tetstat_field(&r, m, g, &err) == ST_OK && r.has_field,
              "field: computed");
    TAP_CHECK(r.mesh_voxels == 125 && r.field_inside == 27 &&
                  r.both_voxels == 27 && r.field_voxels == 216,
              "field: 125 centers in the closed mesh, 27 negative, 27 both "
              "(%zu %zu %zu)", r.mesh_voxels, r.field_inside, r.both_voxels);
    TAP_NEAR(r.iou, 27.0 / 125.0, 1e-15, "field: IoU 27/125");
    st_grid_free(g);
    st_tetmesh_free(m);
}

/* The cubes `pick` (indices i + nx (j + ny k)) of an nx x ny x nz block,
 * sharing its points. */
static st_tetmesh *some_cubes(int nx, int ny, int nz, const int *pick,
                              int npick)
{
    const double o[3] = {0, 0, 0};
    st_tetmesh *all = cubes(o, 1, nx, ny, nz);
    st_tetmesh *m = st_tetmesh_new();
    for (size_t i = 0; i < all->npoints; i++)
        add_pt(m, all->xyz[3 * i], all->xyz[3 * i + 1], all->xyz[3 * i + 2]);
    for (int q = 0; q < npick; q++)
        for (int t = 5 * pick[q]; t < 5 * pick[q] + 5; t++) {
            const uint32_t *v = all->tets + 4 * (size_t)t;
            st_tetmesh_add_tet(m, v[0], v[1], v[2], v[3], NULL);
        }
    st_tetmesh_free(all);
    return m;
}

static void test_contacts(void)
{
    st_tetstat r;
    st_error err;
    const int block[8] = {0, 1, 2, 3, 4, 5, 6, 7};
    st_tetmesh *m = some_cubes(2, 2, 2, block, 8);
    TAP_CHECK(st_tetstat_mesh(&r, m, &err) == ST_OK && r.components == 1 &&
                  r.pinched_edges == 0 && r.pinched_points == 0 &&
                  r.nonmanifold_boundary_edges == 0 &&
                  r.nonmanifold_boundary_points == 0 && r.boundary_manifold,
              "2x2x2 cubes: no contacts, manifold boundary");
    st_tetmesh_free(m);

    const int edge[2] = {0, 3};   /* (0,0,0) and (1,1,0): the edge x=y=1 */
    m = some_cubes(2, 2, 1, edge, 2);
    TAP_CHECK(st_tetstat_mesh(&r, m, &err) == ST_OK && r.components == 2 &&
                  r.pinched_edges == 1 && r.pinched_points == 2 &&
                  r.nonmanifold_boundary_edges == 1 &&
                  r.nonmanifold_boundary_points == 2 && !r.boundary_manifold,
              "two cubes on an edge: 2 components, 1 pinched edge, its 2 "
              "points, 1 non-manifold boundary edge (%zu %zu %zu %zu %zu)",
              r.components, r.pinched_edges, r.pinched_points,
              r.nonmanifold_boundary_edges, r.nonmanifold_boundary_points);
    st_tetmesh_free(m);

    const int corner[2] = {0, 7};   /* share the point (1,1,1) */
    m = some_cubes(2, 2, 2, corner, 2);
    TAP_CHECK(st_tetstat_mesh(&r, m, &err) == ST_OK && r.components == 2 &&
                  r.pinched_edges == 0 && r.pinched_points == 1 &&
                  r.nonmanifold_boundary_edges == 0 &&
                  r.nonmanifold_boundary_points == 1 && !r.boundary_manifold,
              "two cubes on a point: 1 pinched point, 1 non-manifold "
              "boundary point, no edge (%zu %zu %zu %zu %zu)",
              r.components, r.pinched_edges, r.pinched_points,
              r.nonmanifold_boundary_edges, r.nonmanifold_boundary_points);
    st_tetmesh_free(m);

    /* An L of three cubes with a fourth on the corner of the L's notch
     * would be face-joined; a cube hanging by an edge on an L is one
     * component but pinched. */
    const int hang[4] = {0, 1, 2, 7};   /* L in z=0, cube 7 at (1,1,1) */
    m = some_cubes(2, 2, 2, hang, 4);
    TAP_CHECK(st_tetstat_mesh(&r, m, &err) == ST_OK && r.components == 2 &&
                  r.pinched_edges == 2 && !r.boundary_manifold,
              "a cube on an L's two edges: 2 pinched edges (%zu)",
              r.pinched_edges);
    st_tetmesh_free(m);
}

int main(int argc, char **argv)
{
    static const tap_test tests[] = {TAP_TEST(regular), TAP_TEST(cubes), TAP_TEST(bad_tets),
                                     TAP_TEST(surface), TAP_TEST(field), TAP_TEST(contacts),
                                     {0}};
    return tap_main(argc, argv, tests);
}
