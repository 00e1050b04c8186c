/*
 * test_embed.c - embedding points in a tet mesh (embed.h): the containing
 * tet and barycentric coordinates of points inside, on faces, edges and
 * corners of a 5-tet cube and outside it (by one ulp too); the first tet
 * in tet order wins on shared faces; the bins agree with a brute-force
 * scan on a larger mesh; the result does not depend on the thread count;
 * and the sidecar writers.
 */
#include "souptet/embed.h"
#include "souptet/isect.h"
#include "cubetets.h"
#include "tap.h"

#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* n^3 unit cubes of 5 positive tets each (the middle tet first in every
 * cube); corner q of a cube is (q&1, q>>1&1, q>>2&1). */
static st_tetmesh *cubes(int n)
{
    st_tetmesh *m = st_tetmesh_new();
    for (int k = 0; k <= n; k++)
        for (int j = 0; j <= n; j++)
            for (int i = 0; i <= n; i++)
                add_pt(m, i, j, k);
    add_cube_tets(m, 0, n, n, n);
    return m;
}

/* The barycentric coordinate of p's tet corner at point (x, y, z). */
static double bary_at(const st_tetmesh *m, int64_t t, const double *b,
                      double x, double y, double z)
{
    for (int k = 0; k < 4; k++) {
        const double *q = m->xyz + 3 * m->tets[4 * t + k];
        if (q[0] == x && q[1] == y && q[2] == z)
            return b[k];
    }
    return -1.0;
}

