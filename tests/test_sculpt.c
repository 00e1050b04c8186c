/* test_sculpt.c - BCC sculpting keeps every input triangle inside the kept
 * tets (a needle crossing a tet without touching its edges, a tiny triangle
 * inside one tet, a stray triangle off the volume), bomb repair with known
 * answers, manifold repair of a pinch, determinism. */
#include "souptet/grid.h"
#include "souptet/isect.h"
#include "souptet/lattice.h"
#include "souptet/sculpt.h"
#include "souptet/soup.h"
#include "souptet/tetmesh.h"
#include "shapes.h"
#include "tap.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#ifdef _OPENMP
#include <omp.h>
#endif

static const double *P(const st_lattice *L, size_t t, int c)
{
    return L->xyz + 3 * (size_t)L->tets[4 * t + (size_t)c];
}

static double cube_sdf(const double c[3], double half)
{
    return fmax(fabs(c[0]), fmax(fabs(c[1]), fabs(c[2]))) - half;
}

/* The signed field of the cube [-1, 1]^3 on [-2.5, 2.5]^3. */
static st_grid *cube_grid(size_t n)
{
    return signed_grid(n, 2.5, cube_sdf, 1.0);
}

static size_t nearest_tet(const st_lattice *L, const double q[3])
{
    size_t best = 0;
    double bd = INFINITY;
    for (size_t t = 0; t < L->ntets; t++) {
        double d = 0;
        for (int a = 0; a < 3; a++) {
            double c = 0.25 * (P(L, t, 0)[a] + P(L, t, 1)[a] + P(L, t, 2)[a] + P(L, t, 3)[a]);
            d += (c - q[a]) * (c - q[a]);
        }
        if (d < bd) {
            bd = d;
            best = t;
        }
    }
    return best;
}

static void centroid(const st_lattice *L, size_t t, double c[3])
{
    for (int a = 0; a < 3; a++)
        c[a] = 0.25 * (P(L, t, 0)[a] + P(L, t, 1)[a] + P(L, t, 2)[a] + P(L, t, 3)[a]);
}

static int in_kept(const st_lattice *L, const unsigned char *keep, const double p[3])
{
    for (size_t t = 0; t < L->ntets; t++)
        if (keep[t] && st_point_in_tet(p, P(L, t, 0), P(L, t, 1), P(L, t, 2), P(L, t, 3)) != ST_OUTSIDE)
            return 1;
    return 0;
}

static size_t mesh_bombs(const st_tetmesh *m)
{
    int64_t *nbr = NULL;
    st_error err;
    if (st_tetmesh_neighbors(m, &nbr, NULL, &err))
        return (size_t)-1;
    size_t n = 0;
    for (size_t t = 0; t < m->ntets; t++) {
        int b = 0;
        for (int i = 0; i < 4; i++)
            b += nbr[4 * t + (size_t)i] < 0;
        n += b >= 2;
    }
    free(nbr);
    return n;
}

