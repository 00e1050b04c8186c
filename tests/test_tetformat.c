/*
 * test_tetformat.c - the .msh (4.1, 2.2; ASCII, binary), TetGen .node/.ele
 * and Medit .mesh readers and writers (tetformat.h): bit-exact round trips
 * of points, tets and meta for every variant, files as other programs
 * write them (sparse tags, surface elements, attributes, comments,
 * big-endian binary), and malformed input refused with ST_EINPUT at the
 * right line or byte, never a crash.
 *
 *   test_tetformat              the TAP tests
 *   test_tetformat --write DIR  write a sample mesh in every variant into
 *                               DIR (for tests/tools/formats.t, which feeds
 *                               them to gmsh, tetgen and meshio)
 *   test_tetformat --compare A B [--sets|--renumbered]
 *                               exit 0 when meshes A and B (any format,
 *                               .vtu too) have the same points within 1e-15
 *                               of their size and the same tets (--sets:
 *                               the same corner sets in any order;
 *                               --renumbered: B's points also in any order,
 *                               matched to A's by coordinates, as Gmsh
 *                               renumbers the nodes it saves by entity)
 */
#include "souptet/outfile.h"
#include "souptet/tetformat.h"
#include "souptet/tetio.h"
#include "cubetets.h"
#include "tap.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* ---- a sample mesh ------------------------------------------------------- */

/* n^3 cubes of 5 positive tets, mirrored on alternating cubes; the points
 * are moved off the grid by irrational amounts so that every coordinate
 * needs all 17 digits. */
static st_tetmesh *sample_mesh(int n)
{
    st_tetmesh *m = st_tetmesh_new();
    for (int k = 0; k <= n; k++)
        for (int j = 0; j <= n; j++)
            for (int i = 0; i <= n; i++) {
                double p[3] = {i + 0.1 * sin(i + 2.0 * j + 3.0 * k),
                               j + 0.1 * sin(3.0 * i + j + 2.0 * k) - 1e-3,
                               k / 3.0 + 1e5};
                st_tetmesh_add_point(m, p, NULL);
            }
    add_cube_tets(m, 0, n, n, n);
    st_meta_set(&m->meta, "source", "test_tetformat sample");
    st_meta_set(&m->meta, "h", "1");
    st_meta_history_append(&m->meta, "latticetet -r 3 x.vdb");
    st_meta_history_append(&m->meta, "tetsmooth --fit x.vtu");
    return m;
}

static int same_mesh(const st_tetmesh *a, const st_tetmesh *b)
{
    return a->npoints == b->npoints && a->ntets == b->ntets &&
           memcmp(a->xyz, b->xyz, 3 * a->npoints * sizeof(double)) == 0 &&
           memcmp(a->tets, b->tets, 4 * a->ntets * sizeof(uint32_t)) == 0;
}

static int same_meta(const st_tetmesh *a, const st_tetmesh *b)
{
    static const char *const keys[] = {"source", "h", "history"};
    for (size_t i = 0; i < 3; i++) {
        const char *x = st_meta_get(&a->meta, keys[i]);
        const char *y = st_meta_get(&b->meta, keys[i]);
        if (!x || !y || strcmp(x, y) != 0)
            return 0;
    }
    return 1;
}

typedef struct variant {
    const char *file;   /* name in the output directory */
    int version, binary;
} variant;

static const variant k_variants[] = {
    {"m41.msh", 41, 0}, {"m41b.msh", 41, 1}, {"m22.msh", 22, 0},
    {"m22b.msh", 22, 1}, {"m.node", 0, 0},  {"m.mesh", 0, 0},
};
#define NVARIANTS (sizeof k_variants / sizeof k_variants[0])

static int write_samples(const char *dir)
{
    st_tetmesh *m = sample_mesh(3);
    int bad = 0;
    for (size_t i = 0; i < NVARIANTS; i++) {
        char path[4096];
        snprintf(path, sizeof path, "%s/%s", dir, k_variants[i].file);
        st_tetformat_opts o = {.msh_version = k_variants[i].version, .binary = k_variants[i].binary};
        st_error e;
        if (st_tetmesh_save(m, path, &o, &e)) {
            char buf[1100];
            fprintf(stderr, "test_tetformat: %s\n",
                    st_error_format(&e, buf, sizeof buf));
            bad = 1;
        }
    }
    printf("%zu %zu\n", m->npoints, m->ntets);
    st_tetmesh_free(m);
    return bad;
}

/* ---- round trips ----------------------------------------------------------- */

static char g_dir[] = "/tmp/test_tetformat.XXXXXX";

