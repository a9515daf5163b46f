// Image files that lie (src/image/image_probe.cpp): a header claiming more pixels than the limit
// or than the file can hold is refused with one line before anything is allocated; truncated
// files are refused instead of decoded with zeros; the corrupt Radiance HDR that hung stb_image
// is refused; formats lucent does not read are named. Images of one pixel, one row and one column
// decode exactly, and an environment map of one pixel or one row lights a scene like the constant
// sky it is.
#include <gtest/gtest.h>
#include <stb/stb_image_write.h>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <sstream>
#include <string>
#include <vector>

#include "image/image_probe.hpp"
#include "lucent/compare.hpp"
#include "lucent/error.hpp"
#include "render/resources.hpp"
#include "scene/loaders.hpp"
#include "support.hpp"

namespace test_image_limits {

namespace {

using lucent::scene_detail::decode_texture;

std::string le16(unsigned v) { return {char(v & 0xFF), char(v >> 8)}; }
std::string le32(std::uint32_t v) { return le16(v & 0xFFFF) + le16(v >> 16); }
std::string be16(unsigned v) { return {char(v >> 8), char(v & 0xFF)}; }
std::string be32(std::uint32_t v) { return be16(v >> 16) + be16(v & 0xFFFF); }

/// The error decoding `bytes` as a texture named "t", without the "t: " prefix ("" if none).
std::string texture_error(const std::string& bytes) {
  try {
    decode_texture(reinterpret_cast<const unsigned char*>(bytes.data()), bytes.size(), "t");
  } catch (const lucent::Error& e) {
    std::string m = e.what();
    return m.rfind("t: ", 0) == 0 ? m.substr(3) : m;
  }
  return "";
}

lucent::Texture texture(const std::string& bytes) {
  return decode_texture(reinterpret_cast<const unsigned char*>(bytes.data()), bytes.size(), "t");
}

void append(void* ctx, void* data, int size) {
  static_cast<std::string*>(ctx)->append(static_cast<const char*>(data), size);
}

std::string png(int w, int h, const std::vector<unsigned char>& rgb) {
  std::string out;
  stbi_write_png_to_func(append, &out, w, h, 3, rgb.data(), w * 3);
  return out;
}

std::string bmp(int w, int h, const std::vector<unsigned char>& rgb) {
  std::string out;
  stbi_write_bmp_to_func(append, &out, w, h, 3, rgb.data());
  return out;
}

std::string tga(int w, int h, const std::vector<unsigned char>& rgb, bool rle) {
  std::string out;
  stbi_write_tga_with_rle = rle ? 1 : 0;
  stbi_write_tga_to_func(append, &out, w, h, 3, rgb.data());
  return out;
}

std::string hdr_header(int w, int h) {
  return "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y " + std::to_string(h) + " +X " +
         std::to_string(w) + "\n";
}

std::string pfm(int w, int h, std::size_t floats) {
  return "PF\n" + std::to_string(w) + " " + std::to_string(h) + "\n-1.0\n" +
         std::string(4 * floats, '\0');
}

TEST(ImageLimits, LyingSizesAreRefusedBeforeAllocating) {
  auto t0 = std::chrono::steady_clock::now();
  // 65535 x 65535 claimed by a tiny file, in every format that states a size
  std::string ihdr = be32(65535) + be32(65535) + std::string("\x08\x02\x00\x00\x00", 5);
  std::string lying_png = std::string("\x89PNG\r\n\x1a\n", 8) + be32(13) + "IHDR" + ihdr + be32(0);
  EXPECT_EQ(texture_error(lying_png),
            "PNG header claims 65535x65535 pixels, more than the limit of 67108864 pixels "
            "(corrupt, or too large)");
  std::string lying_bmp = "BM" + le32(54) + le32(0) + le32(54) + le32(40) + le32(65535) +
                          le32(65535) + le16(1) + le16(24) + std::string(24, '\0');
  EXPECT_EQ(texture_error(lying_bmp),
            "BMP header claims 65535x65535 pixels, more than the limit of 67108864 pixels "
            "(corrupt, or too large)");
  EXPECT_EQ(texture_error(hdr_header(65535, 65535) + "\x02\x02\xff\xff"),
            "Radiance HDR header claims 65535x65535 pixels, more than the limit of 67108864 "
            "pixels (corrupt, or too large)");
  EXPECT_EQ(texture_error(pfm(65535, 65535, 3)),
            "PFM header claims 65535x65535 pixels, more than the limit of 67108864 pixels "
            "(corrupt, or too large)");
  std::string tga_header =
      std::string("\0\0\2", 3) + std::string(9, '\0') + le16(65535) + le16(65535) + "\x18\x00";
  EXPECT_EQ(texture_error(tga_header + "abc"),
            "TGA header claims 65535x65535 pixels, more than the limit of 67108864 pixels "
            "(corrupt, or too large)");
  std::string jpeg = std::string("\xFF\xD8\xFF\xC0", 4) + be16(11) + "\x08" + be16(65535) +
                     be16(65535) + "\x01\x01\x11\x00" + "\xFF\xD9";
  EXPECT_EQ(texture_error(jpeg),
            "JPEG header claims 65535x65535 pixels, more than the limit of 67108864 pixels "
            "(corrupt, or too large)");
  // within the limit, but more than the file can hold
  std::string ihdr2 = be32(8000) + be32(8000) + std::string("\x08\x02\x00\x00\x00", 5);
  std::string small_png = std::string("\x89PNG\r\n\x1a\n", 8) + be32(13) + "IHDR" + ihdr2 +
                          be32(0) + be32(10) + "IDAT" + std::string(10, 'x') + be32(0) + be32(0) +
                          "IEND" + be32(0);
  EXPECT_EQ(texture_error(small_png),
            "PNG header claims 8000x8000 pixels (192008000 bytes), more than 10 bytes of deflate "
            "data can hold (truncated or corrupt)");
  EXPECT_EQ(texture_error(pfm(4000, 4000, 3)),
            "PFM file is truncated: its 4000x4000 header needs 192000018 bytes of header and "
            "pixels, the file has 30");
  // every refusal above took no time and no memory worth measuring
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 1.0);
}

// A JPEG claiming more pixels than its bytes can code (each 8x8 block takes at least two bits in
// a baseline file: 256 pixels a byte), and one whose component names a quantisation table that no
// DQT defines, are refused; stb_image decoded the first to a texture of stripes (a 96 KB file
// claiming 8192x8192 took 2 GB) and the second from memory it never set. A side beyond
// stb_image's 2^24 is named (it said "too large").
TEST(ImageLimits, JpegsThatCannotHoldTheirPixelsOrTablesAreRefused) {
  std::vector<unsigned char> noise(96 * 96 * 3);
  std::uint32_t state = 12345;
  for (unsigned char& v : noise)
    v = static_cast<unsigned char>((state = state * 1664525u + 1013904223u) >> 24);
  std::string jpeg;
  ASSERT_TRUE(stbi_write_jpg_to_func(append, &jpeg, 96, 96, 3, noise.data(), 100));
  ASSERT_EQ(texture_error(jpeg), "");
  const std::size_t sof = jpeg.find("\xFF\xC0"), sos = jpeg.find("\xFF\xDA");
  ASSERT_NE(sof, std::string::npos);
  ASSERT_NE(sos, std::string::npos);
  // 600 pixels a byte: more than a baseline file holds, less than the 1024 allowed before
  const auto side = static_cast<unsigned>(std::sqrt(600.0 * jpeg.size()));
  std::string lying = jpeg;
  lying.replace(sof + 5, 4, be16(side) + be16(side));
  EXPECT_EQ(texture_error(lying), "JPEG header claims " + std::to_string(side) + "x" +
                                      std::to_string(side) + " pixels, more than " +
                                      std::to_string(jpeg.size()) + " bytes can hold (corrupt)");
  std::string no_table = jpeg;
  ASSERT_EQ(no_table[sof + 9], 3) << "three components";
  no_table[sof + 12] = 3;  // the first component's quantisation table
  EXPECT_EQ(texture_error(no_table),
            "JPEG scan at byte " + std::to_string(sos) +
                " uses quantisation table 3, which no DQT segment before it defines (corrupt)");
  std::string ihdr = be32((1u << 24) + 1) + be32(1) + std::string("\x08\x02\x00\x00\x00", 5);
  EXPECT_EQ(texture_error(std::string("\x89PNG\r\n\x1a\n", 8) + be32(13) + "IHDR" + ihdr + be32(0)),
            "PNG header claims 16777217x1 pixels: lucent reads PNG files of at most 16777216 "
            "pixels a side (PFM and OpenEXR files are not limited so)");
}

TEST(ImageLimits, TruncatedFilesAreRefused) {
  std::vector<unsigned char> px(16 * 8 * 3);
  for (size_t i = 0; i < px.size(); ++i) px[i] = static_cast<unsigned char>(i * 7);
  std::string b = bmp(16, 8, px);
  ASSERT_EQ(texture_error(b), "");
  // stb_image decodes a truncated BMP with black rows: the campaign's "accepted silently"
  EXPECT_EQ(texture_error(b.substr(0, b.size() - 100)),
            "BMP file is truncated: its 16x8 header needs 438 bytes of header and pixel rows, the "
            "file has 338");
  std::string t = tga(16, 8, px, false);
  ASSERT_EQ(texture_error(t), "");
  EXPECT_NE(texture_error(t.substr(0, t.size() - 40)).find("TGA file is truncated"),
            std::string::npos);
  std::string tr = tga(16, 8, px, true);
  ASSERT_EQ(texture_error(tr), "");
  EXPECT_NE(texture_error(tr.substr(0, tr.size() / 2)).find("TGA file is truncated"),
            std::string::npos);
  std::string p = png(16, 8, px);
  ASSERT_EQ(texture_error(p), "");
  EXPECT_EQ(texture_error(p.substr(0, p.size() - 12)), "PNG file is truncated: no IEND chunk");
  std::string f = pfm(3, 2, 18);
  ASSERT_EQ(texture_error(f), "");
  EXPECT_EQ(texture_error(f.substr(0, f.size() - 1)),
            "PFM file is truncated: its 3x2 header needs 84 bytes of header and pixels, the file "
            "has 83");
  std::string jpg;
  stbi_write_jpg_to_func(append, &jpg, 16, 8, 3, px.data(), 90);
  ASSERT_EQ(texture_error(jpg), "");
  EXPECT_EQ(texture_error(jpg.substr(0, jpg.size() - 20)),
            "JPEG file is truncated: no end-of-image marker");
}

// The PFM header ends with the scale's line, whatever precedes its newline: "\r\n" (Windows) or a
// space before it used to end the header one byte early, and the floats were read shifted by a
// byte (values like -8e-44, exit 0). Bytes beyond the pixels are refused: they are what a
// misread header end leaves.
TEST(ImageLimits, PfmHeaderEndsAtTheScalesNewline) {
  std::string floats;
  for (int i = 0; i < 6; ++i) {
    float v = 0.25f * float(i + 1);
    floats.append(reinterpret_cast<const char*>(&v), 4);
  }
  for (const char* end : {"\n", "\r\n", " \n", "\t\r\n", " "}) {
    lucent::Texture t = texture("PF\n2 1\n-1.0" + std::string(end) + floats);
    ASSERT_EQ(t.width, 2);
    for (int i = 0; i < 6; ++i)
      EXPECT_EQ(t.rgba[(i / 3) * 4 + i % 3], 0.25f * float(i + 1))
          << "header end '" << end << "', value " << i;
  }
  EXPECT_EQ(texture_error("PF\r\n2 1\r\n-1.0\r\n" + floats), "");
  EXPECT_EQ(texture_error("PF\n2 1\n-1.0\n" + floats + "\n"),
            "PFM file has 1 bytes after its 2x1 pixels (a header it misreads, or a corrupt file)");
}

// A positive scale marks big-endian floats (the format's own byte order flag): such files, which
// other tools write, were refused ("big-endian PFM files are not supported"); they read as their
// little-endian twins, grey and colour, whatever the scale's magnitude.
TEST(ImageLimits, BigEndianPfmReadsAsItsLittleEndianTwin) {
  for (int channels : {1, 3}) {
    std::string le, be;
    for (int i = 0; i < 2 * channels; ++i) {
      float v = 0.25f * float(i + 1) + 1e-3f;
      char b[4];
      std::memcpy(b, &v, 4);
      le.append(b, 4);
      be.append({b[3], b[2], b[1], b[0]});
    }
    const std::string magic = channels == 3 ? "PF\n" : "Pf\n";
    const lucent::Texture a = texture(magic + "2 1\n-1.0\n" + le);
    for (const char* scale : {"1.0", "2.5"}) {
      const lucent::Texture b = texture(magic + "2 1\n" + scale + "\n" + be);
      ASSERT_EQ(b.width, 2);
      EXPECT_EQ(b.rgba, a.rgba) << channels << " channel(s), scale " << scale;
    }
    EXPECT_EQ(a.rgba[4 * 1 + 0], 0.25f * float(channels + 1) + 1e-3f);  // pixel 1, R
  }
}

// A float image used as a texture or an environment map may not hold a negative, NaN or infinite
// value: they rendered with exit 0 (negative pixels, black in a PNG; dropped non-finite samples),
// where SceneBuilder::add_texture refuses the same texels.
TEST(ImageLimits, FloatTexturesMustBeFiniteAndNonNegative) {
  for (float bad : {-5.0f, std::nanf(""), INFINITY}) {
    std::vector<float> px(2 * 2 * 3, 0.5f);
    px[4] = bad;  // the file's first row is the image's bottom row: pixel (1, 1), channel G
    std::string f =
        "PF\n2 2\n-1.0\n" + std::string(reinterpret_cast<const char*>(px.data()), px.size() * 4);
    std::ostringstream v;
    v << bad;
    EXPECT_EQ(texture_error(f), "pixel (1, 1) channel G is " + v.str() +
                                    "; a texture's values must be finite and >= 0");
  }
  std::vector<float> zero(2 * 2 * 3, 0.0f);
  EXPECT_EQ(texture_error("PF\n2 2\n-1.0\n" +
                          std::string(reinterpret_cast<const char*>(zero.data()), zero.size() * 4)),
            "");
}

// A texture file is checked against the host's memory limit before it is decoded (the limit
// lowered here as the other memory tests lower it; the texture check read the host's memory
// directly and ignored the override).
TEST(ImageLimits, TexturesCheckTheHostMemoryLimitBeforeDecoding) {
  const std::string dir = lucent::test::temp_dir();
  lucent::write_image(dir + "/t.pfm", lucent::Image{64, 64, std::vector<float>(64 * 64 * 3, 0.5f)});
  lucent::render_detail::DeviceLimits lim;
  lim.host_mem = 32 << 10;  // 32 KiB: less than 64 x 64 RGBA floats (64 KiB)
  lucent::render_detail::ScopedLimitOverride o(lim);
  lucent::Scene scene;
  const std::string msg =
      lucent::test::error_of([&] { lucent::scene_detail::load_texture(scene, dir + "/t.pfm"); });
  EXPECT_EQ(msg.rfind(dir + "/t.pfm: with this 64x64 texture (64.0 KiB) the scene's 1 textures "
                            "need 64.0 KiB, more than the limit of 32.0 KiB (80% of ",
                      0),
            0u)
      << msg;
}

// stb_image loops forever on a run-length scanline whose run is 0, which is what it reads past
// the end of a truncated file: the corrupt environment map that hung lucent.
TEST(ImageLimits, CorruptRadianceHdrIsRefusedNotLoopedOn) {
  std::vector<float> rgb(16 * 2 * 3, 0.5f);
  std::string good;
  stbi_write_hdr_to_func(append, &good, 16, 2, 3, rgb.data());
  ASSERT_EQ(texture_error(good), "");
  auto t0 = std::chrono::steady_clock::now();
  EXPECT_NE(texture_error(good.substr(0, good.size() - 5)).find("Radiance HDR file is truncated"),
            std::string::npos);
  std::string zero_run =
      hdr_header(16, 1) + std::string("\x02\x02\x00\x10", 4) + std::string(64, '\0');
  EXPECT_EQ(texture_error(zero_run),
            "Radiance HDR scanline 0 has a bad run length at byte 50 (corrupt)");
  std::string long_run = hdr_header(16, 1) + std::string("\x02\x02\x00\x10", 4) + "\xff\x01";
  EXPECT_EQ(texture_error(long_run),
            "Radiance HDR scanline 0 has a bad run length at byte 50 (corrupt)");
  EXPECT_EQ(texture_error(hdr_header(16, 1) + std::string("\x02\x02\x00\x11", 4)),
            "Radiance HDR scanline 0 has length 17, the header says 16");
  EXPECT_EQ(texture_error("#?RADIANCE\nFORMAT=32-bit_rle_xyze\n\n-Y 1 +X 1\n1234"),
            "Radiance HDR file is not in the 32-bit_rle_rgbe format");
  EXPECT_EQ(texture_error("#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n+Y 1 +X 1\n1234"),
            "Radiance HDR resolution line '+Y 1 +X 1' is not -Y h +X w");
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 1.0);
}

