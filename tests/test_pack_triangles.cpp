// Packed triangles carry their unit geometric normal (lc_triangle.ng_x, ng_y, ng_z), which hits and
// triangle lights read instead of computing it: render_detail::set_triangle_normal and pack_scene.
#include <gtest/gtest.h>

#include <cmath>
#include <glm/glm.hpp>
#include <random>
#include <vector>

#include "render/pack.hpp"
#include "support.hpp"

namespace test_pack_triangles {

namespace {

using lucent::render_detail::set_triangle_normal;

lc_triangle make(glm::dvec3 a, glm::dvec3 b, glm::dvec3 c) {
  lc_triangle t{};
  for (int k = 0; k < 3; ++k) {
    t.v0[k] = static_cast<float>(a[k]);
    t.v1[k] = static_cast<float>(b[k]);
    t.v2[k] = static_cast<float>(c[k]);
  }
  return t;
}

glm::dvec3 ng(const lc_triangle& t) { return {t.ng_x, t.ng_y, t.ng_z}; }

TEST(PackTriangles, NormalFollowsTheWindingOfTheFloatVertices) {
  lc_triangle t = make({0, 0, 0}, {1, 0, 0}, {0, 1, 0});
  ASSERT_TRUE(set_triangle_normal(t));
  EXPECT_EQ(ng(t), glm::dvec3(0, 0, 1));
  t = make({0, 0, 0}, {0, 1, 0}, {1, 0, 0});  // the other winding
  ASSERT_TRUE(set_triangle_normal(t));
  EXPECT_EQ(ng(t), glm::dvec3(0, 0, -1));
}

// Random triangles from 1e-30 to 1e30 (the float cross product underflows or overflows at the
// ends; the double one does not): the normal is unit and orthogonal to both float edges within
// a few float ulps, from the float vertices the kernel sees.
TEST(PackTriangles, NormalIsUnitAndOrthogonalAtEveryScale) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int e = -30; e <= 30; e += 5) {
    double m = std::pow(10.0, e);
    for (int i = 0; i < 200; ++i) {
      glm::dvec3 a(u(rng), u(rng), u(rng)), b(u(rng), u(rng), u(rng)), c(u(rng), u(rng), u(rng));
      lc_triangle t = make(m * a, m * b, m * c);
      glm::dvec3 v0(t.v0[0], t.v0[1], t.v0[2]), v1(t.v1[0], t.v1[1], t.v1[2]);
      glm::dvec3 v2(t.v2[0], t.v2[1], t.v2[2]);
      glm::dvec3 e1 = v1 - v0, e2 = v2 - v0;
      if (glm::length(glm::cross(e1, e2)) < 1e-3 * glm::length(e1) * glm::length(e2)) continue;
      ASSERT_TRUE(set_triangle_normal(t)) << "1e" << e;
      glm::dvec3 n = ng(t);
      EXPECT_NEAR(glm::length(n), 1.0, 2e-7) << "1e" << e;
      // |cos| of the angle to each edge: 0 up to the float rounding of n (a few 1e-8), over a
      // sine of at least 1e-3 between the edges
      EXPECT_LT(std::fabs(glm::dot(n, glm::normalize(e1))), 1e-6) << "1e" << e;
      EXPECT_LT(std::fabs(glm::dot(n, glm::normalize(e2))), 1e-6) << "1e" << e;
      EXPECT_GT(glm::dot(n, glm::cross(e1, e2)), 0.0) << "1e" << e;
    }
  }
}

// The normal's components are the fourth floats of the vertex rows, which the kernel loads and
// computes with (types.h, lc_triangle): none may be subnormal. A triangle tilted by 1e-39 out of
// the xy plane has a normal whose y component is subnormal in float; it is stored as 0.
TEST(PackTriangles, NormalComponentsAreNeverSubnormal) {
  lc_triangle t = make({0, 0, 0}, {1, 0, 0}, {0, 1, 1e-39});
  ASSERT_NE(t.v2[2], 0.0f);  // the vertex itself keeps its subnormal coordinate
  ASSERT_TRUE(set_triangle_normal(t));
  EXPECT_EQ(t.ng_y, 0.0f);
  EXPECT_EQ(ng(t), glm::dvec3(0, 0, 1));
  std::mt19937 rng(12);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int i = 0; i < 2000; ++i) {
    // nearly axis-aligned triangles, tilted by down to 1e-45
    const double tilt = std::pow(10.0, -5.0 - 40.0 * (u(rng) + 1) / 2);
    t = make({u(rng), u(rng), 0}, {u(rng), u(rng), tilt * u(rng)}, {u(rng), u(rng), 0});
    if (!set_triangle_normal(t)) continue;
    for (float c : {t.ng_x, t.ng_y, t.ng_z})
      EXPECT_TRUE(c == 0.0f || std::fpclassify(c) == FP_NORMAL) << c;
  }
}

