/* test_fair.c - st_fair: volume kept, nothing inverted, corners rounded,
 * deterministic for any thread count. Meshes are blocks of 5-tet cubes
 * built here. */
#include "../src/tet/smooth_mesh.h"
#include "souptet/geom.h"
#include "souptet/pred.h"
#include "souptet/smooth.h"
#include "souptet/tetmesh.h"
#include "souptet/tetqual.h"
#include "cubetets.h"
#include "tap.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#ifdef _OPENMP
#include <omp.h>
#endif

static uint64_t rng_state = 88172645463325252ull;
static double rnd(void)   /* xorshift64, uniform in [0, 1) */
{
    rng_state ^= rng_state << 13;
    rng_state ^= rng_state >> 7;
    rng_state ^= rng_state << 17;
    return (double)(rng_state >> 11) / 9007199254740992.0;
}

static int in_ball(const double c[3], void *ctx)
{
    double r = *(const double *)ctx;
    return c[0] * c[0] + c[1] * c[1] + c[2] * c[2] < r * r;
}

static void test_block(void)
{
    double lo[3] = {0, 0, 0};
    st_tetmesh *m = lattice5(4, 1.0, lo, NULL, NULL);
    TAP_CHECK(m->ntets == 320 && nonpositive(m) == 0, "a 4^3 block of 5-tet cubes: 320 positive tets");
    double v0 = mesh_volume(m);
    st_fair_stats st;
    st_error err;
    st_fair_params p = st_fair_params_default();
    st_status s = st_fair(m, &p, &st, NULL, &err);
    TAP_CHECK(s == ST_OK, "fairing a block succeeds (%s)", s ? err.msg : "ok");
    TAP_CHECK(nonpositive(m) == 0, "no tet inverted or flat after fairing");
    double v1 = mesh_volume(m);
    TAP_NEAR(v1 / v0, 1.0, 0.005, "volume kept within 0.5%% (%.5f)", v1 / v0);
    TAP_NEAR(st.volume_before, v0, 1e-9 * v0, "stats: volume before is the tet sum");
    TAP_NEAR(st.volume_after, v1, 1e-9 * v0, "stats: volume after is the tet sum");
    /* the corner (0,0,0) is point 0 (compact keeps the order): it moves
     * inward, the block's corners get rounded */
    double d = sqrt(m->xyz[0] * m->xyz[0] + m->xyz[1] * m->xyz[1] + m->xyz[2] * m->xyz[2]);
    TAP_CHECK(d > 0.1, "the block's corner moved inward (by %.3f)", d);
    /* the middle vertex (2,2,2) is interior: it stays near the middle */
    size_t mid = 2 + 5 * (2 + 5 * 2);
    TAP_NEAR(m->xyz[3 * mid], 2.0, 0.3, "the centre stays near the centre (x %.3f)", m->xyz[3 * mid]);
    TAP_CHECK(st.min_dihedral_after > 0.0 && st.max_dihedral_after < 180.0,
              "dihedral range after: %.1f..%.1f", st.min_dihedral_after, st.max_dihedral_after);
    TAP_NOTE("block: %d iters, %zu moves, %zu back-offs, %zu stuck, dihedral %.1f-%.1f -> %.1f-%.1f",
             st.iters, st.moves, st.backoffs, st.stuck, st.min_dihedral_before,
             st.max_dihedral_before, st.min_dihedral_after, st.max_dihedral_after);
    st_tetmesh_free(m);
}

static void test_ball_many_iters(void)
{
    double lo[3] = {-3, -3, -3}, r = 2.2;
    st_tetmesh *m = lattice5(6, 1.0, lo, in_ball, &r);
    double v0 = mesh_volume(m);
    st_fair_params p = st_fair_params_default();
    p.iters = 10;
    p.lambda_dt = 3.0;   /* strong: a ball of 280 tets loses most of its volume */
    st_fair_stats st;
    st_error err;
    st_status s = st_fair(m, &p, &st, NULL, &err);
    TAP_CHECK(s == ST_OK, "strong fairing of a blocky ball succeeds (%s)", s ? err.msg : "ok");
    TAP_CHECK(nonpositive(m) == 0, "strong fairing inverts nothing");
    TAP_NEAR(mesh_volume(m) / v0, 1.0, 0.005, "strong fairing keeps the volume (%.5f)",
             mesh_volume(m) / v0);
    TAP_NOTE("ball: %zu tets, %zu back-offs, %zu stuck, dihedral %.1f-%.1f -> %.1f-%.1f",
             m->ntets, st.backoffs, st.stuck, st.min_dihedral_before, st.max_dihedral_before,
             st.min_dihedral_after, st.max_dihedral_after);
    st_tetmesh_free(m);
}

