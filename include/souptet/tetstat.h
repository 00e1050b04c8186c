/*
 * tetstat.h - the quality and fit of a tet mesh: the metrics of DESIGN.md
 * ("Metrics"), computed into a struct (the tetstat tool prints them). The
 * quality and stopping measures of Stuart 2013, section 4, and the IoU
 * against the pseudo volume.
 *
 * Units: model units; angles in degrees; ratios where said.
 * Ownership: the caller owns *out (a plain struct); mesh, soup and field
 * are borrowed.
 * Threads: OpenMP inside; deterministic for any thread count (below).
 * Errors: ST_ENOMEM, and what enclose.h and bvh.h return (ST_EINPUT for an
 * empty surface).
 *
 * Over the mesh (st_tetstat_mesh):
 *   counts of tets and points (and points no tet uses), bounds;
 *   min and max dihedral angle over all tets, and a histogram of each
 *   tet's smallest dihedral angle in 10-degree bins;
 *   inverted tets (st_orient3d > 0: negative orientation, see tetmesh.h)
 *   and degenerate tets (st_orient3d exactly 0), both decided exactly;
 *   conformity: faces shared by more than two tets (non-manifold faces),
 *   interior faces (shared by exactly two), boundary faces (one tet);
 *   connected components (tets joined through interior faces);
 *   contacts: pinched points and edges, around which the tets fall in
 *   more than one group joined through faces (a tet hanging on the rest by
 *   an edge pinches that edge and its two points; by a point, that point);
 *   the boundary faces' non-manifold edges (in other than two boundary
 *   faces) and non-manifold points (whose boundary faces do not make one
 *   closed fan: pinched, or on a non-manifold edge);
 *   total signed volume; the lattice cell width h from meta "h".
 * Against a surface S (st_tetstat_surface):
 *   min/max/mean distance from the boundary vertices of the mesh to S
 *   (Cetra's columns; exact point-triangle distances through a BVH), and
 *   with offset_ratio R and h known, how many boundary vertices are
 *   farther than R h from S (Cetra's stopping condition: none);
 *   max distance from S to the mesh boundary, sampled at every vertex of
 *   S and at ST_TETSTAT_TRI_SAMPLES interior points of every triangle of S
 *   (so a lost feature shows even between vertices); S's box diagonal
 *   (both distances are also reported relative to it and to h);
 *   the volume of S, by the divergence theorem, only when S is closed and
 *   consistently oriented (soupinfo.h), and the ratio mesh / S;
 *   enclosure (enclose.h): the fraction of S's vertices inside the closed
 *   mesh and the number of S triangles that meet a boundary face (exact;
 *   a triangle touching the boundary counts as crossing).
 * Against a signed field F (st_tetstat_field):
 *   IoU of the voxels whose centers lie in the mesh (exact point in tet)
 *   and the voxels with a negative value.
 *
 * All of it is deterministic and does not depend on the thread count.
 */
#ifndef SOUPTET_TETSTAT_H
#define SOUPTET_TETSTAT_H

#include <stddef.h>

#include "souptet/err.h"
#include "souptet/grid.h"
#include "souptet/soup.h"
#include "souptet/tetmesh.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Bins of 10 degrees for the per-tet smallest dihedral angle: [0,10),
 * [10,20), ..., [80,90]. A tet's smallest angle is at most 70.53 (the
 * regular tet), so the last bins stay empty for any real mesh. */
#define ST_TETSTAT_BINS 9
#define ST_TETSTAT_BIN_DEG 10.0

/* Interior points of each triangle of S at which S-to-boundary distance
 * is sampled besides its corners: the centroid and the three points
 * halfway between it and each corner. */
#define ST_TETSTAT_TRI_SAMPLES 4

