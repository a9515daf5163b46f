// The fuzz build compiles the decoders lucent links from Debian's shared libraries (stb_image,
// tinyexr, tinyobjloader) from their headers, so that they are instrumented too: coverage guides
// the fuzzer through them and the sanitizers watch them.
#define TINYOBJLOADER_IMPLEMENTATION
#include <tiny_obj_loader.h>

#define TINYEXR_IMPLEMENTATION
#include <tinyexr.h>

#define STB_IMAGE_IMPLEMENTATION
#include <stb/stb_image.h>