static void test_cube(void)
{
    st_tetmesh *m = cubes(1);
    /* Tet 0 is the middle tet on corners 1 2 4 7; tet 1 the corner tet
     * at 0 (corners 0 1 2 4). */
    const double tiny = ldexp(1.0, -60);
    const double past1 = nextafter(1.0, 2.0);
    const double pts[][3] = {
        {0.5, 0.5, 0.5},       /* 0: centre of the middle tet */
        {0.1, 0.1, 0.1},       /* 1: inside the corner tet at 0 */
        {0.25, 0.25, 0.5},     /* 2: on the face shared by tets 0 and 1 */
        {1, 1, 1},             /* 3: corner 7: tets 0 and 4 */
        {0, 0, 0},             /* 4: corner 0: tet 1 only */
        {0.5, 0.5, 0},         /* 5: on edge 1-2 of tets 0, 1 and 2 */
        {0.5, 0.25, 0},        /* 6: on the bottom face of tet 1 only */
        {2, 0, 0},             /* 7: outside the box */
        {0.5, 0.5, -tiny},     /* 8: an ulp below the bottom face */
        {0.5, 0.5, tiny},      /* 9: an ulp above it */
        {past1, 0.5, 0.5},     /* 10: an ulp past the face x = 1 */
    };
    size_t n = sizeof pts / sizeof pts[0];
    int64_t tet[16];
    double bary[64];
    size_t outside = 99;
    int64_t first = 99;
    st_error e;
    st_status s = st_embed_points(tet, bary, &outside, &first, m, &pts[0][0],
                                  n, &e);
    TAP_CHECK(s == ST_OK, "embedding in the 5-tet cube succeeds");
    TAP_CHECK(tet[0] == 0, "the centre is in the middle tet (tet %lld)",
              (long long)tet[0]);
    for (int k = 0; k < 4; k++)
        TAP_NEAR(bary[k], 0.25, 1e-15, "centre: coordinate %d is 1/4", k);
    TAP_CHECK(tet[1] == 1, "(0.1 0.1 0.1) is in the corner tet at 0");
    TAP_NEAR(bary_at(m, tet[1], bary + 4, 0, 0, 0), 0.7, 1e-15,
             "(0.1 0.1 0.1): 0.7 on corner (0 0 0)");
    TAP_NEAR(bary_at(m, tet[1], bary + 4, 1, 0, 0), 0.1, 1e-15,
             "(0.1 0.1 0.1): 0.1 on corner (1 0 0)");
    TAP_CHECK(tet[2] == 0, "a point on a shared face goes to the first tet "
              "(got %lld)", (long long)tet[2]);
    TAP_CHECK(bary_at(m, 0, bary + 8, 1, 1, 1) == 0.0,
              "on the face: the opposite corner's coordinate is exactly 0");
    TAP_NEAR(bary_at(m, 0, bary + 8, 0, 0, 1), 0.5, 1e-15,
             "on the face: 0.5 on corner (0 0 1)");
    TAP_CHECK(tet[3] == 0 && bary_at(m, 0, bary + 12, 1, 1, 1) == 1.0,
              "corner (1 1 1): the first of its tets, coordinate exactly 1");
    TAP_CHECK(tet[4] == 1 && bary_at(m, 1, bary + 16, 0, 0, 0) == 1.0,
              "corner (0 0 0): its only tet, coordinate exactly 1");
    TAP_CHECK(tet[5] == 0 && bary_at(m, 0, bary + 20, 1, 0, 0) == 0.5 &&
                  bary_at(m, 0, bary + 20, 0, 1, 0) == 0.5,
              "the midpoint of a shared edge: first tet, 1/2 and 1/2");
    TAP_CHECK(tet[6] == 1, "a point on one tet's boundary face is in it");
    TAP_CHECK(tet[7] == -1 && tet[8] == -1 && tet[10] == -1,
              "outside the box and an ulp outside two faces: tet -1");
    TAP_CHECK(tet[9] >= 0, "an ulp inside the bottom face: inside");
    TAP_CHECK(outside == 3 && first == 7, "3 points outside, the first is 7");
    TAP_CHECK(bary[28] == 0 && bary[29] == 0 && bary[30] == 0 &&
                  bary[31] == 0,
              "an outside point gets coordinates 0 0 0 0");
    int sums = 1, nonneg = 1;
    for (size_t i = 0; i < n; i++) {
        if (tet[i] < 0)
            continue;
        double sum = 0;
        for (int k = 0; k < 4; k++) {
            sum += bary[4 * i + k];
            nonneg &= bary[4 * i + k] >= 0;
        }
        sums &= fabs(sum - 1.0) <= 4e-16;
    }
    TAP_CHECK(sums && nonneg, "coordinates are >= 0 and sum to 1");

    /* A surface: st_embed_compute reads its vertices. */
    st_soup *so = st_soup_new();
    st_soup_add_vertex(so, 0.5, 0.5, 0.5, NULL);
    st_soup_add_vertex(so, 3, 3, 3, NULL);
    st_soup_add_vertex(so, 0.1, 0.1, 0.1, NULL);
    st_soup_add_triangle(so, 0, 1, 2, NULL);
    s = st_embed_compute(tet, bary, &outside, &first, m, so, &e);
    TAP_CHECK(s == ST_OK && tet[0] == 0 && tet[1] == -1 && tet[2] == 1 &&
                  outside == 1 && first == 1,
              "st_embed_compute embeds a soup's vertices");

    /* The text sidecar. */
    char path[] = "/tmp/test_embed.XXXXXX";
    int fd = mkstemp(path);
    if (fd >= 0)
        close(fd);
    s = st_embed_write_text(path, tet, bary, 3, m->ntets, "cube.vtu",
                            "tri.obj", &e);
    char buf[2048] = {0};
    FILE *fp = fopen(path, "r");
    size_t got = fp ? fread(buf, 1, sizeof buf - 1, fp) : 0;
    if (fp)
        fclose(fp);
    buf[got] = '\0';
    int lines = 0, comments = 0;
    for (char *l = buf; *l; l = strchr(l, '\n') ? strchr(l, '\n') + 1
                                                : l + strlen(l)) {
        lines++;
        comments += *l == '#';
    }
    TAP_CHECK(s == ST_OK && strstr(buf, "# souptet embedding: 3 vertices of "
                                        "tri.obj in the 5 tets of cube.vtu"),
              "the sidecar's header names the surface and the mesh");
    TAP_CHECK(lines - comments == 3 &&
                  strstr(buf, "\n0 0.25 0.25 0.25 0.25\n-1 0 0 0 0\n1 "),
              "one line per vertex: tet b0 b1 b2 b3, -1 outside");
    unlink(path);

    /* The points-only mesh for a .vtu sidecar. */
    st_tetmesh *side = NULL;
    s = st_embed_to_tetmesh(&side, so->xyz, tet, bary, 3, &e);
    const st_tet_array *at =
        side ? st_tetmesh_find_array(side, "embed_tet", ST_ON_POINTS) : NULL;
    const st_tet_array *ab =
        side ? st_tetmesh_find_array(side, "embed_bary", ST_ON_POINTS) : NULL;
    TAP_CHECK(s == ST_OK && side->npoints == 3 && side->ntets == 0 && at &&
                  ab && ab->ncomp == 4 && at->values[1] == -1.0 &&
                  at->values[2] == 1.0 && ab->values[0] == 0.25,
              "the sidecar mesh has the points and embed_tet, embed_bary");
    st_tetmesh_free(side);
    st_soup_free(so);

    double nanpt[3] = {0, NAN, 0};
    s = st_embed_points(tet, bary, NULL, NULL, m, nanpt, 1, &e);
    TAP_CHECK(s == ST_EINPUT, "a non-finite point is refused");
    st_tetmesh_free(m);
}