typedef struct st_tetstat {
    /* mesh */
    size_t tets, points, unused_points;
    double lo[3], hi[3];          /* bounds of the used points (0 if none) */
    double min_dihedral, max_dihedral;   /* degrees; NAN with no tets */
    size_t hist[ST_TETSTAT_BINS];        /* per-tet min dihedral */
    size_t inverted, degenerate;
    size_t nonmanifold_faces, interior_faces, boundary_faces;
    int conforming;               /* no non-manifold face */
    size_t components;
    size_t pinched_points, pinched_edges;  /* tets meet only through them */
    size_t nonmanifold_boundary_edges, nonmanifold_boundary_points;
    int boundary_manifold;        /* both counts above are 0 */
    double volume;                /* sum of signed tet volumes */
    int has_h;
    double h;                     /* meta "h" when it is a number */

    /* against a surface (has_surface) */
    int has_surface;
    size_t surface_vertices, surface_triangles;
    size_t boundary_vertices;
    double dist_min, dist_max, dist_mean;  /* boundary vertices -> S */
    double surface_dist_max;               /* S -> boundary */
    double surface_diag;          /* diagonal of S's bounding box */
    double offset_ratio;          /* R of the condition: meta "offset_ratio"
                                     (st_tetstat_mesh), or set by the caller
                                     before st_tetstat_surface; NAN: none */
    int has_offset;               /* R and h known: the count below */
    size_t beyond_offset;         /* boundary vertices farther than R h */
    int surface_closed;           /* S closed and consistently oriented */
    double surface_volume;        /* |signed volume of S|; NAN if not closed */
    double volume_ratio;          /* volume / surface_volume; NAN if n/a */
    int has_enclosure;            /* the two counts below were computed */
    size_t vertices_inside;       /* S vertices in the closed mesh */
    double fraction_inside;       /* vertices_inside / surface_vertices */
    size_t crossing_triangles;    /* S triangles meeting the boundary */
    int encloses;                 /* all inside and none crossing, and
                                     enclosure_verified */
    int enclosure_verified;       /* no inverted or flat tet and conforming:
                                     only then do the two counts prove
                                     enclosure (enclose.h); with clean
                                     counts and 0 here the answer is
                                     "unverified", not "encloses" */

    /* against a surface and the fill of a signed field (has_fill,
       st_tetstat_fill): boundary vertices -> S or the fill, whichever is
       nearer, as soupmesh's condition measures them */
    int has_fill;
    size_t fill_faces;            /* voxel squares of the fill */
    double fill_dist_max;         /* boundary vertices -> S or the fill */
    size_t beyond_offset_fill;    /* of them farther than R h (has_offset) */

    /* against a signed field (has_field) */
    int has_field;
    size_t field_voxels, field_inside, mesh_voxels, both_voxels;
    double iou;                   /* both / (field + mesh - both); 1 if 0/0 */
} st_tetstat;

/* Fill the mesh part of *out (and reset the rest). */
st_status st_tetstat_mesh(st_tetstat *out, const st_tetmesh *m,
                          st_error *err);

/* Fill the surface part of *out for surface s (at least one triangle).
 * Call st_tetstat_mesh on *out first: encloses needs its inverted,
 * degenerate and nonmanifold_faces counts, the condition its h and
 * offset_ratio (which the caller may set in between). */
st_status st_tetstat_surface(st_tetstat *out, const st_tetmesh *m,
                             const st_soup *s, st_error *err);

/* The largest distance from S to the boundary of m (surface_dist_max
 * alone: S's vertices and ST_TETSTAT_TRI_SAMPLES points per triangle). */
st_status st_tetstat_surface_to_boundary(double *out, const st_tetmesh *m,
                                         const st_soup *s, st_error *err);

/* The fill part of *out: the fill of the signed field f against s
 * (st_pseudo_fill: where f's pseudo volume has a boundary and s no
 * surface) and the boundary vertices' distances to s or the fill,
 * whichever is nearer - the distance soupmesh's stopping condition takes
 * (pipeline.h, fill_counts); beyond_offset_fill counts them against R h
 * when has_offset (call st_tetstat_surface first). */
st_status st_tetstat_fill(st_tetstat *out, const st_tetmesh *m,
                          const st_soup *s, const st_grid *f, st_error *err);

/* Fill the field part of *out for a signed field f. */
st_status st_tetstat_field(st_tetstat *out, const st_tetmesh *m,
                           const st_grid *f, st_error *err);

#ifdef __cplusplus
}
#endif
#endif