static int in_slab(const double c[3], void *ctx)
{
    (void)ctx;
    return c[2] < 1.0;   /* one cell thick */
}

static void test_thin_slab(void)
{
    /* a slab one cell thick: its boundary vertices are all on the rim or
     * the faces, and strong fairing would fold it; the back-off must hold */
    double lo[3] = {0, 0, 0};
    st_tetmesh *m = lattice5(6, 1.0, lo, in_slab, NULL);
    double v0 = mesh_volume(m);
    st_fair_params p = st_fair_params_default();
    p.lambda_dt = 20.0;
    st_fair_stats st;
    st_error err;
    st_status s = st_fair(m, &p, &st, NULL, &err);
    TAP_CHECK(s == ST_OK && st.backoffs > 0, "strong fairing of a thin slab backs off (%zu halvings)",
              st.backoffs);
    TAP_CHECK(nonpositive(m) == 0, "the slab has no inverted or flat tet");
    TAP_NEAR(mesh_volume(m) / v0, 1.0, 0.005, "the slab keeps its volume (%.5f)", mesh_volume(m) / v0);
    TAP_CHECK(st.min_dihedral_after >= p.min_angle, "no angle below the floor of %g degrees: %.2f",
              p.min_angle, st.min_dihedral_after);
    st_tetmesh_free(m);
}

static void test_keeps_30(void)
{
    /* The default fairing of a blocky ball ends with every dihedral angle
     * in [30, 140] (the simulator's bounds) and the volume within 1%; the
     * quality pass, boundary vertices included (tangent moves), leaves the
     * worst tet above where the fairing's floor stopped it. */
    double lo[3] = {-4, -4, -4}, r = 3.3;
    st_tetmesh *m = lattice5(8, 1.0, lo, in_ball, &r);
    double v0 = mesh_volume(m);
    st_fair_stats st;
    st_error err;
    st_status s = st_fair(m, NULL, &st, NULL, &err);
    TAP_CHECK(s == ST_OK && nonpositive(m) == 0, "default fairing of a ball of %zu tets",
              m->ntets);
    TAP_CHECK(st.min_dihedral_after >= 30.0 && st.max_dihedral_after <= 140.0,
              "angles after fairing in [30, 140]: %.2f..%.2f", st.min_dihedral_after,
              st.max_dihedral_after);
    TAP_NEAR(mesh_volume(m) / v0, 1.0, 0.01, "volume within 1%% (%.5f)", mesh_volume(m) / v0);
    TAP_CHECK(st.quality_moves > 0 && st.min_dihedral_after >= st.min_dihedral_fair &&
                  st.max_dihedral_after <= st.max_dihedral_fair,
              "the quality pass moved (%zu) and did not worsen %.2f..%.2f -> %.2f..%.2f",
              st.quality_moves, st.min_dihedral_fair, st.max_dihedral_fair,
              st.min_dihedral_after, st.max_dihedral_after);
    st_tetmesh_free(m);
}

static void test_threads(void)
{
#ifdef _OPENMP
    double lo[3] = {-3, -3, -3}, r = 2.6;
    st_tetmesh *a = lattice5(6, 1.0, lo, in_ball, &r);
    st_tetmesh *b = lattice5(6, 1.0, lo, in_ball, &r);
    int nt = omp_get_max_threads();
    st_error err;
    omp_set_num_threads(1);
    st_status s1 = st_fair(a, NULL, NULL, NULL, &err);
    omp_set_num_threads(3);
    st_status s2 = st_fair(b, NULL, NULL, NULL, &err);
    omp_set_num_threads(nt);
    TAP_CHECK(s1 == ST_OK && s2 == ST_OK && a->npoints == b->npoints &&
                  memcmp(a->xyz, b->xyz, 3 * a->npoints * sizeof(double)) == 0,
              "1 and 3 threads give bit-identical points");
    st_tetmesh_free(a);
    st_tetmesh_free(b);
#else
    TAP_CHECK(1, "1 and 3 threads give bit-identical points # SKIP no OpenMP");
#endif
}