static void test_round_trips(void)
{
    st_tetmesh *m = sample_mesh(3);
    for (size_t i = 0; i < NVARIANTS; i++) {
        const variant *v = &k_variants[i];
        char path[256];
        snprintf(path, sizeof path, "%s/%s", g_dir, v->file);
        st_tetformat_opts o = {.msh_version = v->version, .binary = v->binary};
        st_error e;
        st_status s = st_tetmesh_save(m, path, &o, &e);
        TAP_CHECK(s == ST_OK, "%s: written", v->file);
        st_tetmesh *r = NULL;
        s = st_tetmesh_read(&r, path, 0, &e);
        TAP_CHECK(s == ST_OK, "%s: read back (%s)", v->file,
                  s ? e.msg : "ok");
        TAP_CHECK(r && same_mesh(m, r),
                  "%s: same %zu points (bit-exact) and %zu tets", v->file,
                  m->npoints, m->ntets);
        TAP_CHECK(r && same_meta(m, r),
                  "%s: source, h and two-line history survive", v->file);
        st_tetmesh_free(r);
    }
    /* A TetGen pair is found from either file or the base name. */
    char path[256];
    static const char *const names[] = {"m.ele", "m"};
    for (int i = 0; i < 2; i++) {
        snprintf(path, sizeof path, "%s/%s", g_dir, names[i]);
        st_tetmesh *r = NULL;
        st_error e;
        st_status s = st_tetmesh_read_tetgen(&r, path, 0, &e);
        TAP_CHECK(s == ST_OK && r && same_mesh(m, r),
                  "tetgen pair read through '%s'", names[i]);
        st_tetmesh_free(r);
    }
    /* A tool's way: st_outfile's temporary file, written by name, then
     * renamed; for a TetGen target the other half appears beside it. */
    static const char *const targets[] = {"tool.node", "tool2.ele",
                                          "tool.msh", "tool.mesh"};
    for (int i = 0; i < 4; i++) {
        snprintf(path, sizeof path, "%s/%s", g_dir, targets[i]);
        st_outfile of;
        st_error e;
        int okw = st_outfile_begin(&of, path, 0, &e) == ST_OK &&
                  st_tetmesh_write(m, of.tmp, NULL, &e) == ST_OK &&
                  st_outfile_commit(&of, &e) == ST_OK;
        st_outfile_abort(&of);
        st_tetmesh *r = NULL;
        okw = okw && st_tetmesh_read(&r, path, 0, &e) ==
                         ST_OK && r && same_mesh(m, r);
        TAP_CHECK(okw, "written through st_outfile's temporary name: %s",
                  targets[i]);
        st_tetmesh_free(r);
    }
    /* The content decides when the extension does not. */
    snprintf(path, sizeof path, "%s/m41.msh", g_dir);
    char other[256];
    snprintf(other, sizeof other, "%s/noext", g_dir);
    rename(path, other);
    st_tetmesh *r = NULL;
    st_error e;
    TAP_CHECK(st_tetmesh_read(&r, other, 0, &e) ==
                      ST_OK && r && same_mesh(m, r),
              "an .msh without its extension is recognised by content");
    st_tetmesh_free(r);
    r = NULL;
    /* max_bytes caps the mesh memory. */
    snprintf(path, sizeof path, "%s/m.mesh", g_dir);
    st_status s = st_tetmesh_read(&r, path, 1000, &e);
    TAP_CHECK(s == ST_ELIMIT && !r, "max_bytes 1000 refuses a %zu-byte mesh",
              24 * m->npoints + 16 * m->ntets);
    st_tetmesh_free(m);
}

/* The writers' exact output for one tet: what Gmsh, TetGen and Medit
 * users expect to see. */
