/* test_lattice.c - cubic5 and BCC lattices (conformity, mirrored faces,
 * orientation, volume, dihedral angles, seeded placement) and the density
 * filter on an analytic sphere. */
#include "souptet/grid.h"
#include "souptet/isect.h"
#include "souptet/lattice.h"
#include "souptet/pred.h"
#include "souptet/tetmesh.h"
#include "souptet/tetqual.h"
#include "shapes.h"
#include "cubetets.h"
#include "tap.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#ifdef _OPENMP
#include <omp.h>
#endif

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

static st_lattice *make(st_lattice_kind kind, double h, uint64_t seed, int pad,
                        const double lo[3], const double hi[3])
{
    st_lattice_params p = st_lattice_params_default();
    p.kind = kind;
    p.h = h;
    p.seed = seed;
    p.pad = pad;
    st_lattice *L = NULL;
    st_error err;
    if (st_lattice_build(&L, lo, hi, &p, &err))
        printf("# build failed: %s\n", err.msg);
    return L;
}

static const double *P(const st_lattice *L, size_t t, int c)
{
    return L->xyz + 3 * (size_t)L->tets[4 * t + (size_t)c];
}

static double lattice_volume(const st_lattice *L)
{
    double v = 0;
    for (size_t t = 0; t < L->ntets; t++)
        v += st_tet_volume(P(L, t, 0), P(L, t, 1), P(L, t, 2), P(L, t, 3));
    return v;
}

static size_t negative_tets(const st_lattice *L)
{
    size_t n = 0;
    for (size_t t = 0; t < L->ntets; t++)
        n += !(st_orient3d(P(L, t, 0), P(L, t, 1), P(L, t, 2), P(L, t, 3)) < 0);
    return n;
}

/* Conformity through tetmesh.h: no face on three tets, boundary count. */
static void conformity(const st_lattice *L, const char *what, size_t want_boundary)
{
    st_tetmesh *m = NULL;
    st_error err;
    int ok = st_lattice_to_tetmesh(&m, L, NULL, &err) == ST_OK;
    int64_t *nbr = NULL;
    size_t nonman = 99;
    ok = ok && st_tetmesh_neighbors(m, &nbr, &nonman, &err) == ST_OK;
    size_t bnd = 0, mismatch = 0;
    if (ok)
        for (size_t f = 0; f < 4 * m->ntets; f++) {
            bnd += nbr[f] < 0;
            mismatch += nbr[f] != L->nbr[f];
        }
    TAP_CHECK(ok && nonman == 0 && bnd == want_boundary,
              "%s: conforming (%zu faces on 3+ tets, %zu boundary faces, want %zu)",
              what, nonman, bnd, want_boundary);
    TAP_CHECK(ok && mismatch == 0, "%s: lattice adjacency agrees with st_tetmesh_neighbors", what);
    free(nbr);
    st_tetmesh_free(m);
}

static void test_cubic5(void)
{
    double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
    st_lattice *L = make(ST_LATTICE_CUBIC5, 0.25, 0, 0, lo, hi);
    TAP_CHECK(L && L->ntets == 5 * 64 && L->nverts == 125,
              "cubic5 4x4x4: 320 tets, 125 vertices");
    if (!L)
        return;
    TAP_CHECK(negative_tets(L) == 0, "cubic5: every tet positively oriented (exact)");
    TAP_NEAR(lattice_volume(L), 1.0, 1e-12, "cubic5: volume equals the box's");
    /* 6 sides x 16 squares x 2 triangles */
    conformity(L, "cubic5 4x4x4", 192);
    double dmin = 180, dmax = 0;
    for (size_t t = 0; t < L->ntets; t++) {
        double a, b;
        st_tet_dihedral_range(P(L, t, 0), P(L, t, 1), P(L, t, 2), P(L, t, 3), &a, &b);
        dmin = fmin(dmin, a);
        dmax = fmax(dmax, b);
    }
    TAP_NEAR(dmin, 54.735610317245346, 1e-9, "cubic5: min dihedral atan(sqrt 2)");
    TAP_NEAR(dmax, 90.0, 1e-9, "cubic5: max dihedral 90");
    st_lattice_free(L);

    /* Two cubes side by side: mirrored splits make the shared square's
     * diagonals match, so it is interior (10 boundary squares, 20 faces). A
     * non-mirrored split would leave the 4 triangles of the shared square
     * unmatched (24 boundary faces). */
    double hi2[3] = {2, 1, 1};
    L = make(ST_LATTICE_CUBIC5, 1.0, 0, 0, lo, hi2);
    TAP_CHECK(L && L->ntets == 10, "cubic5 2x1x1: 10 tets");
    if (L) {
        conformity(L, "cubic5 2x1x1 (mirrored cubes)", 20);
        st_lattice_free(L);
    }
}

