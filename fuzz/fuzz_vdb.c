/* fuzz_vdb.c - libFuzzer harness for the .vdb reader (see fuzz_grid.h). */
#define FUZZ_READ st_gridio_read_vdb_mem
#define FUZZ_ASAN_MAY_RETURN_NULL 1
#include "fuzz_grid.h"