static void test_written_text(void)
{
    st_tetmesh *m = st_tetmesh_new();
    const double p[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 0.5}};
    for (int i = 0; i < 4; i++)
        st_tetmesh_add_point(m, p[i], NULL);
    st_tetmesh_add_tet(m, 0, 1, 2, 3, NULL);
    struct {
        const char *file;
        int version;
        const char *want;
    } cases[] = {
        {"one41.msh", 41,
         "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$PhysicalNames\n2\n"
         "2 2 \"boundary\"\n3 1 \"volume\"\n$EndPhysicalNames\n"
         "$Entities\n0 0 1 1\n2 0 0 0 1 1 0.5 1 2 0\n"
         "1 0 0 0 1 1 0.5 1 1 1 2\n$EndEntities\n$Nodes\n1 4 1 4\n3 1 0 4\n"
         "1\n2\n3\n4\n0 0 0\n1 0 0\n0 1 0\n0 0 0.5\n$EndNodes\n"
         "$Elements\n2 5 1 5\n3 1 4 1\n1 1 2 3 4\n2 2 2 4\n2 2 3 4\n"
         "3 1 4 3\n4 1 2 4\n5 1 3 2\n$EndElements\n"},
        {"one22.msh", 22,
         "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$PhysicalNames\n2\n"
         "2 2 \"boundary\"\n3 1 \"volume\"\n$EndPhysicalNames\n"
         "$Nodes\n4\n1 0 0 0\n"
         "2 1 0 0\n3 0 1 0\n4 0 0 0.5\n$EndNodes\n$Elements\n5\n"
         "1 4 2 1 1 1 2 3 4\n2 2 2 2 2 2 3 4\n3 2 2 2 2 1 4 3\n"
         "4 2 2 2 2 1 2 4\n5 2 2 2 2 1 3 2\n$EndElements\n"},
        /* The boundary faces point out of the tet: 2 3 4 away from the
         * origin, 1 4 3 to -x, 1 2 4 to -y, 1 3 2 to -z. */
        {"one.mesh", 0,
         "MeshVersionFormatted 2\n\nDimension 3\n\nVertices\n4\n0 0 0 0\n"
         "1 0 0 0\n0 1 0 0\n0 0 0.5 0\n\nTetrahedra\n1\n1 2 3 4 1\n\n"
         "Triangles\n4\n2 3 4 2\n1 4 3 2\n1 2 4 2\n1 3 2 2\n\nEnd\n"},
        {"one.node", 0, "4 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 0.5\n"},
        {"one.ele", -1, "1 4 0\n1 1 2 3 4\n"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        char path[256];
        snprintf(path, sizeof path, "%s/%s", g_dir, cases[i].file);
        st_tetformat_opts o = {.msh_version = cases[i].version > 0 ? cases[i].version : 0};
        st_error e;
        if (cases[i].version >= 0)
            st_tetmesh_save(m, path, &o, &e);
        char buf[1024] = {0};
        FILE *fp = fopen(path, "rb");
        size_t n = fp ? fread(buf, 1, sizeof buf - 1, fp) : 0;
        if (fp)
            fclose(fp);
        buf[n] = '\0';
        TAP_CHECK(strcmp(buf, cases[i].want) == 0, "%s: exact text",
                  cases[i].file);
        if (strcmp(buf, cases[i].want) != 0)
            TAP_NOTE("got:\n%s", buf);
    }
    /* A negatively oriented tet (read from a foreign file) still gets
     * outward boundary triangles. */
    m->tets[1] = 2;
    m->tets[2] = 1;
    char path[256], buf[1024] = {0};
    snprintf(path, sizeof path, "%s/inv.mesh", g_dir);
    st_error e;
    st_tetmesh_save(m, path, NULL, &e);
    FILE *fp = fopen(path, "rb");
    size_t n = fp ? fread(buf, 1, sizeof buf - 1, fp) : 0;
    if (fp)
        fclose(fp);
    buf[n] = '\0';
    /* The same four outward faces as above (3 4 2 is 2 3 4 turned). */
    const char *want = "Triangles\n4\n3 4 2 2\n1 2 4 2\n1 4 3 2\n"
                       "1 3 2 2\n\nEnd\n";
    const char *tri = strstr(buf, "Triangles\n");
    TAP_CHECK(tri && strcmp(tri, want) == 0,
              "an inverted tet's boundary triangles point outward");
    if (!tri || strcmp(tri, want) != 0)
        TAP_NOTE("got:\n%s", buf);
    st_tetmesh_free(m);
}

/* ---- files as others write them -------------------------------------------- */

static st_tetmesh *parse_msh(const char *text, size_t n, st_error *e)
{
    st_tetmesh *m = NULL;
    st_tetmesh_parse_msh(&m, (const unsigned char *)text, n, "t.msh", 0, e);
    return m;
}

