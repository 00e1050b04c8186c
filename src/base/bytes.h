/*
 * bytes.h - private byte-level decoding the readers share: little-endian
 * words (binary STL, GLB, glTF accessors) and base64 (glTF data URIs,
 * VTK XML binary arrays). Not installed.
 *
 * Nothing here allocates or fails: the callers bound their inputs and
 * word their own messages. Threads: no state.
 */
#ifndef SOUPTET_BYTES_H
#define SOUPTET_BYTES_H

#include <stddef.h>
#include <stdint.h>

/* The unsigned little-endian word at p (2 or 4 bytes, any alignment). */
static inline uint32_t st_le16(const unsigned char *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8;
}
static inline uint32_t st_le32(const unsigned char *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 |
           (uint32_t)p[3] << 24;
}

/* ---- base64 (RFC 4648) -------------------------------------------------- */

/* The standard alphabet's values plus one; 0 for every other byte. */
extern const unsigned char st_b64_table[256];

/* ST_B64_URL: also the URL-safe alphabet's '-' (62) and '_' (63). */
enum { ST_B64_URL = 1u };

/* The value 0..63 of a base64 character, -1 for any other byte. */
int st_b64_value(unsigned char c, unsigned flags);

/* Decode the characters s[0..n) up to the first one that is not in the
 * alphabet (padding '=', a blank, the end): 6 bits a character, every
 * complete 8 into out (room for n / 4 * 3 + 2 bytes). Returns the bytes
 * written; *stop (may be NULL) is the index of the character that ended
 * the data, n when none did. */
size_t st_b64_decode(const unsigned char *s, size_t n, unsigned flags,
                     unsigned char *out, size_t *stop);

/* One quad at p (standard alphabet, n characters left): 3 bytes, 2 or 1
 * when padded ("xxx=", "xx=="; the stream ends there), 0 when p holds no
 * complete quad. */
int st_b64_quad(const unsigned char *p, size_t n, unsigned char out[3]);

#endif
