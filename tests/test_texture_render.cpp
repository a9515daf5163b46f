// End to end: an OBJ quad with UVs and an MTL map_Kd, rendered by the kernel with the albedo
// integrator, shows the texture the right way up (uv (0,0) at the bottom-left, image row 0 at the
// top) with its sRGB values decoded to linear.
#include <gtest/gtest.h>
#include <stb/stb_image_write.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
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

/// The kernel's and the reference's renders of a JSON scene at spp samples per pixel (the scene
/// written as dir/name first: the reference loads it from there, resolving its texture paths).
struct KernelAndReference {
  lucent::RenderResult kernel, reference;
};
KernelAndReference render_both(const std::string& dir, const std::string& name,
                               const std::string& json, int spp) {
  lucent::test::write_file(dir + "/" + name, json);
  lucent::ReferenceOptions ro;
  ro.spp = spp;
  return {lucent::test::render_json(json, spp),
          lucent::render_reference(lucent::load_scene(dir + "/" + name), ro)};
}

/// The albedo of three quads (`shapes`, with their `materials`) that exactly fill a 90-degree
/// (vertical) view of aspect 3 from distance 1, on a 96x32 film (`film_extra`: more film keys).
std::string three_quads_scene(const std::string& materials, const std::string& shapes,
                              const std::string& film_extra, int spp) {
  return R"({
    "camera": {"position": [0, 0, 1], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov": 90},
    "film": {"width": 96, "height": 32)" +
         film_extra + R"(},
    "integrator": {"type": "albedo", "spp": )" +
         std::to_string(spp) + R"(},
    "materials": {)" +
         materials +
         R"(},
    "shapes": [)" +
         shapes + R"(]})";
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
  const KernelAndReference both = render_both(dir, "globe.json", json, 4);
  const lucent::RenderResult &kernel = both.kernel, &reference = both.reference;
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

// A texture's mapping (docs/rendering-model.md, "Textures"), end to end: the block texture on
// three quads side by side, each mapping it at uv * scale + offset (beyond [0, 1] over most of
// the quad) with its wrap modes: clamp, mirror, and repeat in u with clamp in v under a negative
// v scale. Every pixel whose samples all read texels of one block (the closed form: the mapped
// coordinate folded into [0, 1] by the mode, half a texel from a block's edge, and for repeat
// from the image's edge, whose texels mix with the far side) shows that block's colour, in the
// kernel and in the reference.
TEST(TextureRender, WrapModesScalesAndOffsetsOnQuads) {
  std::string dir = lucent::test::temp_dir();
  ASSERT_TRUE(write_block_png(dir + "/blocks.png", 4));
  const std::string png = dir + "/blocks.png";
  struct Quad {
    const char* wrap;  // the JSON
    lucent::TextureWrap wu, wv;
    double su, sv, ou, ov;
  };
  using W = lucent::TextureWrap;
  // (the mapped coordinates span [-1, 2] in both axes, [0.25, 2.75] in the third quad's u)
  const Quad quads[] = {{R"("clamp")", W::Clamp, W::Clamp, 3, 3, -4, 2},
                        {R"("mirror")", W::Mirror, W::Mirror, 3, 3, -4, 2},
                        {R"(["repeat", "clamp"])", W::Repeat, W::Clamp, 2.5, -3, -2.25, -1}};
  std::string materials, shapes;
  for (int k = 0; k < 3; ++k) {
    const Quad& q = quads[k];
    char m[512], sh[512];
    std::snprintf(m, sizeof m,
                  R"(%s"q%d": {"type": "diffuse", "albedo": {"texture": "%s", "wrap": %s,
                     "uv_scale": [%g, %g], "uv_offset": [%g, %g]}})",
                  k ? ", " : "", k, png.c_str(), q.wrap, q.su, q.sv, q.ou, q.ov);
    const double x0 = -3 + 2 * k;
    std::snprintf(sh, sizeof sh,
                  R"(%s{"type": "triangles", "material": "q%d",
                     "positions": [[%g, -1, 0], [%g, -1, 0], [%g, 1, 0], [%g, 1, 0]],
                     "uvs": [[1, -1], [2, -1], [2, 0], [1, 0]], "indices": [0, 1, 2, 0, 2, 3]})",
                  k ? ", " : "", k, x0, x0 + 2, x0 + 2, x0);
    materials += m;
    shapes += sh;
  }
  // the quads exactly fill a 90-degree (vertical) view of aspect 3 from distance 1: pixel (px,
  // py) sees quad px / 32 over u in 1 + [px % 32, px % 32 + 1] / 32, v in -1 + [31 - py, 32 - py]
  // / 32 (uvs moved by whole numbers: the host maps a triangle's uvs, then takes whole periods
  // of its wrap modes off them, 2 for the mirror, none for a clamp)
  const std::string json = three_quads_scene(materials, shapes, "", 4);
  const KernelAndReference both = render_both(dir, "quads.json", json, 4);
  const lucent::RenderResult &kernel = both.kernel, &reference = both.reference;

  // the mapped coordinate folded into [0, 1], where the 4-texel image's blocks meet at 0.5
  auto fold = [](double t, W w) {
    if (w == W::Clamp) return std::clamp(t, 0.0, 1.0);
    if (w == W::Mirror) {
      const double m = t - 2 * std::floor(t / 2);
      return m <= 1 ? m : 2 - m;
    }
    return t - std::floor(t);
  };
  // the block (0: left or bottom, 1: right or top) every sample of [a, b] reads, or -1
  auto block = [&](double a, double b, double scale, double offset, W w) {
    int seen = -1;
    for (int i = 0; i <= 16; ++i) {
      const double f = fold((a + (b - a) * i / 16) * scale + offset, w);
      if (std::abs(f - 0.5) < 0.13) return -1;  // bilinear within half a texel (0.125)
      if (w == W::Repeat && (f < 0.13 || f > 0.87)) return -1;
      const int side = f > 0.5;
      if (seen >= 0 && side != seen) return -1;
      seen = side;
    }
    return seen;
  };
  const float k128 = 0.2158605f;
  const float colour[2][2][3] = {{{0, 0, 1}, {k128, k128, k128}},  // bottom: blue, grey
                                 {{1, 0, 0}, {0, 1, 0}}};          // top: red, green
  for (int k = 0; k < 3; ++k) {
    const Quad& q = quads[k];
    int pure = 0, outside = 0;
    for (int py = 0; py < 32; ++py)
      for (int px = 0; px < 32; ++px) {
        const double u0 = 1 + px / 32.0, u1 = 1 + (px + 1) / 32.0;
        const double v0 = -1 + (31 - py) / 32.0, v1 = -1 + (32 - py) / 32.0;
        const int bu = block(u0, u1, q.su, q.ou, q.wu), bv = block(v0, v1, q.sv, q.ov, q.wv);
        if (bu < 0 || bv < 0) continue;
        ++pure;
        const double tu = (u0 + u1) / 2 * q.su + q.ou, tv = (v0 + v1) / 2 * q.sv + q.ov;
        outside += tu < 0 || tu > 1 || tv < 0 || tv > 1;
        for (const lucent::RenderResult* r : {&kernel, &reference}) {
          const float* c = r->mean.pixel(32 * k + px, py);
          for (int ch = 0; ch < 3; ++ch)
            ASSERT_NEAR(c[ch], colour[bv][bu][ch], 1e-3)
                << "quad " << k << " (wrap " << q.wrap << ") pixel (" << px << ", " << py
                << ") channel " << ch << (r == &kernel ? " (kernel)" : " (reference)");
        }
      }
    // most of each quad is checked, most of it beyond [0, 1]
    EXPECT_GT(pure, 250) << "quad " << k;
    EXPECT_GT(outside, 200) << "quad " << k;
  }
}

