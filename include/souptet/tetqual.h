/*
 * tetqual.h - the quality of one tetrahedron: volume, dihedral angles,
 * circumcenter. Constructed values in double (these are measurements, not
 * decisions: decisions use pred.h).
 *
 * Units: model units; volumes in units^3, angles in degrees.
 * Ownership: none: values in, values out.
 * Threads: pure functions, thread-safe.
 * Errors: none; st_tet_circumcenter returns 0 for a flat tet.
 *
 * A tet is given by its four corners p[0..3]; its six edges are
 * (0 1) (0 2) (0 3) (1 2) (1 3) (2 3), and the dihedral angle of edge
 * (i j) is the angle between the two faces that contain it, in degrees,
 * in [0, 180]. A regular tet has all six at acos(1/3) = 70.53 degrees.
 */
#ifndef SOUPTET_TETQUAL_H
#define SOUPTET_TETQUAL_H

#ifdef __cplusplus
extern "C" {
#endif

/* Signed volume (p1-p0).((p2-p0)x(p3-p0))/6: > 0 for the positive
 * orientation of tetmesh.h. */
double st_tet_volume(const double p0[3], const double p1[3],
                     const double p2[3], const double p3[3]);

/* The six dihedral angles in degrees, in the edge order above. A
 * degenerate tet (a face of zero area) gets 0 for the angles it makes
 * undefined, so it always reads as the worst quality. */
void st_tet_dihedrals(const double p0[3], const double p1[3],
                      const double p2[3], const double p3[3],
                      double angles[6]);

/* Smallest and largest of the six dihedral angles (either may be NULL). */
void st_tet_dihedral_range(const double p0[3], const double p1[3],
                           const double p2[3], const double p3[3],
                           double *min_deg, double *max_deg);

/* The circumcenter (the point equidistant from the four corners); returns
 * 0 and the centroid for a flat tet, 1 otherwise. */
int st_tet_circumcenter(const double p0[3], const double p1[3],
                        const double p2[3], const double p3[3],
                        double c[3]);

#ifdef __cplusplus
}
#endif
#endif
