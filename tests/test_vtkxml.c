/*
 * test_vtkxml.c - the pre-flight check of VTK XML input (src/io/vtkxml.h):
 * no .vti/.vtu file reaches VTK unless its structure and every size it
 * declares have been checked.
 *
 *   - every fuzzing finding (tests/data/fuzz/vti/, tests/data/fuzz/vtu/)
 *     is refused by the check and by the public readers with ST_EINPUT or
 *     ST_ELIMIT naming the file (and never crashes: this runs under
 *     ASan/UBSan in `make config=sanitize check`);
 *   - near misses, one per check: each is refused with the right status,
 *     line and words, and the unmodified document passes;
 *   - what other writers make passes and reads back through souptet's
 *     readers: VTK's writer in every data mode, compressor and header type
 *     and meshio (tests/data/vtk/, made by tests/data/vtk/make.py), and
 *     souptet's own writers.
 *
 * The data directory is tests/data beside the build directory holding
 * this binary (BUILD/tests/test_vtkxml -> ../../tests/data), else
 * tests/data from the current directory (make check runs from the top).
 */
#include "souptet/gridio.h"
#include "souptet/meta.h"
#include "souptet/tetio.h"
#include "souptet/tetmesh.h"
#include "../src/base/fileio.h"
#include "../src/io/vtkxml.h"
#include "../src/adapters/gridio_internal.h"
#include "../src/adapters/tetio_internal.h"
#include "tap.h"

#include <dirent.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* The harnesses' limit (fuzz/fuzz_grid.h). */
#define FUZZ_MAX ((size_t)64 << 20)

static char g_data[4096];
static char g_tmp[] = "/tmp/test_vtkxml.XXXXXX";

static void find_data(const char *argv0)
{
    struct stat st;
    const char *slash = argv0 ? strrchr(argv0, '/') : NULL;
    if (slash) {
        snprintf(g_data, sizeof g_data, "%.*s/../../tests/data",
                 (int)(slash - argv0), argv0);
        if (stat(g_data, &st) == 0 && S_ISDIR(st.st_mode))
            return;
    }
    snprintf(g_data, sizeof g_data, "tests/data");
}

static unsigned char *load(const char *path, size_t *n)
{
    unsigned char *d = NULL;
    st_error e;
    if (st_file_read(path, &d, n, &e) != ST_OK)
        return NULL;
    return d;
}

static int cmp_str(const void *a, const void *b)
{
    return strcmp(*(char *const *)a, *(char *const *)b);
}

/* The regular files of dir whose names end in suffix ("" for all),
 * sorted; *n of them. Caller frees each and the array. */
static char **list_dir(const char *dir, const char *suffix, size_t *n)
{
    *n = 0;
    DIR *d = opendir(dir);
    if (!d)
        return NULL;
    char **v = NULL;
    size_t cap = 0;
    struct dirent *de;
    while ((de = readdir(d))) {
        size_t l = strlen(de->d_name), s = strlen(suffix);
        if (de->d_name[0] == '.' || l < s ||
            strcmp(de->d_name + l - s, suffix) != 0)
            continue;
        if (*n == cap) {
            cap = cap ? 2 * cap : 32;
            v = realloc(v, cap * sizeof *v);
        }
        size_t pl = strlen(dir) + l + 2;
        v[*n] = malloc(pl);
        snprintf(v[*n], pl, "%s/%s", dir, de->d_name);
        (*n)++;
    }
    closedir(d);
    if (*n)
        qsort(v, *n, sizeof *v, cmp_str);
    return v;
}

static void free_list(char **v, size_t n)
{
    for (size_t i = 0; i < n; i++)
        free(v[i]);
    free(v);
}

/* The check as the adapters run it: with VTK's decompressors. */
static st_status vcheck(const unsigned char *d, size_t n, const char *name,
                        const char *type, size_t max_bytes, st_error *err)
{
    return st_vtkxml_check(d, n, name, type, max_bytes,
                           st_vtkxml_inflate_vtk, NULL, err);
}

static int refused(st_status s)
{
    return s == ST_EINPUT || s == ST_ELIMIT;
}

/* ---- (a) the fuzzing findings ------------------------------------------ */

