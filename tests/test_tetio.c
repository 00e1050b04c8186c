/*
 * test_tetio.c - tet meshes through .vtu (tetio.h): round trips through a
 * file, memory and a pipe keep points, tets, arrays and meta bit for bit;
 * the writer adds the quality arrays; bad input is refused with a message
 * naming the input, and VTK prints nothing.
 */
#include "souptet/tetio.h"
#include "souptet/tetmesh.h"
#include "souptet/tetqual.h"
#include "../src/adapters/gridio_internal.h"
#include "cubetets.h"
#include "tap.h"

#include <fcntl.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static char g_dir[] = "/tmp/test_tetio.XXXXXX";

/* Two tets sharing a face, points with many significant digits, a point
 * array and a 3-component cell array, meta with a multi-line history. */
static st_tetmesh *sample(void)
{
    st_tetmesh *m = st_tetmesh_new();
    add_pt(m, 0.1, 0.2, 0.3);
    add_pt(m, 1.0 / 3.0, 0, 1e-300);
    add_pt(m, 0, 2.0 / 7.0, 0);
    add_pt(m, 0, 0, 1e10 + 0.5);
    add_pt(m, -1.25, -1.5, -1.75);
    st_tetmesh_add_tet(m, 0, 1, 2, 3, NULL);
    st_tetmesh_add_tet(m, 0, 2, 1, 4, NULL);
    double *v;
    st_tetmesh_add_array(m, "temperature", ST_ON_POINTS, 1, &v, NULL);
    for (int i = 0; i < 5; i++)
        v[i] = 1.0 / (i + 3);
    st_tetmesh_add_array(m, "region", ST_ON_CELLS, 3, &v, NULL);
    for (int i = 0; i < 6; i++)
        v[i] = i * 0.7;
    st_meta_set(&m->meta, "source", "bunny.obj");
    st_meta_set(&m->meta, "h", "0.0625");
    st_meta_set(&m->meta, "lattice", "cubic5");
    st_meta_set(&m->meta, "history",
                "soupdist -r 64 bunny.obj\nlatticetet --density 0.5");
    /* Numbers in the .vtu are Float64 only when %.17g gives them back
     * exactly; everything else stays text (bytes). */
    st_meta_set(&m->meta, "offset_ratio", "0.40000000000000002");
    st_meta_set(&m->meta, "seed", "1");
    st_meta_set(&m->meta, "not_shortest", "1e5");
    st_meta_set(&m->meta, "padded", " 2");
    st_meta_set(&m->meta, "nan", "nan");
    st_meta_set(&m->meta, "big", "18446744073709551615");
    st_meta_set(&m->meta, "empty", "");
    st_meta_set(&m->meta, "utf8", "caf\xc3\xa9 \xe2\x9c\x93");
    return m;
}

static int same_mesh(const st_tetmesh *a, const st_tetmesh *b)
{
    if (!a || !b || a->npoints != b->npoints || a->ntets != b->ntets)
        return 0;
    if (a->npoints &&
        memcmp(a->xyz, b->xyz, a->npoints * 3 * sizeof(double)) != 0)
        return 0;
    if (a->ntets &&
        memcmp(a->tets, b->tets, a->ntets * 4 * sizeof(uint32_t)) != 0)
        return 0;
    if (a->narrays != b->narrays)
        return 0;
    for (size_t i = 0; i < a->narrays; i++) {
        const st_tet_array *x = &a->arrays[i];
        const st_tet_array *y = st_tetmesh_find_array(b, x->name, x->assoc);
        if (!y || y->ncomp != x->ncomp)
            return 0;
        size_t n = (x->assoc == ST_ON_POINTS ? a->npoints : a->ntets) *
                   (size_t)x->ncomp;
        if (n && memcmp(x->values, y->values, n * sizeof(double)) != 0)
            return 0;
    }
    for (size_t i = 0; i < a->meta.count; i++) {
        const char *v = st_meta_get(&b->meta, a->meta.entries[i].key);
        if (!v || strcmp(v, a->meta.entries[i].value) != 0)
            return 0;
    }
    return a->meta.count == b->meta.count;
}