static void test_enclosure(void)
{
    st_grid *g = cube_grid(40);
    st_soup *s = st_soup_new();
    double lo[3] = {-1, -1, -1}, hi[3] = {1, 1, 1};
    add_box(s, lo, hi);
    size_t nbox = s->ntris;
    st_sculpt_params sp = st_sculpt_params_default();
    double glo[3], ghi[3];
    st_lattice_grid_box(g, glo, ghi);
    sp.h = st_lattice_h_for_cells(glo, ghi, 10);
    st_lattice_params lp = st_lattice_params_default();
    lp.kind = ST_LATTICE_BCC;
    lp.h = sp.h;
    st_lattice *L = NULL;
    st_error err;
    TAP_CHECK(st_lattice_build(&L, glo, ghi, &lp, &err) == ST_OK, "bcc lattice over the field");
    if (!L)
        return;
    /* A needle through the centroid of a tet off the volume: its ends lie
     * outside the tet and no tet edge touches it, so the paper's three
     * tests would drop the tet. */
    double q1[3] = {0.1, 1.9, -0.2};
    size_t tn = nearest_tet(L, q1);
    double c[3], d[3] = {0.48, 0.6, 0.64}, a[3], b[3], e[3];
    centroid(L, tn, c);
    for (int k = 0; k < 3; k++) {
        a[k] = c[k] - 0.75 * sp.h * d[k];
        b[k] = c[k] + 0.75 * sp.h * d[k];
    }
    e[0] = b[0] + 1e-7 * sp.h;
    e[1] = b[1] - 1e-7 * sp.h;
    e[2] = b[2];
    int edge_hits = 0;
    for (int i = 0; i < 4; i++)
        for (int j = i + 1; j < 4; j++)
            edge_hits += st_segment_tri_intersect(P(L, tn, i), P(L, tn, j), a, b, e);
    int vin = st_point_in_tet(a, P(L, tn, 0), P(L, tn, 1), P(L, tn, 2), P(L, tn, 3)) != ST_OUTSIDE ||
              st_point_in_tet(b, P(L, tn, 0), P(L, tn, 1), P(L, tn, 2), P(L, tn, 3)) != ST_OUTSIDE ||
              st_point_in_tet(e, P(L, tn, 0), P(L, tn, 1), P(L, tn, 2), P(L, tn, 3)) != ST_OUTSIDE;
    int crosses = st_tri_tet_intersect(a, b, e, P(L, tn, 0), P(L, tn, 1), P(L, tn, 2), P(L, tn, 3));
    TAP_CHECK(edge_hits == 0 && !vin && crosses,
              "the needle crosses its tet with no vertex inside and no tet edge through it");
    add_tri(s, a, b, e, 0);
    /* A tiny triangle inside one tet. */
    double q2[3] = {-0.3, -1.9, 0.4};
    size_t tt = nearest_tet(L, q2);
    double t0[3], t1[3], t2[3];
    centroid(L, tt, t0);
    memcpy(t1, t0, sizeof t1);
    memcpy(t2, t0, sizeof t2);
    t1[0] += 1e-3 * sp.h;
    t2[1] += 1e-3 * sp.h;
    add_tri(s, t0, t1, t2, 0);
    /* A stray triangle off the volume. */
    double s0[3] = {1.6, 0.1, 0.1}, s1[3] = {1.9, 0.2, 0.15}, s2[3] = {1.7, 0.5, 0.3};
    add_tri(s, s0, s1, s2, 1);

    unsigned char *keep = malloc(L->ntets);
    st_sculpt_stats ss;
    memset(&ss, 0, sizeof ss);
    int ok = st_sculpt_classify(keep, &ss, L, g, s, NULL, &err) == ST_OK;
    TAP_CHECK(ok && keep[tn] == ST_SCULPT_SURFACE, "the needle's tet is kept (by the triangle test)");
    TAP_CHECK(ok && keep[tt] == ST_SCULPT_SURFACE, "the tiny triangle's tet is kept");
    TAP_CHECK(ok && ss.kept_volume > 0 && ss.kept_surface > 0,
              "classification: %zu tets overlap the volume, %zu more meet a triangle",
              ss.kept_volume, ss.kept_surface);
    int all_tris = 1, all_pts = 1;
    for (size_t f = 0; ok && f < s->ntris; f++) {
        const double *v[3];
        for (int k = 0; k < 3; k++)
            v[k] = s->xyz + 3 * (size_t)s->tris[3 * f + (size_t)k];
        int hit = 0;
        for (size_t t = 0; t < L->ntets && !hit; t++)
            hit = keep[t] && st_tri_tet_intersect(v[0], v[1], v[2], P(L, t, 0), P(L, t, 1),
                                                  P(L, t, 2), P(L, t, 3));
        all_tris &= hit;
        /* vertices and interior samples of the triangle */
        for (int i = 0; i <= 4; i++)
            for (int j = 0; i + j <= 4; j++) {
                double p[3];
                for (int k = 0; k < 3; k++)
                    p[k] = v[0][k] + (v[1][k] - v[0][k]) * i / 4.0 + (v[2][k] - v[0][k]) * j / 4.0;
                all_pts &= in_kept(L, keep, p);
            }
    }
    TAP_CHECK(all_tris, "every triangle meets a kept tet");
    TAP_CHECK(all_pts, "every triangle's vertices and samples lie in the kept tets");
    size_t hist[5];
    size_t bombs = st_sculpt_count_bombs(L, keep, hist);
    /* With no search budget every cluster falls back to greedy, is
     * reported so, and is still repaired. */
    unsigned char *keep2 = malloc(L->ntets);
    memcpy(keep2, keep, L->ntets);
    st_sculpt_params gp = st_sculpt_params_default();
    gp.search_budget = 0;
    ok = ok && st_sculpt_repair_bombs(keep2, &ss, L, &gp, &err) == ST_OK;
    TAP_CHECK(ok && ss.clusters > 0 && ss.clusters_greedy == ss.clusters && ss.clusters_exact == 0 &&
              ss.bombs_left == 0 && ss.bomb_tets == ss.greedy_tets,
              "search budget 0: %zu clusters all greedy, still no bomb left", ss.clusters);
    free(keep2);
    st_sculpt_params rp = st_sculpt_params_default();
    ok = ok && st_sculpt_repair_bombs(keep, &ss, L, &rp, &err) == ST_OK;
    size_t hist2[5];
    TAP_CHECK(ok && bombs > 0 && ss.bombs == bombs && st_sculpt_count_bombs(L, keep, hist2) == 0 &&
              ss.bombs_left == 0,
              "bomb repair: %zu bombs (%zu with 3 faces, %zu isolated) -> 0, %zu snowflakes, %zu tets",
              bombs, hist[3], hist[4], ss.snowflakes, ss.bomb_tets);
    TAP_CHECK(ss.repair_rounds == 1, "one round of repair suffices (adding snowflakes makes no bomb)");
    free(keep);
    st_lattice_free(L);

    /* The whole of it, seeded, on 1 and 2 threads. */
    sp.seed = 7;
    st_tetmesh *m1 = NULL, *m2 = NULL;
    st_sculpt_stats s1s, s2s;
#ifdef _OPENMP
    omp_set_num_threads(1);
#endif
    ok = st_sculpt(&m1, &s1s, g, s, NULL, &sp, &err) == ST_OK;
#ifdef _OPENMP
    omp_set_num_threads(2);
#endif
    ok = ok && st_sculpt(&m2, &s2s, g, s, NULL, &sp, &err) == ST_OK;
    TAP_CHECK(ok && m1->ntets == m2->ntets && m1->npoints == m2->npoints &&
              memcmp(m1->tets, m2->tets, 4 * m1->ntets * sizeof(uint32_t)) == 0 &&
              memcmp(m1->xyz, m2->xyz, 3 * m1->npoints * sizeof(double)) == 0,
              "st_sculpt (seed 7): identical meshes on 1 and 2 threads (%zu tets)",
              ok ? m1->ntets : 0);
    TAP_CHECK(ok && mesh_bombs(m1) == 0 && s1s.bombs_left == 0,
              "st_sculpt: no tet of the output has two boundary faces (%zu bombs repaired)",
              ok ? s1s.bombs : 0);
    TAP_CHECK(ok && s1s.nonmanifold_vertices_left == 0 && s1s.nonmanifold_edges_left == 0,
              "st_sculpt: manifold boundary (%zu pinched vertices found, %zu tets added)",
              ok ? s1s.nonmanifold_vertices : 0, ok ? s1s.manifold_tets : 0);
    const char *hm = ok ? st_meta_get(&m1->meta, "h") : NULL;
    TAP_CHECK(hm && strtod(hm, NULL) == sp.h && st_meta_get(&m1->meta, "lattice") &&
              strcmp(st_meta_get(&m1->meta, "lattice"), "bcc") == 0 &&
              strcmp(st_meta_get(&m1->meta, "seed"), "7") == 0,
              "meta h (round trip exact), lattice, seed");
    /* every input vertex lies in the seeded mesh */
    int inmesh = 1;
    for (size_t v = 0; ok && v < s->nverts; v++) {
        int in = 0;
        for (size_t t = 0; t < m1->ntets && !in; t++) {
            const uint32_t *q = m1->tets + 4 * t;
            in = st_point_in_tet(s->xyz + 3 * v, m1->xyz + 3 * (size_t)q[0], m1->xyz + 3 * (size_t)q[1],
                                 m1->xyz + 3 * (size_t)q[2], m1->xyz + 3 * (size_t)q[3]) != ST_OUTSIDE;
        }
        inmesh &= in;
    }
    TAP_CHECK(ok && inmesh, "st_sculpt (rotated lattice): every input vertex is in the mesh");
    const st_tet_array *arr = ok ? st_tetmesh_find_array(m1, "sculpt", ST_ON_CELLS) : NULL;
    TAP_CHECK(arr && arr->ncomp == 1, "per-cell array 'sculpt'");
    (void)nbox;
    st_tetmesh_free(m1);
    st_tetmesh_free(m2);
    /* A field that is not signed is refused. */
    g->kind = ST_GRID_DISTANCE;
    m1 = NULL;
    TAP_CHECK(st_sculpt(&m1, NULL, g, s, NULL, &sp, &err) == ST_EINPUT && !m1,
              "an unsigned field is refused");
    st_soup_free(s);
    st_grid_free(g);
}