static void test_findings(void)
{
    char dir[4200];
    const char *type[2] = {"ImageData", "UnstructuredGrid"};
    for (int k = 0; k < 2; k++) {
        snprintf(dir, sizeof dir, "%s/fuzz/%s", g_data, k ? "vtu" : "vti");
        size_t n;
        char **files = list_dir(dir, "", &n);
        TAP_CHECK(n > 0, "%s: findings to replay", dir);
        for (size_t i = 0; i < n; i++) {
            const char *f = files[i];
            const char *base = strrchr(f, '/') + 1;
            size_t size;
            unsigned char *d = load(f, &size);
            st_error e;
            memset(&e, 0, sizeof e);
            st_status s = d ? vcheck(d, size, f, type[k], FUZZ_MAX,
                                              &e)
                            : ST_EIO;
            TAP_CHECK(refused(s) && strcmp(e.file, f) == 0 && e.msg[0],
                      "%s: the check refuses it", base);
            if (s != ST_EIO) {
                char buf[1200];
                TAP_NOTE("  %s", st_error_format(&e, buf, sizeof buf));
            }
            st_error e2, e3;
            memset(&e2, 0, sizeof e2);
            memset(&e3, 0, sizeof e3);
            st_status s2, s3;
            if (k == 0) {
                st_grid *g = (st_grid *)1, *h = (st_grid *)1;
                s2 = st_grid_read_vti(&g, f, FUZZ_MAX, &e2);
                s3 = st_gridio_read_vti_mem(&h, d, size, "fuzz", FUZZ_MAX,
                                            &e3);
                TAP_CHECK(refused(s2) && !g && strcmp(e2.file, f) == 0,
                          "%s: st_grid_read_vti refuses it naming the file",
                          base);
                TAP_CHECK(refused(s3) && !h && strcmp(e3.file, "fuzz") == 0,
                          "%s: the in-memory .vti reader refuses it", base);
                st_grid_free(g);
                st_grid_free(h);
            } else {
                st_tetmesh *m = (st_tetmesh *)1, *q = (st_tetmesh *)1;
                s2 = st_tetio_read_vtu_file(&m, f, FUZZ_MAX, &e2);
                s3 = st_tetmesh_read_mem(&q, d, size, "fuzz", FUZZ_MAX, &e3);
                TAP_CHECK(refused(s2) && !m && strcmp(e2.file, f) == 0,
                          "%s: the .vtu file reader refuses it naming the "
                          "file",
                          base);
                TAP_CHECK(refused(s3) && !q && strcmp(e3.file, "fuzz") == 0,
                          "%s: st_tetmesh_read_mem refuses it", base);
                st_tetmesh_free(m);
                st_tetmesh_free(q);
            }
            free(d);
        }
        free_list(files, n);
    }
}

/* ---- (b) near misses ---------------------------------------------------- */

#define VTKFILE_OK                                                         \
    "type=\"ImageData\" version=\"1.0\" byte_order=\"LittleEndian\" "      \
    "header_type=\"UInt64\""
#define ARRAY_OK                                                           \
    "<DataArray type=\"Float32\" Name=\"sdf\" format=\"appended\" "        \
    "offset=\"0\"/>"
#define EXT_OK "0 3 0 2 0 1"   /* 4 x 3 x 2 = 24 points, 96 bytes */

/* What follows the payload in vti_doc. */
#define DOC_TAIL "\n  </AppendedData>\n</VTKFile>\n"

typedef struct doc {
    unsigned char *d;
    size_t n;
} doc;

/* An ImageData document: the VTKFile attributes, WholeExtent, Piece
 * Extent, the point array element (line 6) and the appended raw payload.
 */
static doc vti_doc(const char *vtkfile, const char *whole, const char *piece,
                   const char *array, const unsigned char *payload,
                   size_t plen)
{
    char head[2048];
    int h = snprintf(head, sizeof head,
                     "<?xml version=\"1.0\"?>\n"
                     "<VTKFile %s>\n"
                     "  <ImageData WholeExtent=\"%s\" Origin=\"0 0 0\" "
                     "Spacing=\"1 1 1\">\n"
                     "    <Piece Extent=\"%s\">\n"
                     "      <PointData Scalars=\"sdf\">\n"
                     "        %s\n"
                     "      </PointData>\n"
                     "    </Piece>\n"
                     "  </ImageData>\n"
                     "  <AppendedData encoding=\"raw\">\n   _",
                     vtkfile, whole, piece, array);
    const char tail[] = DOC_TAIL;
    doc r;
    r.n = (size_t)h + plen + sizeof tail - 1;
    r.d = malloc(r.n);
    memcpy(r.d, head, (size_t)h);
    if (plen)
        memcpy(r.d + h, payload, plen);
    memcpy(r.d + h + plen, tail, sizeof tail - 1);
    return r;
}

static size_t put_u64(unsigned char *p, uint64_t v)
{
    for (int i = 0; i < 8; i++)
        p[i] = (unsigned char)(v >> (8 * i));
    return 8;
}

/* Uncompressed payload: a UInt64 byte count `claim`, then nfloats floats
 * 0.5 i - 3. */
static size_t raw_payload(unsigned char *p, uint64_t claim, size_t nfloats)
{
    size_t n = put_u64(p, claim);
    for (size_t i = 0; i < nfloats; i++) {
        float f = 0.5f * (float)i - 3.0f;
        memcpy(p + n, &f, 4);
        n += 4;
    }
    return n;
}

/* Check one document: status, line (0: any) and a word in the message. */
static void expect(doc x, size_t max_bytes, const char *type, st_status want,
                   long long line, const char *word, const char *what)
{
    st_error e;
    memset(&e, 0, sizeof e);
    st_status s = vcheck(x.d, x.n, "m.vti", type, max_bytes, &e);
    int ok = s == want;
    if (want != ST_OK)
        ok = ok && strcmp(e.file, "m.vti") == 0 &&
             (line == 0 || e.line == line) && (!word || strstr(e.msg, word));
    TAP_CHECK(ok, "%s", what);
    if (!ok || want != ST_OK) {
        char buf[1200];
        TAP_NOTE("  status %d: %s", (int)s,
                 s ? st_error_format(&e, buf, sizeof buf) : "ok");
    }
    free(x.d);
}

/* A one-tet ascii UnstructuredGrid; np and ncomp go into NumberOfPoints
 * (line 3) and the points' NumberOfComponents (line 4), offs is the text
 * of the offsets (line 7). */
