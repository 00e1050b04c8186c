/*
 * fuzz_grid.h - one libFuzzer entry point for a field reader; fuzz_vdb.c
 * and fuzz_vti.c define FUZZ_READ and include this. A size limit keeps a
 * hostile header from asking for gigabytes (the readers must refuse it
 * with ST_ELIMIT, not allocate it).
 *
 * FUZZ_ASAN_MAY_RETURN_NULL: OpenVDB and VTK size buffers by what a header
 * claims (OpenVDB 10's io::bloscFromStream, VTK's data arrays). Under
 * glibc an impossible size fails (NULL from malloc, std::bad_alloc from
 * new) and the adapter turns that into an error; ASan's default is to
 * abort. allocator_may_return_null=1 makes malloc behave like glibc's.
 * ASan's throwing operator new still aborts when it cannot allocate (it
 * reports out-of-memory instead of throwing, whatever the options), so
 * the OpenVDB new[] in bloscFromStream stays a finding under ASan that
 * production handles: tests/test_fuzzregress.c marks those TODO.
 */
#include "souptet/grid.h"
#include "../src/adapters/gridio_internal.h"

#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>

#ifdef FUZZ_ASAN_MAY_RETURN_NULL
const char *__asan_default_options(void);
const char *__asan_default_options(void)
{
    return "allocator_may_return_null=1";
}
#endif

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    st_grid *g = NULL;
    st_error err;
    if (FUZZ_READ(&g, data, size, "fuzz", (size_t)64 << 20, &err) == ST_OK) {
        if (!g || g->nx == 0 || g->ny == 0 || g->nz == 0 || !(g->voxel > 0.0))
            abort();
        size_t n = st_grid_count(g);
        volatile float sum = 0.0f;
        for (size_t i = 0; i < n; i++)
            sum += g->data[i];   /* every value readable */
        (void)sum;
    } else if (g != NULL || err.msg[0] == '\0') {
        abort();
    }
    st_grid_free(g);
    return 0;
}
