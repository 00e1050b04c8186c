/* fuzz_stl.c - libFuzzer harness for the STL reader (see fuzz_soup.h). */
#define FUZZ_FORMAT ST_SOUP_STL
#include "fuzz_soup.h"
