/* fuzz_msh.c - libFuzzer harness for the Gmsh .msh reader (4.1 and 2.2,
 * ASCII and binary; see fuzz_tet.h). */
#include "souptet/tetformat.h"
#define FUZZ_PARSE(out, data, size, max, err) \
    st_tetmesh_parse_msh(out, data, size, "fuzz.msh", max, err)
#include "fuzz_tet.h"
