/* fuzz_obj.c - libFuzzer harness for the OBJ reader (see fuzz_soup.h). */
#define FUZZ_FORMAT ST_SOUP_OBJ
#include "fuzz_soup.h"
