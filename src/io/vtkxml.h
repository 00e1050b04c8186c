/*
 * vtkxml.h - pre-flight check of a VTK XML file (.vti, .vtu) before VTK
 * reads it. Private to the library (not installed); C, callable from the
 * C++ adapters.
 *
 * VTK 9.1's XML readers trust the file: a misspelled attribute makes them
 * dereference NULL, and block headers and counts read from the file size
 * their allocations (fuzzing found 2^48-byte blocks and 2^60-entry block
 * tables). The adapters therefore hand VTK only a document this check has
 * passed: its XML head parsed, its structure known, and every declared
 * size compared with the bytes present and with the caller's limit.
 */
#ifndef SOUPTET_VTKXML_H
#define SOUPTET_VTKXML_H

#include <stddef.h>
#include "souptet/err.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Decompress one block of n bytes compressed by `compressor` (the VTKFile
 * attribute: "vtkZLibDataCompressor", "vtkLZ4DataCompressor" or
 * "vtkLZMADataCompressor") into out, which holds cap bytes; returns the
 * bytes written, 0 on failure. */
typedef size_t (*st_vtkxml_inflate_fn)(void *user, const char *compressor,
                                       const unsigned char *in, size_t n,
                                       unsigned char *out, size_t cap);

/* Check the VTK XML document data[0..size) whose VTKFile type must be
 * want_type ("ImageData" or "UnstructuredGrid"). name is used in
 * messages only. Checked:
 *
 *   - the head (everything before the raw payload of <AppendedData>, or
 *     the whole file without one) is well-formed XML of the subset VTK's
 *     writers produce: elements, "..." or '...' attributes, comments, an
 *     <?xml ?> declaration, text with only the predefined entities; no
 *     DOCTYPE, CDATA or processing instructions;
 *   - the element tree is the one VTK expects for want_type, VTKFile's
 *     attributes are all known (type, version, byte_order, header_type,
 *     compressor) with known values;
 *   - every Array/DataArray has a known scalar type, a format, sane
 *     counts, and its data (inline base64, appended raw or base64, ascii
 *     text) holds a block header that lies inside the data, whose sizes
 *     fit in the bytes that remain, whose decoded size is consistent and
 *     at most max_bytes (0: no limit) and covers the values the element
 *     declares;
 *   - an UnstructuredGrid piece's last offset, when readable without
 *     decompressing, lies within what its connectivity's data hold (VTK
 *     sizes the connectivity by it);
 *   - a String array's data hold no more strings than it declares (VTK
 *     writes one past the end otherwise). Compressed string data are
 *     inflated for that through inflate (NULL: such arrays are refused),
 *     16 MiB of them at most.
 *
 * Returns ST_OK, ST_EINPUT (message naming the element, err->line its
 * line) or ST_ELIMIT (an array decodes to more than max_bytes). Never
 * allocates from a size read from the file. */
st_status st_vtkxml_check(const unsigned char *data, size_t size,
                          const char *name, const char *want_type,
                          size_t max_bytes, st_vtkxml_inflate_fn inflate,
                          void *inflate_user, st_error *err);

/* An inflate function through VTK's own compressors (vtk_capture.cpp);
 * user is unused. */
size_t st_vtkxml_inflate_vtk(void *user, const char *compressor,
                             const unsigned char *in, size_t n,
                             unsigned char *out, size_t cap);

/* The limit the adapters pass for a caller's max_bytes: twice it
 * (saturating), 0 staying "none". VTK decodes an array in its file type
 * before souptet converts it (Float64 values into a float grid, Int64
 * connectivity into 32-bit tets), so a file whose result fits max_bytes
 * can hold arrays of up to twice that; the readers check the result
 * against max_bytes exactly themselves. */
static inline size_t st_vtkxml_budget(size_t max_bytes)
{
    return max_bytes > (size_t)-1 / 2 ? (size_t)-1 : 2 * max_bytes;
}

#ifdef __cplusplus
}
#endif
#endif