/* The vertex with integer coordinates g, or UINT32_MAX. */
static uint32_t vertex_at(const st_lattice *L, int64_t x, int64_t y, int64_t z)
{
    for (size_t v = 0; v < L->nverts; v++) {
        int64_t g[3];
        st_lattice_vertex_coords(L, (uint32_t)v, g);
        if (g[0] == x && g[1] == y && g[2] == z)
            return (uint32_t)v;
    }
    return UINT32_MAX;
}

static void test_known_repairs(void)
{
    double lo[3] = {0, 0, 0}, hi[3] = {4, 4, 4};
    st_lattice_params lp = st_lattice_params_default();
    lp.kind = ST_LATTICE_BCC;
    lp.h = 1;
    lp.pad = 0;
    st_lattice *L = NULL;
    st_error err;
    if (st_lattice_build(&L, lo, hi, &lp, &err)) {
        TAP_CHECK(0, "lattice for the repair tests");
        return;
    }
    unsigned char *keep = calloc(L->ntets, 1);
    st_sculpt_params p = st_sculpt_params_default();
    st_sculpt_stats ss;
    /* One isolated tet in the middle: one snowflake, 23 tets added. */
    uint32_t v = vertex_at(L, 4, 4, 4);
    size_t t0 = L->star[L->star_off[v]];
    keep[t0] = ST_SCULPT_VOLUME;
    size_t hist[5];
    st_sculpt_count_bombs(L, keep, hist);
    int ok = hist[4] == 1 && st_sculpt_repair_bombs(keep, &ss, L, &p, &err) == ST_OK;
    TAP_CHECK(ok && ss.bombs == 1 && ss.bombs_4faces == 1 && ss.snowflakes == 1 &&
              ss.bomb_tets == 23 && ss.bombs_left == 0 && ss.clusters_exact == 1,
              "an isolated tet: 1 snowflake, 23 tets added (got %zu, %zu)",
              ss.snowflakes, ss.bomb_tets);
    /* Two tets sharing a face: a snowflake around a vertex of the shared
     * face holds both, 22 tets added. */
    memset(keep, 0, L->ntets);
    keep[t0] = ST_SCULPT_VOLUME;
    size_t t1 = (size_t)L->nbr[4 * t0];
    keep[t1] = ST_SCULPT_VOLUME;
    ok = st_sculpt_repair_bombs(keep, &ss, L, &p, &err) == ST_OK;
    TAP_CHECK(ok && ss.bombs == 2 && ss.bombs_3faces == 2 && ss.snowflakes == 1 &&
              ss.bomb_tets == 22 && ss.clusters == 1,
              "two face-adjacent tets: one snowflake, 22 tets (got %zu, %zu)",
              ss.snowflakes, ss.bomb_tets);
    /* Two snowflakes whose corners are a cube diagonal apart touch only
     * at the centre of that cube: one pinched vertex. */
    memset(keep, 0, L->ntets);
    uint32_t va = vertex_at(L, 2, 2, 2), vb = vertex_at(L, 4, 4, 4), vc = vertex_at(L, 3, 3, 3);
    for (size_t a = L->star_off[va]; a < L->star_off[va + 1]; a++)
        keep[L->star[a]] = ST_SCULPT_VOLUME;
    for (size_t a = L->star_off[vb]; a < L->star_off[vb + 1]; a++)
        keep[L->star[a]] = ST_SCULPT_VOLUME;
    size_t nv = 9, ne = 9;
    ok = st_sculpt_count_nonmanifold(L, keep, &nv, &ne, &err) == ST_OK;
    TAP_CHECK(ok && nv == 1 && ne == 0 && st_sculpt_count_bombs(L, keep, NULL) == 0,
              "two snowflakes touching at a vertex: 1 non-manifold vertex, 0 edges, no bomb "
              "(got %zu, %zu)", nv, ne);
    memset(&ss, 0, sizeof ss);
    ok = ok && st_sculpt_repair_manifold(keep, &ss, L, &err) == ST_OK;
    int centre_full = 1;
    for (size_t a = L->star_off[vc]; a < L->star_off[vc + 1]; a++)
        centre_full &= keep[L->star[a]] != 0;
    TAP_CHECK(ok && ss.nonmanifold_vertices == 1 && ss.nonmanifold_vertices_left == 0 &&
              centre_full && st_sculpt_count_bombs(L, keep, NULL) == 0,
              "manifold repair fills the pinch's snowflake (%zu tets), no bomb appears",
              ss.manifold_tets);
    free(keep);
    st_lattice_free(L);
}


