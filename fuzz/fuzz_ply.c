/* fuzz_ply.c - libFuzzer harness for the PLY reader (see fuzz_soup.h). */
#define FUZZ_FORMAT ST_SOUP_PLY
#include "fuzz_soup.h"
