/* fuzz_off.c - libFuzzer harness for the OFF reader (see fuzz_soup.h). */
#define FUZZ_FORMAT ST_SOUP_OFF
#include "fuzz_soup.h"
