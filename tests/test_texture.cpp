// Texture decoding (src/scene/texture.cpp): 8-bit formats from sRGB to linear, HDR/PFM kept linear,
// row 0 at the top, one texture per path, errors naming the file. The images are written by the
// tests with stb_image_write and lucent::write_image; expected values are the sRGB transfer
// function's known values (IEC 61966-2-1), written out below.
#include <gtest/gtest.h>
#include <stb/stb_image_write.h>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <vector>

#include "lucent/error.hpp"
#include "lucent/image.hpp"
#include "scene/loaders.hpp"
#include "support.hpp"

namespace test_texture {

namespace {

using lucent::Scene;
using lucent::scene_detail::load_texture;

// One RGBA texel of a loaded texture, (x, y) with y = 0 the top row.
std::vector<float> texel(const lucent::Texture& t, int x, int y) {
  const float* p = &t.rgba[(static_cast<size_t>(y) * t.width + x) * 4];
  return {p[0], p[1], p[2], p[3]};
}

void expect_texel(const lucent::Texture& t, int x, int y, std::vector<float> want, float tol,
                  const std::string& what) {
  std::vector<float> got = texel(t, x, y);
  for (int c = 0; c < 4; ++c)
    EXPECT_NEAR(got[c], want[c], tol) << what << " texel (" << x << ", " << y << ") channel " << c;
}

// 8-bit sRGB code -> linear, the known values used below.
constexpr float k10 = 0.0030353f, k64 = 0.0512695f, k128 = 0.2158605f, k200 = 0.5775804f;

TEST(Texture, PngDecodesSrgbToLinearAndKeepsAlphaLinear) {
  std::string path = lucent::test::temp_dir() + "/t.png";
  // 2x2 RGBA: top row (0,10,128,a255) (255,64,200,a128); bottom row (128,128,128,a0)
  // (10,200,64,a255)
  const unsigned char px[] = {0,   10,  128, 255, 255, 64,  200, 128,
                              128, 128, 128, 0,   10,  200, 64,  255};
  ASSERT_TRUE(stbi_write_png(path.c_str(), 2, 2, 4, px, 2 * 4));
  Scene scene;
  int i = load_texture(scene, path);
  ASSERT_EQ(i, 0);
  ASSERT_EQ(scene.textures.size(), 1u);
  const lucent::Texture& t = scene.textures[0];
  EXPECT_EQ(t.width, 2);
  EXPECT_EQ(t.height, 2);
  ASSERT_EQ(t.rgba.size(), 16u);
  const float tol = 1e-6f;
  expect_texel(t, 0, 0, {0.0f, k10, k128, 1.0f}, tol, "png");
  expect_texel(t, 1, 0, {1.0f, k64, k200, 128 / 255.0f}, tol, "png");
  expect_texel(t, 0, 1, {k128, k128, k128, 0.0f}, tol, "png");
  expect_texel(t, 1, 1, {k10, k200, k64, 1.0f}, tol, "png");
}

TEST(Texture, GreyAndRgbImagesGetOpaqueRgba) {
  std::string dir = lucent::test::temp_dir();
  const unsigned char grey[] = {128, 64};  // 2x1, one channel
  ASSERT_TRUE(stbi_write_png((dir + "/g.png").c_str(), 2, 1, 1, grey, 2));
  Scene scene;
  const lucent::Texture& g = scene.textures[load_texture(scene, dir + "/g.png")];
  expect_texel(g, 0, 0, {k128, k128, k128, 1}, 1e-6f, "grey");
  expect_texel(g, 1, 0, {k64, k64, k64, 1}, 1e-6f, "grey");
}

TEST(Texture, BmpAndTgaDecodeExactlyWithRowZeroAtTheTop) {
  std::string dir = lucent::test::temp_dir();
  // 2 wide, 3 high, RGB; each row a different colour so a flipped image would show
  const unsigned char px[] = {255, 0,  0,   255, 0,  0,     // top: red
                              0,   64, 0,   0,   64, 0,     // middle: dark green
                              10,  10, 200, 10,  10, 200};  // bottom: blue
  ASSERT_TRUE(stbi_write_bmp((dir + "/t.bmp").c_str(), 2, 3, 3, px));
  ASSERT_TRUE(stbi_write_tga((dir + "/t.tga").c_str(), 2, 3, 3, px));
  for (const char* name : {"/t.bmp", "/t.tga"}) {
    Scene scene;
    const lucent::Texture& t = scene.textures[load_texture(scene, dir + name)];
    ASSERT_EQ(t.width, 2) << name;
    ASSERT_EQ(t.height, 3) << name;
    for (int x = 0; x < 2; ++x) {
      expect_texel(t, x, 0, {1, 0, 0, 1}, 1e-6f, name);
      expect_texel(t, x, 1, {0, k64, 0, 1}, 1e-6f, name);
      expect_texel(t, x, 2, {k10, k10, k200, 1}, 1e-6f, name);
    }
  }
}

TEST(Texture, JpegDecodesSrgbToLinear) {
  // JPEG is lossy: a flat 16x16 image of one colour comes back within a couple of codes
  std::string path = lucent::test::temp_dir() + "/t.jpg";
  std::vector<unsigned char> px;
  for (int i = 0; i < 16 * 16; ++i) px.insert(px.end(), {200, 128, 64});
  ASSERT_TRUE(stbi_write_jpg(path.c_str(), 16, 16, 3, px.data(), 100));
  Scene scene;
  const lucent::Texture& t = scene.textures[load_texture(scene, path)];
  // 2 codes of 8-bit sRGB around these values are at most 0.0095 apart in linear
  expect_texel(t, 7, 7, {k200, k128, k64, 1}, 0.0095f, "jpg");
}

TEST(Texture, HdrAndPfmStayLinear) {
  std::string dir = lucent::test::temp_dir();
  // values exactly representable in RGBE (shared exponent 2^2, 8-bit mantissas): no rounding
  const float hdr[] = {3.5f, 0.25f, 1.0f, 0.5f, 2.0f, 0.125f};  // 2x1 RGB
  ASSERT_TRUE(stbi_write_hdr((dir + "/t.hdr").c_str(), 2, 1, 3, hdr));
  lucent::Image img{2, 1, {3.5f, 0.25f, 1.0f, 0.5f, 2.0f, 0.125f}};
  lucent::write_image(dir + "/t.pfm", img);
  for (const char* name : {"/t.hdr", "/t.pfm"}) {
    Scene scene;
    const lucent::Texture& t = scene.textures[load_texture(scene, dir + name)];
    ASSERT_EQ(t.width, 2) << name;
    ASSERT_EQ(t.height, 1) << name;
    expect_texel(t, 0, 0, {3.5f, 0.25f, 1.0f, 1.0f}, 1e-6f, name);
    expect_texel(t, 1, 0, {0.5f, 2.0f, 0.125f, 1.0f}, 1e-6f, name);
  }
}

void write_png16(const std::string& path, int w, int h, const std::vector<std::uint16_t>& rgb) {
  std::string raw;
  for (int y = 0; y < h; ++y) {
    raw += '\0';  // filter: none
    for (int i = 0; i < w * 3; ++i) {
      std::uint16_t v = rgb[static_cast<size_t>(y) * w * 3 + i];
      raw += char(v >> 8);
      raw += char(v & 0xFF);
    }
  }
  lucent::test::write_file(path, lucent::test::png_file(w, h, 16, 2, {}, raw));  // 16-bit RGB
}

TEST(Texture, SixteenBitPngKeepsItsPrecision) {
  std::string path = lucent::test::temp_dir() + "/t16.png";
  // 1000/65535 lies between two 8-bit codes; 32896/65535 = 128/255 exactly
  write_png16(path, 2, 1, {1000, 32896, 65535, 0, 50000, 32896});
  Scene scene;
  const lucent::Texture& t = scene.textures[load_texture(scene, path)];
  ASSERT_EQ(t.width, 2);
  ASSERT_EQ(t.height, 1);
  // 1000/65535 = 0.0152590 is on the linear segment: / 12.92 = 0.0011810 (8 bits: 0.0009106 or
  // 0.0012141); 50000/65535 = 0.7629511 -> ((c + 0.055) / 1.055)^2.4 = 0.5429248
  expect_texel(t, 0, 0, {0.0011810f, k128, 1.0f, 1.0f}, 2e-7f, "16-bit png");
  expect_texel(t, 1, 0, {0.0f, 0.5429248f, k128, 1.0f}, 2e-7f, "16-bit png");
}

TEST(Texture, SamePathLoadsOnce) {
  std::string dir = lucent::test::temp_dir();
  std::filesystem::create_directories(dir + "/sub");
  const unsigned char a[] = {1, 2, 3}, b[] = {4, 5, 6};
  ASSERT_TRUE(stbi_write_png((dir + "/a.png").c_str(), 1, 1, 3, a, 3));
  ASSERT_TRUE(stbi_write_png((dir + "/b.png").c_str(), 1, 1, 3, b, 3));
  Scene scene;
  EXPECT_EQ(load_texture(scene, dir + "/a.png"), 0);
  EXPECT_EQ(load_texture(scene, dir + "/b.png"), 1);
  EXPECT_EQ(load_texture(scene, dir + "/a.png"), 0);
  EXPECT_EQ(load_texture(scene, dir + "/sub/../a.png"), 0);  // the same file, spelled otherwise
  EXPECT_EQ(load_texture(scene, dir + "/./b.png"), 1);
  EXPECT_EQ(scene.textures.size(), 2u);
}

TEST(Texture, ErrorsNameTheFile) {
  std::string dir = lucent::test::temp_dir();
  Scene scene;
  try {
    load_texture(scene, dir + "/missing.png");
    FAIL() << "no error for a missing file";
  } catch (const lucent::Error& e) {
    EXPECT_NE(std::string(e.what()).find(dir + "/missing.png"), std::string::npos) << e.what();
  }
  lucent::test::write_file(dir + "/bad.png", "this is not an image\n");
  try {
    load_texture(scene, dir + "/bad.png");
    FAIL() << "no error for a file that is not an image";
  } catch (const lucent::Error& e) {
    EXPECT_NE(std::string(e.what()).find(dir + "/bad.png"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(scene.textures.empty());
}

}  // namespace

}  // namespace test_texture
