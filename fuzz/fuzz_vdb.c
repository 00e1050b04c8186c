/* fuzz_vdb.c - libFuzzer harness for the .vdb reader (see fuzz_grid.h). */
#define FUZZ_READ st_gridio_read_vdb_mem
#include "fuzz_grid.h"
