/* fuzz_tetgen.c - libFuzzer harness for the TetGen .node/.ele reader (see
 * fuzz_tet.h). The input is both files, split at its first form feed
 * ("\f"): .node before, .ele after (fuzz_tet_parse_tetgen); scripts/fuzz
 * seeds "node\fele". */
#define FUZZ_PARSE(out, data, size, max, err) \
    fuzz_tet_parse_tetgen(out, data, size, max, err)
#include "fuzz_tet.h"
