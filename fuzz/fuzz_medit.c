/* fuzz_medit.c - libFuzzer harness for the Medit .mesh reader (see
 * fuzz_tet.h). */
#include "souptet/tetformat.h"
#define FUZZ_PARSE(out, data, size, max, err) \
    st_tetmesh_parse_medit(out, data, size, "fuzz.mesh", max, err)
#include "fuzz_tet.h"