// Texture coordinates far from 0 under a mapping: the kernel's float uvs hold about 7 digits,
// so a triangle's uvs near 1e5 or 1e6 keep their texels only if the host brings them near 0
// first. Three quads (16x8 texture of random 0/1 texels, one quad each): repeat under a scale of
// 1.5 with uvs near 1e5, clamp with uvs near 1e6 and an offset of -1e6, mirror under scales 0.75
// and -1.25 with uvs near -3e5 and 2e5. A box filter of radius 1e-4 pixel samples each pixel at
// its centre, where the closed form (bilinear between texel centres, indices wrapped by the
// mode, in double) gives its colour; kernel and reference must both show it (the lookup is
// continuous in uv: float rounding near 0 moves it by under 1e-4; the old host kept these uvs
// as they were, their float rounding, up to 0.03 in uv, moved the lookup by up to a texel).
TEST(TextureRender, MappedUvsFarFromZeroKeepTheirTexels) {
  std::string dir = lucent::test::temp_dir();
  const int W = 16, H = 8;
  std::vector<unsigned char> px(W * H * 3);
  std::uint32_t state = 12345;
  for (unsigned char& c : px) {
    state = state * 1664525u + 1013904223u;
    c = (state >> 31) ? 255 : 0;  // sRGB 0 and 255: linear 0 and 1
  }
  ASSERT_TRUE(stbi_write_png((dir + "/random.png").c_str(), W, H, 3, px.data(), W * 3));
  using Wr = lucent::TextureWrap;
  struct Quad {
    const char* wrap;  // the JSON
    Wr wu, wv;
    double su, sv, ou, ov;
    double u0, v0, du, dv;  // the quad's uvs: [u0, u0 + du] x [v0, v0 + dv]
  };
  const Quad quads[] = {
      {R"("repeat")", Wr::Repeat, Wr::Repeat, 1.5, 1.5, 0, 0, 1e5, 1e5, 0.5, 0.5},
      {R"("clamp")", Wr::Clamp, Wr::Clamp, 1, 1, -1e6, -1e6, 1e6 - 0.1, 1e6 - 0.1, 1.2, 1.2},
      {R"("mirror")", Wr::Mirror, Wr::Mirror, 0.75, -1.25, 0.3, 0.1, -3e5, 2e5, 1.5, 1}};
  std::string materials, shapes;
  for (int k = 0; k < 3; ++k) {
    const Quad& q = quads[k];
    char m[512], sh[768];
    std::snprintf(m, sizeof m,
                  R"(%s"q%d": {"type": "diffuse", "albedo": {"texture": "%s/random.png",
                     "wrap": %s, "uv_scale": [%.17g, %.17g], "uv_offset": [%.17g, %.17g]}})",
                  k ? ", " : "", k, dir.c_str(), q.wrap, q.su, q.sv, q.ou, q.ov);
    const double x0 = -3 + 2 * k;
    std::snprintf(sh, sizeof sh,
                  R"(%s{"type": "triangles", "material": "q%d",
                     "positions": [[%g, -1, 0], [%g, -1, 0], [%g, 1, 0], [%g, 1, 0]],
                     "uvs": [[%.17g, %.17g], [%.17g, %.17g], [%.17g, %.17g], [%.17g, %.17g]],
                     "indices": [0, 1, 2, 0, 2, 3]})",
                  k ? ", " : "", k, x0, x0 + 2, x0 + 2, x0, q.u0, q.v0, q.u0 + q.du, q.v0,
                  q.u0 + q.du, q.v0 + q.dv, q.u0, q.v0 + q.dv);
    materials += m;
    shapes += sh;
  }
  // the quads exactly fill a 90-degree (vertical) view of aspect 3 from distance 1
  const std::string json =
      three_quads_scene(materials, shapes, R"(, "filter": {"type": "box", "radius": 1e-4})", 2);
  const KernelAndReference both = render_both(dir, "far.json", json, 2);
  const lucent::RenderResult &kernel = both.kernel, &reference = both.reference;

  auto wrap = [](long i, long n, Wr w) {
    if (w == Wr::Clamp) return std::clamp(i, 0L, n - 1);
    const long p = w == Wr::Mirror ? 2 * n : n;
    const long r = ((i % p) + p) % p;
    return r < n ? r : p - 1 - r;
  };
  auto texel = [&](long x, long y, const Quad& q, int ch) {
    return px[3 * (wrap(y, H, q.wv) * W + wrap(x, W, q.wu)) + ch] ? 1.0 : 0.0;
  };
  for (int k = 0; k < 3; ++k) {
    const Quad& q = quads[k];
    for (int py = 0; py < 32; ++py)
      for (int pxi = 0; pxi < 32; ++pxi) {
        const double u = q.u0 + q.du * (pxi + 0.5) / 32, v = q.v0 + q.dv * (31.5 - py) / 32;
        const double x = (u * q.su + q.ou) * W - 0.5, y = (1 - (v * q.sv + q.ov)) * H - 0.5;
        const double fx = std::floor(x), fy = std::floor(y), ax = x - fx, ay = y - fy;
        const long ix = static_cast<long>(fx), iy = static_cast<long>(fy);
        for (int ch = 0; ch < 3; ++ch) {
          const double want =
              (1 - ay) * ((1 - ax) * texel(ix, iy, q, ch) + ax * texel(ix + 1, iy, q, ch)) +
              ay * ((1 - ax) * texel(ix, iy + 1, q, ch) + ax * texel(ix + 1, iy + 1, q, ch));
          for (const lucent::RenderResult* r : {&kernel, &reference})
            ASSERT_NEAR(r->mean.pixel(32 * k + pxi, py)[ch], want, 2e-3)
                << "quad " << k << " (wrap " << q.wrap << ") pixel (" << pxi << ", " << py
                << ") channel " << ch << (r == &kernel ? " (kernel)" : " (reference)");
        }
      }
  }
}

