// End to end: an OBJ quad with UVs and an MTL map_Kd, rendered by the kernel with the albedo
// integrator, shows the texture the right way up (uv (0,0) at the bottom-left, image row 0 at the
// top) with its sRGB values decoded to linear.
#include <gtest/gtest.h>
#include <stb/stb_image_write.h>

#include <string>
#include <vector>

#include "lucent/lucent.hpp"
#include "support.hpp"

namespace {

TEST(TextureRender, TexturedObjQuadShowsTheImageUpright) {
  std::string dir = lucent::test::temp_dir();
  // 4x4 texture of 2x2 blocks: top-left red, top-right green, bottom-left blue, bottom-right grey
  const unsigned char red[] = {255, 0, 0}, green[] = {0, 255, 0}, blue[] = {0, 0, 255},
                      grey[] = {128, 128, 128};
  std::vector<unsigned char> px;
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 4; ++x) {
      const unsigned char* c = y < 2 ? (x < 2 ? red : green) : (x < 2 ? blue : grey);
      px.insert(px.end(), c, c + 3);
    }
  ASSERT_TRUE(stbi_write_png((dir + "/quad.png").c_str(), 4, 4, 3, px.data(), 12));
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
}

}  // namespace
