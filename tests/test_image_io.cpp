// Image outputs: the 8-bit display encoding (sRGB, gamma, exposure, tone maps) against published
// values, and round trips through PNG, PFM and EXR; OpenEXR inputs that lucent does not write
// itself (tiled, a single grey channel).
#include <gtest/gtest.h>
#include <stb/stb_image.h>
#include <stb/stb_image_write.h>
#include <tinyexr.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <functional>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "core/host_memory.hpp"
#include "fuzz_common.hpp"
#include "lucent/compare.hpp"
#include "support.hpp"

namespace test_image_io {

namespace {

using lucent::DisplaySettings;
using lucent::encode_display;

TEST(ImageIo, SrgbEncodingKnownValues) {
  DisplaySettings d;  // sRGB, no exposure, clamp
  EXPECT_EQ(encode_display(0.0, d), 0);
  EXPECT_EQ(encode_display(1.0, d), 255);
  EXPECT_EQ(encode_display(7.0, d), 255);  // clamped
  EXPECT_EQ(encode_display(-1.0, d), 0);
  EXPECT_EQ(encode_display(0.5, d), 188);   // sRGB(0.5) = 0.7354
  EXPECT_EQ(encode_display(0.18, d), 118);  // middle grey: 0.4614
  EXPECT_EQ(encode_display(0.002, d), 7);   // linear segment: 12.92 * 0.002 = 0.0258
  EXPECT_EQ(encode_display(NAN, d), 0);
}

// An infinity from an array given to write_image is brighter than any finite value: white, as
// 3e38 is (it was black), under every tone map; -inf is black, as every negative value is.
TEST(ImageIo, PositiveInfinityEncodesAsWhite) {
  for (lucent::ToneMap t :
       {lucent::ToneMap::Clamp, lucent::ToneMap::Reinhard, lucent::ToneMap::Aces}) {
    DisplaySettings d;
    d.tonemap = t;
    EXPECT_EQ(encode_display(3e38, d), 255);
    EXPECT_EQ(encode_display(INFINITY, d), 255);
    EXPECT_EQ(encode_display(-INFINITY, d), 0);
    d.exposure = 1e30;
    EXPECT_EQ(encode_display(INFINITY, d), 255);
  }
}

// encode_display refuses the display settings write_image refuses, as its message says (only the
// C++ API can make them): it took a NaN exposure and a NaN gamma as black, and a transfer of 77
// as linear (0.5 gave 128; the API tester's find).
TEST(ImageIo, EncodeDisplayRefusesWhatWriteImageRefuses) {
  const std::string bad_gamma =
      "encode_display: the display gamma must be finite and > 0, the exposure finite";
  DisplaySettings d;
  d.transfer = lucent::Transfer::Gamma;
  for (double gamma : {double(NAN), 0.0, -2.2, double(INFINITY)}) {
    d.gamma = gamma;
    EXPECT_EQ(lucent::test::error_of([&] { encode_display(0.5, d); }).find(bad_gamma), 0u) << gamma;
  }
  d = DisplaySettings{};
  d.exposure = NAN;
  EXPECT_EQ(lucent::test::error_of([&] { encode_display(0.5, d); }),
            bad_gamma + " (gamma 2.2, exposure nan)");
  d = DisplaySettings{};
  d.transfer = static_cast<lucent::Transfer>(77);
  EXPECT_EQ(lucent::test::error_of([&] { encode_display(0.5, d); }),
            "encode_display: unknown display transfer or tone map (77, 0)");
  d = DisplaySettings{};
  d.tonemap = static_cast<lucent::ToneMap>(-1);
  EXPECT_EQ(lucent::test::error_of([&] { encode_display(0.5, d); }),
            "encode_display: unknown display transfer or tone map (0, -1)");
  // write_image says the same of its file
  const std::string path = lucent::test::temp_dir() + "/x.png";
  EXPECT_EQ(lucent::test::error_of([&] {
              lucent::write_image(path, lucent::Image{1, 1, {0.5f, 0.5f, 0.5f}}, d);
            }),
            path + ": unknown display transfer or tone map (0, -1)");
}

TEST(ImageIo, GammaExposureAndToneMaps) {
  DisplaySettings g;
  g.transfer = lucent::Transfer::Gamma;
  g.gamma = 2.2;
  EXPECT_EQ(encode_display(0.5, g), 186);  // 0.5^(1/2.2) = 0.7297
  DisplaySettings lin;
  lin.transfer = lucent::Transfer::Linear;
  EXPECT_EQ(encode_display(0.5, lin), 128);  // 127.5 rounds up
  DisplaySettings e;
  e.exposure = 1;  // one stop: 0.25 -> 0.5
  EXPECT_EQ(encode_display(0.25, e), 188);
  e.exposure = -2;  // 2 -> 0.5
  EXPECT_EQ(encode_display(2.0, e), 188);
  DisplaySettings r;
  r.tonemap = lucent::ToneMap::Reinhard;  // v / (1 + v): 1 -> 0.5
  EXPECT_EQ(encode_display(1.0, r), 188);
  EXPECT_EQ(encode_display(20.0, r), 250);  // 20/21 = 0.952: compressed, not clipped
  DisplaySettings a;
  a.tonemap = lucent::ToneMap::Aces;       // Narkowicz 2015: 1 -> 2.54 / 3.16 = 0.8038
  EXPECT_EQ(encode_display(1.0, a), 232);  // sRGB(0.8038) = 0.9084
  EXPECT_EQ(encode_display(100.0, a), 255);
  // exposures that overflow: white, as the curves tend to (inf / inf made them black), and black
  // stays black (0 times an infinite scale was NaN)
  for (DisplaySettings m : {r, a, DisplaySettings{}}) {
    for (double stops : {1000.0, 1e30}) {
      m.exposure = stops;
      EXPECT_EQ(encode_display(0.5, m), 255) << stops;
      EXPECT_EQ(encode_display(0.0, m), 0) << stops;
    }
    m.exposure = -1e30;
    EXPECT_EQ(encode_display(0.5, m), 0);
  }
}

lucent::Image gradient(int w, int h) {
  lucent::Image img{w, h, std::vector<float>(static_cast<size_t>(w) * h * 3)};
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < 3; ++c)
        img.pixel(x, y)[c] = float((x + 1) * (c + 1)) / float(w * 3) + 0.01f * y;
  return img;
}

TEST(ImageIo, FloatFormatsRoundTripExactly) {
  lucent::Image img = gradient(7, 5);
  img.pixel(3, 2)[1] = 1234.5f;  // HDR values survive
  for (const char* ext : {".pfm", ".exr"}) {
    std::string path = lucent::test::temp_dir() + "/img" + ext;
    lucent::write_image(path, img);
    lucent::Image back = lucent::read_image(path);
    ASSERT_EQ(back.width, 7) << ext;
    ASSERT_EQ(back.height, 5) << ext;
    for (size_t i = 0; i < img.rgb.size(); ++i)
      ASSERT_EQ(back.rgb[i], img.rgb[i]) << ext << " at " << i;
  }
}

TEST(ImageIo, PngRoundTripWithinQuantisation) {
  lucent::Image img = gradient(9, 4);
  std::string path = lucent::test::temp_dir() + "/img.png";
  lucent::write_image(path, img);
  lucent::Image back = lucent::read_image(path);  // decoded from sRGB to linear
  ASSERT_EQ(back.width, 9);
  ASSERT_EQ(back.height, 4);
  for (size_t i = 0; i < img.rgb.size(); ++i) {
    double v = std::min(1.0f, img.rgb[i]);
    // half an 8-bit step (0.5/255) through the slope of the sRGB decoding curve, which is at
    // most 2.4/1.055 = 2.275 (at 1): 0.0045 in linear terms
    EXPECT_NEAR(back.rgb[i], v, 0.0046) << i;
  }
}

// stb_image and stb_image_write keep their flip settings for the process (stb_image also for a
// thread), and the library is shared with the application: lucent's reads and writes neither
// depend on them nor change them. It set the process's read setting to 0 before each read (the
// application's own reads then came unflipped), a thread's setting turned its reads upside down,
// and an application's stbi_flip_vertically_on_write(1) its PNGs (the API campaign).
TEST(ImageIo, TheApplicationsStbFlipSettingsAreNeitherUsedNorChanged) {
  struct Restore {
    ~Restore() {
      stbi_set_flip_vertically_on_load(0);
      stbi_flip_vertically_on_write(0);
    }
  } restore;
  const std::string dir = lucent::test::temp_dir(), a = dir + "/a.png", b = dir + "/b.png";
  const lucent::Image img{1, 2, {1, 1, 1, 0, 0, 0}};  // white above black
  lucent::write_image(a, img);
  stbi_set_flip_vertically_on_load(1);
  EXPECT_EQ(lucent::read_image(a).rgb[0], 1.0f);
  int w = 0, h = 0, n = 0;
  unsigned char* own = stbi_load(a.c_str(), &w, &h, &n, 3);  // the application's read: flipped
  ASSERT_NE(own, nullptr);
  EXPECT_EQ(own[0], 0);
  stbi_image_free(own);
  stbi_set_flip_vertically_on_load(0);
  std::thread([&] {
    stbi_set_flip_vertically_on_load_thread(1);
    EXPECT_EQ(lucent::read_image(a).rgb[0], 1.0f);
  }).join();
  stbi_flip_vertically_on_write(1);
  lucent::write_image(b, img);
  stbi_flip_vertically_on_write(0);
  EXPECT_EQ(lucent::read_image(b).rgb[0], 1.0f);
}

TEST(ImageIo, UnknownExtensionAndUnwritablePathAreErrors) {
  lucent::Image img = gradient(2, 2);
  EXPECT_THROW(lucent::write_image(lucent::test::temp_dir() + "/x.bmpx", img), lucent::Error);
  EXPECT_THROW(lucent::write_image("/nonexistent-dir/x.png", img), lucent::Error);
  EXPECT_THROW(lucent::read_image(lucent::test::temp_dir() + "/missing.pfm"), lucent::Error);
}

// Display settings the scene format refuses are refused by write_image too, naming the path and
// writing nothing (a gamma of 0 wrote a black PNG, an unknown transfer a linear one).
TEST(ImageIo, InvalidDisplaySettingsAreRefused) {
  const lucent::Image img = gradient(2, 2);
  const std::string path = lucent::test::temp_dir() + "/display.png";
  const auto refused = [&](const DisplaySettings& d) {
    std::remove(path.c_str());
    const std::string e = lucent::test::error_of([&] { lucent::write_image(path, img, d); });
    EXPECT_TRUE(e.empty() || e.rfind(path + ": ", 0) == 0) << e;
    EXPECT_EQ(std::ifstream(path).good(), e.empty()) << e;
    return e;
  };
  DisplaySettings d;
  d.transfer = lucent::Transfer::Gamma;
  for (double gamma : {0.0, -1.0, double(NAN), double(INFINITY)}) {
    d.gamma = gamma;
    EXPECT_NE(refused(d).find("gamma must be finite and > 0"), std::string::npos) << gamma;
  }
  d.gamma = 2.2;
  d.exposure = NAN;
  EXPECT_NE(refused(d).find("exposure finite"), std::string::npos);
  d.exposure = 0;
  d.transfer = static_cast<lucent::Transfer>(7);
  EXPECT_NE(refused(d).find("unknown display transfer or tone map (7, 0)"), std::string::npos);
  d.transfer = lucent::Transfer::Srgb;
  d.tonemap = static_cast<lucent::ToneMap>(-1);
  EXPECT_NE(refused(d).find("(0, -1)"), std::string::npos);
  d.tonemap = lucent::ToneMap::Aces;
  EXPECT_EQ(refused(d), "");  // the last of each list is valid
}

using lucent::fuzz::ExrLayout;

/// Writes lucent::fuzz::exr_file's OpenEXR file to `path`.
void write_exr(const std::string& path, int w, int h, const std::vector<std::string>& names,
               const std::function<float(int, int, int)>& value, ExrLayout layout = {}) {
  lucent::test::write_file(path, lucent::fuzz::exr_file(w, h, names, value, layout));
}

/// The error of reading `bytes` as the image file `path` ("" when it reads).
std::string read_error(const std::string& path, const std::string& bytes) {
  lucent::test::write_file(path, bytes);
  try {
    lucent::read_image(path);
  } catch (const lucent::Error& e) {
    return e.what();
  }
  return "";
}

/// Where the offset table of an OpenEXR file starts: after its magic number, version and header.
size_t exr_offset_table(const std::string& bytes) {
  EXRVersion version;
  EXRHeader header;
  InitEXRHeader(&header);
  const auto* data = reinterpret_cast<const unsigned char*>(bytes.data());
  EXPECT_EQ(ParseEXRVersionFromMemory(&version, data, bytes.size()), TINYEXR_SUCCESS);
  EXPECT_EQ(ParseEXRHeaderFromMemory(&header, &version, data, bytes.size(), nullptr),
            TINYEXR_SUCCESS);
  const size_t table = 8 + header.header_len;
  FreeEXRHeader(&header);
  return table;
}

// A tiled OpenEXR file (a texture from another tool) reads as its scanline twin: 37 x 21 pixels in
// tiles of 16, so the right and bottom tiles are cut; every pixel's value is its own.
TEST(ImageIo, TiledExrReadsAsScanlines) {
  auto value = [](int c, int x, int y) { return float(x + 100 * y) + 0.25f * float(c); };
  const std::string dir = lucent::test::temp_dir();
  write_exr(dir + "/tiled.exr", 37, 21, {"B", "G", "R"}, value, {16});
  write_exr(dir + "/lines.exr", 37, 21, {"B", "G", "R"}, value);
  const lucent::Image tiled = lucent::read_image(dir + "/tiled.exr");
  ASSERT_EQ(tiled.width, 37);
  ASSERT_EQ(tiled.height, 21);
  for (int y = 0; y < 21; ++y)
    for (int x = 0; x < 37; ++x)
      for (int c = 0; c < 3; ++c)  // R is channel 2 of the file
        ASSERT_EQ(tiled.pixel(x, y)[c], value(2 - c, x, y)) << x << "," << y << " channel " << c;
  EXPECT_EQ(tiled.rgb, lucent::read_image(dir + "/lines.exr").rgb);
}

/// `bytes` (an OpenEXR file of one part and level) as OpenEXR writes it with lineOrder
/// DECREASING_Y: the header says so and the chunks are stored last first; the offset table
/// still names each chunk's place (indexed by its y, or its tile), and each chunk its y or tile.
std::string with_decreasing_y(const std::string& bytes) {
  std::string out = bytes;
  const std::string attr("lineOrder\0lineOrder\0\1\0\0\0", 24);
  const size_t at = out.find(attr);
  EXPECT_NE(at, std::string::npos);
  EXPECT_EQ(out[at + attr.size()], '\0');  // INCREASING_Y, as tinyexr writes
  out[at + attr.size()] = '\1';
  const size_t table = exr_offset_table(bytes);
  std::uint64_t first;
  std::memcpy(&first, bytes.data() + table, 8);
  const size_t n = (first - table) / 8;
  std::vector<std::uint64_t> offsets(n);
  std::memcpy(offsets.data(), bytes.data() + table, 8 * n);
  std::vector<std::uint64_t> sorted = offsets;
  std::sort(sorted.begin(), sorted.end());
  EXPECT_EQ(sorted, offsets);  // tinyexr stores chunks in table order
  std::string chunks;
  std::vector<std::uint64_t> moved(n);
  for (size_t i = n; i-- > 0;) {
    const std::uint64_t end = i + 1 < n ? offsets[i + 1] : bytes.size();
    moved[i] = first + chunks.size();
    chunks += bytes.substr(offsets[i], end - offsets[i]);
  }
  std::memcpy(&out[table], moved.data(), 8 * n);
  return out.substr(0, first) + chunks;
}

// OpenEXR's lineOrder only says in which order the chunks are stored; every chunk names its own
// rows (or tile). tinyexr 1.0.1 wrote the rows of a DECREASING_Y file flipped (its issue 213):
// scanline files came out upside down (a texture, an environment map's sky and ground swapped,
// compare failing two files of the same pixels), tiled ones flipped each tile and left the rows
// past a cut edge tile's height uninitialised (garbage texels, a different image each run).
TEST(ImageIo, ExrOfDecreasingLineOrderReadsAsItsPixels) {
  auto value = [](int c, int x, int y) { return float(x + 100 * y) + 0.25f * float(c); };
  const std::string dir = lucent::test::temp_dir();
  for (lucent::fuzz::ExrLayout layout :
       {lucent::fuzz::ExrLayout{},
        lucent::fuzz::ExrLayout{0, TINYEXR_TILE_ONE_LEVEL, TINYEXR_TILE_ROUND_DOWN,
                                TINYEXR_COMPRESSIONTYPE_NONE},
        lucent::fuzz::ExrLayout{16}, lucent::fuzz::ExrLayout{4}}) {
    SCOPED_TRACE("tile " + std::to_string(layout.tile) + ", compression " +
                 std::to_string(layout.compression));
    const std::string path = dir + "/decreasing.exr";
    lucent::test::write_file(
        path, with_decreasing_y(lucent::fuzz::exr_file(37, 21, {"B", "G", "R"}, value, layout)));
    const lucent::Image image = lucent::read_image(path);
    ASSERT_EQ(image.width, 37);
    ASSERT_EQ(image.height, 21);
    for (int y = 0; y < 21; ++y)
      for (int x = 0; x < 37; ++x)
        for (int c = 0; c < 3; ++c)
          ASSERT_EQ(image.pixel(x, y)[c], value(2 - c, x, y)) << x << "," << y << " channel " << c;
  }
}

// Tiled files with mip-map or rip-map levels (texture tools write them), their level sizes
// rounded down or up: the probe's count of levels and tiles (which checks every chunk, against
// tinyexr's unchecked tile coordinates) is tinyexr's, so each reads, as its level 0. (tinyexr's
// writer refuses a level 0 smaller than a tile, so every size here is at least one tile.)
TEST(ImageIo, MipMappedAndRipMappedTiledExrRead) {
  auto value = [](int c, int x, int y) { return float(x + 100 * y) + 0.25f * float(c); };
  const std::string dir = lucent::test::temp_dir();
  for (int levels :
       {TINYEXR_TILE_ONE_LEVEL, TINYEXR_TILE_MIPMAP_LEVELS, TINYEXR_TILE_RIPMAP_LEVELS})
    for (int rounding : {TINYEXR_TILE_ROUND_DOWN, TINYEXR_TILE_ROUND_UP})
      for (const auto& [w, h] : {std::pair{37, 21}, std::pair{16, 9}, std::pair{9, 17}}) {
        const std::string what = "levels " + std::to_string(levels) + ", rounding " +
                                 std::to_string(rounding) + ", " + std::to_string(w) + "x" +
                                 std::to_string(h);
        write_exr(dir + "/m.exr", w, h, {"B", "G", "R"}, value, {8, levels, rounding});
        lucent::Image img;
        try {
          img = lucent::read_image(dir + "/m.exr");
        } catch (const lucent::Error& e) {
          ADD_FAILURE() << what << ": " << e.what();
          continue;
        }
        ASSERT_EQ(img.width, w) << what;
        ASSERT_EQ(img.height, h) << what;
        for (int y = 0; y < h; ++y)
          for (int x = 0; x < w; ++x)
            for (int c = 0; c < 3; ++c)
              ASSERT_EQ(img.pixel(x, y)[c], value(2 - c, x, y)) << what << " at " << x << "," << y;
      }
}

// What the probe refuses in a tiled file before tinyexr decodes it (tinyexr would multiply
// unchecked values in int, or walk the chunks unchecked to rebuild a damaged offset table), each
// with one line naming the file: an offset table entry outside the tiles' data, an unknown level
// mode, and tiles whose buffers exceed the pixel limit. Each is a good file with bytes replaced.
TEST(ImageIo, DamagedTiledExrIsRefused) {
  auto value = [](int c, int x, int y) { return float(x + y + c); };
  const std::string dir = lucent::test::temp_dir(), path = dir + "/t.exr";
  write_exr(path, 37, 21, {"B", "G", "R"}, value, {16});
  const std::string good = lucent::test::read_file(path);
  auto error_of = [&](const std::string& bytes) { return read_error(path, bytes); };
  ASSERT_EQ(error_of(good), "");
  // the offset table follows the header: 6 entries (3 x 2 tiles of 16)
  const size_t table = exr_offset_table(good);
  std::string zeroed = good;
  zeroed.replace(table + 16, 8, std::string(8, '\0'));  // entry 2: tinyexr rebuilds the table
  EXPECT_EQ(error_of(zeroed), path +
                                  ": OpenEXR offset table entry 2 of 6 (0) points outside the "
                                  "file's tiles (damaged offset table)");
  // the "tiles" attribute: x size, y size (uint32), then the mode byte (level mode | rounding << 4)
  const size_t tiles = good.find(std::string("tiles\0tiledesc\0", 15)) + 15 + 4;
  ASSERT_EQ(good[tiles], 16);
  std::string mode = good;
  mode[tiles + 8] = 3;
  EXPECT_EQ(error_of(mode), path + ": OpenEXR header has an unknown tile level mode 3");
  std::string huge = good;
  huge.replace(tiles, 8, std::string("\0\0\0\x01\0\0\0\x01", 8));  // tiles of 2^24 x 2^24
  EXPECT_NE(error_of(huge).find(path + ": OpenEXR tiles of 16777216x16777216 for a 37x21 image "
                                       "take more than the limit of "),
            std::string::npos)
      << error_of(huge);
}

// An OpenEXR image is its display window; its data window holds the pixels stored, which may cover
// part of it (a crop: the rest is 0, as OpenEXR's readers leave it) or reach beyond it (overscan:
// dropped). The data window alone was read as the image: a crop stretched over the whole texture,
// an overscan border shown inside it. tinyexr writes both windows as [0, w) x [0, h); the tests
// rewrite the display window's four numbers in place.
TEST(ImageIo, ExrImageIsItsDisplayWindow) {
  auto value = [](int c, int x, int y) { return 1 + float(x + 10 * y) + 0.25f * float(c); };
  const std::string dir = lucent::test::temp_dir(), path = dir + "/w.exr";
  for (int tile : {0, 2}) {
    ExrLayout layout;
    layout.tile = tile;
    write_exr(path, 3, 2, {"B", "G", "R"}, value, layout);
    const std::string good = lucent::test::read_file(path);
    const std::string name("displayWindow\0box2i\0", 20);
    const size_t at = good.find(name);
    ASSERT_NE(at, std::string::npos);
    auto with_display = [&](std::int32_t x0, std::int32_t y0, std::int32_t x1, std::int32_t y1) {
      std::string bytes = good;
      const std::int32_t box[4] = {x0, y0, x1, y1};
      std::memcpy(&bytes[at + name.size() + 4], box, sizeof box);  // after the size (16)
      lucent::test::write_file(path, bytes);
      return lucent::read_image(path);
    };
    // the data window [0, 3) x [0, 2) at (1, 2) of a display window [-1, 4) x [-2, 1)
    lucent::Image img = with_display(-1, -2, 3, 0);
    ASSERT_EQ(img.width, 5);
    ASSERT_EQ(img.height, 3);
    for (int y = 0; y < 3; ++y)
      for (int x = 0; x < 5; ++x)
        for (int c = 0; c < 3; ++c) {
          const bool stored = x >= 1 && x < 4 && y == 2;
          EXPECT_EQ(img.pixel(x, y)[c], stored ? value(2 - c, x - 1, y - 2) : 0.0f)
              << tile << ": " << x << ", " << y;
        }
    // overscan: a display window [1, 2) x [1, 2) inside the data window shows its pixel (1, 1)
    img = with_display(1, 1, 1, 1);
    ASSERT_EQ(img.width, 1);
    ASSERT_EQ(img.height, 1);
    for (int c = 0; c < 3; ++c) EXPECT_EQ(img.pixel(0, 0)[c], value(2 - c, 1, 1)) << tile;
    // apart: black
    img = with_display(100, 100, 101, 100);
    ASSERT_EQ(img.width, 2);
    for (float v : img.rgb) EXPECT_EQ(v, 0.0f);
    // refused as the data window is: empty, or past the pixel limit
    auto error_with = [&](std::int32_t x0, std::int32_t y0, std::int32_t x1, std::int32_t y1) {
      try {
        with_display(x0, y0, x1, y1);
      } catch (const lucent::Error& e) {
        return std::string(e.what());
      }
      return std::string();
    };
    // a display window far larger than the file: within the host's memory (read_image had no
    // check: a 341-byte file took 418 MiB at 4096x4096)
    lucent::sys::set_host_limit_override(std::uint64_t(1) << 30);
    const std::string huge = error_with(0, 0, 16383, 16383);
    lucent::sys::set_host_limit_override(0);
    EXPECT_EQ(huge.rfind(path + ": reading this 16384x16384 image needs about ", 0), 0u) << huge;
    EXPECT_EQ(error_with(0, 0, -1, 0),
              path + ": OpenEXR header claims an empty display window (0x1)");
    EXPECT_NE(error_with(0, 0, 2000000000, 0)
                  .find("header claims 2000000001x1 pixels, more than the limit"),
              std::string::npos);
  }
}

// The chunkCount attribute of a scanline file: tinyexr sizes the offset table by it, allocating 8
// bytes an entry before reading any (fuzz_render_image found a 735-byte file that asked for
// 3.6 GB: docs/reliability.md), so the probe requires it to be the file's count of chunks, one
// per block of scanlines. A good file with the attribute inserted reads as before; with any other
// count it is refused with one line, before anything is allocated for the table.
TEST(ImageIo, ExrChunkCountMustBeTheChunksOfItsScanlines) {
  auto value = [](int c, int x, int y) { return float(x + 100 * y) + 0.25f * float(c); };
  const std::string dir = lucent::test::temp_dir(), path = dir + "/c.exr";
  for (int compression : {TINYEXR_COMPRESSIONTYPE_NONE, TINYEXR_COMPRESSIONTYPE_ZIP}) {
    ExrLayout layout;
    layout.compression = compression;
    write_exr(path, 37, 21, {"B", "G", "R"}, value, layout);
    const std::string good = lucent::test::read_file(path);
    const int chunks = compression == TINYEXR_COMPRESSIONTYPE_ZIP ? 2 : 21;  // 16 lines or 1
    // the header ends with a 0 byte just before the offset table; the attribute goes before it,
    // and every offset (from the start of the file) moves by its length
    const size_t table = exr_offset_table(good);
    auto with_count = [&](std::int32_t count) {
      std::string attr("chunkCount\0int\0", 15);
      const std::int32_t four = 4;
      attr.append(reinterpret_cast<const char*>(&four), 4);
      attr.append(reinterpret_cast<const char*>(&count), 4);
      std::string bytes = good;
      bytes.insert(table - 1, attr);
      for (int k = 0; k < chunks; ++k) {
        std::uint64_t offset = 0;
        std::memcpy(&offset, bytes.data() + table + attr.size() + 8 * k, 8);
        offset += attr.size();
        std::memcpy(&bytes[table + attr.size() + 8 * k], &offset, 8);
      }
      return bytes;
    };
    const std::string what = "compression " + std::to_string(compression);
    ASSERT_EQ(read_error(path, with_count(chunks)), "") << what;
    const lucent::Image img = lucent::read_image(path);
    ASSERT_EQ(img.width, 37) << what;
    ASSERT_EQ(img.height, 21) << what;
    for (int y = 0; y < 21; ++y)
      for (int x = 0; x < 37; ++x)
        for (int c = 0; c < 3; ++c) ASSERT_EQ(img.pixel(x, y)[c], value(2 - c, x, y)) << what;
    for (std::int32_t count : {1, chunks + 1, 2147483647})
      EXPECT_EQ(read_error(path, with_count(count)),
                path + ": OpenEXR header's chunkCount is " + std::to_string(count) +
                    ", but its 21 scanlines make " + std::to_string(chunks) + " chunks")
          << what;
  }
}

// PIZ-compressed scanline files read; the probe walks each PIZ chunk's table of Huffman code
// lengths as tinyexr unpacks it (tinyexr ignores a failed unpacking and decodes with run codes as
// lengths: signed overflow, found by fuzz_texture), so a good table passes and a table whose
// lengths run past the Huffman data, or whose zero run passes its last symbol, is refused.
TEST(ImageIo, PizExrReadsAndDamagedHuffmanTablesAreRefused) {
  auto value = [](int c, int x, int y) { return float((x * 7 + y * 13 + c * 5) % 23) * 0.125f; };
  const std::string dir = lucent::test::temp_dir(), path = dir + "/p.exr";
  ExrLayout piz;
  piz.compression = TINYEXR_COMPRESSIONTYPE_PIZ;
  write_exr(path, 64, 40, {"B", "G", "R"}, value, piz);
  const std::string good = lucent::test::read_file(path);
  const lucent::Image img = lucent::read_image(path);
  ASSERT_EQ(img.width, 64);
  ASSERT_EQ(img.height, 40);
  for (int y = 0; y < 40; ++y)
    for (int x = 0; x < 64; ++x)
      for (int c = 0; c < 3; ++c) ASSERT_EQ(img.pixel(x, y)[c], value(2 - c, x, y));
  // the first chunk: line, size, then the PIZ data: bitmap bounds and bitmap, the Huffman
  // data's size, then its im, iM, table length, bit count, a reserved word and the table
  const size_t table = exr_offset_table(good);
  std::uint64_t chunk = 0;
  std::memcpy(&chunk, good.data() + table, 8);
  std::int32_t size = 0;
  std::memcpy(&size, good.data() + chunk + 4, 4);
  ASSERT_LT(size, 64 * 32 * 12) << "the first chunk is stored raw, not PIZ-compressed";
  const size_t piz_data = chunk + 8;
  std::uint16_t lo = 0, hi = 0;
  std::memcpy(&lo, good.data() + piz_data, 2);
  std::memcpy(&hi, good.data() + piz_data + 2, 2);
  const size_t huffman = piz_data + 4 + (lo <= hi ? hi - lo + 1 : 0);  // its size, then its data
  std::int32_t im = 0, iM = 0;
  std::memcpy(&im, good.data() + huffman + 4, 4);
  std::memcpy(&iM, good.data() + huffman + 8, 4);
  ASSERT_LT(im, iM);
  auto error_of = [&](const std::string& bytes) { return read_error(path, bytes); };
  const std::string at =
      path + ": OpenEXR PIZ chunk at byte " + std::to_string(chunk) + " is corrupt: ";
  std::string short_table = good;  // the Huffman data: its 20-byte header and one table byte
  const std::int32_t one = 21;
  short_table.replace(huffman, 4, reinterpret_cast<const char*>(&one), 4);
  EXPECT_EQ(error_of(short_table), at + "its Huffman code lengths run past its Huffman data");
  std::string long_run = good;  // one symbol, whose length is a run of at least 6 zeros
  long_run.replace(huffman + 8, 4, reinterpret_cast<const char*>(&im), 4);
  long_run[huffman + 4 + 20] = static_cast<char>(0xFC);  // 111111..: 63, a long zero run
  EXPECT_EQ(error_of(long_run),
            at + "a run of zero code lengths passes the last symbol of its Huffman table");
  std::string short_run = long_run;  // 111011..: 59, a run of 2 zeros
  short_run[huffman + 4 + 20] = static_cast<char>(0xEC);
  EXPECT_EQ(error_of(short_run),
            at + "a run of zero code lengths passes the last symbol of its Huffman table");
}

// A PNG says how its values encode light: sRGB (with the gAMA of 1/2.2 beside it), gAMA 1/gamma
// for the gamma transfer, 1 for linear, after IHDR and before the image data, each with its CRC.
// Without them a viewer took a linear or gamma-1.8 PNG for sRGB (too dark or too light).
TEST(ImageIo, PngsSayTheirTransfer) {
  const std::string dir = lucent::test::temp_dir();
  lucent::Image img{2, 1, {0.0f, 0.5f, 1.0f, 0.25f, 0.125f, 2.0f}};
  const auto be32 = [](const std::string& b, size_t at) {
    return std::uint32_t(std::uint8_t(b[at])) << 24 | std::uint32_t(std::uint8_t(b[at + 1])) << 16 |
           std::uint32_t(std::uint8_t(b[at + 2])) << 8 | std::uint32_t(std::uint8_t(b[at + 3]));
  };
  struct Case {
    lucent::Transfer transfer;
    double gamma;
    std::string srgb;
    std::uint32_t gama;
  };
  const Case cases[] = {{lucent::Transfer::Srgb, 2.2, std::string(1, '\0'), 45455},
                        {lucent::Transfer::Gamma, 2.2, "", 45455},
                        {lucent::Transfer::Gamma, 1.8, "", 55556},
                        {lucent::Transfer::Linear, 2.2, "", 100000}};
  for (const Case& c : cases) {
    lucent::DisplaySettings d;
    d.transfer = c.transfer;
    d.gamma = c.gamma;
    lucent::write_image(dir + "/t.png", img, d);
    const std::string png = lucent::test::read_file(dir + "/t.png");
    std::vector<std::string> tags;
    std::string srgb, gama;
    for (size_t at = 8; at + 12 <= png.size();) {
      const std::uint32_t len = be32(png, at);
      const std::string tag = png.substr(at + 4, 4), data = png.substr(at + 8, len);
      EXPECT_EQ(be32(png, at + 8 + len), lucent::test::crc32(tag + data)) << tag;
      if (tag == "sRGB") srgb = data;
      if (tag == "gAMA") gama = data;
      if (tags.empty() || tags.back() != tag) tags.push_back(tag);
      at += 12 + len;
    }
    const std::vector<std::string> order =
        c.srgb.empty() ? std::vector<std::string>{"IHDR", "gAMA", "IDAT", "IEND"}
                       : std::vector<std::string>{"IHDR", "sRGB", "gAMA", "IDAT", "IEND"};
    EXPECT_EQ(tags, order) << c.gamma;
    EXPECT_EQ(srgb, c.srgb);
    ASSERT_EQ(gama.size(), 4u);
    EXPECT_EQ(be32(gama, 0), c.gama) << c.gamma;
    // the pixels read back as they were encoded (decoders skip the chunks they do not use)
    const lucent::Image back = lucent::read_image(dir + "/t.png");
    EXPECT_EQ(back.width, 2);
    EXPECT_EQ(back.rgb.size(), 6u);
  }
}

// An OpenEXR file's n layer in float (not lucent's UINT) holds whole counts: 16.5, a negative or
// a NaN count is an error naming the file, the pixel and the value (16.5 was read as 16).
TEST(ImageIo, FloatSampleCountsAreWholeNumbers) {
  const std::string dir = lucent::test::temp_dir();
  for (const float bad : {16.5f, -1.0f, std::nanf("")}) {
    write_exr(
        dir + "/n.exr", 4, 2, {"B", "G", "R", "n", "var.B", "var.G", "var.R"},
        [bad](int c, int x, int y) { return c == 3 ? (x == 2 && y == 1 ? bad : 16.0f) : 0.25f; });
    const std::string err = lucent::test::error_of([&] { lucent::read_render(dir + "/n.exr"); });
    EXPECT_EQ(err.rfind(dir + "/n.exr: channel n: pixel 2, 1 has an invalid sample count ", 0), 0u)
        << bad << ": " << err;
  }
  write_exr(dir + "/n.exr", 4, 2, {"B", "G", "R", "n", "var.B", "var.G", "var.R"},
            [](int c, int, int) { return c == 3 ? 16.0f : 0.25f; });
  EXPECT_EQ(lucent::read_render(dir + "/n.exr").samples, std::vector<std::uint32_t>(8, 16));
  // some of the statistics layers: variances without their counts were dropped without a word,
  // and a noisy image was compared as an exact one
  write_exr(dir + "/v.exr", 4, 2, {"B", "G", "R", "var.B", "var.G", "var.R"},
            [](int, int, int) { return 0.25f; });
  EXPECT_EQ(lucent::test::error_of([&] { lucent::read_render(dir + "/v.exr"); }),
            dir +
                "/v.exr: has some of the statistics channels var.R, var.G, var.B and n, not n (a "
                "variance per sample needs its count, n): write all four, or none");
  write_exr(dir + "/v.exr", 4, 2, {"B", "G", "R", "n", "var.R"},
            [](int c, int, int) { return c == 3 ? 16.0f : 0.25f; });
  EXPECT_NE(lucent::test::error_of([&] {
              lucent::read_render(dir + "/v.exr");
            }).find("not var.G, var.B (a variance"),
            std::string::npos);
}

// A single-channel OpenEXR file (Y, or one channel of any name but R, G or B) is grey; one with
// some of R, G and B has the others 0; one without R, G, B or Y among several channels is an
// error naming the file.
TEST(ImageIo, GreyExrIsGreyAndOtherChannelsAreRefused) {
  auto value = [](int, int x, int y) { return 0.5f * float(x) + float(y); };
  const std::string dir = lucent::test::temp_dir();
  for (const char* name : {"Y", "Z"}) {
    write_exr(dir + "/grey.exr", 5, 3, {name}, value);
    const lucent::Image grey = lucent::read_image(dir + "/grey.exr");
    ASSERT_EQ(grey.rgb.size(), 5u * 3u * 3u);
    for (int y = 0; y < 3; ++y)
      for (int x = 0; x < 5; ++x)
        for (int c = 0; c < 3; ++c) ASSERT_EQ(grey.pixel(x, y)[c], value(0, x, y)) << name;
  }
  write_exr(dir + "/uv.exr", 5, 3, {"U", "V"}, value);
  try {
    lucent::read_image(dir + "/uv.exr");
    ADD_FAILURE() << "read an image without colour channels";
  } catch (const lucent::Error& e) {
    EXPECT_EQ(std::string(e.what()), dir + "/uv.exr: OpenEXR file has no R, G, B or Y channels");
  }
  // some of R, G and B: the others are 0, as OpenEXR's RGBA reader fills them (a file of R
  // alone came out grey, R copied into G and B; R and G together were refused)
  for (const std::vector<std::string>& names :
       {std::vector<std::string>{"R"}, {"G", "R"}, {"B"}, {"B", "G"}}) {
    write_exr(dir + "/some.exr", 5, 3, names, value);
    const lucent::Image some = lucent::read_image(dir + "/some.exr");
    ASSERT_EQ(some.rgb.size(), 5u * 3u * 3u);
    for (int c = 0; c < 3; ++c) {
      const bool has =
          std::find(names.begin(), names.end(), std::string(1, "RGB"[c])) != names.end();
      for (int y = 0; y < 3; ++y)
        for (int x = 0; x < 5; ++x)
          ASSERT_EQ(some.pixel(x, y)[c], has ? value(0, x, y) : 0.0f) << names[0] << " " << c;
    }
  }
  // luminance/chroma is a colour image: read from Y alone it came out grey, without a word
  write_exr(dir + "/ryby.exr", 5, 3, {"BY", "RY", "Y"}, value);
  EXPECT_EQ(lucent::test::error_of([&] { lucent::read_image(dir + "/ryby.exr"); }),
            dir +
                "/ryby.exr: OpenEXR file is luminance/chroma (Y, RY, BY channels), which lucent "
                "does not read; save it as RGB");
}

}  // namespace

}  // namespace test_image_io
