/*
 * lattice.h - tetrahedral lattices over a box, and the pseudo-volume
 * density filter (Spillmann, Wagner, Teschner 2006, section 4).
 *
 * Units: model units for h and positions; lattice points in integer half
 * cells.
 * Ownership: the caller owns a lattice (st_lattice_free), a voxel summary
 * (st_voxel_summary_free) and any mesh made (st_tetmesh_free); grids and
 * soups are borrowed.
 * Threads: OpenMP in the build and the density filter; the result depends
 * only on the parameters and the seed, not on the thread count.
 * Errors: ST_EINPUT (bad parameters), ST_ELIMIT (over max_bytes or 32-bit
 * indices), ST_ENOMEM, ST_ECANCELLED, ST_EINTERNAL.
 *
 * Two lattices, both of cubes of side h:
 *
 *   cubic5  every cube split into 5 tets: a central tet on the four cube
 *           corners of even global parity (i + j + k even, in corner
 *           coordinates) and four corner tets. Since the central tet of
 *           every cube uses the globally even corners, the split is
 *           mirrored on cubes of odd parity and the diagonals of shared
 *           faces match (Spillmann section 4, after Cutler et al. 2002).
 *           Dihedral angles 54.74 .. 90 degrees (the corner tets) and
 *           70.53 (the central one).
 *   bcc     the body-centred cubic tetrahedralization (Stuart et al. 2013,
 *           section 3.1): vertices at cube corners and cube centres; for
 *           every face shared by two cubes of the block, four tets, each
 *           made of one edge of the face and the two cube centres. All
 *           tets are congruent, with two long edges (h, one between
 *           corners, one between centres) and four short ones (h sqrt(3)/2),
 *           and dihedral angles of 60 (four) and 90 (two) degrees.
 *
 * Integer coordinates. A lattice point has integer coordinates g in half
 * cells: cube corners have even g, cube centres odd g (all three). Its
 * position is x = center + R (offset + g h / 2), with R a rotation and
 * offset a vector in the lattice frame; so vertices are identified by their
 * integer coordinates, never by comparing floats.
 *
 * Placement. With seed 0 the lattice is axis-aligned and its cube corners
 * start at the box's low corner (R = I). With any other seed a
 * deterministic generator (splitmix64, written here) gives a uniformly
 * random rotation (Shoemake's unit quaternion) and an offset uniform within
 * one cell. Either way the lattice covers the box (rotated: its bounding box
 * in the lattice frame) plus `pad` cells on every side, so that the
 * snowflake (star) of every vertex of a tet that meets the box is complete
 * (pad 2 is what sculpting needs: a tet meeting the box has its vertices in
 * cells at most one cell out, and their stars reach one cell further).
 *
 * Every tet is positively oriented (tetmesh.h: signed volume > 0), decided
 * on the integer coordinates (R is a proper rotation).
 */
#ifndef SOUPTET_LATTICE_H
#define SOUPTET_LATTICE_H

#include <stddef.h>
#include <stdint.h>

#include "souptet/err.h"
#include "souptet/grid.h"
#include "souptet/tetmesh.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum st_lattice_kind {
    ST_LATTICE_CUBIC5 = 0,
    ST_LATTICE_BCC
} st_lattice_kind;

/* "cubic5" / "bcc"; from_name returns 0 and sets *kind, or -1. */
const char *st_lattice_kind_name(st_lattice_kind kind);
int st_lattice_kind_from_name(const char *name, st_lattice_kind *kind);

/* Default padding in cells (see Placement above). */
#define ST_LATTICE_PAD_DEFAULT 2
/* What one lattice tet costs at least while a lattice is built (4 uint32
 * vertex ids, 4 int64 neighbours, 4 uint32 star entries), before the mesh
 * made from it: a lattice of more tets than a memory limit over this cannot
 * fit and is refused before it is allocated. */
#define ST_LATTICE_BYTES_PER_TET 64

typedef struct st_lattice_params {
    st_lattice_kind kind;
    double h;            /* cube side, model units, > 0 and finite */
    uint64_t seed;       /* 0: axis-aligned at the box's low corner */
    int pad;             /* cells of padding on every side, >= 0 */
    size_t max_tets;     /* ST_ELIMIT beyond this many tets (0: none) */
    volatile int *cancel;   /* NULL, or a caller's flag (progress.h):
                               once nonzero the build stops (between
                               slices of cells and in the face matching)
                               with ST_ECANCELLED (NULL) */
} st_lattice_params;

/* kind cubic5, h 1, seed 0, pad ST_LATTICE_PAD_DEFAULT, no limit. */
st_lattice_params st_lattice_params_default(void);

/* A lattice and its combinatorics. Vertex ids index every lattice point of
 * the block (corners first, then centres), used or not; xyz has them all.
 * nbr and the star CSR make sculpting local. Read-only after build. */