static void test_foreign_files(void)
{
    st_error e;
    /* Gmsh 4.1 as Gmsh writes it: physical names, entities, nodes on
     * several entities with parametric coordinates, sparse tags out of
     * order, points, lines and triangles before the tets. */
    static const char gmsh41[] =
        "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n"
        "$PhysicalNames\n1\n3 7 \"solid\"\n$EndPhysicalNames\n"
        "$Entities\n1 0 0 1\n1 0 0 0 0 0\n1 0 0 0 1 1 1 1 7 0\n"
        "$EndEntities\n"
        "$Nodes\n3 5 10 50\n0 1 0 1\n50\n0 0 0\n"
        "2 3 1 2\n20\n30\n1 0 0 0.5 0.5\n0 1 0 0.25 0.75\n"
        "3 1 0 2\n10\n40\n0 0 1\n1 1 1\n$EndNodes\n"
        "$Elements\n3 4 1 9\n0 1 15 1\n9 50\n2 3 2 1\n8 50 20 30\n"
        "3 1 4 2\n1 50 20 30 10\n2 20 30 10 40\n$EndElements\n"
        "$NodeData\n1\n\"t\"\n1\n0.0\n3\n0\n1\n5\n10 1\n20 1\n30 1\n40 1\n"
        "50 1\n$EndNodeData\n";
    st_tetmesh *m = parse_msh(gmsh41, sizeof gmsh41 - 1, &e);
    TAP_CHECK(m && m->npoints == 5 && m->ntets == 2,
              "gmsh 4.1 with entities, physical names, parametric nodes, "
              "surface elements and node data: 5 points, 2 tets");
    /* Node 50 is point 0, 20 is 1, 30 is 2, 10 is 3, 40 is 4. */
    TAP_CHECK(m && m->tets[0] == 0 && m->tets[1] == 1 && m->tets[2] == 2 &&
                  m->tets[3] == 3 && m->tets[7] == 4 &&
                  m->xyz[3 * 4 + 0] == 1.0,
              "sparse node tags map to the right points");
    st_tetmesh_free(m);

    /* 2.2 with three tags per element and a triangle. */
    static const char gmsh22[] =
        "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n4\n7 0 0 0\n"
        "3 1 0 0\n5 0 1 0\n9 0 0 1\n$EndNodes\n$Elements\n2\n"
        "1 2 3 1 2 0 7 3 5\n2 4 3 1 1 0 7 3 5 9\n$EndElements\n";
    m = parse_msh(gmsh22, sizeof gmsh22 - 1, &e);
    TAP_CHECK(m && m->ntets == 1 && m->tets[0] == 0 && m->tets[1] == 1 &&
                  m->tets[2] == 2 && m->tets[3] == 3,
              "gmsh 2.2 with 3 tags and a triangle: the tet maps its tags");
    st_tetmesh_free(m);

    /* Big-endian 2.2 binary, written by hand. */
    unsigned char be[512];
    size_t n = 0;
#define PUT(s) (memcpy(be + n, (s), strlen(s)), n += strlen(s))
#define I32(v) (be[n] = (unsigned char)((uint32_t)(v) >> 24),            \
                be[n + 1] = (unsigned char)((uint32_t)(v) >> 16),        \
                be[n + 2] = (unsigned char)((uint32_t)(v) >> 8),         \
                be[n + 3] = (unsigned char)(v), n += 4)
    PUT("$MeshFormat\n2.2 1 8\n");
    I32(1);
    PUT("\n$EndMeshFormat\n$Nodes\n4\n");
    const double c[4][3] = {{0, 0, 0}, {2, 0, 0}, {0, 2, 0}, {0, 0, 2}};
    for (int i = 0; i < 4; i++) {
        I32(i + 1);
        for (int k = 0; k < 3; k++) {
            uint64_t bits;
            memcpy(&bits, &c[i][k], 8);
            for (int b = 7; b >= 0; b--)
                be[n++] = (unsigned char)(bits >> (8 * b));
        }
    }
    PUT("\n$EndNodes\n$Elements\n1\n");
    I32(4); I32(1); I32(0);
    I32(1); I32(1); I32(2); I32(3); I32(4);
    PUT("\n$EndElements\n");
#undef PUT
#undef I32
    m = parse_msh((const char *)be, n, &e);
    TAP_CHECK(m && m->ntets == 1 && m->xyz[3 * 1] == 2.0 &&
                  m->xyz[3 * 3 + 2] == 2.0,
              "big-endian msh 2.2 binary");
    st_tetmesh_free(m);

    /* 100000 history lines in $Comments: linear time, all kept. */
    {
        static const char head[] = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n"
                                   "$Comments\n";
        static const char line[] = "souptet history: tool --x\n";
        static const char tail[] =
            "$EndComments\n$Nodes\n4\n1 0 0 0\n2 1 0 0\n3 0 1 0\n"
            "4 0 0 1\n$EndNodes\n$Elements\n1\n1 4 0 1 2 3 4\n"
            "$EndElements\n";
        size_t nl = 100000, len = strlen(head) + nl * strlen(line) +
                                  strlen(tail);
        char *big = malloc(len + 1), *q = big;
        q += sprintf(q, "%s", head);
        for (size_t i = 0; i < nl; i++)
            q += sprintf(q, "%s", line);
        sprintf(q, "%s", tail);
        m = parse_msh(big, len, &e);
        const char *h = m ? st_meta_get(&m->meta, "history") : NULL;
        size_t lines = h ? 1 : 0;
        for (; h && *h; h++)
            lines += *h == '\n';
        TAP_CHECK(m && lines == nl, "100000 history lines are all kept "
                  "(%zu)", lines);
        st_tetmesh_free(m);
        free(big);
    }

    /* TetGen with 0-based numbering, attributes, markers, comments. */
    static const char node0[] =
        "# a comment\n4  3  1  1\n0 0 0 0  7.5 1\n1 1 0 0 7.5 1 # c\n"
        "\n2 0 1 0 7.5 1\n3 0 0 1 7.5 0\n";
    static const char ele0[] = "1 4 1\n0 0 1 2 3 -1\n";
    m = NULL;
    st_tetmesh_parse_tetgen(&m, (const unsigned char *)node0,
                            sizeof node0 - 1, "t.node",
                            (const unsigned char *)ele0, sizeof ele0 - 1,
                            "t.ele", 0, &e);
    TAP_CHECK(m && m->npoints == 4 && m->ntets == 1 && m->tets[3] == 3 &&
                  m->xyz[3] == 1.0,
              "tetgen numbered from 0 with attributes and markers");
    st_tetmesh_free(m);

    /* Medit with comments, edges, triangles and corners (as MMG writes). */
    static const char medit[] =
        "MeshVersionFormatted 1\n# mmg\nDimension\n3\nVertices\n4\n"
        "0 0 0 1\n1 0 0 1\n0 1 0 1\n0 0 1 1\nCorners\n1\n1\n"
        "Edges\n1\n1 2 0\nTriangles\n1\n1 2 3 5\nTetrahedra\n1\n"
        "1 2 3 4 3\nEnd\n";
    m = NULL;
    st_tetmesh_parse_medit(&m, (const unsigned char *)medit,
                           sizeof medit - 1, "t.mesh", 0, &e);
    TAP_CHECK(m && m->npoints == 4 && m->ntets == 1,
              "medit with corners, edges and triangles");
    st_tetmesh_free(m);
}

