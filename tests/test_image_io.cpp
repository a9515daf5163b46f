// Image outputs: the 8-bit display encoding (sRGB, gamma, exposure, tone maps) against published
// values, and round trips through PNG, PFM and EXR.
#include <gtest/gtest.h>

#include <cmath>

#include "support.hpp"

namespace {

using lucent::DisplaySettings;
using lucent::encode_display;

TEST(ImageIo, SrgbEncodingKnownValues) {
  DisplaySettings d;  // sRGB, no exposure, clamp
  EXPECT_EQ(encode_display(0.0, d), 0);
  EXPECT_EQ(encode_display(1.0, d), 255);
  EXPECT_EQ(encode_display(7.0, d), 255);      // clamped
  EXPECT_EQ(encode_display(-1.0, d), 0);
  EXPECT_EQ(encode_display(0.5, d), 188);      // sRGB(0.5) = 0.7354
  EXPECT_EQ(encode_display(0.18, d), 118);     // middle grey: 0.4614
  EXPECT_EQ(encode_display(0.002, d), 7);      // linear segment: 12.92 * 0.002 = 0.0258
  EXPECT_EQ(encode_display(NAN, d), 0);
}

TEST(ImageIo, GammaExposureAndToneMaps) {
  DisplaySettings g;
  g.transfer = lucent::Transfer::Gamma;
  g.gamma = 2.2;
  EXPECT_EQ(encode_display(0.5, g), 186);      // 0.5^(1/2.2) = 0.7297
  DisplaySettings lin;
  lin.transfer = lucent::Transfer::Linear;
  EXPECT_EQ(encode_display(0.5, lin), 128);    // 127.5 rounds up
  DisplaySettings e;
  e.exposure = 1;                              // one stop: 0.25 -> 0.5
  EXPECT_EQ(encode_display(0.25, e), 188);
  e.exposure = -2;                             // 2 -> 0.5
  EXPECT_EQ(encode_display(2.0, e), 188);
  DisplaySettings r;
  r.tonemap = lucent::ToneMap::Reinhard;       // v / (1 + v): 1 -> 0.5
  EXPECT_EQ(encode_display(1.0, r), 188);
  EXPECT_EQ(encode_display(20.0, r), 250);     // 20/21 = 0.952: compressed, not clipped
  DisplaySettings a;
  a.tonemap = lucent::ToneMap::Aces;           // Narkowicz 2015: 1 -> 2.54 / 3.16 = 0.8038
  EXPECT_EQ(encode_display(1.0, a), 232);      // sRGB(0.8038) = 0.9084
  EXPECT_EQ(encode_display(100.0, a), 255);
}

lucent::Image gradient(int w, int h) {
  lucent::Image img{w, h, std::vector<float>(static_cast<size_t>(w) * h * 3)};
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < 3; ++c) img.pixel(x, y)[c] = float((x + 1) * (c + 1)) / float(w * 3) + 0.01f * y;
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
    for (size_t i = 0; i < img.rgb.size(); ++i) ASSERT_EQ(back.rgb[i], img.rgb[i]) << ext << " at " << i;
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

}  // namespace