static void test_refusals(void)
{
    double lo[3] = {0, 0, 0};
    st_tetmesh *m = lattice5(1, 1.0, lo, NULL, NULL);
    uint32_t s = m->tets[0];
    m->tets[0] = m->tets[1];
    m->tets[1] = s;
    st_error err;
    st_status rc = st_fair(m, NULL, NULL, NULL, &err);
    TAP_CHECK(rc == ST_EINPUT && strstr(err.msg, "inverted"), "an inverted tet is refused (%s)", err.msg);
    st_tetmesh *e = st_tetmesh_new();
    rc = st_fair(e, NULL, NULL, NULL, &err);
    TAP_CHECK(rc == ST_EINPUT, "a mesh without tets is refused");
    st_tetmesh_free(m);
    st_tetmesh_free(e);
}

/* sm_star_score skips the atan2 of tets that cannot hold the star's
 * extreme angles and shares cross products between edges: its value must
 * still be the minimum of sm_tet_score over the star, bit for bit, for
 * round, sliver, flat and needle tets, and for stars past its block of 64
 * tets. */
static void test_star_score_is_min(void)
{
    enum { NT = 150, NTRIAL = 40 };
    st_tetmesh *m = st_tetmesh_new();
    double o[3] = {0, 0, 0};
    st_tetmesh_add_point(m, o, NULL);
    for (int t = 0; t < NT; t++) {
        double q[3][3];
        for (int i = 0; i < 3; i++)
            for (int a = 0; a < 3; a++)
                q[i][a] = 2.0 * rnd() - 1.0;
        int kind = t % 5;
        if (kind == 1)        /* sliver: the third corner near the plane of the others and v */
            for (int a = 0; a < 3; a++)
                q[2][a] = 0.5 * q[0][a] + 0.4 * q[1][a] + 1e-7 * rnd();
        else if (kind == 2)   /* exactly flat: the third corner on a line */
            for (int a = 0; a < 3; a++)
                q[2][a] = 2.0 * q[0][a] - q[1][a];
        else if (kind == 3)   /* needle: two corners nearly together */
            for (int a = 0; a < 3; a++)
                q[1][a] = q[0][a] + 1e-9 * rnd();
        uint32_t c[3];
        for (int i = 0; i < 3; i++) {
            c[i] = (uint32_t)m->npoints;
            st_tetmesh_add_point(m, q[i], NULL);
        }
        st_tetmesh_add_tet(m, 0, c[0], c[1], c[2], NULL);
    }
    sm_mesh sm;
    memset(&sm, 0, sizeof sm);
    size_t off[2] = {0, NT};
    uint32_t vt[NT];
    for (uint32_t t = 0; t < NT; t++)
        vt[t] = t;
    sm.m = m;
    sm.nv = m->npoints;
    sm.nt = m->ntets;
    sm.vt_off = off;
    sm.vt = vt;
    /* windows of the tet list as stars: single tets (each kind alone),
     * a few, exactly a block, past a block, all */
    static const int lens[] = {1, 1, 2, 3, 4, 5, 9, 64, 65, 130, NT};
    int same = 1, tested = 0, finite_lo = 0, above_ok = 1, above_below = 0, above_first = 1;
    for (size_t k = 0; k < sizeof lens / sizeof lens[0]; k++) {
        for (int trial = 0; trial < NTRIAL; trial++) {
            int len = lens[k], start = (int)(rnd() * (NT - len + 1));
            sm.vt = vt + start;
            off[1] = (size_t)len;
            double p[3], scale = trial < 5 ? 0.0 : pow(10.0, -3.0 - (double)(trial % 8));
            for (int a = 0; a < 3; a++)
                p[a] = scale * (2.0 * rnd() - 1.0);
            double want = INFINITY;
            for (int t = start; t < start + len; t++) {
                const uint32_t *tc = m->tets + 4 * (size_t)t;
                double sc = sm_tet_score(p, m->xyz + 3 * (size_t)tc[1], m->xyz + 3 * (size_t)tc[2],
                                         m->xyz + 3 * (size_t)tc[3]);
                if (sc < want)
                    want = sc;
            }
            double got = sm_star_score(&sm, 0, p);
            if (memcmp(&got, &want, sizeof got) != 0)
                same = 0;
            /* sm_star_score_above: the score itself above the threshold,
             * at most the threshold otherwise; thresholds at the score,
             * an ulp either side, anywhere, and outside (0, 60) */
            double thr[6] = {want, nextafter(want, -INFINITY), nextafter(want, INFINITY),
                             60.0 * rnd(), want + 0.5 * (rnd() - 0.5), 90.0};
            for (int i = 0; i < 6; i++) {
                size_t first = (size_t)(rnd() * (len + 1));   /* len: none */
                double a = sm_star_score_above(&sm, 0, p, first, thr[i]);
                if (want > thr[i] ? memcmp(&a, &want, sizeof a) != 0
                                  : !(a <= thr[i] && a >= want))
                    above_ok = 0;
                /* at or below: the score of the first tet there, tet
                 * `first` first, then the others in order (what the
                 * quality pass sorts its bounds by) */
                if (!(want > thr[i])) {
                    double w = INFINITY;
                    for (int r = -1; r < len && !(w <= thr[i]); r++) {
                        int t = r < 0 ? start + (int)first : start + r;
                        if ((r < 0 && (int)first >= len) || (r >= 0 && r == (int)first))
                            continue;
                        const uint32_t *tc = m->tets + 4 * (size_t)t;
                        w = sm_tet_score(p, m->xyz + 3 * (size_t)tc[1],
                                         m->xyz + 3 * (size_t)tc[2], m->xyz + 3 * (size_t)tc[3]);
                    }
                    if (memcmp(&a, &w, sizeof a) != 0)
                        above_first = 0;
                }
                above_below += !(want > thr[i]);
            }
            tested++;
            finite_lo += want > 0.0 && want < 60.0;
        }
    }
    sm.vt = vt;
    TAP_CHECK(above_ok && above_below > tested && above_below < 5 * tested,
              "the star score above a threshold is the score, or at most the threshold "
              "and at least the score (%d of %d thresholds at or above the score)",
              above_below, 6 * tested);
    TAP_CHECK(above_first, "at or below the threshold, the star score above it is the score of "
              "the first tet there (the given one first), bit for bit");
    TAP_CHECK(same && finite_lo > tested / 8,
              "the star score is the minimum of the tet scores, bit for bit (%d stars, %d "
              "with a non-zero score)", tested, finite_lo);
    /* and sm_tet_score is st_tet_dihedral_range's min(min, W (180 - max)) */
    double worst = 0.0;
    for (int t = 0; t < NT; t++) {
        const uint32_t *tc = m->tets + 4 * (size_t)t;
        const double *q0 = m->xyz + 3 * (size_t)tc[0], *q1 = m->xyz + 3 * (size_t)tc[1],
                     *q2 = m->xyz + 3 * (size_t)tc[2], *q3 = m->xyz + 3 * (size_t)tc[3];
        double lo, hi;
        st_tet_dihedral_range(q0, q1, q2, q3, &lo, &hi);
        double want = fmin(lo, ST_FIT_MAX_WEIGHT * (180.0 - hi));
        double d = fabs(sm_tet_score(q0, q1, q2, q3) - want);
        if (!(d <= worst))
            worst = d;
    }
    TAP_CHECK(worst < 1e-9, "the tet score agrees with the dihedral range (%.3g degrees)", worst);
    st_tetmesh_free(m);
}