/* ---- malformed input --------------------------------------------------------- */

typedef struct bad {
    char fmt;             /* 'g' msh, 't' tetgen (node \f ele), 'm' medit */
    const char *text;
    long long line;       /* expected line; 0: do not check */
    const char *what;
    size_t len;           /* bytes of text with NULs; 0: strlen */
} bad;

#define BINLEN(s) sizeof(s) - 1

static const bad k_bad[] = {
    {'g', "", 1, "empty", 0},
    {'g', "$MeshFormat\n", 1, "truncated after $MeshFormat", 0},
    {'g', "$MeshFormat\n3.0 0 8\n$EndMeshFormat\n", 2, "version 3.0", 0},
    {'g', "$MeshFormat\n4.0 0 8\n$EndMeshFormat\n", 2, "version 4.0", 0},
    {'g', "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n", 3, "no $Nodes", 0},
    {'g', "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n2\n1 0 0 0\n",
     5, "node count larger than the bytes left", 0},
    {'g', "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n2\n1 0 0 0\n"
          "2 1.0000000 0.000", 7, "nodes truncated in a record", 0},
    {'g', "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n99999999999\n"
          "1 0 0 0\n$EndNodes\n", 5, "absurd node count", 0},
    {'g', "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n1\n1 0 nan 0\n"
          "$EndNodes\n", 6, "NaN coordinate", 0},
    {'g', "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n1\n1 0 1e999 0\n"
          "$EndNodes\n", 6, "infinite coordinate", 0},
    {'g', "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n2\n1 0 0 0\n"
          "1 1 1 1\n$EndNodes\n", 4, "duplicated node tag", 0},
    {'g', "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n1\n1 0 0 0\n"
          "$EndNodes\n$Elements\n1\n1 4 0 1 1 1 2\n$EndElements\n", 10,
     "element refers to a missing node", 0},
    {'g', "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n1\n1 0 0 0\n"
          "$EndNodes\n$Elements\n1\n1 5 0 1 1 1 1 1 1 1 1\n$EndElements\n",
     10, "a hexahedron", 0},
    {'g', "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n1\n1 0 0 0\n"
          "$EndNodes\n$Elements\n1\n1 99 0 1\n$EndElements\n", 10,
     "unknown element type", 0},
    {'g', "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n1\n1 0 0 0\n"
          "$EndNodes\n$Elements\n1\n1 15 0 1\n$EndElements\n", 11,
     "no tets", 0},
    {'g', "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 2 1 2\n"
          "3 1 0 3\n1\n2\n3\n0 0 0\n0 0 0\n0 0 0\n$EndNodes\n", 6,
     "4.1 block larger than the header", 0},
    {'g', "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Entities\n0 0 0 0\n", 4,
     "unterminated $Entities", 0},
    {'g', "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Elements\n", 4,
     "$Elements before $Nodes", 0},
#define BAD_BOM "$MeshFormat\n4.1 1 8\n\x02\0\0\0\n$EndMeshFormat\n"
#define BAD_CNT "$MeshFormat\n4.1 1 8\n\x01\0\0\0\n$EndMeshFormat\n" \
                "$Nodes\n\x01\0\0\0\0\0\0\0\xff\xff\xff\xff\xff\xff\0\0"
#define BAD_ELE "$MeshFormat\n4.1 1 8\n\x01\0\0\0\n$EndMeshFormat\n" \
                "$Nodes\n\0\0\0\0\0\0\0\0\0\0\0\0\0\0\0\0" \
                "\0\0\0\0\0\0\0\0\0\0\0\0\0\0\0\0\n$EndNodes\n"
    {'g', "$MeshFormat\n4.1 1 8\n", 0, "binary: no byte-order mark", 0},
    {'g', BAD_BOM, 0, "binary: bad byte-order mark", BINLEN(BAD_BOM)},
    {'g', BAD_CNT, 0, "binary: absurd count, truncated", BINLEN(BAD_CNT)},
    {'g', BAD_ELE, 0, "binary: zero nodes, no elements", BINLEN(BAD_ELE)},
    {'t', "3 3 0 0\n1 0 0 0\n2 1 0 0\n\f1 4 0\n1 1 2 3 4\n", 1,
     "point count larger than the bytes left", 0},
    {'t', "3 3 0 0\n1 0 0 0\n2 1 0 0\n3 1.000000000\n\f1 4 0\n1 1 2 3 4\n", 4,
     "node truncated in a record", 0},
    {'t', "1 2 0 0\n1 0 0\n\f", 1, "2-D node file", 0},
    {'t', "2 3 0 0\n1 0 0 0\n3 1 0 0\n\f", 3, "node numbering gap", 0},
    {'t', "1 3 0 0\n5 0 0 0\n\f", 2, "first node numbered 5", 0},
    {'t', "1 3 0 0\n1 0 0\n\f", 2, "node with 2 coordinates", 0},
    {'t', "1 3 0 0\n1 0 inf 0\n\f", 2, "infinite coordinate", 0},
    {'t', "4 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n\f1 4 0\n"
          "1 1 2 3 5\n", 2, "tet corner out of range", 0},
    {'t', "4 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n\f1 10 0\n", 1,
     "10-node tets", 0},
    {'t', "4 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n\f"
          "4000000000 4 0\n1 1 2 3 4\n", 1, "absurd tet count", 0},
    {'t', "4 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n\f", 0,
     "empty .ele", 0},
    {'m', "Vertices\n1\n0 0 0 0\n", 1, "no MeshVersionFormatted", 0},
    {'m', "MeshVersionFormatted 2\nDimension 2\n", 2, "dimension 2", 0},
    {'m', "MeshVersionFormatted 2\nDimension 3\nVertices\n2\n0 0 0 0\n", 4,
     "vertex count larger than the bytes left", 0},
    {'m', "MeshVersionFormatted 2\nDimension 3\nVertices\n2\n0 0 0 0\n"
          "1 1.0000000 ", 6, "vertices truncated", 0},
    {'m', "MeshVersionFormatted 2\nVertices\n1\n0 0 0 0\nTetrahedra\n1\n"
          "1 1 1 2 0\nEnd\n", 7, "tet corner out of range", 0},
    {'m', "MeshVersionFormatted 2\nVertices\n1\n0 0 0 0\nTetrahedra\n1\n"
          "1 1 1 0 0\nEnd\n", 7, "tet corner 0", 0},
    {'m', "MeshVersionFormatted 2\nVertices\n1\n0 0 0 0\nHexahedra\n0\n",
     5, "hexahedra", 0},
    {'m', "MeshVersionFormatted 2\nVertices\n1\n0 0 0 0\nBogus\n0\n", 5,
     "unknown keyword", 0},
    {'m', "MeshVersionFormatted 2\nVertices\n1\n0 0 0 0\nEnd\n", 5,
     "no tetrahedra", 0},
    {'m', "MeshVersionFormatted 2\nVertices\n9999999\n0 0 0 0\nEnd\n", 3,
     "absurd vertex count", 0},
    {'m', "MeshVersionFormatted 2\nVertices\n1\n0 NaN 0 0\nEnd\n", 4,
     "NaN coordinate", 0},
};