static void test_bcc(void)
{
    double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
    st_lattice *L = make(ST_LATTICE_BCC, 0.25, 0, 0, lo, hi);
    /* 4 tets per interior face: 3 axes x 3 x 4 x 4 faces */
    TAP_CHECK(L && L->ntets == 4 * 144, "bcc 4x4x4: 576 tets");
    if (!L)
        return;
    TAP_CHECK(negative_tets(L) == 0, "bcc: every tet positively oriented (exact)");
    /* each interior face carries a double pyramid of volume h^3 / 3 */
    TAP_NEAR(lattice_volume(L), 144 * 0.25 * 0.25 * 0.25 / 3, 1e-12,
             "bcc: volume of the 4x4x4 block (144 double pyramids)");
    size_t bad = 0, n60 = 0, n90 = 0;
    for (size_t t = 0; t < L->ntets; t++) {
        double d[6];
        st_tet_dihedrals(P(L, t, 0), P(L, t, 1), P(L, t, 2), P(L, t, 3), d);
        int a = 0, b = 0;
        for (int k = 0; k < 6; k++) {
            if (fabs(d[k] - 60) < 1e-9)
                a++;
            else if (fabs(d[k] - 90) < 1e-9)
                b++;
        }
        bad += !(a == 4 && b == 2);
        n60 += (size_t)a;
        n90 += (size_t)b;
    }
    TAP_CHECK(bad == 0, "bcc: every tet has four 60 and two 90 degree dihedrals "
              "(%zu tets differ; %zu/%zu)", bad, n60, n90);
    /* Boundary: the block's 6 sides, each 4x4 squares; every boundary
     * square's 4 tets... count from the lattice itself and compare. */
    size_t bnd = 0;
    for (size_t f = 0; f < 4 * L->ntets; f++)
        bnd += L->nbr[f] < 0;
    conformity(L, "bcc 4x4x4", bnd);
    size_t full = 0, interior = 0;
    for (size_t v = 0; v < L->nverts; v++) {
        int64_t g[3];
        st_lattice_vertex_coords(L, (uint32_t)v, g);
        int in = 1;
        for (int a = 0; a < 3; a++)
            in &= g[a] >= 2 && g[a] <= 6;   /* interior of the block */
        if (in) {
            interior++;
            full += L->star_off[v + 1] - L->star_off[v] == 24;
        }
    }
    TAP_CHECK(interior > 0 && full == interior,
              "bcc: every interior vertex has a 24-tet snowflake (%zu of %zu)",
              full, interior);
    st_lattice_free(L);
}

static int point_in_lattice(const st_lattice *L, const double p[3])
{
    for (size_t t = 0; t < L->ntets; t++)
        if (st_point_in_tet(p, P(L, t, 0), P(L, t, 1), P(L, t, 2), P(L, t, 3)) != ST_OUTSIDE)
            return 1;
    return 0;
}