static doc ug_doc3(const char *np, const char *ncomp, const char *offs)
{
    char t[1024];
    snprintf(t, sizeof t,
             "<VTKFile type=\"UnstructuredGrid\" version=\"0.1\">\n"
             "<UnstructuredGrid>\n"
             "<Piece NumberOfPoints=\"%s\" NumberOfCells=\"1\">\n"
             "<Points><DataArray type=\"Float64\" "
             "NumberOfComponents=\"%s\" format=\"ascii\">"
             "0 0 0 1 0 0 0 1 0 0 0 1</DataArray></Points>\n"
             "<Cells>\n"
             "<DataArray type=\"Int32\" Name=\"connectivity\" "
             "format=\"ascii\">0 1 2 3</DataArray>\n"
             "<DataArray type=\"Int32\" Name=\"offsets\" "
             "format=\"ascii\">%s"
             "</DataArray>\n"
             "<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">10"
             "</DataArray>\n"
             "</Cells>\n"
             "</Piece></UnstructuredGrid></VTKFile>\n",
             np, ncomp, offs);
    doc x = {(unsigned char *)strdup(t), strlen(t)};
    return x;
}

static doc ug_doc(const char *np, const char *ncomp)
{
    return ug_doc3(np, ncomp, "4");
}

static void test_near_misses(void)
{
    unsigned char p[4096];
    size_t pn = raw_payload(p, 96, 24);

    /* the unmodified document: accepted, and VTK then reads it */
    doc ok = vti_doc(VTKFILE_OK, EXT_OK, EXT_OK, ARRAY_OK, p, pn);
    st_grid *g = NULL;
    st_error e;
    st_status s = st_gridio_read_vti_mem(&g, ok.d, ok.n, "m.vti", 0, &e);
    TAP_CHECK(s == ST_OK && g && g->nx == 4 && g->ny == 3 && g->nz == 2 &&
                  g->data[23] == 8.5f,
              "the hand-made appended raw .vti reads back");
    st_grid_free(g);
    expect(ok, 0, "ImageData", ST_OK, 0, NULL, "hand-made .vti passes");

    /* the compressor */
    expect(vti_doc(VTKFILE_OK " compressor=\"vtkZlibDataCompressor\"", EXT_OK,
                   EXT_OK, ARRAY_OK, p, pn),
           0, "ImageData", ST_EINPUT, 2, "unknown compressor",
           "a misspelled compressor name is refused");
    expect(vti_doc(VTKFILE_OK " compresor=\"vtkZLibDataCompressor\"", EXT_OK,
                   EXT_OK, ARRAY_OK, p, pn),
           0, "ImageData", ST_EINPUT, 2, "unknown attribute 'compresor'",
           "a misspelled compressor attribute is refused");
    /* the root */
    expect(vti_doc("type=\"PolyData\" version=\"1.0\"", EXT_OK, EXT_OK,
                   ARRAY_OK, p, pn),
           0, "ImageData", ST_EINPUT, 2, "not ImageData",
           "VTKFile of another type is refused");
    expect(vti_doc("type=\"ImageData\" byte_order=\"LittleEndian\"", EXT_OK,
                   EXT_OK, ARRAY_OK, p, pn),
           0, "ImageData", ST_EINPUT, 2, "version",
           "VTKFile without a version is refused");
    expect(vti_doc("type=\"ImageData\" version=\"1.0\" byte_order=\"Middle\"",
                   EXT_OK, EXT_OK, ARRAY_OK, p, pn),
           0, "ImageData", ST_EINPUT, 2, "byte_order",
           "an unknown byte_order is refused");
    expect(vti_doc("type=\"ImageData\" version=\"1.0\" header_type=\"UInt16\"",
                   EXT_OK, EXT_OK, ARRAY_OK, p, pn),
           0, "ImageData", ST_EINPUT, 2, "header_type",
           "an unknown header_type is refused");
    /* the array element */
    expect(vti_doc(VTKFILE_OK, EXT_OK, EXT_OK,
                   "<DataArray Name=\"band\" format=\"appended\" "
                   "offset=\"0\"/>",
                   p, pn),
           0, "ImageData", ST_EINPUT, 6, "DataArray \"band\": no type",
           "a DataArray without a type is refused at its line");
    expect(vti_doc(VTKFILE_OK, EXT_OK, EXT_OK,
                   "<DataArray type=\"Float16\" Name=\"sdf\" "
                   "format=\"appended\" offset=\"0\"/>",
                   p, pn),
           0, "ImageData", ST_EINPUT, 6, "type is not",
           "an unknown type is refused");
    expect(vti_doc(VTKFILE_OK, EXT_OK, EXT_OK,
                   "<DataArray type=\"Float32\" format=\"appended\" "
                   "offset=\"0\"/>",
                   p, pn),
           0, "ImageData", ST_EINPUT, 6, "no Name",
           "a point array without a Name is refused");
    expect(vti_doc(VTKFILE_OK, EXT_OK, EXT_OK,
                   "<DataArray type=\"Float32\" Name=\"sdf\" "
                   "NumberOfComponents=\"0\" format=\"appended\" "
                   "offset=\"0\"/>",
                   p, pn),
           0, "ImageData", ST_EINPUT, 6, "NumberOfComponents",
           "NumberOfComponents 0 is refused");
    expect(vti_doc(VTKFILE_OK, EXT_OK, EXT_OK,
                   "<DataArray type=\"Float32\" Name=\"sdf\" "
                   "NumberOfTuples=\"-1\" format=\"appended\" offset=\"0\"/>",
                   p, pn),
           0, "ImageData", ST_EINPUT, 6, "NumberOfTuples",
           "a negative NumberOfTuples is refused");
    expect(vti_doc(VTKFILE_OK, EXT_OK, EXT_OK,
                   "<DataArray type=\"Float32\" Name=\"sdf\" "
                   "foramt=\"appended\" offset=\"0\"/>",
                   p, pn),
           0, "ImageData", ST_EINPUT, 6, "no format",
           "an array without a format is refused");
    expect(vti_doc(VTKFILE_OK, EXT_OK, EXT_OK,
                   "<DataArray type=\"Float32\" Name=\"sdf\" "
                   "format=\"base64\" offset=\"0\"/>",
                   p, pn),
           0, "ImageData", ST_EINPUT, 6, "format is not",
           "an unknown format is refused");
    expect(vti_doc(VTKFILE_OK, EXT_OK, EXT_OK,
                   "<DataArray type=\"Float32\" Name=\"sdf\" "
                   "format=\"appended\" offset=\"-8\"/>",
                   p, pn),
           0, "ImageData", ST_EINPUT, 6, "offset",
           "a negative offset is refused");
    expect(vti_doc(VTKFILE_OK, EXT_OK, EXT_OK,
                   "<DataArray type=\"Float32\" Name=\"sdf\" "
                   "format=\"appended\" offset=\"1000\"/>",
                   p, pn),
           0, "ImageData", ST_EINPUT, 6, "lies beyond",
           "an offset beyond the appended data is refused");
    /* extents */
    expect(vti_doc(VTKFILE_OK, "0 3 2 0 0 1", EXT_OK, ARRAY_OK, p, pn), 0,
           "ImageData", ST_EINPUT, 3, "lo > hi",
           "a WholeExtent with lo > hi is refused");
    expect(vti_doc(VTKFILE_OK, EXT_OK, "0 3 2 1 0 1", ARRAY_OK, p, pn), 0,
           "ImageData", ST_EINPUT, 4, "lo > hi",
           "a Piece Extent with lo > hi is refused");
    expect(vti_doc(VTKFILE_OK, EXT_OK, "0 4 0 2 0 1", ARRAY_OK, p, pn), 0,
           "ImageData", ST_EINPUT, 4, "outside",
           "a Piece Extent outside the WholeExtent is refused");
    expect(vti_doc(VTKFILE_OK, "0 3 0 2 0", EXT_OK, ARRAY_OK, p, pn), 0,
           "ImageData", ST_EINPUT, 3, "WholeExtent",
           "a WholeExtent of five numbers is refused");
    /* sizes: uncompressed */
    {
        unsigned char q[4096];
        size_t qn = raw_payload(q, 4294967296ull, 24);
        expect(vti_doc(VTKFILE_OK, EXT_OK, EXT_OK, ARRAY_OK, q, qn), 0,
               "ImageData", ST_EINPUT, 6, "claims 4294967296 bytes but",
               "a block claiming more bytes than remain is refused");
        qn = raw_payload(q, 92, 23);
        expect(vti_doc(VTKFILE_OK, EXT_OK, EXT_OK, ARRAY_OK, q, qn), 0,
               "ImageData", ST_EINPUT, 6, "declares 24 values",
               "a block shorter than the extent's points is refused");
        /* the file ends 5 bytes into the payload */
        doc x = vti_doc(VTKFILE_OK, EXT_OK, EXT_OK, ARRAY_OK, q, qn);
        x.n -= qn - 5 + strlen(DOC_TAIL);
        expect(x, 0, "ImageData", ST_EINPUT, 6, "cut short",
               "a block header cut short by the end of file is refused");
    }
    expect(vti_doc(VTKFILE_OK, EXT_OK, EXT_OK, ARRAY_OK, p, pn), 95,
           "ImageData", ST_ELIMIT, 6, "--max-memory",
           "a block decoding to max_bytes + 1: limit error");
    expect(vti_doc(VTKFILE_OK, EXT_OK, EXT_OK, ARRAY_OK, p, pn), 96,
           "ImageData", ST_OK, 0, NULL,
           "a block decoding to max_bytes passes");
    /* sizes: compressed */
    {
        const char *zf = VTKFILE_OK " compressor=\"vtkZLibDataCompressor\"";
        unsigned char q[256];
        size_t qn = 0;
        qn += put_u64(q + qn, 1);    /* nblocks */
        qn += put_u64(q + qn, 96);   /* block size */
        qn += put_u64(q + qn, 0);    /* last block: full */
        qn += put_u64(q + qn, 20);   /* compressed size */
        memset(q + qn, 0x55, 20);
        qn += 20;
        expect(vti_doc(zf, EXT_OK, EXT_OK, ARRAY_OK, q, qn), 0, "ImageData",
               ST_OK, 0, NULL, "a consistent compression header passes");
        expect(vti_doc(zf, EXT_OK, EXT_OK, ARRAY_OK, q, qn), 95, "ImageData",
               ST_ELIMIT, 6, "--max-memory",
               "compressed: decoded size max_bytes + 1 is a limit error");
        expect(vti_doc(zf, EXT_OK, EXT_OK, ARRAY_OK, q, qn), 96, "ImageData",
               ST_OK, 0, NULL, "compressed: decoded size max_bytes passes");
        /* raw appended data run to the end of the file: after the
         * header, 20 bytes of block and the closing tags */
        const uint64_t left = 20 + strlen(DOC_TAIL);
        char want[64];
        snprintf(want, sizeof want, "claim %llu bytes but %llu remain",
                 (unsigned long long)left + 1, (unsigned long long)left);
        put_u64(q + 24, left);
        expect(vti_doc(zf, EXT_OK, EXT_OK, ARRAY_OK, q, qn), 0, "ImageData",
               ST_OK, 0, NULL, "a compressed block ending at EOF passes");
        put_u64(q + 24, left + 1);
        expect(vti_doc(zf, EXT_OK, EXT_OK, ARRAY_OK, q, qn), 0, "ImageData",
               ST_EINPUT, 6, want,
               "a compressed block one byte past EOF is refused");
        put_u64(q + 24, 1u << 30);
        expect(vti_doc(zf, EXT_OK, EXT_OK, ARRAY_OK, q, qn), 0, "ImageData",
               ST_EINPUT, 6, "claim 1073741824 bytes",
               "a compressed size lying about its length is refused");
        put_u64(q + 24, 20);
        put_u64(q, (uint64_t)1 << 60);
        expect(vti_doc(zf, EXT_OK, EXT_OK, ARRAY_OK, q, qn), 0, "ImageData",
               ST_EINPUT, 6, "blocks, more than",
               "a block count beyond the data is refused unallocated");
        put_u64(q, 3);   /* 3 sizes: 20, 0x5555.., 0x5555.. */
        put_u64(q + 8, (uint64_t)1 << 63);
        expect(vti_doc(zf, EXT_OK, EXT_OK, ARRAY_OK, q, qn), 0, "ImageData",
               ST_EINPUT, 6, NULL,
               "blocks whose sizes overflow are refused");
        size_t on = 0;
        unsigned char o[256];
        on += put_u64(o + on, 3);
        on += put_u64(o + on, (uint64_t)1 << 63);
        on += put_u64(o + on, 0);
        for (int k = 0; k < 3; k++)
            on += put_u64(o + on, 1);
        memset(o + on, 0x55, 3);
        on += 3;
        expect(vti_doc(zf, EXT_OK, EXT_OK, ARRAY_OK, o, on), 0, "ImageData",
               ST_EINPUT, 6, "more than any memory",
               "a block count x block size overflowing 64 bits is refused");
        put_u64(o + 8, 0);
        expect(vti_doc(zf, EXT_OK, EXT_OK, ARRAY_OK, o, on), 0, "ImageData",
               ST_EINPUT, 6, "block size 0",
               "a zero block size is refused");
        put_u64(o + 8, 32);
        put_u64(o + 16, 33);
        expect(vti_doc(zf, EXT_OK, EXT_OK, ARRAY_OK, o, on), 0, "ImageData",
               ST_EINPUT, 6, "last block size 33",
               "a last block larger than a block is refused");
    }
    /* inline base64 */
    {
        /* 8-byte count 96 then 40 bytes: "YAAAAAAAAAA" + ... */
        expect(vti_doc(VTKFILE_OK, EXT_OK, EXT_OK,
                       "<DataArray type=\"Float32\" Name=\"sdf\" "
                       "format=\"binary\">\n  YAAAAAAAAAAAAEDAAAAgwAAAAMAAAMC/"
                       "AACAvwAAAL8AAAAAAAAAPwAAgD8AAMA/\n</DataArray>",
                       NULL, 0),
               0, "ImageData", ST_EINPUT, 6, "claims 96 bytes but 40 remain",
               "truncated inline base64 is refused");
        expect(vti_doc(VTKFILE_OK, EXT_OK, EXT_OK,
                       "<DataArray type=\"Float32\" Name=\"sdf\" "
                       "format=\"binary\">YAAA AAAA</DataArray>",
                       NULL, 0),
               0, "ImageData", ST_EINPUT, 6, "not base64",
               "a blank inside inline base64 is refused");
    }
    /* ascii */
    expect(vti_doc(VTKFILE_OK, EXT_OK, EXT_OK,
                   "<DataArray type=\"Float32\" Name=\"sdf\" "
                   "format=\"ascii\"></DataArray>",
                   NULL, 0),
           0, "ImageData", ST_EINPUT, 6, "no text",
           "an ascii array without text is refused");
    expect(vti_doc(VTKFILE_OK, EXT_OK, EXT_OK,
                   "<DataArray type=\"Float32\" Name=\"sdf\" "
                   "format=\"ascii\">1 2 3</DataArray>",
                   NULL, 0),
           0, "ImageData", ST_EINPUT, 6, "declares 24 values",
           "an ascii array too short for its values is refused");
    /* XML */
    expect(vti_doc(VTKFILE_OK, EXT_OK, EXT_OK,
                   "<DataArray type=\"Float32\" Name=\"a&foo;\" "
                   "format=\"appended\" offset=\"0\"/>",
                   p, pn),
           0, "ImageData", ST_EINPUT, 6, "entity",
           "an undefined entity is refused");
    expect(vti_doc(VTKFILE_OK, EXT_OK, EXT_OK,
                   "<DataArray type=\"Float32\" Name=\"a&amp;b\" "
                   "format=\"appended\" offset=\"0\"/>",
                   p, pn),
           0, "ImageData", ST_OK, 0, NULL,
           "a predefined entity in a name passes");
    expect(vti_doc(VTKFILE_OK, EXT_OK, EXT_OK,
                   "<DataArray type=\"Float32\" type=\"Float64\" "
                   "Name=\"sdf\" format=\"appended\" offset=\"0\"/>",
                   p, pn),
           0, "ImageData", ST_EINPUT, 6, "twice",
           "a repeated attribute is refused");
    expect(vti_doc(VTKFILE_OK, EXT_OK, EXT_OK,
                   "<DataArray type=\"Float32\" Name=\"a>b\" "
                   "format=\"ascii\">0 1 2 3 4 5 6 7 8 9 0 1 2 3 4 5 6 7 8 "
                   "9 0 1 2 3</DataArray>",
                   p, pn),
           0, "ImageData", ST_EINPUT, 6, "'>'",
           "'>' in an attribute of an inline array is refused");
    expect(vti_doc(VTKFILE_OK, EXT_OK, EXT_OK,
                   "<DataArray type=\"Float32\" Name=\"a>b\" "
                   "format=\"appended\" offset=\"0\"/>",
                   p, pn),
           0, "ImageData", ST_OK, 0, NULL,
           "'>' in an attribute of an appended array passes (VTK reads "
           "it)");
    expect(vti_doc(VTKFILE_OK, EXT_OK, EXT_OK,
                   "<!-- <AppendedData --> " ARRAY_OK, p, pn),
           0, "ImageData", ST_EINPUT, 6, "AppendedData",
           "a comment holding <AppendedData is refused");
    expect(vti_doc(VTKFILE_OK, EXT_OK, EXT_OK, "<!-- a note --> " ARRAY_OK,
                   p, pn),
           0, "ImageData", ST_OK, 0, NULL, "a plain comment passes");
    expect(vti_doc(VTKFILE_OK, EXT_OK, EXT_OK,
                   ARRAY_OK "<DataArray type=\"Float64\" Name=\"sdf\" "
                   "format=\"appended\" offset=\"0\"/>",
                   p, pn),
           0, "ImageData", ST_EINPUT, 6, "a second array of this name",
           "two arrays of one name in <PointData> are refused");
    expect(vti_doc(VTKFILE_OK, EXT_OK, EXT_OK,
                   ARRAY_OK "<DataArray type=\"Float32\" Name=\"sdg\" "
                   "format=\"appended\" offset=\"0\"/>",
                   p, pn),
           0, "ImageData", ST_OK, 0, NULL,
           "two arrays of different names pass");
    expect(vti_doc(VTKFILE_OK, EXT_OK, EXT_OK, "<Unknown/>", p, pn), 0,
           "ImageData", ST_EINPUT, 6, "unexpected element <Unknown>",
           "an unknown element is refused");
    expect(vti_doc(VTKFILE_OK, EXT_OK, EXT_OK, "<DataArray type=\"Float32\"",
                   p, pn),
           0, "ImageData", ST_EINPUT, 0, NULL, "an unclosed tag is refused");
    {
        const char *t = "<!DOCTYPE x [<!ENTITY a \"b\">]>\n<VTKFile/>";
        doc x = {(unsigned char *)strdup(t), strlen(t)};
        expect(x, 0, "ImageData", ST_EINPUT, 1, "DOCTYPE",
               "a DOCTYPE is refused");
        t = "<VTKFile type=\"ImageData\" version=\"1.0\"><ImageData "
            "WholeExtent=\"0 0 0 0 0 0\"></ImageData>";
        x = (doc){(unsigned char *)strdup(t), strlen(t)};
        expect(x, 0, "ImageData", ST_EINPUT, 1, "ends inside <VTKFile>",
               "a file ending inside VTKFile is refused");
        t = "<VTKFile type=\"ImageData\" version=\"1.0\"><ImageData "
            "WholeExtent=\"0 0 0 0 0 0\"></ImageData></VTKFile>junk";
        x = (doc){(unsigned char *)strdup(t), strlen(t)};
        expect(x, 0, "ImageData", ST_EINPUT, 1, "outside the root",
               "text after the root element is refused");
    }
    /* UnstructuredGrid */
    {
        doc x = ug_doc("4", "3");
        st_tetmesh *m = NULL;
        s = st_tetmesh_read_mem(&m, x.d, x.n, "m.vtu", 0, &e);
        TAP_CHECK(s == ST_OK && m && m->npoints == 4 && m->ntets == 1,
                  "the hand-made ascii .vtu reads back");
        st_tetmesh_free(m);
        expect(x, 0, "UnstructuredGrid", ST_OK, 0, NULL,
               "hand-made .vtu passes");
        x = ug_doc("-3", "3");
        expect(x, 0, "UnstructuredGrid", ST_EINPUT, 3, "NumberOfPoints",
               "a negative NumberOfPoints is refused");
        x = ug_doc("4", "2");
        expect(x, 0, "UnstructuredGrid", ST_EINPUT, 4, "not 3",
               "points of two components are refused");
        x = ug_doc("400", "3");
        expect(x, 0, "UnstructuredGrid", ST_EINPUT, 4, "declares 1200",
               "more points than the ascii text holds are refused");
        x = ug_doc("4", "3");
        expect(x, 0, "ImageData", ST_EINPUT, 1, "not ImageData",
               "a .vtu checked as ImageData is refused");
        /* VTK sizes the connectivity by the last offset */
        x = ug_doc3("4", "3", "2147483648");
        expect(x, 0, "UnstructuredGrid", ST_EINPUT, 7,
               "offsets end at 2147483648, but the connectivity holds at "
               "most 4",
               "ascii offsets ending beyond the connectivity are refused");
        x = ug_doc3("4", "3", "5");
        expect(x, 0, "UnstructuredGrid", ST_EINPUT, 7, "at most 4",
               "an ascii last offset one past the connectivity is refused");
        x = ug_doc3("4", "3", "4 999");
        expect(x, 0, "UnstructuredGrid", ST_OK, 0, NULL,
               "offsets past the cell count are not what VTK reads");
    }
}