static void test_malformed(void)
{
    for (size_t i = 0; i < sizeof k_bad / sizeof k_bad[0]; i++) {
        const bad *b = &k_bad[i];
        size_t n = b->len ? b->len : strlen(b->text);
        /* Copy into an exact-size heap buffer so ASan sees overreads. */
        unsigned char *buf = malloc(n ? n : 1);
        memcpy(buf, b->text, n);
        st_tetmesh *m = NULL;
        st_error e;
        st_error_clear(&e);
        st_status s;
        if (b->fmt == 'g') {
            s = st_tetmesh_parse_msh(&m, buf, n, "bad.msh", 0, &e);
        } else if (b->fmt == 'm') {
            s = st_tetmesh_parse_medit(&m, buf, n, "bad.mesh", 0, &e);
        } else {
            const unsigned char *ff = memchr(buf, '\f', n);
            size_t nn = (size_t)(ff - buf);
            s = st_tetmesh_parse_tetgen(&m, buf, nn, "bad.node", ff + 1,
                                        n - nn - 1, "bad.ele", 0, &e);
        }
        int ok = s == ST_EINPUT && !m && e.file[0] &&
                 (b->line == 0 || e.line == b->line);
        TAP_CHECK(ok, "refused: %s (%s:%lld: byte %lld: %s)", b->what,
                  e.file, e.line, e.offset, e.msg);
        if (!ok && b->line)
            TAP_NOTE("wanted line %lld, status %d", b->line, (int)s);
        st_tetmesh_free(m);
        free(buf);
    }
}

/* Every prefix of every valid file is refused or read; never a crash. */
static void test_truncations(void)
{
    int crashes_would_abort = 1, all_refused = 1;
    for (size_t i = 0; i < NVARIANTS; i++) {
        if (strstr(k_variants[i].file, ".node"))
            continue;
        char path[256];
        snprintf(path, sizeof path, "%s/%s", g_dir, k_variants[i].file);
        if (strcmp(k_variants[i].file, "m41.msh") == 0)
            snprintf(path, sizeof path, "%s/noext", g_dir);
        FILE *fp = fopen(path, "rb");
        if (!fp)
            continue;
        static unsigned char data[1 << 16];
        size_t size = fread(data, 1, sizeof data, fp);
        fclose(fp);
        int medit = strstr(k_variants[i].file, ".mesh") != NULL;
        /* Cut before the last section's end marker: every cut is bad. */
        size_t stop = size > 20 ? size - 16 : 0;
        for (size_t cut = 0; cut < stop; cut += 1 + cut / 64) {
            unsigned char *b = malloc(cut ? cut : 1);
            memcpy(b, data, cut);
            st_tetmesh *m = NULL;
            st_error e;
            st_status s = medit ? st_tetmesh_parse_medit(&m, b, cut, "c", 0,
                                                         &e)
                                : st_tetmesh_parse_msh(&m, b, cut, "c", 0,
                                                       &e);
            if (s != ST_EINPUT || m)
                all_refused = 0;
            st_tetmesh_free(m);
            free(b);
        }
    }
    TAP_CHECK(crashes_would_abort && all_refused,
              "every truncation of the written msh and mesh files is "
              "refused with ST_EINPUT");
}

