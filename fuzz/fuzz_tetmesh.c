/* fuzz_tetmesh.c - libFuzzer harness for st_tetmesh_read_mem, the path
 * every tet tool takes on standard input (tetstat, tetsmooth, a
 * latticetet or soupmesh output read back): the format is sniffed from
 * the first bytes ($MeshFormat: .msh, MeshVersionFormatted: .mesh, '<':
 * .vtu) and the matching reader runs (see fuzz_tet.h). VTK is behind the
 * '<' branch, hence allocator_may_return_null=1 as in fuzz_vtu.c.
 */
#include "souptet/tetio.h"

const char *__asan_default_options(void);
const char *__asan_default_options(void)
{
    return "allocator_may_return_null=1";
}

#define FUZZ_PARSE(out, data, size, max, err) \
    st_tetmesh_read_mem(out, data, size, "<stdin>", max, err)
#include "fuzz_tet.h"