/* The score as the pair formula gives it one edge at a time (tetqual.c's
 * u = e x f, v = e x g per edge, |u x v| by st_norm3's scaled norm, u . v),
 * the extreme pairs chosen by x_i y_j against x_j y_i in edge order, and
 * st_tet_dihedral_range for a degenerate tet: the value sm_tet_score must
 * give bit for bit however it computes the pairs (two edges per SSE2
 * operation where there is SSE2). */
static double norm_ref(const double w[3])
{
    double m = fabs(w[0]);
    double b = fabs(w[1]) > fabs(w[2]) || isnan(fabs(w[2])) ? fabs(w[1]) : fabs(w[2]);
    m = m > b || isnan(b) ? m : b;
    if (!(m > 0.0) || !isfinite(m))
        return m;
    double x = w[0] / m, y = w[1] / m, z = w[2] / m;
    return m * sqrt(x * x + y * y + z * z);
}

static double score_ref(const double *p0, const double *p1, const double *p2, const double *p3)
{
    const double *P[4] = {p0, p1, p2, p3};
    static const int E[6][4] = {{0, 1, 2, 3}, {0, 2, 1, 3}, {0, 3, 1, 2},
                                {1, 2, 0, 3}, {1, 3, 0, 2}, {2, 3, 0, 1}};
    double y[6], x[6];
    int ok = 1;
    for (int i = 0; i < 6 && ok; i++) {
        double e[3], f[3], g[3], u[3], v[3], w[3];
        for (int k = 0; k < 3; k++) {
            e[k] = P[E[i][1]][k] - P[E[i][0]][k];
            f[k] = P[E[i][2]][k] - P[E[i][0]][k];
            g[k] = P[E[i][3]][k] - P[E[i][0]][k];
        }
        st_cross3(u, e, f);
        st_cross3(v, e, g);
        st_cross3(w, u, v);
        y[i] = norm_ref(w);
        x[i] = st_dot3(u, v);
        ok = y[i] > 0.0 && isfinite(y[i]) && isfinite(x[i]);
    }
    double lo, hi;
    if (!ok) {
        st_tet_dihedral_range(p0, p1, p2, p3, &lo, &hi);
    } else {
        int imin = 0, imax = 0;
        for (int i = 1; i < 6; i++) {
            if (x[i] * y[imin] > x[imin] * y[i])
                imin = i;
            if (x[i] * y[imax] < x[imax] * y[i])
                imax = i;
        }
        lo = atan2(y[imin], x[imin]) * (180.0 / 3.14159265358979323846);
        hi = atan2(y[imax], x[imax]) * (180.0 / 3.14159265358979323846);
    }
    double s2 = ST_FIT_MAX_WEIGHT * (180.0 - hi);
    return lo < s2 ? lo : s2;
}