TEST(PackTriangles, CollinearFloatVerticesHaveNoNormal) {
  lc_triangle t = make({0, 0, 0}, {1, 1, 1}, {2, 2, 2});
  t.ng_x = 7;
  EXPECT_FALSE(set_triangle_normal(t));
  EXPECT_EQ(t.ng_x, 7.0f);  // left unchanged
}

// pack_scene fills ng for every triangle it keeps, a triangle that is collinear only after
// rounding to float included (it takes the normal of its double vertices).
TEST(PackTriangles, PackSceneSetsEveryNormal) {
  lucent::Scene s = lucent::parse_scene(R"({
    "camera": {"position": [0, 0, 5], "look_at": [0, 0, 0], "fov": 40},
    "film": {"width": 8, "height": 8},
    "materials": {"w": {"type": "diffuse", "albedo": [0.5, 0.5, 0.5]},
                  "lamp": {"type": "diffuse", "albedo": [0, 0, 0], "emission": [1, 1, 1]}},
    "shapes": [
      {"type": "triangles", "material": "w", "positions": [[0, 0, 0], [0, 0, 1], [0, 1, 0]],
       "indices": [0, 1, 2]},
      {"type": "triangles", "material": "lamp",
       "positions": [[1, 1, 1], [1.0000000001, 1, 1], [1, 1.0000000001, 1]],
       "indices": [0, 1, 2]}]})",
                                        "pack.json");
  lucent::render_detail::PackedScene p = lucent::render_detail::pack_scene(s);
  ASSERT_EQ(p.triangles.size(), 2u);
  EXPECT_EQ(ng(p.triangles[0]), glm::dvec3(-1, 0, 0));
  EXPECT_NEAR(glm::length(ng(p.triangles[1]) - glm::dvec3(0, 0, 1)), 0.0, 1e-7);
}

// A triangle's uvs are packed in its material's texture space (docs/rendering-model.md,
// "Textures"): uv * scale + offset in double, less the whole periods (repeat 1, mirror 2, clamp
// none) of their smallest; a triangle without uvs gets its barycentrics' mapping, (0, 0), (1, 0),
// (0, 1) mapped. By hand: scale (2.5, -3), offset (0.25, 0), repeat in u and mirror in v, uvs
// (0, 0), (1, 0), (0, 1) map to (0.25, 0), (2.75, 0), (0.25, -3), less (0, -4): v 4, 4, 1.
// Clamped in v, nothing comes off v; far uvs (1e5 + ...) under a scale of 1.5 come out near 0.
TEST(PackTriangles, UvsArePackedMappedAndLessWholePeriods) {
  lucent::Scene s;
  s.textures.push_back(lucent::texture_from_rgba(1, 1, {0.5f, 0.5f, 0.5f, 1}));
  lucent::Material m;
  m.name = "m";
  m.albedo_texture = 0;
  m.albedo_wrap_v = lucent::TextureWrap::Mirror;
  m.albedo_uv_scale = {2.5, -3};
  m.albedo_uv_offset = {0.25, 0};
  lucent::Material c = m, far = m;
  c.name = "c";
  c.albedo_wrap_v = lucent::TextureWrap::Clamp;
  far.name = "far";
  far.albedo_wrap_v = lucent::TextureWrap::Repeat;
  far.albedo_uv_scale = {1.5, 1.5};
  far.albedo_uv_offset = {0, 0};
  s.materials = {m, c, far};
  s.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  s.uvs = {{0, 0}, {1, 0}, {0, 1}, {1e5, 1e5}, {1e5 + 0.5, 1e5}, {1e5, 1e5 + 0.5}};
  lucent::Triangle with_uvs, without;
  for (int k = 0; k < 3; ++k) with_uvs.v[k] = without.v[k] = with_uvs.uv[k] = k;
  lucent::Triangle clamped = with_uvs, far_uvs = with_uvs;
  clamped.material = 1;
  far_uvs.material = 2;
  for (int k = 0; k < 3; ++k) far_uvs.uv[k] = 3 + k;
  s.triangles = {with_uvs, without, clamped, far_uvs};
  const lucent::render_detail::PackedScene p = lucent::render_detail::pack_scene(s);
  ASSERT_EQ(p.tri_attrs.size(), 4u);
  const std::vector<float> want[4] = {{0.25f, 4, 2.75f, 4, 0.25f, 1},
                                      {0.25f, 4, 2.75f, 4, 0.25f, 1},
                                      {0.25f, 0, 2.75f, 0, 0.25f, -3},
                                      {0, 0, 0.75f, 0, 0, 0.75f}};
  for (int i = 0; i < 4; ++i) {
    EXPECT_TRUE(p.triangles[i].flags & LC_TRI_HAS_UVS) << i;
    EXPECT_EQ(std::vector<float>(p.tri_attrs[i].uv, p.tri_attrs[i].uv + 6), want[i]) << i;
  }
}

}  // namespace

}  // namespace test_pack_triangles