static void path_in(char *buf, size_t n, const char *name)
{
    snprintf(buf, n, "%s/%s", g_dir, name);
}

/* Runs with stderr redirected to a file; returns what was printed. */
static long stderr_begin(int *saved)
{
    char p[256];
    path_in(p, sizeof p, "stderr.txt");
    fflush(stderr);
    *saved = dup(2);
    int fd = open(p, O_WRONLY | O_CREAT | O_TRUNC, 0600);
    dup2(fd, 2);
    close(fd);
    return 0;
}
static long stderr_end(int saved)
{
    char p[256];
    struct stat st;
    fflush(stderr);
    dup2(saved, 2);
    close(saved);
    path_in(p, sizeof p, "stderr.txt");
    return stat(p, &st) == 0 ? (long)st.st_size : -1;
}

static void test_file_roundtrip(void)
{
    st_tetmesh *m = sample(), *r = NULL;
    st_error err;
    char p[256];
    path_in(p, sizeof p, "m.vtu");
    TAP_CHECK(st_tetmesh_write(m, p, NULL, &err) == ST_OK, "write m.vtu");
    TAP_CHECK(st_tetmesh_read(&r, p, 0, &err) == ST_OK && same_mesh(m, r),
              "file round trip: points, tets, arrays, meta bit for bit");
    TAP_CHECK(r && !st_tetmesh_find_array(r, "min_dihedral", ST_ON_CELLS),
              "the derived quality arrays are not read back as mesh arrays");
    st_tetmesh_free(r);
    r = NULL;
    path_in(p, sizeof p, "saved.vtu");
    TAP_CHECK(st_tetmesh_save(m, p, NULL, &err) == ST_OK &&
                  st_tetmesh_read(&r, p, 0, &err) == ST_OK && same_mesh(m, r),
              "st_tetmesh_save writes the file atomically, same content");
    st_tetmesh_free(r);
    r = NULL;
    /* A file name without the extension is read by content. */
    char q[256];
    path_in(q, sizeof q, "noext");
    rename(p, q);
    TAP_CHECK(st_tetmesh_read(&r, q, 0, &err) == ST_OK && same_mesh(m, r),
              "a file without extension is read by its content");
    st_tetmesh_free(r);
    r = NULL;
    path_in(p, sizeof p, "m.txt");
    TAP_CHECK(st_tetmesh_write(m, p, NULL, &err) == ST_EINPUT &&
                  strstr(err.msg, "unknown tet mesh format"),
              "writing m.txt: unknown format (%s)", err.msg);
    path_in(p, sizeof p, "nodir/x.vtu");
    TAP_CHECK(st_tetmesh_save(m, p, NULL, &err) != ST_OK &&
                  strcmp(err.file, p) == 0,
              "save into a missing directory fails naming the target");
    st_tetmesh_free(m);
}

/* The simulator formats go through tetformat.h by extension: points,
 * tets and meta come back (arrays are .vtu's only). */