/* Tets of every kind the passes meet and some they should not: random,
 * lattice tets with equal angles (ties between edges), slivers, flat,
 * needles, repeated corners, far from the origin, coordinates near
 * overflow and underflow, NaN and infinite corners; each also with its
 * corners in all 24 orders. */
static void test_score_pairs(void)
{
    enum { NT = 400 };
    int same = 1, tested = 0, degenerate = 0, ties = 0;
    for (int t = 0; t < NT; t++) {
        double q[4][3];
        int kind = t % 10;
        for (int i = 0; i < 4; i++)
            for (int a = 0; a < 3; a++)
                q[i][a] = 2.0 * rnd() - 1.0;
        if (kind == 1) {          /* a BCC lattice tet: two pairs of equal angles */
            static const double bcc[4][3] = {{0, 0, 0}, {2, 0, 0}, {1, 1, 1}, {1, 1, -1}};
            double h = 0.5 + rnd(), o = 100.0 * rnd();
            for (int i = 0; i < 4; i++)
                for (int a = 0; a < 3; a++)
                    q[i][a] = o + h * bcc[i][a];
            ties++;
        } else if (kind == 2) {   /* regular: six equal angles */
            static const double reg[4][3] = {{1, 1, 1}, {1, -1, -1}, {-1, 1, -1}, {-1, -1, 1}};
            memcpy(q, reg, sizeof q);
            ties++;
        } else if (kind == 3) {   /* sliver */
            for (int a = 0; a < 3; a++)
                q[3][a] = 0.3 * q[0][a] + 0.3 * q[1][a] + 0.4 * q[2][a] + 1e-9 * rnd();
        } else if (kind == 4) {   /* flat: a corner on an edge */
            for (int a = 0; a < 3; a++)
                q[3][a] = 2.0 * q[0][a] - q[1][a];
        } else if (kind == 5) {   /* repeated corner */
            memcpy(q[3], q[1], sizeof q[3]);
        } else if (kind == 6) {   /* far from the origin, small */
            for (int i = 0; i < 4; i++)
                for (int a = 0; a < 3; a++)
                    q[i][a] = 1e6 + 1e-4 * q[i][a];
        } else if (kind == 7) {   /* near overflow (the products are infinite) or underflow */
            double sc = t % 20 < 10 ? 1e80 : 1e-80;
            for (int i = 0; i < 4; i++)
                for (int a = 0; a < 3; a++)
                    q[i][a] *= sc;
        } else if (kind == 8) {   /* a NaN or infinite coordinate */
            q[t % 4][(t / 4) % 3] = t % 20 < 10 ? NAN : -INFINITY;
        } else if (kind == 9) {   /* needle */
            for (int a = 0; a < 3; a++)
                q[1][a] = q[0][a] + 1e-12 * rnd();
        }
        static const int perm[24][4] = {
            {0, 1, 2, 3}, {0, 1, 3, 2}, {0, 2, 1, 3}, {0, 2, 3, 1}, {0, 3, 1, 2}, {0, 3, 2, 1},
            {1, 0, 2, 3}, {1, 0, 3, 2}, {1, 2, 0, 3}, {1, 2, 3, 0}, {1, 3, 0, 2}, {1, 3, 2, 0},
            {2, 0, 1, 3}, {2, 0, 3, 1}, {2, 1, 0, 3}, {2, 1, 3, 0}, {2, 3, 0, 1}, {2, 3, 1, 0},
            {3, 0, 1, 2}, {3, 0, 2, 1}, {3, 1, 0, 2}, {3, 1, 2, 0}, {3, 2, 0, 1}, {3, 2, 1, 0}};
        for (int k = 0; k < 24; k++) {
            const double *a = q[perm[k][0]], *b = q[perm[k][1]], *c = q[perm[k][2]],
                         *d = q[perm[k][3]];
            double got = sm_tet_score(a, b, c, d), want = score_ref(a, b, c, d);
            if (memcmp(&got, &want, sizeof got) != 0 && !(isnan(got) && isnan(want))) {
                if (same)
                    TAP_NOTE("tet %d order %d: %.17g, the pair formula %.17g", t, k, got, want);
                same = 0;
            }
            degenerate += !(got > 0.0);
            tested++;
        }
    }
    TAP_CHECK(same && degenerate > tested / 10 && degenerate < tested / 2,
              "the tet score is the pair formula's bit for bit (%d tets in every corner order, "
              "%d scored 0 or less, %d with equal angles)", tested, degenerate, 24 * ties);
}

