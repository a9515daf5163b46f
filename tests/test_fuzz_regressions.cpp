// Inputs the fuzzers (tests/fuzz, scripts/fuzz.sh) found crashing, leaking or reading out of
// bounds, kept in tests/fuzz/regressions/<target>/ and replayed through the release loaders: each
// must be refused with one line that names the file and says what is wrong, or load (the fuzz
// build replays them too, under AddressSanitizer and LeakSanitizer, as seeds).
// docs/reliability.md describes each finding.
#include <gtest/gtest.h>

#include <filesystem>
#include <glm/glm.hpp>
#include <map>
#include <string>

#include "fuzz_common.hpp"
#include "image/image_probe.hpp"
#include "lucent/error.hpp"
#include "scene/loaders.hpp"
#include "support.hpp"

namespace test_fuzz_regressions {

namespace {

namespace fs = std::filesystem;

/// The error loading regression input `file` of `target` ("" when it loads and passes the fuzz
/// targets' checks).
std::string replay(const std::string& target, const fs::path& file) {
  const std::string bytes = lucent::test::read_file(file.string());
  const auto* data = reinterpret_cast<const unsigned char*>(bytes.data());
  const std::string name = file.string();
  try {
    if (target == "texture") {
      lucent::scene_detail::decode_texture(data, bytes.size(), name);
    } else if (target == "render_image") {
      lucent::image_detail::read_render_memory(data, bytes.size(), name);
    } else if (target == "scene") {
      lucent::fuzz::Bundle b = lucent::fuzz::parse_bundle(data, bytes.size());
      std::string dir = lucent::fuzz::write_bundle(b, "scene.json");
      lucent::fuzz::check_scene(lucent::load_scene(dir + "/scene.json"));
    } else if (target == "obj") {
      lucent::fuzz::Bundle b = lucent::fuzz::parse_bundle(data, bytes.size());
      std::string dir = lucent::fuzz::write_bundle(b, "m.obj");
      lucent::Scene scene;
      lucent::scene_detail::load_obj(scene, dir + "/m.obj", glm::dmat4(1.0), -1);
      lucent::fuzz::check_scene(scene);
    }
  } catch (const lucent::Error& e) {
    return e.what();
  }
  return "";
}

// What each input must be refused with (part of the message after the file name); "" for the
// inputs that must load (and pass the fuzz targets' checks).
const std::map<std::string, std::string> kExpected = {
    {"jpeg-dht-overflow.jpg",
     ": JPEG Huffman table at byte 414 has 905 codes, more than 256 (corrupt)"},
    {"exr-piz-overread.exr",
     ": OpenEXR PIZ chunk at byte 329 is corrupt: its bitmap runs past its end"},
    {"exr-piz-overread-2.exr",
     ": OpenEXR PIZ chunk at byte 329 is corrupt: its bitmap runs past its end"},
    {"exr-leak.exr", ": cannot read OpenEXR pixels:"},
    {"exr-piz-negative-bits.exr",
     ": OpenEXR PIZ chunk at byte 329 is corrupt: its Huffman bit count -2147483648 is negative"},
    // not found by fuzzing: progressive JPEGs (jpegtran -progressive of the seeds' RGB and grey
    // images), whose scans read DC or AC tables only, must pass the scan check above
    {"jpeg-progressive-rgb.jpg", ""},
    {"jpeg-progressive-grey.jpg", ""},
    // a scan reading an AC table no DHT defined: stb_image read past its maxcode array
    {"jpeg-undefined-huffman-table.jpg",
     ": JPEG scan at byte 593 uses Huffman table AC1, which no DHT segment before it defines "
     "(corrupt)"},
    // stb_image's bit reader shifted by 32 (code_bits negative): ubsan.supp, a decoding error
    {"jpeg-negative-code-bits.jpg", ": cannot decode JPEG: unknown marker"},
    // stb_image's DC predictor overflows int on this corrupt baseline JPEG (suppressed in
    // tests/fuzz/ubsan.supp: the value is cast to short, garbage pixels); it decoded, with a
    // quantisation table that no DQT defines (its two tables are both 0): now refused for that
    {"jpeg-dc-overflow.jpg",
     ": JPEG scan at byte 593 uses quantisation table 1, which no DQT segment before it defines"},
    // a tiled EXR whose "tiles" attribute has 1 byte: tinyexr read 9 (heap over-read)
    {"exr-short-tiles-attribute.exr", ": OpenEXR header attribute 'tiles' has 1 bytes, not 9"},
    {"exr-offset-table-overread.exr",
     ": OpenEXR file is truncated: its 5x2088 header needs 841 bytes of header and offset table, "
     "the file has 840"},
    {"exr-leak-env.bundle", "/img.exr: cannot read OpenEXR pixels:"},
    // tiled EXRs (from the seed tiled.exr): tinyexr multiplied a chunk's unchecked tile
    // coordinates by the tile size in int, 4 x 1767337573 and 4915204 x 32256 (signed overflow);
    // the probe now checks every chunk's tile and level against the level's grid
    {"exr-tile-coordinate-overflow.exr",
     ": OpenEXR tile chunk at byte 523 names tile (0, 0) of level (1702390128, 1886601580), not "
     "one of the 3x2 tiles of level (0, 0)"},
    {"exr-tile-size-overflow.exr",
     ": OpenEXR tile chunk at byte 431 names tile (1, 0) of level (10240, 0), not one of the 3x1 "
     "tiles of level (0, 0)"},
    // a PIZ chunk whose table of Huffman code lengths tinyexr cannot unpack (a zero run past the
    // last symbol, or lengths past the data): tinyexr ignored the failure and decoded with run
    // codes as lengths, computing (1 << 63) - 1 (signed overflow, found by fuzz_texture)
    {"exr-piz-huffman-run-past-table.exr",
     ": OpenEXR PIZ chunk at byte 329 is corrupt: a run of zero code lengths passes the last "
     "symbol of its Huffman table"},
    // a scanline EXR whose chunkCount attribute (452,989,026) tinyexr took for the size of its
    // offset table: it allocated 3.6 GB before reading an entry
    {"exr-chunk-count-huge.exr",
     ": OpenEXR header's chunkCount is 452989026, but its 40 scanlines make 40 chunks"},
    // a map_Kd name longer than the file system allows: std::filesystem::exists threw
    {"long-texture-name.bundle", ""},
    // a vw (skin weight) line whose joint 112147483648 tinyobjloader converted to int: undefined
    // behaviour; its vertex '0f' is refused first
    {"vw-joint-int-overflow.bundle", "/m.obj:8: skin weight line: '0f' is not a number"},
    // a tag line ('t') whose number 3e2147483648... overflowed tinyobjloader's int exponent:
    // undefined behaviour (src/scene/obj_check.cpp, check_exponent)
    {"tinyobj-exponent-overflow.bundle", "/m.obj:1: '3e2147483648"},
    // a vw line "vw 00  0 # 1e39...": tinyobjloader reads past the '#' and converted 1e39 to int
    {"tinyobj-vw-after-hash.bundle", "/m.obj:2: skin weight line: '#' is not a number"},
    // a vt line "vt 0 0e761": tinyobjloader computes 0 x 5^761 = 0 x inf and read NaN, which
    // the checks (reading 0) had let through: the fuzz target's finite-uv check failed
    {"tinyobj-zero-mantissa-huge-exponent.bundle",
     "/m.obj:30: texture coordinate line: '0e761' has an exponent above 300"},
};

TEST(FuzzRegressions, EveryFoundInputIsRefusedWithOneLineOrLoads) {
  const fs::path root = lucent::test::source_path("tests/fuzz/regressions");
  int n = 0;
  for (const char* target : {"texture", "render_image", "scene", "obj"}) {
    if (!fs::is_directory(root / target)) continue;
    for (const auto& e : fs::directory_iterator(root / target)) {
      const std::string name = e.path().filename().string();
      lucent::test::CaptureWarnings warnings;
      const std::string err = replay(target, e.path());
      ++n;
      auto it = kExpected.find(name);
      ASSERT_NE(it, kExpected.end()) << name << ": no expected message for it: " << err;
      if (it->second.empty()) {
        EXPECT_EQ(err, "") << name;
        continue;
      }
      ASSERT_FALSE(err.empty()) << name << " loaded";
      EXPECT_EQ(err.find('\n'), std::string::npos) << name << ": " << err;
      EXPECT_NE(err.find(it->second), std::string::npos) << name << ": " << err;
      // a bundle's files are written out under their own names (scene.json, m.obj, ...)
      if (std::string(target) != "scene" && std::string(target) != "obj") {
        EXPECT_EQ(err.rfind(e.path().string() + ": ", 0), 0u) << name << ": " << err;
      }
    }
  }
  EXPECT_EQ(n, static_cast<int>(kExpected.size()));
}

}  // namespace

}  // namespace test_fuzz_regressions