static void test_seeded(void)
{
    double lo[3] = {-1, 0, 2}, hi[3] = {1, 0.5, 3};
    for (int kind = 0; kind < 2; kind++) {
        st_lattice *A = make((st_lattice_kind)kind, 0.3, 12345, 1, lo, hi);
        st_lattice *B = make((st_lattice_kind)kind, 0.3, 12345, 1, lo, hi);
        st_lattice *C = make((st_lattice_kind)kind, 0.3, 999, 1, lo, hi);
        const char *kn = kind ? "bcc" : "cubic5";
        TAP_CHECK(A && B && C, "%s: seeded lattices build", kn);
        if (!A || !B || !C)
            continue;
        TAP_CHECK(A->ntets == B->ntets && A->nverts == B->nverts &&
                  memcmp(A->xyz, B->xyz, 3 * A->nverts * sizeof(double)) == 0 &&
                  memcmp(A->tets, B->tets, 4 * A->ntets * sizeof(uint32_t)) == 0,
                  "%s: the same seed gives the same lattice", kn);
        TAP_CHECK(memcmp(A->rot, C->rot, sizeof A->rot) != 0,
                  "%s: another seed rotates differently", kn);
        double RtR = 0;
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++) {
                double s = 0;
                for (int k = 0; k < 3; k++)
                    s += A->rot[3 * k + i] * A->rot[3 * k + j];
                RtR = fmax(RtR, fabs(s - (i == j)));
            }
        double det = A->rot[0] * (A->rot[4] * A->rot[8] - A->rot[5] * A->rot[7]) -
                     A->rot[1] * (A->rot[3] * A->rot[8] - A->rot[5] * A->rot[6]) +
                     A->rot[2] * (A->rot[3] * A->rot[7] - A->rot[4] * A->rot[6]);
        TAP_CHECK(RtR < 1e-14 && fabs(det - 1) < 1e-14, "%s: R is a proper rotation", kn);
        TAP_CHECK(negative_tets(A) == 0, "%s rotated: every tet positively oriented", kn);
        size_t bnd = 0;
        for (size_t f = 0; f < 4 * A->ntets; f++)
            bnd += A->nbr[f] < 0;
        conformity(A, kind ? "bcc rotated" : "cubic5 rotated", bnd);
        int covered = 1;
        for (int c = 0; c < 8; c++) {
            double x[3] = {(c & 1) ? hi[0] : lo[0], (c & 2) ? hi[1] : lo[1],
                           (c & 4) ? hi[2] : lo[2]};
            covered &= point_in_lattice(A, x);
        }
        double mid[3] = {0, 0.25, 2.5};
        covered &= point_in_lattice(A, mid);
        TAP_CHECK(covered, "%s rotated: the lattice covers the box's corners and centre", kn);
        st_lattice_free(A);
        st_lattice_free(B);
        st_lattice_free(C);
    }
}

static double sphere_sdf(const double c[3], double r)
{
    return sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]) - r;
}

/* A signed field of the sphere |x| = r on [-1.5, 1.5]^3. */
static st_grid *sphere_grid(double r, size_t n)
{
    return signed_grid(n, 1.5, sphere_sdf, r);
}

/* st_tet_voxel_count counts the ends of each row's run and what lies
 * between, and with stop_at_inside tests only inside voxels: the counts
 * must be those of a test of every centre (st_point_in_tet), and the stop
 * must say whether one inside centre is in the tet, for tets of a rotated
 * lattice over a sphere's field, with and without the summary. */
static void test_voxel_count_brute(void)
{
    st_grid *g = sphere_grid(1.0, 24);
    double lo[3], hi[3];
    st_lattice_grid_box(g, lo, hi);
    st_lattice *L = g ? make(ST_LATTICE_BCC, st_lattice_h_for_cells(lo, hi, 5), 7, 1, lo, hi)
                      : NULL;
    st_voxel_summary *sum = NULL;
    st_error err;
    int ok = L && st_voxel_summary_build(&sum, g, &err) == ST_OK;
    size_t counted = 0, mixed = 0, bad = 0;
    for (size_t t = 0; ok && t < L->ntets; t++) {
        const double *p0 = P(L, t, 0), *p1 = P(L, t, 1), *p2 = P(L, t, 2), *p3 = P(L, t, 3);
        size_t wm = 0, wM = 0, b0[3], b1[3], n[3] = {g->nx, g->ny, g->nz};
        for (int a = 0; a < 3; a++) {   /* the tet's box and a voxel more */
            double l = fmin(fmin(p0[a], p1[a]), fmin(p2[a], p3[a]));
            double u = fmax(fmax(p0[a], p1[a]), fmax(p2[a], p3[a]));
            double f0 = floor((l - g->origin[a]) / g->voxel) - 1;
            double f1 = ceil((u - g->origin[a]) / g->voxel) + 1;
            b0[a] = f0 < 0 ? 0 : (size_t)f0;
            b1[a] = f1 < 0 ? 0 : (f1 > (double)n[a] - 1 ? n[a] - 1 : (size_t)f1);
        }
        for (size_t k = b0[2]; k <= b1[2]; k++)
            for (size_t j = b0[1]; j <= b1[1]; j++)
                for (size_t i = b0[0]; i <= b1[0]; i++) {
                    double c[3];
                    st_grid_center(g, i, j, k, c);
                    if (st_point_in_tet(c, p0, p1, p2, p3) == ST_OUTSIDE)
                        continue;
                    wM++;
                    wm += g->data[st_grid_index(g, i, j, k)] < 0.0f;
                }
        size_t m, M;
        /* -1 without counting: the tet's box is off the grid */
        int r = st_tet_voxel_count(g, NULL, p0, p1, p2, p3, 0, &m, &M, NULL);
        bad += r < 0 ? wM > 0 : (r != 0 || m != wm || M != wM);
        r = st_tet_voxel_count(g, NULL, p0, p1, p2, p3, 1, &m, &M, NULL);
        bad += r < 0 ? wM > 0 : (r != 0 || (m > 0) != (wm > 0) || M > wM);
        r = st_tet_voxel_count(g, sum, p0, p1, p2, p3, 1, &m, &M, NULL);
        bad += r > 0 ? wm == 0 : (r < 0 ? wm > 0 : (m > 0) != (wm > 0));
        counted++;
        mixed += wm > 0 && wm < wM;
    }
    TAP_CHECK(ok && bad == 0 && mixed > 10,
              "voxel counts equal a test of every centre (%zu tets, %zu across the surface, "
              "%zu wrong)", counted, mixed, bad);
    st_voxel_summary_free(sum);
    st_lattice_free(L);
    st_grid_free(g);
}