// A sphere's uv reaches v = 1 at the north pole, where the half-texel cap (v above the top row's
// centre) blends the top row with the next one beyond the edge: repeating, the image's bottom
// row (docs/rendering-model.md, "Geometry"). Clamped in v, the cap shows the top row's colour
// alone. An 8x4 texture, its top row red, then two green rows and a blue bottom row, seen from
// above the pole: the central 6x6 pixels lie within 12 degrees of the pole (the cap is 22.5).
TEST(TextureRender, ClampedSpherePoleShowsOnlyTheTopRow) {
  std::string dir = lucent::test::temp_dir();
  std::vector<unsigned char> px;
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 8; ++x) {
      const unsigned char on = 255, off = 0;
      const unsigned char c[3] = {y == 0 ? on : off, (y == 1 || y == 2) ? on : off,
                                  y == 3 ? on : off};
      px.insert(px.end(), c, c + 3);
    }
  ASSERT_TRUE(stbi_write_png((dir + "/rows.png").c_str(), 8, 4, 3, px.data(), 8 * 3));
  auto scene = [&](const std::string& mapping) {
    return R"({
      "camera": {"position": [0, 4, 0], "look_at": [0, 0, 0], "up": [0, 0, -1], "fov": 30},
      "film": {"width": 32, "height": 32},
      "integrator": {"type": "albedo", "spp": 4},
      "materials": {"t": {"type": "diffuse", "albedo": {"texture": ")" +
           dir + R"(/rows.png")" + mapping + R"(}}},
      "shapes": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "t"}]})";
  };
  // repeating (the default) the pole bleeds: its centre is half red, half blue
  const lucent::RenderResult repeat = lucent::test::render_json(scene(""), 4);
  const float* centre = repeat.mean.pixel(16, 16);
  EXPECT_GT(centre[2], 0.3f) << "the repeating pole shows the bottom row";
  EXPECT_LT(centre[0], 0.7f);

  const std::string clamped = scene(R"(, "wrap": ["repeat", "clamp"])");
  const KernelAndReference both = render_both(dir, "pole.json", clamped, 4);
  const lucent::RenderResult &kernel = both.kernel, &reference = both.reference;
  for (const lucent::RenderResult* r : {&kernel, &reference})
    for (int y = 13; y <= 18; ++y)
      for (int x = 13; x <= 18; ++x) {
        const float* c = r->mean.pixel(x, y);
        SCOPED_TRACE("pixel (" + std::to_string(x) + ", " + std::to_string(y) + ")" +
                     (r == &kernel ? " (kernel)" : " (reference)"));
        EXPECT_NEAR(c[0], 1.0f, 1e-4);
        EXPECT_NEAR(c[1], 0.0f, 1e-4);
        EXPECT_NEAR(c[2], 0.0f, 1e-4);
      }
}

}  // namespace

}  // namespace test_texture_render