static void test_other_formats(void)
{
    static const char *names[] = {"m.msh", "m.mesh", "m.node"};
    st_tetmesh *m = sample();
    st_tetmesh_clear_arrays(m);
    for (int i = 0; i < 3; i++) {
        st_tetmesh *r = NULL;
        st_error err;
        char p[256];
        path_in(p, sizeof p, names[i]);
        st_status s = st_tetmesh_save(m, p, NULL, &err);
        if (s == ST_OK)
            s = st_tetmesh_read(&r, p, 0, &err);
        TAP_CHECK(s == ST_OK && same_mesh(m, r),
                  "%s: dispatched by extension, points, tets and meta "
                  "round-trip%s%s",
                  names[i], s ? ": " : "", s ? err.msg : "");
        st_tetmesh_free(r);
    }
    TAP_CHECK(st_tetformat_from_path("a/b.MSH") == ST_TETFORMAT_MSH &&
                  st_tetformat_from_path("x.ele") == ST_TETFORMAT_TETGEN &&
                  st_tetformat_from_path("x.mesh") == ST_TETFORMAT_MEDIT &&
                  st_tetformat_from_path("x.Vtu") == ST_TETFORMAT_VTU &&
                  st_tetformat_from_path("-") == ST_TETFORMAT_VTU &&
                  st_tetformat_from_path("x.obj") == ST_TETFORMAT_NONE &&
                  st_tetformat_from_path(".vtu") == ST_TETFORMAT_NONE,
              "formats from paths");
    st_tetmesh_free(m);
}

/* A points-only mesh (soupmesh --embed F.vtu) is written with one vertex
 * cell per point and no cell arrays, and reads back as points only. */
static void test_points_only(void)
{
    st_tetmesh *m = st_tetmesh_new(), *r = NULL;
    add_pt(m, 0.1, 0.2, 0.3);
    add_pt(m, 1, 2, 3);
    add_pt(m, -1, 0.5, 1e-7);
    double *v;
    st_tetmesh_add_array(m, "embed_tet", ST_ON_POINTS, 1, &v, NULL);
    v[0] = 3; v[1] = -1; v[2] = 7;
    st_meta_set(&m->meta, "source", "x.obj");
    st_error err;
    char p[256];
    path_in(p, sizeof p, "pts.vtu");
    TAP_CHECK(st_tetmesh_write(m, p, NULL, &err) == ST_OK, "write a points-only .vtu");
    FILE *f = fopen(p, "rb");
    char buf[4096] = {0};
    size_t n = f ? fread(buf, 1, sizeof buf - 1, f) : 0;
    if (f)
        fclose(f);
    buf[n] = '\0';
    TAP_CHECK(strstr(buf, "NumberOfCells=\"3\"") != NULL &&
                  strstr(buf, "min_dihedral") == NULL,
              "points-only: 3 cells for 3 points, no empty quality arrays");
    TAP_CHECK(st_tetmesh_read(&r, p, 0, &err) == ST_OK && same_mesh(m, r) &&
                  r->ntets == 0,
              "points-only: reads back as the same points, arrays, no tets");
    st_tetmesh_free(r);
    st_tetmesh_free(m);
}