typedef struct st_lattice {
    st_lattice_kind kind;
    double h;
    uint64_t seed;
    double center[3];    /* rotation centre: the box's centre */
    double rot[9];       /* R, row-major: x = center + R u */
    double offset[3];    /* lattice frame position of g = 0 */
    int64_t cell_lo[3];  /* first cell of the block, in cells from g = 0 */
    size_t n[3];         /* cells along each lattice axis */
    size_t nverts;       /* lattice points of the block */
    double *xyz;         /* 3 * nverts positions */
    size_t ntets;
    uint32_t *tets;      /* 4 * ntets vertex ids, positively oriented */
    int64_t *nbr;        /* 4 * ntets: tet across the face opposite corner
                            i, or -1 on the block's boundary */
    size_t *star_off;    /* nverts + 1 offsets into star */
    uint32_t *star;      /* tets around each vertex, ascending */
} st_lattice;

/* Lay a lattice over the box [lo, hi] (lo <= hi componentwise, finite).
 * ST_EINPUT for a bad box or h, ST_ELIMIT past max_tets or UINT32_MAX
 * vertices. Deterministic for given parameters. */
st_status st_lattice_build(st_lattice **out, const double lo[3],
                           const double hi[3], const st_lattice_params *p,
                           st_error *err);
void st_lattice_free(st_lattice *L);   /* safe on NULL */

/* Integer coordinates (half cells, see above) of vertex v. */
void st_lattice_vertex_coords(const st_lattice *L, uint32_t v, int64_t g[3]);

/* The box a grid covers: voxel extents, origin - voxel/2 to
 * origin + (n - 1/2) voxel. */
void st_lattice_grid_box(const st_grid *g, double lo[3], double hi[3]);

/* Cell width for `cells` cells along the longest side of [lo, hi]. */
double st_lattice_h_for_cells(const double lo[3], const double hi[3],
                              size_t cells);

/* The tets with keep[t] != 0 (keep NULL: all) as a tet mesh: unused
 * vertices dropped, vertices numbered in ascending lattice id, tets in
 * lattice order. meta: "h" (%.17g), "lattice" (kind name), "seed". */
st_status st_lattice_to_tetmesh(st_tetmesh **out, const st_lattice *L,
                                const unsigned char *keep, st_error *err);

/* ---- voxels in a tet (shared by the density filter and sculpting) ----
 *
 * A summary of a signed grid in bricks of ST_VOXEL_BRICK^3 voxels (whether
 * each brick has inside and outside voxels), so that a tet whose bounding
 * box lies in bricks that all agree is decided without point tests. */
#define ST_VOXEL_BRICK 4
typedef struct st_voxel_summary st_voxel_summary;
st_status st_voxel_summary_build(st_voxel_summary **out, const st_grid *g,
                                 st_error *err);
void st_voxel_summary_free(st_voxel_summary *s);   /* safe on NULL */

/* Count the voxel centres in the closed tet (p0 p1 p2 p3) (exact test,
 * st_point_in_tet): *M all of them, *m those inside (value < 0). With
 * stop_at_inside, stop at the first inside one (*m is then 0 or 1 and *M a
 * lower bound). *tests (may be NULL) grows by the point tests made.
 * Returns 0 when it counted; -1 (or +1) without counting when the summary
 * shows every voxel of the tet's voxel box - which includes every voxel
 * centre in the tet and the voxels of its centroid and corners - outside
 * (inside); then *m = 0 and *M = 0. s may be NULL (always count). */
int st_tet_voxel_count(const st_grid *g, const st_voxel_summary *s,
                       const double p0[3], const double p1[3],
                       const double p2[3], const double p3[3],
                       int stop_at_inside, size_t *m, size_t *M,
                       size_t *tests);

/* ---- density filter (Spillmann section 4) ----
 *
 * rho(T) = m / M, where M counts the voxels "in" tet T - those whose centre
 * lies in the closed tet (st_point_in_tet, exact) - and m those of them that
 * are inside the pseudo volume (value < 0). A tet that contains no voxel
 * centre at all (h near or below the voxel size, or a tet outside the grid)
 * takes the value of the voxel that contains its centroid: rho = 1 when that
 * voxel is inside, 0 when it is outside or the centroid is off the grid.
 * The voxels are visited over each tet's bounding box; bricks of voxels
 * that are all inside or all outside answer without point tests when the
 * whole box agrees. OpenMP over tets; the result does not depend on the
 * thread count. */

typedef struct st_density_stats {
    size_t lattice_tets;     /* tets in the lattice */
    size_t kept;             /* tets with rho >= rho_min */
    size_t centroid_rule;    /* tets decided by their centroid's voxel */
    size_t point_tests;      /* voxel centres tested against a tet */
} st_density_stats;

/* rho[t] for every lattice tet (rho has L->ntets slots); stats may be
 * NULL. g must be a signed field. */
st_status st_lattice_density(double *rho, st_density_stats *stats,
                             const st_lattice *L, const st_grid *g,
                             st_error *err);

