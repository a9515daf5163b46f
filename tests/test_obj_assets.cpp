// The shared real-world assets (../shared/assets, skipped when absent): the Cornell box with its
// emissive quad, the textured character (CRLF, groups, BMP textures, a missing .dds) and the dragon
// (a missing MTL), plus the project's scenes that use OBJ meshes.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "lucent/lucent.hpp"
#include "scene/loaders.hpp"
#include "support.hpp"

namespace test_obj_assets {

namespace {

using lucent::Scene;

using lucent::test::CaptureWarnings;

// Triangles a fan triangulation of the file's faces gives: sum over `f` lines of (corners - 2),
// counted here independently of the loader.
size_t count_face_triangles(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::string line;
  size_t n = 0;
  while (std::getline(in, line)) {
    std::istringstream ls(line);
    std::string tag, tok;
    ls >> tag;
    if (tag != "f") continue;
    int corners = 0;
    while (ls >> tok) ++corners;
    n += corners - 2;
  }
  return n;
}

TEST(ObjAssets, CornellBoxOriginalHasItsEmissiveQuad) {
  std::string path = lucent::test::shared_asset("cornell-box/CornellBox-Original.obj");
  if (path.empty()) GTEST_SKIP() << "../shared/assets not present";
  CaptureWarnings w;
  Scene s;
  lucent::scene_detail::load_obj(s, path, glm::dmat4(1.0), -1);
  EXPECT_TRUE(w.all().empty()) << w.dump();
  EXPECT_EQ(s.triangles.size(), count_face_triangles(path));
  EXPECT_EQ(s.materials.size(), 8u);
  int emissive = 0;
  for (const auto& t : s.triangles) {
    const lucent::Material& m = s.materials[t.material];
    if (!m.emissive()) continue;
    ++emissive;
    EXPECT_EQ(m.name, "CornellBox-Original.obj:light");
    EXPECT_NEAR(m.emission.x, 17, 1e-6);
    EXPECT_NEAR(m.emission.y, 12, 1e-6);
    EXPECT_NEAR(m.emission.z, 4, 1e-6);
    // the light faces down into the box
    glm::dvec3 ng = glm::cross(s.positions[t.v[1]] - s.positions[t.v[0]],
                               s.positions[t.v[2]] - s.positions[t.v[0]]);
    EXPECT_LT(ng.y, 0);
  }
  EXPECT_EQ(emissive, 2);
  const lucent::Material& left = s.materials[s.find_material("CornellBox-Original.obj:leftWall")];
  EXPECT_EQ(left.type, lucent::MaterialType::Diffuse);
  EXPECT_NEAR(left.albedo.x, 0.63, 1e-6);
}

TEST(ObjAssets, CharacterLoadsWithSixTexturesAndWarnsAboutTheMissingDds) {
  std::string path = lucent::test::shared_asset("beautiful-girl/BeautifulGirl.obj");
  if (path.empty()) GTEST_SKIP() << "../shared/assets not present";
  CaptureWarnings w;
  Scene s;
  lucent::scene_detail::load_obj(s, path, glm::dmat4(1.0), -1);
  EXPECT_EQ(s.triangles.size(), 5484u);
  EXPECT_EQ(s.triangles.size(), count_face_triangles(path));
  ASSERT_EQ(s.textures.size(), 6u);
  for (const auto& t : s.textures) {
    EXPECT_TRUE(t.width == 256 || t.width == 512) << t.path;
    EXPECT_EQ(t.width, t.height) << t.path;
    EXPECT_EQ(t.rgba.size(), size_t(t.width) * t.height * 4) << t.path;
  }
  ASSERT_FALSE(w.all().empty());
  for (const auto& msg : w.all())
    EXPECT_NE(msg.find("13932ef0.dds"), std::string::npos) << "unexpected warning: " << msg;
  EXPECT_EQ(s.materials.size(), 6u);
  for (const auto& m : s.materials) {
    EXPECT_GE(m.albedo_texture, 0) << m.name;
    EXPECT_EQ(m.type, lucent::MaterialType::Plastic) << m.name << ": Ks 0.9, illum 2";
  }
  for (const auto& t : s.triangles)
    for (int k = 0; k < 3; ++k) {
      EXPECT_GE(t.uv[k], 0);
      EXPECT_GE(t.n[k], 0);
    }
}

TEST(ObjAssets, DragonWithoutItsMtlWarnsAndUsesTheDefaultMaterial) {
  std::string path = lucent::test::shared_asset("meshes/dragon.obj");
  if (path.empty()) GTEST_SKIP() << "../shared/assets not present";
  CaptureWarnings w;
  Scene s;
  lucent::scene_detail::load_obj(s, path, glm::dmat4(1.0), -1);
  ASSERT_EQ(w.all().size(), 1u) << w.dump();
  EXPECT_NE(w.all()[0].find("dragon.mtl"), std::string::npos) << w.dump();
  EXPECT_EQ(s.triangles.size(), 100000u);
  ASSERT_EQ(s.materials.size(), 1u);
  EXPECT_EQ(s.materials[0].albedo, glm::dvec3(0.8));
}

// Fraction of the triangles whose winding agrees with their vertex normals.
double agreeing_fraction(const Scene& s, size_t first) {
  size_t agree = 0, n = 0;
  for (size_t i = first; i < s.triangles.size(); ++i) {
    const auto& t = s.triangles[i];
    if (t.n[0] < 0) continue;
    glm::dvec3 ng = glm::cross(s.positions[t.v[1]] - s.positions[t.v[0]],
                               s.positions[t.v[2]] - s.positions[t.v[0]]);
    glm::dvec3 ns = s.normals[t.n[0]] + s.normals[t.n[1]] + s.normals[t.n[2]];
    ++n;
    if (glm::dot(ng, ns) > 0) ++agree;
  }
  return n ? double(agree) / n : 0;
}

TEST(ObjAssets, CourseSceneMirrorsTheCharacterKeepingItsOrientation) {
  if (lucent::test::shared_asset("beautiful-girl/BeautifulGirl.obj").empty())
    GTEST_SKIP() << "../shared/assets not present";
  CaptureWarnings w;
  Scene course = lucent::load_scene(lucent::test::source_path("scenes/course.json"));
  Scene plain;
  lucent::scene_detail::load_obj(
      plain, lucent::test::shared_asset("beautiful-girl/BeautifulGirl.obj"), glm::dmat4(1.0), -1);
  ASSERT_EQ(course.triangles.size(), plain.triangles.size());
  double before = agreeing_fraction(plain, 0), after = agreeing_fraction(course, 0);
  EXPECT_GT(before, 0.9) << "the model's windings and normals mostly agree";
  EXPECT_DOUBLE_EQ(after, before) << "the Y/Z swap must not turn faces inside out";
  // the model stands on the floor (feet at y = -10) and is about 1.72 * 20 units tall
  double ymin = 1e30, ymax = -1e30;
  for (const auto& p : course.positions) {
    ymin = std::min(ymin, p.y);
    ymax = std::max(ymax, p.y);
  }
  EXPECT_NEAR(ymin, -10, 1.0);
  EXPECT_NEAR(ymax - ymin, 34.4, 2.0);
}

TEST(ObjAssets, ProjectScenesLoad) {
  CaptureWarnings w;
  Scene textured = lucent::load_scene(lucent::test::source_path("scenes/textured.json"));
  EXPECT_TRUE(w.all().empty()) << w.dump();
  EXPECT_EQ(textured.textures.size(), 2u);  // the cube is used twice, its texture loaded once
  EXPECT_EQ(textured.triangles.size(), 2u + 2 * 12u);
  if (lucent::test::shared_asset("cornell-box/CornellBox-Original.obj").empty()) return;
  Scene cornell = lucent::load_scene(lucent::test::source_path("scenes/cornell-box.json"));
  EXPECT_EQ(cornell.triangles.size(), 36u);
}

}  // namespace

}  // namespace test_obj_assets