/* sm_mesh_build's neighbour lists: each vertex's edge neighbours in
 * increasing order without repeats or itself, as a brute force over the
 * tets finds them (a 5-tet block: lists of 4 to 18 neighbours). */
static void test_neighbour_lists(void)
{
    double lo[3] = {0, 0, 0};
    st_tetmesh *m = lattice5(3, 1.0, lo, NULL, NULL);
    sm_mesh sm;
    st_error err;
    int ok = sm_mesh_build(&sm, m, &err) == ST_OK, longest = 0;
    unsigned char *adj = calloc(m->npoints, 1);
    for (size_t v = 0; v < m->npoints && ok; v++) {
        memset(adj, 0, m->npoints);
        for (size_t t = 0; t < m->ntets; t++) {
            const uint32_t *c = m->tets + 4 * t;
            if (c[0] == v || c[1] == v || c[2] == v || c[3] == v)
                for (int k = 0; k < 4; k++)
                    adj[c[k]] = c[k] != v;
        }
        size_t j = sm.vv_off[v];
        for (uint32_t u = 0; u < m->npoints && ok; u++)
            if (adj[u])
                ok = j < sm.vv_off[v + 1] && sm.vv[j++] == u;
        ok = ok && j == sm.vv_off[v + 1];
        if ((int)(sm.vv_off[v + 1] - sm.vv_off[v]) > longest)
            longest = (int)(sm.vv_off[v + 1] - sm.vv_off[v]);
    }
    TAP_CHECK(ok && longest >= 12, "the neighbour lists are the tets' edges, sorted, "
              "without repeats (%zu vertices, the longest %d)", m->npoints, longest);
    free(adj);
    sm_mesh_free(&sm);
    st_tetmesh_free(m);
}

int main(int argc, char **argv)
{
    static const tap_test tests[] = {TAP_TEST(star_score_is_min), TAP_TEST(score_pairs), TAP_TEST(neighbour_lists), TAP_TEST(block),
                                     TAP_TEST(ball_many_iters), TAP_TEST(keeps_30),
                                     TAP_TEST(thin_slab), TAP_TEST(threads),
                                     TAP_TEST(refusals), {0}};
    return tap_main(argc, argv, tests);
}
