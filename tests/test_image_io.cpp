// Image outputs: the 8-bit display encoding (sRGB, gamma, exposure, tone maps) against published
// values, and round trips through PNG, PFM and EXR; OpenEXR inputs that lucent does not write
// itself (tiled, a single grey channel).
#include <gtest/gtest.h>
#include <tinyexr.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

#include "support.hpp"

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

TEST(ImageIo, UnknownExtensionAndUnwritablePathAreErrors) {
  lucent::Image img = gradient(2, 2);
  EXPECT_THROW(lucent::write_image(lucent::test::temp_dir() + "/x.bmpx", img), lucent::Error);
  EXPECT_THROW(lucent::write_image("/nonexistent-dir/x.png", img), lucent::Error);
  EXPECT_THROW(lucent::read_image(lucent::test::temp_dir() + "/missing.pfm"), lucent::Error);
}

/// Writes an OpenEXR file of float channels `names` (in that order), w x h, channel c of pixel
/// (x, y) = value(c, x, y), with tinyexr: scanlines, or tiles of `tile` pixels when tile > 0
/// (tinyexr's writer takes the tiles themselves, each a tile x tile buffer, cut at the edges).
void write_exr(const std::string& path, int w, int h, const std::vector<std::string>& names,
               const std::function<float(int, int, int)>& value, int tile = 0) {
  const int nc = static_cast<int>(names.size());
  EXRHeader header;
  InitEXRHeader(&header);
  EXRImage image;
  InitEXRImage(&image);
  std::vector<EXRChannelInfo> channels(nc);
  for (int c = 0; c < nc; ++c) std::strncpy(channels[c].name, names[c].c_str(), 255);
  std::vector<int> types(nc, TINYEXR_PIXELTYPE_FLOAT);
  header.num_channels = nc;
  header.channels = channels.data();
  header.pixel_types = types.data();
  header.requested_pixel_types = types.data();
  header.compression_type = TINYEXR_COMPRESSIONTYPE_ZIP;
  image.num_channels = nc;
  image.width = w;
  image.height = h;
  std::vector<std::vector<float>> planes;
  std::vector<std::vector<unsigned char*>> pointers;
  std::vector<EXRTile> tiles;
  auto plane = [&](int tx, int ty, int stride, int tw, int th) {
    pointers.emplace_back();
    for (int c = 0; c < nc; ++c) {
      planes.emplace_back(static_cast<size_t>(stride) * (tile > 0 ? tile : th), 0.0f);
      for (int j = 0; j < th; ++j)
        for (int i = 0; i < tw; ++i)
          planes.back()[size_t(j) * stride + i] = value(c, tx + i, ty + j);
      pointers.back().push_back(reinterpret_cast<unsigned char*>(planes.back().data()));
    }
    return pointers.back().data();
  };
  planes.reserve(64 * nc);  // stable addresses
  pointers.reserve(64);
  if (tile == 0) {
    image.images = plane(0, 0, w, w, h);
  } else {
    header.tiled = 1;
    header.tile_size_x = header.tile_size_y = tile;
    header.tile_level_mode = TINYEXR_TILE_ONE_LEVEL;
    header.tile_rounding_mode = TINYEXR_TILE_ROUND_DOWN;
    header.data_window.max_x = header.display_window.max_x = w - 1;  // the tile count's source
    header.data_window.max_y = header.display_window.max_y = h - 1;
    for (int ty = 0; ty * tile < h; ++ty)
      for (int tx = 0; tx * tile < w; ++tx) {
        EXRTile t{};
        t.offset_x = tx;
        t.offset_y = ty;
        t.width = std::min(tile, w - tx * tile);
        t.height = std::min(tile, h - ty * tile);
        t.images = plane(tx * tile, ty * tile, tile, t.width, t.height);
        tiles.push_back(t);
      }
    ASSERT_LE(tiles.size(), 64u);
    image.tiles = tiles.data();
    image.num_tiles = static_cast<int>(tiles.size());
  }
  unsigned char* memory = nullptr;
  const char* err = nullptr;
  const size_t size = SaveEXRImageToMemory(&image, &header, &memory, &err);
  ASSERT_GT(size, 0u) << (err ? err : "");
  std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(memory), size);
  std::free(memory);
}

// A tiled OpenEXR file (a texture from another tool) reads as its scanline twin: 37 x 21 pixels in
// tiles of 16, so the right and bottom tiles are cut; every pixel's value is its own.
TEST(ImageIo, TiledExrReadsAsScanlines) {
  auto value = [](int c, int x, int y) { return float(x + 100 * y) + 0.25f * float(c); };
  const std::string dir = lucent::test::temp_dir();
  write_exr(dir + "/tiled.exr", 37, 21, {"B", "G", "R"}, value, 16);
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

// A single-channel OpenEXR file (Y, or one channel of any name) is grey; one without R, G, B or
// Y among several channels is an error naming the file.
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
}

}  // namespace