/* The paper's global search by brute force over all 4^n choices (one
 * candidate vertex per bomb), against the clustered branch and bound. */
static size_t brute_force(const st_lattice *L, const unsigned char *keep,
                          const size_t *bomb, size_t nb)
{
    unsigned char *add = malloc(L->ntets);
    size_t best = (size_t)-1, combos = 1;
    for (size_t b = 0; b < nb; b++)
        combos *= 4;
    for (size_t c = 0; c < combos; c++) {
        memset(add, 0, L->ntets);
        size_t x = c, cost = 0;
        for (size_t b = 0; b < nb; b++, x /= 4) {
            uint32_t v = L->tets[4 * bomb[b] + x % 4];
            for (size_t a = L->star_off[v]; a < L->star_off[v + 1]; a++) {
                size_t t = L->star[a];
                if (!keep[t] && !add[t]) {
                    add[t] = 1;
                    cost++;
                }
            }
        }
        if (cost < best)
            best = cost;
    }
    free(add);
    return best;
}

static void test_search_optimal(void)
{
    double lo[3] = {0, 0, 0}, hi[3] = {6, 6, 6};
    st_lattice_params lp = st_lattice_params_default();
    lp.kind = ST_LATTICE_BCC;
    lp.h = 1;
    lp.pad = 0;
    st_lattice *L = NULL;
    st_error err;
    if (st_lattice_build(&L, lo, hi, &lp, &err)) {
        TAP_CHECK(0, "lattice for the search test");
        return;
    }
    unsigned char *keep = malloc(L->ntets), *work = malloc(L->ntets);
    st_sculpt_params p = st_sculpt_params_default();
    uint64_t rng = 42;
    int trials = 0, agree = 0, better = 0, greedy_ok = 1;
    for (int trial = 0; trial < 400 && trials < 25; trial++) {
        memset(keep, 0, L->ntets);
        /* a few random tets and some of their neighbours, in the middle */
        int k = 2 + trial % 5;
        for (int q = 0; q < k; q++) {
            rng = rng * 6364136223846793005ull + 1442695040888963407ull;
            uint32_t v;
            int64_t g[3];
            do {
                rng = rng * 6364136223846793005ull + 1442695040888963407ull;
                v = (uint32_t)((rng >> 33) % L->nverts);
                st_lattice_vertex_coords(L, v, g);
            } while (g[0] < 4 || g[0] > 8 || g[1] < 4 || g[1] > 8 || g[2] < 4 || g[2] > 8);
            size_t deg = L->star_off[v + 1] - L->star_off[v];
            size_t t = L->star[L->star_off[v] + (rng >> 40) % deg];
            keep[t] = 1;
            if ((rng >> 50) & 1 && L->nbr[4 * t] >= 0)
                keep[L->nbr[4 * t]] = 1;
        }
        size_t bomb[8], nb = 0;
        int complete = 1;
        for (size_t t = 0; t < L->ntets; t++) {
            if (!keep[t])
                continue;
            int bf = 0;
            for (int i = 0; i < 4; i++)
                bf += L->nbr[4 * t + (size_t)i] < 0 || !keep[L->nbr[4 * t + (size_t)i]];
            if (bf >= 2) {
                if (nb == 8) {
                    nb = 9;
                    break;
                }
                bomb[nb++] = t;
                for (int c = 0; c < 4; c++) {
                    uint32_t v = L->tets[4 * t + (size_t)c];
                    complete &= L->star_off[v + 1] - L->star_off[v] == 24;
                }
            }
        }
        if (nb < 3 || nb > 7 || !complete)
            continue;
        trials++;
        size_t want = brute_force(L, keep, bomb, nb);
        memcpy(work, keep, L->ntets);
        st_sculpt_stats ss;
        if (st_sculpt_repair_bombs(work, &ss, L, &p, &err))
            continue;
        agree += ss.bomb_tets == want && ss.bombs_left == 0;
        better += ss.greedy_tets > ss.bomb_tets;
        greedy_ok &= ss.greedy_tets >= ss.bomb_tets;
    }
    TAP_CHECK(trials >= 10 && agree == trials,
              "the clustered search finds the 4^n optimum (%d of %d random bomb sets)",
              agree, trials);
    TAP_CHECK(greedy_ok, "the search is never worse than greedy (better in %d sets)", better);
    free(keep);
    free(work);
    st_lattice_free(L);
}

