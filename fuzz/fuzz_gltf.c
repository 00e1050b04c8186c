/* fuzz_gltf.c - libFuzzer harness for the glTF 2.0 reader, .gltf and .glb
 * (see fuzz_soup.h). Parsed from memory: buffers are GLB chunks or data
 * URIs, never files, so the fuzzer does not touch the file system. */
#define FUZZ_FORMAT ST_SOUP_GLTF
#include "fuzz_soup.h"
