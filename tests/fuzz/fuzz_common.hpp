#pragma once
// Shared by the fuzz targets: inputs that carry several files, a private directory to write them
// to, and the checks every loaded scene must pass.
//
// A bundle is the main file's bytes, then any number of parts, each introduced by a line
// "@@ NAME" (the "\n@@ " marker, a name of at most 32 characters from [A-Za-z0-9._-] not
// starting with a dot, a newline); parts with other names are dropped. The loaders see the main
// file and the parts as files of one directory, so that a scene's meshes and textures, and an
// OBJ file's MTL libraries and textures, come from the same input.
#include <tinyexr.h>

#include <cfloat>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "lucent/scene.hpp"

namespace lucent::fuzz {

struct Bundle {
  std::string main;
  std::vector<std::pair<std::string, std::string>> parts;
};

Bundle parse_bundle(const std::uint8_t* data, std::size_t size);

/// Serialises a bundle (the seed generator writes them).
std::string make_bundle(const std::string& main,
                        const std::vector<std::pair<std::string, std::string>>& parts);

/// A directory private to this process (on /dev/shm when it exists), emptied of the files the
/// previous input wrote; writes `main_name` and the parts into it. Returns the directory.
std::string write_bundle(const Bundle& b, const std::string& main_name);

/// Scene loading warnings are dropped (they are not what the fuzzer looks at).
void silence_warnings();

/// Traps (a crash libFuzzer reports) unless `ok`: a loader accepted something it must refuse.
inline void check(bool ok, const char* what) {
  if (!ok) {
    std::fprintf(stderr, "fuzz invariant violated: %s\n", what);
    std::abort();
  }
}

/// What a loaded scene must satisfy: every index in range, every number finite and within float
/// range where the device stores floats, every texture consistent.
void check_scene(const Scene& s);

/// How exr_file lays out its file: scanlines (tile 0), or tiles of `tile` pixels in one level or
/// in mip-map or rip-map levels, each level's size rounded down or up (OpenEXR's rules).
struct ExrLayout {
  int tile = 0;
  int levels = TINYEXR_TILE_ONE_LEVEL;
  int rounding = TINYEXR_TILE_ROUND_DOWN;
  int compression = TINYEXR_COMPRESSIONTYPE_ZIP;
  int pixel_type = TINYEXR_PIXELTYPE_FLOAT;  ///< as stored: tinyexr converts the floats to half
};

/// An OpenEXR file (its bytes) of channels `names` (in that order), w x h, stored and compressed
/// as `layout` says (default: float, ZIP);
/// channel c of pixel (x, y) of level 0 = value(c, x, y) (of level (lx, ly): that + 1000 (lx +
/// ly)), made by tinyexr. Its writer takes the tiles themselves, each a full tile buffer cut at
/// the edges, level by level in the file's order, checks each level's tile count against its own
/// and refuses a level 0 smaller than a tile. Throws lucent::Error when tinyexr cannot encode it.
/// (Tests of tiled inputs, and the fuzz seeds.)
std::string exr_file(int w, int h, const std::vector<std::string>& names,
                     const std::function<float(int, int, int)>& value, ExrLayout layout = {});

}  // namespace lucent::fuzz