/* A document that passes the check but whose zlib block is not zlib: VTK
 * fails, and its own message still reaches the st_error (each adapter
 * collects VTK's output window for its own calls). */
#define ZLIB_JUNK_ARRAY                                                    \
    "format=\"binary\">AQAAAGAAAAAAAAAABAAAAA==AAAAAA==</DataArray>"
static void test_vtk_messages(void)
{
    const char *vti =
        "<VTKFile type=\"ImageData\" version=\"1.0\" "
        "compressor=\"vtkZLibDataCompressor\">\n"
        "<ImageData WholeExtent=\"0 1 0 0 0 0\" Origin=\"0 0 0\" "
        "Spacing=\"1 1 1\"><Piece Extent=\"0 1 0 0 0 0\"><PointData>"
        "<DataArray type=\"Float32\" Name=\"f\" " ZLIB_JUNK_ARRAY
        "</PointData></Piece></ImageData></VTKFile>\n";
    const char *vtu =
        "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" "
        "compressor=\"vtkZLibDataCompressor\">\n"
        "<UnstructuredGrid><Piece NumberOfPoints=\"4\" NumberOfCells=\"1\">"
        "<Points><DataArray type=\"Float64\" NumberOfComponents=\"3\" "
        ZLIB_JUNK_ARRAY "</Points><Cells>"
        "<DataArray type=\"Int32\" Name=\"connectivity\" format=\"ascii\">"
        "0 1 2 3</DataArray><DataArray type=\"Int32\" Name=\"offsets\" "
        "format=\"ascii\">4</DataArray><DataArray type=\"UInt8\" "
        "Name=\"types\" format=\"ascii\">10</DataArray></Cells></Piece>"
        "</UnstructuredGrid></VTKFile>\n";
    st_error e;
    TAP_CHECK(vcheck((const unsigned char *)vti, strlen(vti), "z",
                              "ImageData", 0, &e) == ST_OK &&
                  vcheck((const unsigned char *)vtu, strlen(vtu),
                                  "z", "UnstructuredGrid", 0, &e) == ST_OK,
              "documents with junk zlib blocks pass the check");
    st_grid *g = NULL;
    st_status s = st_gridio_read_vti_mem(&g, (const unsigned char *)vti,
                                         strlen(vti), "z.vti", 0, &e);
    TAP_CHECK(s == ST_EINPUT && !g && strstr(e.msg, "Zlib error"),
              "the field adapter reports VTK's message (%s)", e.msg);
    st_tetmesh *m = NULL;
    s = st_tetmesh_read_mem(&m, (const unsigned char *)vtu, strlen(vtu),
                            "z.vtu", 0, &e);
    TAP_CHECK(s == ST_EINPUT && !m && strstr(e.msg, "Zlib error"),
              "the mesh adapter reports VTK's message (%s)", e.msg);
    s = st_gridio_read_vti_mem(&g, (const unsigned char *)vti, strlen(vti),
                               "z.vti", 0, &e);
    TAP_CHECK(s == ST_EINPUT && !g && strstr(e.msg, "Zlib error"),
              "and the field adapter after the mesh adapter (%s)", e.msg);
}