/* Random points in a 6^3 block of cubes: bins agree with a linear scan
 * (first containing, non-flat tet), coordinates rebuild the point, and 1
 * or 2 threads give the same bytes. */
static void test_block(void)
{
    st_tetmesh *m = cubes(6);
    enum { N = 6000 };
    double *p = malloc(3 * N * sizeof *p);
    unsigned long long r = 12345;
    for (size_t i = 0; i < 3 * N; i++) {
        r = r * 6364136223846793005ULL + 1442695040888963407ULL;
        double u = (double)(r >> 11) / 9007199254740992.0;
        /* a quarter on the lattice planes, some outside */
        p[i] = (i % 4 == 0) ? (double)((r >> 20) % 8) - 0.5
                            : -0.3 + 6.6 * u;
    }
    int64_t *t1 = malloc(N * sizeof *t1), *t2 = malloc(N * sizeof *t2);
    double *b1 = malloc(4 * N * sizeof *b1), *b2 = malloc(4 * N * sizeof *b2);
    st_error e;
    omp_set_num_threads(1);
    st_embed_points(t1, b1, NULL, NULL, m, p, N, &e);
    omp_set_num_threads(2);
    st_embed_points(t2, b2, NULL, NULL, m, p, N, &e);
    TAP_CHECK(memcmp(t1, t2, N * sizeof *t1) == 0 &&
                  memcmp(b1, b2, 4 * N * sizeof *b1) == 0,
              "1 and 2 threads give identical tets and coordinates");
    int agree = 1, rebuilt = 1;
    size_t inside = 0;
    for (size_t i = 0; i < N; i++) {
        int64_t want = -1;
        for (size_t t = 0; t < m->ntets && want < 0; t++) {
            const uint32_t *v = m->tets + 4 * t;
            if (st_point_in_tet(p + 3 * i, m->xyz + 3 * v[0],
                                m->xyz + 3 * v[1], m->xyz + 3 * v[2],
                                m->xyz + 3 * v[3]) != ST_OUTSIDE)
                want = (int64_t)t;
        }
        agree &= want == t1[i];
        if (t1[i] < 0)
            continue;
        inside++;
        double q[3] = {0, 0, 0};
        for (int k = 0; k < 4; k++)
            for (int c = 0; c < 3; c++)
                q[c] += b1[4 * i + k] * m->xyz[3 * m->tets[4 * t1[i] + k] + c];
        for (int c = 0; c < 3; c++)
            rebuilt &= fabs(q[c] - p[3 * i + c]) <= 1e-14;
    }
    TAP_CHECK(agree, "the bins find the same first tet as a linear scan "
              "(%zu of %d points inside)", inside, (int)N);
    TAP_CHECK(inside > N / 2 && inside < N, "the sample has both kinds");
    TAP_CHECK(rebuilt, "sum b_k p_k gives the point back within 1e-14");
    free(p);
    free(t1);
    free(t2);
    free(b1);
    free(b2);
    st_tetmesh_free(m);
}

int main(int argc, char **argv)
{
    static const tap_test tests[] = {TAP_TEST(cube), TAP_TEST(block), {0}};
    return tap_main(argc, argv, tests);
}
