/* fuzz_soupsniff.c - libFuzzer harness for a surface on standard input,
 * the path every surface tool takes for '-' (st_soup_read): the format is
 * sniffed from the first bytes (st_soup_format_sniff) and that reader runs;
 * an unknown format must be an error with a message (see fuzz_soup.h). */
#define FUZZ_FORMAT st_soup_format_sniff(data, size)
#include "fuzz_soup.h"