static void test_mem_roundtrip(void)
{
    st_tetmesh *m = sample(), *r = NULL;
    st_error err;
    unsigned char *buf;
    size_t n;
    TAP_CHECK(st_tetmesh_write_mem(&buf, &n, m, &err) == ST_OK && n > 100,
              "write to memory (%zu bytes)", n);
    TAP_CHECK(st_tetmesh_read_mem(&r, buf, n, "mem", 0, &err) == ST_OK &&
                  same_mesh(m, r),
              "memory round trip: same mesh");
    /* The document: an UnstructuredGrid, appended raw binary, zlib. */
    char *s = malloc(n + 1);
    memcpy(s, buf, n);
    s[n] = 0;
    TAP_CHECK(strstr(s, "type=\"UnstructuredGrid\"") &&
                  strstr(s, "compressor=\"vtkZLibDataCompressor\"") &&
                  strstr(s, "header_type=\"UInt64\"") &&
                  strstr(s, "encoding=\"raw\""),
              "document: UnstructuredGrid, zlib, UInt64 headers, raw "
              "appended data");
    TAP_CHECK(strstr(s, "Name=\"min_dihedral\"") &&
                  strstr(s, "Name=\"max_dihedral\"") &&
                  strstr(s, "Name=\"volume\"") &&
                  strstr(s, "Name=\"region\"") &&
                  strstr(s, "Name=\"temperature\"") &&
                  strstr(s, "Name=\"history\"") && strstr(s, "Name=\"h\""),
              "document names the quality arrays, the mesh arrays and the "
              "meta keys");
    free(s);
    /* Truncations anywhere must fail cleanly (no crash, a message). */
    int all_fail = 1;
    for (size_t cut = 1; cut < n; cut += n / 23 + 1) {
        st_tetmesh *t = NULL;
        st_status st = st_tetmesh_read_mem(&t, buf, cut, "cut", 0, &err);
        all_fail &= st != ST_OK && t == NULL && strcmp(err.file, "cut") == 0;
        st_tetmesh_free(t);
    }
    TAP_CHECK(all_fail, "every truncated document is refused, naming the "
              "input");
    st_tetmesh_free(r);
    TAP_CHECK(st_tetmesh_read_mem(&r, buf, n, "lim", 100, &err) == ST_ELIMIT,
              "max_bytes 100: refused (%s)", err.msg);
    free(buf);
    st_tetmesh_free(r);

    /* An empty mesh travels too. */
    st_tetmesh *e = st_tetmesh_new();
    r = NULL;
    TAP_CHECK(st_tetmesh_write_mem(&buf, &n, e, &err) == ST_OK &&
                  st_tetmesh_read_mem(&r, buf, n, "empty", 0, &err) ==
                      ST_OK &&
                  r->ntets == 0 && r->npoints == 0,
              "an empty mesh round-trips");
    free(buf);
    st_tetmesh_free(r);
    st_tetmesh_free(e);
    st_tetmesh_free(m);
}

static void test_pipe(void)
{
    st_tetmesh *m = sample(), *r = NULL;
    st_error err;
    char p[256];
    path_in(p, sizeof p, "pipe.vtu");
    fflush(stdout);
    int saved = dup(1);
    int fd = open(p, O_WRONLY | O_CREAT | O_TRUNC, 0600);
    dup2(fd, 1);
    close(fd);
    st_status s = st_tetmesh_write(m, "-", NULL, &err);
    fflush(stdout);
    dup2(saved, 1);
    close(saved);
    TAP_CHECK(s == ST_OK, "write to stdout");
    saved = dup(0);
    fd = open(p, O_RDONLY);
    dup2(fd, 0);
    close(fd);
    s = st_tetmesh_read(&r, "-", 0, &err);
    dup2(saved, 0);
    close(saved);
    clearerr(stdin);
    TAP_CHECK(s == ST_OK && same_mesh(m, r),
              "stdout bytes read back from stdin: same mesh");
    st_tetmesh_free(r);
    r = NULL;
    TAP_CHECK(st_tetmesh_read(&r, p, 0, &err) == ST_OK && same_mesh(m, r),
              "the stdout bytes are a valid .vtu file");
    st_tetmesh_free(r);
    st_tetmesh_free(m);
}

/* An ASCII .vtu with the given points, connectivity and cell types. */
static char *ascii_vtu(const char *points, int npts, const char *conn,
                       const char *offsets, const char *types, int ncells)
{
    char *s = malloc(4096);
    snprintf(s, 4096,
             "<?xml version=\"1.0\"?>\n"
             "<VTKFile type=\"UnstructuredGrid\" version=\"0.1\">\n"
             "<UnstructuredGrid><Piece NumberOfPoints=\"%d\" "
             "NumberOfCells=\"%d\">\n"
             "<Points><DataArray type=\"Float64\" NumberOfComponents=\"3\" "
             "format=\"ascii\">%s</DataArray></Points>\n"
             "<Cells>\n"
             "<DataArray type=\"Int64\" Name=\"connectivity\" "
             "format=\"ascii\">%s</DataArray>\n"
             "<DataArray type=\"Int64\" Name=\"offsets\" "
             "format=\"ascii\">%s</DataArray>\n"
             "<DataArray type=\"UInt8\" Name=\"types\" "
             "format=\"ascii\">%s</DataArray>\n"
             "</Cells></Piece></UnstructuredGrid></VTKFile>\n",
             npts, ncells, points, conn, offsets, types);
    return s;
}

