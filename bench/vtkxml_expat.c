/*
 * bench/vtkxml_expat.c - the measurement behind vtkxml.c's choice of its
 * own XML lexer over expat (issue 39): for each VTK XML file, the best
 * time of st_vtkxml_check (the whole pre-flight) and of expat alone over
 * what VTK's parser reads (the head up to the '_' of raw appended data,
 * then the closing tags; the whole file without appended data), and each
 * one's verdict. An expat-based pre-flight would run expat and then still
 * every check of the structure, the sizes and the data that
 * st_vtkxml_check makes, so expat's time alone is a lower bound of it.
 *
 *   make build/bench/vtkxml_expat          (needs libexpat1-dev)
 *   build/bench/vtkxml_expat REPS FILE...  (.vtu: UnstructuredGrid, else
 *                                           ImageData)
 */
#include "../src/io/vtkxml.h"

#include <expat.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static void XMLCALL on_start(void *u, const XML_Char *n, const XML_Char **a)
{
    (void)u;
    (void)n;
    (void)a;
}

static void XMLCALL on_end(void *u, const XML_Char *n)
{
    (void)u;
    (void)n;
}

static void XMLCALL on_text(void *u, const XML_Char *s, int len)
{
    (void)u;
    (void)s;
    (void)len;
}

static double now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static const unsigned char *find(const unsigned char *d, size_t n,
                                 const char *s)
{
    size_t k = strlen(s);
    for (size_t i = 0; i + k <= n; i++)
        if (memcmp(d + i, s, k) == 0)
            return d + i;
    return NULL;
}

/* expat over what VTK hands its parser; 1 when well-formed. */
static int expat_run(const unsigned char *d, size_t n)
{
    size_t head = n;
    const unsigned char *ap = find(d, n, "<AppendedData");
    if (ap) {
        const unsigned char *u = memchr(ap, '_', n - (size_t)(ap - d));
        if (u)
            head = (size_t)(u - d);
    }
    XML_Parser p = XML_ParserCreate(NULL);
    if (!p)
        return 0;
    XML_SetElementHandler(p, on_start, on_end);
    XML_SetCharacterDataHandler(p, on_text);
    int ok = XML_Parse(p, (const char *)d, (int)head, 0) != XML_STATUS_ERROR;
    if (ok && ap)
        ok = XML_Parse(p, "</AppendedData></VTKFile>", 25, 1) !=
             XML_STATUS_ERROR;
    else if (ok)
        ok = XML_Parse(p, "", 0, 1) != XML_STATUS_ERROR;
    XML_ParserFree(p);
    return ok;
}

static int bench_file(const char *path, int reps)
{
    FILE *f = fopen(path, "rb");
    if (!f || fseek(f, 0, SEEK_END) != 0) {
        perror(path);
        return 1;
    }
    long n = ftell(f);
    unsigned char *d = malloc(n > 0 ? (size_t)n : 1);
    if (!d || fseek(f, 0, SEEK_SET) != 0 ||
        fread(d, 1, (size_t)n, f) != (size_t)n) {
        perror(path);
        fclose(f);
        free(d);
        return 1;
    }
    fclose(f);
    const char *type = strstr(path, ".vtu") ? "UnstructuredGrid" : "ImageData";
    double best[2] = {1e30, 1e30};
    int ok[2] = {0, 0};
    for (int r = 0; r < reps; r++)
        for (int m = 0; m < 2; m++) {
            double t0 = now();
            st_error e;
            ok[m] = m == 0 ? st_vtkxml_check(d, (size_t)n, path, type, 0,
                                             st_vtkxml_inflate_vtk, NULL,
                                             &e) == ST_OK
                           : expat_run(d, (size_t)n);
            double t = now() - t0;
            if (t < best[m])
                best[m] = t;
        }
    printf("%10ld bytes  check %-4s %10.3f ms  expat %-4s %10.3f ms  %s\n", n,
           ok[0] ? "ok" : "FAIL", best[0] * 1e3, ok[1] ? "ok" : "FAIL",
           best[1] * 1e3, path);
    free(d);
    return 0;
}

int main(int argc, char **argv)
{
    if (argc < 3) {
        fprintf(stderr, "usage: vtkxml_expat REPS FILE...\n");
        return 2;
    }
    int reps = atoi(argv[1]), bad = 0;
    for (int i = 2; i < argc; i++)
        bad |= bench_file(argv[i], reps > 0 ? reps : 1);
    return bad;
}
