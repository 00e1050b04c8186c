/*
 * mem.h - checked allocation.
 *
 * Units: bytes and element counts.
 * Ownership: the caller frees what these return, with free().
 * Threads: thread-safe (they call the C allocator only).
 * Errors: NULL (or 0 from the size checks) on overflow or when out of
 * memory; no st_error.
 *
 * Every array allocation goes through these: the element count times the
 * element size is checked for overflow before anything is allocated, so a
 * count read from an untrusted file can never wrap into a small buffer.
 */
#ifndef SOUPTET_MEM_H
#define SOUPTET_MEM_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

/* *out = a * b; returns 0, or -1 (and leaves *out alone) on overflow. */
int st_size_mul(size_t *out, size_t a, size_t b);
/* *out = a + b; returns 0, or -1 on overflow. */
int st_size_add(size_t *out, size_t a, size_t b);

/* malloc/calloc/realloc of n elements of size bytes; NULL on overflow or
 * when the system has no memory. n == 0 returns a valid unique pointer.
 * From 1 MiB on, st_malloc_array and st_calloc_array are st_malloc_big
 * and st_calloc_big (whole 2 MiB pages, transparent huge pages; the
 * calloc one zeroes the block at once rather than page by page on first
 * touch): on this project's virtual machines a page fault costs tens of
 * microseconds, and the field-sized arrays of a 7-cell run took 11.6 K of
 * them in 4 KiB pages (b9_mesh), 3.6 K now. st_realloc_array stays plain
 * realloc (glibc copies a moved block into fresh pages before any advice
 * could be given: routed through the big path, a 3.5 M-triangle read
 * took 196 K faults instead of 68 K). */
void *st_malloc_array(size_t n, size_t size);
void *st_calloc_array(size_t n, size_t size);
void *st_realloc_array(void *p, size_t n, size_t size);

/* n zeroed bytes for a large array that is about to be touched in full:
 * aligned to, and advised to use, transparent huge pages, because first
 * touching hundreds of MB in 4 KiB pages costs about a second on this
 * project's (virtual) machines. Zeroed in parallel. Release with free(). */
void *st_calloc_big(size_t n);
/* The same without zeroing. */
void *st_malloc_big(size_t n);
/* realloc for an array that grows by doubling into the hundreds of MB (a
 * reader's vertices): past a few MB the block's whole 2 MiB pages are
 * advised to be transparent huge pages, so the part still to be touched
 * is faulted in 2 MiB at a time. p comes from malloc, realloc or
 * st_realloc_big (glibc grows those large blocks in place or with
 * mremap; one from st_malloc_big it copies). NULL (p kept) when out of
 * memory. Release with free(). */
void *st_realloc_big(void *p, size_t n);

/* The address space this process may still map: the soft RLIMIT_AS
 * (ulimit -v) less what is mapped now (/proc/self/statm); SIZE_MAX when
 * there is no such limit. *limit (when not NULL) gets the limit itself,
 * SIZE_MAX when none. An allocation past it fails whatever the RAM. */
size_t st_mem_address_space_left(size_t *limit);

/* strdup that returns NULL on failure; NULL in gives NULL out. */
char *st_strdup(const char *s);

#ifdef __cplusplus
}
#endif
#endif