static st_status read_str(const char *s, st_tetmesh **out, st_error *err)
{
    return st_tetmesh_read_mem(out, (const unsigned char *)s, strlen(s),
                               "in.vtu", 0, err);
}

static void test_bad_input(void)
{
    st_tetmesh *r = NULL;
    st_error err;
    int saved;
    stderr_begin(&saved);

    char *s = ascii_vtu("0 0 0 1 0 0 0 1 0 0 0 1", 4, "0 1 2 3", "4", "10", 1);
    st_status st1 = read_str(s, &r, &err);
    int ok1 = st1 == ST_OK && r && r->ntets == 1 && r->tets[3] == 3 &&
              r->xyz[3] == 1.0;
    st_tetmesh_free(r);
    r = NULL;
    free(s);

    s = ascii_vtu("0 0 0 1 0 0 0 1 0", 3, "0 1 2", "3", "5", 1);
    st_status st2 = read_str(s, &r, &err);
    char m2[512];
    snprintf(m2, sizeof m2, "%s", err.msg);
    free(s);

    s = ascii_vtu("0 0 0 1 0 0 0 1 0 0 0 1", 4, "0 1 2 7", "4", "10", 1);
    st_status st3 = read_str(s, &r, &err);
    char m3[512];
    snprintf(m3, sizeof m3, "%s", err.msg);
    free(s);

    s = ascii_vtu("0 0 0 1 0 0 0 nan 0 0 0 1", 4, "0 1 2 3", "4", "10", 1);
    st_status st4 = read_str(s, &r, &err);
    char m4[512];
    snprintf(m4, sizeof m4, "%s", err.msg);
    free(s);

    st_status st5 = read_str("<VTKFile type=\"UnstructuredGrid\" garbage",
                             &r, &err);
    char f5[512], m5[512];
    snprintf(f5, sizeof f5, "%s", err.file);
    snprintf(m5, sizeof m5, "%s", err.msg);

    st_status st6 = st_tetmesh_read_mem(&r, (const unsigned char *)"", 0,
                                        "in.vtu", 0, &err);
    st_status st7 = read_str("not xml at all", &r, &err);

    char p[256];
    path_in(p, sizeof p, "empty.vtu");
    fclose(fopen(p, "w"));
    st_status st8 = st_tetmesh_read(&r, p, 0, &err);
    char f8[512];
    snprintf(f8, sizeof f8, "%s", err.file);
    path_in(p, sizeof p, "missing.vtu");
    st_status st9 = st_tetmesh_read(&r, p, 0, &err);
    /* A VTK ImageData is XML but not an UnstructuredGrid. */
    st_status st10 = read_str("<?xml version=\"1.0\"?><VTKFile "
                              "type=\"ImageData\" version=\"0.1\"><ImageData "
                              "WholeExtent=\"0 1 0 1 0 1\" Origin=\"0 0 0\" "
                              "Spacing=\"1 1 1\"></ImageData></VTKFile>",
                              &r, &err);
    /* The field adapter collects VTK's messages too: each adapter gets
     * its own, whichever ran first. */
    /* Documents that pass the pre-flight check (src/io/vtkxml.h) but whose
     * zlib block is not zlib: VTK itself fails and reports it. */
    st_grid *g = NULL;
    const char *junk =
        "<VTKFile type=\"ImageData\" version=\"1.0\" "
        "compressor=\"vtkZLibDataCompressor\"><ImageData "
        "WholeExtent=\"0 1 0 0 0 0\"><Piece Extent=\"0 1 0 0 0 0\">"
        "<PointData><DataArray type=\"Float32\" Name=\"f\" "
        "format=\"binary\">AQAAAGAAAAAAAAAABAAAAA==AAAAAA==</DataArray>"
        "</PointData></Piece></ImageData></VTKFile>";
    st_status st11 = st_gridio_read_vti_mem(&g, (const unsigned char *)junk,
                                            strlen(junk), "f.vti", 0, &err);
    char m11[512];
    snprintf(m11, sizeof m11, "%s", err.msg);
    st_status st12 = read_str(
        "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" "
        "compressor=\"vtkZLibDataCompressor\"><UnstructuredGrid><Piece "
        "NumberOfPoints=\"4\" NumberOfCells=\"1\"><Points><DataArray "
        "type=\"Float64\" NumberOfComponents=\"3\" format=\"binary\">"
        "AQAAAGAAAAAAAAAABAAAAA==AAAAAA==</DataArray></Points><Cells>"
        "<DataArray type=\"Int32\" Name=\"connectivity\" format=\"ascii\">"
        "0 1 2 3</DataArray><DataArray type=\"Int32\" Name=\"offsets\" "
        "format=\"ascii\">4</DataArray><DataArray type=\"UInt8\" "
        "Name=\"types\" format=\"ascii\">10</DataArray></Cells></Piece>"
        "</UnstructuredGrid></VTKFile>",
        &r, &err);
    char m12[512];
    snprintf(m12, sizeof m12, "%s", err.msg);
    long printed = stderr_end(saved);

    TAP_CHECK(ok1, "an ASCII .vtu with one VTK_TETRA reads");
    TAP_CHECK(st2 == ST_EINPUT && strstr(m2, "not a tetrahedron"),
              "a triangle cell is refused (%s)", m2);
    TAP_CHECK(st3 == ST_EINPUT && strstr(m3, "point 7"),
              "an index out of range is refused (%s)", m3);
    TAP_CHECK(st4 == ST_EINPUT && strstr(m4, "not finite"),
              "a NaN point is refused (%s)", m4);
    TAP_CHECK(st5 == ST_EINPUT && strcmp(f5, "in.vtu") == 0 && m5[0],
              "garbled XML is refused, naming the input (%s)", m5);
    TAP_CHECK(st6 == ST_EINPUT, "empty input is refused");
    TAP_CHECK(st7 == ST_EINPUT, "non-XML input is refused");
    TAP_CHECK(st8 == ST_EINPUT && strstr(f8, "empty.vtu"),
              "an empty file is refused, naming it");
    TAP_CHECK(st9 == ST_EIO, "a missing file: I/O error");
    TAP_CHECK(st10 == ST_EINPUT, "ImageData is not a tet mesh");
    TAP_CHECK(st11 == ST_EINPUT && strstr(m11, "Zlib error"),
              "a bad .vti after .vtu reads: the field adapter still gets "
              "VTK's message (%s)", m11);
    TAP_CHECK(st12 == ST_EINPUT && strstr(m12, "Zlib error"),
              "and the mesh adapter still gets its own (%s)", m12);
    TAP_CHECK(printed == 0, "VTK printed nothing on stderr (%ld bytes)",
              printed);
}

int main(int argc, char **argv)
{
    /* test_tetio --write FILE: the sample mesh, for the tool tests (which
     * check that VTK's own reader opens what the library writes). */
    if (argc == 3 && strcmp(argv[1], "--write") == 0) {
        st_tetmesh *m = sample();
        st_error err;
        st_status s = st_tetmesh_save(m, argv[2], NULL, &err);
        st_tetmesh_free(m);
        if (s) {
            char buf[1200];
            fprintf(stderr, "test_tetio: %s\n",
                    st_error_format(&err, buf, sizeof buf));
            return 1;
        }
        return 0;
    }
    static const tap_test tests[] = {TAP_TEST(file_roundtrip), TAP_TEST(mem_roundtrip),
                                     TAP_TEST(points_only), TAP_TEST(other_formats),
                                     TAP_TEST(pipe), TAP_TEST(bad_input), {0}};
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
