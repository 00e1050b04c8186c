/* meta.c - key/value metadata and command-line history (see meta.h). */
#include "souptet/meta.h"
#include "souptet/mem.h"

#include <stdlib.h>
#include <string.h>

void st_meta_clear(st_meta *m)
{
    if (!m)
        return;
    for (size_t i = 0; i < m->count; i++) {
        free(m->entries[i].key);
        free(m->entries[i].value);
    }
    free(m->entries);
    m->entries = NULL;
    m->count = m->capacity = 0;
}

static st_meta_entry *find(const st_meta *m, const char *key)
{
    for (size_t i = 0; i < m->count; i++)
        if (strcmp(m->entries[i].key, key) == 0)
            return &m->entries[i];
    return NULL;
}

st_status st_meta_set(st_meta *m, const char *key, const char *value)
{
    char *v = st_strdup(value ? value : "");
    if (!v)
        return ST_ENOMEM;
    st_meta_entry *e = find(m, key);
    if (e) {
        free(e->value);
        e->value = v;
        return ST_OK;
    }
    if (m->count == m->capacity) {
        size_t cap = m->capacity ? 2 * m->capacity : 8;
        st_meta_entry *n = st_realloc_array(m->entries, cap, sizeof *n);
        if (!n) {
            free(v);
            return ST_ENOMEM;
        }
        m->entries = n;
        m->capacity = cap;
    }
    char *k = st_strdup(key);
    if (!k) {
        free(v);
        return ST_ENOMEM;
    }
    m->entries[m->count].key = k;
    m->entries[m->count].value = v;
    m->count++;
    return ST_OK;
}

const char *st_meta_get(const st_meta *m, const char *key)
{
    const st_meta_entry *e = find(m, key);
    return e ? e->value : NULL;
}

st_status st_meta_history_append(st_meta *m, const char *line)
{
    const char *old = st_meta_get(m, "history");
    if (!old || !old[0])
        return st_meta_set(m, "history", line);
    size_t a = strlen(old), b = strlen(line);
    char *joined = malloc(a + b + 2);
    if (!joined)
        return ST_ENOMEM;
    memcpy(joined, old, a);
    joined[a] = '\n';
    memcpy(joined + a + 1, line, b + 1);
    st_status s = st_meta_set(m, "history", joined);
    free(joined);
    return s;
}

st_status st_meta_copy(st_meta *dst, const st_meta *src)
{
    st_meta tmp = {0};
    for (size_t i = 0; i < src->count; i++) {
        if (st_meta_set(&tmp, src->entries[i].key, src->entries[i].value)) {
            st_meta_clear(&tmp);
            return ST_ENOMEM;
        }
    }
    st_meta_clear(dst);
    *dst = tmp;
    return ST_OK;
}

st_status st_meta_inherit(st_meta *m, const st_meta *from)
{
    st_meta tmp = {0};
    if (st_meta_copy(&tmp, from))
        return ST_ENOMEM;
    for (size_t i = 0; i < m->count; i++)
        if (st_meta_set(&tmp, m->entries[i].key, m->entries[i].value)) {
            st_meta_clear(&tmp);
            return ST_ENOMEM;
        }
    st_meta_clear(m);
    *m = tmp;
    return ST_OK;
}

/* Characters that make an argument need quoting in a POSIX shell. */
static int needs_quotes(const char *s)
{
    if (!*s)
        return 1;
    for (; *s; s++)
        if (!strchr("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ"
                     "0123456789-_./=:,+@%", *s))
            return 1;
    return 0;
}

char *st_command_line(int argc, char *const argv[])
{
    size_t n = 1;
    for (int i = 0; i < argc; i++)
        n += 4 * strlen(argv[i]) + 3;   /* worst case: every char is ' */
    char *out = malloc(n), *p = out;
    if (!out)
        return NULL;
    for (int i = 0; i < argc; i++) {
        if (i)
            *p++ = ' ';
        const char *a = argv[i];
        if (!needs_quotes(a)) {
            size_t l = strlen(a);
            memcpy(p, a, l);
            p += l;
            continue;
        }
        *p++ = '\'';
        for (; *a; a++) {
            if (*a == '\'') {
                memcpy(p, "'\\''", 4);
                p += 4;
            } else if (*a == '\n') {
                *p++ = ' ';     /* history is line-based */
            } else {
                *p++ = *a;
            }
        }
        *p++ = '\'';
    }
    *p = '\0';
    return out;
}