/* Build the mesh of the tets with rho >= rho_min (rho_min in [0, 1]),
 * with the per-cell array "density" (rho) and meta "rho_min" besides those
 * of st_lattice_to_tetmesh. stats may be NULL. */
st_status st_lattice_density_filter(st_tetmesh **out, st_density_stats *stats,
                                    const st_lattice *L, const st_grid *g,
                                    double rho_min, st_error *err);

/* ---- one piece per piece: the density filter's cleanup ----
 *
 * rho alone keeps tets that hang on the rest by an edge or a point, islands
 * the pseudo volume does not have, and breaks a part where it is about one
 * cell thin. st_lattice_density_clean edits keep (1: kept) so that
 *
 *   the boundary is 2-manifold: at every lattice vertex the kept tets of
 *   its star make one group through the faces at the vertex and so do the
 *   others (on the link sphere, a connected set with a connected complement
 *   is a disc: no pinched point, no edge in four boundary faces). A bad
 *   vertex is mended the cheaper way: fill (keep its whole star; cost the
 *   sum of (1 - rho) vol over the tets added), allowed only when the kept
 *   tets there do not belong to two pieces of the pseudo volume; or drop
 *   (every kept group of the star but the heaviest in rho vol; cost the
 *   sum of rho vol dropped), not allowed on tets a join added;
 *
 *   every face-connected piece is the main piece of a piece of the pseudo
 *   volume (its 6-connected inside voxels; a tet belongs to the piece of
 *   the voxel of its centroid, else of an inside voxel at a corner): each
 *   voxel piece's main tet piece is the one holding most of its rho vol.
 *   Any other tet piece is joined to the main piece of its voxel piece
 *   along the cheapest face path (Dijkstra, cost (1 - rho) vol + tiny) when
 *   that costs less than its own rho vol, and dropped otherwise.
 *
 * The two alternate until nothing changes (at most ST_CLEAN_ROUNDS rounds
 * of each). Deterministic (serial, in vertex and tet order).
 *
 * A voxel piece whose tets hold less than ST_CLEAN_HELD of its volume is
 * "too thin" for the lattice (unless it is a speck, see below): it is
 * listed in stats (up to
 * ST_CLEAN_MAX_THIN of them) with its box, its thickness (twice its
 * deepest voxel's distance to the surface, plus a voxel: that centre is
 * within half a voxel of the middle) and the --cells along the box's
 * longest side at which h is half that thickness. */
/* A piece of the pseudo volume smaller than this many h^3 (a cubic5
 * corner tet is h^3 / 6) is a speck no lattice tet can hold: counted, not
 * listed as too thin (damaged soups leave a few voxels here and there). */
#define ST_CLEAN_SPECK (1.0 / 6.0)
#define ST_CLEAN_ROUNDS 32
#define ST_CLEAN_HELD 0.5
#define ST_CLEAN_MAX_THIN 8

typedef struct st_thin_part {
    size_t voxels;           /* inside voxels of the piece */
    double lo[3], hi[3];     /* its box (voxel extents), model units */
    double thickness;        /* 2 x max depth inside + 1 voxel */
    double held;             /* volume of its tets / its voxels' volume */
    size_t cells;            /* --cells at which h = thickness / 2 */
} st_thin_part;

typedef struct st_density_clean_stats {
    size_t pieces;           /* 6-connected pieces of the pseudo volume */
    size_t tet_pieces;       /* face-connected pieces of the kept tets */
    size_t filled, dropped;  /* tets added / removed at bad vertices */
    size_t joins, join_tets; /* pieces joined and the tets the paths add */
    size_t islands, island_tets;  /* pieces dropped and their tets */
    size_t bad_vertices_left;     /* non-manifold vertices at the end */
    size_t nthin;            /* voxel pieces too thin (all of them) */
    size_t specks, speck_voxels;  /* pieces under ST_CLEAN_SPECK h^3 */
    st_thin_part thin[ST_CLEAN_MAX_THIN];   /* the first of them */
} st_density_clean_stats;

/* Clean keep (L->ntets slots, 0/1) as above; rho the densities of
 * st_lattice_density, g the signed field they came from, longest the
 * longest side of the box the lattice was laid over (for thin[].cells).
 * stats may be NULL. ST_ENOMEM only. */
st_status st_lattice_density_clean(unsigned char *keep,
                                   st_density_clean_stats *stats,
                                   const st_lattice *L, const st_grid *g,
                                   const double *rho, double longest,
                                   st_error *err);

/* st_lattice_density_filter with the cleanup when clean is nonzero (cs
 * may be NULL). */
st_status st_lattice_density_filter_clean(st_tetmesh **out,
                                          st_density_stats *stats,
                                          st_density_clean_stats *cs,
                                          const st_lattice *L,
                                          const st_grid *g, double rho_min,
                                          int clean, st_error *err);

#ifdef __cplusplus
}
#endif
#endif