TEST(ImageLimits, UnsupportedAndUnknownFormatsAreNamed) {
  EXPECT_EQ(texture_error("GIF89a\x01\x00\x01\x00"),
            "GIF images are not supported (lucent reads PNG, JPEG, BMP, TGA, Radiance HDR, PFM "
            "and OpenEXR)");
  EXPECT_EQ(texture_error("P6\n1 1\n255\nabc"),
            "PNM images are not supported (lucent reads PNG, JPEG, BMP, TGA, Radiance HDR, PFM "
            "and OpenEXR)");
  EXPECT_EQ(texture_error("this is not an image at all"),
            "unknown image format (lucent reads PNG, JPEG, BMP, TGA, Radiance HDR, PFM and "
            "OpenEXR)");
  EXPECT_EQ(texture_error(""), "empty image file");
  // a BMP with run-length compression, which stb_image does not read
  std::string rle_bmp = "BM" + le32(70) + le32(0) + le32(54) + le32(40) + le32(2) + le32(2) +
                        le16(1) + le16(8) + le32(1) + std::string(20, '\0') + std::string(16, '\0');
  EXPECT_EQ(texture_error(rle_bmp),
            "BMP compression 1 is not supported (uncompressed and bit-field BMPs are)");
}

// One pixel, one row, one column: every format decodes them exactly (no resampling path divides
// by width - 1 or height - 1).
TEST(ImageLimits, OnePixelRowAndColumnImagesDecode) {
  struct Size {
    int w, h;
  } sizes[] = {{1, 1}, {5, 1}, {1, 5}};
  for (Size s : sizes) {
    std::vector<unsigned char> px(static_cast<size_t>(s.w) * s.h * 3);
    for (size_t i = 0; i < px.size(); ++i) px[i] = static_cast<unsigned char>(40 + 30 * i);
    for (const std::string& bytes :
         {png(s.w, s.h, px), bmp(s.w, s.h, px), tga(s.w, s.h, px, true)}) {
      lucent::Texture t = texture(bytes);
      ASSERT_EQ(t.width, s.w);
      ASSERT_EQ(t.height, s.h);
      for (size_t i = 0; i < px.size(); ++i)
        EXPECT_NEAR(t.rgba[i / 3 * 4 + i % 3], lucent::image_detail::srgb_to_linear(px[i] / 255.0),
                    1e-6);
    }
    std::vector<float> f(px.begin(), px.end());
    for (float& v : f) v /= 64.0f;  // exact in RGBE: multiples of 1/64 below 4
    std::string hdr;
    stbi_write_hdr_to_func(append, &hdr, s.w, s.h, 3, f.data());
    lucent::Image img{s.w, s.h, f};
    std::string dir = lucent::test::temp_dir();
    lucent::write_image(dir + "/i.pfm", img);
    lucent::write_image(dir + "/i.exr", img);
    for (const std::string& path : {dir + "/i.pfm", dir + "/i.exr"}) {
      lucent::Image back = lucent::read_image(path);
      EXPECT_EQ(back.rgb, f) << path;
    }
    lucent::Texture t = texture(hdr);
    ASSERT_EQ(t.width, s.w);
    ASSERT_EQ(t.height, s.h);
    for (size_t i = 0; i < f.size(); ++i) EXPECT_NEAR(t.rgba[i / 3 * 4 + i % 3], f[i], f[i] / 64);
  }
}

