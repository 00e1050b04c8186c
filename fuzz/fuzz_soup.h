/*
 * fuzz_soup.h - one libFuzzer entry point for a surface reader; each
 * fuzz_<format>.c defines FUZZ_FORMAT and includes this.
 *
 * The reader must return (ST_OK with at least one triangle and every index
 * in range and every coordinate finite, or an error with a message): any
 * crash, leak, hang or sanitizer report is a finding.
 */
#include "souptet/soup.h"

#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    st_soup *s = NULL;
    st_error err;
    if (st_soup_parse(&s, FUZZ_FORMAT, data, size, "fuzz", &err) == ST_OK) {
        if (!s || s->ntris == 0)
            abort();
        for (size_t i = 0; i < 3 * s->ntris; i++)
            if (s->tris[i] >= s->nverts)
                abort();
        for (size_t i = 0; i < 3 * s->nverts; i++)
            if (!isfinite(s->xyz[i]))
                abort();
    } else if (s != NULL || err.msg[0] == '\0') {
        abort();
    }
    st_soup_free(s);
    return 0;
}
