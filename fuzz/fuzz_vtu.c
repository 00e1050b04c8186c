/* fuzz_vtu.c - libFuzzer harness for the .vtu reader (VTK XML
 * UnstructuredGrid through src/adapters/tetio_vtu.cpp; see fuzz_tet.h).
 *
 * allocator_may_return_null=1: VTK sizes its data arrays by what the
 * header claims and allocates them with malloc; glibc returns NULL for an
 * impossible size and VTK reports an error, which the adapter turns into
 * ST_EINPUT. ASan's default is to abort instead; this makes it behave like
 * the production allocator. (It does not cover operator new: ASan still
 * aborts when a throwing new cannot be satisfied, where glibc's would
 * throw std::bad_alloc.)
 */
#include "souptet/tetio.h"
#include "../src/adapters/tetio_internal.h"

const char *__asan_default_options(void);
const char *__asan_default_options(void)
{
    return "allocator_may_return_null=1";
}

#define FUZZ_PARSE(out, data, size, max, err) \
    st_tetio_read_vtu_mem(out, data, size, "fuzz.vtu", max, err)
#include "fuzz_tet.h"