// An 8-bit BMP of `w` x 1 pixels `indices` into `palette` (entries B, G, R, 0), written by hand
// (stb_image_write writes no palettes).
std::string palette_bmp(const std::string& palette, const std::string& indices) {
  std::string row = indices + std::string((4 - indices.size() % 4) % 4, '\0');
  const std::uint32_t offset = 14 + 40 + static_cast<std::uint32_t>(palette.size());
  return "BM" + le32(offset + static_cast<std::uint32_t>(row.size())) + le32(0) + le32(offset) +
         le32(40) + le32(static_cast<std::uint32_t>(indices.size())) + le32(1) + le16(1) + le16(8) +
         le32(0) + le32(static_cast<std::uint32_t>(row.size())) + le32(2835) + le32(2835) +
         le32(static_cast<std::uint32_t>(palette.size() / 4)) + le32(0) + palette + row;
}

// A palette shorter than its indices can name (2 entries for 8-bit indices) is valid, and decodes
// to its colours; a pixel that names an entry past it is refused. stb_image read such an entry
// from memory it never set: the texture, and renders with it, changed from run to run, and
// `lucent compare` of such a file with itself failed (the image output campaign). The palettes
// hold black and (1, 0, 0), the first colours that the padding could have taken.
TEST(ImageLimits, PaletteIndicesPastThePaletteAreRefused) {
  const std::string rgb = std::string("\0\0\0\x01\0\0", 6);
  auto png8 = [&](int depth, const std::string& palette, const std::string& packed_row) {
    return lucent::test::png_file(static_cast<int>(depth == 8 ? packed_row.size() : 8), 1, depth, 3,
                                  {{"PLTE", palette}}, '\0' + packed_row);
  };
  const float k1 = static_cast<float>(lucent::image_detail::srgb_to_linear(1 / 255.0));
  lucent::Texture t = texture(png8(8, rgb + "\xC8\x64\x32", std::string("\0\x01\x02\x01", 4)));
  ASSERT_EQ(t.width, 4);
  const float expected[4] = {
      0, k1, static_cast<float>(lucent::image_detail::srgb_to_linear(200 / 255.0)), k1};
  for (int x = 0; x < 4; ++x) EXPECT_FLOAT_EQ(t.rgba[4 * x], expected[x]) << x;
  EXPECT_EQ(texture_error(png8(8, rgb, std::string("\0\x01\0\x05", 4))),
            "PNG pixel (3, 0) names a colour past the 2 entries of its palette (corrupt)");
  // 1-bit indices and a palette of one entry: the eighth pixel names entry 1
  EXPECT_EQ(texture_error(png8(1, rgb.substr(0, 3), "\x01")),
            "PNG pixel (7, 0) names a colour past the 1 entries of its palette (corrupt)");
  const std::string bgr0 = std::string("\0\0\0\0\0\0\x01\0", 8);
  t = texture(palette_bmp(bgr0, std::string("\x01\0\x01", 3)));
  ASSERT_EQ(t.width, 3);
  EXPECT_FLOAT_EQ(t.rgba[0], k1);
  EXPECT_FLOAT_EQ(t.rgba[4], 0);
  EXPECT_EQ(texture_error(palette_bmp(bgr0, std::string("\x01\xC8\0", 3))),
            "BMP pixel (1, 0) names a colour past the 2 entries of its palette (corrupt)");
}