static void test_paths(void)
{
    TAP_CHECK(st_tetformat_from_path("a/b.MSH") == ST_TETFORMAT_MSH &&
                  st_tetformat_from_path("b.node") == ST_TETFORMAT_TETGEN &&
                  st_tetformat_from_path("b.ele") == ST_TETFORMAT_TETGEN &&
                  st_tetformat_from_path("b.mesh") == ST_TETFORMAT_MEDIT &&
                  st_tetformat_from_path("b.Vtu") == ST_TETFORMAT_VTU &&
                  st_tetformat_from_path("-") == ST_TETFORMAT_VTU &&
                  st_tetformat_from_path(NULL) == ST_TETFORMAT_VTU &&
                  st_tetformat_from_path("b.obj") == ST_TETFORMAT_NONE &&
                  st_tetformat_from_path(".msh") == ST_TETFORMAT_NONE &&
                  st_tetformat_from_path(".vtu") == ST_TETFORMAT_NONE,
              "format by extension");
    TAP_CHECK(st_tetformat_from_path("d/.x.msh.tmp-12@host.AbC123") == ST_TETFORMAT_MSH,
              "an st_outfile temporary name has its target's format");
}

static st_tetmesh *read_any(const char *path)
{
    st_tetmesh *m = NULL;
    st_error e;
    st_status s = st_tetmesh_read(&m, path, 0, &e);
    if (s) {
        char buf[1100];
        fprintf(stderr, "test_tetformat: %s\n",
                st_error_format(&e, buf, sizeof buf));
    }
    return m;
}

static int cmp_tet(const void *a, const void *b)
{
    return memcmp(a, b, 4 * sizeof(uint32_t));
}

static int cmp_u32(const void *a, const void *b)
{
    uint32_t x = *(const uint32_t *)a, y = *(const uint32_t *)b;
    return x < y ? -1 : x > y;
}

/* Corners sorted within each tet, tets sorted (byte order: only equality
 * matters). */
static void canonical(st_tetmesh *m)
{
    for (size_t t = 0; t < m->ntets; t++)
        qsort(m->tets + 4 * t, 4, sizeof(uint32_t), cmp_u32);
    qsort(m->tets, m->ntets, 4 * sizeof(uint32_t), cmp_tet);
}

static const double *g_xyz;

static int cmp_point(const void *a, const void *b)
{
    const double *p = g_xyz + 3 * (size_t)*(const uint32_t *)a;
    const double *q = g_xyz + 3 * (size_t)*(const uint32_t *)b;
    for (int k = 0; k < 3; k++)
        if (p[k] != q[k])
            return p[k] < q[k] ? -1 : 1;
    return 0;
}

/* The points of m in lexicographic order (malloc'd indices). */
static uint32_t *point_order(const st_tetmesh *m)
{
    uint32_t *o = malloc((m->npoints ? m->npoints : 1) * sizeof *o);
    if (!o)
        return NULL;
    for (size_t i = 0; i < m->npoints; i++)
        o[i] = (uint32_t)i;
    g_xyz = m->xyz;
    qsort(o, m->npoints, sizeof *o, cmp_point);
    return o;
}

/* Renumber y's points into x's order, matched by sorted coordinates (the
 * tolerance check that follows compares them). */
static int match_points(const st_tetmesh *x, st_tetmesh *y)
{
    uint32_t *ox = point_order(x), *oy = point_order(y);
    uint32_t *to = malloc((y->npoints ? y->npoints : 1) * sizeof *to);
    double *xyz = malloc((y->npoints ? y->npoints : 1) * 3 * sizeof *xyz);
    int rc = ox && oy && to && xyz ? 0 : 1;
    for (size_t i = 0; !rc && i < y->npoints; i++) {
        to[oy[i]] = ox[i];
        memcpy(xyz + 3 * (size_t)ox[i], y->xyz + 3 * (size_t)oy[i],
               3 * sizeof *xyz);
    }
    if (!rc) {
        memcpy(y->xyz, xyz, 3 * y->npoints * sizeof *xyz);
        for (size_t i = 0; i < 4 * y->ntets; i++)
            y->tets[i] = to[y->tets[i]];
    }
    free(ox);
    free(oy);
    free(to);
    free(xyz);
    return rc;
}

