// stb_image_write for the fuzz build (lucent's PNG output, the seed generator's images). Its JPEG
// encoder shifts negative values left, which UBSan reports: compiled without that check
// (CMakeLists.txt), as the writers never see untrusted input.
#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb/stb_image_write.h>
