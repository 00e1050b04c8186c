/* fuzz_vti.c - libFuzzer harness for the .vti reader (see fuzz_grid.h). */
#define FUZZ_READ st_gridio_read_vti_mem
#define FUZZ_ASAN_MAY_RETURN_NULL 1
#include "fuzz_grid.h"