static void test_density(void)
{
    const double r = 1.0, vs = 4.0 / 3.0 * M_PI;
    st_grid *g = sphere_grid(r, 60);
    TAP_CHECK(g != NULL, "sphere field");
    if (!g)
        return;
    double lo[3], hi[3];
    st_lattice_grid_box(g, lo, hi);
    st_error err;
    for (int kind = 0; kind < 2; kind++) {
        const char *kn = kind ? "bcc" : "cubic5";
        st_lattice *L = make((st_lattice_kind)kind, st_lattice_h_for_cells(lo, hi, 16), 0, 2, lo, hi);
        st_tetmesh *m = NULL;
        st_density_stats ds;
        int ok = L && st_lattice_density_filter(&m, &ds, L, g, 0.5, &err) == ST_OK;
        double v = ok ? mesh_volume(m) : 0;
        TAP_CHECK(ok && fabs(v - vs) < 0.04 * vs,
                  "%s rho >= 0.5: kept volume %.4f within 4%% of the sphere's %.4f",
                  kn, v, vs);
        st_tetmesh_free(m);
        m = NULL;
        ok = ok && st_lattice_density_filter(&m, &ds, L, g, 1.0, &err) == ST_OK;
        double v1 = ok ? mesh_volume(m) : 0;
        int inside = 1;
        for (size_t p = 0; ok && p < m->npoints; p++) {
            const double *x = m->xyz + 3 * p;
            /* no vertex further out than a cell width */
            inside &= sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]) < r + L->h;
        }
        TAP_CHECK(ok && v1 < v && inside,
                  "%s rho = 1: only tets within the sphere (volume %.4f)", kn, v1);
        st_tetmesh_free(m);
        m = NULL;
        ok = ok && st_lattice_density_filter(&m, &ds, L, g, 0.0, &err) == ST_OK;
        TAP_CHECK(ok && m->ntets == L->ntets, "%s rho >= 0 keeps every tet", kn);
        st_tetmesh_free(m);
        m = NULL;
        /* Determinism across thread counts. */
        double *r1 = malloc(L->ntets * sizeof *r1), *r2 = malloc(L->ntets * sizeof *r2);
#ifdef _OPENMP
        omp_set_num_threads(1);
#endif
        ok = ok && r1 && r2 && st_lattice_density(r1, NULL, L, g, &err) == ST_OK;
#ifdef _OPENMP
        omp_set_num_threads(3);
#endif
        ok = ok && st_lattice_density(r2, NULL, L, g, &err) == ST_OK;
        TAP_CHECK(ok && memcmp(r1, r2, L->ntets * sizeof *r1) == 0,
                  "%s: densities identical on 1 and 3 threads", kn);
        free(r1);
        free(r2);
        st_lattice_free(L);
    }
    /* Cells smaller than a voxel: most tets hold no voxel centre and take
     * their centroid's voxel; the volume still approximates the sphere. */
    st_grid *gc = sphere_grid(r, 12);
    st_lattice_grid_box(gc, lo, hi);
    st_lattice *L = make(ST_LATTICE_CUBIC5, 0.1, 0, 0, lo, hi);
    st_tetmesh *m = NULL;
    st_density_stats ds;
    int ok = gc && L && st_lattice_density_filter(&m, &ds, L, gc, 0.5, &err) == ST_OK;
    double v = ok ? mesh_volume(m) : 0;
    TAP_CHECK(ok && ds.centroid_rule > L->ntets / 2 && fabs(v - vs) < 0.15 * vs,
              "h below the voxel: %zu of %zu tets by the centroid rule, volume %.3f ~ %.3f",
              ok ? ds.centroid_rule : 0, L ? L->ntets : 0, v, vs);
    st_tetmesh_free(m);
    st_lattice_free(L);
    st_grid_free(gc);
    st_grid_free(g);
}