static int compare_files(const char *a, const char *b, int sets)
{
    st_tetmesh *x = read_any(a), *y = read_any(b);
    int rc = 1;
    if (!x || !y)
        goto out;
    if (x->npoints != y->npoints || x->ntets != y->ntets) {
        fprintf(stderr, "%s: %zu points %zu tets, %s: %zu points %zu tets\n",
                a, x->npoints, x->ntets, b, y->npoints, y->ntets);
        goto out;
    }
    if (sets == 2 && match_points(x, y)) {
        fprintf(stderr, "out of memory\n");
        goto out;
    }
    double size = 0, diff = 0;
    for (size_t i = 0; i < 3 * x->npoints; i++) {
        if (fabs(x->xyz[i]) > size)
            size = fabs(x->xyz[i]);
        if (fabs(x->xyz[i] - y->xyz[i]) > diff)
            diff = fabs(x->xyz[i] - y->xyz[i]);
    }
    if (diff > 1e-15 * size) {
        fprintf(stderr, "points differ by up to %g (size %g)\n", diff,
                size);
        goto out;
    }
    if (sets) {
        canonical(x);
        canonical(y);
    }
    if (memcmp(x->tets, y->tets, 4 * x->ntets * sizeof(uint32_t)) != 0) {
        fprintf(stderr, "the tets differ\n");
        goto out;
    }
    printf("same mesh: %zu points (max difference %g), %zu tets\n",
           x->npoints, diff, x->ntets);
    rc = 0;
out:
    st_tetmesh_free(x);
    st_tetmesh_free(y);
    return rc;
}

/* volume_only: the tets alone in every .msh variant and .mesh (no
 * triangles, no "boundary" group or surface entity); they read back the
 * same; st_tetmesh_write (not atomic) honours it too. */
static int file_has(const char *path, const char *needle)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return -1;
    static char buf[1 << 20];
    size_t n = fread(buf, 1, sizeof buf - 1, f);
    fclose(f);
    size_t k = strlen(needle);
    for (size_t i = 0; i + k <= n; i++)
        if (memcmp(buf + i, needle, k) == 0)
            return 1;
    return 0;
}

static void test_volume_only(void)
{
    st_tetmesh *m = sample_mesh(3);
    for (size_t i = 0; i < NVARIANTS; i++) {
        const variant *v = &k_variants[i];
        char path[256], path2[256];
        snprintf(path, sizeof path, "%s/vo-%s", g_dir, v->file);
        snprintf(path2, sizeof path2, "%s/vw-%s", g_dir, v->file);
        st_tetformat_opts o = {.msh_version = v->version, .binary = v->binary,
                               .volume_only = 1};
        st_error e;
        st_status s = st_tetmesh_save(m, path, &o, &e);
        st_status s2 = st_tetmesh_write(m, path2, &o, &e);
        st_tetmesh *r = NULL, *r2 = NULL;
        if (!s)
            s = st_tetmesh_read(&r, path, 0, &e);
        if (!s2)
            s2 = st_tetmesh_read(&r2, path2, 0, &e);
        TAP_CHECK(!s && !s2 && same_mesh(m, r) && same_mesh(m, r2),
                  "volume_only %s: written (save and write) and read back the same", v->file);
        if (strstr(v->file, ".msh"))
            TAP_CHECK(file_has(path, "boundary") == 0 && file_has(path2, "boundary") == 0 &&
                      file_has(path, "\"volume\"") == 1,
                      "volume_only %s: the \"volume\" group alone", v->file);
        if (strstr(v->file, ".mesh"))
            TAP_CHECK(file_has(path, "Triangles") == 0 && file_has(path2, "Triangles") == 0,
                      "volume_only %s: no Triangles", v->file);
        st_tetmesh_free(r);
        st_tetmesh_free(r2);
    }
    /* The default keeps them. */
    char path[256];
    snprintf(path, sizeof path, "%s/def.mesh", g_dir);
    st_error e;
    TAP_CHECK(st_tetmesh_save(m, path, NULL, &e) == ST_OK && file_has(path, "Triangles") == 1,
              "the default .mesh has its Triangles");
    st_tetmesh_free(m);
}

int main(int argc, char **argv)
{
    if (argc == 3 && strcmp(argv[1], "--write") == 0)
        return write_samples(argv[2]);
    if ((argc == 4 || argc == 5) && strcmp(argv[1], "--compare") == 0)
        return compare_files(
            argv[2], argv[3],
            argc == 5 && strcmp(argv[4], "--sets") == 0          ? 1
            : argc == 5 && strcmp(argv[4], "--renumbered") == 0 ? 2
                                                                 : 0);
    static const tap_test tests[] = {TAP_TEST(paths), TAP_TEST(round_trips),
                                     TAP_TEST(volume_only), TAP_TEST(written_text),
                                     TAP_TEST(foreign_files), TAP_TEST(malformed),
                                     TAP_TEST(truncations), {0}};
    tap_select(argc, argv, tests);
    if (!mkdtemp(g_dir)) {
        perror("mkdtemp");
        return 1;
    }
    tap_run(tests);
    char cmd[300];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", g_dir);
    if (system(cmd) != 0)
        TAP_NOTE("could not remove %s", g_dir);
    return tap_done();
}
