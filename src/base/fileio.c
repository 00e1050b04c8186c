/*
 * fileio.c - path extensions, whole-file reads, first bytes, the XML
 * sniff and the input-file check (see fileio.h).
 */
#include "fileio.h"
#include "souptet/mem.h"
#include "souptet/outfile.h"

#include <errno.h>
#include <fcntl.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static int ascii_lower(int c)
{
    return (c >= 'A' && c <= 'Z') ? c - 'A' + 'a' : c;
}

/* The extension of path[0, len): the bytes after the last dot of the last
 * component (*ext, *elen), or 0 when there is none. */
static int ext_of(const char *path, size_t len, const char **ext,
                  size_t *elen)
{
    size_t base = 0, dot = len;
    for (size_t i = 0; i < len; i++) {
        if (path[i] == '/') {
            base = i + 1;
            dot = len;
        } else if (path[i] == '.') {
            dot = i;
        }
    }
    if (dot == len || dot == base)   /* none, or a hidden file's only dot */
        return 0;
    *ext = path + dot + 1;
    *elen = len - dot - 1;
    return 1;
}

static int match(const char *path, size_t len, const char *const *exts,
                 size_t n)
{
    const char *e;
    size_t el;
    if (!ext_of(path, len, &e, &el))
        return -1;
    for (size_t k = 0; k < n; k++) {
        size_t i = 0;
        while (i < el && exts[k][i] &&
               ascii_lower((unsigned char)e[i]) ==
                   ascii_lower((unsigned char)exts[k][i]))
            i++;
        if (i == el && exts[k][i] == '\0')
            return (int)k;
    }
    return -1;
}

int st_path_ext_match(const char *path, const char *const *exts, size_t n,
                      int outfile_tmp)
{
    if (!path)
        return -1;
    size_t len = strlen(path);
    int k = match(path, len, exts, n);
    /* st_outfile's temporary name (outfile.h): its target's extension. */
    if (k < 0 && outfile_tmp) {
        char *target = st_outfile_target_of(path);
        if (target)
            k = match(target, strlen(target), exts, n);
        free(target);
    }
    return k;
}

/* All of fd into a growing buffer from a first capacity of hint. */
static st_status read_fd(int fd, size_t hint, unsigned char **data,
                         size_t *size, const char *name, st_error *err)
{
    size_t cap = hint ? hint : 65536, n = 0;
    /* A large file is read in huge pages (st_malloc_big): its 4 KiB page
     * faults cost more than the read itself at hundreds of MB. */
    unsigned char *buf = st_malloc_big(cap);
    if (!buf)
        return st_error_set(err, ST_ENOMEM, name, 0, "out of memory");
    for (;;) {
        if (n == cap) {
            size_t ncap;
            unsigned char *nb = NULL;
            if (st_size_mul(&ncap, cap, 2) == 0)
                nb = st_realloc_big(buf, ncap);
            if (!nb) {
                free(buf);
                return st_error_set(err, ST_ENOMEM, name, 0,
                                    "out of memory after %zu bytes", n);
            }
            buf = nb;
            cap = ncap;
        }
        ssize_t r = read(fd, buf + n, cap - n);
        if (r < 0) {
            if (errno == EINTR)
                continue;
            int e = errno;
            free(buf);
            return st_error_set(err, ST_EIO, name, 0, "cannot read: %s",
                                strerror(e));
        }
        if (r == 0)
            break;
        n += (size_t)r;
    }
    *data = buf;
    *size = n;
    return ST_OK;
}

static int is_stdin(const char *path)
{
    return path == NULL || strcmp(path, "-") == 0;
}

static int open_in(const char *path, st_error *err)
{
    int fd;
    do
        fd = open(path, O_RDONLY | O_CLOEXEC);
    while (fd < 0 && errno == EINTR);
    if (fd < 0)
        st_error_set(err, ST_EIO, path, 0, "cannot open: %s",
                     strerror(errno));
    return fd;
}

st_status st_file_read(const char *path, unsigned char **data, size_t *size,
                       st_error *err)
{
    *data = NULL;
    *size = 0;
    if (is_stdin(path))
        return read_fd(STDIN_FILENO, 0, data, size, ST_STDIN_NAME, err);
    int fd = open_in(path, err);
    if (fd < 0)
        return err ? err->status : ST_EIO;
    struct stat sb;
    size_t hint = 0;
    if (fstat(fd, &sb) == 0) {
        if (S_ISDIR(sb.st_mode)) {
            close(fd);
            return st_error_set(err, ST_EIO, path, 0, "is a directory");
        }
        /* +1 so a regular file is read to its end without a regrowth. */
        if (S_ISREG(sb.st_mode) && sb.st_size > 0 &&
            (unsigned long long)sb.st_size < SIZE_MAX / 2)
            hint = (size_t)sb.st_size + 1;
    }
    st_status s = read_fd(fd, hint, data, size, path, err);
    close(fd);
    return s;
}

st_status st_file_head(const char *path, unsigned char *buf, size_t cap,
                       size_t *n, st_error *err)
{
    *n = 0;
    int fd = open_in(path, err);
    if (fd < 0)
        return err ? err->status : ST_EIO;
    while (*n < cap) {
        ssize_t r = read(fd, buf + *n, cap - *n);
        if (r < 0 && errno == EINTR)
            continue;
        if (r < 0) {
            int e = errno;
            close(fd);
            return st_error_set(err, ST_EIO, path, 0, "cannot read: %s",
                                strerror(e));
        }
        if (r == 0)
            break;
        *n += (size_t)r;
    }
    close(fd);
    if (*n == 0)
        return st_error_set(err, ST_EINPUT, path, 0, "empty file");
    return ST_OK;
}

int st_looks_like_xml(const unsigned char *p, size_t n)
{
    size_t i = 0;
    if (n >= 3 && p[0] == 0xEF && p[1] == 0xBB && p[2] == 0xBF)
        i = 3;
    while (i < n && (p[i] == ' ' || p[i] == '\t' || p[i] == '\r' ||
                     p[i] == '\n'))
        i++;
    return i < n && p[i] == '<';
}

st_status st_file_check_input(const char *path, st_error *err)
{
    struct stat st;
    if (stat(path, &st) != 0)
        return st_error_set(err, ST_EIO, path, 0, "cannot open: %s",
                            strerror(errno));
    if (S_ISDIR(st.st_mode))
        return st_error_set(err, ST_EIO, path, 0, "is a directory");
    if (S_ISREG(st.st_mode) && st.st_size == 0)
        return st_error_set(err, ST_EINPUT, path, 0, "empty file");
    int fd = open_in(path, err);
    if (fd < 0)
        return err ? err->status : ST_EIO;
    close(fd);
    return ST_OK;
}
