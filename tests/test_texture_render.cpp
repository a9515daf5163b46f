// End to end: an OBJ quad with UVs and an MTL map_Kd, rendered by the kernel with the albedo
// integrator, shows the texture the right way up (uv (0,0) at the bottom-left, image row 0 at the
// top) with its sRGB values decoded to linear.
#include <gtest/gtest.h>
#include <stb/stb_image_write.h>

#include <cstdio>
#include <string>
#include <vector>

#include "lucent/lucent.hpp"
#include "support.hpp"

namespace test_texture_render {

namespace {

/// A size x size PNG of four blocks: top-left red, top-right green, bottom-left blue, bottom-right
/// grey (8-bit 128).
bool write_block_png(const std::string& path, int size) {
  const unsigned char red[] = {255, 0, 0}, green[] = {0, 255, 0}, blue[] = {0, 0, 255},
                      grey[] = {128, 128, 128};
  std::vector<unsigned char> px;
  const int half = size / 2;
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      const unsigned char* c = y < half ? (x < half ? red : green) : (x < half ? blue : grey);
      px.insert(px.end(), c, c + 3);
    }
  return stbi_write_png(path.c_str(), size, size, 3, px.data(), size * 3) != 0;
}

TEST(TextureRender, TexturedObjQuadShowsTheImageUpright) {
  std::string dir = lucent::test::temp_dir();
  // 4x4 texture of 2x2 blocks
  ASSERT_TRUE(write_block_png(dir + "/quad.png", 4));
  lucent::test::write_file(dir + "/quad.mtl", "newmtl tex\nKd 1 1 1\nmap_Kd quad.png\n");
  lucent::test::write_file(dir + "/quad.obj",
                           "mtllib quad.mtl\nv -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\n"
                           "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nusemtl tex\nf 1/1 2/2 3/3 4/4\n");
  // the quad exactly fills a 90-degree view from distance 1
  std::string json = R"({
    "camera": {"position": [0, 0, 1], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov": 90},
    "film": {"width": 32, "height": 32},
    "integrator": {"type": "albedo", "spp": 4},
    "materials": {},
    "shapes": [{"type": "mesh", "file": ")" +
                     dir + R"(/quad.obj"}]
  })";
  lucent::RenderResult r = lucent::test::render_json(json, 4);
  struct Probe {
    int x, y;
    float r, g, b;
    const char* what;
  };
  const float k128 = 0.2158605f;  // 8-bit sRGB 128 in linear
  const Probe probes[] = {{7, 7, 1, 0, 0, "top-left red"},
                          {24, 8, 0, 1, 0, "top-right green"},
                          {8, 24, 0, 0, 1, "bottom-left blue"},
                          {23, 23, k128, k128, k128, "bottom-right grey"}};
  for (const Probe& p : probes) {
    // pixels 6..10 of each quadrant see only texels of one block (bilinear between same colours)
    const float* c = r.mean.pixel(p.x, p.y);
    EXPECT_NEAR(c[0], p.r, 1e-4) << p.what;
    EXPECT_NEAR(c[1], p.g, 1e-4) << p.what;
    EXPECT_NEAR(c[2], p.b, 1e-4) << p.what;
  }
  // on the vertical middle line the filter mixes red and green half and half
  const float* mid = r.mean.pixel(16, 8);
  EXPECT_GT(mid[0], 0.05f);
  EXPECT_GT(mid[1], 0.05f);

  // the same quad with its uvs moved by whole numbers, up to 1.6e7 (exact in float, as
  // tinyobjloader reads them): lookups repeat with period 1, so the image is the same to the bit.
  // Interpolated in float at that magnitude the uvs lost their fraction (a texture rendered as
  // blocks of one texel); the host now takes each triangle's whole part off.
  for (const char* shift : {"1 -3", "10000000 10000000", "-10000000 16000000"}) {
    double su = 0, sv = 0;
    std::sscanf(shift, "%lf %lf", &su, &sv);
    std::string obj = "mtllib quad.mtl\nv -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\n";
    for (int k = 0; k < 4; ++k) {
      char vt[96];
      std::snprintf(vt, sizeof vt, "vt %.1f %.1f\n", (k == 1 || k == 2) + su, (k >= 2) + sv);
      obj += vt;
    }
    lucent::test::write_file(dir + "/quad.obj", obj + "usemtl tex\nf 1/1 2/2 3/3 4/4\n");
    lucent::RenderResult moved = lucent::test::render_json(json, 4);
    EXPECT_EQ(moved.mean.rgb, r.mean.rgb) << "uvs moved by " << shift;
  }
}

// A sphere shows its texture unmirrored, as an Earth map on a globe: the image's centre faces +z,
// its top row the north pole, and u grows to the right seen from outside. It was mirrored left to
// right (u = 0.5 + atan2(n.z, n.x) / 2 pi put u = 0.75 in front and grew to the left), in the
// kernel and the reference alike, so that their comparison could not see it. The 16x16 texture of
// 8x8 blocks (top-left red, top-right green, bottom-left blue, bottom-right grey) on a unit sphere
// seen from +z: each quadrant of the sphere's disc shows its block.
TEST(TextureRender, TexturedSphereShowsTheImageUnmirrored) {
  std::string dir = lucent::test::temp_dir();
  ASSERT_TRUE(write_block_png(dir + "/globe.png", 16));
  const std::string json = R"({
    "camera": {"position": [0, 0, 4], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov": 30},
    "film": {"width": 32, "height": 32},
    "integrator": {"type": "albedo", "spp": 4},
    "materials": {"t": {"type": "diffuse", "albedo": {"texture": ")" +
                           dir + R"(/globe.png"}}},
    "shapes": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "t"}]
  })";
  lucent::test::write_file(dir + "/globe.json", json);
  const lucent::RenderResult kernel = lucent::test::render_json(json, 4);
  lucent::ReferenceOptions ro;
  ro.spp = 4;
  const lucent::RenderResult reference =
      lucent::render_reference(lucent::load_scene(dir + "/globe.json"), ro);
  // pixels (8, 8) and the like lie at n = (-+0.40, +-0.40, 0.83): u = 0.5 -+ 0.07, v = 0.5 +- 0.13,
  // texel columns 6.4 (red) or 8.6 (green), rows 5.4 or 9.6: texels of one block each (the old u
  // read column 14.1 in front of the camera, green, whichever side)
  struct Probe {
    int x, y, channel;
    const char* what;
  };
  const Probe probes[] = {{8, 8, 0, "top-left red"},
                          {23, 8, 1, "top-right green"},
                          {8, 23, 2, "bottom-left blue"},
                          {23, 23, -1, "bottom-right grey"}};
  for (const lucent::RenderResult* r : {&kernel, &reference})
    for (const Probe& p : probes) {
      const float* c = r->mean.pixel(p.x, p.y);
      SCOPED_TRACE(std::string(p.what) + (r == &kernel ? " (kernel)" : " (reference)"));
      if (p.channel < 0) {
        EXPECT_NEAR(c[0], 0.2158605f, 1e-3);
        EXPECT_NEAR(c[1], 0.2158605f, 1e-3);
        EXPECT_NEAR(c[2], 0.2158605f, 1e-3);
      } else {
        for (int k = 0; k < 3; ++k) EXPECT_NEAR(c[k], k == p.channel ? 1.0f : 0.0f, 1e-3) << k;
      }
    }
}

}  // namespace

}  // namespace test_texture_render