// An environment map of one pixel, or of one row of equal pixels, is a constant sky: a diffuse
// sphere under it renders like under {"radiance": ...} (z-test of lucent compare). A valid
// one-pixel map hung the renderer in the bad-input campaign.
TEST(ImageLimits, OnePixelAndOneRowEnvironmentMapsAreConstantSkies) {
  std::string dir = lucent::test::temp_dir();
  lucent::write_image(dir + "/one.pfm", lucent::Image{1, 1, {0.6f, 0.5f, 0.4f}});
  lucent::Image row{7, 1, {}};
  for (int i = 0; i < 7; ++i) row.rgb.insert(row.rgb.end(), {0.6f, 0.5f, 0.4f});
  lucent::write_image(dir + "/row.pfm", row);
  auto scene = [&](const std::string& light) {
    return R"({"camera": {"position": [0, 0, 4], "look_at": [0, 0, 0], "fov": 40},
      "film": {"width": 12, "height": 12}, "integrator": {"type": "path", "max_depth": 3},
      "materials": {"m": {"type": "diffuse", "albedo": [0.7, 0.7, 0.7]}},
      "shapes": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "m"}],
      "lights": [)" +
           light + "]}";
  };
  auto t0 = std::chrono::steady_clock::now();
  lucent::RenderResult constant = lucent::test::render_json(
      scene(R"({"type": "environment", "radiance": [0.6, 0.5, 0.4]})"), 64);
  for (const char* map : {"one.pfm", "row.pfm"}) {
    lucent::Scene s = lucent::parse_scene(
        scene(std::string(R"({"type": "environment", "file": ")") + map + "\"}"),
        dir + "/scene.json");
    lucent::RenderOptions opt;
    opt.spp = 64;
    lucent::RenderResult r = lucent::render(s, opt);
    EXPECT_EQ(r.nonfinite, 0u) << map;
    lucent::CompareResult c = lucent::compare_images(r, constant);
    EXPECT_TRUE(c.passed) << map << "\n" << c.summary();
  }
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 20.0);
}

}  // namespace

}  // namespace test_image_limits