/* ---- (c) what the writers make ------------------------------------------ */

static void test_foreign_writers(void)
{
    char dir[4200];
    snprintf(dir, sizeof dir, "%s/vtk", g_data);
    size_t n;
    char **vti = list_dir(dir, ".vti", &n);
    TAP_CHECK(n >= 20, "%zu foreign .vti files", n);
    for (size_t i = 0; i < n; i++) {
        const char *base = strrchr(vti[i], '/') + 1;
        st_grid *g = NULL;
        st_error e;
        st_status s = st_grid_read_vti(&g, vti[i], 0, &e);
        int ok = s == ST_OK && g && g->nx == 4 && g->ny == 3 && g->nz == 2 &&
                 g->voxel == 0.25 && g->origin[0] == 0.5;
        for (size_t k = 0; ok && k < 24; k++)
            ok = g->data[k] == 0.5f * (float)k - 3.0f;
        const char *note = ok ? st_meta_get(&g->meta, "note") : NULL;
        ok = ok && note && strcmp(note, "hello") == 0;
        TAP_CHECK(ok, "%s: passes and reads back", base);
        if (s) {
            char buf[1200];
            TAP_NOTE("  %s", st_error_format(&e, buf, sizeof buf));
        }
        st_grid_free(g);
    }
    free_list(vti, n);
    char **vtu = list_dir(dir, ".vtu", &n);
    TAP_CHECK(n >= 24, "%zu foreign .vtu files", n);
    for (size_t i = 0; i < n; i++) {
        const char *base = strrchr(vtu[i], '/') + 1;
        st_tetmesh *m = NULL;
        st_error e;
        st_status s = st_tetmesh_read(&m, vtu[i], 0, &e);
        int ok = s == ST_OK && m && m->npoints == 5 && m->ntets == 2 &&
                 m->tets[4] == 1 && m->tets[7] == 4 && m->xyz[12] == 1.0;
        TAP_CHECK(ok, "%s: passes and reads back", base);
        if (s) {
            char buf[1200];
            TAP_NOTE("  %s", st_error_format(&e, buf, sizeof buf));
        }
        st_tetmesh_free(m);
    }
    free_list(vtu, n);
}