static void test_bad(void)
{
    double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1}, nan3[3] = {NAN, 0, 0};
    st_lattice_params p = st_lattice_params_default();
    st_lattice *L = NULL;
    st_error err;
    p.h = 0;
    TAP_CHECK(st_lattice_build(&L, lo, hi, &p, &err) == ST_EINPUT && !L, "h = 0 is refused");
    p.h = 1;
    TAP_CHECK(st_lattice_build(&L, nan3, hi, &p, &err) == ST_EINPUT && !L, "a NaN box is refused");
    p.h = 1e-4;
    p.max_tets = 1000000;
    TAP_CHECK(st_lattice_build(&L, lo, hi, &p, &err) == ST_ELIMIT && !L,
              "a lattice over max_tets is refused");
    st_lattice_kind k;
    TAP_CHECK(st_lattice_kind_from_name("bcc", &k) == 0 && k == ST_LATTICE_BCC &&
              st_lattice_kind_from_name("cubic", &k) == -1, "lattice names");
}

/* The summary flags a brick inside-only, outside-only or mixed from every
 * voxel of it: one inside voxel anywhere in a row (each place in a brick,
 * the short bricks at the end of a row of 21 too) among outside ones, or
 * one outside (or NaN) among inside ones, must be seen by
 * st_tet_voxel_count's stop through the summary, for a small tet around
 * that voxel's centre. */
static void test_voxel_summary_each_voxel(void)
{
    const double o[3] = {0.25, -1.0, 2.0};
    st_grid *g = NULL;
    st_error err;
    int ok = st_grid_new(&g, 21, 5, 6, o, 0.5, 1.0f, 0, &err) == ST_OK;
    size_t tried = 0, bad = 0;
    for (int sign = 0; ok && sign < 3; sign++) {
        /* sign 0: one inside voxel among outside; 1: one outside among
         * inside; 2: one NaN among inside */
        const float bg = sign ? -1.0f : 1.0f, one = sign == 0 ? -1.0f : sign == 1 ? 1.0f : NAN;
        for (size_t n = 0; n < g->nx * g->ny * g->nz; n++)
            g->data[n] = bg;
        for (size_t k = 1; k < g->nz; k += 3)
            for (size_t j = 0; j < g->ny; j += 2)
                for (size_t i = 0; i < g->nx; i++) {
                    const size_t at = st_grid_index(g, i, j, k);
                    g->data[at] = one;
                    st_voxel_summary *sum = NULL;
                    if (st_voxel_summary_build(&sum, g, &err) != ST_OK) {
                        ok = 0;
                        break;
                    }
                    double c[3], p[4][3];
                    st_grid_center(g, i, j, k, c);
                    static const double d[4][3] = {{-0.1, -0.1, -0.1}, {0.35, -0.1, -0.1},
                                                   {-0.1, 0.35, -0.1}, {-0.1, -0.1, 0.35}};
                    for (int q = 0; q < 4; q++)
                        for (int a = 0; a < 3; a++)
                            p[q][a] = c[a] + d[q][a];
                    size_t m, M;
                    int r = st_tet_voxel_count(g, sum, p[0], p[1], p[2], p[3], 1, &m, &M, NULL);
                    int found = r > 0 || (r == 0 && m > 0);   /* an inside centre in it */
                    if (sign == 0 ? !found : found)
                        TAP_NOTE("sign %d voxel %zu %zu %zu: r %d m %zu M %zu", sign, i, j, k, r, m, M);
                    bad += sign == 0 ? !found : found;
                    tried++;
                    st_voxel_summary_free(sum);
                    g->data[at] = bg;
                }
    }
    TAP_CHECK(ok && bad == 0 && tried == 3 * 21 * 3 * 2,
              "the summary sees one odd voxel at every place of a brick (%zu grids, %zu wrong)",
              tried, bad);
    st_grid_free(g);
}

int main(int argc, char **argv)
{
    static const tap_test tests[] = {TAP_TEST(cubic5), TAP_TEST(bcc), TAP_TEST(seeded),
                                     TAP_TEST(density), TAP_TEST(voxel_count_brute), TAP_TEST(voxel_summary_each_voxel), TAP_TEST(bad), {0}};
    return tap_main(argc, argv, tests);
}
