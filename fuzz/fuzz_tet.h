/*
 * fuzz_tet.h - one libFuzzer entry point for a tet-mesh reader; each
 * fuzz_<reader>.c defines FUZZ_PARSE(out, data, size, max_bytes, err) (an
 * expression returning st_status) and includes this.
 *
 * The reader must return ST_OK with a mesh whose every tet index is below
 * npoints, every coordinate finite, counts
 * within capacity and every named array and meta entry complete; or an
 * error with a message and no mesh. Any crash, leak, hang or sanitizer
 * report is a finding. FUZZ_MAX_BYTES (64 MiB of mesh memory) keeps a
 * hostile count from asking for gigabytes: the readers must refuse it with
 * ST_ELIMIT or ST_EINPUT, not allocate it.
 *
 * tests/test_fuzzregress.c includes this too (with FUZZ_NO_ENTRY) and runs
 * every file of tests/data/fuzz/<reader>/ through fuzz_tet_verdict.
 */
#include "souptet/tetformat.h"
#include "souptet/tetmesh.h"

#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#ifndef FUZZ_MAX_BYTES
#define FUZZ_MAX_BYTES ((size_t)64 << 20)
#endif

/* The TetGen reader takes two files; its fuzz input is both, split at the
 * first form feed byte (0x0C, "\f"): the bytes before it are the .node,
 * the bytes after it the .ele (an input without one is a .node and an
 * empty .ele). Neither format uses a form feed, and tests/test_tetformat.c
 * writes its malformed pairs the same way. */
static inline st_status fuzz_tet_parse_tetgen(st_tetmesh **out,
                                              const unsigned char *data,
                                              size_t size, size_t max_bytes,
                                              st_error *err)
{
    const unsigned char *ff = size ? memchr(data, '\f', size) : NULL;
    size_t nn = ff ? (size_t)(ff - data) : size;
    const unsigned char *ele = ff ? ff + 1 : data + size;
    return st_tetmesh_parse_tetgen(out, data, nn, "fuzz.node", ele,
                                   size - nn - (ff ? 1 : 0), "fuzz.ele",
                                   max_bytes, err);
}

/* NULL when m is a sane result of a successful read, else a reason. */
static const char *fuzz_tet_insane(const st_tetmesh *m)
{
    if (!m)
        return "ST_OK without a mesh";
    /* An empty mesh is a mesh (VTK writes one, souptet's .vtu round-trips
     * it, tetstat reports it); the text formats refuse "no tetrahedra"
     * because their files cannot say so on purpose. */
    if ((m->npoints && !m->xyz) || (m->ntets && !m->tets))
        return "ST_OK with NULL storage";
    if (m->npoints > m->cap_points || m->ntets > m->cap_tets)
        return "count above capacity";
    if ((size_t)24 * m->npoints + (size_t)16 * m->ntets > FUZZ_MAX_BYTES)
        return "mesh larger than max_bytes";
    for (size_t i = 0; i < 4 * m->ntets; i++)
        if (m->tets[i] >= m->npoints)
            return "tet index out of range";
    for (size_t i = 0; i < 3 * m->npoints; i++)
        if (!isfinite(m->xyz[i]))
            return "non-finite coordinate";
    for (size_t a = 0; a < m->narrays; a++) {
        const st_tet_array *ar = &m->arrays[a];
        if (!ar->name || ar->ncomp < 1 || ar->ncomp > 9)
            return "array without a name or with bad components";
        size_t n = (size_t)ar->ncomp *
                   (ar->assoc == ST_ON_POINTS ? m->npoints : m->ntets);
        if (n && !ar->values)
            return "array without values";
        volatile double sum = 0.0;
        for (size_t i = 0; i < n; i++)
            sum += ar->values[i];      /* every value readable */
        (void)sum;
    }
    for (size_t e = 0; e < m->meta.count; e++) {
        const st_meta_entry *me = &m->meta.entries[e];
        if (!me->key || !me->value)
            return "meta entry without key or value";
        volatile size_t n = strlen(me->key) + strlen(me->value);
        (void)n;
    }
    return NULL;
}

/* The verdict on one read: NULL when (ST_OK and sane) or (an error with a
 * message and no mesh); else why not. Frees the mesh. */
static const char *fuzz_tet_verdict(st_status s, st_tetmesh *m,
                                    const st_error *err)
{
    const char *why = NULL;
    if (s == ST_OK)
        why = fuzz_tet_insane(m);
    else if (m != NULL)
        why = "an error with a mesh";
    else if (err->msg[0] == '\0')
        why = "an error without a message";
    st_tetmesh_free(m);
    return why;
}

#ifndef FUZZ_NO_ENTRY
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    st_tetmesh *m = NULL;
    st_error err;
    memset(&err, 0, sizeof err);
    st_status s = FUZZ_PARSE(&m, data, size, FUZZ_MAX_BYTES, &err);
    if (fuzz_tet_verdict(s, m, &err))
        abort();
    return 0;
}
#endif