static void test_own_writers(void)
{
    /* a field: .vti through souptet's writer, by path and in memory */
    const double org[3] = {-1, 0, 2};
    st_grid *g = NULL;
    st_error e;
    st_grid_new(&g, 9, 7, 5, org, 0.125, 0.0f, 0, &e);
    for (size_t i = 0; i < st_grid_count(g); i++)
        g->data[i] = (float)i * 0.25f - 7.0f;
    g->kind = ST_GRID_SIGNED;
    g->band = 1.5;
    st_meta_set(&g->meta, "source", "a&b <c> \"d\"");
    st_meta_set(&g->meta, "history", "line one\nline two");
    char p[256];
    snprintf(p, sizeof p, "%s/own.vti", g_tmp);
    st_status s = st_grid_write_vti(g, p, &e);
    size_t n = 0;
    unsigned char *d = s == ST_OK ? load(p, &n) : NULL;
    st_status c = d ? vcheck(d, n, p, "ImageData", 0, &e) : ST_EIO;
    TAP_CHECK(c == ST_OK, "souptet's .vti passes the check");
    c = d ? vcheck(d, n, p, "ImageData", 9 * 7 * 5 * 4, &e) : ST_EIO;
    TAP_CHECK(c == ST_OK, "souptet's .vti passes at max_bytes = its grid");
    st_grid *h = NULL;
    s = st_grid_read_vti(&h, p, 9 * 7 * 5 * 4, &e);
    TAP_CHECK(s == ST_OK && h && h->nx == 9 && h->nz == 5 &&
                  memcmp(h->data, g->data, st_grid_count(g) * 4) == 0 &&
                  h->kind == ST_GRID_SIGNED,
              "souptet's .vti reads back at max_bytes = its grid");
    st_grid_free(h);
    h = NULL;
    s = d ? st_gridio_read_vti_mem(&h, d, n, "own", 0, &e) : ST_EIO;
    TAP_CHECK(s == ST_OK && h && h->ny == 7,
              "souptet's .vti reads back from memory");
    st_grid_free(h);
    /* cut inside the appended data: refused before VTK */
    if (d) {
        st_error e2;
        c = vcheck(d, n - 40, "cut.vti", "ImageData", 0, &e2);
        TAP_CHECK(c == ST_EINPUT && strcmp(e2.file, "cut.vti") == 0,
                  "souptet's .vti cut short is refused by the check");
    }
    free(d);
    st_grid_free(g);

    /* a mesh: .vtu through souptet's writer */
    st_tetmesh *m = st_tetmesh_new();
    const double q[5][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1},
                            {1, 1, 1}};
    for (int i = 0; i < 5; i++)
        st_tetmesh_add_point(m, q[i], NULL);
    st_tetmesh_add_tet(m, 0, 1, 2, 3, NULL);
    st_tetmesh_add_tet(m, 1, 3, 2, 4, NULL);
    double *v;
    st_tetmesh_add_array(m, "temp", ST_ON_POINTS, 2, &v, NULL);
    for (int i = 0; i < 10; i++)
        v[i] = i;
    st_meta_set(&m->meta, "source", "x&y");
    unsigned char *md = NULL;
    size_t mn = 0;
    s = st_tetmesh_write_mem(&md, &mn, m, &e);
    c = s == ST_OK ? vcheck(md, mn, "own.vtu", "UnstructuredGrid",
                                     0, &e)
                   : s;
    TAP_CHECK(c == ST_OK, "souptet's .vtu passes the check");
    st_tetmesh *r = NULL;
    s = md ? st_tetmesh_read_mem(&r, md, mn, "own.vtu", 0, &e) : ST_EIO;
    TAP_CHECK(s == ST_OK && r && r->npoints == 5 && r->ntets == 2,
              "souptet's .vtu reads back");
    st_tetmesh_free(r);
    snprintf(p, sizeof p, "%s/own.vtu", g_tmp);
    s = st_tetmesh_write(m, p, NULL, &e);
    r = NULL;
    s = s == ST_OK ? st_tetmesh_read(&r, p, 0, &e) : s;
    TAP_CHECK(s == ST_OK && r && r->ntets == 2,
              "souptet's .vtu file reads back by path");
    st_tetmesh_free(r);
    free(md);
    st_tetmesh_free(m);
}

int main(int argc, char **argv)
{
    static const tap_test tests[] = {TAP_TEST(findings), TAP_TEST(near_misses),
                                     TAP_TEST(foreign_writers), TAP_TEST(own_writers),
                                     TAP_TEST(vtk_messages), {0}};
    tap_select(argc, argv, tests);
    find_data(argv[0]);
    if (!mkdtemp(g_tmp)) {
        perror("mkdtemp");
        return 1;
    }
    tap_run(tests);
    char p[256];
    const char *own[] = {"own.vti", "own.vtu"};
    for (int i = 0; i < 2; i++) {
        snprintf(p, sizeof p, "%s/%s", g_tmp, own[i]);
        unlink(p);
    }
    rmdir(g_tmp);
    return tap_done();
}