/* A band of bombs (tets within 0.2 of a patch of sphere) in one cluster:
 * the memo must give the choice, the node count and the exactness of the
 * search without it, at budgets that cut the search and at one that lets
 * it finish, while expanding fewer nodes. */
static void test_search_memo(void)
{
    double lo[3] = {0, 0, 0}, hi[3] = {16, 16, 16};
    st_lattice_params lp = st_lattice_params_default();
    lp.kind = ST_LATTICE_BCC;
    lp.h = 1;
    lp.pad = 0;
    st_lattice *L = NULL;
    st_error err;
    if (st_lattice_build(&L, lo, hi, &lp, &err)) {
        TAP_CHECK(0, "lattice for the memo test");
        return;
    }
    unsigned char *keep = calloc(L->ntets, 1), *a = malloc(L->ntets),
                  *b = malloc(L->ntets);
    const double R = 9;
    for (size_t t = 0; t < L->ntets; t++) {
        double c[3];
        centroid(L, t, c);
        double x = c[0] - 8, y = c[1] - 8, z = c[2] - 8 + R - 2;
        double r = sqrt(x * x + y * y + z * z);
        if (fabs(r - R) < 0.2 && z > R - 2.5 && fabs(x) < 2 && fabs(y) < 2)
            keep[t] = ST_SCULPT_VOLUME;
    }
    st_sculpt_params p = st_sculpt_params_default();
    const int budgets[] = {16, 17, 18, 20, 24};   /* log2 */
    for (int k = 0; k < 5; k++) {
        st_sculpt_stats sa, sb;
        p.search_budget = (size_t)1 << budgets[k];
        p.search_memo = 0;
        memcpy(a, keep, L->ntets);
        int ok = st_sculpt_repair_bombs(a, &sa, L, &p, &err) == ST_OK;
        p.search_memo = 1;
        memcpy(b, keep, L->ntets);
        ok = ok && st_sculpt_repair_bombs(b, &sb, L, &p, &err) == ST_OK;
        TAP_CHECK(ok && sa.bombs == 36 && sa.clusters == 1 &&
                  memcmp(a, b, L->ntets) == 0 && sa.bomb_tets == sb.bomb_tets &&
                  sa.clusters_exact == sb.clusters_exact &&
                  sa.search_nodes == sb.search_nodes &&
                  sb.search_expanded < sa.search_expanded,
                  "budget 2^%d: the memo gives the same repair (%zu tets, exact "
                  "%zu) and count (%zu nodes), %zu expanded", budgets[k],
                  sb.bomb_tets, sb.clusters_exact, sb.search_nodes, sb.search_expanded);
    }
    free(keep);
    free(a);
    free(b);
    st_lattice_free(L);
}

int main(int argc, char **argv)
{
    static const tap_test tests[] = {TAP_TEST(enclosure), TAP_TEST(known_repairs),
                                     TAP_TEST(search_optimal), TAP_TEST(search_memo),
                                     {0}};
    return tap_main(argc, argv, tests);
}
